// Ray throughput of glint's Aggregate against Embree 3 on the same triangles, spheres and rays
// (issue 4, bench 1): Mrays/s per scene × ray set × query × thread count, the ratio glint/Embree,
// the 2-thread speedups, and both BVH build times.
//
//   ray_throughput [--runs N] [--quick] [--no-packets] [--embree-isa ISA] [--isas] [--widths]
//                  [--embree-isas ISA,ISA...]
//
// glint runs its default kernels (GLINT_ISA, else the widest this CPU runs: core/isa.h) on the
// BVH node width they use (bvhNodeWidth: GLINT_BVH_WIDTH, else 4); with --isas every ISA this CPU
// runs, one column each, and with --widths each ISA on both node widths (a 4-wide and an 8-wide
// Aggregate of the same scene) with the ratio 8-wide/4-wide per ISA; with --embree-isas also Embree
// devices restricted to those ISAs (single rays), each beside the widest glint column. All columns
// alternate with Embree within every run, and the rows check that all glint columns gave the same
// answers bit for bit.
//
// Scenes: a 100k- and a 1M-triangle torus over a two-triangle floor, and 1000 spheres (glint:
// analytic spheres; Embree: RTC_GEOMETRY_TYPE_SPHERE_POINT, a true ray–sphere intersection) over
// the same floor. Ray sets: 1024×768 pinhole camera rays, and as many random rays (origins uniform
// in the scene bounds, directions uniform on the sphere). Queries: closest hit (glint intersect,
// rtcIntersect1) and shadow over (0, ∞) (glint transmittance with every kt = 0, rtcOccluded1).
// glint works in double precision, Embree in single; both get the same rays, converted once.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench_scenes.h"
#include "bench_support.h"
#include "build_measure.h"
#include "embree_support.h"
#include "glint/core/isa.h"

