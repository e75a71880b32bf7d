// The Whitted/Phong integrator of DESIGN.md §3 and the tile scheduler that drives it.
#include "glint/render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <variant>

#include "glint/core/sampling.h"
#include "glint/core/spawn.h"

namespace glint {
namespace {

// Per-sample state shared by every ray of one camera path tree. Lives on the stack of the pixel
// loop; nothing here allocates.
struct TraceContext {
  const Scene& scene;
  Rng& rng;
  RayCounts& counts;
  int maxDepth;
  double minWeight;
  std::uint32_t blurSamples;
};

enum class SecondaryKind { Reflection, Refraction };

Color trace(const TraceContext& ctx, const Ray& ray, int depth, const Color& weight, bool split);

// The position of a point or spot light; false for a directional light (at infinity).
bool lightPosition(const Light& light, Point3& position) {
  if (const auto* point = std::get_if<PointLight>(&light)) {
    position = point->position;
    return true;
  }
  if (const auto* spot = std::get_if<SpotLight>(&light)) {
    position = spot->position;
    return true;
  }
  return false;
}

// Direct lighting (DESIGN.md §3), n the geometric normal, v the unit view direction:
//   Σ_lights [(n·l)(n·v) > 0] · T_L(P) · I_L(P) · (kd·|ns·l| + ks·max(0, −v·r)^shininess),
// with the shading normal ns (= n except on smooth meshes) in the diffuse term and in r. The side
// tests and the shadow ray's origin use the geometric n; a light on the other side of ns than of n
// gives no diffuse term.
Color directLight(const TraceContext& ctx, const Material& material, const Point3& p,
                  const Normal3& n, const Normal3& ns, const Vec3& v) {
  Color sum;
  // Nothing for a light to act on: skip the shadow rays too.
  const bool hasSpecular = !isBlack(material.ks);
  if (isBlack(material.kd) && !hasSpecular) return sum;
  const double nv = dot(n, v);
  for (const Light& light : ctx.scene.lights()) {
    const LightSample sample = illuminate(light, p);
    if (isBlack(sample.intensity)) continue;
    const Vec3& l = sample.toPoint;
    const double nl = dot(n, l);
    // The light and the eye must be on the same side of the surface.
    if (!(nl * nv > 0)) continue;

    const Ray shadowRay = spawnRay(p, n, -l);
    Point3 position;
    const double tMax =
        lightPosition(light, position) ? distance(shadowRay.origin, position) : kInfinity;
    ++ctx.counts.shadow;
    const Color transmittance = ctx.scene.transmittance(shadowRay, tMax);
    if (isBlack(transmittance)) continue;

    const double nsl = dot(ns, l);
    Color response = nsl * nl > 0 ? material.kd * std::abs(nsl) : Color();
    if (hasSpecular) {
      const Vec3 r = l - toVec(ns) * (2 * nsl);  // the light's mirror direction about ns
      response += material.ks * std::pow(std::max(0.0, -dot(v, r)), material.shininess);
    }
    sum += transmittance * sample.intensity * response;
  }
  return sum;
}

// Traces one secondary lobe (reflection or transmission) around the unit direction `ideal` leaving
// P, scaled by nothing (the caller multiplies by kr/kt). With blurDegrees > 0 the seed's
// "microfacets": rays spread uniformly over the cone of that half-angle around `ideal`, those that
// would go through the surface to the other side than `ideal` dropped, the rest averaged.
//
// Ray budget ("per-hit ray count falls with depth"): the first glossy lobe on a path traces
// blurSamples stratified rays; every ray below it is marked `split`, and a split path uses a single
// jittered cone ray at later glossy bounces. So a path tree holds at most blurSamples rays per
// glossy lobe of its first glossy hit instead of blurSamples^depth.
Color traceLobe(const TraceContext& ctx, const Point3& p, const Normal3& n, const Vec3& ideal,
                double blurDegrees, SecondaryKind kind, int depth, const Color& weight,
                bool split) {
  std::uint64_t& counter =
      kind == SecondaryKind::Reflection ? ctx.counts.reflection : ctx.counts.refraction;
  if (!(blurDegrees > 0)) {
    ++counter;
    return trace(ctx, spawnRay(p, n, ideal), depth, weight, split);
  }
  const double cosMax = std::cos(std::min(blurDegrees, 180.0) * std::numbers::pi / 180.0);
  const double idealSide = dot(n, ideal);
  const std::uint32_t count = split ? 1u : std::max<std::uint32_t>(ctx.blurSamples, 1u);
  const bool childSplit = split || count > 1;
  // One scramble per lobe decorrelates the radical-inverse dimension between lobes and pixels.
  const auto scramble = static_cast<std::uint32_t>(ctx.rng.nextBits() >> 32);
  Color sum;
  std::uint32_t kept = 0;
  for (std::uint32_t k = 0; k < count; ++k) {
    const double jitterX = ctx.rng.uniform();
    const double jitterY = ctx.rng.uniform();
    const Vec3 w = sampleCone(ideal, cosMax, stratified2D(k, count, jitterX, jitterY, scramble));
    // Keep only directions that leave on the same side of the surface as the ideal one.
    if (!(dot(n, w) * idealSide > 0)) continue;
    ++counter;
    sum += trace(ctx, spawnRay(p, n, w), depth, weight, childSplit);
    ++kept;
  }
  if (kept == 0) {
    ++counter;
    return trace(ctx, spawnRay(p, n, ideal), depth, weight, childSplit);
  }
  return sum / static_cast<double>(kept);
}

// True when a branch scaled by `factor` on top of `weight` is still worth tracing.
bool worthTracing(const Color& factor, const Color& weight, double minWeight, Color& newWeight) {
  if (isBlack(factor)) return false;
  newWeight = weight * factor;
  return maxComponent(newWeight) >= minWeight;
}

// The seed's calcColor with recursion. `depth` counts the surface hits already on this path
// (0 for a camera ray), `weight` the product of kr/kt factors that scale this ray's contribution,
// `split` whether the path has already fanned out into several glossy rays.
Color trace(const TraceContext& ctx, const Ray& ray, int depth, const Color& weight, bool split) {
  Hit hit;
  if (!ctx.scene.intersect(ray, kInfinity, hit)) return ctx.scene.background();
  const int hitDepth = depth + 1;

  const Material& material = ctx.scene.materialOf(hit);
  const Point3 p = ray.at(hit.t);
  const Normal3& n = hit.normal;  // geometric: side decisions and ray origins
  const Vec3& v = ray.direction;  // unit for every ray the renderer creates
  const double nv = dot(n, v);
  // Shading normal: directions and the diffuse/specular terms. One facing the other way from the
  // geometric normal as seen along v would shade a back face; the geometric one is used then.
  const Normal3& ns = dot(hit.shadingNormal, v) * nv > 0 ? hit.shadingNormal : n;
  const double nsv = dot(ns, v);

  Color color = ctx.scene.emissionOf(hit) + material.ka * ctx.scene.ambient();
  color += directLight(ctx, material, p, n, ns, v);
  if (hitDepth >= ctx.maxDepth) return color;

  // A mirror direction about ns that would dive below the geometric surface is replaced by the
  // geometric mirror direction (it can only happen where ns ≠ n).
  const bool smooth = !(ns == n);
  Vec3 reflected = v - toVec(ns) * (2 * nsv);
  if (smooth && !(dot(n, reflected) * nv < 0)) reflected = v - toVec(n) * (2 * nv);
  Color branchWeight;
  if (worthTracing(material.kr, weight, ctx.minWeight, branchWeight)) {
    color += material.kr * traceLobe(ctx, p, n, reflected, material.reflectionBlur,
                                     SecondaryKind::Reflection, hitDepth, branchWeight, split);
  }
  if (worthTracing(material.kt, weight, ctx.minWeight, branchWeight)) {
    Vec3 transmitted = v;
    if (material.ior != 1) {
      // Snell's law with the relative index; n·v < 0 means the ray enters the surface.
      const bool entering = nv < 0;
      const double eta = entering ? 1 / material.ior : material.ior;
      const Vec3 facing = entering ? toVec(ns) : -toVec(ns);  // normal on the incident side
      const double cosIncident = -dot(facing, v);
      const double sin2Transmitted = eta * eta * std::max(0.0, 1 - cosIncident * cosIncident);
      if (sin2Transmitted >= 1) {
        transmitted = reflected;  // total internal reflection: kt's energy follows the mirror ray
      } else {
        const double cosTransmitted = std::sqrt(1 - sin2Transmitted);
        transmitted = v * eta + facing * (eta * cosIncident - cosTransmitted);
        // Bent about ns, it must still cross the geometric surface; otherwise go straight on.
        if (smooth && !(dot(n, transmitted) * nv > 0)) transmitted = v;
      }
    }
    color += material.kt * traceLobe(ctx, p, n, transmitted, material.refractionBlur,
                                     SecondaryKind::Refraction, hitDepth, branchWeight, split);
  }
  return color;
}

// Shading assumes a unit view direction. Camera rays are unit already up to rounding; normalising
// here anyway keeps render() and traceRay() bit-identical for the same ray.
Color traceCameraRay(const TraceContext& ctx, const Ray& ray) {
  ++ctx.counts.camera;
  return trace(ctx, Ray{ray.origin, normalize(ray.direction)}, 0, Color(1), false);
}

TraceContext makeContext(const Scene& scene, Rng& rng, RayCounts& counts) {
  const RenderSettings& settings = scene.render();
  return TraceContext{scene,
                      rng,
                      counts,
                      settings.maxDepth,
                      settings.minWeight,
                      static_cast<std::uint32_t>(std::max(settings.blurSamples, 1))};
}

PixelRegion validatedRegion(const Scene& scene, const RenderOptions& options) {
  const int width = scene.image().width;
  const int height = scene.image().height;
  if (!options.crop) return PixelRegion{0, 0, width, height};
  const PixelRegion& c = *options.crop;
  if (c.x0 < 0 || c.y0 < 0 || c.x1 > width || c.y1 > height || c.x0 >= c.x1 || c.y0 >= c.y1) {
    throw std::invalid_argument("crop region [" + std::to_string(c.x0) + ", " +
                                std::to_string(c.y0) + ") – [" + std::to_string(c.x1) + ", " +
                                std::to_string(c.y1) + ") must be non-empty and inside the " +
                                std::to_string(width) + "×" + std::to_string(height) + " image");
  }
  return c;
}

// Paints the seed's printGrid over the film: pixels whose absolute column or row is a multiple of
// the interval, so a cropped render shows the same grid lines as the full image.
void paintGrid(Film& film, const GridOverlay& grid) {
  if (grid.interval <= 0) return;
  const PixelRegion& region = film.region();
  for (int y = region.y0; y < region.y1; ++y) {
    for (int x = region.x0; x < region.x1; ++x) {
      if (x % grid.interval == 0 || y % grid.interval == 0) {
        film.at(x - region.x0, y - region.y0) = grid.color;
      }
    }
  }
}

// A well-distributed but fixed scramble for the pixel's stratified pattern, independent of the
// per-sample streams (sample index 0xffffffff is never a real sample).
std::uint32_t pixelScramble(int column, int row, std::uint64_t seed) {
  Rng rng = Rng::forPixelSample(static_cast<std::uint32_t>(column), static_cast<std::uint32_t>(row),
                                0xffffffffu, seed);
  return static_cast<std::uint32_t>(rng.nextBits() >> 32);
}

}  // namespace

Color traceRay(const Scene& scene, const Ray& ray, Rng& rng, RayCounts* counts) {
  RayCounts local;
  RayCounts& target = counts ? *counts : local;
  const TraceContext ctx = makeContext(scene, rng, target);
  return traceCameraRay(ctx, ray);
}

std::vector<PixelRegion> tileRegions(const PixelRegion& region, int tileSize) {
  if (tileSize <= 0) throw std::invalid_argument("tile size must be > 0");
  std::vector<PixelRegion> tiles;
  for (int y0 = region.y0; y0 < region.y1; y0 += tileSize) {
    for (int x0 = region.x0; x0 < region.x1; x0 += tileSize) {
      tiles.push_back(PixelRegion{x0, y0, std::min(x0 + tileSize, region.x1),
                                  std::min(y0 + tileSize, region.y1)});
    }
  }
  return tiles;
}

Film render(const Scene& scene, const RenderOptions& options, RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const PixelRegion region = validatedRegion(scene, options);
  if (options.threads < 0) throw std::invalid_argument("thread count must be ≥ 0");
  const std::vector<PixelRegion> tiles = tileRegions(region, options.tileSize);
  const std::size_t tileCount = tiles.size();
  const bool resuming = options.resumeFilm != nullptr && options.resumeTiles != nullptr;
  if (resuming && (options.resumeFilm->region() != region ||
                   options.resumeFilm->fullWidth() != scene.image().width ||
                   options.resumeFilm->fullHeight() != scene.image().height ||
                   options.resumeTiles->size() != tileCount)) {
    throw std::invalid_argument("the film to resume from covers a different image or region");
  }

  const ImageSettings& image = scene.image();
  Film film(image.width, image.height, region);
  const Camera& camera = scene.camera();
  const int samples = std::max(image.samples, 1);
  const auto sampleCount = static_cast<std::uint32_t>(samples);
  const std::uint64_t seed = scene.render().seed;

  std::atomic<std::uint64_t> cameraRays{0}, shadowRays{0}, reflectionRays{0}, refractionRays{0};
  std::atomic<std::uint64_t> nonFinite{0};
  std::atomic<bool> cancelled{false};
  std::mutex progressMutex;  // guards tilesDone, firstNonFinite and the callbacks
  std::size_t tilesDone = 0;
  std::size_t tilesResumed = 0;
  std::optional<PixelCoord> firstNonFinite;
  const auto before = [](const PixelCoord& a, const PixelCoord& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  };

  if (resuming) {
    for (std::size_t tile = 0; tile < tileCount; ++tile) {
      if (!(*options.resumeTiles)[tile]) continue;
      const PixelRegion& t = tiles[tile];
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) {
          film.at(x - region.x0, y - region.y0) =
              options.resumeFilm->at(x - region.x0, y - region.y0);
        }
      }
      ++tilesResumed;
    }
    tilesDone = tilesResumed;
  }

  auto renderTile = [&](std::size_t tile) {
    if (resuming && (*options.resumeTiles)[tile]) return;
    if (cancelled.load(std::memory_order_relaxed)) return;
    if (options.cancel && options.cancel->load()) {
      cancelled.store(true);
      return;
    }
    const int x0 = tiles[tile].x0;
    const int y0 = tiles[tile].y0;
    const int x1 = tiles[tile].x1;
    const int y1 = tiles[tile].y1;
    RayCounts counts;
    std::uint64_t tileNonFinite = 0;
    std::optional<PixelCoord> tileFirstNonFinite;
    for (int row = y0; row < y1; ++row) {
      for (int column = x0; column < x1; ++column) {
        const std::uint32_t scramble = samples > 1 ? pixelScramble(column, row, seed) : 0;
        Color sum;
        for (std::uint32_t s = 0; s < sampleCount; ++s) {
          Rng rng = Rng::forPixelSample(static_cast<std::uint32_t>(column),
                                        static_cast<std::uint32_t>(row), s, seed);
          Point2 offset{0.5, 0.5};
          if (sampleCount > 1) {
            const double jitterX = rng.uniform();
            const double jitterY = rng.uniform();
            offset = stratified2D(s, sampleCount, jitterX, jitterY, scramble);
          }
          // The lens sample is always drawn (a pinhole camera ignores it), so the glossy stream
          // that follows does not depend on the camera model.
          const double lensX = rng.uniform();
          const double lensY = rng.uniform();
          const Ray ray = camera.generateRay(column, row, offset, Point2{lensX, lensY});
          const TraceContext ctx = makeContext(scene, rng, counts);
          Color value = traceCameraRay(ctx, ray);
          if (!isFinite(value)) {
            value = Color{};
            if (tileNonFinite++ == 0) tileFirstNonFinite = PixelCoord{column, row};
          }
          sum += value;
        }
        film.at(column - region.x0, row - region.y0) = sum / static_cast<double>(sampleCount);
      }
    }
    cameraRays += counts.camera;
    shadowRays += counts.shadow;
    reflectionRays += counts.reflection;
    refractionRays += counts.refraction;
    nonFinite += tileNonFinite;
    const std::lock_guard<std::mutex> lock(progressMutex);
    if (tileFirstNonFinite && (!firstNonFinite || before(*tileFirstNonFinite, *firstNonFinite))) {
      firstNonFinite = tileFirstNonFinite;
    }
    ++tilesDone;
    if (options.tileFinished) options.tileFinished(tile, film);
    if (options.progress) options.progress(tilesDone, tileCount);
  };

  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tileCount, 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t tile = range.begin(); tile != range.end(); ++tile) {
                          renderTile(tile);
                        }
                      });
  });

  if (image.grid) paintGrid(film, *image.grid);

  if (stats) {
    stats->rays.camera = cameraRays.load();
    stats->rays.shadow = shadowRays.load();
    stats->rays.reflection = reflectionRays.load();
    stats->rays.refraction = refractionRays.load();
    stats->nonFinite = nonFinite.load();
    stats->firstNonFinite = firstNonFinite;
    stats->tilesResumed = tilesResumed;
    stats->cancelled = cancelled.load();
    stats->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return film;
}

}  // namespace glint
