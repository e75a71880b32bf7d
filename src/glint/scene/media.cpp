// The medium stack and the boundary rule of nested dielectrics (media.h).
#include "glint/scene/media.h"

#include <algorithm>

namespace glint {

void MediumStack::push(std::uint32_t medium) {
  if (size_ == kCapacity) {
    // Forget the outermost: the innermost media decide the next boundaries.
    std::copy(media_.begin() + 1, media_.end(), media_.begin());
    --size_;
  }
  media_[static_cast<std::size_t>(size_++)] = medium;
}

bool MediumStack::remove(std::uint32_t medium) {
  for (int i = size_ - 1; i >= 0; --i) {
    if (media_[static_cast<std::size_t>(i)] != medium) continue;
    std::copy(media_.begin() + i + 1, media_.begin() + size_, media_.begin() + i);
    --size_;
    return true;
  }
  return false;
}

std::uint32_t MediumStack::current(const std::vector<Material>& materials) const {
  std::uint32_t best = kNoMedium;
  int bestPriority = 0;
  // From the most recent down: a later entry wins ties.
  for (int i = size_ - 1; i >= 0; --i) {
    const std::uint32_t medium = media_[static_cast<std::size_t>(i)];
    const int priority = materials[medium].priority;
    if (best == kNoMedium || priority > bestPriority) {
      best = medium;
      bestPriority = priority;
    }
  }
  return best;
}

namespace {

double iorOf(std::uint32_t medium, const std::vector<Material>& materials) {
  return medium == kNoMedium ? 1.0 : materials[medium].ior;
}

// A boundary that is no surface: the current medium continues on both sides.
Boundary noSurface(std::uint32_t current, const std::vector<Material>& materials) {
  const double ior = iorOf(current, materials);
  return Boundary{false, ior, ior};
}

}  // namespace

Boundary crossBoundary(const MediumStack& media, std::uint32_t material, std::uint32_t medium,
                       bool entering, const std::vector<Material>& materials, MediumStack& beyond) {
  // Everything read from `media` is read before `beyond` is written: they may be one object.
  const std::uint32_t current = media.current(materials);
  const double own = materials[material].ior;
  const double around = iorOf(current, materials);
  beyond = media;
  if (medium == kNoMedium) {
    return entering ? Boundary{true, around, own} : Boundary{true, own, around};
  }
  if (entering) {
    beyond.push(medium);
    if (current != kNoMedium &&
        (current == medium || materials[medium].priority < materials[current].priority)) {
      return noSurface(current, materials);
    }
    return Boundary{true, around, own};
  }
  if (!beyond.remove(medium)) return Boundary{true, own, around};
  if (current != medium) return noSurface(current, materials);
  const std::uint32_t after = beyond.current(materials);
  if (after == medium) return noSurface(current, materials);
  return Boundary{true, own, iorOf(after, materials)};
}

}  // namespace glint
