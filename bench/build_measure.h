// Build time and memory of glint's Aggregate and of Embree's BVH over the same scene: what
// ray_throughput prints per scene and build_memory prints for the 100k and 1M meshes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "bench_scenes.h"
#include "bench_support.h"
#include "embree_support.h"

namespace glint::bench {

struct BuildFigures {
  Timing glint;   // the Aggregate constructor (inputs copied beforehand, not timed)
  Timing embree;  // rtcCommitScene (geometry buffers filled beforehand, not timed)
  // CPU seconds per wall second during the timed part, summed over runs: how many cores the
  // build really kept busy.
  double glintCores = 0, embreeCores = 0;
  std::size_t triangles = 0;
  std::size_t spheres = 0;
  // glint: Aggregate::memoryBytes() (meshes, tree, leaf references, Primitive array), and as a
  // cross-check the heap actually used: the inputs handed in (mesh arrays and the Primitive array,
  // by capacity) plus what the constructor kept (mallinfo2 in-use bytes after − before; its
  // temporaries are freed by then).
  std::size_t glintReportedBytes = 0;
  std::size_t glintInputBytes = 0;
  std::int64_t glintAccelBytes = 0;
  // Embree: everything its memory monitor saw for the scene (vertex/index buffers and BVH).
  std::int64_t embreeBytes = 0;

  std::size_t primitives() const { return triangles + spheres; }
  double glintBytesPerPrimitive() const;  // memoryBytes() / primitives
  double glintHeapBytesPerPrimitive() const;
  double embreeBytesPerPrimitive() const;
};

BuildFigures measureBuild(const BenchScene& scene, EmbreeDevice& device, int threads, int runs);

// One table row: "torus 100k  100002  0  1 | 0.052 ±1% | ...". The header goes with it.
std::string buildTableHeader();
std::string buildTableRow(const std::string& scene, int threads, const BuildFigures& f);

}  // namespace glint::bench
