// Checkpoints of an unfinished render (`glint render --checkpoint/--resume`, README "Interrupt and
// resume"): the versioned binary file format, its atomic writing, and the collector that copies
// finished tiles out of a running render.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "glint/render/film.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"

namespace glint {

// Bumped whenever the layout below changes; a file of another version is refused.
inline constexpr std::uint32_t kCheckpointVersion = 2;
// The first 8 bytes of every checkpoint file.
inline constexpr std::string_view kCheckpointMagic{"GLINTCKP", 8};

// The render settings, besides the scene file itself, that determine the pixels of a render: the
// image and render settings after command-line overrides, the rendered region and the tiling.
// Not included because they do not change the linear film: --threads (same bytes on any count),
// the output path and format, image.encoding and the grid overlay (applied when writing; both
// come from the scene file, which is hashed anyway), --quiet, --stats, --max-memory.
struct CheckpointSettings {
  int width = 0;  // full image, pixels
  int height = 0;
  int samples = 0;             // image.samples (the minimum, with adaptive sampling)
  int adaptiveMaxSamples = 0;  // image.adaptive.max_samples; 0: fixed sampling
  double adaptiveThreshold = 0;
  std::uint64_t seed = 0;                       // render.seed
  PixelRegion region;                           // the crop, or the whole image
  int tileSize = 0;                             // pixels per tile side (RenderOptions::tileSize)
  Integrator integrator = Integrator::Whitted;  // render.integrator or --integrator
  friend bool operator==(const CheckpointSettings&, const CheckpointSettings&) = default;
};

// CheckpointSettings as bytes, one layout for the checkpoint file, the render fingerprint and the
// MPI ranks' handshake (all integers little-endian, doubles as their IEEE-754 bits):
//   i32 width, i32 height, i32 samples, i32 adaptiveMaxSamples, f64 adaptiveThreshold, u64 seed,
//   i32 x0, i32 y0, i32 x1, i32 y1, i32 tileSize, i32 integrator (0 whitted, 1 path).
inline constexpr std::size_t kCheckpointSettingsBytes = 4 * 4 + 8 + 8 + 5 * 4 + 4;
std::string encodeCheckpointSettings(const CheckpointSettings& settings);
// Reads exactly kCheckpointSettingsBytes bytes (std::invalid_argument for another size). Values
// are not checked here except the integrator's (std::invalid_argument for an unknown one): each
// reader checks them against what it holds.
CheckpointSettings decodeCheckpointSettings(std::string_view bytes);

// The settings of rendering `scene` over `region` in tiles of `tileSize`.
CheckpointSettings checkpointSettingsFor(const Scene& scene, const PixelRegion& region,
                                         int tileSize);

// 64-bit FNV-1a, continuing from `hash` (so several pieces hash as their concatenation).
inline constexpr std::uint64_t kFnvOffsetBasis = 14695981039346656037ull;
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = kFnvOffsetBasis);

// Every material's values, its texture bindings and the image textures' placement (not their
// pixels), little-endian, in order (for fingerprints).
std::string materialBytes(const std::vector<Material>& materials,
                          const std::vector<MaterialTextures>& bindings,
                          const std::vector<Texture>& textures);

// The fingerprint stored in a checkpoint: FNV-1a 64 over the checkpoint version, the glint
// version, the scene file's bytes, the geometry of every loaded mesh (positions, normals,
// indices, texture coordinates, material index, emission: mesh files are not named in the Scene, so
// their content is hashed as loaded), every material's values (a mesh file's materials too), the
// pixels of every image texture and image background (likewise) and `settings`. A different value
// means the checkpoint belongs to another render.
std::uint64_t renderFingerprint(std::string_view sceneFileBytes, const Scene& scene,
                                const CheckpointSettings& settings);

// A corrupt, truncated, unreadable or unwritable checkpoint file; what() is worded for the user.
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Checkpoint {
  std::uint64_t fingerprint = 0;  // renderFingerprint of the render it belongs to
  CheckpointSettings settings;
  // One flag per tile of tileRegions(settings.region, settings.tileSize): finished and saved.
  std::vector<bool> tiles;
  // Covers settings.region of the settings.width × settings.height image; the pixels of finished
  // tiles are the linear film before the grid overlay, in double precision, so a resumed render
  // gives the same bytes. Other pixels are black.
  Film film;

  std::size_t finishedTiles() const;
};

