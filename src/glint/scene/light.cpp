// illuminate() for the closed set of lights (DESIGN.md §3).
#include "glint/scene/light.h"

#include <cmath>
#include <type_traits>

#include "glint/core/bounds.h"

namespace glint {

namespace {

// 1 / (kc + kl·d + kq·d²) applied to I0; d in scene units.
Color attenuate(const Color& intensity, const Attenuation& a, double d) {
  return intensity / (a.kc + a.kl * d + a.kq * d * d);
}

// l and d from a positional light to p; false when p is the light's position (l undefined).
bool towardPoint(const Point3& lightPosition, const Point3& p, LightSample& sample) {
  const Vec3 offset = p - lightPosition;
  const double d = length(offset);
  if (!(d > 0)) return false;
  sample.toPoint = offset / d;
  sample.distance = d;
  return true;
}

}  // namespace

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
        } else {
          if (!towardPoint(l.position, p, sample)) return sample;  // zero intensity
          sample.intensity = attenuate(l.intensity, l.attenuation, sample.distance);
          if constexpr (std::is_same_v<T, SpotLight>) {
            // A spot lights only the half-space it faces, whatever the exponent (also 0, where
            // pow(0, 0) would be 1).
            const double cosAngle = dot(l.direction, sample.toPoint);
            sample.intensity *= cosAngle > 0 ? std::pow(cosAngle, l.exponent) : 0.0;
          }
        }
        return sample;
      },
      light);
}

}  // namespace glint
