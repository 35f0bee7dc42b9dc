#!/usr/bin/env bash
# The real u-blox + MEMS IMU walk (tests/data/gnss_imu/walk_0827, tests/data/ubx/gnss_1730.ubx)
# through gvins-replay camera-less (IMU and GNSS, no cam0 folder), against the receiver's own RTK
# track (NAV-PVT with ellipsoidal heights, $REF of real_walk_common.sh) on its fixed epochs.
# Bounds are the measured figures with a margin (bench/fusion/real_walk.py prints them beside our
# SPP and RTKLIB's):
#   vio+dopp+psr with the broadcast ionosphere: H 8.26 m, V 4.70 m RMS, velocity 0.212 m/s;
#   initialised 0.9 s into the log (static start), 1333 of 1342 frames; 14.2 pseudorange rows per
#   tight epoch. The receiver tracks BeiDou on B1C/B2a/B3I only: BeiDou enters on B3I through
#   the signal fallback (before it, and before late systems joined the clocks: 7.6 rows, H 8.17 m).
#   The horizontal RMS is mostly the offset every absolute solution, RTKLIB's SPP too, has from
#   the RTK track (6-10 m; its base station is not published, bench/fusion/real_walk.py); the
#   vertical is a mean of +3.0 m with 3.7 m about it. BeiDou's broadcast ionosphere on B3I moves
#   the fused height by about -4 m against GPS + Galileo, which have no broadcast ionosphere in
#   this log (no GPS page 18 in 134 s).
# Consistency of the reported covariances (walk_compare.py consistency; with PYTHON3 only): the
# velocity σ against the fixed RTK positions' differences and the velocity heading's σ where the
# walker moves faster than 0.8 m/s (table 3 of bench/fusion/real_walk.py). Measured with the walk's
# IMU noise from the recording (imu0_sensor.yaml, bench/fusion/walk_imu_noise.py), before -> after
# replacing the static-only figures: psr (both ionosphere models) velocity NEES 10.6 -> 7.9,
# heading |e|/σ 1.67 -> 1.31, heading within 2σ 0.67 -> 0.80; ppp 42.2 -> 25.7, 3.09 -> 2.48,
# 0.43 -> 0.50. The bounds fail with the old figures. Still optimistic (honest: 3, 0.80, 0.95):
# the velocity σ is 1.6x (psr) and 2.9x (ppp) too small, a known limit (docs/results/real_walk.md).
#   tests/fusion/real_walk_camera_less.sh BIN_DIR TEST_DATA_DIR [PYTHON3]
set -u
BIN=$1
DATA=$2
PY=${3:-}
. "$(dirname "$0")/real_walk_common.sh"
walk_dataset "$W/ds"
walk_replay psr vio+dopp+psr --config "$W/sf.yaml"
M=$W/psr/metrics.csv
grep -q "camera-less" "$W/psr.out" || { echo "FAIL the summary does not say camera-less"; fail=1; }
check frames_initialized "$(metric frames_initialized "$M")" ">=" 1300
check init_s "$(metric init_s "$M")" "<=" 2
check gnss_epochs_updated "$(metric gnss_epochs_updated "$M")" ">=" 400
check global_horizontal_rmse_m "$(metric global_horizontal_rmse_m "$M")" "<=" 10
check global_vertical_rmse_m "$(metric global_vertical_rmse_m "$M")" "<=" 5.5
check global_velocity_rmse_mps "$(metric global_velocity_rmse_mps "$M")" "<=" 0.25
# Every tracked system contributes pseudoranges (signal fallback, systems joining the clocks late).
rows=$(awk -F, '!/^#/ && $3 == "tight" { n++; s += $4 } END { if (n) printf "%.2f", s / n; else print 0 }' "$W/psr/gnss_epochs.csv")
check psr_rows_per_tight_epoch "$rows" ">=" 12
grep -q "BeiDou: B1I not tracked, using B3I (C6I)" "$W/psr.out" || { echo "FAIL no notice of the BeiDou B3I fallback"; fail=1; }
grep -q "joins late" "$W/psr.out" || { echo "FAIL no notice of a system joining the clocks late"; fail=1; }
# vio+dopp+psr with ionosphere-free pairs (the default): H 7.23 m, V 4.32 m RMS (mean U -4.1 m)
# with the ISCs of the log's own GPS CNAV messages (without them, with the earlier IMU noise
# figures: V 4.57 m, mean U -4.4 m).
# GPS pairs L1 C/A with L2C; an L1/L5 pair needs those ISCs (docs/gnss_fusion.md, psr rows).
walk_replay if vio+dopp+psr
I=$W/if/metrics.csv
check if_global_horizontal_rmse_m "$(metric global_horizontal_rmse_m "$I")" "<=" 9
check if_global_vertical_rmse_m "$(metric global_vertical_rmse_m "$I")" "<=" 5.5
# vio+dopp+ppp on broadcast orbits and clocks (no products of the day): H 6.95 m, V 4.35 m RMS
# (mean U -4.3 m), velocity 0.214 m/s
# (ionosphere-free pairs of GPS and Galileo, BeiDou single-frequency B3I).
walk_replay ppp vio+dopp+ppp
P=$W/ppp/metrics.csv
check ppp_global_horizontal_rmse_m "$(metric global_horizontal_rmse_m "$P")" "<=" 9
check ppp_global_vertical_rmse_m "$(metric global_vertical_rmse_m "$P")" "<=" 5.5
check ppp_global_velocity_rmse_mps "$(metric global_velocity_rmse_mps "$P")" "<=" 0.25
check ppp_phase_rows_used "$(metric phase_rows_used "$P")" ">=" 1000
if [ -z "$PY" ]; then
  echo "note: no Python 3, the covariance consistency is not checked"
  exit $fail
fi
for run in psr:9.5:1.5:0.72 if:9.5:1.5:0.72 ppp:32:2.9:0.46; do  # run : bounds on NEES, |e|/σ, share
  IFS=: read -r name nees ratio share <<<"$run"
  read -r n _ hr hs _ <<<"$("$PY" "$(dirname "$0")/walk_compare.py" consistency "$W/$name" "$REF")"
  check "${name}_velocity_nees_mean" "$n" "<=" "$nees"
  check "${name}_velocity_nees_mean" "$n" ">=" 0.3
  check "${name}_heading_abs_error_over_sigma" "$hr" "<=" "$ratio"
  check "${name}_heading_within_2_sigma" "$hs" ">=" "$share"
done
exit $fail
