#!/usr/bin/env bash
# Installs a build tree into a temporary prefix and uses the installed copy as another project
# would (tests/install/CMakeLists.txt):
#  1. `cmake --install BUILD --prefix WORK/prefix` (no rebuild);
#  2. no installed file names the source or the build tree (`strings` on the libraries and tools,
#     grep on the CMake package and pkg-config files), the package files are where find_package
#     and pkg-config look, and every installed header compiles with the installed flags alone;
#  3. examples/satellite_spp and examples/rtcm_decode configured and built with
#     find_package(SriGvins CONFIG) and, separately, with their pkg-config Makefiles, and run on
#     tests/data: the satellite position and clock against RTKLIB's, the SPP fixes against the
#     surveyed rover position, the RTCM epochs against RTKLIB's conversion of the same log;
#  4. the installed gvins-sim, run from another folder, simulates GNSS with the navigation file
#     installed with it (the default scenario's, found relative to the executable).
# usage: install_and_use.sh CMAKE SOURCE_DIR BUILD_DIR WORK_DIR CXX
set -eu
cmake_cmd=$1 src=$(cd "$2" && pwd) build=$(cd "$3" && pwd) work=$4 cxx=$5
data=$src/tests/data
fail() { echo "FAIL: $*" >&2; exit 1; }
step() { echo "== $*"; }

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
prefix=$work/prefix

step "install $build into $prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" >"$work/install.log" ||
  { cat "$work/install.log" >&2; fail "cmake --install"; }
for f in lib/libgvins_base.a lib/libgvins_gnss.a lib/libgvins_rtcm.a include/gvins/gnss/spp.hpp \
         lib/cmake/SriGvins/SriGvinsConfig.cmake lib/cmake/SriGvins/SriGvinsConfigVersion.cmake \
         lib/cmake/SriGvins/SriGvinsTargets.cmake lib/pkgconfig/sri-gvins.pc \
         lib/pkgconfig/sri-gvins-gnss.pc bin/gvins-spp bin/gvins-sim \
         share/sri_gvins/data/gnss/nagoya_static_2024/base.nav.gz share/sri_gvins/config/default.yaml \
         share/doc/sri_gvins/LICENSE; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done

step "no path of the source or build tree in the installed files"
# The build folder usually lies inside the source folder; either path is a leak.
leaks=0
while IFS= read -r -d '' f; do
  case "$f" in
    *.a|*.so*|*/bin/*) hits=$(strings -a "$f" | grep -F -e "$src" -e "$build" | sort -u | head -n 3 || true) ;;
    *) hits=$(grep -a -F -e "$src" -e "$build" "$f" | head -n 3 || true) ;;
  esac
  if [ -n "$hits" ]; then
    echo "  ${f#$prefix/}: $hits" >&2
    leaks=$((leaks + 1))
  fi
done < <(find "$prefix" -type f -print0)
while IFS= read -r -d '' f; do
  case "$(readlink "$f")" in
    "$src"*|"$build"*) echo "  ${f#$prefix/} -> $(readlink "$f")" >&2; leaks=$((leaks + 1)) ;;
  esac
done < <(find "$prefix" -type l -print0)
[ "$leaks" -eq 0 ] || fail "$leaks installed files name the source or build tree"
grep -q 'EIGEN_MAX_ALIGN_BYTES=64' "$prefix/lib/cmake/SriGvins/SriGvinsTargets.cmake" ||
  fail "EIGEN_MAX_ALIGN_BYTES is not a usage requirement of the exported targets"

step "every installed header compiles with the pkg-config flags of sri-gvins.pc"
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
(cd "$prefix/include" && find gvins -name '*.hpp' | sort | sed 's/.*/#include <&>/') >"$work/all_headers.cpp"
"$cxx" -std=c++20 -fsyntax-only $(pkg-config --cflags sri-gvins) "$work/all_headers.cpp" ||
  fail "the installed headers do not compile on their own"
echo "  $(wc -l <"$work/all_headers.cpp") headers"

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)

