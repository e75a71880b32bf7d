// The closed set of analytic shapes (the seed's Geometry family and DESIGN.md §5), dispatched
// through std::variant: no virtual call and no allocation per ray.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "glint/core/bounds.h"
#include "glint/core/color.h"
#include "glint/core/ray.h"
#include "glint/core/transform.h"
#include "glint/core/vec.h"

namespace glint {

// Thrown when a shape is built from invalid parameters: which parameter (the scene key, e.g.
// "vertices", "radius", "transform") and what() why, e.g. "vertices are collinear: ...". The scene
// builder reports it at that parameter's file:line:col.
class ShapeError : public std::invalid_argument {
 public:
  ShapeError(std::string parameter, const std::string& message)
      : std::invalid_argument(message), parameter_(std::move(parameter)) {}
  const std::string& parameter() const { return parameter_; }

 private:
  std::string parameter_;
};

// The largest finite |coordinate| of a box (the infinite ones of an unbounded shape left out; a
// bounded shape's box is infinite only past checks that come first: a point past kMaxCoordinate,
// a transform whose determinant overflows).
double reachOf(const Bounds3& bounds);

// "reaches 2e+155 from the origin, beyond the ±1e+100 glint computes in (...)": the reason an
// object past kMaxCoordinate (core/bounds.h) is refused.
std::string beyondReach(double reach);

// Closest-hit result of one shape, in the space of the ray that was passed in.
struct ShapeHit {
  double t = 0;    // ray parameter of the hit, tMin < t < tMax
  Normal3 normal;  // unit geometric normal as the shape defines it (never flipped toward the ray)
  // The hit point, reprojected onto the surface (not ray.at(t), whose error grows with the ray's
  // origin and length), and a per-coordinate bound on its rounding error: the exact surface passes
  // through the box point ± pointError. Both in the space of the ray. For spawnRay (core/spawn.h).
  Point3 point;
  Vec3 pointError;
  // On a csg: the operand shape hit (an index into its CsgTree::operands), for its material and
  // surface coordinates. Not set by other shapes: read it only for a hit on a Csg.
  std::uint32_t part = 0;
};

// Conventions shared by every shape below:
// - intersect(ray, tMin, tMax, hit): closest hit with tMin < t < tMax (both bounds exclusive), for
// any
//   non-zero ray direction. A ray that starts exactly on the surface and leaves it does not hit it
//   at t = 0; a tangent ray (touching at a single point) misses; a ray parallel to a flat shape
//   misses.
// - crossings(ray, tMin, tMax): how many times the ray crosses the surface in (tMin, tMax) — used
// for
//   shadow transmittance, where a transparent sphere in the way counts twice.
// - bounds(): world-space box; unbounded shapes (plane, tube) return Bounds3::unbounded().
// - normalAt(p): unit geometric normal at a point p on the surface (the seed's getNormal).
// - Closed shapes (sphere, tube, cylinder, box) have outward normals; flat shapes have the normal
// of
//   their definition (plane, disk: as given; triangle, polygon, quadrangle: (v1−v0)×(v2−v0) by the
//   right-hand rule over the vertex order; rectangle: edge0 × edge1).
// - Each shape has a static make(...) factory that validates its parameters and throws ShapeError.

struct Sphere {
  Point3 center;
  double radius = 1;
  static Sphere make(const Point3& center, double radius);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Infinite plane through `point` with unit `normal`.
struct Plane {
  Point3 point;
  Normal3 normal;
  static Plane make(const Point3& point, const Vec3& normal);
  // Plane through three non-collinear points; normal (b−a)×(c−a).
  static Plane fromPoints(const Point3& a, const Point3& b, const Point3& c);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Triangle with the watertight ray–triangle test of Woop, Benthin and Wald (2013): rays through a
// shared edge or vertex hit one of the triangles sharing it and never slip between them.
struct Triangle {
  Point3 v0, v1, v2;
  Normal3 normal;  // unit, (v1−v0)×(v2−v0)
  static Triangle make(const Point3& v0, const Point3& v1, const Point3& v2);  // rejects collinear
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Planar convex polygon with ≥ 3 vertices in order (either winding).
struct Polygon {
  std::vector<Point3> vertices;
  Normal3 normal;  // unit, by the right-hand rule over the vertex order
  static Polygon make(std::vector<Point3> vertices);  // rejects non-planar, non-convex, degenerate
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Rectangle: corner + s·edge0 + t·edge1 for s, t in [0, 1]; the edges must be perpendicular.
struct Rectangle {
  Point3 corner;
  Vec3 edge0, edge1;
  Normal3 normal;  // unit, edge0 × edge1
  static Rectangle make(const Point3& corner, const Vec3& edge0, const Vec3& edge1);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Planar quadrangle v0 v1 v2 v3 (in order, simple, need not be convex), split into two triangles
// along a diagonal that lies inside it. Stored compactly: the four vertices rotated so that the
// inner diagonal runs from corners[0] to corners[2]; the halves are (0, 1, 2) and (0, 2, 3), each
// intersected with the watertight triangle test.
struct Quadrangle {
  std::array<Point3, 4> corners;
  Normal3 normal;  // unit, by the right-hand rule over the vertex order
  static Quadrangle make(const Point3& v0, const Point3& v1, const Point3& v2, const Point3& v3);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Infinite cylinder of `radius` around the line origin + s·axis (axis unit).
struct Tube {
  Point3 origin;
  Vec3 axis;
  double radius = 1;
  static Tube make(const Point3& origin, const Vec3& axis, double radius);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Capped cylinder from `base` along unit `axis` for `height`; cap normals −axis at the base and
// +axis at the top, side normals radial.
struct Cylinder {
  Point3 base;
  Vec3 axis;
  double radius = 1;
  double height = 1;
  static Cylinder make(const Point3& base, const Vec3& axis, double radius, double height);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Axis-aligned box [lo, hi] with outward face normals (any box through `transform`).
struct Box {
  Point3 lo, hi;
  static Box make(const Point3& lo, const Point3& hi);  // requires lo < hi on every axis
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Flat disk of `radius` around `center`, facing unit `normal`; with innerRadius > 0 an annulus (a
// ring: the points at distance innerRadius..radius from the centre).
struct Disk {
  Point3 center;
  Normal3 normal;
  double radius = 1;
  double innerRadius = 0;  // 0 ≤ innerRadius < radius
  static Disk make(const Point3& center, const Vec3& normal, double radius, double innerRadius = 0);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
};

// Open cone frustum (no caps) from `base` to `apex` along unit `axis` (height |apex − base|), of
// radius baseRadius at the base and apexRadius at the apex (any two radii ≥ 0, not both 0; equal
// radii make an open cylinder). Intersected exactly as the quadric |q⊥|² = r(s)², s the distance
// along the axis from the base, r(s) linear, cut to 0 ≤ s ≤ height. Outward normals (away from the
// axis). Surface coordinates: u = φ/2π, φ the angle about the axis (right-handed) from
// coneReference(axis) (the projection of +x onto the plane across the axis, or of +y when the axis
// is along x), v = s/height (0 on the base rim, 1 on the apex rim). Implemented in cone.cpp.
struct Cone {
  Point3 base;
  Vec3 axis;  // unit, from base toward apex
  double height = 1;
  double baseRadius = 1;
  double apexRadius = 0;
  static Cone make(const Point3& base, double baseRadius, const Point3& apex, double apexRadius);
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  Normal3 normalAt(const Point3& p) const;
  Point2 uvAt(const Point3& p) const;
};

// The direction across a cone's unit axis from which its u coordinate is measured (see Cone).
Vec3 coneReference(const Vec3& axis);

struct CsgTree;  // csg.h

// Constructive solid geometry (DESIGN.md §11): the union, intersection or difference of closed
// shapes, nested freely, as one shape. csg.h builds the tree and implements the queries (crossings
// of every operand along the ray combined by the operations, Roth 1982); hits name the operand
// they are on in ShapeHit::part. Normals point out of the combined solid.
struct Csg {
  std::shared_ptr<const CsgTree> tree;
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const;
  // The normal of the surface that a short segment through p along x, y or z (the first that
  // crosses it) meets; (0, 0, 0) when none does (p is not on the surface).
  Normal3 normalAt(const Point3& p) const;
};

using Shape = std::variant<Sphere, Plane, Triangle, Polygon, Rectangle, Quadrangle, Tube, Cylinder,
                           Box, Disk, Cone, Csg>;

// A shape placed in the world, optionally through an affine transform (worldFromObject), with what
// the renderer needs to shade it. The seed's Geometry: shape + material + emission colour.
class Primitive {
 public:
  Primitive(Shape shape, std::uint32_t materialIndex, const Color& emission,
            std::optional<Transform> worldFromObject = std::nullopt);

  // World-space closest hit; the normal is transformed to world space and normalised.
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  // intersect in two steps, for a caller that may yet find a closer hit elsewhere: on a hit,
  // `complete` says whether hit is whole; when false only hit.t is set (an untransformed plane,
  // whose hit point is most of its cost), and completeHit(ray, hit) fills the rest, exactly as
  // intersect would have.
  bool intersectDeferred(const Ray& ray, double tMin, double tMax, ShapeHit& hit,
                         bool& complete) const;
  void completeHit(const Ray& ray, ShapeHit& hit) const;
  int crossings(const Ray& ray, double tMin, double tMax) const;
  Bounds3 bounds() const { return bounds_; }
  bool isBounded() const { return bounds_.isBounded(); }
  const Shape& shape() const { return shape_; }
  // Its transform, or null when the shape is already in world space.
  const Transform* worldFromObject() const { return worldFromObject_.get(); }
  std::uint32_t materialIndex() const { return materialIndex_; }
  const Color& emission() const { return emission_; }
  // The material and emission of the surface a hit is on: a csg operand's (ShapeHit::part), else
  // the primitive's own.
  std::uint32_t materialIndexAt(std::uint32_t part) const;
  const Color& emissionAt(std::uint32_t part) const;
  // The csg shape, or null.
  const Csg* csg() const { return std::get_if<Csg>(&shape_); }
  // For a csg: the product of its operands' transmission over every crossing of its surface in
  // (tMin, tMax) (csgTransmittance); the ray in world space.
  Color csgTransmittance(const Ray& ray, double tMin, double tMax) const;

 private:
  // What a ray query reads comes first. The transform lives out of line, shared between copies:
  // most primitives have none, and two inline 4×4 matrix pairs made a Primitive ~800 bytes.
  // Its inverse matrix is objectFromWorld, which maps rays; normals map by its transpose.
  Shape shape_;
  std::shared_ptr<const Transform> worldFromObject_;  // null: the shape is already in world space
  Bounds3 bounds_;
  Color emission_;
  std::uint32_t materialIndex_ = 0;
};

}  // namespace glint
