// How the mesh loader opens files (DESIGN.md §7): regular files only. A FIFO would block the
// reader forever and a device such as /dev/zero never ends, so a path is stat'ed first (a FIFO or
// device is refused without being opened), then opened with O_NONBLOCK (a FIFO put in its place
// meanwhile opens without waiting for a writer) and checked again with fstat on what was opened.
// Internal to the mesh loader.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
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

}  // namespace glint
