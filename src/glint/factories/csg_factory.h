// The `csg` object (DESIGN.md §11): its `operation` and `operands`, each operand an object of a
// closed type (sphere, box, cylinder, mesh, csg) with its own material, emission and transform,
// read into a Csg shape (geometry/csg.h). The object's own material, emission and transform are
// read by the scene builder like every object's.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "glint/core/color.h"
#include "glint/factories/object_factories.h"
#include "glint/geometry/csg.h"
#include "glint/readers/parameter_dictionary.h"
#include "glint/scene/scene.h"

namespace glint {

// What the scene builder lends the csg factory for an operand's shared keys.
struct CsgServices {
  // The material an operand's `material` key names (or defines inline), with the material's
  // `emission` if it has one; nullopt without the key; errors reported. owner: the operand's path
  // ("csg.operands[1]").
  struct OperandMaterial {
    std::uint32_t index = 0;
    std::optional<Color> emission;
  };
  std::function<std::optional<OperandMaterial>(ParameterDictionary&, const std::string& owner)>
      material;
  // A mesh operand's contents (its file through the scene's mesh cache, or its inline arrays);
  // null after an error (reported).
  std::function<std::shared_ptr<const MeshFile>(ParameterDictionary&, const MeshRequest&)> mesh;
  Encoding encoding = Encoding::Srgb;  // of `emission` colours
  // The csg's emission is a texture carried by its material (the emission constant is then 1): an
  // operand with a material of its own does not inherit it.
  bool emissionTexture = false;
};

// The object keys of `csg` besides material, emission and transform.
inline const std::vector<std::string_view> kCsgKeys = {"operation", "operands"};

// Reads `operation` and `operands` of the csg object (or operand) in `params`: operands without a
// material take `material`, without an emission `emission`. `depth`: 1 for an object, +1 per csg
// inside. nullopt after errors (reported at their values, file:line:col).
std::optional<Csg> readCsg(ParameterDictionary& params, const std::string& path,
                           std::uint32_t material, const Color& emission, CsgServices& services,
                           int depth = 1);

}  // namespace glint
