// The Aggregate: input validation, build references for primitives and mesh triangles, and the
// traversals of the 4- or 8-wide BVH (closest hit near-child-first, for one ray or a packet;
// transmittance in slot order), plus the brute-force loops they are measured and tested against.
//
// Compiled once per instruction set (core/isa.h): as itself for the baseline, and included by
// aggregate_avx2.cpp and aggregate_avx512.cpp, which define GLINT_ISA_KERNEL (the ISA's suffix of
// the queries' names) and GLINT_AGGREGATE_KERNELS_ONLY (everything but the queries left out).
// The queries are [[gnu::flatten]] so that the inline functions they call are compiled into them
// for their ISA, never shared with other files (see src/CMakeLists.txt).
#include "glint/accel/aggregate.h"

#include <emmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

#include "glint/accel/instances.h"
#include "glint/accel/slab_test.h"
#include "glint/core/huge_pages.h"
#include "glint/core/ulp.h"
#include "glint/geometry/sphere_intersection.h"

#ifndef GLINT_ISA_KERNEL
#define GLINT_ISA_KERNEL(name) name##Baseline
#endif

namespace glint {

namespace {

using aggregate_detail::LeafSphere;
using bvh::kEmpty;
using bvh::kInner;
using bvh::kPrimitiveKey;
using bvh::Node;
using bvh::Node8;
using slab::BoxRay;
using slab::floatAbove;
using slab::floatBelow;
using slab::intersectHalf;
using slab::intersectNode;
using slab::kFarScale;
using slab::kSlabRows;
using slab::SlabRows;
using slab::StackEntry;

// Marks a triangle reference that was left out (degenerate) before compaction; not a valid key.
constexpr std::uint32_t kDroppedKey = 0xffffffffu;
constexpr std::size_t kTriangleChunk = 4096;

// The vertices of triangle `triangle` of a mesh.
struct TriangleVertices {
  const Point3& p0;
  const Point3& p1;
  const Point3& p2;
};
inline TriangleVertices verticesOf(const TriangleMesh& mesh, std::uint32_t triangle) {
  const std::uint32_t* v = mesh.indices.data() + 3 * static_cast<std::size_t>(triangle);
  const Point3* p = mesh.positions.data();
  return {p[v[0]], p[v[1]], p[v[2]]};
}

// The watertight test of geometry's Triangle on a mesh triangle, rejecting rays in its plane.
// `normal` receives the unnormalised geometric normal (p1 − p0) × (p2 − p0) the plane test needs,
// when the watertight test hits; the closest-hit query keeps it for finishTriangleHit.
inline bool hitTriangle(const WatertightRay& wray, const Vec3& direction, const TriangleVertices& v,
                        double tMin, double tMax, WatertightHit& candidate, Vec3& normal) {
  if (!intersectWatertight(wray, v.p0, v.p1, v.p2, tMin, tMax, candidate)) return false;
  normal = cross(v.p1 - v.p0, v.p2 - v.p0);
  return !isParallelToPlane(normal, direction);
}
inline bool hitTriangle(const WatertightRay& wray, const Vec3& direction, const TriangleVertices& v,
                        double tMin, double tMax, WatertightHit& candidate) {
  Vec3 normal;
  return hitTriangle(wray, direction, v, tMin, tMax, candidate, normal);
}

// The sign an edge function X.x·Y.y − X.y·Y.x that is exactly 0 takes when the ray's origin moves,
// in the sheared 2D space of the watertight test, by the infinitesimal δ = (ε, ε²): its derivative
// δx·(X.y − Y.y) + δy·(Y.x − X.x), decided lexicographically (exact: only comparisons). It depends
// only on the edge's two projected vertices and flips when they swap. 0 for an edge parallel to
// the ray (then the triangle is too, and never counts).
inline int tieSign(double xx, double xy, double yx, double yy) {
  if (xy != yy) return xy > yy ? 1 : -1;
  if (yx != xx) return yx > xx ? 1 : -1;
  return 0;
}

// Whether a watertight hit that touches an edge or vertex (some of u, v, w exactly 0) counts as a
// shadow-ray crossing of this triangle, so that a crossing there is counted once. There the
// watertight test accepts every triangle touching the point (an edge function is exactly 0), so a
// ray through an edge shared by two triangles would multiply in kt twice. Ties are broken by
// simulation of simplicity (Edelsbrunner and Mücke 1990): a zero edge function takes tieSign, which
// is opposite in two triangles sharing the edge (same sign where their windings disagree, but then
// their determinants disagree), so exactly one of the two counts the crossing, and exactly one
// triangle of a fan around a vertex (a silhouette edge or vertex, where the triangles lie on one
// side, counts 0 or 2: the ray touches or enters and leaves). The projected coordinates are
// recomputed exactly as intersectWatertight computes them. Out of line: the hot loop of
// crossesTriangle below rarely needs it.
[[gnu::noinline]] bool ownsTouchingHit(const WatertightRay& wray, const TriangleVertices& v,
                                       const WatertightHit& h) {
  using watertight_detail::coordinate;
  const auto project = [&](const Point3& p, double& x, double& y) {
    const double z = coordinate(p, wray.kz) - coordinate(wray.origin, wray.kz);
    x = (coordinate(p, wray.kx) - coordinate(wray.origin, wray.kx)) - wray.sx * z;
    y = (coordinate(p, wray.ky) - coordinate(wray.origin, wray.ky)) - wray.sy * z;
  };
  double ax, ay, bx, by, cx, cy;
  project(v.p0, ax, ay);
  project(v.p1, bx, by);
  project(v.p2, cx, cy);
  // The non-zero edge functions share the determinant's sign; a zero one must take it too.
  const int want = h.det > 0 ? 1 : -1;
  if (h.u == 0 && tieSign(cx, cy, bx, by) != want) return false;
  if (h.v == 0 && tieSign(ax, ay, cx, cy) != want) return false;
  if (h.w == 0 && tieSign(bx, by, ax, ay) != want) return false;
  return true;
}

inline bool crossesTriangle(const WatertightRay& wray, const Vec3& direction,
                            const TriangleVertices& v, double tMin, double tMax) {
  WatertightHit h;
  if (!hitTriangle(wray, direction, v, tMin, tMax, h)) return false;
  return (h.u != 0 && h.v != 0 && h.w != 0) || ownsTouchingHit(wray, v, h);
}

// The slab test of a node's children for one traversal (slab_test.h): the ray, and the interval
// of t as floats in every lane; test returns a bit per child whose box the interval overlaps and
// can store the entry distances.
template <class NodeType>
class ChildTest;

template <>
class ChildTest<Node> {
 public:
  ChildTest(const BoxRay& ray, float tMin, float tMax)
      : ray_(ray), tMin_(_mm_set1_ps(tMin)), tMax_(_mm_set1_ps(tMax)) {}
  void setTMax(float tMax) { tMax_ = _mm_set1_ps(tMax); }
  unsigned test(const Node& node) const {
    __m128 tNear;
    return static_cast<unsigned>(intersectNode(node, ray_, tMin_, tMax_, tNear));
  }
  unsigned test(const Node& node, float* tNear) const {
    __m128 t;
    const int mask = intersectNode(node, ray_, tMin_, tMax_, t);
    _mm_store_ps(tNear, t);
    return static_cast<unsigned>(mask);
  }

 private:
  const BoxRay& ray_;
  __m128 tMin_;
  __m128 tMax_;
};

#ifdef __AVX2__
// The AVX2 and AVX-512 kernels: one 256-bit test of all eight children.
template <>
class ChildTest<Node8> {
 public:
  ChildTest(const BoxRay& ray, float tMin, float tMax)
      : ray_(ray), tMin_(_mm256_set1_ps(tMin)), tMax_(_mm256_set1_ps(tMax)) {}
  void setTMax(float tMax) { tMax_ = _mm256_set1_ps(tMax); }
  unsigned test(const Node8& node) const {
    __m256 tNear;
    return static_cast<unsigned>(intersectNode(node, ray_, tMin_, tMax_, tNear));
  }
  unsigned test(const Node8& node, float* tNear) const {
    __m256 t;
    const int mask = intersectNode(node, ray_, tMin_, tMax_, t);
    _mm256_store_ps(tNear, t);
    return static_cast<unsigned>(mask);
  }

 private:
  slab::WideBoxRay ray_;
  __m256 tMin_;
  __m256 tMax_;
};
#else
// The baseline kernels on an 8-wide tree: two SSE tests of four children each.
template <>
class ChildTest<Node8> {
 public:
  ChildTest(const BoxRay& ray, float tMin, float tMax)
      : ray_(ray), tMin_(_mm_set1_ps(tMin)), tMax_(_mm_set1_ps(tMax)) {}
  void setTMax(float tMax) { tMax_ = _mm_set1_ps(tMax); }
  unsigned test(const Node8& node) const {
    __m128 low;
    __m128 high;
    return static_cast<unsigned>(intersectHalf(node, 0, ray_, tMin_, tMax_, low) |
                                 intersectHalf(node, 4, ray_, tMin_, tMax_, high) << 4);
  }
  unsigned test(const Node8& node, float* tNear) const {
    __m128 low;
    __m128 high;
    const int mask = intersectHalf(node, 0, ray_, tMin_, tMax_, low) |
                     intersectHalf(node, 4, ray_, tMin_, tMax_, high) << 4;
    _mm_store_ps(tNear, low);
    _mm_store_ps(tNear + 4, high);
    return static_cast<unsigned>(mask);
  }

