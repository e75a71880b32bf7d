// The medium stack and the boundary rule of nested dielectrics (media.h), on material lists alone.
#include "glint/scene/media.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace glint {
namespace {

constexpr std::uint32_t kOpaque = 0;
constexpr std::uint32_t kGlass = 1;
constexpr std::uint32_t kWater = 2;
constexpr std::uint32_t kOtherGlass = 3;  // the same ior as kGlass, another material

std::vector<Material> materials(int glassPriority = 0, int waterPriority = 0) {
  std::vector<Material> list(4);
  list[kGlass].kt = Color(0.9);
  list[kGlass].ior = 1.5;
  list[kGlass].priority = glassPriority;
  list[kWater].kt = Color(0.95);
  list[kWater].ior = 1.33;
  list[kWater].priority = waterPriority;
  list[kOtherGlass].kt = Color(0.8);
  list[kOtherGlass].ior = 1.5;
  return list;
}

MediumStack stackOf(std::initializer_list<std::uint32_t> media) {
  MediumStack stack;
  for (const std::uint32_t m : media) stack.push(m);
  return stack;
}

TEST(MediumStack, PushRemoveAndCurrent) {
  const std::vector<Material> list = materials();
  MediumStack stack;
  EXPECT_TRUE(stack.empty());
  EXPECT_EQ(stack.current(list), kNoMedium);
  stack.push(kGlass);
  stack.push(kWater);
  stack.push(kGlass);
  EXPECT_EQ(stack.size(), 3);
  EXPECT_EQ(stack.current(list), kGlass);  // equal priorities: the latest entered
  EXPECT_TRUE(stack.remove(kGlass));       // the latest glass entry goes
  EXPECT_EQ(stack, stackOf({kGlass, kWater}));
  EXPECT_EQ(stack.current(list), kWater);
  EXPECT_FALSE(stack.remove(kOtherGlass));
  EXPECT_EQ(stack.size(), 2);
}

TEST(MediumStack, HigherPriorityIsCurrentWhateverTheOrder) {
  const std::vector<Material> list = materials(/*glass*/ 2, /*water*/ 1);
  EXPECT_EQ(stackOf({kGlass, kWater}).current(list), kGlass);
  EXPECT_EQ(stackOf({kWater, kGlass}).current(list), kGlass);
}

TEST(MediumStack, BeyondCapacityTheOutermostIsForgotten) {
  MediumStack stack;
  stack.push(kWater);
  for (int i = 0; i < MediumStack::kCapacity; ++i) stack.push(kGlass);
  EXPECT_EQ(stack.size(), MediumStack::kCapacity);
  for (int i = 0; i < MediumStack::kCapacity; ++i) EXPECT_EQ(stack[i], kGlass);
  EXPECT_FALSE(stack.remove(kWater));
}

TEST(CrossBoundary, OneSolidInAirIsTheClassicRule) {
  const std::vector<Material> list = materials();
  MediumStack beyond;
  const Boundary in = crossBoundary(MediumStack{}, kGlass, kGlass, true, list, beyond);
  EXPECT_TRUE(in.surface);
  EXPECT_EQ(in.eta(), 1 / 1.5);  // bit for bit what the air-only rule computes
  EXPECT_EQ(beyond, stackOf({kGlass}));
  const Boundary out = crossBoundary(stackOf({kGlass}), kGlass, kGlass, false, list, beyond);
  EXPECT_TRUE(out.surface);
  EXPECT_EQ(out.eta(), 1.5);
  EXPECT_TRUE(beyond.empty());
}

TEST(CrossBoundary, WaterInGlassBendsByTheRatio) {
  const std::vector<Material> list = materials();
  MediumStack beyond;
  // Entering the water from the glass it lies in, and leaving it back into the glass.
  const Boundary in = crossBoundary(stackOf({kGlass}), kWater, kWater, true, list, beyond);
  EXPECT_TRUE(in.surface);
  EXPECT_DOUBLE_EQ(in.eta(), 1.5 / 1.33);
  EXPECT_EQ(beyond, stackOf({kGlass, kWater}));
  const Boundary out = crossBoundary(beyond, kWater, kWater, false, list, beyond);
  EXPECT_TRUE(out.surface);
  EXPECT_DOUBLE_EQ(out.eta(), 1.33 / 1.5);
  EXPECT_EQ(beyond, stackOf({kGlass}));
}

TEST(CrossBoundary, SameMaterialBoundaryIsNoSurface) {
  const std::vector<Material> list = materials();
  MediumStack beyond;
  // A glass sphere inside a glass sphere of the same material: its boundary, both ways.
  const Boundary in = crossBoundary(stackOf({kGlass}), kGlass, kGlass, true, list, beyond);
  EXPECT_FALSE(in.surface);
  EXPECT_EQ(in.eta(), 1);
  EXPECT_EQ(beyond, stackOf({kGlass, kGlass}));
  const Boundary out = crossBoundary(beyond, kGlass, kGlass, false, list, beyond);
  EXPECT_FALSE(out.surface);
  EXPECT_EQ(beyond, stackOf({kGlass}));
  // Another material of the same ior is a surface (its own Phong terms and kt), but no bend.
  const Boundary other =
      crossBoundary(stackOf({kGlass}), kOtherGlass, kOtherGlass, true, list, beyond);
  EXPECT_TRUE(other.surface);
  EXPECT_EQ(other.eta(), 1);
}

TEST(CrossBoundary, EqualPrioritiesTheLatestEnteredOwnsTheOverlap) {
  const std::vector<Material> list = materials();
  MediumStack media;
  // Overlapping glass and water spheres: enter glass, enter water, leave glass, leave water.
  EXPECT_TRUE(crossBoundary(media, kGlass, kGlass, true, list, media).surface);
  const Boundary intoWater = crossBoundary(media, kWater, kWater, true, list, media);
  EXPECT_TRUE(intoWater.surface);
  EXPECT_DOUBLE_EQ(intoWater.eta(), 1.5 / 1.33);
  EXPECT_FALSE(crossBoundary(media, kGlass, kGlass, false, list, media).surface);  // inside water
  const Boundary out = crossBoundary(media, kWater, kWater, false, list, media);
  EXPECT_TRUE(out.surface);
  EXPECT_EQ(out.eta(), 1.33);
  EXPECT_TRUE(media.empty());
}

TEST(CrossBoundary, HigherPriorityOwnsTheOverlap) {
  // Glass of higher priority: the water's boundary inside the glass is no surface, and leaving the
  // glass into the water is the glass–water interface.
  const std::vector<Material> list = materials(/*glass*/ 1, /*water*/ 0);
  MediumStack media;
  EXPECT_TRUE(crossBoundary(media, kGlass, kGlass, true, list, media).surface);
  EXPECT_FALSE(crossBoundary(media, kWater, kWater, true, list, media).surface);
  EXPECT_EQ(media, stackOf({kGlass, kWater}));
  const Boundary glassToWater = crossBoundary(media, kGlass, kGlass, false, list, media);
  EXPECT_TRUE(glassToWater.surface);
  EXPECT_DOUBLE_EQ(glassToWater.eta(), 1.5 / 1.33);
  EXPECT_EQ(media, stackOf({kWater}));
  // Water of higher priority instead: the same path meets the water where it enters it.
  const std::vector<Material> waterFirst = materials(/*glass*/ 0, /*water*/ 1);
  media = MediumStack{};
  crossBoundary(media, kGlass, kGlass, true, waterFirst, media);
  EXPECT_TRUE(crossBoundary(media, kWater, kWater, true, waterFirst, media).surface);
  EXPECT_FALSE(crossBoundary(media, kGlass, kGlass, false, waterFirst, media).surface);
  // Entering a lower-priority solid inside the water: no surface either.
  EXPECT_FALSE(crossBoundary(media, kGlass, kGlass, true, waterFirst, media).surface);
}

TEST(CrossBoundary, LeavingASolidNotOnTheStackIsASurfaceIntoTheCurrentMedium) {
  const std::vector<Material> list = materials();
  MediumStack beyond;
  const Boundary out = crossBoundary(stackOf({kWater}), kGlass, kGlass, false, list, beyond);
  EXPECT_TRUE(out.surface);
  EXPECT_DOUBLE_EQ(out.eta(), 1.5 / 1.33);
  EXPECT_EQ(beyond, stackOf({kWater}));
}

TEST(CrossBoundary, FlatAndOpaqueSurfacesChangeNoMedium) {
  const std::vector<Material> list = materials();
  MediumStack beyond;
  // A flat glass sheet under water: a surface between water and the sheet's ior; the ray stays in
  // the water.
  const Boundary sheet = crossBoundary(stackOf({kWater}), kGlass, kNoMedium, true, list, beyond);
  EXPECT_TRUE(sheet.surface);
  EXPECT_DOUBLE_EQ(sheet.eta(), 1.33 / 1.5);
  EXPECT_EQ(beyond, stackOf({kWater}));
  const Boundary opaque = crossBoundary(stackOf({kWater}), kOpaque, kNoMedium, true, list, beyond);
  EXPECT_TRUE(opaque.surface);
  EXPECT_EQ(beyond, stackOf({kWater}));
}

}  // namespace
}  // namespace glint
