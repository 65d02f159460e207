#!/usr/bin/python3
"""tpoint_campaign.py -- judge `pmfit explain` on runs of the independent generator
tests/ref/tpoint_gen.py (astropy reduction, exact TPOINT-convention gimbal, files written as
mount software writes them: TPOINT .dat, N.I.N.A./ASCOM CSV logs, named columns for alt-az runs
with temperature or time).

Per case: draw a configuration, make the run without the hidden effect (its baseline sigma from
`pmfit fit RUN --json`), calibrate each hidden effect so that alone it inflates that sigma by a
factor drawn uniformly in 1.15-1.70 (trial size, scale, verify), write the final run, run
`pmfit explain RUN --json` (order 1; tube flexure: order 0, and order 1 for the baseline's
physical reading), and score it:

  single effects   named first (and for periodic effects the right G), parameters within 25%
  null runs        any finding is a false alarm; the noise-free misfit of the run at the
                   baseline order ("floor") says whether real structure was there to find
  2-3 effects      fraction of hidden effects named (also counting alternatives), runs where
                   an effect not hidden was named ("invented"; separately when that finding
                   offers a hidden effect as its alternative)
  reduction        astropy's observed place vs what pmfit's own reduction gives, on
                   noise-free null runs (raw RMS, and what order 0 / order 1 fits leave)

Usage:
  /usr/bin/python3 tests/ref/tpoint_campaign.py --out /tmp/tpc [--jobs 2] [--quick]
      [--per N] [--seed S] [--results FILE]

Every case's run files, its truth, the commands to regenerate it and explain's findings are in
the results JSON (default OUT/results.json).
"""

import argparse
import json
import math
import multiprocessing as mp
import os
import re
import subprocess
import sys
import time
import traceback

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOP = os.path.abspath(os.path.join(HERE, '..', '..'))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True       # leave no __pycache__ in tests/ref
import tpoint_gen as tg  # noqa: E402

PMFIT = os.path.join(TOP, 'build', 'pmfit')
GEN = 'tests/ref/tpoint_gen.py'

VOCAB = {
    'gem': ['ha_pe', 'dec_pe', 'pier_flex', 'refraction', 'sag', 'temperature', 'drift', 'backlash',
            'outlier'],
    'fork': ['ha_pe', 'dec_pe', 'refraction', 'sag', 'temperature', 'drift', 'backlash', 'outlier'],
    'altaz': ['az_pe', 'el_pe', 'az_runout', 'refraction', 'sag', 'temperature', 'drift', 'cable_wrap',
              'outlier'],
}
# our physical name -> explain's effect name
EXPECT = {'ha_pe': 'ha_periodic', 'az_pe': 'ha_periodic', 'az_runout': 'ha_periodic',
          'dec_pe': 'dec_periodic', 'el_pe': 'dec_periodic', 'pier_flex': 'pier_side',
          'refraction': 'refraction', 'pressure': 'refraction', 'sag': 'tube_flexure',
          'temperature': 'temperature', 'drift': 'time_drift', 'backlash': 'hysteresis',
          'cable_wrap': 'hysteresis', 'outlier': 'outlier', 'outliers1pct': 'outlier'}
PERIODIC = ('ha_pe', 'dec_pe', 'az_pe', 'el_pe', 'az_runout')
# trial sizes, in units of the noise (temperature, drift: divided by the input's spread)
# the largest size tried, in units of the noise: beyond it the baseline is said to hold the effect
MAXSIZE = {'outlier': 100.0, 'pier_flex': 60.0}
TRIAL = {'ha_pe': 1.5, 'dec_pe': 1.5, 'az_pe': 2.0, 'el_pe': 1.5, 'az_runout': 2.0, 'pier_flex': 3.0,
         'refraction': 1.0, 'pressure': 1.0, 'sag': 1.0, 'temperature': 1.0, 'drift': 1.0,
         'backlash': 1.0, 'cable_wrap': 1.5, 'outlier': 15.0}


# ----------------------------------------------------------------------------------------------
# pmfit

def pmfit(args, rec, timeout=600):
    cmd = [PMFIT] + [str(a) for a in args]
    t0 = time.time()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        rec.setdefault('pmfit_failures', []).append(dict(cmd=' '.join(cmd), rc='timeout', stderr=''))
        return None, ''
    rec['pmfit_seconds'] = rec.get('pmfit_seconds', 0.0) + time.time() - t0
    for line in r.stderr.splitlines():
        if line.strip():
            rec.setdefault('pmfit_messages', set()).add(re.sub(r'\S+\.(dat|csv):\d+:', 'FILE:LINE:', line)[:240])
    if r.returncode != 0:
        rec.setdefault('pmfit_failures', []).append(dict(cmd=' '.join(cmd), rc=r.returncode,
                                                         stderr=r.stderr.strip()[-2000:]))
        return None, r.stderr
    return r.stdout, r.stderr


def fit_sigma(path, order, rec):
    out, _ = pmfit(['fit', path, '--order', order, '--json'], rec)
    if out is None:
        return None
    try:
        return json.loads(out)['sigma_arcsec']
    except Exception:
        rec.setdefault('pmfit_failures', []).append(dict(cmd='fit %s' % path, rc='bad json', stderr=out[:500]))
        return None


def explain(path, order, rec):
    out, _ = pmfit(['explain', path, '--order', order, '--json'], rec)
    if out is None:
        return None
    try:
        return json.loads(out)
    except Exception:
        rec.setdefault('pmfit_failures', []).append(dict(cmd='explain %s' % path, rc='bad json', stderr=out[:500]))
        return None


# ----------------------------------------------------------------------------------------------
# cases

