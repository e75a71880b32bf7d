#include "glint/cluster/worker.h"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <optional>
#include <thread>
#include <utility>

#include "glint/cluster/protocol.h"
#include "glint/cluster/rank_identity.h"
#include "glint/cluster/tile_feed.h"
#include "glint/core/cancel.h"
#include "glint/job/job_error.h"
#include "glint/job/job_steps.h"

namespace glint::cluster {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::chrono::milliseconds kPoll{20};

struct LoadedRender {
  std::optional<Scene> scene;
  PixelRegion region;
  RankIdentity identity;
};

// Load, limits and build as the job does them on rank 0; a failure becomes identity.error, which
// rank 0 reports. Cancelled passes.
void loadRender(const RenderJobSpec& spec, int threads, const std::string& host,
                LoadedRender& loaded) {
  loaded.identity.host = host;
  loaded.identity.threads = threads;
  try {
    LoadedScene scene =
        loadSceneFile(spec.scene, LoadOptions{spec.memoryBudget, spec.overrides, spec.cancel});
    const ImageSettings& image = scene.parts.image;
    loaded.region = spec.crop.value_or(PixelRegion{0, 0, image.width, image.height});
    ImageSettings allocated = image;
    allocated.width = loaded.region.width();
    allocated.height = loaded.region.height();
    enforceImageLimits(allocated, spec.requestText, spec.memoryBudget);
    scene.parts.isa = spec.isa;  // --isa on every rank (a rank whose CPU lacks it reports so)
    loaded.scene.emplace(freezeScene(std::move(scene.parts), spec.scene.string()));
    const std::string bytes = fingerprintedSceneText(spec.scene, *loaded.scene);
    loaded.identity = identityOf(spec.scene, bytes, *loaded.scene,
                                 checkpointSettingsFor(*loaded.scene, loaded.region, spec.tileSize),
                                 threads, host);
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception& error) {
    loaded.scene.reset();
    loaded.identity.error = error.what();
  }
}

// This rank's render: the tiles from the feed on its own thread, each sent to rank 0 when done.
class TileRender {
 public:
  TileRender(const Scene& scene, const RenderJobSpec& spec, const PixelRegion& region, Link& link)
      : scene_(scene),
        film_(scene.image().width, scene.image().height, region),
        tiles_(tileRegions(region, spec.tileSize)) {
    options_.threads = spec.threads;
    options_.crop = spec.crop;
    options_.tileSize = spec.tileSize;
    options_.cancel = &stop_;
    options_.nextTile = [this] { return feed_.next(); };
    options_.tileFinished = [this, &link](std::size_t tile, const Film& film, int) {
      link.send(0, Tag::Tile, encodeTile(static_cast<std::uint32_t>(tile), tiles_[tile], film));
      ++tilesDone_;
    };
  }
  ~TileRender() { end(true); }
  TileRender(const TileRender&) = delete;
  TileRender& operator=(const TileRender&) = delete;

  void add(const TileList& tiles) {
    if (!thread_.joinable()) {
      start_ = Clock::now();
      thread_ = std::thread([this] {
        try {
          renderInto(scene_, options_, film_, &stats_);
        } catch (...) {
          error_ = std::current_exception();
        }
        seconds_ = std::chrono::duration<double>(Clock::now() - start_).count();
        ended_ = true;
      });
    }
    feed_.push(tiles);
  }
  // Ends the render: after the queued tiles, or with `stop` at once. Rethrows its failure.
  void end(bool stop) {
    if (stop) {
      stop_ = true;
      feed_.cancel();
    } else {
      feed_.close();
    }
    if (thread_.joinable()) thread_.join();
  }
  bool failed() const { return ended_ && error_ != nullptr; }
  std::string failure() const {
    try {
      std::rethrow_exception(error_);
    } catch (const std::exception& error) {
      return error.what();
    } catch (...) {
      return "an unknown error";
    }
  }

  RankReport report(int threads, std::uint64_t bytesSent) const {
    RankReport report;
    report.tiles = tilesDone_;
    report.rays = stats_.rays;
    report.samples = stats_.samples;
    report.nonFinite = stats_.nonFinite;
    report.firstNonFinite = stats_.firstNonFinite;
    report.renderSeconds = seconds_;
    report.idleSeconds = feed_.idleSeconds();
    report.busySeconds = std::max(0.0, seconds_ * threads - report.idleSeconds);
    report.bytesSent = bytesSent;
    return report;
  }

 private:
  const Scene& scene_;
  Film film_;
  std::vector<PixelRegion> tiles_;
  RenderOptions options_;
  TileFeed feed_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> ended_{false};
  std::exception_ptr error_;
  std::thread thread_;
  Clock::time_point start_;
  double seconds_ = 0;
  RenderStats stats_;
  std::uint64_t tilesDone_ = 0;  // touched by the renderer's serialised tileFinished only
};

int signalStatus(const RenderJobSpec& spec) {
  const int signal = spec.cancelSignal != nullptr ? spec.cancelSignal->load() : 0;
  return 128 + (signal != 0 ? signal : 2);
}

}  // namespace

