// Scene-file reading (DESIGN.md §5, §7, §8): the text → SceneDescription half (entities whose
// values keep their places), and the error reporting of loadSceneFromString for problems of
// structure, type and syntax, each at its line and column.
#include "glint/readers/yaml_scene_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "glint/factories/scene_loader.h"
#include "glint/factories/scene_test_support.h"

namespace glint {
namespace {

using testing::errorsOf;
using testing::expectOneError;
using ::testing::HasSubstr;
using testing::kDesignExample;
using testing::kMinimal;

// Reads the values of a description as the factories would, for tests: an entity's parameter by a
// path of keys, typed, with its place.
class Look {
 public:
  explicit Look(const SceneDescription& d) : d_(d) {}
  const Entity& entity(EntityKind kind, std::size_t n = 0) const {
    for (const Entity& e : d_.entities) {
      if (e.kind == kind && n-- == 0) return e;
    }
    ADD_FAILURE() << "no such entity";
    return d_.entities.front();
  }
  std::size_t count(EntityKind kind) const { return d_.count(kind); }
  // The value at `keys` below the entity's mapping (nested mappings), or kNoValue.
  ValueId at(const Entity& e, std::initializer_list<std::string_view> keys) const {
    ValueId v = e.value;
    for (const std::string_view key : keys) {
      const ValueTree& t = tree(e);
      ValueId next = kNoValue;
      for (std::size_t i = 0; t.isMap(v) && i < t.size(v); ++i) {
        if (t.scalar(t.key(v, i)) == key) next = t.value(v, i);
      }
      v = next;
    }
    return v;
  }
  bool has(const Entity& e, std::initializer_list<std::string_view> keys) const {
    return at(e, keys) != kNoValue;
  }
  TextPosition where(const Entity& e, ValueId v) const { return tree(e).position(v); }
  std::string_view text(const Entity& e, ValueId v) const { return tree(e).scalar(v); }
  double number(const Entity& e, ValueId v) { return reader(e).number(v, v, {}).value_or(-999); }
  Vec3 vec3(const Entity& e, ValueId v) { return reader(e).vec3(v, v, {}).value_or(Vec3{}); }
  Point3 point3(const Entity& e, ValueId v) {
    return reader(e).point3(v, v, {}).value_or(Point3{});
  }
  ColorValue color(const Entity& e, ValueId v) {
    return reader(e).color(v, v, {}).value_or(ColorValue{});
  }
  const ValueTree& tree(const Entity& e) const { return d_.fileOf(e).values; }

 private:
  ValueReader reader(const Entity& e) { return ValueReader(d_.fileOf(e).source(), sink_); }
  const SceneDescription& d_;
  Diagnostics sink_;
};

TEST(SceneParser, DesignExampleParsesWithLocations) {
  const ParseResult r = parseScene(kDesignExample, "scene.yaml", "/scenes");
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  const SceneDescription& d = r.description;
  Look look(d);
  EXPECT_TRUE(d.complete);
  EXPECT_EQ(d.files.at(0)->name, "scene.yaml");
  EXPECT_EQ(d.files.at(0)->baseDirectory, std::filesystem::path("/scenes"));
  ASSERT_NE(d.name, kNoValue);
  EXPECT_EQ(d.files.at(0)->values.scalar(d.name), "basic render");
  const Entity& background = look.entity(EntityKind::BackgroundEntity);
  EXPECT_TRUE(look.color(background, background.value).isHex);
  EXPECT_EQ(look.color(background, background.value).code,
            (std::array<std::uint8_t, 3>{0x4b, 0x7f, 0x5a}));
  EXPECT_EQ(look.where(background, background.value).line, 2u);
  EXPECT_EQ(look.where(background, background.value).column, 13u);

  const Entity& camera = look.entity(EntityKind::CameraEntity);
  ASSERT_TRUE(look.has(camera, {"view_plane"}) && look.has(camera, {"direction"}) &&
              look.has(camera, {"up"}));
  EXPECT_EQ(look.vec3(camera, look.at(camera, {"direction"})), (Vec3{0, 0, -1}));
  EXPECT_EQ(look.where(camera, look.at(camera, {"direction"})).line, 6u);
  EXPECT_EQ(look.where(camera, look.at(camera, {"direction"})).column, 14u);
  EXPECT_EQ(look.number(camera, look.at(camera, {"view_plane", "distance"})), 100);
  EXPECT_FALSE(look.has(camera, {"fov"}));

  const Entity& image = look.entity(EntityKind::ImageEntity);
  ASSERT_TRUE(look.has(image, {"grid"}) && look.has(image, {"encoding"}));
  EXPECT_EQ(look.number(image, look.at(image, {"width"})), 1000);
  EXPECT_EQ(look.text(image, look.at(image, {"encoding"})), "srgb");
  EXPECT_EQ(look.number(image, look.at(image, {"grid", "interval"})), 100);
  const Entity& render = look.entity(EntityKind::RenderEntity);
  EXPECT_EQ(look.number(render, look.at(render, {"max_depth"})), 10);
  EXPECT_EQ(look.number(render, look.at(render, {"min_weight"})), 0.001);
  EXPECT_EQ(look.number(render, look.at(render, {"seed"})), 0);

  ASSERT_EQ(look.count(EntityKind::MaterialEntity), 1u);
  const Entity& glass = look.entity(EntityKind::MaterialEntity);
  EXPECT_EQ(look.text(glass, glass.name), "glass");
  EXPECT_EQ(look.number(glass, look.at(glass, {"ior"})), 1.5);
  EXPECT_EQ(look.number(glass, look.at(glass, {"kt"})), 0.9);
  EXPECT_FALSE(look.has(glass, {"kr"}));

  ASSERT_EQ(look.count(EntityKind::ObjectEntity), 2u);
  const Entity& sphere = look.entity(EntityKind::ObjectEntity, 0);
  EXPECT_EQ(look.text(sphere, sphere.type), "sphere");
  EXPECT_EQ(look.where(sphere, sphere.value).line, 25u);
  EXPECT_EQ(look.where(sphere, sphere.value).column, 5u);
  EXPECT_EQ(look.text(sphere, look.at(sphere, {"material"})), "glass");
  const Entity& triangle = look.entity(EntityKind::ObjectEntity, 1);
  EXPECT_EQ(look.text(triangle, triangle.type), "triangle");
  EXPECT_EQ(look.tree(triangle).size(look.at(triangle, {"vertices"})), 3u);
  ASSERT_TRUE(look.tree(triangle).isMap(look.at(triangle, {"material"})));
  EXPECT_EQ(look.number(triangle, look.at(triangle, {"material", "shininess"})), 60);
  EXPECT_EQ(look.color(triangle, look.at(triangle, {"emission"})).code,
            (std::array<std::uint8_t, 3>{0xff, 0, 0}));

  ASSERT_EQ(look.count(EntityKind::LightEntity), 1u);
  const Entity& spot = look.entity(EntityKind::LightEntity);
  EXPECT_EQ(look.text(spot, spot.type), "spot");
  EXPECT_EQ(look.vec3(spot, look.at(spot, {"attenuation"})), (Vec3{1, 0.00001, 0.00000001}));
  EXPECT_EQ(look.where(spot, spot.value).line, 29u);
}

TEST(SceneParser, JsonInputWorks) {
  const std::string json = R"({
  "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 45},
  "image": {"width": 64, "height": 48, "encoding": "linear"},
  "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.5E+0,
               "material": {"kd": [0.5, 0.25, 1]}}],
  "lights": [{"type": "point", "position": [1, 2, 3], "intensity": 2}]
})";
  const LoadedScene s = loadSceneFromString(json, "scene.json");
  EXPECT_EQ(s.parts.image.width, 64);
  EXPECT_EQ(s.parts.image.encoding, Encoding::Linear);
  ASSERT_EQ(s.parts.primitives.size(), 1u);
  EXPECT_EQ(std::get<Sphere>(s.parts.primitives[0].shape()).radius, 1.5);
  EXPECT_EQ(s.parts.materials.at(1).kd, Color(0.5, 0.25, 1));
  ASSERT_EQ(s.parts.lights.size(), 1u);
  EXPECT_EQ(std::get<PointLight>(s.parts.lights[0]).intensity, Color(2));
}

