// The import of a checked mesh file with assimp, in the calling process, and its conversion into a
// MeshFile: only the importer of the file's extension, only regular files opened and the files it
// names only within the folder tree of a ReferencedFileRule (file_access.h), the faces repaired
// (mesh_repair.h) and the materials mapped onto glint's. Internal to the mesh loader: it runs in
// the import child (import_child.h), never in the renderer's own process.
#pragma once

#include <filesystem>
#include <string>

#include "glint/core/file_access.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// `extension` is the file's checked extension (checkedExtension); `rule` the folder tree of the
// files it names. Throws MeshLoadError.
MeshFile importMesh(const std::filesystem::path& path, const std::string& extension,
                    const ReferencedFileRule& rule);

}  // namespace glint
