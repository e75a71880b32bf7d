// The object family's table (DESIGN.md §8): adding a shape is one factory function and one table
// row. A test-only `cube` (center, size), given to the builder as an extra row, is read, checked
// and rendered like any built-in shape — the same pixels as the box it stands for — and its keys
// get the unknown-key, missing-key and range messages of every other shape, with nothing else
// changed.
#include "glint/factories/object_factories.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "glint/factories/build_context.h"
#include "glint/factories/scene_builder.h"
#include "glint/factories/scene_test_support.h"
#include "glint/readers/yaml_scene_reader.h"
#include "glint/render/renderer.h"

namespace glint {
namespace {

using ::testing::HasSubstr;

// The factory: its keys, their checks, the geometry.
std::optional<ObjectGeometry> readCube(ParameterDictionary& params) {
  const auto center = params.point3("center", Presence::Required);
  const auto size = readPositive(params, "size", Presence::Required);
  if (!center || !size) return std::nullopt;
  const Vec3 half(*size / 2, *size / 2, *size / 2);
  return Shape(Box::make(center->value - half, center->value + half));
}

// The table row.
const ObjectFactory kCube{"cube", {"center", "size"}, readCube};

BuildResult buildWithCube(const std::string& text) {
  const ParseResult parsed = parseScene(text, "cube.yaml");
  EXPECT_FALSE(parsed.hasErrors()) << parsed.diagnostics[0].format();
  BuildOptions options;
  options.extraObjectFactories = {kCube};
  return buildScene(parsed.description, options);
}

constexpr const char* kScene =
    "camera: {position: [3, 2, 4], look_at: [0, 0, 0], fov: 40}\n"
    "image: {width: 24, height: 16}\n"
    "lights: [{type: point, position: [5, 5, 5]}]\n"
    "objects:\n";

TEST(ObjectFactories, AShapeAddedByOneFactoryAndOneRowRendersLikeWhatItStandsFor) {
  BuildResult cube = buildWithCube(std::string(kScene) +
                                   "  - {type: cube, center: [0, 0.5, 0], size: 2,\n"
                                   "     material: {kd: [0.8, 0.3, 0.1]}}\n");
  ASSERT_FALSE(cube.hasErrors()) << cube.diagnostics[0].format();
  ASSERT_EQ(cube.parts.primitives.size(), 1u);
  BuildResult box = buildWithCube(std::string(kScene) +
                                  "  - {type: box, min: [-1, -0.5, -1], max: [1, 1.5, 1],\n"
                                  "     material: {kd: [0.8, 0.3, 0.1]}}\n");
  ASSERT_FALSE(box.hasErrors());
  RenderOptions oneThread;
  oneThread.threads = 1;
  const Film cubeFilm = render(Scene(std::move(cube.parts)), oneThread);
  const Film boxFilm = render(Scene(std::move(box.parts)), oneThread);
  ASSERT_EQ(cubeFilm.pixels().size(), boxFilm.pixels().size());
  int lit = 0;
  for (std::size_t i = 0; i < cubeFilm.pixels().size(); ++i) {
    EXPECT_EQ(cubeFilm.pixels()[i], boxFilm.pixels()[i]) << "pixel " << i;
    lit += isBlack(cubeFilm.pixels()[i]) ? 0 : 1;
  }
  EXPECT_GT(lit, 50);  // the cube is in the picture
}

TEST(ObjectFactories, TheAddedShapeGetsEveryMessageOfTheBuiltInOnes) {
  const auto errorsOf = [](const std::string& object) {
    return buildWithCube(std::string(kScene) + "  - " + object + "\n").diagnostics;
  };
  std::vector<Diagnostic> errors = errorsOf("{type: cube, center: [0, 0, 0], size: -1}");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].format(), "cube.yaml:5:43: cube.size must be > 0, got -1");
  errors = errorsOf("{type: cube, center: [0, 0, 0], sise: 1}");
  ASSERT_EQ(errors.size(), 1u);  // the misspelling, not also the missing size
  EXPECT_EQ(errors[0].message,
            "unknown key 'sise' in cube; expected one of: center, size, material, emission, "
            "transform (did you mean 'size'?)");
  errors = errorsOf("{type: cube, size: 1}");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].message, "cube is missing required key 'center'");
  errors = errorsOf("{type: cub, size: 1}");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_THAT(errors[0].message,
              HasSubstr("disk, cone, mesh, csg, instance, cube (did you mean 'cube'?)"));
  // Transforms, materials and emission come with every object type.
  BuildResult moved = buildWithCube(std::string(kScene) +
                                    "  - {type: cube, center: [0, 0, 0], size: 1, emission: "
                                    "[1, 0, 0], transform: [{translate: [0, 3, 0]}]}\n");
  ASSERT_FALSE(moved.hasErrors());
  EXPECT_EQ(moved.parts.primitives.at(0).emission(), Color(1, 0, 0));
  EXPECT_NEAR(moved.parts.primitives.at(0).bounds().lo.y, 2.5, 1e-9);
}

TEST(ObjectFactories, TheTableListsEveryBuiltInTypeOnce) {
  std::vector<std::string_view> types;
  for (const ObjectFactory& f : objectFactories()) {
    EXPECT_EQ(std::count(types.begin(), types.end(), f.type), 0) << f.type;
    types.push_back(f.type);
    EXPECT_NE(f.read, nullptr) << f.type;
    EXPECT_EQ(findObjectFactory(f.type), &f);
  }
  EXPECT_EQ(types.size(), 12u);
  EXPECT_EQ(findObjectFactory("cube"), nullptr);
  const std::vector<ObjectFactory> extra = {kCube};
  EXPECT_EQ(findObjectFactory("cube", extra)->type, "cube");
}

}  // namespace
}  // namespace glint
