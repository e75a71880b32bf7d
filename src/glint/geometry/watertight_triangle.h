// The one ray–triangle kernel: the watertight test of Woop, Benthin and Wald (JCGT 2013), shared by
// the analytic Triangle/Quadrangle shapes and the mesh triangles of the acceleration structure.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#include "glint/core/ray.h"
#include "glint/core/spawn.h"
#include "glint/core/vec.h"

namespace glint {

// Rounding bound for "the ray direction lies in the plane of a flat shape". n·d is a three-term dot
// product (error ≤ γ3·Σ|n_i d_i|) of a normal that is itself a few ulps off; 8ε covers both. Below
// it the sign of n·d is noise, and a ray lying in the plane would otherwise get a hit at an
// arbitrary t. Only rays within ~1e-15 rad of the plane are affected, whose genuine hits would lie
// ~1e15 plane distances away. The test is homogeneous in n, so n need not be unit.
inline constexpr double kParallelBound = 8 * std::numeric_limits<double>::epsilon();

inline bool isParallelToPlane(const Vec3& n, const Vec3& d, double nDotD) {
  return std::abs(nDotD) <=
         kParallelBound * (std::abs(n.x * d.x) + std::abs(n.y * d.y) + std::abs(n.z * d.z));
}
inline bool isParallelToPlane(const Vec3& n, const Vec3& d) {
  return isParallelToPlane(n, d, dot(n, d));
}

// Degenerate when twice the area |e1×e2| ≤ 1e-12 · (longest edge)² (or a vertex is not finite): the
// triangle is then thinner than 1e-12 of its longest edge. Triangle::make rejects such triangles;
// the aggregate leaves such mesh triangles out, so they never hit.
inline constexpr double kCollinearTolerance = 1e-12;

inline bool isDegenerateTriangle(const Point3& p0, const Point3& p1, const Point3& p2) {
  if (!isFinite(p0) || !isFinite(p1) || !isFinite(p2)) return true;
  const double twiceArea = length(cross(p1 - p0, p2 - p0));
  const double longest =
      std::max({distanceSquared(p0, p1), distanceSquared(p1, p2), distanceSquared(p2, p0)});
  return !(twiceArea > kCollinearTolerance * longest);
}

namespace watertight_detail {

// The 2D edge function a·b − c·d. Watertightness needs edge(p, q) = −edge(q, p) in sign, exactly.
// Plain double arithmetic gives that: rounding is symmetric, and glint is compiled with
// -ffp-contract=off (src/CMakeLists.txt), so neither product is fused into an FMA on a target that
// has one — which would break the symmetry and make the result depend on the ISA.
inline double edgeFunction(double a, double b, double c, double d) { return a * b - c * d; }

// Coordinate `axis` (0 = x, 1 = y, 2 = z) of a Point3 or Vec3 read from its object representation:
// one load with a computed offset, where operator[] would branch.
template <typename Triple>
requires std::is_same_v<Triple, Point3> || std::is_same_v<Triple, Vec3>
inline double coordinate(const Triple& p, int axis) {
  static_assert(std::is_standard_layout_v<Triple> && sizeof(Triple) == 3 * sizeof(double));
  double value;
  std::memcpy(&value, reinterpret_cast<const unsigned char*>(&p) + axis * sizeof(double),
              sizeof value);
  return value;
}

}  // namespace watertight_detail

// What the per-triangle test shares for one ray: the axis permutation that makes the dominant
// direction component z (x and y swapped when it is negative, to keep the winding) and the shear
// that turns the ray into +z.
struct WatertightRay {
  Point3 origin;
  int kx = 0, ky = 1, kz = 2;
  double sx = 0, sy = 0, sz = 1;

