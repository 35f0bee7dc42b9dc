#!/usr/bin/env python3
"""The real u-blox + MEMS IMU walk (../shared/data/gnss_imu/rtklibexplorer_walk_0827, a copy in
tests/data) through the camera-less fusion (gvins-replay on an IMU + GNSS dataset), beside our SPP
and RTKLIB's SPP on the same receiver, all against the publisher's RTK track (its fixed epochs).

    bench/fusion/real_walk.py [--build DIR] [-o OUT] [--markdown FILE]

Builds OUT/dataset (mav0/imu0 from the raw IMU log and its time tags with gvins-imu, the UBX log as
the rover), runs gvins-replay in the GNSS modes that need no base (vio+dopp, vio+dopp+psr with
ionosphere-free pairs and with the broadcast ionosphere), gvins-spp on the UBX log, and RTKLIB
(convbin + rnx2rtkp -p 0, when installed) on the same log, and prints one table: epochs compared,
horizontal and vertical RMS and 95 % of the horizontal error, velocity RMS. Progress on stderr.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "data")
UBX = os.path.join(DATA, "ubx", "gnss_1730.ubx")
WALK = os.path.join(DATA, "gnss_imu", "walk_0827")
REF = os.path.join(WALK, "gnss_1730_sf.pos")
A = 6378137.0
F = 1.0 / 298.257223563


def note(msg):
    print("[real_walk] " + msg, file=sys.stderr, flush=True)


def run(cmd, **kw):
    note(" ".join(cmd))
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


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


def read_pos(path):
    """{time key: (lat, lon, h, Q, vel_enu or None)} of a .pos file in lat/lon/h (GPST)."""
    out = {}
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        t = line.split()
        key = round((int(t[1][0:2]) * 3600 + int(t[1][3:5]) * 60 + float(t[1][6:])) * 20) / 20.0
        q = int(float(t[5]))
        vel = None
        if len(t) >= 18:  # date time lat lon h Q ns 6 sigmas age ratio vn ve vu ...
            try:
                vel = (float(t[16]), float(t[15]), float(t[17]))  # ve, vn, vu
            except ValueError:
                vel = None
        out[(t[0], key)] = (float(t[2]), float(t[3]), float(t[4]), q, vel)
    return out


def compare(path, ref):
    est = read_pos(path)
    hs, vs, dv = [], [], []
    for k, r in ref.items():
        if r[3] != 1 or k not in est:
            continue
        e = est[k]
        a, b = llh_to_ecef(*e[:3]), llh_to_ecef(*r[:3])
        de, dn, du = enu([a[i] - b[i] for i in range(3)], r[0], r[1])
        hs.append(de * de + dn * dn)
        vs.append(du * du)
        if e[4] and r[4] and all(not math.isnan(x) for x in e[4]):
            dv.append(sum((e[4][i] - r[4][i]) ** 2 for i in range(3)))
    if not hs:
        return None
    h95 = sorted(math.sqrt(x) for x in hs)[int(0.95 * (len(hs) - 1))]
    rms = lambda xs: math.sqrt(sum(xs) / len(xs)) if xs else float("nan")
    return len(hs), rms(hs), rms(vs), h95, rms(dv)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("-o", dest="out", default=os.path.join(ROOT, "out", "real_walk"))
    ap.add_argument("--markdown")
    a = ap.parse_args()
    b = os.path.join(os.path.abspath(a.build), "bin")
    out = os.path.abspath(a.out)
    ds = os.path.join(out, "dataset")
    shutil.rmtree(ds, ignore_errors=True)
    os.makedirs(os.path.join(ds, "mav0", "imu0"))
    run([os.path.join(b, "gvins-imu"), "convert", os.path.join(WALK, "imu_1730.csv"), "--tag",
         os.path.join(WALK, "imu_1730.csv.tag"), "--columns", "ax,ay,az,gx,gy,gz,t", "--time", "counter-ms",
         "--accel-unit", "g", "--gyro-unit", "deg/s", "-o", os.path.join(ds, "mav0", "imu0", "data.csv")])
    shutil.copy(os.path.join(WALK, "imu0_sensor.yaml"), os.path.join(ds, "mav0", "imu0", "sensor.yaml"))
    rows = []
    ref = read_pos(REF)
    single = os.path.join(out, "single_frequency.yaml")
    with open(single, "w") as f:
        f.write("gnss_fusion:\n  ionosphere: broadcast\n")
    for label, mode, extra in [("fused vio+dopp (camera-less)", "vio+dopp", []),
                               ("fused vio+dopp+psr, ionosphere-free", "vio+dopp+psr", []),
                               ("fused vio+dopp+psr, broadcast ionosphere", "vio+dopp+psr", ["--config", single])]:
        o = os.path.join(out, mode + ("_sf" if extra else ""))
        run([os.path.join(b, "gvins-replay"), ds, "--mode", mode, "--rover", UBX, "--no-eval", "-q", "--imu-gaps", "warn",
             "-o", o] + extra)
        rows.append((label, compare(os.path.join(o, "global.pos"), ref)))
    spp = os.path.join(out, "spp.pos")
    run([os.path.join(b, "gvins-spp"), UBX, "-o", spp])
    rows.append(("gvins-spp (own SFRBX ephemerides)", compare(spp, ref)))
    if shutil.which("convbin") and shutil.which("rnx2rtkp"):
        conv = os.path.join(out, "convbin")
        os.makedirs(conv, exist_ok=True)
        obs, nav = os.path.join(conv, "walk.obs"), os.path.join(conv, "walk.nav")
        run(["convbin", "-r", "ubx", "-v", "3.04", "-od", "-os", "-o", obs, "-n", nav, UBX])
        rpos = os.path.join(out, "rtklib_spp.pos")
        run(["rnx2rtkp", "-p", "0", "-t", "-sys", "G,R,E,J,C", "-o", rpos, obs, nav])
        rows.append(("RTKLIB SPP (convbin + rnx2rtkp -p 0)", compare(rpos, ref)))
    table = ["| solution | epochs (ref. fixed) | H RMS [m] | V RMS [m] | H 95 % [m] | vel. RMS [m/s] |",
             "|---|---|---|---|---|---|"]
    for label, r in rows:
        if r is None:
            table.append(f"| {label} | 0 | | | | |")
        else:
            table.append(f"| {label} | {r[0]} | {r[1]:.2f} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.3f} |")
    text = "\n".join(table) + "\n"
    print(text)
    if a.markdown:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        with open(a.markdown, "w") as f:
            f.write("# The real u-blox + MEMS IMU walk, camera-less\n\n")
            f.write(f"Written by `bench/fusion/real_walk.py --markdown {a.markdown}` at commit {commit}. Do not edit by hand.\n")
            f.write("Reference: the publisher's RTKLIB RTK track, its fixed epochs (`gnss_1730_sf.pos`, Q = 1).\n\n")
            f.write(text)


if __name__ == "__main__":
    main()
