#!/usr/bin/env bash
# The real u-blox + MEMS IMU walk with simulated vision (config/real_walk_0827_vision.yaml):
# gvins-sim fits the trajectory to the receiver's own RTK track (NAV-PVT, ellipsoidal heights:
# $REF of real_walk_common.sh) and the real IMU (trajectory type gnss_track), keeps the real IMU
# and the real UBX log and simulates stereo feature tracks; gvins-replay runs it with and without
# the cameras against the RTK track's fixed epochs.
# Bounds are the figures of bench/fusion/real_walk_vision.py (docs/results/real_walk_vision.md)
# with a margin:
#   fit: antenna 1.4 cm RMS from the track, velocity increments 0.10 m/s RMS, gyro bias within
#     0.16 mrad/s of the mean gyro of the standing first second (gvins-imu info), walking along -y;
#   vio (stereo): 0.04 m horizontal RMSE against the fitted trajectory (4-DoF aligned);
#   vio+dopp+psr, broadcast ionosphere: stereo H 7.97 m, V 3.88 m, velocity 0.194 m/s;
#     camera-less on the same folder: velocity 0.212 m/s (the IMU noise of imu0_sensor.yaml, with
#     the log's sample-time noise). (With BeiDou B1I only, before the
#     signal fallback brought the receiver's BeiDou B3I and the late-arriving systems into the
#     fusion: H 7.92 m, stereo 0.19 against camera-less 0.26 m/s.) The horizontal RMS is mostly
#     the offset every absolute solution has from the RTK track (6-10 m, its base station is not
#     published; docs/results/real_walk.md).
#   tests/fusion/real_walk_vision.sh BIN_DIR TEST_DATA_DIR SOURCE_DIR
set -u
BIN=$(cd "$1" && pwd)
DATA=$(cd "$2" && pwd)
SRC=$(cd "$3" && pwd)
. "$SRC/tests/fusion/real_walk_common.sh"
yamlkey() { sed -n "s/^  $1: *//p" "$2" | sed 's/ *#.*//' | head -1; }
walk_imu "$W/imu0.csv"
sed -e "s|^  imu_csv: .*|  imu_csv: $W/imu0.csv|" -e "s|^  pos_file: .*|  pos_file: $REF|" \
  -e "s|^  rover_log: .*|  rover_log: $UBX|" "$SRC/config/real_walk_0827_vision.yaml" >"$W/scenario.yaml"
"$BIN/gvins-sim" --config "$W/scenario.yaml" -o "$W/ds" >"$W/sim.out" 2>&1 || { cat "$W/sim.out"; exit 1; }
Y=$W/ds/dataset.yaml
cmp -s "$W/ds/gnss/rover.ubx" "$UBX" || { echo "FAIL gnss/rover.ubx is not the real log"; fail=1; }
check track_residual_rms_m "$(yamlkey track_residual_rms_m "$Y")" "<=" 0.03
check velocity_increment_residual_rms_mps "$(yamlkey velocity_increment_residual_rms_mps "$Y")" "<=" 0.15
# Gyro bias of the fit against the mean gyro of the first second (the walker stands still).
read -r g1 g2 g3 <<<"$(sed -n 's/.*gyro \([-0-9.e]*\) \([-0-9.e]*\) \([-0-9.e]*\) rad\/s.*/\1 \2 \3/p' "$W/imu.log")"
read -r b1 b2 b3 <<<"$(yamlkey fitted_gyro_bias_radps "$Y" | tr -d '[],')"
for i in 1 2 3; do
  g=$(eval echo "\$g$i"); bb=$(eval echo "\$b$i")
  check "gyro_bias_minus_static_mean_$i" "$(awk -v a="$bb" -v b="$g" 'BEGIN { d = a - b; print (d < 0 ? -d : d) }')" "<=" 0.0004
done
read -r f1 f2 f3 <<<"$(yamlkey forward_axis_body "$Y" | tr -d '[],')"
check forward_axis_minus_y "$(awk -v y="$f2" 'BEGIN { print -y }')" ">=" 0.95
# The real IMU is the dataset's IMU (sample for sample inside the span).
check imu_samples_kept "$(grep -c -F -x -f <(sed -n '2,50p' "$W/ds/mav0/imu0/data.csv") "$W/imu0.csv")" ">=" 49
mkdir -p "$W/cl/mav0" && cp -r "$W/ds/mav0/imu0" "$W/cl/mav0/" && cp -r "$W/ds/gnss" "$W/ds/dataset.yaml" "$W/cl/"
replay() {  # folder mode out [args]
  local ds=$1 mode=$2 out=$3
  shift 3
  "$BIN/gvins-replay" "$ds" --mode "$mode" --rover "$ds/gnss/rover.ubx" --truth-pos "$REF" \
    --imu-gaps warn -q -o "$out" "$@" >"$out.out" 2>&1 || { cat "$out.out"; exit 1; }
}
replay "$W/ds" vio "$W/vio"
check vio_local_horizontal_rmse_m "$(metric local_horizontal_rmse_m "$W/vio/metrics.csv")" "<=" 0.15
replay "$W/ds" vio+dopp+psr "$W/psr" --config "$W/sf.yaml"
replay "$W/cl" vio+dopp+psr "$W/psr_cl" --config "$W/sf.yaml"
M=$W/psr/metrics.csv
check gnss_epochs_updated "$(metric gnss_epochs_updated "$M")" ">=" 400
check global_horizontal_rmse_m "$(metric global_horizontal_rmse_m "$M")" "<=" 9
check global_vertical_rmse_m "$(metric global_vertical_rmse_m "$M")" "<=" 4.5
check global_velocity_rmse_mps "$(metric global_velocity_rmse_mps "$M")" "<=" 0.23
check local_velocity_rmse_mps "$(metric local_velocity_rmse_mps "$M")" "<=" 0.08
vs=$(metric global_velocity_rmse_mps "$M")
vc=$(metric global_velocity_rmse_mps "$W/psr_cl/metrics.csv")
check camera_less_velocity_over_stereo "$(awk -v a="$vc" -v b="$vs" 'BEGIN { print a / b }')" ">=" 1.0
exit $fail
