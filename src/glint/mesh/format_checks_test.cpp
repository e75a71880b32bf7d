// The reasons a mesh file is refused (DESIGN.md §7): missing, a folder, a device, an extension
// glint does not read, no triangles, header counts the file cannot hold, files it names that are
// not regular, and the fuzzing findings the checks stop before assimp sees them.
#include "glint/mesh/format_checks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>

#include "glint/mesh/mesh_cache.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_size_estimate.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

using ::testing::HasSubstr;

TEST(MeshFormatChecks, ReasonsAFileIsRefused) {
  TempDir dir;
  EXPECT_EQ(reasonFor(dir.path() / "missing.obj"), "no such file");
  EXPECT_THAT(reasonFor(dir.path()), HasSubstr("folder"));
  EXPECT_THAT(reasonFor("/dev/null"), HasSubstr("not a regular file"));
  EXPECT_THAT(reasonFor(dir.write("notes.txt", "Hello, this is not a mesh.\n")),
              HasSubstr("not a mesh format"));
  EXPECT_THAT(reasonFor(dir.write("notes.obj", "Hello, this is not a mesh.\n")),
              HasSubstr("no triangles"));
  EXPECT_THAT(reasonFor(dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\n")),
              HasSubstr("no triangles"));
  EXPECT_THAT(reasonFor(dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")),
              HasSubstr("all 1 triangles are degenerate"));
  const fs::path points = kModels / "OBJ/point_cloud.obj";
  ASSERT_TRUE(installed(points));
  EXPECT_THAT(reasonFor(points), HasSubstr("no triangles"));
  const fs::path empty = kModels / "invalid/empty.obj";
  ASSERT_TRUE(installed(empty));
  EXPECT_THAT(reasonFor(empty), HasSubstr("invalid file"));
  if (::geteuid() != 0) {  // root reads everything
    const fs::path locked = dir.write("locked.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    fs::permissions(locked, fs::perms::none);
    EXPECT_THAT(reasonFor(locked), HasSubstr("permission denied"));
  }
}

TEST(MeshFormatChecks, HeaderCountsTheFileCannotHoldAreRefusedBeforeReading) {
  // assimp reserves memory for a PLY's or OFF's declared counts before reading the elements: these
  // few bytes would otherwise cost gigabytes and minutes.
  TempDir dir;
  const std::string header =
      "ply\nformat {}\nelement vertex {}\nproperty float x\nproperty float y\n"
      "property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n";
  const auto ply = [&](const char* format, const char* vertices, const char* faces) {
    std::string text = header;
    for (const char* value : {format, vertices, faces}) text.replace(text.find("{}"), 2, value);
    return text + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  };
  EXPECT_THAT(reasonFor(dir.write("a.ply", ply("ascii", "300000000", "1"))),
              HasSubstr("its header declares 300.0 million vertex and 1 face elements, more than "
                        "its"));
  EXPECT_THAT(reasonFor(dir.write("b.ply", ply("binary_little_endian", "3", "90000000"))),
              HasSubstr("more than its"));
  EXPECT_THAT(reasonFor(dir.write("c.ply", ply("ascii", "3", "300000000"))),
              HasSubstr("declares 300.0 million faces, more than the limit of 268.4 million"));
  // A vertex element without properties weighs nothing, so only the count limit refuses it (a
  // count past 2^64 must not reach an integer conversion), and face elements count together.
  EXPECT_THAT(
      reasonFor(dir.write("e.ply", "ply\nformat ascii 1.0\nelement vertex 1e30\nend_header\n")),
      HasSubstr("declares 1.0e+30 vertices, more than the limit of 4.3 billion"));
  EXPECT_THAT(reasonFor(dir.write("f.ply",
                                  "ply\nformat ascii 1.0\nelement face 200000000\nelement face "
                                  "200000000\nend_header\n")),
              HasSubstr("faces, more than the limit of 268.4 million"));
  // The same header with counts the file does hold loads.
  const MeshFile small = readMeshFile(dir.write("d.ply", ply("ascii", "3", "1")));
  EXPECT_EQ(small.triangleCount(), 1u);
}

// ------------------------------------------------------------------- hostile files (DESIGN §7)

TEST(MeshFormatChecks, PolygonsOfTooManyCornersAreRefusedBeforeTriangulation) {
  TempDir dir;
  // A fuzzing finding: assimp's ASCII PLY reader took 400000 as a face's corner count (for a
  // uchar list) and read zeros past the end. The body check (ply_check.h) now refuses that line;
  // a face that really has 20000 corners is refused before triangulating it would take minutes.
  EXPECT_THAT(reasonFor(dir.write("fuzz.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 2\nproperty float y\n"
                                  "element face 1\nproperty list uchar int vertex_indices\n"
                                  "end_header\n400000 0")),
              HasSubstr("line 8, column 8: more values than 'vertex' 1 of 2 holds"));
  std::string star =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float y\nelement face 1\nproperty "
      "list int int vertex_indices\nend_header\n0\n1\n20000";
  for (int i = 0; i < 20000; ++i) star += i % 2 ? " 1" : " 0";
  EXPECT_THAT(reasonFor(dir.write("star.ply", star + "\n")),
              HasSubstr("corners, more than the limit of 16384"));
  // A convex polygon of 2000 corners (a disc's cap) is read, as 1998 triangles.
  std::string disc =
      "ply\nformat ascii 1.0\nelement vertex 2000\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 1\nproperty list int int "
      "vertex_indices\nend_header\n";
  for (int i = 0; i < 2000; ++i) {
    const double angle = 2 * 3.141592653589793 * i / 2000;
    disc += std::to_string(std::cos(angle)) + " " + std::to_string(std::sin(angle)) + " 0\n";
  }
  disc += "2000";
  for (int i = 0; i < 2000; ++i) disc += " " + std::to_string(i);
  disc += "\n";
  EXPECT_EQ(readMeshFile(dir.write("disc.ply", disc)).triangleCount(), 1998u);
}

TEST(MeshFormatChecks, CountsPastTheFilesEndFailForMemoryNotTime) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "the mesh reader's address space is not capped under AddressSanitizer";
#else
  // A fuzzing finding: a uint8 list count of 44294967295, which assimp's ASCII PLY reader took
  // and filled with zeros read past the file's end (gigabytes, until the reader's 30 s limit).
  // The reader's address space is capped by the file's size, and the body check refuses the count
  // before assimp reads it: refused at once.
  TempDir dir;
  std::string cube =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float32 x\nproperty float32 "
      "y\nproperty float32 z\nelement face 6\nproperty list uint8 int32 vertex_index\n"
      "end_header\n0 0 0\n0 0 1\n0 1 1\n0 1 0\n1 0 0\n1 0 1\n1 1 1\n1 1 0\n";
  cube += "4 0 1 2 3\n4 7 6 5 4\n44294967295 0 4 5 1\n4 1 5 6 2\n4 2 6 7 3\n4 3 7 4 0\n";
  const auto start = std::chrono::steady_clock::now();
  // Now the body check's words, at the count's place.
  EXPECT_THAT(
      reasonFor(dir.write("counts.ply", cube)),
      HasSubstr("line 20, column 1: '44294967295' is not a count of 'vertex_index' values"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
#endif
}

TEST(MeshFormatChecks, AGltfWhoseAccessorsClaimMoreThanItsBuffersHoldFailsForMemory) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "the mesh reader's address space is not capped under AddressSanitizer";
#else
  // A 577-byte .gltf whose sparse POSITION accessor claims 40 million vertices: assimp fills them
  // all (3 GB, then the 30 s limit). The reader's address space is capped by the .gltf's size and
  // its buffer files' (a data: URI here): refused at once.
  TempDir dir;
  const std::string data = "data:application/octet-stream;base64,AQAAAAAAgD8AAABAAABAQA==";
  const std::string gltf =
      R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
          "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
          "accessors": [{"componentType": 5126, "count": 39999999, "type": "VEC3",
                         "min": [0, 0, 0], "max": [1, 2, 3],
                         "sparse": {"count": 1, "indices": {"bufferView": 0, "componentType": 5125},
                                    "values": {"bufferView": 1}}}],
          "bufferViews": [{"buffer": 0, "byteLength": 4},
                          {"buffer": 0, "byteOffset": 4, "byteLength": 12}],
          "buffers": [{"byteLength": 16, "uri": ")" +
      data + R"("}]})";
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THAT(reasonFor(dir.write("sparse.gltf", gltf)), HasSubstr("not enough memory to read it"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
#endif
}

// A square of two triangles (its positions 4 bytes into the buffer), the positions' offset in
// their buffer view, the view's offset in the buffer and the index count as given.
std::string gltfSquare(int positionOffset, int viewOffset, int indexCount) {
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                   "byteOffset": )" +
         std::to_string(positionOffset) + R"(, "min": [-1, -1, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5125, "count": )" +
         std::to_string(indexCount) + R"(, "type": "SCALAR"}],
    "bufferViews": [{"buffer": 0, "byteOffset": )" +
         std::to_string(viewOffset) + R"(, "byteLength": 52},
                    {"buffer": 0, "byteOffset": 52, "byteLength": 24}],
    "buffers": [{"byteLength": 76, "uri": "data:application/octet-stream;base64,AAAAAAAAgL8AAIC/AAAAAAAAgD8AAIC/AAAAAAAAgD8AAIA/AAAAAAAAgL8AAIA/AAAAAAAAAAABAAAAAgAAAAAAAAACAAAAAwAAAA=="}]})";
}

