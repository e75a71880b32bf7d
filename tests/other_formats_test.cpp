// Other renderers' scenes (DESIGN.md §13) rendered by glint and checked in closed form: an NFF and
// a Tachyon scene's sphere (its silhouette and its colour: a light's direct term), the cameras'
// field of view at the image edge, Tachyon's mirror and orthographic camera, fog, vertex colours
// and spot falloff cones; then `glint convert` (the converted YAML renders the same bytes, with and
// without PLY files) and the quick look at a mesh file.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <set>
#include <string>

#include "glint/factories/quick_look.h"
#include "glint/factories/scene_loader.h"
#include "glint/job/job_error.h"
#include "glint/job/scene_convert.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_test_support.h"
#include "glint/readers/nff_reader.h"
#include "glint/readers/tachyon_reader.h"
#include "glint/render/renderer.h"
#include "glint/writers/ply_writer.h"
#include "glint/writers/yaml_scene_writer.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

Scene sceneOf(const ParseResult& parsed) { return Scene(buildDescribedScene(parsed).parts); }

Film renderOf(const Scene& scene) {
  RenderOptions options;
  options.threads = 2;
  return render(scene, options);
}

void expectColor(const Color& actual, const Color& expected, double tolerance = 1e-9) {
  EXPECT_NEAR(actual.r, expected.r, tolerance);
  EXPECT_NEAR(actual.g, expected.g, tolerance);
  EXPECT_NEAR(actual.b, expected.b, tolerance);
}

// The distance from the centre of a sphere at which the line through `origin` along unit `d`
// passes, and the nearer hit point when it hits.
std::optional<Point3> sphereHit(const Point3& origin, const Vec3& d, const Point3& c, double r) {
  const Vec3 f = origin - c;
  const double b = dot(f, d);
  const double disc = b * b - (dot(f, f) - r * r);
  if (disc < 0) return std::nullopt;
  return origin + d * (-b - std::sqrt(disc));
}

// An SPD-like scene: one sphere, two lights at the eye (one coloured), an opaque fill.
constexpr const char* kNffSphere = R"(b 0.1 0.2 0.3
v
from 0 0 10
at 0 0 0
up 0 1 0
angle 30
hither 1
resolution 65 65
l 0 0 10
l 0 0 10 0.5 0.25 1
f 1 0.5 0.25 0.8 0 1 0 1
s 0 0 0 2
)";

TEST(NffImage, SphereSilhouetteAndColourAreTheDirectTermsOfItsLights) {
  const ParseResult parsed = parseNff(kNffSphere, "sphere.nff");
  const Scene scene = sceneOf(parsed);
  const Film film = renderOf(scene);
  const Color kd{0.8, 0.4, 0.2};
  // Each light has intensity 1/√2 (two lights); the second is coloured.
  const Color lights = (Color(1) + Color{0.5, 0.25, 1}) / std::sqrt(2.0);
  const Camera& camera = scene.camera();
  int sphere = 0, background = 0;
  for (int y = 0; y < 65; ++y) {
    for (int x = 0; x < 65; ++x) {
      const Ray ray = camera.generateRay(x, y);
      const std::optional<Point3> p = sphereHit(ray.origin, ray.direction, {0, 0, 0}, 2);
      // Leave out pixels whose ray grazes the silhouette.
      const Vec3 f = ray.origin - Point3{0, 0, 0};
      const double miss = length(f - ray.direction * dot(f, ray.direction)) - 2;
      if (std::abs(miss) < 1e-6) continue;
      if (!p) {
        expectColor(film.at(x, y), {0.1, 0.2, 0.3}, 0);
        ++background;
        continue;
      }
      // kd·Σ I_L·|n·l| with both lights at the eye.
      const Vec3 n = normalize(*p - Point3{0, 0, 0});
      const Vec3 l = normalize(*p - Point3{0, 0, 10});
      expectColor(film.at(x, y), kd * lights * std::abs(dot(n, l)));
      ++sphere;
    }
  }
  EXPECT_GT(sphere, 500);
  EXPECT_GT(background, 1500);
  // The centre pixel looks straight at the sphere: n·l = −1.
  expectColor(film.at(32, 32), kd * lights);
}

