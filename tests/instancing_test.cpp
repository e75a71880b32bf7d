// Instancing in whole scenes (DESIGN.md §11): an instance renders what the same object written out
// with the instance's transform renders — the same 8-bit bytes, linear pixels within 1e-9 (see
// expectSameBytes for why not the same bits) — the
// instance's material replaces only missing ones, textures and vertex normals work inside
// instances, the same bytes on any thread count, groups from included files, and the errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "glint/factories/scene_loader.h"
#include "glint/factories/scene_test_support.h"
#include "glint/image/image_writer.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using testing::errorsOf;
using testing::expectOneError;
using ::testing::HasSubstr;

// A lit stage: camera, a floor, a mirror-ish back wall (secondary rays see the objects), a point
// light (shadows) and ambient light.
const std::string kStage = R"(camera: {position: [0, 2, 9], look_at: [0, 0.5, 0], fov: 40}
image: {width: 96, height: 72}
ambient: {color: [1, 1, 1], intensity: 0.1}
materials:
  red: {kd: [0.8, 0.2, 0.1], ks: 0.4, shininess: 30}
  blue: {kd: [0.1, 0.3, 0.9], ks: 0.2, shininess: 10}
  mirror: {kd: 0.2, kr: 0.6}
  glass: {kd: 0.05, kt: 0.7, ior: 1.4}
lights:
  - {type: point, position: [4, 6, 5], intensity: 1}
)";
const std::string kFloor =
    "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: blue}\n"
    "  - {type: rectangle, corner: [-6, -1, -3], edges: [[12, 0, 0], [0, 8, 0]], "
    "material: mirror}\n";

const std::string kTransform =
    "[{scale: [1.25, 0.75, 1.5]}, {rotate: {axis: [1, 2, 0.5], angle: 37}}, "
    "{translate: [0.3, 0.4, -0.2]}]";

Film renderText(const std::string& text, int threads = 2) {
  LoadedScene loaded = loadSceneFromString(text, "test.yaml");
  const Scene scene(std::move(loaded.parts));
  RenderOptions options;
  options.threads = threads;
  return render(scene, options);
}

std::vector<std::uint8_t> bytesOf(const Film& film) {
  std::vector<std::uint8_t> bytes;
  for (const Color& c : film.pixels()) {
    for (const double v : {c.r, c.g, c.b}) bytes.push_back(encodeChannel(v, Encoding::Srgb));
  }
  return bytes;
}

// An instance finds the same surfaces at the same t as the transformed object (its rays enter by
// the same inverse matrix), but its world hit points come from a forward matrix re-derived from
// that inverse (instances.h: the record keeps only the inverse), and a mesh object's transform is
// applied to its vertices at load while an instance maps the ray instead. Hit points, and so the
// shading and the spawned rays, differ in their last bits; an 8-bit code could differ only where a
// value lies within that of a rounding boundary of the encoding: the bytes are the same. The
// linear difference is measured too (at most ~1e-15 relative when this was written).
void expectSameBytes(const Film& actual, const Film& expected) {
  EXPECT_EQ(bytesOf(actual), bytesOf(expected));
  ASSERT_EQ(actual.pixels().size(), expected.pixels().size());
  double worst = 0;
  for (std::size_t i = 0; i < actual.pixels().size(); ++i) {
    const Color& a = actual.pixels()[i];
    const Color& e = expected.pixels()[i];
    for (const double d : {a.r - e.r, a.g - e.g, a.b - e.b}) worst = std::max(worst, std::abs(d));
  }
  EXPECT_LT(worst, 1e-9);
}

// The scene with `object` written out (with `transform` on it), and the scene with `object` as
// the only member of a group placed by an instance with that transform.
std::string writtenOut(const std::string& object) {
  return kStage + "objects:\n" + kFloor + "  - {" + object + ", transform: " + kTransform + "}\n";
}
std::string instanced(const std::string& object, const std::string& instanceExtra = "") {
  return kStage + "groups:\n  thing: [{" + object + "}]\nobjects:\n" + kFloor +
         "  - {type: instance, group: thing, transform: " + kTransform + instanceExtra + "}\n";
}

std::size_t litPixels(const Film& film, const Film& background) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < film.pixels().size(); ++i) {
    if (!(film.pixels()[i] == background.pixels()[i])) ++n;
  }
  return n;
}

