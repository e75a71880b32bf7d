#!/usr/bin/env bash
# One-command set-up for glint on Debian 12 (as root, or as a user with sudo).
#
#   scripts/setup.sh render   install dependencies, build Release, render scenes/showcase.yaml
#                             to ./showcase.png (in the current folder)
#   scripts/setup.sh test     install dependencies and the test browser (Chromium, chromedriver,
#                             Selenium), build Release, run every test (ctest)
#   scripts/setup.sh deps     only install the dependencies (the default with no command)
#   scripts/setup.sh build    install dependencies and build Release (build/, binary build/glint)
#   scripts/setup.sh bench    also install Embree, Tachyon and POV-Ray; build Release with the
#                             benchmarks (-DGLINT_BUILD_BENCH=ON) and run them (scripts/bench.sh)
#
# Options (any command):
#   --with-fuzz   also install clang and its libFuzzer/sanitizer runtime (scripts/fuzz.sh)
#   --no-deps     skip the package check (dependencies installed some other way)
#
# Every dependency is a Debian package; nothing is downloaded at build time. The package step is
# idempotent: when every package is already installed it runs no apt-get at all (and needs no root).
# Environment: GLINT_JOBS (build jobs, default 2).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

# What the Release build and the whole test suite need (CMakeLists.txt's find_package calls; the mesh
# tests read Debian's assimp-testmodels; OpenMPI for rendering across processes and its mpirun tests;
# `file` is for CPack's dpkg-shlibdeps step, which the .deb test runs: tests/deb_package_test.sh).
PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libyaml-dev libpng-dev libjpeg62-turbo-dev libopenexr-dev libtbb-dev libcli11-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libassimp-dev assimp-testmodels
  libopenmpi-dev openmpi-bin
  libcpp-httplib-dev file
)
# The tests beyond the build: the preview page in headless Chromium through WebDriver
# (tests/browser/, ctest preview_browser: skipped without them, but a failure under CI=true).
TEST_PACKAGES=(chromium chromium-driver python3-selenium)
# clang with its compiler-rt (libFuzzer, ASan, UBSan runtimes) for the fuzz targets.
FUZZ_PACKAGES=(clang libclang-rt-14-dev)
# The benchmarks' references: Embree 3 (linked by bench/ only), the Tachyon and POV-Ray renderers;
# python3 for bench/spd_bench.sh's NFF-to-Tachyon converter and image comparison; matplotlib draws
# the benchmark plots in docs/images/ (scripts/plot_benchmarks.py).
BENCH_PACKAGES=(libembree-dev libbenchmark-dev tachyon povray python3 python3-matplotlib)

log() { printf 'setup: %s\n' "$*" >&2; }
die() {
  printf 'setup: error: %s\n' "$*" >&2
  exit 1
}

usage() { sed -n '2,20s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"; }

command_name=deps
with_fuzz=0
install_deps=1
for arg in "$@"; do
  case "$arg" in
    render | test | deps | build | bench) command_name="$arg" ;;
    --with-fuzz) with_fuzz=1 ;;
    --no-deps) install_deps=0 ;;
    -h | --help)
      usage
      exit 0
      ;;
    *)
      usage >&2
      die "unknown argument '$arg'"
      ;;
  esac
done

wanted_packages() {
  local packages=("${PACKAGES[@]}")
  ((with_fuzz)) && packages+=("${FUZZ_PACKAGES[@]}")
  [[ "$command_name" == bench ]] && packages+=("${BENCH_PACKAGES[@]}")
  [[ "$command_name" == test ]] && packages+=("${TEST_PACKAGES[@]}")
  printf '%s\n' "${packages[@]}"
}

missing_packages() {
  local package
  while read -r package; do
    # "ii" = wanted install, currently installed; anything else (absent, half-installed) is missing.
    if [[ "$(dpkg-query -W -f='${db:Status-Abbrev}' "$package" 2>/dev/null)" != ii* ]]; then
      printf '%s\n' "$package"
    fi
  done < <(wanted_packages)
}

install_packages() {
  if ! command -v apt-get >/dev/null || ! command -v dpkg-query >/dev/null; then
    die "this script needs Debian 12 (apt-get and dpkg-query not found)"
  fi
  local missing
  mapfile -t missing < <(missing_packages)
  if ((${#missing[@]} == 0)); then
    log "all $(wanted_packages | wc -l) Debian packages already installed"
    return
  fi
  log "installing: ${missing[*]}"

  local as_root=()
  if ((EUID != 0)); then
    command -v sudo >/dev/null ||
      die "missing packages (${missing[*]}); run this script as root, or install sudo"
    # Without a terminal sudo cannot ask for a password: fail at once rather than hang.
    if [[ -t 0 ]]; then as_root=(sudo); else as_root=(sudo -n); fi
    log "not root: using ${as_root[*]} for apt-get"
  fi
  # Wait for a concurrent apt/dpkg (another installer, unattended-upgrades) instead of failing.
  local apt=("${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -q
    -o DPkg::Lock::Timeout=600 -o Acquire::Retries=3)
  "${apt[@]}" update
  "${apt[@]}" install -y --no-install-recommends "${missing[@]}"

  mapfile -t missing < <(missing_packages)
  ((${#missing[@]} == 0)) || die "still not installed after apt-get: ${missing[*]}"
}

build_release() {
  bash "$ROOT/scripts/build.sh" release "$@"
}

render_showcase() {
  local scene="$ROOT/scenes/showcase.yaml" binary="$ROOT/build/glint" output="$PWD/showcase.png"
  [[ -f "$scene" ]] ||
    die "the build succeeded, but $scene does not exist yet (the showcase scene is still being written)"
  [[ -x "$binary" ]] ||
    die "the build succeeded, but produced no $binary (the command-line program is not in the tree yet)"
  log "rendering scenes/showcase.yaml -> $output"
  "$binary" render "$scene" -o "$output"
  log "wrote $output"
}

((install_deps)) && install_packages
case "$command_name" in
  deps) ;;
  build) build_release ;;
  render)
    build_release
    render_showcase
    ;;
  test) build_release --test ;;
  bench) bash "$ROOT/scripts/bench.sh" ;;
esac
