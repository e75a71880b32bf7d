// Instancing (issue 19, DESIGN.md §11): memory and build time of 10^3, 10^5 and 10^6 instances of
// the 100k-triangle torus (the torus of build_memory and ray_throughput), and closest-hit Mrays/s
// of instanced against the same triangles flattened into one Aggregate (world-space copies),
// where the flattened copies fit in memory: 10 and 100 instances (1M and 10M triangles).
//
//   instancing [--runs N] [--quick]
//
// Memory: InstanceSet::memoryBytes() (instance records, top-level tree, the torus and its BVH
// once), checked against the heap in use after − before building (glibc mallinfo2), and the peak
// during the build is not shown. Instances stand on a square grid 3 units apart, each turned about
// the vertical by a deterministic angle; camera rays (1024×768) look across the field.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "bench_scenes.h"
#include "bench_support.h"
#include "glint/accel/instances.h"

namespace glint::bench {
namespace {

constexpr double kSpacing = 3;

std::vector<Transform> fieldTransforms(std::size_t count) {
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(count))));
  std::vector<Transform> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double x = (static_cast<double>(i % side) - 0.5 * static_cast<double>(side)) * kSpacing;
    const double z = -static_cast<double>(i / side) * kSpacing;
    out.push_back(Transform::translate({x, 0, z}) *
                  Transform::rotate({0, 1, 0}, static_cast<double>((i * 37) % 360)));
  }
  return out;
}

CameraSpec fieldCamera(std::size_t count) {
  const double side = std::ceil(std::sqrt(static_cast<double>(count))) * kSpacing;
  CameraSpec spec;
  spec.position = {0, 0.15 * side + 3, 6};
  spec.direction = Point3{0, 0, -0.5 * side} - spec.position;
  spec.up = {0, 1, 0};
  spec.fovDegrees = 50;
  spec.imageWidth = 1024;
  spec.imageHeight = 768;
  return spec;
}

double mraysPerSecond(const Aggregate& aggregate, const RaySet& rays, int runs, std::size_t& hits) {
  tbb::task_arena arena(hardwareThreads());
  Timing timing;
  for (int run = 0; run < runs; ++run) {
    std::vector<std::uint8_t> hit(rays.rays.size());
    const Stopwatch watch;
    forBlocks(arena, rays.rays.size(), [&](std::size_t begin, std::size_t end) {
      Hit h;
      for (std::size_t i = begin; i < end; ++i) {
        hit[i] = aggregate.intersect(rays.rays[i], 0, kInfinity, h) ? 1 : 0;
      }
    });
    timing.seconds.push_back(watch.seconds());
    hits = static_cast<std::size_t>(std::count(hit.begin(), hit.end(), 1));
  }
  return static_cast<double>(rays.rays.size()) / timing.median() / 1e6;
}

struct Built {
  std::unique_ptr<Aggregate> aggregate;
  double seconds = 0;
  std::size_t heapBytes = 0;
};

Built buildInstanced(const std::shared_ptr<const Aggregate>& torus, std::size_t count) {
  Built b;
  // Before the input records exist: they are moved in and freed by the build, so the difference
  // is what the built set keeps.
  const std::size_t before = heapBytesInUse();
  {
    std::vector<Instance> records;
    {
      const std::vector<Transform> transforms = fieldTransforms(count);
      records.reserve(count);
      for (const Transform& t : transforms) records.push_back(makeInstance(&t, 0));
    }
    const Stopwatch watch;
    auto set = std::make_shared<const InstanceSet>(
        std::vector<std::shared_ptr<const Aggregate>>{torus}, std::move(records));
    b.aggregate = std::make_unique<Aggregate>(std::vector<Primitive>{}, std::vector<Color>{},
                                              std::vector<TriangleMesh>{}, std::vector<Color>{},
                                              Acceleration::Bvh, std::move(set));
    b.seconds = watch.seconds();
  }
  b.heapBytes = heapBytesInUse() - before;
  return b;
}

Built buildFlattened(const TriangleMesh& torus, std::size_t count) {
  std::vector<TriangleMesh> meshes;
  for (const Transform& t : fieldTransforms(count)) {
    TriangleMesh m = torus;
    for (Point3& p : m.positions) p = t(p);
    for (Normal3& n : m.normals) n = Normal3(normalize(toVec(t(n))));
    meshes.push_back(std::move(m));
  }
  Built b;
  const std::size_t before = heapBytesInUse();
  const Stopwatch watch;
  b.aggregate =
      std::make_unique<Aggregate>(std::vector<Primitive>{}, std::vector<Color>{}, std::move(meshes),
                                  std::vector<Color>(count), Acceleration::Bvh);
  b.seconds = watch.seconds();
  b.heapBytes = heapBytesInUse() - before;
  return b;
}

