#include "glint/cli/cli_app.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <oneapi/tbb/info.h>
#include <CLI/CLI.hpp>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <variant>
#include <vector>

#include "glint/cli/progress_reporter.h"
#include "glint/cli/signal_guard.h"
#include "glint/factories/scene_loader.h"
#include "glint/image/image_writer.h"
#include "glint/job/checkpoint.h"
#include "glint/readers/diagnostics.h"
#include "glint/render/renderer.h"
#include "glint/scene/light.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#include "glint/scene/scene_overrides.h"

namespace glint::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

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

// Writes without throwing: a closed or full stderr must not turn a finished render into a failure.
void emit(std::FILE* stream, std::string_view text) {
  std::fwrite(text.data(), 1, text.size(), stream);
  std::fflush(stream);
}

void printError(std::string_view message) {
  emit(stderr, fmt::format("glint: error: {}\n", message));
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The render command's arguments as typed. Numbers stay text until parseRequest, so every bad value
// gets the same kind of message, and "-1" cannot wrap around to 2^64 - 1 on its way to a seed.
struct RenderArgs {
  std::string scene;
  std::string output;
  std::optional<std::string> width, height, samples, threads, seed, crop, maxMemory;
  std::optional<std::string> checkpoint, resume;  // checkpoint files
  bool quiet = false;
  bool stats = false;
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
// 1024; "KB", "KiB" and "k" mean the same), fractions allowed; at least 1 byte.
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
  }
  const double bytes = std::floor(number * scale);
  // 2^64 is exactly representable; anything from it up does not fit.
  if (!(bytes >= 1) || bytes >= 18446744073709551616.0)
    throw CliError(kExitBadInput,
                   fmt::format("--max-memory must be from 1 byte to 16 EiB, got '{}'", text));
  return static_cast<std::uint64_t>(bytes);
}

void checkCrop(const PixelRegion& crop, int width, int height) {
  if (0 <= crop.x0 && crop.x0 < crop.x1 && crop.x1 <= width && 0 <= crop.y0 && crop.y0 < crop.y1 &&
      crop.y1 <= height)
    return;
  throw CliError(kExitBadInput,
                 fmt::format("--crop {},{},{},{} does not fit the {}x{} image: it needs "
                             "0 <= X0 < X1 <= {} and 0 <= Y0 < Y1 <= {}",
                             crop.x0, crop.y0, crop.x1, crop.y1, width, height, width, height));
}

// The output path: given, or the scene file's name with ".png" in the current folder. Checked
// before any work so that a typo does not cost a render.
fs::path resolveOutput(const RenderArgs& args) {
  fs::path out =
      args.output.empty() ? fs::path(args.scene).stem().concat(".png") : fs::path(args.output);
  if (!writerForPath(out)) {
    const std::string extension = out.extension().string();
    throw CliError(kExitBadInput,
                   fmt::format("cannot write '{}': {}; use .png, .ppm or .exr", out.string(),
                               extension.empty() ? std::string("the name has no extension")
                                                 : "unknown image format '" + extension + "'"));
  }
  const fs::path folder = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  std::error_code error;
  if (!fs::is_directory(folder, error))
    throw CliError(kExitBadInput, fmt::format("cannot write '{}': the folder '{}' does not exist",
                                              out.string(), folder.string()));
  // Writing problems (exit 1) that can be seen now rather than after the render.
  if (fs::is_directory(out, error))
    throw CliError(kExitFailure, fmt::format("cannot write '{}': it is a folder", out.string()));
  if (access(folder.c_str(), W_OK | X_OK) != 0)
    throw CliError(kExitFailure, fmt::format("cannot write '{}': the folder '{}' is not writable",
                                             out.string(), folder.string()));
  return out;
}

// --- scene ----------------------------------------------------------------------------------

// Prints every diagnostic as "FILE:LINE:COL: message" (gcc style, so editors can jump to it).
void printDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  for (const Diagnostic& diagnostic : diagnostics) emit(stderr, diagnostic.format() + "\n");
}

