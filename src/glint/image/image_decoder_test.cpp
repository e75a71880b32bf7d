// Image texture decoding: sRGB decode of 8-bit images, PNG, JPEG (a real file of Debian's
// assimp-testmodels), EXR and Radiance HDR (flat and run-length), the headers, and refusals.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "glint/image/image_decoder.h"
#include "glint/image/image_writer.h"
#include "glint/render/film.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("glint_image_decoder_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::vector<std::uint8_t> bytesOf(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A 3×2 film whose pixel (x, y) is ((x + 1)·60, y·200, 17) / 255 linear: written with the linear
// encoding, its PNG codes are exactly those numbers.
Film codesFilm() {
  Film film(3, 2, PixelRegion{0, 0, 3, 2});
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x)
      film.at(x, y) = Color((x + 1) * 60 / 255.0, y * 200 / 255.0, 17 / 255.0);
  }
  return film;
}

TEST(ImageDecoder, SrgbDecodesEightBitCodes) {
  EXPECT_NEAR(srgbToLinear(0.5), 0.214041, 1e-6);
  const fs::path png = scratch("codes.png");
  writeImage(codesFilm(), png, Encoding::Linear);
  const std::vector<std::uint8_t> bytes = bytesOf(png);
  const RgbImage srgb = decodeImage(bytes, ImageEncoding::Srgb);
  const RgbImage linear = decodeImage(bytes, ImageEncoding::Linear);
  ASSERT_EQ(srgb.width, 3);
  ASSERT_EQ(srgb.height, 2);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      const std::size_t at = static_cast<std::size_t>(3 * (y * 3 + x));
      const int codes[3] = {(x + 1) * 60, y * 200, 17};
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(srgb.pixels[at + c], srgbToLinear(codes[c] / 255.0), 1e-6) << x << y << c;
        EXPECT_NEAR(linear.pixels[at + c], codes[c] / 255.0, 1e-6);
      }
    }
  }
  // The header alone gives the size without decoding.
  const ImageHeader header = readImageHeader(bytes);
  EXPECT_EQ(header.format, ImageFormat::Png);
  EXPECT_EQ(header.width, 3u);
  EXPECT_EQ(header.height, 2u);
}

TEST(ImageDecoder, ExrRoundTripsLinearValues) {
  Film film(2, 2, PixelRegion{0, 0, 2, 2});
  film.at(0, 0) = Color(0.25, 4, 100);
  film.at(1, 1) = Color(0.5, 0, 1);
  const fs::path exr = scratch("values.exr");
  writeImage(film, exr, Encoding::Linear);
  const std::vector<std::uint8_t> bytes = bytesOf(exr);
  EXPECT_EQ(readImageHeader(bytes).format, ImageFormat::Exr);
  EXPECT_EQ(readImageHeader(bytes).width, 2u);
  const RgbImage image = decodeImage(bytes, ImageEncoding::Srgb);  // EXR is linear regardless
  EXPECT_NEAR(image.pixels[0], 0.25, 1e-3);
  EXPECT_NEAR(image.pixels[1], 4, 1e-2);
  EXPECT_NEAR(image.pixels[2], 100, 0.1);
  EXPECT_NEAR(image.pixels[9], 0.5, 1e-3);
}

// A Radiance file of w×1 pixels, all RGBE (128, 64, 32, 129): (128.5, 64.5, 32.5) / 128.
std::string hdrFile(int width, bool runLength) {
  std::string out = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X " + std::to_string(width) + "\n";
  const unsigned char rgbe[4] = {128, 64, 32, 129};
  if (!runLength) {
    for (int x = 0; x < width; ++x) out.append(reinterpret_cast<const char*>(rgbe), 4);
    return out;
  }
  out += {2, 2, static_cast<char>(width >> 8), static_cast<char>(width & 255)};
  for (int plane = 0; plane < 4; ++plane) {
    out += static_cast<char>(128 + width);  // one run of the whole scanline
    out += static_cast<char>(rgbe[plane]);
  }
  return out;
}

TEST(ImageDecoder, RadianceHdrFlatAndRunLength) {
  for (const bool runLength : {false, true}) {
    const std::string file = hdrFile(16, runLength);
    const std::vector<std::uint8_t> bytes(file.begin(), file.end());
    const ImageHeader header = readImageHeader(bytes);
    EXPECT_EQ(header.format, ImageFormat::Hdr);
    EXPECT_EQ(header.width, 16u);
    const RgbImage image = decodeImage(bytes, ImageEncoding::Srgb);
    ASSERT_EQ(image.pixels.size(), 48u);
    EXPECT_NEAR(image.pixels[45], 128.5 / 128, 1e-6);
    EXPECT_NEAR(image.pixels[46], 64.5 / 128, 1e-6);
    EXPECT_NEAR(image.pixels[47], 32.5 / 128, 1e-6);
    // Cut short: refused, not read past the end.
    const std::vector<std::uint8_t> cut(bytes.begin(), bytes.end() - 3);
    EXPECT_THROW(decodeImage(cut, ImageEncoding::Srgb), ImageReadError);
  }
}

