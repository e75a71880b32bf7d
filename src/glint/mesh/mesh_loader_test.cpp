// Mesh files through assimp (DESIGN.md §5 `mesh`, §7): real files no one here wrote, from Debian's
// assimp-testmodels package — OBJ with MTL, PLY, binary and ASCII STL, glTF binary — whose triangle
// counts, bounds and materials the tests read from the files themselves; normals (file, generated,
// crease angle, repaired), the instancing transform, degenerate and invalid triangles, the cache
// and the reasons a file is refused.
#include "glint/mesh/mesh_loader.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "glint/core/bounds.h"
#include "glint/readers/yaml_tree.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Where Debian's assimp-testmodels puts the models (dpkg -L assimp-testmodels).
const fs::path kModels = "/usr/share/assimp/models";

// Fails (never skips) when the package is missing, saying how to install it.
::testing::AssertionResult installed(const fs::path& model) {
  if (fs::is_regular_file(model)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << model << " is missing: the mesh tests read Debian's assimp-testmodels package; run "
         << "scripts/setup.sh (or apt-get install assimp-testmodels)";
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A folder of its own under the system's temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("glint_mesh_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

Bounds3 boundsOf(const std::vector<TriangleMesh>& parts) {
  Bounds3 b;
  for (const TriangleMesh& part : parts) {
    for (std::uint32_t i : part.indices) b = unite(b, part.positions[i]);
  }
  return b;
}

void expectBounds(const Bounds3& actual, const Bounds3& expected, double tolerance) {
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(actual.lo[axis], expected.lo[axis], tolerance) << "axis " << axis;
    EXPECT_NEAR(actual.hi[axis], expected.hi[axis], tolerance) << "axis " << axis;
  }
}

// Every vertex normal of every part is unit length, and every triangle is non-degenerate.
void expectWellFormed(const MeshFile& file) {
  for (const TriangleMesh& part : file.parts) {
    ASSERT_EQ(part.indices.size() % 3, 0u);
    ASSERT_EQ(part.normals.size(), part.positions.size());
    for (const Normal3& n : part.normals) ASSERT_NEAR(length(n), 1, 1e-12);
    for (std::uint32_t i : part.indices) ASSERT_LT(i, part.positions.size());
    for (std::size_t t = 0; t < part.triangleCount(); ++t) {
      const Point3& a = part.positions[part.indices[3 * t]];
      const Point3& b = part.positions[part.indices[3 * t + 1]];
      const Point3& c = part.positions[part.indices[3 * t + 2]];
      ASSERT_GT(length(cross(b - a, c - a)), 0);
    }
    ASSERT_LT(part.materialIndex, file.materials.size());
  }
}

// ----------------------------------------------------------------------- OBJ with MTL (spider)

// What the OBJ text itself says: triangles per `usemtl` material (a face of n corners is n − 2
// triangles), which of them have zero area (triangles only: twice the area exactly 0 in double
// from the written coordinates), and the bounds of the vertices the faces use.
struct ObjFacts {
  std::map<std::string, std::size_t> trianglesByMaterial;  // all, zero-area ones included
  std::map<std::string, std::size_t> zeroAreaByMaterial;
  std::size_t triangles = 0;
  std::size_t zeroArea = 0;
  Bounds3 bounds;
};

ObjFacts readObjFacts(const fs::path& path) {
  ObjFacts facts;
  std::vector<Point3> vertices;
  std::vector<long> used;
  std::istringstream lines(readText(path));
  std::string line;
  std::string material;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "v") {
      Point3 p;
      words >> p.x >> p.y >> p.z;
      vertices.push_back(p);
    } else if (keyword == "usemtl") {
      words >> material;
    } else if (keyword == "f") {
      std::size_t corners = 0;
      std::string corner;
      while (words >> corner) {
        const long index = std::stol(corner.substr(0, corner.find('/')));
        used.push_back(index > 0 ? index - 1 : static_cast<long>(vertices.size()) + index);
        ++corners;
      }
      if (corners == 3) {
        const Point3& a = vertices.at(static_cast<std::size_t>(used[used.size() - 3]));
        const Point3& b = vertices.at(static_cast<std::size_t>(used[used.size() - 2]));
        const Point3& c = vertices.at(static_cast<std::size_t>(used[used.size() - 1]));
        if (cross(b - a, c - a) == Vec3{}) {
          ++facts.zeroAreaByMaterial[material];
          ++facts.zeroArea;
        }
      }
      facts.trianglesByMaterial[material] += corners - 2;
      facts.triangles += corners - 2;
    }
  }
  for (long i : used) facts.bounds = unite(facts.bounds, vertices.at(static_cast<std::size_t>(i)));
  return facts;
}

