// The BVH against a brute-force loop over all primitives and mesh triangles (closest hit and
// transmittance must agree bit for bit), its structural invariants, watertightness of closed
// meshes, shading normals, mesh validation, and a build that does not depend on the thread count.
#include "glint/accel/aggregate.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "glint/core/rng.h"

namespace glint {

// Reads the private layout (friend of Aggregate) and checks what the build promises: every bounded
// primitive and every non-degenerate triangle is referenced by exactly one leaf, leaves tile the
// reference array, hold ≤ kMaxLeafSize references of one key, and every box contains what is below
// it (conservatively: the float box contains the double bounds).
struct AggregateInspector {
  struct Summary {
    int maxDepth = 0;
    std::size_t nodes = 0;
    std::size_t leaves = 0;
  };

  static bool contains(const float lo[3], const float hi[3], const Bounds3& b) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!(lo[axis] < b.lo[axis] && hi[axis] > b.hi[axis])) return false;
    }
    return true;
  }

  static Summary check(const Aggregate& a) {
    Summary summary;
    summary.nodes = a.nodes_.size() + a.wideNodes_.size();
    const auto& prims = a.primitives_;
    std::vector<std::uint32_t> unbounded;
    std::size_t boundedCount = 0;
    for (std::uint32_t i = 0; i < prims.size(); ++i) {
      if (prims[i].isBounded()) {
        ++boundedCount;
      } else {
        unbounded.push_back(i);
      }
    }
    EXPECT_EQ(a.unbounded_, unbounded);
    EXPECT_EQ(a.leafRefs_.size(), boundedCount);
    // Every mesh holds exactly its tree triangles, renumbered into leaf order, and only the
    // vertices they use, numbered by first use.
    std::size_t meshTriangles = 0;
    for (const TriangleMesh& mesh : a.meshes_) {
      meshTriangles += mesh.triangleCount();
      std::uint32_t nextVertex = 0;
      for (const std::uint32_t v : mesh.indices) {
        EXPECT_LE(v, nextVertex) << "vertices numbered by first use";
        if (v == nextVertex) ++nextVertex;
      }
      EXPECT_EQ(nextVertex, mesh.positions.size());
      EXPECT_TRUE(mesh.normals.empty() || mesh.normals.size() == mesh.positions.size());
    }
    EXPECT_EQ(meshTriangles, a.triangleCount());
    if (a.rootInfo_ == bvh::kEmpty) {
      EXPECT_EQ(a.leafRefs_.size(), 0u);
      EXPECT_EQ(meshTriangles, 0u);
      EXPECT_TRUE(a.nodes_.empty());
      EXPECT_TRUE(a.wideNodes_.empty());
      return summary;
    }

    struct Leaf {
      std::uint32_t first, count, key;
    };
    std::vector<Leaf> leaves;
    Bounds3 everything;
    const auto walk = [&](const auto& nodes) {
      EXPECT_TRUE(a.nodes_.empty() || a.wideNodes_.empty()) << "one tree, of one width";
      if (a.rootInfo_ == bvh::kInner) {
        EXPECT_EQ(a.nodeWidth(), std::remove_cvref_t<decltype(nodes[0])>::kWidth);
      }
      std::vector<int> visits(nodes.size(), 0);
      // Checks the subtree below (child, info) against the float box that holds it.
      struct Item {
        std::uint32_t child, info;
        int depth;
        std::array<float, 3> lo, hi;
      };
      const float inf = std::numeric_limits<float>::infinity();
      std::vector<Item> stack{{a.rootChild_, a.rootInfo_, 1, {-inf, -inf, -inf}, {inf, inf, inf}}};
      while (!stack.empty()) {
        const Item item = stack.back();
        stack.pop_back();
        summary.maxDepth = std::max(summary.maxDepth, item.depth);
        if (bvh::isLeaf(item.info)) {
          const Leaf leaf{item.child, bvh::leafCount(item.info), bvh::leafKey(item.info)};
          EXPECT_GE(leaf.count, 1u);
          EXPECT_LE(leaf.count, bvh::kMaxLeafSize);
          leaves.push_back(leaf);
          for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) {
            Bounds3 b;
            if (leaf.key == bvh::kPrimitiveKey) {
              b = prims[a.leafRefs_[k]].bounds();
            } else {
              const TriangleMesh& mesh = a.meshes_[leaf.key];
              for (int v = 0; v < 3; ++v) b = unite(b, mesh.positions[mesh.indices[3 * k + v]]);
            }
            everything = unite(everything, b);
            EXPECT_TRUE(contains(item.lo.data(), item.hi.data(), b)) << "leaf box too small";
          }
          continue;
        }
        EXPECT_EQ(item.info, bvh::kInner);
        EXPECT_LT(item.child, nodes.size());
        if (item.child >= nodes.size()) return;
        ++visits[item.child];
        const auto& node = nodes[item.child];
        int children = 0;
        bool emptySeen = false;
        for (int i = 0; i < std::remove_cvref_t<decltype(node)>::kWidth; ++i) {
          Item next{node.child[i], node.info[i], item.depth + 1, {}, {}};
          for (int axis = 0; axis < 3; ++axis) {
            next.lo[axis] = node.bounds[axis][i];
            next.hi[axis] = node.bounds[axis + 3][i];
          }
          if (node.info[i] == bvh::kEmpty) {
            EXPECT_EQ(next.lo[0], inf);
            EXPECT_EQ(next.hi[0], -inf);
            emptySeen = true;
            continue;
          }
          EXPECT_FALSE(emptySeen) << "empty slots come last";
          ++children;
          for (int axis = 0; axis < 3; ++axis) {
            EXPECT_GE(next.lo[axis], item.lo[axis]);
            EXPECT_LE(next.hi[axis], item.hi[axis]);
          }
          stack.push_back(next);
        }
        EXPECT_GE(children, 2);
      }
      EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; }))
          << "every node reached exactly once";
    };
    if (a.wideNodes_.empty()) {
      walk(a.nodes_);
    } else {
      walk(a.wideNodes_);
    }
    EXPECT_EQ(everything, a.bounds_);
    EXPECT_LE(summary.maxDepth, bvh::kMaxDepth);
    // The primitive leaves tile the reference array, each primitive once; each mesh's leaves tile
    // its triangles in order.
    std::sort(leaves.begin(), leaves.end(), [](const Leaf& x, const Leaf& y) {
      return std::pair(x.key, x.first) < std::pair(y.key, y.first);
    });
    std::vector<std::uint32_t> next(a.meshes_.size() + 1, 0);
    const auto nextOf = [&](std::uint32_t key) -> std::uint32_t& {
      return key == bvh::kPrimitiveKey ? next.back() : next[key];
    };
    std::vector<std::uint32_t> primitivesSeen;
    for (const Leaf& leaf : leaves) {
      EXPECT_EQ(leaf.first, nextOf(leaf.key));
      nextOf(leaf.key) = leaf.first + leaf.count;
      if (leaf.key != bvh::kPrimitiveKey) continue;
      for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) {
        primitivesSeen.push_back(a.leafRefs_[k]);
      }
    }
    EXPECT_EQ(next.back(), a.leafRefs_.size());
    for (std::size_t m = 0; m < a.meshes_.size(); ++m) {
      EXPECT_EQ(next[m], a.meshes_[m].triangleCount());
    }
    std::sort(primitivesSeen.begin(), primitivesSeen.end());
    EXPECT_TRUE(std::adjacent_find(primitivesSeen.begin(), primitivesSeen.end()) ==
                primitivesSeen.end());
    EXPECT_EQ(primitivesSeen.size(), boundedCount);
    summary.leaves = leaves.size();
    return summary;
  }

  // Whether two arrays hold the same bytes (an empty array's data() may be null, which memcmp
  // must not be given even for zero bytes).
  template <typename T, typename Allocator>
  static bool sameBytes(const std::vector<T, Allocator>& a, const std::vector<T, Allocator>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
  }

  // The bytes that define the tree, for comparing builds.
  static bool sameTree(const Aggregate& x, const Aggregate& y) {
    return x.rootChild_ == y.rootChild_ && x.rootInfo_ == y.rootInfo_ &&
           x.leafRefs_ == y.leafRefs_ && sameBytes(x.nodes_, y.nodes_) &&
           sameBytes(x.wideNodes_, y.wideNodes_);
  }

  // The leaves in the order a depth-first walk visiting children in slot order meets them (the
  // transmittance query's order), each with its float box: the same for both node widths.
  struct LeafInOrder {
    std::uint32_t child, info;
    std::array<float, 6> box;
    bool operator==(const LeafInOrder&) const = default;
  };
  static std::vector<LeafInOrder> leavesInSlotOrder(const Aggregate& a) {
    std::vector<LeafInOrder> out;
    const auto visit = [&](const auto& nodes, auto& self, std::uint32_t child, std::uint32_t info,
                           const std::array<float, 6>& box) -> void {
      if (info == bvh::kEmpty) return;
      if (bvh::isLeaf(info)) {
        out.push_back({child, info, box});
        return;
      }
      const auto& node = nodes[child];
      for (int i = 0; i < std::remove_cvref_t<decltype(node)>::kWidth; ++i) {
        std::array<float, 6> childBox;
        for (int row = 0; row < 6; ++row) childBox[row] = node.bounds[row][i];
        self(nodes, self, node.child[i], node.info[i], childBox);
      }
    };
    const std::array<float, 6> all{};
    if (a.wideNodes_.empty()) {
      visit(a.nodes_, visit, a.rootChild_, a.rootInfo_, all);
    } else {
      visit(a.wideNodes_, visit, a.rootChild_, a.rootInfo_, all);
    }
    return out;
  }
  static std::size_t nodeCount(const Aggregate& a) { return a.nodes_.size() + a.wideNodes_.size(); }
};

namespace {

// Reference answers: every primitive in index order, no culling.
bool bruteIntersect(const std::vector<Primitive>& prims, const Ray& ray, double tMin, double tMax,
                    Hit& hit) {
  bool found = false;
  for (std::uint32_t i = 0; i < prims.size(); ++i) {
    ShapeHit h;
    if (prims[i].intersect(ray, tMin, tMax, h) && (!found || h.t < hit.t)) {
      hit = Hit{};
      hit.t = h.t;
      hit.normal = h.normal;
      hit.shadingNormal = h.normal;
      hit.point = h.point;
      hit.pointError = h.pointError;
      hit.primitive = i;
      found = true;
    }
  }
  return found;
}

Color bruteTransmittance(const std::vector<Primitive>& prims, const std::vector<Color>& kt,
                         const Ray& ray, double tMin, double tMax) {
  Color result(1);
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const int n = prims[i].crossings(ray, tMin, tMax);
    for (int k = 0; k < n; ++k) result *= kt[i];
  }
  return result;
}

