#include "glint/image/exr_module.h"

#include <string_view>

namespace glint::exr_module {

Codec* exrCodec(std::string& error) {
  static std::string loadError;
  static void* const entry = loadHelperModule(kModuleFile, "GLINT_EXR_MODULE", GLINT_HELPER_PATHS,
                                              kModuleIdentity, kCodecFunction, loadError);
  if (entry == nullptr) {
    error = loadError;
    return nullptr;
  }
  static Codec* const codec = reinterpret_cast<CodecFunction>(entry)();
  return codec;
}

}  // namespace glint::exr_module
