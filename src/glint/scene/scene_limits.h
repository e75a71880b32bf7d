// The limits on what a scene (or the command line overriding it) may request: value ranges of the
// image and render settings (DESIGN.md §7) and the size checks that refuse an absurd render before
// anything is allocated. Shared by the scene builder and the CLI, which re-checks after its
// --width/--height/--samples overrides.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "glint/scene/scene.h"

namespace glint {

inline constexpr std::int64_t kMaxImageSide = 65535;         // pixels, width and height
inline constexpr std::int64_t kMaxSamplesPerPixel = 65536;   // image.samples
inline constexpr std::int64_t kMaxBlurSamples = 65536;       // render.blur_samples
inline constexpr std::int64_t kMaxOcclusionSamples = 65536;  // render.ambient_occlusion.samples
// render.max_depth: the renderer recurses once per surface hit, so an unbounded depth between two
// perfect mirrors (weight never falls below min_weight) would overflow a worker thread's stack.
inline constexpr std::int64_t kMaxRenderDepth = 1000;
// Camera rays (width · height · samples) a single render may ask for: 2^40 ≈ 1.1 trillion, days
// of work on any machine; beyond that the request is a typo, not a render.
inline constexpr double kMaxCameraRays = 1099511627776.0;

// Installed physical memory in bytes (sysconf), or 0 when the system does not say.
std::uint64_t physicalMemoryBytes();

// Default budget for the image buffer: half the physical memory (8 GiB when unknown).
std::uint64_t defaultImageMemoryBudget();

// Bytes of the linear film for a width × height image (width · height · sizeof(Color)), saturated
// at UINT64_MAX; non-positive sizes give 0.
std::uint64_t filmBytes(std::int64_t width, std::int64_t height);

// Why rendering width × height pixels with `samples` per pixel is refused, or std::nullopt when it
// is acceptable. Checks, in order: the ranges (sides 1..kMaxImageSide, samples
// 1..kMaxSamplesPerPixel), the film against `memoryBudget`, and the camera rays against
// kMaxCameraRays. The message has no location and names the estimate in human units, e.g.
// "an image of 65535 × 65535 pixels needs 96.0 GiB for its film, more than the memory budget of
// 11.7 GiB (half the physical memory)".
std::optional<std::string> checkRenderSize(std::int64_t width, std::int64_t height,
                                           std::int64_t samples,
                                           std::uint64_t memoryBudget = defaultImageMemoryBudget());

// checkRenderSize for the final image settings (after command-line overrides).
std::optional<std::string> checkImageSettings(
    const ImageSettings& image, std::uint64_t memoryBudget = defaultImageMemoryBudget());

// "512 B", "1.5 KiB", "96.0 GiB" (binary units).
std::string formatBytes(double bytes);
// "950", "12.5 thousand", "1.1 trillion", "2.8e+15".
std::string formatCount(double count);

}  // namespace glint
