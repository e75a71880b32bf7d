// Analytic image tests: small scenes whose pixel values are known in closed form (DESIGN.md §3).
// Every expected value is computed here independently of the renderer — ray from the camera (§4),
// analytic intersection, the shading formula — and compared with the film's linear values.
//
// Tolerance: 1e-9 relative (plus 1e-12 absolute for values near 0). The renderer and these formulas
// differ only by rounding order in double precision (~1e-15 relative per operation); 1e-9 leaves
// room for the ray-origin offset (1e-9 × coordinate magnitude, core/spawn.h) where it moves a
// shadow or secondary ray's start, while any wrong factor (a missing |n·l|, attenuation, kt) is far
// larger.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "glint/geometry/shape.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "glint/scene/seed_scene.h"

namespace glint {
namespace {

constexpr double kRelTol = 1e-9;
constexpr double kAbsTol = 1e-12;

::testing::AssertionResult colorNear(const Color& actual, const Color& expected) {
  const auto close = [](double a, double e) {
    return std::abs(a - e) <= kRelTol * std::abs(e) + kAbsTol;
  };
  if (close(actual.r, expected.r) && close(actual.g, expected.g) && close(actual.b, expected.b))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "got (" << actual.r << ", " << actual.g << ", " << actual.b << "), expected ("
         << expected.r << ", " << expected.g << ", " << expected.b << ")";
}

// Camera at the origin looking down −z (right = +x, up = +y); view plane viewWidth × viewHeight at
// distance 1; linear encoding.
SceneParts baseParts(int width, int height, double viewWidth, double viewHeight) {
  SceneParts parts;
  parts.camera.position = {0, 0, 0};
  parts.camera.direction = {0, 0, -1};
  parts.camera.up = {0, 1, 0};
  parts.camera.viewPlaneWidth = viewWidth;
  parts.camera.viewPlaneHeight = viewHeight;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = width;
  parts.image.height = height;
  parts.image.encoding = Encoding::Linear;
  parts.render.minWeight = 0;
  return parts;
}

std::uint32_t addMaterial(SceneParts& parts, const Material& material) {
  parts.materials.push_back(material);
  return static_cast<std::uint32_t>(parts.materials.size() - 1);
}

// Analytic ray–sphere intersection (the seed's t_m ± t_h form) for a unit direction. Returns the
// nearest t > 0, or nullopt; `grazing` is set when the ray passes within a relative 1e-6 of the
// silhouette, where a test should not insist on hit or miss.
std::optional<double> hitSphere(const Ray& ray, const Point3& center, double radius,
                                bool* grazing = nullptr) {
  const Vec3 u = center - ray.origin;
  const double tm = dot(ray.direction, u);
  const double d2 = lengthSquared(u) - tm * tm;
  const double h2 = radius * radius - d2;
  if (grazing) *grazing = std::abs(h2) < 1e-6 * radius * radius;
  if (h2 < 0) return std::nullopt;
  const double th = std::sqrt(h2);
  if (tm - th > 0) return tm - th;
  if (tm + th > 0) return tm + th;
  return std::nullopt;
}

// Number of times the ray crosses the sphere's surface at t > 0 (0 or 2 from outside).
int sphereCrossings(const Ray& ray, const Point3& center, double radius, bool& grazing) {
  const Vec3 u = center - ray.origin;
  const double tm = dot(ray.direction, u);
  const double h2 = radius * radius - (lengthSquared(u) - tm * tm);
  grazing = grazing || std::abs(h2) < 1e-6 * radius * radius;
  if (h2 <= 0) return 0;
  const double th = std::sqrt(h2);
  return (tm - th > 0 ? 1 : 0) + (tm + th > 0 ? 1 : 0);
}

// Hit of a ray with the plane z = planeZ.
Point3 hitPlaneZ(const Ray& ray, double planeZ) {
  return ray.at((planeZ - ray.origin.z) / ray.direction.z);
}

Color phong(const Material& m, const Color& intensity, const Normal3& n, const Vec3& l,
            const Vec3& v) {
  const double nl = dot(n, l);
  if (!(nl * dot(n, v) > 0)) return Color{};
  Color response = m.kd * std::abs(nl);
  if (!isBlack(m.ks)) {
    const Vec3 r = l - toVec(n) * (2 * nl);
    response += m.ks * std::pow(std::max(0.0, -dot(v, r)), m.shininess);
  }
  return intensity * response;
}

// --- Direct lighting --------------------------------------------------------------------------

void checkLitSphere(const Material& material) {
  const Point3 center{0.3, -0.2, -5};
  const double radius = 1.5;
  const Vec3 l = normalize(Vec3{1, -1, -1});
  const Color intensity = Color(1, 0.9, 0.7) * 1.5;
  const Color background(0.1, 0.2, 0.3);

  SceneParts parts = baseParts(21, 21, 0.9, 0.9);
  parts.background = background;
  parts.primitives.emplace_back(Sphere::make(center, radius), addMaterial(parts, material),
                                Color{});
  parts.lights.push_back(DirectionalLight{l, intensity});
  const Scene scene(std::move(parts));
  const Film film = render(scene);

  int lit = 0, unlit = 0, missed = 0;
  for (int row = 0; row < 21; ++row) {
    for (int column = 0; column < 21; ++column) {
      const Ray ray = scene.camera().generateRay(column, row);
      bool grazing = false;
      const auto t = hitSphere(ray, center, radius, &grazing);
      if (grazing) continue;
      Color expected = background;
      if (t) {
        const Point3 p = ray.at(*t);
        const Normal3 n(normalize(p - center));
        expected = phong(material, intensity, n, l, ray.direction);
        (isBlack(expected) ? unlit : lit)++;
      } else {
        ++missed;
      }
      EXPECT_TRUE(colorNear(film.at(column, row), expected)) << "pixel " << column << "," << row;
    }
  }
  // The view shows lit sphere, its unlit side and background (so every branch was compared).
  EXPECT_GT(lit, 40);
  EXPECT_GT(unlit, 10);
  EXPECT_GT(missed, 40);
}

TEST(AnalyticImage, DiffuseSphereUnderDirectionalLight) {
  Material diffuse;
  diffuse.kd = Color(0.8, 0.5, 0.3);
  checkLitSphere(diffuse);
}

TEST(AnalyticImage, PhongHighlightOnSphere) {
  Material shiny;
  shiny.kd = Color(0.5, 0.4, 0.3);
  shiny.ks = Color(0.6, 0.7, 0.8);
  shiny.shininess = 12;
  checkLitSphere(shiny);
}

TEST(AnalyticImage, PointLightAttenuationOnAPlane) {
  Material diffuse;
  diffuse.kd = Color(0.7, 0.6, 0.5);
  const PointLight light{{1, 2, -6}, Color(3, 2.5, 2), {1, 0.2, 0.05}};
  SceneParts parts = baseParts(21, 21, 2, 2);
  parts.primitives.emplace_back(Plane::make({0, 0, -10}, {0, 0, 1}), addMaterial(parts, diffuse),
                                Color{});
  parts.lights.push_back(light);
  const Scene scene(std::move(parts));
  const Film film = render(scene);
  for (int row = 0; row < 21; ++row) {
    for (int column = 0; column < 21; ++column) {
      const Ray ray = scene.camera().generateRay(column, row);
      const Point3 q = hitPlaneZ(ray, -10);
      const double d = distance(q, light.position);
      const Vec3 l = (q - light.position) / d;
      const Color intensity = light.intensity / (1 + 0.2 * d + 0.05 * d * d);
      const Color expected = diffuse.kd * intensity * std::abs(l.z);
      EXPECT_TRUE(colorNear(film.at(column, row), expected)) << column << "," << row;
    }
  }
  // The attenuation is visible: the pixel under the light is brighter than a corner.
  EXPECT_GT(film.at(11, 8).r, 2 * film.at(0, 20).r);
}

TEST(AnalyticImage, SpotLightFalloffOnAPlane) {
  Material diffuse;
  diffuse.kd = Color(0.7, 0.6, 0.5);
  // The spot faces +x and down: D·(Q−L) = (qx − 1) + 4 on the plane, zero at qx = −3, so the left
  // part of the view is dark and the light falls off across the rest.
  const SpotLight spot{{1, 2, -6}, normalize(Vec3{1, 0, -1}), Color(4, 3, 2), {1, 0.1, 0.02}, 2};
  SceneParts parts = baseParts(21, 21, 2, 2);
  parts.primitives.emplace_back(Plane::make({0, 0, -10}, {0, 0, 1}), addMaterial(parts, diffuse),
                                Color{});
  parts.lights.push_back(spot);
  const Scene scene(std::move(parts));
  const Film film = render(scene);
  int dark = 0;
  for (int row = 0; row < 21; ++row) {
    for (int column = 0; column < 21; ++column) {
      const Ray ray = scene.camera().generateRay(column, row);
      const Point3 q = hitPlaneZ(ray, -10);
      const double d = distance(q, spot.position);
      const Vec3 l = (q - spot.position) / d;
      const double cone = std::pow(std::max(0.0, dot(spot.direction, l)), spot.exponent);
      const Color intensity = spot.intensity * (cone / (1 + 0.1 * d + 0.02 * d * d));
      const Color expected = diffuse.kd * intensity * std::abs(l.z);
      if (std::abs(q.x + 3) < 1e-6) continue;  // on the cone's edge
      if (cone == 0) ++dark;
      EXPECT_TRUE(colorNear(film.at(column, row), expected)) << column << "," << row;
    }
  }
  EXPECT_GT(dark, 21);
  EXPECT_LT(dark, 21 * 21 / 2);
}

// --- Shadows through transparent objects ---------------------------------------------------------

// A diffuse plane z = -10 under a directional light travelling along (2, 0, −1), with kt = 0.6
// spheres between the plane and the light. Every crossing of a sphere's surface keeps 0.6, so the
// plane shows 0.6² behind one sphere and 0.6⁴ behind two. Returns how many pixels had each crossing
// count.
std::vector<int> checkTransparentShadow(const std::vector<Point3>& centers, double radius) {
  Material floor;
  floor.kd = Color(0.8, 0.7, 0.6);
  floor.ka = Color(0);
  Material glass;
  glass.kt = Color(0.6);
  glass.ka = Color(0);
  const Vec3 l = normalize(Vec3{2, 0, -1});
  const Color intensity(1, 1, 1);

  SceneParts parts = baseParts(61, 31, 3, 1.5);
  parts.primitives.emplace_back(Plane::make({0, 0, -10}, {0, 0, 1}), addMaterial(parts, floor),
                                Color{});
  const std::uint32_t glassIndex = addMaterial(parts, glass);
  for (const Point3& c : centers)
    parts.primitives.emplace_back(Sphere::make(c, radius), glassIndex, Color{});
  parts.lights.push_back(DirectionalLight{l, intensity});
  const Scene scene(std::move(parts));
  const Film film = render(scene);

  const Color unshadowed = floor.kd * intensity * std::abs(l.z);
  std::vector<int> histogram(5, 0);
  for (int row = 0; row < 31; ++row) {
    for (int column = 0; column < 61; ++column) {
      const Ray ray = scene.camera().generateRay(column, row);
      bool grazing = false;
      bool seesSphere = false;
      for (const Point3& c : centers)
        seesSphere = seesSphere || hitSphere(ray, c, radius, &grazing);
      if (seesSphere || grazing) continue;  // only pixels that see the floor directly
      const Point3 q = hitPlaneZ(ray, -10);
      const Ray toLight{q, -l};
      int crossings = 0;
      for (const Point3& c : centers) crossings += sphereCrossings(toLight, c, radius, grazing);
      if (grazing) continue;
      ++histogram[static_cast<std::size_t>(crossings)];
      const Color expected = unshadowed * std::pow(0.6, crossings);
      EXPECT_TRUE(colorNear(film.at(column, row), expected))
          << column << "," << row << " behind " << crossings << " crossings";
    }
  }
  return histogram;
}

TEST(AnalyticImage, ShadowBehindTransparentSphereKeepsKtSquared) {
  const std::vector<int> counts = checkTransparentShadow({{0, 0, -5}}, 1.5);
  EXPECT_GT(counts[0], 100);
  EXPECT_GT(counts[2], 20);  // pixels at 0.36 of the unshadowed value
}

TEST(AnalyticImage, ShadowBehindTwoTransparentSpheresKeepsKtToTheFourth) {
  // The second sphere sits on the first one's shadow axis, nearer the floor.
  const std::vector<int> counts = checkTransparentShadow({{0, 0, -5}, {4, 0, -7}}, 1.5);
  EXPECT_GT(counts[0], 100);
  EXPECT_GT(counts[4], 10);  // pixels at 0.6⁴ = 0.1296
}

// --- Mirrors, ambient, misses --------------------------------------------------------------------

TEST(AnalyticImage, MirrorShowsTheWallBehindTheCamera) {
  // Mirror z = -5 facing the camera, emissive wall z = +5 behind it. Ambient is added at both hits:
  // pixel = ka_mirror·Ia + kr·(emission + ka_wall·Ia).
  const Color ambient(0.1, 0.05, 0.02);
  const Color emission(0.2, 0.6, 0.4);
  Material mirror;
  mirror.kr = Color(0.9, 0.8, 0.7);
  mirror.ka = Color(0.5);
  SceneParts parts = baseParts(21, 21, 2, 2);
  parts.ambient = ambient;
  parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), addMaterial(parts, mirror),
                                Color{});
  parts.primitives.emplace_back(Plane::make({0, 0, 5}, {0, 0, -1}), 0u, emission);
  const Scene scene(std::move(parts));
  const Film film = render(scene);
  const Color expected = mirror.ka * ambient + mirror.kr * (emission + ambient);
  for (int row = 0; row < 21; ++row)
    for (int column = 0; column < 21; ++column)
      EXPECT_TRUE(colorNear(film.at(column, row), expected)) << column << "," << row;
}

