// Adaptive against fixed anti-aliasing at equal error (issue 5): the showcase
// (scenes/showcase.yaml, read at run time; only its image size, sample settings and seed are
// overridden here) rendered at a reduced size as a high-sample reference, a ladder of fixed sample
// counts and a ladder of adaptive thresholds. For every render: wall time (median of --runs where a
// run is cheap), CPU time, samples spent per pixel and the RMS error against the reference. Then,
// for each adaptive threshold, the fixed sample count that reaches the same error (log-log
// interpolation between fixed rungs) and its time: how much faster adaptive sampling is at equal
// error.
//
//   adaptive_sampling [--runs N] [--quick] [--size WxH] [--threads T] [--scene FILE]
//                     [--reference-spp N] [--fixed LIST] [--thresholds LIST] [--max-samples M]
//                     [--no-cache]
//
// Error: RMS over all pixels and channels of (render − reference), linear color; "corrected" also
// subtracts the reference's own noise. The reference is the mean of two independent fixed renders
// of N/2 samples with seeds unlike the ladders' (scene seed + kReferenceSeedOffset + 0/1), so its
// noise does not correlate with theirs; its variance per pixel channel is estimated as
// mean((A − B)²) / 4 and subtracted from the squared error (E[(x − ref)²] = err² + Var(ref)). The
// headline uses the corrected linear error; the 8-bit sRGB code error is printed beside it.
// Renders are deterministic (Sobol samples keyed by pixel, sample and seed), so only the times vary
// between runs; a repeated run that differs in any pixel is reported.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bench_support.h"
#include "glint/core/color.h"
#include "glint/factories/scene_loader.h"
#include "glint/readers/diagnostics.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint::bench {
namespace {

namespace fs = std::filesystem;

#ifdef GLINT_SHOWCASE_PATH
constexpr const char* kDefaultScene = GLINT_SHOWCASE_PATH;
#else
constexpr const char* kDefaultScene = "scenes/showcase.yaml";
#endif
#ifdef GLINT_LIBRARY_PATH
constexpr const char* kLibraryPath = GLINT_LIBRARY_PATH;
#else
constexpr const char* kLibraryPath = "/proc/self/exe";
#endif
#ifdef GLINT_BENCH_CACHE_DIR
constexpr const char* kCacheDir = GLINT_BENCH_CACHE_DIR;
#else
constexpr const char* kCacheDir = "adaptive_sampling_cache";
#endif

// Added to the scene's seed for the two reference halves: far from the ladders' seed.
constexpr std::uint64_t kReferenceSeedOffset = 0x9E3779B97F4A7C15ULL;
// A render is repeated (--runs times, median) only while one run takes less than this, in seconds.
constexpr double kCheapSeconds = 4.0;

struct Settings {
  int width = 320;
  int height = 180;
  int threads = 0;  // 0: all cores
  int referenceSpp = 256;
  int maxSamples = 64;
  int runs = 3;
  bool cache = true;
  std::vector<int> fixed{1, 2, 4, 8, 16, 32, 64};
  std::vector<double> thresholds{0.08, 0.04, 0.02, 0.01, 0.005};
  fs::path scene = kDefaultScene;
};

struct Reference {
  Film film;
  double variance = 0;  // of its pixel channels' noise, linear², averaged over the image
  double seconds = 0;   // to render (0: read from the cache)
  bool cached = false;
};

struct Errors {
  double linear = 0;     // RMS, linear color
  double corrected = 0;  // sqrt(max(0, linear² − Var(ref)))
  double srgb8 = 0;      // RMS of 8-bit sRGB code differences
};

struct Measurement {
  std::string label;
  int spp = 0;                      // fixed: samples per pixel; adaptive: the minimum
  std::optional<double> threshold;  // adaptive only
  Timing wall;                      // seconds per run (render() only, scene built outside)
  double cpuSeconds = 0;            // median CPU seconds per run, all threads
  double sppSpent = 0;              // camera samples / pixels
  double rays = 0;                  // all rays traced (camera, shadow, reflection, refraction)
  Errors error;
  bool deterministic = true;  // every repeated run gave the same film
};

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

[[noreturn]] void usageError(const std::string& message, const std::string& usage) {
  std::fprintf(stderr, "adaptive_sampling: %s\n%s", message.c_str(), usage.c_str());
  std::exit(2);
}

int positiveInt(const std::string& text, const std::string& what, const std::string& usage) {
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (errno != 0 || end == text.c_str() || *end != '\0' || value < 1 || value > 1 << 20) {
    usageError(what + " must be a positive integer, not '" + text + "'", usage);
  }
  return static_cast<int>(value);
}

double positiveDouble(const std::string& text, const std::string& what, const std::string& usage) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(value > 0) || !std::isfinite(value)) {
    usageError(what + " must be a positive number, not '" + text + "'", usage);
  }
  return value;
}

