// Test helpers shared by the scene parser and builder tests: a minimal valid scene and
// expectations on the diagnostics of loadSceneFromString.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "glint/io/diagnostics.h"
#include "glint/io/scene_loader.h"

namespace glint::testing {

// The smallest valid scene: the two required top-level keys.
inline constexpr const char* kMinimal =
    "camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 40}\n"
    "image: {width: 4, height: 3}\n";

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
