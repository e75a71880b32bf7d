// Writes the (p, q) torus knot of scenes/meshes/ as a Wavefront OBJ with its MTL material: a tube
// swept along the knot, as a grid of quads split into triangles, without normals (glint's loader
// generates smooth ones). Regenerate the committed files with
//
//   build/examples/make_torus_knot scenes/meshes/torus_knot.obj
//
// Options: --p P --q Q (winding numbers, default 2 and 3: the trefoil), --segments N (along the
// knot, default 480), --sides N (around the tube, default 40), --tube R (tube radius, default
// 0.42). The knot's centre line is r(φ) = 2 + cos(qφ) in the plane and height sin(qφ), so it spans
// about ±(3 + tube) across and ±(1 + tube) in height, in file units.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <string_view>

#include "glint/core/vec.h"

namespace {

struct Options {
  std::string output = "torus_knot.obj";
  int p = 2;
  int q = 3;
  int segments = 480;
  int sides = 40;
  double tube = 0.42;
};

// The knot's centre line at parameter phi ∈ [0, 2π) (it closes after one turn).
glint::Vec3 centre(const Options& o, double phi) {
  const double r = 2 + std::cos(o.q * phi);
  return {r * std::cos(o.p * phi), std::sin(o.q * phi), r * std::sin(o.p * phi)};
}

int usage(const char* program) {
  std::fprintf(stderr,
               "usage: %s [OUT.obj] [--p P] [--q Q] [--segments N] [--sides N] [--tube R]\n",
               program);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const bool hasValue = i + 1 < argc;
    if (arg == "--p" && hasValue) {
      o.p = std::atoi(argv[++i]);
    } else if (arg == "--q" && hasValue) {
      o.q = std::atoi(argv[++i]);
    } else if (arg == "--segments" && hasValue) {
      o.segments = std::atoi(argv[++i]);
    } else if (arg == "--sides" && hasValue) {
      o.sides = std::atoi(argv[++i]);
    } else if (arg == "--tube" && hasValue) {
      o.tube = std::atof(argv[++i]);
    } else if (!arg.empty() && arg[0] != '-') {
      o.output = arg;
    } else {
      return usage(argv[0]);
    }
  }
  if (o.p < 1 || o.q < 1 || o.segments < 3 || o.sides < 3 || !(o.tube > 0)) return usage(argv[0]);

  const std::filesystem::path objPath = o.output;
  std::filesystem::path mtlPath = objPath;
  mtlPath.replace_extension(".mtl");
  std::FILE* obj = std::fopen(objPath.c_str(), "w");
  std::FILE* mtl = std::fopen(mtlPath.c_str(), "w");
  if (!obj || !mtl) {
    std::fprintf(stderr, "cannot write %s\n", !obj ? objPath.c_str() : mtlPath.c_str());
    return 1;
  }

  std::fprintf(mtl,
               "# Material of %s (examples/make_torus_knot.cpp)\n"
               "newmtl copper\nKd 0.56 0.22 0.09\nKs 0.60 0.50 0.40\nNs 80\n",
               objPath.filename().c_str());
  std::fprintf(
      obj,
      "# (%d, %d) torus knot, %d x %d quads as %d triangles: examples/make_torus_knot.cpp\n"
      "mtllib %s\no torus_knot\n",
      o.p, o.q, o.segments, o.sides, 2 * o.segments * o.sides, mtlPath.filename().c_str());

  // A frame along the centre line from the chord to the next point (T) and the sum of the two
  // points (N, roughly away from the knot's axis), as three.js's TorusKnotGeometry does: unlike
  // the Frenet frame it never flips, and it closes up without a twist at φ = 2π.
  const double twoPi = 2 * std::numbers::pi;
  for (int i = 0; i < o.segments; ++i) {
    const double phi = twoPi * i / o.segments;
    const glint::Vec3 p1 = centre(o, phi);
    const glint::Vec3 p2 = centre(o, phi + 0.01);
    const glint::Vec3 t = p2 - p1;
    glint::Vec3 n = p2 + p1;
    const glint::Vec3 b = glint::normalize(glint::cross(t, n));
    n = glint::normalize(glint::cross(b, t));
    for (int j = 0; j < o.sides; ++j) {
      const double theta = twoPi * j / o.sides;
      const glint::Vec3 v = p1 + o.tube * (std::cos(theta) * n + std::sin(theta) * b);
      std::fprintf(obj, "v %.6f %.6f %.6f\n", v.x, v.y, v.z);
    }
  }
  std::fprintf(obj, "usemtl copper\n");
  // Vertex (i, j) is OBJ index 1 + i·sides + j; both directions wrap around.
  const auto index = [&](int i, int j) { return 1 + (i % o.segments) * o.sides + (j % o.sides); };
  for (int i = 0; i < o.segments; ++i) {
    for (int j = 0; j < o.sides; ++j) {
      const int a = index(i, j);
      const int b = index(i + 1, j);
      const int c = index(i + 1, j + 1);
      const int d = index(i, j + 1);
      // Counter-clockwise seen from outside the tube: (p1 − p0) × (p2 − p0) points outward.
      std::fprintf(obj, "f %d %d %d\nf %d %d %d\n", a, d, b, b, d, c);
    }
  }
  const bool ok = std::fclose(obj) == 0 && std::fclose(mtl) == 0;
  if (!ok) {
    std::fprintf(stderr, "cannot finish writing %s\n", objPath.c_str());
    return 1;
  }
  std::printf("wrote %s and %s: %d vertices, %d triangles\n", objPath.c_str(), mtlPath.c_str(),
              o.segments * o.sides, 2 * o.segments * o.sides);
  return 0;
}
