// Analytic checks of illuminate(): attenuation, spot falloff, directional lights.
#include "glint/scene/light.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace glint {
namespace {

constexpr double kTol = 1e-14;

void expectColorNear(const Color& actual, const Color& expected, double tol = kTol) {
  EXPECT_NEAR(actual.r, expected.r, tol);
  EXPECT_NEAR(actual.g, expected.g, tol);
  EXPECT_NEAR(actual.b, expected.b, tol);
}

TEST(LightTest, PointAttenuationAtChosenDistances) {
  const Color i0(3, 6, 9);
  const PointLight light{{1, 2, 3}, i0, {1, 0.1, 0.01}};
  // d = 10 along +x: 1 + 0.1·10 + 0.01·100 = 3.
  LightSample s = illuminate(light, {11, 2, 3});
  expectColorNear(s.intensity, Color(1, 2, 3));
  EXPECT_NEAR(s.distance, 10, kTol);
  EXPECT_NEAR(s.toPoint.x, 1, kTol);
  EXPECT_NEAR(s.toPoint.y, 0, kTol);
  EXPECT_NEAR(s.toPoint.z, 0, kTol);
  // d = 5 along a 3-4-5 diagonal: 1 + 0.5 + 0.25 = 1.75.
  s = illuminate(light, {1, 2 - 3, 3 + 4});
  expectColorNear(s.intensity, i0 / 1.75);
  EXPECT_NEAR(s.distance, 5, kTol);
  EXPECT_NEAR(s.toPoint.y, -0.6, kTol);
  EXPECT_NEAR(s.toPoint.z, 0.8, kTol);
}

TEST(LightTest, PointDefaultAttenuationIsConstant) {
  const PointLight light{{0, 0, 0}, Color(0.5), {}};
  for (const double d : {0.001, 1.0, 1e6}) {
    EXPECT_EQ(illuminate(light, {0, 0, d}).intensity, Color(0.5)) << d;
  }
}

TEST(LightTest, QuadraticOnlyFalloffIsInverseSquare) {
  const PointLight light{{0, 0, 0}, Color(100), {0, 0, 1}};
  expectColorNear(illuminate(light, {0, -2, 0}).intensity, Color(25));
  expectColorNear(illuminate(light, {0, 0, 10}).intensity, Color(1));
}

TEST(LightTest, PointAtLightPositionGivesZeroWithoutNaN) {
  const PointLight point{{1, 1, 1}, Color(1), {0, 0, 1}};
  LightSample s = illuminate(point, {1, 1, 1});
  EXPECT_EQ(s.intensity, Color());
  EXPECT_TRUE(isFinite(s.toPoint));
  EXPECT_EQ(s.distance, 0);

  const SpotLight spot{{1, 1, 1}, {0, 0, 1}, Color(1), {0, 0, 1}, 2};
  s = illuminate(spot, {1, 1, 1});
  EXPECT_EQ(s.intensity, Color());
  EXPECT_TRUE(isFinite(s.toPoint));
}

TEST(LightTest, SpotFalloffAtChosenAngles) {
  const SpotLight spot{{0, 0, 0}, {0, 0, -1}, Color(2, 4, 8), {1, 0.1, 0.01}, 2};
  // On the axis at d = 10: point falloff only (÷3).
  expectColorNear(illuminate(spot, {0, 0, -10}).intensity, Color(2, 4, 8) / 3);
  // 60° off the axis at d = 10: D·l = cos 60° = 0.5, squared = 0.25.
  const double a = std::numbers::pi / 3;
  const LightSample s = illuminate(spot, {10 * std::sin(a), 0, -10 * std::cos(a)});
  expectColorNear(s.intensity, Color(2, 4, 8) / 3 * 0.25);
  EXPECT_NEAR(dot(s.toPoint, Vec3{0, 0, -1}), 0.5, kTol);
  // At 90° and behind the spot: nothing.
  EXPECT_EQ(illuminate(spot, {10, 0, 0}).intensity, Color());
  EXPECT_EQ(illuminate(spot, {0, 3, 10}).intensity, Color());
}

TEST(LightTest, SpotExponentOneIsCosine) {
  const SpotLight spot{{0, 0, 0}, {1, 0, 0}, Color(1), {}, 1};
  const double a = std::numbers::pi / 4;
  expectColorNear(illuminate(spot, {std::cos(a), std::sin(a), 0}).intensity, Color(std::cos(a)));
}

TEST(LightTest, SpotWithExponentZeroLightsOnlyItsHalfSpace) {
  const SpotLight spot{{0, 0, 0}, {1, 0, 0}, Color(1), {}, 0};
  EXPECT_EQ(illuminate(spot, {1, 5, 0}).intensity, Color(1));
  EXPECT_EQ(illuminate(spot, {-1, 5, 0}).intensity, Color());
}

TEST(LightTest, DirectionalIsConstantEverywhere) {
  const Vec3 dir = normalize(Vec3{1, -2, 2});
  const DirectionalLight light{dir, Color(0.25, 0.5, 1)};
  for (const Point3 p : {Point3{0, 0, 0}, Point3{1e6, -3, 7}, Point3{-5, 5, -5}}) {
    const LightSample s = illuminate(light, p);
    EXPECT_EQ(s.intensity, Color(0.25, 0.5, 1));
    EXPECT_EQ(s.toPoint, dir);
    EXPECT_TRUE(std::isinf(s.distance));
    EXPECT_GT(s.distance, 0);
  }
}

}  // namespace
}  // namespace glint
