#include "glint/job/scene_check.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <new>
#include <string>
#include <utility>
#include <variant>

#include "glint/core/file_access.h"
#include "glint/job/job_error.h"
#include "glint/job/job_steps.h"

namespace glint {
namespace {

// Whole numbers as digits up to a million, then in words ("4.3 billion").
std::string countText(double count) {
  return count < 1e6 ? fmt::format("{:.0f}", count) : formatCount(count);
}

}  // namespace

LoadedScene loadSceneFile(const std::filesystem::path& file, const LoadOptions& options) {
  try {
    return loadScene(file, options);
  } catch (const SceneError& error) {
    throw JobError(error);
  }
}

// Only a regular file of at most the loader's 256 MiB is read: a FIFO or a device given as the
// scene cannot be read twice.
std::string readSceneFileAgain(const std::filesystem::path& file) {
  const auto failure = [&file]() {
    return JobError(JobFailure::Failure,
                    fmt::format("cannot read '{}' again to fingerprint it", file.string()));
  };
  constexpr std::uint64_t kMaxSceneBytes = std::uint64_t{256} << 20;
  const ReadableFile opened = openForReading(file);
  bool ok = opened.refusal == FileRefusal::None && opened.size <= kMaxSceneBytes;
  std::string bytes;
  if (ok) bytes.reserve(static_cast<std::size_t>(opened.size));
  char buffer[1 << 16];
  while (ok && bytes.size() <= kMaxSceneBytes) {
    const ssize_t n = ::read(opened.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ok = n == 0;
      break;
    }
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  if (!ok || bytes.size() > kMaxSceneBytes) throw failure();
  return bytes;
}

std::string fingerprintedSceneText(const std::filesystem::path& file, const Scene& scene) {
  namespace fs = std::filesystem;
  std::string text = readSceneFileAgain(file);
  std::error_code error;
  const fs::path folder = fs::absolute(file, error).lexically_normal().parent_path();
  for (const fs::path& included : scene.includedFiles()) {
    const std::string bytes = readSceneFileAgain(included);
    // Named from the scene file's folder, so that the text does not depend on the folder glint
    // runs in or on how the scene was named ("a/scene.yaml" here, "scene.yaml" from a/).
    const std::string name = fs::absolute(included, error)
                                 .lexically_normal()
                                 .lexically_relative(folder)
                                 .generic_string();
    // Each part with its length, so that no two different sets of files give the same text.
    text += fmt::format("\ninclude {}:{}\n{}:", name.size(), name, bytes.size());
    text += bytes;
  }
  return text;
}

void enforceImageLimits(const ImageSettings& image, const std::string& request,
                        std::uint64_t memoryBudget, int filmCopies) {
  std::optional<std::string> refusal = checkImageSettings(image, memoryBudget);
  const std::uint64_t film = filmBytes(image.width, image.height);
  if (!refusal && filmCopies > 1 && film > memoryBudget / static_cast<std::uint64_t>(filmCopies)) {
    refusal = fmt::format(
        "an image of {} × {} pixels needs {} for its film and {} for checkpointing, more than the "
        "memory budget of {}",
        image.width, image.height, formatBytes(static_cast<double>(film)),
        formatBytes(static_cast<double>(film) * static_cast<double>(filmCopies - 1)),
        formatBytes(static_cast<double>(memoryBudget)));
  }
  if (refusal) {
    throw JobError(JobFailure::BadInput, request.empty()
                                             ? fmt::format("request refused: {}", *refusal)
                                             : fmt::format("{} refused: {}", request, *refusal));
  }
}

Scene freezeScene(SceneParts parts, const std::string& file) {
  try {
    return Scene(std::move(parts));
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& error) {
    throw JobError(JobFailure::BadInput, fmt::format("{}: {}", file, error.what()));
  }
}

SceneFacts sceneFacts(const Scene& scene) {
  SceneFacts facts;
  facts.name = scene.name();
  facts.image = scene.image();
  facts.samplesPerPixel = samplesPerPixel(scene.image());
  facts.objects = scene.primitives().size();
  for (const Primitive& primitive : scene.primitives())
    facts.unboundedObjects += primitive.isBounded() ? 0 : 1;
  facts.meshes = scene.meshes().size();
  facts.triangles = scene.aggregate().triangleCount();
  if (const InstanceSet* instances = scene.aggregate().instances()) {
    facts.instances = instances->instanceCount();
    facts.groups = instances->groupCount();
    for (std::uint32_t g = 0; g < instances->groupCount(); ++g)
      facts.groupTriangles += instances->group(g).triangleCount();
  }
  facts.isa = scene.aggregate().isa();
  facts.lights = scene.lights().size();
  for (const Light& light : scene.lights())
    facts.areaLights += std::holds_alternative<AreaLight>(light) ? 1 : 0;
  facts.ambient = !isBlack(scene.ambient());
  facts.materials = scene.materials().size() - 1;  // index 0 is the built-in default
  facts.bounds = scene.aggregate().bounds();
  facts.maxDepth = scene.render().maxDepth;
  facts.seed = scene.render().seed;
  facts.integrator = scene.render().integrator;
  return facts;
}

std::optional<Diagnostic> pixelWorkWarning(const std::string& file, const SceneParts& parts) {
  // The path integrator's next-event rays: toward the emitters, when something glows, and toward
  // an image sky.
  const auto glows = [](const Color& emission) { return !isBlack(emission); };
  bool emitters = std::any_of(parts.meshes.begin(), parts.meshes.end(),
                              [&](const TriangleMesh& m) { return glows(m.emission); }) ||
                  std::any_of(parts.primitives.begin(), parts.primitives.end(),
                              [&](const Primitive& p) { return glows(p.emission()); });
  for (const GroupParts& group : parts.groups) {
    for (const Primitive& p : group.primitives) emitters = emitters || glows(p.emission());
    for (const TriangleMesh& m : group.meshes) emitters = emitters || glows(m.emission);
  }
  const int pathLightRays =
      (emitters ? 1 : 0) + (parts.environment.kind == BackgroundKind::Image ? 1 : 0);
  const PixelWork work =
      estimatePixelWork(parts.image, parts.render, parts.lights, parts.materials, pathLightRays);
  const double rays = work.raysPerPixel();
  if (!(rays > kAbsurdRaysPerPixel)) return std::nullopt;
  const double perHit =
      1 + static_cast<double>(work.shadowRaysPerHit) + static_cast<double>(work.glossyRaysPerHit);
  return Diagnostic{
      Diagnostic::Severity::Warning,
      {file, 1, 1},  // the whole scene's: no natural place (DESIGN.md §7: line 1)
      fmt::format("one pixel may trace about {} rays ({} {} × {} surface {} per sample × {} rays "
                  "per hit: {} shadow, {} glossy and the ray to the hit), more than {}; the render "
                  "may never finish. Lower image.samples, image.adaptive.max_samples, the area "
                  "lights' samples, render.blur_samples or render.max_depth",
                  countText(rays), work.samples, work.samples == 1 ? "sample" : "samples",
                  countText(work.hitsPerSample), work.hitsPerSample == 1 ? "hit" : "hits",
                  countText(perHit), work.shadowRaysPerHit, work.glossyRaysPerHit,
                  countText(kAbsurdRaysPerPixel))};
}

SceneFacts checkScene(const std::filesystem::path& file, const CheckOptions& options) {
  LoadOptions load;
  load.memoryBudget = options.memoryBudget;
  load.overrides = options.overrides;
  load.cancel = options.cancel;
  LoadedScene loaded = loadSceneFile(file, load);
  if (std::optional<Diagnostic> warning = pixelWorkWarning(file.string(), loaded.parts))
    loaded.warnings.push_back(std::move(*warning));
  if (options.warnings && !loaded.warnings.empty()) options.warnings(loaded.warnings);
  enforceImageLimits(loaded.parts.image, options.requestText, options.memoryBudget);
  return sceneFacts(freezeScene(std::move(loaded.parts), file.string()));
}

}  // namespace glint
