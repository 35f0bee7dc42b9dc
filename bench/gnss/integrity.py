#!/usr/bin/env python3
"""RTK integrity on real pairs and stressed variants of them: fix rate and wrong fixes, ours
against RTKLIB's rnx2rtkp on the same inputs.

    bench/gnss/integrity.py [--build DIR] [--data DIR] [--out DIR] [--quick] [--cases a,b]
                            [--modes continuous,instantaneous,...] [--markdown FILE]
                            [--no-sim] [--sim-seeds N] [--ours-args "GVINS-RTK OPTIONS"]

Pairs (tests/data/gnss, provenance in tests/data/README.md):
  nagoya  Septentrio rover/base 0.99 m apart, 301 epochs at 1 Hz, five systems; truth: the
          rover position of the data set (mean of an RTKLIB fixed solution).
  geonet  GEONET 0759/3040, 3.34 km, GPS L1/L2, 120 epochs at 30 s; truth: the last epoch of
          RTKLIB's static fixed solution (reference/rtklib-2.4.3/geonet_0759_rtk_static.pos),
          0.17 m from the header position.
Variants (each alone on top of the base setting L1+L2, 15 deg, all systems): single frequency,
elevation masks 25 and 35 deg, one system at a time, the reported Galileo-only single-frequency
case at 25 deg, arcs cut to 30 s (every 30 s piece processed from a cold start), the rover's
Doppler sign flipped in a copy, the base's codes rewritten to other tracking modes of their band.
Simulated flights (gvins-sim, bench/gnss/harsh_flight.yaml): NLOS, blockages and slips on the
rover, base 5 and 10 km away, seeds 1..N (4); truth: the simulated antenna track.
AR modes: continuous, instantaneous, fix-and-hold, each with and without partial AR (RTKLIB
2.4.3 has no partial AR: its figures stand in both rows), and each again as the combined
forward + backward post-processing solution (mode "... +c": gvins-rtk --combined beside
rnx2rtkp -c).

A wrong fix is a fixed epoch (Q=1) more than 0.10 m (3-D) from the truth. The fix rate is the
share of rover epochs written with Q=1. Prints progress on stderr and a summary table on stdout
(and, with --markdown, the same table as Markdown for docs/).
"""
import gzip, math, os, re, shutil, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WRONG_M = 0.10
SYS_BITS = {'G': 1, 'R': 4, 'E': 8, 'J': 16, 'C': 32}
EXTRA = []  # --ours-args: further gvins-rtk options (experiments)
MODES = ['continuous', 'instantaneous', 'fix-and-hold', 'continuous+c', 'instantaneous+c', 'fix-and-hold+c']


def split_mode(mode):
    """AR mode and whether the combined (forward + backward) solution is asked for ('+c')."""
    return (mode[:-2], True) if mode.endswith('+c') else (mode, False)


def opt(args, name, default):
    return args[args.index(name) + 1] if name in args else default


def llh_to_ecef(lat, lon, h):
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    la, lo = math.radians(lat), math.radians(lon)
    n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo),
            (n * (1 - e2) + h) * math.sin(la))


def read_pos(path):
    """Rows (time string, (x, y, z), Q) of an RTKLIB-style .pos file in x/y/z-ecef form."""
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith('%') or not line.strip():
                continue
            p = line.split()
            rows.append((p[0] + ' ' + p[1], (float(p[2]), float(p[3]), float(p[4])), int(p[5])))
    return rows


# --- RINEX 3 observation files: header, epochs, and the few rewrites the variants need.

def split_rinex3(path):
    with open(path) as f:
        lines = f.read().splitlines()
    end = next(i for i, l in enumerate(lines) if l[60:].strip() == 'END OF HEADER')
    header, body = lines[:end + 1], lines[end + 1:]
    epochs, cur = [], None
    for l in body:
        if l.startswith('>'):
            cur = [l]
            epochs.append(cur)
        elif cur is not None:
            cur.append(l)
    return header, epochs


def obs_types(header):
    types, sys_ = {}, None
    for l in header:
        if l[60:].strip() == 'SYS / # / OBS TYPES':
            if l[0] != ' ':
                sys_ = l[0]
                types[sys_] = []
            types[sys_] += l[7:60].split()
    return types


def epoch_seconds(line):
    p = line[1:].split()
    return int(p[3]) * 3600 + int(p[4]) * 60 + float(p[5])


def write_rinex3(path, header, epochs):
    with open(path, 'w') as f:
        f.write('\n'.join(header) + '\n')
        for e in epochs:
            f.write('\n'.join(e) + '\n')


