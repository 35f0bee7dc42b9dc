#!/usr/bin/env python3
"""Figures of gvins-replay runs of the real walk for tests/fusion/real_walk_reacquisition.sh and
real_walk_quirks.sh. Times are seconds after the run's first frame (timing.csv), positions those
of global.pos.

    walk_compare.py first-update OUT T        s from T to the first epoch with an applied update
    walk_compare.py max-diff OUT_A OUT_B T0 T1  largest horizontal and vertical distance (m) between
                                              the two runs' common epochs in [T0, T1)
    walk_compare.py max-used OUT T0 T1        largest number of pseudorange rows used in [T0, T1)
    walk_compare.py frame-delay OUT SPP.pos   s from the first SPP fix to the first tight epoch
    walk_compare.py start-diff OUT OUT_B LEN  largest horizontal and vertical distance (m) between
                                              the two runs' common epochs over the LEN s after OUT's
                                              first tight epoch ("nan nan" without one)
    walk_compare.py restart OUT               s after the first frame of the first frame restart (the
                                              first epoch reset back to waiting-vio) and s from it to
                                              the next tight epoch ("nan nan" without a restart, "T nan"
                                              without a start after it)
    walk_compare.py drift OUT REF.pos T LEN   horizontal drift (m) of an outage [T, T+LEN): the change
                                              of the horizontal error against the reference's fixed
                                              and float epochs between the last epoch before the
                                              window and the window's last epoch
    walk_compare.py rms OUT REF.pos T0 [OUT_B]  horizontal and vertical RMS (m) against the
                                              reference's fixed and float epochs from T0 on (the
                                              epochs that OUT_B also has, if given)

    walk_compare.py consistency OUT REF.pos   consistency of global.pos's reported covariances
                                              (consistency() below): "nees share95 heading_ratio
                                              heading_share2 heading_rms_deg heading_sigma_deg
                                              pos_nees epochs moving positions"
    walk_compare.py outage-sigma OUT REF.pos T LEN  horizontal drift of the outage [T, T+LEN) as
                                              `drift`, the horizontal σ the run reported at the
                                              window's last epoch (√(σE² + σN²)) and their ratio:
                                              "drift sigma ratio"

REF.pos: the walk's reference track with ellipsoidal heights (gvins-ubx to-pos of the log's
NAV-PVT, $REF of real_walk_common.sh).
"""
import math
import sys

WEEK = 604800.0
A = 6378137.0
F = 1.0 / 298.257223563


def first_frame(out):
    with open(out + "/timing.csv") as f:
        return next(int(l.split(",")[0]) * 1e-9 % WEEK for l in f if not l.startswith("#"))


def sow(date, clock):
    import datetime
    y, m, d = (int(x) for x in date.split("/"))
    days = (datetime.date(y, m, d) - datetime.date(1980, 1, 6)).days
    h, mi, s = clock.split(":")
    return round(((days % 7) * 86400 + int(h) * 3600 + int(mi) * 60 + float(s)) * 20) / 20.0


def read_pos(path, max_q=9, dh=0.0):
    out = {}
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        t = line.split()
        if int(float(t[5])) <= max_q:
            out[sow(t[0], t[1])] = (float(t[2]), float(t[3]), float(t[4]) + dh)
    return out


def signed_square(x):
    """The covariance entry of a .pos off-diagonal column (RTKLIB writes sign(c)·√|c|)."""
    return x * abs(x)


def read_solutions(path, max_q=9):
    """{GPST s of week: (lat, lon, h, Q, P, v, V)} of a .pos file with velocity columns, P and V
    the position and velocity covariances in east, north, up (3×3 lists; the file's order is
    north, east, up), v the velocity (east, north, up) or None where the file has nan."""
    out = {}
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        t = line.split()
        q = int(float(t[5]))
        if q > max_q or len(t) < 24:
            continue
        c = [float(x) for x in t[7:13]] + [float(x) for x in t[18:24]]
        neu = lambda d, o: [[d[0] ** 2, signed_square(o[0]), signed_square(o[2])],
                            [signed_square(o[0]), d[1] ** 2, signed_square(o[1])],
                            [signed_square(o[2]), signed_square(o[1]), d[2] ** 2]]
        perm = [1, 0, 2]  # east, north, up from north, east, up
        to_enu = lambda m: [[m[perm[i]][perm[j]] for j in range(3)] for i in range(3)]
        v = [float(t[16]), float(t[15]), float(t[17])]
        out[sow(t[0], t[1])] = (float(t[2]), float(t[3]), float(t[4]), q, to_enu(neu(c[0:3], c[3:6])),
                                None if any(math.isnan(x) for x in v) else v, to_enu(neu(c[6:9], c[9:12])))
    return out


