// Which tile goes to which rank and which tiles are finished: rank 0's bookkeeping of an MPI
// render, without MPI and without locks (the coordinator serialises its calls).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace glint::cluster {

class TileScheduler {
 public:
  // `tileCount` tiles over `ranks` ranks; tile i with (*finished)[i] true (taken from a checkpoint)
  // is finished already and never handed out. `finished` may be null.
  TileScheduler(std::size_t tileCount, const std::vector<bool>* finished, int ranks);

  // Hands `rank` up to `count` tiles, the lowest unassigned indices first (the order a one-process
  // render takes them, so a stopped render leaves the top of the image done).
  std::vector<std::uint32_t> assign(int rank, std::size_t count);
  // Records that `rank` finished `tile`: false, with nothing changed, when the tile was not
  // assigned to that rank or is finished already.
  bool finish(int rank, std::uint32_t tile);

  std::size_t inFlight(int rank) const { return inFlight_[static_cast<std::size_t>(rank)]; }
  std::size_t finishedBy(int rank) const { return finishedBy_[static_cast<std::size_t>(rank)]; }
  std::size_t unassigned() const { return owner_.size() - next_ - skippedAhead_; }
  std::size_t finished() const { return finished_; }
  std::size_t total() const { return owner_.size(); }
  bool allFinished() const { return finished_ == owner_.size(); }

 private:
  static constexpr int kUnassigned = -1;
  static constexpr int kFinished = -2;
  std::vector<int> owner_;        // the rank rendering each tile, or kUnassigned / kFinished
  std::size_t next_ = 0;          // every tile below it is assigned or finished
  std::size_t skippedAhead_ = 0;  // finished (resumed) tiles at or above next_
  std::size_t finished_ = 0;
  std::vector<std::size_t> inFlight_;
  std::vector<std::size_t> finishedBy_;
};

}  // namespace glint::cluster