TEST(AnalyticImage, UnlitObjectShowsAmbientAndEmission) {
  // The only light shines from behind the sphere toward the camera: the visible side has
  // (n·l)(n·v) < 0 everywhere, so it shows emission + ka·Ia; misses show the background.
  const Color ambient(0.2, 0.3, 0.4);
  const Color emission(0.1, 0, 0.2);
  const Color background(0.05, 0.1, 0.15);
  Material m;
  m.kd = Color(1);
  m.ka = Color(0.5, 0.4, 0.3);
  const Point3 center{0, 0, -4};
  SceneParts parts = baseParts(21, 21, 1, 1);
  parts.ambient = ambient;
  parts.background = background;
  parts.primitives.emplace_back(Sphere::make(center, 1), addMaterial(parts, m), emission);
  parts.lights.push_back(DirectionalLight{{0, 0, 1}, Color(5, 5, 5)});
  const Scene scene(std::move(parts));
  const Film film = render(scene);
  int hits = 0;
  for (int row = 0; row < 21; ++row) {
    for (int column = 0; column < 21; ++column) {
      const Ray ray = scene.camera().generateRay(column, row);
      bool grazing = false;
      const bool hit = hitSphere(ray, center, 1, &grazing).has_value();
      if (grazing) continue;
      hits += hit;
      EXPECT_TRUE(colorNear(film.at(column, row), hit ? emission + m.ka * ambient : background))
          << column << "," << row;
    }
  }
  EXPECT_GT(hits, 50);
}

