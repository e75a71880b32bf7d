// The Whitted/Phong renderer of DESIGN.md §3 (the seed's Render) with distributed ray tracing
// (anti-aliasing, adaptive sampling, area lights, depth of field, glossy lobes): tiles over a
// oneTBB pool, sample points from core/sampler.h keyed by (pixel, sample, dimension, seed), so any
// thread count or crop gives the same bytes.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/rng.h"
#include "glint/render/film.h"
#include "glint/scene/scene.h"

namespace glint {

// Rays traced, by kind.
struct RayCounts {
  std::uint64_t camera = 0;
  std::uint64_t shadow = 0;
  std::uint64_t reflection = 0;
  std::uint64_t refraction = 0;
  std::uint64_t indirect = 0;  // path integrator: the diffuse and glossy bounces
  std::uint64_t total() const { return camera + shadow + reflection + refraction + indirect; }
};

// A pixel in full-image coordinates (row 0 at the top).
struct PixelCoord {
  int x = 0, y = 0;
  friend bool operator==(const PixelCoord&, const PixelCoord&) = default;
};

struct RenderStats {
  RayCounts rays;  // every ray traced (adaptive sampling also recomputes neighbours' first
                   // batches, whose camera rays count here but not in `samples`)
  std::uint64_t samples = 0;    // camera samples that went into the rendered pixels
  double seconds = 0;           // wall-clock time of the render
  std::uint64_t nonFinite = 0;  // samples that came out NaN/inf and were replaced by black
  // Where the first non-finite sample arose: the smallest row, then column, among the pixels that
  // had one (so the same on any thread count).
  std::optional<PixelCoord> firstNonFinite;
  std::size_t tilesResumed = 0;  // tiles copied from RenderOptions::resumeFilm, not rendered
  bool cancelled = false;
};

struct RenderOptions {
  int threads = 0;                  // 0 = all cores
  std::optional<PixelRegion> crop;  // default: the whole image
  int tileSize = 16;                // pixels per tile side
  // Polled before every pixel sample; when set, render stops within one sample per thread (one
  // camera path with its shadow, glossy and area-light rays). A tile left unfinished is neither
  // reported to tileFinished nor to progress.
  const std::atomic<bool>* cancel = nullptr;
  // Called (from worker threads, serialised by the renderer) after each finished tile with
  // (tiles done, tiles total).
  std::function<void(std::size_t, std::size_t)> progress;
  // Called (serialised with `progress`, from the worker that finished the tile) after each rendered
  // tile with its index in tileRegions(region, tileSize), the film, whose pixels inside that tile
  // are final (no grid overlay yet), and the MPI rank that rendered it (−1: this process, outside
  // MPI; the cluster's render step passes each tile's rank). Checkpointing hooks here.
  std::function<void(std::size_t tile, const Film& film, int rank)> tileFinished;
  // Resume: when both are set, every tile i with (*resumeTiles)[i] true is copied from *resumeFilm
  // (which must cover the same region) instead of rendered. Same scene and options as the earlier
  // run give the same bytes as an uninterrupted render.
  const Film* resumeFilm = nullptr;
  const std::vector<bool>* resumeTiles = nullptr;
  // Render only these tiles (indices in tileRegions(region, tileSize), each at most once), taken
  // roughly in this order; the others are neither rendered nor reported. Unset: every tile.
  std::optional<std::vector<std::size_t>> tiles;
  // A feed of tiles instead: every render thread asks it for its next tile when it is free, until
  // it returns std::nullopt; it may block until one is known (another process hands them out).
  // Called concurrently from the render threads. Takes precedence over `tiles`. When a thread's
  // tile throws, render returns (and rethrows) only once the feed has ended for every thread.
  std::function<std::optional<std::size_t>()> nextTile;
};

// Samples per pixel a render takes: every pixel takes `minimum`; with adaptive sampling a pixel
// may take up to `maximum`, otherwise both are image.samples. Adaptive sampling starts with at
// least 4 samples (fewer give no estimate of a pixel's error), capped at its maximum.
struct SamplesPerPixel {
  int minimum = 1;
  int maximum = 1;
};
SamplesPerPixel samplesPerPixel(const ImageSettings& image);

// An upper estimate of the rays one pixel may trace, to warn before a render that cannot finish:
// samples × hitsPerSample × (1 + shadowRaysPerHit + glossyRaysPerHit). Rough on purpose: glossy
// and area-light budgets shrink below a glossy split, and weights fall faster than the strongest
// coefficient suggests.
struct PixelWork {
  std::uint64_t samples = 1;           // the most samples a pixel may take
  int depth = 1;                       // surface hits along one path (max_depth, cut by min_weight)
  double hitsPerSample = 1;            // depth, or 2^depth − 1 when some material both reflects
                                       // and transmits (every such hit forks the path)
  std::uint64_t shadowRaysPerHit = 0;  // one per light, `samples` per area light, the
                                       // ambient occlusion rays, the path integrator's
                                       // next-event rays
  std::uint64_t glossyRaysPerHit = 0;  // blur_samples when some material is glossy, else 0
  double raysPerPixel() const {
    return static_cast<double>(samples) * hitsPerSample *
           (1 + static_cast<double>(shadowRaysPerHit) + static_cast<double>(glossyRaysPerHit));
  }
};
// `pathLightRays`: the path integrator's next-event rays at each hit besides the lights' — one
// toward the emissive objects and one toward an image sky, where the scene has them.
PixelWork estimatePixelWork(const ImageSettings& image, const RenderSettings& render,
                            const std::vector<Light>& lights,
                            const std::vector<Material>& materials, int pathLightRays = 0);

// The tiles a render of `region` is cut into, in the order render() numbers them: row-major from
// the region's top-left corner, tileSize × tileSize pixels, clipped at the right and bottom edges.
std::vector<PixelRegion> tileRegions(const PixelRegion& region, int tileSize);

// Renders the scene (or its crop region) and applies the grid overlay. When cancelled, returns the
// partial film with stats.cancelled = true.
Film render(const Scene& scene, const RenderOptions& options = {}, RenderStats* stats = nullptr);

// render() into the caller's film, which must cover the rendered region of this image: the pixels
// of tiles it does not render stay as they are, and the caller may fill those (another process's
// tiles) while it runs. The grid overlay is painted over the whole film when it returns.
void renderInto(const Scene& scene, const RenderOptions& options, Film& film,
                RenderStats* stats = nullptr);

// Color seen along one ray (the seed's calcColor with recursion), for tests and tools. One value
// of `rng` keys the sample stream (core/sampler.h, sequence index 0) of its glossy lobes and
// area-light points.
Color traceRay(const Scene& scene, const Ray& ray, Rng& rng, RayCounts* counts = nullptr);

}  // namespace glint
