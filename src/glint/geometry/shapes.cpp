// Implementations of every shape in shape.h and of Primitive. All computations are in the space of
// the ray passed in (object space for transformed primitives), in double precision.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include "glint/core/spawn.h"
#include "glint/geometry/csg.h"
#include "glint/geometry/object_space.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/sphere_intersection.h"
#include "glint/geometry/watertight_triangle.h"

namespace glint {

namespace {

using quadric::inOpenRange;
using quadric::nearerRootInRange;
using quadric::quadricRoots;
using quadric::wholeQuadricBehind;

// kParallelBound (watertight_triangle.h) also bounds "the direction is along a tube's axis".

// Tolerances for degenerate input, relative to the shape's size (DESIGN.md §7):
// - collinear: |(b−a)×(c−a)| (twice the area) ≤ kCollinearTolerance (watertight_triangle.h) ·
// size²,
//   i.e. the shape is thinner than 1e-12 of its size — far below anything a scene can mean, above
//   double rounding;
// - planar / perpendicular / convex: a vertex may stray from the plane by kShapeTolerance · size,
//   two rectangle edges may have cosine up to kShapeTolerance, a convex corner may turn the wrong
//   way by a sine of kShapeTolerance — loose enough for coordinates written with ~10 significant
//   digits.
constexpr double kShapeTolerance = 1e-9;

// --- formatting and validation of make() parameters ---

// The scene key a parameter name stands for: "edges[0]" → "edges".
std::string parameterOf(const char* name) {
  const std::string_view text(name);
  return std::string(text.substr(0, text.find('[')));
}

std::string format(const Vec3& v) { return fmt::format("[{}, {}, {}]", v.x, v.y, v.z); }
std::string format(const Point3& p) { return fmt::format("[{}, {}, {}]", p.x, p.y, p.z); }

void requireFinite(const char* name, const Point3& p) {
  if (!isFinite(p))
    throw ShapeError(parameterOf(name), fmt::format("{} must be finite, got {}", name, format(p)));
}

// Unit vector along a direction parameter; rejects non-finite and zero vectors. Dividing by the
// largest component first keeps huge or tiny (but non-zero) inputs from overflowing or
// underflowing.
Vec3 requireDirection(const char* name, const Vec3& v) {
  if (!isFinite(v))
    throw ShapeError(parameterOf(name), fmt::format("{} must be finite, got {}", name, format(v)));
  const double largest = maxComponent(abs(v));
  if (largest == 0)
    throw ShapeError(parameterOf(name),
                     fmt::format("{} must be a non-zero vector, got {}", name, format(v)));
  return normalize(v / largest);
}

double requirePositive(const char* name, double value) {
  if (std::isinf(value))
    throw ShapeError(parameterOf(name), fmt::format("{} must be finite, got {}", name, value));
  if (!(value > 0))
    throw ShapeError(parameterOf(name), fmt::format("{} must be > 0, got {}", name, value));
  return value;
}

// Newell's vector of a vertex loop: twice its vector area. Its direction is the loop's normal by
// the right-hand rule (robust for any planar polygon, convex or not), its length judges degeneracy.
Vec3 newellVector(const Point3* vertices, std::size_t count) {
  Vec3 n;
  for (std::size_t i = 0; i < count; ++i) {
    const Point3& a = vertices[i];
    const Point3& b = vertices[(i + 1) % count];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n;
}

// Size of a vertex set: the diagonal of its bounding box.
double vertexSetSize(const Point3* vertices, std::size_t count) {
  Bounds3 b;
  for (std::size_t i = 0; i < count; ++i) b = unite(b, vertices[i]);
  return length(b.diagonal());
}

// Checks that a vertex loop is non-degenerate and planar; returns its unit normal. Messages start
// with the scene key ("vertices"), which the scene builder uses to point at it.
Normal3 requirePlanarLoop(const Point3* vertices, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!isFinite(vertices[i]))
      throw ShapeError("vertices",
                       fmt::format("vertices[{}] must be finite, got {}", i, format(vertices[i])));
  }
  const double size = vertexSetSize(vertices, count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t j = (i + 1) % count;
    if (distance(vertices[i], vertices[j]) <= kCollinearTolerance * size || size == 0)
      throw ShapeError("vertices", fmt::format("vertices[{}] and [{}] coincide, both {}", i, j,
                                               format(vertices[i])));
  }
  const Vec3 newell = newellVector(vertices, count);
  if (length(newell) <= kCollinearTolerance * size * size) {
    // No area: the points lie on a line, or the loop crosses itself so that its parts enclose
    // opposite areas that cancel (a symmetric bow tie). Off the line through vertices[0] and the
    // vertex farthest from it, some vertex lies away in the second case.
    std::size_t far = 0;
    for (std::size_t i = 1; i < count; ++i) {
      if (distance(vertices[0], vertices[i]) > distance(vertices[0], vertices[far])) far = i;
    }
    const Vec3 axis = vertices[far] - vertices[0];
    for (std::size_t i = 1; i < count; ++i) {
      if (length(cross(axis, vertices[i] - vertices[0])) > kCollinearTolerance * size * size) {
        throw ShapeError("vertices",
                         "vertices are self-intersecting: the loop crosses itself and "
                         "its parts enclose opposite areas that cancel");
      }
    }
    throw ShapeError("vertices",
                     fmt::format("vertices are collinear (enclosed area {} for size {})",
                                 0.5 * length(newell), size));
  }
  const Vec3 n = normalize(newell);
  Vec3 centroid;
  for (std::size_t i = 0; i < count; ++i) centroid += toVec(vertices[i]);
  centroid = centroid / static_cast<double>(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double offPlane = std::abs(dot(toVec(vertices[i]) - centroid, n));
    if (offPlane > kShapeTolerance * size)
      throw ShapeError("vertices", fmt::format("vertices are not planar: vertices[{}] is {} away "
                                               "from the plane of the others (size {})",
                                               i, offPlane, size));
  }
  return Normal3(n);
}

// Signed turn at vertex i of a loop, as the sine of the turning angle along the normal n
// (positive = left turn by the right-hand rule), and the cosine (negative = the edges fold back).
struct Turn {
  double sine = 0;
  double cosine = 0;
};
Turn turnAt(const Point3* vertices, std::size_t count, std::size_t i, const Normal3& n) {
  const Point3& prev = vertices[(i + count - 1) % count];
  const Point3& here = vertices[i];
  const Point3& next = vertices[(i + 1) % count];
  const Vec3 in = normalize(here - prev);
  const Vec3 out = normalize(next - here);
  return {dot(n, cross(in, out)), dot(in, out)};
}

bool isParallel(const Normal3& n, const Vec3& d, double nDotD) {
  return isParallelToPlane(toVec(n), d, nDotD);
}

// Ray parameter where the ray meets the plane (point, unit normal), or false when the ray is
// parallel to it (including lying in it).
bool planeParameter(const Point3& point, const Normal3& n, const Ray& ray, double& t) {
  const double nDotD = dot(n, ray.direction);
  if (isParallel(n, ray.direction, nDotD)) return false;
  t = dot(n, point - ray.origin) / nDotD;
  return true;
}

// Whether the quotient num/den can be > 0, decided from the signs alone: a quotient of operands of
// opposite signs (or a zero, or a NaN numerator) is ≤ 0 or NaN and can never lie in an interval
// (tMin, tMax) with tMin ≥ 0. Exact — it only skips a division whose result the range test would
// reject.
bool positiveQuotientPossible(double num, double den) {
  return (num > 0 && den > 0) || (num < 0 && den < 0);
}

// --- hit points with error bounds (core/spawn.h states the policy these serve) ---
// Each bound covers the rounding of the reprojected point itself and the error with which the
// intersection routine of the same shape, run again from a point near it, decides which side of
// the surface that point is on; both involve the same magnitudes, named in each bound.

Vec3 uniform(double e) { return Vec3{e, e, e}; }

// ray.at(t) moved onto the plane through q with unit normal n, along n. The distance s = n·(p − q)
// is computed with error γ4·|n|₁·|p − q|∞ and the move adds rounding of |p|; the plane
// intersection routine decides the side of a point from n·(q − o) with the same error. `scale`
// adds magnitudes the routine also subtracts (a cylinder's height for its top cap).
void planeHitPoint(const Ray& ray, double t, const Point3& q, const Normal3& n, double scale,
                   ShapeHit& hit) {
  const Point3 p = ray.at(t);
  const Point3 onPlane = p - toVec(n) * dot(n, p - q);
  hit.point = onPlane;
  hit.pointError = abs(toVec(onPlane)) * gammaBound(3) +
                   uniform(gammaBound(10) * (maxComponent(abs(onPlane - q)) + scale));
}

// A point `rel` (relative to axisPoint, near the tube of radius r around the unit axis) moved
// radially onto the tube. Splitting rel into its axial and radial parts and rescaling the radial
// part costs a few ulps of |rel| and r; adding axisPoint back rounds at |point|.
void tubeHitPoint(const Point3& axisPoint, const Vec3& axis, double r, const Vec3& rel,
                  ShapeHit& hit) {
  const double h = dot(rel, axis);
  const Vec3 radial = rel - axis * h;
  const Vec3 onSurface = axis * h + radial * (r / length(radial));
  hit.point = axisPoint + onSurface;
  hit.pointError = abs(toVec(hit.point)) * gammaBound(3) +
                   uniform(gammaBound(32) * (maxComponent(abs(onSurface)) + r));
}

// The hit on the box face of `axis` at coordinate `face`: that coordinate is snapped exactly, so
// the error across the face is 0 (the slab test subtracts it from a spawned origin exactly, by
// Sterbenz's lemma); the other two coordinates keep the rounding of ray.at(t).
void boxHitPoint(const Ray& ray, double t, int axis, double face, ShapeHit& hit) {
  Point3 p = ray.at(t);
  p[axis] = face;
  hit.point = p;
  Vec3 e = (abs(toVec(ray.origin)) + abs(ray.direction * t)) * gammaBound(3);
  e[axis] = 0;
  hit.pointError = e;
}

// Roots of the infinite cylinder of radius r about the unit axis through the ray-relative point f;
// false when the ray runs along the axis (it never crosses the side) or is tangent.
bool tubeRoots(const Vec3& f, const Vec3& d, const Vec3& axis, double r, double& t0, double& t1) {
  const Vec3 dPerp = d - axis * dot(d, axis);
  const double dPerp2 = dot(dPerp, dPerp);
  if (dPerp2 <= kParallelBound * kParallelBound * dot(d, d)) return false;
  const Vec3 fPerp = f - axis * dot(f, axis);
  return quadricRoots(fPerp, dPerp, r, t0, t1);
}

Normal3 radialNormal(const Vec3& fromAxisPoint, const Vec3& axis) {
  return Normal3(normalize(fromAxisPoint - axis * dot(fromAxisPoint, axis)));
}

// Exact bounds of a disk (centre c, unit normal n, radius r): along axis i it extends
// r·sqrt(1 − n_i²) = r·sqrt(n_j² + n_k²) either side of the centre.
Bounds3 diskBounds(const Point3& c, const Vec3& n, double r) {
  const Vec3 half{r * std::sqrt(n.y * n.y + n.z * n.z), r * std::sqrt(n.z * n.z + n.x * n.x),
                  r * std::sqrt(n.x * n.x + n.y * n.y)};
  return Bounds3(c - half, c + half);
}

// Unit normal (b−a)×(c−a) of three finite, non-collinear points named `key` in messages. Degenerate
// when twice the area |e1×e2| ≤ kCollinearTolerance · (longest edge)²: the triangle is then thinner
// than that fraction of its longest edge (or has coincident vertices).
Normal3 nonCollinearNormal(const char* key, const Point3& a, const Point3& b, const Point3& c) {
  const Point3 points[3] = {a, b, c};
  for (int i = 0; i < 3; ++i) {
    if (!isFinite(points[i]))
      throw ShapeError(parameterOf(key),
                       fmt::format("{}[{}] must be finite, got {}", key, i, format(points[i])));
  }
  const Vec3 n = cross(b - a, c - a);
  const double longest =
      std::max({distanceSquared(a, b), distanceSquared(b, c), distanceSquared(c, a)});
  if (length(n) <= kCollinearTolerance * longest)
    throw ShapeError(parameterOf(key), fmt::format("{} are collinear: {}, {}, {}", key, format(a),
                                                   format(b), format(c)));
  return Normal3(normalize(n));
}

}  // namespace

