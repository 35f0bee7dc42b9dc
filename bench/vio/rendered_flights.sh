#!/usr/bin/env bash
# VIO on the ten paper-like UAV flights (config/uav_*.yaml) with rendered stereo images and the
# OpenCV front end, in double and float: the figures of the VIO issue (drift per 100 m, NEES in
# the estimator's gauge, float against double, estimator and front-end time). One flight after
# the other: render (gvins-sim, no GNSS), replay `--mode vio` with the image front end (its tracks
# saved with --save-tracks), replay `--mode vio --float` on those saved tracks (the same input,
# without running the front end again; --float-images runs the front end again instead), delete
# the rendered images (about 0.9 GB per 100 s of flight) unless --keep-data, then the next flight.
#
#   bench/vio/rendered_flights.sh [options]
#     --build DIR      build folder with bin/gvins-sim and bin/gvins-replay (default build)
#     -o DIR           output folder (default out/rendered): runs/<flight>/{double,float}/
#                      (replay outputs, reused unless --force), tables.md, metrics.csv
#     --flights LIST   comma-separated flight names (e.g. uav_20m_1000m_8mps), default all ten
#     --config F.yaml  replay configuration passed to every run (gvins-replay --config)
#     --force          rerun replays whose outputs exist
#     --keep-data      keep the rendered datasets (and the saved tracks) in DIR/data/
#     --float-images   float replays from the images too (default: from the double run's tracks)
#     --markdown FILE  also write the table as a results page (e.g. docs/results/rendered_flights.md)
#                      headed by the command, the commit and the date of the run
#
# Columns (metrics.csv of gvins-replay, docs/replay.md): RMSE after the 4-DoF alignment over the
# whole flight; drift = local_drift_percent (100 m segments); NEES p / θ under the first-pose
# alignment (the estimator's gauge, expected 3); float % = float position RMSE against double.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=build
OUT=$ROOT/out/rendered
FLIGHTS=""
CONFIG=""
FORCE=0
KEEP=0
MARKDOWN=""
COMMAND_LINE="bench/vio/rendered_flights.sh $*"
FLOAT_IMAGES=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build) BUILD=$2; shift ;;
    -o) OUT=$2; shift ;;
    --flights) FLIGHTS=$2; shift ;;
    --config) CONFIG=$2; shift ;;
    --force) FORCE=1 ;;
    --keep-data) KEEP=1 ;;
    --markdown) MARKDOWN=$2; shift ;;
    --float-images) FLOAT_IMAGES=1 ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    *) echo "rendered_flights.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
case "$BUILD" in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
SIM=$BUILD/bin/gvins-sim
REPLAY=$BUILD/bin/gvins-replay
for b in "$SIM" "$REPLAY"; do
  [ -x "$b" ] || { echo "rendered_flights.sh: $b not built (cmake --build $BUILD --target gvins-sim gvins-replay)" >&2; exit 1; }
done
if [ -n "$CONFIG" ]; then
  [ -f "$CONFIG" ] || { echo "rendered_flights.sh: no file $CONFIG" >&2; exit 2; }
  CONFIG=$(cd "$(dirname "$CONFIG")" && pwd)/$(basename "$CONFIG")
fi

ORDER=(uav_60m_400m_8mps uav_60m_1000m_6mps uav_40m_1000m_8mps uav_20m_1000m_8mps uav_60m_1000m_8mps
       uav_60m_1000m_10mps uav_60m_1000m_4mps uav_50m_3000m_8mps uav_50m_3000m_12mps uav_50m_3000m_4mps)
declare -A CFG
for f in "$ROOT"/config/uav_*.yaml; do
  CFG[$(sed -n 's/^name: *//p' "$f")]=$f
done
SELECTED=()
if [ -n "$FLIGHTS" ]; then IFS=, read -r -a SELECTED <<< "$FLIGHTS"; else SELECTED=("${ORDER[@]}"); fi
for n in "${SELECTED[@]}"; do
  [ -n "${CFG[$n]:-}" ] || { echo "rendered_flights.sh: no config/uav_*.yaml with name: $n" >&2; exit 2; }
done
mkdir -p "$OUT/data" "$OUT/runs"

