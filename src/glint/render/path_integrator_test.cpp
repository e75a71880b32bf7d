// render.integrator: path (DESIGN.md §10): the white furnace, the same direct light as the Whitted
// integrator, Russian roulette without bias, and the same bytes on any thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include "glint/core/transform.h"
#include "glint/geometry/shape.h"
#include "glint/render/render_test_support.h"
#include "glint/render/renderer.h"
#include "glint/scene/environment.h"
#include "glint/scene/mip_map.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

// The camera at the origin looking down −z through a 2×2 view plane at distance 1.
SceneParts cameraParts(int width, int height) {
  SceneParts parts;
  parts.camera.position = {0, 0, 0};
  parts.camera.direction = {0, 0, -1};
  parts.camera.up = {0, 1, 0};
  parts.camera.viewPlaneWidth = 2.0 * width / height;
  parts.camera.viewPlaneHeight = 2;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = width;
  parts.image.height = height;
  parts.image.encoding = Encoding::Linear;
  parts.render.integrator = Integrator::Path;
  return parts;
}

std::uint32_t addMaterial(SceneParts& parts, const Material& material) {
  parts.materials.push_back(material);
  return static_cast<std::uint32_t>(parts.materials.size() - 1);
}

Material diffuse(const Color& kd) {
  Material m;
  m.kd = kd;
  return m;  // ka stays 1: the path integrator must not add the ambient light
}

Color meanOf(const Film& film) {
  Color sum;
  for (const Color& c : film.pixels()) sum += c;
  return sum / static_cast<double>(film.pixels().size());
}

// White furnace: a diffuse convex object with kd = a under a uniform background L renders a·L;
// every path that leaves it escapes, so each sample is exactly a·L.
TEST(PathIntegrator, WhiteFurnaceSphereAndPlane) {
  const Color background(0.5, 0.7, 0.9);
  const Color albedo(0.8, 0.5, 0.25);
  for (const bool sphere : {true, false}) {
    SceneParts parts = cameraParts(16, 16);
    parts.background = background;
    parts.ambient = Color(1, 1, 1);  // not added under `path`
    parts.image.samples = 16;
    const std::uint32_t m = addMaterial(parts, diffuse(albedo));
    if (sphere) {
      parts.primitives.emplace_back(Sphere::make({0, 0, -5}, 10), m, Color{});
      parts.camera.position = {0, 0, 30};  // outside it, the sphere filling the view
      parts.camera.viewPlaneWidth = parts.camera.viewPlaneHeight = 0.2;
    } else {
      // A plane seen from above filling the view.
      parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), m, Color{});
    }
    const Film film = render(Scene(std::move(parts)));
    for (const Color& c : film.pixels()) {
      EXPECT_NEAR(c.r, albedo.r * background.r, 1e-12) << (sphere ? "sphere" : "plane");
      EXPECT_NEAR(c.g, albedo.g * background.g, 1e-12);
      EXPECT_NEAR(c.b, albedo.b * background.b, 1e-12);
    }
  }
}

// The furnace holds on a coarse smooth mesh too: where a cosine-weighted direction about a tilted
// shading normal falls below the face, it is folded back above it rather than lost, so every
// sample is again exactly a·L (it was 2–3 % darker on average, down to half at the vertices).
TEST(PathIntegrator, WhiteFurnaceSmoothCoarseMesh) {
  const Color background(0.5, 0.7, 0.9);
  const Color albedo(0.8, 0.5, 0.25);
  SceneParts parts = cameraParts(24, 24);
  parts.background = background;
  parts.image.samples = 16;
  const std::uint32_t m = addMaterial(parts, diffuse(albedo));
  parts.meshes.push_back(testing::smoothIcosahedron({0, 0, -5}, 1, m));
  parts.camera.viewPlaneWidth = parts.camera.viewPlaneHeight = 0.2;  // the mesh fills the view
  const Film film = render(Scene(std::move(parts)));
  for (const Color& c : film.pixels()) {
    EXPECT_NEAR(c.r, albedo.r * background.r, 1e-12);
    EXPECT_NEAR(c.g, albedo.g * background.g, 1e-12);
    EXPECT_NEAR(c.b, albedo.b * background.b, 1e-12);
  }
}

