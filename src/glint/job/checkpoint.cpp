#include "glint/job/checkpoint.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <system_error>
#include <utility>

#include "glint/core/atomic_file.h"
#include "glint/core/file_access.h"
#include "glint/render/renderer.h"
#include "glint/scene/scene_limits.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

// Bytes before the tile bitmap: magic, version, reserved, fingerprint, settings, tile count.
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + kCheckpointSettingsBytes + 8;
constexpr std::size_t kPixelBytes = 3 * 8;
// Tiles of at most this many pixels per side; more is not a file glint wrote.
constexpr std::int64_t kMaxTileSize = 65535;

class Writer {
 public:
  void u32(std::uint32_t v) { put(v, 4); }
  void i32(int v) { put(static_cast<std::uint32_t>(v), 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void f64(double v) { put(std::bit_cast<std::uint64_t>(v), 8); }
  void bytes(std::string_view b) { out_.append(b); }
  std::string& text() { return out_; }

 private:
  void put(std::uint64_t v, int count) {
    for (int i = 0; i < count; ++i) out_.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  std::string out_;
};

class Reader {
 public:
  Reader(std::string_view bytes, const std::string& name) : in_(bytes), name_(name) {}
  std::uint32_t u32() { return static_cast<std::uint32_t>(get(4)); }
  int i32() { return static_cast<int>(static_cast<std::int32_t>(get(4))); }
  std::uint64_t u64() { return get(8); }
  double f64() { return std::bit_cast<double>(get(8)); }
  std::string_view bytes(std::size_t count) {
    need(count);
    const std::string_view part = in_.substr(pos_, count);
    pos_ += count;
    return part;
  }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return in_.size() - pos_; }

 private:
  void need(std::size_t count) const {
    if (in_.size() - pos_ < count)
      throw CheckpointError(
          fmt::format("checkpoint '{}' is truncated ({} bytes)", name_, in_.size()));
  }
  std::uint64_t get(int count) {
    need(static_cast<std::size_t>(count));
    std::uint64_t v = 0;
    for (int i = 0; i < count; ++i)
      v |= std::uint64_t{static_cast<unsigned char>(in_[pos_ + static_cast<std::size_t>(i)])}
           << (8 * i);
    pos_ += static_cast<std::size_t>(count);
    return v;
  }
  std::string_view in_;
  const std::string& name_;
  std::size_t pos_ = 0;
};

std::string_view asBytes(const void* data, std::size_t size) {
  return {static_cast<const char*>(data), size};
}

template <typename T>
std::uint64_t hashVector(const std::vector<T>& values, std::uint64_t hash) {
  const std::uint64_t count = values.size();
  hash = fnv1a64(asBytes(&count, sizeof count), hash);
  return fnv1a64(asBytes(values.data(), values.size() * sizeof(T)), hash);
}

void copyTile(const PixelRegion& tile, const Film& from, Film& to) {
  const PixelRegion& region = to.region();
  for (int y = tile.y0; y < tile.y1; ++y)
    for (int x = tile.x0; x < tile.x1; ++x)
      to.at(x - region.x0, y - region.y0) = from.at(x - region.x0, y - region.y0);
}

// Closes a POSIX file descriptor when it goes out of scope.

// Whether `bytes` starts with the magic and this glint's format version.
bool hasMagicAndVersion(std::string_view bytes) {
  if (bytes.size() < kCheckpointMagic.size() + 4 ||
      bytes.substr(0, kCheckpointMagic.size()) != kCheckpointMagic)
    return false;
  const std::string name;
  Reader r(bytes.substr(kCheckpointMagic.size()), name);
  return r.u32() == kCheckpointVersion;
}

std::string describeRegion(const PixelRegion& r, int width, int height) {
  if (r == PixelRegion{0, 0, width, height}) return "the whole image";
  return fmt::format("--crop {},{},{},{}", r.x0, r.y0, r.x1, r.y1);
}

}  // namespace

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash) {
  constexpr std::uint64_t kPrime = 1099511628211ull;
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= kPrime;
  }
  return hash;
}