TEST(SceneParser, NumbersInAnyUsualNotation) {
  const ParseResult r = parseScene(std::string(kMinimal) +
                                       "lights:\n"
                                       "  - {type: point, position: [1e-5, 1.5E+3, 0.00001],\n"
                                       "     attenuation: [+2, .5, -3.25e2], intensity: 7.}\n",
                                   "t.yaml");
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  Look look(r.description);
  const Entity& light = look.entity(EntityKind::LightEntity);
  EXPECT_EQ(look.point3(light, look.at(light, {"position"})), (Point3{1e-5, 1500, 0.00001}));
  EXPECT_EQ(look.vec3(light, look.at(light, {"attenuation"})), (Vec3{2, 0.5, -325}));
  EXPECT_EQ(look.number(light, look.at(light, {"intensity"})), 7);
}

TEST(SceneParser, UnknownKeyAtTheKeyWithSuggestion) {
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, 0], radus: 2}\n", 4, 39,
      "unknown key 'radus' in sphere; expected one of: center, radius, material, "
      "emission, transform");
  const std::vector<Diagnostic> errors = errorsOf(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, 0], radus: 2}\n");
  ASSERT_FALSE(errors.empty());
  EXPECT_THAT(errors[0].message, HasSubstr("did you mean 'radius'?"));
  expectOneError(std::string(kMinimal) + "camra: {}\n", 3, 1,
                 "unknown key 'camra' at the top level");
  expectOneError(std::string(kMinimal) + "render: {max_dept: 3}\n", 3, 10,
                 "did you mean 'max_depth'?");
}

TEST(SceneParser, DuplicateKeyAtTheSecondOccurrence) {
  expectOneError(std::string(kMinimal) +
                     "objects:\n"
                     "  - type: sphere\n"
                     "    center: [0, 0, 0]\n"
                     "    radius: 1\n"
                     "    radius: 2\n",
                 7, 5, "duplicate key 'radius' in sphere (first at line 6, column 5)");
  expectOneError(
      "image: {width: 4, height: 3}\n"
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40, fov: 50}\n",
      2, 63, "duplicate key 'fov'");
}

TEST(SceneParser, MaterialDefinedTwice) {
  expectOneError(std::string(kMinimal) +
                     "materials:\n"
                     "  red: {kd: [1, 0, 0]}\n"
                     "  red: {kd: 1}\n",
                 5, 3, "duplicate material 'red': defined twice (first at line 4, column 3)");
}

TEST(SceneParser, SeveralDocumentsRejected) {
  expectOneError(std::string(kMinimal) + "---\n" + kMinimal, 3, 1, "more than one YAML document");
  expectOneError(std::string(kMinimal) + "---\n", 3, 1, "more than one YAML document");
  // yaml-cpp 0.7's LoadAll never returns on a stray ',' outside brackets; the loader must.
  expectOneError(",", 1, 1, "unexpected ',' here");
  const std::vector<Diagnostic> errors = errorsOf(
      "{camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}, image: {width: 4, "
      "height: 3}},\n");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].format(), "test.yaml:1:94: syntax error: unexpected ',' here");
}

TEST(SceneParser, SyntaxErrorAtItsMark) {
  const std::vector<Diagnostic> errors = errorsOf("camera: {position: [0, 0, 0]\nimage: 3\n");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].where.line, 2);
  EXPECT_THAT(errors[0].message, HasSubstr("'{' is not closed"));
  EXPECT_THAT(errors[0].message, ::testing::Not(HasSubstr("yaml-cpp")));
  expectOneError("camera:\n\tposition: [0, 0, 0]\n", 2, 1, "tabs are not allowed");
  // At the escape sequence itself (yaml-cpp, the reader before libyaml, put it two columns on).
  expectOneError("name: \"a\\qb\"\n", 1, 9, "unknown escape sequence in quoted text: \\q");
  // libyaml's own words for a \x without its digits ("did not find expected hexdecimal number")
  // are not shown.
  expectOneError("name: \"\\xZZ\"\n", 1, 10,
                 "an escape sequence in quoted text lacks its hexadecimal digits (\\xHH, "
                 "\\uHHHH or \\UHHHHHHHH)");
}

// Every syntax problem libyaml reports is worded for the scene's author: tags, anchors, block
// scalars, directives and explicit keys included (libyaml says "found undefined tag handle", "did
// not find expected alphabetic or numeric character", ...).
TEST(SceneParser, RarerSyntaxErrorsInPlainWords) {
  const std::string kLine2 = "camera: {position: [0, 0, 5], look_at: [0, 0, 0], fov: 40}\n";
  const std::string head = "image: {width: 8, height: 8}\n" + kLine2;
  expectOneError(head + "name: [a, 1:, b]\n", 3, 12, "syntax error: unexpected ':' here");
  for (const char* tag : {"name: !foo!bar x\n", "name: !<foo x\n"}) {
    const std::vector<Diagnostic> errors = errorsOf(head + tag);
    ASSERT_EQ(errors.size(), 1u) << tag;
    EXPECT_THAT(errors[0].message, HasSubstr("a malformed YAML tag")) << tag;
  }
  expectOneError(head + "name: & x\n", 3, 8,
                 "an anchor ('&') or alias ('*') needs a name of letters, digits, '-' or '_'");
  expectOneError(head + "name: |0\n", 3, 8,
                 "the indentation digit after '|' or '>' must be 1 to 9");
  expectOneError(head + "name: ? complex\n", 3, 7, "unexpected '?' here");
  expectOneError("%YAML 2.0\n---\n" + head, 1, 1,
                 "the %YAML line asks for a YAML version other than 1.x");
  expectOneError("%YAML 1.1\n%YAML 1.1\n---\n" + head, 2, 1, "the %YAML line is given twice");
  expectOneError(head + "name: \"abc\n---\nx\"\n", 4, 1,
                 "a line inside quoted text starts with '---' or '...'");
}

