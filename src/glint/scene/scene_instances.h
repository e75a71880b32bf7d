// The scene's instances (DESIGN.md §11): SceneParts' groups and instances made into the
// InstanceSet its Aggregate queries, with the shadow transmission of every group object.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "glint/accel/instances.h"
#include "glint/scene/scene.h"

namespace glint {

// Builds parts.groups into shared Aggregates and places parts.instances (both moved out). A group
// whose instances give transparent materials to its objects (so shadow rays cross them with a
// different kt) is built once per distinct such kt; every other instance of a group shares one.
// takers receives, per built group, which of its objects take an instance's material. Null when
// there are no instances. Throws std::invalid_argument for a material index out of range.
std::shared_ptr<const InstanceSet> buildInstanceSet(SceneParts& parts,
                                                    const std::vector<Material>& materials,
                                                    const std::vector<Texture>& textures,
                                                    const std::vector<MaterialTextures>& bindings,
                                                    std::vector<GroupMaterialTakers>& takers);

// A csg's shadow transmission, for the world's primitives and the groups' alike: each operand
// gets operandKt(its material index) on a copy of the operand tree (the primitive is rebuilt), and
// the primitive's own transmission is returned: Color(1) when every operand is clear, black
// otherwise (the Aggregate then asks the csg, which counts each crossing of the result's surface
// with the crossed operand's kt). std::nullopt, the primitive untouched, when it is not a csg.
std::optional<Color> setCsgTransmission(
    Primitive& primitive, const std::function<Color(std::uint32_t material)>& operandKt);

// The factor a shadow ray keeps crossing a surface of `material`: kt, times the mean of kt's
// texture (a shadow ray has no (u, v) to look one up at).
Color shadowTransmission(const Material& material, const std::vector<Texture>& textures,
                         const std::vector<MaterialTextures>& bindings);

}  // namespace glint
