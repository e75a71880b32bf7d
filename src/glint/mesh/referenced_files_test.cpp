// The folder tree the files a mesh file names must lie in (DESIGN.md §7): glTF buffers and OBJ
// material libraries outside the scene file's folder — by "..", by an absolute name, or through a
// symbolic link — refuse the mesh file, naming the reference; inside it they are read.
#include "glint/core/file_access.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_size_estimate.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

using ::testing::HasSubstr;

// One triangle as a .gltf whose positions are in the buffer file `uri` (36 bytes).
std::string triangleGltf(const std::string& uri) {
  return R"({"asset":{"version":"2.0"},"buffers":[{"uri":")" + uri +
         R"(","byteLength":36}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{)"
         R"("bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],)"
         R"("max":[1,1,0]}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
         R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
}

// The buffer of triangleGltf: (0, 0, 0), (1, 0, 0), (0, 1, 0) as little-endian float32.
std::string triangleBuffer() {
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string bytes(sizeof xyz, '\0');
  std::memcpy(bytes.data(), xyz, sizeof xyz);
  return bytes;
}

// What readMeshFile says of `mesh` read for a scene in `sceneFolder`.
std::string reasonIn(const fs::path& mesh, const fs::path& sceneFolder) {
  try {
    return fmt::format(
        "(loaded {} triangles)",
        readMeshFile(mesh, MeshReadOptions{.sceneFolder = sceneFolder}).triangleCount());
  } catch (const MeshLoadError& e) {
    return e.what();
  }
}

// scene/ holds the scene's files; outside.bin and outside.mtl lie beside it, outside its tree.
class MeshReferencedFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = dir_.path() / "scene";
    fs::create_directories(scene_ / "models");
    dir_.write("outside.bin", triangleBuffer());
    dir_.write("outside.mtl", "newmtl red\nKd 1 0 0\n");
    dir_.write("scene/inside.bin", triangleBuffer());
    dir_.write("scene/inside.mtl", "newmtl red\nKd 1 0 0\n");
  }
  fs::path write(const std::string& name, const std::string& text) {
    return dir_.write("scene/" + name, text);
  }

  TempDir dir_;
  fs::path scene_;
};

TEST_F(MeshReferencedFiles, AGltfBufferOutsideTheSceneFolderIsRefusedNamingIt) {
  const fs::path mesh = write("up.gltf", triangleGltf("../outside.bin"));
  EXPECT_EQ(reasonIn(mesh, scene_),
            fmt::format("it refers to '../outside.bin', which lies outside the folder '{}' (a "
                        "mesh file may only name files in its scene file's folder and below)",
                        scene_.string()));
  // However many "..": the name is resolved before anything is opened.
  EXPECT_THAT(
      reasonIn(write("passwd.gltf", triangleGltf("../../../../../../../../etc/passwd")), scene_),
      HasSubstr("it refers to '../../../../../../../../etc/passwd', which lies outside"));
  // Inside the tree, also up from a subfolder, the buffer is read.
  EXPECT_EQ(reasonIn(write("in.gltf", triangleGltf("inside.bin")), scene_), "(loaded 1 triangles)");
  EXPECT_EQ(reasonIn(write("models/sub.gltf", triangleGltf("../inside.bin")), scene_),
            "(loaded 1 triangles)");
  // The estimate does not count what the load refuses.
  EXPECT_EQ(estimateMeshSize(mesh, MeshReadOptions{.sceneFolder = scene_}).triangles,
            fs::file_size(mesh) / 12);
}

// A buffer that does not exist is the importer's "could not open", whatever names it probes for
// it: given as "../m.gltf" from a subfolder, assimp's glTF importer also tries "../../x.bin"
// (its folder joined twice), which lies outside; that probe read nothing and refused the file as
// if it named a file outside. Checked from inside a subfolder of the scene.
TEST_F(MeshReferencedFiles, AMissingBufferIsNotFoundNotRefused) {
  write("missing.gltf", triangleGltf("nothere.bin"));
  const fs::path before = fs::current_path();
  fs::current_path(scene_ / "models");
  const std::string reason = reasonIn("../missing.gltf", "..");
  const std::string plain = reasonIn("../missing.gltf", "");
  fs::current_path(before);
  EXPECT_THAT(reason, HasSubstr("could not open referenced file \"nothere.bin\""));
  EXPECT_THAT(plain, HasSubstr("could not open referenced file \"nothere.bin\""));
}

