// The refracted direction of Snell's law with total internal reflection, and the relative index of
// a surface against air (nested media give theirs through scene/media.h's Boundary::eta).
#pragma once

#include <algorithm>
#include <cmath>

#include "glint/core/vec.h"

namespace glint {

// The relative index of refraction (n_incident / n_transmitted) of a surface of `ior` against air:
// 1 (straight on) for ior 1; `entering` when n·v < 0 (the ray goes against the outward normal).
inline double airRelativeIndex(double ior, bool entering) {
  if (ior == 1) return 1;
  return entering ? 1 / ior : ior;
}

// The transmitted direction of the unit view direction v at a surface with geometric normal n
// (nv = n·v) and shading normal ns: straight on (v) when eta = 1; otherwise Snell's law
// n_i sin θi = n_t sin θt with the relative index eta = n_i / n_t, bent about ns; on total
// internal reflection (eta · sin θi ≥ 1) the mirror direction `reflected` (kt's energy follows the
// mirror ray). `smooth`: ns ≠ n; a direction bent about ns that would not cross the geometric
// surface goes straight on instead.
[[gnu::always_inline]] inline Vec3 transmittedDirection(double eta, const Vec3& v, const Normal3& n,
                                                        const Normal3& ns, double nv, bool smooth,
                                                        const Vec3& reflected, bool entering) {
  Vec3 transmitted = v;
  if (eta != 1) {
    const Vec3 facing = entering ? toVec(ns) : -toVec(ns);  // normal on the incident side
    const double cosIncident = -dot(facing, v);
    const double sin2Transmitted = eta * eta * std::max(0.0, 1 - cosIncident * cosIncident);
    if (sin2Transmitted >= 1) {
      transmitted = reflected;
    } else {
      const double cosTransmitted = std::sqrt(1 - sin2Transmitted);
      transmitted = v * eta + facing * (eta * cosIncident - cosTransmitted);
      // Bent about ns, it must still cross the geometric surface; otherwise go straight on.
      if (smooth && !(dot(n, transmitted) * nv > 0)) transmitted = v;
    }
  }
  return transmitted;
}

}  // namespace glint
