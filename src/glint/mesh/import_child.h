// The mesh import in a child process (the program glint-mesh-reader, started by fork + execve):
// assimp reads the file there and the MeshFile comes back in a checked binary answer, so that
// memory corruption inside an importer refuses the file instead of crashing or corrupting the
// renderer; a time limit stops an importer that loops. Internal to the mesh loader.
#pragma once

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>

#include "glint/core/file_access.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// A mesh file is read by assimp in a child process, which may take kMeshReadBaseSeconds plus
// kMeshReadSecondsPerMiB per MiB of the file (at most a day); past that it is stopped and the file
// refused (an importer that loops on a malformed file must not hang glint).
inline constexpr double kMeshReadBaseSeconds = 30;
inline constexpr double kMeshReadSecondsPerMiB = 2;
// The mesh reader's address space beyond what it has mapped at start: this much, plus this much
// per byte of the mesh file (mesh_reader_side.cpp; not for a .gltf, nor under AddressSanitizer).
inline constexpr double kMeshReaderMemoryBaseBytes = 512.0 * 1024 * 1024;
inline constexpr double kMeshReaderMemoryPerFileByte = 256;

// importMesh (assimp_import.h) run in a child process; the parent checks the answer (sizes,
// indices, materials) before returning it. A crash of the child, an answer cut short or
// inconsistent, or the time limit is a MeshLoadError. While it waits for the child and checks the
// answer, the parent polls `cancel` (may be null): once it is set the child is killed at once and
// Cancelled (core/cancel.h) thrown, within ~20 ms.
// The child reads only what ReferencedFileRule(path, sceneFolder) allows. The program is found
// as findMeshReader (import_child.cpp) says: GLINT_MESH_READER, beside the running program,
// ../libexec/glint from it, the build tree, the installed libexec folder.
MeshFile importMeshInChild(const std::filesystem::path& path, const std::string& extension,
                           const std::filesystem::path& sceneFolder,
                           const std::atomic<bool>* cancel);

// The name of the mesh reader program.
inline constexpr const char* kMeshReaderProgram = "glint-mesh-reader";

// For tests of the parent's waiting (cancellation, time limit): every child started from now on
// sleeps `delay` before it reads the file; zero turns it off.
void setImportChildDelayForTesting(std::chrono::milliseconds delay);
// Test hook: the child's time limit instead of kMeshReadBaseSeconds + kMeshReadSecondsPerMiB per
// MiB (0: that rule again). The mesh fuzzers use a few seconds, so that a file assimp loops on is
// refused within their own per-input timeout, as glint refuses it after its limit.
void setMeshReadTimeLimitForTesting(std::chrono::milliseconds limit);

}  // namespace glint