// ---------------------------------------------------------------------------------------- Sphere

Sphere Sphere::make(const Point3& center, double radius) {
  requireFinite("center", center);
  return Sphere{center, requirePositive("radius", radius)};
}

bool Sphere::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  return quadric::sphereIntersect(center, radius, ray, tMin, tMax, hit);
}

int Sphere::crossings(const Ray& ray, double tMin, double tMax) const {
  return quadric::sphereCrossings(center, radius, ray, tMin, tMax);
}

Bounds3 Sphere::bounds() const {
  const Vec3 r{radius, radius, radius};
  return Bounds3(center - r, center + r);
}

Normal3 Sphere::normalAt(const Point3& p) const { return Normal3(normalize(p - center)); }

// ----------------------------------------------------------------------------------------- Plane

Plane Plane::make(const Point3& point, const Vec3& normal) {
  requireFinite("point", point);
  return Plane{point, Normal3(requireDirection("normal", normal))};
}

Plane Plane::fromPoints(const Point3& a, const Point3& b, const Point3& c) {
  return Plane{a, nonCollinearNormal("points", a, b, c)};
}

namespace {

// The plane's ray parameter when it lies in (tMin, tMax): planeParameter and the range test, with
// the division skipped where the signs already put t ≤ 0 (the ray leaves the plane's side it
// starts on, as every shadow ray from above a ground plane does).
[[gnu::always_inline]] inline bool planeCrossing(const Point3& point, const Normal3& n,
                                                 const Ray& ray, double tMin, double tMax,
                                                 double& t) {
  const double nDotD = dot(n, ray.direction);
  const double num = dot(n, point - ray.origin);
  if (tMin >= 0 && !positiveQuotientPossible(num, nDotD)) return false;
  if (isParallel(n, ray.direction, nDotD)) return false;
  t = num / nDotD;
  return inOpenRange(t, tMin, tMax);
}

// The rest of a plane hit whose t is set.
[[gnu::always_inline]] inline void planeCompleteHit(const Plane& plane, const Ray& ray,
                                                    ShapeHit& hit) {
  hit.normal = plane.normal;
  planeHitPoint(ray, hit.t, plane.point, plane.normal, 0, hit);
}

[[gnu::always_inline]] inline bool planeIntersect(const Plane& plane, const Ray& ray, double tMin,
                                                  double tMax, ShapeHit& hit) {
  double t;
  if (!planeCrossing(plane.point, plane.normal, ray, tMin, tMax, t)) return false;
  hit.t = t;
  planeCompleteHit(plane, ray, hit);
  return true;
}

[[gnu::always_inline]] inline int planeCrossings(const Plane& plane, const Ray& ray, double tMin,
                                                 double tMax) {
  double t;
  return planeCrossing(plane.point, plane.normal, ray, tMin, tMax, t) ? 1 : 0;
}

}  // namespace

