#!/usr/bin/env bash
# Mutation harness of the command-line tools (issue 44): real and simulated inputs and options
# are damaged the way a careless or hostile user would, and every case must end in one of
#   reject  exit status 1 or 2 with a message on stderr naming the input (file, line, field) or
#           the option, and no output file that looks valid;
#   same    exit status 0 with output equal to that of the undamaged input (harmless mutations:
#           CRLF line ends, comments);
# never in a crash (signal), a hang (timeout) or another exit status.
#
#   tests/apps/input_mutations.sh BIN_DIR TEST_DATA_DIR [TOOL...]
#
# BIN_DIR holds gvins-spp, -rtk, -rtcm, -orbit, -sim, -replay, -eval, -bag, -imu; TOOL limits the run
# to some of them (spp rtk rtcm orbit sim replay eval bag imu). Needs bash, coreutils, gzip, awk.
# Prints one line per failed case and a table of cases per tool; exit status 1 if any failed.
set -u
BIN=$(cd "$1" && pwd)
DATA=$(cd "$2" && pwd)
shift 2
ONLY=" ${*:-spp rtk rtcm orbit sim replay eval bag imu} "
W=$(mktemp -d "${TMPDIR:-/tmp}/gvins_mutations.XXXXXX")
trap 'rm -rf "$W"' EXIT
LIMIT=${GVINS_MUTATION_TIMEOUT:-120}
declare -A CASES FAILED
TOOLS=()
NAV=$DATA/gnss/nagoya_static_2024/base.nav.gz
ROVER=$DATA/gnss/nagoya_static_2024/rover.obs.gz
BASE=$DATA/gnss/nagoya_static_2024/base.obs.gz
BASE_LLH=35.134707705,136.977577939,104.853

wants() { [[ $ONLY == *" $1 "* ]]; }
note() { echo "[mutations] $*" >&2; }

# fail TOOL NAME REASON
fail() {
  FAILED[$1]=$((${FAILED[$1]:-0} + 1))
  echo "FAIL $1 $2: $3" >&2
  if [ -s "$W/err" ]; then { head -c 600 "$W/err"; echo; } | sed 's/^/    stderr: /' >&2; fi
}

# run TOOL NAME CMD...: runs the case with a time limit; sets RC.
run() {
  local tool=$1 name=$2
  shift 2
  CASES[$tool]=$((${CASES[$tool]:-0} + 1))
  [[ " ${TOOLS[*]} " == *" $tool "* ]] || TOOLS+=("$tool")
  timeout -k 5 "$LIMIT" "$@" >"$W/out" 2>"$W/err" </dev/null
  RC=$?
  if [ $RC -eq 124 ] || [ $RC -eq 137 ]; then
    fail "$tool" "$name" "no answer within $LIMIT s (hang or runaway)"
    return 1
  fi
  if [ $RC -gt 128 ]; then
    fail "$tool" "$name" "killed by signal $((RC - 128)) (crash)"
    return 1
  fi
  return 0
}

# reject TOOL NAME 'PATTERN[|PATTERN...]' [--absent PATH] -- CMD...
# Exit 1 or 2 and stderr holds every PATTERN (fixed strings, '|' separated: the file or option
# and the reason); with --absent, PATH must not exist afterwards (no output that looks valid).
reject() {
  local tool=$1 name=$2 patterns=$3 absent=""
  shift 3
  if [ "$1" = "--absent" ]; then absent=$2; shift 2; fi
  [ "$1" = "--" ] && shift
  run "$tool" "$name" "$@" || return 0
  if [ $RC -ne 1 ] && [ $RC -ne 2 ]; then
    fail "$tool" "$name" "exit status $RC, expected 1 or 2 (rejected)"
    return 0
  fi
  local p
  IFS='|' read -ra ps <<<"$patterns"
  for p in "${ps[@]}"; do
    if ! grep -qF -- "$p" "$W/err"; then
      fail "$tool" "$name" "message does not name '$p'"
      return 0
    fi
  done
  if [ -n "$absent" ] && [ -e "$absent" ]; then fail "$tool" "$name" "left $absent behind"; fi
  return 0
}

# same TOOL NAME REF OUT -- CMD...: exit 0 and OUT equal to REF, '%' header lines aside.
same() {
  local tool=$1 name=$2 ref=$3 out=$4
  shift 4
  [ "$1" = "--" ] && shift
  rm -rf "$out"
  run "$tool" "$name" "$@" || return 0
  if [ $RC -ne 0 ]; then
    fail "$tool" "$name" "exit status $RC for a harmless mutation"
    return 0
  fi
  if ! cmp -s <(grep -v '^%' "$ref") <(grep -v '^%' "$out"); then
    fail "$tool" "$name" "output differs from that of the unmutated input"
  fi
  return 0
}

# ok TOOL NAME CMD...: a baseline run that must succeed (its output is the reference).
ok() {
  local tool=$1 name=$2
  shift 2
  run "$tool" "$name" "$@" || return 0
  [ $RC -eq 0 ] || fail "$tool" "$name" "baseline run failed with exit status $RC"
}