LoadedScene load(const std::string& file, bool showWarnings,
                 std::uint64_t memoryBudget = defaultImageMemoryBudget(),
                 const SceneOverrides& overrides = {}) {
  try {
    LoadedScene loaded = loadScene(file, LoadOptions{memoryBudget, overrides});
    if (showWarnings) printDiagnostics(loaded.warnings);
    return loaded;
  } catch (const SceneError& error) {
    if (error.diagnostics().empty()) throw CliError(kExitBadInput, error.what());
    printDiagnostics(error.diagnostics());
    if (error.unreported() > 0)
      emit(stderr, fmt::format("{}: {} more error{} not shown\n", file, error.unreported(),
                               error.unreported() == 1 ? "" : "s"));
    throw CliError(kExitBadInput, "");
  }
}

// The image limits and memory budget (DESIGN.md §7) for the film that will be allocated, checked
// again after the command line changed the image: a request refused as too large is a bad request
// (exit 2), refused before any allocation.
// `request` names the options that changed the image ("--width 70000"), empty for none.
// `filmCopies`: films held at once (checkpointing keeps a copy of the finished tiles, resuming one
// more of the checkpoint).
void enforceImageLimits(const ImageSettings& image, const std::string& request,
                        std::uint64_t memoryBudget = defaultImageMemoryBudget(),
                        int filmCopies = 1) {
  std::optional<std::string> refusal = checkImageSettings(image, memoryBudget);
  const std::uint64_t film = filmBytes(image.width, image.height);
  if (!refusal && filmCopies > 1 && film > memoryBudget / static_cast<std::uint64_t>(filmCopies)) {
    refusal = fmt::format(
        "an image of {} × {} pixels needs {} for its film and {} for checkpointing, more than the "
        "memory budget of {}",
        image.width, image.height, formatBytes(static_cast<double>(film)),
        formatBytes(static_cast<double>(film) * static_cast<double>(filmCopies - 1)),
        formatBytes(static_cast<double>(memoryBudget)));
  }
  if (refusal) {
    throw CliError(kExitBadInput, request.empty()
                                      ? fmt::format("request refused: {}", *refusal)
                                      : fmt::format("{} refused: {}", request, *refusal));
  }
}

// Scene construction (camera frame, BVH). The loader validates everything a file can get wrong,
// so a refusal here is still the scene's fault: exit 2.
Scene build(SceneParts parts, const std::string& file) {
  try {
    return Scene(std::move(parts));
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& error) {
    throw CliError(kExitBadInput, fmt::format("{}: {}", file, error.what()));
  }
}

std::string formatPoint(const Point3& p) {
  return fmt::format("[{:g}, {:g}, {:g}]", p.x, p.y, p.z);
}

std::string formatBounds(const Scene& scene) {
  const Bounds3 bounds = scene.aggregate().bounds();
  if (bounds.isEmpty()) return "none (no bounded objects)";
  return fmt::format("{} to {}", formatPoint(bounds.lo), formatPoint(bounds.hi));
}

std::size_t unboundedCount(const Scene& scene) {
  std::size_t count = 0;
  for (const Primitive& primitive : scene.primitives()) count += primitive.isBounded() ? 0 : 1;
  return count;
}

// Materials the scene defines; index 0 is the built-in default material.
std::size_t materialCount(const Scene& scene) { return scene.materials().size() - 1; }

// "3 (1 area) + ambient": the light sources, how many of them are area lights (soft shadows), and
// whether the scene has ambient light.
std::string lightsText(const Scene& scene) {
  std::size_t area = 0;
  for (const Light& light : scene.lights())
    area += std::holds_alternative<AreaLight>(light) ? 1 : 0;
  return fmt::format("{}{}{}", scene.lights().size(),
                     area > 0 ? fmt::format(" ({} area)", area) : std::string(),
                     isBlack(scene.ambient()) ? "" : " + ambient");
}

// "4 samples per pixel", or with adaptive sampling "4 to 64 samples per pixel (adaptive,
// threshold 0.05)".
std::string samplesText(const ImageSettings& image) {
  if (!image.adaptive)
    return fmt::format("{} {} per pixel", image.samples, image.samples == 1 ? "sample" : "samples");
  return fmt::format("{} to {} samples per pixel (adaptive, threshold {:g})", image.samples,
                     image.adaptive->maxSamples, image.adaptive->threshold);
}

const char* plural(std::uint64_t n, const char* one, const char* many) {
  return n == 1 ? one : many;
}

// --- commands -------------------------------------------------------------------------------

