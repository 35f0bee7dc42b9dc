#!/usr/bin/env bash
# SRI-GVINS build entry point. Installs missing Debian packages, configures, builds, then:
#   ./build.sh demo [--images] [--mode M]  simulate the bundled short flight, run gvins-replay on it
#   ./build.sh test        run every test (unit, integration, fuzz-corpus replay)
#   ./build.sh sanitize    build and run the tests again under AddressSanitizer + UBSan
#   ./build.sh fuzz [S]    build the libFuzzer targets with clang and run each for S seconds (default 20)
#   ./build.sh bench       build and run the benchmarks
#   ./build.sh build       only install dependencies and build
# Environment: JOBS (parallel jobs, default: number of cores), BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
JOBS=${JOBS:-$(nproc)}

PACKAGES=(build-essential cmake ninja-build pkg-config
          zlib1g-dev libeigen3-dev libsuitesparse-dev libopencv-dev libyaml-cpp-dev
          libgtest-dev libgmock-dev libbenchmark-dev
          librosbag-storage-dev
          clang libclang-rt-14-dev rtklib)

install_deps() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "== installing missing Debian packages: ${missing[*]}"
  local SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO=sudo
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

configure_build() {  # dir, extra cmake args...
  local dir=$1; shift
  cmake -S "$ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
  cmake --build "$dir" -j "$JOBS"
}

run_tests() {  # dir [ctest args...]
  local dir=$1; shift
  (cd "$dir" && ctest --output-on-failure -j "$JOBS" --timeout 900 "$@")
}

cmd=${1:-demo}
shift || true
case "$cmd" in
  build)
    install_deps
    configure_build "${BUILD_DIR:-build}"
    ;;
  demo)
    install_deps
    # Only the two tools the demo runs (the full build is `./build.sh build` or `test`).
    cmake -S "$ROOT" -B "${BUILD_DIR:-build}" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "${BUILD_DIR:-build}" -j "$JOBS" --target gvins-sim gvins-replay gvins-eval
    exec "$ROOT/apps/demo.sh" "${BUILD_DIR:-build}" "$@"
    ;;
  test)
    install_deps
    configure_build "${BUILD_DIR:-build}"
    run_tests "${BUILD_DIR:-build}"
    ;;
  sanitize)
    install_deps
    # -O1 with assertions on (no NDEBUG): the optimisation level the sanitizers recommend, and
    # half the compile time of -O2 -g. Tests labelled `slow` (long end-to-end runs that only
    # repeat library code the other tests cover) run in the release build only.
    configure_build "${BUILD_DIR:-build-sanitize}" -DGVINS_SANITIZE=ON -DGVINS_BUILD_BENCH=OFF \
      -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1"
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      run_tests "${BUILD_DIR:-build-sanitize}" -LE slow
    ;;
  fuzz)
    install_deps
    secs=${1:-20}
    dir=${BUILD_DIR:-build-fuzz}
    CXX=clang++ CC=clang configure_build "$dir" -DGVINS_FUZZ=ON -DGVINS_BUILD_BENCH=OFF \
      -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1"
    ls "$dir"/fuzz/fuzz_* >/dev/null 2>&1 || { echo "no fuzz targets were built" >&2; exit 1; }
    for f in "$dir"/fuzz/fuzz_*; do
      [ -x "$f" ] || continue
      name=$(basename "$f")
      corpus="$ROOT/tests/data/fuzz/${name#fuzz_}"
      work=$(mktemp -d)
      dict=()
      [ -f "$corpus.dict" ] && dict=(-dict="$corpus.dict")  # the format's keywords and magic bytes
      echo "== $name for ${secs}s (seeds: $corpus)"
      "$f" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "${dict[@]}" \
        "$work" "$corpus" 2>&1 | tail -n 3
      rm -rf "$work"
    done
    ;;
  bench)
    install_deps
    configure_build "${BUILD_DIR:-build}"
    for b in "${BUILD_DIR:-build}"/bench/bench_*; do
      [ -x "$b" ] && "$b" "$@"
    done
    ;;
  *)
    echo "usage: $0 {demo|test|sanitize|fuzz [seconds]|bench|build}" >&2
    exit 2
    ;;
esac
