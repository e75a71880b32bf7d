#include "glint/factories/scene_builder.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "glint/core/cancel.h"
#include "glint/core/transform.h"
#include "glint/factories/csg_factory.h"
#include "glint/factories/light_factories.h"
#include "glint/factories/material_factory.h"
#include "glint/factories/mesh_textures.h"
#include "glint/factories/object_factories.h"
#include "glint/factories/quick_look.h"
#include "glint/factories/settings_factories.h"
#include "glint/factories/texture_library.h"
#include "glint/factories/transform_reader.h"
#include "glint/geometry/object_space.h"
#include "glint/geometry/surface_coordinates.h"
#include "glint/mesh/mesh_loader.h"
#include "glint/readers/spelling.h"

namespace glint {

bool BuildResult::hasErrors() const { return glint::hasErrors(diagnostics); }

namespace {

// Entities between polls of the cancel flag.
constexpr std::size_t kEntitiesPerPoll = 1024;
// Objects that reflect no light get a warning each up to this many; the rest are counted.
constexpr std::size_t kMaxDarkObjectWarnings = 5;

// `type: instance` is listed and its keys checked like the shapes' types, but the builder places
// it itself (buildInstance): it makes no geometry of its own.
const ObjectFactory kInstanceFactory{"instance", {"group"}, nullptr};

// What an object's `material` key chose.
struct MaterialChoice {
  std::uint32_t index = 0;  // into SceneParts::materials; 0 = the default material
  bool given = false;       // a name or an inline mapping (a mesh then ignores its file's own)
  std::optional<Color> emission;  // the material's `emission`, if it has one
};

class Builder {
 public:
  Builder(const SceneDescription& description, const BuildOptions& options, BuildResult& result)
      : d_(description),
        options_(options),
        parts_(result.parts),
        ctx_{options, sink_, result.parts, Encoding::Srgb, false, {}, nullptr},
        result_(result),
        textures_(description, ctx_, [this] {
          return static_cast<double>(filmBytes(parts_.image.width, parts_.image.height)) +
                 meshCache_.meshBytes();
        }) {
    ctx_.textures = &textures_;
    for (const auto& [path, file] : description.readMeshFiles) meshCache_.adopt(path, file);
    for (const ObjectFactory& f : objectFactories()) objectTypes_.push_back(f.type);
    objectTypes_.push_back(csgFactory_.type);
    objectTypes_.push_back(kInstanceFactory.type);
    for (const ObjectFactory& f : options_.extraObjectFactories) objectTypes_.push_back(f.type);
    for (const LightFactory& f : lightFactories()) lightTypes_.push_back(f.type);
  }

  void build() {
    const SourceFile& main = *d_.files.at(0);
    parts_.name = d_.name != kNoValue ? std::string(main.values.scalar(d_.name))
                                      : std::filesystem::path(main.name).filename().string();
    if (const Entity* image = d_.first(EntityKind::ImageEntity)) {
      buildImage(d_, *image, ctx_);
    } else if (d_.complete) {
      sink_.error({main.name, 1, 1}, "the scene is missing required key 'image'");
    }
    if (const Entity* render = d_.first(EntityKind::RenderEntity)) buildRender(d_, *render, ctx_);
    applyRenderOverrides(parts_.render, options_.overrides);
    for (const Entity& e : d_.entities) {
      if (e.kind == EntityKind::TextureEntity) textures_.buildNamed(e);
    }
    if (const Entity* background = d_.first(EntityKind::BackgroundEntity)) {
      buildBackground(d_, *background, ctx_);
    }
    if (const Entity* ambient = d_.first(EntityKind::AmbientEntity))
      buildAmbient(d_, *ambient, ctx_);
    if (const Entity* fog = d_.first(EntityKind::FogEntity)) buildFog(d_, *fog, ctx_);
    if (const Entity* camera = d_.first(EntityKind::CameraEntity)) {
      buildCamera(d_, *camera, ctx_);
    } else if (d_.complete) {
      sink_.error({main.name, 1, 1}, "the scene is missing required key 'camera'");
    }
    for (const Entity& e : d_.entities) {
      if (e.kind == EntityKind::MaterialEntity) buildNamedMaterial(e);
    }
    for (const Entity& e : d_.entities) {
      if (e.kind == EntityKind::GroupEntity) buildGroup(e);
    }
    // Sized once: a Primitive is a few hundred bytes, and growing the array by doubling would copy
    // them all again and again.
    parts_.primitives.reserve(d_.count(EntityKind::ObjectEntity));
    objectPlaces_.reserve(d_.count(EntityKind::ObjectEntity));
    std::size_t built = 0;
    for (const Entity& e : d_.entities) {
      if (++built % kEntitiesPerPoll == 0) throwIfCancelled(options_.cancel);
      if (e.kind == EntityKind::ObjectEntity) buildObject(e);
    }
    for (const Entity& e : d_.entities) {
      if (e.kind == EntityKind::LightEntity) buildLight(e);
    }
    countEnclosedLights();
    warnIfUnlit();
    warnAboutDarkObjects();
    result_.diagnostics = sink_.take();
  }

 private:
  ValueReader readerOf(const Entity& e) { return ValueReader(d_.fileOf(e).source(), sink_); }

  // --- materials ------------------------------------------------------------------------------

  void buildNamedMaterial(const Entity& e) {
    const ValueReader reader = readerOf(e);
    const std::string name(reader.tree().scalar(e.name));
    if (const auto it = materialIndex_.find(name); it != materialIndex_.end()) {
      // Both places; the file too when the first is in another one (an included file).
      const auto& [firstFile, first] = materialWhere_[it->second];
      const std::string where =
          firstFile == e.file ? fmt::format("line {}, column {}", first.line, first.column)
                              : fmt::format("{}:{}:{}", escapeForMessage(d_.files[firstFile]->name),
                                            first.line, first.column);
      reader.error(e.name, fmt::format("duplicate material '{}': defined twice (first at {})",
                                       escapeForMessage(name), where));
      return;
    }
    const auto index = static_cast<std::uint32_t>(parts_.materials.size());
    materialIndex_.emplace(name, index);
    materialWhere_[index] = {e.file, reader.tree().position(e.name)};
    const std::string path = "materials." + name;
    auto params = entityParameters(reader, e.value, e.name,
                                   "a mapping of material keys (kd, ks, shininess, kr, kt, ka, "
                                   "ior, reflection_blur, refraction_blur, priority, normal_map, "
                                   "bump_map, bump_scale, emission)",
                                   {"in material '" + name + "'", path, path});
    std::optional<Material> material;
    if (params) {
      std::optional<Color> emission;
      material = readMaterial(*params, ctx_.encoding, &textures_, &emission);
      params->finish();
      if (material && emission) materialEmission_[index] = *emission;
    }
    // Kept even when it has errors, so objects naming it do not also report it undefined.
    parts_.materials.push_back(material.value_or(Material{}));
  }