build_example() {  # name -> $work/<name>-cmake/<name>, $work/<name>-pc/<name>
  local name=$1
  step "build examples/$name with find_package(SriGvins CONFIG)"
  "$cmake_cmd" -S "$src/examples/$name" -B "$work/$name-cmake" "${generator[@]}" \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_PREFIX_PATH="$prefix" \
    >"$work/$name-cmake.log" 2>&1 || { cat "$work/$name-cmake.log" >&2; fail "configure $name"; }
  "$cmake_cmd" --build "$work/$name-cmake" >>"$work/$name-cmake.log" 2>&1 ||
    { cat "$work/$name-cmake.log" >&2; fail "build $name (CMake)"; }
  step "build examples/$name with pkg-config ($(pkg-config --modversion sri-gvins))"
  mkdir -p "$work/$name-pc"
  make -s -C "$src/examples/$name" CXX="$cxx" BUILD="$work/$name-pc" >"$work/$name-pc.log" 2>&1 ||
    { cat "$work/$name-pc.log" >&2; fail "build $name (pkg-config)"; }
}

# ---- satellite_spp ----------------------------------------------------------------------------
build_example satellite_spp
# RTKLIB 2.4.3's position and clock of G05 at its signal transmit time in the Nagoya data
# (reference/rtklib-2.4.3/satpos, made by make_satpos.sh there).
ref=$(zcat "$data/reference/rtklib-2.4.3/satpos/nagoya_base_nav.csv.gz" | grep -m1 '^G05,')
ref_time=$(echo "$ref" | cut -d, -f2)
read -r lat0 lon0 h0 <"$data/gnss/nagoya_static_2024/rover_position.txt"
for variant in cmake pc; do
  out=$("$work/satellite_spp-$variant/satellite_spp" "$data/gnss/nagoya_static_2024/rover.obs.gz" \
        "$data/gnss/nagoya_static_2024/base.nav.gz" "$ref_time") || fail "satellite_spp ($variant) failed"
  echo "$out" | grep -E '^(sat G05|fix)' | sed "s/^/  [$variant] /"
  sat=$(echo "$out" | grep -m1 '^sat G05 ') || fail "satellite_spp ($variant): no G05 line"
  # satellite position within 5 cm and clock within 0.1 ns of RTKLIB's
  awk -v s="$sat" -v r="$ref" 'BEGIN {
    split(s, a, " "); split(r, b, ",");
    d = sqrt((a[5] - b[3])^2 + (a[6] - b[4])^2 + (a[7] - b[5])^2); dc = a[8] - b[6]; if (dc < 0) dc = -dc;
    printf "  G05 vs RTKLIB: position %.4f m, clock %.4f ns\n", d, dc;
    exit !(d < 0.05 && dc < 0.1) }' || fail "satellite_spp ($variant): G05 differs from RTKLIB"
  # fixes: first epoch within 5 m horizontally and 10 m vertically, mean of all 301 epochs within
  # 3 m of the surveyed position (RTKLIB's SPP on the file: 2.52 m horizontal, 0.93 m vertical RMS)
  for which in first mean; do
    fix=$(echo "$out" | grep -m1 "^fix $which ") || fail "satellite_spp ($variant): no '$which' fix"
    if [ "$which" = first ]; then hmax=5; vmax=10; else hmax=3; vmax=3; fi
    awk -v f="$fix" -v lat0="$lat0" -v lon0="$lon0" -v h0="$h0" -v hmax=$hmax -v vmax=$vmax -v w=$which 'BEGIN {
      split(f, a, " "); pi = atan2(0, -1); R = 6378137.0;
      dn = (a[8] - lat0) * pi / 180 * R; de = (a[9] - lon0) * pi / 180 * R * cos(lat0 * pi / 180);
      dh = sqrt(dn * dn + de * de); dv = a[10] - h0; if (dv < 0) dv = -dv;
      printf "  %s fix vs truth: horizontal %.2f m, vertical %.2f m\n", w, dh, dv;
      exit !(dh < hmax && dv < vmax) }' || fail "satellite_spp ($variant): $which fix too far from the truth"
  done
  echo "$out" | grep -q '^fix mean .* epochs 301 fixes 301$' || fail "satellite_spp ($variant): expected 301 fixes of 301 epochs"
done