def case_list(args):
    rng = np.random.default_rng(args.seed)
    cases = []
    per = args.per
    n_null = args.null
    n_pair = args.pairs
    n_triple = args.triples
    k = 0

    def add(kind, mount, effects, **kw):
        nonlocal k
        k += 1
        d = dict(id='%s_%s_%s_%03d' % (kind, mount, '+'.join(effects) or 'none', k), kind=kind,
                 mount=mount, effects=effects, seed=int(args.seed * 100000 + k))
        d.update(kw)
        cases.append(d)

    for mount, vocab in VOCAB.items():
        for e in vocab:
            for j in range(per):
                add('single', mount, [e])
    for mount in VOCAB:
        for j in range(n_null):
            levels = [(0.0, 0.0, 'mech'), (3.0, 0.0, 'mech'), (30.0, 0.0, 'mech'), (120.0, 0.0, 'mech'),
                      (30.0, 0.0, 'encoder'), (120.0, 0.0, 'encoder'), (3.0, 0.5, 'mech'), (30.0, 1.0, 'mech')]
            a, b, fr = levels[j % len(levels)]
            add('null', mount, [], aniso=a, aniso_beyond=b, aniso_frame=fr)
    for mount, vocab in VOCAB.items():
        pool = [e for e in vocab if e != 'sag'] + ['outliers1pct']
        for j in range(n_pair):
            add('pair', mount, sorted(rng.choice(pool, 2, replace=False).tolist()))
        for j in range(n_triple):
            add('triple', mount, sorted(rng.choice(pool, 3, replace=False).tolist()))
    return cases


def case_config(spec):
    """The generator's overrides for a case (recorded; the command line repeats them)."""
    rng = np.random.default_rng([spec['seed'], 99])
    mount, effects = spec['mount'], spec['effects']
    kw = dict(mount=mount)
    if mount == 'altaz':
        kw['fmt'] = 'named' if ('temperature' in effects or 'drift' in effects) else \
            str(rng.choice(['tpoint', 'tpoint', 'tpoint', 'named']))
    else:
        kw['fmt'] = 'csv' if 'temperature' in effects else str(rng.choice(['tpoint', 'tpoint', 'csv']))
    skies = ['full', 'full', 'half', 'band', 'oneside']
    if 'pier_flex' in effects:
        skies = ['full', 'full', 'half', 'band']
    kw['sky'] = str(rng.choice(skies))
    if 'aniso' in spec:
        kw['aniso'] = spec['aniso']
        kw['aniso_beyond'] = spec['aniso_beyond']
    elif 'sag' in effects:
        kw['aniso'] = 0.0
        kw['aniso_beyond'] = 0.0
    else:
        kw['aniso'] = float(rng.choice([0.0, 3.0, 30.0, 120.0], p=[0.3, 0.3, 0.25, 0.15]))
        kw['aniso_beyond'] = float(rng.choice([0.0, 0.0, 0.0, 0.3]))
    kw['aniso_frame'] = spec.get('aniso_frame') or ('encoder' if rng.random() < 0.3 else 'mech')
    if 'sag' in effects:
        kw['terms'] = {'TF': 0.0}
    if 'outliers1pct' in effects:
        kw['outlier_frac'] = 0.01
    # refraction: half the runs as a wrong pressure in the file, half as an extra cot(el)
    mode = {}
    for e in effects:
        if e == 'refraction':
            mode[e] = 'pressure' if rng.random() < 0.5 else 'refraction'
    return kw, mode, rng


def gen_command(path, seed, kw, effs):
    s = ['/usr/bin/python3', GEN, path, '--seed', str(seed), '--mount', kw['mount'], '--format', kw['fmt'],
         '--sky', kw['sky'], '--aniso', repr(kw['aniso']), '--aniso-beyond', repr(kw['aniso_beyond']),
         '--aniso-frame', kw['aniso_frame']]
    for k, v in kw.get('terms', {}).items():
        s += ['--term', '%s=%r' % (k, v)]
    if kw.get('outlier_frac'):
        s += ['--outlier-frac', repr(kw['outlier_frac'])]
    for e in effs:
        opts = ','.join('%s=%s' % (k, repr(v) if isinstance(v, float) else v) for k, v in e.items()
                        if k not in ('name', 'size') and not k.startswith(('pressure_', 'dA_', 'dB_')))
        s += ['--effect', '%s:%r%s' % (e['name'], e['size'], (':' + opts) if opts else '')]
    return ' '.join(s)


def ext(kw):
    return '.csv' if kw['fmt'] == 'csv' else '.dat'


class Case:
    def __init__(self, spec, out):
        self.spec = spec
        self.rec = dict(spec)
        self.kw, self.mode, self.rng = case_config(spec)
        self.c = tg.draw_config(spec['seed'], **self.kw)
        self.obs = tg.observe(self.c)
        self.base = os.path.join(out, spec['id'])
        self.order = '0' if 'sag' in spec['effects'] else '1'
        self.ntrial = 0

    def write(self, effs, path):
        run = tg.make_run(self.c, self.obs, effs)
        truth = tg.write(self.c, self.obs, run, path, truth_path='')
        return run, truth

    def sigma_with(self, effs):
        self.ntrial += 1
        p = self.base + '_trial%d' % self.ntrial + ext(self.kw)
        run, truth = self.write(effs, p)
        s = fit_sigma(p, self.order, self.rec)
        if s is not None:
            os.remove(p)          # a file pmfit refused is kept for the report
        return s, run

    def trial_size(self, name):
        nz = self.c['noise']
        t = TRIAL[name] * nz
        if name == 'temperature':
            t = nz / max(np.std(self.obs['temp']), 0.2)
        elif name == 'drift':
            t = nz / max(np.std(self.obs['tsec'] / 3600.0), 0.2)
        return t

    def calibrate(self, e, sigma0, target):
        """Size of effect e (dict with name, params) for sigma/sigma0 = target."""
        name = e['name']
        sign = 1.0
        if name in ('refraction', 'pressure'):
            sign = 1.0 if self.rng.random() < 0.5 else -1.0
        s_t = self.trial_size(name)
        s_max = MAXSIZE.get(name, 30.0) * self.c['noise'] if name not in ('temperature', 'drift') else 30 * s_t
        if name == 'pressure':
            # a legal pressure: 0 < P <= 1100 hPa (positive dA: more pressure written than true)
            A0 = tg.refco(self.c, self.c['pressure'])[0]
            up = (tg.refco(self.c, 1090.0)[0] - A0) / tg.AS
            if sign > 0 and up < s_max:
                sign = -1.0
            s_max = min(s_max, 0.6 * A0 / tg.AS)
        st = None
        for _ in range(4):
            st, run = self.sigma_with([dict(e, size=sign * s_t)])
            if st is None:
                return None, None
            if st ** 2 - sigma0 ** 2 > 0.03 * sigma0 ** 2:
                break
            if s_t >= s_max:
                return 'held', st / sigma0
            s_t = min(3.0 * s_t, s_max)
        kappa = max(st ** 2 - sigma0 ** 2, 1e-12) / s_t ** 2
        s = math.sqrt((target ** 2 - 1.0) * sigma0 ** 2 / kappa)
        if s > 1.5 * s_max:
            return 'held', st / sigma0
        for _ in range(3):
            s = float('%.6g' % min(s, 1.5 * s_max))
            sg, run = self.sigma_with([dict(e, size=sign * s)])
            if sg is None:
                return None, None
            f = sg / sigma0
            if abs(f - target) < 0.03:
                break
            kappa = max(sg ** 2 - sigma0 ** 2, 1e-12) / s ** 2
            s = math.sqrt((target ** 2 - 1.0) * sigma0 ** 2 / kappa)
        return float('%.6g' % (sign * s)), f


