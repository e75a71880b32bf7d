#include "glint/scene/scene_limits.h"

#include <unistd.h>

#include <limits>

#include <fmt/format.h>

#include "glint/core/color.h"

namespace glint {

std::uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return 0;
  const auto p = static_cast<std::uint64_t>(pages);
  const auto s = static_cast<std::uint64_t>(pageSize);
  if (p > std::numeric_limits<std::uint64_t>::max() / s)
    return std::numeric_limits<std::uint64_t>::max();
  return p * s;
}

std::uint64_t defaultImageMemoryBudget() {
  const std::uint64_t physical = physicalMemoryBytes();
  return physical == 0 ? (std::uint64_t{8} << 30) : physical / 2;
}

std::uint64_t filmBytes(std::int64_t width, std::int64_t height) {
  if (width <= 0 || height <= 0) return 0;
  const auto w = static_cast<std::uint64_t>(width);
  const auto h = static_cast<std::uint64_t>(height);
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  if (w > kMax / h) return kMax;
  const std::uint64_t pixels = w * h;
  if (pixels > kMax / sizeof(Color)) return kMax;
  return pixels * sizeof(Color);
}

std::optional<std::string> checkRenderSize(std::int64_t width, std::int64_t height,
                                           std::int64_t samples, std::uint64_t memoryBudget) {
  if (width < 1 || width > kMaxImageSide || height < 1 || height > kMaxImageSide) {
    return fmt::format("image size must be between 1 and {} pixels per side, got {} × {}",
                       kMaxImageSide, width, height);
  }
  if (samples < 1 || samples > kMaxSamplesPerPixel) {
    return fmt::format("samples per pixel must be between 1 and {}, got {}", kMaxSamplesPerPixel,
                       samples);
  }
  const std::uint64_t bytes = filmBytes(width, height);
  if (bytes > memoryBudget) {
    const bool isDefault = memoryBudget == defaultImageMemoryBudget();
    return fmt::format(
        "an image of {} × {} pixels needs {} for its film, more than the memory budget of {}{}",
        width, height, formatBytes(static_cast<double>(bytes)),
        formatBytes(static_cast<double>(memoryBudget)),
        isDefault ? " (half the physical memory)" : "");
  }
  // Exact in double: each factor is below 2^17, so the product stays below 2^50 < 2^53.
  const double rays =
      static_cast<double>(width) * static_cast<double>(height) * static_cast<double>(samples);
  if (rays > kMaxCameraRays) {
    return fmt::format(
        "an image of {} × {} pixels with {} samples per pixel needs {} camera rays, more than the "
        "limit of {}",
        width, height, samples, formatCount(rays), formatCount(kMaxCameraRays));
  }
  return std::nullopt;
}

std::optional<std::string> checkImageSettings(const ImageSettings& image,
                                              std::uint64_t memoryBudget) {
  return checkRenderSize(image.width, image.height, image.samples, memoryBudget);
}

std::string formatBytes(double bytes) {
  static constexpr const char* kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return fmt::format("{:.0f} B", bytes);
  int unit = -1;
  while (bytes >= 1024 && unit < 5) {
    bytes /= 1024;
    ++unit;
  }
  return fmt::format("{:.1f} {}", bytes, kUnits[unit]);
}

std::string formatCount(double count) {
  static constexpr struct {
    double scale;
    const char* name;
  } kNames[] = {{1e12, "trillion"}, {1e9, "billion"}, {1e6, "million"}, {1e3, "thousand"}};
  if (count >= 1e15) return fmt::format("{:.1e}", count);
  for (const auto& n : kNames) {
    if (count >= n.scale) return fmt::format("{:.1f} {}", count / n.scale, n.name);
  }
  return fmt::format("{:.0f}", count);
}

}  // namespace glint
