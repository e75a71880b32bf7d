#include "glint/preview/preview_messages.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstring>

namespace glint {

namespace {

constexpr char kBase64Digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// The two digits of every 12-bit value: three bytes become two lookups instead of four (the
// encoding runs over every pixel a page is sent while the render runs).
struct Base64Pairs {
  std::array<char, 2 * 4096> digits{};
  constexpr Base64Pairs() {
    for (int v = 0; v < 4096; ++v) {
      digits[2 * v] = kBase64Digits[v >> 6];
      digits[2 * v + 1] = kBase64Digits[v & 63];
    }
  }
};
constexpr Base64Pairs kBase64Pairs;

// Writes the (bytes.size() + 2) / 3 * 4 characters of `bytes` in base64 at `out`.
void writeBase64(std::span<const std::uint8_t> bytes, char* out) {
  const char* pairs = kBase64Pairs.digits.data();
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v =
        (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    std::memcpy(out, pairs + 2 * (v >> 12), 2);
    std::memcpy(out + 2, pairs + 2 * (v & 4095), 2);
    out += 4;
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {  // the last one or two bytes, then padding
    const std::uint32_t v =
        (std::uint32_t{bytes[i]} << 16) | (rest == 2 ? std::uint32_t{bytes[i + 1]} << 8 : 0);
    out[0] = kBase64Digits[(v >> 18) & 63];
    out[1] = kBase64Digits[(v >> 12) & 63];
    out[2] = rest == 2 ? kBase64Digits[(v >> 6) & 63] : '=';
    out[3] = '=';
  }
}

std::size_t base64Size(std::size_t bytes) { return (bytes + 2) / 3 * 4; }

}  // namespace

std::string base64(std::span<const std::uint8_t> bytes) {
  std::string out(base64Size(bytes.size()), '=');
  writeBase64(bytes, out.data());
  return out;
}

std::string jsonString(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        else
          out += c;
    }
  }
  return out + "\"";
}

std::string phaseName(PreviewPhase phase) {
  switch (phase) {
    case PreviewPhase::Loading:
      return "loading";
    case PreviewPhase::Rendering:
      return "rendering";
    case PreviewPhase::Finished:
      return "finished";
    case PreviewPhase::Interrupted:
      return "interrupted";
    case PreviewPhase::Failed:
      return "failed";
  }
  return "failed";
}

namespace {

std::string seconds(double value) {
  return std::isfinite(value) ? fmt::format("{:.3f}", value) : std::string("null");
}

}  // namespace

std::string statusEvent(const PreviewStatus& status) {
  return fmt::format(
      "event: status\ndata: {{\"phase\":\"{}\",\"scene\":{},\"width\":{},\"height\":{},"
      "\"tilesDone\":{},\"tilesTotal\":{},\"tilesResumed\":{},\"elapsed\":{},\"eta\":{},"
      "\"summary\":{}}}\n\n",
      phaseName(status.phase), jsonString(status.scene), status.width, status.height,
      status.tilesDone, status.tilesTotal, status.tilesResumed, seconds(status.elapsedSeconds),
      status.etaSeconds ? seconds(*status.etaSeconds) : std::string("null"),
      jsonString(status.summary));
}

std::string tilesEvent(std::span<const PreviewTile> tiles, int width, int height) {
  std::string out =
      fmt::format("event: tiles\ndata: {{\"width\":{},\"height\":{},\"tiles\":[", width, height);
  std::size_t size = out.size() + 4;
  for (const PreviewTile& tile : tiles) size += tile.rgb.size() / 3 * 4 + 80;
  out.reserve(size);
  bool first = true;
  for (const PreviewTile& tile : tiles) {
    out += first ? "" : ",";
    first = false;
    out += fmt::format("{{\"x\":{},\"y\":{},\"w\":{},\"h\":{},\"rank\":{},\"rgb\":\"",
                       tile.region.x0, tile.region.y0, tile.region.width(), tile.region.height(),
                       tile.rank ? fmt::format("{}", *tile.rank) : std::string("null"));
    // In place, at the end of the event: no string per tile.
    const std::size_t at = out.size();
    out.resize(at + base64Size(tile.rgb.size()));
    writeBase64(tile.rgb, out.data() + at);
    out += "\"}";
  }
  out += "]}\n\n";
  return out;  // not `out + ...`: that would copy the whole event
}

}  // namespace glint
