#include "glint/job/scene_convert.h"

#include <cerrno>
#include <system_error>

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
  if (extension != ".yaml" && extension != ".yml" && extension != ".json") {
    throw JobError(JobFailure::BadInput,
                   fmt::format("{}: the converted scene is YAML; name it .yaml (or .yml, .json)",
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

void writeAtomically(const fs::path& target, const std::string& bytes) {
  try {
    AtomicFile file(target);
    file.write(bytes);
    file.close(true);
    file.commit();
  } catch (const std::system_error& e) {
    throw JobError(JobFailure::Failure,
                   fmt::format("{}: cannot write: {}", target.string(), e.code().message()));
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
  for (const WrittenScene::File& file : written.files) {
    const fs::path path = folder / file.name;
    writeAtomically(path, file.bytes);
    result.meshFiles.push_back(path);
  }
  writeAtomically(result.output, written.yaml);
  return result;
}

}  // namespace glint
