// The path integrator (issue 18): convergence, multiple importance sampling and throughput.
//
//   path_tracing [--runs N] [--quick] [--size WxH] [--threads T]
//                [--only convergence|strategies|throughput]
//
// 1. Convergence on the Cornell box (scenes/cornell-path.yaml at --size, default 96×96): the RMS
//    error against a high-sample reference at 4 … 256 samples per pixel and the least-squares
//    slope of log(error) against log(spp); an unbiased Monte Carlo estimate falls as spp^−1/2.
//    The reference is the mean of two renders of R/2 samples with seeds unlike the ladder's; its
//    own noise (estimated from the two halves) is subtracted from the squared error. A second
//    ladder averages N/2 renders of 2 spp with their own seeds (independent samples) and prints
//    its slope too: glint's Sobol samples converge faster than spp^−1/2, independent ones must
//    not be slower. (The independent ladder uses renders of 2 spp: 1 spp is the unjittered
//    pixel centre.)
// 2. MIS against light sampling alone and BRDF sampling alone at equal time, on a scene built here
//    with a small bright emitter and a large dim one (the case each single strategy fails on):
//    the time per sample of each strategy is measured first, then each renders the number of
//    samples that fits the time MIS takes for 64, and its error against an MIS reference is
//    printed.
// 3. Throughput of `path` on the Cornell box and on the showcase (its integrator switched to
//    path) at 1 and 2 threads: Mrays/s over all rays traced (camera, shadow, bounces), median of
//    --runs; and the memory the integrator needs per pixel and per thread.
// Renders are deterministic; only the times vary between runs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "bench_support.h"
#include "glint/factories/scene_loader.h"
#include "glint/geometry/shape.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint::bench {
namespace {

#ifdef GLINT_SCENES_DIR
constexpr const char* kScenesDir = GLINT_SCENES_DIR;
#else
constexpr const char* kScenesDir = "scenes";
#endif

struct Rendered {
  Film film;
  double seconds = 0;
  double rays = 0;
};

Rendered renderTimed(const SceneParts& parts, int threads) {
  const Scene scene{SceneParts(parts)};
  RenderOptions options;
  options.threads = threads;
  RenderStats stats;
  const auto start = std::chrono::steady_clock::now();
  Film film = render(scene, options, &stats);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {std::move(film), seconds, static_cast<double>(stats.rays.total())};
}

double squaredError(const Film& a, const Film& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const Color d = a.pixels()[i] - b.pixels()[i];
    sum += d.r * d.r + d.g * d.g + d.b * d.b;
  }
  return sum / (3.0 * static_cast<double>(a.pixels().size()));
}

// A reference of `samples` per pixel as two halves with their own seeds: the mean, and the
// variance of its noise per pixel channel (mean((A − B)²) / 4).
std::pair<Film, double> reference(SceneParts parts, int samples, int threads) {
  parts.image.samples = samples / 2;
  parts.image.adaptive.reset();
  parts.render.seed = 0x51ED0000u;
  Film a = renderTimed(parts, threads).film;
  parts.render.seed = 0x51ED0001u;
  const Film b = renderTimed(parts, threads).film;
  const double variance = squaredError(a, b) / 4;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) a.at(x, y) = (a.at(x, y) + b.at(x, y)) / 2.0;
  }
  return {std::move(a), variance};
}

double correctedError(const Film& film, const Film& ref, double refVariance) {
  return std::sqrt(std::max(0.0, squaredError(film, ref) - refVariance));
}

SceneParts loadParts(const std::string& name, int width, int height) {
  SceneParts parts = loadScene(std::string(kScenesDir) + "/" + name).parts;
  parts.image.width = width;
  parts.image.height = height;
  parts.image.adaptive.reset();
  parts.render.integrator = Integrator::Path;
  return parts;
}