def flip_doppler(src, dst):
    header, epochs = split_rinex3(src)
    types = obs_types(header)
    for e in epochs:
        for k in range(1, len(e)):
            l = e[k]
            cols = types.get(l[0], [])
            chars = list(l.ljust(3 + 16 * len(cols)))
            for j, t in enumerate(cols):
                if t[0] != 'D':
                    continue
                a = 3 + 16 * j
                field = ''.join(chars[a:a + 14])
                if field.strip():
                    chars[a:a + 14] = list('%14.3f' % -float(field))
            e[k] = ''.join(chars).rstrip()
    write_rinex3(dst, header, epochs)


# Tracking mode a base code is rewritten to (same band, another attribute).
REWRITE = {'G': {'1C': '1X', '2W': '2X', '2L': '2S', '5Q': '5X'},
           'E': {'1C': '1X', '5Q': '5X', '7Q': '7X'},
           'C': {'2I': '2X', '7I': '7X', '6I': '6X'},
           'J': {'1C': '1X', '2L': '2X', '5Q': '5X'}}


def rewrite_codes(src, dst):
    """The base's observation codes moved to another tracking mode of their band (header only:
    the values stay, as from a receiver that reports aligned phases)."""
    header, epochs = split_rinex3(src)
    out, sys_ = [], None
    for l in header:
        lab = l[60:].strip()
        if lab == 'SYS / # / OBS TYPES':
            if l[0] != ' ':
                sys_ = l[0]
            m = REWRITE.get(sys_, {})
            toks = l[6:60].split()
            toks = [t[0] + m.get(t[1:], t[1:]) for t in toks]
            l = l[:6] + ''.join(' ' + t.ljust(3) for t in toks).ljust(54) + l[60:]
        elif lab == 'SYS / PHASE SHIFT' and l[0] in REWRITE:
            code = l[2:5]
            m = REWRITE[l[0]]
            if code[1:] in m:
                l = l[:2] + code[0] + m[code[1:]] + l[5:]
        out.append(l)
    write_rinex3(dst, out, epochs)


def cut_arcs(src, tmp, seconds):
    header, epochs = split_rinex3(src)
    pieces, cur, t0 = [], [], None
    for e in epochs:
        t = epoch_seconds(e[0])
        if t0 is None or t - t0 >= seconds:
            if cur:
                pieces.append(cur)
            cur, t0 = [], t
        cur.append(e)
    if cur:
        pieces.append(cur)
    paths = []
    for i, p in enumerate(pieces):
        path = os.path.join(tmp, 'piece%03d.obs' % i)
        write_rinex3(path, header, p)
        paths.append(path)
    return paths


def count_epochs(path):
    with open(path) as f:
        text = f.read()
    body = text.split('END OF HEADER', 1)[1]
    if '\n>' in body:
        return body.count('\n>')
    # RINEX 2: an epoch line is ' yy mm dd hh mm ss.sssssss  flag nsat...'.
    return len(re.findall(r'^ [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d\.\d{7}  [01]', body, re.M))


# --- The two tools.

def run_ours(build, rover, base, base_xyz, navs, out, mode, partial, freq, mask, systems):
    mode, combined = split_mode(mode)
    cmd = [os.path.join(build, 'bin', 'gvins-rtk'), '-q', '--xyz', '--armode', mode, '--freq', str(freq),
           '--elmask', str(mask), '--systems', systems, '--base-xyz', ','.join('%.4f' % v for v in base_xyz), '--ar-systems', systems.replace('R', '') or 'G',
           '-o', out, rover, base] + navs
    if not partial:
        cmd.insert(1, '--no-partial')
    if combined:
        cmd.insert(1, '--combined')
    cmd[1:1] = EXTRA
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode not in (0, 3):
        raise RuntimeError('gvins-rtk failed: %s\n%s' % (' '.join(cmd), r.stderr[-2000:]))
    return r.stderr


