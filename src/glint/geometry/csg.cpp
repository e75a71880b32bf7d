// The csg tree's construction (with the closed-mesh check and the mesh operands' BVH) and the ray
// queries of Csg: the crossing walk of csg.h, shared by closest hit, crossing count and shadow
// transmittance.
#include "glint/geometry/csg.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <utility>

#include "glint/geometry/object_space.h"
#include "glint/geometry/watertight_triangle.h"

namespace glint {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Triangles per BVH leaf of a mesh operand.
constexpr std::uint32_t kMeshLeafSize = 4;
// Postorder nodes of a tree: at most kMaxCsgSolids solids and one fewer operations.
constexpr std::size_t kMaxCsgNodes = 2 * kMaxCsgSolids;

// ------------------------------------------------------------------------------ mesh operands

Bounds3 triangleBounds(const CsgMesh& mesh, std::uint32_t triangle) {
  const std::uint32_t* index = mesh.indices.data() + 3 * static_cast<std::size_t>(triangle);
  return unite(Bounds3(mesh.positions[index[0]], mesh.positions[index[1]]),
               mesh.positions[index[2]]);
}

// A binary BVH over triangles [begin, end) of `order` (triangle numbers), split at the median of
// the centroids along the widest axis of their bounds (deterministic: ties by triangle number).
void buildMeshNodes(const CsgMesh& mesh, std::vector<std::uint32_t>& order,
                    const std::vector<Point3>& centroids, std::uint32_t begin, std::uint32_t end,
                    std::vector<CsgMesh::Node>& nodes) {
  Bounds3 bounds;
  Bounds3 centroidBounds;
  for (std::uint32_t k = begin; k < end; ++k) {
    bounds = unite(bounds, triangleBounds(mesh, order[k]));
    centroidBounds = unite(centroidBounds, centroids[order[k]]);
  }
  const auto self = static_cast<std::uint32_t>(nodes.size());
  nodes.push_back({bounds, begin, end - begin});
  if (end - begin <= kMeshLeafSize) return;
  const int axis = centroidBounds.longestAxis();
  const std::uint32_t middle = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) {
                     const double ca = centroids[a][axis];
                     const double cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  nodes[self].count = 0;
  buildMeshNodes(mesh, order, centroids, begin, middle, nodes);
  nodes[self].first = static_cast<std::uint32_t>(nodes.size());
  buildMeshNodes(mesh, order, centroids, middle, end, nodes);
}

std::string showPoint(const Point3& p) { return fmt::format("[{}, {}, {}]", p.x, p.y, p.z); }

}  // namespace

