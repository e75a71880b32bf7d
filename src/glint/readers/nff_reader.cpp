#include "glint/readers/nff_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/core/bounds.h"
#include "glint/core/cancel.h"
#include "glint/core/vec.h"
#include "glint/readers/mesh_collector.h"
#include "glint/readers/text_statements.h"

namespace glint {
namespace {

const std::vector<std::string_view> kStatements = {"v", "b", "l", "f", "c", "s", "p", "pp"};

// Statements between polls of the cancel flag.
constexpr std::size_t kStatementsPerPoll = 4096;
// Vertices one polygon may have: far beyond any SPD polygon (the gears' 144). Ear clipping
// (triangulate) takes time growing with the square of a polygon's corners, and with their cube
// for a polygon made to (one that winds around hundreds of times: 4096 corners took 22 s) until its
// budget of point tests runs out (kEarTestsPerSquaredVertex).
constexpr double kMaxPolygonVertices = 4096;
// Point-in-triangle tests ear clipping may make per squared vertex count of a polygon before it
// fans the rest: simple polygons (convex, stars, spirals, crescents) need at most about two (each
// corner tested against the others, again when a neighbour is clipped); 4096 corners get ~0.3 s.
constexpr std::size_t kEarTestsPerSquaredVertex = 8;
constexpr std::size_t kEarTestsBase = 65536;
// A polygon vertex farther than this fraction of the polygon's size from its plane is warned
// about: generated files write ~6 digits, far below it; a real bend is far above.
constexpr double kPolygonPlaneTolerance = 1e-4;

struct Fill {
  std::string name;
  double transmission = 0;
  double ior = 1;
  std::array<Token, 8> tokens;
  std::string insideName;  // the material with 1/ior for inside-visible objects, once made
};

struct Light {
  Token statement;
  std::array<Token, 3> position;
  std::optional<std::array<Token, 3>> color;
};

// A statement's numbers could not be read; the reader skips to the next statement.
struct SyntaxError {};

class NffReader {
 public:
  NffReader(std::string_view text, SceneEmitter& out, const std::atomic<bool>* cancel)
      : text_(text), tokens_(text), out_(out), cancel_(cancel) {}

  void read() {
    std::size_t statements = 0;
    std::optional<Token> last;
    while (const std::optional<Token> t = tokens_.next()) {
      if (++statements % kStatementsPerPoll == 0) throwIfCancelled(cancel_);
      last = t;
      try {
        statement(*t);
      } catch (const SyntaxError&) {
        skipToNextStatement();
      }
    }
    // NFF has no end marker: a file cut inside its last number ("0.0555556" as "0.05") reads as
    // a whole file. The generators end every line with a line break.
    if (last && endsInsideAStatement()) {
      out_.warning(last->at,
                   "the file does not end with a line break: if it was cut short, the "
                   "last statement's numbers may be incomplete");
    }
    if (!viewRead_ && !sawView_) {
      out_.error({0, 1, 1},
                 "the file has no viewpoint: an NFF scene needs a 'v' block (from, at, up, angle, "
                 "hither, resolution)");
    }
    meshes_.emit(out_);
    emitLights();
  }

 private:
  void statement(const Token& t) {
    const std::string_view s = t.text;
    if (s == "v") {
      view(t);
    } else if (s == "b") {
      background(t);
    } else if (s == "l") {
      light(t);
    } else if (s == "f") {
      fill(t);
    } else if (s == "s") {
      sphere(t);
    } else if (s == "c") {
      cone(t);
    } else if (s == "p" || s == "pp") {
      polygon(t, s == "pp");
    } else if (!t.lineStart) {
      // Each statement takes a fixed count of numbers: a word left on its line is one too many.
      out_.error(t.at, fmt::format("unexpected {} after the statement's values on this line (one "
                                   "value too many?)",
                                   quoteForMessage(s)));
      throw SyntaxError{};
    } else {
      const std::string nearest = nearestName(s, kStatements);
      out_.error(t.at,
                 fmt::format("unknown NFF statement {}{}; the statements are v, b, l, f, c, "
                             "s, p, pp and # comments",
                             quoteForMessage(s),
                             nearest.empty() ? "" : fmt::format(" (did you mean '{}'?)", nearest)));
      throw SyntaxError{};
    }
  }