 private:
  const BoxRay& ray_;
  __m128 tMin_;
  __m128 tMax_;
};
#endif

// Fills hit with a hit on analytic primitive `primitive` of this aggregate at t (its ShapeHit).
inline void setPrimitiveHit(const ShapeHit& shapeHit, double t, std::uint32_t primitive, Hit& hit) {
  hit.t = t;
  hit.normal = shapeHit.normal;
  hit.shadingNormal = shapeHit.normal;
  hit.point = shapeHit.point;
  hit.pointError = shapeHit.pointError;
  hit.primitive = primitive;
  hit.mesh = kNoMesh;
  hit.triangle = 0;
  hit.part = shapeHit.part;
  hit.instance = kNoInstance;
}

// Tie ranks of the closest-hit query (see intersect): bounded primitives by index, then triangles
// by mesh and triangle.
constexpr std::uint64_t kBoundedPrimitiveRank = std::uint64_t{1} << 62;
inline std::uint64_t triangleRank(std::uint32_t mesh, std::uint32_t triangle) {
  return (std::uint64_t{2} << 62) | (static_cast<std::uint64_t>(mesh) << 32) | triangle;
}

#ifndef GLINT_AGGREGATE_KERNELS_ONLY
std::string meshName(std::size_t m) { return "mesh " + std::to_string(m); }

void validateMesh(const TriangleMesh& mesh, std::size_t m) {
  if (mesh.indices.size() % 3 != 0) {
    throw std::invalid_argument(meshName(m) + " has " + std::to_string(mesh.indices.size()) +
                                " vertex indices, not a multiple of 3");
  }
  if (mesh.indices.size() / 3 > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error(meshName(m) + " has more triangles than a 32-bit index can address");
  }
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) {
    throw std::invalid_argument(meshName(m) + " has " + std::to_string(mesh.normals.size()) +
                                " normals for " + std::to_string(mesh.positions.size()) +
                                " positions");
  }
  for (const auto& [what, count] :
       {std::pair{"uvs", mesh.uvs.size()}, std::pair{"tangents", mesh.tangents.size()},
        std::pair{"colors", mesh.colors.size()}}) {
    if (count != 0 && count != mesh.positions.size()) {
      throw std::invalid_argument(meshName(m) + " has " + std::to_string(count) + " " + what +
                                  " for " + std::to_string(mesh.positions.size()) + " positions");
    }
  }
  const std::size_t positions = mesh.positions.size();
  const auto bad = std::find_if(mesh.indices.begin(), mesh.indices.end(),
                                [positions](std::uint32_t i) { return i >= positions; });
  if (bad != mesh.indices.end()) {
    const auto k = static_cast<std::size_t>(bad - mesh.indices.begin());
    throw std::invalid_argument(meshName(m) + ": vertex " + std::to_string(k % 3) +
                                " of triangle " + std::to_string(k / 3) + " is index " +
                                std::to_string(*bad) + ", past its " + std::to_string(positions) +
                                " positions");
  }
}
#endif  // GLINT_AGGREGATE_KERNELS_ONLY

}  // namespace

#ifndef GLINT_AGGREGATE_KERNELS_ONLY

Aggregate::Aggregate(std::vector<Primitive> primitives, std::vector<Color> primitiveTransmission,
                     std::vector<TriangleMesh> meshes, std::vector<Color> meshTransmission,
                     Acceleration acceleration, std::shared_ptr<const InstanceSet> instances)
    : primitives_(std::move(primitives)),
      transmission_(std::move(primitiveTransmission)),
      meshes_(std::move(meshes)),
      meshTransmission_(std::move(meshTransmission)),
      acceleration_(acceleration),
      instances_(std::move(instances)) {
  if (instances_) bounds_ = instances_->bounds();
  if (transmission_.size() != primitives_.size()) {
    throw std::invalid_argument("Aggregate: " + std::to_string(transmission_.size()) +
                                " transmission colors for " + std::to_string(primitives_.size()) +
                                " primitives");
  }
  if (meshTransmission_.size() != meshes_.size()) {
    throw std::invalid_argument("Aggregate: " + std::to_string(meshTransmission_.size()) +
                                " mesh transmission colors for " + std::to_string(meshes_.size()) +
                                " meshes");
  }
  if (meshes_.size() > bvh::kMaxMeshes) {
    throw std::length_error("Aggregate: more than " + std::to_string(bvh::kMaxMeshes) + " meshes");
  }
  std::size_t references = primitives_.size();
  for (std::size_t m = 0; m < meshes_.size(); ++m) {
    validateMesh(meshes_[m], m);
    references += meshes_[m].triangleCount();
  }
  if (references > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error(
        "Aggregate: more primitives and triangles than a 32-bit index can "
        "address");
  }

  // One build reference per bounded primitive and per non-degenerate triangle. Triangle references
  // are made in parallel at fixed slots, then the dropped ones are squeezed out in order.
  bvh::BuildItems items(references);
  std::size_t itemCount = 0;
  for (std::uint32_t i = 0; i < primitives_.size(); ++i) {
    const Primitive& p = primitives_[i];
    if (acceleration_ != Acceleration::BruteForce && !p.isBounded()) {
      unbounded_.push_back(i);
      continue;
    }
    if (!p.isBounded()) continue;
    const Bounds3 b = p.bounds();
    bounds_ = unite(bounds_, b);
    const double lo[3] = {b.lo.x, b.lo.y, b.lo.z};
    const double hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    items[itemCount++] = bvh::makeBuildItem(lo, hi, kPrimitiveKey, i);
  }
  const std::size_t primitiveItems = itemCount;
  meshBegin_.assign(meshes_.size() + 1, 0);
  for (std::size_t m = 0; m < meshes_.size(); ++m) {
    const TriangleMesh& mesh = meshes_[m];
    const std::size_t triangles = mesh.triangleCount();
    const std::size_t chunks = (triangles + kTriangleChunk - 1) / kTriangleChunk;
    std::vector<Bounds3> chunkBounds(chunks);
    std::vector<char> chunkDropsSome(chunks, 0);
    bvh::BuildItem* slots = items.data() + itemCount;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const auto& range) {
      for (std::size_t c = range.begin(); c != range.end(); ++c) {
        Bounds3 bounds;
        const std::size_t end = std::min(triangles, (c + 1) * kTriangleChunk);
        for (std::size_t t = c * kTriangleChunk; t < end; ++t) {
          const TriangleVertices v = verticesOf(mesh, static_cast<std::uint32_t>(t));
          if (isDegenerateTriangle(v.p0, v.p1, v.p2)) {
            slots[t] = bvh::makeBuildItem(std::array<double, 3>{}.data(),
                                          std::array<double, 3>{}.data(), kDroppedKey, 0);
            chunkDropsSome[c] = 1;
            continue;
          }
          const Bounds3 b = unite(Bounds3(v.p0, v.p1), v.p2);
          bounds = unite(bounds, b);
          const double lo[3] = {b.lo.x, b.lo.y, b.lo.z};
          const double hi[3] = {b.hi.x, b.hi.y, b.hi.z};
          slots[t] = bvh::makeBuildItem(lo, hi, static_cast<std::uint32_t>(m),
                                        static_cast<std::uint32_t>(t));
        }
        chunkBounds[c] = bounds;
      }
    });
    for (const Bounds3& b : chunkBounds) bounds_ = unite(bounds_, b);
    // The references before the first chunk with a dropped triangle are in place already (a
    // serial pass over 32 MB for a 1M-triangle mesh with none dropped).
    std::size_t t = 0;
    for (std::size_t c = 0; c < chunks && chunkDropsSome[c] == 0; ++c) {
      t = std::min(triangles, (c + 1) * kTriangleChunk);
    }
    itemCount += t;
    for (; t < triangles; ++t) {
      if (bvh::itemKey(slots[t]) != kDroppedKey) items[itemCount++] = slots[t];
    }
    meshBegin_[m + 1] = static_cast<std::uint32_t>(itemCount - primitiveItems);
  }
  items.resize(itemCount);
  triangleCount_ = itemCount - primitiveItems;

  if (acceleration_ == Acceleration::BruteForce) {
    // Every primitive in index order, then each mesh's triangles in order.
    leafRefs_.reserve(triangleCount_);
    for (std::size_t i = primitiveItems; i < itemCount; ++i) {
      leafRefs_.push_back(bvh::itemIndex(items[i]));
    }
    return;
  }
  meshBegin_.clear();
  meshBegin_.shrink_to_fit();
  bvh::Tree tree = bvh::build(items);
  nodes_ = std::move(tree.nodes);
  rootChild_ = tree.rootChild;
  rootInfo_ = tree.rootInfo;
  storeInLeafOrder(items);
  const bool wide = acceleration_ == Acceleration::Bvh8 ||
                    (acceleration_ == Acceleration::Bvh && bvhNodeWidth(kernels_->isa) == 8);
  nodeWidth_ = wide ? 8 : 4;
  if (wide && rootInfo_ == kInner) {
    wideNodes_ = bvh::collapseToWide(nodes_);
    bvh::Nodes().swap(nodes_);
    rootChild_ = 0;
  }
}

