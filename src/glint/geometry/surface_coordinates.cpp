// Per-shape (u, v) parameterisations (DESIGN.md §9 and the conventions in surface_coordinates.h)
// and the mesh tangent frames.
#include "glint/geometry/surface_coordinates.h"

#include "glint/geometry/csg.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <variant>

namespace glint {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// An arbitrary pair of in-plane directions, when a surface's own derivatives are degenerate.
void fallbackAxes(const Vec3& n, Vec3& dpdu, Vec3& dpdv) {
  const double len = length(n);
  if (!(len > 0)) {
    dpdu = {1, 0, 0};
    dpdv = {0, 1, 0};
    return;
  }
  orthonormalBasis(n / len, dpdu, dpdv);
}

SurfaceCoordinates withFrame(Point2 uv, const Vec3& dpdu, const Vec3& dpdv, const Vec3& dndu = {},
                             const Vec3& dndv = {}) {
  return {uv, dpdu, dpdv, dndu, dndv, dpdu, dpdv};
}

// (u, v) over the bounding rectangle, in planeAxes of n, of the points `corners`.
SurfaceCoordinates boundingRectangle(const Normal3& n, const Point3* corners, std::size_t count,
                                     const Point3& p) {
  Vec3 uAxis;
  Vec3 vAxis;
  planeAxes(toVec(n), uAxis, vAxis);
  double uLo = std::numeric_limits<double>::infinity();
  double vLo = uLo;
  double uHi = -uLo;
  double vHi = -uLo;
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 c = toVec(corners[i]);
    uLo = std::min(uLo, dot(c, uAxis));
    uHi = std::max(uHi, dot(c, uAxis));
    vLo = std::min(vLo, dot(c, vAxis));
    vHi = std::max(vHi, dot(c, vAxis));
  }
  const double du = std::max(uHi - uLo, std::numeric_limits<double>::min());
  const double dv = std::max(vHi - vLo, std::numeric_limits<double>::min());
  const Vec3 q = toVec(p);
  return withFrame({(dot(q, uAxis) - uLo) / du, (dot(q, vAxis) - vLo) / dv}, uAxis * du,
                   vAxis * dv);
}

// A disk of `radius` around `center` facing n, inscribed in [0, 1]².
SurfaceCoordinates diskCoordinates(const Point3& center, const Vec3& n, double radius,
                                   const Point3& p) {
  Vec3 uAxis;
  Vec3 vAxis;
  planeAxes(n, uAxis, vAxis);
  const Vec3 q = p - center;
  const double size = 2 * radius;
  return withFrame({0.5 + dot(q, uAxis) / size, 0.5 + dot(q, vAxis) / size}, uAxis * size,
                   vAxis * size);
}

// The side of a tube or cylinder: u the angle about the unit axis, v = `along` (already scaled);
// dpdv = axis · vScale.
SurfaceCoordinates sideCoordinates(const Point3& origin, const Vec3& axis, double radius,
                                   const Point3& p, double vScale) {
  // planeAxes gives e2 = axis × e1: seen from the axis' tip, the angle grows counter-clockwise
  // from e1 toward e2.
  Vec3 e1;
  Vec3 e2;
  planeAxes(axis, e1, e2);
  const Vec3 q = p - origin;
  const double along = dot(q, axis);
  const double x = dot(q, e1);
  const double y = dot(q, e2);
  double phi = std::atan2(y, x);
  if (phi < 0) phi += kTwoPi;
  const Vec3 around = e2 * std::cos(phi) - e1 * std::sin(phi);  // unit, direction of +phi
  const Vec3 dpdu = around * (kTwoPi * radius);
  return withFrame({phi / kTwoPi, along / vScale}, dpdu, axis * vScale, dpdu / radius, Vec3{});
}

SurfaceCoordinates sphereCoordinates(const Sphere& s, const Point3& p) {
  Vec3 d = (p - s.center) / s.radius;
  const double len = length(d);
  if (len > 0) d = d / len;
  const double u = 0.5 + std::atan2(d.x, -d.z) / kTwoPi;
  const double v = 1 - std::acos(std::clamp(d.y, -1.0, 1.0)) / std::numbers::pi;
  const double r = s.radius;
  const double sinTheta = std::sqrt(d.x * d.x + d.z * d.z);
  Vec3 dpdu;
  Vec3 dpdv;
  if (sinTheta > 1e-12) {
    // d = (sinθ sinφ, cosθ, −sinθ cosφ) with φ = 2π(u − 0.5), θ = π(1 − v).
    dpdu = Vec3{-d.z, 0, d.x} * (kTwoPi * r);
    dpdv = Vec3{-d.y * d.x / sinTheta, sinTheta, -d.y * d.z / sinTheta} * (std::numbers::pi * r);
  } else {
    fallbackAxes(d, dpdu, dpdv);  // a pole: every direction is "east"
  }
  return withFrame({u, v}, dpdu, dpdv, dpdu / r, dpdv / r);
}