  MaterialChoice resolveMaterial(ParameterDictionary& params, const std::string& owner) {
    const auto entry = params.find("material");
    if (!entry) return {};
    const ValueReader& reader = params.reader();
    const ValueTree& tree = reader.tree();
    if (tree.isMap(entry->value)) {
      const std::string path = owner + ".material";
      ParameterDictionary inline_(reader, entry->value, {"in " + path, path, path});
      std::optional<Color> emission;
      const std::optional<Material> material =
          readMaterial(inline_, ctx_.encoding, &textures_, &emission);
      inline_.finish();
      if (!material) return {0, true, std::nullopt};
      parts_.materials.push_back(*material);
      return {static_cast<std::uint32_t>(parts_.materials.size() - 1), true, emission};
    }
    if (!tree.isScalar(entry->value)) {
      params.error(entry->where, fmt::format("{}.material: expected a material name or a mapping "
                                             "of material keys, got {}",
                                             owner, reader.describe(entry->value)));
      return {};
    }
    const std::string_view name = tree.scalar(entry->value);
    if (const auto it = materialIndex_.find(name); it != materialIndex_.end()) {
      const auto emission = materialEmission_.find(it->second);
      return {it->second, true,
              emission != materialEmission_.end() ? std::optional<Color>(emission->second)
                                                  : std::nullopt};
    }
    const std::string hint =
        undefinedNameHint(name, materialIndex_, "; no materials are defined", materialHintsLeft_);
    params.error(entry->where, fmt::format("{}.material: undefined material '{}'{}", owner,
                                           nameForMessage(name), hint));
    return {0, true, std::nullopt};
  }

  // --- objects --------------------------------------------------------------------------------

  // The factory an entity's `type` names, or nullptr (reported).
  template <class Factory, class Find>
  const Factory* factoryOf(const ValueReader& reader, const Entity& e, std::string_view family,
                           const std::string& path, const std::vector<std::string_view>& names,
                           Find&& find) {
    const ValueTree& tree = reader.tree();
    if (e.type != kNoValue && tree.isScalar(e.type)) {
      if (const Factory* f = find(tree.scalar(e.type))) return f;
    }
    const std::string list = fmt::format("{}", fmt::join(names, ", "));
    if (e.type == kNoValue) {
      reader.error(e.value,
                   fmt::format("{} is missing required key 'type' (one of: {})", family, list));
      return nullptr;
    }
    if (!tree.isScalar(e.type)) {
      reader.error(
          tree.isNull(e.type) ? e.value : e.type,
          fmt::format("{}.type: expected {} {} type ({}), got {}", path,
                      family == "object" ? "an" : "a", family, list, reader.describe(e.type)));
      return nullptr;
    }
    const std::string_view type = tree.scalar(e.type);
    if (family == "light" && type == "ambient") {
      reader.error(e.type,
                   "ambient light is the top-level key 'ambient' ({color, intensity}), not a light "
                   "type");
      return nullptr;
    }
    reader.error(e.type, fmt::format("unknown {} type {}; expected one of: {}{}", family,
                                     quoteForMessage(type), list, didYouMean(type, names)));
    return nullptr;
  }

  // A degenerate shape (ShapeError) at the value of the parameter it names when that is one of the
  // type's keys — "objects[2] (triangle).vertices are collinear: ..." — else at the entity.
  void reportShapeError(ParameterDictionary& params, const std::vector<std::string_view>& keys,
                        const ShapeError& error, const std::string& prefix) {
    const std::string& parameter = error.parameter();
    const bool isKey = std::find(keys.begin(), keys.end(), parameter) != keys.end();
    if (isKey && params.has(parameter)) {
      params.error(params.find(parameter)->where, prefix + "." + error.what());
    } else {
      params.error(params.place(), prefix + ": " + error.what());
    }
  }

  // --- groups and instances (DESIGN.md §11) ---------------------------------------------------

  // A named group: its objects built as `objects` entries are, into parts_.groups in the group's
  // own space. A name defined twice is an error naming both places (the file too when the first
  // is in another one).
  void buildGroup(const Entity& e) {
    const ValueReader reader = readerOf(e);
    const ValueTree& tree = reader.tree();
    const std::string name(tree.scalar(e.name));
    if (const auto it = groupIndex_.find(name); it != groupIndex_.end()) {
      const auto& [firstFile, first] = groupWhere_[it->second];
      const std::string where =
          firstFile == e.file ? fmt::format("line {}, column {}", first.line, first.column)
                              : fmt::format("{}:{}:{}", escapeForMessage(d_.files[firstFile]->name),
                                            first.line, first.column);
      reader.error(e.name, fmt::format("duplicate group '{}': defined twice (first at {})",
                                       escapeForMessage(name), where));
      return;
    }
    const auto index = static_cast<std::uint32_t>(parts_.groups.size());
    groupIndex_.emplace(name, index);
    groupWhere_.push_back({e.file, tree.position(e.name)});
    parts_.groups.emplace_back();
    if (tree.isNull(e.value)) return;  // `chair:` with nothing under it: an empty group
    if (!tree.isList(e.value)) {
      reader.error(e.value, fmt::format("groups.{}: expected a list of objects, got {}",
                                        escapeForMessage(name), reader.describe(e.value)));
      return;
    }
    for (std::size_t i = 0; i < tree.size(e.value); ++i) {
      Entity member;
      member.kind = EntityKind::ObjectEntity;
      member.file = e.file;
      member.index = static_cast<std::uint32_t>(i);
      member.value = tree.item(e.value, i);
      member.place = member.value;
      if (tree.isMap(member.value)) member.type = typeValue(d_.fileOf(e), member.value);
      group_ = &parts_.groups[index];
      buildObject(member, fmt::format("groups.{}[{}]", escapeForMessage(name), i));
      group_ = nullptr;
    }
  }

