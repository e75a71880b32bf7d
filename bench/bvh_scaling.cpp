// The seed's acceleration measurement made honest (issue 4): primary plus shadow rays through
// scenes of 10 … 1M random spheres, with Acceleration::BruteForce (every ray tests every sphere)
// and with the BVH; nanoseconds per ray, and how the cost grows with n. Embree 3 traces the same
// spheres and rays beside it: what logarithmic growth looks like on this machine's memory.
//
//   bvh_scaling [--runs N] [--quick] [--threads T] [--limit SECONDS]
//
// Scene n: n spheres with centres uniform in [−1, 1]³ and the radius that makes a ray crossing the
// cube meet 3 spheres on average (so every n gives a statistically similar picture and only n
// changes). Camera 320×240 at (0, 0, 4) looking at the origin, fov 30° (the cube fills the frame);
// every primary hit sends a shadow ray to a point light at (3, 4, 5). Brute force is skipped once
// its predicted run time (from the previous size, linear in n) exceeds --limit seconds (default
// 30).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bench_support.h"
#include "embree_support.h"
#include "glint/core/spawn.h"

namespace glint::bench {
namespace {

struct Answers {
  std::size_t rays = 0;      // primary + shadow
  std::size_t hits = 0;      // primary rays that hit
  std::size_t shadowed = 0;  // shadow rays that were blocked
  double tSum = 0;           // Σ primary hit distances: BVH and brute force must agree exactly
};

constexpr Point3 kLight{3, 4, 5};

// Per-ray answers, written by the workers, summed afterwards in ray order (so the sums do not
// depend on the schedule).
struct RayAnswers {
  std::vector<double> tHit;            // primary hit distance, +inf for a miss
  std::vector<std::uint8_t> shadowed;  // 1 when the shadow ray from the hit was blocked
};

// Traces every camera ray and, at each hit, the shadow ray toward the light.
void trace(const Aggregate& aggregate, const std::vector<Ray>& rays, tbb::task_arena& arena,
           RayAnswers& out) {
  out.tHit.resize(rays.size());
  out.shadowed.resize(rays.size());
  forBlocks(arena, rays.size(), [&](std::size_t b, std::size_t e) {
    Hit hit;
    for (std::size_t i = b; i < e; ++i) {
      if (!aggregate.intersect(rays[i], 0, kInfinity, hit)) {
        out.tHit[i] = kInfinity;
        out.shadowed[i] = 0;
        continue;
      }
      out.tHit[i] = hit.t;
      const Point3 p = rays[i].at(hit.t);
      const Vec3 toLight = kLight - p;
      const double d = length(toLight);
      const Ray shadow = spawnRay(p, hit.normal, toLight / d);
      out.shadowed[i] = isBlack(aggregate.transmittance(shadow, 0, d)) ? 1 : 0;
    }
  });
}

// The same rays through Embree (rtcIntersect1, then rtcOccluded1 toward the light from each hit,
// its origin moved 1e-5 off the sphere along Embree's normal); hit[i] = 1 when ray i hit.
void traceEmbree(RTCScene scene, const std::vector<FloatRay>& rays, tbb::task_arena& arena,
                 std::vector<std::uint8_t>& hit) {
  hit.resize(rays.size());
  forBlocks(arena, rays.size(), [&](std::size_t b, std::size_t e) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = b; i < e; ++i) {
      RTCRayHit rh = embreeRayHit(rays[i], 0, std::numeric_limits<float>::infinity());
      rtcIntersect1(scene, &context, &rh);
      hit[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      if (!hit[i]) continue;
      const FloatRay& r = rays[i];
      const float t = rh.ray.tfar;
      float n[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
      const float nLength = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      float p[3] = {r.ox + t * r.dx, r.oy + t * r.dy, r.oz + t * r.dz};
      float l[3] = {static_cast<float>(kLight.x) - p[0], static_cast<float>(kLight.y) - p[1],
                    static_cast<float>(kLight.z) - p[2]};
      const float d = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
      const float side = n[0] * l[0] + n[1] * l[1] + n[2] * l[2] >= 0 ? 1e-5f : -1e-5f;
      for (int k = 0; k < 3; ++k) p[k] += n[k] / nLength * side;
      RTCRay shadow = embreeRay({p[0], p[1], p[2], l[0] / d, l[1] / d, l[2] / d}, 0, d);
      rtcOccluded1(scene, &context, &shadow);
    }
  });
}

Answers summarise(const RayAnswers& r) {
  Answers a;
  for (std::size_t i = 0; i < r.tHit.size(); ++i) {
    ++a.rays;
    if (!std::isfinite(r.tHit[i])) continue;
    ++a.rays;
    ++a.hits;
    a.tSum += r.tHit[i];
    a.shadowed += r.shadowed[i];
  }
  return a;
}

Aggregate makeAggregate(const std::vector<SphereSpec>& spheres, Acceleration acceleration) {
  std::vector<Primitive> primitives = spherePrimitives(spheres);
  std::vector<Color> transmission(primitives.size(), Color());
  return Aggregate(std::move(primitives), std::move(transmission), {}, {}, acceleration);
}

// Least-squares line y = a + b·x; r2 = coefficient of determination.
struct Fit {
  double a = 0, b = 0, r2 = 0;
};
Fit fitLine(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
  }
  Fit f;
  f.b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  f.a = (sy - f.b * sx) / n;
  double ssRes = 0, ssTot = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = y[i] - (f.a + f.b * x[i]);
    ssRes += r * r;
    ssTot += (y[i] - sy / n) * (y[i] - sy / n);
  }
  f.r2 = ssTot > 0 ? 1 - ssRes / ssTot : 1;
  return f;
}

