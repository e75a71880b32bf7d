#include "glint/job/render_job.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <utility>

#include "glint/accel/aggregate.h"
#include "glint/core/atomic_file.h"
#include "glint/core/cancel.h"
#include "glint/core/file_access.h"
#include "glint/core/isa.h"
#include "glint/image/image_writer.h"
#include "glint/job/checkpoint.h"
#include "glint/job/job_steps.h"
#include "glint/job/output_paths.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

fs::path folderOf(const fs::path& path) {
  return path.parent_path().empty() ? fs::path(".") : path.parent_path();
}

// Scoped JobEvents::committing(true) … (false).
class Committing {
 public:
  explicit Committing(const RenderJobEvents& events) : events_(events) {
    if (events_.committing) events_.committing(true);
  }
  Committing(const Committing&) = delete;
  Committing& operator=(const Committing&) = delete;
  ~Committing() {
    if (events_.committing) events_.committing(false);
  }

 private:
  const RenderJobEvents& events_;
};

}  // namespace

RenderJobResult runRenderJob(RenderJobSpec spec, const RenderJobEvents& events) {
  // --threads N means N threads for the whole job: without this limit, oneTBB sizes its worker pool
  // at the first parallel loop (the BVH build: all cores) and warns on stderr when the render then
  // asks for more.
  std::optional<tbb::global_control> parallelism;
  if (spec.threads > 0)
    parallelism.emplace(tbb::global_control::max_allowed_parallelism,
                        static_cast<std::size_t>(spec.threads));

  const bool fromFile = !spec.sceneParts.has_value();
  if (!fromFile && (spec.checkpoint || spec.resume))
    throw JobError(JobFailure::BadInput,
                   "a scene built in code cannot be checkpointed: it has no file to fingerprint");
  if (!fromFile && spec.output.empty())
    throw JobError(JobFailure::BadInput, "a scene built in code needs an output path");
  // The kernels' ISA: a bad GLINT_ISA is refused even when spec.isa overrides it, since every
  // Aggregate starts from defaultIsa(); so is a bad GLINT_BVH_WIDTH (bvhNodeWidth).
  Isa isa = Isa::Baseline;
  try {
    isa = defaultIsa();
    if (spec.isa) {
      requireIsa(*spec.isa);
      isa = *spec.isa;
    }
    bvhNodeWidth(isa);
  } catch (const IsaError& error) {
    throw JobError(JobFailure::BadInput, error.what());
  }
  const fs::path out = spec.output.empty() ? defaultOutputPath(spec.scene) : spec.output;
  checkOutputPath(out, fromFile ? spec.scene : fs::path(), spec.resume);
  const std::optional<fs::path> checkpointPath =
      resolveCheckpointPath(spec.checkpoint, spec.resume, out);
  // Temporary files of glint processes that were killed while writing (core/atomic_file.h).
  removeStaleTemporaryFiles(folderOf(out));
  if (checkpointPath && folderOf(*checkpointPath) != folderOf(out))
    removeStaleTemporaryFiles(folderOf(*checkpointPath));

  RenderJobResult result;
  result.output = out;
  result.crop = spec.crop;
  const auto interrupted = [&result, &spec]() -> RenderJobResult {
    result.outcome = RenderJobResult::Outcome::Interrupted;
    result.signal = spec.cancelSignal != nullptr ? spec.cancelSignal->load() : 0;
    return std::move(result);
  };
  const std::string sceneName = spec.scene.empty() ? std::string("scene") : spec.scene.string();

  // Load: the overrides apply first, so that everything is estimated for the image asked for.
  auto phase = Clock::now();
  SceneParts parts;
  std::vector<Diagnostic> warnings;
  try {
    if (fromFile) {
      LoadedScene loaded =
          loadSceneFile(spec.scene, LoadOptions{spec.memoryBudget, spec.overrides, spec.cancel});
      parts = std::move(loaded.parts);
      warnings = std::move(loaded.warnings);
    } else {
      parts = std::move(*spec.sceneParts);
      applyOverrides(parts, spec.overrides);
    }
  } catch (const Cancelled&) {
    return interrupted();
  }
  checkOutputIsNotRead(out, parts.includedFiles);
  checkOutputIsNotRead(out, parts.readFiles);
  if (std::optional<Diagnostic> warning = pixelWorkWarning(sceneName, parts))
    warnings.push_back(std::move(*warning));
  if (events.sceneWarnings && !warnings.empty()) events.sceneWarnings(warnings);
  ImageSettings allocated = parts.image;
  if (const std::optional<PixelRegion>& crop = spec.crop) {
    const int width = parts.image.width;
    const int height = parts.image.height;
    if (!(0 <= crop->x0 && crop->x0 < crop->x1 && crop->x1 <= width && 0 <= crop->y0 &&
          crop->y0 < crop->y1 && crop->y1 <= height))
      throw JobError(
          JobFailure::BadInput,
          fmt::format("--crop {},{},{},{} does not fit the {}x{} image: it needs "
                      "0 <= X0 < X1 <= {} and 0 <= Y0 < Y1 <= {}",
                      crop->x0, crop->y0, crop->x1, crop->y1, width, height, width, height));
    // The film covers only the crop, so a huge image can still be rendered piece by piece.
    allocated.width = crop->width();
    allocated.height = crop->height();
  }
  const int filmCopies = 1 + (checkpointPath ? 1 : 0) + (spec.resume ? 1 : 0);
  enforceImageLimits(allocated, spec.requestText, spec.memoryBudget, filmCopies);
  result.timings.load = secondsSince(phase);
  if (isCancelled(spec.cancel)) return interrupted();

  phase = Clock::now();
  parts.isa = isa;
  const Scene scene = freezeScene(std::move(parts), sceneName);
  result.timings.build = secondsSince(phase);
  result.scene = sceneFacts(scene);
  if (isCancelled(spec.cancel)) return interrupted();

  RenderOptions options;
  options.threads = spec.threads;
  options.crop = spec.crop;
  options.tileSize = spec.tileSize;
  options.cancel = spec.cancel;
  const PixelRegion region =
      spec.crop.value_or(PixelRegion{0, 0, scene.image().width, scene.image().height});
  const std::vector<PixelRegion> tiles = tileRegions(region, options.tileSize);
  result.tilesTotal = tiles.size();
  if (events.sceneBuilt) events.sceneBuilt(result.scene, region);

  // Checkpointing: the fingerprint of this render, the checkpoint it continues, the collector.
  std::optional<Checkpoint> resumed;
  std::optional<CheckpointCollector> collector;
  if (checkpointPath) {
    const CheckpointSettings settings = checkpointSettingsFor(scene, region, options.tileSize);
    const std::uint64_t fingerprint =
        renderFingerprint(fingerprintedSceneText(spec.scene, scene), scene, settings);
    if (spec.resume) {
      try {
        resumed = readCheckpoint(*spec.resume, spec.memoryBudget);
      } catch (const CheckpointError& error) {
        throw JobError(JobFailure::BadInput, fmt::format("cannot resume: {}", error.what()));
      }
      if (const std::optional<std::string> mismatch =
              checkpointMismatch(*resumed, fingerprint, settings))
        throw JobError(JobFailure::BadInput,
                       fmt::format("cannot resume from '{}': {}; render with the same scene and "
                                   "options, or delete it to start over",
                                   spec.resume->string(), *mismatch));
      options.resumeFilm = &resumed->film;
      options.resumeTiles = &resumed->tiles;
      result.resumedFrom = *spec.resume;
    }
    collector.emplace(*checkpointPath, resumed ? *resumed : emptyCheckpoint(fingerprint, settings),
                      spec.checkpointInterval);
  }
  if (isCancelled(spec.cancel)) return interrupted();

  // Stopped after rendering began: the finished tiles go to the checkpoint.
  const auto interruptedAfterRendering = [&]() -> RenderJobResult {
    if (collector) {
      const Committing committing(events);
      try {
        collector->save();
        result.checkpointSavedTo = *checkpointPath;
        result.tilesSaved = collector->checkpoint().finishedTiles();
      } catch (const CheckpointError& error) {
        result.checkpointSaveError = error.what();
      }
    }
    return interrupted();
  };

  std::size_t tilesDone = resumed ? resumed->finishedTiles() : 0;
  if (events.progress) options.progress = events.progress;
  bool saveFailed = false;  // report once, not at every periodic save
  if (collector || events.tileFinished) {
    options.tileFinished = [&](std::size_t tile, const Film& film, int rank) {
      ++tilesDone;
      if (events.tileFinished) {
        events.tileFinished(FinishedTile{tile, tiles[tile], film, tilesDone, tiles.size(),
                                         rank < 0 ? std::nullopt : std::optional<int>(rank)});
      }
      if (!collector) return;
      collector->addTile(tile, film);
      // After a stop request the checkpoint is saved once, when the render has returned.
      if (!collector->saveDue() || isCancelled(spec.cancel)) return;
      const Committing committing(events);
      try {
        collector->save();
      } catch (const CheckpointError& error) {
        if (!saveFailed && events.checkpointSaveFailed) events.checkpointSaveFailed(error.what());
        saveFailed = true;
      }
    };
  }
  if (events.renderStarting) events.renderStarting(tilesDone, tiles.size());
  // The tiles a resumed checkpoint holds are final already: a preview shows them now, not with the
  // finished image (a resume late in a long render would show almost nothing until the end).
  if (resumed && events.tileFinished) {
    for (std::size_t tile = 0; tile < tiles.size(); ++tile) {
      if (!resumed->tiles[tile]) continue;
      events.tileFinished(
          FinishedTile{tile, tiles[tile], resumed->film, tilesDone, tiles.size(), std::nullopt});
    }
  }
  Film film(scene.image().width, scene.image().height, region);
  if (!spec.renderStep) {
    renderInto(scene, options, film, &result.stats);
  } else {
    try {
      spec.renderStep(scene, options, film, result.stats);
    } catch (const JobError& error) {
      // A failure keeps what was finished (a --resume renders only the rest); a refusal comes
      // before any tile.
      if (!collector || error.failure() == JobFailure::BadInput) throw;
      std::string message = error.what();
      try {
        const Committing committing(events);
        collector->save();
        message += fmt::format("; {} of {} tiles are saved in '{}' (continue with --resume {})",
                               collector->checkpoint().finishedTiles(), tiles.size(),
                               checkpointPath->string(), checkpointPath->string());
      } catch (const CheckpointError& saveError) {
        message += fmt::format("; the checkpoint could not be saved: {}", saveError.what());
      }
      throw JobError(error.failure(), message);
    }
  }
  result.timings.render = result.stats.seconds;
  result.tilesResumed = result.stats.tilesResumed;
  for (std::size_t i = 0; i < tiles.size(); ++i)
    if (!resumed || !resumed->tiles[i])
      result.pixelsRendered += static_cast<std::uint64_t>(tiles[i].width()) *
                               static_cast<std::uint64_t>(tiles[i].height());
  if (events.renderEnded) events.renderEnded();
  // A stop that came after the last tile still means "stop": nothing is written.
  if (result.stats.cancelled || isCancelled(spec.cancel)) return interruptedAfterRendering();

  // The image is complete; the writer commits it atomically (temporary file, rename), polling the
  // cancel flag between rows.
  if (events.imageFinished) events.imageFinished(film);
  {
    const Committing committing(events);
    phase = Clock::now();
    try {
      writeImage(film, out, scene.image().encoding, WriteControl{spec.cancel, {}});
    } catch (const Cancelled&) {
      return interruptedAfterRendering();
    } catch (const ImageWriteError& error) {
      // Keep the finished render: a --resume after fixing the output only writes the image.
      JobError failure(JobFailure::Failure, error.what());
      if (collector) {
        try {
          collector->save();
          failure.withSavedCheckpoint(*checkpointPath);
        } catch (const CheckpointError&) {
          // Report the write failure itself.
        }
      }
      throw failure;
    }
    result.timings.write = secondsSince(phase);
    // The image is complete, so its checkpoint has served its purpose.
    if (checkpointPath) {
      std::error_code error;
      fs::remove(*checkpointPath, error);
      if (error) result.checkpointRemovalError = error.message();
    }
  }
  return result;
}

}  // namespace glint
