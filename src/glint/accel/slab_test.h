// The ray-box slab test the BVH traversals share (the Aggregate's tree and the instances' top-level
// tree): a ray set up once per traversal (BoxRay), one SSE test of a node's four child boxes, or
// one AVX test of an 8-wide node's eight, against an interval of t, conservative in floats.
#pragma once

#include <emmintrin.h>
#ifdef __AVX2__
#include <immintrin.h>  // the 8-wide test in the AVX2 and AVX-512 kernels (aggregate_avx*.cpp)
#endif

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "glint/accel/bvh4.h"
#include "glint/core/ray.h"

namespace glint::slab {

using bvh::Node;
using bvh::Node8;

inline constexpr float kFloatMax = std::numeric_limits<float>::max();

// The far slab distances are scaled by 1 + 2^-20 (16 float ulps). Each slab distance
// (b − o)·(1/d) rounds three times in single precision (the subtraction, 1/d to float, the
// product), so a computed near distance is at most ~3 ulps above the exact one and a far distance
// at most ~4 ulps below (with the scaling rounded too); the scale covers both with room to spare
// (Ize 2013, "Robust BVH Ray Traversal", for the argument). The origin's own rounding to float is
// absolute, not relative, so it is not padded but rounded toward the safe side per slab plane.
inline constexpr double kFarScale = 1 + 0x1p-20;

// The floats of f one ulp further toward +inf (kUp) or −inf in the lanes where `where` is all ones
// and f is finite; the other lanes unchanged.
template <bool kUp>
inline __m128 stepWhere(__m128 f, __m128 where) {
  const __m128 finite = _mm_cmple_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), f), _mm_set1_ps(kFloatMax));
  const __m128i bits = _mm_castps_si128(f);
  const __m128i twiceSign = _mm_add_epi32(_mm_srai_epi32(bits, 31), _mm_srai_epi32(bits, 31));
  // Toward +inf: +1 for a positive pattern, −1 for a negative one (1 + 2·sign, sign 0 or −1).
  const __m128i up =
      _mm_sub_epi32(_mm_set1_epi32(1), _mm_sub_epi32(_mm_setzero_si128(), twiceSign));
  const __m128i delta = kUp ? up : _mm_sub_epi32(_mm_setzero_si128(), up);
  const __m128i step = _mm_and_si128(delta, _mm_castps_si128(_mm_and_ps(where, finite)));
  return _mm_castsi128_ps(_mm_add_epi32(bits, step));
}

// The float nearest to x on the side toward −inf (floatBelow) or +inf (floatAbove); infinite beyond
// the float range. Without branches (whether x rounds up or down to float is a coin toss per ray,
// so a branch there mispredicts half the time): a one-ulp step is ±1 on the bit pattern, away from
// zero on the side of the float's sign (nextUp/nextDown of core/ulp.h; −0 steps to −denorm_min and
// +0 to +denorm_min, as they do). The comparisons are SSE masks, which the compiler cannot turn
// back into branches.
template <bool kUp>
inline float floatStep(double x) {
  const __m128d xd = _mm_set_sd(x);
  const __m128 f = _mm_cvtsd_ss(_mm_setzero_ps(), xd);
  const __m128d back = _mm_cvtss_sd(_mm_setzero_pd(), f);
  // x above (kUp) or below the float: lane 0 all ones.
  const __m128 off = _mm_castpd_ps(kUp ? _mm_cmplt_sd(back, xd) : _mm_cmpgt_sd(back, xd));
  return _mm_cvtss_f32(stepWhere<kUp>(f, off));
}
inline float floatBelow(double x) { return floatStep<false>(x); }
inline float floatAbove(double x) { return floatStep<true>(x); }

// The two doubles of xy and the low one of z as floats in lanes 0, 1, 2 (lane 3: z's high lane),
// rounded to nearest as static_cast<float> rounds.
inline __m128 toFloat3(__m128d xy, __m128d z) {
  return _mm_movelh_ps(_mm_cvtpd_ps(xy), _mm_cvtpd_ps(z));
}

