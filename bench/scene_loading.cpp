// Loading at scale (issue 12): a generated YAML scene of N spheres (default 100,000, each a line
// like the SPD `balls` scene converted to glint's format) through `glint check`, the command that
// reads, builds and freezes the scene (BVH included) and renders nothing. Prints the file size, the
// median wall time of R runs, the throughput in MB/s, the peak resident memory of `check`, and the
// peak of a process that builds the same scene from memory (no file: the "built scene"), so that
//   peak(check) − peak(built) ≤ 3 × file size
// can be read off. Runs of the two alternate, so a change in the machine's load hits both.
//
// With --obj T (T = 100000 or 1000000 triangles; issue 16) it measures instead where the time of
// loading the renderer comparison's torus OBJ goes, for glint's OBJ parser and for assimp's OBJ
// importer (GLINT_OBJ_READER=assimp), alternating the two in every run: reading the bytes, the
// parse alone, the import (parse, assimp's post-processing, glint's vertex join and repairs), the
// whole readMeshFile (the sandboxed child started, its answer through the memory file, the
// parent's checks) and `glint check` of a scene holding the mesh (everything but rendering). The
// phases before readMeshFile each run in a fresh process started as the mesh reader is (its
// environment and malloc settings).
//
//   scene_loading [--spheres N] [--obj T] [--runs R] [--dir DIR] [--quick]
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include "bench_scenes.h"
#include "bench_support.h"
#include "glint/core/file_access.h"
#include "glint/mesh/assimp_import.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/obj_fast_parse.h"
#include "glint/scene/scene.h"

namespace {

namespace fs = std::filesystem;

struct Sphere {
  double x, y, z, r;
};

// Deterministic spheres in a 10-unit cube, radii 0.01–0.05.
std::vector<Sphere> spheres(std::size_t count) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> position(-5, 5);
  std::uniform_real_distribution<double> radius(0.01, 0.05);
  std::vector<Sphere> out(count);
  for (Sphere& s : out) {
    s.x = position(rng);
    s.y = position(rng);
    s.z = position(rng);
    s.r = radius(rng);
  }
  return out;
}

void writeScene(const fs::path& path, const std::vector<Sphere>& list) {
  std::ofstream out(path, std::ios::binary);
  out << "camera: { position: [0, 0, 10], look_at: [0, 0, 0], fov: 40 }\n"
         "image: { width: 320, height: 240 }\n"
         "materials:\n  red: { kd: [0.8, 0.2, 0.2], ks: 0.3, shininess: 40 }\n"
         "lights:\n  - { type: point, position: [10, 10, 10] }\n"
         "objects:\n";
  for (const Sphere& s : list) {
    out << fmt::format(
        "  - {{ type: sphere, center: [{:.6f}, {:.6f}, {:.6f}], radius: {:.6f}, material: red }}\n",
        s.x, s.y, s.z, s.r);
  }
}

// Wall seconds and peak resident kilobytes of a child process running `work`.
struct ChildRun {
  double seconds = 0;
  long peakKiB = 0;
  int status = 0;
};

template <class Work>
ChildRun inChild(Work&& work) {
  std::fflush(stdout);  // or the child's exit prints the buffered lines again
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(work());
  int status = 0;
  struct rusage usage {};
  ::wait4(pid, &status, 0, &usage);
  ChildRun run;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.peakKiB = usage.ru_maxrss;
  run.status = status;
  return run;
}

