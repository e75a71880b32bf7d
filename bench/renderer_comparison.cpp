// glint against Tachyon and POV-Ray on the same two scenes (issue 4, bench 2): 1000 reflective
// spheres (10×10×10 grid, kr 0.3) over a diffuse plane, and the 100k-triangle torus (kr 0.3) over
// the plane; 2 point lights, hard shadows, at most 5 surface hits per path, 1024×768. Writes each
// scene as glint YAML (the torus through an OBJ file), a Tachyon .dat and a POV-Ray .pov, runs each
// renderer's command at 1 and 4 samples per pixel on 1 and 2 threads, and prints the median wall
// time of whole runs (start, parse, build, render, write) and the ratios.
//
//   renderer_comparison [--runs N] [--quick] [--out DIR] [--glint PATH] [--only NAMES]
//                       [--generate-only]
//
// How the formats are matched (and where they cannot be):
// - Camera: glint `fov` is vertical; Tachyon's image plane is 1/ZOOM high at distance 1, so
//   ZOOM = 0.5 / tan(fov/2) with ASPECTRATIO 1 (square pixels); POV-Ray's `angle` is horizontal.
//   Tachyon and POV-Ray are left-handed: Tachyon gets the scene mirrored in x (every position,
//   direction and normal), POV-Ray gets `right -x·aspect`, which makes its camera right-handed.
// - Shading: glint kd = Tachyon DIFFUSE × COLOR = POV-Ray diffuse × pigment, likewise the ambient
//   term (white ambient light of intensity 1); kr = Tachyon SPECULAR (its mirror coefficient) =
//   POV-Ray reflection. No Phong highlights anywhere (the three define the exponent differently).
// - Depth: glint max_depth 5 (the primary hit and 4 bounces) = Tachyon RAYDEPTH 5 = POV-Ray
//   max_trace_level 5; glint min_weight 0.001 ≈ POV-Ray adc_bailout 0.001 (0.3⁴ is above both).
// - Samples: glint --samples S (stratified); Tachyon -aasamples S−1 (its centre ray plus S−1
//   jittered ones); POV-Ray +AM1 +A0.0 +R2 -J (non-adaptive supersampling of every pixel that
//   differs from a neighbour, on a 2×2 grid: POV-Ray prints the samples it took, see the logs).
// - Output: linear values, 8-bit PPM for the timed runs (glint `encoding: linear`, POV-Ray
//   File_Gamma=1.0, Tachyon writes linear); one PNG per renderer for looking at; and timed runs
//   writing PNG at 1 sample (each renderer's own PNG writer and compression settings).
// - Floor: an infinite plane in all three. Torus: smooth (interpolated vertex normals) in all
// three.
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "bench_scenes.h"
#include "bench_support.h"

extern char** environ;

