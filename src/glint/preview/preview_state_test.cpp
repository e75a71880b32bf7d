#include "glint/preview/preview_state.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "glint/image/image_writer.h"

namespace glint {
namespace {

using namespace std::chrono_literals;

// A film over `region` whose pixels vary by position, with the values encoders must get right:
// NaN, negative, above 1.
Film patternFilm(int fullWidth, int fullHeight, const PixelRegion& region, double shift = 0) {
  Film film(fullWidth, fullHeight, region);
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x)
      film.at(x, y) =
          Color(std::fmod(0.013 * x + 0.029 * y + shift, 1.3) - 0.1, 0.5 * x / film.width(),
                (x + y) % 7 == 0 ? std::numeric_limits<double>::quiet_NaN() : 0.2);
  return film;
}

std::vector<PixelRegion> tilesOf(const PixelRegion& region, int size) {
  std::vector<PixelRegion> tiles;
  for (int y = region.y0; y < region.y1; y += size)
    for (int x = region.x0; x < region.x1; x += size)
      tiles.push_back({x, y, std::min(x + size, region.x1), std::min(y + size, region.y1)});
  return tiles;
}

// Waits (the publisher runs on its own thread) until `done` holds for the changes since `since`.
template <typename Done>
PreviewChanges waitUntil(PreviewState& state, std::uint64_t since, Done done) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  PreviewChanges changes = state.waitForChanges(since, 50ms);
  while (!done(changes) && std::chrono::steady_clock::now() < deadline)
    changes = state.waitForChanges(since, 50ms);
  EXPECT_TRUE(done(changes)) << "the preview never got there";
  return changes;
}

// The image the page would assemble from every block received.
std::vector<std::uint8_t> assemble(const PreviewChanges& changes) {
  const int width = changes.status.width;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * changes.status.height * 3);
  for (const PreviewTile& tile : changes.tiles)
    for (int y = tile.region.y0; y < tile.region.y1; ++y)
      for (int x = tile.region.x0; x < tile.region.x1; ++x)
        for (int c = 0; c < 3; ++c)
          rgb[(static_cast<std::size_t>(y) * width + x) * 3 + c] =
              tile.rgb[(static_cast<std::size_t>(y - tile.region.y0) * tile.region.width() +
                        (x - tile.region.x0)) *
                           3 +
                       c];
  return rgb;
}

std::vector<std::uint8_t> encoded(const Film& film, Encoding encoding) {
  std::vector<std::uint8_t> rgb;
  for (const Color& c : film.pixels())
    for (const double v : {c.r, c.g, c.b}) rgb.push_back(encodeChannel(v, encoding));
  return rgb;
}

void renderAll(PreviewState& state, const Film& film, std::optional<int> rank = std::nullopt) {
  const std::vector<PixelRegion> tiles = tilesOf(film.region(), 16);
  state.renderStarting(0, tiles.size());
  for (std::size_t i = 0; i < tiles.size(); ++i)
    state.tileFinished(tiles[i], film, i + 1, tiles.size(), rank);
}

TEST(PreviewState, TilesArriveEncodedAsTheImageWritersEncode) {
  for (const Encoding encoding : {Encoding::Srgb, Encoding::Linear}) {
    PreviewState state("scene.yaml");
    const PixelRegion whole{0, 0, 40, 20};
    const Film film = patternFilm(40, 20, whole);
    state.sceneBuilt("", whole, encoding);
    renderAll(state, film);
    const PreviewChanges changes = waitUntil(state, 0, [](const PreviewChanges& c) {
      return c.tiles.size() == 6 && c.status.tilesDone == 6;
    });
    EXPECT_EQ(changes.status.scene, "scene.yaml");
    EXPECT_EQ(changes.status.phase, PreviewPhase::Rendering);
    EXPECT_EQ(changes.status.tilesDone, 6u);
    EXPECT_EQ(changes.status.tilesTotal, 6u);
    EXPECT_EQ(assemble(changes), encoded(film, encoding));
    for (const PreviewTile& tile : changes.tiles) EXPECT_FALSE(tile.rank.has_value());
  }
}

TEST(PreviewState, ACropIsItsOwnImage) {
  PreviewState state("crop");
  const PixelRegion crop{8, 4, 40, 20};
  const Film film = patternFilm(64, 48, crop);
  state.sceneBuilt("named", crop, Encoding::Srgb);
  renderAll(state, film);
  const PreviewChanges changes =
      waitUntil(state, 0, [](const PreviewChanges& c) { return c.tiles.size() == 2; });
  EXPECT_EQ(changes.status.scene, "named");
  EXPECT_EQ(changes.status.width, 32);
  EXPECT_EQ(changes.status.height, 16);
  EXPECT_EQ(assemble(changes), encoded(film, Encoding::Srgb));
}

// Tiles queued for the first announcement (a larger image) must not land in the second one's
// blocks; the second image is whole and encoded its own way.
TEST(PreviewState, ASceneAnnouncedAgainStartsAFreshImage) {
  PreviewState state("s");
  const PixelRegion large{0, 0, 96, 64};
  const PixelRegion small{0, 0, 32, 16};
  const Film largeFilm = patternFilm(96, 64, large);
  const Film smallFilm = patternFilm(32, 16, small, 0.25);
  state.sceneBuilt("", large, Encoding::Srgb);
  renderAll(state, largeFilm);
  state.sceneBuilt("", small, Encoding::Linear);
  renderAll(state, smallFilm);
  state.imageFinished(smallFilm);
  const PreviewChanges changes = waitUntil(state, 0, [](const PreviewChanges& c) {
    return c.status.width == 32 && c.tiles.size() == 2;
  });
  EXPECT_EQ(assemble(changes), encoded(smallFilm, Encoding::Linear));
}

