// Emissive surfaces as lights for the path integrator (DESIGN.md §10: "emissive objects are lights,
// sampled by area"): next-event estimation picks a point on an emitter with density proportional
// to the emission's luminance per unit area (an emitter chosen by its power, luminance × area,
// then a uniform point on it), so a small bright lamp is found by shadow rays instead of by chance.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "glint/accel/aggregate.h"
#include "glint/accel/instances.h"
#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/triangle_mesh.h"
#include "glint/scene/material.h"
#include "glint/scene/texture.h"

namespace glint {

class EmitterSampler {
 public:
  // What sample() draws: a point on an emitter, its unit geometric normal, its emission (linear
  // radiance, both sides) and the density of drawing it, per unit area (scene units²).
  struct Sample {
    Point3 point;
    Normal3 normal;
    Color emission;
    double areaPdf = 0;
  };

  // The emitters it samples, each uniformly by area: triangles, rectangles, quadrangles, polygons
  // and boxes with or without a transform (an affine map keeps a flat face flat and a uniform
  // point on it uniform); disks and rings likewise (an affine map makes them ellipses); spheres,
  // capped cylinders and cones (their side, from radius to radius) without a transform or under
  // a similarity (rotation, uniform scale, translation: they stay spheres, cylinders and cones);
  // every triangle of an emissive mesh. Not sampled (found only by the paths that hit them):
  // planes and tubes (infinite), spheres, cylinders and cones under a non-uniform scale or a
  // shear, and emission with a texture. Null when there is nothing to sample.
  //
  // With `instances`, the emissive objects of every instance's group are sampled too, each placed
  // by the instance's transform composed with its own (the same rules for which are sampled), up
  // to kInstancedUnitBudget sampled units; `materialOf` gives the material index of an instanced
  // object (Hit with instance, primitive or mesh set: Scene::materialIndexOf), so that emission
  // textured by an instance's material is left out. The Scene that holds `instances` outlives
  // the sampler.
  static std::shared_ptr<const EmitterSampler> make(
      const std::vector<Primitive>& primitives, const std::vector<TriangleMesh>& meshes,
      const std::vector<Material>& materials, const std::vector<MaterialTextures>& textures,
      const InstanceSet* instances = nullptr,
      const std::function<std::uint32_t(const Hit&)>& materialOf = {});
  // At most this many sampled units (a triangle, a sphere, a disk, a side) for instanced objects:
  // ~45 MB of them. A field of instanced lamps past it keeps the first instances' (in the
  // InstanceSet's order) as lights.
  static constexpr std::size_t kInstancedUnitBudget = std::size_t{1} << 18;

  // A point for u in [0,1)² (u.x picks the emitter and is reused inside it).
  Sample sample(const Point2& u) const;
  // The area density with which sample() draws the point `hit` is on, whose base emission is
  // `emission`; 0 when that surface is not sampled. The same at every point of one emitter.
  double areaPdf(const Hit& hit, const Color& emission) const;
  std::size_t size() const { return units_.size(); }

 private:
  enum class Kind : std::uint8_t { Triangle, Sphere, Disk, CylinderSide, ConeSide };
  // One sampled surface in world space (scene units):
  // - Triangle: origin + e0·b1 + e1·b2 over the barycentric triangle;
  // - Sphere: centre origin, radius;
  // - Disk: origin + (e0·cos φ + e1·sin φ)·ρ for innerRadius ≤ ρ ≤ radius (e0, e1 the images of
  //   two orthonormal object-space directions in the disk's plane: an ellipse when they differ);
  // - CylinderSide: origin + (e0·cos φ + e1·sin φ)·radius + e2·v, v in [0, 1];
  // - ConeSide: origin + (e0·cos φ + e1·sin φ)·ρ(v) + e2·v, ρ(v) = radius + (apexRadius −
  //   radius)·v. For both sides e0, e1 are orthogonal of equal length and e2 is the axis times
  //   the height, all in world space.
  struct Unit {
    Kind kind = Kind::Triangle;
    Point3 origin;
    Vec3 e0, e1, e2;
    Normal3 normal;  // triangle and disk
    double radius = 0;
    double innerRadius = 0;  // disk
    double apexRadius = 0;   // cone
    Color emission;
  };
  EmitterSampler() = default;
  void add(const Unit& unit, double area);

  std::vector<Unit> units_;
  std::vector<double> cdf_;  // units_.size() + 1 running power shares, cdf_[0] = 0
  double totalPower_ = 0;    // Σ luminance × area
  std::vector<bool> sampledPrimitive_;
  std::vector<bool> sampledMesh_;
  // Instanced emitters (make's `instances`): per group, each object's slot among its emissive
  // objects (primitives first, then meshes) or kNotEmissive; per instance, the first of its
  // slots' bits in sampledInstanced_, or kNotEmissive when none of its objects is sampled.
  static constexpr std::uint32_t kNotEmissive = 0xffffffffu;
  const InstanceSet* instances_ = nullptr;
  std::vector<std::vector<std::uint32_t>> emissiveSlot_;
  std::vector<std::uint32_t> instanceBase_;
  std::vector<bool> sampledInstanced_;
};

// Luminance (Rec. 709 weights) of a linear colour.
inline double luminance(const Color& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

}  // namespace glint