TEST(AnalyticImage, SecondaryMissReturnsTheBackground) {
  // A convex mirror alone: every reflected ray leaves the scene.
  const Color ambient(0.2, 0.3, 0.4);
  const Color background(0.3, 0.6, 0.9);
  Material m;
  m.kr = Color(0.5, 0.25, 1);
  m.ka = Color(0.1);
  const Point3 center{0, 0, -4};
  SceneParts parts = baseParts(21, 21, 1, 1);
  parts.ambient = ambient;
  parts.background = background;
  parts.primitives.emplace_back(Sphere::make(center, 1), addMaterial(parts, m), Color{});
  const Scene scene(std::move(parts));
  RenderStats stats;
  const Film film = render(scene, {}, &stats);
  int hits = 0;
  for (int row = 0; row < 21; ++row) {
    for (int column = 0; column < 21; ++column) {
      const Ray ray = scene.camera().generateRay(column, row);
      bool grazing = false;
      const bool hit = hitSphere(ray, center, 1, &grazing).has_value();
      if (grazing) continue;
      hits += hit;
      const Color expected = hit ? m.ka * ambient + m.kr * background : background;
      EXPECT_TRUE(colorNear(film.at(column, row), expected)) << column << "," << row;
    }
  }
  EXPECT_GT(hits, 50);
  EXPECT_EQ(stats.rays.reflection, static_cast<std::uint64_t>(hits));
}

