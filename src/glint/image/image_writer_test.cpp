#include "glint/image/image_writer.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "glint/core/atomic_file.h"
#include "glint/core/cancel.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

// A fresh folder under the system temp directory, removed with everything in it afterwards.
class ImageWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("glint-image-writer-" + std::string(info->name()) + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Files in the folder other than `keep` (temporaries would show up here).
  std::vector<std::string> filesExcept(const std::string& keep = "") const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      if (name != keep) names.push_back(name);
    }
    return names;
  }

  fs::path dir_;
};

// A 3×2 film with values that exercise clamping (negative, > 1), NaN and mid-range codes.
Film testFilm() {
  Film film(3, 2, PixelRegion{0, 0, 3, 2});
  film.at(0, 0) = Color(0, 0.5, 1);
  film.at(1, 0) = Color(2.5, -1, 0.25);
  film.at(2, 0) = Color(std::numeric_limits<double>::quiet_NaN(), 0.75, 0.1);
  film.at(0, 1) = Color(0.01, 0.02, 0.03);
  film.at(1, 1) = Color(1, 1, 1);
  film.at(2, 1) = Color(0.2, 0.4, 0.6);
  return film;
}

std::vector<std::uint8_t> expectedBytes(const Film& film, Encoding encoding) {
  std::vector<std::uint8_t> bytes;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const Color& c = film.at(x, y);
      bytes.push_back(encodeChannel(c.r, encoding));
      bytes.push_back(encodeChannel(c.g, encoding));
      bytes.push_back(encodeChannel(c.b, encoding));
    }
  return bytes;
}

std::vector<char> readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct PngContents {
  png_uint_32 width = 0, height = 0;
  int bitDepth = 0, colorType = 0;
  std::vector<std::uint8_t> rgb;
};

// Chunk types in file order, read from the raw bytes (libpng's info struct would report a gAMA
// implied by an sRGB chunk as present).
std::vector<std::string> pngChunks(const std::vector<char>& bytes) {
  std::vector<std::string> chunks;
  std::size_t at = 8;  // after the signature
  while (at + 8 <= bytes.size()) {
    const auto byte = [&](std::size_t i) {
      return static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i]));
    };
    const std::uint32_t length =
        byte(at) << 24 | byte(at + 1) << 16 | byte(at + 2) << 8 | byte(at + 3);
    chunks.emplace_back(bytes.begin() + static_cast<long>(at + 4),
                        bytes.begin() + static_cast<long>(at + 8));
    at += 12 + length;  // length, type, data, CRC
  }
  return chunks;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Low-level libpng read (no transforms) so the chunks and the raw codes can be checked.
bool readPngFile(std::FILE* file, PngContents& out) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, file);
  png_read_info(png, info);
  out.width = png_get_image_width(png, info);
  out.height = png_get_image_height(png, info);
  out.bitDepth = png_get_bit_depth(png, info);
  out.colorType = png_get_color_type(png, info);
  out.rgb.resize(static_cast<std::size_t>(out.width) * out.height * 3);
  for (png_uint_32 row = 0; row < out.height; ++row)
    png_read_row(png, out.rgb.data() + static_cast<std::size_t>(row) * out.width * 3, nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

PngContents readPng(const fs::path& path) {
  PngContents contents;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) ADD_FAILURE() << "cannot open " << path;
  if (file) {
    EXPECT_TRUE(readPngFile(file, contents)) << "libpng could not read " << path;
    std::fclose(file);
  }
  return contents;
}

TEST_F(ImageWriterTest, EncodeDecodeRoundTripsEveryCode) {
  for (int code = 0; code < 256; ++code) {
    const auto c = static_cast<std::uint8_t>(code);
    EXPECT_EQ(encodeChannel(decodeChannel(c, Encoding::Linear), Encoding::Linear), c);
    EXPECT_EQ(encodeChannel(decodeChannel(c, Encoding::Srgb), Encoding::Srgb), c);
    EXPECT_DOUBLE_EQ(decodeChannel(c, Encoding::Linear), code / 255.0);
  }
}

