// The mesh files of one scene load, each read once however many objects use it, and the memory
// estimate that refuses a mesh object before its file is read (DESIGN.md §7).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "glint/mesh/mesh_file.h"

namespace glint {

// Memory model of a mesh object, checked before its file is read (DESIGN.md §7). The peak comes
// while the scene's BVH is built (accel/aggregate.cpp, accel/bvh4.cpp), when glint holds for every
// mesh object its world-space copy (meshCopyBytes, mesh_file.h; the Aggregate keeps it) and its
// share of the build, kBvhBuildBytesPerTriangle:
//  - kBvhReferenceBytesPerTriangle: one bvh::BuildItem per triangle, held until the tree is built;
//  - the tree's 128 B nodes twice over, while bvh::build copies them into an array of their exact
//    size. Connected surfaces (modelled and scanned meshes, scenes/meshes/torus_knot.obj) take
//    17–19 B of nodes per triangle, a soup of tiny disconnected triangles up to 37 B:
//    kBvhNodeBytesPerTriangle allows for that.
// While it reads the files the MeshCache also holds each file's own copy once (meshCopyBytes),
// which the estimate counts too (the Aggregate's reordering holds a second copy of a mesh for a
// moment). Measured with `glint check` on 2 CPUs for N copies of torus_knot.obj (38,400
// triangles, 19,200 vertices): the peak resident memory grows by 4.1–4.6 MB per copy, 1.4 MB of
// them the world copy; the estimate is 5.4 MB. The build's peak grows with its threads (buffers
// freed in per-thread heaps are not given back): a 40,000-triangle grid peaks at 4.5 MB per copy
// on one CPU, 5.1 MB on two, against 5.7 MB estimated. After the build the tree keeps ~18 B per
// triangle.
inline constexpr double kBvhReferenceBytesPerTriangle = 32;
inline constexpr double kBvhNodeBytesPerTriangle = 36;
inline constexpr double kBvhBuildBytesPerTriangle =
    kBvhReferenceBytesPerTriangle + 2 * kBvhNodeBytesPerTriangle;

// Bytes one more mesh object of that size adds at the peak: its world copy and its share of the
// BVH build.
double meshInstanceBytes(double triangles, double vertices);

// An upper bound of what an OBJ's or STL's estimate can count against a budget per byte of the
// file: the cached copy, the world copy and the BVH build count 2 × kMeshBytesPerVertex = 96 B
// per vertex and 2 × kMeshBytesPerTriangle + kBvhBuildBytesPerTriangle = 128 B per triangle; a
// counted `v` line takes at least 2 bytes ("v" and its newline), an `f` line of c corners at
// least 2c + 2 for its c − 2 triangles (toward 2 bytes per triangle as c grows), an ASCII STL
// `facet` line 6, a binary STL triangle 50. MeshCache skips the estimate's scan of the file when
// kMeshBudgetBytesPerFileByte × size + one vertex (kMeshBudgetSlackBytes, for a last line without
// its newline) already fits the budget.
inline constexpr double kMeshBudgetBytesPerFileByte =
    (2 * kMeshBytesPerTriangle + kBvhBuildBytesPerTriangle) / 2 > kMeshBytesPerVertex
        ? (2 * kMeshBytesPerTriangle + kBvhBuildBytesPerTriangle) / 2
        : kMeshBytesPerVertex;
inline constexpr double kMeshBudgetSlackBytes = 2 * kMeshBytesPerVertex;

// With a MeshBudget, every load also counts toward the scene's memory estimate: a file not yet read
// is estimated (estimateMeshSize) — its cached copy, the object's world copy and the BVH build's
// share — and refused with MeshTooLargeError before anything of it is read when the meshes so far,
// this one and the budget's other bytes (the film) would exceed the limit. After the read the
// real sizes replace the estimate and are checked again, before the world copy is made; every
// further object using the file counts one more instance (meshInstanceBytes).
struct MeshBudget {
  std::uint64_t limit = 0;       // bytes: LoadOptions::memoryBudget (--max-memory)
  std::uint64_t otherBytes = 0;  // bytes committed outside meshes: the film
};

// A mesh refused by the memory estimate; what() says the estimate and the limit.
class MeshTooLargeError : public MeshLoadError {
 public:
  using MeshLoadError::MeshLoadError;
};

// Every file read at most once per cache — keyed by the canonical path, so "a.obj" and "./a.obj"
// are one file. A failure is remembered too and thrown again. One cache lives for one scene load.
class MeshCache {
 public:
  // The file's content, shared by every caller asking for the same file. Throws MeshLoadError, or
  // Cancelled when options.cancel is set (not remembered). The options of the first read of a
  // file hold for the cache's life: one cache, one scene.
  std::shared_ptr<const MeshFile> load(const std::filesystem::path& path,
                                       const MeshReadOptions& options = {});
  // The same, counted against `budget` as one more mesh object. Throws MeshTooLargeError (not
  // remembered: the file itself is fine) or MeshLoadError.
  std::shared_ptr<const MeshFile> load(const std::filesystem::path& path, const MeshBudget& budget,
                                       const MeshReadOptions& options = {});
  // Takes `file` as the content of `path`, read elsewhere (the quick look's reader): later loads
  // are served from it. The first load with a budget counts it as a fresh read (its copy, the
  // world copy and the BVH build) from its real sizes, without the estimate (which can exceed
  // them: unused vertices); ignored when the file is cached.
  void adopt(const std::filesystem::path& path, std::shared_ptr<const MeshFile> file);
  // Files actually read (not served from the cache or adopted).
  std::size_t filesRead() const { return filesRead_; }
  // Estimated bytes of every mesh loaded with a budget so far: cached files, world copies, BVH
  // build.
  double meshBytes() const { return meshBytes_; }

 private:
  struct Entry {
    std::shared_ptr<const MeshFile> file;
    std::string error;    // when file is null
    bool counted = true;  // false for an adopted file no budgeted load has counted yet
  };
  static std::filesystem::path keyOf(const std::filesystem::path& path);
  std::shared_ptr<const MeshFile> read(const std::filesystem::path& key,
                                       const std::filesystem::path& path,
                                       const MeshReadOptions& options);
  std::map<std::filesystem::path, Entry> entries_;
  std::size_t filesRead_ = 0;
  double meshBytes_ = 0;
};

}  // namespace glint
