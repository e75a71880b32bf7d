// Mip-map construction (separable box filter with fractional coverage) and lookups.
#include "glint/scene/mip_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace glint {

namespace {

// The next level's size along one axis.
int halved(int size) { return std::max(1, size / 2); }

int wrap(int i, int n) {
  const int r = i % n;
  return r < 0 ? r + n : r;
}

// Box-filters `source` (rows × from texels of `channels` floats, stride along the axis `step`)
// along one axis from `from` to `to` texels: target texel i covers source texels
// [i·from/to, (i+1)·from/to), each weighted by the length of its overlap.
void downsampleAxis(const std::vector<float>& source, std::vector<float>& target, int from, int to,
                    int lines, bool alongRows, int otherSize) {
  const double ratio = static_cast<double>(from) / to;
  for (int line = 0; line < lines; ++line) {
    for (int i = 0; i < to; ++i) {
      const double begin = i * ratio;
      const double end = (i + 1) * ratio;
      double sum[3] = {0, 0, 0};
      for (int s = static_cast<int>(std::floor(begin)); s < from && s < end; ++s) {
        const double weight = std::min<double>(end, s + 1) - std::max<double>(begin, s);
        if (weight <= 0) continue;
        const std::size_t at = alongRows ? (static_cast<std::size_t>(line) * from + s) * 3
                                         : (static_cast<std::size_t>(s) * otherSize + line) * 3;
        for (int c = 0; c < 3; ++c) sum[c] += weight * source[at + c];
      }
      const std::size_t out = alongRows ? (static_cast<std::size_t>(line) * to + i) * 3
                                        : (static_cast<std::size_t>(i) * otherSize + line) * 3;
      for (int c = 0; c < 3; ++c) target[out + c] = static_cast<float>(sum[c] / ratio);
    }
  }
}

RgbImage downsample(const RgbImage& in) {
  const int w = halved(in.width);
  const int h = halved(in.height);
  // Rows first (in.height rows of w texels), then columns (w columns of h texels).
  std::vector<float> rows(static_cast<std::size_t>(w) * in.height * 3);
  downsampleAxis(in.pixels, rows, in.width, w, in.height, true, 0);
  RgbImage out{w, h, std::vector<float>(static_cast<std::size_t>(w) * h * 3)};
  downsampleAxis(rows, out.pixels, in.height, h, w, false, w);
  return out;
}

Color lerp(double t, const Color& a, const Color& b) { return a * (1 - t) + b * t; }

}  // namespace

MipMap::MipMap(RgbImage base) {
  if (base.width <= 0 || base.height <= 0 ||
      base.pixels.size() != static_cast<std::size_t>(base.width) * base.height * 3) {
    throw std::invalid_argument("an image texture needs width × height RGB pixels");
  }
  levels_.push_back(std::move(base));
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    RgbImage next = downsample(levels_.back());
    levels_.push_back(std::move(next));
  }
}

Color MipMap::texel(int level, int x, int y) const {
  const RgbImage& image = levels_[static_cast<std::size_t>(level)];
  const std::size_t at = (static_cast<std::size_t>(wrap(y, image.height)) * image.width +
                          static_cast<std::size_t>(wrap(x, image.width))) *
                         3;
  return {image.pixels[at], image.pixels[at + 1], image.pixels[at + 2]};
}

Color MipMap::nearest(const Point2& st) const {
  const RgbImage& image = levels_.front();
  // Rows run from the top; t from the bottom.
  const double x = std::floor(st.x * image.width);
  const double y = std::floor((1 - st.y) * image.height);
  if (!std::isfinite(x) || !std::isfinite(y)) return texel(0, 0, 0);
  return texel(0, static_cast<int>(std::fmod(x, image.width)),
               static_cast<int>(std::fmod(y, image.height)));
}

Color MipMap::bilinear(int level, const Point2& st, bool clampRows) const {
  const RgbImage& image = levels_[static_cast<std::size_t>(level)];
  // Texel centres sit at (i + 0.5) / size: shift by half a texel to interpolate between them.
  double x = st.x * image.width - 0.5;
  double y = (1 - st.y) * image.height - 0.5;
  if (!std::isfinite(x) || !std::isfinite(y)) return texel(level, 0, 0);
  // Keep the coordinates small so that floor and the weights stay exact for far-repeated lookups.
  x = std::fmod(x, image.width);
  y = std::fmod(y, image.height);
  const double x0 = std::floor(x);
  const double y0 = std::floor(y);
  const double fx = x - x0;
  const double fy = y - y0;
  const int ix = static_cast<int>(x0);
  int iy = static_cast<int>(y0);
  int below = iy + 1;
  if (clampRows) {
    iy = std::clamp(iy, 0, image.height - 1);
    below = std::clamp(below, 0, image.height - 1);
  }
  return lerp(fy, lerp(fx, texel(level, ix, iy), texel(level, ix + 1, iy)),
              lerp(fx, texel(level, ix, below), texel(level, ix + 1, below)));
}

double MipMap::levelFor(double width) const {
  return levels() - 1 + std::log2(std::max(width, 1e-8));
}

Color MipMap::trilinear(const Point2& st, double width) const {
  const double level = levelFor(width);
  if (!(level > 0)) return bilinear(0, st);  // also NaN: the sharpest level
  if (level >= levels() - 1) return texel(levels() - 1, 0, 0);
  const int lower = static_cast<int>(std::floor(level));
  const double t = level - lower;
  return lerp(t, bilinear(lower, st), bilinear(lower + 1, st));
}

std::size_t MipMap::memoryBytes() const {
  std::size_t bytes = 0;
  for (const RgbImage& level : levels_) bytes += level.pixels.capacity() * sizeof(float);
  return bytes;
}

std::uint64_t MipMap::bytesFor(std::uint64_t width, std::uint64_t height) {
  std::uint64_t texels = 0;
  for (;;) {
    texels += width * height;
    if (width <= 1 && height <= 1) break;
    width = std::max<std::uint64_t>(1, width / 2);
    height = std::max<std::uint64_t>(1, height / 2);
  }
  return texels * 3 * sizeof(float);
}

}  // namespace glint
