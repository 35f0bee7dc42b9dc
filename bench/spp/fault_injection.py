#!/usr/bin/env python3
"""SPP fault exclusion under injected multipath-like faults, on real recordings and the simulated
urban drive.

    bench/spp/fault_injection.py [BUILD_DIR] [--markdown] [--rtklib] [--write]
                                                                    (default build dir: build)

For every RINEX 3 recording with a known antenna position (Nagoya rover, Kamakura; the simulated
urban drive of bench/spp/urban_spp.yaml, already full of NLOS and multipath) it writes copies of
the observation file in which 1, 2 or 3 satellites of every epoch carry a positive bias on all
their pseudoranges (every code observable, so an ionosphere-free pair carries it too): each bias
uniform in 10-100 m, the satellites drawn at random among those of the epoch above 15 degrees
elevation (from the truth position), a new draw every 10 s (a reflection lasts a while). Seeded:
the same files every run. gvins-spp (defaults) solves each copy; per case and number of faults
the table gives the RMS and 95th percentile of the 3-D error, the largest error, the share of
epochs whose residual test still fails (test = 1), and the share of epochs whose error is within
3 reported sigma on every axis. A second gvins-spp run keeps the robust weights of the epochs that
pass the residual test on those that fail it (robust: {k0_failed: 2, k1_failed: 5}), the behaviour
before the harder down-weighting of failed epochs. With --rtklib, RTKLIB 2.4.3's SPP (rnx2rtkp -p 0, RAIM-FDE on) of
the same copies as a reference.

--write writes the table to docs/results/spp_fault_injection.md with the commit and the command
(docs/spp.md, "Injected faults", says what it shows).
"""
import datetime
import gzip
import math
import os
import random
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sigma_calibration as sc  # noqa: E402

RESULTS = os.path.join(sc.ROOT, "docs", "results", "spp_fault_injection.md")
SEGMENT_S = 10.0
BIAS_M = (10.0, 100.0)
MASK_DEG = 15.0
GM = 3.986005e14
OMEGA_E = 7.2921151467e-5


def read_lines(path):
    op = gzip.open if path.endswith(".gz") else open
    with op(path, "rt") as f:
        return f.read().splitlines()


def code_columns(header):
    """{system letter: [field index of every C.. observable]} from SYS / # / OBS TYPES."""
    cols, cur = {}, None
    for line in header:
        if line[60:].startswith("SYS / # / OBS TYPES"):
            if line[0] != " ":
                cur = line[0]
                cols[cur] = []
            cols[cur] += line[7:58].split()
    return {s: [i for i, t in enumerate(v) if t.startswith("C")] for s, v in cols.items()}


