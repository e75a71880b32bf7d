// `glint check` in the library: load and build a scene, and the facts about it that the check and
// the render summary print (counts, bounds, the true samples per pixel), plus the warning for a
// pixel whose work is absurd.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "glint/core/bounds.h"
#include "glint/readers/diagnostics.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#include "glint/scene/scene_overrides.h"

namespace glint {

struct SceneFacts {
  std::string name;                  // the scene's `name`, empty when it has none
  ImageSettings image;               // after overrides
  SamplesPerPixel samplesPerPixel;   // what the renderer really takes (adaptive: at least 4)
  std::size_t objects = 0;           // primitives (mesh objects count as their triangles' owner)
  std::size_t unboundedObjects = 0;  // planes and tubes, outside the BVH
  std::size_t meshes = 0;
  std::uint64_t triangles = 0;
  std::size_t instances = 0;         // `type: instance` objects placed (DESIGN.md §11)
  std::size_t groups = 0;            // groups they place, as built (one per distinct kt)
  std::uint64_t groupTriangles = 0;  // mesh triangles in those groups, each counted once
  std::size_t lights = 0;            // light sources
  std::size_t areaLights = 0;        // of which area lights (soft shadows)
  bool ambient = false;              // whether the scene has ambient light
  std::size_t materials = 0;         // defined by the scene (the built-in default not counted)
  Bounds3 bounds;                    // of the bounded objects; empty when there are none
  int maxDepth = 0;                  // render.max_depth
  std::uint64_t seed = 0;            // render.seed
  Integrator integrator = Integrator::Whitted;  // render.integrator, after --integrator
  Isa isa = Isa::Baseline;  // the instruction set the BVH queries run with (core/isa.h)
};

SceneFacts sceneFacts(const Scene& scene);

// One pixel tracing more than this many rays (estimatePixelWork) is worth a warning: at a few
// million rays per second per core it takes seconds for a single pixel.
inline constexpr double kAbsurdRaysPerPixel = 1e7;

// "FILE: warning: one pixel may trace about 4.3 billion rays (...)" naming the factors, when the
// estimate passes kAbsurdRaysPerPixel; std::nullopt otherwise.
std::optional<Diagnostic> pixelWorkWarning(const std::string& file, const SceneParts& parts);

struct CheckOptions {
  std::uint64_t memoryBudget = defaultImageMemoryBudget();  // as LoadOptions::memoryBudget
  // The render command's --width/--height/--samples/--seed/--integrator, applied as a render
  // applies them, so that check reports what that render would; requestText names them in a
  // refusal of the image (as RenderJobSpec::requestText).
  SceneOverrides overrides{};
  std::string requestText;
  // Polled while loading (factories/scene_loader.h); when set the check throws Cancelled.
  const std::atomic<bool>* cancel = nullptr;
  // Hears the scene's warnings (the loader's, then pixelWorkWarning's) as soon as it is loaded,
  // before anything can fail later.
  std::function<void(const std::vector<Diagnostic>&)> warnings;
};

// Loads and builds the scene file as a render would (same errors, same limits), writes nothing,
// and returns its facts. Throws JobError (job/job_error.h).
SceneFacts checkScene(const std::filesystem::path& file, const CheckOptions& options = {});

}  // namespace glint
