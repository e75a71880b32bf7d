// `glint convert FILE -o scene.yaml` (DESIGN.md §13): any scene glint reads (YAML, NFF, Tachyon
// .dat, a mesh file's quick look) written as the equivalent glint YAML scene, its large inline
// meshes as PLY files beside it; rendering the written scene gives the same bytes as rendering
// FILE.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "glint/readers/diagnostics.h"

namespace glint {

struct ConvertSpec {
  std::filesystem::path scene;   // the file to convert
  std::filesystem::path output;  // .yaml or .yml (any case); empty: the scene's name with .yaml,
                                 // in the current folder
  const std::atomic<bool>* cancel = nullptr;  // not owned; may be null
  // True while the written files are renamed over their targets, false when done: the caller
  // should not end the process abruptly then (RenderJobEvents::committing likewise).
  std::function<void(bool)> committing;
};

struct ConvertResult {
  std::filesystem::path output;
  std::vector<std::filesystem::path> meshFiles;  // PLY files written beside it
  std::vector<Diagnostic> warnings;              // of the scene, as render reports them
  std::size_t objects = 0;
  std::size_t lights = 0;
  bool interrupted = false;  // the cancel flag was seen: nothing was written
};

// Reads and checks the scene (the errors `glint check` reports), then writes the YAML and its PLY
// files, all or none (each to a temporary file, then all renamed). Throws JobError: a bad scene,
// an output that is not .yaml/.yml, is a folder or whose folder is missing, the output being the
// scene itself or a file it reads (exit status 2); a failed write (1). Existing files of the PLY
// names (OUTPUT-STEM_mesh1.ply, ...) are replaced.
ConvertResult convertScene(const ConvertSpec& spec);

}  // namespace glint
