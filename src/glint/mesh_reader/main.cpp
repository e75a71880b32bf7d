// glint-mesh-reader: the program glint starts (fork + execve) to read one mesh file with assimp,
// apart from the renderer (mesh/import_child.h says why). Installed in libexec/glint; not a
// command for users.
#include "glint/mesh/mesh_reader_side.h"

int main(int argc, char** argv) { return glint::runMeshReader(argc, argv); }