// A single diffuse plane under one light of each kind: the path integrator's direct light is the
// Whitted integrator's (no ambient, a black background: nothing else reaches the plane), to the
// bit — the area light's points come from the same sampler dimensions.
TEST(PathIntegrator, DirectLightIsTheWhittedIntegratorsForEveryLightKind) {
  std::vector<Light> lights;
  lights.push_back(PointLight{{1, 2, -3}, Color(3, 2, 1), {1, 0, 0.1}});
  lights.push_back(DirectionalLight{normalize(Vec3{0.3, -0.5, -1}), Color(0.9, 0.8, 0.7)});
  SpotLight spot;
  spot.position = {0, 3, -4};
  spot.direction = normalize(Vec3{0, -1, -0.5});
  spot.intensity = Color(2, 2, 2);
  spot.exponent = 4;
  lights.push_back(spot);
  AreaLight area;
  area.shape = AreaShape::Rectangle;
  area.corner = {-1, 2, -1.5};  // above the view: the camera does not see it
  area.edge1 = {2, 0, 0};
  area.edge2 = {0, 0, 2};
  area.intensity = Color(1.5, 1.5, 1.5);
  area.samples = 8;
  lights.push_back(area);
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const auto scene = [&](Integrator integrator) {
      SceneParts parts = cameraParts(12, 9);
      parts.image.samples = 4;
      parts.render.integrator = integrator;
      Material matte = diffuse(Color(0.7, 0.6, 0.5));
      parts.primitives.emplace_back(Plane::make({0, -1, 0}, {0, 1, 0}), addMaterial(parts, matte),
                                    Color{});
      parts.lights.push_back(lights[i]);
      return Scene(std::move(parts));
    };
    const Film whitted = render(scene(Integrator::Whitted));
    const Film path = render(scene(Integrator::Path));
    ASSERT_EQ(whitted.pixels().size(), path.pixels().size());
    double lit = 0;
    for (std::size_t k = 0; k < whitted.pixels().size(); ++k) {
      EXPECT_EQ(whitted.pixels()[k], path.pixels()[k]) << "light " << i << " pixel " << k;
      lit += whitted.pixels()[k].r;
    }
    EXPECT_GT(lit, 0) << "light " << i << " lights nothing";
  }
}

// Inside a closed sphere whose inner surface emits E and reflects diffusely with albedo a, the
// radiance is E·(1 + a + a² + …) = E/(1 − a). Russian roulette (from the third hit) and the
// 1000-hit cap must not bias it: the mean of 16×16 pixels × 64 samples is within 1 %.
TEST(PathIntegrator, ClosedEmissiveSphereConvergesToTheGeometricSeries) {
  SceneParts parts = cameraParts(16, 16);
  parts.image.samples = 64;
  parts.render.maxDepth = 1000;
  const double albedo = 0.5;
  const Color emission(0.25, 0.5, 1);
  parts.primitives.emplace_back(Sphere::make({0, 0, 0}, 10),
                                addMaterial(parts, diffuse(Color(albedo))), emission);
  RenderStats stats;
  const Film film = render(Scene(std::move(parts)), {}, &stats);
  const Color mean = meanOf(film);
  EXPECT_NEAR(mean.r / (emission.r / (1 - albedo)), 1, 0.01);
  EXPECT_NEAR(mean.g / (emission.g / (1 - albedo)), 1, 0.01);
  EXPECT_NEAR(mean.b / (emission.b / (1 - albedo)), 1, 0.01);
  // Paths went on after the primary hit: indirect rays were traced and counted as such.
  EXPECT_GT(stats.rays.indirect, stats.rays.camera);
  EXPECT_EQ(stats.rays.reflection, 0u);
}

