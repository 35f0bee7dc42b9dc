#!/usr/bin/env bash
# Whole-pipeline speed of gvins-replay on a stereo EuRoC sequence (752x480 at 20 Hz + 200 Hz IMU):
# runs it RUNS times and prints the real-time factor (dataset span / wall time) of each run, the
# median, and whether it meets the >= 5x target. CPU time is printed too: on a shared machine the
# wall time includes waiting for a core.
#
#   bench/fusion/bench_replay.sh [BUILD_DIR] [DATASET] [RUNS] [MODE]
#   defaults: build, tests/data/euroc/v101_static_stereo (1.15 s clip), 3, vio
# For a meaningful number use a full sequence, e.g. EuRoC V1_01_easy extracted to a folder
# (https://projects.asl.ethz.ch/datasets/, ASL format).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${1:-build}
DATASET=${2:-$ROOT/tests/data/euroc/v101_static_stereo}
RUNS=${3:-3}
MODE=${4:-vio}
REPLAY="$ROOT/$BUILD/bin/gvins-replay"
[ -x "$REPLAY" ] || { echo "gvins-replay not built: $REPLAY" >&2; exit 1; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
rtfs=()
printf '%-5s %10s %10s %8s\n' run wall_s cpu_s rtf
for i in $(seq 1 "$RUNS"); do
  start=$(date +%s.%N)
  /usr/bin/time -f '%U %S' -o "$TMP/time" "$REPLAY" "$DATASET" --mode "$MODE" -q --no-eval -o "$TMP/out" > "$TMP/log"
  end=$(date +%s.%N)
  rtf=$(sed -n 's/^real-time factor *\([0-9.]*\)x/\1/p' "$TMP/log")
  cpu=$(awk '{print $1+$2}' "$TMP/time")
  printf '%-5s %10.2f %10.2f %8s\n' "$i" "$(echo "$end - $start" | bc)" "$cpu" "$rtf"
  rtfs+=("$rtf")
done
median=$(printf '%s\n' "${rtfs[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
grep -E '^(frames|front end|estimator|dataset)' "$TMP/log" || true
echo "median real-time factor: ${median}x (target >= 5x): $(awk -v m="$median" 'BEGIN {print (m >= 5 ? "PASS" : "FAIL")}')"