// `glint check SCENE` in a child process (its output dropped); nullopt, with a message, when it
// fails.
std::optional<ChildRun> runGlintCheck(const fs::path& scene) {
  const ChildRun check = inChild([&] {
    std::freopen("/dev/null", "w", stdout);
    ::execl(GLINT_CLI_PATH, "glint", "check", scene.c_str(), static_cast<char*>(nullptr));
    return 127;
  });
  if (!WIFEXITED(check.status) || WEXITSTATUS(check.status) != 0) {
    fmt::print(stderr, "glint check failed\n");
    return std::nullopt;
  }
  return check;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// One phase of loading `obj` in this process (the --phase mode), its seconds; negative when it
// fails. "read": the file into memory; "parse": assimp's ReadFile, or the bytes read (untimed) and
// parseSimpleObj; "import": importMeshWithAssimp or importSimpleObj.
double runPhase(const std::string& phase, bool useAssimp, const fs::path& obj) {
  const auto readText = [&] {
    std::ifstream in(obj, std::ios::binary);
    std::string text(static_cast<std::size_t>(fs::file_size(obj)), '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    return in ? text : std::string();
  };
  const glint::ReferencedFileRule rule(obj, obj.parent_path());
  glint::bench::Stopwatch watch;
  if (phase == "read") return readText().empty() ? -1 : watch.seconds();
  if (phase == "parse" && useAssimp) {
    Assimp::Importer importer;  // reads the file itself
    return importer.ReadFile(obj.string(), 0) != nullptr ? watch.seconds() : -1;
  }
  if (phase == "parse") {
    const std::string text = readText();
    glint::bench::Stopwatch parse;
    return glint::parseSimpleObj(text) ? parse.seconds() : -1;
  }
  if (phase == "import" && useAssimp) {
    return glint::importMeshWithAssimp(obj, ".obj", rule).parts.empty() ? -1 : watch.seconds();
  }
  if (phase == "import") return glint::importSimpleObj(obj, rule) ? watch.seconds() : -1;
  return -1;
}

// runPhase in a fresh program (this one, started again with --phase) that begins as the mesh
// reader does: a new process (no heap inherited from a fork), the reader's environment (glibc's
// malloc on huge pages: import_child.cpp, meshReaderEnvironment) and malloc settings.
double phaseInProgram(const std::string& phase, bool useAssimp, const fs::path& obj) {
  int fds[2];
  if (::pipe(fds) != 0) return -1;
  std::fflush(stdout);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(fds[1], 1);
    ::close(fds[0]);
    ::setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1", 1);
    ::execl("/proc/self/exe", "scene_loading", "--phase", phase.c_str(),
            useAssimp ? "assimp" : "glint", obj.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  char answer[64] = {};
  const ssize_t n = ::read(fds[0], answer, sizeof answer - 1);
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return n > 0 ? std::atof(answer) : -1;
}

// The same mesh (positions, normals, uvs, indices, materials) in both, to the bit.
bool sameMesh(const glint::MeshFile& a, const glint::MeshFile& b) {
  if (a.parts.size() != b.parts.size() || a.materials.size() != b.materials.size() ||
      a.droppedTriangles != b.droppedTriangles) {
    return false;
  }
  const auto same = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof x[0]) == 0);
  };
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    const glint::TriangleMesh& p = a.parts[i];
    const glint::TriangleMesh& q = b.parts[i];
    if (!same(p.positions, q.positions) || !same(p.normals, q.normals) ||
        !same(p.indices, q.indices) || !same(p.uvs, q.uvs) || p.materialIndex != q.materialIndex) {
      return false;
    }
  }
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    if (a.materials[i].name != b.materials[i].name) return false;
  }
  return true;
}

// Median seconds of each phase, per reader.
struct ObjPhases {
  std::vector<double> read, parse, import, child, check;
};

void printPhases(const char* name, const ObjPhases& t, double megabytes) {
  const auto line = [&](const char* phase, const std::vector<double>& seconds) {
    const double m = median(seconds);
    fmt::print("  {:<8} {:<34} {:7.3f} s  ({:.3f}–{:.3f})  {:7.1f} MB/s\n", name, phase, m,
               *std::min_element(seconds.begin(), seconds.end()),
               *std::max_element(seconds.begin(), seconds.end()), megabytes / m);
  };
  line("read the file", t.read);
  line(name[0] == 'a' ? "read + parse (ReadFile)" : "parse (parseSimpleObj)", t.parse);
  line("importMesh (+ post-process, join)", t.import);
  line("readMeshFile (child + transfer)", t.child);
  line("glint check (load + build)", t.check);
}

