// Image headers parsed by glint itself (bounds-checked at every byte; fuzzed by
// fuzz/image_header_fuzz.cpp): PNG IHDR, JPEG SOFn, EXR dataWindow, Radiance HDR resolution.
#include "glint/image/image_header.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

namespace glint {

namespace {

std::uint32_t bigEndian32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}
std::uint32_t bigEndian16(const std::uint8_t* p) { return std::uint32_t{p[0]} << 8 | p[1]; }
std::int32_t littleEndian32(const std::uint8_t* p) {
  const std::uint32_t u =
      std::uint32_t{p[3]} << 24 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[1]} << 8 | p[0];
  std::int32_t s = 0;
  std::memcpy(&s, &u, sizeof s);
  return s;
}

[[noreturn]] void malformed(const char* format, const char* why) {
  throw ImageReadError(fmt::format("invalid {} file: {}", format, why));
}

void checkSize(ImageHeader& h, std::uint64_t width, std::uint64_t height) {
  if (width == 0 || height == 0) {
    throw ImageReadError(fmt::format("invalid {} file: it has no pixels ({}×{})",
                                     formatName(h.format), width, height));
  }
  if (width > kMaxTextureSide || height > kMaxTextureSide || width * height > kMaxTexturePixels) {
    throw ImageReadError(
        fmt::format("the image is {}×{} pixels, more than glint's texture limit "
                    "({} pixels a side, {} million pixels)",
                    width, height, kMaxTextureSide, kMaxTexturePixels >> 20));
  }
  h.width = static_cast<std::uint32_t>(width);
  h.height = static_cast<std::uint32_t>(height);
}

ImageHeader pngHeader(std::span<const std::uint8_t> b) {
  ImageHeader h{ImageFormat::Png};
  // Signature (8), IHDR length (4) and type (4), width (4), height (4).
  if (b.size() < 24 || std::memcmp(b.data() + 12, "IHDR", 4) != 0) {
    malformed("PNG", "the header (IHDR) is missing or cut short");
  }
  checkSize(h, bigEndian32(b.data() + 16), bigEndian32(b.data() + 20));
  return h;
}

ImageHeader jpegHeader(std::span<const std::uint8_t> b) {
  ImageHeader h{ImageFormat::Jpeg};
  std::size_t at = 2;  // after SOI
  while (at + 4 <= b.size()) {
    if (b[at] != 0xff) malformed("JPEG", "a marker is missing where one should start");
    const std::uint8_t marker = b[at + 1];
    if (marker == 0xff) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0xd8 || marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) {
      at += 2;  // markers without a length
      continue;
    }
    if (marker == 0xd9 || marker == 0xda) break;  // end of image, start of scan: no frame before
    const std::size_t length = bigEndian16(b.data() + at + 2);
    if (length < 2) malformed("JPEG", "a marker segment has an invalid length");
    // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC): precision, height, width.
    if (marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc) {
      if (at + 9 > b.size()) break;
      checkSize(h, bigEndian16(b.data() + at + 7), bigEndian16(b.data() + at + 5));
      return h;
    }
    at += 2 + length;
  }
  malformed("JPEG", "no frame header (SOF) within the first 256 KiB");
}

// OpenEXR: magic, version, then attributes (name\0 type\0 int32 size, value) up to an empty name.
ImageHeader exrHeader(std::span<const std::uint8_t> b) {
  ImageHeader h{ImageFormat::Exr, 0, 0, true};
  std::size_t at = 8;
  const auto text = [&](std::size_t from) {
    const auto* begin = reinterpret_cast<const char*>(b.data() + from);
    const std::size_t limit = std::min<std::size_t>(b.size() - from, 256);
    const std::size_t length = strnlen(begin, limit);
    if (length == limit)
      malformed("EXR", "the header is cut short or an attribute name is too long");
    return std::string_view(begin, length);
  };
  while (at < b.size()) {
    const std::string_view name = text(at);
    if (name.empty()) break;
    at += name.size() + 1;
    if (at >= b.size()) break;
    const std::string_view type = text(at);
    at += type.size() + 1;
    if (at + 4 > b.size()) break;
    const std::int32_t size = littleEndian32(b.data() + at);
    at += 4;
    if (size < 0 || static_cast<std::size_t>(size) > b.size() - at) break;
    if (name == "dataWindow") {
      if (type != "box2i" || size != 16) malformed("EXR", "its dataWindow is not a box2i");
      const std::int64_t xMin = littleEndian32(b.data() + at);
      const std::int64_t yMin = littleEndian32(b.data() + at + 4);
      const std::int64_t xMax = littleEndian32(b.data() + at + 8);
      const std::int64_t yMax = littleEndian32(b.data() + at + 12);
      if (xMax < xMin || yMax < yMin) malformed("EXR", "its dataWindow is empty");
      checkSize(h, static_cast<std::uint64_t>(xMax - xMin + 1),
                static_cast<std::uint64_t>(yMax - yMin + 1));
      return h;
    }
    at += static_cast<std::size_t>(size);
  }
  malformed("EXR", "the header has no dataWindow within the first 256 KiB");
}

