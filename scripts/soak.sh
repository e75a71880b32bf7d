#!/usr/bin/env bash
# Soak test (not a unit test): tries to break glint for a while, in three phases that share the time:
#
# 1. renders: the scenes in scenes/ again and again, small, with random --threads, random --crop and
#    random SIGINT, checked against DESIGN.md §6/§7:
#      - a completed render (exit 0) is byte-identical to a clean render of the scene at the same
#        size (one thread), or for a --crop render to the same region of it;
#      - an interrupted render (exit 130) left nothing behind: no output and no temporary file;
#      - any other exit code is a failure.
#    It reports the peak RSS of every run (GNU time) and, per scene, how it changes from the first
#    runs to the last (a leak in a long-lived process shows there as growth).
# 2. signals: SIGINT, SIGTERM or SIGHUP at a random moment while glint reads a large generated scene
#    file, reads a large generated mesh file, or writes a large image: the run must end within a
#    second of the signal with exit 130 / 143 / 129 (or 0 if it finished first, with a complete
#    output) and leave nothing behind.
# 3. mutations: every scene in scenes/ mutated at random (lines deleted, duplicated or swapped,
#    numbers replaced by extreme ones, characters flipped to random bytes) and checked with
#    `glint check`: exit 0 or 2 only (no crash, no hang: 20 s at most), every error line names the
#    file and a line:column (or only the file for file-level problems), and no message holds a raw
#    control character.
#
#   scripts/soak.sh [--minutes M | --iterations N] [--width W] [--binary PATH] [--seed S]
#                   [--scene NAME]... [--phases render,signals,mutations]
#
# Defaults: --minutes 5 (split between the phases), --width 160 (keeps each render well under a few
# seconds), --binary build/glint (scripts/build.sh builds it), --seed from the clock (printed, so a
# run can be repeated), every scenes/*.yaml, all three phases. With --iterations N each phase runs N
# times. Work files go to a temporary folder, removed at the end. Exit 0 when every run passed, 1
# otherwise.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

usage() { sed -n '2,31s/^# \{0,1\}//p' "${BASH_SOURCE[0]}" >&2; }
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
phases=render,signals,mutations
while (($#)); do
  case "$1" in
    --minutes) minutes="${2:?}"; shift ;;
    --iterations) iterations="${2:?}"; shift ;;
    --width) width="${2:?}"; shift ;;
    --binary) binary="${2:?}"; shift ;;
    --seed) seed="${2:?}"; shift ;;
    --scene) only+=("${2:?}"); shift ;;
    --phases) phases="${2:?}"; shift ;;
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

