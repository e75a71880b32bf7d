// Properties of every analytic shape and of Primitive: exact hits, the boundary conventions of
// shape.h (exclusive t range, tangent and parallel misses, rays starting on the surface),
// crossings, bounds, normals, input validation, and watertightness of the triangle test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "glint/core/rng.h"
#include "glint/geometry/shape.h"

namespace glint {
namespace {

using ::testing::HasSubstr;

constexpr double kTol = 1e-12;
const double kSqrt2 = std::sqrt(2.0);

// The ShapeError message of a factory call, or a marker when it did not throw one.
template <class Factory>
std::string errorOf(Factory&& factory) {
  try {
    (void)factory();
  } catch (const ShapeError& e) {
    return e.what();
  }
  return "<no ShapeError thrown>";
}

#define EXPECT_VEC_NEAR(actual, ex, ey, ez, tol) \
  do {                                           \
    const auto v_ = (actual);                    \
    EXPECT_NEAR(v_.x, (ex), (tol));              \
    EXPECT_NEAR(v_.y, (ey), (tol));              \
    EXPECT_NEAR(v_.z, (ez), (tol));              \
  } while (0)

// Intersects with the default open range (0, ∞) and returns whether it hit.
template <class S>
bool hits(const S& shape, const Ray& ray, ShapeHit& hit, double tMin = 0, double tMax = kInfinity) {
  return shape.intersect(ray, tMin, tMax, hit);
}
template <class S>
bool hits(const S& shape, const Ray& ray) {
  ShapeHit hit;
  return shape.intersect(ray, 0, kInfinity, hit);
}

// ------------------------------------------------------------------------------------ Sphere

TEST(ShapeSphere, HitFromOutsideGivesNearRootAndOutwardNormal) {
  const Sphere s = Sphere::make({0, 0, -10}, 2);
  ShapeHit hit;
  ASSERT_TRUE(hits(s, Ray{{0, 0, 0}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 8);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  // Off-centre: the 3-4-5 point of a radius-5 sphere.
  const Sphere big = Sphere::make({0, 0, 0}, 5);
  ASSERT_TRUE(hits(big, Ray{{3, 0, 10}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 6);
  EXPECT_VEC_NEAR(hit.normal, 0.6, 0, 0.8, kTol);
}

TEST(ShapeSphere, NonUnitDirectionScalesT) {
  const Sphere s = Sphere::make({0, 0, -10}, 2);
  ShapeHit hit;
  ASSERT_TRUE(hits(s, Ray{{0, 0, 0}, {0, 0, -4}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  ASSERT_TRUE(hits(s, Ray{{0, 0, 0}, {0, 0, -0.5}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 16);
}

TEST(ShapeSphere, FromInsideHitsFarSideWithOutwardNormal) {
  const Sphere s = Sphere::make({1, 1, 1}, 2);
  ShapeHit hit;
  ASSERT_TRUE(hits(s, Ray{{1, 1, 1}, {1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  EXPECT_EQ(s.crossings(Ray{{1, 1, 1}, {1, 0, 0}}, 0, kInfinity), 1);
}

TEST(ShapeSphere, TangentRayMissesAndJustInsideHits) {
  const Sphere s = Sphere::make({0, 0, 0}, 2);
  const Ray tangent{{2, 0, 10}, {0, 0, -1}};
  EXPECT_FALSE(hits(s, tangent));
  EXPECT_EQ(s.crossings(tangent, 0, kInfinity), 0);
  EXPECT_TRUE(hits(s, Ray{{2 - 1e-9, 0, 10}, {0, 0, -1}}));
  EXPECT_FALSE(hits(s, Ray{{2 + 1e-9, 0, 10}, {0, 0, -1}}));
}

TEST(ShapeSphere, StartingOnSurface) {
  const Sphere s = Sphere::make({0, 0, 0}, 5);
  ShapeHit hit;
  // Leaving: the root at t = 0 is excluded.
  EXPECT_FALSE(hits(s, Ray{{0, 0, 5}, {0, 0, 1}}));
  EXPECT_FALSE(hits(s, Ray{{3, 4, 0}, {3, 4, 0}}));
  // Entering: the far side.
  ASSERT_TRUE(hits(s, Ray{{0, 0, 5}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 10);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, kTol);
  ASSERT_TRUE(hits(s, Ray{{3, 4, 0}, {-3, -4, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, -0.6, -0.8, 0, kTol);
  EXPECT_EQ(s.crossings(Ray{{3, 4, 0}, {-3, -4, 0}}, 0, kInfinity), 1);
}

TEST(ShapeSphere, BehindMisses) {
  const Sphere s = Sphere::make({0, 0, 10}, 2);
  EXPECT_FALSE(hits(s, Ray{{0, 0, 0}, {0, 0, -1}}));
  EXPECT_EQ(s.crossings(Ray{{0, 0, 0}, {0, 0, -1}}, 0, kInfinity), 0);
}

TEST(ShapeSphere, TRangeIsExclusive) {
  const Sphere s = Sphere::make({0, 0, -10}, 2);
  const Ray ray{{0, 0, 0}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(s, ray, hit, 0, 8));
  EXPECT_FALSE(hits(s, ray, hit, 0, 7.999));
  ASSERT_TRUE(hits(s, ray, hit, 0, std::nextafter(8.0, 9.0)));
  EXPECT_DOUBLE_EQ(hit.t, 8);
  // tMin at the near root: the far root is next.
  ASSERT_TRUE(hits(s, ray, hit, 8, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, 12);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, kTol);
  EXPECT_FALSE(hits(s, ray, hit, 12, kInfinity));
}

TEST(ShapeSphere, CrossingsCountRootsInRange) {
  const Sphere s = Sphere::make({0, 0, -10}, 2);
  const Ray ray{{0, 0, 0}, {0, 0, -1}};
  EXPECT_EQ(s.crossings(ray, 0, kInfinity), 2);
  EXPECT_EQ(s.crossings(ray, 0, 10), 1);
  EXPECT_EQ(s.crossings(ray, 0, 8), 0);
  EXPECT_EQ(s.crossings(ray, 9, 11), 0);
  EXPECT_EQ(s.crossings(ray, 8, 12), 0);
  EXPECT_EQ(s.crossings(ray, 7.5, 12.5), 2);
}

// A sphere wholly behind the ray (origin outside, moving away) is decided without its roots; the
// roots still count where the range reaches back to them (tMin < 0).
TEST(ShapeSphere, WhollyBehindOnlyHitsWithNegativeTMin) {
  const Sphere s = Sphere::make({0, 0, 0}, 2);
  const Ray away{{0, 0, 10}, {0, 0, 1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(s, away, hit, 0, kInfinity));
  EXPECT_FALSE(hits(s, away, hit, -0.0, kInfinity));
  EXPECT_EQ(s.crossings(away, 0, kInfinity), 0);
  EXPECT_EQ(s.crossings(away, -kInfinity, kInfinity), 2);
  EXPECT_EQ(s.crossings(away, -9, kInfinity), 1);
  ASSERT_TRUE(hits(s, away, hit, -20, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, -12);
  // Moving sideways (f·d = 0, the boundary of "away"): the line passes 10 from the centre.
  EXPECT_EQ(s.crossings(Ray{{0, 0, 10}, {1, 0, 0}}, -kInfinity, kInfinity), 0);
  // Sideways from inside (|f|² − r² < 0): the roots lie on both sides of the origin.
  EXPECT_EQ(s.crossings(Ray{{0, 0, 1.5}, {1, 0, 0}}, 0, kInfinity), 1);
}

// The early-outs agree with the roots: random rays against a reference computed in long double
// (rays whose roots come within 1e-9 of a range end are skipped, where rounding may decide).
TEST(ShapeSphere, CrossingsMatchLongDoubleRoots) {
  const Sphere s = Sphere::make({0.5, -1, 2}, 1.5);
  Rng rng(7);
  int compared = 0;
  for (int i = 0; i < 4000; ++i) {
    const Point3 o{6 * rng.uniform() - 2.5, 6 * rng.uniform() - 4, 6 * rng.uniform() - 1};
    const Vec3 d{2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1};
    const double tMin = i % 3 == 0 ? -1.0 : 0.0;
    const long double fx = o.x - 0.5L, fy = o.y + 1.0L, fz = o.z - 2.0L;
    const long double a = static_cast<long double>(d.x) * d.x +
                          static_cast<long double>(d.y) * d.y + static_cast<long double>(d.z) * d.z;
    const long double b = fx * d.x + fy * d.y + fz * d.z;
    const long double c = fx * fx + fy * fy + fz * fz - 2.25L;
    const long double disc = b * b - a * c;
    int expected = 0;
    if (disc > 1e-9L) {
      const long double root[2] = {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a};
      bool near = false;
      for (const long double t : root) {
        near = near || std::fabs(t - tMin) < 1e-9L;
        expected += t > tMin ? 1 : 0;
      }
      if (near) continue;
    } else if (disc > -1e-9L) {
      continue;
    }
    ++compared;
    EXPECT_EQ(s.crossings(Ray{o, d}, tMin, kInfinity), expected) << "ray " << i;
    ShapeHit hit;
    EXPECT_EQ(s.intersect(Ray{o, d}, tMin, kInfinity, hit), expected > 0) << "ray " << i;
  }
  EXPECT_GT(compared, 3000);
}

TEST(ShapeSphere, DistantSphereKeepsPrecision) {
  // A radius-1 sphere 1e6 away: the naive discriminant b² − ac loses ~1e-4 to cancellation; the
  // Ray Tracing Gems form keeps t to ~1e-9.
  const Sphere s = Sphere::make({0, 0, -1e6}, 1);
  ShapeHit hit;
  ASSERT_TRUE(hits(s, Ray{{0.6, 0, 0}, {0, 0, -1}}, hit));
  EXPECT_NEAR(hit.t, 1e6 - 0.8, 1e-8);
  EXPECT_VEC_NEAR(hit.normal, 0.6, 0, 0.8, 1e-8);
}

TEST(ShapeSphere, BoundsAndNormalAt) {
  const Sphere s = Sphere::make({1, -2, 3}, 0.5);
  EXPECT_EQ(s.bounds(), Bounds3(Point3{0.5, -2.5, 2.5}, Point3{1.5, -1.5, 3.5}));
  EXPECT_VEC_NEAR(s.normalAt({1, -2, 3.5}), 0, 0, 1, kTol);
  EXPECT_VEC_NEAR(s.normalAt({1, -2.5, 3}), 0, -1, 0, kTol);
}

TEST(ShapeSphere, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Sphere::make({0, 0, 0}, -2);
              }),
              HasSubstr("radius must be > 0, got -2"));
  EXPECT_THAT(errorOf([] {
                return Sphere::make({0, 0, 0}, 0);
              }),
              HasSubstr("radius must be > 0, got 0"));
  EXPECT_THAT(errorOf([] {
                return Sphere::make({0, 0, 0}, std::nan(""));
              }),
              HasSubstr("radius must be > 0, got nan"));
  EXPECT_THAT(errorOf([] {
                return Sphere::make({0, 0, 0}, kInfinity);
              }),
              HasSubstr("radius must be finite, got inf"));
  EXPECT_THAT(errorOf([] {
                return Sphere::make({kInfinity, 0, 0}, 1);
              }),
              HasSubstr("center must be finite, got [inf, 0, 0]"));
  EXPECT_EQ(errorOf([] { return Sphere::make({0, 0, 0}, 1e-300); }), "<no ShapeError thrown>");
}

// ------------------------------------------------------------------------------------- Plane

TEST(ShapePlane, HitFromEitherSideKeepsDefinedNormal) {
  const Plane p = Plane::make({0, 0, -5}, {0, 0, 3});
  EXPECT_VEC_NEAR(p.normal, 0, 0, 1, 0);
  ShapeHit hit;
  ASSERT_TRUE(hits(p, Ray{{7, -3, 0}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(p, Ray{{0, 0, -10}, {0, 0, 2}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2.5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  // Oblique: 45° to the plane travels √2 per unit of depth.
  ASSERT_TRUE(hits(p, Ray{{0, 0, 0}, {1, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
}

TEST(ShapePlane, ParallelRaysMissIncludingInPlane) {
  const Plane p = Plane::make({0, 0, -5}, {0, 0, 1});
  EXPECT_FALSE(hits(p, Ray{{0, 0, 0}, {1, 0, 0}}));
  EXPECT_FALSE(hits(p, Ray{{0, 0, -5}, {1, 1, 0}}));
  EXPECT_EQ(p.crossings(Ray{{0, 0, -5}, {1, 1, 0}}, 0, kInfinity), 0);
  // An oblique plane and a ray lying in it, whose n·d rounds to a tiny non-zero value.
  const Plane tilted = Plane::make({0, 0, 0}, {1, 1, 1});
  EXPECT_FALSE(hits(tilted, Ray{{1, -1, 0}, {1, 0, -1}}));
  EXPECT_FALSE(hits(tilted, Ray{{0.1, 0.7, -0.8}, {0.3, -0.1, -0.2}}));
}

TEST(ShapePlane, StartingOnPlaneNeverHitsIt) {
  const Plane p = Plane::make({0, 0, -5}, {0, 0, 1});
  EXPECT_FALSE(hits(p, Ray{{1, 2, -5}, {0, 0, 1}}));
  EXPECT_FALSE(hits(p, Ray{{1, 2, -5}, {0, 0, -1}}));
}

TEST(ShapePlane, BehindAndTMax) {
  const Plane p = Plane::make({0, 0, -5}, {0, 0, 1});
  const Ray ray{{0, 0, 0}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(p, Ray{{0, 0, 0}, {0, 0, 1}}));
  EXPECT_FALSE(hits(p, ray, hit, 0, 5));
  EXPECT_TRUE(hits(p, ray, hit, 0, 5.000001));
  EXPECT_FALSE(hits(p, ray, hit, 5, kInfinity));
  EXPECT_EQ(p.crossings(ray, 0, kInfinity), 1);
  EXPECT_EQ(p.crossings(ray, 0, 5), 0);
}

// The division is skipped where the signs alone put t ≤ 0; a range reaching back still counts it.
TEST(ShapePlane, SignsDecideOnlyForNonNegativeTMin) {
  const Plane p = Plane::make({0, 0, -5}, {0, 0, 1});
  const Ray up{{0, 0, 0}, {0, 0, 1}};  // above the plane, leaving it: t = −5
  ShapeHit hit;
  EXPECT_FALSE(hits(p, up, hit, 0, kInfinity));
  EXPECT_EQ(p.crossings(up, 0, kInfinity), 0);
  EXPECT_EQ(p.crossings(up, -0.0, kInfinity), 0);
  EXPECT_EQ(p.crossings(up, -6, kInfinity), 1);
  ASSERT_TRUE(hits(p, up, hit, -6, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, -5);
  const Ray below{{0, 0, -7}, {0, 0, -1}};  // below, leaving downward: t = −2
  EXPECT_EQ(p.crossings(below, 0, kInfinity), 0);
  EXPECT_EQ(p.crossings(below, -3, kInfinity), 1);
}

TEST(ShapePlane, UnboundedAndNormalAt) {
  const Plane p = Plane::make({1, 2, 3}, {0, -2, 0});
  EXPECT_EQ(p.bounds(), Bounds3::unbounded());
  EXPECT_VEC_NEAR(p.normalAt({5, 2, -7}), 0, -1, 0, 0);
}

TEST(ShapePlane, FromPointsUsesRightHandRule) {
  const Plane p = Plane::fromPoints({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
  EXPECT_VEC_NEAR(p.normal, 0, 0, 1, kTol);
  ShapeHit hit;
  ASSERT_TRUE(hits(p, Ray{{5, 5, 5}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 4);
  EXPECT_VEC_NEAR(Plane::fromPoints({0, 0, 1}, {0, 1, 1}, {1, 0, 1}).normal, 0, 0, -1, kTol);
}

TEST(ShapePlane, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Plane::make({0, 0, 0}, {0, 0, 0});
              }),
              HasSubstr("normal must be a non-zero vector, got [0, 0, 0]"));
  EXPECT_THAT(errorOf([] {
                return Plane::make({0, 0, 0}, {0, std::nan(""), 1});
              }),
              HasSubstr("normal must be finite, got [0, nan, 1]"));
  EXPECT_THAT(errorOf([] {
                return Plane::make({0, -kInfinity, 0}, {0, 0, 1});
              }),
              HasSubstr("point must be finite, got [0, -inf, 0]"));
  EXPECT_THAT(errorOf([] {
                return Plane::fromPoints({0, 0, 0}, {1, 1, 1}, {3, 3, 3});
              }),
              HasSubstr("points are collinear: [0, 0, 0], [1, 1, 1], [3, 3, 3]"));
  EXPECT_THAT(errorOf([] {
                return Plane::fromPoints({1, 1, 1}, {1, 1, 1}, {1, 1, 1});
              }),
              HasSubstr("points are collinear"));
  // Tiny but valid normals are normalised, not rejected.
  EXPECT_VEC_NEAR(Plane::make({0, 0, 0}, {0, 1e-300, 0}).normal, 0, 1, 0, 0);
}

// ---------------------------------------------------------------------------------- Triangle

const Triangle kUnitTriangle = Triangle::make({0, 0, -5}, {1, 0, -5}, {0, 1, -5});

TEST(ShapeTriangle, HitInsideFromEitherSide) {
  ShapeHit hit;
  ASSERT_TRUE(hits(kUnitTriangle, Ray{{0.25, 0.25, 0}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kUnitTriangle, Ray{{0.25, 0.25, -10}, {0, 0, 1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kUnitTriangle, Ray{{0.25, 0.25, 0}, {0, 0, -10}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 0.5);
}

TEST(ShapeTriangle, EdgesAndVerticesCountOutsideMisses) {
  for (const Point3 target : {Point3{0.5, 0.5, -5}, Point3{0, 0, -5}, Point3{1, 0, -5},
                              Point3{0, 1, -5}, Point3{0.5, 0, -5}, Point3{0, 0.3, -5}}) {
    EXPECT_TRUE(hits(kUnitTriangle, Ray{{0.2, 0.1, 0}, target - Point3{0.2, 0.1, 0}}))
        << target.x << " " << target.y;
  }
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{0.6, 0.6, 0}, {0, 0, -1}}));
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{-1e-9, 0.5, 0}, {0, 0, -1}}));
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{0.5, -1e-9, 0}, {0, 0, -1}}));
}

TEST(ShapeTriangle, EveryDominantAxisAndSign) {
  // The same triangle seen along ±x, ±y, ±z exercises each permutation (and the winding swap).
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      auto place = [axis](double a, double b, double depth) {
        Point3 p;
        p[axis] = depth;
        p[(axis + 1) % 3] = a;
        p[(axis + 2) % 3] = b;
        return p;
      };
      const Triangle tri = Triangle::make(place(0, 0, 3), place(1, 0, 3), place(0, 1, 3));
      Vec3 d;
      d[axis] = -sign;
      d[(axis + 1) % 3] = 0.05;
      d[(axis + 2) % 3] = 0.05;
      const Point3 origin = place(0.2, 0.2, 3 + 2 * sign);
      ShapeHit hit;
      ASSERT_TRUE(hits(tri, Ray{origin, d}, hit)) << axis << " " << sign;
      EXPECT_DOUBLE_EQ(hit.t, 2);
      EXPECT_DOUBLE_EQ(hit.normal[axis], 1);
      EXPECT_FALSE(hits(tri, Ray{origin, -d}));
    }
  }
}

TEST(ShapeTriangle, NormalFollowsVertexOrder) {
  const Triangle reversed = Triangle::make({0, 0, -5}, {0, 1, -5}, {1, 0, -5});
  EXPECT_VEC_NEAR(reversed.normal, 0, 0, -1, 0);
  ShapeHit hit;
  ASSERT_TRUE(hits(reversed, Ray{{0.25, 0.25, 0}, {0, 0, -1}}, hit));
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, 0);
  const Triangle tilted = Triangle::make({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  const double c = 1 / std::sqrt(3.0);
  EXPECT_VEC_NEAR(tilted.normalAt({0.2, 0.3, 0.5}), c, c, c, kTol);
}

TEST(ShapeTriangle, ParallelRaysMiss) {
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{-1, 0.25, -5}, {1, 0, 0}}));  // in the plane, across it
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{-1, 0.25, -4}, {1, 0, 0}}));
  const Triangle tilted = Triangle::make({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  EXPECT_FALSE(hits(tilted, Ray{{1, -1, 1}, {-1, 1, 0}}));  // through its interior, in its plane
}

TEST(ShapeTriangle, StartOnSurfaceBehindAndTMax) {
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{0.25, 0.25, -5}, {0, 0, 1}}));
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{0.25, 0.25, -5}, {0, 0, -1}}));
  EXPECT_FALSE(hits(kUnitTriangle, Ray{{0.25, 0.25, 0}, {0, 0, 1}}));
  const Ray ray{{0.25, 0.25, 0}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(kUnitTriangle, ray, hit, 0, 5));
  EXPECT_TRUE(hits(kUnitTriangle, ray, hit, 0, 5.000001));
  EXPECT_FALSE(hits(kUnitTriangle, ray, hit, 5, 10));
  EXPECT_EQ(kUnitTriangle.crossings(ray, 0, kInfinity), 1);
  EXPECT_EQ(kUnitTriangle.crossings(ray, 0, 5), 0);
}

TEST(ShapeTriangle, Bounds) {
  const Triangle tri = Triangle::make({1, -2, 3}, {-4, 5, 0}, {2, 2, 2});
  EXPECT_EQ(tri.bounds(), Bounds3(Point3{-4, -2, 0}, Point3{2, 5, 3}));
}

TEST(ShapeTriangle, MakeRejectsDegenerateWithRelativeTolerance) {
  EXPECT_THAT(errorOf([] {
                return Triangle::make({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
              }),
              HasSubstr("vertices are collinear: [0, 0, 0], [1, 1, 1], [2, 2, 2]"));
  EXPECT_THAT(errorOf([] {
                return Triangle::make({0, 0, 0}, {0, 0, 0}, {2, 2, 2});
              }),
              HasSubstr("vertices are collinear"));
  EXPECT_THAT(errorOf([] {
                return Triangle::make({0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0});
              }),
              HasSubstr("vertices[2] must be finite, got [0, nan, 0]"));
  // Thin relative to its size: 1e-13 rejected, 1e-6 kept, at any scale.
  for (const double scale : {1e-6, 1.0, 1e6}) {
    EXPECT_THAT(errorOf([scale] {
                  return Triangle::make({0, 0, 0}, {scale, 0, 0}, {scale / 2, scale * 1e-13, 0});
                }),
                HasSubstr("vertices are collinear"));
    EXPECT_EQ(errorOf([scale] {
                return Triangle::make({0, 0, 0}, {scale, 0, 0}, {scale / 2, scale * 1e-6, 0});
              }),
              "<no ShapeError thrown>");
  }
}

// A non-planar height field of triangles sharing every interior edge and vertex, in three
// orientations and seen from both sides. Rays aimed at points on the shared edges and at the shared
// vertices must hit at least one triangle: the watertightness of Woop et al.
TEST(ShapeTriangle, WatertightOnSharedEdgesAndVerticesOfAGrid) {
  constexpr int kCells = 6;
  Rng heights(17);
  double height[kCells + 1][kCells + 1];
  for (auto& row : height)
    for (double& h : row) h = 0.4 * heights.uniform() - 0.2;
  int rays = 0;
  int misses = 0;
  for (int axis = 0; axis < 3; ++axis) {
    auto vertex = [&](int i, int j) {
      Point3 p;
      p[(axis + 1) % 3] = i * 1.1 + 0.3;
      p[(axis + 2) % 3] = j * 0.9 - 2.7;
      p[axis] = height[i][j] + 0.1;
      return p;
    };
    std::vector<Triangle> triangles;
    for (int i = 0; i < kCells; ++i)
      for (int j = 0; j < kCells; ++j) {
        triangles.push_back(Triangle::make(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)));
        triangles.push_back(Triangle::make(vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)));
      }
    for (const double side : {1.0, -1.0}) {
      Rng rng(hashCombine(static_cast<std::uint64_t>(axis), side > 0 ? 1 : 2));
      for (int k = 0; k < 700; ++k) {
        // An interior vertex, or a point on one of its edges (right, up, diagonal).
        const int i = 1 + static_cast<int>(rng.uniform() * (kCells - 1));
        const int j = 1 + static_cast<int>(rng.uniform() * (kCells - 1));
        const int kind = static_cast<int>(rng.uniform() * 4);
        const double s = rng.uniform();
        const Point3 a = vertex(i, j);
        const Point3 b = kind == 1   ? vertex(i + 1, j)
                         : kind == 2 ? vertex(i, j + 1)
                                     : vertex(i + 1, j + 1);
        const Point3 target = kind == 0 ? a : a + (b - a) * s;
        Vec3 toOrigin;
        toOrigin[axis] = side * 10;
        toOrigin[(axis + 1) % 3] = 7 * (rng.uniform() - 0.5);
        toOrigin[(axis + 2) % 3] = 7 * (rng.uniform() - 0.5);
        const Ray ray{target + toOrigin, -toOrigin};
        bool any = false;
        ShapeHit hit;
        for (const Triangle& tri : triangles) any = tri.intersect(ray, 0, kInfinity, hit) || any;
        ++rays;
        misses += any ? 0 : 1;
      }
    }
  }
  EXPECT_EQ(rays, 4200);
  EXPECT_EQ(misses, 0);
}

TEST(ShapeTriangle, WatertightThroughTheCentreOfAFan) {
  constexpr int kSpokes = 7;
  Rng rim(99);
  const Point3 centre{0.3, -0.2, 0.1};
  std::vector<Point3> ring;
  for (int k = 0; k < kSpokes; ++k) {
    const double phi = 2 * std::numbers::pi * k / kSpokes;
    ring.push_back(centre + Vec3{std::cos(phi), std::sin(phi), 0.6 * rim.uniform() - 0.3});
  }
  std::vector<Triangle> fan;
  for (int k = 0; k < kSpokes; ++k)
    fan.push_back(Triangle::make(centre, ring[k], ring[(k + 1) % kSpokes]));
  Rng rng(5);
  int misses = 0;
  for (int k = 0; k < 1500; ++k) {
    // Aim at the shared centre or at a point of a spoke, from above or below.
    const int spoke = static_cast<int>(rng.uniform() * kSpokes);
    const Point3 target = (k % 3 == 0) ? centre : centre + (ring[spoke] - centre) * rng.uniform();
    const Vec3 toOrigin{6 * (rng.uniform() - 0.5), 6 * (rng.uniform() - 0.5), k % 2 ? 5.0 : -5.0};
    const Ray ray{target + toOrigin, -toOrigin};
    bool any = false;
    ShapeHit hit;
    for (const Triangle& tri : fan) any = tri.intersect(ray, 0, kInfinity, hit) || any;
    misses += any ? 0 : 1;
  }
  EXPECT_EQ(misses, 0);
}

// ----------------------------------------------------------------------------------- Polygon

// A convex "house" pentagon in z = 0, counter-clockwise seen from +z.
const std::vector<Point3> kHouse = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {1, 3, 0}, {0, 2, 0}};

TEST(ShapePolygon, HitInsideAndOnBoundaryMissOutside) {
  const Polygon poly = Polygon::make(kHouse);
  EXPECT_VEC_NEAR(poly.normal, 0, 0, 1, kTol);
  ShapeHit hit;
  ASSERT_TRUE(hits(poly, Ray{{1, 1, 5}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  ASSERT_TRUE(hits(poly, Ray{{1, 2.5, -2}, {0, 0, 1}}, hit));  // in the roof, from below
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  EXPECT_TRUE(hits(poly, Ray{{2, 1, 5}, {0, 0, -1}}));  // on an edge
  EXPECT_TRUE(hits(poly, Ray{{1, 3, 5}, {0, 0, -1}}));  // on a vertex
  EXPECT_FALSE(hits(poly, Ray{{0.2, 2.9, 5}, {0, 0, -1}}));
  EXPECT_FALSE(hits(poly, Ray{{2.001, 1, 5}, {0, 0, -1}}));
  EXPECT_FALSE(hits(poly, Ray{{1, -0.001, 5}, {0, 0, -1}}));
}

TEST(ShapePolygon, NormalFollowsVertexOrder) {
  const std::vector<Point3> reversed(kHouse.rbegin(), kHouse.rend());
  const Polygon poly = Polygon::make(reversed);
  EXPECT_VEC_NEAR(poly.normal, 0, 0, -1, kTol);
  ShapeHit hit;
  ASSERT_TRUE(hits(poly, Ray{{1, 1, 5}, {0, 0, -1}}, hit));
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, kTol);
  EXPECT_VEC_NEAR(poly.normalAt({1, 1, 0}), 0, 0, -1, kTol);
}

TEST(ShapePolygon, ParallelStartOnSurfaceBehindAndTMax) {
  const Polygon poly = Polygon::make(kHouse);
  EXPECT_FALSE(hits(poly, Ray{{-1, 1, 0}, {1, 0, 0}}));
  EXPECT_FALSE(hits(poly, Ray{{-1, 1, 1}, {1, 0, 0}}));
  EXPECT_FALSE(hits(poly, Ray{{1, 1, 0}, {0, 0, 1}}));
  EXPECT_FALSE(hits(poly, Ray{{1, 1, 5}, {0, 0, 1}}));
  const Ray ray{{1, 1, 5}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(poly, ray, hit, 0, 5));
  EXPECT_TRUE(hits(poly, ray, hit, 0, 5.000001));
  EXPECT_EQ(poly.crossings(ray, 0, kInfinity), 1);
  EXPECT_EQ(poly.crossings(ray, 0, 5), 0);
  EXPECT_EQ(poly.crossings(Ray{{5, 5, 5}, {0, 0, -1}}, 0, kInfinity), 0);
}

TEST(ShapePolygon, BoundsOfAnOrientedPolygon) {
  const Polygon poly = Polygon::make({{0, 0, 0}, {0, 2, 0}, {0, 2, 3}, {0, 1, 4}, {0, -1, 2}});
  EXPECT_EQ(poly.bounds(), Bounds3(Point3{0, -1, 0}, Point3{0, 2, 4}));
  EXPECT_VEC_NEAR(poly.normal, 1, 0, 0, kTol);
}

TEST(ShapePolygon, AcceptsAStraightCornerAndSmallNoise) {
  // A vertex in the middle of an edge is still convex.
  const Polygon poly = Polygon::make({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}});
  EXPECT_TRUE(hits(poly, Ray{{1.5, 0.5, 1}, {0, 0, -1}}));
  // Off the plane by 1e-11 of its size: within the relative tolerance.
  EXPECT_EQ(errorOf([] {
              return Polygon::make({{0, 0, 0}, {1e3, 0, 0}, {1e3, 1e3, 1e-8}, {0, 1e3, 0}});
            }),
            "<no ShapeError thrown>");
}

TEST(ShapePolygon, MakeRejectsInvalidPolygons) {
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {1, 0, 0}});
              }),
              HasSubstr("vertices must hold at least 3 points, got 2"));
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5}, {0, 1, 0}});
              }),
              HasSubstr("vertices are not planar: vertices["));
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {2, 0, 0}, {1, 0.5, 0}, {2, 2, 0}, {0, 2, 0}});
              }),
              HasSubstr("vertices are not convex: the corner at vertices[2] [1, 0.5, 0]"));
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {0, 1, 0}});
              }),
              HasSubstr("vertices[1] and [2] coincide, both [1, 0, 0]"));
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}});
              }),
              HasSubstr("vertices are collinear"));
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {1, kInfinity, 0}, {0, 1, 0}});
              }),
              HasSubstr("vertices[1] must be finite, got [1, inf, 0]"));
  // A pentagram: every corner turns left, but the boundary winds around twice.
  std::vector<Point3> star;
  for (int k = 0; k < 5; ++k) {
    const double phi = 2 * std::numbers::pi * (2 * k) / 5;
    star.push_back({std::cos(phi), std::sin(phi), 0});
  }
  EXPECT_THAT(errorOf([&] { return Polygon::make(star); }),
              HasSubstr("vertices are self-intersecting: the edges wind around 2 times"));
  // Folding back along an edge.
  EXPECT_THAT(errorOf([] {
                return Polygon::make({{0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {1, 1, 0}});
              }),
              HasSubstr("vertices fold back at vertices[1] [2, 0, 0]"));
}

