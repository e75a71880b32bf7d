// Acne and leak tests for the ray-offset policy of core/spawn.h: scenes whose correct image is
// known exactly, rendered at scales 10^-3 .. 10^5 and translated up to 10^6 from the origin, plus
// the renderer's handling of non-finite samples.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "glint/core/rng.h"
#include "glint/core/spawn.h"
#include "glint/core/transform.h"
#include "glint/geometry/shape.h"
#include "glint/geometry/triangle_mesh.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

// Where a test scene is put: world = origin + scale · local. Scenes are built directly in world
// coordinates (no transform), so every rounding happens at the placed magnitudes.
struct Placement {
  double scale = 1;
  Vec3 origin;
  std::string name() const {
    return "scale " + std::to_string(scale) + " at (" + std::to_string(origin.x) + ", " +
           std::to_string(origin.y) + ", " + std::to_string(origin.z) + ")";
  }
  Point3 at(const Vec3& local) const { return toPoint(origin + local * scale); }
  // The largest magnitude of the placed scene: what a relative gap is measured against.
  double magnitude() const { return std::max(scale, maxComponent(abs(origin))); }
};

const std::vector<Placement>& placements() {
  static const std::vector<Placement> all{
      {1e-3, {0, 0, 0}},        {1, {0, 0, 0}},           {1e3, {0, 0, 0}},
      {1e5, {0, 0, 0}},         {1, {1e5, -1e5, 1e5}},    {1, {-1e6, 1e6, 1e6}},
      {1e-3, {1e6, 1e6, 1e6}},  {1e3, {1e6, -1e6, -1e6}}, {1e5, {1e6, 1e6, -1e6}},
      {1e-3, {-1e5, 3e5, 2e5}},
  };
  return all;
}

constexpr Color kBackground{0, 0, 1};
constexpr Color kGray{0.5, 0.5, 0.5};
constexpr int kSize = 16;  // pixels per image side: small keeps the Debug suite fast

// A scene with one gray diffuse material (kd 0.5, no ambient), a blue background and the camera at
// `eye` looking at `target`.
SceneParts baseParts(const Point3& eye, const Point3& target, const Vec3& up, double fovDegrees) {
  SceneParts parts;
  parts.materials = {Material{}};
  parts.materials[0].kd = kGray;
  parts.background = kBackground;
  parts.camera.position = eye;
  parts.camera.direction = target - eye;
  parts.camera.up = up;
  parts.camera.fovDegrees = fovDegrees;
  parts.image.width = kSize;
  parts.image.height = kSize;
  return parts;
}

Film renderScene(const Scene& scene, RenderStats* stats = nullptr) {
  RenderOptions options;
  options.threads = 2;
  return render(scene, options, stats);
}

// An orthonormal frame (u, v, n) around the unit normal n.
struct Frame {
  Vec3 u, v, n;
};
Frame frameAround(const Vec3& normal) {
  Frame f;
  f.n = normalize(normal);
  orthonormalBasis(f.n, f.u, f.v);
  return f;
}

// The colour a ray from the renderer's camera sees: the same normalised ray the renderer traces.
Ray cameraRay(const Scene& scene, int column, int row) {
  const Ray r = scene.camera().generateRay(column, row);
  return Ray{r.origin, normalize(r.direction)};
}

// ------------------------------------------------------------------- flat surfaces: uniform images

enum class FlatKind {
  Plane,
  TransformedPlane,
  Rectangle,
  Disk,
  Triangle,
  Mesh,
  Polygon,
  Quadrangle,
  Box
};
enum class Lighting { HeadOn, GrazingLight, GrazingView, DistantView };

const char* name(FlatKind kind) {
  switch (kind) {
    case FlatKind::Plane:
      return "plane";
    case FlatKind::TransformedPlane:
      return "transformed plane";
    case FlatKind::Rectangle:
      return "rectangle";
    case FlatKind::Disk:
      return "disk";
    case FlatKind::Triangle:
      return "triangle";
    case FlatKind::Mesh:
      return "two-triangle mesh";
    case FlatKind::Polygon:
      return "polygon";
    case FlatKind::Quadrangle:
      return "quadrangle";
    case FlatKind::Box:
      return "box";
  }
  return "?";
}
const char* name(Lighting lighting) {
  switch (lighting) {
    case Lighting::HeadOn:
      return "head-on";
    case Lighting::GrazingLight:
      return "grazing light";
    case Lighting::GrazingView:
      return "grazing view";
    case Lighting::DistantView:
      return "view from 10^7 sizes away";
  }
  return "?";
}