TEST_F(MeshReferencedFiles, ASymbolicLinkLeadingOutsideIsRefused) {
  fs::create_symlink(dir_.path() / "outside.bin", scene_ / "link.bin");
  fs::create_directory_symlink(dir_.path(), scene_ / "up");
  EXPECT_THAT(reasonIn(write("link.gltf", triangleGltf("link.bin")), scene_),
              HasSubstr(fmt::format("it refers to 'link.bin', which leads to '{}' outside the "
                                    "folder '{}' through a symbolic link",
                                    (dir_.path() / "outside.bin").string(), scene_.string())));
  EXPECT_THAT(reasonIn(write("folder.gltf", triangleGltf("up/outside.bin")), scene_),
              HasSubstr("it refers to 'up/outside.bin', which leads to"));
  // A link that stays inside is followed.
  fs::create_symlink(scene_ / "inside.bin", scene_ / "models/inside.bin");
  EXPECT_EQ(reasonIn(write("models/in.gltf", triangleGltf("inside.bin")), scene_),
            "(loaded 1 triangles)");
}

TEST_F(MeshReferencedFiles, WhereAnOpenedFileReallyLeadsIsCheckedAgain) {
  // A link replaced between the check of its name and the open (a race the checks before opening
  // cannot see) is caught on the descriptor.
  const ReferencedFileRule rule(scene_ / "m.gltf", scene_);
  const ReadableFile outside = openForReading(dir_.path() / "outside.bin");
  ASSERT_GE(outside.fd, 0);
  EXPECT_EQ(rule.openedRefusal(outside.fd, scene_ / "swapped.bin"),
            fmt::format("it refers to 'swapped.bin', which leads to '{}' outside the folder '{}' "
                        "through a symbolic link (a mesh file may only name files in its scene "
                        "file's folder and below)",
                        (dir_.path() / "outside.bin").string(), scene_.string()));
  const ReadableFile inside = openForReading(scene_ / "inside.bin");
  ASSERT_GE(inside.fd, 0);
  EXPECT_EQ(rule.openedRefusal(inside.fd, scene_ / "inside.bin"), "");
}

TEST_F(MeshReferencedFiles, AnObjMaterialLibraryOutsideIsRefused) {
  const std::string triangle = "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
  EXPECT_THAT(reasonIn(write("up.obj", "mtllib ../outside.mtl" + triangle), scene_),
              HasSubstr("it refers to '../outside.mtl', which lies outside the folder"));
  const MeshFile inside = readMeshFile(write("in.obj", "mtllib inside.mtl" + triangle),
                                       MeshReadOptions{.sceneFolder = scene_});
  ASSERT_EQ(inside.materials.size(), 1u);
  EXPECT_EQ(inside.materials[0].material.kd, Color(1, 0, 0));
}

TEST_F(MeshReferencedFiles, AMeshOutsideTheSceneFolderMayNameFilesInItsOwnFolder) {
  // The mesh file lies beside the scene folder: its own folder is its tree.
  const fs::path library = dir_.path() / "library";
  fs::create_directories(library / "data");
  dir_.write("library/data/buffer.bin", triangleBuffer());
  EXPECT_EQ(reasonIn(dir_.write("library/ok.gltf", triangleGltf("data/buffer.bin")), scene_),
            "(loaded 1 triangles)");
  EXPECT_EQ(reasonIn(dir_.write("library/up.gltf", triangleGltf("../outside.bin")), scene_),
            fmt::format("it refers to '../outside.bin', which lies outside the folder '{}' (a "
                        "mesh file outside the scene file's folder may only name files in its own "
                        "folder and below)",
                        library.string()));
  // Without a scene folder, likewise.
  EXPECT_THAT(reasonIn(dir_.write("library/up2.gltf", triangleGltf("../outside.bin")), ""),
              HasSubstr("(a mesh file may only name files in its own folder and below)"));
}

}  // namespace
}  // namespace glint::mesh_test
