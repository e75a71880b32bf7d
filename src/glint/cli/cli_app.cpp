#include "glint/cli/cli_app.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <oneapi/tbb/info.h>
#include <CLI/CLI.hpp>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "glint/cli/progress_reporter.h"
#include "glint/cli/signal_guard.h"
#include "glint/io/diagnostics.h"
#include "glint/io/image_writer.h"
#include "glint/io/scene_limits.h"
#include "glint/io/scene_loader.h"
#include "glint/io/scene_overrides.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

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
  std::optional<std::string> width, height, samples, threads, seed, crop;
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

LoadedScene load(const std::string& file, bool showWarnings) {
  try {
    LoadedScene loaded = loadScene(file);
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
void enforceImageLimits(const ImageSettings& image, const std::string& request) {
  if (const std::optional<std::string> refusal = checkImageSettings(image)) {
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

// "2 + ambient": the light sources, and whether the scene has ambient light.
std::string lightsText(const Scene& scene) {
  return fmt::format("{}{}", scene.lights().size(), isBlack(scene.ambient()) ? "" : " + ambient");
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
  text += fmt::format("image:     {}x{}, {} {} per pixel, {} encoding\n", image.width, image.height,
                      image.samples, plural(image.samples, "sample", "samples"),
                      image.encoding == Encoding::Srgb ? "srgb" : "linear");
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

void printSummary(const fs::path& out, const Scene& scene, const std::optional<PixelRegion>& crop,
                  const RenderStats& stats) {
  const RayCounts& rays = stats.rays;
  const std::string rate =
      stats.seconds > 0
          ? fmt::format("{:.2f} Mrays/s", static_cast<double>(rays.total()) / stats.seconds / 1e6)
          : std::string("- Mrays/s");
  emit(stderr, fmt::format("glint: wrote {} ({}) in {}; rays: {} camera, {} shadow, {} reflection, "
                           "{} refraction; {}\n",
                           out.string(), regionText(scene, crop), formatDuration(stats.seconds),
                           rays.camera, rays.shadow, rays.reflection, rays.refraction, rate));
}

struct Timings {
  double load = 0, build = 0, write = 0;
};

void printStats(const Scene& scene, const std::optional<PixelRegion>& crop, int threads,
                const RenderStats& stats, const Timings& timings) {
  const std::size_t primitives = scene.primitives().size();
  const std::size_t unbounded = unboundedCount(scene);
  const PixelRegion region =
      crop.value_or(PixelRegion{0, 0, scene.image().width, scene.image().height});
  const auto pixels = static_cast<double>(region.width()) * region.height();
  std::string text;
  text += fmt::format(
      "glint: scene: {} primitives ({} in the BVH, {} unbounded), {} materials, "
      "lights: {}\n",
      primitives, primitives - unbounded, unbounded, materialCount(scene), lightsText(scene));
  text += fmt::format("glint: bounds: {}\n", formatBounds(scene));
  text += fmt::format("glint: image: {}, {} samples per pixel, {} {}, max depth {}, seed {}\n",
                      regionText(scene, crop), scene.image().samples, threads,
                      plural(static_cast<std::uint64_t>(threads), "thread", "threads"),
                      scene.render().maxDepth, scene.render().seed);
  text += fmt::format("glint: rays: {} total, {:.1f} per pixel\n", stats.rays.total(),
                      static_cast<double>(stats.rays.total()) / pixels);
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
  request.overrideText = fmt::format("{}", fmt::join(named, " "));
  return request;
}

int runRender(const RenderArgs& args, SignalGuard& signals) {
  const RenderRequest request = parseRequest(args);
  const std::optional<PixelRegion>& crop = request.crop;
  const fs::path out = resolveOutput(args);

  Timings timings;
  auto phase = Clock::now();
  LoadedScene loaded = load(args.scene, !args.quiet);
  applyOverrides(loaded.parts, request.overrides);
  ImageSettings allocated = loaded.parts.image;
  if (crop) {
    checkCrop(*crop, loaded.parts.image.width, loaded.parts.image.height);
    // The film covers only the crop, so a huge image can still be rendered piece by piece.
    allocated.width = crop->width();
    allocated.height = crop->height();
  }
  enforceImageLimits(allocated, request.overrideText);
  timings.load = secondsSince(phase);
  if (signals.receivedSignal() != 0) return interrupted(signals.receivedSignal());

  phase = Clock::now();
  const Scene scene = build(std::move(loaded.parts), args.scene);
  timings.build = secondsSince(phase);
  if (signals.receivedSignal() != 0) return interrupted(signals.receivedSignal());

  ProgressReporter progress(
      args.quiet ? ProgressReporter::Style::Silent : ProgressReporter::styleFor(stderr), stderr);
  RenderOptions options;
  options.threads = request.threads;
  options.crop = crop;
  options.cancel = &signals.cancelFlag();
  options.progress = [&progress](std::size_t done, std::size_t total) {
    progress.update(done, total);
  };
  RenderStats stats;
  progress.start();
  Film film = render(scene, options, &stats);
  progress.finish();
  // A signal that came after the last tile still means "stop": nothing is written.
  if (stats.cancelled || signals.receivedSignal() != 0)
    return interrupted(signals.receivedSignal() != 0 ? signals.receivedSignal() : SIGINT);

  // From here on the image is complete; the writer commits it atomically (temporary file, rename)
  // and a second signal no longer ends the process halfway through.
  signals.setCommitting(true);
  phase = Clock::now();
  try {
    writeImage(film, out, scene.image().encoding);
  } catch (const ImageWriteError& error) {
    throw CliError(kExitFailure, error.what());
  }
  timings.write = secondsSince(phase);

  if (!args.quiet) {
    printSummary(out, scene, crop, stats);
    if (args.stats) {
      const int threads = request.threads > 0 ? request.threads : tbb::info::default_concurrency();
      printStats(scene, crop, threads, stats, timings);
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
  render->add_flag("--quiet", args.quiet, "No progress and no summary; errors only");
  render->add_flag("--stats", args.stats, "More statistics at the end");

  std::string checkFile;
  CLI::App* check =
      app.add_subcommand("check", "Parse and build a scene, print a summary; writes nothing");
  check->add_option("SCENE", checkFile, "Scene file (YAML or JSON)")->required()->type_name("FILE");

  // Set after the subcommands exist: CLI11 copies a parent's footer into subcommands made later.
  const std::string exitStatus =
      "Exit status: 0 success; 1 failure while rendering or writing; 2 bad arguments, a bad scene "
      "or a request refused as too large; 130/143 interrupted by SIGINT/SIGTERM (no output "
      "written).";
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
