// The BVH build (accel/bvh4.h): build references and the tree the binned SAH makes of them.
#include "glint/accel/bvh4.h"

#include <tbb/global_control.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "glint/core/rng.h"

namespace glint {
namespace {

// A build reference's box is its double box rounded outward by at least one float ulp, exactly as
// std::nextafter toward ∓inf does it (the build's inline ulp step must agree on zeros, subnormals,
// the largest float, overflow to infinity and NaN).
TEST(BuildItemTest, BoxIsRoundedOutwardLikeNextafter) {
  constexpr double kInfD = std::numeric_limits<double>::infinity();
  constexpr float kInfF = std::numeric_limits<float>::infinity();
  // Each value and its negation: zeros, subnormals, ordinary values, the largest float, values
  // that overflow float, infinity; then NaN and random magnitudes from 1e-30 to 1e29.
  std::vector<double> values = {std::numeric_limits<double>::quiet_NaN()};
  for (const double v : {0.0, 1e-46, 1e-40, 1.0, 0.1, 3.4028234663852886e38, 1e39, 1e300, kInfD}) {
    values.push_back(v);
    values.push_back(-v);
  }
  Rng rng(7);
  for (int i = 0; i < 1000; ++i)
    values.push_back((rng.uniform() - 0.5) * std::pow(10.0, i % 60 - 30));
  const auto same = [](float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b) ||
           (std::isnan(a) && std::isnan(b));
  };
  for (const double v : values) {
    SCOPED_TRACE(v);
    const double lo[3] = {v, v, v};
    const double hi[3] = {v, v, v};
    const bvh::BuildItem item = bvh::makeBuildItem(lo, hi, 3, 5);
    const float down = std::nextafter(static_cast<float>(v), -kInfF);
    const float up = std::nextafter(static_cast<float>(v), kInfF);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_TRUE(same(item.lo[axis], down)) << item.lo[axis] << " vs " << down;
      EXPECT_TRUE(same(item.hi[axis], up)) << item.hi[axis] << " vs " << up;
    }
    EXPECT_EQ(bvh::itemKey(item), 3u);
    EXPECT_EQ(bvh::itemIndex(item), 5u);
  }
}

// FNV-1a 64 over bytes, continuing from `hash`.
std::uint64_t hashBytes(const void* data, std::size_t size, std::uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 1099511628211ull;
  return hash;
}

// 70,000 references of mixed kinds: small boxes along a helix (a mesh's neighbouring triangles),
// some flat, with three mesh keys, and every fifth an analytic primitive (weighted in the SAH).
bvh::BuildItems fixedReferences() {
  bvh::BuildItems items;
  Rng rng(11);
  for (std::uint32_t i = 0; i < 70000; ++i) {
    const double t = i * 0.001;
    const double centre[3] = {std::cos(t * 7) * (3 + std::sin(t)), t - 35, std::sin(t * 7) * 3};
    double lo[3];
    double hi[3];
    for (int a = 0; a < 3; ++a) {
      const double half = (a == 1 && i % 7 == 0) ? 0 : 0.01 + 0.02 * rng.uniform();
      lo[a] = centre[a] - half;
      hi[a] = centre[a] + half;
    }
    items.push_back(bvh::makeBuildItem(lo, hi, i % 5 == 0 ? bvh::kPrimitiveKey : i % 3, i));
  }
  return items;
}

// The tree's bytes (nodes, root) and the references' leaf order, hashed.
std::uint64_t treeHash(int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                            static_cast<std::size_t>(threads));
  bvh::BuildItems items = fixedReferences();
  const bvh::Tree tree = bvh::build(items);
  std::uint64_t hash = 14695981039346656037ull;
  hash = hashBytes(tree.nodes.data(), tree.nodes.size() * sizeof(bvh::Node), hash);
  hash = hashBytes(items.data(), items.size() * sizeof(bvh::BuildItem), hash);
  hash = hashBytes(&tree.rootChild, sizeof tree.rootChild, hash);
  return hashBytes(&tree.rootInfo, sizeof tree.rootInfo, hash);
}

// The same tree on any thread count, and the same tree as when this test was written: a change
// to the build that was meant to keep the trees (a faster binning, a shortcut for small ranges)
// must keep this hash. A change that means to make other trees updates the constant, and says so
// (the images may then differ in the last bit where hits tie).
TEST(BvhBuild, TheTreeOfFixedReferencesIsUnchangedOnAnyThreadCount) {
  const std::uint64_t one = treeHash(1);
  EXPECT_EQ(treeHash(2), one);
  EXPECT_EQ(treeHash(4), one);
  EXPECT_EQ(one, 0x54b631c244dc2e8bull) << std::hex << one;
}

}  // namespace
}  // namespace glint
