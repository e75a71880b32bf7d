#include "glint/cluster/coordinator.h"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "glint/cluster/rank_identity.h"
#include "glint/cluster/tile_feed.h"
#include "glint/cluster/tile_scheduler.h"
#include "glint/core/cancel.h"
#include "glint/job/checkpoint.h"
#include "glint/job/job_error.h"
#include "glint/job/job_steps.h"

namespace glint::cluster {
namespace {

using Clock = std::chrono::steady_clock;

// How long the main thread waits for a message before it looks at the cancel flag again.
constexpr std::chrono::milliseconds kPoll{20};

// Whether the cancel flag is set within `limit`.
bool awaitCancel(const std::atomic<bool>* cancel, std::chrono::milliseconds limit) {
  const Clock::time_point deadline = Clock::now() + limit;
  while (!isCancelled(cancel) && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return isCancelled(cancel);
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The CPU time of the calling thread: what coordination costs, whatever else shares the core.
double threadCpuSeconds() {
  timespec time{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &time);
  return static_cast<double>(time.tv_sec) + 1e-9 * static_cast<double>(time.tv_nsec);
}

}  // namespace

// The film being assembled and the tiles' bookkeeping, shared by rank 0's render threads (its own
// tiles) and its main thread (the other ranks' tiles). Every finished tile goes through finish(),
// one at a time, so the job's callbacks (checkpoint, progress) see one tile after another.
class Assembly {
 public:
  Assembly(const RenderOptions& options, Film& film, int ranks)
      : options_(options),
        film_(film),
        tiles_(tileRegions(film.region(), options.tileSize)),
        scheduler_(tiles_.size(), options.resumeFilm != nullptr ? options.resumeTiles : nullptr,
                   ranks),
        done_(scheduler_.finished()) {}

  const std::vector<PixelRegion>& tiles() const { return tiles_; }

  TileList assign(int rank, std::size_t count) {
    const std::lock_guard<std::mutex> lock(mutex_);
    return scheduler_.assign(rank, count);
  }

  // Rank `rank` finished `tile`: its pixels go into the film (null: rendered into it already),
  // then the job hears of it; `next` tiles are assigned to the same rank in its place. False, with
  // nothing changed, for a tile that was not that rank's or pixels of the wrong size.
  bool finish(int rank, std::uint32_t tile, const std::vector<Color>* pixels, std::size_t next,
              TileList& assigned) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (tile >= tiles_.size()) return false;
    const PixelRegion& t = tiles_[tile];
    if (pixels != nullptr && pixels->size() != static_cast<std::size_t>(t.width()) *
                                                   static_cast<std::size_t>(t.height()))
      return false;
    if (!scheduler_.finish(rank, tile)) return false;
    if (pixels != nullptr) {
      const PixelRegion& region = film_.region();
      std::size_t i = 0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) film_.at(x - region.x0, y - region.y0) = (*pixels)[i++];
    }
    ++done_;
    if (options_.tileFinished) options_.tileFinished(tile, film_, rank);
    if (options_.progress) options_.progress(done_, tiles_.size());
    assigned = scheduler_.assign(rank, next);
    return true;
  }

  bool allFinished() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return scheduler_.allFinished();
  }
  std::size_t finishedBy(int rank) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return scheduler_.finishedBy(rank);
  }

 private:
  const RenderOptions& options_;
  Film& film_;
  std::vector<PixelRegion> tiles_;
  mutable std::mutex mutex_;
  TileScheduler scheduler_;
  std::size_t done_;  // tiles finished, resumed ones included
};

// `threads` is what a rank's Hello says (up to 4096 from a real worker); clamped so that no Hello
// can overflow the count.
int tilesInFlightPerWorker(int threads) { return 2 * std::clamp(threads, 1, 1 << 20) + 1; }

Coordinator::Coordinator(Session& session, std::filesystem::path sceneFile, int threads,
                         const std::atomic<int>* cancelSignal)
    : session_(session),
      sceneFile_(std::move(sceneFile)),
      threads_(threads),
      cancelSignal_(cancelSignal),
      workers_(static_cast<std::size_t>(session.size())) {}

