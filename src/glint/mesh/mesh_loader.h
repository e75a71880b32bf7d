// Mesh files (DESIGN.md §5 `mesh`) read through assimp — OBJ with MTL, PLY, STL and glTF 2.0,
// chosen by the file's extension; assimp's other importers are never reached — into flat
// TriangleMeshes in the file's own units and axes, their memory estimated before reading, and their
// instancing into world space for one mesh object.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/transform.h"
#include "glint/geometry/triangle_mesh.h"
#include "glint/scene/material.h"

namespace glint {

// Triangles one scene may hold in all its meshes together (2^28 ≈ 268 million: with vertices,
// normals and indices in double precision that is already 10–20 GiB). Beyond it the file is a
// mistake or the wrong machine, refused before glint copies the data.
inline constexpr std::uint64_t kMaxMeshTriangles = std::uint64_t{1} << 28;
// A mesh file is read by assimp in a child process, which may take kMeshReadBaseSeconds plus
// kMeshReadSecondsPerMiB per MiB of the file; past that it is stopped and the file refused (an
// importer that loops on a malformed file must not hang glint).
inline constexpr double kMeshReadBaseSeconds = 30;
inline constexpr double kMeshReadSecondsPerMiB = 2;

// Crease angle of generated smooth normals (degrees; assimp's GenSmoothNormals): the normal at a
// corner of a triangle averages the normals of the triangles around that vertex whose normals are
// within this angle of the corner's own triangle. Edges sharper than it — a box's 90° edges — stay
// hard; the smooth surfaces of a finely divided model get one normal per vertex.
inline constexpr double kMeshCreaseAngleDegrees = 80;

// The file extensions glint reads (lower case, any case in the path), one assimp importer each:
// OBJ (+ its MTL), PLY (ASCII and binary), STL (ASCII and binary) and glTF 2.0 (.gltf with its .bin
// files or data URIs, .glb). Any other extension is refused without opening the file, so that none
// of assimp's ~60 other importers (rarely used formats, less hardened) sees hostile input: OFF,
// for one, is not read — fuzzing crashed assimp 5.2's OFF importer within seconds.
inline constexpr const char* kMeshExtensions[] = {".obj", ".ply", ".stl", ".gltf", ".glb"};

// Memory model of a mesh for the estimate checked before loading (DESIGN.md §7): glint keeps the
// file's triangles (MeshFile, in the MeshCache) and, per mesh object, a world-space copy that the
// Aggregate then owns; each copy holds 24 B per position, 24 B per normal (double precision) and
// 12 B per triangle of indices. The 4-wide BVH adds about kBvhBytesPerTriangle (nodes and leaf
// references: measured 58 B per triangle for mesh + tree with 0.5 vertices per triangle, i.e.
// 36 B of mesh and 22 B of tree; bench/build_memory).
inline constexpr double kMeshBytesPerVertex = 48;
inline constexpr double kMeshBytesPerTriangle = 12;
inline constexpr double kBvhBytesPerTriangle = 22;

// Why a mesh file could not be loaded, in words for the user (what() names no file: the scene
// builder names the file as the scene wrote it, at the mesh object's place).
class MeshLoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A material of a mesh file mapped onto glint's (Phong/Whitted) coefficients:
//   diffuse colour → kd, and ka = kd so the ambient light shows the colour as glint's scenes do
//   (files' own ambient colours are mostly exporter defaults: 0, 0.2 or 1);
//   specular colour → ks, shininess (Phong exponent, AI_MATKEY_SHININESS) → shininess;
//   emissive colour → emission; opacity < 1 → kt = 1 − opacity, with the refraction index → ior.
// Textures, vertex colours and PBR parameters other than the base colour are ignored.
// A material assimp made up because the file has none (STL, PLY, OBJ without MTL) is
// kMeshDefaultMaterial instead, with fromFile false.
struct MeshMaterial {
  std::string name;  // as in the file; may be empty
  Material material;
  Color emission;
  bool fromFile = true;
};

// What a mesh without any material of its own looks like: mid grey, lit by lights and ambient
// (the scene format's default material, kd 0, would render black under lights).
inline constexpr Material kMeshDefaultMaterial = [] {
  Material m;
  m.kd = Color(0.7);
  m.ka = Color(0.7);
  return m;
}();

// A mesh file as read: one TriangleMesh per assimp mesh (= per material after assimp's
// PreTransformVertices step bakes the node hierarchy), positions and normals in the file's units
// and axes. Every part has vertex normals — the file's own (OBJ vn, PLY nx ny nz, glTF NORMAL)
// where it has them, else generated smooth normals (crease angle kMeshCreaseAngleDegrees); STL
// facet normals are not vertex normals and are replaced by generated ones.
// TriangleMesh::materialIndex indexes `materials`; emission is left black (it belongs to the
// material until instancing).
struct MeshFile {
  std::vector<TriangleMesh> parts;
  std::vector<MeshMaterial> materials;
  // Triangles of the file that are not in `parts`: zero area (twice the area ≤ 1e-12 · longest
  // edge², the same bound as a scene's triangle), a non-finite vertex, or a vertex index out of
  // range.
  std::size_t droppedTriangles = 0;