// `Kd` of every `newmtl` in an MTL file.
std::map<std::string, Color> readMtlDiffuse(const fs::path& path) {
  std::map<std::string, Color> kd;
  std::istringstream lines(readText(path));
  std::string line;
  std::string name;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "newmtl") words >> name;
    if (keyword == "Kd") words >> kd[name].r >> kd[name].g >> kd[name].b;
  }
  return kd;
}

TEST(MeshLoader, ObjWithMtlTrianglesBoundsAndDiffuseColours) {
  const fs::path obj = kModels / "OBJ/spider.obj";
  ASSERT_TRUE(installed(obj));
  const ObjFacts facts = readObjFacts(obj);
  const std::map<std::string, Color> diffuse = readMtlDiffuse(kModels / "OBJ/spider.mtl");
  ASSERT_EQ(facts.triangles, 1368u);  // the file's own count, a guard on the parsing above
  ASSERT_EQ(diffuse.size(), 5u);
  // The spider's legs hold faces whose three (distinct) vertices share one position.
  ASSERT_GT(facts.zeroArea, 0u);

  const MeshFile file = readMeshFile(obj);
  expectWellFormed(file);
  EXPECT_EQ(file.droppedTriangles, facts.zeroArea);
  EXPECT_EQ(file.triangleCount(), facts.triangles - facts.zeroArea);
  // OBJ coordinates are written with 6 digits; assimp keeps them as float.
  expectBounds(boundsOf(file.parts), facts.bounds, 1e-5);

  std::map<std::string, std::size_t> trianglesByMaterial;
  for (const TriangleMesh& part : file.parts) {
    const MeshMaterial& m = file.materials[part.materialIndex];
    trianglesByMaterial[m.name] += part.triangleCount();
    ASSERT_TRUE(diffuse.count(m.name)) << m.name;
    EXPECT_TRUE(m.fromFile);
    const Color expected = diffuse.at(m.name);
    EXPECT_NEAR(m.material.kd.r, expected.r, 1e-7) << m.name;
    EXPECT_NEAR(m.material.kd.g, expected.g, 1e-7) << m.name;
    EXPECT_NEAR(m.material.kd.b, expected.b, 1e-7) << m.name;
    EXPECT_EQ(m.material.ka, m.material.kd) << "ka = kd: the ambient light shows the colour";
    EXPECT_EQ(m.material.ks, Color(0));  // Ks 0 in the MTL
    EXPECT_EQ(m.emission, Color(0));
  }
  for (const auto& [name, triangles] : facts.trianglesByMaterial) {
    const auto it = facts.zeroAreaByMaterial.find(name);
    EXPECT_EQ(trianglesByMaterial[name],
              triangles - (it == facts.zeroAreaByMaterial.end() ? 0 : it->second))
        << name;
  }
  // Only the materials the faces use are kept (Brusttex is defined but never used).
  EXPECT_EQ(file.materials.size(), facts.trianglesByMaterial.size());
}

TEST(MeshLoader, MtlSpecularShininessAndTheFilesOwnNormals) {
  // cube_usemtl: 12 faces over materials mtl (Ks 0.05, Ns 200), mtl2 (Ks 0.375, Ns 16) and mtl3,
  // which the MTL does not define; every face has a `vn` normal along an axis.
  const fs::path obj = kModels / "OBJ/cube_usemtl.obj";
  ASSERT_TRUE(installed(obj));
  const ObjFacts facts = readObjFacts(obj);
  const MeshFile file = readMeshFile(obj);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount(), facts.triangles);
  expectBounds(boundsOf(file.parts), {{0, 0, 0}, {1, 1, 1}}, 0);

  std::map<std::string, const MeshMaterial*> byName;
  for (const MeshMaterial& m : file.materials) byName[m.name] = &m;
  ASSERT_TRUE(byName.count("mtl") && byName.count("mtl2"));
  EXPECT_EQ(byName["mtl"]->material.kd, Color(1));
  EXPECT_NEAR(byName["mtl"]->material.ks.r, 0.05, 1e-7);
  EXPECT_EQ(byName["mtl"]->material.shininess, 200);
  EXPECT_NEAR(byName["mtl2"]->material.ks.g, 0.375, 1e-7);
  EXPECT_EQ(byName["mtl2"]->material.shininess, 16);

  // The file's normals are kept, not regenerated: each is exactly ± an axis and is the normal of
  // the faces that use it (a box's faces are perpendicular to them).
  for (const TriangleMesh& part : file.parts) {
    for (const Normal3& n : part.normals) {
      EXPECT_EQ(std::abs(n.x) + std::abs(n.y) + std::abs(n.z), 1)
          << n.x << " " << n.y << " " << n.z;
    }
    for (std::size_t t = 0; t < part.triangleCount(); ++t) {
      const Point3& a = part.positions[part.indices[3 * t]];
      const Point3& b = part.positions[part.indices[3 * t + 1]];
      const Point3& c = part.positions[part.indices[3 * t + 2]];
      const Vec3 faceNormal = normalize(cross(b - a, c - a));
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(std::abs(dot(faceNormal, part.normals[part.indices[3 * t + k]])), 1, 1e-12);
      }
    }
  }
}

