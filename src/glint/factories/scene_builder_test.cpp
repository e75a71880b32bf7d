// Scene building (DESIGN.md §5, §7): SceneDescription → SceneParts values, colour decoding under
// both encodings, transforms, normalisation, range checks at the value's place, shape errors at the
// object's place, the image size limits, and warnings.
#include "glint/factories/scene_builder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "glint/factories/scene_loader.h"
#include "glint/factories/scene_test_support.h"
#include "glint/geometry/csg.h"
#include "glint/mesh/mesh_file.h"
#include "glint/readers/yaml_scene_reader.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"

namespace glint {
namespace {

using testing::errorsOf;
using testing::expectOneError;
using ::testing::HasSubstr;
using testing::kDesignExample;
using testing::kMinimal;

// A description made by hand, as a reader of another format would make it: values added to the
// tree with their places, entities pointing at their mappings.
class HandMade {
 public:
  explicit HandMade(const std::string& file) { d.addFile(file, "."); }
  SceneDescription d;
  ValueTree& tree() { return d.files[0]->values; }
  static TextPosition at(std::uint32_t line, std::uint32_t column) {
    return {line * 1000 + column, line, column};
  }
  // A mapping of scalar keys and values, each value at its own place (line, column).
  struct Entry {
    std::string key;
    std::vector<std::string> value;  // one scalar, or the items of a list
    std::uint32_t line = 0, column = 0;
  };
  ValueId map(std::uint32_t line, std::uint32_t column, const std::vector<Entry>& entries) {
    const ValueId id = tree().open(ValueKind::Map, at(line, column));
    for (const Entry& e : entries) {
      tree().addScalar(e.key, at(e.line, e.column > 1 ? e.column - 1 : 1));
      if (e.value.size() == 1) {
        tree().addScalar(e.value[0], at(e.line, e.column));
      } else {
        tree().open(ValueKind::List, at(e.line, e.column));
        for (const std::string& item : e.value) tree().addScalar(item, at(e.line, e.column + 1));
        tree().close();
      }
    }
    tree().close();
    return id;
  }
  void entity(EntityKind kind, ValueId value, std::string_view type = {}) {
    Entity e;
    e.kind = kind;
    e.value = value;
    e.place = value;
    if (!type.empty()) {
      for (std::size_t i = 0; i < tree().size(value); ++i) {
        if (tree().scalar(tree().key(value, i)) == "type") e.type = tree().value(value, i);
      }
    }
    d.entities.push_back(e);
  }
};

// Loads a scene that must be valid.
SceneParts partsOf(const std::string& text) {
  try {
    return loadSceneFromString(text, "test.yaml").parts;
  } catch (const SceneError& e) {
    ADD_FAILURE() << e.what();
    return {};
  }
}

void expectNear(const Point3& a, const Point3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
  EXPECT_NEAR(a.z, b.z, 1e-12);
}

void expectNear(const Vec3& a, const Vec3& b) { expectNear(toPoint(a), toPoint(b)); }

void expectNear(const Color& a, const Color& b) {
  EXPECT_NEAR(a.r, b.r, 1e-15);
  EXPECT_NEAR(a.g, b.g, 1e-15);
  EXPECT_NEAR(a.b, b.b, 1e-15);
}

TEST(SceneBuilder, DesignExampleBuildsTheExpectedParts) {
  const LoadedScene loaded = loadSceneFromString(kDesignExample, "scene.yaml");
  EXPECT_TRUE(loaded.warnings.empty());
  const SceneParts& p = loaded.parts;
  EXPECT_EQ(p.name, "basic render");
  expectNear(p.background, Color(srgbToLinear(0x4b / 255.0), srgbToLinear(0x7f / 255.0),
                                 srgbToLinear(0x5a / 255.0)));
  EXPECT_EQ(p.ambient, Color(1, 0.75, 0.75));

  EXPECT_EQ(p.camera.position, (Point3{0, 0, 0}));
  EXPECT_EQ(p.camera.direction, (Vec3{0, 0, -1}));
  EXPECT_EQ(p.camera.up, (Vec3{0, 1, 0}));
  EXPECT_EQ(p.camera.viewPlaneWidth, 500);
  EXPECT_EQ(p.camera.viewPlaneHeight, 500);
  EXPECT_EQ(p.camera.viewPlaneDistance, 100);
  EXPECT_EQ(p.camera.fovDegrees, 0);
  EXPECT_EQ(p.camera.aperture, 0);
  EXPECT_EQ(p.camera.imageWidth, 1000);
  EXPECT_EQ(p.camera.imageHeight, 1000);

  EXPECT_EQ(p.image.width, 1000);
  EXPECT_EQ(p.image.height, 1000);
  EXPECT_EQ(p.image.samples, 1);
  EXPECT_EQ(p.image.encoding, Encoding::Srgb);
  ASSERT_TRUE(p.image.grid);
  EXPECT_EQ(p.image.grid->interval, 100);
  expectNear(p.image.grid->color, Color(1, 1, 0));

  EXPECT_EQ(p.render.maxDepth, 10);
  EXPECT_EQ(p.render.minWeight, 0.001);
  EXPECT_EQ(p.render.blurSamples, 16);
  EXPECT_EQ(p.render.seed, 0u);

  ASSERT_EQ(p.materials.size(), 3u);  // default, glass, the triangle's inline material
  const Material& glass = p.materials[1];
  EXPECT_EQ(glass.kd, Color(0.1));
  EXPECT_EQ(glass.ks, Color(0.8));
  EXPECT_EQ(glass.shininess, 200);
  EXPECT_EQ(glass.kt, Color(0.9));
  EXPECT_EQ(glass.kr, Color(0));
  EXPECT_EQ(glass.ka, Color(1));
  EXPECT_EQ(glass.ior, 1.5);
  const Material& inlined = p.materials[2];
  EXPECT_EQ(inlined.kd, Color(0.5));
  EXPECT_EQ(inlined.ks, Color(0.5));
  EXPECT_EQ(inlined.shininess, 60);
  EXPECT_EQ(inlined.ior, 1);

  ASSERT_EQ(p.primitives.size(), 2u);
  const Sphere& sphere = std::get<Sphere>(p.primitives[0].shape());
  EXPECT_EQ(sphere.center, (Point3{0, 0, -100}));
  EXPECT_EQ(sphere.radius, 50);
  EXPECT_EQ(p.primitives[0].materialIndex(), 1u);
  EXPECT_EQ(p.primitives[0].emission(), Color());
  const Triangle& triangle = std::get<Triangle>(p.primitives[1].shape());
  EXPECT_EQ(triangle.v0, (Point3{-100, 0, -100}));
  EXPECT_EQ(triangle.v1, (Point3{0, 100, -100}));
  EXPECT_EQ(triangle.v2, (Point3{-100, 100, -100}));
  EXPECT_EQ(p.primitives[1].materialIndex(), 2u);
  EXPECT_EQ(p.primitives[1].emission(), Color(1, 0, 0));

  ASSERT_EQ(p.lights.size(), 1u);
  const SpotLight& spot = std::get<SpotLight>(p.lights[0]);
  EXPECT_EQ(spot.position, (Point3{-50, -50, 50}));
  expectNear(spot.direction, Vec3{1, 1, -2} / std::sqrt(6.0));
  EXPECT_EQ(spot.intensity, Color(1, 0.6, 0));
  EXPECT_EQ(spot.attenuation.kc, 1);
  EXPECT_EQ(spot.attenuation.kl, 0.00001);
  EXPECT_EQ(spot.attenuation.kq, 0.00000001);
  EXPECT_EQ(spot.exponent, 1);

  // The parts make a scene.
  const Scene scene(p);
  EXPECT_EQ(scene.primitives().size(), 2u);
}

TEST(SceneBuilder, HexColorsDecodeUnderTheImageEncoding) {
  // The encoding is given after the colours: it must still decide how they decode.
  const std::string scene =
      "background: \"#4b7f5a\"\n"
      "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1, emission: \"#FF8000\"}\n"
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n";
  const SceneParts linear = partsOf(scene + "image: {width: 4, height: 3, encoding: linear}\n");
  EXPECT_EQ(linear.background, Color(75 / 255.0, 127 / 255.0, 90 / 255.0));
  EXPECT_EQ(linear.primitives.at(0).emission(), Color(1, 128 / 255.0, 0));

  const SceneParts srgb = partsOf(scene + "image: {width: 4, height: 3}\n");
  EXPECT_EQ(srgb.background,
            Color(srgbToLinear(75 / 255.0), srgbToLinear(127 / 255.0), srgbToLinear(90 / 255.0)));
  EXPECT_EQ(srgb.primitives.at(0).emission(), Color(1, srgbToLinear(128 / 255.0), 0));
  // [r, g, b] is linear under either encoding, and may exceed 1.
  EXPECT_EQ(partsOf(std::string(kMinimal) + "background: [0.25, 2, 0]\n").background,
            Color(0.25, 2, 0));
  // Colour-valued material keys and emission take a number, [r, g, b] or "#rrggbb" alike
  // (DESIGN.md §9).
  const std::string material =
      "materials: {m: {kd: \"#804000\", ks: 0.25, ka: [0.5, 0.25, 0]}}\n"
      "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1, material: m, emission: 0.5}\n"
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n";
  for (const bool isLinear : {true, false}) {
    const SceneParts parts =
        partsOf(material + (isLinear ? "image: {width: 4, height: 3, encoding: linear}\n"
                                     : "image: {width: 4, height: 3}\n"));
    const auto decode = [&](int code) {
      return isLinear ? code / 255.0 : srgbToLinear(code / 255.0);
    };
    const Material& m = parts.materials.at(parts.primitives.at(0).materialIndex());
    EXPECT_EQ(m.kd, Color(decode(128), decode(64), 0));
    EXPECT_EQ(m.ks, Color(0.25));
    EXPECT_EQ(m.ka, Color(0.5, 0.25, 0));
    EXPECT_EQ(parts.primitives.at(0).emission(), Color(0.5));
  }
}

// A material's `emission` (DESIGN.md §9: a colour-valued material key) is the emission of every
// object that names the material and gives none of its own: named or inline, a colour or a
// texture, on shapes, meshes and csg operands; an object's own emission replaces it.
TEST(SceneBuilder, AMaterialsEmissionIsItsObjectsEmission) {
  const std::string scene =
      std::string(kMinimal) +
      "textures: {glow: {type: checker, colors: [[1, 0, 0], [0, 0, 1]]}}\n"
      "materials:\n  lamp: {kd: 0.2, emission: [2, 1, 0.5]}\n  neon: {emission: glow}\n"
      "objects:\n"
      "  - {type: sphere, center: [0, 0, -5], radius: 1, material: lamp}\n"
      "  - {type: sphere, center: [3, 0, -5], radius: 1, material: lamp, emission: 0.25}\n"
      "  - {type: sphere, center: [6, 0, -5], radius: 1, material: {emission: \"#ff0000\"}}\n"
      "  - {type: sphere, center: [9, 0, -5], radius: 1, material: neon}\n"
      "  - {type: sphere, center: [12, 0, -5], radius: 1, material: neon, emission: [0, 1, 0]}\n"
      "  - {type: sphere, center: [15, 0, -5], radius: 1}\n"
      "  - {type: csg, operation: union, operands: [{type: sphere, center: [0, 5, -5], radius: "
      "1, material: lamp}, {type: sphere, center: [1, 5, -5], radius: 1}]}\n";
  const SceneParts p = partsOf(scene);
  ASSERT_EQ(p.primitives.size(), 7u);
  EXPECT_EQ(p.primitives[0].emission(), Color(2, 1, 0.5));
  EXPECT_EQ(p.materials[p.primitives[0].materialIndex()].kd, Color(0.2));
  EXPECT_EQ(p.primitives[1].emission(), Color(0.25));
  EXPECT_EQ(p.primitives[2].emission(), Color(1, 0, 0));
  const auto emissionTexture = [&](const Primitive& primitive) {
    const Material& m = p.materials[primitive.materialIndex()];
    return m.textures == kUntextured ? kNoTexture : p.materialTextures[m.textures].emission;
  };
  // A textured emission: the constant 1, the texture in the material's bindings.
  EXPECT_EQ(p.primitives[3].emission(), Color(1));
  EXPECT_NE(emissionTexture(p.primitives[3]), kNoTexture);
  // The object's own colour replaces the material's texture.
  EXPECT_EQ(p.primitives[4].emission(), Color(0, 1, 0));
  EXPECT_EQ(emissionTexture(p.primitives[4]), kNoTexture);
  EXPECT_EQ(p.primitives[5].emission(), Color());
  // The csg's first operand glows with its material's emission, the second not at all.
  const Csg& csg = std::get<Csg>(p.primitives[6].shape());
  const auto emissionOfOperand = [&](std::size_t i) { return csg.tree->operands.at(i).emission; };
  EXPECT_EQ(emissionOfOperand(0), Color(2, 1, 0.5));
  EXPECT_EQ(emissionOfOperand(1), Color());
  // An instance's material override changes its objects' materials, not their emission: a
  // material with an emission is refused there rather than half applied.
  expectOneError(std::string(kMinimal) +
                     "materials:\n  lamp: {emission: 1}\n"
                     "groups:\n  g: [{type: sphere, center: [0, 0, 0], radius: 1}]\n"
                     "objects:\n  - {type: instance, group: g, material: lamp}\n",
                 8, 42, "instance.material: this material has an emission");
}

TEST(SceneBuilder, DefaultsForOptionalKeys) {
  const SceneParts p = partsOf(std::string(kMinimal) +
                               "ambient: {intensity: 0.5}\n"
                               "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1}\n"
                               "lights:\n  - {type: point, position: [0, 5, 0]}\n");
  EXPECT_EQ(p.name, "test.yaml");
  EXPECT_EQ(p.background, Color());
  EXPECT_EQ(p.ambient, Color(0.5));
  EXPECT_EQ(p.image.samples, 1);
  EXPECT_EQ(p.image.encoding, Encoding::Srgb);
  EXPECT_FALSE(p.image.grid);
  EXPECT_EQ(p.render.maxDepth, 10);
  EXPECT_EQ(p.render.minWeight, 0.001);
  EXPECT_EQ(p.render.blurSamples, 16);
  EXPECT_EQ(p.camera.up, (Vec3{0, 1, 0}));
  EXPECT_EQ(p.camera.fovDegrees, 40);
  ASSERT_EQ(p.materials.size(), 1u);
  EXPECT_EQ(p.primitives.at(0).materialIndex(), 0u);
  const Material& m = p.materials[0];
  EXPECT_EQ(m.kd, Color(0));
  EXPECT_EQ(m.ka, Color(1));
  EXPECT_EQ(m.ior, 1);
  const PointLight& light = std::get<PointLight>(p.lights.at(0));
  EXPECT_EQ(light.intensity, Color(1));
  EXPECT_EQ(light.attenuation.kc, 1);
  EXPECT_EQ(light.attenuation.kl, 0);
  EXPECT_EQ(light.attenuation.kq, 0);
}

TEST(SceneBuilder, DirectionsAreNormalised) {
  const SceneParts p = partsOf(
      "camera: {position: [1, 2, 3], look_at: [1, 2, -7], up: [0, 3, 0], fov: 40}\n"
      "image: {width: 4, height: 3}\n"
      "objects:\n"
      "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 4]}\n"
      "  - {type: disk, center: [0, 0, 0], normal: [3, 0, 4], radius: 1}\n"
      "  - {type: cylinder, base: [0, 0, 0], axis: [0, 0.5, 0], radius: 1, height: 2}\n"
      "  - {type: tube, origin: [0, 0, 0], axis: [-2, 0, 0], radius: 1}\n"
      "lights:\n"
      "  - {type: directional, direction: [0, -10, 0]}\n"
      "  - {type: spot, position: [0, 0, 0], direction: [2, 2, 1]}\n");
  EXPECT_EQ(p.camera.direction, (Vec3{0, 0, -1}));
  EXPECT_EQ(p.camera.up, (Vec3{0, 1, 0}));
  ASSERT_EQ(p.primitives.size(), 4u);
  EXPECT_EQ(std::get<Plane>(p.primitives[0].shape()).normal, Normal3(0, 0, 1));
  const Normal3 diskNormal = std::get<Disk>(p.primitives[1].shape()).normal;
  expectNear(Vec3{diskNormal.x, diskNormal.y, diskNormal.z}, Vec3{0.6, 0, 0.8});
  expectNear(std::get<Cylinder>(p.primitives[2].shape()).axis, Vec3{0, 1, 0});
  EXPECT_EQ(std::get<Cylinder>(p.primitives[2].shape()).height, 2);
  expectNear(std::get<Tube>(p.primitives[3].shape()).axis, Vec3{-1, 0, 0});
  EXPECT_EQ(std::get<DirectionalLight>(p.lights.at(0)).direction, (Vec3{0, -1, 0}));
  expectNear(std::get<SpotLight>(p.lights.at(1)).direction, Vec3{2, 2, 1} / 3.0);
}

TEST(SceneBuilder, TransformsApplyInFileOrder) {
  // translate then scale: x ↦ 2(x + 1), so the unit sphere's box [-1, 1] becomes [0, 4].
  const SceneParts p = partsOf(std::string(kMinimal) +
                               "objects:\n"
                               "  - type: sphere\n"
                               "    center: [0, 0, 0]\n"
                               "    radius: 1\n"
                               "    transform: [{translate: [1, 0, 0]}, {scale: 2}]\n"
                               "  - type: sphere\n"
                               "    center: [2, 0, 0]\n"
                               "    radius: 0.5\n"
                               "    transform: [{rotate: {axis: [0, 0, 5], angle: 90}},\n"
                               "                {scale: [1, 3, 1]}]\n"
                               "  - {type: sphere, center: [0, 0, 0], radius: 1,\n"
                               "     transform: [{translate: [0, 0, 0]}]}\n");
  ASSERT_EQ(p.primitives.size(), 3u);
  const Bounds3 a = p.primitives[0].bounds();
  expectNear(a.lo, Point3{0, -2, -2});
  expectNear(a.hi, Point3{4, 2, 2});
  // Rotating (2, 0, 0) by 90° about +z gives (0, 2, 0); the scale then stretches y by 3.
  const Bounds3 b = p.primitives[1].bounds();
  expectNear(b.lo, Point3{-0.5, 4.5, -0.5});
  expectNear(b.hi, Point3{0.5, 7.5, 0.5});
  // An identity transform changes nothing.
  expectNear(p.primitives[2].bounds().lo, Point3{-1, -1, -1});
}

TEST(SceneBuilder, PlaneFromThreePoints) {
  const SceneParts p =
      partsOf(std::string(kMinimal) +
              "objects:\n  - {type: plane, points: [[0, 0, 1], [1, 0, 1], [0, 1, 1]]}\n");
  const Plane& plane = std::get<Plane>(p.primitives.at(0).shape());
  EXPECT_EQ(plane.normal, Normal3(0, 0, 1));
}

TEST(SceneBuilder, ValuesOutOfRangeAtTheValue) {
  struct Case {
    std::string text;  // appended to kMinimal
    int line, column;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {"objects:\n  - {type: sphere, center: [0, 0, 0], radius: -2}\n", 4, 47,
       "sphere.radius must be > 0, got -2"},
      {"objects:\n  - {type: cylinder, base: [0, 0, 0], axis: [0, 1, 0], radius: 1, height: 0}\n",
       4, 75, "cylinder.height must be > 0, got 0"},
      {"materials: {m: {kd: -1}}\n", 3, 21, "materials.m.kd must be >= 0, got -1"},
      {"materials: {m: {ks: [0.5, -1, 0]}}\n", 3, 21,
       "materials.m.ks must be >= 0, got [0.5, -1, 0]"},
      {"materials: {m: {kr: -0.1}}\n", 3, 21, "materials.m.kr must be >= 0"},
      {"materials: {m: {kt: -0.1}}\n", 3, 21, "materials.m.kt must be >= 0"},
      {"materials: {m: {ka: -0.1}}\n", 3, 21, "materials.m.ka must be >= 0"},
      {"materials: {m: {shininess: -1}}\n", 3, 28, "materials.m.shininess must be >= 0"},
      {"materials: {m: {ior: 0}}\n", 3, 22, "materials.m.ior must be > 0, got 0"},
      {"materials: {m: {reflection_blur: -5}}\n", 3, 34, "reflection_blur must be >= 0"},
      {"objects:\n  - {type: disk, center: [0, 0, 0], normal: [0, 0, 1], radius: 1,\n"
       "     material: {kd: -2}}\n",
       5, 21, "disk.material.kd must be >= 0, got -2"},
      {"lights:\n  - {type: point, position: [0, 0, 0], intensity: -1}\n", 4, 51,
       "point light.intensity must be >= 0, got -1"},
      {"lights:\n  - {type: point, position: [0, 0, 0], attenuation: [1, -1, 0]}\n", 4, 53,
       "point light.attenuation components must be >= 0"},
      {"lights:\n  - {type: point, position: [0, 0, 0], attenuation: [0, 0, 0]}\n", 4, 53,
       "point light.attenuation must not be all 0"},
      {"lights:\n  - {type: spot, position: [0, 0, 0], direction: [0, 0, 1], exponent: -1}\n", 4,
       71, "spot light.exponent must be >= 0"},
      {"lights:\n  - {type: directional, direction: [0, 0, 1], color: [1, -1, 1]}\n", 4, 54,
       "directional light.color components must be >= 0"},
      {"render: {max_depth: 0}\n", 3, 21, "render.max_depth must be between 1 and 1000, got 0"},
      {"render: {min_weight: -0.5}\n", 3, 22, "render.min_weight must be >= 0, got -0.5"},
      {"render: {blur_samples: 0}\n", 3, 24, "render.blur_samples must be between 1 and 65536"},
      {"render: {blur_samples: 65537}\n", 3, 24, "render.blur_samples must be between 1 and 65536"},
      {"background: [-1, 0, 0]\n", 3, 13, "background components must be >= 0, got [-1, 0, 0]"},
      {"ambient: {color: [1, 1, 1], intensity: -1}\n", 3, 40, "ambient.intensity must be >= 0"},
      {"objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, emission: [0, -1, 0]}\n", 4, 60,
       "sphere.emission must be >= 0, got [0, -1, 0]"},
      {"objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, emission: -1}\n", 4, 60,
       "sphere.emission must be >= 0, got -1"},
      {"background: {type: sky, top: [0, 0, 1], bottom: [1, 1, 1], top_value: 1, bottom_value: "
       "1}\n",
       3, 71, "background.top_value and background.bottom_value must differ, got 1 and 1"},
      {"background: {type: sky, top: [0, 0, 1], bottom: [1, 1, 1], along: up}\n", 3, 67,
       "background.along must be direction or height, got 'up'"},
      {"background: {type: sky, top: [0, 0, 1], bottom: [1, 1, 1], up: [0, 0, 0]}\n", 3, 64,
       "background.up must be non-zero"},
      {"background: {type: sky, top: [0, 0, 1], bottom: [1, 1, 1], bottom_value: .nan}\n", 3, 74,
       "background.bottom_value must be a finite number, got .nan"},
      // The one error of a background mapping without a type (not also "unknown key 'zenith'
      // ... expected one of:" with nothing after it).
      {"background: {zenith: [0, 0, 1]}\n", 3, 13, "background is missing required key 'type'"},
      {"materials: {m: {kd: \"#12345\"}}\n", 3, 21,
       "materials.m.kd: expected a color \"#rrggbb\" with 6 hexadecimal digits"},
  };
  for (const Case& c : cases)
    expectOneError(std::string(kMinimal) + c.text, c.line, c.column, c.fragment);
}

TEST(SceneBuilder, ImageAndCameraRanges) {
  const std::string camera = "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n";
  expectOneError(camera + "image: {width: 0, height: 3}\n", 2, 16,
                 "image.width must be between 1 and 65535, got 0");
  expectOneError(camera + "image: {width: 4, height: 65536}\n", 2, 27,
                 "image.height must be between 1 and 65535, got 65536");
  expectOneError(camera + "image: {width: 4, height: 3, samples: 0}\n", 2, 39,
                 "image.samples must be between 1 and 65536, got 0");
  expectOneError(camera + "image: {width: 4, height: 3, samples: 65537}\n", 2, 39,
                 "image.samples must be between 1 and 65536");
  expectOneError(camera + "image: {width: 4, height: 3, grid: {interval: 0}}\n", 2, 47,
                 "image.grid.interval must be >= 1, got 0");
  expectOneError(camera + "image: {width: 4, height: 3, grid: {interval: 2147483648}}\n", 2, 47,
                 "image.grid.interval must be at most 2147483647 (the largest integer glint "
                 "keeps), got 2147483648");
  const std::string image = "image: {width: 4, height: 3}\n";
  expectOneError("camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 180}\n" + image, 1, 59,
                 "camera.fov must be in (0, 180) degrees, got 180");
  expectOneError("camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 0}\n" + image, 1, 59,
                 "camera.fov must be in (0, 180)");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1],\n"
      "         view_plane: {width: 0, height: 1, distance: 1}}\n" +
          image,
      2, 30, "camera.view_plane.width must be > 0, got 0");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40, aperture: -1}\n" + image, 1,
      73, "camera.aperture must be >= 0");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40, aperture: 0.5}\n" + image, 1,
      73, "camera.focus_distance is required when camera.aperture > 0");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40, aperture: 0.5,\n"
      "         focus_distance: 0}\n" +
          image,
      2, 26, "camera.focus_distance must be > 0");
  const SceneParts lens = partsOf(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40, aperture: 0.5,\n"
      "         focus_distance: 7}\n" +
      image);
  EXPECT_EQ(lens.camera.aperture, 0.5);
  EXPECT_EQ(lens.camera.focusDistance, 7);
}

