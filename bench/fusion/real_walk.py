#!/usr/bin/env python3
"""The real u-blox + MEMS IMU walk (../shared/data/gnss_imu/rtklibexplorer_walk_0827, a copy in
tests/data) through the camera-less fusion (gvins-replay on an IMU + GNSS dataset), beside our SPP
and RTKLIB's SPP on the same receiver, all against the receiver's own real-time RTK track (its
fixed epochs; UBX-NAV-PVT with ellipsoidal heights through gvins-ubx to-pos, walk_reference.py),
and the drift of the fused track through simulated 15 s GNSS outages.

    bench/fusion/real_walk.py [--build DIR] [-o OUT] [--markdown FILE]

Writes the reference OUT/walk_reference.pos, builds OUT/dataset (mav0/imu0 from the raw IMU log and its time tags with gvins-imu, the UBX log as
the rover), runs gvins-replay in the GNSS modes that need no base (vio+dopp; vio+dopp+psr with the
broadcast ionosphere and with ionosphere-free pairs; vio+dopp+ppp on broadcast orbits and clocks,
as no precise products of the day are bundled), gvins-spp on the UBX log, and RTKLIB (convbin +
rnx2rtkp -p 0, when installed) on the same log. Table 1: epochs compared, mean satellites used,
horizontal and vertical RMS and 95 % of the errors, velocity RMS. Table 2: vio+dopp+psr and
vio+dopp+ppp again with GNSS removed in 15 s windows (gvins-replay --gnss-outage), the antenna
error at the last epoch before each window and at its end, and the drift between them; the
reference there is any RTK epoch (fixed or float: decimetres against metres of drift), with the
horizontal σ the run reported at the window's end. Table 3 (consistency of the reported
covariances, walk_compare.py consistency and outage-sigma): velocity NEES and heading error
against σ on the RTK track, the horizontal position NEES about the mean offset, and the drift
over σ of a 15 s outage placed every 5 s from 35 to 105 s (--no-sweep: without the sweep).
Progress on stderr.
"""
import argparse
import datetime
import math
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from walk_reference import (REFERENCE_TEXT, ROOT, UBX, WALK, error_enu, make_reference,  # noqa: E402
                            matched_errors, read_pos)
sys.path.insert(0, os.path.join(ROOT, "tests", "fusion"))
import walk_compare  # noqa: E402  (the covariance checks the real-walk tests assert)


def note(msg):
    print("[real_walk] " + msg, file=sys.stderr, flush=True)


def run(cmd, **kw):
    note(" ".join(cmd))
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


# Outage placements (s after the first frame; the tight stage starts about 30 s in), 15 s each,
# one run per placement so that an outage's recovery does not carry into the next.
OUTAGES = [(40.0, 15.0), (60.0, 15.0), (80.0, 15.0), (100.0, 15.0)]
# The sweep of the consistency summary: a 15 s outage starting every 5 s from 35 to 105 s.
SWEEP = [float(s) for s in range(35, 106, 5)]
WEEK = 604800.0


def compare(path, ref, sats=None):
    """(epochs, mean satellites, H RMS, V RMS, H 95 %, V 95 %, velocity RMS, mean ENU error,
    H and V standard deviation about that mean) on the reference's fixed epochs; `sats`:
    {time key: satellites used} (else the .pos file's ns column)."""
    est = read_pos(path)
    m = matched_errors(est, ref)
    errs = [x[1] for x in m]
    dv = [x[2] for x in m if x[2] is not None]
    ns = [sats.get(k, 0) if sats is not None else est[k][5] for k, _, _ in m]
    if not errs:
        return None
    n = len(errs)
    hs = [x[0] ** 2 + x[1] ** 2 for x in errs]
    vs = [x[2] ** 2 for x in errs]
    mean = [sum(x[i] for x in errs) / n for i in range(3)]
    sh = math.sqrt(sum((x[0] - mean[0]) ** 2 + (x[1] - mean[1]) ** 2 for x in errs) / n)
    sv = math.sqrt(sum((x[2] - mean[2]) ** 2 for x in errs) / n)
    p95 = lambda xs: sorted(math.sqrt(x) for x in xs)[int(0.95 * (len(xs) - 1))]
    rms = lambda xs: math.sqrt(sum(xs) / len(xs)) if xs else float("nan")
    return n, sum(ns) / n, rms(hs), rms(vs), p95(hs), p95(vs), rms(dv), mean, sh, sv