struct TestScene {
  std::vector<Primitive> prims;
  std::vector<Color> kt;
};

Vec3 uniformDirection(Rng& rng) {
  const double z = 1 - 2 * rng.uniform();
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * std::numbers::pi * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

std::size_t pickIndex(Rng& rng, std::size_t n) {
  return static_cast<std::size_t>(rng.uniform() * static_cast<double>(n));
}

Point3 uniformPoint(Rng& rng, double halfSize) {
  return {halfSize * (2 * rng.uniform() - 1), halfSize * (2 * rng.uniform() - 1),
          halfSize * (2 * rng.uniform() - 1)};
}

// Powers of two (and 0, 1) only, so products are exact in any order and the BVH's product must
// equal the brute-force one bit for bit.
Color randomTransmission(Rng& rng) {
  static constexpr double kValues[] = {0, 0.125, 0.25, 0.5, 1};
  const auto pick = [&] { return kValues[static_cast<int>(rng.uniform() * 5)]; };
  const double u = rng.uniform();
  if (u < 0.15) return Color(0);
  if (u < 0.3) return Color(1);
  if (u < 0.6) return Color(pick(), pick(), pick());
  return Color(0.5);
}

constexpr double kHalf = 10;  // bounded shapes live roughly in [−10, 10]³

// Spheres, boxes (some rotated), triangles, disks, cylinders, duplicates, plus a plane and
// sometimes a tube.
TestScene randomScene(std::uint64_t seed, int count) {
  Rng rng(seed);
  TestScene s;
  const auto add = [&](Shape shape, std::optional<Transform> transform = std::nullopt) {
    s.prims.emplace_back(std::move(shape), 0, Color(), std::move(transform));
    s.kt.push_back(randomTransmission(rng));
  };
  for (int i = 0; i < count; ++i) {
    const Point3 c = uniformPoint(rng, kHalf);
    const double size = 0.1 + 2 * rng.uniform();
    switch (static_cast<int>(rng.uniform() * 7)) {
      case 0:
        add(Sphere::make(c, size));
        break;
      case 1:
        add(Box::make(c, c + Vec3{size, 0.1 + rng.uniform(), 0.1 + 3 * rng.uniform()}));
        break;
      case 2:
        add(Box::make({-size, -size, -0.5 * size}, {size, size, 0.5 * size}),
            Transform::translate(toVec(c)) *
                Transform::rotate(uniformDirection(rng), 360 * rng.uniform()));
        break;
      case 3:
        add(Triangle::make(c, c + uniformDirection(rng) * (2 * size),
                           c + uniformDirection(rng) * (2 * size)));
        break;
      case 4:
        // Axis-aligned triangle: a flat bounding box.
        add(Triangle::make(c, c + Vec3{size, 0, 0}, c + Vec3{0, size, 0}));
        break;
      case 5:
        add(Disk::make(c, rng.uniform() < 0.5 ? Vec3{0, 1, 0} : uniformDirection(rng), size));
        break;
      default:
        add(Cylinder::make(c, uniformDirection(rng), 0.5 * size, 1 + 2 * rng.uniform()));
        break;
    }
    // Exact duplicates: coincident centroids and identical boxes.
    if (rng.uniform() < 0.1) {
      s.prims.push_back(s.prims.back());
      s.kt.push_back(randomTransmission(rng));
    }
  }
  add(Plane::make({0, -kHalf + 1, 0}, Vec3{0.1, 1, -0.2}));
  if (seed % 2 == 0) add(Tube::make({2, 0, -1}, Vec3{1, 0.5, 0.3}, 0.75));
  return s;
}

struct Query {
  Ray ray;
  double tMin = 0;
  double tMax = kInfinity;
};

// Rays from outside, from inside, axis-parallel ones (some starting exactly on a box face plane),
// rays aimed at primitive centres and at box corners; directions are deliberately not all unit.
std::vector<Query> randomQueries(const TestScene& s, std::uint64_t seed, int perKind) {
  Rng rng(seed);
  std::vector<Query> queries;
  const auto interval = [&](Query q) {
    const double u = rng.uniform();
    if (u < 0.2) q.tMin = 5 * rng.uniform();
    if (u > 0.7) q.tMax = q.tMin + 30 * rng.uniform();
    queries.push_back(q);
  };
  const auto scale = [&] { return rng.uniform() < 0.3 ? 0.25 + 3 * rng.uniform() : 1.0; };
  std::vector<Bounds3> boxes;
  for (const Primitive& p : s.prims) {
    if (p.isBounded()) boxes.push_back(p.bounds());
  }
  for (int i = 0; i < perKind; ++i) {
    const Point3 outside = toPoint(uniformDirection(rng) * (4 * kHalf));
    interval({{outside, (uniformPoint(rng, kHalf) - outside) * (scale() / (4 * kHalf))}});

    interval({{uniformPoint(rng, kHalf), uniformDirection(rng) * scale()}});

    Point3 o = uniformPoint(rng, 1.5 * kHalf);
    const int axis = static_cast<int>(rng.uniform() * 3);
    if (rng.uniform() < 0.5) {
      // On the plane of a bounding box face, travelling parallel to it: the slab test's 0·∞.
      const Bounds3& b = boxes[pickIndex(rng, boxes.size())];
      const int faceAxis = (axis + 1) % 3;
      o[faceAxis] = rng.uniform() < 0.5 ? b.lo[faceAxis] : b.hi[faceAxis];
    }
    Vec3 d;
    d[axis] = rng.uniform() < 0.5 ? -scale() : scale();
    interval({{o, d}});

    const Bounds3& target = boxes[pickIndex(rng, boxes.size())];
    const Point3 from = rng.uniform() < 0.5 ? uniformPoint(rng, kHalf)
                                            : toPoint(uniformDirection(rng) * (3 * kHalf));
    interval({{from, target.centroid() - from}});

    // At a corner of a primitive's box or a triangle's vertex: rays that graze the boundaries of
    // the BVH nodes, where a slab test without a safety margin would cull real hits.
    const Primitive& p = s.prims[pickIndex(rng, s.prims.size())];
    Point3 corner;
    if (const auto* tri = std::get_if<Triangle>(&p.shape())) {
      corner = rng.uniform() < 0.5 ? tri->v0 : tri->v2;
    } else if (p.isBounded()) {
      const Bounds3 b = p.bounds();
      corner = {rng.uniform() < 0.5 ? b.lo.x : b.hi.x, rng.uniform() < 0.5 ? b.lo.y : b.hi.y,
                rng.uniform() < 0.5 ? b.lo.z : b.hi.z};
    } else {
      continue;
    }
    const Point3 start = toPoint(uniformDirection(rng) * (3 * kHalf));
    interval({{start, corner - start}});
  }
  return queries;
}

// Compares every query against brute force; reports the first few disagreements in detail.
void expectMatchesBruteForce(const TestScene& s, const Aggregate& aggregate,
                             const std::vector<Query>& queries) {
  int mismatches = 0;
  int hits = 0;
  int partial = 0;
  const auto report = [&](const Query& q, const std::string& what) {
    if (++mismatches <= 8) {
      ADD_FAILURE() << what << " for ray o=(" << q.ray.origin.x << ", " << q.ray.origin.y << ", "
                    << q.ray.origin.z << ") d=(" << q.ray.direction.x << ", " << q.ray.direction.y
                    << ", " << q.ray.direction.z << ") t in (" << q.tMin << ", " << q.tMax << ")";
    }
  };
  for (const Query& q : queries) {
    Hit expected;
    Hit actual;
    const bool expectedFound = bruteIntersect(s.prims, q.ray, q.tMin, q.tMax, expected);
    const bool actualFound = aggregate.intersect(q.ray, q.tMin, q.tMax, actual);
    if (expectedFound != actualFound) {
      report(q, expectedFound ? "BVH missed a hit" : "BVH found a phantom hit");
    } else if (expectedFound) {
      ++hits;
      if (actual.t != expected.t) {
        report(q, "t " + std::to_string(actual.t) + " != " + std::to_string(expected.t));
      } else if (actual.primitive != expected.primitive) {
        // A tie: the other primitive must hit at exactly the same t.
        ShapeHit h;
        if (!s.prims[actual.primitive].intersect(q.ray, q.tMin, q.tMax, h) || h.t != actual.t) {
          report(q, "wrong primitive " + std::to_string(actual.primitive));
        }
      } else if (!(actual.normal == expected.normal)) {
        report(q, "normal differs");
      } else if (!(actual.point == expected.point) || !(actual.pointError == expected.pointError)) {
        // Spheres are tested inline in the BVH's leaves (geometry/sphere_intersection.h), through
        // Primitive::intersect here: the same bits.
        report(q, "hit point or its error bound differs");
      }
    }
    const Color expectedT = bruteTransmittance(s.prims, s.kt, q.ray, q.tMin, q.tMax);
    const Color actualT = aggregate.transmittance(q.ray, q.tMin, q.tMax);
    if (!(expectedT == actualT)) report(q, "transmittance differs");
    if (!isBlack(expectedT) && !(expectedT == Color(1))) ++partial;
  }
  EXPECT_EQ(mismatches, 0) << "of " << queries.size() << " queries";
  // The queries must exercise both hits and misses, and partial shadows.
  EXPECT_GT(hits, static_cast<int>(queries.size()) / 4);
  EXPECT_LT(hits, static_cast<int>(queries.size()));
  EXPECT_GT(partial, static_cast<int>(queries.size()) / 20);
}

// Both node widths (and Acceleration::Bvh, the width of the ISA the Aggregate starts with).
constexpr std::array kTreeKinds = {Acceleration::Bvh, Acceleration::Bvh4, Acceleration::Bvh8};

std::string treeName(Acceleration acceleration) {
  switch (acceleration) {
    case Acceleration::Bvh4:
      return "4-wide";
    case Acceleration::Bvh8:
      return "8-wide";
    case Acceleration::Bvh:
      return "default width";
    case Acceleration::BruteForce:
      break;
  }
  return "brute force";
}

TEST(AggregateTest, MatchesBruteForceOnRandomScenes) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("scene seed " + std::to_string(seed));
    const TestScene s = randomScene(seed, seed <= 2 ? 12 : 90);
    for (const Acceleration kind : kTreeKinds) {
      SCOPED_TRACE(treeName(kind));
      const Aggregate aggregate(s.prims, s.kt, {}, {}, kind);
      AggregateInspector::check(aggregate);
      expectMatchesBruteForce(s, aggregate, randomQueries(s, 1000 + seed, 300));
    }
  }
}

