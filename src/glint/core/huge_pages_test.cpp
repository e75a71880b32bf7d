// HugePageAllocator: large blocks are whole, aligned 2 MiB pages advised for huge pages; small
// ones are ordinary and keep their type's alignment; the arrays behave as vectors (the unzeroed
// ones too).
#include "glint/core/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <type_traits>

namespace glint {
namespace {

constexpr std::uintptr_t kHugePage = kHugePageBytes;

struct alignas(64) CacheLine {
  unsigned char bytes[64];
};

// The VmFlags line of the mapping of /proc/self/smaps that holds `address` ("" if none does).
std::string vmFlagsOf(const void* address) {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0;
    std::uintptr_t end = 0;
    char dash = 0;
    std::istringstream header(line);
    if (header >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

TEST(HugePageAllocator, LargeBlocksAreAlignedWholeHugePagesAdvisedForHugePages) {
  HugePageArray<std::uint32_t> values(3'000'000);  // 12 MB: six huge pages
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) % kHugePage, 0u);
  const std::string flags = vmFlagsOf(values.data());
  ASSERT_NE(flags, "") << "no mapping in /proc/self/smaps holds the block";
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;  // MADV_HUGEPAGE
  std::iota(values.begin(), values.end(), 0u);
  EXPECT_EQ(values[2'999'999], 2'999'999u);
}

TEST(HugePageAllocator, SmallBlocksKeepTheirTypesAlignment) {
  for (std::size_t n : {1, 3, 100, 1000}) {
    HugePageArray<CacheLine> lines(n);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(lines.data()) % alignof(CacheLine), 0u) << n;
  }
}

TEST(HugePageAllocator, ArraysGrowShrinkAndCopyAsVectors) {
  HugePageArray<std::uint64_t> grown;
  for (std::uint64_t i = 0; i < 600'000; ++i) grown.push_back(i * i);  // crosses 2 MiB
  HugePageArray<std::uint64_t> copy = grown;
  copy.resize(10);
  copy.shrink_to_fit();
  EXPECT_EQ(copy.capacity(), 10u);
  EXPECT_EQ(copy[9], 81u);
  EXPECT_EQ(grown.size(), 600'000u);
  EXPECT_EQ(grown[599'999], std::uint64_t{599'999} * 599'999);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(grown.data()) % kHugePage, 0u);
  EXPECT_THROW(grown.get_allocator().allocate(~std::size_t{0} / 4), std::bad_array_new_length);
}

// The build references' arrays: the same blocks (whole huge pages, advised), and the vector
// operations that construct from a value still do (only the size constructor and resize without a
// value leave elements unwritten, for the caller to fill).
TEST(HugePageAllocator, UnzeroedArraysAreHugePageArraysFilledByTheirUser) {
  static_assert(
      std::is_same_v<std::allocator_traits<UnzeroedHugePageAllocator<int>>::rebind_alloc<double>,
                     UnzeroedHugePageAllocator<double>>);
  UnzeroedHugePageArray<std::uint32_t> values(3'000'000);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) % kHugePage, 0u);
  EXPECT_NE(vmFlagsOf(values.data()).find(" hg"), std::string::npos);
  std::iota(values.begin(), values.end(), 0u);
  EXPECT_EQ(values[2'999'999], 2'999'999u);
  values.resize(3'000'010, 7u);
  EXPECT_EQ(values[3'000'000], 7u);
  EXPECT_EQ(values[3'000'009], 7u);
  values.push_back(11u);
  EXPECT_EQ(values.back(), 11u);
  const UnzeroedHugePageArray<std::uint32_t> copy = values;
  EXPECT_EQ(copy, values);
  UnzeroedHugePageArray<std::uint64_t> small(4, 5u);
  EXPECT_EQ(small, (UnzeroedHugePageArray<std::uint64_t>{5u, 5u, 5u, 5u}));
}

}  // namespace
}  // namespace glint
