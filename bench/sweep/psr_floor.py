#!/usr/bin/env python3
"""The error floor of the pseudorange modes on the sweep's open-sky flights (issue 45).

    bench/sweep/psr_floor.py [--bin build/bin] [--seeds 5] [--first-seed 1] [--work out/psr_floor]
                             [--families a,b] [--markdown docs/results/psr_floor.md] [--keep-data]

For every seed of every open-sky family of bench/sweep/families.py the flight of the sweep
(sweep.py's own variant drawing) is simulated with `gnss: error_terms: true` and replayed in
vio+dopp+psr and vio+dopp+dpsr. bench/fusion/psr_error_attribution.py then maps each simulated
error term into the ENU offset a perfect VIO + GNSS filter would keep with the same rows (the
floor): the constant offset over the tight epochs per term, and the causal floor (offset solved
after every epoch from the tight epochs so far, its RMS over the epochs: what a causal filter with
a perfect VIO can reach, to compare with the filter's RMSE). The page shows, per family, the
filter's RMSE and mean error against the floor and its split per term, so that a reader sees
whether a target miss comes from the simulated errors or from the filter.

The psr runs use the precise orbits and clocks gvins-sim writes next to the navigation file (the
replay's default), so the broadcast orbit/clock error (sisre) is not in their floor; its column
shows what it would add with broadcast ephemerides. The dpsr floor is the rover-minus-base part
of every term. Runs are cached in WORK keyed by the scenario and the binaries' digests.
"""
import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "bench", "fusion"))
import families as fam  # noqa: E402
import psr_error_attribution as attribution  # noqa: E402
import sweep  # noqa: E402

MODES = {"psr": ["--mode", "vio+dopp+psr"], "dpsr": ["--mode", "vio+dopp+dpsr"]}
TARGETS = {"psr": fam.GNSS_TARGETS["psr"], "dpsr": fam.GNSS_TARGETS["dpsr"]}


def run_seed(a, family, seed):
    """Simulates one flight with error terms, replays both modes, returns the attribution per mode."""
    v, text = sweep.scenario(family, seed)
    text += "  error_terms: true\n"  # the gnss: section is the scenario's last
    key = hashlib.sha256((text + a.sim_digest + a.replay_digest).encode()).hexdigest()[:16]
    out_dir = os.path.join(a.work, "runs", family["name"], str(seed))
    res_path = os.path.join(out_dir, "result.json")
    if os.path.exists(res_path):
        old = json.load(open(res_path))
        if old.get("key") == key:
            return old
    data = os.path.join(a.work, "data", "%s_%d" % (family["name"], seed))
    t0 = time.time()
    marker = os.path.join(data, "psr_floor_key")  # a kept dataset of the same scenario and gvins-sim
    data_key = hashlib.sha256((text + a.sim_digest).encode()).hexdigest()[:16]
    error = None
    if not (os.path.exists(marker) and open(marker).read() == data_key):
        error, _ = sweep.simulate(a, text, data)
        if error is None:
            with open(marker, "w") as f:
                f.write(data_key)
    res = {"key": key, "family": family["name"], "seed": seed, "variant": v, "error": error, "modes": {}}
    if error is None:
        for mode, args in MODES.items():
            run = os.path.join(out_dir, mode)
            p = subprocess.run([os.path.join(a.bin, "gvins-replay"), data] + args + ["-q", "-o", run],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            if p.returncode != 0:
                res["modes"][mode] = {"error": "gvins-replay exit %d: %s" % (p.returncode, sweep.tail(p.stdout))}
                continue
            opts = attribution.options([data, "--run", run, "--causal"] + (["--dpsr"] if mode == "dpsr" else []))
            r = attribution.attribute(data, opts)
            if mode == "psr":  # the broadcast orbit/clock error these runs do not have (precise products)
                r["terms"]["sisre"] = attribution.attribute(data, attribution.options(
                    [data, "--run", run, "--broadcast"]))["terms"]["sisre"]
            r["precise"] = opts["precise"]
            res["modes"][mode] = r
    res["run_s"] = time.time() - t0
    if not a.keep_data:
        subprocess.run(["rm", "-rf", data, data + ".yaml"])
    os.makedirs(out_dir, exist_ok=True)
    with open(res_path, "w") as f:
        json.dump(res, f, indent=1, sort_keys=True)
    sys.stderr.write("%s seed %d: %.0f s\n" % (family["name"], seed, res["run_s"]))
    return res


def norm(x):
    return math.sqrt(sum(v * v for v in x))


def stats(values):
    return (sum(values) / len(values), max(values)) if values else (float("nan"), float("nan"))


def family_rows(results, mode):
    """Per family: the table cells of one mode."""
    rows = []
    for f in sorted({r["family"] for r in results}, key=lambda n: [x["name"] for x in fam.FAMILIES].index(n)):
        runs = [r["modes"][mode] for r in results if r["family"] == f and "filter" in r["modes"].get(mode, {})]
        if not runs:
            continue
        worst = max(runs, key=lambda m: m["filter"]["rms"])
        rmse, causal = stats([m["filter"]["rms"] for m in runs]), stats([m["causal_tight"]["rms"] for m in runs])
        cells = [f, str(len(runs)), "%.2f / %.2f" % rmse, "%.2f / %.2f" % causal,
                 "%.2f / %.2f" % (worst["filter"]["rms"], worst["causal_tight"]["rms"]),
                 "%.2f" % stats([m["filter"]["rms"] - m["causal_tight"]["rms"] for m in runs])[0],
                 "%.2f / %.2f" % stats([abs(m["filter"]["mean"][2]) for m in runs]),
                 "%.2f / %.2f" % stats([abs(m["sum"][2]) for m in runs])]
        for t in attribution.TERMS:
            vals = [norm(m["terms"][t]) for m in runs]
            cells.append("%.2f" % math.sqrt(sum(v * v for v in vals) / len(vals)))
        rows.append(cells)
    return rows


def run_rows(results, mode):
    rows = []
    for r in results:
        m = r["modes"].get(mode, {})
        if "filter" not in m:
            rows.append([r["family"], str(r["seed"]), "failed: %s" % (r["error"] or m.get("error"))] + [""] * 8)
            continue
        v = r["variant"]
        rows.append([r["family"], str(r["seed"]), "%s %s m, %s m/s, base %s km" % (
                        v["pattern"].replace("_", "-"), v["height_m"], v["speed_mps"], v["base_km"]),
                     "%.2f" % m["filter"]["rms"], "%.2f" % m["causal_tight"]["rms"],
                     "%+.2f" % m["filter"]["mean"][2], "%+.2f" % m["sum"][2]] +
                    ["%+.2f" % m["terms"][t][2] for t in attribution.TERMS])
    return rows


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(out + ["| " + " | ".join(r) + " |" for r in rows]) + "\n"


def commit():
    p = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], stdout=subprocess.PIPE, text=True)
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                           stdout=subprocess.PIPE, text=True).stdout.strip()
    return p.stdout.strip() + (" (with uncommitted changes)" if dirty else "")