  // After an error: on to the next line that starts with a statement.
  void skipToNextStatement() {
    while (const std::optional<Token> t = tokens_.peek()) {
      if (t->lineStart &&
          std::find(kStatements.begin(), kStatements.end(), t->text) != kStatements.end()) {
        return;
      }
      tokens_.next();
    }
  }

  // The next token, which must exist: `what` says what was expected.
  Token expectToken(const Token& statement, std::string_view what) {
    std::optional<Token> t = tokens_.next();
    if (!t) {
      out_.error(tokens_.end(), fmt::format("the file ends inside '{}' (line {}): expected {}",
                                            statement.text, statement.at.line, what));
      throw SyntaxError{};
    }
    return *t;
  }

  // The next token as a number named `what` in messages.
  double number(const Token& statement, std::string_view what, Token& token) {
    token = expectToken(statement, fmt::format("a number ({})", what));
    const std::optional<double> v = parseNumber(token.text);
    if (!v) {
      out_.error(token.at, fmt::format("{}: expected a number ({}), got {}", statement.text, what,
                                       quoteForMessage(token.text)));
      throw SyntaxError{};
    }
    return *v;
  }

  void numbers(const Token& statement, std::initializer_list<std::string_view> names, Token* tokens,
               double* values) {
    std::size_t i = 0;
    for (const std::string_view name : names) {
      values[i] = number(statement, name, tokens[i]);
      ++i;
    }
  }

  void keyword(const Token& statement, std::string_view word) {
    const Token t = expectToken(statement, fmt::format("'{}'", word));
    if (t.text != word) {
      out_.error(t.at, fmt::format("{}: expected '{}', got {} (a viewpoint is v, from, at, up, "
                                   "angle, hither, resolution, in this order)",
                                   statement.text, word, quoteForMessage(t.text)));
      throw SyntaxError{};
    }
  }

  // --- v: the viewpoint --------------------------------------------------------------------

  void view(const Token& v) {
    sawView_ = true;
    if (viewRead_) {
      out_.error(v.at, "a second viewpoint ('v'); an NFF file has one");
      throw SyntaxError{};
    }
    std::array<Token, 3> from, at, up;
    double unused[3];
    keyword(v, "from");
    numbers(v, {"from x", "from y", "from z"}, from.data(), unused);
    keyword(v, "at");
    numbers(v, {"at x", "at y", "at z"}, at.data(), unused);
    keyword(v, "up");
    numbers(v, {"up x", "up y", "up z"}, up.data(), unused);
    keyword(v, "angle");
    Token angle;
    const double degrees = number(v, "angle, degrees", angle);
    keyword(v, "hither");
    Token hither;
    number(v, "hither", hither);
    keyword(v, "resolution");
    std::array<Token, 2> resolution;
    double size[2];
    numbers(v, {"x resolution", "y resolution"}, resolution.data(), size);
    viewRead_ = true;
    if (!(degrees > 0 && degrees < 180)) {
      out_.error(angle.at, fmt::format("v: angle must be in (0, 180) degrees, got {}",
                                       shortenForMessage(angle.text)));
      return;
    }
    // NFF.TXT: the angle spans the centres of the top and bottom pixel rows, so the pixel pitch
    // at distance 1 is 2·tan(angle/2)/(rows − 1); square pixels.
    const double rows = std::max(std::round(size[1]), 1.0);
    const double columns = std::max(std::round(size[0]), 1.0);
    const double span = 2 * std::tan(degrees * std::numbers::pi / 360);
    const double pitch = rows > 1 ? span / (rows - 1) : span;

    ValueId map = out_.nextId();
    out_.openMap(v.at);
    out_.triple("position", from.data());
    out_.triple("look_at", at.data());
    out_.triple("up", up.data());
    out_.key("view_plane", angle.at);
    out_.openMap(angle.at);
    out_.entry("width", numberText(pitch * columns), angle.at);
    out_.entry("height", numberText(pitch * rows), angle.at);
    out_.entry("distance", "1", angle.at);
    out_.close();
    out_.close();
    out_.addEntity(EntityKind::CameraEntity, map);

    map = out_.nextId();
    out_.openMap(resolution[0].at);
    out_.entry("width", resolution[0]);
    out_.entry("height", resolution[1]);
    out_.entry("encoding", "linear", v.at);
    out_.close();
    out_.addEntity(EntityKind::ImageEntity, map);

    map = out_.nextId();
    out_.openMap(v.at);
    out_.entry("max_depth", "5", v.at);
    out_.entry("min_weight", "0", v.at);
    out_.close();
    out_.addEntity(EntityKind::RenderEntity, map);
  }

