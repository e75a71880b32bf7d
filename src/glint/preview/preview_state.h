// PreviewState: what the preview page shows of one render — the image, encoded to 8 bits exactly as
// the output file will be, the progress and the outcome — filled by the render's callbacks without
// ever making them wait for a reader, and read by the preview server's connections.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "glint/image/channel_encoder.h"
#include "glint/render/film.h"
#include "glint/scene/scene.h"

namespace glint {

enum class PreviewPhase { Loading, Rendering, Finished, Interrupted, Failed };

// One block of the image as the page receives it. The image is cut into kPreviewBlockSize blocks
// from its top-left corner: with the default tile size a block is one render tile.
struct PreviewTile {
  PixelRegion region;             // in image pixels, (0, 0) the top-left of the rendered image
  std::optional<int> rank;        // the MPI rank that rendered it; empty when one process renders
  std::vector<std::uint8_t> rgb;  // region.width() × region.height() pixels, 3 codes each, by rows
};

inline constexpr int kPreviewBlockSize = 16;

// The render's progress and outcome as the page shows it.
struct PreviewStatus {
  PreviewPhase phase = PreviewPhase::Loading;
  std::string scene;  // the scene's name, or its file
  int width = 0;      // of the rendered image (the crop when cropped); 0 until built
  int height = 0;
  std::size_t tilesDone = 0;         // render tiles finished (resumed ones included) ...
  std::size_t tilesTotal = 0;        // ... of this many
  std::size_t tilesResumed = 0;      // taken from a checkpoint
  double elapsedSeconds = 0;         // since rendering began; frozen when it ended
  std::optional<double> etaSeconds;  // while rendering, once this run has finished a tile
  std::string summary;               // once it ended: the summary the command printed, or the error
};

// What changed since a reader last looked (PreviewState::waitForChanges).
struct PreviewChanges {
  std::uint64_t version = 0;       // give it back to see only later changes
  PreviewStatus status;            // always the current one
  std::vector<PreviewTile> tiles;  // blocks painted or repainted since, latest pixels only
};

class PreviewState {
 public:
  // Render tiles' pixels waiting to be published, at most: beyond this a tile is not shown until
  // the render ends (the finished image repaints what is missing), so the render never waits.
  static constexpr std::size_t kMaxPendingPixels = std::size_t{1} << 22;

  explicit PreviewState(std::string sceneName);
  ~PreviewState();
  PreviewState(const PreviewState&) = delete;
  PreviewState& operator=(const PreviewState&) = delete;

  // --- the render's side (RenderJobEvents; see attachPreview) ---
  // The scene is built: the region of the image that is rendered (the crop, or all of it) and how
  // its pixels are encoded to 8 bits.
  void sceneBuilt(const std::string& name, const PixelRegion& region, Encoding encoding);
  void renderStarting(std::size_t tilesResumed, std::size_t tilesTotal);
  // From a render thread: encodes the tile's pixels (final in `film`; a few nanoseconds a pixel,
  // the image writers' encodeChannel as a table) into a queue and returns; this state's own thread
  // publishes them. `region` is in full-image pixels, as the film's.
  void tileFinished(const PixelRegion& region, const Film& film, std::size_t tilesDone,
                    std::size_t tilesTotal, std::optional<int> rank = std::nullopt);
  // The finished image as it will be written (grid included): repaints every block that differs
  // (the grid, skipped tiles, tiles taken from a checkpoint). Encodes on the calling thread.
  void imageFinished(const Film& film);
  // The render ended (Finished, Interrupted or Failed) with this summary or error text.
  void ended(PreviewPhase phase, const std::string& summary);

  // --- the server's side ---
  // Waits until something changed after `since` (0: nothing seen yet) or `timeout` passed, then
  // returns the status and every block changed after `since` (all painted blocks for 0). A slow
  // reader gets merged updates: only each block's latest pixels.
  PreviewChanges waitForChanges(std::uint64_t since, std::chrono::milliseconds timeout);
  // Wakes every reader and makes waitForChanges return at once from now on (the server stops).
  void close();
  bool isClosed() const;

