// Instances against brute force over the flattened geometry: every group object of every instance
// as its own primitive with the instance's transform (mesh triangles as transformed triangles).
// Rays enter both by the same inverse matrix, so which object is hit, t, the normals and the
// transmittance must agree bit for bit on thousands of random rays; the world hit point comes from
// the instance's re-derived forward matrix, so it must agree within the two error bounds. Also:
// empty and unbounded groups, shared groups, and a build that does not depend on the thread count.
#include "glint/accel/instances.h"

#include <tbb/task_arena.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "glint/core/rng.h"

namespace glint {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A small closed triangle mesh: an octahedron of radius r around c.
TriangleMesh octahedron(const Point3& c, double r) {
  TriangleMesh m;
  m.positions = {c + Vec3(r, 0, 0),  c + Vec3(-r, 0, 0), c + Vec3(0, r, 0),
                 c + Vec3(0, -r, 0), c + Vec3(0, 0, r),  c + Vec3(0, 0, -r)};
  m.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  return m;
}

struct TestGroup {
  std::vector<Primitive> primitives;
  std::vector<Color> primitiveKt;
  std::vector<TriangleMesh> meshes;
  std::vector<Color> meshKt;
};

// kt values whose products are exact in any order (powers of two), and opaque ones.
const Color kKt[] = {Color(0.5), Color(0.25, 0.5, 1), Color(0), Color(1), Color(0.5, 0.125, 0.25)};

std::vector<TestGroup> makeGroups() {
  std::vector<TestGroup> groups(3);
  // 0: a sphere, a box and an octahedron mesh.
  groups[0].primitives.emplace_back(Sphere::make({0, 0, 0}, 1), 0, Color());
  groups[0].primitiveKt.push_back(kKt[0]);
  groups[0].primitives.emplace_back(Box::make({1.5, -0.5, -0.5}, {2.5, 0.5, 0.5}), 0, Color());
  groups[0].primitiveKt.push_back(kKt[1]);
  groups[0].meshes.push_back(octahedron({-2, 0.5, 0}, 0.8));
  groups[0].meshKt.push_back(kKt[4]);
  // 1: a cylinder and a disk, one opaque.
  groups[1].primitives.emplace_back(Cylinder::make({0, 0, 0}, {0, 1, 0}, 0.5, 2), 0, Color());
  groups[1].primitiveKt.push_back(kKt[2]);
  groups[1].primitives.emplace_back(Disk::make({0, 2.5, 0}, {0, 1, 1}, 1), 0, Color());
  groups[1].primitiveKt.push_back(kKt[0]);
  // 2: two meshes.
  groups[2].meshes.push_back(octahedron({0, 0, 0}, 1));
  groups[2].meshKt.push_back(kKt[0]);
  groups[2].meshes.push_back(octahedron({0, 1.5, 0}, 0.5));
  groups[2].meshKt.push_back(kKt[1]);
  return groups;
}

Transform randomTransform(Rng& rng) {
  const Vec3 axis(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() + 0.1);
  return Transform::translate(
             {40 * rng.uniform() - 20, 40 * rng.uniform() - 20, 40 * rng.uniform() - 20}) *
         Transform::rotate(axis, 360 * rng.uniform()) *
         Transform::scale(0.5 + rng.uniform(), 0.5 + rng.uniform(), 0.5 + rng.uniform());
}

constexpr std::uint32_t kNoPrimitive = 0xffffffffu;

// What a flattened primitive is: instance k's group object (a primitive, or a triangle of a mesh).
struct FlatOrigin {
  std::size_t instance = 0;
  std::uint32_t primitive = kNoPrimitive;
  std::uint32_t mesh = kNoMesh;
};

struct Scenes {
  std::vector<FlatOrigin> flatOrigin;  // per flattened primitive
  std::vector<Transform> transforms;
  std::vector<std::uint32_t> groupOf;
  std::shared_ptr<const InstanceSet> instances;
  Aggregate flattened{{}, {}};
};

// `count` random instances of the test groups, and the same geometry flattened for brute force.
Scenes makeScenes(std::size_t count, std::uint64_t seed) {
  const std::vector<TestGroup> groups = makeGroups();
  std::vector<std::shared_ptr<const Aggregate>> aggregates;
  for (const TestGroup& g : groups) {
    aggregates.push_back(
        std::make_shared<const Aggregate>(g.primitives, g.primitiveKt, g.meshes, g.meshKt));
  }
  Scenes s;
  Rng rng(seed);
  std::vector<Instance> records;
  std::vector<Primitive> flat;
  std::vector<Color> flatKt;
  for (std::size_t k = 0; k < count; ++k) {
    const Transform t = randomTransform(rng);
    const auto g = static_cast<std::uint32_t>(rng.uniform() * 3);
    s.transforms.push_back(t);
    s.groupOf.push_back(g);
    records.push_back(makeInstance(&t, g));
    for (std::size_t i = 0; i < groups[g].primitives.size(); ++i) {
      flat.emplace_back(groups[g].primitives[i].shape(), 0, Color(), t);
      flatKt.push_back(groups[g].primitiveKt[i]);
      s.flatOrigin.push_back({k, static_cast<std::uint32_t>(i), kNoMesh});
    }
    for (std::size_t m = 0; m < groups[g].meshes.size(); ++m) {
      const TriangleMesh& mesh = groups[g].meshes[m];
      for (std::size_t tri = 0; tri < mesh.triangleCount(); ++tri) {
        const Point3& p0 = mesh.positions[mesh.indices[3 * tri]];
        const Point3& p1 = mesh.positions[mesh.indices[3 * tri + 1]];
        const Point3& p2 = mesh.positions[mesh.indices[3 * tri + 2]];
        flat.emplace_back(Triangle::make(p0, p1, p2), 0, Color(), t);
        flatKt.push_back(groups[g].meshKt[m]);
        s.flatOrigin.push_back({k, kNoPrimitive, static_cast<std::uint32_t>(m)});
      }
    }
  }
  s.instances = std::make_shared<const InstanceSet>(aggregates, records);
  s.flattened = Aggregate(std::move(flat), std::move(flatKt), {}, {}, Acceleration::BruteForce);
  return s;
}

Ray randomRay(Rng& rng) {
  const Point3 origin(60 * rng.uniform() - 30, 60 * rng.uniform() - 30, 60 * rng.uniform() - 30);
  const double z = 2 * rng.uniform() - 1;
  const double phi = 2 * kPi * rng.uniform();
  const double r = std::sqrt(1 - z * z);
  return Ray{origin, Vec3(r * std::cos(phi), r * std::sin(phi), z)};
}

TEST(InstanceSetTest, ClosestHitsAndTransmittanceEqualBruteForceOverFlattenedGeometry) {
  const Scenes s = makeScenes(500, 11);
  const Aggregate withInstances({}, {}, {}, {}, Acceleration::Bvh, s.instances);
  Rng rng(5);
  int hits = 0;
  int partial = 0;
  int pointsDiffering = 0;
  for (int k = 0; k < 5000; ++k) {
    const Ray ray = randomRay(rng);
    Hit expected;
    Hit actual;
    const bool want = s.flattened.intersect(ray, 0, 1e30, expected);
    const bool got = withInstances.intersect(ray, 0, 1e30, actual);
    ASSERT_EQ(got, want) << "ray " << k;
    if (want) {
      ++hits;
      EXPECT_EQ(actual.t, expected.t) << "ray " << k;
      // The same object of the same instance.
      const FlatOrigin& origin = s.flatOrigin[expected.primitive];
      const Instance placed = makeInstance(&s.transforms[origin.instance], 0);
      EXPECT_EQ(0, std::memcmp(&s.instances->instance(actual.instance).groupFromWorld,
                               &placed.groupFromWorld, sizeof(AffineMatrix)))
          << "ray " << k;
      // (A mesh's triangles are numbered in its own BVH's order: the face is checked by the
      // normal below.)
      EXPECT_EQ(actual.mesh, origin.mesh) << "ray " << k;
      if (origin.mesh == kNoMesh) {
        EXPECT_EQ(actual.primitive, origin.primitive) << "ray " << k;
      }
      for (int axis = 0; axis < 3; ++axis) {
        // Both bounds contain the exact point, so the points are within their sum; and the
        // instance's bound is not loose: within 64× the transformed primitive's.
        EXPECT_LE(std::abs(actual.point[axis] - expected.point[axis]),
                  actual.pointError[axis] + expected.pointError[axis])
            << "ray " << k << " axis " << axis;
        EXPECT_LE(actual.pointError[axis], 64 * expected.pointError[axis]) << "ray " << k;
        if (actual.point[axis] != expected.point[axis]) ++pointsDiffering;
      }
      EXPECT_EQ(actual.normal, expected.normal) << "ray " << k;
      EXPECT_EQ(actual.shadingNormal, expected.shadingNormal) << "ray " << k;
      EXPECT_NE(actual.instance, kNoInstance);
      // The hit names an object of the instance's group.
      const Aggregate& group = s.instances->group(s.instances->instance(actual.instance).group);
      if (actual.mesh == kNoMesh) {
        EXPECT_LT(actual.primitive, group.primitives().size());
      } else {
        EXPECT_LT(actual.mesh, group.meshes().size());
      }
    }
    const double tMax = 5 + 40 * rng.uniform();
    const Color te = s.flattened.transmittance(ray, 0, tMax);
    const Color ta = withInstances.transmittance(ray, 0, tMax);
    EXPECT_EQ(ta, te) << "ray " << k;
    if (!isBlack(te) && !(te == Color(1))) ++partial;
  }
  // The rays exercise both queries: many hits, many partly transparent paths.
  EXPECT_GT(hits, 800);
  EXPECT_GT(partial, 200);
  // The re-derived forward matrix is not the Transform's to the bit on every instance, so some
  // hit points differ in their last bits (the comparison above is not vacuous).
  EXPECT_GT(pointsDiffering, 0);
}

TEST(InstanceSetTest, GroupsAreSharedNotCopied) {
  const Scenes few = makeScenes(10, 3);
  const Scenes many = makeScenes(10000, 3);
  // The groups' geometry counts once: 1000× the instances, about 1000× the records and the tree.
  const std::size_t perInstance =
      (many.instances->memoryBytes() - few.instances->memoryBytes()) / (10000 - 10);
  EXPECT_GE(perInstance, sizeof(PlacedInstance));
  EXPECT_LT(perInstance, sizeof(PlacedInstance) + 64);
  EXPECT_EQ(many.instances->groupCount(), 3u);
}

TEST(InstanceSetTest, EmptyAndUnboundedGroupsAndIdentity) {
  std::vector<std::shared_ptr<const Aggregate>> groups;
  groups.push_back(
      std::make_shared<const Aggregate>(std::vector<Primitive>{}, std::vector<Color>{}));
  std::vector<Primitive> plane;
  plane.emplace_back(Plane::make({0, 0, 0}, {0, 1, 0}), 0, Color());
  groups.push_back(
      std::make_shared<const Aggregate>(std::move(plane), std::vector<Color>{Color(0.5)}));
  const Transform up = Transform::translate({0, 2, 0});
  const InstanceSet set(groups, {makeInstance(nullptr, 0), makeInstance(&up, 1)});
  Hit hit;
  ASSERT_TRUE(set.intersect(Ray{{0, 5, 0}, {0, -1, 0}}, 0, 100, hit));
  EXPECT_EQ(hit.t, 3);
  EXPECT_EQ(hit.point, Point3(0, 2, 0));
  EXPECT_EQ(hit.normal, Normal3(0, 1, 0));
  EXPECT_FALSE(set.intersect(Ray{{0, 5, 0}, {0, 1, 0}}, 0, 100, hit));
  EXPECT_EQ(set.transmittance(Ray{{0, 5, 0}, {0, -1, 0}}, 0, 100), Color(0.5));
  EXPECT_EQ(set.transmittance(Ray{{0, 5, 0}, {0, -1, 0}}, 0, 2), Color(1));
  EXPECT_THROW(InstanceSet(groups, {makeInstance(nullptr, 2)}), std::invalid_argument);
  const Transform flat =
      Transform(Matrix4{{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 1, 2}}}});
  EXPECT_THROW(makeInstance(&flat, 0), std::invalid_argument);
}

TEST(InstanceSetTest, BuildDoesNotDependOnTheThreadCount) {
  Scenes one;
  Scenes two;
  tbb::task_arena(1).execute([&] { one = makeScenes(5000, 9); });
  tbb::task_arena(2).execute([&] { two = makeScenes(5000, 9); });
  ASSERT_EQ(one.instances->instanceCount(), two.instances->instanceCount());
  for (std::uint32_t i = 0; i < one.instances->instanceCount(); ++i) {
    const PlacedInstance& a = one.instances->instance(i);
    const PlacedInstance& b = two.instances->instance(i);
    ASSERT_EQ(a.group, b.group);
    ASSERT_EQ(0, std::memcmp(&a.groupFromWorld, &b.groupFromWorld, sizeof(AffineMatrix)));
  }
  Rng rng(2);
  for (int k = 0; k < 500; ++k) {
    const Ray ray = randomRay(rng);
    Hit a;
    Hit b;
    ASSERT_EQ(one.instances->intersect(ray, 0, 1e30, a), two.instances->intersect(ray, 0, 1e30, b));
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.instance, b.instance);
  }
}

}  // namespace
}  // namespace glint
