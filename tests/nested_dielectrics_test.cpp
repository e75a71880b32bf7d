// Nested dielectrics (DESIGN.md §11, scene/media.h) through scenes and renders: a glass sphere
// inside a glass sphere of the same material is invisible (Whitted and path), light bends by the
// ratio of the two media's ior at a water–glass interface (Snell's law, total internal reflection),
// shadow rays keep one solid's transmittance across a same-material boundary, material priorities
// decide who owns an overlap, and the camera knows the media it starts in.
#include <gtest/gtest.h>
#include <algorithm>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "glint/core/rng.h"
#include "glint/core/spawn.h"
#include "glint/factories/scene_loader.h"
#include "glint/factories/scene_test_support.h"
#include "glint/image/image_writer.h"
#include "glint/render/refraction.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

Scene sceneOf(const std::string& text) {
  return Scene(loadSceneFromString(text, "test.yaml").parts);
}

// The 8-bit sRGB codes of a render, as the PNG holds them.
std::vector<std::uint8_t> codesOf(const Scene& scene) {
  RenderOptions options;
  options.threads = 2;
  const Film film = render(scene, options);
  std::vector<std::uint8_t> codes;
  for (const Color& c : film.pixels()) {
    for (const double channel : {c.r, c.g, c.b}) {
      codes.push_back(encodeChannel(channel, Encoding::Srgb));
    }
  }
  return codes;
}

// A glass ball on a checker floor in front of coloured balls, lit by a point light from above so
// that its shadow (through the ball) falls on the floor in view; `inner` adds objects.
std::string glassBallScene(const std::string& render, const std::string& inner) {
  return R"(
camera: {position: [0, 1.6, 6], look_at: [0, 0.9, 0], fov: 40}
image: {width: 64, height: 48, samples: 2}
background: [0.3, 0.45, 0.7]
ambient: {color: [1, 1, 1], intensity: 0.1}
render: )" +
         render + R"(
textures:
  tiles: {type: checker, colors: [[0.8, 0.8, 0.75], [0.1, 0.1, 0.12]], scale: 0.5}
materials:
  glass: {kd: 0.03, ks: 0.8, shininess: 120, kr: 0.1, kt: 0.8, ior: 1.5}
  twin: {kd: 0.03, ks: 0.8, shininess: 120, kr: 0.1, kt: 0.8, ior: 1.5}
objects:
  - {type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: {kd: tiles, ka: tiles}}
  - {type: sphere, center: [-1.5, 0.5, -3], radius: 0.5, material: {kd: [0.8, 0.2, 0.1]}}
  - {type: sphere, center: [1.2, 0.6, -2.5], radius: 0.6, material: {kd: [0.1, 0.3, 0.8]}}
  - {type: sphere, center: [0, 1, 0], radius: 1, material: glass}
)" + inner +
         R"(
lights:
  - {type: point, position: [1.5, 6, 2]}
)";
}

constexpr const char* kWhitted = "{integrator: whitted}";
constexpr const char* kPath = "{integrator: path, max_depth: 8}";
constexpr const char* kInnerGlass =
    "  - {type: sphere, center: [0.2, 1.1, 0.1], radius: 0.55, material: glass}\n";
constexpr const char* kInnerTwin =
    "  - {type: sphere, center: [0.2, 1.1, 0.1], radius: 0.55, material: twin}\n";

TEST(NestedDielectrics, SameGlassInsideGlassRendersAsTheOuterSphereAlone) {
  const Scene alone = sceneOf(glassBallScene(kWhitted, ""));
  const Scene nested = sceneOf(glassBallScene(kWhitted, kInnerGlass));
  EXPECT_FALSE(alone.nestedMedia());
  ASSERT_TRUE(nested.nestedMedia());
  EXPECT_EQ(codesOf(nested), codesOf(alone));
  // The test can tell: an inner sphere of another material (the same values, named apart) is a
  // surface, which shows.
  const Scene twin = sceneOf(glassBallScene(kWhitted, kInnerTwin));
  EXPECT_NE(codesOf(twin), codesOf(alone));
}

TEST(NestedDielectrics, SameGlassInsideGlassIsInvisibleToThePathIntegrator) {
  const Scene alone = sceneOf(glassBallScene(kPath, ""));
  const Scene nested = sceneOf(glassBallScene(kPath, kInnerGlass));
  ASSERT_TRUE(nested.nestedMedia());
  EXPECT_EQ(codesOf(nested), codesOf(alone));
  EXPECT_NE(codesOf(sceneOf(glassBallScene(kPath, kInnerTwin))), codesOf(alone));
}

