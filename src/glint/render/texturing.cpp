// Ray differentials, texture evaluation, normal and bump mapping at a hit (pbrt-v4's
// SurfaceInteraction::ComputeDifferentials, BumpMap and NormalMap, in glint's terms).
#include "glint/render/texturing.h"

#include <algorithm>
#include <cmath>

#include "glint/geometry/surface_coordinates.h"

namespace glint {

namespace {

// Derivatives larger than this (per pixel) are clamped, as pbrt-v4 does: a grazing footprint is
// huge anyway and picks the coarsest mip level.
constexpr double kLargestDerivative = 1e8;
// pbrt-v4's smallest step of (u, v) for a bump map's finite differences when the footprint gives
// none.
constexpr double kBumpStep = 0.0005;

// The offset ray (o, d) meets the tangent plane through p with normal n at p + dp.
bool footprint(const Point3& p, const Normal3& n, const Point3& o, const Vec3& d, Vec3& dp) {
  const double t = dot(n, p - o) / dot(n, d);
  if (!std::isfinite(t)) return false;
  dp = (o + d * t) - p;
  return isFinite(dp);
}

double tameDerivative(double d) {
  return std::isfinite(d) ? std::clamp(d, -kLargestDerivative, kLargestDerivative) : 0;
}

// The surface at a hit in world space, and the object-space point and u, v directions that solid
// textures and bump offsets use.
struct SurfaceFrame {
  SurfaceCoordinates world;
  Point3 objectPoint;
  Vec3 objectDpdu;
  Vec3 objectDpdv;
};

// The frame at a hit of the scene's own primitives and meshes, or (local) at a hit inside an
// instance's group, in the group's space.
SurfaceFrame frameAtLocal(const Scene& scene, const Hit& hit) {
  SurfaceFrame f;
  if (hit.mesh != kNoMesh) {
    const TriangleMesh& mesh = scene.meshOf(hit);
    f.world = surfaceCoordinates(mesh, hit.triangle, hit.point);
    f.objectPoint = hit.point;
    f.objectDpdu = f.world.dpdu;
    f.objectDpdv = f.world.dpdv;
    if (mesh.worldFromObject) {
      const Transform objectFromWorld = mesh.worldFromObject->inverse();
      f.objectPoint = objectFromWorld(hit.point);
      f.objectDpdu = objectFromWorld(f.world.dpdu);
      f.objectDpdv = objectFromWorld(f.world.dpdv);
    }
    return f;
  }
  const Primitive& primitive = scene.primitiveOf(hit);
  const Transform* worldFromObject = primitive.worldFromObject();
  f.objectPoint = worldFromObject ? worldFromObject->inverse()(hit.point) : hit.point;
  f.world = surfaceCoordinates(primitive.shape(), f.objectPoint, hit.part);
  f.objectDpdu = f.world.dpdu;
  f.objectDpdv = f.world.dpdv;
  if (worldFromObject) {
    const Transform& t = *worldFromObject;
    SurfaceCoordinates& w = f.world;
    w.dpdu = t(w.dpdu);
    w.dpdv = t(w.dpdv);
    w.tangent = t(w.tangent);
    w.bitangent = t(w.bitangent);
    // Normals map by the inverse transpose; their derivatives likewise (to first order, exact for
    // rotations and uniform scales).
    w.dndu = toVec(t(Normal3(w.dndu)));
    w.dndv = toVec(t(Normal3(w.dndv)));
  }
  return f;
}

// On an instance: the frame in its group's space at the group-space point, its vectors then
// carried to world space (normal derivatives by the inverse transpose, as for a transformed
// primitive). The object point stays the group object's own, so solid textures follow the instance.
SurfaceFrame frameAt(const Scene& scene, const Hit& hit) {
  if (hit.instance == kNoInstance) return frameAtLocal(scene, hit);
  const InstanceSet& instances = *scene.aggregate().instances();
  Hit local = hit;
  local.point = instances.groupPoint(hit.instance, hit.point);
  SurfaceFrame f = frameAtLocal(scene, local);
  SurfaceCoordinates& w = f.world;
  w.dpdu = instances.worldVector(hit.instance, w.dpdu);
  w.dpdv = instances.worldVector(hit.instance, w.dpdv);
  w.tangent = instances.worldVector(hit.instance, w.tangent);
  w.bitangent = instances.worldVector(hit.instance, w.bitangent);
  w.dndu = toVec(instances.worldNormal(hit.instance, Normal3(w.dndu)));
  w.dndv = toVec(instances.worldNormal(hit.instance, Normal3(w.dndv)));
  return f;
}

Color lookup(const Scene& scene, TextureId id, const TextureLookup& at) {
  return evaluate(scene.textures()[id], at);
}

// A bump map's height at a lookup, scene units.
double heightAt(const Scene& scene, const MaterialTextures& b, const TextureLookup& at) {
  const Color c = lookup(scene, b.bumpMap, at);
  return (c.r + c.g + c.b) / 3 * b.bumpScale;
}

// The shading normal a tangent-space normal map gives: RGB ↦ 2·RGB − 1 along (t, b, n), with t the
// surface's tangent made orthogonal to n and b = n × t turned to the side of the bitangent.
Normal3 normalMapped(const Normal3& n, const SurfaceCoordinates& sc, const Color& c) {
  const Vec3 nv = toVec(n);
  Vec3 t = sc.tangent - nv * dot(nv, sc.tangent);
  if (!(lengthSquared(t) > 0)) return n;
  t = normalize(t);
  Vec3 b = cross(nv, t);
  if (dot(b, sc.bitangent) < 0) b = -b;
  const Vec3 m = t * (2 * c.r - 1) + b * (2 * c.g - 1) + nv * (2 * c.b - 1);
  const double len = length(m);
  return len > 0 && std::isfinite(len) ? Normal3(m / len) : n;
}

// pbrt-v4's BumpMap: the surface displaced along n by the height, its tangents by finite
// differences of the height over half the footprint in u and v.
Normal3 bumpMapped(const Scene& scene, const MaterialTextures& b, const Normal3& n,
                   const SurfaceFrame& f, const TextureLookup& at) {
  double du = 0.5 * (std::abs(at.duvdx.x) + std::abs(at.duvdy.x));
  double dv = 0.5 * (std::abs(at.duvdx.y) + std::abs(at.duvdy.y));
  if (!(du > 0)) du = kBumpStep;
  if (!(dv > 0)) dv = kBumpStep;
  TextureLookup shiftedU = at;
  shiftedU.uv.x += du;
  shiftedU.objectPoint = at.objectPoint + f.objectDpdu * du;
  TextureLookup shiftedV = at;
  shiftedV.uv.y += dv;
  shiftedV.objectPoint = at.objectPoint + f.objectDpdv * dv;
  const double h = heightAt(scene, b, at);
  const double hu = heightAt(scene, b, shiftedU);
  const double hv = heightAt(scene, b, shiftedV);
  const Vec3 nv = toVec(n);
  const Vec3 dpdu = f.world.dpdu + nv * ((hu - h) / du) + f.world.dndu * h;
  const Vec3 dpdv = f.world.dpdv + nv * ((hv - h) / dv) + f.world.dndv * h;
  Vec3 bumped = cross(dpdu, dpdv);
  const double len = length(bumped);
  if (!(len > 0) || !std::isfinite(len)) return n;
  bumped = bumped / len;
  return Normal3(dot(bumped, nv) < 0 ? -bumped : bumped);
}

Vec3 reflectAbout(const Vec3& w, const Vec3& normal) {
  const double len = length(normal);
  if (!(len > 0)) return w;
  const Vec3 n = normal / len;
  return w - n * (2 * dot(w, n));
}

// Snell's law for the unit w through a surface whose normal `facing` points to w's side; total
// internal reflection mirrors instead.
Vec3 refractThrough(const Vec3& w, const Vec3& facingNormal, double eta) {
  const double len = length(facingNormal);
  if (!(len > 0)) return w;
  const Vec3 facing = facingNormal / len;
  const double cosIncident = -dot(facing, w);
  const double sin2 = eta * eta * std::max(0.0, 1 - cosIncident * cosIncident);
  if (sin2 >= 1) return w + facing * (2 * cosIncident);
  return w * eta + facing * (eta * cosIncident - std::sqrt(1 - sin2));
}

Vec3 unit(const Vec3& v) {
  const double len = length(v);
  return len > 0 ? v / len : v;
}

}  // namespace

RayDifferential cameraDifferential(const Ray& ray, const Ray& rx, const Ray& ry,
                                   int samplesPerPixel) {
  const double scale =
      std::max(0.125, 1 / std::sqrt(static_cast<double>(std::max(1, samplesPerPixel))));
  return {ray.origin + (rx.origin - ray.origin) * scale,
          ray.origin + (ry.origin - ray.origin) * scale,
          ray.direction + (rx.direction - ray.direction) * scale,
          ray.direction + (ry.direction - ray.direction) * scale};
}

void shadeTexturedHit(const Scene& scene, const Hit& hit, const RayDifferential* differential,
                      TexturedHit& out) {
  const Material& base = scene.materialOf(hit);
  out.material = base;
  out.emission = scene.emissionOf(hit);
  out.shadingNormal = hit.shadingNormal;
  out.hasDifferentials = false;
  out.dpdx = out.dpdy = out.dndx = out.dndy = Vec3{};
  const bool textured = base.textures != kUntextured;
  if (!textured && differential == nullptr) return;

  const SurfaceFrame f = frameAt(scene, hit);
  const SurfaceCoordinates& sc = f.world;
  TextureLookup at{f.objectPoint, sc.uv, {}, {}};
  if (differential != nullptr &&
      footprint(hit.point, hit.normal, differential->rxOrigin, differential->rxDirection,
                out.dpdx) &&
      footprint(hit.point, hit.normal, differential->ryOrigin, differential->ryDirection,
                out.dpdy)) {
    out.hasDifferentials = true;
    // (du/dx, dv/dx) by least squares from dp/dx = dp/du·du/dx + dp/dv·dv/dx (pbrt-v4).
    const double ata00 = dot(sc.dpdu, sc.dpdu);
    const double ata01 = dot(sc.dpdu, sc.dpdv);
    const double ata11 = dot(sc.dpdv, sc.dpdv);
    double inverseDet = 1 / (ata00 * ata11 - ata01 * ata01);
    if (!std::isfinite(inverseDet)) inverseDet = 0;
    const auto solve = [&](const Vec3& dp) {
      const double b0 = dot(sc.dpdu, dp);
      const double b1 = dot(sc.dpdv, dp);
      return Point2{tameDerivative((ata11 * b0 - ata01 * b1) * inverseDet),
                    tameDerivative((ata00 * b1 - ata01 * b0) * inverseDet)};
    };
    at.duvdx = solve(out.dpdx);
    at.duvdy = solve(out.dpdy);
    out.dndx = sc.dndu * at.duvdx.x + sc.dndv * at.duvdx.y;
    out.dndy = sc.dndu * at.duvdy.x + sc.dndv * at.duvdy.y;
    if (!isFinite(out.dndx) || !isFinite(out.dndy)) out.dndx = out.dndy = Vec3{};
  } else {
    out.dpdx = out.dpdy = Vec3{};
  }
  if (!textured) return;

  const MaterialTextures& b = scene.materialTextures()[base.textures];
  Material& m = out.material;
  if (b.kd != kNoTexture) m.kd = base.kd * lookup(scene, b.kd, at);
  if (b.ks != kNoTexture) m.ks = base.ks * lookup(scene, b.ks, at);
  if (b.kr != kNoTexture) m.kr = base.kr * lookup(scene, b.kr, at);
  if (b.kt != kNoTexture) m.kt = base.kt * lookup(scene, b.kt, at);
  if (b.ka != kNoTexture) m.ka = base.ka * lookup(scene, b.ka, at);
  if (b.emission != kNoTexture) out.emission = out.emission * lookup(scene, b.emission, at);
  if (b.normalMap != kNoTexture) {
    out.shadingNormal = normalMapped(out.shadingNormal, sc, lookup(scene, b.normalMap, at));
  }
  if (b.bumpMap != kNoTexture) out.shadingNormal = bumpMapped(scene, b, out.shadingNormal, f, at);
}

RayDifferential reflectedDifferential(const Point3& p, const TexturedHit& s,
                                      const RayDifferential& in, const Normal3& ns) {
  return {p + s.dpdx, p + s.dpdy, reflectAbout(unit(in.rxDirection), toVec(ns) + s.dndx),
          reflectAbout(unit(in.ryDirection), toVec(ns) + s.dndy)};
}

RayDifferential transmittedDifferential(const Point3& p, const TexturedHit& s,
                                        const RayDifferential& in, const Normal3& ns, bool entering,
                                        double eta) {
  if (eta == 1) return {p + s.dpdx, p + s.dpdy, in.rxDirection, in.ryDirection};
  const double side = entering ? 1 : -1;
  return {p + s.dpdx, p + s.dpdy,
          refractThrough(unit(in.rxDirection), (toVec(ns) + s.dndx) * side, eta),
          refractThrough(unit(in.ryDirection), (toVec(ns) + s.dndy) * side, eta)};
}

RayDifferential shiftedDifferential(const RayDifferential& ideal, const Vec3& idealDirection,
                                    const Vec3& direction) {
  return {ideal.rxOrigin, ideal.ryOrigin, direction + (ideal.rxDirection - idealDirection),
          direction + (ideal.ryDirection - idealDirection)};
}

}  // namespace glint