  // --- b, l, f -------------------------------------------------------------------------------

  void background(const Token& b) {
    std::array<Token, 3> rgb;
    double unused[3];
    numbers(b, {"red", "green", "blue"}, rgb.data(), unused);
    const ValueId list = out_.nextId();
    out_.openList(rgb[0].at);
    for (const Token& t : rgb) out_.scalar(t);
    out_.close();
    out_.addEntity(EntityKind::BackgroundEntity, list);
  }

  void light(const Token& l) {
    Light light{l, {}, std::nullopt};
    double unused[3];
    numbers(l, {"x", "y", "z"}, light.position.data(), unused);
    // The colour is optional: three more numbers.
    if (const std::optional<Token> next = tokens_.peek(); next && parseNumber(next->text)) {
      std::array<Token, 3> rgb;
      numbers(l, {"red", "green", "blue"}, rgb.data(), unused);
      light.color = rgb;
    }
    lights_.push_back(std::move(light));
  }

  void emitLights() {
    if (lights_.empty()) return;
    const std::string intensity = numberText(1 / std::sqrt(static_cast<double>(lights_.size())));
    for (const Light& l : lights_) {
      const ValueId map = out_.nextId();
      out_.openMap(l.statement.at);
      const ValueId type = out_.entry("type", "point", l.statement.at);
      out_.triple("position", l.position.data());
      if (l.color) out_.triple("color", l.color->data());
      out_.entry("intensity", intensity, l.statement.at);
      out_.close();
      out_.addEntity(EntityKind::LightEntity, map, type);
    }
  }

  void fill(const Token& f) {
    Fill fill;
    double v[8];
    numbers(f, {"red", "green", "blue", "Kd", "Ks", "Shine", "T", "index of refraction"},
            fill.tokens.data(), v);
    fill.name = fmt::format("fill{}", fills_.size() + 1);
    fill.transmission = v[6];
    fill.ior = v[7];
    emitFill(fill, fill.name, false);
    fills_.push_back(std::move(fill));
  }

  // kd = Kd·colour (at Kd), ks = kr = Ks, shininess = Shine, kt = T, and ior when T > 0 (inverted
  // for the inside-visible variant).
  void emitFill(const Fill& fill, const std::string& name, bool inside) {
    const std::array<Token, 8>& t = fill.tokens;
    const ValueId nameValue = out_.scalar(name, t[3].at);
    const ValueId map = out_.nextId();
    out_.openMap(t[0].at);
    const double kd = *parseNumber(t[3].text);
    const double rgb[3] = {kd * *parseNumber(t[0].text), kd * *parseNumber(t[1].text),
                           kd * *parseNumber(t[2].text)};
    out_.computedTriple("kd", rgb, t[3].at);
    out_.entry("ks", t[4]);
    out_.entry("shininess", t[5]);
    out_.entry("kr", t[4]);
    out_.entry("kt", t[6]);
    if (fill.transmission > 0) {
      if (inside && fill.ior != 0) {
        out_.entry("ior", numberText(1 / fill.ior), t[7].at);
      } else {
        out_.entry("ior", t[7]);
      }
    }
    out_.close();
    out_.addEntity(EntityKind::MaterialEntity, map, kNoValue, nameValue);
  }

