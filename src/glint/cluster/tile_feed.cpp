#include "glint/cluster/tile_feed.h"

namespace glint::cluster {

void TileFeed::push(const std::vector<std::uint32_t>& tiles) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    tiles_.insert(tiles_.end(), tiles.begin(), tiles.end());
  }
  changed_.notify_all();
}

void TileFeed::close() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

void TileFeed::cancel() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    cancelled_ = true;
  }
  changed_.notify_all();
}

std::optional<std::size_t> TileFeed::next() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (tiles_.empty() && !closed_ && !cancelled_) {
    const auto start = std::chrono::steady_clock::now();
    changed_.wait(lock, [this] { return !tiles_.empty() || closed_ || cancelled_; });
    idle_ += std::chrono::steady_clock::now() - start;
  }
  if (cancelled_ || tiles_.empty()) return std::nullopt;
  const std::uint32_t tile = tiles_.front();
  tiles_.pop_front();
  return tile;
}

std::size_t TileFeed::queued() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return tiles_.size();
}

double TileFeed::idleSeconds() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return std::chrono::duration<double>(idle_).count();
}

}  // namespace glint::cluster