TEST_F(ImageWriterTest, EncodeClampsRoundsAndMapsNanToZero) {
  EXPECT_EQ(encodeChannel(-0.5, Encoding::Linear), 0);
  EXPECT_EQ(encodeChannel(7.0, Encoding::Linear), 255);
  EXPECT_EQ(encodeChannel(7.0, Encoding::Srgb), 255);
  EXPECT_EQ(encodeChannel(std::numeric_limits<double>::quiet_NaN(), Encoding::Srgb), 0);
  EXPECT_EQ(encodeChannel(std::numeric_limits<double>::infinity(), Encoding::Linear), 255);
  // Round to nearest: 0.5 → 127.5 → 128; just below the half-way point → 127.
  EXPECT_EQ(encodeChannel(0.5, Encoding::Linear), 128);
  EXPECT_EQ(encodeChannel(127.49 / 255, Encoding::Linear), 127);
  // sRGB: linear 0.5 encodes to 0.73536 → 187.516 → 188. The linear value of code 127.5 is
  // 0.2140411405, the boundary between codes 127 and 128.
  EXPECT_EQ(encodeChannel(0.5, Encoding::Srgb), 188);
  EXPECT_EQ(encodeChannel(0.21404114, Encoding::Srgb), 127);
  EXPECT_EQ(encodeChannel(0.21404115, Encoding::Srgb), 128);
  EXPECT_NEAR(decodeChannel(128, Encoding::Srgb), 0.2158605, 1e-6);
}

TEST_F(ImageWriterTest, PngRoundTripsBytesInBothEncodings) {
  const Film film = testFilm();
  for (const Encoding encoding : {Encoding::Srgb, Encoding::Linear}) {
    const fs::path path = dir_ / "image.png";
    writeImage(film, path, encoding);
    const PngContents png = readPng(path);
    EXPECT_EQ(png.width, 3u);
    EXPECT_EQ(png.height, 2u);
    EXPECT_EQ(png.bitDepth, 8);
    EXPECT_EQ(png.colorType, PNG_COLOR_TYPE_RGB);
    EXPECT_EQ(png.rgb, expectedBytes(film, encoding));
    const std::vector<std::string> chunks = pngChunks(readBytes(path));
    EXPECT_EQ(contains(chunks, "sRGB"), encoding == Encoding::Srgb);
    EXPECT_FALSE(contains(chunks, "gAMA"));
    EXPECT_FALSE(contains(chunks, "iCCP"));
    EXPECT_TRUE(contains(chunks, "IHDR") && contains(chunks, "IDAT") && contains(chunks, "IEND"));
  }
  // Spot-check the expected bytes themselves, so a broken encoder cannot agree with itself.
  const std::vector<std::uint8_t> linear = expectedBytes(film, Encoding::Linear);
  EXPECT_EQ(linear[0], 0);
  EXPECT_EQ(linear[1], 128);
  EXPECT_EQ(linear[2], 255);
  EXPECT_EQ(linear[3], 255);  // 2.5 clamps
  EXPECT_EQ(linear[4], 0);    // -1 clamps
  EXPECT_EQ(linear[6], 0);    // NaN
}

TEST_F(ImageWriterTest, PpmHasHeaderAndEncodedBytes) {
  const Film film = testFilm();
  const fs::path path = dir_ / "image.ppm";
  writeImage(film, path, Encoding::Srgb);
  const std::vector<char> bytes = readBytes(path);
  const std::string header = "P6\n3 2\n255\n";
  ASSERT_EQ(bytes.size(), header.size() + 3 * 2 * 3);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + static_cast<long>(header.size())), header);
  const std::vector<std::uint8_t> expected = expectedBytes(film, Encoding::Srgb);
  const std::vector<std::uint8_t> body(bytes.begin() + static_cast<long>(header.size()),
                                       bytes.end());
  EXPECT_EQ(body, expected);
}

TEST_F(ImageWriterTest, ExrKeepsUnclampedLinearFloats) {
  const Film film = testFilm();
  const fs::path path = dir_ / "image.EXR";  // extension matched case-insensitively
  writeImage(film, path, Encoding::Srgb);    // encoding does not apply to EXR

  Imf::InputFile in(path.c_str());
  const Imath::Box2i window = in.header().dataWindow();
  const int width = window.max.x - window.min.x + 1;
  const int height = window.max.y - window.min.y + 1;
  ASSERT_EQ(width, 3);
  ASSERT_EQ(height, 2);
  for (const char* name : {"R", "G", "B"}) {
    const Imf::Channel* channel = in.header().channels().findChannel(name);
    ASSERT_NE(channel, nullptr) << name;
    EXPECT_EQ(channel->type, Imf::FLOAT) << name;
  }
  std::vector<float> r(6), g(6), b(6);
  Imf::FrameBuffer frame;
  const std::size_t xs = sizeof(float);
  const std::size_t ys = sizeof(float) * 3;
  frame.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(r.data()), xs, ys));
  frame.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(g.data()), xs, ys));
  frame.insert("B", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(b.data()), xs, ys));
  in.setFrameBuffer(frame);
  in.readPixels(window.min.y, window.max.y);

  EXPECT_EQ(r[1], 2.5f);   // unclamped above 1
  EXPECT_EQ(g[1], -1.0f);  // and below 0
  EXPECT_EQ(b[1], 0.25f);
  EXPECT_TRUE(std::isnan(r[2]));
  for (std::size_t i = 0; i < 6; ++i) {
    const Color& c = film.pixels()[i];
    if (!std::isnan(c.r)) {
      EXPECT_EQ(r[i], static_cast<float>(c.r));
    }
    EXPECT_EQ(g[i], static_cast<float>(c.g));
    EXPECT_EQ(b[i], static_cast<float>(c.b));
  }
}

