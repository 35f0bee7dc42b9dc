#!/usr/bin/env python3
"""GNSS/INS start over seeds (issue 43): the hand-held walk (or the car drive) of config/, mono,
replayed in motion in a GNSS mode once per GNSS/INS yaw bound (gnss_fusion.ins_start_yaw_sigma_deg,
docs/gnss_fusion.md "Starting from GNSS/INS"), and per seed: the time to initialise, the heading
error and heading sigma at the first pose, then over windows after the first frame the horizontal
antenna RMSE (global_ecef.csv against the true antenna), the heading RMSE and the mean yaw NEES
(heading error over the estimator's heading sigma from trajectory.cov.csv, squared). Then, per bound,
the median and range over seeds, and the per-seed difference against the first bound.

  bench/vio/gnss_start_seeds.py --bin build/bin [--ground walk] [--seeds 1-24] [--bounds 5,10]
                                [--start 8] [--duration 60] [--mode vio+dopp+psr] [--work DIR] [-j 2]

The datasets are those of bench/vio/init_sweep.py (120 m of config/handheld_walk.yaml, 600 m of
config/car_city_drive.yaml); the heading is that of the IMU in ENU, so it is evaluated only where
the estimator runs in ENU from its start (the GNSS/INS start; a visual start leaves NaN).
Progress to stderr, the table to stdout.
"""
import argparse
import bisect
import concurrent.futures
import math
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import init_sweep  # noqa: E402  (the ground datasets)

WINDOWS = [(10.0, 20.0), (20.0, 40.0), (40.0, 60.0)]  # s after the first frame
NAN = float("nan")


def rows(path, sep=","):
    with open(path) as f:
        return [[float(x) for x in (l.split(sep) if sep else l.split())] for l in f if l.strip() and not l.startswith("#")]


def quat(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def tr(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def dataset_frame(d):
    """R_ecef_local of a gvins-sim dataset (dataset.yaml, row-major): ENU at its origin."""
    R = None
    for line in open(os.path.join(d, "dataset.yaml")):
        if line.strip().startswith("R_ecef_local:"):
            v = [float(x) for x in line.split("[")[1].split("]")[0].split(",")]
            R = [v[0:3], v[3:6], v[6:9]]
    return R


def evaluate(d, out, t_first):
    """Figures of one replay (see the docstring); t_first: first frame, s (GPST since 1980)."""
    truth = rows(os.path.join(d, "truth", "groundtruth_ecef.csv"))
    tt = [r[0] * 1e-9 for r in truth]
    at = lambda t: truth[min(len(tt) - 1, bisect.bisect_left(tt, t - 1e-4))]  # the sample at t (200 Hz)
    R_EN = dataset_frame(d)
    R_NE = tr(R_EN)
    m = init_sweep.metrics(os.path.join(out, "metrics.csv")) if os.path.exists(os.path.join(out, "metrics.csv")) else {}
    res = {"init": m.get("init_s", NAN), "h0": NAN, "s0": NAN}
    head = []  # (t after the first frame, heading error deg, heading sigma deg)
    # In ENU from the start: the frame "initialised" with the state (a GNSS/INS start between two
    # frames counts from the epoch), not later by the frame initialisation of a visual start.
    if os.path.exists(os.path.join(out, "trajectory.cov.csv")) and m.get("frame_init_s", NAN) <= m.get("init_s", NAN):
        for p, c in zip(rows(os.path.join(out, "trajectory.tum"), None), rows(os.path.join(out, "trajectory.cov.csv"))):
            g = at(p[0])
            R_NB = mul(R_NE, quat(*g[7:11]))
            R = quat(p[7], p[4], p[5], p[6])
            e = math.remainder(math.atan2(R[1][0], R[0][0]) - math.atan2(R_NB[1][0], R_NB[0][0]), 2 * math.pi)
            C = [[c[1 + 6 * i + j] for j in range(3)] for i in range(3)]
            s = math.sqrt(mul(mul(R, C), tr(R))[2][2])
            head.append((p[0] - t_first, math.degrees(e), math.degrees(s)))
    if head:
        res["h0"], res["s0"] = head[0][1], head[0][2]
    hor = []
    if os.path.exists(os.path.join(out, "global_ecef.csv")):
        for r in rows(os.path.join(out, "global_ecef.csv")):
            t = r[0] * 604800.0 + r[1]
            g = at(t)
            e = [sum(R_NE[i][k] * (r[2 + k] - g[11 + k]) for k in range(3)) for i in range(3)]
            hor.append((t - t_first, math.hypot(e[0], e[1])))
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v)) if v else NAN
    for a, b in WINDOWS:
        w = [h for h in head if a <= h[0] < b]
        res["hdg %g-%g" % (a, b)] = rms([h[1] for h in w])
        res["nees %g-%g" % (a, b)] = sum((h[1] / h[2]) ** 2 for h in w) / len(w) if w else NAN
        res["hor %g-%g" % (a, b)] = rms([h[1] for h in hor if a <= h[0] < b])
    return res


