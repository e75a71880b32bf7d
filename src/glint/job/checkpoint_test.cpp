#include "glint/job/checkpoint.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <string>

#include "glint/job/job_steps.h"
#include "glint/render/renderer.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

// A 20x13 crop of a 40x30 image in 8-pixel tiles: 3 x 2 tiles, the last column and row clipped.
CheckpointSettings sampleSettings() {
  CheckpointSettings s;
  s.width = 40;
  s.height = 30;
  s.samples = 4;
  s.adaptiveMaxSamples = 16;
  s.adaptiveThreshold = 0.05;
  s.seed = 0xfedcba9876543210ull;
  s.region = PixelRegion{10, 5, 30, 18};
  s.tileSize = 8;
  s.integrator = Integrator::Path;
  return s;
}

// Tiles 0, 2 and 5 finished, with pixel values that need every bit of a double to survive.
Checkpoint sampleCheckpoint() {
  Checkpoint c = emptyCheckpoint(0x0123456789abcdefull, sampleSettings());
  const std::vector<PixelRegion> tiles = tileRegions(c.settings.region, c.settings.tileSize);
  for (const std::size_t i : {0u, 2u, 5u}) {
    c.tiles[i] = true;
    for (int y = tiles[i].y0; y < tiles[i].y1; ++y)
      for (int x = tiles[i].x0; x < tiles[i].x1; ++x)
        c.film.at(x - 10, y - 5) = Color{1.0 / (x + 3), -std::ldexp(1.0, -1070) * y, 1e300 + x};
  }
  return c;
}

bool sameBits(const Color& a, const Color& b) {
  return std::bit_cast<std::uint64_t>(a.r) == std::bit_cast<std::uint64_t>(b.r) &&
         std::bit_cast<std::uint64_t>(a.g) == std::bit_cast<std::uint64_t>(b.g) &&
         std::bit_cast<std::uint64_t>(a.b) == std::bit_cast<std::uint64_t>(b.b);
}

class CheckpointFile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "glint-checkpoint-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::permissions(folder_, fs::perms::owner_all, ignored);
    fs::remove_all(folder_, ignored);
  }
  fs::path folder_;
};

TEST(Checkpoint, Fnv1aMatchesThePublishedTestVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ull);
  // Pieces hash as their concatenation.
  EXPECT_EQ(fnv1a64("bar", fnv1a64("foo")), fnv1a64("foobar"));
}

TEST(Checkpoint, EncodeDecodeRoundTripKeepsEveryBit) {
  const Checkpoint c = sampleCheckpoint();
  const Checkpoint d = decodeCheckpoint(encodeCheckpoint(c), "test.ckpt");
  EXPECT_EQ(d.fingerprint, c.fingerprint);
  EXPECT_EQ(d.settings, c.settings);
  EXPECT_EQ(d.tiles, c.tiles);
  EXPECT_EQ(d.finishedTiles(), 3u);
  ASSERT_EQ(d.film.region(), c.film.region());
  EXPECT_EQ(d.film.fullWidth(), 40);
  EXPECT_EQ(d.film.fullHeight(), 30);
  for (int y = 0; y < c.film.height(); ++y)
    for (int x = 0; x < c.film.width(); ++x)
      EXPECT_TRUE(sameBits(d.film.at(x, y), c.film.at(x, y))) << x << "," << y;
}

TEST(Checkpoint, LayoutHasTheDocumentedSize) {
  const Checkpoint c = sampleCheckpoint();
  const std::string bytes = encodeCheckpoint(c);
  // Finished tiles 0 (8x8), 2 (4x8: x 26..30) and 5 (4x5: x 26..30, y 13..18).
  const std::size_t pixels = 64 + 32 + 20;
  const std::size_t header = 8 + 4 + 4 + 8 + 4 * 4 + 8 + 8 + 5 * 4 + 4 + 8;
  EXPECT_EQ(bytes.size(), header + 1 + pixels * 24 + 8);
  EXPECT_EQ(bytes.substr(0, 8), "GLINTCKP");
  EXPECT_EQ(bytes[8], static_cast<char>(kCheckpointVersion));
  EXPECT_EQ(bytes[header], static_cast<char>(0b100101));  // the tile bitmap
  // An empty checkpoint: header, bitmap and checksum only.
  EXPECT_EQ(encodeCheckpoint(emptyCheckpoint(1, sampleSettings())).size(), header + 1 + 8);
}

