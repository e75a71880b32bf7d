#!/usr/bin/env bash
# Configures and builds one CMake preset (CMakePresets.json), optionally runs its tests.
#
#   scripts/build.sh [PRESET] [--test] [--target TARGET]...
#
# PRESET is release (default, build/), sanitize (build-sanitize/) or fuzz (build-fuzz/). Dependencies
# must be installed (scripts/setup.sh). Environment: GLINT_JOBS (build jobs, default 2).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

preset=release
run_tests=0
targets=()
while (($#)); do
  case "$1" in
    --test) run_tests=1 ;;
    --target)
      targets+=(--target "${2:?--target needs a name}")
      shift
      ;;
    -h | --help)
      sed -n '2,7s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"
      exit 0
      ;;
    -*)
      printf 'build: error: unknown option %s\n' "$1" >&2
      exit 1
      ;;
    *) preset="$1" ;;
  esac
  shift
done

case "$preset" in
  release) binary_dir=build ;;
  *) binary_dir="build-$preset" ;;
esac

# The presets name no generator: prefer Ninja for a new build directory, but keep whatever generator
# an existing one was configured with (CMake refuses to switch generators in place).
if [[ -z "${CMAKE_GENERATOR:-}" && ! -f "$binary_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null; then
  export CMAKE_GENERATOR=Ninja
fi

start=$SECONDS
printf 'build: configuring preset %s (%s/)\n' "$preset" "$binary_dir" >&2
cmake --preset "$preset"
printf 'build: building preset %s with %s jobs\n' "$preset" "${GLINT_JOBS:-2}" >&2
cmake --build --preset "$preset" -j "${GLINT_JOBS:-2}" "${targets[@]}"
printf 'build: preset %s built in %ss\n' "$preset" "$((SECONDS - start))" >&2

if ((run_tests)); then
  start=$SECONDS
  ctest --preset "$preset" --no-tests=error
  printf 'build: preset %s tests ran in %ss\n' "$preset" "$((SECONDS - start))" >&2
fi
