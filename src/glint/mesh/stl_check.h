// An ASCII STL file's statements checked before assimp reads it: assimp 5.2 keeps the first three
// vertices of a facet that has more (a quad lost its second triangle, silently), and on a word
// that is no number it quoted the whole rest of the file in its message. Internal to the mesh
// loader: it runs in the import child (import_child.h) on the mapped file.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "glint/mesh/file_fault.h"

namespace glint {

using StlFault = MeshFileFault;

// Whether assimp reads `file` as a binary STL: 84 bytes or more and exactly 84 + 50 × the
// triangle count its bytes 80–83 hold (whatever its first bytes say: many binary files start
// with "solid").
bool isBinaryStl(std::string_view file);

// The first malformed statement of an ASCII STL file, or nothing (also for a binary one). Read as
// words separated by blanks and line ends:
//   solid NAME...                 (the name runs to the line's end)
//     facet [normal X Y Z]
//       outer loop
//         vertex X Y Z            exactly three
//       endloop
//     endfacet
//   endsolid [NAME...]            (then another solid, or the end)
// Numbers are decimal floats (nan and inf too). A file that ends inside a solid (without its
// endsolid) is a fault only when it ends inside a facet.
std::optional<StlFault> findStlFault(std::string_view file);

}  // namespace glint
