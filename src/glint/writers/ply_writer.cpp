#include "glint/writers/ply_writer.h"

#include <bit>
#include <cstring>

#include <fmt/format.h>

namespace glint {
namespace {

template <class T>
void append(std::string& out, T value) {
  static_assert(std::endian::native == std::endian::little, "PLY bytes are written little-endian");
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

}  // namespace

std::string binaryPly(const PlyMesh& mesh) {
  const std::size_t vertices = mesh.positions.size() / 3;
  const bool normals = !mesh.normals.empty();
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by glint convert\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n{}"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      vertices, normals ? "property float nx\nproperty float ny\nproperty float nz\n" : "",
      mesh.indices.size() / 3);
  out.reserve(out.size() + vertices * (normals ? 24 : 12) + mesh.indices.size() / 3 * 13);
  for (std::size_t v = 0; v < vertices; ++v) {
    for (int k = 0; k < 3; ++k) append(out, static_cast<float>(mesh.positions[3 * v + k]));
    if (normals) {
      for (int k = 0; k < 3; ++k) append(out, static_cast<float>(mesh.normals[3 * v + k]));
    }
  }
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    append(out, std::uint8_t{3});
    for (int k = 0; k < 3; ++k) append(out, static_cast<std::int32_t>(mesh.indices[t + k]));
  }
  return out;
}

}  // namespace glint
