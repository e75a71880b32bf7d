// Sample patterns and warps: stratified 2D points, uniform directions in a cone or on the sphere,
// uniform points on the disk. The sample points themselves come from core/sampler.h.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "glint/core/vec.h"

namespace glint {

// Van der Corput radical inverse in base 2, scrambled by XOR with `scramble` (Kollig–Keller).
inline double radicalInverse2(std::uint32_t index, std::uint32_t scramble = 0) {
  std::uint32_t bits = index;
  bits = (bits << 16) | (bits >> 16);
  bits = ((bits & 0x00ff00ffu) << 8) | ((bits & 0xff00ff00u) >> 8);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  bits = ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
  bits ^= scramble;
  return static_cast<double>(bits) * 0x1.0p-32;
}

// Point k of an n-point stratified 2D pattern in [0,1)²: a jittered m×m grid when n = m², otherwise
// a Hammersley-style set (k + jitter)/n against the scrambled radical inverse of k. Both put
// exactly one point in each of n strata along x. jitterX/jitterY in [0,1) come from the caller's
// Rng.
inline Point2 stratified2D(std::uint32_t k, std::uint32_t n, double jitterX, double jitterY,
                           std::uint32_t scramble) {
  const auto m = static_cast<std::uint32_t>(std::lround(std::sqrt(static_cast<double>(n))));
  if (m * m == n) {
    const std::uint32_t col = k % m;
    const std::uint32_t row = k / m;
    return {(col + jitterX) / m, (row + jitterY) / m};
  }
  (void)jitterY;
  return {(k + jitterX) / n, radicalInverse2(k, scramble)};
}

// Direction uniformly distributed over the spherical cap of half-angle acos(cosMax) around the unit
// vector `axis`, whose orthonormal basis (t, b) orthonormalBasis gives; u in [0,1)² (pbrt's
// UniformSampleCone). Loops over one cone compute the basis once.
inline Vec3 sampleCone(const Vec3& axis, const Vec3& t, const Vec3& b, double cosMax,
                       const Point2& u) {
  const double cosTheta = 1 - u.x * (1 - cosMax);
  const double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
  const double phi = 2 * std::numbers::pi * u.y;
  return t * (std::cos(phi) * sinTheta) + b * (std::sin(phi) * sinTheta) + axis * cosTheta;
}

inline Vec3 sampleCone(const Vec3& axis, double cosMax, const Point2& u) {
  Vec3 t;
  Vec3 b;
  orthonormalBasis(axis, t, b);
  return sampleCone(axis, t, b, cosMax, u);
}

// Direction uniformly distributed over the unit sphere (Archimedes: z uniform in [−1, 1]); u in
// [0,1)².
inline Vec3 sampleUniformSphere(const Point2& u) {
  const double z = 1 - 2 * u.x;
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * std::numbers::pi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Point uniformly distributed on the unit disk (Shirley–Chiu concentric mapping); u in [0,1)².
inline Point2 sampleConcentricDisk(const Point2& u) {
  const double ox = 2 * u.x - 1;
  const double oy = 2 * u.y - 1;
  if (ox == 0 && oy == 0) return {0, 0};
  double r;
  double theta;
  if (std::abs(ox) > std::abs(oy)) {
    r = ox;
    theta = (std::numbers::pi / 4) * (oy / ox);
  } else {
    r = oy;
    theta = std::numbers::pi / 2 - (std::numbers::pi / 4) * (ox / oy);
  }
  return {r * std::cos(theta), r * std::sin(theta)};
}

// Direction about the unit vector `axis` (basis t, b from orthonormalBasis) with density
// cos θ / π over its hemisphere (Malley's method: a concentric-disk point lifted onto the
// hemisphere); u in [0,1)².
inline Vec3 sampleCosineHemisphere(const Vec3& axis, const Vec3& t, const Vec3& b,
                                   const Point2& u) {
  const Point2 d = sampleConcentricDisk(u);
  const double z = std::sqrt(std::max(0.0, 1 - d.x * d.x - d.y * d.y));
  return t * d.x + b * d.y + axis * z;
}

}  // namespace glint
