// The frozen collection of primitives with its two queries: closest hit, and shadow transmittance.
// Bounded primitives go into a bounding volume hierarchy (binned SAH build, flattened nodes,
// near-child-first traversal); unbounded ones (planes, tubes) are tested on every ray.
#pragma once

#include <cstdint>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/ray.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/triangle_mesh.h"

namespace glint {

inline constexpr std::uint32_t kNoMesh = 0xffffffffu;

struct Hit {
  double t = 0;                 // ray parameter
  Normal3 normal;               // unit geometric world-space normal, as the shape defines it
  Normal3 shadingNormal;        // unit; interpolated vertex normal on smooth meshes, else = normal
  std::uint32_t primitive = 0;  // index into the primitives, when mesh == kNoMesh
  std::uint32_t mesh = kNoMesh; // index into the meshes, or kNoMesh for an analytic primitive
  std::uint32_t triangle = 0;   // triangle index within the mesh
};

// How the Aggregate organises its primitives: a BVH, or none (every ray tests every primitive —
// only for measuring what the BVH buys).
enum class Acceleration { Bvh, BruteForce };

class Aggregate {
 public:
  // primitiveTransmission[i] is the factor a shadow ray keeps each time it crosses primitive i
  // (the material's kt); same size as primitives.
  // meshTransmission[m] likewise for every triangle of meshes[m].
  Aggregate(std::vector<Primitive> primitives, std::vector<Color> primitiveTransmission,
            std::vector<TriangleMesh> meshes = {}, std::vector<Color> meshTransmission = {},
            Acceleration acceleration = Acceleration::Bvh);

  // Closest hit with tMin < t < tMax.
  bool intersect(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  // Product of kt over every surface crossing in (tMin, tMax); stops early once it is black.
  Color transmittance(const Ray& ray, double tMin, double tMax) const;

  const std::vector<Primitive>& primitives() const { return primitives_; }
  const std::vector<TriangleMesh>& meshes() const { return meshes_; }
  Bounds3 bounds() const { return bounds_; }  // of the bounded primitives

 private:
  struct Node {
    Bounds3 bounds;
    std::uint32_t offset = 0;  // leaf: first index into order_; inner: index of the second child
    std::uint16_t count = 0;   // leaf: number of primitives; 0 for inner nodes
    std::uint8_t axis = 0;     // inner: split axis (the first child is on the low side)
  };
  struct BuildItem;  // one bounded primitive during the build (aggregate.cpp)
  // Appends the subtree over items[begin, end) to nodes_ depth-first (binned SAH, median fallback).
  void build(std::vector<BuildItem>& items, std::uint32_t begin, std::uint32_t end, int depth);
  friend struct AggregateInspector;  // aggregate_test.cpp checks the node layout invariants

  std::vector<Primitive> primitives_;
  std::vector<TriangleMesh> meshes_;
  std::vector<Color> transmission_;
  std::vector<std::uint32_t> order_;      // bounded primitive indices in leaf order
  std::vector<std::uint32_t> unbounded_;  // primitives tested on every ray
  std::vector<Node> nodes_;               // depth-first; the first child follows its parent
  Bounds3 bounds_;
};

}  // namespace glint
