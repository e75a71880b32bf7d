// The size of a mesh file's content, known before it is read: what the memory estimate of a mesh
// object (mesh_cache.h) counts.
#pragma once

#include <cstdint>
#include <filesystem>

#include "glint/core/file_access.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// From the header (PLY element counts, the binary STL triangle count), by counting lines without
// storing them (OBJ `f` corners and `v` lines, ASCII STL facets), or bounded by the bytes (glTF:
// ~12 bytes per triangle for 16-bit indices and shared vertices, counting the .gltf and the local
// files its `uri`s name). Polygons count as their fan of n − 2 triangles where the corners are
// known (OBJ), as one triangle per face where only the face count is (PLY).
struct MeshSizeEstimate {
  std::uint64_t triangles = 0;
  std::uint64_t vertices = 0;
};

// Throws MeshLoadError for the same unreadable files as readMeshFile (missing, folder, device,
// extension, header counts the file cannot hold). Files the mesh file names outside the folder
// tree of `options` are not counted (readMeshFile refuses them). Throws Cancelled once
// options.cancel is set (polled while the file is scanned).
MeshSizeEstimate estimateMeshSize(const std::filesystem::path& path,
                                  const MeshReadOptions& options = {});

// Bytes of a .gltf file (`size` of them) plus the regular files its "uri" strings name
// (percent-decoded, beside it; data: URIs are inside the file already; files `rule` refuses are
// not counted, the load refuses them). A plain scan for `"uri"`, not a JSON parse: an estimate
// and the mesh reader's memory cap need no more.
std::uint64_t gltfBytes(const std::filesystem::path& path, std::uint64_t size,
                        const ReferencedFileRule& rule);

}  // namespace glint
