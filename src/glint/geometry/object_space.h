// Moving rays into a transformed shape's own space and its hit points back out, with their error
// bounds: what Primitive and the operands of a csg (csg.h) share.
#pragma once

#include "glint/core/ray.h"
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

// objectFromWorld applied to a ray (the direction not normalised, so t is the same in both spaces).
Ray objectRayOf(const Transform& worldFromObject, const Ray& r);

}  // namespace glint
