#include "glint/factories/transform_reader.h"

#include <stdexcept>
#include <string_view>

#include <fmt/format.h>

#include "glint/factories/build_context.h"

namespace glint {
namespace {

// One step: the first of translate, scale, rotate in it; the identity and false when it is wrong.
std::optional<Transform> readStep(ParameterDictionary& step, const std::string& stepPath) {
  step.declare({"translate", "scale", "rotate"});
  const std::vector<std::string_view> keys = step.keys();
  std::string_view kind;
  for (const std::string_view key : keys) {
    if (!step.isDeclared(key)) continue;  // reported by finish() as unknown
    if (kind.empty()) {
      kind = key;
      continue;
    }
    step.error(step.keyPlace(key),
               fmt::format("a transform step holds one of translate, scale, rotate; put '{}' in a "
                           "step of its own",
                           key));
    step.markUsed({key});
  }
  if (keys.empty()) {
    step.error(step.place(),
               fmt::format("{}: a transform step needs one of translate, scale, rotate", stepPath));
    return std::nullopt;
  }
  if (kind.empty()) return std::nullopt;
  const ValueTree& tree = step.reader().tree();
  try {
    if (kind == "translate") {
      const auto t = step.vec3("translate");
      if (!t) return std::nullopt;
      return Transform::translate(t->value);
    }
    if (kind == "scale") {
      const auto entry = step.find("scale");
      std::optional<Located<Vec3>> s;
      if (tree.isScalar(entry->value)) {
        if (const auto n = step.number("scale"))
          s = Located<Vec3>{Vec3{n->value, n->value, n->value}, n->where};
      } else if (tree.isList(entry->value)) {
        s = step.vec3("scale");
      } else {
        step.error(entry->where,
                   fmt::format("{}: expected a number or a list of 3 numbers [sx, sy, sz], got {}",
                               step.pathOf("scale").str(), step.reader().describe(entry->value)));
      }
      if (!s) return std::nullopt;
      const Vec3& v = s->value;
      if (v.x == 0 || v.y == 0 || v.z == 0) {
        step.error(s->where, fmt::format("{}.scale factors must be non-zero, got {}", stepPath,
                                         v.x == v.y && v.y == v.z ? show(v.x) : show(v)));
        return std::nullopt;
      }
      return Transform::scale(v.x, v.y, v.z);
    }
    // rotate: {axis, angle}
    const std::string rotatePath = step.pathOf("rotate").str();
    auto rotate = step.mapping("rotate", "a mapping {axis: [x, y, z], angle: degrees}",
                               {"in " + rotatePath, rotatePath, rotatePath});
    if (!rotate) return std::nullopt;
    rotate->declare({"axis", "angle"});
    const auto axis = rotate->vec3("axis", Presence::Required);
    const auto angle = rotate->number("angle", Presence::Required);
    rotate->finish();
    if (!axis || !angle) return std::nullopt;
    const std::optional<Vec3> unit = unitVector(axis->value);
    if (!unit) {
      step.error(axis->where, fmt::format("{}.rotate.axis must be non-zero, got {}", stepPath,
                                          show(axis->value)));
      return std::nullopt;
    }
    return Transform::rotate(*unit, angle->value);
  } catch (const std::invalid_argument& e) {  // TransformError, or a singular matrix
    step.error(step.place(), fmt::format("{}: {}", stepPath, e.what()));
    return std::nullopt;
  }
}

}  // namespace

TransformResult readTransform(ParameterDictionary& params, const std::string& owner) {
  TransformResult result;
  const auto entry = params.find("transform");
  if (!entry) return result;
  const ValueReader& reader = params.reader();
  const ValueTree& tree = reader.tree();
  const ValuePath path = params.pathOf("transform");
  if (!tree.isList(entry->value)) {
    params.error(
        entry->where,
        fmt::format("{}: expected a list of steps ({{translate: [x, y, z]}}, {{scale: s}}, "
                    "{{rotate: {{axis: [x, y, z], angle: degrees}}}}), got {}",
                    path.str(), reader.describe(entry->value)));
    result.ok = false;
    return result;
  }
  Transform worldFromObject;
  for (std::size_t i = 0; i < tree.size(entry->value); ++i) {
    const ValueId stepValue = tree.item(entry->value, i);
    const ValueId stepPlace = reader.itemPlace(entry->value, entry->where, i);
    const std::string stepPath = fmt::format("{}.transform[{}]", owner, i);
    if (!tree.isMap(stepValue)) {
      params.error(stepPlace, fmt::format("{}: expected a step {{translate: [x, y, z]}}, "
                                          "{{scale: s}} or {{rotate: {{axis, angle}}}}, got {}",
                                          stepPath, reader.describe(stepValue)));
      result.ok = false;
      continue;
    }
    ParameterDictionary step(reader, stepValue, {"in a transform step", stepPath, stepPath});
    const std::optional<Transform> t = readStep(step, stepPath);
    step.finish();
    if (!t || step.errors() != 0) {
      result.ok = false;
      continue;
    }
    // Steps apply in file order: the later step acts on the result of the earlier ones.
    worldFromObject = *t * worldFromObject;
  }
  if (result.ok && !worldFromObject.isIdentity()) result.worldFromObject = worldFromObject;
  return result;
}

}  // namespace glint
