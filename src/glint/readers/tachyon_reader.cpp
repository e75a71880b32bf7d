#include "glint/readers/tachyon_reader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/core/cancel.h"
#include "glint/core/vec.h"
#include "glint/readers/spelling.h"
#include "glint/readers/tachyon_geometry.h"
#include "glint/readers/tachyon_texture.h"
#include "glint/readers/text_statements.h"

namespace glint {
namespace {

using namespace tachyon;

const std::vector<std::string_view> kSupported = {"CAMERA",    "LIGHT",       "DIRECTIONAL_LIGHT",
                                                  "SPOTLIGHT", "BACKGROUND",  "BACKGROUND_GRADIENT",
                                                  "FOG",       "SHADER_MODE", "SPHERE",
                                                  "FCYLINDER", "CYLINDER",    "RING",
                                                  "PLANE",     "BOX",         "TRI",
                                                  "STRI",      "VCSTRI",      "VERTEXARRAY",
                                                  "TEXDEF",    "TEXALIAS",    "END_SCENE"};
// Tachyon statements glint does not read (yet), reported by name rather than as unknown words.
const std::vector<std::string_view> kUnsupported = {
    "SPHEREARRAY", "POLYCYLINDER", "SCALARVOL", "IMAGEDEF",        "SKY_LIGHT",    "SCAPE",
    "TPOLYFILE",   "MGFFILE",      "INCLUDE",   "START_CLIPGROUP", "END_CLIPGROUP"};

constexpr std::size_t kStatementsPerPoll = 1024;

// The supported statement nearest to `word` (always one).
// " (the nearest supported statement is X)" when a supported statement is near enough to be meant
// (at most half the word's letters differ, or two: SPHEREARRAY → SPHERE, SPHER → SPHERE), else
// nothing (INCLUDE is not PLANE).
std::string nearestSupported(std::string_view word) {
  // The distance is quadratic in the word's length: a statement is never longer than this.
  constexpr std::size_t kLongestWord = 64;
  word = word.substr(0, kLongestWord);
  std::string_view best = kSupported[0];
  std::size_t bestDistance = SIZE_MAX;
  for (const std::string_view s : kSupported) {
    const std::size_t d = editDistance(word, s);
    if (d < bestDistance) {
      best = s;
      bestDistance = d;
    }
  }
  if (bestDistance > std::max<std::size_t>(2, word.size() / 2)) return {};
  return fmt::format(" (the nearest supported statement is {})", best);
}

struct Camera {
  TextPosition at;
  bool orthographic = false;
  // PROJECTION PERSPECTIVE_DOF: the distance in focus and the lens's f-number (FOCALDIST or
  // FOCALLENGTH, then APERTURE), at the word PERSPECTIVE_DOF.
  std::optional<TextPosition> depthOfField;
  Number focalDistance, fNumber;
  Number zoom, aspect, antialiasing, raydepth;
  Triple center, viewdir, updir;
};

// Tachyon's lens (rt_camera_dof) is a disc of radius FOCALDIST / (2 · APERTURE), the f-number
// raised to at least 0.01; glint's `aperture` is that radius.
double lensRadius(const Camera& c) {
  return c.focalDistance.value / (2 * std::max(c.fNumber.value, 0.01));
}

class TachyonReader {
 public:
  TachyonReader(std::string_view text, SceneEmitter& out, const std::atomic<bool>* cancel)
      : in_(text, out),
        out_(out),
        textures_(in_, out),
        cancel_(cancel),
        geometry_(in_, out, textures_, transVmd_) {}

  void read() {
    try {
      beginScene();
    } catch (const SyntaxError&) {
      return;
    }
    std::size_t statements = 0;
    bool failed = false;
    while (!ended_) {
      const std::optional<Token> t = in_.tokens().next();
      if (!t) {
        // After a statement's error the END_SCENE may have been read as one of its values (a
        // texture name, say): the error already said what is wrong there.
        if (!failed) out_.error(in_.tokens().end(), "the file ends without END_SCENE");
        break;
      }
      if (++statements % kStatementsPerPoll == 0) throwIfCancelled(cancel_);
      try {
        statement(*t);
      } catch (const SyntaxError&) {
        failed = true;
        skipToNextStatement();
      }
    }
    geometry_.emitMeshes();
    emitSettings();
  }

