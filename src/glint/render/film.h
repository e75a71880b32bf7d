// The film: linear RGB pixels of a rendered region of the image, before encoding.
#pragma once

#include <cstddef>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/huge_pages.h"

namespace glint {

// A pixel rectangle [x0, x1) × [y0, y1) in full-image pixel coordinates (row 0 at the top).
struct PixelRegion {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  friend bool operator==(const PixelRegion&, const PixelRegion&) = default;
};

class Film {
 public:
  Film() = default;
  // A film covering `region` of a fullWidth × fullHeight image.
  Film(int fullWidth, int fullHeight, const PixelRegion& region)
      : fullWidth_(fullWidth), fullHeight_(fullHeight), region_(region) {
    const std::size_t n = static_cast<std::size_t>(region.width()) * region.height();
    reserveOnHugePages(pixels_, n);  // 24 B a pixel: 19 MB at 1024×768
    pixels_.resize(n);
  }

  int width() const { return region_.width(); }
  int height() const { return region_.height(); }
  int fullWidth() const { return fullWidth_; }
  int fullHeight() const { return fullHeight_; }
  const PixelRegion& region() const { return region_; }

  // Local coordinates: (0, 0) is the region's top-left pixel.
  Color& at(int x, int y) { return pixels_[static_cast<std::size_t>(y) * width() + x]; }
  const Color& at(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width() + x]; }
  const std::vector<Color>& pixels() const { return pixels_; }

 private:
  int fullWidth_ = 0, fullHeight_ = 0;
  PixelRegion region_;
  std::vector<Color> pixels_;
};

}  // namespace glint