// ------------------------------------------------------------------------------------------- PLY

TEST(MeshLoader, AsciiPlyTrianglesBoundsAndTheDefaultMaterial) {
  const fs::path ply = kModels / "PLY/Wuson.ply";
  ASSERT_TRUE(installed(ply));
  // The header gives the vertex and face counts; each face line starts with its corner count.
  std::istringstream lines(readText(ply));
  std::string line;
  std::size_t vertexCount = 0;
  std::size_t faceCount = 0;
  while (std::getline(lines, line) && line.rfind("end_header", 0) != 0) {
    std::istringstream words(line);
    std::string keyword, element;
    std::size_t count = 0;
    words >> keyword >> element >> count;
    if (keyword == "element" && element == "vertex") vertexCount = count;
    if (keyword == "element" && element == "face") faceCount = count;
  }
  ASSERT_EQ(vertexCount, 11184u);
  ASSERT_EQ(faceCount, 3732u);
  std::vector<Point3> vertices(vertexCount);
  for (Point3& p : vertices) {
    std::getline(lines, line);
    std::istringstream(line) >> p.x >> p.y >> p.z;
  }
  std::size_t triangles = 0;
  Bounds3 expected;
  for (std::size_t f = 0; f < faceCount; ++f) {
    std::getline(lines, line);
    std::istringstream words(line);
    std::size_t corners = 0;
    words >> corners;
    triangles += corners - 2;
    for (std::size_t k = 0; k < corners; ++k) {
      std::size_t index = 0;
      words >> index;
      expected = unite(expected, vertices.at(index));
    }
  }

  const MeshFile file = readMeshFile(ply);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount() + file.droppedTriangles, triangles);
  EXPECT_EQ(file.droppedTriangles, 0u);
  expectBounds(boundsOf(file.parts), expected, 1e-6);
  // PLY has no materials: glint's mid grey, not assimp's stand-in (kd 1, ks 1).
  ASSERT_EQ(file.materials.size(), 1u);
  EXPECT_FALSE(file.materials[0].fromFile);
  EXPECT_EQ(file.materials[0].material.kd, kMeshDefaultMaterial.kd);
  EXPECT_EQ(file.materials[0].material.ka, Color(0.7));
  EXPECT_EQ(file.materials[0].material.ks, Color(0));
}

TEST(MeshLoader, GeneratedNormalsKeepEdgesSharperThanTheCreaseAngle) {
  // cube.ply: six quads without normals. Its 90° edges exceed the 80° crease angle, so every
  // generated normal is the normal of its face: ± an axis.
  const fs::path ply = kModels / "PLY/cube.ply";
  ASSERT_TRUE(installed(ply));
  const MeshFile file = readMeshFile(ply);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount(), 12u);  // 6 faces of 4 corners in the file
  expectBounds(boundsOf(file.parts), {{0, 0, 0}, {1, 1, 1}}, 0);
  // And each corner carries the normal of its own face, not that of another face around the
  // shared vertex of the file: 8 positions, three normals each.
  for (const TriangleMesh& part : file.parts) {
    EXPECT_EQ(part.positions.size(), 24u);
    for (std::size_t t = 0; t < part.triangleCount(); ++t) {
      const std::uint32_t* i = &part.indices[3 * t];
      const Vec3 face = normalize(cross(part.positions[i[1]] - part.positions[i[0]],
                                        part.positions[i[2]] - part.positions[i[0]]));
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(dot(face, part.normals[i[k]]), 1, 1e-6);
    }
  }
}

// The OBJ text of a regular icosahedron with vertices (0, ±1, ±φ) and their cyclic permutations
// (edge 2), faces outward, and no normals.
std::string icosahedronObj() {
  const double phi = (1 + std::sqrt(5.0)) / 2;
  std::vector<Point3> v;
  for (double a : {-1.0, 1.0}) {
    for (double b : {-phi, phi}) {
      v.push_back({0, a, b});
      v.push_back({a, b, 0});
      v.push_back({b, 0, a});
    }
  }
  std::ostringstream obj;
  obj.precision(17);
  for (const Point3& p : v) obj << "v " << p.x << " " << p.y << " " << p.z << "\n";
  const auto edge = [&](std::size_t i, std::size_t j) {
    return std::abs(distance(v[i], v[j]) - 2) < 1e-9;
  };
  for (std::size_t i = 0; i < v.size(); ++i) {
    for (std::size_t j = i + 1; j < v.size(); ++j) {
      for (std::size_t k = j + 1; k < v.size(); ++k) {
        if (!edge(i, j) || !edge(j, k) || !edge(k, i)) continue;
        const bool outward = dot(cross(v[j] - v[i], v[k] - v[i]), toVec(v[i])) > 0;
        obj << "f " << i + 1 << " " << (outward ? j : k) + 1 << " " << (outward ? k : j) + 1
            << "\n";
      }
    }
  }
  return obj.str();
}