  std::size_t triangleCount() const;
};

// Reads and converts a mesh file. Throws MeshLoadError: no such file, a folder or other non-regular
// file, unreadable, an extension not in kMeshExtensions, a PLY header declaring more elements
// than the file can hold or more faces than kMaxMeshTriangles (checked before assimp
// reserves memory for them), a file assimp rejects (its reason), no triangles, more than
// kMaxMeshTriangles, or more than half the machine's memory. Files the mesh file refers to (MTL,
// glTF buffers) are opened only when they are regular files: never a device or a pipe. A PLY
// header must end (end_header) within 64 KiB; a glTF strip or fan primitive needs its vertices.
// assimp runs in a child process (fork) that sends the result back through a pipe: fuzzing found
// memory corruption inside assimp 5.2's importers, which there becomes a refused file ("the mesh
// library crashed reading it") instead of a crashed or corrupted renderer.
MeshFile readMeshFile(const std::filesystem::path& path);

// The size of a mesh file's content, known before it is read: from the header (PLY element
// counts, the binary STL triangle count), by counting lines without storing them (OBJ
// `f` corners and `v` lines, ASCII STL facets), or bounded by the bytes (glTF: ~12 bytes per
// triangle for 16-bit indices and shared vertices, counting the .gltf and the local files its
// `uri`s name). Polygons count as their fan of n − 2 triangles where the corners are known (OBJ),
// as one triangle per face where only the face count is (PLY).
struct MeshSizeEstimate {
  std::uint64_t triangles = 0;
  std::uint64_t vertices = 0;
};

// Throws MeshLoadError for the same unreadable files as readMeshFile (missing, folder, device,
// extension, header counts the file cannot hold).
MeshSizeEstimate estimateMeshSize(const std::filesystem::path& path);

// An upper bound of what an OBJ's or STL's estimate can count against a budget (the cached copy,
// the world copy and the BVH: 96 B per vertex, 46 B per triangle) per byte of the file: a counted
// `v` line takes at least 2 bytes ("v" and its newline), an `f` line of c corners at least 2c + 2
// for its c − 2 triangles, an ASCII STL `facet` line 6, a binary STL triangle 50. MeshCache skips
// the estimate's scan of the file when kMeshBudgetBytesPerFileByte × size + one vertex
// (kMeshBudgetSlackBytes, for a last line without its newline) already fits the budget.
inline constexpr double kMeshBudgetBytesPerFileByte = 48;
inline constexpr double kMeshBudgetSlackBytes = 96;

// Bytes of one copy of a mesh (positions, normals, indices) of that size.
double meshCopyBytes(double triangles, double vertices);

// Every file read at most once per cache — keyed by the canonical path, so "a.obj" and "./a.obj"
// are one file. A failure is remembered too and thrown again. One cache lives for one scene load.
//
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

class MeshCache {
 public:
  // The file's content, shared by every caller asking for the same file. Throws MeshLoadError.
  std::shared_ptr<const MeshFile> load(const std::filesystem::path& path);
  // The same, counted against `budget` as one more mesh object. Throws MeshTooLargeError (not
  // remembered: the file itself is fine) or MeshLoadError.
  std::shared_ptr<const MeshFile> load(const std::filesystem::path& path, const MeshBudget& budget);
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
                                       const std::filesystem::path& path);
  std::map<std::filesystem::path, Entry> entries_;
  std::size_t filesRead_ = 0;
  double meshBytes_ = 0;
};

// The world-space meshes of one mesh object: every part of `file` with `worldFromFile` applied —
// positions by the transform, normals by its inverse transpose, renormalised; a transform that
// mirrors (negative determinant) also reverses each triangle's index order so the geometric normal
// (right-hand rule) keeps its side relative to the vertex normals. Without `smooth` the normals are
// dropped (flat shading). Material indices and emission are copied from the file; the caller maps
// them onto the scene's materials.
std::vector<TriangleMesh> instantiateMesh(const MeshFile& file,
                                          const std::optional<Transform>& worldFromFile,
                                          bool smooth);

}  // namespace glint