# ---- mutations of files ---------------------------------------------------------------------
plain() { gzip -dcf "$1"; }
crlf() { plain "$1" | sed 's/$/\r/' >"$2"; }
cut_gzip_trailer() { head -c -8 "$1" >"$2"; }           # deflate data complete, CRC/length gone
cut_gzip_half() { head -c $(($(stat -c %s "$1") / 2)) "$1" >"$2"; }
# RINEX 3 observation epochs (records from one '>' line to the next) rearranged: swap epochs A
# and B, repeat epoch A after itself, or give epoch B the time of epoch A (restamped into the past).
rinex_epochs() {  # IN OUT MODE A B
  plain "$1" | awk -v mode="$3" -v a="$4" -v b="$5" '
    function flush() { if (n > 0) { rec[n] = cur; } }
    /^>/ { flush(); n++; cur = $0 "\n"; stamp[n] = substr($0, 1, 29); next }
    { if (n == 0) { printf "%s\n", $0 } else { cur = cur $0 "\n" } }
    END {
      flush();
      for (i = 1; i <= n; i++) {
        if (mode == "swap" && i == a) { printf "%s", rec[b]; continue }
        if (mode == "swap" && i == b) { printf "%s", rec[a]; continue }
        printf "%s", (mode == "past" && i == b) ? stamp[a] substr(rec[b], 30) : rec[i];
        if (mode == "repeat" && i == a) printf "%s", rec[i];
      }
    }' >"$2"
}
# Replaces the text of line L (1-based, of the plain file) columns C.. with S (same length kept
# by the caller).
put_at() {  # IN OUT LINE COL TEXT
  plain "$1" | awk -v l="$3" -v c="$4" -v t="$5" 'NR == l { $0 = substr($0, 1, c - 1) t substr($0, c + length(t)) } { print }' >"$2"
}
# The line number of the first line matching a pattern (after line FROM).
line_of() { plain "$1" | awk -v p="$2" -v f="${3:-0}" 'NR > f && $0 ~ p { print NR; exit }'; }

