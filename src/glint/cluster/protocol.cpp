#include "glint/cluster/protocol.h"

#include <bit>
#include <utility>

namespace glint::cluster {
namespace {

class Writer {
 public:
  void u32(std::uint32_t v) { unsigned_(v, 4); }
  void u64(std::uint64_t v) { unsigned_(v, 8); }
  void i32(int v) { u32(static_cast<std::uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void text(std::string_view s) {
    u64(s.size());
    bytes_.append(s);
  }
  void raw(std::string_view s) { bytes_.append(s); }  // fixed-size bytes, no length
  void reserve(std::size_t n) { bytes_.reserve(n); }
  std::string take() { return std::move(bytes_); }

 private:
  void unsigned_(std::uint64_t v, int size) {
    for (int i = 0; i < size; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  std::string bytes_;
};

class Reader {
 public:
  Reader(std::string_view bytes, const char* what) : bytes_(bytes), what_(what) {}
  std::uint32_t u32() { return static_cast<std::uint32_t>(unsigned_(4)); }
  std::uint64_t u64() { return unsigned_(8); }
  int i32() { return static_cast<int>(u32()); }
  double f64() { return std::bit_cast<double>(u64()); }
  std::string text() {
    const std::uint64_t size = u64();
    need(size);
    std::string s(bytes_.substr(at_, static_cast<std::size_t>(size)));
    at_ += static_cast<std::size_t>(size);
    return s;
  }
  std::string_view raw(std::size_t size) {
    need(size);
    const std::string_view part = bytes_.substr(at_, size);
    at_ += size;
    return part;
  }
  std::size_t left() const { return bytes_.size() - at_; }
  void end() const {
    if (at_ != bytes_.size()) fail();
  }

 private:
  [[noreturn]] void fail() const {
    throw ProtocolError(std::string("a malformed ") + what_ + " message");
  }
  void need(std::uint64_t n) const {
    if (n > bytes_.size() - at_) fail();
  }
  std::uint64_t unsigned_(int size) {
    need(static_cast<std::uint64_t>(size));
    std::uint64_t v = 0;
    for (int i = 0; i < size; ++i)
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[at_ + i])) << (8 * i);
    at_ += static_cast<std::size_t>(size);
    return v;
  }
  std::string_view bytes_;
  const char* what_;
  std::size_t at_ = 0;
};

void writeRays(Writer& w, const RayCounts& rays) {
  w.u64(rays.camera);
  w.u64(rays.shadow);
  w.u64(rays.reflection);
  w.u64(rays.refraction);
  w.u64(rays.indirect);
}

RayCounts readRays(Reader& r) {
  RayCounts rays;
  rays.camera = r.u64();
  rays.shadow = r.u64();
  rays.reflection = r.u64();
  rays.refraction = r.u64();
  rays.indirect = r.u64();
  return rays;
}

}  // namespace

std::string encodeIdentity(const RankIdentity& identity) {
  Writer w;
  w.u32(identity.protocol);
  w.text(identity.version);
  w.text(identity.host);
  w.i32(identity.threads);
  w.text(identity.sceneFile);
  w.u64(identity.sceneBytes);
  w.u64(identity.sceneHash);
  w.u64(identity.meshCount);
  w.u64(identity.meshHash);
  w.raw(encodeCheckpointSettings(identity.settings));
  w.u64(identity.fingerprint);
  w.text(identity.error);
  return w.take();
}

RankIdentity decodeIdentity(std::string_view bytes) {
  Reader r(bytes, "Hello");
  RankIdentity identity;
  identity.protocol = r.u32();
  // Another protocol version may lay out the rest differently: only the version is read then.
  if (identity.protocol != kProtocolVersion) return identity;
  identity.version = r.text();
  identity.host = r.text();
  identity.threads = r.i32();
  identity.sceneFile = r.text();
  identity.sceneBytes = r.u64();
  identity.sceneHash = r.u64();
  identity.meshCount = r.u64();
  identity.meshHash = r.u64();
  try {
    identity.settings = decodeCheckpointSettings(r.raw(kCheckpointSettingsBytes));
  } catch (const std::invalid_argument&) {
    throw ProtocolError("a malformed Hello message");
  }
  identity.fingerprint = r.u64();
  identity.error = r.text();
  r.end();
  return identity;
}

std::string encodeTiles(const TileList& tiles) {
  Writer w;
  w.reserve(4 * tiles.size());
  for (const std::uint32_t tile : tiles) w.u32(tile);
  return w.take();
}

TileList decodeTiles(std::string_view bytes) {
  Reader r(bytes, "Assign");
  TileList tiles;
  tiles.reserve(bytes.size() / 4);
  while (r.left() > 0) tiles.push_back(r.u32());
  return tiles;
}

std::string encodeTile(std::uint32_t index, const PixelRegion& tile, const Film& film) {
  Writer w;
  const auto pixels = static_cast<std::size_t>(tile.width()) * tile.height();
  w.reserve(4 + 8 + 24 * pixels);
  w.u32(index);
  w.u64(pixels);
  const PixelRegion& region = film.region();
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) {
      const Color& c = film.at(x - region.x0, y - region.y0);
      w.f64(c.r);
      w.f64(c.g);
      w.f64(c.b);
    }
  }
  return w.take();
}

TileResult decodeTile(std::string_view bytes) {
  Reader r(bytes, "Tile");
  TileResult result;
  result.tile = r.u32();
  const std::uint64_t pixels = r.u64();
  if (pixels != r.left() / 24 || r.left() % 24 != 0)
    throw ProtocolError("a malformed Tile message");
  result.pixels.resize(static_cast<std::size_t>(pixels));
  for (Color& c : result.pixels) {
    c.r = r.f64();
    c.g = r.f64();
    c.b = r.f64();
  }
  return result;
}

std::string encodeReport(const RankReport& report) {
  Writer w;
  w.u64(report.tiles);
  writeRays(w, report.rays);
  w.u64(report.samples);
  w.u64(report.nonFinite);
  w.u32(report.firstNonFinite ? 1 : 0);
  w.i32(report.firstNonFinite ? report.firstNonFinite->x : 0);
  w.i32(report.firstNonFinite ? report.firstNonFinite->y : 0);
  w.f64(report.renderSeconds);
  w.f64(report.busySeconds);
  w.f64(report.idleSeconds);
  w.u64(report.bytesSent);
  return w.take();
}

RankReport decodeReport(std::string_view bytes) {
  Reader r(bytes, "Report");
  RankReport report;
  report.tiles = r.u64();
  report.rays = readRays(r);
  report.samples = r.u64();
  report.nonFinite = r.u64();
  const bool hasFirst = r.u32() != 0;
  const int x = r.i32();
  const int y = r.i32();
  if (hasFirst) report.firstNonFinite = PixelCoord{x, y};
  report.renderSeconds = r.f64();
  report.busySeconds = r.f64();
  report.idleSeconds = r.f64();
  report.bytesSent = r.u64();
  r.end();
  // Durations a rank could have measured (a century at most): they are printed and summed.
  for (const double seconds : {report.renderSeconds, report.busySeconds, report.idleSeconds}) {
    if (!(seconds >= 0 && seconds <= 3.2e9)) {
      throw ProtocolError("a Report holds an impossible duration");
    }
  }
  return report;
}

std::string encodeStop(const StopOrder& order) {
  Writer w;
  w.i32(order.status);
  w.u32(order.finalize ? 1 : 0);
  return w.take();
}

StopOrder decodeStop(std::string_view bytes) {
  Reader r(bytes, "Stop");
  StopOrder order;
  order.status = r.i32();
  order.finalize = r.u32() != 0;
  r.end();
  return order;
}

std::string encodeLeaving(const Leaving& leaving) {
  Writer w;
  w.i32(leaving.signal);
  w.text(leaving.reason);
  return w.take();
}

Leaving decodeLeaving(std::string_view bytes) {
  Reader r(bytes, "Leaving");
  Leaving leaving;
  leaving.signal = r.i32();
  leaving.reason = r.text();
  r.end();
  return leaving;
}

}  // namespace glint::cluster
