// The ASCII STL checker (stl_check.h): well-formed solids pass (any case, several solids, a facet
// without its normal); facets that are not triangles, words that are not numbers, unexpected
// keywords and a file cut inside a facet are faults at their place; binary files are not read.
#include "glint/mesh/stl_check.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace glint {
namespace {

const std::string kFacet =
    "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n"
    "endfacet\n";

std::string faultAt(const std::string& file) {
  const std::optional<StlFault> fault = findStlFault(file);
  if (!fault) return "none";
  return std::to_string(fault->line) + ":" + std::to_string(fault->column) + " " + fault->what;
}

TEST(StlCheck, WellFormedSolidsPass) {
  EXPECT_EQ(faultAt("solid part 1\n" + kFacet + kFacet + "endsolid part 1\n"), "none");
  EXPECT_EQ(faultAt("solid a\n" + kFacet + "endsolid a\nsolid b\n" + kFacet + "endsolid"), "none");
  EXPECT_EQ(faultAt("SOLID A\r\nFACET NORMAL 0 0 1\r\nOUTER LOOP\r\nVERTEX 1e0 -.5 +2.\r\n"
                    "VERTEX 1 0 0\r\nVERTEX nan inf 0\r\nENDLOOP\r\nENDFACET\r\nENDSOLID\r\n"),
            "none");
  EXPECT_EQ(faultAt("solid\nfacet outer loop vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 endloop "
                    "endfacet\n"),
            "none");                         // no normal, no endsolid
  EXPECT_EQ(faultAt("not an stl"), "none");  // not ASCII STL: the mesh library says so
  EXPECT_EQ(faultAt("solid\n" + kFacet + "endsolid\n" + std::string(20, '\0')), "none");  // padding
}

TEST(StlCheck, MalformedStatementsAreFaultsAtTheirPlace) {
  std::string quad = kFacet;
  quad.insert(quad.find(" endloop"), "  vertex 1 1 0\n");
  EXPECT_EQ(faultAt("solid q\n" + quad + "endsolid\n"),
            "7:3 a facet with more than 3 vertices: STL facets are triangles (the mesh library "
            "would keep the first three and lose the rest)");
  EXPECT_EQ(faultAt("solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
                    "endfacet\nendsolid\n"),
            "2:1 a facet of 2 vertices: STL facets are triangles");
  std::string bad = kFacet;
  bad.replace(bad.find("vertex 1 0 0") + 7, 1, "1x");
  EXPECT_EQ(faultAt("solid b\n" + bad + "endsolid\n"),
            "5:10 '1x' is not a number (a vertex has 3)");
  EXPECT_EQ(faultAt("solid c\nfacet normal 0 0 1\n outer loop\n  vertex 0 0"),
            "4:13 the file ends within a vertex (3 numbers)");
  EXPECT_EQ(faultAt("solid c\n" + kFacet.substr(0, kFacet.find(" endloop"))),
            "7:1 the file ends within a facet, before 'endloop' (cut short?)");
  EXPECT_EQ(faultAt("solid d\nfacet normal 0 0 1\n inner loop\n"),
            "3:2 expected 'outer' in a facet, got 'inner'");
  EXPECT_EQ(faultAt("solid e\n" + kFacet + "facets\n"),
            "9:1 expected 'facet' or 'endsolid', got 'facets'");
  EXPECT_EQ(faultAt("solid f\n" + kFacet + "endsolid f\njunk\n"),
            "10:1 expected 'solid' or the end after 'endsolid', got 'junk'");
}

TEST(StlCheck, ABinaryFileIsNotRead) {
  // 80-byte header starting with "solid", a count of 1, one 50-byte triangle record of garbage.
  std::string binary = "solid this is a binary file";
  binary.resize(80, ' ');
  const std::uint32_t count = 1;
  binary.append(reinterpret_cast<const char*>(&count), 4);
  binary.append(50, 'x');
  EXPECT_TRUE(isBinaryStl(binary));
  EXPECT_EQ(faultAt(binary), "none");
  EXPECT_FALSE(isBinaryStl(binary + "y"));
}

}  // namespace
}  // namespace glint
