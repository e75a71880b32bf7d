// How an MPI render of one 4K frame scales to 8, 64 and 512 ranks (issue 17, docs/benchmarks.md
// "One frame across ranks"): a discrete-event simulation of glint's master/worker protocol
// (src/glint/cluster/) fed by measured tile times and measured costs of rank 0.
//
//   cluster_simulation [--scene FILE] [--measure-width W] [--tile-times CSV]
//                      [--handling-us H] [--per-byte-ns B] [--mpi-us M] [--latency-us L]
//                      [--gbytes-per-s G] [--work-scale K] [--fixed-seconds F]
//
// Tile times: the scene is rendered once on one thread at W×(W·9/16) (default 1280×720) in 16×16
// tiles, each tile's CPU time measured (cached in --tile-times). A pixel's cost does not depend on
// the resolution (the same rays per sample over the same surfaces), so a 16×16 tile of the
// 3840×2160 frame costs what the measured tile covering the same place costs: the 4K frame's tiles
// repeat each measured tile 3×3 times. --work-scale multiplies every tile time (16: a frame at 16
// times the samples).
//
// The model of one frame (every event in simulated time):
//   - every rank has T render threads; rank 0's take tiles straight from the scheduler, the other
//     ranks' from their queue, which rank 0 keeps at 2T + 1 tiles (tilesInFlightPerWorker);
//   - a finished tile of another rank travels to rank 0 (latency + bytes / bandwidth), queues at
//     rank 0's network link (bytes / bandwidth, one after another), then at rank 0's link thread
//     (M µs, one after another: the MPI calls that receive it), then at rank 0's main thread
//     (H µs + B ns per byte over a 16×16 tile's bytes, one after another: decoding, copying into
//     the film and the checkpoint, the next assignment), which sends the next tile back (latency);
//   - the frame ends when the last tile is handled; F seconds of fixed cost per frame (MPI start,
//     loading and building the scene on every rank at once, writing the image) come on top.
// Efficiency = the tiles' total time / (ranks × T × the frame's time): 1 when every thread of every
// rank renders all the time. Rank 0's main and link threads are not counted among the T: the model
// lets them run beside its render threads (on a node with T cores they take cores from them once
// they are busy).
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numeric>
#include <queue>
#include <sstream>
#include <string>
#include <vector>

#include "glint/factories/scene_loader.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace {

using glint::PixelRegion;

constexpr int kFrameWidth = 3840;
constexpr int kFrameHeight = 2160;
constexpr int kMeasuredTile = 16;

struct Settings {
  std::string scene = GLINT_SHOWCASE_PATH;
  int measureWidth = 1280;
  std::string tileTimes = GLINT_BENCH_CACHE_DIR "/showcase_tile_times.csv";
  // Rank 0's CPU per 16×16 tile from another rank, as glint render --stats reports it under
  // mpirun (docs/benchmarks.md): its main thread's handling, and its link thread's MPI calls.
  double handlingMicros = 12;
  double perByteNanos = 0.5;  // handling that grows past a 16×16 tile's bytes: copies of the tile
  double mpiMicros = 25;
  double latencyMicros = 30;        // one way, between two nodes
  double gigabytesPerSecond = 1.1;  // each node's network link (10 GbE)
  double workScale = 1;
  double fixedSeconds = 3;  // per frame: MPI start, load and build, write (measured; see docs)
};

// Tile times of the measured render, in seconds, row-major over its 16×16 tiles.
struct MeasuredTiles {
  int columns = 0;
  int rows = 0;
  std::vector<double> seconds;
};

double threadCpuSeconds() {
  timespec time{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &time);
  return static_cast<double>(time.tv_sec) + 1e-9 * static_cast<double>(time.tv_nsec);
}

