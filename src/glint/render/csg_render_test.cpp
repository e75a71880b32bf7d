// CSG objects in rendered images: a union of disjoint solids is the solids themselves (the same
// bytes, under both integrators), a cut face shades with its flipped normal, and csg scenes render
// the same on any thread count.
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "glint/factories/scene_loader.h"
#include "glint/render/render_test_support.h"
#include "glint/render/renderer.h"

namespace glint {
namespace {

Scene sceneOf(const std::string& text) {
  LoadedScene loaded = loadSceneFromString(text, "test.yaml");
  return Scene(std::move(loaded.parts));
}

// Two spheres on a floor under a point light and a mirror-ish material, with `objects` placed.
std::string twoSphereScene(const std::string& integrator, const std::string& objects) {
  return "camera: {position: [0, 1, 6], look_at: [0, 0.5, 0], fov: 40}\n"
         "image: {width: 40, height: 30, samples: 2}\n"
         "render: {integrator: " +
         integrator +
         ", max_depth: 4}\n"
         "background: [0.2, 0.3, 0.4]\n"
         "ambient: {color: [1, 1, 1], intensity: 0.1}\n"
         "materials:\n"
         "  shiny: {kd: [0.6, 0.3, 0.2], ks: 0.4, shininess: 30, kr: 0.3}\n"
         "  floor: {kd: 0.7}\n"
         "objects:\n"
         "  - {type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: floor}\n" +
         objects +
         "lights:\n"
         "  - {type: point, position: [3, 5, 4], color: [1, 1, 1], intensity: 1}\n";
}

TEST(CsgRender, AUnionOfDisjointSpheresRendersTheSameBytesAsTheSpheres) {
  for (const std::string integrator : {"whitted", "path"}) {
    const Scene separate = sceneOf(twoSphereScene(
        integrator,
        "  - {type: sphere, center: [-1, 0.8, 0], radius: 0.8, material: shiny}\n"
        "  - {type: sphere, center: [1.1, 0.6, 0.5], radius: 0.6, material: shiny}\n"));
    const Scene combined =
        sceneOf(twoSphereScene(integrator,
                               "  - type: csg\n"
                               "    operation: union\n"
                               "    material: shiny\n"
                               "    operands:\n"
                               "      - {type: sphere, center: [-1, 0.8, 0], radius: 0.8}\n"
                               "      - {type: sphere, center: [1.1, 0.6, 0.5], radius: 0.6}\n"));
    const Film a = render(separate);
    const Film b = render(combined);
    ASSERT_EQ(a.pixels().size(), b.pixels().size());
    int lit = 0;
    for (std::size_t i = 0; i < a.pixels().size(); ++i) {
      ASSERT_EQ(a.pixels()[i], b.pixels()[i]) << integrator << " pixel " << i;
      lit += a.pixels()[i].r > 0.25 ? 1 : 0;
    }
    EXPECT_GT(lit, 100) << integrator;  // the spheres are in view
  }
}

TEST(CsgRender, TheCutFaceOfASphereMinusABoxFacesOutOfTheCut) {
  // Seen from +z under a light travelling −z: the hemisphere's flat top (the box's face z = 0,
  // normal −z, flipped to +z) shows kd·(n·l) = kd exactly; beside it the background.
  const Scene scene = sceneOf(
      "camera: {position: [0, 0, 5], direction: [0, 0, -1], fov: 30}\n"
      "image: {width: 21, height: 21, encoding: linear}\n"
      "background: [0, 0, 1]\n"
      "objects:\n"
      "  - type: csg\n"
      "    operation: difference\n"
      "    material: {kd: [0.5, 0.25, 0.125], ka: 0}\n"
      "    operands:\n"
      "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
      "      - {type: box, min: [-2, -2, 0], max: [2, 2, 2]}\n"
      "lights:\n"
      "  - {type: directional, direction: [0, 0, -1], color: [1, 1, 1], intensity: 1}\n");
  const Film film = render(scene);
  for (const auto& [x, y] : {std::pair{10, 10}, std::pair{7, 12}, std::pair{13, 9}}) {
    EXPECT_EQ(film.at(x, y), Color(0.5, 0.25, 0.125)) << x << ", " << y;
  }
  EXPECT_EQ(film.at(0, 0), Color(0, 0, 1));
  // From below the sphere's own surface faces the camera, away from the light: black.
  const Scene below = sceneOf(
      "camera: {position: [0, 0, -5], direction: [0, 0, 1], fov: 30}\n"
      "image: {width: 21, height: 21, encoding: linear}\n"
      "objects:\n"
      "  - type: csg\n"
      "    operation: difference\n"
      "    material: {kd: 0.5, ka: 0}\n"
      "    operands:\n"
      "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
      "      - {type: box, min: [-2, -2, 0], max: [2, 2, 2]}\n"
      "lights:\n"
      "  - {type: directional, direction: [0, 0, -1], color: [1, 1, 1], intensity: 1}\n");
  EXPECT_EQ(render(below).at(10, 10), Color(0));
}

TEST(CsgRender, ShadowsThroughAGlassLensCountEachSurfaceOnce) {
  // A lens (two spheres' intersection) of kt 0.5 between a point light and a floor point: the
  // shadow ray crosses its surface twice, so the floor behind it gets 0.25 of the light.
  const Scene scene = sceneOf(
      "camera: {position: [0, 5, 0.001], look_at: [0, 0, 0], fov: 10}\n"
      "image: {width: 3, height: 3, encoding: linear}\n"
      "objects:\n"
      "  - {type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: {kd: 1, ka: 0}}\n"
      "  - type: csg\n"
      "    operation: intersection\n"
      "    material: {kt: 0.5}\n"
      "    operands:\n"
      "      - {type: sphere, center: [0, 1, 0], radius: 1}\n"
      "      - {type: sphere, center: [0, 2, 0], radius: 1}\n"
      "lights:\n"
      "  - {type: point, position: [0, 10, 0], color: [1, 1, 1], intensity: 1}\n");
  Hit hit;
  const Ray down{{0, 5, 0}, {0, -1, 0}};
  ASSERT_TRUE(scene.intersect(down, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 3);  // the lens' top (the lower sphere's cap), outward +y
  EXPECT_EQ(hit.normal, Normal3(0, 1, 0));
  EXPECT_EQ(scene.transmittance(Ray{{0, 0, 0}, {0, 1, 0}}, 10), Color(0.25));
  EXPECT_EQ(scene.transmittance(Ray{{0, 0, 0}, {0, 1, 0}}, 1.5), Color(0.5));
}

TEST(CsgRender, CsgScenesRenderTheSameOnAnyThreadCount) {
  const Scene scene = sceneOf(twoSphereScene(
      "path",
      "  - type: csg\n"
      "    operation: difference\n"
      "    material: shiny\n"
      "    operands:\n"
      "      - {type: box, min: [-1, 0, -1], max: [1, 2, 1]}\n"
      "      - {type: sphere, center: [0, 1, 0], radius: 1.3, material: {kd: [0, 0.5, 0]}}\n"
      "      - {type: cylinder, base: [0, 1, -2], axis: [0, 0, 1], radius: 0.4, height: 4}\n"));
  EXPECT_TRUE(testing::rendersTheSameOnAnyThreadCountAndTileSize(scene));
}

}  // namespace
}  // namespace glint
