// Binned-SAH build of the 4-wide BVH (bvh4.h): SSE2 binning, in-place partitions, oneTBB task
// parallelism over subtrees, deterministic output.
#include "glint/accel/bvh4.h"

#include <emmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "glint/core/ulp.h"

namespace glint::bvh {

namespace {

// Binned SAH (Wald 2007, "On fast Construction of SAH-based Bounding Volume Hierarchies"). Costs
// are in units of one reference (triangle) test; each binary split adds kTraversalCost ·
// area(parent). Measured on the 100k-triangle torus (camera rays): kTraversalCost 0.3 / 1.0 / 2.0 /
// 3.0 gave 90 / 75 / 62 / 55 bytes per triangle (mesh with normals included), 6.5 / 6.3 / 6.1 / 5.9
// node visits and 2.0 / 2.1 / 2.6 / 3.3 triangle tests per ray, with throughput equal within the
// noise. 2.5 (58 bytes per triangle at 100k and 1M) keeps the memory target (≤ 64 bytes per
// triangle) with a margin for other tessellations (a 200k torus of aspect 4 needed 64.5 at 2.0).
constexpr float kTraversalCost = 2.5f;
// An analytic primitive costs several triangle tests (variant dispatch, object-space transform,
// quadric roots); weighting it so keeps primitives in small leaves. Chosen by instruction counts
// (valgrind) on the analytic showcase: leaves sized for triangles tested ~3× more primitives.
constexpr double kPrimitiveCost = 6;
// Bins per axis: 16, or one per reference for smaller ranges (most ranges are tiny, and clearing
// unused bins would then cost more than binning).
constexpr int kBinCount = 16;
// Subtrees over at least this many references are built as separate tasks; ranges of at least
// kParallelBinThreshold are binned by a parallel reduction in chunks of kBinGrain.
constexpr std::uint32_t kParallelBuildThreshold = 8192;
constexpr std::uint32_t kParallelBinThreshold = 65536;
constexpr std::size_t kBinGrain = 16384;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::ptrdiff_t kSplitBinsThreshold = 256;

// Lanes 0–2 hold x, y, z; lane 3 is whatever the items carry there (key/index bits) and is never
// read.
struct Box {
  __m128 lo = _mm_set1_ps(kInf);
  __m128 hi = _mm_set1_ps(-kInf);