namespace glint::bench {
namespace {

namespace fs = std::filesystem;

#ifdef GLINT_CLI_PATH
constexpr const char* kDefaultGlint = GLINT_CLI_PATH;
#else
constexpr const char* kDefaultGlint = "glint";
#endif

struct Surface {
  Color color;           // base colour
  double ambient = 0.1;  // × colour, under a white ambient light of intensity 1
  double diffuse = 0.8;  // × colour
  double reflect = 0;    // mirror coefficient kr
};

struct PointLightSpec {
  Point3 position;
  double intensity = 1;  // white
};

struct ComparisonScene {
  BenchScene geometry;
  std::vector<Surface> sphereSurfaces;  // sphere i uses sphereSurfaces[i % size]
  Surface meshSurface;
  Surface floorSurface;
  std::vector<PointLightSpec> lights;
  Color background{0.05, 0.07, 0.12};
  int maxDepth = 5;
};

ComparisonScene spheresScene() {
  ComparisonScene s;
  s.geometry = makeSpheresScene();
  s.sphereSurfaces = {{{0.85, 0.30, 0.25}, 0.1, 0.7, 0.3},
                      {{0.30, 0.75, 0.35}, 0.1, 0.7, 0.3},
                      {{0.30, 0.40, 0.90}, 0.1, 0.7, 0.3}};
  s.floorSurface = {{0.75, 0.75, 0.70}, 0.1, 0.8, 0};
  s.lights = {{{12, 20, 10}, 0.7}, {{-15, 12, 8}, 0.4}};
  return s;
}

ComparisonScene torusScene() {
  ComparisonScene s;
  s.geometry = makeTorusScene(100000);
  s.meshSurface = {{0.85, 0.55, 0.25}, 0.1, 0.7, 0.3};
  s.floorSurface = {{0.75, 0.75, 0.70}, 0.1, 0.8, 0};
  s.lights = {{{3, 5, 3}, 0.7}, {{-4, 3, 2}, 0.4}};
  return s;
}

// ---------------------------------------------------------------------------------------------
// Writers

std::string num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}
std::string triple(double x, double y, double z, const char* sep = ", ") {
  return num(x) + sep + num(y) + sep + num(z);
}

double verticalFovRadians(const ComparisonScene& s) {
  return s.geometry.camera.fovDegrees * std::numbers::pi / 180;
}

std::string colorTimes(const Color& c, double k) {
  return "[" + triple(c.r * k, c.g * k, c.b * k) + "]";
}

std::string glintMaterial(const Surface& s) {
  return "{ kd: " + colorTimes(s.color, s.diffuse) + ", ka: " + colorTimes(s.color, s.ambient) +
         (s.reflect > 0 ? ", kr: " + num(s.reflect) : "") + " }";
}

void writeGlint(const fs::path& dir, const ComparisonScene& s) {
  const BenchScene& g = s.geometry;
  std::ofstream out(dir / (g.id + ".yaml"));
  out << "# generated by glint bench/renderer_comparison\n";
  out << "name: " << g.name << " (renderer comparison)\n";
  out << "background: [" << triple(s.background.r, s.background.g, s.background.b) << "]\n";
  out << "ambient: { color: [1, 1, 1], intensity: 1 }\n";
  const Point3& p = g.camera.position;
  out << "camera:\n  position: [" << triple(p.x, p.y, p.z) << "]\n  look_at: ["
      << triple(g.lookAt.x, g.lookAt.y, g.lookAt.z)
      << "]\n  up: [0, 1, 0]\n  fov: " << num(g.camera.fovDegrees) << "\n";
  out << "image: { width: " << g.camera.imageWidth << ", height: " << g.camera.imageHeight
      << ", samples: 1, encoding: linear }\n";
  out << "render: { max_depth: " << s.maxDepth << ", min_weight: 0.001 }\n";
  out << "materials:\n  floor: " << glintMaterial(s.floorSurface) << "\n";
  for (std::size_t i = 0; i < s.sphereSurfaces.size(); ++i) {
    out << "  sphere" << i << ": " << glintMaterial(s.sphereSurfaces[i]) << "\n";
  }
  if (g.meshes.size() > 1) out << "  mesh: " << glintMaterial(s.meshSurface) << "\n";
  out << "objects:\n";
  out << "  - { type: plane, point: [" << triple(g.floorCentre.x, g.floorCentre.y, g.floorCentre.z)
      << "], normal: [0, 1, 0], material: floor }\n";
  for (std::size_t i = 0; i < g.spheres.size(); ++i) {
    const SphereSpec& sp = g.spheres[i];
    out << "  - { type: sphere, center: [" << triple(sp.center.x, sp.center.y, sp.center.z)
        << "], radius: " << num(sp.radius) << ", material: sphere" << i % s.sphereSurfaces.size()
        << " }\n";
  }
  // The last mesh is the floor square of the throughput benchmark; the renderers use a plane.
  for (std::size_t m = 0; m + 1 < g.meshes.size(); ++m) {
    const std::string obj = g.id + (m ? std::to_string(m) : "") + ".obj";
    writeObj(dir / obj, g.meshes[m]);
    out << "  - { type: mesh, file: " << obj << ", smooth: true, material: mesh }\n";
  }
  out << "lights:\n";
  for (const PointLightSpec& l : s.lights) {
    out << "  - { type: point, position: [" << triple(l.position.x, l.position.y, l.position.z)
        << "], color: [1, 1, 1], intensity: " << num(l.intensity) << " }\n";
  }
}

// Tachyon is left-handed (right = up × view): the scene is mirrored in x so the image matches.
std::string tx(const Point3& p) { return triple(-p.x, p.y, p.z, " "); }
std::string tx(const Vec3& v) { return triple(-v.x, v.y, v.z, " "); }
std::string tx(const Normal3& n) { return triple(-n.x, n.y, n.z, " "); }

std::string tachyonTexture(const Surface& s) {
  return "AMBIENT " + num(s.ambient) + " DIFFUSE " + num(s.diffuse) + " SPECULAR " +
         num(s.reflect) + " OPACITY 1.0 COLOR " + triple(s.color.r, s.color.g, s.color.b, " ") +
         " TEXFUNC 0";
}

void writeTachyon(const fs::path& dir, const ComparisonScene& s) {
  const BenchScene& g = s.geometry;
  std::ofstream out(dir / (g.id + ".dat"));
  out << "BEGIN_SCENE\n  RESOLUTION " << g.camera.imageWidth << " " << g.camera.imageHeight
      << "\n\n";
  const Vec3 view = normalize(g.lookAt - g.camera.position);
  out << "CAMERA\n  ZOOM " << num(0.5 / std::tan(verticalFovRadians(s) / 2))
      << "\n  ASPECTRATIO 1.0\n  ANTIALIASING 0\n  RAYDEPTH " << s.maxDepth << "\n  CENTER "
      << tx(g.camera.position) << "\n  VIEWDIR " << tx(view) << "\n  UPDIR 0 1 0\nEND_CAMERA\n\n";
  out << "BACKGROUND " << triple(s.background.r, s.background.g, s.background.b, " ") << "\n\n";
  for (const PointLightSpec& l : s.lights) {
    out << "LIGHT CENTER " << tx(l.position) << " RAD 0.0 COLOR "
        << triple(l.intensity, l.intensity, l.intensity, " ") << "\n";
  }
  out << "\nTEXDEF floor " << tachyonTexture(s.floorSurface) << "\n";
  for (std::size_t i = 0; i < s.sphereSurfaces.size(); ++i) {
    out << "TEXDEF sphere" << i << " " << tachyonTexture(s.sphereSurfaces[i]) << "\n";
  }
  if (g.meshes.size() > 1) out << "TEXDEF mesh " << tachyonTexture(s.meshSurface) << "\n";
  out << "\nPLANE CENTER " << tx(g.floorCentre) << " NORMAL 0 1 0 floor\n";
  for (std::size_t i = 0; i < g.spheres.size(); ++i) {
    out << "SPHERE CENTER " << tx(g.spheres[i].center) << " RAD " << num(g.spheres[i].radius)
        << " sphere" << i % s.sphereSurfaces.size() << "\n";
  }
  for (std::size_t m = 0; m + 1 < g.meshes.size(); ++m) {
    const TriangleMesh& mesh = g.meshes[m];
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      // The mirror reverses the winding; Tachyon (normal fixup off) expects the vertex normals
      // on the side the winding gives, so b and c swap places.
      const std::uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 2],
                          c = mesh.indices[3 * t + 1];
      out << "STRI V0 " << tx(mesh.positions[a]) << " V1 " << tx(mesh.positions[b]) << " V2 "
          << tx(mesh.positions[c]) << " N0 " << tx(mesh.normals[a]) << " N1 " << tx(mesh.normals[b])
          << " N2 " << tx(mesh.normals[c]) << " mesh\n";
    }
  }
  out << "\nEND_SCENE\n";
}

