// The mesh import in a child process (fork): assimp reads the file there and the MeshFile comes
// back in a checked binary answer, so that memory corruption inside an importer refuses the file
// instead of crashing or corrupting the renderer; a time limit stops an importer that loops.
// Internal to the mesh loader.
#pragma once

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>

#include "glint/core/file_access.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// A mesh file is read by assimp in a child process, which may take kMeshReadBaseSeconds plus
// kMeshReadSecondsPerMiB per MiB of the file; past that it is stopped and the file refused (an
// importer that loops on a malformed file must not hang glint).
inline constexpr double kMeshReadBaseSeconds = 30;
inline constexpr double kMeshReadSecondsPerMiB = 2;

// importMesh (assimp_import.h) run in a child process; the parent checks the answer (sizes,
// indices, materials) before returning it. A crash of the child, an answer cut short or
// inconsistent, or the time limit is a MeshLoadError. While it waits for the child and checks the
// answer, the parent polls `cancel` (may be null): once it is set the child is killed at once and
// Cancelled (core/cancel.h) thrown, within ~20 ms.
MeshFile importMeshInChild(const std::filesystem::path& path, const std::string& extension,
                           const ReferencedFileRule& rule, const std::atomic<bool>* cancel);

// For tests of the parent's waiting (cancellation, time limit): every child started from now on
// sleeps `delay` before it reads the file; zero turns it off.
void setImportChildDelayForTesting(std::chrono::milliseconds delay);

}  // namespace glint
