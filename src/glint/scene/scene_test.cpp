// Scene construction: settings carried over, camera sized from the image, material checks, and the
// two queries on a small built scene.
#include "glint/scene/scene.h"

#include <gtest/gtest.h>

namespace glint {
namespace {

// A kt 0.6 glass sphere of radius 1 at the origin (material 1) above an opaque floor y = −2.
SceneParts glassSphereParts() {
  SceneParts parts;
  parts.name = "glass";
  Material glass;
  glass.kt = Color(0.6);
  parts.materials.push_back(glass);
  parts.primitives.emplace_back(Sphere::make({0, 0, 0}, 1), 1, Color());
  parts.primitives.emplace_back(Plane::make({0, -2, 0}, {0, 1, 0}), 0, Color(0.1, 0.2, 0.3));
  parts.lights.push_back(PointLight{{0, 0, 10}, Color(1), {}});
  parts.ambient = Color(0.05);
  parts.background = Color(0.2, 0.3, 0.4);
  parts.camera.position = {0, 0, 5};
  parts.camera.viewPlaneWidth = 2;
  parts.camera.viewPlaneHeight = 1;
  parts.camera.viewPlaneDistance = 1;
  parts.camera.imageWidth = 99;  // overwritten from the image settings
  parts.image.width = 4;
  parts.image.height = 3;
  parts.image.samples = 9;
  parts.render.maxDepth = 3;
  return parts;
}

TEST(SceneTest, CarriesSettingsAndSizesTheCamera) {
  const Scene scene(glassSphereParts());
  EXPECT_EQ(scene.name(), "glass");
  EXPECT_EQ(scene.primitives().size(), 2u);
  EXPECT_EQ(scene.materials().size(), 2u);
  EXPECT_EQ(scene.lights().size(), 1u);
  EXPECT_EQ(scene.ambient(), Color(0.05));
  EXPECT_EQ(scene.background(), Color(0.2, 0.3, 0.4));
  EXPECT_EQ(scene.image().samples, 9);
  EXPECT_EQ(scene.render().maxDepth, 3);
  EXPECT_EQ(scene.camera().imageWidth(), 4);
  EXPECT_EQ(scene.camera().imageHeight(), 3);
  EXPECT_EQ(scene.materialOf(0).kt, Color(0.6));
  EXPECT_EQ(scene.materialOf(1).kt, Color(0));
  EXPECT_EQ(scene.primitives()[1].emission(), Color(0.1, 0.2, 0.3));
}

TEST(SceneTest, IntersectAndShadowTransmittance) {
  const Scene scene(glassSphereParts());
  Hit hit;
  // The camera's centre ray (4×3 image: the centre lies between pixels, so aim directly).
  ASSERT_TRUE(scene.intersect({{0, 0, 5}, {0, 0, -1}}, kInfinity, hit));
  EXPECT_EQ(hit.primitive, 0u);
  EXPECT_NEAR(hit.t, 4, 1e-12);
  EXPECT_NEAR(hit.normal.z, 1, 1e-12);
  EXPECT_FALSE(scene.intersect({{0, 0, 5}, {0, 0, -1}}, 3.5, hit));

  // A shadow ray through the sphere crosses it twice: 0.6² = 0.36 in every channel.
  const Ray shadow{{0, 0, -5}, {0, 0, 1}};
  const Color through = scene.transmittance(shadow, 15);
  EXPECT_NEAR(through.r, 0.36, 1e-15);
  EXPECT_EQ(through.r, through.g);
  EXPECT_EQ(through.g, through.b);
  // Ending inside the sphere: one crossing.
  EXPECT_NEAR(scene.transmittance(shadow, 5).g, 0.6, 1e-15);
  // Down through sphere and the opaque floor: black; stopping above the floor: 0.36.
  const Ray down{{0, 3, 0}, {0, -1, 0}};
  EXPECT_EQ(scene.transmittance(down, 10), Color(0));
  EXPECT_NEAR(scene.transmittance(down, 4.5).b, 0.36, 1e-15);
  // Beside the sphere: nothing in the way.
  EXPECT_EQ(scene.transmittance({{1.5, 0, -5}, {0, 0, 1}}, kInfinity), Color(1));
}

TEST(SceneTest, BadMaterialIndexThrows) {
  SceneParts parts = glassSphereParts();
  parts.primitives.emplace_back(Sphere::make({3, 0, 0}, 1), 2, Color());
  EXPECT_THROW(Scene{std::move(parts)}, std::invalid_argument);

  parts = glassSphereParts();
  parts.materials.clear();
  try {
    const Scene scene(std::move(parts));
    ADD_FAILURE() << "material index past an empty material list accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("material"), std::string::npos) << e.what();
  }
}

TEST(SceneTest, InvalidCameraPropagates) {
  SceneParts parts = glassSphereParts();
  parts.camera.up = {0, 0, 1};
  parts.camera.direction = {0, 0, -1};
  EXPECT_THROW(Scene{std::move(parts)}, CameraError);
  parts = glassSphereParts();
  parts.image.height = 0;
  EXPECT_THROW(Scene{std::move(parts)}, CameraError);
}

}  // namespace
}  // namespace glint
