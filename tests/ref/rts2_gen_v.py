#!/usr/bin/python3
# An RTS2 gpoint file from ERFA, written by an outside probe (V, stop 44)
# without the library: true places of date (atci13) or J2000, the mount at
# the refracted place (atco13) with its own errors and noise; to stdout.
# tests/data/rts2_jnow_short.dat, a 6-minute run of places of date:
#   /usr/bin/python3 tests/ref/rts2_gen_v.py --hours 0.1 --seed 1 --n 30
import numpy as np, erfa, argparse, sys
ap = argparse.ArgumentParser()
ap.add_argument('--n', type=int, default=40)
ap.add_argument('--seed', type=int, default=1)
ap.add_argument('--lat', type=float, default=47.0)
ap.add_argument('--lon', type=float, default=19.0)
ap.add_argument('--alt', type=float, default=500.0)
ap.add_argument('--hours', type=float, default=2.0)
ap.add_argument('--mjd0', type=float, default=60384.83)
ap.add_argument('--truth', default='jnow')   # jnow | j2000
ap.add_argument('--refr', type=int, default=1)  # mount points at refracted place
ap.add_argument('--noise', type=float, default=2.0)
ap.add_argument('--err', type=float, default=1.0)  # scale of mount errors
ap.add_argument('--elmin', type=float, default=20)
ap.add_argument('--press', type=float, default=None)
a = ap.parse_args()
r = np.random.default_rng(a.seed)
lat = np.radians(a.lat); lon = np.radians(a.lon)
press = a.press if a.press is not None else 1013.25*np.exp(-a.alt/8000)
IH, ID, NP, CH, MA, ME = [r.normal(0, s*a.err) for s in (300, 200, 40, 60, 120, 120)]
out = []
i = 0
while len(out) < a.n:
    mjd = a.mjd0 + a.hours/24*len(out)/max(a.n-1, 1)
    ra = r.uniform(0, 2*np.pi); dec = np.arcsin(r.uniform(-1, 1))
    ut1 = mjd  # dut1 = 0
    aob, zob, hob, dob, rob, eo = erfa.atco13(ra, dec, 0, 0, 0, 0, 2400000.5, mjd, 0.0, lon, lat, a.alt, 0, 0,
                                             press if a.refr else 0.0, 10.0, 0.5, 0.55)
    if 90 - np.degrees(zob) < a.elmin: continue
    ri, di, eo2 = erfa.atci13(ra, dec, 0, 0, 0, 0, 2400000.5, mjd)
    era = erfa.era00(2400000.5, ut1)
    last = era + lon - eo2
    if a.truth == 'jnow':
        tra, tdec = ri - eo2, di
    else:
        tra, tdec = ra, dec
    h, d = hob, dob
    eh = (IH + CH/np.cos(d) + NP*np.tan(d) - MA*np.cos(h)*np.tan(d) + ME*np.sin(h)*np.tan(d)) + r.normal(0, a.noise)/np.cos(d)
    ed = (ID + MA*np.sin(h) + ME*np.cos(h)) + r.normal(0, a.noise)
    encH = h + np.radians(eh/3600); encD = d + np.radians(ed/3600)
    mra = last - encH
    out.append((mjd, np.degrees(last) % 360, np.degrees(mra) % 360, np.degrees(encD), np.degrees(tra) % 360, np.degrees(tdec)))
print('#  Observation\t  MJD\t   LST-MNT RA-MNT   DEC-MNT   AXRA\t  AXDEC   RA-TRUE  DEC-TRUE')
print('#observatory %.4f %.4f %.1f' % (a.lon, a.lat, a.alt))
for k, (mjd, lst, mra, md, tra, td) in enumerate(out):
    print('img%04d %.8f %.7f %.9f %.9f %d %d %.9f %.9f' % (k, mjd, lst, mra, md, 0, 0, tra, td))