def quadratic_inverse(e, m):
    """eᵀ M⁻¹ e of a 2- or 3-vector e and a symmetric positive definite M (nan if M is singular)."""
    if len(e) == 2:
        det = m[0][0] * m[1][1] - m[0][1] * m[1][0]
        if det <= 0:
            return float("nan")
        return (m[1][1] * e[0] ** 2 - 2 * m[0][1] * e[0] * e[1] + m[0][0] * e[1] ** 2) / det
    cof = [[m[(i + 1) % 3][(j + 1) % 3] * m[(i + 2) % 3][(j + 2) % 3] - m[(i + 1) % 3][(j + 2) % 3] * m[(i + 2) % 3][(j + 1) % 3]
            for j in range(3)] for i in range(3)]
    det = sum(m[0][j] * cof[0][j] for j in range(3))
    if det <= 0:
        return float("nan")
    return sum(e[i] * cof[j][i] * e[j] for i in range(3) for j in range(3)) / det


CHI2_95 = {2: 5.991, 3: 7.815}  # 95 % quantiles of χ² with 2 and 3 degrees of freedom
MOVING_MPS = 0.8                # horizontal reference speed above which the velocity heading is compared
STEP = 0.25                     # s between the log's epochs (4 Hz)


def heading_and_sigma(v, m):
    """Velocity heading atan2(vE, vN) (rad) and its σ from the velocity covariance m (east,
    north, up) through the gradient (vN, −vE)/(vE² + vN²)."""
    s2 = v[0] ** 2 + v[1] ** 2
    g = [v[1] / s2, -v[0] / s2]
    return math.atan2(v[0], v[1]), math.sqrt(g[0] ** 2 * m[0][0] + 2 * g[0] * g[1] * m[0][1] + g[1] ** 2 * m[1][1])


def consistency(out, ref_path, moving=MOVING_MPS):
    """The run's reported antenna covariances (global.pos) against the reference's fixed epochs.
    Velocity: the reference is the difference of the fixed positions at t ± 0.25 s over 0.5 s
    (the mean velocity over that interval; the receiver's NAV-PVT velocity lags its own positions
    by about 0.14 s, 0.1 m/s RMS per axis on this walk, so it is no reference at 0.05 m/s), the
    run's the trapezoidal mean of its velocities at t − 0.25, t, t + 0.25 s with the covariance
    reported at t (the reference's noise, millimetres per epoch, is neglected: the figures are
    upper bounds). Returns {"nees": mean 3-D velocity NEES (3 if consistent), "share95": share of
    epochs within χ²₃'s 95 % bound (0.95), "heading_ratio": mean |ψ error| / σψ of the velocity
    heading ψ = atan2(vE, vN) where the reference moves faster than `moving` m/s horizontally
    (√(2/π) ≈ 0.80 if consistent), "heading_share2": share with |error| <= 2 σψ (0.95),
    "heading_rms_deg", "heading_sigma_deg" (RMS of σψ), "pos_nees": mean 2-D NEES of the
    horizontal position error about its mean over the run (the reference's unknown constant
    offset removed; 2 if consistent), "epochs" (velocity), "moving", "positions"}; None without
    common epochs."""
    est, ref = read_solutions(out + "/global.pos"), read_solutions(ref_path, 1)
    nees, ratio, share2, dpsi, spsi = [], [], [], [], []
    for t in sorted(ref):
        a, c = t - STEP, t + STEP
        if a not in ref or c not in ref or any(u not in est or est[u][5] is None for u in (a, t, c)):
            continue
        m = est[t][6]
        if m[0][0] <= 0:
            continue
        vr = [x / (c - a) for x in enu(ref[c][:3], ref[a][:3])]
        ve = [0.25 * est[a][5][i] + 0.5 * est[t][5][i] + 0.25 * est[c][5][i] for i in range(3)]
        nees.append(quadratic_inverse([ve[i] - vr[i] for i in range(3)], m))
        if math.hypot(vr[0], vr[1]) > moving:
            psi, sigma = heading_and_sigma(ve, m)
            err = math.remainder(psi - math.atan2(vr[0], vr[1]), 2 * math.pi)
            ratio.append(abs(err) / sigma)
            share2.append(abs(err) <= 2 * sigma)
            dpsi.append(err)
            spsi.append(sigma)
    pos = [(enu(est[t][:3], ref[t][:3]), est[t][4]) for t in sorted(ref) if t in est and est[t][4][0][0] > 0]
    if not nees or not pos:
        return None
    mean = lambda x: sum(x) / len(x) if x else float("nan")
    rms = lambda x: math.degrees(math.sqrt(mean([y * y for y in x]))) if x else float("nan")
    off = [mean([e[i] for e, _ in pos]) for i in range(2)]
    pn = [quadratic_inverse([e[0] - off[0], e[1] - off[1]], [p[0][:2], p[1][:2]]) for e, p in pos]
    return {"nees": mean(nees), "share95": mean([x <= CHI2_95[3] for x in nees]), "heading_ratio": mean(ratio),
            "heading_share2": mean(share2), "heading_rms_deg": rms(dpsi), "heading_sigma_deg": rms(spsi),
            "pos_nees": mean(pn), "epochs": len(nees), "moving": len(ratio), "positions": len(pn)}


