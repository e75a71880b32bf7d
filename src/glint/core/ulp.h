// One-ulp steps of finite floating-point values, for rounding bounds outward.
#pragma once

#include <bit>
#include <concepts>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace glint {

// The next representable value above x (toward +inf): std::nextafter(x, +inf) for x finite or
// −inf (which steps to the lowest finite value), without the library call (it runs per traversal
// and per spawned ray). −0 and +0 both step to the smallest subnormal; the largest finite value
// steps to +inf. Not for +inf or NaN (the bit step would make a NaN, or another NaN).
template <std::floating_point T>
T nextUp(T x) {
  using Bits = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  static_assert(sizeof(T) == sizeof(Bits));
  if (x == 0) return std::numeric_limits<T>::denorm_min();
  const auto bits = std::bit_cast<Bits>(x);
  return std::bit_cast<T>(x > 0 ? static_cast<Bits>(bits + 1) : static_cast<Bits>(bits - 1));
}

// The next representable value below x (toward −inf).
template <std::floating_point T>
T nextDown(T x) {
  return -nextUp(-x);
}

}  // namespace glint
