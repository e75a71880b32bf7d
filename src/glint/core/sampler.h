// Sample points for distributed ray tracing: padded 2D Owen-scrambled Sobol, keyed by
// (pixel, sample index, dimension, seed) and nothing else.
//
// Design (pbrt-v4's PaddedSobolSampler with Burley 2020, "Practical Hash-based Owen Scrambling"):
// every 2D dimension (pixel offset, lens, one glossy lobe, one area light...) draws from its own
// copy of the first two Sobol dimensions, a (0,2)-sequence. Each copy is
//   - shuffled: the sample index goes through a nested uniform (Owen) scramble of its bits, which
//     permutes indices only within aligned blocks of 2^k, so the first 2^k points of a dimension
//     are still a (0,k,2)-net — every prefix stays well distributed, as adaptive sampling needs;
//   - Owen-scrambled per axis: a hash-driven nested permutation of the coordinate's binary digits,
//     which keeps the net property and randomises the points;
// with the shuffle and scramble seeds hashed from (pixel key, dimension). Different dimensions of
// one pixel are therefore decorrelated (independent shuffles: no shared index structure), and so
// are different pixels. There is no generator state: a point is a pure function of its key, so the
// order in which threads render pixels cannot change it.
#pragma once

#include <cstdint>

#include "glint/core/rng.h"
#include "glint/core/vec.h"

