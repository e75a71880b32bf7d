#include "glint/mesh/mesh_repair.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include <assimp/mesh.h>
#include <assimp/scene.h>

#include "glint/core/seeded_hash.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/obj_fast_parse.h"

namespace glint {

namespace {

// Twice a triangle's area may be at most this fraction of its longest edge squared before the
// triangle counts as degenerate: Triangle::make's bound (geometry/shapes.cpp), so a mesh drops
// exactly what a scene file would refuse as a `triangle`. Below it the normal (e1×e2)/|e1×e2| is
// rounding noise, or NaN for coincident vertices.
constexpr double kDegenerateTolerance = 1e-12;

constexpr std::uint32_t kUnused = 0xffffffffu;

// Triangles a face stands for: a polygon of n ≥ 3 corners fans into n − 2.
std::size_t trianglesOf(const aiFace& face) {
  return face.mNumIndices >= 3 ? face.mNumIndices - 2 : 1;
}

Vec3 faceNormal(const TriangleMesh& mesh, std::size_t triangle) {
  const Point3& p0 = mesh.positions[mesh.indices[3 * triangle]];
  const Point3& p1 = mesh.positions[mesh.indices[3 * triangle + 1]];
  const Point3& p2 = mesh.positions[mesh.indices[3 * triangle + 2]];
  return cross(p1 - p0, p2 - p0);  // length = twice the area
}

// Makes every vertex normal unit. A file's zero or non-finite normal is replaced by the
// area-weighted mean of the normals of the triangles around the vertex.
void repairNormals(TriangleMesh& mesh) {
  if (mesh.normals.empty()) return;
  std::vector<bool> invalid(mesh.normals.size(), false);
  bool anyInvalid = false;
  for (std::size_t v = 0; v < mesh.normals.size(); ++v) {
    const Vec3 n = toVec(mesh.normals[v]);
    const double len = length(n);
    if (len > 0 && std::isfinite(len)) {
      mesh.normals[v] = Normal3(n / len);
    } else {
      invalid[v] = true;
      anyInvalid = true;
    }
  }
  if (!anyInvalid) return;
  std::vector<Vec3> sum(mesh.normals.size());
  std::vector<Vec3> first(mesh.normals.size());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 n = faceNormal(mesh, t);
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh.indices[3 * t + k];
      if (!invalid[v]) continue;
      sum[v] += n;
      if (first[v] == Vec3{}) first[v] = n;
    }
  }
  for (std::size_t v = 0; v < mesh.normals.size(); ++v) {
    if (!invalid[v]) continue;
    // Opposite faces may cancel exactly; then one face's normal serves. Every vertex left belongs
    // to a non-degenerate triangle, so `first` is non-zero.
    mesh.normals[v] = Normal3(normalize(length(sum[v]) > 0 ? sum[v] : first[v]));
  }
}

// The vertex data glint keeps, as a key for joining: position, normal and texture coordinates (the
// first set; (0, 0) without) in assimp's float. −0 is made +0 (the two compare equal), and a normal
// that is not finite becomes 0 — every invalid normal is one class, replaced by repairNormals from
// the triangles around the joined vertex.
struct VertexKey {
  float p[3];
  float n[3];
  float t[2];
  // The same bits, as hashOf reads them (keyOf has made −0 +0 already).
  bool operator==(const VertexKey& o) const { return std::memcmp(this, &o, sizeof o) == 0; }
};

// `normal` and `texcoord` may be null (the mesh has none).
VertexKey keyOf(const aiVector3D& p, const aiVector3D* normal, const aiVector3D* texcoord) {
  VertexKey key{};
  key.p[0] = p.x + 0.0f;
  key.p[1] = p.y + 0.0f;
  key.p[2] = p.z + 0.0f;
  if (normal != nullptr) {
    const aiVector3D& n = *normal;
    if (std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z)) {
      key.n[0] = n.x + 0.0f;
      key.n[1] = n.y + 0.0f;
      key.n[2] = n.z + 0.0f;
    }
  }
  if (texcoord != nullptr) {
    const aiVector3D& t = *texcoord;
    // NaN ≠ NaN would never join: such coordinates become 0 (the texture lookup tames them anyway).
    key.t[0] = std::isfinite(t.x) ? t.x + 0.0f : 0.0f;
    key.t[1] = std::isfinite(t.y) ? t.y + 0.0f : 0.0f;
  }
  return key;
}