TEST(SceneParser, EmptyOrNonMappingFileAtLineOne) {
  expectOneError("", 1, 1, "the file is empty");
  expectOneError("# only a comment\n\n", 1, 1, "the file is empty");
  expectOneError("- camera\n- image\n", 1, 1, "must be a mapping");
  expectOneError("42\n", 1, 1, "must be a mapping");
}

TEST(SceneParser, MissingRequiredKeys) {
  // A missing top-level section has no place of its own: line 1, column 1.
  expectOneError("image: {width: 4, height: 3}\n", 1, 1, "missing required key 'camera'");
  expectOneError("camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n", 1, 1,
                 "missing required key 'image'");
  // Otherwise the mapping that lacks the key.
  expectOneError(std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, 0]}\n", 4, 5,
                 "sphere is missing required key 'radius'");
  expectOneError("camera:\n  direction: [0, 0, -1]\n  fov: 40\nimage: {width: 4, height: 3}\n", 2,
                 3, "camera is missing required key 'position'");
  expectOneError("camera: {position: [0, 0, 0], fov: 40}\nimage: {width: 4, height: 3}\n", 1, 9,
                 "camera needs 'direction' or 'look_at'");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, 1]}\nimage: {width: 4, height: 3}\n", 1, 9,
      "camera needs 'view_plane' or 'fov'");
  expectOneError(std::string(kMinimal) + "objects:\n  - {center: [0, 0, 0], radius: 1}\n", 4, 5,
                 "missing required key 'type'");
  expectOneError(std::string(kMinimal) + "lights:\n  - {type: spot, position: [0, 0, 0]}\n", 4, 5,
                 "spot light is missing required key 'direction'");
  expectOneError(std::string(kMinimal) + "objects:\n  - {type: plane, point: [0, 0, 0]}\n", 4, 5,
                 "plane is missing required key 'normal'");
}

TEST(SceneParser, WrongTypesAtTheValue) {
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, 0], radius: abc}\n", 4,
      47, "sphere.radius: expected a number, got 'abc'");
  expectOneError(std::string(kMinimal) + "objects:\n  - {type: sphere, center: 5, radius: 1}\n", 4,
                 28, "sphere.center: expected a list of 3 numbers [x, y, z], got '5'");
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [1, 2], radius: 1}\n", 4, 28,
      "expected a list of 3 numbers [x, y, z], got a list of 2 items");
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [1, x, 3], radius: 1}\n", 4, 32,
      "sphere.center[1]: expected a number, got 'x'");
  expectOneError(std::string(kMinimal) + "background: red\n", 3, 13,
                 "expected a color [r, g, b] or \"#rrggbb\", got 'red'");
  expectOneError(std::string(kMinimal) + "background: \"#12345g\"\n", 3, 13,
                 "6 hexadecimal digits");
  expectOneError(
      std::string(kMinimal) + "materials: {m: {kd: {r: 1}}}\n", 3, 21,
      "materials.m.kd is missing required key 'type' (one of: checker, checker2d, noise, marble, "
      "wood, image)");  // a mapping is a texture
  expectOneError(std::string(kMinimal) + "materials: {m: {kd: [1, 2]}}\n", 3, 21,
                 "materials.m.kd: expected a list of 3 numbers [r, g, b], got a list of 2 items");
  expectOneError(std::string(kMinimal) + "objects: {type: sphere}\n", 3, 10,
                 "objects: expected a list of objects, got a mapping");
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: triangle, vertices: [[0, 0, 0], [1, 0, 0]]}\n",
      4, 32, "expected a list of 3 points");
  expectOneError(std::string(kMinimal) + "image2: 1\n", 3, 1, "unknown key 'image2'");
}

TEST(SceneParser, EmptyValueReportedAtItsKey) {
  expectOneError(std::string(kMinimal) + "objects:\n  - type: sphere\n    center:\n    radius: 1\n",
                 5, 5, "sphere.center: expected a list of 3 numbers [x, y, z], got nothing");
}

TEST(SceneParser, WholeNumbersWhereIntegersAreNeeded) {
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image: {width: 1.5, height: 3}\n",
      2, 16, "image.width: expected a whole number, got 1.5");
  const LoadedScene s = loadSceneFromString(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image: {width: 1e3, height: 2.0E2}\n"
      "render: {seed: 18446744073709551615}\n",
      "t.yaml");
  EXPECT_EQ(s.parts.image.width, 1000);
  EXPECT_EQ(s.parts.image.height, 200);
  EXPECT_EQ(s.parts.render.seed, 18446744073709551615u);
  expectOneError(std::string(kMinimal) + "render: {seed: -1}\n", 3, 16,
                 "render.seed must be between 0");
}

TEST(SceneParser, NanAndInfinityRejectedEverywhere) {
  expectOneError(std::string(kMinimal) + "render: {min_weight: .nan}\n", 3, 22,
                 "render.min_weight must be a finite number, got .nan");
  expectOneError(std::string(kMinimal) + "ambient: {intensity: .inf}\n", 3, 22, "finite");
  expectOneError(std::string(kMinimal) + "background: [0, -.inf, 0]\n", 3, 17,
                 "background[1] must be a finite");
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1e999}\n", 4,
      47, "finite");
  expectOneError(std::string(kMinimal) + "lights:\n  - {type: point, position: [nan, 0, 0]}\n", 4,
                 30, "finite");
}

TEST(SceneParser, ConflictingChoicesAtTheLaterKey) {
  expectOneError(
      "camera:\n  position: [0, 0, 0]\n  direction: [0, 0, -1]\n  look_at: [0, 0, -5]\n"
      "  fov: 40\nimage: {width: 4, height: 3}\n",
      4, 3, "camera has both 'direction' and 'look_at'");
  expectOneError(
      "camera:\n  position: [0, 0, 0]\n  fov: 40\n  direction: [0, 0, -1]\n"
      "  view_plane: {width: 1, height: 1, distance: 1}\nimage: {width: 4, height: 3}\n",
      5, 3, "camera has both 'view_plane' and 'fov'");
  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: plane, points: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "
                     "normal: [0, 0, 1]}\n",
                 4, 62, "plane has both 'points' and 'point'/'normal'");
}