TEST(ImageDecoder, FilesTooShortForTheirSizeAreRefusedBeforeTheirPixelsAreAllocated) {
  // A scanline of 127 pixels in one run per plane is the shortest an HDR scanline can be: read.
  const std::string shortest = hdrFile(127, true);
  EXPECT_EQ(
      decodeImage(std::vector<std::uint8_t>(shortest.begin(), shortest.end()), ImageEncoding::Srgb)
          .pixels.size(),
      127u * 3);
  // A few bytes claiming 8192 × 8192 pixels (805 MB of floats): refused by their count.
  const auto expectCutShort = [](const std::vector<std::uint8_t>& bytes, const char* what) {
    try {
      decodeImage(bytes, ImageEncoding::Srgb);
      ADD_FAILURE() << what << " was decoded";
    } catch (const ImageReadError& e) {
      EXPECT_NE(std::string(e.what()).find("it is cut short"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("8192×8192 pixels need at least"), std::string::npos)
          << e.what();
    }
  };
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 8192\n";
  hdr += std::string(40, '\x02');
  expectCutShort(std::vector<std::uint8_t>(hdr.begin(), hdr.end()), "a 91-byte HDR");
  const fs::path png = scratch("claims.png");
  writeImage(codesFilm(), png, Encoding::Srgb);
  std::vector<std::uint8_t> bytes = bytesOf(png);
  for (const int at : {16, 20}) {  // IHDR's width and height, big-endian
    bytes[at] = 0;
    bytes[at + 1] = 0;
    bytes[at + 2] = 0x20;
    bytes[at + 3] = 0;
  }
  expectCutShort(bytes, "a small PNG claiming 8192 × 8192");
}

TEST(ImageDecoder, JpegFromAssimpTestModels) {
  const fs::path jpeg = "/usr/share/assimp/models/OBJ/wal67ar_small.jpg";
  if (!fs::exists(jpeg)) GTEST_SKIP() << "assimp-testmodels is not installed";
  const std::vector<std::uint8_t> bytes = bytesOf(jpeg);
  const ImageHeader header = readImageHeader(bytes);
  EXPECT_EQ(header.format, ImageFormat::Jpeg);
  const RgbImage image = decodeImage(bytes, ImageEncoding::Srgb);
  EXPECT_EQ(image.width, static_cast<int>(header.width));
  EXPECT_EQ(image.height, static_cast<int>(header.height));
  float lo = 1;
  float hi = 0;
  for (const float v : image.pixels) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  EXPECT_GE(lo, 0);
  EXPECT_LE(hi, 1);
  EXPECT_GT(hi - lo, 0.2);  // a picture, not a flat colour
  // Without only its end marker: the same image (the marker is implied).
  const std::vector<std::uint8_t> unended(bytes.begin(), bytes.end() - 2);
  EXPECT_EQ(decodeImage(unended, ImageEncoding::Srgb).pixels, image.pixels);
  // Cut short anywhere past its header: refused (libjpeg would fill the missing rows with grey and
  // only warn), never a crash.
  for (const std::size_t keep : {std::size_t{200}, bytes.size() / 2, bytes.size() - 40}) {
    SCOPED_TRACE(keep);
    const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + keep);
    try {
      decodeImage(cut, ImageEncoding::Srgb);
      ADD_FAILURE() << "a JPEG cut to " << keep << " of " << bytes.size() << " bytes decoded";
    } catch (const ImageReadError& e) {
      EXPECT_NE(std::string(e.what()).find("invalid JPEG file"), std::string::npos) << e.what();
    }
  }
}

