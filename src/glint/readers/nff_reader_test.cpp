// The NFF reader (nff_reader.h): every statement as the entities the YAML reader would emit, values
// at their tokens' places, and its errors at file:line:col.
#include "glint/readers/nff_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "glint/factories/scene_loader.h"

namespace glint {
namespace {

using ::testing::HasSubstr;

// Every NFF statement: the viewpoint, background, lights with and without colour, fills (one
// transparent), spheres (one inside-visible), a cone, polygons (one concave) and patches, comments.
constexpr const char* kEveryStatement = R"(# an SPD-like file
b 0.1 0.2 0.3
v
from 0 -10 2
at 0 0 0
up 0 0 1
angle 40
hither 1
resolution 40 30
l 5 -5 5
l -5 -5 5 1 0.5 0.5   # a coloured light
f 1 0.5 0.25 0.8 0.2 30 0 1
s 0 0 0 1
c 2 0 -1 0.5 2 0 1 0.25
p 6
-3 -3 -1  3 -3 -1  3 3 -1  0 3 -1  0 0 -1  -3 0 -1
f 1 1 1 0.1 0.5 100 0.8 1.5
s -2 0 0 -0.5
pp 3
0 0 2 0 0 1
1 0 2 0 0.1 1
0 1 2 0.1 0 1
)";

std::size_t count(const ParseResult& r, EntityKind kind) { return r.description.count(kind); }

std::string text(const ParseResult& r, const Entity& e, std::string_view key) {
  return std::string(r.description.text(e, r.description.parameter(e, key)));
}

const Entity& nth(const ParseResult& r, EntityKind kind, std::size_t n) {
  for (const Entity& e : r.description.entities) {
    if (e.kind == kind && n-- == 0) return e;
  }
  throw std::logic_error("no such entity");
}

std::string firstError(const ParseResult& r) {
  for (const Diagnostic& d : r.diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) return d.format();
  }
  return "<no error>";
}

TEST(NffReader, EveryStatementBecomesTheEntitiesOfAYamlScene) {
  const ParseResult r = parseNff(kEveryStatement, "every.nff");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  EXPECT_EQ(count(r, EntityKind::CameraEntity), 1u);
  EXPECT_EQ(count(r, EntityKind::ImageEntity), 1u);
  EXPECT_EQ(count(r, EntityKind::RenderEntity), 1u);
  EXPECT_EQ(count(r, EntityKind::BackgroundEntity), 1u);
  EXPECT_EQ(count(r, EntityKind::AmbientEntity), 0u);
  EXPECT_EQ(count(r, EntityKind::LightEntity), 2u);
  // fill1, fill2 and fill2's inside-visible variant (1/ior) for the negative sphere.
  ASSERT_EQ(count(r, EntityKind::MaterialEntity), 3u);
  // Two spheres, a cone, a mesh of polygons and a mesh of patches.
  EXPECT_EQ(count(r, EntityKind::ObjectEntity), 5u);

  const Entity& light = nth(r, EntityKind::LightEntity, 1);
  EXPECT_EQ(text(r, light, "intensity"), "0.7071067811865475");  // 1/√2
  const SourceLocation at = r.description.location(light, r.description.parameter(light, "color"));
  EXPECT_EQ(at.line, 11);
  EXPECT_EQ(at.column, 11);

  const Entity& fill = nth(r, EntityKind::MaterialEntity, 0);
  const ValueTree& t = r.description.files[0]->values;
  const ValueId kd = r.description.parameter(fill, "kd");
  EXPECT_EQ(t.scalar(t.item(kd, 1)), "0.4");                  // Kd · green = 0.8 · 0.5
  EXPECT_EQ(text(r, fill, "kr"), "0.2");                      // kr = Ks
  EXPECT_EQ(r.description.parameter(fill, "ior"), kNoValue);  // opaque: no ior

  const Entity& inside = nth(r, EntityKind::MaterialEntity, 2);
  EXPECT_EQ(r.description.text(inside, inside.name), "fill2_inside");
  EXPECT_EQ(text(r, inside, "ior"), "0.6666666666666666");
  const Entity& negative = nth(r, EntityKind::ObjectEntity, 2);
  EXPECT_EQ(text(r, negative, "radius"), "0.5");
  EXPECT_EQ(text(r, negative, "material"), "fill2_inside");

  // The camera: look_at, and a view plane on which the centres of the top and bottom rows are
  // 40° apart: height = 2·tan(20°)·30/29.
  const Entity& camera = nth(r, EntityKind::CameraEntity, 0);
  const ValueId plane = r.description.parameter(camera, "view_plane");
  double height = 0;
  for (std::size_t i = 0; i < t.size(plane); ++i) {
    if (t.scalar(t.key(plane, i)) == "height")
      height = std::stod(std::string(t.scalar(t.value(plane, i))));
  }
  EXPECT_NEAR(height, 2 * std::tan(20 * M_PI / 180) * 30 / 29, 1e-15);

  // The concave L-shaped hexagon (area 27) becomes 4 triangles.
  const Entity& polygons = nth(r, EntityKind::ObjectEntity, 3);
  EXPECT_EQ(text(r, polygons, "type"), "mesh");
  EXPECT_EQ(text(r, polygons, "smooth"), "false");
  EXPECT_EQ(t.size(r.description.parameter(polygons, "indices")), 4u);
  const Entity& patches = nth(r, EntityKind::ObjectEntity, 4);
  EXPECT_NE(r.description.parameter(patches, "normals"), kNoValue);

  // And it builds.
  const LoadedScene loaded = buildDescribedScene(r);
  EXPECT_EQ(loaded.parts.primitives.size(), 3u);
  ASSERT_EQ(loaded.parts.meshes.size(), 2u);
  double area = 0;
  const TriangleMesh& m = loaded.parts.meshes[0];
  for (std::size_t i = 0; i < m.indices.size(); i += 3) {
    area += length(cross(m.positions[m.indices[i + 1]] - m.positions[m.indices[i]],
                         m.positions[m.indices[i + 2]] - m.positions[m.indices[i]])) /
            2;
  }
  EXPECT_NEAR(area, 27, 1e-9);
}

