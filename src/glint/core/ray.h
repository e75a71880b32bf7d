// Rays: an origin and a direction, points along them at parameter t.
#pragma once

#include "glint/core/vec.h"

namespace glint {

// A ray P(t) = origin + t·direction. The direction need not be unit (object-space rays of
// transformed shapes are not); t is then measured in multiples of the direction's length.
struct Ray {
  Point3 origin;
  Vec3 direction;

  constexpr Point3 at(double t) const { return origin + direction * t; }
};

}  // namespace glint