// `object` placed by an instance renders the bytes of `object` written out, and shows in the image
// (it and its shadow and reflection change more than 500 pixels of the empty stage).
void expectInstanceRendersAsWrittenOut(const std::string& object) {
  SCOPED_TRACE(object);
  const Film empty = renderText(kStage + "objects:\n" + kFloor);
  const Film expected = renderText(writtenOut(object));
  expectSameBytes(renderText(instanced(object)), expected);
  EXPECT_GT(litPixels(expected, empty), 500u);
}

TEST(Instancing, SphereAndBoxInstancesRenderTheSameBytesAsTransformedObjects) {
  for (const std::string& object :
       {std::string("type: sphere, center: [0, 0.2, 0], radius: 1, material: red"),
        std::string("type: box, min: [-1, -0.5, -0.7], max: [0.8, 1, 0.6], material: red"),
        std::string("type: sphere, center: [0, 0.2, 0], radius: 1, material: glass")}) {
    expectInstanceRendersAsWrittenOut(object);
  }
}

TEST(Instancing, MeshInstanceRendersTheSameBytesAsTheTransformedMesh) {
  const std::string mesh =
      "type: mesh, smooth: true, material: red, positions: [[-1, -0.5, -1], [1, -0.5, -1], "
      "[1, -0.5, 1], [-1, -0.5, 1], [0, 1.2, 0], [0, -1.4, 0]], indices: [[0, 1, 4], [1, 2, 4], "
      "[2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]]";
  expectInstanceRendersAsWrittenOut(mesh);
}

TEST(Instancing, ManyInstancesEqualTheWrittenOutObjectsOnAnyThreadCount) {
  std::string groups =
      "groups:\n  pair:\n"
      "    - {type: sphere, center: [0, 0.5, 0], radius: 0.5}\n"
      "    - {type: box, min: [0.6, 0, -0.3], max: [1.2, 0.6, 0.3], "
      "material: blue}\n";
  std::string instances;
  std::string flat;
  for (int k = 0; k < 12; ++k) {
    const std::string t = "[{rotate: {axis: [0, 1, 0], angle: " + std::to_string(k * 30) +
                          "}}, {translate: [" + std::to_string(-4.5 + 0.8 * k) + ", -1, " +
                          std::to_string(-1.0 * (k % 3)) + "]}]";
    instances += "  - {type: instance, group: pair, material: red, transform: " + t + "}\n";
    flat += "  - {type: sphere, center: [0, 0.5, 0], radius: 0.5, material: red, transform: " + t +
            "}\n";
    flat +=
        "  - {type: box, min: [0.6, 0, -0.3], max: [1.2, 0.6, 0.3], material: blue, "
        "transform: " +
        t + "}\n";
  }
  const Film expected = renderText(kStage + "objects:\n" + kFloor + flat);
  const std::string scene = kStage + groups + "objects:\n" + kFloor + instances;
  const Film one = renderText(scene, 1);
  const Film two = renderText(scene, 2);
  expectSameBytes(one, expected);  // the material replaced only the sphere's
  EXPECT_TRUE(std::ranges::equal(two.pixels(), one.pixels()));
}

TEST(Instancing, InstanceMaterialReplacesOnlyMissingMaterials) {
  const std::string object = "type: sphere, center: [0, 0.2, 0], radius: 1";
  // Without a material of its own the sphere takes the instance's...
  expectSameBytes(renderText(instanced(object, ", material: red")),
                  renderText(writtenOut(object + ", material: red")));
  // ...with one it keeps it.
  expectSameBytes(renderText(instanced(object + ", material: blue", ", material: red")),
                  renderText(writtenOut(object + ", material: blue")));
  // A transparent material given by the instance also changes its shadows (the group is built
  // once more with that kt).
  expectSameBytes(renderText(instanced(object, ", material: glass")),
                  renderText(writtenOut(object + ", material: glass")));
}