TEST(Checkpoint, EveryTruncationIsRefused) {
  const std::string bytes = encodeCheckpoint(sampleCheckpoint());
  for (std::size_t length = 0; length < bytes.size(); ++length) {
    EXPECT_THROW(decodeCheckpoint(bytes.substr(0, length), "cut.ckpt"), CheckpointError)
        << "length " << length;
  }
  try {
    decodeCheckpoint(bytes.substr(0, 40), "cut.ckpt");
    FAIL();
  } catch (const CheckpointError& error) {
    EXPECT_NE(std::string(error.what()).find("cut.ckpt"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("truncated"), std::string::npos) << error.what();
  }
}

TEST(Checkpoint, AnyFlippedByteIsRefused) {
  const std::string bytes = encodeCheckpoint(sampleCheckpoint());
  for (std::size_t at = 0; at < bytes.size(); at += 7) {
    std::string damaged = bytes;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x10);
    EXPECT_THROW(decodeCheckpoint(damaged, "bad.ckpt"), CheckpointError) << "byte " << at;
  }
  std::string damaged = bytes;
  damaged[200] = static_cast<char>(damaged[200] ^ 1);
  try {
    decodeCheckpoint(damaged, "bad.ckpt");
    FAIL();
  } catch (const CheckpointError& error) {
    EXPECT_NE(std::string(error.what()).find("checksum"), std::string::npos) << error.what();
  }
}

TEST(Checkpoint, OtherFilesAndVersionsAreNamedAsSuch) {
  try {
    decodeCheckpoint("P6\n32 24\n255\n....", "image.ppm");
    FAIL();
  } catch (const CheckpointError& error) {
    EXPECT_STREQ(error.what(), "'image.ppm' is not a glint checkpoint");
  }
  std::string future = encodeCheckpoint(sampleCheckpoint());
  future[8] = static_cast<char>(kCheckpointVersion + 1);
  try {
    decodeCheckpoint(future, "new.ckpt");
    FAIL();
  } catch (const CheckpointError& error) {
    EXPECT_NE(std::string(error.what()).find("version 2"), std::string::npos) << error.what();
  }
}

TEST(Checkpoint, AFilmOverTheMemoryBudgetIsRefusedBeforeAllocation) {
  const std::string bytes = encodeCheckpoint(sampleCheckpoint());
  const std::uint64_t film = 20 * 13 * sizeof(Color);
  EXPECT_NO_THROW(decodeCheckpoint(bytes, "c", film));
  EXPECT_THROW(decodeCheckpoint(bytes, "c", film - 1), CheckpointError);
}

TEST(Checkpoint, MismatchNamesTheSettingThatDiffers) {
  const Checkpoint c = sampleCheckpoint();
  EXPECT_EQ(checkpointMismatch(c, c.fingerprint, c.settings), std::nullopt);
  const auto message = [&c](auto change) {
    CheckpointSettings s = c.settings;
    change(s);
    const std::optional<std::string> m = checkpointMismatch(c, c.fingerprint, s);
    return m.value_or("(none)");
  };
  EXPECT_EQ(message([](CheckpointSettings& s) { s.samples = 9; }),
            "it was made with samples per pixel 4, this render has 9");
  EXPECT_EQ(message([](CheckpointSettings& s) { s.width = 80; }),
            "it was made with an image of 40x30, this render has 80x30");
  EXPECT_EQ(message([](CheckpointSettings& s) {
              s.region = {0, 0, 40, 30};
            }),
            "it was made with region --crop 10,5,30,18, this render has the whole image");
  EXPECT_EQ(message([](CheckpointSettings& s) { s.seed = 1; }),
            "it was made with seed 18364758544493064720, this render has 1");
  EXPECT_EQ(message([](CheckpointSettings& s) { s.adaptiveMaxSamples = 0; }),
            "it was made with adaptive sampling max_samples 16, threshold 0.05, this render has "
            "off");
  EXPECT_EQ(message([](CheckpointSettings& s) { s.tileSize = 16; }),
            "it was made with tile size 8, this render has 16");
  EXPECT_EQ(message([](CheckpointSettings& s) { s.integrator = Integrator::Whitted; }),
            "it was made with integrator path, this render has whitted");
  const std::optional<std::string> scene = checkpointMismatch(c, c.fingerprint + 1, c.settings);
  ASSERT_TRUE(scene.has_value());
  EXPECT_NE(scene->find("scene file"), std::string::npos) << *scene;
}