TEST(NestedDielectrics, NestedRendersAreTheSameOnAnyThreadCount) {
  const Scene nested = sceneOf(glassBallScene(kWhitted, kInnerTwin));
  RenderOptions one;
  one.threads = 1;
  one.tileSize = 7;
  RenderOptions two;
  two.threads = 2;
  EXPECT_TRUE(std::ranges::equal(render(nested, one).pixels(), render(nested, two).pixels()));
}

// Two concentric spheres of radius 1 and 0.5 at the origin, the inner of `innerMaterial`.
std::string concentricSpheres(const std::string& innerMaterial) {
  return std::string(testing::kMinimal) + R"(materials:
  glass: {kt: 0.8, ior: 1.5}
  tinted: {kt: 0.5, ior: 1.5}
objects:
  - {type: sphere, center: [0, 0, 0], radius: 1, material: glass}
  - {type: sphere, center: [0, 0, 0], radius: 0.5, material: )" +
         innerMaterial + "}\n";
}

TEST(NestedDielectrics, ShadowRayKeepsOneSolidsTransmittanceAcrossASameMaterialBoundary) {
  const Ray through{{-3, 0, 0}, {1, 0, 0}};
  const Scene same = sceneOf(concentricSpheres("glass"));
  ASSERT_TRUE(same.nestedMedia());
  // Four crossings, of which the inner sphere's two are no surface: kt² of one glass sphere.
  EXPECT_EQ(same.transmittance(through, kInfinity, MediumStack{}), Color(0.8 * 0.8));
  // The order-free query counts every crossing (kt⁴): what the nested rule corrects.
  EXPECT_NEAR(same.transmittance(through, kInfinity).r, std::pow(0.8, 4), 1e-12);
  // A shadow ray that starts inside the glass, between the spheres, leaves it once.
  MediumStack inGlass;
  inGlass.push(1);  // the material index of `glass` (0 is the default material)
  EXPECT_EQ(same.transmittance(Ray{{-0.75, 0, 0}, {1, 0, 0}}, kInfinity, inGlass), Color(0.8));
  // Another material inside is a surface: its two crossings count.
  const Scene other = sceneOf(concentricSpheres("tinted"));
  EXPECT_NEAR(other.transmittance(through, kInfinity, MediumStack{}).g, 0.8 * 0.8 * 0.5 * 0.5,
              1e-15);
  // An opaque blocker still stops it.
  const Scene blocked = sceneOf(concentricSpheres("{kd: 1}"));
  EXPECT_EQ(blocked.transmittance(through, kInfinity, MediumStack{}), Color());
}

// Shadow rays in scenes with nested media take the order-free query when no boundary can be "no
// surface" (spheres of distinct materials strictly inside one another), and walk the crossings
// otherwise. Two partly overlapping spheres of distinct materials are the case the shortcut must
// not take: leaving the first inside the second (entered later, equal priority) is no surface.
TEST(NestedDielectrics, PartlyOverlappingSolidsOfDistinctMaterialsCountOnlyTheirSurfaces) {
  const Scene overlap = sceneOf(std::string(testing::kMinimal) + R"(materials:
  glass: {kt: 0.8, ior: 1.5}
  tinted: {kt: 0.5, ior: 1.5}
objects:
  - {type: sphere, center: [-0.5, 0, 0], radius: 1, material: glass}
  - {type: sphere, center: [0.5, 0, 0], radius: 1, material: tinted}
)");
  ASSERT_TRUE(overlap.nestedMedia());
  const Ray through{{-3, 0, 0}, {1, 0, 0}};
  // Into the glass (0.8), into the tinted (0.5), out of the glass inside the tinted (no surface),
  // out of the tinted (0.5).
  EXPECT_NEAR(overlap.transmittance(through, kInfinity, MediumStack{}).r, 0.8 * 0.5 * 0.5, 1e-15);
  // Strictly nested distinct materials: every crossing is a surface (the shortcut's case), so a
  // ray keeps 0.8 per crossing of the outer sphere and 0.5 per crossing of the inner one.
  const Scene nested = sceneOf(concentricSpheres("tinted"));
  const auto crossingsOf = [](const Ray& ray, double radius, double tMax) {
    // |o + t·d|² = r² with |d| = 1: t = −b ± √(b² − c).
    const double b = dot(toVec(ray.origin), ray.direction);
    const double c = dot(toVec(ray.origin), toVec(ray.origin)) - radius * radius;
    const double disc = b * b - c;
    if (disc <= 0) return 0;
    int n = 0;
    for (const double t : {-b - std::sqrt(disc), -b + std::sqrt(disc)}) n += t > 0 && t < tMax;
    return n;
  };
  Rng rng(3);
  int throughBoth = 0;
  for (int k = 0; k < 400; ++k) {
    // From anywhere near the spheres (inside them too) towards a point near their centre.
    const Point3 origin(4 * rng.uniform() - 2, 4 * rng.uniform() - 2, 4 * rng.uniform() - 2);
    const Point3 target(0.8 * rng.uniform() - 0.4, 0.8 * rng.uniform() - 0.4,
                        0.8 * rng.uniform() - 0.4);
    const Ray ray{origin, normalize(target - origin)};
    const int outer = crossingsOf(ray, 1, 10);
    const int inner = crossingsOf(ray, 0.5, 10);
    throughBoth += outer > 0 && inner > 0;
    EXPECT_NEAR(nested.transmittance(ray, 10, MediumStack{}).r,
                std::pow(0.8, outer) * std::pow(0.5, inner), 1e-14)
        << "ray " << k;
  }
  EXPECT_GT(throughBoth, 100);
}

