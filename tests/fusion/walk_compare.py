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
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