TEST(PathIntegrator, TheSameBytesOnAnyThreadCountAndTileSize) {
  SceneParts parts = cameraParts(20, 14);
  parts.image.samples = 3;
  parts.background = Color(0.3, 0.4, 0.5);
  Material shiny = diffuse(Color(0.4, 0.5, 0.6));
  shiny.ks = Color(0.3);
  shiny.shininess = 20;
  shiny.kr = Color(0.1);
  shiny.reflectionBlur = 10;
  Material glass;
  glass.kd = Color(0);
  glass.kt = Color(0.9);
  glass.ior = 1.5;
  parts.primitives.emplace_back(Plane::make({0, -1, 0}, {0, 1, 0}), addMaterial(parts, shiny),
                                Color{});
  parts.primitives.emplace_back(Sphere::make({0.5, 0, -4}, 1), addMaterial(parts, glass), Color{});
  parts.primitives.emplace_back(Sphere::make({-1.5, 0, -5}, 1), addMaterial(parts, shiny),
                                Color(0.5, 0.2, 0.1));
  parts.lights.push_back(PointLight{{0, 4, -2}, Color(5, 5, 5), {0, 0, 1}});
  EXPECT_TRUE(testing::rendersTheSameOnAnyThreadCountAndTileSize(Scene(std::move(parts))));
}

// An equirectangular environment of width × height texels of `sky`, with a square patch of
// `sunSize` texels of `sun` around texel (sunX, sunY) (rows from the top).
Environment skyWithSun(int width, int height, float sky, float sun, int sunX, int sunY, int sunSize,
                       double rotateDegrees = 0) {
  RgbImage image{width, height,
                 std::vector<float>(static_cast<std::size_t>(width * height * 3), sky)};
  for (int y = sunY; y < sunY + sunSize; ++y) {
    for (int x = sunX; x < sunX + sunSize; ++x) {
      for (int c = 0; c < 3; ++c)
        image.pixels[static_cast<std::size_t>(3 * (y * width + x) + c)] = sun;
    }
  }
  Environment e;
  e.kind = BackgroundKind::Image;
  e.image = std::make_shared<const MipMap>(std::move(image));
  e.cosRotate = std::cos(rotateDegrees * std::numbers::pi / 180);
  e.sinRotate = std::sin(rotateDegrees * std::numbers::pi / 180);
  return e;
}

// The environment sampler's density integrates to 1 over the sphere, and the density sample()
// returns is the one pdf() gives for the same direction.
TEST(EnvironmentSampler, ADensityOverTheSphereThatSampleAndPdfAgreeOn) {
  const Environment sky = skyWithSun(64, 32, 0.2f, 400, 40, 6, 3, 30);
  const auto sampler = EnvironmentSampler::make(sky);
  ASSERT_NE(sampler, nullptr);
  // Midpoint quadrature over θ, φ: ∫ pdf dω.
  constexpr int kSteps = 1024;
  double integral = 0;
  for (int i = 0; i < kSteps; ++i) {
    const double theta = (i + 0.5) * std::numbers::pi / kSteps;
    for (int j = 0; j < 2 * kSteps; ++j) {
      const double phi = (j + 0.5) * std::numbers::pi / kSteps;
      const Vec3 d{std::sin(theta) * std::cos(phi), std::cos(theta),
                   std::sin(theta) * std::sin(phi)};
      integral += sampler->pdf(d) * std::sin(theta);
    }
  }
  integral *= (std::numbers::pi / kSteps) * (std::numbers::pi / kSteps);
  EXPECT_NEAR(integral, 1, 0.01);
  // Drawn directions are unit, carry pdf()'s density, and fall mostly on the sun: it holds
  // 9 × 400 of the 2048 × 0.2 + 9 × 400 luminance (before the sin θ weights).
  int onSun = 0;
  constexpr int kDraws = 4096;
  for (int k = 0; k < kDraws; ++k) {
    const Point2 u{(k + 0.5) / kDraws, std::fmod(k * 0.6180339887498949, 1.0)};
    double pdf = 0;
    const Vec3 d = sampler->sample(u, pdf);
    ASSERT_NEAR(length(d), 1, 1e-12);
    ASSERT_GT(pdf, 0);
    EXPECT_NEAR(sampler->pdf(d) / pdf, 1, 1e-6) << k;
    if (sky.along(d, Color()).r > 100) ++onSun;
  }
  EXPECT_GT(onSun, kDraws * 8 / 10);
  // A black image is nothing to sample.
  EXPECT_EQ(EnvironmentSampler::make(skyWithSun(8, 4, 0, 0, 0, 0, 0)), nullptr);
}

