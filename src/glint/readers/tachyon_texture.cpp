#include "glint/readers/tachyon_texture.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "glint/core/bounds.h"

namespace glint::tachyon {

std::string upper(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// --- Input -------------------------------------------------------------------------------------

Token Input::need(const Token& statement, std::string_view what) {
  std::optional<Token> t = tokens_.next();
  if (!t) {
    out_.error(tokens_.end(), fmt::format("the file ends inside {} (line {}): expected {}",
                                          statement.text, statement.at.line, what));
    throw SyntaxError{};
  }
  return *t;
}

void Input::expectWord(const Token& statement, const Token& got, std::string_view word) {
  if (upper(got.text) != word) {
    out_.error(got.at, fmt::format("{}: expected {}, got {}", statement.text, word,
                                   quoteForMessage(got.text)));
    throw SyntaxError{};
  }
}

std::string Input::expectEither(const Token& statement, const Token& got, std::string_view first,
                                std::string_view second) {
  std::string word = upper(got.text);
  if (word != first && word != second) {
    out_.error(got.at, fmt::format("{}: expected {} or {}, got {}", statement.text, first, second,
                                   quoteForMessage(got.text)));
    throw SyntaxError{};
  }
  return word;
}

void Input::keyword(const Token& statement, std::string_view word) {
  expectWord(statement, need(statement, word), word);
}

Number Input::number(const Token& statement, std::string_view what) {
  const Token t = need(statement, fmt::format("a number ({})", what));
  const std::optional<double> v = parseNumber(t.text);
  if (!v) {
    out_.error(t.at, fmt::format("{}: expected a number ({}), got {}", statement.text, what,
                                 quoteForMessage(t.text)));
    throw SyntaxError{};
  }
  return Number{std::string(t.text), t.at, *v};
}

Triple Input::point(const Token& statement, std::string_view what) {
  Triple p;
  for (Number& n : p.n) n = number(statement, what);
  // The mirror in x (tachyon_reader.h), exact on the text: a sign added or removed.
  Number& x = p.n[0];
  if (x.value != 0) {
    if (x.text[0] == '-') {
      x.text.erase(0, 1);
    } else if (x.text[0] == '+') {
      x.text[0] = '-';
    } else {
      x.text.insert(0, 1, '-');
    }
    x.value = -x.value;
  }
  return p;
}

Triple Input::color(const Token& statement, std::string_view what) {
  Triple c;
  for (Number& n : c.n) n = number(statement, what);
  return c;
}

void Input::emit(std::string_view key, const Number& n) { out_.entry(key, n.text, n.at); }

void Input::emit(std::string_view key, const Triple& t) {
  out_.key(key, t.n[0].at);
  out_.openList(t.n[0].at);
  for (const Number& n : t.n) out_.scalar(n.text, n.at);
  out_.close();
}

// --- Textures ----------------------------------------------------------------------------------

namespace {

// `f` is whatever number the file holds (1e82, -3, 2.5): only the exact integers 1..10 name one of
// Tachyon's texture functions, and only those are converted to int (a cast of an out-of-range
// double is undefined behaviour).
std::string_view texfuncName(double f) {
  if (!(f >= 1 && f <= 10) || f != std::floor(f)) return "unknown";
  switch (static_cast<int>(f)) {
    case 1:
      return "3D checker";
    case 2:
      return "grit";
    case 3:
      return "marble";
    case 4:
      return "wood";
    case 5:
      return "gradient noise";
    case 6:
      return "cylindrical checker";
    case 7:
      return "cylindrical image map";
    case 8:
      return "spherical image map";
    case 9:
      return "planar image map";
    case 10:
      return "volume image map";
    default:
      return "unknown";
  }
}

Number constant(std::string_view text, double value, const TextPosition& at) {
  return Number{std::string(text), at, value};
}

}  // namespace

// A texture's number within [lo, hi] (Tachyon itself takes anything; glint's materials are
// non-negative, DESIGN.md §7); else an error at it.
void Textures::requireRange(const Number& n, double lo, double hi, std::string_view what) {
  if (n.value >= lo && n.value <= hi) return;
  out_.error(n.at, hi == kInfinity ? fmt::format("{} must be >= {:g}, got {}", what, lo, n.text)
                                   : fmt::format("{} must be between {:g} and {:g}, got {}", what,
                                                 lo, hi, n.text));
  throw SyntaxError{};
}

Texture Textures::body(const Token& statement, bool vertexColors) {
  Texture t;
  in_.keyword(statement, "AMBIENT");
  t.ambient = in_.number(statement, "ambient");
  requireRange(t.ambient, 0, kInfinity, "AMBIENT");
  in_.keyword(statement, "DIFFUSE");
  t.diffuse = in_.number(statement, "diffuse");
  requireRange(t.diffuse, 0, kInfinity, "DIFFUSE");
  in_.keyword(statement, "SPECULAR");
  t.specular = in_.number(statement, "specular (mirror reflection)");
  requireRange(t.specular, 0, kInfinity, "SPECULAR");
  in_.keyword(statement, "OPACITY");
  t.opacity = in_.number(statement, "opacity");
  requireRange(t.opacity, 0, 1, "OPACITY");
  t.phong = constant("0", 0, t.diffuse.at);
  t.phongSize = constant("100", 100, t.diffuse.at);
  Token next = in_.need(statement, "COLOR");
  if (upper(next.text) == "TRANSMODE") {
    const Token mode = in_.need(statement, "a transparency mode");
    out_.error(mode.at, fmt::format("TRANSMODE {} is not supported by glint (transparency is "
                                    "OPACITY, as TRANS_ORIG)",
                                    quoteForMessage(mode.text)));
    throw SyntaxError{};
  }
  if (upper(next.text) == "OUTLINE") {
    const Number outline = in_.number(statement, "outline");
    in_.keyword(statement, "OUTLINE_WIDTH");
    in_.number(statement, "outline width");
    if (outline.value > 0) {
      out_.warning(outline.at, "OUTLINE is not rendered: glint draws no silhouette outlines");
    }
    next = in_.need(statement, "COLOR");
  }
  if (upper(next.text) == "PHONG") {
    const Token kind = in_.need(statement, "PLASTIC or METAL");
    if (upper(kind.text) != "PLASTIC" && upper(kind.text) != "METAL") {
      out_.error(kind.at, fmt::format("PHONG: expected PLASTIC or METAL, got {}",
                                      quoteForMessage(kind.text)));
      throw SyntaxError{};
    }
    t.metal = upper(kind.text) == "METAL";
    t.phong = in_.number(statement, "phong");
    requireRange(t.phong, 0, kInfinity, "PHONG");
    in_.keyword(statement, "PHONG_SIZE");
    t.phongSize = in_.number(statement, "phong size");
    requireRange(t.phongSize, 0, kInfinity, "PHONG_SIZE");
    next = in_.need(statement, "COLOR");
  }
  if (vertexColors) {
    in_.expectWord(statement, next, "VCST");
    for (Number& c : t.color) c = constant("1", 1, next.at);
    return t;
  }
  in_.expectWord(statement, next, "COLOR");
  for (Number& c : t.color) {
    c = in_.number(statement, "color");
    requireRange(c, 0, kInfinity, "COLOR");
  }
  in_.keyword(statement, "TEXFUNC");
  const Number f = in_.number(statement, "texture function");
  if (f.value == 0) return t;
  if (f.value != 1 && f.value != 3 && f.value != 4) {
    out_.error(f.at, fmt::format("TEXFUNC {} ({}) is not supported by glint; TEXFUNC 0 (plain "
                                 "colour), 1 (3D checker), 3 (marble) and 4 (wood) are",
                                 f.text, texfuncName(f.value)));
    throw SyntaxError{};
  }
  t.function = static_cast<TexFunc>(static_cast<int>(f.value));
  in_.keyword(statement, "CENTER");
  t.center = in_.point(statement, "texture centre");
  in_.keyword(statement, "ROTATE");
  in_.color(statement, "texture rotation");  // unused by Tachyon's checker, marble and wood
  in_.keyword(statement, "SCALE");
  t.scale = in_.color(statement, "texture scale");
  if (t.function == TexFunc::Wood && !(t.scale.n[0].value > 0)) {
    out_.error(t.scale.n[0].at,
               fmt::format("TEXFUNC 4 (wood): the scale must be > 0, got {}", t.scale.n[0].text));
    throw SyntaxError{};
  }
  if (t.function != TexFunc::Checker) {
    out_.warning(f.at,
                 fmt::format("TEXFUNC {} ({}) is drawn with glint's {} pattern, {}; "
                             "Tachyon's looks different",
                             f.text, texfuncName(f.value), texfuncName(f.value),
                             t.function == TexFunc::Wood ? "with Tachyon's colours and ring spacing"
                                                         : "with glint's marble colours"));
  }
  return t;
}

Texture Textures::defaultTexture() const {
  Texture t;
  t.ambient = constant("0.1", 0.1, {});
  t.diffuse = constant("0.9", 0.9, {});
  t.specular = constant("0", 0, {});
  t.opacity = constant("1", 1, {});
  t.phong = constant("0", 0, {});
  t.phongSize = constant("100", 100, {});
  for (Number& c : t.color) c = constant("1", 1, {});
  return t;
}

std::string Textures::emitMaterial(const Texture& t, bool transVmd, const std::string& name) {
  // TRANS_VMD: a transparent surface's own colour (diffuse, ambient, highlight and mirror terms)
  // is scaled by its opacity, its transmitted colour by 1 − opacity.
  const double surface = transVmd ? std::clamp(t.opacity.value, 0.0, 1.0) : 1;
  const double kd[3] = {t.diffuse.value * t.color[0].value * surface,
                        t.diffuse.value * t.color[1].value * surface,
                        t.diffuse.value * t.color[2].value * surface};
  const double ka[3] = {t.ambient.value * t.color[0].value * surface,
                        t.ambient.value * t.color[1].value * surface,
                        t.ambient.value * t.color[2].value * surface};
  const double phong = t.phong.value * surface;
  const double ks[3] = {phong * (t.metal ? t.color[0].value : 1),
                        phong * (t.metal ? t.color[1].value : 1),
                        phong * (t.metal ? t.color[2].value : 1)};
  materialNames_.insert(name);
  const ValueId nameValue = out_.scalar(name, t.diffuse.at);
  const ValueId map = out_.nextId();
  out_.openMap(t.diffuse.at);
  // Under ambient occlusion the occluded ambient light lights the diffuse colour, and the
  // texture's own ambient term, which Tachyon never occludes, is its emission.
  const bool glows = ambientOcclusion_ && t.ambient.value > 0;
  if (t.function == TexFunc::Constant) {
    out_.computedTriple("kd", kd, t.diffuse.at);
    out_.computedTriple("ka", ambientOcclusion_ ? kd : ka, t.ambient.at);
    if (glows) out_.computedTriple("emission", ka, t.ambient.at);
  } else {
    emitPattern("kd", t, t.diffuse.value * surface, t.diffuse.at);
    emitPattern("ka", t, (ambientOcclusion_ ? t.diffuse.value : t.ambient.value) * surface,
                t.ambient.at);
    if (glows) emitPattern("emission", t, t.ambient.value * surface, t.ambient.at);
  }
  if (phong != 0) {
    out_.computedTriple("ks", ks, t.phong.at);
    out_.entry("shininess", t.phongSize.text, t.phongSize.at);
  }
  if (t.specular.value != 0) {
    out_.entry("kr", numberText(t.specular.value * surface), t.specular.at);
  }
  if (t.opacity.value < 1) {
    out_.entry("kt", numberText(1 - std::max(t.opacity.value, 0.0)), t.opacity.at);
  }
  out_.close();
  out_.addEntity(EntityKind::MaterialEntity, map, kNoValue, nameValue);
  return name;
}

void Textures::emitPattern(std::string_view key, const Texture& t, double factor,
                           const TextPosition& at) {
  out_.key(key, at);
  out_.openMap(at);
  const auto colors = [&](const std::array<std::array<double, 3>, 2>& pair) {
    out_.key("colors", at);
    out_.openList(at);
    for (const auto& c : pair) {
      const double scaled[3] = {c[0] * factor, c[1] * factor, c[2] * factor};
      out_.openList(at);
      for (const double v : scaled) out_.scalar(numberText(v), at);
      out_.close();
    }
    out_.close();
  };
  const auto point = [&](std::string_view name, const double* xyz) {
    out_.computedTriple(name, xyz, at);
  };
  switch (t.function) {
    case TexFunc::Checker: {
      // Tachyon: cell parity of round(3·|p − centre|) per axis, odd orange, even blue. Per axis,
      // round(3|d|) and floor(3d + 1/2) have the same parity, so this is glint's checker of cells
      // 1/3 whose origin is the centre less 1/6 on each axis (and the mirror in x keeps it).
      out_.entry("type", "checker", at);
      colors({{{0, 0.2, 1}, {1, 0.2, 0}}});
      out_.entry("scale", numberText(1.0 / 3), at);
      const Vec3 c = t.center.vector();
      const double origin[3] = {c.x - 1.0 / 6, c.y - 1.0 / 6, c.z - 1.0 / 6};
      point("center", origin);
      break;
    }
    case TexFunc::Wood: {
      // Tachyon's rings about the y axis through the centre, 60 scale units apart, light
      // yellow-green and black.
      out_.entry("type", "wood", at);
      colors({{{0.8, 1, 0.2}, {0, 0, 0}}});
      out_.entry("scale", numberText(60 * t.scale.n[0].value), at);
      const Vec3 c = t.center.vector();
      const double origin[3] = {c.x, c.y, c.z};
      point("center", origin);
      break;
    }
    case TexFunc::Marble:
    case TexFunc::Constant:  // not called for it
      // Tachyon's marble has no centre and no scale (veins along x); glint's marble, its colours.
      out_.entry("type", "marble", at);
      colors({{{0.9, 0.9, 0.88}, {0.2, 0.22, 0.3}}});
      break;
  }
  out_.close();
}

void Textures::define(const std::string& name, const Texture& texture, const TextPosition& at,
                      bool transVmd) {
  if (alreadyDefined("TEXDEF", name, at)) return;
  std::string material = name;
  if (materialNames_.count(material) > 0) {
    int& k = nextSuffix_.try_emplace(name, 2).first->second;
    do {
      material = fmt::format("{}_{}", name, k++);
    } while (materialNames_.count(material) > 0);
  }
  emitMaterial(texture, transVmd, material);
  named_[name] = material;
  definitions_[name] = texture;
}

bool Textures::alreadyDefined(std::string_view statement, const std::string& name,
                              const TextPosition& at) {
  // Tachyon looks a name up in the order names were defined (TEXDEF and TEXALIAS alike): the
  // first definition wins.
  const auto [it, added] = definedAt_.emplace(name, at);
  if (added) return false;
  out_.warning(at, fmt::format("{} {}: the name is already defined (line {}); as Tachyon does, "
                               "the first definition is kept",
                               statement, quoteForMessage(name), it->second.line));
  return true;
}

void Textures::alias(const std::string& alias, const TextPosition& at, const Token& original) {
  const auto it = named_.find(std::string(original.text));
  if (it == named_.end()) {
    out_.error(original.at, fmt::format("TEXALIAS: undefined texture {} (define it with TEXDEF "
                                        "first)",
                                        quoteForMessage(original.text)));
    throw SyntaxError{};
  }
  if (alreadyDefined("TEXALIAS", alias, at)) return;
  named_[alias] = it->second;
  definitions_[alias] = definitions_[std::string(original.text)];
}

std::string Textures::material(const Texture& t, bool transVmd) {
  std::string key =
      fmt::format("{} {} {} {} {} {} {} {} {} {} {}", t.ambient.text, t.diffuse.text,
                  t.specular.text, t.opacity.text, t.phong.text, t.phongSize.text, t.metal,
                  t.color[0].text, t.color[1].text, t.color[2].text, transVmd);
  if (t.function != TexFunc::Constant) {
    key += fmt::format(" {} {} {} {} {}", static_cast<int>(t.function), t.center.n[0].text,
                       t.center.n[1].text, t.center.n[2].text, t.scale.n[0].text);
  }
  const auto it = byValues_.find(key);
  if (it != byValues_.end()) return it->second;
  std::string name = fmt::format("texture{}", ++generated_);
  while (materialNames_.count(name) > 0) name = fmt::format("texture{}", ++generated_);
  emitMaterial(t, transVmd, name);
  byValues_.emplace(std::move(key), name);
  return name;
}

std::string Textures::vertexColored(Texture t, bool transVmd) {
  for (Number& c : t.color) c = constant("1", 1, t.diffuse.at);
  return material(t, transVmd);
}

std::string Textures::reference(const Token& statement, bool vertexColors, bool transVmd) {
  const Token t = in_.need(statement, "TEXTURE or a texture name");
  if (upper(t.text) == "TEXTURE") return material(body(statement, vertexColors), transVmd);
  const auto it = named_.find(std::string(t.text));
  if (it == named_.end()) {
    out_.error(t.at, fmt::format("{}: undefined texture {} (a TEXDEF name, or TEXTURE and its "
                                 "definition)",
                                 statement.text, quoteForMessage(t.text)));
    throw SyntaxError{};
  }
  if (vertexColors) return vertexColored(definitions_[std::string(t.text)], transVmd);
  return it->second;
}

}  // namespace glint::tachyon
