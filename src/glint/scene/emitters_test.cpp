// EmitterSampler: every sampled point lies on its emitter with the emitter's normal, the density
// is one over the emitter's area (boxes, ellipses, rings, cylinders with their caps, cone sides,
// spheres, under the transforms that keep them sampled), and the points spread by area.
#include "glint/scene/emitters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "glint/core/transform.h"
#include "glint/geometry/shape.h"

namespace glint {
namespace {

constexpr double kPi = std::numbers::pi;

Transform scaling(double x, double y, double z) {
  Matrix4 m = Matrix4::identity();
  m.m[0][0] = x;
  m.m[1][1] = y;
  m.m[2][2] = z;
  return Transform(m);
}

// A rotation by 30° about (1, 1, 0)/√2, a uniform scale `s` and a translation: a similarity.
Transform similarity(double s) {
  const Vec3 axis = normalize(Vec3{1, 1, 0});
  const double c = std::cos(kPi / 6);
  const double sn = std::sin(kPi / 6);
  Matrix4 m = Matrix4::identity();
  const double a[3] = {axis.x, axis.y, axis.z};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double r = (i == j ? c : 0) + (1 - c) * a[i] * a[j];
      if (i == 0 && j == 1) r -= sn * a[2];
      if (i == 1 && j == 0) r += sn * a[2];
      if (i == 0 && j == 2) r += sn * a[1];
      if (i == 2 && j == 0) r -= sn * a[1];
      if (i == 1 && j == 2) r -= sn * a[0];
      if (i == 2 && j == 1) r += sn * a[0];
      m.m[i][j] = s * r;
    }
  }
  m.m[0][3] = 0.5;
  m.m[1][3] = -1;
  m.m[2][3] = 2;
  return Transform(m);
}

struct Case {
  std::string name;
  Primitive primitive;
  double area;  // analytic, world space
};

std::vector<Case> cases() {
  const Color glow(2, 1, 0.5);
  std::vector<Case> out;
  out.push_back({"box under a non-uniform scale",
                 Primitive(Box::make({0, 0, 0}, {1, 1, 1}), 0, glow, scaling(2, 3, 4)),
                 2 * (2 * 3 + 2 * 4 + 3 * 4)});
  out.push_back({"disk under a non-uniform scale (an ellipse)",
                 Primitive(Disk::make({0, 0, 0}, {0, 0, 1}, 1), 0, glow, scaling(2, 3, 1)),
                 kPi * 2 * 3});
  out.push_back(
      {"ring", Primitive(Disk::make({1, 2, 3}, {1, 1, 1}, 1, 0.5), 0, glow), kPi * (1 - 0.25)});
  out.push_back({"capped cylinder under a similarity",
                 Primitive(Cylinder::make({0, 0, 0}, {0, 0, 1}, 0.5, 2), 0, glow, similarity(2)),
                 4 * (2 * kPi * 0.5 * 2 + 2 * kPi * 0.25)});
  out.push_back({"cone frustum", Primitive(Cone::make({0, 0, 0}, 1, {0, 2, 0}, 0.5), 0, glow),
                 kPi * 1.5 * std::sqrt(4 + 0.25)});
  out.push_back({"cone to a point under a similarity",
                 Primitive(Cone::make({0, 0, 0}, 1, {0, 0, 3}, 0), 0, glow, similarity(0.5)),
                 0.25 * kPi * 1 * std::sqrt(9 + 1)});
  out.push_back({"sphere under a similarity",
                 Primitive(Sphere::make({1, 0, 0}, 1), 0, glow, similarity(3)), 4 * kPi * 9});
  return out;
}

std::shared_ptr<const EmitterSampler> samplerOf(const Primitive& primitive) {
  return EmitterSampler::make({primitive}, {}, {Material{}}, {});
}

// Where a ray from just outside the sampled point, against its normal, meets the emitter.
std::optional<ShapeHit> hitBack(const Primitive& primitive, const EmitterSampler::Sample& s,
                                double offset) {
  const Vec3 n = toVec(s.normal);
  ShapeHit hit;
  if (!primitive.intersect(Ray{s.point + n * offset, -n}, 0, 2 * offset, hit)) return std::nullopt;
  return hit;
}

