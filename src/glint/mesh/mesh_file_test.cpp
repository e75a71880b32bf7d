// The instancing of a mesh file into world space (instantiateMesh): positions by the transform,
// normals by its inverse transpose, winding kept on the side of the normals under a mirror.
#include "glint/mesh/mesh_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

TEST(MeshFile, InstancingTransformsPositionsAndNormals) {
  // One triangle in the plane x + y = 1 with its normal (1, 1, 0)/√2 written in the file.
  TempDir dir;
  const fs::path obj =
      dir.write("tilted.obj", "v 1 0 0\nv 0 1 0\nv 0 1 1\nvn 1 1 0\nf 1//1 2//1 3//1\n");
  const MeshFile file = readMeshFile(obj);
  ASSERT_EQ(file.parts.size(), 1u);
  ASSERT_EQ(file.parts[0].positions.size(), 3u);

  // Scale x by 2, then translate: the plane becomes x/2 + y = 1, whose normal is (1, 2, 0)/√5 —
  // the inverse transpose, not the transform applied to the normal (which would give (2, 1, 0)).
  const Transform t = Transform::translate({10, 20, 30}) * Transform::scale(2, 1, 1);
  const std::vector<TriangleMesh> world = instantiateMesh(file, t, /*smooth=*/true);
  ASSERT_EQ(world.size(), 1u);
  const TriangleMesh& mesh = world[0];
  ASSERT_EQ(mesh.positions.size(), 3u);
  for (std::size_t v = 0; v < 3; ++v) {
    const Point3& p = file.parts[0].positions[v];
    EXPECT_EQ(mesh.positions[v], (Point3{2 * p.x + 10, p.y + 20, p.z + 30}));
    EXPECT_NEAR(mesh.normals[v].x, 1 / std::sqrt(5.0), 1e-7);
    EXPECT_NEAR(mesh.normals[v].y, 2 / std::sqrt(5.0), 1e-7);
    EXPECT_NEAR(mesh.normals[v].z, 0, 1e-12);
    EXPECT_NEAR(length(mesh.normals[v]), 1, 1e-12);
  }
  EXPECT_EQ(mesh.indices, file.parts[0].indices);

  // Flat: the same triangles without vertex normals.
  const std::vector<TriangleMesh> flat = instantiateMesh(file, t, /*smooth=*/false);
  EXPECT_TRUE(flat[0].normals.empty());
  EXPECT_EQ(flat[0].positions, mesh.positions);

  // No transform: the file's data unchanged.
  const std::vector<TriangleMesh> same = instantiateMesh(file, std::nullopt, true);
  EXPECT_EQ(same[0].positions, file.parts[0].positions);
  EXPECT_EQ(same[0].normals, file.parts[0].normals);
}

TEST(MeshFile, MirroringTransformKeepsGeometricAndVertexNormalsOnOneSide) {
  const fs::path obj = kModels / "OBJ/cube_usemtl.obj";
  ASSERT_TRUE(installed(obj));
  const MeshFile file = readMeshFile(obj);
  const auto sameSide = [](const TriangleMesh& mesh) {
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      const std::uint32_t* i = &mesh.indices[3 * t];
      const Vec3 n = cross(mesh.positions[i[1]] - mesh.positions[i[0]],
                           mesh.positions[i[2]] - mesh.positions[i[0]]);
      if (dot(n, mesh.normals[i[0]]) <= 0) return false;
    }
    return true;
  };
  for (const TriangleMesh& part : instantiateMesh(file, std::nullopt, true)) {
    ASSERT_TRUE(sameSide(part)) << "the file's winding agrees with its normals";
  }
  for (const TriangleMesh& part : instantiateMesh(file, Transform::scale(-1, 2, 1), true)) {
    EXPECT_TRUE(sameSide(part));
  }
}

}  // namespace
}  // namespace glint::mesh_test
