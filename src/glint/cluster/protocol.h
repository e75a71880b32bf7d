// The messages between rank 0 and the other ranks of an MPI render (docs/distributed.md
// "Protocol"): their tags and their byte layouts, encoded and decoded without MPI.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "glint/job/checkpoint.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"

namespace glint::cluster {

// The MPI tag of each message. Every payload is little-endian; doubles travel as their IEEE-754
// bits, so a tile arrives with exactly the bits it was rendered with.
enum class Tag : int {
  Hello = 1,    // worker → 0, once loaded: RankIdentity
  Assign = 2,   // 0 → worker: tiles to render (the first one also means "the fingerprints agree")
  Tile = 3,     // worker → 0: a finished tile and its pixels
  Done = 4,     // 0 → worker: no more tiles; send the Report and finish
  Report = 5,   // worker → 0: RankReport, its last message
  Stop = 6,     // 0 → worker: stop at once and exit (StopOrder: refusal, failure, interrupt)
  Leaving = 7,  // worker → 0: it stops on its own (a signal, an error)
  Heartbeat = 8,  // either way, when nothing else was sent for a while: still alive
  // Never sent, the link's reports: a peer said nothing for longer than the timeout; a send to a
  // peer failed (its process or connection is gone).
  Silent = 100,
  Unreachable = 101,
};

// Bumped whenever a layout below changes; ranks of other versions are refused by the Hello check.
inline constexpr std::uint32_t kProtocolVersion = 2;

// A payload that does not decode: a bug or a rank of another build.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a rank loaded and will render, for the comparison that must find every rank alike.
struct RankIdentity {
  std::uint32_t protocol = kProtocolVersion;
  std::string version;  // glint's
  std::string host;
  int threads = 0;        // render threads of this rank
  std::string sceneFile;  // the path as given on its command line
  std::uint64_t sceneBytes = 0;
  std::uint64_t sceneHash = 0;  // FNV-1a 64 of the scene file's bytes
  std::uint64_t meshCount = 0;
  std::uint64_t meshHash = 0;  // FNV-1a 64 of every loaded mesh's geometry
  CheckpointSettings settings;
  // renderFingerprint: all of the above and whatever else a checkpoint compares (textures, …).
  std::uint64_t fingerprint = 0;
  std::string error;  // why this rank could not load the scene; empty when it did
};

// Tile indices in tileRegions(region, tileSize) order.
using TileList = std::vector<std::uint32_t>;

// A finished tile: its index and its pixels row by row (the region follows from the index).
struct TileResult {
  std::uint32_t tile = 0;
  std::vector<Color> pixels;
};

// A worker's figures for the summary, sent once its render has ended.
struct RankReport {
  std::uint64_t tiles = 0;  // rendered by it
  RayCounts rays;
  std::uint64_t samples = 0;  // camera samples that went into its tiles' pixels
  std::uint64_t nonFinite = 0;
  std::optional<PixelCoord> firstNonFinite;
  double renderSeconds = 0;  // wall time of its render
  double busySeconds = 0;    // thread-seconds spent rendering tiles
  double idleSeconds = 0;    // thread-seconds spent waiting for a tile
  std::uint64_t bytesSent = 0;
};

// Rank 0's order to stop: the exit status, and whether every rank ends with MPI_Finalize (all are
// alive and rank 0 finalizes too) or just exits (a rank is gone, or the launcher is ending the
// job).
struct StopOrder {
  int status = 0;
  bool finalize = false;
};

// A worker that stops by itself: the signal that stopped it (0: none) and why, for rank 0 to say.
struct Leaving {
  int signal = 0;
  std::string reason;
};

std::string encodeIdentity(const RankIdentity& identity);
RankIdentity decodeIdentity(std::string_view bytes);

std::string encodeTiles(const TileList& tiles);
TileList decodeTiles(std::string_view bytes);

// `tile` is the rectangle of tile index `index`; its pixels are copied out of `film`.
std::string encodeTile(std::uint32_t index, const PixelRegion& tile, const Film& film);
TileResult decodeTile(std::string_view bytes);

std::string encodeReport(const RankReport& report);
RankReport decodeReport(std::string_view bytes);

std::string encodeStop(const StopOrder& order);
StopOrder decodeStop(std::string_view bytes);

std::string encodeLeaving(const Leaving& leaving);
Leaving decodeLeaving(std::string_view bytes);

}  // namespace glint::cluster
