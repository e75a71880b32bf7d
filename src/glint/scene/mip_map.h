// An image texture's pixels as a pyramid of linear RGB levels (mip-maps) and its filtered lookups:
// nearest, bilinear, and trilinear with the level chosen from the lookup's footprint (pbrt-v4).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"

namespace glint {

enum class TextureFilter : std::uint8_t { Nearest, Bilinear, Trilinear };

// A decoded picture in linear RGB, 3 floats per pixel, rows from the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;
};

// Lookups take st = (u, v) with (0, 0) the image's bottom-left corner and (1, 1) its top-right
// (DESIGN.md §9); outside [0, 1) the image repeats.
class MipMap {
 public:
  // Builds every level once: each half the size of the one before (rounded down, at least 1),
  // down to 1×1, by a box filter that weights each source texel by how much of it a target texel
  // covers (exact for odd sizes too). Throws std::invalid_argument for an empty image or one
  // whose pixel count does not match its size.
  explicit MipMap(RgbImage base);

  int levels() const { return static_cast<int>(levels_.size()); }
  int width(int level) const { return levels_[static_cast<std::size_t>(level)].width; }
  int height(int level) const { return levels_[static_cast<std::size_t>(level)].height; }
  // A level's texels, 3 floats each, rows from the top.
  const std::vector<float>& pixels(int level) const {
    return levels_[static_cast<std::size_t>(level)].pixels;
  }
  // Texel (x, y) of a level, row y from the top; both wrap around.
  Color texel(int level, int x, int y) const;

  // The texel of level 0 that st falls in.
  Color nearest(const Point2& st) const;
  // Bilinear interpolation between the four texel centres of `level` around st. With clampRows,
  // rows do not wrap (an equirectangular image: its top row is the zenith, its bottom the nadir,
  // and they do not meet); columns always do.
  Color bilinear(int level, const Point2& st, bool clampRows = false) const;
  // pbrt-v4's MIPMap::Filter for a trilinear lookup: `width` is the footprint in st units
  // (2 × the largest of |ds/dx|, |dt/dx|, |ds/dy|, |dt/dy|); the fractional level
  // levels() − 1 + log2(width) is blended between its two neighbouring levels (bilinear in each),
  // clamped to level 0 below and to the 1×1 level above.
  Color trilinear(const Point2& st, double width) const;
  // That fractional level, unclamped (for tests and tools).
  double levelFor(double width) const;

  // Bytes held by every level.
  std::size_t memoryBytes() const;
  // Bytes a MipMap of a width × height image will hold, computed from the size alone.
  static std::uint64_t bytesFor(std::uint64_t width, std::uint64_t height);

 private:
  std::vector<RgbImage> levels_;
};

}  // namespace glint
