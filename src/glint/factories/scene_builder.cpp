#include "glint/factories/scene_builder.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "glint/core/transform.h"
#include "glint/geometry/shape.h"
#include "glint/mesh/mesh_loader.h"
#include "glint/readers/spelling.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene_overrides.h"

namespace glint {

bool BuildResult::hasErrors() const {
  for (const Diagnostic& d : diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) return true;
  }
  return false;
}

namespace {

// area light.samples: shadow rays per shading point, the same bound as samples per pixel.
constexpr std::int64_t kMaxAreaLightSamples = 65536;

// up is refused when the sine of its angle to the view direction is at most this; the camera uses
// the same bound (scene/camera.cpp), so a scene that builds here never fails there.
constexpr double kParallelSine = 1e-6;

std::string show(double v) { return fmt::format("{}", v); }
std::string show(const Vec3& v) { return fmt::format("[{}, {}, {}]", v.x, v.y, v.z); }
std::string show(const Color& c) {
  if (c.r == c.g && c.g == c.b) return show(c.r);
  return fmt::format("[{}, {}, {}]", c.r, c.g, c.b);
}

const char* typeLabel(LightType type) {
  switch (type) {
    case LightType::Directional:
      return "directional";
    case LightType::Point:
      return "point";
    case LightType::Spot:
      return "spot";
    case LightType::Area:
      return "area";
  }
  return "light";
}

class Builder {
 public:
  Builder(const SceneDescription& description, const BuildOptions& options, BuildResult& result)
      : d_(description), options_(options), result_(result), parts_(result.parts) {}

  void build() {
    parts_.name = d_.name ? d_.name->value : std::filesystem::path(d_.file).filename().string();
    buildImage();  // first: the encoding decides how every "#rrggbb" colour decodes
    buildRender();
    if (d_.background) {
      if (auto c = decode(*d_.background, "background")) parts_.background = *c;
    }
    buildAmbient();
    buildCamera();
    buildMaterials();
    for (const ObjectDescription& object : d_.objects) buildObject(object);
    for (const LightDescription& light : d_.lights) buildLight(light);
    warnIfUnlit();
  }

 private:
  SourceLocation start() const { return {d_.file, 1, 1}; }
  std::size_t errorCount() const { return errors_; }

  void error(const SourceLocation& where, std::string message) {
    ++errors_;
    result_.diagnostics.push_back({Diagnostic::Severity::Error, where, std::move(message)});
  }
  void warning(const SourceLocation& where, std::string message) {
    result_.diagnostics.push_back({Diagnostic::Severity::Warning, where, std::move(message)});
  }

  bool positive(const Located<double>& v, const std::string& path) {
    if (v.value > 0) return true;
    error(v.where, fmt::format("{} must be > 0, got {}", path, show(v.value)));
    return false;
  }
  bool nonNegative(const Located<double>& v, const std::string& path) {
    if (v.value >= 0) return true;
    error(v.where, fmt::format("{} must be >= 0, got {}", path, show(v.value)));
    return false;
  }
  bool inRange(const Located<std::int64_t>& v, std::int64_t lo, std::int64_t hi,
               const std::string& path) {
    if (v.value >= lo && v.value <= hi) return true;
    if (hi == std::numeric_limits<int>::max()) {
      error(v.where, fmt::format("{} must be >= {}, got {}", path, lo, v.value));
    } else {
      error(v.where, fmt::format("{} must be between {} and {}, got {}", path, lo, hi, v.value));
    }
    return false;
  }

  // A colour in linear RGB: [r, g, b] as written (components ≥ 0), "#rrggbb" decoded as a display
  // code under the image encoding.
  std::optional<Color> decode(const ColorValue& v, const std::string& path) {
    if (v.isHex) {
      const auto channel = [&](std::uint8_t code) {
        const double encoded = code / 255.0;
        return encoding_ == Encoding::Srgb ? srgbToLinear(encoded) : encoded;
      };
      return Color(channel(v.code[0]), channel(v.code[1]), channel(v.code[2]));
    }
    if (v.rgb.r >= 0 && v.rgb.g >= 0 && v.rgb.b >= 0) return v.rgb;
    error(v.where, fmt::format("{} components must be >= 0, got {}", path, show(v.rgb)));
    return std::nullopt;
  }

  std::optional<Color> coefficient(const std::optional<Located<Color>>& v, const Color& fallback,
                                   const std::string& path) {
    if (!v) return fallback;
    const Color& c = v->value;
    if (c.r >= 0 && c.g >= 0 && c.b >= 0) return c;
    error(v->where, fmt::format("{} must be >= 0, got {}", path, show(c)));
    return std::nullopt;
  }

