#!/usr/bin/env bash
# Rewrites tests/references/<scene>.png for every scene in scenes/ (.yaml, .nff, .dat), rendered 160 pixels wide by the
# glint command exactly as tests/reference_image_test.cpp renders them. Run it only on purpose (a
# deliberate change of the images), look at every new image, and commit them with the reason.
#   usage: scripts/regenerate-references.sh [BUILD_DIR]   (default: build)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
glint="$build/glint"
[ -x "$glint" ] || { echo "regenerate-references: $glint not found; build first" >&2; exit 2; }
mkdir -p "$root/tests/references"
for scene in "$root"/scenes/*.yaml "$root"/scenes/*.nff "$root"/scenes/*.dat; do
  [ -f "$scene" ] || continue
  name=$(basename "${scene%.*}")
  "$glint" render "$scene" --width 160 --quiet -o "$root/tests/references/$name.png"
  echo "wrote tests/references/$name.png"
done
