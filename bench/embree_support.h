// Embree 3 as the benchmarks' reference: the same triangles and spheres as glint sees, in an
// RTCScene, with single-ray (rtcIntersect1/rtcOccluded1) and 16-wide packet queries. Linked by the
// benchmarks only; the glint library never sees Embree.
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "bench_support.h"

namespace glint::bench {

// A ray in Embree's single precision, converted once from a glint (double) ray before timing.
struct FloatRay {
  float ox, oy, oz;
  float dx, dy, dz;
};
std::vector<FloatRay> toFloatRays(const std::vector<Ray>& rays);

class EmbreeDevice {
 public:
  // `config` is rtcNewDevice's configuration string ("" = Embree's defaults).
  explicit EmbreeDevice(const std::string& config = "");
  ~EmbreeDevice();
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  RTCDevice get() const { return device_; }
  // Bytes Embree has allocated and not freed (its memory monitor callback): buffers and BVHs.
  std::int64_t bytesInUse() const { return bytes_.load(); }
  // "AVX512", "AVX2"... what rtcGetDeviceProperty reports about native packet widths.
  std::string describe() const;
  bool supportsSpheres() const;

 private:
  static bool monitor(void* user, ssize_t bytes, bool post);
  RTCDevice device_ = nullptr;
  std::atomic<std::int64_t> bytes_{0};
};

// The scene: one triangle geometry per mesh (float3 vertices, uint3 indices) and one
// RTC_GEOMETRY_TYPE_SPHERE_POINT geometry for all spheres (true ray–sphere intersection, float4
// centre + radius). Built with Embree's defaults (RTC_BUILD_QUALITY_MEDIUM, no robust flag).
class EmbreeScene {
 public:
  EmbreeScene(EmbreeDevice& device, const std::vector<TriangleMesh>& meshes,
              const std::vector<SphereSpec>& spheres);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // rtcCommitScene: builds the BVH (on the calling thread's TBB arena).
  void commit();
  RTCScene get() const { return scene_; }

 private:
  RTCScene scene_ = nullptr;
};

// A single ray for rtcIntersect1/rtcOccluded1 over (tnear, tfar), every field set.
RTCRay embreeRay(const FloatRay& r, float tnear, float tfar);
RTCRayHit embreeRayHit(const FloatRay& r, float tnear, float tfar);

// Closest hit of rays[begin, end): tHit[i] = hit distance, or +inf for a miss.
void embreeIntersect1(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                      float* tHit);
// Occlusion of rays[begin, end) over (0, inf): occluded[i] = 1 when anything is hit.
void embreeOccluded1(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                     std::uint8_t* occluded);
// The same with 16-ray packets (rtcIntersect16/rtcOccluded16; a partial last packet is masked).
void embreeIntersect16(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                       float* tHit);
void embreeOccluded16(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                      std::uint8_t* occluded);

}  // namespace glint::bench