MeasuredTiles measureTiles(const Settings& settings) {
  MeasuredTiles measured;
  {
    std::ifstream cached(settings.tileTimes);
    if (cached >> measured.columns >> measured.rows) {
      double t = 0;
      while (cached >> t) measured.seconds.push_back(t);
      if (measured.seconds.size() == static_cast<std::size_t>(measured.columns) * measured.rows &&
          measured.columns * kMeasuredTile >= settings.measureWidth)
        return measured;
    }
  }
  glint::LoadOptions load;
  load.overrides.width = settings.measureWidth;
  load.overrides.height = settings.measureWidth * 9 / 16;
  const glint::Scene scene(glint::loadScene(settings.scene, load).parts);
  const PixelRegion region{0, 0, scene.image().width, scene.image().height};
  const std::vector<PixelRegion> tiles = glint::tileRegions(region, kMeasuredTile);
  measured.columns = (region.width() + kMeasuredTile - 1) / kMeasuredTile;
  measured.rows = (region.height() + kMeasuredTile - 1) / kMeasuredTile;
  measured.seconds.assign(tiles.size(), 0);
  std::fprintf(stderr, "measuring %zu tiles of %s at %dx%d on one thread...\n", tiles.size(),
               settings.scene.c_str(), region.width(), region.height());
  // One thread (this one: a one-thread arena runs on its caller) renders the tiles in order, so
  // its CPU time between two finished tiles is a tile's, however busy the machine is.
  glint::RenderOptions options;
  options.threads = 1;
  options.tileSize = kMeasuredTile;
  double last = threadCpuSeconds();
  options.tileFinished = [&](std::size_t tile, const glint::Film&, int) {
    const double now = threadCpuSeconds();
    measured.seconds[tile] = now - last;
    last = now;
  };
  glint::render(scene, options);
  std::ofstream out(settings.tileTimes);
  out << measured.columns << " " << measured.rows << "\n";
  for (const double t : measured.seconds) out << t << "\n";
  return measured;
}

// The 4K frame's tiles of `side` pixels: their times and sizes in bytes on the wire.
struct FrameTiles {
  std::vector<double> seconds;
  std::vector<double> bytes;
};

FrameTiles frameTiles(const MeasuredTiles& measured, int side, double workScale) {
  FrameTiles frame;
  // 4K pixels per measured pixel, along each axis.
  const int scale = std::max(1, kFrameWidth / (measured.columns * kMeasuredTile));
  for (int y0 = 0; y0 < kFrameHeight; y0 += side) {
    for (int x0 = 0; x0 < kFrameWidth; x0 += side) {
      const int x1 = std::min(x0 + side, kFrameWidth);
      const int y1 = std::min(y0 + side, kFrameHeight);
      double seconds = 0;
      // Every 16×16 block of the tile costs the measured tile at the same place in the image.
      for (int by = y0; by < y1; by += kMeasuredTile) {
        for (int bx = x0; bx < x1; bx += kMeasuredTile) {
          const int column = std::min(bx / kMeasuredTile / scale, measured.columns - 1);
          const int row = std::min(by / kMeasuredTile / scale, measured.rows - 1);
          const double pixels = static_cast<double>(std::min(bx + kMeasuredTile, x1) - bx) *
                                (std::min(by + kMeasuredTile, y1) - by);
          seconds += measured.seconds[static_cast<std::size_t>(row * measured.columns + column)] *
                     pixels / (kMeasuredTile * kMeasuredTile);
        }
      }
      frame.seconds.push_back(seconds * workScale);
      frame.bytes.push_back(12.0 + 24.0 * (x1 - x0) * (y1 - y0));
    }
  }
  return frame;
}

struct Cluster {
  int ranks = 1;
  int threads = 1;  // per rank
};

struct Outcome {
  double seconds = 0;     // the frame's render phase
  double efficiency = 0;  // of the render phase
  double rank0Busy = 0;   // fraction of the render phase rank 0's main thread was handling tiles
  double mpiBusy = 0;     // ... its link thread was receiving them
  double linkBusy = 0;    // ... its network link was receiving
};