int runCheck(const std::string& file) {
  LoadedScene loaded = load(file, true);
  enforceImageLimits(loaded.parts.image, "");
  const Scene scene = build(std::move(loaded.parts), file);
  const ImageSettings& image = scene.image();
  const std::size_t primitives = scene.primitives().size();
  const std::size_t unbounded = unboundedCount(scene);
  std::string text;
  text += fmt::format("scene:     {}\n", scene.name().empty() ? "(unnamed)" : scene.name());
  text += fmt::format("file:      {}\n", file);
  text += fmt::format("image:     {}x{}, {}, {} encoding\n", image.width, image.height,
                      samplesText(image), image.encoding == Encoding::Srgb ? "srgb" : "linear");
  text += fmt::format("objects:   {} ({} bounded, {} unbounded)\n", primitives,
                      primitives - unbounded, unbounded);
  text += fmt::format("meshes:    {} ({} triangles)\n", scene.meshes().size(),
                      scene.aggregate().triangleCount());
  text += fmt::format("lights:    {}\n", lightsText(scene));
  text += fmt::format("materials: {}\n", materialCount(scene));
  text += fmt::format("bounds:    {}\n", formatBounds(scene));
  emit(stdout, text);
  return kExitSuccess;
}

std::string regionText(const Scene& scene, const std::optional<PixelRegion>& crop) {
  std::string text = fmt::format("{}x{}", scene.image().width, scene.image().height);
  if (crop)
    text += fmt::format(", crop {},{},{},{} ({}x{})", crop->x0, crop->y0, crop->x1, crop->y1,
                        crop->width(), crop->height());
  return text;
}

// What a render did besides the rays: how many pixels it rendered (resumed tiles excluded), from
// which checkpoint it resumed.
struct RenderFacts {
  std::uint64_t pixelsRendered = 0;
  std::size_t tilesTotal = 0;
  std::string resumedFrom;  // the --resume file, empty when not resuming
};

void printSummary(const fs::path& out, const Scene& scene, const std::optional<PixelRegion>& crop,
                  const RenderStats& stats, const RenderFacts& facts) {
  const RayCounts& rays = stats.rays;
  const std::string rate =
      stats.seconds > 0
          ? fmt::format("{:.2f} Mrays/s", static_cast<double>(rays.total()) / stats.seconds / 1e6)
          : std::string("- Mrays/s");
  std::string text = fmt::format(
      "glint: wrote {} ({}) in {}; rays: {} camera, {} shadow, {} reflection, "
      "{} refraction; {}\n",
      out.string(), regionText(scene, crop), formatDuration(stats.seconds), rays.camera,
      rays.shadow, rays.reflection, rays.refraction, rate);
  // Adaptive sampling spends a varying number of samples per pixel; rays.camera counts them.
  if (scene.image().adaptive && facts.pixelsRendered > 0)
    text +=
        fmt::format("glint: samples: {} ({:.2f} per pixel on average, {} to {})\n", rays.camera,
                    static_cast<double>(rays.camera) / static_cast<double>(facts.pixelsRendered),
                    scene.image().samples, scene.image().adaptive->maxSamples);
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
        stats.tilesResumed, facts.tilesTotal, facts.resumedFrom,
        facts.tilesTotal - stats.tilesResumed);
  emit(stderr, text);
}

struct Timings {
  double load = 0, build = 0, write = 0;
};

void printStats(const Scene& scene, const std::optional<PixelRegion>& crop, int threads,
                const RenderStats& stats, const Timings& timings, const RenderFacts& facts) {
  const std::size_t primitives = scene.primitives().size();
  const std::size_t unbounded = unboundedCount(scene);
  const auto pixels = static_cast<double>(std::max<std::uint64_t>(facts.pixelsRendered, 1));
  std::string text;
  text += fmt::format(
      "glint: scene: {} primitives ({} in the BVH, {} unbounded), {} materials, "
      "lights: {}\n",
      primitives, primitives - unbounded, unbounded, materialCount(scene), lightsText(scene));
  text += fmt::format("glint: bounds: {}\n", formatBounds(scene));
  text += fmt::format("glint: image: {}, {}, {} {}, max depth {}, seed {}\n",
                      regionText(scene, crop), samplesText(scene.image()), threads,
                      plural(static_cast<std::uint64_t>(threads), "thread", "threads"),
                      scene.render().maxDepth, scene.render().seed);
  text += fmt::format("glint: rays: {} total, {:.1f} per pixel\n", stats.rays.total(),
                      static_cast<double>(stats.rays.total()) / pixels);
  text += fmt::format("glint: samples: {} total, {:.2f} per pixel\n", stats.rays.camera,
                      static_cast<double>(stats.rays.camera) / pixels);
  text += fmt::format("glint: time: load {}, build {}, render {}, write {}\n",
                      formatDuration(timings.load), formatDuration(timings.build),
                      formatDuration(stats.seconds), formatDuration(timings.write));
  text += fmt::format("glint: non-finite samples: {}\n", stats.nonFinite);
  emit(stderr, text);
}

