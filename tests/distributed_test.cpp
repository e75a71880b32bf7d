// Distributed ray tracing (issue 5): soft shadows from area lights against a closed form, depth of
// field, the image mean under anti-aliasing, convergence with the sample count, and determinism
// with every sampled effect on at once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <utility>
#include <vector>

#include "glint/geometry/shape.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "test_scenes.h"

namespace glint {
namespace {

std::uint32_t addMaterial(SceneParts& parts, const Material& material) {
  parts.materials.push_back(material);
  return static_cast<std::uint32_t>(parts.materials.size() - 1);
}

bool bitwiseEqual(const Film& a, const Film& b) {
  return a.region() == b.region() && a.pixels().size() == b.pixels().size() &&
         std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Color)) == 0;
}

// Area of the intersection of two disks of radii r1, r2 whose centres are d apart.
double circleOverlapArea(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0;
  if (d <= std::abs(r1 - r2)) return std::numbers::pi * std::min(r1, r2) * std::min(r1, r2);
  const double a1 = std::acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1));
  const double a2 = std::acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2));
  const double kite = std::sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2));
  return r1 * r1 * a1 + r2 * r2 * a2 - kite / 2;
}

TEST(DistributedAnalytic, DiskLightBehindAnOccludingDiskMatchesTheCircleOverlap) {
  // Floor y = 0; a disk light of radius R at height H above the origin; an opaque coaxial disk of
  // radius a at height h between. From P = (x, 0, 0) the occluder projects onto the light's plane
  // as a disk of radius a·H/h centred x·(H/h − 1) from the axis (central projection between
  // parallel planes is a similarity), so the unshadowed fraction of the light's area is
  //   1 − overlap(R, a·H/h, |x|·(H/h − 1)) / (π R²).
  // The floor is ks = 1, shininess 0, no attenuation: every unshadowed light point contributes
  // exactly I0 = 1 whatever its direction, so the shaded value is the unshadowed fraction.
  constexpr double kR = 1, kH = 4, kA = 0.55, kh = 2;
  constexpr int kSamples = 256;
  SceneParts parts;
  parts.camera.fovDegrees = 40;
  parts.camera.position = {0, 0.5, 3};
  Material floor;
  floor.ks = Color(1);
  floor.shininess = 0;
  floor.ka = Color(0);
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), addMaterial(parts, floor),
                                Color{});
  parts.primitives.emplace_back(Disk::make({0, kh, 0}, {0, 1, 0}, kA), 0u, Color{});
  AreaLight light;
  light.shape = AreaShape::Disk;
  light.center = {0, kH, 0};
  light.normal = {0, 1, 0};
  light.radius = kR;
  light.intensity = Color(1);
  light.samples = kSamples;
  parts.lights.push_back(light);
  const Scene scene(std::move(parts));

  const double projectedRadius = kA * kH / kh;
  for (const double x : {0.0, 0.3, 0.8, 1.2, 1.7, 2.5}) {
    const double expected = 1 - circleOverlapArea(kR, projectedRadius, x * (kH / kh - 1)) /
                                    (std::numbers::pi * kR * kR);
    // Independent sampling would have this standard deviation; the stratified sampler must do at
    // least as well for one estimate, and the mean of 16 independently scrambled ones 4× better.
    const double sigma = std::sqrt(expected * (1 - expected) / kSamples);
    double mean = 0;
    for (std::uint64_t key = 0; key < 16; ++key) {
      Rng rng(key);
      const Color c = traceRay(scene, Ray{{x, 0.5, 0}, {0, -1, 0}}, rng);
      EXPECT_NEAR(c.r, expected, 3 * sigma + 1e-12) << "x = " << x << ", key " << key;
      mean += c.r / 16;
    }
    EXPECT_NEAR(mean, expected, 0.75 * sigma + 1e-12) << "x = " << x;
  }
  // The cases above cover the umbra (0), penumbra and fully lit (1) regions.
  EXPECT_EQ(circleOverlapArea(kR, projectedRadius, 0), std::numbers::pi * kR * kR);
  EXPECT_EQ(circleOverlapArea(kR, projectedRadius, 2.5), 0);
}

