"""The sweep's results page and CSV (bench/sweep/sweep.py): mean and worst per family and mode,
the issue-45 targets met or missed per cell, NEES, float against double, failures, run time."""
import csv
import datetime
import math
import os
import subprocess

import families as fam

NAN = float("nan")
METRIC_COLUMNS = ["global_position_rmse_m", "local_start_aligned_position_rmse_m", "local_position_rmse_m",
                  "local_drift_percent", "local_position_nees_first_pose", "local_orientation_nees_first_pose",
                  "local_body_velocity_rmse_mps", "gnss_epochs", "gnss_epochs_fixed", "frames",
                  "frames_initialized", "frame_init_s", "gnss_rows_per_epoch", "local_path_m", "global_horizontal_rmse_m",
                  "global_vertical_rmse_m", "dataset_s", "wall_s"]
VARIANT_COLUMNS = ["start_gpst", "height_m", "speed_mps", "length_m", "pattern", "heading_deg", "base_km",
                   "base_azimuth_deg", "rig"]
LABELS = {"vio": "VIO", "vio_float": "VIO float", "vio_perturbed": "VIO perturbed", "gpsvel": "VIO+Gps_vel", "dopp": "VIO+Dopp",
          "psr": "VIO+Dopp+Psr", "ppp": "VIO+Dopp+PPP", "dpsr": "VIO+Dopp+Dpsr", "ddcp": "VIO+Dopp+Ddcp",
          "ddcp_float": "VIO+Dopp+Ddcp float"}


def accuracy(r):
    """The figure of a run: antenna RMSE in ENU without alignment (GNSS modes), else the VIO RMSE
    after the 4-DoF alignment on the first 10 % of the horizontal path (as docs/results/uav_flights.md)."""
    m = r["metrics"]
    key = "local_start_aligned_position_rmse_m" if r["mode"].startswith("vio") else "global_position_rmse_m"
    return m.get(key, NAN)


def finite(values):
    return [v for v in values if v is not None and math.isfinite(v)]


def stats(values):
    v = finite(values)
    return (sum(v) / len(v), max(v), len(v)) if v else (NAN, NAN, 0)


def fmt(x, digits=3):
    return "n/a" if x is None or not math.isfinite(x) else "%.*f" % (digits, x)


def write_csv(path, results):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["family", "seed", "mode", "status", "accuracy_m"] + VARIANT_COLUMNS + METRIC_COLUMNS +
                   ["sim_s", "run_s", "error"])
        for r in sorted(results, key=lambda r: (r["family"], r["seed"], r["mode"])):
            m, v = r["metrics"], r["variant"]
            w.writerow([r["family"], r["seed"], r["mode"], r["status"], fmt(accuracy(r), 4)] +
                       [v.get(k, "") for k in VARIANT_COLUMNS] + [fmt(m.get(k, NAN), 4) for k in METRIC_COLUMNS] +
                       ["%.1f" % r.get("sim_s", 0.0), "%.1f" % r.get("run_s", 0.0), r.get("error") or ""])


def by(results, family, mode):
    return [r for r in results if r["family"] == family and r["mode"] == mode and r["status"] == "ok"]


def variant_text(r):
    v, m = r["variant"], r["metrics"]
    if "height_m" in v:
        text = "seed %d: %s %g m, %g m/s, %g m, base %g km, %s" % (
            r["seed"], v["pattern"].replace("_", "-"), v["height_m"], v["speed_mps"], v["length_m"],
            v["base_km"], v["start_gpst"])
    else:
        text = "seed %d: %g m, %s" % (r["seed"], v["length_m"], v["start_gpst"])
    if not r["mode"].startswith("vio") and math.isfinite(m.get("global_vertical_rmse_m", NAN)):
        text += "; horizontal %.2f m, vertical %.2f m" % (m.get("global_horizontal_rmse_m", NAN),
                                                         m["global_vertical_rmse_m"])
    if math.isfinite(m.get("gnss_rows_per_epoch", NAN)):
        text += "; %.1f code/phase rows per epoch" % m["gnss_rows_per_epoch"]
    if r["mode"] == "vio" and math.isfinite(m.get("local_path_m", NAN)):
        text += "; path %.0f m" % m["local_path_m"]
    return text