TEST(AggregateTest, NodeWidthFollowsTheRequest) {
  const TestScene s = randomScene(3, 90);
  EXPECT_EQ(Aggregate(s.prims, s.kt, {}, {}, Acceleration::Bvh4).nodeWidth(), 4);
  EXPECT_EQ(Aggregate(s.prims, s.kt, {}, {}, Acceleration::Bvh8).nodeWidth(), 8);
  EXPECT_EQ(Aggregate(s.prims, s.kt, {}, {}, Acceleration::BruteForce).nodeWidth(), 0);
  const Aggregate automatic(s.prims, s.kt);
  EXPECT_EQ(automatic.nodeWidth(), bvhNodeWidth(automatic.isa()));
  const char* forced = std::getenv("GLINT_BVH_WIDTH");
  if (forced == nullptr || *forced == '\0') {
    EXPECT_EQ(bvhNodeWidth(Isa::Baseline), 4);
    EXPECT_EQ(bvhNodeWidth(Isa::Avx2), 4);
    EXPECT_EQ(bvhNodeWidth(Isa::Avx512), 4);
  }
}

// Exact ties in t go to the least rank (aggregate.cpp: bounded primitives by index, then
// triangles by mesh and leaf-order index) whatever the width and ISA, though the coincident copies
// sit in different leaves and the traversal meets them in different orders.
TEST(AggregateTest, ExactTiesGoToTheLeastIndex) {
  std::vector<Primitive> prims;
  std::vector<Color> kt;
  for (int i = 0; i < 60; ++i) {
    prims.emplace_back(Sphere::make({1, 2, 3}, 1), 0, Color());
    kt.push_back(Color(0.5));
  }
  TriangleMesh copies;
  copies.positions = {{-1, -1, 10}, {1, -1, 10}, {0, 1, 10}};
  for (int i = 0; i < 70; ++i) copies.indices.insert(copies.indices.end(), {0, 1, 2});
  for (const Acceleration kind : kTreeKinds) {
    SCOPED_TRACE(treeName(kind));
    Aggregate spheres(prims, kt, {}, {}, kind);
    Aggregate triangles({}, {}, {copies, copies}, {Color(0.5), Color(0.5)}, kind);
    EXPECT_GT(AggregateInspector::check(spheres).leaves, 8u);
    EXPECT_GT(AggregateInspector::check(triangles).leaves, 8u);
    const IsaSupport here = isaSupportHere();
    for (const Isa isa : kAllIsas) {
      if (!here.runs(isa)) continue;
      SCOPED_TRACE(std::string(isaName(isa)));
      spheres.setIsa(isa);
      triangles.setIsa(isa);
      Rng rng(99);
      for (int k = 0; k < 200; ++k) {
        // Rays into the spheres from every side, and at the triangles from either side.
        const Point3 from = Point3{1, 2, 3} + uniformDirection(rng) * 5.0;
        const Point3 at = Point3{1, 2, 3} + uniformDirection(rng) * (0.9 * rng.uniform());
        Hit hit;
        ASSERT_TRUE(spheres.intersect({from, at - from}, 0, kInfinity, hit));
        EXPECT_EQ(hit.primitive, 0u);
        const Point3 onTriangle{0.6 * rng.uniform() - 0.3, 0.8 * rng.uniform() - 0.6, 10};
        const Point3 start = onTriangle + uniformDirection(rng) * 3.0;
        ASSERT_TRUE(triangles.intersect({start, onTriangle - start}, 0, kInfinity, hit));
        EXPECT_EQ(hit.mesh, 0u);
        EXPECT_EQ(hit.triangle, 0u);
      }
    }
  }
}

TEST(AggregateTest, EmptyAggregateMisses) {
  const Aggregate aggregate({}, {});
  Hit hit;
  hit.t = 42;
  const Ray ray{{0, 0, 0}, {0, 0, 1}};
  EXPECT_FALSE(aggregate.intersect(ray, 0, kInfinity, hit));
  EXPECT_EQ(hit.t, 42);  // untouched on a miss
  EXPECT_EQ(aggregate.transmittance(ray, 0, kInfinity), Color(1));
  EXPECT_TRUE(aggregate.bounds().isEmpty());
  AggregateInspector::check(aggregate);
}

TEST(AggregateTest, OnlyUnboundedPrimitives) {
  std::vector<Primitive> prims;
  prims.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), 0, Color());
  prims.emplace_back(Tube::make({0, 0, -3}, {1, 0, 0}, 1), 0, Color());
  const Aggregate aggregate(prims, {Color(0.5), Color(0.25, 0.5, 1)});
  AggregateInspector::check(aggregate);
  EXPECT_TRUE(aggregate.bounds().isEmpty());

  Hit hit;
  const Ray down{{0, 5, 0}, {0, -1, 0}};
  ASSERT_TRUE(aggregate.intersect(down, 0, kInfinity, hit));
  EXPECT_EQ(hit.t, 5);
  EXPECT_EQ(hit.primitive, 0u);
  EXPECT_EQ(hit.normal, Normal3(0, 1, 0));
  EXPECT_FALSE(aggregate.intersect(down, 0, 5, hit));  // tMax is exclusive
  EXPECT_EQ(aggregate.transmittance(down, 0, 10), Color(0.5));
  EXPECT_EQ(aggregate.transmittance(down, 0, 4), Color(1));

  // Parallel to the plane at height 0.5, through the tube (crossings at t = 3 ∓ √0.75).
  const Ray alongZ{{5, 0.5, -6}, {0, 0, 1}};
  ASSERT_TRUE(aggregate.intersect(alongZ, 0, kInfinity, hit));
  EXPECT_EQ(hit.primitive, 1u);
  EXPECT_NEAR(hit.t, 3 - std::sqrt(0.75), 1e-12);
  EXPECT_EQ(aggregate.transmittance(alongZ, 0, kInfinity), Color(0.0625, 0.25, 1));
  EXPECT_EQ(aggregate.transmittance(alongZ, 0, 3), Color(0.25, 0.5, 1));
}

TEST(AggregateTest, MismatchedTransmissionRejected) {
  std::vector<Primitive> prims;
  prims.emplace_back(Sphere::make({0, 0, 0}, 1), 0, Color());
  EXPECT_THROW(Aggregate(prims, {}), std::invalid_argument);
}

TEST(AggregateTest, ManyIdenticalPrimitives) {
  std::vector<Primitive> prims;
  std::vector<Color> kt;
  for (int i = 0; i < 50; ++i) {
    prims.emplace_back(Sphere::make({1, 2, 3}, 1), 0, Color());
    kt.push_back(Color(0.5));
  }
  Aggregate aggregate(prims, kt);
  const auto summary = AggregateInspector::check(aggregate);
  EXPECT_LE(summary.maxDepth, 4);  // median splits of 50 coincident centroids: balanced

  const Ray ray{{1, 2, -7}, {0, 0, 2}};
  Hit hit;
  ASSERT_TRUE(aggregate.intersect(ray, 0, kInfinity, hit));
  EXPECT_NEAR(hit.t, 4.5, 1e-12);
  EXPECT_LT(hit.primitive, 50u);
  EXPECT_EQ(aggregate.transmittance(ray, 0, kInfinity), Color(std::ldexp(1.0, -100)));
  EXPECT_EQ(aggregate.transmittance(ray, 0, 5), Color(std::ldexp(1.0, -50)));

  // One opaque copy blacks out the shadow ray.
  kt[37] = Color(0);
  aggregate = Aggregate(prims, kt);
  EXPECT_EQ(aggregate.transmittance(ray, 0, kInfinity), Color(0));
  EXPECT_EQ(aggregate.transmittance(ray, 0, 3), Color(1));  // ends before the spheres
}

TEST(AggregateTest, ThousandSphereGrid) {
  // Spheres of radius 0.3 at integer points (i, j, k), 0 ≤ i, j, k < 10; index 100·i + 10·j + k.
  std::vector<Primitive> prims;
  std::vector<Color> kt;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      for (int k = 0; k < 10; ++k) {
        prims.emplace_back(Sphere::make({double(i), double(j), double(k)}, 0.3), 0, Color());
        kt.push_back(Color(0.5));
      }
    }
  }
  const Aggregate aggregate(prims, kt);
  const auto summary = AggregateInspector::check(aggregate);
  EXPECT_LE(summary.maxDepth, 8);  // close to log4(1000/4) ≈ 4 for a regular grid
  EXPECT_EQ(aggregate.bounds(), Bounds3({-0.3, -0.3, -0.3}, {9.3, 9.3, 9.3}));

  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      Hit hit;
      // Down each column of 10 spheres along +z.
      const Ray column{{double(i), double(j), -5}, {0, 0, 1}};
      ASSERT_TRUE(aggregate.intersect(column, 0, kInfinity, hit));
      EXPECT_EQ(hit.primitive, static_cast<std::uint32_t>(100 * i + 10 * j));
      EXPECT_NEAR(hit.t, 4.7, 1e-12);
      EXPECT_NEAR(hit.normal.z, -1, 1e-12);
      EXPECT_EQ(aggregate.transmittance(column, 0, kInfinity), Color(std::ldexp(1.0, -20)));
      // Back along −x from beyond the grid: the last sphere of the row first.
      const Ray row{{20, double(i), double(j)}, {-1, 0, 0}};
      ASSERT_TRUE(aggregate.intersect(row, 0, kInfinity, hit));
      EXPECT_EQ(hit.primitive, static_cast<std::uint32_t>(900 + 10 * i + j));
      EXPECT_NEAR(hit.t, 10.7, 1e-12);
      // From inside sphere (i, j, 4) along +z: its own far side at t = 0.3.
      const Ray inside{{double(i), double(j), 4}, {0, 0, 1}};
      ASSERT_TRUE(aggregate.intersect(inside, 0, kInfinity, hit));
      EXPECT_EQ(hit.primitive, static_cast<std::uint32_t>(100 * i + 10 * j + 4));
      EXPECT_NEAR(hit.t, 0.3, 1e-12);
      // Crossings at t = 0.3, 0.7, 1.3, 1.7 before t = 2.
      EXPECT_EQ(aggregate.transmittance(inside, 0, 2), Color(std::ldexp(1.0, -4)));
      // Between the columns: nothing.
      const Ray gap{{i + 0.5, j + 0.5, -5}, {0, 0, 1}};
      EXPECT_FALSE(aggregate.intersect(gap, 0, kInfinity, hit));
      EXPECT_EQ(aggregate.transmittance(gap, 0, kInfinity), Color(1));
    }
  }
}

