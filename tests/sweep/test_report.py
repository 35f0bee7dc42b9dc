#!/usr/bin/env python3
"""bench/sweep/report.py's float-against-double judgement: the rank-sum p-value against the exact
permutation distribution (enumerated), and the target rows on runs whose gaps are known.

  test_report.py
"""
import itertools
import math
import os
import random
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "bench", "sweep"))
import report  # noqa: E402


def fail(msg):
    sys.exit("test_report.py: " + msg)


def exact_p(a, b):
    """P(U >= U_observed) over all equally likely splits of the pooled values (ties count one half)."""
    def u(x, y):
        return sum((p > q) + 0.5 * (p == q) for p in x for q in y)
    pooled, n1 = a + b, len(a)
    observed, hits, total = u(a, b), 0, 0
    for idx in itertools.combinations(range(len(pooled)), n1):
        chosen = set(idx)
        x = [pooled[i] for i in idx]
        y = [pooled[i] for i in range(len(pooled)) if i not in chosen]
        hits += u(x, y) >= observed - 1e-12
        total += 1
    return hits / total


def run(family, seed, mode, rmse):
    return {"family": family, "seed": seed, "mode": mode, "status": "ok",
            "metrics": {"local_start_aligned_position_rmse_m": rmse, "global_position_rmse_m": rmse}, "variant": {"length_m": 100, "start_gpst": "x"}}


def main():
    rng = random.Random(45)
    worst = 0.0
    for trial in range(12):
        n1, n2 = rng.choice([(6, 6), (8, 8), (5, 9)])
        scale = rng.choice([1.0, 1.5, 3.0])
        a = [round(rng.expovariate(1.0 / scale), 2) for _ in range(n1)]  # rounding makes ties
        b = [round(rng.expovariate(1.0), 2) for _ in range(n2)]
        got, want = report.rank_sum_p(a, b), exact_p(a, b)
        worst = max(worst, abs(got - want))
        if abs(got - want) > 0.02:
            fail("rank_sum_p(%s, %s) = %.4f, exact %.4f" % (a, b, got, want))
    if not math.isnan(report.rank_sum_p([], [1.0])):
        fail("rank_sum_p of an empty sample must be NaN")
    # Target rows: 20 seeds, double RMSE 1 m; the float gaps are the perturbed gaps in another
    # order (the same spread: met), then 4x larger (a float defect: the rank sum must see it).
    spread = [0.005 + 0.001 * k for k in range(20)]
    for factor, met in ((1.0, True), (4.0, False)):
        shuffled = spread[:]
        rng.shuffle(shuffled)
        results = []
        for s in range(1, 21):
            results += [run("f", s, "vio", 1.0), run("f", s, "vio_float", 1.0 + factor * shuffled[s - 1]),
                        run("f", s, "vio_perturbed", 1.0 - spread[s - 1])]
        rows = report.float_rows(results, "f", "vio_float", "vio")
        if len(rows) != 2:
            fail("expected the mean row and the spread row, got %s" % rows)
        mean_row, spread_row = rows
        gaps = [abs(r["metrics"]["local_start_aligned_position_rmse_m"] - 1.0) for r in results if r["mode"] == "vio_float"]
        mean = sum(gaps) / len(gaps)
        if "%.1f %%" % (100 * mean) not in mean_row[2] or mean_row[3] != (mean <= 0.05):
            fail("mean row %s: mean gap %.2f %%" % (mean_row, 100 * mean))
        if spread_row[3] != met:
            fail("factor %g: spread row %s, expected %s" % (factor, spread_row, "met" if met else "missed"))
    # Without a perturbed run: the worst seed against the tolerance.
    rows = report.float_rows([run("f", 1, "ddcp", 0.1), run("f", 1, "ddcp_float", 0.106)], "f", "ddcp_float", "ddcp")
    if len(rows) != 1 or rows[0][3] or "6.0 %" not in rows[0][2]:
        fail("ddcp without a perturbed run: %s" % rows)
    print("report: rank sum within %.4f of the exact p over 12 samples; float rows as expected" % worst)


if __name__ == "__main__":
    main()
