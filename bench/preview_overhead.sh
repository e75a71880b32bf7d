#!/usr/bin/env bash
# What `--preview` costs a render, with a page's event stream connected (curl reading /events)
# during every previewed run. The target is at most 2 % slower.
#
#   bench/preview_overhead.sh [--runs N] [--instructions] [--glint PATH] [-- RENDER ARGS...]
#
# Time (default): alternating runs without and with the preview; the medians of the render phase
# (`--stats`: "time: ... render X s"), of the whole process's wall time and of its CPU time (user +
# system, all threads), and their ratios. Measure on an idle machine: on a loaded one the spread of
# single runs' wall time exceeds 2 %.
# --instructions: one run of each under callgrind (valgrind), which counts the instructions of
# every thread — independent of the load: the totals, and the preview's own parts (the render
# threads' tile encoding, the publishing thread, the event stream, the finished image after the
# render).
#
# Default render: scenes/first-scene.yaml at 1280×800 (--instructions: 640×400), 4 spp, all cores:
# quick tiles, the worst case per tile for the preview (every tile is encoded, published and sent).
# Default 15 pairs.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
runs=15
instructions=0
glint="$ROOT/build/glint"
render=()
while (($#)); do
  case "$1" in
    --instructions) instructions=1 ;;
    --runs) runs="${2:?--runs needs a number}"; shift ;;
    --glint) glint="${2:?--glint needs a path}"; shift ;;
    --) shift; render=("$@"); break ;;
    -h | --help) sed -n '2,19s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) printf 'preview_overhead: unknown argument %s\n' "$1" >&2; exit 2 ;;
  esac
  shift
