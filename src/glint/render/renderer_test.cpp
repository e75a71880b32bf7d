#include "glint/render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "glint/core/isa.h"
#include "glint/geometry/shape.h"
#include "glint/render/render_test_support.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

// Camera at the origin looking down −z (right = +x, up = +y) through a view plane `viewSize` wide
// and high at distance 1.
SceneParts baseParts(int width, int height, double viewSize = 2) {
  SceneParts parts;
  parts.camera.position = {0, 0, 0};
  parts.camera.direction = {0, 0, -1};
  parts.camera.up = {0, 1, 0};
  parts.camera.viewPlaneWidth = viewSize * width / height;
  parts.camera.viewPlaneHeight = viewSize;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = width;
  parts.image.height = height;
  parts.image.encoding = Encoding::Linear;
  parts.background = Color(0.1, 0.2, 0.3);
  return parts;
}

std::uint32_t addMaterial(SceneParts& parts, const Material& material) {
  parts.materials.push_back(material);
  return static_cast<std::uint32_t>(parts.materials.size() - 1);
}

// A diffuse plane z = -10 facing the camera under a directional light: every point has the same
// colour kd·I·|n·l|.
SceneParts litPlaneParts(int width, int height) {
  SceneParts parts = baseParts(width, height);
  Material diffuse;
  diffuse.kd = Color(0.8, 0.6, 0.4);
  diffuse.ka = Color(0);
  parts.primitives.emplace_back(Plane::make({0, 0, -10}, {0, 0, 1}), addMaterial(parts, diffuse),
                                Color{});
  parts.lights.push_back(DirectionalLight{normalize(Vec3{0.3, 0.2, -1}), Color(1, 1, 1)});
  return parts;
}

bool sameFilm(const Film& a, const Film& b) {
  if (a.region() != b.region()) return false;
  for (std::size_t i = 0; i < a.pixels().size(); ++i)
    if (!(a.pixels()[i] == b.pixels()[i])) return false;
  return true;
}

TEST(Renderer, RejectsCropOutsideTheImageOrEmpty) {
  const Scene scene(baseParts(8, 6));
  for (const PixelRegion& crop :
       {PixelRegion{-1, 0, 4, 4}, PixelRegion{0, 0, 9, 6}, PixelRegion{0, 0, 8, 7},
        PixelRegion{3, 2, 3, 5}, PixelRegion{4, 4, 2, 5}}) {
    RenderOptions options;
    options.crop = crop;
    EXPECT_THROW(render(scene, options), std::invalid_argument)
        << crop.x0 << "," << crop.y0 << "," << crop.x1 << "," << crop.y1;
  }
  RenderOptions whole;
  whole.crop = PixelRegion{0, 0, 8, 6};
  EXPECT_EQ(render(scene, whole).region(), (PixelRegion{0, 0, 8, 6}));
}

TEST(Renderer, EmptySceneShowsBackgroundAndCountsCameraRays) {
  SceneParts parts = baseParts(7, 5);
  parts.image.samples = 3;
  const Scene scene(std::move(parts));
  RenderStats stats;
  const Film film = render(scene, {}, &stats);
  ASSERT_EQ(film.width(), 7);
  ASSERT_EQ(film.height(), 5);
  for (const Color& c : film.pixels()) {
    EXPECT_NEAR(c.r, 0.1, 1e-15);
    EXPECT_NEAR(c.g, 0.2, 1e-15);
    EXPECT_NEAR(c.b, 0.3, 1e-15);
  }
  EXPECT_EQ(stats.rays.camera, 7u * 5u * 3u);
  EXPECT_EQ(stats.rays.shadow, 0u);
  EXPECT_EQ(stats.rays.total(), 7u * 5u * 3u);
  EXPECT_FALSE(stats.cancelled);
  EXPECT_GE(stats.seconds, 0.0);
}

TEST(Renderer, CountsOneShadowRayPerLitHit) {
  SceneParts parts = litPlaneParts(9, 9);
  parts.image.samples = 4;
  const Scene scene(std::move(parts));
  RenderStats stats;
  render(scene, {}, &stats);
  EXPECT_EQ(stats.rays.camera, 9u * 9u * 4u);
  EXPECT_EQ(stats.rays.shadow, 9u * 9u * 4u);
  EXPECT_EQ(stats.rays.reflection, 0u);
  EXPECT_EQ(stats.rays.refraction, 0u);
}

TEST(Renderer, OneSamplePerPixelGoesThroughThePixelCentre) {
  // A sphere makes the colour depend on the exact ray, so any offset from the centre would show.
  SceneParts parts = baseParts(11, 9);
  Material m;
  m.kd = Color(0.9, 0.7, 0.5);
  m.ks = Color(0.3);
  m.shininess = 20;
  parts.primitives.emplace_back(Sphere::make({0.2, -0.1, -4}, 2.5), addMaterial(parts, m), Color{});
  parts.lights.push_back(PointLight{{3, 4, 2}, Color(2, 2, 2), {}});
  const Scene scene(std::move(parts));
  const Film film = render(scene);
  for (int row = 0; row < 9; ++row) {
    for (int column = 0; column < 11; ++column) {
      Rng rng(0);
      const Color expected = traceRay(scene, scene.camera().generateRay(column, row), rng);
      EXPECT_EQ(film.at(column, row), expected) << column << "," << row;
    }
  }
}