  void grow(__m128 l, __m128 h) {
    lo = _mm_min_ps(lo, l);
    hi = _mm_max_ps(hi, h);
  }
  void grow(const Box& b) { grow(b.lo, b.hi); }
};

std::array<float, 4> lanes(__m128 v) {
  alignas(16) std::array<float, 4> out;
  _mm_store_ps(out.data(), v);
  return out;
}

// Half the surface area; 0 for an empty box.
float halfArea(const Box& b) {
  const auto d = lanes(_mm_sub_ps(b.hi, b.lo));
  if (!(d[0] >= 0 && d[1] >= 0 && d[2] >= 0)) return 0;
  return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

// The centroid, doubled (lo + hi): binning and median splits only compare centroids.
__m128 centroid2(const BuildItem& item) {
  return _mm_add_ps(_mm_load_ps(item.lo), _mm_load_ps(item.hi));
}

// The cost of testing one reference, in triangle tests. Sums of these are exact in double (small
// integers), so they do not depend on the order of summation.
double costOf(const BuildItem& item) { return itemKey(item) == kPrimitiveKey ? kPrimitiveCost : 1; }

struct Range {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  Box bounds;
  Box centroids;                 // of centroid2
  std::uint32_t primitives = 0;  // references to analytic primitives

  std::uint32_t count() const { return end - begin; }
  // Σ costOf over the references: exact (small integers), and kept as a count of primitives so
  // that adding a reference is an integer add, not a chain of double-precision adds.
  double cost() const {
    return static_cast<double>(count()) + (kPrimitiveCost - 1) * static_cast<double>(primitives);
  }
  void add(const BuildItem& item) {
    const __m128 lo = _mm_load_ps(item.lo);
    const __m128 hi = _mm_load_ps(item.hi);
    bounds.grow(lo, hi);
    const __m128 c = _mm_add_ps(lo, hi);
    centroids.grow(c, c);
    primitives += itemKey(item) == kPrimitiveKey ? 1 : 0;
  }
};

// Bin of a doubled centroid coordinate; the same float arithmetic as the SSE binning loop, so the
// partition agrees with the bin counts exactly. A NaN (the centroid of a box spanning −inf..+inf)
// goes to bin 0, where the loop's truncation (INT_MIN for NaN) and clamp put it, without the
// undefined cast of NaN to int.
int binIndex(float c, float lo, float scale, int binCount) {
  const float offset = (c - lo) * scale;
  if (!(offset >= 0)) return 0;
  return std::min(static_cast<int>(offset), binCount - 1);
}

struct Binning {
  std::array<float, 3> lo{};     // centroid lower bound per axis
  std::array<float, 3> scale{};  // bins per unit of centroid; 0: the axis is not binned
  int binCount = kBinCount;
  bool weighted = false;  // the range holds primitives: SAH weighs references by costOf
};

// Per axis and bin: bounds, reference count and (weighted ranges only) cost. Only the first
// binCount bins are initialised and used.
struct Bins {
  std::array<std::array<Box, kBinCount>, 3> bounds;
  // Per bin, the counts of the three axes in lanes 0–2 (lane 3 unused, 0): one SSE load in the
  // sweep (bestPlane).
  alignas(16) std::array<std::array<std::uint32_t, 4>, kBinCount> counts;
  std::array<std::array<double, kBinCount>, 3> costs;
  int binCount;

  explicit Bins(int bins) : binCount(bins) {
    for (int b = 0; b < binCount; ++b) counts[b] = {0, 0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
      for (int b = 0; b < binCount; ++b) {
        bounds[axis][b] = Box{};
        costs[axis][b] = 0;
      }
    }
  }

  void add(const BuildItem* begin, const BuildItem* end, const Binning& binning) {
    if (binning.weighted) {
      addItems<true>(begin, end, binning);
    } else {
      addItems<false>(begin, end, binning);
    }
  }
  template <bool kWeighted>
  void addItems(const BuildItem* begin, const BuildItem* end, const Binning& binning) {
    const __m128 lo = _mm_setr_ps(binning.lo[0], binning.lo[1], binning.lo[2], 0);
    const __m128 scale = _mm_setr_ps(binning.scale[0], binning.scale[1], binning.scale[2], 0);
    const BuildItem* item = begin;
    if (end - begin >= kSplitBinsThreshold) {
      // Neighbouring items of a mesh mostly fall in the same bins, and each update of a bin's box
      // waits for the previous one to be stored (a chain of store-to-load forwards). Even and odd
      // items go to two sets of bins, merged at the end: two independent chains. The merge is
      // exact (min, max, sums of small integers), so the bins are the same.
      Bins odd(binCount);
      for (; end - item >= 2; item += 2) {
        addItem<kWeighted>(item[0], lo, scale);
        odd.addItem<kWeighted>(item[1], lo, scale);
      }
      merge(odd);
    }
    for (; item != end; ++item) addItem<kWeighted>(*item, lo, scale);
  }
  template <bool kWeighted>
  void addItem(const BuildItem& item, __m128 lo, __m128 scale) {
    const double cost = kWeighted ? costOf(item) : 1;
    const __m128 itemLo = _mm_load_ps(item.lo);
    const __m128 itemHi = _mm_load_ps(item.hi);
    const __m128 c = _mm_add_ps(itemLo, itemHi);
    alignas(16) std::array<int, 4> bin;
    _mm_store_si128(reinterpret_cast<__m128i*>(bin.data()),
                    _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, lo), scale)));
    for (int axis = 0; axis < 3; ++axis) {
      const int b = std::clamp(bin[axis], 0, binCount - 1);
      bounds[axis][b].grow(itemLo, itemHi);
      ++counts[b][axis];
      if constexpr (kWeighted) costs[axis][b] += cost;
    }
  }
  void merge(const Bins& other) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int b = 0; b < binCount; ++b) {
        bounds[axis][b].grow(other.bounds[axis][b]);
        counts[b][axis] += other.counts[b][axis];
        costs[axis][b] += other.costs[axis][b];
      }
    }
  }
};

// How a range is split: by its best SAH plane, at the object median, or by key (one key to the
// left); None for a single reference.
enum class DecisionKind : std::uint8_t { None, Sah, Median, Key };

