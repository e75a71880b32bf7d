// Mesh files through assimp (DESIGN.md §5 `mesh`): real files no one here wrote, from Debian's
// assimp-testmodels package — OBJ with MTL, PLY, binary and ASCII STL, glTF binary — whose triangle
// counts, bounds and materials the tests read from the files themselves.
#include "glint/mesh/assimp_import.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "glint/mesh/format_checks.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

using ::testing::HasSubstr;

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

TEST(MeshImport, ObjWithMtlTrianglesBoundsAndDiffuseColours) {
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

// An OBJ's `usemtl` of a name no MTL file defines (the MTL left behind, or another one) has no
// material from the file: the mid-grey default, as an OBJ without `usemtl` — not the 0.6 grey
// assimp makes up for it.
TEST(MeshImport, AnObjMaterialNoMtlDefinesIsTheDefaultMaterial) {
  TempDir dir;
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  dir.write("have.mtl", "# one material\n  newmtl  red  \r\nKd 1 0 0\n");
  struct Case {
    const char* name;
    std::string text;
    bool fromFile;
  };
  const Case cases[] = {
      {"no_usemtl", triangle + "f 1 2 3\n", false},
      {"mtl_missing", "mtllib missing.mtl\nusemtl red\n" + triangle + "f 1 2 3\n", false},
      {"no_mtllib", "usemtl red\n" + triangle + "f 1 2 3\n", false},
      {"defined", "mtllib have.mtl\nusemtl red\n" + triangle + "f 1 2 3\n", true},
      {"another_name", "mtllib have.mtl\nusemtl blue\n" + triangle + "f 1 2 3\n", false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const MeshFile file = readMeshFile(dir.write(std::string(c.name) + ".obj", c.text));
    ASSERT_EQ(file.materials.size(), 1u);
    EXPECT_EQ(file.materials[0].fromFile, c.fromFile);
    EXPECT_EQ(file.materials[0].material.kd, c.fromFile ? Color(1, 0, 0) : Color(0.7));
  }
}

TEST(MeshImport, MtlSpecularShininessAndTheFilesOwnNormals) {
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

TEST(MeshImport, AsciiPlyTrianglesBoundsAndTheDefaultMaterial) {
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

// ------------------------------------------------------------------------------------------- STL

TEST(MeshImport, BinaryStlCountFromTheHeaderAndBoundsFromTheRecords) {
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

TEST(MeshImport, AsciiStlCountAndBoundsFromTheText) {
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
GltfJson glbJson(const fs::path& path, std::string& storage) {
  const std::string bytes = readText(path);
  std::uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);
  storage = bytes.substr(20, length);
  return parseGltfJson(storage);
}

double number(const ValueView& node) { return std::stod(std::string(node.scalar())); }
std::size_t count(const ValueView& node) { return std::stoul(std::string(node.scalar())); }

TEST(MeshImport, GlbBoxTrianglesAndBoundsThroughItsNodeMatrix) {
  const fs::path glb = kModels / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
  ASSERT_TRUE(installed(glb));
  std::string json;
  const GltfJson doc = glbJson(glb, json);
  const ValueView root = doc.root();
  // One mesh of one primitive under node 1, the child of node 0 which has a (column-major) matrix.
  const ValueView primitive = root.find("meshes")[0].find("primitives")[0];
  const ValueView accessors = root.find("accessors");
  const std::size_t triangles =
      count(accessors[count(primitive.find("indices"))].find("count")) / 3;
  const ValueView position = accessors[count(primitive.find("attributes").find("POSITION"))];
  const ValueView matrix = root.find("nodes")[0].find("matrix");
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

TEST(MeshImport, GlbNodeHierarchyIsBakedEveryMeshInstanceCounted) {
  // 2CylinderEngine: 82 nodes, 29 meshes, some used by several nodes. PreTransformVertices makes
  // one copy per use, so the expected count walks the scene's node tree.
  const fs::path glb = kModels / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  ASSERT_TRUE(installed(glb));
  std::string json;
  const GltfJson doc = glbJson(glb, json);
  const ValueView root = doc.root();
  const ValueView nodes = root.find("nodes");
  const ValueView meshes = root.find("meshes");
  const ValueView accessors = root.find("accessors");
  std::size_t triangles = 0;
  const std::function<void(std::size_t)> walk = [&](std::size_t n) {
    const ValueView node = nodes[n];
    if (node.find("mesh").isDefined()) {
      const ValueView primitives = meshes[count(node.find("mesh"))].find("primitives");
      for (std::size_t p = 0; p < primitives.size(); ++p) {
        const ValueView mode = primitives[p].find("mode");
        ASSERT_TRUE(!mode.isDefined() || count(mode) == 4);  // triangles
        triangles += count(accessors[count(primitives[p].find("indices"))].find("count")) / 3;
      }
    }
    const ValueView children = node.find("children");
    for (std::size_t c = 0; c < children.size(); ++c) walk(count(children[c]));
  };
  const ValueView sceneNodes = root.find("scenes")[count(root.find("scene"))].find("nodes");
  for (std::size_t i = 0; i < sceneNodes.size(); ++i) walk(count(sceneNodes[i]));
  ASSERT_EQ(triangles, 121496u);

  const MeshFile file = readMeshFile(glb);
  expectWellFormed(file);
  EXPECT_EQ(file.triangleCount() + file.droppedTriangles, triangles);
}

TEST(MeshImport, NonFiniteVerticesAreDroppedNotFatal) {
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

// assimp's glTF reader leaves out a triangle with a vertex index out of range and says so only in
// its log, without a count; glint notes it (importerDroppedFaces, a warning at the mesh object).
TEST(MeshImport, GltfFacesTheImporterDropsAreNoted) {
  const TempDir dir;
  for (const std::uint16_t last : {std::uint16_t{3}, std::uint16_t{7}}) {
    const MeshFile file = readMeshFile(writeQuadGltf(dir, last));
    if (last == 3) {
      EXPECT_EQ(file.triangleCount(), 3u);
      EXPECT_FALSE(file.importerDroppedFaces);
    } else {
      EXPECT_EQ(file.triangleCount(), 2u);
      EXPECT_TRUE(file.importerDroppedFaces);
    }
  }
}

// An OBJ's `mtllib` that is not there is noted (assimp says so only in its log), with the library
// assimp's OBJ reader falls back to: the OBJ's own name with .mtl, when that is there.
TEST(MeshImport, AMissingMaterialLibraryIsNoted) {
  const TempDir dir;
  const std::string obj = "mtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
  const MeshFile alone = readMeshFile(dir.write("alone.obj", obj));
  EXPECT_EQ(alone.missingMaterialLibraries, std::vector<std::string>{"nothere.mtl"});
  EXPECT_EQ(alone.fallbackMaterialLibrary, "");
  dir.write("fallback.mtl", "newmtl red\nKd 1 0 0\n");
  const MeshFile fallback = readMeshFile(dir.write("fallback.obj", obj));
  EXPECT_EQ(fallback.missingMaterialLibraries, std::vector<std::string>{"nothere.mtl"});
  EXPECT_EQ(fallback.fallbackMaterialLibrary, "fallback.mtl");
  ASSERT_EQ(fallback.materials.size(), 1u);
  EXPECT_EQ(fallback.materials[0].name, "red");
  // A library that is there is no note.
  dir.write("here.mtl", "newmtl red\nKd 1 0 0\n");
  const MeshFile here = readMeshFile(
      dir.write("here.obj", "mtllib here.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"));
  EXPECT_TRUE(here.missingMaterialLibraries.empty());
  EXPECT_EQ(here.fallbackMaterialLibrary, "");
}

}  // namespace
}  // namespace glint::mesh_test