std::uint64_t fnv1a(std::uint64_t hash, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001B3ULL;
  }
  return hash;
}

// The reference's cache file: keyed by the scene text, the size, the sample count, the seed and
// the modification time of the glint library this program was linked with (a rebuilt renderer gives
// a new key; kCacheMagic changes when this program computes the reference differently).
fs::path referenceCachePath(const Settings& settings, const std::string& sceneText,
                            std::uint64_t seed) {
  std::uint64_t key = 0xCBF29CE484222325ULL;
  key = fnv1a(key, sceneText.data(), sceneText.size());
  const int numbers[] = {settings.width, settings.height, settings.referenceSpp};
  key = fnv1a(key, numbers, sizeof numbers);
  key = fnv1a(key, &seed, sizeof seed);
  std::error_code ignored;
  fs::path library = kLibraryPath;
  if (fs::is_symlink(library, ignored)) library = fs::read_symlink(library, ignored);
  const auto stamp = fs::last_write_time(library, ignored).time_since_epoch().count();
  key = fnv1a(key, &stamp, sizeof stamp);
  char name[64];
  std::snprintf(name, sizeof name, "reference-%016llx.bin", static_cast<unsigned long long>(key));
  return fs::path(kCacheDir) / name;
}

constexpr char kCacheMagic[8] = {'g', 'l', 'r', 'e', 'f', '0', '0', '1'};

std::optional<Reference> readCachedReference(const fs::path& path, int width, int height) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  char magic[8];
  int size[2];
  Reference reference;
  reference.film = Film(width, height, PixelRegion{0, 0, width, height});
  in.read(magic, sizeof magic);
  in.read(reinterpret_cast<char*>(size), sizeof size);
  in.read(reinterpret_cast<char*>(&reference.variance), sizeof reference.variance);
  if (!in || !std::equal(std::begin(magic), std::end(magic), std::begin(kCacheMagic)) ||
      size[0] != width || size[1] != height) {
    return std::nullopt;
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Color& c = reference.film.at(x, y);
      in.read(reinterpret_cast<char*>(&c.r), sizeof c.r);
      in.read(reinterpret_cast<char*>(&c.g), sizeof c.g);
      in.read(reinterpret_cast<char*>(&c.b), sizeof c.b);
    }
  }
  if (!in) return std::nullopt;
  reference.cached = true;
  return reference;
}

void writeCachedReference(const fs::path& path, const Reference& reference) {
  std::error_code error;
  fs::create_directories(path.parent_path(), error);
  std::ofstream out(path, std::ios::binary);
  const int size[2] = {reference.film.width(), reference.film.height()};
  out.write(kCacheMagic, sizeof kCacheMagic);
  out.write(reinterpret_cast<const char*>(size), sizeof size);
  out.write(reinterpret_cast<const char*>(&reference.variance), sizeof reference.variance);
  for (const Color& c : reference.film.pixels()) {
    out.write(reinterpret_cast<const char*>(&c.r), sizeof c.r);
    out.write(reinterpret_cast<const char*>(&c.g), sizeof c.g);
    out.write(reinterpret_cast<const char*>(&c.b), sizeof c.b);
  }
  if (!out) std::fprintf(stderr, "adaptive_sampling: warning: could not write %s\n", path.c_str());
}