// A flat surface of half-size 10 (local units) around the placement's origin, facing f.n, far
// larger than what the camera sees, so every pixel shows it. Returns the unit normal it stores.
Vec3 addFlatSurface(SceneParts& parts, FlatKind kind, const Placement& pl, const Frame& f) {
  const double h = 10;
  const Point3 c = pl.at({});
  const auto corner = [&](double a, double b) { return pl.at(f.u * a + f.v * b); };
  Shape shape;
  std::optional<Transform> transform;
  switch (kind) {
    case FlatKind::Plane:
      shape = Plane::make(c, f.n);
      break;
    case FlatKind::TransformedPlane: {
      // Object space: the plane z = 0; world: scaled, rotated onto f.n, translated.
      shape = Plane::make({0, 0, 0}, {0, 0, 1});
      const Vec3 axis = cross(Vec3{0, 0, 1}, f.n);
      const double angle = std::acos(f.n.z) * 180 / std::numbers::pi;
      transform = Transform::translate(pl.origin) * Transform::rotate(axis, angle) *
                  Transform::scale(pl.scale, pl.scale, pl.scale);
      break;
    }
    case FlatKind::Rectangle:
      shape = Rectangle::make(corner(-h, -h), f.u * (2 * h * pl.scale), f.v * (2 * h * pl.scale));
      break;
    case FlatKind::Disk:
      shape = Disk::make(c, f.n, h * pl.scale);
      break;
    case FlatKind::Triangle:
      shape = Triangle::make(corner(-h, -h), corner(3 * h, -h), corner(-h, 3 * h));
      break;
    case FlatKind::Mesh: {
      // Two triangles sharing the diagonal through the image centre: camera and shadow rays meet
      // the shared edge there.
      TriangleMesh mesh;
      mesh.positions = {corner(-h, -h), corner(h, -h), corner(h, h), corner(-h, h)};
      mesh.indices = {0, 1, 2, 0, 2, 3};
      parts.meshes.push_back(std::move(mesh));
      return f.n;
    }
    case FlatKind::Polygon:
      shape = Polygon::make(
          {corner(-h, -h), corner(h, -h), corner(1.5 * h, 0), corner(h, h), corner(-h, h)});
      break;
    case FlatKind::Quadrangle:
      shape = Quadrangle::make(corner(-h, -h), corner(h, -h), corner(h, h), corner(-h, h));
      break;
    case FlatKind::Box:
      shape = Box::make(pl.at(-f.u * h - f.v * h - f.n), c + (f.u + f.v) * (h * pl.scale));
      break;
  }
  parts.primitives.emplace_back(shape, 0, Color(), transform);
  return f.n;
}

// Polygon, quadrangle and box need a normal along an axis: their vertices are then exactly
// coplanar at any translation (the planarity check would refuse a tilted 10^-3 polygon at 10^6,
// whose vertices are rounded by more than 10^-9 of its size).
Frame frameFor(FlatKind kind) {
  if (kind == FlatKind::Polygon || kind == FlatKind::Quadrangle || kind == FlatKind::Box) {
    return Frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  }
  return frameAround({1, 2, 3});
}

