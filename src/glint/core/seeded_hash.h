// Hashes for the tables keyed by what an input file writes — duplicate keys, anchors, vertex
// text, positions — seeded once per process from the system's random source. With a fixed hash a
// file can be made of keys that all collide, or all land in a few slots (hash flooding): a few
// megabytes of chosen vertices or keys took minutes. No result depends on these tables' order
// (numbers follow first use; the one table iterated, meshBoundsVolume's edges, answers an
// all-of), so the seed changes no output, only which keys share a slot.
#pragma once

#include <cstdint>
#include <cstring>
#include <string_view>

namespace glint {

// Random per process (std::random_device), the same for every call unless a test sets another.
std::uint64_t processHashSeed() noexcept;
// Tests: the seed from now on (the same input must give the same results under any seed).
void setProcessHashSeedForTesting(std::uint64_t seed);

// splitmix64's finaliser: a bijection of 64-bit words whose every output bit depends on every
// input bit.
constexpr std::uint64_t mixBits(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Words folded in one at a time through mixBits from the seed: `state = mixBits(state ^ word)`.
class SeededHasher {
 public:
  explicit SeededHasher(std::uint64_t seed) noexcept : state_(seed) {}
  void add(std::uint64_t word) noexcept { state_ = mixBits(state_ ^ word); }
  void addBytes(std::string_view bytes) noexcept {
    std::size_t i = 0;
    for (; i + 8 <= bytes.size(); i += 8) {
      std::uint64_t word;
      std::memcpy(&word, bytes.data() + i, 8);
      add(word);
    }
    std::uint64_t tail = 0;
    if (i < bytes.size()) std::memcpy(&tail, bytes.data() + i, bytes.size() - i);
    add(tail ^ static_cast<std::uint64_t>(bytes.size()) << 56);
  }
  std::uint64_t value() const noexcept { return state_; }

 private:
  std::uint64_t state_;
};

// For std::unordered_map and set: strings (any of std::string, string_view; transparent) and
// 64-bit integers, seeded with processHashSeed().
struct SeededHash {
  using is_transparent = void;
  // noexcept: libstdc++'s tables then keep no hash code per node.
  std::size_t operator()(std::string_view text) const noexcept {
    SeededHasher h(processHashSeed());
    h.addBytes(text);
    return static_cast<std::size_t>(h.value());
  }
  std::size_t operator()(std::uint64_t value) const noexcept {
    return static_cast<std::size_t>(mixBits(value ^ processHashSeed()));
  }
};

}  // namespace glint