// One frame under the model in the header.
Outcome simulate(const FrameTiles& frame, const Cluster& cluster, const Settings& settings) {
  struct Event {
    double time;
    int kind;  // 0 thread of a rank finished a tile, 1 tile reached rank 0, 2 assignment arrived
    int rank;
    std::size_t tile;
    bool operator>(const Event& other) const { return time > other.time; }
  };
  std::priority_queue<Event, std::vector<Event>, std::greater<>> events;
  const double latency = settings.latencyMicros * 1e-6;
  const double bandwidth = settings.gigabytesPerSecond * 1e9;
  const std::size_t depth = static_cast<std::size_t>(2 * cluster.threads + 1);
  std::size_t next = 0;
  std::vector<std::vector<std::size_t>> queues(static_cast<std::size_t>(cluster.ranks));
  std::vector<int> idle(static_cast<std::size_t>(cluster.ranks), cluster.threads);
  double linkFree = 0, mpiFree = 0, handlerFree = 0, handling = 0, mpi = 0, receiving = 0, end = 0;
  const double tileBytes16 = 12.0 + 24.0 * kMeasuredTile * kMeasuredTile;
  std::size_t finished = 0;

  const auto start = [&](int rank, double now) {
    auto& queue = queues[static_cast<std::size_t>(rank)];
    while (idle[static_cast<std::size_t>(rank)] > 0) {
      std::size_t tile = 0;
      if (rank == 0) {
        if (next >= frame.seconds.size()) return;
        tile = next++;
      } else {
        if (queue.empty()) return;
        tile = queue.front();
        queue.erase(queue.begin());
      }
      --idle[static_cast<std::size_t>(rank)];
      events.push(Event{now + frame.seconds[tile], 0, rank, tile});
    }
  };
  for (int rank = 1; rank < cluster.ranks; ++rank) {
    for (std::size_t k = 0; k < depth && next < frame.seconds.size(); ++k)
      events.push(Event{latency, 2, rank, next++});
  }
  start(0, 0);
  while (!events.empty()) {
    const Event event = events.top();
    events.pop();
    const auto r = static_cast<std::size_t>(event.rank);
    switch (event.kind) {
      case 0:
        ++idle[r];
        if (event.rank == 0) {
          ++finished;
          end = std::max(end, event.time);
        } else {
          // Travels to rank 0, then queues at its link.
          const double arrival = event.time + latency + frame.bytes[event.tile] / bandwidth;
          events.push(Event{arrival, 1, event.rank, event.tile});
        }
        start(event.rank, event.time);
        break;
      case 1: {
        const double size = frame.bytes[event.tile];
        const double received = std::max(linkFree, event.time) + size / bandwidth;
        receiving += size / bandwidth;
        linkFree = received;
        const double taken = std::max(mpiFree, received) + settings.mpiMicros * 1e-6;
        mpi += settings.mpiMicros * 1e-6;
        mpiFree = taken;
        const double cost =
            (settings.handlingMicros + settings.perByteNanos * 1e-3 * (size - tileBytes16)) * 1e-6;
        const double handled = std::max(handlerFree, taken) + cost;
        handling += cost;
        handlerFree = handled;
        ++finished;
        end = std::max(end, handled);
        if (next < frame.seconds.size())
          events.push(Event{handled + latency, 2, event.rank, next++});
        break;
      }
      case 2:
        queues[r].push_back(event.tile);
        start(event.rank, event.time);
        break;
      default:
        break;
    }
  }
  Outcome outcome;
  outcome.seconds = end;
  const double work = std::accumulate(frame.seconds.begin(), frame.seconds.end(), 0.0);
  outcome.efficiency = work / (static_cast<double>(cluster.ranks) * cluster.threads * end);
  outcome.rank0Busy = handling / end;
  outcome.mpiBusy = mpi / end;
  outcome.linkBusy = receiving / end;
  if (finished != frame.seconds.size()) std::fprintf(stderr, "simulation lost tiles\n");
  return outcome;
}

