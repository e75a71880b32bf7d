// The scene builder: SceneDescription → SceneParts (DESIGN.md §5, §7). Checks value ranges,
// resolves material names, decodes colours under the image encoding, normalises directions,
// composes transforms and creates the shapes through their make() factories, reporting every
// problem at the place in the file it comes from. The only io code that creates render objects.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "glint/readers/diagnostics.h"
#include "glint/readers/scene_description.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#include "glint/scene/scene_overrides.h"

namespace glint {

struct BuildOptions {
  // Largest film (width · height · sizeof(Color) bytes) the image may ask for.
  std::uint64_t imageMemoryBudget = defaultImageMemoryBudget();
  // The caller's replacements of the image size, samples and seed, applied before the film and the
  // meshes are estimated; the caller checks the overridden image against the limits.
  SceneOverrides overrides{};
  // Polled while mesh files are read and instanced; when set the build throws Cancelled
  // (core/cancel.h). Not owned; may be null.
  const std::atomic<bool>* cancel = nullptr;
};

struct BuildResult {
  SceneParts parts;                     // complete only when there is no error
  std::vector<Diagnostic> diagnostics;  // errors and warnings, in the order they were found
  bool hasErrors() const;
};

// Builds whatever the description holds. Required parts that are absent are reported only for
// entities the parser marked complete (the parser has already reported the others).
BuildResult buildScene(const SceneDescription& description, const BuildOptions& options = {});

}  // namespace glint