def outage_sigma(out, ref_path, start, length):
    """(horizontal drift, reported horizontal σ at the window's last epoch, drift / σ) of the
    outage [start, start + length): the drift as `drift` (the change of the horizontal error
    against the reference's fixed and float epochs between the last epoch before the window and
    the window's last epoch), σ = √(σE² + σN²) of global.pos at that last epoch."""
    t0 = first_frame(out)
    est, ref = read_solutions(out + "/global.pos"), read_pos(ref_path, 2)
    common = sorted(t for t in est if t in ref)
    before = [t for t in common if t - t0 < start]
    inside = [t for t in common if start <= t - t0 < start + length]
    if not before or not inside:
        sys.exit("walk_compare: no reference epoch before or inside the window")
    e0, e1 = enu(est[before[-1]][:3], ref[before[-1]]), enu(est[inside[-1]][:3], ref[inside[-1]])
    drift = math.hypot(e1[0] - e0[0], e1[1] - e0[1])
    p = est[inside[-1]][4]
    sigma = math.sqrt(p[0][0] + p[1][1])
    return drift, sigma, drift / sigma if sigma > 0 else float("inf")


def ecef(p):
    e2 = F * (2 - F)
    la, lo = math.radians(p[0]), math.radians(p[1])
    n = A / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + p[2]) * math.cos(la) * math.cos(lo), (n + p[2]) * math.cos(la) * math.sin(lo),
            (n * (1 - e2) + p[2]) * math.sin(la))


def enu(a, b):
    """ENU of a - b at b."""
    x, y = ecef(a), ecef(b)
    d = [x[i] - y[i] for i in range(3)]
    la, lo = math.radians(b[0]), math.radians(b[1])
    e = -math.sin(lo) * d[0] + math.cos(lo) * d[1]
    n = -math.sin(la) * math.cos(lo) * d[0] - math.sin(la) * math.sin(lo) * d[1] + math.cos(la) * d[2]
    u = math.cos(la) * math.cos(lo) * d[0] + math.cos(la) * math.sin(lo) * d[1] + math.sin(la) * d[2]
    return e, n, u


def epochs(out):
    for line in open(out + "/gnss_epochs.csv"):
        if not line.startswith("#"):
            yield line.split(",")