// What to make of a range: a leaf, or an inner node (leaf = false); and how to split it — to make
// the node, or to fill a node's free child slots (a leaf's halves are leaves too).
struct Decision {
  bool leaf = true;
  DecisionKind kind = DecisionKind::None;
  int axis = 0;
  int bin = 0;  // Sah: the low side holds bins [0, bin]
  float binLo = 0;
  float binScale = 0;
  int binCount = kBinCount;
};

struct Child {
  Range range;
  Decision decision;
};

bool mixedKeys(const BuildItems& items, const Range& range) {
  const std::uint32_t key = itemKey(items[range.begin]);
  for (std::uint32_t i = range.begin + 1; i < range.end; ++i) {
    if (itemKey(items[i]) != key) return true;
  }
  return false;
}

// Fills bins (initialised by the caller; 2 KB, so not returned by value).
void binRange(const BuildItems& items, const Range& range, const Binning& binning, Bins& bins) {
  const BuildItem* data = items.data();
  if (range.count() < kParallelBinThreshold) {
    bins.add(data + range.begin, data + range.end, binning);
    return;
  }
  // Min, max and sums of small integers are exact, so any split and join order gives the same
  // bins (and the deterministic reduction fixes the order anyway).
  bins = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(range.begin, range.end, kBinGrain), Bins(binning.binCount),
      [&](const tbb::blocked_range<std::size_t>& r, Bins partial) {
        partial.add(data + r.begin(), data + r.end(), binning);
        return partial;
      },
      [](Bins a, const Bins& b) {
        a.merge(b);
        return a;
      });
}

// The half areas of three boxes (the three axes' at one plane) in lanes 0–2: their extents
// transposed into x, y and z registers, so that each multiply serves all three. Lane for lane
// halfArea's arithmetic (the same products and sums in the same order, 0 where an extent is
// negative or NaN), so the same floats.
__m128 halfAreasOfThree(const Box& a, const Box& b, const Box& c) {
  const __m128 zero = _mm_setzero_ps();
  __m128 dx = _mm_sub_ps(a.hi, a.lo);
  __m128 dy = _mm_sub_ps(b.hi, b.lo);
  __m128 dz = _mm_sub_ps(c.hi, c.lo);
  __m128 dw = zero;
  _MM_TRANSPOSE4_PS(dx, dy, dz, dw);  // dx now holds the three boxes' x extents, and so on
  const __m128 valid = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(dx, zero), _mm_cmpge_ps(dy, zero)),
                                  _mm_cmpge_ps(dz, zero));
  const __m128 area =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dy), _mm_mul_ps(dy, dz)), _mm_mul_ps(dz, dx));
  return _mm_and_ps(valid, area);
}

