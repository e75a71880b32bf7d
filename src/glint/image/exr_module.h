// OpenEXR as a module loaded on the first EXR file read or written (glint-exr.so,
// src/glint/modules/exr_codec.cpp): libOpenEXR and the libraries it brings (Iex, IlmThread,
// Imath) cost ~3 ms of dynamic linking at every start of a program linked with them. The interface
// between the image readers and writers and the module; both come from one build (checked by
// GLINT_MODULE_IDENTITY), so C++ types may cross. Nothing but std::bad_alloc is thrown across it:
// errors come back as text.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "glint/core/helper_files.h"

namespace glint::exr_module {

inline constexpr const char* kModuleFile = "glint-exr.so";
inline constexpr const char* kModuleIdentity = GLINT_MODULE_IDENTITY("exr", 1);
inline constexpr const char* kCodecFunction = "glint_exr_codec";

class Codec {
 public:
  virtual ~Codec() = default;
  // Decodes the EXR file `bytes`, whose header says width × height pixels, through OpenEXR's RGBA
  // interface into `rgb` (3 floats a pixel, rows from the top; every value finite and ≥ 0, NaN,
  // infinity and negatives as 0). Returns "" or, worded for the user, why the file is refused
  // ("invalid EXR file: ...").
  virtual std::string decode(std::span<const std::uint8_t> bytes, std::int64_t width,
                             std::int64_t height, std::vector<float>& rgb) = 0;
  // Writes `path` (which exists: opened again by name) as width × height pixels of 32-bit float R,
  // G and B planes (`red`, `green`, `blue`, rows from the top), `rowsPerCall` rows at a time,
  // calling `rowsWritten(rows so far)` after each; once it returns false the file is left as it is.
  // Returns "" or why not, worded for the user ("write error: File too large").
  virtual std::string write(const char* path, int width, int height, const float* red,
                            const float* green, const float* blue, int rowsPerCall,
                            const std::function<bool(int rows)>& rowsWritten) = 0;
};

// The module's entry point: its one codec.
using CodecFunction = Codec* (*)();

// The codec of this process, the module loaded on the first call. Empty `error` when it is there;
// else nullptr and why (worded for the user).
Codec* exrCodec(std::string& error);

}  // namespace glint::exr_module
