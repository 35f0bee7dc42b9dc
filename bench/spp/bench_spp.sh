#!/usr/bin/env bash
# Whole-process comparison of gvins-spp with RTKLIB's rnx2rtkp (single mode, the settings of
# tests/data/reference/rtklib-2.4.3/conf/spp.conf) on the same plain RINEX files, and a memory
# check on a short and a long observation file.
#
#   bench/spp/bench_spp.sh [BUILD_DIR] [RUNS]      (defaults: build, 5)
#
# Prints per-case median wall time, CPU time per run and peak RSS of each tool, and the speed-ups
# by wall time and by CPU time. The CPU time per run is measured over all RUNS runs of a tool
# together (one /usr/bin/time around the loop), because a single gvins-spp run takes only a few
# hundredths of a second and /usr/bin/time prints 0.01 s; on a shared, loaded machine the CPU
# ratio is the figure to quote, the wall ratio depends on the load. Also runs hyperfine when it is
# installed.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${1:-build}
RUNS=${2:-5}
SPP="$ROOT/$BUILD/bin/gvins-spp"
CONF="$ROOT/tests/data/reference/rtklib-2.4.3/conf/spp.conf"
DATA="$ROOT/tests/data/gnss"
[ -x "$SPP" ] || { echo "gvins-spp not built: $SPP" >&2; exit 1; }
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "needs /usr/bin/time (Debian package 'time')" >&2; exit 1; }
HAVE_RTKLIB=0
command -v rnx2rtkp >/dev/null && HAVE_RTKLIB=1

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
gzip -dc "$DATA/nagoya_static_2024/rover.obs.gz" > "$TMP/nagoya.obs"
gzip -dc "$DATA/nagoya_static_2024/base.nav.gz" > "$TMP/nagoya.nav"
gzip -dc "$DATA/kamakura_static_2021/SEPT078M.21O.gz" > "$TMP/kamakura.obs"
gzip -dc "$DATA/kamakura_static_2021/SEPT078M.21P.gz" > "$TMP/kamakura.nav"
# Short file: header and the first 60 epochs of kamakura.
awk '/^>/{n++} n<=60' "$TMP/kamakura.obs" > "$TMP/kamakura_60.obs"
# Long file (memory check only): kamakura's 900 epochs written 8 times with the epoch times moved
# on by 15 min each time (2 h, 7200 epochs). The copied ranges no longer fit the geometry, so
# this file measures memory and throughput, not accuracy.
awk 'BEGIN{h=1}
     h{print; if ($0 ~ /END OF HEADER/) h=0; next}
     {body[++n]=$0}
     END{for (k=0;k<8;k++) for (i=1;i<=n;i++) { l=body[i];
           if (substr(l,1,1)==">") { hh=substr(l,14,2)+0; mm=substr(l,17,2)+0+15*k;
             hh+=int(mm/60); mm=mm%60; l=sprintf("%s%02d %02d%s", substr(l,1,13), hh, mm, substr(l,19)) }
           print l }}' "$TMP/kamakura.obs" > "$TMP/kamakura_long.obs"

# measure LABEL CMD... -> "median_wall cpu_per_run max_rss_kb"
measure() {
  local label=$1; shift
  local walls=() rss=0
  for ((i = 0; i < RUNS; i++)); do
    "$TIME" -f "%e %U %S %M" -o "$TMP/t" "$@" >/dev/null 2>&1 || { echo "failed: $*" >&2; return 1; }
    read -r w u s m < "$TMP/t"
    walls+=("$w")
    [ "$m" -gt "$rss" ] && rss=$m
  done
  local mw cpu
  mw=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}')
  # CPU time of all RUNS runs together (children of one shell), divided by RUNS.
  "$TIME" -f "%U %S" -o "$TMP/t" bash -c 'n=$1; shift; for ((k = 0; k < n; k++)); do "$@" >/dev/null 2>&1 || exit 1; done' \
    _ "$RUNS" "$@" || { echo "failed: $*" >&2; return 1; }
  cpu=$(awk -v n="$RUNS" '{printf "%.4f", ($1 + $2) / n}' "$TMP/t")
  echo "$mw $cpu $rss"
}

if command -v hyperfine >/dev/null && [ "$HAVE_RTKLIB" = 1 ]; then
  echo "== hyperfine (nagoya rover, 301 epochs)"
  hyperfine -N -w 1 -r "$RUNS" \
    "$SPP -q -o $TMP/g.pos $TMP/nagoya.obs $TMP/nagoya.nav" \
    "rnx2rtkp -k $CONF -o $TMP/r.pos $TMP/nagoya.obs $TMP/nagoya.nav" 2>/dev/null || true
fi

printf '\n%-26s %-9s %10s %10s %10s\n' "case" "tool" "wall_s" "cpu_s/run" "maxRSS_kB"
declare -A W C
for c in nagoya kamakura kamakura_60 kamakura_long; do
  nav=$TMP/${c%%_*}.nav
  r=$(measure "$c gvins" "$SPP" -q -o "$TMP/g.pos" "$TMP/$c.obs" "$nav")
  printf '%-26s %-9s %10s %10s %10s\n' "$c" gvins-spp $r
  W[$c.g]=$(echo "$r" | cut -d' ' -f1)
  C[$c.g]=$(echo "$r" | cut -d' ' -f2)
  if [ "$HAVE_RTKLIB" = 1 ]; then
    r=$(measure "$c rtklib" rnx2rtkp -k "$CONF" -o "$TMP/r.pos" "$TMP/$c.obs" "$nav")
    printf '%-26s %-9s %10s %10s %10s\n' "$c" rnx2rtkp $r
    W[$c.r]=$(echo "$r" | cut -d' ' -f1)
    C[$c.r]=$(echo "$r" | cut -d' ' -f2)
  fi
done
if [ "$HAVE_RTKLIB" = 1 ]; then
  echo
  for c in nagoya kamakura kamakura_60 kamakura_long; do
    awk -v c="$c" -v g="${W[$c.g]}" -v r="${W[$c.r]}" -v gc="${C[$c.g]}" -v rc="${C[$c.r]}" \
      'BEGIN{ printf "speed-up %-16s rnx2rtkp/gvins-spp = ", c;
              if (gc > 0) printf "%.1fx (CPU)", rc/gc; else printf "n/a (CPU)";
              if (g > 0) printf ", %.1fx (wall)\n", r/g; else printf ", n/a (wall)\n" }'
  done
  echo "target (issue): >= 10x as a whole process"
  # The CPU figures include the shell's fork and the exec of every run; on a small virtual
  # machine that alone is several milliseconds, which bounds the ratio of the short case.
  "$TIME" -f "%U %S" -o "$TMP/t" bash -c 'n=$1; for ((k = 0; k < n; k++)); do /bin/true; done' _ "$RUNS"
  awk -v n="$RUNS" '{printf "fork+exec of /bin/true in the same loop: %.4f s CPU per run\n", ($1 + $2) / n}' "$TMP/t"
else
  echo "(rnx2rtkp not installed: RTKLIB not timed)"
fi
echo "epochs: nagoya 301, kamakura 900, kamakura_60 60, kamakura_long 7200"