  // The unit vector along v, refusing a zero vector.
  std::optional<Vec3> unit(const Located<Vec3>& v, const std::string& path) {
    const double len = length(v.value);
    if (len > 0 && std::isfinite(len)) return v.value / len;
    if (len > 0) {  // finite components whose squares overflow: scale down first
      const Vec3 scaled = v.value / maxComponent(abs(v.value));
      return normalize(scaled);
    }
    error(v.where, fmt::format("{} must be non-zero, got {}", path, show(v.value)));
    return std::nullopt;
  }

  // The value of a required key, or nullptr. A missing key is reported here only when the parser
  // did not already report a problem with the entity (`complete`).
  template <class T>
  const T* need(const std::optional<Located<T>>& v, bool complete, const SourceLocation& where,
                const std::string& owner, const char* key) {
    if (v) return &v->value;
    if (complete) error(where, fmt::format("{} is missing required key '{}'", owner, key));
    ++missing_;
    return nullptr;
  }

  void buildImage() {
    if (!d_.image) {
      if (d_.complete) error(start(), "the scene is missing required key 'image'");
      return;
    }
    const ImageDescription& image = *d_.image;
    if (image.encoding) encoding_ = image.encoding->value;
    parts_.image.encoding = encoding_;
    const std::size_t errorsBefore = errorCount();
    bool sizeOk = true;
    if (image.width && inRange(*image.width, 1, kMaxImageSide, "image.width")) {
      parts_.image.width = static_cast<int>(image.width->value);
    } else {
      sizeOk = false;
    }
    if (image.height && inRange(*image.height, 1, kMaxImageSide, "image.height")) {
      parts_.image.height = static_cast<int>(image.height->value);
    } else {
      sizeOk = false;
    }
    if (image.samples) {
      if (inRange(*image.samples, 1, kMaxSamplesPerPixel, "image.samples")) {
        parts_.image.samples = static_cast<int>(image.samples->value);
      } else {
        sizeOk = false;
      }
    }
    if (!image.width || !image.height) {
      if (d_.complete) {
        if (!image.width) error(image.where, "image is missing required key 'width'");
        if (!image.height) error(image.where, "image is missing required key 'height'");
      }
    }
    if (image.grid) {
      GridOverlay grid;
      if (image.grid->interval && inRange(*image.grid->interval, 1, std::numeric_limits<int>::max(),
                                          "image.grid.interval")) {
        grid.interval = static_cast<int>(image.grid->interval->value);
      }
      if (image.grid->color) {
        if (auto c = decode(*image.grid->color, "image.grid.color")) grid.color = *c;
      }
      parts_.image.grid = grid;
    }
    // The caller's --width/--height/--samples replace the scene's values before anything is
    // estimated from them (the film, the meshes' share of the budget); the caller then checks the
    // image it asked for against the limits, naming its options.
    const SceneOverrides& overrides = options_.overrides;
    const bool overridden = overrides.width || overrides.height || overrides.samples;
    if (sizeOk && !overridden) {
      // Refused here, before the renderer allocates anything for it.
      if (auto problem = checkImageSettings(parts_.image, options_.imageMemoryBudget)) {
        error(image.where, "image: " + *problem);
        sizeOk = false;
      }
    }
    if (image.adaptive) buildAdaptive(*image.adaptive, sizeOk && !overridden);
    imageOk_ = sizeOk && errorCount() == errorsBefore;
    if (imageOk_ && overridden) applyImageOverrides(parts_.image, overrides);
  }

  // image.adaptive, after image.samples: max_samples may not be below the fixed count, and the
  // worst case (every pixel taking max_samples) must pass the same camera-ray limit.
  void buildAdaptive(const AdaptiveDescription& a, bool sizeOk) {
    AdaptiveSampling adaptive;  // the defaults
    bool maxOk = true;
    if (a.maxSamples) {
      maxOk = inRange(*a.maxSamples, 1, kMaxSamplesPerPixel, "image.adaptive.max_samples");
      if (maxOk) adaptive.maxSamples = static_cast<int>(a.maxSamples->value);
    }
    if (a.threshold && positive(*a.threshold, "image.adaptive.threshold")) {
      adaptive.threshold = a.threshold->value;
    }
    const ImageDescription& image = *d_.image;
    const bool samplesOk = !image.samples || (image.samples->value >= 1 &&
                                              image.samples->value <= kMaxSamplesPerPixel);
    if (maxOk && samplesOk && adaptive.maxSamples < parts_.image.samples) {
      if (a.maxSamples) {
        error(a.maxSamples->where,
              fmt::format("image.adaptive.max_samples must be >= image.samples ({}), got {}",
                          parts_.image.samples, adaptive.maxSamples));
      } else {
        error(a.where, fmt::format("image.adaptive.max_samples (default {}) must be >= "
                                   "image.samples ({}); give a larger max_samples",
                                   adaptive.maxSamples, parts_.image.samples));
      }
      maxOk = false;
    }
    if (maxOk && sizeOk && adaptive.maxSamples > parts_.image.samples) {
      if (auto problem = checkRenderSize(parts_.image.width, parts_.image.height,
                                         adaptive.maxSamples, options_.imageMemoryBudget)) {
        error(a.maxSamples ? a.maxSamples->where : a.where,
              "image.adaptive.max_samples: " + *problem);
      }
    }
    parts_.image.adaptive = adaptive;
  }