int objLoading(int triangles, const fs::path& dir, const glint::bench::CommonOptions& options) {
  const glint::bench::BenchScene torus = glint::bench::makeTorusScene(triangles);
  const fs::path obj = dir / fmt::format("glint-bench-{}.obj", torus.id);
  glint::bench::writeObj(obj, torus.meshes.front());
  const fs::path scene = dir / fmt::format("glint-bench-{}.yaml", torus.id);
  {
    std::ofstream out(scene);
    out << "camera: { position: [0, 2.6, 4.2], look_at: [0, 0.35, 0], fov: 40 }\n"
           "image: { width: 1024, height: 768 }\n"
           "lights:\n  - { type: point, position: [3, 5, 3] }\n"
           "objects:\n  - { type: mesh, file: "
        << obj.filename().string() << ", smooth: true }\n";
  }
  const double megabytes = static_cast<double>(fs::file_size(obj)) / 1e6;
  glint::bench::printHeader("OBJ loading (the renderer comparison's torus)", options);
  fmt::print(
      "OBJ loading: {} ({:.2f} MB, {} triangles), {} runs, glint's parser and assimp "
      "alternating\n",
      obj.string(), megabytes, triangles, options.runs);
  const glint::ReferencedFileRule rule(obj, dir);
  ObjPhases fast, assimp;
  bool same = true;
  for (int r = 0; r < options.runs; ++r) {
    for (const bool useAssimp : {false, true}) {
      ObjPhases& t = useAssimp ? assimp : fast;
      if (useAssimp) {
        ::setenv("GLINT_OBJ_READER", "assimp", 1);
      } else {
        ::unsetenv("GLINT_OBJ_READER");
      }
      const double read = phaseInProgram("read", useAssimp, obj);
      const double parse = phaseInProgram("parse", useAssimp, obj);
      const double import = phaseInProgram("import", useAssimp, obj);
      if (read < 0 || parse < 0 || import < 0) {
        fmt::print(stderr, "{} failed to read the torus\n",
                   useAssimp ? "assimp" : "glint's parser");
        return 1;
      }
      t.read.push_back(read);
      t.parse.push_back(parse);
      t.import.push_back(import);
      const glint::MeshFile imported = useAssimp ? glint::importMeshWithAssimp(obj, ".obj", rule)
                                                 : *glint::importSimpleObj(obj, rule);
      glint::bench::Stopwatch child;
      const glint::MeshFile loaded = glint::readMeshFile(obj, {dir});
      t.child.push_back(child.seconds());
      same = same && sameMesh(imported, loaded);
      static std::optional<glint::MeshFile> first;
      if (!first) first = loaded;
      same = same && sameMesh(*first, loaded);
      const std::optional<ChildRun> check = runGlintCheck(scene);
      if (!check) return 1;
      t.check.push_back(check->seconds);
    }
  }
  ::unsetenv("GLINT_OBJ_READER");
  printPhases("glint", fast, megabytes);
  printPhases("assimp", assimp, megabytes);
  fmt::print(
      "  glint's parser / assimp: parse {:.2f}×, import {:.2f}×, readMeshFile {:.2f}×, "
      "glint check {:.2f}×; meshes {}; load average now {}\n",
      median(fast.parse) / median(assimp.parse), median(fast.import) / median(assimp.import),
      median(fast.child) / median(assimp.child), median(fast.check) / median(assimp.check),
      same ? "identical" : "DIFFER", glint::bench::loadAverage());
  fs::remove(obj);
  fs::remove(scene);
  return same ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::strcmp(argv[1], "--phase") == 0) {  // phaseInProgram's child
    ::mallopt(M_MMAP_THRESHOLD, 32 << 20);                  // as the mesh reader (import_child.cpp)
    std::printf("%.9f\n", runPhase(argv[2], std::strcmp(argv[3], "assimp") == 0, argv[4]));
    return 0;
  }
  std::vector<glint::bench::ExtraOption> extra = {{"--spheres"}, {"--dir"}, {"--obj"}};
  const glint::bench::CommonOptions options = glint::bench::parseCommonOptions(
      argc, argv,
      "scene_loading [--spheres N] [--obj TRIANGLES] [--runs R] [--dir DIR] [--quick]\n", &extra);
  std::size_t count = options.quick ? 20000 : 100000;
  if (extra[0].present) count = std::stoul(extra[0].value);
  const fs::path dir = extra[1].present ? fs::path(extra[1].value) : fs::temp_directory_path();
  if (extra[2].present) {
    return objLoading(std::stoi(extra[2].value), dir, options);
  }
  const int runs = options.runs;
  const std::vector<Sphere> list = spheres(count);
  const fs::path scene = dir / fmt::format("glint-bench-spheres-{}.yaml", count);
  writeScene(scene, list);
  const double megabytes = static_cast<double>(fs::file_size(scene)) / 1e6;
  glint::bench::printHeader("scene loading (glint check of a generated sphere scene)", options);
  fmt::print("scene loading: {} spheres, {} ({:.2f} MB), {} runs alternating\n", count,
             scene.string(), megabytes, runs);

  std::vector<double> checkSeconds, builtSeconds;
  long checkPeak = 0, builtPeak = 0;
  for (int r = 0; r < runs; ++r) {
    const std::optional<ChildRun> check = runGlintCheck(scene);
    if (!check) return 1;
    checkSeconds.push_back(check->seconds);
    checkPeak = std::max(checkPeak, check->peakKiB);
    // The same scene built from memory: primitives, materials, camera, BVH — no file.
    const ChildRun built = inChild([&] {
      glint::SceneParts parts;
      glint::Material red;
      red.kd = glint::Color(0.8, 0.2, 0.2);
      red.ks = glint::Color(0.3);
      red.shininess = 40;
      parts.materials.push_back(red);
      parts.primitives.reserve(list.size());
      for (const Sphere& s : list) {
        parts.primitives.emplace_back(glint::Sphere::make({s.x, s.y, s.z}, s.r), 1, glint::Color());
      }
      parts.lights.push_back(glint::PointLight{{10, 10, 10}, glint::Color(1), {}});
      parts.camera.position = {0, 0, 10};
      parts.camera.direction = {0, 0, -1};
      parts.camera.fovDegrees = 40;
      parts.image.width = 320;
      parts.image.height = 240;
      const glint::Scene frozen(std::move(parts));
      return frozen.primitives().size() == list.size() ? 0 : 1;
    });
    builtSeconds.push_back(built.seconds);
    builtPeak = std::max(builtPeak, built.peakKiB);
  }
  const double checkMedian = median(checkSeconds);
  const double fileMiB = megabytes * 1e6 / (1 << 20);
  const double extraMiB = static_cast<double>(checkPeak - builtPeak) / 1024;
  fmt::print(
      "  glint check:        {:.3f} s median ({:.3f}–{:.3f}), {:.1f} MB/s, peak {:.1f} MiB\n",
      checkMedian, *std::min_element(checkSeconds.begin(), checkSeconds.end()),
      *std::max_element(checkSeconds.begin(), checkSeconds.end()), megabytes / checkMedian,
      static_cast<double>(checkPeak) / 1024);
  fmt::print("  built from memory:  {:.3f} s median, peak {:.1f} MiB\n", median(builtSeconds),
             static_cast<double>(builtPeak) / 1024);
  fmt::print("  reading costs {:.1f} MiB above the built scene = {:.2f} × the file ({:.2f} MiB)\n",
             extraMiB, extraMiB / fileMiB, fileMiB);
  fmt::print("  targets: >= 20 MB/s {}; <= 3 × file {}\n",
             megabytes / checkMedian >= 20 ? "met" : "NOT met",
             extraMiB <= 3 * fileMiB ? "met" : "NOT met");
  fs::remove(scene);
  return 0;
}
