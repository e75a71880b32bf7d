// Background lookups: gradient and equirectangular image.
#include "glint/scene/environment.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace glint {

Point2 equirectangularUv(const Vec3& d) {
  return {0.5 + std::atan2(d.x, -d.z) / (2 * std::numbers::pi),
          1 - std::acos(std::clamp(d.y, -1.0, 1.0)) / std::numbers::pi};
}

Color Environment::along(const Vec3& d, const Color& uniform) const {
  switch (kind) {
    case BackgroundKind::Uniform:
      return uniform;
    case BackgroundKind::Gradient: {
      const double elevation =
          std::asin(std::clamp(d.y, -1.0, 1.0)) / (std::numbers::pi / 2);  // −1 .. 1
      return elevation >= 0 ? horizon * (1 - elevation) + zenith * elevation
                            : horizon * (1 + elevation) + nadir * -elevation;
    }
    case BackgroundKind::Image:
      break;
  }
  // The picture turned by +rotate about +y: look up the direction turned by −rotate.
  const Vec3 turned{cosRotate * d.x - sinRotate * d.z, d.y, sinRotate * d.x + cosRotate * d.z};
  return image->bilinear(0, equirectangularUv(turned)) * intensity;
}

}  // namespace glint
