// The seed document's test case (four triangles and a sphere, ambient light only, with the grid),
// built in code: a scene without a file. Rendered by examples/seed_test_case.cpp and checked
// pixel by pixel by tests/analytic_image_test.cpp.
#pragma once

#include <utility>

#include "glint/geometry/shape.h"
#include "glint/scene/scene.h"

namespace glint::seed {

// Seed geometry in scene units: everything lies in the plane z = -100, 100 units in front of the
// camera, seen through a 500 × 500 view plane at distance 100 (so 1 scene unit there = 1 view-plane
// unit). `size` is the image side in pixels (the seed uses 1000); `gridInterval` in pixels.
inline SceneParts testCaseParts(int size = 1000, int gridInterval = 100) {
  SceneParts parts;
  parts.name = "seed test case";
  // Display colours are "#rrggbb" codes; under linear encoding a code c decodes to c / 255
  // (image/image_writer.h: decodeChannel).
  const auto display = [](int r, int g, int b) { return Color(r / 255.0, g / 255.0, b / 255.0); };
  parts.background = display(0x4b, 0x7f, 0x5a);
  parts.ambient = display(255, 191, 191) * 1.0;  // colour × intensity 1

  parts.camera.position = {0, 0, 0};
  parts.camera.direction = {0, 0, -1};
  parts.camera.up = {0, 1, 0};
  parts.camera.viewPlaneWidth = 500;
  parts.camera.viewPlaneHeight = 500;
  parts.camera.viewPlaneDistance = 100;

  parts.image.width = size;
  parts.image.height = size;
  parts.image.samples = 1;
  parts.image.encoding = Encoding::Linear;
  parts.image.grid = GridOverlay{gridInterval, display(0xff, 0xff, 0x00)};

  // Default material (index 0: ka = 1, everything else 0): each object shows the ambient colour.
  const auto add = [&parts](Shape shape) {
    parts.primitives.emplace_back(std::move(shape), 0u, Color{});
  };
  add(Sphere::make({0, 0, -100}, 50));
  add(Triangle::make({100, 0, -100}, {0, 100, -100}, {100, 100, -100}));
  add(Triangle::make({-100, 0, -100}, {0, 100, -100}, {-100, 100, -100}));
  add(Triangle::make({100, 0, -100}, {0, -100, -100}, {100, -100, -100}));
  add(Triangle::make({-100, 0, -100}, {0, -100, -100}, {-100, -100, -100}));
  return parts;
}

}  // namespace glint::seed