// The base scene with the image settings of one measurement.
SceneParts withSampling(const SceneParts& base, const Settings& settings, int spp,
                        std::optional<AdaptiveSampling> adaptive, std::uint64_t seed) {
  SceneParts parts = base;
  parts.image.width = settings.width;
  parts.image.height = settings.height;
  parts.image.samples = spp;
  parts.image.adaptive = adaptive;
  parts.image.grid.reset();
  parts.render.seed = seed;
  return parts;
}

Film renderOnce(const Scene& scene, int threads, RenderStats& stats) {
  RenderOptions options;
  options.threads = threads;
  return render(scene, options, &stats);
}

bool sameFilm(const Film& a, const Film& b) {
  const auto& pa = a.pixels();
  const auto& pb = b.pixels();
  return std::equal(pa.begin(), pa.end(), pb.begin(), pb.end(), [](const Color& x, const Color& y) {
    return x.r == y.r && x.g == y.g && x.b == y.b;
  });
}

std::uint8_t srgbCode(double linear) {
  return static_cast<std::uint8_t>(
      std::lround(std::clamp(linearToSrgb(std::clamp(linear, 0.0, 1.0)), 0.0, 1.0) * 255.0));
}

Errors errorsAgainst(const Film& film, const Reference& reference) {
  double sum = 0, sumCodes = 0;
  const auto& pixels = film.pixels();
  const auto& expected = reference.film.pixels();
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const double channels[3][2] = {
        {pixels[i].r, expected[i].r}, {pixels[i].g, expected[i].g}, {pixels[i].b, expected[i].b}};
    for (const auto& [value, ref] : channels) {
      sum += (value - ref) * (value - ref);
      const double codes = static_cast<double>(srgbCode(value)) - srgbCode(ref);
      sumCodes += codes * codes;
    }
  }
  const double count = 3.0 * static_cast<double>(pixels.size());
  Errors errors;
  errors.linear = std::sqrt(sum / count);
  errors.corrected = std::sqrt(std::max(0.0, sum / count - reference.variance));
  errors.srgb8 = std::sqrt(sumCodes / count);
  return errors;
}

Reference renderReference(const SceneParts& base, const Settings& settings, std::uint64_t seed) {
  const int half = std::max(1, settings.referenceSpp / 2);
  Reference reference;
  Film halves[2];
  for (int i = 0; i < 2; ++i) {
    const Scene scene(withSampling(base, settings, half, std::nullopt,
                                   seed + kReferenceSeedOffset + static_cast<std::uint64_t>(i)));
    RenderStats stats;
    halves[i] = renderOnce(scene, settings.threads, stats);
    reference.seconds += stats.seconds;
    std::printf("  reference half %d: %d spp, %.2f s\n", i + 1, half, stats.seconds);
    std::fflush(stdout);
  }
  reference.film = halves[0];
  double squares = 0;
  const auto& a = halves[0].pixels();
  const auto& b = halves[1].pixels();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Color d = a[i] - b[i];
    squares += d.r * d.r + d.g * d.g + d.b * d.b;
    reference.film.at(static_cast<int>(i % static_cast<std::size_t>(settings.width)),
                      static_cast<int>(i / static_cast<std::size_t>(settings.width))) =
        0.5 * (a[i] + b[i]);
  }
  reference.variance = squares / (3.0 * static_cast<double>(a.size())) / 4.0;
  return reference;
}

Measurement measure(const SceneParts& base, const Settings& settings, int spp,
                    std::optional<AdaptiveSampling> adaptive, std::uint64_t seed,
                    const Reference& reference) {
  Measurement m;
  m.spp = spp;
  if (adaptive) m.threshold = adaptive->threshold;
  char label[64];
  if (adaptive) {
    std::snprintf(label, sizeof label, "adaptive T=%g max %d", adaptive->threshold,
                  adaptive->maxSamples);
  } else {
    std::snprintf(label, sizeof label, "fixed %d spp", spp);
  }
  m.label = label;
  const Scene scene(withSampling(base, settings, spp, adaptive, seed));
  Film first;
  std::vector<double> cpu;
  for (int run = 0; run < settings.runs; ++run) {
    RenderStats stats;
    const double cpuBefore = processCpuSeconds();
    Film film = renderOnce(scene, settings.threads, stats);
    cpu.push_back(processCpuSeconds() - cpuBefore);
    m.wall.seconds.push_back(stats.seconds);
    if (run == 0) {
      first = std::move(film);
      m.rays = static_cast<double>(stats.rays.total());
      m.sppSpent = static_cast<double>(stats.rays.camera) /
                   (static_cast<double>(settings.width) * settings.height);
    } else if (!sameFilm(first, film)) {
      m.deterministic = false;
    }
    if (stats.seconds > kCheapSeconds) break;  // not cheap: one run is the figure
  }
  std::sort(cpu.begin(), cpu.end());
  const std::size_t n = cpu.size();
  m.cpuSeconds = n % 2 == 1 ? cpu[n / 2] : 0.5 * (cpu[n / 2 - 1] + cpu[n / 2]);
  m.error = errorsAgainst(first, reference);
  return m;
}