// A glass block with a water block inside it, the water's top face at y = 0 (a planar water–glass
// interface); the camera sits in the glass above the water.
constexpr const char* kWaterInGlass = R"(
camera: {position: [0, 1, 0], direction: [0, -1, 0], up: [0, 0, -1], fov: 40}
image: {width: 4, height: 3}
materials:
  glass: {kt: 0.9, ior: 1.5}
  water: {kt: 0.95, ior: 1.33}
objects:
  - {type: box, min: [-20, -20, -20], max: [20, 20, 20], material: glass}
  - {type: box, min: [-10, -10, -10], max: [10, 0, 10], material: water}
)";

TEST(NestedDielectrics, LightBendsByTheWaterToGlassRatioAtTheirInterface) {
  const Scene scene = sceneOf(kWaterInGlass);
  ASSERT_TRUE(scene.nestedMedia());
  ASSERT_EQ(scene.cameraMedia().size(), 1);
  EXPECT_EQ(scene.cameraMedia()[0], 1u);  // inside the glass
  const double n1 = 1.5;
  const double n2 = 1.33;
  const double critical = std::asin(n2 / n1);  // ≈ 62.46°
  for (const double degrees : {0.0, 10.0, 30.0, 45.0, 60.0, 62.0, 63.0, 75.0}) {
    SCOPED_TRACE(degrees);
    const double theta1 = degrees * std::numbers::pi / 180;
    const Vec3 v{std::sin(theta1), -std::cos(theta1), 0};
    MediumStack media = scene.cameraMedia();
    Hit hit;
    ASSERT_TRUE(scene.intersect(Ray{{0, 1, 0}, v}, kInfinity, hit, media));
    EXPECT_NEAR(hit.point.y, 0, 1e-12);  // the water's top face
    MediumStack beyond;
    const Boundary boundary = scene.boundaryAt(hit, v, media, beyond);
    ASSERT_TRUE(boundary.surface);
    EXPECT_DOUBLE_EQ(boundary.eta(), n1 / n2);
    const double nv = dot(hit.normal, v);
    const Vec3 reflected = v - toVec(hit.normal) * (2 * nv);
    const Vec3 t = transmittedDirection(boundary.eta(), v, hit.normal, hit.normal, nv, false,
                                        reflected, nv < 0);
    EXPECT_NEAR(length(t), 1, 1e-12);
    if (theta1 < critical) {
      // Snell's law: n1 sin θ1 = n2 sin θ2, on into the water (downward, same side of the normal).
      EXPECT_LT(t.y, 0);
      EXPECT_NEAR(n1 * std::sin(theta1), n2 * std::sqrt(t.x * t.x + t.z * t.z), 1e-12);
      EXPECT_EQ(beyond.size(), 2);  // glass, then water
      EXPECT_EQ(beyond[1], 2u);
    } else {
      // Total internal reflection: the mirror direction, back up into the glass.
      EXPECT_EQ(t, reflected);
      EXPECT_GT(t.y, 0);
    }
  }
}

