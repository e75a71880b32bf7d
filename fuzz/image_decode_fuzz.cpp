// libFuzzer target: glint::decodeImage (PNG through libpng, JPEG through libjpeg-turbo, EXR through
// OpenEXR, Radiance HDR through glint's own RGBE reader) and the mip-map built from the result,
// exactly as an image texture is loaded. Any bytes give an image of its header's size whose values
// are finite and ≥ 0 (8-bit and 16-bit ones in [0, 1]) with a complete pyramid, or an
// ImageReadError; anything else is a finding. Inputs declaring more than 4 million pixels are
// skipped after the header (the scene builder's budget check would refuse far smaller ones, and
// decoding them only slows the fuzzer down).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

#include "glint/image/image_decoder.h"
#include "glint/scene/mip_map.h"

namespace {

void require(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  glint::ImageHeader header;
  try {
    header = glint::readImageHeader(bytes);
  } catch (const glint::ImageReadError&) {
    return 0;
  }
  if (std::uint64_t{header.width} * header.height > (std::uint64_t{1} << 22)) return 0;
  for (const glint::ImageEncoding encoding :
       {glint::ImageEncoding::Srgb, glint::ImageEncoding::Linear}) {
    try {
      glint::RgbImage image = glint::decodeImage(bytes, encoding);
      require(image.width == static_cast<int>(header.width));
      require(image.height == static_cast<int>(header.height));
      require(image.pixels.size() == std::size_t{header.width} * header.height * 3);
      for (const float v : image.pixels) {
        require(std::isfinite(v) && v >= 0);
        require(header.floatingPoint || v <= 1.0f);
      }
      const glint::MipMap mip(std::move(image));
      require(mip.width(mip.levels() - 1) == 1 && mip.height(mip.levels() - 1) == 1);
      require(mip.memoryBytes() == glint::MipMap::bytesFor(header.width, header.height));
      const glint::Color c = mip.trilinear({0.3, 0.7}, 0.01);
      require(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b));
    } catch (const glint::ImageReadError&) {
    }
  }
  return 0;
}
