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

// Reserves room for n elements in `out` (empty, or not yet larger) and advises huge pages for the
// whole 2 MiB pages inside that room, before anything touches it. Below 4 MiB it does nothing.
template <typename T>
void reserveOnHugePages(std::vector<T>& out, std::size_t n) {
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  if (n * sizeof(T) < 2 * kHugePage) return;
  out.reserve(n);
  const auto begin = reinterpret_cast<std::uintptr_t>(out.data());
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + n * sizeof(T)) & ~(kHugePage - 1);
  if (last > first) {
    static_cast<void>(::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE));
  }
}

}  // namespace glint
