// libFuzzer target for the NFF reader (readers/nff_reader.h) and the factories behind it: any bytes
// give a LoadedScene or a SceneError, every diagnostic at a line and column.
#include "glint/readers/nff_reader.h"
#include "scene_format_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return glint::fuzz::fuzzSceneFormat(data, size, "fuzz.nff", glint::parseNff);
}