namespace glint::bench {
namespace {

enum class Query { Closest, Shadow };

struct Row {
  std::string scene, rays;
  Query query;
  int threads;
  std::size_t rayCount;
  std::vector<Timing> glint;  // one per column measured, in the order of `columns`
  Timing embree1, embree16;
  Timing glint16;  // 16-ray packets (intersectPacket / transmittancePacket), widest column
  std::vector<Timing> embreeIsas;  // single rays on each --embree-isas device, in that order
  double agreement = 0;            // fraction of rays where glint and Embree give the same answer
  double hitFraction = 0;          // of glint's answers: hit / occluded
  bool isasAgree = true;           // every column gave the same answers, bit for bit
  bool packetsAgree = true;        // glint's packets gave its single rays' answers, bit for bit
  const Timing& widest() const { return glint.back(); }
};

// A glint column: the kernels of `isa` on the tree of `width` children per node.
struct Column {
  Isa isa;
  int width;
  std::string name() const { return std::string(isaName(isa)) + "/" + std::to_string(width); }
};

// The scene's Aggregates, one per node width measured.
struct Aggregates {
  std::optional<Aggregate> four;
  std::optional<Aggregate> eight;
  Aggregate& at(const Column& column) { return column.width == 8 ? *eight : *four; }
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
            Aggregates& aggregates, const std::vector<Column>& columns, RTCScene embree,
            const std::vector<RTCScene>& embreeIsas, Query query, int threads, int runs,
            bool packets) {
  Row row{sceneName, set.name, query, threads, set.rays.size(), {}, {}, {}, {}, {}, 0, 0, true};
  row.glint.resize(columns.size());
  row.embreeIsas.resize(embreeIsas.size());
  Aggregate* aggregate = nullptr;  // the column being run
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
          tGlint[i] = aggregate->intersect(rays[i], 0, kInfinity, hit) ? hit.t : kInfinity;
        }
      });
    } else {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          occGlint[i] = isBlack(aggregate->transmittance(rays[i], 0, kInfinity)) ? 1 : 0;
        }
      });
    }
    return watch.seconds();
  };
  // Consecutive rays in packets of 16, as Embree's packets take them (camera rays: 16 pixels of a
  // row; their shadow rays likewise).
  const auto runGlintPackets = [&] {
    const Stopwatch watch;
    if (query == Query::Shadow) {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        std::array<Color, Aggregate::kPacketSize> transmittance;
        std::array<double, Aggregate::kPacketSize> tMax;
        tMax.fill(kInfinity);
        for (std::size_t i = b; i < e; i += Aggregate::kPacketSize) {
          const auto count = static_cast<int>(std::min<std::size_t>(Aggregate::kPacketSize, e - i));
          aggregate->transmittancePacket(rays + i, count, 0, tMax.data(), transmittance.data());
          for (int k = 0; k < count; ++k) {
            occGlint[i + static_cast<std::size_t>(k)] =
                isBlack(transmittance[static_cast<std::size_t>(k)]) ? 1 : 0;
          }
        }
      });
      return watch.seconds();
    }
    forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
      std::array<Hit, Aggregate::kPacketSize> hits;
      std::array<bool, Aggregate::kPacketSize> found{};
      std::array<double, Aggregate::kPacketSize> tMax;
      tMax.fill(kInfinity);
      for (std::size_t i = b; i < e; i += Aggregate::kPacketSize) {
        const auto count = static_cast<int>(std::min<std::size_t>(Aggregate::kPacketSize, e - i));
        aggregate->intersectPacket(rays + i, count, 0, tMax.data(), hits.data(), found.data());
        for (int k = 0; k < count; ++k) {
          const auto lane = static_cast<std::size_t>(k);
          tGlint[i + lane] = found[lane] ? hits[lane].t : kInfinity;
        }
      }
    });
    return watch.seconds();
  };
  const auto runEmbreeOn = [&](RTCScene target, bool packet) {
    const Stopwatch watch;
    if (query == Query::Closest) {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        packet ? embreeIntersect16(target, frays, b, e, tEmbree.data())
               : embreeIntersect1(target, frays, b, e, tEmbree.data());
      });
    } else {
      forBlocks(arena, n, [&](std::size_t b, std::size_t e) {
        packet ? embreeOccluded16(target, frays, b, e, occEmbree.data())
               : embreeOccluded1(target, frays, b, e, occEmbree.data());
      });
    }
    return watch.seconds();
  };
  const auto runEmbree = [&](bool packet) { return runEmbreeOn(embree, packet); };

  // One untimed warm-up of each (page faults, caches, TBB workers), then the runs interleaved so
  // that a change in machine load hits every side alike. The first column's answers are kept to
  // check that the others give the same bits.
  const auto select = [&](const Column& column) {
    aggregate = &aggregates.at(column);
    aggregate->setIsa(column.isa);
  };
  std::vector<double> firstT;
  std::vector<std::uint8_t> firstOcc;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    select(columns[k]);
    runGlint();
    if (k == 0) {
      firstT = tGlint;
      firstOcc = occGlint;
    } else {
      row.isasAgree = row.isasAgree && firstT == tGlint && firstOcc == occGlint;
    }
  }
  const bool glintPackets = packets;
  if (glintPackets) {
    select(columns.back());
    runGlintPackets();
    row.packetsAgree = query == Query::Closest ? firstT == tGlint : firstOcc == occGlint;
  }
  for (const RTCScene other : embreeIsas) runEmbreeOn(other, false);
  runEmbree(false);
  if (packets) runEmbree(true);
  for (int r = 0; r < runs; ++r) {
    for (std::size_t k = 0; k < columns.size(); ++k) {
      select(columns[k]);
      row.glint[k].seconds.push_back(runGlint());
    }
    if (glintPackets) {
      select(columns.back());
      row.glint16.seconds.push_back(runGlintPackets());
    }
    for (std::size_t k = 0; k < embreeIsas.size(); ++k) {
      row.embreeIsas[k].seconds.push_back(runEmbreeOn(embreeIsas[k], false));
    }
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

// Pairs of columns (4-wide, 8-wide) of the same ISA, for the width ratio columns.
std::vector<std::pair<std::size_t, std::size_t>> widthPairs(const std::vector<Column>& columns) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    for (std::size_t j = 0; j < columns.size(); ++j) {
      if (columns[i].isa == columns[j].isa && columns[i].width == 4 && columns[j].width == 8) {
        pairs.emplace_back(i, j);
      }
    }
  }
  return pairs;
}

