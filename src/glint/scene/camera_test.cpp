// Camera frame and primary rays against hand-computed directions (DESIGN.md §4).
#include "glint/scene/camera.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace glint {
namespace {

constexpr double kTol = 1e-14;

void expectVecNear(const Vec3& actual, const Vec3& expected, double tol = kTol) {
  EXPECT_NEAR(actual.x, expected.x, tol);
  EXPECT_NEAR(actual.y, expected.y, tol);
  EXPECT_NEAR(actual.z, expected.z, tol);
}

// Camera at the origin looking −z with up +y (so vRight = +x), view plane at `distance`.
CameraSpec lookingDownZ(int n, double size, double distance) {
  CameraSpec spec;
  spec.viewPlaneWidth = size;
  spec.viewPlaneHeight = size;
  spec.viewPlaneDistance = distance;
  spec.imageWidth = n;
  spec.imageHeight = n;
  return spec;
}

TEST(CameraTest, ThreeByThreePixelCentres) {
  const Camera camera(lookingDownZ(3, 3, 1));  // Rx = Ry = 1
  expectVecNear(camera.right(), {1, 0, 0});
  const double s3 = std::sqrt(3.0);
  const double s2 = std::sqrt(2.0);
  expectVecNear(camera.generateRay(0, 0).direction, Vec3{-1, 1, -1} / s3);   // top-left corner
  expectVecNear(camera.generateRay(2, 0).direction, Vec3{1, 1, -1} / s3);    // top-right
  expectVecNear(camera.generateRay(0, 2).direction, Vec3{-1, -1, -1} / s3);  // bottom-left
  expectVecNear(camera.generateRay(2, 2).direction, Vec3{1, -1, -1} / s3);   // bottom-right
  expectVecNear(camera.generateRay(1, 0).direction, Vec3{0, 1, -1} / s2);    // top edge
  expectVecNear(camera.generateRay(0, 1).direction, Vec3{-1, 0, -1} / s2);   // left edge
  expectVecNear(camera.generateRay(2, 1).direction, Vec3{1, 0, -1} / s2);    // right edge
  expectVecNear(camera.generateRay(1, 2).direction, Vec3{0, -1, -1} / s2);   // bottom edge
  const Ray centre = camera.generateRay(1, 1);
  EXPECT_EQ(centre.direction, camera.toward());  // exactly along vTo
  EXPECT_EQ(centre.direction, (Vec3{0, 0, -1}));
  EXPECT_EQ(centre.origin, (Point3{0, 0, 0}));
}

TEST(CameraTest, FourByFourPixelCentres) {
  const Camera camera(lookingDownZ(4, 8, 2));  // Rx = Ry = 2, xJ in {−3, −1, 1, 3}
  const double s22 = std::sqrt(22.0);
  const double s14 = std::sqrt(14.0);
  expectVecNear(camera.generateRay(0, 0).direction, Vec3{-3, 3, -2} / s22);
  expectVecNear(camera.generateRay(3, 0).direction, Vec3{3, 3, -2} / s22);
  expectVecNear(camera.generateRay(3, 3).direction, Vec3{3, -3, -2} / s22);
  expectVecNear(camera.generateRay(1, 0).direction, Vec3{-1, 3, -2} / s14);  // top edge
  expectVecNear(camera.generateRay(3, 2).direction, Vec3{3, -1, -2} / s14);  // right edge
  expectVecNear(camera.generateRay(1, 2).direction, Vec3{-1, -1, -2} / std::sqrt(6.0));
  expectVecNear(camera.generateRay(2, 1).direction, Vec3{1, 1, -2} / std::sqrt(6.0));
}

TEST(CameraTest, PixelOffsetsSpanThePixel) {
  const Camera camera(lookingDownZ(3, 3, 1));
  // Offset (0, 0) of pixel (0, 0) is the top-left corner of the view plane, (1, 1) of pixel (2, 2)
  // would be the bottom-right one.
  expectVecNear(camera.generateRay(0, 0, {0, 0}).direction, normalize(Vec3{-1.5, 1.5, -1}));
  expectVecNear(camera.generateRay(2, 2, {1, 1}).direction, normalize(Vec3{1.5, -1.5, -1}));
  // Offset (0, 0.5) of pixel (1, 1) lies on the boundary with pixel (0, 1).
  expectVecNear(camera.generateRay(1, 1, {0, 0.5}).direction, normalize(Vec3{-0.5, 0, -1}));
  expectVecNear(camera.generateRay(0, 1, {1, 0.5}).direction, normalize(Vec3{-0.5, 0, -1}));
}

TEST(CameraTest, RaysStartAtThePositionInAnyFrame) {
  CameraSpec spec = lookingDownZ(5, 2, 1);
  spec.position = {3, -4, 5};
  spec.direction = {1, 0, 0};
  spec.up = {0, 0, 1};  // vRight = x × z = −y
  const Camera camera(spec);
  expectVecNear(camera.right(), {0, -1, 0});
  const Ray r = camera.generateRay(0, 0);  // xJ = −0.8, yI = +0.8
  EXPECT_EQ(r.origin, spec.position);
  expectVecNear(r.direction, normalize(Vec3{1, 0.8, 0.8}));
}

TEST(CameraTest, NonOrthogonalUpIsReorthogonalised) {
  CameraSpec spec = lookingDownZ(3, 3, 1);
  spec.direction = {0, 0, -2};
  spec.up = {0, 1, 1};
  Camera camera(spec);
  expectVecNear(camera.toward(), {0, 0, -1});
  expectVecNear(camera.up(), {0, 1, 0});

  spec.direction = {1, 2, 3};
  spec.up = {-1, 0.5, 2};
  camera = Camera(spec);
  const Vec3 t = camera.toward();
  const Vec3 u = camera.up();
  const Vec3 r = camera.right();
  EXPECT_NEAR(length(t), 1, kTol);
  EXPECT_NEAR(length(u), 1, kTol);
  EXPECT_NEAR(length(r), 1, kTol);
  EXPECT_NEAR(dot(t, u), 0, kTol);
  EXPECT_NEAR(dot(t, r), 0, kTol);
  EXPECT_NEAR(dot(u, r), 0, kTol);
  expectVecNear(t, normalize(spec.direction));
  expectVecNear(r, cross(t, u));
  // Up stays in the plane of the given up and direction, on the given up's side.
  EXPECT_NEAR(dot(u, cross(spec.direction, spec.up)), 0, kTol);
  EXPECT_GT(dot(u, spec.up), 0);
}

TEST(CameraTest, ParallelOrZeroVectorsRejected) {
  CameraSpec spec = lookingDownZ(3, 3, 1);
  spec.up = {0, 0, 3};  // antiparallel to −z
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.up = {0, 0, -0.5};  // parallel
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.up = {1e-9, 0, 1};  // parallel within the tolerance
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.up = {1e-3, 0, 1};  // clearly not parallel
  EXPECT_NO_THROW(Camera{spec});
  spec.up = {0, 0, 0};
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.up = {0, 1, 0};
  spec.direction = {0, 0, 0};
  EXPECT_THROW(Camera{spec}, CameraError);
  try {
    spec.direction = {0, 2, 0};
    Camera camera(spec);
    ADD_FAILURE() << "parallel up accepted";
  } catch (const CameraError& e) {
    EXPECT_NE(std::string(e.what()).find("parallel"), std::string::npos) << e.what();
  }
}

TEST(CameraTest, InvalidSpecsRejected) {
  const CameraSpec good = lookingDownZ(3, 3, 1);
  EXPECT_NO_THROW(Camera{good});
  CameraSpec spec = good;
  spec.viewPlaneDistance = 0;
  EXPECT_THROW(Camera{spec}, CameraError);  // neither a full view plane nor a fov
  spec = good;
  spec.viewPlaneWidth = -1;
  EXPECT_THROW(Camera{spec}, CameraError);
  spec = good;
  spec.imageWidth = 0;
  EXPECT_THROW(Camera{spec}, CameraError);
  spec = good;
  spec.imageHeight = -3;
  EXPECT_THROW(Camera{spec}, CameraError);
  spec = good;
  spec.fovDegrees = 180;
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.fovDegrees = -10;
  EXPECT_THROW(Camera{spec}, CameraError);
  spec = good;
  spec.position.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Camera{spec}, CameraError);
  spec = good;
  spec.viewPlaneHeight = std::numeric_limits<double>::infinity();
  EXPECT_THROW(Camera{spec}, CameraError);
  spec = good;
  spec.aperture = 0.1;  // focus distance missing
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.focusDistance = -2;
  EXPECT_THROW(Camera{spec}, CameraError);
  spec.focusDistance = 2;
  EXPECT_NO_THROW(Camera{spec});
  spec.aperture = -0.1;
  EXPECT_THROW(Camera{spec}, CameraError);
}

