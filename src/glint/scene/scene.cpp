// Scene construction: camera from the image size, material validation, the frozen aggregate.
#include "glint/scene/scene.h"

#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace glint {

namespace {

CameraSpec cameraSpecFor(const SceneParts& parts) {
  CameraSpec spec = parts.camera;
  spec.imageWidth = parts.image.width;
  spec.imageHeight = parts.image.height;
  return spec;
}

// The factor a shadow ray keeps crossing a surface of `material`: kt, times the mean of kt's
// texture (a shadow ray has no (u, v) to look one up at).
Color shadowTransmission(const Material& material, const std::vector<Texture>& textures,
                         const std::vector<MaterialTextures>& bindings) {
  if (material.textures == kUntextured) return material.kt;
  const TextureId kt = bindings[material.textures].kt;
  return kt == kNoTexture ? material.kt : material.kt * meanOf(textures[kt]);
}

// Every material's texture bindings and texture ids must be in range.
void checkTextures(const SceneParts& parts) {
  for (std::size_t i = 0; i < parts.materials.size(); ++i) {
    const std::uint32_t t = parts.materials[i].textures;
    if (t != kUntextured && t >= parts.materialTextures.size()) {
      throw std::invalid_argument("material " + std::to_string(i) + " uses texture binding " +
                                  std::to_string(t) + ", but the scene has only " +
                                  std::to_string(parts.materialTextures.size()));
    }
  }
  for (const MaterialTextures& m : parts.materialTextures) {
    for (const TextureId id : {m.kd, m.ks, m.kr, m.kt, m.ka, m.emission, m.normalMap, m.bumpMap}) {
      if (id != kNoTexture && id >= parts.textures.size()) {
        throw std::invalid_argument("texture " + std::to_string(id) +
                                    " is used, but the scene has only " +
                                    std::to_string(parts.textures.size()) + " textures");
      }
    }
  }
  for (const Texture& texture : parts.textures) {
    const auto* image = std::get_if<ImageTexture>(&texture);
    if (image != nullptr && image->image == nullptr) {
      throw std::invalid_argument("an image texture has no image");
    }
  }
  if (parts.environment.kind == BackgroundKind::Image && parts.environment.image == nullptr) {
    throw std::invalid_argument("an image background has no image");
  }
}

// Checks every material index and pairs each primitive and mesh with its material's kt, the factor
// a shadow ray keeps per crossing.
Aggregate buildAggregate(SceneParts& parts, const std::vector<Material>& materials,
                         const std::vector<Texture>& textures,
                         const std::vector<MaterialTextures>& bindings) {
  const auto checkMaterial = [&](const char* what, std::size_t i, std::uint32_t material) {
    if (material >= materials.size()) {
      throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " uses material " +
                                  std::to_string(material) + ", but the scene has only " +
                                  std::to_string(materials.size()) + " materials");
    }
    return shadowTransmission(materials[material], textures, bindings);
  };
  std::vector<Color> transmission;
  transmission.reserve(parts.primitives.size());
  for (std::size_t i = 0; i < parts.primitives.size(); ++i) {
    transmission.push_back(checkMaterial("primitive", i, parts.primitives[i].materialIndex()));
  }
  std::vector<Color> meshTransmission;
  meshTransmission.reserve(parts.meshes.size());
  for (std::size_t m = 0; m < parts.meshes.size(); ++m) {
    meshTransmission.push_back(checkMaterial("mesh", m, parts.meshes[m].materialIndex));
  }
  Aggregate aggregate(std::move(parts.primitives), std::move(transmission), std::move(parts.meshes),
                      std::move(meshTransmission), parts.acceleration);
  if (parts.isa) aggregate.setIsa(*parts.isa);
  return aggregate;
}

}  // namespace

Scene::Scene(SceneParts parts)
    : name_((checkTextures(parts), std::move(parts.name))),
      materials_(std::move(parts.materials)),
      textures_(std::move(parts.textures)),
      materialTextures_(std::move(parts.materialTextures)),
      lights_(std::move(parts.lights)),
      ambient_(parts.ambient),
      background_(parts.background),
      environment_(std::move(parts.environment)),
      environmentSampler_(parts.render.integrator == Integrator::Path
                              ? EnvironmentSampler::make(environment_)
                              : nullptr),
      fog_(parts.fog),
      camera_(cameraSpecFor(parts)),
      image_(std::move(parts.image)),
      render_(parts.render),
      aggregate_(buildAggregate(parts, materials_, textures_, materialTextures_)),
      emitterSampler_(render_.integrator == Integrator::Path
                          ? EmitterSampler::make(aggregate_.primitives(), aggregate_.meshes(),
                                                 materials_, materialTextures_)
                          : nullptr) {
  if (render_.integrator != Integrator::Path) return;
  for (const Light& light : lights_) {
    const auto* area = std::get_if<AreaLight>(&light);
    if (area == nullptr) continue;
    switch (area->shape) {
      case AreaShape::Rectangle:
        lightSurfaces_.push_back(
            {Rectangle::make(area->corner, area->edge1, area->edge2), area->intensity});
        break;
      case AreaShape::Disk:
        lightSurfaces_.push_back(
            {Disk::make(area->center, area->normal, area->radius), area->intensity});
        break;
      case AreaShape::Sphere:
        lightSurfaces_.push_back({Sphere::make(area->center, area->radius), area->intensity});
        break;
    }
  }
}

}  // namespace glint
