// Background lookups: gradient and equirectangular image.
#include "glint/scene/environment.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace glint {

Point2 equirectangularUv(const Vec3& d) {
  return {0.5 + std::atan2(d.x, -d.z) / (2 * std::numbers::pi),
          1 - std::acos(std::clamp(d.y, -1.0, 1.0)) / std::numbers::pi};
}

Color Environment::along(const Vec3& d, const Color& uniform, const Point3& origin) const {
  switch (kind) {
    case BackgroundKind::Uniform:
      return uniform;
    case BackgroundKind::Sky: {
      const double t = skyByHeight ? dot(toVec(origin), skyUp) : dot(d, skyUp);
      const double f = std::clamp((t - bottomValue) / (topValue - bottomValue), 0.0, 1.0);
      return skyBottom + (skyTop - skyBottom) * f;
    }
    case BackgroundKind::Gradient: {
      const double elevation =
          std::asin(std::clamp(d.y, -1.0, 1.0)) / (std::numbers::pi / 2);  // −1 .. 1
      return elevation >= 0 ? horizon * (1 - elevation) + zenith * elevation
                            : horizon * (1 + elevation) + nadir * -elevation;
    }
    case BackgroundKind::Image:
      break;
  }
  // The picture turned by +rotate about +y: look up the direction turned by −rotate.
  return image->bilinear(0, equirectangularUv(toImage(d)), /*clampRows=*/true) * intensity;
}

Vec3 Environment::toImage(const Vec3& d) const {
  return {cosRotate * d.x - sinRotate * d.z, d.y, sinRotate * d.x + cosRotate * d.z};
}

Vec3 Environment::fromImage(const Vec3& d) const {
  return {cosRotate * d.x + sinRotate * d.z, d.y, -sinRotate * d.x + cosRotate * d.z};
}

std::shared_ptr<const EnvironmentSampler> EnvironmentSampler::make(const Environment& environment) {
  if (environment.kind != BackgroundKind::Image || !environment.image ||
      !(environment.intensity > 0)) {
    return nullptr;
  }
  const MipMap& image = *environment.image;
  int level = 0;
  while (level + 1 < image.levels() && image.width(level) > kEnvironmentSamplingWidth) ++level;
  std::shared_ptr<EnvironmentSampler> sampler(new EnvironmentSampler(environment, level));
  if (!(sampler->rowCdf_.back() > 0)) return nullptr;  // a black image: nothing to sample
  return sampler;
}

EnvironmentSampler::EnvironmentSampler(const Environment& environment, int level)
    : environment_(environment),
      width_(environment.image->width(level)),
      height_(environment.image->height(level)) {
  const MipMap& image = *environment.image;
  const auto w = static_cast<std::size_t>(width_);
  const auto h = static_cast<std::size_t>(height_);
  texelWeight_.resize(w * h);
  columnCdf_.resize((w + 1) * h);
  rowWeight_.resize(h);
  rowCdf_.assign(h + 1, 0);
  double total = 0;
  for (std::size_t y = 0; y < h; ++y) {
    // Row y (from the top) spans θ in [y, y + 1]·π/h; its texels' solid angle goes as sin θ.
    const double sinTheta = std::sin((static_cast<double>(y) + 0.5) * std::numbers::pi / height_);
    double row = 0;
    double* cdf = &columnCdf_[y * (w + 1)];
    cdf[0] = 0;
    for (std::size_t x = 0; x < w; ++x) {
      const Color c = image.texel(level, static_cast<int>(x), static_cast<int>(y));
      const double luminance = std::max(0.0, 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b);
      texelWeight_[y * w + x] = luminance;
      row += luminance;
      cdf[x + 1] = row;
    }
    for (std::size_t x = 0; x < w; ++x) {
      texelWeight_[y * w + x] = row > 0 ? texelWeight_[y * w + x] / row : 0;
      cdf[x + 1] = row > 0 ? cdf[x + 1] / row : static_cast<double>(x + 1) / width_;
    }
    rowWeight_[y] = row * sinTheta;
    total += rowWeight_[y];
    rowCdf_[y + 1] = total;
  }
  for (std::size_t y = 0; y < h; ++y) {
    rowWeight_[y] = total > 0 ? rowWeight_[y] / total : 0;
    rowCdf_[y + 1] = total > 0 ? rowCdf_[y + 1] / total : 0;
  }
  if (total > 0) rowCdf_[h] = 1;
}

int EnvironmentSampler::find(const double* cdf, int n, double u) {
  // upper_bound over cdf[1..n]: the first entry above u, minus one.
  const double* it = std::upper_bound(cdf + 1, cdf + n + 1, u);
  return std::clamp(static_cast<int>(it - cdf) - 1, 0, n - 1);
}

Vec3 EnvironmentSampler::sample(const Point2& u, double& pdf) const {
  const auto w = static_cast<std::size_t>(width_);
  const int y = find(rowCdf_.data(), height_, u.x);
  const double* cdf = &columnCdf_[static_cast<std::size_t>(y) * (w + 1)];
  const int x = find(cdf, width_, u.y);
  // The point inside the texel, from where u falls between the two cdf steps.
  const double rowSpan = rowCdf_[y + 1] - rowCdf_[y];
  const double columnSpan = cdf[x + 1] - cdf[x];
  const double dy = rowSpan > 0 ? std::clamp((u.x - rowCdf_[y]) / rowSpan, 0.0, 1.0) : 0.5;
  const double dx = columnSpan > 0 ? std::clamp((u.y - cdf[x]) / columnSpan, 0.0, 1.0) : 0.5;
  const double s = (x + dx) / width_;                          // image u
  const double theta = (y + dy) / height_ * std::numbers::pi;  // from +y
  const double phi = (s - 0.5) * 2 * std::numbers::pi;
  const double sinTheta = std::sin(theta);
  const Vec3 inImage{sinTheta * std::sin(phi), std::cos(theta), -sinTheta * std::cos(phi)};
  // Density over the unit square: the texel's share × texels; over solid angle ÷ 2π² sin θ.
  const double square = rowWeight_[static_cast<std::size_t>(y)] *
                        texelWeight_[static_cast<std::size_t>(y) * w + x] * width_ * height_;
  pdf = sinTheta > 0 ? square / (2 * std::numbers::pi * std::numbers::pi * sinTheta) : 0;
  return environment_.fromImage(inImage);
}

double EnvironmentSampler::pdf(const Vec3& d) const {
  const Vec3 inImage = environment_.toImage(d);
  const Point2 uv = equirectangularUv(inImage);
  const int x = std::clamp(static_cast<int>(uv.x * width_), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>((1 - uv.y) * height_), 0, height_ - 1);
  const double sinTheta = std::sqrt(std::max(0.0, 1 - inImage.y * inImage.y));
  if (!(sinTheta > 0)) return 0;
  const double square =
      rowWeight_[static_cast<std::size_t>(y)] *
      texelWeight_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                   static_cast<std::size_t>(x)] *
      width_ * height_;
  return square / (2 * std::numbers::pi * std::numbers::pi * sinTheta);
}

}  // namespace glint