// A flat surface lit by one directional light must render as one uniform colour kd·|n·l|: a pixel
// whose shadow ray re-hits the surface (acne) is black, one whose camera ray slips through the
// shared edge of the mesh shows the background.
TEST(RobustnessFlatTest, LitSurfaceIsUniformAtEveryScaleAndAngle) {
  for (const Placement& pl : placements()) {
    for (const FlatKind kind : {FlatKind::Plane, FlatKind::TransformedPlane, FlatKind::Rectangle,
                                FlatKind::Disk, FlatKind::Triangle, FlatKind::Mesh,
                                FlatKind::Polygon, FlatKind::Quadrangle, FlatKind::Box}) {
      for (const Lighting lighting : {Lighting::HeadOn, Lighting::GrazingLight,
                                      Lighting::GrazingView, Lighting::DistantView}) {
        const Frame f = frameFor(kind);
        const Point3 c = pl.at({});
        // Grazing: 0.1° above the surface for the light; 1° above it for the camera, with a
        // narrow field of view (every view ray meets the surface at 0.75°..1.25°). Distant: the
        // camera 10^7 sizes away with a field of view of one size, so ray.at(t) would carry
        // rounding error of ~10^-9 sizes, which an offset relative to |p| alone does not cover.
        const double grazing = 0.1 * std::numbers::pi / 180;
        const Vec3 toLight = lighting == Lighting::GrazingLight
                                 ? f.n * std::sin(grazing) + f.u * std::cos(grazing)
                                 : f.n;
        const double elevation =
            lighting == Lighting::GrazingView ? std::numbers::pi / 180 : std::numbers::pi / 2;
        const Vec3 toEye = f.n * std::sin(elevation) + f.v * std::cos(elevation);
        const double distance = lighting == Lighting::DistantView ? 1e7 : 3;
        const Point3 eye = c + toEye * (distance * pl.scale);
        double fov = 30;
        if (lighting == Lighting::GrazingView) fov = 0.5;
        if (lighting == Lighting::DistantView)
          fov = 2 * std::atan(0.5 / distance) * 180 / std::numbers::pi;
        SceneParts parts = baseParts(eye, c, lighting == Lighting::GrazingView ? f.n : f.v, fov);
        const Vec3 n = addFlatSurface(parts, kind, pl, f);
        const Vec3 l = -normalize(toLight);
        parts.lights.push_back(DirectionalLight{l, Color(1, 1, 1)});
        const Scene scene(std::move(parts));
        const Film film = renderScene(scene);
        // Uniform up to the direction of the stored normal: a 10^-3 triangle at 10^6 has vertices
        // rounded by 10^-8 of its size, which tilts its normal, and |n·l| at 0.1° with it.
        const double expected = 0.5 * std::abs(dot(n, l));
        int wrong = 0;
        for (int row = 0; row < kSize; ++row) {
          for (int column = 0; column < kSize; ++column) {
            Hit hit;
            const bool hits = scene.intersect(cameraRay(scene, column, row), kInfinity, hit);
            const double exact = 0.5 * std::abs(dot(hit.normal, l));
            const Color& got = film.at(column, row);
            if (!(hits && std::abs(got.r - exact) <= 1e-12 * exact && got.b == got.r &&
                  std::abs(got.r - expected) <= 1e-4 * expected))
              ++wrong;
          }
        }
        EXPECT_EQ(wrong, 0) << name(kind) << ", " << name(lighting) << ", " << pl.name()
                            << ": pixels differing from " << expected;
      }
    }
  }
}

// ----------------------------------------------------- curved shapes: no speckles on the lit side

enum class SolidKind { Sphere, Box, Cylinder, Ellipsoid, RotatedBox };

const char* name(SolidKind kind) {
  switch (kind) {
    case SolidKind::Sphere:
      return "sphere";
    case SolidKind::Box:
      return "box";
    case SolidKind::Cylinder:
      return "cylinder";
    case SolidKind::Ellipsoid:
      return "ellipsoid (transformed sphere)";
    case SolidKind::RotatedBox:
      return "rotated box";
  }
  return "?";
}

void addSolid(SceneParts& parts, SolidKind kind, const Placement& pl) {
  const Point3 c = pl.at({});
  const double s = pl.scale;
  switch (kind) {
    case SolidKind::Sphere:
      parts.primitives.emplace_back(Sphere::make(c, s), 0, Color());
      break;
    case SolidKind::Box:
      parts.primitives.emplace_back(Box::make(pl.at({-1, -0.7, -0.8}), pl.at({0.9, 0.8, 0.7})), 0,
                                    Color());
      break;
    case SolidKind::Cylinder:
      parts.primitives.emplace_back(
          Cylinder::make(pl.at({0, 0, -0.6}), Vec3{0.2, 0.3, 1}, 0.8 * s, 1.2 * s), 0, Color());
      break;
    case SolidKind::Ellipsoid:
      parts.primitives.emplace_back(Sphere::make({0, 0, 0}, 1), 0, Color(),
                                    Transform::translate(toVec(c)) *
                                        Transform::rotate({1, 1, 0}, 30) *
                                        Transform::scale(s, 0.6 * s, 0.8 * s));
      break;
    case SolidKind::RotatedBox:
      parts.primitives.emplace_back(Box::make({-1, -1, -1}, {1, 1, 1}), 0, Color(),
                                    Transform::translate(toVec(c)) *
                                        Transform::rotate({1, 2, 3}, 40) *
                                        Transform::scale(0.7 * s, 0.7 * s, 0.7 * s));
      break;
  }
}