// A diffuse plane facing up under a sky with a small bright sun: its radiance is
// kd/π · ∫ L(ω) cos θ dω over the upper hemisphere (computed here by quadrature of the
// background); the environment's samples find the sun, the BRDF's cover the rest, and the mean
// of an 8×8 image at 1024 samples lands within 1 % (0.9925 here; 0.9991 at 8192 samples: the
// estimate converges on the integral).
TEST(PathIntegrator, AnImageSkyLightsADiffusePlaneAsItsIntegralSays) {
  const Environment sky = skyWithSun(64, 32, 0.2f, 400, 20, 5, 2, 70);
  constexpr double kd = 0.6;
  constexpr int kSteps = 1024;
  double irradiance = 0;
  for (int i = 0; i < kSteps; ++i) {
    const double theta = (i + 0.5) * (std::numbers::pi / 2) / kSteps;
    for (int j = 0; j < 4 * kSteps; ++j) {
      const double phi = (j + 0.5) * (std::numbers::pi / 2) / kSteps;
      const Vec3 d{std::sin(theta) * std::cos(phi), std::cos(theta),
                   std::sin(theta) * std::sin(phi)};
      irradiance += sky.along(d, Color()).r * std::cos(theta) * std::sin(theta);
    }
  }
  irradiance *= std::pow((std::numbers::pi / 2) / kSteps, 2);
  SceneParts parts = cameraParts(8, 8);
  parts.camera.position = {0, 5, 0};
  parts.camera.direction = {0, -1, 0};
  parts.camera.up = {0, 0, -1};
  parts.image.samples = 1024;
  parts.environment = sky;
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}),
                                addMaterial(parts, diffuse(Color(kd))), Color{});
  const Scene scene(std::move(parts));
  ASSERT_NE(scene.environmentSampler(), nullptr);
  const Color mean = meanOf(render(scene));
  EXPECT_NEAR(mean.r / (kd / std::numbers::pi * irradiance), 1, 0.01);
}

// The furnace under an image sky of one colour: multiple importance sampling between the
// environment's samples and the BRDF's still gives a·L (mean within 0.5 %).
TEST(PathIntegrator, WhiteFurnaceUnderAnImageSky) {
  SceneParts parts = cameraParts(16, 16);
  parts.image.samples = 64;
  parts.environment = skyWithSun(32, 16, 0.75f, 0.75f, 0, 0, 0);
  const double albedo = 0.8;
  parts.primitives.emplace_back(Sphere::make({0, 0, -5}, 10),
                                addMaterial(parts, diffuse(Color(albedo))), Color{});
  parts.camera.position = {0, 0, 30};
  parts.camera.viewPlaneWidth = parts.camera.viewPlaneHeight = 0.2;
  const Color mean = meanOf(render(Scene(std::move(parts))));
  EXPECT_NEAR(mean.r / (albedo * 0.75), 1, 0.005);
}

// The image-sky furnace on a coarse smooth mesh filling the view: the sky's light samples and the
// BRDF samples, weighted against each other, must agree on the lobes folded above each face.
TEST(PathIntegrator, WhiteFurnaceUnderAnImageSkyOnASmoothCoarseMesh) {
  SceneParts parts = cameraParts(16, 16);
  parts.image.samples = 64;
  parts.environment = skyWithSun(32, 16, 0.75f, 0.75f, 0, 0, 0);
  const double albedo = 0.8;
  parts.meshes.push_back(
      testing::smoothIcosahedron({0, 0, -5}, 1, addMaterial(parts, diffuse(Color(albedo)))));
  parts.camera.viewPlaneWidth = parts.camera.viewPlaneHeight = 0.2;
  const Color mean = meanOf(render(Scene(std::move(parts))));
  EXPECT_NEAR(mean.r / (albedo * 0.75), 1, 0.002);  // 0.992 if the samples disagree
}