int interrupted(int signal) {
  emit(stderr, "glint: interrupted\n");
  return SignalGuard::exitCodeFor(signal);
}

// The typed request of a render command, checked as far as possible without the scene.
struct RenderRequest {
  SceneOverrides overrides;
  std::string overrideText;  // "--width 70000", naming the options in a refusal message
  int threads = 0;           // 0: all cores
  std::optional<PixelRegion> crop;
  std::uint64_t memoryBudget = defaultImageMemoryBudget();  // --max-memory
};

RenderRequest parseRequest(const RenderArgs& args) {
  RenderRequest request;
  std::vector<std::string> named;
  if (args.width) {
    request.overrides.width =
        static_cast<int>(parseWholeNumber("--width", *args.width, 1, kMaxImageSide));
    named.push_back("--width " + *args.width);
  }
  if (args.height) {
    request.overrides.height =
        static_cast<int>(parseWholeNumber("--height", *args.height, 1, kMaxImageSide));
    named.push_back("--height " + *args.height);
  }
  if (args.samples) {
    request.overrides.samples =
        static_cast<int>(parseWholeNumber("--samples", *args.samples, 1, kMaxSamplesPerPixel));
    named.push_back("--samples " + *args.samples);
  }
  if (args.seed) request.overrides.seed = parseSeed(*args.seed);
  if (args.threads)
    request.threads =
        static_cast<int>(parseWholeNumber("--threads", *args.threads, 1, kMaxThreads));
  if (args.crop) request.crop = parseCrop(*args.crop);
  if (args.maxMemory) {
    request.memoryBudget = parseMemorySize(*args.maxMemory);
    named.push_back("--max-memory " + *args.maxMemory);
  }
  request.overrideText = fmt::format("{}", fmt::join(named, " "));
  return request;
}

// The checkpoint file a render writes: --checkpoint, or else the --resume file (a resumed render
// keeps checkpointing, so it can be interrupted again). Checked before any work, like the output.
std::optional<fs::path> resolveCheckpoint(const RenderArgs& args, const fs::path& out) {
  if (!args.checkpoint && !args.resume) return std::nullopt;
  const fs::path path(args.checkpoint ? *args.checkpoint : *args.resume);
  if (path.empty()) throw CliError(kExitBadInput, "--checkpoint needs a file name");
  std::error_code error;
  if (fs::equivalent(path, out, error) || path.lexically_normal() == out.lexically_normal())
    throw CliError(kExitBadInput,
                   fmt::format("the checkpoint '{}' cannot be the output image", path.string()));
  const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(folder, error))
    throw CliError(kExitBadInput,
                   fmt::format("cannot write checkpoint '{}': the folder '{}' does not exist",
                               path.string(), folder.string()));
  if (fs::is_directory(path, error))
    throw CliError(kExitBadInput,
                   fmt::format("cannot write checkpoint '{}': it is a folder", path.string()));
  if (access(folder.c_str(), W_OK | X_OK) != 0)
    throw CliError(kExitFailure,
                   fmt::format("cannot write checkpoint '{}': the folder '{}' is not writable",
                               path.string(), folder.string()));
  // Starting afresh over an existing checkpoint would throw away the work saved in it.
  const bool continuesIt = args.resume && fs::equivalent(path, fs::path(*args.resume), error);
  if (!continuesIt && fs::exists(path, error))
    throw CliError(kExitBadInput,
                   fmt::format("the checkpoint '{}' already exists; continue it with --resume {}, "
                               "or delete it to start over",
                               path.string(), path.string()));
  return path;
}