// Camera at the origin looking down −z, view plane 2 × 0.4 at distance 1, with an emissive white
// half-plane (a large rectangle) whose vertical edge is seen at x = 0.0737 on the view plane.
SceneParts edgeParts(double depth, double aperture) {
  SceneParts parts;
  parts.camera.viewPlaneWidth = 2;
  parts.camera.viewPlaneHeight = 0.4;
  parts.camera.viewPlaneDistance = 1;
  parts.camera.aperture = aperture;
  parts.camera.focusDistance = 5;
  parts.image.width = 40;
  parts.image.height = 8;
  parts.image.samples = 16;
  parts.image.encoding = Encoding::Linear;
  const double edge = 0.0737 * depth;
  parts.primitives.emplace_back(
      Rectangle::make({edge, -depth, -depth}, {3 * depth, 0, 0}, {0, 2 * depth, 0}), 0u,
      Color(1, 1, 1));
  return parts;
}

int partialPixels(const Film& film) {
  int partial = 0;
  for (const Color& c : film.pixels()) partial += c.r > 0 && c.r < 1;
  return partial;
}

TEST(DistributedAnalytic, FocusPlaneIsAsSharpWithApertureAsWithout) {
  // Every lens ray of a pixel sample passes through the point where the pinhole ray meets the
  // focus plane, so an edge on that plane gives the same pixels.
  const Film pinhole = render(Scene(edgeParts(5, 0)));
  const Film lens = render(Scene(edgeParts(5, 0.5)));
  for (std::size_t i = 0; i < pinhole.pixels().size(); ++i) {
    EXPECT_NEAR(lens.pixels()[i].r, pinhole.pixels()[i].r, 1e-12) << i;
  }
  EXPECT_GT(partialPixels(pinhole), 0);
  EXPECT_LE(partialPixels(pinhole), 8);  // one column of edge pixels
  // The same edge off the focus plane (depth 2, focus 5) is blurred: the circle of confusion on
  // the view plane has radius 0.5·|1/2 − 1/5| = 0.15, three pixels.
  const Film nearPinhole = render(Scene(edgeParts(2, 0)));
  const Film nearLens = render(Scene(edgeParts(2, 0.5)));
  EXPECT_LE(partialPixels(nearPinhole), 8);
  EXPECT_GE(partialPixels(nearLens), 3 * 8);
}

TEST(DistributedAnalytic, AntiAliasingKeepsTheImageMeanOfAnEmissiveDisk) {
  // A white emissive disk of radius 1.3 at z = −4 facing the camera, on black: on the 2 × 2 view
  // plane at distance 1 it covers a disk of radius 1.3/4, so the exact image mean is
  // π (1.3/4)² / 4. Anti-aliased pixels hold their covered fractions, whose mean is that value.
  const double exact = std::numbers::pi * (1.3 / 4) * (1.3 / 4) / 4;
  const auto meanOf = [](const Film& film) {
    double sum = 0;
    for (const Color& c : film.pixels()) sum += c.r;
    return sum / static_cast<double>(film.pixels().size());
  };
  const auto parts = [](int samples, bool adaptive) {
    SceneParts p;
    p.camera.viewPlaneWidth = 2;
    p.camera.viewPlaneHeight = 2;
    p.camera.viewPlaneDistance = 1;
    p.image.width = 32;
    p.image.height = 32;
    p.image.samples = samples;
    if (adaptive) p.image.adaptive = AdaptiveSampling{64, 0.02};
    p.primitives.emplace_back(Disk::make({0.2, -0.1, -4}, {0, 0, 1}, 1.3), 0u, Color(1, 1, 1));
    return p;
  };
  const double fixed16 = meanOf(render(Scene(parts(16, false))));
  const double fixed64 = meanOf(render(Scene(parts(64, false))));
  RenderStats stats;
  const double adaptive = meanOf(render(Scene(parts(4, true)), {}, &stats));
  EXPECT_NEAR(fixed16, exact, 1e-3);
  EXPECT_NEAR(fixed64, exact, 5e-4);
  EXPECT_NEAR(adaptive, exact, 1e-3);
  // Adaptive spent extra samples only near the rim: far fewer than 64 everywhere.
  EXPECT_GT(stats.samples, 32u * 32u * 4u);
  EXPECT_LT(stats.samples, 32u * 32u * 16u);
}

