#!/usr/bin/env python3
"""Which simulated error terms make the error of pseudorange positioning (psr or dpsr rows).

    psr_error_attribution.py DATASET [--run OUTDIR] [--dpsr] [--bands G:152,J:152]
                             [--ephemeris-error G:0.6,R:5,E:0.3,C:1,J:0.6] [--precise | --broadcast]
                             [--sigma 0.6] [--mask 15] [--smoothing 100] [--from S] [--until S]
                             [--causal [--series CSV]] [--without sisre,...]

DATASET: gvins-sim output simulated with `gnss: error_terms: true` (gnss/truth/rover_errors.csv,
base_errors.csv). Each error term (broadcast orbit/clock error = sisre, troposphere residual,
ionosphere, code multipath, code noise, phase wind-up) is carried through the rows as the fusion
forms them and mapped into one constant ENU offset by weighted least squares over all epochs with
a clock per system and epoch: the error a perfect VIO + GNSS filter would keep ("the floor").

psr (default): the ionosphere-free pair of the fusion's band order, carrier-smoothed codes (the
Hatch filter of gnss/carrier_smoothing.hpp replayed on each term's code and phase parts, --smoothing
S seconds, 0 = raw codes), weights (sigma k)^2 (1/2 + 1/(2 sin^2 el)) + ephemeris_error^2 with k
the pair's noise factor, the fusion's elevation mask (15 deg). With precise products (--precise, or
a --run whose metrics.csv counts precise satellites, unless --broadcast) the weights take the
fusion's precise_ephemeris_error_m and sisre is left out of the sum: the products' own error
(centimetres in gvins-sim) is not in the truth files.
--dpsr: the rover-base single differences of vio+dopp+dpsr: one row per band (the RTK module's
band order, two bands), both receivers' codes carrier-smoothed, the base's terms interpolated to
the rover epoch, RTK code weights (100 f_sys)^2 2 (0.003^2 + 0.003^2 / sin^2 el); the base clock
drops out with the per-system mean, so the sum is the rover-minus-base part of every term.

With --run (a gvins-replay OUTDIR), the epochs start at the first tight epoch and the filter's mean
ENU error and RMSE are printed alongside; --from/--until keep only the epochs that many seconds
after that start. --causal also solves the offset after every epoch from the epochs so far (what a
causal filter with a perfect VIO can know then): its mean (ENU) and RMS over the tight epochs, once
with the epochs from the first tight one only (the filter's data) and once with all epochs (a
perfect VIO from the first epoch on); --series writes the latter per epoch. --without drops terms
from the sums. NLOS-affected satellites are left out (the filter's gate rejects them).
docs/gnss_fusion.md; bench/sweep/psr_floor.py runs it over the sweep's flights."""
import bisect, collections, math, sys

F = {('G', '1'): 1575.42, ('G', '2'): 1227.60, ('G', '5'): 1176.45, ('J', '1'): 1575.42, ('J', '2'): 1227.60,
     ('J', '5'): 1176.45, ('E', '1'): 1575.42, ('E', '5'): 1176.45, ('E', '7'): 1207.14, ('C', '2'): 1561.098,
     ('C', '7'): 1207.14, ('C', '6'): 1268.52, ('R', '1'): 9.0, ('R', '2'): 7.0}  # GLONASS: ratio 9/7
PRIMARY = {'G': '1', 'J': '1', 'E': '1', 'C': '2', 'R': '1'}
PSR_BANDS = {'G': '152', 'J': '152', 'E': '157', 'C': '276', 'R': '12'}  # the fusion's `bands`
RTK_BANDS = {'G': '125', 'R': '12', 'E': '157', 'C': '276', 'J': '125'}  # RtkConfig::bands, 2 of them
RTK_SYSTEM_FACTOR = {'G': 1.0, 'R': 1.5, 'E': 1.0, 'C': 1.0, 'J': 1.0}    # RtkConfig::codeSystemFactor
TERMS = ['sisre', 'tropo', 'iono', 'mp', 'noise', 'windup']
# The fusion's ephemeris_error_m and precise_ephemeris_error_m (SppConfig), per system.
BROADCAST_ERROR, PRECISE_ERROR = 'G:0.6,R:5,E:0.3,C:1,J:0.6', 'G:0.05,R:5,E:0.05,C:0.1,J:0.1'


def opt(args, name, default):
    return args[args.index(name) + 1] if name in args else default


def per_system(text, conv):
    return {k: conv(v) for k, v in (kv.split(':') for kv in text.split(',') if kv)}


