// Build time and memory of glint and Embree (build_measure.h).
#include "build_measure.h"

#include <cstdio>
#include <optional>
#include <utility>

namespace glint::bench {

double BuildFigures::glintBytesPerPrimitive() const {
  return primitives() ? static_cast<double>(glintReportedBytes) / static_cast<double>(primitives())
                      : 0;
}

double BuildFigures::glintHeapBytesPerPrimitive() const {
  const double total = static_cast<double>(glintInputBytes) + static_cast<double>(glintAccelBytes);
  return primitives() ? total / static_cast<double>(primitives()) : 0;
}

double BuildFigures::embreeBytesPerPrimitive() const {
  return primitives() ? static_cast<double>(embreeBytes) / static_cast<double>(primitives()) : 0;
}

BuildFigures measureBuild(const BenchScene& scene, EmbreeDevice& device, int threads, int runs) {
  BuildFigures f;
  f.triangles = triangleCount(scene.meshes);
  f.spheres = scene.spheres.size();
  tbb::task_arena arena(threads);
  double glintCpu = 0, embreeCpu = 0;
  for (int run = 0; run < runs; ++run) {
    // glint: copy the inputs, then time only the constructor. The heap delta across it is what
    // the Aggregate keeps (its temporaries are freed before it returns).
    {
      GlintInputs inputs = makeGlintInputs(scene);
      f.glintInputBytes =
          meshBytes(inputs.meshes) + inputs.primitives.capacity() * sizeof(Primitive);
      std::optional<Aggregate> aggregate;
      const std::size_t before = heapBytesInUse();
      const double cpu = processCpuSeconds();
      const Stopwatch watch;
      arena.execute([&] { aggregate.emplace(buildAggregate(std::move(inputs))); });
      f.glint.seconds.push_back(watch.seconds());
      glintCpu += processCpuSeconds() - cpu;
      f.glintAccelBytes =
          static_cast<std::int64_t>(heapBytesInUse()) - static_cast<std::int64_t>(before);
      f.glintReportedBytes = aggregate->memoryBytes();
    }
    // Embree: fill the buffers, then time only rtcCommitScene.
    {
      const std::int64_t before = device.bytesInUse();
      EmbreeScene embree(device, scene.meshes, scene.spheres);
      const double cpu = processCpuSeconds();
      const Stopwatch watch;
      arena.execute([&] { embree.commit(); });
      f.embree.seconds.push_back(watch.seconds());
      embreeCpu += processCpuSeconds() - cpu;
      f.embreeBytes = device.bytesInUse() - before;
    }
  }
  const auto sum = [](const Timing& t) {
    double total = 0;
    for (double x : t.seconds) total += x;
    return total;
  };
  f.glintCores = glintCpu / sum(f.glint);
  f.embreeCores = embreeCpu / sum(f.embree);
  return f;
}

std::string buildTableHeader() {
  return "scene          triangles spheres thr |  glint build s  cores |  Embree build s  cores | "
         "glint/Embree | glint B/prim | heap-measured (input + accel) | Embree B/prim";
}

std::string buildTableRow(const std::string& scene, int threads, const BuildFigures& f) {
  const double n = static_cast<double>(f.primitives());
  char text[256];
  std::snprintf(text, sizeof text,
                "%-14s %9zu %7zu %3d | %8.4f ±%4.1f%% %4.2f | %8.4f ±%4.1f%% %4.2f | %12.2f | "
                "%12.1f | %6.1f (%6.1f + %6.1f)        | %6.1f",
                scene.c_str(), f.triangles, f.spheres, threads, f.glint.median(),
                f.glint.spreadPercent(), f.glintCores, f.embree.median(), f.embree.spreadPercent(),
                f.embreeCores, f.glint.median() / f.embree.median(), f.glintBytesPerPrimitive(),
                f.glintHeapBytesPerPrimitive(), static_cast<double>(f.glintInputBytes) / n,
                static_cast<double>(f.glintAccelBytes) / n, f.embreeBytesPerPrimitive());
  return text;
}

}  // namespace glint::bench