// glTF 2.0's data alignment and whole triangles, which assimp does not check: a misaligned
// accessor gave vertices of garbage bits, a count of 5 indices one triangle and two lost indices.
TEST(MeshFormatChecks, GltfAccessorsMustBeAlignedAndTrianglesWhole) {
  TempDir dir;
  EXPECT_EQ(readMeshFile(dir.write("square.gltf", gltfSquare(4, 0, 6))).triangleCount(), 2u);
  EXPECT_THAT(reasonFor(dir.write("offset.gltf", gltfSquare(5, 0, 6))),
              HasSubstr("invalid file: accessor 0 starts at byte 5 of its buffer view, not a "
                        "multiple of its component size (4 bytes), as glTF 2.0 requires"));
  EXPECT_THAT(reasonFor(dir.write("view.gltf", gltfSquare(4, 2, 6))),
              HasSubstr("invalid file: accessor 0 starts at byte 6 of its buffer, not a multiple"));
  EXPECT_THAT(reasonFor(dir.write("five.gltf", gltfSquare(4, 0, 5))),
              HasSubstr("invalid file: primitive 0 of mesh 0 is a list of triangles of 5 indices, "
                        "not a multiple of 3"));
}

TEST(MeshFormatChecks, OnlyTheDocumentedFormatsReachAnImporter) {
  TempDir dir;
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  // The same valid OBJ text under other names: only .obj (any case) reads it.
  EXPECT_EQ(readMeshFile(dir.write("t.OBJ", triangle)).triangleCount(), 1u);
  for (const char* name :
       {"t.off", "t.3ds", "t.dae", "t.x", "t.fbx", "t.blend", "t.obj.txt", "t"}) {
    EXPECT_THAT(reasonFor(dir.write(name, triangle)), HasSubstr("not a mesh format glint reads"))
        << name;
  }
  EXPECT_THAT(reasonFor(dir.write("t", triangle)), HasSubstr("has no extension"));
  // A missing file says so whatever its name; an existing one is refused by name before it is
  // opened.
  EXPECT_EQ(reasonFor(dir.path() / "missing.dae"), "no such file");
  // Assimp's OFF reader (which crashed under fuzzing) is never reached, even for its test file.
  const fs::path off = kModels / "OFF/Cube.off";
  ASSERT_TRUE(installed(off));
  EXPECT_THAT(reasonFor(off), HasSubstr("not a mesh format glint reads: '.off'"));
  // A glTF 1.0 file goes to the glTF 2.0 importer only (assimp's 1.0 importer is removed).
  const fs::path gltf1 = kModels / "glTF/BoxTextured-glTF/BoxTextured.gltf";
  if (fs::is_regular_file(gltf1)) {
    EXPECT_THAT(reasonFor(gltf1), HasSubstr("invalid file"));
  }
}

