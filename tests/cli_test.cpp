// The glint command line (DESIGN.md §6, §7), tested by running the built binary: exit statuses,
// error positions for broken scene files, output files (never partial), overrides, crops, thread
// independence, signals and progress output.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_harness.h"
#include "glint/core/isa.h"

namespace glint_cli_test {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// --- exit statuses and basic output ---------------------------------------------------------

TEST_F(Cli, RenderWritesAPngAndExitsZero) {
  const RunResult r = run({"render", small(), "-o", "out.png"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto size = pngSize(work_ / "out.png");
  ASSERT_TRUE(size.has_value()) << "not a PNG";
  EXPECT_EQ(size->first, 32u);
  EXPECT_EQ(size->second, 24u);
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"out.png"}) << "a temporary file was left";
  EXPECT_EQ(r.out, "");
}

TEST_F(Cli, DefaultOutputIsTheSceneNameWithPngInTheCurrentFolder) {
  const RunResult r = run({"render", small(), "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"small.png"});
  EXPECT_TRUE(pngSize(work_ / "small.png").has_value());
}

TEST_F(Cli, PpmAndExrOutputsFollowTheExtension) {
  ASSERT_EQ(run({"render", small(), "-o", "out.ppm", "--quiet"}).status, 0);
  const Ppm ppm = readPpm(work_ / "out.ppm");
  EXPECT_EQ(ppm.width, 32);
  EXPECT_EQ(ppm.height, 24);
  EXPECT_EQ(ppm.rgb.size(), 32u * 24u * 3u);
  ASSERT_EQ(run({"render", small(), "-o", "out.exr", "--quiet"}).status, 0);
  // OpenEXR magic number 20000630, little-endian.
  EXPECT_EQ(readFile(work_ / "out.exr").substr(0, 4), std::string("\x76\x2f\x31\x01", 4));
}

TEST_F(Cli, HelpAndVersionExitZero) {
  RunResult r = run({"--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.out, "render")) << r.out;
  EXPECT_TRUE(contains(r.out, "check")) << r.out;
  r = run({"render", "--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.out, "--crop")) << r.out;
  EXPECT_TRUE(contains(r.out, "--threads")) << r.out;
  r = run({"--version"});
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.out, GLINT_VERSION)) << r.out;
  EXPECT_TRUE(filesIn(work_).empty());
}

TEST_F(Cli, ArgumentParserErrorsExitTwo) {
  RunResult r = run({"render", small(), "--bogus", "-o", "out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--bogus")) << r.err;
  EXPECT_EQ(run({}).status, 2);  // no command
  r = run({"draw", small()});    // unknown command
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "draw")) << r.err;
  EXPECT_EQ(run({"render"}).status, 2);                      // no scene
  EXPECT_EQ(run({"render", small(), small()}).status, 2);    // two scenes
  EXPECT_EQ(run({"render", small(), "--width"}).status, 2);  // missing value
  r = run({"render", small(), "--width", "abc"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--width")) << r.err;
  // An option given twice, in glint's words rather than the parser library's.
  r = run({"render", small(), "--width", "32", "--width", "16"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--width is given more than once; give it once")) << r.err;
  EXPECT_FALSE(contains(r.err, "At Most")) << r.err;
  // An option before the command is named, not taken for a missing command.
  r = run({"--bogus"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "unknown option '--bogus': options go after the command")) << r.err;
  // Arguments left over are listed in the order given.
  r = run({"render", "--", small(), "--width", "16", "-o", "out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "not expected: --width 16 -o out.png\n")) << r.err;
  // A misspelt option is named, with the option meant, and the help of its command.
  r = run({"render", small(), "--widht", "16"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "unknown option '--widht' (did you mean '--width'?)\n")) << r.err;
  EXPECT_TRUE(contains(r.err, "Run 'glint render --help' for usage.")) << r.err;
  r = run({"check", small(), "--max-memroy", "1G"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "unknown option '--max-memroy' (did you mean '--max-memory'?)"))
      << r.err;
  EXPECT_TRUE(contains(r.err, "Run 'glint check --help' for usage.")) << r.err;
  r = run({"render", small(), "--widht=16"});
  EXPECT_TRUE(contains(r.err, "unknown option '--widht=16' (did you mean '--width'?)")) << r.err;
  // A negative number is no option: the leftover words are named as they are.
  r = run({"render", small(), "3", "-1"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "not expected: 3 -1\n")) << r.err;
  // A scene name with a leading '-' is read as an option: say so, and how to name the file.
  r = run({"render", "-scene.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "unknown option '-scene.yaml'")) << r.err;
  EXPECT_TRUE(contains(r.err, "./-scene.yaml")) << r.err;
  // An empty output name is refused, not replaced by the default one.
  r = run({"render", small(), "-o", ""});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "-o needs a file name")) << r.err;
  EXPECT_TRUE(filesIn(work_).empty());
}

TEST_F(Cli, OutOfRangeOptionsExitTwoBeforeRendering) {
  const std::vector<std::vector<std::string>> cases{
      {"--samples", "0"},        {"--samples", "65537"},
      {"--threads", "0"},        {"--threads", "-3"},
      {"--width", "0"},          {"--height", "-1"},
      {"--width", "70000"},      {"--height", "65536"},
      {"--width", "65535"},      {"--seed", "-1"},
      {"--integrator", "bidir"}, {"--crop", "0,0,33,24"},
      {"--crop", "0,0,32,25"},   {"--crop", "5,0,5,24"},
      {"--crop", "0,10,32,4"},   {"--crop", "-1,0,8,8"},
      {"--crop", "1,2,3"},       {"--crop", "a,b,c,d"},
      {"--crop", "0,0,8,8,9"},   {"--crop", "0,0,40,30", "--width", "32"},
  };
  for (const auto& extra : cases) {
    std::vector<std::string> args{"render", small(), "-o", "out.png"};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = run(args);
    EXPECT_EQ(r.status, 2) << extra[0] << " " << extra[1] << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, extra[0])) << extra[0] << " " << extra[1] << ": " << r.err;
    EXPECT_TRUE(filesIn(work_).empty()) << extra[0] << " " << extra[1];
  }
}

TEST_F(Cli, MissingSceneFileExitsTwoNamingIt) {
  const RunResult r = run({"render", "no-such-scene.yaml", "-o", "out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "no-such-scene.yaml")) << r.err;
  EXPECT_TRUE(filesIn(work_).empty());
}

TEST_F(Cli, SceneThatIsAFolderExitsTwoNamingIt) {
  const RunResult r = run({"check", kBroken.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, kBroken.string())) << r.err;
}

TEST_F(Cli, CheckPrintsASummaryAndWritesNothing) {
  const RunResult r = run({"check", small()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "cli small")) << r.out;
  EXPECT_TRUE(contains(r.out, "32x24")) << r.out;
  EXPECT_TRUE(contains(r.out, "shapes:    4 (3 bounded, 1 unbounded)")) << r.out;
  EXPECT_TRUE(contains(r.out, "lights:    2 + ambient")) << r.out;
  EXPECT_TRUE(contains(r.out, "materials:")) << r.out;
  EXPECT_TRUE(contains(r.out, "bounds:")) << r.out;
  EXPECT_TRUE(filesIn(work_).empty());
}

// check takes render's scene options and reports what that render would: their warnings, and
// the image they ask for refused, naming them.
TEST_F(Cli, CheckTakesRendersSceneOptions) {
  writeFile(work_ / "ao.yaml",
            "camera: {position: [0, 0, 5], look_at: [0, 0, 0], fov: 40}\n"
            "image: {width: 32, height: 24}\n"
            "render: {ambient_occlusion: {samples: 4}}\n"
            "objects: [{type: sphere, center: [0, 0, 0], radius: 1, material: {kd: 0.5}}]\n"
            "lights: [{type: point, position: [0, 4, 4]}]\n");
  RunResult r = run({"check", "ao.yaml"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(contains(r.err, "warning")) << r.err;
  r = run({"check", "ao.yaml", "--integrator", "path", "--samples", "4", "--seed", "3"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.err,
                       "ao.yaml:3:10: warning: render.ambient_occlusion has no effect: it is "
                       "an option of the whitted integrator, and this render uses path "
                       "(--integrator)"))
      << r.err;
  EXPECT_TRUE(contains(r.out, "32x24, 4 samples per pixel")) << r.out;
  r = run({"check", "ao.yaml", "--width", "60000", "--height", "60000"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--width 60000 --height 60000 refused")) << r.err;
  EXPECT_EQ(run({"check", "ao.yaml", "--integrator", "bidir"}).status, 2);
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"ao.yaml"});
}

// scenes/mesh.yaml places scenes/meshes/torus_knot.obj (38,400 triangles, one material) twice.
TEST_F(Cli, CheckCountsMeshesAndTheirTriangles) {
  const RunResult r =
      run({"check", (std::filesystem::path(GLINT_SOURCE_DIR) / "scenes" / "mesh.yaml").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "meshes:    2 (76800 triangles)")) << r.out;
  EXPECT_TRUE(filesIn(work_).empty());
}

// The mesh reader program (glint-mesh-reader) is found beside glint in the build tree; one that
// cannot be started refuses the mesh at its line, naming the program and why.
TEST_F(Cli, AMeshReaderThatCannotStartIsAClearErrorAtTheMesh) {
  const std::string reader = (work_ / "no-such-reader").string();
  ASSERT_EQ(::setenv("GLINT_MESH_READER", reader.c_str(), 1), 0);
  const RunResult r =
      run({"render", (std::filesystem::path(GLINT_SOURCE_DIR) / "scenes" / "mesh.yaml").string(),
           "-o", "out.png"});
  ::unsetenv("GLINT_MESH_READER");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "mesh.yaml:")) << r.err;
  EXPECT_TRUE(
      contains(r.err, "cannot start the mesh reader " + reader + ": no such file or directory"))
      << r.err;
  EXPECT_TRUE(filesIn(work_).empty());
}

TEST_F(Cli, CheckReportsTheSameErrorsAsRender) {
  const std::string scene = (kBroken / "negative_radius.yaml").string();
  const RunResult check = run({"check", scene});
  const RunResult render = run({"render", scene, "-o", "out.png"});
  EXPECT_EQ(check.status, 2);
  EXPECT_EQ(render.status, 2);
  EXPECT_TRUE(contains(check.err, "negative_radius.yaml:12:13")) << check.err;
  EXPECT_EQ(check.err, render.err);
  EXPECT_TRUE(filesIn(work_).empty());
}

// --- broken scene files ---------------------------------------------------------------------

struct BrokenScene {
  const char* file;
  const char* position;  // LINE:COL of the key or value at fault (1:1 when there is no place)
  std::vector<std::string> fragments;  // each must appear in the message
};

// One file per error class of DESIGN.md §5 and §7.
const std::vector<BrokenScene> kBrokenScenes{
    {"unknown_top_level_key.yaml", "9:1", {"colour"}},
    {"misspelt_object_key.yaml", "12:5", {"raduis"}},
    {"wrong_type.yaml", "7:10", {"width"}},
    {"missing_camera.yaml", "1:1", {"camera"}},
    {"missing_image.yaml", "1:1", {"image"}},
    {"negative_radius.yaml", "12:13", {"radius", "-2"}},
    {"zero_length_direction.yaml", "4:14", {"direction"}},
    {"up_parallel_to_direction.yaml", "5:7", {"up", "parallel"}},
    {"width_zero.yaml", "7:10", {"width"}},
    {"width_too_large.yaml", "7:10", {"70000"}},
    {"samples_zero.yaml", "9:12", {"samples"}},
    {"fov_180.yaml", "5:8", {"fov"}},
    {"direction_and_look_at.yaml", "5:3", {"direction", "look_at"}},
    {"view_plane_and_fov.yaml", "6:3", {"view_plane", "fov"}},
    {"undefined_material.yaml", "12:61", {"chrome"}},
    {"duplicate_key.yaml", "13:5", {"radius"}},
    {"two_documents.yaml", "9:1", {"document"}},
    {"nan_value.yaml", "10:52", {"intensity"}},
    {"infinite_value.yaml", "5:48", {"distance"}},
    {"collinear_triangle.yaml", "11:15", {"collinear"}},
    {"non_planar_polygon.yaml", "11:15", {"planar"}},
    {"non_convex_polygon.yaml", "11:15", {"convex"}},
    {"rectangle_edges_not_perpendicular.yaml", "12:12", {"perpendicular"}},
    {"attenuation_all_zero.yaml", "12:18", {"attenuation"}},
    {"bad_color_string.yaml", "9:13", {"background"}},
    {"unknown_object_type.yaml", "10:11", {"pyramid"}},
    {"unknown_light_type.yaml", "10:11", {"laser"}},
    {"mesh_object.yaml", "10:5", {"mesh"}},
    {"syntax_error.yaml", "3:22", {"syntax"}},
    {"empty_file.yaml", "1:1", {"empty"}},
    {"negative_kd.yaml", "10:15", {"kd"}},
    {"ior_zero.yaml", "12:10", {"ior"}},
    {"missing_object_key.yaml", "10:5", {"radius"}},
    {"max_depth_zero.yaml", "10:14", {"max_depth"}},
    {"unknown_transform_step.yaml", "15:11", {"skew"}},
    {"unknown_encoding.yaml", "9:13", {"gamma"}},
    {"triangle_four_vertices.yaml", "11:15", {"vertices"}},
    {"negative_intensity.yaml", "11:14", {"intensity"}},
    {"objects_not_a_list.yaml", "9:10", {"objects"}},
    {"negative_min_weight.yaml", "10:15", {"min_weight"}},
    {"grid_interval_zero.yaml", "9:21", {"interval"}},
    {"area_light_missing_shape.yaml", "12:5", {"shape", "rectangle, disk, sphere"}},
    {"area_light_key_of_another_shape.yaml", "16:5", {"radius", "not of a rectangle"}},
    {"area_light_edges_not_perpendicular.yaml", "15:12", {"perpendicular"}},
    {"area_light_zero_normal.yaml", "15:13", {"normal", "non-zero"}},
    {"area_light_radius_zero.yaml", "12:61", {"radius", "> 0"}},
    {"area_light_samples_zero.yaml", "12:75", {"samples"}},
    {"adaptive_max_below_samples.yaml", "10:28", {"max_samples", "image.samples"}},
    {"adaptive_threshold_zero.yaml", "9:43", {"threshold"}},
    {"aperture_without_focus.yaml", "6:13", {"focus_distance", "look_at"}},
    {"undefined_texture.yaml", "12:67", {"undefined texture 'tyles'", "did you mean 'tiles'"}},
    {"unknown_texture_type.yaml", "10:18", {"chequer", "checker2d"}},
    {"missing_texture_file.yaml", "10:88", {"nowhere.png", "no such file"}},
    {"unknown_background_type.yaml", "9:21", {"skybox", "gradient, sky or image"}},
    // Other renderers' formats (DESIGN.md §13), read by their extension.
    {"nff_unknown_statement.nff", "11:1", {"unknown NFF statement 'sp'", "did you mean 's'"}},
    {"nff_not_a_number.nff", "10:7", {"expected a number", "'zero'"}},
    {"nff_zero_radius.nff", "11:9", {"sphere.radius must be > 0"}},
    {"dat_unsupported_statement.dat",
     "7:1",
     {"SPHEREARRAY", "nearest supported statement is SPHERE"}},
    {"dat_undefined_texture.dat", "4:27", {"undefined texture 'Carbon'"}},
    {"dat_texfunc_grit.dat",
     "6:11",
     {"TEXFUNC 2 (grit) is not supported by glint", "1 (3D checker)"}},
    // Found by the fuzzer: a texture function far outside int's range is named, not cast.
    {"dat_texfunc_huge.dat", "6:11", {"TEXFUNC 4.44444e+82 (unknown) is not supported by glint"}},
    // Counts larger than the file: an error where the numbers run out, not gigabytes reserved.
    {"dat_vertex_count_beyond_file.dat", "4:1", {"expected a number (vertex)", "END_SCENE"}},
    {"dat_triangle_count_beyond_file.dat", "6:1", {"expected a number (vertex index)"}},
    // A bare mesh file (a quick look): a malformed statement at its place — a vertex index past the
    // file's vertices...
    {"obj_vertex_index_past.obj", "4:7", {"vertex index 7 is past the file's 3 vertices"}},
    // ... a word that is no number (assimp would read it as 1), an index past the normals (assimp
    // would drop every normal).
    {"obj_not_a_number.obj", "3:7", {"'1x' is not a number"}},
    {"obj_normal_index_past.obj", "5:16", {"normal index 2 is past the file's 1 normal"}},
};

TEST_F(Cli, BrokenScenesExitTwoNamingFileLineAndColumn) {
  for (const BrokenScene& broken : kBrokenScenes) {
    SCOPED_TRACE(broken.file);
    const RunResult r = run({"render", (kBroken / broken.file).string(), "-o", "out.png"});
    EXPECT_EQ(r.status, 2) << r.err;
    const std::string where = std::string(broken.file) + ":" + broken.position + ":";
    EXPECT_TRUE(contains(r.err, where)) << "expected " << where << " in:\n" << r.err;
    for (const std::string& fragment : broken.fragments)
      EXPECT_TRUE(contains(r.err, fragment)) << "expected '" << fragment << "' in:\n" << r.err;
    // No library jargon and no crash report.
    for (const char* jargon : {"YAML::", "yaml-cpp", "terminate", "what()", "std::", "Assertion"})
      EXPECT_FALSE(contains(r.err, jargon)) << r.err;
    EXPECT_TRUE(filesIn(work_).empty()) << "a failed run left a file behind";
  }
}

TEST_F(Cli, EveryBrokenFileIsInTheTable) {
  std::set<std::string> listed;
  for (const BrokenScene& broken : kBrokenScenes) listed.insert(broken.file);
  EXPECT_EQ(listed.size(), kBrokenScenes.size()) << "a file is listed twice";
  EXPECT_GE(listed.size(), 25u);
  EXPECT_EQ(filesIn(kBroken), listed);
}

TEST_F(Cli, ConvertWritesAYamlSceneThatRendersTheSameBytes) {
  const std::string scene = (fs::path(GLINT_SOURCE_DIR) / "scenes" / "spd-balls.nff").string();
  RunResult r = run({"convert", scene, "-o", "balls.yaml"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "wrote balls.yaml (")) << r.out;
  r = run({"render", scene, "--width", "96", "-o", "nff.ppm", "--quiet"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = run({"render", "balls.yaml", "--width", "96", "-o", "yaml.ppm", "--quiet"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readFile(work_ / "nff.ppm"), readFile(work_ / "yaml.ppm"));
  // A wrong output name, a broken scene: exit 2 and nothing written.
  fs::remove(work_ / "balls.yaml");
  r = run({"convert", scene, "-o", "balls.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "name it .yaml")) << r.err;
  r = run({"convert", scene, "-o", "balls.json"});  // YAML's flow style is not JSON
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "is YAML (not JSON); name it .yaml or .yml")) << r.err;
  r = run({"convert", (kBroken / "nff_zero_radius.nff").string(), "-o", "zero.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "nff_zero_radius.nff:11:9:")) << r.err;
  EXPECT_FALSE(fs::exists(work_ / "zero.yaml"));
}

TEST_F(Cli, AMeshFileRendersAsAQuickLook) {
  const std::string mesh =
      (fs::path(GLINT_SOURCE_DIR) / "scenes" / "meshes" / "torus_knot.obj").string();
  const RunResult r = run({"render", mesh, "--width", "80", "-o", "look.png", "--quiet"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(pngSize(work_ / "look.png"), std::make_pair(80u, 60u));
}

TEST_F(Cli, EveryErrorOfAFileIsReported) {
  const RunResult r = run({"check", (kScenes / "several_errors.yaml").string()});
  EXPECT_EQ(r.status, 2);
  for (const char* where :
       {"several_errors.yaml:10:48:", "several_errors.yaml:11:48:", "several_errors.yaml:13:52:"})
    EXPECT_TRUE(contains(r.err, where)) << "expected " << where << " in:\n" << r.err;
}

TEST_F(Cli, WarningsArePrintedButDoNotChangeTheExitStatus) {
  const std::string scene = (kScenes / "zero_light.yaml").string();
  RunResult r = run({"render", scene, "-o", "out.png"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "zero_light.yaml:12:5: warning: ")) << r.err;
  EXPECT_TRUE(contains(r.err, "intensity")) << r.err;
  EXPECT_TRUE(pngSize(work_ / "out.png").has_value());
  r = run({"check", scene});
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.err, "zero_light.yaml:12:5: warning: ")) << r.err;
  r = run({"render", scene, "-o", "out.png", "--quiet"});
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.err, "") << "--quiet prints errors only";
}

// A file of many warnings prints the first 100 and how many more, not one line each (400,000
// collinear NFF polygons printed 39 MB).
TEST_F(Cli, WarningsPastAHundredAreCounted) {
  std::string nff =
      "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n"
      "l 0 5 5\nf 1 1 1 1 0 0 0 0\n";
  for (int i = 0; i < 150; ++i) nff += "p 3\n0 0 0\n1 1 1\n2 2 2\n";
  writeFile(work_ / "collinear.nff", nff);
  const RunResult r = run({"check", "collinear.nff"});
  EXPECT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.err);
  std::vector<std::string> shown;
  for (std::string line; std::getline(lines, line);) shown.push_back(line);
  ASSERT_EQ(shown.size(), 101u) << r.err;
  EXPECT_EQ(shown[0],
            "collinear.nff:10:1: warning: p: the polygon's vertices are collinear (no "
            "area); it is left out");
  EXPECT_EQ(shown[100], "glint: 50 more warnings not shown");
}

// --- output files are never broken ----------------------------------------------------------

TEST_F(Cli, ExistingOutputIsUntouchedAfterABadScene) {
  const std::string precious = "not an image, but mine\n";
  writeFile(work_ / "out.png", precious);
  const RunResult r = run({"render", (kBroken / "negative_radius.yaml").string(), "-o", "out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(readFile(work_ / "out.png"), precious);
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"out.png"});
}

TEST_F(Cli, UnknownOutputExtensionExitsTwoAndTouchesNothing) {
  const std::string precious = "BM not really a bitmap\n";
  writeFile(work_ / "out.bmp", precious);
  RunResult r = run({"render", small(), "-o", "out.bmp"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "out.bmp")) << r.err;
  EXPECT_TRUE(contains(r.err, ".png")) << "should say which formats exist: " << r.err;
  EXPECT_EQ(readFile(work_ / "out.bmp"), precious);
  r = run({"render", small(), "-o", "out"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"out.bmp"});
}

TEST_F(Cli, MissingOutputFolderExitsTwo) {
  const RunResult r = run({"render", small(), "-o", "no-such-folder/out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "no-such-folder")) << r.err;
  EXPECT_TRUE(filesIn(work_).empty());
}

// OpenEXR is a module (glint-exr.so, beside glint in the build tree) loaded on demand: when it
// cannot be loaded, an EXR output fails before the render, and an EXR texture is refused at its
// line; other outputs do not need it.
TEST_F(Cli, AnExrModuleThatCannotLoadFailsBeforeTheRender) {
  const std::string missing = (work_ / "no-such-module.so").string();
  ASSERT_EQ(::setenv("GLINT_EXR_MODULE", missing.c_str(), 1), 0);
  const RunResult exr = run({"render", small(), "-o", "out.exr"});
  const RunResult png = run({"render", small(), "-o", "out.png", "--quiet"});
  ::unsetenv("GLINT_EXR_MODULE");
  EXPECT_EQ(exr.status, 1) << exr.err;
  EXPECT_TRUE(contains(exr.err, "cannot write 'out.exr': cannot load " + missing)) << exr.err;
  EXPECT_FALSE(contains(exr.err, "%")) << "it rendered first: " << exr.err;
  EXPECT_FALSE(fs::exists(work_ / "out.exr"));
  EXPECT_EQ(png.status, 0) << png.err;
  EXPECT_TRUE(fs::exists(work_ / "out.png"));

  // An EXR texture: read through the module when it is there, refused at its line when not.
  ASSERT_EQ(run({"render", small(), "-o", "texture.exr", "--quiet"}).status, 0);
  writeFile(work_ / "textured.yaml",
            "name: textured\n"
            "camera: { position: [0, 0, 3], look_at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
            "image: { width: 16, height: 12 }\n"
            "textures:\n"
            "  picture: { type: image, file: texture.exr }\n"
            "objects:\n"
            "  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: picture } }\n"
            "lights:\n"
            "  - { type: point, position: [2, 2, 3], color: [1, 1, 1], intensity: 1 }\n");
  EXPECT_EQ(run({"render", "textured.yaml", "-o", "textured.png", "--quiet"}).status, 0);
  ASSERT_EQ(::setenv("GLINT_EXR_MODULE", missing.c_str(), 1), 0);
  const RunResult texture = run({"render", "textured.yaml", "-o", "refused.png"});
  ::unsetenv("GLINT_EXR_MODULE");
  EXPECT_EQ(texture.status, 2) << texture.err;
  EXPECT_TRUE(contains(texture.err, "textured.yaml:5:")) << texture.err;
  EXPECT_TRUE(contains(texture.err, "cannot read EXR files: cannot load " + missing +
                                        ": cannot open shared object file"))
      << texture.err;
  EXPECT_FALSE(fs::exists(work_ / "refused.png"));
}

// An image texture the scene reads is an input too: writing the image over it is refused before
// the render, and the texture is left as it was.
TEST_F(Cli, AnOutputThatIsATextureOfTheSceneIsRefused) {
  fs::copy_file(fs::path(GLINT_SOURCE_DIR) / "scenes" / "textures" / "uv_grid.png",
                work_ / "tex.png");
  const std::string texture = readFile(work_ / "tex.png");
  writeFile(work_ / "own.yaml",
            "image: {width: 16, height: 12}\ncamera: {position: [0, 0, 3], look_at: [0, 0, 0], "
            "fov: 40}\nambient: {intensity: 1}\nobjects:\n  - {type: sphere, center: [0, 0, 0], "
            "radius: 1, material: {ka: {type: image, file: tex.png}}}\n");
  const RunResult r = run({"render", (work_ / "own.yaml").string(), "-o", "tex.png"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "cannot write 'tex.png': the scene reads it")) << r.err;
  EXPECT_FALSE(contains(r.err, "%")) << "it rendered first: " << r.err;
  EXPECT_EQ(readFile(work_ / "tex.png"), texture);
}

// Output paths no image can be written to are wrong arguments (exit 2), refused before the render.
TEST_F(Cli, OutputPathsThatCannotBeAFileExitTwo) {
  fs::create_directory(work_ / "out.png");
  RunResult r = run({"render", small(), "-o", "out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "cannot write 'out.png': it is a folder")) << r.err;
  EXPECT_TRUE(fs::is_empty(work_ / "out.png"));
  // A folder is a folder whatever its name: not "the name has no extension".
  fs::create_directory(work_ / "renders");
  r = run({"render", small(), "-o", "renders"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "cannot write 'renders': it is a folder")) << r.err;
  writeFile(work_ / "file", "precious");
  r = run({"render", small(), "-o", "file/out.png"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "cannot write 'file/out.png': 'file' is not a folder")) << r.err;
  const std::string longName = std::string(300, 'a') + ".png";
  r = run({"render", small(), "-o", longName});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "the file name is 304 bytes long, longer than the 255")) << r.err;
  EXPECT_FALSE(contains(r.err, "%")) << "it rendered first: " << r.err;
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"file", "out.png", "renders"}));
  EXPECT_EQ(readFile(work_ / "file"), "precious");
}

// An image past the file-size limit (ulimit -f) fails its write (exit 1) rather than being killed
// by SIGXFSZ, and removes its temporary file.
TEST_F(Cli, AnImagePastTheFileSizeLimitIsAWriteFailureThatLeavesNoFile) {
  rlimit previous{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &previous), 0);
  rlimit limited = previous;
  limited.rlim_cur = 4096;  // bytes; the 200×150 PPM is 90,015, the EXR larger still
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  const RunResult r = run({"render", small(), "--width", "200", "-o", "out.ppm", "--quiet"});
  const RunResult exr = run({"render", small(), "--width", "200", "-o", "out.exr", "--quiet"});
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &previous), 0);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(contains(r.err, "cannot write 'out.ppm': write error: File too large")) << r.err;
  // In the system's words, as for the other formats: not OpenEXR's, which name the temporary file.
  EXPECT_EQ(exr.status, 1) << exr.err;
  EXPECT_TRUE(contains(exr.err, "cannot write 'out.exr': write error: File too large\n"))
      << exr.err;
  EXPECT_FALSE(contains(exr.err, "glint-tmp")) << exr.err;
  EXPECT_TRUE(filesIn(work_).empty()) << "a temporary file was left behind";
}

// --- overrides ------------------------------------------------------------------------------

TEST_F(Cli, WidthOrHeightAloneKeepsTheAspect) {
  struct Case {
    std::vector<std::string> options;
    std::uint32_t width, height;
  };
  const std::vector<Case> cases{{{"--width", "64"}, 64, 48},
                                {{"--height", "12"}, 16, 12},
                                {{"--width", "10"}, 10, 8},  // 7.5 rounds to 8
                                {{"--width", "1"}, 1, 1},    // 0.75 rounds to 1
                                {{"--width", "20", "--height", "30"}, 20, 30}};
  for (const Case& c : cases) {
    std::vector<std::string> args{"render", small(), "-o", "out.png", "--quiet", "--samples", "1"};
    args.insert(args.end(), c.options.begin(), c.options.end());
    ASSERT_EQ(run(args).status, 0);
    const auto size = pngSize(work_ / "out.png");
    ASSERT_TRUE(size.has_value());
    EXPECT_EQ(size->first, c.width) << c.options[0] << " " << c.options[1];
    EXPECT_EQ(size->second, c.height) << c.options[0] << " " << c.options[1];
  }
}

TEST_F(Cli, CropsStitchedTogetherEqualTheFullImageByteForByte) {
  ASSERT_EQ(run({"render", small(), "-o", "full.ppm", "--quiet"}).status, 0);
  const Ppm full = readPpm(work_ / "full.ppm");
  ASSERT_EQ(full.width, 32);
  ASSERT_EQ(full.height, 24);
  // Split off the 16-pixel tile grid on purpose: 13 and 10 are not tile boundaries.
  struct Quadrant {
    int x0, y0, x1, y1;
  };
  const std::vector<Quadrant> quadrants{
      {0, 0, 13, 10}, {13, 0, 32, 10}, {0, 10, 13, 24}, {13, 10, 32, 24}};
  std::string stitched(full.rgb.size(), '\0');
  for (const Quadrant& q : quadrants) {
    const std::string crop = std::to_string(q.x0) + "," + std::to_string(q.y0) + "," +
                             std::to_string(q.x1) + "," + std::to_string(q.y1);
    ASSERT_EQ(run({"render", small(), "-o", "crop.ppm", "--quiet", "--crop", crop}).status, 0);
    const Ppm part = readPpm(work_ / "crop.ppm");
    ASSERT_EQ(part.width, q.x1 - q.x0) << crop;
    ASSERT_EQ(part.height, q.y1 - q.y0) << crop;
    ASSERT_EQ(part.rgb.size(), static_cast<std::size_t>(part.width * part.height * 3));
    for (int y = 0; y < part.height; ++y)
      stitched.replace(static_cast<std::size_t>(((q.y0 + y) * full.width + q.x0) * 3),
                       static_cast<std::size_t>(part.width * 3),
                       part.rgb.substr(static_cast<std::size_t>(y * part.width * 3),
                                       static_cast<std::size_t>(part.width * 3)));
  }
  EXPECT_TRUE(stitched == full.rgb) << "the crops differ from the full render";
}

TEST_F(Cli, MemoryBudgetCountsOnlyTheCropThatIsRendered) {
  // The full 65535-pixel-wide image would not fit in memory; a 32x24 piece of it does.
  RunResult r = run({"render", small(), "-o", "out.png", "--width", "65535", "--samples", "1"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--width 65535")) << r.err;
  r = run({"render", small(), "-o", "out.png", "--width", "65535", "--samples", "1", "--quiet",
           "--crop", "30000,20000,30032,20024"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto size = pngSize(work_ / "out.png");
  ASSERT_TRUE(size.has_value());
  EXPECT_EQ(size->first, 32u);
  EXPECT_EQ(size->second, 24u);
}

TEST_F(Cli, ThreadCountDoesNotChangeTheBytes) {
  ASSERT_EQ(run({"render", small(), "-o", "one.png", "--quiet", "--threads", "1"}).status, 0);
  ASSERT_EQ(run({"render", small(), "-o", "two.png", "--quiet", "--threads", "2"}).status, 0);
  ASSERT_EQ(run({"render", small(), "-o", "all.png", "--quiet"}).status, 0);
  const std::string one = readFile(work_ / "one.png");
  EXPECT_FALSE(one.empty());
  EXPECT_TRUE(one == readFile(work_ / "two.png"));
  EXPECT_TRUE(one == readFile(work_ / "all.png"));
}

TEST_F(Cli, SeedReplacesTheScenesSeed) {
  // small.yaml has render.seed 7 and glossy reflections, so the seed shows in the pixels.
  ASSERT_EQ(run({"render", small(), "-o", "scene.ppm", "--quiet"}).status, 0);
  ASSERT_EQ(run({"render", small(), "-o", "seven.ppm", "--quiet", "--seed", "7"}).status, 0);
  ASSERT_EQ(run({"render", small(), "-o", "eight.ppm", "--quiet", "--seed", "8"}).status, 0);
  const std::string scene = readFile(work_ / "scene.ppm");
  EXPECT_TRUE(scene == readFile(work_ / "seven.ppm"));
  EXPECT_FALSE(scene == readFile(work_ / "eight.ppm"));
}

TEST_F(Cli, IntegratorReplacesTheScenesIntegrator) {
  // small.yaml renders with Whitted's model (it names no integrator); --integrator whitted keeps
  // the bytes, --integrator path changes them (no ambient term, indirect light) and says so.
  ASSERT_EQ(run({"render", small(), "-o", "scene.ppm", "--quiet"}).status, 0);
  ASSERT_EQ(
      run({"render", small(), "-o", "whitted.ppm", "--quiet", "--integrator", "whitted"}).status,
      0);
  const RunResult path =
      run({"render", small(), "-o", "path.ppm", "--stats", "--integrator", "path"});
  ASSERT_EQ(path.status, 0) << path.err;
  EXPECT_TRUE(contains(path.err, "path integrator")) << path.err;
  EXPECT_TRUE(contains(path.err, " indirect")) << path.err;
  const std::string scene = readFile(work_ / "scene.ppm");
  EXPECT_TRUE(scene == readFile(work_ / "whitted.ppm"));
  EXPECT_FALSE(scene == readFile(work_ / "path.ppm"));
}

TEST_F(Cli, SamplesOverrideChangesTheImage) {
  ASSERT_EQ(run({"render", small(), "-o", "four.ppm", "--quiet"}).status, 0);
  ASSERT_EQ(run({"render", small(), "-o", "one.ppm", "--quiet", "--samples", "1"}).status, 0);
  EXPECT_FALSE(readFile(work_ / "four.ppm") == readFile(work_ / "one.ppm"));
}

// --- signals --------------------------------------------------------------------------------

TEST_F(Cli, SigintStopsTheRenderWith130AndWritesNothing) {
  const RunResult r = interruptHeavyRender(SIGINT);
  EXPECT_EQ(r.status, 130) << r.err;
  EXPECT_TRUE(contains(r.err, "glint: interrupted")) << r.err;
  EXPECT_TRUE(filesIn(work_).empty()) << "an output or temporary file was left";
}

TEST_F(Cli, SecondSigintEndsTheRenderAtOnceAndWritesNothing) {
  const pid_t pid = start({"render", (kScenes / "heavy.yaml").string(), "-o", "out.png"});
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!catchesSignal(pid, SIGINT) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(2ms);
  std::this_thread::sleep_for(300ms);
  kill(pid, SIGINT);
  std::this_thread::sleep_for(300ms);  // past the 250 ms within which a repeat is the same request
  kill(pid, SIGINT);
  const RunResult r = finish(pid, 30s);
  EXPECT_EQ(r.status, 130) << r.err;
  EXPECT_TRUE(contains(r.err, "glint: interrupted")) << r.err;
  EXPECT_TRUE(filesIn(work_).empty());
}

// GNU timeout sends its signal to the command and then to the whole process group: the same
// signal twice within microseconds is one request, and the checkpoint is still saved.
TEST_F(Cli, TheSameSignalTwiceAtOnceIsOneRequestAndTheCheckpointIsSaved) {
  const pid_t pid = start(
      {"render", (kScenes / "heavy.yaml").string(), "-o", "out.png", "--checkpoint", "run.ckpt"});
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!catchesSignal(pid, SIGINT) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(2ms);
  std::this_thread::sleep_for(300ms);
  kill(pid, SIGINT);
  kill(pid, SIGINT);
  const RunResult r = finish(pid, 30s);
  EXPECT_EQ(r.status, 130) << r.err;
  EXPECT_TRUE(contains(r.err, "tiles saved to 'run.ckpt'")) << r.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"run.ckpt"});
}

TEST_F(Cli, SigtermStopsTheRenderWith143AndKeepsTheExistingOutput) {
  const std::string precious = "the previous image\n";
  writeFile(work_ / "out.png", precious);
  const RunResult r = interruptHeavyRender(SIGTERM, {"--quiet"});
  EXPECT_EQ(r.status, 143) << r.err;
  EXPECT_EQ(readFile(work_ / "out.png"), precious);
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"out.png"});
}

// --- progress and summary -------------------------------------------------------------------

TEST_F(Cli, ProgressIsPlainPercentLinesWhenNotATerminal) {
  // 96x72 pixels: several tiles for any sensible tile size, so several progress steps.
  const RunResult r = run({"render", small(), "-o", "out.png", "--width", "96"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::regex line(R"(glint: (\d+)% \(elapsed [0-9.]+ s, ETA (--|[0-9.]+ s)\))");
  int lines = 0, last = -1;
  std::istringstream in(r.err);
  for (std::string text; std::getline(in, text);) {
    std::smatch m;
    if (!std::regex_match(text, m, line)) continue;
    const int percent = std::stoi(m[1]);
    EXPECT_GT(percent, last) << "percentages go up";
    last = percent;
    ++lines;
  }
  EXPECT_GE(lines, 2) << r.err;
  EXPECT_EQ(last, 100) << r.err;
  EXPECT_FALSE(contains(r.err, "\r")) << "no terminal control characters in logs";
  // The summary: time, rays by kind, Mrays/s.
  for (const char* part : {"camera", "shadow", "reflection", "refraction", "Mrays/s", "out.png"})
    EXPECT_TRUE(contains(r.err, part)) << part << " missing in:\n" << r.err;
  EXPECT_FALSE(contains(r.err, "non-finite")) << "details only with --stats";
}

TEST_F(Cli, QuietPrintsNothingOnSuccess) {
  const RunResult r = run({"render", small(), "-o", "out.png", "--quiet"});
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, "");
  EXPECT_TRUE(fs::exists(work_ / "out.png"));
}

TEST_F(Cli, QuietStillPrintsErrors) {
  const RunResult r = run({"render", (kBroken / "negative_radius.yaml").string(), "--quiet"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "negative_radius.yaml:12:13")) << r.err;
}

TEST_F(Cli, StatsAddsDetails) {
  const RunResult r = run({"render", small(), "-o", "out.png", "--stats", "--threads", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"4 primitives", "0 meshes (0 triangles)", "4 samples per pixel",
                           "2 threads", "non-finite samples: 0"})
    EXPECT_TRUE(contains(r.err, part)) << part << " missing in:\n" << r.err;
  // The meshes are counted too (a scene of mesh files is not "1 primitive").
  const RunResult meshes =
      run({"render", (fs::path(GLINT_SOURCE_DIR) / "scenes/mesh.yaml").string(), "-o", "mesh.png",
           "--width", "32", "--stats"});
  ASSERT_EQ(meshes.status, 0) << meshes.err;
  EXPECT_TRUE(contains(meshes.err, "2 meshes (76800 triangles)")) << meshes.err;
}

// --isa and GLINT_ISA (core/isa.h): the instruction set of the BVH queries, shown by --stats; a
// bad name or an ISA this processor lacks exits 2 before anything is written.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value, 1);
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;
  ~ScopedEnvironment() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST_F(Cli, IsaIsChosenByOptionOrEnvironmentAndShownByStats) {
  const glint::IsaSupport here = glint::isaSupportHere();
  const std::string best(glint::isaName(glint::bestIsa(here)));
  RunResult r = run({"render", small(), "-o", "auto.png", "--stats", "--isa", "auto"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "glint: isa: " + best + " ")) << r.err;
  for (const glint::Isa isa : glint::kAllIsas) {
    if (!here.runs(isa)) continue;
    const std::string name(glint::isaName(isa));
    r = run({"render", small(), "-o", name + ".png", "--stats", "--isa", name});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "glint: isa: " + name + " ")) << r.err;
    EXPECT_EQ(readFile(work_ / (name + ".png")), readFile(work_ / "auto.png")) << name;
    const ScopedEnvironment forced("GLINT_ISA", name.c_str());
    r = run({"render", small(), "-o", "env.png", "--stats"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "glint: isa: " + name + " ")) << r.err;
  }
}

TEST_F(Cli, AnIsaThatCannotRunExitsTwoAndWritesNothing) {
  RunResult r = run({"render", small(), "-o", "out.png", "--isa", "sse9"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--isa expects baseline, avx2, avx512 or auto, got 'sse9'")) << r.err;
  {
    const ScopedEnvironment forced("GLINT_ISA", "avx1024");
    r = run({"render", small(), "-o", "out.png"});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, "GLINT_ISA expects baseline, avx2, avx512 or auto")) << r.err;
  }
  const glint::IsaSupport here = glint::isaSupportHere();
  for (const glint::Isa isa : glint::kAllIsas) {
    if (here.runs(isa)) continue;  // on this processor; the refusal itself: core/isa_test.cpp
    const std::string name(glint::isaName(isa));
    r = run({"render", small(), "-o", "out.png", "--isa", name});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, "--isa " + name + ": this")) << r.err;
  }
  EXPECT_TRUE(filesIn(work_).empty());
}

TEST_F(Cli, ProgressIsABarRedrawnInPlaceOnATerminal) {
  const RunResult r = runOnTerminal({"render", small(), "-o", "out.png"});
  const std::string& err = r.err;
  EXPECT_EQ(r.status, 0) << err;
  EXPECT_TRUE(contains(err, "\rglint: [")) << err;
  EXPECT_TRUE(contains(err, "100%")) << err;
  EXPECT_FALSE(std::regex_search(err, std::regex("glint: [0-9]+% \\(elapsed"))) << "no log lines";
  EXPECT_TRUE(contains(err, "ETA")) << err;
  EXPECT_TRUE(contains(err, "Mrays/s")) << err;
}

// Progress and the summary are only messages: a full or closed stderr loses them, not the image.
TEST_F(Cli, AStderrThatCannotBeWrittenDoesNotFailTheRender) {
  // /dev/full: every write fails with ENOSPC; a read-only descriptor: with EBADF, as a closed one.
  for (const bool full : {true, false}) {
    const int outFd = open("/dev/null", O_WRONLY);
    const int errFd = full ? open("/dev/full", O_WRONLY) : open("/dev/null", O_RDONLY);
    ASSERT_GE(outFd, 0);
    ASSERT_GE(errFd, 0);
    const pid_t pid = fork();
    if (pid == 0) execGlint({"render", small(), "-o", "out.png"}, work_, outFd, errFd);
    close(outFd);
    close(errFd);
    EXPECT_EQ(waitFor(pid, 60s), 0) << (full ? "/dev/full" : "read-only");
    EXPECT_TRUE(pngSize(work_ / "out.png").has_value()) << (full ? "/dev/full" : "read-only");
    fs::remove(work_ / "out.png");
  }
}

// A bar line as wide as the terminal would wrap, and then every redraw ('\r' goes back to the
// start of the last row only) would add a row: each drawing of the bar stays narrower than the
// terminal, the bar's cells going first.
TEST_F(Cli, TheProgressBarFitsANarrowTerminal) {
  for (const int columns : {80, 40, 12}) {
    const RunResult r =
        runOnTerminal({"render", small(), "-o", "out.png"}, static_cast<unsigned short>(columns));
    EXPECT_EQ(r.status, 0) << r.err;
    // The bar's drawings: from each '\r' to the next '\r' or '\n'.
    std::size_t drawings = 0;
    for (std::size_t at = r.err.find('\r'); at != std::string::npos; at = r.err.find('\r', at)) {
      ++at;
      const std::size_t end = r.err.find_first_of("\r\n", at);
      const std::size_t length = (end == std::string::npos ? r.err.size() : end) - at;
      EXPECT_LT(length, static_cast<std::size_t>(columns))
          << columns << " columns: '" << r.err.substr(at, length) << "'";
      ++drawings;
    }
    EXPECT_GE(drawings, 2u) << r.err;
    if (columns == 80) {
      EXPECT_TRUE(contains(r.err, "\rglint: [")) << "a bar at 80 columns: " << r.err;
    }
    if (columns == 40) {
      EXPECT_TRUE(contains(r.err, "100%  elapsed")) << r.err;
    }
  }
}

// --- memory budget ------------------------------------------------------------------------

TEST_F(Cli, MaxMemoryAcceptsUnitsAndRefusesTooSmallABudget) {
  // small.yaml's film: 32 × 24 pixels × 24 bytes = 18 KiB.
  for (const char* size : {"1G", "1.5GiB", "512M", "4g", "19K", "100000", "20kb", "1 MiB"}) {
    const RunResult r = run({"render", small(), "-o", "out.png", "--quiet", "--max-memory", size});
    EXPECT_EQ(r.status, 0) << size << ": " << r.err;
  }
  // The scene's own image is refused by the loader, at the image's place in the file.
  RunResult r = run({"render", small(), "-o", "small.png", "--max-memory", "10K"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "small.yaml:13:3")) << r.err;
  EXPECT_TRUE(contains(r.err, "needs 18.0 KiB")) << r.err;
  EXPECT_TRUE(contains(r.err, "memory budget of 10.0 KiB")) << r.err;
  // An image enlarged on the command line is refused by the command line, naming the options.
  r = run({"render", small(), "-o", "small.png", "--max-memory", "30K", "--width", "64"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "--width 64 --max-memory 30K refused")) << r.err;
  EXPECT_TRUE(contains(r.err, "needs 72.0 KiB")) << r.err;
  EXPECT_TRUE(contains(r.err, "memory budget of 30.0 KiB")) << r.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"out.png"});
}

TEST_F(Cli, TexturesCountAgainstTheMemoryBudgetBeforeTheyAreDecoded) {
  // scenes/textures.yaml's sky is a 1024 × 512 HDR: 8.4 MB as a float mip-map, estimated from its
  // header. At 96 pixels wide the film is small; with the named textures before it (3.1 MiB) the
  // sky does not fit in 4 MB.
  const std::string scene = (fs::path(GLINT_SOURCE_DIR) / "scenes/textures.yaml").string();
  const RunResult r =
      run({"render", scene, "-o", "out.png", "--width", "96", "--max-memory", "4M"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "textures.yaml:9:")) << r.err;
  EXPECT_TRUE(contains(r.err, "cannot load texture file 'textures/sky.hdr'")) << r.err;
  EXPECT_TRUE(contains(r.err, "HDR 1024×512 image needs about 8.0 MiB")) << r.err;
  EXPECT_TRUE(contains(r.err, "more than the memory limit of 4.0 MiB")) << r.err;
  EXPECT_TRUE(filesIn(work_).empty());
  // check reports the same refusals as render, with the same limit.
  const RunResult checked = run({"check", scene, "--max-memory", "4M"});
  EXPECT_EQ(checked.status, 2);
  EXPECT_TRUE(contains(checked.err, "cannot load texture file 'textures/sky.hdr'")) << checked.err;
  EXPECT_TRUE(contains(checked.err, "more than the memory limit of 4.0 MiB")) << checked.err;
  EXPECT_EQ(run({"check", scene, "--max-memory", "64M"}).status, 0);
}

TEST_F(Cli, MaxMemoryWithABadSizeIsAnArgumentError) {
  for (const char* size : {"abc", "0", "-5", "12Q", "1.5.2G", "", "G", "0.1", "99999999999T"}) {
    const RunResult r = run({"render", small(), "-o", "out.png", "--max-memory", size});
    EXPECT_EQ(r.status, 2) << size;
    EXPECT_TRUE(contains(r.err, "--max-memory")) << size << ": " << r.err;
  }
  // A fraction of a byte is a unit left out, not 2 bytes.
  const RunResult fraction = run({"render", small(), "-o", "out.png", "--max-memory", "2.5"});
  EXPECT_EQ(fraction.status, 2);
  EXPECT_TRUE(contains(fraction.err,
                       "--max-memory 2.5: a number of bytes must be whole (a size "
                       "with a unit may have a fraction: 2.5G, 2.5M)"))
      << fraction.err;
  EXPECT_TRUE(filesIn(work_).empty());
}

TEST_F(Cli, CheckpointCopiesCountAgainstTheMemoryBudget) {
  // 18 KiB fits in 30 KiB, the film and its checkpoint copy (36 KiB) do not.
  ASSERT_EQ(run({"render", small(), "-o", "out.png", "--quiet", "--max-memory", "30K"}).status, 0);
  const RunResult r =
      run({"render", small(), "-o", "out.png", "--max-memory", "30K", "--checkpoint", "run.ckpt"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "for checkpointing")) << r.err;
}

// --- checkpoint and resume ------------------------------------------------------------------

class CliCheckpoint : public Cli {
 protected:
  // small.yaml at 128x96 (48 tiles): long enough to interrupt, short enough for a test.
  std::vector<std::string> renderArgs(const std::vector<std::string>& extra) const {
    std::vector<std::string> args{"render", scene(), "--width", "128"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  std::string scene() const { return (work_ / "scene.yaml").string(); }
  void SetUp() override {
    Cli::SetUp();
    fs::copy_file(kScenes / "small.yaml", work_ / "scene.yaml");
  }

  // Starts a render with --checkpoint, sends SIGINT once it has reported progress (some tiles
  // done), and returns how it ended.
  RunResult interruptedRender(const std::vector<std::string>& extra) {
    const pid_t pid = start(renderArgs(extra));
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    std::string err;
    while (std::chrono::steady_clock::now() < deadline) {
      err = readFile(root_ / "capture" / "stderr");
      if (std::regex_search(err, std::regex(R"(glint: [1-9][0-9]?% )"))) break;
      std::this_thread::sleep_for(1ms);
    }
    kill(pid, SIGINT);
    return finish(pid, 30s);
  }
};

TEST_F(CliCheckpoint, SigintSavesACheckpointAndResumeGivesTheSameBytes) {
  ASSERT_EQ(run(renderArgs({"-o", "reference.ppm", "--quiet"})).status, 0);
  const RunResult stopped =
      interruptedRender({"-o", "out.ppm", "--checkpoint", "run.ckpt", "--threads", "1"});
  ASSERT_EQ(stopped.status, 130) << "the render ended before the signal?\n" << stopped.err;
  const std::regex saved(R"(glint: interrupted; (\d+) of 48 tiles saved to 'run.ckpt')");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stopped.err, m, saved)) << stopped.err;
  const int tilesSaved = std::stoi(m[1]);
  EXPECT_GT(tilesSaved, 0);
  EXPECT_LT(tilesSaved, 48);
  EXPECT_TRUE(contains(stopped.err, "--resume run.ckpt")) << stopped.err;
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"reference.ppm", "run.ckpt", "scene.yaml"}))
      << "no partial image, no temporary file";
  EXPECT_EQ(readFile(work_ / "run.ckpt").substr(0, 8), "GLINTCKP");

