#!/usr/bin/env python3
"""The real u-blox + MEMS IMU walk (../shared/data/gnss_imu/rtklibexplorer_walk_0827, a copy in
tests/data) with simulated vision: gvins-sim drives a stereo pair along the trajectory fitted to
the publisher's RTK track and the real IMU (config/real_walk_0827_vision.yaml, trajectory type
gnss_track), keeping the real IMU samples and the real UBX log; gvins-replay runs every GNSS mode
that needs no base station on it and on the same dataset without its cameras (camera-less), and
the antenna is compared with the RTK track on its fixed epochs.

    bench/fusion/real_walk_vision.py [--build DIR] [-o OUT] [--markdown FILE]

Steps: gvins-imu puts the raw IMU log on GPST (its RTKLIB time tags); gvins-sim writes
OUT/dataset (feature tracks, gnss/rover.ubx); OUT/camera_less is a copy without mav0/cam*; then
gvins-replay per mode and dataset. Columns: epochs compared (reference Q = 1), horizontal and
vertical RMS, 95 % of the horizontal error, velocity RMS against the .pos velocity, the
horizontal RMS after removing the mean offset, and the local (4-DoF aligned) horizontal RMSE and
velocity RMSE against the fitted trajectory the cameras followed (gvins-replay metrics.csv).
Progress on stderr.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "data")
WALK = os.path.join(DATA, "gnss_imu", "walk_0827")
REF = os.path.join(WALK, "gnss_1730_sf.pos")
CONFIG = os.path.join(ROOT, "config", "real_walk_0827_vision.yaml")
A = 6378137.0
F = 1.0 / 298.257223563
MODES = [("vio", "vio", False), ("vio+gpsvel", "vio+gpsvel", False), ("vio+dopp", "vio+dopp", False),
         ("vio+dopp+psr, ionosphere-free", "vio+dopp+psr", False),
         ("vio+dopp+psr, broadcast ionosphere", "vio+dopp+psr", True),
         ("vio+dopp+psr-nointegration, broadcast ionosphere", "vio+dopp+psr-nointegration", True),
         ("vio+dopp+ppp, broadcast orbits/clocks", "vio+dopp+ppp", False)]


def note(msg):
    print("[real_walk_vision] " + msg, file=sys.stderr, flush=True)


def run(cmd):
    note(" ".join(cmd))
    return subprocess.run(cmd, check=True, capture_output=True, text=True)


def llh_to_ecef(lat, lon, h):
    e2 = F * (2 - F)
    la, lo = math.radians(lat), math.radians(lon)
    n = A / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo), (n * (1 - e2) + h) * math.sin(la))


def enu(d, lat, lon):
    la, lo = math.radians(lat), math.radians(lon)
    e = -math.sin(lo) * d[0] + math.cos(lo) * d[1]
    n = -math.sin(la) * math.cos(lo) * d[0] - math.sin(la) * math.sin(lo) * d[1] + math.cos(la) * d[2]
    u = math.cos(la) * math.cos(lo) * d[0] + math.cos(la) * math.sin(lo) * d[1] + math.sin(la) * d[2]
    return e, n, u


def read_pos(path):
    """{(date, time key): (lat, lon, h, Q, (ve, vn, vu) or None)} of a lat/lon/h .pos file (GPST)."""
    out = {}
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        t = line.split()
        key = round((int(t[1][0:2]) * 3600 + int(t[1][3:5]) * 60 + float(t[1][6:])) * 20) / 20.0
        vel = None
        if len(t) >= 18:  # date time lat lon h Q ns 6 sigmas age ratio vn ve vu ...
            try:
                vel = (float(t[16]), float(t[15]), float(t[17]))
            except ValueError:
                vel = None
        out[(t[0], key)] = (float(t[2]), float(t[3]), float(t[4]), int(float(t[5])), vel)
    return out


def compare(path, ref):
    """Errors of a solution at the reference's fixed epochs: n, H RMS, V RMS, H 95 %, velocity
    RMS, H RMS about the mean horizontal offset, mean offset (E, N)."""
    if not os.path.exists(path):
        return None
    est = read_pos(path)
    d, dv = [], []
    for k, r in ref.items():
        if r[3] != 1 or k not in est:
            continue
        e = est[k]
        a, b = llh_to_ecef(*e[:3]), llh_to_ecef(*r[:3])
        d.append(enu([a[i] - b[i] for i in range(3)], r[0], r[1]))
        if e[4] and r[4] and all(not math.isnan(x) for x in e[4]):
            dv.append(sum((e[4][i] - r[4][i]) ** 2 for i in range(3)))
    if not d:
        return None
    n = len(d)
    rms = lambda xs: math.sqrt(sum(xs) / len(xs)) if xs else float("nan")
    h2 = [x[0] ** 2 + x[1] ** 2 for x in d]
    me, mn = sum(x[0] for x in d) / n, sum(x[1] for x in d) / n
    hc = [(x[0] - me) ** 2 + (x[1] - mn) ** 2 for x in d]
    h95 = sorted(math.sqrt(x) for x in h2)[int(0.95 * (n - 1))]
    return n, rms(h2), rms([x[2] ** 2 for x in d]), h95, rms(dv), rms(hc), (me, mn)


def metrics(path):
    out = {}
    if os.path.exists(path):
        for line in open(path):
            k, _, v = line.strip().partition(",")
            try:
                out[k] = float(v)
            except ValueError:
                pass
    return out


def fit_report(dataset_yaml):
    """The gnss_track fit's figures from dataset.yaml (flat 'key: value' lines of its trajectory section)."""
    keys = ("track_epochs", "initial_yaw_deg", "fitted_gyro_bias_radps", "fitted_accel_bias_mps2",
            "velocity_increment_residual_rms_mps", "track_residual_rms_m", "track_residual_max_m",
            "accel_residual_rms_mps2", "forward_axis_body", "path_length_m", "duration_s")
    out = {}
    for line in open(dataset_yaml):
        k, _, v = line.strip().partition(":")
        if k in keys and k not in out:
            v = v.split("#")[0].strip()
            nums = v.strip("[]").split(",")
            try:
                v = ", ".join("%.4g" % float(x) for x in nums)
            except ValueError:
                pass
            out[k] = v
    return out


