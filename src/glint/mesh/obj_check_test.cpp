// The OBJ statement checker (obj_check.h): which words are numbers and corners, where a fault is
// placed across line endings and continuations, which fault comes first, what is not checked.
#include "glint/mesh/obj_check.h"

#include <gtest/gtest.h>

#include <string>

namespace glint {
namespace {

const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

std::string faultAt(const std::string& text) {
  const std::optional<ObjFault> fault = findObjFault(text);
  if (!fault) return "none";
  return std::to_string(fault->line) + ":" + std::to_string(fault->column) + " " + fault->what;
}

TEST(ObjCheck, NumbersInEverySpellingExportersWrite) {
  for (const char* number :
       {"1", "-1", "+1", ".5", "1.", "-.5e-3", "1E+07", "0.000", "nan", "-NaN", "inf", "-Infinity",
        "1.#QNAN", "-1.#IND", "1.#INF", "-1.#QNAN0", "1.#SNAN", "00012.50"}) {
    SCOPED_TRACE(number);
    EXPECT_EQ(faultAt("v " + std::string(number) + " 0 0\n" + kTriangle + "f 2 3 4\n"), "none");
  }
  for (const char* word : {"x", "1x", "1,5", "e5", "1e", "1e+", "--1", "+-1", ".", "-", "1.#FOO",
                           "#1", "0x10", "1..2", "nanx", "infinit"}) {
    SCOPED_TRACE(word);
    const std::string text = "v 0 " + std::string(word) + " 0\n" + kTriangle + "f 2 3 4\n";
    if (std::string(word) == "#1") {
      // A comment: the line has one number.
      EXPECT_EQ(faultAt(text), "1:4 'v' needs 3 numbers, this line has 1");
    } else {
      EXPECT_EQ(faultAt(text), "1:5 '" + std::string(word) + "' is not a number");
    }
  }
}

TEST(ObjCheck, CountsOfNumbers) {
  EXPECT_EQ(faultAt("v 0 0 0 1\nv 1 0 0 1 0 0\n" + kTriangle + "f 1 2 3\n"), "none");  // w, colour
  EXPECT_EQ(faultAt(kTriangle + "v\nf 1 2 3\n"), "4:2 'v' needs 3 numbers, this line has 0");
  EXPECT_EQ(faultAt(kTriangle + "vn 0 1\nf 1 2 3\n"), "4:7 'vn' needs 3 numbers, this line has 2");
  EXPECT_EQ(faultAt(kTriangle + "vt 0.5\nvt\nf 1 2 3\n"),
            "5:3 'vt' needs a number, this line has 0");
}

TEST(ObjCheck, CornersAndIndices) {
  const std::string all = kTriangle + "vt 0 0\nvn 0 0 1\n";
  for (const char* face : {"f 1 2 3", "f 1/1 2/1 3/1", "f 1//1 2//1 3//1", "f 1/1/1 2/1/1 3/1/1",
                           "f -1 -2 -3", "f -3/-1/-1 2/1/1 +3/1/1", "f 1 2", "f 1 2 3 # c"}) {
    SCOPED_TRACE(face);
    EXPECT_EQ(faultAt(all + face + "\n"), "none");
  }
  const std::string corner = " is not a face corner (v, v/vt, v//vn or v/vt/vn, whole numbers)";
  for (const char* word : {"1/", "1/1/", "/1", "1///1", "1/1/1/1", "1/x", "a", "1.5", "-", "1//"}) {
    SCOPED_TRACE(word);
    EXPECT_EQ(faultAt(all + "f 1 2 " + word + "\n"), "6:7 '" + std::string(word) + "'" + corner);
  }
  EXPECT_EQ(faultAt(all + "f 1 2 3/0/1\n"),
            "6:9 texture coordinate index 0: OBJ indices count from 1 (or back from -1)");
  EXPECT_EQ(faultAt(all + "f 1 2 3/1/-2\n"),
            "6:11 normal index -2 reaches before the first normal (1 is above it)");
  EXPECT_EQ(faultAt(all + "f 1 2 99999999999999999999999\n"),
            "6:7 vertex index 99999999999999999999999 is past the file's 3 vertices");
}

TEST(ObjCheck, AFaceMayNameVerticesFurtherDown) {
  EXPECT_EQ(faultAt("f 1 2 3\n" + kTriangle), "none");
  EXPECT_EQ(faultAt("f 1 2 4\n" + kTriangle), "1:7 vertex index 4 is past the file's 3 vertices");
  // A forward index past the file comes before a later fault, which does not stop the count.
  EXPECT_EQ(faultAt("f 1 2 6\n" + kTriangle + "v 1 x 0\nv 0 0 1\n"),
            "1:7 vertex index 6 is past the file's 5 vertices");
  EXPECT_EQ(faultAt("f 1 2 5\n" + kTriangle + "v 1 x 0\nv 0 0 1\n"), "5:5 'x' is not a number");
  // Relative indices count only what lies above.
  EXPECT_EQ(faultAt("f -1 -2 -3\n" + kTriangle),
            "1:3 vertex index -1 reaches before the first vertex (0 are above it)");
}

TEST(ObjCheck, LinesAsAssimpReadsThem) {
  // "\r\n", a lone "\r" and no final line end; a continued line keeps counting lines.
  EXPECT_EQ(faultAt("v 0 0 0\r\nv 1 0 0\rv 0 1 0\rf 1 2 x"),
            "4:7 'x'" + std::string(" is not a face "
                                    "corner (v, v/vt, "
                                    "v//vn or v/vt/vn, "
                                    "whole numbers)"));
  EXPECT_EQ(faultAt("v 0 0 \\\n0\nv 1 \\\r\n 0 x\n" + kTriangle), "4:4 'x' is not a number");
  EXPECT_EQ(faultAt("v 0 0 \\\n0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "none");
  // A line starting with a blank is skipped whole; so is every statement not checked.
  EXPECT_EQ(faultAt(kTriangle + " v 1 x\n\tf 0 0 0\nf 1 2 3\n"), "none");
  EXPECT_EQ(faultAt("mtllib a b c\no x y\ng\nusemtl 1x\ns off\nl 1 99\np 0\ncurv 1 x\n" +
                    kTriangle + "vp 1 x\nf 1 2 3\n"),
            "none");
  EXPECT_EQ(faultAt("# v 1 x\n" + kTriangle + "f 1 2 3 #\n"), "none");
  // A keyword must stand alone: "vx" and "fo" are other statements.
  EXPECT_EQ(faultAt("vx 1\nfo 9\n" + kTriangle + "f 1 2 3\n"), "none");
}

TEST(ObjCheck, FilesThatAreNoTextAreNotChecked) {
  EXPECT_EQ(faultAt(std::string("v 1 x 0\n\0", 9)), "none");
  EXPECT_EQ(faultAt("v 1 x 0\n\f"), "none");
  EXPECT_EQ(faultAt(""), "none");
  // Non-printable bytes in a word are shown as '?', and a long word is cut.
  EXPECT_EQ(faultAt("v 1 \x01\xff 0\n"),
            "1:5 '?"
            "?' is not a number");
  EXPECT_EQ(faultAt("v 1 " + std::string(40, 'y') + " 0\n"),
            "1:5 '" + std::string(24, 'y') + "...' is not a number");
}

}  // namespace
}  // namespace glint
