// The material factory: a material's keys (DESIGN.md §3, §5) → Material, for named materials
// (`materials:`) and inline ones (an object's `material: {...}`) alike.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "glint/readers/parameter_dictionary.h"
#include "glint/scene/material.h"
#include "glint/scene/scene.h"

namespace glint {

// The keys of a material, in the order messages list them.
const std::vector<std::string_view>& materialKeys();

class TextureLibrary;

// Declares and reads the material keys of `params`; nullopt when a value is out of range or of
// the wrong type (reported at the value). Absent keys keep Material's defaults. With `textures`,
// a colour key may name or describe a texture (its constant is then 1, the texture's colour
// replacing it), and normal_map, bump_map and bump_scale are read; the bindings are added to the
// scene and indexed by Material::textures. A colour written "#rrggbb" is decoded under `encoding`
// (the image's, as every display colour of the scene). `emission` (may be null) receives the
// material's `emission` when it has one: a colour, or 1 with the texture in the bindings (DESIGN.md
// §9: the emission of the objects naming the material that give none of their own).
std::optional<Material> readMaterial(ParameterDictionary& params, Encoding encoding,
                                     TextureLibrary* textures = nullptr,
                                     std::optional<Color>* emission = nullptr);

}  // namespace glint
