// Determinism (DESIGN.md §1): every random number comes from (pixel, sample index, seed), so the
// same scene gives the same film — bit for bit — and the same encoded bytes on any thread count,
// any tile schedule, and when rendered in crops and stitched.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "glint/geometry/shape.h"
#include "glint/image/image_writer.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "test_scenes.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using testing::glossyTestScene;

constexpr int kWidth = testing::kGlossySceneWidth;
constexpr int kHeight = testing::kGlossySceneHeight;

bool bitwiseEqual(const Film& a, const Film& b) {
  return a.region() == b.region() && a.pixels().size() == b.pixels().size() &&
         std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Color)) == 0;
}

std::vector<char> fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Determinism, ThreadCountDoesNotChangeFilmOrBytes) {
  const Scene scene(glossyTestScene(0));
  RenderOptions one;
  one.threads = 1;
  RenderOptions two;
  two.threads = 2;
  two.tileSize = 7;  // a different tile schedule as well
  RenderStats statsOne, statsTwo;
  const Film a = render(scene, one, &statsOne);
  const Film b = render(scene, two, &statsTwo);
  ASSERT_TRUE(bitwiseEqual(a, b));
  EXPECT_EQ(statsOne.rays.total(), statsTwo.rays.total());
  EXPECT_EQ(statsOne.rays.reflection, statsTwo.rays.reflection);
  EXPECT_EQ(statsOne.rays.refraction, statsTwo.rays.refraction);
  EXPECT_GT(statsOne.rays.reflection, 0u);
  EXPECT_GT(statsOne.rays.refraction, 0u);

  const fs::path dir =
      fs::temp_directory_path() / ("glint-determinism-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  writeImage(a, dir / "one.png", Encoding::Srgb);
  writeImage(b, dir / "two.png", Encoding::Srgb);
  const std::vector<char> bytesOne = fileBytes(dir / "one.png");
  EXPECT_FALSE(bytesOne.empty());
  EXPECT_EQ(bytesOne, fileBytes(dir / "two.png"));
  fs::remove_all(dir);
}

TEST(Determinism, StitchedCropsEqualTheFullRender) {
  const Scene scene(glossyTestScene(0));
  const Film full = render(scene);
  // Crop edges deliberately off the tile grid.
  const int xs[] = {0, 9, 17, kWidth};
  const int ys[] = {0, 7, kHeight};
  Film stitched(kWidth, kHeight, PixelRegion{0, 0, kWidth, kHeight});
  int cropIndex = 0;
  for (int cy = 0; cy + 1 < 3; ++cy) {
    for (int cx = 0; cx + 1 < 4; ++cx) {
      RenderOptions options;
      options.crop = PixelRegion{xs[cx], ys[cy], xs[cx + 1], ys[cy + 1]};
      options.threads = 1 + cropIndex++ % 2;
      options.tileSize = 5;
      const Film part = render(scene, options);
      for (int y = 0; y < part.height(); ++y)
        for (int x = 0; x < part.width(); ++x) stitched.at(xs[cx] + x, ys[cy] + y) = part.at(x, y);
    }
  }
  EXPECT_TRUE(bitwiseEqual(stitched, full));
}

TEST(Determinism, DifferentSeedChangesTheGlossyPixels) {
  const Film a = render(Scene(glossyTestScene(0)));
  const Film b = render(Scene(glossyTestScene(1)));
  const Film again = render(Scene(glossyTestScene(0)));
  EXPECT_TRUE(bitwiseEqual(a, again));
  int differing = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i)
    differing += !(a.pixels()[i] == b.pixels()[i]);
  // Supersampling jitter and glossy lobes touch almost every pixel that sees geometry.
  EXPECT_GT(differing, kWidth * kHeight / 4);
}

TEST(Determinism, SeedLeavesADeterministicSceneUnchanged) {
  // Without glossy materials and with one sample per pixel nothing is random.
  SceneParts parts = glossyTestScene(0);
  parts.image.samples = 1;
  for (Material& m : parts.materials) m.reflectionBlur = m.refractionBlur = 0;
  SceneParts other = parts;
  other.render.seed = 12345;
  EXPECT_TRUE(bitwiseEqual(render(Scene(std::move(parts))), render(Scene(std::move(other)))));
}

}  // namespace
}  // namespace glint
