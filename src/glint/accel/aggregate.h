// The frozen collection of primitives and mesh triangles with its two queries: closest hit, and
// shadow transmittance. Bounded primitives and all mesh triangles go into one bounding volume
// hierarchy (bvh4.h: binned SAH build of 4-wide nodes, optionally collapsed into 8-wide ones; flat
// node array, near-child-first traversal with SIMD slab tests); unbounded primitives (planes,
// tubes) are tested on every ray.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "glint/accel/bvh4.h"
#include "glint/core/color.h"
#include "glint/core/isa.h"
#include "glint/core/ray.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/triangle_mesh.h"
#include "glint/geometry/watertight_triangle.h"

namespace glint {

inline constexpr std::uint32_t kNoMesh = 0xffffffffu;
inline constexpr std::uint32_t kNoInstance = 0xffffffffu;

class InstanceSet;  // instances.h: groups placed by transforms (a two-level BVH)

namespace aggregate_detail {
// An untransformed sphere of a BVH leaf, tested inline (geometry/sphere_intersection.h); radius 0
// for any other primitive.
struct LeafSphere {
  Point3 center;
  double radius = 0;
};
}  // namespace aggregate_detail

struct Hit {
  double t = 0;           // ray parameter
  Normal3 normal;         // unit geometric world-space normal, as the shape defines it
  Normal3 shadingNormal;  // unit; interpolated vertex normal on smooth meshes, else = normal
  // The hit point reprojected onto the surface and its per-coordinate error bound (world space,
  // scene units): the exact surface passes through point ± pointError. Secondary rays start from
  // spawnRay(point, pointError, normal, w) (core/spawn.h), not from ray.at(t).
  Point3 point;
  Vec3 pointError;
  std::uint32_t primitive = 0;   // index into the primitives, when mesh == kNoMesh
  std::uint32_t mesh = kNoMesh;  // index into the meshes, or kNoMesh for an analytic primitive
  std::uint32_t triangle = 0;    // triangle index within meshes()[mesh] (see meshes())
  std::uint32_t part = 0;        // on a csg primitive: the operand hit (ShapeHit::part)
  // The instance hit (instances.h), or kNoInstance. On an instance, primitive, mesh and triangle
  // index its group's Aggregate (InstanceSet::group), not this one; t, the normals, point and
  // pointError are in world space all the same.
  std::uint32_t instance = kNoInstance;
};

// How the Aggregate organises its primitives: a BVH, or none (every ray tests every primitive —
// only for measuring what the BVH buys). Bvh chooses the node width for the ISA the Aggregate
// starts with (bvhNodeWidth); Bvh4 and Bvh8 force one (tests and benchmarks). Every width finds
// the same hits bit for bit: the 8-wide tree is the 4-wide one collapsed (bvh::collapseToWide),
// with the same leaves, boxes and triangle numbering.
enum class Acceleration { Bvh, BruteForce, Bvh4, Bvh8 };

// The node width Acceleration::Bvh builds for the kernels of `isa`: GLINT_BVH_WIDTH (4 or 8) when
// set and not empty, else 4 for every ISA — 8-wide nodes measured no faster with the AVX2 and
// AVX-512 kernels and take ~9 more bytes per triangle (docs/benchmarks.md, "Instruction sets").
// Throws IsaError for another GLINT_BVH_WIDTH.
int bvhNodeWidth(Isa isa);

// The acceleration to build for queries that will run with `isa` (when known): Bvh as that ISA's
// node width (Bvh4 or Bvh8), any other choice as it is.
inline Acceleration accelerationFor(Acceleration acceleration, std::optional<Isa> isa) {
  if (acceleration != Acceleration::Bvh || !isa) return acceleration;
  return bvhNodeWidth(*isa) == 8 ? Acceleration::Bvh8 : Acceleration::Bvh4;
}

class Aggregate {
 public:
  // primitiveTransmission[i] is the factor a shadow ray keeps each time it crosses primitive i
  // (the material's kt); same size as primitives. For a csg primitive it only says whether the
  // csg may dim a shadow ray (1: every operand is fully transparent); the crossings of its surface
  // count with their operands' own transmission (CsgOperand::transmission).
  // meshTransmission[m] likewise for every triangle of meshes[m]; same size as meshes.
  // Throws std::invalid_argument for mismatched sizes, a mesh whose index count is not a multiple
  // of 3, an index past the mesh's positions, or normals that are neither absent nor one per
  // position; std::length_error past 2^32 − 1 references or kMaxMeshes meshes.
  // Degenerate triangles (zero area or non-finite vertices) are left out: they never hit.
  // Large inputs are built in parallel on the calling oneTBB arena; the result does not depend on
  // the thread count. `instances` (may be null) are queried with the rest: their hits carry
  // Hit::instance.
  Aggregate(std::vector<Primitive> primitives, std::vector<Color> primitiveTransmission,
            std::vector<TriangleMesh> meshes = {}, std::vector<Color> meshTransmission = {},
            Acceleration acceleration = Acceleration::Bvh,
            std::shared_ptr<const InstanceSet> instances = nullptr);

