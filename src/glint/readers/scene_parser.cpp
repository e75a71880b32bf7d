#include "glint/readers/scene_parser.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/readers/spelling.h"
#include "glint/readers/yaml_tree.h"

namespace glint {

bool ParseResult::hasErrors() const {
  for (const Diagnostic& d : diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) return true;
  }
  return false;
}

namespace {

using Keys = std::vector<std::string_view>;

const Keys kTopKeys = {"name",   "background", "ambient", "camera", "image",
                       "render", "materials",  "objects", "lights"};
const Keys kCameraKeys = {"position",   "direction", "look_at",  "up",
                          "view_plane", "fov",       "aperture", "focus_distance"};
const Keys kViewPlaneKeys = {"width", "height", "distance"};
const Keys kImageKeys = {"width", "height", "samples", "encoding", "grid", "adaptive"};
const Keys kGridKeys = {"interval", "color"};
const Keys kAdaptiveKeys = {"max_samples", "threshold"};
const Keys kRenderKeys = {"max_depth", "min_weight", "blur_samples", "seed"};
const Keys kAmbientKeys = {"color", "intensity"};
const Keys kMaterialKeys = {
    "kd", "ks", "shininess", "kr", "kt", "ka", "ior", "reflection_blur", "refraction_blur"};
const Keys kObjectCommonKeys = {"material", "emission", "transform"};
const Keys kTransformKeys = {"translate", "scale", "rotate"};
const Keys kRotateKeys = {"axis", "angle"};
const Keys kEncodings = {"srgb", "linear"};

struct ShapeInfo {
  std::string_view name;
  ShapeType type;
  Keys keys;      // geometry keys, in the order the documentation lists them
  Keys required;  // plane's either/or choice is checked separately
};

const std::array<ShapeInfo, 11> kShapes{{
    {"sphere", ShapeType::Sphere, {"center", "radius"}, {"center", "radius"}},
    {"plane", ShapeType::Plane, {"point", "normal", "points"}, {}},
    {"triangle", ShapeType::Triangle, {"vertices"}, {"vertices"}},
    {"polygon", ShapeType::Polygon, {"vertices"}, {"vertices"}},
    {"rectangle", ShapeType::Rectangle, {"corner", "edges"}, {"corner", "edges"}},
    {"quadrangle", ShapeType::Quadrangle, {"vertices"}, {"vertices"}},
    {"tube", ShapeType::Tube, {"origin", "axis", "radius"}, {"origin", "axis", "radius"}},
    {"cylinder",
     ShapeType::Cylinder,
     {"base", "axis", "radius", "height"},
     {"base", "axis", "radius", "height"}},
    {"box", ShapeType::Box, {"min", "max"}, {"min", "max"}},
    {"disk", ShapeType::Disk, {"center", "normal", "radius"}, {"center", "normal", "radius"}},
    {"mesh", ShapeType::Mesh, {"file", "smooth"}, {"file"}},
}};

struct LightInfo {
  std::string_view name;
  LightType type;
  Keys keys;
  Keys required;
};

const std::array<LightInfo, 4> kLights{{
    {"directional", LightType::Directional, {"direction", "color", "intensity"}, {"direction"}},
    {"point", LightType::Point, {"position", "color", "intensity", "attenuation"}, {"position"}},
    {"spot",
     LightType::Spot,
     {"position", "direction", "color", "intensity", "attenuation", "exponent"},
     {"position", "direction"}},
    // Plus the geometry keys of its shape (kAreaShapes). `shape` is required, but parseAreaLight
    // reports it missing, with the list of shapes.
    {"area", LightType::Area, {"shape", "color", "intensity", "attenuation", "samples"}, {}},
}};

// The shapes an area light may take: the objects of the same name, with their geometry keys.
const Keys kAreaShapes = {"rectangle", "disk", "sphere"};

const ShapeInfo* shapeInfo(std::string_view name) {
  for (const ShapeInfo& s : kShapes) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

bool contains(const Keys& names, std::string_view key) {
  for (std::string_view n : names) {
    if (n == key) return true;
  }
  return false;
}

// A scalar as quoted in messages, shortened when long.
std::string inQuotes(const std::string& text) {
  constexpr std::size_t kMaxShown = 40;
  if (text.size() <= kMaxShown) return "'" + text + "'";
  return "'" + text.substr(0, kMaxShown) + "...'";
}

// What a node is, for "expected X, got Y".
std::string describe(const yaml::Node& node) {
  switch (node.kind()) {
    case yaml::Node::Kind::Undefined:
    case yaml::Node::Kind::Null:
      return "nothing";
    case yaml::Node::Kind::Scalar:
      return inQuotes(node.scalar());
    case yaml::Node::Kind::Sequence:
      return node.size() == 1 ? "a list of 1 item" : fmt::format("a list of {} items", node.size());
    case yaml::Node::Kind::Map:
      return "a mapping";
  }
  return "nothing";
}

// A YAML 1.2 core-schema float (also 1.1's .inf/.nan spellings), as text → double. Accepts any
// usual notation: 0.00001, 1e-5, 1.5E+3, +2, .5; "inf"/"nan" forms parse to non-finite values,
// which the caller rejects with a precise message.
std::optional<double> parseDouble(std::string_view text) {
  if (text == ".inf" || text == ".Inf" || text == ".INF" || text == "+.inf" || text == "+.Inf" ||
      text == "+.INF") {
    return std::numeric_limits<double>::infinity();
  }
  if (text == "-.inf" || text == "-.Inf" || text == "-.INF") {
    return -std::numeric_limits<double>::infinity();
  }
  if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ptr != end) return std::nullopt;
  // Out of range (1e999) is an infinite request, reported as such.
  if (ec == std::errc::result_out_of_range) {
    return text[0] == '-' ? -std::numeric_limits<double>::infinity()
                          : std::numeric_limits<double>::infinity();
  }
  if (ec != std::errc()) return std::nullopt;
  return value;
}

// One key: value pair of a mapping.
struct Entry {
  std::string key;
  yaml::Node value;
  SourceLocation keyWhere;
  SourceLocation valueWhere;  // the value's own place, or the key's when the value is empty
  bool unknown = false;       // reported as unknown; kept only to detect its repetition
};

// A value to read, with the path that names it in messages ("camera.position", "sphere.radius").
struct Value {
  yaml::Node node;
  SourceLocation where;
  std::string path;
};

class Fields {
 public:
  std::vector<Entry> entries;
  const Entry* find(std::string_view key) const {
    for (const Entry& e : entries) {
      if (e.key == key && !e.unknown) return &e;
    }
    return nullptr;
  }
  const Entry* findAny(std::string_view key) const {
    for (const Entry& e : entries) {
      if (e.key == key) return &e;
    }
    return nullptr;
  }
};

class Parser {
 public:
  Parser(const std::string& file, std::vector<Diagnostic>& diagnostics)
      : file_(file), diagnostics_(diagnostics) {}