int bvhNodeWidth(Isa isa) {
  const char* forced = std::getenv("GLINT_BVH_WIDTH");
  if (forced != nullptr && *forced != '\0') {
    const std::string_view width(forced);
    if (width == "4") return 4;
    if (width == "8") return 8;
    throw IsaError("GLINT_BVH_WIDTH is \"" + std::string(width) +
                   "\"; it must be 4 or 8 (children per BVH node)");
  }
  // Per ISA, as measured (docs/benchmarks.md): 8-wide nodes gave no gain beyond the noise.
  constexpr std::array<int, 3> kWidthOf = {4, 4, 4};  // baseline, avx2, avx512
  return kWidthOf[static_cast<std::size_t>(isa)];
}

int Aggregate::nodeWidth() const { return nodeWidth_; }

namespace {

// Stores `mesh` with its triangles in the order `order` (old triangle indices, new order) and its
// vertices numbered by first use in that order (unused ones left out). The numbering is serial by
// nature; on several threads the triangles are cut into blocks numbered side by side: the first
// block numbers its vertices for good, each other block numbers its own in first-use order, and
// a serial merge in block order then gives each vertex not used by an earlier block the next
// number — the same numbers as one pass over all triangles, whatever the thread count.
void storeMeshInOrder(TriangleMesh& mesh, const std::uint32_t* order, std::size_t triangles) {
  constexpr std::uint32_t kUnused = 0xffffffffu;
  // Blocks of at least this many triangles (smaller ones are not worth their merge); at most
  // kMaxBlocks, since each other block holds a number per old vertex.
  constexpr std::size_t kMinBlockTriangles = 16384;
  constexpr std::size_t kMaxBlocks = 4;
  const std::size_t threads = std::min<std::size_t>(
      static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()),
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  const std::size_t blocks =
      std::clamp<std::size_t>(std::min(threads, triangles / kMinBlockTriangles), 1, kMaxBlocks);
  const std::size_t oldVertices = mesh.positions.size();
  HugePageArray<std::uint32_t> vertexOf(oldVertices, kUnused);  // old vertex → new, block 0's
  std::vector<std::uint32_t> indices = hugePageVector<std::uint32_t>(3 * triangles);
  struct Block {
    std::size_t begin = 0, end = 0;        // triangles
    HugePageArray<std::uint32_t> localOf;  // old vertex → number within the block
    std::vector<std::uint32_t> firstUsed;  // old vertices, in the block's first-use order
    std::vector<std::uint32_t> globalOf;   // number within the block → new vertex
  };
  std::vector<Block> parts(blocks);
  for (std::size_t b = 0; b < blocks; ++b) {
    parts[b].begin = triangles * b / blocks;
    parts[b].end = triangles * (b + 1) / blocks;
  }
  std::uint32_t vertices = 0;
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    Block& block = parts[b];
    std::uint32_t* numbers = vertexOf.data();
    std::uint32_t used = 0;
    if (b > 0) {
      block.localOf.assign(oldVertices, kUnused);
      numbers = block.localOf.data();
    }
    for (std::size_t t = block.begin; t < block.end; ++t) {
      const std::uint32_t* corners = mesh.indices.data() + std::size_t{3} * order[t];
      for (std::size_t c = 0; c < 3; ++c) {
        std::uint32_t& v = numbers[corners[c]];
        if (v == kUnused) {
          v = used++;
          if (b > 0) block.firstUsed.push_back(corners[c]);
        }
        indices[3 * t + c] = v;
      }
    }
    if (b == 0) vertices = used;
  });
  for (std::size_t b = 1; b < blocks; ++b) {
    Block& block = parts[b];
    block.globalOf.resize(block.firstUsed.size());
    for (std::size_t local = 0; local < block.firstUsed.size(); ++local) {
      std::uint32_t& v = vertexOf[block.firstUsed[local]];
      if (v == kUnused) v = vertices++;
      block.globalOf[local] = v;
    }
    HugePageArray<std::uint32_t>().swap(block.localOf);
  }
  tbb::parallel_for(std::size_t{1}, std::max<std::size_t>(blocks, 1), [&](std::size_t b) {
    const Block& block = parts[b];
    for (std::size_t k = 3 * block.begin; k < 3 * block.end; ++k) {
      indices[k] = block.globalOf[indices[k]];
    }
  });

  std::vector<Point3> positions = hugePageVector<Point3>(vertices);
  std::vector<Normal3> normals = hugePageVector<Normal3>(mesh.normals.empty() ? 0 : vertices);
  std::vector<Point2> uvs = hugePageVector<Point2>(mesh.uvs.empty() ? 0 : vertices);
  std::vector<VertexTangent> tangents =
      hugePageVector<VertexTangent>(mesh.tangents.empty() ? 0 : vertices);
  std::vector<Color> colors = hugePageVector<Color>(mesh.colors.empty() ? 0 : vertices);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, oldVertices, 16384),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t old = range.begin(); old != range.end(); ++old) {
          const std::uint32_t v = vertexOf[old];
          if (v == kUnused) continue;
          positions[v] = mesh.positions[old];
          if (!normals.empty()) normals[v] = mesh.normals[old];
          if (!uvs.empty()) uvs[v] = mesh.uvs[old];
          if (!tangents.empty()) tangents[v] = mesh.tangents[old];
          if (!colors.empty()) colors[v] = mesh.colors[old];
        }
      },
      tbb::simple_partitioner());
  mesh.indices = std::move(indices);
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
  mesh.uvs = std::move(uvs);
  mesh.tangents = std::move(tangents);
  mesh.colors = std::move(colors);
}

}  // namespace

// Measured on the 1M-triangle torus with random rays: a triangle test chased leaf reference →
// mesh index triple → three positions, up to five cache misses with the node's two, and closest
// hit ran at 0.35× Embree's rate (0.40× after this; camera rays 0.43× → 0.54×). Renumbering each
// mesh's triangles into leaf order makes a leaf a contiguous range of its mesh's index triples (no
// reference array for triangles), and renumbering the vertices by first use in that order puts a
// leaf's positions and normals next to each other. Values are moved, never recomputed, so every hit
// is bit for bit what it was.
void Aggregate::storeInLeafOrder(const bvh::BuildItems& items) {
  const std::size_t n = items.size();
  // Keys 0 .. meshes_.size() − 1 are the meshes, meshes_.size() the analytic primitives.
  const std::size_t keys = meshes_.size() + 1;
  const auto keyIndex = [&](const bvh::BuildItem& item) {
    const std::uint32_t key = bvh::itemKey(item);
    return key == kPrimitiveKey ? meshes_.size() : std::size_t{key};
  };
  // An item's slot is its rank among the items of its key, in leaf order: counted per block of
  // items, the blocks in parallel (one block when the per-block counters would outweigh them).
  constexpr std::size_t kBlockItems = 65536;
  std::size_t blocks = std::max<std::size_t>(1, (n + kBlockItems - 1) / kBlockItems);
  if (keys * blocks > n) blocks = 1;
  const auto blockRange = [&](std::size_t b) {
    return std::pair{n * b / blocks, n * (b + 1) / blocks};
  };
  std::vector<std::uint32_t> firstSlot(blocks * keys, 0);  // [block][key], counts at first
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    const auto [begin, end] = blockRange(b);
    std::uint32_t* counts = firstSlot.data() + b * keys;
    for (std::size_t i = begin; i < end; ++i) ++counts[keyIndex(items[i])];
  });
  std::vector<std::uint32_t> keyCount(keys, 0);
  for (std::size_t b = 0; b < blocks; ++b) {
    for (std::size_t k = 0; k < keys; ++k) {
      const std::uint32_t count = firstSlot[b * keys + k];
      firstSlot[b * keys + k] = keyCount[k];
      keyCount[k] += count;
    }
  }
  const std::uint32_t primitiveRefs = keyCount[meshes_.size()];
  leafRefs_.assign(primitiveRefs, 0);
  // Per mesh, its triangles' old indices in leaf order (each element written once).
  std::vector<UnzeroedHugePageArray<std::uint32_t>> oldTriangle(meshes_.size());
  for (std::size_t m = 0; m < meshes_.size(); ++m) oldTriangle[m].resize(keyCount[m]);
  UnzeroedHugePageArray<std::uint32_t> slot(n);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    const auto [begin, end] = blockRange(b);
    std::uint32_t* next = firstSlot.data() + b * keys;
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t k = keyIndex(items[i]);
      slot[i] = next[k]++;
      std::uint32_t& to = k == meshes_.size() ? leafRefs_[slot[i]] : oldTriangle[k][slot[i]];
      to = bvh::itemIndex(items[i]);
    }
  });
  leafSpheres_.assign(primitiveRefs, LeafSphere{});
  for (std::size_t k = 0; k < leafRefs_.size(); ++k) {
    const Primitive& p = primitives_[leafRefs_[k]];
    if (const auto* sphere = std::get_if<Sphere>(&p.shape()); sphere && !p.worldFromObject()) {
      leafSpheres_[k] = {sphere->center, sphere->radius};
    }
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes_.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        Node& node = nodes_[i];
                        for (int k = 0; k < 4; ++k) {
                          if (bvh::isLeaf(node.info[k])) node.child[k] = slot[node.child[k]];
                        }
                      }
                    });
  if (bvh::isLeaf(rootInfo_)) rootChild_ = slot[rootChild_];
  UnzeroedHugePageArray<std::uint32_t>().swap(slot);
  tbb::parallel_for(std::size_t{0}, meshes_.size(), [&](std::size_t m) {
    storeMeshInOrder(meshes_[m], oldTriangle[m].data(), oldTriangle[m].size());
  });
}

