// Scene construction: camera from the image size, material validation, the frozen aggregate.
#include "glint/scene/scene.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace glint {

namespace {

CameraSpec cameraSpecFor(const SceneParts& parts) {
  CameraSpec spec = parts.camera;
  spec.imageWidth = parts.image.width;
  spec.imageHeight = parts.image.height;
  return spec;
}

// Checks every material index and pairs each primitive and mesh with its material's kt, the factor
// a shadow ray keeps per crossing.
Aggregate buildAggregate(SceneParts& parts, const std::vector<Material>& materials) {
  const auto checkMaterial = [&](const char* what, std::size_t i, std::uint32_t material) {
    if (material >= materials.size()) {
      throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " uses material " +
                                  std::to_string(material) + ", but the scene has only " +
                                  std::to_string(materials.size()) + " materials");
    }
    return materials[material].kt;
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
  return Aggregate(std::move(parts.primitives), std::move(transmission), std::move(parts.meshes),
                   std::move(meshTransmission), parts.acceleration);
}

}  // namespace

Scene::Scene(SceneParts parts)
    : name_(std::move(parts.name)),
      materials_(std::move(parts.materials)),
      lights_(std::move(parts.lights)),
      ambient_(parts.ambient),
      background_(parts.background),
      fog_(parts.fog),
      camera_(cameraSpecFor(parts)),
      image_(std::move(parts.image)),
      render_(parts.render),
      aggregate_(buildAggregate(parts, materials_)) {}

}  // namespace glint
