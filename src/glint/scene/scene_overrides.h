// Overrides of a loaded scene's image and render settings by its caller (the command line's
// --width/--height/--samples/--seed, DESIGN.md §6, and --integrator), applied to SceneParts before
// the Scene is built.
#pragma once

#include <cstdint>
#include <optional>

#include "glint/scene/scene.h"

namespace glint {

struct ImageSize {
  int width = 1;  // pixels
  int height = 1;
  friend bool operator==(const ImageSize&, const ImageSize&) = default;
};

struct SceneOverrides {
  std::optional<int> width;    // pixels; given alone, the height follows the scene's aspect ratio
  std::optional<int> height;   // pixels; given alone, the width follows the scene's aspect ratio
  std::optional<int> samples;  // per pixel
  std::optional<std::uint64_t> seed;     // replaces render.seed
  std::optional<Integrator> integrator;  // replaces render.integrator (--integrator)
};

// The image size after a requested width and/or height. One side alone keeps the aspect ratio of
// `current`: the other side is round(requested · other / side), half away from zero, at least 1,
// saturated at INT_MAX (so a huge request stays huge and the image limits refuse it). Both sides
// given: taken as they are. Neither: `current`. Requested sides must be ≥ 1 (callers check).
ImageSize resizeKeepingAspect(const ImageSize& current, std::optional<int> width,
                              std::optional<int> height);

// Applies the size and samples overrides to `image`; an adaptive maximum below the samples rises
// to them.
void applyImageOverrides(ImageSettings& image, const SceneOverrides& overrides);

// Applies the seed and integrator overrides to `render`.
void applyRenderOverrides(RenderSettings& render, const SceneOverrides& overrides);

// Applies the overrides to parts.image and parts.render. Values are not range-checked here: the
// caller re-runs the scene's image limits afterwards.
void applyOverrides(SceneParts& parts, const SceneOverrides& overrides);

}  // namespace glint