  // A resumed render keeps checkpointing into the same file, so it can be interrupted again.
  const RunResult again = interruptedRender({"-o", "out.ppm", "--resume", "run.ckpt"});
  ASSERT_EQ(again.status, 130) << again.err;
  ASSERT_TRUE(std::regex_search(again.err, m, saved)) << again.err;
  const int tilesSavedAgain = std::stoi(m[1]);
  EXPECT_GE(tilesSavedAgain, tilesSaved);
  EXPECT_FALSE(fs::exists(work_ / "out.ppm"));

  // Resumed on another thread count; the checkpoint goes once the image is written.
  const RunResult resumed = run(renderArgs({"-o", "out.ppm", "--resume", "run.ckpt"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_TRUE(contains(resumed.err,
                       std::to_string(tilesSavedAgain) + " of 48 tiles resumed from 'run.ckpt'"))
      << resumed.err;
  EXPECT_TRUE(readFile(work_ / "out.ppm") == readFile(work_ / "reference.ppm"))
      << "the resumed image differs from the uninterrupted one";
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"out.ppm", "reference.ppm", "scene.yaml"}));
}

TEST_F(CliCheckpoint, ResumeRefusesAMismatchedCorruptOrMissingCheckpoint) {
  const RunResult stopped = interruptedRender({"-o", "out.ppm", "--checkpoint", "run.ckpt"});
  ASSERT_EQ(stopped.status, 130) << stopped.err;
  const std::string checkpoint = readFile(work_ / "run.ckpt");
  ASSERT_FALSE(checkpoint.empty());

  const auto refused = [&](const std::vector<std::string>& extra, const std::string& reason) {
    std::vector<std::string> all{"-o", "out.ppm", "--resume", "run.ckpt"};
    all.insert(all.end(), extra.begin(), extra.end());
    const RunResult r = run(renderArgs(all));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, reason)) << reason << " missing in:\n" << r.err;
    EXPECT_FALSE(fs::exists(work_ / "out.ppm"));
  };
  refused({"--samples", "2"},
          "cannot resume from 'run.ckpt': it was made with samples per "
          "pixel 4, this render has 2");
  refused({"--seed", "8"}, "it was made with seed 7, this render has 8");
  refused({"--integrator", "path"}, "it was made with integrator whitted, this render has path");
  refused({"--crop", "0,0,80,60"}, "region the whole image, this render has --crop 0,0,80,60");
  EXPECT_EQ(readFile(work_ / "run.ckpt"), checkpoint) << "a refused resume keeps the checkpoint";

  // The scene file changed (a comment is enough: the fingerprint covers its bytes).
  writeFile(work_ / "scene.yaml", readFile(kScenes / "small.yaml") + "# changed\n");
  refused({}, "the scene file");
  fs::copy_file(kScenes / "small.yaml", work_ / "scene.yaml", fs::copy_options::overwrite_existing);

  writeFile(work_ / "run.ckpt", checkpoint.substr(0, checkpoint.size() / 2));
  refused({}, "cannot resume: checkpoint 'run.ckpt' is ");
  std::string flipped = checkpoint;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 4);
  writeFile(work_ / "run.ckpt", flipped);
  refused({}, "checksum");
  writeFile(work_ / "run.ckpt", "P6\n1 1\n255\nabc");
  refused({}, "'run.ckpt' is not a glint checkpoint");
  fs::remove(work_ / "run.ckpt");
  refused({}, "'run.ckpt': no such file");
}

