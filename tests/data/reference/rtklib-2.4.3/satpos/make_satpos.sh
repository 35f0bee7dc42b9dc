#!/bin/sh
# Regenerates the RTKLIB 2.4.3 b34 (Debian package rtklib) satellite position/clock references in
# this folder from the navigation and observation files in tests/data. RTKLIB's rnx2rtkp prints,
# at trace level 4, one line per satellite and epoch from satposs():
#   <transmit time GPST, 1 us> sat=<n> rs=<x y z, mm> dts=<clock incl. relativity, no TGD, ps> ...
# which is converted to CSV rows "sat,time_gpst,x_m,y_m,z_m,clock_ns,svh" (RINEX 3 satellite ids).
# Usage: sh make_satpos.sh   (run from this folder; needs rnx2rtkp and convbin on PATH)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
data="$here/../../../gnss"
conf="$here/../conf/spp.conf"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for f in nagoya_static_2024/rover.obs nagoya_static_2024/base.nav kamakura_static_2021/SEPT078M.21O \
         kamakura_static_2021/SEPT078M.21P kamakura_static_2021/30340780.21q \
         geonet_0759_3040_2005/07590920.05o geonet_0759_3040_2005/07590920.05n; do
  gzip -dc "$data/$f.gz" > "$tmp/$(basename "$f")"
done
# GLONASS from RINEX 2.11: RTKLIB's own conversion of the RTCM test log (obs, nav and gnav files).
convbin -r rtcm3 -tr 2009/12/18 23:00:00 -v 2.11 -od -os -d "$tmp" "$here/../../../rtcm/rtklib_testglo.rtcm3" >/dev/null 2>&1
gzip -9n < "$tmp/rtklib_testglo.nav" > "$here/testglo_rinex211.nav.gz"
gzip -9n < "$tmp/rtklib_testglo.gnav" > "$here/testglo_rinex211.gnav.gz"

# RTKLIB internal satellite numbers (2.4.3 b34): G1-32, R33-59, E60-95, J96-105, C106-168.
extract() {
  awk '$0 ~ / sat=/ && $0 ~ / rs=/ {
    line = $0
    t = $2 " " $3; gsub("/", "-", t)
    sub(/.* sat= */, "", line); n = line + 0
    sub(/^[0-9]+ rs= */, "", line)
    split(line, v, /[ =]+/)
    x = v[1]; y = v[2]; z = v[3]; dts = v[5]; svh = v[9]
    if (x == 0 && y == 0 && z == 0) next
    if (n <= 32) id = sprintf("G%02d", n)
    else if (n <= 59) id = sprintf("R%02d", n - 32)
    else if (n <= 95) id = sprintf("E%02d", n - 59)
    else if (n <= 105) id = sprintf("J%02d", n - 95)
    else if (n <= 168) id = sprintf("C%02d", n - 105)
    else next
    printf "%s,%s,%s,%s,%s,%s,%s\n", id, t, x, y, z, dts, svh
  }' "$1"
}

run() {  # name, extra rnx2rtkp options..., files...
  name=$1; shift
  rnx2rtkp -k "$conf" -x 4 -o "$tmp/$name.pos" "$@" >/dev/null 2>&1
  { echo "sat,time_gpst,x_m,y_m,z_m,clock_ns,svh"; extract "$tmp/$name.pos.trace"; } | gzip -9n > "$here/$name.csv.gz"
  echo "$name: $(gzip -dc "$here/$name.csv.gz" | tail -n +2 | wc -l) rows"
}

cd "$tmp"
run nagoya_base_nav -ti 10 rover.obs base.nav
run kamakura_21P -ti 30 SEPT078M.21O SEPT078M.21P
run kamakura_21q -ti 30 -sys J SEPT078M.21O 30340780.21q
run geonet_0759_rinex2 -ti 30 07590920.05o 07590920.05n
run testglo_rinex211 -sys G,R rtklib_testglo.obs rtklib_testglo.nav rtklib_testglo.gnav
