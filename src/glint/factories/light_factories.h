// The light family (DESIGN.md §3, §5): one factory per light `type` — directional, point, spot,
// area — in one table. An area light reads its surface with the factory of the object of that shape
// (the same keys, ranges and messages).
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "glint/factories/build_context.h"
#include "glint/readers/parameter_dictionary.h"
#include "glint/scene/light.h"

namespace glint {

struct LightFactory {
  std::string_view type;
  // Its keys, in the order messages list them.
  std::vector<std::string_view> keys;
  // Reads the keys; nullopt when one is missing or wrong (reported).
  // May throw ShapeError (an area light's degenerate surface), naming the parameter at fault.
  std::optional<Light> (*read)(ParameterDictionary& params, BuildContext& ctx) = nullptr;
};

const std::vector<LightFactory>& lightFactories();
const LightFactory* findLightFactory(std::string_view type);

}  // namespace glint
