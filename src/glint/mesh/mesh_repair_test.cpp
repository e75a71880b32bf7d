// What glint repairs in a mesh file (DESIGN.md §5 `mesh`, §7): normals generated with the crease
// angle (also for indexed files), corners joined into shared vertices exactly, creases and seams
// kept, degenerate and invalid triangles dropped and counted, invalid file normals rebuilt.
#include "glint/mesh/mesh_repair.h"

#include <assimp/mesh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "glint/core/seeded_hash.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

TEST(MeshRepair, GeneratedNormalsKeepEdgesSharperThanTheCreaseAngle) {
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

TEST(MeshRepair, GeneratedNormalsAreSmoothBelowTheCreaseAngle) {
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

// The corners of a rows × columns grid of quads, two triangles each (a, b, c and a, c, d of the
// quad with corners point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)).
template <class PointAt>
std::vector<Point3> gridCorners(int rows, int columns, const PointAt& point) {
  std::vector<Point3> corners;
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < columns; ++j) {
      const Point3 a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1),
                   d = point(i, j + 1);
      for (const Point3& p : {a, b, c, a, c, d}) corners.push_back(p);
    }
  }
  return corners;
}

// An assimp mesh of one vertex per corner, three corners per triangle (as assimp's OBJ importer
// gives), positions rounded to float as assimp stores them.
void setCorners(aiMesh& mesh, const std::vector<Point3>& corners) {
  mesh.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh.mNumVertices = static_cast<unsigned>(corners.size());
  mesh.mVertices = new aiVector3D[corners.size()];
  for (std::size_t i = 0; i < corners.size(); ++i) {
    mesh.mVertices[i] =
        aiVector3D(static_cast<float>(corners[i].x), static_cast<float>(corners[i].y),
                   static_cast<float>(corners[i].z));
  }
  mesh.mNumFaces = mesh.mNumVertices / 3;
  mesh.mFaces = new aiFace[mesh.mNumFaces];
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    mesh.mFaces[f].mNumIndices = 3;
    mesh.mFaces[f].mIndices = new unsigned[3]{3 * f, 3 * f + 1, 3 * f + 2};
  }
}

// The unit normal of the triangle of corner i (zero for one of no area), from the float positions.
Vec3 cornerFaceNormal(const aiMesh& mesh, std::size_t i) {
  const auto at = [&](std::size_t k) {
    const aiVector3D& v = mesh.mVertices[k];
    return Point3{v.x, v.y, v.z};
  };
  const std::size_t f = i / 3;
  const Vec3 n = cross(at(3 * f + 1) - at(3 * f), at(3 * f + 2) - at(3 * f));
  const double length = std::sqrt(dot(n, n));
  return length > 0 ? n / length : n;
}

