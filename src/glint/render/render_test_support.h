// Tests of the renderer's determinism promise: the same film on any thread count and tile size.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>

#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint::testing {

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