bool Plane::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  return planeIntersect(*this, ray, tMin, tMax, hit);
}

int Plane::crossings(const Ray& ray, double tMin, double tMax) const {
  return planeCrossings(*this, ray, tMin, tMax);
}

Bounds3 Plane::bounds() const { return Bounds3::unbounded(); }

Normal3 Plane::normalAt(const Point3&) const { return normal; }

// -------------------------------------------------------------------------------------- Triangle

Triangle Triangle::make(const Point3& v0, const Point3& v1, const Point3& v2) {
  return Triangle{v0, v1, v2, nonCollinearNormal("vertices", v0, v1, v2)};
}

// The watertight test of watertight_triangle.h (Woop, Benthin and Wald 2013): rays through a shared
// edge or vertex hit one of the triangles sharing it.
bool Triangle::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  WatertightHit candidate;
  if (!intersectWatertight(WatertightRay(ray), v0, v1, v2, tMin, tMax, candidate) ||
      isParallel(normal, ray.direction, dot(normal, ray.direction))) {
    return false;
  }
  hit.t = candidate.t;
  hit.normal = normal;
  watertightHitPoint(v0, v1, v2, candidate, hit.point, hit.pointError);
  return true;
}

int Triangle::crossings(const Ray& ray, double tMin, double tMax) const {
  ShapeHit hit;
  return intersect(ray, tMin, tMax, hit) ? 1 : 0;
}