int serveTiles(Session& session, const RenderJobSpec& spec) {
  std::optional<tbb::global_control> parallelism;
  if (spec.threads > 0)
    parallelism.emplace(tbb::global_control::max_allowed_parallelism,
                        static_cast<std::size_t>(spec.threads));
  Link& link = session.link();
  const auto leave = [&](const Leaving& leaving, int status) {
    link.send(0, Tag::Leaving, encodeLeaving(leaving));
    link.flush(std::chrono::seconds(1));
    return session.finish(status, false);
  };
  const auto stopped = [&]() {
    const int signal = spec.cancelSignal != nullptr ? spec.cancelSignal->load() : 0;
    return leave(Leaving{signal, fmt::format("rank {} on {} was interrupted", session.rank(),
                                             session.host())},
                 signalStatus(spec));
  };

  // While the scene loads, a watcher reads the link: rank 0 may stop the job meanwhile (its own
  // error, found before the render, or a lost rank), and a large scene's load must not keep it
  // waiting in MPI_Finalize for minutes. A message cancels the load and is handled below; so does
  // a stop signal.
  LoadedRender loaded;
  std::optional<Message> early;
  {
    std::atomic<bool> loadCancel{false};
    std::atomic<bool> loading{true};
    std::thread watcher([&]() {
      while (loading.load()) {
        if (isCancelled(spec.cancel)) loadCancel.store(true);
        if (std::optional<Message> message = link.receive(kPoll)) {
          early = std::move(message);
          loadCancel.store(true);
          return;
        }
      }
    });
    RenderJobSpec loadSpec = spec;
    loadSpec.cancel = &loadCancel;
    bool cancelled = false;
    try {
      loadRender(loadSpec, spec.threads, session.host(), loaded);
    } catch (const Cancelled&) {
      cancelled = true;
    }
    loading.store(false);
    watcher.join();
    if (cancelled && !early) return stopped();
  }
  if (!early) link.send(0, Tag::Hello, encodeIdentity(loaded.identity));

  std::optional<TileRender> render;
  for (;;) {
    if (isCancelled(spec.cancel)) {
      if (render) render->end(true);
      return stopped();
    }
    if (render && render->failed()) {
      const std::string reason = render->failure();
      return leave(Leaving{0, fmt::format("rendering failed: {}", reason)}, 1);
    }
    std::optional<Message> message =
        early ? std::exchange(early, std::nullopt) : link.receive(kPoll);
    if (!message) continue;
    switch (message->tag) {
      case Tag::Assign:
        // Rank 0 assigns tiles only once every rank's identity agreed with its own.
        if (!loaded.scene) break;
        if (!render) render.emplace(*loaded.scene, spec, loaded.region, link);
        try {
          render->add(decodeTiles(message->bytes));
        } catch (const ProtocolError& error) {
          // A damaged or foreign Assign: rank 0 hears why, as for a failed render.
          render->end(true);
          return leave(
              Leaving{0, fmt::format("a tile assignment could not be read: {}", error.what())}, 1);
        }
        break;
      case Tag::Done: {
        if (render) render->end(false);
        if (render && render->failed())
          return leave(Leaving{0, fmt::format("rendering failed: {}", render->failure())}, 1);
        const RankReport report =
            render ? render->report(spec.threads, link.counters().bytesSent) : RankReport{};
        link.send(0, Tag::Report, encodeReport(report));
        const bool sent = link.flush(session.timing().timeout);
        link.forget(0);
        return session.finish(sent ? 0 : 1, sent);
      }
      case Tag::Stop: {
        // An unreadable Stop still stops this rank, as an unorderly one with status 1.
        StopOrder order{1, false};
        try {
          order = decodeStop(message->bytes);
        } catch (const ProtocolError&) {
        }
        if (render) render->end(true);
        // An orderly stop (a refused rank, rank 0's own error) ends every rank with MPI_Finalize;
        // rank 0's status is the job's. A non-zero status here would make mpirun abort the job
        // while rank 0 is still finalizing, and keep it waiting.
        return session.finish(order.finalize ? 0 : order.status, order.finalize);
      }
      case Tag::Silent:
      case Tag::Unreachable:
        if (render) render->end(true);
        std::fprintf(
            stderr, "glint: error: rank %d on %s: rank 0 %s; stopping\n", session.rank(),
            session.host().c_str(),
            message->tag == Tag::Unreachable
                ? "cannot be reached"
                : fmt::format("sent nothing for {:g} s",
                              std::chrono::duration<double>(session.timing().timeout).count())
                      .c_str());
        return session.finish(1, false);
      default:
        break;
    }
  }
}

}  // namespace glint::cluster
