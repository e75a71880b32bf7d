#include "glint/cli/cli_app.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <oneapi/tbb/info.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "glint/cli/console.h"
#include "glint/cli/preview_session.h"
#include "glint/cli/progress_reporter.h"
#include "glint/cli/signal_guard.h"
#include "glint/core/isa.h"
#include "glint/job/job_error.h"
#include "glint/job/output_paths.h"
#include "glint/job/render_job.h"
#include "glint/job/scene_check.h"
#include "glint/job/scene_convert.h"
#include "glint/preview/preview_server.h"
#include "glint/preview/preview_state.h"
#include "glint/readers/diagnostics.h"
#include "glint/readers/spelling.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#ifdef GLINT_MPI
#include "glint/cli/cluster_summary.h"
#include "glint/cluster/cluster_render.h"
#include "glint/cluster/launch.h"
#endif

namespace glint::cli {
namespace {

// An error already worded for the user; `exitCode` is what the process returns. An empty message
// means the details were printed already (scene diagnostics).
class CliError : public std::runtime_error {
 public:
  CliError(int exitCode, const std::string& message)
      : std::runtime_error(message), exitCode_(exitCode) {}
  int exitCode() const { return exitCode_; }

 private:
  int exitCode_;
};

void printError(std::string_view message) {
  emit(stderr, fmt::format("glint: error: {}\n", message));
}

// The render command's arguments as typed. Numbers stay text until parseRequest, so every bad value
// gets the same kind of message, and "-1" cannot wrap around to 2^64 - 1 on its way to a seed.
struct RenderArgs {
  std::string scene;
  std::string output;
  std::optional<std::string> width, height, samples, threads, seed, crop, maxMemory, integrator;
  std::optional<std::string> checkpoint, resume;  // checkpoint files
  std::optional<std::string> isa;                 // --isa: baseline, avx2, avx512 or auto
  bool quiet = false;
  bool stats = false;
  std::optional<PreviewRequest> preview;  // --preview and its options
};

// --- argument checks ------------------------------------------------------------------------

// More worker threads than this is a typo, not a machine.
constexpr std::int64_t kMaxThreads = 4096;

// A whole number in [min, max] (decimal, optional leading '-'), or exit 2 naming the option.
std::int64_t parseWholeNumber(std::string_view option, const std::string& text, std::int64_t min,
                              std::int64_t max) {
  std::int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc{} || stop != end || value < min || value > max)
    throw CliError(kExitBadInput, fmt::format("{} expects a whole number from {} to {}, got '{}'",
                                              option, min, max, text));
  return value;
}

// A whole number 0 .. 2^64 - 1.
std::uint64_t parseSeed(const std::string& text) {
  std::uint64_t seed = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, seed);
  if (text.empty() || error != std::errc{} || stop != end)
    throw CliError(kExitBadInput,
                   fmt::format("--seed expects a whole number from 0 to {}, got '{}'",
                               std::numeric_limits<std::uint64_t>::max(), text));
  return seed;
}

