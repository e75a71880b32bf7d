// The two-level BVH of instances: the top-level tree over the instances' world bounds, the
// traversals that map a ray into each instance's group and its hit back, and the instance records.
#include "glint/accel/instances.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "glint/accel/slab_test.h"
#include "glint/core/spawn.h"
#include "glint/geometry/object_space.h"

namespace glint {

namespace {

using bvh::kEmpty;
using bvh::kInner;
using bvh::Node;
using slab::BoxRay;
using slab::floatAbove;
using slab::floatBelow;
using slab::intersectNode;
using slab::kFarScale;
using slab::StackEntry;

constexpr std::size_t kInstanceChunk = 4096;

AffineMatrix topRows(const Matrix4& m) {
  AffineMatrix a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) a.m[i][j] = m.m[i][j];
  return a;
}

// m·p + translation, summed in Transform::operator()(Point3)'s order (its w is exactly 1 for an
// affine matrix, so it never divides).
Point3 applyToPoint(const AffineMatrix& a, const Point3& p) {
  const auto& m = a.m;
  return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
          m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
          m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
}

Vec3 applyToVector(const AffineMatrix& a, const Vec3& v) {
  const auto& m = a.m;
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
          m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

// A normal by the inverse transpose: column i of the inverse dotted with n (Transform's order).
Normal3 applyToNormal(const AffineMatrix& inverse, const Normal3& n) {
  const auto& mi = inverse.m;
  return {mi[0][0] * n.x + mi[1][0] * n.y + mi[2][0] * n.z,
          mi[0][1] * n.x + mi[1][1] * n.y + mi[2][1] * n.z,
          mi[0][2] * n.x + mi[1][2] * n.y + mi[2][2] * n.z};
}

PlacedInstance placed(const Instance& in) { return {in.groupFromWorld, in.group, in.material}; }

// The world bounds of a group-space box: its eight corners mapped (Transform's bounds).
Bounds3 worldBounds(const AffineMatrix& a, const Bounds3& b) {
  if (b.isEmpty()) return b;
  if (!b.isBounded()) return Bounds3::unbounded();
  Bounds3 result;
  for (int corner = 0; corner < 8; ++corner) {
    const Point3 p{(corner & 1) ? b.hi.x : b.lo.x, (corner & 2) ? b.hi.y : b.lo.y,
                   (corner & 4) ? b.hi.z : b.lo.z};
    result = unite(result, applyToPoint(a, p));
  }
  return result;
}

// The world-from-group map of an instance, re-derived from the stored inverse [B | c]: the linear
// part by the adjugate formula B⁻¹ = adj(B) / det(B), the translation −B⁻¹·c. Deterministic, so
// every hit on the instance gets the same matrix; it differs from the Transform's own forward
// matrix in the last bits (bounded in worldPointError below).
AffineMatrix forwardOf(const AffineMatrix& inverse) {
  const auto& b = inverse.m;
  const double c00 = b[1][1] * b[2][2] - b[1][2] * b[2][1];
  const double c01 = b[1][2] * b[2][0] - b[1][0] * b[2][2];
  const double c02 = b[1][0] * b[2][1] - b[1][1] * b[2][0];
  const double c10 = b[0][2] * b[2][1] - b[0][1] * b[2][2];
  const double c11 = b[0][0] * b[2][2] - b[0][2] * b[2][0];
  const double c12 = b[0][1] * b[2][0] - b[0][0] * b[2][1];
  const double c20 = b[0][1] * b[1][2] - b[0][2] * b[1][1];
  const double c21 = b[0][2] * b[1][0] - b[0][0] * b[1][2];
  const double c22 = b[0][0] * b[1][1] - b[0][1] * b[1][0];
  const double det = b[0][0] * c00 + b[0][1] * c01 + b[0][2] * c02;
  AffineMatrix f;
  auto& a = f.m;
  // adj(B) is the transpose of the cofactor matrix.
  a[0][0] = c00 / det;
  a[0][1] = c10 / det;
  a[0][2] = c20 / det;
  a[1][0] = c01 / det;
  a[1][1] = c11 / det;
  a[1][2] = c21 / det;
  a[2][0] = c02 / det;
  a[2][1] = c12 / det;
  a[2][2] = c22 / det;
  for (int i = 0; i < 3; ++i) {
    a[i][3] = -(a[i][0] * b[0][3] + a[i][1] * b[1][3] + a[i][2] * b[2][3]);
  }
  return f;
}

// Error bound of the world point forward·p for a group-space point p with error bound e, `world`
// being forward·p and `forward` = forwardOf(in.groupFromWorld): the bound a transformed Primitive
// gives its hit points (geometry/object_space.h, same function), plus the derived matrix's own
// error as an inverse of the stored one. The adjugate inverse of a 3×3 matrix is componentwise
// accurate to a small multiple of the unit roundoff times the condition number
// κ = ‖|A|·|B|‖∞ (1 for scales, ≤ 3 for rotations); taken as γ24·κ, and carried through the
// translation −A·c, whose own rounding adds γ3·|A|·|c|.
Vec3 worldPointError(const PlacedInstance& in, const AffineMatrix& forward, const Point3& p,
                     const Vec3& e, const Point3& world) {
  Vec3 out = worldPointErrorOf(forward.m, in.groupFromWorld.m, p, e, world);
  const auto& a = forward.m;
  const auto& b = in.groupFromWorld.m;
  const double derivation = gammaBound(24) * conditionNumberOf(a, b);
  const double pAbs[3] = {std::abs(p.x), std::abs(p.y), std::abs(p.z)};
  for (int i = 0; i < 3; ++i) {
    double linear = 0;
    double translation = 0;
    for (int j = 0; j < 3; ++j) {
      linear += std::abs(a[i][j]) * pAbs[j];
      translation += std::abs(a[i][j]) * std::abs(b[j][3]);
    }
    out[i] += derivation * (linear + translation) + gammaBound(3) * translation;
  }
  return out;
}

}  // namespace

Instance makeInstance(const Transform* worldFromGroup, std::uint32_t group,
                      std::uint32_t material) {
  Instance in;
  in.group = group;
  in.material = material;
  if (worldFromGroup == nullptr || worldFromGroup->isIdentity()) return in;
  const Matrix4& m = worldFromGroup->matrix();
  const Matrix4& inv = worldFromGroup->inverseMatrix();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      if (!std::isfinite(m.m[i][j]) || !std::isfinite(inv.m[i][j])) {
        throw std::invalid_argument("transform must be finite, got a non-finite matrix entry");
      }
    }
  }
  if (m.m[3][0] != 0 || m.m[3][1] != 0 || m.m[3][2] != 0 || m.m[3][3] != 1) {
    throw std::invalid_argument("transform must be affine");
  }
  in.worldFromGroup = topRows(m);
  in.groupFromWorld = topRows(inv);
  return in;
}

