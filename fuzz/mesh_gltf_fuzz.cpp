// libFuzzer target: glTF 2.0 through glint::readMeshFile (see mesh_fuzz.h). An input starting with
// the binary magic "glTF" is written as input.glb, any other as input.gltf; either may name the
// side file input.bin as a buffer.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  return glint::fuzz::runMeshInput(data, size, binary ? ".glb" : ".gltf", "input.bin");
}