start=$(date +%s)
k=0
for n in "${SELECTED[@]}"; do
  k=$((k + 1))
  echo "== [$k/${#SELECTED[@]}] $n (elapsed $(( $(date +%s) - start )) s)" >&2
  data=$OUT/data/$n
  tracks=$OUT/data/$n.tracks
  for prec in double float; do
    dir=$OUT/runs/$n/$prec
    if [ "$FORCE" = 0 ] && [ -f "$dir/metrics.csv" ]; then continue; fi
    input=$data
    if [ "$prec" = float ] && [ "$FLOAT_IMAGES" = 0 ] && [ -f "$tracks/mav0/cam0/features.csv" ]; then
      input=$tracks
    elif [ ! -f "$data/dataset.yaml" ]; then
      rm -rf "$data"
      echo "   rendering $n" >&2
      "$SIM" --config "${CFG[$n]}" --no-gnss -o "$data" > "$data.sim.log" 2>&1 || { cat "$data.sim.log" >&2; exit 1; }
    fi
    rm -rf "$dir"
    mkdir -p "$dir"
    args=(--mode vio -q -o "$dir")
    [ "$prec" = float ] && args+=(--float)
    if [ "$prec" = double ]; then rm -rf "$tracks"; args+=(--save-tracks "$tracks"); fi
    [ -n "$CONFIG" ] && args+=(--config "$CONFIG")
    if "$REPLAY" "$input" "${args[@]}" > "$dir/summary.txt" 2> "$dir/stderr.txt"; then
      printf '   %-22s %-6s RMSE %s m, drift %s %%\n' "$n" "$prec" \
        "$(sed -n 's/^local_position_rmse_m,//p' "$dir/metrics.csv")" \
        "$(sed -n 's/^local_drift_percent,//p' "$dir/metrics.csv")" >&2
    else
      printf '   %-22s %-6s FAILED (see %s)\n' "$n" "$prec" "$dir/stderr.txt" >&2
    fi
  done
  [ "$KEEP" = 1 ] || rm -rf "$data" "$tracks"
done

ALL=$OUT/metrics.csv
echo "flight,precision,key,value" > "$ALL"
for n in "${SELECTED[@]}"; do
  for prec in double float; do
    f=$OUT/runs/$n/$prec/metrics.csv
    [ -f "$f" ] && grep -v '^#' "$f" | sed "s|^|$n,$prec,|" >> "$ALL"
  done
done

awk -F, '
NR > 1 { v[$1 "|" $2 "|" $3] = $4; if (!($1 in seen)) { seen[$1] = 1; order[++nf] = $1 } }
function g(f, p, k) { return ((f "|" p "|" k) in v) ? v[f "|" p "|" k] + 0 : "nan" }
function label(f,   a) { split(f, a, "_"); sub("000m", "km", a[3]); sub("mps", "m/s", a[4]); return a[2] "-" a[3] "-" a[4] }
BEGIN {
  print "| flight | path m | double RMSE m / deg | drift % | NEES p / θ | float RMSE m (vs double) | float drift % | float NEES p / θ | estimator ms d / f | front end ms | real time (double) |"
  print "|---|---|---|---|---|---|---|---|---|---|---|"
}
END {
  for (i = 1; i <= nf; ++i) {
    f = order[i]
    d = g(f, "double", "local_position_rmse_m"); fl = g(f, "float", "local_position_rmse_m")
    printf "| %s | %.0f | %.3f / %.2f | %.3f | %.2f / %.2f | %.3f (%+.0f %%) | %.3f | %.2f / %.2f | %.2f / %.2f | %.1f | %.2fx |\n", label(f),
      g(f, "double", "local_path_m"), d, g(f, "double", "local_rotation_rmse_deg"), g(f, "double", "local_drift_percent"),
      g(f, "double", "local_position_nees_first_pose"), g(f, "double", "local_orientation_nees_first_pose"),
      fl, 100 * (fl / d - 1), g(f, "float", "local_drift_percent"),
      g(f, "float", "local_position_nees_first_pose"), g(f, "float", "local_orientation_nees_first_pose"),
      g(f, "double", "estimator_ms_median"), g(f, "float", "estimator_ms_median"), g(f, "double", "frontend_ms_mean"),
      g(f, "double", "real_time_factor")
    sd += d; sf += fl; sr += fl / d; sdr += g(f, "double", "local_drift_percent"); sfr += g(f, "float", "local_drift_percent")
    snp += g(f, "double", "local_position_nees_first_pose"); snt += g(f, "double", "local_orientation_nees_first_pose")
    sfp += g(f, "float", "local_position_nees_first_pose"); sft += g(f, "float", "local_orientation_nees_first_pose")
    se += g(f, "double", "estimator_ms_median"); sef += g(f, "float", "estimator_ms_median"); sfe += g(f, "double", "frontend_ms_mean")
  }
  if (nf > 0) printf "| **mean (%d)** | | %.3f | %.3f | %.2f / %.2f | %.3f (per flight %+.1f %%) | %.3f | %.2f / %.2f | %.2f / %.2f | %.1f | |\n", nf,
    sd / nf, sdr / nf, snp / nf, snt / nf, sf / nf, 100 * (sr / nf - 1), sfr / nf, sfp / nf, sft / nf, se / nf, sef / nf, sfe / nf
}' "$ALL" | tee "$OUT/tables.md"
echo "rendered_flights.sh: $OUT/tables.md, $OUT/metrics.csv ($(( $(date +%s) - start )) s)" >&2
if [ -n "$MARKDOWN" ]; then
  mkdir -p "$(dirname "$MARKDOWN")"
  {
    echo "# VIO on the ten rendered UAV flights"
    echo
    echo "Written by \`$COMMAND_LINE\` at commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)"
    echo "on $(date -u '+%Y-%m-%d %H:%M UTC') ($(nproc) cores, $(( $(date +%s) - start )) s). Do not edit by hand: run the script again."
    echo "Columns: the header of bench/vio/rendered_flights.sh; the estimator: docs/vio_estimator.md."
    echo
    cat "$OUT/tables.md"
  } >"$MARKDOWN"
  echo "results page: $MARKDOWN" >&2
fi
