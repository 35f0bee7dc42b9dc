#!/usr/bin/env python3
"""Initialisation sweep (issue 43): simulate short lawnmower flights (features only, GNSS rover at
5 Hz over the bundled Nagoya ephemerides) for the scenario families mono/stereo x {take-off from
the ground, hover start, start in cruise} at several heights and seeds, replay each in every
--modes (`vio`: vision only; a GNSS mode: the GNSS/INS start may start the estimator,
docs/gnss_fusion.md), and print the table: time to initialise, share of frames initialised, local
RMSE and drift and global RMSE after initialisation, estimator ms per frame before/after
initialisation, and the reasons while waiting.

  bench/vio/init_sweep.py --bin build/bin [--heights 20,60,100] [--seeds 1,2] [--modes vio,vio+dopp+psr]
                          [--work DIR] [-j 2] [--out docs/results/init_sweep.md]

The template is bench/vio/init/mono_takeoff_40m.yaml; 'stereo' adds cam1, 'hover' replaces the
take-off by a 3 s hover at height, 'cruise' replays the take-off flight from 3 s after the climb
(height / climb rate + 3 s + 2 s on the ground). Progress to stderr, the table to stdout.
"""
import argparse
import concurrent.futures
import csv
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
TEMPLATE = os.path.join(HERE, "init", "mono_takeoff_40m.yaml")
NAV = os.path.join(HERE, "..", "..", "tests", "data", "gnss", "nagoya_static_2024", "base.nav.gz")
CAM1 = "    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04], mount_rpy_deg: [-0.2, 0.3, -0.4]}\n"


def scenario(rig, start, height, seed):
    text = open(TEMPLATE).read()
    text = text.replace("height_m: 40", "height_m: %g" % height).replace("seed: 1", "seed: %d" % seed)
    text = text.replace("name: init_mono_takeoff_40m", "name: init_%s_%s_%gm" % (rig, start, height))
    text = text.replace("mono 40 m lawnmower with take-off", "%s %g m lawnmower, %s" % (rig, height, start))
    text = text.replace("gnss: none", "gnss:\n  navigation: %s\n  rover:\n    rate_hz: 5" % os.path.abspath(NAV))
    if rig == "stereo":
        cam0 = next(l for l in text.split("\n") if l.startswith("    - {name: cam0"))
        text = text.replace(cam0 + "\n", cam0 + "\n" + CAM1, 1)
    if start == "hover":
        text = text.replace("  wobble_deg: 0.3", "  wobble_deg: 0.3\n  takeoff_landing: false\n  hover_start_s: 3")
    return text


def metrics(path):
    out = {}
    with open(path) as f:
        for row in csv.reader(l for l in f if not l.startswith("#")):
            if len(row) == 2:
                try:
                    out[row[0]] = float(row[1])
                except ValueError:
                    pass
    return out


def run(args, rig, start, height, seed, mode):
    sim_start = "hover" if start == "hover" else "takeoff"
    name = "%s_%s_%g_%d" % (rig, sim_start, height, seed)
    data = os.path.join(args.work, name)
    if not os.path.isdir(os.path.join(data, "gnss")):
        yml = os.path.join(args.work, name + ".yaml")
        with open(yml, "w") as f:
            f.write(scenario(rig, sim_start, height, seed))
        subprocess.run([os.path.join(args.bin, "gvins-sim"), "--config", yml, "-o", data], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = os.path.join(args.work, "%s_%s_%g_%d_%s_out" % (rig, start, height, seed, mode.replace("+", "_")))
    cmd = [os.path.join(args.bin, "gvins-replay"), data, "--mode", mode, "-q", "-o", out]
    if start == "cruise":
        cmd += ["--start", "%g" % (2.0 + height / 3.0 + 3.0)]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    waiting = ""
    for line in p.stdout.splitlines():
        if line.startswith("initialisation"):
            waiting = line.split("waiting:", 1)[-1].strip() + waiting
        if line.startswith("GNSS/INS start waiting"):
            waiting += "; GNSS/INS: " + line.split("waiting", 1)[-1].strip()
    m = metrics(os.path.join(out, "metrics.csv")) if os.path.exists(os.path.join(out, "metrics.csv")) else {}
    sys.stderr.write("  %-7s %-8s %4g m seed %d %s: %s\n" % (rig, start, height, seed, mode, "ok" if m else "FAILED"))
    return (mode, rig, start, height, seed, m, waiting)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--heights", default="20,60,100")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--rigs", default="mono,stereo")
    ap.add_argument("--starts", default="takeoff,hover,cruise")
    ap.add_argument("--modes", default="vio,vio+dopp+psr")
    ap.add_argument("--out", default=None, help="also write the table (markdown with its command) here")
    ap.add_argument("--work", default=None, help="dataset folder (reused when present); default: a temporary one")
    ap.add_argument("-j", type=int, default=2, help="parallel replays (at most 2)")
    a = ap.parse_args()
    a.argv = ["--heights", a.heights, "--seeds", a.seeds, "--rigs", a.rigs, "--starts", a.starts, "--modes", a.modes]
    a.work = a.work or tempfile.mkdtemp(prefix="init_sweep_")
    os.makedirs(a.work, exist_ok=True)
    jobs = [(r, s, float(h), int(sd), md) for md in a.modes.split(",") for r in a.rigs.split(",")
            for s in a.starts.split(",") for h in a.heights.split(",") for sd in a.seeds.split(",")]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, min(2, a.j))) as ex:
        # Each dataset is simulated by the first replay that needs it (cruise reuses the take-off
        # flight): those go first, the rest after.
        first = {}
        for j in jobs:
            first.setdefault((j[0], "hover" if j[1] == "hover" else "takeoff", j[2], j[3]), j)
        head = list(first.values())
        results = list(ex.map(lambda j: run(a, *j), head))
        results += list(ex.map(lambda j: run(a, *j), [j for j in jobs if j not in head]))
    nan = float("nan")
    lines = ["| mode | rig | start | height [m] | seed | init after [s] | frames initialised | local RMSE [m] | drift [%] "
             "| global RMSE [m] | ms/frame before init | ms/frame after | waiting (frames) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for mode, rig, start, h, seed, m, waiting in sorted(results, key=lambda r: r[:5]):
        g = lambda k: m.get(k, nan)
        share = g("frames_initialized") / g("frames") if m.get("frames") else nan
        lines.append("| %s | %s | %s | %g | %d | %.2f | %.1f %% | %.3f | %.2f | %.3f | %.2f | %.2f | %s |" % (
            mode, rig, start, h, seed, g("init_s"), 100 * share, g("local_position_rmse_m"), g("local_drift_percent"),
            g("global_position_rmse_m"), g("estimator_ms_mean_before_init"), g("estimator_ms_mean_after_init"), waiting))
    print("\n".join(lines))
    if a.out:
        with open(a.out, "w") as f:
            f.write("# Initialisation sweep (issue 43)\n\nWritten by `bench/vio/init_sweep.py %s`. Start: take-off from "
                    "the ground (2 s at rest), hover start (3 s hover at height), cruise (the take-off flight replayed from "
                    "3 s after the end of the climb). Init after: first frame to the first initialised one; in a GNSS mode "
                    "the first GNSS epoch is within 0.2 s of the first frame. RMSE and drift after initialisation "
                    "(local: 4-DoF aligned; global: antenna in ENU, GNSS modes only). Estimator ms per frame on a shared "
                    "2-core host.\n\n" % " ".join(a.argv))
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