std::shared_ptr<const CsgMesh> CsgMesh::make(std::vector<Point3> positions,
                                             std::vector<std::uint32_t> indices) {
  const std::size_t triangles = indices.size() / 3;
  if (triangles < 4 || indices.size() % 3 != 0) {
    throw ShapeError("file", fmt::format("a mesh in a csg must be a closed surface, got {} "
                                         "triangle{}",
                                         triangles, triangles == 1 ? "" : "s"));
  }
  // Vertices matched by position: the id of the first vertex at each point.
  std::map<std::array<double, 3>, std::uint32_t> firstAt;
  std::vector<std::uint32_t> welded(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const Point3& p = positions[v];
    welded[v] = firstAt.try_emplace({p.x, p.y, p.z}, static_cast<std::uint32_t>(v)).first->second;
  }
  // Every directed edge once, and its reverse once.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  edges.reserve(indices.size());
  for (std::size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      edges.emplace_back(welded[indices[3 * t + k]], welded[indices[3 * t + (k + 1) % 3]]);
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    if (e + 1 < edges.size() && edges[e + 1] == edges[e]) {
      throw ShapeError("file", fmt::format("a mesh in a csg must be a closed, consistently "
                                           "oriented surface: the edge from {} to {} runs the same "
                                           "way in two triangles",
                                           showPoint(positions[a]), showPoint(positions[b])));
    }
    if (!std::binary_search(edges.begin(), edges.end(), std::make_pair(b, a))) {
      throw ShapeError("file",
                       fmt::format("a mesh in a csg must be a closed surface: the edge from "
                                   "{} to {} belongs to only one triangle",
                                   showPoint(positions[a]), showPoint(positions[b])));
    }
  }
  // Signed volume (divergence theorem): negative for an inside-out mesh, whose winding is then
  // reversed so that every normal points out.
  double volume = 0;
  for (std::size_t t = 0; t < triangles; ++t) {
    const Vec3 a = toVec(positions[indices[3 * t]]);
    const Vec3 b = toVec(positions[indices[3 * t + 1]]);
    const Vec3 c = toVec(positions[indices[3 * t + 2]]);
    volume += dot(a, cross(b, c));
  }
  if (volume < 0) {
    for (std::size_t t = 0; t < triangles; ++t) std::swap(indices[3 * t + 1], indices[3 * t + 2]);
  }
  auto mesh = std::make_shared<CsgMesh>();
  mesh->positions = std::move(positions);
  mesh->indices = std::move(indices);
  std::vector<Point3> centroids(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    centroids[t] = triangleBounds(*mesh, static_cast<std::uint32_t>(t)).centroid();
  }
  std::vector<std::uint32_t> order(triangles);
  std::iota(order.begin(), order.end(), 0u);
  buildMeshNodes(*mesh, order, centroids, 0, static_cast<std::uint32_t>(triangles), mesh->nodes);
  std::vector<std::uint32_t> sorted;
  sorted.reserve(mesh->indices.size());
  for (const std::uint32_t t : order) {
    for (int k = 0; k < 3; ++k) sorted.push_back(mesh->indices[3 * t + k]);
  }
  mesh->indices = std::move(sorted);
  return mesh;
}

bool CsgMesh::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  const Vec3 inverse{1 / ray.direction.x, 1 / ray.direction.y, 1 / ray.direction.z};
  const WatertightRay wray(ray);
  // Depth-first, near child first; a median split keeps the depth under 2·log2(triangles) + 1.
  std::array<std::uint32_t, 64> stack;
  int stackSize = 0;
  std::uint32_t node = 0;
  bool found = false;
  WatertightHit best;
  std::uint32_t bestTriangle = 0;
  while (true) {
    const Node& n = nodes[node];
    double enter = 0;
    double exit = 0;
    if (intersectSlabs(n.bounds, ray, inverse, tMin, tMax, enter, exit)) {
      if (n.count > 0) {
        for (std::uint32_t t = n.first; t < n.first + n.count; ++t) {
          const std::uint32_t* index = indices.data() + 3 * static_cast<std::size_t>(t);
          const Point3& p0 = positions[index[0]];
          const Point3& p1 = positions[index[1]];
          const Point3& p2 = positions[index[2]];
          WatertightHit candidate;
          if (!intersectWatertight(wray, p0, p1, p2, tMin, tMax, candidate)) continue;
          if (isParallelToPlane(cross(p1 - p0, p2 - p0), ray.direction)) continue;
          best = candidate;
          bestTriangle = t;
          tMax = candidate.t;
          found = true;
        }
      } else {
        // The child whose centre lies further along the ray waits on the stack.
        const std::uint32_t near = node + 1;
        const std::uint32_t far = n.first;
        const bool flip =
            dot(nodes[far].bounds.centroid() - nodes[near].bounds.centroid(), ray.direction) < 0;
        stack[stackSize++] = flip ? near : far;
        node = flip ? far : near;
        continue;
      }
    }
    if (stackSize == 0) break;
    node = stack[--stackSize];
  }
  if (!found) return false;
  const std::uint32_t* index = indices.data() + 3 * static_cast<std::size_t>(bestTriangle);
  const Point3& p0 = positions[index[0]];
  const Point3& p1 = positions[index[1]];
  const Point3& p2 = positions[index[2]];
  hit.t = best.t;
  hit.normal = Normal3(normalize(cross(p1 - p0, p2 - p0)));
  watertightHitPoint(p0, p1, p2, best, hit.point, hit.pointError);
  return true;
}

