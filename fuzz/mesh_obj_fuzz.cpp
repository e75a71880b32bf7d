// libFuzzer target: OBJ files through glint::readMeshFile (see mesh_fuzz.h).
#include <cstddef>
#include <cstdint>

#include "mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return glint::fuzz::runMeshInput(data, size, ".obj", "input.mtl");
}
