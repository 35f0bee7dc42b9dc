"""The reference track of the real u-blox + MEMS IMU walk and the error geometry shared by
bench/fusion/real_walk.py and bench/fusion/real_walk_vision.py.

The reference is the receiver's own real-time RTK solution (UBX-NAV-PVT of
tests/data/ubx/gnss_1730.ubx: 349 fixed, 187 float epochs), written as a .pos file with
ellipsoidal heights by `gvins-ubx to-pos`. The publisher's `gnss_1730_sf.pos` holds the same
solutions with NAV-PVT's mean-sea-level heights (21.39 m higher here), so it is not used for
heights. The base station the receiver's RTK used is not published.
"""
import math
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "data")
UBX = os.path.join(DATA, "ubx", "gnss_1730.ubx")
WALK = os.path.join(DATA, "gnss_imu", "walk_0827")
A = 6378137.0
F = 1.0 / 298.257223563
REFERENCE_TEXT = ("the receiver's own real-time RTK solution (UBX-NAV-PVT of `gnss_1730.ubx`, ellipsoidal heights, "
                  "written by `gvins-ubx to-pos`)")


def make_reference(bin_dir, out_dir, run):
    """Writes OUT_DIR/walk_reference.pos with `gvins-ubx to-pos` (through `run`, which takes the
    command list) and returns its path."""
    path = os.path.join(out_dir, "walk_reference.pos")
    run([os.path.join(bin_dir, "gvins-ubx"), "to-pos", UBX, "-o", path])
    return path


def llh_to_ecef(lat, lon, h):
    e2 = F * (2 - F)
    la, lo = math.radians(lat), math.radians(lon)
    n = A / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo), (n * (1 - e2) + h) * math.sin(la))


def enu(d, lat, lon):
    la, lo = math.radians(lat), math.radians(lon)
    e = -math.sin(lo) * d[0] + math.cos(lo) * d[1]
    n = -math.sin(la) * math.cos(lo) * d[0] - math.sin(la) * math.sin(lo) * d[1] + math.cos(la) * d[2]
    u = math.cos(la) * math.cos(lo) * d[0] + math.cos(la) * math.sin(lo) * d[1] + math.sin(la) * d[2]
    return e, n, u


def error_enu(e, r):
    """East, north, up error of the solution row `e` against the reference row `r` (read_pos values)."""
    a, b = llh_to_ecef(*e[:3]), llh_to_ecef(*r[:3])
    return enu([a[i] - b[i] for i in range(3)], r[0], r[1])


def read_pos(path):
    """{(date, seconds of day rounded to 0.05 s): (lat, lon, h, Q, (ve, vn, vu) or None, ns)} of a
    .pos file in lat/lon/h (GPST)."""
    out = {}
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        t = line.split()
        key = round((int(t[1][0:2]) * 3600 + int(t[1][3:5]) * 60 + float(t[1][6:])) * 20) / 20.0
        vel = None
        if len(t) >= 18:  # date time lat lon h Q ns 6 sigmas age ratio vn ve vu ...
            try:
                vel = (float(t[16]), float(t[15]), float(t[17]))  # ve, vn, vu
            except ValueError:
                vel = None
        out[(t[0], key)] = (float(t[2]), float(t[3]), float(t[4]), int(float(t[5])), vel, int(float(t[6])))
    return out


def matched_errors(est, ref, max_q=1):
    """[(key, (E, N, U) error, squared velocity error or None)] of the solution rows `est` at the
    reference epochs of quality <= max_q (read_pos dictionaries)."""
    out = []
    for k, r in ref.items():
        if r[3] > max_q or k not in est:
            continue
        e = est[k]
        dv = None
        if e[4] and r[4] and all(not math.isnan(x) for x in e[4]):
            dv = sum((e[4][i] - r[4][i]) ** 2 for i in range(3))
        out.append((k, error_enu(e, r), dv))
    return out