std::size_t Aggregate::memoryBytes() const {
  std::size_t bytes = 0;
  for (const TriangleMesh& mesh : meshes_) {
    bytes +=
        mesh.positions.capacity() * sizeof(Point3) + mesh.normals.capacity() * sizeof(Normal3) +
        mesh.indices.capacity() * sizeof(std::uint32_t) + mesh.uvs.capacity() * sizeof(Point2) +
        mesh.tangents.capacity() * sizeof(VertexTangent) + mesh.colors.capacity() * sizeof(Color);
  }
  bytes += primitives_.capacity() * sizeof(Primitive) + transmission_.capacity() * sizeof(Color) +
           meshTransmission_.capacity() * sizeof(Color) +
           unbounded_.capacity() * sizeof(std::uint32_t) + nodes_.capacity() * sizeof(Node) +
           wideNodes_.capacity() * sizeof(Node8) + leafRefs_.capacity() * sizeof(std::uint32_t) +
           leafSpheres_.capacity() * sizeof(LeafSphere) +
           meshBegin_.capacity() * sizeof(std::uint32_t);
  if (instances_) bytes += instances_->memoryBytes();
  return bytes;
}

void Aggregate::finishTriangleHit(std::uint32_t mesh, std::uint32_t triangle,
                                  const WatertightHit& candidate, const Vec3& normal,
                                  Hit& hit) const {
  const TriangleMesh& m = meshes_[mesh];
  const TriangleVertices v = verticesOf(m, triangle);
  hit.t = candidate.t;
  hit.normal = Normal3(normalize(normal));
  hit.shadingNormal = hit.normal;
  watertightHitPoint(v.p0, v.p1, v.p2, candidate, hit.point, hit.pointError);
  hit.primitive = 0;
  hit.mesh = mesh;
  hit.triangle = triangle;
  hit.instance = kNoInstance;
  if (m.normals.empty()) return;
  // Barycentric interpolation of the vertex normals (weights u/det, v/det, w/det).
  const std::uint32_t* index = m.indices.data() + 3 * static_cast<std::size_t>(triangle);
  const double inverseDet = 1 / candidate.det;
  const Vec3 n = toVec(m.normals[index[0]]) * (candidate.u * inverseDet) +
                 toVec(m.normals[index[1]]) * (candidate.v * inverseDet) +
                 toVec(m.normals[index[2]]) * (candidate.w * inverseDet);
  const double len = length(n);
  // Opposed vertex normals can cancel; the geometric normal is then the only meaningful one.
  if (len > 0 && std::isfinite(len)) hit.shadingNormal = Normal3(n / len);
}

#endif  // GLINT_AGGREGATE_KERNELS_ONLY

namespace {

// What a closest-hit search reads of the Aggregate's leaves.
struct LeafView {
  const Primitive* primitives;
  const std::uint32_t* leafRefs;
  const LeafSphere* leafSpheres;
  const TriangleMesh* meshes;
};

// One ray's closest-hit search: the best hit so far and the bounds it sets on the rest of the walk.
// The single-ray query keeps one, the packet query one per ray; both run the same leaf tests, so
// a ray finds the same hit either way.
//
// Exact ties in t. The answer is the hit of least (t, rank), whatever order the tree is walked in
// (node width, ISA, near-child order, packet or single ray): an unbounded primitive (rank 0: the
// loop over them keeps the first of equals) before a bounded primitive (by index) before a mesh
// triangle (by mesh, then triangle in leaf order, the same numbering for every width). Elements
// are tested against `limit`: tMax (exclusive) until the tree finds a hit, then the next double
// above `closest`, so an element at exactly `closest` is seen and the ranks decide.
struct ClosestHitSearch {
  enum class Found { None, Primitive, Triangle };

  const Ray* ray = nullptr;
  double tMin = 0;
  Found found = Found::None;
  double closest = 0;
  double limit = 0;
  std::uint64_t bestRank = 0;
  float closestF = 0;     // floatAbove(closest · kFarScale): the slab tests' far bound
  ShapeHit primitiveHit;  // the closest primitive hit so far (valid when found == Primitive)
  bool primitiveHitComplete = true;
  std::uint32_t hitIndex = 0;  // primitive, or triangle within hitMesh
  std::uint32_t hitMesh = 0;
  WatertightHit triangleHit;
  Vec3 triangleNormal;  // of the closest triangle hit, unnormalised (see hitTriangle)
  WatertightRay wray;   // set up at the first triangle leaf: analytic scenes never need it
  bool wrayReady = false;

  // Unbounded primitives first: they are typically ground planes and walls, and a hit there
  // shrinks the interval the BVH has to search. A plane's hit point waits until it is known to be
  // the closest hit: a third of the plane hits of the spheres scene lie behind a sphere.
  void start(const Ray& r, double tMinimum, double tMax, const Primitive* primitives,
             const std::vector<std::uint32_t>& unbounded, ShapeHit& scratch) {
    ray = &r;
    tMin = tMinimum;
    closest = tMax;
    for (const std::uint32_t index : unbounded) {
      bool complete;
      if (primitives[index].intersectDeferred(r, tMin, closest, scratch, complete)) {
        closest = scratch.t;
        primitiveHit = scratch;
        primitiveHitComplete = complete;
        hitIndex = index;
        found = Found::Primitive;
      }
    }
    limit = closest;
    closestF = floatAbove(closest * kFarScale);
  }

  bool accept(double t, std::uint64_t rank) {
    if (t == closest && found != Found::None && !(rank < bestRank)) return false;
    closest = t;
    bestRank = rank;
    limit = nextUp(closest);
    return true;
  }

  // Tests the leaf (child, info) of the tree; true when it holds a closer hit (closestF lowered).
  bool testLeaf(const LeafView& v, std::uint32_t child, std::uint32_t info, ShapeHit& scratch) {
    const std::uint32_t count = bvh::leafCount(info);
    const std::uint32_t key = bvh::leafKey(info);
    bool closer = false;
    if (key == kPrimitiveKey) {
      for (std::uint32_t k = child; k < child + count; ++k) {
        const std::uint32_t index = v.leafRefs[k];
        const LeafSphere& sphere = v.leafSpheres[k];
        // An untransformed sphere inline, exactly as Primitive::intersect would test it.
        const bool hitIt =
            sphere.radius > 0
                ? quadric::sphereIntersect(sphere.center, sphere.radius, *ray, tMin, limit, scratch)
                : v.primitives[index].intersect(*ray, tMin, limit, scratch);
        if (hitIt && accept(scratch.t, kBoundedPrimitiveRank | index)) {
          primitiveHit = scratch;
          primitiveHitComplete = true;
          hitIndex = index;
          found = Found::Primitive;
          closer = true;
        }
      }
    } else {
      const TriangleMesh& mesh = v.meshes[key];
      if (!wrayReady) {
        wray = WatertightRay(*ray);
        wrayReady = true;
      }
      WatertightHit candidate;  // a rejected (parallel) candidate must not overwrite the best
      Vec3 candidateNormal;
      for (std::uint32_t triangle = child; triangle < child + count; ++triangle) {
        if (hitTriangle(wray, ray->direction, verticesOf(mesh, triangle), tMin, limit, candidate,
                        candidateNormal) &&
            accept(candidate.t, triangleRank(key, triangle))) {
          triangleHit = candidate;
          triangleNormal = candidateNormal;
          hitIndex = triangle;
          hitMesh = key;
          found = Found::Triangle;
          closer = true;
        }
      }
    }
    if (closer) closestF = floatAbove(closest * kFarScale);
    return closer;
  }

  // Fills hit from the best hit found (finishTriangle(mesh, triangle, watertight hit, normal, hit)
  // for a triangle); false when there is none.
  template <class FinishTriangle>
  bool finish(const Primitive* primitives, Hit& hit, FinishTriangle finishTriangle) {
    if (found == Found::Triangle) {
      const WatertightHit best = triangleHit;
      const Vec3 normal = triangleNormal;
      finishTriangle(hitMesh, hitIndex, best, normal, hit);
    } else if (found == Found::Primitive) {
      ShapeHit best = primitiveHit;
      if (!primitiveHitComplete) primitives[hitIndex].completeHit(*ray, best);
      setPrimitiveHit(best, closest, hitIndex, hit);
    }
    return found != Found::None;
  }
};

// Near child first: visits the nearest entry of `hits` (hitCount ≥ 2 entries, any order) next
// and pushes the others onto the stack farthest first.
template <int kWidth, class Entry, class Stack>
void sortNearFirst(std::array<Entry, kWidth>& hits, int hitCount, Stack& stack, int& stackSize) {
  for (int k = 1; k < hitCount; ++k) {
    const Entry entry = hits[k];
    int j = k;
    while (j > 0 && hits[j - 1].tNear > entry.tNear) {
      hits[j] = hits[j - 1];
      --j;
    }
    hits[j] = entry;
  }
  for (int k = hitCount - 1; k > 0; --k) stack[stackSize++] = hits[k];
}

// Starts loading a child reference pushed onto a traversal stack: its node (every cache line)
// or a triangle leaf's first index triple. The near children below it are walked first, so by the
// time it is popped the lines have arrived (the walk of a large tree waits on memory, not on
// arithmetic).
template <class NodeType>
inline void prefetchChild(const NodeType* nodes, const TriangleMesh* meshes, std::uint32_t child,
                          std::uint32_t info) {
  if (info == kInner) {
    const char* node = reinterpret_cast<const char*>(nodes + child);
    for (std::size_t line = 0; line < sizeof(NodeType); line += 64) {
      _mm_prefetch(node + line, _MM_HINT_T0);
    }
  } else if (bvh::leafKey(info) != kPrimitiveKey) {
    _mm_prefetch(reinterpret_cast<const char*>(meshes[bvh::leafKey(info)].indices.data() +
                                               std::size_t{3} * child),
                 _MM_HINT_T0);
  }
}

}  // namespace