// The least-squares slope of ys against xs.
double leastSquaresSlope(const std::vector<double>& xs, const std::vector<double>& ys) {
  const double n = static_cast<double>(xs.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    sx += xs[i];
    sy += ys[i];
    sxx += xs[i] * xs[i];
    sxy += xs[i] * ys[i];
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void convergence(int width, int height, int threads, bool quick) {
  std::printf("1. Convergence, cornell-path.yaml at %dx%d\n", width, height);
  SceneParts parts = loadParts("cornell-path.yaml", width, height);
  const int referenceSpp = quick ? 1024 : 4096;
  const auto [ref, refVariance] = reference(parts, referenceSpp, threads);
  std::printf("   reference: %d spp, its noise RMS %.5f (subtracted)\n", referenceSpp,
              std::sqrt(refVariance));
  std::printf("   %6s %10s %12s %16s\n", "spp", "seconds", "RMS error", "independent RMS");
  // Two ladders: glint's renders at N spp (scrambled Sobol points, stratified across a pixel's
  // samples), and the mean of N/2 renders of 2 spp with seeds 1..N/2 (independent estimates: a
  // plain Monte Carlo mean, whose error must fall as N^-1/2 if the estimator is unbiased). Not
  // 1 spp: a single sample goes through the pixel centre (DESIGN.md §4), unjittered.
  std::vector<double> xs;
  std::vector<double> ys;
  std::vector<double> independentYs;
  SceneParts single = parts;
  single.image.samples = 2;
  std::vector<Color> sum(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  int summed = 0;
  for (int spp = 4; spp <= 256; spp *= 2) {
    parts.image.samples = spp;
    parts.render.seed = 0;
    const Rendered r = renderTimed(parts, threads);
    const double error = correctedError(r.film, ref, refVariance);
    for (; 2 * summed < spp; ++summed) {
      single.render.seed = static_cast<std::uint64_t>(summed) + 1;
      const Film one = renderTimed(single, threads).film;
      for (std::size_t i = 0; i < one.pixels().size(); ++i) sum[i] += one.pixels()[i];
    }
    Film mean(width, height, PixelRegion{0, 0, width, height});
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        mean.at(x, y) = sum[static_cast<std::size_t>(y) * width + x] / static_cast<double>(summed);
      }
    }
    const double independent = correctedError(mean, ref, refVariance);
    std::printf("   %6d %10.3f %12.5f %16.5f\n", spp, r.seconds, error, independent);
    xs.push_back(std::log(spp));
    ys.push_back(std::log(error));
    independentYs.push_back(std::log(independent));
  }
  std::printf(
      "   log-log slope of the error: %.3f (scrambled Sobol samples converge faster than "
      "independent ones)\n",
      leastSquaresSlope(xs, ys));
  std::printf("   log-log slope with independent samples: %.3f (1/sqrt(spp): -0.5)\n\n",
              leastSquaresSlope(xs, independentYs));
}

// A room corner lit by a small bright sphere (radius 0.05, radiance 4000) and a large dim panel
// (4 × 4, radiance 0.5), over a diffuse floor and wall and a glossy ball (Phong exponent 200):
// light sampling finds the small light, BRDF sampling the panel's reflection in the ball.
SceneParts twoLightScene(int width, int height) {
  SceneParts parts;
  parts.camera.position = {0, 1.5, 5};
  parts.camera.direction = normalize(Vec3{0, -0.25, -1});
  parts.camera.up = {0, 1, 0};
  parts.camera.viewPlaneHeight = 0.8;
  parts.camera.viewPlaneWidth = 0.8 * width / height;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = width;
  parts.image.height = height;
  parts.image.encoding = Encoding::Linear;
  parts.render.integrator = Integrator::Path;
  Material floor;
  floor.kd = Color(0.6);
  Material glossy;
  glossy.kd = Color(0.1, 0.2, 0.4);
  glossy.ks = Color(0.5);
  glossy.shininess = 200;
  Material dark;
  dark.kd = Color(0);
  dark.ka = Color(0);
  parts.materials = {Material{}, floor, glossy, dark};
  parts.primitives.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), 1u, Color{});
  parts.primitives.emplace_back(Plane::make({0, 0, -2}, {0, 0, 1}), 1u, Color{});
  parts.primitives.emplace_back(Sphere::make({0.6, 0.5, -0.5}, 0.5), 2u, Color{});
  // Both emitters above the camera's view: the errors are those of the light they cast.
  parts.primitives.emplace_back(Sphere::make({-1.2, 2.6, 0}, 0.05), 3u, Color(4000, 3600, 3000));
  parts.primitives.emplace_back(Rectangle::make({-2, 3, -2}, {4, 0, 0}, {0, 0, 4}), 3u,
                                Color(0.5, 0.55, 0.6));
  return parts;
}

