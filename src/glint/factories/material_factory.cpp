#include "glint/factories/material_factory.h"

#include <limits>

#include "glint/factories/build_context.h"
#include "glint/factories/texture_library.h"

namespace glint {

const std::vector<std::string_view>& materialKeys() {
  static const std::vector<std::string_view> keys = {"kd",
                                                     "ks",
                                                     "shininess",
                                                     "kr",
                                                     "kt",
                                                     "ka",
                                                     "ior",
                                                     "reflection_blur",
                                                     "refraction_blur",
                                                     "priority",
                                                     "normal_map",
                                                     "bump_map",
                                                     "bump_scale",
                                                     "emission"};
  return keys;
}

std::optional<Material> readMaterial(ParameterDictionary& params, Encoding encoding,
                                     TextureLibrary* textures, std::optional<Color>* emission) {
  params.declare(materialKeys());
  const std::size_t errorsBefore = params.errors();
  Material out;
  MaterialTextures bindings;
  bool textured = false;
  // A colour key: a coefficient, or (with a texture library) a texture whose colour it becomes.
  const auto coefficient = [&](std::string_view key, Color& value, TextureId& texture) {
    if (textures != nullptr && textures->isTexture(params, key)) {
      if (const auto id = textures->read(params, key, TextureRole::Color)) {
        value = Color(1);
        texture = *id;
        textured = true;
      }
      return;
    }
    if (const auto c = readCoefficient(params, key, encoding)) value = *c;
  };
  coefficient("kd", out.kd, bindings.kd);
  coefficient("ks", out.ks, bindings.ks);
  if (const auto v = readNonNegative(params, "shininess")) out.shininess = *v;
  coefficient("kr", out.kr, bindings.kr);
  coefficient("kt", out.kt, bindings.kt);
  coefficient("ka", out.ka, bindings.ka);
  if (params.has("emission")) {
    // The emission of the objects that name this material and give none of their own; a texture
    // is carried by the material's bindings, as an object's emission texture is, the constant 1.
    Color value;
    coefficient("emission", value, bindings.emission);
    if (emission != nullptr) *emission = value;
  }
  if (const auto v = readPositive(params, "ior")) out.ior = *v;
  if (const auto v = readNonNegative(params, "reflection_blur")) out.reflectionBlur = *v;
  if (const auto v = readNonNegative(params, "refraction_blur")) out.refractionBlur = *v;
  // Nested dielectrics (scene/media.h): an integer, higher wins where transparent solids overlap.
  if (const auto v = readIntegerInRange(params, "priority", 0, std::numeric_limits<int>::max())) {
    out.priority = static_cast<int>(*v);
  }
  if (textures != nullptr) {
    for (const auto& [key, slot] :
         {std::pair{"normal_map", &bindings.normalMap}, std::pair{"bump_map", &bindings.bumpMap}}) {
      if (const auto id = textures->read(params, key, TextureRole::Data)) {
        *slot = *id;
        textured = true;
      }
    }
    if (const auto v = params.number("bump_scale")) bindings.bumpScale = v->value;
  }
  if (params.errors() != errorsBefore) return std::nullopt;
  if (textured) out.textures = textures->addBindings(bindings);
  return out;
}

}  // namespace glint