TEST(SceneParser, MeshKeys) {
  const ParseResult r = parseScene(std::string(kMinimal) +
                                       "objects:\n"
                                       "  - type: mesh\n"
                                       "    file: models/bunny.obj\n"
                                       "    smooth: false\n"
                                       "    material: {kd: 0.5}\n"
                                       "    emission: [0.1, 0, 0]\n"
                                       "    transform: [{scale: 2}]\n"
                                       "  - {type: mesh, file: \"a b.ply\"}\n",
                                   "test.yaml", "/scenes");
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  const SceneDescription& d = r.description;
  Look look(d);
  EXPECT_EQ(d.files.at(0)->baseDirectory, std::filesystem::path("/scenes"));
  ASSERT_EQ(look.count(EntityKind::ObjectEntity), 2u);
  const Entity& mesh = look.entity(EntityKind::ObjectEntity, 0);
  EXPECT_EQ(look.text(mesh, mesh.type), "mesh");
  const ValueId file = look.at(mesh, {"file"});
  ASSERT_NE(file, kNoValue);
  EXPECT_EQ(look.text(mesh, file), "models/bunny.obj");
  EXPECT_EQ(look.where(mesh, file).line, 5u);
  EXPECT_EQ(look.where(mesh, file).column, 11u);
  const ValueId smooth = look.at(mesh, {"smooth"});
  ASSERT_NE(smooth, kNoValue);
  EXPECT_EQ(look.text(mesh, smooth), "false");
  EXPECT_EQ(look.where(mesh, smooth).line, 6u);
  EXPECT_TRUE(look.tree(mesh).isMap(look.at(mesh, {"material"})));
  EXPECT_TRUE(look.has(mesh, {"emission"}));
  EXPECT_EQ(look.tree(mesh).size(look.at(mesh, {"transform"})), 1u);
  const Entity& second = look.entity(EntityKind::ObjectEntity, 1);
  ASSERT_TRUE(look.has(second, {"file"}));
  EXPECT_EQ(look.text(second, look.at(second, {"file"})), "a b.ply");
  EXPECT_FALSE(look.has(second, {"smooth"}));  // default: the builder's true
}

TEST(SceneParser, MeshKeyErrors) {
  const std::string objects = std::string(kMinimal) + "objects:\n";
  expectOneError(objects + "  - {type: mesh}\n", 4, 5, "mesh is missing required key 'file'");
  expectOneError(objects + "  - {type: mesh, file: a.obj, smooth: yes}\n", 4, 39,
                 "mesh.smooth: expected true or false, got 'yes'");
  expectOneError(objects + "  - {type: mesh, file: [a.obj]}\n", 4, 24,
                 "mesh.file: expected text, got a list of 1 item");
  expectOneError(objects + "  - {type: mesh, file: a.obj, smoth: true}\n", 4, 31,
                 "unknown key 'smoth' in mesh; expected one of: file, smooth, positions, normals, "
                 "colors, indices, material, emission, transform (did you mean 'smooth'?)");
  // Another shape's key is only unknown here (one error, not also a type error).
  expectOneError(objects + "  - {type: mesh, file: a.obj, radius: 1}\n", 4, 31,
                 "unknown key 'radius' in mesh");
  expectOneError(objects + "  - {type: sphere, center: [0, 0, 0], radius: 1, file: 1}\n", 4, 50,
                 "unknown key 'file' in sphere");
  expectOneError(std::string(kMinimal) +
                     "lights:\n  - {type: point, position: [0, 0, 0], "
                     "direction: 1}\n",
                 4, 40, "unknown key 'direction' in point light");
}

TEST(SceneParser, UnknownTypesListTheKnownOnes) {
  expectOneError(std::string(kMinimal) + "lights:\n  - {type: laser, position: [0, 0, 0]}\n", 4, 12,
                 "unknown light type 'laser'; expected one of: directional, point, spot, area");
  expectOneError(
      std::string(kMinimal) + "objects:\n  - {type: sphre}\n", 4, 12,
      "unknown object type 'sphre'; expected one of: sphere, plane, triangle, polygon, "
      "rectangle, quadrangle, tube, cylinder, box, disk, cone, mesh, csg, instance (did you mean "
      "'sphere'?)");
  expectOneError(std::string(kMinimal) + "lights:\n  - {type: ambient}\n", 4, 12,
                 "top-level key 'ambient'");
  expectOneError(std::string(kMinimal) + "image2: {}\n", 3, 1, "did you mean 'image'?");
  expectOneError(
      "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image: {width: 4, height: 3, encoding: srbg}\n",
      2, 40, "image.encoding must be srgb or linear, got 'srbg' (did you mean 'srgb'?)");
}

// The column (1-based) where `token` first starts in `line`: positions written as what they point
// at rather than as bare numbers.
int columnOf(const std::string& line, const std::string& token) {
  const std::size_t at = line.find(token);
  EXPECT_NE(at, std::string::npos) << token << " not in " << line;
  return static_cast<int>(at) + 1;
}

TEST(SceneParser, AreaLightKeysOfEachShape) {
  const ParseResult r = parseScene(
      std::string(kMinimal) +
          "lights:\n"
          "  - type: area\n"
          "    shape: rectangle\n"
          "    corner: [-1, 4, -1]\n"
          "    edges: [[2, 0, 0], [0, 0, 3]]\n"
          "    color: [1, 0.9, 0.8]\n"
          "    intensity: 2\n"
          "    attenuation: [1, 0, 0.01]\n"
          "    samples: 32\n"
          "  - {type: area, shape: disk, center: [0, 5, 0], normal: [0, -2, 0], radius: 0.5}\n"
          "  - {type: area, shape: sphere, center: [1, 2, 3], radius: 0.25, samples: 4}\n",
      "test.yaml");
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  Look look(r.description);
  ASSERT_EQ(look.count(EntityKind::LightEntity), 3u);

  const Entity& rect = look.entity(EntityKind::LightEntity, 0);
  EXPECT_EQ(look.text(rect, rect.type), "area");
  const ValueId shape = look.at(rect, {"shape"});
  EXPECT_EQ(look.text(rect, shape), "rectangle");
  EXPECT_EQ(look.where(rect, shape).line, 5u);
  EXPECT_EQ(look.where(rect, shape).column, 12u);
  EXPECT_EQ(look.point3(rect, look.at(rect, {"corner"})), (Point3{-1, 4, -1}));
  EXPECT_EQ(look.where(rect, look.at(rect, {"corner"})).line, 6u);
  const ValueId edges = look.at(rect, {"edges"});
  EXPECT_EQ(look.vec3(rect, look.tree(rect).item(edges, 0)), (Vec3{2, 0, 0}));
  EXPECT_EQ(look.vec3(rect, look.tree(rect).item(edges, 1)), (Vec3{0, 0, 3}));
  EXPECT_EQ(look.where(rect, edges).line, 7u);
  EXPECT_EQ(look.where(rect, edges).column, 12u);
  EXPECT_FALSE(look.has(rect, {"radius"}));
  EXPECT_EQ(look.number(rect, look.at(rect, {"samples"})), 32);
  EXPECT_EQ(look.where(rect, look.at(rect, {"samples"})).line, 11u);
  EXPECT_EQ(look.number(rect, look.at(rect, {"intensity"})), 2);
  EXPECT_EQ(look.vec3(rect, look.at(rect, {"attenuation"})), (Vec3{1, 0, 0.01}));

  const Entity& disk = look.entity(EntityKind::LightEntity, 1);
  EXPECT_EQ(look.text(disk, look.at(disk, {"shape"})), "disk");
  EXPECT_EQ(look.vec3(disk, look.at(disk, {"normal"})), (Vec3{0, -2, 0}));  // normalised later
  EXPECT_EQ(look.number(disk, look.at(disk, {"radius"})), 0.5);
  EXPECT_FALSE(look.has(disk, {"samples"}));  // default: the factory's AreaLight::samples
  EXPECT_FALSE(look.has(disk, {"color"}));

  const Entity& sphere = look.entity(EntityKind::LightEntity, 2);
  EXPECT_EQ(look.text(sphere, look.at(sphere, {"shape"})), "sphere");
  EXPECT_EQ(look.point3(sphere, look.at(sphere, {"center"})), (Point3{1, 2, 3}));
  EXPECT_EQ(look.number(sphere, look.at(sphere, {"radius"})), 0.25);
  EXPECT_EQ(look.number(sphere, look.at(sphere, {"samples"})), 4);
}

