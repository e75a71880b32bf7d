// The mesh cache (every file read once per scene load, failures remembered) and the memory
// estimate it checks before reading a file (DESIGN.md §7).
#include "glint/mesh/mesh_cache.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>

#include "glint/mesh/mesh_size_estimate.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

using ::testing::HasSubstr;

TEST(MeshCache, CacheReadsEachFileOnce) {
  const fs::path obj = kModels / "OBJ/cube_usemtl.obj";
  ASSERT_TRUE(installed(obj));
  MeshCache cache;
  const auto first = cache.load(obj);
  const auto second = cache.load(kModels / "OBJ/../OBJ/./cube_usemtl.obj");  // the same file
  EXPECT_EQ(first.get(), second.get());
  EXPECT_EQ(cache.filesRead(), 1u);
  const auto other = cache.load(kModels / "PLY/cube.ply");
  EXPECT_NE(other.get(), first.get());
  EXPECT_EQ(cache.filesRead(), 2u);

  // A failure is remembered as well.
  for (int i = 0; i < 2; ++i) {
    EXPECT_THROW(cache.load(kModels / "OBJ/no_such_file.obj"), MeshLoadError);
  }
  EXPECT_EQ(cache.filesRead(), 3u);
}

TEST(MeshCache, TheFileSizeBoundsEveryEstimate) {
  // MeshCache skips the scan when kMeshBudgetBytesPerFileByte × size + kMeshBudgetSlackBytes fits
  // the budget: that must bound what the estimate would count for the densest files possible.
  TempDir dir;
  const auto budgetBytes = [](const MeshSizeEstimate& e) {
    const double t = static_cast<double>(e.triangles);
    const double v = static_cast<double>(e.vertices);
    return meshCopyBytes(t, v) + meshInstanceBytes(t, v);
  };
  const auto bound = [](const fs::path& file) {
    return kMeshBudgetBytesPerFileByte * static_cast<double>(fs::file_size(file)) +
           kMeshBudgetSlackBytes;
  };
  std::string vertices;
  for (int i = 0; i < 1000; ++i) vertices += "v\n";
  std::string fans;
  for (int corners = 3; corners < 200; ++corners) {
    fans += "f";
    for (int k = 0; k < corners; ++k) fans += " 1";
    fans += "\n";
  }
  std::string facets;
  for (int i = 0; i < 1000; ++i) facets += "facet\n";
  const fs::path spider = kModels / "STL/Spider_binary.stl";
  ASSERT_TRUE(installed(spider));
  for (const fs::path& file :
       {dir.write("v.obj", vertices + "v"), dir.write("f.obj", fans + "f 1 1 1"),
        dir.write("mixed.obj", vertices + fans), dir.write("a.stl", facets + "facet"), spider}) {
    const MeshSizeEstimate estimate = estimateMeshSize(file);
    EXPECT_GT(estimate.triangles + estimate.vertices, 0u) << file;
    EXPECT_LE(budgetBytes(estimate), bound(file)) << file;
  }
  // `f` lines of 127 corners (256 bytes, the longest line the scan counts whole) come within 3 %
  // of it: the factor is not loose.
  std::string fan = "f";
  for (int k = 0; k < 127; ++k) fan += " 1";
  std::string fanLines;
  for (int i = 0; i < 100; ++i) fanLines += fan + "\n";
  const fs::path dense = dir.write("dense.obj", fanLines);
  EXPECT_GT(budgetBytes(estimateMeshSize(dense)) + kMeshBudgetSlackBytes, 0.97 * bound(dense));

  // With a budget the bound fits, the cache still counts the real sizes of what it read.
  const fs::path obj = dir.write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  MeshCache cache;
  ASSERT_EQ(cache.load(obj, MeshBudget{std::uint64_t{1} << 30, 0})->triangleCount(), 1u);
  EXPECT_DOUBLE_EQ(cache.meshBytes(), meshCopyBytes(1, 3) + meshInstanceBytes(1, 3));
  EXPECT_THROW(cache.load(dir.path() / "none.obj", MeshBudget{std::uint64_t{1} << 30, 0}),
               MeshLoadError);
}

