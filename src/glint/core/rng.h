// Deterministic, counter-based random numbers keyed by (pixel, sample index, seed): the same key
// gives the same stream on any thread, so renders are byte-identical for any thread count.
#pragma once

#include <cstdint>

namespace glint {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mixer with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

constexpr std::uint64_t hashCombine(std::uint64_t a, std::uint64_t b) {
  return mix64(a ^ mix64(b));
}

// A stream of uniform numbers: value k is mix64(key + k). Cheap to create per pixel sample, holds
// no shared state, and never depends on scheduling.
class Rng {
 public:
  constexpr Rng() = default;
  constexpr explicit Rng(std::uint64_t key) : key_(mix64(key)) {}
  // Key for one pixel sample: (column, row, sample index, seed).
  static constexpr Rng forPixelSample(std::uint32_t column, std::uint32_t row,
                                      std::uint32_t sampleIndex, std::uint64_t seed) {
    return Rng(hashCombine(hashCombine(hashCombine(seed, column), row), sampleIndex));
  }

  constexpr std::uint64_t nextBits() { return mix64(key_ + 0x9e3779b97f4a7c15ULL * ++counter_); }
  // Uniform double in [0, 1) with 53 random bits.
  constexpr double uniform() { return static_cast<double>(nextBits() >> 11) * 0x1.0p-53; }
  // An independent child stream (e.g. for one glossy lobe), derived from this stream's next value.
  constexpr Rng split() { return Rng(nextBits()); }

 private:
  std::uint64_t key_ = 0;
  std::uint64_t counter_ = 0;
};

}  // namespace glint
