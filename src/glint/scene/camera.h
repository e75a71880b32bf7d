// The pinhole/thin-lens camera of DESIGN.md §4 (the seed's Camera and constructRayThroughPixel).
#pragma once

#include <stdexcept>

#include "glint/core/ray.h"
#include "glint/core/vec.h"

namespace glint {

class CameraError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct CameraSpec {
  Point3 position;            // p0, the centre of projection
  Vec3 direction{0, 0, -1};   // vTo, any non-zero length
  Vec3 up{0, 1, 0};           // vUp, re-orthogonalised against vTo; parallel to vTo is an error
  double viewPlaneWidth = 0;  // scene units (set these three, or fovDegrees)
  double viewPlaneHeight = 0;
  double viewPlaneDistance = 0;
  double fovDegrees = 0;     // vertical field of view in (0, 180); if > 0, replaces the view plane
  double aperture = 0;       // lens radius, scene units; 0 = pinhole
  double focusDistance = 0;  // distance along vTo to the plane in focus (with aperture > 0)
  int imageWidth = 1;        // nX, pixels
  int imageHeight = 1;       // nY, pixels
  // Parallel rays along vTo, one from each pixel's point of the view plane placed at p0 (its
  // width × height in scene units; distance unused). No fov and no aperture.
  bool orthographic = false;
};

class Camera {
 public:
  // Validates the spec (throws CameraError with a message) and derives the orthonormal frame.
  explicit Camera(const CameraSpec& spec);

  // Ray through pixel (column j, row i; row 0 at the top). pixelOffset in [0,1)² is the position
  // inside the pixel, (0.5, 0.5) its centre; lensSample in [0,1)² picks the point on the lens when
  // aperture > 0. The direction is unit.
  Ray generateRay(int column, int row, const Point2& pixelOffset = {0.5, 0.5},
                  const Point2& lensSample = {0.5, 0.5}) const;

  const Point3& position() const { return position_; }
  const Vec3& toward() const { return toward_; }
  const Vec3& up() const { return up_; }
  const Vec3& right() const { return right_; }
  int imageWidth() const { return imageWidth_; }
  int imageHeight() const { return imageHeight_; }
  double viewPlaneWidth() const { return width_; }
  double viewPlaneHeight() const { return height_; }
  double viewPlaneDistance() const { return distance_; }
  // Whether generateRay reads its lensSample (a thin lens, aperture > 0); a pinhole camera ignores
  // it, so callers may skip drawing one.
  bool hasLens() const { return aperture_ > 0; }
  bool isOrthographic() const { return orthographic_; }

 private:
  Point3 position_;
  Vec3 toward_, up_, right_;  // unit; right = toward × up
  double width_ = 0, height_ = 0, distance_ = 0;
  double aperture_ = 0, focusDistance_ = 0;
  int imageWidth_ = 1, imageHeight_ = 1;
  bool orthographic_ = false;
  // Pixel pitch on the view plane (width_ / imageWidth_, height_ / imageHeight_), scene units:
  // computed once instead of two divisions per camera ray.
  double pitchX_ = 0, pitchY_ = 0;
};

}  // namespace glint