  void buildRender() {
    if (options_.overrides.seed) parts_.render.seed = *options_.overrides.seed;
    if (!d_.render) return;
    const RenderDescription& render = *d_.render;
    if (render.maxDepth && inRange(*render.maxDepth, 1, kMaxRenderDepth, "render.max_depth")) {
      parts_.render.maxDepth = static_cast<int>(render.maxDepth->value);
    }
    if (render.minWeight && nonNegative(*render.minWeight, "render.min_weight")) {
      parts_.render.minWeight = render.minWeight->value;
    }
    if (render.blurSamples &&
        inRange(*render.blurSamples, 1, kMaxBlurSamples, "render.blur_samples")) {
      parts_.render.blurSamples = static_cast<int>(render.blurSamples->value);
    }
    if (render.seed) parts_.render.seed = render.seed->value;
    if (options_.overrides.seed) parts_.render.seed = *options_.overrides.seed;
  }

  void buildAmbient() {
    if (!d_.ambient) return;
    Color color(1);
    double intensity = 1;
    if (d_.ambient->color) {
      if (auto c = decode(*d_.ambient->color, "ambient.color")) color = *c;
    }
    if (d_.ambient->intensity && nonNegative(*d_.ambient->intensity, "ambient.intensity")) {
      intensity = d_.ambient->intensity->value;
    }
    parts_.ambient = color * intensity;
  }

  void buildCamera() {
    if (!d_.camera) {
      if (d_.complete) error(start(), "the scene is missing required key 'camera'");
      return;
    }
    const CameraDescription& c = *d_.camera;
    const std::size_t errorsBefore = errorCount();
    CameraSpec& spec = parts_.camera;

    if (const Point3* p = need(c.position, c.complete, c.where, "camera", "position")) {
      spec.position = *p;
    }
    std::optional<Vec3> direction;
    SourceLocation directionWhere = c.where;
    if (c.direction) {
      direction = unit(*c.direction, "camera.direction");
      directionWhere = c.direction->where;
    } else if (c.lookAt) {
      directionWhere = c.lookAt->where;
      if (c.position) {
        const Vec3 toward = c.lookAt->value - c.position->value;
        if (length(toward) > 0) {
          direction = normalize(toward);
        } else {
          error(c.lookAt->where,
                fmt::format("camera.look_at must differ from camera.position, got {} for both",
                            show(toVec(c.lookAt->value))));
        }
      }
    } else if (c.complete) {
      error(c.where, "camera needs 'direction' or 'look_at'");
    }
    std::optional<Vec3> up = Vec3{0, 1, 0};
    if (c.up) up = unit(*c.up, "camera.up");
    if (direction && up) {
      if (length(cross(*direction, *up)) <= kParallelSine) {
        error(c.up ? c.up->where : directionWhere,
              fmt::format("camera.up {} is parallel to the view direction {}; choose an up that "
                          "points away from it",
                          c.up ? show(c.up->value) : "(default [0, 1, 0])", show(*direction)));
      }
    }
    if (direction) spec.direction = *direction;
    if (up) spec.up = *up;

    if (c.viewPlane) {
      const ViewPlaneDescription& plane = *c.viewPlane;
      const bool complete = c.complete;
      if (auto w = need(plane.width, complete, plane.where, "camera.view_plane", "width")) {
        if (positive(*plane.width, "camera.view_plane.width")) spec.viewPlaneWidth = *w;
      }
      if (auto h = need(plane.height, complete, plane.where, "camera.view_plane", "height")) {
        if (positive(*plane.height, "camera.view_plane.height")) spec.viewPlaneHeight = *h;
      }
      if (auto dist =
              need(plane.distance, complete, plane.where, "camera.view_plane", "distance")) {
        if (positive(*plane.distance, "camera.view_plane.distance")) spec.viewPlaneDistance = *dist;
      }
    } else if (c.fov) {
      if (c.fov->value > 0 && c.fov->value < 180) {
        spec.fovDegrees = c.fov->value;
      } else {
        error(c.fov->where,
              fmt::format("camera.fov must be in (0, 180) degrees, got {}", show(c.fov->value)));
      }
    } else if (c.complete) {
      error(c.where, "camera needs 'view_plane' or 'fov'");
    }
    if (c.aperture && nonNegative(*c.aperture, "camera.aperture"))
      spec.aperture = c.aperture->value;
    if (c.focusDistance && positive(*c.focusDistance, "camera.focus_distance")) {
      spec.focusDistance = c.focusDistance->value;
    }
    if (c.aperture && c.aperture->value > 0 && !c.focusDistance) {
      // The point looked at is in focus unless focus_distance says otherwise; it lies on the view
      // axis, so its distance is the distance along vTo.
      if (c.lookAt && c.position && direction) {
        spec.focusDistance = length(c.lookAt->value - c.position->value);
      } else if (!c.lookAt) {
        error(c.aperture->where,
              "camera.focus_distance is required when camera.aperture > 0 and the camera has no "
              "look_at (with look_at it defaults to the distance to that point)");
      }
    }
    spec.imageWidth = parts_.image.width;
    spec.imageHeight = parts_.image.height;

    // The camera's own checks as a last guard (they should agree with the ones above).
    if (c.complete && errorCount() == errorsBefore && imageOk_) {
      try {
        const Camera camera(spec);
      } catch (const std::invalid_argument& e) {  // CameraError
        error(c.where, fmt::format("camera: {}", e.what()));
      }
    }
  }