Bounds3 Triangle::bounds() const { return unite(Bounds3(v0, v1), v2); }

Normal3 Triangle::normalAt(const Point3&) const { return normal; }

// --------------------------------------------------------------------------------------- Polygon

Polygon Polygon::make(std::vector<Point3> vertices) {
  const std::size_t count = vertices.size();
  if (count < 3)
    throw ShapeError("vertices",
                     fmt::format("vertices must hold at least 3 points, got {}", count));
  const Normal3 n = requirePlanarLoop(vertices.data(), count);
  // Convex and simple: every corner turns the same way about the normal (a straight corner, a
  // vertex in the middle of an edge, is allowed), and the turns add up to one full revolution —
  // a star whose corners all turn left still winds around twice.
  double totalTurn = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const Turn turn = turnAt(vertices.data(), count, i, n);
    if (turn.sine < -kShapeTolerance)
      throw ShapeError(
          "vertices",
          fmt::format("vertices are not convex: the corner at vertices[{}] {} turns the other way",
                      i, format(vertices[i])));
    if (std::abs(turn.sine) <= kShapeTolerance && turn.cosine < 0)
      throw ShapeError(
          "vertices", fmt::format("vertices fold back at vertices[{}] {}", i, format(vertices[i])));
    totalTurn += std::atan2(turn.sine, turn.cosine);
  }
  if (totalTurn > 3 * std::numbers::pi)
    throw ShapeError("vertices",
                     fmt::format("vertices are self-intersecting: the edges wind around {} times",
                                 std::lround(totalTurn / (2 * std::numbers::pi))));
  return Polygon{std::move(vertices), n};
}

bool Polygon::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  double t;
  if (!planeParameter(vertices[0], normal, ray, t) || !inOpenRange(t, tMin, tMax)) return false;
  // Inside a convex polygon: on the left of (or on) every edge, looking down the normal.
  const Point3 p = ray.at(t);
  const std::size_t count = vertices.size();
  for (std::size_t i = 0; i < count; ++i) {
    const Point3& a = vertices[i];
    const Point3& b = vertices[i + 1 == count ? 0 : i + 1];
    if (dot(normal, cross(b - a, p - a)) < 0) return false;
  }
  hit.t = t;
  hit.normal = normal;
  planeHitPoint(ray, t, vertices[0], normal, 0, hit);
  return true;
}

int Polygon::crossings(const Ray& ray, double tMin, double tMax) const {
  ShapeHit hit;
  return intersect(ray, tMin, tMax, hit) ? 1 : 0;
}

Bounds3 Polygon::bounds() const {
  Bounds3 b;
  for (const Point3& v : vertices) b = unite(b, v);
  return b;
}

Normal3 Polygon::normalAt(const Point3&) const { return normal; }

// ------------------------------------------------------------------------------------- Rectangle

Rectangle Rectangle::make(const Point3& corner, const Vec3& edge0, const Vec3& edge1) {
  requireFinite("corner", corner);
  requireDirection("edges[0]", edge0);
  requireDirection("edges[1]", edge1);
  const double len0 = length(edge0);
  const double len1 = length(edge1);
  const double cosine = dot(edge0, edge1) / (len0 * len1);
  if (std::abs(cosine) > kShapeTolerance)
    throw ShapeError(
        "edges", fmt::format("edges must be perpendicular, got {} and {} at {:.6g} degrees",
                             format(edge0), format(edge1),
                             std::acos(std::clamp(cosine, -1.0, 1.0)) * 180 / std::numbers::pi));
  return Rectangle{corner, edge0, edge1, Normal3(normalize(cross(edge0, edge1)))};
}

bool Rectangle::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  double t;
  if (!planeParameter(corner, normal, ray, t) || !inOpenRange(t, tMin, tMax)) return false;
  // Coordinates along the perpendicular edges, each in [0, 1] inside (edges included).
  const Vec3 offset = ray.at(t) - corner;
  const double s = dot(offset, edge0) / dot(edge0, edge0);
  const double r = dot(offset, edge1) / dot(edge1, edge1);
  if (!(s >= 0 && s <= 1 && r >= 0 && r <= 1)) return false;
  hit.t = t;
  hit.normal = normal;
  planeHitPoint(ray, t, corner, normal, 0, hit);
  return true;
}

int Rectangle::crossings(const Ray& ray, double tMin, double tMax) const {
  ShapeHit hit;
  return intersect(ray, tMin, tMax, hit) ? 1 : 0;
}

Bounds3 Rectangle::bounds() const {
  return unite(Bounds3(corner, corner + edge0 + edge1), Bounds3(corner + edge0, corner + edge1));
}

Normal3 Rectangle::normalAt(const Point3&) const { return normal; }

// ------------------------------------------------------------------------------------ Quadrangle

