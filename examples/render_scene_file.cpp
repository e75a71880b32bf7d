// A scene file rendered through the library as `glint render` renders it: any format glint reads
// (YAML, NFF, Tachyon .dat, a mesh file), meshes read by the installed mesh reader, OpenEXR
// written by the installed module — with a progress callback and Ctrl-C stopping the job.
//
//   render_scene_file SCENE OUT.(png|ppm|exr) [WIDTH]
//
// A program linked with an installed glint finds the mesh reader and the modules beside itself
// (PREFIX/bin next to PREFIX/libexec/glint), in the install prefix glint was configured with or
// in the Debian package's /usr; elsewhere set GLINT_MESH_READER, GLINT_EXR_MODULE and
// GLINT_PREVIEW_MODULE to their paths.
#include <atomic>
#include <csignal>
#include <exception>
#include <iostream>
#include <string>
#include <utility>

#include "glint/glint.h"

namespace {

std::atomic<bool> gStop{false};
extern "C" void onInterrupt(int) { gStop = true; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: render_scene_file SCENE OUT.(png|ppm|exr) [WIDTH]\n";
    return 2;
  }
  glint::RenderJobSpec job;
  job.scene = argv[1];
  job.output = argv[2];
  if (argc > 3) job.overrides.width = std::stoi(argv[3]);
  std::signal(SIGINT, onInterrupt);
  job.cancel = &gStop;
  glint::RenderJobEvents events;
  events.sceneWarnings = [](const std::vector<glint::Diagnostic>& warnings) {
    for (const glint::Diagnostic& warning : warnings) std::cerr << warning.format() << "\n";
  };
  int lastPercent = -1;
  events.progress = [&lastPercent](std::size_t done, std::size_t total) {
    const int percent = static_cast<int>(done * 100 / total);
    if (percent / 25 != lastPercent / 25) std::cerr << percent << "%\n";
    lastPercent = percent;
  };
  try {
    const glint::RenderJobResult result = glint::runRenderJob(std::move(job), events);
    if (result.outcome == glint::RenderJobResult::Outcome::Interrupted) {
      std::cerr << "interrupted\n";
      return 130;
    }
    std::cout << "wrote " << result.output.string() << " (" << result.scene.image.width << "×"
              << result.scene.image.height << ", " << result.stats.rays.total() << " rays)\n";
  } catch (const glint::JobError& e) {
    std::cerr << "render_scene_file: " << e.what() << "\n";
    return e.exitCode();
  } catch (const std::exception& e) {
    std::cerr << "render_scene_file: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
