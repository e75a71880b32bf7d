#include "glint/readers/source_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>

#include "glint/readers/diagnostics.h"

namespace glint {
namespace {

[[noreturn]] void refuse(const std::string& name, const std::string& reason) {
  throw SceneError({{Diagnostic::Severity::Error, {name, 0, 0}, "cannot open file: " + reason}});
}

// The system's words ("No such file or directory"), with the file as the user named it.
[[noreturn]] void failOpening(const std::string& name, int error) {
  refuse(name, std::generic_category().message(error));
}

// Why a file of this type is not read, or "" for a regular file.
std::string notRegular(mode_t mode) {
  if (S_ISREG(mode)) return {};
  if (S_ISDIR(mode)) return std::generic_category().message(EISDIR);
  if (S_ISFIFO(mode)) return "not a regular file (a FIFO)";
  if (S_ISSOCK(mode)) return "not a regular file (a socket)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "not a regular file (a device)";
  return "not a regular file";
}

}  // namespace

FileHandle& FileHandle::operator=(FileHandle&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

FileHandle::~FileHandle() {
  if (fd_ >= 0) ::close(fd_);
}

OpenedFile openRegularFile(const std::filesystem::path& path, const std::string& name) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) failOpening(name, errno);
  if (const std::string reason = notRegular(info.st_mode); !reason.empty()) refuse(name, reason);
  // Non-blocking, so that a FIFO swapped in after the stat() cannot block the open.
  FileHandle handle(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY));
  if (handle.get() < 0) failOpening(name, errno);
  if (::fstat(handle.get(), &info) != 0) failOpening(name, errno);
  if (const std::string reason = notRegular(info.st_mode); !reason.empty()) refuse(name, reason);
  const int flags = ::fcntl(handle.get(), F_GETFL);
  if (flags >= 0) ::fcntl(handle.get(), F_SETFL, flags & ~O_NONBLOCK);
  return {std::move(handle), static_cast<std::uint64_t>(info.st_size)};
}

}  // namespace glint
