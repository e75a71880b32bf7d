// Image files decoded into linear RGB for textures: PNG (libpng), JPEG (libjpeg-turbo), EXR
// (OpenEXR), Radiance HDR (glint's own RGBE reader), all from bytes in memory, and the one way a
// texture file is read from disk (regular files only, the header checked before the pixels).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <vector>

#include "glint/image/image_header.h"
#include "glint/scene/mip_map.h"

namespace glint {

// How 8- and 16-bit channels become linear: sRGB-decoded (IEC 61966-2-1, colour images), or
// divided by 255 / 65535 (normal maps, bump maps, `encoding: linear`). EXR and HDR are linear.
enum class ImageEncoding : std::uint8_t { Srgb, Linear };

// Decodes a whole image file held in memory. Grey images become RGB, alpha is dropped, palettes
// are expanded. Throws ImageReadError naming what is wrong (a corrupt or truncated file, an
// unsupported variant) — never crashes on hostile bytes (fuzzed: fuzz/image_decode_fuzz.cpp).
RgbImage decodeImage(std::span<const std::uint8_t> bytes, ImageEncoding encoding);

// Largest texture file glint reads (bytes): the largest image it accepts compresses to far less.
inline constexpr std::uint64_t kMaxImageFileBytes = std::uint64_t{1} << 30;

// Reads an image file: opened as a regular file only (openForReading: never a FIFO or a device),
// its header read first and passed to `accept` (which may throw to refuse it, e.g. over the memory
// budget) before the rest is read and decoded. Throws ImageReadError: no such file, not a regular
// file, unreadable, too large, or what decodeImage throws.
RgbImage readImageFile(const std::filesystem::path& path, ImageEncoding encoding,
                       const std::function<void(const ImageHeader&)>& accept = {});

// The header alone, from the file's first kImageHeaderBytes.
ImageHeader readImageFileHeader(const std::filesystem::path& path);

}  // namespace glint
