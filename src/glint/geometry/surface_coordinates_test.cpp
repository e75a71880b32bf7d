// Each shape's (u, v) at known points (DESIGN.md §9 and surface_coordinates.h), the derivatives
// against finite differences, and mesh uvs and tangents.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "glint/geometry/surface_coordinates.h"

namespace glint {
namespace {

constexpr double kTol = 1e-12;

void expectUv(const SurfaceCoordinates& sc, double u, double v, double tol = kTol) {
  EXPECT_NEAR(sc.uv.x, u, tol);
  EXPECT_NEAR(sc.uv.y, v, tol);
}

TEST(SurfaceCoordinates, SphereFollowsTheEquirectangularConvention) {
  const Shape s = Sphere::make({1, 2, 3}, 2);
  expectUv(surfaceCoordinates(s, {1, 2, 1}), 0.5, 0.5);         // −z: the centre column
  expectUv(surfaceCoordinates(s, {3, 2, 3}), 0.75, 0.5);        // +x at u = 0.75
  expectUv(surfaceCoordinates(s, {-1, 2, 3}), 0.25, 0.5);       // −x at u = 0.25
  EXPECT_NEAR(surfaceCoordinates(s, {1, 4, 3}).uv.y, 1, kTol);  // +y: the top row
  EXPECT_NEAR(surfaceCoordinates(s, {1, 0, 3}).uv.y, 0, kTol);  // −y: the bottom row
  // +z is the seam: u = 0 or 1.
  const double seam = surfaceCoordinates(s, {1, 2, 5}).uv.x;
  EXPECT_TRUE(std::abs(seam) < kTol || std::abs(seam - 1) < kTol) << seam;
}

TEST(SurfaceCoordinates, SphereDerivativesMatchFiniteDifferences) {
  const Sphere sphere = Sphere::make({0, 0, 0}, 1.5);
  const Shape s = sphere;
  const double theta = 1.1;
  const double phi = 0.7;
  const auto at = [&](double t, double p) {
    return Point3{1.5 * std::sin(t) * std::sin(p), 1.5 * std::cos(t),
                  -1.5 * std::sin(t) * std::cos(p)};
  };
  const SurfaceCoordinates sc = surfaceCoordinates(s, at(theta, phi));
  // u = 0.5 + φ/(2π): dp/du = 2π dp/dφ; v = 1 − θ/π: dp/dv = −π dp/dθ.
  const double h = 1e-6;
  const Vec3 dpdphi = (at(theta, phi + h) - at(theta, phi - h)) / (2 * h);
  const Vec3 dpdtheta = (at(theta + h, phi) - at(theta - h, phi)) / (2 * h);
  const Vec3 dpdu = dpdphi * (2 * std::numbers::pi);
  const Vec3 dpdv = dpdtheta * -std::numbers::pi;
  EXPECT_NEAR(sc.dpdu.x, dpdu.x, 1e-6);
  EXPECT_NEAR(sc.dpdu.y, dpdu.y, 1e-6);
  EXPECT_NEAR(sc.dpdu.z, dpdu.z, 1e-6);
  EXPECT_NEAR(sc.dpdv.x, dpdv.x, 1e-6);
  EXPECT_NEAR(sc.dpdv.y, dpdv.y, 1e-6);
  EXPECT_NEAR(sc.dpdv.z, dpdv.z, 1e-6);
  // The unit normal of a sphere changes by dp / radius.
  EXPECT_NEAR(sc.dndu.x, dpdu.x / 1.5, 1e-6);
}

TEST(SurfaceCoordinates, RectangleCornerEdgesAreTheUnitSquare) {
  const Shape r = Rectangle::make({1, 0, 0}, {4, 0, 0}, {0, 2, 0});
  expectUv(surfaceCoordinates(r, {1, 0, 0}), 0, 0);
  expectUv(surfaceCoordinates(r, {5, 0, 0}), 1, 0);
  expectUv(surfaceCoordinates(r, {1, 2, 0}), 0, 1);
  expectUv(surfaceCoordinates(r, {3, 1.5, 0}), 0.5, 0.75);
}

TEST(SurfaceCoordinates, TriangleUvIsTheBarycentricsOfItsSecondAndThirdVertex) {
  const Shape t = Triangle::make({0, 0, 0}, {2, 0, 0}, {0, 4, 1});
  expectUv(surfaceCoordinates(t, {0, 0, 0}), 0, 0);
  expectUv(surfaceCoordinates(t, {2, 0, 0}), 1, 0);
  expectUv(surfaceCoordinates(t, {0, 4, 1}), 0, 1);
  expectUv(surfaceCoordinates(t, {0.5, 1, 0.25}), 0.25, 0.25);
}

TEST(SurfaceCoordinates, PlaneUsesSceneUnitsAlongItsAxes) {
  // A floor: u along +x, v along −z.
  const Shape floor = Plane::make({1, 0, 1}, {0, 1, 0});
  expectUv(surfaceCoordinates(floor, {3, 0, -2}), 2, 3);
  // A wall facing +z: u along +x, v along +y.
  const Shape wall = Plane::make({0, 0, -5}, {0, 0, 1});
  expectUv(surfaceCoordinates(wall, {2, 3, -5}), 2, 3);
}

TEST(SurfaceCoordinates, DiskIsInscribedInTheUnitSquare) {
  const Shape d = Disk::make({0, 1, 0}, {0, 1, 0}, 2);
  expectUv(surfaceCoordinates(d, {0, 1, 0}), 0.5, 0.5);
  expectUv(surfaceCoordinates(d, {2, 1, 0}), 1, 0.5);
  expectUv(surfaceCoordinates(d, {0, 1, -2}), 0.5, 1);
}

TEST(SurfaceCoordinates, PolygonAndQuadrangleSpanTheirBoundingRectangle) {
  const Shape p = Polygon::make({{0, 0, 0}, {2, 0, 0}, {2, 0, -1}, {0, 0, -1}});
  expectUv(surfaceCoordinates(p, {0, 0, 0}), 0, 0);
  expectUv(surfaceCoordinates(p, {2, 0, -1}), 1, 1);
  expectUv(surfaceCoordinates(p, {1, 0, -0.25}), 0.5, 0.25);
  const Shape q = Quadrangle::make({0, 0, 0}, {0, 0, 4}, {2, 0, 4}, {2, 0, 0});
  const SurfaceCoordinates sc = surfaceCoordinates(q, {1, 0, 2});
  expectUv(sc, 0.5, 0.5);
}

TEST(SurfaceCoordinates, TubeAndCylinderSide) {
  const Shape tube = Tube::make({0, 0, 0}, {0, 1, 0}, 1);
  // planeAxes(+y): u axis +x (angle 0), then counter-clockwise seen from +y toward −z.
  expectUv(surfaceCoordinates(tube, {1, 3, 0}), 0, 3);
  expectUv(surfaceCoordinates(tube, {0, -2, -1}), 0.25, -2);
  expectUv(surfaceCoordinates(tube, {-1, 0, 0}), 0.5, 0);
  const Shape cylinder = Cylinder::make({0, 0, 0}, {0, 1, 0}, 1, 4);
  expectUv(surfaceCoordinates(cylinder, {0, 1, -1}), 0.25, 0.25);
  expectUv(surfaceCoordinates(cylinder, {0, 4, 0}), 0.5, 0.5);  // top cap centre
  // The base cap faces −y: planeAxes(−y) has u along −x.
  expectUv(surfaceCoordinates(cylinder, {0.5, 0, 0}), 0.25, 0.5);
}

TEST(SurfaceCoordinates, BoxFacesAreEachTheUnitSquare) {
  const Shape b = Box::make({0, 0, 0}, {2, 4, 8});
  expectUv(surfaceCoordinates(b, {1, 4, 4}), 0.5, 0.5);  // top face centre
  // The +z face (a wall facing +z): u along +x, v along +y.
  expectUv(surfaceCoordinates(b, {0.5, 3, 8}), 0.25, 0.75);
  // The top face (a floor facing +y): u along +x, v along −z.
  expectUv(surfaceCoordinates(b, {0.5, 4, 2}), 0.25, 0.75);
}

TEST(SurfaceCoordinates, MeshUsesItsUvsAndComputesTangents) {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  m.indices = {0, 1, 2};
  m.uvs = {{0.5, 0.5}, {1, 0.5}, {0.5, 1}};
  const SurfaceCoordinates sc = surfaceCoordinates(m, 0, {0.5, 1, 0});
  expectUv(sc, 0.625, 0.75);
  EXPECT_NEAR(sc.dpdu.x, 4, kTol);  // u grows by 0.5 over 2 units of x
  EXPECT_NEAR(sc.dpdv.y, 4, kTol);
  computeMeshTangents(m);
  ASSERT_EQ(m.tangents.size(), 3u);
  EXPECT_NEAR(m.tangents[0].direction.x, 1, kTol);
  EXPECT_EQ(m.tangents[0].sign, 1);
  // A mirrored layout (u decreasing along +x) flips the tangent and keeps n × t along dp/dv.
  m.uvs = {{0.5, 0.5}, {0, 0.5}, {0.5, 1}};
  m.tangents.clear();
  computeMeshTangents(m);
  EXPECT_NEAR(m.tangents[0].direction.x, -1, kTol);
  EXPECT_EQ(m.tangents[0].sign, -1);
}

TEST(SurfaceCoordinates, MeshWithoutUvsUsesBarycentrics) {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  m.indices = {0, 1, 2};
  expectUv(surfaceCoordinates(m, 0, {1, 0.5, 0}), 0.5, 0.25);
}

}  // namespace
}  // namespace glint