// --------------------------------------------------------------------------------- Rectangle

const Rectangle kRect = Rectangle::make({0, 0, -5}, {2, 0, 0}, {0, 3, 0});

TEST(ShapeRectangle, HitInsideAndOnEdgesMissOutside) {
  EXPECT_VEC_NEAR(kRect.normal, 0, 0, 1, 0);
  ShapeHit hit;
  ASSERT_TRUE(hits(kRect, Ray{{1, 1, 0}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kRect, Ray{{1, 1, -7}, {0, 0, 0.5}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 4);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  for (const Point3 onEdge : {Point3{0, 1, 0}, Point3{2, 1, 0}, Point3{1, 0, 0}, Point3{1, 3, 0},
                              Point3{0, 0, 0}, Point3{2, 3, 0}})
    EXPECT_TRUE(hits(kRect, Ray{onEdge, {0, 0, -1}})) << onEdge.x << " " << onEdge.y;
  for (const Point3 outside :
       {Point3{-1e-9, 1, 0}, Point3{2 + 1e-9, 1, 0}, Point3{1, -1e-9, 0}, Point3{1, 3 + 1e-9, 0}})
    EXPECT_FALSE(hits(kRect, Ray{outside, {0, 0, -1}})) << outside.x << " " << outside.y;
}

TEST(ShapeRectangle, ParallelStartOnSurfaceBehindAndTMax) {
  EXPECT_FALSE(hits(kRect, Ray{{-1, 1, -5}, {1, 0, 0}}));
  EXPECT_FALSE(hits(kRect, Ray{{1, 1, -5}, {0, 0, 1}}));
  EXPECT_FALSE(hits(kRect, Ray{{1, 1, 0}, {0, 0, 1}}));
  const Ray ray{{1, 1, 0}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(kRect, ray, hit, 0, 5));
  EXPECT_TRUE(hits(kRect, ray, hit, 0, 5.000001));
  EXPECT_EQ(kRect.crossings(ray, 0, kInfinity), 1);
  EXPECT_EQ(kRect.crossings(ray, 0, 5), 0);
}

TEST(ShapeRectangle, BoundsAndNormalOfARotatedRectangle) {
  EXPECT_EQ(kRect.bounds(), Bounds3(Point3{0, 0, -5}, Point3{2, 3, -5}));
  const Rectangle rotated = Rectangle::make({0, 0, 0}, {1, 1, 0}, {-2, 2, 0});
  EXPECT_EQ(rotated.bounds(), Bounds3(Point3{-2, 0, 0}, Point3{1, 3, 0}));
  EXPECT_VEC_NEAR(rotated.normalAt({0, 1, 0}), 0, 0, 1, kTol);
  const Rectangle flipped = Rectangle::make({0, 0, 0}, {0, 3, 0}, {2, 0, 0});
  EXPECT_VEC_NEAR(flipped.normal, 0, 0, -1, 0);
}

TEST(ShapeRectangle, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Rectangle::make({0, 0, 0}, {1, 0, 0}, {1, 1, 0});
              }),
              HasSubstr("edges must be perpendicular, got [1, 0, 0] and [1, 1, 0]"));
  EXPECT_THAT(errorOf([] {
                return Rectangle::make({0, 0, 0}, {1, 0, 0}, {1, 1, 0});
              }),
              HasSubstr("at 45 degrees"));
  EXPECT_THAT(errorOf([] {
                return Rectangle::make({0, 0, 0}, {0, 0, 0}, {0, 1, 0});
              }),
              HasSubstr("edges[0] must be a non-zero vector, got [0, 0, 0]"));
  EXPECT_THAT(errorOf([] {
                return Rectangle::make({0, 0, 0}, {1, 0, 0}, {0, 0, 0});
              }),
              HasSubstr("edges[1] must be a non-zero vector"));
  EXPECT_THAT(errorOf([] {
                return Rectangle::make({0, 0, std::nan("")}, {1, 0, 0}, {0, 1, 0});
              }),
              HasSubstr("corner must be finite"));
  // Perpendicular within the 1e-9 relative tolerance is accepted; 1e-8 is not.
  EXPECT_EQ(errorOf([] {
              return Rectangle::make({0, 0, 0}, {5, 0, 0}, {5e-10, 1, 0});
            }),
            "<no ShapeError thrown>");
  EXPECT_THAT(errorOf([] {
                return Rectangle::make({0, 0, 0}, {5, 0, 0}, {1e-8, 1, 0});
              }),
              HasSubstr("perpendicular"));
}

