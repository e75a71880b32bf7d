#include "glint/readers/yaml_scene_reader.h"

#include <set>
#include <string>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

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

// How deep `include`s may nest (the scene file's own includes are depth 1). Each level reads its
// file on the stack of the one that includes it: a chain of thousands of files exhausted the stack
// (a crash); POV-Ray allows 10 levels, 64 leaves room for any library layout.
constexpr std::size_t kMaxIncludeDepth = 64;

// The files being read through `include`, outermost first (to find cycles), and the cancel flag.
struct IncludeState {
  std::vector<std::filesystem::path> open;  // weakly canonical paths
  // Files already included (weakly canonical): one reached again — two libraries that both include
  // a palette — adds nothing a second time (an included file holds only named definitions, and
  // the same definitions from the same place are not two).
  std::set<std::filesystem::path> included;
  const std::atomic<bool>* cancel = nullptr;
};

// A YAML file read whole into a document; a file that cannot be opened throws SceneError (naming
// only the file), one that is not YAML yaml::SyntaxError.
yaml::Document readYamlFile(const std::filesystem::path& path, const std::string& name,
                            const std::atomic<bool>* cancel);

// The keys of a scene file's top level, and the ones an included file may hold too.
const std::vector<std::string_view> kSceneKeys = {
    "name",     "background", "ambient", "fog",    "camera",  "image", "render",
    "textures", "materials",  "objects", "lights", "include", "groups"};
const std::vector<std::string_view> kIncludedKeys = {"include", "textures", "materials", "groups"};

// The sections of the top-level mapping as entities.
class TopLevel {
 public:
  TopLevel(SceneDescription& scene, std::uint32_t file, Diagnostics& sink, IncludeState& includes,
           bool included = false)
      : scene_(scene),
        file_(file),
        source_(*scene.files[file]),
        reader_(source_.source(), sink),
        sink_(sink),
        includes_(includes),
        included_(included) {}

