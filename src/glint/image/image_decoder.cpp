// PNG, JPEG, EXR and Radiance HDR decoding from memory, and texture files read from disk.
#include "glint/image/image_decoder.h"

#include <jpeglib.h>
// After jpeglib.h, which it needs.
#include <jerror.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include <fmt/format.h>

#include "glint/core/color.h"
#include "glint/core/file_access.h"
#include "glint/image/exr_module.h"

namespace glint {

namespace {

// 8-bit code → linear value, for sRGB-encoded images (the transfer function once per code).
const std::array<float, 256>& srgbTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i)
      t[static_cast<std::size_t>(i)] = static_cast<float>(srgbToLinear(i / 255.0));
    return t;
  }();
  return table;
}

RgbImage emptyImage(const ImageHeader& h) {
  RgbImage image{static_cast<int>(h.width), static_cast<int>(h.height), {}};
  image.pixels.resize(static_cast<std::size_t>(h.width) * h.height * 3);
  return image;
}

// Fills `image` from 8-bit RGB samples.
void fromBytes(const std::uint8_t* rgb, std::size_t count, ImageEncoding encoding, float* out) {
  const std::array<float, 256>& table = srgbTable();
  for (std::size_t i = 0; i < count; ++i) {
    out[i] = encoding == ImageEncoding::Srgb ? table[rgb[i]] : static_cast<float>(rgb[i] / 255.0);
  }
}

// --- PNG (libpng, from memory) -------------------------------------------------------------------

// libpng reports errors by longjmp; the message is kept here. The frame holding setjmp creates no
// object with a destructor, so the jump skips none.
struct PngState {
  std::span<const std::uint8_t> bytes;
  std::size_t at = 0;
  std::jmp_buf jump;
  char message[256] = {};
};

void pngError(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", message);
  std::longjmp(state->jump, 1);
}
void pngWarning(png_structp, png_const_charp) {}

void pngRead(png_structp png, png_bytep data, png_size_t size) {
  auto* state = static_cast<PngState*>(png_get_io_ptr(png));
  if (size > state->bytes.size() - state->at) png_error(png, "the file is cut short");
  std::memcpy(data, state->bytes.data() + state->at, size);
  state->at += size;
}

// Decodes into `samples` (16-bit RGB, host order) with row pointers `rows`; both sized here after
// the header. Returns false with state.message set on failure.
bool decodePngSamples(PngState& state, const ImageHeader& header,
                      std::vector<std::uint16_t>& samples, std::vector<png_bytep>& rows) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, pngError, pngWarning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return false;
  }
  if (setjmp(state.jump)) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, &state, pngRead);
  // A hostile file's chunks may claim gigabytes of text or ICC data: cap what libpng allocates.
  png_set_user_limits(png, kMaxTextureSide, kMaxTextureSide);
  png_set_chunk_malloc_max(png, 8 << 20);
  png_read_info(png, info);
  if (png_get_image_width(png, info) != header.width ||
      png_get_image_height(png, info) != header.height) {
    png_error(png, "its size changed between reads");
  }
  // Everything becomes 16-bit RGB: palettes and low bit depths expanded, grey to RGB, alpha
  // dropped.
  png_set_expand(png);
  png_set_gray_to_rgb(png);
  png_set_strip_alpha(png);
  png_set_expand_16(png);
  png_set_swap(png);  // 16-bit samples in host (little-endian) order
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != std::size_t{header.width} * 6) {
    png_error(png, "an unexpected pixel layout");
  }
  samples.resize(std::size_t{header.width} * header.height * 3);
  rows.resize(header.height);
  for (std::uint32_t y = 0; y < header.height; ++y) {
    rows[y] = reinterpret_cast<png_bytep>(samples.data() + std::size_t{y} * header.width * 3);
  }
  png_read_image(png, rows.data());
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

RgbImage decodePng(std::span<const std::uint8_t> bytes, const ImageHeader& header,
                   ImageEncoding encoding) {
  PngState state;
  state.bytes = bytes;
  std::vector<std::uint16_t> samples;
  std::vector<png_bytep> rows;
  if (!decodePngSamples(state, header, samples, rows)) {
    throw ImageReadError(fmt::format("invalid PNG file: {}",
                                     state.message[0] != 0 ? state.message : "libpng failed"));
  }
  RgbImage image = emptyImage(header);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double value = samples[i] / 65535.0;
    image.pixels[i] =
        static_cast<float>(encoding == ImageEncoding::Srgb ? srgbToLinear(value) : value);
  }
  return image;
}