  std::optional<Material> material(const MaterialDescription& m) {
    Material out;
    const std::size_t errorsBefore = errorCount();
    const std::string& p = m.context;
    if (auto c = coefficient(m.kd, out.kd, p + ".kd")) out.kd = *c;
    if (auto c = coefficient(m.ks, out.ks, p + ".ks")) out.ks = *c;
    if (auto c = coefficient(m.kr, out.kr, p + ".kr")) out.kr = *c;
    if (auto c = coefficient(m.kt, out.kt, p + ".kt")) out.kt = *c;
    if (auto c = coefficient(m.ka, out.ka, p + ".ka")) out.ka = *c;
    if (m.shininess && nonNegative(*m.shininess, p + ".shininess"))
      out.shininess = m.shininess->value;
    if (m.ior && positive(*m.ior, p + ".ior")) out.ior = m.ior->value;
    if (m.reflectionBlur && nonNegative(*m.reflectionBlur, p + ".reflection_blur")) {
      out.reflectionBlur = m.reflectionBlur->value;
    }
    if (m.refractionBlur && nonNegative(*m.refractionBlur, p + ".refraction_blur")) {
      out.refractionBlur = m.refractionBlur->value;
    }
    if (errorCount() != errorsBefore) return std::nullopt;
    return out;
  }

  void buildMaterials() {
    for (const MaterialDescription& m : d_.materials) {
      if (const auto it = materialWhere_.find(m.name); it != materialWhere_.end()) {
        error(m.where, fmt::format("duplicate material '{}': defined twice (first at line {}, "
                                   "column {})",
                                   m.name, it->second.line, it->second.column));
        continue;
      }
      materialWhere_[m.name] = m.where;
      materialIndex_[m.name] = static_cast<std::uint32_t>(parts_.materials.size());
      parts_.materials.push_back(material(m).value_or(Material{}));
    }
  }

  std::uint32_t resolveMaterial(const ObjectDescription& o) {
    if (o.inlineMaterial) {
      const std::optional<Material> m = material(*o.inlineMaterial);
      if (!m) return 0;
      parts_.materials.push_back(*m);
      return static_cast<std::uint32_t>(parts_.materials.size() - 1);
    }
    if (!o.materialName) return 0;  // the default material
    const std::string& name = o.materialName->value;
    if (const auto it = materialIndex_.find(name); it != materialIndex_.end()) return it->second;
    std::vector<std::string> names;
    for (const auto& [n, index] : materialIndex_) names.push_back(n);
    std::string hint = didYouMean(name, names);
    if (hint.empty()) {
      hint = names.empty() ? "; no materials are defined"
                           : fmt::format("; defined: {}", fmt::join(names, ", "));
    }
    error(o.materialName->where,
          fmt::format("{}.material: undefined material '{}'{}", o.typeName, name, hint));
    return 0;
  }