Quadrangle Quadrangle::make(const Point3& v0, const Point3& v1, const Point3& v2,
                            const Point3& v3) {
  const Point3 v[4] = {v0, v1, v2, v3};
  const Normal3 n = requirePlanarLoop(v, 4);
  // A simple quadrangle turns the same way as its Newell normal at all corners (convex) or at all
  // but one (the reflex corner of a dart); a bow tie turns the other way at two corners.
  int reflexCount = 0;
  std::size_t diagonalFrom = 0;
  double smallestTurn = kInfinity;
  for (std::size_t i = 0; i < 4; ++i) {
    const Turn turn = turnAt(v, 4, i, n);
    if (std::abs(turn.sine) <= kShapeTolerance && turn.cosine < 0)
      throw ShapeError("vertices",
                       fmt::format("vertices fold back at vertices[{}] {}", i, format(v[i])));
    if (turn.sine < -kShapeTolerance) ++reflexCount;
    if (turn.sine < smallestTurn) {
      smallestTurn = turn.sine;
      diagonalFrom = i;
    }
  }
  if (reflexCount > 1)
    throw ShapeError("vertices", fmt::format("vertices are self-intersecting: {}, {}, {}, {}",
                                             format(v0), format(v1), format(v2), format(v3)));
  // The diagonal from the reflex corner (or, when convex, from the flattest one, which may be a
  // straight 180° corner) lies inside and leaves no degenerate half.
  const std::size_t k = diagonalFrom;
  const std::array<Point3, 4> corners{v[k], v[(k + 1) % 4], v[(k + 2) % 4], v[(k + 3) % 4]};
  try {
    Triangle::make(corners[0], corners[1], corners[2]);
    Triangle::make(corners[0], corners[2], corners[3]);
  } catch (const ShapeError&) {
    throw ShapeError("vertices", fmt::format("vertices are degenerate: {}, {}, {}, {}", format(v0),
                                             format(v1), format(v2), format(v3)));
  }
  return Quadrangle{corners, n};
}

bool Quadrangle::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  // The halves are coplanar (within the planarity tolerance), so the nearer one is kept only to be
  // exact; the normal is the quadrangle's, identical for both halves. Each half rejects rays in
  // its own plane, as a Triangle does.
  const WatertightRay watertightRay(ray);
  const auto half = [&](const Point3& a, const Point3& b, const Point3& c, double tFar,
                        WatertightHit& candidate) {
    return intersectWatertight(watertightRay, a, b, c, tMin, tFar, candidate) &&
           !isParallelToPlane(cross(b - a, c - a), ray.direction);
  };
  WatertightHit candidate;
  bool found = half(corners[0], corners[1], corners[2], tMax, candidate);
  bool second = false;
  if (half(corners[0], corners[2], corners[3], found ? candidate.t : tMax, candidate)) {
    found = true;
    second = true;
  }
  if (!found) return false;
  hit.t = candidate.t;
  hit.normal = normal;
  watertightHitPoint(corners[0], second ? corners[2] : corners[1], second ? corners[3] : corners[2],
                     candidate, hit.point, hit.pointError);
  return true;
}

int Quadrangle::crossings(const Ray& ray, double tMin, double tMax) const {
  ShapeHit hit;
  return intersect(ray, tMin, tMax, hit) ? 1 : 0;
}

Bounds3 Quadrangle::bounds() const {
  return unite(Bounds3(corners[0], corners[1]), Bounds3(corners[2], corners[3]));
}

Normal3 Quadrangle::normalAt(const Point3&) const { return normal; }

// ------------------------------------------------------------------------------------------ Tube

Tube Tube::make(const Point3& origin, const Vec3& axis, double radius) {
  requireFinite("origin", origin);
  const Vec3 unitAxis = requireDirection("axis", axis);
  return Tube{origin, unitAxis, requirePositive("radius", radius)};
}

bool Tube::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  const Vec3 f = ray.origin - origin;
  double t0;
  double t1;
  if (!tubeRoots(f, ray.direction, axis, radius, t0, t1)) return false;
  double t;
  if (!nearerRootInRange(t0, t1, tMin, tMax, t)) return false;
  hit.t = t;
  hit.normal = radialNormal(f + ray.direction * t, axis);
  tubeHitPoint(origin, axis, radius, f + ray.direction * t, hit);
  return true;
}

int Tube::crossings(const Ray& ray, double tMin, double tMax) const {
  double t0;
  double t1;
  if (!tubeRoots(ray.origin - origin, ray.direction, axis, radius, t0, t1)) return 0;
  return int{inOpenRange(t0, tMin, tMax)} + int{inOpenRange(t1, tMin, tMax)};
}

Bounds3 Tube::bounds() const { return Bounds3::unbounded(); }

Normal3 Tube::normalAt(const Point3& p) const { return radialNormal(p - origin, axis); }

// -------------------------------------------------------------------------------------- Cylinder