// The vertices of an assimp mesh, for joinVertices and convertVertices.
class AssimpVertices {
 public:
  explicit AssimpVertices(const aiMesh& mesh) : mesh_(mesh) {}
  unsigned faceCount() const { return mesh_.mNumFaces; }
  unsigned faceSize(unsigned f) const { return mesh_.mFaces[f].mNumIndices; }
  // The vertex at corner k of face f (3 corners).
  const unsigned* face(unsigned f) const { return mesh_.mFaces[f].mIndices; }
  unsigned vertexCount() const { return mesh_.mNumVertices; }
  const aiVector3D& position(unsigned v) const { return mesh_.mVertices[v]; }
  const aiVector3D* normal(unsigned v) const {
    return mesh_.mNormals != nullptr ? &mesh_.mNormals[v] : nullptr;
  }
  const aiVector3D* texcoord(unsigned v) const {
    return mesh_.mTextureCoords[0] != nullptr ? &mesh_.mTextureCoords[0][v] : nullptr;
  }
  bool hasNormals() const { return mesh_.HasNormals(); }
  bool hasTexcoords() const { return mesh_.mTextureCoords[0] != nullptr; }
  // No shortcut: every vertex is looked up by its key.
  std::uint32_t knownJoin(unsigned /*v*/) const { return kUnused; }
  void rememberJoin(unsigned /*v*/, std::uint32_t /*joined*/) const {}

 private:
  const aiMesh& mesh_;
};

// The one mesh assimp's OBJ importer makes of a SimpleObj of triangles — a vertex per face corner,
// numbered in face order, with the corner's position, normal and texture coordinates — read from
// the OBJ's own arrays instead of copied out.
class SimpleObjVertices {
 public:
  explicit SimpleObjVertices(const SimpleObj& obj)
      : obj_(obj),
        corners_(static_cast<unsigned>(obj.vertexIndices.size())),
        normals_(!obj.normalIndices.empty()),
        texcoords_(!obj.texcoordIndices.empty()) {}
  unsigned faceCount() const { return static_cast<unsigned>(obj_.faceSizes.size()); }
  unsigned faceSize(unsigned /*f*/) const { return 3; }
  const unsigned* face(unsigned f) const {
    corner_[0] = 3 * f;
    corner_[1] = 3 * f + 1;
    corner_[2] = 3 * f + 2;
    return corner_;
  }
  unsigned vertexCount() const { return corners_; }
  aiVector3D position(unsigned v) const { return at(obj_.positions, obj_.vertexIndices[v]); }
  const aiVector3D* normal(unsigned v) const {
    if (!normals_) return nullptr;
    normal_ = at(obj_.normals, obj_.normalIndices[v]);
    return &normal_;
  }
  const aiVector3D* texcoord(unsigned v) const {
    if (!texcoords_) return nullptr;
    texcoord_ = at(obj_.texcoords, obj_.texcoordIndices[v]);
    return &texcoord_;
  }
  bool hasNormals() const { return normals_; }
  bool hasTexcoords() const { return texcoords_; }
  // A corner whose position, normal and texture coordinate indices are those of an earlier joined
  // corner of the same position index has that corner's key, so its joined vertex: found without
  // the key's hash lookup (a smooth OBJ surface names each position from about six corners, all
  // alike). kUnused when not known.
  std::uint32_t knownJoin(unsigned v) const {
    if (firstUse_.empty()) firstUse_.assign(obj_.positions.size() / 3, FirstUse{});
    const FirstUse& first = firstUse_[obj_.vertexIndices[v]];
    if (first.joined == kUnused || first.normal != normalIndex(v) ||
        first.texcoord != texcoordIndex(v)) {
      return kUnused;
    }
    return first.joined;
  }
  void rememberJoin(unsigned v, std::uint32_t joined) const {
    FirstUse& first = firstUse_[obj_.vertexIndices[v]];
    if (first.joined == kUnused) first = {normalIndex(v), texcoordIndex(v), joined};
  }