std::vector<std::string> warningsOf(const ParseResult& r) {
  std::vector<std::string> out;
  for (const Diagnostic& d : r.diagnostics) {
    if (d.severity == Diagnostic::Severity::Warning) out.push_back(d.format());
  }
  return out;
}

// Polygons ear clipping cannot cut as meant are said, not drawn wrong in silence; a polygon past
// the corner limit is refused before its (quadratic) triangulation.
TEST(NffReader, PolygonsThatCrossThemselvesOrBendAreWarnedAbout) {
  const std::string view =
      "v from 0 3 0 at 0 0 0 up 0 0 1 angle 60 hither 0.01 resolution 8 8\n"
      "l 1 3 1\nf 1 0 0 0.5 0.5 3 0 1\n";
  std::string star = "p 5\n";
  for (int k = 0; k < 5; ++k) {
    const double phi = (90 + 144 * k) * std::numbers::pi / 180;
    star += fmt::format("{} 0 {}\n", std::cos(phi), std::sin(phi));
  }
  EXPECT_EQ(warningsOf(parseNff(view + star, "a.nff")),
            std::vector<std::string>{"a.nff:4:1: warning: p: the polygon winds around 2 times (it "
                                     "crosses itself, as a star drawn in one stroke); its "
                                     "triangles may cover other parts than meant"});
  EXPECT_EQ(warningsOf(parseNff(view + "p 4\n-1 0 -1\n1 0 1\n1 0 -1\n-1 0 1\n", "a.nff")),
            std::vector<std::string>{"a.nff:4:1: warning: p: the polygon crosses itself so that "
                                     "its parts enclose opposite areas that cancel; it is left "
                                     "out"});
  EXPECT_EQ(warningsOf(parseNff(view + "p 3\n0 0 0\n1 0 0\n2 0 0\n", "a.nff")),
            std::vector<std::string>{"a.nff:4:1: warning: p: the polygon's vertices are collinear "
                                     "(no area); it is left out"});
  EXPECT_EQ(warningsOf(parseNff(view + "p 4\n0 0 0\n1 0 0\n1 1 1\n0 0 1\n", "a.nff")),
            std::vector<std::string>{"a.nff:4:1: warning: p: the polygon is not planar (a vertex "
                                     "lies 0.118 of its size off its plane); its triangles follow "
                                     "the vertices"});
  // A concave polygon (an L) is cut without a word.
  EXPECT_TRUE(
      warningsOf(parseNff(view + "p 6\n0 0 0\n2 0 0\n2 0 1\n1 0 1\n1 0 2\n0 0 2\n", "a.nff"))
          .empty());
  std::string big = "p 4097\n";
  for (int i = 0; i < 4097; ++i) big += "0 0 0\n";
  EXPECT_EQ(firstError(parseNff(view + big, "a.nff")),
            "a.nff:4:3: p: the number of vertices must be a whole number from 3 to 4096, got 4097");
  // A file cut inside its last number reads as a whole one; without its final line break it is
  // suspect, and a warning says so.
  EXPECT_EQ(warningsOf(parseNff(view + "s 0 0 0 0.05", "a.nff")),
            std::vector<std::string>{"a.nff:4:1: warning: the file does not end with a line "
                                     "break: if it was cut short, the last statement's numbers "
                                     "may be incomplete"});
  EXPECT_TRUE(warningsOf(parseNff(view + "s 0 0 0 0.05\r\n", "a.nff")).empty());
  EXPECT_TRUE(warningsOf(parseNff(view + "s 0 0 0 0.05\n# the end", "a.nff")).empty());
  EXPECT_TRUE(warningsOf(parseNff(view + "s 0 0 0 0.05   ", "a.nff")).empty());
  // A number below the smallest double is 0 (as in YAML scenes), one above the largest an error.
  {
    const ParseResult tiny = parseNff(view + "s 0 0 0 1\ns 0 1e-400 0 1\n", "a.nff");
    EXPECT_FALSE(tiny.hasErrors()) << firstError(tiny);
    EXPECT_EQ(firstError(parseNff(view + "s 0 1e400 0 1\n", "a.nff")),
              "a.nff:4:5: s: expected a number (center y), got '1e400'");
  }
  // A vertex past glint's coordinates is an error there, not a polygon left out as collinear (its
  // normal overflowed).
  EXPECT_EQ(firstError(parseNff(view + "p 3\n1e308 0 0\n-1e308 0 0\n0 0 1e308\n", "a.nff")),
            "a.nff:5:1: p: a vertex must lie within ±1e+100 of the origin, got [1e308, 0, 0] "
            "(glint's coordinates stay below it)");
}

