#include "glint/image/channel_encoder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "glint/image/image_writer.h"

namespace glint {
namespace {

class ChannelEncoderTest : public ::testing::TestWithParam<Encoding> {};

// The table's premise: encodeChannel never decreases. Checked where it could fail — thousands of
// doubles either side of every code change — and at the ends of every bucket.
TEST_P(ChannelEncoderTest, EncodeChannelIsMonotoneAroundEveryThreshold) {
  const ChannelEncoder encoder(GetParam());
  for (int code = 1; code <= 255; ++code) {
    const double t = encoder.threshold(code);
    EXPECT_GE(encodeChannel(t, GetParam()), code);
    double below = t;
    double above = t;
    for (int step = 0; step < 2000; ++step) {
      below = std::nextafter(below, 0.0);
      above = std::nextafter(above, 2.0);
      ASSERT_LT(encodeChannel(below, GetParam()), code) << "code " << code << " step " << step;
      ASSERT_GE(encodeChannel(above, GetParam()), code) << "code " << code << " step " << step;
    }
  }
  for (int bucket = 0; bucket < ChannelEncoder::kBuckets; ++bucket) {
    const double start = static_cast<double>(bucket) / ChannelEncoder::kBuckets;
    const double end =
        std::nextafter(static_cast<double>(bucket + 1) / ChannelEncoder::kBuckets, 0.0);
    EXPECT_LE(encodeChannel(end, GetParam()) - encodeChannel(start, GetParam()), 1) << bucket;
  }
}

TEST_P(ChannelEncoderTest, GivesEncodeChannelsAnswers) {
  const ChannelEncoder encoder(GetParam());
  const double specials[] = {0.0,
                             -0.0,
                             -1.0,
                             1.0,
                             1.5,
                             1e300,
                             -1e300,
                             5e-324,
                             std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()};
  for (const double v : specials) EXPECT_EQ(encoder(v), encodeChannel(v, GetParam())) << v;
  for (int code = 1; code <= 255; ++code) {
    double v = encoder.threshold(code);
    for (int i = 0; i < 3; ++i) v = std::nextafter(v, 0.0);
    for (int i = 0; i < 6; ++i, v = std::nextafter(v, 2.0))
      ASSERT_EQ(encoder(v), encodeChannel(v, GetParam())) << v;
  }
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-0.1, 1.1);
  for (int i = 0; i < 2'000'000; ++i) {
    const double v = unit(random);
    ASSERT_EQ(encoder(v), encodeChannel(v, GetParam())) << v;
  }
}

INSTANTIATE_TEST_SUITE_P(Encodings, ChannelEncoderTest,
                         ::testing::Values(Encoding::Srgb, Encoding::Linear));

}  // namespace
}  // namespace glint