 private:
  void beginScene() {
    const std::optional<Token> begin = in_.tokens().next();
    if (!begin || upper(begin->text) != "BEGIN_SCENE") {
      const TextPosition at = begin ? begin->at : in_.tokens().end();
      out_.error(at, fmt::format("expected BEGIN_SCENE, got {}; a Tachyon scene starts with "
                                 "BEGIN_SCENE and RESOLUTION",
                                 begin ? quoteForMessage(begin->text) : "the end of the file"));
      throw SyntaxError{};
    }
    scene_ = *begin;
    in_.keyword(*begin, "RESOLUTION");
    resolution_[0] = in_.number(*begin, "x resolution");
    resolution_[1] = in_.number(*begin, "y resolution");
  }

  void statement(const Token& t) {
    const std::string word = upper(t.text);
    if (word == "END_SCENE") {
      ended_ = true;
    } else if (word == "CAMERA") {
      camera(t);
    } else if (word == "LIGHT" || word == "SPOTLIGHT") {
      light(t, word == "SPOTLIGHT");
    } else if (word == "DIRECTIONAL_LIGHT") {
      directionalLight(t);
    } else if (word == "BACKGROUND") {
      background_ = in_.color(t, "background");
      backgroundAt_ = t.at;
    } else if (word == "BACKGROUND_GRADIENT") {
      backgroundGradient(t);
    } else if (word == "FOG") {
      fog(t);
    } else if (word == "SHADER_MODE") {
      shaderMode(t);
    } else if (word == "TEXDEF") {
      const Token name = in_.need(t, "a texture name");
      requireTextureName(t, name);
      const Texture texture = textures_.body(t, false);
      textures_.define(std::string(name.text), texture, name.at, transVmd_);
    } else if (word == "TEXALIAS") {
      const Token alias = in_.need(t, "the alias name");
      requireTextureName(t, alias);
      const Token original = in_.need(t, "the texture it names");
      textures_.alias(std::string(alias.text), alias.at, original);
    } else if (word == "SPHERE" || word == "FCYLINDER" || word == "CYLINDER" || word == "RING" ||
               word == "PLANE" || word == "BOX") {
      geometry_.shape(t, word);
    } else if (word == "TRI" || word == "STRI" || word == "VCSTRI") {
      geometry_.triangle(t, word);
    } else if (word == "VERTEXARRAY") {
      geometry_.vertexArray(t);
    } else if (std::find(kUnsupported.begin(), kUnsupported.end(), word) != kUnsupported.end()) {
      out_.error(t.at, fmt::format("the Tachyon statement {} is not supported by glint{}", t.text,
                                   nearestSupported(word)));
      throw SyntaxError{};
    } else {
      out_.error(t.at, fmt::format("unknown Tachyon statement {}{}", quoteForMessage(t.text),
                                   nearestSupported(word)));
      throw SyntaxError{};
    }
  }

  // After an error: on to the next statement keyword.
  void skipToNextStatement() {
    while (const std::optional<Token> t = in_.tokens().peek()) {
      const std::string word = upper(t->text);
      if (std::find(kSupported.begin(), kSupported.end(), word) != kSupported.end() ||
          std::find(kUnsupported.begin(), kUnsupported.end(), word) != kUnsupported.end()) {
        return;
      }
      in_.tokens().next();
    }
  }

  // --- camera, shader mode, fog --------------------------------------------------------------

