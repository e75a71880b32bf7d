// What a ray that leaves the scene sees (DESIGN.md §9 `background`): one colour, a gradient from
// nadir through horizon to zenith, or an equirectangular image around the scene.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/scene/mip_map.h"

namespace glint {

enum class BackgroundKind : std::uint8_t { Uniform, Gradient, Image, Sky };

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
  // by +rotate degrees, counter-clockwise seen from above), times intensity; around the vertical
  // it wraps, at the zenith and nadir its top and bottom rows hold (they are not neighbours).
  std::shared_ptr<const MipMap> image;
  double intensity = 1;
  double cosRotate = 1;
  double sinRotate = 0;
  // Sky (Tachyon's BACKGROUND_GRADIENT): skyBottom + (skyTop − skyBottom) · clamp((t − bottomValue)
  // / (topValue − bottomValue), 0, 1), with t = d·skyUp (skyUp a unit vector; Tachyon's SKY_SPHERE)
  // or, skyByHeight, t = o·skyUp for the ray's origin o (its SKY_ORTHO_PLANE, for orthographic
  // views: the gradient runs across the picture, not around the sky).
  Vec3 skyUp{0, 1, 0};
  Color skyTop;
  Color skyBottom;
  double topValue = 1;
  double bottomValue = -1;
  bool skyByHeight = false;

  // The radiance along the unit world direction d of a ray from `origin` (Uniform: `uniform`, the
  // scene's background; only a Sky by height looks at the origin).
  Color along(const Vec3& d, const Color& uniform, const Point3& origin = Point3()) const;
  // The direction turned by −rotate about +y (where the image is looked up), and back.
  Vec3 toImage(const Vec3& d) const;
  Vec3 fromImage(const Vec3& d) const;
};

// Importance sampling of an image environment for the path integrator's next-event estimation
// (pbrt's piecewise-constant 2D distribution): directions are drawn with density proportional to
// the luminance of a level of the image's mip-map at most kEnvironmentSamplingWidth texels wide,
// weighted by sin θ (the texels' solid angle), so bright parts (the sun, a window) are found by
// shadow rays instead of by chance. Texels of zero luminance are never drawn; the path
// integrator's multiple importance sampling leaves those directions to the BRDF samples.
class EnvironmentSampler {
 public:
  static constexpr int kEnvironmentSamplingWidth = 512;
  // Null unless `environment` is an image with some light in it.
  static std::shared_ptr<const EnvironmentSampler> make(const Environment& environment);

  // A unit world direction for u in [0,1)², with its density over solid angle (> 0).
  Vec3 sample(const Point2& u, double& pdf) const;
  // The density over solid angle of drawing the unit world direction d.
  double pdf(const Vec3& d) const;

 private:
  EnvironmentSampler(const Environment& environment, int level);
  // The first index i of `cdf` (size n + 1, cdf[0] = 0, cdf[n] = 1) with cdf[i + 1] > u.
  static int find(const double* cdf, int n, double u);

  Environment environment_;  // a copy: the image is shared
  int width_;
  int height_;
  std::vector<double> rowCdf_;       // height_ + 1 values
  std::vector<double> columnCdf_;    // height_ rows of width_ + 1 values
  std::vector<double> rowWeight_;    // each row's share of the total
  std::vector<double> texelWeight_;  // each texel's share of its row
};

}  // namespace glint