CheckpointSettings checkpointSettingsFor(const Scene& scene, const PixelRegion& region,
                                         int tileSize) {
  const ImageSettings& image = scene.image();
  CheckpointSettings s;
  s.width = image.width;
  s.height = image.height;
  s.samples = image.samples;
  if (image.adaptive) {
    s.adaptiveMaxSamples = image.adaptive->maxSamples;
    s.adaptiveThreshold = image.adaptive->threshold;
  }
  s.seed = scene.render().seed;
  s.region = region;
  s.tileSize = tileSize;
  s.integrator = scene.render().integrator;
  return s;
}

std::string materialBytes(const std::vector<Material>& materials,
                          const std::vector<MaterialTextures>& bindings,
                          const std::vector<Texture>& textures) {
  Writer w;
  w.u64(materials.size());
  const auto color = [&](const Color& c) {
    w.f64(c.r);
    w.f64(c.g);
    w.f64(c.b);
  };
  for (const Material& m : materials) {
    color(m.kd);
    color(m.ks);
    w.f64(m.shininess);
    color(m.kr);
    color(m.kt);
    color(m.ka);
    w.f64(m.ior);
    w.f64(m.reflectionBlur);
    w.f64(m.refractionBlur);
    w.i32(m.priority);
    w.u32(m.textures);
  }
  // Which texture each coefficient takes (an MTL's map_Kd or map_Ks of one image differ here),
  // and the placement of image textures (an MTL's -s and -o); their pixels are hashed apart.
  w.u64(bindings.size());
  for (const MaterialTextures& b : bindings) {
    for (const TextureId id : {b.kd, b.ks, b.kr, b.kt, b.ka, b.emission, b.normalMap, b.bumpMap})
      w.u32(id);
    w.f64(b.bumpScale);
  }
  w.u64(textures.size());
  for (const Texture& texture : textures) {
    w.u32(static_cast<std::uint32_t>(texture.index()));
    if (const auto* image = std::get_if<ImageTexture>(&texture)) {
      w.u32(static_cast<std::uint32_t>(image->filter));
      w.f64(image->transform.repeat.x);
      w.f64(image->transform.repeat.y);
      w.f64(image->transform.offset.x);
      w.f64(image->transform.offset.y);
      w.f64(image->transform.cosRotate);
      w.f64(image->transform.sinRotate);
    }
  }
  return std::move(w.text());
}

std::uint64_t renderFingerprint(std::string_view sceneFileBytes, const Scene& scene,
                                const CheckpointSettings& settings) {
  Writer w;
  w.u32(kCheckpointVersion);
  w.bytes(GLINT_VERSION);
  w.u64(sceneFileBytes.size());
  std::uint64_t hash = fnv1a64(w.text());
  hash = fnv1a64(sceneFileBytes, hash);
  for (const TriangleMesh& mesh : scene.meshes()) {
    // Point3, Normal3 and uint32 are plain arrays of scalars without padding.
    static_assert(sizeof(Point3) == 3 * sizeof(double) && sizeof(Normal3) == 3 * sizeof(double));
    hash = hashVector(mesh.positions, hash);
    hash = hashVector(mesh.normals, hash);
    hash = hashVector(mesh.indices, hash);
    // Texture coordinates, kept only by textured meshes (none: the hash is unchanged).
    static_assert(sizeof(Point2) == 2 * sizeof(double));
    if (!mesh.uvs.empty()) hash = hashVector(mesh.uvs, hash);
    Writer m;
    m.u32(mesh.materialIndex);
    m.f64(mesh.emission.r);
    m.f64(mesh.emission.g);
    m.f64(mesh.emission.b);
    hash = fnv1a64(m.text(), hash);
  }
  // Every material's values: those of mesh files (an OBJ's MTL, a glTF's materials) are not in the
  // scene file's bytes.
  hash =
      fnv1a64(materialBytes(scene.materials(), scene.materialTextures(), scene.textures()), hash);
  // The pictures of image textures and of the background, read from files the scene only names
  // (each once; an untextured scene adds nothing).
  std::vector<const MipMap*> images;
  for (const Texture& texture : scene.textures()) {
    if (const auto* t = std::get_if<ImageTexture>(&texture)) images.push_back(t->image.get());
  }
  if (scene.environment().image) images.push_back(scene.environment().image.get());
  for (std::size_t i = 0; i < images.size(); ++i) {
    if (std::find(images.begin(), images.begin() + static_cast<std::ptrdiff_t>(i), images[i]) !=
        images.begin() + static_cast<std::ptrdiff_t>(i)) {
      continue;
    }
    hash = hashVector(images[i]->pixels(0), hash);
  }
  return fnv1a64(encodeCheckpointSettings(settings), hash);
}