// Without adaptive sampling, textures, nested media or the path integrator, render() traces the
// camera rays of 4 × 4 pixel blocks as packets (Aggregate::intersectPacket): every pixel must
// still be exactly its single camera ray's colour. A fan of triangles (a mesh), spheres in front
// of it (some of glass), a reflective floor and lights of each kind (their shadow rays from the
// camera hits go in packets too, Aggregate::transmittancePacket); an image of odd size in small
// tiles, so that blocks are cut short at tile and image edges; on every instruction set this
// processor runs.
TEST(Renderer, CameraRayPacketsRenderEveryPixelAsItsSingleRay) {
  SceneParts parts = baseParts(37, 23);
  Material shiny;
  shiny.kd = Color(0.6, 0.5, 0.4);
  shiny.ks = Color(0.3);
  shiny.shininess = 30;
  shiny.kr = Color(0.4);
  const std::uint32_t material = addMaterial(parts, shiny);
  TriangleMesh fan;
  constexpr int kSpokes = 24;
  fan.positions.push_back({0, 0, -6});
  for (int i = 0; i <= kSpokes; ++i) {
    const double a = 2 * std::numbers::pi * i / kSpokes;
    fan.positions.push_back({2.5 * std::cos(a), 2.5 * std::sin(a), -7 - 0.3 * std::sin(3 * a)});
  }
  for (std::uint32_t i = 1; i <= kSpokes; ++i) fan.indices.insert(fan.indices.end(), {0, i, i + 1});
  fan.materialIndex = material;
  parts.meshes.push_back(fan);
  Material glass = shiny;  // dims the shadow rays through it (their packets multiply kt)
  glass.kd = Color(0.1);
  glass.kt = Color(0.5, 0.6, 0.7);
  glass.ior = 1.3;
  const std::uint32_t glassMaterial = addMaterial(parts, glass);
  for (int i = 0; i < 5; ++i) {
    parts.primitives.emplace_back(Sphere::make({-1.6 + 0.8 * i, 0.3 * (i % 2), -4.5}, 0.35),
                                  i % 2 == 0 ? material : glassMaterial, Color{});
  }
  parts.primitives.emplace_back(Plane::make({0, -1.2, 0}, {0, 1, 0}), material, Color{});
  // Each kind of light whose camera-hit shadow rays go in packets (not area lights: traceRay
  // below cannot draw a pixel's light samples).
  parts.lights.push_back(PointLight{{2, 3, 1}, Color(1.5, 1.5, 1.5), {}});
  parts.lights.push_back(DirectionalLight{normalize(Vec3{-1, -2, -1}), Color(0.4)});
  parts.lights.push_back(
      SpotLight{{-2, 3, 0}, normalize(Vec3{0.5, -1, -1.5}), Color(2), {}, 1, 20, 40});
  for (const Isa isa : {Isa::Baseline, Isa::Avx2, Isa::Avx512}) {
    if (!isaSupportHere().runs(isa)) continue;
    SCOPED_TRACE(isaName(isa));
    SceneParts copy = parts;
    copy.isa = isa;
    const Scene scene(std::move(copy));
    RenderOptions options;
    options.tileSize = 7;
    const Film film = render(scene, options);
    int mismatches = 0;
    for (int row = 0; row < 23; ++row) {
      for (int column = 0; column < 37; ++column) {
        Rng rng(0);
        const Color expected = traceRay(scene, scene.camera().generateRay(column, row), rng);
        mismatches += film.at(column, row) == expected ? 0 : 1;
      }
    }
    EXPECT_EQ(mismatches, 0) << "of 37 × 23 pixels";
  }
}

TEST(Renderer, SupersamplingAveragesCoverageAtASilhouette) {
  // A black-on-white edge: an emissive white sphere whose silhouette crosses pixels. With 16
  // samples some pixel must come out strictly between the two, and every pixel stays within [0, 1].
  SceneParts parts = baseParts(15, 15);
  parts.background = Color(0);
  parts.primitives.emplace_back(Sphere::make({0, 0, -5}, 2), 0u, Color(1, 1, 1));
  parts.image.samples = 16;
  const Scene scene(std::move(parts));
  const Film film = render(scene);
  int partial = 0;
  for (const Color& c : film.pixels()) {
    EXPECT_GE(c.r, 0.0);
    EXPECT_LE(c.r, 1.0);
    if (c.r > 0 && c.r < 1) ++partial;
  }
  EXPECT_GT(partial, 8);
  EXPECT_EQ(film.at(7, 7), Color(1, 1, 1));
  EXPECT_EQ(film.at(0, 0), Color(0, 0, 0));
}