def target_rows(results, families, modes):
    """(family, target, measured, met, worst run) for every target that applies to a family."""
    rows = []
    for f in families:
        n = f["name"]
        if f["open_sky"]:
            for mode, bound in fam.GNSS_TARGETS.items():
                runs = by(results, n, mode) if mode in modes else []
                if runs:
                    worst = max(runs, key=lambda r: accuracy(r) if math.isfinite(accuracy(r)) else 1e9)
                    x = accuracy(worst)
                    rows.append((n, "%s worst <= %.2f m" % (LABELS[mode], bound), fmt(x), x <= bound, worst))
        vio = by(results, n, "vio")
        if vio:
            mean = stats(r["metrics"].get("local_drift_percent", NAN) for r in vio)[0]
            worst = max(vio, key=lambda r: r["metrics"].get("local_drift_percent", -1))
            rows.append((n, "VIO drift mean <= %.1f %%" % fam.DRIFT_TARGET_PERCENT, fmt(mean, 2) + " %",
                         mean <= fam.DRIFT_TARGET_PERCENT, worst))
            ratio = stats(r["metrics"].get("local_position_nees_first_pose", NAN) / 3.0 for r in vio)[0]
            lo, hi = fam.NEES_RATIO_RANGE
            rows.append((n, "VIO position NEES / 3 (mean) in [%.1f, %.1f]" % (lo, hi), fmt(ratio, 3),
                         lo <= ratio <= hi, None))
        for fl, dbl in fam.FLOAT_PAIRS.items():
            rows += float_rows(results, n, fl, dbl)
    return rows


def float_rows(results, n, fl, dbl):
    """The float target of one pair: with a perturbed double run, the mean over the seeds of
    |float - double| / double, and whether the float differences exceed the run-to-run spread (the
    perturbed double's differences, one-sided rank sum); without one, the worst seed."""
    fg = gaps(results, n, fl, dbl)
    if not fg:
        return []
    worst = max(fg, key=lambda g: g[0])
    tol = 100 * fam.FLOAT_TOLERANCE
    pg = gaps(results, n, fam.PERTURBED[dbl], dbl) if dbl in fam.PERTURBED else []
    if not pg:
        return [(n, "%s within %.0f %% of double (worst seed)" % (LABELS[dbl], tol), fmt(100 * worst[0], 1) + " %",
                 worst[0] <= fam.FLOAT_TOLERANCE, worst[1])]
    mean = sum(g for g, _ in fg) / len(fg)
    p = rank_sum_p([g for g, _ in fg], [g for g, _ in pg])
    return [(n, "%s within %.0f %% of double (mean over the seeds)" % (LABELS[dbl], tol),
             "%s %% (worst %s %%)" % (fmt(100 * mean, 1), fmt(100 * worst[0], 1)), mean <= fam.FLOAT_TOLERANCE, None),
            (n, "%s: float no farther from double than a 1-ns perturbed double (rank sum, p >= %.2f)" % (
                LABELS[dbl], fam.SPREAD_SIGNIFICANCE),
             "p = %s; worst seed float %s %%, perturbed %s %%" % (
                 fmt(p, 2), fmt(100 * worst[0], 1), fmt(100 * max(g for g, _ in pg), 1)),
             p >= fam.SPREAD_SIGNIFICANCE, worst[1])]


def gaps(results, family, other, dbl):
    """(|other - double| / double of the accuracy, other's run) for every seed with both runs."""
    doubles = {r["seed"]: r for r in by(results, family, dbl)}
    out = []
    for r in by(results, family, other):
        d = doubles.get(r["seed"])
        if d is None or not (accuracy(d) > 0 and math.isfinite(accuracy(r))):
            continue
        out.append((abs(accuracy(r) - accuracy(d)) / accuracy(d), r))
    return out