// --- JPEG (libjpeg-turbo's libjpeg API, from memory) --------------------------------------------

struct JpegError {
  jpeg_error_mgr manager;  // first: libjpeg casts the pointer back
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {};
};

void jpegErrorExit(j_common_ptr info) {
  auto* error = reinterpret_cast<JpegError*>(info->err);
  (*info->err->format_message)(info, error->message);
  std::longjmp(error->jump, 1);
}
void jpegOutputMessage(j_common_ptr) {}
// libjpeg warns, and goes on, when the data ends before the image does: it fills the missing
// scanlines with grey. A cut-short file is refused, as PNG and HDR files are: the file's end
// (JWRN_JPEG_EOF) or its end marker (JWRN_HIT_MARKER: decodeJpegSamples appends one to a file
// without it) met inside the entropy-coded data. Other warnings (stray bytes before a marker,
// which many cameras write) are passed over as viewers pass them.
void jpegEmitMessage(j_common_ptr info, int level) {
  if (level < 0 &&
      (info->err->msg_code == JWRN_JPEG_EOF || info->err->msg_code == JWRN_HIT_MARKER)) {
    auto* error = reinterpret_cast<JpegError*>(info->err);
    std::snprintf(error->message, sizeof error->message, "the file is cut short");
    std::longjmp(error->jump, 1);
  }
}

// Scans a progressive file may have (libjpeg-turbo's suggested scan limit): encoders write about
// ten; a small file of thousands of scans, each redoing the whole image, took 27 s per MB.
constexpr int kMaxJpegScans = 500;

// Called by libjpeg as it reads (jpeg_progress_mgr): refuses a file past kMaxJpegScans scans.
void jpegProgress(j_common_ptr info) {
  if (!info->is_decompressor) return;
  const auto* decompress = reinterpret_cast<j_decompress_ptr>(info);
  if (decompress->input_scan_number <= kMaxJpegScans) return;
  auto* error = reinterpret_cast<JpegError*>(info->err);
  std::snprintf(error->message, sizeof error->message, "it has more than %d scans", kMaxJpegScans);
  std::longjmp(error->jump, 1);
}