// --------------------------------------------------------------------------------- building

namespace {

Bounds3 solidBounds(const CsgSolid& solid) {
  if (const auto* mesh = std::get_if<std::shared_ptr<const CsgMesh>>(&solid)) {
    return (*mesh)->bounds();
  }
  if (const auto* sphere = std::get_if<Sphere>(&solid)) return sphere->bounds();
  if (const auto* box = std::get_if<Box>(&solid)) return box->bounds();
  return std::get<Cylinder>(solid).bounds();
}

Bounds3 operandBounds(const CsgOperand& operand) {
  const Bounds3 own = solidBounds(operand.solid);
  return operand.csgFromSolid ? (*operand.csgFromSolid)(own) : own;
}

// The bounds of every node, from the operands' bounds, in postorder; the root's returned.
Bounds3 treeBounds(const CsgTree& tree) {
  std::vector<Bounds3> stack;
  for (const CsgNode& node : tree.postorder) {
    if (node.isSolid) {
      stack.push_back(tree.operands[node.value].bounds);
      continue;
    }
    const std::size_t first = stack.size() - node.value;
    Bounds3 b = stack[first];
    for (std::size_t k = first + 1; k < stack.size(); ++k) {
      if (node.operation == CsgOperation::Union) {
        b = unite(b, stack[k]);
      } else if (node.operation == CsgOperation::Intersection) {
        b.lo = max(b.lo, stack[k].lo);
        b.hi = min(b.hi, stack[k].hi);
      }
    }
    // An empty overlap holds nothing; a point box keeps the primitive bounded (a ray never hits).
    if (b.isEmpty()) b = Bounds3(stack[first].lo, stack[first].lo);
    stack.resize(first);
    stack.push_back(b);
  }
  return stack.empty() ? Bounds3() : stack.back();
}

}  // namespace

Csg makeCsgSolid(CsgSolid solid, const std::optional<Transform>& csgFromSolid,
                 std::uint32_t materialIndex, const Color& emission) {
  auto tree = std::make_shared<CsgTree>();
  CsgOperand operand;
  operand.solid = std::move(solid);
  if (csgFromSolid && !csgFromSolid->isIdentity()) {
    requireInvertibleAffine(*csgFromSolid);
    operand.csgFromSolid = std::make_shared<const Transform>(*csgFromSolid);
  }
  operand.materialIndex = materialIndex;
  operand.emission = emission;
  operand.bounds = operandBounds(operand);
  tree->operands.push_back(std::move(operand));
  tree->postorder.push_back({true, CsgOperation::Union, 0});
  tree->bounds = tree->operands[0].bounds;
  return Csg{std::move(tree)};
}

Csg combineCsg(CsgOperation operation, const std::vector<Csg>& operands) {
  if (operands.size() < 2) {
    throw ShapeError("operands",
                     fmt::format("a csg needs at least two operands, got {}", operands.size()));
  }
  auto tree = std::make_shared<CsgTree>();
  std::size_t solids = 0;
  for (const Csg& operand : operands) {
    solids += operand.tree->operands.size();
    tree->depth = std::max(tree->depth, operand.tree->depth + 1);
  }
  if (solids > kMaxCsgSolids) {
    throw ShapeError("operands", fmt::format("a csg may combine at most {} shapes in all (nested "
                                             "csgs' included), got {}",
                                             kMaxCsgSolids, solids));
  }
  if (tree->depth > kMaxCsgDepth) {
    throw ShapeError("operands", fmt::format("csgs may be nested at most {} deep", kMaxCsgDepth));
  }
  for (const Csg& operand : operands) {
    const auto offset = static_cast<std::uint32_t>(tree->operands.size());
    for (CsgNode node : operand.tree->postorder) {
      if (node.isSolid) node.value += offset;
      tree->postorder.push_back(node);
    }
    tree->operands.insert(tree->operands.end(), operand.tree->operands.begin(),
                          operand.tree->operands.end());
  }
  tree->postorder.push_back({false, operation, static_cast<std::uint32_t>(operands.size())});
  tree->bounds = treeBounds(*tree);
  return Csg{std::move(tree)};
}

