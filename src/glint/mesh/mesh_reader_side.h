// The mesh reader program's side of importMeshInChild (import_child.h): it reads the file with
// importMesh (assimp_import.h) and writes the answer. Built into glint-mesh-reader (and the tests),
// not into libglint: only this side links assimp.
#pragma once

namespace glint {

// The mesh reader program's main: the child's side of importMeshInChild (its arguments are
// importMeshInChild's; run alone it says so and returns 2).
int runMeshReader(int argc, char** argv);

}  // namespace glint
