// The scene builder: SceneDescription → SceneParts (DESIGN.md §5, §7, §8). Walks the entities in
// order — image first (its encoding decodes every "#rrggbb"), then render, background, ambient,
// camera, materials, objects, lights — hands each to the factory of its type, reports every
// parameter nothing read as an unknown key, resolves material names and reads mesh files. The only
// code that turns scene files into render objects.
#pragma once

#include <vector>

#include "glint/factories/build_context.h"
#include "glint/readers/diagnostics.h"
#include "glint/readers/scene_description.h"
#include "glint/scene/scene.h"

namespace glint {

struct BuildResult {
  SceneParts parts;                     // complete only when there is no error
  std::vector<Diagnostic> diagnostics;  // errors and warnings, in the order they were found
  bool hasErrors() const;
};

// Builds whatever the description holds. A missing camera or image is reported here only when the
// reader reported nothing (it reports them itself for files it read).
BuildResult buildScene(const SceneDescription& description, const BuildOptions& options = {});

}  // namespace glint
