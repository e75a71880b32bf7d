#!/usr/bin/env bash
# Soak test (not a unit test): renders the scenes in scenes/ again and again, small, with random
# --threads, random --crop and random SIGINT interrupts, and checks every run against DESIGN.md §6/§7:
#   - a completed render (exit 0) is byte-identical to a clean render of the scene at the same
#     size (one thread), or for a --crop render to the same region of it (a crop writes only the
#     region);
#   - an interrupted render (exit 130) left nothing behind: no output and no temporary file in
#     the output folder;
#   - any other exit code is a failure.
# It reports the peak RSS of every run (GNU time) and, per scene, how it changes from the first
# runs to the last (a leak in a long-lived process shows there as growth).
#
#   scripts/soak.sh [--minutes M | --iterations N] [--width W] [--binary PATH] [--seed S]
#                   [--scene NAME]...
#
# Defaults: --minutes 5, --width 160 (keeps each render well under a few seconds), --binary
# build/glint (scripts/build.sh builds it), --seed from the clock (printed, so a run can be
# repeated), every scenes/*.yaml. Work files go to a temporary folder, removed at the end. Exit 0
# when every run passed, 1 otherwise.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

usage() { sed -n '2,20s/^# \{0,1\}//p' "${BASH_SOURCE[0]}" >&2; }
die() {
  printf 'soak: error: %s\n' "$*" >&2
  exit 1
}

minutes=5
iterations=0
width=160
binary=build/glint
seed="$(date +%s)"
only=()
while (($#)); do
  case "$1" in
    --minutes) minutes="${2:?}"; shift ;;
    --iterations) iterations="${2:?}"; shift ;;
    --width) width="${2:?}"; shift ;;
    --binary) binary="${2:?}"; shift ;;
    --seed) seed="${2:?}"; shift ;;
    --scene) only+=("${2:?}"); shift ;;
    -h | --help) usage; exit 0 ;;
    *) usage; die "unknown argument '$1'" ;;
  esac
  shift
done
[[ "$minutes" =~ ^[0-9]+(\.[0-9]+)?$ && "$iterations" =~ ^[0-9]+$ && "$width" =~ ^[0-9]+$ ]] ||
  die "--minutes, --iterations and --width take numbers"
[[ -x "$binary" ]] || die "no glint binary at $binary (build it with scripts/build.sh, or pass --binary)"
[[ -x /usr/bin/time ]] || die "GNU time (/usr/bin/time) is needed for the peak RSS (apt-get install time)"
command -v python3 >/dev/null || die "python3 is needed to compare images"
RANDOM=$((seed % 32768))
cores="$(nproc)"