// The fixed-sampling cost of reaching `error`: spp, wall and CPU seconds, by log-log interpolation
// between the two fixed rungs whose errors bracket it (the nearest two, extrapolated, outside).
struct EqualError {
  double spp = 0;
  double seconds = 0;
  double cpuSeconds = 0;
  double rays = 0;
  bool extrapolated = false;
};

EqualError fixedAtError(const std::vector<Measurement>& fixed, double error) {
  EqualError result;
  if (fixed.size() < 2 || !(error > 0)) return result;
  std::size_t segment = fixed.size() - 2;  // below the last rung: extrapolate from the last two
  result.extrapolated = true;
  if (error >= fixed.front().error.corrected) {
    segment = 0;
    result.extrapolated = error > fixed.front().error.corrected;
  } else {
    for (std::size_t i = 0; i + 1 < fixed.size(); ++i) {
      if (fixed[i].error.corrected >= error && error >= fixed[i + 1].error.corrected) {
        segment = i;
        result.extrapolated = false;
        break;
      }
    }
  }
  const Measurement& a = fixed[segment];
  const Measurement& b = fixed[segment + 1];
  const double la = std::log(a.error.corrected), lb = std::log(b.error.corrected);
  const double t = lb != la ? (std::log(error) - la) / (lb - la) : 0.0;
  const auto lerpLog = [t](double x, double y) {
    return std::exp(std::log(x) + t * (std::log(y) - std::log(x)));
  };
  result.spp = lerpLog(a.spp, b.spp);
  result.seconds = lerpLog(a.wall.median(), b.wall.median());
  result.cpuSeconds = lerpLog(a.cpuSeconds, b.cpuSeconds);
  result.rays = lerpLog(a.rays, b.rays);
  return result;
}

void printRow(const Measurement& m) {
  std::printf("%-24s | %7.2f | %8.3f ±%3.0f%% %2zu | %8.3f | %7.2f | %9.5f | %9.5f | %7.3f%s\n",
              m.label.c_str(), m.sppSpent, m.wall.median(), m.wall.spreadPercent(),
              m.wall.seconds.size(), m.cpuSeconds, m.rays * 1e-6, m.error.linear, m.error.corrected,
              m.error.srgb8, m.deterministic ? "" : "  (runs differ!)");
  std::fflush(stdout);
}

