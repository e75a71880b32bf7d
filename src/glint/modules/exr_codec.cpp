// glint-exr.so: image/exr_module.h on OpenEXR — textures decoded from memory through its RGBA
// interface, images written as 32-bit float R, G, B. The only file of glint that includes OpenEXR.
#include <IexErrnoExc.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "glint/image/exr_module.h"

namespace glint::exr_module {
namespace {

// A refusal worded in full for the user, thrown out of OpenEXR's reading and caught below.
class Refusal : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class MemoryStream : public Imf::IStream {
 public:
  explicit MemoryStream(std::span<const std::uint8_t> bytes)
      : Imf::IStream("texture"), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || static_cast<std::uint64_t>(n) > bytes_.size() - at_) {
      throw Refusal("invalid EXR file: it is cut short");
    }
    std::memcpy(c, bytes_.data() + at_, static_cast<std::size_t>(n));
    at_ += static_cast<std::uint64_t>(n);
    return at_ < bytes_.size();
  }
  std::uint64_t tellg() override { return at_; }
  void seekg(std::uint64_t pos) override {
    if (pos > bytes_.size()) throw Refusal("invalid EXR file: an offset points past its end");
    at_ = pos;
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::uint64_t at_ = 0;
};

class OpenExrCodec final : public Codec {
 public:
  std::string decode(std::span<const std::uint8_t> bytes, std::int64_t width, std::int64_t height,
                     std::vector<float>& rgb) override {
    try {
      MemoryStream stream(bytes);
      Imf::RgbaInputFile file(stream, 1);
      const Imath::Box2i window = file.dataWindow();
      if (std::int64_t{window.max.x} - window.min.x + 1 != width ||
          std::int64_t{window.max.y} - window.min.y + 1 != height) {
        return "invalid EXR file: its size is inconsistent";
      }
      std::vector<Imf::Rgba> pixels(static_cast<std::size_t>(width * height));
      // The frame buffer is addressed from the data window's origin.
      Imf::Rgba* base =
          pixels.data() - (std::int64_t{window.min.x} + std::int64_t{window.min.y} * width);
      file.setFrameBuffer(base, 1, static_cast<std::size_t>(width));
      file.readPixels(window.min.y, window.max.y);
      rgb.resize(3 * pixels.size());
      for (std::size_t i = 0; i < pixels.size(); ++i) {
        const float channels[3] = {pixels[i].r, pixels[i].g, pixels[i].b};
        for (std::size_t c = 0; c < 3; ++c) {
          // Textures hold finite radiance ≥ 0; NaN and infinity become 0.
          const float v = channels[c];
          rgb[3 * i + c] = std::isfinite(v) && v > 0 ? v : 0.0f;
        }
      }
      return {};
    } catch (const Refusal& refusal) {
      return refusal.what();
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      return std::string("invalid EXR file: ") + e.what();
    }
  }

  std::string write(const char* path, int width, int height, const float* red, const float* green,
                    const float* blue, int rowsPerCall,
                    const std::function<bool(int rows)>& rowsWritten) override {
    try {
      Imf::Header header(width, height);
      header.channels().insert("R", Imf::Channel(Imf::FLOAT));
      header.channels().insert("G", Imf::Channel(Imf::FLOAT));
      header.channels().insert("B", Imf::Channel(Imf::FLOAT));
      Imf::FrameBuffer frame;
      const std::size_t xStride = sizeof(float);
      const std::size_t yStride = sizeof(float) * static_cast<std::size_t>(width);
      // OpenEXR's Slice takes a non-const base; writing only reads it.
      const auto slice = [&](const float* plane) {
        return Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(plane)), xStride,
                          yStride);
      };
      frame.insert("R", slice(red));
      frame.insert("G", slice(green));
      frame.insert("B", slice(blue));
      Imf::OutputFile out(path, header);
      out.setFrameBuffer(frame);
      // writePixels(n) writes the next n rows of the frame buffer.
      for (int y = 0; y < height; y += rowsPerCall) {
        const int rows = std::min(rowsPerCall, height - y);
        out.writePixels(rows);
        if (!rowsWritten(y + rows)) break;
      }
      return {};
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const Iex::ErrnoExc& e) {
      // OpenEXR's message names the temporary file; the system's reason is what the user needs.
      return "write error: " + systemReason(e);
    } catch (const std::exception& e) {
      return std::string("OpenEXR error: ") + e.what();
    }
  }

 private:
  // The errno behind a failed write, from the exception class OpenEXR chose for it
  // (Iex::throwErrnoExc); OpenEXR's own words for any other.
  static std::string systemReason(const Iex::ErrnoExc& e) {
    int code = 0;
    if (dynamic_cast<const Iex::EfbigExc*>(&e) != nullptr) code = EFBIG;
    if (dynamic_cast<const Iex::EnospcExc*>(&e) != nullptr) code = ENOSPC;
    if (dynamic_cast<const Iex::EdquotExc*>(&e) != nullptr) code = EDQUOT;
    if (dynamic_cast<const Iex::EioExc*>(&e) != nullptr) code = EIO;
    if (dynamic_cast<const Iex::EaccesExc*>(&e) != nullptr) code = EACCES;
    if (dynamic_cast<const Iex::ErofsExc*>(&e) != nullptr) code = EROFS;
    return code != 0 ? std::strerror(code) : e.what();
  }
};

}  // namespace
}  // namespace glint::exr_module

GLINT_DEFINE_MODULE_IDENTITY(glint::exr_module::kModuleIdentity)

extern "C" {

[[gnu::visibility("default")]] glint::exr_module::Codec* glint_exr_codec() {
  static glint::exr_module::OpenExrCodec codec;
  return &codec;
}

}  // extern "C"
