// The film: linear RGB pixels of a rendered region of the image, before encoding.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <span>
#include <type_traits>

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
  // A film covering `region` of a fullWidth × fullHeight image, every pixel black.
  Film(int fullWidth, int fullHeight, const PixelRegion& region)
      : fullWidth_(fullWidth), fullHeight_(fullHeight), region_(region) {
    allocate(static_cast<std::size_t>(region.width()) * region.height());
  }
  Film(const Film& other)
      : fullWidth_(other.fullWidth_), fullHeight_(other.fullHeight_), region_(other.region_) {
    allocate(other.size_);
    if (size_ != 0) std::memcpy(pixels_.get(), other.pixels_.get(), size_ * sizeof(Color));
  }
  Film(Film&&) noexcept = default;
  Film& operator=(const Film& other) {
    if (this != &other) *this = Film(other);
    return *this;
  }
  Film& operator=(Film&&) noexcept = default;

  int width() const { return region_.width(); }
  int height() const { return region_.height(); }
  int fullWidth() const { return fullWidth_; }
  int fullHeight() const { return fullHeight_; }
  const PixelRegion& region() const { return region_; }

  // Local coordinates: (0, 0) is the region's top-left pixel.
  Color& at(int x, int y) { return pixels_[static_cast<std::size_t>(y) * width() + x]; }
  const Color& at(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width() + x]; }
  std::span<const Color> pixels() const { return {pixels_.get(), size_}; }

 private:
  // The pixels come from calloc: 24 B a pixel (19 MB at 1024×768) is a fresh mapping of the
  // system's, zero already, so nothing writes it before the render does, and each page is first
  // touched — faulted in and zeroed by the kernel — by the render thread that fills it, in
  // parallel (filling it here took ~8 % of a 512² render of a small scene). Color is trivially
  // copyable and destructible, and all-zero bytes are Color(0, 0, 0).
  static_assert(std::is_trivially_copyable_v<Color> && std::is_trivially_destructible_v<Color>);
  struct Free {
    void operator()(Color* pixels) const { std::free(pixels); }
  };
  void allocate(std::size_t n) {
    size_ = n;
    if (n == 0) return;
    pixels_.reset(static_cast<Color*>(std::calloc(n, sizeof(Color))));
    if (!pixels_) throw std::bad_alloc();
    adviseHugePages(pixels_.get(), n * sizeof(Color));
  }

  int fullWidth_ = 0, fullHeight_ = 0;
  PixelRegion region_;
  std::unique_ptr<Color[], Free> pixels_;
  std::size_t size_ = 0;
};

}  // namespace glint
