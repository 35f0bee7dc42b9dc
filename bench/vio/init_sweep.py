#!/usr/bin/env python3
"""Initialisation sweep (issue 43): simulate short lawnmower flights (features only, GNSS rover at
5 Hz over the bundled Nagoya ephemerides) for the scenario families mono/stereo x {take-off from
the ground, hover start, start in cruise} at several heights and seeds, and the car drive and
hand-held walk of config/ (--ground) started at rest or in motion, replay each in every --modes
(`vio`: vision only; a GNSS mode: the GNSS/INS start may start the estimator,
docs/gnss_fusion.md), and print the table: time to initialise, the GNSS start (first frame to the
first tightly coupled GNSS epoch, frame_init_s), share of frames initialised, local RMSE and drift and global RMSE after initialisation, estimator ms per frame before
initialisation against the initialised cost of the same flight, and the reasons while waiting.

  bench/vio/init_sweep.py --bin build/bin [--heights 20,60,100] [--seeds 1,2] [--modes vio,vio+dopp+psr]
                          [--ground drive,walk] [--work DIR] [-j 2] [--out docs/results/init_sweep.md]

UAV: the template is bench/vio/init/mono_takeoff_40m.yaml; 'stereo' adds cam1, 'hover' replaces the
take-off by a 3 s hover at height, 'cruise' replays the take-off flight from 3 s after the climb
(height / climb rate + 3 s + 2 s on the ground). Ground: config/car_city_drive.yaml (600 m) and
config/handheld_walk.yaml (120 m), 'mono' without cam1; 'rest' replays from the first frame (4 s
at rest), 'motion' from 8 s (the car at 6 m/s and accelerating, the walker at walking speed),
40 s each. Progress to stderr, the table to stdout.

The reference cost ("initialised ms/frame") of a start in motion is the initialised cost of the
same flight replayed from its start (take-off or rest) in the same mode: a late initialisation
leaves too few frames after it to measure its own.
"""
import argparse
import concurrent.futures
import csv
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
TEMPLATE = os.path.join(HERE, "init", "mono_takeoff_40m.yaml")
NAV = os.path.join(ROOT, "tests", "data", "gnss", "nagoya_static_2024", "base.nav.gz")
# Ground scenarios: template, shortened length, replay start of 'motion', replay duration (s).
GROUND = {"drive": ("config/car_city_drive.yaml", "length_m: 2000", "length_m: 600", 8.0, 40.0),
          "walk": ("config/handheld_walk.yaml", "length_m: 830", "length_m: 120", 8.0, 40.0)}
REFERENCE = {"cruise": "takeoff", "motion": "rest"}  # start in motion -> the same flight from its start
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


def ground_scenario(kind, rig, seed):
    tpl, old_len, new_len = GROUND[kind][:3]
    text = open(os.path.join(ROOT, tpl)).read()
    text = text.replace(old_len, new_len).replace("../tests/data/gnss/nagoya_static_2024/base.nav.gz", NAV)
    text = "\n".join(("seed: %d" % seed) if l.startswith("seed:") else l for l in text.split("\n"))
    if rig == "mono":
        text = "\n".join(l for l in text.split("\n") if not l.startswith("    - {name: cam1"))
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


def dataset(scen, rig, start, height, seed):
    """Folder name and scenario text of the simulated dataset a replay uses."""
    if scen == "uav":
        sim_start = "hover" if start == "hover" else "takeoff"
        return "%s_%s_%g_%d" % (rig, sim_start, height, seed), lambda: scenario(rig, sim_start, height, seed)
    return "%s_%s_%d" % (scen, rig, seed), lambda: ground_scenario(scen, rig, seed)