  // Tiles that could not be shown while rendering because too many pixels waited (see above).
  std::size_t tilesSkipped() const;

 private:
  // A block that encoded pixels touch, and the hash of its pixels when they cover it whole.
  struct Touched {
    std::size_t index;
    PixelRegion part;
    std::optional<std::uint64_t> hash;
  };
  // A finished tile, encoded, waiting to be published.
  struct PendingTile {
    PixelRegion image;   // the rendered region when it was encoded: what `blocks` index
    PixelRegion inside;  // full-image pixels, within `image`
    std::optional<int> rank;
    std::vector<std::uint8_t> codes;  // 3 a pixel, by rows
    std::vector<Touched> blocks;
  };
  // Tiles kept for reuse: render threads then queue tiles without allocating.
  static constexpr std::size_t kMaxSpareBuffers = 256;

  void publishLoop();
  void recycle(std::vector<PendingTile>& batch);  // its buffers to spare_; empties it
  // The codes of the pixels `inside` (rows `stride` apart from `origin`, the top-left pixel of
  // `region`) and the blocks of `image` they touch.
  static void encodePixels(const ChannelEncoder& encode, const Color* origin, int stride,
                           const PixelRegion& region, const PixelRegion& inside,
                           const PixelRegion& image, std::vector<std::uint8_t>& codes,
                           std::vector<Touched>& blocks);
  // Copies encoded pixels into the image and gives their blocks a new version: all of them, or
  // only those whose codes differ. Nothing when `image` is no longer the rendered region.
  void publish(const PixelRegion& image, const PixelRegion& inside,
               const std::vector<std::uint8_t>& codes, const std::vector<Touched>& blocks,
               std::optional<int> rank, bool onlyIfChanged);
  // Block `index` in full-image pixels, for the image region `image`.
  static PixelRegion blockRegion(std::size_t index, const PixelRegion& image);
  PreviewStatus statusNow() const;  // with mutex_ held

  // Held by whoever publishes queued tiles (the publisher, imageFinished) while it does; guards
  // the scratch buffers of imageFinished.
  std::mutex paintMutex_;
  std::vector<std::uint8_t> paintCodes_;
  std::vector<Touched> paintBlocks_;
  // Render threads and the publishing thread: the tiles waiting to be published.
  mutable std::mutex queueMutex_;
  std::condition_variable queueChanged_;
  std::vector<PendingTile> pending_;
  std::vector<PendingTile> spare_;
  // Set with the scene. Shared, so that a render thread encoding outside the lock keeps the one
  // it took even if the scene is announced again.
  std::shared_ptr<const ChannelEncoder> encoder_;
  PixelRegion queueImage_;  // region_, likewise
  std::size_t pendingPixels_ = 0;
  std::size_t tilesSkipped_ = 0;
  std::size_t tilesDone_ = 0;  // the latest progress a tile reported
  std::size_t tilesTotal_ = 0;
  std::optional<std::pair<PreviewPhase, std::string>> ending_;
  bool rendering_ = false;  // the publisher polls while tiles may come, and sleeps otherwise
  bool stopPublisher_ = false;

  // The publisher, the job's thread and the readers: the 8-bit image and the status.
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::uint64_t version_ = 0;
  PreviewStatus status_;
  PixelRegion region_;  // full-image pixels rendered
  int blocksAcross_ = 0;
  std::vector<std::uint8_t> image_;            // region_ pixels, RGB
  std::vector<std::uint64_t> blockVersion_;    // 0: never painted
  std::vector<std::optional<int>> blockRank_;  // who rendered it
  // The hash of its pixels when one tile covered it whole (see imageFinished).
  std::vector<std::optional<std::uint64_t>> blockHash_;
  std::chrono::steady_clock::time_point renderStart_;
  std::chrono::steady_clock::time_point renderEnd_;
  bool closed_ = false;

  std::thread publisher_;
};

}  // namespace glint