// generateSmoothNormals against its definition computed the slow way (every pair of vertices):
// the normalised sum of the unit face normals of the vertices within epsilon (1e-4 of the
// bounding box's diagonal) whose face lies within the crease angle — on a bumpy sphere of one
// vertex per corner, some corners moved by 0.3 epsilon (still merged) or 3 epsilon (not).
TEST(MeshRepair, GeneratedNormalsFollowTheirDefinition) {
  constexpr int kRings = 12;
  constexpr int kSegments = 24;
  const auto point = [&](int ring, int segment) {
    const double theta = std::numbers::pi * ring / kRings;
    const double phi = 2 * std::numbers::pi * segment / kSegments;
    const double radius = 1 + 0.15 * std::sin(3 * theta) * std::cos(5 * phi);  // bumps and creases
    return Point3{radius * std::sin(theta) * std::cos(phi), radius * std::cos(theta),
                  radius * std::sin(theta) * std::sin(phi)};
  };
  std::vector<Point3> corners = gridCorners(kRings, kSegments, point);
  const double epsilon = 1e-4 * std::sqrt(2.0 * 2.0 * 3);  // the bumps stay within ±1.15: close
  for (std::size_t i = 0; i < corners.size(); i += 37) corners[i].x += 0.3 * epsilon;
  for (std::size_t i = 5; i < corners.size(); i += 41) corners[i].y += 3 * epsilon;

  aiMesh mesh;
  setCorners(mesh, corners);
  generateSmoothNormals(mesh, kMeshCreaseAngleDegrees);

  // The definition, from the float positions as the function reads them.
  const auto at = [&](std::size_t i) {
    const aiVector3D& v = mesh.mVertices[i];
    return Point3{v.x, v.y, v.z};
  };
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Point3 p = at(i);
    const double q[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
  }
  const double eps =
      1e-4 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
  // Unit, or zero for a face of no area (the poles' triangles with two corners at the pole).
  const auto safeNormalize = [](const Vec3& v) {
    const double length = std::sqrt(dot(v, v));
    return length > 0 ? v / length : v;
  };
  const auto faceNormal = [&](std::size_t i) {
    const std::size_t f = i / 3;
    return safeNormalize(cross(at(3 * f + 1) - at(3 * f), at(3 * f + 2) - at(3 * f)));
  };
  const double cosLimit = std::cos(kMeshCreaseAngleDegrees * std::numbers::pi / 180);
  int merged = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    Vec3 sum;
    for (std::size_t j = 0; j < corners.size(); ++j) {
      const Vec3 d = at(j) - at(i);
      if (j != i && !(dot(d, d) < eps * eps)) continue;
      if (j != i && !(dot(faceNormal(j), faceNormal(i)) >= cosLimit)) continue;
      if (j != i && !(at(j) == at(i))) ++merged;
      sum = sum + faceNormal(j);
    }
    const Vec3 expected = safeNormalize(sum);
    const aiVector3D& got = mesh.mNormals[i];
    ASSERT_NEAR(got.x, expected.x, 1e-6) << i;
    ASSERT_NEAR(got.y, expected.y, 1e-6) << i;
    ASSERT_NEAR(got.z, expected.z, 1e-6) << i;
  }
  EXPECT_GT(merged, 0);  // some moved corners were within epsilon of others
}

// Checks the normals of the corners `which` against the smoothing over exactly equal positions:
// the normalised sum of the face normals, within the crease angle, of the corners at exactly
// corner i's position (itself always).
void expectSmoothedOverExactPositions(const aiMesh& mesh, const std::vector<std::size_t>& which) {
  std::map<std::tuple<float, float, float>, std::vector<std::size_t>> cornersAt;
  for (std::size_t i = 0; i < mesh.mNumVertices; ++i) {
    const aiVector3D& v = mesh.mVertices[i];
    cornersAt[{v.x, v.y, v.z}].push_back(i);
  }
  const double cosLimit = std::cos(kMeshCreaseAngleDegrees * std::numbers::pi / 180);
  for (const std::size_t i : which) {
    const aiVector3D& v = mesh.mVertices[i];
    Vec3 sum;
    for (const std::size_t j : cornersAt[{v.x, v.y, v.z}]) {
      if (j != i && !(dot(cornerFaceNormal(mesh, j), cornerFaceNormal(mesh, i)) >= cosLimit)) {
        continue;
      }
      sum = sum + cornerFaceNormal(mesh, j);
    }
    const Vec3 expected = sum / std::sqrt(dot(sum, sum));
    const aiVector3D& got = mesh.mNormals[i];
    ASSERT_NEAR(got.x, expected.x, 1e-6) << i;
    ASSERT_NEAR(got.y, expected.y, 1e-6) << i;
    ASSERT_NEAR(got.z, expected.z, 1e-6) << i;
  }
}

