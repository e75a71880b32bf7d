// Bounding volume hierarchy over the bounded primitives: binned SAH build into a flat depth-first
// node array, iterative near-child-first traversal for closest hits, any-order traversal for shadow
// transmittance.
#include "glint/accel/aggregate.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace glint {

namespace {

// Binned SAH (Wald 2007, "On fast Construction of SAH-based Bounding Volume Hierarchies"): the
// cost of an inner node is kTraversalCost + Σ_children area(child)/area(node) · count(child), in
// units of one primitive intersection; a leaf costs its primitive count. 1/8 is pbrt's ratio.
constexpr double kTraversalCost = 0.125;
constexpr int kBinCount = 16;
constexpr std::uint32_t kMaxLeafSize = 4;
// Below this depth only median splits are made. A median split halves the count, so no leaf is
// deeper than kMaxSahDepth + 31 for any primitive count that fits in std::uint32_t — the
// traversal stack (one entry per level at most) can never overflow, even on pathological inputs
// (e.g. primitives spaced geometrically) where SAH peels off one primitive per level.
constexpr int kMaxSahDepth = 64;
constexpr int kStackSize = 128;
// The far slab distance is padded by 2γ(3), pbrt's bound on the rounding of (bound − origin)·(1/d),
// so a ray grazing a box is not lost to rounding (as in intersectSlabs, bounds.h).
constexpr double kSlabFarPad = 1 + 2 * 3 * std::numeric_limits<double>::epsilon();
static_assert(kStackSize > kMaxSahDepth + 32);

struct SahSplit {
  int axis = -1;  // -1: no split with primitives on both sides
  int bin = 0;    // the low side holds bins [0, bin]
  double cost = kInfinity;
};

int binOf(double centroid, double lo, double extent) {
  const int b = static_cast<int>(kBinCount * ((centroid - lo) / extent));
  return std::clamp(b, 0, kBinCount - 1);
}

// What the slab tests of one traversal share: 1/direction (±inf for zero components) and which
// box side each axis enters through.
struct SlabRay {
  Point3 origin;
  Vec3 invDirection;
  std::array<bool, 3> negative;

  explicit SlabRay(const Ray& ray)
      : origin(ray.origin),
        invDirection{1 / ray.direction.x, 1 / ray.direction.y, 1 / ray.direction.z},
        negative{invDirection.x < 0, invDirection.y < 0, invDirection.z < 0} {}
};

// One axis of the Kay–Kajiya slab test: narrows [tMin, tMax] to the slab [lo, hi].
inline void clipSlab(double lo, double hi, double origin, double invDirection, bool negative,
                     double& tMin, double& tMax) {
  const double tNear = ((negative ? hi : lo) - origin) * invDirection;
  double tFar = ((negative ? lo : hi) - origin) * invDirection;
  tFar *= kSlabFarPad;
  // Written so that a NaN (0·inf: origin on the slab plane, direction parallel to it) leaves the
  // interval unchanged, which keeps the test conservative.
  tMin = tNear > tMin ? tNear : tMin;
  tMax = tFar < tMax ? tFar : tMax;
}

// The slab test of bounds.h's intersectSlabs (same far-distance padding, same NaN handling),
// unrolled and with the entry side chosen once per ray instead of a swap per axis: it is most of
// the traversal's time.
inline bool overlapsBox(const Bounds3& b, const SlabRay& r, double tMin, double tMax) {
  clipSlab(b.lo.x, b.hi.x, r.origin.x, r.invDirection.x, r.negative[0], tMin, tMax);
  clipSlab(b.lo.y, b.hi.y, r.origin.y, r.invDirection.y, r.negative[1], tMin, tMax);
  clipSlab(b.lo.z, b.hi.z, r.origin.z, r.invDirection.z, r.negative[2], tMin, tMax);
  return tMin <= tMax;
}

}  // namespace

struct Aggregate::BuildItem {
  Bounds3 bounds;
  Point3 centroid;
  std::uint32_t index = 0;  // into primitives_
};