TEST(NffImage, AngleSpansTheCentresOfTheEdgeRowsAndColumns) {
  for (const auto& [columns, rows] : {std::pair{65, 65}, std::pair{80, 41}, std::pair{32, 96}}) {
    const std::string text = fmt::format(
        "v from 1 2 3 at 1 2 -7 up 0 1 0 angle 50 hither 1 resolution {} {}\n", columns, rows);
    const Scene scene = sceneOf(parseNff(text, "fov.nff"));
    const Camera& camera = scene.camera();
    // The centres of the top and bottom rows lie 25° above and below the view direction (−z).
    for (const int row : {0, rows - 1}) {
      const Ray ray = camera.generateRay(columns / 2, row);
      EXPECT_NEAR(std::abs(std::atan2(ray.direction.y, -ray.direction.z)) * 180 / std::numbers::pi,
                  25, 1e-10)
          << columns << "x" << rows;
    }
    // Square pixels: the horizontal pitch is the vertical one.
    const Ray a = camera.generateRay(0, 0), b = camera.generateRay(1, 0),
              c = camera.generateRay(0, 1);
    EXPECT_NEAR(length(a.direction / -a.direction.z - b.direction / -b.direction.z),
                length(a.direction / -a.direction.z - c.direction / -c.direction.z), 1e-12);
  }
}

constexpr const char* kTachyonSphere = R"(BEGIN_SCENE
RESOLUTION 64 64
CAMERA ZOOM 1 ASPECTRATIO 1 ANTIALIASING 0 RAYDEPTH 4
  CENTER 0 0 -10 VIEWDIR 0 0 1 UPDIR 0 1 0 END_CAMERA
LIGHT CENTER 0 0 -10 RAD 0 COLOR 1 1 1
BACKGROUND 0.1 0.2 0.3
SPHERE CENTER 2 0 0 RAD 1 TEXTURE AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0 OPACITY 1
  COLOR 1 0.5 0.25 TEXFUNC 0
END_SCENE
)";

TEST(TachyonImage, SphereIsOnTheRightWithAmbientPlusDiffuseColour) {
  const Scene scene = sceneOf(parseTachyon(kTachyonSphere, "sphere.dat"));
  const Film film = renderOf(scene);
  const Color color{1, 0.5, 0.25};
  // Tachyon shows +x on the right looking along +z: the mirrored scene puts the sphere there.
  double sumX = 0;
  int count = 0;
  const Camera& camera = scene.camera();
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const Ray ray = camera.generateRay(x, y);
      const std::optional<Point3> p = sphereHit(ray.origin, ray.direction, {-2, 0, 0}, 1);
      if (!p) continue;
      const Vec3 n = normalize(*p - Point3{-2, 0, 0});
      const Vec3 l = normalize(*p - Point3{0, 0, -10});
      // Tachyon: colour · (ambient + diffuse · n·L).
      expectColor(film.at(x, y), color * (0.1 + 0.8 * std::abs(dot(n, l))), 1e-9);
      sumX += x;
      ++count;
    }
  }
  ASSERT_GT(count, 20);
  // 2/10 of the way out in a plane 1/zoom = 1 high at distance 1: 0.2·64 pixels right of centre.
  EXPECT_NEAR(sumX / count, 31.5 + 0.2 * 64, 0.6);
  // ZOOM 1: the top row's centre is atan(0.5·63/64) above the view direction.
  const Ray top = camera.generateRay(32, 0);
  EXPECT_NEAR(std::atan2(top.direction.y, top.direction.z), std::atan(0.5 * 63 / 64), 1e-9);
}

TEST(TachyonImage, OrthographicCameraShowsTrueSizes) {
  std::string text = kTachyonSphere;
  text.replace(text.find("CAMERA ZOOM 1"), 13, "CAMERA PROJECTION ORTHOGRAPHIC ZOOM 0.1");
  const Scene scene = sceneOf(parseTachyon(text, "ortho.dat"));
  ASSERT_TRUE(scene.camera().isOrthographic());
  const Film film = renderOf(scene);
  // A view plane 10 units high: the sphere of radius 1 is 6.4 pixels in radius, centred 12.8 px
  // right of the centre; its pixels are those within that radius.
  for (int x = 0; x < 64; ++x) {
    const double offset = (x - 31.5) / 6.4;  // scene units from the centre line
    const bool inside = std::abs(offset - 2) < 0.99;
    const bool outside = std::abs(offset - 2) > 1.01;
    if (inside) {
      EXPECT_FALSE(film.at(x, 31) == Color(0.1, 0.2, 0.3)) << x;
    }
    if (outside) {
      EXPECT_TRUE(film.at(x, 31) == Color(0.1, 0.2, 0.3)) << x;
    }
  }
}