TEST(SceneBuilder, ZeroLengthDirectionsAreErrors) {
  const std::string image = "image: {width: 4, height: 3}\n";
  expectOneError("camera: {position: [0, 0, 0], direction: [0, 0, 0], fov: 40}\n" + image, 1, 42,
                 "camera.direction must be non-zero, got [0, 0, 0]");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, 1], up: [0, 0, 0], fov: 40}\n" + image, 1,
      57, "camera.up must be non-zero");
  expectOneError("camera: {position: [1, 2, 3], look_at: [1, 2, 3], fov: 40}\n" + image, 1, 40,
                 "camera.look_at must differ from camera.position");
  expectOneError(
      std::string(kMinimal) +
          "objects:\n  - {type: disk, center: [0, 0, 0], normal: [0, 0, 0], radius: 1}\n",
      4, 45, "disk.normal must be non-zero, got [0, 0, 0]");
  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: tube, origin: [0, 0, 0], axis: [0, 0, 0], radius: 1}\n",
                 4, 43, "tube.axis must be non-zero");
  expectOneError(std::string(kMinimal) + "lights:\n  - {type: directional, direction: [0, 0, 0]}\n",
                 4, 36, "directional light.direction must be non-zero");
  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1,\n"
                     "     transform: [{rotate: {axis: [0, 0, 0], angle: 30}}]}\n",
                 5, 34, "sphere.transform[0].rotate.axis must be non-zero");
  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1,\n"
                     "     transform: [{scale: [1, 0, 1]}]}\n",
                 5, 26, "sphere.transform[0].scale factors must be non-zero, got [1, 0, 1]");
}