TEST_F(CliCheckpoint, AFailedImageWriteKeepsTheFinishedRenderInTheCheckpoint) {
  fs::create_directory(work_ / "images");
  const pid_t pid = start(renderArgs({"-o", "images/out.ppm", "--checkpoint", "run.ckpt"}));
  // The output folder disappears while the render runs: writing the image fails (exit 1).
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!contains(readFile(root_ / "capture" / "stderr"), "%") &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  fs::remove(work_ / "images");
  const RunResult failed = finish(pid, 30s);
  ASSERT_EQ(failed.status, 1) << failed.err;
  EXPECT_TRUE(contains(failed.err, "the finished render is saved in 'run.ckpt'")) << failed.err;
  fs::create_directory(work_ / "images");
  const RunResult written = run(renderArgs({"-o", "images/out.ppm", "--resume", "run.ckpt"}));
  ASSERT_EQ(written.status, 0) << written.err;
  EXPECT_TRUE(contains(written.err, "48 of 48 tiles resumed from 'run.ckpt'")) << written.err;
  EXPECT_TRUE(contains(written.err, "rays: 0 camera")) << "nothing rendered again: " << written.err;
  EXPECT_FALSE(fs::exists(work_ / "run.ckpt"));
  EXPECT_EQ(readPpm(work_ / "images" / "out.ppm").width, 128);
}

