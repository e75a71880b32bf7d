// The mesh import in a child process (fork): assimp reads the file there and the MeshFile comes
// back in a checked binary answer, so that memory corruption inside an importer refuses the file
// instead of crashing or corrupting the renderer; a time limit stops an importer that loops.
// Internal to the mesh loader.
#pragma once

#include <filesystem>
#include <string>

#include "glint/mesh/file_access.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// A mesh file is read by assimp in a child process, which may take kMeshReadBaseSeconds plus
// kMeshReadSecondsPerMiB per MiB of the file; past that it is stopped and the file refused (an
// importer that loops on a malformed file must not hang glint).
inline constexpr double kMeshReadBaseSeconds = 30;
inline constexpr double kMeshReadSecondsPerMiB = 2;

// importMesh (assimp_import.h) run in a child process; the parent checks the answer (sizes,
// indices, materials) before returning it. A crash of the child, an answer cut short or
// inconsistent, or the time limit is a MeshLoadError.
MeshFile importMeshInChild(const std::filesystem::path& path, const std::string& extension,
                           const ReferencedFileRule& rule);

}  // namespace glint