TEST(AggregateTest, GeometricallySpacedPrimitivesStayShallow) {
  // Sizes and gaps growing by 1.2× per sphere: SAH keeps peeling off the largest one, which the
  // depth limit must cut off before the traversal stack could overflow.
  TestScene s;
  double x = 0;
  for (int i = 0; i < 300; ++i) {
    const double r = 1e-3 * std::pow(1.2, i / 3.0);
    x += 3 * r;
    s.prims.emplace_back(Sphere::make({x, 0.1 * (i % 3), 0}, r), 0, Color());
    s.kt.push_back(i % 7 == 0 ? Color(0) : Color(0.5));
  }
  const Aggregate aggregate(s.prims, s.kt);
  const auto summary = AggregateInspector::check(aggregate);
  EXPECT_LE(summary.maxDepth, bvh::kMaxDepth);
  std::vector<Query> queries;
  Rng rng(7);
  for (int i = 0; i < 300; ++i) {
    const Point3 target = s.prims[pickIndex(rng, 300)].bounds().centroid();
    const Point3 from{x * rng.uniform(), 5 * rng.uniform() - 2.5, 3};
    queries.push_back({{from, target - from}});
    queries.push_back({{Point3{-1, target.y, target.z}, Vec3{1, 0, 0}}, 0, kInfinity});
  }
  int mismatches = 0;
  for (const Query& q : queries) {
    Hit expected;
    Hit actual;
    const bool e = bruteIntersect(s.prims, q.ray, q.tMin, q.tMax, expected);
    const bool a = aggregate.intersect(q.ray, q.tMin, q.tMax, actual);
    if (e != a || (e && actual.t != expected.t)) ++mismatches;
    if (!(bruteTransmittance(s.prims, s.kt, q.ray, q.tMin, q.tMax) ==
          aggregate.transmittance(q.ray, q.tMin, q.tMax))) {
      ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// ------------------------------------------------------------------------------- triangle meshes

// Flips triangles whose (p1−p0)×(p2−p0) points against `outward` at their centroid, so generated
// meshes have the outward winding a file would have.
template <class Outward>
void orientOutward(TriangleMesh& mesh, Outward outward) {
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    std::uint32_t* v = &mesh.indices[3 * t];
    const Point3& a = mesh.positions[v[0]];
    const Point3& b = mesh.positions[v[1]];
    const Point3& c = mesh.positions[v[2]];
    const Point3 centroid{(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3};
    if (dot(cross(b - a, c - a), outward(centroid)) < 0) std::swap(v[1], v[2]);
  }
}

// A closed UV sphere: poles are single vertices shared by a fan, rings share their vertices, the
// seam wraps around. Vertex normals are the sphere's.
TriangleMesh uvSphere(const Point3& center, double radius, int rings, int segments, bool normals) {
  TriangleMesh mesh;
  const auto add = [&](double theta, double phi) {
    const Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
    mesh.positions.push_back(center + n * radius);
    if (normals) mesh.normals.push_back(Normal3(n));
  };
  add(0, 0);
  for (int i = 1; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      add(std::numbers::pi * i / rings, 2 * std::numbers::pi * j / segments);
    }
  }
  add(std::numbers::pi, 0);
  const auto ring = [&](int i, int j) {
    return static_cast<std::uint32_t>(1 + (i - 1) * segments + (j % segments));
  };
  const auto south = static_cast<std::uint32_t>(mesh.positions.size() - 1);
  for (int j = 0; j < segments; ++j) {
    mesh.indices.insert(mesh.indices.end(), {0, ring(1, j), ring(1, j + 1)});
    mesh.indices.insert(mesh.indices.end(), {south, ring(rings - 1, j), ring(rings - 1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      mesh.indices.insert(mesh.indices.end(), {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      mesh.indices.insert(mesh.indices.end(), {ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  orientOutward(mesh, [&](const Point3& p) { return p - center; });
  return mesh;
}

// A closed torus around the y axis through `center`: major radius R, tube radius r, nu × nv quads
// split into two triangles each, wrapping in both directions.
TriangleMesh torus(const Point3& center, double R, double r, int nu, int nv, bool normals) {
  TriangleMesh mesh;
  for (int i = 0; i < nu; ++i) {
    const double phi = 2 * std::numbers::pi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double theta = 2 * std::numbers::pi * j / nv;
      const Vec3 n{std::cos(theta) * std::cos(phi), std::sin(theta),
                   std::cos(theta) * std::sin(phi)};
      mesh.positions.push_back(center + Vec3{R * std::cos(phi), 0, R * std::sin(phi)} + n * r);
      if (normals) mesh.normals.push_back(Normal3(n));
    }
  }
  const auto at = [&](int i, int j) {
    return static_cast<std::uint32_t>((i % nu) * nv + (j % nv));
  };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  orientOutward(mesh, [&](const Point3& p) {
    const Vec3 radial = normalize(Vec3{p.x - center.x, 0, p.z - center.z});
    return p - (center + radial * R);
  });
  return mesh;
}

// A flat sheet over [0, n]² in the plane z = 0: n × n unit cells, each split into two triangles
// along alternating diagonals (so interior vertices are shared by fans of 4 or 8 triangles), with
// alternating windings in every other row (so shared edges are traversed both ways and the same
// way round).
TriangleMesh sheet(int n) {
  TriangleMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) mesh.positions.push_back({double(i), double(j), 0});
  }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      std::array<std::uint32_t, 6> t =
          (i + j) % 2 == 0 ? std::array{at(i, j), at(i + 1, j),     at(i + 1, j + 1),
                                        at(i, j), at(i + 1, j + 1), at(i, j + 1)}
                           : std::array{at(i, j),     at(i + 1, j),     at(i, j + 1),
                                        at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
      if (j % 2 == 1) std::swap(t[1], t[2]);
      mesh.indices.insert(mesh.indices.end(), t.begin(), t.end());
    }
  }
  return mesh;
}

// Random triangles in [−kHalf, kHalf]³, with exact duplicates, a pair sharing an edge, and three
// degenerate triangles (collinear, a repeated vertex, a non-finite vertex) that must never hit.
TriangleMesh triangleSoup(Rng& rng, int count) {
  TriangleMesh mesh;
  const auto vertex = [&](const Point3& p) {
    mesh.positions.push_back(p);
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
  };
  for (int i = 0; i < count; ++i) {
    const Point3 c = uniformPoint(rng, kHalf);
    const double size = 0.2 + 3 * rng.uniform();
    const std::uint32_t a = vertex(c);
    const std::uint32_t b = vertex(c + uniformDirection(rng) * size);
    const std::uint32_t d = vertex(c + uniformDirection(rng) * size);
    mesh.indices.insert(mesh.indices.end(), {a, b, d});
    if (rng.uniform() < 0.1) mesh.indices.insert(mesh.indices.end(), {a, b, d});
    if (rng.uniform() < 0.2) {
      mesh.indices.insert(mesh.indices.end(), {b, a, vertex(c + uniformDirection(rng) * size)});
    }
  }
  const std::uint32_t p = vertex({0, 0, 0});
  const std::uint32_t q = vertex({1, 1, 1});
  const std::uint32_t r = vertex({2, 2, 2});
  const std::uint32_t bad = vertex({std::nan(""), 0, 0});
  mesh.indices.insert(mesh.indices.end(), {p, q, r, p, p, q, p, q, bad});
  return mesh;
}

struct MeshScene {
  TestScene analytic;
  std::vector<TriangleMesh> meshes;
  std::vector<Color> meshKt;

  Aggregate make(Acceleration acceleration) const {
    return Aggregate(analytic.prims, analytic.kt, meshes, meshKt, acceleration);
  }
};

MeshScene randomMeshScene(std::uint64_t seed) {
  Rng rng(seed);
  MeshScene s{randomScene(seed, 30), {}, {}};
  s.meshes.push_back(torus({2, -1, 1}, 5, 1.5, 24, 12, true));
  s.meshes.push_back(uvSphere({-4, 3, -2}, 3, 10, 16, false));
  s.meshes.push_back(triangleSoup(rng, 40));
  for (std::size_t m = 0; m < s.meshes.size(); ++m) s.meshKt.push_back(randomTransmission(rng));
  return s;
}

// A point on a random triangle of a random mesh: a vertex, a point on an edge (its midpoint or a
// random one), or an interior point.
Point3 meshTarget(Rng& rng, const TriangleMesh& mesh) {
  const std::size_t t = pickIndex(rng, mesh.triangleCount());
  const Point3& a = mesh.positions[mesh.indices[3 * t]];
  const Point3& b = mesh.positions[mesh.indices[3 * t + 1]];
  const Point3& c = mesh.positions[mesh.indices[3 * t + 2]];
  const double u = rng.uniform();
  if (u < 0.3) return a;
  if (u < 0.45) return a + (b - a) * 0.5;
  if (u < 0.6) return b + (c - b) * rng.uniform();
  const double r1 = rng.uniform();
  const double r2 = rng.uniform() * (1 - r1);
  return a + (b - a) * r1 + (c - a) * r2;
}

// Rays at mesh vertices, edges and interiors: from far outside, from inside the scene,
// axis-parallel ones, and grazing ones lying in a triangle's plane; plus the analytic scene's own
// query set.
std::vector<Query> meshQueries(const MeshScene& s, std::uint64_t seed, int count) {
  Rng rng(seed);
  std::vector<Query> queries = randomQueries(s.analytic, seed + 7, count / 4);
  for (int i = 0; i < count; ++i) {
    const TriangleMesh& mesh = s.meshes[pickIndex(rng, s.meshes.size())];
    if (mesh.triangleCount() == 0) continue;
    const Point3 target = meshTarget(rng, mesh);
    if (!isFinite(target)) continue;
    Query q;
    switch (static_cast<int>(rng.uniform() * 4)) {
      case 0: {
        const Point3 from = toPoint(uniformDirection(rng) * (4 * kHalf));
        q.ray = {from, (target - from) * (rng.uniform() < 0.5 ? 1.0 : 0.1)};
        break;
      }
      case 1: {
        const Point3 from = uniformPoint(rng, kHalf);
        q.ray = {from, target - from};
        break;
      }
      case 2: {
        Vec3 d;
        d[static_cast<int>(rng.uniform() * 3)] = rng.uniform() < 0.5 ? -1 : 1;
        q.ray = {target - d * (20 * rng.uniform() + 0.5), d};
        break;
      }
      default: {
        // In the plane of the triangle's first edge and the target: grazing.
        const std::size_t t = pickIndex(rng, mesh.triangleCount());
        const Point3& a = mesh.positions[mesh.indices[3 * t]];
        const Point3& b = mesh.positions[mesh.indices[3 * t + 1]];
        q.ray = {a - (b - a) * 3.0, b - a};
        break;
      }
    }
    if (rng.uniform() < 0.2) q.tMin = 0.5 * rng.uniform();
    queries.push_back(q);
  }
  return queries;
}

// The vertices of a hit triangle, in index order.
std::array<Point3, 3> hitTriangleVertices(const Aggregate& a, const Hit& h) {
  const TriangleMesh& mesh = a.meshes()[h.mesh];
  const std::uint32_t* v = &mesh.indices[3 * static_cast<std::size_t>(h.triangle)];
  return {mesh.positions[v[0]], mesh.positions[v[1]], mesh.positions[v[2]]};
}

// The same element at the same t, or a tie (another element hitting at exactly the same t). x is
// the BVH's answer, y brute force's; the BVH renumbers mesh triangles, so triangles are compared by
// their vertices.
bool sameHit(const Aggregate& a, const Aggregate& brute, const Hit& x, const Hit& y,
             const Query& q) {
  if (x.t != y.t) return false;
  if (x.mesh == y.mesh &&
      (x.mesh == kNoMesh ? x.primitive == y.primitive
                         : hitTriangleVertices(a, x) == hitTriangleVertices(brute, y))) {
    return x.normal == y.normal && x.shadingNormal == y.shadingNormal;
  }
  // A tie: the element the BVH reports must hit at exactly that t.
  if (x.mesh == kNoMesh) {
    ShapeHit h;
    return a.primitives()[x.primitive].intersect(q.ray, q.tMin, q.tMax, h) && h.t == x.t;
  }
  const TriangleMesh& mesh = a.meshes()[x.mesh];
  const Triangle tri = Triangle::make(mesh.positions[mesh.indices[3 * x.triangle]],
                                      mesh.positions[mesh.indices[3 * x.triangle + 1]],
                                      mesh.positions[mesh.indices[3 * x.triangle + 2]]);
  ShapeHit h;
  return tri.intersect(q.ray, q.tMin, q.tMax, h) && h.t == x.t;
}

struct Agreement {
  int mismatches = 0;
  int hits = 0;
  int meshHits = 0;
  int partial = 0;
};

Agreement compareWithBruteForce(const Aggregate& bvh, const Aggregate& brute,
                                const std::vector<Query>& queries) {
  Agreement result;
  for (const Query& q : queries) {
    Hit expected;
    Hit actual;
    const bool e = brute.intersect(q.ray, q.tMin, q.tMax, expected);
    const bool a = bvh.intersect(q.ray, q.tMin, q.tMax, actual);
    bool ok = e == a && (!e || sameHit(bvh, brute, actual, expected, q));
    const Color expectedT = brute.transmittance(q.ray, q.tMin, q.tMax);
    ok = ok && expectedT == bvh.transmittance(q.ray, q.tMin, q.tMax);
    if (!ok && ++result.mismatches <= 8) {
      ADD_FAILURE() << "disagreement for ray o=(" << q.ray.origin.x << ", " << q.ray.origin.y
                    << ", " << q.ray.origin.z << ") d=(" << q.ray.direction.x << ", "
                    << q.ray.direction.y << ", " << q.ray.direction.z << ") t in (" << q.tMin
                    << ", " << q.tMax << "): hit " << a << "/" << e << " t " << actual.t << "/"
                    << expected.t << " mesh " << actual.mesh << "/" << expected.mesh << " tri "
                    << actual.triangle << "/" << expected.triangle << " prim " << actual.primitive
                    << "/" << expected.primitive;
    }
    result.hits += e;
    result.meshHits += e && expected.mesh != kNoMesh;
    result.partial += !isBlack(expectedT) && !(expectedT == Color(1));
  }
  return result;
}

// Every field of two hits equal, bit for bit.
bool identicalHit(const Hit& a, const Hit& b) {
  return a.t == b.t && a.normal == b.normal && a.shadingNormal == b.shadingNormal &&
         a.point == b.point && a.pointError == b.pointError && a.primitive == b.primitive &&
         a.mesh == b.mesh && a.triangle == b.triangle;
}

TEST(AggregateMeshTest, MeshesAndPrimitivesMatchBruteForce) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE("scene seed " + std::to_string(seed));
    const MeshScene s = randomMeshScene(seed);
    const Aggregate brute = s.make(Acceleration::BruteForce);
    const std::vector<Query> queries = meshQueries(s, 500 + seed, 1200);
    for (const Acceleration kind : kTreeKinds) {
      SCOPED_TRACE(treeName(kind));
      const Aggregate bvh = s.make(kind);
      AggregateInspector::check(bvh);
      EXPECT_EQ(bvh.bounds(), brute.bounds());
      EXPECT_EQ(bvh.triangleCount(), brute.triangleCount());
      const Agreement agreement = compareWithBruteForce(bvh, brute, queries);
      EXPECT_EQ(agreement.mismatches, 0) << "of " << queries.size() << " queries";
      EXPECT_GT(agreement.meshHits, static_cast<int>(queries.size()) / 3);
      EXPECT_LT(agreement.hits, static_cast<int>(queries.size()));
      EXPECT_GT(agreement.partial, static_cast<int>(queries.size()) / 20);
    }
  }
}

// Transmission factors whose products round: the order in which a shadow ray multiplies them in
// shows in the last bits.
Color roundingTransmission(Rng& rng) {
  if (rng.uniform() < 0.1) return Color(0);
  return Color(0.3 + 0.69 * rng.uniform(), 0.3 + 0.69 * rng.uniform(), 0.3 + 0.69 * rng.uniform());
}

// The 8-wide tree is the 4-wide one collapsed: the same leaves with the same boxes in the same
// depth-first slot order, the same triangle numbering, and so the same answers bit for bit — the
// closest hit (ties included) and the transmittance product, multiplied in the same order.
TEST(AggregateMeshTest, BothNodeWidthsGiveTheSameAnswersBitForBit) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("scene seed " + std::to_string(seed));
    MeshScene s = randomMeshScene(seed);
    Rng rng(seed + 40);
    for (Color& kt : s.analytic.kt) kt = roundingTransmission(rng);
    for (Color& kt : s.meshKt) kt = roundingTransmission(rng);
    s.meshes.push_back(torus({-3, 2, 4}, 3, 1, 60, 30, true));
    s.meshKt.push_back(Color(0.7, 0.9, 0.8));
    const Aggregate four = s.make(Acceleration::Bvh4);
    const Aggregate eight = s.make(Acceleration::Bvh8);
    AggregateInspector::check(four);
    AggregateInspector::check(eight);
    EXPECT_EQ(AggregateInspector::leavesInSlotOrder(four),
              AggregateInspector::leavesInSlotOrder(eight));
    EXPECT_LT(AggregateInspector::nodeCount(eight), AggregateInspector::nodeCount(four));
    ASSERT_EQ(four.meshes().size(), eight.meshes().size());
    for (std::size_t m = 0; m < four.meshes().size(); ++m) {
      EXPECT_EQ(four.meshes()[m].indices, eight.meshes()[m].indices);
      EXPECT_TRUE(four.meshes()[m].positions == eight.meshes()[m].positions);
    }
    const std::vector<Query> queries = meshQueries(s, 900 + seed, 1500);
    int mismatches = 0;
    int partial = 0;
    for (const Query& q : queries) {
      Hit x;
      Hit y;
      const bool fx = four.intersect(q.ray, q.tMin, q.tMax, x);
      const bool fy = eight.intersect(q.ray, q.tMin, q.tMax, y);
      const Color tx = four.transmittance(q.ray, q.tMin, q.tMax);
      const Color ty = eight.transmittance(q.ray, q.tMin, q.tMax);
      mismatches += fx == fy && (!fx || identicalHit(x, y)) && tx == ty ? 0 : 1;
      partial += !isBlack(tx) && !(tx == Color(1)) ? 1 : 0;
    }
    EXPECT_EQ(mismatches, 0) << "of " << queries.size() << " queries";
    EXPECT_GT(partial, static_cast<int>(queries.size()) / 20);
  }
}

TEST(AggregateMeshTest, BruteForceModeMatchesTheReferenceLoopOnPrimitives) {
  const TestScene s = randomScene(3, 60);
  const Aggregate brute(s.prims, s.kt, {}, {}, Acceleration::BruteForce);
  EXPECT_EQ(brute.acceleration(), Acceleration::BruteForce);
  int mismatches = 0;
  for (const Query& q : randomQueries(s, 77, 200)) {
    Hit expected;
    Hit actual;
    const bool e = bruteIntersect(s.prims, q.ray, q.tMin, q.tMax, expected);
    const bool a = brute.intersect(q.ray, q.tMin, q.tMax, actual);
    if (e != a || (e && (actual.t != expected.t || actual.primitive != expected.primitive))) {
      ++mismatches;
    }
    if (!(bruteTransmittance(s.prims, s.kt, q.ray, q.tMin, q.tMax) ==
          brute.transmittance(q.ray, q.tMin, q.tMax))) {
      ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// Rays aimed exactly at every vertex and every edge midpoint of a closed mesh, from outside within
// ~30° of the surface normal and from a point inside behind the target, must hit it (at or before
// the target), and every ray from inside must hit; both for the BVH and for brute force. (A ray
// that reaches a saddle-shaped part tangentially may touch it without crossing, so targets are not
// approached from arbitrary directions.)
void expectWatertight(const TriangleMesh& mesh, const std::vector<Point3>& insidePoints,
                      const std::function<Vec3(const Point3&)>& outward, double depth) {
  const Aggregate bvh({}, {}, {mesh}, {Color(0.5)});
  const Aggregate brute({}, {}, {mesh}, {Color(0.5)}, Acceleration::BruteForce);
  std::vector<Point3> targets = mesh.positions;
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const Point3& a = mesh.positions[mesh.indices[3 * t + e]];
      const Point3& b = mesh.positions[mesh.indices[3 * t + (e + 1) % 3]];
      targets.push_back(a + (b - a) * 0.5);
    }
  }
  Rng rng(42);
  int outsideMisses = 0;
  int insideMisses = 0;
  int rays = 0;
  for (const Point3& target : targets) {
    const Vec3 n = normalize(outward(target));
    const Point3 from = target + (n + uniformDirection(rng) * 0.5) * (2 + 5 * rng.uniform());
    const Ray ray{from, target - from};
    for (const Aggregate* a : {&bvh, &brute}) {
      Hit hit;
      if (!a->intersect(ray, 0, kInfinity, hit) || hit.t > 1 + 1e-9) ++outsideMisses;
    }
    // From inside, towards the target and in a random direction.
    const Point3 behind = target - (n + uniformDirection(rng) * 0.5) * (depth * rng.uniform());
    const Ray towards{behind, target - behind};
    const Point3& inside = insidePoints[pickIndex(rng, insidePoints.size())];
    const Ray random{inside, uniformDirection(rng)};
    for (const Aggregate* a : {&bvh, &brute}) {
      Hit hit;
      if (!a->intersect(towards, 0, kInfinity, hit) || hit.t > 1 + 1e-9) ++insideMisses;
      if (!a->intersect(random, 0, kInfinity, hit)) ++insideMisses;
      // Leaving a closed surface crosses it at least once.
      if (!(a->transmittance(random, 0, kInfinity).r <= 0.5)) ++insideMisses;
    }
    ++rays;
  }
  EXPECT_GT(rays, 1000);
  EXPECT_EQ(outsideMisses, 0) << "of " << rays << " rays from outside";
  EXPECT_EQ(insideMisses, 0) << "of " << rays << " rays from inside";
}

TEST(AggregateMeshTest, ClosedSphereMeshIsWatertightAtVerticesAndEdges) {
  const Point3 c{0.3, -0.2, 0.1};
  const TriangleMesh mesh = uvSphere(c, 2, 16, 32, false);
  Rng rng(5);
  std::vector<Point3> inside;
  for (int i = 0; i < 16; ++i) inside.push_back(c + uniformDirection(rng) * (1.8 * rng.uniform()));
  inside.push_back(c);
  expectWatertight(
      mesh, inside, [&](const Point3& p) { return p - c; }, 1.5);
}

TEST(AggregateMeshTest, ClosedTorusMeshIsWatertightAtVerticesAndEdges) {
  const Point3 c{1, 2, -1};
  const double R = 3;
  const double r = 1;
  const TriangleMesh mesh = torus(c, R, r, 32, 16, true);
  Rng rng(6);
  std::vector<Point3> inside;
  for (int i = 0; i < 16; ++i) {
    const double phi = 2 * std::numbers::pi * rng.uniform();
    inside.push_back(c + Vec3{R * std::cos(phi), 0, R * std::sin(phi)} +
                     uniformDirection(rng) * (0.8 * r * rng.uniform()));
  }
  expectWatertight(
      mesh, inside,
      [&](const Point3& p) {
        const Vec3 radial = normalize(Vec3{p.x - c.x, 0, p.z - c.z});
        return p - (c + radial * R);
      },
      0.5);
}

TEST(AggregateMeshTest, ShadingNormalInterpolatesVertexNormals) {
  const Point3 c{0, 0, 0};
  const TriangleMesh smooth = uvSphere(c, 1.5, 8, 12, true);
  const Aggregate a({}, {}, {smooth}, {Color(0)});
  // The aggregate keeps every vertex and triangle (none is degenerate), renumbered.
  ASSERT_EQ(a.meshes()[0].positions.size(), smooth.positions.size());
  ASSERT_EQ(a.meshes()[0].triangleCount(), smooth.triangleCount());
  // Aimed at a vertex along its normal: the shading normal is that vertex's normal, and unit.
  for (std::size_t v = 0; v < smooth.positions.size(); ++v) {
    const Vec3 n = toVec(smooth.normals[v]);
    const Ray ray{smooth.positions[v] + n * 4, -n};
    Hit hit;
    ASSERT_TRUE(a.intersect(ray, 0, kInfinity, hit));
    EXPECT_NEAR(hit.t, 4, 1e-12);
    EXPECT_EQ(hit.mesh, 0u);
    const TriangleMesh& stored = a.meshes()[0];
    const std::uint32_t* tri = &stored.indices[3 * hit.triangle];
    EXPECT_TRUE(stored.positions[tri[0]] == smooth.positions[v] ||
                stored.positions[tri[1]] == smooth.positions[v] ||
                stored.positions[tri[2]] == smooth.positions[v])
        << "the hit triangle holds the vertex";
    EXPECT_NEAR(hit.shadingNormal.x, n.x, 1e-12);
    EXPECT_NEAR(hit.shadingNormal.y, n.y, 1e-12);
    EXPECT_NEAR(hit.shadingNormal.z, n.z, 1e-12);
    EXPECT_NEAR(length(hit.shadingNormal), 1, 1e-15);
    // The geometric normal is the triangle's, by the right-hand rule over its index order.
    const Point3& p0 = stored.positions[tri[0]];
    const Vec3 geometric =
        normalize(cross(stored.positions[tri[1]] - p0, stored.positions[tri[2]] - p0));
    EXPECT_EQ(toVec(hit.normal), geometric);
    EXPECT_GT(dot(hit.normal, n), 0.8);
  }
  // Inside a triangle: unit, between the geometric normal and the sphere's.
  Rng rng(3);
  for (int i = 0; i < 200; ++i) {
    const Vec3 d = uniformDirection(rng);
    const Ray ray{toPoint(d * 5), -d};
    Hit hit;
    ASSERT_TRUE(a.intersect(ray, 0, kInfinity, hit));
    EXPECT_NEAR(length(hit.shadingNormal), 1, 1e-15);
    EXPECT_GT(dot(hit.shadingNormal, d), 0.99);  // close to the true sphere normal
  }
  // Without vertex normals the shading normal is the geometric one.
  const Aggregate flat({}, {}, {uvSphere(c, 1.5, 8, 12, false)}, {Color(0)});
  Hit hit;
  ASSERT_TRUE(flat.intersect({{0.2, 0.1, 5}, {0, 0, -1}}, 0, kInfinity, hit));
  EXPECT_EQ(hit.shadingNormal, hit.normal);
  EXPECT_NEAR(length(hit.normal), 1, 1e-15);
}

TEST(AggregateMeshTest, DegenerateTrianglesNeverHit) {
  TriangleMesh mesh;
  mesh.positions = {
      {0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0, 0, 5}, {1, 0, 5}, {0, 1, 5}, {std::nan(""), 0, 0},
      {1, 0, 0}};
  // Collinear, a repeated vertex, a NaN vertex, nearly collinear (thinner than 1e-12), then one
  // proper triangle at z = 5.
  mesh.indices = {0, 1, 2, 0, 0, 1, 6, 7, 1, 0, 7, 0, 3, 4, 5};
  mesh.positions.push_back({1, 1e-14, 0});
  mesh.indices[11] = 8;
  for (const Acceleration acceleration : {Acceleration::Bvh, Acceleration::BruteForce}) {
    const Aggregate a({}, {}, {mesh}, {Color(0)}, acceleration);
    EXPECT_EQ(a.triangleCount(), 1u);
    EXPECT_EQ(a.bounds(), Bounds3({0, 0, 5}, {1, 1, 5}));
    Hit hit;
    // Through the collinear triangles' line and their points, from several directions.
    for (const Vec3& d : {Vec3{0, 0, 1}, Vec3{1, -1, 0}, Vec3{0.3, 0.2, -1}}) {
      for (const Point3& p : {Point3{1, 1, 1}, Point3{0.5, 0.5, 0.5}, Point3{0.5, 0, 0}}) {
        const Ray ray{p - d * 3, d};
        EXPECT_FALSE(a.intersect(ray, 0, 5, hit)) << "a degenerate triangle was hit";
        EXPECT_EQ(a.transmittance(ray, 0, 5), Color(1));
      }
    }
    ASSERT_TRUE(a.intersect({{0.2, 0.2, 0}, {0, 0, 1}}, 0, kInfinity, hit));
    // Brute force keeps the input numbering; the BVH keeps only the proper triangle, renumbered.
    EXPECT_EQ(hit.triangle, acceleration == Acceleration::Bvh ? 0u : 4u);
    EXPECT_EQ(a.meshes()[0].triangleCount(), acceleration == Acceleration::Bvh ? 1u : 5u);
    EXPECT_EQ(hit.t, 5);
  }
  // Nothing but degenerate triangles: an empty structure.
  mesh.indices.resize(12);
  const Aggregate empty({}, {}, {mesh}, {Color(0)});
  EXPECT_EQ(empty.triangleCount(), 0u);
  EXPECT_TRUE(empty.bounds().isEmpty());
  Hit hit;
  EXPECT_FALSE(empty.intersect({{0.5, 0.5, -1}, {0, 0, 1}}, 0, kInfinity, hit));
}

// Triangle references are made in chunks of 4096 and squeezed past the dropped ones from the
// first chunk that drops any: a strip of 20000 triangles whose first degenerate one lies in the
// second chunk keeps every proper triangle exactly once, and leaves holes where the others were.
TEST(AggregateMeshTest, DegenerateTrianglesInLaterChunksLeaveHolesAndNothingElse) {
  constexpr std::uint32_t kQuads = 10000;
  TriangleMesh mesh;
  for (std::uint32_t i = 0; i <= kQuads; ++i) {
    mesh.positions.push_back({static_cast<double>(i), 0, 0});
    mesh.positions.push_back({static_cast<double>(i), 1, 0});
  }
  for (std::uint32_t i = 0; i < kQuads; ++i) {
    const std::uint32_t v = 2 * i;
    mesh.indices.insert(mesh.indices.end(), {v, v + 2, v + 1, v + 1, v + 2, v + 3});
  }
  const std::set<std::uint32_t> holes = {5000, 9001, 12288, 19999};  // triangle numbers
  for (const std::uint32_t t : holes) mesh.indices[3 * t + 1] = mesh.indices[3 * t];
  const Aggregate a({}, {}, {mesh}, {Color(0)}, Acceleration::Bvh);
  EXPECT_EQ(a.triangleCount(), 2 * kQuads - holes.size());
  AggregateInspector::check(a);
  Hit hit;
  for (std::uint32_t t = 0; t < 2 * kQuads; ++t) {
    // The centroid of triangle t as the strip was made, before the holes.
    const double x = t / 2 + (t % 2 == 0 ? 1.0 / 3 : 2.0 / 3);
    const double y = t % 2 == 0 ? 1.0 / 3 : 2.0 / 3;
    const bool hits = a.intersect({{x, y, 1}, {0, 0, -1}}, 0, kInfinity, hit);
    EXPECT_EQ(hits, holes.count(t) == 0) << "triangle " << t;
  }
}

TEST(AggregateMeshTest, InvalidMeshesAreRejected) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.indices = {0, 1, 2};
  EXPECT_NO_THROW(Aggregate({}, {}, {mesh}, {Color(1)}));
  EXPECT_THROW(Aggregate({}, {}, {mesh}, {}), std::invalid_argument);

  TriangleMesh bad = mesh;
  bad.indices = {0, 1, 3};
  try {
    const Aggregate a({}, {}, {mesh, bad}, {Color(1), Color(1)});
    ADD_FAILURE() << "an index past the positions was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "mesh 1: vertex 2 of triangle 0 is index 3, past its 3 positions");
  }
  bad.indices = {0, 1, 2, 0};
  EXPECT_THROW(Aggregate({}, {}, {bad}, {Color(1)}), std::invalid_argument);
  bad = mesh;
  bad.normals = {Normal3(0, 0, 1)};
  EXPECT_THROW(Aggregate({}, {}, {bad}, {Color(1)}), std::invalid_argument);
}

TEST(AggregateMeshTest, MeshTransmissionCountsEveryCrossing) {
  // Two parallel unit squares (two triangles each) with kt 0.5 and 0.25, and a kt-1 mesh.
  TriangleMesh square;
  square.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  square.indices = {0, 1, 2, 0, 2, 3};
  TriangleMesh far = square;
  for (Point3& p : far.positions) p.z = 2;
  const Aggregate a({}, {}, {square, far, square}, {Color(0.5), Color(0.25, 0.5, 1), Color(1)});
  const Ray ray{{0.3, -0.4, -1}, {0, 0, 1}};
  EXPECT_EQ(a.transmittance(ray, 0, kInfinity), Color(0.125, 0.25, 0.5));
  EXPECT_EQ(a.transmittance(ray, 0, 2), Color(0.5));
  EXPECT_EQ(a.transmittance(ray, 1, 2.5), Color(1));
  Hit hit;
  ASSERT_TRUE(a.intersect(ray, 0, kInfinity, hit));
  EXPECT_EQ(hit.t, 1);
  EXPECT_NE(hit.mesh, 1u);
  EXPECT_EQ(hit.normal, Normal3(0, 0, 1));
  // An opaque mesh blacks the shadow ray out.
  const Aggregate opaque({}, {}, {square, far}, {Color(0.5), Color(0)});
  EXPECT_EQ(opaque.transmittance(ray, 0, kInfinity), Color(0));
}

// A shadow ray through an edge shared by two triangles, or through a vertex shared by a fan,
// crosses the surface once: kt is applied once, by the BVH and by brute force alike (issue 6: no
// ray passes between two triangles sharing an edge, and none is counted twice). Vertical rays hit
// the sheet's edges and vertices exactly (every edge function is exactly 0 there); oblique ones
// nearly.
TEST(AggregateMeshTest, ShadowRayThroughASharedEdgeOrVertexCrossesOnce) {
  const int n = 4;
  const TriangleMesh mesh = sheet(n);
  const std::array<Vec3, 6> directions{Vec3{0, 0, -1},     Vec3{0, 0, 1},      Vec3{0.3, -0.2, -1},
                                       Vec3{-1, 0.5, 0.7}, Vec3{0.1, 1, -0.4}, Vec3{1, 1, -1}};
  for (const Acceleration acceleration : {Acceleration::Bvh, Acceleration::BruteForce}) {
    const Aggregate a({}, {}, {mesh}, {Color(0.5)}, acceleration);
    int rays = 0;
    int wrong = 0;
    // Every vertex, edge midpoint, diagonal point and cell centre strictly inside the sheet.
    for (int yi = 1; yi < 4 * n; ++yi) {
      for (int xi = 1; xi < 4 * n; ++xi) {
        const Point3 target{xi / 4.0, yi / 4.0, 0};
        for (const Vec3& d : directions) {
          const Ray ray{target - d * 3, d};
          const Color t = a.transmittance(ray, 0, kInfinity);
          Hit hit;
          const bool hits = a.intersect(ray, 0, kInfinity, hit);
          if (!(t == Color(0.5)) || !hits || std::abs(hit.t - 3) > 1e-12) {
            if (++wrong <= 5) {
              ADD_FAILURE() << "ray at (" << target.x << ", " << target.y << ") d=(" << d.x << ", "
                            << d.y << ", " << d.z << "): transmittance " << t.r << ", hit " << hits;
            }
          }
          ++rays;
        }
      }
    }
    EXPECT_EQ(wrong, 0) << "of " << rays;
    // Along an interior edge (in the sheet's plane) the ray is parallel to it: no crossing.
    EXPECT_EQ(a.transmittance({{1, -1, 0}, {0, 1, 0}}, 0, kInfinity), Color(1));
  }
}

// Leaving a closed convex mesh through any of its vertices or edges crosses it exactly once.
TEST(AggregateMeshTest, ShadowRayLeavingAClosedMeshThroughVerticesAndEdgesCrossesOnce) {
  const Point3 c{0.25, -0.5, 0.125};
  const TriangleMesh mesh = uvSphere(c, 2, 12, 24, false);
  std::vector<Point3> targets = mesh.positions;
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const Point3& p = mesh.positions[mesh.indices[3 * t + e]];
      const Point3& q = mesh.positions[mesh.indices[3 * t + (e + 1) % 3]];
      targets.push_back(p + (q - p) * 0.5);
    }
  }
  for (const Acceleration acceleration : {Acceleration::Bvh, Acceleration::BruteForce}) {
    const Aggregate a({}, {}, {mesh}, {Color(0.5)}, acceleration);
    Rng rng(11);
    int wrong = 0;
    for (const Point3& target : targets) {
      const Point3 from = c + uniformDirection(rng) * (1.5 * rng.uniform());
      if (!(a.transmittance({from, target - from}, 0, kInfinity) == Color(0.5))) ++wrong;
      // Along the centre's axis too: through the pole fans and ring vertices head-on.
      if (!(a.transmittance({c, target - c}, 0, kInfinity) == Color(0.5))) ++wrong;
    }
    EXPECT_EQ(wrong, 0) << "of " << 2 * targets.size() << " rays";
  }
}