// An empty checkpoint (no tile finished) for a render with these settings.
Checkpoint emptyCheckpoint(std::uint64_t fingerprint, const CheckpointSettings& settings);

// File format, version 2; all integers little-endian, doubles as their IEEE-754 bits:
//   magic "GLINTCKP" | u32 version | u32 0 (reserved) | u64 fingerprint |
//   settings (encodeCheckpointSettings) |
//   u64 tile count | tile bitmap, ceil(count / 8) bytes, tile i in bit (i % 8) of byte i / 8 |
//   for each finished tile in index order, its pixels row by row: f64 r, g, b |
//   u64 FNV-1a 64 of every byte before it.
std::string encodeCheckpoint(const Checkpoint& checkpoint);
// Throws CheckpointError naming what is wrong (not a checkpoint, another version, truncated,
// inconsistent, checksum mismatch, a film larger than `memoryBudget` bytes); `name` is used in
// the messages.
Checkpoint decodeCheckpoint(std::string_view bytes, const std::string& name,
                            std::uint64_t memoryBudget = defaultImageMemoryBudget());

// The largest file (bytes) a checkpoint starting with `header` can be: header, tile bitmap, every
// pixel of its region, checksum. std::nullopt when `header` is shorter than a header, not of this
// format and version, or its sizes are impossible.
std::optional<std::uint64_t> checkpointSizeLimit(std::string_view header);

// Writes atomically: a temporary file in the same folder (core/atomic_file.h), flushed to disk,
// then renamed over `path`, so a crash or a kill leaves either the old checkpoint or the new one,
// never a torn one.
void writeCheckpoint(const Checkpoint& checkpoint, const std::filesystem::path& path);
// Throws CheckpointError ("cannot read checkpoint 'x': no such file", "...: it is a folder", "...:
// it is not a regular file (a device, FIFO or socket)") unless `path` names a regular file. Decided
// by stat alone, so nothing is opened, read or waited on.
void checkCheckpointFile(const std::filesystem::path& path);
// Reads and decodes a checkpoint file. Only a regular file is opened (a device or a FIFO is refused
// before it is read or waited on), and no more is read than the file's size and what its header
// allows (checkpointSizeLimit), so a foreign file cannot exhaust the memory. Throws
// CheckpointError.
Checkpoint readCheckpoint(const std::filesystem::path& path,
                          std::uint64_t memoryBudget = defaultImageMemoryBudget());

// The first setting in which two renders differ, worded for the user: what ("samples per pixel"),
// then each render's value ("16", "4").
struct SettingDifference {
  std::string what;
  std::string first;
  std::string second;
};
std::optional<SettingDifference> firstSettingDifference(const CheckpointSettings& a,
                                                        const CheckpointSettings& b);

// Why `checkpoint` cannot continue a render with this fingerprint and these settings (naming the
// first setting that differs, e.g. "it was made with --samples 16, this render has 4"), or
// std::nullopt when it can.
std::optional<std::string> checkpointMismatch(const Checkpoint& checkpoint,
                                              std::uint64_t fingerprint,
                                              const CheckpointSettings& settings);

// Collects the finished tiles of a running render (from RenderOptions::tileFinished) and saves
// them every `interval`, and at least 20 times as long as the last save took, so saving never
// costs more than about 5% of the render time.
class CheckpointCollector {
 public:
  // `start`: the checkpoint being continued, or emptyCheckpoint(...).
  CheckpointCollector(std::filesystem::path path, Checkpoint start,
                      std::chrono::duration<double> interval = std::chrono::seconds(5));

  // Copies the pixels of tile `tile` (index in tileRegions) from `film` (the render's film, which
  // covers the same region). Calls must not overlap (the renderer serialises tileFinished).
  void addTile(std::size_t tile, const Film& film);
  // Whether a periodic save is due: new tiles since the last save and the interval is over.
  bool saveDue() const;
  // Writes the checkpoint now (writeCheckpoint); throws CheckpointError.
  void save();

  const Checkpoint& checkpoint() const { return checkpoint_; }
  const std::filesystem::path& path() const { return path_; }
  int saves() const { return saves_; }

 private:
  using Clock = std::chrono::steady_clock;
  std::filesystem::path path_;
  Checkpoint checkpoint_;
  std::vector<PixelRegion> tileRegions_;
  std::chrono::duration<double> interval_;
  Clock::time_point lastSave_;
  std::chrono::duration<double> lastSaveTook_{0};
  bool unsaved_ = false;
  int saves_ = 0;
};

}  // namespace glint
