// The Whitted/Phong integrator of DESIGN.md §3 with distributed ray tracing (sampler-driven pixel,
// lens, glossy and area-light samples; adaptive anti-aliasing) and the tile scheduler that drives
// it.
#include "glint/render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>

#include "glint/core/cache_line.h"
#include "glint/core/sampler.h"
#include "glint/core/sampling.h"
#include "glint/core/spawn.h"
#include "glint/render/refraction.h"
#include "glint/render/texturing.h"

namespace glint {
namespace {

// Sample dimension layout (core/sampler.h: each dimension is an independent 2D scrambled Sobol
// sequence, selected by a SampleStream key and this number). The stream of camera sample s of a
// pixel (sequence index s):
//   0      pixel offset inside the pixel (only with several samples or adaptive sampling; one
//          fixed sample goes through the pixel centre, DESIGN.md §4)
//   1      lens point for the thin lens (depth of field; unused by a pinhole camera)
// At every surface hit, on the stream of the path that reached it:
//   2      reflection lobe: glossy cone direction(s)
//   3      refraction lobe: the same for the transmitted direction(s)
//   4 + i  area light i (its index in Scene::lights()): the points sampled on its surface
//   2^30   ambient occlusion: the directions of its rays (above any light index)
//   2^30+1 path: the direction toward the image environment (next-event estimation)
//   2^30+2 path: the emitter and the point on it (next-event estimation)
// The primary hit shares the camera sample's stream (its dimensions start at 2). A secondary ray
// continues on stream.branch(lobe dimension, count, k): a new key, so the next hit draws its own
// dimensions 2, 3, 4 + i independently of this hit's; fanned-out sub-samples (glossy rays, area
// light points) take consecutive sequence indices index·count + k, so they stratify against each
// other and against the other pixel samples.
constexpr std::uint32_t kPixelDimension = 0;
constexpr std::uint32_t kLensDimension = 1;
constexpr std::uint32_t kReflectionDimension = 2;
constexpr std::uint32_t kRefractionDimension = 3;
constexpr std::uint32_t kFirstLightDimension = 4;
constexpr std::uint32_t kOcclusionDimension = std::uint32_t{1} << 30;
constexpr std::uint32_t kEnvironmentDimension = kOcclusionDimension + 1;
constexpr std::uint32_t kEmitterDimension = kOcclusionDimension + 2;

// Adaptive anti-aliasing starts with at least this many samples per pixel: fewer give no useful
// estimate of the pixel's error (four Sobol points already fall one in each quadrant).
constexpr std::uint32_t kMinAdaptiveSamples = 4;

struct BlockAhead;  // rays of renderBlock's packets traced ahead

// Per-render state shared by every ray of one camera path tree. Lives on the stack of the pixel
// loop; nothing here allocates.
struct TraceContext {
  const Scene& scene;
  RayCounts& counts;
  int maxDepth;
  double minWeight;
  std::uint32_t blurSamples;
  // One Hit per path depth, owned by the caller: trace() at depth d < hitCount fills hits[d], which
  // stays valid while its child rays run. Reused rather than a fresh Hit per call, whose 120 bytes
  // of default initialisation (rep stos) cost more than the rest of a miss. Deeper paths (a scene
  // built in code may set any maxDepth) use a Hit of their own frame.
  Hit* hits;
  int hitCount;
  // The scene has textures: hits evaluate them, and rays carry differentials (RayDifferential) for
  // their footprint. Without, neither is ever looked at.
  bool textured;
  bool uniformBackground;  // a miss returns Scene::background() without looking at the direction
  bool vertexColors;       // some mesh has vertex colours: hits on meshes look them up
  bool fog;                // the scene has fog: hits and misses go through it
  const AmbientOcclusion* occlusion;      // render.ambient_occlusion, or null
  bool path;                              // render.integrator: path (tracePath) rather than Whitted
  const EnvironmentSampler* environment;  // path: the image background's sampler, or null
  const EmitterSampler* emitters;         // path: the emissive surfaces' sampler, or null
  PathLightSampling lightSampling;        // path: MIS, or one strategy alone
  int minDepth;                           // path: Russian roulette from this many hits on
  int samplesPerPixel;                    // scales camera ray differentials
  // Scene::nestedMedia: rays carry the media they are inside (MediumStack) and refract by the
  // ratio of the media's ior at each boundary. Otherwise the stacks stay empty and unread.
  bool nested;
  // renderBlock's reflection rays traced ahead, for the lane it shades (else null).
  BlockAhead* ahead = nullptr;
};

enum class SecondaryKind { Reflection, Refraction };

Color trace(const TraceContext& ctx, const Ray& ray, const MediumStack& media, int depth,
            const Color& weight, bool split, const SampleStream& stream,
            const RayDifferential* differential = nullptr);
Color fogged(const TraceContext& ctx, const Color& color, const Ray& ray, double t, int depth);

// The position of a point or spot light; false for a directional light (at infinity).
bool lightPosition(const Light& light, Point3& position) {
  if (const auto* point = std::get_if<PointLight>(&light)) {
    position = point->position;
    return true;
  }
  if (const auto* spot = std::get_if<SpotLight>(&light)) {
    position = spot->position;
    return true;
  }
  return false;
}

// The origins of the rays that leave one hit. offsetRayOrigin (core/spawn.h) depends on the
// direction only through the side of the surface it leaves toward, so the hit has at most two
// distinct origins; each is computed once, at its first use, and shared by every shadow,
// reflection and refraction ray toward that side (the same bits as spawnRay per ray).
class SpawnOrigins {
 public:
  SpawnOrigins(const Point3& p, const Vec3& pError, const Normal3& n)
      : p_(p), pError_(pError), n_(n) {}

  // The ray spawnRay(p, pError, n, w) returns.
  Ray spawn(const Vec3& w) {
    const int side = leavesAlongNormal(n_, w) ? 1 : 0;
    if (!ready_[side]) {
      origin_[side] = offsetRayOrigin(p_, pError_, n_, w);
      ready_[side] = true;
    }
    return Ray{origin_[side], w};
  }

 private:
  const Point3& p_;
  const Vec3& pError_;
  const Normal3& n_;
  Point3 origin_[2];
  bool ready_[2] = {false, false};
};

// Lights whose camera-hit shadow rays renderBlock traces as packets: the first ones of the scene
// (point, spot and directional lights among them); the rest are traced one ray at a time.
constexpr std::size_t kPacketLights = 8;

// The shadow rays of a packet of hits (renderBlock: camera hits, and the hits of their reflection
// rays) toward each of the first kPacketLights lights, traced ahead as one packet per light
// (Aggregate::transmittancePacket). Storage for a tile's blocks, filled anew for each packet
// (tracePacketShadows).
struct alignas(64) PacketShadows {
  static constexpr std::size_t kLanes = Aggregate::kPacketSize;
  // rayOf codes other than a ray's index: not traced ahead (the shading samples the light itself);
  // the light's intensity at the hit is black; the light is on the other side of the surface.
  static constexpr std::uint8_t kNone = 0xff;
  static constexpr std::uint8_t kBlack = 0xfe;
  static constexpr std::uint8_t kAway = 0xfd;
  struct LightPacket {
    std::array<LightSample, kLanes> samples;
    std::array<Ray, kLanes> rays;
    std::array<double, kLanes> tMax;
    std::array<Color, kLanes> transmittance;
  };
  std::array<LightPacket, kPacketLights> lights;
  // [lane][light]: the index of lane's sample and ray in lights[light], or a code above.
  std::array<std::array<std::uint8_t, kPacketLights>, kLanes> rayOf;
  // The hit point (Hit::point) each lane's samples were taken at, or null: directLight takes them
  // for that very hit only.
  std::array<const Point3*, kLanes> pointOf;
};

// What renderBlock traces ahead for a packet of camera rays, and the lane it is shading: the camera
// hits' shadow rays, their mirror reflection rays (closest hits, one packet) and those hits' shadow
// rays. trace() takes a reflection's hit from here when its ray is exactly the lane's.
struct alignas(64) BlockAhead {
  static constexpr std::size_t kLanes = Aggregate::kPacketSize;
  static constexpr std::uint8_t kNone = 0xff;
  PacketShadows cameraShadows;
  // The reflection rays, their hits and those hits' shadow rays, packed (index r < count).
  std::array<Ray, kLanes> reflectionRays;
  std::array<Hit, kLanes> reflectionHits;
  std::array<bool, kLanes> reflectionFound{};
  PacketShadows reflectionShadows;
  std::array<std::uint8_t, kLanes> reflectionOfLane;  // lane → r, or kNone
  std::size_t lane = 0;                               // the lane being shaded