 private:
  struct FirstUse {
    std::uint32_t normal = 0, texcoord = 0, joined = kUnused;
  };
  std::uint32_t normalIndex(unsigned v) const { return normals_ ? obj_.normalIndices[v] : 0; }
  std::uint32_t texcoordIndex(unsigned v) const { return texcoords_ ? obj_.texcoordIndices[v] : 0; }
  static aiVector3D at(const std::vector<float>& values, std::uint32_t i) {
    const std::size_t k = 3 * std::size_t{i};
    return {values[k], values[k + 1], values[k + 2]};
  }
  const SimpleObj& obj_;
  unsigned corners_;
  bool normals_;
  bool texcoords_;
  mutable unsigned corner_[3] = {0, 0, 0};
  mutable aiVector3D normal_;
  mutable aiVector3D texcoord_;
  mutable std::vector<FirstUse> firstUse_;  // per position index
};

// Floats' bits folded two at a time (an odd last one alone) through the process's seeded hash
// (core/seeded_hash.h): a file cannot be made of keys that all land in a few slots of a table.
std::uint64_t hashFloatBits(const float* values, int count, std::uint64_t seed) {
  SeededHasher h(seed);
  for (int i = 0; i < count; i += 2) {
    std::uint32_t low = 0;
    std::uint32_t high = 0;
    std::memcpy(&low, values + i, 4);
    if (i + 1 < count) std::memcpy(&high, values + i + 1, 4);
    h.add(low | std::uint64_t{high} << 32);
  }
  return h.value();
}

// The eight floats of a key (positions are finite here: triangles touching a non-finite vertex
// were dropped).
std::uint64_t hashOf(const VertexKey& key, std::uint64_t seed) {
  float values[8];
  static_assert(sizeof values == sizeof(VertexKey));
  std::memcpy(values, &key, sizeof values);
  return hashFloatBits(values, 8, seed);
}

}  // namespace

std::size_t dropInvalidFaces(aiScene& scene) {
  std::size_t dropped = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr || mesh->mFaces == nullptr) {
      if (mesh != nullptr) mesh->mNumFaces = 0;
      continue;
    }
    unsigned kept = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      bool valid = face.mNumIndices > 0 && face.mIndices != nullptr && mesh->mVertices != nullptr;
      for (unsigned i = 0; valid && i < face.mNumIndices; ++i) {
        valid = face.mIndices[i] < mesh->mNumVertices;
      }
      if (!valid) {
        dropped += trianglesOf(face);
        continue;
      }
      if (kept != f) {
        // Swap the members: aiFace's own copy assignment would copy the index arrays.
        aiFace& to = mesh->mFaces[kept];
        std::swap(to.mNumIndices, face.mNumIndices);
        std::swap(to.mIndices, face.mIndices);
      }
      ++kept;
    }
    // The faces past `kept` stay allocated; delete[] mFaces still destroys all of them.
    mesh->mNumFaces = kept;
  }
  return dropped;
}