def page(results, command):
    terms = " | ".join("%s" % t for t in attribution.TERMS)
    fam_header = ["family", "seeds", "filter RMSE mean / worst [m]", "causal floor RMS mean / worst [m]",
                  "worst seed: filter / floor [m]", "filter − floor, mean [m]", "filter \\|mean Up\\| mean / worst [m]",
                  "floor \\|Up\\| mean / worst [m]"] + ["%s [m]" % t for t in attribution.TERMS]
    run_header = ["family", "seed", "flight", "filter RMSE [m]", "causal floor RMS [m]", "filter mean Up [m]",
                  "floor Up [m]"] + ["%s Up [m]" % t for t in attribution.TERMS]
    text = ["# Pseudorange modes: filter error against the floor of the simulated errors\n\n",
            "Written by `%s` at commit %s on %s. Do not edit by hand: run the script again. Flights: the sweep's "
            "open-sky families and seeds (bench/sweep/sweep.py's variant drawing), simulated with "
            "`gnss: error_terms: true`; floors: bench/fusion/psr_error_attribution.py.\n\n"
            % (command, commit(), time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())),
            "Filter: RMSE of the antenna in ENU from the first tight epoch on (as the sweep) and its mean Up error. "
            "Floor: the same rows' simulated errors (carrier-smoothed as the replay smooths them, the fusion's "
            "weights and elevation mask, NLOS satellites left out) mapped into the antenna offset by weighted "
            "least squares with a clock per system and epoch. 'Causal floor RMS': the offset solved after every "
            "tight epoch from the tight epochs so far, RMS over the epochs (a perfect-VIO causal filter; compare "
            "with the filter's RMSE). 'Floor Up': one constant offset over the flight; per term: RMS over the "
            "seeds of the length of its ENU offset (first table), its Up part per run (second table). Terms: "
            "sisre broadcast orbit/clock error, tropo troposphere residual, iono ionosphere (cancels in the "
            "ionosphere-free psr rows), mp code multipath, noise code noise, windup phase wind-up carried into "
            "the smoothed codes.\n"]
    for mode, title in (("psr", "VIO+Dopp+Psr (undifferenced ionosphere-free codes, precise orbits and clocks)"),
                        ("dpsr", "VIO+Dopp+Dpsr (rover-base single differences, two bands)")):
        note = (" The psr runs read the precise products gvins-sim writes (the replay's default), so sisre is not "
                "in their floor or sum; its column is what the broadcast ephemerides would add." if mode == "psr"
                else " Every term is the rover's minus the base's (interpolated to the rover epoch).")
        text += ["\n## %s\n" % title, "Target: worst seed <= %.2f m.%s\n\n" % (TARGETS[mode], note),
                 table(fam_header, family_rows(results, mode)), "\nPer run:\n\n", table(run_header, run_rows(results, mode))]
    return "".join(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--work", default=os.path.join(ROOT, "out", "psr_floor"))
    ap.add_argument("--families", default=",".join(f["name"] for f in fam.FAMILIES if f["open_sky"]))
    ap.add_argument("--markdown", default=None)
    ap.add_argument("--keep-data", action="store_true")
    a = ap.parse_args()
    known = {f["name"]: f for f in fam.FAMILIES}
    for n in a.families.split(","):
        if n not in known:
            ap.error("--families: unknown family '%s'" % n)
    a.sim_digest = sweep.digest_file(os.path.join(a.bin, "gvins-sim"))
    a.replay_digest = sweep.digest_file(os.path.join(a.bin, "gvins-replay"))
    results = [run_seed(a, known[n], s) for s in range(a.first_seed, a.first_seed + a.seeds)
               for n in a.families.split(",")]
    command = "bench/sweep/psr_floor.py " + " ".join(
        os.path.relpath(x, ROOT) if x.startswith(ROOT + os.sep) else x for x in sys.argv[1:])
    text = page(results, command)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
