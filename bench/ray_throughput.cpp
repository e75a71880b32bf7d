// Ray throughput of glint's Aggregate against Embree 3 on the same triangles, spheres and rays
// (issue 4, bench 1): Mrays/s per scene × ray set × query × thread count, the ratio glint/Embree,
// the 2-thread speedups, and both BVH build times.
//
//   ray_throughput [--runs N] [--quick] [--no-packets] [--embree-isa ISA]
//
// Scenes: a 100k- and a 1M-triangle torus over a two-triangle floor, and 1000 spheres (glint:
// analytic spheres; Embree: RTC_GEOMETRY_TYPE_SPHERE_POINT, a true ray–sphere intersection) over
// the same floor. Ray sets: 1024×768 pinhole camera rays, and as many random rays (origins uniform
// in the scene bounds, directions uniform on the sphere). Queries: closest hit (glint intersect,
// rtcIntersect1) and shadow over (0, ∞) (glint transmittance with every kt = 0, rtcOccluded1).
// glint works in double precision, Embree in single; both get the same rays, converted once.
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bench_scenes.h"
#include "bench_support.h"
#include "build_measure.h"
#include "embree_support.h"

namespace glint::bench {
namespace {

enum class Query { Closest, Shadow };

struct Row {
  std::string scene, rays;
  Query query;
  int threads;
  std::size_t rayCount;
  Timing glint, embree1, embree16;
  double agreement = 0;    // fraction of rays where glint and Embree give the same answer
  double hitFraction = 0;  // of glint's answers: hit / occluded
};

double mrays(std::size_t count, const Timing& t) {
  return t.median() > 0 ? static_cast<double>(count) / t.median() * 1e-6 : 0;
}

// Same answer: both miss, or both hit at distances equal to single precision's accuracy (with
// room for Embree's float rounding of vertices and rays).
bool sameHit(double tGlint, float tEmbree) {
  const bool gHit = std::isfinite(tGlint), eHit = std::isfinite(tEmbree);
  if (gHit != eHit) return false;
  return !gHit || std::abs(tGlint - static_cast<double>(tEmbree)) <= 1e-4 * std::max(1.0, tGlint);
}

Row measure(const std::string& sceneName, const RaySet& set, const std::vector<FloatRay>& floatRays,
            const Aggregate& aggregate, RTCScene embree, Query query, int threads, int runs,
            bool packets) {
  Row row{sceneName, set.name, query, threads, set.rays.size(), {}, {}, {}, 0, 0};
  const std::size_t n = set.rays.size();
  tbb::task_arena arena(threads);
  std::vector<double> tGlint(n);
  std::vector<float> tEmbree(n);
  std::vector<std::uint8_t> occGlint(n), occEmbree(n);
  const Ray* rays = set.rays.data();
  const FloatRay* frays = floatRays.data();

  const auto runGlint = [&] {
    const Stopwatch watch;
    if (query == Query::Closest) {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        Hit hit;
        for (std::size_t i = b; i < e; ++i) {
          tGlint[i] = aggregate.intersect(rays[i], 0, kInfinity, hit) ? hit.t : kInfinity;
        }
      });
    } else {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          occGlint[i] = isBlack(aggregate.transmittance(rays[i], 0, kInfinity)) ? 1 : 0;
        }
      });
    }
    return watch.seconds();
  };
  const auto runEmbree = [&](bool packet) {
    const Stopwatch watch;
    if (query == Query::Closest) {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        packet ? embreeIntersect16(embree, frays, b, e, tEmbree.data())
               : embreeIntersect1(embree, frays, b, e, tEmbree.data());
      });
    } else {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        packet ? embreeOccluded16(embree, frays, b, e, occEmbree.data())
               : embreeOccluded1(embree, frays, b, e, occEmbree.data());
      });
    }
    return watch.seconds();
  };

  // One untimed warm-up of each (page faults, caches, TBB workers), then the runs interleaved so
  // that a change in machine load hits both sides alike.
  runGlint();
  runEmbree(false);
  if (packets) runEmbree(true);
  for (int r = 0; r < runs; ++r) {
    row.glint.seconds.push_back(runGlint());
    row.embree1.seconds.push_back(runEmbree(false));
    if (packets) row.embree16.seconds.push_back(runEmbree(true));
  }
  // The last run of either kind left its answers in the arrays; packets and single rays agree,
  // so it does not matter which Embree variant wrote them.
  std::size_t agree = 0, hits = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (query == Query::Closest) {
      agree += sameHit(tGlint[i], tEmbree[i]);
      hits += std::isfinite(tGlint[i]);
    } else {
      agree += occGlint[i] == occEmbree[i];
      hits += occGlint[i];
    }
  }
  row.agreement = static_cast<double>(agree) / static_cast<double>(n);
  row.hitFraction = static_cast<double>(hits) / static_cast<double>(n);
  return row;
}

void printRowHeader(bool packets) {
  std::printf("%-12s %-7s %-8s %3s | %-18s | %-18s | %12s |%s %6s | %9s\n", "scene", "rays",
              "query", "thr", "glint Mrays/s", "Embree-1 Mrays/s", "glint/Embree",
              packets ? " Embree-16 Mrays/s  |" : "", "hits", "agree");
}

