// Mesh objects in whole scenes (DESIGN.md §7): a scene load cancelled while a mesh file is read
// stops at once; a mesh file naming a file outside the scene's folder is an error at its object.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "glint/core/cancel.h"
#include "glint/factories/scene_loader.h"
#include "glint/mesh/import_child.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using ::testing::HasSubstr;

// The smallest scene around mesh objects: a camera, an image, a light.
constexpr const char* kSceneStart =
    "camera: {position: [0, 0, 50], look_at: [0, 0, 0], fov: 40}\n"
    "image: {width: 8, height: 8}\n"
    "lights: [{type: point, position: [0, 0, 60]}]\n"
    "objects:\n";

// A folder of its own under the system's temporary folder, removed with everything in it.
class SceneFolder {
 public:
  SceneFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            fmt::format("glint_mesh_limits_{}_{}", info->name(), ::getpid());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~SceneFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  SceneFolder(const SceneFolder&) = delete;
  SceneFolder& operator=(const SceneFolder&) = delete;
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << bytes;
    return file;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

TEST(MeshInScene, ACancelledSceneLoadStopsWhileAMeshFileIsRead) {
  SceneFolder folder;
  folder.write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  // Every mesh read takes 10 s (a slow importer); the cancel comes after 200 ms.
  setImportChildDelayForTesting(10s);
  std::atomic<bool> cancel{false};
  std::chrono::steady_clock::time_point cancelledAt;
  std::thread canceller([&] {
    std::this_thread::sleep_for(200ms);
    cancelledAt = std::chrono::steady_clock::now();
    cancel = true;
  });
  const std::string scene = std::string(kSceneStart) + "  - {type: mesh, file: t.obj}\n";
  EXPECT_THROW(
      loadSceneFromString(scene, "test.yaml", folder.path(), LoadOptions{.cancel = &cancel}),
      Cancelled);
  const auto stopped = std::chrono::steady_clock::now();
  canceller.join();
  setImportChildDelayForTesting(0ms);
  EXPECT_LT(stopped - cancelledAt, 1s);
}

TEST(MeshInScene, AMeshNamingAFileOutsideTheScenesFolderIsAnErrorAtItsObject) {
  SceneFolder folder;
  fs::create_directories(folder.path() / "scene");
  folder.write("outside.mtl", "newmtl red\nKd 1 0 0\n");
  folder.write("scene/up.obj",
               "mtllib ../outside.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  const std::string scene = std::string(kSceneStart) + "  - {type: mesh, file: up.obj}\n";
  try {
    loadSceneFromString(scene, "test.yaml", folder.path() / "scene");
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_EQ(e.diagnostics()[0].where.line, 5);
    EXPECT_THAT(e.diagnostics()[0].message,
                HasSubstr("cannot load mesh file 'up.obj': it refers to '../outside.mtl', which "
                          "lies outside the folder"));
  }
}

}  // namespace
}  // namespace glint
