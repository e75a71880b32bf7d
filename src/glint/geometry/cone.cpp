// The open cone frustum of shape.h (NFF's `c`, Tachyon's FCYLINDER): an exact quadric
// intersection in the cone's own frame, in the space of the ray passed in, in double precision.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "glint/core/spawn.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/watertight_triangle.h"

namespace glint {
namespace {

std::string format(const Point3& p) { return fmt::format("[{}, {}, {}]", p.x, p.y, p.z); }

void requireFinitePoint(const char* name, const Point3& p) {
  if (!isFinite(p))
    throw ShapeError(name, fmt::format("{} must be finite, got {}", name, format(p)));
}

void requireRadius(const char* name, double r) {
  if (!std::isfinite(r)) throw ShapeError(name, fmt::format("{} must be finite, got {}", name, r));
  if (!(r >= 0)) throw ShapeError(name, fmt::format("{} must be >= 0, got {}", name, r));
}

// Exact bounds of a circle (centre c, unit normal n, radius r), as for a disk.
Bounds3 circleBounds(const Point3& c, const Vec3& n, double r) {
  const Vec3 half{r * std::sqrt(n.y * n.y + n.z * n.z), r * std::sqrt(n.z * n.z + n.x * n.x),
                  r * std::sqrt(n.x * n.x + n.y * n.y)};
  return Bounds3(c - half, c + half);
}

// The roots of the cone's quadric along a ray, and where along the ray they were solved from.
// With f = o − base split into its axial part fa and its part across the axis fp (likewise d into
// da, dp), and the radius along the ray R(t) = (r0 + k·fa) + t·k·da (k = (r1 − r0)/height), the
// ray meets the infinite double cone where |fp + t·dp|² = R(t)²:
//   A t² + 2B t + C = 0,  A = dp·dp − (k·da)²,  B = fp·dp − R0·k·da,  C = fp·fp − R0².
// The ray origin is first moved along the ray to its closest approach to the frustum's centre (as
// Ray Tracing Gems ch. 7 does for spheres), so that a distant origin does not cancel the
// coefficients; the roots are then solved with q = −(B + sign(B)·√(B² − AC)) (t = q/A, C/q).
struct ConeRoots {
  double t[2] = {0, 0};
  int count = 0;
};

ConeRoots coneRoots(const Cone& cone, const Ray& ray) {
  ConeRoots roots;
  const Vec3& d = ray.direction;
  const double dd = dot(d, d);
  const Point3 middle = cone.base + cone.axis * (cone.height / 2);
  const double shift = dot(middle - ray.origin, d) / dd;
  const Vec3 f = (ray.origin - cone.base) + d * shift;
  const double k = (cone.apexRadius - cone.baseRadius) / cone.height;
  const double fa = dot(f, cone.axis);
  const double da = dot(d, cone.axis);
  const Vec3 fp = f - cone.axis * fa;
  const Vec3 dp = d - cone.axis * da;
  const double r0 = cone.baseRadius + k * fa;
  const double rd = k * da;
  const double a = dot(dp, dp) - rd * rd;
  const double b = dot(fp, dp) - r0 * rd;
  const double c = dot(fp, fp) - r0 * r0;
  const auto add = [&](double t) {
    const double s = fa + t * da;  // along the axis from the base
    if (s >= 0 && s <= cone.height && std::isfinite(t)) roots.t[roots.count++] = t + shift;
  };
  // A ray along the axis of a cylinder (a = 0 and b = 0) never crosses the side; a ray parallel to
  // a generator line of a cone (a ≈ 0) crosses the infinite cone once.
  if (std::abs(a) <= kParallelBound * dd) {
    if (std::abs(b) > 0) add(-c / (2 * b));
    return roots;
  }
  const double discriminant = b * b - a * c;
  if (!(discriminant > 0)) return roots;  // a tangent line touches without crossing
  const double q = -(b + std::copysign(std::sqrt(discriminant), b));
  double t0 = q / a;
  double t1 = c / q;
  if (t0 > t1) std::swap(t0, t1);
  add(t0);
  add(t1);
  return roots;
}

bool inOpenRange(double t, double tMin, double tMax) { return t > tMin && t < tMax; }

}  // namespace

Vec3 coneReference(const Vec3& axis) {
  const Vec3 seed = std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  return normalize(seed - axis * dot(seed, axis));
}

Cone Cone::make(const Point3& base, double baseRadius, const Point3& apex, double apexRadius) {
  requireFinitePoint("base", base);
  requireFinitePoint("apex", apex);
  requireRadius("base_radius", baseRadius);
  requireRadius("apex_radius", apexRadius);
  if (baseRadius == 0 && apexRadius == 0) {
    throw ShapeError("base_radius", "base_radius and apex_radius are both 0 (a line, not a cone)");
  }
  const Vec3 axis = apex - base;
  const double height = length(axis);
  // The same relative bound as a collinear triangle: a cone shorter than 1e-12 of its radius is a
  // flat ring, which the quadric cannot describe.
  if (!(height >
        kCollinearTolerance * std::max({baseRadius, apexRadius, maxComponent(abs(axis))})) ||
      !std::isfinite(height)) {
    throw ShapeError(
        "apex", base == apex
                    ? fmt::format("apex must differ from base, got {} for both", format(apex))
                    : fmt::format("apex is {:g} from base, too short for radii {:g} and {:g} (the "
                                  "cone would be a flat ring; its height must exceed 1e-12 of its "
                                  "radius)",
                                  height, baseRadius, apexRadius));
  }
  return Cone{base, axis / height, height, baseRadius, apexRadius};
}

bool Cone::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  const ConeRoots roots = coneRoots(*this, ray);
  for (int i = 0; i < roots.count; ++i) {
    const double t = roots.t[i];
    if (!inOpenRange(t, tMin, tMax)) continue;
    // The hit moved onto the surface: radially to the radius at its height, the height kept
    // within the frustum.
    const Vec3 rel = ray.origin - base + ray.direction * t;
    const double s = std::clamp(dot(rel, axis), 0.0, height);
    const Vec3 radial = rel - axis * dot(rel, axis);
    const double r = baseRadius + (apexRadius - baseRadius) * (s / height);
    const double radialLength = length(radial);
    const Vec3 onSurface = axis * s + (radialLength > 0 ? radial * (r / radialLength) : Vec3{});
    hit.t = t;
    hit.normal = normalAt(base + onSurface);
    hit.point = base + onSurface;
    // Splitting rel into its axial and radial parts, rescaling and adding the base back costs a
    // few ulps of |rel|, the radii and |point| (as for a tube's side); the root solve from a
    // spawned point decides its side with errors of the same magnitudes.
    hit.pointError = abs(toVec(hit.point)) * gammaBound(3) +
                     Vec3{1, 1, 1} * (gammaBound(64) * (maxComponent(abs(onSurface)) + height +
                                                        std::max(baseRadius, apexRadius)));
    return true;
  }
  return false;
}