  // The material objects take now: the last fill, or its inside-visible variant.
  std::string material(bool inside) {
    if (fills_.empty()) return {};
    Fill& fill = fills_.back();
    if (!inside || fill.transmission <= 0 || fill.ior == 1) return fill.name;
    if (fill.insideName.empty()) {
      fill.insideName = fill.name + "_inside";
      emitFill(fill, fill.insideName, true);
    }
    return fill.insideName;
  }

  // --- s, c ----------------------------------------------------------------------------------

  // A radius token without its minus sign (an exact negation).
  static Token unsigned_(Token t) {
    if (!t.text.empty() && t.text[0] == '-') t.text.remove_prefix(1);
    return t;
  }

  void sphere(const Token& s) {
    std::array<Token, 4> t;
    double v[4];
    numbers(s, {"center x", "center y", "center z", "radius"}, t.data(), v);
    const bool inside = v[3] < 0;
    const std::string m = material(inside);  // may emit a material: before the sphere's mapping
    const ValueId map = out_.nextId();
    out_.openMap(s.at);
    const ValueId type = out_.entry("type", "sphere", s.at);
    out_.triple("center", t.data());
    out_.entry("radius", inside ? unsigned_(t[3]) : t[3]);
    if (!m.empty()) out_.entry("material", m, s.at);
    out_.close();
    out_.addEntity(EntityKind::ObjectEntity, map, type);
  }

  void cone(const Token& c) {
    std::array<Token, 8> t;
    double v[8];
    numbers(
        c,
        {"base x", "base y", "base z", "base radius", "apex x", "apex y", "apex z", "apex radius"},
        t.data(), v);
    const bool inside = (v[3] < 0 || v[7] < 0) && v[3] <= 0 && v[7] <= 0;
    if (!inside && (v[3] < 0 || v[7] < 0)) {
      out_.error(t[v[3] < 0 ? 3 : 7].at,
                 "c: a negative radius needs the other one negative too (both negative: only the "
                 "inside is visible)");
      return;
    }
    const std::string m = material(inside);
    const ValueId map = out_.nextId();
    out_.openMap(c.at);
    const ValueId type = out_.entry("type", "cone", c.at);
    out_.triple("base", &t[0]);
    out_.entry("base_radius", inside ? unsigned_(t[3]) : t[3]);
    out_.triple("apex", &t[4]);
    out_.entry("apex_radius", inside ? unsigned_(t[7]) : t[7]);
    if (!m.empty()) out_.entry("material", m, c.at);
    out_.close();
    out_.addEntity(EntityKind::ObjectEntity, map, type);
  }

  // --- p, pp ---------------------------------------------------------------------------------