  // The index r of the shaded lane's reflection ray when it is exactly `ray`, else −1.
  int reflectionOf(const Ray& ray) const {
    const std::uint8_t r = reflectionOfLane[lane];
    if (r == kNone || std::memcmp(&reflectionRays[r], &ray, sizeof(Ray)) != 0) return -1;
    return r;
  }
};

// The shadow ray and its tMax that shadeLightSample traces from the shading point of `origins`
// toward a light sample of direction toPoint (−l: toward the light) at `lightPoint`, or toward
// infinity when lightPoint is null.
inline Ray lightShadowRay(SpawnOrigins& origins, const Vec3& toPoint, const Point3* lightPoint,
                          double& tMax) {
  const Ray shadowRay = origins.spawn(-toPoint);
  tMax = lightPoint ? distance(shadowRay.origin, *lightPoint) : kInfinity;
  return shadowRay;
}

// Whether a hit takes its mesh's vertex colours (they tint kd and ka there): the branch traceFound
// and tracePath take, and the one renderBlock's traced-ahead rays leave to the shading.
inline bool takesVertexColours(const TraceContext& ctx, const Hit& hit) {
  return ctx.vertexColors && hit.mesh != kNoMesh && !ctx.scene.meshOf(hit).colors.empty();
}

// The shading normal to shade a hit with, seen along the unit direction v (nv = n·v): one facing
// the other way from the geometric normal n would shade a back face; n is used then.
inline const Normal3& facingShadingNormal(const Normal3& shadingNormal, const Normal3& n,
                                          const Vec3& v, double nv) {
  return dot(shadingNormal, v) * nv > 0 ? shadingNormal : n;
}

// Shading inputs at one hit that every light sample shares (references into trace()'s frame: no
// copies per hit).
struct ShadingPoint {
  const Material& material;
  const Point3& p;    // on the surface (Hit::point)
  const Normal3& n;   // geometric: side tests and shadow-ray origins
  const Normal3& ns;  // shading (= n except on smooth meshes): diffuse term and mirror direction
  const Vec3& v;      // unit view direction
  double nv;          // n·v
  bool hasSpecular;
  SpawnOrigins& origins;  // of p, pError and n
  // The media on the viewer's side, where the shadow rays start (nested media only; else null).
  const MediumStack* media;
  // This hit's shadow rays as renderBlock traced them ahead (lane tracedLane's of a packet), or
  // null.
  const PacketShadows* traced = nullptr;
  std::size_t tracedLane = 0;
};

// The response of the surface at sp to a light sample that reaches it with `transmittance`: the
// last factors of shadeLightSample's term below.
[[gnu::always_inline]] inline Color lightResponse(const ShadingPoint& sp, const LightSample& sample,
                                                  const Color& transmittance) {
  if (isBlack(transmittance)) return Color();
  const Vec3& l = sample.toPoint;
  const double nl = dot(sp.n, l);
  const Material& material = sp.material;
  const double nsl = dot(sp.ns, l);
  Color response = nsl * nl > 0 ? material.kd * std::abs(nsl) : Color();
  if (sp.hasSpecular) {
    const Vec3 r = l - toVec(sp.ns) * (2 * nsl);  // the light's mirror direction about ns
    response += material.ks * std::pow(std::max(0.0, -dot(sp.v, r)), material.shininess);
  }
  return transmittance * sample.intensity * response;
}

// One light sample's term of DESIGN.md §3:
//   [(n·l)(n·v) > 0] · T_L(P) · I_L(P) · (kd·|ns·l| + ks·max(0, −v·r)^shininess),
// with its own shadow ray toward `lightPoint` (tMax = the distance to it, so nothing behind the
// light, and never the light itself, blocks) or toward infinity when lightPoint is null.
// Inlined: it runs once per light per hit, and an out-of-line call costs more than its shading.
[[gnu::always_inline]] inline Color shadeLightSample(const TraceContext& ctx,
                                                     const ShadingPoint& sp,
                                                     const LightSample& sample,
                                                     const Point3* lightPoint) {
  // The light and the eye must be on the same side of the surface.
  if (!(dot(sp.n, sample.toPoint) * sp.nv > 0)) return Color();
  double tMax;
  const Ray shadowRay = lightShadowRay(sp.origins, sample.toPoint, lightPoint, tMax);
  ++ctx.counts.shadow;
  return lightResponse(sp, sample,
                       sp.media ? ctx.scene.transmittance(shadowRay, tMax, *sp.media)
                                : ctx.scene.transmittance(shadowRay, tMax));
}

// Area-light sample budget ("the per-hit ray count falls with depth"): a path that has not split
// yet takes the light's `samples` points (shadow rays); a path below a glossy split (one of
// blurSamples sibling rays) takes ⌈samples / blurSamples⌉, so the siblings together spend about
// `samples` shadow rays per area light at each depth, as the one unsplit path would.
// Ambient occlusion rays take the same budget.
std::uint32_t splitSampleCount(int samplesPerHit, std::uint32_t blurSamples, bool split) {
  const auto samples = static_cast<std::uint32_t>(std::max(samplesPerHit, 1));
  return split ? std::max<std::uint32_t>(1, (samples + blurSamples - 1) / blurSamples) : samples;
}
std::uint32_t areaLightSampleCount(const AreaLight& light, std::uint32_t blurSamples, bool split) {
  return splitSampleCount(light.samples, blurSamples, split);
}

// An area light's term: the average over its sample points, each a point light of I0 with its own
// distance falloff and shadow ray. Kept out of line so that the loop over the other lights stays
// small.
[[gnu::noinline]] Color areaLightTerm(const TraceContext& ctx, const ShadingPoint& sp,
                                      const AreaLight& area, std::uint32_t dimension,
                                      const SampleStream& stream, bool split) {
  const std::uint32_t count = areaLightSampleCount(area, ctx.blurSamples, split);
  const SobolDimension2D points = stream.dimension(dimension);
  Color sum;
  for (std::uint32_t k = 0; k < count; ++k) {
    const Point3 x = sampleAreaLight(area, sp.p, points.at(stream.subIndex(count, k)));
    const LightSample sample = illuminateFrom(area, x, sp.p);
    if (isBlack(sample.intensity)) continue;
    sum += shadeLightSample(ctx, sp, sample, &x);
  }
  return sum / static_cast<double>(count);
}

// The mirror image of a unit direction w in the plane of the geometric surface (unit normal n).
// Where a smooth mesh's shading normal tilts away from the geometric one, part of the hemisphere
// about the shading normal lies below the surface; a diffuse or glossy direction drawn there is
// folded back above it. The lobes then keep all their energy: a diffuse convex object under a
// uniform sky is kd × sky everywhere (the white furnace of DESIGN.md §10), where ending the path
// (or, for ambient occlusion, calling the direction blocked) darkened coarse smooth meshes.
inline Vec3 foldAboveSurface(const Vec3& w, const Normal3& n) {
  return w - toVec(n) * (2 * dot(n, w));
}

// Ambient occlusion (DESIGN.md §10, Tachyon's): the fraction of the ambient light that reaches the
// hit, as the mean transmittance (the shadow rays' T_L: glass lets it through in part) of rays in
// cosine-weighted directions about the shading normal on the viewer's side (the side of the
// geometric surface the ray came from), each travelling render.ambient_occlusion.distance. A
// direction below the geometric surface (where ns ≠ n) is folded back above it
// (foldAboveSurface), so that a smooth surface with nothing near it keeps all its ambient light.
// The rays count as shadow rays (both are any-hit queries).
[[gnu::noinline]] Color ambientVisibility(const TraceContext& ctx, SpawnOrigins& origins,
                                          const Normal3& n, const Normal3& ns, double nv,
                                          const MediumStack* media, const SampleStream& stream,
                                          bool split) {
  const AmbientOcclusion& occlusion = *ctx.occlusion;
  const double side = nv < 0 ? 1 : -1;  // +1: the viewer is on n's side
  const Vec3 axis = toVec(ns) * side;
  Vec3 tangent;
  Vec3 bitangent;
  orthonormalBasis(axis, tangent, bitangent);
  const std::uint32_t count = splitSampleCount(occlusion.samples, ctx.blurSamples, split);
  const SobolDimension2D directions = stream.dimension(kOcclusionDimension);
  Color sum;
  for (std::uint32_t k = 0; k < count; ++k) {
    Vec3 w =
        sampleCosineHemisphere(axis, tangent, bitangent, directions.at(stream.subIndex(count, k)));
    if (!(dot(n, w) * side > 0)) {
      w = foldAboveSurface(w, n);
      if (!(dot(n, w) * side > 0)) continue;
    }
    ++ctx.counts.shadow;
    sum += media ? ctx.scene.transmittance(origins.spawn(w), occlusion.distance, *media)
                 : ctx.scene.transmittance(origins.spawn(w), occlusion.distance);
  }
  return sum / static_cast<double>(count);
}

// Direct lighting (DESIGN.md §3) with the shading normal ns (= n except on smooth meshes) in the
// diffuse term and in r. The side tests and the shadow ray's origin use the geometric n; a light on
// the other side of ns than of n gives no diffuse term. Inlined into both shading paths (plain and
// textured): a call here measured +0.9 % instructions on untextured scenes.
[[gnu::always_inline]] inline Color directLight(const TraceContext& ctx, const ShadingPoint& sp,
                                                const SampleStream& stream, bool split) {
  Color sum;
  // Nothing for a light to act on: skip the shadow rays too.
  if (isBlack(sp.material.kd) && !sp.hasSpecular) return sum;
  const std::vector<Light>& lights = ctx.scene.lights();
  const std::size_t lightCount = lights.size();
  // The samples renderBlock took ahead at this very hit, with their shadow rays' answers
  // (tracePacketShadows: the same computations as below).
  const PacketShadows* ahead =
      sp.traced != nullptr && sp.traced->pointOf[sp.tracedLane] == &sp.p ? sp.traced : nullptr;
  for (std::size_t i = 0; i < lightCount; ++i) {
    const Light& light = lights[i];
    if (ahead != nullptr && i < kPacketLights) {
      const std::uint8_t r = ahead->rayOf[sp.tracedLane][i];
      if (r == PacketShadows::kBlack) continue;
      if (r == PacketShadows::kAway) {
        sum += Color();  // shadeLightSample's answer
        continue;
      }
      if (r != PacketShadows::kNone) {
        ++ctx.counts.shadow;
        const PacketShadows::LightPacket& packet = ahead->lights[i];
        sum += lightResponse(sp, packet.samples[r], packet.transmittance[r]);
        continue;
      }
    }
    // Point lights (the common case) inline: no call and no LightSample through memory.
    if (const auto* point = std::get_if<PointLight>(&light)) {
      const LightSample sample = illuminate(*point, sp.p);
      if (isBlack(sample.intensity)) continue;
      sum += shadeLightSample(ctx, sp, sample, &point->position);
      continue;
    }
    if (const auto* area = std::get_if<AreaLight>(&light)) {
      sum += areaLightTerm(ctx, sp, *area, kFirstLightDimension + static_cast<std::uint32_t>(i),
                           stream, split);
      continue;
    }
    const LightSample sample = illuminate(light, sp.p);
    if (isBlack(sample.intensity)) continue;
    Point3 position;
    sum += shadeLightSample(ctx, sp, sample, lightPosition(light, position) ? &position : nullptr);
  }
  return sum;
}

// Traces one secondary lobe (reflection or transmission) around the unit direction `ideal` leaving
// P, scaled by nothing (the caller multiplies by kr/kt). With blurDegrees > 0 the seed's
// "microfacets": rays spread uniformly over the cone of that half-angle around `ideal`, those that
// would go through the surface to the other side than `ideal` dropped, the rest averaged.
//
// Ray budget ("per-hit ray count falls with depth"): the first glossy lobe on a path traces
// blurSamples rays (consecutive points of the lobe's sampler dimension); every ray below it is
// marked `split`, and a split path uses a single cone ray at later glossy bounces (and fewer
// area-light samples, see areaLightSampleCount). So a path tree holds at most blurSamples rays
// per glossy lobe of its first glossy hit instead of blurSamples^depth.
//
// `differential` (null without textures) is that of the ideal ray; a cone ray takes its offsets
// moved onto its own direction.
Color traceLobe(const TraceContext& ctx, SpawnOrigins& origins, const Normal3& n, const Vec3& ideal,
                double blurDegrees, SecondaryKind kind, const MediumStack& media, int depth,
                const Color& weight, bool split, const SampleStream& stream,
                const RayDifferential* differential) {
  const bool reflection = kind == SecondaryKind::Reflection;
  std::uint64_t& counter = reflection ? ctx.counts.reflection : ctx.counts.refraction;
  const std::uint32_t dimension = reflection ? kReflectionDimension : kRefractionDimension;
  if (!(blurDegrees > 0)) {
    ++counter;
    return trace(ctx, origins.spawn(ideal), media, depth, weight, split,
                 stream.branch(dimension, 1, 0), differential);
  }
  const double cosMax = std::cos(std::min(blurDegrees, 180.0) * std::numbers::pi / 180.0);
  const double idealSide = dot(n, ideal);
  const std::uint32_t count = split ? 1u : ctx.blurSamples;
  const bool childSplit = split || count > 1;
  Vec3 tangent;
  Vec3 bitangent;
  orthonormalBasis(ideal, tangent, bitangent);
  const SobolDimension2D directions = stream.dimension(dimension);
  const std::uint64_t childKey = stream.branchKey(dimension);
  Color sum;
  std::uint32_t kept = 0;
  for (std::uint32_t k = 0; k < count; ++k) {
    const std::uint32_t index = stream.subIndex(count, k);
    const Vec3 w = sampleCone(ideal, tangent, bitangent, cosMax, directions.at(index));
    // Keep only directions that leave on the same side of the surface as the ideal one.
    if (!(dot(n, w) * idealSide > 0)) continue;
    ++counter;
    std::optional<RayDifferential> shifted;  // built only in textured scenes
    if (differential != nullptr) shifted = shiftedDifferential(*differential, ideal, w);
    sum += trace(ctx, origins.spawn(w), media, depth, weight, childSplit,
                 SampleStream(childKey, index), shifted ? &*shifted : nullptr);
    ++kept;
  }
  if (kept == 0) {
    ++counter;
    return trace(ctx, origins.spawn(ideal), media, depth, weight, childSplit,
                 SampleStream(childKey, stream.subIndex(count, 0)), differential);
  }
  return sum / static_cast<double>(kept);
}

// The mirror direction of the unit view direction v about the shading normal ns (nsv = ns·v). One
// that would dive below the geometric surface (n, nv = n·v) is replaced by the geometric mirror
// direction (it can only happen where ns ≠ n, `smooth`).
[[gnu::always_inline]] inline Vec3 mirrorDirection(const Vec3& v, const Normal3& n,
                                                   const Normal3& ns, double nv, double nsv,
                                                   bool smooth) {
  Vec3 reflected = v - toVec(ns) * (2 * nsv);
  if (smooth && !(dot(n, reflected) * nv < 0)) reflected = v - toVec(n) * (2 * nv);
  return reflected;
}

// True when a branch scaled by `factor` on top of `weight` is still worth tracing.
bool worthTracing(const Color& factor, const Color& weight, double minWeight, Color& newWeight) {
  if (isBlack(factor)) return false;
  newWeight = weight * factor;
  return maxComponent(newWeight) >= minWeight;
}

// The shading of one hit (the seed's calcColor after the intersection) with its material, emission
// and shading normal as given: the hit's own, or, in a textured scene, those its textures make.
// `textured` (null without textures) also carries the hit's footprint on to the secondary rays.
[[gnu::always_inline]] inline Color shadeHit(
    const TraceContext& ctx, const Ray& ray, const Hit& hit, const MediumStack& media,
    const Material& material, const Color& emission, const Normal3& shadingNormal, int depth,
    const Color& weight, bool split, const SampleStream& stream, const TexturedHit* textured,
    const RayDifferential* differential, const PacketShadows* traced = nullptr,
    std::size_t tracedLane = 0) {
  const int hitDepth = depth + 1;
  // The reprojected hit point and its error bound: ray.at(hit.t) would carry rounding error that
  // grows with the ray's origin and length, which no offset proportional to |p| covers.
  const Point3& p = hit.point;
  const Vec3& pError = hit.pointError;
  const Normal3& n = hit.normal;  // geometric: side decisions and ray origins
  const Vec3& v = ray.direction;  // unit for every ray the renderer creates
  const double nv = dot(n, v);
  // Shading normal: directions and the diffuse/specular terms.
  const Normal3& ns = facingShadingNormal(shadingNormal, n, v, nv);
  const double nsv = dot(ns, v);

  SpawnOrigins origins(p, pError, n);
  const MediumStack* viewerMedia = ctx.nested ? &media : nullptr;
  Color color = emission;
  if (const Color ambient = material.ka * ctx.scene.ambient(); !isBlack(ambient)) {
    color += ctx.occlusion == nullptr
                 ? ambient
                 : ambient * ambientVisibility(ctx, origins, n, ns, nv, viewerMedia, stream, split);
  }
  color += directLight(ctx,
                       ShadingPoint{material, p, n, ns, v, nv, !isBlack(material.ks), origins,
                                    viewerMedia, traced, tracedLane},
                       stream, split);
  if (hitDepth >= ctx.maxDepth) return color;

  const bool smooth = !(ns == n);
  const Vec3 reflected = mirrorDirection(v, n, ns, nv, nsv, smooth);
  // Differentials go on only from a hit whose footprint is known.
  const bool carry = textured != nullptr && differential != nullptr && textured->hasDifferentials;
  std::optional<RayDifferential> childDifferential;  // built only when carried
  Color branchWeight;
  if (worthTracing(material.kr, weight, ctx.minWeight, branchWeight)) {
    if (carry) childDifferential = reflectedDifferential(p, *textured, *differential, ns);
    color += material.kr * traceLobe(ctx, origins, n, reflected, material.reflectionBlur,
                                     SecondaryKind::Reflection, media, hitDepth, branchWeight,
                                     split, stream, carry ? &*childDifferential : nullptr);
  }
  if (worthTracing(material.kt, weight, ctx.minWeight, branchWeight)) {
    const bool entering = nv < 0;
    // Nested media: the relative index of the media on the two sides, and the stack of a ray that
    // crosses (one that totally reflects stays inside `media`).
    MediumStack beyond;
    const double eta = ctx.nested ? ctx.scene.boundaryAt(hit, v, media, beyond).eta()
                                  : airRelativeIndex(material.ior, entering);
    const Vec3 transmitted = transmittedDirection(eta, v, n, ns, nv, smooth, reflected, entering);
    const bool crosses = ctx.nested && dot(n, transmitted) * nv > 0;
    if (carry) {
      childDifferential = transmittedDifferential(p, *textured, *differential, ns, entering, eta);
    }
    color +=
        material.kt * traceLobe(ctx, origins, n, transmitted, material.refractionBlur,
                                SecondaryKind::Refraction, crosses ? beyond : media, hitDepth,
                                branchWeight, split, stream, carry ? &*childDifferential : nullptr);
  }
  return color;
}

// A textured scene's hit: its textures evaluated, its footprint from the ray's differential.
[[gnu::noinline]] Color traceTexturedHit(const TraceContext& ctx, const Ray& ray, const Hit& hit,
                                         const MediumStack& media, int depth, const Color& weight,
                                         bool split, const SampleStream& stream,
                                         const RayDifferential* differential) {
  TexturedHit textured;
  shadeTexturedHit(ctx.scene, hit, differential, textured);
  if (hit.mesh != kNoMesh && !ctx.scene.meshOf(hit).colors.empty()) {
    const Color tint = ctx.scene.aggregate().vertexColor(hit);
    textured.material.kd *= tint;
    textured.material.ka *= tint;
  }
  return shadeHit(ctx, ray, hit, media, textured.material, textured.emission,
                  textured.shadingNormal, depth, weight, split, stream, &textured, differential);
}

// An untextured scene's hit on a mesh with vertex colours: they tint kd and ka at the hit
// (TriangleMesh::colors, Tachyon's and VMD's per-vertex colours).
[[gnu::noinline]] Color traceVertexColouredHit(const TraceContext& ctx, const Ray& ray,
                                               const Hit& hit, const MediumStack& media, int depth,
                                               const Color& weight, bool split,
                                               const SampleStream& stream) {
  Material tinted = ctx.scene.materialOf(hit);
  const Color tint = ctx.scene.aggregate().vertexColor(hit);
  tinted.kd *= tint;
  tinted.ka *= tint;
  return shadeHit(ctx, ray, hit, media, tinted, ctx.scene.emissionOf(hit), hit.shadingNormal, depth,
                  weight, split, stream, nullptr, nullptr);
}

// The seed's calcColor with recursion. `depth` counts the surface hits already on this path
// (0 for a camera ray), `weight` the product of kr/kt factors that scale this ray's contribution,
// `split` whether the path has already fanned out into several glossy rays, `stream` its samples,
// `differential` the ray's footprint (textured scenes only; else null).
Color traceFound(const TraceContext& ctx, const Ray& ray, const MediumStack& here, int depth,
                 const Color& weight, bool split, const SampleStream& stream,
                 const RayDifferential* differential, bool found, const Hit& hit,
                 const PacketShadows* traced = nullptr, std::size_t tracedLane = 0);

Color trace(const TraceContext& ctx, const Ray& ray, const MediumStack& media, int depth,
            const Color& weight, bool split, const SampleStream& stream,
            const RayDifferential* differential) {
  // A camera hit's reflection traced ahead by renderBlock (with its shadow rays).
  if (ctx.ahead != nullptr && depth == 1) {
    if (const int r = ctx.ahead->reflectionOf(ray); r >= 0) {
      const auto i = static_cast<std::size_t>(r);
      return traceFound(ctx, ray, media, depth, weight, split, stream, differential,
                        ctx.ahead->reflectionFound[i], ctx.ahead->reflectionHits[i],
                        &ctx.ahead->reflectionShadows, i);
    }
  }
  // Aggregate::intersect sets every field of a hit it reports; a miss reads nothing.
  std::optional<Hit> deepHit;  // constructed only past the preallocated depths
  Hit& hit = depth < ctx.hitCount ? ctx.hits[depth] : deepHit.emplace();
  // Nested media: the boundaries that are no surface are passed, and the stack at the hit is
  // `inside`; otherwise the ray's (empty) stack stays as it is.
  std::optional<MediumStack> inside;
  if (ctx.nested) inside.emplace(media);
  const bool found = ctx.nested ? ctx.scene.intersect(ray, kInfinity, hit, *inside)
                                : ctx.scene.intersect(ray, kInfinity, hit);
  return traceFound(ctx, ray, ctx.nested ? *inside : media, depth, weight, split, stream,
                    differential, found, hit);
}

// trace() past its closest-hit query: what the ray sees, given whether it hit and where (`here`:
// the media at the hit). The camera-ray packets of renderBlock come in here with their hits, and
// with their shadow rays traced ahead (`traced`, lane tracedLane's; or null), which an untextured
// hit without vertex colours takes.
Color traceFound(const TraceContext& ctx, const Ray& ray, const MediumStack& here, int depth,
                 const Color& weight, bool split, const SampleStream& stream,
                 const RayDifferential* differential, bool found, const Hit& hit,
                 const PacketShadows* traced, std::size_t tracedLane) {
  if (!found) {
    // Fog measured along rays hides whatever lies at infinity.
    if (ctx.fog && ctx.scene.fog()->distance == FogDistance::Ray) {
      return ctx.scene.fog()->color;
    }
    return ctx.uniformBackground ? ctx.scene.background() : ctx.scene.backgroundSeenBy(ray);
  }
  Color color;
  if (ctx.textured) {
    color = traceTexturedHit(ctx, ray, hit, here, depth, weight, split, stream, differential);
  } else if (takesVertexColours(ctx, hit)) {
    color = traceVertexColouredHit(ctx, ray, hit, here, depth, weight, split, stream);
  } else {
    color = shadeHit(ctx, ray, hit, here, ctx.scene.materialOf(hit), ctx.scene.emissionOf(hit),
                     hit.shadingNormal, depth, weight, split, stream, nullptr, nullptr, traced,
                     tracedLane);
  }
  return ctx.fog ? fogged(ctx, color, ray, hit.t, depth) : color;
}

// What a ray sees at its hit, seen through the fog over the distance t it travelled (Fog::distance
// says how camera rays measure it).
Color fogged(const TraceContext& ctx, const Color& color, const Ray& ray, double t, int depth) {
  const Fog& fog = *ctx.scene.fog();
  const bool viewDepth = fog.distance == FogDistance::Depth && depth == 0;
  return fog.apply(color, viewDepth ? t * dot(ray.direction, ctx.scene.camera().toward()) : t);
}

// ---- render.integrator: path (DESIGN.md §10) ---------------------------------------------------
//
// Unidirectional path tracing, one path per camera sample, iterative. At every hit:
//   - emissive surfaces are lights (EmitterSampler: a point drawn by luminance per area, one
//     shadow ray per hit with diffuse or glossy lobes, blocked by any surface), weighted against
//     the BRDF samples that hit them by the power heuristic; emitters it does not sample count in
//     full where paths meet them, as does a uniform or gradient background a path escapes to;
//   - an image background is also sampled as a light (EnvironmentSampler: by luminance): one
//     shadow ray per hit with diffuse or glossy lobes, blocked by any surface, weighted against
//     the BRDF samples that escape to it by the power heuristic (multiple importance sampling);
//   - the lights of the scene give exactly the Whitted integrator's direct term (directLight:
//     point, spot and directional lights are delta lights, area lights keep their `samples`
//     points with Whitted's falloff), so switching integrators never changes direct lighting;
//   - the ambient light is not added (the background and the surfaces light the scene);
//   - after that direct term, a material whose kd + ks + kr + kt exceeds 1 in a channel has the
//     four scaled down together to a sum of 1 there (energy conservation for the indirect light
//     and the sky and emitter samples);
//   - the path goes on along one lobe chosen with probability proportional to its strength
//     (largest component of kd, ks, kr, kt): kd by cosine-weighted sampling (f = kd/π, estimator
//     kd), ks by sampling the normalised modified Phong lobe about the mirror direction
//     (f = ks·(s+2)/(2π)·cos^s α, pdf (s+1)/(2π)·cos^s α, estimator ks·(s+2)/(s+1)·cos θ), kr and
//     kt as specular lobes with their blur cones, each divided by the lobe's probability;
//   - from render.min_depth hits on, Russian roulette ends the path with probability
//     1 − min(1, max component of its throughput) and divides the survivors by the rest;
//   - fog, linear in what lies behind it, fades each segment: L += T·(1 − f)·fog; T *= f;
//   - camera rays and the rays of kr/kt lobes reached from the camera by kr/kt lobes only see the
//     area lights as surfaces of radiance colour × intensity (Scene::lightSurfaces) and end there;
//     once a path has taken a kd or ks lobe its rays pass them (their light, through glass too,
//     is in every later hit's direct term), and so do all shadow rays (as under Whitted).
// Sample dimensions at each hit (the stream of the path there): 2 the lobe direction, 3 the lobe
// choice (x) and the roulette (y), 4 + i area light i as in Whitted's, 2^30 + 1 the environment
// direction; the next hit's stream is branch(2, 1, 0). The same bytes on any thread count, crop and
// MPI split.
constexpr std::uint32_t kPathDirectionDimension = kReflectionDimension;
constexpr std::uint32_t kPathChoiceDimension = kRefractionDimension;
// A blurred specular lobe tries this many cone directions (consecutive points of its dimension)
// for one on the side of the surface of its ideal direction, as traceLobe keeps only those; after
// as many misses it takes the ideal direction.
constexpr std::uint32_t kPathConeTries = 8;

// Direction of a Phong lobe about the unit `axis` with exponent s: cos α = u^(1/(s+1)), density
// (s+1)/(2π)·cos^s α over the sphere of directions.
Vec3 samplePhongLobe(const Vec3& axis, double exponent, const Point2& u) {
  Vec3 tangent;
  Vec3 bitangent;
  orthonormalBasis(axis, tangent, bitangent);
  const double cosAlpha = std::pow(u.x, 1 / (exponent + 1));
  const double sinAlpha = std::sqrt(std::max(0.0, 1 - cosAlpha * cosAlpha));
  const double phi = 2 * std::numbers::pi * u.y;
  return tangent * (std::cos(phi) * sinAlpha) + bitangent * (std::sin(phi) * sinAlpha) +
         axis * cosAlpha;
}

// One direction of a specular lobe about `ideal` with blur cone `blurDegrees` (0: `ideal`), on the
// same side of the geometric surface n as `ideal`.
Vec3 specularLobeDirection(const Vec3& ideal, double blurDegrees, const Normal3& n,
                           const SampleStream& stream) {
  if (!(blurDegrees > 0)) return ideal;
  const double cosMax = std::cos(std::min(blurDegrees, 180.0) * std::numbers::pi / 180.0);
  Vec3 tangent;
  Vec3 bitangent;
  orthonormalBasis(ideal, tangent, bitangent);
  const SobolDimension2D directions = stream.dimension(kPathDirectionDimension);
  const double idealSide = dot(n, ideal);
  for (std::uint32_t k = 0; k < kPathConeTries; ++k) {
    const Vec3 w = sampleCone(ideal, tangent, bitangent, cosMax,
                              directions.at(stream.subIndex(kPathConeTries, k)));
    if (dot(n, w) * idealSide > 0) return w;
  }
  return ideal;
}

// The power heuristic (Veach, β = 2): the weight of a sample drawn with density `own` when another
// strategy would have drawn it with density `other`.
double powerHeuristic(double own, double other) {
  const double a = own * own;
  return a / (a + other * other);
}

// The weight of a light sample (next-event estimation) drawn with density lightPdf, which the
// BRDF would have drawn with density brdfPdf.
double lightSampleWeight(const TraceContext& ctx, double lightPdf, double brdfPdf) {
  switch (ctx.lightSampling) {
    case PathLightSampling::LightsOnly:
      return 1;
    case PathLightSampling::BrdfOnly:
      return 0;
    case PathLightSampling::Mis:
      break;
  }
  return powerHeuristic(lightPdf, brdfPdf);
}

// The weight of a BRDF sample (density brdfPdf) that met a light the light samples draw with
// density lightPdf (0: they never draw it, and the BRDF sample counts in full).
double brdfSampleWeight(const TraceContext& ctx, double brdfPdf, double lightPdf) {
  switch (ctx.lightSampling) {
    case PathLightSampling::LightsOnly:
      return lightPdf > 0 ? 0 : 1;
    case PathLightSampling::BrdfOnly:
      return 1;
    case PathLightSampling::Mis:
      break;
  }
  return powerHeuristic(brdfPdf, lightPdf);
}

// The diffuse and glossy part of the normalised Phong BRDF at one hit, and the density with which
// the path's lobe choice draws a direction from those two lobes. On a smooth surface (shading
// normal ≠ geometric) both are folded (foldAboveSurface): at a direction above the geometric
// surface, the lobe's value there plus its value at the direction's mirror image below it.
struct PhongLobes {
  const Material& material;
  const Vec3& up;         // shading normal on the side the path arrived from
  const Vec3& reflected;  // mirror direction of the view ray
  double diffuseShare;    // probability of the diffuse lobe (its strength / all lobes')
  double glossyShare;     // probability of the Phong lobe
  const Normal3& n;       // geometric normal
  bool smooth;            // the shading normal differs from n

