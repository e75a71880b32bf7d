// Generated benchmark scenes, ray sets, timing statistics and machine facts (bench_support.h).
#include "bench_support.h"

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <thread>

#include "glint/core/rng.h"

namespace glint::bench {

double Timing::median() const {
  if (seconds.empty()) return 0;
  std::vector<double> sorted = seconds;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t n = sorted.size();
  return n % 2 == 1 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

double Timing::min() const {
  return seconds.empty() ? 0 : *std::min_element(seconds.begin(), seconds.end());
}

double Timing::max() const {
  return seconds.empty() ? 0 : *std::max_element(seconds.begin(), seconds.end());
}

double Timing::spreadPercent() const {
  const double m = median();
  return m > 0 ? 50.0 * (max() - min()) / m : 0;
}

TriangleMesh makeTorus(const Point3& center, double majorRadius, double minorRadius,
                       int majorSegments, int minorSegments, bool normals) {
  TriangleMesh mesh;
  const auto nu = static_cast<std::uint32_t>(majorSegments);
  const auto nv = static_cast<std::uint32_t>(minorSegments);
  mesh.positions.reserve(std::size_t{nu} * nv);
  if (normals) mesh.normals.reserve(std::size_t{nu} * nv);
  mesh.indices.reserve(std::size_t{6} * nu * nv);
  constexpr double kTwoPi = 2 * std::numbers::pi;
  // u runs around the vertical axis, v around the tube; vertex (i, j) is at u_i, v_j.
  for (std::uint32_t i = 0; i < nu; ++i) {
    const double u = kTwoPi * i / nu;
    const double cu = std::cos(u), su = std::sin(u);
    for (std::uint32_t j = 0; j < nv; ++j) {
      const double v = kTwoPi * j / nv;
      const double cv = std::cos(v), sv = std::sin(v);
      const double ring = majorRadius + minorRadius * cv;
      mesh.positions.push_back(center + Vec3{ring * cu, minorRadius * sv, ring * su});
      if (normals) mesh.normals.push_back(Normal3{cv * cu, sv, cv * su});
    }
  }
  const auto vertex = [nu, nv](std::uint32_t i, std::uint32_t j) {
    return (i % nu) * nv + (j % nv);
  };
  for (std::uint32_t i = 0; i < nu; ++i) {
    for (std::uint32_t j = 0; j < nv; ++j) {
      const std::uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1),
                          d = vertex(i, j + 1);
      // (d − a) × (c − a) ≈ ∂p/∂v × ∂p/∂u, which points out of the tube.
      mesh.indices.insert(mesh.indices.end(), {a, d, c, a, c, b});
    }
  }
  return mesh;
}

TriangleMesh makeFloor(const Point3& centre, double halfSize) {
  TriangleMesh mesh;
  const double s = halfSize;
  mesh.positions = {centre + Vec3{-s, 0, -s}, centre + Vec3{s, 0, -s}, centre + Vec3{s, 0, s},
                    centre + Vec3{-s, 0, s}};
  // (p3 − p0) × (p2 − p0) = (0,0,2s) × (2s,0,2s) points to +y.
  mesh.indices = {0, 3, 2, 0, 2, 1};
  return mesh;
}

std::vector<SphereSpec> makeSphereGrid(const Point3& first, int perAxis, double spacing,
                                       double radius) {
  std::vector<SphereSpec> spheres;
  spheres.reserve(static_cast<std::size_t>(perAxis) * perAxis * perAxis);
  for (int i = 0; i < perAxis; ++i) {
    for (int j = 0; j < perAxis; ++j) {
      for (int k = 0; k < perAxis; ++k) {
        spheres.push_back({first + Vec3{i * spacing, j * spacing, k * spacing}, radius});
      }
    }
  }
  return spheres;
}

std::vector<SphereSpec> makeRandomSpheres(std::size_t n, double depthComplexity,
                                          std::uint64_t seed) {
  // Cube [−1, 1]³: volume 8, chord 2. Expected spheres met by a ray = n/8 · π r² · 2.
  const double radius =
      std::sqrt(4 * depthComplexity / (std::numbers::pi * static_cast<double>(n)));
  std::vector<SphereSpec> spheres;
  spheres.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Rng rng(hashCombine(seed, i));
    const Point3 c{2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1};
    spheres.push_back({c, radius});
  }
  return spheres;
}

