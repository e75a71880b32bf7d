#include "glint/mesh/file_access.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <system_error>

#include "glint/mesh/mesh_file.h"

namespace glint {

std::string systemReason(int error) {
  std::string text = std::generic_category().message(error);
  if (!text.empty()) text[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  return text;
}

FileHandle& FileHandle::operator=(FileHandle&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

FileHandle::~FileHandle() {
  if (fd_ >= 0) ::close(fd_);
}

namespace {

// The refusal of a file stat'ed as `info`.
FileRefusal refusalOf(const struct stat& info) {
  if (S_ISDIR(info.st_mode)) return FileRefusal::Folder;
  if (!S_ISREG(info.st_mode)) return FileRefusal::NotRegular;
  return FileRefusal::None;
}

RegularFile failed(int error) {
  RegularFile file;
  file.refusal = error == ENOENT ? FileRefusal::Missing : FileRefusal::System;
  file.error = error;
  return file;
}

}  // namespace

RegularFile statRegularFile(const std::filesystem::path& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return failed(errno);
  RegularFile file;
  file.refusal = refusalOf(info);
  file.size = static_cast<std::uint64_t>(info.st_size);
  return file;
}

RegularFile openRegularFile(const std::filesystem::path& path) {
  RegularFile file = statRegularFile(path);
  if (file.refusal != FileRefusal::None) return file;
  FileHandle handle(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (!handle) return failed(errno);
  struct stat info {};
  if (::fstat(handle.get(), &info) != 0) return failed(errno);
  file.refusal = refusalOf(info);
  if (file.refusal != FileRefusal::None) return file;
  const int flags = ::fcntl(handle.get(), F_GETFL);
  if (flags < 0 || ::fcntl(handle.get(), F_SETFL, flags & ~O_NONBLOCK) != 0) return failed(errno);
  file.size = static_cast<std::uint64_t>(info.st_size);
  file.handle = std::move(handle);
  return file;
}

std::string meshFileRefusal(const RegularFile& file) {
  switch (file.refusal) {
    case FileRefusal::None:
      return "";
    case FileRefusal::Missing:
      return "no such file";
    case FileRefusal::Folder:
      return "it is a folder, not a mesh file";
    case FileRefusal::NotRegular:
      return "it is not a regular file";
    case FileRefusal::System:
      break;
  }
  return systemReason(file.error);
}

RegularFile openMeshFile(const std::filesystem::path& path) {
  RegularFile file = openRegularFile(path);
  if (file.refusal != FileRefusal::None) throw MeshLoadError(meshFileRefusal(file));
  return file;
}

}  // namespace glint
