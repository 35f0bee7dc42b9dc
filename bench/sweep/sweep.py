#!/usr/bin/env python3
"""Sweep benchmark (issue 45): every mode of gvins-replay on many seeds of every scenario family of
bench/sweep/families.py (UAV flights over each real navigation file at random heights, speeds,
lengths, patterns, headings and start times; mono; bases 1-10 km away; harsh GNSS; the city drive;
the hand-held walk), feature-track datasets of gvins-sim. Writes the results page (mean and worst
per family and mode, targets met or missed, NEES, float against double, run time) and a CSV of
every run.

  bench/sweep/sweep.py [--bin build/bin [--binaries-commit C]] [--seeds 20] [--jobs 1] [--work out/sweep]
                       [--only-seeds 3,14] [--families a,b] [--modes vio,ddcp,...] [--markdown docs/results/sweep.md]
                       [--csv docs/results/sweep.csv] [--retry-failed] [--keep-data]

Cache: every run leaves WORK/runs/FAMILY/SEED/MODE/result.json, keyed by the scenario text, the
replay arguments and the digests of the gvins-sim and gvins-replay binaries; a repeated or
interrupted sweep computes only the runs whose key is new (a rebuilt binary reruns everything).
A failed simulation or replay is recorded as a failed run (with its message) and the sweep goes
on; --retry-failed runs the failed ones again; --report-only writes the page from the cache alone
(e.g. after stopping a sweep). Datasets are deleted once all modes of a seed are
done (--keep-data keeps them). Progress lines (done/total, ETA) go to stderr.
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import random
import re
import shutil
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import families as fam  # noqa: E402
import report  # noqa: E402


def digest_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def draw(family, seed):
    """The variant of a family for one seed (deterministic: the same seed gives the same flight)."""
    rng = random.Random("%s:%d" % (family["name"], seed))
    nav = fam.NAVIGATION[family["navigation"]]
    hour = rng.uniform(*nav["hours"])
    v = {"start_gpst": "%s %02d:%02d:00" % (nav["date"], int(hour), int(60 * (hour - int(hour)))),
         "length_m": 10 * round(rng.uniform(*family["length_m"]) / 10)}
    if "template" not in family:
        v.update(height_m=round(rng.uniform(*family["height_m"])),
                 speed_mps=round(rng.uniform(*family["speed_mps"]), 1),
                 pattern=rng.choice(family["patterns"]), heading_deg=rng.randrange(360),
                 base_km=round(rng.uniform(*family["base_km"]), 1), base_azimuth_deg=rng.randrange(360),
                 rig=family["rig"])
    return v


def uav_scenario(family, seed, v):
    lat, lon, h = fam.place(family["navigation"])
    nav = os.path.join(ROOT, fam.NAVIGATION[family["navigation"]]["file"])
    shape = ("  laps: 1\n" if v["pattern"] == "figure_eight" else "  rows: 2\n  row_spacing_m: 50\n")
    cams = "    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04], mount_rpy_deg: [0.4, -0.3, 0.2]}\n"
    if v["rig"] == "stereo":
        cams += "    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04], mount_rpy_deg: [-0.2, 0.3, -0.4]}\n"
    rover = "".join("    %s: %s\n" % kv for kv in sorted(family["rover"].items()))
    return ("name: sweep_%s_%d\n" % (family["name"], seed) +
            "description: \"sweep %s seed %d\"\n" % (family["name"], seed) +
            "seed: %d\n" % seed +
            "origin: {latitude_deg: %.9f, longitude_deg: %.9f, height_m: %.3f}\n" % (lat, lon, h) +
            "start_gpst: \"%s\"\n" % v["start_gpst"] +
            "trajectory:\n  type: flight\n  pattern: %s\n  height_m: %g\n  length_m: %g\n"
            "  speed_mps: %g\n  climb_rate_mps: 3\n%s  heading_deg: %d\n  wobble_deg: 0.3\n"
            % (v["pattern"], v["height_m"], v["length_m"], v["speed_mps"], shape, v["heading_deg"]) +
            "imu:\n  rate_hz: 250\n" +
            "cameras:\n  rate_hz: 20\n  output: features\n  list:\n" + cams +
            "lever_arm_m: [0.08, 0.0, 0.18]\n" +
            "gnss:\n  navigation: %s\n  rover:\n    rate_hz: 5\n%s" % (nav, rover) +
            "  base:\n    distance_m: %g\n    azimuth_deg: %d\n    rate_hz: 1\n"
            % (1000 * v["base_km"], v["base_azimuth_deg"]))


def template_scenario(family, seed, v):
    text = open(os.path.join(ROOT, family["template"])).read()
    nav = os.path.join(ROOT, fam.NAVIGATION[family["navigation"]]["file"])
    for key, value in (("seed", "%d" % seed), ("name", "sweep_%s_%d" % (family["name"], seed)),
                       ("start_gpst", "\"%s\"" % v["start_gpst"]), ("  length_m", "%g" % v["length_m"]),
                       ("  navigation", nav)):
        text, n = re.subn(r"^%s: .*$" % key, "%s: %s" % (key, value), text, count=1, flags=re.M)
        if n != 1:
            raise ValueError("%s: no line '%s:' to vary" % (family["template"], key.strip()))
    return text


def scenario(family, seed):
    v = draw(family, seed)
    text = template_scenario(family, seed, v) if "template" in family else uav_scenario(family, seed, v)
    return v, text


class Progress:
    def __init__(self, total, jobs):
        self.total, self.jobs, self.done, self.computed, self.seconds = total, jobs, 0, 0, 0.0
        self.lock = threading.Lock()

    def tick(self, label, seconds, computed):
        with self.lock:
            self.done += 1
            if computed:
                self.computed += 1
                self.seconds += seconds
            left = self.total - self.done
            eta = (self.seconds / self.computed * left / self.jobs) if self.computed else 0.0
            sys.stderr.write("[%d/%d] %s (%.1f s)  ETA %dh%02dm\n" % (
                self.done, self.total, label, seconds, eta // 3600, (eta % 3600) // 60))
            sys.stderr.flush()


def read_metrics(path):
    out = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or "," not in line:
                continue
            k, val = line.strip().split(",", 1)
            try:
                out[k] = float(val)
            except ValueError:
                pass
    return out


def gnss_rows(path):
    """Mean code/phase rows (satellites or satellite pairs) per updated epoch of gnss_epochs.csv:
    the geometry behind a GNSS mode's accuracy."""
    if not os.path.exists(path):
        return {}
    header, rows = None, []
    with open(path) as f:
        for line in f:
            cells = [c.strip() for c in line.lstrip("# ").strip().split(",")]
            if header is None:
                header = [c.split(" ")[0] for c in cells]
                continue
            row = dict(zip(header, cells))
            if row.get("updated") == "1":
                rows.append(sum(float(row.get(k, 0) or 0) for k in
                                ("psr_used", "dpsr_used", "ddcp_used", "phase_used")))
    return {"gnss_rows_per_epoch": sum(rows) / len(rows)} if rows else {}


