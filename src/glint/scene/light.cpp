// illuminate() for the closed set of lights (DESIGN.md §3).
#include "glint/scene/light.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <type_traits>

#include "glint/core/bounds.h"
#include "glint/core/sampling.h"

namespace glint {

using light_detail::attenuate;
using light_detail::towardPoint;

LightSample illuminate(const Light& light, const Point3& p) {
  return std::visit(
      [&p](const auto& l) -> LightSample {
        using T = std::decay_t<decltype(l)>;
        LightSample sample;
        if constexpr (std::is_same_v<T, DirectionalLight>) {
          sample.toPoint = l.direction;
          sample.distance = kInfinity;
          sample.intensity = l.intensity;
        } else if constexpr (std::is_same_v<T, AreaLight>) {
          const Point3 centre =
              l.shape == AreaShape::Rectangle ? l.corner + (l.edge1 + l.edge2) * 0.5 : l.center;
          if (!towardPoint(centre, p, sample)) return sample;
          sample.intensity = attenuate(l.intensity, l.attenuation, sample.distance);
        } else if constexpr (std::is_same_v<T, PointLight>) {
          return illuminate(l, p);
        } else {
          if (!towardPoint(l.position, p, sample)) return sample;  // zero intensity
          sample.intensity = attenuate(l.intensity, l.attenuation, sample.distance);
          if constexpr (std::is_same_v<T, SpotLight>) {
            // A spot lights only the half-space it faces, whatever the exponent (also 0, where
            // pow(0, 0) would be 1).
            sample.intensity *= spotFactor(l, sample.toPoint);
          }
        }
        return sample;
      },
      light);
}

double spotFactor(const SpotLight& light, const Vec3& l) {
  const double cosAngle = dot(light.direction, l);
  if (light.falloffEnd >= 0) {
    const double angle = std::acos(std::clamp(cosAngle, -1.0, 1.0)) * (180 / std::numbers::pi);
    if (angle <= light.falloffStart) return 1;
    if (angle >= light.falloffEnd) return 0;
    return 1 - (angle - light.falloffStart) / (light.falloffEnd - light.falloffStart);
  }
  return cosAngle > 0 ? std::pow(cosAngle, light.exponent) : 0.0;
}

Point3 sampleAreaLight(const AreaLight& light, const Point3& p, const Point2& u) {
  switch (light.shape) {
    case AreaShape::Rectangle:
      return light.corner + light.edge1 * u.x + light.edge2 * u.y;
    case AreaShape::Disk: {
      const Point2 d = sampleConcentricDisk(u);
      Vec3 t;
      Vec3 b;
      orthonormalBasis(light.normal, t, b);
      return light.center + (t * d.x + b * d.y) * light.radius;
    }
    case AreaShape::Sphere:
      break;
  }
  const Vec3 toCenter = light.center - p;
  const double dc2 = lengthSquared(toCenter);
  const double r2 = light.radius * light.radius;
  if (!(dc2 > r2)) return light.center + sampleUniformSphere(u) * light.radius;
  // Uniform in solid angle over the cone of half-angle θmax, sin θmax = r/dc, around the axis
  // P → centre (pbrt's sphere sampling). 1 − cos is formed as sin²/(1 + cos) so that a small or
  // distant sphere keeps its cone instead of rounding to a single direction.
  const double dc = std::sqrt(dc2);
  const Vec3 axis = toCenter / dc;
  const double sin2Max = r2 / dc2;
  const double cosMax = std::sqrt(std::max(0.0, 1 - sin2Max));
  const double oneMinusCos = u.x * (sin2Max / (1 + cosMax));
  const double cosTheta = 1 - oneMinusCos;
  const double sin2Theta = std::max(0.0, oneMinusCos * (2 - oneMinusCos));
  const double sinTheta = std::sqrt(sin2Theta);
  const double phi = 2 * std::numbers::pi * u.y;
  Vec3 t;
  Vec3 b;
  orthonormalBasis(axis, t, b);
  const Vec3 w = t * (std::cos(phi) * sinTheta) + b * (std::sin(phi) * sinTheta) + axis * cosTheta;
  // The near intersection of P + s·w with the sphere: s = dc·cosθ − sqrt(r² − dc²·sin²θ).
  const double s = dc * cosTheta - std::sqrt(std::max(0.0, r2 - dc2 * sin2Theta));
  return p + w * s;
}

LightSample illuminateFrom(const AreaLight& light, const Point3& x, const Point3& p) {
  LightSample sample;
  if (!towardPoint(x, p, sample)) return sample;
  sample.intensity = attenuate(light.intensity, light.attenuation, sample.distance);
  return sample;
}

}  // namespace glint