// floatBelow and floatAbove of three doubles at once (lanes 0–2; lane 3 unused), without branches.
inline void floatBracket(__m128d xy, __m128d z, __m128& below, __m128& above) {
  const __m128 f = toFloat3(xy, z);
  const __m128d backXY = _mm_cvtps_pd(f);
  const __m128d backZ = _mm_cvtps_pd(_mm_movehl_ps(f, f));
  // 64-bit compare masks narrowed to 32-bit lanes 0–2.
  const __m128 above64 =
      _mm_shuffle_ps(_mm_castpd_ps(_mm_cmpgt_pd(backXY, xy)), _mm_castpd_ps(_mm_cmpgt_sd(backZ, z)),
                     _MM_SHUFFLE(2, 0, 2, 0));
  const __m128 below64 =
      _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(backXY, xy)), _mm_castpd_ps(_mm_cmplt_sd(backZ, z)),
                     _MM_SHUFFLE(2, 0, 2, 0));
  // f above x: below steps toward −inf; f below x: above steps toward +inf.
  below = stepWhere<false>(f, above64);
  above = stepWhere<true>(f, below64);
}

// Lanes 0, 1, 2 of v, each broadcast to all four lanes of its own register (one per axis).
inline void broadcastAxes(__m128 v, __m128 (&axes)[3]) {
  axes[0] = _mm_shuffle_ps(v, v, _MM_SHUFFLE(0, 0, 0, 0));
  axes[1] = _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 1, 1, 1));
  axes[2] = _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 2, 2, 2));
}

// Byte offsets of the rows of Node::bounds or Node8::bounds (0–2 low, 3–5 high) a slab test reads
// per axis, for each octant of the direction (bit a set: component a negative, the near plane is
// the high one).
struct SlabRows {
  std::array<std::size_t, 3> nearRow;
  std::array<std::size_t, 3> farRow;
};
template <std::size_t kRow>
inline constexpr std::array<SlabRows, 8> kSlabRowsOf = [] {
  std::array<SlabRows, 8> table{};
  for (std::size_t signs = 0; signs < 8; ++signs) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      const std::size_t flip = 3 * ((signs >> axis) & 1u);
      table[signs].nearRow[axis] = kRow * (axis + flip);
      table[signs].farRow[axis] = kRow * (axis + 3 - flip);
    }
  }
  return table;
}();
inline constexpr const std::array<SlabRows, 8>& kSlabRows = kSlabRowsOf<sizeof(Node::bounds[0])>;
inline constexpr const std::array<SlabRows, 8>& kWideSlabRows =
    kSlabRowsOf<sizeof(Node8::bounds[0])>;

// What the SSE slab tests of one traversal share. For a positive direction component the near
// plane is the low one and the origin is rounded up there (down at the far plane), and the other
// way round for a negative one, so the computed interval can only grow. A zero component gives
// ±inf reciprocals, and the NaN of 0·inf (origin on the slab plane) is ignored by the min/max order
// below, which keeps the test conservative. Set up without branches: with random directions a
// branch on a sign or a rounding direction mispredicts half the time.
struct BoxRay {
  __m128 nearOrigin[3];
  __m128 farOrigin[3];
  __m128 nearInverse[3];
  __m128 farInverse[3];
  SlabRows rows;      // of Node
  SlabRows wideRows;  // of Node8

  explicit BoxRay(const Ray& ray) {
    static_assert(std::is_standard_layout_v<Vec3> && sizeof(Vec3) == 3 * sizeof(double));
    static_assert(std::is_standard_layout_v<Point3> && sizeof(Point3) == 3 * sizeof(double));
    const __m128d one = _mm_set1_pd(1.0);
    const __m128d scale = _mm_set1_pd(kFarScale);
    const __m128d inverseXY = _mm_div_pd(one, _mm_loadu_pd(&ray.direction.x));
    const __m128d inverseZ = _mm_div_sd(one, _mm_load_sd(&ray.direction.z));
    const __m128 nearInv = toFloat3(inverseXY, inverseZ);
    const __m128 farInv = toFloat3(_mm_mul_pd(inverseXY, scale), _mm_mul_sd(inverseZ, scale));
    __m128 below;
    __m128 above;
    floatBracket(_mm_loadu_pd(&ray.origin.x), _mm_load_sd(&ray.origin.z), below, above);
    // The sign of the double reciprocal, which its float rounding keeps.
    const __m128 negative = _mm_castsi128_ps(_mm_srai_epi32(_mm_castps_si128(nearInv), 31));
    const __m128 nearO = _mm_or_ps(_mm_and_ps(negative, below), _mm_andnot_ps(negative, above));
    const __m128 farO = _mm_or_ps(_mm_and_ps(negative, above), _mm_andnot_ps(negative, below));
    broadcastAxes(nearO, nearOrigin);
    broadcastAxes(farO, farOrigin);
    broadcastAxes(nearInv, nearInverse);
    broadcastAxes(farInv, farInverse);
    const unsigned octant = static_cast<unsigned>(_mm_movemask_ps(negative)) & 7u;
    rows = kSlabRows[octant];
    wideRows = kWideSlabRows[octant];
  }
};