def run(a, seed, bound, cfg):
    name, text = init_sweep.dataset(a.ground, "mono", "motion", 0.0, seed)
    d = os.path.join(a.work, name)
    if not os.path.isdir(os.path.join(d, "gnss")):
        yml = d + ".yaml"
        with open(yml, "w") as f:
            f.write(text())
        subprocess.run([os.path.join(a.bin, "gvins-sim"), "--config", yml, "-o", d], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = os.path.join(a.work, "%s_%d_bound%g_out" % (a.ground, seed, bound))
    subprocess.run([os.path.join(a.bin, "gvins-replay"), d, "--mode", a.mode, "-q", "-o", out, "--config", cfg,
                    "--start", "%g" % a.start, "--duration", "%g" % a.duration],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t_first = rows(os.path.join(d, "truth", "cam0_poses.csv"))[0][0] * 1e-9 + a.start
    r = evaluate(d, out, t_first)
    sys.stderr.write("  %s seed %d bound %g: init %.2f s\n" % (a.ground, seed, bound, r["init"]))
    return seed, bound, r


def seeds_of(text):
    out = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        out += list(range(int(lo), int(hi or lo) + 1))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--ground", default="walk", choices=sorted(init_sweep.GROUND))
    ap.add_argument("--seeds", default="1-24")
    ap.add_argument("--bounds", default="5,10", help="ins_start_yaw_sigma_deg values, deg")
    ap.add_argument("--start", type=float, default=8.0, help="replay from this many s after the first frame")
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--mode", default="vio+dopp+psr")
    ap.add_argument("--work", default=None, help="dataset folder (reused when present); default: a temporary one")
    ap.add_argument("-j", type=int, default=2, help="parallel replays (at most 2)")
    a = ap.parse_args()
    a.work = a.work or tempfile.mkdtemp(prefix="gnss_start_seeds_")
    os.makedirs(a.work, exist_ok=True)
    bounds = [float(b) for b in a.bounds.split(",")]
    cfgs = {}
    for b in bounds:
        cfgs[b] = os.path.join(a.work, "bound%g.yaml" % b)
        with open(cfgs[b], "w") as f:
            f.write("gnss_fusion:\n  ins_start_yaw_sigma_deg: %g\n" % b)
    seeds = seeds_of(a.seeds)
    for s in seeds:  # one simulation per dataset before the parallel replays
        run(a, s, bounds[0], cfgs[bounds[0]])
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, min(2, a.j))) as ex:
        res = list(ex.map(lambda j: run(a, j[0], j[1], cfgs[j[1]]), [(s, b) for b in bounds for s in seeds]))
    by = {(s, b): r for s, b, r in res}
    keys = list(res[0][2].keys())
    print("| bound [deg] | seed | " + " | ".join(keys) + " |")
    print("|---" * (len(keys) + 2) + "|")
    for b in bounds:
        for s in seeds:
            print("| %g | %d | " % (b, s) + " | ".join("%.3f" % by[(s, b)][k] for k in keys) + " |")
    for b in bounds:
        for label, f in (("median", statistics.median), ("min", min), ("max", max)):
            vals = [f([by[(s, b)][k] for s in seeds if not math.isnan(by[(s, b)][k])] or [NAN]) for k in keys]
            print("| %g | %s | " % (b, label) + " | ".join("%.3f" % v for v in vals) + " |")
        if b != bounds[0]:
            d = {k: [by[(s, b)][k] - by[(s, bounds[0])][k] for s in seeds] for k in keys}
            d = {k: [x for x in v if not math.isnan(x)] or [NAN] for k, v in d.items()}
            print("| %g - %g | median (min, max) | " % (b, bounds[0]) +
                  " | ".join("%.3f (%.3f, %.3f)" % (statistics.median(d[k]), min(d[k]), max(d[k])) for k in keys) + " |")


if __name__ == "__main__":
    main()
