#include "glint/readers/yaml_scene_reader.h"

#include <string>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include "glint/readers/parameter_dictionary.h"
#include "glint/readers/source_file.h"
#include "glint/readers/yaml_reader.h"

namespace glint {

bool ParseResult::hasErrors() const { return glint::hasErrors(diagnostics); }

namespace {

SourceLocation startOf(const SourceFile& file) { return {file.name, 1, 1}; }

// The value of `key` in `map`, or kNoValue (the first occurrence; duplicates are the dictionary's
// to report).
ValueId findKey(const ValueTree& tree, ValueId map, std::string_view key) {
  for (std::size_t i = 0; i < tree.size(map); ++i) {
    if (tree.isScalar(tree.key(map, i)) && tree.scalar(tree.key(map, i)) == key) {
      return tree.value(map, i);
    }
  }
  return kNoValue;
}

// The sections of the top-level mapping as entities.
class TopLevel {
 public:
  TopLevel(SceneDescription& scene, std::uint32_t file, Diagnostics& sink)
      : scene_(scene),
        file_(file),
        source_(*scene.files[file]),
        reader_(source_.source(), sink),
        sink_(sink) {}

  void read(ValueId root) {
    ParameterDictionary top(reader_, root, {"at the top level", "", "the scene"});
    top.declare({"name", "background", "ambient", "fog", "camera", "image", "render", "materials",
                 "objects", "lights"});
    for (const char* key : {"camera", "image"}) {
      if (!top.has(key)) {
        sink_.error(startOf(source_), fmt::format("the scene is missing required key '{}'", key));
      }
    }
    if (const auto name = top.text("name")) scene_.name = name->where;
    section(top, "background", EntityKind::BackgroundEntity);
    section(top, "ambient", EntityKind::AmbientEntity);
    section(top, "fog", EntityKind::FogEntity);
    section(top, "camera", EntityKind::CameraEntity);
    section(top, "image", EntityKind::ImageEntity);
    section(top, "render", EntityKind::RenderEntity);
    materials(top);
    list(top, "objects", "objects", EntityKind::ObjectEntity);
    list(top, "lights", "lights", EntityKind::LightEntity);
    top.finish();
  }

 private:
  const ValueTree& tree() const { return source_.values; }

  void add(EntityKind kind, std::uint32_t index, ValueId value, ValueId place,
           ValueId name = kNoValue) {
    Entity e;
    e.kind = kind;
    e.file = file_;
    e.index = index;
    e.value = value;
    e.place = tree().isNull(value) ? place : value;
    e.name = name;
    if (tree().isMap(value)) e.type = findKey(tree(), value, "type");
    scene_.entities.push_back(e);
  }

  // A section holding one entity (camera: {...}); an empty one is still an entity, reported by
  // its factory as not a mapping.
  void section(ParameterDictionary& top, std::string_view key, EntityKind kind) {
    if (const auto e = top.find(key)) add(kind, 0, e->value, e->key);
  }

  // `materials`: a mapping from names to materials, each an entity named by its key.
  void materials(ParameterDictionary& top) {
    const auto e = top.find("materials");
    if (!e || tree().isNull(e->value)) return;  // `materials:` with nothing under it: none
    if (!tree().isMap(e->value)) {
      top.error(e->where, fmt::format("materials: expected a mapping from material names to "
                                      "materials, got {}",
                                      reader_.describe(e->value)));
      return;
    }
    for (std::size_t i = 0; i < tree().size(e->value); ++i) {
      const ValueId key = tree().key(e->value, i);
      if (!tree().isScalar(key)) {
        reader_.error(
            key, fmt::format("expected a key name in materials, got {}", reader_.describe(key)));
        continue;
      }
      add(EntityKind::MaterialEntity, static_cast<std::uint32_t>(i), tree().value(e->value, i), key,
          key);
    }
  }

  // `objects`, `lights`: lists of entities.
  void list(ParameterDictionary& top, std::string_view key, std::string_view what,
            EntityKind kind) {
    const auto e = top.find(key);
    if (!e || tree().isNull(e->value)) return;
    if (!tree().isList(e->value)) {
      top.error(e->where, fmt::format("{}: expected a list of {}, got {}", key, what,
                                      reader_.describe(e->value)));
      return;
    }
    for (std::size_t i = 0; i < tree().size(e->value); ++i) {
      add(kind, static_cast<std::uint32_t>(i), tree().item(e->value, i), e->value);
    }
  }

