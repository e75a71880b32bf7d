// libFuzzer target: glint::decodeCheckpoint, the reader of `glint render --resume FILE` files, and
// glint::checkpointSizeLimit, which bounds how much of such a file is read. The input is decoded
// twice: as it is, and with its correct FNV-1a checksum appended — a checksum the fuzzer would
// almost never guess, so that the layout behind it (settings, tile count, bitmap, pixels) is
// reached. Any bytes give a checkpoint or a CheckpointError; a decoded checkpoint must encode to
// bytes that decode to the same checkpoint, and a size limit must cover the input it came from
// when that input decodes. Anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "glint/job/checkpoint.h"

namespace {

// A film budget far below the default (half the machine's memory), so that a header claiming a
// large region is refused for its budget rather than allocated.
constexpr std::uint64_t kBudget = 64ull << 20;

void decodeAndCheck(const std::string& bytes) {
  glint::Checkpoint checkpoint;
  try {
    checkpoint = glint::decodeCheckpoint(bytes, "fuzz.ckpt", kBudget);
  } catch (const glint::CheckpointError&) {
    return;
  }
  const std::optional<std::uint64_t> limit = glint::checkpointSizeLimit(bytes);
  if (!limit || *limit < bytes.size()) std::abort();
  // Re-encoding is canonical (unused bitmap bits become 0): its decoding encodes the same.
  const std::string encoded = glint::encodeCheckpoint(checkpoint);
  const glint::Checkpoint again = glint::decodeCheckpoint(encoded, "again.ckpt", kBudget);
  // Settings compared as bytes: the decoder leaves values to the resuming render's comparison, so
  // a NaN threshold decodes (and then matches no render), and NaN != NaN.
  if (glint::encodeCheckpoint(again) != encoded ||
      glint::encodeCheckpointSettings(again.settings) !=
          glint::encodeCheckpointSettings(checkpoint.settings) ||
      again.fingerprint != checkpoint.fingerprint || again.tiles != checkpoint.tiles) {
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  (void)glint::checkpointSizeLimit(bytes);
  decodeAndCheck(bytes);
  std::string sealed = bytes;
  std::uint64_t sum = glint::fnv1a64(bytes);
  for (int i = 0; i < 8; ++i, sum >>= 8) sealed.push_back(static_cast<char>(sum & 0xff));
  decodeAndCheck(sealed);
  return 0;
}