def gap_text(results, family, other, dbl):
    """'mean / worst %' of gaps(), or n/a."""
    g = [x for x, _ in gaps(results, family, other, dbl)]
    return "%s / %s %%" % (fmt(100 * sum(g) / len(g), 1), fmt(100 * max(g), 1)) if g else "n/a"


def rank_sum_p(a, b):
    """One-sided p-value of the Wilcoxon-Mann-Whitney rank-sum test that the values `a` tend to be
    larger than the values `b` (normal approximation with midranks for ties and the continuity
    correction; Hollander, Wolfe & Chicken, "Nonparametric Statistical Methods", 3rd ed., sec. 4.1).
    NaN when either sample is empty."""
    n1, n2 = len(a), len(b)
    if n1 == 0 or n2 == 0:
        return NAN
    pooled = sorted([(x, 0) for x in a] + [(x, 1) for x in b])
    ranks, ties, i = [0.0] * len(pooled), 0.0, 0
    while i < len(pooled):
        j = i
        while j + 1 < len(pooled) and pooled[j + 1][0] == pooled[i][0]:
            j += 1
        for k in range(i, j + 1):
            ranks[k] = (i + j) / 2.0 + 1.0
        t = j - i + 1
        ties += t ** 3 - t
        i = j + 1
    n = n1 + n2
    u = sum(r for r, (_, g) in zip(ranks, pooled) if g == 0) - n1 * (n1 + 1) / 2.0
    var = n1 * n2 / 12.0 * ((n + 1) - ties / (n * (n - 1)))
    if var <= 0:
        return 1.0
    z = (u - n1 * n2 / 2.0 - 0.5) / math.sqrt(var)
    return 0.5 * math.erfc(z / math.sqrt(2.0))


def accuracy_table(results, families, modes):
    out = ["| family | open sky | seeds | " + " | ".join(LABELS[m] for m in modes) + " |",
           "|---|---|---|" + "---|" * len(modes)]
    for f in families:
        seeds = {r["seed"] for r in results if r["family"] == f["name"]}
        cells = []
        for m in modes:
            mean, worst, n = stats(accuracy(r) for r in by(results, f["name"], m))
            cell = "%s / %s" % (fmt(mean), fmt(worst)) if n else "n/a"
            if n and n < len(seeds):
                cell += " (%d ok)" % n
            bound = fam.GNSS_TARGETS.get(m)
            if n and bound is not None and f["open_sky"]:
                cell += " met" if worst <= bound else " **missed**"
            cells.append(cell)
        out.append("| %s | %s | %d | %s |" % (f["name"], "yes" if f["open_sky"] else "no", len(seeds), " | ".join(cells)))
    return out


def vio_table(results, families):
    out = ["| family | VIO drift mean / worst [%] | VIO RMSE (whole-flight 4-DoF) mean / worst [m] | "
           "position NEES / 3: mean [min, max] | orientation NEES / 3: mean [min, max] | "
           "float vs double, mean / worst: VIO; Ddcp | 1-ns perturbed double vs double, mean / worst: VIO | "
           "RTK-fixed epochs (Ddcp) | frame init [s] (Ddcp, worst) |",
           "|---|---|---|---|---|---|---|---|---|"]
    for f in families:
        n = f["name"]
        vio, ddcp = by(results, n, "vio"), by(results, n, "ddcp")
        if not vio and not ddcp:
            continue
        drift = stats(r["metrics"].get("local_drift_percent", NAN) for r in vio)
        rmse = stats(r["metrics"].get("local_position_rmse_m", NAN) for r in vio)
        cells = ["%s / %s" % (fmt(drift[0], 2), fmt(drift[1], 2)), "%s / %s" % (fmt(rmse[0]), fmt(rmse[1]))]
        for key in ("local_position_nees_first_pose", "local_orientation_nees_first_pose"):
            v = finite(r["metrics"].get(key, NAN) / 3.0 for r in vio)
            cells.append("%s [%s, %s]" % (fmt(sum(v) / len(v), 2), fmt(min(v), 2), fmt(max(v), 2)) if v else "n/a")
        cells.append("; ".join(gap_text(results, n, fl, dbl) for fl, dbl in fam.FLOAT_PAIRS.items()))
        cells.append(gap_text(results, n, fam.PERTURBED["vio"], "vio"))
        fixed = sum(r["metrics"].get("gnss_epochs_fixed", 0) for r in ddcp)
        epochs = sum(r["metrics"].get("gnss_epochs", 0) for r in ddcp)
        cells.append("%.1f %%" % (100.0 * fixed / epochs) if epochs else "n/a")
        cells.append(fmt(stats(r["metrics"].get("frame_init_s", NAN) for r in ddcp)[1], 1))
        out.append("| %s | %s |" % (n, " | ".join(cells)))
    return out