  SceneDescription& scene_;
  std::uint32_t file_;
  const SourceFile& source_;
  ValueReader reader_;
  Diagnostics& sink_;
};

// The read document → entities, or the one error that stopped the reading.
ParseResult describe(SceneDescription scene, yaml::Document* document,
                     const yaml::SyntaxError* failure) {
  ParseResult result;
  Diagnostics sink;
  SourceFile& file = *scene.files[0];
  const auto at = [&](const TextPosition& p) {
    return p.line == 0
               ? startOf(file)
               : SourceLocation{file.name, static_cast<int>(p.line), static_cast<int>(p.column)};
  };
  if (failure != nullptr) {
    sink.error(at(failure->where()), failure->what());
  } else {
    file.values = std::move(document->values);
    file.fnv1a = document->fnv1a;
    file.bytes = document->bytesRead;
    if (document->secondDocument) {
      sink.error(at(*document->secondDocument),
                 "the file holds more than one YAML document (the second starts here); a "
                 "scene file holds exactly one");
    }
    const ValueId root = document->root;
    const ValueReader reader(file.source(), sink);
    if (file.values.isNull(root)) {
      sink.error(startOf(file), "the file is empty; a scene needs at least 'camera' and 'image'");
    } else if (!file.values.isMap(root)) {
      sink.error(startOf(file), fmt::format("a scene file must be a mapping of keys (camera, "
                                            "image, objects, ...), got {}",
                                            reader.describe(root)));
    } else {
      TopLevel(scene, 0, sink).read(root);
    }
  }
  scene.complete = !sink.hasErrors();
  result.description = std::move(scene);
  result.diagnostics = sink.take();
  return result;
}

SceneDescription emptyScene(const std::string& name, const std::filesystem::path& baseDirectory) {
  SceneDescription scene;
  scene.addFile(name, baseDirectory);
  return scene;
}

}  // namespace

ParseResult parseScene(std::string_view text, const std::string& file,
                       const std::filesystem::path& baseDirectory,
                       const std::atomic<bool>* cancel) {
  SceneDescription scene = emptyScene(file, baseDirectory);
  try {
    yaml::Document document = yaml::read(text, {}, cancel);
    return describe(std::move(scene), &document, nullptr);
  } catch (const yaml::SyntaxError& e) {
    return describe(std::move(scene), nullptr, &e);
  }
}

ParseResult readSceneFile(const std::filesystem::path& path, const std::string& name,
                          const std::atomic<bool>* cancel) {
  const auto tooLarge = [&name]() {
    return SceneError({{Diagnostic::Severity::Error,
                        {name, 0, 0},
                        "the file is larger than 256 MiB; a scene file holds a scene description "
                        "(meshes belong in their own files)"}});
  };
  const ReadableFile opened = openRegularFile(path, name);
  if (opened.size > kMaxSceneFileBytes) throw tooLarge();
  std::filesystem::path base = path.parent_path();
  if (base.empty()) base = ".";
  SceneDescription scene = emptyScene(name, base);
  try {
    yaml::Document document = yaml::readFile(opened.fd, kMaxSceneFileBytes, {}, cancel);
    return describe(std::move(scene), &document, nullptr);
  } catch (const yaml::SyntaxError& e) {
    // A file that grew past the limit while it was read.
    if (e.kind() == yaml::SyntaxError::Kind::Refused && e.where().line == 0 && *e.what() == '\0') {
      throw tooLarge();
    }
    return describe(std::move(scene), nullptr, &e);
  } catch (const std::system_error& e) {
    throw SceneError(
        {{Diagnostic::Severity::Error, {name, 0, 0}, "cannot open file: " + e.code().message()}});
  }
}

// --- SceneDescription ------------------------------------------------------------------------

SourceFile& SceneDescription::addFile(std::string fileName, std::filesystem::path baseDirectory) {
  auto file = std::make_unique<SourceFile>();
  file->name = std::move(fileName);
  file->baseDirectory = std::move(baseDirectory);
  files.push_back(std::move(file));
  return *files.back();
}

const Entity* SceneDescription::first(EntityKind kind) const {
  for (const Entity& e : entities) {
    if (e.kind == kind) return &e;
  }
  return nullptr;
}

std::size_t SceneDescription::count(EntityKind kind) const {
  std::size_t n = 0;
  for (const Entity& e : entities) n += e.kind == kind ? 1 : 0;
  return n;
}

std::string_view SceneDescription::text(const Entity& e, ValueId id) const {
  return fileOf(e).values.scalar(id);
}

ValueId SceneDescription::parameter(const Entity& e, std::string_view key) const {
  const ValueTree& tree = fileOf(e).values;
  return tree.isMap(e.value) ? findKey(tree, e.value, key) : kNoValue;
}

}  // namespace glint