def read_metrics(run):
    out = {}
    for line in open(run + '/metrics.csv'):
        v = line.strip().split(',')
        if len(v) == 2 and not line.startswith('#'):
            try:
                out[v[0]] = float(v[1])
            except ValueError:
                pass
    return out


def read_errors(path):
    """{tag_ns: {sat: {signal: row}}} of a gvins-sim error-terms file."""
    rows, hdr = collections.defaultdict(lambda: collections.defaultdict(dict)), None
    for line in open(path):
        if line.startswith('#'):
            continue
        if line.startswith('tag_ns'):
            hdr = line.strip().split(',')
            continue
        r = dict(zip(hdr, line.strip().split(',')))
        rows[int(r['tag_ns'])][r['sat']][r['signal']] = r
    return rows


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


def parts(r):
    """(code, phase) error of each term of one signal, m: the smoothing filter sees both. The
    ionosphere is the whole delay (its model is subtracted where a row uses one)."""
    g = lambda k: float(r[k])
    sisre, tropo = g('orbit_error_los') - g('sat_clock_error'), g('tropo') - g('tropo_model')
    return {'sisre': (sisre, sisre), 'tropo': (tropo, tropo), 'iono': (g('iono'), -g('iono')),
            'mp': (g('mp_code'), g('mp_phase')), 'noise': (g('code_noise'), g('phase_noise')),
            'windup': (0.0, g('windup_cycles') * g('wavelength'))}


def smooth(rows, window, max_gap=60.0):
    """Each term's error in the codes the rows use: carried through the Hatch filter of
    gnss/carrier_smoothing.hpp (w = max(1/n, dt/window), all signals of a satellite on one arc,
    restarted on a new ambiguity, a loss-of-lock flag, a changed signal set or a gap), or raw
    (window 0). Returns {(tag, sat, signal): {term: error}}."""
    out, arcs = {}, {}
    for tag in sorted(rows):
        t = tag * 1e-9
        for sat, sig in rows[tag].items():
            now = {code: parts(r) for code, r in sig.items()}
            amb = {code: r['ambiguity_cycles'] for code, r in sig.items()}
            a = arcs.get(sat)
            restart = (a is None or window <= 0 or set(sig) != set(a['amb']) or not 0 < t - a['t'] <= max_gap or
                       any(amb[c] != a['amb'][c] for c in amb) or
                       any(int(r['arc_start']) or int(float(r['lli'])) & 1 for r in sig.values()))
            if restart:
                a = arcs[sat] = {'n': 1, 'est': {c: {k: v[0] for k, v in p.items()} for c, p in now.items()}}
            else:
                w = max(1.0 / (a['n'] + 1), min(1.0, (t - a['t']) / window))
                a['n'] += 1
                for c, p in now.items():
                    e = a['est'][c]
                    for k, (code, phase) in p.items():
                        e[k] = w * code + (1 - w) * (e[k] + phase - a['phase'][c][k])
            a['t'], a['amb'], a['phase'] = t, amb, {c: {k: v[1] for k, v in p.items()} for c, p in now.items()}
            for c in sig:
                out[(tag, sat, c)] = dict(a['est'][c])
    return out


def line_of_sight(r):
    el, az = math.radians(float(r['elevation_deg'])), math.radians(float(r['azimuth_deg']))
    return el, [-math.cos(el) * math.sin(az), -math.cos(el) * math.cos(az), -math.sin(el)]


def psr_rows(tag, sats, smoothed, o):
    """Rows (clock system, weight, ENU gradient, {term: error}) of one epoch of psr rows."""
    out = []
    for sat, sig in sats.items():
        s = sat[0]
        bands = {code[0]: code for code in sig}
        if s not in PRIMARY or PRIMARY[s] not in bands:
            continue
        r1 = sig[bands[PRIMARY[s]]]
        el, h = line_of_sight(r1)
        if el < o['mask'] or float(r1['nlos']) > 0:
            continue
        e, k = smoothed[(tag, sat, r1['signal'])], 1.0
        for b2 in o['bands'].get(s, ''):
            if b2 != PRIMARY[s] and b2 in bands:
                f1, f2 = F[(s, PRIMARY[s])], F[(s, b2)]
                a1 = f1 * f1 / (f1 * f1 - f2 * f2)
                e2 = smoothed[(tag, sat, bands[b2])]
                e = {t: a1 * e[t] + (1 - a1) * e2[t] for t in TERMS}
                k = math.hypot(a1, 1 - a1)
                break
        else:
            e = dict(e, iono=e['iono'] - float(r1['iono_model']))  # single frequency: Klobuchar
        se = max(math.sin(el), 0.1)
        w = 1.0 / ((o['sigma'] * k) ** 2 * (0.5 + 0.5 / se ** 2) + o['eph'].get(s, 0.0) ** 2)
        out.append(('G' if s == 'J' else s, w, h, e))
    return out


