// Groups into shared Aggregates, one per distinct shadow transmission its instances give it, and
// the instances placed on them.
#include "glint/scene/scene_instances.h"

#include "glint/geometry/csg.h"

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace glint {

namespace {

bool takes(const std::vector<std::uint8_t>& flags, std::size_t i) {
  return i < flags.size() && flags[i] != 0;
}

void checkMaterial(std::uint32_t material, std::size_t count, const std::string& what) {
  if (material >= count) {
    throw std::invalid_argument(what + " uses material " + std::to_string(material) +
                                ", but the scene has only " + std::to_string(count) + " materials");
  }
}

}  // namespace

std::optional<Color> setCsgTransmission(
    Primitive& primitive, const std::function<Color(std::uint32_t material)>& operandKt) {
  const Csg* csg = primitive.csg();
  if (csg == nullptr) return std::nullopt;
  std::vector<Color> operandTransmission;
  bool clear = true;
  for (const CsgOperand& operand : csg->tree->operands) {
    operandTransmission.push_back(operandKt(operand.materialIndex));
    clear = clear && operandTransmission.back() == Color(1);
  }
  const Transform* transform = primitive.worldFromObject();
  primitive = Primitive(withCsgTransmission(*csg, operandTransmission), primitive.materialIndex(),
                        primitive.emission(),
                        transform ? std::optional<Transform>(*transform) : std::nullopt);
  return clear ? Color(1) : Color();
}

std::shared_ptr<const InstanceSet> buildInstanceSet(SceneParts& parts,
                                                    const std::vector<Material>& materials,
                                                    const std::vector<Texture>& textures,
                                                    const std::vector<MaterialTextures>& bindings,
                                                    std::vector<GroupMaterialTakers>& takers) {
  takers.clear();
  if (parts.instances.empty()) {
    parts.groups.clear();
    return nullptr;
  }
  const auto kt = [&](std::uint32_t material) {
    return shadowTransmission(materials[material], textures, bindings);
  };
  // Each group's objects' own kt, and whether any takes an instance's material.
  std::vector<std::vector<Color>> primitiveKt(parts.groups.size());
  std::vector<std::vector<Color>> meshKt(parts.groups.size());
  for (std::size_t g = 0; g < parts.groups.size(); ++g) {
    const GroupParts& group = parts.groups[g];
    const std::string name = "group " + std::to_string(g);
    for (std::size_t i = 0; i < group.primitives.size(); ++i) {
      checkMaterial(group.primitives[i].materialIndex(), materials.size(),
                    name + " primitive " + std::to_string(i));
      primitiveKt[g].push_back(kt(group.primitives[i].materialIndex()));
      if (const Csg* csg = group.primitives[i].csg()) {
        for (const CsgOperand& operand : csg->tree->operands) {
          checkMaterial(operand.materialIndex, materials.size(),
                        name + " csg operand of primitive " + std::to_string(i));
        }
      }
    }
    for (std::size_t m = 0; m < group.meshes.size(); ++m) {
      checkMaterial(group.meshes[m].materialIndex, materials.size(),
                    name + " mesh " + std::to_string(m));
      meshKt[g].push_back(kt(group.meshes[m].materialIndex));
    }
  }
  // Which built Aggregate each instance uses: its group with the objects' own kt (no override, or
  // one that changes no kt), or its group with the override's kt on the objects that take it.
  // Numbered in order of first use, so the result depends only on the input order.
  using Key = std::tuple<std::uint32_t, bool, double, double, double>;
  std::map<Key, std::uint32_t> built;
  std::vector<std::pair<std::uint32_t, std::optional<Color>>> recipes;  // group, override kt
  for (std::size_t k = 0; k < parts.instances.size(); ++k) {
    Instance& in = parts.instances[k];
    if (in.group >= parts.groups.size()) {
      throw std::invalid_argument("instance " + std::to_string(k) + " places group " +
                                  std::to_string(in.group) + ", but there are only " +
                                  std::to_string(parts.groups.size()));
    }
    std::optional<Color> override;
    if (in.material != kNoMaterialOverride) {
      checkMaterial(in.material, materials.size(), "instance " + std::to_string(k));
      const Color given = kt(in.material);
      const GroupParts& group = parts.groups[in.group];
      for (std::size_t i = 0; i < group.primitives.size() && !override; ++i) {
        if (!takes(group.primitiveTakesMaterial, i)) continue;
        if (!(primitiveKt[in.group][i] == given)) override = given;
        // A csg that takes the material takes it for every operand (Scene::materialIndexOf).
        if (const Csg* csg = group.primitives[i].csg()) {
          for (const CsgOperand& operand : csg->tree->operands) {
            if (!(kt(operand.materialIndex) == given)) override = given;
          }
        }
      }
      for (std::size_t m = 0; m < group.meshes.size() && !override; ++m) {
        if (takes(group.meshTakesMaterial, m) && !(meshKt[in.group][m] == given)) override = given;
      }
    }
    const Key key = override ? Key{in.group, true, override->r, override->g, override->b}
                             : Key{in.group, false, 0, 0, 0};
    const auto [it, added] = built.emplace(key, static_cast<std::uint32_t>(recipes.size()));
    if (added) recipes.emplace_back(in.group, override);
    in.group = it->second;
  }
  // The last use of a group moves its geometry; earlier ones (other kt) copy it.
  std::vector<std::size_t> lastUse(parts.groups.size(), 0);
  for (std::size_t r = 0; r < recipes.size(); ++r) lastUse[recipes[r].first] = r;
  std::vector<std::shared_ptr<const Aggregate>> aggregates;
  for (std::size_t r = 0; r < recipes.size(); ++r) {
    const auto& [g, override] = recipes[r];
    GroupParts& group = parts.groups[g];
    std::vector<Color> pKt = primitiveKt[g];
    std::vector<Color> mKt = meshKt[g];
    if (override) {
      for (std::size_t i = 0; i < pKt.size(); ++i) {
        if (takes(group.primitiveTakesMaterial, i)) pKt[i] = *override;
      }
      for (std::size_t m = 0; m < mKt.size(); ++m) {
        if (takes(group.meshTakesMaterial, m)) mKt[m] = *override;
      }
    }
    GroupMaterialTakers t{group.primitiveTakesMaterial, group.meshTakesMaterial};
    t.primitives.resize(group.primitives.size(), 0);
    t.meshes.resize(group.meshes.size(), 0);
    takers.push_back(std::move(t));
    std::vector<Primitive> primitives =
        lastUse[g] == r ? std::move(group.primitives) : group.primitives;
    for (std::size_t i = 0; i < primitives.size(); ++i) {
      // The kt an operand takes: a copy, since clang 14 (the fuzz build) cannot capture a
      // structured binding.
      const std::optional<Color> given =
          override && takes(group.primitiveTakesMaterial, i) ? override : std::nullopt;
      const std::optional<Color> csgKt =
          setCsgTransmission(primitives[i], [&](std::uint32_t material) {
            return given ? *given : kt(material);  // indices checked above
          });
      if (csgKt) pKt[i] = *csgKt;
    }
    // The node width of the scene's ISA.
    const Acceleration acceleration = accelerationFor(parts.acceleration, parts.isa);
    std::shared_ptr<Aggregate> aggregate =
        lastUse[g] == r
            ? std::make_shared<Aggregate>(std::move(primitives), std::move(pKt),
                                          std::move(group.meshes), std::move(mKt), acceleration)
            : std::make_shared<Aggregate>(std::move(primitives), std::move(pKt), group.meshes,
                                          std::move(mKt), acceleration);
    if (parts.isa) aggregate->setIsa(*parts.isa);  // the groups' queries run as the scene's
    aggregates.push_back(std::move(aggregate));
  }
  parts.groups.clear();
  return std::make_shared<const InstanceSet>(std::move(aggregates), std::move(parts.instances));
}

}  // namespace glint
