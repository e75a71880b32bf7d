#include "glint/scene/scene_overrides.h"

#include <gtest/gtest.h>

#include <limits>

namespace glint {
namespace {

TEST(SceneOverrides, WidthAloneKeepsAspect) {
  EXPECT_EQ(resizeKeepingAspect({32, 24}, 64, std::nullopt), (ImageSize{64, 48}));
  EXPECT_EQ(resizeKeepingAspect({32, 24}, 16, std::nullopt), (ImageSize{16, 12}));
}

TEST(SceneOverrides, HeightAloneKeepsAspect) {
  EXPECT_EQ(resizeKeepingAspect({32, 24}, std::nullopt, 12), (ImageSize{16, 12}));
  EXPECT_EQ(resizeKeepingAspect({1000, 500}, std::nullopt, 3), (ImageSize{6, 3}));
}

TEST(SceneOverrides, RoundsHalfAwayFromZeroExactly) {
  // 10 · 24 / 32 = 7.5 exactly: integer arithmetic must give 8, not a float-tie 7.
  EXPECT_EQ(resizeKeepingAspect({32, 24}, 10, std::nullopt), (ImageSize{10, 8}));
  // 7 · 24 / 32 = 5.25 → 5; 9 · 24 / 32 = 6.75 → 7.
  EXPECT_EQ(resizeKeepingAspect({32, 24}, 7, std::nullopt).height, 5);
  EXPECT_EQ(resizeKeepingAspect({32, 24}, 9, std::nullopt).height, 7);
}

TEST(SceneOverrides, OtherSideIsAtLeastOne) {
  EXPECT_EQ(resizeKeepingAspect({1000, 1}, 10, std::nullopt), (ImageSize{10, 1}));
  EXPECT_EQ(resizeKeepingAspect({1, 1000}, std::nullopt, 1), (ImageSize{1, 1}));
}

TEST(SceneOverrides, HugeRequestSaturatesInsteadOfOverflowing) {
  const ImageSize size = resizeKeepingAspect({1, 65535}, 65535, std::nullopt);
  EXPECT_EQ(size.width, 65535);
  EXPECT_EQ(size.height, std::numeric_limits<int>::max());
}

TEST(SceneOverrides, BothSidesAreTakenAsGiven) {
  EXPECT_EQ(resizeKeepingAspect({32, 24}, 5, 50), (ImageSize{5, 50}));
  EXPECT_EQ(resizeKeepingAspect({32, 24}, std::nullopt, std::nullopt), (ImageSize{32, 24}));
}

TEST(SceneOverrides, ApplyChangesOnlyWhatIsGiven) {
  SceneParts parts;
  parts.image.width = 40;
  parts.image.height = 30;
  parts.image.samples = 3;
  parts.render.seed = 9;
  applyOverrides(parts, {});
  EXPECT_EQ(parts.image.width, 40);
  EXPECT_EQ(parts.image.height, 30);
  EXPECT_EQ(parts.image.samples, 3);
  EXPECT_EQ(parts.render.seed, 9u);

  EXPECT_EQ(parts.render.integrator, Integrator::Whitted);

  applyOverrides(parts, {.width = 80,
                         .height = std::nullopt,
                         .samples = 16,
                         .seed = 5,
                         .integrator = Integrator::Path});
  EXPECT_EQ(parts.image.width, 80);
  EXPECT_EQ(parts.image.height, 60);
  EXPECT_EQ(parts.image.samples, 16);
  EXPECT_EQ(parts.render.seed, 5u);
  EXPECT_EQ(parts.render.integrator, Integrator::Path);
}

}  // namespace
}  // namespace glint
