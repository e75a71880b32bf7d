#include "glint/factories/light_factories.h"

#include <algorithm>
#include <string>

#include <fmt/format.h>

#include "glint/readers/spelling.h"
#include "glint/scene/scene_limits.h"

namespace glint {
namespace {

constexpr Presence kRequired = Presence::Required;

// area light.samples: shadow rays per shading point, the same bound as samples per pixel.
constexpr std::int64_t kMaxAreaLightSamples = 65536;

// color × intensity (default white × 1).
Color readPower(ParameterDictionary& p, BuildContext& ctx) {
  Color color(1);
  double intensity = 1;
  if (const auto c = readColor(p, "color", ctx.encoding)) color = *c;
  if (const auto v = readNonNegative(p, "intensity")) intensity = *v;
  return color * intensity;
}

// [kc, kl, kq]: components >= 0, not all 0.
Attenuation readAttenuation(ParameterDictionary& p) {
  const auto a = p.triple("attenuation", "[kc, kl, kq]");
  if (!a) return {};
  const auto& k = a->value;
  const std::string& owner = p.names().path;
  if (k[0] < 0 || k[1] < 0 || k[2] < 0) {
    p.error(a->where, fmt::format("{}.attenuation components must be >= 0, got {}", owner,
                                  show(Vec3{k[0], k[1], k[2]})));
    return {};
  }
  if (k[0] == 0 && k[1] == 0 && k[2] == 0) {
    p.error(a->where, fmt::format("{}.attenuation must not be all 0 (the light would be "
                                  "infinitely bright)",
                                  owner));
    return {};
  }
  return {k[0], k[1], k[2]};
}

std::optional<Light> readDirectional(ParameterDictionary& p, BuildContext& ctx) {
  const auto direction = readDirection(p, "direction", kRequired);
  const Color power = readPower(p, ctx);
  if (!direction) return std::nullopt;
  return DirectionalLight{*direction, power};
}

std::optional<Light> readPoint(ParameterDictionary& p, BuildContext& ctx) {
  const auto position = p.point3("position", kRequired);
  const Color power = readPower(p, ctx);
  const Attenuation attenuation = readAttenuation(p);
  if (!position) return std::nullopt;
  return PointLight{position->value, power, attenuation};
}

std::optional<Light> readSpot(ParameterDictionary& p, BuildContext& ctx) {
  const auto position = p.point3("position", kRequired);
  const auto direction = readDirection(p, "direction", kRequired);
  const Color power = readPower(p, ctx);
  const Attenuation attenuation = readAttenuation(p);
  double exponent = 1;
  if (const auto v = readNonNegative(p, "exponent")) exponent = *v;
  // A falloff cone in degrees (Tachyon's spotlight): both angles, instead of the exponent.
  const auto start = p.number("falloff_start");
  const auto end = p.number("falloff_end");
  double falloffStart = -1;
  double falloffEnd = -1;
  if (start || end) {
    if (p.has("exponent")) {
      p.error(p.keyPlace("exponent"),
              "spot light has both 'exponent' and a falloff cone; give only one of them");
    } else if (!start || !end) {
      p.error(start ? start->where : end->where,
              "spot light needs both 'falloff_start' and 'falloff_end' (degrees)");
    } else if (!(start->value >= 0 && start->value < end->value && end->value <= 180)) {
      p.error(end->where, fmt::format("spot light falloff angles must satisfy 0 <= falloff_start < "
                                      "falloff_end <= 180, got {} and {}",
                                      show(start->value), show(end->value)));
    } else {
      falloffStart = start->value;
      falloffEnd = end->value;
    }
  }
  if (!position || !direction) return std::nullopt;
  return SpotLight{position->value, *direction,   power,     attenuation,
                   exponent,        falloffStart, falloffEnd};
}

// The area shapes that have geometry key `key`, in table order.
std::vector<std::string_view> areaShapesWithKey(std::string_view key) {
  std::vector<std::string_view> owners;
  for (const ObjectFactory* f : areaShapeFactories()) {
    if (std::find(f->keys.begin(), f->keys.end(), key) != f->keys.end()) owners.push_back(f->type);
  }
  return owners;
}

// The shape an area light names in `shape`, or nullptr (reported).
const ObjectFactory* areaShape(ParameterDictionary& p) {
  std::vector<std::string_view> names;
  for (const ObjectFactory* f : areaShapeFactories()) names.push_back(f->type);
  const std::string shapeList = fmt::format("{}", fmt::join(names, ", "));
  const auto entry = p.find("shape");
  if (!entry) {
    // As for every required key: a misspelt `shape` is reported as unknown, with the suggestion.
    bool misspelt = false;
    for (const std::string_view key : p.keys()) {
      misspelt = misspelt || (!p.isDeclared(key) &&
                              closestName(key, std::vector<std::string_view>{"shape"}) == "shape");
    }
    if (!misspelt) {
      p.error(p.place(),
              fmt::format("area light is missing required key 'shape' (one of: {})", shapeList));
    }
    return nullptr;
  }
  const ValueTree& tree = p.reader().tree();
  if (!tree.isScalar(entry->value)) {
    p.error(entry->where, fmt::format("area light.shape: expected one of {}, got {}", shapeList,
                                      p.reader().describe(entry->value)));
    return nullptr;
  }
  const std::string_view shape = tree.scalar(entry->value);
  for (const ObjectFactory* f : areaShapeFactories()) {
    if (f->type == shape) return f;
  }
  p.error(entry->where, fmt::format("unknown area light shape {}; expected one of: {}{}",
                                    quoteForMessage(shape), shapeList, didYouMean(shape, names)));
  return nullptr;
}

// An area light: its `shape` and the geometry keys of that shape, read by the factory of the
// object of that shape; the geometry keys of the other area shapes are errors.
std::optional<Light> readArea(ParameterDictionary& p, BuildContext& ctx) {
  AreaLight light;
  light.intensity = readPower(p, ctx);
  light.attenuation = readAttenuation(p);
  if (const auto samples = readIntegerInRange(p, "samples", 1, kMaxAreaLightSamples)) {
    light.samples = static_cast<int>(*samples);
  }
  std::vector<std::string_view> geometryKeys;
  for (const ObjectFactory* f : areaShapeFactories()) {
    for (const std::string_view key : f->keys) {
      if (std::find(geometryKeys.begin(), geometryKeys.end(), key) == geometryKeys.end()) {
        geometryKeys.push_back(key);
      }
    }
  }
  const ObjectFactory* shape = areaShape(p);
  // The keys of its shape are offered in messages (a disk's but inner_radius: a disk light is a
  // whole disk); the other shapes' are accepted only to be refused by name below.
  for (const std::string_view key : geometryKeys) {
    const bool offered =
        shape != nullptr && key != "inner_radius" &&
        std::find(shape->keys.begin(), shape->keys.end(), key) != shape->keys.end();
    if (offered) {
      p.declare({key});
    } else {
      p.declareHidden(key);
    }
  }
  if (shape == nullptr) {
    p.markUsed(geometryKeys);  // without a shape its geometry keys cannot be checked
    return std::nullopt;
  }
  for (const std::string_view key : p.keys()) {
    const std::vector<std::string_view> owners = areaShapesWithKey(key);
    if (owners.empty() ||
        std::find(shape->keys.begin(), shape->keys.end(), key) != shape->keys.end()) {
      continue;
    }
    std::vector<std::string_view> takes;
    for (const std::string_view k : shape->keys) {
      if (k != "inner_radius") takes.push_back(k);
    }
    p.error(
        p.keyPlace(key),
        fmt::format("'{}' is a key of a {} area light, not of a {}; a {} takes {}", key,
                    fmt::join(owners, " or "), shape->type, shape->type, fmt::join(takes, ", ")));
    p.markUsed({key});
  }
  p.setOwner(std::string(shape->type) + " area light");
  const std::optional<ObjectGeometry> geometry = shape->read(p);
  if (!geometry) return std::nullopt;
  const Shape& surface = std::get<Shape>(*geometry);
  if (const auto* r = std::get_if<Rectangle>(&surface)) {
    light.shape = AreaShape::Rectangle;
    light.corner = r->corner;
    light.edge1 = r->edge0;
    light.edge2 = r->edge1;
  } else if (const auto* disk = std::get_if<Disk>(&surface)) {
    if (disk->innerRadius > 0) {
      p.error(p.keyPlace("inner_radius"),
              "a disk area light has no inner_radius (it is a whole disk)");
      return std::nullopt;
    }
    light.shape = AreaShape::Disk;
    light.center = disk->center;
    light.normal = Vec3{disk->normal.x, disk->normal.y, disk->normal.z};
    light.radius = disk->radius;
  } else if (const auto* sphere = std::get_if<Sphere>(&surface)) {
    light.shape = AreaShape::Sphere;
    light.center = sphere->center;
    light.radius = sphere->radius;
  } else {
    return std::nullopt;  // areaShapeFactories() holds no other shape
  }
  return light;
}

}  // namespace

const std::vector<LightFactory>& lightFactories() {
  static const std::vector<LightFactory> factories = [] {
    std::vector<LightFactory> table = {
        {"directional", {"direction", "color", "intensity"}, readDirectional},
        {"point", {"position", "color", "intensity", "attenuation"}, readPoint},
        {"spot",
         {"position", "direction", "color", "intensity", "attenuation", "exponent", "falloff_start",
          "falloff_end"},
         readSpot},
        // The geometry keys of its shape are declared by readArea, once the shape is known.
        {"area", {"shape", "color", "intensity", "attenuation", "samples"}, readArea},
    };
    return table;
  }();
  return factories;
}

const LightFactory* findLightFactory(std::string_view type) {
  for (const LightFactory& f : lightFactories()) {
    if (f.type == type) return &f;
  }
  return nullptr;
}

}  // namespace glint
