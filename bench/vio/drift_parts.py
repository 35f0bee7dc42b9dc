#!/usr/bin/env python3
"""Parts of the VIO drift of simulated runs: the drift figure of gvins-replay (local_drift_percent:
mean over all 100 m segments of |dRr^T (R_i^T dp_est - R_ref,i^T dp_ref)| / 100 m, the translation
part of the relative pose error expressed in the body frame at the segment start,
vio/src/trajectory_metrics.cpp) recomputed from trajectory.tum and the dataset's truth, and split
into
  length     | |dp_est| - |dp_ref| |: how much the segment is too long or short (scale, speed);
  world      |dp_est - dp_ref| in the world frame after the best yaw and translation (4-DoF) fit
             of the whole run: the position drift without the attitude error at the segment start;
  tilt       mean angle between the estimated and true gravity directions in the body frame (deg):
             its share of the drift is about tilt x 100 m when it does not cancel with the
             trajectory's own tilt.

  bench/vio/drift_parts.py DATASET REPLAY_OUT [DATASET REPLAY_OUT ...]

DATASET is a gvins-sim dataset (mav0/state_groundtruth_estimate0/data.csv), REPLAY_OUT the -o folder
of `gvins-replay DATASET --mode vio` (trajectory.tum, metrics.csv). The recomputed drift is checked
against metrics.csv (a warning when they differ by more than 1 %). Standard library only.
"""
import bisect
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gnss_start_seeds import quat  # noqa: E402  (unit quaternion w, x, y, z -> rotation matrix)

SEGMENT_M = 100.0  # the longest segment of vio::EvaluationOptions::segmentLengths


def rt_times(r, v):
    """R^T v."""
    return [sum(r[k][i] * v[k] for k in range(3)) for i in range(3)]


def rows(path):
    out = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if line.startswith("#") or not line.strip():
                continue
            try:
                out.append([float(x) for x in line.replace(",", " ").split()])
            except ValueError:
                sys.exit("%s:%d: not a row of numbers" % (path, n))
    return out


def matched(dataset, run):
    """(p_est, R_est, p_ref, R_ref) at the estimate's stamps that the truth has (within 1 ms)."""
    truth = rows(os.path.join(dataset, "mav0", "state_groundtruth_estimate0", "data.csv"))
    est = rows(os.path.join(run, "trajectory.tum"))  # t x y z qx qy qz qw
    t_ref = [r[0] * 1e-9 for r in truth]
    out = []
    for e in est:
        i = bisect.bisect_left(t_ref, e[0] - 1e-6)
        if i < len(t_ref) and abs(t_ref[i] - e[0]) < 1e-3:
            g = truth[i]
            out.append((e[1:4], quat(e[7], e[4], e[5], e[6]), g[1:4], quat(*g[4:8])))
    if len(out) < 2:
        sys.exit("%s: fewer than 2 poses matched to the truth of %s" % (run, dataset))
    return out


def yaw_fit(poses):
    """Estimate positions after the best 4-DoF (yaw about z, translation) fit to the truth."""
    n = len(poses)
    ce = [sum(p[0][k] for p in poses) / n for k in range(3)]
    cr = [sum(p[2][k] for p in poses) / n for k in range(3)]
    ze = [complex(p[0][0] - ce[0], p[0][1] - ce[1]) for p in poses]
    zr = [complex(p[2][0] - cr[0], p[2][1] - cr[1]) for p in poses]
    c = sum(a.conjugate() * b for a, b in zip(ze, zr))
    c = c / abs(c) if abs(c) > 0 else 1.0
    return [((c * z).real, (c * z).imag, p[0][2] - ce[2]) for z, p in zip(ze, poses)]


def parts(poses):
    dist = [0.0]
    for a, b in zip(poses, poses[1:]):
        dist.append(dist[-1] + math.dist(a[2], b[2]))
    world = yaw_fit(poses)
    total = length = wpart = tilt = 0.0
    count, j = 0, 0
    for i, (pe_i, re_i, pr_i, rr_i) in enumerate(poses):
        j = max(j, i + 1)
        while j < len(poses) and dist[j] - dist[i] < SEGMENT_M:
            j += 1
        if j >= len(poses):
            break
        de = rt_times(re_i, [a - b for a, b in zip(poses[j][0], pe_i)])
        dr = rt_times(rr_i, [a - b for a, b in zip(poses[j][2], pr_i)])
        total += math.dist(de, dr)
        length += abs(math.hypot(*de) - math.hypot(*dr))
        wpart += math.dist([a - b for a, b in zip(world[j], world[i])], [a - b for a, b in zip(poses[j][2], pr_i)])
        cos = sum(re_i[2][k] * rr_i[2][k] for k in range(3))  # world z in both body frames
        tilt += math.degrees(math.acos(max(-1.0, min(1.0, cos))))
        count += 1
    if count == 0:
        return None
    s = 100.0 / (count * SEGMENT_M)
    return total * s, length * s, wpart * s, tilt / count


def reported_drift(run):
    path = os.path.join(run, "metrics.csv")
    if not os.path.exists(path):
        return None
    for line in open(path):
        if line.startswith("local_drift_percent,"):
            return float(line.split(",")[1])
    return None


def main():
    args = sys.argv[1:]
    if not args or len(args) % 2:
        sys.exit(__doc__)
    print("| run | drift [%] | length [%] | world, 4-DoF [%] | tilt [deg] |")
    print("|---|---|---|---|---|")
    for dataset, run in zip(args[::2], args[1::2]):
        p = parts(matched(dataset, run))
        if p is None:
            print("| %s | path shorter than %g m | | | |" % (run, SEGMENT_M))
            continue
        rep = reported_drift(run)
        if rep is not None and abs(rep - p[0]) > 0.01 * max(rep, 1e-9):
            sys.stderr.write("drift_parts.py: %s: recomputed drift %.4f %% differs from metrics.csv %.4f %%\n"
                             % (run, p[0], rep))
        print("| %s | %.3f | %.3f | %.3f | %.3f |" % ((run,) + p))


if __name__ == "__main__":
    main()