TEST(SceneParser, AreaLightKeyErrors) {
  const std::string lights = std::string(kMinimal) + "lights:\n";
  const auto expectLightError = [&](const std::string& light, const std::string& token,
                                    const std::string& fragment) {
    const std::string line = "  - " + light;
    expectOneError(lights + line + "\n", 4, token.empty() ? 5 : columnOf(line, token), fragment);
  };
  expectLightError("{type: area, center: [0, 1, 0], radius: 1}", "",
                   "area light is missing required key 'shape' (one of: rectangle, disk, sphere)");
  // A misspelt shape is one error: the unknown key, with the suggestion.
  expectLightError("{type: area, shap: disk, center: [0, 1, 0], radius: 1}", "shap",
                   "unknown key 'shap' in area light; expected one of: shape, color, intensity, "
                   "attenuation, samples (did you mean 'shape'?)");
  // With its shape known, a misspelt key is offered that shape's keys only (a disk light's
  // without inner_radius: it is a whole disk).
  expectLightError(
      "{type: area, shape: disk, center: [0, 1, 0], normal: [0, -1, 0], radius: 1, "
      "radus: 2}",
      "radus",
      "unknown key 'radus' in area light; expected one of: shape, color, intensity, "
      "attenuation, samples, center, normal, radius (did you mean 'radius'?)");
  expectLightError("{type: area, shape: square, corner: [0, 1, 0]}", "square",
                   "unknown area light shape 'square'; expected one of: rectangle, disk, sphere");
  expectLightError("{type: area, shape: spere, center: [0, 1, 0], radius: 1}", "spere",
                   "(did you mean 'sphere'?)");
  expectLightError(
      "{type: area, shape: [disk], center: [0, 1, 0], radius: 1}", "[disk]",
      "area light.shape: expected one of rectangle, disk, sphere, got a list of 1 item");
  // Another shape's geometry key is an error naming the shapes it belongs to.
  expectLightError(
      "{type: area, shape: rectangle, corner: [0, 1, 0], edges: [[1, 0, 0], [0, 0, 1]], "
      "radius: 1}",
      "radius",
      "'radius' is a key of a disk or sphere area light, not of a rectangle; a rectangle takes "
      "corner, edges");
  expectLightError("{type: area, shape: sphere, center: [0, 1, 0], radius: 1, normal: [0, 1, 0]}",
                   "normal", "'normal' is a key of a disk area light, not of a sphere");
  expectLightError(
      "{type: area, shape: disk, center: [0, 1, 0], normal: [0, 1, 0], radius: 1, corner: [0, 0, "
      "0]}",
      "corner", "'corner' is a key of a rectangle area light, not of a disk");
  // Keys of no area light: unknown, with a suggestion.
  expectLightError("{type: area, shape: sphere, center: [0, 1, 0], radius: 1, sampels: 4}",
                   "sampels",
                   "unknown key 'sampels' in area light; expected one of: shape, color, "
                   "intensity, attenuation, samples");
  expectLightError("{type: area, shape: sphere, center: [0, 1, 0], radius: 1, sampels: 4}",
                   "sampels", "(did you mean 'samples'?)");
  const std::vector<Diagnostic> positioned =
      errorsOf(lights + "  - {type: area, shape: sphere, position: [0, 1, 0], radius: 1}\n");
  ASSERT_EQ(positioned.size(), 2u);
  // In file order: the light (missing center), then its unknown key.
  EXPECT_EQ(positioned[0].message, "sphere area light is missing required key 'center'");
  EXPECT_EQ(positioned[0].where.column, 5);
  EXPECT_THAT(positioned[1].message, HasSubstr("unknown key 'position' in area light"));
  EXPECT_EQ(positioned[1].where.column, 33);
  // Missing geometry, reported at the light.
  expectLightError("{type: area, shape: rectangle, corner: [0, 1, 0]}", "",
                   "rectangle area light is missing required key 'edges'");
  expectLightError("{type: area, shape: disk, center: [0, 1, 0], normal: [0, 1, 0]}", "",
                   "disk area light is missing required key 'radius'");
  // Types of the values, as for the object of that shape.
  expectLightError("{type: area, shape: rectangle, corner: [0, 1, 0], edges: [[1, 0, 0]]}",
                   "[[1, 0, 0]]",
                   "area light.edges: expected a list of 2 vectors [[x, y, z], ...], got a list of "
                   "1 item");
  expectLightError("{type: area, shape: sphere, center: [0, 1, 0], radius: big}", "big",
                   "area light.radius: expected a number, got 'big'");
  expectLightError("{type: area, shape: sphere, center: [0, 1, 0], radius: 1, samples: 2.5}", "2.5",
                   "area light.samples: expected a whole number, got 2.5");
  expectLightError("{type: area, shape: sphere, center: [0, 1, .nan], radius: 1}", ".nan",
                   "area light.center[2] must be a finite number, got .nan");
  // A point light's keys stay unknown to area lights and the other way round.
  expectOneError(lights + "  - {type: point, position: [0, 0, 0], samples: 4}\n", 4, 40,
                 "unknown key 'samples' in point light");
}

