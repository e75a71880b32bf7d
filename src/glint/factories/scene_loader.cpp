#include "glint/factories/scene_loader.h"

#include <algorithm>
#include <cctype>
#include <string>
#include <utility>
#include <vector>

#include "glint/factories/quick_look.h"
#include "glint/factories/scene_builder.h"
#include "glint/readers/nff_reader.h"
#include "glint/readers/tachyon_reader.h"
#include "glint/readers/yaml_scene_reader.h"

namespace glint {
namespace {

// File order: by file (the scene first, then what it includes), then line and column.
bool before(const Diagnostic& a, const Diagnostic& b) {
  if (a.where.line != b.where.line) return a.where.line < b.where.line;
  return a.where.column < b.where.column;
}

LoadedScene build(const ParseResult& parsedScene, const LoadOptions& options) {
  ParseResult parsed;
  parsed.diagnostics = parsedScene.diagnostics;
  const SceneDescription& description = parsedScene.description;
  BuildOptions buildOptions;
  buildOptions.imageMemoryBudget = options.memoryBudget;
  buildOptions.overrides = options.overrides;
  buildOptions.cancel = options.cancel;
  BuildResult built = buildScene(description, buildOptions);

  std::vector<Diagnostic> errors;
  std::vector<Diagnostic> warnings;
  for (std::vector<Diagnostic>* list : {&parsed.diagnostics, &built.diagnostics}) {
    for (Diagnostic& d : *list) {
      (d.severity == Diagnostic::Severity::Error ? errors : warnings).push_back(std::move(d));
    }
  }
  // The reader and the builder each report in their own walk of the file.
  std::stable_sort(errors.begin(), errors.end(), before);
  std::stable_sort(warnings.begin(), warnings.end(), before);
  if (!errors.empty()) throw SceneError(std::move(errors));
  const SourceFile& scene = *description.files.at(0);
  return LoadedScene{std::move(built.parts), std::move(warnings), scene.bytes, scene.fnv1a};
}

}  // namespace

LoadedScene loadSceneFromString(std::string_view text, const std::string& displayName,
                                const std::filesystem::path& baseDirectory,
                                const LoadOptions& options) {
  return build(parseScene(text, displayName, baseDirectory, options.cancel), options);
}

LoadedScene buildDescribedScene(const ParseResult& parsed, const LoadOptions& options) {
  return build(parsed, options);
}

ParseResult describeSceneFile(const std::filesystem::path& file, const LoadOptions& options) {
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".nff") return readNffFile(file, file.string(), options.cancel);
  if (extension == ".dat") return readTachyonFile(file, file.string(), options.cancel);
  if (isQuickLookFile(file)) return describeQuickLook(file, options);
  return readSceneFile(file, file.string(), options.cancel);
}

LoadedScene loadScene(const std::filesystem::path& file, const LoadOptions& options) {
  return build(describeSceneFile(file, options), options);
}

}  // namespace glint