def fixed_errors(ecef_path, truth_path, limit=0.10):
    """Integrity of the fixed epochs (issue 39): the epochs of global_ecef.csv flagged RTK-fixed
    and how many of them are more than `limit` m (3-D) from the simulated antenna track."""
    if not (os.path.exists(ecef_path) and os.path.exists(truth_path)):
        return {}
    truth = {}
    with open(truth_path) as f:
        for line in f:
            if line.startswith("#"):
                continue
            c = line.split(",")
            truth[round(int(c[0]) / 1e6)] = (float(c[11]), float(c[12]), float(c[13]))  # ms -> antenna_E
    fixed = far = 0
    with open(ecef_path) as f:
        for line in f:
            if line.startswith("#"):
                continue
            c = line.strip().split(",")
            if c[-1] != "1":
                continue
            t = truth.get(round((int(c[0]) * 604800 + float(c[1])) * 1e3))
            if t is None:
                continue
            fixed += 1
            far += sum((float(c[2 + i]) - t[i]) ** 2 for i in range(3)) > limit * limit
    return {"fixed_epochs_checked": fixed, "fixed_epochs_over_0.10m": far}


def tail(text, n=3):
    lines = [l for l in text.strip().splitlines() if l.strip()]
    return " | ".join(lines[-n:])[-400:]