  void camera(const Token& t) {
    Camera c;
    c.at = t.at;
    Token next = in_.need(t, "PROJECTION or ZOOM");
    if (upper(next.text) == "PROJECTION") {
      const Token mode = in_.need(t, "a projection");
      const std::string m = upper(mode.text);
      if (m == "ORTHOGRAPHIC") {
        c.orthographic = true;
      } else if (m == "PERSPECTIVE_DOF") {
        // VMD writes FOCALDIST, Tachyon's manual FOCALLENGTH: both are the first value of
        // Tachyon's rt_camera_dof (the distance in focus), APERTURE its second (the f-number).
        c.depthOfField = mode.at;
        in_.expectEither(t, in_.need(t, "FOCALDIST"), "FOCALDIST", "FOCALLENGTH");
        c.focalDistance = in_.number(t, "focal distance");
        in_.keyword(t, "APERTURE");
        c.fNumber = in_.number(t, "aperture");
      } else if (m != "PERSPECTIVE") {
        out_.error(mode.at, fmt::format("camera projection {} is not supported (glint reads "
                                        "PERSPECTIVE, PERSPECTIVE_DOF and ORTHOGRAPHIC)",
                                        quoteForMessage(mode.text)));
        throw SyntaxError{};
      }
      next = in_.need(t, "ZOOM");
    }
    in_.expectWord(t, next, "ZOOM");
    c.zoom = in_.number(t, "zoom");
    in_.keyword(t, "ASPECTRATIO");
    c.aspect = in_.number(t, "aspect ratio");
    in_.keyword(t, "ANTIALIASING");
    c.antialiasing = in_.number(t, "antialiasing");
    in_.keyword(t, "RAYDEPTH");
    c.raydepth = in_.number(t, "ray depth");
    in_.keyword(t, "CENTER");
    c.center = in_.point(t, "camera center");
    in_.keyword(t, "VIEWDIR");
    c.viewdir = in_.point(t, "view direction");
    in_.keyword(t, "UPDIR");
    c.updir = in_.point(t, "up direction");
    const Token end = in_.need(t, "END_CAMERA");
    if (upper(end.text) == "FRUSTUM") {
      out_.error(end.at, "the camera's FRUSTUM is not supported by glint");
      throw SyntaxError{};
    }
    in_.expectWord(t, end, "END_CAMERA");
    bool valid = true;  // every error of the statement is reported
    for (const Number* n : {&c.zoom, &c.aspect}) {
      if (!(n->value > 0)) {
        out_.error(n->at, fmt::format("camera: {} must be > 0, got {}",
                                      n == &c.zoom ? "ZOOM" : "ASPECTRATIO", n->text));
        valid = false;
      }
    }
    if (!(c.antialiasing.value >= 0 && c.antialiasing.value == std::floor(c.antialiasing.value))) {
      out_.error(c.antialiasing.at, fmt::format("camera: ANTIALIASING must be a whole number >= 0, "
                                                "got {}",
                                                c.antialiasing.text));
      valid = false;
    }
    if (c.depthOfField) {
      bool lens = true;
      for (const Number* n : {&c.focalDistance, &c.fNumber}) {
        if (!(n->value > 0)) {
          out_.error(n->at, fmt::format("camera: {} must be > 0, got {}",
                                        n == &c.focalDistance ? "the focal distance" : "APERTURE",
                                        n->text));
          lens = false;
        }
      }
      if (lens && !std::isfinite(lensRadius(c))) {
        out_.error(c.focalDistance.at,
                   fmt::format("camera: the lens radius, focal distance / (2 · APERTURE) = {} / (2 "
                               "· {}), is too large for a number",
                               c.focalDistance.text, c.fNumber.text));
        lens = false;
      }
      valid = valid && lens;
    }
    if (!valid) return;
    camera_ = c;
  }

  void shaderMode(const Token& t) {
    const Token mode = in_.need(t, "FULL, MEDIUM, LOW or LOWEST");
    const std::string m = upper(mode.text);
    if (m != "FULL" && m != "MEDIUM" && m != "LOW" && m != "LOWEST") {
      out_.error(mode.at, fmt::format("SHADER_MODE: expected FULL, MEDIUM, LOW or LOWEST, got {}",
                                      quoteForMessage(mode.text)));
      throw SyntaxError{};
    }
    if (m != "FULL") {
      out_.warning(mode.at, fmt::format("SHADER_MODE {}: glint shades every scene fully (with "
                                        "shadows, reflections and transparency)",
                                        mode.text));
    }
    for (;;) {
      const Token option = in_.need(t, "END_SHADER_MODE");
      const std::string o = upper(option.text);
      if (o == "END_SHADER_MODE") return;
      if (o == "TRANS_VMD") {
        transVmd_ = true;
      } else if (o == "TRANS_ORIG") {
        transVmd_ = false;
      } else if (o == "FOG_VMD") {
        fogVmd_ = true;
      } else if (o == "SHADOW_FILTER_ON") {
      } else if (o == "AMBIENT_OCCLUSION") {
        ambientOcclusion(t, option);
      } else if (o == "SHADOW_FILTER_OFF" || o == "TRANS_MAX_SURFACES") {
        if (o == "TRANS_MAX_SURFACES") in_.number(t, "surfaces");
        out_.warning(option.at, fmt::format("SHADER_MODE {} is ignored: glint filters shadows "
                                            "through every transparent surface",
                                            option.text));
      } else {
        out_.error(option.at, fmt::format("SHADER_MODE option {} is not supported by glint",
                                          quoteForMessage(option.text)));
        throw SyntaxError{};
      }
    }
  }