TEST(FogImage, LinearFogBlendsByDistance) {
  const std::string yaml = R"(camera: {position: [0, 0, 0], direction: [0, 0, -1], fov: 30}
image: {width: 8, height: 8, encoding: linear}
ambient: {intensity: 1}
fog: {type: linear, start: 2, end: 12, color: [0, 0, 1]}
objects:
  - {type: plane, point: [0, 0, -6], normal: [0, 0, 1], material: {kd: 0, ka: [1, 1, 0]}}
)";
  const Scene scene(loadSceneFromString(yaml, "fog.yaml").parts);
  const Film film = renderOf(scene);
  const Ray ray = scene.camera().generateRay(3, 4);
  const double t = 6 / -ray.direction.z;
  const double f = (12 - t) / (12 - 2);
  expectColor(film.at(3, 4), Color{1, 1, 0} * f + Color{0, 0, 1} * (1 - f));
}

TEST(VertexColorImage, ColoursInterpolateAndTintKdAndKa) {
  const std::string yaml = R"(camera: {position: [0, 0, 5], direction: [0, 0, -1], fov: 40}
image: {width: 9, height: 9, encoding: linear}
ambient: {intensity: 1}
objects:
  - type: mesh
    positions: [[-4, -4, 0], [4, -4, 0], [0, 4, 0]]
    colors: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    indices: [[0, 1, 2]]
    material: {ka: 0.5}
)";
  const Scene scene(loadSceneFromString(yaml, "colors.yaml").parts);
  const Film film = renderOf(scene);
  // The centre pixel looks at (0, 0): barycentrics (0.25, 0.25, 0.5).
  expectColor(film.at(4, 4), Color{0.25, 0.25, 0.5} * 0.5, 1e-12);
}

TEST(SpotFalloff, LinearInTheAngleBetweenTheCones) {
  SpotLight spot;
  spot.direction = {0, 0, -1};
  spot.falloffStart = 20;
  spot.falloffEnd = 40;
  const auto at = [&](double degrees) {
    const double a = degrees * std::numbers::pi / 180;
    return spotFactor(spot, Vec3{std::sin(a), 0, -std::cos(a)});
  };
  EXPECT_DOUBLE_EQ(at(10), 1);
  EXPECT_NEAR(at(30), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(at(45), 0);
}

// --- convert -------------------------------------------------------------------------------------

class Convert : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() / fmt::format("glint-convert-{}", ::getpid());
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  fs::path write(const std::string& name, const std::string& text) {
    const fs::path path = folder_ / name;
    std::ofstream(path) << text;
    return path;
  }

  // Renders FILE and its conversion to `name`.yaml; both images must be the same bytes.
  // `width`: render both at that width (0: the scene's own).
  void expectSameImage(const fs::path& file, std::size_t plyFiles, int width = 0) {
    const fs::path output = folder_ / "out" / (file.stem().string() + ".yaml");
    fs::create_directories(output.parent_path());
    const ConvertResult result = convertScene(ConvertSpec{file, output, nullptr, {}});
    EXPECT_EQ(result.meshFiles.size(), plyFiles);
    LoadOptions options;
    if (width > 0) options.overrides.width = width;
    const Film original = renderOf(Scene(loadScene(file, options).parts));
    const Film converted = renderOf(Scene(loadScene(output, options).parts));
    ASSERT_EQ(original.width(), converted.width());
    ASSERT_EQ(original.height(), converted.height());
    int different = 0;
    for (int y = 0; y < original.height(); ++y) {
      for (int x = 0; x < original.width(); ++x)
        different += original.at(x, y) == converted.at(x, y) ? 0 : 1;
    }
    EXPECT_EQ(different, 0) << file;
  }

  // scenes/textures/uv_grid.png as maps/chart.png in the folder.
  void copyChart() {
    fs::create_directories(folder_ / "maps");
    fs::copy_file(fs::path(GLINT_SOURCE_DIR) / "scenes" / "textures" / "uv_grid.png",
                  folder_ / "maps" / "chart.png");
  }

  fs::path folder_;
};

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST_F(Convert, NffRendersTheSameBytes) { expectSameImage(write("sphere.nff", kNffSphere), 0); }