TEST_F(ImageWriterTest, WriterIsChosenByExtensionCaseInsensitively) {
  EXPECT_NE(writerForPath("a.png"), nullptr);
  EXPECT_NE(writerForPath("a.PnG"), nullptr);
  EXPECT_NE(writerForPath("dir/a.ppm"), nullptr);
  EXPECT_NE(writerForPath("a.Exr"), nullptr);
  EXPECT_EQ(writerForPath("a.jpg"), nullptr);
  EXPECT_EQ(writerForPath("a"), nullptr);
  EXPECT_EQ(writerForPath("png"), nullptr);
}

TEST_F(ImageWriterTest, UnknownExtensionThrowsAndWritesNothing) {
  try {
    writeImage(testFilm(), dir_ / "image.jpg", Encoding::Srgb);
    FAIL() << "expected ImageWriteError";
  } catch (const ImageWriteError& e) {
    EXPECT_NE(std::string(e.what()).find(".jpg"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(filesExcept().empty());
}

TEST_F(ImageWriterTest, MissingFolderThrowsAndLeavesNoTemporary) {
  const fs::path missing = dir_ / "no-such-folder";
  for (const char* name : {"image.png", "image.ppm", "image.exr"}) {
    try {
      writeImage(testFilm(), missing / name, Encoding::Srgb);
      FAIL() << "expected ImageWriteError for " << name;
    } catch (const ImageWriteError& e) {
      EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(missing));
  EXPECT_TRUE(filesExcept().empty());
}

TEST_F(ImageWriterTest, FailedWriteLeavesExistingFileUnchanged) {
  const fs::path path = dir_ / "image.png";
  {
    std::ofstream out(path, std::ios::binary);
    out << "previous contents";
  }
  const std::vector<char> before = readBytes(path);
  // An empty film cannot be written as an image.
  const Film empty(4, 4, PixelRegion{0, 0, 0, 0});
  EXPECT_THROW(writeImage(empty, path, Encoding::Srgb), ImageWriteError);
  EXPECT_EQ(readBytes(path), before);
  EXPECT_EQ(filesExcept("image.png"), std::vector<std::string>{});
}

TEST_F(ImageWriterTest, RenameFailureRemovesTheCompleteTemporary) {
  // The target is a non-empty folder: the image is fully written to the temporary file, then the
  // rename fails; the folder and its contents must survive and the temporary must be gone.
  for (const char* name : {"target.png", "target.ppm", "target.exr"}) {
    const fs::path target = dir_ / name;
    fs::create_directories(target / "inside");
    EXPECT_THROW(writeImage(testFilm(), target, Encoding::Linear), ImageWriteError) << name;
    EXPECT_TRUE(fs::is_directory(target / "inside")) << name;
  }
  std::vector<std::string> left = filesExcept();
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"target.exr", "target.png", "target.ppm"}));
}

TEST_F(ImageWriterTest, PermissionDeniedIsReadable) {
  if (::geteuid() == 0) GTEST_SKIP() << "root ignores folder permissions";
  const fs::path locked = dir_ / "locked";
  fs::create_directories(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  try {
    writeImage(testFilm(), locked / "image.png", Encoding::Srgb);
    ADD_FAILURE() << "expected ImageWriteError";
  } catch (const ImageWriteError& e) {
    EXPECT_NE(std::string(e.what()).find("ermission denied"), std::string::npos) << e.what();
  }
  fs::permissions(locked, fs::perms::owner_all);
  EXPECT_TRUE(fs::is_empty(locked));
}

TEST_F(ImageWriterTest, SuccessfulWritesReplaceTargetAndLeaveNoTemporary) {
  const Film film = testFilm();
  for (const char* name : {"a.png", "a.ppm", "a.exr"}) {
    const fs::path path = dir_ / name;
    {
      std::ofstream out(path, std::ios::binary);
      out << "old";
    }
    writeImage(film, path, Encoding::Srgb);
    EXPECT_GT(fs::file_size(path), 3u) << name;
  }
  std::vector<std::string> left = filesExcept();
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"a.exr", "a.png", "a.ppm"}));
}

