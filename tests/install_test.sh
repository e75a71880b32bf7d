#!/usr/bin/env bash
# glint as another project sees it once installed: `cmake --install` into a fresh prefix, then the
# examples/ folder configured on its own against that prefix (find_package(glint CONFIG), which
# finds glint's dependencies itself), built, and the seed's test case rendered — the same bytes as
# the in-tree example's. examples/seed_test_case.cpp includes only glint/glint.h.
#
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail

build="$(cd "$1" && pwd)"
source="$(cd "$2" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/glint-install-XXXXXX")"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
fail() {
  printf 'FAIL: %s\n' "$*" >&2
  exit 1
}

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
[[ -x "$prefix/bin/glint" ]] || fail "no bin/glint in the prefix"
"$prefix/bin/glint" --version
[[ -f "$prefix/include/glint/glint.h" ]] || fail "no include/glint/glint.h"
config="$(find "$prefix" -name glintConfig.cmake)"
[[ -n "$config" ]] || fail "no glintConfig.cmake"
archive="$(find "$prefix" -name libglint.a)"
[[ -n "$archive" ]] || fail "no libglint.a"
! grep -rlE 'gtest|gmock' "$prefix/include" || fail "test headers were installed"
[[ ! -e "$prefix/include/glint/cli" ]] || fail "the command's headers were installed"
[[ -x "$prefix/libexec/glint/glint-mesh-reader" ]] || fail "no libexec/glint/glint-mesh-reader"
# The installed command reads meshes with the installed reader (../libexec/glint from bin/glint):
# the same bytes as the build tree's command.
"$prefix/bin/glint" render "$source/scenes/mesh.yaml" -o "$work/mesh.png" --quiet
"$build/glint" render "$source/scenes/mesh.yaml" -o "$work/mesh-in-tree.png" --quiet
cmp "$work/mesh.png" "$work/mesh-in-tree.png" ||
  fail "the installed glint renders scenes/mesh.yaml other than the build tree's"
for module in glint-preview-http.so glint-exr.so; do
  [[ -f "$prefix/libexec/glint/$module" ]] || fail "no libexec/glint/$module"
done
# An EXR image from the installed command, with the installed OpenEXR module.
"$prefix/bin/glint" render "$source/tests/cli/small.yaml" -o "$work/small.exr" --quiet ||
  fail "the installed glint could not write an EXR image"
if [[ -f "$build/glint-mpi.so" ]]; then
  [[ -f "$prefix/libexec/glint/glint-mpi.so" ]] || fail "no libexec/glint/glint-mpi.so"
fi
# A preview from the installed command, with the installed module.
"$prefix/bin/glint" render "$source/tests/cli/small.yaml" -o "$work/previewed.png" \
  --preview 0 --preview-linger 0 2>"$work/preview.log" ||
  fail "the installed glint could not show a preview: $(cat "$work/preview.log")"
grep -q 'preview at http://127.0.0.1:' "$work/preview.log" ||
  fail "the installed glint did not serve a preview: $(cat "$work/preview.log")"
echo "installed: $(cd "$prefix" && find . -type f | wc -l) files (${config#"$prefix"/}, ${archive#"$prefix"/})"

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
cmake -S "$source/examples" -B "$work/examples" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$work/configure.log" || {
  cat "$work/configure.log"
  fail "examples/ does not configure against the installed package"
}
# examples/CMakeLists.txt sets no C++ standard of its own: glint::glint must bring C++20.
cmake --build "$work/examples" -j "${GLINT_JOBS:-2}" --target seed_test_case render_scene_file
"$work/examples/seed_test_case" "$work/seed.png"
"$build/examples/seed_test_case" "$work/seed-in-tree.png" >/dev/null
cmp "$work/seed.png" "$work/seed-in-tree.png" ||
  fail "the example built against the installed package renders other bytes than the in-tree one"
echo "ok: examples/ built against the installed glint renders the seed's test case"
# Only the mesh reader runs assimp: the package's consumers neither find nor link it (no
# libassimp-dev needed to build against libglint), and no installed header declares its side.
! grep -rl 'assimp' "$(dirname "$config")" || fail "glint's CMake package names assimp"
if command -v ldd >/dev/null; then
  ! ldd "$work/examples/render_scene_file" | grep -q libassimp ||
    fail "a program linked with the installed library links libassimp"
fi
for internal in assimp_import.h obj_fast_parse.h mesh_reader_side.h mesh_reader_wire.h; do
  [[ ! -e "$prefix/include/glint/mesh/$internal" ]] || fail "mesh/$internal was installed"
done

# A program of the library's user, in PREFIX/bin: a mesh scene (the installed mesh reader) to an
# EXR image (the installed module), found from the program's place — never from the build tree,
# which an installed library must not run helpers from.
cp "$work/examples/render_scene_file" "$prefix/bin/"
"$prefix/bin/render_scene_file" "$source/scenes/mesh.yaml" "$work/mesh-lib.exr" 96 >/dev/null ||
  fail "a program linked with the installed library could not render scenes/mesh.yaml to EXR"
"$prefix/bin/glint" render "$source/scenes/mesh.yaml" -o "$work/mesh-cmd.exr" --width 96 --quiet
cmp "$work/mesh-lib.exr" "$work/mesh-cmd.exr" ||
  fail "the library's program and the command render scenes/mesh.yaml to other EXR bytes"
# Outside the prefix (and outside the build tree) the helpers are not found, and the error says
# how to name them, unless glint was configured for an install prefix that holds them.
configured="$(sed -n 's/^CMAKE_INSTALL_PREFIX:[A-Z]*=//p' "$build/CMakeCache.txt")"
found_elsewhere=false
for installed in "${configured:-/usr/local}" /usr; do
  [[ -e "$installed/libexec/glint/glint-mesh-reader" ]] && found_elsewhere=true
done
if ! $found_elsewhere; then
  if "$work/examples/render_scene_file" "$source/scenes/mesh.yaml" "$work/nowhere.png" 32 \
    >/dev/null 2>"$work/nowhere.log"; then
    fail "a program outside the prefix found a mesh reader: the build tree's?"
  fi
  grep -q "GLINT_MESH_READER" "$work/nowhere.log" ||
    fail "the missing mesh reader is not explained: $(cat "$work/nowhere.log")"
fi
echo "ok: a program linked with the installed library reads meshes and writes EXR"

# Every installed header compiles on its own (no include order, no definition from the build).
cxx="${CXX:-c++}"
find "$prefix/include/glint" -name '*.h' -printf '%P\n' | sort |
  xargs -P "${GLINT_JOBS:-2}" -I{} sh -c \
    'echo "#include <glint/{}>" | "$0" -std=c++20 -fsyntax-only -I"$1/include" -x c++ - ||
       { echo "FAIL: <glint/{}> does not compile on its own" >&2; exit 255; }' "$cxx" "$prefix" ||
  fail "an installed header does not compile on its own"
echo "ok: every installed header compiles on its own"
