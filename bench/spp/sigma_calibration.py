#!/usr/bin/env python3
"""SPP sigma calibration on the real recordings with a known antenna position.

    bench/spp/sigma_calibration.py [BUILD_DIR] [--markdown] [--write] [--check] [--seeds N]
                                                        (default build dir: build)

Needs gvins-spp and, for the simulated case, gvins-sim in BUILD_DIR/bin.

Runs gvins-spp on every recording: with the a-priori covariance of the weighted least squares
(`covariance_scaling` and `reported_error` off), with the correlated-error model off (all errors
independent, scaled by the variance factor), with the defaults (errors correlated between
satellites, docs/spp.md), and the last two on dual-frequency ionosphere-free pseudoranges
(`--freq 2 --iono dual-frequency`), and scores
RTKLIB 2.4.3's stored SPP solutions of the same files where there are some
(tests/data/reference/rtklib-2.4.3). For each run and axis (east, north, up) it prints the share of
epochs whose error lies within 1, 2 and 3 of the reported standard deviations; a Gaussian error
with an honest sigma gives 68.3 / 95.4 / 99.7 %. Also the median of |error|/sigma (0.674 for an
honest sigma) and the RMS error. Epochs whose residual test failed (test = 1) are counted like the
others, and scored apart as well where there are some.

Truths: Nagoya rover and base: the positions in tests/data/gnss/nagoya_static_2024/*_position.txt;
Kamakura: the GSI F5 ECEF position in tests/data/README.md; GEONET 0759 and 3040: only the
approximate position of their RINEX headers (RTKLIB's static RTK puts 0759 within 0.2 m of it,
small against SPP errors of metres); RTKLIB's testglo RTCM log (GPS + GLONASS, 3 minutes, as
convbin's RINEX in tests/data/reference): the reference station position of its own 1005
messages; the u-blox walk (tests/data/ubx/gnss_1730.ubx, 4 Hz, own
SFRBX ephemerides): the receiver's own real-time RTK track (its NAV-PVT solutions, written with
ellipsoidal heights by `gvins-ubx to-pos`; walk_reference), with the mean horizontal error removed (its base position is not published). Simulated: a 10-minute urban
drive (bench/spp/urban_spp.yaml: 1.5 m code multipath, NLOS reception of 5-80 m extra path on
low satellites) with gvins-sim's antenna truth, standing in for the urban recordings we do not
have.

--seeds N also simulates the urban drive with seeds 1..N (the yaml's `seed` replaced) and gives,
for the defaults on single frequency and on ionosphere-free pseudoranges, the spread over the
seeds of the share within 3 sigma and of the median |error|/sigma per axis (one seed is one draw
of multipath and NLOS: no figure of the drive should rest on it).

--write writes the table to docs/results/spp_sigma.md with the commit and the command.
--check exits non-zero unless the bands of check() hold (the ctest test spp_sigma_calibration):
within 3 sigma >= 97 % on every axis of every real recording, with the defaults on single
frequency and on ionosphere-free pseudoranges and with the correlated-error model off (single
frequency), and the defaults' median |error|/sigma >= 0.1 (the sigma not more than about 7x the
typical error); on the simulated drive (the yaml's seed), ionosphere-free with the defaults,
within 3 sigma >= 97 % and median |error|/sigma >= 0.4 on every axis.
"""
import datetime
import gzip
import math
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.path.join(ROOT, "tests", "data", "gnss")
REF = os.path.join(ROOT, "tests", "data", "reference", "rtklib-2.4.3")
UBX = os.path.join(ROOT, "tests", "data", "ubx", "gnss_1730.ubx")
# The walk's reference: the receiver's own real-time RTK track, i.e. the log's NAV-PVT solutions,
# written with ellipsoidal heights by `gvins-ubx to-pos` (the shipped gnss_1730_sf.pos holds the
# same track with mean-sea-level heights; test_ubx_to_pos checks the two against each other).

