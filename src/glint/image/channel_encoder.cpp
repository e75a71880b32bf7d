#include "glint/image/channel_encoder.h"

#include <bit>
#include <limits>

#include "glint/image/image_writer.h"

namespace glint {

ChannelEncoder::ChannelEncoder(Encoding encoding) {
  // Each code's threshold by bisection over the bit patterns of the doubles in [0, 1], which are
  // ordered as the values are; encodeChannel does not decrease, which image/channel_encoder_test
  // checks around every threshold.
  thresholds_[0] = 0;
  thresholds_[256] = std::numeric_limits<double>::infinity();
  for (int code = 1; code <= 255; ++code) {
    auto below = std::bit_cast<std::uint64_t>(0.0);
    auto atOrAbove = std::bit_cast<std::uint64_t>(1.0);
    while (atOrAbove - below > 1) {
      const std::uint64_t middle = below + (atOrAbove - below) / 2;
      if (encodeChannel(std::bit_cast<double>(middle), encoding) >= code)
        atOrAbove = middle;
      else
        below = middle;
    }
    thresholds_[code] = std::bit_cast<double>(atOrAbove);
  }
  for (int bucket = 0; bucket <= kBuckets; ++bucket) {
    const std::uint8_t code = encodeChannel(static_cast<double>(bucket) / kBuckets, encoding);
    base_[bucket] = code;
    next_[bucket] = thresholds_[code + 1];
  }
}

}  // namespace glint
