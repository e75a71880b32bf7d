#include "glint/preview/preview_messages.h"

#include <fmt/format.h>

#include <cmath>

namespace glint {

std::string base64(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  // Written through a pointer into a string of the final size: every tile of every page passes
  // through here, and appending character by character costs several times more.
  std::string out((bytes.size() + 2) / 3 * 4, '=');
  char* next = out.data();
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v =
        (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    next[0] = kDigits[(v >> 18) & 63];
    next[1] = kDigits[(v >> 12) & 63];
    next[2] = kDigits[(v >> 6) & 63];
    next[3] = kDigits[v & 63];
    next += 4;
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {  // the last one or two bytes; the padding '=' is already there
    const std::uint32_t v =
        (std::uint32_t{bytes[i]} << 16) | (rest == 2 ? std::uint32_t{bytes[i + 1]} << 8 : 0);
    next[0] = kDigits[(v >> 18) & 63];
    next[1] = kDigits[(v >> 12) & 63];
    if (rest == 2) next[2] = kDigits[(v >> 6) & 63];
  }
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
    out += base64(tile.rgb);
    out += "\"}";
  }
  return out + "]}\n\n";
}

}  // namespace glint
