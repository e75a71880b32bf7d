#include "glint/job/scene_overrides.h"

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

void applyOverrides(SceneParts& parts, const SceneOverrides& overrides) {
  const ImageSize size = resizeKeepingAspect({parts.image.width, parts.image.height},
                                             overrides.width, overrides.height);
  parts.image.width = size.width;
  parts.image.height = size.height;
  if (overrides.samples) parts.image.samples = *overrides.samples;
  if (overrides.seed) parts.render.seed = *overrides.seed;
}

}  // namespace glint