void printRow(const Row& r, bool packets) {
  char packet[64] = "";
  if (packets) {
    std::snprintf(packet, sizeof packet, " %8.2f ±%5.1f%%   |", mrays(r.rayCount, r.embree16),
                  r.embree16.spreadPercent());
  }
  std::printf(
      "%-12s %-7s %-8s %3d | %8.2f ±%5.1f%%   | %8.2f ±%5.1f%%   | %12.2f |%s %5.1f%% | %8.4f%%\n",
      r.scene.c_str(), r.rays.c_str(), r.query == Query::Closest ? "closest" : "shadow", r.threads,
      mrays(r.rayCount, r.glint), r.glint.spreadPercent(), mrays(r.rayCount, r.embree1),
      r.embree1.spreadPercent(), mrays(r.rayCount, r.glint) / mrays(r.rayCount, r.embree1), packet,
      100 * r.hitFraction, 100 * r.agreement);
  std::fflush(stdout);
}

int run(int argc, char** argv) {
  const std::string usage =
      "usage: ray_throughput [--runs N] [--quick] [--no-packets] [--embree-isa ISA]\n"
      "  --runs N      repetitions per figure (median printed; default 5)\n"
      "  --quick       10k-triangle torus instead of 1M, 256x192 rays (smoke test)\n"
      "  --no-packets  skip the informative Embree 16-ray packet column\n"
      "  --embree-isa ISA  run Embree's kernels for ISA (sse2, sse4.2, avx, avx2, avx512) instead\n"
      "                of the widest this CPU has: glint's own build targets baseline x86-64\n";
  std::vector<ExtraOption> extra{{"--no-packets", false}, {"--embree-isa", true}};
  const CommonOptions options = parseCommonOptions(argc, argv, usage, &extra);
  const bool packets = !extra[0].present;
  printHeader("ray throughput: glint vs Embree", options);

  EmbreeDevice device(extra[1].present ? "isa=" + extra[1].value : "");
  std::printf("%s; glint double precision, Embree single precision\n", device.describe().c_str());

  std::vector<BenchScene> scenes;
  scenes.push_back(makeTorusScene(100000));
  scenes.push_back(makeTorusScene(options.quick ? 10000 : 1000000));
  scenes.push_back(makeSpheresScene());
  if (options.quick) {
    for (BenchScene& s : scenes) s.camera.imageWidth = 256, s.camera.imageHeight = 192;
  }
  const std::vector<int> threadCounts{1, 2};

  std::printf("\n-- BVH build (glint: Aggregate constructor; Embree: rtcCommitScene) --\n");
  std::printf("%s\n", buildTableHeader().c_str());
  for (const BenchScene& scene : scenes) {
    for (int threads : threadCounts) {
      const BuildFigures f = measureBuild(scene, device, threads, options.runs);
      std::printf("%s\n", buildTableRow(scene.name, threads, f).c_str());
      std::fflush(stdout);
    }
  }

  std::printf(
      "\n-- ray throughput (Mrays/s, median ± half range; glint/Embree uses Embree-1 = "
      "rtcIntersect1/rtcOccluded1) --\n");
  printRowHeader(packets);
  std::vector<Row> rows;
  for (const BenchScene& scene : scenes) {
    std::optional<Aggregate> aggregate;
    {
      tbb::task_arena arena(2);
      arena.execute([&] { aggregate.emplace(buildAggregate(makeGlintInputs(scene))); });
    }
    EmbreeScene embree(device, scene.meshes, scene.spheres);
    embree.commit();
    const std::size_t count =
        static_cast<std::size_t>(scene.camera.imageWidth) * scene.camera.imageHeight;
    const std::vector<RaySet> sets{cameraRays(scene.camera),
                                   randomRays(boundsOf(scene.meshes, scene.spheres), count, 4)};
    for (const RaySet& set : sets) {
      const std::vector<FloatRay> floatRays = toFloatRays(set.rays);
      for (Query query : {Query::Closest, Query::Shadow}) {
        for (int threads : threadCounts) {
          rows.push_back(measure(scene.name, set, floatRays, *aggregate, embree.get(), query,
                                 threads, options.runs, packets));
          printRow(rows.back(), packets);
        }
      }
    }
  }

  // 2-thread speedups, and the issue-4 targets over every row.
  std::printf("\n-- 2-thread speedup (Mrays/s at 2 threads / at 1 thread) --\n");
  std::printf("%-12s %-7s %-8s | %13s | %14s\n", "scene", "rays", "query", "glint speedup",
              "Embree speedup");
  double worstRatio = 1e300, worstSpeedup = 1e300;
  for (std::size_t i = 0; i + 1 < rows.size(); i += 2) {
    const Row& one = rows[i];
    const Row& two = rows[i + 1];
    const double g = mrays(two.rayCount, two.glint) / mrays(one.rayCount, one.glint);
    const double e = mrays(two.rayCount, two.embree1) / mrays(one.rayCount, one.embree1);
    worstSpeedup = std::min(worstSpeedup, g);
    std::printf("%-12s %-7s %-8s | %13.2f | %14.2f\n", one.scene.c_str(), one.rays.c_str(),
                one.query == Query::Closest ? "closest" : "shadow", g, e);
  }
  for (const Row& r : rows) {
    worstRatio = std::min(worstRatio, mrays(r.rayCount, r.glint) / mrays(r.rayCount, r.embree1));
  }
  std::printf("\ntargets: glint/Embree >= 0.80 on every row: worst %.2f -> %s\n", worstRatio,
              worstRatio >= 0.8 ? "MET" : "NOT MET");
  std::printf("         2-thread speedup >= 1.85 on every row: worst %.2f -> %s\n", worstSpeedup,
              worstSpeedup >= 1.85 ? "MET" : "NOT MET");
  std::printf("load average at the end: %s\n", loadAverage().c_str());
  return 0;
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) { return glint::bench::run(argc, argv); }