Aggregate::Aggregate(std::vector<Primitive> primitives, std::vector<Color> primitiveTransmission,
                     std::vector<TriangleMesh> meshes, std::vector<Color> meshTransmission,
                     Acceleration acceleration)
    : primitives_(std::move(primitives)),
      meshes_(std::move(meshes)),
      transmission_(std::move(primitiveTransmission)) {
  // Meshes and brute force arrive with the acceleration work; until then they are refused loudly.
  if (!meshes_.empty() || !meshTransmission.empty() || acceleration != Acceleration::Bvh)
    throw std::logic_error("Aggregate: triangle meshes and brute force are not implemented yet");
  if (transmission_.size() != primitives_.size()) {
    throw std::invalid_argument("Aggregate: " + std::to_string(transmission_.size()) +
                                " transmission colors for " + std::to_string(primitives_.size()) +
                                " primitives");
  }
  if (primitives_.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error("Aggregate: more primitives than a 32-bit index can address");
  }

  std::vector<BuildItem> items;
  items.reserve(primitives_.size());
  for (std::uint32_t i = 0; i < primitives_.size(); ++i) {
    const Primitive& p = primitives_[i];
    if (!p.isBounded()) {
      unbounded_.push_back(i);
      continue;
    }
    const Bounds3 b = p.bounds();
    items.push_back({b, b.centroid(), i});
    bounds_ = unite(bounds_, b);
  }
  if (items.empty()) return;
  // A binary tree with leaves of ≥ 1 primitive has at most 2n − 1 nodes.
  nodes_.reserve(2 * items.size() - 1);
  order_.reserve(items.size());
  build(items, 0, static_cast<std::uint32_t>(items.size()), 0);
  nodes_.shrink_to_fit();
}

void Aggregate::build(std::vector<BuildItem>& items, std::uint32_t begin, std::uint32_t end,
                      int depth) {
  const auto nodeIndex = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Bounds3 bounds;
  Bounds3 centroidBounds;
  for (std::uint32_t i = begin; i < end; ++i) {
    bounds = unite(bounds, items[i].bounds);
    centroidBounds = unite(centroidBounds, items[i].centroid);
  }
  nodes_[nodeIndex].bounds = bounds;
  const std::uint32_t count = end - begin;

  const auto makeLeaf = [&] {
    Node& leaf = nodes_[nodeIndex];
    leaf.offset = static_cast<std::uint32_t>(order_.size());
    leaf.count = static_cast<std::uint16_t>(count);
    for (std::uint32_t i = begin; i < end; ++i) order_.push_back(items[i].index);
  };
  if (count == 1) return makeLeaf();

  // Costs are kept multiplied by area(node) so that flat nodes (coplanar triangles, area 0) need
  // no division.
  const double nodeArea = bounds.surfaceArea();
  const double leafCost = static_cast<double>(count) * nodeArea;
  const Vec3 centroidExtent = centroidBounds.diagonal();
  const bool centroidsCoincide = maxComponent(centroidExtent) <= 0;

  SahSplit best;
  if (!centroidsCoincide && depth < kMaxSahDepth) {
    // One pass over the items bins them on all three axes at once.
    std::array<std::array<Bounds3, kBinCount>, 3> binBounds{};
    std::array<std::array<std::uint32_t, kBinCount>, 3> binCounts{};
    // An axis is binned when its centroids differ (and their spread is finite, so bin indices are).
    const auto binnable = [](double extent) { return extent > 0 && extent < kInfinity; };
    const std::array<bool, 3> binned{binnable(centroidExtent.x), binnable(centroidExtent.y),
                                     binnable(centroidExtent.z)};
    for (std::uint32_t i = begin; i < end; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!binned[axis]) continue;
        const int b = binOf(items[i].centroid[axis], centroidBounds.lo[axis], centroidExtent[axis]);
        binBounds[axis][b] = unite(binBounds[axis][b], items[i].bounds);
        ++binCounts[axis][b];
      }
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (!binned[axis]) continue;
      // Sweep from the right for the high side of every plane, then from the left; the plane
      // after bin b puts bins [0, b] on the low side.
      std::array<double, kBinCount> rightArea{};
      std::array<std::uint32_t, kBinCount> rightCount{};
      Bounds3 right;
      std::uint32_t highCount = 0;
      for (int b = kBinCount - 1; b > 0; --b) {
        right = unite(right, binBounds[axis][b]);
        highCount += binCounts[axis][b];
        rightArea[b - 1] = right.surfaceArea();
        rightCount[b - 1] = highCount;
      }
      Bounds3 left;
      std::uint32_t lowCount = 0;
      for (int b = 0; b < kBinCount - 1; ++b) {
        left = unite(left, binBounds[axis][b]);
        lowCount += binCounts[axis][b];
        if (lowCount == 0 || rightCount[b] == 0) continue;
        const double cost = kTraversalCost * nodeArea + left.surfaceArea() * lowCount +
                            rightArea[b] * rightCount[b];
        if (cost < best.cost) best = {axis, b, cost};
      }
    }
  }

  std::uint32_t mid;
  int axis;
  if (best.axis >= 0 && best.cost < leafCost) {
    axis = best.axis;
    const double lo = centroidBounds.lo[axis];
    const double extent = centroidExtent[axis];
    const auto it = std::partition(
        items.begin() + begin, items.begin() + end,
        [&](const BuildItem& item) { return binOf(item.centroid[axis], lo, extent) <= best.bin; });
    mid = static_cast<std::uint32_t>(it - items.begin());
  } else if (count <= kMaxLeafSize) {
    return makeLeaf();
  } else {
    // Median split on the widest centroid axis: always balanced, so it also ends the recursion
    // when centroids coincide (then the two halves are arbitrary but still halves).
    axis = centroidsCoincide ? bounds.longestAxis() : centroidBounds.longestAxis();
    mid = begin + count / 2;
    // Ties broken by index: a strict total order, so each half is a well-defined set of
    // primitives even when many centroids coincide.
    std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                     [axis](const BuildItem& a, const BuildItem& b) {
                       const double ca = a.centroid[axis];
                       const double cb = b.centroid[axis];
                       return ca < cb || (ca == cb && a.index < b.index);
                     });
  }

  build(items, begin, mid, depth + 1);
  const auto secondChild = static_cast<std::uint32_t>(nodes_.size());
  build(items, mid, end, depth + 1);
  Node& node = nodes_[nodeIndex];
  node.offset = secondChild;
  node.count = 0;
  node.axis = static_cast<std::uint8_t>(axis);
}

