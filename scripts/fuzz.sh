#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`: clang, address + undefined sanitizers, build-fuzz/)
# and runs each one for a bounded time.
#
#   scripts/fuzz.sh [SECONDS] [-- LIBFUZZER_FLAGS...]
#
# SECONDS per fuzz target, default 60. Longer runs: `scripts/fuzz.sh 3600`; on both cores:
# `scripts/fuzz.sh 3600 -- -fork=2`. The working corpus build-fuzz/corpus/NAME/ persists between
# runs (it grows), seeded from fuzz/corpus/NAME/ and, for the scene loader, scenes/*.yaml.
# A finding (crash, sanitizer report, uncaught exception other than SceneError, input slower than
# FUZZ_TIMEOUT seconds, more than FUZZ_RSS_MB MiB) stops that target and makes this script fail;
# the input is saved under build-fuzz/artifacts/NAME/. Reproduce with
# `build-fuzz/fuzz/NAME_fuzz FILE`, then add the (fixed) input to fuzz/corpus/NAME/ as a regression.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

seconds=60
if (($#)) && [[ "$1" != -- ]]; then
  [[ "$1" =~ ^[0-9]+$ ]] || {
    sed -n '2,13s/^# \{0,1\}//p' "${BASH_SOURCE[0]}" >&2
    exit 1
  }
  seconds="$1"
  shift
fi
[[ "${1:-}" == -- ]] && shift
extra_flags=("$@")
timeout_s="${FUZZ_TIMEOUT:-10}"
rss_mb="${FUZZ_RSS_MB:-2048}"

bash scripts/setup.sh deps --with-fuzz
bash scripts/build.sh fuzz

mapfile -t fuzzers < <(find build-fuzz/fuzz -maxdepth 1 -type f -name '*_fuzz' -perm -u+x | sort)
((${#fuzzers[@]})) || {
  echo "fuzz: error: no fuzz targets were built in build-fuzz/fuzz/" >&2
  exit 1
}

failed=()
for fuzzer in "${fuzzers[@]}"; do
  name="$(basename "$fuzzer" _fuzz)"
  corpus="build-fuzz/corpus/$name"
  artifacts="build-fuzz/artifacts/$name"
  log="build-fuzz/fuzz-$name.log"
  mkdir -p "$corpus" "$artifacts"
  # libFuzzer writes new inputs into the first corpus folder only, so seeds are copied into it.
  if [[ -d "fuzz/corpus/$name" ]]; then
    find "fuzz/corpus/$name" -maxdepth 1 -type f -exec cp -f {} "$corpus"/ \;
  fi
  if [[ "$name" == scene_loader ]]; then
    for scene in scenes/*.yaml; do
      [[ -f "$scene" ]] && cp -f "$scene" "$corpus/scenes-$(basename "$scene")"
    done
  fi
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
