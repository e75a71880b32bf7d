// Constructive solid geometry (DESIGN.md §11): the tree of a `csg` object — its operand solids
// (sphere, box, cylinder, closed triangle mesh), each placed by its own transform, combined by
// union, intersection and difference — and the ray queries of the Csg shape (shape.h).
//
// Algorithm (Roth 1982, "Ray casting for modeling solids"): along a ray, every operand is a set of
// intervals where the ray is inside it. Rather than building the interval lists, the query walks
// the operands' surface crossings in order of t with one cursor per operand (no allocation per
// ray): the operands' inside/outside states at tMin are known first, then at each crossing the
// crossed operand's state is set (entering or leaving it), the boolean tree is evaluated on the
// states, and where the combined state changes the ray crosses the result's surface. Crossings of
// several operands at exactly the same t are applied together before the tree is evaluated, so a
// face two unioned boxes share is no surface. The normal is the crossed operand's outward normal,
// flipped where the ray enters the result while leaving that operand (a subtracted operand's
// surface) or the other way round.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include "glint/core/bounds.h"
#include "glint/core/color.h"
#include "glint/core/ray.h"
#include "glint/core/transform.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/surface_coordinates.h"

namespace glint {

enum class CsgOperation : std::uint8_t { Union, Intersection, Difference };

// At most this many operand solids in one csg (nested csgs' operands included): a ray query keeps
// one cursor per solid on the stack and the inside states in one 64-bit mask.
inline constexpr std::size_t kMaxCsgSolids = 64;
// At most this many levels of csg inside csg (the outermost is level 1): hostile files cannot make
// the builder recurse without bound.
inline constexpr int kMaxCsgDepth = 16;

// A closed, consistently oriented triangle mesh as a csg operand, in its own space: every edge is
// shared by exactly two triangles that run along it in opposite directions (checked by make), and
// the triangles wind counter-clockwise seen from outside (make reverses an inside-out mesh), so
// (p1 − p0) × (p2 − p0) points out of the solid. Crossings come from the watertight triangle test
// over a binary BVH of its triangles.
struct CsgMesh {
  struct Node {
    Bounds3 bounds;
    std::uint32_t first = 0;  // leaf: first triangle; inner: index of the second child
    std::uint32_t count = 0;  // leaf: number of triangles (> 0); inner: 0, first child follows
  };
  std::vector<Point3> positions;
  std::vector<std::uint32_t> indices;  // three per triangle, in BVH leaf order
  std::vector<Node> nodes;             // depth-first; nodes[0] is the root

  // Throws ShapeError("file") naming the first open or inconsistently oriented edge (vertices are
  // matched by position, so files that repeat a vertex per face, as STL does, still close).
  static std::shared_ptr<const CsgMesh> make(std::vector<Point3> positions,
                                             std::vector<std::uint32_t> indices);
  // Closest crossing in (tMin, tMax); the normal is the triangle's unit outward normal.
  bool intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const;
  Bounds3 bounds() const { return nodes.empty() ? Bounds3() : nodes[0].bounds; }
  std::size_t triangleCount() const { return indices.size() / 3; }
};

// The closed shapes a csg may combine.
using CsgSolid = std::variant<Sphere, Box, Cylinder, std::shared_ptr<const CsgMesh>>;

// One operand solid: where it is and what its surface is made of.
struct CsgOperand {
  CsgSolid solid;
  std::shared_ptr<const Transform> csgFromSolid;  // null: the solid is in the csg's space
  Bounds3 bounds;                                 // in the csg's space
  std::uint32_t materialIndex = 0;                // into SceneParts::materials
  Color emission;
  Color transmission{1};  // the factor a shadow ray keeps per crossing (the material's kt)
};

// The boolean tree in postorder: a solid pushes its inside state, an operation pops `count`
// states (its operands, in order) and pushes their combination.
struct CsgNode {
  bool isSolid = true;
  CsgOperation operation = CsgOperation::Union;
  std::uint32_t value = 0;  // solid: index into operands; operation: its number of operands
};

struct CsgTree {
  std::vector<CsgOperand> operands;
  std::vector<CsgNode> postorder;
  Bounds3 bounds;  // in the csg's space: union's of all, intersection's overlap, difference's first
  int depth = 0;   // levels of operations (a lone solid: 0)
};

// A csg of one solid: the leaf an operand starts as. Throws ShapeError("transform") for a
// transform that is not invertible affine.
Csg makeCsgSolid(CsgSolid solid, const std::optional<Transform>& csgFromSolid,
                 std::uint32_t materialIndex, const Color& emission);
// `operation` over `operands` (each a solid or a csg; difference: the first minus all others).
// Throws ShapeError("operands") for fewer than two operands, more than kMaxCsgSolids solids in all,
// or nesting deeper than kMaxCsgDepth.
Csg combineCsg(CsgOperation operation, const std::vector<Csg>& operands);
// The same csg moved by `transform` (applied after each operand's own).
Csg transformCsg(const Csg& csg, const Transform& transform);
// The same csg with operand i's transmission set to transmission[i].
Csg withCsgTransmission(const Csg& csg, const std::vector<Color>& transmission);

// Product of the crossed operands' transmission over every crossing of the csg's surface in
// (tMin, tMax), in the csg's space.
Color csgTransmittance(const Csg& csg, const Ray& ray, double tMin, double tMax);

// Surface coordinates at point p (csg space) on operand `part`: the solid's own (u, v)
// (surface_coordinates.h; a mesh operand: each face of its bounding box as a box's), with the
// derivatives carried into the csg's space.
SurfaceCoordinates csgSurfaceCoordinates(const Csg& csg, std::uint32_t part, const Point3& p);

}  // namespace glint