void printRowHeader(bool packets, const std::vector<Column>& columns,
                    const std::vector<std::string>& embreeIsas) {
  std::printf("%-12s %-7s %-8s %3s |", "scene", "rays", "query", "thr");
  for (const Column& c : columns) {
    const std::string title = "glint " + c.name() + " Mrays/s";
    std::printf(" %-20s |", title.c_str());
  }
  std::printf(" %-20s |", "Embree-1 Mrays/s");
  for (const Column& c : columns) {
    const std::string title = c.name() + "/Embree";
    std::printf(" %15s |", title.c_str());
  }
  for (const auto& [four, eight] : widthPairs(columns)) {
    const std::string title = std::string(isaName(columns[four].isa)) + " 8/4";
    std::printf(" %11s |", title.c_str());
  }
  for (const std::string& isa : embreeIsas) {
    const std::string title = "Embree-1 " + isa + " Mrays/s";
    const std::string ratio = columns.back().name() + "/Embree " + isa;
    std::printf(" %-20s | %15s |", title.c_str(), ratio.c_str());
  }
  std::printf("%s %6s | %9s%s\n",
              packets ? " Embree-16 Mrays/s    | glint-16 Mrays/s     | g16/g1 | g16/E16 |" : "",
              "hits", "agree", columns.size() > 1 ? " | all same" : "");
}

void printRow(const Row& r, const std::vector<Column>& columns, bool packets) {
  std::printf("%-12s %-7s %-8s %3d |", r.scene.c_str(), r.rays.c_str(),
              r.query == Query::Closest ? "closest" : "shadow", r.threads);
  for (const Timing& t : r.glint)
    std::printf(" %8.2f ±%5.1f%%     |", mrays(r.rayCount, t), t.spreadPercent());
  std::printf(" %8.2f ±%5.1f%%     |", mrays(r.rayCount, r.embree1), r.embree1.spreadPercent());
  for (const Timing& t : r.glint)
    std::printf(" %15.2f |", mrays(r.rayCount, t) / mrays(r.rayCount, r.embree1));
  for (const auto& [four, eight] : widthPairs(columns)) {
    std::printf(" %11.3f |", mrays(r.rayCount, r.glint[eight]) / mrays(r.rayCount, r.glint[four]));
  }
  for (const Timing& t : r.embreeIsas) {
    std::printf(" %8.2f ±%5.1f%%     | %15.2f |", mrays(r.rayCount, t), t.spreadPercent(),
                mrays(r.rayCount, r.widest()) / mrays(r.rayCount, t));
  }
  if (packets) {
    std::printf(" %8.2f ±%5.1f%%     |", mrays(r.rayCount, r.embree16), r.embree16.spreadPercent());
    if (r.glint16.seconds.empty()) {
      std::printf(" %-20s | %6s | %7s |", "-", "-", "-");
    } else {
      std::printf(" %8.2f ±%5.1f%% %s   | %6.2f | %7.2f |", mrays(r.rayCount, r.glint16),
                  r.glint16.spreadPercent(), r.packetsAgree ? " " : "!",
                  mrays(r.rayCount, r.glint16) / mrays(r.rayCount, r.widest()),
                  mrays(r.rayCount, r.glint16) / mrays(r.rayCount, r.embree16));
    }
  }
  std::printf(" %5.1f%% | %8.4f%%%s\n", 100 * r.hitFraction, 100 * r.agreement,
              r.glint.size() > 1 ? (r.isasAgree ? " | yes" : " | NO") : "");
  std::fflush(stdout);
}