def base_at(base, base_tags, tag):
    """The base's smoothed terms at a rover epoch: linear between the bracketing base epochs."""
    i = bisect.bisect_right(base_tags, tag)
    if i == 0:
        return None
    t0 = base_tags[i - 1]
    if i == len(base_tags) or t0 == tag:
        return base[t0] if tag - t0 <= 2e9 else None
    t1 = base_tags[i]
    u = (tag - t0) / (t1 - t0)
    out = {}
    for key, e0 in base[t0].items():
        e1 = base[t1].get(key)
        out[key] = {t: e0[t] + u * (e1[t] - e0[t]) for t in TERMS} if e1 else e0
    return out


def dpsr_rows(tag, sats, smoothed, base, o):
    """Rows of one epoch of rover-base single-differenced codes (one per band, two bands)."""
    out = []
    if base is None:
        return out
    for sat, sig in sats.items():
        s = sat[0]
        if s not in RTK_BANDS:
            continue
        bands = {code[0]: code for code in sig}
        first = sig[next(iter(sig))]
        el, h = line_of_sight(first)
        if el < o['mask'] or float(first['nlos']) > 0:
            continue
        se = max(math.sin(el), 0.05)
        w = 1.0 / ((100 * RTK_SYSTEM_FACTOR[s]) ** 2 * 2 * (0.003 ** 2 + 0.003 ** 2 / se ** 2))
        used = 0
        for b in RTK_BANDS[s]:
            if used == 2:
                break
            if b not in bands or (sat, bands[b]) not in base:
                continue
            er, eb = smoothed[(tag, sat, bands[b])], base[(sat, bands[b])]
            out.append(('G' if s == 'J' else s, w, h, {t: er[t] - eb[t] for t in TERMS}))
            used += 1
    return out


def first_tight(run):
    for line in open(run + '/gnss_epochs.csv'):
        v = line.split(',')
        if len(v) > 2 and v[2] == 'tight':
            return float(v[1])
    return -1.0


class Normal:
    """Normal equations of the constant ENU offset, the clocks eliminated epoch by epoch."""

    def __init__(self):
        self.n = [[0.0] * 3 for _ in range(3)]
        self.b = {t: [0.0] * 3 for t in TERMS}

    def add(self, rows):
        by_clock = collections.defaultdict(list)
        for clock, w, h, e in rows:
            by_clock[clock].append((w, h, e))
        for lst in by_clock.values():  # the clock of each system eliminated: weighted de-meaning
            ws = sum(x[0] for x in lst)
            hb = [sum(x[0] * x[1][i] for x in lst) / ws for i in range(3)]
            eb = {t: sum(x[0] * x[2][t] for x in lst) / ws for t in TERMS}
            for w, h, e in lst:
                d = [h[i] - hb[i] for i in range(3)]
                for i in range(3):
                    for j in range(3):
                        self.n[i][j] += w * d[i] * d[j]
                    for t in TERMS:
                        self.b[t][i] += w * d[i] * (e[t] - eb[t])

    def offset(self, terms):
        try:
            return solve3(self.n, [sum(self.b[t][i] for t in terms) for i in range(3)])
        except ZeroDivisionError:
            return None


class Running:
    """Mean and RMS of the causal offsets over the epochs they are taken at."""

    def __init__(self):
        self.s, self.sq, self.k = [0.0] * 3, 0.0, 0

    def add(self, x):
        self.s = [self.s[i] + x[i] for i in range(3)]
        self.sq += sum(v * v for v in x)
        self.k += 1

    def result(self):
        return {'mean': [v / self.k for v in self.s], 'rms': math.sqrt(self.sq / self.k), 'epochs': self.k} if self.k else None


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
    return {'mean': [a / max(n, 1) for a in acc], 'rms': math.sqrt(sq / max(n, 1)), 'epochs': n}