def run_rtklib(conf_template, rover, base, base_xyz, navs, out, mode, freq, mask, systems, tmp):
    mode, combined = split_mode(mode)
    lines = open(conf_template).read().splitlines()
    bits = sum(SYS_BITS[s] for s in systems)
    set_ = {'pos1-posmode': 'kinematic', 'pos2-armode': mode, 'pos1-elmask': str(mask),
            'pos2-arelmask': str(mask), 'pos1-navsys': str(bits), 'out-solformat': 'xyz',
            'pos1-frequency': {1: 'l1', 2: 'l1+2', 3: 'l1+2+5'}[freq],
            'pos1-soltype': 'combined' if combined else 'forward'}
    out_lines, seen = [], set()
    for l in lines:
        k = l.split('=')[0].strip()
        if k in set_:
            l = '%-19s=%s' % (k, set_[k])
            seen.add(k)
        out_lines.append(l)
    for k, v in set_.items():
        if k not in seen:
            out_lines.append('%-19s=%s' % (k, v))
    conf = os.path.join(tmp, 'rtklib.conf')
    with open(conf, 'w') as f:
        f.write('\n'.join(out_lines) + '\n')
    r = subprocess.run(['rnx2rtkp', '-k', conf] + (['-c'] if combined else []) + ['-r'] + ['%.4f' % v for v in base_xyz] + ['-o', out, rover, base] + navs, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
    return r.returncode


def score(pos_path, truth):
    """Fixed epochs, wrong fixes, worst wrong error. `truth`: one ECEF point (static), or a
    function of the .pos time string giving the ECEF point (None: no truth, not counted)."""
    fixed = wrong = 0
    worst = 0.0
    if not os.path.exists(pos_path):
        return 0, 0, 0.0
    for t, x, q in read_pos(pos_path):
        if q != 1:
            continue
        ref = truth(t) if callable(truth) else truth
        if ref is None:
            continue
        fixed += 1
        d = math.dist(x, ref)
        if d > WRONG_M:
            wrong += 1
            worst = max(worst, d)
    return fixed, wrong, worst


# --- Cases.

def plain(path, tmp):
    """The file itself, or its .gz decompressed into tmp (tests/data keeps RINEX compressed)."""
    if os.path.exists(path):
        return path
    out = os.path.join(tmp, os.path.basename(path))
    if not os.path.exists(out):
        with gzip.open(path + '.gz', 'rb') as f, open(out, 'wb') as g:
            shutil.copyfileobj(f, g)
    return out


def datasets(data, tmp):
    n = os.path.join(data, 'gnss', 'nagoya_static_2024')
    g = os.path.join(data, 'gnss', 'geonet_0759_3040_2005')
    def llh_file(path):
        with open(path) as f:
            return llh_to_ecef(*(float(v) for v in f.read().split()[:3]))
    nag_truth = llh_file(os.path.join(n, 'rover_position.txt'))
    nag_base = llh_file(os.path.join(n, 'base_position.txt'))
    geo_truth = read_pos(os.path.join(data, 'reference', 'rtklib-2.4.3', 'geonet_0759_rtk_static.pos'))[-1][1]
    return {
        'nagoya': dict(rover=plain(os.path.join(n, 'rover.obs'), tmp), base=plain(os.path.join(n, 'base.obs'), tmp),
                       navs=[plain(os.path.join(n, 'base.nav'), tmp)], truth=nag_truth, base_xyz=nag_base, systems='GREJC', rinex3=True),
        'geonet': dict(rover=plain(os.path.join(g, '07590920.05o'), tmp), base=plain(os.path.join(g, '30400920.05o'), tmp),
                       navs=[plain(os.path.join(g, '30400920.05n'), tmp)], truth=geo_truth, base_xyz=(-3978242.4348, 3382841.1715, 3649902.7667), systems='G', rinex3=False),
    }


def gpst_seconds(text):
    """Seconds of GPS time (from 1980-01-06) of a .pos time 'YYYY/MM/DD hh:mm:ss.sss'."""
    import datetime
    d, t = text.split()
    y, mo, da = (int(v) for v in d.split('/'))
    h, mi, se = t.split(':')
    base = datetime.datetime(y, mo, da) - datetime.datetime(1980, 1, 6)
    return base.days * 86400.0 + int(h) * 3600 + int(mi) * 60 + float(se)


def antenna_truth(csv_path):
    """The simulator's rover antenna truth as a function of the .pos time (nearest epoch within
    5 ms of true GPST)."""
    rows = []
    with open(csv_path) as f:
        for line in f:
            if line[0] in '#t':
                continue
            p = line.split(',')
            rows.append((int(p[1]) * 1e-9, (float(p[2]), float(p[3]), float(p[4]))))
    rows.sort()
    times = [r[0] for r in rows]
    import bisect

    def at(text):
        t = gpst_seconds(text)
        i = bisect.bisect_left(times, t)
        best = None
        for j in (i - 1, i):
            if 0 <= j < len(rows) and abs(rows[j][0] - t) < 0.005:
                best = rows[j][1]
        return best
    return at


def simulated(build, tmp, seeds, distances):
    """Harsh simulated flights (bench/gnss/harsh_flight.yaml) per base distance and seed."""
    scenario = os.path.join(ROOT, 'bench', 'gnss', 'harsh_flight.yaml')
    text = open(scenario).read().replace('../../tests/data', os.path.join(ROOT, 'tests', 'data'))
    out = {}
    for dist in distances:
        for seed in seeds:
            name = 'sim %d km seed %d' % (dist // 1000, seed)
            d = os.path.join(tmp, 'sim_%d_%d' % (dist, seed))
            if not os.path.exists(os.path.join(d, 'gnss', 'rover.obs')):
                y = os.path.join(tmp, 'harsh_%d.yaml' % dist)
                with open(y, 'w') as f:
                    f.write(text.replace('distance_m: 5000', 'distance_m: %d' % dist))
                subprocess.run([os.path.join(build, 'bin', 'gvins-sim'), '--config', y, '--seed', str(seed),
                                '--features-only', '-o', d], check=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
            g = os.path.join(d, 'gnss')
            base_xyz = None
            with open(os.path.join(g, 'base.obs')) as f:
                for line in f:
                    if 'APPROX POSITION XYZ' in line:
                        base_xyz = tuple(float(v) for v in line.split()[:3])
                        break
            out[name] = dict(rover=os.path.join(g, 'rover.obs'), base=os.path.join(g, 'base.obs'),
                             navs=[os.path.join(g, 'nav.rnx')], truth=antenna_truth(os.path.join(g, 'truth', 'rover_antenna.csv')),
                             base_xyz=base_xyz, systems='GREJC', rinex3=False, simulated=True)
    return out


def variants(ds):
    """(name, settings) of each stressed variant of a data set."""
    if ds.get('simulated'):
        return [('base', {})]
    v = [('base', {}), ('L1 only', {'freq': 1}), ('mask 25', {'mask': 25}), ('mask 35', {'mask': 35})]
    if len(ds['systems']) > 1:
        for s in ds['systems']:
            if s != 'R':
                v.append(('%s only' % s, {'systems': s}))
        v.append(('E L1 mask 25', {'systems': 'E', 'freq': 1, 'mask': 25}))
    if ds['rinex3']:
        v.append(('arcs 30 s', {'cut': 30}))
        v.append(('Doppler flipped', {'flip': True}))
        v.append(('base codes rewritten', {'rewrite': True}))
    return v


def main(args):
    EXTRA[:] = opt(args, '--ours-args', '').split()
    build = os.path.abspath(opt(args, '--build', os.path.join(ROOT, 'build')))
    data = os.path.abspath(opt(args, '--data', os.path.join(ROOT, 'tests', 'data')))
    conf = os.path.join(data, 'reference', 'rtklib-2.4.3', 'conf', 'rtk_kin.conf')
    only = opt(args, '--cases', '')
    modes = opt(args, '--modes', ','.join(MODES)).split(',')
    have_rtklib = shutil.which('rnx2rtkp') is not None and os.path.exists(conf)
    keep = opt(args, '--out', None)
    tmp_root = keep or tempfile.mkdtemp(prefix='integrity')
    os.makedirs(tmp_root, exist_ok=True)
    rows = []
    t_start = time.time()
    sets = datasets(data, tmp_root)
    if '--no-sim' not in args:
        seeds = range(1, int(opt(args, '--sim-seeds', '4')) + 1)
        sets.update(simulated(build, tmp_root, seeds, (5000, 10000)))
    for dname, ds in sets.items():
        for vname, s in variants(ds):
            case = '%s: %s' % (dname, vname)
            if only and not any(c in case for c in only.split(',')):
                continue
            if '--quick' in args and vname not in ('base', 'E L1 mask 25', 'L1 only'):
                continue
            tmp = os.path.join(tmp_root, (dname + '_' + vname).replace(' ', '_'))
            os.makedirs(tmp, exist_ok=True)
            rover, base = ds['rover'], ds['base']
            if s.get('flip'):
                rover = os.path.join(tmp, 'rover_flipped.obs')
                flip_doppler(ds['rover'], rover)
            if s.get('rewrite'):
                base = os.path.join(tmp, 'base_rewritten.obs')
                rewrite_codes(ds['base'], base)
            rovers = cut_arcs(ds['rover'], tmp, s['cut']) if s.get('cut') else [rover]
            epochs = sum(count_epochs(r) for r in rovers)
            freq, mask, systems = s.get('freq', 2), s.get('mask', 15), s.get('systems', ds['systems'])
            for mode in modes:
                res = {}
                for partial in (True, False):
                    fixed = wrong = 0
                    worst = 0.0
                    for i, r in enumerate(rovers):
                        out = os.path.join(tmp, 'ours_%s_%d_%d.pos' % (mode.replace('+', '_'), partial, i))
                        run_ours(build, r, base, ds['base_xyz'], ds['navs'], out, mode, partial, freq, mask, systems)
                        f, w, m = score(out, ds['truth'])
                        fixed, wrong, worst = fixed + f, wrong + w, max(worst, m)
                    res[partial] = (fixed, wrong, worst)
                rk = None
                if have_rtklib:
                    fixed = wrong = 0
                    worst = 0.0
                    for i, r in enumerate(rovers):
                        out = os.path.join(tmp, 'rtklib_%s_%d.pos' % (mode.replace('+', '_'), i))
                        run_rtklib(conf, r, base, ds['base_xyz'], ds['navs'], out, mode, freq, mask, systems, tmp)
                        f, w, m = score(out, ds['truth'])
                        fixed, wrong, worst = fixed + f, wrong + w, max(worst, m)
                    rk = (fixed, wrong, worst)
                rows.append((case, mode, epochs, res[True], res[False], rk))
                print('%6.0f s  %-34s %-13s ours %5.1f %% fixed, %d wrong (PAR) / %5.1f %%, %d wrong;  RTKLIB %s' % (
                    time.time() - t_start, case, mode, 100.0 * res[True][0] / max(epochs, 1), res[True][1],
                    100.0 * res[False][0] / max(epochs, 1), res[False][1],
                    '%5.1f %%, %d wrong' % (100.0 * rk[0] / max(epochs, 1), rk[1]) if rk else 'n/a'),
                      file=sys.stderr, flush=True)
    if not keep:
        shutil.rmtree(tmp_root, ignore_errors=True)

    def pct(n, d):
        return '%.1f' % (100.0 * n / d) if d else '-'

    head = ['case', 'AR mode', 'epochs', 'ours fix %', 'wrong', 'ours no-PAR fix %', 'wrong', 'RTKLIB fix %', 'wrong',
            'fix ≥ RTKLIB']
    table = []
    total_wrong = 0
    below = 0
    for case, mode, ep, par, nopar, rk in rows:
        total_wrong += par[1] + nopar[1]
        ge = '-' if rk is None else ('yes' if par[0] >= rk[0] else 'NO')
        if ge == 'NO':
            below += 1
        table.append([case, mode, str(ep), pct(par[0], ep), str(par[1]), pct(nopar[0], ep), str(nopar[1]),
                      pct(rk[0], ep) if rk else 'n/a', str(rk[1]) if rk else 'n/a', ge])
    w = [max(len(h), *(len(r[i]) for r in table)) for i, h in enumerate(head)] if table else [len(h) for h in head]
    print('  '.join(h.ljust(w[i]) for i, h in enumerate(head)))
    for r in table:
        print('  '.join(c.ljust(w[i]) for i, c in enumerate(r)))
    print('summary: %d cases x modes, %d wrong fixes (ours, with and without PAR), %d rows with a fix rate below '
          'RTKLIB\'s' % (len(rows), total_wrong, below))
    md = opt(args, '--markdown', None)
    if md:
        with open(md, 'w') as f:
            f.write('<!-- written by bench/gnss/integrity.py; do not edit by hand -->\n')
            f.write('# RTK integrity: fix rate and wrong fixes, ours and RTKLIB 2.4.3\n\n')
            f.write('`bench/gnss/integrity.py --markdown docs/rtk_integrity.md` (docstring of the script: pairs, '
                    'truth, stressed variants, simulated flights). A wrong fix is a fixed epoch more than %.2f m '
                    '(3-D) from the truth; fix %% is of all rover epochs. "no-PAR": `--no-partial`. RTKLIB '
                    '(rnx2rtkp, same elevation mask, frequencies, systems and AR mode, ratio 3) has no partial '
                    'fixing. AR mode "... +c": the combined forward + backward solution (`gvins-rtk --combined`, '
                    '`rnx2rtkp -c`; docs/rtk.md, "Combined forward + backward solution"). Model of the fix: '
                    'docs/rtk.md, "Integrity of the fix".\n\n' % WRONG_M)
            f.write('| ' + ' | '.join(head) + ' |\n|' + '---|' * len(head) + '\n')
            for r in table:
                f.write('| ' + ' | '.join(r) + ' |\n')
            f.write('\n%d wrong fixes in all (ours); wrong = fixed epoch > %.2f m (3-D) from the truth.\n' % (
                total_wrong, WRONG_M))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