  void polygon(const Token& p, bool patch) {
    Token countToken;
    const double count = number(p, "number of vertices", countToken);
    if (!(count >= 3 && count == std::floor(count) && count <= kMaxPolygonVertices)) {
      out_.error(countToken.at,
                 fmt::format("{}: the number of vertices must be a whole number from 3 to {}, "
                             "got {}",
                             p.text, kMaxPolygonVertices, shortenForMessage(countToken.text)));
      throw SyntaxError{};
    }
    const auto n = static_cast<std::size_t>(count);
    std::vector<CollectedVertex> vertices(n);
    std::vector<Point3> points(n);
    ValueTree& tree = out_.tree();
    for (std::size_t i = 0; i < n; ++i) {
      Token t[6];
      double v[6];
      if (patch) {
        numbers(p, {"vertex x", "vertex y", "vertex z", "normal x", "normal y", "normal z"}, t, v);
      } else {
        numbers(p, {"vertex x", "vertex y", "vertex z"}, t, v);
      }
      for (int k = 0; k < 3; ++k) {
        vertices[i].position[k] = tree.addScalar(t[k].text, t[k].at);
        if (patch) vertices[i].normal[k] = tree.addScalar(t[k + 3].text, t[k + 3].at);
      }
      points[i] = Point3{v[0], v[1], v[2]};
      // Checked here, not only when the mesh is built: past it the polygon's normal overflows and
      // the polygon would be left out as having no area.
      if (!(std::abs(v[0]) <= kMaxCoordinate && std::abs(v[1]) <= kMaxCoordinate &&
            std::abs(v[2]) <= kMaxCoordinate)) {
        out_.error(t[0].at, fmt::format("{}: a vertex must lie within ±{:g} of the origin, got "
                                        "[{}, {}, {}] (glint's coordinates stay below it)",
                                        p.text, kMaxCoordinate, t[0].text, t[1].text, t[2].text));
        throw SyntaxError{};
      }
    }
    const std::string m = material(false);
    bool fanned = false;
    bool outOfBudget = false;
    const std::vector<std::array<std::size_t, 3>> triangles =
        triangulate(points, cancel_, fanned, outOfBudget);
    if (triangles.empty()) {
      out_.warning(p.at, fmt::format("{}: the polygon{}; it is left out", p.text,
                                     collinear(points) ? "'s vertices are collinear (no area)"
                                                       : " crosses itself so that its parts "
                                                         "enclose opposite areas that cancel"));
      return;
    }
    if (outOfBudget) {
      out_.warning(p.at, fmt::format("{}: cutting the polygon into triangles took more than {} "
                                     "tests of its corners; the rest of it is a fan of triangles, "
                                     "which may cover other parts than meant",
                                     p.text,
                                     kEarTestsPerSquaredVertex * points.size() * points.size() +
                                         kEarTestsBase));
    }
    if (const long turns = windings(points); turns > 1) {
      out_.warning(p.at, fmt::format("{}: the polygon winds around {} times (it crosses itself, "
                                     "as a star drawn in one stroke); its triangles may cover "
                                     "other parts than meant",
                                     p.text, turns));
    } else if (fanned) {
      out_.warning(p.at, fmt::format("{}: the polygon crosses itself or repeats a vertex, so ear "
                                     "clipping cannot cut it; the rest of it is a fan of "
                                     "triangles, which may cover other parts than meant",
                                     p.text));
    }
    if (const double off = offPlane(points); off > kPolygonPlaneTolerance) {
      out_.warning(p.at, fmt::format("{}: the polygon is not planar (a vertex lies {:.3g} of its "
                                     "size off its plane); its triangles follow the vertices",
                                     p.text, off));
    }
    for (const auto& tri : triangles) {
      meshes_.add(tree, m, vertices[tri[0]], vertices[tri[1]], vertices[tri[2]], p.at);
    }
  }

  // Newell's vector of the vertex loop: its direction the polygon's normal, its length twice the
  // (signed, projected) area.
  static Vec3 newellNormal(const std::vector<Point3>& p) {
    Vec3 normal;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Point3& a = p[i];
      const Point3& b = p[(i + 1) % p.size()];
      normal +=
          Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    }
    return normal;
  }

  // The coordinate axis to drop to project onto the plane `normal` is most perpendicular to.
  static int droppedAxis(const Vec3& normal) {
    const Vec3 an = abs(normal);
    return an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
  }