TEST(MeshCache, TheMemoryEstimateRefusesBeforeReadingAndCountsEveryInstance) {
  TempDir dir;
  // A flat strip of 1,000 triangles over 1,002 vertices, all facing +z: assimp neither joins nor
  // splits a vertex. One copy is 12·1000 + 48·1002 = 60,096 B; a first load costs two copies (the
  // file's, the instance's) plus 104 B per triangle of BVH build: 224,192 B.
  std::string text;
  for (int i = 0; i <= 500; ++i) text += fmt::format("v {} 0 0\nv {} 1 0\n", i, i);
  for (int i = 0; i < 500; ++i) {
    text += fmt::format("f {} {} {}\nf {} {} {}\n", 2 * i + 1, 2 * i + 3, 2 * i + 2, 2 * i + 2,
                        2 * i + 3, 2 * i + 4);
  }
  const fs::path obj = dir.write("strip.obj", text);
  const MeshSizeEstimate estimate = estimateMeshSize(obj);
  ASSERT_EQ(estimate.triangles, 1000u);
  ASSERT_EQ(estimate.vertices, 1002u);
  EXPECT_DOUBLE_EQ(meshCopyBytes(1000, 1002), 60096);
  EXPECT_DOUBLE_EQ(meshInstanceBytes(1000, 1002), 60096 + 104000);

  MeshCache refused;
  try {
    refused.load(obj, MeshBudget{300000, 75809});  // 224,192 + 75,809 > 300,000
    ADD_FAILURE() << "loaded";
  } catch (const MeshTooLargeError& e) {
    EXPECT_THAT(e.what(), HasSubstr("its estimated 1.0 thousand triangles need about 218.9 KiB"));
    EXPECT_THAT(e.what(), HasSubstr("more than the memory limit of 293.0 KiB"));
  }
  EXPECT_EQ(refused.filesRead(), 0u);  // refused before reading

  MeshCache cache;
  const auto file = cache.load(obj, MeshBudget{300000, 75808});  // exactly at the limit
  ASSERT_EQ(file->triangleCount(), 1000u);
  ASSERT_EQ(file->parts.size(), 1u);
  ASSERT_EQ(file->parts[0].positions.size(), 1002u);
  EXPECT_DOUBLE_EQ(cache.meshBytes(), 224192);
  // A second instance adds one copy and its BVH build share (164,096 B), refused past the limit.
  EXPECT_THROW(cache.load(obj, MeshBudget{224192 + 164095, 0}), MeshTooLargeError);
  EXPECT_EQ(cache.load(obj, MeshBudget{224192 + 164096, 0}), file);
  EXPECT_DOUBLE_EQ(cache.meshBytes(), 224192 + 164096);
  EXPECT_EQ(cache.filesRead(), 1u);

  // A file read elsewhere (the quick look) and adopted is not read again, and its first budgeted
  // load counts as a fresh read from its real sizes (here equal to the estimate).
  MeshCache adopting;
  adopting.adopt(obj, file);
  EXPECT_THROW(adopting.load(obj, MeshBudget{300000, 75809}), MeshTooLargeError);
  EXPECT_EQ(adopting.load(obj, MeshBudget{300000, 75808}), file);
  EXPECT_DOUBLE_EQ(adopting.meshBytes(), 224192);
  EXPECT_EQ(adopting.load(obj, MeshBudget{224192 + 164096, 0}), file);
  EXPECT_DOUBLE_EQ(adopting.meshBytes(), 224192 + 164096);
  EXPECT_EQ(adopting.filesRead(), 0u);
  // Adopting a file the cache holds already changes nothing.
  adopting.adopt(obj, std::make_shared<const MeshFile>());
  EXPECT_EQ(adopting.load(obj), file);

  // Where the estimate exceeds the real sizes (1000 vertices no face uses), an adopted file is
  // checked by its real sizes only, a file not yet read by the estimate first.
  std::string unused;
  for (int i = 0; i < 1000; ++i) unused += fmt::format("v {} 0 0\n", i);
  const fs::path sparse =
      dir.write("sparse.obj", unused + "v 0 0 1\nv 0 1 1\nv 1 0 1\nf 1001 1002 1003\n");
  const MeshBudget tight{static_cast<std::uint64_t>(meshCopyBytes(1, 3) + meshInstanceBytes(1, 3)),
                         0};
  EXPECT_THROW(MeshCache().load(sparse, tight), MeshTooLargeError);
  MeshCache quickLook;
  quickLook.adopt(sparse, MeshCache().load(sparse));
  ASSERT_EQ(quickLook.load(sparse, tight)->parts[0].positions.size(), 3u);
}

}  // namespace
}  // namespace glint::mesh_test
