#!/usr/bin/python3
"""Own alt-az pointing-run generator (first principles, TPOINT-like classical terms).
All angles in degrees in files; arcsec for model terms.
enc = true + classical terms + effect + noise;  file: tau delta (encoder)  T D (observed).

Written by an outside probe (Z2, stop 45) without pmfit simulate or the other
tests/ref scripts; numpy only.  The azimuth is written as the mount's count
in -270..270 (a cable wrap).  Its sag TF = 6" is encoder minus true, so the
tool reads about -6" (a sag toward the horizon is negative).

    /usr/bin/python3 tests/ref/altaz_gen_z2.py

writes tests/data/altaz_lowband_sag.dat (seed 3338: 40 stars at elevations
10-35 deg, noise 15", no effect beyond the base terms), altaz_cable_drag.dat
and altaz_cable_step.dat (below), which tests/check_pmfit.c reads.  Before stop 45 explain read "tube flexure held by
the order-1 terms: 3026.37\" +- 85.55\"" from it."""
import numpy as np

AS = 1.0 / 3600.0
D2R = np.pi / 180

COVER = {
    'full': (0, 360, 15, 80),
    'half': (0, 180, 15, 80),     # east half
    'high': (0, 360, 50, 80),
    'low':  (0, 360, 10, 35),
}


def sky(rng, n, cover):
    a0, a1, e0, e1 = COVER[cover]
    A = rng.uniform(a0, a1, n)
    # uniform on the sphere in the band
    s = rng.uniform(np.sin(e0 * D2R), np.sin(e1 * D2R), n)
    E = np.arcsin(s) / D2R
    return A % 360, E


def counts(A, lo=-270.0, hi=270.0):
    """azimuth count chosen nearest to the previous one within the wrap limits"""
    c = np.empty_like(A)
    prev = 0.0
    for k, a in enumerate(A):
        cands = [a + 360 * t for t in range(-2, 3) if lo <= a + 360 * t <= hi]
        best = min(cands, key=lambda x: abs(x - prev))
        c[k] = best
        prev = best
    return c


def make(seed, n, cover, noise, effect='none', amp=0.0, G=None, azwrite='count',
         lat=31.7, temp_mode='wiggle', base=None, step_at=0.0):
    rng = np.random.default_rng(seed)
    A, E = sky(rng, n, cover)
    cnt = counts(A) if azwrite == 'count' else A.copy()
    if azwrite == 'm180':
        cnt = ((A + 180) % 360) - 180
    # times (h), temperature
    span = max(1.0, n * 2.0 / 60.0)
    t = np.sort(rng.uniform(0, span, n)) + 20.0
    tt = t - t[0]
    if temp_mode == 'wiggle':
        temp = 12 - 4 * tt / span + 2.5 * np.sin(2 * np.pi * tt / (0.6 * span)) + rng.normal(0, 0.2, n)
    else:
        temp = 12 - 6 * tt / span + rng.normal(0, 0.05, n)
    b = dict(IA=95.0, IE=-48.0, CA=35.0, NPAE=-18.0, AN=22.0, AW=-15.0, TF=6.0)
    if base:
        b.update(base)
    Ar, Er = A * D2R, E * D2R
    dA = b['IA'] + b['CA'] / np.cos(Er) + b['NPAE'] * np.tan(Er) \
        + b['AN'] * np.sin(Ar) * np.tan(Er) - b['AW'] * np.cos(Ar) * np.tan(Er)
    dE = b['IE'] + b['AN'] * np.cos(Ar) + b['AW'] * np.sin(Ar) + b['TF'] * np.cos(Er)
    # direction of the last azimuth move (on the count)
    dirs = np.sign(np.diff(np.concatenate([[cnt[0] - 1.0], cnt])))
    ph = rng.uniform(0, 2 * np.pi)
    truth = {}
    out_line = None
    if effect == 'azper':
        dA = dA + amp * np.cos(G * Ar + ph)
    elif effect == 'elper':
        dE = dE + amp * np.cos(G * Er + ph)
    elif effect == 'drag':
        dA = dA + amp * cnt / 270.0
    elif effect == 'step':
        dA = dA + amp * (cnt > step_at)
    elif effect == 'flex':
        dE = dE + amp * np.cos(Er)
    elif effect == 'refr':      # observed places given without refraction / wrong scale
        dE = dE + amp / np.tan(Er)
    elif effect == 'tempIE':    # amp = arcsec per degC
        dE = dE + amp * (temp - temp.mean())
    elif effect == 'drift':     # amp = arcsec per hour, azimuth axis (on the sky)
        dA = dA + amp * (tt - tt.mean()) / np.cos(Er)
    elif effect == 'driftax':   # amp = arcsec per hour on the azimuth AXIS angle
        dA = dA + amp * (tt - tt.mean())
    elif effect == 'tempIEax':
        dE = dE + amp * (temp - temp.mean())
    elif effect == 'backlash':
        dA = dA + amp * dirs
    elif effect == 'outlier':
        k = n // 2
        ang = rng.uniform(0, 2 * np.pi)
        dA[k] += amp * np.cos(ang) / np.cos(Er[k])
        dE[k] += amp * np.sin(ang)
        out_line = k
    # noise (on the sky)
    dA = dA + rng.normal(0, noise, n) / np.cos(Er)
    dE = dE + rng.normal(0, noise, n)
    encA = cnt + dA * AS
    encE = E + dE * AS
    return dict(A=A, E=E, encA=encA, encE=encE, temp=temp, t=t, out_k=out_line, lat=lat)


def write(path, r, cols='temp time'):
    with open(path, 'w') as f:
        f.write('# probeZ2 synthetic alt-az run\n')
        f.write('# latitude: %.4f\n' % r['lat'])
        f.write('# mount: altaz\n')
        f.write('# tau delta T D %s\n' % cols)
        for i in range(len(r['A'])):
            extra = ''
            if 'temp' in cols:
                extra += ' %.2f' % r['temp'][i]
            if 'time' in cols:
                extra += ' %.5f' % r['t'][i]
            f.write('%.7f %.7f %.7f %.7f%s\n' % (r['encA'][i], r['encE'][i], r['A'][i], r['E'][i], extra))
    # header lines = 4, so record i is on file line 5 + i


if __name__ == '__main__':
    import os
    top = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'data')
    write(os.path.join(top, 'altaz_lowband_sag.dat'), make(3338, 40, 'low', 15.0))
    # a cable's drag of 50" * count / 270 deg (66.7" a turn) and a 25" step
    # past count 0, 80 stars, 5" noise (tests/check_pmfit.c)
    write(os.path.join(top, 'altaz_cable_drag.dat'), make(4242, 80, 'full', 5.0, effect='drag', amp=50.0))
    write(os.path.join(top, 'altaz_cable_step.dat'), make(4243, 80, 'full', 5.0, effect='step', amp=25.0))