std::string Coordinator::describeRank(int rank) const {
  const std::string& host =
      rank == 0 ? session_.host() : workers_[static_cast<std::size_t>(rank)].identity.host;
  return host.empty() ? fmt::format("rank {}", rank) : fmt::format("rank {} on {}", rank, host);
}

std::string Coordinator::lostText(Tag tag) const {
  if (tag == Tag::Unreachable) return "cannot be reached (a message to it failed: it is gone)";
  return fmt::format(
      "sent nothing for {:g} s (it died, hangs or lost its network; "
      "GLINT_MPI_TIMEOUT sets this limit)",
      std::chrono::duration<double>(session_.timing().timeout).count());
}

void Coordinator::stopWorkers(const StopOrder& order) {
  for (int rank = 1; rank < session_.size(); ++rank) {
    Worker& worker = workers_[static_cast<std::size_t>(rank)];
    if (worker.finished) continue;
    session_.link().send(rank, Tag::Stop, encodeStop(order));
    session_.link().forget(rank);
    worker.finished = true;
  }
}

void Coordinator::failWith(const std::string& message) {
  lost_ = true;
  stopWorkers(StopOrder{1, false});
  throw JobError(JobFailure::Failure, message);
}

template <class Decode>
auto Coordinator::readFrom(int rank, Decode decode) {
  try {
    return decode();
  } catch (const ProtocolError& error) {
    // A message of the right tag but the wrong layout (a peer of another build that passed the
    // Hello, or damage): the run fails as for a lost rank — workers stopped, the rank named —
    // rather than the error leaving the coordinator past its clean-up.
    failWith(
        fmt::format("a message from {} could not be read: {}", describeRank(rank), error.what()));
  }
}

bool Coordinator::release(int status) {
  const bool orderly = !lost_ && !interrupted_;
  stopWorkers(StopOrder{status, orderly});
  // The orders must leave before MPI ends. A rank that does not take them is gone: after a failure
  // or a signal, with the launcher ending the job, that is not waited for long.
  const std::chrono::milliseconds limit =
      orderly ? session_.timing().timeout : std::chrono::milliseconds(1000);
  return session_.link().flush(limit) && orderly;
}

// Every other rank's Hello, compared with rank 0's identity. False when stopped by the cancel flag.
bool Coordinator::awaitHellos(const RankIdentity& mine, const std::atomic<bool>* cancel) {
  int waiting = session_.size() - 1;
  while (waiting > 0) {
    if (isCancelled(cancel)) return false;
    std::optional<Message> message = session_.link().receive(kPoll);
    if (!message) continue;
    const int rank = message->peer;
    Worker& worker = workers_[static_cast<std::size_t>(rank)];
    switch (message->tag) {
      case Tag::Hello: {
        if (worker.greeted) break;
        worker.identity = readFrom(rank, [&] { return decodeIdentity(message->bytes); });
        worker.greeted = true;
        --waiting;
        if (const std::optional<std::string> difference =
                identityDifference(mine, worker.identity)) {
          stopWorkers(StopOrder{2, true});
          throw JobError(JobFailure::BadInput,
                         fmt::format("{} does not render what {} renders: {}; every rank must load "
                                     "the same scene, meshes and textures with the same options "
                                     "and glint version",
                                     describeRank(rank), describeRank(0), *difference));
        }
        break;
      }
      case Tag::Leaving:
        failWith(fmt::format("{} stopped before rendering: {}", describeRank(rank),
                             readFrom(rank, [&] { return decodeLeaving(message->bytes); }).reason));
      case Tag::Silent:
      case Tag::Unreachable:
        failWith(fmt::format("{} {}", describeRank(rank), lostText(message->tag)));
      default:
        break;
    }
  }
  return true;
}

