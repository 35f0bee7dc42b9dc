#!/usr/bin/env bash
# The README's main job: simulate the short bundled flight (config/demo_short.yaml: 45 s stereo
# figure-eight at 30 m over the real Nagoya broadcast ephemerides, rover GNSS 5 Hz, base station
# 3 km away) and run SRI-GVINS on it in the paper's best configuration, vio+dopp+ddcp (VIO +
# Doppler + double-differenced carrier phase with RTK-fixed ambiguities). Prints the accuracy
# tables and writes the trajectory, the global track and SVG plots to out/demo/.
#   apps/demo.sh [BUILD_DIR] [--images] [--mode MODE]
# --images renders camera images and runs the OpenCV front end (slower); by default the
# simulator's feature tracks feed the filter directly. The dataset is reused when present.
set -euo pipefail
BUILD=${1:-build}
shift || true
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN="$ROOT/$BUILD/bin"
MODE=vio+dopp+ddcp
SIMARGS=(--features-only)
KIND=features
while [ $# -gt 0 ]; do
  case "$1" in
    --images) SIMARGS=(); KIND=images ;;
    --mode) MODE=$2; shift ;;
    *) echo "usage: apps/demo.sh [BUILD_DIR] [--images] [--mode MODE]" >&2; exit 2 ;;
  esac
  shift
done
OUT="$ROOT/out/demo"
DATA="$OUT/dataset_$KIND"
mkdir -p "$OUT"
if [ ! -f "$DATA/dataset.yaml" ]; then
  echo "== simulating config/demo_short.yaml ($KIND) into $DATA"
  rm -rf "$DATA"
  "$BIN/gvins-sim" --config "$ROOT/config/demo_short.yaml" "${SIMARGS[@]}" -o "$DATA"
else
  echo "== reusing the simulated dataset $DATA"
fi
echo "== gvins-replay --mode $MODE"
"$BIN/gvins-replay" "$DATA" --mode "$MODE" -o "$OUT/$MODE"
echo "== outputs in $OUT/$MODE: trajectory.tum, global.pos, track.kml, eval_*.svg (plots)"