TEST_F(Convert, TachyonRendersTheSameBytes) {
  expectSameImage(write("sphere.dat", kTachyonSphere), 0);
}

TEST_F(Convert, LargePolygonSetsGoToPlyFilesAndRenderTheSameBytes) {
  // A 90×90 grid of quads (16,200 triangles) with patch normals, and a flat copy of it.
  std::string nff =
      "v from 0 -60 40 at 0 0 0 up 0 0 1 angle 40 hither 1 resolution 48 36\nl 10 -20 30\n"
      "f 0.9 0.6 0.3 0.8 0.2 20 0 1\n";
  for (const bool patch : {true, false}) {
    for (int i = 0; i < 90; ++i) {
      for (int j = 0; j < 90; ++j) {
        nff += patch ? "pp 4\n" : "p 4\n";
        for (const auto& [a, b] :
             {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
          const double x = (i + a) * 0.4 - 18, y = (j + b) * 0.4 - 18;
          const double z = patch ? 2 * std::sin(x * 0.3) * std::cos(y * 0.2) : -3 + 0.01 * x;
          nff += fmt::format("{} {} {}", x, y, z);
          if (patch)
            nff += fmt::format(" {} {} 1", -0.6 * std::cos(x * 0.3) * std::cos(y * 0.2),
                               0.4 * std::sin(x * 0.3) * std::sin(y * 0.2));
          nff += "\n";
        }
      }
    }
  }
  expectSameImage(write("grid.nff", nff), 2);
  // Every file or none: a folder where the second mesh file would go fails the convert before
  // anything is written.
  const fs::path output = folder_ / "blocked" / "grid.yaml";
  fs::create_directories(folder_ / "blocked" / "grid_mesh2.ply");
  try {
    convertScene(ConvertSpec{folder_ / "grid.nff", output, nullptr, {}});
    ADD_FAILURE() << "not refused";
  } catch (const JobError& e) {
    EXPECT_EQ(e.exitCode(), 2);  // as an output image that is a folder
    EXPECT_THAT(e.what(), testing::HasSubstr("grid_mesh2.ply: cannot write: it is a folder"));
  }
  std::set<std::string> left;
  for (const auto& entry : fs::directory_iterator(folder_ / "blocked")) {
    left.insert(entry.path().filename().string());
  }
  EXPECT_EQ(left, std::set<std::string>{"grid_mesh2.ply"});
}

TEST_F(Convert, TexturesAndTheirImageFilesKeepTheirPaths) {
  // Named and inline image textures, a normal map, an HDR sky; mesh files with their own maps.
  for (const char* scene : {"textures.yaml", "textured-model.yaml"}) {
    expectSameImage(fs::path(GLINT_SOURCE_DIR) / "scenes" / scene, 0, 96);
  }
  // Textures from an included file, whose image names start at that file's folder.
  const fs::path chart = fs::path(GLINT_SOURCE_DIR) / "scenes" / "textures" / "uv_grid.png";
  ASSERT_TRUE(fs::exists(chart)) << chart;
  fs::create_directories(folder_ / "library" / "maps");
  fs::copy_file(chart, folder_ / "library" / "maps" / "chart.png");
  write("library/paints.yaml",
        "textures:\n  chart: {type: image, file: maps/chart.png, filter: bilinear}\n"
        "materials:\n  charted: {kd: chart}\n");
  expectSameImage(
      write("included.yaml",
            "include: library/paints.yaml\n"
            "camera: {position: [0, 0, 4], look_at: [0, 0, 0], fov: 40}\n"
            "image: {width: 40, height: 30}\n"
            "ambient: {color: [1, 1, 1], intensity: 1}\n"
            "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: charted}\n"
            "  - {type: rectangle, corner: [-2, -1.5, -1], edges: [[4, 0, 0], [0, 3, 0]], "
            "material: {ka: {type: image, file: library/maps/chart.png}}}\n"),
      0);
}

// A YAML inline mesh of 8,192 triangles (a PLY file when converted) without normals, a solid
// checker in kd and an image file (maps/chart.png beside the scene) in ka.
std::string texturedGridScene(const std::string& extraObject) {
  std::string positions, indices;
  constexpr int kCells = 64;
  for (int j = 0; j <= kCells; ++j) {
    for (int i = 0; i <= kCells; ++i) {
      const double x = i * 4.0 / kCells - 2, y = j * 3.0 / kCells - 1.5;
      positions += fmt::format("{}[{}, {}, {}]", positions.empty() ? "" : ", ", x, y,
                               0.3 * std::sin(3 * x) * std::cos(2 * y));
    }
  }
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) {
      const int a = j * (kCells + 1) + i, b = a + 1, c = a + kCells + 1, d = c + 1;
      indices += fmt::format("{}[{}, {}, {}], [{}, {}, {}]", indices.empty() ? "" : ", ", a, b, d,
                             a, d, c);
    }
  }
  return "camera: {position: [0, -3, 4], look_at: [0, 0, 0], fov: 45}\n"
         "image: {width: 48, height: 36}\n"
         "lights: [{type: point, position: [3, -2, 5]}]\n"
         "objects:\n"
         "  - {type: mesh, positions: [" +
         positions + "], indices: [" + indices +
         "], material: {kd: {type: checker, colors: [[0.9, 0.2, 0.1], [0.9, 0.9, 0.8]], scale: "
         "0.5}, ks: 0.5, shininess: 30, ka: {type: image, file: maps/chart.png}}}\n" +
         extraObject;
}

