#!/usr/bin/python3
# An alt-az run from an outside probe's own generator (Y, stop 44), numpy only: a mount
# that slews the short way round or never through the file's seam (its count),
# with backlash, a periodic azimuth error, flexure and noise.  tests/data/altaz_count_pe.dat:
#   /usr/bin/python3 tests/ref/altaz_gen_y.py tests/data/altaz_count_pe.dat \
#     '{"n":300,"seed":5075,"mount":"count","backlash":5.0,"pe":20.0,"pecyc":2,"noise":0.5,"wrap":"360"}'
# tests/data/altaz_short_backlash.dat: the same with
#     '{"n":120,"seed":5036,"mount":"short","backlash":5.0,"pecyc":2,"flex":5.0,"noise":0.5,"wrap":"360"}'
import numpy as np, sys, json
def gen(path, n, seed, mount='short', backlash=0.0, pe=0.0, pecyc=1, flex=0.0, noise=1.0,
        wrap='360', order='random', lat=40.0, g=None):
    rng = np.random.default_rng(seed)
    AS = 1/3600.0
    # commanded (encoder) positions
    az = rng.uniform(0, 360, n); el = np.degrees(np.arcsin(rng.uniform(np.sin(np.radians(15)), np.sin(np.radians(85)), n)))
    if order == 'sweep':
        idx = np.argsort(az); az, el = az[idx], el[idx]
    # encoder az as written
    if wrap == '360':
        wa = az % 360.0   # stop at north for count mounts
    else:
        wa = (az + 180) % 360 - 180  # stop at south
    # slew direction on axis 1
    s = np.zeros(n)
    s[0] = 1.0
    for k in range(1, n):
        d = wa[k] - wa[k-1]
        if mount == 'short':
            d = (d + 180) % 360 - 180
        s[k] = 1.0 if d > 0 else -1.0
    # gimbal terms (arcsec): IA, IE, CA, NPAE, AN, AW
    IA, IE, CA, NPAE, AN, AW = rng.normal(0, 60, 6)
    if g is not None: IA, IE, CA, NPAE, AN, AW = g
    phi = rng.uniform(0, 2*np.pi)
    A = np.radians(wa); E = np.radians(el)
    dA = (IA + CA/np.cos(E) + NPAE*np.tan(E) + (AN*np.sin(A) - AW*np.cos(A))*np.tan(E)
          + backlash*s + pe*np.sin(pecyc*A + phi))  # on the axis (arcsec)
    dE = (IE + flex*np.cos(E) + AN*np.cos(A) + AW*np.sin(A))
    dA = dA + rng.normal(0, noise, n)/np.cos(E)
    dE = dE + rng.normal(0, noise, n)
    T = wa + dA*AS; D = el + dE*AS
    T = T % 360.0 if wrap == '360' else (T + 180) % 360 - 180
    meta = dict(n=n, seed=seed, mount=mount, backlash=backlash, pe=pe, pecyc=pecyc, flex=flex,
                noise=noise, wrap=wrap, order=order, g=g)
    with open(path, 'w') as f:
        f.write('# probeY generator ' + json.dumps(meta) + '\n')
        f.write('# latitude: %.6f\n# mount: altaz\n# tau delta T D\n' % lat)
        for a, e, t, d in zip(wa, el, T, D):
            f.write('%.9f %.9f %.9f %.9f\n' % (a, e, t, d))
if __name__ == '__main__':
    kw = json.loads(sys.argv[2]); gen(sys.argv[1], **kw)
