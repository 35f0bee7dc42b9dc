#!/usr/bin/env python3
"""Which simulated error terms make the error of undifferenced pseudorange positioning.

    psr_error_attribution.py DATASET [--run OUTDIR] [--bands G:152,J:152]
                             [--ephemeris-error G:0.6,R:5,E:0.3,C:1,J:0.6] [--sigma 0.6] [--mask 10]
                             [--from S] [--until S] [--causal [--series CSV]] [--without sisre,...]

DATASET: gvins-sim output simulated with `gnss: error_terms: true` (gnss/truth/rover_errors.csv).
Each error term (broadcast orbit/clock error, troposphere residual, code multipath, code noise),
combined over the ionosphere-free pair as the fusion's psr rows do, is mapped into one constant
ENU offset by weighted least squares over all epochs with a clock per system and epoch: the
error a perfect VIO + psr filter would keep. Weights as the psr rows: (sigma k)^2 (1/2 + 1/(2
sin^2 el)) + ephemeris_error^2, k the IF noise factor (defaults: the fusion's; a given
--ephemeris-error replaces the whole list, systems not named get 0). With --run (a gvins-replay OUTDIR), the
epochs start at the first tight epoch and the filter's mean ENU error is printed alongside;
--from/--until keep only the epochs that many seconds after that start (a window of the flight).
--causal also solves the offset after every epoch from the epochs so far (what a causal filter
with a perfect VIO can know then) and prints its RMS over the epochs, to compare with the
filter's RMSE (--series writes it per epoch); its sums also hold the epochs before the first tight one (a perfect VIO from the
first epoch on). Without --causal, those epochs are left out. --without drops terms from the sums (e.g. sisre for runs with precise products).
NLOS-affected satellites are left out (the filter's gate rejects them). docs/gnss_fusion.md."""
import bisect, collections, math, sys

F = {('G', '1'): 1575.42, ('G', '2'): 1227.60, ('G', '5'): 1176.45, ('J', '1'): 1575.42, ('J', '2'): 1227.60,
     ('J', '5'): 1176.45, ('E', '1'): 1575.42, ('E', '5'): 1176.45, ('E', '7'): 1207.14, ('C', '2'): 1561.098,
     ('C', '7'): 1207.14, ('C', '6'): 1268.52, ('R', '1'): 9.0, ('R', '2'): 7.0}  # GLONASS: ratio 9/7
PRIMARY = {'G': '1', 'J': '1', 'E': '1', 'C': '2', 'R': '1'}
TERMS = ['sisre', 'tropo', 'mp', 'noise']


def opt(args, name, default):
    return args[args.index(name) + 1] if name in args else default


def per_system(text, conv):
    return {k: conv(v) for k, v in (kv.split(':') for kv in text.split(',') if kv)}


def solve3(n, b):
    a = [n[i][:] + [b[i]] for i in range(3)]
    for i in range(3):
        p = max(range(i, 3), key=lambda k: abs(a[k][i]))
        a[i], a[p] = a[p], a[i]
        for k in range(i + 1, 3):
            m = a[k][i] / a[i][i]
            for j in range(i, 4):
                a[k][j] -= m * a[i][j]
    x = [0.0] * 3
    for i in (2, 1, 0):
        x[i] = (a[i][3] - sum(a[i][j] * x[j] for j in range(i + 1, 3))) / a[i][i]
    return x


def filter_error(ds, run, start):
    truth = []
    for line in open(ds + '/gnss/truth/rover_antenna.csv'):
        if line[0] in '#t':
            continue
        v = line.split(',')
        truth.append((int(v[0]) * 1e-9, float(v[2]), float(v[3]), float(v[4])))
    x0 = truth[0][1:]
    lon = math.atan2(x0[1], x0[0])
    lat = math.atan2(x0[2], math.hypot(x0[0], x0[1]) * (1 - 0.00669438))
    sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    ts = [t[0] for t in truth]
    acc, sq, n = [0.0] * 3, 0.0, 0
    for line in open(run + '/global_ecef.csv'):
        if line[0] == '#':
            continue
        v = line.split(',')
        t = int(v[0]) * 604800 + float(v[1])
        if float(v[1]) < start - 1e-6:
            continue
        i = bisect.bisect_left(ts, t - 1e-4)
        if i >= len(ts) or abs(ts[i] - t) > 1e-3:
            continue
        d = [float(v[2 + k]) - truth[i][1 + k] for k in range(3)]
        enu = (-so * d[0] + co * d[1], -sl * co * d[0] - sl * so * d[1] + cl * d[2],
               cl * co * d[0] + cl * so * d[1] + sl * d[2])
        acc = [acc[k] + enu[k] for k in range(3)]
        sq += sum(v * v for v in enu)
        n += 1
    return [a / max(n, 1) for a in acc], math.sqrt(sq / max(n, 1))


