// PNG (libpng), PPM (P6) and OpenEXR writers behind one atomic write-then-rename policy.
#include "glint/image/image_writer.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <system_error>
#include <vector>

namespace glint {

std::uint8_t encodeChannel(double linear, Encoding encoding) {
  if (std::isnan(linear)) return 0;
  const double clamped = std::clamp(linear, 0.0, 1.0);
  const double encoded = encoding == Encoding::Srgb ? linearToSrgb(clamped) : clamped;
  // std::lround (half away from zero) of v in [0, 255], without the libm call: v − ⌊v⌋ is exact
  // there (Sterbenz), so comparing it with 0.5 rounds exactly as lround does.
  const double v = std::clamp(encoded, 0.0, 1.0) * 255.0;
  const auto whole = static_cast<int>(v);
  return static_cast<std::uint8_t>(whole + (v - whole >= 0.5 ? 1 : 0));
}

double decodeChannel(std::uint8_t code, Encoding encoding) {
  const double encoded = code / 255.0;
  return encoding == Encoding::Srgb ? srgbToLinear(encoded) : encoded;
}

namespace {

std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

[[noreturn]] void fail(const std::filesystem::path& target, const std::string& reason) {
  throw ImageWriteError("cannot write " + quoted(target) + ": " + reason);
}

// A temporary file beside the target, created exclusively, removed on destruction unless committed
// by renaming it over the target. This is what makes every write all-or-nothing.
class TemporaryFile {
 public:
  explicit TemporaryFile(const std::filesystem::path& target) : target_(target) {
    const std::filesystem::path folder =
        target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
    std::error_code ec;
    const auto status = std::filesystem::status(folder, ec);
    if (!std::filesystem::exists(status))
      fail(target, "folder " + quoted(folder) + " does not exist");
    if (!std::filesystem::is_directory(status)) fail(target, quoted(folder) + " is not a folder");
    if (!target.has_filename()) fail(target, "the path names no file");

    static std::atomic<unsigned long> counter{0};
    // Exclusive creation ("x"): a name collision (another process, a stale file) takes the next n.
    for (int attempt = 0; attempt < 100; ++attempt) {
      const std::string name = "." + target.filename().string() + ".tmp-" +
                               std::to_string(::getpid()) + "-" + std::to_string(counter++);
      path_ = target.has_parent_path() ? target.parent_path() / name : std::filesystem::path(name);
      file_ = std::fopen(path_.c_str(), "wbx");
      if (file_ || errno != EEXIST) break;
    }
    if (!file_) fail(target, std::strerror(errno));
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() {
    if (file_) std::fclose(file_);
    if (!committed_) {
      std::error_code ignored;
      std::filesystem::remove(path_, ignored);
    }
  }

  std::FILE* stream() const { return file_; }
  const std::filesystem::path& path() const { return path_; }

  // Closes the stream (without writing more through it).
  void close() {
    if (!file_) return;
    const bool failed = std::ferror(file_) != 0;
    const int savedErrno = errno;
    const int closed = std::fclose(file_);
    file_ = nullptr;
    if (failed) fail(target_, std::string("write error: ") + std::strerror(savedErrno));
    if (closed != 0) fail(target_, std::string("write error: ") + std::strerror(errno));
  }

  // Flushes, closes and atomically replaces the target.
  void commit() {
    close();
    std::error_code ec;
    std::filesystem::rename(path_, target_, ec);
    if (ec) fail(target_, ec.message());
    committed_ = true;
  }

 private:
  std::filesystem::path target_;
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

void requireNonEmpty(const Film& film, const std::filesystem::path& path) {
  if (film.width() <= 0 || film.height() <= 0) fail(path, "the image is empty");
}

// Interleaved 8-bit RGB rows, top row first.
std::vector<std::uint8_t> encodeRgb8(const Film& film, Encoding encoding) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(film.width()) * film.height() * 3);
  std::uint8_t* out = bytes.data();
  for (const Color& c : film.pixels()) {  // row-major, top row first: the file's order
    *out++ = encodeChannel(c.r, encoding);
    *out++ = encodeChannel(c.g, encoding);
    *out++ = encodeChannel(c.b, encoding);
  }
  return bytes;
}

// libpng reports errors by longjmp; the message is kept here. The setjmp frame below holds only
// trivially destructible locals, so the jump skips no destructor.
struct PngErrorState {
  std::jmp_buf jump;
  char message[256];
};

void pngError(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", message);
  std::longjmp(state->jump, 1);
}

void pngWarning(png_structp, png_const_charp) {}

// Returns false (with state.message set) when libpng fails.
bool writePngStream(std::FILE* file, const std::uint8_t* rgb, png_uint_32 width, png_uint_32 height,
                    bool srgb, PngErrorState& state) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, pngError, pngWarning);
  if (!png) {
    std::snprintf(state.message, sizeof state.message, "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(state.message, sizeof state.message, "out of memory");
    return false;
  }
  if (setjmp(state.jump)) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // sRGB-encoded codes say so; linear codes carry no colour-space chunk at all (no gAMA).
  if (srgb) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  for (png_uint_32 row = 0; row < height; ++row) {
    png_write_row(png, rgb + static_cast<std::size_t>(row) * width * 3);
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

class PngWriter final : public ImageWriter {
 public:
  void write(const Film& film, const std::filesystem::path& path,
             Encoding encoding) const override {
    requireNonEmpty(film, path);
    const std::vector<std::uint8_t> rgb = encodeRgb8(film, encoding);
    TemporaryFile temp(path);
    PngErrorState state{};
    if (!writePngStream(temp.stream(), rgb.data(), static_cast<png_uint_32>(film.width()),
                        static_cast<png_uint_32>(film.height()), encoding == Encoding::Srgb,
                        state)) {
      fail(path, std::string("PNG error: ") + state.message);
    }
    temp.commit();
  }
};

class PpmWriter final : public ImageWriter {
 public:
  void write(const Film& film, const std::filesystem::path& path,
             Encoding encoding) const override {
    requireNonEmpty(film, path);
    const std::vector<std::uint8_t> rgb = encodeRgb8(film, encoding);
    TemporaryFile temp(path);
    const std::string header =
        "P6\n" + std::to_string(film.width()) + " " + std::to_string(film.height()) + "\n255\n";
    std::fwrite(header.data(), 1, header.size(), temp.stream());
    std::fwrite(rgb.data(), 1, rgb.size(), temp.stream());
    temp.commit();
  }
};

// Linear half of the pipeline: the film's values as 32-bit floats, unclamped, no encoding.
class ExrWriter final : public ImageWriter {
 public:
  void write(const Film& film, const std::filesystem::path& path, Encoding) const override {
    requireNonEmpty(film, path);
    const int width = film.width();
    const int height = film.height();
    const std::size_t count = static_cast<std::size_t>(width) * height;
    std::vector<float> red(count), green(count), blue(count);
    for (std::size_t i = 0; i < count; ++i) {
      const Color& c = film.pixels()[i];
      red[i] = static_cast<float>(c.r);
      green[i] = static_cast<float>(c.g);
      blue[i] = static_cast<float>(c.b);
    }
    TemporaryFile temp(path);
    temp.close();  // reserves the unique name; OpenEXR reopens it by path
    try {
      Imf::Header header(width, height);
      header.channels().insert("R", Imf::Channel(Imf::FLOAT));
      header.channels().insert("G", Imf::Channel(Imf::FLOAT));
      header.channels().insert("B", Imf::Channel(Imf::FLOAT));
      Imf::FrameBuffer frame;
      const std::size_t xStride = sizeof(float);
      const std::size_t yStride = sizeof(float) * static_cast<std::size_t>(width);
      frame.insert("R",
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(red.data()), xStride, yStride));
      frame.insert("G",
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(green.data()), xStride, yStride));
      frame.insert("B",
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(blue.data()), xStride, yStride));
      Imf::OutputFile out(temp.path().c_str(), header);
      out.setFrameBuffer(frame);
      out.writePixels(height);
    } catch (const std::exception& e) {
      fail(path, std::string("OpenEXR error: ") + e.what());
    }
    temp.commit();
  }
};

std::string lowercaseExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}

}  // namespace

std::unique_ptr<ImageWriter> writerForPath(const std::filesystem::path& path) {
  const std::string ext = lowercaseExtension(path);
  if (ext == ".png") return std::make_unique<PngWriter>();
  if (ext == ".ppm") return std::make_unique<PpmWriter>();
  if (ext == ".exr") return std::make_unique<ExrWriter>();
  return nullptr;
}

void writeImage(const Film& film, const std::filesystem::path& path, Encoding encoding) {
  const std::unique_ptr<ImageWriter> writer = writerForPath(path);
  if (!writer) {
    const std::string ext = path.extension().string();
    fail(path,
         (ext.empty() ? std::string("no file extension") : "unknown file extension '" + ext + "'") +
             " (expected .png, .ppm or .exr)");
  }
  writer->write(film, path, encoding);
}

}  // namespace glint