# WGS84 (NIMA TR8350.2)
A = 6378137.0
F = 1.0 / 298.257223563
E2 = F * (2.0 - F)


def llh_to_ecef(lat_deg, lon_deg, h):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = A / math.sqrt(1.0 - E2 * math.sin(lat) ** 2)
    return [(n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - E2) + h) * math.sin(lat)]


def ecef_to_latlon(x):
    p = math.hypot(x[0], x[1])
    lat = math.atan2(x[2], p * (1.0 - E2))
    for _ in range(10):
        n = A / math.sqrt(1.0 - E2 * math.sin(lat) ** 2)
        h = p / math.cos(lat) - n
        lat = math.atan2(x[2], p * (1.0 - E2 * n / (n + h)))
    return lat, math.atan2(x[1], x[0])


def enu_rotation(lat, lon):
    sl, cl, sp, cp = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    return [[-sp, cp, 0.0], [-sl * cp, -sl * sp, cl], [cl * cp, cl * sp, sl]]


def mat_vec(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def rotate_cov(r, c):  # r c r^T
    rc = [[sum(r[i][k] * c[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return [[sum(rc[i][k] * r[j][k] for k in range(3)) for j in range(3)] for i in range(3)]


def signed_sq(v):
    return -v * v if v < 0 else v * v


GPS_EPOCH = datetime.datetime(1980, 1, 6)


def gpst_ns(date, time):
    """GPST 'yyyy/mm/dd' 'hh:mm:ss.sss' as ns since the GPS epoch (the calendar of GPST, no leap seconds)."""
    d = datetime.datetime.strptime(date + " " + time.split(".")[0], "%Y/%m/%d %H:%M:%S")
    frac = float("0." + time.split(".")[1]) if "." in time else 0.0
    return int((d - GPS_EPOCH).total_seconds()) * 1000000000 + round(frac * 1e9)


def read_pos(path):
    """(GPST ns, ecef position, ENU covariance, test flag or None) per row of a .pos file of either layout."""
    rows, ecef, test_col = [], False, False
    with open(path) as f:
        for line in f:
            if line.startswith("%"):
                if "x-ecef(m)" in line or "latitude(deg)" in line:
                    ecef = "x-ecef(m)" in line
                    test_col = line.split()[-1] == "test"
                continue
            t = line.split()
            if len(t) < 13:
                continue
            test = int(t[-1]) if test_col else None
            v = [float(x) for x in t[2:5]]
            sd = [float(x) for x in t[7:10]]
            cr = [float(x) for x in t[10:13]]
            c = [[sd[0] ** 2, signed_sq(cr[0]), signed_sq(cr[2])],
                 [signed_sq(cr[0]), sd[1] ** 2, signed_sq(cr[1])],
                 [signed_sq(cr[2]), signed_sq(cr[1]), sd[2] ** 2]]
            if ecef:
                x = v
                lat, lon = ecef_to_latlon(x)
                c = rotate_cov(enu_rotation(lat, lon), c)
            else:
                x = llh_to_ecef(*v)
                # n, e, u columns -> e, n, u
                p = [1, 0, 2]
                c = [[c[p[i]][p[j]] for j in range(3)] for i in range(3)]
            rows.append((gpst_ns(t[0], t[1]), x, c, test))
    return rows


def header_position(obs_gz):
    with gzip.open(obs_gz, "rt") as f:
        for line in f:
            if "APPROX POSITION XYZ" in line:
                return [float(x) for x in line[:42].split()]
            if "END OF HEADER" in line:
                break
    raise RuntimeError(obs_gz + ": no APPROX POSITION XYZ")


def position_file(path):
    with open(path) as f:
        lat, lon, h = (float(x) for x in f.read().split()[:3])
    return llh_to_ecef(lat, lon, h)


def simulated_case(build, tmp, seed=None):
    """The harsh simulated drive of bench/spp/urban_spp.yaml (multipath, NLOS), made by gvins-sim;
    with `seed`, the same drive with that seed."""
    sim = os.path.join(build, "bin", "gvins-sim")
    if not os.access(sim, os.X_OK):
        print("gvins-sim not built: no simulated case", file=sys.stderr)
        return []
    config = os.path.join(ROOT, "bench", "spp", "urban_spp.yaml")
    out = os.path.join(tmp, "urban_spp")
    if seed is not None:
        with open(config) as f:
            text = f.read()
        nav = os.path.join(ROOT, "tests", "data", "gnss", "nagoya_static_2024", "base.nav.gz")
        text = "\n".join("seed: %d" % seed if l.startswith("seed:") else
                         "  navigation: " + nav if l.strip().startswith("navigation:") else l
                         for l in text.splitlines()) + "\n"
        config = os.path.join(tmp, "urban_spp_seed.yaml")
        with open(config, "w") as f:
            f.write(text)
        shutil.rmtree(out, ignore_errors=True)
    subprocess.run([sim, "--config", config, "--features-only", "--threads", "1", "-o", out], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    g = os.path.join(out, "gnss")
    return [("Sim urban drive", [g + "/rover.obs", g + "/nav.rnx"], AntennaTrack(g + "/truth/rover_antenna.csv"), None,
             "simulation truth")]


def seed_spread(build, spp, tmp, seeds):
    """Markdown lines: per solution (defaults, single frequency and ionosphere-free) and axis, the
    spread over seeds 1..`seeds` of the simulated drive of the share within 3 sigma and of the
    median |error|/sigma."""
    runs = [("default", []), ("default, dual-frequency", ["--freq", "2", "--iono", "dual-frequency"])]
    got = {label: [] for label, _ in runs}
    for seed in range(1, seeds + 1):
        _, inputs, truth, _, _ = simulated_case(build, tmp, seed)[0]
        for label, extra in runs:
            out = os.path.join(tmp, "seed.pos")
            subprocess.run([spp, "-q"] + extra + ["-o", out] + inputs, check=True, stderr=subprocess.DEVNULL)
            _, pct, med, _ = score(read_pos(out), truth)
            got[label].append(([pct[a][2] for a in range(3)], med))
        print("seed %d done" % seed, file=sys.stderr)
    lines = ["| solution | axis | within 3 σ (%) min / median / max | median abs(err)/σ min / median / max |",
             "|---|---|---|---|"]
    for label, _ in runs:
        for a in range(3):
            w = sorted(x[0][a] for x in got[label])
            m = sorted(x[1][a] for x in got[label])
            lines.append("| gvins-spp %s | %s | %.1f / %.1f / %.1f | %.2f / %.2f / %.2f |" % (
                label, "ENU"[a], w[0], w[len(w) // 2], w[-1], m[0], m[len(m) // 2], m[-1]))
    return lines


def cases(build, tmp):
    n = os.path.join(DATA, "nagoya_static_2024")
    k = os.path.join(DATA, "kamakura_static_2021")
    g = os.path.join(DATA, "geonet_0759_3040_2005")
    return [
        ("Nagoya rover", [n + "/rover.obs.gz", n + "/base.nav.gz"], position_file(n + "/rover_position.txt"),
         "nagoya_rover_spp.pos", "rover_position.txt"),
        ("Nagoya base", [n + "/base.obs.gz", n + "/base.nav.gz"], position_file(n + "/base_position.txt"), None,
         "base_position.txt"),
        ("Kamakura", [k + "/SEPT078M.21O.gz", k + "/SEPT078M.21P.gz", k + "/30340780.21q.gz"],
         [-3962108.673, 3381309.574, 3668678.638], "kamakura_sept078_spp.pos", "GSI F5 (data README)"),
        ("GEONET 0759", [g + "/07590920.05o.gz", g + "/07590920.05n.gz"], header_position(g + "/07590920.05o.gz"),
         "geonet_0759_spp.pos", "RINEX header only"),
        ("GEONET 3040", [g + "/30400920.05o.gz", g + "/30400920.05n.gz"], header_position(g + "/30400920.05o.gz"),
         None, "RINEX header only"),
        ("u-blox walk", [UBX], walk_reference(build, tmp), "ubx_gnss_1730_spp.pos",
         "publisher's RTK track, mean horizontal error removed"),
        ("RTCM testglo", [REF + "/rtcm_testglo_convbin.obs", REF + "/rtcm_testglo_convbin.nav"],
         [-3869297.5138, 3436571.3345, 3717369.3757], None, "station position of its 1005 message"),
    ]


def walk_reference(build, tmp):
    """The u-blox walk's reference track with ellipsoidal heights: the receiver's NAV-PVT solutions
    of the log, written by `gvins-ubx to-pos`."""
    path = os.path.join(tmp, "walk_reference.pos")
    subprocess.run([os.path.join(build, "bin", "gvins-ubx"), "to-pos", UBX, "-o", path], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return ReferenceTrack(path)


class ReferenceTrack:
    """A reference .pos track (latitude/longitude/height, GPST): the position of the row nearest
    in time, within 0.1 s (the solutions of a 4 Hz receiver carry its epoch times to the ms);
    `height_offset` (m) is added to its heights (0 for a track with ellipsoidal heights). Its horizontal position is relative: the track
    is an RTK solution relative to a base station whose position is not published (every SPP
    solution, ours and RTKLIB's, sits 6-8 m off it horizontally), so the mean horizontal error is
    removed before scoring (horizontal: the time-varying part only; up: absolute)."""

    relative_axes = (0, 1)

    def __init__(self, path, height_offset=0.0):
        self.rows = []
        for t, x, _, _ in read_pos(path):
            lat, lon = ecef_to_latlon(x)
            up = [math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)]
            self.rows.append((t, [x[i] + height_offset * up[i] for i in range(3)]))
        self.rows.sort()

    def at(self, t):
        import bisect
        i = bisect.bisect_left(self.rows, (t,))
        near = [r for r in self.rows[max(i - 1, 0):i + 1] if abs(r[0] - t) <= 100000000]
        return min(near, key=lambda r: abs(r[0] - t))[1] if near else None


class AntennaTrack:
    """gvins-sim's gnss/truth/rover_antenna.csv: the antenna position and velocity at the true GPST
    of every rover epoch; at a solution's time t the position moved on by v (t - t_k)."""

    def __init__(self, path):
        self.rows = []
        with open(path) as f:
            for line in f:
                if line[0] in "#t":
                    continue
                v = line.split(",")
                self.rows.append((int(v[1]), [float(x) for x in v[2:5]], [float(x) for x in v[5:8]]))
        self.rows.sort()

    def at(self, t):
        import bisect
        i = bisect.bisect_left(self.rows, (t,))
        best = min((r for r in self.rows[max(i - 1, 0):i + 1]), key=lambda r: abs(r[0] - t))
        dt = (t - best[0]) * 1e-9
        if abs(dt) > 0.5:
            return None
        return [best[1][k] + best[2][k] * dt for k in range(3)]


def score(rows, truth):
    within = [[0, 0, 0] for _ in range(3)]
    ratios = [[] for _ in range(3)]
    sq = [0.0, 0.0, 0.0]
    errors = []
    for t, x, c, _ in rows:
        tx = truth.at(t) if hasattr(truth, "at") else truth
        if tx is None:
            continue
        lat, lon = ecef_to_latlon(tx)
        errors.append((mat_vec(enu_rotation(lat, lon), [x[i] - tx[i] for i in range(3)]), c))
    n = len(errors)
    relative = getattr(truth, "relative_axes", ())
    mean = [sum(e[a] for e, _ in errors) / n if a in relative else 0.0 for a in range(3)]
    for e, c in errors:
        e = [e[a] - mean[a] for a in range(3)]
        for a in range(3):
            s = math.sqrt(max(c[a][a], 0.0))
            q = abs(e[a]) / s if s > 0 else float("inf")
            ratios[a].append(q)
            sq[a] += e[a] ** 2
            for k in range(3):
                within[a][k] += q <= k + 1
    med = [sorted(q)[len(q) // 2] if q else float("nan") for q in ratios]
    return n, [[100.0 * w / n for w in within[a]] for a in range(3)], med, [math.sqrt(s / n) for s in sq]


EXTRA_RUNS = []  # (label, gvins-spp arguments): experiments
RESULTS = os.path.join(ROOT, "docs", "results", "spp_sigma.md")
MODEL_OFF = "correlated-error model off"  # label of the runs with spp.reported_error disabled


def runs_of(spp, inputs, tmp):
    """(label, rows) of every gvins-spp configuration on one recording."""
    apriori = os.path.join(tmp, "apriori.yaml")
    independent = os.path.join(tmp, "independent.yaml")
    with open(apriori, "w") as f:
        f.write("spp:\n  covariance_scaling: {enabled: false}\n  reported_error: {enabled: false}\n")
    with open(independent, "w") as f:
        f.write("spp:\n  reported_error: {enabled: false}\n")
    dual = ["--freq", "2", "--iono", "dual-frequency"]
    runs = []
    for label, extra in [("a-priori", ["--config", apriori]), (MODEL_OFF, ["--config", independent]),
                         ("default", []), ("default, dual-frequency", dual),
                         (MODEL_OFF + ", dual-frequency", ["--config", independent] + dual)] + EXTRA_RUNS:
        out = os.path.join(tmp, "out.pos")
        cmd = [spp, "-q"] + extra + ["-o", out] + inputs
        p = subprocess.run(cmd, stderr=subprocess.PIPE, text=True)
        if p.returncode != 0:
            sys.exit("failed: " + " ".join(cmd) + "\n" + p.stderr)
        runs.append(("gvins-spp " + label, read_pos(out)))
    return runs


CHECKED = ("gvins-spp default", "gvins-spp " + MODEL_OFF, "gvins-spp default, dual-frequency")


def check(name, label, pct, med):
    """The bands of --check; a list of failures. Every real recording, with the defaults (single
    frequency and ionosphere-free) and with the correlated-error model off (single frequency): at
    least 97 % of the epochs within 3 sigma on every axis (not optimistic); with the defaults the
    median |error|/sigma over the axes at least 0.1 (not grossly pessimistic)."""
    bad = []
    if label not in CHECKED:
        return bad
    for a in range(3):
        if pct[a][2] < 97.0:
            bad.append("%s, %s: %s within 3 sigma %.1f %% < 97 %%" % (name, label, "ENU"[a], pct[a][2]))
    m = sorted(med)[1]
    if label != "gvins-spp " + MODEL_OFF and m < 0.1:
        bad.append("%s, %s: median |error|/sigma %.2f < 0.1 (sigma grossly pessimistic)" % (name, label, m))
    return bad


def check_simulated(name, label, pct, med):
    """The band of --check on the simulated drive (the yaml's seed), ionosphere-free with the
    defaults, where the non-line-of-sight delays stay in the solution: at least 97 % within
    3 sigma on every axis, and the median |error|/sigma of every axis at least 0.4 (an honest
    sigma gives 0.674: not more than about 1.7x too wide)."""
    if label != "gvins-spp default, dual-frequency":
        return []
    bad = ["%s, %s: %s within 3 sigma %.1f %% < 97 %%" % (name, label, "ENU"[a], pct[a][2])
           for a in range(3) if pct[a][2] < 97.0]
    bad += ["%s, %s: %s median |error|/sigma %.2f < 0.4" % (name, label, "ENU"[a], med[a])
            for a in range(3) if med[a] < 0.4]
    return bad


def commit_of_tree():
    def git(*a):
        return subprocess.run(["git", "-C", ROOT] + list(a), capture_output=True, text=True).stdout.strip()
    c = git("rev-parse", "--short", "HEAD")
    # Results files being rewritten do not count as changes of the tree that made them.
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!docs/results")
    return c + (" (with uncommitted changes)" if dirty else "")


def main():
    seeds = int(sys.argv[sys.argv.index("--seeds") + 1]) if "--seeds" in sys.argv else 0
    args = [a for i, a in enumerate(sys.argv[1:], 1) if not a.startswith("--") and sys.argv[i - 1] != "--seeds"]
    markdown = "--markdown" in sys.argv or "--write" in sys.argv
    build = args[0] if args else "build"
    build = build if os.path.isabs(build) else os.path.join(ROOT, build)
    spp = os.path.join(build, "bin", "gvins-spp")
    if not os.access(spp, os.X_OK):
        sys.exit("gvins-spp not built: " + spp)
    tmp = tempfile.mkdtemp()
    lines, failures = [], []
    if markdown:
        lines.append("| recording (truth) | solution | epochs | E 1/2/3 σ (%) | N 1/2/3 σ (%) | U 1/2/3 σ (%) "
                     "| median abs(err)/σ E/N/U | RMS E/N/U (m) |")
        lines.append("|---|---|---|---|---|---|---|---|")
    else:
        lines.append("%-15s %-31s %6s  %-17s %-17s %-17s %-17s %s" % (
            "recording", "solution", "epochs", "E within 1/2/3 sd", "N within 1/2/3 sd", "U within 1/2/3 sd",
            "median |e|/sd ENU", "RMS E/N/U m"))
    for name, inputs, truth, ref, truth_note in cases(build, tmp) + simulated_case(build, tmp):
        runs = runs_of(spp, inputs, tmp)
        if ref:
            runs.append(("RTKLIB 2.4.3 (stored)", read_pos(os.path.join(REF, ref))))
        print("%s: %s" % (name, " ".join(os.path.basename(i) for i in inputs)), file=sys.stderr)
        for label, all_rows in runs:
            # All epochs, then (where there are some) only those whose residual test failed.
            failed = [r for r in all_rows if r[3] == 1]
            for part, rows in (("", all_rows), (", test=1 only", failed)):
                if not rows:
                    continue
                n, pct, med, rms = score(rows, truth)
                if not part:
                    failures += (check_simulated if name.startswith("Sim") else check)(name, label, pct, med)
                if markdown:
                    lines.append("| %s (%s) | %s | %d | %s | %s | %s | %s | %s |" % (
                        name, truth_note, label + part, n, *["%.1f / %.1f / %.1f" % tuple(pct[a]) for a in range(3)],
                        " / ".join("%.2f" % m for m in med), " / ".join("%.2f" % r for r in rms)))
                else:
                    lines.append("%-15s %-31s %6d  %-17s %-17s %-17s %-17s %s" % (
                        name, label + part, n, *["%4.1f %4.1f %5.1f" % tuple(pct[a]) for a in range(3)],
                        " ".join("%5.2f" % m for m in med), " ".join("%5.2f" % r for r in rms)))
    print("\n".join(lines))
    spread = seed_spread(build, spp, tmp, seeds) if seeds else []
    if spread:
        print("\n".join(spread))
    shutil.rmtree(tmp)
    if "--write" in sys.argv:
        commit = commit_of_tree()  # before the file is opened (and so modified)
        with open(RESULTS, "w") as f:
            f.write("# SPP standard deviation against the truth\n\n")
            f.write("Written by `bench/spp/sigma_calibration.py BUILD_DIR --write%s` at commit %s, %s. "
                    "What the columns mean and what the rows say: docs/spp.md, \"Standard deviation\".\n\n"
                    % (" --seeds %d" % seeds if seeds else "", commit, datetime.date.today().isoformat()))
            f.write("\n".join(lines) + "\n")
            if spread:
                f.write("\n## Simulated urban drive, seeds 1-%d\n\n" % seeds)
                f.write("The drive of bench/spp/urban_spp.yaml with its seed replaced by 1..%d: the spread over the "
                        "seeds.\n\n" % seeds)
                f.write("\n".join(spread) + "\n")
    if "--check" in sys.argv:
        for msg in failures:
            print("FAIL " + msg, file=sys.stderr)
        sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