# ---- gvins-spp -------------------------------------------------------------------------------
spp_cases() {
  local S=$BIN/gvins-spp d=$W/spp
  mkdir -p "$d"
  ok spp baseline "$S" -q -o "$d/ref.pos" "$ROVER" "$NAV"
  crlf "$ROVER" "$d/crlf.obs"
  same spp crlf-rover "$d/ref.pos" "$d/crlf.pos" -- "$S" -q -o "$d/crlf.pos" "$d/crlf.obs" "$NAV"
  crlf "$NAV" "$d/crlf.nav"
  same spp crlf-nav "$d/ref.pos" "$d/crlf2.pos" -- "$S" -q -o "$d/crlf2.pos" "$ROVER" "$d/crlf.nav"
  printf '%s\n' '# a comment line' 'spp:' '  # another' '  elevation_mask_deg: 15  # the default' >"$d/comment.yaml"
  same spp config-comments "$d/ref.pos" "$d/cfg.pos" -- "$S" -q --config "$d/comment.yaml" -o "$d/cfg.pos" "$ROVER" "$NAV"
  cut_gzip_trailer "$ROVER" "$d/trailer.obs.gz"
  reject spp gzip-no-trailer "trailer.obs.gz|truncated gzip" -- "$S" -q -o "$d/x.pos" "$d/trailer.obs.gz" "$NAV"
  cut_gzip_half "$ROVER" "$d/half.obs.gz"
  reject spp gzip-half "half.obs.gz|truncated gzip" -- "$S" -q -o "$d/x.pos" "$d/half.obs.gz" "$NAV"
  cut_gzip_trailer "$NAV" "$d/trailer.nav.gz"
  reject spp gzip-nav-no-trailer "trailer.nav.gz|truncated gzip" -- "$S" -q -o "$d/x.pos" "$ROVER" "$d/trailer.nav.gz"
  rinex_epochs "$ROVER" "$d/swap.obs" swap 10 11
  reject spp epochs-swapped-strict "swap.obs:|epoch time|before the previous epoch" -- "$S" -q --strict -o "$d/x.pos" "$d/swap.obs" "$NAV"
  # A run that fails half way leaves no .pos behind (written under a temporary name).
  reject spp failed-run-leaves-no-pos "swap.obs:|no output written" --absent "$d/swapped.pos" -- "$S" -q --strict -o "$d/swapped.pos" "$d/swap.obs" "$NAV"
  rinex_epochs "$ROVER" "$d/repeat.obs" repeat 10 0
  reject spp epoch-repeated-strict "repeat.obs:|epoch time|repeat" -- "$S" -q --strict -o "$d/x.pos" "$d/repeat.obs" "$NAV"
  rinex_epochs "$ROVER" "$d/past.obs" past 5 40
  reject spp epoch-restamped-strict "past.obs:|epoch time" -- "$S" -q --strict -o "$d/x.pos" "$d/past.obs" "$NAV"
  # Without --strict the epochs out of order are reported and skipped: rows stay in time order.
  local c
  for c in swap repeat past; do
    run spp "epochs-$c-skipped" "$S" -q -o "$d/$c.pos" "$d/$c.obs" "$NAV" || continue
    if [ $RC -ne 0 ]; then fail spp "epochs-$c-skipped" "exit status $RC"; continue; fi
    grep -qF "epochs must increase" "$W/err" || fail spp "epochs-$c-skipped" "out-of-order epoch not reported"
    grep -v '^%' "$d/$c.pos" | awk '{ t = $1 " " $2; if (NR > 1 && t <= last) { bad = 1 } last = t } END { exit bad }' ||
      fail spp "epochs-$c-skipped" "rows not in increasing time order"
  done
  local l
  # A pseudorange (the second F14.3 field; the first column is the channel number X1) of an
  # observation record after the header.
  l=$(line_of "$ROVER" '^G' "$(line_of "$ROVER" 'END OF HEADER')")
  put_at "$ROVER" "$d/nan.obs" "$l" 20 "           nan"
  reject spp value-nan "nan.obs:$l" -- "$S" -q --strict -o "$d/x.pos" "$d/nan.obs" "$NAV"
  put_at "$ROVER" "$d/big.obs" "$l" 20 "         1e999"
  reject spp value-1e999 "big.obs:$l" -- "$S" -q --strict -o "$d/x.pos" "$d/big.obs" "$NAV"
  { plain "$ROVER" | head -n 30; head -c 100000 /dev/zero | tr '\0' 'x'; echo; } >"$d/long.obs"
  reject spp line-100kB "long.obs" -- "$S" -q --strict -o "$d/x.pos" "$d/long.obs" "$NAV"
  plain "$ROVER" | head -c 200000 >"$d/cut.obs"
  reject spp obs-cut-mid-epoch "cut.obs:" -- "$S" -q --strict -o "$d/x.pos" "$d/cut.obs" "$NAV"
  reject spp obs-is-directory "$d|directory" -- "$S" -q -o "$d/x.pos" "$d" "$NAV"
  reject spp obs-missing "$d/none.obs" -- "$S" -q -o "$d/x.pos" "$d/none.obs" "$NAV"
  reject spp config-directory "$d|directory" -- "$S" -q --config "$d" -o "$d/x.pos" "$ROVER" "$NAV"
  printf 'sp:\n  elevation_mask_deg: 10\n' >"$d/typo.yaml"
  reject spp config-misspelled-section "typo.yaml:1|unknown section 'sp'" -- "$S" -q --config "$d/typo.yaml" -o "$d/x.pos" "$ROVER" "$NAV"
  reject spp elmask-nan "--elmask" -- "$S" -q --elmask nan -o "$d/x.pos" "$ROVER" "$NAV"
  reject spp elmask-1e999 "--elmask" -- "$S" -q --elmask 1e999 -o "$d/x.pos" "$ROVER" "$NAV"
  reject spp elmask-200-digits "--elmask" -- "$S" -q --elmask "$(printf '9%.0s' $(seq 200))" -o "$d/x.pos" "$ROVER" "$NAV"
  reject spp elmask-inf "--elmask" -- "$S" -q --elmask inf -o "$d/x.pos" "$ROVER" "$NAV"
  reject spp o-without-value "-o|needs a value" -- "$S" -q "$ROVER" "$NAV" -o
}

