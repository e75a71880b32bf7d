// Csg against a brute-force reference: random trees of random solids, thousands of random rays;
// the closest hit, its normal, the crossing count and the shadow transmittance must equal what
// classifying points along the ray by independent inside tests gives. Plus the closed-mesh check,
// the limits and the normals of a cut.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "glint/core/rng.h"
#include "glint/geometry/csg.h"

namespace glint {
namespace {

using ::testing::HasSubstr;

constexpr double kInf = std::numeric_limits<double>::infinity();

// A cube [lo, hi]³ as 12 outward triangles over 8 shared vertices.
std::shared_ptr<const CsgMesh> cubeMesh(double lo, double hi, bool insideOut = false) {
  std::vector<Point3> p;
  for (int k = 0; k < 8; ++k) {
    p.push_back({(k & 1) ? hi : lo, (k & 2) ? hi : lo, (k & 4) ? hi : lo});
  }
  // Faces as quads (counter-clockwise seen from outside), split into two triangles.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::uint32_t> indices;
  for (const auto& q : quads) {
    const std::uint32_t a = q[0], b = q[1], c = q[2], d = q[3];
    if (insideOut) {
      indices.insert(indices.end(), {a, c, b, a, d, c});
    } else {
      indices.insert(indices.end(), {a, b, c, a, c, d});
    }
  }
  return CsgMesh::make(p, indices);
}

// Whether point p (csg space) is inside one operand, by a test independent of the ray code:
// distances for the analytic solids, crossing parity of a fixed skew ray for meshes.
bool insideOperand(const CsgOperand& operand, const Point3& p) {
  const Point3 q = operand.csgFromSolid ? operand.csgFromSolid->inverse()(p) : p;
  if (const auto* s = std::get_if<Sphere>(&operand.solid)) {
    return length(q - s->center) < s->radius;
  }
  if (const auto* b = std::get_if<Box>(&operand.solid)) {
    return q.x > b->lo.x && q.x < b->hi.x && q.y > b->lo.y && q.y < b->hi.y && q.z > b->lo.z &&
           q.z < b->hi.z;
  }
  if (const auto* c = std::get_if<Cylinder>(&operand.solid)) {
    const Vec3 rel = q - c->base;
    const double along = dot(rel, c->axis);
    return along > 0 && along < c->height && length(rel - c->axis * along) < c->radius;
  }
  const CsgMesh& mesh = *std::get<std::shared_ptr<const CsgMesh>>(operand.solid);
  const Ray probe{q, normalize(Vec3{0.3127, 0.5161, 0.7979})};
  int crossings = 0;
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const Triangle tri =
        Triangle::make(mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                       mesh.positions[mesh.indices[3 * t + 2]]);
    ShapeHit hit;
    crossings += tri.intersect(probe, 0, kInf, hit) ? 1 : 0;
  }
  return crossings % 2 == 1;
}

bool insideTree(const CsgTree& tree, const Point3& p) {
  std::vector<bool> stack;
  for (const CsgNode& node : tree.postorder) {
    if (node.isSolid) {
      stack.push_back(insideOperand(tree.operands[node.value], p));
      continue;
    }
    const std::size_t first = stack.size() - node.value;
    bool v = stack[first];
    for (std::size_t k = first + 1; k < stack.size(); ++k) {
      if (node.operation == CsgOperation::Union) v = v || stack[k];
      if (node.operation == CsgOperation::Intersection) v = v && stack[k];
      if (node.operation == CsgOperation::Difference) v = v && !stack[k];
    }
    stack.resize(first);
    stack.push_back(v);
  }
  return stack.back();
}

// Every crossing of every operand's surface along the ray in (tMin, ∞), found by stepping each
// solid's own intersect from crossing to crossing.
struct OperandCrossing {
  double t;
  std::uint32_t operand;
};
std::vector<OperandCrossing> allOperandCrossings(const CsgTree& tree, const Ray& ray, double tMin) {
  std::vector<OperandCrossing> out;
  for (std::uint32_t i = 0; i < tree.operands.size(); ++i) {
    const CsgOperand& operand = tree.operands[i];
    const Ray r = operand.csgFromSolid ? operand.csgFromSolid->inverse()(ray) : ray;
    double t = tMin;
    ShapeHit hit;
    while (true) {
      bool found = false;
      std::visit(
          [&](const auto& s) {
            if constexpr (std::is_same_v<std::decay_t<decltype(s)>,
                                         std::shared_ptr<const CsgMesh>>) {
              found = s->intersect(r, t, kInf, hit);
            } else {
              found = s.intersect(r, t, kInf, hit);
            }
          },
          operand.solid);
      if (!found) break;
      out.push_back({hit.t, i});
      t = hit.t;
    }
  }
  std::sort(out.begin(), out.end(),
            [](const OperandCrossing& a, const OperandCrossing& b) { return a.t < b.t; });
  return out;
}

// The reference walk: the result's state on each stretch between successive operand crossings
// (at the stretch's midpoint), and a crossing wherever it changes. Crossings at exactly the same t
// (coincident faces) are one event, reported on the lowest-numbered operand, as the walk does;
// `ambiguous` when two differ by too little to tell apart in double precision (the ray is then
// skipped).
struct ReferenceCrossing {
  double t;
  std::uint32_t operand;
  bool enters;
};
std::vector<ReferenceCrossing> referenceCrossings(const CsgTree& tree, const Ray& ray, double tMin,
                                                  double tMax, bool& ambiguous) {
  std::vector<OperandCrossing> all = allOperandCrossings(tree, ray, tMin);
  // Merge exact ties, keeping the lowest operand.
  std::vector<OperandCrossing> events;
  for (const OperandCrossing& c : all) {
    if (!events.empty() && events.back().t == c.t) {
      events.back().operand = std::min(events.back().operand, c.operand);
    } else {
      events.push_back(c);
    }
  }
  ambiguous = false;
  const double scale = 1e-7 * (1 + length(ray.direction));
  double previous = tMin;
  for (const OperandCrossing& c : events) {
    if (c.t - previous < scale * (1 + std::abs(c.t))) ambiguous = true;
    previous = c.t;
  }
  for (const OperandCrossing& c : events) {
    if (std::abs(c.t - tMax) < scale * (1 + std::abs(tMax))) ambiguous = true;
  }
  const auto stateAt = [&](double t) { return insideTree(tree, ray.at(t)); };
  std::vector<ReferenceCrossing> out;
  bool state = stateAt(events.empty() ? tMin + 1 : 0.5 * (tMin + events[0].t));
  for (std::size_t k = 0; k < events.size(); ++k) {
    if (!(events[k].t < tMax)) break;
    const double next = k + 1 < events.size() ? events[k + 1].t : events[k].t + 1;
    const bool after = stateAt(0.5 * (events[k].t + next));
    if (after != state) out.push_back({events[k].t, events[k].operand, after});
    state = after;
  }
  return out;
}

Transform randomTransform(Rng& rng) {
  const Vec3 axis{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5 + 1e-3};
  return Transform::translate({rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5}) *
         Transform::rotate(axis, 360 * rng.uniform()) *
         Transform::scale(0.7 + 0.6 * rng.uniform(), 0.7 + 0.6 * rng.uniform(),
                          0.7 + 0.6 * rng.uniform());
}

Csg randomSolid(Rng& rng, std::uint32_t material) {
  const double pick = rng.uniform();
  const Point3 c{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
  std::optional<Transform> transform;
  if (rng.uniform() < 0.5) transform = randomTransform(rng);
  CsgSolid solid;
  if (pick < 0.3) {
    solid = Sphere::make(c, 0.5 + 0.6 * rng.uniform());
  } else if (pick < 0.55) {
    solid = Box::make(c - Vec3{0.6, 0.5, 0.7} * (0.5 + rng.uniform()),
                      c + Vec3{0.5, 0.7, 0.6} * (0.5 + rng.uniform()));
  } else if (pick < 0.8) {
    solid = Cylinder::make(c, {rng.uniform() - 0.5, rng.uniform() + 0.1, rng.uniform() - 0.5},
                           0.3 + 0.5 * rng.uniform(), 0.5 + rng.uniform());
  } else {
    solid = cubeMesh(-0.6, 0.4 + 0.4 * rng.uniform(), rng.uniform() < 0.3);
  }
  return makeCsgSolid(solid, transform, material, Color());
}

Csg randomCsg(Rng& rng, int depth, std::uint32_t& nextMaterial) {
  const int count = 2 + static_cast<int>(rng.uniform() * 2);
  std::vector<Csg> operands;
  for (int k = 0; k < count; ++k) {
    if (depth > 0 && rng.uniform() < 0.4) {
      operands.push_back(randomCsg(rng, depth - 1, nextMaterial));
    } else {
      operands.push_back(randomSolid(rng, nextMaterial++));
    }
  }
  const auto operation = static_cast<CsgOperation>(static_cast<int>(rng.uniform() * 3));
  Csg csg = combineCsg(operation, operands);
  return rng.uniform() < 0.3 ? transformCsg(csg, randomTransform(rng)) : csg;
}

TEST(Csg, ClosestHitCrossingsAndTransmittanceEqualTheBruteForceReference) {
  Rng rng(1911);
  int rays = 0;
  int hits = 0;
  int skipped = 0;
  int fromInside = 0;
  for (int tree = 0; tree < 150; ++tree) {
    std::uint32_t material = 0;
    Csg csg = randomCsg(rng, 2, material);
    std::vector<Color> kt;
    for (std::size_t i = 0; i < csg.tree->operands.size(); ++i) {
      kt.push_back(Color(0.3 + 0.6 * rng.uniform(), 0.5, 0.9));
    }
    csg = withCsgTransmission(csg, kt);
    for (int k = 0; k < 100; ++k) {
      const Point3 origin{3 * (rng.uniform() - 0.5), 3 * (rng.uniform() - 0.5),
                          3 * (rng.uniform() - 0.5)};
      // Aimed at a random point of the csg's bounds (most rays meet it), at any speed.
      const Bounds3 b = csg.bounds();
      const Point3 target =
          b.lo + Vec3{b.diagonal().x * rng.uniform(), b.diagonal().y * rng.uniform(),
                      b.diagonal().z * rng.uniform()};
      const Vec3 direction =
          rng.uniform() < 0.8 ? target - origin
                              : Vec3{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
      const Ray ray{origin, direction * (0.5 + rng.uniform())};
      const double tMax = rng.uniform() < 0.3 ? 1 + 3 * rng.uniform() : kInf;
      bool ambiguous = false;
      const std::vector<ReferenceCrossing> expected =
          referenceCrossings(*csg.tree, ray, 0, tMax, ambiguous);
      if (ambiguous) {
        ++skipped;
        continue;
      }
      ++rays;
      fromInside += insideTree(*csg.tree, origin) ? 1 : 0;
      ShapeHit hit;
      const bool found = csg.intersect(ray, 0, tMax, hit);
      ASSERT_EQ(found, !expected.empty()) << "tree " << tree << " ray " << k;
      ASSERT_EQ(csg.crossings(ray, 0, tMax), static_cast<int>(expected.size()))
          << "tree " << tree << " ray " << k;
      Color transmittance(1);
      for (const ReferenceCrossing& c : expected) transmittance *= kt[c.operand];
      const Color got = csgTransmittance(csg, ray, 0, tMax);
      EXPECT_NEAR(got.r, transmittance.r, 1e-12 * (1 + transmittance.r));
      EXPECT_NEAR(got.g, transmittance.g, 1e-12);
      if (!found) continue;
      ++hits;
      const ReferenceCrossing& first = expected[0];
      EXPECT_NEAR(hit.t, first.t, 1e-9 * (1 + first.t)) << "tree " << tree << " ray " << k;
      EXPECT_EQ(hit.part, first.operand);
      EXPECT_NEAR(length(hit.normal), 1, 1e-12);
      // Outward from the result: against the ray where it enters.
      EXPECT_EQ(dot(hit.normal, ray.direction) < 0, first.enters)
          << "tree " << tree << " ray " << k;
      EXPECT_LT(length(hit.point - ray.at(hit.t)), 1e-9 * (1 + length(toVec(hit.point))));
    }
  }
  std::printf("%d rays (%d from inside the csg), %d hits; %d ambiguous rays skipped\n", rays,
              fromInside, hits, skipped);
  EXPECT_GT(rays, 14500);  // of 15000
  EXPECT_GT(hits, 4500);
  EXPECT_GT(fromInside, 600);
}

TEST(Csg, UnionOfBoxesSharingAFaceHasNoSurfaceThere) {
  const Csg csg =
      combineCsg(CsgOperation::Union,
                 {makeCsgSolid(Box::make({0, 0, 0}, {1, 1, 1}), std::nullopt, 0, Color()),
                  makeCsgSolid(Box::make({1, 0, 0}, {2, 1, 1}), std::nullopt, 1, Color())});
  const Ray ray{{-1, 0.5, 0.5}, {1, 0, 0}};
  EXPECT_EQ(csg.crossings(ray, 0, kInf), 2);
  ShapeHit hit;
  ASSERT_TRUE(csg.intersect(ray, 1.5, kInf, hit));  // from inside the first box
  EXPECT_EQ(hit.t, 3);
  EXPECT_EQ(hit.part, 1u);
  EXPECT_EQ(hit.normal, Normal3(1, 0, 0));
}

TEST(Csg, DifferenceShowsTheSubtractedFaceWithItsNormalFlipped) {
  // The unit sphere minus the half space z > 0 (a box): a hemisphere whose cut face looks up.
  const Csg csg =
      combineCsg(CsgOperation::Difference,
                 {makeCsgSolid(Sphere::make({0, 0, 0}, 1), std::nullopt, 0, Color()),
                  makeCsgSolid(Box::make({-2, -2, 0}, {2, 2, 2}), std::nullopt, 1, Color())});
  for (const double x : {-0.5, 0.0, 0.3, 0.9}) {
    ShapeHit hit;
    ASSERT_TRUE(csg.intersect(Ray{{x, 0.1, 5}, {0, 0, -1}}, 0, kInf, hit));
    EXPECT_DOUBLE_EQ(hit.t, 5);
    EXPECT_EQ(hit.part, 1u);
    // The box's face z = 0 has outward normal −z; as the hemisphere's top it faces +z.
    EXPECT_EQ(hit.normal, Normal3(0, 0, 1));
  }
  // From below: the sphere's own surface, normal as the sphere's.
  ShapeHit below;
  ASSERT_TRUE(csg.intersect(Ray{{0, 0, -5}, {0, 0, 1}}, 0, kInf, below));
  EXPECT_DOUBLE_EQ(below.t, 4);
  EXPECT_EQ(below.part, 0u);
  EXPECT_EQ(below.normal, Normal3(0, 0, -1));
  // Leaving through the cut from inside: the flipped face again, now along the ray.
  ShapeHit out;
  ASSERT_TRUE(csg.intersect(Ray{{0, 0, -0.5}, {0, 0, 1}}, 0, kInf, out));
  EXPECT_DOUBLE_EQ(out.t, 0.5);
  EXPECT_EQ(out.normal, Normal3(0, 0, 1));
  EXPECT_EQ(csg.normalAt({0.2, 0.1, 0}), Normal3(0, 0, 1));
}

TEST(Csg, IntersectionBoundsAreTheOverlapOfTheOperands) {
  const Csg lens =
      combineCsg(CsgOperation::Intersection,
                 {makeCsgSolid(Sphere::make({0, 0, -1.5}, 2), std::nullopt, 0, Color()),
                  makeCsgSolid(Sphere::make({0, 0, 1.5}, 2), std::nullopt, 0, Color())});
  EXPECT_EQ(lens.bounds().lo, Point3(-2, -2, -0.5));
  EXPECT_EQ(lens.bounds().hi, Point3(2, 2, 0.5));
  const Csg nothing =
      combineCsg(CsgOperation::Intersection,
                 {makeCsgSolid(Sphere::make({0, 0, -5}, 1), std::nullopt, 0, Color()),
                  makeCsgSolid(Sphere::make({0, 0, 5}, 1), std::nullopt, 0, Color())});
  EXPECT_FALSE(nothing.bounds().isEmpty());
  ShapeHit hit;
  EXPECT_FALSE(nothing.intersect(Ray{{0, 0, -10}, {0, 0, 1}}, 0, kInf, hit));
}

TEST(Csg, AClosedMeshActsAsTheSolidItBounds) {
  // A cube mesh minus a sphere equals the box minus the sphere, either winding of the mesh.
  for (const bool insideOut : {false, true}) {
    const Csg meshCut =
        combineCsg(CsgOperation::Difference,
                   {makeCsgSolid(cubeMesh(-1, 1, insideOut), std::nullopt, 0, Color()),
                    makeCsgSolid(Sphere::make({1, 1, 1}, 1.2), std::nullopt, 1, Color())});
    const Csg boxCut =
        combineCsg(CsgOperation::Difference,
                   {makeCsgSolid(Box::make({-1, -1, -1}, {1, 1, 1}), std::nullopt, 0, Color()),
                    makeCsgSolid(Sphere::make({1, 1, 1}, 1.2), std::nullopt, 1, Color())});
    Rng rng(7);
    for (int k = 0; k < 2000; ++k) {
      const Ray ray{
          {4 * (rng.uniform() - 0.5), 4 * (rng.uniform() - 0.5), 4 * (rng.uniform() - 0.5)},
          {rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5}};
      ShapeHit a;
      ShapeHit b;
      const bool hitMesh = meshCut.intersect(ray, 0, kInf, a);
      ASSERT_EQ(hitMesh, boxCut.intersect(ray, 0, kInf, b)) << k;
      EXPECT_EQ(meshCut.crossings(ray, 0, kInf), boxCut.crossings(ray, 0, kInf)) << k;
      if (!hitMesh) continue;
      EXPECT_NEAR(a.t, b.t, 1e-9) << k;
      EXPECT_NEAR(dot(a.normal, toVec(b.normal)), 1, 1e-9) << k;
    }
  }
}

TEST(Csg, OpenOrInconsistentMeshesAreRejected) {
  std::vector<Point3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  // A tetrahedron missing its last face.
  EXPECT_THAT(
      [&] {
        CsgMesh::make(p, {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 0, 1, 3});
      },
      ::testing::ThrowsMessage<ShapeError>(HasSubstr("runs the same way")));
  EXPECT_THAT(
      [&] {
        CsgMesh::make(p, {0, 2, 1, 0, 1, 3, 0, 3, 2});
      },
      ::testing::ThrowsMessage<ShapeError>(HasSubstr("closed surface")));
  // The full tetrahedron with one face turned over.
  EXPECT_THAT(
      [&] {
        CsgMesh::make(p, {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 3, 2});
      },
      ::testing::ThrowsMessage<ShapeError>(HasSubstr("runs the same way")));
  // Closed: also when every triangle has its own copies of the vertices (as STL stores them).
  const std::vector<std::uint32_t> tetra = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  std::vector<Point3> split;
  std::vector<std::uint32_t> splitIndices;
  for (const std::uint32_t i : tetra) {
    splitIndices.push_back(static_cast<std::uint32_t>(split.size()));
    split.push_back(p[i]);
  }
  EXPECT_EQ(CsgMesh::make(split, splitIndices)->triangleCount(), 4u);
}

TEST(Csg, LimitsOnSizeAndNesting) {
  const auto solid = [] {
    return makeCsgSolid(Sphere::make({0, 0, 0}, 1), std::nullopt, 0, Color());
  };
  EXPECT_THAT([&] { combineCsg(CsgOperation::Union, {solid()}); },
              ::testing::ThrowsMessage<ShapeError>(HasSubstr("at least two operands")));
  std::vector<Csg> many(kMaxCsgSolids + 1, solid());
  EXPECT_THAT([&] { combineCsg(CsgOperation::Union, many); },
              ::testing::ThrowsMessage<ShapeError>(HasSubstr("at most 64 shapes")));
  Csg nested = combineCsg(CsgOperation::Union, {solid(), solid()});
  for (int depth = 2; depth <= kMaxCsgDepth; ++depth) {
    nested = combineCsg(CsgOperation::Union, {nested, solid()});
  }
  EXPECT_EQ(nested.tree->depth, kMaxCsgDepth);
  EXPECT_THAT(
      [&] {
        combineCsg(CsgOperation::Union, {nested, solid()});
      },
      ::testing::ThrowsMessage<ShapeError>(HasSubstr("nested at most 16 deep")));
}

}  // namespace
}  // namespace glint
