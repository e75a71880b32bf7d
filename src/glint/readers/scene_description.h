// SceneDescription: a scene as plain data — the files it was read from, with their values, and the
// entities (camera, image, render settings, ambient light, background, textures, materials,
// objects, lights)
// whose parameters are mappings of those values, each value with its file:line:col. Readers fill
// it (YAML, and later other formats); the factories (factories/scene_builder) turn it into
// SceneParts. No render types here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "glint/readers/diagnostics.h"
#include "glint/readers/parameter_dictionary.h"
#include "glint/readers/value_tree.h"

namespace glint {

struct MeshFile;  // mesh/mesh_file.h

enum class EntityKind : std::uint8_t {
  CameraEntity,
  ImageEntity,   // the film: size, samples, encoding, grid, adaptive sampling
  RenderEntity,  // the integrator's settings
  AmbientEntity,
  BackgroundEntity,
  MaterialEntity,  // a named material of `materials`
  TextureEntity,   // a named texture of `textures`
  ObjectEntity,    // an entry of `objects`; its `type` names its factory
  LightEntity,     // an entry of `lights`; its `type` names its factory
  FogEntity,       // distance fog
  GroupEntity,     // a named group of `groups` (its value: the list of its objects)
};

// One text a scene was read from.
struct SourceFile {
  std::string name;                     // as the user gave it, for messages
  std::filesystem::path baseDirectory;  // relative paths inside the file resolve from here
  ValueTree values;
  std::uint64_t bytes = 0;

  SourceText source() const { return {&values, &name}; }
  SourceLocation location(ValueId id) const { return source().location(id); }
};

struct Entity {
  EntityKind kind = EntityKind::ObjectEntity;
  std::uint32_t file = 0;    // index into SceneDescription::files
  std::uint32_t index = 0;   // position in its list (objects[i], lights[i]) or section
  ValueId value = kNoValue;  // its mapping of parameters, or its single value (a background colour)
  ValueId place = kNoValue;  // where messages put it: its value, or its key or list when empty
  ValueId type = kNoValue;   // objects, lights: the value of its `type` key, if any
  ValueId name = kNoValue;   // materials, textures, groups: its name (the key in its section)
};

struct SceneDescription {
  std::vector<std::unique_ptr<SourceFile>> files;  // [0]: the scene file itself
  std::vector<Entity> entities;                    // in file order
  ValueId name = kNoValue;                         // the top-level `name` (in files[0])
  bool complete = true;                            // false when the reader reported an error
  // A bare mesh file's quick look (factories/quick_look.h): no scene file, so the files the model
  // names are judged against the model's own folder.
  bool bareMeshFile = false;
  // Mesh files the reader has read already (the quick look reads its model to frame it), by the
  // path it read: the builder takes them as read instead of reading them again.
  std::vector<std::pair<std::filesystem::path, std::shared_ptr<const MeshFile>>> readMeshFiles;

  // A new file; its index is files.size() - 1.
  SourceFile& addFile(std::string fileName, std::filesystem::path baseDirectory);
  const SourceFile& fileOf(const Entity& e) const { return *files[e.file]; }
  // The first entity of `kind`, or nullptr.
  const Entity* first(EntityKind kind) const;
  std::size_t count(EntityKind kind) const;
  // The scalar text of an entity's type or name value ("" when absent or not text).
  std::string_view text(const Entity& e, ValueId id) const;
  // The value of `key` in an entity's mapping, or kNoValue; for tests and tools.
  ValueId parameter(const Entity& e, std::string_view key) const;
  SourceLocation location(const Entity& e, ValueId id) const { return fileOf(e).location(id); }
};

}  // namespace glint