// The SAH sweep over the bins of every binned axis: lowers bestCost to the least cost of a plane
// (halfArea · cost on each side) and sets decision's axis and bin to it; ties keep the first
// (lowest axis, then lowest bin). The three axes are swept side by side, one SSE lane each. A
// side's cost is the sum of its bins' costs, converted to float: for a range of triangles alone
// of fewer than 2^31 references (the counts convert as signed 32-bit integers) its count,
// converted in the register — the same float as through the double sum, since both conversions
// round to nearest.
void bestPlane(const Bins& bins, const Binning& binning, std::uint32_t count, float& bestCost,
               Decision& decision) {
  const bool countsAreCosts = !binning.weighted && count < 0x80000000u;
  const int planes = binning.binCount - 1;
  const auto countsAt = [&](int b) {
    return _mm_load_si128(reinterpret_cast<const __m128i*>(bins.counts[b].data()));
  };
  // The double sums of a side's costs when they are not its counts (countsAreCosts false).
  const auto addCosts = [&](int b, std::array<double, 3>& sums) {
    for (int axis = 0; axis < 3; ++axis) {
      sums[axis] += binning.weighted ? bins.costs[axis][b] : bins.counts[b][axis];
    }
  };
  const auto sideCost = [&](__m128i counts, const std::array<double, 3>& sums) {
    return countsAreCosts ? _mm_cvtepi32_ps(counts)
                          : _mm_setr_ps(static_cast<float>(sums[0]), static_cast<float>(sums[1]),
                                        static_cast<float>(sums[2]), 0);
  };
  // Plane b puts bins [0, b] on the low side. Per plane, lanes 0–2 = axes: the high side's area,
  // count and cost from a sweep from the right, then the low side's from the left, and the cost.
  __m128 rightArea[kBinCount];
  __m128i rightCount[kBinCount];
  __m128 rightCost[kBinCount];
  Box right[3];
  __m128i highCount = _mm_setzero_si128();
  std::array<double, 3> highCost{};
  for (int b = planes; b > 0; --b) {
    for (int axis = 0; axis < 3; ++axis) right[axis].grow(bins.bounds[axis][b]);
    highCount = _mm_add_epi32(highCount, countsAt(b));
    if (!countsAreCosts) addCosts(b, highCost);
    rightArea[b - 1] = halfAreasOfThree(right[0], right[1], right[2]);
    rightCount[b - 1] = highCount;
    rightCost[b - 1] = sideCost(highCount, highCost);
  }
  alignas(16) float cost[kBinCount][4];
  alignas(16) std::int32_t oneSideEmpty[kBinCount][4];  // all ones where a side holds nothing
  Box left[3];
  __m128i lowCount = _mm_setzero_si128();
  std::array<double, 3> lowCost{};
  const __m128i zero = _mm_setzero_si128();
  for (int b = 0; b < planes; ++b) {
    for (int axis = 0; axis < 3; ++axis) left[axis].grow(bins.bounds[axis][b]);
    lowCount = _mm_add_epi32(lowCount, countsAt(b));
    if (!countsAreCosts) addCosts(b, lowCost);
    const __m128 lowSide =
        _mm_mul_ps(halfAreasOfThree(left[0], left[1], left[2]), sideCost(lowCount, lowCost));
    const __m128 highSide = _mm_mul_ps(rightArea[b], rightCost[b]);
    _mm_store_ps(cost[b], _mm_add_ps(lowSide, highSide));
    _mm_store_si128(
        reinterpret_cast<__m128i*>(oneSideEmpty[b]),
        _mm_or_si128(_mm_cmpeq_epi32(lowCount, zero), _mm_cmpeq_epi32(rightCount[b], zero)));
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (binning.scale[axis] == 0) continue;
    for (int b = 0; b < planes; ++b) {
      if (oneSideEmpty[b][axis] == 0 && cost[b][axis] < bestCost) {
        bestCost = cost[b][axis];
        decision.axis = axis;
        decision.bin = b;
      }
    }
  }
}

// bestPlane for a range of two references of cost 1 (a quarter of the ranges a mesh's build
// decides), without binning them: on every binned axis their centroids are the ends of the
// centroid extent, so they fall in the two bins, one each, and the one plane costs
// halfArea(first) · 1 + halfArea(second) · 1 in either order (float addition commutes) — the
// same on every axis, so the sweep would keep the first binned axis. Same operations, same result.
void bestPlaneOfTwo(const BuildItem& first, const BuildItem& second, const Binning& binning,
                    float& bestCost, Decision& decision) {
  // The sweep's axes: those binned with a non-zero scale (an infinite extent binned at scale 0
  // has every reference in one bin, and no plane).
  const int axis = binning.scale[0] != 0   ? 0
                   : binning.scale[1] != 0 ? 1
                   : binning.scale[2] != 0 ? 2
                                           : -1;
  if (axis < 0) return;
  Box a;
  a.grow(_mm_load_ps(first.lo), _mm_load_ps(first.hi));
  Box b;
  b.grow(_mm_load_ps(second.lo), _mm_load_ps(second.hi));
  const float cost = halfArea(a) * 1.0f + halfArea(b) * 1.0f;
  if (cost < bestCost) {
    bestCost = cost;
    decision.axis = axis;
    decision.bin = 0;
  }
}

