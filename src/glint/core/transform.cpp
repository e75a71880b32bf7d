#include "glint/core/transform.h"

#include <cmath>
#include <numbers>
#include <utility>

namespace glint {

Matrix4 operator*(const Matrix4& a, const Matrix4& b) {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += a.m[i][k] * b.m[k][j];
      r.m[i][j] = sum;
    }
  return r;
}

Matrix4 transpose(const Matrix4& a) {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = a.m[j][i];
  return r;
}

Matrix4 inverse(const Matrix4& a) {
  Matrix4 work = a;
  Matrix4 inv = Matrix4::identity();
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int row = col + 1; row < 4; ++row)
      if (std::abs(work.m[row][col]) > std::abs(work.m[pivot][col])) pivot = row;
    // Exact zero only: scene transforms are products of rotations, translations and validated
    // non-zero scales, so a tiny-but-non-zero pivot is a legitimate (tiny) scale.
    if (work.m[pivot][col] == 0) throw std::invalid_argument("matrix is singular");
    std::swap(work.m[pivot], work.m[col]);
    std::swap(inv.m[pivot], inv.m[col]);
    const double scale = 1.0 / work.m[col][col];
    for (int j = 0; j < 4; ++j) {
      work.m[col][j] *= scale;
      inv.m[col][j] *= scale;
    }
    for (int row = 0; row < 4; ++row) {
      if (row == col) continue;
      const double factor = work.m[row][col];
      if (factor == 0) continue;
      for (int j = 0; j < 4; ++j) {
        work.m[row][j] -= factor * work.m[col][j];
        inv.m[row][j] -= factor * inv.m[col][j];
      }
    }
  }
  return inv;
}

Transform Transform::translate(const Vec3& delta) {
  Matrix4 m = Matrix4::identity();
  Matrix4 inv = Matrix4::identity();
  m.m[0][3] = delta.x;
  m.m[1][3] = delta.y;
  m.m[2][3] = delta.z;
  inv.m[0][3] = -delta.x;
  inv.m[1][3] = -delta.y;
  inv.m[2][3] = -delta.z;
  return Transform(m, inv);
}

Transform Transform::scale(double sx, double sy, double sz) {
  if (sx == 0 || sy == 0 || sz == 0 || !std::isfinite(sx) || !std::isfinite(sy) ||
      !std::isfinite(sz))
    throw TransformError("scale factors must be finite and non-zero");
  Matrix4 m = Matrix4::identity();
  Matrix4 inv = Matrix4::identity();
  m.m[0][0] = sx;
  m.m[1][1] = sy;
  m.m[2][2] = sz;
  inv.m[0][0] = 1 / sx;
  inv.m[1][1] = 1 / sy;
  inv.m[2][2] = 1 / sz;
  return Transform(m, inv);
}

Transform Transform::rotate(const Vec3& axis, double angleDegrees) {
  const double len = length(axis);
  if (!(len > 0) || !std::isfinite(len)) throw TransformError("rotation axis must be non-zero");
  const Vec3 a = axis / len;
  const double theta = angleDegrees * std::numbers::pi / 180.0;
  const double s = std::sin(theta);
  const double c = std::cos(theta);
  // Rodrigues' rotation formula as a matrix.
  Matrix4 m = Matrix4::identity();
  m.m[0][0] = a.x * a.x + (1 - a.x * a.x) * c;
  m.m[0][1] = a.x * a.y * (1 - c) - a.z * s;
  m.m[0][2] = a.x * a.z * (1 - c) + a.y * s;
  m.m[1][0] = a.x * a.y * (1 - c) + a.z * s;
  m.m[1][1] = a.y * a.y + (1 - a.y * a.y) * c;
  m.m[1][2] = a.y * a.z * (1 - c) - a.x * s;
  m.m[2][0] = a.x * a.z * (1 - c) - a.y * s;
  m.m[2][1] = a.y * a.z * (1 - c) + a.x * s;
  m.m[2][2] = a.z * a.z + (1 - a.z * a.z) * c;
  // A rotation's inverse is its transpose.
  return Transform(m, transpose(m));
}

Point3 Transform::operator()(const Point3& p) const {
  const auto& m = m_.m;
  const double x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
  const double y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
  const double z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
  const double w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
  return w == 1 ? Point3{x, y, z} : Point3{x / w, y / w, z / w};
}

Vec3 Transform::operator()(const Vec3& v) const {
  const auto& m = m_.m;
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
          m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Normal3 Transform::operator()(const Normal3& n) const {
  const auto& mi = mInv_.m;  // (M^-1)^T applied: column i of M^-1 dotted with n
  return {mi[0][0] * n.x + mi[1][0] * n.y + mi[2][0] * n.z,
          mi[0][1] * n.x + mi[1][1] * n.y + mi[2][1] * n.z,
          mi[0][2] * n.x + mi[1][2] * n.y + mi[2][2] * n.z};
}

Ray Transform::operator()(const Ray& r) const {
  return Ray{(*this)(r.origin), (*this)(r.direction)};
}

Bounds3 Transform::operator()(const Bounds3& b) const {
  if (b.isEmpty()) return b;
  if (!b.isBounded()) return Bounds3::unbounded();
  Bounds3 result;
  for (int corner = 0; corner < 8; ++corner) {
    const Point3 p{(corner & 1) ? b.hi.x : b.lo.x, (corner & 2) ? b.hi.y : b.lo.y,
                   (corner & 4) ? b.hi.z : b.lo.z};
    result = unite(result, (*this)(p));
  }
  return result;
}

}  // namespace glint
