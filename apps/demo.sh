#!/usr/bin/env bash
# The README's main job on bundled data. Until the fused replay lands, it runs the most complete
# tool there is on bundled real data: single point positioning with Doppler velocity on the
# nagoya_static_2024 rover (Septentrio mosaic-X5, five systems), scored against the known position.
set -euo pipefail
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN="$ROOT/$BUILD/bin"
DATA="$ROOT/tests/data/gnss/nagoya_static_2024"
OUT="$ROOT/out/demo"
mkdir -p "$OUT"
echo "== SRI-GVINS demo: gvins-spp on $DATA (rover, 301 epochs, GPS+GLONASS+Galileo+BeiDou+QZSS)"
"$BIN/gvins-spp" -o "$OUT/nagoya_rover_spp.pos" --truth-llh 35.13469901,136.97757549,104.8626 \
  "$DATA/rover.obs.gz" "$DATA/base.nav.gz"
echo "== solution written to $OUT/nagoya_rover_spp.pos (RTKLIB .pos layout)"
