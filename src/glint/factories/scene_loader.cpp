#include "glint/factories/scene_loader.h"

#include <algorithm>
#include <cctype>
#include <functional>
#include <map>
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

// File order: by file (the scene first, then the files it includes, in the order they were
// read), then line and column.
struct InFileOrder {
  std::map<std::string, std::size_t> fileIndex;
  std::size_t indexOf(const std::string& file) const {
    const auto it = fileIndex.find(file);
    return it == fileIndex.end() ? 0 : it->second;
  }
  bool operator()(const Diagnostic& a, const Diagnostic& b) const {
    const std::size_t fa = indexOf(a.where.file), fb = indexOf(b.where.file);
    if (fa != fb) return fa < fb;
    if (a.where.line != b.where.line) return a.where.line < b.where.line;
    return a.where.column < b.where.column;
  }
};

LoadedScene build(const ParseResult& parsed, const LoadOptions& options) {
  BuildOptions buildOptions;
  buildOptions.imageMemoryBudget = options.memoryBudget;
  buildOptions.overrides = options.overrides;
  buildOptions.cancel = options.cancel;
  BuildResult built = buildScene(parsed.description, buildOptions);

  std::vector<Diagnostic> errors;
  std::vector<Diagnostic> warnings;
  for (const std::vector<Diagnostic>* list :
       {&parsed.diagnostics, static_cast<const std::vector<Diagnostic>*>(&built.diagnostics)}) {
    for (const Diagnostic& d : *list) {
      (d.severity == Diagnostic::Severity::Error ? errors : warnings).push_back(d);
    }
  }
  // The reader and the builder each report in their own walk of the file.
  InFileOrder before;
  for (std::size_t i = 0; i < parsed.description.files.size(); ++i) {
    before.fileIndex.emplace(parsed.description.files[i]->name, i);
  }
  std::stable_sort(errors.begin(), errors.end(), std::cref(before));
  std::stable_sort(warnings.begin(), warnings.end(), std::cref(before));
  if (!errors.empty()) throw SceneError(std::move(errors));
  const SourceFile& scene = *parsed.description.files.at(0);
  for (std::size_t i = 1; i < parsed.description.files.size(); ++i) {
    built.parts.includedFiles.emplace_back(parsed.description.files[i]->name);
  }
  return LoadedScene{std::move(built.parts), std::move(warnings), scene.bytes};
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