// The icosahedron of icosahedronObj as loaded with generated smooth normals: 20 triangles over 12
// shared vertices, each with the direction of the vertex itself as its normal (by symmetry, the
// average of the five faces around it).
void expectIcosahedronWithVertexNormals(const MeshFile& file) {
  expectWellFormed(file);
  ASSERT_EQ(file.parts.size(), 1u);
  const TriangleMesh& part = file.parts[0];
  EXPECT_EQ(part.triangleCount(), 20u);
  ASSERT_EQ(part.positions.size(), 12u);  // shared: one normal per vertex
  for (std::size_t v = 0; v < part.positions.size(); ++v) {
    const Vec3 expected = normalize(toVec(part.positions[v]));
    EXPECT_NEAR(part.normals[v].x, expected.x, 1e-6) << "vertex " << v;
    EXPECT_NEAR(part.normals[v].y, expected.y, 1e-6) << "vertex " << v;
    EXPECT_NEAR(part.normals[v].z, expected.z, 1e-6) << "vertex " << v;
  }
}

TEST(MeshLoader, GeneratedNormalsAreSmoothBelowTheCreaseAngle) {
  // A regular icosahedron without normals. Around a vertex, the five face normals are at most
  // 70.5° apart (< 80°), so every corner's normal averages all five, which by symmetry gives the
  // direction of the vertex itself, and the corners of one vertex share one normal.
  TempDir dir;
  const std::string text = icosahedronObj();
  ASSERT_EQ(std::count(text.begin(), text.end(), 'f'), 20);
  expectIcosahedronWithVertexNormals(readMeshFile(dir.write("icosahedron.obj", text)));
}

// The vertex lines (coordinates as written) and 0-based faces of icosahedronObj, for writing the
// same solid in other formats.
struct IcosahedronText {
  std::vector<std::string> vertices;
  std::vector<std::array<std::size_t, 3>> faces;
};
IcosahedronText icosahedronText() {
  IcosahedronText out;
  std::istringstream obj(icosahedronObj());
  std::string line;
  while (std::getline(obj, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "v") out.vertices.push_back(line.substr(2));
    if (keyword != "f") continue;
    std::array<std::size_t, 3> face{};
    for (std::size_t& index : face) {
      words >> index;
      --index;
    }
    out.faces.push_back(face);
  }
  return out;
}

// The icosahedron of icosahedronObj as an indexed ASCII PLY without normals: 12 shared vertices.
std::string icosahedronPly() {
  const IcosahedronText ico = icosahedronText();
  std::ostringstream ply;
  ply << "ply\nformat ascii 1.0\nelement vertex " << ico.vertices.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << ico.faces.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const std::string& v : ico.vertices) ply << v << "\n";
  for (const auto& f : ico.faces) ply << "3 " << f[0] << " " << f[1] << " " << f[2] << "\n";
  return ply.str();
}

TEST(MeshLoader, IndexedFilesWithoutNormalsGetSmoothNormalsPerVertex) {
  // The same icosahedron, but indexed (PLY shares each vertex among its five faces): the generated
  // normal of a vertex must still average all five faces (the vertex direction), not keep the
  // normal of whichever face came last.
  TempDir dir;
  expectIcosahedronWithVertexNormals(readMeshFile(dir.write("icosahedron.ply", icosahedronPly())));
}

// ------------------------------------------------------------------------------ joined vertices