  // f(wi)·cos θ and the density, for wi above the geometric surface.
  Color weighted(const Vec3& wi, double& pdf) const {
    pdf = 0;
    Color f = unfolded(wi, pdf);
    if (smooth) f += unfolded(foldAboveSurface(wi, n), pdf);
    return f;
  }

 private:
  // The lobes' own f(wi)·cos θ, their density added to pdf; zero below the shading surface.
  Color unfolded(const Vec3& wi, double& pdf) const {
    const double cosTheta = dot(up, wi);
    if (!(cosTheta > 0)) return Color();
    Color f;
    if (diffuseShare > 0) {
      f += material.kd * std::numbers::inv_pi;
      pdf += diffuseShare * cosTheta * std::numbers::inv_pi;
    }
    if (glossyShare > 0) {
      const double lobe = std::pow(std::max(0.0, dot(reflected, wi)), material.shininess);
      f += material.ks * ((material.shininess + 2) * lobe / (2 * std::numbers::pi));
      pdf += glossyShare * (material.shininess + 1) * lobe / (2 * std::numbers::pi);
    }
    return f * cosTheta;
  }
};

// Next-event estimation toward the image environment: one direction drawn by luminance, its
// radiance if no surface is in the way, weighted against the BRDF's samples by the power
// heuristic. `side` is +1 when the path arrived on n's side.
Color environmentLight(const TraceContext& ctx, const PhongLobes& lobes, const Normal3& n,
                       double side, SpawnOrigins& origins, const SampleStream& stream) {
  double lightPdf = 0;
  const Vec3 wi = ctx.environment->sample(stream.get2D(kEnvironmentDimension), lightPdf);
  if (!(lightPdf > 0) || !(dot(n, wi) * side > 0)) return Color();
  double brdfPdf = 0;
  const Color f = lobes.weighted(wi, brdfPdf);
  if (isBlack(f)) return Color();
  ++ctx.counts.shadow;
  // Any surface blocks it: light through glass reaches the hit along the glass's own lobes.
  Hit blocker;
  if (ctx.scene.intersect(origins.spawn(wi), kInfinity, blocker)) return Color();
  return f * ctx.scene.backgroundAlong(wi) * (lightSampleWeight(ctx, lightPdf, brdfPdf) / lightPdf);
}

// Next-event estimation toward the emissive surfaces: one point drawn by luminance per area, its
// emission if nothing is in the way, weighted against the BRDF's samples by the power heuristic.
Color emitterLight(const TraceContext& ctx, const PhongLobes& lobes, const Point3& p,
                   const Normal3& n, double side, SpawnOrigins& origins,
                   const SampleStream& stream) {
  const EmitterSampler::Sample light = ctx.emitters->sample(stream.get2D(kEmitterDimension));
  const Vec3 toLight = light.point - p;
  const double distance2 = dot(toLight, toLight);
  if (!(distance2 > 0)) return Color();
  const double distance = std::sqrt(distance2);
  const Vec3 wi = toLight / distance;
  // Emitters shine from both sides, as they show from both.
  const double cosLight = std::abs(dot(light.normal, wi));
  if (!(cosLight > 0) || !(dot(n, wi) * side > 0)) return Color();
  double brdfPdf = 0;
  const Color f = lobes.weighted(wi, brdfPdf);
  if (isBlack(f)) return Color();
  // The density over solid angle at the hit: the area density × d² / cos θ at the light.
  const double lightPdf = light.areaPdf * distance2 / cosLight;
  ++ctx.counts.shadow;
  // Anything before the point blocks it (the last millionth of the way is left out, so that the
  // emitter's own surface, a rounding error away from the point, does not).
  Hit blocker;
  const Ray shadowRay = origins.spawn(wi);
  if (ctx.scene.intersect(shadowRay, distance * (1 - 1e-6), blocker)) return Color();
  return f * light.emission * (lightSampleWeight(ctx, lightPdf, brdfPdf) / lightPdf);
}

// The radiance along a camera ray (unit direction) by path tracing; see above.
Color tracePath(const TraceContext& ctx, const Ray& cameraRay, const SampleStream& cameraStream,
                const RayDifferential* differential) {
  const Scene& scene = ctx.scene;
  Color radiance;
  Color throughput(1);
  Ray ray = cameraRay;
  SampleStream stream = cameraStream;
  Hit& hit = ctx.hits[0];  // one hit at a time: nothing refers to the previous one
  // The media the path is inside (nested media only: else it stays empty and unread).
  MediumStack media = scene.cameraMedia();
  // The density with which the diffuse and glossy lobes drew `ray` (PhongLobes), for multiple
  // importance sampling where it meets the image environment; 0 for camera rays and specular
  // lobes, which the environment's samples never stand in for.
  double brdfPdf = 0;
  // Camera rays and specular chains from them see the area lights (Scene::lightSurfaces); paths
  // past a diffuse or glossy lobe do not (the lights' direct term already counts their light).
  bool seesLights = true;
  // Fog over a segment of length t (scene units) of the path at `depth`: what lies behind fades.
  const auto fogSegment = [&](double t, int depth) {
    const Fog& fog = *scene.fog();
    const bool viewDepth = fog.distance == FogDistance::Depth && depth == 0;
    const double f =
        fog.visibility(viewDepth ? t * dot(ray.direction, scene.camera().toward()) : t);
    radiance += throughput * fog.color * (1 - f);
    throughput *= f;
  };
  for (int depth = 0;; ++depth) {
    const bool found = ctx.nested ? scene.intersect(ray, kInfinity, hit, media)
                                  : scene.intersect(ray, kInfinity, hit);
    if (seesLights && !scene.lightSurfaces().empty()) {
      // The nearest area light in front of the hit is what the ray sees; a light reflects
      // nothing, so the path ends there.
      double nearest = found ? hit.t : kInfinity;
      const Color* lamp = nullptr;
      for (const Scene::LightSurface& surface : scene.lightSurfaces()) {
        ShapeHit lightHit;
        const bool crossed = std::visit(
            [&](const auto& shape) { return shape.intersect(ray, 0, nearest, lightHit); },
            surface.shape);
        if (crossed) {
          nearest = lightHit.t;
          lamp = &surface.radiance;
        }
      }
      if (lamp != nullptr) {
        if (ctx.fog) fogSegment(nearest, depth);
        radiance += throughput * *lamp;
        break;
      }
    }
    if (!found) {
      if (ctx.fog && scene.fog()->distance == FogDistance::Ray) {
        radiance += throughput * scene.fog()->color;
      } else if (ctx.uniformBackground) {
        radiance += throughput * scene.background();
      } else {
        const double misWeight =
            brdfPdf > 0 && ctx.environment != nullptr
                ? brdfSampleWeight(ctx, brdfPdf, ctx.environment->pdf(ray.direction))
                : 1;
        radiance += throughput * scene.backgroundSeenBy(ray) * misWeight;
      }
      break;
    }
    if (ctx.fog) fogSegment(hit.t, depth);
    // The hit's material, emission and shading normal, textures and vertex colours applied.
    TexturedHit textured;
    if (ctx.textured) {
      shadeTexturedHit(scene, hit, depth == 0 ? differential : nullptr, textured);
    } else {
      textured.material = scene.materialOf(hit);
      textured.emission = scene.emissionOf(hit);
      textured.shadingNormal = hit.shadingNormal;
    }
    Material& material = textured.material;
    if (takesVertexColours(ctx, hit)) {
      const Color tint = scene.aggregate().vertexColor(hit);
      material.kd *= tint;
      material.ka *= tint;
    }
    if (brdfPdf > 0 && ctx.emitters != nullptr && !isBlack(textured.emission)) {
      // Met by a BRDF sample: weighted against the emitter samples that could have drawn it.
      const double areaPdf = ctx.emitters->areaPdf(hit, scene.emissionOf(hit));
      const double cosLight = std::abs(dot(hit.normal, ray.direction));
      const double lightPdf = areaPdf > 0 && cosLight > 0 ? areaPdf * hit.t * hit.t / cosLight : 0;
      radiance += throughput * textured.emission * brdfSampleWeight(ctx, brdfPdf, lightPdf);
    } else {
      radiance += throughput * textured.emission;
    }

    const Point3& p = hit.point;
    const Normal3& n = hit.normal;
    const Vec3& v = ray.direction;
    const double nv = dot(n, v);
    const Normal3& ns = facingShadingNormal(textured.shadingNormal, n, v, nv);
    const double nsv = dot(ns, v);
    SpawnOrigins origins(p, hit.pointError, n);
    radiance +=
        throughput * directLight(ctx,
                                 ShadingPoint{material, p, n, ns, v, nv, !isBlack(material.ks),
                                              origins, ctx.nested ? &media : nullptr},
                                 stream, false);
    if (depth + 1 >= ctx.maxDepth) break;

    // Past the lights' direct term a surface passes on at most the light it receives: materials
    // written for Whitted's model often have kd + ks + kr + kt above 1 (ks there is only the
    // lights' highlight), which would make every bounce add light and glass glow. Their lobes
    // are scaled down together to a sum of 1 in the strongest channel.
    const double lobeSum = maxComponent(material.kd + material.ks + material.kr + material.kt);
    if (lobeSum > 1) {
      const double conserve = 1 / lobeSum;
      material.kd *= conserve;
      material.ks *= conserve;
      material.kr *= conserve;
      material.kt *= conserve;
    }

    // One lobe, chosen by strength.
    const double diffuse = maxComponent(material.kd);
    const double glossy = maxComponent(material.ks);
    const double mirror = maxComponent(material.kr);
    const double transmit = maxComponent(material.kt);
    const double total = diffuse + glossy + mirror + transmit;
    if (!(total > 0)) break;
    const Point2 choice = stream.get2D(kPathChoiceDimension);
    const double pick = choice.x * total;
    const double side = nv < 0 ? 1 : -1;  // +1: the path arrived on n's side
    const bool smooth = !(ns == n);
    const Vec3 reflected = mirrorDirection(v, n, ns, nv, nsv, smooth);
    const Vec3 up = toVec(ns) * side;
    const PhongLobes lobes{material, up, reflected, diffuse / total, glossy / total, n, smooth};
    const bool sampleLights =
        diffuse + glossy > 0 && ctx.lightSampling != PathLightSampling::BrdfOnly;
    if (ctx.environment != nullptr && sampleLights) {
      radiance += throughput * environmentLight(ctx, lobes, n, side, origins, stream);
    }
    if (ctx.emitters != nullptr && sampleLights) {
      radiance += throughput * emitterLight(ctx, lobes, p, n, side, origins, stream);
    }
    Vec3 w;
    Color factor;
    brdfPdf = 0;
    // Only specular chains from the camera see the area lights: after a diffuse or glossy bounce
    // their light is in that hit's direct term, shadow rays through glass included (a kt chain
    // reaching a lamp would count it twice, and as fireflies).
    seesLights = seesLights && pick >= diffuse + glossy;
    if (pick < diffuse + glossy) {
      const Point2 u = stream.get2D(kPathDirectionDimension);
      if (pick < diffuse) {
        Vec3 tangent;
        Vec3 bitangent;
        orthonormalBasis(up, tangent, bitangent);
        w = sampleCosineHemisphere(up, tangent, bitangent, u);
        factor = material.kd * (total / diffuse);
      } else {
        w = samplePhongLobe(reflected, material.shininess, u);
        const double cosTheta = dot(up, w);
        if (!(cosTheta > 0)) break;  // below the surface: the BRDF is zero there
        factor = material.ks * ((material.shininess + 2) / (material.shininess + 1) * cosTheta *
                                (total / glossy));
      }
      if (!(dot(n, w) * side > 0)) {
        // Below the geometric surface (only where the shading normal tilts): folded back above.
        w = foldAboveSurface(w, n);
        if (!(dot(n, w) * side > 0)) break;
      }
      if (ctx.environment != nullptr || ctx.emitters != nullptr) lobes.weighted(w, brdfPdf);
      ++ctx.counts.indirect;
    } else if (pick < diffuse + glossy + mirror) {
      w = specularLobeDirection(reflected, material.reflectionBlur, n, stream);
      factor = material.kr * (total / mirror);
      ++ctx.counts.reflection;
    } else {
      const bool entering = nv < 0;
      MediumStack beyond;
      const double eta = ctx.nested ? scene.boundaryAt(hit, v, media, beyond).eta()
                                    : airRelativeIndex(material.ior, entering);
      const Vec3 transmitted = transmittedDirection(eta, v, n, ns, nv, smooth, reflected, entering);
      w = specularLobeDirection(transmitted, material.refractionBlur, n, stream);
      // A ray that crosses the surface is inside the media beyond it; one that totally reflects
      // stays.
      if (ctx.nested && dot(n, w) * nv > 0) media = beyond;
      factor = material.kt * (total / transmit);
      ++ctx.counts.refraction;
    }
    throughput *= factor;
    if (depth + 1 >= ctx.minDepth) {
      const double survive = std::min(1.0, maxComponent(throughput));
      if (!(choice.y < survive)) break;
      throughput = throughput / survive;
    }
    if (isBlack(throughput)) break;
    ray = origins.spawn(w);
    stream = stream.branch(kPathDirectionDimension, 1, 0);
  }
  return radiance;
}

// Shading assumes a unit view direction. Camera rays are unit already up to rounding; normalising
// here anyway keeps render() and traceRay() bit-identical for the same ray.
Color traceCameraRay(const TraceContext& ctx, const Ray& ray, const SampleStream& stream,
                     const RayDifferential* differential = nullptr) {
  ++ctx.counts.camera;
  if (ctx.path) {
    return tracePath(ctx, Ray{ray.origin, normalize(ray.direction)}, stream, differential);
  }
  return trace(ctx, Ray{ray.origin, normalize(ray.direction)}, ctx.scene.cameraMedia(), 0, Color(1),
               false, stream, differential);
}

// The per-depth hits a TraceContext points into (one allocation per tile, not per ray): one per
// depth a path can reach, at most kPreallocatedDepths (the default max_depth is 10; scene files
// allow up to 1000, and a scene built in code any value).
constexpr int kPreallocatedDepths = 64;
// On cache lines of its own (core/cache_line.h): written on every ray, while other threads read
// the scene.
using HitStorage = std::vector<Hit, CacheLineAllocator<Hit>>;
HitStorage hitStorage(const Scene& scene) {
  return HitStorage(
      static_cast<std::size_t>(std::clamp(scene.render().maxDepth, 1, kPreallocatedDepths)));
}

bool hasVertexColors(const Scene& scene) {
  return std::any_of(scene.meshes().begin(), scene.meshes().end(),
                     [](const TriangleMesh& mesh) { return !mesh.colors.empty(); });
}

TraceContext makeContext(const Scene& scene, RayCounts& counts, HitStorage& hits) {
  const RenderSettings& settings = scene.render();
  return TraceContext{scene,
                      counts,
                      settings.maxDepth,
                      settings.minWeight,
                      static_cast<std::uint32_t>(std::max(settings.blurSamples, 1)),
                      hits.data(),
                      static_cast<int>(hits.size()),
                      scene.hasTextures(),
                      scene.uniformBackground(),
                      hasVertexColors(scene),
                      scene.fog().has_value(),
                      settings.ambientOcclusion ? &*settings.ambientOcclusion : nullptr,
                      settings.integrator == Integrator::Path,
                      scene.environmentSampler(),
                      scene.emitterSampler(),
                      settings.lightSampling,
                      settings.minDepth,
                      samplesPerPixel(scene.image()).minimum,
                      scene.nestedMedia()};
}

PixelRegion validatedRegion(const Scene& scene, const RenderOptions& options) {
  const int width = scene.image().width;
  const int height = scene.image().height;
  if (!options.crop) return PixelRegion{0, 0, width, height};
  const PixelRegion& c = *options.crop;
  if (c.x0 < 0 || c.y0 < 0 || c.x1 > width || c.y1 > height || c.x0 >= c.x1 || c.y0 >= c.y1) {
    throw std::invalid_argument("crop region [" + std::to_string(c.x0) + ", " +
                                std::to_string(c.y0) + ") – [" + std::to_string(c.x1) + ", " +
                                std::to_string(c.y1) + ") must be non-empty and inside the " +
                                std::to_string(width) + "×" + std::to_string(height) + " image");
  }
  return c;
}

// Paints the seed's printGrid over the film: pixels whose absolute column or row is a multiple of
// the interval, so a cropped render shows the same grid lines as the full image.
void paintGrid(Film& film, const GridOverlay& grid) {
  if (grid.interval <= 0) return;
  const PixelRegion& region = film.region();
  for (int y = region.y0; y < region.y1; ++y) {
    for (int x = region.x0; x < region.x1; ++x) {
      if (x % grid.interval == 0 || y % grid.interval == 0) {
        film.at(x - region.x0, y - region.y0) = grid.color;
      }
    }
  }
}

// How many samples each pixel takes.
struct SamplingPlan {
  std::uint32_t initial = 1;  // every pixel takes these first
  std::uint32_t maximum = 1;  // adaptive: the cap; otherwise = initial
  std::uint32_t batch = 1;    // adaptive: samples added per refinement step
  double threshold = 0;       // adaptive: the standard error to reach, linear color units
  bool adaptive = false;
  bool jitter = false;  // false: the single sample goes through the pixel centre (DESIGN.md §4)
  // Whether any sample dimension is ever drawn (jitter, a lens, an area light, a glossy lobe).
  // Without one the pixel's stream key is never read, and its hash is skipped.
  bool drawsSamples = true;
};

SamplingPlan samplingPlan(const ImageSettings& image) {
  SamplingPlan plan;
  const auto samples = static_cast<std::uint32_t>(std::max(image.samples, 1));
  plan.initial = plan.maximum = samples;
  plan.jitter = samples > 1;
  if (image.adaptive) {
    plan.adaptive = true;
    plan.jitter = true;
    plan.maximum =
        std::max(samples, static_cast<std::uint32_t>(std::max(image.adaptive->maxSamples, 1)));
    plan.initial = std::min(std::max(samples, kMinAdaptiveSamples), plan.maximum);
    plan.batch = plan.initial;
    plan.threshold = image.adaptive->threshold;
  }
  return plan;
}

// Whether a render of `scene` under `plan` reads any sampler dimension (see the layout at the top
// of this file): a jittered pixel offset, a thin lens, ambient occlusion, an area light or a glossy
// lobe.
// Conservative: a blurred material counts even where its lobe is never traced.
bool drawsSamples(const Scene& scene, const SamplingPlan& plan) {
  if (plan.jitter || scene.camera().hasLens() || scene.render().ambientOcclusion ||
      scene.render().integrator == Integrator::Path) {
    return true;
  }
  for (const Light& light : scene.lights()) {
    if (std::holds_alternative<AreaLight>(light)) return true;
  }
  for (const Material& material : scene.materials()) {
    if (material.reflectionBlur > 0 || material.refractionBlur > 0) return true;
  }
  return false;
}

// The largest per-channel standard error of the mean of n samples with sums Σx and Σx²:
// sqrt(s² / n) with the unbiased sample variance s² = (Σx² − (Σx)²/n) / (n − 1).
double standardError(const Color& sum, const Color& sumSquares, std::uint32_t n) {
  if (n < 2) return kInfinity;
  const double count = n;
  const auto channel = [count](double s, double s2) {
    return std::max(0.0, s2 - s * s / count) / ((count - 1) * count);
  };
  return std::sqrt(std::max(
      {channel(sum.r, sumSquares.r), channel(sum.g, sumSquares.g), channel(sum.b, sumSquares.b)}));
}

// The running sums of one pixel's samples: Σx, Σx² (adaptive sampling only) and their number.
struct PixelSamples {
  Color sum;
  Color sumSquares;
  std::uint32_t n = 0;
  std::uint64_t nonFinite = 0;  // samples that were not finite (counted as black)
};

// Where a pixel's camera rays come from: the pixel's sample stream and its two camera dimensions,
// the same for every sample of the pixel.
class PixelCamera {
 public:
  PixelCamera(const TraceContext& ctx, const SamplingPlan& plan, int column, int row,
              std::uint64_t seed)
      : camera_(&ctx.scene.camera()),
        column_(column),
        row_(row),
        jitter_(plan.jitter),
        lensed_(camera_->hasLens()),
        // A render that draws no sample never reads the key: its hash is skipped.
        pixel_(plan.drawsSamples ? SampleStream::forPixel(static_cast<std::uint32_t>(column),
                                                          static_cast<std::uint32_t>(row), 0, seed)
                                 : SampleStream()),
        // Dimensions nobody reads are not drawn: the pixel offset of an unjittered sample (the
        // pixel centre) and the lens point of a pinhole camera (generateRay ignores it).
        offsets_(jitter_ ? pixel_.dimension(kPixelDimension) : SobolDimension2D(0)),
        lens_(lensed_ ? pixel_.dimension(kLensDimension) : SobolDimension2D(0)) {}