int run(int argc, char** argv) {
  const std::string usage =
      "usage: ray_throughput [--runs N] [--quick] [--no-packets] [--embree-isa ISA] [--isas]\n"
      "                      [--widths] [--embree-isas ISA,ISA...]\n"
      "  --runs N      repetitions per figure (median printed; default 5)\n"
      "  --quick       10k-triangle torus instead of 1M, 256x192 rays (smoke test)\n"
      "  --no-packets  skip the 16-ray packet columns (Embree rtcIntersect16/rtcOccluded16, glint\n"
      "                intersectPacket and transmittancePacket)\n"
      "  --embree-isa ISA  run Embree's kernels for ISA (sse2, sse4.2, avx, avx2, avx512) instead\n"
      "                of the widest this CPU has\n"
      "  --isas        every glint ISA this CPU runs (baseline, avx2, avx512) side by side, not\n"
      "                only the default one (GLINT_ISA, else the widest)\n"
      "  --widths      each ISA on 4-wide and on 8-wide BVH nodes, not only on its default width\n"
      "  --embree-isas ISA,...  also Embree restricted to each ISA (e.g. sse4.2,avx2), single\n"
      "                rays, measured in the same runs beside the default device\n";
  std::vector<ExtraOption> extra{{"--no-packets", false},
                                 {"--embree-isa", true},
                                 {"--isas", false},
                                 {"--widths", false},
                                 {"--embree-isas", true}};
  const CommonOptions options = parseCommonOptions(argc, argv, usage, &extra);
  const bool packets = !extra[0].present;
  printHeader("ray throughput: glint vs Embree", options);

  EmbreeDevice device(extra[1].present ? "isa=" + extra[1].value : "");
  std::printf("%s; glint double precision, Embree single precision\n", device.describe().c_str());
  // More Embree devices, each restricted to one ISA, measured in the same runs as the first.
  std::vector<std::string> embreeIsaNames;
  std::vector<std::unique_ptr<EmbreeDevice>> embreeIsaDevices;
  if (extra[4].present) {
    std::string list = extra[4].value;
    for (std::size_t start = 0; start <= list.size();) {
      const std::size_t comma = std::min(list.find(',', start), list.size());
      const std::string isa = list.substr(start, comma - start);
      if (!isa.empty()) {
        embreeIsaNames.push_back(isa);
        embreeIsaDevices.push_back(std::make_unique<EmbreeDevice>("isa=" + isa));
        std::printf("also %s\n", embreeIsaDevices.back()->describe().c_str());
      }
      start = comma + 1;
    }
  }
  std::vector<Isa> isas{defaultIsa()};
  if (extra[2].present) {
    isas.clear();
    for (const Isa isa : kAllIsas) {
      if (isaSupportHere().runs(isa)) isas.push_back(isa);
    }
  }
  std::vector<Column> columns;
  for (const Isa isa : isas) {
    if (extra[3].present) {
      columns.push_back({isa, 4});
      columns.push_back({isa, 8});
    } else {
      columns.push_back({isa, bvhNodeWidth(isa)});
    }
  }
  const auto usesWidth = [&](int width) {
    return std::any_of(columns.begin(), columns.end(),
                       [width](const Column& c) { return c.width == width; });
  };
  std::printf("glint kernels (ISA/node width):");
  for (const Column& c : columns) std::printf(" %s", c.name().c_str());
  std::printf(" (the widest this CPU runs: %s)\n",
              std::string(isaName(bestIsa(isaSupportHere()))).c_str());

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
  printRowHeader(packets, columns, embreeIsaNames);
  std::vector<Row> rows;
  for (const BenchScene& scene : scenes) {
    Aggregates aggregates;
    {
      tbb::task_arena arena(2);
      arena.execute([&] {
        if (usesWidth(4)) {
          aggregates.four.emplace(buildAggregate(makeGlintInputs(scene), Acceleration::Bvh4));
        }
        if (usesWidth(8)) {
          aggregates.eight.emplace(buildAggregate(makeGlintInputs(scene), Acceleration::Bvh8));
        }
      });
    }
    EmbreeScene embree(device, scene.meshes, scene.spheres);
    embree.commit();
    std::vector<std::unique_ptr<EmbreeScene>> embreeIsaScenes;
    std::vector<RTCScene> embreeIsaHandles;
    for (const auto& other : embreeIsaDevices) {
      embreeIsaScenes.push_back(std::make_unique<EmbreeScene>(*other, scene.meshes, scene.spheres));
      embreeIsaScenes.back()->commit();
      embreeIsaHandles.push_back(embreeIsaScenes.back()->get());
    }
    const std::size_t count =
        static_cast<std::size_t>(scene.camera.imageWidth) * scene.camera.imageHeight;
    const std::vector<RaySet> sets{cameraRays(scene.camera),
                                   randomRays(boundsOf(scene.meshes, scene.spheres), count, 4)};
    for (const RaySet& set : sets) {
      const std::vector<FloatRay> floatRays = toFloatRays(set.rays);
      for (Query query : {Query::Closest, Query::Shadow}) {
        for (int threads : threadCounts) {
          rows.push_back(measure(scene.name, set, floatRays, aggregates, columns, embree.get(),
                                 embreeIsaHandles, query, threads, options.runs, packets));
          printRow(rows.back(), columns, packets);
        }
      }
    }
  }

  // 2-thread speedups, and the issue-4 targets over every row.
  std::printf("\n-- 2-thread speedup (Mrays/s at 2 threads / at 1 thread; glint: %s) --\n",
              columns.back().name().c_str());
  std::printf("%-12s %-7s %-8s | %13s | %14s\n", "scene", "rays", "query", "glint speedup",
              "Embree speedup");
  double worstRatio = 1e300, worstSpeedup = 1e300;
  for (std::size_t i = 0; i + 1 < rows.size(); i += 2) {
    const Row& one = rows[i];
    const Row& two = rows[i + 1];
    const double g = mrays(two.rayCount, two.widest()) / mrays(one.rayCount, one.widest());
    const double e = mrays(two.rayCount, two.embree1) / mrays(one.rayCount, one.embree1);
    worstSpeedup = std::min(worstSpeedup, g);
    std::printf("%-12s %-7s %-8s | %13.2f | %14.2f\n", one.scene.c_str(), one.rays.c_str(),
                one.query == Query::Closest ? "closest" : "shadow", g, e);
  }
  bool isasAgree = true;
  bool packetsAgree = true;
  for (const Row& r : rows) {
    worstRatio = std::min(worstRatio, mrays(r.rayCount, r.widest()) / mrays(r.rayCount, r.embree1));
    isasAgree = isasAgree && r.isasAgree;
    packetsAgree = packetsAgree && r.packetsAgree;
  }
  if (packets) {
    std::printf(
        "\nglint's 16-ray packets gave its single rays' answers on every row: %s\n",
        packetsAgree ? "yes" : "NO");
  }
  if (columns.size() > 1) {
    std::printf("\nevery column gave the same answers on every row: %s\n",
                isasAgree ? "yes" : "NO");
  }
  std::printf("\ntargets (glint %s): glint/Embree >= 1.0 on every row: worst %.2f -> %s\n",
              columns.back().name().c_str(), worstRatio, worstRatio >= 1.0 ? "MET" : "NOT MET");
  std::printf("         2-thread speedup >= 1.85 on every row: worst %.2f -> %s\n", worstSpeedup,
              worstSpeedup >= 1.85 ? "MET" : "NOT MET");
  std::printf("load average at the end: %s\n", loadAverage().c_str());
  return 0;
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) { return glint::bench::run(argc, argv); }
