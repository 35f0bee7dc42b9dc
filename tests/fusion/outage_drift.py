#!/usr/bin/env python3
"""Horizontal drift of a gvins-replay GNSS outage: the change of the antenna's horizontal error
against a reference .pos (epochs of quality <= 2) between the last epoch before the window and
the window's last epoch. Prints the drift in metres.

    outage_drift.py OUT_DIR REFERENCE.pos START LENGTH   (seconds after the first frame)
"""
import math
import sys

WEEK = 604800.0


def tow(date, clock):
    y, m, d = (int(x) for x in date.split("/"))
    import datetime
    days = (datetime.date(y, m, d) - datetime.date(1980, 1, 6)).days
    h, mi, s = clock.split(":")
    return round(((days % 7) * 86400 + int(h) * 3600 + int(mi) * 60 + float(s)) * 20) / 20.0


def read(path, max_q):
    out = {}
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        t = line.split()
        if int(float(t[5])) <= max_q:
            out[tow(t[0], t[1])] = (math.radians(float(t[2])), math.radians(float(t[3])))
    return out


def main():
    out_dir, ref_path, start, length = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
    with open(out_dir + "/timing.csv") as f:
        t0 = next(int(l.split(",")[0]) * 1e-9 % WEEK for l in f if not l.startswith("#"))
    est, ref = read(out_dir + "/global.pos", 9), read(ref_path, 2)
    common = sorted(t for t in est if t in ref)
    before = [t for t in common if t - t0 < start]
    inside = [t for t in common if start <= t - t0 < start + length]
    if not before or not inside:
        sys.exit("outage_drift: no reference epoch before or inside the window")
    r = 6378137.0

    def err(t):  # horizontal error (north, east), m, small-angle
        (la, lo), (rla, rlo) = est[t], ref[t]
        return (la - rla) * r, (lo - rlo) * r * math.cos(rla)

    e0, e1 = err(before[-1]), err(inside[-1])
    print("%.2f" % math.hypot(e1[0] - e0[0], e1[1] - e0[1]))


if __name__ == "__main__":
    main()