// Radiance RGBE: "#?RADIANCE" (or "#?RGBE"), header lines up to an empty line, then "-Y h +X w".
ImageHeader hdrHeader(std::span<const std::uint8_t> b, std::size_t* pixelsStart = nullptr) {
  ImageHeader h{ImageFormat::Hdr, 0, 0, true};
  const std::string_view all(reinterpret_cast<const char*>(b.data()), b.size());
  std::size_t at = 0;
  for (;;) {
    const std::size_t end = all.find('\n', at);
    if (end == std::string_view::npos) malformed("HDR", "the header does not end within 256 KiB");
    const std::string_view line = all.substr(at, end - at);
    at = end + 1;
    if (line.empty()) break;
    if (line.starts_with("FORMAT=")) {
      // The only other format, 32-bit_rle_xyze, holds CIE XYZ, not RGB.
      if (line != "FORMAT=32-bit_rle_rgbe") {
        malformed("HDR", "only the FORMAT=32-bit_rle_rgbe pixel format is read");
      }
    }
  }
  const std::size_t end = all.find('\n', at);
  if (end == std::string_view::npos) malformed("HDR", "the resolution line is missing");
  const std::string line(all.substr(at, end - at));
  unsigned long height = 0;
  unsigned long width = 0;
  char tail = 0;
  // %lu alone would take "-5" (as 2^64 − 5): the sizes must start with a digit.
  const std::size_t widthAt = line.find("+X ");
  const auto digitAt = [&](std::size_t i) {
    return i < line.size() && line[i] >= '0' && line[i] <= '9';
  };
  if (std::sscanf(line.c_str(), "-Y %lu +X %lu%c", &height, &width, &tail) != 2 || !digitAt(3) ||
      widthAt == std::string::npos || !digitAt(widthAt + 3)) {
    malformed("HDR",
              "the resolution line is not '-Y height +X width' (the standard "
              "orientation, sizes in digits)");
  }
  checkSize(h, width, height);
  if (pixelsStart != nullptr) *pixelsStart = end + 1;
  return h;
}

}  // namespace

const char* formatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::Png:
      return "PNG";
    case ImageFormat::Jpeg:
      return "JPEG";
    case ImageFormat::Exr:
      return "EXR";
    case ImageFormat::Hdr:
      return "HDR";
  }
  return "image";
}

ImageHeader readImageHeader(std::span<const std::uint8_t> bytes, std::size_t* pixelsStart) {
  if (pixelsStart != nullptr) *pixelsStart = 0;
  static constexpr std::uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static constexpr std::uint8_t kExr[4] = {0x76, 0x2f, 0x31, 0x01};
  const auto startsWith = [&](const void* magic, std::size_t size) {
    return bytes.size() >= size && std::memcmp(bytes.data(), magic, size) == 0;
  };
  if (startsWith(kPng, sizeof kPng)) return pngHeader(bytes);
  if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
    return jpegHeader(bytes);
  }
  if (startsWith(kExr, sizeof kExr)) return exrHeader(bytes);
  if (startsWith("#?RADIANCE\n", 11) || startsWith("#?RGBE\n", 7))
    return hdrHeader(bytes, pixelsStart);
  throw ImageReadError(
      bytes.empty() ? std::string("the file is empty")
                    : std::string("it is not a PNG, JPEG, EXR or Radiance HDR image (its first "
                                  "bytes match none of them)"));
}

}  // namespace glint