# ---- gvins-rtk -------------------------------------------------------------------------------
rtk_cases() {
  local R=$BIN/gvins-rtk d=$W/rtk
  mkdir -p "$d"
  plain "$ROVER" | awk '/^>/ { n++ } n <= 60 { print }' >"$d/rover.obs"  # the first 60 epochs
  ok rtk baseline "$R" -q --base-llh "$BASE_LLH" -o "$d/ref.pos" "$d/rover.obs" "$BASE" "$NAV"
  crlf "$d/rover.obs" "$d/crlf.obs"
  same rtk crlf-rover "$d/ref.pos" "$d/crlf.pos" -- "$R" -q --base-llh "$BASE_LLH" -o "$d/crlf.pos" "$d/crlf.obs" "$BASE" "$NAV"
  rinex_epochs "$d/rover.obs" "$d/swap.obs" swap 10 11
  reject rtk epochs-swapped-strict "swap.obs:|epoch time" -- "$R" -q --strict --base-llh "$BASE_LLH" -o "$d/x.pos" "$d/swap.obs" "$BASE" "$NAV"
  reject rtk failed-run-leaves-no-pos "swap.obs:|no output written" --absent "$d/swapped.pos" -- "$R" -q --strict --base-llh "$BASE_LLH" -o "$d/swapped.pos" "$d/swap.obs" "$BASE" "$NAV"
  rinex_epochs "$d/rover.obs" "$d/repeat.obs" repeat 10 0
  reject rtk epoch-repeated-strict "repeat.obs:|epoch time|repeat" -- "$R" -q --strict --base-llh "$BASE_LLH" -o "$d/x.pos" "$d/repeat.obs" "$BASE" "$NAV"
  rinex_epochs "$d/rover.obs" "$d/past.obs" past 5 40
  reject rtk epoch-restamped-strict "past.obs:|epoch time" -- "$R" -q --strict --base-llh "$BASE_LLH" -o "$d/x.pos" "$d/past.obs" "$BASE" "$NAV"
  run rtk epochs-restamped-skipped "$R" -q --base-llh "$BASE_LLH" -o "$d/past.pos" "$d/past.obs" "$BASE" "$NAV" && {
    [ $RC -eq 0 ] || fail rtk epochs-restamped-skipped "exit status $RC"
    grep -qF "epochs must increase" "$W/err" || fail rtk epochs-restamped-skipped "out-of-order epoch not reported"
    grep -v '^%' "$d/past.pos" | awk '{ t = $1 " " $2; if (NR > 1 && t <= last) { bad = 1 } last = t } END { exit bad }' ||
      fail rtk epochs-restamped-skipped "rows not in increasing time order"
  }
  reject rtk base-is-directory "$d|directory" -- "$R" -q --base-llh "$BASE_LLH" -o "$d/x.pos" "$d/rover.obs" "$d" "$NAV"
  reject rtk base-llh-height-1e9 "--base-llh" -- "$R" -q --base-llh 35,137,1e9 -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  reject rtk base-xyz-1e7 "--base-xyz|Earth's surface" -- "$R" -q --base-xyz 1e7,1e7,1e7 -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  reject rtk base-xyz-zero "--base-xyz" -- "$R" -q --base-xyz 0,0,0 -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  reject rtk base-xyz-nan "--base-xyz" -- "$R" -q --base-xyz nan,0,0 -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  reject rtk config-directory "$d|directory" -- "$R" -q --config "$d" -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  printf 'rt:\n  ratio: 3\n' >"$d/typo.yaml"
  reject rtk config-misspelled-section "typo.yaml:1|unknown section 'rt'" -- "$R" -q --config "$d/typo.yaml" -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  { printf 'rtk:\n  mode: kinematic\n  big: ['; head -c 4000000 /dev/zero | tr '\0' '1' | sed 's/1111111111/1111111111,/g'; printf '1]\n'; } >"$d/huge.yaml"
  reject rtk config-4MB "huge.yaml|limit" -- "$R" -q --config "$d/huge.yaml" -o "$d/x.pos" "$d/rover.obs" "$BASE" "$NAV"
  cut_gzip_trailer "$BASE" "$d/base.obs.gz"
  # The whole rover: the base is read to its end.
  reject rtk base-gzip-no-trailer "base.obs.gz|truncated gzip" -- "$R" -q --base-llh "$BASE_LLH" -o "$d/x.pos" "$ROVER" "$d/base.obs.gz" "$NAV"
  reject rtk o-without-value "-o|needs a value" -- "$R" -q "$d/rover.obs" "$BASE" "$NAV" -o
}

# ---- the simulated dataset the other tools read ---------------------------------------------
# About 20 s of a figure-eight with stereo feature tracks, a 5 Hz rover, a base station with its
# RTCM stream, and the simulated precise products (gnss/precise.sp3, gnss/precise.clk).
scenario() {  # FILE
  cat >"$1" <<YAML
name: mutation_harness
seed: 5
origin: {latitude_deg: 35.134707705, longitude_deg: 136.977577939, height_m: 104.853}
start_gpst: "2024-06-24 08:20:00"
trajectory: {type: flight, pattern: figure_eight, height_m: 30, length_m: 80, speed_mps: 6, laps: 1,
             takeoff_landing: false, hover_start_s: 2, hover_end_s: 2}
imu: {rate_hz: 200}
cameras:
  rate_hz: 10
  output: features
  list:
    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04]}
    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04]}
lever_arm_m: [0.08, 0.0, 0.18]
gnss:
  navigation: $NAV
  rover: {rate_hz: 5}
  precise_products: {write: true}
YAML
}
DS=$W/dataset
dataset() {
  [ -f "$DS/dataset.yaml" ] && return 0
  scenario "$W/scenario.yaml"
  note "simulating $DS"
  if ! timeout -k 5 600 "$BIN/gvins-sim" --config "$W/scenario.yaml" --threads 2 -o "$DS" >"$W/sim.out" 2>"$W/sim.err"; then
    cat "$W/sim.err" >&2
    echo "FAIL: the harness dataset cannot be simulated" >&2
    exit 1
  fi
}