std::string readWholeFile(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in && !in.eof())
    throw CliError(kExitFailure, fmt::format("cannot read '{}' again to fingerprint it", file));
  return bytes;
}

int runRender(const RenderArgs& args, SignalGuard& signals) {
  const RenderRequest request = parseRequest(args);
  const std::optional<PixelRegion>& crop = request.crop;
  const fs::path out = resolveOutput(args);
  const std::optional<fs::path> checkpointPath = resolveCheckpoint(args, out);

  Timings timings;
  auto phase = Clock::now();
  LoadedScene loaded = load(args.scene, !args.quiet, request.memoryBudget, request.overrides);
  ImageSettings allocated = loaded.parts.image;
  if (crop) {
    checkCrop(*crop, loaded.parts.image.width, loaded.parts.image.height);
    // The film covers only the crop, so a huge image can still be rendered piece by piece.
    allocated.width = crop->width();
    allocated.height = crop->height();
  }
  const int filmCopies = 1 + (checkpointPath ? 1 : 0) + (args.resume ? 1 : 0);
  enforceImageLimits(allocated, request.overrideText, request.memoryBudget, filmCopies);
  timings.load = secondsSince(phase);
  if (signals.receivedSignal() != 0) return interrupted(signals.receivedSignal());

  phase = Clock::now();
  const Scene scene = build(std::move(loaded.parts), args.scene);
  timings.build = secondsSince(phase);
  if (signals.receivedSignal() != 0) return interrupted(signals.receivedSignal());

  RenderOptions options;
  options.threads = request.threads;
  options.crop = crop;
  options.cancel = &signals.cancelFlag();
  const PixelRegion region =
      crop.value_or(PixelRegion{0, 0, scene.image().width, scene.image().height});
  const std::vector<PixelRegion> tiles = tileRegions(region, options.tileSize);

  // Checkpointing: the fingerprint of this render, the checkpoint it continues, the collector.
  std::optional<Checkpoint> resumed;
  std::optional<CheckpointCollector> collector;
  if (checkpointPath) {
    const CheckpointSettings settings = checkpointSettingsFor(scene, region, options.tileSize);
    const std::uint64_t fingerprint = renderFingerprint(readWholeFile(args.scene), scene, settings);
    if (args.resume) {
      try {
        resumed = readCheckpoint(*args.resume, request.memoryBudget);
      } catch (const CheckpointError& error) {
        throw CliError(kExitBadInput, fmt::format("cannot resume: {}", error.what()));
      }
      if (const std::optional<std::string> mismatch =
              checkpointMismatch(*resumed, fingerprint, settings))
        throw CliError(kExitBadInput,
                       fmt::format("cannot resume from '{}': {}; render with the same scene and "
                                   "options, or delete it to start over",
                                   *args.resume, *mismatch));
      options.resumeFilm = &resumed->film;
      options.resumeTiles = &resumed->tiles;
    }
    collector.emplace(*checkpointPath, resumed ? *resumed : emptyCheckpoint(fingerprint, settings));
  }
  if (signals.receivedSignal() != 0) return interrupted(signals.receivedSignal());

  ProgressReporter progress(
      args.quiet ? ProgressReporter::Style::Silent : ProgressReporter::styleFor(stderr), stderr);
  options.progress = [&progress](std::size_t done, std::size_t total) {
    progress.update(done, total);
  };
  bool saveFailed = false;  // warn once, not at every periodic save
  if (collector) {
    options.tileFinished = [&](std::size_t tile, const Film& film) {
      collector->addTile(tile, film);
      // After a stop request the checkpoint is saved once, when the render has returned.
      if (!collector->saveDue() || signals.receivedSignal() != 0) return;
      // A second signal must not end the process with a temporary file left behind.
      signals.setCommitting(true);
      try {
        collector->save();
      } catch (const CheckpointError& error) {
        if (!saveFailed)
          emit(stderr, fmt::format("\nglint: warning: {}; the render goes on\n", error.what()));
        saveFailed = true;
      }
      signals.setCommitting(false);
    };
  }
  RenderStats stats;
  progress.start(resumed ? resumed->finishedTiles() : 0);
  Film film = render(scene, options, &stats);
  progress.finish();
  // A signal that came after the last tile still means "stop": nothing is written.
  if (stats.cancelled || signals.receivedSignal() != 0) {
    const int signal = signals.receivedSignal() != 0 ? signals.receivedSignal() : SIGINT;
    if (!collector) return interrupted(signal);
    signals.setCommitting(true);
    try {
      collector->save();
      emit(stderr, fmt::format("glint: interrupted; {} of {} tiles saved to '{}' (continue with "
                               "--resume {})\n",
                               collector->checkpoint().finishedTiles(), tiles.size(),
                               checkpointPath->string(), checkpointPath->string()));
    } catch (const CheckpointError& error) {
      emit(stderr, fmt::format("glint: interrupted; {}\n", error.what()));
    }
    return SignalGuard::exitCodeFor(signal);
  }

  // From here on the image is complete; the writer commits it atomically (temporary file, rename)
  // and a second signal no longer ends the process halfway through.
  signals.setCommitting(true);
  phase = Clock::now();
  try {
    writeImage(film, out, scene.image().encoding);
  } catch (const ImageWriteError& error) {
    // Keep the finished render: a --resume after fixing the output only writes the image.
    if (collector) {
      try {
        collector->save();
        printError(error.what());
        emit(stderr, fmt::format("glint: the finished render is saved in '{}' (write the image "
                                 "with --resume {})\n",
                                 checkpointPath->string(), checkpointPath->string()));
        return kExitFailure;
      } catch (const CheckpointError&) {
        // Report the write failure itself.
      }
    }
    throw CliError(kExitFailure, error.what());
  }
  timings.write = secondsSince(phase);
  // The image is complete, so its checkpoint has served its purpose.
  if (checkpointPath) {
    std::error_code error;
    fs::remove(*checkpointPath, error);
    if (error && !args.quiet)
      emit(stderr, fmt::format("glint: warning: cannot remove the checkpoint '{}': {}\n",
                               checkpointPath->string(), error.message()));
  }

  if (!args.quiet) {
    RenderFacts facts;
    facts.tilesTotal = tiles.size();
    for (std::size_t i = 0; i < tiles.size(); ++i)
      if (!resumed || !resumed->tiles[i])
        facts.pixelsRendered += static_cast<std::uint64_t>(tiles[i].width()) *
                                static_cast<std::uint64_t>(tiles[i].height());
    if (args.resume) facts.resumedFrom = *args.resume;
    printSummary(out, scene, crop, stats, facts);
    if (args.stats) {
      const int threads = request.threads > 0 ? request.threads : tbb::info::default_concurrency();
      printStats(scene, crop, threads, stats, timings, facts);
    }
  }
  return kExitSuccess;
}