// A solid lit by a directional light from the side, so the terminator (grazing light) is in view:
// every pixel must equal [(n·l)(n·v) > 0]·kd·|n·l| with n the normal of the camera ray's hit
// (the solid is convex, so nothing shadows its lit side). A speckle is a lit pixel gone black.
TEST(RobustnessSolidTest, LitSideHasNoSelfShadowSpeckles) {
  const Vec3 l = normalize(Vec3{-1, -0.3, -0.4});
  for (const Placement& pl : placements()) {
    for (const SolidKind kind : {SolidKind::Sphere, SolidKind::Box, SolidKind::Cylinder,
                                 SolidKind::Ellipsoid, SolidKind::RotatedBox}) {
      const Point3 c = pl.at({});
      SceneParts parts = baseParts(pl.at({0.3, -0.2, 4}), c, {0, 1, 0}, 40);
      addSolid(parts, kind, pl);
      parts.lights.push_back(DirectionalLight{l, Color(1, 1, 1)});
      const Scene scene(std::move(parts));
      const Film film = renderScene(scene);
      int wrong = 0;
      int lit = 0;
      for (int row = 0; row < kSize; ++row) {
        for (int column = 0; column < kSize; ++column) {
          const Ray ray = cameraRay(scene, column, row);
          Hit hit;
          Color expected = kBackground;
          if (scene.intersect(ray, kInfinity, hit)) {
            const double nl = dot(hit.normal, l);
            const double nv = dot(hit.normal, ray.direction);
            expected = nl * nv > 0 ? kGray * std::abs(nl) : Color();
            if (nl * nv > 0) ++lit;
          }
          const Color& got = film.at(column, row);
          if (!(std::abs(got.r - expected.r) <= 1e-12 && std::abs(got.b - expected.b) <= 1e-12))
            ++wrong;
        }
      }
      EXPECT_GT(lit, kSize * kSize / 10) << name(kind) << ", " << pl.name();
      EXPECT_EQ(wrong, 0) << name(kind) << ", " << pl.name();
    }
  }
}

// --------------------------------------------------- closed mesh: no light inside, no slipping

// The closed surface of the box [−1, 1]² × [−1, 1] (local units) as one triangle mesh, each face a
// fan of four triangles around its centre: edges run along both face diagonals and four triangles
// share each face centre, so rays through edges and vertices are common.
TriangleMesh fannedBoxMesh(const Placement& pl) {
  TriangleMesh mesh;
  const auto add = [&](const Vec3& p) {
    mesh.positions.push_back(pl.at(p));
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (const double side : {-1.0, 1.0}) {
      Vec3 n;
      n[axis] = side;
      Vec3 a;
      a[(axis + 1) % 3] = 1;
      const Vec3 b = cross(n, a);  // (a, b, n) right-handed: corners counter-clockwise about n
      const std::uint32_t centre = add(n);
      const std::uint32_t corners[4] = {add(n - a - b), add(n + a - b), add(n + a + b),
                                        add(n - a + b)};
      for (int k = 0; k < 4; ++k) {
        mesh.indices.insert(mesh.indices.end(), {centre, corners[k], corners[(k + 1) % 4]});
      }
    }
  }
  return mesh;
}

// A light outside a closed mesh, the camera inside looking down at a floor inside it: everything
// the camera sees is in shadow (floor) or faces away from the light (walls), so every pixel is
// exactly black. A shadow ray slipping through an edge or vertex of the mesh lights a floor pixel;
// a camera ray slipping through shows the background. The second case puts the floor a sliver
// (10^-12 of the scene's magnitude) below the mesh's top face, with the camera in the gap: a
// shadow-ray origin pushed past the top face lights the floor.
TEST(RobustnessClosedMeshTest, LightOutsideNeverReachesInside) {
  for (const Placement& pl : placements()) {
    for (const bool sliver : {false, true}) {
      const double gap = 1e-12 * pl.magnitude() / pl.scale;  // local units
      const double floorHeight = sliver ? 1 - gap : 0;
      const Point3 floorPoint = pl.at({0, 0, floorHeight});
      // The camera looks straight down from half-way up (floor at 0), or steeply down from inside
      // the gap, where every view ray meets the floor within a few gap widths.
      const Point3 eye = sliver ? pl.at({0, 0, floorHeight + gap / 2}) : pl.at({0, 0, 0.5});
      const Point3 target = sliver ? pl.at({gap, gap / 2, floorHeight}) : floorPoint;
      SceneParts parts = baseParts(eye, target, {0, 1, 0}, sliver ? 20 : 90);
      parts.meshes.push_back(fannedBoxMesh(pl));
      parts.primitives.emplace_back(Plane::make(floorPoint, {0, 0, 1}), 0, Color());
      parts.lights.push_back(DirectionalLight{{0, 0, -1}, Color(1, 1, 1)});
      parts.lights.push_back(DirectionalLight{normalize(Vec3{0.3, -0.2, -1}), Color(1, 1, 1)});
      const Scene scene(std::move(parts));
      const Film film = renderScene(scene);
      int lit = 0;
      int escaped = 0;
      for (const Color& c : film.pixels()) {
        if (c.b > 0 && c.r == 0) ++escaped;
        if (c.r != 0) ++lit;
      }
      EXPECT_EQ(lit, 0) << (sliver ? "sliver, " : "") << pl.name();
      EXPECT_EQ(escaped, 0) << (sliver ? "sliver, " : "") << pl.name();
    }
  }
}

