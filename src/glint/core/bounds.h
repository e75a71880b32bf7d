// Axis-aligned bounding boxes in world space, and the ray–slab test used by acceleration.
#pragma once

#include <limits>
#include <utility>

#include "glint/core/ray.h"
#include "glint/core/vec.h"

namespace glint {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// An axis-aligned box [lo, hi]. Default-constructed it is empty (lo = +inf, hi = -inf), so uniting
// with anything gives that thing. Unbounded shapes (planes, tubes) report infinite extents.
// How far from the origin a scene may reach, in every space (world, an object's own): the
// intersection tests multiply up to three coordinates (the watertight triangle test's scaled
// distance), and a point light's attenuation squares a distance, so farther coordinates would
// overflow to infinity and the object or light silently vanish. 1e100 is ~10^74 times the
// observable universe in metres. Points of a scene file past it are errors at the value
// (ValueReader::point3); objects, which transforms and sizes may carry past it, at the object.
inline constexpr double kMaxCoordinate = 1e100;

struct Bounds3 {
  Point3 lo{kInfinity, kInfinity, kInfinity};
  Point3 hi{-kInfinity, -kInfinity, -kInfinity};

  constexpr Bounds3() = default;
  constexpr Bounds3(const Point3& a, const Point3& b) : lo(min(a, b)), hi(max(a, b)) {}

  static constexpr Bounds3 unbounded() {
    Bounds3 b;
    b.lo = {-kInfinity, -kInfinity, -kInfinity};
    b.hi = {kInfinity, kInfinity, kInfinity};
    return b;
  }

  constexpr bool isEmpty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  bool isBounded() const { return !isEmpty() && isFinite(lo) && isFinite(hi); }
  constexpr Vec3 diagonal() const { return hi - lo; }
  constexpr Point3 centroid() const {
    return {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)};
  }
  constexpr double surfaceArea() const {
    if (isEmpty()) return 0;
    const Vec3 d = diagonal();
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
  constexpr int longestAxis() const {
    const Vec3 d = diagonal();
    return (d.x >= d.y && d.x >= d.z) ? 0 : (d.y >= d.z ? 1 : 2);
  }
  constexpr bool contains(const Point3& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  friend constexpr bool operator==(const Bounds3&, const Bounds3&) = default;
};

constexpr Bounds3 unite(const Bounds3& a, const Bounds3& b) {
  Bounds3 r;
  r.lo = min(a.lo, b.lo);
  r.hi = max(a.hi, b.hi);
  return r;
}
constexpr Bounds3 unite(const Bounds3& a, const Point3& p) {
  Bounds3 r;
  r.lo = min(a.lo, p);
  r.hi = max(a.hi, p);
  return r;
}

// Slab test (Kay–Kajiya) against [tMin, tMax]. invDirection = 1/direction per axis (±inf for zero
// components). The NaN of 0·inf (origin on a slab plane, direction parallel) is treated as inside:
// std::min/max below return the non-NaN operand, so the test stays conservative. On a hit the
// clipped interval is returned in tEnter/tExit.
inline bool intersectSlabs(const Bounds3& b, const Ray& ray, const Vec3& invDirection, double tMin,
                           double tMax, double& tEnter, double& tExit) {
  for (int axis = 0; axis < 3; ++axis) {
    double t0 = (b.lo[axis] - ray.origin[axis]) * invDirection[axis];
    double t1 = (b.hi[axis] - ray.origin[axis]) * invDirection[axis];
    if (t0 > t1) std::swap(t0, t1);
    // Pad the far distance by 2γ(3) (pbrt's bound on the rounding of the two operations above) so
    // a ray grazing the box is not lost to rounding.
    t1 *= 1 + 2 * 3 * std::numeric_limits<double>::epsilon();
    tMin = t0 > tMin ? t0 : tMin;
    tMax = t1 < tMax ? t1 : tMax;
    if (tMin > tMax) return false;
  }
  tEnter = tMin;
  tExit = tMax;
  return true;
}

}  // namespace glint