namespace {

enum class CylinderPart { kSide, kBase, kTop };

// The open interval (enter, exit) of the line inside the solid cylinder, found like the slab method
// of a box: the solid is the intersection of the open infinite tube |q⊥| < r and the open slab
// 0 < h < height, so the line is inside on the intersection of its two intervals, and the part that
// bounds it (side, base or top) gives the normal. A line along the side surface or in a cap plane
// is in neither open set and misses, like a ray grazing a box face; a line touching only the rim
// has enter == exit and misses (tangent). A ray through the rim enters or leaves there once, on the
// side (ties go to the side), so there is no gap and no double count where side and cap meet.
struct CylinderSpan {
  double enter = -kInfinity;
  double exit = kInfinity;
  CylinderPart enterPart = CylinderPart::kSide;
  CylinderPart exitPart = CylinderPart::kSide;
};

bool cylinderSpan(const Cylinder& cyl, const Ray& ray, CylinderSpan& span) {
  const Vec3 f = ray.origin - cyl.base;
  const Vec3& d = ray.direction;
  // Tube interval.
  double tube0 = -kInfinity;
  double tube1 = kInfinity;
  const Vec3 dPerp = d - cyl.axis * dot(d, cyl.axis);
  const Vec3 fPerp = f - cyl.axis * dot(f, cyl.axis);
  if (dot(dPerp, dPerp) <= kParallelBound * kParallelBound * dot(d, d)) {
    if (!(dot(fPerp, fPerp) < cyl.radius * cyl.radius)) return false;
  } else if (!quadricRoots(fPerp, dPerp, cyl.radius, tube0, tube1)) {
    return false;
  }
  // Slab interval between the cap planes.
  double slab0 = -kInfinity;
  double slab1 = kInfinity;
  CylinderPart slabEnter = CylinderPart::kBase;
  CylinderPart slabExit = CylinderPart::kTop;
  const double h = dot(f, cyl.axis);
  const double aDotD = dot(cyl.axis, d);
  if (isParallel(Normal3(cyl.axis), d, aDotD)) {
    if (!(h > 0 && h < cyl.height)) return false;
  } else {
    slab0 = -h / aDotD;
    slab1 = (cyl.height - h) / aDotD;
    if (aDotD < 0) {
      std::swap(slab0, slab1);
      std::swap(slabEnter, slabExit);
    }
  }
  span.enter = tube0 >= slab0 ? tube0 : slab0;
  span.enterPart = tube0 >= slab0 ? CylinderPart::kSide : slabEnter;
  span.exit = tube1 <= slab1 ? tube1 : slab1;
  span.exitPart = tube1 <= slab1 ? CylinderPart::kSide : slabExit;
  return span.enter < span.exit;
}

}  // namespace

Cylinder Cylinder::make(const Point3& base, const Vec3& axis, double radius, double height) {
  requireFinite("base", base);
  const Vec3 unitAxis = requireDirection("axis", axis);
  requirePositive("radius", radius);
  requirePositive("height", height);
  return Cylinder{base, unitAxis, radius, height};
}

bool Cylinder::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  CylinderSpan span;
  if (!cylinderSpan(*this, ray, span)) return false;
  CylinderPart part;
  if (inOpenRange(span.enter, tMin, tMax)) {
    hit.t = span.enter;
    part = span.enterPart;
  } else if (inOpenRange(span.exit, tMin, tMax)) {
    hit.t = span.exit;
    part = span.exitPart;
  } else {
    return false;
  }
  switch (part) {
    case CylinderPart::kSide:
      hit.normal = radialNormal(ray.origin - base + ray.direction * hit.t, axis);
      tubeHitPoint(base, axis, radius, ray.origin - base + ray.direction * hit.t, hit);
      break;
    case CylinderPart::kBase:
      hit.normal = Normal3(-axis);
      planeHitPoint(ray, hit.t, base, hit.normal, 0, hit);
      break;
    case CylinderPart::kTop:
      hit.normal = Normal3(axis);
      planeHitPoint(ray, hit.t, base + axis * height, hit.normal, height, hit);
      break;
  }
  return true;
}

int Cylinder::crossings(const Ray& ray, double tMin, double tMax) const {
  CylinderSpan span;
  if (!cylinderSpan(*this, ray, span)) return 0;
  return int{inOpenRange(span.enter, tMin, tMax)} + int{inOpenRange(span.exit, tMin, tMax)};
}

Bounds3 Cylinder::bounds() const {
  return unite(diskBounds(base, axis, radius), diskBounds(base + axis * height, axis, radius));
}

// The part whose surface p is nearest to decides: a cap (±axis) or the side (radial).
Normal3 Cylinder::normalAt(const Point3& p) const {
  const Vec3 f = p - base;
  const double h = dot(f, axis);
  const Vec3 radial = f - axis * h;
  const double toSide = std::abs(length(radial) - radius);
  const double toBase = std::abs(h);
  const double toTop = std::abs(h - height);
  if (toSide <= toBase && toSide <= toTop) return Normal3(normalize(radial));
  return toBase <= toTop ? Normal3(-axis) : Normal3(axis);
}

// ------------------------------------------------------------------------------------------- Box

namespace {

// Slab method (Kay–Kajiya) over the open interval of the line inside the box. Returns false when
// the line misses, touches only an edge or corner (entry == exit: tangent), or lies in the plane of
// a face (direction component 0 with the origin exactly on that face's plane): such a ray touches
// the surface without ever entering the interior, as a tangent ray touches a sphere, so it misses.
struct Slabs {
  double tEnter = -kInfinity;
  double tExit = kInfinity;
  int enterAxis = 0;
  int exitAxis = 0;
};

bool boxSlabs(const Box& box, const Ray& ray, Slabs& s) {
  for (int axis = 0; axis < 3; ++axis) {
    const double o = ray.origin[axis];
    const double d = ray.direction[axis];
    if (d == 0) {
      if (!(o > box.lo[axis] && o < box.hi[axis])) return false;
      continue;
    }
    double tNear = (box.lo[axis] - o) / d;
    double tFar = (box.hi[axis] - o) / d;
    if (d < 0) std::swap(tNear, tFar);
    if (tNear > s.tEnter) {
      s.tEnter = tNear;
      s.enterAxis = axis;
    }
    if (tFar < s.tExit) {
      s.tExit = tFar;
      s.exitAxis = axis;
    }
  }
  return s.tEnter < s.tExit;
}

Normal3 axisNormal(int axis, double sign) {
  Normal3 n;
  if (axis == 0) n = Normal3(sign, 0, 0);
  if (axis == 1) n = Normal3(0, sign, 0);
  if (axis == 2) n = Normal3(0, 0, sign);
  return n;
}

}  // namespace

