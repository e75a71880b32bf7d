// The BVH against a brute-force loop over all primitives (closest hit and transmittance must agree
// bit for bit), its structural invariants, and analytic queries on regular scenes.
#include "glint/accel/aggregate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "glint/core/rng.h"

namespace glint {

// Reads the private node layout (friend of Aggregate) and checks what the build promises.
struct AggregateInspector {
  struct Summary {
    int maxDepth = 0;
    std::size_t nodes = 0;
    std::size_t leaves = 0;
  };

  static Summary check(const Aggregate& a) {
    Summary summary;
    summary.nodes = a.nodes_.size();
    const auto& prims = a.primitives_;
    std::vector<std::uint32_t> bounded;
    std::vector<std::uint32_t> unbounded;
    for (std::uint32_t i = 0; i < prims.size(); ++i) {
      (prims[i].isBounded() ? bounded : unbounded).push_back(i);
    }
    EXPECT_EQ(a.unbounded_, unbounded);
    std::vector<std::uint32_t> order = a.order_;
    std::sort(order.begin(), order.end());
    EXPECT_EQ(order, bounded) << "order_ must be a permutation of the bounded primitives";
    if (a.nodes_.empty()) {
      EXPECT_TRUE(bounded.empty());
      return summary;
    }
    EXPECT_EQ(a.nodes_[0].bounds, a.bounds_);

    // Walk the tree; every node must be reached once, leaves must tile order_ in sequence.
    std::vector<int> visits(a.nodes_.size(), 0);
    std::uint32_t nextLeafStart = 0;
    struct Item {
      std::uint32_t node;
      int depth;
    };
    std::vector<Item> stack{{0, 1}};
    while (!stack.empty()) {
      const Item item = stack.back();
      stack.pop_back();
      EXPECT_LT(item.node, a.nodes_.size());
      if (item.node >= a.nodes_.size()) return summary;
      ++visits[item.node];
      summary.maxDepth = std::max(summary.maxDepth, item.depth);
      const auto& node = a.nodes_[item.node];
      if (node.count > 0) {
        ++summary.leaves;
        EXPECT_LE(node.count, 4);
        EXPECT_EQ(node.offset, nextLeafStart) << "leaves must appear depth-first in order_";
        nextLeafStart = node.offset + node.count;
        for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
          EXPECT_EQ(unite(node.bounds, prims[a.order_[i]].bounds()), node.bounds);
        }
      } else {
        EXPECT_GT(node.offset, item.node + 1);
        EXPECT_LE(node.axis, 2);
        const auto& first = a.nodes_[item.node + 1];
        const auto& second = a.nodes_[node.offset];
        EXPECT_EQ(unite(first.bounds, second.bounds), node.bounds);
        // Depth-first: the second child comes after the whole first subtree.
        stack.push_back({node.offset, item.depth + 1});
        stack.push_back({item.node + 1, item.depth + 1});
      }
    }
    EXPECT_EQ(nextLeafStart, a.order_.size());
    EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; }));
    EXPECT_EQ(summary.nodes, 2 * summary.leaves - 1);
    return summary;
  }
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

TEST(AggregateTest, MatchesBruteForceOnRandomScenes) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("scene seed " + std::to_string(seed));
    const TestScene s = randomScene(seed, seed <= 2 ? 12 : 90);
    const Aggregate aggregate(s.prims, s.kt);
    AggregateInspector::check(aggregate);
    expectMatchesBruteForce(s, aggregate, randomQueries(s, 1000 + seed, 300));
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
  EXPECT_LE(summary.maxDepth, 6);  // median splits of 50 coincident centroids: balanced

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
  EXPECT_LE(summary.maxDepth, 16);  // close to log2(1000/4) ≈ 8 for a regular grid
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
  EXPECT_LE(summary.maxDepth, 64 + 32);
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

}  // namespace
}  // namespace glint