// forceLeaf: the range is the half of a leaf split to fill a node's slots; it stays a leaf.
Decision decide(const BuildItems& items, const Range& range, int depth, bool forceLeaf = false) {
  const std::uint32_t count = range.count();
  Decision decision;
  if (count == 1) return decision;

  const float area = halfArea(range.bounds);
  if (depth < kMaxSahDepth) {
    Binning binning;
    binning.binCount = static_cast<int>(std::min<std::uint32_t>(kBinCount, count));
    binning.weighted = range.primitives != 0;
    const auto cLo = lanes(range.centroids.lo);
    const auto cHi = lanes(range.centroids.hi);
    bool anyAxis = false;
    for (int axis = 0; axis < 3; ++axis) {
      const float extent = cHi[axis] - cLo[axis];
      const float scale = static_cast<float>(binning.binCount) * (1 - 1e-6f) / extent;
      binning.lo[axis] = cLo[axis];
      if (extent > 0 && std::isfinite(scale) && std::isfinite(cLo[axis])) {
        binning.scale[axis] = scale;
        anyAxis = true;
      }
    }
    if (anyAxis) {
      float bestCost = kInf;
      if (count == 2 && !binning.weighted) {
        bestPlaneOfTwo(items[range.begin], items[range.begin + 1], binning, bestCost, decision);
      } else {
        Bins bins(binning.binCount);
        binRange(items, range, binning, bins);
        bestPlane(bins, binning, count, bestCost, decision);
      }
      if (bestCost < kInf) {
        decision.kind = DecisionKind::Sah;
        decision.binLo = binning.lo[decision.axis];
        decision.binScale = binning.scale[decision.axis];
        decision.binCount = binning.binCount;
        if (forceLeaf) return decision;
        const float splitCost = kTraversalCost * area + bestCost;
        // Past the leaf size a split is forced, and the best SAH plane beats a median.
        decision.leaf =
            !(splitCost < static_cast<float>(range.cost()) * area) && count <= kMaxLeafSize;
        if (decision.leaf && mixedKeys(items, range)) {
          decision.leaf = false;
          decision.kind = DecisionKind::Key;
        }
        return decision;
      }
    }
  }
  decision.kind = DecisionKind::Median;
  if (forceLeaf) return decision;
  decision.leaf = count <= kMaxLeafSize;
  if (decision.leaf && mixedKeys(items, range)) {
    decision.leaf = false;
    decision.kind = DecisionKind::Key;
  }
  return decision;
}

// Hoare partition of range by goesLeft, accumulating both sides' bounds as it goes.
template <class GoesLeft>
std::pair<Range, Range> partition(BuildItems& items, const Range& range, GoesLeft goesLeft) {
  Range left;
  Range right;
  std::uint32_t i = range.begin;
  std::uint32_t j = range.end;
  while (true) {
    while (i < j && goesLeft(items[i])) left.add(items[i++]);
    while (i < j && !goesLeft(items[j - 1])) right.add(items[--j]);
    if (i >= j) break;
    std::swap(items[i], items[j - 1]);
    left.add(items[i++]);
    right.add(items[--j]);
  }
  left.begin = range.begin;
  left.end = i;
  right.begin = i;
  right.end = range.end;
  return {left, right};
}

std::pair<Range, Range> split(BuildItems& items, const Child& child) {
  const Range& range = child.range;
  const Decision& d = child.decision;
  switch (d.kind) {
    case DecisionKind::Sah:
      return partition(items, range, [&](const BuildItem& item) {
        return binIndex(lanes(centroid2(item))[d.axis], d.binLo, d.binScale, d.binCount) <= d.bin;
      });
    case DecisionKind::Key: {
      const std::uint32_t key = itemKey(items[range.begin]);
      return partition(items, range, [key](const BuildItem& item) { return itemKey(item) == key; });
    }
    default:
      break;
  }
  // Object median on the widest centroid axis; ties (and a range of coincident centroids) are
  // ordered by key and index, a strict total order, so the halves are well defined.
  const auto extent = lanes(_mm_sub_ps(range.centroids.hi, range.centroids.lo));
  const int axis = (extent[0] >= extent[1] && extent[0] >= extent[2]) ? 0
                   : (extent[1] >= extent[2])                         ? 1
                                                                      : 2;
  const std::uint32_t mid = range.begin + range.count() / 2;
  std::nth_element(items.begin() + range.begin, items.begin() + mid, items.begin() + range.end,
                   [axis](const BuildItem& a, const BuildItem& b) {
                     const float ca = lanes(centroid2(a))[axis];
                     const float cb = lanes(centroid2(b))[axis];
                     if (ca != cb) return ca < cb;
                     const std::uint32_t ka = itemKey(a);
                     const std::uint32_t kb = itemKey(b);
                     if (ka != kb) return ka < kb;
                     return itemIndex(a) < itemIndex(b);
                   });
  Range left;
  Range right;
  for (std::uint32_t i = range.begin; i < mid; ++i) left.add(items[i]);
  for (std::uint32_t i = mid; i < range.end; ++i) right.add(items[i]);
  left.begin = range.begin;
  left.end = mid;
  right.begin = mid;
  right.end = range.end;
  return {left, right};
}

