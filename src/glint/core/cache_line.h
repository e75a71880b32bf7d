// Heap memory that shares no cache line with any other allocation, for arrays one thread writes
// while others read their neighbours (false sharing). The scene (lights, materials) is read by
// every render thread, and the main thread's per-tile scratch comes from the same malloc arena: an
// array of hits written on every ray once landed on the light list's cache line, and the render
// time then depended on the heap's layout.
#pragma once

#include <cstddef>
#include <new>

namespace glint {

inline constexpr std::size_t kCacheLine = 64;  // bytes, x86-64

// An allocator whose blocks start on a cache line and fill whole lines.
template <typename T>
struct CacheLineAllocator {
  using value_type = T;
  CacheLineAllocator() = default;
  template <typename U>
  explicit CacheLineAllocator(const CacheLineAllocator<U>&) {}
  static std::size_t bytesFor(std::size_t n) {
    return (n * sizeof(T) + kCacheLine - 1) / kCacheLine * kCacheLine;
  }
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new (bytesFor(n), std::align_val_t{kCacheLine}));
  }
  // Unsized: clang declares the sized aligned delete only with -fsized-deallocation.
  void deallocate(T* p, std::size_t) { ::operator delete (p, std::align_val_t{kCacheLine}); }
  template <typename U>
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator<U>&) {
    return true;
  }
};

}  // namespace glint