SurfaceCoordinates triangleCoordinates(const Point3& v0, const Point3& v1, const Point3& v2,
                                       const Point3& p, double& b1, double& b2) {
  const Vec3 e1 = v1 - v0;
  const Vec3 e2 = v2 - v0;
  const Vec3 q = p - v0;
  const double d00 = dot(e1, e1);
  const double d01 = dot(e1, e2);
  const double d11 = dot(e2, e2);
  const double d20 = dot(q, e1);
  const double d21 = dot(q, e2);
  const double det = d00 * d11 - d01 * d01;
  b1 = det != 0 ? (d11 * d20 - d01 * d21) / det : 0;
  b2 = det != 0 ? (d00 * d21 - d01 * d20) / det : 0;
  return withFrame({b1, b2}, e1, e2);
}

SurfaceCoordinates boxCoordinates(const Box& box, const Point3& p) {
  // The face: the axis along which p is nearest a face, relative to the box's size.
  int axis = 0;
  bool high = false;
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double size = box.hi[k] - box.lo[k];
    const double toLo = std::abs(p[k] - box.lo[k]) / size;
    const double toHi = std::abs(p[k] - box.hi[k]) / size;
    if (toLo < best) best = toLo, axis = k, high = false;
    if (toHi < best) best = toHi, axis = k, high = true;
  }
  Vec3 n;
  n[axis] = high ? 1 : -1;
  const Point3 corners[2] = {box.lo, box.hi};
  return boundingRectangle(Normal3(n), corners, 2, p);
}

SurfaceCoordinates cylinderCoordinates(const Cylinder& c, const Point3& p) {
  const Vec3 q = p - c.base;
  const double along = dot(q, c.axis);
  const double radial = length(q - c.axis * along);
  const double toSide = std::abs(radial - c.radius);
  const double toBase = std::abs(along);
  const double toTop = std::abs(along - c.height);
  if (toSide <= std::min(toBase, toTop)) {
    return sideCoordinates(c.base, c.axis, c.radius, p, c.height);
  }
  if (toBase < toTop) return diskCoordinates(c.base, -c.axis, c.radius, p);
  return diskCoordinates(c.base + c.axis * c.height, c.axis, c.radius, p);
}

}  // namespace

void planeAxes(const Vec3& n, Vec3& uAxis, Vec3& vAxis) {
  const Vec3 h = std::abs(n.y) < 0.999 ? Vec3{0, 1, 0} : Vec3{0, 0, -1};
  uAxis = normalize(cross(h, n));
  vAxis = cross(n, uAxis);
}

SurfaceCoordinates surfaceCoordinates(const Shape& shape, const Point3& p, std::uint32_t part) {
  if (const auto* s = std::get_if<Csg>(&shape)) return csgSurfaceCoordinates(*s, part, p);
  if (const auto* s = std::get_if<Sphere>(&shape)) return sphereCoordinates(*s, p);
  if (const auto* s = std::get_if<Plane>(&shape)) {
    Vec3 uAxis;
    Vec3 vAxis;
    planeAxes(toVec(s->normal), uAxis, vAxis);
    const Vec3 q = p - s->point;
    return withFrame({dot(q, uAxis), dot(q, vAxis)}, uAxis, vAxis);
  }
  if (const auto* s = std::get_if<Triangle>(&shape)) {
    double b1 = 0;
    double b2 = 0;
    return triangleCoordinates(s->v0, s->v1, s->v2, p, b1, b2);
  }
  if (const auto* s = std::get_if<Polygon>(&shape)) {
    return boundingRectangle(s->normal, s->vertices.data(), s->vertices.size(), p);
  }
  if (const auto* s = std::get_if<Rectangle>(&shape)) {
    const Vec3 q = p - s->corner;
    return withFrame(
        {dot(q, s->edge0) / lengthSquared(s->edge0), dot(q, s->edge1) / lengthSquared(s->edge1)},
        s->edge0, s->edge1);
  }
  if (const auto* s = std::get_if<Quadrangle>(&shape)) {
    return boundingRectangle(s->normal, s->corners.data(), s->corners.size(), p);
  }
  if (const auto* s = std::get_if<Tube>(&shape)) {
    return sideCoordinates(s->origin, s->axis, s->radius, p, 1);
  }
  if (const auto* s = std::get_if<Cylinder>(&shape)) return cylinderCoordinates(*s, p);
  if (const auto* s = std::get_if<Box>(&shape)) return boxCoordinates(*s, p);
  const Disk& disk = std::get<Disk>(shape);
  return diskCoordinates(disk.center, toVec(disk.normal), disk.radius, p);
}

