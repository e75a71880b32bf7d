#include "glint/core/seeded_hash.h"

#include <chrono>
#include <exception>
#include <random>

namespace glint {

std::uint64_t processHashSeed() {
  static const std::uint64_t seed = [] {
    try {
      std::random_device device;
      return static_cast<std::uint64_t>(device()) << 32 ^ device();
    } catch (const std::exception&) {
      // No random source: the clock still keeps the seed from being known ahead.
      return static_cast<std::uint64_t>(
          std::chrono::steady_clock::now().time_since_epoch().count());
    }
  }();
  return seed;
}

}  // namespace glint