# ----------------------------------------------------------------------------------------------
# scoring

NUM = r'([-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?)'


def coef(text, name):
    m = re.search(re.escape(name) + r' = ' + NUM, text)
    return float(m.group(1)) if m else None


def truth_values(e, c, truth_effects):
    """What explain should report, in explain's definitions (docs/explain.md "Parameters")."""
    nm = e['name']
    s = e['size']
    if nm in PERIODIC:
        return dict(G=int(round(e['G'])), amplitude=abs(s), phase_deg=-e['phase'])
    if nm == 'pier_flex':
        return dict(amplitude=abs(s))
    if nm == 'refraction':
        return dict(signed=s, key='cot(el)')
    if nm == 'pressure':
        return dict(signed=e['dA_arcsec'], key='cot(el)')
    if nm == 'sag':
        return dict(signed=-(s + c['terms']['TF']), key='cos(el)')
    if nm in ('temperature', 'drift', 'backlash', 'cable_wrap'):
        cp = s * math.cos(e['psi'] * tg.DEG)
        ep = -s * math.sin(e['psi'] * tg.DEG)
        key = {'temperature': ("c'*temp", "e'*temp"), 'drift': ("c'*time", "e'*time"),
               'backlash': ("c'*dir", "e'*dec_dir"), 'cable_wrap': ("c'*dir", "e'*dec_dir")}[nm]
        return dict(vector=(cp, ep), keys=key, amplitude_c=cp)
    if nm in ('outlier',):
        return dict(amplitude=abs(s))
    return {}


def finding_matches(f, e):
    if f['effect'] != EXPECT[e['name']]:
        return False
    if e['name'] in PERIODIC:
        return int(round(f.get('cycles_per_rev') or -1)) == int(round(e['G'])) and \
            abs(f.get('cycles_per_rev') - round(f.get('cycles_per_rev'))) < 1e-6
    return True


def params_ok(f, e, tv, truth):
    """(ok, note)"""
    nm = e['name']
    a = f.get('amplitude_arcsec')
    if nm in PERIODIC:
        ok = abs(a / tv['amplitude'] - 1) <= 0.25
        return ok, 'G %s/%d amp %.3f/%.3f' % (f.get('cycles_per_rev'), tv['G'], a, tv['amplitude'])
    if nm == 'pier_flex':
        return abs(a / tv['amplitude'] - 1) <= 0.25, 'amp %.3f/%.3f' % (a, tv['amplitude'])
    if 'signed' in tv:
        v = coef(f['text'], tv['key'])
        if v is None:
            v = a
        return abs(v - tv['signed']) <= 0.25 * abs(tv['signed']), '%s %.3f/%.3f' % (tv['key'], v, tv['signed'])
    if 'vector' in tv:
        c1 = coef(f['text'], tv['keys'][0]) or 0.0
        c2 = coef(f['text'], tv['keys'][1]) or 0.0
        t1, t2 = tv['vector']
        mag = math.hypot(t1, t2)
        ok = math.hypot(c1 - t1, c2 - t2) <= 0.25 * mag
        return ok, "c',e' (%.3f, %.3f)/(%.3f, %.3f) amplitude_arcsec %.3f vs c' %.3f" % (c1, c2, t1, t2, a, t1)
    if nm == 'outlier':
        lines_ok = sorted(f.get('lines') or []) == sorted(truth['outlier_lines'])
        return lines_ok and abs(a / tv['amplitude'] - 1) <= 0.25, 'lines %s/%s amp %.2f/%.2f' % (
            f.get('lines'), truth['outlier_lines'], a, tv['amplitude'])
    return False, ''


def summarise_findings(ex):
    if ex is None:
        return None
    out = []
    for f in ex.get('findings', []):
        out.append(dict(effect=f['effect'], cycles_per_rev=f.get('cycles_per_rev'),
                        amplitude_arcsec=f.get('amplitude_arcsec'),
                        amplitude_error_arcsec=f.get('amplitude_error_arcsec'),
                        log10_fap=f.get('log10_false_alarm_probability'), step=f.get('step'),
                        lines=f.get('lines'), with_=f.get('with'),
                        alternatives=[dict(effect=a['effect'], kind=a.get('kind'), delta_bic=a.get('delta_bic'))
                                      for a in f.get('alternatives', [])],
                        text=f.get('text')))
    return out


def close_kind(a):
    """Offered for close evidence (Delta BIC < 6): kind "close" at the
    finding's step or "final" in the final model, not "smooth"."""
    return (a.get('kind') or 'close') in ('close', 'final')