std::string pv(const Point3& p) { return "<" + triple(p.x, p.y, p.z) + ">"; }
std::string pv(const Normal3& n) { return "<" + triple(n.x, n.y, n.z) + ">"; }

std::string povTexture(const std::string& name, const Surface& s) {
  return "#declare T_" + name + " = texture { pigment { color rgb <" +
         triple(s.color.r, s.color.g, s.color.b) + "> } finish { ambient " + num(s.ambient) +
         " diffuse " + num(s.diffuse) + (s.reflect > 0 ? " reflection " + num(s.reflect) : "") +
         " } }\n";
}

void writePov(const fs::path& dir, const ComparisonScene& s) {
  const BenchScene& g = s.geometry;
  std::ofstream out(dir / (g.id + ".pov"));
  const double aspect = static_cast<double>(g.camera.imageWidth) / g.camera.imageHeight;
  const double horizontalFov =
      2 * std::atan(aspect * std::tan(verticalFovRadians(s) / 2)) * 180 / std::numbers::pi;
  out << "// generated by glint bench/renderer_comparison\n#version 3.7;\n";
  out << "global_settings { assumed_gamma 1.0 max_trace_level " << s.maxDepth
      << " adc_bailout 0.001 ambient_light rgb <1, 1, 1> }\n";
  out << "background { color rgb <" << triple(s.background.r, s.background.g, s.background.b)
      << "> }\n";
  // right −x: POV-Ray's default is left-handed; this makes the view match glint's.
  out << "camera { perspective location " << pv(g.camera.position) << " up y right -x*"
      << num(aspect) << " angle " << num(horizontalFov) << " look_at " << pv(g.lookAt) << " }\n";
  for (const PointLightSpec& l : s.lights) {
    out << "light_source { " << pv(l.position) << " color rgb <"
        << triple(l.intensity, l.intensity, l.intensity) << "> }\n";
  }
  out << povTexture("floor", s.floorSurface);
  for (std::size_t i = 0; i < s.sphereSurfaces.size(); ++i) {
    out << povTexture("sphere" + std::to_string(i), s.sphereSurfaces[i]);
  }
  if (g.meshes.size() > 1) out << povTexture("mesh", s.meshSurface);
  out << "plane { y, " << num(g.floorCentre.y) << " texture { T_floor } }\n";
  for (std::size_t i = 0; i < g.spheres.size(); ++i) {
    out << "sphere { " << pv(g.spheres[i].center) << ", " << num(g.spheres[i].radius)
        << " texture { T_sphere" << i % s.sphereSurfaces.size() << " } }\n";
  }
  for (std::size_t m = 0; m + 1 < g.meshes.size(); ++m) {
    const TriangleMesh& mesh = g.meshes[m];
    out << "mesh2 {\n  vertex_vectors { " << mesh.positions.size();
    for (const Point3& p : mesh.positions) out << ",\n    " << pv(p);
    out << " }\n  normal_vectors { " << mesh.normals.size();
    for (const Normal3& n : mesh.normals) out << ",\n    " << pv(n);
    out << " }\n  face_indices { " << mesh.triangleCount();
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      out << ",\n    <" << mesh.indices[3 * t] << ", " << mesh.indices[3 * t + 1] << ", "
          << mesh.indices[3 * t + 2] << ">";
    }
    out << " }\n  texture { T_mesh }\n}\n";
  }
}

