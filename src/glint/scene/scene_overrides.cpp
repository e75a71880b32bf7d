#include "glint/scene/scene_overrides.h"

#include <algorithm>
#include <limits>

namespace glint {
namespace {

// round(requested · numerator / denominator) half away from zero, in 64-bit integers so the result
// is exact (no floating-point tie errors) and cannot overflow for int inputs; clamped to [1,
// INT_MAX].
int scaledSide(int requested, int numerator, int denominator) {
  const std::int64_t num = std::int64_t{requested} * numerator;
  const std::int64_t den = std::max(denominator, 1);
  const std::int64_t rounded = (2 * num + den) / (2 * den);
  return static_cast<int>(std::clamp<std::int64_t>(rounded, 1, std::numeric_limits<int>::max()));
}

}  // namespace

ImageSize resizeKeepingAspect(const ImageSize& current, std::optional<int> width,
                              std::optional<int> height) {
  if (width && height) return {*width, *height};
  if (width) return {*width, scaledSide(*width, current.height, current.width)};
  if (height) return {scaledSide(*height, current.width, current.height), *height};
  return current;
}

void applyImageOverrides(ImageSettings& image, const SceneOverrides& overrides) {
  const ImageSize size =
      resizeKeepingAspect({image.width, image.height}, overrides.width, overrides.height);
  image.width = size.width;
  image.height = size.height;
  if (overrides.samples) image.samples = *overrides.samples;
  // With adaptive sampling the samples are the minimum per pixel; a maximum below it rises to it,
  // so --samples N always means "at least N samples".
  if (image.adaptive && image.adaptive->maxSamples < image.samples)
    image.adaptive->maxSamples = image.samples;
}

void applyRenderOverrides(RenderSettings& render, const SceneOverrides& overrides) {
  if (overrides.seed) render.seed = *overrides.seed;
  if (overrides.integrator) render.integrator = *overrides.integrator;
}

void applyOverrides(SceneParts& parts, const SceneOverrides& overrides) {
  applyImageOverrides(parts.image, overrides);
  applyRenderOverrides(parts.render, overrides);
}

}  // namespace glint