// --- Refraction ----------------------------------------------------------------------------------

// A glass half-space below z = -1 (plane normal +z, kt, ior 1.5), a small green emissive disk where
// the ray is predicted to arrive, and a red plane further down catching anything else.
SceneParts glassHalfSpace(const Point3& diskCenter, const Color& kt) {
  SceneParts parts = baseParts(3, 3, 1, 1);
  Material glass;
  glass.kt = kt;
  glass.ka = Color(0);
  glass.ior = 1.5;
  parts.primitives.emplace_back(Plane::make({0, 0, -1}, {0, 0, 1}), addMaterial(parts, glass),
                                Color{});
  parts.primitives.emplace_back(Disk::make(diskCenter, {0, 0, 1}, 0.05), 0u, Color(0, 1, 0));
  parts.primitives.emplace_back(Plane::make({0, 0, -3.5}, {0, 0, 1}), 0u, Color(1, 0, 0));
  return parts;
}

TEST(AnalyticImage, RefractionBendsBySnellsLaw) {
  // Incidence 30° from the normal, ior 1.5: sin θt = sin 30° / 1.5 = 1/3, so the ray leaves
  // P = (tan 30°, 0, −1) along (1/3, 0, −√8/3) and crosses z = −3 at x = tan 30° + 2/√8.
  // Going straight it would cross at x = 3·tan 30° = 1.73, far outside the disk (radius 0.05).
  const double tan30 = std::tan(std::numbers::pi / 6);
  const Point3 arrival{tan30 + 2 / std::sqrt(8.0), 0, -3};
  const Scene scene(glassHalfSpace(arrival, Color(1)));
  Rng rng(0);
  RayCounts counts;
  const Color c = traceRay(
      scene, Ray{{0, 0, 0}, {std::sin(std::numbers::pi / 6), 0, -std::cos(std::numbers::pi / 6)}},
      rng, &counts);
  EXPECT_TRUE(colorNear(c, Color(0, 1, 0)));
  EXPECT_EQ(counts.refraction, 1u);

  // The same setup with the disk where the unbent ray would land shows the red plane instead.
  const Scene straight(glassHalfSpace({3 * tan30, 0, -3}, Color(1)));
  Rng rng2(0);
  EXPECT_TRUE(colorNear(
      traceRay(straight,
               Ray{{0, 0, 0}, {std::sin(std::numbers::pi / 6), 0, -std::cos(std::numbers::pi / 6)}},
               rng2),
      Color(1, 0, 0)));
}