Bounds3 boundsOf(const std::vector<TriangleMesh>& meshes, const std::vector<SphereSpec>& spheres) {
  Bounds3 b;
  for (const TriangleMesh& mesh : meshes) {
    for (const Point3& p : mesh.positions) b = unite(b, p);
  }
  for (const SphereSpec& s : spheres) {
    const Vec3 r{s.radius, s.radius, s.radius};
    b = unite(b, Bounds3(s.center - r, s.center + r));
  }
  return b;
}

std::vector<Primitive> spherePrimitives(const std::vector<SphereSpec>& spheres) {
  std::vector<Primitive> primitives;
  primitives.reserve(spheres.size());
  for (const SphereSpec& s : spheres) {
    primitives.emplace_back(Sphere::make(s.center, s.radius), 0, Color());
  }
  return primitives;
}

std::size_t meshBytes(const std::vector<TriangleMesh>& meshes) {
  std::size_t bytes = 0;
  for (const TriangleMesh& m : meshes) {
    bytes += m.positions.capacity() * sizeof(Point3) + m.normals.capacity() * sizeof(Normal3) +
             m.indices.capacity() * sizeof(std::uint32_t);
  }
  return bytes;
}

std::size_t triangleCount(const std::vector<TriangleMesh>& meshes) {
  std::size_t n = 0;
  for (const TriangleMesh& m : meshes) n += m.triangleCount();
  return n;
}

RaySet cameraRays(const CameraSpec& spec) {
  const Camera camera(spec);
  RaySet set{"camera", {}};
  set.rays.reserve(static_cast<std::size_t>(spec.imageWidth) * spec.imageHeight);
  for (int row = 0; row < spec.imageHeight; ++row) {
    for (int column = 0; column < spec.imageWidth; ++column) {
      set.rays.push_back(camera.generateRay(column, row));
    }
  }
  return set;
}

RaySet randomRays(const Bounds3& bounds, std::size_t count, std::uint64_t seed) {
  RaySet set{"random", {}};
  set.rays.reserve(count);
  const Vec3 extent = bounds.diagonal();
  for (std::size_t i = 0; i < count; ++i) {
    Rng rng(hashCombine(seed, i));
    const Point3 origin = bounds.lo + Vec3{extent.x * rng.uniform(), extent.y * rng.uniform(),
                                           extent.z * rng.uniform()};
    // Uniform on the sphere (Archimedes): z uniform in [−1, 1], azimuth uniform.
    const double z = 1 - 2 * rng.uniform();
    const double phi = 2 * std::numbers::pi * rng.uniform();
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    set.rays.push_back(Ray{origin, Vec3{s * std::cos(phi), s * std::sin(phi), z}});
  }
  return set;
}

std::size_t heapBytesInUse() {
  const struct mallinfo2 info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

double processCpuSeconds() {
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(in >> a >> b >> c)) return "unknown";
  char text[64];
  std::snprintf(text, sizeof text, "%.2f, %.2f, %.2f", a, b, c);
  return text;
}

int hardwareThreads() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(n);
}

CommonOptions parseCommonOptions(int argc, char** argv, const std::string& usage,
                                 std::vector<ExtraOption>* extra) {
  CommonOptions options;
  const auto fail = [&](const std::string& message) {
    std::cerr << argv[0] << ": " << message << "\n" << usage;
    std::exit(2);
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << usage;
      std::exit(0);
    } else if (arg == "--quick") {
      options.quick = true;
    } else if (arg == "--runs") {
      if (i + 1 >= argc) fail("--runs needs a number");
      options.runs = std::atoi(argv[++i]);
      if (options.runs < 1) fail("--runs must be >= 1");
    } else {
      ExtraOption* option = nullptr;
      if (extra) {
        for (ExtraOption& e : *extra) {
          if (e.name == arg) option = &e;
        }
      }
      if (!option) fail("unknown argument '" + arg + "'");
      option->present = true;
      if (option->takesValue) {
        if (i + 1 >= argc) fail(arg + " needs a value");
        option->value = argv[++i];
      }
    }
  }
  return options;
}

void printHeader(const std::string& title, const CommonOptions& options) {
  std::string cpu = "unknown CPU";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
#ifdef NDEBUG
  const char* build = "optimised (NDEBUG)";
#else
  const char* build = "NOT optimised (assertions on): figures are meaningless";
#endif
  std::printf("== %s ==\n", title.c_str());
  std::printf("machine: %s, %d hardware threads; load average %s; build %s\n", cpu.c_str(),
              hardwareThreads(), loadAverage().c_str(), build);
  std::printf("each figure: median of %d runs%s\n\n", options.runs,
              options.quick ? " (--quick: reduced sizes)" : "");
  std::fflush(stdout);
}

}  // namespace glint::bench
