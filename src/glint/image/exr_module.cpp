#include "glint/image/exr_module.h"

#include <string_view>

namespace glint::exr_module {

Codec* exrCodec(std::string& error) {
#ifdef GLINT_EXR_MODULE_BUILD_PATH
  constexpr std::string_view kBuildPath = GLINT_EXR_MODULE_BUILD_PATH;
#else
  constexpr std::string_view kBuildPath;
#endif
#ifdef GLINT_EXR_MODULE_INSTALL_PATH
  constexpr std::string_view kInstallPath = GLINT_EXR_MODULE_INSTALL_PATH;
#else
  constexpr std::string_view kInstallPath;
#endif
  static std::string loadError;
  static void* const entry =
      loadHelperModule(kModuleFile, "GLINT_EXR_MODULE", kBuildPath, kInstallPath, kModuleIdentity,
                       kCodecFunction, loadError);
  if (entry == nullptr) {
    error = loadError;
    return nullptr;
  }
  static Codec* const codec = reinterpret_cast<CodecFunction>(entry)();
  return codec;
}

}  // namespace glint::exr_module