TEST(AnalyticImage, TotalInternalReflectionSendsKtAlongTheMirrorDirection) {
  // From inside the glass at 60° from the normal: 1.5 · sin 60° = 1.3 > 1, so no ray leaves; the
  // transmitted energy (kt = 0.7) follows the reflection (sin 60°, 0, −cos 60°) from P = (√3, 0,
  // −1) and crosses z = −3 at x = 3√3, where the green disk is.
  const double sqrt3 = std::sqrt(3.0);
  const Scene scene(glassHalfSpace({3 * sqrt3, 0, -3}, Color(0.7)));
  Rng rng(0);
  RayCounts counts;
  const Color c = traceRay(scene, Ray{{0, 0, -2}, {sqrt3 / 2, 0, 0.5}}, rng, &counts);
  EXPECT_TRUE(colorNear(c, Color(0, 0.7, 0)));
  EXPECT_EQ(counts.reflection, 0u);  // no kr: the only secondary ray is the transmitted one
  EXPECT_EQ(counts.refraction, 1u);
}

// --- Recursion limits ----------------------------------------------------------------------------

// Two facing mirrors (kr = 0.5, ka = 1) around the camera: every ray bounces between them, and each
// hit adds Ia, so a path of H hits gives Ia · (1 + 0.5 + … + 0.5^(H−1)) = Ia · (1 − 0.5^H) / 0.5.
Film renderFacingMirrors(int maxDepth, double minWeight) {
  Material mirror;
  mirror.kr = Color(0.5);
  SceneParts parts = baseParts(9, 9, 1, 1);
  parts.ambient = Color(0.2, 0.3, 0.4);
  const std::uint32_t m = addMaterial(parts, mirror);
  parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), m, Color{});
  parts.primitives.emplace_back(Plane::make({0, 0, 5}, {0, 0, -1}), m, Color{});
  parts.render.maxDepth = maxDepth;
  parts.render.minWeight = minWeight;
  return render(Scene(std::move(parts)));
}

