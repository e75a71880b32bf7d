#include "glint/mesh/inline_mesh.h"

#include <assimp/mesh.h>

#include <utility>

#include "glint/geometry/watertight_triangle.h"
#include "glint/mesh/mesh_repair.h"

namespace glint {
namespace {

// A double as the single-precision value a PLY file of it holds, back in double.
double single(double v) { return static_cast<double>(static_cast<float>(v)); }

MeshFile withDefaultMaterial(TriangleMesh part, std::size_t dropped) {
  MeshFile file;
  part.materialIndex = 0;
  file.parts.push_back(std::move(part));
  file.materials.push_back(MeshMaterial{"", kMeshDefaultMaterial, Color(), false});
  file.droppedTriangles = dropped;
  return file;
}

// Colours: every triangle keeps its own corners (no joining), degenerate ones dropped.
MeshFile coloredMesh(const MeshArrays& in) {
  TriangleMesh out;
  std::size_t dropped = 0;
  for (std::size_t t = 0; t + 2 < in.indices.size(); t += 3) {
    const std::uint32_t* corner = &in.indices[t];
    const auto at = [&](std::uint32_t v) {
      const Point3& p = in.positions[v];
      return Point3{single(p.x), single(p.y), single(p.z)};
    };
    if (isDegenerateTriangle(at(corner[0]), at(corner[1]), at(corner[2]))) {
      ++dropped;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = corner[k];
      out.indices.push_back(static_cast<std::uint32_t>(out.positions.size()));
      out.positions.push_back(at(v));
      if (!in.normals.empty()) {
        const Vec3& n = in.normals[v];
        out.normals.push_back(Normal3{single(n.x), single(n.y), single(n.z)});
      }
      out.colors.push_back(in.colors[v]);
    }
  }
  return withDefaultMaterial(std::move(out), dropped);
}

}  // namespace

MeshFile meshFromArrays(const MeshArrays& arrays) {
  if (!arrays.colors.empty()) return coloredMesh(arrays);
  // The aiMesh assimp's PLY importer makes of such a file, then the loader's own steps.
  aiMesh mesh;
  mesh.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh.mNumVertices = static_cast<unsigned>(arrays.positions.size());
  mesh.mVertices = new aiVector3D[mesh.mNumVertices];
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    const Point3& p = arrays.positions[v];
    mesh.mVertices[v] =
        aiVector3D(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
  }
  if (!arrays.normals.empty()) {
    mesh.mNormals = new aiVector3D[mesh.mNumVertices];
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const Vec3& n = arrays.normals[v];
      mesh.mNormals[v] =
          aiVector3D(static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z));
    }
  }
  mesh.mNumFaces = static_cast<unsigned>(arrays.indices.size() / 3);
  mesh.mFaces = new aiFace[mesh.mNumFaces];
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    aiFace& face = mesh.mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (unsigned k = 0; k < 3; ++k) face.mIndices[k] = arrays.indices[3 * std::size_t{f} + k];
  }
  std::size_t dropped = 0;
  JoinedMesh joined = joinMesh(mesh, dropped);
  return withDefaultMaterial(convertMesh(mesh, std::move(joined)), dropped);
}

}  // namespace glint
