// The benchmark scenes of issue 4, defined once so that every program (ray throughput, build and
// memory, renderer comparison) measures exactly the same geometry seen by the same camera.
#pragma once

#include <string>
#include <vector>

#include "bench_support.h"
#include "glint/accel/aggregate.h"
#include "glint/scene/camera.h"

namespace glint::bench {

struct BenchScene {
  std::string name;                  // for tables: "torus 100k"
  std::string id;                    // for file names: "torus100k"
  std::vector<TriangleMesh> meshes;  // the object meshes, then the floor (two triangles) last
  std::vector<SphereSpec> spheres;
  Point3 floorCentre;  // the floor square: y = floorCentre.y, normal +y
  double floorHalfSize = 0;
  Point3 lookAt;      // what the camera aims at
  CameraSpec camera;  // pinhole, vertical fov, 1024×768
};

// A closed torus (R = 1, r = 0.4, axis vertical, lowest point 0.1 above the floor) over a floor.
// triangles: 100000 → 400 × 125 segments, 1000000 → 1250 × 400; any other value must be
// 2·major·minor with major = 3.2·minor (e.g. 10000 for quick runs → 100 × 50 is also accepted).
BenchScene makeTorusScene(int triangles);
// 1000 spheres (radius 0.4) on a 10×10×10 grid with spacing 1, over a floor.
BenchScene makeSpheresScene();

// What glint's Aggregate is built from: analytic spheres as primitives, meshes as flat triangle
// meshes; every transmission is 0 (opaque), so transmittance() is the occlusion query.
struct GlintInputs {
  std::vector<Primitive> primitives;
  std::vector<Color> primitiveTransmission;
  std::vector<TriangleMesh> meshes;
  std::vector<Color> meshTransmission;
};
GlintInputs makeGlintInputs(const BenchScene& scene);
inline Aggregate buildAggregate(GlintInputs inputs, Acceleration acceleration = Acceleration::Bvh) {
  return Aggregate(std::move(inputs.primitives), std::move(inputs.primitiveTransmission),
                   std::move(inputs.meshes), std::move(inputs.meshTransmission), acceleration);
}

}  // namespace glint::bench