void splitSharedCorners(aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr || mesh->mNormals != nullptr || mesh->mVertices == nullptr ||
        mesh->mNumBones != 0 || mesh->mNumAnimMeshes != 0) {
      continue;
    }
    std::uint64_t corners = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) corners += mesh->mFaces[f].mNumIndices;
    if (corners == mesh->mNumVertices || corners > kMaxMeshTriangles * 3) continue;
    auto* vertices = new aiVector3D[corners];
    // The first set of texture coordinates follows its corners; other sets are dropped.
    aiVector3D* uvs = mesh->mTextureCoords[0] != nullptr ? new aiVector3D[corners] : nullptr;
    unsigned next = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      for (unsigned i = 0; i < face.mNumIndices; ++i) {
        vertices[next] = mesh->mVertices[face.mIndices[i]];  // checked by dropInvalidFaces
        if (uvs != nullptr) uvs[next] = mesh->mTextureCoords[0][face.mIndices[i]];
        face.mIndices[i] = next++;
      }
    }
    delete[] mesh->mVertices;
    mesh->mVertices = vertices;
    mesh->mNumVertices = next;
    delete[] mesh->mTangents;
    mesh->mTangents = nullptr;
    delete[] mesh->mBitangents;
    mesh->mBitangents = nullptr;
    for (auto*& colors : mesh->mColors) {
      delete[] colors;
      colors = nullptr;
    }
    for (unsigned k = 0; k < AI_MAX_NUMBER_OF_TEXTURECOORDS; ++k) {
      delete[] mesh->mTextureCoords[k];
      mesh->mTextureCoords[k] = nullptr;
      mesh->mNumUVComponents[k] = 0;
    }
    if (uvs != nullptr) {
      mesh->mTextureCoords[0] = uvs;
      mesh->mNumUVComponents[0] = 2;
    }
  }
}

std::size_t facesWithTriangles(const aiScene& scene) {
  std::size_t n = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    for (unsigned f = 0; mesh != nullptr && f < mesh->mNumFaces; ++f) {
      if (mesh->mFaces[f].mNumIndices >= 3) ++n;
    }
  }
  return n;
}