void Coordinator::handleDuringRender(const Message& message, Assembly& assembly,
                                     const std::atomic<bool>* cancel, std::string& failure,
                                     std::uint64_t& remoteTiles) {
  Link& link = session_.link();
  const int rank = message.peer;
  switch (message.tag) {
    case Tag::Tile: {
      const TileResult result = decodeTile(message.bytes);
      TileList next;
      if (!assembly.finish(rank, result.tile, &result.pixels, 1, next)) {
        failure = fmt::format("{} sent tile {}, which it was not rendering", describeRank(rank),
                              result.tile);
        return;
      }
      if (!next.empty()) link.send(rank, Tag::Assign, encodeTiles(next));
      ++remoteTiles;
      return;
    }
    case Tag::Leaving: {
      const Leaving leaving = decodeLeaving(message.bytes);
      // A launcher that stops the job signals every rank: this one's signal is probably on its way,
      // and then the job was interrupted rather than failed.
      if (leaving.signal != 0 && awaitCancel(cancel, std::chrono::milliseconds(500))) return;
      failure = fmt::format("{} stopped: {}", describeRank(rank), leaving.reason);
      return;
    }
    case Tag::Silent:
    case Tag::Unreachable:
      failure = fmt::format("{} {}", describeRank(rank), lostText(message.tag));
      return;
    default:
      return;
  }
}

int Coordinator::interruptStatus() const {
  const int signal = cancelSignal_ != nullptr ? cancelSignal_->load() : 0;
  return 128 + (signal != 0 ? signal : SIGINT);
}