TEST(Renderer, TileSizeAndThreadCountDoNotChangeThePixels) {
  SceneParts parts = litPlaneParts(23, 17);
  Material glossy;
  glossy.kd = Color(0.2);
  glossy.kr = Color(0.7);
  glossy.reflectionBlur = 15;
  parts.primitives.emplace_back(Sphere::make({0, 0, -6}, 2), addMaterial(parts, glossy), Color{});
  parts.image.samples = 2;
  parts.render.blurSamples = 3;
  EXPECT_TRUE(testing::rendersTheSameOnAnyThreadCountAndTileSize(Scene(std::move(parts))));
}

// A subset of tiles, or tiles from a feed, into the caller's film: the rendered tiles have the
// pixels of a whole render, the others keep what the film held; together they make the whole.
TEST(Renderer, TileSubsetsAndTheFeedIntoOneFilmEqualTheWholeRender) {
  SceneParts parts = litPlaneParts(21, 13);
  parts.image.samples = 3;
  const Scene scene(std::move(parts));
  RenderOptions whole;
  whole.tileSize = 4;
  const Film expected = render(scene, whole);
  const std::size_t tileCount = tileRegions(expected.region(), 4).size();

  RenderOptions odd = whole;
  odd.threads = 2;
  odd.tiles.emplace();
  for (std::size_t tile = tileCount; tile-- > 0;)
    if (tile % 2 == 1) odd.tiles->push_back(tile);
  std::vector<std::size_t> finished;
  odd.tileFinished = [&finished](std::size_t tile, const Film&, int rank) {
    EXPECT_EQ(rank, -1);  // not an MPI rank's
    finished.push_back(tile);
  };
  Film film(21, 13, expected.region());
  const Color marker(7, 7, 7);
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) film.at(x, y) = marker;
  RenderStats stats;
  renderInto(scene, odd, film, &stats);
  EXPECT_EQ(finished.size(), odd.tiles->size());
  EXPECT_FALSE(sameFilm(film, expected));  // the even tiles still hold the marker
  EXPECT_TRUE(film.at(0, 0) == marker);

  std::atomic<std::size_t> nextEven{0};
  RenderOptions fed = whole;
  fed.threads = 2;
  fed.nextTile = [&nextEven, tileCount]() -> std::optional<std::size_t> {
    const std::size_t tile = 2 * nextEven++;
    if (tile >= tileCount) return std::nullopt;
    return tile;
  };
  renderInto(scene, fed, film);
  EXPECT_TRUE(sameFilm(film, expected));

  RenderOptions twice = whole;
  twice.tiles = std::vector<std::size_t>{1, 1};
  EXPECT_THROW(renderInto(scene, twice, film), std::invalid_argument);
  Film wrongRegion(21, 13, PixelRegion{0, 0, 20, 13});
  EXPECT_THROW(renderInto(scene, whole, wrongRegion), std::invalid_argument);
}

TEST(Renderer, NonFiniteSamplesBecomeBlackAndAreCounted) {
  SceneParts parts = baseParts(10, 10);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // A small NaN-emitting square in the middle, seen by the centre 2×2 pixels (pixel pitch 0.2 at
  // distance 1, so ±0.15 at distance 1 covers the centres ±0.1).
  parts.primitives.emplace_back(Rectangle::make({-0.15, -0.15, -1}, {0.3, 0, 0}, {0, 0.3, 0}), 0u,
                                Color(nan, 0, 0));
  parts.image.samples = 1;
  const Scene scene(std::move(parts));
  RenderStats stats;
  const Film film = render(scene, {}, &stats);
  EXPECT_EQ(stats.nonFinite, 4u);
  for (int y = 4; y <= 5; ++y)
    for (int x = 4; x <= 5; ++x) EXPECT_EQ(film.at(x, y), Color(0, 0, 0)) << x << "," << y;
  EXPECT_EQ(film.at(0, 0), Color(0.1, 0.2, 0.3));
}

TEST(Renderer, GridUsesAbsolutePixelCoordinatesInACrop) {
  SceneParts parts = litPlaneParts(20, 12);
  parts.image.grid = GridOverlay{4, Color(1, 1, 0)};
  const Scene scene(std::move(parts));
  const Film full = render(scene);
  RenderOptions options;
  options.crop = PixelRegion{5, 3, 17, 11};
  const Film crop = render(scene, options);
  ASSERT_EQ(crop.width(), 12);
  ASSERT_EQ(crop.height(), 8);
  int painted = 0;
  for (int y = 3; y < 11; ++y) {
    for (int x = 5; x < 17; ++x) {
      const bool onGrid = x % 4 == 0 || y % 4 == 0;
      EXPECT_EQ(crop.at(x - 5, y - 3), full.at(x, y)) << x << "," << y;
      EXPECT_EQ(crop.at(x - 5, y - 3) == Color(1, 1, 0), onGrid) << x << "," << y;
      painted += onGrid;
    }
  }
  EXPECT_GT(painted, 0);
  EXPECT_EQ(full.at(0, 0), Color(1, 1, 0));  // 0 is a multiple of the interval
  EXPECT_NE(full.at(1, 1), Color(1, 1, 0));
}