// A small emissive sphere (radius r, radiance L) at height h over a diffuse plane: the point under
// it receives E = π·L·(r/h)² (a sphere seen at sin α = r/h, straight overhead) and shows
// kd·L·(r/h)². The sphere is drawn by the emitter sampler (area sampling, power heuristic against
// the BRDF's samples); both emitter kinds here give the analytic value within 1 % on a camera
// looking straight down at that point.
TEST(PathIntegrator, AnEmissiveSphereAndAnEmissiveTriangleLightAPlaneAsTheirFormulaSays) {
  constexpr double kd = 0.5;
  constexpr double radius = 0.1;
  constexpr double height = 2;
  const Color radiance(8, 4, 2);
  // A diffuse plane y = 0 seen straight down at the origin through a tiny view, 256 samples.
  const auto planeSeenAtTheOrigin = [&] {
    SceneParts p = cameraParts(8, 8);
    p.camera.position = {0, 1, 0};
    p.camera.direction = {0, -1, 0};
    p.camera.up = {0, 0, -1};
    p.camera.viewPlaneWidth = p.camera.viewPlaneHeight = 1e-4;
    p.image.samples = 256;
    p.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), addMaterial(p, diffuse(Color(kd))),
                              Color{});
    return p;
  };
  SceneParts parts = planeSeenAtTheOrigin();
  parts.primitives.emplace_back(Sphere::make({0, height, 0}, radius), 0u, radiance);
  const Scene scene(std::move(parts));
  ASSERT_NE(scene.emitterSampler(), nullptr);
  const double ratio = (radius / height) * (radius / height);
  const Color mean = meanOf(render(scene));
  EXPECT_NEAR(mean.r / (kd * radiance.r * ratio), 1, 0.01);
  EXPECT_NEAR(mean.b / (kd * radiance.b * ratio), 1, 0.01);

  // A small emissive triangle facing down, of area A at height h, straight overhead: E ≈ L·A/h²
  // (solid angle A/h², both cosines 1); exact to 0.1 % for a side of 0.04 at h = 2.
  SceneParts flat = planeSeenAtTheOrigin();
  constexpr double side = 0.04;
  flat.primitives.emplace_back(
      Triangle::make({-side / 2, height, -side / 3}, {side / 2, height, -side / 3},
                     {0, height, 2 * side / 3}),
      0u, radiance);
  const Scene triangleScene(std::move(flat));
  const double area = 0.5 * side * side;
  const Color lit = meanOf(render(triangleScene));
  EXPECT_NEAR(lit.g / (kd / std::numbers::pi * radiance.g * area / (height * height)), 1, 0.01);
}

// Renders `parts` with MIS, with light sampling alone and with BRDF sampling alone, and expects
// the two single strategies' image means within 3 % of MIS's in every channel.
void expectEachStrategyAgreesWithMis(const SceneParts& parts) {
  Color means[3];
  const PathLightSampling kinds[] = {PathLightSampling::Mis, PathLightSampling::LightsOnly,
                                     PathLightSampling::BrdfOnly};
  for (int k = 0; k < 3; ++k) {
    SceneParts copy = parts;
    copy.render.lightSampling = kinds[k];
    means[k] = meanOf(render(Scene(std::move(copy))));
  }
  for (int k = 1; k < 3; ++k) {
    EXPECT_NEAR(means[k].r / means[0].r, 1, 0.03) << k;
    EXPECT_NEAR(means[k].g / means[0].g, 1, 0.03) << k;
    EXPECT_NEAR(means[k].b / means[0].b, 1, 0.03) << k;
  }
}

