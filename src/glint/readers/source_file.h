// Opening the files a scene names (the scene itself, later textures and included files) safely:
// only regular files, checked before they are opened for reading where the system allows, so a
// FIFO, a device or a folder is refused instead of blocking or reading forever.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace glint {

// Scene files larger than this are refused: a scene file holds a scene description (meshes belong
// in their own files). 256 MiB.
inline constexpr std::uint64_t kMaxSceneFileBytes = std::uint64_t{256} << 20;

// An open file descriptor, closed on destruction.
class FileHandle {
 public:
  explicit FileHandle(int fd = -1) : fd_(fd) {}
  FileHandle(FileHandle&& other) noexcept : fd_(other.release()) {}
  FileHandle& operator=(FileHandle&& other) noexcept;
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  ~FileHandle();
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_;
};

struct OpenedFile {
  FileHandle handle;
  std::uint64_t size = 0;  // bytes, from fstat
};

// Opens `path` for reading if it is a regular file. Throws SceneError naming only `name`:
// "cannot open file: No such file or directory", "cannot open file: Is a directory",
// "cannot open file: not a regular file (a FIFO)", ... A FIFO is recognised by stat() before
// open(); the open itself is non-blocking and the type checked again on the open descriptor.
OpenedFile openRegularFile(const std::filesystem::path& path, const std::string& name);

}  // namespace glint