def options(args):
    run = opt(args, '--run', None)
    precise = not ('--dpsr' in args or '--broadcast' in args) and (
        '--precise' in args or (run is not None and read_metrics(run).get('precise_satellites', 0) > 0))
    bands = dict(PSR_BANDS)
    bands.update(per_system(opt(args, '--bands', ''), str))
    dropped = set(opt(args, '--without', '').split(',')) - {''}
    if precise:
        dropped.add('sisre')
    return {'run': run, 'dpsr': '--dpsr' in args, 'precise': precise, 'bands': bands,
            'mask': math.radians(float(opt(args, '--mask', 15))), 'sigma': float(opt(args, '--sigma', 0.6)),
            'eph': per_system(opt(args, '--ephemeris-error', PRECISE_ERROR if precise else BROADCAST_ERROR), float),
            'smoothing': float(opt(args, '--smoothing', 100)), 'causal': '--causal' in args,
            'from': float(opt(args, '--from', '0')), 'until': float(opt(args, '--until', '1e9')),
            'kept': [t for t in TERMS if t not in dropped], 'series': opt(args, '--series', None)}


def attribute(ds, o):
    """The floor of one dataset (and run): {'terms': {term: ENU}, 'sum': ENU, 'kept': [...],
    'causal_tight'/'causal_all': {'mean', 'rms', 'epochs'} or None, 'filter': {...} or None}."""
    start = first_tight(o['run']) if o['run'] else -1.0
    rover = read_errors(ds + '/gnss/truth/rover_errors.csv')
    smoothed = smooth(rover, o['smoothing'])
    base, base_tags = {}, []
    if o['dpsr']:
        b = read_errors(ds + '/gnss/truth/base_errors.csv')
        bs = smooth(b, o['smoothing'])
        for (tag, sat, code), e in bs.items():
            base.setdefault(tag, {})[(sat, code)] = e
        base_tags = sorted(base)
    flight, causal = Normal(), {'tight': (Normal(), Running()), 'all': (Normal(), Running())}
    series = open(o['series'], 'w') if o['causal'] and o['series'] else None
    if series is not None:
        series.write('# tow [s],E [m],N [m],U [m]  (causal offset after each epoch, all epochs)\n')
    for tag in sorted(rover):
        tow = (tag * 1e-9) % 604800
        before = tow < start - 1e-6
        if before and not o['causal']:
            continue
        if not before and not start + o['from'] - 1e-6 <= tow <= start + o['until'] + 1e-6:
            continue
        rows = (dpsr_rows(tag, rover[tag], smoothed, base_at(base, base_tags, tag), o) if o['dpsr']
                else psr_rows(tag, rover[tag], smoothed, o))
        if not before:
            flight.add(rows)
        for key, (normal, running) in causal.items() if o['causal'] else ():
            if key == 'tight' and before:
                continue
            normal.add(rows)
            x = normal.offset(o['kept']) if not before and rows else None
            if x is None:
                continue
            running.add(x)
            if series is not None and key == 'all':
                series.write(f'{tow:.3f},{x[0]:.4f},{x[1]:.4f},{x[2]:.4f}\n')
    terms = {t: flight.offset([t]) for t in TERMS}
    total = [sum(terms[t][i] for t in o['kept']) for i in range(3)]
    return {'terms': terms, 'sum': total, 'kept': o['kept'],
            'causal_tight': causal['tight'][1].result(), 'causal_all': causal['all'][1].result(),
            'filter': filter_error(ds, o['run'], start) if o['run'] else None}


def main(args):
    if not args or args[0].startswith('-'):
        print(__doc__)
        return 2
    o = options(args)
    a = attribute(args[0], o)
    print('term         E [m]    N [m]    U [m]   (constant offset, least squares over the flight)')
    for t in TERMS:
        x = a['terms'][t]
        print(f'{t:10s} {x[0]:8.3f} {x[1]:8.3f} {x[2]:8.3f}' + ('' if t in a['kept'] else '   (not in the sum)'))
    s = a['sum']
    print(f'{"sum":10s} {s[0]:8.3f} {s[1]:8.3f} {s[2]:8.3f}   |sum| {math.sqrt(sum(v * v for v in s)):.3f}')
    for key, what in (('causal_tight', 'first tight epoch on'), ('causal_all', 'first epoch on')):
        c = a[key]
        if c:
            m = c['mean']
            print(f'{"causal":10s} {m[0]:8.3f} {m[1]:8.3f} {m[2]:8.3f}   RMS |offset| {c["rms"]:.3f}   (offset solved '
                  f'after every epoch from the epochs of the {what}; mean and RMS over {c["epochs"]} epochs)')
    if a['filter']:
        m = a['filter']['mean']
        print(f'{"filter":10s} {m[0]:8.3f} {m[1]:8.3f} {m[2]:8.3f}   RMSE {a["filter"]["rms"]:.3f}   (mean error of '
              f'{o["run"]}/global_ecef.csv)')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