// MIS, light sampling alone and BRDF sampling alone estimate the same image: on a scene with a
// small bright emitter, a large dim one and an image sky over a diffuse floor and a glossy ball,
// their means over a 16×16 image at 256 samples agree within 3 %.
TEST(PathIntegrator, MisAndEachStrategyAloneConvergeToTheSameImage) {
  SceneParts parts = cameraParts(16, 16);
  parts.camera.position = {0, 1.5, 5};
  parts.camera.direction = normalize(Vec3{0, -0.3, -1});
  parts.image.samples = 256;
  parts.environment = skyWithSun(32, 16, 0.1f, 50, 10, 3, 2);
  Material glossy = diffuse(Color(0.1, 0.2, 0.4));
  glossy.ks = Color(0.5);
  glossy.shininess = 40;
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}),
                                addMaterial(parts, diffuse(Color(0.6))), Color{});
  parts.primitives.emplace_back(Sphere::make({0.6, 0.5, -0.5}, 0.5), addMaterial(parts, glossy),
                                Color{});
  const std::uint32_t dark = addMaterial(parts, diffuse(Color(0)));
  parts.primitives.emplace_back(Sphere::make({-1.2, 1.4, 0}, 0.3), dark, Color(40, 36, 30));
  parts.primitives.emplace_back(Rectangle::make({-2, 3, -2}, {4, 0, 0}, {0, 0, 4}), dark,
                                Color(0.5, 0.55, 0.6));
  expectEachStrategyAgreesWithMis(parts);
}

// A 12×12 view from (0, 2, 6) down onto a diffuse floor (kd 0.6) at y = 0, 1024 samples, and a
// black material for emitters (index returned in `dark`): the stage of the emitter tests below.
SceneParts floorForEmitters(std::uint32_t& dark) {
  SceneParts parts = cameraParts(12, 12);
  parts.camera.position = {0, 2, 6};
  parts.camera.direction = normalize(Vec3{0, -0.35, -1});
  parts.image.samples = 1024;
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}),
                                addMaterial(parts, diffuse(Color(0.6))), Color{});
  dark = addMaterial(parts, diffuse(Color(0)));
  return parts;
}

// The same agreement for the emitters sampled by their surfaces' areas beyond triangles and
// spheres: a rotated box, a capped cylinder under a similarity, a cone frustum and an ellipse
// (a disk under a non-uniform scale) light a diffuse floor; a wrong area or density in any of
// them would part light sampling from BRDF sampling.
TEST(PathIntegrator, BoxesCylindersConesAndEllipsesAreSampledAsLights) {
  std::uint32_t dark = 0;
  SceneParts parts = floorForEmitters(dark);
  Matrix4 turn = Matrix4::identity();  // 90° about y, scaled by 0.5, moved up
  turn.m[0][2] = 0.5;
  turn.m[2][0] = -0.5;
  turn.m[0][0] = turn.m[2][2] = 0;
  turn.m[1][1] = 0.5;
  turn.m[1][3] = 1.5;
  parts.primitives.emplace_back(Box::make({-1.5, 0.2, -0.5}, {-1, 0.6, 0}), dark, Color(6, 5, 4),
                                Transform(Matrix4::identity()));
  parts.primitives.emplace_back(Cylinder::make({2, 0, 0}, {0, 1, 0}, 0.3, 1), dark, Color(4, 6, 5),
                                Transform(turn));
  parts.primitives.emplace_back(Cone::make({0.5, 1.5, -1.5}, 0.3, {0.5, 2.2, -1.5}, 0.1), dark,
                                Color(8, 4, 6));
  Matrix4 squash = Matrix4::identity();
  squash.m[0][0] = 2;
  squash.m[2][2] = 0.5;
  parts.primitives.emplace_back(Disk::make({0, 3, -0.5}, {0, -1, 0}, 0.4), dark, Color(3, 3, 3),
                                Transform(squash));
  ASSERT_NE(Scene(SceneParts(parts)).emitterSampler(), nullptr);
  ASSERT_EQ(Scene(SceneParts(parts)).emitterSampler()->size(), 12u + 3 + 1 + 1);
  expectEachStrategyAgreesWithMis(parts);
}