// A floor under a sphere lit by a square area light above: the floor shows the sphere's soft
// shadow (umbra and a wide penumbra). One sample per pixel, so only the light sampling varies.
SceneParts softShadowParts(int lightSamples, std::uint64_t seed) {
  SceneParts parts;
  parts.camera.position = {0, 5, 5};
  parts.camera.direction = {0, -1, -1};
  parts.camera.fovDegrees = 40;
  parts.image.width = 10;
  parts.image.height = 8;
  parts.image.encoding = Encoding::Linear;
  parts.render.seed = seed;
  Material diffuse;
  diffuse.kd = Color(0.8);
  diffuse.ka = Color(0);
  const std::uint32_t m = addMaterial(parts, diffuse);
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), m, Color{});
  parts.primitives.emplace_back(Sphere::make({0, 0.9, 0}, 0.6), m, Color{});
  AreaLight light;
  light.corner = {-1.5, 4, -1.5};
  light.edge1 = {3, 0, 0};
  light.edge2 = {0, 0, 3};
  light.intensity = Color(12);
  light.samples = lightSamples;
  parts.lights.push_back(light);
  return parts;
}

TEST(DistributedConvergence, SoftShadowErrorFallsAtLeastLikeOneOverSqrtN) {
  // RMS error over the image (and four seeds) against a 4096-sample reference (another seed), for
  // N = 1, 4, 16, 64 light samples; the least-squares slope of log error against log N must be
  // −0.5 or steeper (stratified Sobol points reach about −0.75 on a penumbra).
  const Film reference = render(Scene(softShadowParts(4096, 99)));
  std::vector<double> logN, logError;
  for (const int n : {1, 4, 16, 64}) {
    double squared = 0;
    std::size_t count = 0;
    for (std::uint64_t seed = 0; seed < 4; ++seed) {
      const Film film = render(Scene(softShadowParts(n, seed)));
      for (std::size_t i = 0; i < film.pixels().size(); ++i) {
        const double d = film.pixels()[i].r - reference.pixels()[i].r;
        squared += d * d;
        ++count;
      }
    }
    logN.push_back(std::log(static_cast<double>(n)));
    logError.push_back(std::log(std::sqrt(squared / static_cast<double>(count))));
  }
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < logN.size(); ++i) {
    mx += logN[i] / 4;
    my += logError[i] / 4;
  }
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < logN.size(); ++i) {
    sxy += (logN[i] - mx) * (logError[i] - my);
    sxx += (logN[i] - mx) * (logN[i] - mx);
  }
  const double slope = sxy / sxx;
  EXPECT_LT(slope, -0.5) << "error ∝ N^" << slope;
  for (std::size_t i = 1; i < logError.size(); ++i) EXPECT_LT(logError[i], logError[i - 1]) << i;
  // The scene does have a penumbra to converge on: the 1-sample error is not negligible.
  EXPECT_GT(std::exp(logError[0]), 0.01);
}