// The icosahedron of icosahedronObj as ASCII STL: 20 facets of three vertices each, stored apart
// (STL has no shared vertices), with facet normals glint discards.
std::string icosahedronStl() {
  const IcosahedronText ico = icosahedronText();
  std::ostringstream stl;
  stl << "solid ico\n";
  for (const auto& face : ico.faces) {
    stl << "facet normal 0 0 0\nouter loop\n";
    for (const std::size_t index : face) stl << "vertex " << ico.vertices.at(index) << "\n";
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid ico\n";
  return stl.str();
}

TEST(MeshLoader, DeindexedStlCornersAreJoinedIntoSharedVertices) {
  // 60 corners in the file at 12 distinct positions, every corner's generated normal the smooth
  // one (the icosahedron's dihedral angles are below the crease angle): 12 shared vertices, the
  // same as the indexed OBJ of the same solid.
  TempDir dir;
  const MeshFile stl = readMeshFile(dir.write("icosahedron.stl", icosahedronStl()));
  expectWellFormed(stl);
  ASSERT_EQ(stl.parts.size(), 1u);
  EXPECT_EQ(stl.parts[0].triangleCount(), 20u);
  EXPECT_EQ(stl.parts[0].positions.size(), 12u);
  EXPECT_EQ(stl.droppedTriangles, 0u);
  const MeshFile obj = readMeshFile(dir.write("icosahedron.obj", icosahedronObj()));
  ASSERT_EQ(obj.parts.size(), 1u);
  // The same vertices in the same order (first use by the triangles, which are in the same order).
  ASSERT_EQ(obj.parts[0].positions.size(), 12u);
  for (std::size_t v = 0; v < 12; ++v) {
    EXPECT_NEAR(distance(stl.parts[0].positions[v], obj.parts[0].positions[v]), 0, 1e-6);
    EXPECT_NEAR(length(toVec(stl.parts[0].normals[v]) - toVec(obj.parts[0].normals[v])), 0, 1e-6);
  }
  EXPECT_EQ(stl.parts[0].indices, obj.parts[0].indices);
}

TEST(MeshLoader, CreasesKeepOneVertexPerNormal) {
  // A unit cube of 8 positions and 6 quads, without normals. Every 90° edge is a crease (beyond
  // the 80° crease angle), so each position carries three generated normals, one per face around
  // it: 24 vertices, each with its face's normal.
  TempDir dir;
  const MeshFile file = readMeshFile(
      dir.write("cube.obj",
                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"));
  expectWellFormed(file);
  ASSERT_EQ(file.parts.size(), 1u);
  const TriangleMesh& part = file.parts[0];
  EXPECT_EQ(part.triangleCount(), 12u);
  EXPECT_EQ(part.positions.size(), 24u);
  std::map<std::tuple<double, double, double>, int> normalsAt;
  for (const Point3& p : part.positions) ++normalsAt[{p.x, p.y, p.z}];
  EXPECT_EQ(normalsAt.size(), 8u);
  for (const auto& [position, normals] : normalsAt) EXPECT_EQ(normals, 3);
  for (std::size_t t = 0; t < part.triangleCount(); ++t) {
    const std::uint32_t* i = &part.indices[3 * t];
    const Vec3 face = normalize(cross(part.positions[i[1]] - part.positions[i[0]],
                                      part.positions[i[2]] - part.positions[i[0]]));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(dot(face, part.normals[i[k]]), 1, 1e-6);
  }
}

TEST(MeshLoader, SeamsOfSplitNormalsKeepBothNormals) {
  // Two triangles hinged on the edge of vertices 2 and 3. In `seam` each triangle gives the
  // shared edge its own normal (`vn`): the edge's two positions carry two normals each, so 6
  // vertices. In `smooth` both use one normal: 4 vertices. Corners that differ only in a texture
  // coordinate (glint does not use them) or in the sign of a zero coordinate are one vertex.
  TempDir dir;
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvt 0 0\nvt 1 1\n";
  const MeshFile seam = readMeshFile(
      dir.write("seam.obj", v + "vn 0 0 1\nvn 0 1 0\nf 1//1 2//1 3//1\nf 2//2 4//2 3//2\n"));
  ASSERT_EQ(seam.parts.size(), 1u);
  EXPECT_EQ(seam.parts[0].positions.size(), 6u);
  const std::vector<std::uint32_t> seamIndices{0, 1, 2, 3, 4, 5};
  EXPECT_EQ(seam.parts[0].indices, seamIndices);
  EXPECT_EQ(seam.parts[0].normals[1], Normal3(0, 0, 1));
  EXPECT_EQ(seam.parts[0].normals[3], Normal3(0, 1, 0));
  EXPECT_EQ(seam.parts[0].positions[1], seam.parts[0].positions[3]);

  const MeshFile smooth = readMeshFile(
      dir.write("smooth.obj", v + "v -0 0 -0\nvn 0 0 1\nf 5/1/1 2/1/1 3/1/1\nf 2/2/1 4/2/1 3/1/1\n"
                                  "f 1/2/1 3/1/1 2/2/1\n"));
  ASSERT_EQ(smooth.parts.size(), 1u);
  EXPECT_EQ(smooth.parts[0].positions.size(), 4u);
  const std::vector<std::uint32_t> smoothIndices{0, 1, 2, 1, 3, 2, 0, 2, 1};
  EXPECT_EQ(smooth.parts[0].indices, smoothIndices);
}

// ------------------------------------------------------------------------------------------- STL

TEST(MeshLoader, BinaryStlCountFromTheHeaderAndBoundsFromTheRecords) {
  const fs::path stl = kModels / "STL/Spider_binary.stl";
  ASSERT_TRUE(installed(stl));
  // 80-byte header, uint32 triangle count, then 50 bytes per triangle: normal and three vertices
  // as little-endian float32, and a 2-byte attribute.
  const std::string bytes = readText(stl);
  ASSERT_GE(bytes.size(), 84u);
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  ASSERT_EQ(bytes.size(), 84 + 50 * std::size_t{count});
  Bounds3 expected;
  for (std::size_t t = 0; t < count; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      float xyz[3];
      std::memcpy(xyz, bytes.data() + 84 + 50 * t + 12 + 12 * k, 12);
      expected = unite(expected, Point3{xyz[0], xyz[1], xyz[2]});
    }
  }

  const MeshFile file = readMeshFile(stl);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount() + file.droppedTriangles, count);
  expectBounds(boundsOf(file.parts), expected, 0);
  // Facet normals were replaced by smooth vertex normals, so facets share vertices: far fewer
  // vertices than the 3 per facet the file stores.
  std::size_t vertices = 0;
  for (const TriangleMesh& part : file.parts) vertices += part.positions.size();
  EXPECT_LT(vertices, std::size_t{count});
  ASSERT_EQ(file.materials.size(), 1u);
  EXPECT_FALSE(file.materials[0].fromFile);
}

TEST(MeshLoader, AsciiStlCountAndBoundsFromTheText) {
  const fs::path stl = kModels / "STL/Spider_ascii.stl";
  ASSERT_TRUE(installed(stl));
  std::istringstream lines(readText(stl));
  std::string line;
  std::size_t facets = 0;
  Bounds3 expected;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "facet") ++facets;
    if (keyword == "vertex") {
      Point3 p;
      words >> p.x >> p.y >> p.z;
      expected = unite(expected, p);
    }
  }
  ASSERT_GT(facets, 0u);
  const MeshFile file = readMeshFile(stl);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount() + file.droppedTriangles, facets);
  expectBounds(boundsOf(file.parts), expected, 1e-6);
}

