// Image output: PNG (8-bit, libpng), PPM (8-bit binary P6) and OpenEXR (linear float), chosen by
// the file extension. Every writer writes a temporary file beside the target (core/atomic_file.h)
// and renames it into place, so an existing file is only ever replaced by a complete image.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "glint/render/film.h"
#include "glint/scene/scene.h"

namespace glint {

class ImageWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One linear channel value to an 8-bit code: srgb applies the sRGB curve, linear multiplies by 255;
// both clamp to [0, 1] first and round to nearest. NaN gives 0.
std::uint8_t encodeChannel(double linear, Encoding encoding);
// The inverse for a display code, used for "#rrggbb" colours: encodeChannel(decodeChannel(c)) == c.
double decodeChannel(std::uint8_t code, Encoding encoding);

// How a long write (a large image takes seconds) may be stopped or followed.
struct WriteControl {
  // Polled before every row; once set, the write stops, removes its temporary file and throws
  // Cancelled (core/cancel.h), leaving the target as it was. Not owned; may be null.
  const std::atomic<bool>* cancel = nullptr;
  // Called after each row has gone to the file with (rows written, rows in the image).
  std::function<void(int, int)> rowWritten;
};

class ImageWriter {
 public:
  virtual ~ImageWriter() = default;
  // Writes film to `path` (complete file, then rename). Throws ImageWriteError, or Cancelled.
  virtual void write(const Film& film, const std::filesystem::path& path, Encoding encoding,
                     const WriteControl& control) const = 0;
  // Empty when the writer can write; else why not (its module cannot be loaded), worded for the
  // user — asked before a render, so that the failure comes before the work.
  virtual std::string unavailable() const { return {}; }
};

// The writer for path's extension (.png, .ppm, .exr; case-insensitive), or nullptr if unknown.
std::unique_ptr<ImageWriter> writerForPath(const std::filesystem::path& path);

// writerForPath + write; throws ImageWriteError for an unknown extension too.
void writeImage(const Film& film, const std::filesystem::path& path, Encoding encoding,
                const WriteControl& control = {});

}  // namespace glint