TEST(SceneBuilder, UpParallelToTheViewDirection) {
  const std::string image = "image: {width: 4, height: 3}\n";
  // Reported at `up` when given, else at the direction that meets the default up.
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, 1], up: [0, 0, -3], fov: 40}\n" + image, 1,
      57, "camera.up [0, 0, -3] is parallel to the view direction");
  expectOneError("camera: {position: [0, 0, 0], direction: [0, 2, 0], fov: 40}\n" + image, 1, 42,
                 "is parallel to the view direction");
}

TEST(SceneBuilder, UndefinedMaterialIsNamed) {
  expectOneError(std::string(kMinimal) +
                     "materials: {glass: {kt: 1}}\n"
                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: glas}\n",
                 5, 60, "undefined material 'glas' (did you mean 'glass'?)");
  expectOneError(
      std::string(kMinimal) +
          "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: steel}\n",
      4, 60, "undefined material 'steel'; no materials are defined");
}

// Names are the scene's text: the list of defined names in an undefined-name error is cut to ten
// and escaped (a name of terminal escape codes printed them raw), a name past 256 bytes is an
// error where it is defined, and an undefined one that long is shortened in the message (an alias
// of a megabyte name, used at every object, kept a megabyte per error).
TEST(SceneBuilder, NamesInErrorsAreFewShortAndEscaped) {
  std::string materials = "materials:\n  \"red\\e[2J\": {kd: 1}\n";
  for (int i = 0; i < 14; ++i) materials += fmt::format("  m{:02}: {{kd: 1}}\n", i);
  expectOneError(std::string(kMinimal) + materials +
                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: "
                     "steel}\n",
                 20, 60,
                 "undefined material 'steel'; defined: m00, m01, m02, m03, m04, m05, m06, m07, "
                 "m08, m09 and 5 more");
  expectOneError(std::string(kMinimal) + materials +
                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: "
                     "red}\n",
                 20, 60, "undefined material 'red'; defined: m00, m01");
  expectOneError(std::string(kMinimal) + "materials:\n  \"red\\e[2J\": {kd: 1}\n" +
                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: "
                     "rod}\n",
                 6, 60, "undefined material 'rod'; defined: red\\x1b[2J");
  const std::string longName(300, 'n');
  expectOneError(
      std::string(kMinimal) + "materials:\n  " + longName + ": {kd: 1}\n", 4, 3,
      "material name 'nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn...' is 300 bytes long, more "
      "than the limit of 256");
  const std::vector<Diagnostic> errors = errorsOf(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, " +
      "material: " + longName + "}\n  - {type: instance, group: " + longName + "}\n");
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].message,
            "sphere.material: undefined material "
            "'nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn...'; names are at most 256 "
            "bytes");
  EXPECT_EQ(errors[1].message,
            "instance.group: undefined group "
            "'nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn...'; names are at most 256 bytes");
}

// Points past ±1e100 are errors at the value; objects that sizes or transforms carry past it at
// the object (the tests multiply up to three coordinates: beyond, a product overflows and the
// object vanished from the image without a word).
TEST(SceneBuilder, TheSceneMustLieWithinReachOfTheOrigin) {
  const std::string objects = std::string(kMinimal) + "objects:\n  - ";
  expectOneError(objects + "{type: sphere, center: [0, 0, -2e155], radius: 1}\n", 4, 28,
                 "sphere.center must lie within ±1e+100 of the origin, got [0, 0, -2e+155]");
  expectOneError(objects + "{type: sphere, center: [0, 0, 0], radius: 1e150}\n", 4, 5,
                 "objects[0] (sphere): the object reaches 1e+150 from the origin, beyond the "
                 "±1e+100 glint computes in");
  expectOneError(objects +
                     "{type: sphere, center: [0, 0, 0], radius: 1, transform: [{scale: "
                     "1e30}, {translate: [0, 0, 2e100]}]}\n",
                 4, 5, "objects[0] (sphere): the object reaches 2e+100 from the origin");
  expectOneError(objects + "{type: triangle, vertices: [[0, 0, 0], [1, 0, 0], [0, 1e101, 0]]}\n", 4,
                 55, "triangle.vertices[2] must lie within ±1e+100 of the origin");
  expectOneError(std::string(kMinimal) +
                     "lights:\n  - {type: point, position: [0, 1e300, 0], color: [1, 1, 1]}\n",
                 4, 29, "point light.position must lie within ±1e+100 of the origin");
  expectOneError(
      "camera: {position: [0, 0, 1e300], look_at: [0, 0, 0], fov: 40}\n"
      "image: {width: 4, height: 3}\n",
      1, 20, "camera.position must lie within ±1e+100 of the origin");
  // Up to the limit, and an unbounded plane anywhere within it.
  EXPECT_EQ(loadSceneFromString(objects + "{type: sphere, center: [0, 0, -2e99], radius: 1e99}\n"
                                          "  - {type: plane, point: [0, 0, -1e100], normal: [0, 0, "
                                          "1]}\n",
                                "near.yaml")
                .parts.primitives.size(),
            2u);
}

TEST(SceneBuilder, DegenerateShapesAtTheKeyTheyName) {
  // The factory's refusal is reported at the value of the key it names, else at the object.
  const auto expectShapeError = [](const std::string& object, const std::string& key,
                                   const std::string& fragment) {
    const std::string line = "  - " + object;
    const int column = static_cast<int>(key.empty() ? 5 : line.find(key + ": ") + key.size() + 3);
    expectOneError(std::string(kMinimal) +
                       "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1}\n" + line + "\n",
                   5, column, fragment);
  };
  expectShapeError("{type: triangle, vertices: [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}", "vertices",
                   "objects[1] (triangle).vertices");
  expectShapeError("{type: polygon, vertices: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]]}",
                   "vertices", "objects[1] (polygon)");
  expectShapeError("{type: polygon, vertices: [[0, 0, 0], [2, 0, 0], [1, 0.2, 0], [1, 2, 0]]}",
                   "vertices", "objects[1] (polygon)");
  expectShapeError("{type: rectangle, corner: [0, 0, 0], edges: [[1, 0, 0], [1, 1, 0]]}", "edges",
                   "objects[1] (rectangle).edges");
  expectShapeError("{type: quadrangle, vertices: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]]}",
                   "vertices", "objects[1] (quadrangle)");
  expectShapeError("{type: plane, points: [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}", "points",
                   "objects[1] (plane)");
  expectShapeError("{type: box, min: [0, 0, 0], max: [1, 0, 1]}", "min", "objects[1] (box)");
}

