// Triangle meshes as binary PLY files (little-endian, single-precision vertices: what assimp reads
// back exactly), for `glint convert`'s large meshes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace glint {

struct PlyMesh {
  std::vector<double> positions;       // x, y, z per vertex
  std::vector<double> normals;         // nx, ny, nz per vertex, or empty
  std::vector<std::uint32_t> indices;  // three per triangle
};

// The bytes of a binary_little_endian 1.0 PLY file: element vertex (float x y z [nx ny nz]) and
// element face (list uchar int vertex_indices), in the given order.
std::string binaryPly(const PlyMesh& mesh);

}  // namespace glint