TEST_F(CliCheckpoint, ExistingCheckpointIsNotOverwrittenWithoutResume) {
  writeFile(work_ / "run.ckpt", "GLINTCKP precious work");
  const RunResult r = run(renderArgs({"-o", "out.ppm", "--checkpoint", "run.ckpt"}));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "already exists; continue it with --resume run.ckpt")) << r.err;
  EXPECT_EQ(readFile(work_ / "run.ckpt"), "GLINTCKP precious work");
  EXPECT_FALSE(fs::exists(work_ / "out.ppm"));
  // Another file in the way (notes, a scene, an image) is not offered for --resume.
  writeFile(work_ / "notes.txt", "precious work");
  const RunResult other = run(renderArgs({"-o", "out.ppm", "--checkpoint", "notes.txt"}));
  EXPECT_EQ(other.status, 2);
  EXPECT_TRUE(contains(other.err,
                       "cannot write checkpoint 'notes.txt': the file exists and is not "
                       "a glint checkpoint; choose another --checkpoint path"))
      << other.err;
  EXPECT_FALSE(contains(other.err, "--resume")) << other.err;
  EXPECT_EQ(readFile(work_ / "notes.txt"), "precious work");
  EXPECT_FALSE(fs::exists(work_ / "out.ppm"));
  // Nor can the checkpoint be the output image.
  const RunResult same = run(renderArgs({"-o", "out.ppm", "--checkpoint", "out.ppm"}));
  EXPECT_EQ(same.status, 2);
  EXPECT_TRUE(contains(same.err, "cannot be the output image")) << same.err;
}