// A polygon made to make ear clipping cubic — it winds around a triangle hundreds of times and
// ends in an arc its clipping takes in ring order, each clip re-testing most corners (4096 corners
// took 22 s) — is clipped until its budget of tests runs out and fanned from there: all of its
// n − 2 triangles, and the winding warning.
TEST(NffReader, EarClippingStopsAtItsBudget) {
  constexpr int kCorners = 3000;
  constexpr int kArc = kCorners / 3;
  constexpr int kRounds = (kCorners - kArc) / 3;
  std::vector<std::pair<double, double>> points;
  for (int i = 0; i < kRounds; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double angle = (90 + 120 * j) * std::numbers::pi / 180;
      const double off = (i - kRounds / 2.0) * 1e-3 / kRounds;  // along the tangent
      points.emplace_back(std::cos(angle) - std::sin(angle) * off,
                          std::sin(angle) + std::cos(angle) * off);
    }
  }
  const auto [px, py] = points.back();
  const double radius = std::hypot(px, py);
  const double base = std::atan2(-py, -px);
  for (int j = 0; j < kArc; ++j) {  // an arc of length 0.2 about the last point, through the middle
    const double angle = base - 0.1 / radius + 0.2 / radius * j / (kArc - 1);
    points.emplace_back(px + radius * std::cos(angle), py + radius * std::sin(angle));
  }
  std::string nff =
      "v from 0 0 10 at 0 0 0 up 0 1 0 angle 40 hither 1 resolution 8 8\n"
      "l 0 10 10\nf 1 0 0 0.5 0.5 10 0 1\n" +
      fmt::format("p {}\n", points.size());
  for (const auto& [x, y] : points) nff += fmt::format("{:.17g} {:.17g} 0\n", x, y);
  const ParseResult r = parseNff(nff, "a.nff");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  const std::vector<std::string> warnings = warningsOf(r);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0],
            "a.nff:4:1: warning: p: cutting the polygon into triangles took more "
            "than 71969568 tests of its corners; the rest of it is a fan of "
            "triangles, which may cover other parts than meant");
  EXPECT_THAT(warnings[1], ::testing::HasSubstr("the polygon winds around"));
  const Entity& polygon = nth(r, EntityKind::ObjectEntity, 0);
  const ValueTree& t = r.description.files[0]->values;
  EXPECT_EQ(t.size(r.description.parameter(polygon, "indices")), points.size() - 2);
}