TEST_F(ImageWriterTest, RelativePathWritesIntoCurrentFolder) {
  const fs::path previous = fs::current_path();
  fs::current_path(dir_);
  writeImage(testFilm(), "relative.ppm", Encoding::Linear);
  fs::current_path(previous);
  EXPECT_TRUE(fs::exists(dir_ / "relative.ppm"));
  EXPECT_EQ(filesExcept("relative.ppm"), std::vector<std::string>{});
}

// A target name of NAME_MAX bytes is legal, so its image must be writable: the temporary file's
// name may not grow with it.
TEST_F(ImageWriterTest, TheLongestLegalFileNameIsWritten) {
  for (const char* extension : {".png", ".ppm", ".exr"}) {
    const fs::path path = dir_ / (std::string(NAME_MAX - 4, 'n') + extension);
    writeImage(testFilm(), path, Encoding::Srgb);
    EXPECT_TRUE(fs::exists(path)) << extension;
    fs::remove(path);
  }
  EXPECT_TRUE(filesExcept().empty());
}

// A film tall enough for several OpenEXR write calls (64 rows each).
Film tallFilm() {
  Film film(5, 200, PixelRegion{0, 0, 5, 200});
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 5; ++x) film.at(x, y) = Color(x * 0.2, y / 200.0, 0.5);
  return film;
}

TEST_F(ImageWriterTest, ACancelledWriteStopsWithinARowAndLeavesNothing) {
  const Film film = tallFilm();
  for (const char* name : {"image.png", "image.ppm", "image.exr"}) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << "previous image";
    std::atomic<bool> cancel{false};
    int rowsWhenCancelled = 0;
    int rowsAfter = 0;
    WriteControl control;
    control.cancel = &cancel;
    control.rowWritten = [&](int rows, int total) {
      EXPECT_EQ(total, 200);
      // The temporary file exists beside the target while the image is written.
      std::vector<std::string> others = filesExcept(name);
      EXPECT_EQ(others.size(), 1u) << name;
      if (others.size() == 1) {
        EXPECT_TRUE(isTemporaryFileName(others[0])) << others[0];
      }
      if (cancel.load()) ++rowsAfter;
      if (rows >= 3 && !cancel.load()) {
        rowsWhenCancelled = rows;
        cancel.store(true);
      }
    };
    EXPECT_THROW(writeImage(film, path, Encoding::Srgb, control), Cancelled) << name;
    EXPECT_GT(rowsWhenCancelled, 0) << name;
    EXPECT_LT(rowsWhenCancelled, 200) << name;
    EXPECT_EQ(rowsAfter, 0) << name << ": rows were written after the cancel";
    std::ifstream in(path, std::ios::binary);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "previous image") << name;
    EXPECT_EQ(filesExcept(name), std::vector<std::string>{}) << name;
    fs::remove(path);
  }
}

TEST_F(ImageWriterTest, AWriteCancelledBeforeItStartsCreatesNoFile) {
  std::atomic<bool> cancel{true};
  for (const char* name : {"image.png", "image.ppm", "image.exr"}) {
    EXPECT_THROW(writeImage(testFilm(), dir_ / name, Encoding::Srgb, WriteControl{&cancel, {}}),
                 Cancelled)
        << name;
  }
  EXPECT_TRUE(filesExcept().empty());
}

TEST_F(ImageWriterTest, RowByRowWritingReportsEveryRowOnce) {
  const Film film = tallFilm();
  for (const char* name : {"rows.png", "rows.ppm", "rows.exr"}) {
    int last = 0;
    WriteControl control;
    control.rowWritten = [&](int rows, int total) {
      EXPECT_GT(rows, last);
      EXPECT_EQ(total, 200);
      last = rows;
    };
    writeImage(film, dir_ / name, Encoding::Linear, control);
    EXPECT_EQ(last, 200) << name;
  }
  const PngContents png = readPng(dir_ / "rows.png");
  EXPECT_EQ(png.rgb, expectedBytes(film, Encoding::Linear));
}

}  // namespace
}  // namespace glint
