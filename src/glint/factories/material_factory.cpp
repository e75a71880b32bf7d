#include "glint/factories/material_factory.h"

#include "glint/factories/build_context.h"

namespace glint {

const std::vector<std::string_view>& materialKeys() {
  static const std::vector<std::string_view> keys = {
      "kd", "ks", "shininess", "kr", "kt", "ka", "ior", "reflection_blur", "refraction_blur"};
  return keys;
}

std::optional<Material> readMaterial(ParameterDictionary& params) {
  params.declare(materialKeys());
  const std::size_t errorsBefore = params.errors();
  Material out;
  if (const auto c = readCoefficient(params, "kd")) out.kd = *c;
  if (const auto c = readCoefficient(params, "ks")) out.ks = *c;
  if (const auto v = readNonNegative(params, "shininess")) out.shininess = *v;
  if (const auto c = readCoefficient(params, "kr")) out.kr = *c;
  if (const auto c = readCoefficient(params, "kt")) out.kt = *c;
  if (const auto c = readCoefficient(params, "ka")) out.ka = *c;
  if (const auto v = readPositive(params, "ior")) out.ior = *v;
  if (const auto v = readNonNegative(params, "reflection_blur")) out.reflectionBlur = *v;
  if (const auto v = readNonNegative(params, "refraction_blur")) out.refractionBlur = *v;
  if (params.errors() != errorsBefore) return std::nullopt;
  return out;
}

}  // namespace glint