// Text that is no text: a NUL byte is refused at its place (it read as a blank); a UTF-8
// byte-order mark at the start is skipped.
TEST(NffReader, ANulByteIsRefusedAndAByteOrderMarkSkipped) {
  const std::string scene =
      "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8\ns 0 0 0 1\n";
  const ParseResult nul = parseNff(std::string("v from 0 0 5\ns 0 0 0\0 1\n", 24), "nul.nff");
  EXPECT_EQ(firstError(nul), "nul.nff:2:8: the file holds a NUL byte here; a scene file is text");
  EXPECT_FALSE(nul.description.complete);
  const ParseResult bom = parseNff("\xEF\xBB\xBF" + scene, "bom.nff");
  EXPECT_FALSE(bom.hasErrors()) << firstError(bom);
  EXPECT_EQ(count(bom, EntityKind::ObjectEntity), 1u);
}

TEST(NffReader, ErrorsNameTheirLineAndColumn) {
  const auto error = [](const std::string& body) {
    return firstError(parseNff(
        "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8\n" + body, "bad.nff"));
  };
  EXPECT_EQ(error("sphere 0 0 0 1\n"),
            "bad.nff:2:1: unknown NFF statement 'sphere'; the statements are v, b, l, f, c, s, p, "
            "pp and # comments");
  EXPECT_EQ(error("pq 3\n"),
            "bad.nff:2:1: unknown NFF statement 'pq' (did you mean 'p'?); the statements are v, "
            "b, l, f, c, s, p, pp and # comments");
  EXPECT_EQ(error("s 0 0 x 1\n"), "bad.nff:2:7: s: expected a number (center z), got 'x'");
  // Lines end at "\n", "\r\n" or a lone "\r" (classic Mac OS).
  EXPECT_EQ(firstError(parseNff("v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8"
                                "\r# a comment\rs 0 0 x 1\r",
                                "cr.nff")),
            "cr.nff:3:7: s: expected a number (center z), got 'x'");
  EXPECT_EQ(firstError(parseNff("v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8"
                                "\r\n# a comment\r\ns 0 0 x 1\r\n",
                                "crlf.nff")),
            "crlf.nff:3:7: s: expected a number (center z), got 'x'");
  // A value too many is named on its own line (it was 'unknown NFF statement '7'').
  EXPECT_EQ(error("s 0 0 0 1 7\n"),
            "bad.nff:2:11: unexpected '7' after the statement's values on this line (one value "
            "too many?)");
  EXPECT_EQ(error("c 0 0 0 1 0 0 1\n"),
            "bad.nff:3:1: the file ends inside 'c' (line 2): expected a number (apex radius)");
  EXPECT_EQ(error("c 0 0 0 -1 0 0 1 1\n"),
            "bad.nff:2:9: c: a negative radius needs the other one negative too (both negative: "
            "only the inside is visible)");
  EXPECT_EQ(error("p 2\n0 0 0 1 1 1\n"),
            "bad.nff:2:3: p: the number of vertices must be a whole number from 3 to 4096, got 2");
  EXPECT_THAT(firstError(parseNff("s 0 0 0 1\n", "none.nff")),
              HasSubstr("none.nff:1:1: the file has no viewpoint"));
  EXPECT_EQ(firstError(parseNff("v from 0 0 5 at 0 0 0 up 0 1 0 angle 180 hither 1 resolution 8 8",
                                "a.nff")),
            "a.nff:1:38: v: angle must be in (0, 180) degrees, got 180");
  EXPECT_EQ(firstError(parseNff("v from 0 0 5 to 0 0 0", "a.nff")),
            "a.nff:1:14: v: expected 'at', got 'to' (a viewpoint is v, from, at, up, angle, "
            "hither, resolution, in this order)");
}

TEST(NffReader, ReadingGoesOnAfterAnErrorAndTheFactoriesReportAtTheTokens) {
  const ParseResult r = parseNff(
      "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8\n"
      "s 0 0 oops 1\n"
      "s 0 0 0 0\n",
      "two.nff");
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].where.line, 2);
  try {
    buildDescribedScene(r);
    FAIL() << "expected errors";
  } catch (const SceneError& e) {
    ASSERT_EQ(e.diagnostics().size(), 2u);
    // The factory's own check, at the radius token of line 3.
    EXPECT_EQ(e.diagnostics()[1].format(), "two.nff:3:9: sphere.radius must be > 0, got 0");
  }
}

}  // namespace
}  // namespace glint