// Room for the nodes of a subtree over `count` references: about one node per four (leaves of
// a few references in nodes of four children); more only makes the vector grow once.
std::size_t nodeCountGuess(std::uint32_t count) { return count / 4 + 1; }

Node emptyNode() {
  Node node{};
  for (int i = 0; i < 4; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      node.bounds[axis][i] = kInf;
      node.bounds[axis + 3][i] = -kInf;
    }
  }
  return node;
}

// A part of the tree built by one task: its nodes, depth-first, with child indices relative to
// its start, and the subtrees of its node that were built by tasks of their own (a node over at
// least kParallelBuildThreshold references builds each inner child's subtree as a task; such a
// node is the only node of its part, since its parent builds it as a task too). `place` puts
// every part in its place of the tree's depth-first array at the end: the subtrees are neither
// copied level by level into their parents' arrays nor copied on one thread.
struct Part {
  struct Subtree {
    std::uint32_t node;  // the node here, and its slot, that points to the subtree
    int slot;
    std::unique_ptr<Part> part;
  };
  Nodes nodes;
  std::vector<Subtree> subtrees;  // in slot order: depth-first, they follow nodes in that order
  std::size_t totalNodes = 0;     // with every subtree's, at all levels (countNodes)
};

// Appends the subtree of a range that must be split to out (depth-first); returns its root's index
// in out.nodes. Child indices are relative to out's start; the slots of subtrees built as tasks
// of their own are set by `place`.
std::uint32_t buildNode(BuildItems& items, const Range& range, const Decision& decision, int depth,
                        Part& out) {
  std::array<Child, 4> children;
  int childCount = 1;
  children[0] = {range, decision};
  while (childCount < 4) {
    // Split the child of largest surface area that is to be an inner node; when there is none,
    // fill the free slots by splitting leaves (their halves stay leaves): the four boxes are
    // tested together anyway, and smaller leaves mean fewer reference tests, for no extra node.
    int pick = -1;
    bool pickLeaf = true;
    float pickArea = -1;
    for (int i = 0; i < childCount; ++i) {
      const Decision& d = children[i].decision;
      if (d.kind == DecisionKind::None || (d.leaf && !pickLeaf)) continue;
      const float area = halfArea(children[i].range.bounds);
      if ((pickLeaf && !d.leaf) || area > pickArea) {
        pickArea = area;
        pick = i;
        pickLeaf = d.leaf;
      }
    }
    if (pick < 0) break;
    // Named references, not a structured binding: clang 14 cannot capture those in lambdas.
    const std::pair<Range, Range> halves = split(items, children[pick]);
    const Range& left = halves.first;
    const Range& right = halves.second;
    Decision leftDecision, rightDecision;
    if (range.count() >= kParallelBuildThreshold) {
      // The halves' decisions read disjoint items: side by side, so that the node's own splits
      // (serial, before its subtrees become tasks) keep both threads busy.
      tbb::parallel_invoke([&] { leftDecision = decide(items, left, depth + 1, pickLeaf); },
                           [&] { rightDecision = decide(items, right, depth + 1, pickLeaf); });
    } else {
      leftDecision = decide(items, left, depth + 1, pickLeaf);
      rightDecision = decide(items, right, depth + 1, pickLeaf);
    }
    children[pick] = {left, leftDecision};
    children[childCount++] = {right, rightDecision};
  }

  const auto nodeIndex = static_cast<std::uint32_t>(out.nodes.size());
  out.nodes.push_back(emptyNode());
  for (int i = 0; i < childCount; ++i) {
    const auto lo = lanes(children[i].range.bounds.lo);
    const auto hi = lanes(children[i].range.bounds.hi);
    Node& node = out.nodes[nodeIndex];
    for (int axis = 0; axis < 3; ++axis) {
      node.bounds[axis][i] = lo[axis];
      node.bounds[axis + 3][i] = hi[axis];
    }
    if (children[i].decision.leaf) {
      node.child[i] = children[i].range.begin;
      node.info[i] = leafInfo(itemKey(items[children[i].range.begin]), children[i].range.count());
    } else {
      node.info[i] = kInner;
    }
  }

  if (range.count() < kParallelBuildThreshold) {
    for (int i = 0; i < childCount; ++i) {
      if (children[i].decision.leaf) continue;
      const std::uint32_t index =
          buildNode(items, children[i].range, children[i].decision, depth + 1, out);
      out.nodes[nodeIndex].child[i] = index;
    }
    return nodeIndex;
  }
  // The subtrees work on disjoint ranges of items, each into its own part.
  for (int i = 0; i < childCount; ++i) {
    if (!children[i].decision.leaf) {
      out.subtrees.push_back({nodeIndex, i, std::make_unique<Part>()});
    }
  }
  tbb::task_group group;
  for (const Part::Subtree& subtree : out.subtrees) {
    Part* part = subtree.part.get();
    const Child* child = &children[subtree.slot];
    group.run([&items, part, child, depth] {
      // A part over fewer references than kParallelBuildThreshold holds their whole subtree.
      if (child->range.count() < kParallelBuildThreshold) {
        part->nodes.reserve(nodeCountGuess(child->range.count()));
      }
      buildNode(items, child->range, child->decision, depth + 1, *part);
    });
  }
  group.wait();
  return nodeIndex;
}