TEST(SceneParser, AdaptiveSamplingKeys) {
  const std::string camera = "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n";
  const ParseResult r = parseScene(camera +
                                       "image: {width: 4, height: 3, samples: 2,\n"
                                       "        adaptive: {max_samples: 128, threshold: 0.02}}\n",
                                   "test.yaml");
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  Look look(r.description);
  const Entity& imageEntity = look.entity(EntityKind::ImageEntity);
  ASSERT_TRUE(look.has(imageEntity, {"adaptive"}));
  const ValueId maxSamples = look.at(imageEntity, {"adaptive", "max_samples"});
  ASSERT_TRUE(maxSamples != kNoValue && look.has(imageEntity, {"adaptive", "threshold"}));
  EXPECT_EQ(look.number(imageEntity, maxSamples), 128);
  EXPECT_EQ(look.where(imageEntity, maxSamples).line, 3u);
  EXPECT_EQ(look.where(imageEntity, maxSamples).column, 33u);
  EXPECT_EQ(look.number(imageEntity, look.at(imageEntity, {"adaptive", "threshold"})), 0.02);
  EXPECT_EQ(look.where(imageEntity, look.at(imageEntity, {"adaptive"})).line, 3u);
  EXPECT_EQ(look.where(imageEntity, look.at(imageEntity, {"adaptive"})).column, 19u);

  // Both keys are optional; absent ones are left to AdaptiveSampling's defaults.
  const ParseResult empty =
      parseScene(camera + "image: {width: 4, height: 3, adaptive: {}}\n", "test.yaml");
  ASSERT_FALSE(empty.hasErrors()) << empty.diagnostics[0].format();
  Look emptyLook(empty.description);
  const Entity& emptyImage = emptyLook.entity(EntityKind::ImageEntity);
  ASSERT_TRUE(emptyLook.has(emptyImage, {"adaptive"}));
  EXPECT_FALSE(emptyLook.has(emptyImage, {"adaptive", "max_samples"}));
  EXPECT_FALSE(emptyLook.has(emptyImage, {"adaptive", "threshold"}));
  const ParseResult plain = parseScene(std::string(kMinimal), "test.yaml");
  Look plainLook(plain.description);
  EXPECT_FALSE(plainLook.has(plainLook.entity(EntityKind::ImageEntity), {"adaptive"}));
  // The built scene: the defaults, or none.
  EXPECT_EQ(loadSceneFromString(camera + "image: {width: 4, height: 3, adaptive: {}}\n", "t.yaml")
                .parts.image.adaptive->maxSamples,
            AdaptiveSampling{}.maxSamples);
  EXPECT_FALSE(loadSceneFromString(kMinimal, "t.yaml").parts.image.adaptive);

  const std::string image = "image: {width: 4, height: 3, adaptive: ";
  const auto expectAdaptiveError = [&](const std::string& adaptive, const std::string& token,
                                       const std::string& fragment) {
    const std::string line = image + adaptive + "}";
    expectOneError(camera + line + "\n", 2, columnOf(line, token), fragment);
  };
  expectAdaptiveError("{max_sample: 8}", "max_sample",
                      "unknown key 'max_sample' in image.adaptive; expected one of: max_samples, "
                      "threshold (did you mean 'max_samples'?)");
  expectAdaptiveError("{max_samples: 8.5}", "8.5",
                      "image.adaptive.max_samples: expected a whole number, got 8.5");
  expectAdaptiveError("{threshold: low}", "low",
                      "image.adaptive.threshold: expected a number, got 'low'");
  expectAdaptiveError("{threshold: .inf}", ".inf",
                      "image.adaptive.threshold must be a finite number, got .inf");
  expectAdaptiveError("8", "8",
                      "image.adaptive: expected a mapping {max_samples, threshold}, got '8'");
  expectAdaptiveError("{max_samples: 8, max_samples: 9}", "max_samples: 9",
                      "duplicate key 'max_samples' in image.adaptive");
}

TEST(SceneParser, TransformSteps) {
  const ParseResult r = parseScene(std::string(kMinimal) +
                                       "objects:\n"
                                       "  - type: box\n"
                                       "    min: [0, 0, 0]\n"
                                       "    max: [1, 1, 1]\n"
                                       "    transform:\n"
                                       "      - {translate: [1, 2, 3]}\n"
                                       "      - {scale: 2}\n"
                                       "      - {scale: [1, 2, 3]}\n"
                                       "      - {rotate: {axis: [0, 0, 2], angle: 90}}\n",
                                   "t.yaml");
  ASSERT_FALSE(r.hasErrors()) << r.diagnostics[0].format();
  Look look(r.description);
  const Entity& box = look.entity(EntityKind::ObjectEntity);
  const ValueId steps = look.at(box, {"transform"});
  const ValueTree& tree = look.tree(box);
  ASSERT_EQ(tree.size(steps), 4u);
  const auto step = [&](std::size_t i) { return tree.item(steps, i); };
  const auto value = [&](std::size_t i) { return tree.value(step(i), 0); };
  EXPECT_EQ(tree.scalar(tree.key(step(0), 0)), "translate");
  EXPECT_EQ(look.vec3(box, value(0)), (Vec3{1, 2, 3}));
  EXPECT_EQ(look.number(box, value(1)), 2);
  EXPECT_EQ(look.vec3(box, value(2)), (Vec3{1, 2, 3}));
  EXPECT_EQ(tree.scalar(tree.key(step(3), 0)), "rotate");
  EXPECT_EQ(look.number(box, tree.value(value(3), 1)), 90);
  EXPECT_EQ(tree.position(step(3)).line, 11u);
  // Built: translate, then scale 2, then scale (1, 2, 3), then a quarter turn about +z.
  const SceneParts built =
      loadSceneFromString(std::string(kMinimal) +
                              "objects:\n"
                              "  - type: box\n"
                              "    min: [0, 0, 0]\n"
                              "    max: [1, 1, 1]\n"
                              "    transform:\n"
                              "      - {translate: [1, 2, 3]}\n"
                              "      - {scale: 2}\n"
                              "      - {scale: [1, 2, 3]}\n"
                              "      - {rotate: {axis: [0, 0, 2], angle: 90}}\n",
                          "t.yaml")
          .parts;
  ASSERT_EQ(built.primitives.size(), 1u);
  const Bounds3 b = built.primitives[0].bounds();
  EXPECT_NEAR(b.lo.x, -12, 1e-9);
  EXPECT_NEAR(b.hi.x, -8, 1e-9);
  EXPECT_NEAR(b.lo.y, 2, 1e-9);
  EXPECT_NEAR(b.hi.y, 4, 1e-9);
  EXPECT_NEAR(b.lo.z, 18, 1e-9);
  EXPECT_NEAR(b.hi.z, 24, 1e-9);

  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: box, min: [0, 0, 0], max: [1, 1, 1],\n"
                     "     transform: [{translate: [1, 2, 3], scale: 2}]}\n",
                 5, 41, "put 'scale' in a step of its own");
  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: box, min: [0, 0, 0], max: [1, 1, 1],\n"
                     "     transform: [{rotate: {axis: [0, 0, 1]}}]}\n",
                 5, 27, "box.transform[0].rotate is missing required key 'angle'");
  expectOneError(std::string(kMinimal) +
                     "objects:\n  - {type: box, min: [0, 0, 0], max: [1, 1, 1],\n"
                     "     transform: [{shear: 1}]}\n",
                 5, 19,
                 "unknown key 'shear' in a transform step; expected one of: translate, "
                 "scale, rotate");
}