double number(const char* text, const char* option) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(value >= 0)) {
    std::fprintf(stderr, "cluster_simulation: %s expects a number >= 0, got '%s'\n", option, text);
    std::exit(2);
  }
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string option = argv[i];
    const char* value = argv[i + 1];
    if (option == "--scene")
      settings.scene = value;
    else if (option == "--measure-width")
      settings.measureWidth = static_cast<int>(number(value, argv[i]));
    else if (option == "--tile-times")
      settings.tileTimes = value;
    else if (option == "--handling-us")
      settings.handlingMicros = number(value, argv[i]);
    else if (option == "--per-byte-ns")
      settings.perByteNanos = number(value, argv[i]);
    else if (option == "--mpi-us")
      settings.mpiMicros = number(value, argv[i]);
    else if (option == "--latency-us")
      settings.latencyMicros = number(value, argv[i]);
    else if (option == "--gbytes-per-s")
      settings.gigabytesPerSecond = number(value, argv[i]);
    else if (option == "--work-scale")
      settings.workScale = number(value, argv[i]);
    else if (option == "--fixed-seconds")
      settings.fixedSeconds = number(value, argv[i]);
    else {
      std::fprintf(stderr, "cluster_simulation: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  const MeasuredTiles measured = measureTiles(settings);
  const double measuredTotal =
      std::accumulate(measured.seconds.begin(), measured.seconds.end(), 0.0);
  std::printf("# One 4K frame over MPI ranks: simulated (bench/cluster_simulation.cpp)\n\n");
  std::printf(
      "measured: %s at %dx%d, %zu tiles of 16x16 on one thread, %.2f s in all (mean %.2f "
      "ms per tile)\n",
      settings.scene.c_str(), measured.columns * kMeasuredTile, measured.rows * kMeasuredTile,
      measured.seconds.size(), measuredTotal,
      1e3 * measuredTotal / static_cast<double>(measured.seconds.size()));
  std::printf(
      "rank 0 per tile from another rank: %.1f us handling + %.2f ns per byte past 16x16, %.1f us "
      "in MPI; network: %.0f us latency, %.2f GB/s per node; work x%.0f; fixed %.1f s per "
      "frame\n\n",
      settings.handlingMicros, settings.perByteNanos, settings.mpiMicros, settings.latencyMicros,
      settings.gigabytesPerSecond, settings.workScale, settings.fixedSeconds);
  for (const int threads : {1, 16}) {
    std::printf("%d render thread%s per rank\n\n", threads, threads == 1 ? "" : "s");
    std::printf(
        "| tiles | ranks | frame work (s) | render (s) | efficiency | with fixed cost | rank 0 "
        "main thread busy | rank 0 link thread busy | rank 0 network busy |\n"
        "|---|---|---|---|---|---|---|---|---|\n");
    for (const int side : {16, 32, 64}) {
      const FrameTiles frame = frameTiles(measured, side, settings.workScale);
      const double work = std::accumulate(frame.seconds.begin(), frame.seconds.end(), 0.0);
      for (const int ranks : {8, 64, 512}) {
        const Outcome outcome = simulate(frame, Cluster{ranks, threads}, settings);
        const double withFixed = work / (static_cast<double>(ranks) * threads *
                                         (outcome.seconds + settings.fixedSeconds));
        std::printf("| %dx%d | %d | %.0f | %.3f | %.0f%% | %.0f%% | %.0f%% | %.0f%% | %.0f%% |\n",
                    side, side, ranks, work, outcome.seconds, 100 * outcome.efficiency,
                    100 * withFixed, 100 * outcome.rank0Busy, 100 * outcome.mpiBusy,
                    100 * outcome.linkBusy);
      }
    }
    // Where rank 0 saturates: the smallest rank count at which one of its serial stages (main
    // thread, link thread, network link) is busy 90% of the render, and which one.
    std::printf("\n");
    for (const int side : {16, 32, 64}) {
      const FrameTiles frame = frameTiles(measured, side, settings.workScale);
      int saturated = 0;
      const char* stage = "";
      for (int ranks = 2; ranks <= 8192 && saturated == 0; ranks = ranks * 9 / 8 + 1) {
        const Outcome outcome = simulate(frame, Cluster{ranks, threads}, settings);
        const double busiest = std::max({outcome.rank0Busy, outcome.mpiBusy, outcome.linkBusy});
        if (busiest < 0.9) continue;
        saturated = ranks;
        stage = busiest == outcome.rank0Busy ? "main thread"
                : busiest == outcome.mpiBusy ? "link thread (MPI calls)"
                                             : "network link";
      }
      if (saturated > 0)
        std::printf("%dx%d tiles: rank 0's %s is busy >= 90%% of the render from about %d ranks\n",
                    side, side, stage, saturated);
      else
        std::printf("%dx%d tiles: rank 0 stays below 90%% busy up to 8192 ranks\n", side, side);
    }
    std::printf("\n");
  }
  return 0;
}