scenes=()
if ((${#only[@]})); then
  for name in "${only[@]}"; do scenes+=("scenes/${name%.yaml}.yaml"); done
else
  for scene in scenes/*.yaml; do scenes+=("$scene"); done
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/glint-soak.XXXXXX")"
cleanup() { rm -rf "$work"; }
trap cleanup EXIT

# compare.py FULL CANDIDATE [X0 Y0 X1 Y1]: exit 0 when CANDIDATE (binary PPM) equals FULL, or the
# region [X0, X1) × [Y0, Y1) of FULL; prints the first difference otherwise. compare.py FULL alone
# prints the image's width and height.
cat >"$work/compare.py" <<'EOF'
import sys

def read_ppm(path):
    data = open(path, "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    pos += 1  # the single whitespace after maxval
    assert fields[0] == b"P6" and fields[3] == b"255", f"{path}: not an 8-bit binary PPM"
    w, h = int(fields[1]), int(fields[2])
    pixels = data[pos:pos + 3 * w * h]
    assert len(pixels) == 3 * w * h, f"{path}: truncated"
    return w, h, pixels

fw, fh, full = read_ppm(sys.argv[1])
if len(sys.argv) == 2:  # compare.py IMAGE: print its width and height
    sys.exit(print(fw, fh))
cw, ch, cand = read_ppm(sys.argv[2])
x0, y0, x1, y1 = map(int, sys.argv[3:7]) if len(sys.argv) > 3 else (0, 0, fw, fh)
if (cw, ch) != (x1 - x0, y1 - y0):
    sys.exit(print(f"size {cw}x{ch}, expected {x1 - x0}x{y1 - y0}") or 1)
for y in range(ch):
    want = full[3 * ((y0 + y) * fw + x0):3 * ((y0 + y) * fw + x1)]
    got = cand[3 * y * cw:3 * (y + 1) * cw]
    if want != got:
        x = next(i for i in range(len(got)) if got[i] != want[i]) // 3
        sys.exit(print(f"first difference at pixel ({x0 + x}, {y0 + y})") or 1)
EOF

# run_glint LOG ARGS...: runs glint under GNU time (its report goes to LOG) and sets `status`.
# With `interrupt_after` non-empty, SIGINT goes to glint (not to time) after that many seconds.
run_glint() {
  local log="$1"
  shift
  /usr/bin/time -v -o "$log" "$binary" "$@" >"$work/stdout" 2>"$work/stderr" &
  local timer=$!
  if [[ -n "$interrupt_after" ]]; then
    sleep "$interrupt_after"
    local child
    child="$(ps -o pid= --ppid "$timer" 2>/dev/null | tr -d ' ' || true)"
    [[ -n "$child" ]] && kill -INT "$child" 2>/dev/null || true
  fi
  status=0
  wait "$timer" || status=$?
  # GNU time reports a child killed by a signal as "Command terminated by signal N" and exits
  # 128 + N; a child that handled SIGINT and exited 130 comes back as 130 either way.
}

peak_kb() { sed -n 's/^[[:space:]]*Maximum resident set size (kbytes): //p' "$1"; }

printf 'soak: %s, width %s, seed %s, %s, %s scenes, binary %s\n' "$(date -u +%H:%M:%SZ)" "$width" \
  "$seed" "$( ((iterations)) && echo "$iterations iterations" || echo "$minutes minutes")" \
  "${#scenes[@]}" "$binary"

# Clean renders: one thread, the whole image.
declare -A clean_w clean_h
usable=()
interrupt_after=""
mkdir -p "$work/clean"
for scene in "${scenes[@]}"; do
  name="$(basename "$scene" .yaml)"
  run_glint "$work/clean/$name.time" render "$scene" --width "$width" --threads 1 --quiet \
    -o "$work/clean/$name.ppm"
  if ((status != 0)); then
    printf 'soak: %s: the clean render failed (exit %s): %s\n' "$name" "$status" \
      "$(head -c 300 "$work/stderr")"
    continue
  fi
  read -r w h < <(python3 "$work/compare.py" "$work/clean/$name.ppm") || true
  clean_w[$name]=$w
  clean_h[$name]=$h
  usable+=("$scene")
  printf 'soak: clean %-24s %sx%s, peak RSS %s MiB\n' "$name" "$w" "$h" \
    "$(($(peak_kb "$work/clean/$name.time") / 1024))"
done
((${#usable[@]})) || die "no scene rendered cleanly"

declare -A rss_list
failures=0
runs=0
completed=0
interrupted=0
crops=0
deadline=$((SECONDS + ${minutes%.*} * 60))
[[ "$minutes" == *.* ]] && deadline=$((deadline + (10#${minutes#*.} * 6)))

while :; do
  if ((iterations)); then ((runs < iterations)) || break; else ((SECONDS < deadline)) || break; fi
  runs=$((runs + 1))
  scene="${usable[RANDOM % ${#usable[@]}]}"
  name="$(basename "$scene" .yaml)"
  w=${clean_w[$name]}
  h=${clean_h[$name]}
  threads=$((1 + RANDOM % (2 * cores)))
  args=(render "$scene" --width "$w" --threads "$threads" --quiet)
  crop=()
  if ((RANDOM % 2)); then
    x0=$((RANDOM % w)); x1=$((x0 + 1 + RANDOM % (w - x0)))
    y0=$((RANDOM % h)); y1=$((y0 + 1 + RANDOM % (h - y0)))
    crop=("$x0" "$y0" "$x1" "$y1")
    args+=(--crop "$x0,$y0,$x1,$y1")
  fi
  interrupt_after=""
  # A third of the runs get SIGINT after 0.01–0.6 s (some finish first: those count as complete).
  ((RANDOM % 3 == 0)) && interrupt_after="$(printf '0.%02d' $((1 + RANDOM % 60)))"
  out="$work/run/out.ppm"
  rm -rf "$work/run"
  mkdir -p "$work/run"
  run_glint "$work/time.log" "${args[@]}" -o "$out"
  rss=$(($(peak_kb "$work/time.log") / 1024))
  rss_list[$name]+="$rss "
  what="$name threads=$threads${crop:+ crop=${crop[*]}}${interrupt_after:+ SIGINT@${interrupt_after}s}"
  verdict=ok
  case "$status" in
    0)
      completed=$((completed + 1))
      ((${#crop[@]})) && crops=$((crops + 1))
      if [[ ! -f "$out" ]]; then
        verdict="FAIL: exit 0 but no output"
      elif ! diff_text="$(python3 "$work/compare.py" "$work/clean/$name.ppm" "$out" "${crop[@]}")"; then
        verdict="FAIL: differs from the clean render: $diff_text"
      fi
      ;;
    130)
      interrupted=$((interrupted + 1))
      left="$(find "$work/run" -mindepth 1 -printf '%f ' 2>/dev/null)"
      [[ -z "$left" ]] || verdict="FAIL: interrupted, but left: $left"
      ;;
    *) verdict="FAIL: exit $status: $(head -c 300 "$work/stderr" | tr '\n' ' ')" ;;
  esac
  # Temporary files must not appear next to the output in any case.
  extra="$(find "$work/run" -mindepth 1 ! -name out.ppm -printf '%f ' 2>/dev/null)"
  [[ -z "$extra" || "$verdict" != ok ]] || verdict="FAIL: left behind: $extra"
  [[ "$verdict" == ok ]] || failures=$((failures + 1))
  printf 'soak: run %4d %-60s exit %3s  peak %4s MiB  %s\n' "$runs" "$what" "$status" "$rss" \
    "$verdict"
done

printf '\nsoak: %d runs: %d completed (%d cropped), %d interrupted, %d failed\n' "$runs" \
  "$completed" "$crops" "$interrupted" "$failures"
printf 'soak: peak RSS per scene in MiB (runs; min / median / max; mean of the first and last third)\n'
for scene in "${usable[@]}"; do
  name="$(basename "$scene" .yaml)"
  [[ -n "${rss_list[$name]:-}" ]] || continue
  python3 - "$name" ${rss_list[$name]} <<'EOF'
import statistics, sys
name, values = sys.argv[1], [int(v) for v in sys.argv[2:]]
third = max(1, len(values) // 3)
first, last = statistics.mean(values[:third]), statistics.mean(values[-third:])
print(f"  {name:24s} {len(values):4d} runs; {min(values)} / {statistics.median(values):.0f} / "
      f"{max(values)}; first {first:.0f} -> last {last:.0f} ({last - first:+.0f})")
EOF
done
((failures == 0))
