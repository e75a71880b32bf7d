#include "glint/job/scene_convert.h"

#include <cerrno>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/core/atomic_file.h"
#include "glint/factories/scene_loader.h"
#include "glint/job/job_error.h"
#include "glint/writers/yaml_scene_writer.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

fs::path outputFor(const ConvertSpec& spec) {
  if (!spec.output.empty()) return spec.output;
  return fs::path(spec.scene.stem().string() + ".yaml");
}

void checkOutput(const fs::path& output, const fs::path& scene) {
  const std::string extension = output.extension().string();
  // The scene is written in YAML's flow style, which is not JSON: a .json name would mislead.
  if (extension != ".yaml" && extension != ".yml") {
    throw JobError(JobFailure::BadInput,
                   fmt::format("{}: the converted scene is YAML (not JSON); name it .yaml or .yml",
                               output.string()));
  }
  fs::path folder = output.parent_path();
  if (folder.empty()) folder = ".";
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    throw JobError(JobFailure::BadInput, fmt::format("{}: the folder {} does not exist",
                                                     output.string(), folder.string()));
  }
  if (fs::exists(output, error) && fs::equivalent(output, scene, error)) {
    throw JobError(JobFailure::BadInput,
                   fmt::format("{}: the output is the scene being converted; choose another name",
                               output.string()));
  }
}

// Writes every file (the meshes, then the scene) or none: each is written whole to a temporary
// file first, and only when all are complete are they renamed over their targets. A target that
// is a folder is refused before anything is written (the rename would fail after the others).
void writeAllOrNothing(const std::vector<std::pair<fs::path, const std::string*>>& files) {
  std::vector<std::unique_ptr<AtomicFile>> written;
  for (const auto& [target, bytes] : files) {
    std::error_code error;
    if (fs::is_directory(target, error)) {
      throw JobError(JobFailure::Failure,
                     fmt::format("{}: cannot write: it is a folder", target.string()));
    }
  }
  const fs::path* current = nullptr;
  try {
    for (const auto& [target, bytes] : files) {
      current = &target;
      written.push_back(std::make_unique<AtomicFile>(target));
      written.back()->write(*bytes);
      written.back()->close(true);
    }
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
  } catch (const SceneError& error) {
    throw JobError(error);
  }
  SceneWriteOptions write;
  write.sourceName = spec.scene.filename().string();
  const WrittenScene written = writeSceneYaml(parsed.description, result.output, write);
  fs::path folder = result.output.parent_path();
  std::vector<std::pair<fs::path, const std::string*>> files;
  for (const WrittenScene::File& file : written.files) {
    files.emplace_back(folder / file.name, &file.bytes);
  }
  files.emplace_back(result.output, &written.yaml);
  writeAllOrNothing(files);
  for (std::size_t i = 0; i + 1 < files.size(); ++i) result.meshFiles.push_back(files[i].first);
  return result;
}

}  // namespace glint
