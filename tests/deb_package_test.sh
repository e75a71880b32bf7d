#!/usr/bin/env bash
# The .debs that CPack makes: glint (the command) and libglint-dev (library, headers, CMake
# package). Checks their control fields — glint's Depends come from dpkg-shlibdeps and name the
# shared libraries it links — and unpacks glint into a scratch root, where `glint --version` and a
# small render run. (Installing them — dpkg -i, apt-get -f install — changes the machine, so that
# is described in docs/developing.md rather than done here.)
#
#   deb_package_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail

build="$(cd "$1" && pwd)"
source="$(cd "$2" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/glint-deb-XXXXXX")"
trap 'rm -rf "$work"' EXIT
fail() {
  printf 'FAIL: %s\n' "$*" >&2
  exit 1
}

(cd "$work" && cpack --config "$build/CPackConfig.cmake" -B "$work/packages" >"$work/cpack.log") || {
  cat "$work/cpack.log"
  fail "cpack failed"
}
runtime="$(find "$work/packages" -maxdepth 1 -name 'glint_*.deb')"
dev="$(find "$work/packages" -maxdepth 1 -name 'libglint-dev_*.deb')"
[[ -f "$runtime" && -f "$dev" ]] || fail "expected glint_*.deb and libglint-dev_*.deb, got: $(ls "$work/packages")"

depends="$(dpkg-deb -f "$runtime" Depends)"
echo "glint Depends: $depends"
for library in libc6 libstdc++6 libtbb libassimp libpng libopenexr libyaml libcpp-httplib; do
  grep -q "$library" <<<"$depends" || fail "glint's Depends lack $library"
done
dev_depends="$(dpkg-deb -f "$dev" Depends)"
echo "libglint-dev Depends: $dev_depends"
grep -q "glint (= " <<<"$dev_depends" || fail "libglint-dev does not depend on glint"
runtime_files="$(dpkg-deb -c "$runtime")"
dev_files="$(dpkg-deb -c "$dev")"
grep -q '\./usr/bin/glint$' <<<"$runtime_files" || fail "no /usr/bin/glint in the package"
grep -q '\./usr/libexec/glint/glint-mesh-reader$' <<<"$runtime_files" ||
  fail "no /usr/libexec/glint/glint-mesh-reader in the package"
for module in glint-preview-http.so glint-exr.so; do
  grep -q "\./usr/libexec/glint/$module\$" <<<"$runtime_files" ||
    fail "no /usr/libexec/glint/$module in the package"
done
# The MPI module is a package of its own: glint does not pull OpenMPI in.
! grep -q "libopenmpi" <<<"$depends" || fail "glint's Depends name OpenMPI (the MPI module's)"
if [[ -f "$build/glint-mpi.so" ]]; then
  mpi="$(find "$work/packages" -maxdepth 1 -name 'glint-mpi_*.deb')"
  [[ -f "$mpi" ]] || fail "no glint-mpi_*.deb, got: $(ls "$work/packages")"
  dpkg-deb -c "$mpi" | grep -q '\./usr/libexec/glint/glint-mpi\.so$' ||
    fail "no /usr/libexec/glint/glint-mpi.so in glint-mpi"
  mpi_depends="$(dpkg-deb -f "$mpi" Depends)"
  echo "glint-mpi Depends: $mpi_depends"
  grep -q "libopenmpi" <<<"$mpi_depends" || fail "glint-mpi's Depends lack libopenmpi"
  grep -q "glint (= " <<<"$mpi_depends" || fail "glint-mpi does not depend on glint"
  grep -q "glint-mpi" <<<"$(dpkg-deb -f "$runtime" Suggests)" || fail "glint does not suggest glint-mpi"
fi
grep -q 'usr/include/glint/glint.h$' <<<"$dev_files" || fail "no glint.h in libglint-dev"
grep -q 'cmake/glint/glintConfig.cmake$' <<<"$dev_files" || fail "no CMake package in libglint-dev"
grep -q 'libglint\.a$' <<<"$dev_files" || fail "no libglint.a in libglint-dev"

dpkg-deb -x "$runtime" "$work/root"
"$work/root/usr/bin/glint" --version | grep -q '^glint ' || fail "the unpacked glint does not run"
"$work/root/usr/bin/glint" render "$source/tests/cli/small.yaml" -o "$work/small.png" --quiet
[[ -s "$work/small.png" ]] || fail "the unpacked glint did not render"
# A mesh scene: the unpacked glint reads its mesh with the unpacked reader (../libexec/glint).
"$work/root/usr/bin/glint" render "$source/scenes/mesh.yaml" -o "$work/mesh.png" --quiet
[[ -s "$work/mesh.png" ]] || fail "the unpacked glint did not render a mesh scene"
# An EXR image: the unpacked glint loads the unpacked OpenEXR module.
"$work/root/usr/bin/glint" render "$source/tests/cli/small.yaml" -o "$work/small.exr" --quiet ||
  fail "the unpacked glint could not write an EXR image"
# A preview: the unpacked glint loads the unpacked HTTP module (../libexec/glint).
"$work/root/usr/bin/glint" render "$source/tests/cli/small.yaml" -o "$work/previewed.png" \
  --preview 0 --preview-linger 0 2>"$work/preview.log" ||
  fail "the unpacked glint could not show a preview: $(cat "$work/preview.log")"
grep -q 'preview at http://127.0.0.1:' "$work/preview.log" ||
  fail "the unpacked glint did not serve a preview: $(cat "$work/preview.log")"
echo "ok: $(basename "$runtime") and $(basename "$dev")"
