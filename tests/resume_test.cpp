// Interrupt and resume (issue 6): a render stopped after a random number of tiles, saved to a
// checkpoint (through the file format), then resumed — possibly stopped and resumed again — gives
// the same film bit for bit as an uninterrupted render, on any thread count and for crops.
#include <gtest/gtest.h>

#include <atomic>
#include <bit>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "glint/factories/scene_loader.h"
#include "glint/job/checkpoint.h"
#include "glint/render/renderer.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

const fs::path kSceneFile = fs::path(GLINT_SOURCE_DIR) / "tests" / "cli" / "small.yaml";
constexpr int kTileSize = 8;

std::string sceneBytes() {
  std::ifstream in(kSceneFile, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// small.yaml (glossy floor, glass, 4 samples per pixel) at 40x28 — 5 x 4 tiles of 8 pixels, the
// last row clipped — with a grid overlay, which the checkpoint must not capture.
Scene smallScene() {
  LoadedScene loaded = loadScene(kSceneFile);
  loaded.parts.image.width = 40;
  loaded.parts.image.height = 28;
  loaded.parts.image.grid = GridOverlay{10, Color{1, 1, 0}};
  return Scene(std::move(loaded.parts));
}

bool sameBits(const Film& a, const Film& b) {
  if (a.region() != b.region() || a.pixels().size() != b.pixels().size()) return false;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const Color& p = a.pixels()[i];
    const Color& q = b.pixels()[i];
    if (std::bit_cast<std::uint64_t>(p.r) != std::bit_cast<std::uint64_t>(q.r) ||
        std::bit_cast<std::uint64_t>(p.g) != std::bit_cast<std::uint64_t>(q.g) ||
        std::bit_cast<std::uint64_t>(p.b) != std::bit_cast<std::uint64_t>(q.b))
      return false;
  }
  return true;
}

// One leg of a render: continues `from` (all tiles pending when empty), stops after `stopAfter`
// newly finished tiles (never when 0), and returns the checkpoint as it would be saved, read back
// through encodeCheckpoint/decodeCheckpoint.
struct Leg {
  Checkpoint saved;
  Film film;
  RenderStats stats;
};

Leg renderLeg(const Scene& scene, const std::optional<PixelRegion>& crop, int threads,
              const Checkpoint& from, std::size_t stopAfter) {
  std::atomic<bool> cancel{false};
  CheckpointCollector collector(fs::temp_directory_path() / "unused.ckpt", from,
                                std::chrono::hours(1));
  std::size_t finished = 0;
  RenderOptions options;
  options.threads = threads;
  options.crop = crop;
  options.tileSize = kTileSize;
  options.cancel = &cancel;
  options.resumeFilm = &from.film;
  options.resumeTiles = &from.tiles;
  options.tileFinished = [&](std::size_t tile, const Film& film, int) {
    collector.addTile(tile, film);
    if (++finished == stopAfter) cancel.store(true);
  };
  Leg leg;
  leg.film = render(scene, options, &leg.stats);
  leg.saved = decodeCheckpoint(encodeCheckpoint(collector.checkpoint()), "leg");
  return leg;
}

void checkInterruptedAndResumed(const std::optional<PixelRegion>& crop, unsigned seed) {
  const Scene scene = smallScene();
  const PixelRegion region =
      crop.value_or(PixelRegion{0, 0, scene.image().width, scene.image().height});
  const std::size_t tiles = tileRegions(region, kTileSize).size();
  ASSERT_GE(tiles, 4u);
  const CheckpointSettings settings = checkpointSettingsFor(scene, region, kTileSize);
  const std::uint64_t fingerprint = renderFingerprint(sceneBytes(), scene, settings);

  RenderOptions plain;
  plain.threads = 1;
  plain.crop = crop;
  plain.tileSize = kTileSize;
  const Film reference = render(scene, plain);

  std::mt19937 random(seed);
  for (int trial = 0; trial < 6; ++trial) {
    const int threads = 1 + trial % 3;
    // Stop after k tiles, resume, stop again after k2 more (a resumed render can be interrupted
    // again), then finish.
    const std::size_t k = std::uniform_int_distribution<std::size_t>(1, tiles - 4)(random);
    const std::size_t k2 = std::uniform_int_distribution<std::size_t>(1, 3)(random);
    SCOPED_TRACE(testing::Message() << "trial " << trial << ": threads " << threads
                                    << ", stop after " << k << " then " << k2 << " tiles");

    const Leg first = renderLeg(scene, crop, threads, emptyCheckpoint(fingerprint, settings), k);
    EXPECT_TRUE(first.stats.cancelled);
    EXPECT_GE(first.saved.finishedTiles(), k);
    EXPECT_LT(first.saved.finishedTiles(), tiles) << "the stop came too late to test anything";
    ASSERT_EQ(checkpointMismatch(first.saved, fingerprint, settings), std::nullopt);

    const Leg second = renderLeg(scene, crop, threads, first.saved, k2);
    EXPECT_EQ(second.stats.tilesResumed, first.saved.finishedTiles());
    EXPECT_GE(second.saved.finishedTiles(), first.saved.finishedTiles());

    const Leg last = renderLeg(scene, crop, threads, second.saved, 0);
    EXPECT_FALSE(last.stats.cancelled);
    EXPECT_EQ(last.stats.tilesResumed, second.saved.finishedTiles());
    EXPECT_EQ(last.saved.finishedTiles(), tiles);
    EXPECT_TRUE(sameBits(last.film, reference)) << "the resumed render differs";
    // Pixel samples of the last leg: only the tiles it rendered.
    std::uint64_t pixelsLeft = 0;
    const std::vector<PixelRegion> regions = tileRegions(region, kTileSize);
    for (std::size_t i = 0; i < tiles; ++i)
      if (!second.saved.tiles[i])
        pixelsLeft += static_cast<std::uint64_t>(regions[i].width() * regions[i].height());
    EXPECT_EQ(last.stats.rays.camera,
              pixelsLeft * static_cast<std::uint64_t>(scene.image().samples));
  }
}

TEST(Resume, InterruptedAndResumedRenderIsBitIdentical) {
  checkInterruptedAndResumed(std::nullopt, 20261121);
}

TEST(Resume, InterruptedAndResumedCropIsBitIdentical) {
  checkInterruptedAndResumed(PixelRegion{3, 5, 37, 26}, 6);
}

TEST(Resume, CheckpointHoldsTheFilmBeforeTheGrid) {
  const Scene scene = smallScene();
  const PixelRegion region{0, 0, 40, 28};
  const CheckpointSettings settings = checkpointSettingsFor(scene, region, kTileSize);
  const Leg all = renderLeg(scene, std::nullopt, 2, emptyCheckpoint(1, settings), 0);
  // Pixel (0, 0) lies on a grid line in the image but not in the saved film.
  EXPECT_EQ(all.film.at(0, 0).r, 1.0);
  EXPECT_EQ(all.film.at(0, 0).b, 0.0);
  EXPECT_NE(all.saved.film.at(0, 0).b, 0.0);
}

}  // namespace
}  // namespace glint