def hidden_named(findings, e, with_alt):
    for f in findings:
        if finding_matches(f, e):
            return True
        if with_alt:
            for a in f.get('alternatives', []):
                if a['effect'] == EXPECT[e['name']] and close_kind(a):
                    return True
    return False


def invented(findings, effs):
    inv, inv_alt = [], []
    for f in findings:
        if any(finding_matches(f, e) for e in effs):
            continue
        alts = [a['effect'] for a in f.get('alternatives', []) if close_kind(a)]
        if any(EXPECT[e['name']] in alts for e in effs):
            inv_alt.append(f['effect'])
        else:
            inv.append(f['effect'] + ('' if f.get('cycles_per_rev') is None else ':%g' % f['cycles_per_rev']))
    return inv, inv_alt


# ----------------------------------------------------------------------------------------------

def run_case(arg):
    spec, out = arg
    t0 = time.time()
    rec = dict(spec)
    try:
        cs = Case(spec, out)
        rec = cs.rec
        c = cs.c
        rec['config'] = {k: c[k] for k in ('n', 'noise', 'sky', 'lat', 'aniso', 'aniso_beyond', 'aniso_frame', 'format',
                                            'flip_side', 'flip_writing', 'ra_writing', 'az_writing',
                                            'csv_equinox', 'order', 'hours', 'terms')}
        rec['order'] = int(cs.order)
        p0 = cs.base + '_base' + ext(cs.kw)
        run0, truth0 = cs.write([], p0)
        rec['base_run'] = p0
        rec['base_command'] = gen_command(p0, spec['seed'], cs.kw, [])
        sigma0 = fit_sigma(p0, cs.order, rec)
        rec['sigma0'] = sigma0
        if sigma0 is None:
            rec['error'] = 'baseline fit failed'
            return rec
        # the noise-free floor of the configuration at the baseline order
        cnf = dict(c)
        cnf['noise'] = 1e-6
        cnf['outlier_frac'] = 0.0
        run_nf = tg.make_run(cnf, cs.obs, [])
        pnf = cs.base + '_floor' + ext(cs.kw)
        tg.write(cnf, cs.obs, run_nf, pnf, truth_path='')
        fl = fit_sigma(pnf, cs.order, rec)
        os.remove(pnf)
        rec['floor'] = fl
        if fl is not None:
            rec['floor_excess_chi2'] = 2 * c['n'] * (fl / c['noise']) ** 2
        # effects: each calibrated alone
        effs = []
        rec['targets'] = []
        rec['inflation_alone'] = []
        for name in spec['effects']:
            nm = cs.mode.get(name, name)
            if nm == 'outliers1pct':
                continue
            e = tg.effect_defaults(dict(name=nm, size=1.0), c, np.random.default_rng([spec['seed'], len(effs), 5]))
            target = float(cs.rng.uniform(1.15, 1.70))
            size, f = cs.calibrate(e, sigma0, target)
            if size is None:
                rec['error'] = 'calibration fit failed for ' + nm
                return rec
            if size == 'held':
                rec['held'] = dict(effect=nm, inflation_at_max=f)
                rec['seconds'] = time.time() - t0
                return rec
            e['size'] = size
            effs.append(e)
            rec['targets'].append(target)
            rec['inflation_alone'].append(f)
        path = cs.base + ext(cs.kw)
        run, truth = cs.write(effs, path)
        with open(path + '.truth.json', 'w') as fh:
            json.dump(dict(truth, outlier_lines=truth['outlier_lines']), fh, indent=1, default=float)
        rec['run'] = path
        rec['command'] = gen_command(path, spec['seed'], cs.kw, [{k: v for k, v in e.items()} for e in effs])
        rec['truth_effects'] = run['effects']
        effs = run['effects']          # as make_run filled them (a wrong pressure's dA, dB)
        rec['outlier_lines'] = truth['outlier_lines']
        sig = fit_sigma(path, cs.order, rec)
        rec['sigma'] = sig
        rec['inflation'] = sig / sigma0 if sig else None
        ex = explain(path, cs.order, rec)
        rec['explain_command'] = 'build/pmfit explain %s --order %s --json' % (path, cs.order)
        if ex is None:
            rec['error'] = 'explain failed'
            return rec
        F = summarise_findings(ex)
        rec['findings'] = F
        rec['withdrawn'] = ex.get('withdrawn')
        rec['unmodelled'] = [u['effect'] for u in ex.get('unmodelled', [])]
        rec['baseline'] = ex.get('baseline')
        rec['final'] = ex.get('final')
        rec['interpretation'] = {i['what']: (i['value'], i['error']) for i in ex.get('interpretation', [])}
        cv = (ex.get('baseline') or {}).get('cv_rms_arcsec')
        rec['cv_available'] = cv is not None and (not isinstance(cv, list) or all(x is not None for x in cv))
        rec['structure'] = (rec.get('floor_excess_chi2') or 0.0) > 20.0
        # the sampled extent of each axis and the smallest period explain searches (docs/explain.md)
        if c['mount'] == 'altaz':
            a1, a2 = cs.obs['az_obs'], cs.obs['el_obs']
        else:
            a1 = np.where(cs.obs['side'] > 0, cs.obs['ha_obs'], cs.obs['ha_obs'] + math.pi)
            a2 = np.where(cs.obs['side'] > 0, cs.obs['dec_obs'], math.pi - cs.obs['dec_obs'])
        srt = np.sort(np.mod(a1, 2 * math.pi))
        gaps = np.diff(np.concatenate([srt, [srt[0] + 2 * math.pi]]))
        ext1 = 2 * math.pi - gaps.max()
        ext2 = np.ptp(a2)
        rec['extent_deg'] = [math.degrees(ext1), math.degrees(ext2)]
        rec['g_min'] = [1.5 * 2 * math.pi / ext1, 1.5 * 2 * math.pi / ext2]
        # a second explain at order 1 for sag cases: the baseline's reading of the sag
        if 'sag' in spec['effects']:
            ex1 = explain(path, '1', rec)
            if ex1 is not None:
                rec['findings_order1'] = summarise_findings(ex1)
                it = {i['what']: (i['value'], i['error']) for i in ex1.get('interpretation', [])}
                rec['sag_in_order1'] = it.get('tube_flexure_in_order1')
        # scoring
        sc = {}
        if spec['kind'] == 'single':
            e = effs[0]
            tv = truth_values(e, c, effs)
            sc['truth'] = tv
            first = F[0] if F else None
            sc['named_first'] = bool(first and finding_matches(first, e))
            sc['first'] = (first['effect'] + ('' if first.get('cycles_per_rev') is None else
                                              ':%g' % first['cycles_per_rev'])) if first else None
            match = [f for f in F if finding_matches(f, e)]
            sc['named_anywhere'] = bool(match)
            sc['named_as_alternative'] = (not sc['named_first']) and bool(first) and any(
                a['effect'] == EXPECT[e['name']] for a in first['alternatives'])
            sc['smooth_alternative'] = bool(first) and any(a.get('kind') == 'smooth' for a in first['alternatives'])
            if e['name'] in PERIODIC:
                ax = 1 if e['name'] in ('ha_pe', 'az_pe', 'az_runout') else 2
                sc['searchable'] = bool(e['G'] >= rec['g_min'][ax - 1])
            if match:
                ok, note = params_ok(match[0], e, tv, truth)
                sc['params_ok'] = ok
                sc['params_note'] = note
                err = match[0].get('amplitude_error_arcsec')
                sc['amp_error'] = err
                if err and 'amplitude' in tv:
                    sc['amp_z'] = (match[0]['amplitude_arcsec'] - tv['amplitude']) / err
                elif err and 'signed' in tv:
                    v = coef(match[0]['text'], tv['key'])
                    if v is not None:
                        sc['amp_z'] = (v - tv['signed']) / err
            else:
                sc['params_ok'] = False
            sc['others'] = [f['effect'] for f in F if not finding_matches(f, e)]
            if 'sag_in_order1' in rec and rec['sag_in_order1']:
                v, er = rec['sag_in_order1']
                t = tv['signed']
                sc['sag_in_order1_ok'] = abs(v - t) <= max(3 * er, 0.0) or abs(v - t) <= 0.25 * abs(t)
        elif spec['kind'] == 'null':
            sc['false_alarm'] = bool(F)
            sc['found'] = [f['effect'] for f in F]
        else:
            allfx = list(effs)
            if 'outliers1pct' in spec['effects']:
                allfx.append(dict(name='outliers1pct'))
            sc['named'] = [hidden_named(F, e, False) if e['name'] != 'outliers1pct' else
                           any(f['effect'] == 'outlier' for f in F) for e in allfx]
            sc['named_or_alt'] = [hidden_named(F, e, True) if e['name'] != 'outliers1pct' else
                                  any(f['effect'] == 'outlier' for f in F) for e in allfx]
            inv, inv_alt = invented(F, allfx)
            if rec['structure']:
                sc['higher_order_structure'] = [x for x in inv if x == 'higher_order']
                inv = [x for x in inv if x != 'higher_order']
            sc['invented'] = inv
            sc['invented_alt'] = inv_alt
            sc['hidden'] = [e['name'] for e in allfx]
            sc['found'] = [f['effect'] for f in F]
        rec['score'] = sc
    except Exception:
        rec['error'] = traceback.format_exc()
    rec['seconds'] = time.time() - t0
    if 'pmfit_messages' in rec:
        rec['pmfit_messages'] = sorted(rec['pmfit_messages'])
    return rec


