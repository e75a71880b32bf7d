// Transparent huge pages for large arrays: a hint to the kernel that an array about to be filled
// should be backed by 2 MiB pages, so that filling tens of megabytes costs a few page faults
// instead of one per 4 KiB (on the virtual machines measured, page faults dominated filling a
// film or a mesh's arrays). Only a hint: where the system has no huge pages nothing changes.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace glint {

// The size of a transparent huge page on x86-64.
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

// Advises huge pages for the whole 2 MiB pages inside [data, data + bytes), before anything
// touches them. Below 4 MiB it does nothing.
inline void adviseHugePages(void* data, std::size_t bytes) {
  if (bytes < 2 * kHugePageBytes) return;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHugePageBytes - 1);
  if (last > first) {
    static_cast<void>(::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE));
  }
}

// Reserves room for n elements in `out` (empty, or not yet larger) and, where that room is
// large, advises huge pages for the whole 2 MiB pages inside it (adviseHugePages).
template <typename T>
void reserveOnHugePages(std::vector<T>& out, std::size_t n) {
  out.reserve(n);
  adviseHugePages(out.data(), n * sizeof(T));
}

// n value-initialised elements on huge pages (reserveOnHugePages): the zeroing then costs a
// fault per 2 MiB, not per 4 KiB.
template <typename T>
std::vector<T> hugePageVector(std::size_t n) {
  std::vector<T> out;
  reserveOnHugePages(out, n);
  out.resize(n);
  return out;
}

// An allocator for arrays built and dropped in one go (BVH build references, tree nodes): blocks
// of at least one huge page are whole 2 MiB pages, aligned and advised (MADV_HUGEPAGE), so that
// every page of them can be a huge page — adviseHugePages on a malloc'd block only covers the
// whole huge pages that happen to lie inside it, none at all for most blocks of 2–4 MiB. Costs
// up to 2 MiB of rounding per large block; smaller blocks come from std::allocator.
template <typename T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <typename U>
  explicit HugePageAllocator(const HugePageAllocator<U>& /*other*/) noexcept {}

  T* allocate(std::size_t n) {
    constexpr auto kMaxBytes = static_cast<std::size_t>(std::numeric_limits<std::ptrdiff_t>::max());
    if (n > (kMaxBytes - kHugePageBytes) / sizeof(T)) {
      throw std::bad_array_new_length();
    }
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePageBytes) return std::allocator<T>().allocate(n);
    const std::size_t rounded = (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
    void* block = std::aligned_alloc(kHugePageBytes, rounded);
    if (block == nullptr) throw std::bad_alloc();
    static_cast<void>(::madvise(block, rounded, MADV_HUGEPAGE));
    return static_cast<T*>(block);
  }
  void deallocate(T* block, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePageBytes) {
      std::allocator<T>().deallocate(block, n);
    } else {
      std::free(block);
    }
  }
  template <typename U>
  bool operator==(const HugePageAllocator<U>& /*other*/) const noexcept {
    return true;
  }
};

template <typename T>
using HugePageArray = std::vector<T, HugePageAllocator<T>>;

// HugePageAllocator whose value-initialisation is default-initialisation: a vector's size
// constructor and resize leave trivial elements unwritten. For arrays that are sized, then filled
// in parallel, every element written before it is read: sized by a std::vector, they would be
// zeroed first on the calling thread alone, which takes every page fault there, serially (the
// build references of a mesh: 3.2 MB at 100k triangles, 32 MB at 1M, before the render's
// threads start), only for the fill to write them again.
template <typename T>
struct UnzeroedHugePageAllocator : HugePageAllocator<T> {
  UnzeroedHugePageAllocator() = default;
  template <typename U>
  explicit UnzeroedHugePageAllocator(const UnzeroedHugePageAllocator<U>& /*other*/) noexcept {}

  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using UnzeroedHugePageArray = std::vector<T, UnzeroedHugePageAllocator<T>>;

}  // namespace glint