SurfaceCoordinates surfaceCoordinates(const TriangleMesh& mesh, std::uint32_t triangle,
                                      const Point3& p) {
  const std::uint32_t* index = mesh.indices.data() + 3 * static_cast<std::size_t>(triangle);
  const Point3& p0 = mesh.positions[index[0]];
  const Point3& p1 = mesh.positions[index[1]];
  const Point3& p2 = mesh.positions[index[2]];
  double b1 = 0;
  double b2 = 0;
  SurfaceCoordinates out = triangleCoordinates(p0, p1, p2, p, b1, b2);
  const double b0 = 1 - b1 - b2;
  if (!mesh.uvs.empty()) {
    const Point2& t0 = mesh.uvs[index[0]];
    const Point2& t1 = mesh.uvs[index[1]];
    const Point2& t2 = mesh.uvs[index[2]];
    out.uv = {b0 * t0.x + b1 * t1.x + b2 * t2.x, b0 * t0.y + b1 * t1.y + b2 * t2.y};
    // Solve [dp02 dp12] = [dpdu dpdv]·[duv02 duv12] (pbrt's triangle derivatives).
    const double du02 = t0.x - t2.x;
    const double dv02 = t0.y - t2.y;
    const double du12 = t1.x - t2.x;
    const double dv12 = t1.y - t2.y;
    const double det = du02 * dv12 - dv02 * du12;
    const Vec3 dp02 = p0 - p2;
    const Vec3 dp12 = p1 - p2;
    const Vec3 dpdu = (dp02 * dv12 - dp12 * dv02) / det;
    const Vec3 dpdv = (dp12 * du02 - dp02 * du12) / det;
    if (std::abs(det) > 1e-20 && isFinite(dpdu) && isFinite(dpdv) &&
        lengthSquared(cross(dpdu, dpdv)) > 0) {
      out.dpdu = out.tangent = dpdu;
      out.dpdv = out.bitangent = dpdv;
      if (!mesh.normals.empty()) {
        const Vec3 dn02 = toVec(mesh.normals[index[0]]) - toVec(mesh.normals[index[2]]);
        const Vec3 dn12 = toVec(mesh.normals[index[1]]) - toVec(mesh.normals[index[2]]);
        out.dndu = (dn02 * dv12 - dn12 * dv02) / det;
        out.dndv = (dn12 * du02 - dn02 * du12) / det;
      }
    } else {
      fallbackAxes(cross(p1 - p0, p2 - p0), out.dpdu, out.dpdv);
      out.tangent = out.dpdu;
      out.bitangent = out.dpdv;
    }
  }
  if (!mesh.tangents.empty()) {
    const VertexTangent& a = mesh.tangents[index[0]];
    const VertexTangent& b = mesh.tangents[index[1]];
    const VertexTangent& c = mesh.tangents[index[2]];
    const Vec3 t = a.direction * b0 + b.direction * b1 + c.direction * b2;
    if (lengthSquared(t) > 0) {
      out.tangent = t;
      const Vec3 n = mesh.normals.empty()
                         ? cross(p1 - p0, p2 - p0)
                         : toVec(mesh.normals[index[0]]) * b0 + toVec(mesh.normals[index[1]]) * b1 +
                               toVec(mesh.normals[index[2]]) * b2;
      out.bitangent = cross(n, t) * (a.sign < 0 ? -1.0 : 1.0);
    }
  }
  return out;
}

void computeMeshTangents(TriangleMesh& mesh) {
  if (mesh.uvs.empty() || mesh.normals.empty()) return;
  std::vector<Vec3> tangentSum(mesh.positions.size());
  std::vector<Vec3> bitangentSum(mesh.positions.size());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const std::uint32_t* index = mesh.indices.data() + 3 * t;
    const Point3& p0 = mesh.positions[index[0]];
    const Point3& p1 = mesh.positions[index[1]];
    const Point3& p2 = mesh.positions[index[2]];
    const SurfaceCoordinates frame = surfaceCoordinates(mesh, static_cast<std::uint32_t>(t), p0);
    for (int k = 0; k < 3; ++k) {
      // The corner angle weights the triangle's share, as MikkTSpace does.
      const Point3& here = k == 0 ? p0 : (k == 1 ? p1 : p2);
      const Point3& next = k == 0 ? p1 : (k == 1 ? p2 : p0);
      const Point3& prev = k == 0 ? p2 : (k == 1 ? p0 : p1);
      const Vec3 a = next - here;
      const Vec3 b = prev - here;
      const double denominator = length(a) * length(b);
      const double angle =
          denominator > 0 ? std::acos(std::clamp(dot(a, b) / denominator, -1.0, 1.0)) : 0;
      const double lu = length(frame.dpdu);
      const double lv = length(frame.dpdv);
      if (!(lu > 0) || !(lv > 0) || !std::isfinite(angle)) continue;
      tangentSum[index[k]] += frame.dpdu * (angle / lu);
      bitangentSum[index[k]] += frame.dpdv * (angle / lv);
    }
  }
  mesh.tangents.resize(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3 n = toVec(mesh.normals[v]);
    Vec3 t = tangentSum[v] - n * dot(n, tangentSum[v]);
    if (!(lengthSquared(t) > 0)) {
      Vec3 unused;
      orthonormalBasis(n, t, unused);
    }
    t = normalize(t);
    mesh.tangents[v] = {t, dot(cross(n, t), bitangentSum[v]) < 0 ? -1.0 : 1.0};
  }
}

}  // namespace glint
