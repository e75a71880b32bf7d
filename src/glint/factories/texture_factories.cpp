// One factory per texture type (DESIGN.md §9); docs/scene-format.md lists their keys and defaults.
#include "glint/factories/texture_factories.h"

#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "glint/factories/build_context.h"
#include "glint/readers/spelling.h"

namespace glint {

namespace {

// Octaves of noise a texture may sum: beyond ~20 the terms are below double precision anyway.
constexpr std::int64_t kMaxOctaves = 16;

// `key`: [a, b] of two numbers.
std::optional<Point2> readPair(ParameterDictionary& params, std::string_view key) {
  const auto entry = params.find(key);
  if (!entry) return std::nullopt;
  const ValueReader& reader = params.reader();
  const ValuePath path = params.pathOf(key);
  if (!reader.tree().isList(entry->value) || reader.tree().size(entry->value) != 2) {
    params.error(entry->where, fmt::format("{}: expected [u, v] (two numbers), got {}", path.str(),
                                           reader.describe(entry->value)));
    return std::nullopt;
  }
  double v[2] = {0, 0};
  for (std::size_t i = 0; i < 2; ++i) {
    const ValueId item = reader.tree().item(entry->value, i);
    const auto n =
        reader.number(item, reader.itemPlace(entry->value, entry->where, i), path.item(i));
    if (!n) return std::nullopt;
    v[i] = *n;
  }
  return Point2{v[0], v[1]};
}

// `colors`: two colours, [r, g, b] or "#rrggbb" each; `defaults` when absent.
std::optional<std::array<Color, 2>> readColors(ParameterDictionary& params,
                                               const TextureReadContext& ctx,
                                               const std::array<Color, 2>& defaults) {
  const auto entry = params.find("colors");
  if (!entry) return defaults;
  const ValueReader& reader = params.reader();
  const ValuePath path = params.pathOf("colors");
  if (!reader.tree().isList(entry->value) || reader.tree().size(entry->value) != 2) {
    params.error(entry->where, fmt::format("{}: expected two colours [c0, c1], got {}", path.str(),
                                           reader.describe(entry->value)));
    return std::nullopt;
  }
  std::array<Color, 2> out;
  for (std::size_t i = 0; i < 2; ++i) {
    const ValueId item = reader.tree().item(entry->value, i);
    const ValueId where = reader.itemPlace(entry->value, entry->where, i);
    const auto value = reader.color(item, where, path.item(i));
    if (!value) return std::nullopt;
    const auto c = decodeColor(params, {*value, where}, path.item(i).str(), ctx.sceneEncoding);
    if (!c) return std::nullopt;
    out[i] = *c;
  }
  return out;
}

const std::array<Color, 2> kBlackWhite = {Color(0), Color(1)};

std::optional<Texture> readChecker(ParameterDictionary& p, const TextureReadContext& ctx) {
  const auto colors = readColors(p, ctx, kBlackWhite);
  const auto scale = readPositive(p, "scale");
  const auto center = p.point3("center");
  if (!colors || p.errors() != 0) return std::nullopt;
  return CheckerTexture{*colors, scale.value_or(1), center ? center->value : Point3{}};
}

std::optional<Texture> readChecker2d(ParameterDictionary& p, const TextureReadContext& ctx) {
  const auto colors = readColors(p, ctx, kBlackWhite);
  const auto transform = readUvTransform(p, Point2{8, 8});
  if (!colors || !transform || p.errors() != 0) return std::nullopt;
  return Checker2dTexture{*colors, *transform};
}

std::optional<Texture> readNoiseLike(ParameterDictionary& p, const TextureReadContext& ctx,
                                     NoisePattern pattern, const std::array<Color, 2>& colors,
                                     double turbulence, std::int64_t octaves) {
  NoiseTexture t;
  t.pattern = pattern;
  const auto c = readColors(p, ctx, colors);
  t.scale = readPositive(p, "scale").value_or(1);
  if (const auto center = p.point3("center")) t.center = center->value;
  if (pattern != NoisePattern::Noise) {
    t.turbulence = readNonNegative(p, "turbulence").value_or(turbulence);
  }
  t.octaves = static_cast<int>(readIntegerInRange(p, "octaves", 1, kMaxOctaves).value_or(octaves));
  if (!c || p.errors() != 0) return std::nullopt;
  t.colors = *c;
  return t;
}

std::optional<Texture> readNoise(ParameterDictionary& p, const TextureReadContext& ctx) {
  return readNoiseLike(p, ctx, NoisePattern::Noise, kBlackWhite, 0, 4);
}
std::optional<Texture> readMarble(ParameterDictionary& p, const TextureReadContext& ctx) {
  // White marble with grey-blue veins, like POV-Ray's and Tachyon's defaults.
  return readNoiseLike(p, ctx, NoisePattern::Marble, {Color(0.9, 0.9, 0.88), Color(0.2, 0.22, 0.3)},
                       5, 6);
}
std::optional<Texture> readWood(ParameterDictionary& p, const TextureReadContext& ctx) {
  return readNoiseLike(p, ctx, NoisePattern::Wood,
                       {Color(0.55, 0.33, 0.15), Color(0.3, 0.15, 0.06)}, 0.5, 4);
}

std::optional<Texture> readImage(ParameterDictionary& p, const TextureReadContext& ctx) {
  const auto file = p.text("file", Presence::Required);
  ImageTexture t;
  if (const auto filter = p.text("filter")) {
    if (filter->value == "nearest") {
      t.filter = TextureFilter::Nearest;
    } else if (filter->value == "bilinear") {
      t.filter = TextureFilter::Bilinear;
    } else if (filter->value == "trilinear") {
      t.filter = TextureFilter::Trilinear;
    } else {
      p.error(filter->where,
              fmt::format("{}: expected nearest, bilinear or trilinear, got {}{}",
                          p.pathOf("filter").str(), quoteForMessage(filter->value),
                          didYouMean(filter->value, std::vector<std::string_view>{
                                                        "nearest", "bilinear", "trilinear"})));
    }
  }
  ImageEncoding encoding =
      ctx.role == TextureRole::Color ? ImageEncoding::Srgb : ImageEncoding::Linear;
  ValueId srgbGiven = kNoValue;
  if (const auto e = p.text("encoding")) {
    if (e->value == "srgb") {
      encoding = ImageEncoding::Srgb;
      srgbGiven = e->where;
    } else if (e->value == "linear") {
      encoding = ImageEncoding::Linear;
    } else {
      p.error(e->where, fmt::format("{}: expected srgb or linear, got {}",
                                    p.pathOf("encoding").str(), quoteForMessage(e->value)));
    }
  }
  const auto transform = readUvTransform(p, Point2{1, 1});
  if (!file || !transform || p.errors() != 0 || ctx.images == nullptr) return std::nullopt;
  t.transform = *transform;
  t.image = ctx.images->image(p, file->where, file->value, encoding, srgbGiven);
  if (t.image == nullptr) return std::nullopt;
  return t;
}

}  // namespace

std::optional<UvTransform> readUvTransform(ParameterDictionary& params, Point2 defaultRepeat) {
  UvTransform t;
  t.repeat = defaultRepeat;
  const std::size_t before = params.errors();
  if (const auto repeat = readPair(params, "repeat")) {
    if (repeat->x == 0 || repeat->y == 0) {
      params.error(params.find("repeat")->where,
                   fmt::format("{} components must be non-zero (a negative one mirrors), got "
                               "[{}, {}]",
                               params.pathOf("repeat").str(), show(repeat->x), show(repeat->y)));
    }
    t.repeat = *repeat;
  }
  if (const auto offset = readPair(params, "offset")) t.offset = *offset;
  if (const auto rotate = params.number("rotate")) {
    const double radians = rotate->value * std::numbers::pi / 180;
    t.cosRotate = std::cos(radians);
    t.sinRotate = std::sin(radians);
  }
  if (params.errors() != before) return std::nullopt;
  return t;
}

const std::vector<TextureFactory>& textureFactories() {
  static const std::vector<TextureFactory> factories = {
      {"checker", {"colors", "scale", "center"}, readChecker},
      {"checker2d", {"colors", "repeat", "offset", "rotate"}, readChecker2d},
      {"noise", {"colors", "scale", "center", "octaves"}, readNoise},
      {"marble", {"colors", "scale", "center", "turbulence", "octaves"}, readMarble},
      {"wood", {"colors", "scale", "center", "turbulence", "octaves"}, readWood},
      {"image", {"file", "filter", "encoding", "repeat", "offset", "rotate"}, readImage},
  };
  return factories;
}

const TextureFactory* findTextureFactory(std::string_view type) {
  for (const TextureFactory& f : textureFactories()) {
    if (f.type == type) return &f;
  }
  return nullptr;
}

}  // namespace glint
