#include "glint/core/sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

namespace glint {
namespace {

// True when every elementary interval [i/2^a, (i+1)/2^a) × [j/2^b, (j+1)/2^b) with a + b = k
// holds exactly one of the 2^k points: a (0,k,2)-net in base 2.
bool isZeroNet(const std::vector<Point2>& points, int k) {
  const std::size_t n = std::size_t{1} << k;
  if (points.size() != n) return false;
  for (int a = 0; a <= k; ++a) {
    const int b = k - a;
    std::vector<int> count(n, 0);
    for (const Point2& p : points) {
      const auto i = static_cast<std::size_t>(std::floor(p.x * double(1 << a)));
      const auto j = static_cast<std::size_t>(std::floor(p.y * double(1 << b)));
      if (++count[(i << b) | j] > 1) return false;
    }
  }
  return true;
}

// The exact star discrepancy of a 1D point set: max over the sorted points of the largest gap
// between the empirical distribution and the uniform one.
double starDiscrepancy1D(std::vector<double> xs) {
  std::sort(xs.begin(), xs.end());
  const double n = static_cast<double>(xs.size());
  double worst = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    worst = std::max(
        {worst, static_cast<double>(i + 1) / n - xs[i], xs[i] - static_cast<double>(i) / n});
  }
  return worst;
}

TEST(Sampler, SobolDimensionsHaveTheirKnownFirstPoints) {
  // Dimension 0: van der Corput 0, 1/2, 1/4, 3/4; dimension 1: 0, 1/2, 3/4, 1/4.
  const double x[] = {0, 0.5, 0.25, 0.75};
  const double y[] = {0, 0.5, 0.75, 0.25};
  for (std::uint32_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sobolDimension0(i) * 0x1.0p-32, x[i]) << i;
    EXPECT_EQ(sobolDimension1(i) * 0x1.0p-32, y[i]) << i;
  }
}

TEST(Sampler, SobolDimension1TableMatchesTheGeneratorMatrix) {
  // The byte tables against the definition: XOR of the direction numbers of the index's set bits.
  for (std::uint32_t index : {5u, 255u, 256u, 0x12345678u, 0xffffffffu, 0x80000001u}) {
    std::uint32_t expected = 0;
    std::uint32_t v = 0x80000000u;
    for (int bit = 0; bit < 32; ++bit, v ^= v >> 1) {
      if (index & (1u << bit)) expected ^= v;
    }
    EXPECT_EQ(sobolDimension1(index), expected) << index;
  }
}

TEST(Sampler, IndexShuffleKeepsAlignedBlocks) {
  // The nested uniform scramble maps every aligned block of 2^k indices onto an aligned block,
  // bijectively: what keeps every prefix of a shuffled sequence well distributed.
  for (const std::uint32_t seed : {0u, 1u, 0xdeadbeefu}) {
    for (const int k : {1, 4, 8}) {
      const std::uint32_t size = 1u << k;
      for (const std::uint32_t block : {0u, 1u, 37u}) {
        std::set<std::uint32_t> images;
        std::uint32_t high = 0;
        for (std::uint32_t i = 0; i < size; ++i) {
          const std::uint32_t j = nestedUniformScramble(block * size + i, seed);
          if (i == 0) high = j >> k;
          EXPECT_EQ(j >> k, high) << seed << " " << k << " " << block;
          images.insert(j & (size - 1));
        }
        EXPECT_EQ(images.size(), size);
      }
    }
  }
}

TEST(Sampler, IsAPureFunctionOfItsKey) {
  const SampleStream a = SampleStream::forPixel(3, 7, 5, 42);
  const SampleStream b = SampleStream::forPixel(3, 7, 5, 42);
  for (std::uint32_t d = 0; d < 6; ++d) {
    EXPECT_EQ(a.get2D(d).x, b.get2D(d).x);
    EXPECT_EQ(a.get2D(d).y, b.get2D(d).y);
  }
  // Pixel, sample, seed and dimension each change the point.
  const Point2 p = a.get2D(2);
  for (const SampleStream& other :
       {SampleStream::forPixel(7, 3, 5, 42), SampleStream::forPixel(3, 7, 6, 42),
        SampleStream::forPixel(3, 7, 5, 43)}) {
    EXPECT_NE(other.get2D(2).x, p.x);
  }
  EXPECT_NE(a.get2D(3).x, p.x);
  // Sub-sample k of count is the point at sequence index index·count + k.
  const SampleStream sub(a.key(), 5 * 8 + 3);
  EXPECT_EQ(a.get2D(4, 8, 3).x, sub.get2D(4).x);
  EXPECT_EQ(a.get2D(4, 8, 3).y, sub.get2D(4).y);
  // Branch siblings share a new key and take consecutive indices.
  EXPECT_EQ(a.branch(2, 8, 3).key(), a.branch(2, 8, 4).key());
  EXPECT_NE(a.branch(2, 8, 3).key(), a.key());
  EXPECT_NE(a.branch(2, 8, 3).key(), a.branch(3, 8, 3).key());
  EXPECT_EQ(a.branch(2, 8, 3).index(), 43u);
}

