#include "glint/factories/settings_factories.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "glint/factories/texture_library.h"
#include "glint/readers/spelling.h"
#include "glint/scene/camera.h"

namespace glint {
namespace {

constexpr Presence kRequired = Presence::Required;

// up is refused when the sine of its angle to the view direction is at most this; the camera uses
// the same bound (scene/camera.cpp), so a scene that builds here never fails there.
constexpr double kParallelSine = 1e-6;

ValueReader readerOf(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  return ValueReader(scene.fileOf(e).source(), ctx.sink);
}

// A scene-wide section (`image: {...}`) as a dictionary named after it, or nullopt after the error
// "{section}: expected {what}, got ...".
std::optional<ParameterDictionary> sectionParameters(const SceneDescription& scene, const Entity& e,
                                                     BuildContext& ctx, std::string_view what,
                                                     const std::string& section) {
  return entityParameters(readerOf(scene, e, ctx), e.value, e.place, what,
                          {"in " + section, section, section});
}

// image.adaptive, after image.samples: max_samples may not be below the fixed count, and the
// worst case (every pixel taking max_samples) must pass the same camera-ray limit.
void buildAdaptive(ParameterDictionary& adaptiveParams, bool checkSize, BuildContext& ctx) {
  ParameterDictionary& p = adaptiveParams;
  p.declare({"max_samples", "threshold"});
  AdaptiveSampling adaptive;  // the defaults
  const auto maxSamples = p.integer("max_samples");
  bool maxOk = true;
  if (maxSamples) {
    maxOk = checkInRange(p, *maxSamples, 1, kMaxSamplesPerPixel, "image.adaptive.max_samples");
    if (maxOk) adaptive.maxSamples = static_cast<int>(maxSamples->value);
  }
  if (const auto threshold = readPositive(p, "threshold")) adaptive.threshold = *threshold;
  ImageSettings& image = ctx.parts.image;
  if (maxOk && adaptive.maxSamples < image.samples) {
    if (maxSamples) {
      p.error(maxSamples->where,
              fmt::format("image.adaptive.max_samples must be >= image.samples ({}), got {}",
                          image.samples, adaptive.maxSamples));
    } else {
      p.error(p.place(), fmt::format("image.adaptive.max_samples (default {}) must be >= "
                                     "image.samples ({}); give a larger max_samples",
                                     adaptive.maxSamples, image.samples));
    }
    maxOk = false;
  }
  if (maxOk && checkSize && adaptive.maxSamples > image.samples) {
    if (auto problem = checkRenderSize(image.width, image.height, adaptive.maxSamples,
                                       ctx.options.imageMemoryBudget)) {
      p.error(maxSamples ? maxSamples->where : p.place(),
              "image.adaptive.max_samples: " + *problem);
    }
  }
  image.adaptive = adaptive;
  p.finish();
}

}  // namespace

void buildImage(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  auto params = sectionParameters(scene, e, ctx, "a mapping with width and height", "image");
  if (!params) return;
  ParameterDictionary& p = *params;
  p.declare({"width", "height", "samples", "encoding", "grid", "adaptive"});
  ImageSettings& image = ctx.parts.image;
  const std::size_t errorsBefore = p.errors();
  // First: the encoding decides how every "#rrggbb" colour decodes.
  if (const auto name = p.text("encoding")) {
    if (name->value == "srgb") {
      ctx.encoding = Encoding::Srgb;
    } else if (name->value == "linear") {
      ctx.encoding = Encoding::Linear;
    } else {
      p.error(name->where,
              fmt::format(
                  "image.encoding must be srgb or linear, got {}{}", quoteForMessage(name->value),
                  didYouMean(name->value, std::vector<std::string_view>{"srgb", "linear"})));
    }
  }
  image.encoding = ctx.encoding;
  bool sizeOk = true;
  if (const auto w = readIntegerInRange(p, "width", 1, kMaxImageSide, kRequired)) {
    image.width = static_cast<int>(*w);
  } else {
    sizeOk = false;
  }
  if (const auto h = readIntegerInRange(p, "height", 1, kMaxImageSide, kRequired)) {
    image.height = static_cast<int>(*h);
  } else {
    sizeOk = false;
  }
  if (const auto samples = p.integer("samples")) {
    if (checkInRange(p, *samples, 1, kMaxSamplesPerPixel, "image.samples")) {
      image.samples = static_cast<int>(samples->value);
    } else {
      sizeOk = false;
    }
  }
  if (auto gridParams = p.mapping("grid", "a mapping {interval, color}",
                                  {"in image.grid", "image.grid", "image.grid"})) {
    gridParams->declare({"interval", "color"});
    GridOverlay grid;
    if (const auto interval =
            readIntegerInRange(*gridParams, "interval", 1, std::numeric_limits<int>::max())) {
      grid.interval = static_cast<int>(*interval);
    }
    if (const auto c = readColor(*gridParams, "color", ctx.encoding)) grid.color = *c;
    gridParams->finish();
    image.grid = grid;
  }
  ctx.sceneImage = {image.width, image.height};
  // The caller's --width/--height/--samples replace the scene's values before anything is
  // estimated from them (the film, the meshes' share of the budget); the caller then checks the
  // image it asked for against the limits, naming its options.
  const SceneOverrides& overrides = ctx.options.overrides;
  const bool overridden = overrides.width || overrides.height || overrides.samples;
  if (sizeOk && !overridden) {
    // Refused here, before the renderer allocates anything for it.
    if (auto problem = checkImageSettings(image, ctx.options.imageMemoryBudget)) {
      p.error(p.place(), "image: " + *problem);
      sizeOk = false;
    }
  }
  if (auto adaptive = p.mapping("adaptive", "a mapping {max_samples, threshold}",
                                {"in image.adaptive", "image.adaptive", "image.adaptive"})) {
    buildAdaptive(*adaptive, sizeOk && !overridden, ctx);
  }
  p.finish();
  ctx.imageOk = sizeOk && p.errors() == errorsBefore;
  if (ctx.imageOk && overridden) applyImageOverrides(image, overrides);
}

void buildRender(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  RenderSettings& render = ctx.parts.render;
  auto params = sectionParameters(scene, e, ctx, "a mapping of render settings", "render");
  if (!params) return;
  ParameterDictionary& p = *params;
  p.declare({"max_depth", "min_weight", "blur_samples", "seed", "integrator", "ambient_occlusion",
             "min_depth"});
  // DESIGN.md §10: `whitted` (§3) is the default.
  if (const auto name = p.text("integrator")) {
    if (name->value == "whitted") {
      render.integrator = Integrator::Whitted;
    } else if (name->value == "path") {
      render.integrator = Integrator::Path;
    } else {
      p.error(
          name->where,
          fmt::format("render.integrator must be whitted or path, got {}{}",
                      quoteForMessage(name->value),
                      didYouMean(name->value, std::vector<std::string_view>{"whitted", "path"})));
    }
  }
  if (const auto v = readIntegerInRange(p, "min_depth", 1, kMaxRenderDepth)) {
    render.minDepth = static_cast<int>(*v);
  }
  if (auto occlusion = p.mapping("ambient_occlusion", "a mapping {samples, distance}",
                                 {"in render.ambient_occlusion", "render.ambient_occlusion",
                                  "render.ambient_occlusion"})) {
    ParameterDictionary& ao = *occlusion;
    ao.declare({"samples", "distance"});
    AmbientOcclusion settings;
    if (const auto v = readIntegerInRange(ao, "samples", 1, kMaxOcclusionSamples)) {
      settings.samples = static_cast<int>(*v);
    }
    if (const auto v = readPositive(ao, "distance")) settings.distance = *v;
    ao.finish();
    render.ambientOcclusion = settings;
  }
  if (const auto v = readIntegerInRange(p, "max_depth", 1, kMaxRenderDepth)) {
    render.maxDepth = static_cast<int>(*v);
  }
  if (const auto v = readNonNegative(p, "min_weight")) render.minWeight = *v;
  if (const auto v = readIntegerInRange(p, "blur_samples", 1, kMaxBlurSamples)) {
    render.blurSamples = static_cast<int>(*v);
  }
  if (const auto v = p.unsignedInteger("seed")) render.seed = v->value;
  p.finish();
  // Each integrator's own option has no effect under the other: a warning at its key (not an
  // error: a scene may carry both, the integrator then chosen with --integrator).
  const bool overridden = ctx.options.overrides.integrator.has_value();
  const Integrator used = ctx.options.overrides.integrator.value_or(render.integrator);
  const auto unusedOption = [&](std::string_view key, std::string_view owner) {
    if (!p.has(key)) return;
    ctx.sink.warning(p.location(p.keyPlace(key)),
                     fmt::format("render.{} has no effect: it is an option of the {} integrator, "
                                 "and this render uses {}{}",
                                 key, owner, used == Integrator::Path ? "path" : "whitted",
                                 overridden ? " (--integrator)" : ""));
  };
  if (used == Integrator::Path) unusedOption("ambient_occlusion", "whitted");
  if (used == Integrator::Whitted) unusedOption("min_depth", "path");
  // Allowed (it turns Russian roulette off), but more often a min_depth meant for a larger
  // max_depth: said at the key.
  if (used == Integrator::Path && p.has("min_depth") && render.minDepth >= render.maxDepth) {
    ctx.sink.warning(p.location(p.keyPlace("min_depth")),
                     fmt::format("render.min_depth {} is not below max_depth {}: every path ends "
                                 "at max_depth before Russian roulette would start",
                                 render.minDepth, render.maxDepth));
  }
}

void buildAmbient(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  auto params = sectionParameters(scene, e, ctx, "a mapping {color, intensity}", "ambient");
  if (!params) return;
  ParameterDictionary& p = *params;
  p.declare({"color", "intensity"});
  Color color(1);
  double intensity = 1;
  if (const auto c = readColor(p, "color", ctx.encoding)) color = *c;
  if (const auto v = readNonNegative(p, "intensity")) intensity = *v;
  ctx.parts.ambient = color * intensity;
  p.finish();
}

namespace {

// background: {type: gradient, zenith, horizon, nadir}, {type: sky, top, bottom, up, top_value,
// bottom_value, along} or {type: image, file, intensity, rotate, encoding} (DESIGN.md §9, §13).
void buildEnvironment(const ValueReader& reader, const Entity& e, BuildContext& ctx) {
  ParameterDictionary p(reader, e.value, {"in background", "background", "background"});
  p.declareHidden("type");
  const auto type = p.text("type", kRequired);
  Environment environment;
  if (type && type->value == "gradient") {
    p.declare({"zenith", "horizon", "nadir"});
    environment.kind = BackgroundKind::Gradient;
    const auto zenith = readColor(p, "zenith", ctx.encoding);
    const auto horizon = readColor(p, "horizon", ctx.encoding);
    if (!p.has("zenith")) p.requireKey("zenith");
    if (!p.has("horizon")) p.requireKey("horizon");
    const auto nadir = readColor(p, "nadir", ctx.encoding);
    environment.zenith = zenith.value_or(Color());
    environment.horizon = horizon.value_or(Color());
    environment.nadir = nadir.value_or(environment.horizon);
  } else if (type && type->value == "sky") {
    // Tachyon's BACKGROUND_GRADIENT (SKY_SPHERE, or SKY_ORTHO_PLANE as `along: height`).
    p.declare({"top", "bottom", "up", "top_value", "bottom_value", "along"});
    environment.kind = BackgroundKind::Sky;
    const auto top = readColor(p, "top", ctx.encoding);
    const auto bottom = readColor(p, "bottom", ctx.encoding);
    if (!p.has("top")) p.requireKey("top");
    if (!p.has("bottom")) p.requireKey("bottom");
    environment.skyTop = top.value_or(Color());
    environment.skyBottom = bottom.value_or(Color());
    if (const auto up = readDirection(p, "up")) environment.skyUp = *up;
    const auto topValue = p.number("top_value");
    const auto bottomValue = p.number("bottom_value");
    if (topValue) environment.topValue = topValue->value;
    if (bottomValue) environment.bottomValue = bottomValue->value;
    if ((topValue || bottomValue) && !(environment.topValue != environment.bottomValue)) {
      p.error(topValue ? topValue->where : bottomValue->where,
              fmt::format("background.top_value and background.bottom_value must differ, got {} "
                          "and {}",
                          show(environment.topValue), show(environment.bottomValue)));
    }
    if (const auto along = p.text("along")) {
      if (along->value == "height") {
        environment.skyByHeight = true;
      } else if (along->value != "direction") {
        p.error(along->where, fmt::format("background.along must be direction or height, got {}{}",
                                          quoteForMessage(along->value),
                                          didYouMean(along->value, std::vector<std::string_view>{
                                                                       "direction", "height"})));
      }
    }
  } else if (type && type->value == "image") {
    p.declare({"file", "intensity", "rotate", "encoding"});
    environment.kind = BackgroundKind::Image;
    const auto file = p.text("file", kRequired);
    environment.intensity = readNonNegative(p, "intensity").value_or(1);
    if (const auto rotate = p.number("rotate")) {
      const double radians = rotate->value * std::numbers::pi / 180;
      environment.cosRotate = std::cos(radians);
      environment.sinRotate = std::sin(radians);
    }
    ImageEncoding encoding = ImageEncoding::Srgb;
    ValueId srgbGiven = kNoValue;
    if (const auto text = p.text("encoding")) {
      if (text->value == "linear") {
        encoding = ImageEncoding::Linear;
      } else if (text->value == "srgb") {
        srgbGiven = text->where;
      } else {
        p.error(text->where, fmt::format("background.encoding: expected srgb or linear, got {}",
                                         quoteForMessage(text->value)));
      }
    }
    if (file && p.errors() == 0 && ctx.textures != nullptr) {
      environment.image = ctx.textures->image(p, file->where, file->value, encoding, srgbGiven);
    }
  } else {
    if (type) {
      p.error(type->where,
              fmt::format("unknown background type {}; expected gradient, sky or image (or give a "
                          "colour instead of a mapping){}",
                          quoteForMessage(type->value),
                          didYouMean(type->value,
                                     std::vector<std::string_view>{"gradient", "sky", "image"})));
    }
    // Without a known type no key can be judged: the type's error is the only one.
    p.markUsed(p.keys());
  }
  p.finish();
  if (p.errors() == 0) ctx.parts.environment = std::move(environment);
}

}  // namespace

void buildFog(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  auto params = sectionParameters(scene, e, ctx,
                                  "a mapping {type, start, end, density, color, distance}", "fog");
  if (!params) return;
  ParameterDictionary& p = *params;
  p.declare({"type", "start", "end", "density", "color", "distance"});
  const std::size_t errorsBefore = p.errors();
  Fog fog;
  // Reads a keyword of `choices` (the first is the default), or reports it.
  const auto choice = [&p](std::string_view key, std::vector<std::string_view> choices,
                           Presence presence) -> std::size_t {
    const auto name = p.text(key, presence);
    if (!name) return 0;
    for (std::size_t i = 0; i < choices.size(); ++i) {
      if (name->value == choices[i]) return i;
    }
    p.error(name->where,
            fmt::format("fog.{} must be one of {}, got {}{}", key, fmt::join(choices, ", "),
                        quoteForMessage(name->value), didYouMean(name->value, choices)));
    return 0;
  };
  fog.falloff = static_cast<FogFalloff>(choice("type", {"linear", "exp", "exp2"}, kRequired));
  fog.distance = static_cast<FogDistance>(choice("distance", {"ray", "depth"}, Presence::Optional));
  if (const auto v = p.number("start")) fog.start = v->value;
  if (fog.falloff == FogFalloff::Linear) {
    if (const auto v = p.number("end", kRequired)) {
      if (v->value > fog.start) {
        fog.end = v->value;
      } else {
        p.error(v->where, fmt::format("fog.end must be > fog.start ({}), got {}", show(fog.start),
                                      show(v->value)));
      }
    }
  } else if (const auto v = readNonNegative(p, "density", kRequired)) {
    fog.density = *v;
  }
  // Read (and checked) whatever the type, as Tachyon's FOG statement gives them all.
  if (fog.falloff != FogFalloff::Linear) p.number("end");
  if (fog.falloff == FogFalloff::Linear) readNonNegative(p, "density");
  if (const auto c = readColor(p, "color", ctx.encoding)) fog.color = *c;
  p.finish();
  if (p.errors() == errorsBefore) ctx.parts.fog = fog;
}

void buildBackground(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  const ValueReader reader = readerOf(scene, e, ctx);
  if (reader.tree().isMap(e.value)) {
    buildEnvironment(reader, e, ctx);
    return;
  }
  // A single colour: read as the one value of a dictionary-less entity.
  const ValuePath path{nullptr, "background", {}, ValuePath::kNoIndex};
  const std::size_t before = ctx.sink.errorCount();
  const auto value = reader.color(e.value, e.place, path);
  if (!value || ctx.sink.errorCount() != before) return;
  ParameterDictionary none(reader, kNoValue, {"", "background", "background"});
  if (const auto c = decodeColor(none, {*value, e.place}, "background", ctx.encoding)) {
    ctx.parts.background = *c;
  }
}

void buildCamera(const SceneDescription& scene, const Entity& e, BuildContext& ctx) {
  auto params = sectionParameters(
      scene, e, ctx, "a mapping with position, direction or look_at, and view_plane or fov",
      "camera");
  if (!params) return;
  ParameterDictionary& p = *params;
  p.declare({"position", "direction", "look_at", "up", "view_plane", "fov", "aperture",
             "focus_distance", "projection"});
  CameraSpec& spec = ctx.parts.camera;
  // Orthographic: parallel rays from the view plane, which then needs no distance (Tachyon's and
  // VMD's orthographic camera).
  if (const auto projection = p.text("projection")) {
    if (projection->value == "orthographic") {
      spec.orthographic = true;
    } else if (projection->value != "perspective") {
      p.error(projection->where,
              fmt::format("camera.projection must be perspective or orthographic, got {}{}",
                          quoteForMessage(projection->value),
                          didYouMean(projection->value, std::vector<std::string_view>{
                                                            "perspective", "orthographic"})));
    }
  }
  if (spec.orthographic) {
    for (const char* key : {"fov", "aperture", "focus_distance"}) {
      if (p.has(key)) {
        p.error(
            p.keyPlace(key),
            fmt::format("an orthographic camera has no '{}' (its view_plane sets the view)", key));
      }
    }
  }

  // The either/or choices, at the later key when both are given.
  for (const auto& [a, b] : {std::pair{"direction", "look_at"}, std::pair{"view_plane", "fov"}}) {
    if (const ValueId later = p.laterKey(a, b); later != kNoValue) {
      p.error(later, fmt::format("camera has both '{}' and '{}'; give only one of them", a, b));
    } else if (!p.has(a) && !p.has(b)) {
      p.error(p.place(), spec.orthographic && std::string_view(a) == "view_plane"
                             ? std::string("an orthographic camera needs 'view_plane'")
                             : fmt::format("camera needs '{}' or '{}'", a, b));
    }
  }

  const auto position = p.point3("position", kRequired);
  if (position) spec.position = position->value;
  std::optional<Vec3> direction;
  ValueId directionWhere = p.place();
  const auto lookAt = p.point3("look_at");
  if (p.has("direction")) {
    direction = readDirection(p, "direction");
    directionWhere = p.find("direction")->where;
  } else if (lookAt) {
    directionWhere = lookAt->where;
    if (position) {
      direction = unitVector(lookAt->value - position->value);
      if (!direction) {
        p.error(lookAt->where,
                fmt::format("camera.look_at must differ from camera.position, got {} for both",
                            show(toVec(lookAt->value))));
      }
    }
  }
  const auto upWritten = p.vec3("up");
  std::optional<Vec3> up = Vec3{0, 1, 0};
  if (upWritten) {
    up = unitVector(upWritten->value);
    if (!up) {
      p.error(upWritten->where,
              fmt::format("camera.up must be non-zero, got {}", show(upWritten->value)));
    }
  } else if (p.has("up")) {
    up.reset();  // a wrong type, already reported
  }
  if (direction && up && length(cross(*direction, *up)) <= kParallelSine) {
    p.error(
        upWritten ? upWritten->where : directionWhere,
        fmt::format("camera.up {} is parallel to the view direction {}; choose an up that "
                    "points away from it",
                    upWritten ? show(upWritten->value) : "(default [0, 1, 0])", show(*direction)));
  }
  if (direction) spec.direction = *direction;
  if (up) spec.up = *up;

  if (auto plane = p.mapping("view_plane", "a mapping {width, height, distance}",
                             {"in camera.view_plane", "camera.view_plane", "camera.view_plane"})) {
    plane->declare({"width", "height", "distance"});
    if (const auto w = readPositive(*plane, "width", kRequired)) spec.viewPlaneWidth = *w;
    if (const auto h = readPositive(*plane, "height", kRequired)) spec.viewPlaneHeight = *h;
    if (const auto d =
            readPositive(*plane, "distance", spec.orthographic ? Presence::Optional : kRequired)) {
      spec.viewPlaneDistance = *d;
    }
    plane->finish();
    // Square pixels also when the caller changed the image's aspect (--width and --height): the
    // view plane widens or narrows with the image, its height kept, as a fov camera's does.
    const ImageSize& asked = ctx.sceneImage;
    const ImageSettings& image = ctx.parts.image;
    if (ctx.imageOk && spec.viewPlaneWidth > 0 &&
        static_cast<std::int64_t>(image.width) * asked.height !=
            static_cast<std::int64_t>(image.height) * asked.width) {
      spec.viewPlaneWidth *= (static_cast<double>(image.width) / image.height) /
                             (static_cast<double>(asked.width) / asked.height);
    }
  }
  // With both a view plane and a fov (an error above) the view plane is the one checked.
  if (const auto fov = p.number("fov"); fov && !p.has("view_plane")) {
    if (fov->value > 0 && fov->value < 180) {
      spec.fovDegrees = fov->value;
    } else {
      p.error(fov->where,
              fmt::format("camera.fov must be in (0, 180) degrees, got {}", show(fov->value)));
    }
  }
  const auto aperture = p.number("aperture");
  if (aperture && checkNonNegative(p, *aperture, "camera.aperture"))
    spec.aperture = aperture->value;
  const auto focus = p.number("focus_distance");
  if (focus && checkPositive(p, *focus, "camera.focus_distance")) spec.focusDistance = focus->value;
  if (aperture && aperture->value > 0 && !focus) {
    // The point looked at is in focus unless focus_distance says otherwise; it lies on the view
    // axis, so its distance is the distance along vTo.
    if (lookAt && position && direction) {
      spec.focusDistance = length(lookAt->value - position->value);
    } else if (!lookAt) {
      p.error(aperture->where,
              "camera.focus_distance is required when camera.aperture > 0 and the camera has no "
              "look_at (with look_at it defaults to the distance to that point)");
    }
  }
  spec.imageWidth = ctx.parts.image.width;
  spec.imageHeight = ctx.parts.image.height;
  p.finish();

  // The camera's own checks as a last guard (they should agree with the ones above).
  if (p.errors() == 0 && ctx.imageOk) {
    try {
      const Camera camera(spec);
    } catch (const std::invalid_argument& error) {  // CameraError
      p.error(p.place(), fmt::format("camera: {}", error.what()));
    }
  }
}

}  // namespace glint
