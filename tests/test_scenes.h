// A small test scene shared by the determinism and distributed-sampling tests.
#pragma once

#include <cstdint>

#include "glint/geometry/shape.h"
#include "glint/scene/scene.h"

namespace glint::testing {

inline constexpr int kGlossySceneWidth = 24;  // pixels
inline constexpr int kGlossySceneHeight = 20;

// Glossy reflection and blurred refraction through glass, supersampled: every random decision of
// the renderer is exercised (pixel jitter, cone samples for both lobes, the split rule below them).
inline SceneParts glossyTestScene(std::uint64_t seed) {
  SceneParts parts;
  parts.camera.position = {0, 1, 4};
  parts.camera.direction = {0, -0.2, -1};
  parts.camera.fovDegrees = 50;
  parts.image.width = kGlossySceneWidth;
  parts.image.height = kGlossySceneHeight;
  parts.image.samples = 4;
  parts.image.encoding = Encoding::Srgb;
  parts.render.blurSamples = 4;
  parts.render.maxDepth = 5;
  parts.render.seed = seed;
  parts.background = Color(0.2, 0.3, 0.5);
  parts.ambient = Color(0.05);

  Material floor;
  floor.kd = Color(0.5, 0.5, 0.45);
  floor.kr = Color(0.4);
  floor.reflectionBlur = 12;
  Material glass;
  glass.kd = Color(0.05);
  glass.ks = Color(0.8);
  glass.shininess = 100;
  glass.kt = Color(0.85);
  glass.ior = 1.5;
  glass.refractionBlur = 6;
  Material red;
  red.kd = Color(0.8, 0.1, 0.1);
  red.ks = Color(0.3);
  red.shininess = 30;
  parts.materials.push_back(floor);
  parts.materials.push_back(glass);
  parts.materials.push_back(red);
  parts.primitives.emplace_back(Plane::make({0, -1, 0}, {0, 1, 0}), 1u, Color{});
  parts.primitives.emplace_back(Sphere::make({0, 0, -1}, 1), 2u, Color{});
  parts.primitives.emplace_back(Sphere::make({1.5, -0.3, -3}, 0.7), 3u, Color{});
  parts.primitives.emplace_back(Sphere::make({-1.6, -0.4, -2.5}, 0.6), 3u, Color{});
  parts.lights.push_back(PointLight{{3, 5, 3}, Color(40, 38, 35), {1, 0, 1}});
  parts.lights.push_back(DirectionalLight{normalize(Vec3{-0.5, -1, -0.3}), Color(0.4)});
  return parts;
}

}  // namespace glint::testing