void strategies(int width, int height, int threads, bool quick) {
  std::printf(
      "2. MIS against one strategy at equal time (small bright + large dim emitter, %dx%d)\n",
      width, height);
  SceneParts parts = twoLightScene(width, height);
  const auto [ref, refVariance] = reference(parts, quick ? 2048 : 8192, threads);
  const PathLightSampling kinds[] = {PathLightSampling::Mis, PathLightSampling::LightsOnly,
                                     PathLightSampling::BrdfOnly};
  const char* names[] = {"MIS (power heuristic)", "light sampling alone", "BRDF sampling alone"};
  // Seconds per sample of each strategy, measured at 16 spp, alternating.
  double perSample[3] = {0, 0, 0};
  parts.image.samples = 16;
  for (int run = 0; run < 2; ++run) {
    for (int k = 0; k < 3; ++k) {
      parts.render.lightSampling = kinds[k];
      const double t = renderTimed(parts, threads).seconds / 16;
      perSample[k] = run == 0 ? t : std::min(perSample[k], t);
    }
  }
  const double budget = perSample[0] * 64;
  std::printf("   time budget: %.3f s (MIS at 64 spp)\n", budget);
  std::printf("   %-24s %6s %10s %12s\n", "strategy", "spp", "seconds", "RMS error");
  for (int k = 0; k < 3; ++k) {
    parts.render.lightSampling = kinds[k];
    parts.image.samples = std::max(1, static_cast<int>(std::lround(budget / perSample[k])));
    parts.render.seed = 0;
    const Rendered r = renderTimed(parts, threads);
    std::printf("   %-24s %6d %10.3f %12.5f\n", names[k], parts.image.samples, r.seconds,
                correctedError(r.film, ref, refVariance));
  }
  std::printf("\n");
}

void throughput(int runs, bool quick) {
  std::printf("3. Throughput of path (Mrays/s: all rays / wall time, median of %d)\n", runs);
  std::printf("   %-22s %8s %8s %10s %10s\n", "scene", "threads", "spp", "Mrays", "Mrays/s");
  const int spp = quick ? 4 : 16;
  for (const char* name : {"cornell-path.yaml", "showcase.yaml"}) {
    SceneParts parts = loadParts(name, 320, std::string(name) == "showcase.yaml" ? 180 : 320);
    parts.image.samples = spp;
    for (const int threads : {1, 2}) {
      std::vector<double> rates;
      double rays = 0;
      for (int run = 0; run < runs; ++run) {
        const Rendered r = renderTimed(parts, threads);
        rays = r.rays;
        rates.push_back(r.rays / r.seconds / 1e6);
      }
      std::sort(rates.begin(), rates.end());
      std::printf("   %-22s %8d %8d %10.1f %10.2f\n", name, threads, spp, rays / 1e6,
                  rates[rates.size() / 2]);
    }
  }
  std::printf(
      "   memory: the film holds %zu B per pixel (linear RGB doubles); a path needs one Hit (%zu "
      "B) "
      "and its shading state on the worker's stack, nothing on the heap\n",
      sizeof(Color), sizeof(Hit));
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) {
  using namespace glint::bench;
  const std::string usage =
      "usage: path_tracing [--runs N] [--quick] [--size WxH] [--threads T] "
      "[--only convergence|strategies|throughput]\n";
  std::vector<ExtraOption> extra{ExtraOption("--size"), ExtraOption("--threads"),
                                 ExtraOption("--only")};
  const CommonOptions common = parseCommonOptions(argc, argv, usage, &extra);
  int width = 96;
  int height = 96;
  if (extra[0].present && std::sscanf(extra[0].value.c_str(), "%dx%d", &width, &height) != 2) {
    std::fprintf(stderr, "path_tracing: --size takes WxH\n%s", usage.c_str());
    return 2;
  }
  const int threads = extra[1].present ? std::atoi(extra[1].value.c_str()) : 0;
  printHeader("Path tracing: convergence, MIS, throughput", common);
  const std::string only = extra[2].present ? extra[2].value : std::string();
  if (!only.empty() && only != "convergence" && only != "strategies" && only != "throughput") {
    std::fprintf(stderr, "path_tracing: --only takes convergence, strategies or throughput\n%s",
                 usage.c_str());
    return 2;
  }
  if (only.empty() || only == "convergence") convergence(width, height, threads, common.quick);
  if (only.empty() || only == "strategies") strategies(width, height, threads, common.quick);
  if (only.empty() || only == "throughput") {
    throughput(common.quick ? 1 : std::max(1, common.runs), common.quick);
  }
  return 0;
}