InstanceSet::InstanceSet(std::vector<std::shared_ptr<const Aggregate>> groups,
                         std::vector<Instance> instances)
    : groups_(std::move(groups)) {
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (!groups_[g])
      throw std::invalid_argument("InstanceSet: group " + std::to_string(g) + " is null");
  }
  if (instances.size() >= std::numeric_limits<std::uint32_t>::max() - 1) {
    throw std::length_error("InstanceSet: more instances than a 32-bit index can address");
  }
  for (const Instance& in : instances) {
    if (in.group >= groups_.size()) {
      throw std::invalid_argument("InstanceSet: instance of group " + std::to_string(in.group) +
                                  ", but there are only " + std::to_string(groups_.size()));
    }
  }
  // Each group's own bounds with its unbounded primitives (planes, tubes), which its Aggregate's
  // bounds() leaves out.
  std::vector<Bounds3> groupBounds(groups_.size());
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const Aggregate& a = *groups_[g];
    groupBounds[g] = a.bounds();
    for (const Primitive& p : a.primitives()) {
      if (!p.isBounded()) groupBounds[g] = Bounds3::unbounded();
    }
  }
  // Build items at fixed slots in parallel (one key: every leaf is a range of instances), then
  // the empty ones (instances of empty groups, which nothing can hit) dropped in order.
  const std::size_t n = instances.size();
  bvh::BuildItems slots(n);
  std::vector<std::uint8_t> kind(n);  // 0 dropped, 1 bounded, 2 unbounded
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kInstanceChunk), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const Bounds3 b = worldBounds(instances[i].worldFromGroup, groupBounds[instances[i].group]);
      if (b.isEmpty()) continue;
      if (!b.isBounded()) {
        kind[i] = 2;
        continue;
      }
      const double lo[3] = {b.lo.x, b.lo.y, b.lo.z};
      const double hi[3] = {b.hi.x, b.hi.y, b.hi.z};
      slots[i] = bvh::makeBuildItem(lo, hi, 0, static_cast<std::uint32_t>(i));
      kind[i] = 1;
    }
  });
  bvh::BuildItems items;
  items.reserve(n);
  std::vector<PlacedInstance> unboundedInstances;
  for (std::size_t i = 0; i < n; ++i) {
    if (kind[i] == 1) {
      items.push_back(slots[i]);
      const bvh::BuildItem& item = slots[i];
      bounds_ = unite(bounds_, Bounds3(Point3{item.lo[0], item.lo[1], item.lo[2]},
                                       Point3{item.hi[0], item.hi[1], item.hi[2]}));
    } else if (kind[i] == 2) {
      unboundedInstances.push_back(placed(instances[i]));
    }
  }
  bvh::BuildItems().swap(slots);
  std::vector<std::uint8_t>().swap(kind);
  if (!items.empty()) {
    bvh::Tree tree = bvh::build(items);
    nodes_ = std::move(tree.nodes);
    rootChild_ = tree.rootChild;
    rootInfo_ = tree.rootInfo;
  }
  // The instances in leaf order (leaves already point at item positions), then the unbounded ones.
  instances_.reserve(items.size() + unboundedInstances.size());
  for (const bvh::BuildItem& item : items) {
    instances_.push_back(placed(instances[bvh::itemIndex(item)]));
  }
  std::vector<Instance>().swap(instances);
  for (const PlacedInstance& in : unboundedInstances) {
    unbounded_.push_back(static_cast<std::uint32_t>(instances_.size()));
    instances_.push_back(in);
  }
  instances_.shrink_to_fit();
}