  // `type: instance`: a group placed with the object's transform; its material replaces the
  // materials of the group's objects written without one. Instances inside groups are refused
  // (two levels: groups hold shapes and meshes, `objects` places groups), so no group can
  // instance itself.
  void buildInstance(ParameterDictionary& params, const std::string& path,
                     const MaterialChoice& material, const TransformResult& transform) {
    const auto group = params.text("group", Presence::Required);
    if (group_ != nullptr) {
      params.error(params.find("type")->where,
                   fmt::format("{}: an instance cannot be inside a group (instancing has two "
                               "levels: groups hold shapes and meshes, objects place groups)",
                               path));
      return;
    }
    if (!group) return;
    const auto it = groupIndex_.find(group->value);
    if (it == groupIndex_.end()) {
      const std::string hint =
          undefinedNameHint(group->value, groupIndex_, "; no groups are defined", groupHintsLeft_);
      params.error(group->where, fmt::format("instance.group: undefined group '{}'{}",
                                             nameForMessage(group->value), hint));
      return;
    }
    if (params.errors() != 0 || !transform.ok) return;
    const Transform* worldFromGroup =
        transform.worldFromObject ? &*transform.worldFromObject : nullptr;
    const ValueId where =
        params.has("transform") ? params.find("transform")->where : params.find("type")->where;
    try {
      // As a placed object's transform (Primitive): invertible, and the placed group within reach.
      if (worldFromGroup != nullptr) requireInvertibleAffine(*worldFromGroup);
      const Bounds3& local = groupBounds(it->second);
      const double reach = reachOf(worldFromGroup ? (*worldFromGroup)(local) : local);
      if (reach > kMaxCoordinate)
        throw ShapeError("transform", "the placed group " + beyondReach(reach));
      parts_.instances.push_back(makeInstance(
          worldFromGroup, it->second, material.given ? material.index : kNoMaterialOverride));
      if (!material.given) {
        bareInstances_.push_back({params.location(), it->second, parts_.primitives.size()});
      }
      const GroupParts& placed = parts_.groups[it->second];
      if (placed.primitives.empty() && placed.meshes.empty()) {
        sink_.warning(params.location(group->where),
                      fmt::format("instance.group: the group '{}' is empty, so this instance "
                                  "shows nothing",
                                  escapeForMessage(group->value)));
      }
    } catch (const std::invalid_argument& error) {
      params.error(where, fmt::format("instance.transform: {}", error.what()));
    }
  }

  // The bounds of group `g` in its own space (its bounded primitives' and its mesh vertices'),
  // computed once.
  const Bounds3& groupBounds(std::uint32_t g) {
    if (groupBounds_.size() <= g) groupBounds_.resize(parts_.groups.size());
    std::optional<Bounds3>& bounds = groupBounds_[g];
    if (!bounds) {
      Bounds3 b;
      // Bounded content only: a plane reaches everywhere anyway, and its infinite box would hide
      // how far the rest is carried.
      for (const Primitive& p : parts_.groups[g].primitives) {
        if (p.isBounded()) b = unite(b, p.bounds());
      }
      for (const TriangleMesh& mesh : parts_.groups[g].meshes) {
        for (const Point3& q : mesh.positions) b = unite(b, q);
      }
      bounds = b;
    }
    return *bounds;
  }

  void buildObject(const Entity& e) { buildObject(e, fmt::format("objects[{}]", e.index)); }

  // path: how messages name the entry ("objects[3]", "groups.chair[0]").
  void buildObject(const Entity& e, const std::string& path) {
    const ValueReader reader = readerOf(e);
    if (!reader.tree().isMap(e.value)) {
      reader.error(e.place, fmt::format("{}: expected a mapping with a 'type' (sphere, plane, "
                                        "triangle, ...), got {}",
                                        path, reader.describe(e.value)));
      return;
    }
    const ObjectFactory* factory = factoryOf<ObjectFactory>(
        reader, e, "object", path, objectTypes_, [this](std::string_view type) {
          if (type == csgFactory_.type) return &csgFactory_;
          if (type == kInstanceFactory.type) return &kInstanceFactory;
          return findObjectFactory(type, options_.extraObjectFactories);
        });
    if (factory == nullptr) {
      // Without a type the keys cannot be checked; duplicates still are.
      ParameterDictionary(reader, e.value, {"in " + path, path, path}).finish();
      return;
    }
    const std::string type(factory->type);
    ParameterDictionary params(reader, e.value, {"in " + type, type, type});
    params.declareHidden("type");
    params.find("type");
    params.declare(factory->keys);
    if (type == "instance") {
      params.declare({"material", "transform"});  // no emission: its objects have their own
      const MaterialChoice material = resolveMaterial(params, type);
      if (material.emission) {
        // The override replaces its objects' material index only; their emission stays theirs.
        params.error(params.find("material")->where,
                     "instance.material: this material has an emission, which an instance cannot "
                     "give the objects it places (they keep their own); use a material without "
                     "emission, or give the group's objects the material");
      }
      const TransformResult transform = readTransform(params, type);
      buildInstance(params, path, material, transform);
      params.finish();
      return;
    }
    params.declare({"material", "emission", "transform"});

    MaterialChoice material = resolveMaterial(params, type);
    bool hasEmission = params.has("emission");
    // `emission` is a colour (or a number, grey), or a texture: then the object's own copy of its
    // material carries it and the constant is 1.
    std::optional<Color> emission;
    std::optional<TextureId> emissionTexture;
    if (textures_.isTexture(params, "emission")) {
      emissionTexture = textures_.read(params, "emission", TextureRole::Color);
      if (emissionTexture) emission = Color(1);
    } else {
      emission = readCoefficient(params, "emission", ctx_.encoding);
    }
    if (material.emission) {
      if (!hasEmission) {
        // The material's emission (its texture, if any, is in the material's bindings).
        emission = material.emission;
        hasEmission = true;
      } else if (!emissionTexture && hasEmissionTexture(material.index)) {
        // The object's own emission colour replaces the material's emission texture too.
        material.index = withEmissionTexture(material.index, kNoTexture);
      }
    }
    const TransformResult transform = readTransform(params, type);
    if (factory == &csgFactory_) {
      buildCsg(e, params, material, emission.value_or(Color()), emissionTexture, transform);
      return;
    }
    std::optional<ObjectGeometry> geometry;
    std::optional<ShapeError> degenerate;
    try {
      geometry = factory->read(params);
    } catch (const ShapeError& error) {
      degenerate = error;
    }
    params.finish();
    // A degenerate shape is reported only for an object whose keys are otherwise right.
    if (degenerate && params.errors() == 0) {
      reportShapeError(params, factory->keys, *degenerate, fmt::format("{} ({})", path, type));
    }
    if (!geometry || params.errors() != 0 || !transform.ok) return;
    if (auto* request = std::get_if<MeshRequest>(&*geometry)) {
      buildMesh(params, *request, material,
                hasEmission ? emission.value_or(Color()) : std::optional<Color>(),
                transform.worldFromObject, emissionTexture);
      return;
    }
    if (emissionTexture) material.index = withEmissionTexture(material.index, *emissionTexture);
    try {
      if (group_ != nullptr) {
        group_->primitives.emplace_back(std::move(std::get<Shape>(*geometry)), material.index,
                                        emission.value_or(Color()), transform.worldFromObject);
        group_->primitiveTakesMaterial.push_back(
            static_cast<std::uint8_t>(material.given || emissionTexture ? 0 : 1));
        return;
      }
      parts_.primitives.emplace_back(std::move(std::get<Shape>(*geometry)), material.index,
                                     emission.value_or(Color()), transform.worldFromObject);
      objectPlaces_.push_back({e.file, e.value, false});
    } catch (const ShapeError& error) {
      reportShapeError(params, factory->keys, error, fmt::format("{} ({})", path, type));
    }
  }