std::string encodeCheckpointSettings(const CheckpointSettings& settings) {
  Writer w;
  w.i32(settings.width);
  w.i32(settings.height);
  w.i32(settings.samples);
  w.i32(settings.adaptiveMaxSamples);
  w.f64(settings.adaptiveThreshold);
  w.u64(settings.seed);
  w.i32(settings.region.x0);
  w.i32(settings.region.y0);
  w.i32(settings.region.x1);
  w.i32(settings.region.y1);
  w.i32(settings.tileSize);
  w.i32(settings.integrator == Integrator::Path ? 1 : 0);
  return std::move(w.text());
}

CheckpointSettings decodeCheckpointSettings(std::string_view bytes) {
  if (bytes.size() != kCheckpointSettingsBytes)
    throw std::invalid_argument(fmt::format("render settings of {} bytes, expected {}",
                                            bytes.size(), kCheckpointSettingsBytes));
  const std::string name;
  Reader r(bytes, name);
  CheckpointSettings s;
  s.width = r.i32();
  s.height = r.i32();
  s.samples = r.i32();
  s.adaptiveMaxSamples = r.i32();
  s.adaptiveThreshold = r.f64();
  s.seed = r.u64();
  s.region.x0 = r.i32();
  s.region.y0 = r.i32();
  s.region.x1 = r.i32();
  s.region.y1 = r.i32();
  s.tileSize = r.i32();
  const int integrator = r.i32();
  if (integrator != 0 && integrator != 1)
    throw std::invalid_argument(fmt::format("unknown integrator number {}", integrator));
  s.integrator = integrator == 1 ? Integrator::Path : Integrator::Whitted;
  return s;
}

std::size_t Checkpoint::finishedTiles() const {
  std::size_t count = 0;
  for (const bool done : tiles) count += done ? 1 : 0;
  return count;
}

Checkpoint emptyCheckpoint(std::uint64_t fingerprint, const CheckpointSettings& settings) {
  Checkpoint checkpoint;
  checkpoint.fingerprint = fingerprint;
  checkpoint.settings = settings;
  checkpoint.tiles.assign(tileRegions(settings.region, settings.tileSize).size(), false);
  checkpoint.film = Film(settings.width, settings.height, settings.region);
  return checkpoint;
}

std::string encodeCheckpoint(const Checkpoint& checkpoint) {
  const CheckpointSettings& s = checkpoint.settings;
  const std::vector<PixelRegion> tiles = tileRegions(s.region, s.tileSize);
  if (tiles.size() != checkpoint.tiles.size() || checkpoint.film.region() != s.region)
    throw std::invalid_argument("checkpoint tiles or film do not match its settings");
  Writer w;
  w.bytes(kCheckpointMagic);
  w.u32(kCheckpointVersion);
  w.u32(0);
  w.u64(checkpoint.fingerprint);
  w.bytes(encodeCheckpointSettings(s));
  w.u64(tiles.size());
  std::string bitmap((tiles.size() + 7) / 8, '\0');
  for (std::size_t i = 0; i < tiles.size(); ++i)
    if (checkpoint.tiles[i]) bitmap[i / 8] = static_cast<char>(bitmap[i / 8] | (1 << (i % 8)));
  w.bytes(bitmap);
  std::size_t pixels = 0;
  for (std::size_t i = 0; i < tiles.size(); ++i)
    if (checkpoint.tiles[i])
      pixels +=
          static_cast<std::size_t>(tiles[i].width()) * static_cast<std::size_t>(tiles[i].height());
  w.text().reserve(w.text().size() + pixels * kPixelBytes + 8);
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    if (!checkpoint.tiles[i]) continue;
    const PixelRegion& t = tiles[i];
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const Color& c = checkpoint.film.at(x - s.region.x0, y - s.region.y0);
        w.f64(c.r);
        w.f64(c.g);
        w.f64(c.b);
      }
    }
  }
  w.u64(fnv1a64(w.text()));
  return std::move(w.text());
}

