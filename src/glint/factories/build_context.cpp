#include "glint/factories/build_context.h"

#include <cmath>

#include <fmt/format.h>

namespace glint {

std::string show(double v) { return fmt::format("{}", v); }
std::string show(const Vec3& v) { return fmt::format("[{}, {}, {}]", v.x, v.y, v.z); }
std::string show(const Color& c) {
  if (c.r == c.g && c.g == c.b) return show(c.r);
  return fmt::format("[{}, {}, {}]", c.r, c.g, c.b);
}

std::optional<ParameterDictionary> entityParameters(const ValueReader& reader, ValueId value,
                                                    ValueId place, std::string_view what,
                                                    DictionaryNames names) {
  if (reader.tree().isMap(value)) return ParameterDictionary(reader, value, std::move(names));
  reader.error(place,
               fmt::format("{}: expected {}, got {}", names.path, what, reader.describe(value)));
  return std::nullopt;
}

std::optional<Color> decodeColor(ParameterDictionary& params, const Located<ColorValue>& value,
                                 const std::string& path, Encoding encoding) {
  const ColorValue& v = value.value;
  if (v.isHex) {
    const auto channel = [&](std::uint8_t code) {
      const double encoded = code / 255.0;
      return encoding == Encoding::Srgb ? srgbToLinear(encoded) : encoded;
    };
    return Color(channel(v.code[0]), channel(v.code[1]), channel(v.code[2]));
  }
  if (v.rgb.r >= 0 && v.rgb.g >= 0 && v.rgb.b >= 0) return v.rgb;
  params.error(value.where, fmt::format("{} components must be >= 0, got {}", path, show(v.rgb)));
  return std::nullopt;
}

std::optional<Color> readColor(ParameterDictionary& params, std::string_view key,
                               Encoding encoding) {
  const auto value = params.color(key);
  if (!value) return std::nullopt;
  return decodeColor(params, *value, params.pathOf(key).str(), encoding);
}

bool checkPositive(ParameterDictionary& params, const Located<double>& v, const std::string& path) {
  if (v.value > 0) return true;
  params.error(v.where, fmt::format("{} must be > 0, got {}", path, show(v.value)));
  return false;
}

bool checkNonNegative(ParameterDictionary& params, const Located<double>& v,
                      const std::string& path) {
  if (v.value >= 0) return true;
  params.error(v.where, fmt::format("{} must be >= 0, got {}", path, show(v.value)));
  return false;
}

bool checkInRange(ParameterDictionary& params, const Located<std::int64_t>& v, std::int64_t lo,
                  std::int64_t hi, const std::string& path) {
  if (v.value >= lo && v.value <= hi) return true;
  if (hi == std::numeric_limits<int>::max()) {
    // The upper bound only keeps the value in an int: said when it is the one broken.
    params.error(v.where, v.value < lo ? fmt::format("{} must be >= {}, got {}", path, lo, v.value)
                                       : fmt::format("{} must be at most {} (the largest integer "
                                                     "glint keeps), got {}",
                                                     path, hi, v.value));
  } else {
    params.error(v.where,
                 fmt::format("{} must be between {} and {}, got {}", path, lo, hi, v.value));
  }
  return false;
}

std::optional<double> readPositive(ParameterDictionary& params, std::string_view key,
                                   Presence presence) {
  const auto v = params.number(key, presence);
  if (!v || !checkPositive(params, *v, params.pathOf(key).str())) return std::nullopt;
  return v->value;
}

std::optional<double> readNonNegative(ParameterDictionary& params, std::string_view key,
                                      Presence presence) {
  const auto v = params.number(key, presence);
  if (!v || !checkNonNegative(params, *v, params.pathOf(key).str())) return std::nullopt;
  return v->value;
}

std::optional<std::int64_t> readIntegerInRange(ParameterDictionary& params, std::string_view key,
                                               std::int64_t lo, std::int64_t hi,
                                               Presence presence) {
  const auto v = params.integer(key, presence);
  if (!v || !checkInRange(params, *v, lo, hi, params.pathOf(key).str())) return std::nullopt;
  return v->value;
}

std::optional<Color> readCoefficient(ParameterDictionary& params, std::string_view key,
                                     Encoding encoding) {
  const auto v = params.coefficient(key);
  if (!v) return std::nullopt;
  if (v->value.isHex) return decodeColor(params, *v, params.pathOf(key).str(), encoding);
  const Color& c = v->value.rgb;
  if (c.r >= 0 && c.g >= 0 && c.b >= 0) return c;
  params.error(v->where, fmt::format("{} must be >= 0, got {}", params.pathOf(key).str(), show(c)));
  return std::nullopt;
}

std::optional<Vec3> unitVector(const Vec3& v) {
  // Below this length the squared components lose precision in the subnormal range (or vanish),
  // above it their squares may overflow: divide by the largest component first there.
  constexpr double kSmallestDirectLength = 1e-150;
  const double len = length(v);
  if (len > kSmallestDirectLength && std::isfinite(len)) return v / len;
  const double largest = maxComponent(abs(v));
  if (!(largest > 0) || !std::isfinite(largest)) return std::nullopt;
  return normalize(v / largest);
}

std::optional<Vec3> readDirection(ParameterDictionary& params, std::string_view key,
                                  Presence presence) {
  const auto v = params.vec3(key, presence);
  if (!v) return std::nullopt;
  if (const auto u = unitVector(v->value)) return u;
  params.error(v->where, fmt::format("{} must be non-zero, got {}", params.pathOf(key).str(),
                                     show(v->value)));
  return std::nullopt;
}

}  // namespace glint