TEST(Renderer, ReportsProgressOncePerTileInOrder) {
  const Scene scene(litPlaneParts(37, 21));
  RenderOptions options;
  options.tileSize = 8;
  options.threads = 2;
  std::vector<std::size_t> done;
  std::size_t reportedTotal = 0;
  options.progress = [&](std::size_t d, std::size_t total) {
    done.push_back(d);
    reportedTotal = total;
  };
  render(scene, options);
  const std::size_t tiles = 5 * 3;  // ⌈37/8⌉ × ⌈21/8⌉
  EXPECT_EQ(reportedTotal, tiles);
  ASSERT_EQ(done.size(), tiles);
  for (std::size_t i = 0; i < tiles; ++i) EXPECT_EQ(done[i], i + 1);
}

TEST(Renderer, CancelStopsBeforeTheRemainingTiles) {
  const Scene scene(litPlaneParts(32, 32));
  {
    const std::atomic<bool> cancel{true};
    RenderOptions options;
    options.cancel = &cancel;
    std::size_t calls = 0;
    options.progress = [&](std::size_t, std::size_t) { ++calls; };
    RenderStats stats;
    render(scene, options, &stats);
    EXPECT_TRUE(stats.cancelled);
    EXPECT_EQ(calls, 0u);
    EXPECT_EQ(stats.rays.camera, 0u);
  }
  {
    std::atomic<bool> cancel{false};
    RenderOptions options;
    options.cancel = &cancel;
    options.threads = 1;
    options.tileSize = 8;
    std::size_t calls = 0;
    options.progress = [&](std::size_t, std::size_t) {
      ++calls;
      cancel = true;
    };
    RenderStats stats;
    render(scene, options, &stats);
    EXPECT_TRUE(stats.cancelled);
    EXPECT_EQ(calls, 1u);
    EXPECT_EQ(stats.rays.camera, 8u * 8u);
  }
}

// Two facing mirrors z = -5 (normal +z) and z = +5 (normal −z) around the camera.
SceneParts facingMirrors(const Material& mirror) {
  SceneParts parts = baseParts(3, 3);
  const std::uint32_t m = addMaterial(parts, mirror);
  parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), m, Color{});
  parts.primitives.emplace_back(Plane::make({0, 0, 5}, {0, 0, -1}), m, Color{});
  return parts;
}

// The ray counts of one path started between facingMirrors of reflectivity 0.5.
RayCounts mirrorPathCounts(int maxDepth, double minWeight) {
  Material mirror;
  mirror.kr = Color(0.5);
  SceneParts parts = facingMirrors(mirror);
  parts.render.maxDepth = maxDepth;
  parts.render.minWeight = minWeight;
  const Scene scene(std::move(parts));
  RayCounts counts;
  Rng rng(1);
  traceRay(scene, Ray{{0, 0, 0}, {0, 0, -1}}, rng, &counts);
  return counts;
}

TEST(Renderer, PrimaryHitIsDepthOne) {
  // 70: past the 64 depths the renderer keeps a Hit for in advance.
  for (const int maxDepth : {1, 2, 4, 70}) {
    const RayCounts counts = mirrorPathCounts(maxDepth, 0);
    EXPECT_EQ(counts.camera, 1u);
    EXPECT_EQ(counts.reflection, static_cast<std::uint64_t>(maxDepth - 1));
  }
}

// A scene built in code may ask for any depth; nothing is allocated per possible depth, and
// min_weight ends the path: a tenth reflection would weigh 0.5^10 < 0.001.
TEST(Renderer, UnlimitedDepthEndsByWeight) {
  EXPECT_EQ(mirrorPathCounts(std::numeric_limits<int>::max(), 0.001).reflection, 9u);
}

TEST(Renderer, GlossySplitsOnceThenUsesOneRayPerBounce) {
  // Hits: mirror A (depth 1) fans out into N glossy rays; each reaches mirror B (depth 2), where
  // the already-split path traces 1 cone ray back to A (depth 3 = max_depth, no further rays).
  Material glossy;
  glossy.kr = Color(0.9);
  glossy.reflectionBlur = 2;  // narrow: no sample is dropped at normal incidence
  SceneParts parts = facingMirrors(glossy);
  parts.render.maxDepth = 3;
  parts.render.blurSamples = 6;
  const Scene scene(std::move(parts));
  RayCounts counts;
  Rng rng(7);
  traceRay(scene, Ray{{0, 0, 0}, {0, 0, -1}}, rng, &counts);
  EXPECT_EQ(counts.reflection, 6u + 6u);
  EXPECT_EQ(counts.refraction, 0u);
}