TEST_F(CliCheckpoint, FinishedRenderLeavesNoCheckpoint) {
  const RunResult r = run({"render", small(), "-o", "out.png", "--checkpoint", "run.ckpt"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"out.png", "scene.yaml"}));
  const RunResult missingFolder =
      run({"render", small(), "-o", "out.png", "--checkpoint", "nowhere/run.ckpt"});
  EXPECT_EQ(missingFolder.status, 2);
  EXPECT_TRUE(contains(missingFolder.err, "the folder 'nowhere' does not exist"))
      << missingFolder.err;
}

TEST_F(Cli, CheckCountsAreaLights) {
  std::string text = readFile(kScenes / "small.yaml");
  text +=
      "  - { type: area, shape: disk, center: [0, 3, 0], normal: [0, -1, 0], radius: 0.5,\n"
      "      color: [1, 1, 1], intensity: 2, samples: 4 }\n";
  writeFile(root_ / "area.yaml", text);
  const RunResult r = run({"check", (root_ / "area.yaml").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "lights:    3 (1 area) + ambient")) << r.out;
}

TEST_F(Cli, NonFiniteSamplesAreCountedWithTheirFirstPixel) {
  // Two lights of 1.7e308 each: their sum overflows to infinity wherever both reach a surface.
  std::string text = readFile(kScenes / "small.yaml");
  for (const std::string intensity : {"intensity: 1.2 }", "intensity: 0.4 }"}) {
    ASSERT_NE(text.find(intensity), std::string::npos);
    text.replace(text.find(intensity), intensity.size(), "intensity: 1.7e308 }");
  }
  writeFile(root_ / "overflow.yaml", text);
  const std::regex line(
      R"(glint: (\d+) NaN/inf samples replaced by black, first at pixel \((\d+), (\d+)\))");
  std::string first;
  for (const char* threads : {"1", "2"}) {
    const RunResult r = run({"render", (root_ / "overflow.yaml").string(), "-o", "out.png",
                             "--threads", threads, "--stats"});
    ASSERT_EQ(r.status, 0) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.err, m, line)) << r.err;
    EXPECT_GT(std::stoi(m[1]), 0);
    EXPECT_TRUE(contains(r.err, "non-finite samples: " + m[1].str())) << r.err;
    if (first.empty()) first = m[0];
    EXPECT_EQ(m[0], first) << "the count and first pixel do not depend on the thread count";
  }
  const RunResult plain = run({"render", small(), "-o", "out.png"});
  EXPECT_FALSE(contains(plain.err, "NaN")) << plain.err;
}

