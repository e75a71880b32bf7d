// Light sources of DESIGN.md §3 (the seed's LightSource family): directional, point and spot.
// Ambient light is a scene property (Scene::ambient). Closed set: std::variant, no virtual calls.
#pragma once

#include <variant>

#include "glint/core/color.h"
#include "glint/core/vec.h"

namespace glint {

// Distance attenuation 1 / (kc + kl·d + kq·d²); components ≥ 0 and not all 0.
struct Attenuation {
  double kc = 1;
  double kl = 0;
  double kq = 0;
};

// A light at infinity; `direction` (unit) is the way its light travels. No falloff.
struct DirectionalLight {
  Vec3 direction;
  Color intensity;  // color × intensity
};

// I0 / (kc + kl·d + kq·d²).
struct PointLight {
  Point3 position;
  Color intensity;  // I0 = color × intensity
  Attenuation attenuation;
};

// Point-light falloff × max(0, D·l)^exponent, D = unit `direction` the spot faces. With a falloff
// cone (Tachyon's spotlight) the factor is instead 1 within falloffStart of D, falling linearly in
// the angle to 0 at falloffEnd.
struct SpotLight {
  Point3 position;
  Vec3 direction;
  Color intensity;  // I0 = color × intensity
  Attenuation attenuation;
  double exponent = 1;
  double falloffStart = -1;  // degrees, 0 ≤ start < end ≤ 180; < 0: the exponent falloff
  double falloffEnd = -1;
};

// The angular factor of a spot light toward the unit direction l (from the light to the point).
double spotFactor(const SpotLight& light, const Vec3& l);

// An area light (soft shadows): the shape's surface stands for `samples` point lights of intensity
// I0 each, at stratified points over it; I_L(P) is their average, each attenuated by its own
// distance and shadowed by its own shadow ray (kt product per sample). Invisible to camera rays,
// like every glint light. Geometry in world space, with the keys of the object of that shape.
enum class AreaShape { Rectangle, Disk, Sphere };

struct AreaLight {
  AreaShape shape = AreaShape::Rectangle;
  Point3 corner;  // rectangle: one corner ...
  Vec3 edge1;     //   ... and two perpendicular edges from it
  Vec3 edge2;
  Point3 center;      // disk, sphere
  Vec3 normal;        // disk: unit normal (a disk light shines to both sides)
  double radius = 0;  // disk, sphere
  Color intensity;    // I0 = color × intensity, per point
  Attenuation attenuation;
  int samples = 16;  // shadow rays per shading point (≥ 1)
};

using Light = std::variant<DirectionalLight, PointLight, SpotLight, AreaLight>;

// What a light delivers to a point P.
struct LightSample {
  Vec3 toPoint;         // l: unit vector from the light to P
  double distance = 0;  // from P to the light; infinity for directional lights
  Color intensity;      // I_L(P) before shadowing
};

namespace light_detail {
// 1 / (kc + kl·d + kq·d²) applied to I0; d in scene units.
inline Color attenuate(const Color& intensity, const Attenuation& a, double d) {
  return intensity / (a.kc + a.kl * d + a.kq * d * d);
}

// l and d from a positional light to p; false when p is the light's position (l undefined).
inline bool towardPoint(const Point3& lightPosition, const Point3& p, LightSample& sample) {
  const Vec3 offset = p - lightPosition;
  const double d = length(offset);
  if (!(d > 0)) return false;
  sample.toPoint = offset / d;
  sample.distance = d;
  return true;
}
}  // namespace light_detail

// illuminate() of a point light, inline for the renderer's light loop (the variant overload below
// gives the same bits: it calls this one).
inline LightSample illuminate(const PointLight& light, const Point3& p) {
  LightSample sample;
  if (!light_detail::towardPoint(light.position, p, sample)) return sample;  // zero intensity
  sample.intensity = light_detail::attenuate(light.intensity, light.attenuation, sample.distance);
  return sample;
}

// I_L(P) and l for any light (DESIGN.md §3). P at the position of a point/spot light gives zero
// intensity (l is undefined there). An area light is treated here as one point light at its centre;
// the renderer samples its surface instead.
LightSample illuminate(const Light& light, const Point3& p);

// A point on an area light for the sample u in [0,1)², the light seen from P (world space):
//   rectangle: corner + u.x·edge1 + u.y·edge2, uniform by area;
//   disk: centre + radius·(concentric-disk point) in the disk's plane, uniform by area;
//   sphere: where a direction drawn uniformly by solid angle from the cone of directions from P
//     that meet the sphere first hits it (the cap visible from P); P inside or on the sphere: a
//     point uniform over the whole surface.
// Every such point stands for one point light of intensity I0 (DESIGN.md §3 area lights).
Point3 sampleAreaLight(const AreaLight& light, const Point3& p, const Point2& u);

// I_L(P) and l of one area-light point x, as a point light of I0 at x: attenuated by |P − x|.
// Zero intensity when P = x.
LightSample illuminateFrom(const AreaLight& light, const Point3& x, const Point3& p);

}  // namespace glint