// One vertex far from a model makes epsilon (1e-4 of the bounding box's diagonal) reach across the
// whole model, and the pairwise comparisons quadratic (a 150 × 150 grid took 11 s, a larger one
// hours): past the budget the normals smooth over exactly shared positions only, and say so.
TEST(MeshRepair, GeneratedNormalsWithAFarOutlierSmoothOverExactPositions) {
  constexpr int kCells = 100;
  const auto height = [](int i, int j) { return 0.02 * std::sin(0.7 * i) * std::cos(0.9 * j); };
  const auto point = [&](int i, int j) {
    return Point3{static_cast<double>(i) / kCells, height(i, j), static_cast<double>(j) / kCells};
  };
  std::vector<Point3> corners = gridCorners(kCells, kCells, point);
  for (const Point3& p : {Point3{1e6, 0, 0}, Point3{1e6, 0, 1}, Point3{1e6, 1, 0}}) {
    corners.push_back(p);
  }
  aiMesh mesh;
  setCorners(mesh, corners);
  const SmoothNormalsReport report = generateSmoothNormals(mesh, kMeshCreaseAngleDegrees);
  EXPECT_TRUE(report.exactPositionsOnly);
  EXPECT_EQ(report.crowdedPositions, 0u);
  std::vector<std::size_t> all(corners.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  expectSmoothedOverExactPositions(mesh, all);
  // A grid vertex inside averages its six triangles: not any one face's normal.
  const std::size_t inner = 6 * (50 * kCells + 50);  // corner a of cell (50, 50)
  EXPECT_GT(
      std::abs(dot(cornerFaceNormal(mesh, inner),
                   Vec3{mesh.mNormals[inner].x, mesh.mNormals[inner].y, mesh.mNormals[inner].z}) -
               1),
      1e-9);
}

// A position shared by more corners than kMaxSmoothedCorners (the apex of a huge fan: 200,000
// triangles took 41 s) leaves its corners their own faces' normals; one of exactly that many (the
// pole of a fine UV sphere) is smoothed as always, and the other positions are too.
TEST(MeshRepair, GeneratedNormalsAtACrowdedPositionKeepTheirFaceNormals) {
  for (const std::uint32_t triangles : {kMaxSmoothedCorners, kMaxSmoothedCorners + 1}) {
    SCOPED_TRACE(triangles);
    const auto rim = [&](std::uint32_t k) {
      const double angle = 2 * std::numbers::pi * k / triangles;
      return Point3{std::cos(angle), 0.2 * std::sin(5 * angle), std::sin(angle)};
    };
    std::vector<Point3> corners;
    for (std::uint32_t k = 0; k < triangles; ++k) {
      for (const Point3& p : {Point3{0, 0.5, 0}, rim((k + 1) % triangles), rim(k)}) {
        corners.push_back(p);
      }
    }
    aiMesh mesh;
    setCorners(mesh, corners);
    const SmoothNormalsReport report = generateSmoothNormals(mesh, kMeshCreaseAngleDegrees);
    EXPECT_FALSE(report.exactPositionsOnly);
    const bool crowded = triangles > kMaxSmoothedCorners;
    EXPECT_EQ(report.crowdedPositions, crowded ? 1u : 0u);
    std::vector<std::size_t> apex;
    std::vector<std::size_t> others;
    for (std::size_t i = 0; i < corners.size(); ++i) (i % 3 == 0 ? apex : others).push_back(i);
    // The rim's points are ~2π/1024 apart, far beyond epsilon (1e-4 of a diagonal of ~2.9): their
    // smoothing is over exactly shared positions.
    expectSmoothedOverExactPositions(mesh, others);
    if (!crowded) {
      expectSmoothedOverExactPositions(mesh, apex);
      continue;
    }
    for (const std::size_t i : apex) {
      const Vec3 own = cornerFaceNormal(mesh, i);
      ASSERT_NEAR(mesh.mNormals[i].x, own.x, 1e-6) << i;
      ASSERT_NEAR(mesh.mNormals[i].y, own.y, 1e-6) << i;
      ASSERT_NEAR(mesh.mNormals[i].z, own.z, 1e-6) << i;
    }
  }
}

// The tables that group vertices and positions are seeded per process (core/seeded_hash.h) so
// that no file can make them collide; what they give — joined vertices numbered by first use,
// generated normals, in the normal case and in the exact-position fallback (with −0 written
// beside 0) — must be the same under any seed.
TEST(MeshRepair, JoinsAndNormalsDoNotDependOnTheHashSeed) {
  constexpr int kCells = 60;
  const auto point = [](int i, int j) {
    return Point3{i / 60.0, 0.02 * std::sin(0.7 * i) * std::cos(0.9 * j), j / 60.0};
  };
  std::vector<Point3> corners = gridCorners(kCells, kCells, point);
  for (std::size_t k = 0; k < corners.size(); k += 2) {  // some corners on z = 0 written as −0
    if (corners[k].z == 0) corners[k].z = -0.0;
  }
  struct Result {
    std::vector<std::array<float, 3>> normals;
    JoinedMesh joined;
    bool exactPositionsOnly;
  };
  const auto run = [&](std::uint64_t seed, bool outlier) {
    setProcessHashSeedForTesting(seed);
    std::vector<Point3> all = corners;
    if (outlier) all.insert(all.end(), {{1e6, 0, 0}, {1e6, 0, 1}, {1e6, 1, 0}});
    aiMesh mesh;
    setCorners(mesh, all);
    Result r;
    r.exactPositionsOnly = generateSmoothNormals(mesh, kMeshCreaseAngleDegrees).exactPositionsOnly;
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      r.normals.push_back({mesh.mNormals[v].x, mesh.mNormals[v].y, mesh.mNormals[v].z});
    }
    std::size_t dropped = 0;
    r.joined = joinMesh(mesh, dropped);
    return r;
  };
  const std::uint64_t saved = processHashSeed();
  for (const bool outlier : {false, true}) {
    SCOPED_TRACE(outlier);
    const Result a = run(1, outlier);
    const Result b = run(0x9e3779b97f4a7c15ull, outlier);
    EXPECT_EQ(a.exactPositionsOnly, outlier);
    EXPECT_EQ(b.exactPositionsOnly, outlier);
    EXPECT_EQ(a.normals, b.normals);
    EXPECT_EQ(a.joined.indices, b.joined.indices);
    EXPECT_EQ(a.joined.source, b.joined.source);
    // −0 and 0 are one position and one vertex: the grid's points (and the outlier's three).
    EXPECT_EQ(a.joined.source.size(), (kCells + 1u) * (kCells + 1u) + (outlier ? 3u : 0u));
  }
  setProcessHashSeedForTesting(saved);
}