int Cone::crossings(const Ray& ray, double tMin, double tMax) const {
  const ConeRoots roots = coneRoots(*this, ray);
  int n = 0;
  for (int i = 0; i < roots.count; ++i) n += inOpenRange(roots.t[i], tMin, tMax) ? 1 : 0;
  return n;
}

Bounds3 Cone::bounds() const {
  return unite(circleBounds(base, axis, baseRadius),
               circleBounds(base + axis * height, axis, apexRadius));
}

// The gradient of |q⊥|² − r(s)²: q⊥ − r·k·axis, i.e. the unit radial direction tilted by the
// slope k = (r1 − r0)/height; on the axis (an apex of radius 0) the axis direction it tilts to.
Normal3 Cone::normalAt(const Point3& p) const {
  const Vec3 rel = p - base;
  const Vec3 radial = rel - axis * dot(rel, axis);
  const double k = (apexRadius - baseRadius) / height;
  const double radialLength = length(radial);
  if (!(radialLength > 0)) return Normal3(k > 0 ? -axis : axis);
  return Normal3(normalize(radial / radialLength - axis * k));
}

Point2 Cone::uvAt(const Point3& p) const {
  const Vec3 rel = p - base;
  const Vec3 reference = coneReference(axis);
  const Vec3 across = cross(axis, reference);
  double phi = std::atan2(dot(rel, across), dot(rel, reference));
  if (phi < 0) phi += 2 * std::numbers::pi;
  return Point2{phi / (2 * std::numbers::pi), std::clamp(dot(rel, axis) / height, 0.0, 1.0)};
}

}  // namespace glint