  void read(ValueId root) {
    ParameterDictionary top(reader_, root, {"at the top level", "", "the scene"});
    if (included_) {
      // What only a scene file holds, named as such rather than as an unknown key.
      top.declare(kIncludedKeys);
      for (const std::string_view key : kSceneKeys) {
        if (top.isDeclared(key) || !top.has(key)) continue;
        top.error(top.keyPlace(key),
                  fmt::format("'{}' belongs in the scene file: an included file holds textures, "
                              "materials, groups and further includes only",
                              key));
        top.markUsed({key});
      }
      includes(top);
      named(top, "textures", "texture", EntityKind::TextureEntity);
      named(top, "materials", "material", EntityKind::MaterialEntity);
      named(top, "groups", "group", EntityKind::GroupEntity);
      top.finish();
      return;
    }
    top.declare(kSceneKeys);
    for (const char* key : {"camera", "image"}) {
      if (!top.has(key)) {
        sink_.error(startOf(source_), fmt::format("the scene is missing required key '{}'", key));
      }
    }
    includes(top);
    if (const auto name = top.text("name")) scene_.name = name->where;
    section(top, "background", EntityKind::BackgroundEntity);
    section(top, "ambient", EntityKind::AmbientEntity);
    section(top, "fog", EntityKind::FogEntity);
    section(top, "camera", EntityKind::CameraEntity);
    section(top, "image", EntityKind::ImageEntity);
    section(top, "render", EntityKind::RenderEntity);
    named(top, "textures", "texture", EntityKind::TextureEntity);
    named(top, "materials", "material", EntityKind::MaterialEntity);
    named(top, "groups", "group", EntityKind::GroupEntity);
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

  // `materials`, `textures`: a mapping from names to entities, each named by its key.
  void named(ParameterDictionary& top, std::string_view section, std::string_view what,
             EntityKind kind) {
    const auto e = top.find(section);
    if (!e || tree().isNull(e->value)) return;  // `materials:` with nothing under it: none
    if (!tree().isMap(e->value)) {
      top.error(e->where, fmt::format("{}: expected a mapping from {} names to {}s, got {}",
                                      section, what, what, reader_.describe(e->value)));
      return;
    }
    for (std::size_t i = 0; i < tree().size(e->value); ++i) {
      const ValueId key = tree().key(e->value, i);
      if (!tree().isScalar(key)) {
        reader_.error(
            key, fmt::format("expected a key name in {}, got {}", section, reader_.describe(key)));
        continue;
      }
      if (const std::size_t bytes = tree().scalar(key).size(); bytes > kMaxNameBytes) {
        reader_.error(key,
                      fmt::format("{} name {} is {} bytes long, more than the limit of {}", what,
                                  quoteForMessage(tree().scalar(key)), bytes, kMaxNameBytes));
        continue;
      }
      add(kind, static_cast<std::uint32_t>(i), tree().value(e->value, i), key, key);
    }
  }

  // `include`: a file name or a list of them, each read as a file of materials (and includes) of
  // its own; relative names start at this file's folder.
  void includes(ParameterDictionary& top) {
    const auto e = top.find("include");
    if (!e || tree().isNull(e->value)) return;
    std::vector<std::pair<ValueId, ValueId>> names;  // (value, place)
    if (tree().isScalar(e->value)) {
      names.emplace_back(e->value, e->value);
    } else if (tree().isList(e->value)) {
      for (std::size_t i = 0; i < tree().size(e->value); ++i) {
        names.emplace_back(tree().item(e->value, i), reader_.itemPlace(e->value, e->where, i));
      }
    } else {
      top.error(e->where, fmt::format("include: expected a file name or a list of file names, "
                                      "got {}",
                                      reader_.describe(e->value)));
      return;
    }
    for (const auto& [value, place] : names) {
      if (!tree().isScalar(value) || tree().scalar(value).empty()) {
        reader_.error(
            place, fmt::format("include: expected a file name, got {}", reader_.describe(value)));
        continue;
      }
      include(std::string(tree().scalar(value)), place);
    }
  }

  void include(const std::string& written, ValueId place) {
    namespace fs = std::filesystem;
    const fs::path path = fs::path(written).is_relative()
                              ? (source_.baseDirectory / written).lexically_normal()
                              : fs::path(written);
    // open holds the scene file and each file whose includes are being read.
    if (includes_.open.size() > kMaxIncludeDepth) {
      reader_.error(place,
                    fmt::format("cannot include '{}': includes nest more than {} files "
                                "deep (from {})",
                                escapeForMessage(written), kMaxIncludeDepth,
                                escapeForMessage(includes_.open.front().filename().string())));
      return;
    }
    std::error_code ignored;
    const fs::path identity = fs::weakly_canonical(path, ignored);
    for (std::size_t i = 0; i < includes_.open.size(); ++i) {
      if (includes_.open[i] != identity) continue;
      std::string chain;
      for (std::size_t j = i; j < includes_.open.size(); ++j) {
        chain += includes_.open[j].filename().string() + " -> ";
      }
      reader_.error(place, fmt::format("include cycle: {}{}", escapeForMessage(chain),
                                       escapeForMessage(identity.filename().string())));
      return;
    }
    if (includes_.included.contains(identity)) return;
    const std::string name = path.string();
    yaml::Document document;
    try {
      document = readYamlFile(path, name, includes_.cancel);
    } catch (const SceneError& e) {
      std::string reason = e.diagnostics().empty() ? e.what() : e.diagnostics()[0].message;
      if (reason.rfind("cannot open file: ", 0) == 0) reason.erase(0, 18);
      reader_.error(place,
                    fmt::format("cannot include '{}': {}", escapeForMessage(written), reason));
      return;
    } catch (const yaml::SyntaxError& e) {
      // The file joins the description all the same, so its errors sort after its includer's.
      scene_.addFile(name, path.parent_path());
      const TextPosition p = e.where();
      sink_.error({name, p.line == 0 ? 1 : static_cast<int>(p.line),
                   p.line == 0 ? 1 : static_cast<int>(p.column)},
                  e.what());
      return;
    }
    SourceFile& file = scene_.addFile(name, path.parent_path());
    includes_.included.insert(identity);
    file.values = std::move(document.values);
    file.bytes = document.bytesRead;
    const auto index = static_cast<std::uint32_t>(scene_.files.size() - 1);
    if (document.secondDocument) {
      const TextPosition& second = *document.secondDocument;
      sink_.error(second.line == 0 ? SourceLocation{name, 1, 1}
                                   : SourceLocation{name, static_cast<int>(second.line),
                                                    static_cast<int>(second.column)},
                  "the file holds more than one YAML document (the second starts here); an "
                  "included file holds exactly one");
    }
    const ValueId root = document.root;
    if (file.values.isNull(root)) return;  // an empty file includes nothing
    if (!file.values.isMap(root)) {
      sink_.error({name, 1, 1}, fmt::format("an included file must be a mapping (of {}), got {}",
                                            fmt::join(kIncludedKeys, ", "),
                                            ValueReader(file.source(), sink_).describe(root)));
      return;
    }
    includes_.open.push_back(identity);
    TopLevel(scene_, index, sink_, includes_, true).read(root);
    includes_.open.pop_back();
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
  IncludeState& includes_;
  bool included_;
};

// The read document → entities, or the one error that stopped the reading.
ParseResult describe(SceneDescription scene, yaml::Document* document,
                     const yaml::SyntaxError* failure, const std::atomic<bool>* cancel) {
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
      IncludeState includes{{}, {}, cancel};
      std::error_code ignored;
      includes.open.push_back(std::filesystem::weakly_canonical(file.name, ignored));
      TopLevel(scene, 0, sink, includes).read(root);
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
    return describe(std::move(scene), &document, nullptr, cancel);
  } catch (const yaml::SyntaxError& e) {
    return describe(std::move(scene), nullptr, &e, cancel);
  }
}

namespace {

yaml::Document readYamlFile(const std::filesystem::path& path, const std::string& name,
                            const std::atomic<bool>* cancel) {
  const auto tooLarge = [&name]() {
    return SceneError({{Diagnostic::Severity::Error,
                        {name, 0, 0},
                        "the file is larger than 256 MiB; a scene file holds a scene description "
                        "(meshes belong in their own files)"}});
  };
  const ReadableFile opened = openRegularFile(path, name);
  if (opened.size > kMaxSceneFileBytes) throw tooLarge();
  try {
    return yaml::readFile(opened.fd, kMaxSceneFileBytes, {}, cancel);
  } catch (const yaml::SyntaxError& e) {
    // A file that grew past the limit while it was read.
    if (e.kind() == yaml::SyntaxError::Kind::Refused && e.where().line == 0 && *e.what() == '\0') {
      throw tooLarge();
    }
    throw;
  } catch (const std::system_error& e) {
    throw SceneError(
        {{Diagnostic::Severity::Error, {name, 0, 0}, "cannot open file: " + e.code().message()}});
  }
}

}  // namespace

ParseResult readSceneFile(const std::filesystem::path& path, const std::string& name,
                          const std::atomic<bool>* cancel) {
  std::filesystem::path base = path.parent_path();
  if (base.empty()) base = ".";
  SceneDescription scene = emptyScene(name, base);
  try {
    yaml::Document document = readYamlFile(path, name, cancel);
    return describe(std::move(scene), &document, nullptr, cancel);
  } catch (const yaml::SyntaxError& e) {
    return describe(std::move(scene), nullptr, &e, cancel);
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
