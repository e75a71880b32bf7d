// Nested dielectrics (DESIGN.md §11): the stack of transparent solids a ray is inside, and the rule
// that decides, at a boundary, which media lie on its two sides — Schmidt and Budge's "Simple
// Nested Dielectrics in Ray Traced Images" (2002) with material priorities.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "glint/scene/material.h"

namespace glint {

// "No medium": a surface that bounds no transparent solid (an opaque one, or a flat shape), or
// air where a ray is inside nothing.
inline constexpr std::uint32_t kNoMedium = 0xffffffffu;

// The transparent solids a ray is inside, each as its material's index (a medium is a material:
// two overlapping solids of the same material are one body of it), in the order the ray entered
// them, outermost first. Fixed size, copied by value: no allocation per ray.
class MediumStack {
 public:
  // More solids inside one another than a scene plausibly nests. Entering one more forgets the
  // outermost entry; leaving that solid later is then leaving a solid the ray was not known to be
  // in (see crossBoundary).
  static constexpr int kCapacity = 8;

  bool empty() const { return size_ == 0; }
  int size() const { return size_; }
  std::uint32_t operator[](int i) const { return media_[static_cast<std::size_t>(i)]; }

  void push(std::uint32_t medium);
  // Removes the most recently entered entry of `medium`; false when it is not on the stack.
  bool remove(std::uint32_t medium);
  // The medium at the ray's position: the entry of highest Material::priority, the most recently
  // entered among equals; kNoMedium (air, index of refraction 1) when the stack is empty.
  std::uint32_t current(const std::vector<Material>& materials) const;

  friend bool operator==(const MediumStack& a, const MediumStack& b) {
    if (a.size_ != b.size_) return false;
    for (int i = 0; i < a.size_; ++i) {
      if (a[i] != b[i]) return false;
    }
    return true;
  }

 private:
  std::array<std::uint32_t, kCapacity> media_{};
  int size_ = 0;
};

// What a ray meets at a surface hit, given the media it is inside.
struct Boundary {
  // False: no surface at all — the same medium lies on both sides (a solid entered or left inside
  // another solid of the same material), or the solid is of lower priority than the medium the ray
  // is in (its boundary lies inside that medium). The ray goes on straight with `beyond`; nothing
  // is shaded and no kt applies.
  bool surface = true;
  double iorIncident = 1;  // index of refraction on the side the ray comes from
  double iorBeyond = 1;    // on the side it crosses into
  // The relative index of Snell's law for a ray crossing: sin θt = eta · sin θi.
  double eta() const { return iorIncident / iorBeyond; }
};

// The boundary a ray inside `media` meets at a hit on a surface of material index `material`,
// entering (n·v < 0: against the outward normal) or leaving it. `medium` is `material` when the
// surface bounds a transparent solid (MediumStack holds such), else kNoMedium. `beyond` receives
// the stack of a ray that crosses the surface (a transmitted ray, or one that passes a boundary
// that is no surface); a ray that reflects keeps `media`. `beyond` may be `media` itself.
//   - A surface that bounds no medium (a flat shape) is a surface between the current medium and
//     its own material's ior; crossing it changes no medium.
//   - Entering solid M: no surface when the current medium C is M or has a higher priority;
//     otherwise the boundary from C (air when none) into M. M is pushed either way.
//   - Leaving solid M that is on the stack: its entry is removed; no surface when M is not the
//     current medium (something of higher priority, or entered later with equal priority, owns the
//     point) or when the medium after it is M again; otherwise the boundary from M into the new
//     current medium.
//   - Leaving solid M that is not on the stack (the ray started inside it unknown, or it was
//     forgotten past kCapacity): the boundary from M into the current medium, which stays.
// In air with one solid this is the classic rule: entering ior 1 → M.ior, leaving M.ior → 1.
Boundary crossBoundary(const MediumStack& media, std::uint32_t material, std::uint32_t medium,
                       bool entering, const std::vector<Material>& materials, MediumStack& beyond);

}  // namespace glint
