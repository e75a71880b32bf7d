#include "glint/cli/cluster_summary.h"

#include <fmt/format.h>

#include <algorithm>

#include "glint/cli/progress_reporter.h"

namespace glint::cli {
namespace {

std::string bytesText(std::uint64_t bytes) {
  if (bytes < 10 * 1024) return fmt::format("{} B", bytes);
  if (bytes < 10 * 1024 * 1024) return fmt::format("{:.1f} KiB", static_cast<double>(bytes) / 1024);
  return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
}

}  // namespace

std::string clusterStatsText(const cluster::ClusterFigures& figures) {
  if (figures.ranks.empty()) return {};
  std::string text = fmt::format("glint: ranks: {}\n", figures.ranks.size());
  for (const cluster::RankFigures& rank : figures.ranks) {
    const double total = rank.busySeconds + rank.idleSeconds;
    text += fmt::format(
        "glint:   rank {} on {} ({} {}): {} tiles, {} rays, busy {}, idle {} ({:.0f}%), sent {}\n",
        rank.rank, rank.host, rank.threads, rank.threads == 1 ? "thread" : "threads", rank.tiles,
        rank.rays.total(), formatDuration(rank.busySeconds), formatDuration(rank.idleSeconds),
        total > 0 ? 100 * rank.idleSeconds / total : 0.0, bytesText(rank.bytesSent));
  }
  const double tiles = static_cast<double>(std::max<std::uint64_t>(figures.remoteTiles, 1));
  text += fmt::format(
      "glint: rank 0 received {} and sent {}; per tile from another rank {:.1f} us handling and "
      "{:.1f} us in MPI (CPU); its link thread used {:.1f}% of a core\n",
      bytesText(figures.bytesReceived), bytesText(figures.bytesSent),
      1e6 * figures.handlingSeconds / tiles, 1e6 * figures.messagingSeconds / tiles,
      figures.renderSeconds > 0 ? 100 * figures.linkSeconds / figures.renderSeconds : 0.0);
  return text;
}

}  // namespace glint::cli
