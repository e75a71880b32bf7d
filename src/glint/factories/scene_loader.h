// Scene files (DESIGN.md §5): YAML/JSON text → SceneDescription (plain data with the file:line:col
// of every entity; readers/scene_description.h) → SceneParts (render objects; scene/scene.h).
// Strict: an unknown key, a wrong type, a missing required key or an invalid value is an error
// naming its place.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "glint/readers/diagnostics.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#include "glint/scene/scene_overrides.h"

namespace glint {

struct LoadedScene {
  SceneParts parts;
  std::vector<Diagnostic> warnings;
  std::uint64_t sceneBytes = 0;        // size of the scene file (or text)
};

struct LoadOptions {
  // Bytes the scene may need (film now; meshes and BVH estimated before loading): the limit of
  // DESIGN.md §7, set by `--max-memory`.
  std::uint64_t memoryBudget = defaultImageMemoryBudget();
  // --width/--height/--samples/--seed, applied before anything is estimated from the image.
  SceneOverrides overrides{};
  // Polled while reading, parsing, loading meshes and building; when set the load throws
  // Cancelled (core/cancel.h). Not owned; may be null.
  const std::atomic<bool>* cancel = nullptr;
};

// Reads (streaming), parses and builds a scene file. Throws SceneError carrying every error found
// (up to 20); a missing, unreadable or non-regular path (a folder, a FIFO, a device) is an error
// naming only the file. Throws Cancelled when options.cancel is set while loading.
LoadedScene loadScene(const std::filesystem::path& file, const LoadOptions& options = {});

// The same for text in memory. `displayName` names the text in messages; relative paths inside it
// (mesh files) resolve from `baseDirectory`.
LoadedScene loadSceneFromString(std::string_view text, const std::string& displayName,
                                const std::filesystem::path& baseDirectory = ".",
                                const LoadOptions& options = {});

}  // namespace glint
