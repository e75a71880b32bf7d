// The open cone frustum (cone.cpp) and the disk's inner radius: exact hits from outside and inside,
// the open ends, tangent and axis-parallel rays, crossings, normals, bounds, (u, v), validation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "glint/core/rng.h"
#include "glint/core/spawn.h"
#include "glint/geometry/shape.h"

namespace glint {
namespace {

using ::testing::HasSubstr;

template <class Factory>
std::string errorOf(Factory&& factory) {
  try {
    (void)factory();
  } catch (const ShapeError& e) {
    return e.parameter() + ": " + e.what();
  }
  return "<no ShapeError thrown>";
}

// A cone along +z from the origin: radius 2 at z = 0, 1 at z = 4.
Cone frustum() { return Cone::make({0, 0, 0}, 2, {0, 0, 4}, 1); }

TEST(ShapeCone, HitFromOutsideAtTheRadiusOfItsHeight) {
  const Cone c = frustum();
  ShapeHit hit;
  // At z = 2 the radius is 1.5.
  ASSERT_TRUE(c.intersect(Ray{{10, 0, 2}, {-1, 0, 0}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 8.5, 1e-12);
  EXPECT_NEAR(hit.point.x, 1.5, 1e-12);
  // Outward normal: radial, tilted up by the slope 1/4 (the radius shrinks along +z).
  const double n = std::sqrt(1 + 0.25 * 0.25);
  EXPECT_NEAR(hit.normal.x, 1 / n, 1e-12);
  EXPECT_NEAR(hit.normal.z, 0.25 / n, 1e-12);
  EXPECT_EQ(c.crossings(Ray{{10, 0, 2}, {-1, 0, 0}}, 0, kInfinity), 2);
}

TEST(ShapeCone, OpenEndsLetRaysThroughAndInsideIsHit) {
  const Cone c = frustum();
  // Down the axis: no side is crossed.
  EXPECT_EQ(c.crossings(Ray{{0, 0, 10}, {0, 0, -1}}, 0, kInfinity), 0);
  // Into the open top, onto the inside of the wall at z = 1 (radius 1.75): the normal points out.
  ShapeHit hit;
  ASSERT_TRUE(c.intersect(Ray{{0, 0, 4.5}, {0.5, 0, -1}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.point.x, 1.75, 1e-12);
  EXPECT_NEAR(hit.point.z, 1, 1e-12);
  EXPECT_GT(hit.normal.x, 0);
  // Steeper, it leaves through the open base without touching the wall.
  EXPECT_EQ(c.crossings(Ray{{0, 0, 10}, {0.1, 0, -1}}, 0, kInfinity), 0);
  // Past the top (z > 4) or below the base the ray misses.
  EXPECT_EQ(c.crossings(Ray{{10, 0, 4.5}, {-1, 0, 0}}, 0, kInfinity), 0);
  EXPECT_EQ(c.crossings(Ray{{10, 0, -0.1}, {-1, 0, 0}}, 0, kInfinity), 0);
}

TEST(ShapeCone, TangentRayMissesAndTRangeIsExclusive) {
  const Cone c = Cone::make({0, 0, 0}, 1, {0, 0, 2}, 1);  // an open cylinder
  EXPECT_EQ(c.crossings(Ray{{1, -5, 1}, {0, 1, 0}}, 0, kInfinity), 0);
  ShapeHit hit;
  EXPECT_FALSE(c.intersect(Ray{{5, 0, 1}, {-1, 0, 0}}, 0, 4, hit));  // first hit at t = 4
  ASSERT_TRUE(c.intersect(Ray{{5, 0, 1}, {-1, 0, 0}}, 0, 4.0001, hit));
  EXPECT_NEAR(hit.normal.x, 1, 1e-12);
}

TEST(ShapeCone, PointedConeHitsNearItsApex) {
  const Cone c = Cone::make({0, 0, 0}, 1, {0, 0, 1}, 0);
  ShapeHit hit;
  ASSERT_TRUE(c.intersect(Ray{{5, 0, 0.9}, {-1, 0, 0}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.point.x, 0.1, 1e-12);
  // A ray parallel to a generator line (x + z = 1) crosses the other side once, at z = 0.6.
  const Vec3 along = normalize(Vec3{-1, 0, 1});
  EXPECT_EQ(c.crossings(Ray{Point3{0, 0, 0.2} - along * 10, along}, 0, kInfinity), 1);
  ASSERT_TRUE(c.intersect(Ray{Point3{0, 0, 0.2} - along * 10, along}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.point.z, 0.6, 1e-12);
}

TEST(ShapeCone, RandomRaysHitOnTheSurfaceAndNormalsAreUnit) {
  const Cone c = Cone::make({1, -2, 3}, 0.5, {-2, 4, 1}, 1.5);
  Rng rng(7);
  int hitsCount = 0;
  for (int i = 0; i < 2000; ++i) {
    const Point3 o{rng.uniform() * 20 - 10, rng.uniform() * 20 - 10, rng.uniform() * 20 - 10};
    const Point3 target{rng.uniform() * 4 - 2, rng.uniform() * 6 - 1, rng.uniform() * 4};
    const Ray ray{o, normalize(target - o)};
    ShapeHit hit;
    if (!c.intersect(ray, 0, kInfinity, hit)) continue;
    ++hitsCount;
    EXPECT_NEAR(length(toVec(hit.normal)), 1, 1e-12);
    EXPECT_TRUE(c.bounds().contains(hit.point));
    // On the surface: the radius at its height.
    const Vec3 rel = hit.point - c.base;
    const double s = dot(rel, c.axis);
    const double r = c.baseRadius + (c.apexRadius - c.baseRadius) * s / c.height;
    EXPECT_NEAR(length(rel - c.axis * s), r, 1e-9);
    // A ray spawned from the hit (core/spawn.h) does not hit the cone again at its own point.
    for (const double side : {1.0, -1.0}) {
      const Vec3 w = toVec(hit.normal) * side;
      ShapeHit again;
      if (c.intersect(spawnRay(hit.point, hit.pointError, hit.normal, w), 0, kInfinity, again)) {
        EXPECT_GT(again.t, 1e-6);
      }
    }
  }
  EXPECT_GT(hitsCount, 100);
}

TEST(ShapeCone, SurfaceCoordinates) {
  const Cone c = frustum();
  // v runs from 0 on the base rim to 1 on the apex rim; u is the angle from +x (about +z).
  const Point2 base = c.uvAt({2, 0, 0});
  EXPECT_NEAR(base.x, 0, 1e-12);
  EXPECT_NEAR(base.y, 0, 1e-12);
  const Point2 quarter = c.uvAt({0, 1.5, 2});
  EXPECT_NEAR(quarter.x, 0.25, 1e-12);
  EXPECT_NEAR(quarter.y, 0.5, 1e-12);
}

TEST(ShapeCone, MakeRejectsDegenerateInput) {
  EXPECT_THAT(errorOf([] {
                return Cone::make({0, 0, 0}, 1, {0, 0, 0}, 1);
              }),
              HasSubstr("apex: apex must differ from base"));
  // Apart, but too short for its radii: said so, not that the two points are one.
  EXPECT_THAT(errorOf([] {
                return Cone::make({0, 0, 0}, 1e12, {0, 0, 1}, 1e12);
              }),
              HasSubstr("apex: apex is 1 from base, too short for radii 1e+12 and 1e+12"));
  EXPECT_THAT(errorOf([] {
                return Cone::make({0, 0, 0}, -1, {0, 0, 1}, 1);
              }),
              HasSubstr("base_radius: base_radius must be >= 0"));
  EXPECT_THAT(errorOf([] { return Cone::make({0, 0, 0}, 0, {0, 0, 1}, 0); }), HasSubstr("both 0"));
  EXPECT_THAT(errorOf([] {
                return Cone::make({0, 0, NAN}, 1, {0, 0, 1}, 1);
              }),
              HasSubstr("base must be finite"));
}

TEST(ShapeDisk, InnerRadiusMakesARing) {
  const Disk ring = Disk::make({0, 0, 0}, {0, 0, 1}, 2, 1);
  EXPECT_EQ(ring.crossings(Ray{{0, 0, 5}, {0, 0, -1}}, 0, kInfinity), 0);    // the hole
  EXPECT_EQ(ring.crossings(Ray{{1.5, 0, 5}, {0, 0, -1}}, 0, kInfinity), 1);  // the ring
  EXPECT_EQ(ring.crossings(Ray{{2.5, 0, 5}, {0, 0, -1}}, 0, kInfinity), 0);  // outside
  EXPECT_THAT(errorOf([] {
                return Disk::make({0, 0, 0}, {0, 0, 1}, 2, 2);
              }),
              HasSubstr("inner_radius: inner_radius must be >= 0 and < radius"));
}

}  // namespace
}  // namespace glint
