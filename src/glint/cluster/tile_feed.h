// The tiles handed to one rank's render threads (RenderOptions::nextTile): a queue that rank 0's
// messages fill, which the threads wait on, and the time they spent waiting.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

namespace glint::cluster {

class TileFeed {
 public:
  void push(const std::vector<std::uint32_t>& tiles);
  // No more tiles will come: the threads take what is queued, then end.
  void close();
  // Stop now: the threads end without taking the queued tiles.
  void cancel();

  // For RenderOptions::nextTile: the next queued tile, waiting while none is queued and the feed
  // is neither closed nor cancelled; std::nullopt at the end.
  std::optional<std::size_t> next();

  std::size_t queued() const;
  // Thread-seconds spent waiting inside next() so far.
  double idleSeconds() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::uint32_t> tiles_;
  bool closed_ = false;
  bool cancelled_ = false;
  std::chrono::steady_clock::duration idle_{0};
};

}  // namespace glint::cluster
