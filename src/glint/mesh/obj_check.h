// The first malformed statement of a Wavefront OBJ file, with its line and column: what glint says
// instead of assimp's words (which name no place, and for some faults name the wrong one) or
// instead of assimp's silent repair. Internal to the mesh loader: it runs in the import child
// (import_child.h), only on a file glint's own parser (obj_fast_parse.h) did not take.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace glint {

struct ObjFault {
  std::size_t line = 0;    // 1-based
  std::size_t column = 0;  // 1-based, in bytes (a tab is one column)
  std::string what;        // e.g. "'1x' is not a number"
};

// The statements checked are the ones that make the mesh, read as assimp 5.2 reads lines (a line
// ends at "\n", "\r\n" or a lone "\r"; one starting with a blank is skipped whole; a backslash
// before a line end continues the line; '#' starts a comment):
//   v X Y Z ...   at least 3 numbers (a w or a vertex colour may follow)
//   vn X Y Z      at least 3 numbers
//   vt U ...      at least 1 number
//   f C C ...     corners v, v/vt, v//vn or v/vt/vn; indices are whole numbers, not 0; a positive
//                 one within the file's count of that kind (OBJ lets a face name a vertex defined
//                 further down), a negative one within the ones defined above it
// A number is a decimal float (".5", "1.", "-2e-3"), nan or inf in any case, or the Microsoft C
// library's spellings of them ("1.#QNAN", "-1.#IND", "1.#INF"), which exporters write. Any other
// statement (o, g, s, usemtl, mtllib, l, p, curves...) is not checked: assimp reads or ignores it.
// A face of fewer than 3 corners is assimp's line or point, not a fault. A file with a NUL or a
// form feed is not checked (assimp ends lines there; such a file is no text this reads by lines).
std::optional<ObjFault> findObjFault(std::string_view text);

}  // namespace glint