TEST(Checkpoint, FingerprintCoversSceneBytesMeshesMaterialsAndEverySetting) {
  SceneParts parts;
  parts.image.width = 40;
  parts.image.height = 30;
  parts.camera.position = Point3{0, 0, 5};
  parts.camera.fovDegrees = 45;
  const Scene plain{parts};
  TriangleMesh mesh;
  mesh.positions = {Point3{0, 0, 0}, Point3{1, 0, 0}, Point3{0, 1, 0}};
  mesh.indices = {0, 1, 2};
  parts.meshes.push_back(mesh);
  const Scene withMesh{parts};
  parts.meshes[0].positions[2].y = 1.5;
  const Scene movedMesh{parts};
  // A material value that comes from a mesh file (an MTL's Kd) is not in the scene file's bytes.
  Material fromMtl;
  fromMtl.kd = Color(0.56, 0.22, 0.09);
  parts.materials.push_back(fromMtl);
  parts.meshes[0].materialIndex = 1;
  const Scene copper{parts};
  parts.materials[1].kd.g = 0.62;
  const Scene green{parts};
  // The same texture as the diffuse or the specular map (an MTL's map_Kd or map_Ks).
  parts.textures.push_back(CheckerTexture{});
  parts.materialTextures.push_back(MaterialTextures{});
  parts.materialTextures[0].kd = 0;
  parts.materials[1].textures = 0;
  const Scene diffuseMap{parts};
  parts.materialTextures[0].kd = kNoTexture;
  parts.materialTextures[0].ks = 0;
  const Scene specularMap{parts};

  const CheckpointSettings s = sampleSettings();
  const std::uint64_t base = renderFingerprint("scene text", plain, s);
  EXPECT_EQ(base, renderFingerprint("scene text", plain, s));
  EXPECT_NE(base, renderFingerprint("scene text ", plain, s));
  EXPECT_NE(base, renderFingerprint("scene text", withMesh, s));
  EXPECT_NE(renderFingerprint("scene text", withMesh, s),
            renderFingerprint("scene text", movedMesh, s));
  EXPECT_NE(renderFingerprint("scene text", copper, s), renderFingerprint("scene text", green, s));
  EXPECT_NE(renderFingerprint("scene text", diffuseMap, s),
            renderFingerprint("scene text", specularMap, s));
  const auto changed = [&](auto change) {
    CheckpointSettings t = s;
    change(t);
    return renderFingerprint("scene text", plain, t);
  };
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.width = 41; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.height = 31; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.samples = 5; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.adaptiveMaxSamples = 17; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.adaptiveThreshold = 0.06; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.seed ^= 1; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.region.x1 = 31; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.tileSize = 9; }));
  EXPECT_NE(base, changed([](CheckpointSettings& t) { t.integrator = Integrator::Whitted; }));
}

// A checkpoint's (and an MPI rank's) fingerprint covers the files the scene includes: a changed
// texture colour or group in an included file is a changed scene, as an edit of the scene file is.
TEST(Checkpoint, FingerprintCoversIncludedFiles) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("glint-fingerprint-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  struct RemoveFolder {
    std::filesystem::path folder;
    ~RemoveFolder() {
      std::error_code ignored;
      std::filesystem::remove_all(folder, ignored);
    }
  } removeFolder{folder};
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(folder / name) << text;
  };
  write("lib.yaml",
        "textures:\n  chk: {type: checker2d, colors: [\"#e0e0e0\", \"#202020\"]}\n"
        "materials:\n  floor: {kd: chk}\n");
  write("scene.yaml",
        "include: lib.yaml\ncamera: {position: [0, 2, 5], look_at: [0, 0, 0], fov: 40}\n"
        "image: {width: 16, height: 12}\nlights: [{type: point, position: [0, 5, 5]}]\n"
        "objects:\n  - {type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: floor}\n");
  const std::filesystem::path scene = folder / "scene.yaml";
  const auto fingerprint = [&](const std::filesystem::path& named) {
    const Scene built{loadSceneFile(named, {}).parts};
    EXPECT_EQ(built.includedFiles().size(), 1u);
    return renderFingerprint(fingerprintedSceneText(named, built), built, sampleSettings());
  };
  const std::uint64_t before = fingerprint(scene);
  EXPECT_EQ(before, fingerprint(scene));
  // The same files named another way (relative to the working folder, with a detour): the same
  // scene, as a resume from another folder or an MPI rank started elsewhere must find.
  EXPECT_EQ(before, fingerprint(std::filesystem::relative(scene)));
  EXPECT_EQ(before, fingerprint(folder / "." / ".." / folder.filename() / "scene.yaml"));
  write("lib.yaml",
        "textures:\n  chk: {type: checker2d, colors: [\"#00e000\", \"#202020\"]}\n"
        "materials:\n  floor: {kd: chk}\n");
  EXPECT_NE(before, fingerprint(scene));
}