namespace {

// joinMesh over either kind of vertices.
template <class Vertices>
JoinedMesh joinVertices(const Vertices& in, std::size_t& dropped) {
  JoinedMesh out;
  out.indices.reserve(std::size_t{3} * in.faceCount());
  std::vector<VertexKey> keys;  // of the joined vertices, in step with out.source
  std::vector<std::uint32_t> joinedOf(in.vertexCount(), kUnused);  // assimp vertex → joined
  // Open addressing, linear probing, at most half full; sized for the joined vertices (a smooth
  // OBJ surface has about one per six face corners) and doubled as they grow, so that the table
  // stays small enough for the cache. A slot holds the joined vertex in its low 32 bits and the
  // hash's high 32 bits above, which rule out almost every other key without reading it.
  constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  const std::uint64_t seed = processHashSeed();
  std::size_t slots = 16;
  while (slots < std::size_t{in.vertexCount()} / 3) slots *= 2;
  std::vector<std::uint64_t> table(slots, kEmpty);
  const auto place = [&](std::uint64_t hash, std::uint32_t j) {
    std::size_t slot = hash & (slots - 1);
    while (table[slot] != kEmpty) slot = (slot + 1) & (slots - 1);
    table[slot] = (hash & 0xffffffff00000000ull) | j;
  };
  // `key` and `hash` are those of assimp vertex v, not yet joined.
  const auto join = [&](unsigned v, const VertexKey& key, std::uint64_t hash) {
    const std::uint64_t tag = hash & 0xffffffff00000000ull;
    for (std::size_t slot = hash & (slots - 1);; slot = (slot + 1) & (slots - 1)) {
      const std::uint64_t entry = table[slot];
      if (entry == kEmpty) break;
      const auto j = static_cast<std::uint32_t>(entry);
      if ((entry & 0xffffffff00000000ull) == tag && keys[j] == key) return joinedOf[v] = j;
    }
    const auto j = static_cast<std::uint32_t>(keys.size());
    keys.push_back(key);
    out.source.push_back(v);
    if (2 * keys.size() > slots) {
      slots *= 2;
      table.assign(slots, kEmpty);
      for (std::uint32_t k = 0; k < keys.size(); ++k) place(hashOf(keys[k], seed), k);
    } else {
      place(hash, j);
    }
    return joinedOf[v] = j;
  };
  for (unsigned f = 0; f < in.faceCount(); ++f) {
    const unsigned size = in.faceSize(f);
    if (size != 3) {
      if (size > 3 || size == 0) dropped += size >= 3 ? size - 2 : 1;
      continue;
    }
    const unsigned* face = in.face(f);
    const unsigned a = face[0];
    const unsigned b = face[1];
    const unsigned c = face[2];
    if (a >= in.vertexCount() || b >= in.vertexCount() || c >= in.vertexCount()) {
      ++dropped;
      continue;
    }
    const auto point = [&](unsigned v) {
      const aiVector3D p = in.position(v);
      return Point3{p.x, p.y, p.z};
    };
    const Point3 p0 = point(a);
    const Point3 p1 = point(b);
    const Point3 p2 = point(c);
    const double twiceArea = length(cross(p1 - p0, p2 - p0));
    const double longest =
        std::max({distanceSquared(p0, p1), distanceSquared(p1, p2), distanceSquared(p2, p0)});
    // Also false for NaN and infinite coordinates, which make the area or the edges non-finite.
    if (!(twiceArea > kDegenerateTolerance * longest) || !std::isfinite(twiceArea) ||
        !std::isfinite(longest)) {
      ++dropped;
      continue;
    }
    // The three corners' keys and hashes first, their table slots fetched together: the lookups
    // are cache misses more often than not, and three at once overlap.
    const unsigned corners[3] = {a, b, c};
    VertexKey cornerKeys[3] = {};
    std::uint64_t hashes[3] = {};
    for (int k = 0; k < 3; ++k) {
      if (joinedOf[corners[k]] != kUnused) continue;
      if (const std::uint32_t known = in.knownJoin(corners[k]); known != kUnused) {
        joinedOf[corners[k]] = known;
        continue;
      }
      cornerKeys[k] =
          keyOf(in.position(corners[k]), in.normal(corners[k]), in.texcoord(corners[k]));
      hashes[k] = hashOf(cornerKeys[k], seed);
      __builtin_prefetch(&table[hashes[k] & (slots - 1)]);
    }
    for (int k = 0; k < 3; ++k) {
      const unsigned v = corners[k];
      if (joinedOf[v] == kUnused) in.rememberJoin(v, join(v, cornerKeys[k], hashes[k]));
      out.indices.push_back(joinedOf[v]);
    }
  }
  return out;
}

// convertMesh over either kind of vertices.
template <class Vertices>
TriangleMesh convertVertices(const Vertices& in, JoinedMesh&& joined) {
  TriangleMesh out;
  out.indices = std::move(joined.indices);
  out.positions.resize(joined.source.size());
  for (std::size_t j = 0; j < joined.source.size(); ++j) {
    const aiVector3D p = in.position(joined.source[j]);
    out.positions[j] = {p.x, p.y, p.z};
  }
  if (in.hasNormals()) {
    out.normals.resize(joined.source.size());
    for (std::size_t j = 0; j < joined.source.size(); ++j) {
      const aiVector3D n = *in.normal(joined.source[j]);
      out.normals[j] = {n.x, n.y, n.z};
    }
  }
  if (in.hasTexcoords()) {
    out.uvs.resize(joined.source.size());
    for (std::size_t j = 0; j < joined.source.size(); ++j) {
      const aiVector3D t = *in.texcoord(joined.source[j]);
      out.uvs[j] = {std::isfinite(t.x) ? t.x : 0.0, std::isfinite(t.y) ? t.y : 0.0};
    }
  }
  repairNormals(out);
  return out;
}

}  // namespace

JoinedMesh joinMesh(const aiMesh& in, std::size_t& dropped) {
  return joinVertices(AssimpVertices(in), dropped);
}

TriangleMesh convertMesh(const aiMesh& in, JoinedMesh&& joined) {
  return convertVertices(AssimpVertices(in), std::move(joined));
}

TriangleMesh joinSimpleObj(const SimpleObj& obj, std::size_t& dropped) {
  const SimpleObjVertices vertices(obj);
  return convertVertices(vertices, joinVertices(vertices, dropped));
}

