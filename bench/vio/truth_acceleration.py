#!/usr/bin/env python3
"""True acceleration of a gvins-sim flight over a replay window (issue 43: what a mono start in
motion can observe). Reads the dataset's ground truth (mav0/state_groundtruth_estimate0, local
ENU velocity) and prints, for 0.1 s means of the acceleration (velocity difference over each
0.1 s), the largest and RMS horizontal and vertical magnitude over the window, the speed range,
and per second the largest magnitudes and the change within that second (largest distance of a
0.1 s mean from the second's mean: the truth counterpart of the initialiser's accelerationChange,
docs/vio_estimator.md "In motion (mono)").

  bench/vio/truth_acceleration.py DATASET START_S DURATION_S

The init sweep's UAV cruise start is START_S = 2 + height / 3 + 3 (bench/vio/init_sweep.py).
"""
import argparse
import math


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("start", type=float, help="s after the first ground-truth sample")
    ap.add_argument("duration", type=float, help="s")
    a = ap.parse_args()
    t, v = [], []
    with open(a.dataset + "/mav0/state_groundtruth_estimate0/data.csv") as f:
        for line in f:
            if line.startswith("#"):
                continue
            r = line.split(",")
            t.append(int(r[0]))
            v.append([float(x) for x in r[8:11]])
    step = (t[1] - t[0]) * 1e-9

    def vel(s):
        i = int(round(s / step))
        if i >= len(v):
            raise SystemExit("%s: the window ends after the ground truth (%.1f s)" % (a.dataset, len(v) * step))
        return v[i]

    nb = int(round(a.duration / 0.1))
    acc = []
    for k in range(nb):
        v0, v1 = vel(a.start + 0.1 * k), vel(a.start + 0.1 * (k + 1))
        acc.append([(v1[i] - v0[i]) / 0.1 for i in range(3)])
    ah = [math.hypot(x[0], x[1]) for x in acc]
    av = [abs(x[2]) for x in acc]
    speed = [math.sqrt(sum(c * c for c in vel(a.start + 0.1 * k))) for k in range(nb)]
    rms = lambda xs: math.sqrt(sum(x * x for x in xs) / len(xs))
    print("%.1f..%.1f s: |a_h| max %.3f rms %.3f m/s², |a_v| max %.3f rms %.3f m/s², speed %.2f..%.2f m/s" % (
        a.start, a.start + a.duration, max(ah), rms(ah), max(av), rms(av), min(speed), max(speed)))
    for s in range(nb // 10):
        k = acc[10 * s:10 * s + 10]
        m = [sum(x[i] for x in k) / len(k) for i in range(3)]
        change = max(math.sqrt(sum((x[i] - m[i]) ** 2 for i in range(3))) for x in k)
        print("  %6.1f..%6.1f s: |a_h| max %.3f, |a_v| max %.3f, change %.3f m/s²" % (
            a.start + s, a.start + s + 1, max(ah[10 * s:10 * s + 10]), max(av[10 * s:10 * s + 10]), change))


if __name__ == "__main__":
    main()
