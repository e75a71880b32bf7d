// A mesh file as glint keeps it (MeshFile: flat TriangleMeshes in the file's own units and axes,
// with its materials mapped onto glint's), the one call that reads it, and its instancing into
// world space for one mesh object (DESIGN.md §5 `mesh`).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/file_access.h"
#include "glint/core/transform.h"
#include "glint/geometry/triangle_mesh.h"
#include "glint/scene/material.h"

namespace glint {

// Triangles one scene may hold in all its meshes together (2^28 ≈ 268 million: with vertices,
// normals and indices in double precision that is already 10–20 GiB). Beyond it the file is a
// mistake or the wrong machine, refused before glint copies the data.
inline constexpr std::uint64_t kMaxMeshTriangles = std::uint64_t{1} << 28;

// Corners one polygon of a mesh file may have. assimp triangulates a polygon in time quadratic in
// its corners (a 40,000-corner face: 0.8 s, 400,000: past the reader's 30 s), and its ASCII PLY
// reader takes any list count, reading zeros past the end of the file: a 2 KB file made a
// 400,000-corner face. Real models' polygons (caps of cylinders, n-gons of modellers) have tens
// to a few thousand corners.
inline constexpr std::uint32_t kMaxFaceCorners = 16384;

// Crease angle of generated smooth normals (degrees; generateSmoothNormals): the normal at a
// corner of a triangle averages the normals of the triangles around that vertex whose normals are
// within this angle of the corner's own triangle. Edges sharper than it — a box's 90° edges — stay
// hard; the smooth surfaces of a finely divided model get one normal per vertex.
inline constexpr double kMeshCreaseAngleDegrees = 80;
// Corners at one position beyond which generated normals stop comparing them pairwise (see
// generateSmoothNormals): each keeps its own triangle's normal.
inline constexpr std::uint32_t kMaxSmoothedCorners = 1024;

// Bytes of one copy of a mesh's arrays (TriangleMesh, double precision): 24 B per position and
// 24 B per normal, 12 B of indices per triangle.
inline constexpr double kMeshBytesPerVertex = 48;
inline constexpr double kMeshBytesPerTriangle = 12;

// Bytes of one copy of a mesh (positions, normals, indices) of that size.
double meshCopyBytes(double triangles, double vertices);

// Why a mesh file could not be loaded, in words for the user (what() names no file: the scene
// builder names the file as the scene wrote it, at the mesh object's place).
class MeshLoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A reason that names its place in the mesh file ("invalid file: line 4, column 7: vertex index 9
// is past the file's 3 vertices", as the OBJ reader words it; the reason travels as text from the
// mesh reader): that line and column, and the reason without them ("invalid file: vertex ...").
struct MeshErrorPlace {
  int line = 0;
  int column = 0;
  std::string reason;
};
std::optional<MeshErrorPlace> meshErrorPlace(const std::string& reason);

// A material of a mesh file mapped onto glint's (Phong/Whitted) coefficients:
//   diffuse colour → kd, and ka = kd so the ambient light shows the colour as glint's scenes do
//   (files' own ambient colours are mostly exporter defaults: 0, 0.2 or 1);
//   specular colour → ks, shininess (Phong exponent, AI_MATKEY_SHININESS) → shininess;
//   emissive colour → emission; opacity < 1 → kt = 1 − opacity, with the refraction index → ior.
// Textures (MeshTexture) are named, not read: the scene builder reads them (DESIGN.md §9).
// Vertex colours and PBR parameters other than the base colour are ignored.
// A material assimp made up because the file has none (STL, PLY, OBJ without MTL, an OBJ's
// `usemtl` of a name no MTL file defines) is kMeshDefaultMaterial instead, with fromFile false.
// A texture a mesh file's material names: a file, as the mesh file wrote it (relative to the mesh
// file's folder), or an image embedded in the mesh file (a .glb's buffers, a data: URI).
struct MeshTexture {
  std::string file;            // empty when embedded or absent
  std::int32_t embedded = -1;  // index into MeshFile::embeddedImages, or -1
  bool present() const { return !file.empty() || embedded >= 0; }
};

// The texture slots of a mesh material: OBJ/MTL map_Kd, map_Ks, map_Ke, map_Bump/bump, norm;
// glTF baseColorTexture, emissiveTexture, normalTexture.
enum MeshTextureSlot : std::uint8_t {
  kDiffuseTexture,
  kSpecularTexture,
  kEmissiveTexture,
  kNormalTexture,
  kBumpTexture,
  kMeshTextureSlots
};

struct MeshMaterial {
  std::string name;  // as in the file; may be empty
  Material material;
  Color emission;
  bool fromFile = true;
  std::array<MeshTexture, kMeshTextureSlots> textures{};
  bool textured() const {
    for (const MeshTexture& t : textures) {
      if (t.present()) return true;
    }
    return false;
  }
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
  // The compressed bytes (PNG, JPEG, ...) of the images the materials' textures embed.
  std::vector<std::vector<std::uint8_t>> embeddedImages;
  // Triangles of the file that are not in `parts`: zero area (twice the area ≤ 1e-12 · longest
  // edge², the same bound as a scene's triangle), a non-finite vertex, or a vertex index out of
  // range.
  std::size_t droppedTriangles = 0;
  // The importer itself left out faces with a vertex index out of range, without a count
  // (assimp's glTF readers): reported in a warning.
  bool importerDroppedFaces = false;
  // Textures the materials name that glint does not use, as "map_Ka 'wood.png'" (an OBJ's
  // ambient, opacity, shininess, reflection and displacement maps): reported in a warning.
  std::vector<std::string> ignoredTextures;  // at most kMaxIgnoredTextures
  // An OBJ's `mtllib` files that are not there, as the file names them (at most
  // kMaxIgnoredTextures), and the library read instead: the OBJ's own name with .mtl, when that
  // is there ("" otherwise). Reported in a warning.
  std::vector<std::string> missingMaterialLibraries;
  std::string fallbackMaterialLibrary;
  // Of the parts whose normals glint generated (generateSmoothNormals, mesh_repair.h): those whose
  // vertices are smoothed with the vertices at exactly their position only (their smoothing radius
  // reached too many: a far outlier), and the positions whose corners kept their own faces'
  // normals (more than kMaxSmoothedCorners corners). Reported in warnings.
  std::size_t exactPositionNormalParts = 0;
  std::size_t crowdedNormalPositions = 0;

  std::size_t triangleCount() const;
};
inline constexpr std::size_t kMaxIgnoredTextures = 16;

// How a mesh file is read, besides its path.
struct MeshReadOptions {
  // The scene file's folder. The files a mesh file names (MTL libraries, glTF buffers and images)
  // must lie in this folder or below, or, for a mesh file outside it, in the mesh file's own
  // folder or below; empty: always the mesh file's own folder (ReferencedFileRule, file_access.h).
  std::filesystem::path sceneFolder{};
  // Polled while the file is read (waiting for the import child, checking its answer, scanning the
  // file for the estimate); once set, the child is killed at once and the read throws Cancelled
  // (core/cancel.h). Not owned; may be null.
  const std::atomic<bool>* cancel = nullptr;
};

// Reads and converts a mesh file. Throws MeshLoadError: no such file, a folder or other non-regular
// file, unreadable, an extension not in kMeshExtensions, a PLY header declaring more elements
// than the file can hold or more faces than kMaxMeshTriangles (checked before assimp
// reserves memory for them), a file assimp rejects (its reason), no triangles, more than
// kMaxMeshTriangles, or more than half the machine's memory. Files the mesh file refers to (MTL,
// glTF buffers) are opened only when they are regular files (never a device or a pipe) inside the
// folder tree of MeshReadOptions::sceneFolder; one that is not refuses the mesh file, naming it. A
// PLY header must end (end_header) within 64 KiB; a glTF strip or fan primitive needs its vertices.
// assimp runs in a child process (fork) that sends the result back through a pipe: fuzzing found
// memory corruption inside assimp 5.2's importers, which there becomes a refused file ("the mesh
// library crashed reading it") instead of a crashed or corrupted renderer. Plain OBJ files are
// parsed in that child by glint's own parser (obj_fast_parse.h), with the same result to the bit.
// Throws Cancelled when options.cancel is set.
MeshFile readMeshFile(const std::filesystem::path& path, const MeshReadOptions& options = {});

// The world-space meshes of one mesh object: every part of `file` with `worldFromFile` applied —
// positions by the transform, normals by its inverse transpose, renormalised; a transform that
// mirrors (negative determinant) also reverses each triangle's index order so the geometric normal
// (right-hand rule) keeps its side relative to the vertex normals. Without `smooth` the normals are
// dropped (flat shading). Material indices and emission are copied from the file; the caller maps
// them onto the scene's materials. Polls `cancel` (may be null) as it goes and throws Cancelled
// once it is set.
// With `uvs` the parts' texture coordinates are copied too (else left out).
std::vector<TriangleMesh> instantiateMesh(const MeshFile& file,
                                          const std::optional<Transform>& worldFromFile,
                                          bool smooth, const std::atomic<bool>* cancel = nullptr,
                                          bool uvs = false);

// The reason a mesh file is refused, in the user's words: "no such file", "it is a folder, not a
// mesh file", "it is not a regular file", or the system's reason.
std::string meshFileRefusal(const ReadableFile& file);

// openForReading for a mesh file itself: a refusal throws MeshLoadError (meshFileRefusal).
ReadableFile openMeshFile(const std::filesystem::path& path);

}  // namespace glint
