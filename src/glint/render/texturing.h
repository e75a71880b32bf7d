// Textures at a hit (DESIGN.md §9): ray differentials (pbrt-v4's: two offset rays one pixel
// apart, scaled by the sample count) and what they give at a surface — the footprint dp/dx, dp/dy,
// (u, v) differentials, the material with its textures evaluated, normal and bump maps — and the
// differentials of the reflected and transmitted rays. Used only for scenes with textures.
#pragma once

#include "glint/core/color.h"
#include "glint/core/ray.h"
#include "glint/core/vec.h"
#include "glint/scene/scene.h"

namespace glint {

// The rays through the neighbouring pixel to the right (x) and below (y), as offsets of a ray.
struct RayDifferential {
  Point3 rxOrigin;
  Point3 ryOrigin;
  Vec3 rxDirection;
  Vec3 ryDirection;
};

// A camera ray's differential from the rays through its neighbours `rx` and `ry` (same lens
// sample), scaled toward the main ray by max(1/8, 1/√samplesPerPixel) as pbrt-v4 does: several
// samples per pixel each cover a smaller part of it.
RayDifferential cameraDifferential(const Ray& ray, const Ray& rx, const Ray& ry,
                                   int samplesPerPixel);

// The shading inputs at a hit of a textured scene.
struct TexturedHit {
  Material material;      // its coefficients with their textures evaluated
  Color emission;         // the object's emission, with its texture
  Normal3 shadingNormal;  // after normal and bump maps (unit)
  // Screen-space derivatives of the point and the shading normal (zero without differentials).
  bool hasDifferentials = false;
  Vec3 dpdx;
  Vec3 dpdy;
  Vec3 dndx;
  Vec3 dndy;
};

// Evaluates the textures of the material at `hit` (with the ray's differential, or null) into
// `out`. Also for an untextured material when `differential` is set:
// its footprint then carries on to the reflected and transmitted rays.
void shadeTexturedHit(const Scene& scene, const Hit& hit, const RayDifferential* differential,
                      TexturedHit& out);

// The differential of a ray leaving the hit along `direction`, which mirrors `v` about the unit
// normal ns (reflection) or bends through it with relative index eta (transmission; eta 1: straight
// on): the offset rays start at p + dp/dx and p + dp/dy and turn about the normal there,
// ns + dn/dx and ns + dn/dy — pbrt-v4's specular differentials, to first order.
RayDifferential reflectedDifferential(const Point3& p, const TexturedHit& s,
                                      const RayDifferential& in, const Normal3& ns);
// `entering`: the ray crosses ns against it (n·v < 0); eta is the relative index the renderer bent
// the ray with (1: straight on).
RayDifferential transmittedDifferential(const Point3& p, const TexturedHit& s,
                                        const RayDifferential& in, const Normal3& ns, bool entering,
                                        double eta);
// The same offsets moved onto another direction of the same lobe (a glossy sample).
RayDifferential shiftedDifferential(const RayDifferential& ideal, const Vec3& idealDirection,
                                    const Vec3& direction);

}  // namespace glint