def run(args, scen, rig, start, height, seed, mode):
    name, text = dataset(scen, rig, start, height, seed)
    data = os.path.join(args.work, name)
    if not os.path.isdir(os.path.join(data, "gnss")):
        yml = os.path.join(args.work, name + ".yaml")
        with open(yml, "w") as f:
            f.write(text())
        subprocess.run([os.path.join(args.bin, "gvins-sim"), "--config", yml, "-o", data], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = os.path.join(args.work, "%s_%s_%s_%g_%d_%s_out" % (scen, rig, start, height, seed, mode.replace("+", "_")))
    cmd = [os.path.join(args.bin, "gvins-replay"), data, "--mode", mode, "-q", "-o", out]
    if start == "cruise":
        cmd += ["--start", "%g" % (2.0 + height / 3.0 + 3.0)]
    if scen != "uav":
        cmd += ["--start", "%g" % (GROUND[scen][3] if start == "motion" else 0.0), "--duration", "%g" % GROUND[scen][4]]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    waiting = ""
    for line in p.stdout.splitlines():
        if line.startswith("initialisation"):
            waiting = line.split("waiting:", 1)[-1].strip() + waiting
        if line.startswith("GNSS/INS start waiting"):
            waiting += "; GNSS/INS: " + line.split("waiting", 1)[-1].strip()
    m = metrics(os.path.join(out, "metrics.csv")) if os.path.exists(os.path.join(out, "metrics.csv")) else {}
    sys.stderr.write("  %-5s %-7s %-8s %4g m seed %d %s: %s\n" % (scen, rig, start, height, seed, mode, "ok" if m else "FAILED"))
    return (mode, rig, scen, start, height, seed, m, waiting)


def commit():
    def git(*a):
        return subprocess.run(["git", "-C", ROOT] + list(a), capture_output=True, text=True).stdout.strip()
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    return head + (" with local changes" if git("status", "--porcelain", "--untracked-files=no") else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--heights", default="20,60,100")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--rigs", default="mono,stereo")
    ap.add_argument("--starts", default="takeoff,hover,cruise", help="UAV starts (empty: no UAV rows)")
    ap.add_argument("--ground", default="drive,walk", help="ground scenarios (empty: none)")
    ap.add_argument("--ground-starts", default="rest,motion")
    ap.add_argument("--modes", default="vio,vio+dopp+psr")
    ap.add_argument("--out", default=None, help="also write the table (markdown with its command) here")
    ap.add_argument("--work", default=None, help="dataset folder (reused when present); default: a temporary one")
    ap.add_argument("-j", type=int, default=2, help="parallel replays (at most 2)")
    a = ap.parse_args()
    a.argv = ["--heights", a.heights, "--seeds", a.seeds, "--rigs", a.rigs, "--starts", "'%s'" % a.starts,
              "--ground", "'%s'" % a.ground, "--ground-starts", a.ground_starts, "--modes", a.modes]
    a.commit = commit()  # before the page is rewritten (it would count as a local change)
    a.work = a.work or tempfile.mkdtemp(prefix="init_sweep_")
    os.makedirs(a.work, exist_ok=True)
    split = lambda v: [x for x in v.split(",") if x]
    wanted = [(md, r, "uav", s, float(h), int(sd)) for md in split(a.modes) for r in split(a.rigs)
              for s in split(a.starts) for h in split(a.heights) for sd in split(a.seeds)]
    wanted += [(md, r, g, s, 0.0, int(sd)) for md in split(a.modes) for r in split(a.rigs)
               for g in split(a.ground) for s in split(a.ground_starts) for sd in split(a.seeds)]
    # A start in motion is compared with the same flight from its start: that replay runs too.
    jobs = list(wanted)
    for md, r, sc, s, h, sd in wanted:
        ref = (md, r, sc, REFERENCE.get(s, s), h, sd)
        if ref not in jobs:
            jobs.append(ref)
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, min(2, a.j))) as ex:
        # Each dataset is simulated by the first replay that needs it (a start in motion reuses the
        # flight from its start): those go first, the rest after.
        first = {}
        for j in jobs:
            first.setdefault(dataset(j[2], j[1], j[3], j[4], j[5])[0], j)
        head = list(first.values())
        run_job = lambda j: run(a, j[2], j[1], j[3], j[4], j[5], j[0])
        results = list(ex.map(run_job, head))
        results += list(ex.map(run_job, [j for j in jobs if j not in head]))
    nan = float("nan")
    by_key = {r[:6]: r for r in results}
    lines = ["| mode | rig | scenario | start | height [m] | seed | init after [s] | GNSS start [s] | frames initialised "
             "| local RMSE [m] | drift [%] | global RMSE [m] | ms/frame before init | initialised ms/frame (reference) | before / initialised "
             "| waiting (frames) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for mode, rig, scen, start, h, seed, m, waiting in sorted(results, key=lambda r: r[:6]):
        g = lambda k: m.get(k, nan)
        share = g("frames_initialized") / g("frames") if m.get("frames") else nan
        ref_key = (mode, rig, scen, REFERENCE.get(start, start), h, seed)
        ref = by_key[ref_key][6].get("estimator_ms_mean_after_init", nan) if ref_key in by_key else nan
        ref_txt = "%.2f%s" % (ref, " (from %s)" % ref_key[3] if ref_key[3] != start else "")
        before = g("estimator_ms_mean_before_init")
        lines.append("| %s | %s | %s | %s | %s | %d | %.2f | %.2f | %.1f %% | %.3f | %.2f | %.3f | %.2f | %s | %.2f | %s |" % (
            mode, rig, scen, start, "%g" % h if scen == "uav" else "-", seed, g("init_s"), g("frame_init_s"), 100 * share,
            g("local_position_rmse_m"), g("local_drift_percent"), g("global_position_rmse_m"), before, ref_txt,
            before / ref if ref > 0 else nan, waiting))
    print("\n".join(lines))
    if a.out:
        with open(a.out, "w") as f:
            f.write("# Initialisation sweep (issue 43)\n\nWritten by `bench/vio/init_sweep.py %s` at commit %s. UAV "
                    "starts: take-off from the ground (2 s at rest), hover start (3 s hover at height), cruise (the "
                    "take-off flight replayed from 3 s after the end of the climb). Ground: car drive (600 m of "
                    "config/car_city_drive.yaml) and hand-held walk (120 m of config/handheld_walk.yaml), 40 s replayed "
                    "from the first frame (rest: 4 s at rest) or from 8 s (motion). Init after: first frame to the first "
                    "initialised one; in a GNSS mode the first GNSS epoch is within 0.2 s of the first frame. GNSS start: "
                    "first frame to the first tightly coupled GNSS epoch (metrics.csv frame_init_s; nan: none, or vio). RMSE and "
                    "drift after initialisation (local: 4-DoF aligned; global: antenna in ENU, GNSS modes only). "
                    "Estimator ms per frame on a shared 2-core host; the initialised reference of a start in motion "
                    "is the same flight replayed from its start (take-off or rest) in the same mode.\n\n"
                    % (" ".join(a.argv), a.commit))
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