[[gnu::flatten]] bool Aggregate::GLINT_ISA_KERNEL(intersect)(const Ray& ray, double tMin,
                                                             double tMax, Hit& hit) const {
  if (acceleration_ == Acceleration::BruteForce) return intersectBruteForce(ray, tMin, tMax, hit);
  enum class Found { None, Primitive, Triangle } found = Found::None;
  double closest = tMax;
  ShapeHit shapeHit;
  ShapeHit primitiveHit;       // the closest primitive hit so far (valid when found == Primitive)
  std::uint32_t hitIndex = 0;  // primitive, or triangle within hitMesh
  std::uint32_t hitMesh = 0;
  WatertightHit triangleHit;
  Vec3 triangleNormal;  // of the closest triangle hit, unnormalised (see hitTriangle)

  // Unbounded primitives first: they are typically ground planes and walls, and a hit there shrinks
  // the interval the BVH has to search. A plane's hit point waits until it is known to be the
  // closest hit: a third of the plane hits of the spheres scene lie behind a sphere.
  bool primitiveHitComplete = true;
  for (const std::uint32_t index : unbounded_) {
    bool complete;
    if (primitives_[index].intersectDeferred(ray, tMin, closest, shapeHit, complete)) {
      closest = shapeHit.t;
      primitiveHit = shapeHit;
      primitiveHitComplete = complete;
      hitIndex = index;
      found = Found::Primitive;
    }
  }

  // Exact ties in t: the answer is the hit of least (t, rank) whatever order the tree is walked in
  // (see ClosestHitSearch, which runs these leaf tests for each ray of a packet). This query keeps
  // its search in plain locals rather than a ClosestHitSearch: measured, the struct made single-ray
  // closest hits 3–18 % slower (the compiler kept fewer of its fields in registers).
  std::uint64_t bestRank = 0;
  double limit = closest;
  const auto accept = [&](double t, std::uint64_t rank) {
    if (t == closest && found != Found::None && !(rank < bestRank)) return false;
    closest = t;
    bestRank = rank;
    limit = nextUp(closest);
    return true;
  };
  const auto traverse = [&](const auto* nodes) {
    using NodeType = std::remove_cvref_t<decltype(*nodes)>;
    constexpr int kWidth = NodeType::kWidth;
    const BoxRay boxRay(ray);
    WatertightRay wray;  // set up at the first triangle leaf: analytic scenes never need it
    bool wrayReady = false;
    float closestF = floatAbove(closest * kFarScale);
    ChildTest<NodeType> childTest(boxRay, floatBelow(tMin), closestF);
    constexpr int kStack = kWidth == 4 ? bvh::kStackSize : bvh::kWideStackSize;
    std::array<StackEntry, kStack> stack;
    int stackSize = 0;
    std::uint32_t child = rootChild_;
    std::uint32_t info = rootInfo_;
    while (true) {
      if (info == kInner) {
        const NodeType& node = nodes[child];
        alignas(32) std::array<float, kWidth> tNear;
        unsigned mask = childTest.test(node, tNear.data());
        if (mask != 0) {
          const int first = std::countr_zero(mask);
          mask &= mask - 1;
          if (mask == 0) {
            child = node.child[first];
            info = node.info[first];
            continue;
          }
          // Near child first: visit the nearest entry now, push the others farthest first.
          std::array<StackEntry, kWidth> hits;
          int hitCount = 0;
          hits[hitCount++] = {node.child[first], node.info[first], tNear[first]};
          while (mask != 0) {
            const int i = std::countr_zero(mask);
            mask &= mask - 1;
            StackEntry entry{node.child[i], node.info[i], tNear[i]};
            int k = hitCount++;
            while (k > 0 && hits[k - 1].tNear > entry.tNear) {
              hits[k] = hits[k - 1];
              --k;
            }
            hits[k] = entry;
          }
          for (int k = hitCount - 1; k > 0; --k) {
            stack[stackSize++] = hits[k];
            prefetchChild(nodes, meshes_.data(), hits[k].child, hits[k].info);
          }
          child = hits[0].child;
          info = hits[0].info;
          continue;
        }
      } else {
        const std::uint32_t count = bvh::leafCount(info);
        const std::uint32_t key = bvh::leafKey(info);
        bool closer = false;
        if (key == kPrimitiveKey) {
          for (std::uint32_t k = child; k < child + count; ++k) {
            const std::uint32_t index = leafRefs_[k];
            const LeafSphere& sphere = leafSpheres_[k];
            // An untransformed sphere inline, exactly as Primitive::intersect would test it.
            const bool hitIt = sphere.radius > 0
                                   ? quadric::sphereIntersect(sphere.center, sphere.radius, ray,
                                                              tMin, limit, shapeHit)
                                   : primitives_[index].intersect(ray, tMin, limit, shapeHit);
            if (hitIt && accept(shapeHit.t, kBoundedPrimitiveRank | index)) {
              primitiveHit = shapeHit;
              primitiveHitComplete = true;
              hitIndex = index;
              found = Found::Primitive;
              closer = true;
            }
          }
        } else {
          const TriangleMesh& mesh = meshes_[key];
          if (!wrayReady) {
            wray = WatertightRay(ray);
            wrayReady = true;
          }
          WatertightHit candidate;  // a rejected (parallel) candidate must not overwrite the best
          Vec3 candidateNormal;
          for (std::uint32_t triangle = child; triangle < child + count; ++triangle) {
            if (hitTriangle(wray, ray.direction, verticesOf(mesh, triangle), tMin, limit, candidate,
                            candidateNormal) &&
                accept(candidate.t, triangleRank(key, triangle))) {
              triangleHit = candidate;
              triangleNormal = candidateNormal;
              hitIndex = triangle;
              hitMesh = key;
              found = Found::Triangle;
              closer = true;
            }
          }
        }
        if (closer) {
          closestF = floatAbove(closest * kFarScale);
          childTest.setTMax(closestF);
        }
      }
      // Pop the next entry that can still hold something closer (or as close: a tie).
      while (stackSize > 0 && stack[stackSize - 1].tNear > closestF) --stackSize;
      if (stackSize == 0) break;
      --stackSize;
      child = stack[stackSize].child;
      info = stack[stackSize].info;
    }
  };
  if (rootInfo_ != kEmpty) {
    if (wideNodes_.empty()) {
      traverse(nodes_.data());
    } else {
      traverse(wideNodes_.data());
    }
  }

  // Instances last, within the closest hit so far: a tie keeps this aggregate's own hit.
  if (instances_ && instances_->intersect(ray, tMin, closest, hit)) return true;
  if (found == Found::Triangle) {
    finishTriangleHit(hitMesh, hitIndex, triangleHit, triangleNormal, hit);
  } else if (found == Found::Primitive) {
    if (!primitiveHitComplete) primitives_[hitIndex].completeHit(ray, primitiveHit);
    setPrimitiveHit(primitiveHit, closest, hitIndex, hit);
  }
  return found != Found::None;
}