// Rendering the conversion gives the same bytes also when the inline mesh becomes a PLY file:
// without normals it stays flat (a mesh file without normals would get generated ones), and a
// texture file its material names is found from the output's folder.
TEST_F(Convert, InlineMeshesWrittenAsPlyKeepFlatFacetsAndTheirTextures) {
  copyChart();
  expectSameImage(write("grid.yaml", texturedGridScene("")), 1);
  EXPECT_THAT(readText(folder_ / "out" / "grid.yaml"), testing::HasSubstr("smooth: false"));
}

// The files a conversion writes never replace a file the scene reads: a PLY file of the scene's
// own takes another name, and an output named as an included file is refused (exit status 2).
TEST_F(Convert, NothingTheSceneReadsIsWrittenOver) {
  copyChart();
  fs::create_directories(folder_ / "out");
  // A mesh file of the name the first PLY file would take.
  PlyMesh triangle;
  triangle.positions = {-2, 1, -1, -1, 1, -1, -1.5, 1.5, -1};
  triangle.indices = {0, 1, 2};
  const std::string ownBytes = binaryPly(triangle);
  std::ofstream(folder_ / "out" / "grid_mesh1.ply", std::ios::binary) << ownBytes;
  expectSameImage(
      write("grid.yaml", texturedGridScene("  - {type: mesh, file: out/grid_mesh1.ply}\n")), 1);
  EXPECT_EQ(readText(folder_ / "out" / "grid_mesh1.ply"), ownBytes);
  EXPECT_TRUE(fs::exists(folder_ / "out" / "grid_mesh2.ply"));

  write("library.yaml", "materials:\n  red: {kd: [1, 0, 0]}\n");
  const fs::path scene = write(
      "main.yaml",
      "include: library.yaml\ncamera: {position: [0, 0, 4], look_at: [0, 0, 0], fov: 40}\n"
      "image: {width: 8, height: 6}\nobjects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, "
      "material: red}\n");
  try {
    convertScene(ConvertSpec{scene, folder_ / "library.yaml", nullptr, {}});
    ADD_FAILURE() << "not refused";
  } catch (const JobError& e) {
    EXPECT_EQ(e.exitCode(), 2);
    EXPECT_THAT(e.what(), testing::HasSubstr("the scene being converted reads this file"));
  }
  EXPECT_EQ(readText(folder_ / "library.yaml"), "materials:\n  red: {kd: [1, 0, 0]}\n");
}

