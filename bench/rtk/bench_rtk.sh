#!/usr/bin/env bash
# Whole-process comparison of gvins-rtk with RTKLIB's rnx2rtkp on the same plain RINEX files and
# the same settings (tests/data/reference/rtklib-2.4.3/conf/rtk_*.conf: L1+L2, 15 deg mask,
# continuous or instantaneous AR, ratio 3, GLONASS AR off, broadcast iono/Saastamoinen tropo),
# with the fix rate of each tool from its own output.
#
#   bench/rtk/bench_rtk.sh [BUILD_DIR] [RUNS]      (defaults: build, 5)
#
# Cases: nagoya_kin / nagoya_inst (0.99 m, GPS+GLO+GAL+BDS+QZS, 301 epochs at 1 Hz, ~42 satellites),
# geonet_static / geonet_kin (3.34 km, GPS L1/L2, 120 epochs at 30 s). Prints per case the median
# wall and CPU (user+sys) time over RUNS runs, peak RSS, fix rate, and the speed-up in both wall
# and CPU time. On a shared machine the CPU-time ratio is the meaningful one: wall time includes
# waiting for a core.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${1:-build}
RUNS=${2:-5}
RTK="$ROOT/$BUILD/bin/gvins-rtk"
CONF="$ROOT/tests/data/reference/rtklib-2.4.3/conf"
DATA="$ROOT/tests/data/gnss"
[ -x "$RTK" ] || { echo "gvins-rtk not built: $RTK" >&2; exit 1; }
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "needs /usr/bin/time (Debian package 'time')" >&2; exit 1; }
HAVE_RTKLIB=0
command -v rnx2rtkp >/dev/null && HAVE_RTKLIB=1

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
N=$DATA/nagoya_static_2024
G=$DATA/geonet_0759_3040_2005
gzip -dc "$N/rover.obs.gz" > "$TMP/n_rover.obs"
gzip -dc "$N/base.obs.gz" > "$TMP/n_base.obs"
gzip -dc "$N/base.nav.gz" > "$TMP/n.nav"
gzip -dc "$G/07590920.05o.gz" > "$TMP/g_rover.obs"
gzip -dc "$G/30400920.05o.gz" > "$TMP/g_base.obs"
gzip -dc "$G/30400920.05n.gz" > "$TMP/g.nav"
read -r NLAT NLON NH < "$N/base_position.txt" || true  # (no final newline)
GXYZ=(-3978242.4348 3382841.1715 3649902.7667)  # 3040 RINEX header position (both tools)

NF="$TMP/n_rover.obs $TMP/n_base.obs $TMP/n.nav"
GF="$TMP/g_rover.obs $TMP/g_base.obs $TMP/g.nav"
declare -A GV RL
GV[nagoya_kin]="--xyz --base-llh $NLAT,$NLON,$NH $NF"
RL[nagoya_kin]="-k $CONF/rtk_kin.conf -l $NLAT $NLON $NH $NF"
GV[nagoya_inst]="--xyz --armode instantaneous --base-llh $NLAT,$NLON,$NH $NF"
RL[nagoya_inst]="-k $CONF/rtk_inst.conf -l $NLAT $NLON $NH $NF"
GV[geonet_static]="--xyz --mode static --systems G $GF"
RL[geonet_static]="-k $CONF/rtk_static_gps.conf -r ${GXYZ[*]} $GF"
GV[geonet_kin]="--xyz --systems G $GF"
RL[geonet_kin]="-k $CONF/rtk_kin.conf -r ${GXYZ[*]} $GF"
CASES="nagoya_kin nagoya_inst geonet_static geonet_kin"

# measure OUT.pos CMD... -> "median_wall median_cpu max_rss_kb"
measure() {
  local walls=() cpus=() rss=0
  for ((i = 0; i < RUNS; i++)); do
    "$TIME" -f "%e %U %S %M" -o "$TMP/t" "$@" >/dev/null 2>&1 || { echo "failed: $*" >&2; return 1; }
    read -r w u s m < "$TMP/t"
    walls+=("$w")
    cpus+=("$(awk -v u="$u" -v s="$s" 'BEGIN{print u + s}')")
    [ "$m" -gt "$rss" ] && rss=$m
  done
  local mw mc
  mw=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}')
  mc=$(printf '%s\n' "${cpus[@]}" | sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}')
  echo "$mw $mc $rss"
}
# fixes FILE.pos EPOCHS -> "fixed/epochs (rate %)" from the Q column of an x/y/z .pos file
fixes() {
  awk -v n="$2" '!/^%/ && NF > 6 {if ($6 == 1) f++} END{printf "%d/%d (%.1f%%)", f, n, 100 * f / n}' "$1"
}
declare -A EPOCHS=([nagoya_kin]=301 [nagoya_inst]=301 [geonet_static]=120 [geonet_kin]=120)

printf '%-14s %-9s %8s %8s %10s  %s\n' case tool wall_s cpu_s maxRSS_kB "fixed"
declare -A W C
for c in $CASES; do
  # shellcheck disable=SC2086
  r=$(measure "$RTK" -q -o "$TMP/g.pos" ${GV[$c]})
  printf '%-14s %-9s %8s %8s %10s  %s\n' "$c" gvins-rtk $r "$(fixes "$TMP/g.pos" "${EPOCHS[$c]}")"
  W[$c.g]=$(echo "$r" | cut -d' ' -f1)
  C[$c.g]=$(echo "$r" | cut -d' ' -f2)
  if [ "$HAVE_RTKLIB" = 1 ]; then
    # shellcheck disable=SC2086
    r=$(measure rnx2rtkp -o "$TMP/r.pos" ${RL[$c]})
    printf '%-14s %-9s %8s %8s %10s  %s\n' "$c" rnx2rtkp $r "$(fixes "$TMP/r.pos" "${EPOCHS[$c]}")"
    W[$c.r]=$(echo "$r" | cut -d' ' -f1)
    C[$c.r]=$(echo "$r" | cut -d' ' -f2)
  fi
done
echo
if [ "$HAVE_RTKLIB" = 1 ]; then
  for c in $CASES; do
    awk -v c="$c" -v gw="${W[$c.g]}" -v rw="${W[$c.r]}" -v gc="${C[$c.g]}" -v rc="${C[$c.r]}" 'BEGIN{
      printf "speed-up %-14s rnx2rtkp/gvins-rtk: ", c
      if (gw > 0) printf "wall %.1fx", rw / gw; else printf "wall (below timer resolution)"
      if (gc > 0) printf ", cpu %.1fx\n", rc / gc; else printf ", cpu (below timer resolution)\n" }'
  done
else
  echo "(rnx2rtkp not installed: RTKLIB not timed)"
fi
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg) (on $(nproc) cores)"
