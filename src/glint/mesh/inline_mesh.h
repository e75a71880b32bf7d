// Meshes given as arrays inside a scene (an inline `mesh` object's positions, normals, colors and
// indices; the polygons of an NFF or Tachyon file) as the MeshFile glint would keep for a PLY file
// holding the same arrays, so that a scene converted to YAML with its large meshes written as PLY
// files (`glint convert`) renders the same bytes.
#pragma once

#include <cstdint>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

struct MeshArrays {
  std::vector<Point3> positions;
  std::vector<Vec3> normals;           // one per position, or none
  std::vector<Color> colors;           // one per position (linear), or none
  std::vector<std::uint32_t> indices;  // three per triangle, each < positions.size()
};

// The mesh as glint keeps a mesh file's: positions and normals in single precision (what a PLY file
// holds and assimp reads), degenerate triangles dropped and counted (droppedTriangles) by the same
// rule as a file's, vertices of equal position and normal shared — the mesh loader's own joining
// and conversion (mesh_repair.h), so the result equals that of the PLY file
// writeBinaryPly(arrays) makes. A mesh with colours is not joined (vertices of equal position may
// differ in colour). Its one material is kMeshDefaultMaterial (fromFile false), as for a PLY file.
// Requires valid indices (the factory checks them).
MeshFile meshFromArrays(const MeshArrays& arrays);

}  // namespace glint
