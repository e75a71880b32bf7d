// The one epsilon policy: where secondary rays (reflection, refraction, shadow) start.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "glint/core/ray.h"
#include "glint/core/ulp.h"
#include "glint/core/vec.h"

namespace glint {

// Error-bounded ray origins in the style of pbrt-v4 (Pharr, Jakob, Humphreys, "Physically Based
// Rendering", 4th ed., §6.8 "Managing Rounding Error").
//
// Every intersection routine returns, with its hit point p, a per-coordinate bound pError (scene
// units, in the space of p) such that the exact surface passes through the box p ± pError. The
// routines reproject their hit point onto the surface (spheres and tubes radially, flat shapes and
// caps along their normal, triangles by barycentric interpolation, box faces by snapping the face
// coordinate), so pError scales with the magnitudes of the hit point and of the shape itself —
// never with the distance the ray travelled or the magnitude of its origin.
//
// The spawned origin moves along the geometric unit normal n by twice the projection of that box
// onto n, 2·(|n|·pError), to the side the new direction leaves toward, then one more ulp away from
// the surface per coordinate. The first half of the offset takes the origin past every point the
// surface can occupy; the second half exceeds the error with which an intersection routine,
// re-run from the new origin, decides on which side of the surface that origin lies (each routine
// here keeps that error below the same bound: it involves the same magnitudes and fewer roundings).
// So a spawned ray can neither re-hit the surface it leaves at t ≈ 0 (acne) nor start beyond a
// neighbouring surface farther than ~1e-14 relative away (leaks through thin slivers).

// γn of Higham ("Accuracy and Stability of Numerical Algorithms", §3.1): the relative error bound
// of n chained roundings, n·u / (1 − n·u), with u = 2^−53 the unit round-off of double.
constexpr double gammaBound(int n) {
  constexpr double u = std::numeric_limits<double>::epsilon() * 0.5;
  return n * u / (1 - n * u);
}

// The side of the surface a ray leaving in direction w starts on: the side n points to when
// n·w ≥ 0. offsetRayOrigin depends on w only through this.
inline bool leavesAlongNormal(const Normal3& n, const Vec3& w) { return dot(n, w) >= 0; }

// Moves the hit point p (per-coordinate error bound pError) off its surface along the geometric
// unit normal n, to the side the direction w leaves toward (the +n side when w is tangent).
inline Point3 offsetRayOrigin(const Point3& p, const Vec3& pError, const Normal3& n,
                              const Vec3& w) {
  const double d =
      2 * (std::abs(n.x) * pError.x + std::abs(n.y) * pError.y + std::abs(n.z) * pError.z);
  const double side = leavesAlongNormal(n, w) ? 1.0 : -1.0;
  const Vec3 along = toVec(n) * side;
  Point3 o = p + along * d;
  // One ulp further away from the surface on every axis the normal has a component along: covers
  // the rounding of the addition above, and moves the origin even when pError is 0 (box faces).
  for (int axis = 0; axis < 3; ++axis) {
    if (along[axis] > 0) o[axis] = nextUp(o[axis]);
    if (along[axis] < 0) o[axis] = nextDown(o[axis]);
  }
  return o;
}

// A ray leaving the surface point p (error bound pError, geometric unit normal n) in direction w.
inline Ray spawnRay(const Point3& p, const Vec3& pError, const Normal3& n, const Vec3& w) {
  return Ray{offsetRayOrigin(p, pError, n, w), w};
}

// Legacy policy, for points that come without an error bound: an offset of 1e-9 × the largest
// coordinate magnitude (at least 1e-9 scene units). It clears the rounding error of hit points by
// orders of magnitude, but it is ~10^6 times larger than that error, so it steps over features
// thinner than 1e-9·|p| (1e-3 units at 10^6 from the origin: slivers, gaps and tiny objects leak
// light there), and it ignores the magnitude of the ray origin that produced p = ray.at(t).
// Prefer the overload with pError; this one remains for callers not yet passing bounds.
inline constexpr double kRayOffsetRelative = 1e-9;

inline Point3 offsetRayOrigin(const Point3& p, const Normal3& n, const Vec3& w) {
  const double magnitude = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  const double offset = kRayOffsetRelative * magnitude;
  const double side = dot(n, w) >= 0 ? offset : -offset;
  return p + toVec(n) * side;
}

inline Ray spawnRay(const Point3& p, const Normal3& n, const Vec3& w) {
  return Ray{offsetRayOrigin(p, n, w), w};
}

}  // namespace glint