  // Closest hit with tMin < t < tMax. The slab tests run in single precision on boxes rounded
  // outward; rays must have finite origins within ±1e38 and no direction component above 1e30 in
  // magnitude (every ray a scene produces).
  bool intersect(const Ray& ray, double tMin, double tMax, Hit& hit) const {
    return (this->*kernels_->intersect)(ray, tMin, tMax, hit);
  }
  // The closest hits of up to kPacketSize rays traced together (a packet: coherent rays such as
  // the camera rays of neighbouring pixels): found[i] and hits[i] are exactly what
  // intersect(rays[i], tMin, tMax[i], hits[i]) returns and sets, bit for bit. The tree is walked
  // once for the packet, each node's boxes tested against all its rays at once (SIMD across rays);
  // rays of a direction octant other than the first ray's are traced alone.
  static constexpr int kPacketSize = 16;
  void intersectPacket(const Ray* rays, int count, double tMin, const double* tMax, Hit* hits,
                       bool* found) const {
    (this->*kernels_->intersectPacket)(rays, count, tMin, tMax, hits, found);
  }
  // Product of kt over every surface crossing in (tMin, tMax), this aggregate's own (the ISA's
  // kernel) times its instances'; stops early once it is black.
  Color transmittance(const Ray& ray, double tMin, double tMax) const;
  // The transmittances of up to kPacketSize rays traced together (a packet: coherent rays such as
  // the shadow rays of neighbouring camera hits toward one light): results[i] is exactly
  // transmittance(rays[i], tMin, tMax[i]), bit for bit. As intersectPacket, the tree is walked
  // once for the packet; rays of a direction octant other than the first ray's go alone.
  void transmittancePacket(const Ray* rays, int count, double tMin, const double* tMax,
                           Color* results) const;

  // The instruction set the two queries run with (core/isa.h); defaultIsa() when built, which
  // throws IsaError when GLINT_ISA is bad. setIsa throws IsaError when this processor cannot run
  // `isa`. Every ISA finds the same hits, bit for bit: only the speed differs.
  void setIsa(Isa isa);
  Isa isa() const { return kernels_->isa; }

  // The instances queried with this aggregate's own primitives and meshes, or null.
  const InstanceSet* instances() const { return instances_.get(); }
  // The mesh a hit with hit.mesh != kNoMesh is on, and the primitive of one with kNoMesh, in this
  // aggregate or in the hit instance's group.
  const TriangleMesh& meshOf(const Hit& hit) const;
  const Primitive& primitiveOf(const Hit& hit) const;

  // The vertex colour at a hit on a mesh that has colors (TriangleMesh::colors), interpolated
  // barycentrically at the hit point.
  Color vertexColor(const Hit& hit) const;

  const std::vector<Primitive>& primitives() const { return primitives_; }
  // The meshes as stored. With Acceleration::Bvh each mesh's triangles and vertices are renumbered
  // into the tree's leaf order and its degenerate triangles and unused vertices are left out (same
  // values, same winding, same material); Hit::triangle indexes these, not the input order.
  const std::vector<TriangleMesh>& meshes() const { return meshes_; }
  // Of the bounded primitives and the mesh triangles (and the bounded instances).
  Bounds3 bounds() const { return bounds_; }
  Acceleration acceleration() const { return acceleration_; }
  // Children per BVH node: 4 or 8 (0 for BruteForce). Every ISA's kernels traverse either width.
  int nodeWidth() const;
  // Mesh triangles in the structure (the degenerate ones left out).
  std::size_t triangleCount() const { return triangleCount_; }
  // Heap bytes held for meshes (positions, normals, indices), the tree and its leaf references;
  // primitives count with sizeof(Primitive) each. For "bytes per triangle" figures.
  std::size_t memoryBytes() const;