TEST(SceneBuilder, BuildsHandMadeDescriptions) {
  HandMade made("made.yaml");
  // Complete entities missing required parts are reported by the builder itself.
  BuildResult r = buildScene(made.d);
  ASSERT_EQ(r.diagnostics.size(), 2u);
  EXPECT_THAT(r.diagnostics[0].message, HasSubstr("missing required key 'image'"));
  EXPECT_THAT(r.diagnostics[1].message, HasSubstr("missing required key 'camera'"));

  const auto scene = [](const std::string& radius) {
    HandMade m("made.yaml");
    m.entity(EntityKind::ImageEntity,
             m.map(1, 1, {{"width", {"640"}, 2, 3}, {"height", {"480"}, 3, 3}}));
    m.entity(EntityKind::CameraEntity, m.map(4, 1,
                                             {{"position", {"0", "0", "0"}, 5, 3},
                                              {"direction", {"0", "0", "-2"}, 6, 3},
                                              {"fov", {"60"}, 7, 3}}));
    m.entity(EntityKind::ObjectEntity,
             m.map(8, 1,
                   {{"type", {"sphere"}, 8, 9},
                    {"center", {"0", "0", "-5"}, 8, 30},
                    {"radius", {radius}, 9, 13}}),
             "sphere");
    return m;
  };
  HandMade bad = scene("-1");
  r = buildScene(bad.d);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(), "made.yaml:9:13: sphere.radius must be > 0, got -1");

  HandMade good = scene("2");
  r = buildScene(good.d);
  EXPECT_FALSE(r.hasErrors());
  EXPECT_EQ(r.parts.camera.direction, (Vec3{0, 0, -1}));
  EXPECT_EQ(r.parts.camera.imageWidth, 640);
  ASSERT_EQ(r.parts.primitives.size(), 1u);
}

TEST(SceneBuilder, ImageSizeLimits) {
  // Ranges, then the film against the memory budget, then the camera-ray cap.
  EXPECT_EQ(checkRenderSize(1000, 1000, 16, std::uint64_t{1} << 30), std::nullopt);
  EXPECT_THAT(checkRenderSize(0, 10, 1).value_or(""), HasSubstr("between 1 and 65535"));
  EXPECT_THAT(checkRenderSize(10, 10, 65537).value_or(""), HasSubstr("between 1 and 65536"));
  const std::optional<std::string> film = checkRenderSize(1000, 1000, 1, std::uint64_t{1} << 20);
  ASSERT_TRUE(film);
  EXPECT_THAT(*film, HasSubstr("needs 22.9 MiB for its film"));
  EXPECT_THAT(*film, HasSubstr("budget of 1.0 MiB"));
  const std::optional<std::string> rays =
      checkRenderSize(65535, 65535, 65536, std::numeric_limits<std::uint64_t>::max());
  ASSERT_TRUE(rays);
  EXPECT_THAT(*rays, HasSubstr("camera rays"));
  EXPECT_EQ(filmBytes(65535, 65535), std::uint64_t{65535} * 65535 * sizeof(Color));
  EXPECT_EQ(formatBytes(512), "512 B");
  EXPECT_EQ(formatBytes(1536), "1.5 KiB");
  EXPECT_EQ(formatCount(1.1e12), "1.1 trillion");
  EXPECT_GT(physicalMemoryBytes(), 0u);
  EXPECT_EQ(defaultImageMemoryBudget(), physicalMemoryBytes() / 2);

  ImageSettings image;
  image.width = 2000;
  image.height = 1000;
  image.samples = 4;
  EXPECT_EQ(checkImageSettings(image, std::uint64_t{1} << 30), std::nullopt);
  image.samples = 0;
  EXPECT_TRUE(checkImageSettings(image, std::uint64_t{1} << 30));
}

TEST(SceneBuilder, HugeImageRefusedBeforeAllocation) {
  // Through the builder with a small budget: the error points at the image mapping.
  const ParseResult parsed = parseScene(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image:\n  width: 2000\n  height: 1000\n",
      "big.yaml");
  ASSERT_FALSE(parsed.hasErrors());
  const BuildResult built =
      buildScene(parsed.description, BuildOptions{.imageMemoryBudget = std::uint64_t{16} << 20});
  ASSERT_EQ(built.diagnostics.size(), 1u);
  EXPECT_EQ(built.diagnostics[0].format(),
            "big.yaml:3:3: image: an image of 2000 × 1000 pixels needs 45.8 MiB for its film, more "
            "than the memory budget of 16.0 MiB");

  // Through the loader with the default budget (half the physical memory). 65535² pixels need
  // 96 GiB of film; only a machine with more than 192 GiB would accept it.
  if (filmBytes(65535, 65535) <= defaultImageMemoryBudget()) {
    GTEST_SKIP() << "this machine has enough memory for a 65535 × 65535 film";
  }
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image: {width: 65535, height: 65535}\n",
      2, 8, "needs 96.0 GiB for its film");
  // The ray cap applies whatever the memory.
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image: {width: 20000, height: 20000, samples: 4096}\n",
      2, 8, "camera rays");
}

TEST(SceneBuilder, Warnings) {
  const LoadedScene dark = loadSceneFromString(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1}\n",
      "dark.yaml");
  ASSERT_EQ(dark.warnings.size(), 1u);
  EXPECT_EQ(dark.warnings[0].severity, Diagnostic::Severity::Warning);
  EXPECT_THAT(dark.warnings[0].format(),
              HasSubstr("dark.yaml:1:1: warning: the scene has no lights"));

  const LoadedScene off =
      loadSceneFromString(std::string(kMinimal) +
                              "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1, "
                              "material: {kd: 1}}\n"
                              "lights:\n"
                              "  - {type: point, position: [0, 0, 0]}\n"
                              "  - {type: point, position: [0, 0, 0], intensity: 0}\n"
                              "  - {type: directional, direction: [0, 0, 1], color: [0, 0, 0]}\n",
                          "off.yaml");
  ASSERT_EQ(off.warnings.size(), 2u);
  EXPECT_EQ(off.warnings[0].format(),
            "off.yaml:7:5: warning: point light has zero intensity; it lights nothing");
  EXPECT_EQ(off.warnings[1].where.line, 8);
  EXPECT_EQ(off.parts.lights.size(), 3u);

  // Lit scenes have none.
  EXPECT_TRUE(
      loadSceneFromString(std::string(kMinimal) +
                              "ambient: {color: [1, 1, 1]}\n"
                              "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1}\n",
                          "lit.yaml")
          .warnings.empty());
}

TEST(SceneBuilder, YamlMergeKeysShareMaterialsAndObjects) {
  const SceneParts p = partsOf(std::string(kMinimal) +
                               "materials:\n"
                               "  paint: &paint {kd: [0.8, 0.2, 0.2], ks: 0.5, shininess: 40}\n"
                               "  shiny: {<<: *paint, kr: 0.3, ks: 0.9}\n"
                               "objects:\n"
                               "  - &ball {type: sphere, center: [0, 0, -5], radius: 1, "
                               "material: shiny}\n"
                               "  - {<<: *ball, center: [2, 0, -5]}\n"
                               "lights: [{type: point, position: [4, 4, 4]}]\n");
  ASSERT_EQ(p.materials.size(), 3u);
  EXPECT_EQ(p.materials[2].kd, Color(0.8, 0.2, 0.2));
  EXPECT_EQ(p.materials[2].ks, Color(0.9));
  EXPECT_EQ(p.materials[2].kr, Color(0.3));
  EXPECT_EQ(p.materials[2].shininess, 40);
  ASSERT_EQ(p.primitives.size(), 2u);
  EXPECT_EQ(std::get<Sphere>(p.primitives[1].shape()).center, (Point3{2, 0, -5}));
  EXPECT_EQ(p.primitives[1].materialIndex(), 2u);
  // A misspelt key merged in is reported where it was written, for each material that has it.
  const std::vector<Diagnostic> errors = errorsOf(std::string(kMinimal) +
                                                  "materials:\n"
                                                  "  base: &base {kd: 0.5, shinyness: 4}\n"
                                                  "  other: {<<: *base}\n");
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].format(),
            "test.yaml:4:25: unknown key 'shinyness' in material 'base'; expected one of: kd, ks, "
            "shininess, kr, kt, ka, ior, reflection_blur, refraction_blur, priority, normal_map, "
            "bump_map, bump_scale, emission (did you mean 'shininess'?)");
  EXPECT_THAT(errors[1].format(), HasSubstr("test.yaml:4:25: unknown key 'shinyness' in material "
                                            "'other'"));
}

TEST(SceneBuilder, ObjectsThatReflectNoLightUnderLightsAreWarnings) {
  // Under a light, an object without a material (or with one of all-zero kd, ks, kr, kt) shows
  // only the ambient light: one warning at the object, naming why.
  const LoadedScene dark = loadSceneFromString(
      std::string(kMinimal) +
          "materials: {black: {ka: 0.5}}\n"
          "objects:\n"
          "  - {type: sphere, center: [0, 0, -5], radius: 1}\n"
          "  - {type: box, min: [0, 0, -9], max: [1, 1, -8], material: black}\n"
          "  - {type: sphere, center: [0, 2, -5], radius: 1, emission: [1, 0, 0]}\n"
          "  - {type: sphere, center: [0, 4, -5], radius: 1, material: {kd: 0.5}}\n"
          "lights: [{type: point, position: [0, 0, 5]}]\n",
      "dark.yaml");
  ASSERT_EQ(dark.warnings.size(), 2u);
  EXPECT_EQ(dark.warnings[0].format(),
            "dark.yaml:5:5: warning: sphere has no material, so it reflects no light: under the "
            "lights it shows only the ambient light (give it a material with kd or ks)");
  EXPECT_EQ(dark.warnings[1].format(),
            "dark.yaml:6:5: warning: box's material reflects no light (kd, ks, kr and kt are all "
            "0): under the lights it shows only the ambient light");
  // Many such objects: a few warnings and a count of the rest.
  std::string many =
      std::string(kMinimal) + "lights: [{type: point, position: [0, 0, 5]}]\nobjects:\n";
  for (int i = 0; i < 9; ++i) many += "  - {type: sphere, center: [0, 0, -5], radius: 1}\n";
  const LoadedScene manyDark = loadSceneFromString(many, "many.yaml");
  ASSERT_EQ(manyDark.warnings.size(), 6u);
  EXPECT_THAT(manyDark.warnings[0].format(), HasSubstr("many.yaml:5:5: warning: sphere has no"));
  // The count comes after the five named, at the first object it counts.
  EXPECT_EQ(manyDark.warnings[5].format(),
            "many.yaml:10:5: warning: 4 more objects reflect no light (this one first)");
}

