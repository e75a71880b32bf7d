// The scene-file parser: YAML/JSON text → SceneDescription (DESIGN.md §5). Checks structure and
// types only — one document whose top level is a mapping, known keys (no duplicates), required
// keys, the type and length of every value, finite numbers, whole numbers where an integer is
// needed, and the either/or choices (direction | look_at, view_plane | fov). Ranges are the
// builder's job.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "glint/readers/diagnostics.h"
#include "glint/readers/scene_description.h"

namespace glint {

struct ParseResult {
  SceneDescription description;  // what could be read; entities with errors are marked incomplete
  std::vector<Diagnostic> diagnostics;  // errors and warnings, in the order they were found
  bool hasErrors() const;
};

// `file` names the text in messages; relative paths inside it resolve from `baseDirectory`.
ParseResult parseScene(std::string_view text, const std::string& file,
                       const std::filesystem::path& baseDirectory = ".");

}  // namespace glint