// ------------------------------------------------------------------- thin slivers, analytic shapes

// Two nearly touching surfaces: a floor (the top face of a huge box) and a thin opaque plate
// floating above it, gap and thickness each 10^-12 of the scene's magnitude. (1) From inside the
// gap, the floor under the plate is in shadow: black. (2) Seen from above, the plate's top is lit
// uniformly (no acne on a thin slab). (3) Through a thin transparent slab (kt 0.5, ior 1) the
// background arrives scaled by 0.25: the transmitted ray must leave through the far face too, not
// start beyond it.
TEST(RobustnessSliverTest, ThinGapsAndSlabsNeitherLeakNorSkip) {
  for (const Placement& pl : placements()) {
    const double thin = 1e-12 * pl.magnitude() / pl.scale;  // local units
    const auto floorBox = [&] { return Box::make(pl.at({-1e3, -1e3, -1}), pl.at({1e3, 1e3, 0})); };
    const auto plate = [&] { return Box::make(pl.at({-1, -1, thin}), pl.at({1, 1, 2 * thin})); };
    const Vec3 l = normalize(Vec3{0.2, 0.1, -1});
    {
      SceneParts parts =
          baseParts(pl.at({0, 0, thin / 2}), pl.at({thin, thin / 3, 0}), {0, 0, 1}, 20);
      parts.primitives.emplace_back(floorBox(), 0, Color());
      parts.primitives.emplace_back(plate(), 0, Color());
      parts.lights.push_back(DirectionalLight{l, Color(1, 1, 1)});
      const Scene scene(std::move(parts));
      const Film film = renderScene(scene);
      int wrong = 0;
      for (const Color& c : film.pixels()) wrong += !(c.r == 0 && c.b == 0);
      EXPECT_EQ(wrong, 0) << "floor under the plate, " << pl.name();
    }
    {
      SceneParts parts = baseParts(pl.at({0, 0.1, 2}), pl.at({0, 0, 0}), {0, 1, 0}, 30);
      parts.primitives.emplace_back(floorBox(), 0, Color());
      parts.primitives.emplace_back(plate(), 0, Color());
      parts.lights.push_back(DirectionalLight{l, Color(1, 1, 1)});
      const Scene scene(std::move(parts));
      const Film film = renderScene(scene);
      const double expected = 0.5 * -l.z;
      int wrong = 0;
      for (const Color& c : film.pixels()) wrong += !(std::abs(c.r - expected) <= 1e-12);
      EXPECT_EQ(wrong, 0) << "top of the plate, " << pl.name();
    }
    {
      SceneParts parts = baseParts(pl.at({0, 0.1, 2}), pl.at({0, 0, 0}), {0, 1, 0}, 30);
      parts.materials[0] = Material{};
      parts.materials[0].kt = Color(0.5, 0.5, 0.5);
      parts.materials[0].ka = Color();
      parts.primitives.emplace_back(plate(), 0, Color());
      const Scene scene(std::move(parts));
      const Film film = renderScene(scene);
      int wrong = 0;
      for (const Color& c : film.pixels()) wrong += !(std::abs(c.b - 0.25) <= 1e-12 && c.r == 0);
      EXPECT_EQ(wrong, 0) << "through the thin slab, " << pl.name();
    }
  }
}

// ------------------------------------------------------------------ tiny object next to a huge one

