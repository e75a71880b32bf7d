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

// Memory model of a mesh for the estimate checked before loading (DESIGN.md §7): glint keeps the
// file's triangles (MeshFile, in the MeshCache) and, per mesh object, a world-space copy that the
// Aggregate then owns; each copy is meshCopyBytes (mesh_file.h). The 4-wide BVH adds about
// kBvhBytesPerTriangle (nodes and leaf references: measured 58 B per triangle for mesh + tree with
// 0.5 vertices per triangle, i.e. 36 B of mesh and 22 B of tree; bench/build_memory).
inline constexpr double kBvhBytesPerTriangle = 22;

// An upper bound of what an OBJ's or STL's estimate can count against a budget (the cached copy,
// the world copy and the BVH: 96 B per vertex, 46 B per triangle) per byte of the file: a counted
// `v` line takes at least 2 bytes ("v" and its newline), an `f` line of c corners at least 2c + 2
// for its c − 2 triangles, an ASCII STL `facet` line 6, a binary STL triangle 50. MeshCache skips
// the estimate's scan of the file when kMeshBudgetBytesPerFileByte × size + one vertex
// (kMeshBudgetSlackBytes, for a last line without its newline) already fits the budget.
inline constexpr double kMeshBudgetBytesPerFileByte = 48;
inline constexpr double kMeshBudgetSlackBytes = 96;

// With a MeshBudget, every load also counts toward the scene's memory estimate: a file not yet read
// is estimated (estimateMeshSize) — its cached copy, the object's world copy and the BVH's share —
// and refused with MeshTooLargeError before anything of it is read when the meshes so far, this
// one and the budget's other bytes (the film) would exceed the limit. After the read the estimate
// is replaced by the real sizes.
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
  // Files actually read (not served from the cache).
  std::size_t filesRead() const { return filesRead_; }
  // Estimated bytes of every mesh loaded with a budget so far: cached files, world copies, BVH.
  double meshBytes() const { return meshBytes_; }

 private:
  struct Entry {
    std::shared_ptr<const MeshFile> file;
    std::string error;  // when file is null
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