  void parseRoot(const yaml::Node& root, SceneDescription& scene);

  SourceLocation at(const yaml::Mark& mark) const {
    if (mark.line < 0) return {file_, 0, 0};
    return {file_, mark.line + 1, mark.column + 1};
  }
  SourceLocation at(const yaml::Node& node) const { return at(node.mark()); }
  SourceLocation start() const { return {file_, 1, 1}; }

  void error(const SourceLocation& where, std::string message) {
    diagnostics_.push_back({Diagnostic::Severity::Error, where, std::move(message)});
  }
  std::size_t errorCount() const { return diagnostics_.size(); }

 private:
  // The entries of a mapping in file order. Reports keys that are not plain names, duplicate keys
  // (at the second occurrence, which is dropped) and, when `known` is given, unknown keys (also
  // dropped). `context` completes "unknown key 'x' ..." — "in sphere", "at the top level".
  Fields readFields(const yaml::Node& map, std::string_view context, const Keys* known,
                    bool namesMaterials = false);

  static Value valueOf(const Entry& e, const std::string& parentPath) {
    return {e.value, e.valueWhere, parentPath.empty() ? e.key : parentPath + "." + e.key};
  }
  Value element(const Value& list, std::size_t i) {
    const yaml::Node child = list.node[i];
    return {child, child.isNull() ? list.where : at(child), fmt::format("{}[{}]", list.path, i)};
  }

  bool expectMapping(const Value& v, std::string_view what) {
    if (v.node.isMap()) return true;
    error(v.where, fmt::format("{}: expected {}, got {}", v.path, what, describe(v.node)));
    return false;
  }

  std::optional<Located<double>> number(const Value& v);
  std::optional<Located<std::int64_t>> integer(const Value& v);
  std::optional<Located<std::uint64_t>> unsignedInteger(const Value& v);
  std::optional<std::array<double, 3>> triple(const Value& v, std::string_view what);
  std::optional<Located<Vec3>> vec3(const Value& v);
  std::optional<Located<Point3>> point3(const Value& v);
  std::optional<ColorValue> color(const Value& v);
  std::optional<Located<Color>> coefficient(const Value& v);
  std::optional<Located<std::string>> text(const Value& v);
  std::optional<Located<bool>> boolean(const Value& v);
  std::optional<Located<std::vector<Point3>>> pointList(const Value& v, std::size_t minCount,
                                                        std::size_t maxCount);
  std::optional<Located<std::vector<Vec3>>> vectorList(const Value& v, std::size_t count);

  void requireKeys(const Fields& fields, const Keys& required, const SourceLocation& where,
                   std::string_view owner);
  // The later of two keys that must not appear together, or nullptr.
  const Entry* conflict(const Fields& fields, std::string_view a, std::string_view b,
                        std::string_view owner);

  void parseCamera(const Value& v, SceneDescription& scene);
  void parseImage(const Value& v, SceneDescription& scene);
  void parseRender(const Value& v, SceneDescription& scene);
  void parseAmbient(const Value& v, SceneDescription& scene);
  MaterialDescription parseMaterial(const Value& v, std::string name, std::string context);
  void parseMaterials(const Value& v, SceneDescription& scene);
  void parseObjects(const Value& v, SceneDescription& scene);
  void parseObject(const Value& v, std::size_t index, SceneDescription& scene);
  void parseTransform(const Value& v, ObjectDescription& object);
  // Reads geometry key `e` of a shape of `type` into `object` (objects and area lights alike).
  void parseGeometryKey(const Entry& e, const Value& value, ShapeType type,
                        ObjectDescription& object);
  void parseAreaLight(const Value& v, const Fields& fields, LightDescription& light);
  void parseLights(const Value& v, SceneDescription& scene);
  void parseLight(const Value& v, std::size_t index, SceneDescription& scene);