TEST(SceneParser, SeveralErrorsAllReportedInFileOrder) {
  const std::vector<Diagnostic> errors = errorsOf(
      "camera: {position: [0, 0], direction: [0, 0, -1], fov: 40}\n"
      "image: {width: 4, height: x}\n"
      "objects:\n"
      "  - {type: sphere, center: [0, 0, 0], radius: -1}\n"
      "  - {type: sphere, centre: [0, 0, 0], radius: 1}\n"
      "lights:\n"
      "  - {type: point, position: [0, 0, 0], intensity: -2}\n");
  // The misspelt 'centre' is one error: the missing 'center' it stands for is not reported again.
  ASSERT_EQ(errors.size(), 5u);
  const std::vector<std::pair<int, int>> expected = {{1, 20}, {2, 27}, {4, 47}, {5, 20}, {7, 51}};
  for (std::size_t i = 0; i < errors.size(); ++i) {
    EXPECT_EQ(errors[i].where.line, expected[i].first) << errors[i].format();
    EXPECT_EQ(errors[i].where.column, expected[i].second) << errors[i].format();
  }
  EXPECT_THAT(errors[2].message, HasSubstr("sphere.radius must be > 0, got -1"));
  EXPECT_THAT(errors[3].message, HasSubstr("unknown key 'centre' in sphere"));
  EXPECT_THAT(errors[3].message, HasSubstr("did you mean 'center'?"));
  EXPECT_THAT(errors[4].message, HasSubstr("point light.intensity must be >= 0, got -2"));
}