TEST(MeshFormatChecks, AMeshFileThatIsAFifoIsRefusedWithoutOpeningIt) {
  // Opening a FIFO for reading blocks until a writer comes; reading it never ends while one
  // stays. The mesh file is stat'ed before it is opened, for the read and for the estimate.
  TempDir dir;
  for (const char* name : {"pipe.obj", "pipe.ply", "pipe.stl", "pipe.gltf", "pipe.glb"}) {
    const fs::path fifo = dir.path() / name;
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    withFifoWatchdog(fifo, [&] {
      EXPECT_EQ(reasonFor(fifo), "it is not a regular file") << name;
      EXPECT_THROW(estimateMeshSize(fifo), MeshLoadError) << name;
      MeshCache cache;
      EXPECT_THROW(cache.load(fifo, MeshBudget{std::uint64_t{1} << 30, 0}), MeshLoadError) << name;
    });
  }
}

TEST(MeshFormatChecks, FilesAMeshNamesAreReadOnlyWhenRegular) {
  TempDir dir;
  // An MTL that is a FIFO would block the load forever: it is not opened, and the mesh file that
  // names it is refused, naming it.
  const fs::path fifo = dir.path() / "pipe.mtl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string triangle = "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
  withFifoWatchdog(fifo, [&] {
    EXPECT_EQ(reasonFor(dir.write("m.obj", "mtllib pipe.mtl" + triangle)),
              "it refers to 'pipe.mtl', which is not a regular file (a file a mesh names is never "
              "read from a FIFO or a device)");
  });
  // /dev/zero would never end; assimp looks for it inside the mesh file's folder, where there is
  // none: the OBJ loads with the default material.
  EXPECT_EQ(readMeshFile(dir.write("z.obj", "mtllib /dev/zero" + triangle)).triangleCount(), 1u);
  // A glTF buffer on /dev/zero with a huge stated length is refused, not read.
  const std::string gltf =
      R"({"asset":{"version":"2.0"},"buffers":[{"uri":"/dev/zero","byteLength":100000000000}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,)"
      R"("componentType":5126,"count":3,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":)"
      R"({"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  EXPECT_THAT(reasonFor(dir.write("zero.gltf", gltf)), HasSubstr("invalid file"));
}

