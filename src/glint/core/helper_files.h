// Where glint's helper files are found: the programs and modules it starts or loads on demand
// (the mesh reader, the preview server, the MPI transport), wherever glint was built, installed or
// moved to.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "glint/core/version.h"

namespace glint {

// The helper's path in this build tree and once installed, for the source file that finds it:
// src/CMakeLists.txt (glint_helper_paths) defines GLINT_HELPER_BUILD_PATH and
// GLINT_HELPER_INSTALL_PATH for it; empty where they are not defined.
#ifdef GLINT_HELPER_BUILD_PATH
#define GLINT_HELPER_BUILD_PATH_OR_EMPTY GLINT_HELPER_BUILD_PATH
#else
#define GLINT_HELPER_BUILD_PATH_OR_EMPTY ""
#endif
#ifdef GLINT_HELPER_BUILD_TREE
#define GLINT_HELPER_BUILD_TREE_OR_EMPTY GLINT_HELPER_BUILD_TREE
#else
#define GLINT_HELPER_BUILD_TREE_OR_EMPTY ""
#endif
#ifdef GLINT_HELPER_INSTALL_PATH
#define GLINT_HELPER_INSTALL_PATH_OR_EMPTY GLINT_HELPER_INSTALL_PATH
#else
#define GLINT_HELPER_INSTALL_PATH_OR_EMPTY ""
#endif
#ifdef GLINT_HELPER_PACKAGE_PATH
#define GLINT_HELPER_PACKAGE_PATH_OR_EMPTY GLINT_HELPER_PACKAGE_PATH
#else
#define GLINT_HELPER_PACKAGE_PATH_OR_EMPTY ""
#endif
// The three, for findHelperFile and loadHelperModule.
#define GLINT_HELPER_PATHS                                                     \
  ::glint::HelperPaths {                                                       \
    GLINT_HELPER_BUILD_PATH_OR_EMPTY, GLINT_HELPER_BUILD_TREE_OR_EMPTY,        \
        GLINT_HELPER_INSTALL_PATH_OR_EMPTY, GLINT_HELPER_PACKAGE_PATH_OR_EMPTY \
  }

// Where a helper was put by the build and by the installs (any may be empty).
struct HelperPaths {
  std::string_view build;      // the build tree's
  std::string_view buildTree;  // the top of the build tree whose programs may use `build`
  std::string_view install;    // the configured install prefix's (cmake --install)
  std::string_view package;    // the .deb's (/usr)
};

// The helper `name`: the path in environment variable `override` when it is set and not empty
// (returned whether or not it exists, so that a wrong setting is reported as such); else the first
// regular file that exists of: `name` beside the running program (a build tree, a program linked
// with the library), ../libexec/glint/`name` from it (an installed tree, wherever it was moved),
// the build tree's — only for a program inside that build tree (its tests and tools, a project
// that builds glint with add_subdirectory: an installed library never runs what a build folder
// happens to hold) —, the configured install prefix's and
// the .deb's. Empty when none is found. `executable`: whether it must be executable (a program,
// not a module).
std::filesystem::path findHelperFile(std::string_view name, const char* override,
                                     const HelperPaths& paths, bool executable);

}  // namespace glint

namespace glint {

// Every module glint loads answers `glint_module_identity()` with this text for its name and
// interface version; a module of another glint version, another module or another interface is
// refused (its classes would not match the caller's).
#define GLINT_MODULE_IDENTITY(module, interface) \
  ("glint " GLINT_VERSION " module " module " interface " #interface)

// The function that answers it, exported by every module: GLINT_DEFINE_MODULE_IDENTITY(identity)
// at namespace scope in the module's source defines it; loadHelperModule looks it up by name.
#define GLINT_MODULE_IDENTITY_FUNCTION glint_module_identity
#define GLINT_DEFINE_MODULE_IDENTITY(identity)                                             \
  extern "C" [[gnu::visibility("default")]] const char* GLINT_MODULE_IDENTITY_FUNCTION() { \
    return identity;                                                                       \
  }

// A module (a shared object of this build) loaded on demand: found as findHelperFile says, opened
// with dlopen (RTLD_NOW: every symbol resolved now, not at a first call in a server thread),
// checked against `identity`, and `entry` looked up. Returns the entry point, or nullptr with the
// reason in `error`, worded for the user. The module stays loaded until the process ends.
void* loadHelperModule(std::string_view name, const char* override, const HelperPaths& paths,
                       const char* identity, const char* entry, std::string& error);

}  // namespace glint
