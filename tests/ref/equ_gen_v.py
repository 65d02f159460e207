#!/usr/bin/python3
# An equatorial run (four columns, degrees) from an outside probe's own
# gimbal (V, stop 44), numpy only: German (flipping at --flipat), fork, or a
# German mount that never flips (gem1), written with its axes, folded to the
# sky, or folded with a pier column; to stdout.  tests/data/gem_oneside_balstep.dat:
#   /usr/bin/python3 tests/ref/equ_gen_v.py --seed 201 --mount gem1 --balstep 10
# independent equatorial generator: GEM (flip) / fork, written as mount axes, folded, or with pier column
import numpy as np, argparse, sys
ap = argparse.ArgumentParser()
ap.add_argument('--n', type=int, default=60)
ap.add_argument('--seed', type=int, default=1)
ap.add_argument('--lat', type=float, default=45)
ap.add_argument('--mount', default='gem')   # gem | fork | gem1 (one side, no flip)
ap.add_argument('--write', default='axes')  # axes | folded | piercol (folded + W column) | piercol_axes
ap.add_argument('--noise', type=float, default=1.0)
ap.add_argument('--ch', type=float, default=None)
ap.add_argument('--id', type=float, default=None)
ap.add_argument('--hamax', type=float, default=90)  # |HA| max deg
ap.add_argument('--hamin', type=float, default=0)   # |HA| min deg
ap.add_argument('--elmin', type=float, default=20)
ap.add_argument('--flipat', type=float, default=0)  # HA (deg) where the GEM flips (west side beyond pole for HA>flipat)
ap.add_argument('--hyst', type=float, default=0)    # HA backlash arcsec
ap.add_argument('--hyst_dec', type=float, default=0)
ap.add_argument('--order', default='random')        # random | alt (alternate E/W) | sweep (HA ascending)
ap.add_argument('--pe', type=float, default=0)
ap.add_argument('--peG', type=float, default=2)
ap.add_argument('--flex', type=float, default=0)    # HA-axis flexure sin(HA) in dec, odd in HA: flex*sin(H)*cos(lat)
ap.add_argument('--polflex', type=float, default=0) # sign(HA)-like smooth: flex tanh(H/10deg)
ap.add_argument('--tmp', type=float, default=0)
ap.add_argument("--balstep", type=float, default=0)  # HA worm flank change at meridian (one-sided balance reversal)
a = ap.parse_args()
r = np.random.default_rng(a.seed)
AS = 1/3600.; D = np.radians; phi = D(a.lat)
H = []; De = []
while len(H) < a.n:
    h = r.uniform(-a.hamax, a.hamax)
    if abs(h) < a.hamin: continue
    d = np.degrees(np.arcsin(r.uniform(-1, 1)))
    el = np.degrees(np.arcsin(np.sin(phi)*np.sin(D(d)) + np.cos(phi)*np.cos(D(d))*np.cos(D(h))))
    if el < a.elmin: continue
    H.append(h); De.append(d)
H = np.array(H); De = np.array(De)
if a.order == 'alt':
    e = [i for i in range(a.n) if H[i] < 0]; w = [i for i in range(a.n) if H[i] >= 0]
    idx = []
    while e or w:
        if e: idx.append(e.pop())
        if w: idx.append(w.pop())
    H, De = H[idx], De[idx]
elif a.order == 'sweep':
    idx = np.argsort(H); H, De = H[idx], De[idx]
n = a.n
IH, ID, CH, NP, MA, ME, TF = [r.normal(0, s) for s in (200, 150, 40, 20, 60, 60, 10)]
if a.ch is not None: CH = a.ch
if a.id is not None: ID = a.id
flip = (a.mount == 'gem') & (H > a.flipat)
Hm = np.where(flip, H - 180, H); Dm = np.where(flip, 180 - De, De)
# direction of axis moves (in mech angles)
dH = np.zeros(n); dH[1:] = np.sign(np.diff(Hm)); dD = np.zeros(n); dD[1:] = np.sign(np.diff(Dm))
h = D(Hm); d = D(Dm)
el = np.arcsin(np.sin(phi)*np.sin(D(De)) + np.cos(phi)*np.cos(D(De))*np.cos(D(H)))
# encoder minus sky in mech coords (TPOINT-like, arcsec)
eh = (IH + CH/np.cos(d) + NP*np.tan(d) - MA*np.cos(h)*np.tan(d) + ME*np.sin(h)*np.tan(d)
      + a.hyst*dH + a.pe*np.sin(a.peG*h + 0.3) + a.balstep*np.sign(H))
ed = (ID + MA*np.sin(h) + ME*np.cos(h) + TF*(np.cos(phi)*np.cos(h)*np.sin(d) - np.sin(phi)*np.cos(d))
      + a.hyst_dec*dD + a.flex*np.sin(D(H)) + a.polflex*np.tanh(D(H)/D(10)))
eh = eh + r.normal(0, a.noise, n)/np.cos(d); ed = ed + r.normal(0, a.noise, n)
encH = Hm + eh*AS; encD = Dm + ed*AS
print('# latitude: %.3f' % a.lat)
w = a.write
if w in ('folded', 'piercol'):
    fH = np.where(flip, encH + 180, encH); fD = np.where(flip, 180 - encD, encD)
else:
    fH, fD = encH, encD
if w.startswith('piercol'):
    print('# tau delta T D pier')
    for i in range(n): print('%.6f %.6f %.6f %.6f %s' % (fH[i], fD[i], H[i], De[i], 'W' if flip[i] else 'E'))
else:
    print('# tau delta T D')
    for i in range(n): print('%.6f %.6f %.6f %.6f' % (fH[i], fD[i], H[i], De[i]))
sys.stderr.write('flipped %d of %d CH %.1f ID %.1f\n' % (flip.sum(), n, CH, ID))