# ----------------------------------------------------------------------------------------------
# the reduction mismatch: astropy vs pmfit's reduction, noise-free null runs

def reduction_case(arg):
    (mount, fmt, eqx, seed), out = arg
    rec = dict(mount=mount, format=fmt, equinox=eqx, seed=seed)
    try:
        kw = dict(mount=mount, fmt=fmt, aniso=0.0, aniso_beyond=0.0, noise=1e-6, terms={'TF': 0.0})
        if fmt == 'csv':
            kw['csv_equinox'] = eqx
        c = tg.draw_config(seed, **kw)
        obs = tg.observe(c)
        run = tg.make_run(c, obs, [])
        base = os.path.join(out, 'reduction_%s_%s_%s_%d' % (mount, fmt, eqx, seed))
        p = base + ('.csv' if fmt == 'csv' else '.dat')
        tg.write(c, obs, run, p, truth_path='')
        p4 = base + '_astropy.txt'
        tg.write_four_column(c, obs, run, p4)
        pm = base + '_astropy.pm'
        o, _ = pmfit(['fit', p4, '--order', '0', '--save', pm, '--json'], rec)
        rec['astropy_fit_sigma'] = json.loads(o)['sigma_arcsec'] if o else None
        o, _ = pmfit(['eval', pm, p, '--json'], rec)
        rec['raw_rms'] = json.loads(o)['rms_arcsec'] if o else None
        for L in ('0', '1'):
            o, _ = pmfit(['fit', p, '--order', L, '--json'], rec)
            rec['sigma_order' + L] = json.loads(o)['sigma_arcsec'] if o else None
            if L == '0' and o:
                t_file = {t['name']: t['value_arcsec'] for t in json.loads(o)['terms']}
                o4, _ = pmfit(['fit', p4, '--order', '0', '--json'], rec)
                t_ast = {t['name']: t['value_arcsec'] for t in json.loads(o4)['terms']}
                rec['term_diff'] = {k: t_file[k] - t_ast[k] for k in t_file}
        # a null explain of the same noise-free geometry with 0.3" noise: anything found?
        c2 = dict(c)
        c2['noise'] = 0.3
        run2 = tg.make_run(c2, obs, [])
        p2 = base + '_n03' + ('.csv' if fmt == 'csv' else '.dat')
        tg.write(c2, obs, run2, p2, truth_path='')
        p24 = base + '_n03_astropy.txt'
        tg.write_four_column(c2, obs, run2, p24)
        for L in ('0', '1'):
            ex = explain(p2, L, rec)
            rec['explain_0.3_order' + L] = [f['effect'] for f in ex['findings']] if ex else None
            ex = explain(p24, L, rec)
            rec['explain_0.3_astropy_order' + L] = [f['effect'] for f in ex['findings']] if ex else None
        if mount != 'altaz':
            rec.update(erfa_decomposition(c, obs))
        rec['run'] = p
        rec['n'] = c['n']
        rec['lat'] = c['lat']
    except Exception:
        rec['error'] = traceback.format_exc()
    if 'pmfit_messages' in rec:
        rec['pmfit_messages'] = sorted(rec['pmfit_messages'])
    return rec


