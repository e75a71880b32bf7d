// Embree 3 scenes and queries for the benchmarks (embree_support.h).
#include "embree_support.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace glint::bench {

namespace {

constexpr float kFloatInfinity = std::numeric_limits<float>::infinity();

void throwOnError(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) {
    throw std::runtime_error(std::string("Embree: ") + what + " failed with error " +
                             std::to_string(static_cast<int>(error)));
  }
}

void errorCallback(void*, RTCError code, const char* message) {
  std::fprintf(stderr, "Embree error %d: %s\n", static_cast<int>(code), message ? message : "");
}

}  // namespace

std::vector<FloatRay> toFloatRays(const std::vector<Ray>& rays) {
  std::vector<FloatRay> out;
  out.reserve(rays.size());
  for (const Ray& r : rays) {
    out.push_back({static_cast<float>(r.origin.x), static_cast<float>(r.origin.y),
                   static_cast<float>(r.origin.z), static_cast<float>(r.direction.x),
                   static_cast<float>(r.direction.y), static_cast<float>(r.direction.z)});
  }
  return out;
}

EmbreeDevice::EmbreeDevice(const std::string& config) {
  device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
  if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");
  rtcSetDeviceErrorFunction(device_, errorCallback, nullptr);
  rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeDevice::monitor, this);
}

EmbreeDevice::~EmbreeDevice() { rtcReleaseDevice(device_); }

bool EmbreeDevice::monitor(void* user, ssize_t bytes, bool /*post*/) {
  static_cast<EmbreeDevice*>(user)->bytes_ += bytes;
  return true;
}

std::string EmbreeDevice::describe() const {
  const auto property = [this](RTCDeviceProperty p) { return rtcGetDeviceProperty(device_, p); };
  std::string text = "Embree " + std::to_string(property(RTC_DEVICE_PROPERTY_VERSION_MAJOR)) + "." +
                     std::to_string(property(RTC_DEVICE_PROPERTY_VERSION_MINOR)) + "." +
                     std::to_string(property(RTC_DEVICE_PROPERTY_VERSION_PATCH));
  text += ", native packets:";
  if (property(RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) text += " 4";
  if (property(RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) text += " 8";
  if (property(RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) text += " 16";
  const auto tasking = property(RTC_DEVICE_PROPERTY_TASKING_SYSTEM);
  text +=
      tasking == 1 ? ", tasking TBB" : (tasking == 0 ? ", tasking internal" : ", tasking other");
  return text;
}

bool EmbreeDevice::supportsSpheres() const {
  return rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED) != 0;
}

EmbreeScene::EmbreeScene(EmbreeDevice& device, const std::vector<TriangleMesh>& meshes,
                         const std::vector<SphereSpec>& spheres) {
  RTCDevice d = device.get();
  scene_ = rtcNewScene(d);
  throwOnError(d, "rtcNewScene");
  for (const TriangleMesh& mesh : meshes) {
    RTCGeometry geometry = rtcNewGeometry(d, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree reads vertices with 16-byte loads: its buffers carry the padding it needs.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.positions.size()));
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      vertices[3 * i + 0] = static_cast<float>(mesh.positions[i].x);
      vertices[3 * i + 1] = static_cast<float>(mesh.positions[i].y);
      vertices[3 * i + 2] = static_cast<float>(mesh.positions[i].z);
    }
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangleCount()));
    std::copy(mesh.indices.begin(), mesh.indices.end(), indices);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    throwOnError(d, "triangle geometry");
  }
  if (!spheres.empty()) {
    if (!device.supportsSpheres()) throw std::runtime_error("Embree: no point geometry support");
    RTCGeometry geometry = rtcNewGeometry(d, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* points = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), spheres.size()));
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      points[4 * i + 0] = static_cast<float>(spheres[i].center.x);
      points[4 * i + 1] = static_cast<float>(spheres[i].center.y);
      points[4 * i + 2] = static_cast<float>(spheres[i].center.z);
      points[4 * i + 3] = static_cast<float>(spheres[i].radius);
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    throwOnError(d, "sphere geometry");
  }
}

EmbreeScene::~EmbreeScene() { rtcReleaseScene(scene_); }

void EmbreeScene::commit() { rtcCommitScene(scene_); }

RTCRay embreeRay(const FloatRay& r, float tnear, float tfar) {
  RTCRay ray;
  ray.org_x = r.ox;
  ray.org_y = r.oy;
  ray.org_z = r.oz;
  ray.tnear = tnear;
  ray.dir_x = r.dx;
  ray.dir_y = r.dy;
  ray.dir_z = r.dz;
  ray.time = 0;
  ray.tfar = tfar;
  ray.mask = ~0u;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

RTCRayHit embreeRayHit(const FloatRay& r, float tnear, float tfar) {
  RTCRayHit rh;
  rh.ray = embreeRay(r, tnear, tfar);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

void embreeIntersect1(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                      float* tHit) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (std::size_t i = begin; i < end; ++i) {
    RTCRayHit rh = embreeRayHit(rays[i], 0, kFloatInfinity);
    rtcIntersect1(scene, &context, &rh);
    tHit[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : kFloatInfinity;
  }
}

void embreeOccluded1(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                     std::uint8_t* occluded) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (std::size_t i = begin; i < end; ++i) {
    RTCRay ray = embreeRay(rays[i], 0, kFloatInfinity);
    rtcOccluded1(scene, &context, &ray);
    // Embree marks an occluded ray by setting tfar to −inf.
    occluded[i] = ray.tfar < 0 ? 1 : 0;
  }
}

namespace {

// Fills lanes [0, n) of a 16-ray packet from rays[first...] and returns the valid mask.
void loadPacket(const FloatRay* rays, std::size_t first, int n, RTCRay16& p, int (&valid)[16]) {
  for (int k = 0; k < 16; ++k) {
    valid[k] = k < n ? -1 : 0;
    const FloatRay& r = rays[first + static_cast<std::size_t>(k < n ? k : 0)];
    p.org_x[k] = r.ox;
    p.org_y[k] = r.oy;
    p.org_z[k] = r.oz;
    p.tnear[k] = 0;
    p.dir_x[k] = r.dx;
    p.dir_y[k] = r.dy;
    p.dir_z[k] = r.dz;
    p.time[k] = 0;
    p.tfar[k] = kFloatInfinity;
    p.mask[k] = ~0u;
    p.id[k] = static_cast<unsigned>(k);
    p.flags[k] = 0;
  }
}

}  // namespace

void embreeIntersect16(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                       float* tHit) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[16];
  for (std::size_t i = begin; i < end; i += 16) {
    const int n = static_cast<int>(std::min<std::size_t>(16, end - i));
    loadPacket(rays, i, n, packet.ray, valid);
    for (int k = 0; k < 16; ++k) {
      packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, scene, &context, &packet);
    for (int k = 0; k < n; ++k) {
      tHit[i + static_cast<std::size_t>(k)] =
          packet.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? packet.ray.tfar[k] : kFloatInfinity;
    }
  }
}

void embreeOccluded16(RTCScene scene, const FloatRay* rays, std::size_t begin, std::size_t end,
                      std::uint8_t* occluded) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(64) RTCRay16 packet;
  alignas(64) int valid[16];
  for (std::size_t i = begin; i < end; i += 16) {
    const int n = static_cast<int>(std::min<std::size_t>(16, end - i));
    loadPacket(rays, i, n, packet, valid);
    rtcOccluded16(valid, scene, &context, &packet);
    for (int k = 0; k < n; ++k) occluded[i + static_cast<std::size_t>(k)] = packet.tfar[k] < 0;
  }
}

}  // namespace glint::bench