TEST(PreviewState, ASlowReaderGetsEachBlocksLatestPixelsOnce) {
  PreviewState state("s");
  const PixelRegion whole{0, 0, 32, 16};
  const Film first = patternFilm(32, 16, whole);
  const Film second = patternFilm(32, 16, whole, 0.5);
  state.sceneBuilt("", whole, Encoding::Srgb);
  renderAll(state, first);
  const std::uint64_t seen =
      waitUntil(state, 0, [](const PreviewChanges& c) { return c.tiles.size() == 2; }).version;
  // The left block changes twice before the reader looks again.
  state.tileFinished({0, 0, 16, 16}, second, 2, 2);
  const std::uint64_t between =
      waitUntil(state, seen, [](const PreviewChanges& c) { return !c.tiles.empty(); }).version;
  state.tileFinished({0, 0, 16, 16}, first, 2, 2);
  waitUntil(state, between, [](const PreviewChanges& c) { return !c.tiles.empty(); });
  const PreviewChanges changes = state.waitForChanges(seen, 0ms);
  ASSERT_EQ(changes.tiles.size(), 1u);
  EXPECT_EQ(changes.tiles[0].region, (PixelRegion{0, 0, 16, 16}));
  EXPECT_EQ(assemble(state.waitForChanges(0, 0ms)), encoded(first, Encoding::Srgb));
}

TEST(PreviewState, TheFinishedImageRepaintsOnlyWhatDiffersAndTheEndComesAfterIt) {
  PreviewState state("s");
  const PixelRegion whole{0, 0, 48, 16};
  const Film rendered = patternFilm(48, 16, whole);
  state.sceneBuilt("", whole, Encoding::Srgb);
  renderAll(state, rendered, 2);
  const std::uint64_t seen =
      waitUntil(state, 0, [](const PreviewChanges& c) { return c.tiles.size() == 3; }).version;
  Film finished = rendered;  // a grid line through the middle block only
  for (int y = 0; y < 16; ++y) finished.at(20, y) = Color(1, 1, 0);
  state.imageFinished(finished);
  state.ended(PreviewPhase::Finished, "glint: wrote it");
  const PreviewChanges changes = waitUntil(state, seen, [](const PreviewChanges& c) {
    return c.status.phase == PreviewPhase::Finished;
  });
  ASSERT_EQ(changes.tiles.size(), 1u);
  EXPECT_EQ(changes.tiles[0].region, (PixelRegion{16, 0, 32, 16}));
  EXPECT_EQ(changes.tiles[0].rank, 2);  // the finished image does not change who rendered it
  EXPECT_EQ(changes.status.summary, "glint: wrote it");
  EXPECT_FALSE(changes.status.etaSeconds.has_value());
  EXPECT_EQ(assemble(state.waitForChanges(0, 0ms)), encoded(finished, Encoding::Srgb));
}

TEST(PreviewState, TheFinishedImageFillsBlocksNoTileShowed) {
  PreviewState state("s");
  const PixelRegion whole{0, 0, 40, 20};  // blocks cut at the right and bottom edges
  const Film film = patternFilm(40, 20, whole);
  state.sceneBuilt("", whole, Encoding::Srgb);
  state.renderStarting(2, 6);  // as if two tiles came from a checkpoint
  for (const PixelRegion& tile : tilesOf(whole, 16))
    if (tile.x0 != 16) state.tileFinished(tile, film, 6, 6);
  state.imageFinished(film);
  state.ended(PreviewPhase::Finished, "");
  const PreviewChanges changes = waitUntil(
      state, 0, [](const PreviewChanges& c) { return c.status.phase == PreviewPhase::Finished; });
  EXPECT_EQ(changes.tiles.size(), 6u);
  EXPECT_EQ(assemble(changes), encoded(film, Encoding::Srgb));
}

TEST(PreviewState, ReportsEtaWhileRenderingAndFreezesTheTimeAtTheEnd) {
  PreviewState state("s");
  const PixelRegion whole{0, 0, 64, 16};
  const Film film = patternFilm(64, 16, whole);
  state.sceneBuilt("", whole, Encoding::Srgb);
  state.renderStarting(1, 4);  // one tile resumed from a checkpoint
  std::this_thread::sleep_for(20ms);
  state.tileFinished({16, 0, 32, 16}, film, 2, 4);
  const PreviewChanges rendering =
      waitUntil(state, 0, [](const PreviewChanges& c) { return c.status.tilesDone == 2; });
  EXPECT_EQ(rendering.status.tilesResumed, 1u);
  ASSERT_TRUE(rendering.status.etaSeconds.has_value());
  // One tile rendered now in the elapsed time, two to go.
  EXPECT_NEAR(*rendering.status.etaSeconds, 2 * rendering.status.elapsedSeconds, 0.05);
  state.ended(PreviewPhase::Interrupted, "interrupted");
  const double elapsed = waitUntil(state, 0, [](const PreviewChanges& c) {
                           return c.status.phase == PreviewPhase::Interrupted;
                         }).status.elapsedSeconds;
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(state.waitForChanges(0, 0ms).status.elapsedSeconds, elapsed);
}

TEST(PreviewState, CloseWakesAWaitingReaderAtOnce) {
  PreviewState state("s");
  const std::uint64_t now = state.waitForChanges(0, 0ms).version;
  std::thread closer([&state]() {
    std::this_thread::sleep_for(50ms);
    state.close();
  });
  const auto start = std::chrono::steady_clock::now();
  state.waitForChanges(now, 20s);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  EXPECT_TRUE(state.isClosed());
  closer.join();
}

}  // namespace
}  // namespace glint