def inject(obs_lines, nfaults, seed, visible):
    """The observation file with faults; visible(epoch seconds, [sat ids]) -> sats above the mask."""
    end = next(i for i, l in enumerate(obs_lines) if l[60:].startswith("END OF HEADER"))
    header = obs_lines[:end + 1]
    cols = code_columns(header)
    rng = random.Random(seed)
    out = list(header)
    i = end + 1
    segment, chosen = None, {}
    while i < len(obs_lines):
        line = obs_lines[i]
        n = int(line[32:35])
        t = line[2:29].split()
        secs = int(t[3]) * 3600 + int(t[4]) * 60 + float(t[5])
        sats = [obs_lines[i + 1 + k][:3] for k in range(n)]
        seg = int(secs // SEGMENT_S)
        if seg != segment:
            segment = seg
            cand = visible(line, sats)
            rng.shuffle(cand)
            chosen = {s: rng.uniform(*BIAS_M) for s in cand[:nfaults]}
        out.append(line)
        for k in range(n):
            rec = obs_lines[i + 1 + k]
            if rec[:3] in chosen:
                rec = rec.ljust(3 + 16 * (max(cols.get(rec[0], [0])) + 1))
                for c in cols.get(rec[0], []):
                    f = rec[3 + 16 * c:3 + 16 * c + 14]
                    if f.strip():
                        v = float(f) + chosen[rec[:3]]
                        rec = rec[:3 + 16 * c] + "%14.3f" % v + rec[3 + 16 * c + 14:]
                rec = rec.rstrip()
            out.append(rec)
        i += n + 1
    return out


class Visibility:
    """Elevation of the satellites of an epoch from a first gvins-spp run's satellite set: the
    satellites above the mask are those RINEX lists that the broadcast orbits put above it. To
    stay independent of our own code it uses the Keplerian GPS-style records of a RINEX 3
    navigation file (G, E, J, C MEO); satellites without a record are never faulted."""

    def __init__(self, nav_paths, truth):
        self.eph = {}
        for p in nav_paths:
            self._read(p)
        self.truth = truth
        lat, lon = sc.ecef_to_latlon(truth)
        self.r = sc.enu_rotation(lat, lon)

    def _read(self, path):
        lines = read_lines(path)
        end = next(i for i, l in enumerate(lines) if "END OF HEADER" in l)
        i = end + 1
        while i < len(lines):
            l = lines[i]
            sys_ = l[0]
            nrec = {"G": 8, "E": 8, "J": 8, "C": 8, "R": 4, "S": 4, "I": 8}.get(sys_, 0)
            if nrec == 0 or sys_ in "RS":
                i += max(nrec, 1)
                continue
            vals = [l[23:42], l[42:61], l[61:80]]
            for k in range(1, nrec):
                s = lines[i + k]
                vals += [s[4:23], s[23:42], s[42:61], s[61:80]]
            v = [float(x.replace("D", "E")) if x.strip() else 0.0 for x in vals]
            self.eph.setdefault(l[:3], v)
            i += nrec

    def position(self, sat, tow):
        v = self.eph.get(sat)
        if v is None:
            return None
        crs, dn, m0, cuc, e, cus, sqa, toe, cic, om0, cis, i0, crc, w, omd, idot = (
            v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13], v[14], v[15], v[16], v[17], v[18], v[19])
        a = sqa * sqa
        tk = (tow - toe + 302400) % 604800 - 302400
        mk = m0 + (math.sqrt(GM / a ** 3) + dn) * tk
        ek = mk
        for _ in range(10):
            ek = mk + e * math.sin(ek)
        nu = math.atan2(math.sqrt(1 - e * e) * math.sin(ek), math.cos(ek) - e)
        phi = nu + w
        u = phi + cus * math.sin(2 * phi) + cuc * math.cos(2 * phi)
        r = a * (1 - e * math.cos(ek)) + crs * math.sin(2 * phi) + crc * math.cos(2 * phi)
        inc = i0 + idot * tk + cis * math.sin(2 * phi) + cic * math.cos(2 * phi)
        om = om0 + (omd - OMEGA_E) * tk - OMEGA_E * toe
        x, y = r * math.cos(u), r * math.sin(u)
        return [x * math.cos(om) - y * math.cos(inc) * math.sin(om), x * math.sin(om) + y * math.cos(inc) * math.cos(om),
                y * math.sin(inc)]

    def __call__(self, epoch_line, sats):
        t = epoch_line[2:29].split()
        import datetime
        d = datetime.datetime(int(t[0]), int(t[1]), int(t[2]))
        tow = ((d.weekday() + 1) % 7) * 86400 + int(t[3]) * 3600 + int(t[4]) * 60 + float(t[5])
        out = []
        for s in sats:
            p = self.position(s, tow)  # BeiDou's time offset (14 s) moves it by < 50 m: irrelevant here
            if p is None:
                continue
            enu = sc.mat_vec(self.r, [p[k] - self.truth[k] for k in range(3)])
            if math.degrees(math.atan2(enu[2], math.hypot(enu[0], enu[1]))) >= MASK_DEG:
                out.append(s)
        return sorted(out)


def stats(rows, truth):
    errs, within, failed = [], 0, 0
    for t, x, c, test in rows:
        tx = truth.at(t) if hasattr(truth, "at") else truth
        if tx is None:
            continue
        lat, lon = sc.ecef_to_latlon(tx)
        e = sc.mat_vec(sc.enu_rotation(lat, lon), [x[k] - tx[k] for k in range(3)])
        errs.append(math.sqrt(sum(v * v for v in e)))
        within += all(abs(e[a]) <= 3.0 * math.sqrt(max(c[a][a], 1e-30)) for a in range(3))
        failed += test == 1
    n = len(errs)
    if n == 0:
        return None
    s = sorted(errs)
    return n, math.sqrt(sum(v * v for v in errs) / n), s[int(0.95 * (n - 1))], s[-1], 100.0 * failed / n, \
        100.0 * within / n


