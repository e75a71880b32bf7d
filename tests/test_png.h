// Test helper: decodes an 8-bit RGB/RGBA PNG file into RGB bytes with libpng.
#pragma once

#include <png.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace glint::testing {

struct DecodedImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, 3 bytes per pixel, row 0 at the top
};

inline DecodedImage readPng(const std::filesystem::path& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.string().c_str()))
    throw std::runtime_error("cannot read PNG " + path.string() + ": " + image.message);
  image.format = PNG_FORMAT_RGB;
  DecodedImage result;
  result.width = static_cast<int>(image.width);
  result.height = static_cast<int>(image.height);
  result.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, result.rgb.data(), 0, nullptr)) {
    png_image_free(&image);
    throw std::runtime_error("cannot decode PNG " + path.string() + ": " + image.message);
  }
  return result;
}

}  // namespace glint::testing