Csg transformCsg(const Csg& csg, const Transform& transform) {
  if (transform.isIdentity()) return csg;
  requireInvertibleAffine(transform);
  auto tree = std::make_shared<CsgTree>(*csg.tree);
  for (CsgOperand& operand : tree->operands) {
    const Transform composed = operand.csgFromSolid ? transform * *operand.csgFromSolid : transform;
    operand.csgFromSolid = std::make_shared<const Transform>(composed);
    operand.bounds = operandBounds(operand);
  }
  tree->bounds = treeBounds(*tree);
  return Csg{std::move(tree)};
}

Csg withCsgTransmission(const Csg& csg, const std::vector<Color>& transmission) {
  auto tree = std::make_shared<CsgTree>(*csg.tree);
  for (std::size_t i = 0; i < tree->operands.size() && i < transmission.size(); ++i) {
    tree->operands[i].transmission = transmission[i];
  }
  return Csg{std::move(tree)};
}

// ------------------------------------------------------------------------------- ray queries

namespace {

Ray operandRay(const CsgOperand& operand, const Ray& ray) {
  return operand.csgFromSolid ? objectRayOf(*operand.csgFromSolid, ray) : ray;
}

bool solidIntersect(const CsgSolid& solid, const Ray& ray, double tMin, double tMax,
                    ShapeHit& hit) {
  if (const auto* mesh = std::get_if<std::shared_ptr<const CsgMesh>>(&solid)) {
    return (*mesh)->intersect(ray, tMin, tMax, hit);
  }
  if (const auto* sphere = std::get_if<Sphere>(&solid)) {
    return sphere->intersect(ray, tMin, tMax, hit);
  }
  if (const auto* box = std::get_if<Box>(&solid)) return box->intersect(ray, tMin, tMax, hit);
  return std::get<Cylinder>(solid).intersect(ray, tMin, tMax, hit);
}

int solidCrossings(const CsgSolid& solid, const Ray& ray, double tMin, double tMax) {
  if (const auto* sphere = std::get_if<Sphere>(&solid)) return sphere->crossings(ray, tMin, tMax);
  if (const auto* box = std::get_if<Box>(&solid)) return box->crossings(ray, tMin, tMax);
  return std::get<Cylinder>(solid).crossings(ray, tMin, tMax);
}

// The next crossing of one operand along the ray. Trivially constructible: an array of them lives
// on the stack of every query without being cleared.
struct Cursor {
  double t;      // the crossing's ray parameter; +inf when the operand has no more
  double after;  // the lower bound of the query that found it: asking again gives the same hit
  double exitT;  // convex solids: the exit after an entry at t (+inf otherwise)
  bool entering;
};

// One crossing of the combined surface, as the walk reports it.
struct Crossing {
  double t;
  std::uint32_t operand;
  double after;        // see Cursor
  bool operandEnters;  // the ray enters the operand there
  bool resultEnters;   // the ray enters the combined solid there
};

// The combined inside state for the operands' states (bit i: inside operand i).
bool evaluate(const CsgTree& tree, std::uint64_t inside) {
  std::array<bool, kMaxCsgNodes> stack;
  std::size_t size = 0;
  for (const CsgNode& node : tree.postorder) {
    if (node.isSolid) {
      stack[size++] = ((inside >> node.value) & 1u) != 0;
      continue;
    }
    const std::size_t first = size - node.value;
    bool value = stack[first];
    for (std::size_t k = first + 1; k < size; ++k) {
      switch (node.operation) {
        case CsgOperation::Union:
          value = value || stack[k];
          break;
        case CsgOperation::Intersection:
          value = value && stack[k];
          break;
        case CsgOperation::Difference:
          value = value && !stack[k];
          break;
      }
    }
    size = first;
    stack[size++] = value;
  }
  return size > 0 && stack[size - 1];
}

// The crossing walk: calls visit(crossing) at every crossing of the combined surface in
// (tMin, tMax), in order of t, until visit returns false.
template <class Visit>
void walkCrossings(const CsgTree& tree, const Ray& ray, double tMin, double tMax, Visit&& visit) {
  const std::size_t count = tree.operands.size();
  std::array<Cursor, kMaxCsgSolids> cursors;
  std::uint64_t inside = 0;
  ShapeHit hit;
  // The state at tMin and the first crossing after it, per operand.
  for (std::size_t i = 0; i < count; ++i) {
    const CsgOperand& operand = tree.operands[i];
    Cursor& c = cursors[i];
    c = {kInf, tMin, kInf, false};
    const Ray r = operandRay(operand, ray);
    const bool isMesh = std::holds_alternative<std::shared_ptr<const CsgMesh>>(operand.solid);
    if (isMesh) {
      // A closed mesh: the first crossing after tMin leaves it exactly when the ray starts inside.
      if (solidIntersect(operand.solid, r, tMin, kInf, hit)) {
        c.t = hit.t;
        c.entering = dot(hit.normal, r.direction) < 0;
        if (!c.entering) inside |= std::uint64_t{1} << i;
      }
      continue;
    }
    // A convex solid: two crossings after tMin (entry, exit) when the ray starts outside it, one
    // (the exit) when inside. The count decides, not the normal, whose sign rounding may flip on a
    // nearly tangent ray; more than two (a cylinder's rim met by side and cap at once) falls back
    // on the normal.
    const int crossings = solidCrossings(operand.solid, r, tMin, kInf);
    if (crossings == 0 || !solidIntersect(operand.solid, r, tMin, kInf, hit)) continue;
    const bool entering = crossings == 2 || (crossings > 2 && dot(hit.normal, r.direction) < 0);
    if (!entering) {
      inside |= std::uint64_t{1} << i;
      c.t = hit.t;
      continue;
    }
    const double entry = hit.t;
    // An entry without an exit is a ray grazing an edge: it never gets inside.
    if (!solidIntersect(operand.solid, r, entry, kInf, hit)) continue;
    c.t = entry;
    c.exitT = hit.t;
    c.entering = true;
  }

  bool result = evaluate(tree, inside);
  while (true) {
    double t = kInf;
    for (std::size_t i = 0; i < count; ++i) t = std::min(t, cursors[i].t);
    if (!(t < tMax)) return;
    // Every operand crossing at t changes its state before the tree is evaluated.
    Crossing crossing{t, 0, 0, false, false};
    bool first = true;
    for (std::size_t i = 0; i < count; ++i) {
      Cursor& c = cursors[i];
      if (c.t != t) continue;
      const std::uint64_t bit = std::uint64_t{1} << i;
      inside = c.entering ? (inside | bit) : (inside & ~bit);
      if (first) {
        crossing.operand = static_cast<std::uint32_t>(i);
        crossing.after = c.after;
        crossing.operandEnters = c.entering;
        first = false;
      }
      // Advance to the operand's next crossing, strictly after t.
      const CsgOperand& operand = tree.operands[i];
      if (std::holds_alternative<std::shared_ptr<const CsgMesh>>(operand.solid)) {
        const Ray r = operandRay(operand, ray);
        if (solidIntersect(operand.solid, r, t, kInf, hit)) {
          c = {hit.t, t, kInf, dot(hit.normal, r.direction) < 0};
        } else {
          c.t = kInf;
        }
      } else if (c.entering) {
        c = {c.exitT, t, kInf, false};
      } else {
        c.t = kInf;
      }
    }
    const bool now = evaluate(tree, inside);
    if (now == result) continue;
    result = now;
    crossing.resultEnters = now;
    if (!visit(crossing)) return;
  }
}

}  // namespace