TEST(SceneParser, AtMostTwentyErrorsReported) {
  std::string text = kMinimal;
  text += "objects:\n";
  for (int i = 0; i < 25; ++i) text += "  - {type: sphere, center: [0, 0, 0], radius: -1}\n";
  try {
    loadSceneFromString(text, "t.yaml");
    FAIL() << "expected a SceneError";
  } catch (const SceneError& e) {
    ASSERT_EQ(e.diagnostics().size(), SceneError::kMaxReportedErrors);
    for (std::size_t i = 0; i < e.diagnostics().size(); ++i) {
      EXPECT_EQ(e.diagnostics()[i].where.line, static_cast<int>(4 + i));
    }
    EXPECT_EQ(e.unreported(), 5u);
    EXPECT_THAT(std::string(e.what()), HasSubstr("5 more errors not shown"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("t.yaml:4:47: sphere.radius must be > 0, got -1"));
  }
}

TEST(SceneParser, DiagnosticFormats) {
  const Diagnostic error{
      Diagnostic::Severity::Error, {"scene.yaml", 14, 7}, "sphere.radius must be > 0, got -2"};
  EXPECT_EQ(error.format(), "scene.yaml:14:7: sphere.radius must be > 0, got -2");
  const Diagnostic warning{Diagnostic::Severity::Warning, {"a/b.yaml", 3, 1}, "zero intensity"};
  EXPECT_EQ(warning.format(), "a/b.yaml:3:1: warning: zero intensity");
  const Diagnostic fileOnly{Diagnostic::Severity::Error, {"scene.yaml", 0, 0}, "cannot open file"};
  EXPECT_EQ(fileOnly.format(), "scene.yaml: cannot open file");
}

TEST(SceneParser, UnreadableFilesNameOnlyTheFile) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("glint_parser_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto firstError = [](const std::filesystem::path& p) -> Diagnostic {
    try {
      loadScene(p);
    } catch (const SceneError& e) {
      if (!e.diagnostics().empty()) return e.diagnostics()[0];
    }
    return {};
  };
  const Diagnostic missing = firstError(dir / "missing.yaml");
  EXPECT_EQ(missing.format(),
            (dir / "missing.yaml").string() + ": cannot open file: No such file or directory");
  const Diagnostic directory = firstError(dir);
  EXPECT_EQ(directory.format(), dir.string() + ": cannot open file: Is a directory");

  // A readable file: relative paths are kept as given in messages.
  { std::ofstream(dir / "bad.yaml") << kMinimal << "objects: 3\n"; }
  const std::filesystem::path previous = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const Diagnostic bad = firstError("bad.yaml");
  const Diagnostic relativeMissing = firstError("scene.yaml");
  std::filesystem::current_path(previous);
  EXPECT_EQ(bad.format(), "bad.yaml:3:10: objects: expected a list of objects, got '3'");
  EXPECT_EQ(relativeMissing.format(), "scene.yaml: cannot open file: No such file or directory");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace glint

namespace glint {
namespace {

// A folder of scene files for the include tests, removed afterwards.
class IncludeFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("glint_include_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    std::filesystem::create_directories(dir_ / "common");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  // Every error of loading `name`, formatted, with the folder left out.
  std::vector<std::string> errorsOf(const std::string& name) const {
    std::vector<std::string> out;
    try {
      loadScene(dir_ / name);
    } catch (const SceneError& e) {
      for (const Diagnostic& d : e.diagnostics()) {
        std::string text = d.format();
        for (std::size_t at; (at = text.find(dir_.string() + "/")) != std::string::npos;) {
          text.erase(at, dir_.string().size() + 1);
        }
        out.push_back(text);
      }
    }
    return out;
  }
  std::filesystem::path dir_;
};

constexpr const char* kCameraImage =
    "camera: {position: [0, 0, 5], direction: [0, 0, -1], fov: 40}\n"
    "image: {width: 8, height: 6}\n";

TEST_F(IncludeFiles, IncludedMaterialsJoinTheScene) {
  write("scene.yaml", std::string("include: [common/paints.yaml]\n") + kCameraImage +
                          "objects:\n"
                          "  - {type: sphere, center: [0, 0, 0], radius: 1, material: red}\n"
                          "  - {type: sphere, center: [2, 0, 0], radius: 1, material: blue}\n");
  // Paths in an included file start at its own folder; includes nest.
  write("common/paints.yaml", "include: more.yaml\nmaterials:\n  red: {kd: [1, 0, 0]}\n");
  write("common/more.yaml", "materials:\n  blue: {kd: [0, 0, 1]}\n");
  const LoadedScene s = loadScene(dir_ / "scene.yaml");
  ASSERT_EQ(s.parts.primitives.size(), 2u);
  EXPECT_EQ(s.parts.materials.at(s.parts.primitives[0].materialIndex()).kd, Color(1, 0, 0));
  EXPECT_EQ(s.parts.materials.at(s.parts.primitives[1].materialIndex()).kd, Color(0, 0, 1));
  // A single name works as a list of one; an empty included file brings nothing.
  write("empty.yaml", "");
  write("one.yaml", std::string("include: empty.yaml\n") + kCameraImage);
  EXPECT_TRUE(errorsOf("one.yaml").empty());
}

TEST_F(IncludeFiles, ErrorsNameBothPlacesAndTheFileTheyAreIn) {
  write("scene.yaml", std::string("include: [common/paints.yaml]\n") + kCameraImage +
                          "materials:\n  red: {kd: 1}\n");
  write("common/paints.yaml", "materials:\n  red: {kd: [1, 0, 0]}\n  bad: {kd: -1}\n");
  EXPECT_EQ(
      errorsOf("scene.yaml"),
      (std::vector<std::string>{"scene.yaml:5:3: duplicate material 'red': defined twice (first at "
                                "common/paints.yaml:2:3)",
                                "common/paints.yaml:3:13: materials.bad.kd must be >= 0, got -1"}));
}

TEST_F(IncludeFiles, IncludedTexturesJoinTheSceneAndAreNamedOnce) {
  // A library of textures and the materials that use them; the scene uses both.
  write("scene.yaml", std::string("include: common/library.yaml\n") + kCameraImage +
                          "objects:\n"
                          "  - {type: sphere, center: [0, 0, 0], radius: 1, material: tiles}\n"
                          "  - {type: sphere, center: [2, 0, 0], radius: 1, "
                          "material: {kd: squares}}\n");
  write("common/library.yaml",
        "textures:\n  squares: {type: checker, colors: [[1, 1, 1], [0, 0, 0]]}\n"
        "materials:\n  tiles: {kd: squares}\n");
  const LoadedScene s = loadScene(dir_ / "scene.yaml");
  ASSERT_EQ(s.parts.primitives.size(), 2u);
  for (const auto& primitive : s.parts.primitives) {
    EXPECT_NE(s.parts.materials.at(primitive.materialIndex()).textures, kUntextured);
  }
  write("twice.yaml", std::string("include: common/library.yaml\n") + kCameraImage +
                          "textures:\n  squares: {type: noise}\n");
  EXPECT_EQ(errorsOf("twice.yaml"),
            (std::vector<std::string>{"twice.yaml:5:3: duplicate texture 'squares': defined "
                                      "twice (first at common/library.yaml:2:3)"}));
}

TEST_F(IncludeFiles, AFileReachedTwiceIsIncludedOnce) {
  // Two libraries that both include one palette (a diamond, no cycle), and a name written twice
  // in one list: the palette's definitions join the scene once, without a "defined twice".
  write("scene.yaml", std::string("include: [common/walls.yaml, common/floors.yaml, "
                                  "common/palette.yaml, ./common/palette.yaml]\n") +
                          kCameraImage +
                          "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, "
                          "material: stone}\n");
  write("common/walls.yaml", "include: palette.yaml\nmaterials:\n  wall: {kd: stone_colour}\n");
  write("common/floors.yaml", "include: [palette.yaml]\nmaterials:\n  floor: {kd: 0.5}\n");
  write("common/palette.yaml",
        "textures:\n  stone_colour: {type: noise}\nmaterials:\n  stone: {kd: [0.5, 0.5, 0.4]}\n");
  EXPECT_TRUE(errorsOf("scene.yaml").empty());
  const LoadedScene s = loadScene(dir_ / "scene.yaml");
  ASSERT_EQ(s.parts.primitives.size(), 1u);
  EXPECT_EQ(s.parts.materials.at(s.parts.primitives[0].materialIndex()).kd, Color(0.5, 0.5, 0.4));
  // A name the scene defines as well is still defined twice, once.
  write("again.yaml", std::string("include: [common/walls.yaml, common/floors.yaml]\n") +
                          kCameraImage + "materials:\n  stone: {kd: 1}\n");
  EXPECT_EQ(errorsOf("again.yaml"),
            (std::vector<std::string>{"again.yaml:5:3: duplicate material 'stone': defined "
                                      "twice (first at common/palette.yaml:4:3)"}));
}

// A chain of includes reads each file on the stack of the one before: thousands of files crashed
// glint (stack exhaustion). 64 levels are read; the 65th is an error at the include that asks for
// it, and the files above it still count.
TEST_F(IncludeFiles, IncludesNestAtMost64Deep) {
  const auto chain = [&](const std::string& prefix, int files) {
    write(prefix + "scene.yaml", "include: " + prefix + "0.yaml\n" + kCameraImage +
                                     "objects:\n  - {type: sphere, center: [0, 0, 0], radius: "
                                     "1, material: m0}\n");
    for (int i = 0; i < files; ++i) {
      const std::string next =
          i + 1 < files ? "include: " + prefix + std::to_string(i + 1) + ".yaml\n" : "";
      write(prefix + std::to_string(i) + ".yaml",
            next + "materials: {m" + std::to_string(i) + ": {kd: 0.5}}\n");
    }
  };
  chain("ok", 64);
  EXPECT_TRUE(errorsOf("okscene.yaml").empty());
  EXPECT_EQ(loadScene(dir_ / "okscene.yaml").parts.materials.size(), 65u);  // and the default
  chain("deep", 100);
  EXPECT_EQ(errorsOf("deepscene.yaml"),
            (std::vector<std::string>{"deep63.yaml:1:10: cannot include 'deep64.yaml': includes "
                                      "nest more than 64 files deep (from deepscene.yaml)"}));
}

TEST_F(IncludeFiles, CyclesMissingFilesAndSceneKeysAreErrorsAtTheirPlace) {
  write("a.yaml", std::string("include: [b.yaml, missing.yaml]\n") + kCameraImage);
  write("b.yaml", "include: [a.yaml]\nmaterials: {m: {kd: 1}}\nobjects: []\n");
  EXPECT_EQ(errorsOf("a.yaml"),
            (std::vector<std::string>{
                "a.yaml:1:19: cannot include 'missing.yaml': No such file or directory",
                "b.yaml:1:11: include cycle: a.yaml -> b.yaml -> a.yaml",
                "b.yaml:3:1: 'objects' belongs in the scene file: an included file holds "
                "textures, materials, groups and further includes only"}));
  write("c.yaml", std::string("include: [list.yaml, broken.yaml, {a: 1}]\n") + kCameraImage);
  write("list.yaml", "- a\n");
  write("broken.yaml", "materials: {m: {kd: [1, 2}\n");
  const std::vector<std::string> errors = errorsOf("c.yaml");
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0], "c.yaml:1:35: include: expected a file name, got a mapping");
  EXPECT_EQ(errors[1],
            "list.yaml:1:1: an included file must be a mapping (of include, textures, "
            "materials, groups), got a list of 1 item");
  EXPECT_THAT(errors[2], HasSubstr("broken.yaml:1:26: syntax error: a '[' is not closed"));
  // An included file of two documents: the error is at the second one's start, as in a scene.
  write("d.yaml", std::string("include: two.yaml\n") + kCameraImage);
  write("two.yaml", "materials:\n  a: {kd: 1}\n---\nmaterials: {}\n");
  EXPECT_EQ(errorsOf("d.yaml"),
            (std::vector<std::string>{"two.yaml:3:1: the file holds more than one YAML document "
                                      "(the second starts here); an included file holds exactly "
                                      "one"}));
}

}  // namespace
}  // namespace glint