  std::optional<Transform> transform(const ObjectDescription& o) {
    if (o.transform.empty()) return std::nullopt;
    Transform worldFromObject;
    bool ok = true;
    for (std::size_t i = 0; i < o.transform.size(); ++i) {
      const TransformStep& step = o.transform[i];
      const std::string path = fmt::format("{}.transform[{}]", o.typeName, i);
      try {
        Transform t;
        switch (step.kind) {
          case TransformStep::Kind::Translate:
            t = Transform::translate(step.vector.value);
            break;
          case TransformStep::Kind::Scale: {
            const Vec3& s = step.vector.value;
            if (s.x == 0 || s.y == 0 || s.z == 0) {
              error(step.vector.where,
                    fmt::format("{}.scale factors must be non-zero, got {}", path,
                                s.x == s.y && s.y == s.z ? show(s.x) : show(s)));
              ok = false;
              continue;
            }
            t = Transform::scale(s.x, s.y, s.z);
            break;
          }
          case TransformStep::Kind::Rotate: {
            const std::optional<Vec3> axis = unit(step.vector, path + ".rotate.axis");
            if (!axis) {
              ok = false;
              continue;
            }
            t = Transform::rotate(*axis, step.angle.value);
            break;
          }
        }
        // Steps apply in file order: the later step acts on the result of the earlier ones.
        worldFromObject = t * worldFromObject;
      } catch (const std::invalid_argument& e) {  // TransformError, or a singular matrix
        error(step.where, fmt::format("{}: {}", path, e.what()));
        ok = false;
      }
    }
    if (!ok || worldFromObject.isIdentity()) return std::nullopt;
    return worldFromObject;
  }

  // The shape an object describes, after the range checks the factories would repeat less
  // precisely (they cannot point at the key). nullopt when a check failed or a value is missing.
  std::optional<Shape> shape(const ObjectDescription& o) {
    const std::string& t = o.typeName;
    const bool complete = o.complete;
    const SourceLocation& w = o.where;
    const std::size_t errorsBefore = errorCount();
    missing_ = 0;
    const auto radius = [&]() -> std::optional<double> {
      const double* r = need(o.radius, complete, w, t, "radius");
      if (!r || !positive(*o.radius, t + ".radius")) return std::nullopt;
      return *r;
    };
    const auto direction = [&](const std::optional<Located<Vec3>>& v,
                               const char* key) -> std::optional<Vec3> {
      if (!need(v, complete, w, t, key)) return std::nullopt;
      return unit(*v, t + "." + key);
    };
    const auto usable = [&]() { return complete && missing_ == 0 && errorCount() == errorsBefore; };

    switch (o.type) {
      case ShapeType::Sphere: {
        const Point3* c = need(o.center, complete, w, t, "center");
        const auto r = radius();
        if (!usable() || !c || !r) return std::nullopt;
        return Sphere::make(*c, *r);
      }
      case ShapeType::Plane: {
        if (o.points) {
          if (!usable()) return std::nullopt;
          const std::vector<Point3>& p = o.points->value;
          return Plane::fromPoints(p[0], p[1], p[2]);
        }
        const Point3* p = need(o.point, complete, w, t, "point");
        const auto n = direction(o.normal, "normal");
        if (!usable() || !p || !n) return std::nullopt;
        return Plane::make(*p, *n);
      }
      case ShapeType::Triangle: {
        const auto* v = need(o.vertices, complete, w, t, "vertices");
        if (!usable() || !v || v->size() != 3) return std::nullopt;
        return Triangle::make((*v)[0], (*v)[1], (*v)[2]);
      }
      case ShapeType::Polygon: {
        const auto* v = need(o.vertices, complete, w, t, "vertices");
        if (!usable() || !v || v->size() < 3) return std::nullopt;
        return Polygon::make(*v);
      }
      case ShapeType::Rectangle: {
        const Point3* c = need(o.corner, complete, w, t, "corner");
        const auto* e = need(o.edges, complete, w, t, "edges");
        if (!usable() || !c || !e || e->size() != 2) return std::nullopt;
        return Rectangle::make(*c, (*e)[0], (*e)[1]);
      }
      case ShapeType::Quadrangle: {
        const auto* v = need(o.vertices, complete, w, t, "vertices");
        if (!usable() || !v || v->size() != 4) return std::nullopt;
        return Quadrangle::make((*v)[0], (*v)[1], (*v)[2], (*v)[3]);
      }
      case ShapeType::Tube: {
        const Point3* origin = need(o.origin, complete, w, t, "origin");
        const auto axis = direction(o.axis, "axis");
        const auto r = radius();
        if (!usable() || !origin || !axis || !r) return std::nullopt;
        return Tube::make(*origin, *axis, *r);
      }
      case ShapeType::Cylinder: {
        const Point3* base = need(o.base, complete, w, t, "base");
        const auto axis = direction(o.axis, "axis");
        const auto r = radius();
        const double* h = need(o.height, complete, w, t, "height");
        if (h && !positive(*o.height, t + ".height")) h = nullptr;
        if (!usable() || !base || !axis || !r || !h) return std::nullopt;
        return Cylinder::make(*base, *axis, *r, *h);
      }
      case ShapeType::Box: {
        const Point3* lo = need(o.min, complete, w, t, "min");
        const Point3* hi = need(o.max, complete, w, t, "max");
        if (!usable() || !lo || !hi) return std::nullopt;
        return Box::make(*lo, *hi);
      }
      case ShapeType::Disk: {
        const Point3* c = need(o.center, complete, w, t, "center");
        const auto n = direction(o.normal, "normal");
        const auto r = radius();
        if (!usable() || !c || !n || !r) return std::nullopt;
        return Disk::make(*c, *n, *r);
      }
      case ShapeType::Mesh:
        break;  // not a Shape: buildMesh
    }
    return std::nullopt;
  }

