#!/usr/bin/env bash
# One frame across MPI ranks against one process on the same cores (issue 17; docs/benchmarks.md
# "One frame across MPI ranks"): `mpirun -np 2 glint render --threads 1` against `glint render
# --threads 2`, whole runs (MPI start, load, build, render, write), on the showcase and on the
# 100k-triangle torus of bench/renderer_comparison. Prints the median wall times, their ratio (the
# single process's time over the MPI run's: 1 means as fast), the same ratio of CPU times (user +
# system: what the MPI run costs in extra work, which a busy machine does not distort as much), the
# bytes rank 0 received and sent per frame and rank 0's coordination cost per tile (from --stats;
# medians of the runs), and checks that both wrote the same bytes. Each run's figures go to stderr
# as they come.
#
#   bench/cluster_speed.sh [--runs N] [--build-dir DIR] [--bind core|none]
#
# Needs a build with MPI (build/glint) and the benchmarks (DIR/bench/renderer_comparison writes the
# torus scene). The machine should be otherwise idle: the load average is printed before and after.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
runs=5
build_dir="$ROOT/build"
bind=core
while (($#)); do
  case "$1" in
    --runs) runs="${2:?--runs needs a number}"; shift ;;
    --build-dir) build_dir="$(cd "${2:?--build-dir needs a folder}" && pwd)"; shift ;;
    --bind) bind="${2:?--bind needs core or none}"; shift ;;
    -h | --help) sed -n '2,16s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) printf 'cluster_speed: unknown argument %s\n' "$1" >&2; exit 2 ;;
  esac
  shift
done

glint="$build_dir/glint"
work="$build_dir/bench-results/cluster_speed"
mkdir -p "$work"
"$build_dir/bench/renderer_comparison" --generate-only --out "$work/scenes" >/dev/null
# As root (a container) OpenMPI needs --allow-run-as-root; shared memory between the two ranks.
mpirun=(mpirun --allow-run-as-root --bind-to "$bind" --mca btl "self,vader"
  --mca btl_vader_single_copy_mechanism none -np 2)

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
# Runs "$@" once; sets wall and cpu to its wall time and the CPU time (user + system) of it and its
# children, in seconds. mpirun starts the ranks of one machine as its children, so theirs is counted.
timed() {
  /usr/bin/time -f '%e %U %S' -o "$work/time" "$@" || { echo "cluster_speed: failed: $*" >&2; exit 1; }
  read -r wall cpu < <(awk '{ printf "%s %.2f\n", $1, $2 + $3 }' "$work/time")
}

printf 'load average before: %s\n\n' "$(cut -d' ' -f1-3 /proc/loadavg)"
printf '| scene | one process, --threads 2 | mpirun -np 2, --threads 1 | speed ratio (wall) | CPU time, one process / MPI | bytes per frame (received / sent by rank 0) | rank 0 per remote tile: handling + MPI (CPU) | rank 0 link thread |\n'
printf '|---|---|---|---|---|---|---|---|\n'
scenes=("$ROOT/scenes/showcase.yaml" "$work/scenes/torus100k.yaml")
names=("showcase 1280x720, 4-16 spp adaptive" "torus 100k triangles, 1024x768, 16 spp")
extras=("" "--samples 16")
for i in "${!scenes[@]}"; do
  scene="${scenes[$i]}"
  read -r -a extra <<<"${extras[$i]}"
  plain_wall=() plain_cpu=() mpi_wall=() mpi_cpu=() handling=() messaging=() link=()
  # Alternating, so a change in the machine's load falls on both.
  for ((run = 0; run < runs; ++run)); do
    timed "$glint" render "$scene" "${extra[@]}" --threads 2 -o "$work/plain.png" --quiet
    plain_wall+=("$wall") plain_cpu+=("$cpu")
    timed "${mpirun[@]}" "$glint" render "$scene" "${extra[@]}" --threads 1 -o "$work/mpi.png" \
      --stats 2>"$work/mpi.log"
    mpi_wall+=("$wall") mpi_cpu+=("$cpu")
    # Rank 0's figures (--stats): per tile from another rank, CPU us of handling and of MPI calls;
    # its link thread's share of a core.
    read -r h m l < <(sed -nE 's/.*per tile from another rank ([0-9.]+) us handling and ([0-9.]+) us in MPI \(CPU\); its link thread used ([0-9.]+)% of a core.*/\1 \2 \3/p' "$work/mpi.log")
    handling+=("$h") messaging+=("$m") link+=("$l")
    cmp -s "$work/plain.png" "$work/mpi.png" || { echo "cluster_speed: the images differ" >&2; exit 1; }
    printf '%s run %d: one process %s s (CPU %s s), mpirun %s s (CPU %s s; rank 0 per tile %s + %s us, link %s%%), load %s\n' \
      "$(basename "$scene")" "$run" "${plain_wall[-1]}" "${plain_cpu[-1]}" "${mpi_wall[-1]}" \
      "${mpi_cpu[-1]}" "$h" "$m" "$l" "$(cut -d' ' -f1 /proc/loadavg)" >&2
  done
  pw=$(printf '%s\n' "${plain_wall[@]}" | median)
  pc=$(printf '%s\n' "${plain_cpu[@]}" | median)
  mw=$(printf '%s\n' "${mpi_wall[@]}" | median)
  mc=$(printf '%s\n' "${mpi_cpu[@]}" | median)
  traffic=$(grep -o 'rank 0 received [0-9.]* [KMGi]*B and sent [0-9.]* [KMGi]*B' "$work/mpi.log" |
    sed -E 's/rank 0 received (.*) and sent (.*)/\1 \/ \2/')
  per_tile="$(printf '%s\n' "${handling[@]}" | median) + $(printf '%s\n' "${messaging[@]}" | median) us"
  link_share="$(printf '%s\n' "${link[@]}" | median)% of a core"
  printf '| %s | %.2f s (CPU %.1f s) | %.2f s (CPU %.1f s) | %.3f | %.3f | %s | %s | %s |\n' \
    "${names[$i]}" "$pw" "$pc" "$mw" "$mc" "$(echo "$pw / $mw" | bc -l)" \
    "$(echo "$pc / $mc" | bc -l)" "$traffic" "$per_tile" "$link_share"
done
printf '\nload average after: %s\n' "$(cut -d' ' -f1-3 /proc/loadavg)"