TEST(Renderer, GlossyReflectionDropsRaysBelowTheSurface) {
  // A wide glossy mirror floor (y = 0, normal +y) seen at 45°: much of an 80° cone around the ideal
  // reflection points below the floor. Above the floor everything is a white emissive dome; below
  // it a red plane. Dropped samples never reach the red plane, so the result is exactly kr · white.
  SceneParts parts = baseParts(3, 3);
  Material glossy;
  glossy.kr = Color(0.5, 0.25, 1);
  glossy.ka = Color(0);
  glossy.reflectionBlur = 80;
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), addMaterial(parts, glossy),
                                Color{});
  parts.primitives.emplace_back(Sphere::make({0, 0, 0}, 1000), 0u, Color(1, 1, 1));
  parts.primitives.emplace_back(Plane::make({0, -1, 0}, {0, 1, 0}), 0u, Color(1, 0, 0));
  parts.render.blurSamples = 64;
  const Scene scene(std::move(parts));
  for (std::uint64_t key = 0; key < 8; ++key) {
    Rng rng(key);
    RayCounts counts;
    const Color c = traceRay(scene, Ray{{0, 1, 0}, normalize(Vec3{1, -1, 0})}, rng, &counts);
    EXPECT_EQ(c, Color(0.5, 0.25, 1)) << key;
    // Roughly a third of the cone lies below the floor: some must have been dropped.
    EXPECT_LT(counts.reflection, 64u) << key;
    EXPECT_GT(counts.reflection, 0u) << key;
  }
}

TEST(Renderer, GlossySamplingIsKeyedByTheRng) {
  // A glossy mirror reflecting a diffuse wall lit by a point light: the wall's colour varies
  // continuously with position, so the average over the cone depends on the exact samples.
  SceneParts parts = baseParts(3, 3);
  Material glossy;
  glossy.kr = Color(1);
  glossy.ka = Color(0);
  glossy.reflectionBlur = 30;
  Material wall;
  wall.kd = Color(0.8);
  wall.ka = Color(0);
  parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), addMaterial(parts, glossy),
                                Color{});
  parts.primitives.emplace_back(Plane::make({0, 0, 5}, {0, 0, -1}), addMaterial(parts, wall),
                                Color{});
  parts.lights.push_back(PointLight{{0.5, 0.5, 0}, Color(10, 10, 10), {1, 0, 0.05}});
  parts.render.blurSamples = 5;
  const Scene scene(std::move(parts));
  const Ray ray{{0, 0, 0}, {0, 0, -1}};
  Rng a1(11), a2(11), b(12);
  const Color first = traceRay(scene, ray, a1);
  EXPECT_GT(first.r, 0.0);
  EXPECT_EQ(traceRay(scene, ray, a2), first);
  EXPECT_NE(traceRay(scene, ray, b), first);
}

TEST(Renderer, TransmissionWithIorOneGoesStraightThrough) {
  // A kt = 0.5 pane (z = -1) in front of a blue emissive rectangle that only the straight
  // continuation of the ray reaches (x in [2, 4] at z = -3; the ray crosses z = -3 at x = 3).
  SceneParts parts = baseParts(3, 3);
  Material pane;
  pane.kt = Color(0.5);
  pane.ka = Color(0);
  parts.primitives.emplace_back(Plane::make({0, 0, -1}, {0, 0, 1}), addMaterial(parts, pane),
                                Color{});
  parts.primitives.emplace_back(Rectangle::make({2, -1, -3}, {2, 0, 0}, {0, 2, 0}), 0u,
                                Color(0, 0, 1));
  const Scene scene(std::move(parts));
  RayCounts counts;
  Rng rng(0);
  const Color c = traceRay(scene, Ray{{0, 0, 0}, normalize(Vec3{1, 0, -1})}, rng, &counts);
  EXPECT_EQ(c, Color(0, 0, 0.5));
  EXPECT_EQ(counts.refraction, 1u);
  EXPECT_EQ(counts.reflection, 0u);
}

// A diffuse, specular sphere over a diffuse floor, lit by one light: shadows, highlights and
// distance falloff all depend on where the light is.
SceneParts shadedSphereParts() {
  SceneParts parts = baseParts(16, 12);
  Material m;
  m.kd = Color(0.7, 0.5, 0.3);
  m.ks = Color(0.4);
  m.shininess = 30;
  m.ka = Color(0);
  const std::uint32_t mi = addMaterial(parts, m);
  parts.primitives.emplace_back(Sphere::make({0.3, 0, -5}, 1.2), mi, Color{});
  parts.primitives.emplace_back(Plane::make({0, -1.2, 0}, {0, 1, 0}), mi, Color{});
  return parts;
}