TEST(Sampler, EveryPowerOfTwoPrefixAndBlockIsANet) {
  for (const std::uint64_t key : {0ULL, 1ULL, 0x123456789abcdefULL}) {
    for (int k = 0; k <= 10; ++k) {
      const std::uint32_t n = 1u << k;
      for (const std::uint32_t block : {0u, 3u}) {
        std::vector<Point2> points;
        for (std::uint32_t i = 0; i < n; ++i)
          points.push_back(scrambledSobol2D(block * n + i, key));
        EXPECT_TRUE(isZeroNet(points, k)) << "key " << key << ", 2^" << k << ", block " << block;
      }
    }
  }
}

TEST(Sampler, EveryPrefixHasLowDiscrepancy) {
  // Each axis is a scrambled (0,1)-sequence, whose star discrepancy obeys
  // n·D*(n) ≤ log2(n)/3 + 1 (Niederreiter); independent uniform points give n·D* ≈ 0.87·sqrt(n),
  // 14 at n = 256, far above the bound's 3.7.
  const SampleStream stream = SampleStream::forPixel(11, 4, 0, 9);
  std::vector<double> xs;
  std::vector<double> ys;
  for (std::uint32_t n = 1; n <= 256; ++n) {
    const Point2 p = SampleStream(stream.key(), n - 1).get2D(6);
    xs.push_back(p.x);
    ys.push_back(p.y);
    const double bound = std::log2(static_cast<double>(n)) / 3 + 1 + 1e-9;
    EXPECT_LE(n * starDiscrepancy1D(xs), bound) << n;
    EXPECT_LE(n * starDiscrepancy1D(ys), bound) << n;
  }
}

// Pearson correlation of two equally long series.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i] / n;
    mb += b[i] / n;
  }
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// Pearson's chi-square of points in [0,1)² against the uniform distribution on an 8 × 8 grid.
double chiSquare8x8(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> count(64, 0);
  for (std::size_t i = 0; i < a.size(); ++i) {
    count[static_cast<std::size_t>(a[i] * 8) * 8 + static_cast<std::size_t>(b[i] * 8)] += 1;
  }
  const double expected = static_cast<double>(a.size()) / 64;
  double chi2 = 0;
  for (const double c : count) chi2 += (c - expected) * (c - expected) / expected;
  return chi2;
}

TEST(Sampler, DimensionsAndPixelsAreDecorrelated) {
  // Pairs across dimensions of one pixel, and the same dimension of neighbouring pixels, must look
  // like independent uniform pairs. With 4096 pairs a correlation's standard deviation is 0.016,
  // and chi-square on 63 degrees of freedom has mean 63 and deviation 11. Unshuffled copies of one
  // sequence would put every pair on one curve (chi-square in the thousands).
  constexpr std::uint32_t kN = 4096;
  const SampleStream stream = SampleStream::forPixel(5, 9, 0, 0);
  std::vector<double> d0x, d0y, d1x, d5y;
  for (std::uint32_t i = 0; i < kN; ++i) {
    const SampleStream s(stream.key(), i);
    d0x.push_back(s.get2D(0).x);
    d0y.push_back(s.get2D(0).y);
    d1x.push_back(s.get2D(1).x);
    d5y.push_back(s.get2D(5).y);
  }
  EXPECT_LT(std::abs(correlation(d0x, d1x)), 0.07);
  EXPECT_LT(std::abs(correlation(d0y, d5y)), 0.07);
  EXPECT_LT(chiSquare8x8(d0x, d1x), 130);
  EXPECT_LT(chiSquare8x8(d0x, d5y), 130);
  // Within one dimension the two axes are one (0,2)-sequence: far more even than random.
  EXPECT_LT(chiSquare8x8(d0x, d0y), 1e-9);

  std::vector<double> here, right;
  for (std::uint32_t p = 0; p < kN; ++p) {
    here.push_back(SampleStream::forPixel(p % 64, p / 64, 0, 0).get2D(0).x);
    right.push_back(SampleStream::forPixel(p % 64 + 1, p / 64, 0, 0).get2D(0).x);
  }
  EXPECT_LT(std::abs(correlation(here, right)), 0.07);
  EXPECT_LT(chiSquare8x8(here, right), 130);
}

TEST(Sampler, PointsLieInTheUnitSquare) {
  for (std::uint32_t i = 0; i < 2000; ++i) {
    const Point2 p = SampleStream::forPixel(i, 2 * i, i, i).get2D(i % 7);
    EXPECT_GE(p.x, 0.0);
    EXPECT_LT(p.x, 1.0);
    EXPECT_GE(p.y, 0.0);
    EXPECT_LT(p.y, 1.0);
  }
}

}  // namespace
}  // namespace glint