# ---- rtcm_decode ------------------------------------------------------------------------------
build_example rtcm_decode
# RTKLIB's RINEX conversion of the same log: epochs, first epoch and its satellites, satellites
# over all epochs, and the station position (from the 1005 messages) in its header.
conv=$data/reference/rtklib-2.4.3/rtcm_testglo_convbin.obs
want_epochs=$(grep -c '^>' "$conv")
want_first=$(grep -m1 '^>' "$conv" | awk '{ printf "%04d-%02d-%02d %02d:%02d:%04.1f %d", $2, $3, $4, $5, $6, $7, $9 }')
want_sats=$(grep '^>' "$conv" | awk '{ n += $9 } END { print n }')
want_pos=$(grep 'APPROX POSITION XYZ' "$conv" | awk '{ print $1, $2, $3 }')
for variant in cmake pc; do
  out=$("$work/rtcm_decode-$variant/rtcm_decode" "$data/rtcm/rtklib_testglo.rtcm3" 2009-12-18) ||
    fail "rtcm_decode ($variant) failed"
  echo "$out" | sed "s/^/  [$variant] /"
  got_epochs=$(echo "$out" | awk '$1 == "epochs" { print $2 }')
  got_first=$(echo "$out" | awk '$1 == "first_epoch" { print $2, $3, $5 }')
  got_sats=$(echo "$out" | awk '$1 == "satellite_epochs" { print $2 }')
  got_pos=$(echo "$out" | awk '$1 == "station" { print $4, $5, $6 }')
  [ "$got_epochs" = "$want_epochs" ] || fail "rtcm_decode ($variant): $got_epochs epochs, RTKLIB $want_epochs"
  [ "$got_first" = "$want_first" ] || fail "rtcm_decode ($variant): first epoch '$got_first', RTKLIB '$want_first'"
  [ "$got_sats" = "$want_sats" ] || fail "rtcm_decode ($variant): $got_sats satellite epochs, RTKLIB $want_sats"
  awk -v g="$got_pos" -v w="$want_pos" 'BEGIN { split(g, a, " "); split(w, b, " ");
    exit !((a[1] - b[1])^2 + (a[2] - b[2])^2 + (a[3] - b[3])^2 < 1e-6) }' ||
    fail "rtcm_decode ($variant): station '$got_pos', RTKLIB '$want_pos'"
  echo "  [$variant] matches RTKLIB: $want_epochs epochs, first '$want_first', $want_sats satellite epochs"
done

# ---- the installed simulator finds its data ---------------------------------------------------
step "installed gvins-sim with the bundled navigation file"
mkdir -p "$work/sim-cwd"
cat >"$work/sim-cwd/tiny.yaml" <<'EOF'
name: tiny
trajectory: {type: flight, pattern: figure_eight, height_m: 20, length_m: 40, speed_mps: 5, laps: 1,
             takeoff_landing: false, hover_start_s: 2, hover_end_s: 2}
cameras:
  rate_hz: 5
  output: features
  list:
    - {name: cam0, look: down, position_m: [0.0, 0.0, 0.0]}
gnss: {rover: {rate_hz: 1}}
EOF
(cd "$work/sim-cwd" && env -u GVINS_DATA_DIR "$prefix/bin/gvins-sim" --config tiny.yaml -o out \
   >"$work/sim.log" 2>&1) || { tail -n 20 "$work/sim.log" >&2; fail "installed gvins-sim"; }
[ -s "$work/sim-cwd/out/gnss/rover.obs" ] && [ -s "$work/sim-cwd/out/gnss/nav.rnx" ] ||
  fail "installed gvins-sim wrote no GNSS files"
echo "  simulated: $(ls "$work/sim-cwd/out/gnss" | tr '\n' ' ')"
# ... and it is that data it reads: pointed elsewhere, the same run fails naming the file.
if (cd "$work/sim-cwd" && GVINS_DATA_DIR="$work/nowhere" "$prefix/bin/gvins-sim" --config tiny.yaml -o out2 \
      >"$work/sim2.log" 2>&1); then
  fail "gvins-sim ran without its navigation file"
fi
grep -q "$work/nowhere/gnss/nagoya_static_2024/base.nav.gz" "$work/sim2.log" ||
  { cat "$work/sim2.log" >&2; fail "gvins-sim's error does not name the missing navigation file"; }
echo "PASS"