def epoch_sats(out_dir, column):
    """{time key: rows used} of a gvins-replay gnss_epochs.csv column (3: psr, 5: Doppler)."""
    sats = {}
    for line in open(os.path.join(out_dir, "gnss_epochs.csv")):
        if line.startswith("#"):
            continue
        t = line.split(",")
        week, tow = int(t[0]), float(t[1])
        date = datetime.date(1980, 1, 6) + datetime.timedelta(days=week * 7 + int(tow // 86400))
        sod = tow - 86400 * int(tow // 86400)
        sats[(date.strftime("%Y/%m/%d"), round(sod * 20) / 20.0)] = int(t[column])
    return sats


def first_frame_tow(out_dir):
    for line in open(os.path.join(out_dir, "timing.csv")):
        if not line.startswith("#"):
            return (int(line.split(",")[0]) * 1e-9) % WEEK
    raise RuntimeError("no frame in timing.csv")


def outage_drift(out_dir, ref, tow0, start, length):
    """(H error before, H and V error at the end, H and V drift) of the window [start, start +
    length) against the reference's fixed and float epochs, or None."""
    by_tow = {tow_of(k): (k, e) for k, e in read_pos(out_dir + "/global.pos").items()}
    inside = sorted(t for t in by_tow if start <= t - tow0 < start + length)
    before = sorted(t for t in by_tow if t - tow0 < start)
    pick = lambda t: by_tow[t] if t is not None and by_tow[t][0] in ref and ref[by_tow[t][0]][3] <= 2 else None
    end = pick(inside[-1] if inside else None)
    pre = pick(before[-1] if before else None)
    if not end or not pre:
        return None
    e0 = error_enu(pre[1], ref[pre[0]])
    e1 = error_enu(end[1], ref[end[0]])
    return (math.hypot(e0[0], e0[1]), math.hypot(e1[0], e1[1]), abs(e1[2]), math.hypot(e1[0] - e0[0], e1[1] - e0[1]),
            abs(e1[2] - e0[2]))


def tow_of(key):
    """Seconds of the GPS week of a read_pos key (date string, seconds of day)."""
    y, m, d = (int(x) for x in key[0].split("/"))
    days = (datetime.date(y, m, d) - datetime.date(1980, 1, 6)).days
    return (days % 7) * 86400 + key[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("-o", dest="out", default=os.path.join(ROOT, "out", "real_walk"))
    ap.add_argument("--markdown")
    ap.add_argument("--no-sweep", action="store_true", help="no outage sweep in the consistency table")
    a = ap.parse_args()
    b = os.path.join(os.path.abspath(a.build), "bin")
    out = os.path.abspath(a.out)
    ds = os.path.join(out, "dataset")
    shutil.rmtree(ds, ignore_errors=True)
    os.makedirs(os.path.join(ds, "mav0", "imu0"))
    run([os.path.join(b, "gvins-imu"), "convert", os.path.join(WALK, "imu_1730.csv"), "--tag",
         os.path.join(WALK, "imu_1730.csv.tag"), "--columns", "ax,ay,az,gx,gy,gz,t", "--time", "counter-ms",
         "--accel-unit", "g", "--gyro-unit", "deg/s", "-o", os.path.join(ds, "mav0", "imu0", "data.csv")])
    shutil.copy(os.path.join(WALK, "imu0_sensor.yaml"), os.path.join(ds, "mav0", "imu0", "sensor.yaml"))
    rows = []
    rtklib_nav = None
    ref_path = make_reference(b, out, run)
    ref = read_pos(ref_path)
    single = os.path.join(out, "single_frequency.yaml")
    with open(single, "w") as f:
        f.write("gnss_fusion:\n  ionosphere: broadcast\n")
    modes = [("fused vio+dopp (camera-less)", "vio+dopp", []),
             ("fused vio+dopp+psr, broadcast ionosphere", "vio+dopp+psr", ["--config", single]),
             ("fused vio+dopp+psr, ionosphere-free", "vio+dopp+psr", []),
             ("fused vio+dopp+ppp, broadcast orbits/clocks (no products)", "vio+dopp+ppp", [])]
    replay = lambda mode, extra, o: run([os.path.join(b, "gvins-replay"), ds, "--mode", mode, "--rover", UBX, "--no-eval",
                                         "-q", "--imu-gaps", "warn", "-o", o] + extra)
    runs = {}
    for label, mode, extra in modes:
        o = os.path.join(out, mode + ("_sf" if extra else ""))
        replay(mode, extra, o)
        runs[label] = o
        rows.append((label, compare(os.path.join(o, "global.pos"), ref, epoch_sats(o, 5 if mode == "vio+dopp" else 3))))
    for label, extra in [("gvins-spp (own SFRBX ephemerides, broadcast ionosphere)", []),
                         ("gvins-spp --iono dual-frequency --freq 2", ["--iono", "dual-frequency", "--freq", "2"])]:
        spp = os.path.join(out, "spp%s.pos" % ("_if" if extra else ""))
        run([os.path.join(b, "gvins-spp"), UBX, "-o", spp] + extra)
        rows.append((label, compare(spp, ref)))
    if shutil.which("convbin") and shutil.which("rnx2rtkp"):
        conv = os.path.join(out, "convbin")
        os.makedirs(conv, exist_ok=True)
        obs, nav = os.path.join(conv, "walk.obs"), os.path.join(conv, "walk.nav")
        run(["convbin", "-r", "ubx", "-v", "3.04", "-od", "-os", "-o", obs, "-n", nav, UBX])
        rpos = os.path.join(out, "rtklib_spp.pos")
        run(["rnx2rtkp", "-p", "0", "-t", "-sys", "G,R,E,J,C", "-o", rpos, obs, nav])
        rows.append(("RTKLIB SPP (convbin + rnx2rtkp -p 0)", compare(rpos, ref)))
        sats = {}
        for line in open(nav):
            if len(line) > 3 and line[0] in "GRECJ" and line[1:3].isdigit() and line[3] == " ":
                sats.setdefault(line[0], set()).add(line[:3])
        rtklib_nav = ", ".join(f"{k} {len(v)}" for k, v in sorted(sats.items())) or "none"
    table = ["| solution | epochs (ref. fixed) | satellites | H RMS [m] | V RMS [m] | H 95 % [m] | V 95 % [m] | vel. RMS [m/s] "
             "| mean error E, N, U [m] | σ H, σ V about the mean [m] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for label, r in rows:
        if r is None:
            table.append(f"| {label} | 0 | | | | | | | | |")
        else:
            table.append(f"| {label} | {r[0]} | {r[1]:.1f} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.2f} | {r[5]:.2f} | {r[6]:.3f} "
                         f"| {r[7][0]:.2f}, {r[7][1]:.2f}, {r[7][2]:.2f} | {r[8]:.2f}, {r[9]:.2f} |")
    drift = ["| mode | outage [s after first frame] | H error before [m] | H error at end [m] | V error at end [m] "
             "| H drift [m] | V drift [m] | H σ at end [m] | drift / σ | H error 10 s after [m] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for label, mode, extra in modes[1:2] + modes[3:4]:
        for start, length in OUTAGES:
            o = os.path.join(out, f"{mode}_outage{start:g}")
            replay(mode, extra + ["--gnss-outage", f"{start:g},{length:g}"], o)
            tow0 = first_frame_tow(o)
            r = outage_drift(o, ref, tow0, start, length)
            after = outage_drift(o, ref, tow0, start + length, 10.0)  # recovery: error 10 s after the end
            span = f"{start:g}–{start + length:g}"
            if r is None:
                drift.append(f"| {label} | {span} | | | | | | | | |")
            else:
                rec = f"{after[1]:.2f}" if after else ""
                _, sigma, ratio = walk_compare.outage_sigma(o, ref_path, start, length)
                drift.append(f"| {label} | {span} | {r[0]:.2f} | {r[1]:.2f} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.2f} "
                             f"| {sigma:.2f} | {ratio:.2f} | {rec} |")
    cons = consistency_table(modes[1:], runs, ref_path, replay, out, a.no_sweep)
    text = "\n".join(table) + "\n"
    dtext = "\n".join(drift) + "\n"
    print(text)
    print(dtext)
    print(cons)
    if a.markdown:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        with open(a.markdown, "w") as f:
            f.write("# The real u-blox + MEMS IMU walk, camera-less\n\n")
            f.write(f"Written by `bench/fusion/real_walk.py --markdown {a.markdown}` at commit {commit}. Do not edit by hand.\n")
            f.write(f"Reference: {REFERENCE_TEXT}, its fixed epochs (Q = 1).\n")
            f.write("Satellites: mean per compared epoch (fused: pseudorange rows applied, Doppler rows in vio+dopp;\n"
                    "SPP: the .pos `ns` column). The mean error and the spread about it are printed because every\n"
                    "solution, ours and RTKLIB's, sits at nearly the same horizontal offset from the reference (6-10 m,\n"
                    "mostly east and north) while scattering by metres at most about it. The reference is an RTK\n"
                    "solution relative to a base station whose data and coordinates are not published: an RTK track\n"
                    "inherits any error of the base coordinates the base announced, as one constant shift, and every\n"
                    "absolute solution (code positioning on broadcast orbits) sees that shift as its error. The RMS\n"
                    "columns therefore hold the offset; σ about the mean is the part a solution controls. The same\n"
                    "unknown shift may have a vertical part, so the mean U error is not a measured bias either. What\n"
                    "the ionosphere-free height depends on (GPS L1/L2C against L1/L5 pairs and their group delays)\n"
                    "is in docs/gnss_fusion.md (Measurement rows, psr).\n"
                    "The publisher's `gnss_1730_sf.pos` holds the same solutions with mean-sea-level heights (NAV-PVT\n"
                    "hMSL, 21.39 m above the ellipsoidal heights here); against it every vertical error would carry a\n"
                    "spurious -21.39 m, so it is not the reference.\n\n")
            f.write(text)
            f.write("\nvio+dopp+ppp runs on broadcast orbits and clocks: no precise products (SP3, clock, OSB) of\n"
                    "2025-08-28 are bundled, so it is float PPP without products, i.e. ionosphere-free code and\n"
                    "carrier phase with a float ambiguity per arc, limited by the broadcast orbit/clock errors and\n"
                    "the pair's amplified noise; BeiDou, tracked on B1C/B2a/B3I with D1/D2 records, has no\n"
                    "ionosphere-free pair with a broadcast group delay and enters single-frequency (B3I).\n"
                    "GPS and Galileo have no broadcast ionosphere in this log (no GPS page 18 in its 134 s), so the\n"
                    "'broadcast ionosphere' rows correct only BeiDou (its own model, on B3I).\n")
            if rtklib_nav:
                f.write(f"RTKLIB's input is convbin's conversion of the log: its navigation file holds the satellites\n"
                        f"{rtklib_nav} (system letter, satellites with ephemerides) and its observations no BeiDou,\n"
                        f"so RTKLIB solves with the few GPS satellites it has ephemerides for.\n")
            f.write("\n## GNSS outages of 15 s\n\n")
            f.write("GNSS removed in one window per run (`gvins-replay --gnss-outage START,15`); errors against the\n"
                    "reference's fixed or float epoch at the last epoch before the window and at the window's last\n"
                    "epoch; drift = the change of the error between the two (the reference's offset cancels);\n"
                    "the last column is the error at the last epoch of the 10 s after the window (re-acquisition).\n\n")
            f.write(dtext)
            f.write("\n## Consistency of the reported uncertainty\n\n")
            f.write("The σ columns of `global.pos` (the estimator's antenna position and velocity covariance) against\n"
                    "the reference (`tests/fusion/walk_compare.py consistency` and `outage-sigma`). Velocity: the\n"
                    "reference is the difference of the fixed positions 0.25 s before and after each fixed epoch (the\n"
                    "mean velocity over 0.5 s), the run's the trapezoidal mean of its velocities at the same three\n"
                    "epochs, with the covariance reported at the middle one; the receiver's own NAV-PVT velocity lags\n"
                    "its positions by about 0.14 s (0.1 m/s RMS per axis against their differences, 0.04 m/s once\n"
                    "shifted), so it is not the reference. The reference's noise (millimetres per epoch) is neglected:\n"
                    "NEES figures are upper bounds. NEES: mean of eᵀP⁻¹e, 3 for the 3-D velocity (share within\n"
                    "χ²₃'s 95 % bound 7.81: 0.95) and 2 for the horizontal position error about its mean over the run\n"
                    "(the reference's unknown offset removed). Velocity heading ψ = atan2(vE, vN) where the reference\n"
                    "moves faster than 0.8 m/s, σψ from the velocity covariance: mean |e|/σψ is 0.80 and the share\n"
                    "within 2σψ 0.95 for an honest σ. Outages: 15 s windows starting every 5 s from 35 to 105 s, one\n"
                    "per run; drift as in the table above, σ = √(σE² + σN²) reported at the window's last epoch\n"
                    "(mean drift/σ 0.89 for an honest σ, Rayleigh). The IMU noise the estimator is told is the\n"
                    "recording's (`imu0_sensor.yaml`, `bench/fusion/walk_imu_noise.py`: the sensor's noise at rest\n"
                    "plus the sample-time noise of its log).\n\n")
            f.write(cons)


def consistency_table(modes, runs, ref_path, replay, out, no_sweep):
    """Markdown table of walk_compare's consistency figures for the runs of `modes` and, for the
    psr (broadcast ionosphere) and ppp modes, the outage sweep."""
    lines = ["| solution | velocity NEES (3) | share ≤ 7.81 | heading \\|e\\|/σ (0.80) | share ≤ 2σ | heading error RMS [°] "
             "| heading σ RMS [°] | H position NEES about the mean (2) | outages: drift mean [m] | drift/σ mean (0.89) "
             "| drift/σ max | outages with drift > 3σ |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for k, (label, mode, extra) in enumerate(modes):
        c = walk_compare.consistency(runs[label], ref_path)
        sweep = ""
        if not no_sweep and k != 1:  # not the ionosphere-free psr run: same IMU, same rows as the broadcast one
            d = []
            for start in SWEEP:
                o = os.path.join(out, f"{mode}_sweep{start:g}")
                replay(mode, extra + ["--gnss-outage", f"{start:g},15"], o)
                d.append(walk_compare.outage_sigma(o, ref_path, start, 15.0))
            sweep = (f"{sum(x[0] for x in d) / len(d):.2f} | {sum(x[2] for x in d) / len(d):.2f} | "
                     f"{max(x[2] for x in d):.2f} | {sum(x[2] > 3 for x in d)} of {len(d)}")
        else:
            sweep = " | | | "
        lines.append(f"| {label} | {c['nees']:.2f} | {c['share95']:.2f} | {c['heading_ratio']:.2f} | {c['heading_share2']:.2f} "
                     f"| {c['heading_rms_deg']:.2f} | {c['heading_sigma_deg']:.2f} | {c['pos_nees']:.2f} | {sweep} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