TEST(AggregateMeshTest, ParallelBuildIsIndependentOfTheThreadCount) {
#ifdef NDEBUG
  const int nu = 500;  // 200k triangles
#else
  const int nu = 180;  // 72k triangles: still above the parallel binning threshold
#endif
  const TriangleMesh mesh = torus({0, 0, 0}, 4, 1, nu, 200, true);
  const auto buildWith = [&](int threads) {
    std::optional<Aggregate> a;
    tbb::task_arena arena(threads);
    arena.execute([&] {
      a.emplace(std::vector<Primitive>{}, std::vector<Color>{}, std::vector<TriangleMesh>{mesh},
                std::vector<Color>{Color(0)});
    });
    return std::move(*a);
  };
  // (This machine class has 2 cores; oneTBB caps an arena at the hardware concurrency.)
  const Aggregate one = buildWith(1);
  const Aggregate two = buildWith(2);
  EXPECT_EQ(one.triangleCount(), mesh.triangleCount());
  EXPECT_TRUE(AggregateInspector::sameTree(one, two));
  AggregateInspector::check(two);
  // The mesh as stored, renumbered into leaf order with its vertices by first use (on two threads
  // numbered in blocks side by side, then merged): the same arrays too.
  ASSERT_EQ(one.meshes().size(), 1U);
  ASSERT_EQ(two.meshes().size(), 1U);
  EXPECT_EQ(one.meshes()[0].indices, two.meshes()[0].indices);
  EXPECT_TRUE(AggregateInspector::sameBytes(one.meshes()[0].positions, two.meshes()[0].positions));
  EXPECT_TRUE(AggregateInspector::sameBytes(one.meshes()[0].normals, two.meshes()[0].normals));
  EXPECT_EQ(one.meshes()[0].positions.size(), mesh.positions.size());  // every vertex is used
  // Memory: mesh (positions, normals, indices) and tree together within 64 bytes per triangle.
  const double bytesPerTriangle =
      static_cast<double>(one.memoryBytes()) / static_cast<double>(one.triangleCount());
  EXPECT_LE(bytesPerTriangle, 64);
  EXPECT_GT(bytesPerTriangle, 36);  // the mesh alone takes 36
  // The 8-wide tree too (bvh::collapseToWide): about 9 bytes per triangle more on this torus.
  const Aggregate wide(std::vector<Primitive>{}, std::vector<Color>{},
                       std::vector<TriangleMesh>{mesh}, std::vector<Color>{Color(0)},
                       Acceleration::Bvh8);
  EXPECT_LE(static_cast<double>(wide.memoryBytes()) / static_cast<double>(wide.triangleCount()),
            64);
}