// A csg's shadow counts each crossing of its surface with the crossed operand's kt (csg.h); inside
// a group as in the world. Here the glass sphere's shadow on the floor falls through the glass
// operand and the red (opaque) one's, and an instance's material given to a csg without one
// reaches every operand's shadow too.
TEST(Instancing, ATransparentCsgCastsTheSameShadowInAGroup) {
  const std::string csg =
      "type: csg, operation: union, operands: [{type: sphere, center: [-0.5, 0.2, 0], radius: "
      "0.8, material: glass}, {type: box, min: [0.2, -0.4, -0.4], max: [1.2, 0.6, 0.4], "
      "material: red}]";
  expectInstanceRendersAsWrittenOut(csg);
  // The same union without operand materials, glass given by the instance.
  const std::string open =
      "type: csg, operation: union, operands: [{type: sphere, center: [-0.5, 0.2, 0], radius: "
      "0.8}, {type: box, min: [0.2, -0.4, -0.4], max: [1.2, 0.6, 0.4]}]";
  const std::string closed =
      "type: csg, operation: union, material: glass, operands: [{type: sphere, center: [-0.5, "
      "0.2, 0], radius: 0.8}, {type: box, min: [0.2, -0.4, -0.4], max: [1.2, 0.6, 0.4]}]";
  expectSameBytes(renderText(instanced(open, ", material: glass")), renderText(writtenOut(closed)));
}

TEST(Instancing, SolidTexturesFollowTheInstance) {
  const std::string stage = kStage +
                            "textures:\n  checks: {type: checker, scale: 0.5, "
                            "colors: [[1, 1, 1], [0.1, 0.1, 0.1]]}\n";
  const std::string sphere =
      "type: sphere, center: [0, 0.2, 0], radius: 1, material: {kd: checks, ks: 0.2}";
  const Film expected = renderText(stage + "objects:\n" + kFloor + "  - {" + sphere +
                                   ", transform: " + kTransform + "}\n");
  const Film actual =
      renderText(stage + "groups:\n  thing: [{" + sphere + "}]\nobjects:\n" + kFloor +
                 "  - {type: instance, group: thing, transform: " + kTransform + "}\n");
  EXPECT_EQ(bytesOf(actual), bytesOf(expected));
}

TEST(Instancing, AGlowingInstanceIsLightEnoughForTheUnlitSceneWarning) {
  const std::string base = std::string(testing::kMinimal) +
                           "groups:\n  lamp: [{type: sphere, center: [0, 0, 0], radius: 1, "
                           "emission: [1, 1, 1]}]\n  ball: [{type: sphere, center: [0, 0, 0], "
                           "radius: 1}]\nobjects:\n";
  EXPECT_TRUE(loadSceneFromString(base + "  - {type: instance, group: lamp}\n", "test.yaml")
                  .warnings.empty());
  EXPECT_TRUE(loadSceneFromString(base + "  - {type: instance, group: ball, material: {kr: 1}}\n",
                                  "test.yaml")
                  .warnings.empty());
  const std::vector<Diagnostic> dark =
      loadSceneFromString(base + "  - {type: instance, group: ball}\n", "test.yaml").warnings;
  ASSERT_EQ(dark.size(), 1u);
  EXPECT_THAT(dark[0].message, HasSubstr("every object will render black"));
}

class IncludedGroups : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("glint_instancing_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  std::vector<std::string> errorsIn(const std::string& name) {
    std::vector<std::string> out;
    try {
      loadScene(dir_ / name);
    } catch (const SceneError& e) {
      for (const Diagnostic& d : e.diagnostics()) {
        std::string s = d.format();
        const std::string prefix = (dir_ / "").string();
        for (std::size_t p; (p = s.find(prefix)) != std::string::npos;) s.erase(p, prefix.size());
        out.push_back(s);
      }
    }
    return out;
  }
  fs::path dir_;
};

TEST_F(IncludedGroups, GroupsComeFromIncludedFilesAndDuplicatesNameBothPlaces) {
  write("lib.yaml",
        "materials: {gold: {kd: [1, 0.8, 0.2]}}\n"
        "groups:\n  ball: [{type: sphere, center: [0, 0, 0], radius: 1, "
        "material: gold}]\n");
  write("scene.yaml", "include: lib.yaml\n" + std::string(testing::kMinimal) +
                          "objects:\n  - {type: instance, group: ball, transform: "
                          "[{translate: [0, 0, -5]}]}\n");
  const LoadedScene loaded = loadScene(dir_ / "scene.yaml");
  ASSERT_EQ(loaded.parts.instances.size(), 1u);
  ASSERT_EQ(loaded.parts.groups.size(), 1u);
  EXPECT_EQ(loaded.parts.groups[0].primitives.size(), 1u);
  write("twice.yaml",
        "include: lib.yaml\n" + std::string(testing::kMinimal) + "groups:\n  ball: []\n");
  EXPECT_EQ(errorsIn("twice.yaml"),
            (std::vector<std::string>{"twice.yaml:5:3: duplicate group 'ball': defined twice "
                                      "(first at lib.yaml:3:3)"}));
  write("loop.yaml", "include: scene2.yaml\ngroups: {a: []}\n");
  write("scene2.yaml", "include: loop.yaml\n" + std::string(testing::kMinimal));
  const std::vector<std::string> errors = errorsIn("scene2.yaml");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_THAT(errors[0], HasSubstr("loop.yaml:1:10: include cycle: scene2.yaml -> loop.yaml"));
}