void Coordinator::render(const Scene& scene, const RenderOptions& options, Film& film,
                         RenderStats& stats) {
  const Clock::time_point start = Clock::now();
  Link& link = session_.link();
  const int ranks = session_.size();

  RankIdentity mine;
  {
    const CheckpointSettings settings =
        checkpointSettingsFor(scene, film.region(), options.tileSize);
    const std::string bytes = fingerprintedSceneText(sceneFile_, scene);
    mine = identityOf(sceneFile_, bytes, scene, settings, threads_, session_.host());
  }
  if (!awaitHellos(mine, options.cancel)) {
    interrupted_ = true;
    stats.cancelled = true;
    return;
  }

  Assembly assembly(options, film, ranks);
  // Rank 0's own threads take tiles from this feed, refilled as each tile finishes.
  TileFeed feed;
  std::atomic<bool> stopLocal{false};
  RenderOptions local = options;
  local.progress = nullptr;
  local.tiles.reset();
  local.cancel = &stopLocal;
  local.nextTile = [&feed] { return feed.next(); };
  local.tileFinished = [&](std::size_t tile, const Film&, int) {
    TileList next;
    assembly.finish(0, static_cast<std::uint32_t>(tile), nullptr, 1, next);
    feed.push(next);
    if (next.empty() && assembly.allFinished()) feed.close();
  };

  for (int rank = 1; rank < ranks; ++rank) {
    const TileList tiles =
        assembly.assign(rank, static_cast<std::size_t>(tilesInFlightPerWorker(
                                  workers_[static_cast<std::size_t>(rank)].identity.threads)));
    link.send(rank, Tag::Assign, encodeTiles(tiles));
  }
  feed.push(assembly.assign(0, static_cast<std::size_t>(std::max(threads_, 1))));
  if (assembly.allFinished()) feed.close();

  RenderStats localStats;
  std::exception_ptr localError;
  std::atomic<bool> localEnded{false};
  const Clock::time_point localStart = Clock::now();
  double localSeconds = 0;
  std::thread localRender([&] {
    try {
      renderInto(scene, local, film, &localStats);
    } catch (...) {
      localError = std::current_exception();
    }
    localSeconds = secondsSince(localStart);
    localEnded = true;
  });
  // Ends rank 0's render: after the last tile (the threads take what is queued, nothing) or, with
  // `stop`, at once. Also when anything below throws.
  const auto endLocal = [&](bool stop) {
    if (!localRender.joinable()) return;
    if (stop) {
      stopLocal = true;
      feed.cancel();
    } else {
      feed.close();
    }
    localRender.join();
  };
  struct Joiner {
    const decltype(endLocal)& end;
    ~Joiner() { end(true); }
  } joiner{endLocal};

  // Tiles from the other ranks until every tile is in, a rank is lost, or the job is stopped.
  std::string failure;
  double handling = 0;
  std::uint64_t remoteTiles = 0;
  while (failure.empty()) {
    if (isCancelled(options.cancel)) {
      interrupted_ = true;
      break;
    }
    if (assembly.allFinished()) break;
    if (localEnded && localError) {
      try {
        std::rethrow_exception(localError);
      } catch (const std::exception& error) {
        failure = fmt::format("rendering on {} failed: {}", describeRank(0), error.what());
      }
      break;
    }
    std::optional<Message> message = link.receive(kPoll);
    if (!message) continue;
    const double handlingStart = threadCpuSeconds();
    const int rank = message->peer;
    try {
      handleDuringRender(*message, assembly, options.cancel, failure, remoteTiles);
    } catch (const std::exception& error) {
      failure =
          fmt::format("a message from {} could not be used: {}", describeRank(rank), error.what());
    }
    handling += threadCpuSeconds() - handlingStart;
  }
  // Interrupted by a signal: mpirun and srun signal every rank, each stops by itself.
  if (interrupted_) stopWorkers(StopOrder{interruptStatus(), false});
  if (!failure.empty()) stopWorkers(StopOrder{1, false});
  endLocal(interrupted_ || !failure.empty());
  if (!failure.empty()) {
    lost_ = true;
    throw JobError(JobFailure::Failure, failure);
  }
  if (localError) std::rethrow_exception(localError);

  stats = localStats;
  // Every tile is in: the other ranks report their figures and finish.
  if (!interrupted_) {
    for (int rank = 1; rank < ranks; ++rank) link.send(rank, Tag::Done, {});
    int reporting = ranks - 1;
    while (reporting > 0) {
      if (isCancelled(options.cancel)) {
        interrupted_ = true;
        stopWorkers(StopOrder{interruptStatus(), false});
        break;
      }
      std::optional<Message> message = link.receive(kPoll);
      if (!message) continue;
      Worker& worker = workers_[static_cast<std::size_t>(message->peer)];
      if (message->tag == Tag::Report && !worker.finished) {
        worker.report = readFrom(message->peer, [&] { return decodeReport(message->bytes); });
        worker.finished = true;
        link.forget(message->peer);
        --reporting;
      } else if (message->tag == Tag::Leaving) {
        failWith(fmt::format(
            "{} did not report after the last tile: {}", describeRank(message->peer),
            readFrom(message->peer, [&] { return decodeLeaving(message->bytes); }).reason));
      } else if (message->tag == Tag::Silent || message->tag == Tag::Unreachable) {
        failWith(fmt::format("{} did not report after the last tile: it {}",
                             describeRank(message->peer), lostText(message->tag)));
      }
    }
  }

  // The figures: rank 0's and every reported rank's, summed into the stats.
  figures_ = ClusterFigures{};
  const double localThreadSeconds = localSeconds * std::max(threads_, 1);
  figures_.ranks.push_back(RankFigures{0, session_.host(), threads_, assembly.finishedBy(0),
                                       localStats.rays,
                                       std::max(0.0, localThreadSeconds - feed.idleSeconds()),
                                       feed.idleSeconds(), link.counters().bytesSent});
  for (int rank = 1; rank < ranks; ++rank) {
    const Worker& worker = workers_[static_cast<std::size_t>(rank)];
    const RankReport& report = worker.report;
    figures_.ranks.push_back(RankFigures{rank, worker.identity.host, worker.identity.threads,
                                         report.tiles, report.rays, report.busySeconds,
                                         report.idleSeconds, report.bytesSent});
    stats.rays.camera += report.rays.camera;
    stats.rays.shadow += report.rays.shadow;
    stats.rays.reflection += report.rays.reflection;
    stats.rays.refraction += report.rays.refraction;
    stats.rays.indirect += report.rays.indirect;
    stats.samples += report.samples;
    stats.nonFinite += report.nonFinite;
    if (report.firstNonFinite &&
        (!stats.firstNonFinite || report.firstNonFinite->y < stats.firstNonFinite->y ||
         (report.firstNonFinite->y == stats.firstNonFinite->y &&
          report.firstNonFinite->x < stats.firstNonFinite->x)))
      stats.firstNonFinite = report.firstNonFinite;
  }
  const LinkCounters counters = link.counters();
  figures_.bytesReceived = counters.bytesReceived;
  figures_.bytesSent = counters.bytesSent;
  figures_.remoteTiles = remoteTiles;
  figures_.handlingSeconds = handling;
  figures_.messagingSeconds = counters.movingCpuSeconds;
  figures_.linkSeconds = counters.cpuSeconds;
  figures_.renderSeconds = secondsSince(start);
  stats.cancelled = stats.cancelled || interrupted_;
  stats.seconds = secondsSince(start);
}

}  // namespace glint::cluster
