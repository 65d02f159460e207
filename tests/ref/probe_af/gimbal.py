#!/usr/bin/python3
"""Independent first-principles equatorial gimbal (probe AF). Writes named-column runs.
usage: gimbal.py OUT --seed S --n N --noise ARCSEC --lat DEG --mount gem|fork --zone DEG
   [--aniso ARCSEC] [--daf ARCSEC] [--dcol ARCSEC] [--did ARCSEC] [--polar ARCSEC]
   [--sag ARCSEC] [--refr ARCSEC] [--ih DEG] [--id DEG] [--ch ARCSEC] [--np ARCSEC]
 truth (library sense): tube_flexure = sag, refraction = refr, pier step: collimation dcol on
 W side, decl. zero-point step did on W side (true-minus-encoder)."""
import argparse, json, numpy as np
AS = np.pi/180/3600
ap = argparse.ArgumentParser()
ap.add_argument('out'); ap.add_argument('--seed', type=int, default=1)
ap.add_argument('--n', type=int, default=100); ap.add_argument('--noise', type=float, default=1.0)
ap.add_argument('--lat', type=float, default=47.0); ap.add_argument('--mount', default='gem')
ap.add_argument('--zone', type=float, default=0.0)
for k in ['aniso','daf','dcol','did','polar','sag','refr','ch','np']:
    ap.add_argument('--'+k, type=float, default=0.0)
ap.add_argument('--ih', type=float, default=0.0); ap.add_argument('--id', type=float, default=0.0)
ap.add_argument('--minel', type=float, default=15.0)
A = ap.parse_args()
rng = np.random.default_rng(A.seed)
phi = np.radians(A.lat)
def Rx(a):
    c,s=np.cos(a),np.sin(a); return np.array([[1,0,0],[0,c,-s],[0,s,c]])
def Ry(a):  # maps x -> (cos a, 0, sin a)
    c,s=np.cos(a),np.sin(a); return np.array([[c,0,-s],[0,1,0],[s,0,c]])
def Rz(a):
    c,s=np.cos(a),np.sin(a); return np.array([[c,-s,0],[s,c,0],[0,0,1]])
# random gimbal pieces
pa, pb = (rng.normal(size=2)*A.polar*AS) if A.polar else (0.0,0.0)
H = Rx(pa) @ Ry(pb)
# generic smooth distortions of mechanical axis angles and collimation: order-1 harmonics
# of the mechanical position, amplitude ~ aniso
cA = rng.normal(size=(3,3))*A.aniso*AS/np.sqrt(3)
def Y1(t,d): return np.array([np.sin(d), np.cos(d)*np.cos(t), np.cos(d)*np.sin(t)])
ZEN = np.array([np.cos(phi),0,np.sin(phi)])
def point(te, de, west):
    tm = te + np.radians(A.ih); dm = de + np.radians(A.id)
    y = Y1(tm, dm)
    tm2 = tm + cA[0]@y / max(np.cos(dm)**0,1)  # hour-angle axis angle error
    dm2 = dm + cA[1]@y + (A.did*AS if west else 0)
    ci = A.ch*AS + cA[2]@y + (A.dcol*AS if west else 0)
    d = A.np*AS + A.daf*AS*np.cos(tm)        # dec-axis flexure ~ cos(HA mech)
    v0 = np.array([np.cos(ci), np.sin(ci), 0.0])
    p = H @ Rz(tm2) @ Rx(d) @ Ry(dm2) @ v0
    # zenith-ward displacements
    sel = p@ZEN
    zt = ZEN - sel*p; nz = np.linalg.norm(zt)
    if nz > 0: zt /= nz
    cel = np.sqrt(max(0,1-sel**2))
    disp = A.sag*AS*cel + A.refr*AS*cel/max(sel,0.01)
    p = p*np.cos(disp) + zt*np.sin(disp)
    return p/np.linalg.norm(p)
rows=[]
while len(rows) < A.n:
    # uniform on visible sphere above minel
    z = rng.uniform(-1,1); az = rng.uniform(0,2*np.pi)
    v = np.array([np.sqrt(1-z*z)*np.cos(az), np.sqrt(1-z*z)*np.sin(az), z])  # horizon frame: x=N? use eq directly
    # take v as equatorial direction in p(tau,dec) frame
    if v@ZEN < np.sin(np.radians(A.minel)): continue
    ha = np.arctan2(v[1], v[0]); dec = np.arcsin(v[2])
    if A.mount == 'gem':
        z0 = np.radians(A.zone)
        if ha > z0: west = False
        elif ha < -z0: west = True
        else: west = rng.random() < 0.5
    else: west = False
    if west:
        te = ha + np.pi; de = (np.pi - dec) if A.lat >= 0 else (-np.pi - dec)
    else:
        te, de = ha, dec
    te -= np.radians(A.ih); de -= np.radians(A.id) * (1 if not west else 1)
    p = point(te, de, west)
    # noise on sky
    D = np.arcsin(np.clip(p[2],-1,1)); T = np.arctan2(p[1],p[0])
    D += rng.normal()*A.noise*AS; T += rng.normal()*A.noise*AS/np.cos(D)
    rows.append((np.degrees(te), np.degrees(de), np.degrees(T), np.degrees(D), 'W' if west else 'E'))
with open(A.out,'w') as f:
    f.write('# probeAF gimbal ' + json.dumps(vars(A)) + '\n')
    f.write(f'# latitude: {A.lat:.4f}\n# mount: equatorial\n# tau delta T D pier\n')
    for r in rows:
        te = (r[0]+180)%360-180
        f.write(f'{te:.8f} {r[1]:.8f} {r[2]:.8f} {r[3]:.8f} {r[4]}\n')