// A group object without a material, placed by an instance that gives none, is as dark as a
// plain object: one warning at the first such instance of the group.
TEST(SceneBuilder, AnInstanceOfAnUnlitGroupObjectIsAWarning) {
  const LoadedScene loaded = loadSceneFromString(
      std::string(kMinimal) +
          "groups:\n"
          "  ball: [{type: sphere, center: [0, 0, -5], radius: 1}]\n"
          "  lit: [{type: sphere, center: [0, 0, -5], radius: 1, material: {kd: 0.5}}]\n"
          "objects:\n"
          "  - {type: instance, group: ball}\n"
          "  - {type: instance, group: ball, transform: [{translate: [2, 0, 0]}]}\n"
          "  - {type: instance, group: ball, material: {kd: 0.5}}\n"
          "  - {type: instance, group: lit}\n"
          "lights: [{type: point, position: [0, 0, 5]}]\n",
      "groups.yaml");
  ASSERT_EQ(loaded.warnings.size(), 1u);
  EXPECT_EQ(loaded.warnings[0].format(),
            "groups.yaml:7:5: warning: instance of group 'ball': an object of the group has no "
            "material and the instance gives none, so it reflects no light: under the lights it "
            "shows only the ambient light (give the instance or the object a material with kd or "
            "ks)");
  // A group object with a black material of its own: an instance's material would not change it,
  // so the instance is not blamed.
  const LoadedScene own = loadSceneFromString(
      std::string(kMinimal) +
          "groups: {ball: [{type: sphere, center: [0, 0, -5], radius: 1, material: {ka: 0.5}}]}\n"
          "objects: [{type: instance, group: ball}]\n"
          "lights: [{type: point, position: [0, 0, 5]}]\n",
      "own.yaml");
  EXPECT_TRUE(own.warnings.empty());
  // Instances and plain objects share the five named warnings and the count, in file order.
  std::string mixed = std::string(kMinimal) +
                      "groups: {ball: [{type: sphere, center: [0, 0, -5], radius: 1}]}\n"
                      "lights: [{type: point, position: [0, 0, 5]}]\nobjects:\n";
  for (int i = 0; i < 6; ++i) mixed += "  - {type: sphere, center: [0, 0, -5], radius: 1}\n";
  mixed += "  - {type: instance, group: ball}\n";
  const LoadedScene ordered = loadSceneFromString(mixed, "mixed.yaml");
  ASSERT_EQ(ordered.warnings.size(), 6u);
  EXPECT_EQ(ordered.warnings[4].format().substr(0, 23), "mixed.yaml:10:5: warnin");
  EXPECT_EQ(ordered.warnings[5].format(),
            "mixed.yaml:11:5: warning: 2 more objects reflect no light (this one first)");
  // Every instance of the group giving a material: none.
  const LoadedScene given =
      loadSceneFromString(std::string(kMinimal) +
                              "groups: {ball: [{type: sphere, center: [0, 0, -5], radius: 1}]}\n"
                              "objects: [{type: instance, group: ball, material: {kd: 0.5}}]\n"
                              "lights: [{type: point, position: [0, 0, 5]}]\n",
                          "given.yaml");
  EXPECT_TRUE(given.warnings.empty());
}

// A point or spot light inside a closed opaque solid that does not hold the camera lights nothing
// the camera sees: a warning at the light. Not for a clear solid, one that holds the camera too
// (a room), or a light outside.
TEST(SceneBuilder, ALightInsideAnOpaqueSolidIsAWarning) {
  const auto warnings = [](const std::string& objects, const std::string& light) {
    const LoadedScene loaded = loadSceneFromString(
        std::string(kMinimal) + "materials: {white: {kd: 0.8}, glass: {kd: 0.1, kt: 0.9}}\n" +
            "objects:\n" + objects + "lights:\n  - " + light + "\n",
        "lamp.yaml");
    std::vector<std::string> texts;
    for (const Diagnostic& d : loaded.warnings) texts.push_back(d.format());
    return texts;
  };
  const std::string bulb = "  - {type: sphere, center: [0, 0, -5], radius: 1, material: white}\n";
  EXPECT_EQ(warnings(bulb, "{type: point, position: [0, 0.5, -5]}"),
            std::vector<std::string>{
                "lamp.yaml:7:5: warning: point light is inside the sphere at lamp.yaml:5:5, which "
                "is opaque and does not hold the camera: it lights nothing the camera sees (give "
                "the sphere a kt, or move the light)"});
  // Through a transform, and in a csg; a spot light alike.
  EXPECT_EQ(warnings("  - {type: box, min: [-1, -1, -1], max: [1, 1, 1], material: white,\n"
                     "     transform: [{scale: [3, 1, 1]}, {translate: [0, 0, -5]}]}\n",
                     "{type: spot, position: [2.5, 0, -5], direction: [0, -1, 0]}")
                .size(),
            1u);
  EXPECT_EQ(warnings("  - {type: csg, operation: difference, material: white, operands: [\n"
                     "      {type: sphere, center: [0, 0, -5], radius: 2},\n"
                     "      {type: sphere, center: [0, 0, -5], radius: 1}]}\n",
                     "{type: point, position: [0, 1.5, -5]}")
                .size(),
            1u);
  // None: a clear bulb, the light in the csg's hollow, a room holding the camera, a light outside.
  EXPECT_TRUE(warnings("  - {type: sphere, center: [0, 0, -5], radius: 1, material: glass}\n",
                       "{type: point, position: [0, 0.5, -5]}")
                  .empty());
  EXPECT_TRUE(warnings("  - {type: csg, operation: difference, material: white, operands: [\n"
                       "      {type: sphere, center: [0, 0, -5], radius: 2},\n"
                       "      {type: sphere, center: [0, 0, -5], radius: 1}]}\n",
                       "{type: point, position: [0, 0, -5]}")
                  .empty());
  EXPECT_TRUE(warnings("  - {type: box, min: [-9, -9, -9], max: [9, 9, 9], material: white}\n",
                       "{type: point, position: [0, 5, -5]}")
                  .empty());
  EXPECT_TRUE(warnings(bulb, "{type: point, position: [0, 1.5, -5]}").empty());
  // A camera standing in the wall of a room (kMinimal's camera is at the origin) is inside.
  EXPECT_TRUE(warnings("  - {type: box, min: [-9, -9, -9], max: [9, 9, 0], material: white}\n",
                       "{type: point, position: [0, 5, -5]}")
                  .empty());
  // Past five such lights, one line counts the rest, at the first one not named.
  std::string many;
  for (int i = 0; i < 7; ++i) {
    many += "  - {type: sphere, center: [" + std::to_string(3 * i) +
            ", 0, -5], radius: 1, material: white}\n";
  }
  const LoadedScene lamps = loadSceneFromString(
      std::string(kMinimal) + "materials: {white: {kd: 0.8}}\nobjects:\n" + many + "lights:\n" +
          [] {
            std::string lights;
            for (int i = 0; i < 7; ++i) {
              lights += "  - {type: point, position: [" + std::to_string(3 * i) + ", 0, -5]}\n";
            }
            return lights;
          }(),
      "lamps.yaml");
  ASSERT_EQ(lamps.warnings.size(), 6u);
  EXPECT_EQ(lamps.warnings[5].format(),
            "lamps.yaml:18:5: warning: 2 more lights are inside opaque solids that do not hold the "
            "camera (this one first)");
}

// ------------------------------------------------------------------------------------ mesh objects