TEST(MeshRepair, IndexedFilesWithoutNormalsGetSmoothNormalsPerVertex) {
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

TEST(MeshRepair, DeindexedStlCornersAreJoinedIntoSharedVertices) {
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

TEST(MeshRepair, CreasesKeepOneVertexPerNormal) {
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

TEST(MeshRepair, SeamsOfSplitNormalsKeepBothNormals) {
  // Two triangles hinged on the edge of vertices 2 and 3. In `seam` each triangle gives the
  // shared edge its own normal (`vn`): the edge's two positions carry two normals each, so 6
  // vertices. In `smooth` both use one normal; corners that differ only in the sign of a zero
  // coordinate are one vertex, corners with different texture coordinates two (a texture seam):
  // 5 vertices.
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
                                  "f 1/1/1 3/1/1 2/2/1\n"));
  ASSERT_EQ(smooth.parts.size(), 1u);
  EXPECT_EQ(smooth.parts[0].positions.size(), 5u);
  const std::vector<std::uint32_t> smoothIndices{0, 1, 2, 3, 4, 2, 0, 2, 3};
  EXPECT_EQ(smooth.parts[0].indices, smoothIndices);
}

// ------------------------------------------------------------------- degenerate and invalid faces

TEST(MeshRepair, DegenerateTrianglesAreDroppedAndCounted) {
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

TEST(MeshRepair, FacesWithIndicesOutOfRangeAreDroppedAndCounted) {
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

TEST(MeshRepair, PlyFacesOfOneOrTwoCornersAreDroppedAndCounted) {
  // PLY has no points or lines among its faces: such a face is a malformed polygon, counted in
  // the warning with the degenerate triangles (the mesh library's step removed it silently).
  TempDir dir;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 3\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
  const MeshFile file = readMeshFile(dir.write("short.ply", header + "3 0 1 2\n2 1 3\n1 3\n"));
  EXPECT_EQ(file.triangleCount(), 1u);
  EXPECT_EQ(file.droppedTriangles, 2u);
  // Only such faces: no triangles, not "indices out of range".
  try {
    readMeshFile(dir.write("lines.ply", header + "2 0 1\n2 1 3\n2 3 0\n"));
    FAIL() << "a PLY of two-corner faces loaded";
  } catch (const MeshLoadError& e) {
    EXPECT_STREQ(e.what(), "the file holds no triangles");
  }
}

TEST(MeshRepair, InvalidFileNormalsAreRepairedFromTheFaces) {
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

}  // namespace
}  // namespace glint::mesh_test
