// ChannelEncoder: encodeChannel (linear value → 8-bit code) by table lookup, with exactly its
// answers — for encoding pixels while a render runs (the preview) at a few nanoseconds a value.
#pragma once

#include <array>
#include <cstdint>

#include "glint/scene/scene.h"

namespace glint {

class ChannelEncoder {
 public:
  explicit ChannelEncoder(Encoding encoding);

  // encodeChannel(linear, encoding), exactly.
  std::uint8_t operator()(double linear) const {
    if (!(linear > 0)) return 0;  // NaN, negative and zero
    if (linear >= 1) return 255;
    // x·kBuckets is exact (a power of two), so the bucket is floor(x·kBuckets).
    const auto bucket = static_cast<int>(linear * kBuckets);
    return static_cast<std::uint8_t>(base_[bucket] + (linear >= next_[bucket] ? 1 : 0));
  }

  // Buckets of [0, 1]: the steepest encoding (sRGB's linear toe, 12.92·255 ≈ 3295 codes per unit)
  // changes code at most once across 1/4096, so a bucket's code is its first one or the next.
  static constexpr int kBuckets = 4096;

  // The least value that encodes to `code` or more (code 1 … 255).
  double threshold(int code) const { return thresholds_[code]; }

 private:
  std::array<double, 257> thresholds_{};           // [0] = 0, [256] = +inf
  std::array<std::uint8_t, kBuckets + 1> base_{};  // the code at the bucket's start
  std::array<double, kBuckets + 1> next_{};        // where the bucket's code goes up by one
};

}  // namespace glint