// The settings' bytes are shared by the file, the fingerprint and the MPI handshake: every field
// survives, and a number that names no integrator is refused rather than read as one.
TEST(Checkpoint, SettingsBytesRoundTripAndRefuseAnUnknownIntegrator) {
  const CheckpointSettings s = sampleSettings();
  std::string bytes = encodeCheckpointSettings(s);
  ASSERT_EQ(bytes.size(), kCheckpointSettingsBytes);
  EXPECT_EQ(decodeCheckpointSettings(bytes), s);
  EXPECT_THROW(decodeCheckpointSettings(bytes.substr(1)), std::invalid_argument);
  bytes[kCheckpointSettingsBytes - 4] = 2;  // the integrator, little-endian i32
  EXPECT_THROW(decodeCheckpointSettings(bytes), std::invalid_argument);
}

TEST_F(CheckpointFile, WriteIsAtomicAndReplacesTheOldFile) {
  const fs::path path = folder_ / "render.ckpt";
  Checkpoint c = sampleCheckpoint();
  writeCheckpoint(c, path);
  c.tiles[1] = true;
  writeCheckpoint(c, path);
  const Checkpoint d = readCheckpoint(path);
  EXPECT_EQ(d.tiles, c.tiles);
  // No temporary file is left beside it.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(folder_)) ++files;
  EXPECT_EQ(files, 1u);
}