TEST(Renderer, AreaLightShrunkToAPointEqualsThePointLight) {
  const Point3 position{1.5, 3, -2};
  const Color intensity(3, 2.5, 2);
  const Attenuation attenuation{1, 0.1, 0.02};
  SceneParts pointParts = shadedSphereParts();
  pointParts.lights.push_back(PointLight{position, intensity, attenuation});
  const Film expected = render(Scene(std::move(pointParts)));

  AreaLight rectangle;
  rectangle.shape = AreaShape::Rectangle;
  rectangle.corner = position;
  AreaLight disk;
  disk.shape = AreaShape::Disk;
  disk.center = position;
  disk.normal = {0, 1, 0};
  AreaLight sphere;
  sphere.shape = AreaShape::Sphere;
  sphere.center = position;
  int shaded = 0;
  for (AreaLight light : {rectangle, disk, sphere}) {
    light.intensity = intensity;
    light.attenuation = attenuation;
    light.samples = 5;
    SceneParts parts = shadedSphereParts();
    parts.lights.push_back(light);
    RenderStats stats;
    const Film film = render(Scene(std::move(parts)), {}, &stats);
    for (std::size_t i = 0; i < film.pixels().size(); ++i) {
      const Color& a = film.pixels()[i];
      const Color& e = expected.pixels()[i];
      EXPECT_NEAR(a.r, e.r, 1e-12 * (1 + e.r)) << static_cast<int>(light.shape) << " pixel " << i;
      EXPECT_NEAR(a.g, e.g, 1e-12 * (1 + e.g));
      EXPECT_NEAR(a.b, e.b, 1e-12 * (1 + e.b));
      shaded += e.r > 0;
    }
    EXPECT_EQ(stats.rays.shadow % 5, 0u);  // five shadow rays per lit hit
  }
  EXPECT_GT(shaded, 100);
}

TEST(Renderer, AreaLightSamplesFallBelowAGlossySplit) {
  // Glossy mirror A (z = -5, normal +z; kd > 0) splits into blurSamples = 4 rays that reach the
  // diffuse wall B (z = +5, normal −z). A small area light between them with samples = 7 lights
  // both sides: A (unsplit) takes 7 shadow rays, each of the 4 split paths ⌈7/4⌉ = 2.
  SceneParts parts = baseParts(3, 3);
  Material glossy;
  glossy.kd = Color(0.5);
  glossy.kr = Color(0.5);
  glossy.reflectionBlur = 2;
  Material wall;
  wall.kd = Color(0.5);
  parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), addMaterial(parts, glossy),
                                Color{});
  parts.primitives.emplace_back(Plane::make({0, 0, 5}, {0, 0, -1}), addMaterial(parts, wall),
                                Color{});
  AreaLight light;
  light.corner = {2, 2, 0};
  light.edge1 = {0.5, 0, 0};
  light.edge2 = {0, 0.5, 0};
  light.intensity = Color(1);
  light.samples = 7;
  parts.lights.push_back(light);
  parts.render.blurSamples = 4;
  parts.render.maxDepth = 2;
  const Scene scene(std::move(parts));
  RayCounts counts;
  Rng rng(3);
  const Color c = traceRay(scene, Ray{{0, 0, 0}, {0, 0, -1}}, rng, &counts);
  EXPECT_GT(c.r, 0.0);
  EXPECT_EQ(counts.reflection, 4u);
  EXPECT_EQ(counts.shadow, 7u + 4u * 2u);
}

// An emissive white sphere on black whose silhouette crosses pixels (see the supersampling test).
SceneParts silhouetteParts(int samples) {
  SceneParts parts = baseParts(15, 15);
  parts.background = Color(0);
  parts.primitives.emplace_back(Sphere::make({0, 0, -5}, 2), 0u, Color(1, 1, 1));
  parts.image.samples = samples;
  return parts;
}

std::uint64_t cameraRaysOfCrop(const Scene& scene, const PixelRegion& crop) {
  RenderOptions options;
  options.crop = crop;
  RenderStats stats;
  render(scene, options, &stats);
  return stats.samples;
}

