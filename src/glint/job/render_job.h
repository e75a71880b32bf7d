// RenderJob (DESIGN.md §8): what a render needs besides the scene — overrides, the memory limits,
// checkpoint/resume, cancellation, progress and tile callbacks, the atomic output — in one run that
// the command line, MPI ranks and the preview server share.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "glint/core/isa.h"
#include "glint/job/job_error.h"
#include "glint/job/scene_check.h"
#include "glint/readers/diagnostics.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#include "glint/scene/scene_overrides.h"

namespace glint {

struct RenderJobSpec {
  std::filesystem::path scene;  // the scene file; with sceneParts, only the name messages use
  // A scene built in code, rendered instead of reading `scene`. Such a scene has no file bytes to
  // fingerprint, so it cannot be checkpointed.
  std::optional<SceneParts> sceneParts;
  std::filesystem::path output;  // .png, .ppm or .exr; empty: defaultOutputPath(scene)
  SceneOverrides overrides;      // image size, samples, seed; applied before anything is estimated
  // How the caller names what changed the image or the limits ("--width 70000 --max-memory 3M"),
  // quoted in a refusal; empty when nothing did.
  std::string requestText;
  // Worker threads, 0 for all cores. A positive count also limits loading and the BVH build, for
  // the whole process while the job runs (oneTBB's global_control).
  int threads = 0;
  std::optional<PixelRegion> crop;  // render only this region of the image; it is the image
  std::uint64_t memoryBudget = defaultImageMemoryBudget();  // bytes; see LoadOptions
  // Saves the finished tiles there periodically and when stopped; removed once the image is
  // written. Default with `resume`: the resumed file.
  std::optional<std::filesystem::path> checkpoint;
  std::optional<std::filesystem::path> resume;  // continue the render saved in this checkpoint
  int tileSize = 16;                            // pixels per tile side; part of the fingerprint
  // The instruction set of the BVH queries (core/isa.h); none: defaultIsa() (GLINT_ISA, else the
  // widest this processor runs). Never changes a pixel. One this processor lacks, or a bad
  // GLINT_ISA, is bad input (exit status 2) before any work.
  std::optional<Isa> isa;
  // Least time between periodic checkpoint saves (longer when a save is slow: at most ~5% of the
  // render goes to saving).
  std::chrono::duration<double> checkpointInterval = std::chrono::seconds(5);
  // Set by the caller to stop the job (from a signal handler, another thread or a callback): the
  // load, the render (within one pixel sample) and the image write stop, the checkpoint is saved,
  // and run returns an Interrupted result. Not owned; may be null.
  const std::atomic<bool>* cancel = nullptr;
  // The signal that set `cancel`, reported in the result (0 or null: not a signal). Not owned.
  const std::atomic<int>* cancelSignal = nullptr;
  // Renders in place of renderInto, with the same contract: fills `film` (the region, resumed
  // tiles included), calls the options' callbacks, sets the stats. The MPI coordinator (cluster/)
  // spreads the tiles over processes here. A JobError it throws fails the job, after the finished
  // tiles are saved to the checkpoint when it is a Failure. Empty: renderInto in this process.
  std::function<void(const Scene&, const RenderOptions&, Film&, RenderStats&)> renderStep;
};

// A tile the render just finished.
struct FinishedTile {
  std::size_t index = 0;  // in tileRegions(region, tileSize)
  PixelRegion region;     // its pixels, in full-image coordinates
  const Film& film;  // the render's film: the pixels inside `region` are final (before the grid)
  std::size_t done = 0;     // tiles finished so far (resumed ones included) ...
  std::size_t total = 0;    // ... of this many
  std::optional<int> rank;  // the MPI rank that rendered it (none outside MPI)
};

// What a caller hears while the job runs. Every callback is optional. They are called on the
// thread that runs the job, except progress and tileFinished: from render threads, one at a time.
// (tileFinished is also called for each tile a resumed checkpoint holds, on the job's thread,
// after renderStarting and before the render.)
struct RenderJobEvents {
  // The scene's warnings (FILE:LINE:COL), once it is loaded, before anything else is done.
  std::function<void(const std::vector<Diagnostic>&)> sceneWarnings;
  // The scene is built: what will be rendered, and the region of the image rendered (the crop, or
  // all of it).
  std::function<void(const SceneFacts&, const PixelRegion&)> sceneBuilt;
  // Rendering begins: tiles taken from the checkpoint, tiles in all.
  std::function<void(std::size_t, std::size_t)> renderStarting;
  // After each finished tile: (tiles done, tiles in all).
  std::function<void(std::size_t, std::size_t)> progress;
  // After each finished tile, with its pixels (the preview server, MPI and checkpoints hook here).
  std::function<void(const FinishedTile&)> tileFinished;
  // The render returned, finished or stopped.
  std::function<void()> renderEnded;
  // The finished image as it will be written (grid included), just before the write.
  std::function<void(const Film&)> imageFinished;
  // A periodic checkpoint save failed (reported once; the render goes on); worded for the user.
  std::function<void(const std::string&)> checkpointSaveFailed;
  // True while the job commits a file (a checkpoint, the image): the caller should not end the
  // process abruptly then, or a temporary file would stay behind. False when it is done.
  std::function<void(bool)> committing;
};

// Seconds spent in each phase.
struct RenderJobTimings {
  double load = 0;
  double build = 0;
  double render = 0;
  double write = 0;
};

struct RenderJobResult {
  enum class Outcome {
    Written,      // the image is complete in `output`
    Interrupted,  // stopped through the cancel flag; nothing written but the checkpoint
  };
  Outcome outcome = Outcome::Written;
  int signal = 0;  // Interrupted: *cancelSignal when it stopped (0 when it was no signal)

  std::filesystem::path output;     // the image path (resolved)
  std::optional<PixelRegion> crop;  // the rendered region when not the whole image
  SceneFacts scene;                 // what was rendered (set once the scene is built)
  RenderStats stats;                // rays, samples, non-finite samples, tiles resumed
  RenderJobTimings timings;
  std::uint64_t pixelsRendered = 0;  // by this run: tiles taken from a checkpoint excluded
  std::size_t tilesTotal = 0;
  std::size_t tilesResumed = 0;
  std::optional<std::filesystem::path> resumedFrom;  // the checkpoint this run continued

  // Interrupted with checkpointing: where the finished tiles were saved and how many there are,
  // or why that final save failed (worded for the user). Both empty when the job stopped before
  // rendering (nothing new to save).
  std::optional<std::filesystem::path> checkpointSavedTo;
  std::size_t tilesSaved = 0;
  std::string checkpointSaveError;
  // Written: why the checkpoint, no longer needed, could not be removed; empty when it was.
  std::string checkpointRemovalError;
};

// Runs the job: checks the output and checkpoint paths before any work, removes temporary files
// that killed glint processes left in those folders, loads the scene (overrides, memory budget,
// cancel flag), warns about absurd pixel work, enforces the image limits, builds the scene, sets up
// checkpoint/resume (fingerprint, mismatch, periodic saves), renders, and writes the image
// atomically. Throws JobError for bad input (exit status 2) and failures (1); a stop through the
// cancel flag is not an error but an Interrupted result. An exception a callback of `events`
// throws ends the job and comes out of runRenderJob as it was thrown (not as a JobError), with no
// temporary file left behind. A missing OpenEXR module for an .exr output is a failure (1), found
// before the scene is loaded.
RenderJobResult runRenderJob(RenderJobSpec spec, const RenderJobEvents& events = {});

}  // namespace glint
