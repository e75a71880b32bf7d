// The PLY body checker (ply_check.h): a body that holds what the header declares passes; one cut
// short, with a count too large or too small, a short or long line, a value that is no number, a
// negative binary list count or triangle strips is a fault at its place.
#include "glint/mesh/ply_check.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

namespace glint {
namespace {

std::string header(const std::string& format, int vertices, int faces,
                   const std::string& faceElement = "face") {
  return "ply\nformat " + format + " 1.0\ncomment made by hand\nelement vertex " +
         std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement " + faceElement + " " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

const std::string kSquare = "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n";

std::string faultAt(const std::string& file) {
  const std::optional<PlyFault> fault = findPlyFault(file);
  if (!fault) return "none";
  return std::to_string(fault->line) + ":" + std::to_string(fault->column) + " " + fault->what;
}

TEST(PlyCheck, AnAsciiBodyAsTheHeaderSaysPasses) {
  EXPECT_EQ(faultAt(header("ascii", 4, 2) + kSquare + "3 0 1 2\n3 0 2 3\n"), "none");
  // CRLF, tabs, trailing blanks, a missing last newline, numbers in every spelling.
  EXPECT_EQ(faultAt(header("ascii", 4, 2) + "-1 -1 0\r\n1\t-1 0  \n+1 1.0 .0\n-1e0 1 nan\n" +
                    "4 0 1 2 3\n3 0 2 3"),
            "none");
  // Blank lines and NUL padding after the last element.
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "3 0 1 2\n\n  \r\n" + std::string(3, '\0')),
            "none");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "0\n"), "none");  // an empty list
}

TEST(PlyCheck, AnAsciiBodyThatDisagreesIsAFaultAtItsPlace) {
  // Line 11 is the first body line of header(...).
  EXPECT_EQ(faultAt(header("ascii", 4, 3) + kSquare + "3 0 1 2\n"),
            "16:1 the file ends before 'face' 2 of 3 (the header declares 3 'face' elements): it "
            "is cut short, or the count is too large");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "3 0 1 2\n3 0 2 3\n"),
            "16:1 more data after the last element the header declares: the file holds more "
            "than the header's counts say");
  // A blank line among the elements: assimp read some as an element of zeros and skipped
  // others, shifting the lines after it.
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + "-1 -1 0\n\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n"),
            "12:1 a blank line where 'vertex' 2 of 4 should be: the mesh library would read it as "
            "one, or skip it, and shift the lines after it");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + "  \r\n" + kSquare + "3 0 1 2\n").substr(0, 21),
            "11:1 a blank line whe");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + "-1 -1\n"),
            "11:6 the line of 'vertex' 1 of 4 ends early: no value for 'z' (the header's "
            "properties: x y z)");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "3 0 1\n"),
            "15:6 the line of 'face' 1 of 1 ends early: 'vertex_indices' holds 2 of its 3 values "
            "(the header's properties: (list vertex_indices))");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + "-1 -1 0 5\n"),
            "11:9 more values than 'vertex' 1 of 4 holds (the header's properties: x y z): the "
            "header does not describe this line");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + "-1 1x 0\n"),
            "11:4 '1x' is not a number ('y' of 'vertex' 1 of 4)");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "256 0 1 2\n"),
            "15:1 '256' is not a count of 'vertex_indices' values for 'face' 1 of 1 (a whole "
            "number of the count's type)");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "-3 0 1 2\n").substr(0, 10), "15:1 '-3' ");
  EXPECT_EQ(faultAt(header("ascii", 4, 1) + kSquare + "3 0 1 two\n"),
            "15:7 'two' is not a number ('vertex_indices' of 'face' 1 of 1)");
}