// ------------------------------------------------------------------------------------ glTF binary

// The JSON chunk of a .glb (12-byte header, then the chunk's uint32 length and type, then JSON),
// read with glint's own YAML reader (JSON is YAML).
yaml::Stream glbJson(const fs::path& path, std::string& storage) {
  const std::string bytes = readText(path);
  std::uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);
  storage = bytes.substr(20, length);
  return yaml::parse(storage);
}

double number(const yaml::Node& node) { return std::stod(node.scalar()); }
std::size_t count(const yaml::Node& node) { return std::stoul(node.scalar()); }

TEST(MeshLoader, GlbBoxTrianglesAndBoundsThroughItsNodeMatrix) {
  const fs::path glb = kModels / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
  ASSERT_TRUE(installed(glb));
  std::string json;
  const yaml::Stream doc = glbJson(glb, json);
  const yaml::Node& root = doc.root;
  // One mesh of one primitive under node 1, the child of node 0 which has a (column-major) matrix.
  const yaml::Node primitive = root.find("meshes")[0].find("primitives")[0];
  const yaml::Node accessors = root.find("accessors");
  const std::size_t triangles =
      count(accessors[count(primitive.find("indices"))].find("count")) / 3;
  const yaml::Node position = accessors[count(primitive.find("attributes").find("POSITION"))];
  const yaml::Node matrix = root.find("nodes")[0].find("matrix");
  ASSERT_EQ(matrix.size(), 16u);
  Bounds3 expected;
  for (int corner = 0; corner < 8; ++corner) {
    double p[3];
    for (int axis = 0; axis < 3; ++axis) {
      p[axis] =
          number(((corner >> axis) & 1) ? position.find("max")[axis] : position.find("min")[axis]);
    }
    Point3 q;
    for (int row = 0; row < 3; ++row) {
      q[row] = number(matrix[12 + row]);
      for (int col = 0; col < 3; ++col) q[row] += number(matrix[4 * col + row]) * p[col];
    }
    expected = unite(expected, q);
  }

  const MeshFile file = readMeshFile(glb);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount(), triangles);
  EXPECT_EQ(triangles, 12u);
  expectBounds(boundsOf(file.parts), expected, 1e-7);
  ASSERT_EQ(file.materials.size(), 1u);
  EXPECT_EQ(file.materials[0].name, "Texture");
  EXPECT_TRUE(file.materials[0].fromFile);
}

