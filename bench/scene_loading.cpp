// Loading at scale (issue 12): a generated YAML scene of N spheres (default 100,000, each a line
// like the SPD `balls` scene converted to glint's format) through `glint check`, the command that
// reads, builds and freezes the scene (BVH included) and renders nothing. Prints the file size, the
// median wall time of R runs, the throughput in MB/s, the peak resident memory of `check`, and the
// peak of a process that builds the same scene from memory (no file: the "built scene"), so that
//   peak(check) − peak(built) ≤ 3 × file size
// can be read off. Runs of the two alternate, so a change in the machine's load hits both.
//
//   scene_loading [--spheres N] [--runs R] [--dir DIR] [--quick]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench_support.h"
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

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<glint::bench::ExtraOption> extra = {{"--spheres"}, {"--dir"}};
  const glint::bench::CommonOptions options = glint::bench::parseCommonOptions(
      argc, argv, "scene_loading [--spheres N] [--runs R] [--dir DIR] [--quick]", &extra);
  std::size_t count = options.quick ? 20000 : 100000;
  if (extra[0].present) count = std::stoul(extra[0].value);
  const fs::path dir = extra[1].present ? fs::path(extra[1].value) : fs::temp_directory_path();
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
    const ChildRun check = inChild([&] {
      std::freopen("/dev/null", "w", stdout);
      ::execl(GLINT_CLI_PATH, "glint", "check", scene.c_str(), static_cast<char*>(nullptr));
      return 127;
    });
    if (!WIFEXITED(check.status) || WEXITSTATUS(check.status) != 0) {
      fmt::print(stderr, "glint check failed\n");
      return 1;
    }
    checkSeconds.push_back(check.seconds);
    checkPeak = std::max(checkPeak, check.peakKiB);
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