TEST(NestedDielectrics, LeavingTheWaterIntoTheGlassBendsTheOtherWay) {
  // From inside the water (entered through its top face), the bottom face leads back into glass.
  const Scene scene = sceneOf(kWaterInGlass);
  const double theta1 = 40 * std::numbers::pi / 180;
  const Vec3 v{std::sin(theta1), -std::cos(theta1), 0};
  MediumStack media;
  media.push(1);
  media.push(2);
  Hit hit;
  ASSERT_TRUE(scene.intersect(Ray{{0, -1, 0}, v}, kInfinity, hit, media));
  EXPECT_NEAR(hit.point.y, -10, 1e-9);
  MediumStack beyond;
  const Boundary boundary = scene.boundaryAt(hit, v, media, beyond);
  EXPECT_DOUBLE_EQ(boundary.eta(), 1.33 / 1.5);
  const double nv = dot(hit.normal, v);
  const Vec3 t =
      transmittedDirection(boundary.eta(), v, hit.normal, hit.normal, nv, false, v, nv < 0);
  EXPECT_NEAR(1.33 * std::sin(theta1), 1.5 * std::sqrt(t.x * t.x + t.z * t.z), 1e-12);
  ASSERT_EQ(beyond.size(), 1);
  EXPECT_EQ(beyond[0], 1u);
}

// Surfaces a ray from x = −5 along +x meets through overlapping glass (centre x = −0.6) and water
// (centre x = 0.6) spheres of radius 1 with the given priorities: (x of the hit, eta) pairs.
std::vector<std::pair<double, double>> surfacesThroughOverlap(int glassPriority,
                                                              int waterPriority) {
  const Scene scene =
      sceneOf(std::string(testing::kMinimal) + "materials:\n  glass: {kt: 0.9, " +
              "ior: 1.5, priority: " + std::to_string(glassPriority) +
              "}\n  water: {kt: 0.9, ior: 1.33, priority: " + std::to_string(waterPriority) + R"(}
objects:
  - {type: sphere, center: [-0.6, 0, 0], radius: 1, material: glass}
  - {type: sphere, center: [0.6, 0, 0], radius: 1, material: water}
)");
  std::vector<std::pair<double, double>> surfaces;
  const Vec3 direction{1, 0, 0};
  Ray ray{{-5, 0, 0}, direction};
  MediumStack media;
  Hit hit;
  while (scene.intersect(ray, kInfinity, hit, media) && surfaces.size() < 10) {
    MediumStack beyond;
    surfaces.emplace_back(hit.point.x, scene.boundaryAt(hit, direction, media, beyond).eta());
    media = beyond;
    ray = spawnRay(hit.point, hit.pointError, hit.normal, direction);
  }
  return surfaces;
}

void expectSurfaces(const std::vector<std::pair<double, double>>& actual,
                    const std::vector<std::pair<double, double>>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    EXPECT_NEAR(actual[i].first, expected[i].first, 1e-12) << i;
    EXPECT_DOUBLE_EQ(actual[i].second, expected[i].second) << i;
  }
}

TEST(NestedDielectrics, PriorityDecidesWhoOwnsAnOverlap) {
  // Glass first: the water's boundary inside the glass is no surface; the glass's far side is the
  // glass–water interface.
  expectSurfaces(surfacesThroughOverlap(1, 0), {{-1.6, 1 / 1.5}, {0.4, 1.5 / 1.33}, {1.6, 1.33}});
  // Water first: the water's near side is the interface, the glass's far side inside it is none.
  expectSurfaces(surfacesThroughOverlap(0, 1), {{-1.6, 1 / 1.5}, {-0.4, 1.5 / 1.33}, {1.6, 1.33}});
  // Equal priorities: the one entered last (the water) owns the overlap — the same as water first.
  expectSurfaces(surfacesThroughOverlap(0, 0), {{-1.6, 1 / 1.5}, {-0.4, 1.5 / 1.33}, {1.6, 1.33}});
}

TEST(NestedDielectrics, TheCameraStartsInTheMediaItIsInside) {
  const Scene scene = sceneOf(R"(
camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}
image: {width: 4, height: 3}
materials:
  glass: {kt: 0.9, ior: 1.5}
  water: {kt: 0.9, ior: 1.33}
objects:
  - {type: sphere, center: [0, 0, 0], radius: 1, material: glass}
  - {type: sphere, center: [0, 0, 0.5], radius: 3, material: water}
  - {type: sphere, center: [0, 0, -6], radius: 1, material: glass}
)");
  ASSERT_TRUE(scene.nestedMedia());
  ASSERT_EQ(scene.cameraMedia().size(), 2);
  EXPECT_EQ(scene.cameraMedia()[0], 2u);  // water, outermost
  EXPECT_EQ(scene.cameraMedia()[1], 1u);  // glass, innermost
}