int run(int argc, char** argv) {
  const std::string usage =
      "usage: adaptive_sampling [--runs N] [--quick] [--size WxH] [--threads T] [--scene FILE]\n"
      "                         [--reference-spp N] [--fixed LIST] [--thresholds LIST]\n"
      "                         [--max-samples M] [--no-cache]\n"
      "  --runs N             repetitions of a render taking < 4 s (median; default 3)\n"
      "  --quick              160x90, reference 64 spp, 1 run: a smoke test\n"
      "  --size WxH           image size the showcase is rendered at (default 320x180)\n"
      "  --threads T          render threads (default: all cores)\n"
      "  --scene FILE         scene file (default scenes/showcase.yaml of the source tree)\n"
      "  --reference-spp N    samples per pixel of the reference, two halves (default 256)\n"
      "  --fixed LIST         fixed sample counts, ascending (default 1,2,4,8,16,32,64)\n"
      "  --thresholds LIST    adaptive thresholds (default 0.08,0.04,0.02,0.01,0.005 plus the\n"
      "                       scene's own)\n"
      "  --max-samples M      adaptive cap per pixel (default 64); the minimum is 4\n"
      "  --no-cache           render the reference even if a cached one matches\n";
  std::vector<ExtraOption> extra{{"--size"},          {"--threads"},        {"--scene"},
                                 {"--reference-spp"}, {"--fixed"},          {"--thresholds"},
                                 {"--max-samples"},   {"--no-cache", false}};
  const CommonOptions common = parseCommonOptions(argc, argv, usage, &extra);
  bool runsGiven = false;
  for (int i = 1; i < argc; ++i) runsGiven = runsGiven || std::string(argv[i]) == "--runs";

  Settings settings;
  if (common.quick) {
    settings.width = 160;
    settings.height = 90;
    settings.referenceSpp = 64;
    settings.runs = 1;
  }
  if (runsGiven) settings.runs = common.runs;
  if (extra[0].present) {
    const std::string& size = extra[0].value;
    const std::size_t x = size.find('x');
    if (x == std::string::npos) usageError("--size must be WxH, not '" + size + "'", usage);
    settings.width = positiveInt(size.substr(0, x), "--size width", usage);
    settings.height = positiveInt(size.substr(x + 1), "--size height", usage);
  }
  if (extra[1].present) settings.threads = positiveInt(extra[1].value, "--threads", usage);
  if (extra[2].present) settings.scene = extra[2].value;
  if (extra[3].present) {
    settings.referenceSpp = positiveInt(extra[3].value, "--reference-spp", usage);
  }
  if (extra[4].present) {
    settings.fixed.clear();
    for (const std::string& item : splitList(extra[4].value)) {
      settings.fixed.push_back(positiveInt(item, "--fixed", usage));
    }
    if (settings.fixed.size() < 2 ||
        !std::is_sorted(settings.fixed.begin(), settings.fixed.end())) {
      usageError("--fixed needs at least two ascending sample counts", usage);
    }
  }
  if (extra[5].present) {
    settings.thresholds.clear();
    for (const std::string& item : splitList(extra[5].value)) {
      settings.thresholds.push_back(positiveDouble(item, "--thresholds", usage));
    }
    if (settings.thresholds.empty()) usageError("--thresholds needs a value", usage);
  }
  if (extra[6].present) settings.maxSamples = positiveInt(extra[6].value, "--max-samples", usage);
  settings.cache = !extra[7].present;

  CommonOptions shown = common;
  shown.runs = settings.runs;
  printHeader("Adaptive vs fixed sampling at equal error (showcase)", shown);
  SceneParts base;
  std::string sceneText;
  try {
    std::ifstream in(settings.scene, std::ios::binary);
    sceneText.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    base = loadScene(settings.scene).parts;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "adaptive_sampling: cannot load %s: %s\n", settings.scene.c_str(),
                 error.what());
    return 1;
  }
  const std::optional<AdaptiveSampling> own = base.image.adaptive;
  if (own && !extra[5].present &&
      std::find(settings.thresholds.begin(), settings.thresholds.end(), own->threshold) ==
          settings.thresholds.end()) {
    settings.thresholds.push_back(own->threshold);
  }
  std::sort(settings.thresholds.rbegin(), settings.thresholds.rend());
  const double headlineThreshold =
      own && std::find(settings.thresholds.begin(), settings.thresholds.end(), own->threshold) !=
                  settings.thresholds.end()
          ? own->threshold
          : settings.thresholds[settings.thresholds.size() / 2];
  const std::uint64_t seed = base.render.seed;
  const int threads = settings.threads > 0 ? settings.threads : hardwareThreads();

  std::printf("scene: %s (file: %dx%d, %d spp", settings.scene.c_str(), base.image.width,
              base.image.height, base.image.samples);
  if (own) std::printf(", adaptive max %d threshold %g", own->maxSamples, own->threshold);
  std::printf(", blur_samples %d, max_depth %d)\n", base.render.blurSamples, base.render.maxDepth);
  std::printf(
      "rendered at %dx%d on %d thread%s, seed %llu; adaptive: min 4 spp, max %d, thresholds as "
      "listed\nreference: %d spp (two halves, other seeds); wall time of render() only, median of "
      "up to %d runs (one when a run takes > %.0f s)\n\n",
      settings.width, settings.height, threads, threads == 1 ? "" : "s",
      static_cast<unsigned long long>(seed), settings.maxSamples, settings.referenceSpp,
      settings.runs, kCheapSeconds);
  std::fflush(stdout);

  const fs::path cachePath = referenceCachePath(settings, sceneText, seed);
  std::optional<Reference> reference;
  if (settings.cache) reference = readCachedReference(cachePath, settings.width, settings.height);
  if (reference) {
    std::printf("reference: read from %s\n", cachePath.c_str());
  } else {
    std::printf("reference: rendering (load average %s)\n", loadAverage().c_str());
    std::fflush(stdout);
    reference = renderReference(base, settings, seed);
    if (settings.cache) writeCachedReference(cachePath, *reference);
    std::printf("reference: %.1f s, cached in %s\n", reference->seconds, cachePath.c_str());
  }
  std::printf("reference noise: RMS %.5f per pixel channel (subtracted in \"corrected\")\n\n",
              std::sqrt(reference->variance));

  std::printf("%-24s | %7s | %-17s | %8s | %7s | %9s | %9s | %7s\n", "render", "spp",
              "wall s (runs)", "CPU s", "Mrays", "RMS lin", "corrected", "RMS 8b");
  std::printf("%s\n", std::string(114, '-').c_str());
  std::vector<Measurement> fixed;
  for (int spp : settings.fixed) {
    fixed.push_back(measure(base, settings, spp, std::nullopt, seed, *reference));
    printRow(fixed.back());
  }
  std::vector<Measurement> adaptive;
  for (double threshold : settings.thresholds) {
    const int minimum = std::min(4, settings.maxSamples);
    adaptive.push_back(measure(base, settings, minimum,
                               AdaptiveSampling{settings.maxSamples, threshold}, seed, *reference));
    printRow(adaptive.back());
  }
  // The showcase's own adaptive settings, when its cap differs from the ladder's.
  if (own && own->maxSamples != settings.maxSamples) {
    adaptive.push_back(
        measure(base, settings, std::max(1, base.image.samples), own, seed, *reference));
    printRow(adaptive.back());
  }

  std::printf(
      "\nat equal error (corrected RMS, fixed ladder interpolated log-log; * = extrapolated):\n");
  std::printf("%-24s | %9s | %9s | %10s | %10s | %9s | %9s | %9s\n", "adaptive", "corrected",
              "fixed spp", "fixed s", "adaptive s", "speedup", "CPU ratio", "ray ratio");
  std::printf("%s\n", std::string(112, '-').c_str());
  std::vector<std::pair<const Measurement*, EqualError>> headlines;
  for (const Measurement& m : adaptive) {
    const EqualError eq = fixedAtError(fixed, m.error.corrected);
    std::printf("%-24s | %9.5f | %8.1f%s | %10.3f | %10.3f | %8.2fx | %8.2fx | %8.2fx\n",
                m.label.c_str(), m.error.corrected, eq.spp, eq.extrapolated ? "*" : " ", eq.seconds,
                m.wall.median(), eq.seconds / m.wall.median(), eq.cpuSeconds / m.cpuSeconds,
                eq.rays / m.rays);
    if (m.threshold && *m.threshold == headlineThreshold) headlines.emplace_back(&m, eq);
  }
  for (const auto& [m, eq] : headlines) {
    std::printf(
        "\nheadline: %s reaches RMS %.5f (linear, reference noise removed) with %.2f spp on "
        "average in %.3f s;\nfixed sampling needs %.1f spp%s and %.3f s for that error: adaptive "
        "is %.2fx as fast at equal error (%.2fx in CPU time; fixed traces %.2fx "
        "the rays, a ratio no load changes)\n",
        m->label.c_str(), m->error.corrected, m->sppSpent, m->wall.median(), eq.spp,
        eq.extrapolated ? " (extrapolated)" : "", eq.seconds, eq.seconds / m->wall.median(),
        eq.cpuSeconds / m->cpuSeconds, eq.rays / m->rays);
  }
  std::printf("threads %d; load average at the end %s\n", threads, loadAverage().c_str());
  return 0;
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) { return glint::bench::run(argc, argv); }