  // SHADER_MODE's AMBIENT_OCCLUSION AMBIENT_COLOR r g b RESCALE_DIRECT s SAMPLES n (what VMD
  // writes with its ambient occlusion on). Tachyon adds to a surface's diffuse lighting
  // AMBIENT_COLOR times the cosine-weighted open fraction of the hemisphere (n rays, shadow-style),
  // and scales its lights by s: glint's render.ambient_occlusion on an ambient light of that colour
  // and ka = the texture's DIFFUSE·COLOR, the texture's own AMBIENT·COLOR (which Tachyon does not
  // occlude) becoming its emission, and the lights' colours × s. It changes the lights and the
  // materials, so it must come before them, as VMD writes it. SAMPLES 0 is Tachyon's "off".
  void ambientOcclusion(const Token& t, const Token& option) {
    if (lightsRead_ || textures_.emittedAny()) {
      out_.error(option.at,
                 "SHADER_MODE AMBIENT_OCCLUSION must come before the scene's lights and textures "
                 "(it rescales the lights and changes every texture's ambient term), as VMD "
                 "writes it");
      throw SyntaxError{};
    }
    AmbientOcclusion ao;
    ao.at = option.at;
    in_.keyword(t, "AMBIENT_COLOR");
    ao.color = in_.color(t, "ambient occlusion color");
    in_.keyword(t, "RESCALE_DIRECT");
    ao.rescale = in_.number(t, "direct light scale");
    if (!(ao.rescale.value >= 0) || !std::isfinite(ao.rescale.value)) {
      out_.error(ao.rescale.at,
                 fmt::format("RESCALE_DIRECT must be >= 0, got {}", ao.rescale.text));
      throw SyntaxError{};
    }
    in_.keyword(t, "SAMPLES");
    ao.samples = in_.number(t, "ambient occlusion samples");
    if (!(ao.samples.value >= 0 && ao.samples.value <= 65536) ||
        ao.samples.value != std::floor(ao.samples.value)) {
      out_.error(
          ao.samples.at,
          fmt::format("SAMPLES must be a whole number from 0 to 65536, got {}", ao.samples.text));
      throw SyntaxError{};
    }
    if (ao.samples.value == 0) return;
    ambientOcclusion_ = ao;
    textures_.setAmbientOcclusion(true);
  }

  // A light's COLOR, times RESCALE_DIRECT under ambient occlusion.
  void emitLightColor(const Triple& color) {
    if (!ambientOcclusion_ || ambientOcclusion_->rescale.value == 1) {
      in_.emit("color", color);
      return;
    }
    const double s = ambientOcclusion_->rescale.value;
    const double scaled[3] = {color.n[0].value * s, color.n[1].value * s, color.n[2].value * s};
    out_.computedTriple("color", scaled, color.n[0].at);
  }

  // BACKGROUND_GRADIENT SKY_SPHERE|SKY_ORTHO_PLANE UPDIR x y z TOPVAL t BOTTOMVAL b TOPCOLOR r g b
  // BOTTOMCOLOR r g b: glint's sky background. Tachyon blends by d·UPDIR (SKY_SPHERE, d the ray's
  // unit direction) or o·UPDIR (SKY_ORTHO_PLANE, o its origin) with UPDIR as written, not made
  // unit; glint's `up` is a unit vector, so the values are divided by UPDIR's length instead (the
  // same blend). It replaces BACKGROUND's colour wherever it is written.
  void backgroundGradient(const Token& t) {
    const Token kind = in_.need(t, "SKY_SPHERE or SKY_ORTHO_PLANE");
    const std::string k = in_.expectEither(t, kind, "SKY_SPHERE", "SKY_ORTHO_PLANE");
    Gradient g;
    g.at = t.at;
    g.kindAt = kind.at;
    g.byHeight = k == "SKY_ORTHO_PLANE";
    in_.keyword(t, "UPDIR");
    g.up = in_.point(t, "gradient up direction");
    in_.keyword(t, "TOPVAL");
    g.top = in_.number(t, "top value");
    in_.keyword(t, "BOTTOMVAL");
    g.bottom = in_.number(t, "bottom value");
    in_.keyword(t, "TOPCOLOR");
    g.topColor = in_.color(t, "top color");
    in_.keyword(t, "BOTTOMCOLOR");
    g.bottomColor = in_.color(t, "bottom color");
    gradient_ = g;
  }