// Packets (Aggregate::intersectPacket, transmittancePacket): every ray of a packet gets exactly
// its single-ray answers.
// Coherent packets (a 4×4 block of camera-like rays, aimed near a mesh vertex or a primitive's
// box corner so that they straddle edges and silhouettes, with a mix of far bounds), incoherent
// ones (the property queries in groups of 16: mixed octants, traced alone), short ones,
// shadow-ray packets converging on a light point, and packets of rays each exactly through a
// vertex or edge (the triangle tests' float pre-test must keep them).
TEST(AggregatePacketTest, EveryRayOfAPacketGetsItsSingleRayAnswers) {
  const IsaSupport here = isaSupportHere();
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("scene seed " + std::to_string(seed));
    const MeshScene s = randomMeshScene(seed);
    Rng rng(seed + 90);
    struct Packet {
      std::vector<Ray> rays;
      double tMin = 0;
      std::vector<double> tMax;
    };
    std::vector<Packet> packets;
    for (int p = 0; p < 150; ++p) {
      Packet packet;
      packet.tMin = p % 3 == 0 ? 1e-3 : 0;
      const Point3 eye = toPoint(uniformDirection(rng) * 40);
      Point3 target;
      if (p % 2 == 0) {
        target = meshTarget(rng, s.meshes[pickIndex(rng, s.meshes.size())]);
      } else {
        const Primitive& prim = s.analytic.prims[pickIndex(rng, s.analytic.prims.size())];
        target = prim.isBounded() ? prim.bounds().centroid() : Point3{0, 0, 0};
      }
      const Vec3 forward = normalize(target - eye);
      Vec3 right;
      Vec3 up;
      orthonormalBasis(forward, right, up);
      const double spread = 0.002 + 0.03 * rng.uniform();  // radians between neighbours
      const int count = p % 10 == 9 ? 1 + static_cast<int>(rng.uniform() * 15) : 16;
      for (int i = 0; i < count; ++i) {
        const double x = (i % 4 - 1.5) * spread;
        const double y = (i / 4 - 1.5) * spread;
        packet.rays.push_back({eye, forward + right * x + up * y});
        packet.tMax.push_back(rng.uniform() < 0.2 ? 20 + 40 * rng.uniform() : kInfinity);
      }
      packets.push_back(packet);
    }
    // Shadow-ray packets: from a 4 × 4 patch of points toward one light point, each ray ending
    // there (tMax = its distance) or running on to infinity.
    for (int p = 0; p < 100; ++p) {
      Packet packet;
      packet.tMin = p % 4 == 0 ? 1e-4 : 0;
      const Point3 light = toPoint(uniformDirection(rng) * (10 + 30 * rng.uniform()));
      const Point3 centre = p % 2 == 0 ? meshTarget(rng, s.meshes[pickIndex(rng, s.meshes.size())])
                                       : toPoint(uniformDirection(rng) * 8 * rng.uniform());
      Vec3 right;
      Vec3 up;
      orthonormalBasis(normalize(light - centre), right, up);
      const double spacing = 0.01 + 0.3 * rng.uniform();
      for (int i = 0; i < 16; ++i) {
        const Point3 from =
            centre + right * ((i % 4 - 1.5) * spacing) + up * ((i / 4 - 1.5) * spacing);
        const Vec3 toLight = light - from;
        packet.rays.push_back({from, normalize(toLight)});
        packet.tMax.push_back(p % 5 == 4 ? kInfinity : length(toLight));
      }
      packets.push_back(packet);
    }
    // Every ray of the packet exactly through a vertex or an edge point of neighbouring triangles
    // (the float pre-test must keep each: its exact test is a tie or a graze).
    for (int p = 0; p < 100; ++p) {
      Packet packet;
      const TriangleMesh& mesh = s.meshes[pickIndex(rng, s.meshes.size())];
      const std::size_t first = pickIndex(rng, mesh.triangleCount());
      const Point3 eye = toPoint(uniformDirection(rng) * (p % 2 == 0 ? 40 : 8));
      for (int i = 0; i < 16; ++i) {
        const std::size_t t = (first + static_cast<std::size_t>(i / 4)) % mesh.triangleCount();
        const Point3& a = mesh.positions[mesh.indices[3 * t]];
        const Point3& b = mesh.positions[mesh.indices[3 * t + 1]];
        const Point3& c = mesh.positions[mesh.indices[3 * t + 2]];
        const std::array<Point3, 4> targets{a, a + (b - a) * 0.5, b, b + (c - b) * rng.uniform()};
        const Vec3 toTarget = targets[static_cast<std::size_t>(i % 4)] - eye;
        packet.rays.push_back({eye, normalize(toTarget)});
        packet.tMax.push_back(p % 3 == 0 ? length(toTarget) * 1.5 : kInfinity);
      }
      packets.push_back(packet);
    }
    const std::vector<Query> queries = meshQueries(s, 300 + seed, 480);
    for (std::size_t q = 0; q + 16 <= queries.size(); q += 16) {
      Packet packet;
      for (std::size_t i = q; i < q + 16; ++i) {
        packet.rays.push_back(queries[i].ray);
        packet.tMax.push_back(queries[i].tMax);
      }
      packets.push_back(packet);
    }
    for (const auto& [isa, kind] :
         {std::pair{Isa::Baseline, Acceleration::Bvh4}, std::pair{Isa::Avx2, Acceleration::Bvh4},
          std::pair{Isa::Avx512, Acceleration::Bvh4}, std::pair{Isa::Avx512, Acceleration::Bvh8},
          std::pair{Isa::Baseline, Acceleration::BruteForce}}) {
      if (!here.runs(isa)) continue;
      SCOPED_TRACE(std::string(isaName(isa)) + ", " + treeName(kind));
      Aggregate aggregate = s.make(kind);
      aggregate.setIsa(isa);
      int mismatches = 0;
      int hits = 0;
      int rays = 0;
      int transmittanceMismatches = 0;
      int blocked = 0;
      int dimmed = 0;  // neither black nor 1: crossings of partly transparent surfaces
      for (const Packet& packet : packets) {
        const int count = static_cast<int>(packet.rays.size());
        std::array<Hit, Aggregate::kPacketSize> packetHits;
        std::array<bool, Aggregate::kPacketSize> packetFound{};
        aggregate.intersectPacket(packet.rays.data(), count, packet.tMin, packet.tMax.data(),
                                  packetHits.data(), packetFound.data());
        std::array<Color, Aggregate::kPacketSize> packetTransmittance;
        aggregate.transmittancePacket(packet.rays.data(), count, packet.tMin, packet.tMax.data(),
                                      packetTransmittance.data());
        for (int i = 0; i < count; ++i) {
          const Color single = aggregate.transmittance(packet.rays[i], packet.tMin, packet.tMax[i]);
          const Color& fromPacket = packetTransmittance[static_cast<std::size_t>(i)];
          transmittanceMismatches += std::memcmp(&single, &fromPacket, sizeof(Color)) == 0 ? 0 : 1;
          blocked += isBlack(single) ? 1 : 0;
          dimmed += !isBlack(single) && !(single == Color(1)) ? 1 : 0;
        }
        for (int i = 0; i < count; ++i) {
          Hit single;
          const bool found =
              aggregate.intersect(packet.rays[i], packet.tMin, packet.tMax[i], single);
          const auto k = static_cast<std::size_t>(i);
          const bool same =
              found == packetFound[k] && (!found || (identicalHit(single, packetHits[k]) &&
                                                     single.part == packetHits[k].part &&
                                                     single.instance == packetHits[k].instance));
          mismatches += same ? 0 : 1;
          hits += found ? 1 : 0;
          ++rays;
        }
      }
      EXPECT_EQ(mismatches, 0) << "of " << rays << " rays";
      EXPECT_GT(hits, rays / 3);
      EXPECT_LT(hits, rays);
      EXPECT_EQ(transmittanceMismatches, 0) << "of " << rays << " rays";
      EXPECT_GT(blocked, rays / 200);
      EXPECT_GT(dimmed, rays / 20);
    }
  }
}