# ---- gvins-sim -------------------------------------------------------------------------------
sim_cases() {
  local S=$BIN/gvins-sim d=$W/sim
  mkdir -p "$d"
  dataset
  CASES[sim]=$((${CASES[sim]:-0} + 1))  # the dataset itself was the baseline run
  [[ " ${TOOLS[*]} " == *" sim "* ]] || TOOLS+=(sim)
  reject sim config-directory "$d|directory" --absent "$d/o1" -- "$S" --config "$d" -o "$d/o1"
  sed 's/^trajectory:/trajectry:/' "$W/scenario.yaml" >"$d/typo.yaml"
  reject sim config-misspelled-key "typo.yaml:|trajectry" --absent "$d/o2" -- "$S" --config "$d/typo.yaml" -o "$d/o2"
  sed 's/height_m: 30/height_m: .nan/' "$W/scenario.yaml" >"$d/nan.yaml"
  reject sim value-nan "nan.yaml:|height_m" --absent "$d/o3" -- "$S" --config "$d/nan.yaml" -o "$d/o3"
  head -c 400 "$W/scenario.yaml" >"$d/cut.yaml"
  reject sim scenario-cut "cut.yaml" --absent "$d/o4" -- "$S" --config "$d/cut.yaml" -o "$d/o4"
  # 10,000 waypoints 1000 km apart: rejected before anything is written, not a disk filled.
  {
    grep -v -e '^trajectory:' -e '^ *takeoff_landing:' "$W/scenario.yaml"
    printf 'trajectory:\n  type: flight\n  pattern: waypoints\n  waypoints_m:\n'
    awk 'BEGIN { for (i = 0; i < 10000; i++) printf "    - [%d, %d, 30]\n", (i % 2) * 900000, i * 50 }'
  } >"$d/waypoints.yaml"
  reject sim waypoints-10000 "limit" --absent "$d/o5" -- "$S" --config "$d/waypoints.yaml" -o "$d/o5"
  sed 's/^start_gpst: .*/start_gpst: "2021-01-01 00:00:00"/' "$W/scenario.yaml" >"$d/start.yaml"
  reject sim start-outside-navigation "base.nav.gz|no satellite has a usable ephemeris" --absent "$d/o6" -- "$S" --config "$d/start.yaml" -o "$d/o6"
  # An existing dataset is not overwritten (its files would mix with the new ones) without --force.
  reject sim output-not-empty "$DS|not empty|--force" -- "$S" --config "$W/scenario.yaml" -o "$DS"
  [ -f "$DS/dataset.yaml" ] || fail sim output-not-empty "the existing dataset was damaged"
  mkdir -p "$d/old/mav0/cam7" && echo stale >"$d/old/mav0/cam7/data.csv"
  run sim output-force-replaces "$S" --config "$W/scenario.yaml" --no-gnss --threads 2 --force -o "$d/old" && {
    [ $RC -eq 0 ] || fail sim output-force-replaces "exit status $RC"
    [ -e "$d/old/mav0/cam7" ] && fail sim output-force-replaces "files of the older dataset left in place"
    [ -f "$d/old/dataset.yaml" ] || fail sim output-force-replaces "no dataset written"
  }
  reject sim seed-negative "--seed" -- "$S" --seed -1 -o "$d/o7"
  reject sim threads-zero "--threads" -- "$S" --threads 0 -o "$d/o8"
  reject sim o-without-value "-o|needs a value" -- "$S" --config "$W/scenario.yaml" -o
}

# ---- gvins-rtcm ------------------------------------------------------------------------------
rtcm_cases() {
  local T=$BIN/gvins-rtcm d=$W/rtcm
  mkdir -p "$d"
  dataset
  local S=$DS/gnss/base.rtcm3
  ok rtcm to-rinex-baseline "$T" to-rinex "$S" --date 2024-06-24 -o "$d/ref"
  ok rtcm info-baseline "$T" info "$S"
  local y
  for y in 1900-01-01 1970-01-01 1980-01-05 9999-01-01; do
    reject rtcm "date-$y" "--date $y|outside GPS time" --absent "$d/y.obs" -- "$T" to-rinex "$S" --date "$y" -o "$d/y"
  done
  : >"$d/empty.rtcm3"
  reject rtcm to-rinex-empty "empty.rtcm3|no RTCM 3 frame" --absent "$d/e.obs" -- "$T" to-rinex "$d/empty.rtcm3" --date 2024-06-24 -o "$d/e"
  awk 'BEGIN { srand(44); for (i = 0; i < 65536; i++) printf "%c", int(rand() * 256) }' >"$d/random.bin"
  reject rtcm to-rinex-random "random.bin|no RTCM 3 frame" --absent "$d/r.obs" -- "$T" to-rinex "$d/random.bin" --date 2024-06-24 -o "$d/r"
  reject rtcm info-directory "$d|directory" -- "$T" info "$d"
  reject rtcm to-rinex-o-without-value "-o|needs a value" -- "$T" to-rinex "$S" --date 2024-06-24 -o
  reject rtcm info-date-without-value "--date|needs a value" -- "$T" info "$S" --date
  # from-products: the simulated products, a clock file cut inside its last value, products
  # and navigation of different years.
  local P=$DS/gnss
  ok rtcm from-products-baseline "$T" from-products "$NAV" "$P/precise.sp3" "$P/precise.clk" -o "$d/ssr.rtcm3"
  head -c -5 "$P/precise.clk" >"$d/cut.clk"
  reject rtcm from-products-clock-cut "cut.clk:|clock bias" --absent "$d/x.rtcm3" -- "$T" from-products "$NAV" "$P/precise.sp3" "$d/cut.clk" -o "$d/x.rtcm3"
  reject rtcm from-products-other-year "07590920.05n.gz|no SSR correction" --absent "$d/x.rtcm3" -- \
    "$T" from-products "$DATA/gnss/geonet_0759_3040_2005/07590920.05n.gz" "$P/precise.sp3" "$P/precise.clk" -o "$d/x.rtcm3"
  reject rtcm from-products-interval-nan "--interval" -- "$T" from-products "$NAV" "$P/precise.sp3" --interval nan -o "$d/x.rtcm3"
  reject rtcm ntrip-duration-nan "--duration" -- "$T" ntrip ntrip://h/M -o "$d/n.rtcm3" --duration nan
}