  // Where a key of an object was written, or nullptr.
  static const SourceLocation* locationOf(const ObjectDescription& o, std::string_view key) {
    const auto at = [](const auto& field) -> const SourceLocation* {
      return field ? &field->where : nullptr;
    };
    if (key == "center") return at(o.center);
    if (key == "radius") return at(o.radius);
    if (key == "point") return at(o.point);
    if (key == "normal") return at(o.normal);
    if (key == "points") return at(o.points);
    if (key == "vertices") return at(o.vertices);
    if (key == "corner") return at(o.corner);
    if (key == "edges") return at(o.edges);
    if (key == "origin") return at(o.origin);
    if (key == "axis") return at(o.axis);
    if (key == "base") return at(o.base);
    if (key == "height") return at(o.height);
    if (key == "min") return at(o.min);
    if (key == "max") return at(o.max);
    return nullptr;
  }

  // A factory's refusal, at the key it names when it names one ("vertices are collinear",
  // "box min must be < max") — "objects[2] (triangle).vertices are collinear: ..." — else at the
  // object — "objects[2] (polygon): ...".
  void shapeError(const ObjectDescription& o, const std::string& what) {
    shapeError(o, what, fmt::format("objects[{}] ({})", o.index, o.typeName));
  }
  void shapeError(const ObjectDescription& o, const std::string& what, const std::string& prefix) {
    std::string_view rest = what;
    if (rest.size() > o.typeName.size() && rest.compare(0, o.typeName.size(), o.typeName) == 0 &&
        rest[o.typeName.size()] == ' ') {
      rest.remove_prefix(o.typeName.size() + 1);
    }
    const std::size_t end = rest.find_first_of(" [");
    if (end != std::string_view::npos) {
      if (const SourceLocation* where = locationOf(o, rest.substr(0, end))) {
        error(*where, prefix + "." + std::string(rest));
        return;
      }
    }
    error(o.where, prefix + ": " + what);
  }

  // The scene-material index of every material of `file`, added to the scene the first time the
  // file is used without a material override (a file used twice shares them).
  const std::vector<std::uint32_t>& fileMaterials(const MeshFile& file) {
    std::vector<std::uint32_t>& indices = fileMaterials_[&file];
    if (indices.empty()) {
      for (const MeshMaterial& m : file.materials) {
        indices.push_back(static_cast<std::uint32_t>(parts_.materials.size()));
        parts_.materials.push_back(m.material);
      }
    }
    return indices;
  }