  SampleStream stream(std::uint32_t n) const { return SampleStream(pixel_.key(), n); }
  Point2 offset(std::uint32_t n) const { return jitter_ ? offsets_.at(n) : Point2{0.5, 0.5}; }
  Point2 lensPoint(std::uint32_t n) const { return lensed_ ? lens_.at(n) : Point2{0.5, 0.5}; }
  // Sample n's camera ray.
  Ray ray(std::uint32_t n) const {
    return camera_->generateRay(column_, row_, offset(n), lensPoint(n));
  }

 private:
  const Camera* camera_;
  int column_;
  int row_;
  bool jitter_;
  bool lensed_;
  SampleStream pixel_;
  SobolDimension2D offsets_;
  SobolDimension2D lens_;
};

// Adds a sample's value to the pixel's sums; a non-finite one counts as black and is counted.
void addSample(const SamplingPlan& plan, Color value, PixelSamples& samples) {
  if (!isFinite(value)) {
    value = Color{};
    ++samples.nonFinite;
  }
  samples.sum += value;
  if (plan.adaptive) samples.sumSquares += value * value;
}

// Adds the pixel's samples n … target − 1 to `samples`. Sample s uses the sampler stream
// (pixel, s, seed); non-finite samples count as black and are counted. `cancel` is polled before
// every sample (one relaxed load beside a whole camera path), so a pixel of millions of rays still
// stops within one sample; false when it did.
bool addSamples(const TraceContext& ctx, const SamplingPlan& plan, int column, int row,
                std::uint64_t seed, const std::atomic<bool>* cancel, PixelSamples& samples,
                std::uint32_t target) {
  const Camera& camera = ctx.scene.camera();
  const PixelCamera pixel(ctx, plan, column, row, seed);
  for (std::uint32_t& n = samples.n; n < target; ++n) {
    if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return false;
    const SampleStream stream = pixel.stream(n);
    const Ray ray = pixel.ray(n);
    Color value;
    if (ctx.textured) {
      const Point2 offset = pixel.offset(n);
      const Point2 lensPoint = pixel.lensPoint(n);
      // The rays through the same point of the pixels to the right and below, same lens point.
      const RayDifferential differential = cameraDifferential(
          ray, camera.generateRay(column, row, Point2{offset.x + 1, offset.y}, lensPoint),
          camera.generateRay(column, row, Point2{offset.x, offset.y + 1}, lensPoint),
          ctx.samplesPerPixel);
      value = traceCameraRay(ctx, ray, stream, &differential);
    } else {
      value = traceCameraRay(ctx, ray, stream);
    }
    addSample(plan, value, samples);
  }
  return true;
}

// Whether renderBlock may take the pixels of a tile: a fixed number of samples per pixel under the
// Whitted integrator, in a scene without nested media (whose camera rays pass boundaries) or
// textures (whose camera rays carry differentials).
bool rendersInBlocks(const TraceContext& ctx, const SamplingPlan& plan) {
  return !plan.adaptive && !ctx.path && !ctx.nested && !ctx.textured;
}

// The shadow rays of a packet's hits (rays[k] found hits[k] when found[k]) toward each of the
// first kPacketLights lights that is not an area light, traced as one packet per light
// (Aggregate::transmittancePacket) into `shadows`: the rays shadeLightSample would trace at those
// hits, with their light samples (the same computations as directLight's and shadeLightSample's,
// on the same hit: directLight checks that by the hit point's address). A hit whose material has
// nothing for a light to act on gets none.
void tracePacketShadows(const TraceContext& ctx, const Ray* rays, const Hit* hits,
                        const bool* found, int count, PacketShadows& shadows) {
  const std::vector<Light>& lights = ctx.scene.lights();
  const std::size_t lightCount = std::min(lights.size(), kPacketLights);
  std::array<std::optional<SpawnOrigins>, Aggregate::kPacketSize> origins;
  std::array<double, Aggregate::kPacketSize> nv;
  std::uint32_t lit = 0;  // bit k: lane k's hit takes light
  for (int k = 0; k < count; ++k) {
    const auto lane = static_cast<std::size_t>(k);
    shadows.rayOf[lane].fill(PacketShadows::kNone);
    shadows.pointOf[lane] = nullptr;
    if (!found[k]) continue;
    const Hit& hit = hits[k];
    // traceFound passes the rays on to the plain shading only.
    if (takesVertexColours(ctx, hit)) continue;
    const Material& material = ctx.scene.materialOf(hit);
    if (isBlack(material.kd) && isBlack(material.ks)) continue;
    origins[lane].emplace(hit.point, hit.pointError, hit.normal);
    nv[lane] = dot(hit.normal, rays[k].direction);
    shadows.pointOf[lane] = &hit.point;
    lit |= 1u << k;
  }
  if (lit == 0) return;
  for (std::size_t i = 0; i < lightCount; ++i) {
    const Light& light = lights[i];
    if (std::holds_alternative<AreaLight>(light)) continue;
    Point3 position;
    const bool positioned = lightPosition(light, position);
    PacketShadows::LightPacket& packet = shadows.lights[i];
    int rayCount = 0;
    for (std::uint32_t bits = lit; bits != 0; bits &= bits - 1) {
      const auto lane = static_cast<std::size_t>(std::countr_zero(bits));
      const Point3& p = hits[lane].point;
      // As directLight samples the light and shadeLightSample tests the side.
      const auto* point = std::get_if<PointLight>(&light);
      const auto r = static_cast<std::size_t>(rayCount);
      LightSample& sample = packet.samples[r];
      sample = point != nullptr ? illuminate(*point, p) : illuminate(light, p);
      if (isBlack(sample.intensity)) {
        shadows.rayOf[lane][i] = PacketShadows::kBlack;
        continue;
      }
      if (!(dot(hits[lane].normal, sample.toPoint) * nv[lane] > 0)) {
        shadows.rayOf[lane][i] = PacketShadows::kAway;
        continue;
      }
      packet.rays[r] = lightShadowRay(*origins[lane], sample.toPoint,
                                      positioned ? &position : nullptr, packet.tMax[r]);
      shadows.rayOf[lane][i] = static_cast<std::uint8_t>(rayCount++);
    }
    ctx.scene.aggregate().transmittancePacket(packet.rays.data(), rayCount, 0, packet.tMax.data(),
                                              packet.transmittance.data());
  }
}

// The mirror reflection rays shadeHit would trace from a packet's camera hits (of weight 1,
// unblurred, kr worth tracing), traced as one packet (Aggregate::intersectPacket) into `ahead`,
// and their hits' shadow rays as tracePacketShadows traces them. trace() takes these hits for
// exactly these rays; it traces any other ray itself.
void traceCameraReflections(const TraceContext& ctx, const Ray* rays, const Hit* hits,
                            const bool* found, int count, BlockAhead& ahead) {
  ahead.reflectionOfLane.fill(BlockAhead::kNone);
  if (ctx.maxDepth <= 1) return;
  int reflections = 0;
  for (int k = 0; k < count; ++k) {
    if (!found[k]) continue;
    const Hit& hit = hits[k];
    // traceFound's plain shading only (its own material and shading normal).
    if (takesVertexColours(ctx, hit)) continue;
    const Material& material = ctx.scene.materialOf(hit);
    Color branchWeight;
    if (material.reflectionBlur > 0 ||
        !worthTracing(material.kr, Color(1), ctx.minWeight, branchWeight)) {
      continue;
    }
    // As shadeHit computes it.
    const Normal3& n = hit.normal;
    const Vec3& v = rays[k].direction;
    const double nv = dot(n, v);
    const Normal3& ns = facingShadingNormal(hit.shadingNormal, n, v, nv);
    const Vec3 reflected = mirrorDirection(v, n, ns, nv, dot(ns, v), !(ns == n));
    SpawnOrigins origins(hit.point, hit.pointError, n);
    const auto r = static_cast<std::size_t>(reflections);
    ahead.reflectionRays[r] = origins.spawn(reflected);
    ahead.reflectionOfLane[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(reflections++);
  }
  if (reflections == 0) return;
  std::array<double, Aggregate::kPacketSize> tMax;
  tMax.fill(kInfinity);
  ctx.scene.aggregate().intersectPacket(ahead.reflectionRays.data(), reflections, 0, tMax.data(),
                                        ahead.reflectionHits.data(), ahead.reflectionFound.data());
  tracePacketShadows(ctx, ahead.reflectionRays.data(), ahead.reflectionHits.data(),
                     ahead.reflectionFound.data(), reflections, ahead.reflectionShadows);
}

// The pixels [x0, x0 + width) × [y0, y0 + height) of a tile (at most 4 × 4), sample by sample:
// the camera rays of one sample of all of them are traced as one packet
// (Aggregate::intersectPacket), their hits' shadow rays toward each light as one more
// (tracePacketShadows), their mirror reflections as one more and those hits' shadow rays likewise
// (traceCameraReflections), and each pixel shaded from its hit. The same rays, hits, values and
// sums as addSamples gives each pixel alone (a pixel's samples are added in the same order), so
// the image does not change; the packets only walk the tree once for the block's coherent rays.
// samples[(y − y0)·4 + (x − x0)] receives pixel (x, y)'s; ctx.ahead (not null) is the scratch.
// False when cancelled (polled per sample, as addSamples does).
bool renderBlock(const TraceContext& ctx, const SamplingPlan& plan, int x0, int y0, int width,
                 int height, std::uint64_t seed, const std::atomic<bool>* cancel,
                 std::array<PixelSamples, Aggregate::kPacketSize>& samples) {
  BlockAhead& ahead = *ctx.ahead;
  constexpr int kSide = 4;
  static_assert(kSide * kSide == Aggregate::kPacketSize);
  std::array<std::optional<PixelCamera>, Aggregate::kPacketSize> pixels;
  std::array<std::size_t, Aggregate::kPacketSize> slotOf;  // lane → samples slot
  int count = 0;
  for (int y = y0; y < y0 + height; ++y) {
    for (int x = x0; x < x0 + width; ++x) {
      pixels[static_cast<std::size_t>(count)].emplace(ctx, plan, x, y, seed);
      slotOf[static_cast<std::size_t>(count)] =
          static_cast<std::size_t>((y - y0) * kSide + (x - x0));
      ++count;
    }
  }
  std::array<Ray, Aggregate::kPacketSize> rays;
  std::array<double, Aggregate::kPacketSize> tMax;
  tMax.fill(kInfinity);
  std::array<Hit, Aggregate::kPacketSize> hits;
  std::array<bool, Aggregate::kPacketSize> found{};
  for (std::uint32_t n = 0; n < plan.initial; ++n) {
    if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return false;
    for (std::size_t k = 0; k < static_cast<std::size_t>(count); ++k) {
      // As traceCameraRay gives it to trace().
      const Ray ray = pixels[k]->ray(n);
      rays[k] = Ray{ray.origin, normalize(ray.direction)};
    }
    ctx.scene.aggregate().intersectPacket(rays.data(), count, 0, tMax.data(), hits.data(),
                                          found.data());
    tracePacketShadows(ctx, rays.data(), hits.data(), found.data(), count, ahead.cameraShadows);
    traceCameraReflections(ctx, rays.data(), hits.data(), found.data(), count, ahead);
    for (std::size_t k = 0; k < static_cast<std::size_t>(count); ++k) {
      ++ctx.counts.camera;
      ahead.lane = k;
      const Color value =
          traceFound(ctx, rays[k], ctx.scene.cameraMedia(), 0, Color(1), false,
                     pixels[k]->stream(n), nullptr, found[k], hits[k], &ahead.cameraShadows, k);
      PixelSamples& pixel = samples[slotOf[k]];
      addSample(plan, value, pixel);
      ++pixel.n;
    }
  }
  return true;
}

// The mean of a pixel's samples.
Color pixelEstimate(const PixelSamples& samples) {
  return samples.sum / static_cast<double>(samples.n);
}

// The estimate of one pixel: the mean of its samples. Without adaptive sampling, exactly
// image.samples samples. Adaptive (image.adaptive): `initial` samples (already in `samples`),
// then batches of `batch` more while the largest per-channel standard error of the pixel's mean
// (from the sample variance of its own samples, linear color) exceeds the threshold, up to
// `maximum`. The first decision also looks at `neighbourError`, the largest standard error of
// the first batches of the pixel's eight neighbours: a pixel whose own first samples happen to
// agree (a speckle on a blurred edge, a sliver of a penumbra) goes on when its neighbours are
// noisy. Every first batch is a pure function of its pixel, so the decision is the same on any
// thread count, tile schedule, crop or MPI split. (With stratified Sobol samples the sample
// variance overestimates the mean's true error: the rule errs toward more samples.) False when
// cancelled, leaving `color` unset.
bool finishPixel(const TraceContext& ctx, const SamplingPlan& plan, int column, int row,
                 std::uint64_t seed, const std::atomic<bool>* cancel, PixelSamples& samples,
                 double neighbourError, Color& color) {
  if (!addSamples(ctx, plan, column, row, seed, cancel, samples, plan.initial)) return false;
  if (plan.adaptive) {
    bool first = true;
    while (samples.n < plan.maximum) {
      const double error = standardError(samples.sum, samples.sumSquares, samples.n);
      if (!(error > plan.threshold) && !(first && neighbourError > plan.threshold)) break;
      first = false;
      if (!addSamples(ctx, plan, column, row, seed, cancel, samples,
                      std::min(samples.n + plan.batch, plan.maximum))) {
        return false;
      }
    }
  }
  color = pixelEstimate(samples);
  return true;
}

// The first batches of adaptive sampling over a tile and the one-pixel ring around it (inside
// the image; the ring's pixels belong to other tiles, and their batches are recomputed here, the
// same bits), and the neighbour error finishPixel reads for each pixel of the tile.
class FirstBatches {
 public:
  FirstBatches(const PixelRegion& tile, int imageWidth, int imageHeight)
      : x0_(std::max(tile.x0 - 1, 0)),
        y0_(std::max(tile.y0 - 1, 0)),
        x1_(std::min(tile.x1 + 1, imageWidth)),
        y1_(std::min(tile.y1 + 1, imageHeight)),
        samples_(static_cast<std::size_t>(x1_ - x0_) * static_cast<std::size_t>(y1_ - y0_)),
        errors_(samples_.size()) {}

  // Renders them; false when cancelled.
  bool render(const TraceContext& ctx, const SamplingPlan& plan, std::uint64_t seed,
              const std::atomic<bool>* cancel) {
    for (int row = y0_; row < y1_; ++row) {
      for (int column = x0_; column < x1_; ++column) {
        PixelSamples& s = samples_[index(column, row)];
        if (!addSamples(ctx, plan, column, row, seed, cancel, s, plan.initial)) return false;
        errors_[index(column, row)] = standardError(s.sum, s.sumSquares, s.n);
      }
    }
    return true;
  }
  PixelSamples& at(int column, int row) { return samples_[index(column, row)]; }
  // The largest first-batch standard error of the pixel's eight neighbours inside the image.
  double neighbourError(int column, int row) const {
    double largest = 0;
    for (int y = std::max(row - 1, y0_); y <= std::min(row + 1, y1_ - 1); ++y) {
      for (int x = std::max(column - 1, x0_); x <= std::min(column + 1, x1_ - 1); ++x) {
        if (x != column || y != row) largest = std::max(largest, errors_[index(x, y)]);
      }
    }
    return largest;
  }

 private:
  std::size_t index(int column, int row) const {
    return static_cast<std::size_t>(row - y0_) * static_cast<std::size_t>(x1_ - x0_) +
           static_cast<std::size_t>(column - x0_);
  }
  int x0_, y0_, x1_, y1_;
  // Written per sample by this tile's thread: on cache lines of their own, as the hits are.
  std::vector<PixelSamples, CacheLineAllocator<PixelSamples>> samples_;
  std::vector<double, CacheLineAllocator<double>> errors_;
};

}  // namespace

Color traceRay(const Scene& scene, const Ray& ray, Rng& rng, RayCounts* counts) {
  RayCounts local;
  RayCounts& target = counts ? *counts : local;
  HitStorage hits = hitStorage(scene);
  const TraceContext ctx = makeContext(scene, target, hits);
  return traceCameraRay(ctx, ray, SampleStream(rng.nextBits(), 0));
}

SamplesPerPixel samplesPerPixel(const ImageSettings& image) {
  const SamplingPlan plan = samplingPlan(image);
  return SamplesPerPixel{static_cast<int>(plan.initial), static_cast<int>(plan.maximum)};
}

PixelWork estimatePixelWork(const ImageSettings& image, const RenderSettings& render,
                            const std::vector<Light>& lights,
                            const std::vector<Material>& materials, int pathLightRays) {
  PixelWork work;
  work.samples = static_cast<std::uint64_t>(samplesPerPixel(image).maximum);
  for (const Light& light : lights) {
    const auto* area = std::get_if<AreaLight>(&light);
    work.shadowRaysPerHit += area ? static_cast<std::uint64_t>(std::max(area->samples, 1)) : 1;
  }
  bool secondary = false;  // some material reflects or transmits: paths go on to max_depth
  bool branching = false;  // some material does both: a path forks at every such hit
  bool glossy = false;
  double strongest = 0;  // the largest kr or kt component: how slowly a branch's weight falls
  for (const Material& material : materials) {
    const bool reflects = !isBlack(material.kr);
    const bool transmits = !isBlack(material.kt);
    secondary = secondary || reflects || transmits;
    branching = branching || (reflects && transmits);
    glossy = glossy || material.reflectionBlur > 0 || material.refractionBlur > 0;
    strongest = std::max({strongest, maxComponent(material.kr), maxComponent(material.kt)});
  }
  if (render.ambientOcclusion) {
    work.shadowRaysPerHit += static_cast<std::uint64_t>(render.ambientOcclusion->samples);
  }
  work.glossyRaysPerHit = glossy ? static_cast<std::uint64_t>(std::max(render.blurSamples, 1)) : 0;
  int depth = secondary ? std::max(render.maxDepth, 1) : 1;
  // A branch stops once its weight, at most strongest^k after k bounces, is below min_weight.
  if (secondary && strongest < 1 && render.minWeight > 0) {
    const double bounces = std::floor(std::log(render.minWeight) / std::log(strongest));
    if (bounces + 1 < depth) depth = static_cast<int>(std::max(0.0, bounces)) + 1;
  }
  work.depth = depth;
  // A forking path visits up to 2^depth − 1 hits (capped far above any warning threshold).
  work.hitsPerSample = branching ? std::exp2(std::min(depth, 200)) - 1 : depth;
  if (render.integrator == Integrator::Path) {
    // One path of up to max_depth hits, one ray on from each.
    work.depth = std::max(render.maxDepth, 1);
    work.hitsPerSample = work.depth;
    work.glossyRaysPerHit = 1;
    work.shadowRaysPerHit += static_cast<std::uint64_t>(std::max(pathLightRays, 0));
  }
  return work;
}

std::vector<PixelRegion> tileRegions(const PixelRegion& region, int tileSize) {
  if (tileSize <= 0) throw std::invalid_argument("tile size must be > 0");
  std::vector<PixelRegion> tiles;
  for (int y0 = region.y0; y0 < region.y1; y0 += tileSize) {
    for (int x0 = region.x0; x0 < region.x1; x0 += tileSize) {
      tiles.push_back(PixelRegion{x0, y0, std::min(x0 + tileSize, region.x1),
                                  std::min(y0 + tileSize, region.y1)});
    }
  }
  return tiles;
}

Film render(const Scene& scene, const RenderOptions& options, RenderStats* stats) {
  Film film(scene.image().width, scene.image().height, validatedRegion(scene, options));
  renderInto(scene, options, film, stats);
  return film;
}

void renderInto(const Scene& scene, const RenderOptions& options, Film& film, RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const PixelRegion region = validatedRegion(scene, options);
  if (options.threads < 0) throw std::invalid_argument("thread count must be ≥ 0");
  if (film.region() != region || film.fullWidth() != scene.image().width ||
      film.fullHeight() != scene.image().height)
    throw std::invalid_argument("the film covers a different image or region than the render");
  const std::vector<PixelRegion> tiles = tileRegions(region, options.tileSize);
  const std::size_t tileCount = tiles.size();
  if (options.tiles) {
    std::vector<bool> listed(tileCount, false);
    for (const std::size_t tile : *options.tiles) {
      if (tile >= tileCount || listed[tile])
        throw std::invalid_argument("the tiles to render must be distinct tile indices");
      listed[tile] = true;
    }
  }
  const bool resuming = options.resumeFilm != nullptr && options.resumeTiles != nullptr;
  if (resuming && (options.resumeFilm->region() != region ||
                   options.resumeFilm->fullWidth() != scene.image().width ||
                   options.resumeFilm->fullHeight() != scene.image().height ||
                   options.resumeTiles->size() != tileCount)) {
    throw std::invalid_argument("the film to resume from covers a different image or region");
  }

  const ImageSettings& image = scene.image();
  SamplingPlan plan = samplingPlan(image);
  plan.drawsSamples = drawsSamples(scene, plan);
  const std::uint64_t seed = scene.render().seed;

  std::atomic<std::uint64_t> cameraRays{0}, shadowRays{0}, reflectionRays{0}, refractionRays{0},
      indirectRays{0};
  std::atomic<std::uint64_t> pixelSamples{0};
  std::atomic<std::uint64_t> nonFinite{0};
  std::atomic<bool> cancelled{false};
  std::mutex progressMutex;  // guards tilesDone, firstNonFinite and the callbacks
  std::size_t tilesDone = 0;
  std::size_t tilesResumed = 0;
  std::optional<PixelCoord> firstNonFinite;
  const auto before = [](const PixelCoord& a, const PixelCoord& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  };

  if (resuming) {
    for (std::size_t tile = 0; tile < tileCount; ++tile) {
      if (!(*options.resumeTiles)[tile]) continue;
      const PixelRegion& t = tiles[tile];
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) {
          film.at(x - region.x0, y - region.y0) =
              options.resumeFilm->at(x - region.x0, y - region.y0);
        }
      }
      ++tilesResumed;
    }
    tilesDone = tilesResumed;
  }

