// Rank 0 of an MPI render (docs/distributed.md): checks that every rank loaded the same render,
// hands out tiles on request, renders with its own threads too, puts every tile into the film, and
// keeps each rank's figures for the summary.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "glint/cluster/protocol.h"
#include "glint/cluster/session.h"
#include "glint/render/film.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint::cluster {

// One rank's share of the render, for --stats.
struct RankFigures {
  int rank = 0;
  std::string host;
  int threads = 0;
  std::uint64_t tiles = 0;  // rendered by this rank
  RayCounts rays;
  double busySeconds = 0;  // thread-seconds rendering
  double idleSeconds = 0;  // thread-seconds waiting for a tile
  std::uint64_t bytesSent = 0;
};

struct ClusterFigures {
  std::vector<RankFigures> ranks;   // by rank; empty until the render ran
  std::uint64_t bytesReceived = 0;  // by rank 0: the tiles, reports, heartbeats
  std::uint64_t bytesSent = 0;      // by rank 0: tile assignments, orders, heartbeats
  std::uint64_t remoteTiles = 0;    // tiles that came from other ranks
  // Rank 0's coordination, CPU seconds: its main thread handling those tiles (decoding, copying
  // into the film, the checkpoint's copy, the next assignment); its link thread's polls that moved
  // messages (MPI calls); all its link thread's polls (heartbeats and idle polls too).
  double handlingSeconds = 0;
  double messagingSeconds = 0;
  double linkSeconds = 0;
  double renderSeconds = 0;  // wall time of the render step, for the link's share of a core
};

// Tiles each worker holds at once (rendering and queued): enough that a thread finishing a tile
// finds the next one queued while its result travels to rank 0 and the reply comes back.
int tilesInFlightPerWorker(int threads);

class Assembly;

class Coordinator {
 public:
  // `sceneFile`: rank 0's scene file (read again for the comparison); `threads`: its render
  // threads; `cancelSignal`: the signal that stopped the job (RenderJobSpec::cancelSignal), may be
  // null.
  Coordinator(Session& session, std::filesystem::path sceneFile, int threads,
              const std::atomic<int>* cancelSignal);

  // RenderJobSpec::renderStep. Throws JobError: BadInput when a rank differs or could not load
  // the scene (exit 2, naming the rank, its host and the difference), Failure when a rank is lost.
  void render(const Scene& scene, const RenderOptions& options, Film& film, RenderStats& stats);

  // Rank 0's side of the ending: every rank not yet finished is told to exit with `status`.
  // Whether the ending is orderly (Session::finish).
  bool release(int status);

  const ClusterFigures& figures() const { return figures_; }

 private:
  struct Worker {
    RankIdentity identity;
    bool greeted = false;   // its Hello arrived
    bool finished = false;  // its Report arrived, or it was told to stop
    RankReport report;
  };
  // A message while tiles are rendered; `failure` is set when it means the job cannot finish.
  void handleDuringRender(const Message& message, Assembly& assembly,
                          const std::atomic<bool>* cancel, std::string& failure,
                          std::uint64_t& remoteTiles);
  int interruptStatus() const;
  bool awaitHellos(const RankIdentity& mine, const std::atomic<bool>* cancel);
  void stopWorkers(const StopOrder& order);
  [[noreturn]] void failWith(const std::string& message);
  // decode(), or failWith naming `rank` when it throws ProtocolError.
  template <class Decode>
  auto readFrom(int rank, Decode decode);
  std::string describeRank(int rank) const;
  // Why a rank the link reported (Tag::Silent or Tag::Unreachable) is lost.
  std::string lostText(Tag tag) const;

  Session& session_;
  std::filesystem::path sceneFile_;
  int threads_;
  const std::atomic<int>* cancelSignal_;
  std::vector<Worker> workers_;  // by rank; [0] unused
  bool lost_ = false;            // a rank is gone or stopped answering
  bool interrupted_ = false;
  ClusterFigures figures_;
};

}  // namespace glint::cluster
