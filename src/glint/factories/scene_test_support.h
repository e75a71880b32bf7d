// Test helpers shared by the scene parser and builder tests: a minimal valid scene and
// expectations on the diagnostics of loadSceneFromString.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "glint/factories/scene_loader.h"
#include "glint/readers/diagnostics.h"

namespace glint::testing {

// The smallest valid scene: the two required top-level keys.
inline constexpr const char* kMinimal =
    "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
    "image: {width: 4, height: 3}\n";

// The example scene of DESIGN.md §5, verbatim (comments included, so its line numbers are the
// document's).
inline constexpr const char* kDesignExample = R"(name: basic render                 # optional
background: "#4b7f5a"              # default black
ambient: { color: [1, 0.75, 0.75], intensity: 1 }     # default none
camera:
  position: [0, 0, 0]
  direction: [0, 0, -1]            # or look_at: [x, y, z]
  up: [0, 1, 0]                    # default [0, 1, 0]
  view_plane: { width: 500, height: 500, distance: 100 }   # or fov: 40
  aperture: 0                      # optional, with focus_distance
image:
  width: 1000                      # pixels
  height: 1000
  samples: 1                       # per pixel
  encoding: srgb                   # srgb (default) | linear (value × 255, rounded to nearest)
  grid: { interval: 100, color: "#ffff00" }   # optional: after rendering, paints every pixel
                                              # whose column or row is a multiple of interval (0 too)
render:
  max_depth: 10
  min_weight: 0.001
  blur_samples: 16
  seed: 0
materials:
  glass: { kd: 0.1, ks: 0.8, shininess: 200, kt: 0.9, ior: 1.5 }
objects:
  - { type: sphere, center: [0, 0, -100], radius: 50, material: glass }
  - { type: triangle, vertices: [[-100, 0, -100], [0, 100, -100], [-100, 100, -100]],
      emission: "#ff0000", material: { kd: 0.5, ks: 0.5, shininess: 60 } }
lights:
  - { type: spot, position: [-50, -50, 50], direction: [1, 1, -2], color: [1, 0.6, 0],
      intensity: 1, attenuation: [1, 0.00001, 0.00000001], exponent: 1 }
)";

// Every error loading `text` (as "test.yaml") reports; empty when it loads.
inline std::vector<Diagnostic> errorsOf(const std::string& text) {
  try {
    loadSceneFromString(text, "test.yaml");
  } catch (const SceneError& e) {
    return e.diagnostics();
  }
  return {};
}

// Expects exactly one error, at line:column of test.yaml, whose message contains `fragment`.
inline void expectOneError(const std::string& text, int line, int column,
                           const std::string& fragment) {
  SCOPED_TRACE(text);
  const std::vector<Diagnostic> errors = errorsOf(text);
  ASSERT_EQ(errors.size(), 1u) << (errors.empty() ? "no error" : errors[0].format());
  EXPECT_EQ(errors[0].where.file, "test.yaml");
  EXPECT_EQ(errors[0].where.line, line) << errors[0].format();
  EXPECT_EQ(errors[0].where.column, column) << errors[0].format();
  EXPECT_THAT(errors[0].message, ::testing::HasSubstr(fragment));
  EXPECT_EQ(errors[0].severity, Diagnostic::Severity::Error);
}

}  // namespace glint::testing