namespace glint {

// Bit i of the result is bit 31 − i of `bits`.
inline std::uint32_t reverseBits32(std::uint32_t bits) {
  bits = __builtin_bswap32(bits);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  return ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
}

// Burley 2020's Laine–Karras-style hash: bit k of the result depends only on bits 0..k of x (every
// step adds or multiplies by an even constant), so it is a nested permutation of the low bits.
inline std::uint32_t laineKarrasPermutation(std::uint32_t x, std::uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// Owen scrambling of a 32-bit binary fraction (bit 31 = 1/2): each digit is flipped by a hash of
// the digits above it. Applied to an integer index it shuffles within aligned blocks of 2^k.
inline std::uint32_t nestedUniformScramble(std::uint32_t x, std::uint32_t seed) {
  return reverseBits32(laineKarrasPermutation(reverseBits32(x), seed));
}

// The first two dimensions of the Sobol sequence as 32-bit fractions: dimension 0 is the van der
// Corput radical inverse; dimension 1 has the generator matrix of primitive polynomial x + 1
// (direction numbers v0 = 2^31, v(i+1) = v(i) ^ (v(i) >> 1)). Together a (0,2)-sequence.
inline std::uint32_t sobolDimension0(std::uint32_t index) { return reverseBits32(index); }

namespace detail {
// reverseBits32(sobolDimension1(index)) one index byte at a time: entry [b][v] is the XOR of the
// bit-reversed direction numbers r(i) = reverse(v(i)) (r0 = 1, r(i+1) = r(i) ^ (r(i) << 1)) over
// the set bits of v, for i = 8b + bit. Four lookups instead of a 32-step loop.
struct SobolDimension1Table {
  std::uint32_t entries[4][256] = {};
  constexpr SobolDimension1Table() {
    std::uint32_t r[32] = {};
    r[0] = 1;
    for (int i = 1; i < 32; ++i) r[i] = r[i - 1] ^ (r[i - 1] << 1);
    for (int b = 0; b < 4; ++b) {
      for (int v = 0; v < 256; ++v) {
        std::uint32_t x = 0;
        for (int bit = 0; bit < 8; ++bit) {
          if (v & (1 << bit)) x ^= r[8 * b + bit];
        }
        entries[b][v] = x;
      }
    }
  }
};
inline constexpr SobolDimension1Table kSobolDimension1Table{};

inline std::uint32_t sobolDimension1Reversed(std::uint32_t index) {
  const auto& t = kSobolDimension1Table.entries;
  return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^
         t[3][index >> 24];
}
}  // namespace detail

inline std::uint32_t sobolDimension1(std::uint32_t index) {
  return reverseBits32(detail::sobolDimension1Reversed(index));
}

// One 2D dimension: the shuffled, Owen-scrambled 2D Sobol sequence selected by a 64-bit key. The
// three seeds are hashed once, so a loop over many sub-samples of one dimension pays only for the
// scrambles of each point.
class SobolDimension2D {
 public:
  explicit constexpr SobolDimension2D(std::uint64_t key)
      : shuffleSeed_(static_cast<std::uint32_t>(key)),
        xSeed_(static_cast<std::uint32_t>(key >> 32)),
        ySeed_(static_cast<std::uint32_t>(mix64(key))) {}

  // Point `index` of the sequence, in [0,1)². The scrambles are written without the bit
  // reversals that cancel: Owen(sobol0(j)) = reverse(LK(j)), Owen(sobol1(j)) =
  // reverse(LK(reverse(sobol1(j)))).
  Point2 at(std::uint32_t index) const {
    const std::uint32_t shuffled = nestedUniformScramble(index, shuffleSeed_);
    const std::uint32_t x = reverseBits32(laineKarrasPermutation(shuffled, xSeed_));
    const std::uint32_t y =
        reverseBits32(laineKarrasPermutation(detail::sobolDimension1Reversed(shuffled), ySeed_));
    return {static_cast<double>(x) * 0x1.0p-32, static_cast<double>(y) * 0x1.0p-32};
  }

 private:
  std::uint32_t shuffleSeed_, xSeed_, ySeed_;
};

// Point `index` of the shuffled, Owen-scrambled 2D Sobol sequence selected by `key`, in [0,1)².
inline Point2 scrambledSobol2D(std::uint32_t index, std::uint64_t key) {
  return SobolDimension2D(key).at(index);
}

// The sample points of one sample path. `key` identifies the pixel (and seed) and, below a branch,
// the branch; `index` is the sample's position in its dimension's sequence. Cheap to copy.
//
// A dimension is a small integer chosen by the caller (the renderer documents its layout). Where a
// path fans out into `count` sub-samples in one dimension (several glossy rays, several area-light
// points), sub-sample k takes sequence index index·count + k: the count sub-samples of one pixel
// sample are consecutive points of the sequence (a net when count is a power of two) and all
// pixel samples together are a longer prefix of it, so they stratify against each other too.
class SampleStream {
 public:
  constexpr SampleStream() = default;
  constexpr SampleStream(std::uint64_t key, std::uint32_t index) : key_(key), index_(index) {}

  // The stream of pixel sample `sampleIndex` of pixel (column, row) under `seed`.
  static constexpr SampleStream forPixel(std::uint32_t column, std::uint32_t row,
                                         std::uint32_t sampleIndex, std::uint64_t seed) {
    // The salt keeps these keys apart from Rng::forPixelSample's for the same numbers.
    return {hashCombine(hashCombine(hashCombine(seed, 0x5a3b1e0d9c7f2468ULL), column), row),
            sampleIndex};
  }

  // The sequence of `dimension` on this path (hoist it out of loops over sub-samples).
  SobolDimension2D dimension(std::uint32_t dimension) const {
    return SobolDimension2D(mix64(key_ ^ (0x9e3779b97f4a7c15ULL * (dimension + 1))));
  }
  // The 2D point of this sample in `dimension`.
  Point2 get2D(std::uint32_t dimension) const { return this->dimension(dimension).at(index_); }
  // Sub-sample k of `count` in `dimension` (see the class comment).
  Point2 get2D(std::uint32_t dimension, std::uint32_t count, std::uint32_t k) const {
    return this->dimension(dimension).at(subIndex(count, k));
  }
  std::uint32_t subIndex(std::uint32_t count, std::uint32_t k) const { return index_ * count + k; }

  // The key of every path that continues below `dimension` (a glossy lobe): fresh, so the
  // dimensions of the next hit are independent of this path's. A bijective multiply-add step is
  // enough (one per bounce, so it is kept cheap): dimension() hashes every key before use, and
  // distinct paths reach distinct keys except by 2^-64 coincidences.
  std::uint64_t branchKey(std::uint32_t dimension) const {
    return key_ * 0xd1342543de82ef95ULL + 0x9e3779b97f4a7c15ULL * (dimension + 1);
  }
  // The stream of the path that continues below sub-sample k of `count` in `dimension` (count 1
  // for a single continuation): the branch key and the sub-sample's sequence index, so siblings
  // (same key, consecutive indices) stratify against each other.
  SampleStream branch(std::uint32_t dimension, std::uint32_t count, std::uint32_t k) const {
    return {branchKey(dimension), subIndex(count, k)};
  }

  std::uint64_t key() const { return key_; }
  std::uint32_t index() const { return index_; }

 private:
  std::uint64_t key_ = 0;
  std::uint32_t index_ = 0;
};

}  // namespace glint
