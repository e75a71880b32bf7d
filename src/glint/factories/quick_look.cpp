#include "glint/factories/quick_look.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "glint/core/bounds.h"
#include "glint/mesh/format_checks.h"
#include "glint/mesh/mesh_loader.h"
#include "glint/readers/diagnostics.h"
#include "glint/readers/text_statements.h"

namespace glint {
namespace {

constexpr double kFovDegrees = 35;
constexpr int kImageWidth = 800;
constexpr int kImageHeight = 600;
constexpr int kSamples = 4;
// The bounding sphere fills this fraction of the vertical field of view.
constexpr double kFill = 0.9;

// Adds `key: [x, y, z]` of computed numbers, with no place in any text.
void vector(SceneEmitter& out, std::string_view key, const Vec3& v) {
  const double xyz[3] = {v.x, v.y, v.z};
  out.computedTriple(key, xyz, {});
}

void light(SceneEmitter& out, const Vec3& towardLight, double intensity) {
  const ValueId map = out.nextId();
  out.openMap({});
  const ValueId type = out.entry("type", "directional", {});
  vector(out, "direction", -normalize(towardLight));  // the way the light travels
  out.entry("intensity", numberText(intensity), {});
  out.close();
  out.addEntity(EntityKind::LightEntity, map, type);
}

}  // namespace

std::string bareMeshFileHint(std::string_view refusal, const std::filesystem::path& model) {
  if (refusal.find("may only name files in its own folder and below") == std::string_view::npos) {
    return {};
  }
  // The model as a scene file in the folder above its own would name it.
  const std::filesystem::path folder = std::filesystem::absolute(model).parent_path().filename();
  return fmt::format(
      "; to use files outside the model's folder (a textures folder beside it), render a scene "
      "file written in a folder that holds both, with a mesh object naming the model ({{type: "
      "mesh, file: {}}}, and a camera: glint convert cannot write it, as it reads the model the "
      "same way)",
      escapeForMessage((folder / model.filename()).generic_string()));
}

bool isQuickLookFile(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return std::any_of(std::begin(kMeshExtensions), std::end(kMeshExtensions),
                     [&](const char* e) { return extension == e; });
}

ParseResult describeQuickLook(const std::filesystem::path& file, const LoadOptions& options) {
  const std::string name = file.string();
  std::filesystem::path base = file.parent_path();
  if (base.empty()) base = ".";
  std::shared_ptr<const MeshFile> read;
  try {
    // No scene folder: the files the model names are judged against its own folder, and the
    // refusal says so (not "its scene file's folder", which a bare mesh file does not have).
    read = std::make_shared<const MeshFile>(
        readMeshFile(file, MeshReadOptions{.sceneFolder = {}, .cancel = options.cancel}));
  } catch (const MeshLoadError& e) {
    const std::string reason = e.what() + bareMeshFileHint(e.what(), file);
    // At the line and column in the file when the reason names them.
    if (const std::optional<MeshErrorPlace> place = meshErrorPlace(e.what())) {
      throw SceneError({{Diagnostic::Severity::Error,
                         {name, place->line, place->column},
                         fmt::format("cannot load mesh file: {}", place->reason)}});
    }
    throw SceneError({{Diagnostic::Severity::Error,
                       {name, 0, 0},
                       fmt::format("cannot load mesh file: {}", reason)}});
  }
  Bounds3 bounds;
  for (const TriangleMesh& part : read->parts) {
    for (const Point3& p : part.positions) bounds = unite(bounds, p);
  }
  const Point3 center = bounds.centroid();
  const double radius = std::max(length(bounds.diagonal()) / 2, 1e-9);
  const double distance = radius / (kFill * std::sin(kFovDegrees / 2 * std::numbers::pi / 180));
  const Vec3 view = normalize(Vec3{0.55, 0.35, 1});  // from the model toward the camera

  ParseResult result;
  result.description = sceneWithFile(name, base);
  SceneDescription& scene = result.description;
  scene.files[0]->bytes = std::filesystem::file_size(file);
  scene.bareMeshFile = true;
  // The builder's mesh object names the file by its name in `base`: the same file, not read again.
  scene.readMeshFiles.emplace_back(base / file.filename(), read);
  Diagnostics sink;
  SceneEmitter out(scene, sink);

  ValueId map = out.nextId();
  out.openMap({});
  vector(out, "position", toVec(center) + view * distance);
  vector(out, "look_at", toVec(center));
  out.entry("fov", numberText(kFovDegrees), {});
  out.close();
  out.addEntity(EntityKind::CameraEntity, map);

  map = out.nextId();
  out.openMap({});
  out.entry("width", std::to_string(kImageWidth), {});
  out.entry("height", std::to_string(kImageHeight), {});
  out.entry("samples", std::to_string(kSamples), {});
  out.close();
  out.addEntity(EntityKind::ImageEntity, map);

  map = out.nextId();
  out.scalar("#333a45", {});
  out.addEntity(EntityKind::BackgroundEntity, map);

  map = out.nextId();
  out.openMap({});
  out.entry("intensity", "0.15", {});
  out.close();
  out.addEntity(EntityKind::AmbientEntity, map);

  // The model, with its own materials.
  map = out.nextId();
  out.openMap({});
  ValueId type = out.entry("type", "mesh", {});
  out.entry("file", file.filename().string(), {});
  out.close();
  out.addEntity(EntityKind::ObjectEntity, map, type);

  // A ground plane under the lowest point, light grey and dull: 1/1000 of the model's size below
  // it, so that a flat model lying in its lowest plane (a floor plan, a decal) is not in the
  // ground's plane (the two would speckle through each other); a gap no one sees under a model
  // standing on its lowest point.
  map = out.nextId();
  out.openMap({});
  type = out.entry("type", "plane", {});
  vector(out, "point", Vec3{center.x, bounds.lo.y - 1e-3 * radius, center.z});
  vector(out, "normal", Vec3{0, 1, 0});
  out.key("material", {});
  out.openMap({});
  out.entry("kd", "0.55", {});
  out.entry("ka", "0.55", {});
  out.close();
  out.close();
  out.addEntity(EntityKind::ObjectEntity, map, type);

  light(out, Vec3{1, 1.4, 1.2}, 0.8);      // key: front-right-above
  light(out, Vec3{-1.2, 0.4, 0.8}, 0.35);  // fill: front-left, lower
  light(out, Vec3{-0.3, 1, -1.2}, 0.45);   // rim: behind, above

  scene.complete = true;
  result.diagnostics = sink.take();
  return result;
}

}  // namespace glint