# ---- gvins-orbit -----------------------------------------------------------------------------
orbit_cases() {
  local O=$BIN/gvins-orbit d=$W/orbit
  mkdir -p "$d"
  dataset
  local P=$DS/gnss T="2024-06-24 08:20:10"
  run orbit baseline "$O" "$NAV" --time "$T" && { [ $RC -eq 0 ] || fail orbit baseline "exit status $RC"; cp "$W/out" "$d/ref.csv"; }
  crlf "$NAV" "$d/crlf.nav"
  run orbit crlf-nav "$O" "$d/crlf.nav" --time "$T" && {
    [ $RC -eq 0 ] && cmp -s "$W/out" "$d/ref.csv" || fail orbit crlf-nav "output differs from that of the unmutated input"
  }
  reject orbit time-outside-ephemerides "--time|no satellite has a usable ephemeris" -- "$O" "$NAV" --time "2030-01-01 00:00:00"
  [ -s "$W/out" ] && fail orbit time-outside-ephemerides "printed output (a header) anyway"
  ok orbit compare-baseline "$O" "$NAV" "$P/precise.sp3" "$P/precise.clk" --time "$T" --compare
  head -c -5 "$P/precise.clk" >"$d/cut.clk"
  reject orbit compare-clock-cut "cut.clk:|clock bias" -- "$O" "$NAV" "$P/precise.sp3" "$d/cut.clk" --time "$T" --compare
  reject orbit compare-no-overlap "--compare|do not overlap" -- "$O" "$DATA/gnss/geonet_0759_3040_2005/07590920.05n.gz" "$P/precise.sp3" --time "2005-04-02 00:00:00" --compare
  reject orbit time-hour-25 "--time" -- "$O" "$NAV" --time "2024-06-24 25:00:00"
  reject orbit duration-negative "--duration" -- "$O" "$NAV" "$P/precise.sp3" --time "$T" --compare --duration -1
  reject orbit step-nan "--step" -- "$O" "$NAV" "$P/precise.sp3" --time "$T" --compare --step nan
  cut_gzip_trailer "$NAV" "$d/nav.gz"
  reject orbit nav-gzip-no-trailer "nav.gz|truncated gzip" -- "$O" "$d/nav.gz" --time "$T"
  reject orbit nav-directory "$d|directory" -- "$O" "$d" --time "$T"
  reject orbit time-without-value "--time|needs a value" -- "$O" "$NAV" --time
}

# A copy of the dataset with one file changed by a command (CMD gets the copy's path).
dataset_copy() {  # NAME
  rm -rf "${W:?}/$1"
  cp -r "$DS" "$W/$1"
}

# ---- gvins-replay ----------------------------------------------------------------------------
replay_cases() {
  local R=$BIN/gvins-replay d=$W/replay
  mkdir -p "$d"
  dataset
  ok replay baseline "$R" "$DS" -q --no-eval -o "$d/ref"
  dataset_copy crlf_ds
  sed -i 's/$/\r/' "$W/crlf_ds/mav0/imu0/data.csv"
  same replay crlf-imu "$d/ref/trajectory.tum" "$d/crlf/trajectory.tum" -- "$R" "$W/crlf_ds" -q --no-eval -o "$d/crlf"
  reject replay duration-negative "--duration" -- "$R" "$DS" -q --duration -1 -o "$d/x"
  reject replay start-negative "--start" -- "$R" "$DS" -q --start -5 -o "$d/x"
  reject replay start-nan "--start" -- "$R" "$DS" -q --start nan -o "$d/x"
  reject replay start-inf "--start" -- "$R" "$DS" -q --start inf -o "$d/x"
  reject replay duration-200-digits "--duration" -- "$R" "$DS" -q --duration "$(printf '9%.0s' $(seq 200))" -o "$d/x"
  reject replay lever-arm-1e6 "--lever-arm" -- "$R" "$DS" -q --mode vio+dopp+psr --lever-arm 1e6,0,0 -o "$d/x"
  reject replay base-position-zero "--base-position|Earth's surface" -- "$R" "$DS" -q --base-position 0,0,0 -o "$d/x"
  reject replay base-position-1e7 "--base-position|Earth's surface" -- "$R" "$DS" -q --base-position 1e7,1e7,1e7 -o "$d/x"
  reject replay dataset-missing "$W/none|no such folder" -- "$R" "$W/none" -q -o "$d/x"
  reject replay config-directory "$d|directory" -- "$R" "$DS" -q --config "$d" -o "$d/x"
  printf 'replai:\n  start_s: 1\n' >"$d/typo.yaml"
  reject replay config-misspelled-section "typo.yaml:1|replai" -- "$R" "$DS" -q --config "$d/typo.yaml" -o "$d/x"
  reject replay o-without-value "-o|needs a value" -- "$R" "$DS" -q -o
  dataset_copy empty_features
  : >"$W/empty_features/mav0/cam0/features.csv"
  : >"$W/empty_features/mav0/cam1/features.csv"
  reject replay features-empty "no frame was processed" --absent "$d/x/trajectory.tum" -- "$R" "$W/empty_features" -q --no-eval -o "$d/x"
  dataset_copy imu_1e30
  awk -F, 'NR == 100 { $5 = "1e30" } { print }' OFS=, "$DS/mav0/imu0/data.csv" >"$W/imu_1e30/mav0/imu0/data.csv"
  reject replay imu-1e30 "imu0/data.csv:100|a_x" -- "$R" "$W/imu_1e30" -q --no-eval -o "$d/x"
  dataset_copy rover_swapped
  rinex_epochs "$DS/gnss/rover.obs" "$W/rover_swapped/gnss/rover.obs" swap 20 21
  # Rover epochs out of order: skipped and reported with file and line (as gvins-spp does).
  run replay rover-epochs-swapped "$R" "$W/rover_swapped" -q --no-eval --mode vio+dopp+psr -o "$d/swapped" && {
    [ $RC -eq 0 ] || fail replay rover-epochs-swapped "exit status $RC"
    grep -qF "rover.obs:" "$W/err" && grep -qF "epochs must increase" "$W/err" ||
      fail replay rover-epochs-swapped "out-of-order epoch not reported with file and line"
  }
}