// A cancel seen before the files are renamed writes nothing and leaves no temporary file; the
// renames happen with `committing` true.
TEST_F(Convert, ACancelWritesNothingAndTheRenamesAreOneCommit) {
  copyChart();
  const fs::path scene = write("grid.yaml", texturedGridScene(""));
  fs::create_directories(folder_ / "out");
  std::atomic<bool> cancel{true};
  ConvertSpec spec{scene, folder_ / "out" / "grid.yaml", &cancel, {}};
  std::vector<bool> commits;
  spec.committing = [&commits](bool committing) { commits.push_back(committing); };
  EXPECT_TRUE(convertScene(spec).interrupted);
  EXPECT_TRUE(fs::is_empty(folder_ / "out"));
  EXPECT_TRUE(commits.empty());
  cancel = false;
  const ConvertResult result = convertScene(spec);
  EXPECT_FALSE(result.interrupted);
  EXPECT_EQ(result.meshFiles.size(), 1u);
  EXPECT_EQ(commits, (std::vector<bool>{true, false}));
}

TEST(YamlScalar, ControlCharactersAreEscaped) {
  EXPECT_EQ(yamlScalar("a\x7f"
                       "b"),
            "\"a\\x7fb\"");
  EXPECT_EQ(yamlScalar("a\xc2\x80"
                       "b"),
            "\"a\\u0080b\"");
  EXPECT_EQ(yamlScalar("caf\xc3\xa9"), "\"caf\xc3\xa9\"");  // é is no control character
  EXPECT_EQ(yamlScalar("tab\there"), "\"tab\\there\"");
}

TEST_F(Convert, YamlWithAMeshFileKeepsItsPath) {
  const fs::path mesh = fs::path(GLINT_SOURCE_DIR) / "scenes" / "mesh.yaml";
  expectSameImage(mesh, 0);
}

TEST(QuickLook, FramesTheModelWithLightsAndGround) {
  const fs::path model = fs::path(GLINT_SOURCE_DIR) / "scenes" / "meshes" / "torus_knot.obj";
  const LoadedScene loaded = loadScene(model);
  const SceneParts& parts = loaded.parts;
  EXPECT_EQ(parts.lights.size(), 3u);
  ASSERT_EQ(parts.primitives.size(), 1u);  // the ground plane
  EXPECT_FALSE(parts.meshes.empty());
  // The whole model is in view: every vertex projects inside the image.
  const Scene scene{SceneParts(parts)};
  const Camera& camera = scene.camera();
  for (const TriangleMesh& mesh : scene.meshes()) {
    for (const Point3& p : mesh.positions) {
      const Vec3 d = p - camera.position();
      const double depth = dot(d, camera.toward());
      ASSERT_GT(depth, 0);
      EXPECT_LT(std::abs(dot(d, camera.right()) / depth), camera.viewPlaneWidth() / 2);
      EXPECT_LT(std::abs(dot(d, camera.up()) / depth), camera.viewPlaneHeight() / 2);
    }
  }
  // From the front-right-above.
  const Vec3 toCamera = camera.position() - scene.aggregate().bounds().centroid();
  EXPECT_GT(toCamera.x, 0);
  EXPECT_GT(toCamera.y, 0);
  EXPECT_GT(toCamera.z, 0);
}

// Triangles assimp's glTF reader leaves out for an index out of range are not silent: a warning
// at the mesh object says so.
TEST(QuickLook, FacesTheMeshLibraryDropsAreAWarning) {
  const mesh_test::TempDir dir;
  const LoadedScene clean = loadScene(mesh_test::writeQuadGltf(dir, 3));
  EXPECT_TRUE(clean.warnings.empty());
  const LoadedScene dropped = loadScene(mesh_test::writeQuadGltf(dir, 7));
  ASSERT_EQ(dropped.parts.meshes.size(), 1u);
  EXPECT_EQ(dropped.parts.meshes[0].triangleCount(), 2u);
  ASSERT_EQ(dropped.warnings.size(), 1u);
  EXPECT_THAT(
      dropped.warnings[0].format(),
      testing::HasSubstr("warning: mesh file 'quad7.gltf': the mesh library left out faces whose "
                         "vertex indices are out of range (it does not say how many); 2 triangles "
                         "remain"));
}

