// The `csg` object in scene files: operands, their materials and transforms, and every error at its
// file:line:col.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "glint/factories/scene_test_support.h"
#include "glint/geometry/csg.h"

namespace glint {
namespace {

using testing::expectOneError;
using testing::kMinimal;

std::string scene(const std::string& objects) {
  return std::string(kMinimal) + "materials: {red: {kd: [1, 0, 0]}, glass: {kt: 0.8}}\n" +
         "objects:\n" + objects;
}

TEST(CsgFactory, BuildsOnePrimitiveWithTheOperandsMaterialsAndTransforms) {
  LoadedScene loaded = loadSceneFromString(
      scene("  - type: csg\n"
            "    operation: difference\n"
            "    material: red\n"
            "    emission: [0.5, 0, 0]\n"
            "    transform: [{translate: [0, 0, -5]}]\n"
            "    operands:\n"
            "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
            "      - {type: box, min: [-2, -2, 0], max: [2, 2, 2], material: glass,\n"
            "         emission: [0, 0, 1], transform: [{scale: 0.5}]}\n"
            "      - type: csg\n"
            "        operation: union\n"
            "        operands: [{type: cylinder, base: [0, 0, -2], axis: [0, 0, 1], radius: 0.1,\n"
            "                    height: 4}, {type: sphere, center: [3, 0, 0], radius: 0.1}]\n"),
      "test.yaml");
  const Scene s(std::move(loaded.parts));
  ASSERT_EQ(s.primitives().size(), 1u);
  const Primitive& p = s.primitives()[0];
  ASSERT_NE(p.csg(), nullptr);
  const CsgTree& tree = *p.csg()->tree;
  ASSERT_EQ(tree.operands.size(), 4u);
  const std::uint32_t red = p.materialIndex();
  EXPECT_EQ(s.materials()[red].kd, Color(1, 0, 0));
  EXPECT_EQ(tree.operands[0].materialIndex, red);
  EXPECT_EQ(tree.operands[0].emission, Color(0.5, 0, 0));
  EXPECT_EQ(s.materials()[tree.operands[1].materialIndex].kt, Color(0.8));
  EXPECT_EQ(tree.operands[1].emission, Color(0, 0, 1));
  EXPECT_EQ(tree.operands[1].transmission, Color(0.8));  // filled in by the Scene
  EXPECT_EQ(tree.operands[0].transmission, Color(0));
  EXPECT_EQ(tree.operands[3].materialIndex, red);  // nested operands inherit too
  EXPECT_EQ(tree.depth, 2);
  // The difference's bounds are the sphere's, moved by the object's transform.
  EXPECT_EQ(p.bounds().lo, Point3(-1, -1, -6));
  EXPECT_EQ(p.bounds().hi, Point3(1, 1, -4));
  // Through the half-sized box: the cut at z = 0 (object space), then the hole of the cylinder.
  Hit hit;
  ASSERT_TRUE(s.intersect(Ray{{0.5, 0.5, 0}, {0, 0, -1}}, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 5);
  EXPECT_EQ(hit.part, 1u);
  EXPECT_EQ(hit.normal, Normal3(0, 0, 1));
  EXPECT_EQ(&s.materialOf(hit), &s.materials()[tree.operands[1].materialIndex]);
  EXPECT_EQ(s.emissionOf(hit), Color(0, 0, 1));
  EXPECT_FALSE(s.intersect(Ray{{0, 0, 0}, {0, 0, -1}}, kInfinity, hit) && hit.t < 5.9);
}

TEST(CsgFactory, AnEmissionTextureGlowsOnOperandsWithoutAMaterialOfTheirOwn) {
  LoadedScene loaded = loadSceneFromString(
      scene("  - type: csg\n"
            "    operation: union\n"
            "    emission: {type: checker, colors: [[1, 1, 1], [0, 0, 0]], scale: 1}\n"
            "    operands:\n"
            "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
            "      - {type: sphere, center: [3, 0, 0], radius: 1, material: red}\n"),
      "test.yaml");
  const Scene s(std::move(loaded.parts));
  const CsgTree& tree = *s.primitives().at(0).csg()->tree;
  EXPECT_EQ(tree.operands[0].emission, Color(1));  // × the texture, in the csg's material
  EXPECT_NE(s.materials()[tree.operands[0].materialIndex].textures, kUntextured);
  EXPECT_EQ(tree.operands[1].emission, Color(0));
  EXPECT_EQ(s.materials()[tree.operands[1].materialIndex].kd, Color(1, 0, 0));
}

TEST(CsgFactory, AClosedInlineMeshIsAnOperand) {
  LoadedScene loaded = loadSceneFromString(
      scene("  - type: csg\n"
            "    operation: intersection\n"
            "    operands:\n"
            "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
            "      - {type: mesh, positions: [[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 2]],\n"
            "         indices: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}\n"),
      "test.yaml");
  const Scene s(std::move(loaded.parts));
  const Primitive& p = s.primitives().at(0);
  EXPECT_EQ(p.bounds().lo, Point3(0, 0, 0));
  EXPECT_EQ(p.bounds().hi, Point3(1, 1, 1));
  Hit hit;
  ASSERT_TRUE(s.intersect(Ray{{0.2, 0.2, -3}, {0, 0, 1}}, kInfinity, hit));
  EXPECT_DOUBLE_EQ(hit.t, 3);  // the mesh's face z = 0, outward −z
  EXPECT_EQ(hit.normal, Normal3(0, 0, -1));
}

TEST(CsgFactory, OpenShapesAreErrorsAtTheirType) {
  for (const char* type :
       {"plane", "disk", "triangle", "rectangle", "tube", "cone", "polygon", "quadrangle"}) {
    expectOneError(scene("  - type: csg\n"
                         "    operation: union\n"
                         "    operands:\n"
                         "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
                         "      - {type: " +
                         std::string(type) + "}\n"),
                   9, 16, "is not a closed shape");
  }
}

TEST(CsgFactory, AMeshThatIsNotClosedIsAnErrorAtItsPositions) {
  expectOneError(
      scene("  - type: csg\n"
            "    operation: union\n"
            "    operands:\n"
            "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
            "      - {type: mesh, positions: [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],\n"
            "         indices: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [0, 1, 2]]}\n"),
      9, 33, "closed, consistently oriented surface");
  expectOneError(
      scene("  - type: csg\n"
            "    operation: union\n"
            "    operands:\n"
            "      - {type: sphere, center: [0, 0, 0], radius: 1}\n"
            "      - {type: mesh, positions: [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1],\n"
            "                                 [5, 5, 5]],\n"
            "         indices: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 4]]}\n"),
      9, 33, "belongs to only one triangle");
}

TEST(CsgFactory, KeyAndValueErrorsNameTheirPlace) {
  // A bad operation, with a suggestion.
  expectOneError(scene("  - {type: csg, operation: unoin, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1},\n"
                       "      {type: sphere, center: [1, 0, 0], radius: 1}]}\n"),
                 5, 28, "did you mean 'union'");
  // Unknown keys: of the csg, of an operand.
  expectOneError(scene("  - {type: csg, operation: union, colour: red, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1},\n"
                       "      {type: sphere, center: [1, 0, 0], radius: 1}]}\n"),
                 5, 35, "unknown key 'colour'");
  expectOneError(scene("  - {type: csg, operation: union, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1},\n"
                       "      {type: sphere, center: [1, 0, 0], raduis: 1}]}\n"),
                 7, 41, "did you mean 'radius'");
  // A bad value inside an operand.
  expectOneError(scene("  - {type: csg, operation: union, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1},\n"
                       "      {type: sphere, center: [1, 0, 0], radius: -1}]}\n"),
                 7, 49, "radius must be > 0");
  // Too few operands, an unknown operand type, an undefined material.
  expectOneError(scene("  - {type: csg, operation: union, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1}]}\n"),
                 5, 45, "at least two objects");
  expectOneError(scene("  - {type: csg, operation: union, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1},\n"
                       "      {type: sphear, center: [1, 0, 0], radius: 1}]}\n"),
                 7, 14, "did you mean 'sphere'");
  expectOneError(scene("  - {type: csg, operation: union, operands: [\n"
                       "      {type: sphere, center: [0, 0, 0], radius: 1, material: rde},\n"
                       "      {type: sphere, center: [1, 0, 0], radius: 1}]}\n"),
                 6, 62, "undefined material 'rde'");
  expectOneError(scene("  - {type: csg, operation: union}\n"), 5, 5,
                 "missing required key 'operands'");
}

TEST(CsgFactory, DeepNestingIsAnErrorNotAStackOverflow) {
  // 5000 levels: the YAML reader's own depth limit reports it.
  std::string deep;
  for (int k = 0; k < 5000; ++k) deep += "{type: csg, operation: union, operands: [";
  EXPECT_FALSE(testing::errorsOf(scene("  - " + deep + "\n")).empty());
  // 20 levels: within the reader's limit, the csg's limit of 16.
  std::string nested = "{type: sphere, center: [0, 0, 0], radius: 1}";
  for (int k = 0; k < 20; ++k) {
    nested = "{type: csg, operation: union, operands: [" + nested +
             ", {type: sphere, center: [1, 0, 0], radius: 1}]}";
  }
  const auto errors = testing::errorsOf(scene("  - " + nested + "\n"));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_THAT(errors[0].message, ::testing::HasSubstr("nested at most 16 deep"));
  EXPECT_EQ(errors[0].where.line, 5);
}

}  // namespace
}  // namespace glint
