// The Whitted/Phong renderer of DESIGN.md §3 (the seed's Render): tiles over a oneTBB pool, one
// deterministic random stream per (pixel, sample, seed), so any thread count gives the same bytes.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>

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
  std::uint64_t total() const { return camera + shadow + reflection + refraction; }
};

struct RenderStats {
  RayCounts rays;
  double seconds = 0;           // wall-clock time of the render
  std::uint64_t nonFinite = 0;  // samples that came out NaN/inf and were replaced by black
  bool cancelled = false;
};

struct RenderOptions {
  int threads = 0;                            // 0 = all cores
  std::optional<PixelRegion> crop;            // default: the whole image
  int tileSize = 16;                          // pixels per tile side
  const std::atomic<bool>* cancel = nullptr;  // polled between tiles; when set, render stops
  // Called (from worker threads, serialised by the renderer) after each finished tile with
  // (tiles done, tiles total).
  std::function<void(std::size_t, std::size_t)> progress;
};

// Renders the scene (or its crop region) and applies the grid overlay. When cancelled, returns the
// partial film with stats.cancelled = true.
Film render(const Scene& scene, const RenderOptions& options = {}, RenderStats* stats = nullptr);

// Color seen along one ray (the seed's calcColor with recursion), for tests and tools.
// `rng` supplies glossy sampling; depth counts surface hits already on this path.
Color traceRay(const Scene& scene, const Ray& ray, Rng& rng, RayCounts* counts = nullptr);

}  // namespace glint
