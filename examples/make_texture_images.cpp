// Writes the images scenes/textures.yaml and scenes/showcase.yaml use, into one folder:
//   uv_grid.png      512×256 orientation chart: red grows with u, green with v, a grid every 1/8,
//                    a white square at the top-left corner (u ≈ 0, v ≈ 1) — sRGB
//   bumps_normal.png 256×256 tangent-space normal map of hemispherical bumps on a 4×4 grid —
//                    linear 8-bit (RGB = (n + 1)/2)
//   sky.hdr          1024×512 equirectangular sky (Radiance RGBE, run-length scanlines): a blue
//                    gradient over a dim ground, and a sun of radiance 40 toward +x+z, 30° high
// Regenerate the committed files with
//
//   build/examples/make_texture_images scenes/textures
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "glint/core/vec.h"
#include "glint/image/image_writer.h"
#include "glint/render/film.h"

namespace {

using glint::Color;
using glint::Film;
using glint::Vec3;

Film uvGrid() {
  const int w = 512;
  const int h = 256;
  Film film(w, h, glint::PixelRegion{0, 0, w, h});
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double u = (x + 0.5) / w;
      const double v = 1 - (y + 0.5) / h;  // rows from the top, v from the bottom
      Color c(0.15 + 0.8 * u, 0.15 + 0.8 * v, 0.35);
      const bool line = x % (w / 8) < 3 || y % (h / 8) < 3;
      if (line) c = Color(0.05);
      if (x < w / 16 && y < h / 8) c = Color(1);
      film.at(x, y) = c;
    }
  }
  return film;
}

Film bumpsNormal() {
  const int size = 256;
  const int cells = 4;
  Film film(size, size, glint::PixelRegion{0, 0, size, size});
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      // Position inside the cell, −1..1; x right (+u), y up (+v).
      const double cx = std::fmod((x + 0.5) * cells / size, 1.0) * 2 - 1;
      const double cy = std::fmod((size - y - 0.5) * cells / size, 1.0) * 2 - 1;
      const double r2 = cx * cx + cy * cy;
      Vec3 n{0, 0, 1};
      if (r2 < 0.8 * 0.8) n = glint::normalize(Vec3{cx, cy, std::sqrt(0.8 * 0.8 - r2)});
      film.at(x, y) = Color((n.x + 1) / 2, (n.y + 1) / 2, (n.z + 1) / 2);
    }
  }
  return film;
}

// Radiance RGBE: the shared exponent e with mantissas below 256.
void toRgbe(const Color& c, unsigned char* out) {
  const double m = std::max({c.r, c.g, c.b});
  if (m < 1e-32) {
    out[0] = out[1] = out[2] = out[3] = 0;
    return;
  }
  int e = 0;
  const double scale = std::frexp(m, &e) * 256.0 / m;
  out[0] = static_cast<unsigned char>(c.r * scale);
  out[1] = static_cast<unsigned char>(c.g * scale);
  out[2] = static_cast<unsigned char>(c.b * scale);
  out[3] = static_cast<unsigned char>(e + 128);
}

bool writeSky(const std::filesystem::path& path) {
  const int w = 1024;
  const int h = 512;
  const double pi = std::numbers::pi;
  const Vec3 sun = glint::normalize(
      Vec3{std::cos(pi / 6) * std::sqrt(0.5), std::sin(pi / 6), std::cos(pi / 6) * std::sqrt(0.5)});
  std::ofstream out(path, std::ios::binary);
  out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " << h << " +X " << w << "\n";
  std::vector<unsigned char> rgbe(static_cast<std::size_t>(w) * 4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // The inverse of u = 0.5 + atan2(d.x, −d.z)/(2π), v = 1 − acos(d.y)/π.
      const double u = (x + 0.5) / w;
      const double v = 1 - (y + 0.5) / h;
      const double theta = (1 - v) * pi;
      const double phi = (u - 0.5) * 2 * pi;
      const Vec3 d{std::sin(theta) * std::sin(phi), std::cos(theta),
                   -std::sin(theta) * std::cos(phi)};
      Color c;
      if (d.y >= 0) {
        const double t = std::pow(d.y, 0.5);
        c = Color(0.75, 0.85, 1.0) * (1 - t) + Color(0.15, 0.35, 0.85) * t;
        c *= 1.2;
      } else {
        c = Color(0.18, 0.16, 0.14) * (0.6 + 0.4 * std::exp(8 * d.y));
      }
      const double toSun = glint::dot(d, sun);
      if (toSun > std::cos(2.0 * pi / 180))
        c = Color(40, 36, 30);
      else
        c += Color(1.0, 0.8, 0.5) * (0.6 * std::pow(std::max(0.0, toSun), 64));
      toRgbe(c, rgbe.data() + 4 * x);
    }
    // Run-length scanline: 2 2 w/256 w%256, then each of the four planes as literal dumps of at
    // most 128 bytes.
    out.put(2).put(2).put(static_cast<char>(w >> 8)).put(static_cast<char>(w & 255));
    for (int plane = 0; plane < 4; ++plane) {
      for (int x = 0; x < w; x += 128) {
        const int count = std::min(128, w - x);
        out.put(static_cast<char>(count));
        for (int k = 0; k < count; ++k) out.put(static_cast<char>(rgbe[4 * (x + k) + plane]));
      }
    }
  }
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_FOLDER\n", argv[0]);
    return 2;
  }
  const std::filesystem::path folder = argv[1];
  std::filesystem::create_directories(folder);
  try {
    glint::writeImage(uvGrid(), folder / "uv_grid.png", glint::Encoding::Srgb);
    glint::writeImage(bumpsNormal(), folder / "bumps_normal.png", glint::Encoding::Linear);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_texture_images: %s\n", e.what());
    return 1;
  }
  if (!writeSky(folder / "sky.hdr")) {
    std::fprintf(stderr, "make_texture_images: cannot write %s\n", (folder / "sky.hdr").c_str());
    return 1;
  }
  std::printf("wrote uv_grid.png, bumps_normal.png and sky.hdr in %s\n", folder.c_str());
  return 0;
}