TEST(MeshFormatChecks, FuzzerFindingsAreRefusedBeforeAssimpSeesThem) {
  TempDir dir;
  // assimp 5.2's PLY reader looped without end (and without bound on memory) on a header with no
  // end_header; glint checks the header's lines first.
  const std::string start = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n";
  EXPECT_THAT(reasonFor(dir.write("open.ply", start + "0\n1\n2\n")),
              HasSubstr("its PLY header has no end_header line in its first 64.0 KiB"));
  // The same loop on "end_header" followed by a vertical tab, which assimp does not take for a
  // separator: glint's check reads the keyword as assimp does.
  EXPECT_THAT(reasonFor(dir.write("vt.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 1\n"
                                  "property float x\nend_header\v0.0\n")),
              HasSubstr("its PLY header has no end_header line in its first 64.0 KiB"));
  EXPECT_THAT(reasonFor(dir.write("fmt.ply", "ply\nformat utf8 1.0\nend_header\n")),
              HasSubstr("unknown format 'utf8'"));
  EXPECT_THAT(reasonFor(dir.write("notply.ply", "v 0 0 0\n")), HasSubstr("not a PLY file"));
  // A glTF line strip without positions made assimp ask for 2^32 faces (64 GiB).
  const std::string strip =
      R"({"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"count":1,"type":"VEC3"}],)"
      R"("meshes":[{"primitives":[{"attributes":{},"mode":3},{"attributes":{"POSITION":0},)"
      R"("mode":6}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  EXPECT_THAT(reasonFor(dir.write("strip.gltf", strip)),
              HasSubstr("primitive 0 of mesh 0 is a line strip of 0 vertices (at least 2 needed)"));
  std::string fan = strip;
  fan.replace(fan.find("\"mode\":3"), 8, "\"mode\":4");
  EXPECT_THAT(
      reasonFor(dir.write("fan.gltf", fan)),
      HasSubstr("primitive 1 of mesh 0 is a triangle fan of 1 vertices (at least 3 needed)"));
}

}  // namespace
}  // namespace glint::mesh_test