TEST(CameraTest, FovDerivesTheViewPlane) {
  CameraSpec spec;
  spec.fovDegrees = 90;
  spec.imageWidth = 4;
  spec.imageHeight = 2;
  const Camera camera(spec);
  EXPECT_EQ(camera.viewPlaneDistance(), 1);
  EXPECT_NEAR(camera.viewPlaneHeight(), 2, kTol);  // 2·tan 45°
  EXPECT_NEAR(camera.viewPlaneWidth(), 4, kTol);   // height · 4/2
  // The top edge of the middle column boundary is fov/2 = 45° above vTo.
  expectVecNear(camera.generateRay(2, 0, {0, 0}).direction, normalize(Vec3{0, 1, -1}));
  expectVecNear(camera.generateRay(0, 1, {0, 1}).direction, normalize(Vec3{-2, -1, -1}));

  // A fov replaces a view plane given alongside it.
  spec.viewPlaneWidth = spec.viewPlaneHeight = spec.viewPlaneDistance = 7;
  spec.fovDegrees = 60;
  const Camera narrow(spec);
  EXPECT_NEAR(narrow.viewPlaneHeight(), 2 / std::sqrt(3.0), kTol);
  EXPECT_EQ(narrow.viewPlaneDistance(), 1);
}

TEST(CameraTest, ThinLensRaysOfOnePixelMeetAtTheFocusPlane) {
  CameraSpec spec;
  spec.position = {1, 2, 3};
  spec.direction = {1, -1, -2};
  spec.fovDegrees = 60;
  spec.imageWidth = 8;
  spec.imageHeight = 6;
  const Camera pinhole(spec);
  spec.aperture = 0.5;
  spec.focusDistance = 5;
  const Camera lens(spec);
  const Vec3 toward = lens.toward();

  // The point a ray reaches on the plane focusDistance along vTo.
  const auto onFocusPlane = [&](const Ray& r) {
    const double t =
        (spec.focusDistance - dot(r.origin - spec.position, toward)) / dot(r.direction, toward);
    return r.at(t);
  };
  for (const auto& [column, row] : {std::pair{3, 1}, std::pair{0, 5}, std::pair{7, 0}}) {
    const Ray reference = pinhole.generateRay(column, row, {0.3, 0.8});
    const Point3 focus = onFocusPlane(reference);
    for (const Point2 u : {Point2{0.1, 0.2}, Point2{0.9, 0.7}, Point2{0, 0.99}, Point2{0.5, 0.5}}) {
      const Ray r = lens.generateRay(column, row, {0.3, 0.8}, u);
      EXPECT_NEAR(length(r.direction), 1, kTol);
      // The lens point lies in the lens plane within the aperture.
      const Vec3 onLens = r.origin - spec.position;
      EXPECT_NEAR(dot(onLens, toward), 0, kTol);
      EXPECT_LE(length(onLens), spec.aperture + kTol);
      const Point3 p = onFocusPlane(r);
      EXPECT_NEAR(p.x, focus.x, 1e-12);
      EXPECT_NEAR(p.y, focus.y, 1e-12);
      EXPECT_NEAR(p.z, focus.z, 1e-12);
    }
    // The centre of the lens gives the pinhole ray.
    const Ray centre = lens.generateRay(column, row, {0.3, 0.8}, {0.5, 0.5});
    EXPECT_EQ(centre.origin, spec.position);
    expectVecNear(centre.direction, reference.direction);
  }
  // Different lens samples really start at different points.
  EXPECT_GT(distance(lens.generateRay(3, 1, {0.5, 0.5}, {0.1, 0.2}).origin,
                     lens.generateRay(3, 1, {0.5, 0.5}, {0.9, 0.7}).origin),
            0.3);
}

}  // namespace
}  // namespace glint