def main():
    cmd, args = sys.argv[1], sys.argv[2:]
    if cmd == "first-update":
        t0 = first_frame(args[0]) + float(args[1])
        first = next(float(e[1]) for e in epochs(args[0]) if float(e[1]) >= t0 and e[13] == "1")
        print("%.2f" % (first - t0))
    elif cmd == "max-diff":
        t0 = first_frame(args[0])
        a, b = read_pos(args[0] + "/global.pos"), read_pos(args[1] + "/global.pos")
        common = [t for t in a if t in b and float(args[2]) <= t - t0 < float(args[3])]
        if not common:
            sys.exit("walk_compare: no common epoch")
        d = [enu(a[t], b[t]) for t in common]
        print("%.2f %.2f" % (max(math.hypot(x[0], x[1]) for x in d), max(abs(x[2]) for x in d)))
    elif cmd == "max-used":
        t0 = first_frame(args[0])
        print(max(int(e[3]) for e in epochs(args[0]) if float(args[1]) <= float(e[1]) - t0 < float(args[2])))
    elif cmd == "frame-delay":
        spp = min(read_pos(args[1]))
        tight = next(float(e[1]) for e in epochs(args[0]) if e[2] == "tight")
        print("%.2f" % (tight - spp))
    elif cmd == "start-diff":
        tight = next((float(e[1]) for e in epochs(args[0]) if e[2] == "tight"), None)
        if tight is None:
            print("nan nan")
            return
        a, b = read_pos(args[0] + "/global.pos"), read_pos(args[1] + "/global.pos")
        common = [t for t in a if t in b and tight <= t < tight + float(args[2])]
        if not common:
            sys.exit("walk_compare: no common epoch")
        d = [enu(a[t], b[t]) for t in common]
        print("%.2f %.2f" % (max(math.hypot(x[0], x[1]) for x in d), max(abs(x[2]) for x in d)))
    elif cmd == "restart":
        t0, ep = first_frame(args[0]), list(epochs(args[0]))
        k = next((i for i, e in enumerate(ep) if e[15] == "1" and e[2] == "waiting-vio"), None)
        if k is None:
            print("nan nan")
            return
        tr = float(ep[k][1])
        ts = next((float(e[1]) for e in ep[k:] if e[2] == "tight"), None)
        print("%.2f %s" % (tr - t0, "nan" if ts is None else "%.2f" % (ts - tr)))
    elif cmd == "drift":
        t0, start, length = first_frame(args[0]), float(args[2]), float(args[3])
        est, ref = read_pos(args[0] + "/global.pos"), read_pos(args[1], 2)
        common = sorted(t for t in est if t in ref)
        before = [t for t in common if t - t0 < start]
        inside = [t for t in common if start <= t - t0 < start + length]
        if not before or not inside:
            sys.exit("walk_compare: no reference epoch before or inside the window")
        e0, e1 = enu(est[before[-1]], ref[before[-1]]), enu(est[inside[-1]], ref[inside[-1]])
        print("%.2f" % math.hypot(e1[0] - e0[0], e1[1] - e0[1]))
    elif cmd == "rms":
        t0 = first_frame(args[0])
        est, ref = read_pos(args[0] + "/global.pos"), read_pos(args[1], 2)
        other = read_pos(args[3] + "/global.pos") if len(args) > 3 else est
        common = [t for t in est if t in ref and t in other and t - t0 >= float(args[2])]
        if not common:
            sys.exit("walk_compare: no common epoch")
        d = [enu(est[t], ref[t]) for t in common]
        print("%.2f %.2f" % (math.sqrt(sum(x[0] ** 2 + x[1] ** 2 for x in d) / len(d)),
                             math.sqrt(sum(x[2] ** 2 for x in d) / len(d))))
    elif cmd == "consistency":
        c = consistency(args[0], args[1])
        if c is None:
            sys.exit("walk_compare: no common epoch with velocities")
        print("%.3f %.3f %.3f %.3f %.2f %.2f %.3f %d %d %d" % tuple(c[k] for k in (
            "nees", "share95", "heading_ratio", "heading_share2", "heading_rms_deg", "heading_sigma_deg", "pos_nees",
            "epochs", "moving", "positions")))
    elif cmd == "outage-sigma":
        print("%.2f %.2f %.2f" % outage_sigma(args[0], args[1], float(args[2]), float(args[3])))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