TEST(ImageDecoder, HeadersRefuseWhatIsNotAnImage) {
  const auto header = [](const std::string& s) {
    return readImageHeader(std::vector<std::uint8_t>(s.begin(), s.end()));
  };
  EXPECT_THROW(header(""), ImageReadError);
  EXPECT_THROW(header("GIF89a....."), ImageReadError);
  EXPECT_THROW(header("\x89PNG\r\n\x1a\n"), ImageReadError);          // no IHDR
  EXPECT_THROW(header("#?RADIANCE\n\n+X 4 -Y 4\n"), ImageReadError);  // an unusual orientation
  // A negative size is malformed, not 2^64 − 5 pixels past the texture limit.
  try {
    header("#?RADIANCE\n\n-Y -5 +X 10\n");
    ADD_FAILURE() << "a negative height was accepted";
  } catch (const ImageReadError& e) {
    EXPECT_NE(std::string(e.what()).find("sizes in digits"), std::string::npos) << e.what();
  }
  EXPECT_THROW(header("#?RADIANCE\n\n-Y 5 +X -10\n"), ImageReadError);
  try {
    header("#?RADIANCE\n\n-Y 100000 +X 100000\n");
    ADD_FAILURE() << "a 10-gigapixel image was accepted";
  } catch (const ImageReadError& e) {
    EXPECT_NE(std::string(e.what()).find("texture limit"), std::string::npos) << e.what();
  }
  // A PNG cut after its header: refused by libpng's error, no crash.
  const fs::path png = scratch("cut.png");
  writeImage(codesFilm(), png, Encoding::Srgb);
  std::vector<std::uint8_t> bytes = bytesOf(png);
  bytes.resize(40);
  EXPECT_THROW(decodeImage(bytes, ImageEncoding::Srgb), ImageReadError);
}

TEST(ImageDecoder, ReadsRegularFilesOnly) {
  try {
    readImageFile(scratch("missing.png"), ImageEncoding::Srgb);
    ADD_FAILURE();
  } catch (const ImageReadError& e) {
    EXPECT_STREQ(e.what(), "no such file");
  }
  EXPECT_THROW(readImageFile(scratch(""), ImageEncoding::Srgb), ImageReadError);  // a folder
  const fs::path fifo = scratch("fifo.png");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    readImageFile(fifo, ImageEncoding::Srgb);
    ADD_FAILURE();
  } catch (const ImageReadError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
  // The header is handed to `accept` before the pixels are decoded; it may refuse.
  const fs::path png = scratch("accept.png");
  writeImage(codesFilm(), png, Encoding::Srgb);
  int seen = 0;
  EXPECT_THROW(readImageFile(png, ImageEncoding::Srgb,
                             [&](const ImageHeader& h) {
                               seen = static_cast<int>(h.width);
                               throw ImageReadError("over budget");
                             }),
               ImageReadError);
  EXPECT_EQ(seen, 3);
}

// A progressive JPEG of one 8 × 8 grey block: a DC scan, then `acScans` identical AC scans (each
// one end-of-band run) — valid to libjpeg, and each scan a pass over the whole image.
std::vector<std::uint8_t> progressiveJpeg(int acScans) {
  std::vector<std::uint8_t> f = {0xFF, 0xD8};
  const auto segment = [&](std::uint8_t marker, std::vector<std::uint8_t> payload) {
    const std::size_t length = payload.size() + 2;
    f.insert(f.end(), {0xFF, marker, static_cast<std::uint8_t>(length >> 8),
                       static_cast<std::uint8_t>(length)});
    f.insert(f.end(), payload.begin(), payload.end());
  };
  std::vector<std::uint8_t> table = {0};  // DQT: table 0, all ones
  table.resize(65, 1);
  segment(0xDB, table);
  segment(0xC2, {8, 0, 8, 0, 8, 1, 1, 0x11, 0});  // SOF2: 8 × 8, one component
  std::vector<std::uint8_t> dc = {0x00, 1};       // DHT DC 0: one code of length 1, symbol 0
  dc.resize(17, 0);
  dc.push_back(0);
  segment(0xC4, dc);
  std::vector<std::uint8_t> ac = {0x10, 1};  // DHT AC 0: one code of length 1, symbol 0 (EOB)
  ac.resize(17, 0);
  ac.push_back(0);
  segment(0xC4, ac);
  segment(0xDA, {1, 1, 0x00, 0, 0, 0x00});  // SOS: DC first scan
  f.push_back(0x7F);                        // the block's DC difference 0 (bit 0), padded with 1s
  for (int k = 0; k < acScans; ++k) {
    segment(0xDA, {1, 1, 0x00, 1, 63, 0x00});  // SOS: AC 1..63 first scan
    f.push_back(0x7F);                         // EOB, padded with 1s
  }
  f.insert(f.end(), {0xFF, 0xD9});
  return f;
}

// A file of thousands of scans redoes the image for each (27 s per MB of them): past 500 scans
// (libjpeg-turbo's suggested limit; encoders write about ten) it is refused, naming why.
TEST(ImageDecoder, ProgressiveJpegsOfTooManyScansAreRefused) {
  const RgbImage grey = decodeImage(progressiveJpeg(499), ImageEncoding::Linear);
  ASSERT_EQ(grey.width, 8);
  ASSERT_EQ(grey.height, 8);
  try {
    decodeImage(progressiveJpeg(500), ImageEncoding::Linear);
    FAIL() << "501 scans decoded";
  } catch (const ImageReadError& e) {
    EXPECT_STREQ(e.what(), "invalid JPEG file: it has more than 500 scans");
  }
}

}  // namespace
}  // namespace glint
