// Texture evaluation: the solid checker, the uv checker, the Perlin patterns and image lookups.
#include "glint/scene/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace glint {

namespace {

// Ken Perlin's reference permutation (improved noise, SIGGRAPH 2002), repeated to 512 entries.
constexpr std::array<std::uint8_t, 256> kPermutation = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103,
    30,  69,  142, 8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,
    197, 62,  94,  252, 219, 203, 117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174,
    20,  125, 136, 171, 168, 68,  175, 74,  165, 71,  134, 139, 48,  27,  166, 77,  146, 158, 231,
    83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,  55,  46,  245, 40,  244, 102, 143,
    54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,  18,  169, 200, 196,
    135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250, 124,
    123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,
    182, 189, 28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101,
    155, 167, 43,  172, 9,   129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185,
    112, 104, 218, 246, 97,  228, 251, 34,  242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,
    51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,  181, 199, 106, 157, 184, 84,  204, 176,
    115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114, 67,  29,  24,  72,  243,
    141, 128, 195, 78,  66,  215, 61,  156, 180};

int permutation(int i) { return kPermutation[static_cast<std::size_t>(i & 255)]; }

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
double lerp(double t, double a, double b) { return a + t * (b - a); }

// The dot product of one of the 12 cube-edge gradients (chosen by the hash) with (x, y, z).
double gradient(int hash, double x, double y, double z) {
  const int h = hash & 15;
  const double u = h < 8 ? x : y;
  const double v = h < 4 ? y : (h == 12 || h == 14 ? x : z);
  return ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v);
}

Color blend(const std::array<Color, 2>& colors, double t) {
  return colors[0] * (1 - t) + colors[1] * t;
}

// Σ_k |noise(2^k·p)| / 2^k over `octaves` terms.
double turbulence(const Point3& p, int octaves) {
  double sum = 0;
  double frequency = 1;
  for (int k = 0; k < octaves; ++k) {
    sum += std::abs(perlinNoise(Point3{p.x * frequency, p.y * frequency, p.z * frequency})) /
           frequency;
    frequency *= 2;
  }
  return sum;
}

// Largest magnitude of a lookup coordinate kept exact enough for floor(): beyond it a checker or a
// noise cell is meaningless anyway (and a cast to int would overflow).
constexpr double kLargestCoordinate = 1e15;
double tame(double x) {
  return std::isfinite(x) ? std::clamp(x, -kLargestCoordinate, kLargestCoordinate) : 0;
}

Color evaluateNoise(const NoiseTexture& t, const Point3& objectPoint) {
  const Point3 p{tame((objectPoint.x - t.center.x) / t.scale),
                 tame((objectPoint.y - t.center.y) / t.scale),
                 tame((objectPoint.z - t.center.z) / t.scale)};
  double value = 0;
  switch (t.pattern) {
    case NoisePattern::Noise: {
      double sum = 0;
      double frequency = 1;
      for (int k = 0; k < t.octaves; ++k) {
        sum += perlinNoise(Point3{p.x * frequency, p.y * frequency, p.z * frequency}) / frequency;
        frequency *= 2;
      }
      value = 0.5 + 0.5 * sum;
      break;
    }
    case NoisePattern::Marble:
      value =
          0.5 + 0.5 * std::sin(std::numbers::pi * (p.x + t.turbulence * turbulence(p, t.octaves)));
      break;
    case NoisePattern::Wood: {
      const double ring =
          std::sqrt(p.x * p.x + p.z * p.z) + t.turbulence * turbulence(p, t.octaves);
      value = ring - std::floor(ring);
      break;
    }
  }
  return blend(t.colors, std::clamp(value, 0.0, 1.0));
}

// The odd cells' share of [0, x] along one axis of a checkerboard of unit cells: the integral of
// the square wave that is 1 on odd cells (pbrt-v3's closed-form checkerboard filter).
double oddShare(double x) {
  const double half = x / 2;
  return std::floor(half) + 2 * std::max(half - std::floor(half) - 0.5, 0.0);
}

// The uv checker, box-filtered over the lookup's footprint in closed form (pbrt-v3's
// Checkerboard2DTexture): a footprint inside one cell gives that cell's colour exactly; a wider
// one the share of odd cells under it, so a distant checker floor fades to the mean instead of
// aliasing.
Color evaluateChecker2d(const Checker2dTexture& t, const TextureLookup& at) {
  const Point2 st = t.transform.apply(at.uv);
  const double s = tame(st.x);
  const double u = tame(st.y);
  const Point2 dx = t.transform.applyLinear(at.duvdx);
  const Point2 dy = t.transform.applyLinear(at.duvdy);
  const double ds = std::min(std::max(std::abs(dx.x), std::abs(dy.x)), 1e6);
  const double dt = std::min(std::max(std::abs(dx.y), std::abs(dy.y)), 1e6);
  if (std::floor(s - ds) == std::floor(s + ds) && std::floor(u - dt) == std::floor(u + dt)) {
    const double cells = std::floor(s) + std::floor(u);
    return t.colors[std::fmod(std::abs(cells), 2.0) == 1 ? 1 : 0];
  }
  const double oddS = ds > 0 ? (oddShare(s + ds) - oddShare(s - ds)) / (2 * ds)
                             : std::fmod(std::abs(std::floor(s)), 2.0);
  const double oddT = dt > 0 ? (oddShare(u + dt) - oddShare(u - dt)) / (2 * dt)
                             : std::fmod(std::abs(std::floor(u)), 2.0);
  // A cell is odd when exactly one of its two indices is.
  const double odd = std::clamp(oddS + oddT - 2 * oddS * oddT, 0.0, 1.0);
  return blend(t.colors, odd);
}