// A sphere of radius 10^-3 floating 10^-12 (of the scene's magnitude) above a ground box 10^5
// wide, lit at 45°. Probed with single rays straight down: the sphere's top is lit, the ground in
// its shadow is black, the ground beside it is lit, each exactly.
TEST(RobustnessScaleTest, TinyObjectOnHugeGround) {
  const Vec3 l = normalize(Vec3{1, 0, -1});
  for (const Placement& pl : placements()) {
    const double r = 1e-3;
    const double gap = 1e-12 * pl.magnitude() / pl.scale;
    SceneParts parts = baseParts(pl.at({0, 0, 1}), pl.at({0, 0, 0}), {0, 1, 0}, 30);
    parts.primitives.emplace_back(Box::make(pl.at({-5e4, -5e4, -1e3}), pl.at({5e4, 5e4, 0})), 0,
                                  Color());
    parts.primitives.emplace_back(Sphere::make(pl.at({0, 0, r + gap}), r * pl.scale), 0, Color());
    parts.lights.push_back(DirectionalLight{l, Color(1, 1, 1)});
    const Scene scene(std::move(parts));
    const double lit = 0.5 * std::sqrt(0.5);
    const auto probe = [&](double x) {
      Rng rng = Rng::forPixelSample(0, 0, 0, 0);
      return traceRay(scene, Ray{pl.at({x * r, 0, 10 * r}), {0, 0, -1}}, rng).r;
    };
    EXPECT_NEAR(probe(0), lit, 1e-9 * lit) << "top of the tiny sphere, " << pl.name();
    // The shadow of the centre falls at x = r + gap; (1.5r, 0) is outside the sphere's footprint
    // and 0.5r from there, inside the shadow (which is r wide across the light's plane).
    EXPECT_EQ(probe(1.5), 0) << "ground in the tiny sphere's shadow, " << pl.name();
    EXPECT_NEAR(probe(-3), lit, 1e-9 * lit) << "ground beside the tiny sphere, " << pl.name();
  }
}

// ------------------------------------------------------- the policy itself, shape by shape

