#include "glint/preview/preview_state.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <utility>

namespace glint {
namespace {

using Clock = std::chrono::steady_clock;

// How often the encoder looks for finished tiles while rendering. Render threads never wake it:
// a notification per tile would cost them a system call whenever the encoder sleeps.
constexpr std::chrono::milliseconds kEncodeInterval{40};

double secondsBetween(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// FNV-1a (three interleaved chains) over the bit patterns of the pixels of `part` (inside
// `region`, whose rows of `pixels` are `stride` apart): whether the finished image still holds a
// block's tile pixels, at the cost of reading them, not of encoding them again.
std::uint64_t pixelHash(const std::vector<Color>& pixels, const PixelRegion& region, int stride,
                        const PixelRegion& part) {
  constexpr std::uint64_t kPrime = 1099511628211ull;
  std::uint64_t r = 14695981039346656037ull, g = r + 1, b = r + 2;  // three independent chains
  for (int y = part.y0; y < part.y1; ++y) {
    const Color* row =
        pixels.data() + static_cast<std::ptrdiff_t>(y - region.y0) * stride + (part.x0 - region.x0);
    for (int x = 0; x < part.width(); ++x) {
      r = (r ^ std::bit_cast<std::uint64_t>(row[x].r)) * kPrime;
      g = (g ^ std::bit_cast<std::uint64_t>(row[x].g)) * kPrime;
      b = (b ^ std::bit_cast<std::uint64_t>(row[x].b)) * kPrime;
    }
  }
  return ((r ^ (g * kPrime)) * kPrime) ^ b;
}

PixelRegion intersection(const PixelRegion& a, const PixelRegion& b) {
  PixelRegion r{std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1),
                std::min(a.y1, b.y1)};
  if (r.x1 < r.x0) r.x1 = r.x0;
  if (r.y1 < r.y0) r.y1 = r.y0;
  return r;
}

}  // namespace

PreviewState::PreviewState(std::string sceneName) {
  status_.scene = std::move(sceneName);
  encodingThread_ = std::thread([this]() { encodeLoop(); });
}

PreviewState::~PreviewState() {
  {
    const std::lock_guard lock(queueMutex_);
    stopEncoder_ = true;
  }
  queueChanged_.notify_all();
  encodingThread_.join();
  close();
}

void PreviewState::sceneBuilt(const std::string& name, const PixelRegion& region,
                              Encoding encoding) {
  const ChannelEncoder encode(encoding);  // about a millisecond: outside the lock
  {
    const std::lock_guard lock(mutex_);
    if (!name.empty()) status_.scene = name;
    status_.width = region.width();
    status_.height = region.height();
    region_ = region;
    encode_.emplace(encode);
    blocksAcross_ = (region.width() + kPreviewBlockSize - 1) / kPreviewBlockSize;
    const int blocksDown = (region.height() + kPreviewBlockSize - 1) / kPreviewBlockSize;
    const auto blocks =
        static_cast<std::size_t>(blocksAcross_) * static_cast<std::size_t>(blocksDown);
    image_.assign(static_cast<std::size_t>(region.width()) * region.height() * 3, 0);
    blockVersion_.assign(blocks, 0);
    blockRank_.assign(blocks, std::nullopt);
    blockHash_.assign(blocks, std::nullopt);
    ++version_;
  }
  changed_.notify_all();
}

void PreviewState::renderStarting(std::size_t tilesResumed, std::size_t tilesTotal) {
  {
    const std::lock_guard lock(queueMutex_);
    rendering_ = true;
    tilesDone_ = tilesResumed;
    tilesTotal_ = tilesTotal;
  }
  queueChanged_.notify_all();
  {
    const std::lock_guard lock(mutex_);
    status_.phase = PreviewPhase::Rendering;
    status_.tilesDone = tilesResumed;
    status_.tilesResumed = tilesResumed;
    status_.tilesTotal = tilesTotal;
    renderStart_ = Clock::now();
    ++version_;
  }
  changed_.notify_all();
}

void PreviewState::tileFinished(const PixelRegion& region, const Film& film, std::size_t tilesDone,
                                std::size_t tilesTotal, std::optional<int> rank) {
  const auto pixels = static_cast<std::size_t>(region.width()) * region.height();
  bool first = false;  // a caller that did not announce the render: wake the encoder once
  std::vector<Color> buffer;
  {
    const std::lock_guard lock(queueMutex_);
    first = !rendering_;
    rendering_ = true;
    tilesDone_ = std::max(tilesDone_, tilesDone);
    tilesTotal_ = tilesTotal;
    if (pendingPixels_ + pixels > kMaxPendingPixels) {
      ++tilesSkipped_;
      return;
    }
    pendingPixels_ += pixels;
    if (!spare_.empty()) {
      buffer = std::move(spare_.back());
      spare_.pop_back();
    }
  }
  // Copied outside the lock: other render threads may queue their tiles meanwhile. The buffer is a
  // spare one (no allocation once the render is under way).
  buffer.resize(pixels);
  PendingTile tile{region, rank, std::move(buffer)};
  const PixelRegion& filmRegion = film.region();
  for (int y = region.y0; y < region.y1; ++y) {
    const Color* row = &film.at(region.x0 - filmRegion.x0, y - filmRegion.y0);
    std::copy(row, row + region.width(),
              tile.pixels.begin() + static_cast<std::ptrdiff_t>(y - region.y0) * region.width());
  }
  {
    const std::lock_guard lock(queueMutex_);
    pending_.push_back(std::move(tile));
  }
  if (first) queueChanged_.notify_all();
}

void PreviewState::imageFinished(const Film& film) {
  // Painted here, on the job's thread (the render is over), rather than copied for the encoder:
  // no second film in memory. The tiles still queued go first, so that none paints over it.
  const std::lock_guard painting(paintMutex_);
  std::vector<PendingTile> batch;
  {
    const std::lock_guard lock(queueMutex_);
    batch.swap(pending_);
    pendingPixels_ = 0;
  }
  for (const PendingTile& tile : batch)
    paint(tile.region, tile.pixels, tile.region.width(), tile.rank, false);
  recycle(batch);
  // Only the blocks whose pixels changed after their tile was painted (the grid), and those never
  // painted (tiles skipped, or taken from a checkpoint), are encoded again.
  std::vector<std::uint64_t> versions;
  std::vector<std::optional<std::uint64_t>> hashes;
  PixelRegion image;
  {
    const std::lock_guard lock(mutex_);
    versions = blockVersion_;
    hashes = blockHash_;
    image = region_;
  }
  for (std::size_t index = 0; index < versions.size(); ++index) {
    const PixelRegion block = blockRegion(index, image);
    if (versions[index] != 0 && hashes[index] &&
        *hashes[index] == pixelHash(film.pixels(), film.region(), film.width(), block))
      continue;
    paint(film.region(), film.pixels(), film.width(), {}, true, &block);
  }
  changed_.notify_all();
}

PixelRegion PreviewState::blockRegion(std::size_t index, const PixelRegion& image) {
  const auto across =
      static_cast<std::size_t>((image.width() + kPreviewBlockSize - 1) / kPreviewBlockSize);
  const int bx = static_cast<int>(index % across);
  const int by = static_cast<int>(index / across);
  return {image.x0 + bx * kPreviewBlockSize, image.y0 + by * kPreviewBlockSize,
          std::min(image.x0 + (bx + 1) * kPreviewBlockSize, image.x1),
          std::min(image.y0 + (by + 1) * kPreviewBlockSize, image.y1)};
}

void PreviewState::ended(PreviewPhase phase, const std::string& summary) {
  {
    const std::lock_guard lock(queueMutex_);
    ending_ = std::make_pair(phase, summary);
  }
  queueChanged_.notify_all();
}

void PreviewState::recycle(std::vector<PendingTile>& batch) {
  const std::lock_guard lock(queueMutex_);
  for (PendingTile& tile : batch)
    if (spare_.size() < kMaxSpareBuffers) spare_.push_back(std::move(tile.pixels));
  batch.clear();
}

void PreviewState::encodeLoop() {
  std::vector<PendingTile> batch;
  for (;;) {
    std::optional<std::pair<PreviewPhase, std::string>> ending;
    std::size_t tilesDone = 0;
    std::size_t tilesTotal = 0;
    {
      std::unique_lock lock(queueMutex_);
      const auto due = [this]() { return stopEncoder_ || ending_.has_value(); };
      if (rendering_)
        queueChanged_.wait_for(lock, kEncodeInterval, due);
      else
        queueChanged_.wait(lock, [&]() { return due() || rendering_; });
      if (stopEncoder_) return;
    }
    // Whoever paints holds paintMutex_ from taking tiles off the queue until they are painted, so
    // that tiles are painted in the order they were queued, and before the finished image.
    const std::lock_guard painting(paintMutex_);
    {
      const std::lock_guard lock(queueMutex_);
      batch.swap(pending_);
      pendingPixels_ = 0;
      ending.swap(ending_);
      if (ending) rendering_ = false;
      tilesDone = tilesDone_;
      tilesTotal = tilesTotal_;
    }
    for (const PendingTile& tile : batch)
      paint(tile.region, tile.pixels, tile.region.width(), tile.rank, false);
    recycle(batch);
    // The end comes after every pixel (the finished image was painted before ended() was called),
    // so that a reader who sees it has the whole picture.
    {
      const std::lock_guard lock(mutex_);
      if (status_.tilesDone != tilesDone || status_.tilesTotal != tilesTotal) {
        status_.tilesDone = tilesDone;
        status_.tilesTotal = tilesTotal;
        ++version_;
      }
      if (ending) {
        status_.phase = ending->first;
        status_.summary = ending->second;
        renderEnd_ = Clock::now();
        ++version_;
      }
    }
    changed_.notify_all();
  }
}

void PreviewState::paint(const PixelRegion& region, const std::vector<Color>& pixels, int stride,
                         std::optional<int> rank, bool onlyIfChanged, const PixelRegion* only) {
  PixelRegion image;
  const ChannelEncoder* encode = nullptr;
  {
    const std::lock_guard lock(mutex_);
    image = region_;
    if (encode_) encode = &*encode_;
  }
  const PixelRegion inside =
      only ? intersection(intersection(region, image), *only) : intersection(region, image);
  if (!encode || inside.width() <= 0 || inside.height() <= 0) return;
  // Encoded outside the lock, with the image writers' encodeChannel (as a table): the page shows
  // the bytes of the PNG that will be written.
  std::vector<std::uint8_t>& rgb = paintCodes_;
  rgb.resize(static_cast<std::size_t>(inside.width()) * inside.height() * 3);
  std::uint8_t* out = rgb.data();
  for (int y = inside.y0; y < inside.y1; ++y) {
    const Color* row = pixels.data() + static_cast<std::ptrdiff_t>(y - region.y0) * stride +
                       (inside.x0 - region.x0);
    for (int x = 0; x < inside.width(); ++x) {
      *out++ = (*encode)(row[x].r);
      *out++ = (*encode)(row[x].g);
      *out++ = (*encode)(row[x].b);
    }
  }
  // The blocks touched, and for those painted whole the hash of their pixels (imageFinished).
  std::vector<Touched>& touched = paintBlocks_;
  touched.clear();
  const int bx0 = (inside.x0 - image.x0) / kPreviewBlockSize;
  const int bx1 = (inside.x1 - image.x0 + kPreviewBlockSize - 1) / kPreviewBlockSize;
  const int by0 = (inside.y0 - image.y0) / kPreviewBlockSize;
  const int by1 = (inside.y1 - image.y0 + kPreviewBlockSize - 1) / kPreviewBlockSize;
  const auto across =
      static_cast<std::size_t>((image.width() + kPreviewBlockSize - 1) / kPreviewBlockSize);
  for (int by = by0; by < by1; ++by)
    for (int bx = bx0; bx < bx1; ++bx) {
      const std::size_t index = static_cast<std::size_t>(by) * across + bx;
      const PixelRegion block = blockRegion(index, image);
      const PixelRegion part = intersection(block, inside);
      touched.push_back(
          {index, part,
           part == block ? std::optional(pixelHash(pixels, region, stride, part)) : std::nullopt});
    }

  const auto rowBytes = static_cast<std::size_t>(inside.width()) * 3;
  const std::lock_guard lock(mutex_);
  const std::uint64_t version = version_ + 1;
  bool painted = false;
  for (const Touched& block : touched) {
    const PixelRegion& part = block.part;
    const auto span = static_cast<std::size_t>(part.width()) * 3;
    const auto source = [&](int y) {
      return rgb.data() + static_cast<std::size_t>(y - inside.y0) * rowBytes +
             static_cast<std::size_t>(part.x0 - inside.x0) * 3;
    };
    const auto target = [&](int y) {
      return image_.data() +
             (static_cast<std::size_t>(y - image.y0) * image.width() + (part.x0 - image.x0)) * 3;
    };
    bool differs = !onlyIfChanged || blockVersion_[block.index] == 0;
    for (int y = part.y0; y < part.y1 && !differs; ++y)
      differs = std::memcmp(source(y), target(y), span) != 0;
    blockHash_[block.index] = block.hash;
    if (!differs) continue;
    for (int y = part.y0; y < part.y1; ++y) std::memcpy(target(y), source(y), span);
    blockVersion_[block.index] = version;
    if (!onlyIfChanged) blockRank_[block.index] = rank;
    painted = true;
  }
  if (painted) version_ = version;
}

PreviewStatus PreviewState::statusNow() const {
  PreviewStatus status = status_;
  if (status.phase == PreviewPhase::Loading) return status;
  const bool running = status.phase == PreviewPhase::Rendering;
  status.elapsedSeconds = secondsBetween(renderStart_, running ? Clock::now() : renderEnd_);
  const std::size_t doneNow = status.tilesDone - std::min(status.tilesDone, status.tilesResumed);
  if (running && doneNow > 0 && status.tilesTotal >= status.tilesDone)
    status.etaSeconds = status.elapsedSeconds / static_cast<double>(doneNow) *
                        static_cast<double>(status.tilesTotal - status.tilesDone);
  return status;
}

PreviewChanges PreviewState::waitForChanges(std::uint64_t since,
                                            std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&]() { return closed_ || version_ > since; });
  PreviewChanges changes;
  changes.version = version_;
  changes.status = statusNow();
  if (version_ <= since) return changes;
  const int blocksDown =
      blocksAcross_ > 0 ? static_cast<int>(blockVersion_.size()) / blocksAcross_ : 0;
  for (int by = 0; by < blocksDown; ++by) {
    for (int bx = 0; bx < blocksAcross_; ++bx) {
      const std::size_t index = static_cast<std::size_t>(by) * blocksAcross_ + bx;
      if (blockVersion_[index] <= since) continue;
      PreviewTile tile;
      tile.region = {bx * kPreviewBlockSize, by * kPreviewBlockSize,
                     std::min((bx + 1) * kPreviewBlockSize, region_.width()),
                     std::min((by + 1) * kPreviewBlockSize, region_.height())};
      tile.rank = blockRank_[index];
      const auto span = static_cast<std::size_t>(tile.region.width()) * 3;
      tile.rgb.resize(span * tile.region.height());
      for (int y = tile.region.y0; y < tile.region.y1; ++y)
        std::memcpy(
            tile.rgb.data() + static_cast<std::size_t>(y - tile.region.y0) * span,
            image_.data() + (static_cast<std::size_t>(y) * region_.width() + tile.region.x0) * 3,
            span);
      changes.tiles.push_back(std::move(tile));
    }
  }
  return changes;
}

void PreviewState::close() {
  {
    const std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool PreviewState::isClosed() const {
  const std::lock_guard lock(mutex_);
  return closed_;
}

std::size_t PreviewState::tilesSkipped() const {
  const std::lock_guard lock(queueMutex_);
  return tilesSkipped_;
}

}  // namespace glint