namespace {

struct Double3 {
  double x = 0, y = 0, z = 0;
};

Double3 toDouble(const aiVector3D& v) { return {v.x, v.y, v.z}; }

bool isFinite(const Double3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// A position with −0 made +0: the two are one position (as keyOf and meshBoundsVolume take them).
aiVector3D canonical(const aiVector3D& v) { return {v.x + 0.0f, v.y + 0.0f, v.z + 0.0f}; }

// A hash of a float position's bits (−0 as +0).
std::uint64_t positionHash(const aiVector3D& v, std::uint64_t seed) {
  const aiVector3D c = canonical(v);
  const float values[3] = {c.x, c.y, c.z};
  return hashFloatBits(values, 3, seed);
}

bool samePosition(const aiVector3D& a, const aiVector3D& b) {
  const aiVector3D ca = canonical(a);
  const aiVector3D cb = canonical(b);
  return std::memcmp(&ca, &cb, sizeof(aiVector3D)) == 0;
}

}  // namespace

SmoothNormalsReport generateSmoothNormals(aiMesh& mesh, double creaseDegrees) {
  SmoothNormalsReport report;
  const std::size_t n = mesh.mNumVertices;
  if (n == 0 || mesh.mVertices == nullptr) return report;
  const aiVector3D* vertices = mesh.mVertices;
  constexpr std::uint32_t kNone = 0xffffffffu;
  // Each face's unit normal, and each vertex's face: the last one that uses it.
  std::vector<Double3> faceNormal(mesh.mNumFaces);
  std::vector<std::uint32_t> faceOf(n, kNone);
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices < 3) continue;
    const Double3 p0 = toDouble(vertices[face.mIndices[0]]);
    const Double3 p1 = toDouble(vertices[face.mIndices[1]]);
    const Double3 p2 = toDouble(vertices[face.mIndices[face.mNumIndices - 1]]);
    const Double3 a{p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
    const Double3 b{p2.x - p0.x, p2.y - p0.y, p2.z - p0.z};
    Double3 normal{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    const double length =
        std::sqrt(normal.x * normal.x + normal.y * normal.y + normal.z * normal.z);
    if (length > 0) normal = {normal.x / length, normal.y / length, normal.z / length};
    faceNormal[f] = normal;
    for (unsigned k = 0; k < face.mNumIndices; ++k) faceOf[face.mIndices[k]] = f;
  }

  // Distinct positions (an open-addressing table of their first vertex), and the vertices at each
  // as compressed rows.
  const std::size_t slots = n + n / 2 + 1;
  const std::uint64_t seed = processHashSeed();
  std::vector<std::uint32_t> slot(slots, kNone);
  std::vector<std::uint32_t> positionOf(n);
  std::vector<std::uint32_t> firstVertex;  // of each distinct position
  // In batches whose table slots are requested from memory before the first is probed: the
  // probes are cache misses, and waiting for them one by one was most of this function's time.
  constexpr std::size_t kBatch = 32;
  std::size_t home[kBatch];
  for (std::size_t begin = 0; begin < n; begin += kBatch) {
    const std::size_t count = std::min(kBatch, n - begin);
    for (std::size_t k = 0; k < count; ++k) {
      home[k] = static_cast<std::size_t>(positionHash(vertices[begin + k], seed) % slots);
      __builtin_prefetch(&slot[home[k]]);
    }
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t v = begin + k;
      std::size_t at = home[k];
      while (slot[at] != kNone && !samePosition(vertices[firstVertex[slot[at]]], vertices[v])) {
        at = at + 1 == slots ? 0 : at + 1;
      }
      if (slot[at] == kNone) {
        slot[at] = static_cast<std::uint32_t>(firstVertex.size());
        firstVertex.push_back(static_cast<std::uint32_t>(v));
      }
      positionOf[v] = slot[at];
    }
  }
  slot = {};
  const std::size_t positions = firstVertex.size();
  std::vector<std::uint32_t> rowStart(positions + 1, 0);
  for (std::size_t v = 0; v < n; ++v) ++rowStart[positionOf[v] + 1];
  for (std::size_t p = 0; p < positions; ++p) rowStart[p + 1] += rowStart[p];
  std::vector<std::uint32_t> verticesAt(n);
  {
    std::vector<std::uint32_t> fill(rowStart.begin(), rowStart.end() - 1);
    for (std::size_t v = 0; v < n; ++v) {
      verticesAt[fill[positionOf[v]]++] = static_cast<std::uint32_t>(v);
    }
  }

