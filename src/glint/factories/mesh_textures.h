// The textures a mesh file's materials name (DESIGN.md §9: OBJ/MTL map_Kd, map_Ks, map_Ke,
// map_Bump/bump, norm; glTF baseColorTexture, emissiveTexture, normalTexture), read through the
// scene's TextureLibrary and bound to the material's keys.
#pragma once

#include <filesystem>

#include "glint/factories/texture_library.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

// A mesh file's bump map displaces its surface by up to this fraction of the file's bounding-box
// diagonal (heights 0..1 scaled): files give no scale of their own that assimp passes on.
inline constexpr double kMeshBumpFraction = 0.005;

// The bindings of one material of `file` (found at meshPath; files it names must lie in the
// folder tree ReferencedFileRule gives for sceneFolder): diffuse → kd and ka (a mesh material's ka
// is its kd), specular → ks, emissive → emission, normal → normal map, bump → bump map. A
// textured value is the material's constant times the texture (OBJ: Kd × map_Kd; glTF:
// baseColorFactor × baseColorTexture). Files named with '\' (Windows exporters) are read with '/',
// glTF URIs percent-decoded. Throws ImageReadError "its diffuse texture 'x': why" for a texture
// that is missing, unreadable, corrupt, outside the folder tree, or over the memory budget.
MaterialTextures meshMaterialTextures(const MeshFile& file, const MeshMaterial& material,
                                      const std::filesystem::path& meshPath,
                                      const std::filesystem::path& sceneFolder,
                                      TextureLibrary& textures);

// A texture name as a mesh file wrote it → a relative path: '\' → '/', %XX decoded (glTF URIs).
std::string meshTexturePath(std::string_view written);

}  // namespace glint