def erfa_decomposition(c, obs):
    """The reduction docs/formats.md describes (eraAtci13, the equation of the origins, eraRefco and
    one Newton step), redone here with pyerfa at the true UTC, against astropy's observed place:
    the difference split into a rotation (what the model's order-0 terms absorb) and a tilt toward a
    fixed direction (diurnal aberration is one toward the east point, 0.32" cos(lat))."""
    import erfa
    A = tg._ap()
    phi = c['lat'] * tg.DEG
    tt = A['Time'](obs['mjd'], format='mjd', scale='utc').tt
    ri, di, eo = erfa.atci13(obs['ra'], obs['dec'], 0, 0, 0, 0, tt.jd1, tt.jd2)
    h = obs['lst'] - erfa.anp(ri - eo)
    az, e0 = erfa.hd2ae(h, di, phi)
    zd = math.pi / 2 - e0
    Ar, Br = erfa.refco(c['pressure'], c['temp_c'], c['humidity'], c['wavelength'])
    tz = np.tan(zd)
    dz = (Ar + Br * tz ** 2) * tz / (1 + (Ar + 3 * Br * tz ** 2) / np.cos(zd) ** 2)
    hh, dd = erfa.ae2hd(az, e0 + dz, phi)
    v1 = tg.vec(hh, dd)
    v0 = tg.vec(obs['ha_obs'], obs['dec_obs'])
    ea, eb = tg.tangent_basis(v0)
    Dv = v1 - v0
    Y = np.concatenate([np.sum(Dv * ea, -1), np.sum(Dv * eb, -1)]) / tg.AS
    cols = []
    for V in np.eye(3):
        r = np.cross(V, v0)
        cols.append(np.concatenate([np.sum(r * ea, -1), np.sum(r * eb, -1)]))
    for V in np.eye(3):
        t = V - (v0 @ V)[:, None] * v0
        cols.append(np.concatenate([np.sum(t * ea, -1), np.sum(t * eb, -1)]))
    X = np.array(cols).T
    k3 = np.linalg.lstsq(X[:, :3], Y, rcond=None)[0]
    k6 = np.linalg.lstsq(X, Y, rcond=None)[0]
    return dict(erfa_raw_rms=float(np.sqrt(np.mean(Y ** 2))),
                erfa_after_rotation_rms=float(np.sqrt(np.mean((Y - X[:, :3] @ k3) ** 2))),
                erfa_after_rotation_tilt_rms=float(np.sqrt(np.mean((Y - X @ k6) ** 2))),
                erfa_tilt_arcsec=[float(x) for x in k6[3:]],
                diurnal_expected_arcsec=0.32 * math.cos(phi))


# ----------------------------------------------------------------------------------------------

def pct(a, b):
    return '%d/%d' % (a, b) if b else '-'