  // How many times the boundary winds around, from its turning angles in the coordinate plane its
  // Newell normal is most perpendicular to (1 for a simple polygon, 2 for a pentagram).
  static long windings(const std::vector<Point3>& p) {
    const std::size_t n = p.size();
    const int drop = droppedAxis(newellNormal(p));
    double total = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Point3& a = p[(i + n - 1) % n];
      const Point3& b = p[i];
      const Point3& c = p[(i + 1) % n];
      const double eu = b[(drop + 1) % 3] - a[(drop + 1) % 3];
      const double ew = b[(drop + 2) % 3] - a[(drop + 2) % 3];
      const double fu = c[(drop + 1) % 3] - b[(drop + 1) % 3];
      const double fw = c[(drop + 2) % 3] - b[(drop + 2) % 3];
      total += std::atan2(eu * fw - ew * fu, eu * fu + ew * fw);
    }
    return std::lround(std::abs(total) / (2 * std::numbers::pi));
  }

  // Whether all points lie on one line (through the first and the one farthest from it).
  static bool collinear(const std::vector<Point3>& p) {
    std::size_t far = 0;
    for (std::size_t i = 1; i < p.size(); ++i) {
      if (distance(p[0], p[i]) > distance(p[0], p[far])) far = i;
    }
    const Vec3 axis = p[far] - p[0];
    const double size = length(axis);
    for (const Point3& q : p) {
      if (length(cross(axis, q - p[0])) > 1e-12 * size * size) return false;
    }
    return true;
  }

  // The largest distance of a vertex from the polygon's plane (through its centroid, normal
  // Newell's), relative to the polygon's size (its bounding box diagonal); 0 without a normal.
  static double offPlane(const std::vector<Point3>& p) {
    const Vec3 normal = newellNormal(p);
    Vec3 centroid;
    Bounds3 box;
    for (const Point3& a : p) {
      centroid += toVec(a);
      box = unite(box, a);
    }
    const double size = length(box.diagonal());
    if (!(length(normal) > 0) || !(size > 0)) return 0;
    const Vec3 n = normalize(normal);
    centroid = centroid / static_cast<double>(p.size());
    double off = 0;
    for (const Point3& q : p) off = std::max(off, std::abs(dot(toVec(q) - centroid, n)));
    return off / size;
  }

