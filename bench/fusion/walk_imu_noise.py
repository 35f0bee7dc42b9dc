#!/usr/bin/env python3
"""White-noise densities of the real walk's MEMS IMU (tests/data/gnss_imu/walk_0827/imu_1730.csv)
from the recording itself, for its imu0_sensor.yaml.

    bench/fusion/walk_imu_noise.py [IMU.csv]

Two parts, per axis and then as the RMS over the three axes:
- static: the standard deviation of the samples about their mean in the 1 s windows where the
  IMU is at rest (gyro norm varying by less than 0.1 deg/s within the window: the first 2 s and
  the last 15 s of the walk), times √T for the sensor period T: the density of the sensor's own
  noise (continuous-time white noise sampled every T has σ = q/√T).
- timing: the log holds the newest sensor sample on every line, and its lines (about 167 Hz,
  6-9 ms apart) are not the sensor's samples (100 Hz): about a third of the lines repeat the line
  before, and a value is stamped when the logger wrote it, between 0 and T after it was measured.
  A sample integrated as if taken at its stamp is off by the signal's change over that age:
  e = ḟ·δt with δt uniform over one period (σ = T/√12), independent from sample to sample, i.e.
  white noise of density RMS(ḟ)·(T/√12)·√T, ḟ from consecutive distinct samples over the whole
  recording (walk and rest, nothing selected).
The density for the filter is √(static² + timing²). Units: rad/s/√Hz and m/s²/√Hz (the log's g
and deg/s converted with 9.80665 m/s² and π/180).
"""
import math
import os
import sys

G = 9.80665
HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT = os.path.join(HERE, "..", "..", "tests", "data", "gnss_imu", "walk_0827", "imu_1730.csv")


def read(path):
    """[(t s, gx, gy, gz rad/s, ax, ay, az m/s²)] of the log's complete lines (ax,ay,az,gx,gy,gz,t ms)."""
    rows = []
    for line in open(path):
        f = line.strip().split(",")
        if len(f) != 7:
            continue  # the cut-off first line
        a = [float(x) * G for x in f[0:3]]
        g = [math.radians(float(x)) for x in f[3:6]]
        rows.append([float(f[6]) * 1e-3] + g + a)
    return rows


def main():
    rows = read(sys.argv[1] if len(sys.argv) > 1 else DEFAULT)
    distinct = [rows[0]]
    for r in rows[1:]:
        if r[1:] != distinct[-1][1:]:
            distinct.append(r)
    T = (distinct[-1][0] - distinct[0][0]) / (len(distinct) - 1)
    print(f"lines {len(rows)}, distinct samples {len(distinct)}, sensor period T {T * 1e3:.2f} ms")
    # Static windows of 1 s.
    t0, static = distinct[0][0], {k: [] for k in range(1, 7)}
    seconds = int(distinct[-1][0] - t0)
    for s in range(seconds):
        w = [r for r in distinct if s <= r[0] - t0 < s + 1]
        if len(w) < 10:
            continue
        norm = [math.degrees(math.sqrt(r[1] ** 2 + r[2] ** 2 + r[3] ** 2)) for r in w]
        mn = sum(norm) / len(norm)
        if math.sqrt(sum((x - mn) ** 2 for x in norm) / len(norm)) >= 0.1:
            continue
        for k in range(1, 7):
            m = sum(r[k] for r in w) / len(w)
            static[k] += [r[k] - m for r in w]
    n_static = len(static[1])
    rms = lambda xs: math.sqrt(sum(x * x for x in xs) / len(xs))
    print(f"static samples {n_static} ({n_static * T:.1f} s)")
    for name, axes in (("gyroscope", (1, 2, 3)), ("accelerometer", (4, 5, 6))):
        q_static = [rms(static[k]) * math.sqrt(T) for k in axes]
        deriv = [rms([(b[k] - a[k]) / T for a, b in zip(distinct, distinct[1:])]) for k in axes]
        q_timing = [d * T / math.sqrt(12.0) * math.sqrt(T) for d in deriv]
        qs, qt = rms(q_static), rms(q_timing)
        print(f"{name}: static density per axis {', '.join(f'{x:.3g}' for x in q_static)} (RMS {qs:.3g}); "
              f"RMS rate of change per axis {', '.join(f'{x:.3g}' for x in deriv)}; timing density RMS {qt:.3g}; "
              f"total {math.hypot(qs, qt):.3g}")


if __name__ == "__main__":
    main()
