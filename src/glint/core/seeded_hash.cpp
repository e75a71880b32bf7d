#include "glint/core/seeded_hash.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <random>

namespace glint {
namespace {

std::uint64_t randomSeed() {
  try {
    std::random_device device;
    return static_cast<std::uint64_t>(device()) << 32 ^ device();
  } catch (const std::exception&) {
    // No random source: the clock still keeps the seed from being known ahead.
    return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  }
}

std::atomic<std::uint64_t>& seedStore() {
  static std::atomic<std::uint64_t> seed{randomSeed()};
  return seed;
}

}  // namespace

std::uint64_t processHashSeed() noexcept { return seedStore().load(std::memory_order_relaxed); }

void setProcessHashSeedForTesting(std::uint64_t seed) {
  seedStore().store(seed, std::memory_order_relaxed);
}

}  // namespace glint