// -------------------------------------------------------------------------------- Quadrangle

// A dart (arrowhead) in z = 0, counter-clockwise from +z, reflex at (2, 1): the notch is the
// triangle (0,0) (2,1) (4,0) below the reflex corner.
const Point3 kDart[4] = {{0, 0, 0}, {2, 1, 0}, {4, 0, 0}, {2, 3, 0}};

TEST(ShapeQuadrangle, ConvexHitAndNormalByVertexOrder) {
  const Quadrangle q = Quadrangle::make({0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0});
  EXPECT_VEC_NEAR(q.normal, 0, 0, 1, kTol);
  ShapeHit hit;
  ASSERT_TRUE(hits(q, Ray{{1.5, 0.2, 4}, {0, 0, -2}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  ASSERT_TRUE(hits(q, Ray{{0.3, 0.9, -4}, {0, 0, 1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 4);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  const Quadrangle reversed = Quadrangle::make({0, 1, 0}, {2, 1, 0}, {2, 0, 0}, {0, 0, 0});
  EXPECT_VEC_NEAR(reversed.normal, 0, 0, -1, kTol);
  ASSERT_TRUE(hits(reversed, Ray{{1.5, 0.2, 4}, {0, 0, -2}}, hit));
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, kTol);
  EXPECT_VEC_NEAR(reversed.normalAt({1, 1, 0}), 0, 0, -1, kTol);
}

TEST(ShapeQuadrangle, DartHitsItsBodyAndMissesTheNotchForEveryStartingVertex) {
  for (int start = 0; start < 4; ++start) {
    const Quadrangle q = Quadrangle::make(kDart[start], kDart[(start + 1) % 4],
                                          kDart[(start + 2) % 4], kDart[(start + 3) % 4]);
    EXPECT_VEC_NEAR(q.normal, 0, 0, 1, kTol);
    for (const Point3 inside : {Point3{2, 2, 0}, Point3{1, 1, 0}, Point3{3, 1, 0},
                                Point3{2, 1.01, 0}, Point3{2, 2.99, 0}})
      EXPECT_TRUE(hits(q, Ray{inside + Vec3{0, 0, 1}, {0, 0, -1}}))
          << start << ": " << inside.x << " " << inside.y;
    for (const Point3 notch :
         {Point3{2, 0.5, 0}, Point3{2, 0.99, 0}, Point3{1, 0.25, 0}, Point3{3, 0.25, 0}})
      EXPECT_FALSE(hits(q, Ray{notch + Vec3{0, 0, 1}, {0, 0, -1}}))
          << start << ": " << notch.x << " " << notch.y;
    EXPECT_EQ(q.bounds(), Bounds3(Point3{0, 0, 0}, Point3{4, 3, 0}));
  }
}

TEST(ShapeQuadrangle, WatertightAlongTheDiagonal) {
  // A convex quadrangle in the tilted plane z = 0.1x + 0.05y; both diagonals (the inner split edge
  // and the other one) are aimed at.
  auto onPlane = [](double x, double y) { return Point3{x, y, 0.1 * x + 0.05 * y}; };
  const Point3 v[4] = {onPlane(0, 0), onPlane(3, 0.2), onPlane(3.3, 2.9), onPlane(-0.1, 2)};
  const Quadrangle q = Quadrangle::make(v[0], v[1], v[2], v[3]);
  const Point3 ends[2][2] = {{v[0], v[2]}, {v[1], v[3]}};
  Rng rng(3);
  int misses = 0;
  for (int k = 0; k < 400; ++k) {
    const auto& diag = ends[k % 2];
    const Point3 target = diag[0] + (diag[1] - diag[0]) * rng.uniform();
    const Vec3 toOrigin{rng.uniform() - 0.5, rng.uniform() - 0.5, 3};
    misses += hits(q, Ray{target + toOrigin, -toOrigin}) ? 0 : 1;
  }
  EXPECT_EQ(misses, 0);
}

TEST(ShapeQuadrangle, ParallelStartOnSurfaceBehindAndTMax) {
  const Quadrangle q = Quadrangle::make(kDart[0], kDart[1], kDart[2], kDart[3]);
  EXPECT_FALSE(hits(q, Ray{{-1, 2, 0}, {1, 0, 0}}));
  EXPECT_FALSE(hits(q, Ray{{2, 2, 0}, {0, 0, 1}}));
  EXPECT_FALSE(hits(q, Ray{{2, 2, 1}, {0, 0, 1}}));
  const Ray ray{{2, 2, 1}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(q, ray, hit, 0, 1));
  EXPECT_TRUE(hits(q, ray, hit, 0, 1.000001));
  EXPECT_EQ(q.crossings(ray, 0, kInfinity), 1);
  EXPECT_EQ(q.crossings(ray, 0, 1), 0);
  // On the inner diagonal both halves touch the point; it is still one crossing.
  EXPECT_EQ(q.crossings(Ray{{2, 2, 1}, {0, 0, -1}}, 0, kInfinity), 1);
}

TEST(ShapeQuadrangle, AcceptsAStraightCorner) {
  // A triangle drawn with a fourth vertex in the middle of its base.
  const Quadrangle q = Quadrangle::make({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 1, 0});
  EXPECT_VEC_NEAR(q.normal, 0, 0, 1, kTol);
  EXPECT_TRUE(hits(q, Ray{{0.6, 0.1, 1}, {0, 0, -1}}));
  EXPECT_TRUE(hits(q, Ray{{1.4, 0.1, 1}, {0, 0, -1}}));
  EXPECT_FALSE(hits(q, Ray{{0.3, 0.5, 1}, {0, 0, -1}}));
}

TEST(ShapeQuadrangle, MakeRejectsInvalidQuadrangles) {
  EXPECT_THAT(errorOf([] {
                return Quadrangle::make({0, 0, 0}, {2, 2, 0}, {2, 0, 0}, {0, 3, 0});
              }),
              HasSubstr("vertices are self-intersecting"));
  // A symmetric bow tie encloses no net area, yet its points are not on a line.
  const std::string cancel =
      "vertices are self-intersecting: the loop crosses itself and its parts enclose opposite "
      "areas that cancel";
  EXPECT_EQ(errorOf([] {
              return Quadrangle::make({0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0});
            }),
            cancel);
  EXPECT_EQ(errorOf([] {
              return Polygon::make({{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}});
            }),
            cancel);
  EXPECT_THAT(errorOf([] {
                return Quadrangle::make({0, 0, 0}, {1, 0, 0}, {1, 1, 1}, {0, 1, 0});
              }),
              HasSubstr("vertices are not planar"));
  EXPECT_THAT(errorOf([] {
                return Quadrangle::make({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0});
              }),
              HasSubstr("vertices are collinear"));
  EXPECT_THAT(errorOf([] {
                return Quadrangle::make({0, 0, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0});
              }),
              HasSubstr("vertices[0] and [1] coincide"));
  EXPECT_THAT(errorOf([] {
                return Quadrangle::make({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, std::nan(""), 0});
              }),
              HasSubstr("vertices[3] must be finite"));
  EXPECT_THAT(errorOf([] {
                return Quadrangle::make({0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {1, 1, 0});
              }),
              HasSubstr("vertices fold back at vertices[1]"));
}

// -------------------------------------------------------------------------------------- Tube

const Tube kTube = Tube::make({0, 0, 0}, {0, 0, 3}, 1);

TEST(ShapeTube, HitFromOutsideWithRadialNormal) {
  EXPECT_VEC_NEAR(kTube.axis, 0, 0, 1, 0);
  ShapeHit hit;
  ASSERT_TRUE(hits(kTube, Ray{{5, 0, 0}, {-1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 4);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  // Oblique to the axis: the normal has no axial part.
  ASSERT_TRUE(hits(kTube, Ray{{5, 0, 100}, {-2, 0, -7}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  ASSERT_TRUE(hits(kTube, Ray{{0.6, 5, 0}, {0, -1, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 4.2);
  EXPECT_VEC_NEAR(hit.normal, 0.6, 0.8, 0, kTol);
}

TEST(ShapeTube, FromInsideHitsFarSideWithOutwardNormal) {
  ShapeHit hit;
  ASSERT_TRUE(hits(kTube, Ray{{0, 0, 7}, {0, 1, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_VEC_NEAR(hit.normal, 0, 1, 0, kTol);
  EXPECT_EQ(kTube.crossings(Ray{{0, 0, 7}, {0, 1, 0}}, 0, kInfinity), 1);
}

TEST(ShapeTube, TangentAndAxisParallelRaysMiss) {
  EXPECT_FALSE(hits(kTube, Ray{{5, 1, 0}, {-1, 0, 0}}));
  EXPECT_EQ(kTube.crossings(Ray{{5, 1, 0}, {-1, 0, 0}}, 0, kInfinity), 0);
  EXPECT_TRUE(hits(kTube, Ray{{5, 1 - 1e-9, 0}, {-1, 0, 0}}));
  EXPECT_FALSE(hits(kTube, Ray{{0.5, 0, 0}, {0, 0, 1}}));  // inside, along the axis
  EXPECT_FALSE(hits(kTube, Ray{{3, 0, 0}, {0, 0, -1}}));   // outside, along the axis
  EXPECT_FALSE(hits(kTube, Ray{{1, 0, 0}, {0, 0, 1}}));    // on the surface, along it
  // An oblique axis and a ray along it whose perpendicular part is pure rounding.
  const Tube oblique = Tube::make({0, 0, 0}, {1, 1, 1}, 1);
  EXPECT_FALSE(hits(oblique, Ray{{0.1, 0.2, 0.3}, {1, 1, 1}}));
}

TEST(ShapeTube, StartingOnSurfaceBehindAndTMax) {
  ShapeHit hit;
  EXPECT_FALSE(hits(kTube, Ray{{1, 0, 0}, {1, 0, 0}}));
  ASSERT_TRUE(hits(kTube, Ray{{1, 0, 0}, {-1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, -1, 0, 0, kTol);
  EXPECT_FALSE(hits(kTube, Ray{{5, 0, 0}, {1, 0, 0}}));
  const Ray ray{{5, 0, 0}, {-1, 0, 0}};
  EXPECT_FALSE(hits(kTube, ray, hit, 0, 4));
  ASSERT_TRUE(hits(kTube, ray, hit, 4, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, 6);
  EXPECT_VEC_NEAR(hit.normal, -1, 0, 0, kTol);
  EXPECT_EQ(kTube.crossings(ray, 0, kInfinity), 2);
  EXPECT_EQ(kTube.crossings(ray, 0, 5), 1);
  EXPECT_EQ(kTube.crossings(ray, 4, 6), 0);
}

TEST(ShapeTube, UnboundedAndNormalAt) {
  EXPECT_EQ(kTube.bounds(), Bounds3::unbounded());
  EXPECT_VEC_NEAR(kTube.normalAt({0, 1, 42}), 0, 1, 0, kTol);
  const Tube oblique = Tube::make({1, 0, 0}, {1, 1, 0}, kSqrt2);
  EXPECT_VEC_NEAR(oblique.normalAt({2, 3, 0}), -1 / kSqrt2, 1 / kSqrt2, 0, kTol);
  ShapeHit hit;
  ASSERT_TRUE(hits(oblique, Ray{{1, 5, 0}, {0, -1, 0}}, hit));
  EXPECT_NEAR(hit.t, 3, kTol);  // the tube's boundary meets x = 1 at y = ±2
  EXPECT_VEC_NEAR(hit.normal, -1 / kSqrt2, 1 / kSqrt2, 0, kTol);
}

TEST(ShapeTube, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Tube::make({0, 0, 0}, {0, 0, 0}, 1);
              }),
              HasSubstr("axis must be a non-zero vector, got [0, 0, 0]"));
  EXPECT_THAT(errorOf([] {
                return Tube::make({0, 0, 0}, {0, 0, 1}, -0.5);
              }),
              HasSubstr("radius must be > 0, got -0.5"));
  EXPECT_THAT(errorOf([] {
                return Tube::make({0, 0, 0}, {0, kInfinity, 1}, 1);
              }),
              HasSubstr("axis must be finite"));
  EXPECT_THAT(errorOf([] {
                return Tube::make({std::nan(""), 0, 0}, {0, 0, 1}, 1);
              }),
              HasSubstr("origin must be finite"));
}

// ---------------------------------------------------------------------------------- Cylinder

const Cylinder kCylinder = Cylinder::make({0, 0, 0}, {0, 0, 1}, 1, 2);

TEST(ShapeCylinder, HitsSideAndCapsFromOutside) {
  ShapeHit hit;
  ASSERT_TRUE(hits(kCylinder, Ray{{5, 0, 1}, {-1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 4);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  ASSERT_TRUE(hits(kCylinder, Ray{{0.5, 0, 10}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 8);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kCylinder, Ray{{0, 0.5, -3}, {0, 0, 2}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1.5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, 0);
  // Above and below the side band.
  EXPECT_FALSE(hits(kCylinder, Ray{{5, 0, 2.001}, {-1, 0, 0}}));
  EXPECT_FALSE(hits(kCylinder, Ray{{5, 0, -0.001}, {-1, 0, 0}}));
}

TEST(ShapeCylinder, FromInsideHitsExitWithOutwardNormal) {
  ShapeHit hit;
  ASSERT_TRUE(hits(kCylinder, Ray{{0, 0, 1}, {1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  ASSERT_TRUE(hits(kCylinder, Ray{{0, 0, 1}, {0, 0, 1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kCylinder, Ray{{0, 0, 1.5}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1.5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, 0);
  EXPECT_EQ(kCylinder.crossings(Ray{{0, 0, 1}, {1, 0, 1}}, 0, kInfinity), 1);
}

TEST(ShapeCylinder, TangentAndGrazingRaysMiss) {
  EXPECT_FALSE(hits(kCylinder, Ray{{5, 1, 1}, {-1, 0, 0}}));
  EXPECT_EQ(kCylinder.crossings(Ray{{5, 1, 1}, {-1, 0, 0}}, 0, kInfinity), 0);
  // Along the side surface, parallel to the axis: touches the rims but never enters.
  EXPECT_FALSE(hits(kCylinder, Ray{{1, 0, 10}, {0, 0, -1}}));
  EXPECT_EQ(kCylinder.crossings(Ray{{1, 0, 10}, {0, 0, -1}}, 0, kInfinity), 0);
  // In the plane of the top cap.
  EXPECT_FALSE(hits(kCylinder, Ray{{-5, 0.5, 2}, {1, 0, 0}}));
}

TEST(ShapeCylinder, RayThroughTheRimCrossesOnce) {
  // Enters at the top rim (1, 0, 2) and leaves at the bottom rim (−1, 0, 0): the rim belongs to the
  // closed side band, not to the open caps, so each point counts once.
  const Ray ray{{2, 0, 3}, {-1, 0, -1}};
  ShapeHit hit;
  ASSERT_TRUE(hits(kCylinder, ray, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  EXPECT_EQ(kCylinder.crossings(ray, 0, kInfinity), 2);
}

TEST(ShapeCylinder, StartingOnSurface) {
  ShapeHit hit;
  EXPECT_FALSE(hits(kCylinder, Ray{{0, 0, 2}, {0, 0, 1}}));
  ASSERT_TRUE(hits(kCylinder, Ray{{0, 0, 2}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, 0);
  EXPECT_FALSE(hits(kCylinder, Ray{{1, 0, 1}, {1, 0, 0}}));
  ASSERT_TRUE(hits(kCylinder, Ray{{1, 0, 1}, {-1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, -1, 0, 0, kTol);
}

TEST(ShapeCylinder, BehindTMaxAndCrossings) {
  EXPECT_FALSE(hits(kCylinder, Ray{{5, 0, 1}, {1, 0, 0}}));
  const Ray sideways{{5, 0, 1}, {-1, 0, 0}};
  const Ray downwards{{0.5, 0, 10}, {0, 0, -1}};
  const Ray diagonal{{-3, 0, 0.5}, {2, 0, 1}};  // enters the side at t = 1, leaves the top at 1.5
  ShapeHit hit;
  EXPECT_FALSE(hits(kCylinder, sideways, hit, 0, 4));
  ASSERT_TRUE(hits(kCylinder, sideways, hit, 4, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, 6);
  EXPECT_EQ(kCylinder.crossings(sideways, 0, kInfinity), 2);
  EXPECT_EQ(kCylinder.crossings(downwards, 0, kInfinity), 2);
  EXPECT_EQ(kCylinder.crossings(diagonal, 0, kInfinity), 2);
  EXPECT_EQ(kCylinder.crossings(diagonal, 0, 1.2), 1);
  ASSERT_TRUE(hits(kCylinder, diagonal, hit, 1, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, 1.5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
}

TEST(ShapeCylinder, ExactBoundsForAnyAxis) {
  EXPECT_EQ(kCylinder.bounds(), Bounds3(Point3{-1, -1, 0}, Point3{1, 1, 2}));
  EXPECT_EQ(Cylinder::make({0, 0, 0}, {-2, 0, 0}, 1, 3).bounds(),
            Bounds3(Point3{-3, -1, -1}, Point3{0, 1, 1}));
  const Bounds3 b = Cylinder::make({0, 0, 0}, {0, 3, 4}, 1, 2).bounds();
  EXPECT_VEC_NEAR(b.lo, -1, -0.8, -0.6, kTol);
  EXPECT_VEC_NEAR(b.hi, 1, 2.0, 2.2, kTol);
}

TEST(ShapeCylinder, NormalAt) {
  EXPECT_VEC_NEAR(kCylinder.normalAt({0, 1, 1}), 0, 1, 0, kTol);
  EXPECT_VEC_NEAR(kCylinder.normalAt({-0.6, -0.8, 0.5}), -0.6, -0.8, 0, kTol);
  EXPECT_VEC_NEAR(kCylinder.normalAt({0.3, 0.2, 2}), 0, 0, 1, 0);
  EXPECT_VEC_NEAR(kCylinder.normalAt({0.3, 0.2, 0}), 0, 0, -1, 0);
}

TEST(ShapeCylinder, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Cylinder::make({0, 0, 0}, {0, 0, 1}, 1, 0);
              }),
              HasSubstr("height must be > 0, got 0"));
  EXPECT_THAT(errorOf([] {
                return Cylinder::make({0, 0, 0}, {0, 0, 1}, -2, 1);
              }),
              HasSubstr("radius must be > 0, got -2"));
  EXPECT_THAT(errorOf([] {
                return Cylinder::make({0, 0, 0}, {0, 0, 0}, 1, 1);
              }),
              HasSubstr("axis must be a non-zero vector"));
  EXPECT_THAT(errorOf([] {
                return Cylinder::make({0, 0, 0}, {0, 0, 1}, 1, kInfinity);
              }),
              HasSubstr("height must be finite, got inf"));
  EXPECT_THAT(errorOf([] {
                return Cylinder::make({0, 0, kInfinity}, {0, 0, 1}, 1, 1);
              }),
              HasSubstr("base must be finite"));
}

// --------------------------------------------------------------------------------------- Box

const Box kBox = Box::make({0, 0, 0}, {1, 2, 3});

TEST(ShapeBox, HitFromOutsideGivesEnteredFaceNormal) {
  ShapeHit hit;
  ASSERT_TRUE(hits(kBox, Ray{{-5, 1, 1}, {1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, -1, 0, 0, 0);
  ASSERT_TRUE(hits(kBox, Ray{{0.5, 1, 10}, {0, 0, -2}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 3.5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kBox, Ray{{0.5, 5, 1}, {0.01, -1, 0.01}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 3);
  EXPECT_VEC_NEAR(hit.normal, 0, 1, 0, 0);
}

TEST(ShapeBox, FromInsideHitsExitFaceWithOutwardNormal) {
  ShapeHit hit;
  ASSERT_TRUE(hits(kBox, Ray{{0.5, 1, 1.5}, {0, 1, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_VEC_NEAR(hit.normal, 0, 1, 0, 0);
  ASSERT_TRUE(hits(kBox, Ray{{0.5, 1, 1.5}, {-1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 0.5);
  EXPECT_VEC_NEAR(hit.normal, -1, 0, 0, 0);
  ASSERT_TRUE(hits(kBox, Ray{{0.5, 1, 1.5}, {0, 0, -3}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 0.5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, -1, 0);
}

TEST(ShapeBox, GrazingAFaceOrTouchingAnEdgeMisses) {
  // In the plane of the y = 0 face, across it: touches the surface, never enters.
  EXPECT_FALSE(hits(kBox, Ray{{-5, 0, 1}, {1, 0, 0}}));
  EXPECT_EQ(kBox.crossings(Ray{{-5, 0, 1}, {1, 0, 0}}, 0, kInfinity), 0);
  EXPECT_FALSE(hits(kBox, Ray{{0.5, 2, -5}, {0, 0, 1}}));
  // Through the edge x = 0, y = 0 only (entry == exit).
  EXPECT_FALSE(hits(kBox, Ray{{-1, 1, 1.5}, {1, -1, 0}}));
  EXPECT_EQ(kBox.crossings(Ray{{-1, 1, 1.5}, {1, -1, 0}}, 0, kInfinity), 0);
  // Just inside the face plane does enter.
  EXPECT_TRUE(hits(kBox, Ray{{-5, 1e-12, 1}, {1, 0, 0}}));
}

TEST(ShapeBox, StartingOnSurface) {
  ShapeHit hit;
  EXPECT_FALSE(hits(kBox, Ray{{0, 1, 1}, {-1, 0, 0}}));
  ASSERT_TRUE(hits(kBox, Ray{{0, 1, 1}, {1, 0, 0}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, 0);
  EXPECT_EQ(kBox.crossings(Ray{{0, 1, 1}, {1, 0, 0}}, 0, kInfinity), 1);
}

TEST(ShapeBox, BehindTMaxAndCrossings) {
  EXPECT_FALSE(hits(kBox, Ray{{-5, 1, 1}, {-1, 0, 0}}));
  const Ray ray{{-5, 1, 1}, {1, 0, 0}};
  ShapeHit hit;
  EXPECT_FALSE(hits(kBox, ray, hit, 0, 5));
  ASSERT_TRUE(hits(kBox, ray, hit, 5, kInfinity));
  EXPECT_DOUBLE_EQ(hit.t, 6);
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, 0);
  EXPECT_EQ(kBox.crossings(ray, 0, kInfinity), 2);
  EXPECT_EQ(kBox.crossings(ray, 0, 5.5), 1);
  EXPECT_EQ(kBox.crossings(ray, 5, 6), 0);
  EXPECT_EQ(kBox.crossings(Ray{{0.5, 1, 1}, {1, 1, 1}}, 0, kInfinity), 1);
}

TEST(ShapeBox, BoundsAndNormalAt) {
  EXPECT_EQ(kBox.bounds(), Bounds3(Point3{0, 0, 0}, Point3{1, 2, 3}));
  EXPECT_VEC_NEAR(kBox.normalAt({1, 0.5, 0.5}), 1, 0, 0, 0);
  EXPECT_VEC_NEAR(kBox.normalAt({0.5, 2, 1}), 0, 1, 0, 0);
  EXPECT_VEC_NEAR(kBox.normalAt({0.5, 1, 0}), 0, 0, -1, 0);
  EXPECT_VEC_NEAR(kBox.normalAt({0, 1, 2}), -1, 0, 0, 0);
}

TEST(ShapeBox, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Box::make({0, 0, 0}, {1, 0, 1});
              }),
              HasSubstr("min must be < max on every axis, got min [0, 0, 0] and max [1, 0, 1]"));
  EXPECT_THAT(errorOf([] { return Box::make({2, 0, 0}, {1, 1, 1}); }), HasSubstr("min must be <"));
  EXPECT_THAT(errorOf([] {
                return Box::make({0, 0, 0}, {1, std::nan(""), 1});
              }),
              HasSubstr("max must be finite, got [1, nan, 1]"));
}

// -------------------------------------------------------------------------------------- Disk

const Disk kDisk = Disk::make({0, 0, -5}, {0, 0, 2}, 2);

TEST(ShapeDisk, HitInsideAndOnRimMissOutside) {
  EXPECT_VEC_NEAR(kDisk.normal, 0, 0, 1, 0);
  ShapeHit hit;
  ASSERT_TRUE(hits(kDisk, Ray{{1, 1, 0}, {0, 0, -1}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  ASSERT_TRUE(hits(kDisk, Ray{{1, 1, -9}, {0, 0, 2}}, hit));
  EXPECT_DOUBLE_EQ(hit.t, 2);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, 0);
  EXPECT_TRUE(hits(kDisk, Ray{{2, 0, 0}, {0, 0, -1}}));
  EXPECT_TRUE(hits(kDisk, Ray{{0, -2, 0}, {0, 0, -1}}));
  EXPECT_FALSE(hits(kDisk, Ray{{2 + 1e-9, 0, 0}, {0, 0, -1}}));
  EXPECT_FALSE(hits(kDisk, Ray{{1.5, 1.5, 0}, {0, 0, -1}}));
}

TEST(ShapeDisk, ParallelStartOnSurfaceBehindAndTMax) {
  EXPECT_FALSE(hits(kDisk, Ray{{-5, 0, -5}, {1, 0, 0}}));
  EXPECT_FALSE(hits(kDisk, Ray{{-5, 0, -4}, {1, 0, 0}}));
  EXPECT_FALSE(hits(kDisk, Ray{{0, 0, -5}, {0, 0, 1}}));
  EXPECT_FALSE(hits(kDisk, Ray{{0, 0, 0}, {0, 0, 1}}));
  const Ray ray{{0, 0, 0}, {0, 0, -1}};
  ShapeHit hit;
  EXPECT_FALSE(hits(kDisk, ray, hit, 0, 5));
  EXPECT_TRUE(hits(kDisk, ray, hit, 0, 5.000001));
  EXPECT_EQ(kDisk.crossings(ray, 0, kInfinity), 1);
  EXPECT_EQ(kDisk.crossings(ray, 0, 5), 0);
}

TEST(ShapeDisk, ExactBoundsAndNormalAt) {
  EXPECT_EQ(kDisk.bounds(), Bounds3(Point3{-2, -2, -5}, Point3{2, 2, -5}));
  const Disk tilted = Disk::make({1, 1, 1}, {0, 3, 4}, 2);
  EXPECT_VEC_NEAR(tilted.bounds().lo, -1, 1 - 1.6, 1 - 1.2, kTol);
  EXPECT_VEC_NEAR(tilted.bounds().hi, 3, 1 + 1.6, 1 + 1.2, kTol);
  EXPECT_VEC_NEAR(tilted.normalAt({1, 1, 1}), 0, 0.6, 0.8, kTol);
}

TEST(ShapeDisk, MakeRejectsInvalidInput) {
  EXPECT_THAT(errorOf([] {
                return Disk::make({0, 0, 0}, {0, 0, 1}, 0);
              }),
              HasSubstr("radius must be > 0, got 0"));
  EXPECT_THAT(errorOf([] {
                return Disk::make({0, 0, 0}, {0, 0, 0}, 1);
              }),
              HasSubstr("normal must be a non-zero vector, got [0, 0, 0]"));
  EXPECT_THAT(errorOf([] {
                return Disk::make({0, std::nan(""), 0}, {0, 0, 1}, 1);
              }),
              HasSubstr("center must be finite"));
}

// --------------------------------------------------------------------------------- Primitive

TEST(ShapePrimitive, WithoutTransformMatchesTheShape) {
  const Primitive prim(Sphere::make({0, 0, -10}, 2), 3, Color(1, 0.5, 0));
  ShapeHit hit;
  ASSERT_TRUE(prim.intersect(Ray{{0, 0, 0}, {0, 0, -1}}, 0, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 8);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  EXPECT_EQ(prim.crossings(Ray{{0, 0, 0}, {0, 0, -1}}, 0, kInfinity), 2);
  EXPECT_EQ(prim.bounds(), Bounds3(Point3{-2, -2, -12}, Point3{2, 2, -8}));
  EXPECT_EQ(prim.materialIndex(), 3u);
  EXPECT_EQ(prim.emission(), Color(1, 0.5, 0));
  EXPECT_TRUE(std::holds_alternative<Sphere>(prim.shape()));
  EXPECT_TRUE(prim.isBounded());
  EXPECT_FALSE(Primitive(Plane::make({0, 0, 0}, {0, 1, 0}), 0, Color()).isBounded());
}

// intersectDeferred followed by completeHit (when it defers) gives intersect's hit bit for bit:
// untransformed planes defer their hit point, every other primitive answers whole.
TEST(ShapePrimitive, DeferredHitEqualsIntersectBitForBit) {
  const std::vector<Primitive> prims = {
      Primitive(Plane::make({0.3, -1, 0.2}, {0.1, 1, -0.3}), 0, Color()),
      Primitive(Plane::make({0, 0, 0}, {0, 1, 0}), 0, Color(), Transform::translate({0, -1, 0})),
      Primitive(Sphere::make({0.5, 0, -3}, 1.5), 0, Color())};
  const bool defers[] = {true, false, false};
  Rng rng(11);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Ray ray{{4 * rng.uniform() - 2, 4 * rng.uniform() - 2, 4 * rng.uniform() - 2},
                  {2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1}};
    const double tMax = i % 2 == 0 ? kInfinity : 3 * rng.uniform();
    for (std::size_t k = 0; k < prims.size(); ++k) {
      ShapeHit whole;
      ShapeHit deferred;
      bool complete = false;
      const bool hit = prims[k].intersect(ray, 1e-9, tMax, whole);
      ASSERT_EQ(prims[k].intersectDeferred(ray, 1e-9, tMax, deferred, complete), hit);
      if (!hit) continue;
      ++hits;
      EXPECT_EQ(complete, !defers[k]);
      if (!complete) prims[k].completeHit(ray, deferred);
      EXPECT_EQ(std::memcmp(&whole, &deferred, sizeof(ShapeHit)), 0) << "primitive " << k;
    }
  }
  EXPECT_GT(hits, 1000);
}

TEST(ShapePrimitive, TranslatedSphere) {
  const Primitive prim(Sphere::make({0, 0, 0}, 1), 0, Color(), Transform::translate({0, 0, -10}));
  ShapeHit hit;
  ASSERT_TRUE(prim.intersect(Ray{{0, 0, 0}, {0, 0, -1}}, 0, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 9);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  EXPECT_EQ(prim.bounds(), Bounds3(Point3{-1, -1, -11}, Point3{1, 1, -9}));
}

TEST(ShapePrimitive, NonUniformlyScaledSphereIsAnEllipsoid) {
  // x²/4 + y² + z² = 1: at x = √2 the surface is at y = √½, where the gradient (x/2, 2y, 0)
  // points along (1, 2, 0).
  const Primitive prim(Sphere::make({0, 0, 0}, 1), 0, Color(), Transform::scale(2, 1, 1));
  ShapeHit hit;
  ASSERT_TRUE(prim.intersect(Ray{{kSqrt2, 5, 0}, {0, -1, 0}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 5 - std::sqrt(0.5), kTol);
  EXPECT_VEC_NEAR(hit.normal, 1 / std::sqrt(5.0), 2 / std::sqrt(5.0), 0, kTol);
  ASSERT_TRUE(prim.intersect(Ray{{5, 0, 0}, {-2, 0, 0}}, 0, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1.5);  // world t, with the world direction's length
  EXPECT_VEC_NEAR(hit.normal, 1, 0, 0, kTol);
  EXPECT_EQ(prim.bounds(), Bounds3(Point3{-2, -1, -1}, Point3{2, 1, 1}));
  EXPECT_EQ(prim.crossings(Ray{{5, 0, 0}, {-2, 0, 0}}, 0, kInfinity), 2);
}

TEST(ShapePrimitive, RotatedAndTranslatedBox) {
  // Rotated 45° about z first, then moved to x = 10: the face with object normal +x now faces
  // (c, c, 0), one unit from the centre.
  const Transform worldFromObject =
      Transform::translate({10, 0, 0}) * Transform::rotate({0, 0, 1}, 45);
  const Primitive prim(Box::make({-1, -1, -1}, {1, 1, 1}), 0, Color(), worldFromObject);
  const double c = std::sqrt(0.5);
  ShapeHit hit;
  ASSERT_TRUE(
      prim.intersect(Ray{{10 + 5 * c, 5 * c, 0.3}, {-2 * c, -2 * c, 0}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 2, kTol);
  EXPECT_VEC_NEAR(hit.normal, c, c, 0, kTol);
  // From the centre straight up: out through the top face, unchanged by the rotation about z.
  ASSERT_TRUE(prim.intersect(Ray{{10, 0, 0}, {0, 0, 1}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 1, kTol);
  EXPECT_VEC_NEAR(hit.normal, 0, 0, 1, kTol);
  // Along x the rotated box reaches √2 from its centre (its corner).
  EXPECT_TRUE(prim.intersect(Ray{{0, 0, 0}, {1, 0, 0}}, 0, 10 - kSqrt2 + 1e-9, hit));
  EXPECT_FALSE(prim.intersect(Ray{{0, 0, 0}, {1, 0, 0}}, 0, 10 - kSqrt2 - 1e-9, hit));
}

TEST(ShapePrimitive, ScaledBoxNormalUsesInverseTranspose) {
  // Rotated 45° about z, then stretched ×2 along x. The object face x = 1 (centre (1, 0, 0),
  // normal +x) lands at (2c, c, 0) with normal ∝ (c/2, c, 0) ∝ (1, 2, 0) by the inverse transpose;
  // mapping the normal like a vector would give (2, 1, 0) instead.
  const Transform worldFromObject = Transform::scale(2, 1, 1) * Transform::rotate({0, 0, 1}, 45);
  const Primitive prim(Box::make({-1, -1, -1}, {1, 1, 1}), 0, Color(), worldFromObject);
  const double c = std::sqrt(0.5);
  const Point3 faceCentre{2 * c, c, 0};
  const Vec3 n = normalize(Vec3{1, 2, 0});
  ShapeHit hit;
  ASSERT_TRUE(prim.intersect(Ray{faceCentre + n * 5, -n}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 5, kTol);
  EXPECT_VEC_NEAR(hit.normal, n.x, n.y, 0, kTol);
}

TEST(ShapePrimitive, BoundsOfRotatedBoxAndUnboundedShapes) {
  const Primitive prim(Box::make({0, 0, 0}, {1, 1, 1}), 0, Color(),
                       Transform::rotate({0, 0, 1}, 45));
  const double c = std::sqrt(0.5);
  EXPECT_VEC_NEAR(prim.bounds().lo, -c, 0, 0, kTol);
  EXPECT_VEC_NEAR(prim.bounds().hi, c, kSqrt2, 1, kTol);
  const Primitive plane(Plane::make({0, 0, 0}, {0, 0, 1}), 0, Color(),
                        Transform::rotate({1, 0, 0}, 30));
  EXPECT_EQ(plane.bounds(), Bounds3::unbounded());
  const Primitive tube(Tube::make({0, 0, 0}, {0, 0, 1}, 1), 0, Color(), Transform::scale(2, 2, 2));
  EXPECT_EQ(tube.bounds(), Bounds3::unbounded());
  // A transformed plane still hits where expected: rotated 90° about x, z = 0 becomes y = 0.
  const Primitive turned(Plane::make({0, 0, 0}, {0, 0, 1}), 0, Color(),
                         Transform::rotate({1, 0, 0}, 90));
  ShapeHit hit;
  ASSERT_TRUE(turned.intersect(Ray{{0, 3, 0}, {0, -1, 0}}, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 3, kTol);
  EXPECT_VEC_NEAR(hit.normal, 0, -1, 0, kTol);
}

TEST(ShapePrimitive, IdentityTransformBehavesLikeNone) {
  const Primitive prim(Box::make({0, 0, 0}, {1, 1, 1}), 0, Color(), Transform());
  ShapeHit hit;
  ASSERT_TRUE(prim.intersect(Ray{{-1, 0.5, 0.5}, {1, 0, 0}}, 0, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1);
  EXPECT_EQ(prim.bounds(), Bounds3(Point3{0, 0, 0}, Point3{1, 1, 1}));
}

TEST(ShapePrimitive, RejectsSingularAndNonFiniteTransforms) {
  Matrix4 flat = Matrix4::identity();
  flat.m[2][2] = 0;
  EXPECT_THAT(errorOf([&] {
                return Primitive(Sphere::make({0, 0, 0}, 1), 0, Color(),
                                 Transform(flat, Matrix4::identity()));
              }),
              HasSubstr("transform must be invertible, got determinant 0"));
  Matrix4 infinite = Matrix4::identity();
  infinite.m[0][3] = kInfinity;
  EXPECT_THAT(errorOf([&] {
                return Primitive(Sphere::make({0, 0, 0}, 1), 0, Color(),
                                 Transform(infinite, Matrix4::identity()));
              }),
              HasSubstr("transform must be finite"));
  Matrix4 projective = Matrix4::identity();
  projective.m[3][2] = 1;
  EXPECT_THAT(errorOf([&] {
                return Primitive(Sphere::make({0, 0, 0}, 1), 0, Color(),
                                 Transform(projective, Matrix4::identity()));
              }),
              HasSubstr("transform must be affine"));
}

// Properties every shape must satisfy for deterministic random rays aimed near it: intersect hits
// iff crossings > 0, the hit lies in the bounds, normalAt at the hit point equals the hit normal,
// and re-intersecting from just past the hit never returns the same t.
TEST(ShapePrimitive, EveryShapeIsSelfConsistent) {
  const std::vector<Shape> shapes = {
      Sphere::make({0.1, 0.2, -0.3}, 1.2),
      Plane::make({0, 0, 0.5}, {0.2, 0.3, 1}),
      Triangle::make({-1, -1, 0}, {1.2, -0.8, 0.3}, {0, 1.1, -0.2}),
      Polygon::make(kHouse),
      Rectangle::make({-1, -1, 0}, {2, 0, 0.5}, {0, 1.5, 0}),
      Quadrangle::make(kDart[0], kDart[1], kDart[2], kDart[3]),
      Tube::make({0, 0, 0}, {0.3, 1, 0.2}, 0.8),
      Cylinder::make({0, -1, 0}, {0.2, 1, -0.1}, 0.9, 1.7),
      Box::make({-1, -0.5, -0.8}, {0.7, 1, 0.6}),
      Disk::make({0, 0, 0}, {1, -1, 2}, 1.3),
  };
  Rng rng(2024);
  for (std::size_t index = 0; index < shapes.size(); ++index) {
    const Primitive prim(shapes[index], 0, Color());
    const Bounds3 box = prim.isBounded() ? prim.bounds() : Bounds3({-3, -3, -3}, {3, 3, 3});
    int hitCount = 0;
    for (int k = 0; k < 300; ++k) {
      const Point3 target =
          box.lo + Vec3{box.diagonal().x * rng.uniform(), box.diagonal().y * rng.uniform(),
                        box.diagonal().z * rng.uniform()};
      const Vec3 away{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
      const Ray ray{target + away * 20, away * -(0.5 + rng.uniform())};
      ShapeHit hit;
      const bool didHit = prim.intersect(ray, 0, kInfinity, hit);
      ASSERT_EQ(didHit, prim.crossings(ray, 0, kInfinity) > 0) << index << " " << k;
      if (!didHit) continue;
      ++hitCount;
      const Point3 p = ray.at(hit.t);
      EXPECT_NEAR(length(hit.normal), 1, 1e-12);
      if (prim.isBounded()) {
        const Vec3 pad{1e-9, 1e-9, 1e-9};
        EXPECT_TRUE(Bounds3(prim.bounds().lo - pad, prim.bounds().hi + pad).contains(p)) << index;
      }
      const Normal3 n = std::visit([&](const auto& s) { return s.normalAt(p); }, prim.shape());
      EXPECT_NEAR(dot(n, toVec(hit.normal)), 1, 1e-9) << index << " " << k;
      ShapeHit next;
      if (prim.intersect(ray, hit.t, kInfinity, next)) {
        EXPECT_GT(next.t, hit.t);
      }
      EXPECT_EQ(prim.crossings(ray, 0, kInfinity) - prim.crossings(ray, hit.t, kInfinity), 1)
          << index << " " << k;
    }
    EXPECT_GT(hitCount, 30) << index;
  }
}

}  // namespace
}  // namespace glint