  // A csg object (DESIGN.md §11, factories/csg_factory.h): one primitive; operands without a
  // material or emission of their own take the object's.
  void buildCsg(const Entity& e, ParameterDictionary& params, MaterialChoice material,
                const Color& emission, const std::optional<TextureId>& emissionTexture,
                const TransformResult& transform) {
    if (emissionTexture) material.index = withEmissionTexture(material.index, *emissionTexture);
    CsgServices services{
        [this](ParameterDictionary& p,
               const std::string& owner) -> std::optional<CsgServices::OperandMaterial> {
          if (!p.has("material")) return std::nullopt;
          const MaterialChoice choice = resolveMaterial(p, owner);
          return CsgServices::OperandMaterial{choice.index, choice.emission};
        },
        [this](ParameterDictionary& p, const MeshRequest& request) { return loadMesh(p, request); },
        ctx_.encoding, emissionTexture.has_value()};
    std::optional<Csg> csg = readCsg(params, "csg", material.index, emission, services);
    params.finish();
    if (!csg || params.errors() != 0 || !transform.ok) return;
    try {
      if (group_ != nullptr) {
        // In a group: an instance's material covers a csg written without one (all its
        // operands).
        group_->primitives.emplace_back(std::move(*csg), material.index, emission,
                                        transform.worldFromObject);
        group_->primitiveTakesMaterial.push_back(
            static_cast<std::uint8_t>(material.given || emissionTexture ? 0 : 1));
        return;
      }
      parts_.primitives.emplace_back(std::move(*csg), material.index, emission,
                                     transform.worldFromObject);
      objectPlaces_.push_back({e.file, e.value, false});
    } catch (const ShapeError& error) {
      params.error(params.place(), fmt::format("objects[{}] (csg): {}", e.index, error.what()));
    }
  }

  bool hasEmissionTexture(std::uint32_t index) const {
    const Material& m = parts_.materials[index];
    return m.textures != kUntextured && parts_.materialTextures[m.textures].emission != kNoTexture;
  }

  // A copy of material `index` whose emission is the texture `emission` (times the object's
  // emission constant; kNoTexture: none).
  std::uint32_t withEmissionTexture(std::uint32_t index, TextureId emission) {
    Material m = parts_.materials[index];
    MaterialTextures bindings =
        m.textures != kUntextured ? parts_.materialTextures[m.textures] : MaterialTextures{};
    bindings.emission = emission;
    m.textures = textures_.addBindings(bindings);
    parts_.materials.push_back(m);
    return static_cast<std::uint32_t>(parts_.materials.size() - 1);
  }

  // The scene-material index of every material of `file`, added to the scene the first time the
  // file is used without a material override (a file used twice shares them), with the textures
  // its materials name (mesh_textures.cpp). Throws ImageReadError naming the texture file.
  const std::vector<std::uint32_t>& fileMaterials(const MeshFile& file,
                                                  const std::filesystem::path& meshPath,
                                                  const std::filesystem::path& sceneFolder) {
    std::vector<std::uint32_t>& indices = fileMaterials_[&file];
    if (indices.empty()) {
      std::vector<std::uint32_t> added;
      for (const MeshMaterial& m : file.materials) {
        Material material = m.material;
        if (m.textured()) {
          material.textures = textures_.addBindings(
              meshMaterialTextures(file, m, meshPath, sceneFolder, textures_));
        }
        added.push_back(static_cast<std::uint32_t>(parts_.materials.size()));
        parts_.materials.push_back(material);
      }
      indices = std::move(added);
    }
    return indices;
  }