TEST(AnalyticImage, FacingMirrorsTruncateTheSeriesAtMaxDepth) {
  for (const int maxDepth : {1, 2, 3, 10}) {
    const Film film = renderFacingMirrors(maxDepth, 0);
    const Color expected = Color(0.2, 0.3, 0.4) * ((1 - std::pow(0.5, maxDepth)) / 0.5);
    for (const Color& c : film.pixels()) EXPECT_TRUE(colorNear(c, expected)) << maxDepth;
  }
}

TEST(AnalyticImage, MinWeightStopsTheSeries) {
  // Weight after k reflections is 0.5^k; with min_weight 0.01 the 7th hit (weight 0.5^6 = 0.0156)
  // is traced and the 8th (0.0078) is not: 7 terms.
  const Film film = renderFacingMirrors(100, 0.01);
  const Color expected = Color(0.2, 0.3, 0.4) * ((1 - std::pow(0.5, 7)) / 0.5);
  for (const Color& c : film.pixels()) EXPECT_TRUE(colorNear(c, expected));
}

// --- Supersampling -------------------------------------------------------------------------------

TEST(AnalyticImage, SupersamplingKeepsTheMeanOfAUniformPlane) {
  Material diffuse;
  diffuse.kd = Color(0.8, 0.6, 0.4);
  const Vec3 l = normalize(Vec3{0.3, 0.2, -1});
  const Color expected = diffuse.kd * std::abs(l.z);
  for (const int samples : {1, 2, 4, 9}) {
    for (const bool adaptive : {false, true}) {
      SceneParts parts = baseParts(21, 21, 2, 2);
      parts.primitives.emplace_back(Plane::make({0, 0, -10}, {0, 0, 1}),
                                    addMaterial(parts, diffuse), Color{});
      parts.lights.push_back(DirectionalLight{l, Color(1, 1, 1)});
      parts.image.samples = samples;
      if (adaptive) parts.image.adaptive = AdaptiveSampling{32, 1e-6};
      RenderStats stats;
      const Film film = render(Scene(std::move(parts)), {}, &stats);
      Color mean;
      for (const Color& c : film.pixels()) mean += c;
      mean = mean / static_cast<double>(film.pixels().size());
      EXPECT_TRUE(colorNear(mean, expected)) << samples << " samples, adaptive " << adaptive;
      // Adaptive: every pixel's samples agree, so none takes more than the initial count (at
      // least 4).
      const auto perPixel = static_cast<std::uint64_t>(adaptive ? std::max(samples, 4) : samples);
      EXPECT_EQ(stats.samples, 21u * 21u * perPixel) << samples << ", adaptive " << adaptive;
    }
  }
}