namespace {

// The lanes of a packet of Aggregate::kPacketSize rays in this ISA's widest float registers: one
// 512-bit register under AVX-512, two 256-bit ones under AVX2, four SSE ones in the baseline.
// Lane for lane the arithmetic of the single-ray slab test (slab_test.h): subtract, multiply, then
// max/min with the same operand order, so a NaN lane is ignored alike.
constexpr int kPacketLanes = Aggregate::kPacketSize;
// The least of four floats (none NaN).
inline float minOfFour(__m128 x) {
  x = _mm_min_ps(x, _mm_shuffle_ps(x, x, _MM_SHUFFLE(2, 3, 0, 1)));
  x = _mm_min_ps(x, _mm_shuffle_ps(x, x, _MM_SHUFFLE(1, 0, 3, 2)));
  return _mm_cvtss_f32(x);
}
#if defined(__AVX512F__) && defined(__AVX512DQ__)
struct PacketChunk {
  static constexpr int kWidth = 16;
  __m512 v;
  static PacketChunk load(const float* p) { return {_mm512_loadu_ps(p)}; }
  static PacketChunk all(float x) { return {_mm512_set1_ps(x)}; }
  friend PacketChunk operator-(PacketChunk a, PacketChunk b) { return {_mm512_sub_ps(a.v, b.v)}; }
  friend PacketChunk operator*(PacketChunk a, PacketChunk b) { return {_mm512_mul_ps(a.v, b.v)}; }
  friend PacketChunk max(PacketChunk a, PacketChunk b) { return {_mm512_max_ps(a.v, b.v)}; }
  friend PacketChunk min(PacketChunk a, PacketChunk b) { return {_mm512_min_ps(a.v, b.v)}; }
  friend unsigned lessEqual(PacketChunk a, PacketChunk b) {
    return _mm512_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ);
  }
  // The least of the lanes of `lanes` (bit i: lane i); +inf for none.
  float minOf(unsigned lanes) const {
    return _mm512_mask_reduce_min_ps(static_cast<__mmask16>(lanes), v);
  }
  void store(float* p) const { _mm512_storeu_ps(p, v); }
};
#elif defined(__AVX2__)
struct PacketChunk {
  static constexpr int kWidth = 8;
  __m256 v;
  static PacketChunk load(const float* p) { return {_mm256_loadu_ps(p)}; }
  static PacketChunk all(float x) { return {_mm256_set1_ps(x)}; }
  friend PacketChunk operator-(PacketChunk a, PacketChunk b) { return {_mm256_sub_ps(a.v, b.v)}; }
  friend PacketChunk operator*(PacketChunk a, PacketChunk b) { return {_mm256_mul_ps(a.v, b.v)}; }
  friend PacketChunk max(PacketChunk a, PacketChunk b) { return {_mm256_max_ps(a.v, b.v)}; }
  friend PacketChunk min(PacketChunk a, PacketChunk b) { return {_mm256_min_ps(a.v, b.v)}; }
  friend unsigned lessEqual(PacketChunk a, PacketChunk b) {
    return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)));
  }
  float minOf(unsigned lanes) const {
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256 keep = _mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(static_cast<int>(lanes)), bit), bit));
    const __m256 x =
        _mm256_blendv_ps(_mm256_set1_ps(std::numeric_limits<float>::infinity()), v, keep);
    return minOfFour(_mm_min_ps(_mm256_castps256_ps128(x), _mm256_extractf128_ps(x, 1)));
  }
  void store(float* p) const { _mm256_storeu_ps(p, v); }
};
#else
struct PacketChunk {
  static constexpr int kWidth = 4;
  __m128 v;
  static PacketChunk load(const float* p) { return {_mm_loadu_ps(p)}; }
  static PacketChunk all(float x) { return {_mm_set1_ps(x)}; }
  friend PacketChunk operator-(PacketChunk a, PacketChunk b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend PacketChunk operator*(PacketChunk a, PacketChunk b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend PacketChunk max(PacketChunk a, PacketChunk b) { return {_mm_max_ps(a.v, b.v)}; }
  friend PacketChunk min(PacketChunk a, PacketChunk b) { return {_mm_min_ps(a.v, b.v)}; }
  friend unsigned lessEqual(PacketChunk a, PacketChunk b) {
    return static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(a.v, b.v)));
  }
  float minOf(unsigned lanes) const {
    const __m128i bit = _mm_setr_epi32(1, 2, 4, 8);
    const __m128 keep = _mm_castsi128_ps(
        _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(static_cast<int>(lanes)), bit), bit));
    return minOfFour(
        _mm_or_ps(_mm_and_ps(keep, v),
                  _mm_andnot_ps(keep, _mm_set1_ps(std::numeric_limits<float>::infinity()))));
  }
  void store(float* p) const { _mm_storeu_ps(p, v); }
};
#endif
constexpr int kPacketChunks = kPacketLanes / PacketChunk::kWidth;

// The slab-test data of a packet's rays (BoxRay's, one lane per ray), structure of arrays.
struct PacketRays {
  alignas(64) float nearOrigin[3][kPacketLanes];
  alignas(64) float farOrigin[3][kPacketLanes];
  alignas(64) float nearInverse[3][kPacketLanes];
  alignas(64) float farInverse[3][kPacketLanes];
  alignas(64) float tMin[kPacketLanes];
  alignas(64) float tMax[kPacketLanes];  // each ray's closestF, lowered as it finds hits
  SlabRows rows;                         // of Node, shared: one direction octant per packet

  // Every lane empty (its ray never overlaps a box), the packet's tMin set, its octant that of
  // `first`'s direction.
  PacketRays(double tMinimum, const Ray& first)
      : rows(kSlabRows[static_cast<std::size_t>(
            static_cast<unsigned>(std::signbit(first.direction.x)) |
            static_cast<unsigned>(std::signbit(first.direction.y)) << 1 |
            static_cast<unsigned>(std::signbit(first.direction.z)) << 2)]) {
    const float tMinF = floatBelow(tMinimum);
    for (int i = 0; i < kPacketLanes; ++i) {
      tMin[i] = tMinF;
      tMax[i] = -std::numeric_limits<float>::infinity();
      for (int axis = 0; axis < 3; ++axis) {
        nearOrigin[axis][i] = farOrigin[axis][i] = nearInverse[axis][i] = farInverse[axis][i] = 0;
      }
    }
  }
  // Whether the ray of boxRay has the packet's octant (the others are traced alone).
  bool takes(const BoxRay& boxRay) const { return boxRay.rows.nearRow == rows.nearRow; }
  // Lane i takes the ray of boxRay with the far bound tMaxF.
  void set(int i, const BoxRay& boxRay, float tMaxF) {
    tMax[i] = tMaxF;
    for (int axis = 0; axis < 3; ++axis) {
      nearOrigin[axis][i] = _mm_cvtss_f32(boxRay.nearOrigin[axis]);
      farOrigin[axis][i] = _mm_cvtss_f32(boxRay.farOrigin[axis]);
      nearInverse[axis][i] = _mm_cvtss_f32(boxRay.nearInverse[axis]);
      farInverse[axis][i] = _mm_cvtss_f32(boxRay.farInverse[axis]);
    }
  }
};

// Bit i (of `lanes`): ray i overlaps child `slot`'s box of `node` within its [tMin, tMax].
// `least` (when not null) receives the least entry distance of those rays (+inf for none).
inline unsigned testPacketChild(const Node& node, int slot, const PacketRays& r, unsigned lanes,
                                float* least) {
  const auto row = [&](std::size_t offset) {
    return reinterpret_cast<const float*>(reinterpret_cast<const unsigned char*>(node.bounds) +
                                          offset)[slot];
  };
  std::array<float, 3> nearPlane;
  std::array<float, 3> farPlane;
  for (int axis = 0; axis < 3; ++axis) {
    nearPlane[axis] = row(r.rows.nearRow[axis]);
    farPlane[axis] = row(r.rows.farRow[axis]);
  }
  unsigned bits = 0;
  float nearest = std::numeric_limits<float>::infinity();
  for (int c = 0; c < kPacketChunks; ++c) {
    const int lane = c * PacketChunk::kWidth;
    constexpr unsigned kChunkLanes = (1u << PacketChunk::kWidth) - 1;
    const unsigned chunkLanes = (lanes >> lane) & kChunkLanes;
    if (chunkLanes == 0) continue;
    PacketChunk tn = PacketChunk::load(r.tMin + lane);
    PacketChunk tf = PacketChunk::load(r.tMax + lane);
    for (int axis = 0; axis < 3; ++axis) {
      const PacketChunk n =
          (PacketChunk::all(nearPlane[axis]) - PacketChunk::load(r.nearOrigin[axis] + lane)) *
          PacketChunk::load(r.nearInverse[axis] + lane);
      const PacketChunk f =
          (PacketChunk::all(farPlane[axis]) - PacketChunk::load(r.farOrigin[axis] + lane)) *
          PacketChunk::load(r.farInverse[axis] + lane);
      tn = max(n, tn);
      tf = min(f, tf);
    }
    const unsigned overlap = lessEqual(tn, tf) & chunkLanes;
    if (least != nullptr && overlap != 0) nearest = std::min(nearest, tn.minOf(overlap));
    bits |= overlap << lane;
  }
  if (least != nullptr) *least = nearest;
  return bits;
}

struct PacketEntry {
  std::uint32_t child;
  std::uint32_t info;
  std::uint32_t rays;  // bit i: ray i of the packet goes on into this child
  float tNear;         // the least entry distance among those rays
};

}  // namespace