TEST(Renderer, AdaptiveSamplingRefinesOnlyWhereSamplesDisagree) {
  SceneParts parts = silhouetteParts(4);
  parts.image.adaptive = AdaptiveSampling{12, 1e-6};
  const Scene scene(std::move(parts));
  RenderStats stats;
  const Film film = render(scene, {}, &stats);
  // Flat pixels (inside, outside) away from the edge stop after the first 4 samples; a pixel
  // whose samples disagree goes to the cap in batches of 4 (4 → 8 → 12); a flat pixel beside a
  // disagreeing one takes one more batch (its neighbours' first batches are noisy) and stops at 8.
  EXPECT_EQ(cameraRaysOfCrop(scene, {7, 7, 8, 8}), 4u);
  EXPECT_EQ(cameraRaysOfCrop(scene, {0, 0, 1, 1}), 4u);
  EXPECT_EQ(film.at(7, 7), Color(1, 1, 1));
  EXPECT_EQ(film.at(0, 0), Color(0, 0, 0));
  // The silhouette on the image: a circle about the image centre (7.5, 7.5) of radius
  // tan(asin(2/5)) / (2/15) pixels (the sphere of radius 2 at distance 5, a view plane 2 high at
  // distance 1, 15 pixels).
  const double radius = std::tan(std::asin(0.4)) / (2.0 / 15.0);
  std::uint64_t refined = 0;
  for (int y = 0; y < 15; ++y) {
    for (int x = 0; x < 15; ++x) {
      const std::uint64_t spent = cameraRaysOfCrop(scene, {x, y, x + 1, y + 1});
      EXPECT_TRUE(spent == 4u || spent == 8u || spent == 12u) << x << "," << y << ": " << spent;
      // A pixel whose samples disagree (a value strictly between black and white) was refined.
      const double value = film.at(x, y).r;
      if (value > 0 && value < 1) {
        EXPECT_EQ(spent, 12u) << x << "," << y;
      }
      // Every pixel the silhouette crosses took more than its first batch, also one whose four
      // first samples all landed on one side of the edge: its neighbours' disagree.
      const double nearX = std::clamp(7.5, double(x), x + 1.0) - 7.5;
      const double nearY = std::clamp(7.5, double(y), y + 1.0) - 7.5;
      const double farX = std::max(std::abs(x - 7.5), std::abs(x + 1 - 7.5));
      const double farY = std::max(std::abs(y - 7.5), std::abs(y + 1 - 7.5));
      if (std::hypot(nearX, nearY) < radius && std::hypot(farX, farY) > radius) {
        EXPECT_GT(spent, 4u) << x << "," << y << " lies on the silhouette";
      }
      refined += spent > 4u;
    }
  }
  EXPECT_GE(refined, 12u);
  EXPECT_GT(stats.samples, 15u * 15u * 4u);
  EXPECT_LT(stats.samples, 15u * 15u * 12u);
  // In 5-pixel tiles the rays traced include the recomputed first batches of each tile's ring
  // (one tile covers this whole image at the default size): the same film and samples, more
  // camera rays.
  RenderOptions small;
  small.tileSize = 5;
  RenderStats smallStats;
  const Film tiled = render(scene, small, &smallStats);
  EXPECT_EQ(smallStats.samples, stats.samples);
  EXPECT_GT(smallStats.rays.camera, smallStats.samples);
  for (std::size_t i = 0; i < film.pixels().size(); ++i) {
    EXPECT_EQ(tiled.pixels()[i], film.pixels()[i]) << i;
  }

  // A generous threshold refines less than a strict one; maxSamples = samples means fixed.
  SceneParts loose = silhouetteParts(4);
  loose.image.adaptive = AdaptiveSampling{12, 0.3};
  RenderStats looseStats;
  render(Scene(std::move(loose)), {}, &looseStats);
  EXPECT_LT(looseStats.samples, stats.samples);
  SceneParts capped = silhouetteParts(4);
  capped.image.adaptive = AdaptiveSampling{4, 1e-6};
  RenderStats cappedStats;
  render(Scene(std::move(capped)), {}, &cappedStats);
  EXPECT_EQ(cappedStats.samples, 15u * 15u * 4u);
}

TEST(Renderer, CancelStopsInsideATileWithoutReportingIt) {
  // One 64×64 tile at 256 samples per pixel: about a million camera samples, far more than the
  // render can do before the cancel arrives; it must stop mid-tile, not at the tile's end.
  SceneParts parts = litPlaneParts(64, 64);
  parts.image.samples = 256;
  const Scene scene(std::move(parts));
  std::atomic<bool> cancel{false};
  RenderOptions options;
  options.cancel = &cancel;
  options.threads = 1;
  options.tileSize = 64;
  std::size_t reports = 0;
  options.progress = [&](std::size_t, std::size_t) { ++reports; };
  options.tileFinished = [&](std::size_t, const Film&, int) { ++reports; };
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    cancel = true;
  });
  RenderStats stats;
  const auto start = std::chrono::steady_clock::now();
  render(scene, options, &stats);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  canceller.join();
  EXPECT_TRUE(stats.cancelled);
  EXPECT_EQ(reports, 0u);
  EXPECT_LT(stats.rays.camera, 64u * 64u * 256u);
  EXPECT_LT(seconds, 2.0);
}

// One pixel of millions of rays (issue 13: 65536 samples, each lit by a 4096-sample area light,
// about 2.7e8 shadow rays): a cancel must stop it within one sample, not at the pixel's end.
TEST(Renderer, CancelStopsInsideAPixelWithinOneSample) {
  SceneParts parts = litPlaneParts(1, 1);
  parts.image.samples = 65536;
  AreaLight light;
  light.shape = AreaShape::Disk;
  light.center = {0, 0, 5};
  light.normal = {0, 0, -1};
  light.radius = 1;
  light.intensity = Color(1);
  light.samples = 4096;
  parts.lights.push_back(light);
  const Scene scene(std::move(parts));
  std::atomic<bool> cancel{false};
  RenderOptions options;
  options.cancel = &cancel;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    cancel = true;
  });
  RenderStats stats;
  const auto start = std::chrono::steady_clock::now();
  render(scene, options, &stats);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  canceller.join();
  EXPECT_TRUE(stats.cancelled);
  EXPECT_LT(stats.rays.camera, 65536u);
  EXPECT_LT(seconds, 1.0);
}

