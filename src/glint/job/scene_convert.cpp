#include "glint/job/scene_convert.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/core/atomic_file.h"
#include "glint/core/cancel.h"
#include "glint/factories/scene_loader.h"
#include "glint/job/job_error.h"
#include "glint/job/output_paths.h"
#include "glint/writers/yaml_scene_writer.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

fs::path outputFor(const ConvertSpec& spec) {
  if (!spec.output.empty()) return spec.output;
  return fs::path(spec.scene.stem().string() + ".yaml");
}

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// Refuses, as a bad argument (exit status 2), a name the conversion cannot write a file under
// (the output scene, checked before the scene is read, or a PLY file): output_paths' reasons.
void checkTarget(const fs::path& target) {
  if (const std::string problem = targetProblem(target); !problem.empty()) {
    throw JobError(JobFailure::BadInput,
                   fmt::format("{}: cannot write: {}", target.string(), problem));
  }
}

void checkOutput(const fs::path& output, const fs::path& scene) {
  const std::string extension = lowercase(output.extension().string());
  // The scene is written in YAML's flow style, which is not JSON: a .json name would mislead.
  if (extension != ".yaml" && extension != ".yml") {
    throw JobError(JobFailure::BadInput,
                   fmt::format("{}: the converted scene is YAML (not JSON); name it .yaml or .yml",
                               output.string()));
  }
  checkTarget(output);
  std::error_code error;
  if (fs::exists(output, error) && sameFile(output, scene)) {
    throw JobError(JobFailure::BadInput,
                   fmt::format("{}: the output is the scene being converted; choose another name",
                               output.string()));
  }
}

// Whether `target` is one of the files the scene reads (by name, or the same file by another).
bool readByScene(const fs::path& target, const std::vector<fs::path>& inputs) {
  return std::any_of(inputs.begin(), inputs.end(),
                     [&](const fs::path& input) { return sameFile(target, input); });
}

// Writes every file (the meshes, then the scene) or none: each is written whole to a temporary
// file first, and only when all are complete are they renamed over their targets, with
// `committing` true meanwhile (the CLI then lets no signal end the process: a set half renamed
// would mix old and new files). A cancel seen before the renames writes nothing.
void writeAllOrNothing(const std::vector<std::pair<fs::path, const std::string*>>& files,
                       const ConvertSpec& spec) {
  std::vector<std::unique_ptr<AtomicFile>> written;
  const fs::path* current = nullptr;
  try {
    for (const auto& [target, bytes] : files) {
      throwIfCancelled(spec.cancel);
      current = &target;
      written.push_back(std::make_unique<AtomicFile>(target));
      written.back()->write(*bytes);
      written.back()->close(true);
    }
    if (spec.committing) spec.committing(true);
    struct EndCommit {
      const ConvertSpec& spec;
      ~EndCommit() {
        if (spec.committing) spec.committing(false);
      }
    } endCommit{spec};
    throwIfCancelled(spec.cancel);
    for (const std::unique_ptr<AtomicFile>& file : written) {
      current = &file->target();
      file->commit();
    }
  } catch (const std::system_error& e) {
    throw JobError(JobFailure::Failure,
                   fmt::format("{}: cannot write: {}", current->string(), e.code().message()));
  }
}

}  // namespace

ConvertResult convertScene(const ConvertSpec& spec) {
  ConvertResult result;
  result.output = outputFor(spec);
  checkOutput(result.output, spec.scene);
  LoadOptions options;
  options.cancel = spec.cancel;
  ParseResult parsed;
  try {
    parsed = describeSceneFile(spec.scene, options);
    LoadedScene loaded = buildDescribedScene(parsed, options);
    result.warnings = std::move(loaded.warnings);
    result.objects = parsed.description.count(EntityKind::ObjectEntity);
    result.lights = parsed.description.count(EntityKind::LightEntity);
    SceneWriteOptions write;
    write.sourceName = spec.scene.filename().string();
    const WrittenScene written = writeSceneYaml(parsed.description, result.output, write);
    // An included file, a mesh or a texture named as the output would be replaced by the scene
    // that reads it.
    if (readByScene(result.output, written.inputs)) {
      throw JobError(JobFailure::BadInput,
                     fmt::format("{}: the scene being converted reads this file; choose another "
                                 "name",
                                 result.output.string()));
    }
    fs::path folder = result.output.parent_path();
    std::vector<std::pair<fs::path, const std::string*>> files;
    for (const WrittenScene::File& file : written.files) {
      files.emplace_back(folder / file.name, &file.bytes);
      checkTarget(files.back().first);
      // The writer skipped names the scene reads; this catches the same file reached another way
      // (a symbolic link, a hard link).
      if (readByScene(files.back().first, written.inputs)) {
        throw JobError(JobFailure::BadInput,
                       fmt::format("{}: the scene being converted reads this file; choose another "
                                   "name for the output",
                                   files.back().first.string()));
      }
    }
    files.emplace_back(result.output, &written.yaml);
    writeAllOrNothing(files, spec);
    for (std::size_t i = 0; i + 1 < files.size(); ++i) result.meshFiles.push_back(files[i].first);
  } catch (const SceneError& error) {
    throw JobError(error);
  } catch (const Cancelled&) {
    result.interrupted = true;
  }
  return result;
}

}  // namespace glint