def run_seed(a, family, seed, modes, progress):
    """Simulates one seed of a family (if a run needs it) and replays it in every mode."""
    v, text = scenario(family, seed)
    data_key = hashlib.sha256((text + a.sim_digest).encode()).hexdigest()[:16]
    seed_dir = os.path.join(a.work, "runs", family["name"], str(seed))
    data = os.path.join(a.work, "data", "%s_%d" % (family["name"], seed))
    os.makedirs(seed_dir, exist_ok=True)
    results, sim_error, sim_s = [], None, 0.0
    for mode in modes:
        args = fam.MODES[mode]
        key = hashlib.sha256((data_key + " ".join(args) + a.replay_digest).encode()).hexdigest()[:16]
        out = os.path.join(seed_dir, mode)
        res_path = os.path.join(out, "result.json")
        if os.path.exists(res_path):
            old = json.load(open(res_path))
            if old.get("key") == key and (old["status"] == "ok" or not a.retry_failed):
                results.append(old)
                progress.tick("%s seed %d %s: cached %s" % (family["name"], seed, mode, old["status"]), 0.0, False)
                continue
        if a.report_only:
            progress.tick("%s seed %d %s: not run" % (family["name"], seed, mode), 0.0, False)
            continue
        t0 = time.time()
        if sim_error is None and not os.path.exists(os.path.join(data, "dataset.yaml")):
            sim_error, sim_s = simulate(a, text, data)
        res = {"key": key, "family": family["name"], "seed": seed, "mode": mode, "variant": v,
               "sim_s": sim_s, "status": "failed", "error": sim_error, "metrics": {}, "jobs": a.jobs}
        sim_s = 0.0  # the simulation is counted once, with the first run that needed it
        if sim_error is None:
            shutil.rmtree(out, ignore_errors=True)
            cmd = [os.path.join(a.bin, "gvins-replay"), data] + args + ["-q", "-o", out]
            p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            mpath = os.path.join(out, "metrics.csv")
            if p.returncode == 0 and os.path.exists(mpath):
                res.update(status="ok", error=None, metrics=read_metrics(mpath))
                res["metrics"].update(gnss_rows(os.path.join(out, "gnss_epochs.csv")))
                res["metrics"].update(fixed_errors(os.path.join(out, "global_ecef.csv"),
                                                   os.path.join(data, "truth", "groundtruth_ecef.csv")))
            else:
                res["error"] = "gvins-replay exit %d: %s" % (p.returncode, tail(p.stdout))
            for f in os.listdir(out) if os.path.isdir(out) else []:  # keep only what the page needs
                if f != "metrics.csv":
                    path = os.path.join(out, f)
                    shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
        res["run_s"] = time.time() - t0
        os.makedirs(out, exist_ok=True)
        with open(res_path + ".tmp", "w") as f:
            json.dump(res, f, indent=1, sort_keys=True)
        os.replace(res_path + ".tmp", res_path)
        results.append(res)
        progress.tick("%s seed %d %s: %s" % (family["name"], seed, mode, res["status"]), res["run_s"], True)
    if not a.keep_data and not a.report_only:
        shutil.rmtree(data, ignore_errors=True)
    return results


