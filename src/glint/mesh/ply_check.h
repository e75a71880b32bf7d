// The body of a PLY file checked against its header before assimp reads it: assimp 5.2 trusts the
// header's counts and reads past a short body (a file cut short, or a count too large, gave
// triangles the file does not hold, made of whatever came next), ignores a body longer than the
// header says (faces silently dropped), and keeps only the last triangle of a triangle strip.
// Internal to the mesh loader: it runs in the import child (import_child.h) on the mapped file.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "glint/mesh/file_fault.h"

namespace glint {

using PlyFault = MeshFileFault;

// The first way the body disagrees with the header, or nothing. The header is read as
// checkPlyHeader (format_checks.h) reads it, which has passed already. Element instances are
// read as assimp reads them:
//  - ASCII: one instance per line, its values separated by blanks; a scalar property takes one
//    value, a list property a count and that many values. A blank line before the last instance,
//    a line with too few values, a value that is not a number, a list count that is not a whole
//    number within its type, more values on the line than the instance holds, and anything but
//    blanks or NULs after the last instance are faults at their line and column.
//  - binary (either byte order): the instances packed one after another, a list's count in its
//    count type. A body that ends before the last instance, a negative list count, or bytes after
//    the last instance other than whitespace and NUL padding are faults (at their byte offset,
//    said in `what`).
// A `tristrips` element is a fault: glint does not read triangle strips from PLY files; so is an
// element of a non-zero count that has no properties.
std::optional<PlyFault> findPlyFault(std::string_view file);

}  // namespace glint
