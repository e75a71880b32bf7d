// Rank 0's tile bookkeeping hands each tile out once, lowest first, skips resumed tiles and knows
// who finished what; the feed hands queued tiles to waiting threads and ends on close or cancel.
#include "glint/cluster/tile_scheduler.h"

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <thread>
#include <vector>

#include "glint/cluster/tile_feed.h"

namespace glint::cluster {
namespace {

using Tiles = std::vector<std::uint32_t>;

TEST(TileScheduler, HandsOutEachTileOnceLowestFirstAndSkipsResumedOnes) {
  const std::vector<bool> resumed{false, true, true, false, false, true};
  TileScheduler scheduler(6, &resumed, 3);
  EXPECT_EQ(scheduler.finished(), 3u);
  EXPECT_EQ(scheduler.unassigned(), 3u);
  EXPECT_EQ(scheduler.assign(1, 2), (Tiles{0, 3}));
  EXPECT_EQ(scheduler.assign(0, 5), (Tiles{4}));
  EXPECT_TRUE(scheduler.assign(2, 1).empty());
  EXPECT_EQ(scheduler.unassigned(), 0u);
  EXPECT_EQ(scheduler.inFlight(1), 2u);

  EXPECT_FALSE(scheduler.finish(2, 0)) << "tile 0 is rank 1's";
  EXPECT_FALSE(scheduler.finish(1, 1)) << "tile 1 was resumed";
  EXPECT_FALSE(scheduler.finish(1, 99));
  EXPECT_TRUE(scheduler.finish(1, 3));
  EXPECT_FALSE(scheduler.finish(1, 3)) << "a duplicate";
  EXPECT_TRUE(scheduler.finish(0, 4));
  EXPECT_FALSE(scheduler.allFinished());
  EXPECT_TRUE(scheduler.finish(1, 0));
  EXPECT_TRUE(scheduler.allFinished());
  EXPECT_EQ(scheduler.finishedBy(1), 2u);
  EXPECT_EQ(scheduler.finishedBy(0), 1u);
  EXPECT_EQ(scheduler.inFlight(1), 0u);
}

TEST(TileScheduler, AllResumedIsFinishedAtOnce) {
  const std::vector<bool> resumed(4, true);
  TileScheduler scheduler(4, &resumed, 1);
  EXPECT_TRUE(scheduler.allFinished());
  EXPECT_TRUE(scheduler.assign(0, 4).empty());
  EXPECT_THROW(TileScheduler(3, &resumed, 1), std::invalid_argument);
}

TEST(TileFeed, WaitingThreadsGetPushedTilesAndEndOnClose) {
  TileFeed feed;
  std::vector<std::size_t> taken;
  std::thread taker([&] {
    while (const std::optional<std::size_t> tile = feed.next()) taken.push_back(*tile);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  feed.push({5, 6});
  feed.push({2});
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  feed.close();
  taker.join();
  EXPECT_EQ(taken, (std::vector<std::size_t>{5, 6, 2}));
  EXPECT_GT(feed.idleSeconds(), 0.01);
}

TEST(TileFeed, CancelDropsTheQueuedTiles) {
  TileFeed feed;
  feed.push({1, 2, 3});
  feed.cancel();
  EXPECT_FALSE(feed.next());
  EXPECT_EQ(feed.queued(), 3u);
}

}  // namespace
}  // namespace glint::cluster
