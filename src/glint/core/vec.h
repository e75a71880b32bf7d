// Distinct 3D vector, point and normal types (double precision) and the algebra allowed between
// them.
#pragma once

#include <algorithm>
#include <cmath>

namespace glint {

// The seed's Coordinate is a plain double; its Point2D is Point2.
struct Point2 {
  double x = 0;
  double y = 0;
};

// A displacement or direction. Any length unless a function says "unit".
struct Vec3 {
  double x = 0;
  double y = 0;
  double z = 0;

  constexpr double operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr double& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3& operator+=(const Vec3& v) {
    x += v.x;
    y += v.y;
    z += v.z;
    return *this;
  }
  constexpr Vec3& operator-=(const Vec3& v) {
    x -= v.x;
    y -= v.y;
    z -= v.z;
    return *this;
  }
  constexpr Vec3& operator*=(double s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  friend constexpr bool operator==(const Vec3&, const Vec3&) = default;
};

// A position in space. Points subtract to vectors and move by vectors; they do not add together.
struct Point3 {
  double x = 0;
  double y = 0;
  double z = 0;

  constexpr double operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr double& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr Point3& operator+=(const Vec3& v) {
    x += v.x;
    y += v.y;
    z += v.z;
    return *this;
  }
  constexpr Point3& operator-=(const Vec3& v) {
    x -= v.x;
    y -= v.y;
    z -= v.z;
    return *this;
  }
  friend constexpr bool operator==(const Point3&, const Point3&) = default;
};

// A surface normal. Kept apart from Vec3 because transforms map normals by the inverse transpose.
struct Normal3 {
  double x = 0;
  double y = 0;
  double z = 0;

  constexpr Normal3() = default;
  constexpr Normal3(double nx, double ny, double nz) : x(nx), y(ny), z(nz) {}
  constexpr explicit Normal3(const Vec3& v) : x(v.x), y(v.y), z(v.z) {}
  constexpr double operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr Normal3 operator-() const { return {-x, -y, -z}; }
  friend constexpr bool operator==(const Normal3&, const Normal3&) = default;
};

// --- Vec3 algebra ---
constexpr Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr Vec3 operator*(const Vec3& v, double s) { return {v.x * s, v.y * s, v.z * s}; }
constexpr Vec3 operator*(double s, const Vec3& v) { return {v.x * s, v.y * s, v.z * s}; }
constexpr Vec3 operator/(const Vec3& v, double s) { return {v.x / s, v.y / s, v.z / s}; }
constexpr double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr double lengthSquared(const Vec3& v) { return dot(v, v); }
inline double length(const Vec3& v) { return std::sqrt(dot(v, v)); }
// Unit vector along v. v must be non-zero (callers validate scene input before normalising).
inline Vec3 normalize(const Vec3& v) { return v / length(v); }
constexpr Vec3 abs(const Vec3& v) { return {std::abs(v.x), std::abs(v.y), std::abs(v.z)}; }
constexpr double maxComponent(const Vec3& v) { return std::max({v.x, v.y, v.z}); }
inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// --- Point3 algebra ---
constexpr Point3 operator+(const Point3& p, const Vec3& v) {
  return {p.x + v.x, p.y + v.y, p.z + v.z};
}
constexpr Point3 operator-(const Point3& p, const Vec3& v) {
  return {p.x - v.x, p.y - v.y, p.z - v.z};
}
constexpr Vec3 operator-(const Point3& a, const Point3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
constexpr Vec3 toVec(const Point3& p) { return {p.x, p.y, p.z}; }
constexpr Point3 toPoint(const Vec3& v) { return {v.x, v.y, v.z}; }
inline double distance(const Point3& a, const Point3& b) { return length(a - b); }
constexpr double distanceSquared(const Point3& a, const Point3& b) { return lengthSquared(a - b); }
constexpr Point3 min(const Point3& a, const Point3& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Point3 max(const Point3& a, const Point3& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline bool isFinite(const Point3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// --- Normal3 algebra ---
constexpr Vec3 toVec(const Normal3& n) { return {n.x, n.y, n.z}; }
constexpr double dot(const Normal3& n, const Vec3& v) { return n.x * v.x + n.y * v.y + n.z * v.z; }
constexpr double dot(const Vec3& v, const Normal3& n) { return dot(n, v); }
constexpr Normal3 operator*(const Normal3& n, double s) { return {n.x * s, n.y * s, n.z * s}; }
inline Normal3 normalize(const Normal3& n) { return Normal3(normalize(toVec(n))); }
inline double length(const Normal3& n) { return length(toVec(n)); }

// Builds a right-handed orthonormal basis (u, v, w) with w = the given unit vector
// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
inline void orthonormalBasis(const Vec3& w, Vec3& u, Vec3& v) {
  const double sign = std::copysign(1.0, w.z);
  const double a = -1.0 / (sign + w.z);
  const double b = w.x * w.y * a;
  u = {1.0 + sign * w.x * w.x * a, sign * b, -sign * w.x};
  v = {b, sign + w.y * w.y * a, -w.y};
}

}  // namespace glint