# ---- gvins-eval ------------------------------------------------------------------------------
eval_cases() {
  local E=$BIN/gvins-eval d=$W/eval
  mkdir -p "$d"
  dataset
  [ -f "$W/replay/ref/trajectory.tum" ] || {
    mkdir -p "$W/replay"
    timeout -k 5 "$LIMIT" "$BIN/gvins-replay" "$DS" -q --no-eval -o "$W/replay/ref" >/dev/null 2>&1
  }
  local T=$W/replay/ref/trajectory.tum
  run eval baseline "$E" --no-cov "$T" "$DS" && { [ $RC -eq 0 ] || fail eval baseline "exit status $RC"; grep -v '^estimate\|^reference' "$W/out" >"$d/ref.txt"; }
  sed 's/$/\r/' "$T" >"$d/crlf.tum"
  run eval crlf-estimate "$E" --no-cov "$d/crlf.tum" "$DS" && {
    [ $RC -eq 0 ] && cmp -s <(grep -v '^estimate\|^reference' "$W/out") "$d/ref.txt" ||
      fail eval crlf-estimate "output differs from that of the unmutated input"
  }
  : >"$d/empty.tum"
  reject eval estimate-empty "empty.tum" -- "$E" "$d/empty.tum" "$DS"
  awk 'NR == 5 { $2 = "nan" } { print }' "$T" >"$d/nan.tum"
  reject eval estimate-nan "nan.tum:5" -- "$E" "$d/nan.tum" "$DS"
  head -c 100 "$T" >"$d/cut.tum"
  reject eval estimate-cut "cut.tum:" -- "$E" "$d/cut.tum" "$DS"
  : >"$d/empty_gt.csv"
  reject eval reference-empty "empty_gt.csv" -- "$E" "$T" "$d/empty_gt.csv"
  reject eval reference-directory-without-truth "$d" -- "$E" "$T" "$d"
  reject eval tolerance-nan "--tolerance" -- "$E" --tolerance nan "$T" "$DS"
  reject eval segments-zero "--segments" -- "$E" --segments 0,10 "$T" "$DS"
  reject eval tolerance-without-value "--tolerance|needs a value" -- "$E" "$T" "$DS" --tolerance
}

