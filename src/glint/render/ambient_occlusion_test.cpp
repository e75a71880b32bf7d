// render.ambient_occlusion (DESIGN.md §10): the ambient term scaled by the cosine-weighted fraction
// of the hemisphere that is open up to the occlusion distance, checked against the analytic value
// for a point on a plane beside a sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "glint/geometry/shape.h"
#include "glint/render/render_test_support.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

// A plane y = 0 lit by ambient light alone (white, ka = 1, kd = 0): a point sees ka·Ia times its
// open fraction. The camera looks straight down from y = 50 at a 9×9 view of [-9, 9]² (unused by
// traceRay tests).
SceneParts ambientPlaneParts(int samples, double distance) {
  SceneParts parts;
  parts.camera.position = {0, 50, 0};
  parts.camera.direction = {0, -1, 0};
  parts.camera.up = {0, 0, -1};
  parts.camera.viewPlaneWidth = 18.0 / 50;
  parts.camera.viewPlaneHeight = 18.0 / 50;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = 9;
  parts.image.height = 9;
  parts.image.encoding = Encoding::Linear;
  parts.background = Color(0.2, 0.3, 0.4);
  parts.ambient = Color(1, 1, 1);
  Material matte;
  matte.kd = Color(0);
  matte.ka = Color(1);
  parts.materials.push_back(matte);
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), 1u, Color{});
  parts.render.ambientOcclusion = AmbientOcclusion{samples, distance};
  return parts;
}

// The open fraction (cosine-weighted) at a point of the plane at distance r from where a sphere of
// radius R touches it: the sphere covers a cap of half-angle α, sin α = R/D (D = √(r² + R²)),
// whose axis makes the angle θ with the normal, cos θ = R/D; θ + α = 90°, so the cap lies wholly
// above the horizon and its projected solid angle is π·sin²α·cos θ. Open: 1 − (R/D)³.
double openFraction(double r, double radius) {
  const double ratio = radius / std::hypot(r, radius);
  return 1 - ratio * ratio * ratio;
}

Color seenStraightDownAt(const Scene& scene, double x, std::uint64_t key = 0) {
  Rng rng(key);
  return traceRay(scene, Ray{{x, 20, 0.25}, {0, -1, 0}}, rng);
}

TEST(AmbientOcclusion, APlaneAloneIsUnchanged) {
  SceneParts with = ambientPlaneParts(64, 1e9);
  SceneParts without = with;
  without.render.ambientOcclusion.reset();
  const Film a = render(Scene(std::move(with)));
  const Film b = render(Scene(std::move(without)));
  ASSERT_EQ(a.pixels().size(), b.pixels().size());
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    EXPECT_EQ(a.pixels()[i], b.pixels()[i]) << i;
    EXPECT_EQ(a.pixels()[i], Color(1, 1, 1)) << i;
  }
}

// A smooth coarse mesh with nothing near it keeps all its ambient light: the directions about its
// tilted shading normals that fall below a face are folded back above it, not counted as blocked.
TEST(AmbientOcclusion, ASmoothMeshAloneIsUnchanged) {
  SceneParts parts = ambientPlaneParts(64, 1e9);
  parts.primitives.clear();
  parts.meshes.push_back(testing::smoothIcosahedron({0, 0, 0}, 8, 1));
  const Film film = render(Scene(std::move(parts)));
  std::size_t onMesh = 0;
  for (const Color& c : film.pixels()) {
    if (c == Color(0.2, 0.3, 0.4)) continue;  // the background beside it
    ++onMesh;
    EXPECT_EQ(c, Color(1, 1, 1));
  }
  EXPECT_GT(onMesh, 40u);
}

TEST(AmbientOcclusion, BesideASphereTheContactRingDarkensAsTheAnalyticValueSays) {
  constexpr double kRadius = 1;
  SceneParts parts = ambientPlaneParts(4096, 1e9);
  parts.primitives.emplace_back(Sphere::make({0, kRadius, 0.25}, kRadius), 1u, Color{});
  const Scene scene(std::move(parts));
  double previous = 0;
  for (const double r : {8.0, 4.0, 2.0, 1.5, 1.2, 1.05}) {
    const Color c = seenStraightDownAt(scene, r);
    // 4096 stratified cosine-weighted directions: the estimate is within 0.5 % of the fraction.
    EXPECT_NEAR(c.r, openFraction(r, kRadius), 0.005) << "r = " << r;
    EXPECT_EQ(c.r, c.g);
    EXPECT_EQ(c.r, c.b);
    // Monotonic toward the contact point: every step closer is darker.
    if (previous > 0) {
      EXPECT_LT(c.r, previous) << "r = " << r;
    }
    previous = c.r;
  }
}

TEST(AmbientOcclusion, OnlyOccludersWithinTheDistanceCount) {
  // From the plane point at r = 1.05 the sphere is at least √(1.05² + 1) − 1 ≈ 0.45 away: rays of
  // length 1e-3 meet nothing, and the point is as open as on the plane alone.
  SceneParts nearOnly = ambientPlaneParts(1024, 1e-3);
  nearOnly.primitives.emplace_back(Sphere::make({0, 1, 0.25}, 1), 1u, Color{});
  const Scene scene(std::move(nearOnly));
  EXPECT_EQ(seenStraightDownAt(scene, 1.05), Color(1, 1, 1));
}

TEST(AmbientOcclusion, GlassOccludesByItsTransmittance) {
  // Shadow-style rays: a sphere with kt = 0.5 (no reflection) lets half of its share through.
  constexpr double kRadius = 1;
  SceneParts parts = ambientPlaneParts(4096, 1e9);
  Material glass;
  glass.kd = Color(0);
  glass.ka = Color(0);
  glass.kt = Color(0.5);
  parts.materials.push_back(glass);
  parts.primitives.emplace_back(Sphere::make({0, kRadius, 0.25}, kRadius), 2u, Color{});
  const Scene scene(std::move(parts));
  // Each ray toward the sphere crosses it twice: transmittance 0.25.
  const double occluded = 1 - openFraction(2, kRadius);
  EXPECT_NEAR(seenStraightDownAt(scene, 2).r, 1 - 0.75 * occluded, 0.005);
}

TEST(AmbientOcclusion, TheSameBytesForAnyThreadCountAndTheWorkEstimateCountsItsRays) {
  SceneParts parts = ambientPlaneParts(32, 1e9);
  parts.primitives.emplace_back(Sphere::make({0, 1, 0}, 1), 1u, Color{});
  parts.image.width = 24;
  parts.image.height = 24;
  parts.image.samples = 2;
  const Scene scene(std::move(parts));
  EXPECT_TRUE(testing::rendersTheSameOnAnyThreadCountAndTileSize(scene));
  const PixelWork work =
      estimatePixelWork(scene.image(), scene.render(), scene.lights(), scene.materials());
  EXPECT_EQ(work.shadowRaysPerHit, 32u);
}

}  // namespace
}  // namespace glint