TEST_F(CheckpointFile, UnwritableFolderAndMissingFileAreCheckpointErrors) {
  if (geteuid() == 0) GTEST_SKIP() << "root ignores folder permissions";
  fs::permissions(folder_, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(writeCheckpoint(sampleCheckpoint(), folder_ / "x.ckpt"), CheckpointError);
  EXPECT_THROW(readCheckpoint(folder_ / "missing.ckpt"), CheckpointError);
}

TEST_F(CheckpointFile, ReadingAMissingFileOrAFolderNamesIt) {
  try {
    readCheckpoint(folder_ / "missing.ckpt");
    FAIL();
  } catch (const CheckpointError& error) {
    EXPECT_NE(std::string(error.what()).find("missing.ckpt': no such file"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(readCheckpoint(folder_), CheckpointError);
}

TEST_F(CheckpointFile, CollectorCopiesExactlyTheFinishedTileAndSavesWhenDue) {
  const CheckpointSettings s = sampleSettings();
  Film film(s.width, s.height, s.region);
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) film.at(x, y) = Color{double(x), double(y), 1};
  const fs::path path = folder_ / "c.ckpt";
  CheckpointCollector collector(path, emptyCheckpoint(7, s), std::chrono::seconds(0));
  EXPECT_FALSE(collector.saveDue()) << "nothing to save yet";
  collector.addTile(4, film);  // tile 4: x 18..26, y 13..18 (local 8..16, 8..13)
  EXPECT_TRUE(collector.saveDue());
  collector.save();
  EXPECT_FALSE(collector.saveDue());
  EXPECT_EQ(collector.saves(), 1);
  const Checkpoint saved = readCheckpoint(path);
  EXPECT_EQ(saved.finishedTiles(), 1u);
  EXPECT_TRUE(saved.tiles[4]);
  for (int y = 0; y < film.height(); ++y) {
    for (int x = 0; x < film.width(); ++x) {
      const bool inTile = x >= 8 && x < 16 && y >= 8;
      EXPECT_EQ(saved.film.at(x, y).r, inTile ? double(x) : 0.0) << x << "," << y;
    }
  }
  // A long interval: not due again.
  CheckpointCollector slow(path, emptyCheckpoint(7, s), std::chrono::hours(1));
  slow.addTile(0, film);
  EXPECT_FALSE(slow.saveDue());
  EXPECT_THROW(slow.addTile(6, film), std::invalid_argument);
}

// A device or a FIFO named as a checkpoint is refused by its stat: /dev/zero would be read forever,
// and opening a FIFO would wait for a writer forever.
TEST_F(CheckpointFile, DevicesAndFifosAreRefusedWithoutReadingThem) {
  const fs::path fifo = folder_ / "run.ckpt";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // /dev/zero is refused the same way (tests/cli_test.cpp, where a read that never ends is killed).
  for (const fs::path& path : {fifo}) {
    auto reading = std::async(std::launch::async, [&path]() {
      try {
        readCheckpoint(path);
        return std::string("read");
      } catch (const CheckpointError& error) {
        return std::string(error.what());
      }
    });
    if (reading.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
      // Unblock the reader (a writer opens and closes the FIFO) so that the test can end.
      const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (writer >= 0) ::close(writer);
      ADD_FAILURE() << "reading " << path << " did not return within 5 s";
    }
    EXPECT_EQ(reading.get(), "cannot read checkpoint '" + path.string() +
                                 "': it is not a regular file (a device, FIFO or socket)");
  }
  EXPECT_THROW(checkCheckpointFile(fifo), CheckpointError);
  EXPECT_THROW(checkCheckpointFile(folder_), CheckpointError);
  EXPECT_THROW(checkCheckpointFile(folder_ / "missing.ckpt"), CheckpointError);
}

TEST(Checkpoint, TheHeaderBoundsTheFileSize) {
  const Checkpoint c = sampleCheckpoint();
  const std::string bytes = encodeCheckpoint(c);
  // Header, bitmap (1 byte for 6 tiles), every pixel of the 20 x 13 region, checksum.
  const std::size_t header = 8 + 4 + 4 + 8 + 4 * 4 + 8 + 8 + 5 * 4 + 4 + 8;
  EXPECT_EQ(checkpointSizeLimit(bytes), header + 1 + 20 * 13 * 24 + 8);
  EXPECT_GE(*checkpointSizeLimit(bytes), bytes.size());
  EXPECT_EQ(checkpointSizeLimit(bytes.substr(0, header - 1)), std::nullopt);
  EXPECT_EQ(checkpointSizeLimit("P6\n1 1\n255\nabc" + std::string(100, 'x')), std::nullopt);
  std::string impossible = bytes;
  impossible[24] = 0;  // width 0
  impossible[25] = 0;
  EXPECT_EQ(checkpointSizeLimit(impossible), std::nullopt);
}

// A file larger than its header allows is refused before it is read: a checkpoint's size never
// decides what glint allocates.
TEST_F(CheckpointFile, AFileLargerThanItsHeaderAllowsIsRefusedUnread) {
  const std::string bytes = encodeCheckpoint(sampleCheckpoint());
  const fs::path path = folder_ / "big.ckpt";
  {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
  }
  // Grown to 1 GiB without using the disk (a sparse file).
  fs::resize_file(path, std::uint64_t{1} << 30);
  const auto start = std::chrono::steady_clock::now();
  try {
    readCheckpoint(path);
    FAIL() << "expected CheckpointError";
  } catch (const CheckpointError& error) {
    EXPECT_NE(std::string(error.what()).find("its header allows"), std::string::npos)
        << error.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  // Without a sane header, a file larger than the memory budget is refused unread as well.
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << "not a checkpoint at all";
  }
  fs::resize_file(path, std::uint64_t{1} << 30);
  try {
    readCheckpoint(path, std::uint64_t{1} << 20);
    FAIL() << "expected CheckpointError";
  } catch (const CheckpointError& error) {
    EXPECT_EQ(std::string(error.what()), "'" + path.string() + "' is not a glint checkpoint");
  }
}

// The temporary file of a save is short and hidden, so a checkpoint name of NAME_MAX bytes works.
TEST_F(CheckpointFile, TheLongestLegalFileNameIsSaved) {
  const fs::path path = folder_ / (std::string(NAME_MAX - 5, 'c') + ".ckpt");
  writeCheckpoint(sampleCheckpoint(), path);
  EXPECT_EQ(readCheckpoint(path).finishedTiles(), 3u);
}

}  // namespace
}  // namespace glint