 private:
  // The two queries, compiled once per ISA: aggregate.cpp as itself (Baseline), and again inside
  // aggregate_avx2.cpp and aggregate_avx512.cpp with that ISA's flags (src/CMakeLists.txt).
  bool intersectBaseline(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  bool intersectAvx2(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  bool intersectAvx512(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  Color transmittanceBaseline(const Ray& ray, double tMin, double tMax) const;
  Color transmittanceAvx2(const Ray& ray, double tMin, double tMax) const;
  Color transmittanceAvx512(const Ray& ray, double tMin, double tMax) const;
  void intersectPacketBaseline(const Ray* rays, int count, double tMin, const double* tMax,
                               Hit* hits, bool* found) const;
  void intersectPacketAvx2(const Ray* rays, int count, double tMin, const double* tMax, Hit* hits,
                           bool* found) const;
  void intersectPacketAvx512(const Ray* rays, int count, double tMin, const double* tMax, Hit* hits,
                             bool* found) const;
  void transmittancePacketBaseline(const Ray* rays, int count, double tMin, const double* tMax,
                                   Color* results) const;
  void transmittancePacketAvx2(const Ray* rays, int count, double tMin, const double* tMax,
                               Color* results) const;
  void transmittancePacketAvx512(const Ray* rays, int count, double tMin, const double* tMax,
                                 Color* results) const;
  struct Kernels {
    bool (Aggregate::*intersect)(const Ray&, double, double, Hit&) const;
    Color (Aggregate::*transmittance)(const Ray&, double, double) const;
    void (Aggregate::*intersectPacket)(const Ray*, int, double, const double*, Hit*, bool*) const;
    void (Aggregate::*transmittancePacket)(const Ray*, int, double, const double*, Color*) const;
    Isa isa;
  };
  static const Kernels& kernelsFor(Isa isa);  // aggregate_isa.cpp

  bool intersectBruteForce(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  Color transmittanceBruteForce(const Ray& ray, double tMin, double tMax) const;
  bool intersectInstances(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  // normal: the triangle's unnormalised geometric normal (p1 − p0) × (p2 − p0).
  void finishTriangleHit(std::uint32_t mesh, std::uint32_t triangle, const WatertightHit& candidate,
                         const Vec3& normal, Hit& hit) const;
  // Renumbers the leaves' references and each mesh's triangles and vertices into the leaf order
  // of items (the build's references).
  void storeInLeafOrder(const bvh::BuildItems& items);
  friend struct AggregateInspector;  // aggregate_test.cpp checks the node layout invariants

  std::vector<Primitive> primitives_;
  std::vector<Color> transmission_;  // per primitive
  std::vector<TriangleMesh> meshes_;
  std::vector<Color> meshTransmission_;
  std::vector<std::uint32_t> unbounded_;  // primitives tested on every ray (Bvh only)
  // Bvh: the tree, either 4-wide (nodes_) or 8-wide (wideNodes_; nodes_ then empty). A primitive
  // leaf points into leafRefs_ (primitive indices in leaf order); a triangle leaf holds a range of
  // its mesh's triangles, which the build renumbers into leaf order (BruteForce: leafRefs_ holds
  // the triangles of every mesh, see meshBegin_).
  bvh::Nodes nodes_;
  bvh::Nodes8 wideNodes_;
  std::vector<std::uint32_t> leafRefs_;
  // Bvh: per primitive slot of leafRefs_, its sphere record (aggregate_detail::LeafSphere).
  std::vector<aggregate_detail::LeafSphere> leafSpheres_;
  int nodeWidth_ = 0;
  std::uint32_t rootChild_ = 0;
  std::uint32_t rootInfo_ = bvh::kEmpty;
  // BruteForce: the non-degenerate triangles of mesh m are leafRefs_[meshBegin_[m] ..
  // meshBegin_[m + 1]).
  std::vector<std::uint32_t> meshBegin_;
  std::size_t triangleCount_ = 0;
  Bounds3 bounds_;
  Acceleration acceleration_ = Acceleration::Bvh;
  std::shared_ptr<const InstanceSet> instances_;
  const Kernels* kernels_ = &kernelsFor(defaultIsa());
};

}  // namespace glint
