// The seed document's test case — four triangles and a sphere under ambient light, with the yellow
// grid — built in code (no scene file) and rendered through the same render job as `glint render`
// (atomic output, the memory limits, the render summary's facts).
//
//   seed_test_case [OUT.png]      (default: seed_test_case.png)
//
// Expected picture: a green background, four pink right triangles forming a square with a green
// diamond gap in the middle, a pink disc in the centre, and a yellow grid every 100 pixels.
#include <exception>
#include <iostream>
#include <string>
#include <utility>

#include "glint/glint.h"

int main(int argc, char** argv) {
  glint::RenderJobSpec job;
  job.scene = "seed test case";  // what messages call the scene
  job.sceneParts = glint::seed::testCaseParts(1000, 100);
  job.output = argc > 1 ? argv[1] : "seed_test_case.png";
  try {
    const glint::RenderJobResult result = glint::runRenderJob(std::move(job));
    std::cout << "wrote " << result.output.string() << " (" << result.scene.image.width << "×"
              << result.scene.image.height << ", " << result.stats.rays.total() << " rays, "
              << result.stats.seconds << " s)\n";
  } catch (const glint::JobError& e) {
    std::cerr << "seed_test_case: " << e.what() << "\n";
    return e.exitCode();
  } catch (const std::exception& e) {
    std::cerr << "seed_test_case: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