TEST(Renderer, SamplesPerPixelIsTheRangeTheRendererTakes) {
  ImageSettings image;
  image.samples = 1;
  EXPECT_EQ(samplesPerPixel(image).minimum, 1);
  EXPECT_EQ(samplesPerPixel(image).maximum, 1);
  // Adaptive sampling takes at least 4 samples, whatever image.samples says ...
  image.adaptive = AdaptiveSampling{64, 0.02};
  EXPECT_EQ(samplesPerPixel(image).minimum, 4);
  EXPECT_EQ(samplesPerPixel(image).maximum, 64);
  // ... but never more than its maximum, and image.samples above the maximum raises it.
  image.adaptive->maxSamples = 2;
  EXPECT_EQ(samplesPerPixel(image).minimum, 2);
  EXPECT_EQ(samplesPerPixel(image).maximum, 2);
  image.samples = 16;
  image.adaptive->maxSamples = 8;
  EXPECT_EQ(samplesPerPixel(image).minimum, 16);
  EXPECT_EQ(samplesPerPixel(image).maximum, 16);

  // What the renderer really spends: 4 samples per pixel on a flat, noiseless image.
  SceneParts parts = litPlaneParts(6, 4);
  parts.image.samples = 1;
  parts.image.adaptive = AdaptiveSampling{64, 0.02};
  RenderStats stats;
  render(Scene(std::move(parts)), {}, &stats);
  EXPECT_EQ(stats.rays.camera, 6u * 4u * 4u);
}

TEST(Renderer, PixelWorkCountsSamplesLightsGlossAndDepth) {
  SceneParts parts = litPlaneParts(1, 1);
  parts.image.samples = 65536;
  AreaLight light;
  light.samples = 65536;
  parts.lights.push_back(light);
  PixelWork work = estimatePixelWork(parts.image, parts.render, parts.lights, parts.materials);
  EXPECT_EQ(work.samples, 65536u);
  EXPECT_EQ(work.depth, 1) << "nothing reflects or transmits";
  EXPECT_EQ(work.shadowRaysPerHit, 65536u + 1u);  // the area light and the directional light
  EXPECT_EQ(work.glossyRaysPerHit, 0u);
  EXPECT_DOUBLE_EQ(work.raysPerPixel(), 65536.0 * (1 + 65537));

  // A glossy mirror: paths go to max_depth, cut where the weight 0.5^k falls below min_weight.
  Material mirror;
  mirror.kr = Color(0.5);
  mirror.reflectionBlur = 5;
  parts.materials.push_back(mirror);
  parts.render.maxDepth = 20;
  parts.render.minWeight = 0.01;  // 0.5^6 = 0.016 is traced, 0.5^7 = 0.008 is not
  parts.render.blurSamples = 8;
  work = estimatePixelWork(parts.image, parts.render, parts.lights, parts.materials);
  EXPECT_EQ(work.depth, 7);
  EXPECT_DOUBLE_EQ(work.hitsPerSample, 7);
  EXPECT_EQ(work.glossyRaysPerHit, 8u);
  // Glass that reflects and transmits forks every path: 2^depth − 1 hits.
  Material glass;
  glass.kr = Color(0.1);
  glass.kt = Color(0.9);
  parts.materials.push_back(glass);
  parts.render.minWeight = 0;
  work = estimatePixelWork(parts.image, parts.render, parts.lights, parts.materials);
  EXPECT_EQ(work.depth, 20);
  EXPECT_DOUBLE_EQ(work.hitsPerSample, std::exp2(20) - 1);
  // Adaptive sampling: its maximum counts.
  parts.image.samples = 4;
  parts.image.adaptive = AdaptiveSampling{128, 0.02};
  EXPECT_EQ(estimatePixelWork(parts.image, parts.render, parts.lights, parts.materials).samples,
            128u);
  // The path integrator: one path of max_depth hits, one ray on from each, and its next-event
  // rays toward emitters and an image sky besides the lights' shadow rays.
  parts.render.integrator = Integrator::Path;
  work = estimatePixelWork(parts.image, parts.render, parts.lights, parts.materials, 2);
  EXPECT_DOUBLE_EQ(work.hitsPerSample, 20);
  EXPECT_EQ(work.shadowRaysPerHit, 65536u + 1u + 2u);
  EXPECT_EQ(work.glossyRaysPerHit, 1u);
}

}  // namespace
}  // namespace glint
