#include "glint/preview/preview_state.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <utility>

namespace glint {
namespace {

using Clock = std::chrono::steady_clock;

// How often the publisher looks for finished tiles while rendering. Render threads never wake it:
// a notification per tile would cost them a system call whenever the publisher sleeps.
constexpr std::chrono::milliseconds kPublishInterval{40};

double secondsBetween(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// FNV-1a (three interleaved chains) over the bit patterns of the pixels of `part` (inside
// `region`, whose top-left pixel is at `origin` and whose rows are `stride` apart): whether the
// finished image still holds a block's tile pixels, at the cost of reading them, not of encoding
// them again.
std::uint64_t pixelHash(const Color* origin, int stride, const PixelRegion& region,
                        const PixelRegion& part) {
  constexpr std::uint64_t kPrime = 1099511628211ull;
  std::uint64_t r = 14695981039346656037ull, g = r + 1, b = r + 2;  // three independent chains
  for (int y = part.y0; y < part.y1; ++y) {
    const Color* row =
        origin + static_cast<std::ptrdiff_t>(y - region.y0) * stride + (part.x0 - region.x0);
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
  publisher_ = std::thread([this]() { publishLoop(); });
}

PreviewState::~PreviewState() {
  {
    const std::lock_guard lock(queueMutex_);
    stopPublisher_ = true;
  }
  queueChanged_.notify_all();
  publisher_.join();
  close();
}

void PreviewState::sceneBuilt(const std::string& name, const PixelRegion& region,
                              Encoding encoding) {
  // About a millisecond: outside the locks.
  auto encoder = std::make_shared<const ChannelEncoder>(encoding);
  {
    const std::lock_guard lock(mutex_);
    if (!name.empty()) status_.scene = name;
    status_.width = region.width();
    status_.height = region.height();
    region_ = region;
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
  {
    const std::lock_guard lock(queueMutex_);
    encoder_ = std::move(encoder);
    queueImage_ = region;
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
  bool first = false;  // a caller that did not announce the render: wake the publisher once
  bool queued = false;
  PendingTile tile;
  std::shared_ptr<const ChannelEncoder> encode;
  PixelRegion image;
  {
    const std::lock_guard lock(queueMutex_);
    first = !rendering_;
    rendering_ = true;
    tilesDone_ = std::max(tilesDone_, tilesDone);
    tilesTotal_ = tilesTotal;
    if (!encoder_ || pendingPixels_ + pixels > kMaxPendingPixels) {
      ++tilesSkipped_;
    } else {
      queued = true;
      encode = encoder_;
      image = queueImage_;
      pendingPixels_ += pixels;
      if (!spare_.empty()) {
        tile = std::move(spare_.back());
        spare_.pop_back();
      }
    }
  }
  if (!queued) {
    if (first) queueChanged_.notify_all();
    return;
  }
  // Encoded here, outside the lock, while the tile's pixels are still in this core's cache: the
  // queue then holds 3 bytes a pixel, not 24, and the publishing thread only copies them. The
  // buffers are recycled ones (no allocation once the render is under way).
  tile.image = image;
  tile.inside = intersection(region, image);
  tile.rank = rank;
  encodePixels(*encode, film.pixels().data(), film.width(), film.region(), tile.inside, image,
               tile.codes, tile.blocks);
  {
    const std::lock_guard lock(queueMutex_);
    pending_.push_back(std::move(tile));
  }
  if (first) queueChanged_.notify_all();
}

void PreviewState::imageFinished(const Film& film) {
  // Painted here, on the job's thread (the render is over), rather than copied for the publisher:
  // no second film in memory. The tiles still queued go first, so that none paints over it.
  std::shared_ptr<const ChannelEncoder> encode;
  PixelRegion image;
  {
    const std::lock_guard lock(queueMutex_);
    encode = encoder_;
    image = queueImage_;
  }
  if (!encode) return;
  const std::lock_guard painting(paintMutex_);
  std::vector<PendingTile> batch;
  {
    const std::lock_guard lock(queueMutex_);
    batch.swap(pending_);
    pendingPixels_ = 0;
  }
  for (const PendingTile& tile : batch)
    publish(tile.image, tile.inside, tile.codes, tile.blocks, tile.rank, false);
  recycle(batch);
  // Only the blocks whose pixels changed after their tile was painted (the grid), and those never
  // painted (tiles skipped, or taken from a checkpoint), are encoded again.
  std::vector<std::uint64_t> versions;
  std::vector<std::optional<std::uint64_t>> hashes;
  {
    const std::lock_guard lock(mutex_);
    if (region_ != image) return;
    versions = blockVersion_;
    hashes = blockHash_;
  }
  for (std::size_t index = 0; index < versions.size(); ++index) {
    const PixelRegion block = blockRegion(index, image);
    if (versions[index] != 0 && hashes[index] &&
        *hashes[index] == pixelHash(film.pixels().data(), film.width(), film.region(), block))
      continue;
    encodePixels(*encode, film.pixels().data(), film.width(), film.region(), block, image,
                 paintCodes_, paintBlocks_);
    publish(image, block, paintCodes_, paintBlocks_, {}, true);
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
    if (spare_.size() < kMaxSpareBuffers) spare_.push_back(std::move(tile));
  batch.clear();
}

void PreviewState::publishLoop() {
  std::vector<PendingTile> batch;
  for (;;) {
    std::optional<std::pair<PreviewPhase, std::string>> ending;
    std::size_t tilesDone = 0;
    std::size_t tilesTotal = 0;
    {
      std::unique_lock lock(queueMutex_);
      const auto due = [this]() { return stopPublisher_ || ending_.has_value(); };
      if (rendering_)
        queueChanged_.wait_for(lock, kPublishInterval, due);
      else
        queueChanged_.wait(lock, [&]() { return due() || rendering_; });
      if (stopPublisher_) return;
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
      publish(tile.image, tile.inside, tile.codes, tile.blocks, tile.rank, false);
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

void PreviewState::encodePixels(const ChannelEncoder& encode, const Color* origin, int stride,
                                const PixelRegion& region, const PixelRegion& inside,
                                const PixelRegion& image, std::vector<std::uint8_t>& codes,
                                std::vector<Touched>& blocks) {
  codes.resize(static_cast<std::size_t>(std::max(inside.width(), 0)) *
               std::max(inside.height(), 0) * 3);
  blocks.clear();
  if (inside.width() <= 0 || inside.height() <= 0) return;
  std::uint8_t* out = codes.data();
  for (int y = inside.y0; y < inside.y1; ++y) {
    const Color* row =
        origin + static_cast<std::ptrdiff_t>(y - region.y0) * stride + (inside.x0 - region.x0);
    for (int x = 0; x < inside.width(); ++x) {
      *out++ = encode(row[x].r);
      *out++ = encode(row[x].g);
      *out++ = encode(row[x].b);
    }
  }
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
      blocks.push_back(
          {index, part,
           part == block ? std::optional(pixelHash(origin, stride, region, part)) : std::nullopt});
    }
}

void PreviewState::publish(const PixelRegion& image, const PixelRegion& inside,
                           const std::vector<std::uint8_t>& codes,
                           const std::vector<Touched>& blocks, std::optional<int> rank,
                           bool onlyIfChanged) {
  const auto rowBytes = static_cast<std::size_t>(inside.width()) * 3;
  const std::lock_guard lock(mutex_);
  if (image != region_) return;  // encoded for a scene announced before this one
  const std::uint64_t version = version_ + 1;
  bool painted = false;
  for (const Touched& block : blocks) {
    const PixelRegion& part = block.part;
    const auto span = static_cast<std::size_t>(part.width()) * 3;
    const auto source = [&](int y) {
      return codes.data() + static_cast<std::size_t>(y - inside.y0) * rowBytes +
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