bool Aggregate::intersect(const Ray& ray, double tMin, double tMax, Hit& hit) const {
  ShapeHit shapeHit;
  Normal3 hitNormal;
  bool found = false;
  std::uint32_t hitPrimitive = 0;
  double closest = tMax;

  // Unbounded primitives first: they are typically ground planes and walls, and a hit there shrinks
  // the interval the BVH has to search.
  for (const std::uint32_t index : unbounded_) {
    if (primitives_[index].intersect(ray, tMin, closest, shapeHit)) {
      closest = shapeHit.t;
      hitNormal = shapeHit.normal;
      hitPrimitive = index;
      found = true;
    }
  }

  if (!nodes_.empty()) {
    const SlabRay slabRay(ray);
    std::array<std::uint32_t, kStackSize> stack;
    int stackSize = 0;
    std::uint32_t current = 0;
    while (true) {
      const Node& node = nodes_[current];
      if (overlapsBox(node.bounds, slabRay, tMin, closest)) {
        if (node.count > 0) {
          for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
            const std::uint32_t index = order_[i];
            if (primitives_[index].intersect(ray, tMin, closest, shapeHit)) {
              closest = shapeHit.t;
              hitNormal = shapeHit.normal;
              hitPrimitive = index;
              found = true;
            }
          }
        } else {
          // Visit the child on the side the ray comes from first, so its hits cull the other.
          if (slabRay.negative[node.axis]) {
            stack[stackSize++] = current + 1;
            current = node.offset;
          } else {
            stack[stackSize++] = node.offset;
            current = current + 1;
          }
          continue;
        }
      }
      if (stackSize == 0) break;
      current = stack[--stackSize];
    }
  }

  if (found) {
    hit.t = closest;
    hit.normal = hitNormal;
    hit.shadingNormal = hitNormal;
    hit.mesh = kNoMesh;
    hit.primitive = hitPrimitive;
  }
  return found;
}

Color Aggregate::transmittance(const Ray& ray, double tMin, double tMax) const {
  Color result(1);
  // Multiplies in kt once per crossing of primitive `index`; false once the product is black.
  const auto cross = [&](std::uint32_t index) {
    const Color& kt = transmission_[index];
    if (kt == Color(1)) return true;  // fully transparent: crossings cannot change the product
    const int crossings = primitives_[index].crossings(ray, tMin, tMax);
    if (crossings == 0) return true;
    if (isBlack(kt)) return false;
    for (int k = 0; k < crossings; ++k) result *= kt;
    return !isBlack(result);
  };

  for (const std::uint32_t index : unbounded_) {
    if (!cross(index)) return Color();
  }
  if (nodes_.empty()) return result;

  // Every crossing counts, so the order of the visit is irrelevant and the interval never shrinks.
  const SlabRay slabRay(ray);
  std::array<std::uint32_t, kStackSize> stack;
  int stackSize = 0;
  std::uint32_t current = 0;
  while (true) {
    const Node& node = nodes_[current];
    if (overlapsBox(node.bounds, slabRay, tMin, tMax)) {
      if (node.count > 0) {
        for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
          if (!cross(order_[i])) return Color();
        }
      } else {
        stack[stackSize++] = node.offset;
        current = current + 1;
        continue;
      }
    }
    if (stackSize == 0) break;
    current = stack[--stackSize];
  }
  return result;
}

}  // namespace glint