  // A mesh object (DESIGN.md §5, §7): its file read once per scene through meshCache_, instanced
  // with the object's transform. The object's `material` replaces every material of the file
  // (their emission too); its `emission` replaces the files' emission. A file that cannot be
  // loaded is an error at the object naming the file as written; dropped degenerate triangles are
  // one warning there.
  void buildMesh(const ObjectDescription& o) {
    const bool overridesMaterial = o.inlineMaterial || o.materialName;
    const std::uint32_t materialIndex = resolveMaterial(o);
    std::optional<Color> emission;
    if (o.emission) emission = decode(*o.emission, o.typeName + ".emission").value_or(Color());
    const std::size_t errorsBefore = errorCount();
    const std::optional<Transform> worldFromFile = transform(o);
    const std::string* name = need(o.file, o.complete, o.where, o.typeName, "file");
    if (name && name->empty()) error(o.file->where, o.typeName + ".file must not be empty");
    if (!o.complete || !name || errorCount() != errorsBefore) return;

    const std::filesystem::path written(*name);
    const std::filesystem::path path = written.is_relative() ? d_.baseDirectory / written : written;
    std::shared_ptr<const MeshFile> file;
    try {
      // Estimated (mesh + BVH, with the film) against the memory limit before anything is read.
      file = meshCache_.load(
          path,
          MeshBudget{options_.imageMemoryBudget,
                     filmBytes(parts_.image.width, parts_.image.height)},
          MeshReadOptions{.sceneFolder = d_.baseDirectory, .cancel = options_.cancel});
    } catch (const MeshLoadError& e) {
      std::string reason = e.what();
      if (path != written && reason == "no such file") {
        reason += fmt::format(" (looked for {}: relative paths start at the scene file's folder)",
                              path.string());
      }
      error(o.where, fmt::format("cannot load mesh file '{}': {}", *name, reason));
      return;
    }
    const std::uint64_t triangles = file->triangleCount();
    if (meshTriangles_ + triangles > kMaxMeshTriangles) {
      error(o.where,
            fmt::format("mesh file '{}' brings the scene's meshes to {} triangles, more than the "
                        "limit of {}",
                        *name, formatCount(static_cast<double>(meshTriangles_ + triangles)),
                        formatCount(static_cast<double>(kMaxMeshTriangles))));
      return;
    }
    meshTriangles_ += triangles;
    if (file->droppedTriangles > 0) {
      warning(o.where, fmt::format("mesh file '{}': dropped {} degenerate triangle{} (zero area, "
                                   "non-finite or invalid vertices); {} remain",
                                   *name, file->droppedTriangles,
                                   file->droppedTriangles == 1 ? "" : "s", triangles));
    }
    const bool smooth = o.smooth ? o.smooth->value : true;
    std::vector<TriangleMesh> meshes =
        instantiateMesh(*file, worldFromFile, smooth, options_.cancel);
    const std::vector<std::uint32_t>* scene = overridesMaterial ? nullptr : &fileMaterials(*file);
    for (TriangleMesh& mesh : meshes) {
      const MeshMaterial& own = file->materials[mesh.materialIndex];
      mesh.emission = emission.value_or(overridesMaterial ? Color() : own.emission);
      mesh.materialIndex = overridesMaterial ? materialIndex : (*scene)[mesh.materialIndex];
      parts_.meshes.push_back(std::move(mesh));
    }
  }

  void buildObject(const ObjectDescription& o) {
    if (o.type == ShapeType::Mesh) {
      buildMesh(o);
      return;
    }
    const std::uint32_t materialIndex = resolveMaterial(o);
    Color emission;
    if (o.emission) {
      if (auto c = decode(*o.emission, o.typeName + ".emission")) emission = *c;
    }
    const std::size_t errorsBefore = errorCount();
    const std::optional<Transform> worldFromObject = transform(o);
    const bool transformOk = errorCount() == errorsBefore;
    try {
      std::optional<Shape> s = shape(o);
      if (!s || !transformOk) return;
      parts_.primitives.emplace_back(std::move(*s), materialIndex, emission, worldFromObject);
    } catch (const ShapeError& e) {
      shapeError(o, e.what());
    } catch (const std::invalid_argument& e) {
      shapeError(o, e.what());
    }
  }

  void buildLight(const LightDescription& l) {
    const std::string owner =
        l.typeName.empty() ? std::string(typeLabel(l.type)) + " light" : l.typeName + " light";
    const std::size_t errorsBefore = errorCount();
    missing_ = 0;
    Color color(1);
    double intensity = 1;
    if (l.color) {
      if (auto c = decode(*l.color, owner + ".color")) color = *c;
    }
    if (l.intensity && nonNegative(*l.intensity, owner + ".intensity")) {
      intensity = l.intensity->value;
    }
    const Color power = color * intensity;

    Attenuation attenuation;
    if (l.attenuation) {
      const auto& a = l.attenuation->value;
      if (a[0] < 0 || a[1] < 0 || a[2] < 0) {
        error(l.attenuation->where, fmt::format("{}.attenuation components must be >= 0, got {}",
                                                owner, show(Vec3{a[0], a[1], a[2]})));
      } else if (a[0] == 0 && a[1] == 0 && a[2] == 0) {
        error(l.attenuation->where,
              fmt::format("{}.attenuation must not be all 0 (the light would be infinitely "
                          "bright)",
                          owner));
      } else {
        attenuation = {a[0], a[1], a[2]};
      }
    }
    double exponent = 1;
    if (l.exponent && nonNegative(*l.exponent, owner + ".exponent")) exponent = l.exponent->value;
    if (l.type == LightType::Area) {
      buildAreaLight(l, power, attenuation, errorsBefore);
      return;
    }

    std::optional<Vec3> direction;
    if (l.type != LightType::Point) {
      if (need(l.direction, l.complete, l.where, owner, "direction")) {
        direction = unit(*l.direction, owner + ".direction");
      }
    }
    const Point3* position = nullptr;
    if (l.type != LightType::Directional) {
      position = need(l.position, l.complete, l.where, owner, "position");
    }
    if (!l.complete || missing_ != 0 || errorCount() != errorsBefore) return;

    switch (l.type) {
      case LightType::Directional:
        parts_.lights.push_back(DirectionalLight{*direction, power});
        break;
      case LightType::Point:
        parts_.lights.push_back(PointLight{*position, power, attenuation});
        break;
      case LightType::Spot:
        parts_.lights.push_back(SpotLight{*position, *direction, power, attenuation, exponent});
        break;
      case LightType::Area:
        break;  // buildAreaLight
    }
    if (isBlack(power)) {
      warning(l.where, fmt::format("{} has zero intensity; it lights nothing", owner));
    }
  }

