// The one epsilon policy: where secondary rays (reflection, refraction, shadow) start.
#pragma once

#include <algorithm>
#include <cmath>

#include "glint/core/ray.h"
#include "glint/core/vec.h"

namespace glint {

// Relative size of the offset that moves a secondary ray's origin off the surface it leaves.
// Hit points are computed in double precision (unit round-off 1.1e-16); the intersection routines
// here lose at most a few thousand ulps of the point's magnitude (catastrophic cancellation in the
// quadratic of near-tangent hits included), so an offset of 1e-9 × the largest coordinate magnitude
// (and at least 1e-9 scene units near the origin) clears that error by three orders of magnitude
// while staying far below any feature size a scene describes.
inline constexpr double kRayOffsetRelative = 1e-9;

// Moves p off its surface along the geometric unit normal n, to the side the new direction w leaves
// toward, so that the ray (result, w) cannot re-hit the surface at p through rounding.
inline Point3 offsetRayOrigin(const Point3& p, const Normal3& n, const Vec3& w) {
  const double magnitude = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  const double offset = kRayOffsetRelative * magnitude;
  const double side = dot(n, w) >= 0 ? offset : -offset;
  return p + toVec(n) * side;
}

// A ray leaving the surface point p (geometric unit normal n) in direction w.
inline Ray spawnRay(const Point3& p, const Normal3& n, const Vec3& w) {
  return Ray{offsetRayOrigin(p, n, w), w};
}

}  // namespace glint
