// Shading of triangle meshes: a sphere tessellated finely with interpolated vertex normals must
// shade like the analytic sphere; without normals it shows its facets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "glint/render/renderer.h"

namespace glint {
namespace {

// A UV sphere of `rings` × `segments` around the origin, outward winding, optional vertex normals
// (the sphere's own).
TriangleMesh sphereMesh(double radius, int rings, int segments, bool normals) {
  TriangleMesh mesh;
  const auto add = [&](double theta, double phi) {
    const Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
    mesh.positions.push_back(toPoint(n * radius));
    if (normals) mesh.normals.push_back(Normal3(n));
  };
  for (int i = 0; i <= rings; ++i) {
    for (int j = 0; j <= segments; ++j) {
      add(std::numbers::pi * i / rings, 2 * std::numbers::pi * j / segments);
    }
  }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      // Both windings below are outward for this parameterisation (θ down from +y, φ toward +z).
      if (i > 0) mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j)});
      if (i + 1 < rings) {
        mesh.indices.insert(mesh.indices.end(), {at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
      }
    }
  }
  return mesh;
}

// The unit sphere seen from +z under a directional light, with a diffuse and a specular term.
SceneParts sphereScene() {
  SceneParts parts;
  Material m;
  m.kd = Color(0.8, 0.6, 0.4);
  m.ks = Color(0.5);
  m.shininess = 20;
  m.ka = Color(0);
  parts.materials.push_back(m);
  parts.lights.push_back(DirectionalLight{normalize(Vec3{-1, -1, -1.5}), Color(1)});
  parts.camera.position = {0, 0, 4};
  parts.camera.fovDegrees = 32;
  parts.image.width = 48;
  parts.image.height = 48;
  parts.render.maxDepth = 1;
  return parts;
}

struct Comparison {
  double maxDifference = 0;
  int pixels = 0;
};

// Pixels where the analytic sphere faces the camera (n·v < −0.2) and is clearly lit or clearly
// unlit (|n·l| > 0.15), away from the silhouette and the terminator, where tessellation changes
// coverage and self-shadowing rather than shading.
Comparison compareWithAnalytic(const Scene& analytic, const Film& reference, const Film& film,
                               const Vec3& light) {
  Comparison c;
  for (int y = 0; y < film.height(); ++y) {
    for (int x = 0; x < film.width(); ++x) {
      Ray ray = analytic.camera().generateRay(x, y, Point2{0.5, 0.5}, Point2{0.5, 0.5});
      ray.direction = normalize(ray.direction);
      Hit hit;
      if (!analytic.intersect(ray, kInfinity, hit)) continue;
      if (!(dot(hit.normal, ray.direction) < -0.2) || !(std::abs(dot(hit.normal, light)) > 0.15)) {
        continue;
      }
      const Color d = film.at(x, y) - reference.at(x, y);
      c.maxDifference = std::max({c.maxDifference, std::abs(d.r), std::abs(d.g), std::abs(d.b)});
      ++c.pixels;
    }
  }
  return c;
}

TEST(MeshShading, SmoothSphereMeshShadesLikeTheAnalyticSphere) {
  SceneParts analyticParts = sphereScene();
  analyticParts.primitives.emplace_back(Sphere::make({0, 0, 0}, 1), 1, Color());
  const Scene analytic(std::move(analyticParts));
  const Film reference = render(analytic);
  const Vec3 light = std::get<DirectionalLight>(analytic.lights()[0]).direction;

  const auto meshFilm = [&](bool normals) {
    SceneParts parts = sphereScene();
    parts.meshes.push_back(sphereMesh(1, 64, 128, normals));
    parts.meshes.back().materialIndex = 1;
    return render(Scene(std::move(parts)));
  };
  const Comparison smooth = compareWithAnalytic(analytic, reference, meshFilm(true), light);
  const Comparison flat = compareWithAnalytic(analytic, reference, meshFilm(false), light);
  EXPECT_GT(smooth.pixels, 600);
  // Tolerance: the flat triangles lie up to r(1 − cos(π/128)) ≈ 3e-4 inside the sphere, so a pixel
  // sees its interpolated normal up to ~2e-3 rad away from the analytic one; the steepest term,
  // ks·20·cos¹⁹·sin, turns that into < 0.01.
  EXPECT_LT(smooth.maxDifference, 0.01);
  // Without normals the facets (π/64 apart) show: the difference is several times larger.
  EXPECT_GT(flat.maxDifference, 3 * smooth.maxDifference);
}

TEST(MeshShading, ShadingNormalOnTheFarSideFallsBackToTheGeometricNormal) {
  // One triangle facing +z whose vertex normals all point to −z (as a broken file may have):
  // seen from +z they face away from the viewer, so the geometric normal shades it, exactly like
  // the same triangle without normals.
  const auto trianglePixel = [](bool reversedNormals) {
    SceneParts parts = sphereScene();
    TriangleMesh tri;
    tri.positions = {{-2, -2, 0}, {2, -2, 0}, {0, 2, 0}};
    tri.indices = {0, 1, 2};
    if (reversedNormals) tri.normals.assign(3, Normal3(0, 0, -1));
    tri.materialIndex = 1;
    parts.meshes.push_back(tri);
    const Scene scene(std::move(parts));
    Rng rng(0);
    return traceRay(scene, {{0.1, 0.2, 4}, {0, 0, -1}}, rng);
  };
  const Color flat = trianglePixel(false);
  EXPECT_GT(flat.r, 0.1);
  EXPECT_EQ(trianglePixel(true), flat);
}

}  // namespace
}  // namespace glint
