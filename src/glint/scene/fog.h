// Distance fog (Tachyon's and OpenGL's linear, exp and exp2 fog): what a ray sees blends toward the
// fog colour with the distance it travelled.
#pragma once

#include <algorithm>
#include <cmath>

#include "glint/core/color.h"

namespace glint {

enum class FogFalloff { Linear, Exp, Exp2 };

// How far a ray's hit is, for the fog.
enum class FogDistance {
  Ray,    // the length of each ray to its hit (Tachyon's radial fog); a ray that leaves the scene
          // travels infinitely far and sees the fog colour
  Depth,  // camera rays: the hit's depth along the view direction; others: their length; a ray
          // that leaves the scene sees the background unfogged (OpenGL's and VMD's fog)
};

struct Fog {
  FogFalloff falloff = FogFalloff::Exp2;
  FogDistance distance = FogDistance::Ray;
  double start = 0;    // scene units: no fog nearer than this
  double end = 1;      // scene units: linear fog is total from here on (end > start)
  double density = 1;  // per scene unit, exp and exp2 (≥ 0)
  Color color;         // linear

  // The fraction of the unfogged colour left at distance d (OpenGL's f, clamped to [0, 1]):
  // linear (end − d)/(end − start), exp e^(−density·(d − start)), exp2 e^(−(density·(d − start))²).
  double visibility(double d) const {
    double f = 1;
    switch (falloff) {
      case FogFalloff::Linear:
        f = (end - d) / (end - start);
        break;
      case FogFalloff::Exp:
        f = std::exp(-density * (d - start));
        break;
      case FogFalloff::Exp2: {
        const double v = density * (d - start);
        f = std::exp(-v * v);
        break;
      }
    }
    return std::isnan(f) ? 0.0 : std::clamp(f, 0.0, 1.0);
  }
  Color apply(const Color& c, double d) const {
    const double f = visibility(d);
    return c * f + color * (1 - f);
  }
};

}  // namespace glint
