// The ray–sphere tests, shared by Sphere (shapes.cpp) and the Aggregate's kernels (aggregate.cpp,
// compiled once per instruction set), which test the untransformed spheres of a BVH leaf inline
// rather than through Primitive (an out-of-line call and a variant dispatch per candidate). One
// definition, so either path gives the same bits. The kernels inline these ([[gnu::flatten]]); see
// src/CMakeLists.txt on why no out-of-line copy may come from them.
#pragma once

#include <cmath>
#include <utility>

#include "glint/core/ray.h"
#include "glint/core/spawn.h"
#include "glint/geometry/shape.h"

namespace glint::quadric {

inline bool inOpenRange(double t, double tMin, double tMax) { return t > tMin && t < tMax; }

// The nearer of the roots t0 ≤ t1 that lies in (tMin, tMax), into t; false when neither does.
inline bool nearerRootInRange(double t0, double t1, double tMin, double tMax, double& t) {
  if (inOpenRange(t0, tMin, tMax)) {
    t = t0;
    return true;
  }
  if (inOpenRange(t1, tMin, tMax)) {
    t = t1;
    return true;
  }
  return false;
}

// Whether the sphere (or the tube's cross-section) relative to the ray origin, f = origin − centre,
// lies wholly behind the ray: the origin is outside or on it (|f|² − r² ≥ 0) and the ray does not
// move toward the centre (−f·d ≤ 0, −0 included). quadricRoots returns then, in floating point as
// well, roots t0 = c/q and t1 = q/a with q = b − √Δ < 0, c ≥ 0 and a > 0, both ≤ 0 (or NaN), so no
// root lies in (tMin, tMax) when tMin ≥ 0. Shadow and reflection rays leaving a sphere meet this
// case for the sphere they leave; deciding it here skips the root computation (a square root and
// three divisions).
inline bool wholeQuadricBehind(double b, double c, double tMin) {
  return tMin >= 0 && std::signbit(b) && c >= 0;
}

// Roots t0 < t1 of |f + t·d|² = r² (f = origin relative to the centre, d the direction; both
// already projected onto the cross-section for tubes), by the method of Ray Tracing Gems ch. 7
// ("Precision Improvements for Ray/Sphere Intersection", Haines et al. 2019): the discriminant from
// the squared distance of the line to the centre, r² − |f − (f·d̂)d̂|², which does not cancel
// catastrophically for distant rays, and the root pair from q = b + sign(b)·√Δ
// (t0 = c/q, t1 = q/a), which avoids subtracting nearly equal numbers. A tangent line (Δ ≤ 0) has
// no roots.
[[gnu::always_inline]] inline bool quadricRoots(const Vec3& f, const Vec3& d, double r, double& t0,
                                                double& t1) {
  const double a = dot(d, d);
  const double b = -dot(f, d);
  const Vec3 closest = f + d * (b / a);  // centre-to-line offset at the closest approach
  const double discriminant = a * (r * r - dot(closest, closest));
  if (!(discriminant > 0)) return false;
  const double c = dot(f, f) - r * r;
  const double q = b + std::copysign(std::sqrt(discriminant), b);
  t0 = c / q;
  t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// Sphere::intersect: the nearer root in (tMin, tMax), its outward normal, and the hit point moved
// radially onto the sphere with its error bound. Sets t, normal, point and pointError only.
[[gnu::always_inline]] inline bool sphereIntersect(const Point3& center, double radius,
                                                   const Ray& ray, double tMin, double tMax,
                                                   ShapeHit& hit) {
  const Vec3 f = ray.origin - center;
  if (wholeQuadricBehind(-dot(f, ray.direction), dot(f, f) - radius * radius, tMin)) return false;
  double t0;
  double t1;
  if (!quadricRoots(f, ray.direction, radius, t0, t1)) return false;
  double t;
  if (!nearerRootInRange(t0, t1, tMin, tMax, t)) return false;
  hit.t = t;
  const Vec3 rel = f + ray.direction * t;
  hit.normal = Normal3(normalize(rel));
  // Radial reprojection onto the sphere (error γ5·|rel|, pbrt-v4 §6.8.5); the re-intersection
  // test |o − c|² − r² of a spawned origin o is exact to a few ulps of r² and r·|o − c|.
  const Vec3 onSphere = rel * (radius / length(rel));
  hit.point = center + onSphere;
  hit.pointError = abs(onSphere) * gammaBound(8) + abs(toVec(hit.point)) * gammaBound(2);
  return true;
}

// Sphere::crossings: how many of the two roots lie in (tMin, tMax).
[[gnu::always_inline]] inline int sphereCrossings(const Point3& center, double radius,
                                                  const Ray& ray, double tMin, double tMax) {
  const Vec3 f = ray.origin - center;
  if (wholeQuadricBehind(-dot(f, ray.direction), dot(f, f) - radius * radius, tMin)) return 0;
  double t0;
  double t1;
  if (!quadricRoots(f, ray.direction, radius, t0, t1)) return 0;
  return int{inOpenRange(t0, tMin, tMax)} + int{inOpenRange(t1, tMin, tMax)};
}

}  // namespace glint::quadric
