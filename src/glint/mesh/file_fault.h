// What the mesh loader's own checks of a file (ply_check.h, stl_check.h) find, and the words of
// text formats they take as numbers. Internal to the mesh loader.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace glint {

// The first fault of a mesh file: its place (line 0 for a binary body, which says its byte offset
// in `what`) and what is wrong, e.g. "'1x' is not a number ...".
struct MeshFileFault {
  std::size_t line = 0;    // 1-based
  std::size_t column = 0;  // 1-based, in bytes
  std::string what;
};

// Whether a word of a text mesh file (PLY, STL) is a number as assimp's readers take one:
// an optional sign, then a decimal float (digits with an optional fraction and exponent: "1",
// ".5", "1.", "-2e-3"), nan or inf in any case; a value beyond the double range counts.
bool isNumberWord(std::string_view word);

}  // namespace glint