def report(results, red, fh=sys.stdout):
    P = lambda *a: print(*a, file=fh)  # noqa: E731
    P('\n=== single effects (baseline order 1; sag: order 0) ===')
    P('%-7s %-12s %5s %12s %12s %10s %14s  %s' % ('mount', 'effect', 'runs', 'named first', 'params<=25%',
                                                  'as alt', 'inflation', 'first findings when missed'))
    for mount in VOCAB:
        for eff in VOCAB[mount]:
            rs = [r for r in results if r['kind'] == 'single' and r['mount'] == mount and r['effects'] == [eff]
                  and 'score' in r]
            held = [r for r in results if r['kind'] == 'single' and r['mount'] == mount and r['effects'] == [eff]
                    and 'held' in r]
            if not rs and not held:
                continue
            nf = sum(r['score']['named_first'] for r in rs)
            po = sum(r['score']['params_ok'] for r in rs)
            alt = sum(r['score'].get('named_as_alternative', False) for r in rs)
            inf = [r['inflation'] for r in rs if r.get('inflation')]
            miss = [(r['score']['first'] or 'nothing') + ('(+smooth alt)' if r['score'].get('smooth_alternative')
                                                          else '') for r in rs if not r['score']['named_first']]
            if held:
                miss.append('(+%d held by the baseline: inflation < 1.015 at the largest size)' % len(held))
            P('%-7s %-12s %5d %12s %12s %10s %14s  %s' % (
                mount, eff, len(rs), pct(nf, len(rs)), pct(po, len(rs)), pct(alt, len(rs)),
                ('%.2f-%.2f' % (min(inf), max(inf))) if inf else '-', ', '.join(miss)))
    amps = [r for r in results if r['kind'] == 'single' and 'score' in r and r['score'].get('named_anywhere')]
    P('(named first: the first finding is the hidden effect, periodic ones with the exact G; params: the'
      ' matching finding\'s parameters within 25%%, periodic: G exact; outlier: exactly its line)')
    sag = [r for r in results if r['kind'] == 'single' and r['effects'] == ['sag'] and 'score' in r]
    if sag:
        ok = sum(1 for r in sag if r['score'].get('sag_in_order1_ok'))
        f1 = sum(1 for r in sag if r.get('findings_order1'))
        P('sag: order-1 baseline reading tube_flexure_in_order1 within 3 sigma or 25%% of the truth: %s; '
          'order-1 explain named something: %s' % (pct(ok, len(sag)), pct(f1, len(sag))))
    P('\n=== null runs (nothing hidden) ===')
    P('(aniso: RMS of the in-span anisotropy / of the part beyond order 1, arcsec; frame: a function of the'
      ' mechanical or of the encoder angles; floor chi2: the excess chi2 a noise-free copy of the run leaves'
      ' at order 1 -- above 20 there is real structure to find, so a finding there is not a false alarm)')
    P('%-7s %-22s %5s %12s %14s  %s' % ('mount', 'aniso in/beyond frame', 'runs', 'any finding', 'floor chi2>20',
                                        'found (floor excess chi2)'))
    tot = [0, 0, 0]
    for mount in VOCAB:
        lev = sorted(set((r['aniso'], r['aniso_beyond'], r['aniso_frame']) for r in results
                         if r['kind'] == 'null' and r['mount'] == mount))
        for a, b, fr in lev:
            rs = [r for r in results if r['kind'] == 'null' and r['mount'] == mount and r['aniso'] == a
                  and r['aniso_beyond'] == b and r['aniso_frame'] == fr and 'score' in r]
            fa = [r for r in rs if r['score']['false_alarm']]
            st = [r for r in fa if r.get('structure')]
            tot[0] += len(rs)
            tot[1] += len(fa) - len(st)
            tot[2] += len(st)
            P('%-7s %-22s %5d %12s %14s  %s' % (mount, '%g/%g %s' % (a, b, fr), len(rs), pct(len(fa), len(rs)),
                                                pct(len(st), len(fa)) if fa else '-',
                                                '; '.join('%s (%.0f)' % ('+'.join(r['score']['found']),
                                                                         r.get('floor_excess_chi2') or -1) for r in fa)))
    P('null runs: %d; a finding without real structure (false alarm): %d; a finding where the noise-free run'
      ' has real structure (floor chi2 > 20): %d' % tuple(tot))
    flg = [r for r in results if r['kind'] == 'null' and 'score' in r and r.get('unmodelled')
           and not r['score']['false_alarm']]
    P('null runs without a finding that flag a family significant, not modelled: %d%s' % (
        len(flg), ''.join(' (%s %s, floor chi2 %.0f)' % (r['mount'], '+'.join(r['unmodelled']),
                                                          r.get('floor_excess_chi2') or -1) for r in flg)))
    zs = [r['score']['amp_z'] for r in results if r['kind'] == 'single' and 'score' in r and 'amp_z' in r['score']]
    if zs:
        zs = np.array(zs)
        P('\nsingle-effect amplitudes, (found - true) / reported error: %d values, mean %+.2f, sd %.2f, within 2: %.1f%%'
          ' (pier_side reports no error and is not counted)' % (len(zs), zs.mean(), zs.std(), 100 * np.mean(np.abs(zs) <= 2)))
    gs = []
    for r in results:
        for f in r.get('findings') or []:
            for e in r.get('truth_effects', []):
                if e['name'] in PERIODIC and f['effect'] == EXPECT[e['name']] and f.get('cycles_per_rev') is not None \
                        and abs(f['cycles_per_rev'] - e['G']) <= 3 and e['G'] >= 10:
                    ax = 0 if e['name'] in ('ha_pe', 'az_pe', 'az_runout') else 1
                    gs.append((r['extent_deg'][ax], f['cycles_per_rev'] - e['G']))
    if gs:
        for lo, hi in ((0, 90), (90, 180), (180, 400)):
            sel = [d for x, d in gs if lo <= x < hi]
            if sel:
                P('gear periods (G >= 10) found on an axis sampled over %d-%d deg: %d, G exact in %d, off by 1-3 in %d' % (
                    lo, hi, len(sel), sum(1 for d in sel if d == 0), sum(1 for d in sel if d != 0)))
    nocv = [r for r in results if r.get('cv_available') is False]
    if nocv:
        P('runs whose baseline cross-validation was "not available": %d (%s)' % (
            len(nocv), ', '.join('%s:%s' % (r['id'], ('found ' + '+'.join(f['effect'] for f in r['findings'])) if r.get('findings')
                                            else 'nothing found') for r in nocv[:12])))
    base_fa = [r for r in results if r['kind'] == 'single' and 'findings' in r]
    P('\n=== two and three effects at once ===')
    P('%-7s %-7s %5s %10s %12s %10s %14s %14s  %s' % ('mount', 'kind', 'runs', 'named', 'named/alt', 'invented',
                                                      'invented(alt)', 'h.o.+structure', 'what was invented'))
    for kind in ('pair', 'triple'):
        for mount in VOCAB:
            rs = [r for r in results if r['kind'] == kind and r['mount'] == mount and 'score' in r]
            if not rs:
                continue
            nh = sum(len(r['score']['named']) for r in rs)
            nn = sum(sum(r['score']['named']) for r in rs)
            na = sum(sum(r['score']['named_or_alt']) for r in rs)
            inv = sum(1 for r in rs if r['score']['invented'])
            hos = sum(1 for r in rs if r['score'].get('higher_order_structure'))
            inva = sum(1 for r in rs if r['score']['invented_alt'] and not r['score']['invented'])
            P('%-7s %-7s %5d %10s %12s %10s %14s %14s  %s' % (mount, kind, len(rs), pct(nn, nh), pct(na, nh),
                                                      pct(inv, len(rs)), pct(inva, len(rs)), pct(hos, len(rs)),
                                                      '; '.join('%s: %s' % ('+'.join(r['effects']), '+'.join(r['score']['invented']))
                                                                for r in rs if r['score']['invented'])))
    if red:
        P('\n=== reduction mismatch: astropy observed place vs pmfit\'s reduction (noise-free null runs) ===')
        P('(raw RMS: the saved order-0 model of the astropy places applied to the file as pmfit reduces it;'
          ' L0/L1 sig: what a noise-free fit of the file leaves; 0.3" noise: explain at order 0 / order 1 on the'
          ' file, and [in brackets] on the same run with astropy\'s places given directly)')
        P('%-6s %-7s %-6s %4s %7s %9s %9s %9s  %-16s %s' % ('mount', 'format', 'eqx', 'n', 'lat', 'raw RMS"',
                                                            'L0 sig"', 'L1 sig"', 'max |d term| L0',
                                                            '0.3" noise: L0 / L1 findings [astropy places]'))
        for r in red:
            if 'error' in r:
                P('%-6s %-7s %-6s ERROR %s' % (r['mount'], r['format'], r['equinox'], r['error'][-200:]))
                continue
            td = r.get('term_diff') or {}
            k = max(td, key=lambda x: abs(td[x])) if td else '-'
            f = lambda x: '%.4f' % x if x is not None else 'n/a'  # noqa: E731
            P('%-6s %-7s %-6s %4d %7.2f %9s %9s %9s  %-16s %s / %s  [%s / %s]' % (
                r['mount'], r['format'], r['equinox'] if r['format'] == 'csv' else '-', r['n'], r['lat'],
                f(r.get('raw_rms')), f(r.get('sigma_order0')), f(r.get('sigma_order1')),
                ('%s %+.3f' % (k, td[k])) if td else '-', r.get('explain_0.3_order0'), r.get('explain_0.3_order1'),
                r.get('explain_0.3_astropy_order0'), r.get('explain_0.3_astropy_order1')))
        dec = [r for r in red if 'erfa_raw_rms' in r]
        if dec:
            P('the reduction docs/formats.md describes, redone with pyerfa at the true UTC, minus astropy\'s place:')
            for r in dec:
                P('  %-5s lat %+6.2f: raw %.3f", after a rotation %.4f", after a rotation and a tilt %.5f";'
                  ' tilt toward the east point %+.3f" (diurnal aberration 0.32" cos(lat) = %.3f")' % (
                      r['mount'], r['lat'], r['erfa_raw_rms'], r['erfa_after_rotation_rms'],
                      r['erfa_after_rotation_tilt_rms'], r['erfa_tilt_arcsec'][1], r['diurnal_expected_arcsec']))
    fails = [(r.get('id', r.get('run')), f) for r in list(results) + list(red or []) for f in r.get('pmfit_failures', [])]
    errs = [(r.get('id'), r['error'][-300:]) for r in results if 'error' in r]
    P('\n=== pmfit refusals / crashes: %d;  campaign errors: %d ===' % (len(fails), len(errs)))
    for cid, f in fails[:30]:
        P('  %s: rc=%s %s\n     %s' % (cid, f['rc'], f['cmd'], f['stderr'][-400:].replace('\n', '\n     ')))
    for cid, e in errs[:30]:
        P('  %s: %s' % (cid, e.replace('\n', ' | ')))
    msgs = {}
    for r in results:
        for m in r.get('pmfit_messages', []):
            msgs[m] = msgs.get(m, 0) + 1
    if msgs:
        P('\n=== pmfit messages on stderr (distinct, count of cases) ===')
        for m, k in sorted(msgs.items(), key=lambda x: -x[1])[:25]:
            P('  %4d  %s' % (k, m))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--out', required=True, help='directory for the generated runs')
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--quick', action='store_true', help='1 run per single effect, 2 null, 1 pair, 1 triple per mount')
    ap.add_argument('--per', type=int, default=15, help='runs per single effect and mount')
    ap.add_argument('--null', type=int, default=40, help='null runs per mount')
    ap.add_argument('--pairs', type=int, default=15)
    ap.add_argument('--triples', type=int, default=10)
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--results', help='results JSON (default OUT/results.json)')
    ap.add_argument('--no-reduction', action='store_true')
    ap.add_argument('--only', help='run only cases whose id contains this')
    a = ap.parse_args()
    if a.quick:
        a.per, a.null, a.pairs, a.triples = 1, 2, 1, 1
    os.makedirs(a.out, exist_ok=True)
    if not os.path.exists(PMFIT):
        sys.exit('missing %s: make -C %s build/pmfit' % (PMFIT, TOP))
    cases = case_list(a)
    if a.only:
        cases = [c for c in cases if a.only in c['id']]
    red_specs = []
    if not a.no_reduction:
        for s in ((1, 2) if a.quick else (1, 2, 3)):
            for mount, fmt, eqx in (('gem', 'tpoint', '-'), ('gem', 'csv', 'J2000'), ('gem', 'csv', 'JNow'),
                                    ('fork', 'tpoint', '-'), ('altaz', 'tpoint', '-')):
                red_specs.append((mount, fmt, eqx, 500 + 10 * s + len(red_specs)))
    t0 = time.time()
    results = []
    red = []
    res_path = a.results or os.path.join(a.out, 'results.json')
    print('tpoint_campaign: %d cases, %d reduction runs, %d jobs, runs in %s' % (len(cases), len(red_specs),
                                                                                  a.jobs, a.out), flush=True)
    ctx = mp.get_context('fork')
    with ctx.Pool(a.jobs) as pool:
        for r in pool.imap_unordered(reduction_case, [(s, a.out) for s in red_specs]):
            red.append(r)
        for i, r in enumerate(pool.imap_unordered(run_case, [(s, a.out) for s in cases])):
            results.append(r)
            if (i + 1) % 10 == 0 or i + 1 == len(cases):
                print('  %d/%d cases, %.0f s' % (i + 1, len(cases), time.time() - t0), flush=True)
                with open(res_path, 'w') as fh:
                    json.dump(dict(cases=results, reduction=red), fh, indent=1, default=str)
    results.sort(key=lambda r: r['id'])
    red.sort(key=lambda r: (r['mount'], r['format'], r['equinox'], r['seed']))
    with open(res_path, 'w') as fh:
        json.dump(dict(cases=results, reduction=red, seconds=time.time() - t0, args=vars(a)), fh, indent=1,
                  default=str)
    report(results, red)
    print('\nresults: %s (%.0f s)' % (res_path, time.time() - t0))


if __name__ == '__main__':
    main()
