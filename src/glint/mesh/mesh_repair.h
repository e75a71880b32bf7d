// Repairs of what assimp reads, before and after its post-processing, and the conversion into
// glint's TriangleMesh: faces with invalid indices dropped, shared corners split so that generated
// normals follow the crease angle, degenerate triangles dropped, vertices of equal position and
// normal joined, invalid normals rebuilt. Internal to the mesh loader (run in its import child).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "glint/geometry/triangle_mesh.h"
#include "glint/mesh/mesh_file.h"

struct aiMesh;
struct aiScene;

namespace glint {

struct SimpleObj;

// Removes, in place, every face that has no index or one past the mesh's vertices, before
// assimp's post-processing steps (which index vertex arrays without checking) see it. Most
// importers check their indices (OBJ refuses the file); PLY, for one, does not. Returns the
// triangles removed. Faces of one or two indices (points, lines) stay for SortByPType to remove.
std::size_t dropInvalidFaces(aiScene& scene);

// Gives every face corner of a mesh without normals its own vertex, before generateSmoothNormals.
// That step (as assimp's GenSmoothNormals) first stores each face's normal at its vertices — a
// vertex shared by several faces keeps only the last one — and then averages the normals of the
// vertices at the same position within the crease angle. Indexed files (PLY, glTF) share a vertex
// among all faces around it, so a smooth surface got one face's normal per vertex (faceted,
// lopsided shading) and a crease could not be kept. One vertex per corner, as assimp's OBJ and STL
// importers already give, lets every corner average exactly the faces within the crease angle;
// glint's join (joinMesh) shares them again afterwards. The first set of texture coordinates
// follows the corners; colours, tangents and further sets are dropped (glint reads none of them);
// meshes with bones are left alone (their weights index the vertices).
void splitSharedCorners(aiScene& scene);

// Vertex normals for a mesh without them (after splitSharedCorners and assimp's triangulation), as
// assimp's GenSmoothNormals step defines them but in O(n) instead of its spatial sort's O(n^1.5)
// (7.5 s of a 1M-triangle file's load): each vertex first takes the unit normal of the last face
// that uses it (p1 − p0) × (p_last − p0); then its normal is the normalised sum of those normals
// over the vertices within epsilon of its position (1e-4 of the mesh's bounding-box diagonal)
// whose normal lies within `creaseDegrees` of its own (itself always). Vertices within epsilon are
// found through a grid of cells 4 epsilon wide over the distinct positions. Computed in double
// precision, stored as floats; a vertex of no face gets NaN (convertMesh rebuilds it or drops it).
//
// Comparing the vertices near each other pairwise is quadratic where many are near one another,
// so two limits keep hostile or broken files from taking hours (a 200k-triangle fan took 41 s):
// when epsilon reaches across many vertices (one far outlier makes it reach across the model) and
// the comparisons pass a budget of kMaxSmoothedCorners per vertex, the search starts over with the
// vertices at exactly the same position only (SmoothNormalsReport::exactPositionsOnly; −0 and +0
// are one position); and the vertices at a position shared by more than kMaxSmoothedCorners
// corners (the apex of a huge fan) keep their own face's normal (crowdedPositions). The models of
// Debian's assimp test set stay far below both (so does a UV sphere of 256 × 128 on a ground 600
// times its size), so their normals follow the definition.
// (kMaxSmoothedCorners: mesh_file.h)
struct SmoothNormalsReport {
  bool exactPositionsOnly = false;
  std::size_t crowdedPositions = 0;
};
SmoothNormalsReport generateSmoothNormals(aiMesh& mesh, double creaseDegrees);

// Faces of at least three corners in all meshes of the scene.
std::size_t facesWithTriangles(const aiScene& scene);

// One assimp mesh's triangles with the degenerate ones left out, over joined vertices: the
// vertices of equal position, normal and texture coordinates (VertexKey) are one, numbered in order
// of first use by the kept triangles. assimp's importers give OBJ and STL one vertex per face
// corner; glint joins them here, exactly and in O(n) with a hash table, instead of assimp's
// JoinIdenticalVertices (which compares within an epsilon through a spatial sort: ~0.1 s of a 0.3 s
// load for a 100k-triangle OBJ). generateSmoothNormals has already run (before any join), so the
// normals of a crease differ and its vertices stay split.
struct JoinedMesh {
  std::vector<std::uint32_t> indices;  // three per kept triangle, into `source`
  std::vector<std::uint32_t> source;   // the assimp vertex each joined vertex copies
};

// Adds the triangles left out to `dropped`.
JoinedMesh joinMesh(const aiMesh& in, std::size_t& dropped);

// One assimp mesh (triangulated, its node transforms baked), joined, → a TriangleMesh in file
// space, with the first set of texture coordinates as its uvs. Invalid vertex normals (zero or not
// finite) are rebuilt from the triangles around the vertex.
TriangleMesh convertMesh(const aiMesh& in, JoinedMesh&& joined);

// convertMesh(joinMesh(m)) for the mesh m that assimp's OBJ importer, its post-processing and
// glint's repairs above make of an OBJ file of the simple subset (obj_fast_parse.h) whose faces
// are all triangles and whose corners all name a normal — where those steps change nothing (no
// polygon to triangulate, no normal to generate, no invalid index, no node transform) — read
// straight from the file's arrays instead of from a vertex per face corner: the same TriangleMesh.
// Adds the triangles left out to `dropped`.
TriangleMesh joinSimpleObj(const SimpleObj& obj, std::size_t& dropped);

}  // namespace glint