// "X0,Y0,X1,Y1" in whole pixels; the range is checked against the image later.
PixelRegion parseCrop(const std::string& text) {
  std::vector<int> values;
  std::string_view rest = text;
  bool ok = true;
  while (ok) {
    const std::size_t comma = rest.find(',');
    std::string_view field = rest.substr(0, comma);
    while (!field.empty() && field.front() == ' ') field.remove_prefix(1);
    while (!field.empty() && field.back() == ' ') field.remove_suffix(1);
    int value = 0;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
    ok = !field.empty() && error == std::errc{} && end == field.data() + field.size();
    values.push_back(value);
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  if (!ok || values.size() != 4)
    throw CliError(
        kExitBadInput,
        fmt::format("--crop expects X0,Y0,X1,Y1 (four whole pixel numbers), got '{}'", text));
  return {values[0], values[1], values[2], values[3]};
}

// "512M", "4G", "1.5GiB", "100000": bytes, with an optional binary unit K, M, G or T (powers of
// 1024; "KB", "KiB" and "k" mean the same), fractions allowed with a unit (a fraction of a byte is
// a unit left out: an error); at least 1 byte.
std::uint64_t parseMemorySize(const std::string& text) {
  const auto bad = [&text]() {
    return CliError(kExitBadInput,
                    fmt::format("--max-memory expects a size such as 512M, 4G, 1.5GiB or a number "
                                "of bytes, got '{}'",
                                text));
  };
  std::string_view rest = text;
  while (!rest.empty() && rest.back() == ' ') rest.remove_suffix(1);
  std::size_t digits = 0;
  while (digits < rest.size() &&
         (std::isdigit(static_cast<unsigned char>(rest[digits])) != 0 || rest[digits] == '.'))
    ++digits;
  if (digits == 0) throw bad();
  double number = 0;
  const auto [stop, error] = std::from_chars(rest.data(), rest.data() + digits, number);
  if (error != std::errc{} || stop != rest.data() + digits) throw bad();
  std::string unit;
  for (const char c : rest.substr(digits))
    unit.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
  if (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
  double scale = 1;
  if (!unit.empty() && unit != "B") {
    const std::string_view units = "KMGT";
    const std::size_t power = units.find(unit.front());
    const std::string_view suffix = std::string_view(unit).substr(1);
    if (power == std::string_view::npos || !(suffix.empty() || suffix == "B" || suffix == "IB"))
      throw bad();
    scale = std::pow(1024.0, static_cast<double>(power + 1));
  } else if (number != std::floor(number)) {
    // "2.5" is no number of bytes; most likely a unit was left out.
    throw CliError(kExitBadInput,
                   fmt::format("--max-memory {}: a number of bytes must be whole (a size with a "
                               "unit may have a fraction: {}G, {}M)",
                               text, rest.substr(0, digits), rest.substr(0, digits)));
  }
  const double bytes = std::floor(number * scale);
  // 2^64 is exactly representable; anything from it up does not fit.
  if (!(bytes >= 1) || bytes >= 18446744073709551616.0)
    throw CliError(kExitBadInput,
                   fmt::format("--max-memory must be from 1 byte to 16 EiB, got '{}'", text));
  return static_cast<std::uint64_t>(bytes);
}

// --- printing ------------------------------------------------------------------------------

// Prints every diagnostic as "FILE:LINE:COL: message" (gcc style, so editors can jump to it).
void printDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  for (const Diagnostic& diagnostic : diagnostics) emit(stderr, diagnostic.format() + "\n");
}

// Warnings shown before the rest are only counted: a file of 400,000 collinear NFF polygons
// printed 400,000 lines (39 MB).
constexpr std::size_t kMaxShownWarnings = 100;

// The first kMaxShownWarnings of `warnings` (in the loader's order: by place), then how many more.
void printWarnings(const std::vector<Diagnostic>& warnings) {
  const std::size_t shown = std::min(warnings.size(), kMaxShownWarnings);
  for (std::size_t i = 0; i < shown; ++i) emit(stderr, warnings[i].format() + "\n");
  if (warnings.size() > shown) {
    const std::size_t more = warnings.size() - shown;
    emit(stderr, fmt::format("glint: {} more warning{} not shown\n", more, more == 1 ? "" : "s"));
  }
}

std::string formatPoint(const Point3& p) {
  return fmt::format("[{:g}, {:g}, {:g}]", p.x, p.y, p.z);
}

std::string boundsText(const SceneFacts& scene) {
  if (scene.bounds.isEmpty()) return "none (no bounded objects)";
  return fmt::format("{} to {}", formatPoint(scene.bounds.lo), formatPoint(scene.bounds.hi));
}

std::string_view integratorName(Integrator integrator) {
  return integrator == Integrator::Path ? "path" : "whitted";
}

// "3 (1 area) + ambient": the light sources, how many of them are area lights (soft shadows), and
// whether the scene has ambient light.
std::string lightsText(const SceneFacts& scene) {
  return fmt::format(
      "{}{}{}", scene.lights,
      scene.areaLights > 0 ? fmt::format(" ({} area)", scene.areaLights) : std::string(),
      scene.ambient ? " + ambient" : "");
}

// "4 samples per pixel", or with adaptive sampling "4 to 64 samples per pixel (adaptive,
// threshold 0.05)": the samples every pixel takes (at least 4 when adaptive) to the most any may.
std::string samplesText(const SceneFacts& scene) {
  const ImageSettings& image = scene.image;
  if (!image.adaptive)
    return fmt::format("{} {} per pixel", image.samples, image.samples == 1 ? "sample" : "samples");
  return fmt::format("{} to {} samples per pixel (adaptive, threshold {:g})",
                     scene.samplesPerPixel.minimum, scene.samplesPerPixel.maximum,
                     image.adaptive->threshold);
}

const char* plural(std::uint64_t n, const char* one, const char* many) {
  return n == 1 ? one : many;
}

std::string regionText(const SceneFacts& scene, const std::optional<PixelRegion>& crop) {
  std::string text = fmt::format("{}x{}", scene.image.width, scene.image.height);
  if (crop)
    text += fmt::format(", crop {},{},{},{} ({}x{})", crop->x0, crop->y0, crop->x1, crop->y1,
                        crop->width(), crop->height());
  return text;
}

// What the render wrote, how long it took and what it traced (printed, and shown by the preview).
std::string summaryText(const RenderJobResult& result) {
  const SceneFacts& scene = result.scene;
  const RenderStats& stats = result.stats;
  const RayCounts& rays = stats.rays;
  const std::string rate =
      stats.seconds > 0
          ? fmt::format("{:.2f} Mrays/s", static_cast<double>(rays.total()) / stats.seconds / 1e6)
          : std::string("- Mrays/s");
  // The path integrator's diffuse and glossy bounces are a kind of their own.
  const std::string indirect =
      rays.indirect > 0 ? fmt::format(", {} indirect", rays.indirect) : std::string();
  std::string text = fmt::format(
      "glint: wrote {} ({}) in {}; rays: {} camera, {} shadow, {} reflection, "
      "{} refraction{}; {}\n",
      result.output.string(), regionText(scene, result.crop), formatDuration(stats.seconds),
      rays.camera, rays.shadow, rays.reflection, rays.refraction, indirect, rate);
  // Adaptive sampling spends a varying number of samples per pixel.
  if (scene.image.adaptive && result.pixelsRendered > 0)
    text +=
        fmt::format("glint: samples: {} ({:.2f} per pixel on average, {} to {})\n", stats.samples,
                    static_cast<double>(stats.samples) / static_cast<double>(result.pixelsRendered),
                    scene.samplesPerPixel.minimum, scene.samplesPerPixel.maximum);
  if (stats.nonFinite > 0) {
    text += fmt::format("glint: {} NaN/inf {} replaced by black", stats.nonFinite,
                        stats.nonFinite == 1 ? "sample" : "samples");
    if (stats.firstNonFinite)
      text += fmt::format(", first at pixel ({}, {})", stats.firstNonFinite->x,
                          stats.firstNonFinite->y);
    text += "\n";
  }
  if (stats.tilesResumed > 0)
    text += fmt::format(
        "glint: {} of {} tiles resumed from '{}'; the time and counts above cover the {} tiles "
        "rendered now\n",
        stats.tilesResumed, result.tilesTotal,
        result.resumedFrom ? result.resumedFrom->string() : std::string(),
        result.tilesTotal - stats.tilesResumed);
  return text;
}

void printStats(const RenderJobResult& result, int threads) {
  const SceneFacts& scene = result.scene;
  const RenderStats& stats = result.stats;
  const RenderJobTimings& timings = result.timings;
  const auto pixels = static_cast<double>(std::max<std::uint64_t>(result.pixelsRendered, 1));
  std::string text;
  text += fmt::format(
      "glint: scene: {} primitives ({} in the BVH, {} unbounded), {} meshes ({} triangles), {} "
      "materials, lights: {}\n",
      scene.objects, scene.objects - scene.unboundedObjects, scene.unboundedObjects, scene.meshes,
      scene.triangles, scene.materials, lightsText(scene));
  if (scene.instances > 0) {
    text += fmt::format("glint: instances: {} of {} groups ({} triangles in the groups)\n",
                        scene.instances, scene.groups, scene.groupTriangles);
  }
  text += fmt::format("glint: bounds: {}\n", boundsText(scene));
  text += fmt::format("glint: image: {}, {}, {} {}, {} integrator, max depth {}, seed {}\n",
                      regionText(scene, result.crop), samplesText(scene), threads,
                      plural(static_cast<std::uint64_t>(threads), "thread", "threads"),
                      integratorName(scene.integrator), scene.maxDepth, scene.seed);
  text += fmt::format("glint: rays: {} total, {:.1f} per pixel\n", stats.rays.total(),
                      static_cast<double>(stats.rays.total()) / pixels);
  text += fmt::format("glint: samples: {} total, {:.2f} per pixel\n", stats.samples,
                      static_cast<double>(stats.samples) / pixels);
  text += fmt::format("glint: time: load {}, build {}, render {}, write {}\n",
                      formatDuration(timings.load), formatDuration(timings.build),
                      formatDuration(timings.render), formatDuration(timings.write));
  text += fmt::format("glint: non-finite samples: {}\n", stats.nonFinite);
  text += fmt::format("glint: isa: {} (BVH queries; this processor runs up to {})\n",
                      isaName(scene.isa), isaName(bestIsa(isaSupportHere())));
  emit(stderr, text);
}

// Prints why the job failed: the scene's errors at their places, or one message.
int reportJobError(const JobError& error, const std::string& sceneFile) {
  if (!error.diagnostics().empty()) {
    printDiagnostics(error.diagnostics());
    if (error.unreported() > 0)
      emit(stderr, fmt::format("{}: {} more error{} not shown\n", sceneFile, error.unreported(),
                               error.unreported() == 1 ? "" : "s"));
    return error.exitCode();
  }
  printError(error.what());
  if (!error.savedCheckpoint().empty())
    emit(stderr, fmt::format("glint: the finished render is saved in '{}' (write the image "
                             "with --resume {})\n",
                             error.savedCheckpoint().string(), error.savedCheckpoint().string()));
  return error.exitCode();
}

// --- commands -------------------------------------------------------------------------------

RenderJobSpec parseRequest(const RenderArgs& args);

// `args`: the scene, --max-memory and the scene overrides render takes (the rest empty).
int runCheck(const RenderArgs& args) {
  const std::string& file = args.scene;
  const RenderJobSpec request = parseRequest(args);
  CheckOptions options;
  options.warnings = printWarnings;
  options.memoryBudget = request.memoryBudget;
  options.overrides = request.overrides;
  options.requestText = request.requestText;
  SceneFacts scene;
  try {
    scene = checkScene(file, options);
  } catch (const JobError& error) {
    return reportJobError(error, file);
  }
  std::string text;
  text += fmt::format("scene:     {}\n", scene.name.empty() ? "(unnamed)" : scene.name);
  text += fmt::format("file:      {}\n", file);
  text +=
      fmt::format("image:     {}x{}, {}, {} encoding\n", scene.image.width, scene.image.height,
                  samplesText(scene), scene.image.encoding == Encoding::Srgb ? "srgb" : "linear");
  text += fmt::format("shapes:    {} ({} bounded, {} unbounded)\n", scene.objects,
                      scene.objects - scene.unboundedObjects, scene.unboundedObjects);
  text += fmt::format("meshes:    {} ({} triangles)\n", scene.meshes, scene.triangles);
  if (scene.instances > 0) {
    text += fmt::format("instances: {} of {} groups ({} triangles in the groups)\n",
                        scene.instances, scene.groups, scene.groupTriangles);
  }
  text += fmt::format("lights:    {}\n", lightsText(scene));
  text += fmt::format("materials: {}\n", scene.materials);
  text += fmt::format("bounds:    {}\n", boundsText(scene));
  emit(stdout, text);
  return kExitSuccess;
}

int runConvert(const std::string& file, const std::string& output, SignalGuard& signals) {
  ConvertResult result;
  try {
    ConvertSpec spec{file, output, &signals.cancelFlag(), {}};
    spec.committing = [&signals](bool committing) { signals.setCommitting(committing); };
    result = convertScene(spec);
  } catch (const JobError& error) {
    return reportJobError(error, file);
  }
  if (result.interrupted) {
    emit(stderr, "glint: interrupted; nothing was written\n");
    return SignalGuard::exitCodeFor(signals.receivedSignal() != 0 ? signals.receivedSignal()
                                                                  : SIGINT);
  }
  printWarnings(result.warnings);
  std::string files;
  for (const auto& mesh : result.meshFiles) files += ", " + mesh.string();
  emit(stdout,
       fmt::format("wrote {} ({} objects, {} lights){}\n", result.output.string(), result.objects,
                   result.lights, files.empty() ? "" : " and its meshes " + files.substr(2)));
  return kExitSuccess;
}

// The render command's arguments as a job: every value checked as far as possible without the
// scene. `--seed` is not named in refusals: it changes no size.
RenderJobSpec parseRequest(const RenderArgs& args) {
  RenderJobSpec spec;
  spec.scene = args.scene;
  spec.output = args.output;
  std::vector<std::string> named;
  if (args.width) {
    spec.overrides.width =
        static_cast<int>(parseWholeNumber("--width", *args.width, 1, kMaxImageSide));
    named.push_back("--width " + *args.width);
  }
  if (args.height) {
    spec.overrides.height =
        static_cast<int>(parseWholeNumber("--height", *args.height, 1, kMaxImageSide));
    named.push_back("--height " + *args.height);
  }
  if (args.samples) {
    spec.overrides.samples =
        static_cast<int>(parseWholeNumber("--samples", *args.samples, 1, kMaxSamplesPerPixel));
    named.push_back("--samples " + *args.samples);
  }
  if (args.seed) spec.overrides.seed = parseSeed(*args.seed);
  if (args.integrator) {
    if (*args.integrator == "whitted") {
      spec.overrides.integrator = Integrator::Whitted;
    } else if (*args.integrator == "path") {
      spec.overrides.integrator = Integrator::Path;
    } else {
      throw CliError(kExitBadInput, fmt::format("--integrator expects whitted or path, got '{}'",
                                                *args.integrator));
    }
  }
  if (args.threads)
    spec.threads = static_cast<int>(parseWholeNumber("--threads", *args.threads, 1, kMaxThreads));
  if (args.crop) spec.crop = parseCrop(*args.crop);
  if (args.maxMemory) {
    spec.memoryBudget = parseMemorySize(*args.maxMemory);
    named.push_back("--max-memory " + *args.maxMemory);
  }
  spec.requestText = fmt::format("{}", fmt::join(named, " "));
  if (args.checkpoint) spec.checkpoint = std::filesystem::path(*args.checkpoint);
  if (args.resume) spec.resume = std::filesystem::path(*args.resume);
  if (args.isa) {
    try {
      spec.isa = resolveIsa(*args.isa, "--isa", isaSupportHere());
    } catch (const IsaError& error) {
      throw CliError(kExitBadInput, error.what());
    }
  }
  return spec;
}

int reportInterrupted(const RenderJobResult& result) {
  if (result.checkpointSavedTo) {
    const std::string path = result.checkpointSavedTo->string();
    emit(stderr, fmt::format("glint: interrupted; {} of {} tiles saved to '{}' (continue with "
                             "--resume {})\n",
                             result.tilesSaved, result.tilesTotal, path, path));
  } else if (!result.checkpointSaveError.empty()) {
    emit(stderr, fmt::format("glint: interrupted; {}\n", result.checkpointSaveError));
  } else {
    emit(stderr, "glint: interrupted\n");
  }
  return SignalGuard::exitCodeFor(result.signal != 0 ? result.signal : SIGINT);
}

// Runs the job and prints its outcome; `moreStats` adds to --stats.
int renderAndReport(RenderJobSpec spec, const RenderArgs& args, SignalGuard& signals,
                    const std::function<std::string()>& moreStats) {
  const int threads = spec.threads > 0 ? spec.threads : tbb::info::default_concurrency();

  ProgressReporter progress(
      args.quiet ? ProgressReporter::Style::Silent : ProgressReporter::styleFor(stderr), stderr);
  RenderJobEvents events;
  if (!args.quiet) events.sceneWarnings = printWarnings;
  events.renderStarting = [&progress](std::size_t resumed, std::size_t) {
    progress.start(resumed);
  };
  events.progress = [&progress](std::size_t done, std::size_t total) {
    progress.update(done, total);
  };
  events.renderEnded = [&progress]() { progress.finish(); };
  events.checkpointSaveFailed = [](const std::string& reason) {
    emit(stderr, fmt::format("\nglint: warning: {}; the render goes on\n", reason));
  };
  // A second signal must not end the process with a temporary file left behind.
  events.committing = [&signals](bool committing) { signals.setCommitting(committing); };
  std::optional<PreviewSession> preview;
  if (args.preview) {
    // An output path the job would refuse is said before the preview's address (no page for a
    // render that never starts).
    try {
      checkOutputPath(spec.output.empty() ? defaultOutputPath(spec.scene) : spec.output,
                      spec.sceneParts ? std::filesystem::path() : spec.scene, spec.resume);
    } catch (const JobError& error) {
      return reportJobError(error, args.scene);
    }
    try {
      preview.emplace(*args.preview, args.scene, stderr);
    } catch (const PreviewError& error) {
      throw CliError(kExitBadInput, error.what());
    }
    preview->attach(events);
  }

  RenderJobResult result;
  try {
    result = runRenderJob(std::move(spec), events);
  } catch (const JobError& error) {
    const int status = reportJobError(error, args.scene);
    if (preview)
      preview->end(PreviewPhase::Failed,
                   *error.what() ? error.what() : "the scene has errors (see the terminal)",
                   signals.cancelFlag(), error.failure() == JobFailure::BadInput);
    return status;
  }
  if (result.outcome == RenderJobResult::Outcome::Interrupted) {
    const int status = reportInterrupted(result);
    if (preview) preview->end(PreviewPhase::Interrupted, "interrupted", signals.cancelFlag());
    return status;
  }
  if (!result.checkpointRemovalError.empty() && !args.quiet)
    emit(stderr, fmt::format("glint: warning: cannot remove the checkpoint '{}': {}\n",
                             args.checkpoint ? *args.checkpoint : *args.resume,
                             result.checkpointRemovalError));
  const std::string summary = summaryText(result);
  if (!args.quiet) {
    emit(stderr, summary);
    if (args.stats) printStats(result, threads);
    if (args.stats && moreStats) emit(stderr, moreStats());
  }
  if (preview) preview->end(PreviewPhase::Finished, summary, signals.cancelFlag());
  return kExitSuccess;
}

int runRender(const RenderArgs& args, SignalGuard& signals) {
  RenderJobSpec spec = parseRequest(args);
  spec.cancel = &signals.cancelFlag();
  spec.cancelSignal = &signals.signalNumber();
#ifdef GLINT_MPI
  // Under mpirun or srun: one frame over every rank (docs/distributed.md); rank 0 reports.
  if (cluster::launchedByMpi()) {
    if (spec.threads == 0) spec.threads = cluster::defaultThreadsPerRank();
    std::optional<cluster::ClusterRender> started;
    try {
      started.emplace();
    } catch (const std::invalid_argument& error) {
      throw CliError(kExitBadInput, error.what());  // a bad GLINT_MPI_TIMEOUT, as a bad GLINT_ISA
    }
    cluster::ClusterRender& ranks = *started;
    if (!ranks.coordinates()) return ranks.serve(spec);
    ranks.distribute(spec);
    const int status = renderAndReport(std::move(spec), args, signals,
                                       [&ranks] { return clusterStatsText(ranks.figures()); });
    return ranks.finish(status);
  }
#endif
  return renderAndReport(std::move(spec), args, signals, {});
}

// The arguments the parser could not place, in the order given ("--" left out).
std::vector<std::string> unplacedArguments(const CLI::App& app) {
  std::vector<std::string> words;
  for (std::string& word : app.remaining(true)) {
    if (word != "--") words.push_back(std::move(word));
  }
  return words;
}

// The long options of `command` ("--width", ...), for did-you-mean hints.
std::vector<std::string> longOptions(const CLI::App& command) {
  std::vector<std::string> names;
  for (const CLI::Option* option : command.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  }
  return names;
}

// Argument-parser errors: CLI11's own message, minus its jargon, plus where to find help.
int parseFailure(const CLI::ParseError& error, const CLI::App& app, int argc, char** argv) {
  const std::string_view message = error.what();
  const std::size_t colon = message.find(": ");
  const std::vector<std::string> unplaced = unplacedArguments(app);
  // An option is a word of '-' or '--' and a letter given before any "--" (after it every word
  // is an argument); "-1" is a number.
  char** const separator = std::find_if(
      argv, argv + argc, [](const char* word) { return std::string_view(word) == "--"; });
  const auto isOption = [&](const std::string& word) {
    const std::size_t dashes = word.starts_with("--") ? 2 : word.starts_with("-") ? 1 : 0;
    return dashes > 0 && word.size() > dashes &&
           std::isalpha(static_cast<unsigned char>(word[dashes])) != 0 &&
           std::any_of(argv, separator, [&](const char* given) { return word == given; });
  };
  const auto firstOption = std::find_if(unplaced.begin(), unplaced.end(), isOption);
  // The command being parsed (render, check, convert), when one was named.
  const std::vector<CLI::App*> commands = app.get_subcommands();
  const CLI::App* command = commands.empty() ? nullptr : commands.front();
  // "--widht=100" is matched as "--widht".
  const std::string optionHint =
      command != nullptr && firstOption != unplaced.end()
          ? didYouMean(std::string_view(*firstOption).substr(0, firstOption->find('=')),
                       longOptions(*command))
          : std::string();
  if (message == "A subcommand is required") {
    if (argc >= 2 && argv[1][0] == '-') {
      printError(
          fmt::format("unknown option '{}': options go after the command, as in glint "
                      "render SCENE --width 800",
                      argv[1]));
    } else {
      printError(
          "a command is required: glint render SCENE, glint check SCENE or glint convert "
          "SCENE");
    }
  } else if (dynamic_cast<const CLI::RequiredError*>(&error) && firstOption != unplaced.end()) {
    // "glint render -scene.yaml": the name was taken for an option, so SCENE is "missing".
    printError(optionHint.empty()
                   ? fmt::format("unknown option '{}' (a file whose name starts with '-' is "
                                 "written ./{})",
                                 *firstOption, *firstOption)
                   : fmt::format("unknown option '{}'{}", *firstOption, optionHint));
  } else if (dynamic_cast<const CLI::ExtrasError*>(&error) && firstOption != unplaced.end()) {
    // "--widht 100": the value is not expected because its option is unknown.
    printError(fmt::format("unknown option '{}'{}", *firstOption, optionHint));
  } else if (dynamic_cast<const CLI::ExtrasError*>(&error) && !unplaced.empty()) {
    // CLI11 lists them in reverse order.
    printError(fmt::format("not expected: {}", fmt::join(unplaced, " ")));
  } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) &&
             colon != std::string_view::npos && message.ends_with(" missing")) {
    // CLI11 says "--width: 1 required W missing".
    printError(fmt::format("{} needs a value", message.substr(0, colon)));
  } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) &&
             colon != std::string_view::npos &&
             message.find("At Most 1 required but received") != std::string_view::npos) {
    // CLI11 says "--width: At Most 1 required but received 2".
    printError(fmt::format("{} is given more than once; give it once", message.substr(0, colon)));
  } else {
    printError(message);
  }
  emit(stderr, command != nullptr
                   ? fmt::format("Run 'glint {} --help' for usage.\n", command->get_name())
                   : std::string("Run 'glint --help' for usage.\n"));
  return kExitBadInput;
}