  void fog(const Token& t) {
    const Token mode = in_.need(t, "LINEAR, EXP, EXP2 or OFF");
    const std::string m = upper(mode.text);
    if (m != "LINEAR" && m != "EXP" && m != "EXP2" && m != "OFF") {
      out_.error(mode.at, fmt::format("FOG: expected LINEAR, EXP, EXP2 or OFF, got {}",
                                      quoteForMessage(mode.text)));
      throw SyntaxError{};
    }
    Fog f;
    f.at = t.at;
    f.mode = m;
    f.modeAt = mode.at;
    in_.keyword(t, "START");
    f.start = in_.number(t, "start");
    in_.keyword(t, "END");
    f.end = in_.number(t, "end");
    in_.keyword(t, "DENSITY");
    f.density = in_.number(t, "density");
    in_.keyword(t, "COLOR");
    f.color = in_.color(t, "fog color");
    if (m == "OFF") {
      fog_.reset();
    } else {
      fog_ = f;
    }
  }

  // A texture name becomes a material name of the scene (and a YAML key when converted): at most
  // 256 bytes of UTF-8 text without control characters. VMD writes short ASCII names.
  void requireTextureName(const Token& statement, const Token& name) {
    constexpr std::size_t kLongestName = kMaxNameBytes;  // as a YAML scene's names
    const std::string_view text = name.text;
    bool ok = text.size() <= kLongestName;
    for (std::size_t i = 0; ok && i < text.size();) {
      const std::size_t width = utf8Width(text, i);
      const auto c = static_cast<unsigned char>(text[i]);
      // Not UTF-8, a C0 control or DEL, or a C1 control (U+0080..U+009F: 0xC2 0x80..0x9F).
      ok = width > 0 && c >= 0x20 && c != 0x7F &&
           !(c == 0xC2 && (static_cast<unsigned char>(text[i + 1]) & 0xE0) == 0x80);
      i += width;
    }
    if (ok) return;
    out_.error(name.at, fmt::format("{}: a texture name must be UTF-8 text of at most {} bytes "
                                    "without control characters, got {}",
                                    statement.text, kLongestName, quoteForMessage(text)));
    throw SyntaxError{};
  }

  // --- lights --------------------------------------------------------------------------------

  void light(const Token& t, bool spot) {
    in_.keyword(t, "CENTER");
    const Triple center = in_.point(t, "light center");
    in_.keyword(t, "RAD");
    const Number radius = in_.number(t, "light radius");
    if (!(radius.value >= 0)) {
      out_.error(radius.at, fmt::format("light RAD must be >= 0, got {}", radius.text));
      throw SyntaxError{};
    }
    std::optional<Triple> direction;
    Number start, end;
    if (spot) {
      in_.keyword(t, "DIRECTION");
      direction = in_.point(t, "spot direction");
      in_.keyword(t, "FALLOFF_START");
      start = in_.number(t, "falloff start, degrees");
      in_.keyword(t, "FALLOFF_END");
      end = in_.number(t, "falloff end, degrees");
    }
    std::optional<std::array<Number, 3>> attenuation;
    Token next = in_.need(t, "COLOR or ATTENUATION");
    if (upper(next.text) == "ATTENUATION") {
      std::array<Number, 3> k;
      in_.keyword(t, "CONSTANT");
      k[0] = in_.number(t, "constant attenuation");
      in_.keyword(t, "LINEAR");
      k[1] = in_.number(t, "linear attenuation");
      in_.keyword(t, "QUADRATIC");
      k[2] = in_.number(t, "quadratic attenuation");
      attenuation = k;
      next = in_.need(t, "COLOR");
    }
    in_.expectWord(t, next, "COLOR");
    const Triple color = in_.color(t, "light color");
    if (radius.value > 0) {
      out_.warning(radius.at,
                   "the light's sphere (RAD > 0) is not drawn: glint's lights are "
                   "invisible points");
    }
    const ValueId map = out_.nextId();
    out_.openMap(t.at);
    const ValueId type = out_.entry("type", spot ? "spot" : "point", t.at);
    in_.emit("position", center);
    if (spot) {
      in_.emit("direction", *direction);
      in_.emit("falloff_start", start);
      in_.emit("falloff_end", end);
    }
    if (attenuation) {
      out_.key("attenuation", (*attenuation)[0].at);
      out_.openList((*attenuation)[0].at);
      for (const Number& k : *attenuation) out_.scalar(k.text, k.at);
      out_.close();
    }
    emitLightColor(color);
    out_.close();
    out_.addEntity(EntityKind::LightEntity, map, type);
    lightsRead_ = true;
  }