def build_dataset(b, out):
    imu = os.path.join(out, "imu0.csv")
    run([os.path.join(b, "gvins-imu"), "convert", os.path.join(WALK, "imu_1730.csv"), "--tag",
         os.path.join(WALK, "imu_1730.csv.tag"), "--columns", "ax,ay,az,gx,gy,gz,t", "--time", "counter-ms",
         "--accel-unit", "g", "--gyro-unit", "deg/s", "-o", imu])
    # The shipped scenario with its file paths made absolute (it is written into OUT).
    cfg_dir = os.path.dirname(CONFIG)
    lines = []
    for line in open(CONFIG):
        key = line.strip().split(":")[0]
        if key == "imu_csv":
            line = "  imu_csv: " + imu + "\n"
        elif key in ("pos_file", "rover_log"):
            rel = line.split(":", 1)[1].strip()
            line = "  %s: %s\n" % (key, os.path.normpath(os.path.join(cfg_dir, rel)))
        lines.append(line)
    scenario = os.path.join(out, "scenario.yaml")
    with open(scenario, "w") as f:
        f.writelines(lines)
    ds = os.path.join(out, "dataset")
    run([os.path.join(b, "gvins-sim"), "--config", scenario, "--force", "-o", ds])
    cl = os.path.join(out, "camera_less")
    shutil.rmtree(cl, ignore_errors=True)
    shutil.copytree(ds, cl, ignore=lambda d, names: [n for n in names if n.startswith("cam") and d.endswith("mav0")])
    return ds, cl


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("-o", dest="out", default=os.path.join(ROOT, "out", "real_walk_vision"))
    ap.add_argument("--markdown")
    a = ap.parse_args()
    b = os.path.join(os.path.abspath(a.build), "bin")
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    ds, cl = build_dataset(b, out)
    single = os.path.join(out, "single_frequency.yaml")
    with open(single, "w") as f:
        f.write("gnss_fusion:\n  ionosphere: broadcast\n")
    ref = read_pos(REF)
    rows = []
    for label, mode, sf in MODES:
        for rig, folder in (("stereo", ds), ("camera-less", cl)):
            o = os.path.join(out, "%s_%s%s" % (os.path.basename(folder), mode, "_sf" if sf else ""))
            run([os.path.join(b, "gvins-replay"), folder, "--mode", mode, "--rover", os.path.join(folder, "gnss", "rover.ubx"),
                 "--truth-pos", REF, "--imu-gaps", "warn", "-q", "-o", o] + (["--config", single] if sf else []))
            rows.append((label, rig, compare(os.path.join(o, "global.pos"), ref), metrics(os.path.join(o, "metrics.csv"))))
    table = ["| mode | rig | epochs (ref. fixed) | H RMS [m] | V RMS [m] | H 95 % [m] | vel. RMS [m/s] | H RMS about mean [m] "
             "| mean offset E, N [m] | local H RMSE [m] | local vel. RMSE [m/s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, rig, r, m in rows:
        loc = "%.2f | %.3f" % (m.get("local_horizontal_rmse_m", float("nan")), m.get("local_velocity_rmse_mps", float("nan")))
        if r is None:
            table.append(f"| {label} | {rig} | 0 | | | | | | | {loc} |")
        else:
            table.append(f"| {label} | {rig} | {r[0]} | {r[1]:.2f} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.3f} | {r[5]:.2f} "
                         f"| {r[6][0]:.1f}, {r[6][1]:.1f} | {loc} |")
    text = "\n".join(table) + "\n"
    fit = fit_report(os.path.join(ds, "dataset.yaml"))
    fit_text = "\n".join("| %s | %s |" % (k, v) for k, v in fit.items())
    print(text)
    print(fit_text)
    if a.markdown:
        write_page(a.markdown, text, fit_text)


def write_page(path, table, fit_text):
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    with open(path, "w") as f:
        f.write("# The real u-blox + MEMS IMU walk with simulated vision\n\n")
        f.write(f"Written by `bench/fusion/real_walk_vision.py --markdown {path}` at commit {commit}. Do not edit by hand.\n\n")
        f.write(PAGE_INTRO)
        f.write("\n## The trajectory fitted to the RTK track and the real IMU (dataset.yaml)\n\n| key | value |\n|---|---|\n")
        f.write(fit_text + "\n")
        f.write("\n## Against the publisher's RTK track, its fixed epochs\n\n")
        f.write(table)
        f.write(PAGE_NOTES)


PAGE_INTRO = """Data: `tests/data/gnss_imu/walk_0827` and `tests/data/ubx/gnss_1730.ubx` (u-blox X20P, 4 Hz UBX
with its own SFRBX navigation, MEMS IMU; 2025-08-28, 132 s of a hand-held backyard walk). Dataset:
`config/real_walk_0827_vision.yaml` (gvins-sim trajectory type `gnss_track`,
docs/dataset_format.md): the real IMU samples and the real UBX log are kept; only the stereo
feature tracks (10 Hz, 10 cm baseline, tilted 30 deg down over ground landmarks with 0.5 m relief,
0.5 px noise) are simulated along the trajectory fitted to the RTK track and the real IMU.
"Camera-less" is the same folder without `mav0/cam*`. Every GNSS row uses the real rover
observations; the reference is the publisher's RTKLIB RTK track (`gnss_1730_sf.pos`, Q = 1).
"Local" columns are `gvins-replay`'s 4-DoF aligned trajectory against the fitted trajectory the
cameras followed (the simulation truth; it follows the RTK track to 1.4 cm RMS, see below).
"""

PAGE_NOTES = """
Modes that do not apply: `vio+dopp+dpsr` and `vio+dopp+ddcp` need the base station, whose data the
publisher did not release. `vio+dopp+ppp` needs precise orbits and clocks or an SSR stream; none
for 2025-08-28 is in the repository, so its row runs on the broadcast ephemerides of the log
(gvins-replay warns). `vio` has no global solution.

Reading the table: every fused solution, with or without cameras, sits metres from the RTK track
(as do both SPPs of [real_walk.md](real_walk.md), 8.2-8.4 m horizontal RMS), mostly as a nearly
constant horizontal offset ("mean offset"); the spread about it ("H RMS about mean") is what the
receiver's code errors and the estimator leave, and there the cameras help most (vio+gpsvel
0.11 m against 0.54 m). Whether the offset belongs to the receiver's pseudoranges or to the
reference (a base position the publisher did not give) cannot be decided from these files.
The cameras lower the velocity error in every GNSS mode (0.19-0.22 m/s against 0.23-0.30 m/s
camera-less, and 8.3 m/s in the diverged camera-less run below). One
row is worse with them: in `vio+dopp` (no absolute position after the frame initialisation) the
stereo run's vertical error grows from -12.5 m to -40.6 m over the compared epochs while the
camera-less one stays between -12.5 m and -15.9 m, although the stereo run's local trajectory is
right to 6 cm vertically (the drift is in its global anchoring, which Doppler rows observe only
weakly); not investigated further. The `psr-nointegration` ablation (rows at the newest state, no
IMU integration to the measurement time) gives the psr figures with stereo, but diverges
camera-less (203 m horizontal RMS; not investigated).
The camera-less runs are sensitive to where the IMU log starts: this dataset begins at
17:30:41.5 GPST; started at 17:30:41.0 the camera-less estimator loses its attitude (45 of 526
GNSS epochs used), with the stereo tracks it does not.
"""


if __name__ == "__main__":
    main()