// Every sampled effect at once: adaptive anti-aliasing, depth of field, glossy reflection and
// blurred refraction, and all three area-light shapes (one behind glass, so the kt product
// applies per light sample).
SceneParts everythingParts(std::uint64_t seed) {
  SceneParts parts = testing::glossyTestScene(seed);
  parts.camera.aperture = 0.08;
  parts.camera.focusDistance = 5;
  parts.image.samples = 2;
  parts.image.adaptive = AdaptiveSampling{12, 0.01};
  parts.render.blurSamples = 3;
  parts.render.maxDepth = 4;
  parts.lights.clear();  // the glossy scene's point and directional lights give way to area lights
  AreaLight rectangle;
  rectangle.corner = {1, 4, 0};
  rectangle.edge1 = {1.5, 0, 0};
  rectangle.edge2 = {0, 0, 1.5};
  rectangle.intensity = Color(0.9, 0.85, 0.8);
  rectangle.samples = 3;
  AreaLight disk;
  disk.shape = AreaShape::Disk;
  disk.center = {-2, 3, 1};
  disk.normal = normalize(Vec3{1, -1, 0});
  disk.radius = 0.8;
  disk.intensity = Color(0.5, 0.5, 0.7);
  disk.samples = 2;
  AreaLight sphere;
  sphere.shape = AreaShape::Sphere;
  sphere.center = {0.2, 2.5, -1};
  sphere.radius = 0.4;
  sphere.intensity = Color(0.6);
  sphere.attenuation = {1, 0, 0.05};
  sphere.samples = 2;
  parts.lights.push_back(rectangle);
  parts.lights.push_back(disk);
  parts.lights.push_back(sphere);
  return parts;
}

TEST(DistributedDeterminism, ThreadsTilesAndCropsGiveTheSameBytes) {
  const Scene scene(everythingParts(0));
  RenderOptions one;
  one.threads = 1;
  RenderOptions two;
  two.threads = 2;
  two.tileSize = 7;
  RenderStats statsOne, statsTwo, statsTwoSameTiles;
  const Film full = render(scene, one, &statsOne);
  EXPECT_TRUE(bitwiseEqual(full, render(scene, two, &statsTwo)));
  // The same samples in every pixel; the rays traced depend on the tiles only (adaptive sampling
  // recomputes the first batches of a ring around each tile), not on the threads.
  EXPECT_EQ(statsOne.samples, statsTwo.samples);
  RenderOptions twoSameTiles;
  twoSameTiles.threads = 2;
  EXPECT_TRUE(bitwiseEqual(full, render(scene, twoSameTiles, &statsTwoSameTiles)));
  EXPECT_EQ(statsOne.rays.camera, statsTwoSameTiles.rays.camera);
  EXPECT_EQ(statsOne.rays.shadow, statsTwoSameTiles.rays.shadow);
  EXPECT_EQ(statsOne.rays.total(), statsTwoSameTiles.rays.total());
  // Adaptive refined some pixels (the initial count is 4) but not all to the cap.
  EXPECT_GT(statsOne.samples, 24u * 20u * 4u);
  EXPECT_LT(statsOne.samples, 24u * 20u * 12u);

  // Crops with edges off the tile grid, stitched, equal the full render bit for bit.
  const int xs[] = {0, 9, 17, 24};
  const int ys[] = {0, 7, 20};
  Film stitched(24, 20, PixelRegion{0, 0, 24, 20});
  for (int cy = 0; cy < 2; ++cy) {
    for (int cx = 0; cx < 3; ++cx) {
      RenderOptions options;
      options.crop = PixelRegion{xs[cx], ys[cy], xs[cx + 1], ys[cy + 1]};
      options.threads = 1 + (cx + cy) % 2;
      options.tileSize = 5;
      const Film part = render(scene, options);
      for (int y = 0; y < part.height(); ++y)
        for (int x = 0; x < part.width(); ++x) stitched.at(xs[cx] + x, ys[cy] + y) = part.at(x, y);
    }
  }
  EXPECT_TRUE(bitwiseEqual(stitched, full));

  // The seed varies the samples of almost every pixel.
  const Film other = render(Scene(everythingParts(1)));
  int differing = 0;
  for (std::size_t i = 0; i < full.pixels().size(); ++i)
    differing += !(full.pixels()[i] == other.pixels()[i]);
  EXPECT_GT(differing, 24 * 20 / 2);
}

}  // namespace
}  // namespace glint