std::size_t countNodes(Part& part) {
  part.totalNodes = part.nodes.size();
  for (Part::Subtree& subtree : part.subtrees) part.totalNodes += countNodes(*subtree.part);
  return part.totalNodes;
}

// Copies part (countNodes done) and its subtrees to out[base ...], depth-first: its own nodes,
// then each subtree after the last; child indices made absolute. Parts are copied in parallel.
void place(const Part& part, std::uint32_t base, Node* out) {
  tbb::task_group group;
  auto next = static_cast<std::uint32_t>(base + part.nodes.size());
  for (const Part::Subtree& subtree : part.subtrees) {
    const Part* child = subtree.part.get();
    group.run([child, next, out] { place(*child, next, out); });
    next += static_cast<std::uint32_t>(child->totalNodes);
  }
  for (std::size_t n = 0; n < part.nodes.size(); ++n) {
    Node node = part.nodes[n];
    for (int k = 0; k < 4; ++k) {
      if (node.info[k] == kInner) node.child[k] += base;
    }
    out[base + n] = node;
  }
  next = static_cast<std::uint32_t>(base + part.nodes.size());
  for (const Part::Subtree& subtree : part.subtrees) {
    out[base + subtree.node].child[subtree.slot] = next;
    next += static_cast<std::uint32_t>(subtree.part->totalNodes);
  }
  group.wait();
}

Range wholeRange(const BuildItems& items) {
  const auto count = static_cast<std::uint32_t>(items.size());
  Range range = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, count, kBinGrain), Range{},
      [&](const tbb::blocked_range<std::size_t>& r, Range acc) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) acc.add(items[i]);
        return acc;
      },
      [](Range a, const Range& b) {
        a.bounds.grow(b.bounds);
        a.centroids.grow(b.centroids);
        a.primitives += b.primitives;
        return a;
      });
  range.begin = 0;
  range.end = count;
  return range;
}

// One float ulp outward from the nearest float: std::nextafter toward ∓inf, inline (a libm call
// per coordinate was 2 % of a 100k-triangle build). NaN and the infinity stepped toward are
// returned unchanged, as nextafter returns them; the other infinity steps to ∓FLT_MAX, as it does.
float roundDown(double x) {
  const auto f = static_cast<float>(x);
  return f > -kInf ? nextDown(f) : f;
}
float roundUp(double x) {
  const auto f = static_cast<float>(x);
  return f < kInf ? nextUp(f) : f;
}

// One child slot of a node during the collapse: the 4-wide node it lives in and its slot there.
struct SlotRef {
  std::uint32_t node;
  int slot;
};

// Half the surface area of a child box of a 4-wide node (float, as stored).
float childHalfArea(const Node& node, int slot) {
  const float dx = node.bounds[3][slot] - node.bounds[0][slot];
  const float dy = node.bounds[4][slot] - node.bounds[1][slot];
  const float dz = node.bounds[5][slot] - node.bounds[2][slot];
  return dx * dy + dy * dz + dz * dx;
}

int childCountOf(const Node& node) {
  int count = 0;
  while (count < Node::kWidth && node.info[count] != kEmpty) ++count;
  return count;
}