bool InstanceSet::intersectInstance(std::uint32_t i, const Ray& ray, double tMin, double tMax,
                                    Hit& local, Ray& groupRay) const {
  const PlacedInstance& in = instances_[i];
  // The group-space direction is not normalised, so t is the same in both spaces.
  groupRay = Ray{applyToPoint(in.groupFromWorld, ray.origin),
                 applyToVector(in.groupFromWorld, ray.direction)};
  return groups_[in.group]->intersect(groupRay, tMin, tMax, local);
}

void InstanceSet::finishHit(std::uint32_t i, const Ray& /*groupRay*/, Hit& hit) const {
  const PlacedInstance& in = instances_[i];
  const bool smooth = !(hit.shadingNormal == hit.normal);
  hit.normal = Normal3(normalize(toVec(applyToNormal(in.groupFromWorld, hit.normal))));
  hit.shadingNormal =
      smooth ? Normal3(normalize(toVec(applyToNormal(in.groupFromWorld, hit.shadingNormal))))
             : hit.normal;
  const Point3 groupPoint = hit.point;
  const AffineMatrix forward = forwardOf(in.groupFromWorld);
  hit.point = applyToPoint(forward, groupPoint);
  hit.pointError = worldPointError(in, forward, groupPoint, hit.pointError, hit.point);
  hit.instance = i;
}

bool InstanceSet::intersect(const Ray& ray, double tMin, double tMax, Hit& hit) const {
  bool found = false;
  double closest = tMax;
  Hit local;
  Ray groupRay;
  Ray bestGroupRay;
  std::uint32_t best = 0;
  for (const std::uint32_t i : unbounded_) {
    if (intersectInstance(i, ray, tMin, closest, local, groupRay)) {
      closest = local.t;
      hit = local;
      bestGroupRay = groupRay;
      best = i;
      found = true;
    }
  }
  if (rootInfo_ != kEmpty) {
    const BoxRay boxRay(ray);
    const __m128 tMinV = _mm_set1_ps(floatBelow(tMin));
    float closestF = floatAbove(closest * kFarScale);
    __m128 tMaxV = _mm_set1_ps(closestF);
    std::array<StackEntry, bvh::kStackSize> stack;
    int stackSize = 0;
    std::uint32_t child = rootChild_;
    std::uint32_t info = rootInfo_;
    while (true) {
      if (info == kInner) {
        const Node& node = nodes_[child];
        __m128 tNearV;
        int mask = intersectNode(node, boxRay, tMinV, tMaxV, tNearV);
        if (mask != 0) {
          alignas(16) std::array<float, 4> tNear;
          _mm_store_ps(tNear.data(), tNearV);
          // Near child first; the others pushed farthest first.
          std::array<StackEntry, 4> hits;
          int hitCount = 0;
          while (mask != 0) {
            const int c = std::countr_zero(static_cast<unsigned>(mask));
            mask &= mask - 1;
            const StackEntry entry{node.child[c], node.info[c], tNear[c]};
            int k = hitCount++;
            while (k > 0 && hits[k - 1].tNear > entry.tNear) {
              hits[k] = hits[k - 1];
              --k;
            }
            hits[k] = entry;
          }
          for (int k = hitCount - 1; k > 0; --k) stack[stackSize++] = hits[k];
          child = hits[0].child;
          info = hits[0].info;
          continue;
        }
      } else {
        const std::uint32_t count = bvh::leafCount(info);
        bool closer = false;
        for (std::uint32_t i = child; i < child + count; ++i) {
          if (intersectInstance(i, ray, tMin, closest, local, groupRay)) {
            closest = local.t;
            hit = local;
            bestGroupRay = groupRay;
            best = i;
            found = true;
            closer = true;
          }
        }
        if (closer) {
          closestF = floatAbove(closest * kFarScale);
          tMaxV = _mm_set1_ps(closestF);
        }
      }
      while (stackSize > 0 && stack[stackSize - 1].tNear > closestF) --stackSize;
      if (stackSize == 0) break;
      --stackSize;
      child = stack[stackSize].child;
      info = stack[stackSize].info;
    }
  }
  if (found) finishHit(best, bestGroupRay, hit);
  return found;
}