// Emissive objects inside instanced groups are sampled as lights too, each placed by its instance:
// a sphere and a rectangle in one group placed twice (once under a similarity, where the sphere
// stays a sphere and is sampled; once under a non-uniform scale, where it is an ellipsoid and is
// left to BRDF sampling), and a two-triangle emissive mesh in another. The three strategies agree.
TEST(PathIntegrator, EmittersInsideInstancesAreSampledAsLights) {
  std::uint32_t dark = 0;
  SceneParts parts = floorForEmitters(dark);
  GroupParts lamps;
  lamps.primitives.emplace_back(Sphere::make({0, 0, 0}, 0.25), dark, Color(10, 8, 6));
  lamps.primitives.emplace_back(Rectangle::make({-0.3, 0.6, -0.3}, {0.6, 0, 0}, {0, 0, 0.6}), dark,
                                Color(2, 3, 4));
  GroupParts panel;
  TriangleMesh mesh;
  mesh.positions = {{-0.4, 0, -0.4}, {0.4, 0, -0.4}, {0.4, 0, 0.4}, {-0.4, 0, 0.4}};
  mesh.indices = {0, 2, 1, 0, 3, 2};
  mesh.materialIndex = dark;
  mesh.emission = Color(3, 5, 3);
  panel.meshes.push_back(mesh);
  parts.groups = {lamps, panel};
  const Transform similar = Transform::translate({-1.2, 1.2, -0.5}) *
                            Transform::rotate({1, 1, 0}, 30) * Transform::scale(1.5, 1.5, 1.5);
  const Transform stretched = Transform::translate({1.3, 1, -1}) * Transform::scale(1, 2, 0.7);
  const Transform overhead = Transform::translate({0, 3, -0.5}) * Transform::rotate({1, 0, 0}, 20);
  parts.instances = {makeInstance(&similar, 0), makeInstance(&stretched, 0),
                     makeInstance(&overhead, 1)};
  const Scene scene{SceneParts(parts)};
  ASSERT_NE(scene.emitterSampler(), nullptr);
  // Sphere + 2 rectangle triangles, 2 rectangle triangles (the ellipsoid left out), 2 triangles.
  EXPECT_EQ(scene.emitterSampler()->size(), 3u + 2 + 2);
  expectEachStrategyAgreesWithMis(parts);
}

// Under `path` an area light is a surface camera rays and mirror rays see, of radiance colour ×
// intensity; under Whitted it is invisible (the background shows).
TEST(PathIntegrator, AreaLightsAreSeenByCameraAndMirrorRays) {
  const auto scene = [](Integrator integrator, bool mirror) {
    SceneParts parts = cameraParts(4, 4);
    parts.render.integrator = integrator;
    parts.background = Color(0.1, 0.1, 0.1);
    AreaLight lamp;
    lamp.shape = AreaShape::Disk;
    lamp.center = {0, 0, mirror ? 5.0 : -5.0};
    lamp.normal = {0, 0, 1};
    lamp.radius = 50;  // fills the view
    lamp.intensity = Color(2, 3, 4);
    parts.lights.push_back(lamp);
    if (mirror) {
      // A mirror across the view at z = −5 reflects the lamp behind the camera.
      Material chrome;
      chrome.kd = Color(0);
      chrome.kr = Color(0.5);
      parts.primitives.emplace_back(Plane::make({0, 0, -5}, {0, 0, 1}), addMaterial(parts, chrome),
                                    Color{});
    }
    return Scene(std::move(parts));
  };
  const Film seen = render(scene(Integrator::Path, false));
  for (const Color& c : seen.pixels()) EXPECT_EQ(c, Color(2, 3, 4));
  const Film unseen = render(scene(Integrator::Whitted, false));
  for (const Color& c : unseen.pixels()) EXPECT_EQ(c, Color(0.1, 0.1, 0.1));
  const Film mirrored = render(scene(Integrator::Path, true));
  for (const Color& c : mirrored.pixels()) EXPECT_EQ(c, Color(1, 1.5, 2));
}