done
((${#render[@]})) || render=("$ROOT/scenes/first-scene.yaml" --width $((instructions ? 640 : 1280)))
if ! command -v curl >/dev/null || [[ ! -x /usr/bin/time ]]; then
  echo "preview_overhead: needs curl and /usr/bin/time" >&2
  exit 1
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# connect_client LOG: once glint has printed its preview address in LOG, reads /events in the
# background; prints curl's process id.
connect_client() {
  local url=""
  for _ in $(seq 3000); do
    url="$(grep -oE 'http://127\.0\.0\.1:[0-9]+/' "$1" | head -n 1 || true)"
    [[ -n "$url" ]] && break
    sleep 0.01
  done
  curl -sN "${url}events" >/dev/null 2>&1 &
  echo $!
}

if ((instructions)); then
  command -v valgrind >/dev/null || { echo "preview_overhead: --instructions needs valgrind" >&2; exit 1; }
  callgrind() {
    local out="$work/callgrind.$1" log="$work/log.$1"
    shift
    valgrind --tool=callgrind --callgrind-out-file="$out" "$glint" render "${render[@]}" \
      -o "$work/out.png" --quiet "$@" 2>"$log" &
    local pid=$! client=""
    (($#)) && client="$(connect_client "$log")"
    wait "$pid"
    [[ -n "$client" ]] && { kill "$client" 2>/dev/null || true; }
    sed -nE 's/.*Collected : ([0-9]+).*/\1/p' "$log"
  }
  # The inclusive count of the first function whose name matches $2 in callgrind file $1.
  part() {
    callgrind_annotate --inclusive=yes --threshold=100 "$1" 2>/dev/null |
      grep -E "$2" | head -n 1 | awk '{ gsub(",", "", $1); print $1 + 0 }'
  }
  printf 'glint %s; %s; instructions (callgrind)\n' "$("$glint" --version)" "${render[*]}"
  without="$(callgrind without)"
  with="$(callgrind with --preview 0 --preview-linger 0)"
  file="$work/callgrind.with"
  tiles="$(part "$file" 'attachPreview.*FinishedTile')"
  encoder="$(part "$file" 'PreviewState::publishLoop')"
  stream="$(part "$file" 'PreviewServer::Impl::stream.*operator')"
  final="$(part "$file" 'PreviewState::imageFinished')"
  awk -v a="$without" -v b="$with" -v t="$tiles" -v e="$encoder" -v s="$stream" -v f="$final" 'BEGIN {
    printf "%-44s %15.0f\n", "without --preview", a
    printf "%-44s %15.0f  %+.2f%%\n", "with --preview and a page connected", b, 100 * (b - a) / a
    printf "  %-42s %15.0f  %+.2f%%\n", "render threads: encoding finished tiles", t, 100 * t / a
    printf "  %-42s %15.0f  %+.2f%%\n", "publishing thread: tiles into the image", e, 100 * e / a
    printf "  %-42s %15.0f  %+.2f%%\n", "event stream: JSON, base64, writes", s, 100 * s / a
    printf "  %-42s %15.0f  %+.2f%%\n", "while rendering (the three above)", t + e + s, 100 * (t + e + s) / a
    printf "  %-42s %15.0f  %+.2f%%\n", "after rendering: the finished image", f, 100 * f / a
  }'
  exit 0
fi

# run_once with|without: prints "RENDER_SECONDS WALL_SECONDS CPU_SECONDS".
run_once() {
  local log="$work/log" start end client=""
  local args=(render "${render[@]}" -o "$work/out.png" --stats)
  [[ "$1" == with ]] && args+=(--preview 0 --preview-linger 0)
  start=$(date +%s.%N)
  /usr/bin/time -f '%U %S' -o "$work/cpu" "$glint" "${args[@]}" 2>"$log" &
  local pid=$!
  [[ "$1" == with ]] && client="$(connect_client "$log")"
  wait "$pid"
  end=$(date +%s.%N)
  [[ -n "$client" ]] && { kill "$client" 2>/dev/null || true; wait "$client" 2>/dev/null || true; }
  local seconds
  seconds="$(sed -nE 's/.*time: .*render ([0-9.]+) (m?s).*/\1 \2/p' "$log")"
  awk -v s="$seconds" -v a="$start" -v b="$end" -v c="$(cat "$work/cpu")" \
    'BEGIN { split(s, p, " "); r = p[2] == "ms" ? p[1] / 1000 : p[1]; split(c, u, " ")
             printf "%.4f %.4f %.4f\n", r, b - a, u[1] + u[2] }'
}

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }

printf 'glint %s; %s; load average %s\n' "$("$glint" --version)" "${render[*]}" "$(cut -d' ' -f1-3 /proc/loadavg)"
run_once without >/dev/null  # warm the caches
for ((i = 1; i <= runs; ++i)); do
  run_once without >>"$work/without"
  run_once with >>"$work/with"
done
render_without="$(cut -d' ' -f1 "$work/without" | median)"
render_with="$(cut -d' ' -f1 "$work/with" | median)"
wall_without="$(cut -d' ' -f2 "$work/without" | median)"
wall_with="$(cut -d' ' -f2 "$work/with" | median)"
cpu_without="$(cut -d' ' -f3 "$work/without" | median)"
cpu_with="$(cut -d' ' -f3 "$work/with" | median)"
printf '%-22s %12s %12s %8s\n' "median of $runs runs" "without" "--preview" "ratio"
awk -v a="$render_without" -v b="$render_with" 'BEGIN { printf "%-22s %11.3fs %11.3fs %8.4f\n", "render phase", a, b, b / a }'
awk -v a="$wall_without" -v b="$wall_with" 'BEGIN { printf "%-22s %11.3fs %11.3fs %8.4f\n", "whole process", a, b, b / a }'
awk -v a="$cpu_without" -v b="$cpu_with" 'BEGIN { printf "%-22s %11.3fs %11.3fs %8.4f\n", "CPU time (all threads)", a, b, b / a }'
printf 'load average at the end: %s\n' "$(cut -d' ' -f1-3 /proc/loadavg)"
