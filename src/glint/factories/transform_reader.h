// An object's `transform` (DESIGN.md §5): a list of steps {translate}, {scale}, {rotate: {axis,
// angle}} applied in file order, read and composed into worldFromObject.
#pragma once

#include <optional>
#include <string>

#include "glint/core/transform.h"
#include "glint/readers/parameter_dictionary.h"

namespace glint {

struct TransformResult {
  std::optional<Transform> worldFromObject;  // absent: no transform, or the identity
  bool ok = true;                            // false when a step was wrong (reported)
};

// Reads `transform` of an object of type `owner` ("sphere": messages say "sphere.transform[0]").
TransformResult readTransform(ParameterDictionary& params, const std::string& owner);

}  // namespace glint