// Argument-parser errors: CLI11's own message, minus its jargon, plus where to find help.
int parseFailure(const CLI::ParseError& error) {
  const std::string_view message = error.what();
  const std::size_t colon = message.find(": ");
  if (message == "A subcommand is required") {
    printError("a command is required: glint render SCENE, or glint check SCENE");
  } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) &&
             colon != std::string_view::npos && message.ends_with(" missing")) {
    // CLI11 says "--width: 1 required W missing".
    printError(fmt::format("{} needs a value", message.substr(0, colon)));
  } else {
    printError(message);
  }
  emit(stderr, "Run 'glint --help' for usage.\n");
  return kExitBadInput;
}

int runCommandLine(int argc, char** argv) {
  CLI::App app{
      "glint: a Whitted ray tracer. Renders YAML scene files to PNG, PPM or OpenEXR images.",
      "glint"};
  app.set_version_flag("--version", std::string("glint ") + GLINT_VERSION,
                       "Print the version and exit");
  app.require_subcommand(1);

  RenderArgs args;
  CLI::App* render = app.add_subcommand("render", "Render a scene file to an image");
  render->add_option("SCENE", args.scene, "Scene file (YAML or JSON)")
      ->required()
      ->type_name("FILE");
  render
      ->add_option("-o,--output", args.output,
                   "Output image: .png (8-bit), .ppm (8-bit) or .exr (linear float); "
                   "default: the scene's name with .png, in the current folder")
      ->type_name("OUT");
  // Valued options are read as text and parsed by parseRequest (uniform messages, no wrap-around).
  std::string width, height, samples, threads, seed, crop;
  CLI::Option* widthOption =
      render->add_option("--width", width, "Image width in pixels; alone it keeps the aspect")
          ->type_name("W");
  CLI::Option* heightOption =
      render->add_option("--height", height, "Image height in pixels; alone it keeps the aspect")
          ->type_name("H");
  CLI::Option* samplesOption =
      render->add_option("--samples", samples, "Samples per pixel, 1 to 65536")->type_name("N");
  CLI::Option* threadsOption =
      render->add_option("--threads", threads, "Worker threads (default: all cores)")
          ->type_name("N");
  CLI::Option* seedOption =
      render->add_option("--seed", seed, "Random seed (replaces the scene's render.seed)")
          ->type_name("S");
  CLI::Option* cropOption =
      render
          ->add_option("--crop", crop,
                       "Render only pixels X0 <= x < X1, Y0 <= y < Y1; the image is that region")
          ->type_name("X0,Y0,X1,Y1");
  std::string maxMemory, checkpoint, resume;
  CLI::Option* maxMemoryOption =
      render
          ->add_option("--max-memory", maxMemory,
                       "Memory the scene may need (film, meshes, BVH), e.g. 512M, 4G, 1.5GiB or "
                       "bytes; default: half the physical memory")
          ->type_name("SIZE");
  CLI::Option* checkpointOption =
      render
          ->add_option("--checkpoint", checkpoint,
                       "Save finished tiles to FILE every few seconds and when interrupted; "
                       "removed when the image is written")
          ->type_name("FILE");
  CLI::Option* resumeOption =
      render
          ->add_option("--resume", resume,
                       "Continue the render saved in FILE (same scene and options), and keep "
                       "checkpointing into it unless --checkpoint names another file")
          ->type_name("FILE");
  render->add_flag("--quiet", args.quiet, "No progress and no summary; errors only");
  render->add_flag("--stats", args.stats, "More statistics at the end");

  std::string checkFile;
  CLI::App* check =
      app.add_subcommand("check", "Parse and build a scene, print a summary; writes nothing");
  check->add_option("SCENE", checkFile, "Scene file (YAML or JSON)")->required()->type_name("FILE");

  // Set after the subcommands exist: CLI11 copies a parent's footer into subcommands made later.
  const std::string exitStatus =
      "Exit status: 0 success; 1 failure while rendering or writing; 2 bad arguments, a bad scene, "
      "a request refused as too large or a checkpoint that does not match; 130/143 interrupted "
      "by SIGINT/SIGTERM (no output written; the --checkpoint file saved).";
  app.footer(
      "Examples:\n  glint render scene.yaml -o scene.png --width 800\n"
      "  glint render scene.yaml --crop 0,0,400,300 -o top-left.ppm\n"
      "  glint check scene.yaml\n\nRun 'glint render --help' for the render options.\n\n" +
      exitStatus);
  render->footer(exitStatus);
  check->footer(exitStatus);

  // CLI11 would call an unknown command a "missing subcommand"; say what happened instead.
  if (argc >= 2 && argv[1][0] != '-' && std::string_view(argv[1]) != "render" &&
      std::string_view(argv[1]) != "check") {
    printError(fmt::format("unknown command '{}'; the commands are render and check", argv[1]));
    emit(stderr, "Run 'glint --help' for usage.\n");
    return kExitBadInput;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& success) {
    return app.exit(success);  // --help, --version: printed on stdout, exit 0
  } catch (const CLI::ParseError& error) {
    return parseFailure(error);
  }
  const auto given = [](const CLI::Option* option, const std::string& text) {
    return option->count() > 0 ? std::optional<std::string>(text) : std::nullopt;
  };
  args.width = given(widthOption, width);
  args.height = given(heightOption, height);
  args.samples = given(samplesOption, samples);
  args.threads = given(threadsOption, threads);
  args.seed = given(seedOption, seed);
  args.crop = given(cropOption, crop);
  args.maxMemory = given(maxMemoryOption, maxMemory);
  args.checkpoint = given(checkpointOption, checkpoint);
  args.resume = given(resumeOption, resume);

  if (check->parsed()) return runCheck(checkFile);
  SignalGuard signals;
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