  WatertightRay() = default;  // for callers that set it up lazily
  // Set up without branches (with random directions a branch on the axis order mispredicts
  // often); the same values as the textbook form.
  explicit WatertightRay(const Ray& ray) : origin(ray.origin) {
    using watertight_detail::coordinate;
    const Vec3& d = ray.direction;
    const double absX = std::abs(d.x);
    const double absY = std::abs(d.y);
    const double absZ = std::abs(d.z);
    const int zIfX = absX > absZ ? 0 : 2;
    const int zIfY = absY > absZ ? 1 : 2;
    kz = absX > absY ? zIfX : zIfY;
    const double dz = coordinate(d, kz);
    const int next = kz == 2 ? 0 : kz + 1;
    const int afterNext = next == 2 ? 0 : next + 1;
    const bool flip = dz < 0;  // swap x and y to keep the winding
    kx = flip ? afterNext : next;
    ky = flip ? next : afterNext;
    sx = coordinate(d, kx) / dz;
    sy = coordinate(d, ky) / dz;
    sz = 1.0 / dz;
  }
};

// A candidate hit of the watertight test: t and the unnormalised barycentric weights u, v, w of
// p0, p1, p2 (the barycentric coordinates are u/det, v/det, w/det; det = u + v + w).
struct WatertightHit {
  double t = 0;
  double u = 0, v = 0, w = 0;
  double det = 0;
};

// Watertight ray–triangle intersection (Woop, Benthin and Wald, JCGT 2013), in double. The vertices
// are translated to the ray origin, permuted and sheared so the ray is +z. The three 2D edge
// functions then depend only on the two vertices of their edge, so a shared edge gets exactly the
// opposite (or same) value in both triangles and a ray through it hits at least one of them. Edge
// functions that round to exactly zero are recomputed in long double, as the paper does in double
// for its single-precision test; a hit on an edge or vertex counts. Returns the hit with
// tMin < t < tMax. The caller rejects rays parallel to the plane (isParallelToPlane): that test
// does not change which rays hit, only where it is made, so it is left until a candidate is found.
inline bool intersectWatertight(const WatertightRay& r, const Point3& p0, const Point3& p1,
                                const Point3& p2, double tMin, double tMax, WatertightHit& hit) {
  using watertight_detail::coordinate;
  using watertight_detail::edgeFunction;
  const double az = coordinate(p0, r.kz) - coordinate(r.origin, r.kz);
  const double bz = coordinate(p1, r.kz) - coordinate(r.origin, r.kz);
  const double cz = coordinate(p2, r.kz) - coordinate(r.origin, r.kz);
  const double ax = (coordinate(p0, r.kx) - coordinate(r.origin, r.kx)) - r.sx * az;
  const double ay = (coordinate(p0, r.ky) - coordinate(r.origin, r.ky)) - r.sy * az;
  const double bx = (coordinate(p1, r.kx) - coordinate(r.origin, r.kx)) - r.sx * bz;
  const double by = (coordinate(p1, r.ky) - coordinate(r.origin, r.ky)) - r.sy * bz;
  const double cx = (coordinate(p2, r.kx) - coordinate(r.origin, r.kx)) - r.sx * cz;
  const double cy = (coordinate(p2, r.ky) - coordinate(r.origin, r.ky)) - r.sy * cz;

  double u = edgeFunction(cx, by, cy, bx);
  double v = edgeFunction(ax, cy, ay, cx);
  double w = edgeFunction(bx, ay, by, ax);
  if (u == 0 || v == 0 || w == 0) {
    using Wide = long double;
    u = static_cast<double>(Wide{cx} * Wide{by} - Wide{cy} * Wide{bx});
    v = static_cast<double>(Wide{ax} * Wide{cy} - Wide{ay} * Wide{cx});
    w = static_cast<double>(Wide{bx} * Wide{ay} - Wide{by} * Wide{ax});
  }
  if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
  const double det = u + v + w;
  if (det == 0) return false;

  const double scaledT = u * (r.sz * az) + v * (r.sz * bz) + w * (r.sz * cz);
  const double t = scaledT / det;
  if (!(t > tMin && t < tMax)) return false;
  hit.t = t;
  hit.u = u;
  hit.v = v;
  hit.w = w;
  hit.det = det;
  return true;
}

// The point of a watertight hit on the triangle p0 p1 p2, by barycentric interpolation
// (u·p0 + v·p1 + w·p2) / det, and its per-coordinate error bound (pbrt-v4 §6.8.5): γ7·Σ|b_i·p_i|
// for the interpolation (barycentrics that do not sum exactly to 1 scale the point about the
// origin, which the same bound covers), plus γ16 × the triangle's extent around the point: a ray
// spawned from it decides its side of the plane from vertex coordinates relative to its origin
// (sheared as in intersectWatertight), with a rounding error of a few ulps of that extent.
inline void watertightHitPoint(const Point3& p0, const Point3& p1, const Point3& p2,
                               const WatertightHit& hit, Point3& point, Vec3& pointError) {
  const double inverseDet = 1 / hit.det;
  const double b0 = hit.u * inverseDet;
  const double b1 = hit.v * inverseDet;
  const double b2 = hit.w * inverseDet;
  const Vec3 w0 = toVec(p0) * b0;
  const Vec3 w1 = toVec(p1) * b1;
  const Vec3 w2 = toVec(p2) * b2;
  point = toPoint(w0 + w1 + w2);
  const double extent = std::max({maxComponent(abs(p0 - point)), maxComponent(abs(p1 - point)),
                                  maxComponent(abs(p2 - point))});
  const double extentError = gammaBound(16) * extent;
  pointError =
      (abs(w0) + abs(w1) + abs(w2)) * gammaBound(7) + Vec3{extentError, extentError, extentError};
}

}  // namespace glint
