#include "glint/factories/scene_loader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "glint/factories/scene_builder.h"
#include "glint/readers/scene_parser.h"

namespace glint {
namespace {

// Far above any hand-written scene; stops a device such as /dev/zero from filling the memory.
constexpr std::size_t kMaxSceneFileBytes = std::size_t{256} << 20;

[[noreturn]] void failOpening(const std::string& file, int error) {
  // The system's words ("No such file or directory"), with the file as the user named it.
  throw SceneError({{Diagnostic::Severity::Error,
                     {file, 0, 0},
                     "cannot open file: " + std::generic_category().message(error)}});
}

// The whole file as text. POSIX calls rather than streams so each failure keeps its errno.
std::string readFile(const std::filesystem::path& path, const std::string& name) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) failOpening(name, errno);
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error = errno;
    ::close(fd);
    failOpening(name, error);
  }
  if (S_ISDIR(info.st_mode)) {
    ::close(fd);
    failOpening(name, EISDIR);
  }
  std::string text;
  if (S_ISREG(info.st_mode) && info.st_size > 0)
    text.reserve(static_cast<std::size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      failOpening(name, error);
    }
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > kMaxSceneFileBytes) {
      ::close(fd);
      throw SceneError({{Diagnostic::Severity::Error,
                         {name, 0, 0},
                         "the file is larger than 256 MiB; a scene file holds a scene description "
                         "(meshes belong in their own files)"}});
    }
  }
  ::close(fd);
  return text;
}

bool before(const Diagnostic& a, const Diagnostic& b) {
  if (a.where.line != b.where.line) return a.where.line < b.where.line;
  return a.where.column < b.where.column;
}

}  // namespace

LoadedScene loadSceneFromString(std::string_view text, const std::string& displayName,
                                const std::filesystem::path& baseDirectory,
                                const LoadOptions& options) {
  ParseResult parsed = parseScene(text, displayName, baseDirectory);
  BuildResult built = buildScene(
      parsed.description, BuildOptions{options.memoryBudget, options.overrides, options.cancel});

  std::vector<Diagnostic> errors;
  std::vector<Diagnostic> warnings;
  for (std::vector<Diagnostic>* list : {&parsed.diagnostics, &built.diagnostics}) {
    for (Diagnostic& d : *list) {
      (d.severity == Diagnostic::Severity::Error ? errors : warnings).push_back(std::move(d));
    }
  }
  // File order; the parser and the builder each report in their own walk of the file.
  std::stable_sort(errors.begin(), errors.end(), before);
  std::stable_sort(warnings.begin(), warnings.end(), before);
  if (!errors.empty()) throw SceneError(std::move(errors));
  return LoadedScene{std::move(built.parts), std::move(warnings)};
}

LoadedScene loadScene(const std::filesystem::path& file, const LoadOptions& options) {
  const std::string name = file.string();
  const std::string text = readFile(file, name);
  std::filesystem::path base = file.parent_path();
  if (base.empty()) base = ".";
  return loadSceneFromString(text, name, base, options);
}

}  // namespace glint