// ---------------------------------------------------------------------------------------------
// Running

// Finds an executable on PATH (or checks an explicit path); empty when absent.
std::string findProgram(const std::string& name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::string candidate = dir + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

std::string commandLine(const std::vector<std::string>& args) {
  std::string text;
  for (const std::string& a : args) text += (text.empty() ? "" : " ") + a;
  return text;
}

// What one run of a command cost.
struct RunCost {
  double wallSeconds = 0;
  double cpuSeconds = 0;  // the child's user + system time, all its threads
};

// Runs args (stdout and stderr to `log`) in `dir`; exits the benchmark if the command fails, since
// a failed render has no meaningful time.
RunCost runTimed(const std::vector<std::string>& args, const fs::path& dir, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const fs::path previous = fs::current_path();
  fs::current_path(dir);  // POV-Ray and Tachyon resolve relative paths from here
  const Stopwatch watch;
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  int status = 0;
  struct rusage usage {};
  if (spawned == 0) wait4(pid, &status, 0, &usage);
  RunCost cost;
  cost.wallSeconds = watch.seconds();
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  cost.cpuSeconds = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  fs::current_path(previous);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "renderer_comparison: command failed (%s): %s\nsee %s\n",
                 spawned != 0 ? "could not start" : "non-zero exit", commandLine(args).c_str(),
                 log.c_str());
    std::exit(1);
  }
  return cost;
}