// Rays spawned from hits on every shape, at every placement, in directions from head-on to
// 10^-6 rad off the surface, on both sides: none may re-hit its surface near its origin (for flat
// shapes: at all), and the origin moves by no more than ~10^-13 of the magnitudes involved.
TEST(RobustnessSpawnTest, SpawnedRaysNeverRehitTheirSurface) {
  Rng rng = Rng::forPixelSample(7, 7, 7, 7);
  for (const Placement& pl : placements()) {
    const Frame f = frameAround({0.3, -0.5, 0.8});
    const Point3 c = pl.at({});
    const double s = pl.scale;
    struct Case {
      const char* name;
      Primitive primitive;
      bool flat;
    };
    const std::vector<Case> cases{
        {"sphere", Primitive(Sphere::make(c, s), 0, Color()), false},
        {"plane", Primitive(Plane::make(c, f.n), 0, Color()), true},
        {"triangle",
         Primitive(Triangle::make(pl.at(f.u * -2 - f.v), pl.at(f.u * 2 - f.v), pl.at(f.v * 2)), 0,
                   Color()),
         true},
        {"rectangle",
         Primitive(Rectangle::make(pl.at(-f.u - f.v), f.u * (2 * s), f.v * (2 * s)), 0, Color()),
         true},
        {"disk", Primitive(Disk::make(c, f.n, s), 0, Color()), true},
        {"box", Primitive(Box::make(pl.at({-1, -0.5, -0.7}), pl.at({1, 0.5, 0.7})), 0, Color()),
         false},
        {"cylinder", Primitive(Cylinder::make(pl.at({0, 0, -0.5}), f.n, 0.7 * s, s), 0, Color()),
         false},
        {"tube", Primitive(Tube::make(c, f.n, 0.7 * s), 0, Color()), false},
        {"ellipsoid",
         Primitive(Sphere::make({0, 0, 0}, 1), 0, Color(),
                   Transform::translate(pl.origin) * Transform::rotate({1, 2, 3}, 25) *
                       Transform::scale(s, 0.3 * s, 0.6 * s)),
         false},
    };
    for (const Case& tc : cases) {
      int rehits = 0;
      int tooFar = 0;
      int hits = 0;
      for (int k = 0; k < 200; ++k) {
        // A ray from a random point 3 units away toward a random point near the centre.
        const Vec3 from{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
        const Vec3 to{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
        const Point3 o = pl.at(normalize(from) * 3);
        const Ray ray{o, normalize(pl.at(to * 0.5) - o)};
        ShapeHit hit;
        if (!tc.primitive.intersect(ray, 0, kInfinity, hit)) continue;
        ++hits;
        Vec3 tu;
        Vec3 tv;
        const Vec3 n = toVec(hit.normal);
        orthonormalBasis(n, tu, tv);
        for (const double angle : {1.0, 1e-2, 1e-4, 1e-6}) {
          for (const double side : {1.0, -1.0}) {
            const double phi = 2 * std::numbers::pi * rng.uniform();
            const Vec3 tangent = tu * std::cos(phi) + tv * std::sin(phi);
            const Vec3 w = normalize(n * (side * std::sin(angle)) + tangent * std::cos(angle));
            const Ray spawned = spawnRay(hit.point, hit.pointError, hit.normal, w);
            const double moved = maxComponent(abs(spawned.origin - hit.point));
            if (moved > 1e-13 * (maxComponent(abs(toVec(hit.point))) + s)) ++tooFar;
            ShapeHit again;
            if (!tc.primitive.intersect(spawned, 0, kInfinity, again)) continue;
            // A closed shape is met again on its far side, farther than the chord of a ray
            // 10^-6 rad off the surface; a self-hit is at t of the order of the offset.
            if (tc.flat || again.t < 1e-9 * s) ++rehits;
          }
        }
      }
      EXPECT_GT(hits, 20) << tc.name << ", " << pl.name();
      EXPECT_EQ(rehits, 0) << tc.name << ", " << pl.name();
      EXPECT_EQ(tooFar, 0) << tc.name << ", " << pl.name();
    }
  }
}

// The offset rule of spawn.h on its own: 2·(|n|·pError) along ±n, then one ulp further on every
// axis n has a component along, so a zero bound (box faces) still leaves the surface.
TEST(RobustnessSpawnTest, OffsetIsTwiceTheProjectedBoundPlusOneUlp) {
  const Point3 p{1, 2, 3};
  const Normal3 n{0, 0.6, 0.8};
  const Vec3 e{1e-10, 2e-10, 3e-10};
  const double d = 2 * (0.6 * 2e-10 + 0.8 * 3e-10);
  const Point3 up = offsetRayOrigin(p, e, n, {0, 0, 1});
  EXPECT_EQ(up.x, 1);  // no normal component: untouched
  EXPECT_EQ(up.y, std::nextafter(2 + 0.6 * d, 3.0));
  EXPECT_EQ(up.z, std::nextafter(3 + 0.8 * d, 4.0));
  const Point3 down = offsetRayOrigin(p, e, n, {1, 0, -1});
  EXPECT_EQ(down.y, std::nextafter(2 - 0.6 * d, 1.0));
  EXPECT_EQ(down.z, std::nextafter(3 - 0.8 * d, 2.0));
  const Point3 face = offsetRayOrigin({5, 0, 7}, {}, Normal3{0, 0, -1}, {0.5, 0, -1});
  EXPECT_EQ(face.z, std::nextafter(7.0, 0.0));
  EXPECT_EQ(face.x, 5);
  const Ray r = spawnRay(p, e, n, {0, 1, 0});
  EXPECT_EQ(r.origin, up);
  EXPECT_EQ(r.direction, (Vec3{0, 1, 0}));
}

// The bound itself: the exact surface passes within pointError of every reported hit point
// (distances evaluated in long double, 11 more bits than the double arithmetic they check), and the
// bound stays below ~10^-13 of the magnitudes involved.
TEST(RobustnessSpawnTest, HitPointsLieWithinTheirErrorBound) {
  using Wide = long double;
  Rng rng = Rng::forPixelSample(3, 1, 4, 1);
  for (const Placement& pl : placements()) {
    const Frame f = frameAround({-0.4, 0.7, 0.2});
    const Point3 c = pl.at({});
    const double s = pl.scale;
    const Sphere sphere = Sphere::make(c, s);
    const Plane plane = Plane::make(c, f.n);
    const Triangle triangle =
        Triangle::make(pl.at(f.u * -2 - f.v), pl.at(f.u * 2 - f.v), pl.at(f.v * 2));
    const Tube tube = Tube::make(c, f.u, 0.5 * s);
    const auto wide = [](const Vec3& v) {
      return std::array<Wide, 3>{Wide{v.x}, Wide{v.y}, Wide{v.z}};
    };
    const auto wdot = [](const std::array<Wide, 3>& a, const std::array<Wide, 3>& b) {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    };
    const auto diff = [&](const Point3& a, const Point3& b) {
      return std::array<Wide, 3>{Wide{a.x} - Wide{b.x}, Wide{a.y} - Wide{b.y},
                                 Wide{a.z} - Wide{b.z}};
    };
    // Distance of p from each exact surface.
    const auto sphereDistance = [&](const Point3& p) {
      const auto d = diff(p, c);
      return std::abs(std::sqrt(wdot(d, d)) - Wide{s});
    };
    const auto planeDistance = [&](const Point3& p) {
      return std::abs(wdot(wide(toVec(plane.normal)), diff(p, plane.point)));
    };
    const auto triangleDistance = [&](const Point3& p) {
      const auto e1 = diff(triangle.v1, triangle.v0);
      const auto e2 = diff(triangle.v2, triangle.v0);
      const std::array<Wide, 3> n{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                  e1[0] * e2[1] - e1[1] * e2[0]};
      return std::abs(wdot(n, diff(p, triangle.v0))) / std::sqrt(wdot(n, n));
    };
    const auto tubeDistance = [&](const Point3& p) {
      const auto d = diff(p, tube.origin);
      const auto a = wide(tube.axis);
      const Wide h = wdot(d, a);
      const std::array<Wide, 3> radial{d[0] - a[0] * h, d[1] - a[1] * h, d[2] - a[2] * h};
      return std::abs(std::sqrt(wdot(radial, radial)) - Wide{tube.radius});
    };
    int checked = 0;
    for (int k = 0; k < 300; ++k) {
      const Vec3 from{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
      const Vec3 to{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
      // Origins up to 10^3 scene sizes away: the bound must not grow with the ray's length.
      const Point3 o = pl.at(normalize(from) * std::pow(10.0, 3 * rng.uniform()));
      const Ray ray{o, normalize(pl.at(to * 0.5) - o)};
      const auto check = [&](const char* what, const auto& shape, const auto& distanceOf) {
        ShapeHit hit;
        if (!shape.intersect(ray, 0, kInfinity, hit)) return;
        ++checked;
        const double bound = std::abs(hit.normal.x) * hit.pointError.x +
                             std::abs(hit.normal.y) * hit.pointError.y +
                             std::abs(hit.normal.z) * hit.pointError.z;
        const Wide distance = distanceOf(hit.point);
        EXPECT_LE(distance, Wide{bound} + Wide{1e-18} * Wide{maxComponent(abs(toVec(hit.point)))})
            << what << ", " << pl.name();
        EXPECT_LE(bound, 1e-13 * (maxComponent(abs(toVec(hit.point))) + s))
            << what << ", " << pl.name();
      };
      check("sphere", sphere, sphereDistance);
      check("plane", plane, planeDistance);
      check("triangle", triangle, triangleDistance);
      check("tube", tube, tubeDistance);
    }
    EXPECT_GT(checked, 300) << pl.name();
  }
}

// ---------------------------------------------------------------------------- non-finite samples

// Two directional lights of intensity 10^308 shine head-on on a rectangle that covers the image
// from column 5 and row 7 on: each alone is finite, their sum overflows to infinity. Those pixels
// are counted, replaced by black, and the first (smallest row, then column) is reported.
TEST(RobustnessNonFiniteTest, OverflowingSamplesAreCountedAndBlack) {
  const int width = 20;
  const int height = 16;
  SceneParts parts = baseParts({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 0);
  parts.camera.fovDegrees = 0;
  parts.camera.viewPlaneWidth = width;  // one unit per pixel at distance 1
  parts.camera.viewPlaneHeight = height;
  parts.camera.viewPlaneDistance = 1;
  parts.image.width = width;
  parts.image.height = height;
  parts.materials[0].kd = Color(1, 1, 1);
  // Pixel (column j, row i) centre looks at x = j + 0.5 − width/2, y = height/2 − i − 0.5 on z = 0.
  // Column 5's centre is x = −4.5, row 7's is y = 0.5: the rectangle spans x ≥ −4.75, y ≤ 0.75.
  parts.primitives.emplace_back(Rectangle::make({-4.75, -20, 0}, {30, 0, 0}, {0, 20.75, 0}), 0,
                                Color());
  parts.lights.push_back(DirectionalLight{{0, 0, -1}, Color(1e308, 1e308, 1e308)});
  parts.lights.push_back(DirectionalLight{{0, 0, -1}, Color(1e308, 1e308, 1e308)});
  const Scene scene(std::move(parts));
  RenderStats stats;
  const Film film = renderScene(scene, &stats);
  EXPECT_EQ(stats.nonFinite, static_cast<std::uint64_t>((width - 5) * (height - 7)));
  ASSERT_TRUE(stats.firstNonFinite.has_value());
  EXPECT_EQ(*stats.firstNonFinite, (PixelCoord{5, 7}));
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      const Color& c = film.at(column, row);
      const bool covered = column >= 5 && row >= 7;
      EXPECT_TRUE(covered ? isBlack(c) : (c.r == 0 && c.b == 1))
          << "pixel (" << column << ", " << row << ")";
    }
  }
}

}  // namespace
}  // namespace glint