TEST(MeshLoader, GlbNodeHierarchyIsBakedEveryMeshInstanceCounted) {
  // 2CylinderEngine: 82 nodes, 29 meshes, some used by several nodes. PreTransformVertices makes
  // one copy per use, so the expected count walks the scene's node tree.
  const fs::path glb = kModels / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  ASSERT_TRUE(installed(glb));
  std::string json;
  const yaml::Stream doc = glbJson(glb, json);
  const yaml::Node& root = doc.root;
  const yaml::Node nodes = root.find("nodes");
  const yaml::Node meshes = root.find("meshes");
  const yaml::Node accessors = root.find("accessors");
  std::size_t triangles = 0;
  const std::function<void(std::size_t)> walk = [&](std::size_t n) {
    const yaml::Node node = nodes[n];
    if (node.find("mesh").isDefined()) {
      const yaml::Node primitives = meshes[count(node.find("mesh"))].find("primitives");
      for (std::size_t p = 0; p < primitives.size(); ++p) {
        const yaml::Node mode = primitives[p].find("mode");
        ASSERT_TRUE(!mode.isDefined() || count(mode) == 4);  // triangles
        triangles += count(accessors[count(primitives[p].find("indices"))].find("count")) / 3;
      }
    }
    const yaml::Node children = node.find("children");
    for (std::size_t c = 0; c < children.size(); ++c) walk(count(children[c]));
  };
  const yaml::Node sceneNodes = root.find("scenes")[count(root.find("scene"))].find("nodes");
  for (std::size_t i = 0; i < sceneNodes.size(); ++i) walk(count(sceneNodes[i]));
  ASSERT_EQ(triangles, 121496u);

  const MeshFile file = readMeshFile(glb);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount() + file.droppedTriangles, triangles);
}

TEST(MeshLoader, NonFiniteVerticesAreDroppedNotFatal) {
  // BoxWithInfinites: a box whose position data holds infinities.
  const fs::path glb = kModels / "glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb";
  ASSERT_TRUE(installed(glb));
  try {
    const MeshFile file = readMeshFile(glb);
    expectWellFormed(file);
    EXPECT_GT(file.droppedTriangles, 0u);
    EXPECT_EQ(file.triangleCount() + file.droppedTriangles, 12u);
    for (const TriangleMesh& part : file.parts) {
      for (const Point3& p : part.positions) EXPECT_TRUE(isFinite(p));
    }
  } catch (const MeshLoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("degenerate"));  // every triangle touched an infinity
  }
}

// ------------------------------------------------------------------- degenerate and invalid faces

TEST(MeshLoader, DegenerateTrianglesAreDroppedAndCounted) {
  TempDir dir;
  // Two good triangles, one collinear (zero area), one with a repeated vertex.
  const fs::path obj = dir.write("degenerate.obj",
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 1 1 0\n"
                                 "f 1 2 3\nf 2 5 3\nf 1 2 4\nf 1 1 3\n");
  const MeshFile file = readMeshFile(obj);
  expectWellFormed(file);
  EXPECT_EQ(file.droppedTriangles, 2u);
  EXPECT_EQ(file.triangleCount(), 2u);
  // Vertex 4 (2, 0, 0) was used only by the dropped triangle: it is gone from the arrays too.
  EXPECT_EQ(file.parts[0].positions.size(), 4u);
  expectBounds(boundsOf(file.parts), {{0, 0, 0}, {1, 1, 0}}, 0);
}

TEST(MeshLoader, FacesWithIndicesOutOfRangeAreDroppedAndCounted) {
  // PLY, unlike OBJ, does not check its indices itself.
  TempDir dir;
  const fs::path ply = dir.write("bad_index.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face 3\n"
                                 "property list uchar int vertex_indices\nend_header\n"
                                 "0 0 0\n1 0 0\n0 1 0\n1 1 0\n"
                                 "3 0 1 2\n3 1 3 2\n4 0 1 7 2\n");
  const MeshFile file = readMeshFile(ply);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount(), 2u);
  EXPECT_EQ(file.droppedTriangles, 2u);  // the quad with index 7 stood for two triangles
}

TEST(MeshLoader, InvalidFileNormalsAreRepairedFromTheFaces) {
  // A zero normal in the file (vn 0 0 0) is replaced by the mean of the faces around the vertex.
  TempDir dir;
  const fs::path obj = dir.write("zero_normal.obj",
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 0\n"
                                 "f 1//1 2//2 3//1\n");
  const MeshFile file = readMeshFile(obj);
  expectWellFormed(file);
  ASSERT_EQ(file.triangleCount(), 1u);
  for (const Normal3& n : file.parts[0].normals) EXPECT_EQ(n, Normal3(0, 0, 1));
}

// ------------------------------------------------------------------------------------ instancing

