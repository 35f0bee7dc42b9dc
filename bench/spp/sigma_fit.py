#!/usr/bin/env python3
"""Cross-validated choice of the SPP correlated-error model's scale (spp.reported_error, docs/spp.md).

    bench/spp/sigma_fit.py [BUILD_DIR] [--markdown] [--write]     (default build dir: build)

--write writes the table to docs/results/spp_sigma_fit.md with the commit and the command.

Runs gvins-spp on the real recordings with a known antenna position (the cases of
sigma_calibration.py: Nagoya rover and base, Kamakura, GEONET 0759 and 3040, the u-blox walk
with its mean horizontal error removed) with the
correlated-error model over a grid of its one scale, the correlation length of the broadcast
ionosphere error (reported_error.ionosphere_correlation_km); the solutions do not change with it,
only the reported covariance. A length is scored on a set of sites by pooling: p_ak, the share (%)
of epochs whose error on axis a (east, north, up) is within k reported standard deviations, is
averaged over the recordings of a site and then over the sites (each site counts once whatever
its length), and the loss is the sum over axes and k = 1, 2, 3 of |p_ak - (68.3, 95.4, 99.7)_k|.
One recording's error is nearly one draw of a slowly varying error (ionosphere, orbits: minutes
to hours), so only the pooled shares can approach the Gaussian ones.

Cross-validation by site (the two Nagoya receivers are one site, the two GEONET stations another:
their errors are shared): for each site the length that scores best on the other sites is chosen
and the site's shares under it are kept; the pooled held-out shares are the cross-validated
estimate. The simulated urban drive is not used: sigma_calibration.py checks it.

See docs/spp.md for what this prints.
"""
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sigma_calibration as sc  # noqa: E402

LENGTHS_KM = [500, 1000, 2000, 4000, 8000]
TARGET = (68.3, 95.4, 99.7)
SITES = {"Nagoya rover": "Nagoya", "Nagoya base": "Nagoya", "Kamakura": "Kamakura", "GEONET 0759": "GEONET",
         "GEONET 3040": "GEONET", "u-blox walk": "u-blox walk"}


def pooled(pcts):
    """Mean of a list of 3x3 share tables."""
    return [[sum(p[a][k] for p in pcts) / len(pcts) for k in range(3)] for a in range(3)]


def loss(pct):
    return sum(abs(pct[a][k] - TARGET[k]) for a in range(3) for k in range(3))


def fmt(pct):
    return " | ".join("%.0f / %.0f / %.0f" % tuple(pct[a]) for a in range(3))


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    markdown = "--markdown" in sys.argv or "--write" in sys.argv
    build = args[0] if args else "build"
    build = build if os.path.isabs(build) else os.path.join(sc.ROOT, build)
    spp = os.path.join(build, "bin", "gvins-spp")
    tmp = tempfile.mkdtemp()
    grid = list(LENGTHS_KM)
    shares = {}  # (site, pair) -> [3x3 per recording]
    for name, inputs, truth, _, _ in sc.cases(build, tmp):
        if name not in SITES:
            continue
        for pair in grid + [None, "independent", "off"]:  # defaults, correlated-error model off, a-priori
            cfg = os.path.join(tmp, "c.yaml")
            with open(cfg, "w") as f:
                f.write("spp:\n")
                if pair == "off":
                    f.write("  reported_error: {enabled: false}\n  covariance_scaling: {enabled: false}\n")
                elif pair == "independent":
                    f.write("  reported_error: {enabled: false}\n")
                elif pair:
                    f.write("  reported_error: {enabled: true, ionosphere_correlation_km: %g}\n" % pair)
            out = os.path.join(tmp, "o.pos")
            subprocess.run([spp, "-q", "--config", cfg, "-o", out] + inputs, check=True, stderr=subprocess.DEVNULL)
            shares.setdefault((SITES[name], pair), []).append(sc.score(sc.read_pos(out), truth)[1])
        print(name, file=sys.stderr)
    sites = sorted(set(SITES.values()))
    site_pct = {k: pooled(v) for k, v in shares.items()}

    def best(on):
        return min(grid, key=lambda p: loss(pooled([site_pct[(s, p)] for s in on])))

    lines = ["| held-out site | correlation length chosen on the other sites (km) | held-out E 1/2/3 σ (%) "
             "| N 1/2/3 σ (%) | U 1/2/3 σ (%) |", "|---|---|---|---|---|"]
    held = []
    for s in sites:
        p = best([o for o in sites if o != s])
        held.append(site_pct[(s, p)])
        lines.append("| %s | %g | %s |" % (s, p, fmt(site_pct[(s, p)])))
    cv = pooled(held)
    lines.append("| pooled held-out (cross-validated) | | %s |" % fmt(cv))
    allp = best(sites)
    for label, p in (("pooled, length chosen on all sites (%g km)" % allp, allp),
                     ("pooled, defaults", None),
                     ("pooled, correlated-error model off (independent errors, variance factor)", "independent"),
                     ("pooled, a-priori covariance", "off")):
        lines.append("| %s | | %s |" % (label, fmt(pooled([site_pct[(s, p)] for s in sites]))))
    print("\n".join(lines if markdown else lines[2:]))
    if "--write" in sys.argv:
        import datetime
        commit = sc.commit_of_tree()  # before the file is opened (and so modified)
        with open(os.path.join(sc.ROOT, "docs", "results", "spp_sigma_fit.md"), "w") as f:
            f.write("# SPP correlated-error model: correlation length, leave-one-site-out\n\n")
            f.write("Written by `bench/spp/sigma_fit.py BUILD_DIR --write` at commit %s, %s. Shares of the "
                    "epochs within 1/2/3 reported sigma, pooled per site; what it says: docs/spp.md, "
                    "\"Standard deviation\".\n\n" % (commit, datetime.date.today().isoformat()))
            f.write("\n".join(lines) + "\n")
    print("cross-validated loss %.1f; fitted on all sites %s, loss %.1f" % (
        loss(cv), allp, loss(pooled([site_pct[(s, allp)] for s in sites]))), file=sys.stderr)


if __name__ == "__main__":
    main()