BANDS = [("flight height [m]", "height_m", (20, 40, 60, 80.01)),
         ("speed [m/s]", "speed_mps", (4, 6.67, 9.33, 12.01)),
         ("dataset length [s]", "dataset_s", (0, 115, 130, 1e9))]


def band_table(results, families):
    """Drift and the absolute/differential code modes of the open-sky UAV runs against the drawn
    height, speed and the dataset's length: where the misses concentrate."""
    open_uav = {f["name"] for f in families if f["open_sky"] and "template" not in f}
    runs = [r for r in results if r["family"] in open_uav and r["status"] == "ok"]
    length = {(r["family"], r["seed"]): r["metrics"].get("dataset_s", NAN) for r in runs if r["mode"] == "vio"}
    out = ["| variable | band | runs | VIO drift mean / worst [%] | Psr mean / worst [m] | Dpsr mean / worst [m] |",
           "|---|---|---|---|---|---|"]
    for label, key, edges in BANDS:
        for lo, hi in zip(edges[:-1], edges[1:]):
            def inside(r):
                x = length.get((r["family"], r["seed"]), NAN) if key == "dataset_s" else r["variant"].get(key, NAN)
                return lo <= x < hi
            sel = [r for r in runs if inside(r)]
            drift = stats(r["metrics"].get("local_drift_percent", NAN) for r in sel if r["mode"] == "vio")
            psr = stats(accuracy(r) for r in sel if r["mode"] == "psr")
            dpsr = stats(accuracy(r) for r in sel if r["mode"] == "dpsr")
            band = ">= %g" % lo if hi >= 1e8 else "%g-%g" % (round(lo, 1), round(hi, 1))
            out.append("| %s | %s | %d | %s / %s | %s / %s | %s / %s |" % (
                label, band, drift[2], fmt(drift[0], 2),
                fmt(drift[1], 2), fmt(psr[0]), fmt(psr[1]), fmt(dpsr[0]), fmt(dpsr[1])))
    return out