  void directionalLight(const Token& t) {
    in_.keyword(t, "DIRECTION");
    const Triple direction = in_.point(t, "light direction");
    in_.keyword(t, "COLOR");
    const Triple color = in_.color(t, "light color");
    const ValueId map = out_.nextId();
    out_.openMap(t.at);
    const ValueId type = out_.entry("type", "directional", t.at);
    in_.emit("direction", direction);
    emitLightColor(color);
    out_.close();
    out_.addEntity(EntityKind::LightEntity, map, type);
    lightsRead_ = true;
  }

  // --- the scene-wide entities, once everything is read ---------------------------------------

  void emitSettings() {
    const TextPosition at = scene_.at;
    const Camera c = camera_.value_or(Camera{});
    ValueId map = out_.nextId();
    out_.openMap(camera_ ? c.at : at);
    if (camera_) {
      in_.emit("position", c.center);
      in_.emit("direction", c.viewdir);
      in_.emit("up", c.updir);
    } else {
      // Tachyon's default camera: at the origin looking along +z (−z mirrored), +y up.
      const double position[3] = {0, 0, 0};
      const double direction[3] = {0, 0, 1};
      out_.computedTriple("position", position, at);
      out_.computedTriple("direction", direction, at);
    }
    if (c.orthographic) out_.entry("projection", "orthographic", c.at);
    if (c.depthOfField && c.antialiasing.value == 0) {
      out_.warning(*c.depthOfField,
                   "PERSPECTIVE_DOF with ANTIALIASING 0: Tachyon traces each pixel's one sample "
                   "through the centre of the lens, so the image is sharp, and glint's is too "
                   "(depth of field needs ANTIALIASING 1 or more)");
    } else if (c.depthOfField) {
      // (Tachyon focuses at the distance along each ray, glint on the plane at that distance
      // along the view direction.)
      out_.entry("aperture", numberText(lensRadius(c)), c.fNumber.at);
      out_.entry("focus_distance", numberText(c.focalDistance.value), c.focalDistance.at);
    }
    const double zoom = camera_ ? c.zoom.value : 1;
    const double aspect = camera_ ? c.aspect.value : 1;
    const double w = resolution_[0].value, h = resolution_[1].value;
    const TextPosition planeAt = camera_ ? c.zoom.at : at;
    out_.key("view_plane", planeAt);
    out_.openMap(planeAt);
    out_.entry("width", numberText(h > 0 ? (w / h) / aspect / zoom : 1), planeAt);
    out_.entry("height", numberText(1 / zoom), planeAt);
    if (!c.orthographic) out_.entry("distance", "1", planeAt);
    out_.close();
    out_.close();
    out_.addEntity(EntityKind::CameraEntity, map);

    map = out_.nextId();
    out_.openMap(resolution_[0].at);
    in_.emit("width", resolution_[0]);
    in_.emit("height", resolution_[1]);
    out_.entry("samples", camera_ ? numberText(c.antialiasing.value + 1) : std::string("1"),
               camera_ ? c.antialiasing.at : at);
    out_.entry("encoding", "linear", at);
    out_.close();
    out_.addEntity(EntityKind::ImageEntity, map);

    map = out_.nextId();
    out_.openMap(camera_ ? c.raydepth.at : at);
    if (camera_) in_.emit("max_depth", c.raydepth);
    out_.entry("min_weight", "0", at);
    if (ambientOcclusion_) {
      out_.key("ambient_occlusion", ambientOcclusion_->at);
      out_.openMap(ambientOcclusion_->at);
      in_.emit("samples", ambientOcclusion_->samples);
      out_.close();
    }
    out_.close();
    out_.addEntity(EntityKind::RenderEntity, map);

    // A texture's AMBIENT is its own ambient term: glint's ka under white ambient light 1. Under
    // ambient occlusion the ambient light is AMBIENT_COLOR and ka the texture's diffuse colour.
    map = out_.nextId();
    out_.openMap(at);
    if (ambientOcclusion_) in_.emit("color", ambientOcclusion_->color);
    out_.entry("intensity", "1", at);
    out_.close();
    out_.addEntity(EntityKind::AmbientEntity, map);

    if (gradient_) {
      const Gradient& g = *gradient_;
      map = out_.nextId();
      out_.openMap(g.at);
      out_.entry("type", "sky", g.at);
      if (g.byHeight) out_.entry("along", "height", g.kindAt);
      in_.emit("up", g.up);
      const double length = ::glint::length(g.up.vector());
      const double scale = length > 0 ? 1 / length : 1;  // a zero UPDIR is the factory's error
      out_.entry("top_value", numberText(g.top.value * scale), g.top.at);
      out_.entry("bottom_value", numberText(g.bottom.value * scale), g.bottom.at);
      in_.emit("top", g.topColor);
      in_.emit("bottom", g.bottomColor);
      out_.close();
      out_.addEntity(EntityKind::BackgroundEntity, map);
    } else if (background_) {
      map = out_.nextId();
      out_.openList(backgroundAt_);
      for (const Number& n : background_->n) out_.scalar(n.text, n.at);
      out_.close();
      out_.addEntity(EntityKind::BackgroundEntity, map);
    }
    if (fog_) {
      const Fog& f = *fog_;
      map = out_.nextId();
      out_.openMap(f.at);
      std::string mode = f.mode;
      for (char& ch : mode) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      out_.entry("type", mode, f.modeAt);
      in_.emit("start", f.start);
      in_.emit(f.mode == "LINEAR" ? "end" : "density", f.mode == "LINEAR" ? f.end : f.density);
      in_.emit("color", f.color);
      if (fogVmd_) out_.entry("distance", "depth", f.at);
      out_.close();
      out_.addEntity(EntityKind::FogEntity, map);
    }
  }