Checkpoint decodeCheckpoint(std::string_view bytes, const std::string& name,
                            std::uint64_t memoryBudget) {
  if (bytes.size() < kCheckpointMagic.size() ||
      bytes.substr(0, kCheckpointMagic.size()) != kCheckpointMagic)
    throw CheckpointError(fmt::format("'{}' is not a glint checkpoint", name));
  Reader r(bytes, name);
  r.bytes(kCheckpointMagic.size());
  const std::uint32_t version = r.u32();
  if (version != kCheckpointVersion)
    throw CheckpointError(
        fmt::format("checkpoint '{}' has format version {}; this glint reads version {}", name,
                    version, kCheckpointVersion));
  const auto corrupt = [&name](const std::string& what) {
    return CheckpointError(fmt::format("checkpoint '{}' is corrupt: {}", name, what));
  };
  // The checksum first, so that damage anywhere is reported as such rather than as an odd value.
  if (bytes.size() < kHeaderBytes + 8)
    throw CheckpointError(
        fmt::format("checkpoint '{}' is truncated ({} bytes)", name, bytes.size()));
  Reader tail(bytes.substr(bytes.size() - 8), name);
  if (tail.u64() != fnv1a64(bytes.substr(0, bytes.size() - 8)))
    throw corrupt("its checksum does not match (damaged or truncated)");
  r.u32();  // reserved
  Checkpoint checkpoint;
  checkpoint.fingerprint = r.u64();
  try {
    checkpoint.settings = decodeCheckpointSettings(r.bytes(kCheckpointSettingsBytes));
  } catch (const std::invalid_argument& error) {
    throw corrupt(error.what());
  }
  const CheckpointSettings& s = checkpoint.settings;
  const PixelRegion& region = s.region;
  if (s.width < 1 || s.width > 65535 || s.height < 1 || s.height > 65535 || region.x0 < 0 ||
      region.x0 >= region.x1 || region.x1 > s.width || region.y0 < 0 || region.y0 >= region.y1 ||
      region.y1 > s.height || s.tileSize < 1 || s.tileSize > kMaxTileSize)
    throw corrupt("impossible image size, region or tile size");
  // Sizes are checked before anything is allocated from them.
  const std::uint64_t tileCount =
      static_cast<std::uint64_t>((region.width() + s.tileSize - 1) / s.tileSize) *
      static_cast<std::uint64_t>((region.height() + s.tileSize - 1) / s.tileSize);
  if (r.u64() != tileCount) throw corrupt("the tile count does not match the tile size");
  if ((tileCount + 7) / 8 > r.remaining()) throw corrupt("the tile bitmap is cut short");
  const std::uint64_t film = filmBytes(region.width(), region.height());
  if (film > memoryBudget)
    throw CheckpointError(fmt::format(
        "checkpoint '{}' needs {} for its film, more than the memory budget of {}", name,
        formatBytes(static_cast<double>(film)), formatBytes(static_cast<double>(memoryBudget))));
  const std::vector<PixelRegion> tiles = tileRegions(region, s.tileSize);
  const std::string_view bitmap = r.bytes((tiles.size() + 7) / 8);
  checkpoint.tiles.assign(tiles.size(), false);
  std::size_t pixels = 0;
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    checkpoint.tiles[i] = (static_cast<unsigned char>(bitmap[i / 8]) >> (i % 8)) & 1;
    if (checkpoint.tiles[i])
      pixels +=
          static_cast<std::size_t>(tiles[i].width()) * static_cast<std::size_t>(tiles[i].height());
  }
  if (r.remaining() < 8 || r.remaining() - 8 != pixels * kPixelBytes)
    throw corrupt(fmt::format("{} bytes of pixels for {} finished tiles, expected {}",
                              r.remaining() - 8, checkpoint.finishedTiles(), pixels * kPixelBytes));
  checkpoint.film = Film(s.width, s.height, region);
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    if (!checkpoint.tiles[i]) continue;
    const PixelRegion& t = tiles[i];
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        Color& c = checkpoint.film.at(x - region.x0, y - region.y0);
        c.r = r.f64();
        c.g = r.f64();
        c.b = r.f64();
      }
    }
  }
  return checkpoint;
}

