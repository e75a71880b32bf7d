// The import of a checked mesh file with assimp, in the calling process, and its conversion into a
// MeshFile: only the importer of the file's extension, only regular files opened and the files it
// names only within the folder tree of a ReferencedFileRule (file_access.h), the faces repaired
// (mesh_repair.h) and the materials mapped onto glint's. Internal to the mesh loader: it runs in
// the import child (import_child.h), never in the renderer's own process.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "glint/core/file_access.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// `extension` is the file's checked extension (checkedExtension); `rule` the folder tree of the
// files it names. Throws MeshLoadError. An OBJ file goes through importSimpleObj first, unless
// GLINT_OBJ_READER=assimp (objFastPathDisabled); what it does not take, importMeshWithAssimp reads.
MeshFile importMesh(const std::filesystem::path& path, const std::string& extension,
                    const ReferencedFileRule& rule);

// An OBJ file of the plain subset (obj_fast_parse.h) read by glint's parser and then converted as
// importMeshWithAssimp converts assimp's scene (the same post-processing and repairs): the same
// MeshFile. Nothing for a file outside the subset or one that fails (the caller then lets assimp
// read it, and report the failure in its words) — except a file outside the subset with a
// malformed statement (findObjFault, obj_check.h: a word that is no number, an index past the
// file's vertices...): MeshLoadError naming the statement's line and column (meshErrorPlace),
// whether assimp would refuse the file or repair it.
std::optional<MeshFile> importSimpleObj(const std::filesystem::path& path,
                                        const ReferencedFileRule& rule);

// importMesh with assimp's own importer for the extension, whatever the file.
MeshFile importMeshWithAssimp(const std::filesystem::path& path, const std::string& extension,
                              const ReferencedFileRule& rule);

}  // namespace glint
