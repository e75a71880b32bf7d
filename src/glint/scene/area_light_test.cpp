// sampleAreaLight / illuminateFrom: where the sample points of the three area-light shapes fall.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "glint/core/sampler.h"
#include "glint/scene/light.h"

namespace glint {
namespace {

constexpr std::uint32_t kN = 1024;

Point2 pointAt(std::uint32_t i) { return scrambledSobol2D(i, 12345); }

TEST(AreaLightSampling, RectanglePointsCoverTheRectangleUniformly) {
  AreaLight light;
  light.shape = AreaShape::Rectangle;
  light.corner = {1, 2, 3};
  light.edge1 = {2, 0, 0};
  light.edge2 = {0, 0, -4};
  Vec3 mean{0, 0, 0};
  int firstQuarter = 0;  // points with local u < 0.25 along edge1
  for (std::uint32_t i = 0; i < kN; ++i) {
    const Point3 x = sampleAreaLight(light, {0, 10, 0}, pointAt(i));
    EXPECT_NEAR(x.y, 2, 1e-12);
    EXPECT_GE(x.x, 1 - 1e-12);
    EXPECT_LE(x.x, 3 + 1e-12);
    EXPECT_GE(x.z, -1 - 1e-12);
    EXPECT_LE(x.z, 3 + 1e-12);
    mean = mean + (x - Point3{0, 0, 0}) / kN;
    firstQuarter += x.x < 1.5;
  }
  EXPECT_NEAR(mean.x, 2, 1e-3);
  EXPECT_NEAR(mean.z, 1, 1e-3);
  EXPECT_EQ(firstQuarter, static_cast<int>(kN / 4));  // stratified: exactly a quarter
}

TEST(AreaLightSampling, DiskPointsLieOnTheDiskUniformlyByArea) {
  AreaLight light;
  light.shape = AreaShape::Disk;
  light.center = {0, 5, 0};
  light.normal = normalize(Vec3{1, 1, 0});
  light.radius = 2;
  int inner = 0;  // within half the radius: a quarter of the area
  for (std::uint32_t i = 0; i < kN; ++i) {
    const Point3 x = sampleAreaLight(light, {0, 0, 0}, pointAt(i));
    const Vec3 offset = x - light.center;
    EXPECT_NEAR(dot(offset, light.normal), 0, 1e-12);
    EXPECT_LE(length(offset), 2 + 1e-12);
    inner += length(offset) < 1;
  }
  EXPECT_NEAR(inner, kN / 4.0, kN * 0.01);
}

TEST(AreaLightSampling, SpherePointsLieOnTheCapVisibleFromP) {
  AreaLight light;
  light.shape = AreaShape::Sphere;
  light.center = {0, 10, 0};
  light.radius = 3;
  const Point3 p{1, 0, 0.5};
  const Vec3 axis = normalize(light.center - p);
  const double cosMax = std::sqrt(1 - 9 / lengthSquared(light.center - p));
  double meanCos = 0;
  for (std::uint32_t i = 0; i < kN; ++i) {
    const Point3 x = sampleAreaLight(light, p, pointAt(i));
    EXPECT_NEAR(distance(x, light.center), 3, 1e-9);
    // Visible from p: the surface normal there faces p.
    EXPECT_GE(dot(x - light.center, p - x), -1e-9);
    const double c = dot(normalize(x - p), axis);
    EXPECT_GE(c, cosMax - 1e-12);
    meanCos += c / kN;
  }
  // Uniform by solid angle over the cone: cos θ is uniform on [cosMax, 1].
  EXPECT_NEAR(meanCos, (1 + cosMax) / 2, 1e-5);
}

TEST(AreaLightSampling, InsideASphereThePointsCoverTheWholeSurface) {
  AreaLight light;
  light.shape = AreaShape::Sphere;
  light.center = {0, 0, 0};
  light.radius = 2;
  Vec3 mean{0, 0, 0};
  for (std::uint32_t i = 0; i < kN; ++i) {
    const Point3 x = sampleAreaLight(light, {0.5, 0.2, 0}, pointAt(i));
    EXPECT_NEAR(length(x - light.center), 2, 1e-12);
    mean = mean + (x - light.center) / kN;
  }
  EXPECT_NEAR(length(mean), 0, 1e-2);
}

TEST(AreaLightSampling, EachPointIsAPointLightOfI0) {
  AreaLight light;
  light.intensity = Color(4, 2, 1);
  light.attenuation = {1, 0, 0.5};
  const LightSample s = illuminateFrom(light, {0, 2, 0}, {0, 0, 0});
  EXPECT_NEAR(s.distance, 2, 1e-15);
  EXPECT_EQ(s.toPoint.y, -1);
  EXPECT_NEAR(s.intensity.r, 4 / 3.0, 1e-15);  // 4 / (1 + 0.5·2²)
  EXPECT_TRUE(isBlack(illuminateFrom(light, {1, 1, 1}, {1, 1, 1}).intensity));
}

}  // namespace
}  // namespace glint
