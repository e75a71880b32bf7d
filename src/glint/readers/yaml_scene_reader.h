// The YAML (and JSON) scene reader (DESIGN.md §5): one YAML document whose top level is a mapping
// of the sections name, background, ambient, camera, image, render, materials, objects and lights
// → a SceneDescription of entities. It knows YAML and this top-level structure, never the keys of a
// shape, light or material (their factories read those).
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "glint/readers/diagnostics.h"
#include "glint/readers/scene_description.h"

namespace glint {

struct ParseResult {
  SceneDescription description;         // what could be read
  std::vector<Diagnostic> diagnostics;  // errors and warnings, in the order they were found
  bool hasErrors() const;
};

// Reads scene text. `file` names it in messages; relative paths inside it resolve from
// `baseDirectory`. Throws glint::Cancelled when `cancel` is set while reading.
ParseResult parseScene(std::string_view text, const std::string& file,
                       const std::filesystem::path& baseDirectory = ".",
                       const std::atomic<bool>* cancel = nullptr);

// Reads a scene file, streaming (the text is never held whole). `name` names it in messages.
// Throws SceneError naming only the file when it cannot be read (missing, a folder, not a regular
// file, unreadable, larger than kMaxSceneFileBytes), glint::Cancelled when cancelled.
ParseResult readSceneFile(const std::filesystem::path& path, const std::string& name,
                          const std::atomic<bool>* cancel = nullptr);

}  // namespace glint
