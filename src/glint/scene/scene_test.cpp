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

// A unit square (two triangles) at z = −2 facing +z with material 2 and an emission, beside the
// glass sphere scene.
SceneParts meshParts() {
  SceneParts parts = glassSphereParts();
  Material red;
  red.kd = Color(0.8, 0.1, 0.1);
  parts.materials.push_back(red);
  TriangleMesh square;
  square.positions = {{3, -1, -2}, {5, -1, -2}, {5, 1, -2}, {3, 1, -2}};
  square.indices = {0, 1, 2, 0, 2, 3};
  square.materialIndex = 2;
  square.emission = Color(0.25, 0.5, 1);
  parts.meshes.push_back(square);
  return parts;
}

TEST(SceneTest, MaterialAndEmissionOfMeshAndPrimitiveHits) {
  const Scene scene(meshParts());
  ASSERT_EQ(scene.meshes().size(), 1u);
  Hit hit;
  ASSERT_TRUE(scene.intersect({{4, 0.5, 5}, {0, 0, -1}}, kInfinity, hit));
  EXPECT_EQ(hit.mesh, 0u);
  EXPECT_NEAR(hit.t, 7, 1e-12);
  EXPECT_EQ(&scene.materialOf(hit), &scene.materials()[2]);
  EXPECT_EQ(scene.materialOf(hit).kd, Color(0.8, 0.1, 0.1));
  EXPECT_EQ(scene.emissionOf(hit), Color(0.25, 0.5, 1));

  ASSERT_TRUE(scene.intersect({{0, 0, 5}, {0, 0, -1}}, kInfinity, hit));
  EXPECT_EQ(hit.mesh, kNoMesh);
  EXPECT_EQ(hit.primitive, 0u);
  EXPECT_EQ(scene.materialOf(hit).kt, Color(0.6));
  EXPECT_EQ(scene.emissionOf(hit), Color());
  ASSERT_TRUE(scene.intersect({{0, 0, -5}, {0, -1, 0}}, kInfinity, hit));
  EXPECT_EQ(hit.primitive, 1u);
  EXPECT_EQ(scene.emissionOf(hit), Color(0.1, 0.2, 0.3));
  // The mesh's material is opaque: a shadow ray through the square is blocked.
  EXPECT_EQ(scene.transmittance({{4, 0, -5}, {0, 0, 1}}, kInfinity), Color(0));
  EXPECT_EQ(scene.transmittance({{4, 0, -5}, {0, 0, 1}}, 2.5), Color(1));
}

TEST(SceneTest, MeshTransmissionComesFromItsMaterial) {
  SceneParts parts = meshParts();
  parts.materials[2].kt = Color(0.5, 0.25, 1);
  parts.acceleration = Acceleration::BruteForce;
  const Scene scene(std::move(parts));
  EXPECT_EQ(scene.aggregate().acceleration(), Acceleration::BruteForce);
  // Off the shared diagonal (a ray through it may cross both triangles).
  EXPECT_EQ(scene.transmittance({{4.5, -0.2, -5}, {0, 0, 1}}, kInfinity), Color(0.5, 0.25, 1));
}

TEST(SceneTest, BadMeshesThrow) {
  SceneParts parts = meshParts();
  parts.meshes[0].materialIndex = 3;
  try {
    const Scene scene(std::move(parts));
    ADD_FAILURE() << "a mesh material index past the materials was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "mesh 0 uses material 3, but the scene has only 3 materials");
  }
  parts = meshParts();
  parts.meshes[0].indices[4] = 4;
  EXPECT_THROW(Scene{std::move(parts)}, std::invalid_argument);
}

}  // namespace
}  // namespace glint
