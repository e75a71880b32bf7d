// Texture evaluation and filtering: a 2×2 image's texels under nearest, bilinear and trilinear
// lookups, mip level selection at known footprints, mip building, the solid checker, the uv
// transform, Perlin noise, and the environment's equirectangular directions.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "glint/scene/environment.h"
#include "glint/scene/mip_map.h"
#include "glint/scene/texture.h"

namespace glint {
namespace {

constexpr double kTol = 1e-6;

// Rows from the top: top-left red, top-right green, bottom-left blue, bottom-right white.
RgbImage twoByTwo() {
  return RgbImage{2, 2, {1, 0, 0, 0, 1, 0, /* bottom row */ 0, 0, 1, 1, 1, 1}};
}

void expectColor(const Color& c, double r, double g, double b, double tol = kTol) {
  EXPECT_NEAR(c.r, r, tol);
  EXPECT_NEAR(c.g, g, tol);
  EXPECT_NEAR(c.b, b, tol);
}

TEST(MipMap, NearestReturnsEachTexelOfATwoByTwoImage) {
  const MipMap m(twoByTwo());
  // (0, 0) is the image's bottom-left corner, (1, 1) its top-right.
  expectColor(m.nearest({0.25, 0.75}), 1, 0, 0);
  expectColor(m.nearest({0.75, 0.75}), 0, 1, 0);
  expectColor(m.nearest({0.25, 0.25}), 0, 0, 1);
  expectColor(m.nearest({0.75, 0.25}), 1, 1, 1);
  expectColor(m.nearest({0.99, 0.01}), 1, 1, 1);
  expectColor(m.nearest({1.25, -0.25}), 1, 0, 0);  // repeats: (0.25, 0.75)
}

TEST(MipMap, BilinearInterpolatesBetweenTexelCentres) {
  const MipMap m(twoByTwo());
  expectColor(m.bilinear(0, {0.25, 0.75}), 1, 0, 0);  // a texel centre: the texel itself
  expectColor(m.bilinear(0, {0.75, 0.25}), 1, 1, 1);
  // Halfway between the two top texels.
  expectColor(m.bilinear(0, {0.5, 0.75}), 0.5, 0.5, 0);
  // The centre: the mean of all four.
  expectColor(m.bilinear(0, {0.5, 0.5}), 0.5, 0.5, 0.5);
  // At the left edge, halfway to the wrapped right column.
  expectColor(m.bilinear(0, {0, 0.75}), 0.5, 0.5, 0);
}

TEST(MipMap, TrilinearPicksTheLevelOfTheFootprint) {
  const MipMap m(twoByTwo());
  ASSERT_EQ(m.levels(), 2);
  expectColor(m.texel(1, 0, 0), 0.5, 0.5, 0.5);
  // A footprint of one texel (1/2 in st): level 0, the texel itself.
  expectColor(m.trilinear({0.25, 0.75}, 0.5), 1, 0, 0);
  // Smaller footprints stay at level 0.
  expectColor(m.trilinear({0.25, 0.75}, 0.01), 1, 0, 0);
  // The whole image: level 1, the mean.
  expectColor(m.trilinear({0.25, 0.75}, 1), 0.5, 0.5, 0.5);
  // Halfway in log2 between them: level 0.5, the blend.
  expectColor(m.trilinear({0.25, 0.75}, std::sqrt(0.5)), 0.75, 0.25, 0.25);
}

TEST(MipMap, LevelAtAKnownFootprint) {
  RgbImage big{256, 64, std::vector<float>(256 * 64 * 3, 0.5f)};
  const MipMap m(std::move(big));
  EXPECT_EQ(m.levels(), 9);  // 256×64, 128×32, ..., 1×1
  EXPECT_EQ(m.width(2), 64);
  EXPECT_EQ(m.height(2), 16);
  EXPECT_EQ(m.height(7), 1);
  // pbrt-v4: levels − 1 + log2(width): one texel of level 0 (1/256) is level 0; four, level 2.
  EXPECT_NEAR(m.levelFor(1.0 / 256), 0, kTol);
  EXPECT_NEAR(m.levelFor(4.0 / 256), 2, kTol);
  EXPECT_NEAR(m.levelFor(1), 8, kTol);
}

TEST(MipMap, OddSizesAverageWithFractionalCoverage) {
  // A 3×1 image → 1×1: every texel counts a third.
  const MipMap m(RgbImage{3, 1, {0, 0, 0, 0.3f, 0.3f, 0.3f, 0.9f, 0.9f, 0.9f}});
  ASSERT_EQ(m.levels(), 2);
  expectColor(m.texel(1, 0, 0), 0.4, 0.4, 0.4);
  EXPECT_EQ(m.memoryBytes(), MipMap::bytesFor(3, 1));
}

TEST(Texture, SolidCheckerAtCellCentres) {
  // The pattern's origin at `center`: the cell centres move with it.
  for (const Point3 origin : {Point3{0, 0, 0}, Point3{0.2, -0.3, 1.1}}) {
    const Texture t = CheckerTexture{{Color(0.1), Color(0.9)}, 0.5, origin};
    for (int i = -3; i <= 3; ++i) {
      for (int j = -3; j <= 3; ++j) {
        for (int k = -3; k <= 3; ++k) {
          const Point3 centre{origin.x + (i + 0.5) * 0.5, origin.y + (j + 0.5) * 0.5,
                              origin.z + (k + 0.5) * 0.5};
          const bool odd = ((i + j + k) % 2 + 2) % 2 == 1;
          EXPECT_EQ(evaluate(t, {centre, {}, {}, {}}).r, odd ? 0.9 : 0.1)
              << i << " " << j << " " << k;
        }
      }
    }
  }
}

// A point a few ulps off a cell boundary (a transformed face on it, its hit point brought back
// through the inverse transform) takes the boundary's cell, as the exact point does: the face
// is one colour, not speckled with both.
TEST(Texture, SolidCheckerPointsWithinRoundingOfABoundaryTakeItsCell) {
  const Texture t = CheckerTexture{{Color(0.1), Color(0.9)}, 0.5, Point3{}};
  const auto colorAt = [&](double x) { return evaluate(t, {Point3{x, 0.25, 0.25}, {}, {}, {}}).r; };
  for (const double boundary : {1.0, -1.0, 0.0, 1e6 + 0.5}) {
    const double exact = colorAt(boundary);
    double below = boundary;
    double above = boundary;
    for (int ulps = 1; ulps <= 4; ++ulps) {
      below = std::nextafter(below, -HUGE_VAL);
      above = std::nextafter(above, HUGE_VAL);
      EXPECT_EQ(colorAt(below), exact) << boundary << " - " << ulps << " ulps";
      EXPECT_EQ(colorAt(above), exact) << boundary << " + " << ulps << " ulps";
    }
    // A millionth of a cell away (near the origin) is the cell it is in.
    if (std::abs(boundary) <= 1) {
      EXPECT_NE(colorAt(boundary - 0.5e-6), exact) << boundary;
      EXPECT_EQ(colorAt(boundary + 0.5e-6), exact) << boundary;
    }
  }
  // Far from the origin in cells (a tiny scale), points well inside a cell keep their cell: the
  // slack never grows past a millionth of a cell.
  const Texture fine = CheckerTexture{{Color(0.1), Color(0.9)}, 1e-6, Point3{}};
  const auto fineAt = [&](double x) { return evaluate(fine, {Point3{x, 0, 0}, {}, {}, {}}).r; };
  EXPECT_EQ(fineAt(0.5 + 0.3e-6), fineAt(0.5 + 0.7e-6));  // cells 500000.3 and .7: one cell
  EXPECT_NE(fineAt(0.5 + 0.7e-6), fineAt(0.5 + 1.2e-6));
}

TEST(Texture, Checker2dAppliesRepeatOffsetAndRotation) {
  UvTransform transform;
  transform.repeat = {4, 2};
  const Texture t = Checker2dTexture{{Color(0), Color(1)}, transform};
  EXPECT_EQ(evaluate(t, {{}, {0.1, 0.1}, {}, {}}).r, 0);
  EXPECT_EQ(evaluate(t, {{}, {0.3, 0.1}, {}, {}}).r, 1);
  EXPECT_EQ(evaluate(t, {{}, {0.3, 0.6}, {}, {}}).r, 0);
  // Rotated by 90°: (u, v) ↦ (−v, u).
  UvTransform rotated;
  rotated.cosRotate = 0;
  rotated.sinRotate = 1;
  const Point2 p = rotated.apply({0.25, 0.5});
  EXPECT_NEAR(p.x, -0.5, kTol);
  EXPECT_NEAR(p.y, 0.25, kTol);
}

TEST(Texture, PerlinNoiseIsZeroOnTheLatticeAndBounded) {
  EXPECT_EQ(perlinNoise({0, 0, 0}), 0);
  EXPECT_EQ(perlinNoise({3, -7, 12}), 0);
  for (int i = 0; i < 1000; ++i) {
    const double n = perlinNoise({i * 0.173, i * 0.311, i * 0.0917});
    EXPECT_LE(std::abs(n), 1.0);
  }
  // Lattice points past int64's range (a tamed 1e15 times an octave's 2^15): on the lattice, so 0
  // (the sanitizers' float-cast-overflow check sees the cell's conversion).
  EXPECT_EQ(perlinNoise({1.6384e19, 3.3e19, -3.3e19}), 0);
  const Texture fine =
      NoiseTexture{NoisePattern::Noise, {Color(0.2), Color(0.6)}, 1e-16, 0, 16, Point3{}};
  const double far = evaluate(fine, {{0.3, 0.7, 0.1}, {}, {}, {}}).r;
  EXPECT_GE(far, 0.2 - kTol);
  EXPECT_LE(far, 0.6 + kTol);
  // The marble, wood and noise patterns stay between their two colours.
  for (const NoisePattern pattern :
       {NoisePattern::Noise, NoisePattern::Marble, NoisePattern::Wood}) {
    const Texture t = NoiseTexture{pattern, {Color(0.2), Color(0.6)}, 0.3, 2, 4, Point3{}};
    for (int i = 0; i < 200; ++i) {
      const double v = evaluate(t, {{i * 0.07, i * 0.05, -i * 0.03}, {}, {}, {}}).r;
      EXPECT_GE(v, 0.2 - kTol);
      EXPECT_LE(v, 0.6 + kTol);
    }
  }
}

TEST(Environment, EquirectangularDirections) {
  // −z is the centre column, +y the top row, +x at u = 0.75.
  const Point2 back = equirectangularUv({0, 0, -1});
  EXPECT_NEAR(back.x, 0.5, kTol);
  EXPECT_NEAR(back.y, 0.5, kTol);
  EXPECT_NEAR(equirectangularUv({0, 1, 0}).y, 1, kTol);
  EXPECT_NEAR(equirectangularUv({0, -1, 0}).y, 0, kTol);
  EXPECT_NEAR(equirectangularUv({1, 0, 0}).x, 0.75, kTol);
  EXPECT_NEAR(equirectangularUv({-1, 0, 0}).x, 0.25, kTol);
}

TEST(Environment, ImageAndRotationAndGradient) {
  // 4×2: the top row red, green, blue, white from left to right; the bottom row black.
  RgbImage image{4, 2, std::vector<float>(4 * 2 * 3, 0.0f)};
  const float top[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (int x = 0; x < 4; ++x) {
    for (int c = 0; c < 3; ++c) image.pixels[static_cast<std::size_t>(3 * x + c)] = top[x][c];
  }
  Environment e;
  e.kind = BackgroundKind::Image;
  e.image = std::make_shared<const MipMap>(std::move(image));
  e.intensity = 2;
  // The centre of the top row's second texel (green): u = 0.375, v = 0.75.
  const double r = std::sqrt(0.5);
  expectColor(e.along({-0.5, r, -0.5}, Color()), 0, 2, 0);
  // The centre of the top row's third texel (blue): u = 0.625.
  expectColor(e.along({0.5, r, -0.5}, Color()), 0, 0, 2);
  // Turned by +90° about +y (counter-clockwise seen from above), green moves to (−0.5, ·, +0.5).
  e.cosRotate = 0;
  e.sinRotate = 1;
  expectColor(e.along({-0.5, r, 0.5}, Color()), 0, 2, 0);
  // Straight up and down: the top row's and the bottom row's colours alone, the rows not wrapping
  // into each other at the poles (the top row's mean there: its texels around the pole).
  e.cosRotate = 1;
  e.sinRotate = 0;
  const Color up = e.along({0, 1, 0}, Color());
  EXPECT_GT(up.r + up.g + up.b, 0);
  const Color nearUp = e.along({0, 0.99999, -std::sqrt(1 - 0.99999 * 0.99999)}, Color());
  expectColor(nearUp, 0, 1, 1, 1e-3);  // u = 0.5: halfway between the green and the blue texel
  expectColor(e.along({0, -1, 0}, Color()), 0, 0, 0);
  expectColor(e.along({0, -0.99999, -std::sqrt(1 - 0.99999 * 0.99999)}, Color()), 0, 0, 0);
  // The plain lookup (textures) still repeats vertically: at v = 1 the top and bottom rows blend.
  expectColor(e.image->bilinear(0, {0.375, 1}), 0, 0.5, 0);
  expectColor(e.image->bilinear(0, {0.375, 1}, true), 0, 1, 0);

  Environment g;
  g.kind = BackgroundKind::Gradient;
  g.zenith = Color(0, 0, 1);
  g.horizon = Color(1, 1, 1);
  g.nadir = Color(0.2, 0.1, 0);
  expectColor(g.along({0, 1, 0}, Color()), 0, 0, 1);
  expectColor(g.along({1, 0, 0}, Color()), 1, 1, 1);
  expectColor(g.along({0, -1, 0}, Color()), 0.2, 0.1, 0);
  expectColor(g.along({r, r, 0}, Color()), 0.5, 0.5, 1);  // 45°: halfway in elevation
  Environment uniform;
  expectColor(uniform.along({0, 1, 0}, Color(0.3)), 0.3, 0.3, 0.3);

  // Tachyon's sky: bottom + (top − bottom) · clamp((t − bottom value) / (top − bottom value), 0, 1)
  // with t = d·up, or o·up for the ray's origin o (by height).
  Environment sky;
  sky.kind = BackgroundKind::Sky;
  sky.skyUp = Vec3(0, 0, 1);
  sky.skyTop = Color(0, 0, 1);
  sky.skyBottom = Color(1, 1, 0);
  sky.topValue = 0.5;
  sky.bottomValue = -0.5;
  expectColor(sky.along({0, 0, 1}, Color()), 0, 0, 1);        // past the top value: the top colour
  expectColor(sky.along({0, 0, -1}, Color()), 1, 1, 0);       // below the bottom one: the bottom
  expectColor(sky.along({1, 0, 0}, Color()), 0.5, 0.5, 0.5);  // t = 0: halfway
  expectColor(sky.along({0, 0.8, 0.25 * 0.8 / 0.2 * 0.2}, Color()), 0.3, 0.3, 0.7);  // t = 0.2
  // By height the direction does not matter, the origin does.
  sky.skyByHeight = true;
  expectColor(sky.along({0, 0, 1}, Color(), {3, -2, 0.25}), 0.25, 0.25, 0.75);
  expectColor(sky.along({0, 1, 0}, Color(), {3, -2, 0.25}), 0.25, 0.25, 0.75);
  expectColor(sky.along({0, 1, 0}, Color(), {0, 0, -7}), 1, 1, 0);
}

}  // namespace
}  // namespace glint