// An 8- or 16-bit binary PPM (P6), as all three renderers write it; values scaled to 0..255.
struct PpmImage {
  int width = 0, height = 0;
  std::vector<double> values;  // r, g, b per pixel, row by row
};

bool readPpm(const fs::path& path, PpmImage& image) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int maxValue = 0;
  in >> magic;
  // Header fields may be separated by comments.
  const auto next = [&](int& v) {
    while (in >> std::ws && in.peek() == '#') in.ignore(1 << 20, '\n');
    in >> v;
  };
  next(image.width);
  next(image.height);
  next(maxValue);
  in.get();
  if (!in || magic != "P6" || image.width <= 0 || image.height <= 0 || maxValue <= 0 ||
      maxValue > 65535) {
    return false;
  }
  const std::size_t count = static_cast<std::size_t>(image.width) * image.height * 3;
  const int bytes = maxValue > 255 ? 2 : 1;
  std::vector<unsigned char> raw(count * bytes);
  in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size()));
  if (!in) return false;
  image.values.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    const int v = bytes == 2 ? raw[2 * i] << 8 | raw[2 * i + 1] : raw[i];
    image.values[i] = 255.0 * v / maxValue;
  }
  return true;
}

// How far two renders of the same scene are apart: mean |difference| over all channels (0..255)
// and the share of pixels where some channel differs by more than 16/255.
std::string imageDifference(const fs::path& a, const fs::path& b) {
  PpmImage x, y;
  if (!readPpm(a, x) || !readPpm(b, y)) return "(could not read the images)";
  if (x.width != y.width || x.height != y.height) return "(different sizes)";
  double sum = 0;
  std::size_t differing = 0;
  for (std::size_t p = 0; p < x.values.size(); p += 3) {
    double largest = 0;
    for (std::size_t c = p; c < p + 3; ++c) {
      const double d = std::abs(x.values[c] - y.values[c]);
      sum += d;
      largest = std::max(largest, d);
    }
    differing += largest > 16;
  }
  char text[128];
  std::snprintf(text, sizeof text, "mean |difference| %.2f/255, pixels off by > 16/255: %.2f%%",
                sum / static_cast<double>(x.values.size()),
                300.0 * static_cast<double>(differing) / static_cast<double>(x.values.size()));
  return text;
}

enum class Renderer { Glint, Tachyon, PovRay };
const char* rendererName(Renderer r) {
  return r == Renderer::Glint ? "glint" : (r == Renderer::Tachyon ? "tachyon" : "povray");
}

struct Programs {
  std::string glint, tachyon, povray;
};

// The command for one render; `image` is the output file name (its extension picks the format).
std::vector<std::string> renderCommand(Renderer r, const Programs& programs, const std::string& id,
                                       int samples, int threads, const std::string& image) {
  const std::string t = std::to_string(threads);
  const bool png = image.ends_with(".png");
  switch (r) {
    case Renderer::Glint:
      return {
          programs.glint,          "render", id + ".yaml", "-o", image, "--threads", t, "--samples",
          std::to_string(samples), "--quiet"};
    case Renderer::Tachyon:
      return {programs.tachyon,
              id + ".dat",
              "-numthreads",
              t,
              "-aasamples",
              std::to_string(samples - 1),
              "-format",
              png ? "PNG" : "PPM",
              "-o",
              image};
    case Renderer::PovRay: {
      std::vector<std::string> args{
          programs.povray,  "+I" + id + ".pov", "+O" + image, png ? "+FN" : "+FP", "-D", "+WT" + t,
          "File_Gamma=1.0", "+W1024",           "+H768"};
      if (samples == 1) {
        args.push_back("-A");
      } else {
        args.insert(args.end(), {"+A0.0", "+AM1", "+R2", "-J"});
      }
      return args;
    }
  }
  return {};
}

