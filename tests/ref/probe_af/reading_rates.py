#!/usr/bin/python3
"""What pmfit explain reads from 1,800 German and fork mounts of an independent
gimbal (probe AF, stop 46; gimbal.py beside this file, numpy only, no pm code):
12 scenarios of 150 runs (15-300 stars, noise 0.5-10", latitudes -33..47,
flip zones 0-30 deg), and how often the baseline's reading (JSON
physical_reading) names a pier-side step, a sag or refraction, false or beyond
3 sigma of the truth, and whether each refraction or tube-flexure finding's
"beside" values are within 3 sigma of it.

    /usr/bin/python3 tests/ref/probe_af/reading_rates.py build/pmfit [OUTDIR]

(about 10 minutes on two cores; the runs are written to OUTDIR, default a
temporary directory).  docs/explain.md quotes its table."""
import collections, json, os, re, subprocess, sys, tempfile
from concurrent.futures import ThreadPoolExecutor
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCENARIOS = ['null', 'aniso', 'polar+aniso', 'aniso+sag', 'daf', 'sag', 'refr', 'sag+refr',
             'pcol', 'pid', 'pcol+aniso', 'pid+aniso']
BASE = 3000


def gen_case(k, scen, rng):
    """The probe's draw of one mount (the order of the draws is the probe's)."""
    c = dict(seed=int(k), n=int(rng.choice([15, 20, 30, 40, 60, 80, 120, 200, 300])),
             noise=float(np.round(rng.uniform(0.5, 10) if rng.random() < 0.5 else rng.uniform(0.5, 3), 2)),
             lat=float(rng.choice([47, 35, -33, -24.6, 20])), mount='gem' if rng.random() < 0.8 else 'fork',
             zone=float(rng.choice([0, 5, 15, 30])), ch=float(rng.uniform(-60, 60)),
             np=float(rng.uniform(-30, 30)), ih=float(rng.uniform(-3, 3)), id=float(rng.uniform(-1, 1)),
             polar=0.0)
    if 'aniso' in scen: c['aniso'] = float(np.round(rng.uniform(5, 60), 1))
    if 'polar' in scen: c['polar'] = float(np.round(rng.uniform(30, 300), 1))
    if 'daf' in scen: c['daf'] = float(np.round(rng.uniform(10, 40) * rng.choice([-1, 1]), 1))
    if 'sag' in scen: c['sag'] = float(np.round(rng.uniform(5, 30) * rng.choice([-1, 1]), 1))
    if 'refr' in scen: c['refr'] = float(np.round(rng.uniform(5, 40) * rng.choice([-1, 1]), 1))
    if 'pcol' in scen:
        c['dcol'] = float(np.round(rng.uniform(5, 25) * rng.choice([-1, 1]), 1)); c['mount'] = 'gem'
    if 'pid' in scen:
        c['did'] = float(np.round(rng.uniform(5, 25) * rng.choice([-1, 1]), 1)); c['mount'] = 'gem'
    return c


def value(reading, key):
    m = re.search(re.escape(key) + r' ?(-?[0-9.]+)" \+- ([0-9.]+)"', reading or '')
    return (float(m.group(1)), float(m.group(2))) if m else None


def main():
    pmfit = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix='pm_af_')
    os.makedirs(out, exist_ok=True)
    cases = []
    for scen in SCENARIOS:
        rng = np.random.default_rng(BASE)
        for k in range(150):
            cases.append((scen, '%s_%d' % (scen.replace('+', '_'), BASE + k), gen_case(BASE + k, scen, rng)))

    def run(case):
        scen, name, c = case
        f = os.path.join(out, name + '.dat')
        subprocess.run(['/usr/bin/python3', os.path.join(HERE, 'gimbal.py'), f] +
                       sum([['--' + k, str(v)] for k, v in c.items()], []), check=True)
        p = subprocess.run([pmfit, 'explain', f, '--json'], capture_output=True, text=True)
        try:
            return scen, c, json.loads(p.stdout)
        except ValueError:
            return scen, c, None
    with ThreadPoolExecutor(2) as ex:
        res = list(ex.map(run, cases))
    rows = collections.OrderedDict((s, collections.Counter()) for s in SCENARIOS)
    beside = collections.Counter()
    for scen, c, j in res:
        S = rows[scen]
        S['runs'] += 1
        if j is None:
            S['refused'] += 1
            continue
        r = j.get('physical_reading') or ''
        step = c.get('dcol', 0) != 0 or c.get('did', 0) != 0
        if 'pier_side' in r:
            S['pier step read' if step else 'pier step read, none there'] += 1
        for key, truth in (('tube_flexure (', c.get('sag', 0.0)), ('refraction (', c.get('refr', 0.0))):
            v = value(r, key)
            if v:
                S[key[:-2] + ' read'] += 1
                if abs(v[0] - truth) > 3 * v[1]:
                    S[key[:-2] + ' read, > 3 sigma off'] += 1
        truth = {'tube_flexure': c.get('sag', 0.0), 'refraction': c.get('refr', 0.0)}
        for f in j['findings']:
            b = f.get('beside')
            if not b:
                continue
            beside['findings with beside'] += 1
            beside['value > 3 sigma off'] += abs(b['value_arcsec'] - truth[f['effect']]) > 3 * b['error_arcsec']
            beside['other > 3 sigma off'] += (abs(b['other_value_arcsec'] - truth[b['effect']]) >
                                              3 * b['other_error_arcsec'])
    keys = ['runs', 'pier step read', 'pier step read, none there', 'tube_flexure read',
            'tube_flexure read, > 3 sigma off', 'refraction read', 'refraction read, > 3 sigma off']
    print('| scenario | ' + ' | '.join(keys) + ' |')
    print('|' + '---|' * (len(keys) + 1))
    for s, S in rows.items():
        print('| %s | ' % s + ' | '.join(str(S[k]) for k in keys) + ' |')
    print('\nbeside lines of refraction / tube-flexure findings: %s' % dict(beside))


if __name__ == '__main__':
    main()
