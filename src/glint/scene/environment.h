// What a ray that leaves the scene sees (DESIGN.md §9 `background`): one colour, a gradient from
// nadir through horizon to zenith, or an equirectangular image around the scene.
#pragma once

#include <cstdint>
#include <memory>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/scene/mip_map.h"

namespace glint {

enum class BackgroundKind : std::uint8_t { Uniform, Gradient, Image };

// (u, v) of a unit direction d on an equirectangular image (+y up): u = 0.5 + atan2(d.x,
// −d.z)/(2π), v = 1 − acos(d.y)/π. The image's centre column is −z, its top row +y, +x at u = 0.75.
Point2 equirectangularUv(const Vec3& d);

struct Environment {
  BackgroundKind kind = BackgroundKind::Uniform;
  // Gradient: blended linearly in the elevation angle, horizon (0°) to zenith (+90°, +y) above the
  // horizon and to nadir (−90°) below it.
  Color zenith;
  Color horizon;
  Color nadir;
  // Image: looked up bilinearly at the direction turned by −rotate about +y (so the picture turns
  // by +rotate degrees, counter-clockwise seen from above), times intensity.
  std::shared_ptr<const MipMap> image;
  double intensity = 1;
  double cosRotate = 1;
  double sinRotate = 0;

  // The radiance along the unit world direction d (Uniform: `uniform`, the scene's background).
  Color along(const Vec3& d, const Color& uniform) const;
};

}  // namespace glint
