// Hostile scene files refused with a clear error before memory is committed (DESIGN.md §7): YAML
// alias bombs (nested and one-level), an alias inside its own anchor, deep nesting, a file past
// the 256 MiB cap, and a mesh whose estimated memory (mesh + BVH, with the film) exceeds the
// loader's memory budget — each an error at its place in the file.
#include "glint/scene/scene_limits.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "glint/factories/scene_loader.h"
#include "glint/factories/scene_test_support.h"
#include "glint/mesh/mesh_loader.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using testing::errorsOf;
using testing::expectOneError;
using ::testing::HasSubstr;
using testing::kMinimal;

// Seconds `f` takes: a refusal must come before the work it refuses.
template <typename F>
double secondsFor(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(SceneLimits, NestedAliasBombIsAnErrorAtTheAliasThatCrossesTheLimit) {
  // "Billion laughs": 10 levels of ten aliases each would stand for 10^10 nodes in 500 bytes.
  std::string text = std::string(kMinimal) + "l0: &l0 [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n";
  for (int k = 1; k <= 10; ++k) {
    text += fmt::format("l{}: &l{} [", k, k);
    for (int i = 0; i < 10; ++i) text += fmt::format("{}*l{}", i ? ", " : "", k - 1);
    text += "]\n";
  }
  // Levels 1–5 repeat 1.2 million nodes; each alias of level 6 (line 9) another 1.1 million: its
  // third alias (column 20) crosses 2^22.
  const double seconds = secondsFor([&] { expectOneError(text, 9, 20, "(a YAML alias bomb?)"); });
  EXPECT_LT(seconds, 2.0);
}

TEST(SceneLimits, OneLevelRepetitionOfALargeObjectIsRefused) {
  // A polygon of 1,000 points (4,005 nodes) as 1,100 objects: 4.4 million nodes to walk from
  // 40 KB of text; the 1,048th alias crosses 2^22.
  const auto scene = [](int copies) {
    std::string text = std::string(kMinimal) + "shapes:\n  p: &p {type: polygon, vertices: [";
    for (int i = 0; i < 1000; ++i) text += fmt::format("{}[{}, 0, 0]", i ? ", " : "", i);
    text += "]}\nobjects: [";
    for (int i = 0; i < copies; ++i) text += i ? ", *p" : "*p";
    return text + "]\n";
  };
  const std::vector<Diagnostic> refused = errorsOf(scene(1100));
  ASSERT_FALSE(refused.empty());
  EXPECT_EQ(refused[0].where.line, 5) << refused[0].format();
  EXPECT_EQ(refused[0].where.column, 11 + 4 * 1047) << refused[0].format();
  EXPECT_THAT(refused[0].message, HasSubstr("more than the limit of 4194304"));
}

TEST(SceneLimits, AnAliasInsideItsOwnAnchorIsAnError) {
  expectOneError(std::string(kMinimal) + "objects: &o [*o]\n", 3, 14, "contains it");
}

TEST(SceneLimits, NestingTooDeepIsAnError) {
  const std::string text =
      std::string(kMinimal) + "objects: " + std::string(3000, '[') + std::string(3000, ']') + "\n";
  const std::vector<Diagnostic> errors = errorsOf(text);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].where.line, 3);
  EXPECT_THAT(errors[0].message, HasSubstr("nested too deeply"));
}

TEST(SceneLimits, ASceneFilePastTheSizeCapIsRefusedWhileReading) {
  // A sparse file: 256 MiB + 1 byte of zeros on disk costs no space.
  const fs::path file = fs::temp_directory_path() / fmt::format("glint_huge_{}.yaml", ::getpid());
  {
    const int fd = ::open(file.c_str(), O_CREAT | O_TRUNC | O_WRONLY, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, (off_t{256} << 20) + 1), 0);
    ::close(fd);
  }
  try {
    loadScene(file);
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_EQ(e.diagnostics()[0].where.line, 0);  // names only the file
    EXPECT_THAT(e.diagnostics()[0].message, HasSubstr("larger than 256 MiB"));
  }
  fs::remove(file);
}

// A scene in its own folder with one OBJ of 1,000 triangles and 1,002 vertices: a flat strip, all
// triangles facing +z, so assimp neither joins nor splits a vertex.
class MeshBudgetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() / fmt::format("glint_budget_{}", ::getpid());
    fs::create_directories(folder_);
    std::ofstream obj(folder_ / "strip.obj");
    // Vertex 2i + 1 is (i, 0, 0), vertex 2i + 2 is (i, 1, 0) (1-based).
    for (int i = 0; i <= 500; ++i) obj << fmt::format("v {} 0 0\nv {} 1 0\n", i, i);
    for (int i = 0; i < 500; ++i) {
      obj << fmt::format("f {} {} {}\nf {} {} {}\n", 2 * i + 1, 2 * i + 3, 2 * i + 2, 2 * i + 2,
                         2 * i + 3, 2 * i + 4);
    }
  }
  void TearDown() override { fs::remove_all(folder_); }

  // Loads the scene with `objects` mesh objects from line 5 on, under `budget` bytes.
  std::vector<Diagnostic> errorsWithBudget(std::uint64_t budget, int objects = 1) const {
    std::string text =
        std::string(kMinimal) + "lights: [{type: point, position: [0, 0, 5]}]\n" + "objects:\n";
    for (int i = 0; i < objects; ++i) text += "  - {type: mesh, file: strip.obj}\n";
    try {
      loadSceneFromString(text, "test.yaml", folder_, LoadOptions{.memoryBudget = budget});
    } catch (const SceneError& e) {
      return e.diagnostics();
    }
    return {};
  }

  fs::path folder_;
};

TEST_F(MeshBudgetTest, AMeshPastTheMemoryBudgetIsAnErrorAtItsObject) {
  // The estimate: two copies of 12·1000 + 48·1002 bytes and 104 B per triangle of BVH build =
  // 224,192 B, plus the 4 × 3 film (288 B).
  const std::uint64_t film = filmBytes(4, 3);
  ASSERT_EQ(film, 288u);
  const std::vector<Diagnostic> errors = errorsWithBudget(224192 + film - 1);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].where.line, 5);
  EXPECT_THAT(errors[0].message,
              HasSubstr("cannot load mesh file 'strip.obj': its estimated 1.0 thousand triangles "
                        "need about 218.9 KiB as a mesh and its BVH"));
  EXPECT_THAT(errors[0].message, HasSubstr("more than the memory limit of 219.2 KiB"));
  const std::vector<Diagnostic> fits = errorsWithBudget(224192 + film);
  EXPECT_TRUE(fits.empty()) << fits[0].format();
}

TEST_F(MeshBudgetTest, EveryInstanceOfAFileCountsAgainstTheBudget) {
  // A second instance adds one world copy and its BVH build share (164,096 B): refused at its own
  // line.
  const std::uint64_t film = filmBytes(4, 3);
  const std::vector<Diagnostic> fits = errorsWithBudget(224192 + 164096 + film, 2);
  EXPECT_TRUE(fits.empty()) << fits[0].format();
  const std::vector<Diagnostic> errors = errorsWithBudget(224192 + 164096 + film - 1, 2);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].where.line, 6);
  EXPECT_THAT(errors[0].message, HasSubstr("another instance of its 1.0 thousand triangles"));
}

}  // namespace
}  // namespace glint