TEST(EmitterSampler, PointsLieOnTheEmitterWithItsNormalAtOneOverItsArea) {
  for (const Case& c : cases()) {
    const auto sampler = samplerOf(c.primitive);
    ASSERT_NE(sampler, nullptr) << c.name;
    const double offset = 1e-3 * std::sqrt(c.area);
    int checked = 0;
    for (int i = 0; i < 32; ++i) {
      for (int j = 0; j < 32; ++j) {
        const EmitterSampler::Sample s = sampler->sample({(i + 0.5) / 32, (j + 0.37) / 32});
        EXPECT_NEAR(s.areaPdf * c.area, 1, 1e-9) << c.name;
        EXPECT_EQ(s.emission, Color(2, 1, 0.5)) << c.name;
        const std::optional<ShapeHit> hit = hitBack(c.primitive, s, offset);
        // Points on a rim may be missed by the ray back; every other one is on the surface.
        if (!hit) continue;
        ++checked;
        EXPECT_NEAR(hit->t, offset, 1e-7 * offset + 1e-9) << c.name;
        EXPECT_NEAR(std::abs(dot(toVec(hit->normal), s.normal)), 1, 1e-9) << c.name;
        Hit asHit;
        EXPECT_EQ(sampler->areaPdf(asHit, Color(2, 1, 0.5)), s.areaPdf) << c.name;
      }
    }
    EXPECT_GT(checked, 1000) << c.name;
  }
}

// The points spread by area: on a cylinder 0.5 wide and 2 high the caps take 2πr² of
// 2πr² + 2πrh (a fifth); on a frustum of radii 1 and 0.5 the mean height is
// ∫v·ρ(v) dv / ∫ρ(v) dv = (1/3)/(3/4) of the height.
TEST(EmitterSampler, PointsSpreadByArea) {
  const Primitive cylinder(Cylinder::make({0, 0, 0}, {0, 0, 1}, 0.5, 2), 0, Color(1));
  const Primitive cone(Cone::make({0, 0, 0}, 1, {0, 0, 2}, 0.5), 0, Color(1));
  const auto cylinderSampler = samplerOf(cylinder);
  const auto coneSampler = samplerOf(cone);
  ASSERT_NE(cylinderSampler, nullptr);
  ASSERT_NE(coneSampler, nullptr);
  constexpr int kSide = 128;
  int onCaps = 0;
  double height = 0;
  for (int i = 0; i < kSide; ++i) {
    for (int j = 0; j < kSide; ++j) {
      const Point2 u{(i + 0.5) / kSide, (j + 0.5) / kSide};
      const EmitterSampler::Sample s = cylinderSampler->sample(u);
      if (std::abs(s.normal.z) > 0.5) ++onCaps;
      height += coneSampler->sample(u).point.z / 2;
    }
  }
  // u.x chooses between side and caps: the grid's step in it, 1/128, bounds the share's error.
  EXPECT_NEAR(onCaps / double(kSide * kSide), 0.2, 1.0 / kSide);
  EXPECT_NEAR(height / (kSide * kSide), (1.0 / 3) / 0.75, 0.002);
}

// Round shapes under a non-uniform scale are no longer spheres, cylinders or cones: they are not
// sampled (the paths that meet them find them), and their hits have density 0.
TEST(EmitterSampler, RoundShapesUnderANonUniformScaleAreNotSampled) {
  EXPECT_EQ(samplerOf(Primitive(Sphere::make({0, 0, 0}, 1), 0, Color(1), scaling(1, 2, 1))),
            nullptr);
  EXPECT_EQ(samplerOf(Primitive(Cylinder::make({0, 0, 0}, {0, 0, 1}, 1, 1), 0, Color(1),
                                scaling(2, 1, 1))),
            nullptr);
  EXPECT_EQ(samplerOf(Primitive(Plane::make({0, 0, 0}, {0, 0, 1}), 0, Color(1))), nullptr);
}

}  // namespace
}  // namespace glint
