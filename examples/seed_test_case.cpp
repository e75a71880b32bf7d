// The seed document's test case — four triangles and a sphere under ambient light, with the yellow
// grid — built in code (no scene file), rendered and written as a PNG.
//
//   seed_test_case [OUT.png]      (default: seed_test_case.png)
//
// Expected picture: a green background, four pink right triangles forming a square with a green
// diamond gap in the middle, a pink disc in the centre, and a yellow grid every 100 pixels.
#include <exception>
#include <iostream>
#include <string>

#include "../tests/seed_scene.h"
#include "glint/image/image_writer.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene.h"

int main(int argc, char** argv) {
  const std::string output = argc > 1 ? argv[1] : "seed_test_case.png";
  try {
    const glint::Scene scene(glint::seed::testCaseParts(1000, 100));
    glint::RenderStats stats;
    const glint::Film film = glint::render(scene, {}, &stats);
    glint::writeImage(film, output, scene.image().encoding);
    std::cout << "wrote " << output << " (" << film.width() << "×" << film.height() << ", "
              << stats.rays.total() << " rays, " << stats.seconds << " s)\n";
  } catch (const std::exception& e) {
    std::cerr << "seed_test_case: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
