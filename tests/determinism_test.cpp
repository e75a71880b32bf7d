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
#include "glint/io/image_writer.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 24;
constexpr int kHeight = 20;

// Glossy reflection and blurred refraction through glass, supersampled: every random decision of
// the renderer is exercised (pixel jitter, cone samples for both lobes, the split rule below them).
SceneParts glossyParts(std::uint64_t seed) {
  SceneParts parts;
  parts.camera.position = {0, 1, 4};
  parts.camera.direction = {0, -0.2, -1};
  parts.camera.fovDegrees = 50;
  parts.image.width = kWidth;
  parts.image.height = kHeight;
  parts.image.samples = 4;
  parts.image.encoding = Encoding::Srgb;
  parts.render.blurSamples = 4;
  parts.render.maxDepth = 5;
  parts.render.seed = seed;
  parts.background = Color(0.2, 0.3, 0.5);
  parts.ambient = Color(0.05);

  Material floor;
  floor.kd = Color(0.5, 0.5, 0.45);
  floor.kr = Color(0.4);
  floor.reflectionBlur = 12;
  Material glass;
  glass.kd = Color(0.05);
  glass.ks = Color(0.8);
  glass.shininess = 100;
  glass.kt = Color(0.85);
  glass.ior = 1.5;
  glass.refractionBlur = 6;
  Material red;
  red.kd = Color(0.8, 0.1, 0.1);
  red.ks = Color(0.3);
  red.shininess = 30;
  parts.materials.push_back(floor);
  parts.materials.push_back(glass);
  parts.materials.push_back(red);
  parts.primitives.emplace_back(Plane::make({0, -1, 0}, {0, 1, 0}), 1u, Color{});
  parts.primitives.emplace_back(Sphere::make({0, 0, -1}, 1), 2u, Color{});
  parts.primitives.emplace_back(Sphere::make({1.5, -0.3, -3}, 0.7), 3u, Color{});
  parts.primitives.emplace_back(Sphere::make({-1.6, -0.4, -2.5}, 0.6), 3u, Color{});
  parts.lights.push_back(PointLight{{3, 5, 3}, Color(40, 38, 35), {1, 0, 1}});
  parts.lights.push_back(DirectionalLight{normalize(Vec3{-0.5, -1, -0.3}), Color(0.4)});
  return parts;
}

bool bitwiseEqual(const Film& a, const Film& b) {
  return a.region() == b.region() && a.pixels().size() == b.pixels().size() &&
         std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Color)) == 0;
}

std::vector<char> fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Determinism, ThreadCountDoesNotChangeFilmOrBytes) {
  const Scene scene(glossyParts(0));
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
  const Scene scene(glossyParts(0));
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
  const Film a = render(Scene(glossyParts(0)));
  const Film b = render(Scene(glossyParts(1)));
  const Film again = render(Scene(glossyParts(0)));
  EXPECT_TRUE(bitwiseEqual(a, again));
  int differing = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i)
    differing += !(a.pixels()[i] == b.pixels()[i]);
  // Supersampling jitter and glossy lobes touch almost every pixel that sees geometry.
  EXPECT_GT(differing, kWidth * kHeight / 4);
}

TEST(Determinism, SeedLeavesADeterministicSceneUnchanged) {
  // Without glossy materials and with one sample per pixel nothing is random.
  SceneParts parts = glossyParts(0);
  parts.image.samples = 1;
  for (Material& m : parts.materials) m.reflectionBlur = m.refractionBlur = 0;
  SceneParts other = parts;
  other.render.seed = 12345;
  EXPECT_TRUE(bitwiseEqual(render(Scene(std::move(parts))), render(Scene(std::move(other)))));
}

}  // namespace
}  // namespace glint