[[gnu::flatten]] void Aggregate::GLINT_ISA_KERNEL(intersectPacket)(const Ray* rays, int count,
                                                                   double tMin, const double* tMax,
                                                                   Hit* hits, bool* found) const {
  count = std::clamp(count, 0, kPacketSize);
  // Packets walk 4-wide trees only; the rest go one ray at a time.
  if (count == 0 || acceleration_ == Acceleration::BruteForce || rootInfo_ != kInner ||
      !wideNodes_.empty()) {
    for (int i = 0; i < count; ++i) {
      found[i] = GLINT_ISA_KERNEL(intersect)(rays[i], tMin, tMax[i], hits[i]);
    }
    return;
  }
  std::array<ClosestHitSearch, kPacketSize> search;
  ShapeHit scratch;
  PacketRays packet(tMin, rays[0]);
  std::uint32_t active = 0;
  for (int i = 0; i < count; ++i) {
    const BoxRay boxRay(rays[i]);
    if (!packet.takes(boxRay)) {  // another octant: alone
      found[i] = GLINT_ISA_KERNEL(intersect)(rays[i], tMin, tMax[i], hits[i]);
      continue;
    }
    search[i].start(rays[i], tMin, tMax[i], primitives_.data(), unbounded_, scratch);
    packet.set(i, boxRay, search[i].closestF);
    active |= 1u << i;
  }

  const LeafView leaves{primitives_.data(), leafRefs_.data(), leafSpheres_.data(), meshes_.data()};
  // Depth first, nearest child first (by its rays' least entry distance); each child goes on with
  // the rays that overlap its box. Every ray meets every leaf that single-ray traversal would
  // test for it (or more), and the leaf tests and the tie ranks are the single ray's, so the
  // answers are the same.
  std::array<PacketEntry, bvh::kStackSize> stack;
  int stackSize = 0;
  std::uint32_t child = rootChild_;
  std::uint32_t info = rootInfo_;
  std::uint32_t mask = active;
  while (mask != 0) {
    if (info == kInner) {
      const Node& node = nodes_[child];
      std::array<PacketEntry, 4> next;
      int nextCount = 0;
      for (int slot = 0; slot < 4 && node.info[slot] != kEmpty; ++slot) {
        float least;
        const std::uint32_t rayBits = testPacketChild(node, slot, packet, mask, &least);
        if (rayBits == 0) continue;
        next[nextCount++] = {node.child[slot], node.info[slot], rayBits, least};
      }
      if (nextCount > 0) {
        if (nextCount > 1) sortNearFirst<4>(next, nextCount, stack, stackSize);
        child = next[0].child;
        info = next[0].info;
        mask = next[0].rays;
        continue;
      }
    } else {
      for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1) {
        const auto i = static_cast<std::size_t>(std::countr_zero(bits));
        if (search[i].testLeaf(leaves, child, info, scratch)) packet.tMax[i] = search[i].closestF;
      }
    }
    // Pop the next entry that can still hold something closer for one of its rays.
    mask = 0;
    while (stackSize > 0 && mask == 0) {
      const PacketEntry& entry = stack[--stackSize];
      for (std::uint32_t bits = entry.rays; bits != 0; bits &= bits - 1) {
        const int i = std::countr_zero(bits);
        if (!(entry.tNear > packet.tMax[i])) mask |= 1u << i;
      }
      child = entry.child;
      info = entry.info;
    }
  }

  for (std::uint32_t bits = active; bits != 0; bits &= bits - 1) {
    const auto i = static_cast<std::size_t>(std::countr_zero(bits));
    // Instances last, within the closest hit so far: a tie keeps this aggregate's own hit.
    if (instances_ && instances_->intersect(rays[i], tMin, search[i].closest, hits[i])) {
      found[i] = true;
      continue;
    }
    found[i] = search[i].finish(primitives_.data(), hits[i],
                                [this](auto&&... args) { finishTriangleHit(args...); });
  }
}

namespace {

// Multiplies into `result` primitive `primitive`'s factor kt once per crossing of the ray within
// (tMin, tMax) (a csg primitive: each crossing with its operand's kt); false once the product is
// black. `sphere`: its leaf record (radius 0 when it is not an untransformed sphere, or unknown).
// The one crossing rule of the single-ray and the packet transmittance queries.
inline bool crossPrimitive(const Primitive& primitive, const Color& kt, const LeafSphere& sphere,
                           const Ray& ray, double tMin, double tMax, Color& result) {
  if (kt == Color(1)) return true;  // fully transparent: crossings cannot change the product
  if (primitive.csg() != nullptr) {
    result *= primitive.csgTransmittance(ray, tMin, tMax);
    return !isBlack(result);
  }
  // An untransformed sphere inline, exactly as Primitive::crossings would count it.
  const int crossings =
      sphere.radius > 0 ? quadric::sphereCrossings(sphere.center, sphere.radius, ray, tMin, tMax)
                        : primitive.crossings(ray, tMin, tMax);
  if (crossings == 0) return true;
  if (isBlack(kt)) return false;
  for (int k = 0; k < crossings; ++k) result *= kt;
  return !isBlack(result);
}

// Multiplies into `result` the mesh's factor kt once per triangle of the leaf range
// [first, first + count) the ray crosses within (tMin, tMax); false once the product is black.
// `wray` is set up at the first call (wrayReady).
inline bool crossTriangles(const TriangleMesh& mesh, const Color& kt, std::uint32_t first,
                           std::uint32_t count, const Ray& ray, double tMin, double tMax,
                           WatertightRay& wray, bool& wrayReady, Color& result) {
  if (kt == Color(1)) return true;
  if (!wrayReady) {
    wray = WatertightRay(ray);
    wrayReady = true;
  }
  const bool opaque = isBlack(kt);
  for (std::uint32_t triangle = first; triangle < first + count; ++triangle) {
    if (!crossesTriangle(wray, ray.direction, verticesOf(mesh, triangle), tMin, tMax)) continue;
    if (opaque) return false;
    result *= kt;
    if (isBlack(result)) return false;
  }
  return true;
}

}  // namespace

[[gnu::flatten]] Color Aggregate::GLINT_ISA_KERNEL(transmittance)(const Ray& ray, double tMin,
                                                                  double tMax) const {
  if (acceleration_ == Acceleration::BruteForce) return transmittanceBruteForce(ray, tMin, tMax);
  Color result(1);
  const auto cross = [&](std::uint32_t index, const LeafSphere& sphere) {
    return crossPrimitive(primitives_[index], transmission_[index], sphere, ray, tMin, tMax,
                          result);
  };
  for (const std::uint32_t index : unbounded_) {
    if (!cross(index, LeafSphere{})) return Color();
  }
  if (rootInfo_ == kEmpty) return result;

  // Every crossing counts, so the set of crossings does not depend on the order of the visit and
  // the interval never shrinks. Children are visited in slot order, depth first, not nearest first:
  // measured on the 100k torus over its floor (camera rays), sorting made the query 3× slower, and
  // merely taking the nearest child first 3–5× slower (100k / 1M triangles), since the large
  // occluders (the floor) sit near the root and end the query at once. Slot order is also the
  // order of the leaves in either node width (bvh::collapseToWide), so the product of the kt
  // factors is multiplied in the same order, and rounds the same, whatever the width.
  const auto traverse = [&](const auto* nodes) {
    using NodeType = std::remove_cvref_t<decltype(*nodes)>;
    constexpr int kWidth = NodeType::kWidth;
    const BoxRay boxRay(ray);
    WatertightRay wray;  // set up at the first triangle leaf: analytic scenes never need it
    bool wrayReady = false;
    const ChildTest<NodeType> childTest(boxRay, floatBelow(tMin), floatAbove(tMax * kFarScale));
    constexpr int kStack = kWidth == 4 ? bvh::kStackSize : bvh::kWideStackSize;
    std::array<std::uint64_t, kStack> stack;  // child | info << 32
    int stackSize = 0;
    std::uint32_t child = rootChild_;
    std::uint32_t info = rootInfo_;
    while (true) {
      if (info == kInner) {
        const NodeType& node = nodes[child];
        unsigned mask = childTest.test(node);
        if (mask != 0) {
          const int first = std::countr_zero(mask);
          mask &= mask - 1;
          // The others last slot first, so that they come off the stack in slot order.
          while (mask != 0) {
            const int i = std::bit_width(mask) - 1;
            mask &= ~(1u << i);
            stack[stackSize++] = node.child[i] | static_cast<std::uint64_t>(node.info[i]) << 32;
          }
          child = node.child[first];
          info = node.info[first];
          continue;
        }
      } else {
        const std::uint32_t count = bvh::leafCount(info);
        const std::uint32_t key = bvh::leafKey(info);
        if (key == kPrimitiveKey) {
          for (std::uint32_t k = child; k < child + count; ++k) {
            if (!cross(leafRefs_[k], leafSpheres_[k])) return false;
          }
        } else if (!crossTriangles(meshes_[key], meshTransmission_[key], child, count, ray, tMin,
                                   tMax, wray, wrayReady, result)) {
          return false;
        }
      }
      if (stackSize == 0) break;
      const std::uint64_t entry = stack[--stackSize];
      child = static_cast<std::uint32_t>(entry);
      info = static_cast<std::uint32_t>(entry >> 32);
    }
    return true;
  };
  const bool open = wideNodes_.empty() ? traverse(nodes_.data()) : traverse(wideNodes_.data());
  return open ? result : Color();
}

