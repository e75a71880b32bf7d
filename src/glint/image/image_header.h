// What an image file is before it is decoded: its format and size read from its first bytes, so
// that the memory a texture will take is known (and refused) before any pixel is decoded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

namespace glint {

enum class ImageFormat : std::uint8_t { Png, Jpeg, Exr, Hdr };

// Why an image file cannot be used, in the user's words (no file name: the caller names it).
class ImageReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Largest side of an image texture, and most pixels, that glint decodes: 32768² would already take
// 16 GiB as a float mip-map.
inline constexpr std::uint32_t kMaxTextureSide = 32768;
inline constexpr std::uint64_t kMaxTexturePixels = std::uint64_t{1} << 28;

// Bytes from the start of a file that readImageHeader needs at most: an EXR's header (its
// attributes come before the pixels), a JPEG's markers before its frame header (EXIF and ICC data
// can take tens of KiB), a Radiance HDR's text header.
inline constexpr std::size_t kImageHeaderBytes = 256 * 1024;

struct ImageHeader {
  ImageFormat format = ImageFormat::Png;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  // Decoded as floating point, already linear (EXR, HDR); 8- and 16-bit images are display-encoded.
  bool floatingPoint = false;
};

// The format by signature (PNG, JPEG SOI marker, EXR magic, "#?RADIANCE"/"#?RGBE"), and the size
// from the format's own header: PNG's IHDR, JPEG's frame header (SOFn), EXR's dataWindow attribute,
// HDR's resolution line (only the standard orientation "-Y h +X w"). `bytes` is the file's start
// (kImageHeaderBytes or the whole file when shorter). Throws ImageReadError for an unknown format,
// a truncated or malformed header, a zero size, or one past kMaxTextureSide / kMaxTexturePixels.
// `pixelsStart`, when given, is set to where an HDR file's pixels begin (0 for the other formats).
ImageHeader readImageHeader(std::span<const std::uint8_t> bytes,
                            std::size_t* pixelsStart = nullptr);

const char* formatName(ImageFormat format);

}  // namespace glint