int run(int argc, char** argv) {
  const std::string usage =
      "usage: bvh_scaling [--runs N] [--quick] [--threads T] [--limit SECONDS]\n"
      "  --runs N         BVH repetitions per size (median printed; default 5); brute force runs "
      "once\n"
      "  --quick          sizes up to 100k, brute force limit 5 s\n"
      "  --threads T      worker threads (default 1: per-ray cost without scheduling noise)\n"
      "  --limit SECONDS  skip brute force when its predicted time exceeds this (default 30)\n";
  std::vector<ExtraOption> extra{{"--threads"}, {"--limit"}};
  const CommonOptions options = parseCommonOptions(argc, argv, usage, &extra);
  const int threads = extra[0].present ? std::atoi(extra[0].value.c_str()) : 1;
  double limit = extra[1].present ? std::atof(extra[1].value.c_str()) : 30.0;
  if (options.quick && !extra[1].present) limit = 5;
  if (threads < 1 || !(limit > 0)) {
    std::fprintf(stderr, "%s", usage.c_str());
    return 2;
  }
  printHeader("BVH scaling: brute force vs BVH, random spheres", options);
  std::printf(
      "threads: %d; camera 320x240 primary rays + one shadow ray per hit; brute force "
      "skipped above %.0f s predicted\n\n",
      threads, limit);

  CameraSpec camera;
  camera.position = {0, 0, 4};
  camera.direction = {0, 0, -1};
  camera.fovDegrees = 30;
  camera.imageWidth = 320;
  camera.imageHeight = 240;
  const RaySet rays = cameraRays(camera);
  tbb::task_arena arena(threads);

  std::vector<std::size_t> sizes{10, 100, 1000, 10000, 100000, 1000000};
  if (options.quick) sizes.pop_back();

  EmbreeDevice device;
  const std::vector<FloatRay> floatRays = toFloatRays(rays.rays);
  std::printf("%9s %9s | %9s | %-20s | %-20s | %9s | %-20s | %12s | %8s %6s %s\n", "objects",
              "radius", "build s", "BVH ns/ray", "brute force ns/ray", "BF / BVH", "Embree ns/ray",
              "glint/Embree", "rays", "hits", "same answers");
  std::vector<double> logN, bvhNs, logBvhNs, bfLogN, bfLogNs, logEmbreeNs;
  double bfNsPerRayPerObject = 0;  // from the last brute-force size: predicts the next one
  for (std::size_t n : sizes) {
    const std::vector<SphereSpec> spheres = makeRandomSpheres(n, 3.0, 7);
    Timing build;
    std::optional<Aggregate> bvh;
    for (int r = 0; r < options.runs; ++r) {
      bvh.reset();
      const Stopwatch watch;
      arena.execute([&] { bvh.emplace(makeAggregate(spheres, Acceleration::Bvh)); });
      build.seconds.push_back(watch.seconds());
    }
    RayAnswers answers;
    trace(*bvh, rays.rays, arena, answers);  // warm-up
    Timing bvhTime;
    for (int r = 0; r < options.runs; ++r) {
      const Stopwatch watch;
      trace(*bvh, rays.rays, arena, answers);
      bvhTime.seconds.push_back(watch.seconds());
    }
    const Answers bvhAnswers = summarise(answers);
    const double rayCount = static_cast<double>(bvhAnswers.rays);
    const double bvhNsPerRay = bvhTime.median() / rayCount * 1e9;

    // Embree on the same spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT) and camera rays, for what
    // logarithmic growth looks like on this machine's caches.
    EmbreeScene embree(device, {}, spheres);
    arena.execute([&] { embree.commit(); });
    std::vector<std::uint8_t> embreeHits;
    traceEmbree(embree.get(), floatRays, arena, embreeHits);  // warm-up
    Timing embreeTime;
    for (int r = 0; r < options.runs; ++r) {
      const Stopwatch watch;
      traceEmbree(embree.get(), floatRays, arena, embreeHits);
      embreeTime.seconds.push_back(watch.seconds());
    }
    std::size_t embreeRays = embreeHits.size();
    for (std::uint8_t h : embreeHits) embreeRays += h;
    const double embreeNsPerRay = embreeTime.median() / static_cast<double>(embreeRays) * 1e9;

    char bfText[64] = "skipped";
    char ratioText[32] = "-";
    char sameText[48] = "-";
    const double predicted = bfNsPerRayPerObject * static_cast<double>(n) * rayCount * 1e-9;
    if (predicted <= limit) {
      const Aggregate brute = makeAggregate(spheres, Acceleration::BruteForce);
      const Stopwatch watch;
      trace(brute, rays.rays, arena, answers);
      const double seconds = watch.seconds();
      const Answers bf = summarise(answers);
      const double bfNs = seconds / static_cast<double>(bf.rays) * 1e9;
      bfNsPerRayPerObject = bfNs / static_cast<double>(n);
      std::snprintf(bfText, sizeof bfText, "%12.1f (1 run)", bfNs);
      std::snprintf(ratioText, sizeof ratioText, "%9.1f", bfNs / bvhNsPerRay);
      const bool same = bf.rays == bvhAnswers.rays && bf.hits == bvhAnswers.hits &&
                        bf.shadowed == bvhAnswers.shadowed && bf.tSum == bvhAnswers.tSum;
      std::snprintf(sameText, sizeof sameText, "%s", same ? "yes" : "NO (BVH differs!)");
      bfLogN.push_back(std::log2(static_cast<double>(n)));
      bfLogNs.push_back(std::log2(bfNs));
    } else {
      std::snprintf(bfText, sizeof bfText, "skipped (~%.0f s)", predicted);
    }
    std::printf(
        "%9zu %9.5f | %9.5f | %9.1f ±%5.1f%%    | %-20s | %9s | %9.1f ±%5.1f%%    | %12.2f | "
        "%8zu %5.1f%% %s\n",
        n, spheres.front().radius, build.median(), bvhNsPerRay, bvhTime.spreadPercent(), bfText,
        ratioText, embreeNsPerRay, embreeTime.spreadPercent(), embreeNsPerRay / bvhNsPerRay,
        bvhAnswers.rays,
        100.0 * static_cast<double>(bvhAnswers.hits) / static_cast<double>(rays.rays.size()),
        sameText);
    std::fflush(stdout);
    logN.push_back(std::log2(static_cast<double>(n)));
    bvhNs.push_back(bvhNsPerRay);
    logBvhNs.push_back(std::log2(bvhNsPerRay));
    logEmbreeNs.push_back(std::log2(embreeNsPerRay));
  }

  const Fit linear = fitLine(logN, bvhNs);
  const Fit power = fitLine(logN, logBvhNs);
  std::printf(
      "\nBVH: ns/ray = %.1f + %.2f * log2(n)   (R^2 = %.3f): each doubling of n adds "
      "%.2f ns per ray\n",
      linear.a, linear.b, linear.r2, linear.b);
  std::printf(
      "BVH: as a power law ns/ray ~ n^%.3f (R^2 = %.3f); logarithmic growth shows as a "
      "small exponent, linear as 1\n",
      power.b, power.r2);
  const Fit embreePower = fitLine(logN, logEmbreeNs);
  std::printf("Embree (same rays, same spheres): ns/ray ~ n^%.3f (R^2 = %.3f)\n", embreePower.b,
              embreePower.r2);
  if (bfLogN.size() >= 2) {
    const Fit bf = fitLine(bfLogN, bfLogNs);
    std::printf("brute force: ns/ray ~ n^%.3f (R^2 = %.3f) over the sizes it ran\n", bf.b, bf.r2);
  }
  std::printf("load average at the end: %s\n", loadAverage().c_str());
  return 0;
}

}  // namespace
}  // namespace glint::bench

int main(int argc, char** argv) { return glint::bench::run(argc, argv); }