// A bare mesh file has no scene folder: what it names outside its own folder (a textures folder
// beside it) is refused in those words, with the way to use such a layout.
TEST(QuickLook, FilesOutsideTheModelsFolderAreRefusedWithTheWayOut) {
  const mesh_test::TempDir dir;
  fs::create_directories(dir.path() / "models");
  fs::create_directories(dir.path() / "textures");
  fs::copy_file(fs::path(GLINT_SOURCE_DIR) / "scenes" / "textures" / "uv_grid.png",
                dir.path() / "textures" / "uv_grid.png");
  dir.write("models/m.mtl", "newmtl m\nKd 1 1 1\nmap_Kd ../textures/uv_grid.png\n");
  const fs::path model = dir.write(
      "models/m.obj",
      "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n");
  const auto way = [](const std::string& name) {
    return "; to use files outside the model's folder (a textures folder beside it), render a "
           "scene file written in a folder that holds both, with a mesh object naming the model "
           "({type: mesh, file: models/" +
           name +
           "}, and a camera: glint convert cannot write it, as it reads the model the "
           "same way)";
  };
  try {
    loadScene(model);
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("(a mesh file may only name files in its own folder "
                                             "and below)" +
                                             way("m.obj")));
  }
  // A scene file above both reads it.
  const fs::path scene = dir.write(
      "scene.yaml",
      "camera: {position: [0, 0, 3], look_at: [0, 0, 0], fov: 40}\nimage: {width: 8, height: 8}\n"
      "objects:\n  - {type: mesh, file: models/m.obj}\n");
  EXPECT_EQ(loadScene(scene).parts.meshes.size(), 1u);
  // The model's own MTL outside its folder: refused by the reader, with the same way out.
  dir.write("shared.mtl", "newmtl m\nKd 1 0 0\n");
  const fs::path outside =
      dir.write("models/o.obj", "mtllib ../shared.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  try {
    loadScene(outside);
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("its own folder and below)" + way("o.obj")));
  }
}

// An OBJ's material library that is not there is a warning, not a silent grey.
TEST(QuickLook, AMissingMaterialLibraryIsAWarning) {
  const mesh_test::TempDir dir;
  const LoadedScene loaded = loadScene(dir.write(
      "knot.obj", "mtllib knot-copper.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl copper\nf 1 2 3\n"));
  ASSERT_EQ(loaded.warnings.size(), 1u);
  EXPECT_THAT(loaded.warnings[0].format(),
              testing::HasSubstr("warning: mesh file 'knot.obj': its material library "
                                 "'knot-copper.mtl' is not there (the mesh library takes a whole "
                                 "mtllib line as one file name); a material no library defines "
                                 "is mid-grey"));
  // An object material replaces the file's: nothing to say.
  const fs::path scene = dir.write(
      "scene.yaml",
      "camera: {position: [0, 0, 3], look_at: [0, 0, 0], fov: 40}\nimage: {width: 8, height: 8}\n"
      "objects:\n  - {type: mesh, file: knot.obj, material: {kd: 0.5}}\n"
      "lights: [{type: point, position: [0, 0, 3]}]\n");
  EXPECT_TRUE(loadScene(scene).warnings.empty());
}

// The quick look reads its model once: to frame it, and the scene's mesh object takes that read
// (the file may be gone by the time the scene is built).
TEST(QuickLook, ReadsTheModelOnce) {
  const fs::path folder = fs::temp_directory_path() / fmt::format("glint-quick-{}", ::getpid());
  fs::create_directories(folder);
  const fs::path model = folder / "knot.obj";
  fs::copy_file(fs::path(GLINT_SOURCE_DIR) / "scenes" / "meshes" / "torus_knot.obj", model,
                fs::copy_options::overwrite_existing);
  const ParseResult described = describeSceneFile(model);
  ASSERT_EQ(described.description.readMeshFiles.size(), 1u);
  fs::remove_all(folder);
  const LoadedScene loaded = buildDescribedScene(described);
  ASSERT_EQ(loaded.parts.meshes.size(), 1u);
  EXPECT_EQ(loaded.parts.meshes[0].triangleCount(),
            described.description.readMeshFiles[0].second->triangleCount());
  EXPECT_EQ(loaded.parts.meshes[0].triangleCount(), 38400u);
}

}  // namespace
}  // namespace glint