  // A mesh object's contents: its file read once per scene through meshCache_ (estimated against
  // the memory limit first), or its inline arrays, counted against the scene's triangle limit.
  // Null after an error at the object naming the file as written; dropped degenerate triangles
  // are one warning there.
  std::shared_ptr<const MeshFile> loadMesh(ParameterDictionary& params,
                                           const MeshRequest& request) {
    const std::filesystem::path written(request.file);
    const std::filesystem::path path =
        written.is_relative() ? baseDirectory(params) / written : written;
    const std::string shown = escapeForMessage(request.file);
    // How messages name the mesh: its file, or the inline arrays.
    const std::string named =
        request.contents ? std::string("the inline mesh") : fmt::format("mesh file '{}'", shown);
    std::shared_ptr<const MeshFile> file = request.contents;  // an inline mesh is built already
    try {
      // Estimated (mesh + BVH, with the film) against the memory limit before anything is read.
      if (!file) {
        parts_.readFiles.push_back(path);
        file = meshCache_.load(
            path,
            MeshBudget{options_.imageMemoryBudget,
                       filmBytes(parts_.image.width, parts_.image.height) +
                           static_cast<std::uint64_t>(textures_.bytes())},
            MeshReadOptions{.sceneFolder = baseDirectory(params), .cancel = options_.cancel});
      }
    } catch (const MeshLoadError& e) {
      std::string reason = e.what();
      if (path != written && reason == "no such file") {
        reason += fmt::format(" (looked for {}: relative paths start at the scene file's folder)",
                              escapeForMessage(path.string()));
      }
      params.error(params.place(), fmt::format("cannot load mesh file '{}': {}", shown, reason));
      return nullptr;
    }
    const std::uint64_t triangles = file->triangleCount();
    if (meshTriangles_ + triangles > kMaxMeshTriangles) {
      params.error(params.place(),
                   fmt::format("{} brings the scene's meshes to {} triangles, more "
                               "than the limit of {}",
                               named, formatCount(static_cast<double>(meshTriangles_ + triangles)),
                               formatCount(static_cast<double>(kMaxMeshTriangles))));
      return nullptr;
    }
    meshTriangles_ += triangles;
    if (file->droppedTriangles > 0) {
      sink_.warning(params.location(),
                    fmt::format("{}: dropped {} degenerate triangle{} (zero area, "
                                "non-finite or invalid vertices); {} remain",
                                named, file->droppedTriangles,
                                file->droppedTriangles == 1 ? "" : "s", triangles));
    }
    if (file->importerDroppedFaces) {
      sink_.warning(params.location(),
                    fmt::format("{}: the mesh library left out faces whose vertex indices are "
                                "out of range (it does not say how many); {} triangle{} remain",
                                named, triangles, triangles == 1 ? "" : "s"));
    }
    // (With `smooth: false` the generated normals are not used.)
    if (file->exactPositionNormalParts > 0 && request.smooth) {
      sink_.warning(
          params.location(),
          fmt::format("{}: its generated normals smooth only over vertices at exactly the "
                      "same position: within the usual radius (1e-4 of the bounding "
                      "box's diagonal) too many vertices are near one another (a "
                      "vertex far from the rest, or fine detail in a large mesh)",
                      named));
    }
    if (file->crowdedNormalPositions > 0 && request.smooth) {
      sink_.warning(params.location(),
                    fmt::format("{}: in its generated normals, at {} position{} shared by more "
                                "than {} triangle corners each corner keeps its own triangle's "
                                "normal",
                                named, file->crowdedNormalPositions,
                                file->crowdedNormalPositions == 1 ? "" : "s", kMaxSmoothedCorners));
    }
    if (!file->ignoredTextures.empty()) {
      std::vector<std::string> ignoredShown;
      for (const std::string& ignored : file->ignoredTextures) {
        ignoredShown.push_back(shortenForMessage(ignored));  // the reader's text: not trusted
      }
      sink_.warning(params.location(),
                    fmt::format("{}: its materials' {} {} not used (glint reads map_Kd, map_Ks, "
                                "map_Ke, map_Bump or bump, and norm)",
                                named, fmt::join(ignoredShown, ", "),
                                ignoredShown.size() == 1 ? "is" : "are"));
    }
    return file;
  }

