#include "glint/cluster/tile_scheduler.h"

#include <stdexcept>

namespace glint::cluster {

TileScheduler::TileScheduler(std::size_t tileCount, const std::vector<bool>* finished, int ranks)
    : owner_(tileCount, kUnassigned),
      inFlight_(static_cast<std::size_t>(ranks), 0),
      finishedBy_(static_cast<std::size_t>(ranks), 0) {
  if (ranks < 1) throw std::invalid_argument("a render needs at least one rank");
  if (finished != nullptr && finished->size() != tileCount)
    throw std::invalid_argument("the finished tiles cover a different tiling");
  for (std::size_t i = 0; finished != nullptr && i < tileCount; ++i) {
    if ((*finished)[i]) {
      owner_[i] = kFinished;
      ++finished_;
      ++skippedAhead_;
    }
  }
}

std::vector<std::uint32_t> TileScheduler::assign(int rank, std::size_t count) {
  std::vector<std::uint32_t> tiles;
  while (tiles.size() < count && next_ < owner_.size()) {
    const std::size_t tile = next_++;
    if (owner_[tile] == kFinished) {
      --skippedAhead_;
      continue;
    }
    owner_[tile] = rank;
    tiles.push_back(static_cast<std::uint32_t>(tile));
  }
  inFlight_[static_cast<std::size_t>(rank)] += tiles.size();
  return tiles;
}

bool TileScheduler::finish(int rank, std::uint32_t tile) {
  if (rank < 0 || tile >= owner_.size() || owner_[tile] != rank) return false;
  owner_[tile] = kFinished;
  ++finished_;
  --inFlight_[static_cast<std::size_t>(rank)];
  ++finishedBy_[static_cast<std::size_t>(rank)];
  return true;
}

}  // namespace glint::cluster