  // An area light's surface goes through shape() and the shape factories exactly as the object of
  // that shape would (the same ranges, tolerance and messages), then lends the light its geometry.
  void buildAreaLight(const LightDescription& l, const Color& power, const Attenuation& attenuation,
                      std::size_t errorsBefore) {
    AreaLight light;
    light.intensity = power;
    light.attenuation = attenuation;
    if (l.samples && inRange(*l.samples, 1, kMaxAreaLightSamples, "area light.samples")) {
      light.samples = static_cast<int>(l.samples->value);
    }
    if (!l.surface) {
      // The parser reported the missing or unknown shape; a hand-made description may lack it.
      if (l.complete) error(l.where, "area light is missing required key 'shape'");
      return;
    }
    const ObjectDescription& surface = *l.surface;
    std::optional<Shape> shaped;
    try {
      shaped = shape(surface);
    } catch (const std::invalid_argument& e) {  // ShapeError
      shapeError(surface, e.what(), fmt::format("lights[{}] (area light)", l.index));
    }
    if (!shaped || !l.complete || errorCount() != errorsBefore) return;
    if (const auto* r = std::get_if<Rectangle>(&*shaped)) {
      light.shape = AreaShape::Rectangle;
      light.corner = r->corner;
      light.edge1 = r->edge0;
      light.edge2 = r->edge1;
    } else if (const auto* disk = std::get_if<Disk>(&*shaped)) {
      light.shape = AreaShape::Disk;
      light.center = disk->center;
      light.normal = Vec3{disk->normal.x, disk->normal.y, disk->normal.z};
      light.radius = disk->radius;
    } else if (const auto* sphere = std::get_if<Sphere>(&*shaped)) {
      light.shape = AreaShape::Sphere;
      light.center = sphere->center;
      light.radius = sphere->radius;
    } else {
      return;  // the parser admits no other shape
    }
    parts_.lights.push_back(light);
    if (isBlack(power)) warning(l.where, "area light has zero intensity; it lights nothing");
  }

  // Objects shade black without any light, ambient, emission or mirror/glass to show the
  // background; that is almost always a forgotten `lights` or `ambient` section.
  void warnIfUnlit() {
    if (errorCount() != 0 || (parts_.primitives.empty() && parts_.meshes.empty()) ||
        !parts_.lights.empty() || !isBlack(parts_.ambient)) {
      return;
    }
    const auto shows = [&](const Color& emission, std::uint32_t material) {
      const Material& m = parts_.materials[material];
      return !isBlack(emission) || !isBlack(m.kr) || !isBlack(m.kt);
    };
    for (const Primitive& p : parts_.primitives) {
      if (shows(p.emission(), p.materialIndex())) return;
    }
    for (const TriangleMesh& mesh : parts_.meshes) {
      if (shows(mesh.emission, mesh.materialIndex)) return;
    }
    warning({d_.file, 0, 0},
            "the scene has no lights, no ambient light and no emissive, reflective or transparent "
            "objects: every object will render black");
  }

  const SceneDescription& d_;
  const BuildOptions& options_;
  BuildResult& result_;
  SceneParts& parts_;
  Encoding encoding_ = Encoding::Srgb;
  bool imageOk_ = false;
  std::size_t errors_ = 0;
  std::size_t missing_ = 0;  // required keys found absent in the entity being built
  std::map<std::string, std::uint32_t> materialIndex_;
  std::map<std::string, SourceLocation> materialWhere_;
  MeshCache meshCache_;  // each mesh file read once per scene
  std::map<const MeshFile*, std::vector<std::uint32_t>> fileMaterials_;
  std::uint64_t meshTriangles_ = 0;  // in parts_.meshes
};

}  // namespace

BuildResult buildScene(const SceneDescription& description, const BuildOptions& options) {
  BuildResult result;
  Builder(description, options, result).build();
  return result;
}

}  // namespace glint