bool Csg::intersect(const Ray& ray, double tMin, double tMax, ShapeHit& hit) const {
  bool found = false;
  Crossing first{};
  walkCrossings(*tree, ray, tMin, tMax, [&](const Crossing& c) {
    first = c;
    found = true;
    return false;
  });
  if (!found) return false;
  // The operand's hit again, by the same query that found it: the same t, point and normal.
  const CsgOperand& operand = tree->operands[first.operand];
  const Ray r = operandRay(operand, ray);
  if (!solidIntersect(operand.solid, r, first.after, kInf, hit)) return false;  // cannot happen
  hit.t = first.t;
  if (operand.csgFromSolid) {
    const Transform& t = *operand.csgFromSolid;
    hit.normal = normalize(t(hit.normal));
    const Point3 solidPoint = hit.point;
    hit.point = t(solidPoint);
    hit.pointError = worldPointError(t, solidPoint, hit.pointError, hit.point);
  }
  // Outward from the combined solid: against the ray where the ray enters it.
  if (first.operandEnters != first.resultEnters) hit.normal = -hit.normal;
  hit.part = first.operand;
  return true;
}

int Csg::crossings(const Ray& ray, double tMin, double tMax) const {
  int count = 0;
  walkCrossings(*tree, ray, tMin, tMax, [&](const Crossing&) {
    ++count;
    return true;
  });
  return count;
}