  Input in_;
  SceneEmitter& out_;
  Textures textures_;
  const std::atomic<bool>* cancel_;
  Token scene_;
  std::array<Number, 2> resolution_;
  bool ended_ = false;
  bool transVmd_ = false;
  bool fogVmd_ = false;
  bool lightsRead_ = false;
  struct AmbientOcclusion {
    TextPosition at;
    Triple color;
    Number rescale, samples;
  };
  std::optional<AmbientOcclusion> ambientOcclusion_;
  std::optional<Camera> camera_;
  std::optional<Triple> background_;
  TextPosition backgroundAt_;
  struct Gradient {
    TextPosition at, kindAt;
    bool byHeight = false;
    Triple up;
    Number top, bottom;
    Triple topColor, bottomColor;
  };
  std::optional<Gradient> gradient_;
  struct Fog {
    TextPosition at, modeAt;
    std::string mode;
    Number start, end, density;
    Triple color;
  };
  std::optional<Fog> fog_;
  Geometry geometry_;
};

ParseResult parse(std::string_view text, SceneDescription scene, const std::atomic<bool>* cancel) {
  Diagnostics sink;
  {
    SceneEmitter out(scene, sink);
    TachyonReader(text, out, cancel).read();
  }
  ParseResult result;
  scene.complete = !sink.hasErrors();
  result.description = std::move(scene);
  result.diagnostics = sink.take();
  return result;
}

}  // namespace

ParseResult parseTachyon(std::string_view text, const std::string& file,
                         const std::filesystem::path& baseDirectory,
                         const std::atomic<bool>* cancel) {
  return parseSceneText(text, file, baseDirectory, cancel, parse);
}

ParseResult readTachyonFile(const std::filesystem::path& path, const std::string& name,
                            const std::atomic<bool>* cancel) {
  return readSceneTextFile(path, name, cancel, parse);
}

}  // namespace glint