Color InstanceSet::transmittance(const Ray& ray, double tMin, double tMax) const {
  Color result(1);
  const auto cross = [&](std::uint32_t i) {
    const PlacedInstance& in = instances_[i];
    const Ray groupRay{applyToPoint(in.groupFromWorld, ray.origin),
                       applyToVector(in.groupFromWorld, ray.direction)};
    const Color t = groups_[in.group]->transmittance(groupRay, tMin, tMax);
    if (t == Color(1)) return true;
    result *= t;
    return !isBlack(result);
  };
  for (const std::uint32_t i : unbounded_) {
    if (!cross(i)) return Color();
  }
  if (rootInfo_ == kEmpty) return result;
  // Every crossing counts: children in slot order, the interval never shrinks (as the Aggregate's).
  const BoxRay boxRay(ray);
  const __m128 tMinV = _mm_set1_ps(floatBelow(tMin));
  const __m128 tMaxV = _mm_set1_ps(floatAbove(tMax * kFarScale));
  std::array<std::uint64_t, bvh::kStackSize> stack;  // child | info << 32
  int stackSize = 0;
  std::uint32_t child = rootChild_;
  std::uint32_t info = rootInfo_;
  while (true) {
    if (info == kInner) {
      const Node& node = nodes_[child];
      __m128 tNear;
      int mask = intersectNode(node, boxRay, tMinV, tMaxV, tNear);
      if (mask != 0) {
        const int first = std::countr_zero(static_cast<unsigned>(mask));
        mask &= mask - 1;
        while (mask != 0) {
          const int c = std::countr_zero(static_cast<unsigned>(mask));
          mask &= mask - 1;
          stack[stackSize++] = node.child[c] | static_cast<std::uint64_t>(node.info[c]) << 32;
        }
        child = node.child[first];
        info = node.info[first];
        continue;
      }
    } else {
      const std::uint32_t count = bvh::leafCount(info);
      for (std::uint32_t i = child; i < child + count; ++i) {
        if (!cross(i)) return Color();
      }
    }
    if (stackSize == 0) break;
    const std::uint64_t entry = stack[--stackSize];
    child = static_cast<std::uint32_t>(entry);
    info = static_cast<std::uint32_t>(entry >> 32);
  }
  return result;
}

Transform InstanceSet::placement(std::uint32_t i) const {
  const AffineMatrix& inverse = instances_[i].groupFromWorld;
  const AffineMatrix forward = forwardOf(inverse);
  Matrix4 m = Matrix4::identity();
  Matrix4 inv = Matrix4::identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      m.m[r][c] = forward.m[r][c];
      inv.m[r][c] = inverse.m[r][c];
    }
  }
  return Transform(m, inv);
}

Point3 InstanceSet::groupPoint(std::uint32_t i, const Point3& world) const {
  return applyToPoint(instances_[i].groupFromWorld, world);
}

Vec3 InstanceSet::worldVector(std::uint32_t i, const Vec3& v) const {
  return applyToVector(forwardOf(instances_[i].groupFromWorld), v);
}

Normal3 InstanceSet::worldNormal(std::uint32_t i, const Normal3& n) const {
  return applyToNormal(instances_[i].groupFromWorld, n);
}

Color InstanceSet::vertexColor(const Hit& hit) const {
  Hit local = hit;
  local.point = groupPoint(hit.instance, hit.point);
  local.instance = kNoInstance;
  return groups_[instances_[hit.instance].group]->vertexColor(local);
}

std::size_t InstanceSet::memoryBytes() const {
  std::size_t bytes = instances_.capacity() * sizeof(PlacedInstance) +
                      nodes_.capacity() * sizeof(Node) +
                      unbounded_.capacity() * sizeof(std::uint32_t) +
                      groups_.capacity() * sizeof(std::shared_ptr<const Aggregate>);
  for (const auto& g : groups_) bytes += g->memoryBytes();
  return bytes;
}

}  // namespace glint