  // Ear clipping (Meisters 1975) of a planar polygon, projected onto the coordinate plane its
  // normal (Newell's) is most perpendicular to. Triangles keep the polygon's vertex order. A
  // polygon that clipping cannot finish (self-intersecting, repeated vertices) gets a fan for the
  // rest, as does one whose clipping runs out of its budget of tests (kEarTestsPerSquaredVertex).
  // `fanned`: set when the fan was needed; `outOfBudget` too when the budget ran out.
  static std::vector<std::array<std::size_t, 3>> triangulate(const std::vector<Point3>& p,
                                                             const std::atomic<bool>* cancel,
                                                             bool& fanned, bool& outOfBudget) {
    const std::size_t n = p.size();
    const Vec3 normal = newellNormal(p);
    std::vector<std::array<std::size_t, 3>> out;
    if (!(length(normal) > 0)) return out;
    if (n == 3) return {{0, 1, 2}};
    const int drop = droppedAxis(normal);
    const double sign = normal[drop] > 0 ? 1 : -1;
    const auto u = [&](std::size_t i) { return p[i][(drop + 1) % 3]; };
    const auto w = [&](std::size_t i) { return p[i][(drop + 2) % 3]; };
    const auto turn = [&](std::size_t a, std::size_t b, std::size_t c) {
      return sign * ((u(b) - u(a)) * (w(c) - w(a)) - (w(b) - w(a)) * (u(c) - u(a)));
    };
    // Each round clips the first ear in ring order. A corner's ear test (convex, and no other
    // vertex in its triangle) is kept between rounds: clipping b changes the triangles of b's two
    // neighbours only, and can only empty a triangle b lay in — so a corner that was no ear
    // because vertex q lay in its triangle stays none while q remains (`blocker`). Without this
    // every round tested every corner against every vertex: a 4096-vertex spiral took 7.9 s.
    constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::vector<std::size_t> ring(n);
    for (std::size_t i = 0; i < n; ++i) ring[i] = i;
    std::vector<char> ear(n, 0);
    std::vector<std::size_t> blocker(n, kNone);  // per vertex: what lies in its corner's triangle
    std::size_t tests = 0;                       // point-in-triangle tests so far
    const std::size_t budget = kEarTestsPerSquaredVertex * n * n + kEarTestsBase;
    const auto test = [&](std::size_t i) {
      const std::size_t m = ring.size();
      const std::size_t a = ring[(i + m - 1) % m];
      const std::size_t b = ring[i];
      const std::size_t c = ring[(i + 1) % m];
      blocker[b] = kNone;
      ear[b] = 0;
      if (!(turn(a, b, c) > 0)) return;  // a reflex or straight corner is no ear
      for (const std::size_t q : ring) {
        if (q == a || q == b || q == c) continue;
        ++tests;
        if (turn(a, b, q) >= 0 && turn(b, c, q) >= 0 && turn(c, a, q) >= 0) {
          blocker[b] = q;
          return;
        }
      }
      ear[b] = 1;
    };
    for (std::size_t i = 0; i < n; ++i) test(i);
    while (ring.size() > 3) {
      throwIfCancelled(cancel);  // a large polygon takes a while: Ctrl-C must not wait for it
      const std::size_t m = ring.size();
      std::size_t i = 0;
      while (i < m && !ear[ring[i]]) ++i;
      if (i == m || tests > budget) {
        fanned = true;
        outOfBudget = i < m;
        for (std::size_t k = 1; k + 1 < ring.size(); ++k) {
          out.push_back({ring[0], ring[k], ring[k + 1]});
        }
        return out;
      }
      const std::size_t clipped = ring[i];
      out.push_back({ring[(i + m - 1) % m], clipped, ring[(i + 1) % m]});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
      const std::size_t left = ring.size();
      // The two neighbours' corners changed; corners the clipped vertex blocked may be ears now.
      const std::size_t before = (i + left - 1) % left;
      const std::size_t after = i % left;
      test(before);
      test(after);
      for (std::size_t k = 0; k < left; ++k) {
        if (k != before && k != after && blocker[ring[k]] == clipped) test(k);
      }
    }
    out.push_back({ring[0], ring[1], ring[2]});
    return out;
  }

  // Whether the text's last line has no line break after it and ends in a value (not in blanks
  // or a comment).
  bool endsInsideAStatement() const {
    if (text_.empty() || text_.back() == '\n' || text_.back() == '\r') return false;
    const std::size_t lineStart = text_.find_last_of("\r\n") + 1;  // npos + 1 = 0
    const std::string_view line = text_.substr(lineStart);
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos || line[first] == '#') return false;
    const char lastChar = line.back();
    return lastChar != ' ' && lastChar != '\t';
  }

  std::string_view text_;
  Tokenizer tokens_;
  SceneEmitter& out_;
  const std::atomic<bool>* cancel_;
  bool viewRead_ = false;
  bool sawView_ = false;
  std::vector<Fill> fills_;
  std::vector<Light> lights_;
  MeshCollector meshes_;
};

ParseResult finish(SceneDescription scene, Diagnostics& sink) {
  ParseResult result;
  scene.complete = !sink.hasErrors();
  result.description = std::move(scene);
  result.diagnostics = sink.take();
  return result;
}

ParseResult parse(std::string_view text, SceneDescription scene, const std::atomic<bool>* cancel) {
  Diagnostics sink;
  SceneEmitter out(scene, sink);
  NffReader(text, out, cancel).read();
  return finish(std::move(scene), sink);
}

}  // namespace

ParseResult parseNff(std::string_view text, const std::string& file,
                     const std::filesystem::path& baseDirectory, const std::atomic<bool>* cancel) {
  return parseSceneText(text, file, baseDirectory, cancel, parse);
}

ParseResult readNffFile(const std::filesystem::path& path, const std::string& name,
                        const std::atomic<bool>* cancel) {
  return readSceneTextFile(path, name, cancel, parse);
}

}  // namespace glint