TEST(MeshLoader, InstancingTransformsPositionsAndNormals) {
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

TEST(MeshLoader, MirroringTransformKeepsGeometricAndVertexNormalsOnOneSide) {
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

// ------------------------------------------------------------------------------ cache and errors

TEST(MeshLoader, CacheReadsEachFileOnce) {
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

std::string reasonFor(const fs::path& path) {
  try {
    readMeshFile(path);
  } catch (const MeshLoadError& e) {
    return e.what();
  }
  return "(loaded)";
}

TEST(MeshLoader, ReasonsAFileIsRefused) {
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

TEST(MeshLoader, HeaderCountsTheFileCannotHoldAreRefusedBeforeReading) {
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
  // The same header with counts the file does hold loads.
  const MeshFile small = readMeshFile(dir.write("d.ply", ply("ascii", "3", "1")));
  EXPECT_EQ(small.triangleCount(), 1u);
}

// ------------------------------------------------------------------- hostile files (DESIGN §7)

TEST(MeshLoader, OnlyTheDocumentedFormatsReachAnImporter) {
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

TEST(MeshLoader, FilesAMeshNamesAreReadOnlyWhenRegular) {
  TempDir dir;
  // An MTL that is a FIFO would block the load forever; /dev/zero would never end. Both are
  // skipped: the OBJ loads with the default material.
  const fs::path fifo = dir.path() / "pipe.mtl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const char* library : {"pipe.mtl", "/dev/zero"}) {
    const fs::path obj =
        dir.write("m.obj", std::string("mtllib ") + library +
                               "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
    const MeshFile file = readMeshFile(obj);
    EXPECT_EQ(file.triangleCount(), 1u) << library;
  }
  // A glTF buffer on /dev/zero with a huge stated length is refused, not read.
  const std::string gltf =
      R"({"asset":{"version":"2.0"},"buffers":[{"uri":"/dev/zero","byteLength":100000000000}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,)"
      R"("componentType":5126,"count":3,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":)"
      R"({"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  EXPECT_THAT(reasonFor(dir.write("zero.gltf", gltf)), HasSubstr("invalid file"));
}

TEST(MeshLoader, FuzzerFindingsAreRefusedBeforeAssimpSeesThem) {
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

MeshSizeEstimate estimateOf(const fs::path& path) { return estimateMeshSize(path); }

TEST(MeshLoader, SizeEstimatesFromHeadersAndCounts) {
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

TEST(MeshLoader, TheFileSizeBoundsEveryEstimate) {
  // MeshCache skips the scan when kMeshBudgetBytesPerFileByte × size + kMeshBudgetSlackBytes fits
  // the budget: that must bound what the estimate would count for the densest files possible.
  TempDir dir;
  const auto budgetBytes = [](const MeshSizeEstimate& e) {
    const double t = static_cast<double>(e.triangles);
    return 2 * meshCopyBytes(t, static_cast<double>(e.vertices)) + kBvhBytesPerTriangle * t;
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
  // Vertex lines alone reach it: the factor is not loose.
  const fs::path dense = dir.write("dense.obj", vertices);
  EXPECT_DOUBLE_EQ(budgetBytes(estimateMeshSize(dense)) + kMeshBudgetSlackBytes, bound(dense));

  // With a budget the bound fits, the cache still counts the real sizes of what it read.
  const fs::path obj = dir.write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  MeshCache cache;
  ASSERT_EQ(cache.load(obj, MeshBudget{std::uint64_t{1} << 30, 0})->triangleCount(), 1u);
  EXPECT_DOUBLE_EQ(cache.meshBytes(), 2 * meshCopyBytes(1, 3) + kBvhBytesPerTriangle);
  EXPECT_THROW(cache.load(dir.path() / "none.obj", MeshBudget{std::uint64_t{1} << 30, 0}),
               MeshLoadError);
}

TEST(MeshLoader, TheMemoryEstimateRefusesBeforeReadingAndCountsEveryInstance) {
  TempDir dir;
  // A flat strip of 1,000 triangles over 1,002 vertices, all facing +z: assimp neither joins nor
  // splits a vertex. One copy is 12·1000 + 48·1002 = 60,096 B; a first load costs two copies (the
  // file's, the instance's) plus 22 B per triangle of BVH: 142,192 B.
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

  MeshCache refused;
  try {
    refused.load(obj, MeshBudget{200000, 57809});  // 142,192 + 57,809 > 200,000
    ADD_FAILURE() << "loaded";
  } catch (const MeshTooLargeError& e) {
    EXPECT_THAT(e.what(), HasSubstr("its estimated 1.0 thousand triangles need about 138.9 KiB"));
    EXPECT_THAT(e.what(), HasSubstr("more than the memory limit of 195.3 KiB"));
  }
  EXPECT_EQ(refused.filesRead(), 0u);  // refused before reading

  MeshCache cache;
  const auto file = cache.load(obj, MeshBudget{200000, 57808});  // exactly at the limit
  ASSERT_EQ(file->triangleCount(), 1000u);
  ASSERT_EQ(file->parts.size(), 1u);
  ASSERT_EQ(file->parts[0].positions.size(), 1002u);
  EXPECT_DOUBLE_EQ(cache.meshBytes(), 142192);
  // A second instance adds one copy and its BVH share (82,096 B), refused past the limit.
  EXPECT_THROW(cache.load(obj, MeshBudget{142192 + 82095, 0}), MeshTooLargeError);
  EXPECT_EQ(cache.load(obj, MeshBudget{142192 + 82096, 0}), file);
  EXPECT_DOUBLE_EQ(cache.meshBytes(), 142192 + 82096);
  EXPECT_EQ(cache.filesRead(), 1u);
}

}  // namespace
}  // namespace glint