  auto renderTile = [&](std::size_t tile) {
    if (resuming && (*options.resumeTiles)[tile]) return;
    if (cancelled.load(std::memory_order_relaxed)) return;
    if (options.cancel && options.cancel->load()) {
      cancelled.store(true);
      return;
    }
    const int x0 = tiles[tile].x0;
    const int y0 = tiles[tile].y0;
    const int x1 = tiles[tile].x1;
    const int y1 = tiles[tile].y1;
    RayCounts counts;
    HitStorage hits = hitStorage(scene);
    const TraceContext ctx = makeContext(scene, counts, hits);
    std::uint64_t tileNonFinite = 0;
    std::uint64_t tileSamples = 0;
    std::optional<PixelCoord> tileFirstNonFinite;
    bool abandoned = false;
    std::optional<FirstBatches> firstBatches;  // adaptive sampling only
    if (plan.adaptive) {
      firstBatches.emplace(tiles[tile], scene.image().width, scene.image().height);
      if (!firstBatches->render(ctx, plan, seed, options.cancel)) {
        cancelled.store(true);
        abandoned = true;
      }
    }
    // A finished pixel's samples and non-finite samples count for the tile.
    const auto account = [&](int column, int row, const PixelSamples& samples) {
      tileSamples += samples.n;
      if (samples.nonFinite > 0 &&
          (!tileFirstNonFinite || before(PixelCoord{column, row}, *tileFirstNonFinite))) {
        tileFirstNonFinite = PixelCoord{column, row};
      }
      tileNonFinite += samples.nonFinite;
    };
    if (rendersInBlocks(ctx, plan)) {
      // Blocks of 4 × 4 pixels, their camera rays traced as packets (renderBlock). The scratch
      // of what it traces ahead on cache lines of its own, as the hits are.
      const auto ahead = std::make_unique<BlockAhead>();
      TraceContext blockContext = ctx;
      blockContext.ahead = ahead.get();
      for (int row = y0; row < y1 && !abandoned; row += 4) {
        for (int column = x0; column < x1; column += 4) {
          const int width = std::min(4, x1 - column);
          const int height = std::min(4, y1 - row);
          std::array<PixelSamples, Aggregate::kPacketSize> block{};
          // Another thread's stop, polled per block; the caller's cancel flag per sample.
          if (cancelled.load(std::memory_order_relaxed) ||
              !renderBlock(blockContext, plan, column, row, width, height, seed, options.cancel,
                           block)) {
            cancelled.store(true);
            abandoned = true;
            break;
          }
          for (int y = row; y < row + height; ++y) {
            for (int x = column; x < column + width; ++x) {
              const PixelSamples& samples =
                  block[static_cast<std::size_t>((y - row) * 4 + (x - column))];
              film.at(x - region.x0, y - region.y0) = pixelEstimate(samples);
              account(x, y, samples);
            }
          }
        }
      }
    } else {
      for (int row = y0; row < y1 && !abandoned; ++row) {
        for (int column = x0; column < x1; ++column) {
          // Another thread's stop, polled per pixel; the caller's cancel flag is polled per
          // sample inside finishPixel.
          PixelSamples own;
          PixelSamples& samples = firstBatches ? firstBatches->at(column, row) : own;
          const double neighbourError =
              firstBatches ? firstBatches->neighbourError(column, row) : 0.0;
          if (cancelled.load(std::memory_order_relaxed) ||
              !finishPixel(ctx, plan, column, row, seed, options.cancel, samples, neighbourError,
                           film.at(column - region.x0, row - region.y0))) {
            cancelled.store(true);
            abandoned = true;
            break;
          }
          account(column, row, samples);
        }
      }
    }
    // The rays of an abandoned tile were traced and count; its pixels are dropped and it is not
    // reported as finished.
    cameraRays += counts.camera;
    shadowRays += counts.shadow;
    reflectionRays += counts.reflection;
    refractionRays += counts.refraction;
    indirectRays += counts.indirect;
    if (abandoned) return;
    nonFinite += tileNonFinite;
    pixelSamples += tileSamples;
    const std::lock_guard<std::mutex> lock(progressMutex);
    if (tileFirstNonFinite && (!firstNonFinite || before(*tileFirstNonFinite, *firstNonFinite))) {
      firstNonFinite = tileFirstNonFinite;
    }
    ++tilesDone;
    if (options.tileFinished) options.tileFinished(tile, film, -1);
    if (options.progress) options.progress(tilesDone, tileCount);
  };

  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  if (options.nextTile) {
    // One puller per thread of the arena; a tile index out of range is the feed's bug.
    arena.execute([&] {
      tbb::task_group pullers;
      for (int i = 0; i < arena.max_concurrency(); ++i) {
        pullers.run([&] {
          while (const std::optional<std::size_t> tile = options.nextTile()) {
            if (*tile >= tileCount) throw std::invalid_argument("the tile feed gave no tile index");
            renderTile(*tile);
          }
        });
      }
      pullers.wait();
    });
  } else {
    const std::size_t count = options.tiles ? options.tiles->size() : tileCount;
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) {
                            renderTile(options.tiles ? (*options.tiles)[i] : i);
                          }
                        });
    });
  }

  if (image.grid) paintGrid(film, *image.grid);

  if (stats) {
    stats->rays.camera = cameraRays.load();
    stats->samples = pixelSamples.load();
    stats->rays.shadow = shadowRays.load();
    stats->rays.reflection = reflectionRays.load();
    stats->rays.refraction = refractionRays.load();
    stats->rays.indirect = indirectRays.load();
    stats->nonFinite = nonFinite.load();
    stats->firstNonFinite = firstNonFinite;
    stats->tilesResumed = tilesResumed;
    stats->cancelled = cancelled.load();
    stats->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
}

}  // namespace glint