has_phase() { [[ ",$phases," == *",$1,"* ]]; }
phase_count=0
for phase in render signals mutations; do has_phase "$phase" && phase_count=$((phase_count + 1)); done
((phase_count > 0)) || die "--phases takes render, signals and/or mutations"
# Seconds each phase may take.
total_seconds=$((${minutes%.*} * 60))
[[ "$minutes" == *.* ]] && total_seconds=$((total_seconds + (10#${minutes#*.} * 6)))
phase_seconds=$((total_seconds / phase_count))
# phase_left RUNS DEADLINE: whether a phase that has made RUNS runs may go on.
phase_left() {
  if ((iterations)); then (($1 < iterations)); else ((SECONDS < $2)); fi
}

declare -A rss_list
failures=0
runs=0
completed=0
interrupted=0
crops=0
deadline=$((SECONDS + phase_seconds))

while has_phase render; do
  phase_left "$runs" "$deadline" || break
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

printf '\nsoak: renders: %d runs: %d completed (%d cropped), %d interrupted, %d failed\n' "$runs" \
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

# ---- 2. signals while reading a scene, reading a mesh, writing an image -------------------------

signal_runs=0
signal_latency_ms=0
signal_counts=""
if has_phase signals; then
  heavy="$work/heavy"
  mkdir -p "$heavy"
  # A scene of 250,000 spheres (~24 MB of YAML), a mesh of ~1 million triangles (a 700 × 700 grid
  # OBJ), and a large image of the first scene: each takes a second or more here.
  python3 - "$heavy" <<'PY'
import sys
d = sys.argv[1]
head = ("camera: {position: [0, 0, 10], look_at: [0, 0, 0], fov: 40}\n"
        "image: {width: 8, height: 8}\nambient: {color: [1, 1, 1]}\n")
with open(f"{d}/spheres.yaml", "w") as f:
    f.write(head + "objects:\n")
    for i in range(250000):
        f.write(f"  - {{type: sphere, center: [{i % 500 * 0.02:.3f}, {i // 500 * 0.02:.3f}, -1.5], "
                f"radius: 0.01}}\n")
n = 700
with open(f"{d}/grid.obj", "w") as f:
    for y in range(n):
        for x in range(n):
            f.write(f"v {x / n:.5f} {y / n:.5f} {(x * y % 7) * 0.001:.4f}\n")
    for y in range(n - 1):
        for x in range(n - 1):
            a = y * n + x + 1
            f.write(f"f {a} {a + 1} {a + n}\nf {a + 1} {a + n + 1} {a + n}\n")
with open(f"{d}/mesh.yaml", "w") as f:
    f.write(head + "objects:\n  - {type: mesh, file: grid.obj}\n")
PY
  workloads=(parse mesh write)
  # workload_args NAME: the command of a workload.
  workload_args() {
    case "$1" in
      parse) echo "render $heavy/spheres.yaml --quiet" ;;
      mesh) echo "render $heavy/mesh.yaml --quiet" ;;
      write) echo "render scenes/first-scene.yaml --width 4000 --quiet" ;;
    esac
  }
  # How long each workload takes uninterrupted, in ms: signals go at a random moment inside it.
  declare -A workload_ms
  for workload in "${workloads[@]}"; do
    start_ms=$(date +%s%3N)
    # shellcheck disable=SC2046
    "$binary" $(workload_args "$workload") -o "$heavy/clean.exr" >/dev/null 2>&1 ||
      die "the $workload workload fails without a signal"
    workload_ms[$workload]=$(($(date +%s%3N) - start_ms))
    printf 'soak: signals: %-5s workload takes %s ms\n' "$workload" "${workload_ms[$workload]}"
  done
  deadline=$((SECONDS + phase_seconds))
  declare -A exit_of=([INT]=130 [TERM]=143 [HUP]=129)
  while phase_left "$signal_runs" "$deadline"; do
    signal_runs=$((signal_runs + 1))
    workload="${workloads[RANDOM % ${#workloads[@]}]}"
    signal=(INT TERM HUP)
    signal="${signal[RANDOM % 3]}"
    after_ms=$((20 + RANDOM % (workload_ms[$workload] + 1)))
    rm -rf "$work/run"
    mkdir -p "$work/run"
    out="$work/run/out.exr"
    # shellcheck disable=SC2046
    "$binary" $(workload_args "$workload") -o "$out" >/dev/null 2>"$work/stderr" &
    pid=$!
    sleep "$(printf '%d.%03d' $((after_ms / 1000)) $((after_ms % 1000)))"
    sent_ms=$(date +%s%3N)
    kill -"$signal" "$pid" 2>/dev/null || true
    status=0
    wait "$pid" || status=$?
    latency=$(($(date +%s%3N) - sent_ms))
    verdict=ok
    if ((status == 0)); then
      [[ -f "$out" ]] || verdict="FAIL: exit 0 but no output"
    elif ((status == exit_of[$signal])); then
      ((latency > signal_latency_ms)) && signal_latency_ms=$latency
      ((latency <= 1500)) || verdict="FAIL: stopped ${latency} ms after the signal"
      left="$(find "$work/run" -mindepth 1 -printf '%f ' 2>/dev/null)"
      [[ -z "$left" ]] || verdict="FAIL: interrupted, but left: $left"
    else
      verdict="FAIL: exit $status after SIG$signal: $(head -c 300 "$work/stderr" | tr '\n' ' ')"
    fi
    signal_counts+="$status "
    [[ "$verdict" == ok ]] || failures=$((failures + 1))
    printf 'soak: signal %4d %-6s SIG%-4s at %5d ms  exit %3s after %4d ms  %s\n' "$signal_runs" \
      "$workload" "$signal" "$after_ms" "$status" "$latency" "$verdict"
  done
  printf '\nsoak: signals: %d runs, exits %s; slowest stop %d ms after the signal\n' \
    "$signal_runs" "$(tr ' ' '\n' <<<"$signal_counts" | sort | uniq -c | awk 'NF{printf "%s×%s ", $1, $2}')" \
    "$signal_latency_ms"
fi

# ---- 3. mutated scenes through `glint check` ----------------------------------------------------