// A folder of its own under the system's temporary folder for mesh files, removed afterwards.
class MeshDir {
 public:
  MeshDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("glint_builder_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~MeshDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name, std::ios::binary) << text;
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Two unit right triangles in z = 0 with two MTL materials: `red` (Kd, Ks, Ns) and `glow` (Ke).
constexpr const char* kTwoMaterialObj =
    "mtllib two.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
    "usemtl red\nf 1 2 3\n"
    "usemtl glow\nf 2 4 3\n";
constexpr const char* kTwoMaterialMtl =
    "newmtl red\nKd 0.75 0.25 0.125\nKs 0.5 0.5 0.5\nNs 40\n"
    "newmtl glow\nKd 0 0 0\nKe 2 1.5 1\n";

constexpr const char* kLit = "lights: [{type: point, position: [0, 0, 5]}]\n";

LoadedScene loadIn(const MeshDir& dir, const std::string& text) {
  return loadSceneFromString(text, "meshes.yaml", dir.path());
}

std::vector<Diagnostic> meshErrorsOf(const MeshDir& dir, const std::string& text) {
  try {
    loadIn(dir, text);
  } catch (const SceneError& e) {
    return e.diagnostics();
  }
  return {};
}

const TriangleMesh* meshWithMaterial(const SceneParts& p, const Color& kd) {
  for (const TriangleMesh& m : p.meshes) {
    if (p.materials.at(m.materialIndex).kd == kd) return &m;
  }
  return nullptr;
}

TEST(SceneBuilder, MeshObjectTakesTheFilesMaterials) {
  MeshDir dir;
  dir.write("two.obj", kTwoMaterialObj);
  dir.write("two.mtl", kTwoMaterialMtl);
  const LoadedScene loaded =
      loadIn(dir, std::string(kMinimal) + kLit + "objects:\n  - {type: mesh, file: two.obj}\n");
  EXPECT_TRUE(loaded.warnings.empty());
  const SceneParts& p = loaded.parts;
  EXPECT_TRUE(p.primitives.empty());
  ASSERT_EQ(p.meshes.size(), 2u);
  ASSERT_EQ(p.materials.size(), 3u);  // the default, red, glow

  const TriangleMesh* red = meshWithMaterial(p, Color(0.75, 0.25, 0.125));
  ASSERT_NE(red, nullptr);
  const Material& m = p.materials[red->materialIndex];
  EXPECT_EQ(m.ka, m.kd);
  EXPECT_EQ(m.ks, Color(0.5));
  EXPECT_EQ(m.shininess, 40);
  EXPECT_EQ(m.kr, Color(0));
  EXPECT_EQ(m.kt, Color(0));
  EXPECT_EQ(red->emission, Color(0));
  EXPECT_EQ(red->triangleCount(), 1u);

  const TriangleMesh* glow = meshWithMaterial(p, Color(0));
  ASSERT_NE(glow, nullptr);
  EXPECT_EQ(glow->emission, Color(2, 1.5, 1));  // Ke → emission

  // smooth by default: unit vertex normals, here all +z.
  for (const TriangleMesh& mesh : p.meshes) {
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    for (const Normal3& n : mesh.normals) EXPECT_EQ(n, Normal3(0, 0, 1));
  }
}

TEST(SceneBuilder, MeshSceneIsHitThroughTheAggregate) {
  MeshDir dir;
  dir.write("two.obj", kTwoMaterialObj);
  dir.write("two.mtl", kTwoMaterialMtl);
  const Scene scene(loadIn(dir, std::string(kMinimal) + kLit +
                                    "objects:\n  - {type: mesh, file: two.obj, transform: "
                                    "[{translate: [0, 0, -5]}]}\n")
                        .parts);
  ASSERT_EQ(scene.meshes().size(), 2u);
  Hit hit;
  // Straight down the axis onto the red triangle (below the diagonal x + y = 1), at z = −5.
  ASSERT_TRUE(scene.intersect({{0.25, 0.25, 0}, {0, 0, -1}}, kInfinity, hit));
  EXPECT_NEAR(hit.t, 5, 1e-12);
  ASSERT_NE(hit.mesh, kNoMesh);
  EXPECT_EQ(scene.materialOf(hit).kd, Color(0.75, 0.25, 0.125));
  EXPECT_EQ(scene.emissionOf(hit), Color(0));
  EXPECT_NEAR(hit.shadingNormal.z, 1, 1e-12);
  // Above the diagonal: the glowing triangle.
  ASSERT_TRUE(scene.intersect({{0.75, 0.75, 0}, {0, 0, -1}}, kInfinity, hit));
  EXPECT_EQ(scene.emissionOf(hit), Color(2, 1.5, 1));
  // Beside the square: nothing.
  EXPECT_FALSE(scene.intersect({{1.5, 0.5, 0}, {0, 0, -1}}, kInfinity, hit));
}

TEST(SceneBuilder, MeshMaterialAndEmissionOverrideTheFiles) {
  MeshDir dir;
  dir.write("two.obj", kTwoMaterialObj);
  dir.write("two.mtl", kTwoMaterialMtl);
  const SceneParts named =
      loadIn(dir, std::string(kMinimal) + kLit +
                      "materials: {gold: {kd: [0.6, 0.5, 0.1]}}\n"
                      "objects:\n  - {type: mesh, file: two.obj, material: gold}\n")
          .parts;
  ASSERT_EQ(named.materials.size(), 2u);  // the default and gold: none from the file
  ASSERT_EQ(named.meshes.size(), 2u);
  for (const TriangleMesh& mesh : named.meshes) {
    EXPECT_EQ(mesh.materialIndex, 1u);
    EXPECT_EQ(mesh.emission, Color(0));  // the file's Ke belongs to the replaced material
  }

  const SceneParts inlined =
      loadIn(dir, std::string(kMinimal) + kLit +
                      "objects:\n  - {type: mesh, file: two.obj, material: {kd: 0.3},"
                      " emission: [0, 0.5, 0]}\n")
          .parts;
  ASSERT_EQ(inlined.materials.size(), 2u);
  for (const TriangleMesh& mesh : inlined.meshes) {
    EXPECT_EQ(inlined.materials[mesh.materialIndex].kd, Color(0.3));
    EXPECT_EQ(mesh.emission, Color(0, 0.5, 0));
  }

  // emission alone replaces the files' emission and keeps their materials.
  const SceneParts lit = loadIn(dir, std::string(kMinimal) + kLit +
                                         "objects:\n  - {type: mesh, file: two.obj, "
                                         "emission: [0.25, 0.25, 0.25]}\n")
                             .parts;
  ASSERT_EQ(lit.materials.size(), 3u);
  for (const TriangleMesh& mesh : lit.meshes) EXPECT_EQ(mesh.emission, Color(0.25));
}

TEST(SceneBuilder, MeshWithoutAnyMaterialIsMidGrey) {
  MeshDir dir;
  dir.write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const SceneParts p =
      loadIn(dir, std::string(kMinimal) + kLit + "objects:\n  - {type: mesh, file: plain.obj}\n")
          .parts;
  ASSERT_EQ(p.meshes.size(), 1u);
  const Material& m = p.materials.at(p.meshes[0].materialIndex);
  EXPECT_EQ(m.kd, Color(0.7));
  EXPECT_EQ(m.ka, Color(0.7));
  EXPECT_EQ(m.ks, Color(0));
}

TEST(SceneBuilder, MeshTransformAndFlatShading) {
  MeshDir dir;
  dir.write("two.obj", kTwoMaterialObj);
  dir.write("two.mtl", kTwoMaterialMtl);
  // The same file three times, once through another spelling of its path: read once, so its
  // materials enter the scene once and all three objects share them.
  const SceneParts p =
      loadIn(dir, std::string(kMinimal) + kLit +
                      "objects:\n"
                      "  - {type: mesh, file: two.obj}\n"
                      "  - type: mesh\n"
                      "    file: ./two.obj\n"
                      "    smooth: false\n"
                      "    transform: [{rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 2},"
                      " {translate: [0, 0, -5]}]\n"
                      "  - {type: mesh, file: " +
                      (dir.path() / "two.obj").string() + ", smooth: true}\n")
          .parts;
  ASSERT_EQ(p.materials.size(), 3u);
  ASSERT_EQ(p.meshes.size(), 6u);
  for (std::size_t i = 0; i < 2; ++i) {
    const TriangleMesh& plain = p.meshes[i];
    const TriangleMesh& moved = p.meshes[2 + i];
    const TriangleMesh& absolute = p.meshes[4 + i];
    EXPECT_EQ(moved.materialIndex, plain.materialIndex);
    EXPECT_EQ(absolute.materialIndex, plain.materialIndex);
    EXPECT_EQ(absolute.positions, plain.positions);
    EXPECT_EQ(moved.indices, plain.indices);
    EXPECT_TRUE(moved.normals.empty());  // smooth: false
    EXPECT_EQ(absolute.normals.size(), absolute.positions.size());
    ASSERT_EQ(moved.positions.size(), plain.positions.size());
    for (std::size_t v = 0; v < plain.positions.size(); ++v) {
      // Rotating 90° about x takes (x, y, 0) to (x, 0, y); then ×2 and 5 along −z.
      const Point3& q = plain.positions[v];
      expectNear(moved.positions[v], Point3{2 * q.x, 0, 2 * q.y - 5});
    }
  }
}

TEST(SceneBuilder, MeshDegenerateTrianglesAreOneWarningAtTheObject) {
  MeshDir dir;
  dir.write("some_flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 2 4 1\n");
  const LoadedScene loaded = loadIn(dir, std::string(kMinimal) + kLit +
                                             "objects:\n"
                                             "  - {type: sphere, center: [0, 0, -5], radius: 1,\n"
                                             "     material: {kd: 1}}\n"
                                             "  - type: mesh\n"
                                             "    file: some_flat.obj\n");
  ASSERT_EQ(loaded.warnings.size(), 1u);
  const Diagnostic& w = loaded.warnings[0];
  EXPECT_EQ(w.severity, Diagnostic::Severity::Warning);
  EXPECT_EQ(w.format(),
            "meshes.yaml:7:5: warning: mesh file 'some_flat.obj': dropped 2 degenerate triangles "
            "(zero area, non-finite or invalid vertices); 1 remain");
  ASSERT_EQ(loaded.parts.meshes.size(), 1u);
  EXPECT_EQ(loaded.parts.meshes[0].triangleCount(), 1u);
}

// Generated normals that leave their definition to stay fast (generateSmoothNormals: a far
// outlier vertex, a position shared by too many corners) say so at the object.
TEST(SceneBuilder, MeshGeneratedNormalsThatGiveUpSmoothingAreWarnings) {
  MeshDir dir;
  std::string grid;  // 40 × 40 quads and one triangle a million units away
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) grid += fmt::format("v {} {} {}\n", i / 40.0, 0, j / 40.0);
  }
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      const int a = i * 41 + j + 1;
      grid += fmt::format("f {} {} {} {}\n", a, a + 1, a + 42, a + 41);
    }
  }
  grid += "v 1e6 0 0\nv 1e6 0 1\nv 1e6 1 0\nf 1682 1683 1684\n";
  dir.write("outlier.obj", grid);
  std::string fan = "v 0 1 0\n";  // kMaxSmoothedCorners + 1 triangles around one vertex
  const std::uint32_t triangles = kMaxSmoothedCorners + 1;
  for (std::uint32_t k = 0; k < triangles; ++k) {
    const double angle = 2 * std::numbers::pi * k / triangles;
    fan += fmt::format("v {} 0 {}\n", std::cos(angle), std::sin(angle));
  }
  for (std::uint32_t k = 0; k < triangles; ++k) {
    fan += fmt::format("f 1 {} {}\n", (k + 1) % triangles + 2, k + 2);
  }
  dir.write("fan.obj", fan);
  const LoadedScene loaded = loadIn(dir, std::string(kMinimal) + kLit +
                                             "objects:\n"
                                             "  - {type: mesh, file: outlier.obj}\n"
                                             "  - {type: mesh, file: fan.obj}\n"
                                             "  - {type: mesh, file: fan.obj, smooth: false}\n");
  ASSERT_EQ(loaded.warnings.size(), 2u);  // flat facets use no generated normals: no warning
  EXPECT_EQ(loaded.warnings[0].format(),
            "meshes.yaml:5:5: warning: mesh file 'outlier.obj': its generated normals smooth only "
            "over vertices at exactly the same position: within the usual radius (1e-4 of the "
            "bounding box's diagonal) too many vertices are near one another (a vertex far from "
            "the rest, or fine detail in a large mesh)");
  EXPECT_EQ(loaded.warnings[1].format(),
            "meshes.yaml:6:5: warning: mesh file 'fan.obj': in its generated normals, at 1 "
            "position shared by more than 1024 triangle corners each corner keeps its own "
            "triangle's normal");
  ASSERT_EQ(loaded.parts.meshes.size(), 3u);
  // The grid is flat: its normals are straight up (or down) whichever way they were smoothed.
  const TriangleMesh& flat = loaded.parts.meshes[0];
  ASSERT_EQ(flat.normals.size(), flat.positions.size());
  for (std::size_t v = 0; v < flat.positions.size(); ++v) {
    if (flat.positions[v].x < 2) {
      EXPECT_NEAR(std::abs(flat.normals[v].y), 1, 1e-6) << v;
    }
  }
}

TEST(SceneBuilder, MeshFilesThatCannotBeLoadedAreErrorsAtTheObject) {
  MeshDir dir;
  dir.write("notes.txt", "Hello, this is not a mesh.\n");
  dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
  std::filesystem::create_directories(dir.path() / "folder.obj");
  const std::vector<Diagnostic> errors =
      meshErrorsOf(dir, std::string(kMinimal) + kLit +
                            "objects:\n"
                            "  - {type: mesh, file: missing.obj}\n"
                            "  - {type: sphere, center: [0, 0, -5], radius: 1}\n"
                            "  - type: mesh\n"
                            "    file: notes.txt\n"
                            "  -   {type: mesh, file: folder.obj}\n"
                            "  - {type: mesh, file: lines.obj}\n"
                            "  - {type: mesh, file: missing.obj}\n"
                            "  - {type: mesh, file: ''}\n");
  ASSERT_EQ(errors.size(), 6u);
  const std::string looked = (dir.path() / "missing.obj").string();
  EXPECT_EQ(errors[0].format(),
            "meshes.yaml:5:5: cannot load mesh file 'missing.obj': no such file (looked for " +
                looked + ": relative paths start at the scene file's folder)");
  EXPECT_EQ(errors[1].where.line, 7);
  EXPECT_EQ(errors[1].where.column, 5);
  EXPECT_THAT(errors[1].message, HasSubstr("cannot load mesh file 'notes.txt': not a mesh format"));
  EXPECT_EQ(errors[2].where.line, 9);
  EXPECT_EQ(errors[2].where.column, 7);
  EXPECT_THAT(errors[2].message, HasSubstr("'folder.obj': it is a folder, not a mesh file"));
  EXPECT_EQ(errors[3].where.line, 10);
  EXPECT_THAT(errors[3].message, HasSubstr("'lines.obj': the file holds no triangles"));
  // The same missing file again: the same error (from the cache), at its own object.
  EXPECT_EQ(errors[4].where.line, 11);
  EXPECT_THAT(errors[4].message, HasSubstr("'missing.obj': no such file"));
  EXPECT_EQ(errors[5].where.line, 12);
  EXPECT_THAT(errors[5].message, HasSubstr("mesh.file must not be empty"));
}

TEST(SceneBuilder, MeshRealFileFromTheTestModels) {
  // Debian's assimp-testmodels: an absolute path is used as it is.
  const std::filesystem::path stl = "/usr/share/assimp/models/STL/Spider_binary.stl";
  ASSERT_TRUE(std::filesystem::is_regular_file(stl))
      << stl << " is missing: run scripts/setup.sh (it installs assimp-testmodels)";
  const LoadedScene loaded = loadSceneFromString(
      std::string(kMinimal) + kLit + "objects:\n  - {type: mesh, file: " + stl.string() +
          ", transform: [{translate: [0, 0, -10]}]}\n",
      "spider.yaml");
  const SceneParts& p = loaded.parts;
  ASSERT_EQ(p.meshes.size(), 1u);
  std::uint32_t header = 0;  // the STL's triangle count, after its 80-byte header
  std::ifstream in(stl, std::ios::binary);
  in.seekg(80);
  in.read(reinterpret_cast<char*>(&header), 4);
  // The spider has facets of zero area (three distinct vertices at one position): the warning
  // accounts for every triangle of the header that is not in the mesh.
  ASSERT_LT(p.meshes[0].triangleCount(), header);
  ASSERT_EQ(loaded.warnings.size(), 1u);
  EXPECT_EQ(loaded.warnings[0].where.line, 5);
  EXPECT_THAT(loaded.warnings[0].message,
              HasSubstr(fmt::format("dropped {} degenerate triangles",
                                    header - p.meshes[0].triangleCount())));
  for (const Point3& q : p.meshes[0].positions) ASSERT_LT(q.z, -8);  // the file spans z ±1.65
}

