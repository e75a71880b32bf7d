// Transparent huge pages for large arrays: a hint to the kernel that an array about to be filled
// should be backed by 2 MiB pages, so that filling tens of megabytes costs a few page faults
// instead of one per 4 KiB (on the virtual machines measured, page faults dominated filling a
// film or a mesh's arrays). Only a hint: where the system has no huge pages nothing changes.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glint {

// Advises huge pages for the whole 2 MiB pages inside [data, data + bytes), before anything
// touches them. Below 4 MiB it does nothing.
inline void adviseHugePages(void* data, std::size_t bytes) {
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  if (bytes < 2 * kHugePage) return;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHugePage - 1);
  if (last > first) {
    static_cast<void>(::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE));
  }
}

// Reserves room for n elements in `out` (empty, or not yet larger) and advises huge pages for the
// whole 2 MiB pages inside that room (adviseHugePages).
template <typename T>
void reserveOnHugePages(std::vector<T>& out, std::size_t n) {
  if (n * sizeof(T) < (std::size_t{4} << 20)) return;
  out.reserve(n);
  adviseHugePages(out.data(), n * sizeof(T));
}

}  // namespace glint
