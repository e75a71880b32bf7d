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

// Checks every material index and pairs each primitive with its material's kt, the factor a shadow
// ray keeps per crossing.
Aggregate buildAggregate(std::vector<Primitive> primitives,
                         const std::vector<Material>& materials) {
  std::vector<Color> transmission;
  transmission.reserve(primitives.size());
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    const std::uint32_t material = primitives[i].materialIndex();
    if (material >= materials.size()) {
      throw std::invalid_argument("primitive " + std::to_string(i) + " uses material " +
                                  std::to_string(material) + ", but the scene has only " +
                                  std::to_string(materials.size()) + " materials");
    }
    transmission.push_back(materials[material].kt);
  }
  return Aggregate(std::move(primitives), std::move(transmission));
}

}  // namespace

Scene::Scene(SceneParts parts)
    : name_(std::move(parts.name)),
      materials_(std::move(parts.materials)),
      lights_(std::move(parts.lights)),
      ambient_(parts.ambient),
      background_(parts.background),
      camera_(cameraSpecFor(parts)),
      image_(std::move(parts.image)),
      render_(parts.render),
      aggregate_(buildAggregate(std::move(parts.primitives), materials_)) {}

}  // namespace glint
