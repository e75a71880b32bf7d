// How the mesh loader opens files (DESIGN.md §7): regular files only, and the files a mesh file
// names only inside the folder tree it may use. A FIFO would block the reader forever and a device
// such as /dev/zero never ends, so a path is stat'ed first (a FIFO or device is refused without
// being opened), then opened with O_NONBLOCK (a FIFO put in its place meanwhile opens without
// waiting for a writer) and checked again with fstat on what was opened. Internal to the mesh
// loader.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

namespace glint {

// The system's words for an errno, starting lower-case to follow "cannot load mesh file 'x': ".
std::string systemReason(int error);

// A file descriptor, closed when it goes out of scope.
class FileHandle {
 public:
  FileHandle() = default;
  explicit FileHandle(int fd) : fd_(fd) {}
  FileHandle(FileHandle&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  FileHandle& operator=(FileHandle&& other) noexcept;
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  ~FileHandle();

  int get() const { return fd_; }
  // Hands the descriptor over (to fdopen, say); the handle no longer closes it.
  int release() { return std::exchange(fd_, -1); }
  explicit operator bool() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// Why a path cannot be read as a regular file.
enum class FileRefusal {
  None,        // a regular file
  Missing,     // no such file (ENOENT)
  Folder,      // a directory
  NotRegular,  // a FIFO, device or socket
  System,      // stat or open failed otherwise (permission, ...): see `error`
};

struct RegularFile {
  FileHandle handle;  // open for reading (blocking), close-on-exec; empty unless refusal is None
  std::uint64_t size = 0;  // bytes
  FileRefusal refusal = FileRefusal::None;
  int error = 0;  // errno for Missing and System
};

// What stat says of `path` (handle left empty): its size, or why it is refused.
RegularFile statRegularFile(const std::filesystem::path& path);

// statRegularFile, then the file opened with O_NONBLOCK and checked again with fstat (O_NONBLOCK
// is cleared before returning).
RegularFile openRegularFile(const std::filesystem::path& path);

// The reason a mesh file is refused, in the user's words: "no such file", "it is a folder, not a
// mesh file", "it is not a regular file", or the system's reason.
std::string meshFileRefusal(const RegularFile& file);

// openRegularFile for a mesh file itself: a refusal throws MeshLoadError (meshFileRefusal).
RegularFile openMeshFile(const std::filesystem::path& path);

// The folder tree that the files a mesh file names (MTL libraries, glTF buffers and images, and
// texture files) must lie in: the scene file's folder when the mesh file lies in it, else (and
// without a scene folder) the mesh file's own folder. A name is checked lexically ("." and ".."
// resolved: `../../etc/passwd` is refused whether or not it exists) and after following symbolic
// links (a link inside the tree to a file outside it is refused), and a file once opened is checked
// again where its descriptor really leads, so a link changed in between cannot escape either. The
// mesh file itself is exempt: the scene names it.
class ReferencedFileRule {
 public:
  ReferencedFileRule(const std::filesystem::path& meshFile,
                     const std::filesystem::path& sceneFolder);

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
