#include "glint/preview/preview_messages.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace glint {
namespace {

std::string base64Of(const std::string& text) {
  const std::vector<std::uint8_t> bytes(text.begin(), text.end());
  return base64(bytes);
}

TEST(PreviewMessages, Base64MatchesRfc4648TestVectors) {
  EXPECT_EQ(base64Of(""), "");
  EXPECT_EQ(base64Of("f"), "Zg==");
  EXPECT_EQ(base64Of("fo"), "Zm8=");
  EXPECT_EQ(base64Of("foo"), "Zm9v");
  EXPECT_EQ(base64Of("foob"), "Zm9vYg==");
  EXPECT_EQ(base64Of("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64Of("foobar"), "Zm9vYmFy");
  const std::vector<std::uint8_t> high{0xff, 0xfe, 0x00};
  EXPECT_EQ(base64(high), "//4A");
}

// The table-driven encoder against the definition, six bits at a time, for every 12-bit group
// (all byte pairs appear across the shifted runs) and every length's padding.
TEST(PreviewMessages, Base64MatchesTheBitByBitDefinition) {
  constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto reference = [&](const std::vector<std::uint8_t>& bytes) {
    std::string out;
    for (std::size_t bit = 0; bit < bytes.size() * 8; bit += 6) {
      int v = 0;
      for (std::size_t b = bit; b < bit + 6; ++b)
        v = v * 2 + (b < bytes.size() * 8 ? (bytes[b / 8] >> (7 - b % 8)) & 1 : 0);
      out += kDigits[v];
    }
    while (out.size() % 4 != 0) out += '=';
    return out;
  };
  std::vector<std::uint8_t> bytes;
  for (int shift = 0; shift < 3; ++shift)
    for (int a = 0; a < 256; ++a)
      for (int b = 0; b < 256; b += 17) {
        bytes.push_back(static_cast<std::uint8_t>(a));
        bytes.push_back(static_cast<std::uint8_t>(b + shift));
      }
  EXPECT_EQ(base64(bytes), reference(bytes));
  for (std::size_t length = 0; length < 8; ++length) {
    const std::vector<std::uint8_t> part(bytes.begin() + 100, bytes.begin() + 100 + length);
    EXPECT_EQ(base64(part), reference(part)) << length << " bytes";
  }
}

TEST(PreviewMessages, JsonStringEscapesQuotesBackslashesAndControls) {
  EXPECT_EQ(jsonString("plain"), "\"plain\"");
  EXPECT_EQ(jsonString("a \"b\" \\ c\nd\te\x01"), "\"a \\\"b\\\" \\\\ c\\nd\\te\\u0001\"");
  EXPECT_EQ(jsonString("×2 ü"), "\"×2 ü\"");  // UTF-8 passes through
}

TEST(PreviewMessages, StatusEventIsOneServerSentEventWithJson) {
  PreviewStatus status;
  status.phase = PreviewPhase::Rendering;
  status.scene = "a \"scene\"";
  status.width = 64;
  status.height = 32;
  status.tilesDone = 3;
  status.tilesTotal = 8;
  status.elapsedSeconds = 1.5;
  status.etaSeconds = 2.5;
  status.summary = "line 1\nline 2";
  EXPECT_EQ(statusEvent(status),
            "event: status\ndata: {\"phase\":\"rendering\",\"scene\":\"a \\\"scene\\\"\","
            "\"width\":64,\"height\":32,\"tilesDone\":3,\"tilesTotal\":8,\"tilesResumed\":0,"
            "\"elapsed\":1.500,\"eta\":2.500,\"summary\":\"line 1\\nline 2\"}\n\n");
  status.etaSeconds.reset();
  EXPECT_NE(statusEvent(status).find("\"eta\":null"), std::string::npos);
}

TEST(PreviewMessages, TilesEventCarriesSizePlacePixelsAndAnOptionalRank) {
  std::vector<PreviewTile> tiles(2);
  tiles[0].region = {0, 0, 1, 1};
  tiles[0].rgb = {'f', 'o', 'o'};
  tiles[1].region = {16, 0, 17, 2};
  tiles[1].rank = 3;
  tiles[1].rgb = {'f', 'o', 'o', 'b', 'a', 'r'};
  EXPECT_EQ(tilesEvent(tiles, 17, 2),
            "event: tiles\ndata: {\"width\":17,\"height\":2,\"tiles\":["
            "{\"x\":0,\"y\":0,\"w\":1,\"h\":1,\"rank\":null,\"rgb\":\"Zm9v\"},"
            "{\"x\":16,\"y\":0,\"w\":1,\"h\":2,\"rank\":3,\"rgb\":\"Zm9vYmFy\"}]}\n\n");
}

}  // namespace
}  // namespace glint