def main(args):
    if not args or args[0].startswith('-'):
        print(__doc__)
        return 2
    ds, run = args[0], opt(args, '--run', None)
    mask = math.radians(float(opt(args, '--mask', 10)))
    sigma = float(opt(args, '--sigma', 0.6))
    eph = per_system(opt(args, '--ephemeris-error', 'G:0.6,R:5,E:0.3,C:1,J:0.6'), float)
    order = {'G': '152', 'J': '152', 'E': '157', 'C': '276', 'R': '12'}
    order.update(per_system(opt(args, '--bands', ''), str))
    start = -1.0
    t_from, t_until = float(opt(args, '--from', '0')), float(opt(args, '--until', '1e9'))
    if run:
        for line in open(run + '/gnss_epochs.csv'):
            v = line.split(',')
            if len(v) > 2 and v[2] == 'tight':
                start = float(v[1])
                break
    rows = collections.defaultdict(lambda: collections.defaultdict(dict))
    hdr = None
    for line in open(ds + '/gnss/truth/rover_errors.csv'):
        if line.startswith('#'):
            continue
        if line.startswith('tag_ns'):
            hdr = line.strip().split(',')
            continue
        r = dict(zip(hdr, line.strip().split(',')))
        rows[int(r['tag_ns'])][r['sat']][r['signal']] = r
    causal = '--causal' in args
    dropped = set(opt(args, '--without', '').split(',')) - {''}
    kept = [t for t in TERMS if t not in dropped]
    n = [[0.0] * 3 for _ in range(3)]
    b = {t: [0.0] * 3 for t in TERMS}
    running = [0.0, 0.0, 0]  # sum of |offset|^2, of Up^2, epochs (causal)
    series = open(opt(args, '--series', ''), 'w') if causal and '--series' in args else None
    if series is not None:
        series.write('# tow [s],E [m],N [m],U [m]  (causal offset after each epoch)\n')
    for tag in sorted(rows):
        before = (tag * 1e-9) % 604800 < start - 1e-6
        if before and not causal:
            continue
        if not before and not start + t_from - 1e-6 <= (tag * 1e-9) % 604800 <= start + t_until + 1e-6:
            continue
        by_clock = collections.defaultdict(list)
        for sat, sig in rows[tag].items():
            s = sat[0]
            if s not in PRIMARY:
                continue
            bands = {code[0]: code for code in sig}
            if PRIMARY[s] not in bands:
                continue
            r1 = sig[bands[PRIMARY[s]]]
            el, az = math.radians(float(r1['elevation_deg'])), math.radians(float(r1['azimuth_deg']))
            if el < mask or float(r1['nlos']) > 0:
                continue
            def terms(r):
                g = lambda k: float(r[k])
                return {'sisre': g('orbit_error_los') - g('sat_clock_error'), 'tropo': g('tropo') - g('tropo_model'),
                        'mp': g('mp_code'), 'noise': g('code_noise')}
            e, k = terms(r1), 1.0
            for b2 in order.get(s, ''):
                if b2 != PRIMARY[s] and b2 in bands:
                    f1, f2 = F[(s, PRIMARY[s])], F[(s, b2)]
                    a1 = f1 * f1 / (f1 * f1 - f2 * f2)
                    e2 = terms(sig[bands[b2]])
                    e = {t: a1 * e[t] + (1 - a1) * e2[t] for t in TERMS}
                    k = math.hypot(a1, 1 - a1)
                    break
            se = max(math.sin(el), 0.1)
            w = 1.0 / ((sigma * k) ** 2 * (0.5 + 0.5 / se ** 2) + eph.get(s, 0.0) ** 2)
            h = [-math.cos(el) * math.sin(az), -math.cos(el) * math.cos(az), -math.sin(el)]
            by_clock['G' if s == 'J' else s].append((w, h, e))
        for lst in by_clock.values():  # the clock of each system eliminated: weighted de-meaning
            ws = sum(x[0] for x in lst)
            hb = [sum(x[0] * x[1][i] for x in lst) / ws for i in range(3)]
            eb = {t: sum(x[0] * x[2][t] for x in lst) / ws for t in TERMS}
            for w, h, e in lst:
                d = [h[i] - hb[i] for i in range(3)]
                for i in range(3):
                    for j in range(3):
                        n[i][j] += w * d[i] * d[j]
                    for t in TERMS:
                        b[t][i] += w * d[i] * (e[t] - eb[t])
        if causal and not before and sum(len(v) for v in by_clock.values()) > 0:
            try:
                x = solve3(n, [sum(b[t][i] for t in kept) for i in range(3)])
            except ZeroDivisionError:
                continue
            if series is not None:
                series.write(f'{(tag * 1e-9) % 604800:.3f},{x[0]:.4f},{x[1]:.4f},{x[2]:.4f}\n')
            running[0] += sum(v * v for v in x)
            running[1] += x[2] * x[2]
            running[2] += 1
    total = [0.0] * 3
    print('term         E [m]    N [m]    U [m]   (constant offset, least squares over the flight)')
    for t in TERMS:
        x = solve3(n, b[t])
        if t in kept:
            total = [total[i] + x[i] for i in range(3)]
        print(f'{t:10s} {x[0]:8.3f} {x[1]:8.3f} {x[2]:8.3f}' + ('' if t in kept else '   (not in the sum)'))
    print(f'{"sum":10s} {total[0]:8.3f} {total[1]:8.3f} {total[2]:8.3f}   |sum| {math.sqrt(sum(v * v for v in total)):.3f}')
    if causal and running[2]:
        print(f'causal     RMS |offset| {math.sqrt(running[0] / running[2]):.3f}  RMS Up {math.sqrt(running[1] / running[2]):.3f}'
              f'   (offset solved after every epoch from the epochs so far; {running[2]} epochs)')
    if run:
        m, rms = filter_error(ds, run, start)
        print(f'{"filter":10s} {m[0]:8.3f} {m[1]:8.3f} {m[2]:8.3f}   (mean error of {run}/global_ecef.csv; RMSE {rms:.3f})')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
