// A SceneDescription written as a glint YAML scene (DESIGN.md §13, `glint convert`): every entity's
// values as their reader read them (numbers keep their text, so the YAML reads back to the same
// values and renders the same bytes), large inline meshes as binary PLY files beside the scene.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "glint/readers/scene_description.h"

namespace glint {

struct SceneWriteOptions {
  // Inline meshes (positions, indices) with at least this many triangles and no vertex colours
  // are written as PLY files (PLY files hold no per-vertex colours glint reads).
  std::size_t plyTriangles = 5000;
  // A line the YAML written names the source with (a comment), or empty.
  std::string sourceName;
};

struct WrittenScene {
  std::string yaml;
  // Files to write beside the scene: the name (relative to the scene's folder) and the bytes.
  struct File {
    std::string name;
    std::string bytes;
  };
  std::vector<File> files;
  // Every file the scene reads (its included files, the files its values name), absolute: none
  // of them may be written over.
  std::vector<std::filesystem::path> inputs;
};

// The YAML of `scene` for a file at `output`: relative mesh paths are rewritten to resolve from
// output's folder; PLY files are named after output's stem (scene_mesh1.ply, ...), skipping names
// of files the scene reads.
WrittenScene writeSceneYaml(const SceneDescription& scene, const std::filesystem::path& output,
                            const SceneWriteOptions& options = {});

// A scalar as YAML reads it back to the same text: plain when that is unambiguous, else quoted.
std::string yamlScalar(std::string_view text);

}  // namespace glint
