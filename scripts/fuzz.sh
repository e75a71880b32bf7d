#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`: clang, address + undefined sanitizers, build-fuzz/)
# and runs each one for a bounded time, one after the other on one core.
#
#   scripts/fuzz.sh [SECONDS | --total SECONDS] [--only NAME]... [-- LIBFUZZER_FLAGS...]
#
# SECONDS per fuzz target, default 60; --total SECONDS shares that time among the targets (CI).
# --only NAME runs that target only (scene_loader, nff, tachyon, mesh_obj, mesh_ply, mesh_stl,
# mesh_gltf, image_header, image_decode, mesh_texture, obj_fast_parse, checkpoint).
# Longer runs: `scripts/fuzz.sh 3600`; on both cores: `scripts/fuzz.sh 3600 -- -fork=2`.
# The working corpus BUILD/corpus/NAME/ persists between runs (it grows), seeded from
# fuzz/corpus/NAME/ and scenes/ (scene_loader: *.yaml, nff: *.nff, tachyon: *.dat). A finding
# (crash, sanitizer report, uncaught exception, broken loader promise, input slower than
# FUZZ_TIMEOUT seconds, more than FUZZ_RSS_MB MiB) stops that target and makes this script fail; the input is saved under
# BUILD/artifacts/NAME/. Reproduce with `BUILD/fuzz/NAME_fuzz FILE`, then add the (fixed) input
# to fuzz/corpus/NAME/ as a regression. BUILD is build-fuzz, or FUZZ_BUILD_DIR.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

usage() { sed -n '2,20s/^# \{0,1\}//p' "${BASH_SOURCE[0]}" >&2; }

seconds=60
total=0
only=()
while (($#)) && [[ "$1" != -- ]]; do
  case "$1" in
    --total)
      [[ "${2:-}" =~ ^[0-9]+$ ]] || { usage; exit 1; }
      total="$2"
      shift
      ;;
    --only)
      [[ -n "${2:-}" ]] || { usage; exit 1; }
      only+=("$2")
      shift
      ;;
    *)
      [[ "$1" =~ ^[0-9]+$ ]] || { usage; exit 1; }
      seconds="$1"
      ;;
  esac
  shift
done
[[ "${1:-}" == -- ]] && shift
extra_flags=("$@")
timeout_s="${FUZZ_TIMEOUT:-10}"
rss_mb="${FUZZ_RSS_MB:-2048}"
build="${FUZZ_BUILD_DIR:-build-fuzz}"

bash scripts/setup.sh deps --with-fuzz
start=$SECONDS
# The preset's settings in BUILD (its binaryDir is build-fuzz; -B overrides it).
cmake --preset fuzz -B "$build" >/dev/null
cmake --build "$build" --target glint_fuzzers -j "${GLINT_JOBS:-2}"
printf 'fuzz: targets built in %ss (%s/)\n' "$((SECONDS - start))" "$build"

# The targets are the sources fuzz/*_fuzz.cpp (a stale executable of a removed target is not run).
fuzzers=()
for source in fuzz/*_fuzz.cpp; do
  fuzzer="$build/fuzz/$(basename "$source" .cpp)"
  [[ -x "$fuzzer" ]] || {
    echo "fuzz: error: $fuzzer was not built" >&2
    exit 1
  }
  fuzzers+=("$fuzzer")
done
if ((${#only[@]})); then
  selected=()
  for name in "${only[@]}"; do
    [[ -x "$build/fuzz/${name}_fuzz" ]] || {
      echo "fuzz: error: no target $name in $build/fuzz/" >&2
      exit 1
    }
    selected+=("$build/fuzz/${name}_fuzz")
  done
  fuzzers=("${selected[@]}")
fi
((${#fuzzers[@]})) || {
  echo "fuzz: error: no fuzz targets were built in $build/fuzz/" >&2
  exit 1
}
if ((total > 0)); then
  seconds=$((total / ${#fuzzers[@]}))
  ((seconds > 0)) || seconds=1
fi

# assimp 5.2 leaks small objects (an aiMesh, an IOStream) on some of its error paths; glint loads a
# scene once per process, so they are suppressed rather than reported (fuzz/lsan.supp).
export LSAN_OPTIONS="suppressions=$ROOT/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

failed=()
for fuzzer in "${fuzzers[@]}"; do
  name="$(basename "$fuzzer" _fuzz)"
  corpus="$build/corpus/$name"
  artifacts="$build/artifacts/$name"
  log="$build/fuzz-$name.log"
  mkdir -p "$corpus" "$artifacts"
  # libFuzzer writes new inputs into the first corpus folder only, so seeds are copied into it.
  if [[ -d "fuzz/corpus/$name" ]]; then
    find "fuzz/corpus/$name" -maxdepth 1 -type f -exec cp -f {} "$corpus"/ \;
  fi
  seeds=()
  case "$name" in
    scene_loader) seeds=(scenes/*.yaml) ;;
    nff) seeds=(scenes/*.nff) ;;
    tachyon) seeds=(scenes/*.dat) ;;
  esac
  for scene in "${seeds[@]}"; do
    [[ -f "$scene" ]] && cp -f "$scene" "$corpus/scenes-$(basename "$scene")"
  done
  dict=()
  [[ -f "fuzz/$name.dict" ]] && dict=("-dict=fuzz/$name.dict")

  printf 'fuzz: %s for %ss (corpus %s: %s inputs)\n' "$name" "$seconds" "$corpus" \
    "$(find "$corpus" -type f | wc -l)"
  start=$SECONDS
  status=0
  # The per-input log is long; it goes to a file and only the summary (or the report) is shown.
  "$fuzzer" "$corpus" "${dict[@]}" -max_total_time="$seconds" -timeout="$timeout_s" \
    -rss_limit_mb="$rss_mb" -artifact_prefix="$artifacts/" -print_final_stats=1 \
    "${extra_flags[@]}" >"$log" 2>&1 || status=$?
  if ((status == 0)); then
    grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb|stat::new_units_added)' "$log" |
      sed 's/^/  /'
    printf 'fuzz: %s: no finding in %ss (corpus now %s inputs)\n' "$name" "$((SECONDS - start))" \
      "$(find "$corpus" -type f | wc -l)"
  else
    echo "fuzz: $name: FINDING (exit $status); the end of $log:"
    tail -n 80 "$log"
    echo "fuzz: inputs saved in $artifacts/:"
    ls -l "$artifacts"
    failed+=("$name")
  fi
done

if ((${#failed[@]})); then
  echo "fuzz: findings in: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: ${#fuzzers[@]} target(s), no finding"