int run(int argc, char** argv) {
  const std::string usage =
      "usage: instancing [--runs N] [--quick]\n"
      "  --runs N   repetitions per figure (median printed; default 5)\n"
      "  --quick    up to 10^5 instances, flattened only for 10\n";
  const CommonOptions options = parseCommonOptions(argc, argv, usage);
  printHeader("Instancing: the 100k-triangle torus placed 10^3..10^6 times", options);
  const TriangleMesh torusMesh = makeTorus({0, 0.5, 0}, 1.0, 0.4, 400, 125, /*normals=*/true);
  const auto torus = std::make_shared<const Aggregate>(
      std::vector<Primitive>{}, std::vector<Color>{}, std::vector<TriangleMesh>{torusMesh},
      std::vector<Color>{Color()});
  std::printf("the group: %zu triangles, its Aggregate %.1f MB (mesh + BVH, built once)\n\n",
              torus->triangleCount(), static_cast<double>(torus->memoryBytes()) / 1e6);

  std::printf("%-10s %14s %12s %14s %12s %10s %12s\n", "instances", "triangles", "build s",
              "memoryBytes MB", "heap MB", "B/instance", "Mrays/s");
  const std::vector<std::size_t> counts = options.quick
                                              ? std::vector<std::size_t>{1000, 100000}
                                              : std::vector<std::size_t>{1000, 100000, 1000000};
  for (const std::size_t count : counts) {
    Timing build;
    Built b;
    const int runs = count >= 1000000 ? std::min(options.runs, 3) : options.runs;
    for (int r = 0; r < runs; ++r) {
      b = Built{};  // the previous set freed before the next is measured
      b = buildInstanced(torus, count);
      build.seconds.push_back(b.seconds);
    }
    const RaySet rays = cameraRays(fieldCamera(count));
    std::size_t hits = 0;
    const double mrays = mraysPerSecond(*b.aggregate, rays, options.runs, hits);
    const std::size_t bytes = b.aggregate->memoryBytes();
    std::printf("%-10zu %14.3g %12.3f %14.1f %12.1f %10.1f %12.2f  (%.0f%% of rays hit)\n", count,
                static_cast<double>(count) * static_cast<double>(torus->triangleCount()),
                build.median(), static_cast<double>(bytes) / 1e6,
                static_cast<double>(b.heapBytes + torus->memoryBytes()) / 1e6,
                static_cast<double>(bytes - torus->memoryBytes()) / static_cast<double>(count),
                mrays, 100.0 * static_cast<double>(hits) / static_cast<double>(rays.rays.size()));
    std::fflush(stdout);
    if (count == 1000000) {
      std::printf("  target <= 200 MB for 10^6 instances: %.1f MB -> %s\n",
                  static_cast<double>(bytes) / 1e6, bytes <= 200000000 ? "MET" : "NOT MET");
    }
  }

  std::printf(
      "\n-- instanced vs flattened (the same triangles as world-space meshes in one BVH) --\n");
  std::printf("%-10s %14s %16s %16s %14s %14s %s\n", "instances", "triangles", "instanced MB",
              "flattened MB", "inst. Mrays/s", "flat Mrays/s", "hits inst/flat");
  const std::vector<std::size_t> flatCounts =
      options.quick ? std::vector<std::size_t>{10} : std::vector<std::size_t>{10, 100};
  for (const std::size_t count : flatCounts) {
    const RaySet rays = cameraRays(fieldCamera(count));
    const Built inst = buildInstanced(torus, count);
    std::size_t instHits = 0;
    const double instMrays = mraysPerSecond(*inst.aggregate, rays, options.runs, instHits);
    std::size_t flatHits = 0;
    double flatMrays = 0;
    std::size_t flatBytes = 0;
    {
      const Built flat = buildFlattened(torusMesh, count);
      flatMrays = mraysPerSecond(*flat.aggregate, rays, options.runs, flatHits);
      flatBytes = flat.aggregate->memoryBytes();
    }
    std::printf("%-10zu %14.3g %16.1f %16.1f %14.2f %14.2f %zu/%zu\n", count,
                static_cast<double>(count) * static_cast<double>(torus->triangleCount()),
                static_cast<double>(inst.aggregate->memoryBytes()) / 1e6,
                static_cast<double>(flatBytes) / 1e6, instMrays, flatMrays, instHits, flatHits);
    std::fflush(stdout);
  }
  std::printf(
      "\nMrays/s: closest hit of 1024x768 camera rays across the field, all hardware threads.\n"
      "memoryBytes: the aggregate's own count (104 B per instance record + the top-level tree +\n"
      "the torus group once); heap: mallinfo2 bytes in use after - before the build, plus the\n"
      "group. Flattened 10^3 instances would be 10^8 triangles (~6 GB): not run.\n");
  std::printf("load average at the end: %s\n", loadAverage().c_str());
  return 0;
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) { return glint::bench::run(argc, argv); }