// An option taken as text, parsed later by parseRequest; value() is empty when it was not given.
// Stays where it is once added (the parser writes into `text`).
struct TextOption {
  std::string text;
  CLI::Option* option = nullptr;

  void add(CLI::App& command, const std::string& name, const std::string& help,
           const std::string& typeName) {
    option = command.add_option(name, text, help)->type_name(typeName);
  }
  std::optional<std::string> value() const {
    return option != nullptr && option->count() > 0 ? std::optional<std::string>(text)
                                                    : std::nullopt;
  }
};

// The options render and check share: what the scene is loaded and built with.
struct SceneOptions {
  TextOption width, height, samples, seed, integrator, maxMemory;

  void readInto(RenderArgs& args) const {
    args.width = width.value();
    args.height = height.value();
    args.samples = samples.value();
    args.seed = seed.value();
    args.integrator = integrator.value();
    args.maxMemory = maxMemory.value();
  }
};

int runCommandLine(int argc, char** argv) {
  CLI::App app{
      "glint: a ray tracer (Whitted's model, or path tracing). Renders scene files — YAML, NFF, "
      "Tachyon .dat, mesh files — to PNG, PPM or OpenEXR images.",
      "glint"};
  app.set_version_flag("--version", std::string("glint ") + GLINT_VERSION,
                       "Print the version and exit");
  app.require_subcommand(1);

  RenderArgs args;
  CLI::App* render = app.add_subcommand("render", "Render a scene file to an image");
  render->add_option("SCENE", args.scene, "Scene file (YAML, JSON, .nff, .dat, or a mesh file)")
      ->required()
      ->type_name("FILE");
  CLI::Option* outputOption =
      render
          ->add_option("-o,--output", args.output,
                       "Output image: .png (8-bit), .ppm (8-bit) or .exr (linear float); "
                       "default: the scene's name with .png, in the current folder")
          ->type_name("OUT");
  // Valued options are read as text and parsed by parseRequest (uniform messages, no wrap-around).
  SceneOptions renderScene;
  TextOption threads, crop, checkpoint, resume, isa;
  renderScene.width.add(*render, "--width", "Image width in pixels; alone it keeps the aspect",
                        "W");
  renderScene.height.add(*render, "--height", "Image height in pixels; alone it keeps the aspect",
                         "H");
  renderScene.samples.add(*render, "--samples", "Samples per pixel, 1 to 65536", "N");
  threads.add(*render, "--threads", "Worker threads (default: all cores)", "N");
  renderScene.seed.add(*render, "--seed", "Random seed (replaces the scene's render.seed)", "S");
  renderScene.integrator.add(*render, "--integrator",
                             "whitted or path (replaces the scene's render.integrator)", "NAME");
  crop.add(*render, "--crop",
           "Render only pixels X0 <= x < X1, Y0 <= y < Y1; the image is that region",
           "X0,Y0,X1,Y1");
  renderScene.maxMemory.add(
      *render, "--max-memory",
      "Memory the scene may need (film, meshes, BVH, textures), e.g. 512M, 4G, 1.5GiB or bytes; "
      "default: half the physical memory",
      "SIZE");
  checkpoint.add(*render, "--checkpoint",
                 "Save finished tiles to FILE every few seconds and when interrupted; removed "
                 "when the image is written",
                 "FILE");
  resume.add(*render, "--resume",
             "Continue the render saved in FILE (same scene and options), and keep checkpointing "
             "into it unless --checkpoint names another file",
             "FILE");
  isa.add(*render, "--isa",
          "Instruction set of the BVH queries: baseline, avx2, avx512 or auto (the widest this "
          "processor runs; default, or GLINT_ISA); never changes a pixel",
          "ISA");
  render->add_flag("--quiet", args.quiet, "No progress and no summary; errors only");
  render->add_flag("--stats", args.stats, "More statistics at the end");
  const PreviewOptions previewOptions(*render);

  std::string checkFile;
  CLI::App* check =
      app.add_subcommand("check", "Parse and build a scene, print a summary; writes nothing");
  check->add_option("SCENE", checkFile, "Scene file (YAML, JSON, .nff, .dat, or a mesh file)")
      ->required()
      ->type_name("FILE");
  // The memory estimate's refusals and the warnings render's options bring (a path integrator,
  // more samples) are among what check reports as render does.
  SceneOptions checkScene;
  checkScene.maxMemory.add(
      *check, "--max-memory",
      "Memory the scene may need, as for render (default: half the physical memory)", "SIZE");
  checkScene.width.add(*check, "--width", "As for render", "W");
  checkScene.height.add(*check, "--height", "As for render", "H");
  checkScene.samples.add(*check, "--samples", "As for render", "N");
  checkScene.seed.add(*check, "--seed", "As for render", "S");
  checkScene.integrator.add(*check, "--integrator", "As for render", "NAME");

  std::string convertFile, convertOutput;
  CLI::App* convert = app.add_subcommand(
      "convert", "Write any scene glint reads (NFF, Tachyon .dat, a mesh) as a glint YAML scene");
  convert->add_option("SCENE", convertFile, "Scene file (YAML, .nff, .dat, or a mesh file)")
      ->required()
      ->type_name("FILE");
  CLI::Option* convertOutputOption =
      convert
          ->add_option(
              "-o,--output", convertOutput,
              "The YAML scene to write (large meshes go beside it as PLY files); default: the "
              "scene's name with .yaml, in the current folder")
          ->type_name("OUT");

  // Set after the subcommands exist: CLI11 copies a parent's footer into subcommands made later.
  const std::string exitStatus =
      "Exit status: 0 success; 1 failure while rendering or writing; 2 bad arguments, a bad scene, "
      "a request refused as too large or a checkpoint that does not match; 130/143/129 "
      "interrupted by SIGINT/SIGTERM/SIGHUP (no output written; the --checkpoint file saved).";
  app.footer(
      "Examples:\n  glint render scene.yaml -o scene.png --width 800\n"
      "  glint render scene.yaml --crop 0,0,400,300 -o top-left.ppm\n"
      "  glint render model.glb            (a quick look at a mesh)\n"
      "  glint convert balls.nff -o balls.yaml\n"
      "  glint check scene.yaml\n\nRun 'glint render --help' for the render options.\n\n" +
      exitStatus);
  render->footer(exitStatus);
  check->footer(exitStatus);
  convert->footer(exitStatus);

  // CLI11 would call an unknown command a "missing subcommand"; say what happened instead.
  if (argc >= 2 && argv[1][0] != '-' && std::string_view(argv[1]) != "render" &&
      std::string_view(argv[1]) != "check" && std::string_view(argv[1]) != "convert") {
    printError(
        fmt::format("unknown command '{}'; the commands are render, check and convert", argv[1]));
    emit(stderr, "Run 'glint --help' for usage.\n");
    return kExitBadInput;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& success) {
    return app.exit(success);  // --help, --version: printed on stdout, exit 0
  } catch (const CLI::ParseError& error) {
    return parseFailure(error, app, argc, argv);
  }
  // An empty name ("-o $OUT" with OUT unset) is a mistake, not a request for the default name.
  if ((outputOption->count() > 0 && args.output.empty()) ||
      (convertOutputOption->count() > 0 && convertOutput.empty()))
    throw CliError(kExitBadInput, "-o needs a file name");
  renderScene.readInto(args);
  args.threads = threads.value();
  args.crop = crop.value();
  args.checkpoint = checkpoint.value();
  args.resume = resume.value();
  args.isa = isa.value();
  try {
    args.preview = previewOptions.request();
  } catch (const PreviewError& error) {
    throw CliError(kExitBadInput, error.what());
  }

  if (check->parsed()) {
    RenderArgs checkArgs;
    checkArgs.scene = checkFile;
    checkScene.readInto(checkArgs);
    return runCheck(checkArgs);
  }
  SignalGuard signals;
  if (convert->parsed()) return runConvert(convertFile, convertOutput, signals);
  return runRender(args, signals);
}

}  // namespace

int run(int argc, char** argv) {
  try {
    return runCommandLine(argc, argv);
  } catch (const CliError& error) {
    if (*error.what() != '\0') printError(error.what());
    return error.exitCode();
  } catch (const std::bad_alloc&) {
    printError("out of memory");
    return kExitFailure;
  } catch (const std::exception& error) {
    printError(error.what());
    return kExitFailure;
  } catch (...) {
    printError("unexpected failure");
    return kExitFailure;
  }
}

}  // namespace glint::cli