// --- adaptive sampling in the summaries --------------------------------------------------------

TEST_F(Cli, AdaptiveSamplingIsReportedAndSamplesRaisesItsMaximum) {
  std::string text = readFile(kScenes / "small.yaml");
  const std::string fixed = "  samples: 4\n";
  ASSERT_NE(text.find(fixed), std::string::npos);
  text.replace(text.find(fixed), fixed.size(),
               fixed + "  adaptive: { max_samples: 8, threshold: 0.05 }\n");
  writeFile(root_ / "adaptive.yaml", text);
  const std::string scene = (root_ / "adaptive.yaml").string();
  const RunResult check = run({"check", scene});
  if (check.status == 2 && contains(check.err, "adaptive"))
    GTEST_SKIP() << "the scene parser does not read image.adaptive yet:\n" << check.err;
  ASSERT_EQ(check.status, 0) << check.err;
  EXPECT_TRUE(contains(check.out, "32x24, 4 to 8 samples per pixel (adaptive, threshold 0.05)"))
      << check.out;
  EXPECT_TRUE(contains(check.out, "lights:    2 + ambient")) << "no area light: " << check.out;

  RunResult r = run({"render", scene, "-o", "out.png", "--stats"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      r.err, m, std::regex(R"(glint: samples: (\d+) \(([0-9.]+) per pixel on average, 4 to 8\))")))
      << r.err;
  const double average = std::stod(m[2]);
  EXPECT_GE(average, 4.0);
  EXPECT_LE(average, 8.0);
  EXPECT_NEAR(std::stod(m[1]) / (32 * 24), average, 0.01);
  // --samples above max_samples raises the maximum: every pixel takes exactly 16.
  r = run({"render", scene, "-o", "out.png", "--stats", "--samples", "16"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "16 to 16 samples per pixel")) << r.err;
  EXPECT_TRUE(contains(r.err, "glint: samples: 12288 (16.00 per pixel on average")) << r.err;
}

}  // namespace
}  // namespace glint_cli_test