void writeCheckpoint(const Checkpoint& checkpoint, const fs::path& path) {
  const std::string bytes = encodeCheckpoint(checkpoint);
  try {
    AtomicFile file(path, 0600);
    file.write(bytes);
    // fsync before rename: after a power cut the name points at complete bytes, old or new.
    file.close(true);
    file.commit();
  } catch (const std::system_error& error) {
    throw CheckpointError(
        fmt::format("cannot save checkpoint '{}': {}", path.string(), error.code().message()));
  }
}

std::optional<std::uint64_t> checkpointSizeLimit(std::string_view header) {
  if (header.size() < kHeaderBytes || header.substr(0, kCheckpointMagic.size()) != kCheckpointMagic)
    return std::nullopt;
  const std::string name;
  Reader r(header, name);
  r.bytes(kCheckpointMagic.size());
  if (r.u32() != kCheckpointVersion) return std::nullopt;
  r.u32();  // reserved
  r.u64();  // fingerprint
  CheckpointSettings settings;
  try {
    settings = decodeCheckpointSettings(r.bytes(kCheckpointSettingsBytes));
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
  const int width = settings.width;
  const int height = settings.height;
  const PixelRegion& region = settings.region;
  const int tileSize = settings.tileSize;
  const std::uint64_t tileCount = r.u64();
  if (width < 1 || height < 1 || region.x0 < 0 || region.x0 >= region.x1 || region.x1 > width ||
      region.y0 < 0 || region.y0 >= region.y1 || region.y1 > height || tileSize < 1 ||
      tileCount == 0 || tileCount > static_cast<std::uint64_t>(region.width()) * region.height())
    return std::nullopt;
  const std::uint64_t pixels =
      static_cast<std::uint64_t>(region.width()) * static_cast<std::uint64_t>(region.height());
  return kHeaderBytes + (tileCount + 7) / 8 + pixels * kPixelBytes + 8;
}

namespace {

CheckpointError cannotRead(const fs::path& path, const std::string& why) {
  return CheckpointError(fmt::format("cannot read checkpoint '{}': {}", path.string(), why));
}

std::string openFailure(int error) {
  if (error == ENOENT || error == ENOTDIR) return "no such file";
  if (error == EACCES || error == EPERM) return "permission denied";
  return std::generic_category().message(error);
}

// Why the checkpoint at `path` cannot be read (core/file_access.h), in this file's words.
CheckpointError refused(const fs::path& path, const ReadableFile& file) {
  switch (file.refusal) {
    case FileRefusal::Folder:
      return cannotRead(path, "it is a folder");
    case FileRefusal::NotRegular:
      return cannotRead(path, "it is not a regular file (a device, FIFO or socket)");
    default:
      return cannotRead(path, openFailure(file.error));
  }
}

}  // namespace

void checkCheckpointFile(const fs::path& path) {
  // stat, not open: reading a device such as /dev/zero would never end, and opening a FIFO would
  // wait for a writer forever.
  const ReadableFile file = statForReading(path);
  if (file.refusal != FileRefusal::None) throw refused(path, file);
}

Checkpoint readCheckpoint(const fs::path& path, std::uint64_t memoryBudget) {
  // Opened only when regular, checked again on what was opened (a FIFO swapped in meanwhile).
  const ReadableFile file = openForReading(path);
  if (file.refusal != FileRefusal::None) throw refused(path, file);
  const int fd = file.fd;
  const std::uint64_t size = file.size;

  // Reads up to `count` more bytes into `bytes` (fewer at the end of the file).
  std::string bytes;
  const auto readUpTo = [&](std::uint64_t count) {
    char buffer[1 << 16];
    while (count > 0) {
      const ssize_t n = ::read(
          fd, buffer, static_cast<std::size_t>(std::min<std::uint64_t>(count, sizeof buffer)));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw cannotRead(path, "read error");
      if (n == 0) return;
      bytes.append(buffer, static_cast<std::size_t>(n));
      count -= static_cast<std::uint64_t>(n);
    }
  };
  // The header first: what it promises bounds the rest, so no size read from a damaged or foreign
  // file makes glint allocate more than the file's own size or a checkpoint of that image needs.
  readUpTo(std::min<std::uint64_t>(size, kHeaderBytes));
  const std::optional<std::uint64_t> limit = checkpointSizeLimit(bytes);
  if (limit && size > *limit)
    throw CheckpointError(fmt::format(
        "checkpoint '{}' is corrupt: it holds {} bytes, more than the {} its header allows",
        path.string(), size, *limit));
  // Without a sane header the bound is the memory budget: a checkpoint holds at most a film within
  // it (plus a few bytes). Smaller files are read whole, so that decodeCheckpoint names the damage.
  if (!limit && size > memoryBudget) {
    if (!hasMagicAndVersion(bytes))
      decodeCheckpoint(bytes, path.string(), memoryBudget);  // not a checkpoint; another version
    throw CheckpointError(fmt::format(
        "checkpoint '{}' is corrupt: impossible image size, region or tile size", path.string()));
  }
  bytes.reserve(static_cast<std::size_t>(size));
  readUpTo(size - bytes.size());
  return decodeCheckpoint(bytes, path.string(), memoryBudget);
}

std::optional<SettingDifference> firstSettingDifference(const CheckpointSettings& a,
                                                        const CheckpointSettings& b) {
  if (a.width != b.width || a.height != b.height)
    return SettingDifference{"an image of", fmt::format("{}x{}", a.width, a.height),
                             fmt::format("{}x{}", b.width, b.height)};
  if (a.region != b.region)
    return SettingDifference{"region", describeRegion(a.region, a.width, a.height),
                             describeRegion(b.region, b.width, b.height)};
  if (a.samples != b.samples)
    return SettingDifference{"samples per pixel", std::to_string(a.samples),
                             std::to_string(b.samples)};
  if (a.adaptiveMaxSamples != b.adaptiveMaxSamples || a.adaptiveThreshold != b.adaptiveThreshold) {
    const auto adaptive = [](const CheckpointSettings& s) {
      return s.adaptiveMaxSamples == 0 ? std::string("off")
                                       : fmt::format("max_samples {}, threshold {:g}",
                                                     s.adaptiveMaxSamples, s.adaptiveThreshold);
    };
    return SettingDifference{"adaptive sampling", adaptive(a), adaptive(b)};
  }
  if (a.seed != b.seed)
    return SettingDifference{"seed", std::to_string(a.seed), std::to_string(b.seed)};
  if (a.tileSize != b.tileSize)
    return SettingDifference{"tile size", std::to_string(a.tileSize), std::to_string(b.tileSize)};
  if (a.integrator != b.integrator) {
    const auto name = [](Integrator i) { return i == Integrator::Path ? "path" : "whitted"; };
    return SettingDifference{"integrator", name(a.integrator), name(b.integrator)};
  }
  return std::nullopt;
}

std::optional<std::string> checkpointMismatch(const Checkpoint& checkpoint,
                                              std::uint64_t fingerprint,
                                              const CheckpointSettings& settings) {
  if (const std::optional<SettingDifference> difference =
          firstSettingDifference(checkpoint.settings, settings))
    return fmt::format("it was made with {} {}, this render has {}", difference->what,
                       difference->first, difference->second);
  if (checkpoint.fingerprint != fingerprint)
    return std::string(
        "the scene differs from the render that made it: the scene file, a file it includes, a "
        "mesh or texture it loads, or the glint version");
  return std::nullopt;
}

CheckpointCollector::CheckpointCollector(fs::path path, Checkpoint start,
                                         std::chrono::duration<double> interval)
    : path_(std::move(path)),
      checkpoint_(std::move(start)),
      tileRegions_(tileRegions(checkpoint_.settings.region, checkpoint_.settings.tileSize)),
      interval_(interval),
      lastSave_(Clock::now()) {}

void CheckpointCollector::addTile(std::size_t tile, const Film& film) {
  if (tile >= tileRegions_.size() || film.region() != checkpoint_.film.region())
    throw std::invalid_argument("tile or film does not belong to this checkpoint");
  copyTile(tileRegions_[tile], film, checkpoint_.film);
  checkpoint_.tiles[tile] = true;
  unsaved_ = true;
}

bool CheckpointCollector::saveDue() const {
  if (!unsaved_) return false;
  const auto wait = std::max(interval_, 20 * lastSaveTook_);
  return Clock::now() - lastSave_ >= wait;
}

void CheckpointCollector::save() {
  const auto begin = Clock::now();
  writeCheckpoint(checkpoint_, path_);
  lastSave_ = Clock::now();
  lastSaveTook_ = lastSave_ - begin;
  unsaved_ = false;
  ++saves_;
}

}  // namespace glint