// The SSE slab test of four children whose boxes are the float rows at `base` (`rows`: each axis'
// near and far row, as byte offsets for this ray's direction) against [tMin, tMax]: bit i of the
// result is set when child i's box overlaps the interval; tNear receives the entry distances.
// _mm_max_ps/_mm_min_ps return their second operand when either is NaN, so a NaN slab distance
// leaves the interval unchanged.
inline int intersectFourBoxes(const unsigned char* base, const SlabRows& rows, const BoxRay& r,
                              __m128 tMin, __m128 tMax, __m128& tNear) {
  __m128 tn = tMin;
  __m128 tf = tMax;
  for (int axis = 0; axis < 3; ++axis) {
    const __m128 n = _mm_mul_ps(
        _mm_sub_ps(_mm_load_ps(reinterpret_cast<const float*>(base + rows.nearRow[axis])),
                   r.nearOrigin[axis]),
        r.nearInverse[axis]);
    const __m128 f =
        _mm_mul_ps(_mm_sub_ps(_mm_load_ps(reinterpret_cast<const float*>(base + rows.farRow[axis])),
                              r.farOrigin[axis]),
                   r.farInverse[axis]);
    tn = _mm_max_ps(n, tn);
    tf = _mm_min_ps(f, tf);
  }
  tNear = tn;
  return _mm_movemask_ps(_mm_cmple_ps(tn, tf));
}

// Slab test of a 4-wide node's children (intersectFourBoxes).
inline int intersectNode(const Node& node, const BoxRay& r, __m128 tMin, __m128 tMax,
                         __m128& tNear) {
  return intersectFourBoxes(reinterpret_cast<const unsigned char*>(node.bounds), r.rows, r, tMin,
                            tMax, tNear);
}

// The SSE test of four lanes of an 8-wide node (lanes `offset` .. offset + 3, offset 0 or 4), the
// same arithmetic as intersectNode.
inline int intersectHalf(const Node8& node, int offset, const BoxRay& r, __m128 tMin, __m128 tMax,
                         __m128& tNear) {
  return intersectFourBoxes(
      reinterpret_cast<const unsigned char*>(node.bounds) + sizeof(float) * offset, r.wideRows, r,
      tMin, tMax, tNear);
}

#ifdef __AVX2__
// BoxRay's registers broadcast to eight lanes, for the 256-bit test of an 8-wide node.
struct WideBoxRay {
  __m256 nearOrigin[3];
  __m256 farOrigin[3];
  __m256 nearInverse[3];
  __m256 farInverse[3];
  SlabRows rows;

  explicit WideBoxRay(const BoxRay& r) : rows(r.wideRows) {
    for (int axis = 0; axis < 3; ++axis) {
      nearOrigin[axis] = _mm256_set_m128(r.nearOrigin[axis], r.nearOrigin[axis]);
      farOrigin[axis] = _mm256_set_m128(r.farOrigin[axis], r.farOrigin[axis]);
      nearInverse[axis] = _mm256_set_m128(r.nearInverse[axis], r.nearInverse[axis]);
      farInverse[axis] = _mm256_set_m128(r.farInverse[axis], r.farInverse[axis]);
    }
  }
};

// Slab test of the eight children in one 256-bit pass: lane for lane the arithmetic of
// intersectNode (subtract, multiply, then max/min with the same operand order, so NaN lanes are
// ignored alike), hence the same mask bits as two SSE tests.
inline int intersectNode(const Node8& node, const WideBoxRay& r, __m256 tMin, __m256 tMax,
                         __m256& tNear) {
  __m256 tn = tMin;
  __m256 tf = tMax;
  const auto* base = reinterpret_cast<const unsigned char*>(node.bounds);
  for (int axis = 0; axis < 3; ++axis) {
    const __m256 n = _mm256_mul_ps(
        _mm256_sub_ps(_mm256_load_ps(reinterpret_cast<const float*>(base + r.rows.nearRow[axis])),
                      r.nearOrigin[axis]),
        r.nearInverse[axis]);
    const __m256 f = _mm256_mul_ps(
        _mm256_sub_ps(_mm256_load_ps(reinterpret_cast<const float*>(base + r.rows.farRow[axis])),
                      r.farOrigin[axis]),
        r.farInverse[axis]);
    tn = _mm256_max_ps(n, tn);
    tf = _mm256_min_ps(f, tf);
  }
  tNear = tn;
  return _mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ));
}
#endif

struct StackEntry {
  std::uint32_t child;
  std::uint32_t info;
  float tNear;
};

}  // namespace glint::slab