std::string binaryBody(bool bigEndian, std::int8_t faceCorners, int faces) {
  std::string body;
  const auto put = [&](const void* data, std::size_t size) {
    std::string bytes(static_cast<const char*>(data), size);
    if (bigEndian) bytes = std::string(bytes.rbegin(), bytes.rend());
    body += bytes;
  };
  for (int v = 0; v < 4; ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      const float value = static_cast<float>((v + axis) % 2);
      put(&value, sizeof value);
    }
  }
  for (int f = 0; f < faces; ++f) {
    put(&faceCorners, 1);
    for (int c = 0; c < faceCorners; ++c) {
      const std::int32_t index = c;
      put(&index, sizeof index);
    }
  }
  return body;
}

TEST(PlyCheck, ABinaryBodyIsWalkedToItsEnd) {
  for (const bool big : {false, true}) {
    const std::string format = big ? "binary_big_endian" : "binary_little_endian";
    SCOPED_TRACE(format);
    const std::string file = header(format, 4, 2) + binaryBody(big, 3, 2);
    EXPECT_EQ(faultAt(file), "none");
    const std::string cut = file.substr(0, file.size() - 1);
    EXPECT_EQ(faultAt(cut),
              "0:0 the file ends at byte " + std::to_string(cut.size()) +
                  " within 'face' 2 of 2 (the header declares 2 'face' elements): it is cut "
                  "short, or the count is too large");
    EXPECT_EQ(faultAt(file + "\n"), "none");  // a final newline, or NUL padding
    EXPECT_EQ(faultAt(file + std::string(4, '\0')), "none");
    EXPECT_EQ(faultAt(file + "xy"),
              "0:0 2 bytes after the last element the header declares (from byte " +
                  std::to_string(file.size()) +
                  "): the file holds more than the header's counts "
                  "say");
  }
  // A list count of uchar 200 where the file has room for 3 indices.
  EXPECT_NE(faultAt(header("binary_little_endian", 4, 1) + binaryBody(false, -56, 0) + "\xc8"),
            "none");
  // Too few vertices for the count (the vertices' 48 bytes cut to 40).
  const std::string shortVertices =
      header("binary_little_endian", 4, 0) + binaryBody(false, 3, 0).substr(0, 40);
  EXPECT_EQ(faultAt(shortVertices),
            "0:0 the file ends at byte " + std::to_string(shortVertices.size()) +
                " within 'vertex' 4 of 4 (the header declares 4 'vertex' elements): it is cut "
                "short, or the count is too large");
}

// A count whose size in bytes overflows 64 bits is cut short, not wrapped around (a header line
// with a leading blank, which the header check once did not read, declared it).
TEST(PlyCheck, ACountTooLargeForTheFileIsCutShortWhateverItsSize) {
  const std::string file =
      "ply\nformat binary_little_endian 1.0\n element vertex 6148914691236517206\nproperty uchar "
      "x\nproperty uchar y\nproperty uchar z\nend_header\nab";
  EXPECT_EQ(faultAt(file), "0:0 the file ends at byte " + std::to_string(file.size()) +
                               " within 'vertex' 1 of 6148914691236517206 (the header declares "
                               "6148914691236517206 'vertex' elements): it is cut short, or the "
                               "count is too large");
}

TEST(PlyCheck, AnElementWithoutPropertiesIsRefused) {
  EXPECT_EQ(
      faultAt("ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nend_header\n"),
      "0:0 its header declares 4000000000 'vertex' elements without any property");
  EXPECT_EQ(faultAt("ply\nformat ascii 1.0\nelement nothing 0\n" +
                    header("ascii", 4, 1).substr(std::string("ply\nformat ascii 1.0\n").size()) +
                    kSquare + "3 0 1 2\n"),
            "none");  // declared empty: allowed
}

TEST(PlyCheck, TriangleStripsAreRefused) {
  EXPECT_EQ(faultAt(header("ascii", 4, 1, "tristrips") + kSquare + "4 0 1 2 3\n"),
            "0:0 it holds triangle strips (element 'tristrips'), which glint does not read from "
            "PLY files: convert them to faces");
  EXPECT_EQ(faultAt(header("ascii", 4, 0, "tristrips") + kSquare), "none");
}

}  // namespace
}  // namespace glint