  // Epsilon: 1e-4 of the bounding box's diagonal (finite positions).
  constexpr double infinity = std::numeric_limits<double>::infinity();
  Double3 lo{infinity, infinity, infinity};
  Double3 hi{-infinity, -infinity, -infinity};
  for (std::size_t p = 0; p < positions; ++p) {
    const Double3 q = toDouble(vertices[firstVertex[p]]);
    if (!isFinite(q)) continue;
    lo = {std::min(lo.x, q.x), std::min(lo.y, q.y), std::min(lo.z, q.z)};
    hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), std::max(hi.z, q.z)};
  }
  const Double3 extent{hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
  const double diagonal =
      isFinite(lo) && isFinite(hi)
          ? std::sqrt(extent.x * extent.x + extent.y * extent.y + extent.z * extent.z)
          : 0;
  const double epsilon = 1e-4 * diagonal;

  // The distinct positions within epsilon of each (itself included), from a grid of cells sorted
  // by cell: a position looks in its own cell and the neighbours its epsilon
  // ball reaches into. Found one position at a time (a far outlier can make epsilon cover the
  // whole model: then every position is near every other, and a stored list would be quadratic).
  // Cells four epsilon wide: a ball reaches at most one neighbour along each axis (half the time),
  // and a cell holds few positions beyond the ball's own. Cells of 16 epsilon scanned so many more
  // that a dense small part of a large mesh (a fine sphere on a wide ground) passed the budget
  // below; cells of 2 epsilon always meant eight cells' lookups (+30 % on a mesh without normals).
  const double cell = 4 * epsilon;
  // Cells along an axis: at most diagonal / cell + 1 = 2501, so 21 bits each make a key.
  const auto cellOf = [&](double value, double origin) {
    return static_cast<std::int64_t>(std::floor((value - origin) / cell));
  };
  const auto keyOf = [](std::int64_t cx, std::int64_t cy, std::int64_t cz) {
    return (static_cast<std::uint64_t>(cx + 1) << 42) | (static_cast<std::uint64_t>(cy + 1) << 21) |
           static_cast<std::uint64_t>(cz + 1);
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> byCell;
  const bool grid = epsilon > 0 && std::isfinite(cell);
  if (grid) {
    byCell.reserve(positions);
    for (std::size_t p = 0; p < positions; ++p) {
      const Double3 q = toDouble(vertices[firstVertex[p]]);
      if (!isFinite(q)) continue;
      byCell.emplace_back(keyOf(cellOf(q.x, lo.x), cellOf(q.y, lo.y), cellOf(q.z, lo.z)),
                          static_cast<std::uint32_t>(p));
    }
    std::sort(byCell.begin(), byCell.end());
  }
  const double squaredEpsilon = epsilon * epsilon;
  std::vector<std::uint32_t> near;
  // Work done (positions looked at, pairs of vertices compared), against the budget of a search
  // within epsilon.
  std::uint64_t work = 0;
  const auto findNear = [&](std::size_t p, bool withinEpsilon) {
    near.clear();
    const Double3 q = toDouble(vertices[firstVertex[p]]);
    if (!withinEpsilon || !isFinite(q)) {
      near.push_back(static_cast<std::uint32_t>(p));
      return;
    }
    const std::int64_t c[3] = {cellOf(q.x, lo.x), cellOf(q.y, lo.y), cellOf(q.z, lo.z)};
    const double at[3] = {q.x - lo.x, q.y - lo.y, q.z - lo.z};
    std::int64_t from[3];
    std::int64_t to[3];
    for (int axis = 0; axis < 3; ++axis) {
      const double low = static_cast<double>(c[axis]) * cell;
      from[axis] = c[axis] - (at[axis] - epsilon < low ? 1 : 0);
      to[axis] = c[axis] + (at[axis] + epsilon >= low + cell ? 1 : 0);
    }
    for (std::int64_t x = from[0]; x <= to[0]; ++x) {
      for (std::int64_t y = from[1]; y <= to[1]; ++y) {
        for (std::int64_t z = from[2]; z <= to[2]; ++z) {
          const std::uint64_t key = keyOf(x, y, z);
          auto it = std::lower_bound(byCell.begin(), byCell.end(),
                                     std::pair<std::uint64_t, std::uint32_t>{key, 0});
          for (; it != byCell.end() && it->first == key; ++it) {
            ++work;
            const std::uint32_t other = it->second;
            const Double3 r = toDouble(vertices[firstVertex[other]]);
            const double dx = r.x - q.x, dy = r.y - q.y, dz = r.z - q.z;
            if (other == p || dx * dx + dy * dy + dz * dz < squaredEpsilon) near.push_back(other);
          }
        }
      }
    }
  };

  // Each vertex: the sum of the face normals within the crease angle at positions within epsilon
  // (withinEpsilon), or at its own position only. Comparing every pair of vertices near each other
  // is quadratic where many are near: the search within epsilon gives up past its budget (false),
  // and the vertices at a position of more than kMaxSmoothedCorners keep their own face's normal.
  const double cosLimit = std::cos(creaseDegrees * std::numbers::pi / 180);
  if (mesh.mNormals == nullptr) mesh.mNormals = new aiVector3D[n];
  const std::uint64_t budget = std::uint64_t{kMaxSmoothedCorners} * n + (std::uint64_t{1} << 24);
  // The normals of the vertices at position p from the positions in `near`; `crowded`: each its
  // own face's.
  const auto smoothPosition = [&](std::size_t p, bool crowded) {
    for (std::uint32_t i = rowStart[p]; i < rowStart[p + 1]; ++i) {
      const std::uint32_t v = verticesAt[i];
      if (faceOf[v] == kNone) {
        mesh.mNormals[v] = aiVector3D(std::numeric_limits<float>::quiet_NaN());
        continue;
      }
      const Double3 own = faceNormal[faceOf[v]];
      Double3 sum = crowded ? own : Double3{};
      for (std::size_t k = 0; !crowded && k < near.size(); ++k) {
        const std::uint32_t other = near[k];
        for (std::uint32_t j = rowStart[other]; j < rowStart[other + 1]; ++j) {
          const std::uint32_t w = verticesAt[j];
          if (faceOf[w] == kNone) continue;
          const Double3& normal = faceNormal[faceOf[w]];
          if (w != v && !(normal.x * own.x + normal.y * own.y + normal.z * own.z >= cosLimit)) {
            continue;
          }
          sum = {sum.x + normal.x, sum.y + normal.y, sum.z + normal.z};
        }
      }
      const double length = std::sqrt(sum.x * sum.x + sum.y * sum.y + sum.z * sum.z);
      const double scale = length > 0 ? 1 / length : 1;
      mesh.mNormals[v] =
          aiVector3D(static_cast<float>(sum.x * scale), static_cast<float>(sum.y * scale),
                     static_cast<float>(sum.z * scale));
    }
  };
  const auto smooth = [&](bool withinEpsilon) {
    work = 0;
    report.crowdedPositions = 0;
    for (std::size_t p = 0; p < positions; ++p) {
      findNear(p, withinEpsilon);
      const std::uint32_t corners = rowStart[p + 1] - rowStart[p];
      const bool crowded = corners > kMaxSmoothedCorners;
      if (crowded) {
        ++report.crowdedPositions;
      } else if (withinEpsilon) {
        for (const std::uint32_t other : near) {
          work += std::uint64_t{corners} * (rowStart[other + 1] - rowStart[other]);
        }
      }
      if (withinEpsilon && work > budget) return false;
      smoothPosition(p, crowded);
    }
    return true;
  };
  if (!smooth(grid)) {
    report.exactPositionsOnly = true;
    smooth(false);
  }
  return report;
}

}  // namespace glint
