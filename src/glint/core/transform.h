// Affine transforms (4×4 matrices with their inverses) applied to points, vectors, normals, rays
// and bounds. Named destination-from-source: worldFromObject maps object-space coordinates to world
// space.
#pragma once

#include <array>
#include <stdexcept>
#include <string>

#include "glint/core/bounds.h"
#include "glint/core/ray.h"
#include "glint/core/vec.h"

namespace glint {

// Row-major 4×4 matrix acting on column vectors: p' = M·p.
struct Matrix4 {
  std::array<std::array<double, 4>, 4> m{};

  static constexpr Matrix4 identity() {
    Matrix4 r;
    for (int i = 0; i < 4; ++i) r.m[i][i] = 1;
    return r;
  }
  friend constexpr bool operator==(const Matrix4&, const Matrix4&) = default;
};

Matrix4 operator*(const Matrix4& a, const Matrix4& b);
Matrix4 transpose(const Matrix4& a);
// Inverse by Gauss–Jordan elimination with partial pivoting. Throws std::invalid_argument when the
// matrix is singular (e.g. a zero scale).
Matrix4 inverse(const Matrix4& a);

// Thrown for invalid transform parameters (zero scale, zero-length rotation axis).
class TransformError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// An invertible affine transform. The inverse is kept alongside so applying either is one product.
class Transform {
 public:
  Transform() = default;  // identity
  Transform(const Matrix4& matrix, const Matrix4& inverseMatrix)
      : m_(matrix), mInv_(inverseMatrix) {}
  explicit Transform(const Matrix4& matrix) : m_(matrix), mInv_(glint::inverse(matrix)) {}

  static Transform translate(const Vec3& delta);
  // Non-uniform scale; every factor must be non-zero (throws TransformError otherwise).
  static Transform scale(double sx, double sy, double sz);
  // Rotation by angleDegrees about a non-zero axis through the origin, right-handed (Rodrigues).
  static Transform rotate(const Vec3& axis, double angleDegrees);

  const Matrix4& matrix() const { return m_; }
  const Matrix4& inverseMatrix() const { return mInv_; }
  Transform inverse() const { return Transform(mInv_, m_); }
  bool isIdentity() const { return m_ == Matrix4::identity(); }

  Point3 operator()(const Point3& p) const;
  Vec3 operator()(const Vec3& v) const;
  // Normals map by the inverse transpose so they stay perpendicular to transformed surfaces.
  // The result is not normalised.
  Normal3 operator()(const Normal3& n) const;
  // Maps origin and direction; the direction is not normalised, so t values are preserved.
  Ray operator()(const Ray& r) const;
  // Bounds of the eight transformed corners; unbounded stays unbounded.
  Bounds3 operator()(const Bounds3& b) const;

  // Composition: (a * b)(p) = a(b(p)) — b is applied first.
  friend Transform operator*(const Transform& a, const Transform& b) {
    return Transform(a.m_ * b.m_, b.mInv_ * a.mInv_);
  }

 private:
  Matrix4 m_ = Matrix4::identity();
  Matrix4 mInv_ = Matrix4::identity();
};

}  // namespace glint
