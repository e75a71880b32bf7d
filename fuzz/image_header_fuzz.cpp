// libFuzzer target: glint::readImageHeader, the header checks glint parses itself (PNG IHDR, JPEG
// SOFn markers, EXR attributes, Radiance HDR text) before any texture is decoded. Any bytes give a
// header within the texture limits or an ImageReadError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "glint/image/image_header.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    std::size_t pixelsStart = 0;
    const glint::ImageHeader header = glint::readImageHeader({data, size}, &pixelsStart);
    if (header.width == 0 || header.height == 0 || header.width > glint::kMaxTextureSide ||
        header.height > glint::kMaxTextureSide ||
        std::uint64_t{header.width} * header.height > glint::kMaxTexturePixels ||
        pixelsStart > size) {
      std::abort();
    }
  } catch (const glint::ImageReadError&) {
  }
  return 0;
}
