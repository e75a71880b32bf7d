#!/usr/bin/env bash
# Builds the benchmarks (Release, -DGLINT_BUILD_BENCH=ON) and runs them all, printing their tables.
#
#   scripts/bench.sh [--quick] [--runs N] [--build-dir DIR] [--no-build] [--only NAMES]
#
#   --quick          smaller scenes and fewer configurations: a smoke test in a few minutes
#   --runs N         repetitions per figure (medians are printed; default: each program's own)
#   --build-dir DIR  build tree to use (default build/, the release preset's)
#   --no-build       run what DIR already holds
#   --only NAMES     comma-separated subset of: ray_throughput, build_memory, bvh_scaling,
#                    renderer_comparison, adaptive_sampling, path_tracing, instancing, spd
#
# spd is bench/spd_bench.sh (the seven SPD scenes, glint against Tachyon); it needs the SPD files
# in ../shared/spd beside the repository and is skipped, saying so, without them.
# Needs Embree 3, Tachyon and POV-Ray (scripts/setup.sh bench installs them). Everything printed is
# also saved to DIR/bench-results/bench-DATE.txt; the renderer comparison leaves its scenes, logs and
# one PNG per renderer in DIR/bench-results/renderer_comparison/. The machine should be otherwise idle:
# the load average is printed at the start and end of every program. adaptive_sampling (the
# showcase at 320x180, adaptive against fixed sampling at equal error) caches its reference render
# in DIR/bench/adaptive_sampling_cache/.
# Environment: GLINT_JOBS (build jobs, default 2).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

quick=()
runs=()
build_dir=build
build=1
only=ray_throughput,build_memory,bvh_scaling,renderer_comparison,adaptive_sampling,path_tracing,instancing,spd
while (($#)); do
  case "$1" in
    --quick) quick=(--quick) ;;
    --runs)
      runs=(--runs "${2:?--runs needs a number}")
      shift
      ;;
    --build-dir)
      build_dir="${2:?--build-dir needs a folder}"
      shift
      ;;
    --no-build) build=0 ;;
    --only)
      only="${2:?--only needs names}"
      shift
      ;;
    -h | --help)
      sed -n '2,22s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"
      exit 0
      ;;
    *)
      printf 'bench: error: unknown argument %s\n' "$1" >&2
      exit 2
      ;;
  esac
  shift
done

if ((build)); then
  if [[ "$build_dir" == build ]]; then
    # The release preset's tree, with the benchmarks switched on (kept in its cache).
    if [[ -z "${CMAKE_GENERATOR:-}" && ! -f build/CMakeCache.txt ]] && command -v ninja >/dev/null; then
      export CMAKE_GENERATOR=Ninja
    fi
    cmake --preset release -DGLINT_BUILD_BENCH=ON
  else
    generator=()
    if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null; then generator=(-G Ninja); fi
    cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DGLINT_BUILD_BENCH=ON
  fi
  cmake --build "$build_dir" -j "${GLINT_JOBS:-2}" --target glint_bench
fi

bench_bin="$build_dir/bench"
[[ -x "$bench_bin/ray_throughput" ]] ||
  { printf 'bench: error: no benchmarks in %s (build with -DGLINT_BUILD_BENCH=ON)\n' "$bench_bin" >&2; exit 1; }
grep -q 'CMAKE_BUILD_TYPE:STRING=Release' "$build_dir/CMakeCache.txt" ||
  printf 'bench: warning: %s is not a Release build; the figures mean little\n' "$build_dir" >&2

results="$build_dir/bench-results"
mkdir -p "$results"
log="$results/bench-$(date +%Y%m%d-%H%M%S).txt"

run() {
  local name="$1"
  shift
  [[ ",$only," == *",$name,"* ]] || return 0
  printf '\n$ %s\n' "$*"
  "$@"
}

{
  printf 'glint benchmarks, %s, commit %s%s\n' "$(date -u +%Y-%m-%dT%H:%M:%SZ)" \
    "$(git rev-parse --short HEAD 2>/dev/null || echo unknown)" \
    "$(git diff --quiet HEAD 2>/dev/null || echo ' (with local changes)')"
  printf 'uptime: %s\n' "$(uptime)"
  run ray_throughput "$bench_bin/ray_throughput" "${quick[@]}" "${runs[@]}"
  run build_memory "$bench_bin/build_memory" "${quick[@]}" "${runs[@]}"
  run bvh_scaling "$bench_bin/bvh_scaling" "${quick[@]}" "${runs[@]}"
  run renderer_comparison "$bench_bin/renderer_comparison" "${quick[@]}" "${runs[@]}" \
    --out "$results/renderer_comparison"
  run adaptive_sampling "$bench_bin/adaptive_sampling" "${quick[@]}" "${runs[@]}"
  run path_tracing "$bench_bin/path_tracing" "${quick[@]}" "${runs[@]}"
  run instancing "$bench_bin/instancing" "${quick[@]}" "${runs[@]}"
  if [[ -f "$ROOT/../shared/spd/balls.nff.gz" ]]; then
    spd_runs=("${runs[@]}")
    ((${#quick[@]})) && spd_runs=(--runs 1)
    run spd bash "$ROOT/bench/spd_bench.sh" "${spd_runs[@]}" --glint "$build_dir/glint"
  elif [[ ",$only," == *",spd,"* ]]; then
    printf '\nspd: skipped: the SPD files are not in %s\n' "$ROOT/../shared/spd"
  fi
  printf '\nuptime: %s\n' "$(uptime)"
} 2>&1 | tee "$log"
printf 'bench: results saved to %s\n' "$log" >&2