def simulate(a, text, data):
    """Writes the scenario and simulates it; returns (error or None, seconds)."""
    t0 = time.time()
    partial = data + ".partial"  # renamed when complete: an interrupted simulation is never used
    for d in (data, partial):
        shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.dirname(data), exist_ok=True)
    with open(data + ".yaml", "w") as f:
        f.write(text)
    p = subprocess.run([os.path.join(a.bin, "gvins-sim"), "--config", data + ".yaml", "--features-only",
                        "--threads", "1", "-o", partial],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        return "gvins-sim exit %d: %s" % (p.returncode, tail(p.stdout)), time.time() - t0
    os.rename(partial, data)
    return None, time.time() - t0


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--binaries-commit", default=None,
                    help="commit the binaries of --bin were built from, for the page (default: this checkout's HEAD)")
    ap.add_argument("--seeds", type=int, default=20, help="seeds 1..N of every family (default 20)")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--only-seeds", default=None,
                    help="comma-separated seeds to run instead of --first-seed/--seeds (e.g. 7 or 3,14)")
    ap.add_argument("--jobs", type=int, default=1, help="seeds simulated and replayed in parallel")
    ap.add_argument("--work", default=os.path.join(ROOT, "out", "sweep"))
    ap.add_argument("--families", default=",".join(f["name"] for f in fam.FAMILIES))
    ap.add_argument("--modes", default=",".join(fam.DEFAULT_MODES), help="of: " + ",".join(fam.MODES))
    ap.add_argument("--markdown", default=None, help="results page (e.g. docs/results/sweep.md)")
    ap.add_argument("--csv", default=None, help="one line per run (e.g. docs/results/sweep.csv)")
    ap.add_argument("--retry-failed", action="store_true")
    ap.add_argument("--keep-data", action="store_true")
    ap.add_argument("--report-only", action="store_true",
                    help="compute nothing: write the page and CSV from the runs in the cache")
    a = ap.parse_args()
    known = {f["name"]: f for f in fam.FAMILIES}
    a.family_list = []
    for n in a.families.split(","):
        if n not in known:
            ap.error("--families: unknown family '%s' (known: %s)" % (n, ", ".join(known)))
        a.family_list.append(known[n])
    a.mode_list = a.modes.split(",")
    for m in a.mode_list:
        if m not in fam.MODES:
            ap.error("--modes: unknown mode '%s' (known: %s)" % (m, ", ".join(fam.MODES)))
    if a.seeds < 1 or a.jobs < 1:
        ap.error("--seeds and --jobs must be at least 1")
    a.seed_list = list(range(a.first_seed, a.first_seed + a.seeds))
    if a.only_seeds is not None:
        try:
            a.seed_list = sorted({int(x) for x in a.only_seeds.split(",")})
        except ValueError:
            ap.error("--only-seeds: '%s' is not a comma-separated list of integers" % a.only_seeds)
    return a


def main():
    a = parse_args()
    for b in ("gvins-sim", "gvins-replay"):
        if not os.access(os.path.join(a.bin, b), os.X_OK):
            sys.exit("sweep.py: %s not built (cmake --build build --target gvins-sim gvins-replay)"
                     % os.path.join(a.bin, b))
    a.sim_digest = digest_file(os.path.join(a.bin, "gvins-sim"))
    a.replay_digest = digest_file(os.path.join(a.bin, "gvins-replay"))
    os.makedirs(a.work, exist_ok=True)
    tasks = [(f, s) for s in a.seed_list for f in a.family_list]
    progress = Progress(len(tasks) * len(a.mode_list), a.jobs)
    t0 = time.time()
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        for rows in ex.map(lambda t: run_seed(a, t[0], t[1], a.mode_list, progress), tasks):
            results.extend(rows)
    wall = time.time() - t0
    info = {"command": "bench/sweep/sweep.py " + " ".join(
                os.path.relpath(x, ROOT) if x.startswith(ROOT + os.sep) else x for x in sys.argv[1:]),
            "seeds": sorted({r["seed"] for r in results}), "jobs": a.jobs, "cores": os.cpu_count(), "wall_s": wall,
            "computed": progress.computed, "report_only": a.report_only, "binaries_commit": a.binaries_commit,
            "families": a.family_list, "modes": a.mode_list}
    if a.csv:
        report.write_csv(a.csv, results)
    page = report.page(results, info)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(page)
    else:
        sys.stdout.write(page)
    failed = sum(r["status"] != "ok" for r in results)
    sys.stderr.write("sweep: %d runs (%d computed, %d failed) in %.0f s\n" % (len(results), progress.computed,
                                                                             failed, wall))


if __name__ == "__main__":
    main()
