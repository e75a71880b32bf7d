// The preview's server-sent events: the status as JSON, and image blocks as JSON with their RGB
// bytes in base64 (what preview_page.html reads), with the JSON and base64 encoding they need.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "glint/preview/preview_state.h"

namespace glint {

std::string base64(std::span<const std::uint8_t> bytes);
// `text` as a JSON string literal, quotes included (UTF-8 passes through; controls are escaped).
std::string jsonString(std::string_view text);
std::string phaseName(PreviewPhase phase);  // "loading", "rendering", "finished", ...

// "event: status\ndata: {...}\n\n": phase, scene, width, height, tilesDone, tilesTotal,
// tilesResumed, elapsed and eta (seconds; eta null when unknown), summary.
std::string statusEvent(const PreviewStatus& status);
// "event: tiles\ndata: {width, height, tiles: [{x, y, w, h, rank, rgb}, ...]}\n\n": the image's
// size and `tiles`; rank is null when one process renders.
std::string tilesEvent(std::span<const PreviewTile> tiles, int width, int height);

}  // namespace glint
