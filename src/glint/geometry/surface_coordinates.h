// Surface (u, v) coordinates of every shape and of mesh triangles, with the partial derivatives a
// texture lookup and a tangent-space normal map need (DESIGN.md §9). Computed after the closest hit
// is known, only for textured materials: intersection itself never pays for them.
#pragma once

#include <cstdint>

#include "glint/core/vec.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/triangle_mesh.h"

namespace glint {

// (u, v) at a surface point and its derivatives, all in the space of the point passed in (object
// space for a shape, world space for a mesh). dndu and dndv are the change of the unit shading
// normal along u and v (zero on flat surfaces); they carry ray differentials through curved
// mirrors. `tangent` and `bitangent` span the tangent space of a normal map: dpdu and dpdv, or a
// mesh's per-vertex tangent frame; only their directions matter.
struct SurfaceCoordinates {
  Point2 uv;
  Vec3 dpdu;
  Vec3 dpdv;
  Vec3 dndu;
  Vec3 dndv;
  Vec3 tangent;
  Vec3 bitangent;
};

// The two in-plane axes a flat surface with unit normal n takes for (u, v): u along
// normalize(h × n) and v along n × u, with h = +y (h = −z when n is within 2.6° of ±y). So a floor
// (n = +y) has u along +x and v along −z, a wall facing +z has u along +x and v along +y: an image
// on either reads upright to a camera looking at it with +y up.
void planeAxes(const Vec3& n, Vec3& uAxis, Vec3& vAxis);

// The conventions, per shape (p in the shape's own space, on its surface):
//   sphere: u = 0.5 + atan2(d.x, −d.z)/(2π), v = 1 − acos(d.y)/π for d = (p − center)/radius;
//   plane: planeAxes coordinates of p − point, in scene units (one unit of u per scene unit);
//   triangle: the barycentric coordinates of vertices[1] and vertices[2];
//   rectangle: corner (0, 0), corner + edges[0] (1, 0), corner + edges[1] (0, 1);
//   polygon, quadrangle: planeAxes of the normal, scaled so that the shape's bounding rectangle
//     in those axes is [0, 1]²;
//   disk: planeAxes of its normal, the disk inscribed in [0, 1]² (centre at (0.5, 0.5));
//   tube: u = angle about the axis / 360° from planeAxes(axis)'s u axis, counter-clockwise seen
//     from the axis' tip; v = distance along the axis from origin, in scene units;
//   cylinder: the side as the tube with v = 0 at the base and 1 at the top; each cap as a disk
//     with the cap's outward normal;
//   box: each face its own [0, 1]² with planeAxes of the face's outward normal;
//   csg: those of its operand `part` (ShapeHit::part; csgSurfaceCoordinates in csg.h).
SurfaceCoordinates surfaceCoordinates(const Shape& shape, const Point3& p, std::uint32_t part = 0);

// (u, v) of a mesh triangle at point p (world space) from the mesh's per-vertex uvs, or the
// barycentric coordinates of its second and third corner when the mesh has none. Smooth meshes
// give dndu, dndv from their vertex normals; meshes with tangents give their interpolated frame.
SurfaceCoordinates surfaceCoordinates(const TriangleMesh& mesh, std::uint32_t triangle,
                                      const Point3& p);

// Per-vertex tangents of a mesh with uvs and normals (MikkTSpace-like): every triangle's dp/du and
// dp/dv from its uvs, summed at its corners weighted by the corner angle, made orthogonal to the
// vertex normal (Gram–Schmidt); the sign says whether n × t points along dp/dv (+1) or against it
// (−1, a mirrored uv layout). Vertices whose triangles have no usable uvs get an arbitrary
// tangent. Fills mesh.tangents; does nothing without uvs and normals.
void computeMeshTangents(TriangleMesh& mesh);

}  // namespace glint