def cases(build, tmp):
    n = os.path.join(sc.DATA, "nagoya_static_2024")
    k = os.path.join(sc.DATA, "kamakura_static_2021")
    out = [("Nagoya rover", n + "/rover.obs.gz", [n + "/base.nav.gz"], sc.position_file(n + "/rover_position.txt")),
           ("Kamakura", k + "/SEPT078M.21O.gz", [k + "/SEPT078M.21P.gz", k + "/30340780.21q.gz"],
            [-3962108.673, 3381309.574, 3668678.638])]
    for name, inputs, truth, _, _ in sc.simulated_case(build, tmp):
        out.append((name, inputs[0], inputs[1:], truth))
    return out


def rtklib_spp(obs, navs, tmp):
    conf = os.path.join(tmp, "spp.conf")
    with open(conf, "w") as f:
        f.write("pos1-posmode=single\npos1-elmask=15\npos1-navsys=61\npos1-ionoopt=brdc\npos1-tropopt=saas\n"
                "pos1-posopt5=on\nout-solformat=xyz\n")
    out = os.path.join(tmp, "rtklib.pos")
    subprocess.run(["rnx2rtkp", "-k", conf, "-o", out, obs] + navs, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return out


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    markdown, rtklib, write = "--markdown" in sys.argv, "--rtklib" in sys.argv, "--write" in sys.argv
    build = args[0] if args else "build"
    build = build if os.path.isabs(build) else os.path.join(sc.ROOT, build)
    spp = os.path.join(build, "bin", "gvins-spp")
    tmp = tempfile.mkdtemp()
    lines = ["| recording | faults per epoch | solution | epochs | RMS 3-D (m) | 95 % 3-D (m) | max 3-D (m) "
             "| test failed (%) | within 3 σ on E, N and U (%) |", "|---|---|---|---|---|---|---|---|---|"]
    same = os.path.join(tmp, "same.yaml")  # the behaviour before robust.k0_failed/k1_failed
    with open(same, "w") as f:
        f.write("spp:\n  robust: {k0_failed: 2.0, k1_failed: 5.0}\n")
    for name, obs, navs, truth in cases(build, tmp):
        first = truth.at(truth.rows[0][0]) if hasattr(truth, "rows") else truth
        vis = Visibility(navs, first)
        base = read_lines(obs)
        for nf in range(4):
            path = os.path.join(tmp, "faulty.obs")
            with open(path, "w") as f:
                f.write("\n".join(inject(base, nf, 1000 + nf, vis)) + "\n")
            out = os.path.join(tmp, "out.pos")
            runs = []
            for label, extra in (("gvins-spp", []), ("gvins-spp, robust k0/k1 2/5 on failed epochs too", ["--config", same])):
                subprocess.run([spp, "-q", "--xyz", "-o", out] + extra + [path] + navs, check=True,
                               stderr=subprocess.DEVNULL)
                runs.append((label, sc.read_pos(out)))
            if rtklib:
                runs.append(("RTKLIB 2.4.3 (RAIM-FDE)", sc.read_pos(rtklib_spp(path, navs, tmp))))
            for label, rows in runs:
                st = stats(rows, truth)
                if st is None:
                    lines.append("| %s | %d | %s | 0 | | | | | |" % (name, nf, label))
                else:
                    lines.append("| %s | %d | %s | %d | %.2f | %.2f | %.1f | %.1f | %.1f |" % ((name, nf, label) + st))
                print(lines[-1], file=sys.stderr)
    print("\n".join(lines) if markdown or write else "\n".join(lines[2:]))
    if write:
        commit = sc.commit_of_tree()  # before the file is opened (and so modified)
        command = "bench/spp/fault_injection.py BUILD_DIR --write" + (" --rtklib" if rtklib else "")
        with open(RESULTS, "w") as f:
            f.write("<!-- written by bench/spp/fault_injection.py; do not edit by hand -->\n")
            f.write("# SPP under injected pseudorange faults\n\n")
            f.write("Written by `%s` at commit %s, %s. What the rows are and what they say: docs/spp.md, "
                    "\"Injected faults\".\n\n" % (command, commit, datetime.date.today().isoformat()))
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