def commit():
    try:
        here = os.path.dirname(os.path.abspath(__file__))
        return subprocess.run(["git", "-C", here, "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True).stdout.strip() or "unknown"
    except OSError:
        return "unknown"


def page(results, info):
    families, modes = info["families"], info["modes"]
    seeds = info["seeds"] or [0]
    ok = sum(r["status"] == "ok" for r in results)
    run_s = sum(r.get("run_s", 0.0) for r in results)
    scenarios = len({(r["family"], r["seed"]) for r in results})
    per_seed = run_s / max(1, scenarios) * len(families)  # one seed of every family
    jobs = sorted({r.get("jobs", info["jobs"]) for r in results}) or [info["jobs"]]
    origin = (", from the run cache, whose runs were computed with --jobs %s" % "/".join(map(str, jobs))
              if info.get("report_only") else ", --jobs %d" % info["jobs"])
    L = ["# Sweep: every mode on many seeds of every scenario family", "",
         "Written by `%s` with the binaries of commit %s on %s, %d cores%s. Do not edit by hand: "
         "run the script again. Families, modes and targets: bench/sweep/families.py; each seed draws its own "
         "variant (height, speed, length, pattern, heading, start time, base distance and direction) and "
         "simulator noise; datasets are feature tracks." % (
             info["command"], info.get("binaries_commit") or commit(),
             datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M UTC"),
             info["cores"], origin), "",
         "Seeds %s (the seeds column says how many each family has); %d runs, %d ok, %d failed." % (
             ", ".join(str(s) for s in seeds), len(results), ok, len(results) - ok), "",
         "## Families", "", "| family | scenario | navigation file (systems) | open sky | known limitation |",
         "|---|---|---|---|---|"]
    for f in families:
        nav = fam.NAVIGATION[f["navigation"]]
        L.append("| %s | %s | %s (%s) | %s | %s |" % (f["name"], f["title"], os.path.basename(nav["file"]),
                                                     nav["systems"], "yes" if f["open_sky"] else "no",
                                                     f["note"] or ""))
    L += ["", "## Accuracy: mean / worst over the seeds [m]", "",
          "GNSS modes: antenna RMSE in ENU without alignment from the first tightly coupled update on; VIO: "
          "RMSE after the 4-DoF alignment on the first 10 %% of the horizontal path. Targets on the worst seed "
          "of the open-sky families: Ddcp <= %.2f m, Dpsr <= %.2f m, Psr <= %.2f m (met / **missed**)." % (
              fam.GNSS_TARGETS["ddcp"], fam.GNSS_TARGETS["dpsr"], fam.GNSS_TARGETS["psr"]), ""]
    L += accuracy_table(results, families, modes)
    L += ["", "## VIO consistency, float against double, RTK", "",
          "Drift: longest-segment relative error of the VIO run; NEES: position and orientation NEES of the VIO "
          "run under the first-pose alignment divided by their expectation 3 (target [%.1f, %.1f]); float against "
          "double: mean and largest over the seeds of |float - double| / double of the accuracy (the RMSE of the "
          "accuracy table); 1-ns perturbed double: the same for the double run with its frames shifted by 1 ns "
          "(bench/sweep/families.py), the run-to-run spread that any rounding-sized change causes, against which "
          "the float difference is judged (rank sum over the seeds, Targets)." % fam.NEES_RATIO_RANGE, ""]
    L += vio_table(results, families)
    L += ["", "## Where the open-sky flights miss", "",
          "The open-sky UAV runs of all families pooled by the drawn height and speed and by the dataset's "
          "length (take-off to landing); 'runs' counts the VIO runs of the band.", ""]
    L += band_table(results, families)
    L += ["", "## Targets", "", "| family | target | measured | result | worst seed |", "|---|---|---|---|---|"]
    rows = target_rows(results, families, modes)
    for n, target, measured, met, worst in rows:
        L.append("| %s | %s | %s | %s | %s |" % (n, target, measured, "met" if met else "**missed**",
                                                 variant_text(worst) if worst else ""))
    missed = sum(not r[3] for r in rows)
    L += ["", "%d of %d targets missed." % (missed, len(rows))]
    failures = [r for r in results if r["status"] != "ok"]
    if failures:
        L += ["", "## Failed runs", "", "| family | seed | mode | message |", "|---|---|---|---|"]
        for r in sorted(failures, key=lambda r: (r["family"], r["seed"], r["mode"])):
            L.append("| %s | %d | %s | %s |" % (r["family"], r["seed"], r["mode"], (r["error"] or "").replace("|", "/")))
    L += ["", "## Run time", "",
          "Sum of the run times (simulation + replay, wall clock of each run): %.0f s for %d family seeds, %.0f s "
          "per seed of all %d families. This invocation computed %d runs in %.0f s wall clock (the rest came from the cache). "
          "Projected for 20 seeds: %.1f h with --jobs 1, about %.1f h with --jobs 2 on an otherwise idle 2-core "
          "machine (each replay also runs a front-end thread, so two jobs do not halve the time exactly)." % (
              run_s, scenarios, per_seed, len(families), info["computed"], info["wall_s"], 20 * per_seed / 3600,
              20 * per_seed / 3600 / 2), ""]
    return "\n".join(L)