Box Box::make(const Point3& lo, const Point3& hi) {
  requireFinite("min", lo);
  requireFinite("max", hi);
  if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
    throw ShapeError("min", fmt::format("min must be < max on every axis, got min {} and max {}",
                                        format(lo), format(hi)));
  return Box{lo, hi};
}

bool Box::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  Slabs s;
  if (!boxSlabs(*this, ray, s)) return false;
  if (inOpenRange(s.tEnter, tMin, tMax)) {
    hit.t = s.tEnter;  // the entered face faces against the ray
    const bool positive = ray.direction[s.enterAxis] < 0;
    hit.normal = axisNormal(s.enterAxis, positive ? 1.0 : -1.0);
    boxHitPoint(ray, hit.t, s.enterAxis, positive ? hi[s.enterAxis] : lo[s.enterAxis], hit);
    return true;
  }
  if (inOpenRange(s.tExit, tMin, tMax)) {
    hit.t = s.tExit;  // from inside: the exit face, still with its outward normal
    const bool positive = ray.direction[s.exitAxis] > 0;
    hit.normal = axisNormal(s.exitAxis, positive ? 1.0 : -1.0);
    boxHitPoint(ray, hit.t, s.exitAxis, positive ? hi[s.exitAxis] : lo[s.exitAxis], hit);
    return true;
  }
  return false;
}

int Box::crossings(const Ray& ray, double tMin, double tMax) const {
  Slabs s;
  if (!boxSlabs(*this, ray, s)) return 0;
  return int{inOpenRange(s.tEnter, tMin, tMax)} + int{inOpenRange(s.tExit, tMin, tMax)};
}

Bounds3 Box::bounds() const { return Bounds3(lo, hi); }

// The face whose plane p is nearest to.
Normal3 Box::normalAt(const Point3& p) const {
  int bestAxis = 0;
  double bestSign = -1;
  double bestDistance = kInfinity;
  for (int axis = 0; axis < 3; ++axis) {
    const double toLo = std::abs(p[axis] - lo[axis]);
    const double toHi = std::abs(p[axis] - hi[axis]);
    if (toLo < bestDistance) {
      bestDistance = toLo;
      bestAxis = axis;
      bestSign = -1;
    }
    if (toHi < bestDistance) {
      bestDistance = toHi;
      bestAxis = axis;
      bestSign = 1;
    }
  }
  return axisNormal(bestAxis, bestSign);
}

// ------------------------------------------------------------------------------------------ Disk

Disk Disk::make(const Point3& center, const Vec3& normal, double radius, double innerRadius) {
  requireFinite("center", center);
  const Vec3 unitNormal = requireDirection("normal", normal);
  requirePositive("radius", radius);
  if (!(innerRadius >= 0 && innerRadius < radius)) {
    throw ShapeError(
        "inner_radius",
        fmt::format("inner_radius must be >= 0 and < radius ({}), got {}", radius, innerRadius));
  }
  return Disk{center, Normal3(unitNormal), radius, innerRadius};
}

bool Disk::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  double t;
  if (!planeParameter(center, normal, ray, t) || !inOpenRange(t, tMin, tMax)) return false;
  const double d2 = distanceSquared(ray.at(t), center);
  if (d2 > radius * radius || d2 < innerRadius * innerRadius) return false;
  hit.t = t;
  hit.normal = normal;
  planeHitPoint(ray, t, center, normal, 0, hit);
  return true;
}

int Disk::crossings(const Ray& ray, double tMin, double tMax) const {
  ShapeHit hit;
  return intersect(ray, tMin, tMax, hit) ? 1 : 0;
}

Bounds3 Disk::bounds() const { return diskBounds(center, toVec(normal), radius); }

Normal3 Disk::normalAt(const Point3&) const { return normal; }

// ------------------------------------------------------------------------------------- Primitive
// (requireInvertibleAffine, worldPointError and objectRayOf are shared with csg.cpp through
// object_space.h.)

// An affine transform whose linear part has a finite, non-zero determinant (and a finite inverse),
// so object-space rays keep non-zero directions and t means the same in both spaces.
void requireInvertibleAffine(const Transform& transform) {
  const auto& m = transform.matrix().m;
  const auto& inv = transform.inverseMatrix().m;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(m[i][j]) || !std::isfinite(inv[i][j]))
        throw ShapeError("transform", "transform must be finite, got a non-finite matrix entry");
  if (m[3][0] != 0 || m[3][1] != 0 || m[3][2] != 0 || m[3][3] != 1)
    throw ShapeError("transform",
                     fmt::format("transform must be affine, got bottom row [{}, {}, {}, {}]",
                                 m[3][0], m[3][1], m[3][2], m[3][3]));
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  if (det == 0 || !std::isfinite(det))
    throw ShapeError("transform",
                     fmt::format("transform must be invertible, got determinant {}", det));
}

// Error bound of worldFromObject(p): worldPointErrorOf (object_space.h) on its two matrices.
Vec3 worldPointError(const Transform& worldFromObject, const Point3& p, const Vec3& e,
                     const Point3& world) {
  return worldPointErrorOf(worldFromObject.matrix().m, worldFromObject.inverseMatrix().m, p, e,
                           world);
}