# ---- gvins-bag -------------------------------------------------------------------------------
bag_cases() {
  local B=$BIN/gvins-bag d=$W/bag
  mkdir -p "$d"
  if "$BIN/gvins-bag" info /dev/null 2>&1 | grep -q "no ROS bag support"; then
    note "gvins-bag built without ROS bag support: its cases are skipped"
    return 0
  fi
  # A real EuRoC excerpt with images (tests/data/euroc, 24 stereo frames).
  local E=$DATA/euroc/v101_static_stereo
  ok bag from-dataset-baseline "$B" from-dataset "$E" -o "$d/ok.bag"
  ok bag info-baseline "$B" info "$d/ok.bag"
  reject bag info-directory "$d|is a directory" -- "$B" info "$d"
  if [ -f "$d/ok.bag" ]; then
    head -c $(($(stat -c %s "$d/ok.bag") / 2)) "$d/ok.bag" >"$d/half.bag"
    reject bag info-cut "half.bag" -- "$B" info "$d/half.bag"
  fi
  # A conversion that fails half way (a bad IMU row) leaves no bag behind.
  rm -rf "$W/bag_bad_imu"
  cp -r "$E" "$W/bag_bad_imu"
  rm -f "$W/bag_bad_imu/mav0/imu0/"data.csv*
  plain "$E/mav0/imu0/data.csv.gz" | awk -F, 'NR == 300 { $2 = "x" } { print }' OFS=, >"$W/bag_bad_imu/mav0/imu0/data.csv"
  reject bag from-dataset-bad-imu "imu0/data.csv:300" --absent "$d/bad.bag" -- "$B" from-dataset "$W/bag_bad_imu" -o "$d/bad.bag"
  ls "$d" | grep -q '^bad.bag' && fail bag from-dataset-bad-imu "left a temporary file behind"
  rm -rf "$W/bag_bad_png"
  cp -r "$E" "$W/bag_bad_png"
  local png
  png=$(ls "$W/bag_bad_png/mav0/cam0/data" | sed -n 12p)
  head -c 3000 "$E/mav0/cam0/data/$png" >"$W/bag_bad_png/mav0/cam0/data/$png"  # cut PNG, read half way
  reject bag from-dataset-cut-image "$png" --absent "$d/png.bag" -- "$B" from-dataset "$W/bag_bad_png" -o "$d/png.bag"
  ls "$d" | grep -q '^png.bag' && fail bag from-dataset-cut-image "left a temporary file behind"
  reject bag to-dataset-calib-missing "--calib-from|$W/none" --absent "$d/ds2/mav0" -- "$B" to-dataset "$d/ok.bag" -o "$d/ds2" --calib-from "$W/none"
  reject bag from-dataset-missing "$W/none" --absent "$d/none.bag" -- "$B" from-dataset "$W/none" -o "$d/none.bag"
  reject bag o-without-value "-o|needs a value" -- "$B" from-dataset "$E" -o
}

imu_cases() {
  local I=$BIN/gvins-imu d=$W/imu C=$DATA/gnss_imu/walk_0827
  mkdir -p "$d"
  local RAW=(--columns ax,ay,az,gx,gy,gz,t --time counter-ms --accel-unit g --gyro-unit deg/s)
  ok imu baseline "$I" convert "$C/imu_1730.csv" --tag "$C/imu_1730.csv.tag" "${RAW[@]}" -o "$d/ref.csv"
  sed 's/$/\r/' "$C/imu_1730.csv" >"$d/crlf.csv"
  # CR LF lines are the file the logger wrote: the tags then match without the CR LF correction
  same imu crlf-lines "$d/ref.csv" "$d/crlf_out.csv" -- "$I" convert "$d/crlf.csv" --tag "$C/imu_1730.csv.tag" "${RAW[@]}" -o "$d/crlf_out.csv"
  reject imu counter-without-tag "--tag" --absent "$d/a.csv" -- "$I" convert "$C/imu_1730.csv" "${RAW[@]}" -o "$d/a.csv"
  head -c 70 "$C/imu_1730.csv.tag" >"$d/short.tag"
  reject imu cut-tag-file "short.tag|header" --absent "$d/b.csv" -- "$I" convert "$C/imu_1730.csv" --tag "$d/short.tag" "${RAW[@]}" -o "$d/b.csv"
  awk 'NR == 500 { print "0.1,0.2,x,0,0,0,3329000"; next } { print }' "$C/imu_1730.csv" >"$d/bad.csv"
  reject imu bad-field "bad.csv:500|az" --absent "$d/c.csv" -- "$I" convert "$d/bad.csv" --tag "$C/imu_1730.csv.tag" "${RAW[@]}" -o "$d/c.csv"
  awk 'NR == 900 { next } NR == 901 { print; print prev; next } { prev = $0; print }' "$C/imu_1730.csv" >"$d/swap.csv"
  reject imu counter-goes-back "swap.csv|counter" --absent "$d/e.csv" -- "$I" convert "$d/swap.csv" --tag "$C/imu_1730.csv.tag" "${RAW[@]}" -o "$d/e.csv"
  reject imu bad-column-spec "--columns|gq" -- "$I" info "$C/imu_1730.csv" --columns ax,ay,az,gx,gy,gq,t
  reject imu bad-unit "--gyro-unit|rpm" -- "$I" info "$C/imu_1730.csv" --gyro-unit rpm
  reject imu bad-rotation "--rotate" -- "$I" info "$C/imu_1730.csv" --rotate 1,2
}

for t in spp rtk sim rtcm orbit replay eval bag imu; do
  if wants "$t"; then
    note "$t"
    "${t}_cases"
  fi
done
total=0
bad=0
printf '\n%-8s %6s %7s\n' tool cases failed
for t in "${TOOLS[@]}"; do
  printf '%-8s %6d %7d\n' "$t" "${CASES[$t]:-0}" "${FAILED[$t]:-0}"
  total=$((total + ${CASES[$t]:-0}))
  bad=$((bad + ${FAILED[$t]:-0}))
done
printf '%-8s %6d %7d\n' total "$total" "$bad"
[ "$bad" -eq 0 ]
