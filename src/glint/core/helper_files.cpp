#include "glint/core/helper_files.h"

#include <dlfcn.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <system_error>
#include <vector>

namespace glint {

std::filesystem::path findHelperFile(std::string_view name, const char* override,
                                     const HelperPaths& paths, bool executable) {
  namespace fs = std::filesystem;
  if (const char* forced = std::getenv(override); forced != nullptr && *forced != 0) return forced;
  std::vector<fs::path> candidates;
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    candidates.push_back(self.parent_path() / name);
    candidates.push_back(self.parent_path().parent_path() / "libexec/glint" / name);
  }
  if (!paths.build.empty() && !error) {
    // The build tree's helper: for programs of that tree only.
    std::error_code canonicalError;
    const fs::path buildTree = fs::weakly_canonical(
        paths.buildTree.empty() ? fs::path(paths.build).parent_path() : fs::path(paths.buildTree),
        canonicalError);
    const bool insideTree =
        !canonicalError && !buildTree.empty() &&
        std::mismatch(buildTree.begin(), buildTree.end(), self.begin(), self.end()).first ==
            buildTree.end();
    if (insideTree) candidates.emplace_back(paths.build);
  }
  if (!paths.install.empty()) candidates.emplace_back(paths.install);
  if (!paths.package.empty() && paths.package != paths.install) {
    candidates.emplace_back(paths.package);
  }
  for (const fs::path& candidate : candidates) {
    if (fs::is_regular_file(candidate, error) &&
        ::access(candidate.c_str(), executable ? X_OK : R_OK) == 0)
      return candidate;
  }
  return {};
}

}  // namespace glint

namespace glint {
namespace {

// GLINT_MODULE_IDENTITY_FUNCTION's name as a string, for dlsym.
#define GLINT_QUOTE(name) #name
#define GLINT_QUOTE_EXPANDED(name) GLINT_QUOTE(name)
constexpr const char* kIdentityFunctionName = GLINT_QUOTE_EXPANDED(GLINT_MODULE_IDENTITY_FUNCTION);
#undef GLINT_QUOTE_EXPANDED
#undef GLINT_QUOTE

}  // namespace

void* loadHelperModule(std::string_view name, const char* override, const HelperPaths& paths,
                       const char* identity, const char* entry, std::string& error) {
  const std::filesystem::path path = findHelperFile(name, override, paths, /*executable=*/false);
  if (path.empty()) {
    error = fmt::format(
        "{} was not found beside this program, in ../libexec/glint from it, or where glint was "
        "built or installed (set {} to its path)",
        name, override);
    return nullptr;
  }
  // Never closed: its threads and the objects it made may live until the process ends.
  void* const module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (module == nullptr) {
    const char* const failure = ::dlerror();  // clears it: read once
    std::string_view reason = failure != nullptr ? failure : "";
    // dlerror() names the file itself: "PATH: cannot open shared object file: ...".
    const std::string prefix = path.string() + ": ";
    if (reason.starts_with(prefix)) reason.remove_prefix(prefix.size());
    error = fmt::format("cannot load {}: {}", path.string(),
                        reason.empty() ? std::string_view("unknown reason") : reason);
    return nullptr;
  }
  using IdentityFunction = const char* (*)();
  const auto moduleIdentity =
      reinterpret_cast<IdentityFunction>(::dlsym(module, kIdentityFunctionName));
  if (moduleIdentity == nullptr || std::string_view(moduleIdentity()) != identity) {
    error = fmt::format("{} is not the module of this glint ({}; expected '{}')", path.string(),
                        moduleIdentity ? fmt::format("it is '{}'", moduleIdentity())
                                       : std::string("it has no glint module identity"),
                        identity);
    return nullptr;
  }
  void* const function = ::dlsym(module, entry);
  if (function == nullptr) error = fmt::format("{} has no entry point {}", path.string(), entry);
  return function;
}

}  // namespace glint
