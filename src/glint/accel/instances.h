// Instancing (DESIGN.md §11): groups of primitives and meshes, each in its own Aggregate built once
// in the group's object space, placed any number of times by affine transforms. A two-level
// bounding volume hierarchy: a top-level 4-wide BVH (bvh4.h) over the instances' world bounds; a
// ray reaching an instance is mapped into the group's space and traced in the group's shared
// Aggregate, and its hit mapped back (point, error bound, normals by the inverse transpose).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "glint/accel/aggregate.h"
#include "glint/accel/bvh4.h"
#include "glint/core/color.h"
#include "glint/core/ray.h"
#include "glint/core/transform.h"

namespace glint {

inline constexpr std::uint32_t kNoMaterialOverride = 0xffffffffu;

// An affine map as the top three rows of its 4×4 matrix (the fourth is 0 0 0 1), row-major, acting
// on column vectors. Applied with the same arithmetic, in the same order, as Transform and the
// transformed Primitive apply theirs, so an instance hit is bit for bit a transformed primitive's.
struct AffineMatrix {
  double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
};

// One placement of a group as the scene gives it: the world-from-group map and its inverse as
// Transform computed them. The build input of an InstanceSet (200 bytes); the set keeps only the
// inverse (PlacedInstance).
struct Instance {
  AffineMatrix worldFromGroup;
  AffineMatrix groupFromWorld;  // the inverse, as Transform computed it (not re-derived)
  std::uint32_t group = 0;      // index into InstanceSet's groups
  // The material index the instance gives the group's objects written without one, or
  // kNoMaterialOverride; the Scene resolves it (the InstanceSet only carries it).
  std::uint32_t material = kNoMaterialOverride;
};

// What an InstanceSet stores per instance: 104 bytes, so a million instances hold 104 MB of
// records (the tree's nodes come on top; the groups' geometry is shared). Only the inverse is
// kept: it maps every ray entering the instance, so which surface a ray hits and at which t are
// exactly what the transformed objects give. The forward map, needed once per closest hit (the
// world hit point, tangents), is re-derived from the inverse (adjugate formula); the hit point's
// error bound includes that derivation's error (instances.cpp).
struct PlacedInstance {
  AffineMatrix groupFromWorld;
  std::uint32_t group = 0;
  std::uint32_t material = kNoMaterialOverride;
};
static_assert(sizeof(PlacedInstance) == 104);

// The instance record of a transform (identity when absent). Throws std::invalid_argument when the
// transform is not a finite, invertible affine map.
Instance makeInstance(const Transform* worldFromGroup, std::uint32_t group,
                      std::uint32_t material = kNoMaterialOverride);

class InstanceSet {
 public:
  // groups: one Aggregate per distinct group, in the group's own space, shared by every instance
  // of it (never copied). instances: in any order; the set stores them in its tree's leaf order
  // (Hit::instance and instance() index that order). Throws std::invalid_argument for a group index
  // out of range or a null group, std::length_error past 2^32 − 2 instances. Built in parallel on
  // the calling oneTBB arena; the result does not depend on the thread count.
  InstanceSet(std::vector<std::shared_ptr<const Aggregate>> groups,
              std::vector<Instance> instances);

  // Closest hit among the instances with tMin < t < tMax, in world space: hit.instance names the
  // instance, hit.primitive / mesh / triangle what was hit inside its group (indices into
  // group(instance(i).group)'s primitives() and meshes()). Rays as for Aggregate::intersect.
  bool intersect(const Ray& ray, double tMin, double tMax, Hit& hit) const;
  // Product of kt over every crossing of an instance's surfaces in (tMin, tMax).
  Color transmittance(const Ray& ray, double tMin, double tMax) const;

  const PlacedInstance& instance(std::uint32_t i) const { return instances_[i]; }
  std::size_t instanceCount() const { return instances_.size(); }
  const Aggregate& group(std::uint32_t g) const { return *groups_[g]; }
  std::size_t groupCount() const { return groups_.size(); }
  // Instance i's world-from-group transform: the forward matrix re-derived from the stored inverse
  // (as for its hit points), with that inverse.
  Transform placement(std::uint32_t i) const;
  // The group-space point of a world-space point on instance i.
  Point3 groupPoint(std::uint32_t i, const Point3& world) const;
  // A group-space vector (a tangent) in world space.
  Vec3 worldVector(std::uint32_t i, const Vec3& v) const;
  // A group-space normal in world space (inverse transpose, not normalised).
  Normal3 worldNormal(std::uint32_t i, const Normal3& n) const;
  // The vertex colour at a hit on an instanced mesh with colours (Aggregate::vertexColor).
  Color vertexColor(const Hit& hit) const;
  Bounds3 bounds() const { return bounds_; }
  // Heap bytes: the instance records, the tree, and each group's Aggregate once.
  std::size_t memoryBytes() const;

 private:
  bool intersectInstance(std::uint32_t i, const Ray& ray, double tMin, double tMax, Hit& local,
                         Ray& groupRay) const;
  void finishHit(std::uint32_t i, const Ray& groupRay, Hit& hit) const;

  std::vector<std::shared_ptr<const Aggregate>> groups_;
  std::vector<PlacedInstance> instances_;  // in leaf order: a leaf is a range of them
  std::vector<std::uint32_t> unbounded_;   // instances of groups with planes or tubes: every ray
  bvh::Nodes nodes_;
  std::uint32_t rootChild_ = 0;
  std::uint32_t rootInfo_ = bvh::kEmpty;
  Bounds3 bounds_;  // of the bounded instances
};

}  // namespace glint
