#!/usr/bin/env bash
# What the GNSS fusion adds to the estimator time (the paper's Table III: +13.77 % for
# VIO+Dopp+Dpsr over VIO), measured so that a drifting or shared host does not decide it: the VIO
# run and the GNSS run go at the same time, each pinned to its own core (taskset), and swap cores
# every round; each round gives the ratio (estimator + GNSS ms per frame) / (VIO estimator ms per
# frame) of two runs that saw the same machine. Prints every round and the median per mode.
#
#   bench/fusion/gnss_time_share.sh DATASET [ROUNDS] [BUILD_DIR] [MODES]
#   defaults: 4 rounds, build, "vio+dopp+psr vio+dopp+dpsr vio+dopp+ddcp"
# DATASET: a gvins-sim flight with GNSS (e.g. bench/fusion/paper_tables.sh's data/uav_60m_1000m_6mps).
# Needs two cores; with one, the runs go one after the other (then host drift enters the ratios).
# Each round writes to output directories of another name length: the path's length moves the
# process's stack, and a replay's estimator time moved by several % with it (memory layout, not
# work: docs/sri_core.md §10, "Buffer alignment"), so the rounds sample layouts instead of
# repeating one.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
DATASET=${1:?usage: gnss_time_share.sh DATASET [ROUNDS] [BUILD_DIR] [MODES]}
ROUNDS=${2:-4}
BUILD=${3:-build}
MODES=${4:-vio+dopp+psr vio+dopp+dpsr vio+dopp+ddcp}
case "$BUILD" in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
REPLAY=$BUILD/bin/gvins-replay
[ -x "$REPLAY" ] || { echo "gnss_time_share.sh: $REPLAY not built" >&2; exit 1; }
[ -f "$DATASET/dataset.yaml" ] || { echo "gnss_time_share.sh: $DATASET is not a gvins-sim dataset" >&2; exit 1; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
PAIRED=0
if [ "$(nproc)" -ge 2 ] && command -v taskset > /dev/null; then PAIRED=1; fi

key() { sed -n "s/^$2,//p" "$1/metrics.csv"; }
run() {  # core mode outdir
  if [ "$PAIRED" = 1 ]; then
    taskset -c "$1" "$REPLAY" "$DATASET" --mode "$2" -q --no-eval -o "$3" > /dev/null 2>&1
  else
    "$REPLAY" "$DATASET" --mode "$2" -q --no-eval -o "$3" > /dev/null 2>&1
  fi
}

printf '%-16s %5s %12s %12s %12s %8s\n' mode round vio_ms est_ms gnss_ms ratio
for m in $MODES; do
  ratios=()
  for i in $(seq 1 "$ROUNDS"); do
    a=$((i % 2)); b=$(((i + 1) % 2))
    pad=$(printf '%*s' "$i" '' | tr ' ' p)
    if [ "$PAIRED" = 1 ]; then
      run "$a" vio "$TMP/v$pad" & run "$b" "$m" "$TMP/g$pad" & wait
    else
      run 0 vio "$TMP/v$pad"; run 0 "$m" "$TMP/g$pad"
    fi
    v=$(key "$TMP/v$pad" estimator_ms_mean); e=$(key "$TMP/g$pad" estimator_ms_mean); g=$(key "$TMP/g$pad" gnss_ms_per_frame)
    r=$(awk -v v="$v" -v e="$e" -v g="$g" 'BEGIN { printf "%.4f", (e + g) / v }')
    ratios+=("$r")
    printf '%-16s %5d %12.4f %12.4f %12.4f %8.4f\n' "$m" "$i" "$v" "$e" "$g" "$r"
  done
  med=$(printf '%s\n' "${ratios[@]}" | sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}')
  printf '%-16s median ratio %.4f: +%.1f %% estimator time over VIO (%s)\n' "$m" "$med" \
    "$(awk -v r="$med" 'BEGIN { print 100 * (r - 1) }')" "$([ "$PAIRED" = 1 ] && echo "paired on two cores" || echo "sequential")"
done