// Materials written for Whitted's model may reflect and transmit more than they receive (kd + kr
// = 1.4 here): past the lights' direct term the path integrator scales the lobes to a sum of 1, so
// a convex object under a uniform sky L renders exactly L (not 1.4·L, nor more with each bounce).
TEST(PathIntegrator, ASurfaceNeverPassesOnMoreLightThanItReceives) {
  const Color background(0.5, 0.7, 0.9);
  SceneParts parts = cameraParts(16, 16);
  parts.background = background;
  parts.image.samples = 16;
  Material bright = diffuse(Color(0.5, 0.5, 0.5));
  bright.kr = Color(0.9, 0.9, 0.9);
  parts.primitives.emplace_back(Sphere::make({0, 0, -5}, 10), addMaterial(parts, bright), Color{});
  parts.camera.position = {0, 0, 30};
  parts.camera.viewPlaneWidth = parts.camera.viewPlaneHeight = 0.2;
  const Film film = render(Scene(std::move(parts)));
  for (const Color& c : film.pixels()) {
    EXPECT_NEAR(c.r, background.r, 1e-12);
    EXPECT_NEAR(c.g, background.g, 1e-12);
    EXPECT_NEAR(c.b, background.b, 1e-12);
  }
}

// A diffuse floor under an area light behind a clear slab (kt 1, ior 1): the direct term already
// carries the lamp's light through the slab (its shadow rays keep kt per crossing), so a diffuse
// bounce that passes the slab must not find the lamp again. The path integrator gives the Whitted
// integrator's image to the bit (the background is black and nothing else is lit), also for a
// floor whose kd + ks is above 1 (its direct term is Whitted's, unscaled).
TEST(PathIntegrator, AnAreaLightBehindClearGlassIsCountedOnce) {
  for (const double ks : {0.0, 0.7}) {
    const auto scene = [ks](Integrator integrator) {
      SceneParts parts = cameraParts(12, 9);
      parts.camera.direction = {0, -1, 0};  // looking down at the floor, away from the slab
      parts.camera.up = {0, 0, -1};
      parts.image.samples = 4;
      parts.render.integrator = integrator;
      Material floor = diffuse(Color(0.7, 0.6, 0.5));
      floor.ks = Color(ks, ks, ks);
      floor.shininess = 20;
      parts.primitives.emplace_back(Plane::make({0, -1, 0}, {0, 1, 0}), addMaterial(parts, floor),
                                    Color{});
      Material clear;
      clear.kt = Color(1, 1, 1);
      parts.primitives.emplace_back(Box::make({-50, 1, -50}, {50, 1.1, 50}),
                                    addMaterial(parts, clear), Color{});
      AreaLight lamp;
      lamp.shape = AreaShape::Rectangle;
      lamp.corner = {-2, 3, -2};
      lamp.edge1 = {4, 0, 0};
      lamp.edge2 = {0, 0, 4};
      lamp.intensity = Color(1.5, 1.5, 1.5);
      lamp.samples = 4;
      parts.lights.push_back(lamp);
      return Scene(std::move(parts));
    };
    const Film whitted = render(scene(Integrator::Whitted));
    const Film path = render(scene(Integrator::Path));
    ASSERT_EQ(whitted.pixels().size(), path.pixels().size());
    double lit = 0;
    for (std::size_t k = 0; k < whitted.pixels().size(); ++k) {
      EXPECT_EQ(whitted.pixels()[k], path.pixels()[k]) << "ks " << ks << " pixel " << k;
      lit += whitted.pixels()[k].r;
    }
    EXPECT_GT(lit, 0) << "the lamp lights nothing";
  }
}

}  // namespace
}  // namespace glint