mutation_runs=0
if has_phase mutations; then
  mutated="$work/mutated"
  mkdir -p "$mutated"
  ln -s "$ROOT/scenes/meshes" "$mutated/meshes"
  cat >"$work/mutate.py" <<'PY'
import random, re, sys
seed, source, target = int(sys.argv[1]), sys.argv[2], sys.argv[3]
r = random.Random(seed)
lines = open(source, "rb").read().split(b"\n")
extremes = [b"1e308", b"-1e308", b"1e-320", b"0", b"-0", b"1e999", b".nan", b".inf", b"-.inf",
            b"99999999999999999999", b"-1", b"65536", b"4294967296", b"0.0000001", b"1e-400"]
done = []
for _ in range(r.randint(1, 3)):
    kind = r.choice(["delete", "duplicate", "swap", "number", "flip"])
    i = r.randrange(len(lines))
    if kind == "delete" and len(lines) > 1:
        del lines[i]
    elif kind == "duplicate":
        lines.insert(i, lines[i])
    elif kind == "swap":
        j = r.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif kind == "number":
        numbers = [(k, m) for k, line in enumerate(lines)
                   for m in re.finditer(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?", line)]
        if numbers:
            k, m = r.choice(numbers)
            lines[k] = lines[k][:m.start()] + r.choice(extremes) + lines[k][m.end():]
    else:
        text = b"\n".join(lines)
        p = r.randrange(len(text))
        text = text[:p] + bytes([r.randrange(256)]) + text[p + 1:]
        lines = text.split(b"\n")
    done.append(kind)
open(target, "wb").write(b"\n".join(lines))
print(" ".join(done))
PY
  cat >"$work/judge.py" <<'PY'
import re, sys
name, status = sys.argv[1], int(sys.argv[2])
err = open(sys.argv[3], "rb").read()
problems = []
if status not in (0, 2):
    problems.append(f"exit {status}")
raw = [c for c in err if (c < 0x20 and c != 0x0A) or c == 0x7F]
if raw:
    problems.append(f"raw control character 0x{raw[0]:02x} in a message")
placed = filed = 0
for line in err.decode("utf-8", "replace").splitlines():
    if re.match(re.escape(name) + r":\d+:\d+: ", line):
        placed += 1
    elif line.startswith(name + ": "):
        filed += 1
    else:
        problems.append(f"a line naming no file: {line[:120]!r}")
if status == 2 and placed + filed == 0:
    problems.append("exit 2 without an error naming the file")
print(f"{placed} {filed} " + ("; ".join(problems) if problems else "ok"))
PY
  deadline=$((SECONDS + phase_seconds))
  placed_total=0
  filed_total=0
  exit0=0
  exit2=0
  scenes_all=(scenes/*.yaml)
  while phase_left "$mutation_runs" "$deadline"; do
    mutation_runs=$((mutation_runs + 1))
    scene="${scenes_all[RANDOM % ${#scenes_all[@]}]}"
    target="$mutated/$(basename "$scene")"
    kinds="$(python3 "$work/mutate.py" "$((seed + mutation_runs))" "$scene" "$target")"
    status=0
    timeout 20 "$binary" check "$target" >/dev/null 2>"$work/stderr" || status=$?
    read -r placed filed verdict < <(python3 "$work/judge.py" "$target" "$status" "$work/stderr")
    placed_total=$((placed_total + placed))
    filed_total=$((filed_total + filed))
    ((status == 0)) && exit0=$((exit0 + 1))
    ((status == 2)) && exit2=$((exit2 + 1))
    if [[ "$verdict" != ok ]]; then
      failures=$((failures + 1))
      cp "$target" "${TMPDIR:-/tmp}/glint-soak-failure-$mutation_runs.yaml" 2>/dev/null || true
      printf 'soak: mutation %4d %-28s (%s) FAIL: %s (kept as ${TMPDIR:-/tmp}/glint-soak-failure-%d.yaml)\n' \
        "$mutation_runs" "$(basename "$scene")" "$kinds" "$verdict" "$mutation_runs"
    fi
  done
  printf '\nsoak: mutations: %d mutated scenes: %d exit 0, %d exit 2; %d error lines at file:line:col, %d naming only the file\n' \
    "$mutation_runs" "$exit0" "$exit2" "$placed_total" "$filed_total"
fi

printf '\nsoak: %d failures in all\n' "$failures"
((failures == 0))