// --- The seed's test case ------------------------------------------------------------------------

TEST(AnalyticImage, SeedTestCaseAt100Pixels) {
  // At 100 × 100 the 500-unit view plane gives 5 units per pixel in the plane z = −100, pixel
  // centres at x = (column − 49.5)·5, y = −(row − 49.5)·5. The grid every 30 px keeps the checked
  // pixels below off the grid lines.
  const Scene scene(seed::testCaseParts(100, 30));
  const Film film = render(scene);
  const Color pink(1, 191 / 255.0, 191 / 255.0);
  const Color background(75 / 255.0, 127 / 255.0, 90 / 255.0);
  const Color yellow(1, 1, 0);

  EXPECT_EQ(film.at(50, 50), pink);        // the disc, (2.5, −2.5)
  EXPECT_EQ(film.at(58, 41), background);  // diamond gap on the diagonal, (42.5, 42.5)
  EXPECT_EQ(film.at(69, 69), pink);        // corner of the square, (97.5, −97.5)
  EXPECT_EQ(film.at(70, 50), background);  // right of the square, (102.5, −2.5)
  EXPECT_EQ(film.at(50, 95), background);  // below the square
  for (const int k : {0, 30, 60, 90}) {
    EXPECT_EQ(film.at(k, 17), yellow) << k;
    EXPECT_EQ(film.at(17, k), yellow) << k;
  }

  // Every other pixel classified analytically: disc (sphere hit), the four triangles (inside the
  // square, outside the diamond |x| + |y| < 100), else background. Pixels on the hypotenuses
  // (|x| + |y| = 100 exactly at these centres) are left out: which side an edge falls on is the
  // triangle test's business, not this test's.
  int pinkCount = 0;
  for (int row = 0; row < 100; ++row) {
    for (int column = 0; column < 100; ++column) {
      const Color& actual = film.at(column, row);
      if (column % 30 == 0 || row % 30 == 0) {
        EXPECT_EQ(actual, yellow);
        continue;
      }
      const Ray ray = scene.camera().generateRay(column, row);
      bool grazing = false;
      if (hitSphere(ray, {0, 0, -100}, 50, &grazing)) {
        EXPECT_EQ(actual, pink) << column << "," << row;
        ++pinkCount;
        continue;
      }
      if (grazing) continue;
      const Point3 q = hitPlaneZ(ray, -100);
      const double taxi = std::abs(q.x) + std::abs(q.y);
      if (std::abs(taxi - 100) < 1e-6) continue;
      const bool inTriangle = std::abs(q.x) <= 100 && std::abs(q.y) <= 100 && taxi > 100;
      EXPECT_EQ(actual, inTriangle ? pink : background) << column << "," << row;
      pinkCount += inTriangle;
    }
  }
  EXPECT_GT(pinkCount, 500);
}

}  // namespace
}  // namespace glint