Bounds3 Csg::bounds() const { return tree->bounds; }

Normal3 Csg::normalAt(const Point3& p) const {
  // Segments of ±1e-6 of the csg's size about p; the closest crossing to p wins.
  const double reach = 1e-6 * std::max(1.0, maxComponent(tree->bounds.diagonal()));
  Normal3 best;
  double bestDistance = kInf;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 d{0, 0, 0};
    d[axis] = 2 * reach;
    ShapeHit hit;
    if (intersect(Ray{p - d * 0.5, d}, 0, 1, hit) && std::abs(hit.t - 0.5) < bestDistance) {
      bestDistance = std::abs(hit.t - 0.5);
      best = hit.normal;
    }
  }
  return best;
}

Color csgTransmittance(const Csg& csg, const Ray& ray, double tMin, double tMax) {
  Color result(1);
  walkCrossings(*csg.tree, ray, tMin, tMax, [&](const Crossing& c) {
    result *= csg.tree->operands[c.operand].transmission;
    return !isBlack(result);
  });
  return isBlack(result) ? Color() : result;
}

SurfaceCoordinates csgSurfaceCoordinates(const Csg& csg, std::uint32_t part, const Point3& p) {
  const CsgOperand& operand = csg.tree->operands.at(part);
  const Point3 q = operand.csgFromSolid ? operand.csgFromSolid->inverse()(p) : p;
  SurfaceCoordinates sc;
  if (const auto* mesh = std::get_if<std::shared_ptr<const CsgMesh>>(&operand.solid)) {
    const Bounds3 b = (*mesh)->bounds();
    sc = surfaceCoordinates(Shape(Box{b.lo, b.hi}), q);
  } else if (const auto* sphere = std::get_if<Sphere>(&operand.solid)) {
    sc = surfaceCoordinates(Shape(*sphere), q);
  } else if (const auto* box = std::get_if<Box>(&operand.solid)) {
    sc = surfaceCoordinates(Shape(*box), q);
  } else {
    sc = surfaceCoordinates(Shape(std::get<Cylinder>(operand.solid)), q);
  }
  if (operand.csgFromSolid) {
    const Transform& t = *operand.csgFromSolid;
    sc.dpdu = t(sc.dpdu);
    sc.dpdv = t(sc.dpdv);
    sc.tangent = t(sc.tangent);
    sc.bitangent = t(sc.bitangent);
    sc.dndu = toVec(t(Normal3(sc.dndu)));
    sc.dndv = toVec(t(Normal3(sc.dndv)));
  }
  return sc;
}

}  // namespace glint
