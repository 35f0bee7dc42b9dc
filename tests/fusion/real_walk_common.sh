# Shared setup of the real-walk tests, sourced by tests/fusion/real_walk_*.sh after they set BIN
# (the build's bin/) and DATA (tests/data): a scratch folder $W removed on exit, the check and
# metric helpers, $REF = the walk's reference track and the IMU helpers.
# The reference is the receiver's own real-time RTK solution (UBX-NAV-PVT of the log, 349 fixed
# and 187 float epochs) with ellipsoidal heights, written by gvins-ubx to-pos; the publisher's
# gnss_1730_sf.pos holds the same solutions with mean-sea-level heights (21.39 m higher) and is
# not used. The RTK's base station is not published: every absolute solution sits 6-10 m
# horizontally from the track (bench/fusion/real_walk.py), so horizontal RMS bounds hold that
# offset.
WALK=$DATA/gnss_imu/walk_0827
UBX=$DATA/ubx/gnss_1730.ubx
W=$(mktemp -d "${TMPDIR:-/tmp}/gvins_walk.XXXXXX")
trap 'rm -rf "$W"' EXIT
fail=0
check() {  # name value op bound
  if awk -v v="$2" -v b="$4" -v op="$3" 'BEGIN { exit !(v != "" && ((op == "<=" && v <= b) || (op == ">=" && v >= b))) }'; then
    echo "ok   $1 = $2 ($3 $4)"
  else
    echo "FAIL $1 = $2 (expected $3 $4)"
    fail=1
  fi
}
metric() { sed -n "s/^$1,//p" "$2"; }
REF=$W/walk_reference.pos
"$BIN/gvins-ubx" to-pos "$UBX" -o "$REF" 2>"$W/reference.log" || { cat "$W/reference.log"; exit 1; }
# walk_imu OUT.csv: the raw IMU log on GPST (its RTKLIB time tags); gvins-imu's report in $W/imu.log.
walk_imu() {
  "$BIN/gvins-imu" convert "$WALK/imu_1730.csv" --tag "$WALK/imu_1730.csv.tag" --columns ax,ay,az,gx,gy,gz,t \
    --time counter-ms --accel-unit g --gyro-unit deg/s -o "$1" >"$W/imu.log" 2>&1 || { cat "$W/imu.log"; exit 1; }
}
# walk_dataset DIR: a camera-less dataset, DIR/mav0/imu0 with the IMU and its calibration.
walk_dataset() {
  mkdir -p "$1/mav0/imu0"
  walk_imu "$1/mav0/imu0/data.csv"
  cp "$WALK/imu0_sensor.yaml" "$1/mav0/imu0/sensor.yaml"
}
# walk_replay NAME MODE [REPLAY OPTIONS...]: the walk dataset $W/ds replayed with the log as the
# rover against the reference into $W/NAME (its output in $W/NAME.out, shown when it fails).
walk_replay() {
  local name=$1 mode=$2
  shift 2
  "$BIN/gvins-replay" "$W/ds" --mode "$mode" "$@" --rover "$UBX" \
    --truth-pos "$REF" --imu-gaps warn -q -o "$W/$name" >"$W/$name.out" 2>&1 ||
    { cat "$W/$name.out"; exit 1; }
}
# Single-frequency fusion with the broadcast ionosphere.
printf 'gnss_fusion:\n  ionosphere: broadcast\n' >"$W/sf.yaml"
