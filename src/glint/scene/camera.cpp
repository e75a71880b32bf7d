// Camera frame, view plane and primary rays (DESIGN.md §4), pinhole and thin lens.
#include "glint/scene/camera.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "glint/core/sampling.h"

namespace glint {

namespace {

// up is rejected when the sine of its angle to direction is below this: the re-orthogonalised up
// would then be dominated by the rounding of the projection (and a user almost surely meant a
// different up). 1e-6 rad is 0.2 arc seconds.
constexpr double kParallelSine = 1e-6;

std::string str(const Vec3& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }

void requireFinite(double value, const char* name) {
  if (!std::isfinite(value)) throw CameraError(fmt::format("camera {} must be finite", name));
}

}  // namespace

Camera::Camera(const CameraSpec& spec)
    : position_(spec.position),
      aperture_(spec.aperture),
      focusDistance_(spec.focusDistance),
      imageWidth_(spec.imageWidth),
      imageHeight_(spec.imageHeight),
      orthographic_(spec.orthographic) {
  if (!isFinite(spec.position)) throw CameraError("camera position must be finite");
  if (!isFinite(spec.direction)) throw CameraError("camera direction must be finite");
  if (!isFinite(spec.up)) throw CameraError("camera up must be finite");
  requireFinite(spec.viewPlaneWidth, "view plane width");
  requireFinite(spec.viewPlaneHeight, "view plane height");
  requireFinite(spec.viewPlaneDistance, "view plane distance");
  requireFinite(spec.fovDegrees, "fov");
  requireFinite(spec.aperture, "aperture");
  requireFinite(spec.focusDistance, "focus distance");

  const double directionLength = length(spec.direction);
  if (!(directionLength > 0)) {
    throw CameraError("camera direction must be non-zero, got " + str(spec.direction));
  }
  const double upLength = length(spec.up);
  if (!(upLength > 0)) throw CameraError("camera up must be non-zero, got " + str(spec.up));

  // Gram–Schmidt: keep vTo, remove its component from vUp.
  toward_ = spec.direction / directionLength;
  const Vec3 upOrthogonal = spec.up - toward_ * dot(spec.up, toward_);
  const double upOrthogonalLength = length(upOrthogonal);
  if (!(upOrthogonalLength > kParallelSine * upLength)) {
    throw CameraError("camera up " + str(spec.up) + " is parallel to direction " +
                      str(spec.direction) + "; up must point away from the view direction");
  }
  up_ = upOrthogonal / upOrthogonalLength;
  right_ = cross(toward_, up_);

  if (spec.imageWidth < 1 || spec.imageHeight < 1) {
    throw CameraError(fmt::format("image size must be at least 1×1 pixels, got {}×{}",
                                  spec.imageWidth, spec.imageHeight));
  }

  if (spec.orthographic) {
    if (spec.fovDegrees != 0 || spec.aperture != 0) {
      throw CameraError("an orthographic camera has no fov and no aperture");
    }
    if (!(spec.viewPlaneWidth > 0 && spec.viewPlaneHeight > 0)) {
      throw CameraError(fmt::format(
          "an orthographic camera needs a view plane with width and height > 0 (got {}, {})",
          spec.viewPlaneWidth, spec.viewPlaneHeight));
    }
    width_ = spec.viewPlaneWidth;
    height_ = spec.viewPlaneHeight;
    distance_ = 0;
  } else if (spec.fovDegrees != 0) {
    if (!(spec.fovDegrees > 0 && spec.fovDegrees < 180)) {
      throw CameraError(
          fmt::format("camera fov must be in (0, 180) degrees, got {}", spec.fovDegrees));
    }
    distance_ = 1;
    height_ = 2 * std::tan(spec.fovDegrees * (std::numbers::pi / 360));
    width_ = height_ * spec.imageWidth / spec.imageHeight;
  } else {
    if (!(spec.viewPlaneWidth > 0 && spec.viewPlaneHeight > 0 && spec.viewPlaneDistance > 0)) {
      throw CameraError(fmt::format(
          "camera needs a view plane with width, height and distance > 0 (got {}, {}, {}) or a fov",
          spec.viewPlaneWidth, spec.viewPlaneHeight, spec.viewPlaneDistance));
    }
    width_ = spec.viewPlaneWidth;
    height_ = spec.viewPlaneHeight;
    distance_ = spec.viewPlaneDistance;
  }

  pitchX_ = width_ / imageWidth_;
  pitchY_ = height_ / imageHeight_;

  if (spec.aperture < 0) {
    throw CameraError(fmt::format("camera aperture must be >= 0, got {}", spec.aperture));
  }
  if (spec.aperture > 0 && !(spec.focusDistance > 0)) {
    throw CameraError(fmt::format(
        "camera focus distance must be > 0 when the aperture is > 0, got {}", spec.focusDistance));
  }
}

Ray Camera::generateRay(int column, int row, const Point2& pixelOffset,
                        const Point2& lensSample) const {
  // Offsets from the view-plane centre Pc = p0 + d·vTo, in scene units along vRight and vUp; the
  // pixel centre (offset 0.5) gives DESIGN.md §4's xJ = (j − (nX−1)/2)·Rx exactly.
  const double rx = pitchX_;
  const double ry = pitchY_;
  const double xj = (column + pixelOffset.x - 0.5 - (imageWidth_ - 1) / 2.0) * rx;
  const double yi = -(row + pixelOffset.y - 0.5 - (imageHeight_ - 1) / 2.0) * ry;
  if (orthographic_) return Ray{position_ + right_ * xj + up_ * yi, toward_};
  // Pc + xJ·vRight + yI·vUp − p0, formed without the round trip through world positions.
  const Vec3 direction = normalize(toward_ * distance_ + right_ * xj + up_ * yi);
  if (aperture_ <= 0) return Ray{position_, direction};

  // Thin lens: every ray of this pixel passes through the point where the pinhole ray meets the
  // plane focusDistance along vTo, so that plane is sharp.
  const Point3 focus = position_ + direction * (focusDistance_ / dot(direction, toward_));
  const Point2 disk = sampleConcentricDisk(lensSample);
  const Point3 lens = position_ + (right_ * disk.x + up_ * disk.y) * aperture_;
  return Ray{lens, normalize(focus - lens)};
}

}  // namespace glint