  const std::string& file_;
  std::vector<Diagnostic>& diagnostics_;
};

Fields Parser::readFields(const yaml::Node& map, std::string_view context, const Keys* known,
                          bool namesMaterials) {
  Fields fields;
  for (std::size_t i = 0; i < map.size(); ++i) {
    const yaml::Node keyNode = map.key(i);
    const yaml::Node value = map.value(i);
    const SourceLocation keyWhere = at(keyNode);
    if (!keyNode.isScalar()) {
      error(keyWhere, fmt::format("expected a key name {}, got {}", context, describe(keyNode)));
      continue;
    }
    std::string key = keyNode.scalar();
    if (const Entry* first = fields.findAny(key)) {
      if (namesMaterials) {
        error(keyWhere, fmt::format("duplicate material '{}': defined twice (first at line {}, "
                                    "column {})",
                                    key, first->keyWhere.line, first->keyWhere.column));
      } else {
        error(keyWhere, fmt::format("duplicate key '{}' {} (first at line {}, column {})", key,
                                    context, first->keyWhere.line, first->keyWhere.column));
      }
      continue;
    }
    if (known != nullptr && !contains(*known, key)) {
      // `type` is known to every object and light but not offered in the list of keys.
      std::vector<std::string_view> offered;
      for (std::string_view k : *known) {
        if (k != "type") offered.push_back(k);
      }
      std::string list;
      for (std::string_view k : offered) list += (list.empty() ? "" : ", ") + std::string(k);
      error(keyWhere, fmt::format("unknown key {} {}; expected one of: {}{}", inQuotes(key),
                                  context, list, didYouMean(key, *known)));
      fields.entries.push_back({std::move(key), yaml::Node(), keyWhere, keyWhere, true});
      continue;
    }
    const SourceLocation valueWhere = value.isNull() ? keyWhere : at(value);
    fields.entries.push_back({std::move(key), value, keyWhere, valueWhere});
  }
  return fields;
}

std::optional<Located<double>> Parser::number(const Value& v) {
  if (!v.node.isScalar()) {
    error(v.where, fmt::format("{}: expected a number, got {}", v.path, describe(v.node)));
    return std::nullopt;
  }
  const std::optional<double> value = parseDouble(v.node.scalar());
  if (!value) {
    error(v.where, fmt::format("{}: expected a number, got {}", v.path, inQuotes(v.node.scalar())));
    return std::nullopt;
  }
  if (!std::isfinite(*value)) {
    error(v.where, fmt::format("{} must be a finite number, got {}", v.path, v.node.scalar()));
    return std::nullopt;
  }
  return Located<double>{*value, v.where};
}

std::optional<Located<std::int64_t>> Parser::integer(const Value& v) {
  const std::optional<Located<double>> n = number(v);
  if (!n) return std::nullopt;
  if (n->value != std::trunc(n->value)) {
    error(v.where, fmt::format("{}: expected a whole number, got {}", v.path, v.node.scalar()));
    return std::nullopt;
  }
  // ±2^62 holds every meaningful count; beyond it the value is only an absurd request.
  constexpr double kLimit = 4611686018427387904.0;
  if (std::abs(n->value) > kLimit) {
    error(v.where, fmt::format("{}: {} is too large", v.path, v.node.scalar()));
    return std::nullopt;
  }
  return Located<std::int64_t>{static_cast<std::int64_t>(n->value), v.where};
}

std::optional<Located<std::uint64_t>> Parser::unsignedInteger(const Value& v) {
  if (v.node.isScalar()) {
    // Exact for every 64-bit value, which a double is not.
    std::string_view s = v.node.scalar();
    if (s.size() > 1 && s[0] == '+') s.remove_prefix(1);
    std::uint64_t value = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec == std::errc() && ptr == s.data() + s.size()) {
      return Located<std::uint64_t>{value, v.where};
    }
  }
  const std::optional<Located<double>> n = number(v);
  if (!n) return std::nullopt;
  if (n->value != std::trunc(n->value)) {
    error(v.where, fmt::format("{}: expected a whole number, got {}", v.path, v.node.scalar()));
    return std::nullopt;
  }
  if (n->value < 0 || n->value >= 18446744073709551616.0) {
    error(v.where, fmt::format("{} must be between 0 and {}, got {}", v.path,
                               std::numeric_limits<std::uint64_t>::max(), v.node.scalar()));
    return std::nullopt;
  }
  return Located<std::uint64_t>{static_cast<std::uint64_t>(n->value), v.where};
}

