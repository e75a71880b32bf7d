// Tests of the renderer's determinism promise: the same film on any thread count and tile size.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "glint/geometry/triangle_mesh.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint::testing {

// A regular icosahedron (20 triangles, outward winding) inscribed in the sphere of `radius` about
// `center`, with smooth normals: each vertex's normal points away from the centre. Its shading
// normals tilt up to ~37° from the faces' geometric normals (a coarse smooth mesh).
inline TriangleMesh smoothIcosahedron(const Point3& center, double radius,
                                      std::uint32_t materialIndex) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  const double corners[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                 {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                 {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  TriangleMesh mesh;
  for (const auto& c : corners) {
    const Vec3 d = normalize(Vec3{c[0], c[1], c[2]});
    mesh.positions.push_back(center + d * radius);
    mesh.normals.push_back(Normal3{d.x, d.y, d.z});
  }
  mesh.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                  4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                  6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  mesh.materialIndex = materialIndex;
  return mesh;
}

// Success when `scene` renders bit-identical films on one thread in 16-pixel tiles and on one and
// two threads in tiles of 1, 5 and 64 pixels; otherwise says where the first difference is.
inline ::testing::AssertionResult rendersTheSameOnAnyThreadCountAndTileSize(const Scene& scene) {
  RenderOptions reference;
  reference.threads = 1;
  reference.tileSize = 16;
  const Film expected = render(scene, reference);
  for (const int tileSize : {1, 5, 64}) {
    for (const int threads : {1, 2}) {
      RenderOptions options;
      options.threads = threads;
      options.tileSize = tileSize;
      const Film film = render(scene, options);
      if (film.region() != expected.region()) {
        return ::testing::AssertionFailure() << "another region: tile " << tileSize;
      }
      for (std::size_t i = 0; i < film.pixels().size(); ++i) {
        if (!(film.pixels()[i] == expected.pixels()[i])) {
          return ::testing::AssertionFailure()
                 << "pixel " << i << " differs with tile " << tileSize << ", threads " << threads;
        }
      }
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace glint::testing