TEST(SceneBuilder, MeshesCountForTheUnlitWarning) {
  MeshDir dir;
  dir.write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const LoadedScene dark =
      loadIn(dir, std::string(kMinimal) + "objects:\n  - {type: mesh, file: plain.obj}\n");
  ASSERT_EQ(dark.warnings.size(), 1u);
  EXPECT_THAT(dark.warnings[0].message, HasSubstr("no lights"));
  EXPECT_TRUE(loadIn(dir, std::string(kMinimal) +
                              "objects:\n  - {type: mesh, file: plain.obj, emission: [1, 1, 1]}\n")
                  .warnings.empty());
}

// Under `path` the background is a light and the ambient light is not added: a lit background
// (of any kind) or an emitter is enough, ambient light is not.
TEST(SceneBuilder, TheUnlitWarningFollowsTheIntegrator) {
  const auto warningsOf = [&](const std::string& extra, const std::string& otherObject = "") {
    return loadSceneFromString(std::string(kMinimal) + "render: {integrator: path}\n" + extra +
                                   "objects:\n  - {type: sphere, center: [0, 0, -5], radius: 1, "
                                   "material: {kd: 0.5}}\n" +
                                   otherObject,
                               "t.yaml")
        .warnings;
  };
  EXPECT_TRUE(warningsOf("background: [0.8, 0.8, 0.8]\n").empty());
  EXPECT_TRUE(
      warningsOf("background: {type: gradient, zenith: [0, 0, 1], horizon: [0, 0, 0]}\n").empty());
  EXPECT_TRUE(warningsOf("background: {type: sky, top: [0, 0, 0], bottom: [0.1, 0, 0]}\n").empty());
  EXPECT_TRUE(
      warningsOf("lights: [{type: point, position: [0, 0, 0], color: [1, 1, 1]}]\n").empty());
  const std::vector<Diagnostic> ambientOnly = warningsOf("ambient: {color: [1, 1, 1]}\n");
  ASSERT_EQ(ambientOnly.size(), 1u);
  EXPECT_EQ(ambientOnly[0].format(),
            "t.yaml:1:1: warning: the scene has no lights, no emissive objects and a black "
            "background: under the path integrator every object will render black (the path "
            "integrator adds no ambient light)");
  EXPECT_EQ(
      warningsOf("background: {type: gradient, zenith: [0, 0, 0], horizon: [0, 0, 0]}\n").size(),
      1u);
  EXPECT_TRUE(warningsOf("background: [0, 0, 0]\n",
                         "  - {type: sphere, center: [0, 3, -5], radius: 1, emission: [1, 1, 1]}\n")
                  .empty());
  // A mirror under a black background still shows only black under `path`.
  EXPECT_EQ(warningsOf("", "  - {type: sphere, center: [0, 3, -5], radius: 1, material: {kr: 1}}\n")
                .size(),
            1u);
}

// The column (1-based) where `token` first starts in `line`.
int columnOf(const std::string& line, const std::string& token) {
  const std::size_t at = line.find(token);
  EXPECT_NE(at, std::string::npos) << token << " not in " << line;
  return static_cast<int>(at) + 1;
}

TEST(SceneBuilder, AreaLightsOfEachShape) {
  const SceneParts p = partsOf(
      std::string(kMinimal) +
      "lights:\n"
      "  - {type: area, shape: rectangle, corner: [-1, 4, -1], edges: [[2, 0, 0], [0, 0, 3]],\n"
      "     color: [1, 0.5, 0.25], intensity: 2, attenuation: [1, 0, 0.01], samples: 32}\n"
      "  - {type: area, shape: disk, center: [0, 5, 0], normal: [0, -2, 0], radius: 0.5}\n"
      "  - {type: area, shape: sphere, center: [1, 2, 3], radius: 0.25, samples: 1,\n"
      "     color: \"#ffffff\", intensity: 0.5}\n");
  ASSERT_EQ(p.lights.size(), 3u);

  const AreaLight& rect = std::get<AreaLight>(p.lights[0]);
  EXPECT_EQ(rect.shape, AreaShape::Rectangle);
  EXPECT_EQ(rect.corner, (Point3{-1, 4, -1}));
  EXPECT_EQ(rect.edge1, (Vec3{2, 0, 0}));
  EXPECT_EQ(rect.edge2, (Vec3{0, 0, 3}));
  EXPECT_EQ(rect.intensity, Color(2, 1, 0.5));  // color × intensity
  EXPECT_EQ(rect.attenuation.kc, 1);
  EXPECT_EQ(rect.attenuation.kl, 0);
  EXPECT_EQ(rect.attenuation.kq, 0.01);
  EXPECT_EQ(rect.samples, 32);

  // Defaults: white, intensity 1, attenuation [1, 0, 0] like a point light, AreaLight's samples.
  const AreaLight& disk = std::get<AreaLight>(p.lights[1]);
  EXPECT_EQ(disk.shape, AreaShape::Disk);
  EXPECT_EQ(disk.center, (Point3{0, 5, 0}));
  EXPECT_EQ(disk.normal, (Vec3{0, -1, 0}));  // normalised
  EXPECT_EQ(disk.radius, 0.5);
  EXPECT_EQ(disk.intensity, Color(1));
  EXPECT_EQ(disk.attenuation.kc, 1);
  EXPECT_EQ(disk.attenuation.kl, 0);
  EXPECT_EQ(disk.attenuation.kq, 0);
  EXPECT_EQ(disk.samples, AreaLight{}.samples);
  EXPECT_EQ(disk.samples, 16);

  const AreaLight& sphere = std::get<AreaLight>(p.lights[2]);
  EXPECT_EQ(sphere.shape, AreaShape::Sphere);
  EXPECT_EQ(sphere.center, (Point3{1, 2, 3}));
  EXPECT_EQ(sphere.radius, 0.25);
  EXPECT_EQ(sphere.samples, 1);
  expectNear(sphere.intensity, Color(0.5));
}

TEST(SceneBuilder, AreaLightErrorsAtTheValue) {
  const std::string lights = std::string(kMinimal) + "lights:\n";
  const auto expectLightError = [&](const std::string& light, const std::string& token,
                                    const std::string& fragment) {
    const std::string line = "  - " + light;
    expectOneError(lights + line + "\n", 4, columnOf(line, token), fragment);
  };
  const std::string rect = "{type: area, shape: rectangle, corner: [0, 4, 0], ";
  expectLightError(rect + "edges: [[1, 0, 0], [1, 0, 1]]}", "[[1, 0, 0]",
                   "lights[0] (area light).edges must be perpendicular, got [1, 0, 0] and "
                   "[1, 0, 1] at 45 degrees");
  expectLightError(rect + "edges: [[1, 0, 0], [0, 0, 0]]}", "[[1, 0, 0]",
                   "lights[0] (area light).edges[1] must be a non-zero vector");
  const std::string disk = "{type: area, shape: disk, center: [0, 4, 0], ";
  expectLightError(disk + "normal: [0, 0, 0], radius: 1}", "[0, 0, 0]",
                   "area light.normal must be non-zero, got [0, 0, 0]");
  expectLightError(disk + "normal: [0, 1, 0], radius: 0}", "0}",
                   "area light.radius must be > 0, got 0");
  const std::string sphere = "{type: area, shape: sphere, center: [0, 4, 0], radius: 1, ";
  expectLightError("{type: area, shape: sphere, center: [0, 4, 0], radius: -1}", "-1",
                   "area light.radius must be > 0, got -1");
  expectLightError(sphere + "samples: 0}", "0}",
                   "area light.samples must be between 1 and 65536, got 0");
  expectLightError(sphere + "samples: 65537}", "65537",
                   "area light.samples must be between 1 and 65536, got 65537");
  expectLightError(sphere + "intensity: -1}", "-1", "area light.intensity must be >= 0, got -1");
  expectLightError(sphere + "color: [1, -1, 1]}", "[1, -1, 1]",
                   "area light.color components must be >= 0");
  expectLightError(sphere + "attenuation: [0, 0, 0]}", "[0, 0, 0]",
                   "area light.attenuation must not be all 0");
  expectLightError(sphere + "attenuation: [1, -1, 0]}", "[1, -1, 0]",
                   "area light.attenuation components must be >= 0");
  // The index names the light among several.
  const std::string second = "  - " + rect + "edges: [[1, 0, 0], [1, 1, 0]]}";
  expectOneError(lights + "  - {type: point, position: [0, 4, 0]}\n" + second + "\n", 5,
                 columnOf(second, "[[1, 0, 0]"),
                 "lights[1] (area light).edges must be perpendicular");
  // A zero-intensity area light is a warning, like the other lights.
  const LoadedScene dark =
      loadSceneFromString(lights + "  - " + sphere + "intensity: 0}\n", "test.yaml");
  ASSERT_EQ(dark.warnings.size(), 1u);
  EXPECT_THAT(dark.warnings[0].message, HasSubstr("area light has zero intensity"));
}

TEST(SceneBuilder, AreaLightHandMadeDescriptions) {
  const auto scene = [](const std::vector<HandMade::Entry>& light) {
    HandMade m("made.yaml");
    m.entity(EntityKind::ImageEntity,
             m.map(1, 1, {{"width", {"64"}, 2, 3}, {"height", {"48"}, 3, 3}}));
    m.entity(EntityKind::CameraEntity, m.map(4, 1,
                                             {{"position", {"0", "0", "0"}, 4, 20},
                                              {"direction", {"0", "0", "-1"}, 5, 20},
                                              {"fov", {"60"}, 6, 20}}));
    m.entity(EntityKind::LightEntity, m.map(7, 5, light), "area");
    return m;
  };
  // A light without a surface: the builder reports the missing shape itself.
  HandMade noShape = scene({{"type", {"area"}, 7, 12}});
  BuildResult r = buildScene(noShape.d);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(),
            "made.yaml:7:5: area light is missing required key 'shape' (one of: rectangle, disk, "
            "sphere)");

  HandMade noRadius = scene({{"type", {"area"}, 7, 12},
                             {"shape", {"disk"}, 8, 12},
                             {"center", {"0", "3", "0"}, 9, 12},
                             {"normal", {"0", "-1", "0"}, 10, 12}});
  r = buildScene(noRadius.d);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(),
            "made.yaml:7:5: disk area light is missing required key 'radius'");

  HandMade disk = scene({{"type", {"area"}, 7, 12},
                         {"shape", {"disk"}, 8, 12},
                         {"center", {"0", "3", "0"}, 9, 12},
                         {"normal", {"0", "-1", "0"}, 10, 12},
                         {"radius", {"0.5"}, 11, 12}});
  r = buildScene(disk.d);
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  const AreaLight& built = std::get<AreaLight>(r.parts.lights.at(0));
  EXPECT_EQ(built.shape, AreaShape::Disk);
  EXPECT_EQ(built.radius, 0.5);
  EXPECT_EQ(built.samples, AreaLight{}.samples);
}