std::optional<std::array<double, 3>> Parser::triple(const Value& v, std::string_view what) {
  if (!v.node.isSequence() || v.node.size() != 3) {
    error(v.where, fmt::format("{}: expected a list of 3 numbers {}, got {}", v.path, what,
                               describe(v.node)));
    return std::nullopt;
  }
  std::array<double, 3> out{};
  bool ok = true;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::optional<Located<double>> n = number(element(v, i));
    if (n) {
      out[i] = n->value;
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<Located<Vec3>> Parser::vec3(const Value& v) {
  const auto t = triple(v, "[x, y, z]");
  if (!t) return std::nullopt;
  return Located<Vec3>{{(*t)[0], (*t)[1], (*t)[2]}, v.where};
}

std::optional<Located<Point3>> Parser::point3(const Value& v) {
  const auto t = triple(v, "[x, y, z]");
  if (!t) return std::nullopt;
  return Located<Point3>{{(*t)[0], (*t)[1], (*t)[2]}, v.where};
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::optional<ColorValue> Parser::color(const Value& v) {
  ColorValue out;
  out.where = v.where;
  if (v.node.isScalar() && !v.node.scalar().empty() && v.node.scalar()[0] == '#') {
    const std::string& s = v.node.scalar();
    bool ok = s.size() == 7;
    for (std::size_t i = 1; ok && i < 7; ++i) ok = hexDigit(s[i]) >= 0;
    if (!ok) {
      error(v.where,
            fmt::format("{}: expected a color \"#rrggbb\" with 6 hexadecimal digits, got {}",
                        v.path, inQuotes(s)));
      return std::nullopt;
    }
    out.isHex = true;
    for (std::size_t c = 0; c < 3; ++c) {
      out.code[c] = static_cast<std::uint8_t>(hexDigit(s[1 + 2 * c]) * 16 + hexDigit(s[2 + 2 * c]));
    }
    return out;
  }
  if (!v.node.isSequence()) {
    error(v.where, fmt::format("{}: expected a color [r, g, b] or \"#rrggbb\", got {}", v.path,
                               describe(v.node)));
    return std::nullopt;
  }
  const auto t = triple(v, "[r, g, b]");
  if (!t) return std::nullopt;
  out.rgb = Color((*t)[0], (*t)[1], (*t)[2]);
  return out;
}

std::optional<Located<Color>> Parser::coefficient(const Value& v) {
  if (v.node.isScalar()) {
    const std::optional<Located<double>> n = number(v);
    if (!n) return std::nullopt;
    return Located<Color>{Color(n->value), v.where};
  }
  if (!v.node.isSequence()) {
    error(v.where, fmt::format("{}: expected a number or a list of 3 numbers [r, g, b], got {}",
                               v.path, describe(v.node)));
    return std::nullopt;
  }
  const auto t = triple(v, "[r, g, b]");
  if (!t) return std::nullopt;
  return Located<Color>{Color((*t)[0], (*t)[1], (*t)[2]), v.where};
}

std::optional<Located<std::string>> Parser::text(const Value& v) {
  if (!v.node.isScalar()) {
    error(v.where, fmt::format("{}: expected text, got {}", v.path, describe(v.node)));
    return std::nullopt;
  }
  return Located<std::string>{v.node.scalar(), v.where};
}

// YAML 1.2 core-schema booleans only: "yes", "on" and "1" are YAML 1.1 spellings that read as
// text elsewhere, so they are refused rather than guessed.
std::optional<Located<bool>> Parser::boolean(const Value& v) {
  if (v.node.isScalar()) {
    const std::string& s = v.node.scalar();
    if (s == "true" || s == "True" || s == "TRUE") return Located<bool>{true, v.where};
    if (s == "false" || s == "False" || s == "FALSE") return Located<bool>{false, v.where};
  }
  error(v.where, fmt::format("{}: expected true or false, got {}", v.path, describe(v.node)));
  return std::nullopt;
}

std::optional<Located<std::vector<Point3>>> Parser::pointList(const Value& v, std::size_t minCount,
                                                              std::size_t maxCount) {
  const std::string count =
      minCount == maxCount ? std::to_string(minCount) : fmt::format("at least {}", minCount);
  if (!v.node.isSequence() || v.node.size() < minCount || v.node.size() > maxCount) {
    error(v.where, fmt::format("{}: expected a list of {} points [[x, y, z], ...], got {}", v.path,
                               count, describe(v.node)));
    return std::nullopt;
  }
  Located<std::vector<Point3>> out{{}, v.where};
  out.value.reserve(v.node.size());
  bool ok = true;
  for (std::size_t i = 0; i < v.node.size(); ++i) {
    if (const auto p = point3(element(v, i))) {
      out.value.push_back(p->value);
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<Located<std::vector<Vec3>>> Parser::vectorList(const Value& v, std::size_t count) {
  if (!v.node.isSequence() || v.node.size() != count) {
    error(v.where, fmt::format("{}: expected a list of {} vectors [[x, y, z], ...], got {}", v.path,
                               count, describe(v.node)));
    return std::nullopt;
  }
  Located<std::vector<Vec3>> out{{}, v.where};
  bool ok = true;
  for (std::size_t i = 0; i < count; ++i) {
    if (const auto e = vec3(element(v, i))) {
      out.value.push_back(e->value);
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

void Parser::requireKeys(const Fields& fields, const Keys& required, const SourceLocation& where,
                         std::string_view owner) {
  for (std::string_view key : required) {
    if (fields.find(key)) continue;
    // A misspelling of the key was already reported as unknown, with the suggestion: one error.
    bool misspelt = false;
    for (const Entry& e : fields.entries) {
      if (e.unknown && closestName(e.key, std::vector<std::string_view>{key}) == key) {
        misspelt = true;
      }
    }
    if (!misspelt) error(where, fmt::format("{} is missing required key '{}'", owner, key));
  }
}

const Entry* Parser::conflict(const Fields& fields, std::string_view a, std::string_view b,
                              std::string_view owner) {
  const Entry* ea = fields.find(a);
  const Entry* eb = fields.find(b);
  if (!ea || !eb) return nullptr;
  const Entry* later =
      ea->keyWhere.line > eb->keyWhere.line ||
              (ea->keyWhere.line == eb->keyWhere.line && ea->keyWhere.column > eb->keyWhere.column)
          ? ea
          : eb;
  error(later->keyWhere,
        fmt::format("{} has both '{}' and '{}'; give only one of them", owner, a, b));
  return later;
}

void Parser::parseRoot(const yaml::Node& root, SceneDescription& scene) {
  const Fields top = readFields(root, "at the top level", &kTopKeys);
  for (std::string_view key : {"camera", "image"}) {
    if (!top.find(key)) {
      error(start(), fmt::format("the scene is missing required key '{}'", key));
    }
  }
  for (const Entry& e : top.entries) {
    const Value v = valueOf(e, "");
    if (e.key == "name") {
      scene.name = text(v);
    } else if (e.key == "background") {
      scene.background = color(v);
    } else if (e.key == "ambient") {
      parseAmbient(v, scene);
    } else if (e.key == "camera") {
      parseCamera(v, scene);
    } else if (e.key == "image") {
      parseImage(v, scene);
    } else if (e.key == "render") {
      parseRender(v, scene);
    } else if (e.key == "materials") {
      parseMaterials(v, scene);
    } else if (e.key == "objects") {
      parseObjects(v, scene);
    } else if (e.key == "lights") {
      parseLights(v, scene);
    }
  }
}

void Parser::parseCamera(const Value& v, SceneDescription& scene) {
  if (!expectMapping(v, "a mapping with position, direction or look_at, and view_plane or fov")) {
    return;
  }
  const std::size_t errorsBefore = errorCount();
  CameraDescription camera;
  camera.where = at(v.node);
  const Fields fields = readFields(v.node, "in camera", &kCameraKeys);
  requireKeys(fields, {"position"}, camera.where, "camera");
  if (!conflict(fields, "direction", "look_at", "camera") && !fields.find("direction") &&
      !fields.find("look_at")) {
    error(camera.where, "camera needs 'direction' or 'look_at'");
  }
  if (!conflict(fields, "view_plane", "fov", "camera") && !fields.find("view_plane") &&
      !fields.find("fov")) {
    error(camera.where, "camera needs 'view_plane' or 'fov'");
  }
  for (const Entry& e : fields.entries) {
    const Value value = valueOf(e, "camera");
    if (e.key == "position") {
      camera.position = point3(value);
    } else if (e.key == "direction") {
      camera.direction = vec3(value);
    } else if (e.key == "look_at") {
      camera.lookAt = point3(value);
    } else if (e.key == "up") {
      camera.up = vec3(value);
    } else if (e.key == "view_plane") {
      if (!expectMapping(value, "a mapping {width, height, distance}")) continue;
      ViewPlaneDescription plane;
      plane.where = at(value.node);
      const Fields pf = readFields(value.node, "in camera.view_plane", &kViewPlaneKeys);
      requireKeys(pf, kViewPlaneKeys, plane.where, "camera.view_plane");
      for (const Entry& pe : pf.entries) {
        const Value pv = valueOf(pe, "camera.view_plane");
        if (pe.key == "width") plane.width = number(pv);
        if (pe.key == "height") plane.height = number(pv);
        if (pe.key == "distance") plane.distance = number(pv);
      }
      camera.viewPlane = plane;
    } else if (e.key == "fov") {
      camera.fov = number(value);
    } else if (e.key == "aperture") {
      camera.aperture = number(value);
    } else if (e.key == "focus_distance") {
      camera.focusDistance = number(value);
    }
  }
  camera.complete = errorCount() == errorsBefore;
  scene.camera = std::move(camera);
}

void Parser::parseImage(const Value& v, SceneDescription& scene) {
  if (!expectMapping(v, "a mapping with width and height")) return;
  ImageDescription image;
  image.where = at(v.node);
  const Fields fields = readFields(v.node, "in image", &kImageKeys);
  requireKeys(fields, {"width", "height"}, image.where, "image");
  for (const Entry& e : fields.entries) {
    const Value value = valueOf(e, "image");
    if (e.key == "width") {
      image.width = integer(value);
    } else if (e.key == "height") {
      image.height = integer(value);
    } else if (e.key == "samples") {
      image.samples = integer(value);
    } else if (e.key == "encoding") {
      const auto name = text(value);
      if (!name) continue;
      if (name->value == "srgb") {
        image.encoding = Located<Encoding>{Encoding::Srgb, value.where};
      } else if (name->value == "linear") {
        image.encoding = Located<Encoding>{Encoding::Linear, value.where};
      } else {
        error(value.where, fmt::format("image.encoding must be srgb or linear, got {}{}",
                                       inQuotes(name->value), didYouMean(name->value, kEncodings)));
      }
    } else if (e.key == "grid") {
      if (!expectMapping(value, "a mapping {interval, color}")) continue;
      GridDescription grid;
      grid.where = at(value.node);
      const Fields gf = readFields(value.node, "in image.grid", &kGridKeys);
      for (const Entry& ge : gf.entries) {
        const Value gv = valueOf(ge, "image.grid");
        if (ge.key == "interval") grid.interval = integer(gv);
        if (ge.key == "color") grid.color = color(gv);
      }
      image.grid = grid;
    } else if (e.key == "adaptive") {
      if (!expectMapping(value, "a mapping {max_samples, threshold}")) continue;
      AdaptiveDescription adaptive;
      adaptive.where = at(value.node);
      const Fields af = readFields(value.node, "in image.adaptive", &kAdaptiveKeys);
      for (const Entry& ae : af.entries) {
        const Value av = valueOf(ae, "image.adaptive");
        if (ae.key == "max_samples") adaptive.maxSamples = integer(av);
        if (ae.key == "threshold") adaptive.threshold = number(av);
      }
      image.adaptive = adaptive;
    }
  }
  scene.image = std::move(image);
}

void Parser::parseRender(const Value& v, SceneDescription& scene) {
  if (!expectMapping(v, "a mapping of render settings")) return;
  RenderDescription render;
  render.where = at(v.node);
  const Fields fields = readFields(v.node, "in render", &kRenderKeys);
  for (const Entry& e : fields.entries) {
    const Value value = valueOf(e, "render");
    if (e.key == "max_depth") render.maxDepth = integer(value);
    if (e.key == "min_weight") render.minWeight = number(value);
    if (e.key == "blur_samples") render.blurSamples = integer(value);
    if (e.key == "seed") render.seed = unsignedInteger(value);
  }
  scene.render = std::move(render);
}

void Parser::parseAmbient(const Value& v, SceneDescription& scene) {
  if (!expectMapping(v, "a mapping {color, intensity}")) return;
  AmbientDescription ambient;
  ambient.where = at(v.node);
  const Fields fields = readFields(v.node, "in ambient", &kAmbientKeys);
  for (const Entry& e : fields.entries) {
    const Value value = valueOf(e, "ambient");
    if (e.key == "color") ambient.color = color(value);
    if (e.key == "intensity") ambient.intensity = number(value);
  }
  scene.ambient = std::move(ambient);
}

MaterialDescription Parser::parseMaterial(const Value& v, std::string name, std::string context) {
  MaterialDescription material;
  material.name = std::move(name);
  material.context = std::move(context);
  material.where = v.where;
  if (!expectMapping(v,
                     "a mapping of material keys (kd, ks, shininess, kr, kt, ka, ior, "
                     "reflection_blur, refraction_blur)")) {
    return material;
  }
  material.where = at(v.node);
  const std::string owner =
      material.name.empty() ? material.context : "material '" + material.name + "'";
  const Fields fields = readFields(v.node, "in " + owner, &kMaterialKeys);
  for (const Entry& e : fields.entries) {
    const Value value = valueOf(e, material.context);
    if (e.key == "kd") material.kd = coefficient(value);
    if (e.key == "ks") material.ks = coefficient(value);
    if (e.key == "kr") material.kr = coefficient(value);
    if (e.key == "kt") material.kt = coefficient(value);
    if (e.key == "ka") material.ka = coefficient(value);
    if (e.key == "shininess") material.shininess = number(value);
    if (e.key == "ior") material.ior = number(value);
    if (e.key == "reflection_blur") material.reflectionBlur = number(value);
    if (e.key == "refraction_blur") material.refractionBlur = number(value);
  }
  return material;
}

void Parser::parseMaterials(const Value& v, SceneDescription& scene) {
  if (v.node.isNull()) return;  // `materials:` with nothing under it: none
  if (!expectMapping(v, "a mapping from material names to materials")) return;
  const Fields fields = readFields(v.node, "in materials", nullptr, /*namesMaterials=*/true);
  for (const Entry& e : fields.entries) {
    // Kept even when it has errors, so objects naming it do not also report it undefined.
    MaterialDescription m = parseMaterial(valueOf(e, "materials"), e.key, "materials." + e.key);
    m.where = e.keyWhere;
    scene.materials.push_back(std::move(m));
  }
}

void Parser::parseObjects(const Value& v, SceneDescription& scene) {
  if (v.node.isNull()) return;
  if (!v.node.isSequence()) {
    error(v.where, fmt::format("objects: expected a list of objects, got {}", describe(v.node)));
    return;
  }
  for (std::size_t i = 0; i < v.node.size(); ++i) parseObject(element(v, i), i, scene);
}

void Parser::parseObject(const Value& v, std::size_t index, SceneDescription& scene) {
  if (!expectMapping(v, "a mapping with a 'type' (sphere, plane, triangle, ...)")) return;
  const std::size_t errorsBefore = errorCount();
  ObjectDescription object;
  object.index = index;
  object.where = at(v.node);

  std::vector<std::string_view> typeNames;
  for (const ShapeInfo& s : kShapes) typeNames.push_back(s.name);
  const std::string typeList = fmt::format("{}", fmt::join(typeNames, ", "));

  const yaml::Node typeNode = v.node.find("type");
  const ShapeInfo* info = nullptr;
  if (!typeNode.isDefined()) {
    error(object.where,
          fmt::format("object is missing required key 'type' (one of: {})", typeList));
  } else if (!typeNode.isScalar()) {
    error(typeNode.isNull() ? object.where : at(typeNode),
          fmt::format("{}.type: expected an object type ({}), got {}", v.path, typeList,
                      describe(typeNode)));
  } else {
    object.typeName = typeNode.scalar();
    for (const ShapeInfo& s : kShapes) {
      if (s.name == object.typeName) info = &s;
    }
    if (!info) {
      error(at(typeNode),
            fmt::format("unknown object type {}; expected one of: {}{}", inQuotes(object.typeName),
                        typeList, didYouMean(object.typeName, typeNames)));
    }
  }
  if (!info) {
    // Without a type the keys cannot be checked; still report duplicates.
    readFields(v.node, "in " + v.path, nullptr);
    return;
  }
  object.type = info->type;
  const std::string& owner = object.typeName;

  Keys known{"type"};
  known.insert(known.end(), info->keys.begin(), info->keys.end());
  known.insert(known.end(), kObjectCommonKeys.begin(), kObjectCommonKeys.end());
  const Fields fields = readFields(v.node, "in " + owner, &known);
  requireKeys(fields, info->required, object.where, owner);
  if (info->type == ShapeType::Plane) {
    const bool pointNormal = fields.find("point") || fields.find("normal");
    if (fields.find("points") && pointNormal) {
      // At the later of the keys, as for every either/or conflict.
      const Entry* later = nullptr;
      for (const Entry& e : fields.entries) {
        if (e.key == "points" || e.key == "point" || e.key == "normal") later = &e;
      }
      error(later->keyWhere, "plane has both 'points' and 'point'/'normal'; give only one of them");
    } else if (fields.find("points")) {
      // three points: nothing else needed
    } else if (pointNormal) {
      requireKeys(fields, {"point", "normal"}, object.where, owner);
    } else {
      error(object.where, "plane needs 'point' and 'normal', or 'points'");
    }
  }

  for (const Entry& e : fields.entries) {
    const Value value = valueOf(e, owner);
    const std::string& k = e.key;
    if (k == "type" || e.unknown) continue;  // unknown keys are already reported
    parseGeometryKey(e, value, info->type, object);
    if (k == "material") {
      if (value.node.isScalar()) {
        object.materialName = text(value);
      } else if (value.node.isMap()) {
        object.inlineMaterial = parseMaterial(value, "", owner + ".material");
      } else {
        error(value.where, fmt::format("{}: expected a material name or a mapping of material "
                                       "keys, got {}",
                                       value.path, describe(value.node)));
      }
    }
    if (k == "emission") object.emission = color(value);
    if (k == "transform") parseTransform(value, object);
  }
  object.complete = errorCount() == errorsBefore;
  scene.objects.push_back(std::move(object));
}

void Parser::parseGeometryKey(const Entry& e, const Value& value, ShapeType type,
                              ObjectDescription& object) {
  const std::string& k = e.key;
  if (k == "center") object.center = point3(value);
  if (k == "point") object.point = point3(value);
  if (k == "origin") object.origin = point3(value);
  if (k == "base") object.base = point3(value);
  if (k == "corner") object.corner = point3(value);
  if (k == "min") object.min = point3(value);
  if (k == "max") object.max = point3(value);
  if (k == "normal") object.normal = vec3(value);
  if (k == "axis") object.axis = vec3(value);
  if (k == "radius") object.radius = number(value);
  if (k == "height") object.height = number(value);
  if (k == "edges") object.edges = vectorList(value, 2);
  if (k == "points") object.points = pointList(value, 3, 3);
  if (k == "file") object.file = text(value);
  if (k == "smooth") object.smooth = boolean(value);
  if (k == "vertices") {
    switch (type) {
      case ShapeType::Triangle:
        object.vertices = pointList(value, 3, 3);
        break;
      case ShapeType::Quadrangle:
        object.vertices = pointList(value, 4, 4);
        break;
      default:
        object.vertices = pointList(value, 3, std::numeric_limits<std::size_t>::max());
        break;
    }
  }
}

void Parser::parseTransform(const Value& v, ObjectDescription& object) {
  if (!v.node.isSequence()) {
    error(v.where, fmt::format("{}: expected a list of steps ({{translate: [x, y, z]}}, "
                               "{{scale: s}}, {{rotate: {{axis: [x, y, z], angle: degrees}}}}), "
                               "got {}",
                               v.path, describe(v.node)));
    return;
  }
  for (std::size_t i = 0; i < v.node.size(); ++i) {
    const Value stepValue = element(v, i);
    if (!expectMapping(stepValue,
                       "a step {translate: [x, y, z]}, {scale: s} or {rotate: {axis, "
                       "angle}}")) {
      continue;
    }
    TransformStep step;
    step.where = at(stepValue.node);
    const Fields fields = readFields(stepValue.node, "in a transform step", &kTransformKeys);
    if (fields.entries.empty()) {
      error(step.where, fmt::format("{}: a transform step needs one of translate, scale, rotate",
                                    stepValue.path));
      continue;
    }
    const Entry* first = nullptr;
    for (const Entry& e : fields.entries) {
      if (e.unknown) continue;  // already reported
      if (first) {
        error(e.keyWhere, fmt::format("a transform step holds one of translate, scale, rotate; put "
                                      "'{}' in a step of its own",
                                      e.key));
        continue;
      }
      first = &e;
    }
    if (!first) continue;
    const Value value = valueOf(*first, stepValue.path);
    bool ok = false;
    if (first->key == "translate") {
      step.kind = TransformStep::Kind::Translate;
      if (auto t = vec3(value)) {
        step.vector = *t;
        ok = true;
      }
    } else if (first->key == "scale") {
      step.kind = TransformStep::Kind::Scale;
      if (value.node.isScalar()) {
        if (auto s = number(value)) {
          step.vector = {{s->value, s->value, s->value}, s->where};
          ok = true;
        }
      } else if (value.node.isSequence()) {
        if (auto s = vec3(value)) {
          step.vector = *s;
          ok = true;
        }
      } else {
        error(value.where, fmt::format("{}: expected a number or a list of 3 numbers [sx, sy, sz], "
                                       "got {}",
                                       value.path, describe(value.node)));
      }
    } else if (first->key == "rotate") {
      step.kind = TransformStep::Kind::Rotate;
      if (!expectMapping(value, "a mapping {axis: [x, y, z], angle: degrees}")) continue;
      const Fields rf = readFields(value.node, "in " + value.path, &kRotateKeys);
      requireKeys(rf, kRotateKeys, at(value.node), value.path);
      std::optional<Located<Vec3>> axis;
      std::optional<Located<double>> angle;
      for (const Entry& re : rf.entries) {
        if (re.key == "axis") axis = vec3(valueOf(re, value.path));
        if (re.key == "angle") angle = number(valueOf(re, value.path));
      }
      if (axis && angle) {
        step.vector = *axis;
        step.angle = *angle;
        ok = true;
      }
    }
    if (ok) object.transform.push_back(std::move(step));
  }
}

void Parser::parseLights(const Value& v, SceneDescription& scene) {
  if (v.node.isNull()) return;
  if (!v.node.isSequence()) {
    error(v.where, fmt::format("lights: expected a list of lights, got {}", describe(v.node)));
    return;
  }
  for (std::size_t i = 0; i < v.node.size(); ++i) parseLight(element(v, i), i, scene);
}

void Parser::parseLight(const Value& v, std::size_t index, SceneDescription& scene) {
  if (!expectMapping(v, "a mapping with a 'type' (directional, point, spot or area)")) return;
  const std::size_t errorsBefore = errorCount();
  LightDescription light;
  light.index = index;
  light.where = at(v.node);

  std::vector<std::string_view> typeNames;
  for (const LightInfo& l : kLights) typeNames.push_back(l.name);
  const std::string typeList = fmt::format("{}", fmt::join(typeNames, ", "));

  const yaml::Node typeNode = v.node.find("type");
  const LightInfo* info = nullptr;
  if (!typeNode.isDefined()) {
    error(light.where, fmt::format("light is missing required key 'type' (one of: {})", typeList));
  } else if (!typeNode.isScalar()) {
    error(typeNode.isNull() ? light.where : at(typeNode),
          fmt::format("{}.type: expected a light type ({}), got {}", v.path, typeList,
                      describe(typeNode)));
  } else {
    light.typeName = typeNode.scalar();
    for (const LightInfo& l : kLights) {
      if (l.name == light.typeName) info = &l;
    }
    if (light.typeName == "ambient") {
      error(at(typeNode),
            "ambient light is the top-level key 'ambient' ({color, intensity}), "
            "not a light type");
    } else if (!info) {
      error(at(typeNode),
            fmt::format("unknown light type {}; expected one of: {}{}", inQuotes(light.typeName),
                        typeList, didYouMean(light.typeName, typeNames)));
    }
  }
  if (!info) {
    readFields(v.node, "in " + v.path, nullptr);
    return;
  }
  light.type = info->type;
  const std::string owner = light.typeName + " light";

  Keys known{"type"};
  known.insert(known.end(), info->keys.begin(), info->keys.end());
  if (info->type == LightType::Area) {
    // Every geometry key of every area shape is known here, so that a key of another shape gets
    // its own message (parseAreaLight) rather than a plain "unknown key".
    for (std::string_view shape : kAreaShapes) {
      for (std::string_view key : shapeInfo(shape)->keys) {
        if (!contains(known, key)) known.push_back(key);
      }
    }
  }
  const Fields fields = readFields(v.node, "in " + owner, &known);
  requireKeys(fields, info->required, light.where, owner);
  if (info->type == LightType::Area) parseAreaLight(v, fields, light);
  for (const Entry& e : fields.entries) {
    if (e.unknown) continue;  // already reported (another light type's key)
    const Value value = valueOf(e, owner);
    if (e.key == "color") light.color = color(value);
    if (e.key == "intensity") light.intensity = number(value);
    if (e.key == "position") light.position = point3(value);
    if (e.key == "direction") light.direction = vec3(value);
    if (e.key == "exponent") light.exponent = number(value);
    if (e.key == "samples") light.samples = integer(value);
    if (e.key == "attenuation") {
      if (auto t = triple(value, "[kc, kl, kq]")) {
        light.attenuation = Located<std::array<double, 3>>{*t, value.where};
      }
    }
  }
  light.complete = errorCount() == errorsBefore;
  if (light.surface) light.surface->complete = light.complete;
  scene.lights.push_back(std::move(light));
}

// An area light's `shape` and the geometry keys of that shape, read exactly as the object of that
// shape reads them; the geometry keys of the other shapes are errors.
void Parser::parseAreaLight(const Value& v, const Fields& fields, LightDescription& light) {
  const std::string shapeList = fmt::format("{}", fmt::join(kAreaShapes, ", "));
  const ShapeInfo* info = nullptr;
  const Entry* shapeEntry = fields.find("shape");
  if (!shapeEntry) {
    // As requireKeys: a misspelt `shape` was already reported as unknown, with the suggestion.
    bool misspelt = false;
    for (const Entry& e : fields.entries) {
      misspelt = misspelt || (e.unknown && closestName(e.key, Keys{"shape"}) == "shape");
    }
    if (!misspelt) {
      error(light.where,
            fmt::format("area light is missing required key 'shape' (one of: {})", shapeList));
    }
  } else {
    const Value value = valueOf(*shapeEntry, "area light");
    if (!value.node.isScalar()) {
      error(value.where, fmt::format("area light.shape: expected one of {}, got {}", shapeList,
                                     describe(value.node)));
    } else {
      light.shape = Located<std::string>{value.node.scalar(), value.where};
      if (contains(kAreaShapes, light.shape->value)) {
        info = shapeInfo(light.shape->value);
      } else {
        error(value.where, fmt::format("unknown area light shape {}; expected one of: {}{}",
                                       inQuotes(light.shape->value), shapeList,
                                       didYouMean(light.shape->value, kAreaShapes)));
      }
    }
  }
  if (!info) return;  // without a shape its geometry keys cannot be checked

  ObjectDescription surface;
  surface.type = info->type;
  surface.typeName = "area light";
  surface.index = light.index;
  surface.where = at(v.node);
  const std::string owner = std::string(info->name) + " area light";
  requireKeys(fields, info->required, light.where, owner);
  for (const Entry& e : fields.entries) {
    if (e.unknown) continue;
    std::vector<std::string_view> owners;  // the area shapes that have this geometry key
    for (std::string_view shape : kAreaShapes) {
      if (contains(shapeInfo(shape)->keys, e.key)) owners.push_back(shape);
    }
    if (owners.empty()) continue;  // not a geometry key: parseLight reads it
    if (!contains(info->keys, e.key)) {
      error(e.keyWhere, fmt::format("'{}' is a key of a {} area light, not of a {}; a {} takes {}",
                                    e.key, fmt::join(owners, " or "), info->name, info->name,
                                    fmt::join(info->keys, ", ")));
      continue;
    }
    parseGeometryKey(e, valueOf(e, "area light"), info->type, surface);
  }
  light.surface = std::move(surface);
}

// yaml-cpp's syntax messages in plain words.
std::string describeSyntaxError(const std::string& message) {
  static constexpr std::pair<std::string_view, std::string_view> kPlain[] = {
      {"end of map not found", "a mapping is not closed (check the indentation)"},
      {"end of map flow not found", "a '{' is not closed with '}'"},
      {"end of sequence not found", "a list is not closed (check the indentation)"},
      {"end of sequence flow not found", "a '[' is not closed with ']'"},
      {"illegal map value", "unexpected ':' here (check the indentation, or quote the text)"},
      {"illegal map key", "unexpected key here (check the indentation)"},
      {"illegal block entry", "unexpected '-' list item here (check the indentation)"},
      {"illegal flow end", "unexpected closing bracket"},
      {"illegal tab when looking for indentation",
       "tabs are not allowed in indentation; use spaces"},
      {"illegal EOF in scalar", "the file ends inside a quoted text (missing closing quote?)"},
      {"illegal character in scalar", "unexpected character in text"},
      {"unknown escape character: ", "unknown escape sequence in quoted text: \\"},
      {"the referenced anchor is not defined", "an alias (*name) refers to an undefined anchor"},
      {"unknown token", "unexpected character"},
  };
  for (const auto& [library, plain] : kPlain) {
    if (message.rfind(library, 0) == 0) {
      return "syntax error: " + std::string(plain) + message.substr(library.size());
    }
  }
  return "syntax error: " + message;
}

// The 1-based line `line` of text (without its newline).
std::string_view lineOf(std::string_view text, int line) {
  std::size_t begin = 0;
  for (int l = 1; l < line; ++l) {
    begin = text.find('\n', begin);
    if (begin == std::string_view::npos) return {};
    ++begin;
  }
  const std::size_t end = text.find('\n', begin);
  return text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
}

}  // namespace

ParseResult parseScene(std::string_view text, const std::string& file,
                       const std::filesystem::path& baseDirectory) {
  ParseResult result;
  SceneDescription& scene = result.description;
  scene.complete = false;  // until the whole text has been read without error
  scene.file = file;
  scene.baseDirectory = baseDirectory;
  Parser parser(scene.file, result.diagnostics);

  const std::string owned(text);
  yaml::Stream stream;
  try {
    stream = yaml::parse(owned);
  } catch (const yaml::SyntaxError& e) {
    SourceLocation where = parser.at(e.mark);
    if (where.line == 0) where = parser.start();
    if (e.tooDeep) {
      parser.error(where, "syntax error: lists or mappings are nested too deeply");
      return result;
    }
    if (e.refused) {
      // An alias bomb, too many values, an alias inside its own anchor: not a syntax error, and
      // the reader's message is already in plain words.
      parser.error(where, e.what());
      return result;
    }
    std::string message = describeSyntaxError(e.what());
    // A tab in the indentation of this line or the previous one is the usual cause of a baffling
    // syntax error; YAML forbids tabs there.
    for (int line = where.line; line >= 1 && line >= where.line - 1; --line) {
      const std::string_view l = lineOf(text, line);
      const std::size_t indent = l.find_first_not_of(" \t");
      if (l.substr(0, indent).find('\t') != std::string_view::npos) {
        where = {scene.file, line, 1};
        message = "syntax error: tabs are not allowed in indentation; use spaces";
        break;
      }
    }
    parser.error(where, std::move(message));
    return result;
  }

  const std::vector<yaml::Mark>& starts = stream.documentStarts;
  if (stream.stuck) {
    const yaml::Mark& mark = starts.back();
    const std::size_t pos = mark.pos >= 0 ? static_cast<std::size_t>(mark.pos) : owned.size();
    const std::string what = pos < owned.size() ? std::string(1, owned[pos]) : "end of file";
    parser.error(parser.at(mark), fmt::format("syntax error: unexpected '{}' here", what));
  } else if (starts.size() > 1) {
    SourceLocation where = parser.at(starts[1]);
    if (where.line == 0) where = parser.start();
    parser.error(where,
                 "the file holds more than one YAML document (the second starts here); a "
                 "scene file holds exactly one");
  }
  const yaml::Node& root = stream.root;
  if (!root.isDefined() || root.isNull()) {
    if (!stream.stuck) {
      parser.error(parser.start(),
                   "the file is empty; a scene needs at least 'camera' and 'image'");
    }
    return result;
  }
  if (!root.isMap()) {
    parser.error(parser.start(), fmt::format("a scene file must be a mapping of keys (camera, "
                                             "image, objects, ...), got {}",
                                             describe(root)));
    return result;
  }
  parser.parseRoot(root, scene);
  scene.complete = !result.hasErrors();
  return result;
}

}  // namespace glint
