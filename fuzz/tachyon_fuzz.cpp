// libFuzzer target for the Tachyon .dat reader (readers/tachyon_reader.h) and the factories behind
// it: any bytes give a LoadedScene or a SceneError, every diagnostic at a line and column.
#include "glint/readers/tachyon_reader.h"
#include "scene_format_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return glint::fuzz::fuzzSceneFormat(data, size, "fuzz.dat", glint::parseTachyon);
}