// Instruction sets (core/isa.h). ctest also runs every test of this file under GLINT_ISA=avx2 and
// GLINT_ISA=avx512 (tests/CMakeLists.txt: aggregate_properties_*), where each Aggregate above
// starts with that ISA's kernels; here one tree is queried with every ISA this processor runs.

TEST(AggregateIsaTest, EveryIsaFindsTheBaselineHitsBitForBit) {
  const IsaSupport here = isaSupportHere();
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("scene seed " + std::to_string(seed));
    const MeshScene s = randomMeshScene(seed);
    // The answers of the 4-wide tree with the baseline kernels; every ISA on either width must
    // give them.
    Aggregate reference = s.make(Acceleration::Bvh4);
    EXPECT_EQ(reference.isa(), defaultIsa());
    const std::vector<Query> queries = meshQueries(s, 700 + seed, 1000);
    reference.setIsa(Isa::Baseline);
    std::vector<std::optional<Hit>> hits;
    std::vector<Color> transmittances;
    for (const Query& q : queries) {
      Hit hit;
      hits.push_back(reference.intersect(q.ray, q.tMin, q.tMax, hit) ? std::optional(hit)
                                                                     : std::nullopt);
      transmittances.push_back(reference.transmittance(q.ray, q.tMin, q.tMax));
    }
    for (const auto& [isa, kind] :
         {std::pair{Isa::Baseline, Acceleration::Bvh4}, std::pair{Isa::Avx2, Acceleration::Bvh4},
          std::pair{Isa::Avx512, Acceleration::Bvh4}, std::pair{Isa::Baseline, Acceleration::Bvh8},
          std::pair{Isa::Avx2, Acceleration::Bvh8}, std::pair{Isa::Avx512, Acceleration::Bvh8}}) {
      SCOPED_TRACE(std::string(isaName(isa)) + ", " + treeName(kind));
      Aggregate bvh = s.make(kind);
      if (!here.runs(isa)) {
        EXPECT_THROW(bvh.setIsa(isa), IsaError);
        continue;
      }
      bvh.setIsa(isa);
      EXPECT_EQ(bvh.isa(), isa);
      int mismatches = 0;
      for (std::size_t i = 0; i < queries.size(); ++i) {
        const Query& q = queries[i];
        Hit hit;
        const bool found = bvh.intersect(q.ray, q.tMin, q.tMax, hit);
        const bool same = found == hits[i].has_value() && (!found || identicalHit(hit, *hits[i])) &&
                          bvh.transmittance(q.ray, q.tMin, q.tMax) == transmittances[i];
        mismatches += same ? 0 : 1;
      }
      EXPECT_EQ(mismatches, 0) << "of " << queries.size() << " queries";
    }
  }
}

TEST(AggregateIsaTest, AggregatesStartWithTheProcessDefault) {
  const TestScene s = randomScene(2, 20);
  const Aggregate aggregate(s.prims, s.kt);
  EXPECT_EQ(aggregate.isa(), defaultIsa());
  const char* forced = std::getenv("GLINT_ISA");
  if (forced != nullptr && *forced != '\0' && std::string(forced) != "auto") {
    EXPECT_EQ(isaName(aggregate.isa()), forced);
  } else {
    EXPECT_EQ(aggregate.isa(), bestIsa(isaSupportHere()));
  }
}

}  // namespace
}  // namespace glint
