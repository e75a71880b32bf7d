#include "glint/core/file_access.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <system_error>

#include <fmt/format.h>

namespace glint {

std::string systemReason(int error) {
  std::string text = std::generic_category().message(error);
  if (!text.empty()) text[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  return text;
}

ReadableFile::ReadableFile(ReadableFile&& other) noexcept
    : fd(other.release()),
      size(other.size),
      refusal(other.refusal),
      error(other.error),
      mode(other.mode) {}

ReadableFile& ReadableFile::operator=(ReadableFile&& other) noexcept {
  if (this != &other) {
    if (fd >= 0) ::close(fd);
    fd = other.release();
    size = other.size;
    refusal = other.refusal;
    error = other.error;
    mode = other.mode;
  }
  return *this;
}

ReadableFile::~ReadableFile() {
  if (fd >= 0) ::close(fd);
}

namespace {

// The refusal of a file stat'ed as `info`.
FileRefusal refusalOf(const struct stat& info) {
  if (S_ISDIR(info.st_mode)) return FileRefusal::Folder;
  if (!S_ISREG(info.st_mode)) return FileRefusal::NotRegular;
  return FileRefusal::None;
}

ReadableFile failed(int error) {
  ReadableFile file;
  file.refusal = error == ENOENT ? FileRefusal::Missing : FileRefusal::System;
  file.error = error;
  return file;
}

}  // namespace

std::string nonRegularKind(unsigned mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return "not a regular file";
}

ReadableFile statForReading(const std::filesystem::path& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return failed(errno);
  ReadableFile file;
  file.refusal = refusalOf(info);
  file.mode = info.st_mode;
  file.size = static_cast<std::uint64_t>(info.st_size);
  return file;
}

ReadableFile openForReading(const std::filesystem::path& path) {
  ReadableFile file = statForReading(path);
  if (file.refusal != FileRefusal::None) return file;
  file.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (file.fd < 0) return failed(errno);
  struct stat info {};
  if (::fstat(file.fd, &info) != 0) return failed(errno);
  file.refusal = refusalOf(info);
  file.mode = info.st_mode;
  if (file.refusal != FileRefusal::None) {
    ::close(file.release());
    return file;
  }
  const int flags = ::fcntl(file.fd, F_GETFL);
  if (flags < 0 || ::fcntl(file.fd, F_SETFL, flags & ~O_NONBLOCK) != 0) return failed(errno);
  file.size = static_cast<std::uint64_t>(info.st_size);
  return file;
}

namespace {

namespace fs = std::filesystem;

// `path` (absolute, normal) is `root` or inside it.
bool within(const fs::path& path, const fs::path& root) {
  const fs::path relative = path.lexically_relative(root);
  return !relative.empty() && *relative.begin() != "..";
}

fs::path lexicalPath(const fs::path& path) {
  std::error_code error;
  const fs::path absolute = fs::absolute(path, error);
  return (error ? path : absolute).lexically_normal();
}

// Symbolic links resolved as far as the path exists, the rest lexically; absolute (weakly_canonical
// of a relative path none of whose parts exist stays relative, and then lay "outside" any root).
fs::path resolvedPath(const fs::path& path) {
  std::error_code error;
  const fs::path absolute = lexicalPath(path);
  const fs::path resolved = fs::weakly_canonical(absolute, error);
  return error ? absolute : resolved;
}

// The folder itself, without the empty last element a trailing '/' leaves.
fs::path folderOf(fs::path folder) {
  folder = lexicalPath(folder);
  if (folder.has_parent_path() && folder.filename().empty()) folder = folder.parent_path();
  return folder;
}

}  // namespace

ReferencedFileRule::ReferencedFileRule(const fs::path& meshFile, const fs::path& sceneFolder,
                                       std::string_view what)
    : meshFile_(meshFile.string()), meshFolder_(meshFile.parent_path().string()) {
  const fs::path meshLexical = lexicalPath(meshFile);
  if (!sceneFolder.empty()) {
    const fs::path scene = folderOf(sceneFolder);
    if (within(meshLexical, scene) && within(resolvedPath(meshFile), resolvedPath(scene))) {
      lexicalRoot_ = scene;
      why_ = fmt::format("a {} may only name files in its scene file's folder and below", what);
    } else {
      why_ = fmt::format(
          "a {} outside the scene file's folder may only name files in its own folder and below",
          what);
    }
  } else {
    why_ = fmt::format("a {} may only name files in its own folder and below", what);
  }
  if (lexicalRoot_.empty()) lexicalRoot_ = meshLexical.parent_path();
  resolvedRoot_ = resolvedPath(lexicalRoot_);
}

std::string ReferencedFileRule::asWritten(std::string_view path) const {
  if (!meshFolder_.empty() && path.size() > meshFolder_.size() &&
      path.substr(0, meshFolder_.size()) == meshFolder_ && path[meshFolder_.size()] == '/') {
    path.remove_prefix(meshFolder_.size() + 1);
  }
  return std::string(path);
}

std::string ReferencedFileRule::refusedBecause(const fs::path& path, const fs::path& target) const {
  return fmt::format("it refers to '{}', which {} outside the folder '{}'{} ({})",
                     asWritten(path.string()),
                     target.empty() ? "lies" : fmt::format("leads to '{}'", target.string()),
                     lexicalRoot_.string(), target.empty() ? "" : " through a symbolic link", why_);
}

std::string ReferencedFileRule::refusal(const fs::path& path) const {
  if (isMeshFile(path.string())) return "";
  if (!within(lexicalPath(path), lexicalRoot_)) return refusedBecause(path, {});
  const fs::path resolved = resolvedPath(path);
  return within(resolved, resolvedRoot_) ? "" : refusedBecause(path, resolved);
}

std::string ReferencedFileRule::openedRefusal(int fd, const fs::path& path) const {
  if (isMeshFile(path.string())) return "";
  std::array<char, 4096> target{};
  const std::string link = fmt::format("/proc/self/fd/{}", fd);
  const ssize_t n = ::readlink(link.c_str(), target.data(), target.size() - 1);
  if (n <= 0 || target[0] != '/') return "";  // no /proc: the checks before opening stand
  const fs::path opened(std::string(target.data(), static_cast<std::size_t>(n)));
  return within(opened.lexically_normal(), resolvedRoot_) ? "" : refusedBecause(path, opened);
}

}  // namespace glint
