// How glint opens the files it reads (DESIGN.md §7): regular files only, and the files a file
// names (a mesh's MTL and buffers, later textures) only inside the folder tree it may use. A FIFO
// would block the reader forever and a device such as /dev/zero never ends, so a path is stat'ed
// first (a FIFO or device is refused without being opened), then opened with O_NONBLOCK (a FIFO put
// in its place meanwhile opens without waiting for a writer) and checked again with fstat on what
// was opened.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

namespace glint {

// The system's words for an errno, starting lower-case to follow "cannot load mesh file 'x': ".
std::string systemReason(int error);

// Why a path cannot be read as a regular file.
enum class FileRefusal {
  None,        // a regular file
  Missing,     // no such file (ENOENT)
  Folder,      // a directory
  NotRegular,  // a FIFO, device or socket
  System,      // stat or open failed otherwise (permission, ...): see `error`
};

// A path stat'ed or opened for reading: its size, or why it cannot be read. An opened file's
// descriptor is closed when the ReadableFile goes out of scope.
struct ReadableFile {
  int fd = -1;  // open for reading (blocking, close-on-exec) when opened and refusal is None
  std::uint64_t size = 0;  // bytes
  FileRefusal refusal = FileRefusal::None;
  int error = 0;      // errno for Missing and System
  unsigned mode = 0;  // st_mode, when stat or fstat answered

  ReadableFile() = default;
  ReadableFile(ReadableFile&& other) noexcept;
  ReadableFile& operator=(ReadableFile&& other) noexcept;
  ReadableFile(const ReadableFile&) = delete;
  ReadableFile& operator=(const ReadableFile&) = delete;
  ~ReadableFile();
  // Hands the descriptor over (to fdopen, say): it is no longer closed here.
  int release() { return std::exchange(fd, -1); }
};

// What stat says of `path` (nothing opened): its size, or why it is refused.
ReadableFile statForReading(const std::filesystem::path& path);

// statForReading, then the file opened with O_NONBLOCK and checked again with fstat (O_NONBLOCK
// is cleared before returning).
ReadableFile openForReading(const std::filesystem::path& path);

// What a file that is not regular is, for messages: "a FIFO", "a device", "a socket".
std::string nonRegularKind(unsigned mode);

// The folder tree that the files a mesh file names (MTL libraries, glTF buffers and images, and
// texture files) must lie in: the scene file's folder when the mesh file lies in it, else (and
// without a scene folder) the mesh file's own folder. A name is checked lexically ("." and ".."
// resolved: `../../etc/passwd` is refused whether or not it exists) and after following symbolic
// links (a link inside the tree to a file outside it is refused), and a file once opened is checked
// again where its descriptor really leads, so a link changed in between cannot escape either. The
// mesh file itself is exempt: the scene names it.
class ReferencedFileRule {
 public:
  // `what` names the naming file in messages: "mesh file", "texture".
  ReferencedFileRule(const std::filesystem::path& meshFile,
                     const std::filesystem::path& sceneFolder, std::string_view what = "mesh file");

  // Why the file at `path` may not be read, or "" when it may. `path` is the name as the importer
  // formed it (the mesh file's folder joined with the reference); the message names the reference
  // as the mesh file wrote it.
  std::string refusal(const std::filesystem::path& path) const;
  // The same for the file open as `fd` (found as `path`), from where the descriptor leads
  // (/proc/self/fd); "" when the system does not say.
  std::string openedRefusal(int fd, const std::filesystem::path& path) const;

  bool isMeshFile(std::string_view path) const { return path == meshFile_; }
  // `path` as the mesh file wrote it: without the mesh file's folder the importer put in front.
  std::string asWritten(std::string_view path) const;

 private:
  // The refusal of `path`: outside lexically, or (with `target`) where a symbolic link leads.
  std::string refusedBecause(const std::filesystem::path& path,
                             const std::filesystem::path& target) const;

  std::string meshFile_;                // as given to the importer
  std::string meshFolder_;              // its folder, as given
  std::filesystem::path lexicalRoot_;   // absolute, lexically normal
  std::filesystem::path resolvedRoot_;  // lexicalRoot_ with symbolic links resolved
  std::string why_;                     // which tree the root is, for messages
};

}  // namespace glint