TEST(SceneBuilder, AreaRectangleIsValidatedLikeTheRectangleObject) {
  // The same edges are accepted or refused alike, at the same tolerance, for both.
  int accepted = 0;
  int refused = 0;
  for (const double skew : {0.0, 1e-13, 1e-10, 1e-8, 1e-6, 1e-3, 0.5}) {
    const std::string edges = fmt::format("edges: [[2, 0, 0], [{}, 0, 3]]", skew);
    const bool objectOk =
        errorsOf(std::string(kMinimal) + "objects:\n  - {type: rectangle, corner: [0, 0, 0], " +
                 edges + "}\n")
            .empty();
    const bool lightOk =
        errorsOf(std::string(kMinimal) +
                 "lights:\n  - {type: area, shape: rectangle, corner: [0, 0, 0], " + edges + "}\n")
            .empty();
    EXPECT_EQ(objectOk, lightOk) << edges;
    (lightOk ? accepted : refused) += 1;
  }
  EXPECT_GT(accepted, 0);
  EXPECT_GT(refused, 0);
}

TEST(SceneBuilder, AdaptiveSampling) {
  const std::string camera = "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n";
  EXPECT_FALSE(partsOf(std::string(kMinimal)).image.adaptive);

  // Absent keys take AdaptiveSampling's defaults (the one place they are written).
  const SceneParts defaults = partsOf(camera + "image: {width: 4, height: 3, adaptive: {}}\n");
  ASSERT_TRUE(defaults.image.adaptive);
  EXPECT_EQ(defaults.image.adaptive->maxSamples, AdaptiveSampling{}.maxSamples);
  EXPECT_EQ(defaults.image.adaptive->threshold, AdaptiveSampling{}.threshold);
  EXPECT_EQ(defaults.image.adaptive->maxSamples, 64);
  EXPECT_EQ(defaults.image.adaptive->threshold, 0.02);

  const SceneParts set =
      partsOf(camera +
              "image: {width: 4, height: 3, samples: 4, adaptive: {max_samples: 256, "
              "threshold: 0.01}}\n");
  ASSERT_TRUE(set.image.adaptive);
  EXPECT_EQ(set.image.samples, 4);
  EXPECT_EQ(set.image.adaptive->maxSamples, 256);
  EXPECT_EQ(set.image.adaptive->threshold, 0.01);
  // max_samples may equal samples (adaptive then adds nothing).
  const SceneParts equal =
      partsOf(camera + "image: {width: 4, height: 3, samples: 8, adaptive: {max_samples: 8}}\n");
  ASSERT_TRUE(equal.image.adaptive);
  EXPECT_EQ(equal.image.adaptive->maxSamples, 8);

  const auto expectImageError = [&](const std::string& image, const std::string& token,
                                    const std::string& fragment) {
    expectOneError(camera + image + "\n", 2, columnOf(image, token), fragment);
  };
  expectImageError("image: {width: 4, height: 3, adaptive: {max_samples: 0}}", "0}",
                   "image.adaptive.max_samples must be between 1 and 65536, got 0");
  expectImageError("image: {width: 4, height: 3, adaptive: {max_samples: 65537}}", "65537",
                   "image.adaptive.max_samples must be between 1 and 65536, got 65537");
  expectImageError("image: {width: 4, height: 3, samples: 8, adaptive: {max_samples: 4}}", "4}",
                   "image.adaptive.max_samples must be >= image.samples (8), got 4");
  // The default max_samples below samples: at the mapping, naming the default.
  expectImageError("image: {width: 4, height: 3, samples: 100, adaptive: {threshold: 0.1}}",
                   "{threshold",
                   "image.adaptive.max_samples (default 64) must be >= image.samples (100)");
  expectImageError("image: {width: 4, height: 3, adaptive: {threshold: 0}}", "0}",
                   "image.adaptive.threshold must be > 0, got 0");
  expectImageError("image: {width: 4, height: 3, adaptive: {threshold: -0.1}}", "-0.1",
                   "image.adaptive.threshold must be > 0, got -0.1");
  // An invalid samples is one error, not also a comparison with it.
  expectImageError("image: {width: 4, height: 3, samples: 0, adaptive: {max_samples: 4}}", "0,",
                   "image.samples must be between 1 and 65536, got 0");

  // The worst case (every pixel at max_samples) must pass the camera-ray limit, refused at
  // max_samples before anything is allocated.
  const std::string hugeImage =
      "image: {width: 65535, height: 65535, adaptive: {max_samples: 65536}}";
  const ParseResult huge = parseScene(camera + hugeImage + "\n", "test.yaml");
  ASSERT_FALSE(huge.hasErrors());
  BuildOptions unlimited;
  unlimited.imageMemoryBudget = std::numeric_limits<std::uint64_t>::max();
  const BuildResult built = buildScene(huge.description, unlimited);
  ASSERT_EQ(built.diagnostics.size(), 1u);
  EXPECT_EQ(built.diagnostics[0].where.line, 2);
  EXPECT_EQ(built.diagnostics[0].where.column, columnOf(hugeImage, "65536"));
  EXPECT_THAT(built.diagnostics[0].message,
              HasSubstr("image.adaptive.max_samples: an image of 65535 × 65535 pixels with 65536 "
                        "samples per pixel needs"));
}

TEST(SceneBuilder, FocusDistanceDefaultsToTheLookAtPoint) {
  const std::string image = "image: {width: 4, height: 3}\n";
  // |(3, 0, -4) − (0, 0, 0)| = 5: the point looked at is in focus.
  const SceneParts lookAt = partsOf(
      "camera: {position: [0, 0, 0], look_at: [3, 0, -4], fov: 40, aperture: 0.2}\n" + image);
  EXPECT_EQ(lookAt.camera.aperture, 0.2);
  EXPECT_EQ(lookAt.camera.focusDistance, 5);
  // An explicit focus_distance wins.
  const SceneParts given = partsOf(
      "camera: {position: [0, 0, 0], look_at: [3, 0, -4], fov: 40, aperture: 0.2,\n"
      "         focus_distance: 2.5}\n" +
      image);
  EXPECT_EQ(given.camera.focusDistance, 2.5);
  // Without aperture nothing is in or out of focus; the distance stays unset.
  EXPECT_EQ(partsOf("camera: {position: [0, 0, 0], look_at: [3, 0, -4], fov: 40}\n" + image)
                .camera.focusDistance,
            0);
  // With direction there is no point to focus on: focus_distance is required.
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40, aperture: 0.5}\n" + image, 1,
      73,
      "camera.focus_distance is required when camera.aperture > 0 and the camera has no "
      "look_at");
  // A look_at equal to the position is one error (at look_at), not also a focus error.
  expectOneError(
      "camera: {position: [1, 2, 3], look_at: [1, 2, 3], fov: 40, aperture: 1}\n" + image, 1, 40,
      "camera.look_at must differ from camera.position");
}

// render.integrator and render.ambient_occlusion (DESIGN.md §10).
TEST(SceneBuilder, AmbientOcclusionAndIntegratorKeys) {
  const std::string base = std::string(kMinimal) + "render: ";
  const auto build = [&](const std::string& render) {
    return loadSceneFromString(base + render + "\n", "t.yaml").parts.render;
  };
  EXPECT_FALSE(build("{max_depth: 3}").ambientOcclusion);
  const RenderSettings defaults = build("{integrator: whitted, ambient_occlusion: {}}");
  ASSERT_TRUE(defaults.ambientOcclusion);
  EXPECT_EQ(defaults.ambientOcclusion->samples, 16);
  EXPECT_EQ(defaults.ambientOcclusion->distance, std::numeric_limits<double>::infinity());
  const RenderSettings given = build("{ambient_occlusion: {samples: 64, distance: 2.5}}");
  ASSERT_TRUE(given.ambientOcclusion);
  EXPECT_EQ(given.ambientOcclusion->samples, 64);
  EXPECT_EQ(given.ambientOcclusion->distance, 2.5);

  const auto expectRenderError = [&](const std::string& render, const std::string& token,
                                     const std::string& fragment) {
    const std::string line = "render: " + render;
    expectOneError(std::string(kMinimal) + line + "\n", 3, static_cast<int>(line.find(token)) + 1,
                   fragment);
  };
  expectRenderError("{ambient_occlusion: {samples: 0}}", "0}",
                    "render.ambient_occlusion.samples must be");
  expectRenderError("{ambient_occlusion: {distance: -1}}", "-1",
                    "render.ambient_occlusion.distance must be > 0");
  expectRenderError("{ambient_occlusion: {sample: 4}}", "sample",
                    "unknown key 'sample' in render.ambient_occlusion; expected one of: samples, "
                    "distance (did you mean 'samples'?)");
  expectRenderError("{ambient_occlusion: 16}", "16",
                    "render.ambient_occlusion: expected a mapping {samples, distance}, got '16'");
  expectRenderError("{integrator: wited}", "wited",
                    "render.integrator must be whitted or path, got 'wited' (did you mean "
                    "'whitted'?)");
  expectRenderError("{min_depth: 0}", "0", "render.min_depth must be");
  const RenderSettings path = build("{integrator: path, min_depth: 5}");
  EXPECT_EQ(path.integrator, Integrator::Path);
  EXPECT_EQ(path.minDepth, 5);
  // An option of the other integrator is read (and checked) but has no effect: a warning at its
  // key, for the integrator the render uses (--integrator included).
  const auto warningsOf = [&](const std::string& render, SceneOverrides overrides = {}) {
    LoadOptions options;
    options.overrides = overrides;
    return loadSceneFromString(base + render + "\n", "t.yaml", ".", options).warnings;
  };
  const std::vector<Diagnostic> aoUnderPath =
      warningsOf("{integrator: path, ambient_occlusion: {samples: 4}}");
  ASSERT_EQ(aoUnderPath.size(), 1U);
  EXPECT_EQ(aoUnderPath[0].format(),
            "t.yaml:3:28: warning: render.ambient_occlusion has no effect: it is an option of the "
            "whitted integrator, and this render uses path");
  const std::vector<Diagnostic> minDepthUnderWhitted = warningsOf("{min_depth: 4}");
  ASSERT_EQ(minDepthUnderWhitted.size(), 1U);
  EXPECT_THAT(minDepthUnderWhitted[0].format(),
              HasSubstr("t.yaml:3:10: warning: render.min_depth has no effect: it is an option "
                        "of the path integrator, and this render uses whitted"));
  SceneOverrides toPath;
  toPath.integrator = Integrator::Path;
  EXPECT_TRUE(warningsOf("{min_depth: 4}", toPath).empty());
  const std::vector<Diagnostic> aoOverridden = warningsOf("{ambient_occlusion: {}}", toPath);
  ASSERT_EQ(aoOverridden.size(), 1U);
  EXPECT_THAT(aoOverridden[0].format(), HasSubstr("this render uses path (--integrator)"));
  EXPECT_EQ(warningsOf("{ambient_occlusion: {}, min_depth: 2}", toPath).size(), 1U);
  // Russian roulette starting at or past max_depth is allowed (it never runs) but said.
  const std::vector<Diagnostic> noRoulette =
      warningsOf("{integrator: path, min_depth: 5, max_depth: 3}");
  ASSERT_EQ(noRoulette.size(), 1U);
  EXPECT_EQ(noRoulette[0].format(),
            "t.yaml:3:28: warning: render.min_depth 5 is not below max_depth 3: every path ends "
            "at max_depth before Russian roulette would start");
  EXPECT_TRUE(warningsOf("{integrator: path, min_depth: 2, max_depth: 3}").empty());
  EXPECT_TRUE(warningsOf("{integrator: path, max_depth: 2}").empty());  // min_depth not written
  EXPECT_EQ(build("{}").integrator, Integrator::Whitted);
  EXPECT_EQ(build("{}").minDepth, 3);
}

}  // namespace
}  // namespace glint
