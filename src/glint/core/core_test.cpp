// Properties of the core types: vector algebra (with the seed's formulas and example), bounds and
// the slab test, transforms, the counter-based Rng, sample patterns and the ray-offset policy.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <set>
#include <stdexcept>
#include <vector>

#include "glint/core/bounds.h"
#include "glint/core/ray.h"
#include "glint/core/rng.h"
#include "glint/core/sampling.h"
#include "glint/core/spawn.h"
#include "glint/core/transform.h"
#include "glint/core/ulp.h"
#include "glint/core/vec.h"

namespace glint {
namespace {

constexpr double kTol = 1e-12;

#define EXPECT_VEC_NEAR(actual, ex, ey, ez, tol) \
  do {                                           \
    const auto v_ = (actual);                    \
    EXPECT_NEAR(v_.x, (ex), (tol));              \
    EXPECT_NEAR(v_.y, (ey), (tol));              \
    EXPECT_NEAR(v_.z, (ez), (tol));              \
  } while (0)

// ---------------------------------------------------------------------------------- Vectors

TEST(CoreVec, AddSubtractScaleNegate) {
  const Vec3 a{1, 2, 3};
  const Vec3 b{-4, 0.5, 7};
  EXPECT_EQ(a + b, (Vec3{-3, 2.5, 10}));
  EXPECT_EQ(a - b, (Vec3{5, 1.5, -4}));
  EXPECT_EQ(a * 2, (Vec3{2, 4, 6}));
  EXPECT_EQ(-2 * a, (Vec3{-2, -4, -6}));
  EXPECT_EQ(a / 4, (Vec3{0.25, 0.5, 0.75}));
  EXPECT_EQ(-a, (Vec3{-1, -2, -3}));
  Vec3 c = a;
  c += b;
  EXPECT_EQ(c, a + b);
  c -= b;
  EXPECT_EQ(c, a);
  c *= 3;
  EXPECT_EQ(c, (Vec3{3, 6, 9}));
  EXPECT_EQ(a[0], 1);
  EXPECT_EQ(a[1], 2);
  EXPECT_EQ(a[2], 3);
}

TEST(CoreVec, DotIsSumOfProductsAndCosine) {
  EXPECT_EQ(dot(Vec3{1, 2, 3}, Vec3{4, -5, 6}), 4 - 10 + 18);
  EXPECT_EQ(dot(Vec3{1, 0, 0}, Vec3{0, 1, 0}), 0);
  // |A||B|cos θ: unit vectors 60° apart.
  EXPECT_NEAR(dot(Vec3{1, 0, 0}, Vec3{0.5, std::sqrt(3.0) / 2, 0}), 0.5, kTol);
}

TEST(CoreVec, CrossFollowsTheSeedFormulaAndRightHandRule) {
  // u × v = (u2v3 − u3v2, u3v1 − u1v3, u1v2 − u2v1).
  const Vec3 u{1, 2, 3};
  const Vec3 v{4, 5, 6};
  EXPECT_EQ(cross(u, v), (Vec3{2 * 6 - 3 * 5, 3 * 4 - 1 * 6, 1 * 5 - 2 * 4}));
  EXPECT_EQ(cross(u, v), (Vec3{-3, 6, -3}));
  EXPECT_EQ(cross(v, u), -cross(u, v));
  EXPECT_EQ(dot(cross(u, v), u), 0);
  EXPECT_EQ(dot(cross(u, v), v), 0);
  EXPECT_EQ(cross(Vec3{1, 0, 0}, Vec3{0, 1, 0}), (Vec3{0, 0, 1}));
  EXPECT_EQ(cross(Vec3{0, 1, 0}, Vec3{0, 0, 1}), (Vec3{1, 0, 0}));
  EXPECT_EQ(cross(u, u * 2), (Vec3{0, 0, 0}));
}

TEST(CoreVec, LengthAndNormalize) {
  EXPECT_EQ(length(Vec3{3, 4, 0}), 5);
  EXPECT_EQ(length(Vec3{2, 3, 6}), 7);
  EXPECT_EQ(lengthSquared(Vec3{2, 3, 6}), 49);
  const Vec3 n = normalize(Vec3{2, 3, 6});
  EXPECT_NEAR(length(n), 1, kTol);
  EXPECT_VEC_NEAR(n, 2.0 / 7, 3.0 / 7, 6.0 / 7, kTol);
  EXPECT_VEC_NEAR(normalize(Vec3{0, 0, -0.25}), 0, 0, -1, 0);
  EXPECT_EQ(maxComponent(Vec3{-7, 2, 1}), 2);
  EXPECT_EQ(abs(Vec3{-7, 2, -1}), (Vec3{7, 2, 1}));
  EXPECT_TRUE(isFinite(Vec3{1, 2, 3}));
  EXPECT_FALSE(isFinite(Vec3{1, std::nan(""), 3}));
}

TEST(CoreVec, PointsMoveByVectorsAndSubtractToVectors) {
  const Point3 p{1, 2, 3};
  EXPECT_EQ((p + Vec3{1, 1, 1}), (Point3{2, 3, 4}));
  EXPECT_EQ((p - Vec3{1, 1, 1}), (Point3{0, 1, 2}));
  EXPECT_EQ((Point3{5, 5, 5} - p), (Vec3{4, 3, 2}));
  Point3 q = p;
  q += Vec3{0, 0, 1};
  EXPECT_EQ(q, (Point3{1, 2, 4}));
  q -= Vec3{0, 0, 1};
  EXPECT_EQ(q, p);
  EXPECT_EQ(min(Point3{1, 5, -2}, Point3{3, 0, -1}), (Point3{1, 0, -2}));
  EXPECT_EQ(max(Point3{1, 5, -2}, Point3{3, 0, -1}), (Point3{3, 5, -1}));
}

TEST(CoreVec, DistanceOfTheSeedExample) {
  // P1(1, 3, −5), P2(−4, 0, 7): (−5)² + (−3)² + 12² = 25 + 9 + 144 = 178.
  const Point3 p1{1, 3, -5};
  const Point3 p2{-4, 0, 7};
  EXPECT_EQ(distanceSquared(p1, p2), 178);
  EXPECT_DOUBLE_EQ(distance(p1, p2), std::sqrt(178.0));
  EXPECT_DOUBLE_EQ(distance(p2, p1), distance(p1, p2));
  EXPECT_EQ(distance(p1, p1), 0);
}

TEST(CoreVec, NormalsDotAndNormalize) {
  const Normal3 n{0, 0, 2};
  EXPECT_EQ(dot(n, Vec3{1, 2, 3}), 6);
  EXPECT_EQ(dot(Vec3{1, 2, 3}, n), 6);
  EXPECT_EQ(length(n), 2);
  EXPECT_EQ(normalize(n), (Normal3{0, 0, 1}));
  EXPECT_EQ(-n, (Normal3{0, 0, -2}));
  EXPECT_EQ(n * 0.5, (Normal3{0, 0, 1}));
}

TEST(CoreVec, OrthonormalBasisIsRightHanded) {
  for (const Vec3 w : {Vec3{0, 0, 1}, Vec3{0, 0, -1}, normalize(Vec3{1, 2, 3}),
                       normalize(Vec3{-0.3, 0.1, -0.9})}) {
    Vec3 u;
    Vec3 v;
    orthonormalBasis(w, u, v);
    EXPECT_NEAR(length(u), 1, kTol);
    EXPECT_NEAR(length(v), 1, kTol);
    EXPECT_NEAR(dot(u, v), 0, kTol);
    EXPECT_NEAR(dot(u, w), 0, kTol);
    EXPECT_VEC_NEAR(cross(u, v), w.x, w.y, w.z, kTol);
  }
}

// ----------------------------------------------------------------------------------- Bounds

TEST(CoreBounds, EmptyUniteAndContains) {
  const Bounds3 empty;
  EXPECT_TRUE(empty.isEmpty());
  EXPECT_FALSE(empty.isBounded());
  EXPECT_EQ(empty.surfaceArea(), 0);
  const Bounds3 a(Point3{1, 2, 3}, Point3{0, 0, 0});  // corners in any order
  EXPECT_EQ(a.lo, (Point3{0, 0, 0}));
  EXPECT_EQ(a.hi, (Point3{1, 2, 3}));
  EXPECT_EQ(unite(empty, a), a);
  EXPECT_EQ(unite(a, empty), a);
  const Bounds3 b = unite(a, Point3{-1, 5, 1});
  EXPECT_EQ(b, Bounds3(Point3{-1, 0, 0}, Point3{1, 5, 3}));
  EXPECT_EQ(unite(a, Bounds3(Point3{2, 2, 2}, Point3{4, 4, 4})),
            Bounds3(Point3{0, 0, 0}, Point3{4, 4, 4}));
  EXPECT_TRUE(a.contains({1, 2, 3}));
  EXPECT_TRUE(a.contains({0.5, 1, 1.5}));
  EXPECT_FALSE(a.contains({1.0001, 1, 1}));
  EXPECT_EQ(unite(empty, Point3{1, 1, 1}).diagonal(), (Vec3{0, 0, 0}));
  EXPECT_FALSE(Bounds3::unbounded().isBounded());
  EXPECT_FALSE(Bounds3::unbounded().isEmpty());
}

TEST(CoreBounds, SurfaceAreaCentroidAndLongestAxis) {
  const Bounds3 b(Point3{0, 0, 0}, Point3{1, 2, 3});
  EXPECT_EQ(b.surfaceArea(), 2 * (1 * 2 + 2 * 3 + 3 * 1));
  EXPECT_EQ(b.centroid(), (Point3{0.5, 1, 1.5}));
  EXPECT_EQ(b.longestAxis(), 2);
  EXPECT_EQ(Bounds3(Point3{0, 0, 0}, Point3{5, 2, 3}).longestAxis(), 0);
  EXPECT_EQ(Bounds3(Point3{0, 0, 0}, Point3{1, 4, 3}).longestAxis(), 1);
  EXPECT_EQ(Bounds3(Point3{0, 0, 0}, Point3{2, 2, 2}).longestAxis(), 0);  // ties go to x
  EXPECT_EQ(Bounds3(Point3{0, 0, 0}, Point3{1, 0, 1}).surfaceArea(), 2);  // flat box
}

Vec3 reciprocal(const Vec3& d) { return {1 / d.x, 1 / d.y, 1 / d.z}; }

TEST(CoreBounds, IntersectSlabsHitsAndClipsTheInterval) {
  const Bounds3 b(Point3{0, 0, 0}, Point3{1, 1, 1});
  const Ray ray{{-1, 0.5, 0.5}, {1, 0, 0}};
  double tEnter = -1;
  double tExit = -1;
  ASSERT_TRUE(intersectSlabs(b, ray, reciprocal(ray.direction), 0, kInfinity, tEnter, tExit));
  EXPECT_DOUBLE_EQ(tEnter, 1);
  EXPECT_NEAR(tExit, 2, 1e-14);
  EXPECT_GE(tExit, 2);  // the far distance is padded, never shortened
  // Clipped by the caller's range.
  ASSERT_TRUE(intersectSlabs(b, ray, reciprocal(ray.direction), 1.5, 1.7, tEnter, tExit));
  EXPECT_EQ(tEnter, 1.5);
  EXPECT_EQ(tExit, 1.7);
  // Diagonal.
  const Ray diagonal{{-1, -1, -1}, {1, 1, 1}};
  ASSERT_TRUE(
      intersectSlabs(b, diagonal, reciprocal(diagonal.direction), 0, kInfinity, tEnter, tExit));
  EXPECT_DOUBLE_EQ(tEnter, 1);
  EXPECT_NEAR(tExit, 2, 1e-14);
}

TEST(CoreBounds, IntersectSlabsMisses) {
  const Bounds3 b(Point3{0, 0, 0}, Point3{1, 1, 1});
  double tEnter;
  double tExit;
  const Ray beside{{-1, 2, 0.5}, {1, 0, 0}};
  EXPECT_FALSE(
      intersectSlabs(b, beside, reciprocal(beside.direction), 0, kInfinity, tEnter, tExit));
  const Ray away{{-1, 0.5, 0.5}, {-1, 0, 0}};
  EXPECT_FALSE(intersectSlabs(b, away, reciprocal(away.direction), 0, kInfinity, tEnter, tExit));
  const Ray ahead{{-1, 0.5, 0.5}, {1, 0, 0}};
  EXPECT_FALSE(intersectSlabs(b, ahead, reciprocal(ahead.direction), 0, 0.9, tEnter, tExit));
  const Ray skew{{-1, 0, 0.5}, {1, 3, 0}};  // passes above the box's near corner
  EXPECT_FALSE(intersectSlabs(b, skew, reciprocal(skew.direction), 0, kInfinity, tEnter, tExit));
}

TEST(CoreBounds, IntersectSlabsAxisParallelAndOriginInside) {
  const Bounds3 b(Point3{0, 0, 0}, Point3{1, 1, 1});
  double tEnter;
  double tExit;
  // Parallel to two axes, inside their slabs: ±inf inverse components are handled.
  const Ray along{{0.5, 0.5, -3}, {0, 0, 1}};
  ASSERT_TRUE(intersectSlabs(b, along, reciprocal(along.direction), 0, kInfinity, tEnter, tExit));
  EXPECT_DOUBLE_EQ(tEnter, 3);
  EXPECT_NEAR(tExit, 4, 1e-14);
  const Ray alongOutside{{1.5, 0.5, -3}, {0, 0, 1}};
  EXPECT_FALSE(intersectSlabs(b, alongOutside, reciprocal(alongOutside.direction), 0, kInfinity,
                              tEnter, tExit));
  // Origin on a slab plane and parallel to it (0·inf = NaN): conservatively a hit.
  const Ray onFace{{0, 0.5, -3}, {0, 0, 1}};
  EXPECT_TRUE(intersectSlabs(b, onFace, reciprocal(onFace.direction), 0, kInfinity, tEnter, tExit));
  // Origin inside: the interval starts at tMin.
  const Ray inside{{0.5, 0.5, 0.5}, {1, 0, 0}};
  ASSERT_TRUE(intersectSlabs(b, inside, reciprocal(inside.direction), 0, kInfinity, tEnter, tExit));
  EXPECT_EQ(tEnter, 0);
  EXPECT_NEAR(tExit, 0.5, 1e-14);
}

// -------------------------------------------------------------------------------- Transform

TEST(CoreTransform, TranslateMovesPointsNotVectorsOrNormals) {
  const Transform t = Transform::translate({1, 2, 3});
  EXPECT_EQ(t(Point3{1, 1, 1}), (Point3{2, 3, 4}));
  EXPECT_EQ(t(Vec3{1, 1, 1}), (Vec3{1, 1, 1}));
  EXPECT_EQ(t(Normal3{0, 0, 1}), (Normal3{0, 0, 1}));
  const Ray r = t(Ray{{0, 0, 0}, {0, 0, 2}});
  EXPECT_EQ(r.origin, (Point3{1, 2, 3}));
  EXPECT_EQ(r.direction, (Vec3{0, 0, 2}));
  EXPECT_FALSE(t.isIdentity());
  EXPECT_TRUE(Transform().isIdentity());
}

TEST(CoreTransform, ScaleActsOnPointsVectorsAndNormalsDifferently) {
  const Transform s = Transform::scale(2, 3, 4);
  EXPECT_EQ(s(Point3{1, 1, 1}), (Point3{2, 3, 4}));
  EXPECT_EQ(s(Vec3{1, -1, 0.5}), (Vec3{2, -3, 2}));
  // Normals by the inverse transpose: divided by the scale.
  EXPECT_VEC_NEAR(s(Normal3{1, 1, 1}), 0.5, 1.0 / 3, 0.25, kTol);
}

TEST(CoreTransform, Rotate90AboutZMapsXToY) {
  const Transform r = Transform::rotate({0, 0, 1}, 90);
  EXPECT_VEC_NEAR(r(Vec3{1, 0, 0}), 0, 1, 0, kTol);
  EXPECT_VEC_NEAR(r(Vec3{0, 1, 0}), -1, 0, 0, kTol);
  EXPECT_VEC_NEAR(r(Vec3{0, 0, 1}), 0, 0, 1, kTol);
  EXPECT_VEC_NEAR(r(Point3{2, 0, 5}), 0, 2, 5, kTol);
  EXPECT_VEC_NEAR(r(Normal3{1, 0, 0}), 0, 1, 0, kTol);  // rotations map normals like vectors
  // Any axis length; right-handed about x: y → z.
  EXPECT_VEC_NEAR(Transform::rotate({5, 0, 0}, 90)(Vec3{0, 1, 0}), 0, 0, 1, kTol);
  // Lengths are preserved by an arbitrary rotation.
  EXPECT_NEAR(length(Transform::rotate({1, 2, 3}, 37)(Vec3{3, -1, 2})), std::sqrt(14.0), kTol);
}

TEST(CoreTransform, CompositionAppliesTheRightOperandFirst) {
  const Transform move = Transform::translate({10, 0, 0});
  const Transform turn = Transform::rotate({0, 0, 1}, 90);
  // (move * turn)(p) = move(turn(p)): rotate (1,0,0) to (0,1,0), then move.
  EXPECT_VEC_NEAR((move * turn)(Point3{1, 0, 0}), 10, 1, 0, kTol);
  // (turn * move)(p) = turn(move(p)): move to (11,0,0), then rotate.
  EXPECT_VEC_NEAR((turn * move)(Point3{1, 0, 0}), 0, 11, 0, kTol);
}

TEST(CoreTransform, InverseRoundTrips) {
  const Transform t = Transform::translate({1, -2, 3}) * Transform::rotate({1, 1, 0}, 33) *
                      Transform::scale(2, 0.5, -3);
  const Transform inv = t.inverse();
  const Point3 p{0.3, -7, 2};
  EXPECT_VEC_NEAR(inv(t(p)), p.x, p.y, p.z, 1e-12);
  EXPECT_VEC_NEAR(t(inv(p)), p.x, p.y, p.z, 1e-12);
  const Vec3 v{1, 2, 3};
  EXPECT_VEC_NEAR(inv(t(v)), v.x, v.y, v.z, 1e-12);
  const Normal3 n{0, 1, -1};
  EXPECT_VEC_NEAR(inv(t(n)), n.x, n.y, n.z, 1e-12);
  // The stored inverse agrees with Gauss–Jordan inversion of the matrix.
  const Matrix4 computed = glint::inverse(t.matrix());
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(computed.m[i][j], t.inverseMatrix().m[i][j], 1e-12);
  const Matrix4 product = t.matrix() * t.inverseMatrix();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(product.m[i][j], i == j ? 1 : 0, 1e-12);
}

TEST(CoreTransform, NormalStaysPerpendicularUnderNonUniformScale) {
  const Transform t = Transform::rotate({0, 1, 1}, 20) * Transform::scale(5, 1, 0.2);
  // A surface with normal n contains the tangents t1, t2.
  const Normal3 n = normalize(Normal3{1, 1, 1});
  const Vec3 t1{1, -1, 0};
  const Vec3 t2{1, 1, -2};
  const Normal3 mapped = t(n);
  EXPECT_NEAR(dot(mapped, t(t1)), 0, 1e-12);
  EXPECT_NEAR(dot(mapped, t(t2)), 0, 1e-12);
  // Mapping the normal like a vector would not stay perpendicular.
  EXPECT_GT(std::abs(dot(t(toVec(n)), t(t1))), 1);
}

TEST(CoreTransform, BoundsOfTransformedBoxes) {
  const Bounds3 unit(Point3{0, 0, 0}, Point3{1, 1, 1});
  EXPECT_EQ(Transform::translate({1, 2, 3})(unit), Bounds3(Point3{1, 2, 3}, Point3{2, 3, 4}));
  const Bounds3 rotated = Transform::rotate({0, 0, 1}, 45)(unit);
  const double c = std::sqrt(0.5);
  EXPECT_VEC_NEAR(rotated.lo, -c, 0, 0, kTol);
  EXPECT_VEC_NEAR(rotated.hi, c, 2 * c, 1, kTol);
  EXPECT_EQ(Transform::scale(2, 2, 2)(Bounds3::unbounded()), Bounds3::unbounded());
  EXPECT_TRUE(Transform::scale(2, 2, 2)(Bounds3()).isEmpty());
}

TEST(CoreTransform, RejectsZeroScaleAndZeroAxis) {
  EXPECT_THROW(Transform::scale(1, 0, 1), TransformError);
  EXPECT_THROW(Transform::scale(std::nan(""), 1, 1), TransformError);
  EXPECT_THROW(Transform::rotate({0, 0, 0}, 30), TransformError);
  Matrix4 singular = Matrix4::identity();
  singular.m[1][1] = 0;
  EXPECT_THROW(glint::inverse(singular), std::invalid_argument);
}

// -------------------------------------------------------------------------------------- Rng

TEST(CoreRng, SameKeyGivesSameStreamDifferentKeysDiffer) {
  Rng a = Rng::forPixelSample(3, 7, 2, 42);
  Rng b = Rng::forPixelSample(3, 7, 2, 42);
  Rng otherPixel = Rng::forPixelSample(7, 3, 2, 42);
  Rng otherSample = Rng::forPixelSample(3, 7, 3, 42);
  Rng otherSeed = Rng::forPixelSample(3, 7, 2, 43);
  int equalToOthers = 0;
  for (int i = 0; i < 100; ++i) {
    const std::uint64_t bits = a.nextBits();
    EXPECT_EQ(bits, b.nextBits());
    equalToOthers += bits == otherPixel.nextBits();
    equalToOthers += bits == otherSample.nextBits();
    equalToOthers += bits == otherSeed.nextBits();
  }
  EXPECT_EQ(equalToOthers, 0);
  // Child streams are deterministic too.
  Rng c = Rng(9);
  Rng d = Rng(9);
  Rng childC = c.split();
  Rng childD = d.split();
  EXPECT_EQ(childC.nextBits(), childD.nextBits());
  EXPECT_NE(Rng(9).nextBits(), Rng(9).split().nextBits());
}

TEST(CoreRng, UniformIsInRangeAndRoughlyUniform) {
  Rng rng(123);
  int buckets[10] = {};
  constexpr int kCount = 20000;
  double sum = 0;
  for (int i = 0; i < kCount; ++i) {
    const double u = rng.uniform();
    ASSERT_GE(u, 0);
    ASSERT_LT(u, 1);
    sum += u;
    ++buckets[static_cast<int>(u * 10)];
  }
  EXPECT_NEAR(sum / kCount, 0.5, 0.01);
  for (const int count : buckets) EXPECT_NEAR(count, kCount / 10, 200);  // ~4.7σ
}

TEST(CoreRng, Mix64IsABijectionOnSamples) {
  std::set<std::uint64_t> seen;
  for (std::uint64_t i = 0; i < 1000; ++i) seen.insert(mix64(i));
  EXPECT_EQ(seen.size(), 1000u);
  static_assert(mix64(0) != mix64(1));
}

// --------------------------------------------------------------------------------- Sampling

TEST(CoreSampling, Stratified2DSquareCountPutsOnePointPerCell) {
  constexpr std::uint32_t kN = 16;  // 4 × 4
  Rng rng(77);
  int cells[4][4] = {};
  for (std::uint32_t k = 0; k < kN; ++k) {
    const Point2 p = stratified2D(k, kN, rng.uniform(), rng.uniform(), 0);
    ASSERT_GE(p.x, 0);
    ASSERT_LT(p.x, 1);
    ASSERT_GE(p.y, 0);
    ASSERT_LT(p.y, 1);
    ++cells[static_cast<int>(p.x * 4)][static_cast<int>(p.y * 4)];
  }
  for (const auto& column : cells)
    for (const int count : column) EXPECT_EQ(count, 1);
}

TEST(CoreSampling, Stratified2DOtherCountsPutOnePointPerStratum) {
  constexpr std::uint32_t kN = 8;  // not a square: Hammersley-style
  for (const std::uint32_t scramble : {0u, 0x9abcdef0u}) {
    Rng rng(scramble);
    int xStrata[kN] = {};
    int yStrata[kN] = {};
    for (std::uint32_t k = 0; k < kN; ++k) {
      const Point2 p = stratified2D(k, kN, rng.uniform(), rng.uniform(), scramble);
      ++xStrata[static_cast<int>(p.x * kN)];
      ++yStrata[static_cast<int>(p.y * kN)];
    }
    for (std::uint32_t i = 0; i < kN; ++i) {
      EXPECT_EQ(xStrata[i], 1);
      EXPECT_EQ(yStrata[i], 1);  // the radical inverse also stratifies a power of two
    }
  }
  EXPECT_EQ(radicalInverse2(1), 0.5);
  EXPECT_EQ(radicalInverse2(2), 0.25);
  EXPECT_EQ(radicalInverse2(3), 0.75);
}

TEST(CoreSampling, SampleConeStaysInsideTheConeAndCentresOnTheAxis) {
  const Vec3 axis = normalize(Vec3{1, -2, 0.5});
  const double halfAngle = 10 * std::numbers::pi / 180;
  const double cosMax = std::cos(halfAngle);
  Rng rng(31);
  Vec3 mean;
  double smallestCos = 1;
  constexpr int kCount = 4000;
  for (int i = 0; i < kCount; ++i) {
    const Vec3 w = sampleCone(axis, cosMax, {rng.uniform(), rng.uniform()});
    EXPECT_NEAR(length(w), 1, 1e-12);
    smallestCos = std::min(smallestCos, dot(w, axis));
    mean += w;
  }
  EXPECT_GE(smallestCos, cosMax - 1e-12);
  EXPECT_LT(smallestCos, cosMax + 1e-3);  // and it reaches the rim
  // The mean of a uniform cap is along the axis with length (1 + cosMax) / 2.
  mean = mean / kCount;
  EXPECT_NEAR(dot(normalize(mean), axis), 1, 1e-4);
  EXPECT_NEAR(length(mean), (1 + cosMax) / 2, 1e-3);
  // A zero-width cone is the axis itself.
  EXPECT_VEC_NEAR(sampleCone(axis, 1, {0.3, 0.8}), axis.x, axis.y, axis.z, kTol);
}

TEST(CoreSampling, ConcentricDiskStaysInTheUnitDisk) {
  Rng rng(8);
  for (int i = 0; i < 1000; ++i) {
    const Point2 p = sampleConcentricDisk({rng.uniform(), rng.uniform()});
    EXPECT_LE(p.x * p.x + p.y * p.y, 1 + 1e-12);
  }
  const Point2 centre = sampleConcentricDisk({0.5, 0.5});
  EXPECT_EQ(centre.x, 0);
  EXPECT_EQ(centre.y, 0);
  const Point2 edge = sampleConcentricDisk({1, 0.5});
  EXPECT_NEAR(edge.x, 1, kTol);
  EXPECT_NEAR(edge.y, 0, kTol);
}

// ------------------------------------------------------------------------------------ Spawn

TEST(CoreSpawn, OffsetMovesToTheSideOfTheNewDirectionByABoundedAmount) {
  const Normal3 n{0, 0, 1};
  const Point3 p{0.5, -0.25, 0};
  const Point3 above = offsetRayOrigin(p, n, {0.3, 0, 1});
  const Point3 below = offsetRayOrigin(p, n, {0.3, 0, -1});
  EXPECT_GT(above.z, 0);
  EXPECT_LT(below.z, 0);
  // Near the origin the offset is kRayOffsetRelative scene units, along the normal only.
  EXPECT_DOUBLE_EQ(above.z, kRayOffsetRelative);
  EXPECT_DOUBLE_EQ(below.z, -kRayOffsetRelative);
  EXPECT_EQ(above.x, p.x);
  EXPECT_EQ(above.y, p.y);
  // Far from the origin it grows with the largest coordinate magnitude, staying relative.
  const Point3 far{-2e6, 10, 3};
  const Point3 farOffset = offsetRayOrigin(far, normalize(Normal3{1, 1, 0}), {1, 0, 0});
  const double moved = distance(far, farOffset);
  EXPECT_NEAR(moved, kRayOffsetRelative * 2e6, 1e-9);
  EXPECT_GT(dot(farOffset - far, Vec3{1, 1, 0}), 0);
  EXPECT_LT(moved / 2e6, 1e-8);
  // spawnRay keeps the direction.
  const Ray r = spawnRay(p, n, {0, 1, 1});
  EXPECT_EQ(r.direction, (Vec3{0, 1, 1}));
  EXPECT_EQ(r.origin, offsetRayOrigin(p, n, {0, 1, 1}));
}

// nextUp/nextDown (core/ulp.h) agree bit for bit with std::nextafter toward ±inf.
template <class T, class Bits>
void expectStepsAsNextafter() {
  constexpr T kInf = std::numeric_limits<T>::infinity();
  constexpr T kMax = std::numeric_limits<T>::max();
  constexpr T kTiny = std::numeric_limits<T>::denorm_min();
  constexpr T kMinNormal = std::numeric_limits<T>::min();
  for (const T x : {T(0), T(-0.0), kTiny, -kTiny, kMinNormal, -kMinNormal, T(1), T(-1), T(0.1),
                    T(-3e-30), T(2e6), T(-2e6), T(1e30), kMax, -kMax}) {
    EXPECT_EQ(std::bit_cast<Bits>(nextUp(x)), std::bit_cast<Bits>(std::nextafter(x, kInf))) << x;
    EXPECT_EQ(std::bit_cast<Bits>(nextDown(x)), std::bit_cast<Bits>(std::nextafter(x, -kInf))) << x;
  }
  // Each infinity steps away from itself to the largest finite value (the build's outward rounding
  // relies on it).
  EXPECT_EQ(std::bit_cast<Bits>(nextUp(-kInf)), std::bit_cast<Bits>(std::nextafter(-kInf, kInf)));
  EXPECT_EQ(std::bit_cast<Bits>(nextDown(kInf)), std::bit_cast<Bits>(std::nextafter(kInf, -kInf)));
}

TEST(CoreUlp, NextUpAndDownStepExactlyAsNextafter) {
  expectStepsAsNextafter<double, std::uint64_t>();
  expectStepsAsNextafter<float, std::uint32_t>();
}

}  // namespace
}  // namespace glint
