// The benchmark scenes (bench_scenes.h).
#include "bench_scenes.h"

#include <stdexcept>
#include <string>

namespace glint::bench {

namespace {

CameraSpec cameraAt(const Point3& position, const Point3& lookAt, double fovDegrees) {
  CameraSpec spec;
  spec.position = position;
  spec.direction = lookAt - position;
  spec.up = {0, 1, 0};
  spec.fovDegrees = fovDegrees;
  spec.imageWidth = 1024;
  spec.imageHeight = 768;
  return spec;
}

}  // namespace

BenchScene makeTorusScene(int triangles) {
  int major = 0, minor = 0;
  switch (triangles) {
    case 100000:
      major = 400, minor = 125;
      break;
    case 1000000:
      major = 1250, minor = 400;
      break;
    case 10000:
      major = 100, minor = 50;
      break;
    default:
      throw std::invalid_argument("makeTorusScene: no segment counts for " +
                                  std::to_string(triangles) + " triangles");
  }
  BenchScene scene;
  scene.id = "torus" + (triangles >= 1000000 ? std::to_string(triangles / 1000000) + "M"
                                             : std::to_string(triangles / 1000) + "k");
  scene.name = "torus " + scene.id.substr(5);
  scene.meshes.push_back(makeTorus({0, 0.5, 0}, 1.0, 0.4, major, minor, /*normals=*/true));
  scene.floorCentre = {0, 0, 0};
  scene.floorHalfSize = 4;
  scene.meshes.push_back(makeFloor(scene.floorCentre, scene.floorHalfSize));
  scene.lookAt = {0, 0.35, 0};
  scene.camera = cameraAt({0, 2.6, 4.2}, scene.lookAt, 40);
  return scene;
}

BenchScene makeSpheresScene() {
  BenchScene scene;
  scene.id = "spheres1000";
  scene.name = "1000 spheres";
  scene.spheres = makeSphereGrid({-4.5, 0.5, -4.5}, 10, 1.0, 0.4);
  scene.floorCentre = {0, 0, 0};
  scene.floorHalfSize = 12;
  scene.meshes.push_back(makeFloor(scene.floorCentre, scene.floorHalfSize));
  scene.lookAt = {0, 4.6, 0};
  scene.camera = cameraAt({13, 11, 17}, scene.lookAt, 40);
  return scene;
}

GlintInputs makeGlintInputs(const BenchScene& scene) {
  GlintInputs in;
  in.primitives = spherePrimitives(scene.spheres);
  in.primitiveTransmission.assign(in.primitives.size(), Color());
  in.meshes = scene.meshes;
  in.meshTransmission.assign(in.meshes.size(), Color());
  return in;
}

}  // namespace glint::bench