TEST(InstancingErrors, AreReportedAtTheirPlace) {
  const std::string base = testing::kMinimal;
  expectOneError(base + "objects:\n  - {type: instance, group: chiar}\n", 4, 29,
                 "instance.group: undefined group 'chiar'; no groups are defined");
  expectOneError(base + "groups: {chair: []}\nobjects:\n  - {type: instance, group: chiar}\n", 5,
                 29, "undefined group 'chiar' (did you mean 'chair'?)");
  expectOneError(base + "groups: {chair: []}\nobjects:\n  - {type: instance}\n", 5, 5,
                 "missing required key 'group'");
  expectOneError(base +
                     "groups: {chair: []}\nobjects:\n  - {type: instance, group: chair, "
                     "emission: [1, 1, 1]}\n",
                 5, 36, "unknown key 'emission' in instance");
  expectOneError(base +
                     "groups: {chair: []}\nobjects:\n  - {type: instance, group: chair, "
                     "scale: 2}\n",
                 5, 36, "unknown key 'scale'");
  // Two levels: a group holds no instances, so none can instance itself.
  expectOneError(base + "groups:\n  chair: [{type: instance, group: chair}]\n", 4, 18,
                 "groups.chair[0]: an instance cannot be inside a group");
  expectOneError(base + "groups:\n  chair: [{type: sphere, center: [0, 0, 0], radius: -1}]\n", 4,
                 53, "radius must be > 0");
  expectOneError(base + "groups:\n  chair: [{type: spehre}]\n", 4, 18, "did you mean 'sphere'");
  expectOneError(base + "groups:\n  chair: {type: sphere}\n", 4, 10,
                 "groups.chair: expected a list of objects, got a mapping");
  expectOneError(base +
                     "groups: {chair: []}\nobjects:\n  - {type: instance, group: chair, "
                     "transform: [{scale: 0}]}\n",
                 5, 56, "instance.transform[0].scale factors must be non-zero");
  // As a placed object's: the transform invertible in double precision and the placed group
  // within ±1e100 of the origin (a scale of 1e150 rendered nothing, without a word).
  const std::string ball =
      "groups:\n  ball: [{type: sphere, center: [0, 0, 0], radius: 1}, {type: plane, point: [0, "
      "-1, 0], normal: [0, 1, 0]}]\nobjects:\n  - {type: instance, group: ball, transform: ";
  expectOneError(base + ball + "[{scale: 1e150}]}\n", 6, 46,
                 "instance.transform: transform must be invertible, got determinant inf");
  expectOneError(base + ball + "[{scale: 1e-300}]}\n", 6, 46,
                 "instance.transform: transform must be invertible, got determinant 0");
  expectOneError(base + ball + "[{translate: [0, 0, -1e120]}]}\n", 6, 46,
                 "instance.transform: the placed group reaches 1e+120 from the origin, beyond the "
                 "±1e+100 glint computes in");
}

// An instance of an empty group (`chair:` or `chair: []`) shows nothing: said at its group.
TEST(Instancing, AnInstanceOfAnEmptyGroupIsWarnedAbout) {
  const LoadedScene loaded =
      loadSceneFromString(std::string(testing::kMinimal) +
                              "groups:\n  chair:\nobjects:\n  - {type: instance, group: chair}\n",
                          "empty.yaml");
  ASSERT_EQ(loaded.warnings.size(), 2u);  // and the scene's own "no lights"
  EXPECT_EQ(loaded.warnings[1].format(),
            "empty.yaml:6:29: warning: instance.group: the group 'chair' is empty, so this "
            "instance shows nothing");
}

}  // namespace
}  // namespace glint