// The packet form of the transmittance query: the tree walked once, depth first in slot order as
// the single ray walks it, each child entered with the rays whose slab test (lane for lane the
// single ray's arithmetic) overlaps its box. So each ray meets the leaves its single-ray walk
// meets, in the same order, and multiplies the same kt factors in the same order: the same bits.
// A ray whose product turns black leaves the packet (any-hit: an opaque blocker ends it).
[[gnu::flatten]] void Aggregate::GLINT_ISA_KERNEL(transmittancePacket)(const Ray* rays, int count,
                                                                       double tMin,
                                                                       const double* tMax,
                                                                       Color* results) const {
  count = std::clamp(count, 0, kPacketSize);
  // Packets walk 4-wide trees only; the rest go one ray at a time.
  if (count == 0 || acceleration_ == Acceleration::BruteForce || rootInfo_ != kInner ||
      !wideNodes_.empty()) {
    for (int i = 0; i < count; ++i) {
      results[i] = GLINT_ISA_KERNEL(transmittance)(rays[i], tMin, tMax[i]);
    }
    return;
  }
  PacketRays packet(tMin, rays[0]);
  std::array<WatertightRay, kPacketSize> wrays;  // set up at each ray's first triangle leaf
  std::array<bool, kPacketSize> wrayReady{};
  std::uint32_t active = 0;
  for (int i = 0; i < count; ++i) {
    const BoxRay boxRay(rays[i]);
    if (!packet.takes(boxRay)) {  // another octant: alone
      results[i] = GLINT_ISA_KERNEL(transmittance)(rays[i], tMin, tMax[i]);
      continue;
    }
    results[i] = Color(1);
    // Unbounded primitives first, as the single ray takes them.
    bool open = true;
    for (const std::uint32_t index : unbounded_) {
      if (!crossPrimitive(primitives_[index], transmission_[index], LeafSphere{}, rays[i], tMin,
                          tMax[i], results[i])) {
        open = false;
        break;
      }
    }
    if (!open) {
      results[i] = Color();
      continue;
    }
    packet.set(i, boxRay, floatAbove(tMax[i] * kFarScale));
    active |= 1u << i;
  }

  // Ray i is blocked: black, and out of the packet.
  const auto block = [&](std::size_t i) {
    results[i] = Color();
    active &= ~(1u << i);
    packet.tMax[i] = -std::numeric_limits<float>::infinity();
  };
  struct Entry {
    std::uint32_t child;
    std::uint32_t info;
    std::uint32_t rays;  // bit i: ray i of the packet goes on into this child
  };
  std::array<Entry, bvh::kStackSize> stack;
  int stackSize = 0;
  std::uint32_t child = rootChild_;
  std::uint32_t info = rootInfo_;
  std::uint32_t mask = active;
  while (mask != 0) {
    if (info == kInner) {
      const Node& node = nodes_[child];
      std::array<Entry, 4> next;
      int nextCount = 0;
      for (int slot = 0; slot < 4 && node.info[slot] != kEmpty; ++slot) {
        const std::uint32_t rayBits = testPacketChild(node, slot, packet, mask, nullptr);
        if (rayBits != 0) next[nextCount++] = {node.child[slot], node.info[slot], rayBits};
      }
      if (nextCount > 0) {
        // The others last slot first, so that they come off the stack in slot order.
        for (int k = nextCount - 1; k > 0; --k) stack[stackSize++] = next[k];
        child = next[0].child;
        info = next[0].info;
        mask = next[0].rays;
        continue;
      }
    } else {
      const std::uint32_t leafCount = bvh::leafCount(info);
      const std::uint32_t key = bvh::leafKey(info);
      for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1) {
        const auto i = static_cast<std::size_t>(std::countr_zero(bits));
        bool open = true;
        if (key == kPrimitiveKey) {
          for (std::uint32_t k = child; k < child + leafCount && open; ++k) {
            const std::uint32_t index = leafRefs_[k];
            open = crossPrimitive(primitives_[index], transmission_[index], leafSpheres_[k],
                                  rays[i], tMin, tMax[i], results[i]);
          }
        } else {
          open = crossTriangles(meshes_[key], meshTransmission_[key], child, leafCount, rays[i],
                                tMin, tMax[i], wrays[i], wrayReady[i], results[i]);
        }
        if (!open) block(i);
      }
    }
    // Pop the next entry that one of the rays still open goes into.
    mask = 0;
    while (stackSize > 0 && mask == 0) {
      const Entry& entry = stack[--stackSize];
      mask = entry.rays & active;
      child = entry.child;
      info = entry.info;
    }
  }
}

#ifndef GLINT_AGGREGATE_KERNELS_ONLY
bool Aggregate::intersectBruteForce(const Ray& ray, double tMin, double tMax, Hit& hit) const {
  bool found = false;
  double closest = tMax;
  ShapeHit shapeHit;
  for (std::uint32_t i = 0; i < primitives_.size(); ++i) {
    if (primitives_[i].intersect(ray, tMin, closest, shapeHit)) {
      closest = shapeHit.t;
      setPrimitiveHit(shapeHit, closest, i, hit);
      found = true;
    }
  }
  if (triangleCount_ == 0) return intersectInstances(ray, tMin, closest, hit) || found;
  const WatertightRay wray(ray);
  WatertightHit candidate;
  std::uint32_t hitMesh = kNoMesh;
  std::uint32_t hitTriangleIndex = 0;
  WatertightHit best;
  Vec3 candidateNormal;
  Vec3 bestNormal;
  for (std::uint32_t m = 0; m < meshes_.size(); ++m) {
    const TriangleMesh& mesh = meshes_[m];
    for (std::uint32_t k = meshBegin_[m]; k < meshBegin_[m + 1]; ++k) {
      const std::uint32_t triangle = leafRefs_[k];
      if (hitTriangle(wray, ray.direction, verticesOf(mesh, triangle), tMin, closest, candidate,
                      candidateNormal)) {
        closest = candidate.t;
        best = candidate;
        bestNormal = candidateNormal;
        hitMesh = m;
        hitTriangleIndex = triangle;
      }
    }
  }
  if (intersectInstances(ray, tMin, closest, hit)) return true;
  if (hitMesh == kNoMesh) return found;
  finishTriangleHit(hitMesh, hitTriangleIndex, best, bestNormal, hit);
  return true;
}

Color Aggregate::transmittanceBruteForce(const Ray& ray, double tMin, double tMax) const {
  Color result(1);
  for (std::uint32_t i = 0; i < primitives_.size(); ++i) {
    const Color& kt = transmission_[i];
    if (kt == Color(1)) continue;
    if (primitives_[i].csg() != nullptr) {  // each crossing with its operand's kt
      result *= primitives_[i].csgTransmittance(ray, tMin, tMax);
      if (isBlack(result)) return Color();
      continue;
    }
    const int crossings = primitives_[i].crossings(ray, tMin, tMax);
    if (crossings == 0) continue;
    if (isBlack(kt)) return Color();
    for (int k = 0; k < crossings; ++k) result *= kt;
    if (isBlack(result)) return Color();
  }
  if (triangleCount_ == 0) return result;
  const WatertightRay wray(ray);
  for (std::uint32_t m = 0; m < meshes_.size(); ++m) {
    const Color& kt = meshTransmission_[m];
    if (kt == Color(1)) continue;
    const TriangleMesh& mesh = meshes_[m];
    for (std::uint32_t k = meshBegin_[m]; k < meshBegin_[m + 1]; ++k) {
      if (!crossesTriangle(wray, ray.direction, verticesOf(mesh, leafRefs_[k]), tMin, tMax)) {
        continue;
      }
      if (isBlack(kt)) return Color();
      result *= kt;
      if (isBlack(result)) return Color();
    }
  }
  return result;
}

Color Aggregate::transmittance(const Ray& ray, double tMin, double tMax) const {
  Color result = (this->*kernels_->transmittance)(ray, tMin, tMax);
  if (instances_ && !isBlack(result)) result *= instances_->transmittance(ray, tMin, tMax);
  return result;
}

void Aggregate::transmittancePacket(const Ray* rays, int count, double tMin, const double* tMax,
                                    Color* results) const {
  (this->*kernels_->transmittancePacket)(rays, count, tMin, tMax, results);
  if (!instances_) return;
  for (int i = 0; i < std::clamp(count, 0, kPacketSize); ++i) {
    if (!isBlack(results[i])) results[i] *= instances_->transmittance(rays[i], tMin, tMax[i]);
  }
}

bool Aggregate::intersectInstances(const Ray& ray, double tMin, double tMax, Hit& hit) const {
  return instances_ && instances_->intersect(ray, tMin, tMax, hit);
}

const TriangleMesh& Aggregate::meshOf(const Hit& hit) const {
  if (hit.instance == kNoInstance) return meshes_[hit.mesh];
  return instances_->group(instances_->instance(hit.instance).group).meshes()[hit.mesh];
}

const Primitive& Aggregate::primitiveOf(const Hit& hit) const {
  if (hit.instance == kNoInstance) return primitives_[hit.primitive];
  return instances_->group(instances_->instance(hit.instance).group).primitives()[hit.primitive];
}

Color Aggregate::vertexColor(const Hit& hit) const {
  if (hit.instance != kNoInstance) return instances_->vertexColor(hit);
  const TriangleMesh& m = meshes_[hit.mesh];
  const std::uint32_t* index = m.indices.data() + 3 * static_cast<std::size_t>(hit.triangle);
  const Point3& p0 = m.positions[index[0]];
  const Vec3 e1 = m.positions[index[1]] - p0;
  const Vec3 e2 = m.positions[index[2]] - p0;
  const Vec3 rel = hit.point - p0;
  // Barycentric coordinates of the hit point from the sub-triangle areas (signed, along n),
  // clamped against the rounding of a point on an edge.
  const Vec3 n = cross(e1, e2);
  const double area = dot(n, n);
  const double b1 = std::clamp(dot(cross(rel, e2), n) / area, 0.0, 1.0);
  const double b2 = std::clamp(dot(cross(e1, rel), n) / area, 0.0, 1.0 - b1);
  return m.colors[index[0]] * (1 - b1 - b2) + m.colors[index[1]] * b1 + m.colors[index[2]] * b2;
}
#endif  // GLINT_AGGREGATE_KERNELS_ONLY

}  // namespace glint