int run(int argc, char** argv) {
  const std::string usage =
      "usage: renderer_comparison [--runs N] [--quick] [--out DIR] [--glint PATH] "
      "[--only NAMES] [--generate-only]\n"
      "  --runs N        timed runs per figure (median printed; default 3)\n"
      "  --quick         1 sample per pixel only, 2 threads only\n"
      "  --out DIR       where scenes, images and logs go (default ./renderer_comparison)\n"
      "  --glint PATH    the glint binary (default: the one built with this benchmark)\n"
      "  --only NAMES    comma-separated subset of glint,tachyon,povray\n"
      "  --generate-only write the scene files and exit\n";
  std::vector<ExtraOption> extra{{"--out"}, {"--glint"}, {"--only"}, {"--generate-only", false}};
  bool runsGiven = false;
  for (int i = 1; i < argc; ++i) runsGiven |= std::string(argv[i]) == "--runs";
  CommonOptions options = parseCommonOptions(argc, argv, usage, &extra);
  if (!runsGiven) options.runs = 3;
  const fs::path dir = fs::absolute(extra[0].present ? extra[0].value : "renderer_comparison");
  fs::create_directories(dir);

  const std::vector<ComparisonScene> scenes{spheresScene(), torusScene()};
  for (const ComparisonScene& s : scenes) {
    writeGlint(dir, s);
    writeTachyon(dir, s);
    writePov(dir, s);
  }
  std::printf("scenes written to %s\n", dir.c_str());
  if (extra[3].present) return 0;

  printHeader("renderer comparison: glint vs Tachyon vs POV-Ray (whole runs, wall time)", options);
  Programs programs{findProgram(extra[1].present ? extra[1].value : kDefaultGlint),
                    findProgram("tachyon"), findProgram("povray")};
  const std::string only = extra[2].present ? extra[2].value : "glint,tachyon,povray";
  std::vector<Renderer> renderers;
  for (Renderer r : {Renderer::Glint, Renderer::Tachyon, Renderer::PovRay}) {
    const std::string& program = r == Renderer::Glint     ? programs.glint
                                 : r == Renderer::Tachyon ? programs.tachyon
                                                          : programs.povray;
    if (only.find(rendererName(r)) == std::string::npos) continue;
    if (program.empty()) {
      std::printf("%s: not installed (scripts/setup.sh bench installs it) - skipped\n",
                  rendererName(r));
      continue;
    }
    renderers.push_back(r);
  }

  // One PNG per renderer and scene, to look at (not timed).
  for (const ComparisonScene& s : scenes) {
    for (Renderer r : renderers) {
      const std::string image = s.geometry.id + "-" + rendererName(r) + ".png";
      (void)runTimed(renderCommand(r, programs, s.geometry.id, 1, 2, image), dir,
                     dir / (s.geometry.id + "-" + rendererName(r) + "-png.log"));
    }
  }
  std::printf("images for checking: %s/*-{glint,tachyon,povray}.png\n", dir.c_str());
  std::printf("commands (in %s), e.g. 4 samples, 2 threads:\n", dir.c_str());
  for (Renderer r : renderers) {
    std::printf("  %s\n",
                commandLine(renderCommand(r, programs, "SCENE", 4, 2, "out.ppm")).c_str());
  }

  const std::vector<int> sampleCounts =
      options.quick ? std::vector<int>{1} : std::vector<int>{1, 4};
  const std::vector<int> threadCounts =
      options.quick ? std::vector<int>{2} : std::vector<int>{1, 2};
  std::printf("\n%-13s %3s %3s | %-17s | %-17s | %-17s | %13s | %13s\n", "scene", "spp", "thr",
              "glint s", "Tachyon s", "POV-Ray s", "glint/Tachyon", "glint/POV-Ray");
  struct Key {
    std::string scene;
    int samples, threads;
  };
  std::vector<std::pair<Key, std::map<Renderer, Timing>>> results;
  // CPU seconds per wall second of each renderer's runs: shows the thread count really used.
  std::map<std::tuple<std::string, int, int, Renderer>, double> cores;
  for (const ComparisonScene& s : scenes) {
    for (int samples : sampleCounts) {
      for (int threads : threadCounts) {
        std::map<Renderer, Timing> times;
        std::map<Renderer, double> cpu;
        // Runs interleaved across renderers so that load changes hit all of them alike.
        for (int run = 0; run < options.runs; ++run) {
          for (Renderer r : renderers) {
            const std::string tag = s.geometry.id + "-" + rendererName(r) + "-" +
                                    std::to_string(samples) + "spp-" + std::to_string(threads) +
                                    "t";
            const RunCost cost =
                runTimed(renderCommand(r, programs, s.geometry.id, samples, threads, tag + ".ppm"),
                         dir, dir / (tag + ".log"));
            times[r].seconds.push_back(cost.wallSeconds);
            cpu[r] += cost.cpuSeconds;
          }
        }
        for (auto& [r, seconds] : cpu) {
          double wall = 0;
          for (double w : times[r].seconds) wall += w;
          cores[{s.geometry.name, samples, threads, r}] = seconds / wall;
        }
        const auto cell = [&](Renderer r) {
          char text[32] = "-";
          if (times.count(r)) {
            std::snprintf(text, sizeof text, "%7.3f ±%5.1f%%", times[r].median(),
                          times[r].spreadPercent());
          }
          return std::string(text);
        };
        const auto ratio = [&](Renderer r) {
          char text[32] = "-";
          if (times.count(Renderer::Glint) && times.count(r)) {
            std::snprintf(text, sizeof text, "%.2f",
                          times[Renderer::Glint].median() / times[r].median());
          }
          return std::string(text);
        };
        std::printf("%-13s %3d %3d | %-17s | %-17s | %-17s | %13s | %13s\n",
                    s.geometry.name.c_str(), samples, threads, cell(Renderer::Glint).c_str(),
                    cell(Renderer::Tachyon).c_str(), cell(Renderer::PovRay).c_str(),
                    ratio(Renderer::Tachyon).c_str(), ratio(Renderer::PovRay).c_str());
        std::fflush(stdout);
        results.push_back({{s.geometry.name, samples, threads}, times});
      }
    }
  }

  // PNG, every renderer's usual output, costs a serial compression after the parallel render:
  // the same runs (1 sample, the last thread count) once more, writing PNG.
  std::printf("\nwriting PNG instead (1 sample per pixel, %d thread(s)):\n", threadCounts.back());
  for (const ComparisonScene& s : scenes) {
    std::map<Renderer, Timing> times;
    for (int run = 0; run < options.runs; ++run) {
      for (Renderer r : renderers) {
        const std::string tag = s.geometry.id + "-" + rendererName(r) + "-1spp-" +
                                std::to_string(threadCounts.back()) + "t";
        times[r].seconds.push_back(runTimed(renderCommand(r, programs, s.geometry.id, 1,
                                                          threadCounts.back(), tag + ".png"),
                                            dir, dir / (tag + "-png-timed.log"))
                                       .wallSeconds);
      }
    }
    std::printf("%-13s %3d %3d |", s.geometry.name.c_str(), 1, threadCounts.back());
    for (Renderer r : {Renderer::Glint, Renderer::Tachyon, Renderer::PovRay}) {
      if (times.count(r)) {
        std::printf(" %s %7.3f ±%5.1f%% |", rendererName(r), times[r].median(),
                    times[r].spreadPercent());
      }
    }
    if (times.count(Renderer::Glint) && times.count(Renderer::Tachyon)) {
      std::printf(" glint/Tachyon %.2f",
                  times[Renderer::Glint].median() / times[Renderer::Tachyon].median());
    }
    std::printf("\n");
    std::fflush(stdout);
  }

  // glint's worst 2-thread speedup, for the target line at the end.
  double worstSpeedup = std::numeric_limits<double>::infinity();
  std::string worstSpeedupRow;
  if (threadCounts.size() == 2) {
    std::printf("\n2-thread speedup (1-thread time / 2-thread time)\n%-13s %3s |", "scene", "spp");
    for (Renderer r : renderers) std::printf(" %8s", rendererName(r));
    std::printf("\n");
    for (std::size_t i = 0; i + 1 < results.size(); i += 2) {
      auto& one = results[i].second;
      auto& two = results[i + 1].second;
      std::printf("%-13s %3d |", results[i].first.scene.c_str(), results[i].first.samples);
      for (Renderer r : renderers) {
        const double speedup = one[r].median() / two[r].median();
        std::printf(" %8.2f", speedup);
        if (r == Renderer::Glint && speedup < worstSpeedup) {
          worstSpeedup = speedup;
          worstSpeedupRow =
              results[i].first.scene + " at " + std::to_string(results[i].first.samples) + " spp";
        }
      }
      std::printf("\n");
    }
  }

  std::printf(
      "\ncores kept busy (child CPU time / wall time, all runs): shows each renderer "
      "really ran the threads asked for\n");
  std::printf("%-13s %3s %3s |", "scene", "spp", "thr");
  for (Renderer r : renderers) std::printf(" %8s", rendererName(r));
  std::printf("\n");
  for (auto& [key, times] : results) {
    std::printf("%-13s %3d %3d |", key.scene.c_str(), key.samples, key.threads);
    for (Renderer r : renderers) {
      std::printf(" %8.2f", cores[{key.scene, key.samples, key.threads, r}]);
    }
    std::printf("\n");
  }

  // Do the renders show the same thing? glint's 1-sample image against the others'.
  const bool haveGlint =
      std::find(renderers.begin(), renderers.end(), Renderer::Glint) != renderers.end();
  if (haveGlint) {
    std::printf("\nimage check (1 sample per pixel, %d thread(s)), against glint's render:\n",
                threadCounts.back());
    for (const ComparisonScene& s : scenes) {
      const auto file = [&](Renderer r) {
        return dir / (s.geometry.id + "-" + rendererName(r) + "-1spp-" +
                      std::to_string(threadCounts.back()) + "t.ppm");
      };
      for (Renderer r : renderers) {
        if (r == Renderer::Glint) continue;
        std::printf("  %-13s %-8s %s\n", s.geometry.name.c_str(), rendererName(r),
                    imageDifference(file(Renderer::Glint), file(r)).c_str());
      }
    }
  }

  // Issue 16's targets at 2 threads: the spheres in at most Tachyon's time, the torus in at most
  // half of it.
  bool anyTarget = false, met = true;
  double worstExcess = 0;  // the largest ratio / limit
  std::string worstRow;
  for (auto& [key, times] : results) {
    if (key.threads != 2 || !times.count(Renderer::Glint) || !times.count(Renderer::Tachyon)) {
      continue;
    }
    anyTarget = true;
    const double limit = key.scene.find("spheres") != std::string::npos ? 1.0 : 0.5;
    const double r = times[Renderer::Glint].median() / times[Renderer::Tachyon].median();
    if (r / limit > worstExcess) {
      worstExcess = r / limit;
      char text[96];
      std::snprintf(text, sizeof text, "%s at %d spp: %.2fx against <= %.1fx", key.scene.c_str(),
                    key.samples, r, limit);
      worstRow = text;
    }
    met = met && r <= limit;
  }
  if (anyTarget) {
    std::printf(
        "\ntarget (issue 16): at 2 threads spheres <= 1.0x and torus <= 0.5x Tachyon: worst %s -> "
        "%s\n",
        worstRow.c_str(), met ? "MET" : "NOT MET");
  }
  if (!worstSpeedupRow.empty()) {
    constexpr double kSpeedupTarget = 1.85;
    std::printf("         2-thread speedup >= %.2f on every whole render: worst %s: %.2f -> %s\n",
                kSpeedupTarget, worstSpeedupRow.c_str(), worstSpeedup,
                worstSpeedup >= kSpeedupTarget ? "MET" : "NOT MET");
  }
  std::printf("load average at the end: %s\n", loadAverage().c_str());
  return 0;
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) { return glint::bench::run(argc, argv); }
