// Moving rays into a transformed shape's own space and its hit points back out, with their error
// bounds: what Primitive and the operands of a csg (csg.h) share.
#pragma once

#include <algorithm>
#include <cmath>

#include "glint/core/ray.h"
#include "glint/core/spawn.h"
#include "glint/core/transform.h"
#include "glint/core/vec.h"

namespace glint {

// Throws ShapeError("transform", ...) unless `transform` is affine with a finite, non-zero
// determinant and a finite inverse, so object-space rays keep non-zero directions and t means the
// same in both spaces.
void requireInvertibleAffine(const Transform& transform);

// Error bound of worldFromObject(p) for an object-space point p with error bound e, `world` being
// worldFromObject(p) (pbrt-v4 §6.8.6, plus the round trip through the stored inverse).
Vec3 worldPointError(const Transform& worldFromObject, const Point3& p, const Vec3& e,
                     const Point3& world);

// The same bound from the rows of the matrix `m` and of its stored inverse `inv` (indexable as
// [row][column], rows 0..2 read: Matrix4::m, or the 3×4 rows of an instance's AffineMatrix), so
// that a transformed primitive and an instance bound their hit points with identical arithmetic
// (pbrt-v4 §6.8.6: (1 + γ3)·|M|·e + γ3·(|M|·|p| + |translation|), plus the round trip: a ray
// spawned near the world point is mapped back by the stored inverse, whose rounding and
// inexactness as an inverse, carried back to world space, grow with the condition number
// κ = ‖|M|·|M⁻¹|‖∞ of the linear part: 1 for scales, ≤ 3 for rotations).
// κ = ‖|M|·|M⁻¹|‖∞ of the linear parts (the 3×3 upper left) of `m` and `inv`, rows as below.
template <typename Rows>
double conditionNumberOf(const Rows& m, const Rows& inv) {
  double kappa = 0;
  for (int i = 0; i < 3; ++i) {
    double row = 0;
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) row += std::abs(m[i][k]) * std::abs(inv[k][j]);
    kappa = std::max(kappa, row);
  }
  return kappa;
}

template <typename Rows>
Vec3 worldPointErrorOf(const Rows& m, const Rows& inv, const Point3& p, const Vec3& e,
                       const Point3& world) {
  const double kappa = conditionNumberOf(m, inv);
  double translation = 0;
  for (int i = 0; i < 3; ++i) translation = std::max(translation, std::abs(m[i][3]));
  const double roundTrip = gammaBound(8) * kappa * (maxComponent(abs(toVec(world))) + translation);
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    const double carried =
        std::abs(m[i][0]) * e.x + std::abs(m[i][1]) * e.y + std::abs(m[i][2]) * e.z;
    const double rounding = std::abs(m[i][0] * p.x) + std::abs(m[i][1] * p.y) +
                            std::abs(m[i][2] * p.z) + std::abs(m[i][3]);
    out[i] = (1 + gammaBound(3)) * carried + gammaBound(3) * rounding + roundTrip;
  }
  return out;
}

// objectFromWorld applied to a ray (the direction not normalised, so t is the same in both spaces).
Ray objectRayOf(const Transform& worldFromObject, const Ray& r);

}  // namespace glint