  // A mesh object (DESIGN.md §5, §7): its contents (loadMesh) instanced with the object's
  // transform. The object's `material` replaces every material of the file (their emission too);
  // its `emission` replaces the files' emission.
  void buildMesh(ParameterDictionary& params, const MeshRequest& request,
                 const MaterialChoice& material, const std::optional<Color>& emission,
                 const std::optional<Transform>& worldFromFile,
                 const std::optional<TextureId>& emissionTexture) {
    const std::shared_ptr<const MeshFile> file = loadMesh(params, request);
    if (file == nullptr) return;
    // Only where the file's own materials are used: an object `material` replaces them all.
    if (!material.given) {
      for (const std::string& library : file->missingMaterialLibraries) {
        // The reader's text: not trusted.
        sink_.warning(params.location(),
                      file->fallbackMaterialLibrary.empty()
                          ? fmt::format("mesh file '{}': its material library '{}' is not there "
                                        "(the mesh library takes a whole mtllib line as one file "
                                        "name); a material no library defines is mid-grey",
                                        escapeForMessage(request.file), shortenForMessage(library))
                          : fmt::format("mesh file '{}': its material library '{}' is not there; "
                                        "the mesh library read '{}' (the OBJ's own name) instead",
                                        escapeForMessage(request.file), shortenForMessage(library),
                                        shortenForMessage(file->fallbackMaterialLibrary)));
      }
    }
    const std::filesystem::path written(request.file);
    const std::filesystem::path path =
        written.is_relative() ? baseDirectory(params) / written : written;
    const std::string shown = escapeForMessage(request.file);
    const std::vector<std::uint32_t>* scene = nullptr;
    if (!material.given) {
      try {
        // A bare mesh file's quick look has no scene folder: its model's own folder rules.
        scene = &fileMaterials(*file, path,
                               d_.bareMeshFile ? std::filesystem::path() : baseDirectory(params));
      } catch (const ImageReadError& e) {
        params.error(params.place(), fmt::format("mesh file '{}': {}{}", shown, e.what(),
                                                 d_.bareMeshFile ? bareMeshFileHint(e.what(), path)
                                                                 : std::string()));
        return;
      }
    }
    // The scene material of each part: the object's, or the file's own; with an emission texture,
    // a copy carrying it.
    std::vector<std::uint32_t> partMaterial;
    bool anyUv = false;
    for (const TriangleMesh& part : file->parts) {
      std::uint32_t index = material.given ? material.index : (*scene)[part.materialIndex];
      if (emissionTexture) index = withEmissionTexture(index, *emissionTexture);
      partMaterial.push_back(index);
      anyUv = anyUv || needsUv(index);
    }
    // In a group, a mesh written without a material takes its instances' (which may be textured).
    const bool takesMaterial = group_ != nullptr && !material.given && !emissionTexture;
    anyUv = anyUv || takesMaterial;
    std::vector<TriangleMesh> meshes =
        instantiateMesh(*file, worldFromFile, request.smooth, options_.cancel, anyUv);
    // Within reach in the world (a file's floats are, but a transform may scale them past it).
    double reach = 0;
    for (const TriangleMesh& mesh : meshes) {
      for (const Point3& p : mesh.positions) {
        reach = std::max({reach, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
      }
    }
    if (reach > kMaxCoordinate) {
      params.error(params.place(), fmt::format("mesh file '{}' {}", shown, beyondReach(reach)));
      return;
    }
    const auto objectTransform =
        worldFromFile ? std::make_shared<const Transform>(*worldFromFile) : nullptr;
    for (std::size_t k = 0; k < meshes.size(); ++k) {
      TriangleMesh& mesh = meshes[k];
      const MeshMaterial& own = file->materials[mesh.materialIndex];
      mesh.emission = emission.value_or(material.given ? Color() : own.emission);
      mesh.materialIndex = partMaterial[k];
      mesh.worldFromObject = objectTransform;
      if (!needsUv(mesh.materialIndex) && !takesMaterial) {
        std::vector<Point2>().swap(mesh.uvs);
      } else if (needsTangents(mesh.materialIndex)) {
        computeMeshTangents(mesh);
      }
      if (group_ != nullptr) {
        group_->meshes.push_back(std::move(mesh));
        group_->meshTakesMaterial.push_back(static_cast<std::uint8_t>(takesMaterial ? 1 : 0));
        continue;
      }
      parts_.meshes.push_back(std::move(mesh));
    }
  }

  bool needsUv(std::uint32_t material) const {
    const std::uint32_t t = parts_.materials[material].textures;
    return t != kUntextured && parts_.materialTextures[t].needsUv;
  }
  bool needsTangents(std::uint32_t material) const {
    const std::uint32_t t = parts_.materials[material].textures;
    return t != kUntextured && parts_.materialTextures[t].normalMap != kNoTexture;
  }

  std::filesystem::path baseDirectory(const ParameterDictionary& params) const {
    for (const auto& file : d_.files) {
      if (&file->values == &params.reader().tree()) return file->baseDirectory;
    }
    return d_.files.at(0)->baseDirectory;
  }

  // --- lights ---------------------------------------------------------------------------------

  void buildLight(const Entity& e) {
    const ValueReader reader = readerOf(e);
    const std::string path = fmt::format("lights[{}]", e.index);
    if (!reader.tree().isMap(e.value)) {
      reader.error(e.place, fmt::format("{}: expected a mapping with a 'type' (directional, point, "
                                        "spot or area), got {}",
                                        path, reader.describe(e.value)));
      return;
    }
    const LightFactory* factory =
        factoryOf<LightFactory>(reader, e, "light", path, lightTypes_,
                                [](std::string_view type) { return findLightFactory(type); });
    if (factory == nullptr) {
      ParameterDictionary(reader, e.value, {"in " + path, path, path}).finish();
      return;
    }
    const std::string owner = std::string(factory->type) + " light";
    ParameterDictionary params(reader, e.value, {"in " + owner, owner, owner});
    params.declareHidden("type");
    params.find("type");
    params.declare(factory->keys);
    std::optional<Light> light;
    std::optional<ShapeError> degenerate;
    try {
      light = factory->read(params, ctx_);
    } catch (const ShapeError& error) {
      degenerate = error;
    }
    params.finish();
    if (degenerate && params.errors() == 0) {
      reportShapeError(params, params.declared(), *degenerate, fmt::format("{} ({})", path, owner));
    }
    if (!light || params.errors() != 0) return;
    parts_.lights.push_back(*light);
    const Color power = std::visit([](const auto& l) { return l.intensity; }, *light);
    if (isBlack(power)) {
      sink_.warning(params.location(),
                    fmt::format("{} has zero intensity; it lights nothing", owner));
    }
    warnIfEnclosed(*light, owner, params.location());
  }

  // A point or spot light inside a closed opaque solid that does not also hold the camera (a lamp
  // inside its bulb, forgotten kt) lights only that solid's inside, which the camera cannot see:
  // almost always a mistake, and the image shows only the other lights.
  void warnIfEnclosed(const Light& light, const std::string& owner, const SourceLocation& at) {
    const Point3* position = nullptr;
    if (const auto* point = std::get_if<PointLight>(&light)) position = &point->position;
    if (const auto* spot = std::get_if<SpotLight>(&light)) position = &spot->position;
    if (position == nullptr) return;
    const Point3 eye = parts_.camera.position;
    for (std::size_t i = 0; i < parts_.primitives.size(); ++i) {
      const Primitive& p = parts_.primitives[i];
      // The light surely inside; the camera not even on the surface (a camera in a room's wall
      // sees the room).
      if (!isOpaqueClosedSolid(p) || !encloses(p, *position, Probe::AllOdd) ||
          encloses(p, eye, Probe::AnyOdd)) {
        continue;
      }
      if (++enclosedLights_ > kMaxDarkObjectWarnings) {
        if (!firstUnnamedEnclosedLight_) firstUnnamedEnclosedLight_ = at;
        return;
      }
      const ObjectPlace& place = objectPlaces_[i];
      const SourceFile& file = *d_.files[place.file];
      const SourceLocation where = file.location(place.value);
      const std::string_view type = file.values.scalar(typeValue(file, place.value));
      sink_.warning(at, fmt::format("{} is inside the {} at {}:{}:{}, which is opaque and does not "
                                    "hold the camera: it lights nothing the camera sees (give the "
                                    "{} a kt, or move the light)",
                                    owner, type, where.file, where.line, where.column, type));
      return;
    }
  }

  // After the lights: how many more lights than were named are inside opaque solids.
  void countEnclosedLights() {
    if (!firstUnnamedEnclosedLight_) return;
    sink_.warning(*firstUnnamedEnclosedLight_,
                  fmt::format("{} more lights are inside opaque solids that do not hold the camera "
                              "(this one first)",
                              enclosedLights_ - kMaxDarkObjectWarnings));
  }

  // Spheres, boxes, closed cylinders and csg solids (with or without a transform) whose material
  // passes no light (kt 0; a csg's every operand).
  bool isOpaqueClosedSolid(const Primitive& p) const {
    const Shape& shape = p.shape();
    if (const Csg* csg = p.csg()) {
      return std::all_of(
          csg->tree->operands.begin(), csg->tree->operands.end(),
          [&](const CsgOperand& o) { return isBlack(parts_.materials[o.materialIndex].kt); });
    }
    const bool solid = std::holds_alternative<Sphere>(shape) ||
                       std::holds_alternative<Box>(shape) ||
                       std::holds_alternative<Cylinder>(shape);
    return solid && isBlack(parts_.materials[p.materialIndex()].kt);
  }

  // Whether the closed solid p holds `point`: inside its bounds, and an odd number of surface
  // crossings along two rays from it — both (surely inside: a ray grazing an edge cannot decide
  // alone), or either (inside or on the surface, where a ray leaving through it crosses nothing).
  enum class Probe { AllOdd, AnyOdd };
  static bool encloses(const Primitive& p, const Point3& point, Probe probe) {
    if (!p.bounds().contains(point)) return false;
    int odd = 0;
    for (const Vec3& direction : {Vec3{0.5773, 0.5774, 0.5775}, Vec3{-0.6245, 0.4472, -0.6402}}) {
      odd += p.crossings(Ray{point, direction}, 0, kInfinity) % 2;
    }
    return probe == Probe::AllOdd ? odd == 2 : odd > 0;
  }

  // --- warnings -------------------------------------------------------------------------------

  bool shows(const Color& emission, std::uint32_t material) const {
    const Material& m = parts_.materials[material];
    return !isBlack(emission) || !isBlack(m.kr) || !isBlack(m.kt);
  }

  bool isDark(const Color& emission, std::uint32_t material) const {
    const Material& m = parts_.materials[material];
    return isBlack(emission) && isBlack(m.kd) && isBlack(m.ks) && isBlack(m.kr) && isBlack(m.kt);
  }

  // Whether pred(emission, material index) holds for some object: a primitive, a csg's operand, a
  // mesh, an instance's material, or an object of a placed group (each group looked at once).
  template <class Pred>
  bool anyObject(Pred pred) const {
    for (const Primitive& p : parts_.primitives) {
      if (pred(p.emission(), p.materialIndex())) return true;
      if (const Csg* csg = p.csg()) {
        for (const CsgOperand& o : csg->tree->operands) {
          if (pred(o.emission, o.materialIndex)) return true;
        }
      }
    }
    for (const TriangleMesh& mesh : parts_.meshes) {
      if (pred(mesh.emission, mesh.materialIndex)) return true;
    }
    std::vector<bool> placed(parts_.groups.size(), false);
    for (const Instance& instance : parts_.instances) {
      if (instance.material != kNoMaterialOverride && pred(Color(), instance.material)) return true;
      placed[instance.group] = true;
    }
    for (std::size_t g = 0; g < parts_.groups.size(); ++g) {
      if (!placed[g]) continue;
      for (const Primitive& p : parts_.groups[g].primitives) {
        if (pred(p.emission(), p.materialIndex())) return true;
      }
      for (const TriangleMesh& mesh : parts_.groups[g].meshes) {
        if (pred(mesh.emission, mesh.materialIndex)) return true;
      }
    }
    return false;
  }

  // Whether every ray that misses sees black (no light from the background under `path`).
  bool backgroundIsBlack() const {
    const Environment& e = parts_.environment;
    switch (e.kind) {
      case BackgroundKind::Uniform:
        return isBlack(parts_.background);
      case BackgroundKind::Gradient:
        return isBlack(e.zenith) && isBlack(e.horizon) && isBlack(e.nadir);
      case BackgroundKind::Sky:
        return isBlack(e.skyTop) && isBlack(e.skyBottom);
      case BackgroundKind::Image:
        return !(e.intensity > 0);
    }
    return false;
  }

  // Objects shade black without any light: under `whitted` no lights, ambient, emission or
  // mirror/glass to show the background; under `path` (which adds no ambient light, and to which
  // the background is a light) no lights, emission or background. Almost always a forgotten
  // `lights` or `ambient` section, or a scene written for the other integrator.
  void warnIfUnlit() {
    if (sink_.hasErrors() ||
        (parts_.primitives.empty() && parts_.meshes.empty() && parts_.instances.empty()) ||
        !parts_.lights.empty()) {
      return;
    }
    const SourceLocation scene{d_.files.at(0)->name, 1, 1};
    if (parts_.render.integrator == Integrator::Path) {
      if (!backgroundIsBlack() ||
          anyObject([](const Color& emission, std::uint32_t) { return !isBlack(emission); })) {
        return;
      }
      sink_.warning(scene, fmt::format("the scene has no lights, no emissive objects and a black "
                                       "background: under the path integrator every object will "
                                       "render black{}",
                                       isBlack(parts_.ambient)
                                           ? ""
                                           : " (the path integrator adds no ambient light)"));
      return;
    }
    if (!isBlack(parts_.ambient) ||
        anyObject([this](const Color& emission, std::uint32_t material) {
          return shows(emission, material);
        })) {
      return;
    }
    sink_.warning(scene,
                  "the scene has no lights, no ambient light and no emissive, reflective or "
                  "transparent objects: every object will render black");
  }

  // Under lights, an object whose material reflects nothing (kd, ks, kr, kt all 0: the default
  // material of an object without `material`) and that does not glow shows only the ambient light:
  // almost always a forgotten material.
  void warnAboutDarkObjects() {
    if (sink_.hasErrors() || parts_.lights.empty()) return;
    // Every dark object in file order: primitive i at (i, 1); an instance at (the primitives
    // built before it, 0), so that it sorts before the next primitive.
    struct DarkObject {
      std::pair<std::size_t, int> order;
      SourceLocation where;
      std::string message;
    };
    std::vector<DarkObject> darkObjects;
    for (std::size_t i = 0; i < parts_.primitives.size(); ++i) {
      const Primitive& p = parts_.primitives[i];
      if (!isDarkPrimitive(p)) continue;
      const ObjectPlace& place = objectPlaces_[i];
      const SourceFile& file = *d_.files[place.file];
      const std::string_view type = file.values.scalar(typeValue(file, place.value));
      darkObjects.push_back(
          {{i, 1},
           file.location(place.value),
           p.materialIndex() == 0
               ? fmt::format("{} has no material, so it reflects no light: under the lights it "
                             "shows only the ambient light (give it a material with kd or ks)",
                             type)
               : fmt::format("{}'s material reflects no light (kd, ks, kr and kt are all 0): "
                             "under the lights it shows only the ambient light",
                             type)});
    }
    // Instances that give no material, once per group: a group object written without one shows
    // only the ambient light there too.
    std::set<std::uint32_t> groupsSeen;
    for (const BareInstance& instance : bareInstances_) {
      if (!groupsSeen.insert(instance.group).second ||
          !groupHasObjectWithoutMaterial(parts_.groups[instance.group])) {
        continue;
      }
      const std::uint32_t group = instance.group;
      const auto name = std::find_if(groupIndex_.begin(), groupIndex_.end(),
                                     [&](const auto& entry) { return entry.second == group; });
      darkObjects.push_back(
          {{instance.primitivesBefore, 0},
           instance.where,
           fmt::format("instance of group '{}': an object of the group has no material and the "
                       "instance gives none, so it reflects no light: under the lights it shows "
                       "only the ambient light (give the instance or the object a material with "
                       "kd or ks)",
                       name == groupIndex_.end() ? std::string() : nameForMessage(name->first))});
    }
    std::stable_sort(darkObjects.begin(), darkObjects.end(),
                     [](const DarkObject& a, const DarkObject& b) { return a.order < b.order; });
    for (std::size_t k = 0; k < darkObjects.size() && k < kMaxDarkObjectWarnings; ++k) {
      sink_.warning(darkObjects[k].where, darkObjects[k].message);
    }
    if (darkObjects.size() > kMaxDarkObjectWarnings) {
      // At the first object not named, so that the line comes after the five that are.
      sink_.warning(darkObjects[kMaxDarkObjectWarnings].where,
                    fmt::format("{} more objects reflect no light (this one first)",
                                darkObjects.size() - kMaxDarkObjectWarnings));
    }
  }

  // Reflects no light and does not glow (a csg: none of its operands).
  bool isDarkPrimitive(const Primitive& p) const {
    if (!isDark(p.emission(), p.materialIndex())) return false;
    const Csg* csg = p.csg();
    return csg == nullptr ||
           std::all_of(csg->tree->operands.begin(), csg->tree->operands.end(),
                       [&](const CsgOperand& o) { return isDark(o.emission, o.materialIndex); });
  }

  // Whether a group holds a shape written without a material that does not glow: dark wherever an
  // instance gives it none.
  bool groupHasObjectWithoutMaterial(const GroupParts& group) const {
    for (std::size_t j = 0; j < group.primitives.size(); ++j) {
      const bool takesMaterial =
          j < group.primitiveTakesMaterial.size() && group.primitiveTakesMaterial[j] != 0;
      if (takesMaterial && isDarkPrimitive(group.primitives[j])) return true;
    }
    return false;
  }

  static ValueId typeValue(const SourceFile& file, ValueId map) {
    const ValueTree& t = file.values;
    for (std::size_t i = 0; i < t.size(map); ++i) {
      if (t.scalar(t.key(map, i)) == "type") return t.value(map, i);
    }
    return kNoValue;
  }

  struct ObjectPlace {
    std::uint32_t file = 0;
    ValueId value = kNoValue;
    bool mesh = false;
  };

  const SceneDescription& d_;
  const BuildOptions& options_;
  SceneParts& parts_;
  Diagnostics sink_;
  BuildContext ctx_;
  BuildResult& result_;
  std::map<std::string, std::uint32_t, std::less<>> materialIndex_;
  // `csg` has no entry in objectFactories(): its operands need the builder (materials, meshes).
  const ObjectFactory csgFactory_{"csg", kCsgKeys, nullptr};
  std::map<std::uint32_t, std::pair<std::uint32_t, TextPosition>> materialWhere_;  // file, place
  std::map<std::uint32_t, Color> materialEmission_;  // named materials with an `emission`
  std::map<std::string, std::uint32_t, std::less<>> groupIndex_;  // into parts_.groups
  // Undefined material and group names that may still get a hint (undefinedNameHint).
  int materialHintsLeft_ = kMaxNameHints;
  int groupHintsLeft_ = kMaxNameHints;
  std::vector<std::optional<Bounds3>> groupBounds_;                 // groupBounds()
  std::vector<std::pair<std::uint32_t, TextPosition>> groupWhere_;  // per group: file, place
  GroupParts* group_ = nullptr;  // while building a group's objects: where they go
  MeshCache meshCache_;          // each mesh file read once per scene
  std::map<const MeshFile*, std::vector<std::uint32_t>> fileMaterials_;
  std::uint64_t meshTriangles_ = 0;            // in parts_.meshes
  std::vector<ObjectPlace> objectPlaces_;      // per primitive, where its object was written
  std::vector<std::string_view> objectTypes_;  // in the order messages list them
  std::vector<std::string_view> lightTypes_;
  // warnIfEnclosed: lights found inside an opaque solid, and where the first one not named is
  // (the count of the rest is said there, as for dark objects).
  std::size_t enclosedLights_ = 0;
  std::optional<SourceLocation> firstUnnamedEnclosedLight_;
  // Instances that give no material (warnAboutDarkObjects): where, the group placed, and how many
  // primitives were built before them (their place in file order among the objects).
  struct BareInstance {
    SourceLocation where;
    std::uint32_t group = 0;
    std::size_t primitivesBefore = 0;
  };
  std::vector<BareInstance> bareInstances_;
  TextureLibrary textures_;  // the scene's textures; ctx_.textures points here
};

}  // namespace

BuildResult buildScene(const SceneDescription& description, const BuildOptions& options) {
  BuildResult result;
  Builder(description, options, result).build();
  return result;
}

}  // namespace glint
