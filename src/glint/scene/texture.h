// Textures (DESIGN.md §9): the closed set of texture types, their evaluation at a shading point,
// the (u, v) transform of the uv-mapped ones, and the per-material bindings of textures to the
// colour keys and to normal and bump maps. Dispatched through std::variant: no virtual call and no
// allocation per lookup.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <variant>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/scene/mip_map.h"

namespace glint {

using TextureId = std::uint32_t;
inline constexpr TextureId kNoTexture = 0xffffffffu;

// (u, v) ↦ R(rotate)·(repeat ⊙ (u, v)) + offset: `repeat` scales (a negative one mirrors), the
// rotation turns counter-clockwise by `rotate` degrees about (0, 0), then `offset` shifts.
struct UvTransform {
  Point2 repeat{1, 1};
  Point2 offset{0, 0};
  double cosRotate = 1;
  double sinRotate = 0;

  Point2 apply(const Point2& uv) const {
    const double u = uv.x * repeat.x;
    const double v = uv.y * repeat.y;
    return {cosRotate * u - sinRotate * v + offset.x, sinRotate * u + cosRotate * v + offset.y};
  }
  // The linear part alone, for differentials.
  Point2 applyLinear(const Point2& duv) const {
    const double u = duv.x * repeat.x;
    const double v = duv.y * repeat.y;
    return {cosRotate * u - sinRotate * v, sinRotate * u + cosRotate * v};
  }
};

// Solid checker: cell index floor(x/s) + floor(y/s) + floor(z/s) of the object-space point less
// `center`, even → colors[0], odd → colors[1].
struct CheckerTexture {
  std::array<Color, 2> colors;
  double scale = 1;  // cell size, object units
  Point3 center;     // the pattern's origin, object space
};

// Checker on (u, v): after the transform, floor(u) + floor(v) even → colors[0]; box-filtered over
// the lookup's footprint when that spans several cells.
struct Checker2dTexture {
  std::array<Color, 2> colors;
  UvTransform transform;
};

// Perlin noise solid textures (POV-Ray's and Tachyon's): each blends colors[0] → colors[1] by a
// value in [0, 1] computed at the object-space point less `center`, divided by `scale`.
//  - noise: 0.5 + 0.5·fractal noise, `octaves` terms of noise(2^k·p)/2^k;
//  - marble: 0.5 + 0.5·sin(π·(x + turbulence·turb(p))) — veins across x;
//  - wood: the fractional part of the distance from the y axis plus turbulence·turb(p), as rings.
// turb(p) = Σ |noise(2^k·p)|/2^k over `octaves` terms.
enum class NoisePattern : std::uint8_t { Noise, Marble, Wood };
struct NoiseTexture {
  NoisePattern pattern = NoisePattern::Noise;
  std::array<Color, 2> colors;
  double scale = 1;
  double turbulence = 0;
  int octaves = 1;
  Point3 center;  // the pattern's origin, object space
};

// A picture mapped on (u, v) (after the transform), through its shared mip-map.
struct ImageTexture {
  std::shared_ptr<const MipMap> image;
  TextureFilter filter = TextureFilter::Trilinear;
  UvTransform transform;
};

using Texture = std::variant<CheckerTexture, Checker2dTexture, NoiseTexture, ImageTexture>;

// Where a texture is looked up: the point in the object's own space (solid textures), (u, v) and
// its screen-space differentials (uv-mapped ones; zero differentials give the sharpest level).
struct TextureLookup {
  Point3 objectPoint;
  Point2 uv;
  Point2 duvdx;
  Point2 duvdy;
};

Color evaluate(const Texture& texture, const TextureLookup& at);
// The texture's mean colour: of its two colours, or of its image (the 1×1 mip level).
Color meanOf(const Texture& texture);
// Whether a texture reads (u, v) (checker2d, image) rather than the object-space point.
bool usesUv(const Texture& texture);

// Ken Perlin's improved noise (2002) at p, in [−1, 1]; 0 at integer lattice points.
double perlinNoise(const Point3& p);

// The textures of one material: each colour key's texture (kNoTexture: its constant in Material)
// and the maps that perturb the shading normal.
struct MaterialTextures {
  TextureId kd = kNoTexture;
  TextureId ks = kNoTexture;
  TextureId kr = kNoTexture;
  TextureId kt = kNoTexture;
  TextureId ka = kNoTexture;
  TextureId emission = kNoTexture;   // an object's emission texture (the object's own material)
  TextureId normalMap = kNoTexture;  // tangent space, RGB ↦ 2·RGB − 1 (x along u, y along v)
  TextureId bumpMap = kNoTexture;    // height = mean of RGB × bumpScale, scene units
  double bumpScale = 1;
  // Whether anything here reads (u, v) or needs a tangent frame.
  bool needsUv = false;
};

}  // namespace glint