// objectFromWorld applied to a ray: the inverse matrix of worldFromObject, with the same arithmetic
// as Transform::operator() so results do not depend on where the matrix is stored.
Ray objectRayOf(const Transform& worldFromObject, const Ray& r) {
  const auto& m = worldFromObject.inverseMatrix().m;
  const Point3& p = r.origin;
  const Vec3& v = r.direction;
  const double x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
  const double y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
  const double z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
  const double w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
  const Point3 origin = w == 1 ? Point3{x, y, z} : Point3{x / w, y / w, z / w};
  return Ray{
      origin,
      {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
       m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z}};
}

double reachOf(const Bounds3& bounds) {
  double reach = 0;
  for (const Point3& corner : {bounds.lo, bounds.hi}) {
    for (const double c : {corner.x, corner.y, corner.z}) {
      if (std::isfinite(c)) reach = std::max(reach, std::abs(c));
    }
  }
  return reach;
}

std::string beyondReach(double reach) {
  return fmt::format(
      "reaches {:g} from the origin, beyond the ±{:g} glint computes in (its double-precision "
      "intersection tests multiply up to three coordinates, which would overflow): scale the "
      "scene down",
      reach, kMaxCoordinate);
}

Primitive::Primitive(Shape shape, std::uint32_t materialIndex, const Color& emission,
                     std::optional<Transform> worldFromObject)
    : shape_(std::move(shape)), emission_(emission), materialIndex_(materialIndex) {
  if (worldFromObject && !worldFromObject->isIdentity()) {
    requireInvertibleAffine(*worldFromObject);
    worldFromObject_ = std::make_shared<const Transform>(*worldFromObject);
  }
  const Bounds3 objectBounds = std::visit([](const auto& s) { return s.bounds(); }, shape_);
  bounds_ = worldFromObject_ ? (*worldFromObject_)(objectBounds) : objectBounds;
  // Within reach in its own space and in the world.
  for (const Bounds3& box : {objectBounds, bounds_}) {
    if (const double reach = reachOf(box); reach > kMaxCoordinate) {
      throw ShapeError("", "the object " + beyondReach(reach));
    }
  }
}

bool Primitive::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  if (!worldFromObject_) {
    if (const auto* sphere = std::get_if<Sphere>(&shape_))
      return quadric::sphereIntersect(sphere->center, sphere->radius, ray, tMin, tMax, hit);
    if (const auto* plane = std::get_if<Plane>(&shape_))
      return planeIntersect(*plane, ray, tMin, tMax, hit);
    return std::visit([&](const auto& s) { return s.intersect(ray, tMin, tMax, hit); }, shape_);
  }
  // The object-space direction is deliberately not normalised, so t is the same in both spaces.
  const Ray objectRay = objectRayOf(*worldFromObject_, ray);
  if (!std::visit([&](const auto& s) { return s.intersect(objectRay, tMin, tMax, hit); }, shape_))
    return false;
  hit.normal = normalize((*worldFromObject_)(hit.normal));
  const Point3 objectPoint = hit.point;
  hit.point = (*worldFromObject_)(objectPoint);
  hit.pointError = worldPointError(*worldFromObject_, objectPoint, hit.pointError, hit.point);
  return true;
}

bool Primitive::intersectDeferred(const Ray& ray, double tMin, double tMax, ShapeHit& hit,
                                  bool& complete) const {
  if (const auto* plane = std::get_if<Plane>(&shape_); plane && !worldFromObject_) {
    complete = false;
    return planeCrossing(plane->point, plane->normal, ray, tMin, tMax, hit.t);
  }
  complete = true;
  return intersect(ray, tMin, tMax, hit);
}

void Primitive::completeHit(const Ray& ray, ShapeHit& hit) const {
  // Only an untransformed plane defers (intersectDeferred).
  planeCompleteHit(std::get<Plane>(shape_), ray, hit);
}

int Primitive::crossings(const Ray& ray, double tMin, double tMax) const {
  // Untransformed (the common case): the shape reads the caller's ray, no copy.
  if (!worldFromObject_) {
    if (const auto* sphere = std::get_if<Sphere>(&shape_))
      return quadric::sphereCrossings(sphere->center, sphere->radius, ray, tMin, tMax);
    if (const auto* plane = std::get_if<Plane>(&shape_))
      return planeCrossings(*plane, ray, tMin, tMax);
    return std::visit([&](const auto& s) { return s.crossings(ray, tMin, tMax); }, shape_);
  }
  const Ray objectRay = objectRayOf(*worldFromObject_, ray);
  return std::visit([&](const auto& s) { return s.crossings(objectRay, tMin, tMax); }, shape_);
}

std::uint32_t Primitive::materialIndexAt(std::uint32_t part) const {
  const Csg* c = csg();
  return c != nullptr ? c->tree->operands[part].materialIndex : materialIndex_;
}

const Color& Primitive::emissionAt(std::uint32_t part) const {
  const Csg* c = csg();
  return c != nullptr ? c->tree->operands[part].emission : emission_;
}

Color Primitive::csgTransmittance(const Ray& ray, double tMin, double tMax) const {
  const Csg& c = std::get<Csg>(shape_);
  return worldFromObject_
             ? glint::csgTransmittance(c, objectRayOf(*worldFromObject_, ray), tMin, tMax)
             : glint::csgTransmittance(c, ray, tMin, tMax);
}

}  // namespace glint
