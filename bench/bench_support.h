// What the benchmark programs share: deterministic generated scenes (torus meshes, floors, sphere
// grids, random spheres), ray sets, repeated timing with medians, heap accounting, table output.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "glint/accel/aggregate.h"
#include "glint/core/bounds.h"
#include "glint/core/ray.h"
#include "glint/core/vec.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/triangle_mesh.h"
#include "glint/scene/camera.h"
#include "oneapi/tbb/blocked_range.h"
#include "oneapi/tbb/parallel_for.h"
#include "oneapi/tbb/partitioner.h"
#include "oneapi/tbb/task_arena.h"

namespace glint::bench {

// ---------------------------------------------------------------------------------------------
// Timing

// Wall-clock seconds of repeated runs of one measurement.
struct Timing {
  std::vector<double> seconds;  // one per run, in run order
  double median() const;
  double min() const;
  double max() const;
  // Half the range relative to the median, in percent: "±x %" in the tables.
  double spreadPercent() const;
};

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// ---------------------------------------------------------------------------------------------
// Threads

// Rays per work item. Every program hands glint and Embree the same blocks of consecutive rays
// (a camera row is 1024 rays), scheduled dynamically by oneTBB inside an arena of the thread count
// being measured, so both get the same partition and the same load balancing.
inline constexpr std::size_t kRayBlock = 1024;

template <class Body>
void forBlocks(tbb::task_arena& arena, std::size_t count, const Body& body) {
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count, kRayBlock),
        [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); },
        tbb::simple_partitioner());
  });
}

// ---------------------------------------------------------------------------------------------
// Generated geometry (all deterministic: the same arguments give the same bytes)

// A sphere as both glint and Embree describe it.
struct SphereSpec {
  Point3 center;
  double radius = 1;
};

// A closed torus around the vertical axis through `center`: majorSegments × minorSegments quads,
// each split into two triangles (2·major·minor triangles, (major·minor) shared vertices), wound so
// the geometric normal points out of the tube. With `normals`, the analytic unit vertex normals
// are stored too (as a smooth mesh loaded from a file would have them).
TriangleMesh makeTorus(const Point3& center, double majorRadius, double minorRadius,
                       int majorSegments, int minorSegments, bool normals);

// `mesh` as an OBJ file: a comment line, `v` and `vn` lines (%.9g: a double's value to float
// precision and beyond), one `f a//a b//b c//c` line per triangle — what the renderer comparison
// and the loading benchmark hand to glint.
void writeObj(const std::filesystem::path& path, const TriangleMesh& mesh);

// Two triangles covering the square [−halfSize, halfSize]² around (centre.x, centre.z) at height
// centre.y, normal +y.
TriangleMesh makeFloor(const Point3& centre, double halfSize);

// perAxis³ spheres on a cubic grid: centres first + (i, j, k)·spacing.
std::vector<SphereSpec> makeSphereGrid(const Point3& first, int perAxis, double spacing,
                                       double radius);

// n spheres with centres uniform in the cube [−1, 1]³ (glint::Rng keyed by `seed` and the index)
// and one radius chosen so that a ray crossing the cube meets `depthComplexity` spheres on average
// (n·π·r²·2 / 8 = depthComplexity): every n gives a statistically similar image.
std::vector<SphereSpec> makeRandomSpheres(std::size_t n, double depthComplexity,
                                          std::uint64_t seed);

Bounds3 boundsOf(const std::vector<TriangleMesh>& meshes, const std::vector<SphereSpec>& spheres);

// Glint primitives (world-space spheres, default material) for the sphere specs.
std::vector<Primitive> spherePrimitives(const std::vector<SphereSpec>& spheres);

// Bytes held by the mesh arrays (capacities, as allocated).
std::size_t meshBytes(const std::vector<TriangleMesh>& meshes);
std::size_t triangleCount(const std::vector<TriangleMesh>& meshes);

// ---------------------------------------------------------------------------------------------
// Ray sets

struct RaySet {
  std::string name;
  std::vector<Ray> rays;  // unit directions
};

// One pinhole ray through the centre of every pixel, row by row (glint::Camera, DESIGN.md §4).
RaySet cameraRays(const CameraSpec& spec);
// `count` rays with origins uniform inside `bounds` and directions uniform on the unit sphere.
RaySet randomRays(const Bounds3& bounds, std::size_t count, std::uint64_t seed);

// ---------------------------------------------------------------------------------------------
// Memory and machine

// Bytes of heap currently allocated through malloc (glibc mallinfo2: arena bytes in use plus
// mmap'ed blocks), summed over all threads' arenas.
std::size_t heapBytesInUse();
// CPU seconds (user + system) this process has used so far, all threads together.
double processCpuSeconds();
// The 1-, 5- and 15-minute load averages, as uptime prints them.
std::string loadAverage();
// Hardware threads available to this process.
int hardwareThreads();

// ---------------------------------------------------------------------------------------------
// Command line: every program takes --runs N and --quick (smaller scenes / fewer repetitions).

struct CommonOptions {
  int runs = 5;
  bool quick = false;
};
// A program's own option: a flag, or an option taking one value.
struct ExtraOption {
  ExtraOption(std::string optionName, bool withValue = true)
      : name(std::move(optionName)), takesValue(withValue) {}
  std::string name;  // "--threads"
  bool takesValue = true;
  bool present = false;
  std::string value;
};
// Parses --runs N, --quick and the `extra` options from argv; prints `usage` and exits on --help
// (status 0) and on anything unknown or malformed (status 2).
CommonOptions parseCommonOptions(int argc, char** argv, const std::string& usage,
                                 std::vector<ExtraOption>* extra = nullptr);

// Prints the machine, the load and the build type once at the top of every program's output.
void printHeader(const std::string& title, const CommonOptions& options);

}  // namespace glint::bench