bool decodeJpegSamples(std::span<const std::uint8_t> file, const ImageHeader& header,
                       std::vector<std::uint8_t>& samples, JpegError& error) {
  // A file whose data is whole but lacks the end marker (FF D9) decodes as if it had one: the
  // marker is appended, so that only missing data is "cut short". (Before the setjmp below: a
  // longjmp must not cross a live object's lifetime.)
  std::vector<std::uint8_t> ended;
  std::span<const std::uint8_t> bytes = file;
  if (file.size() < 2 || file[file.size() - 2] != 0xFF || file[file.size() - 1] != 0xD9) {
    ended.reserve(file.size() + 2);
    ended.assign(file.begin(), file.end());
    ended.push_back(0xFF);
    ended.push_back(0xD9);
    bytes = ended;
  }
  jpeg_progress_mgr progress{};
  progress.progress_monitor = jpegProgress;
  jpeg_decompress_struct info;
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jpegErrorExit;
  error.manager.output_message = jpegOutputMessage;
  error.manager.emit_message = jpegEmitMessage;
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  info.progress = &progress;
  // Progressive files buffer every coefficient: cap the memory libjpeg may take for them.
  info.mem->max_memory_to_use =
      std::max<long>(64L << 20, static_cast<long>(header.width) * header.height * 8);
  jpeg_mem_src(&info, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&info, TRUE);
  if (info.image_width != header.width || info.image_height != header.height) {
    std::snprintf(error.message, sizeof error.message, "its frame size is inconsistent");
    jpeg_destroy_decompress(&info);
    return false;
  }
  info.out_color_space = JCS_RGB;  // grey, YCbCr (and CMYK/YCCK: refused by libjpeg) to RGB
  jpeg_start_decompress(&info);
  if (info.output_components != 3) {
    std::snprintf(error.message, sizeof error.message, "an unsupported colour space");
    jpeg_destroy_decompress(&info);
    return false;
  }
  samples.resize(std::size_t{header.width} * header.height * 3);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = samples.data() + std::size_t{info.output_scanline} * header.width * 3;
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

RgbImage decodeJpeg(std::span<const std::uint8_t> bytes, const ImageHeader& header,
                    ImageEncoding encoding) {
  JpegError error;
  std::vector<std::uint8_t> samples;
  if (!decodeJpegSamples(bytes, header, samples, error)) {
    throw ImageReadError(fmt::format("invalid JPEG file: {}", error.message));
  }
  RgbImage image = emptyImage(header);
  fromBytes(samples.data(), samples.size(), encoding, image.pixels.data());
  return image;
}

// --- EXR (OpenEXR's RGBA interface over memory, in the module exr_module.h) ---------------------

RgbImage decodeExr(std::span<const std::uint8_t> bytes, const ImageHeader& header) {
  std::string error;
  exr_module::Codec* const codec = exr_module::exrCodec(error);
  if (codec == nullptr) throw ImageReadError("cannot read EXR files: " + error);
  RgbImage image{static_cast<int>(header.width), static_cast<int>(header.height), {}};
  error = codec->decode(bytes, header.width, header.height, image.pixels);
  if (!error.empty()) throw ImageReadError(error);
  return image;
}

// --- Radiance HDR (RGBE with the "new" run-length scanlines of Greg Ward's format) --------------

// One RGBE pixel → linear RGB: mantissas × 2^(E − 136), 0 for E = 0.
void rgbeToFloat(const std::uint8_t* rgbe, float* out) {
  if (rgbe[3] == 0) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  const float scale = std::ldexp(1.0f, static_cast<int>(rgbe[3]) - (128 + 8));
  for (int c = 0; c < 3; ++c) out[c] = (static_cast<float>(rgbe[c]) + 0.5f) * scale;
}

// Whether an HDR scanline of this width may be run-length encoded (the new scheme: the reader and
// the file-size bound share this rule).
bool hdrRunsAllowed(std::uint32_t width) { return width >= 8 && width < 32768; }

RgbImage decodeHdr(std::span<const std::uint8_t> bytes, const ImageHeader& header,
                   std::size_t pixelsStart) {
  const std::uint32_t width = header.width;
  RgbImage image = emptyImage(header);
  std::vector<std::uint8_t> line(std::size_t{width} * 4);
  std::size_t at = pixelsStart;
  const auto need = [&](std::size_t n) {
    if (n > bytes.size() - at) throw ImageReadError("invalid HDR file: it is cut short");
  };
  for (std::uint32_t y = 0; y < header.height; ++y) {
    need(4);
    const bool runLength = hdrRunsAllowed(width) && bytes[at] == 2 && bytes[at + 1] == 2 &&
                           (bytes[at + 2] & 0x80) == 0;
    if (runLength) {
      if ((std::uint32_t{bytes[at + 2]} << 8 | bytes[at + 3]) != width) {
        throw ImageReadError("invalid HDR file: a scanline's length does not match the width");
      }
      at += 4;
      // Four planes (R, G, B, E), each as runs (count > 128: count − 128 copies of one byte) and
      // dumps (count bytes as they are).
      for (int plane = 0; plane < 4; ++plane) {
        std::uint32_t x = 0;
        while (x < width) {
          need(1);
          std::uint32_t count = bytes[at++];
          if (count > 128) {
            count -= 128;
            if (count > width - x)
              throw ImageReadError("invalid HDR file: a run overflows its scanline");
            need(1);
            const std::uint8_t value = bytes[at++];
            for (std::uint32_t k = 0; k < count; ++k)
              line[4 * (x + k) + static_cast<std::size_t>(plane)] = value;
          } else {
            if (count == 0 || count > width - x) {
              throw ImageReadError("invalid HDR file: a run overflows its scanline");
            }
            need(count);
            for (std::uint32_t k = 0; k < count; ++k)
              line[4 * (x + k) + static_cast<std::size_t>(plane)] = bytes[at++];
          }
          x += count;
        }
      }
    } else {
      // Flat RGBE pixels (old run-length encodings are not read).
      need(std::size_t{width} * 4);
      std::memcpy(line.data(), bytes.data() + at, std::size_t{width} * 4);
      at += std::size_t{width} * 4;
    }
    float* row = image.pixels.data() + std::size_t{y} * width * 3;
    for (std::uint32_t x = 0; x < width; ++x) rgbeToFloat(line.data() + 4 * x, row + 3 * x);
  }
  return image;
}

// Reads up to `size` bytes at the descriptor's current offset.
std::size_t readUpTo(int fd, std::uint8_t* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(fd, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw ImageReadError("cannot read it: " + systemReason(errno));
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  return done;
}

ReadableFile openImageFile(const std::filesystem::path& path) {
  ReadableFile file = openForReading(path);
  switch (file.refusal) {
    case FileRefusal::None:
      return file;
    case FileRefusal::Missing:
      throw ImageReadError("no such file");
    case FileRefusal::Folder:
      throw ImageReadError("it is a folder, not an image file");
    case FileRefusal::NotRegular:
      throw ImageReadError("it is not a regular file (" + nonRegularKind(file.mode) + ")");
    case FileRefusal::System:
      break;
  }
  throw ImageReadError("cannot open it: " + systemReason(file.error));
}

// The fewest bytes a file of `header` can have, by the best each format's coding can do, or 0
// when no useful bound is known: a file below it is cut short, and is refused before its pixels
// (up to 3 GB of them) are allocated. PNG: the rows' bytes (a filter byte, then the samples at
// the IHDR's bit depth and colour type) deflated at deflate's best ratio, 1032:1 (a 258-byte
// match in two bits). HDR: a scanline is at least its 4-byte header and, per plane, a 2-byte run
// per 127 pixels, or flat RGBE pixels where runs are not allowed. JPEG (arithmetic coding can
// take less than a bit a block) and EXR are not bounded here.
std::uint64_t fewestFileBytes(std::span<const std::uint8_t> bytes, const ImageHeader& header,
                              std::size_t pixelsStart) {
  const std::uint64_t width = header.width;
  const std::uint64_t height = header.height;
  switch (header.format) {
    case ImageFormat::Png: {
      // IHDR's data starts at 16 (signature, length, type): width, height, depth, colour type.
      if (bytes.size() < 26) return 0;
      const std::uint64_t depth = bytes[24];
      const std::uint8_t colourType = bytes[25];
      const std::uint64_t channels = colourType == 2   ? 3
                                     : colourType == 4 ? 2
                                     : colourType == 6 ? 4
                                                       : 1;
      const std::uint64_t rowBytes = 1 + (width * channels * depth + 7) / 8;
      return height * rowBytes / 1032;
    }
    case ImageFormat::Hdr: {
      const std::uint64_t scanline =
          hdrRunsAllowed(header.width) ? 4 + 4 * 2 * ((width + 126) / 127) : 4 * width;
      return pixelsStart + height * scanline;
    }
    case ImageFormat::Jpeg:
    case ImageFormat::Exr:
      break;
  }
  return 0;
}

}  // namespace

RgbImage decodeImage(std::span<const std::uint8_t> bytes, ImageEncoding encoding) {
  std::size_t pixelsStart = 0;
  const ImageHeader header = readImageHeader(bytes, &pixelsStart);
  if (const std::uint64_t fewest = fewestFileBytes(bytes, header, pixelsStart);
      bytes.size() < fewest) {
    throw ImageReadError(
        fmt::format("invalid {} file: it is cut short ({} bytes; {}×{} pixels need at least {})",
                    header.format == ImageFormat::Png ? "PNG" : "HDR", bytes.size(), header.width,
                    header.height, fewest));
  }
  switch (header.format) {
    case ImageFormat::Png:
      return decodePng(bytes, header, encoding);
    case ImageFormat::Jpeg:
      return decodeJpeg(bytes, header, encoding);
    case ImageFormat::Exr:
      return decodeExr(bytes, header);
    case ImageFormat::Hdr:
      return decodeHdr(bytes, header, pixelsStart);
  }
  throw ImageReadError("unknown image format");
}

ImageHeader readImageFileHeader(const std::filesystem::path& path) {
  const ReadableFile file = openImageFile(path);
  std::vector<std::uint8_t> start(
      static_cast<std::size_t>(std::min<std::uint64_t>(file.size, kImageHeaderBytes)));
  start.resize(readUpTo(file.fd, start.data(), start.size()));
  return readImageHeader(start);
}

RgbImage readImageFile(const std::filesystem::path& path, ImageEncoding encoding,
                       const std::function<void(const ImageHeader&)>& accept) {
  const ReadableFile file = openImageFile(path);
  if (file.size > kMaxImageFileBytes) {
    throw ImageReadError(fmt::format("the file is larger than {} GiB", kMaxImageFileBytes >> 30));
  }
  std::vector<std::uint8_t> bytes(
      static_cast<std::size_t>(std::min<std::uint64_t>(file.size, kImageHeaderBytes)));
  bytes.resize(readUpTo(file.fd, bytes.data(), bytes.size()));
  const ImageHeader header = readImageHeader(bytes);
  if (accept) accept(header);
  const std::size_t head = bytes.size();
  bytes.resize(static_cast<std::size_t>(file.size));
  bytes.resize(head + readUpTo(file.fd, bytes.data() + head, bytes.size() - head));
  try {
    return decodeImage(bytes, encoding);
  } catch (const std::bad_alloc&) {
    throw ImageReadError("not enough memory to decode it");
  }
}

}  // namespace glint