// A glass sphere of radius 1 at the origin with a cube mesh of half-size 0.5 inside it, both of one
// glass material; `faces` picks the cube's triangles (12: closed), `inward` flips their winding.
Scene sphereWithCubeMesh(int faces, bool inward) {
  SceneParts parts;
  parts.camera.position = {0, 0, 5};
  parts.camera.direction = {0, 0, -1};
  parts.camera.up = {0, 1, 0};
  parts.camera.viewPlaneWidth = 1;
  parts.camera.viewPlaneHeight = 1;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = 4;
  parts.image.height = 4;
  Material glass;
  glass.kt = Color(0.8);
  glass.ior = 1.5;
  parts.materials.push_back(glass);
  parts.primitives.emplace_back(Sphere::make({0, 0, 0}, 1), 1u, Color{});
  TriangleMesh cube;
  const double h = 0.5;
  cube.positions = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h},
                    {-h, -h, h},  {h, -h, h},  {h, h, h},  {-h, h, h}};
  const std::vector<std::uint32_t> outward = {0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                              3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  for (int t = 0; t < faces; ++t) {
    const std::size_t i = 3 * static_cast<std::size_t>(t);
    if (inward) {
      cube.indices.insert(cube.indices.end(), {outward[i], outward[i + 2], outward[i + 1]});
    } else {
      cube.indices.insert(cube.indices.end(), {outward[i], outward[i + 1], outward[i + 2]});
    }
  }
  cube.materialIndex = 1;
  parts.meshes.push_back(std::move(cube));
  return Scene(std::move(parts));
}

TEST(NestedDielectrics, AClosedOutwardMeshIsASolid) {
  // Along the x axis: the sphere at ±1, the cube's faces at ±0.5 (crossed through face centres).
  const Ray through{{-3, 0.1, 0.2}, {1, 0, 0}};
  const Scene closed = sphereWithCubeMesh(12, false);
  ASSERT_TRUE(closed.nestedMedia());
  // The cube is of the sphere's glass: its faces are no surface, for shadow rays and for rays.
  EXPECT_EQ(closed.transmittance(through, kInfinity, MediumStack{}), Color(0.8 * 0.8));
  MediumStack media;
  Hit hit;
  ASSERT_TRUE(closed.intersect(through, kInfinity, hit, media));
  EXPECT_NEAR(hit.point.x, -std::sqrt(1 - 0.05), 1e-12);  // the sphere
  Ray inside = spawnRay(hit.point, hit.pointError, hit.normal, through.direction);
  MediumStack beyond;
  closed.boundaryAt(hit, through.direction, media, beyond);
  ASSERT_TRUE(closed.intersect(inside, kInfinity, hit, beyond));
  EXPECT_NEAR(hit.point.x, std::sqrt(1 - 0.05), 1e-12);  // the sphere's far side: the cube passed
  // An open cube (two triangles missing) or one facing inward bounds nothing: a surface each time.
  for (const auto& [faces, inward] : {std::pair{10, false}, std::pair{12, true}}) {
    const Scene sheets = sphereWithCubeMesh(faces, inward);
    Hit first;
    MediumStack none;
    ASSERT_TRUE(sheets.intersect(through, kInfinity, first, none));
    EXPECT_EQ(sheets.mediumOf(first), 1u);  // the sphere
    const Ray on = spawnRay(first.point, first.pointError, first.normal, through.direction);
    ASSERT_TRUE(sheets.intersect(on, kInfinity, first, none));
    EXPECT_EQ(first.mesh, 0u);
    EXPECT_EQ(sheets.mediumOf(first), kNoMedium);
  }
}

TEST(NestedDielectrics, PriorityIsAWholeNumberAtLeastZero) {
  const std::string scene = std::string(testing::kMinimal) + "materials:\n";
  testing::expectOneError(scene + "  water: {kt: 0.9, priority: 1.5}\n", 4, 30,
                          "expected a whole number");
  testing::expectOneError(scene + "  water: {kt: 0.9, priority: -1}\n", 4, 30, "must be >= 0");
  EXPECT_TRUE(testing::errorsOf(scene + "  water: {kt: 0.9, priority: 3}\n").empty());
}

}  // namespace
}  // namespace glint
