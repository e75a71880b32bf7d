// The bounding volume hierarchy of the Aggregate: 4- and 8-wide node layouts, child references, the
// parallel, deterministic binned-SAH build of 4-wide nodes over tagged references (analytic
// primitives and mesh triangles in one tree), and its collapse into 8-wide nodes.
#pragma once

#include <cstdint>
#include <vector>

#include "glint/core/huge_pages.h"

namespace glint::bvh {

// A child reference is (child, info): info 0 is an empty slot, kInner an inner node (child = index
// into the node array), and a leaf has the top bit set: child = first index into the leaf-ordered
// reference array, bits 0–3 the count (1..15), bits 4–30 the leaf's key — a mesh index, or
// kPrimitiveKey for analytic primitives. Every leaf holds references of a single key, so a
// triangle leaf knows its mesh without a per-triangle mesh index.
inline constexpr std::uint32_t kEmpty = 0;
inline constexpr std::uint32_t kInner = 1;
inline constexpr std::uint32_t kLeafBit = 0x80000000u;
inline constexpr std::uint32_t kCountBits = 4;
inline constexpr std::uint32_t kCountMask = (1u << kCountBits) - 1;
inline constexpr std::uint32_t kKeyMask = 0x07ffffffu;  // 27 bits
inline constexpr std::uint32_t kPrimitiveKey = kKeyMask;
inline constexpr std::uint32_t kMaxMeshes = kPrimitiveKey;  // mesh keys are 0 .. kMaxMeshes − 1

constexpr bool isLeaf(std::uint32_t info) { return (info & kLeafBit) != 0; }
constexpr std::uint32_t leafCount(std::uint32_t info) { return info & kCountMask; }
constexpr std::uint32_t leafKey(std::uint32_t info) { return (info >> kCountBits) & kKeyMask; }
constexpr std::uint32_t leafInfo(std::uint32_t key, std::uint32_t count) {
  return kLeafBit | (key << kCountBits) | count;
}

// Width child boxes in single precision, structure of arrays for one SIMD slab test of all of
// them: bounds[0..2] the low x, y, z of the children, bounds[3..5] the high ones. Boxes are rounded
// outward from the double-precision bounds (at least one float ulp), so no hit is ever culled;
// empty slots hold the empty box (lo = +inf, hi = −inf), which no ray enters. No padding (so equal
// trees compare equal byte for byte).
template <int Width>
struct alignas(64) NodeOf {
  static constexpr int kWidth = Width;
  float bounds[6][Width];
  std::uint32_t child[Width];
  std::uint32_t info[Width];
};
// The 4-wide node: one SSE test of all four children; 128 bytes, two cache lines.
using Node = NodeOf<4>;
static_assert(sizeof(Node) == 128);
// The 8-wide node of the AVX2 and AVX-512 kernels: one 256-bit test of all eight children (or two
// SSE tests); 256 bytes, four cache lines.
using Node8 = NodeOf<8>;
static_assert(sizeof(Node8) == 256);

// One reference during the build: its box (float, rounded outward) and what it refers to.
// lo[3] and hi[3] carry the key and the index (bit patterns), so an item is two SSE registers.
struct alignas(16) BuildItem {
  float lo[4];
  float hi[4];
};
static_assert(sizeof(BuildItem) == 32);
// The build's references and nodes are on huge pages (HugePageAllocator): a 1M-triangle build
// fills ~50 MB of them, and one page fault per 4 KiB took a third of its time here. The
// references, and the 4-wide tree's final array, are sized, then written in parallel, each
// element before it is read: not zeroed first (UnzeroedHugePageAllocator).
using BuildItems = UnzeroedHugePageArray<BuildItem>;
using Nodes = UnzeroedHugePageArray<Node>;
using Nodes8 = HugePageArray<Node8>;

BuildItem makeBuildItem(const double lo[3], const double hi[3], std::uint32_t key,
                        std::uint32_t index);
std::uint32_t itemKey(const BuildItem& item);
std::uint32_t itemIndex(const BuildItem& item);

struct Tree {
  Nodes nodes;                  // depth-first, the root (if inner) at 0
  std::uint32_t rootChild = 0;  // the root reference: an inner node, one leaf, or empty
  std::uint32_t rootInfo = kEmpty;
};

// Builds the tree over items, which it reorders into leaf order (leaves point into it). Binned SAH
// (Wald 2007) with 4-wide nodes made by splitting the child of largest surface area (as Embree
// does); object-median splits past a depth limit or where centroids coincide; leaves hold at most
// kMaxLeafSize references of one key. Large subtrees are built in parallel (oneTBB) and the binning
// of large ranges is a parallel reduction, yet the result depends only on the items: subtrees are
// stitched in depth-first order and every reduction is an exact min/max/count.
Tree build(BuildItems& items);

// The 8-wide tree of a 4-wide one (nodes, root an inner node at index 0): each 8-wide node takes
// a 4-wide node's children and pulls up the children of its inner children, largest surface area
// first, while they fit in eight slots. A pulled-up node's children take its slot, in their order,
// so the children of every 8-wide node are in the 4-wide tree's depth-first order: a traversal
// that visits children in slot order meets the leaves in the same order in both trees. Leaves and
// child boxes are copied bit for bit (a slab test of a leaf's box answers the same in either), and
// the result is depth-first with the root at 0.
Nodes8 collapseToWide(const Nodes& nodes);

inline constexpr std::uint32_t kMaxLeafSize = 8;
static_assert(kMaxLeafSize <= kCountMask);
// Deepest possible tree, in 4-wide levels: SAH until kMaxSahDepth, then median splits (each level
// at least halves the count: 32 levels for 2^32 references), then key splits of leaves with mixed
// keys (at most kMaxLeafSize − 1). The traversal stack holds at most 3 entries per level.
inline constexpr int kMaxSahDepth = 32;
inline constexpr int kMaxDepth = kMaxSahDepth + 33 + static_cast<int>(kMaxLeafSize);
inline constexpr int kStackSize = 3 * kMaxDepth + 1;
// An 8-wide tree is no deeper than the 4-wide one it was collapsed from; 7 entries per level.
inline constexpr int kWideStackSize = 7 * kMaxDepth + 1;

}  // namespace glint::bvh