Color evaluateImage(const ImageTexture& t, const TextureLookup& at) {
  const Point2 st = t.transform.apply(at.uv);
  switch (t.filter) {
    case TextureFilter::Nearest:
      return t.image->nearest(st);
    case TextureFilter::Bilinear:
      return t.image->bilinear(0, st);
    case TextureFilter::Trilinear:
      break;
  }
  const Point2 dx = t.transform.applyLinear(at.duvdx);
  const Point2 dy = t.transform.applyLinear(at.duvdy);
  const double width =
      2 * std::max({std::abs(dx.x), std::abs(dx.y), std::abs(dy.x), std::abs(dy.y)});
  return t.image->trilinear(st, width);
}

}  // namespace

namespace {

// The lattice cell of an integral coordinate, modulo 256. Past 2^62 (an octave's frequency takes a
// tamed 1e15 there) the exact fmod brings it into int64's range first, so the cast is defined and
// gives the same low eight bits; a non-finite coordinate takes cell 0.
int latticeCell(double cell) {
  if (!(std::abs(cell) < 0x1p62)) cell = std::isfinite(cell) ? std::fmod(cell, 256.0) : 0;
  return static_cast<int>(static_cast<std::int64_t>(cell) & 255);
}

}  // namespace

double perlinNoise(const Point3& p) {
  const double fx = std::floor(p.x);
  const double fy = std::floor(p.y);
  const double fz = std::floor(p.z);
  const int X = latticeCell(fx);
  const int Y = latticeCell(fy);
  const int Z = latticeCell(fz);
  const double x = p.x - fx;
  const double y = p.y - fy;
  const double z = p.z - fz;
  const double u = fade(x);
  const double v = fade(y);
  const double w = fade(z);
  const int A = permutation(X) + Y;
  const int AA = permutation(A) + Z;
  const int AB = permutation(A + 1) + Z;
  const int B = permutation(X + 1) + Y;
  const int BA = permutation(B) + Z;
  const int BB = permutation(B + 1) + Z;
  return lerp(
      w,
      lerp(v, lerp(u, gradient(permutation(AA), x, y, z), gradient(permutation(BA), x - 1, y, z)),
           lerp(u, gradient(permutation(AB), x, y - 1, z),
                gradient(permutation(BB), x - 1, y - 1, z))),
      lerp(v,
           lerp(u, gradient(permutation(AA + 1), x, y, z - 1),
                gradient(permutation(BA + 1), x - 1, y, z - 1)),
           lerp(u, gradient(permutation(AB + 1), x, y - 1, z - 1),
                gradient(permutation(BB + 1), x - 1, y - 1, z - 1))));
}

Color meanOf(const Texture& texture) {
  if (const auto* t = std::get_if<ImageTexture>(&texture)) {
    return t->image->texel(t->image->levels() - 1, 0, 0);
  }
  return std::visit(
      [](const auto& t) -> Color {
        if constexpr (requires { t.colors; }) {
          return (t.colors[0] + t.colors[1]) * 0.5;
        } else {
          return Color(1);
        }
      },
      texture);
}

bool usesUv(const Texture& texture) {
  return std::holds_alternative<Checker2dTexture>(texture) ||
         std::holds_alternative<ImageTexture>(texture);
}

namespace {

// The solid checker's cell index along one axis: floor((coordinate − center) / scale), except
// that a value within the rounding of its inputs of a cell boundary counts as on it. A face lying
// on a boundary (a unit box's sides under a checker of scale 0.5) is hit exactly on it when the
// box is untransformed, but a transformed one's hit point comes back through the inverse transform
// a few ulps either side, and floor alone then flips between the two cells from pixel to pixel.
// The slack is 64 ulps of the coordinate, the center and a cell (near the origin the errors are
// those of the object's size, not of zero), in cells, and never more than 1e-6 of a cell: where
// rounding errors are larger than that, no snapping could make a face one colour.
double checkerCell(double coordinate, double center, double scale) {
  const double x = tame((coordinate - center) / scale);
  const double boundary = std::nearbyint(x);
  constexpr double kUlp = std::numeric_limits<double>::epsilon();
  const double slack =
      std::min(64 * kUlp * (std::abs(coordinate) + std::abs(center) + scale) / scale, 1e-6);
  if (std::abs(x - boundary) <= slack) return boundary;
  return std::floor(x);
}

}  // namespace

Color evaluate(const Texture& texture, const TextureLookup& at) {
  if (const auto* t = std::get_if<ImageTexture>(&texture)) return evaluateImage(*t, at);
  if (const auto* t = std::get_if<CheckerTexture>(&texture)) {
    const Point3& p = at.objectPoint;
    const Point3& c = t->center;
    const double cells = checkerCell(p.x, c.x, t->scale) + checkerCell(p.y, c.y, t->scale) +
                         checkerCell(p.z, c.z, t->scale);
    return t->colors[std::fmod(std::abs(cells), 2.0) == 1 ? 1 : 0];
  }
  if (const auto* t = std::get_if<Checker2dTexture>(&texture)) return evaluateChecker2d(*t, at);
  return evaluateNoise(std::get<NoiseTexture>(texture), at.objectPoint);
}

}  // namespace glint
