// The size of a mesh file known before reading it: header counts, counted lines, glTF bytes.
#include "glint/mesh/mesh_size_estimate.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

MeshSizeEstimate estimateOf(const fs::path& path) { return estimateMeshSize(path); }

TEST(MeshSizeEstimate, SizeEstimatesFromHeadersAndCounts) {
  TempDir dir;
  // OBJ: `f` corners fan into n − 2 triangles; `v` lines are vertices; comments do not count.
  const MeshSizeEstimate obj = estimateOf(
      dir.write("q.obj",
                "# f 1 2 3\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\n"
                "f 1 2 5 # a comment 6 7\n  f 1/1/1 2/2/2 3/3/3 4/4/4 5/5/5\nvn 0 0 1\n"));
  EXPECT_EQ(obj.triangles, 2u + 1u + 3u);
  EXPECT_EQ(obj.vertices, 5u);
  // PLY: the header's counts, one triangle per face.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
  const MeshSizeEstimate p = estimateOf(dir.write("s.ply", ply));
  EXPECT_EQ(p.triangles, 2u);
  EXPECT_EQ(p.vertices, 4u);
  // Binary STL: the count in the header when the size matches it; ASCII: `facet` lines.
  const fs::path binary = kModels / "STL/Spider_binary.stl";
  ASSERT_TRUE(installed(binary));
  const std::string bytes = readText(binary);
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(estimateOf(binary).triangles, count);
  EXPECT_EQ(estimateOf(dir.write("a.stl",
                                 "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                 "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
                                 "  facet normal 0 0 1\nendfacet\nendsolid x\n"))
                .triangles,
            2u);
  // glTF: bytes / 12, the .gltf and the local buffers it names.
  const std::string gltf = R"({"buffers":[{"uri":"b.bin"},{"uri":"data:,abc"}]})";
  dir.write("b.bin", std::string(1200, '\0'));
  EXPECT_EQ(estimateOf(dir.write("g.gltf", gltf)).triangles, (gltf.size() + 1200) / 12);
  // Unreadable files fail as readMeshFile would.
  EXPECT_THROW(estimateMeshSize(dir.path() / "none.obj"), MeshLoadError);
  EXPECT_THROW(estimateMeshSize(dir.write("x.dae", "")), MeshLoadError);
}

}  // namespace
}  // namespace glint::mesh_test