// Appends the 8-wide node made of 4-wide node `index` and its subtree to out; returns its index.
std::uint32_t collapseNode(const Nodes& nodes, std::uint32_t index, Nodes8& out) {
  std::array<SlotRef, Node8::kWidth> slots;
  int count = 0;
  for (int i = 0; i < childCountOf(nodes[index]); ++i) slots[count++] = {index, i};
  while (true) {
    // The inner child of largest area whose children fit in the free slots (the first of equals).
    int pick = -1;
    float pickArea = -1;
    for (int i = 0; i < count; ++i) {
      const Node& parent = nodes[slots[i].node];
      if (parent.info[slots[i].slot] != kInner) continue;
      const int grandchildren = childCountOf(nodes[parent.child[slots[i].slot]]);
      if (count - 1 + grandchildren > Node8::kWidth) continue;
      const float area = childHalfArea(parent, slots[i].slot);
      if (area > pickArea) {
        pickArea = area;
        pick = i;
      }
    }
    if (pick < 0) break;
    const std::uint32_t pulled = nodes[slots[pick].node].child[slots[pick].slot];
    const int grandchildren = childCountOf(nodes[pulled]);
    // Shift the slots after pick right and put the pulled node's children in its place.
    for (int i = count - 1; i > pick; --i) slots[i + grandchildren - 1] = slots[i];
    for (int k = 0; k < grandchildren; ++k) slots[pick + k] = {pulled, k};
    count += grandchildren - 1;
  }

  const auto wideIndex = static_cast<std::uint32_t>(out.size());
  Node8 wide{};
  for (int i = 0; i < Node8::kWidth; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      wide.bounds[axis][i] = kInf;
      wide.bounds[axis + 3][i] = -kInf;
    }
  }
  for (int i = 0; i < count; ++i) {
    const Node& parent = nodes[slots[i].node];
    const int s = slots[i].slot;
    for (int row = 0; row < 6; ++row) wide.bounds[row][i] = parent.bounds[row][s];
    wide.child[i] = parent.child[s];
    wide.info[i] = parent.info[s];
  }
  out.push_back(wide);
  for (int i = 0; i < count; ++i) {
    if (out[wideIndex].info[i] != kInner) continue;
    const std::uint32_t child = collapseNode(nodes, out[wideIndex].child[i], out);
    out[wideIndex].child[i] = child;
  }
  return wideIndex;
}

}  // namespace

BuildItem makeBuildItem(const double lo[3], const double hi[3], std::uint32_t key,
                        std::uint32_t index) {
  BuildItem item;
  for (int axis = 0; axis < 3; ++axis) {
    item.lo[axis] = roundDown(lo[axis]);
    item.hi[axis] = roundUp(hi[axis]);
  }
  item.lo[3] = std::bit_cast<float>(key);
  item.hi[3] = std::bit_cast<float>(index);
  return item;
}

std::uint32_t itemKey(const BuildItem& item) { return std::bit_cast<std::uint32_t>(item.lo[3]); }
std::uint32_t itemIndex(const BuildItem& item) { return std::bit_cast<std::uint32_t>(item.hi[3]); }

Tree build(BuildItems& items) {
  Tree tree;
  if (items.empty()) return tree;
  const Range root = wholeRange(items);
  const Decision decision = decide(items, root, 0);
  if (decision.leaf) {
    tree.rootChild = 0;
    tree.rootInfo = leafInfo(itemKey(items[0]), root.count());
    return tree;
  }
  Part whole;
  if (root.count() < kParallelBuildThreshold) whole.nodes.reserve(nodeCountGuess(root.count()));
  tree.rootChild = buildNode(items, root, decision, 0, whole);
  tree.rootInfo = kInner;
  if (whole.subtrees.empty()) {
    tree.nodes = std::move(whole.nodes);
    tree.nodes.shrink_to_fit();
  } else {
    tree.nodes.resize(countNodes(whole));  // not zeroed (Nodes' allocator): place writes them all
    place(whole, 0, tree.nodes.data());
  }
  return tree;
}

Nodes8 collapseToWide(const Nodes& nodes) {
  Nodes8 wide;
  if (nodes.empty()) return wide;
  wide.reserve(nodes.size() / 2 + 1);
  collapseNode(nodes, 0, wide);
  wide.shrink_to_fit();
  return wide;
}

}  // namespace glint::bvh
