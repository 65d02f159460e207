#!/usr/bin/python3
"""Own equatorial-mount generator (first principles gimbal). Writes named-column runs.

Written by an outside probe (Z1, stop 45) without pmfit simulate or the other
tests/ref scripts; numpy only: IH, ID, NP, CH, MA, ME as exact rotations, TF
sag, FO on forks; German mounts write flipped records with encoder Dec 90..270
(north) or -90..-270 (south).  The first line of each run is the JSON of its
arguments; tests/data/fork_decband.dat (tests/check_pmfit.c) is

    /usr/bin/python3 tests/ref/equ_gen_z1.py '{"tag": "fork_decband", "seed": 5084, "n": 200,
        "cov": "decband", "noise": 5.0, "mount": "fork", "lat": 40, "effect": "none", "mult": 0,
        "out": "tests/data/fork_decband.dat"}'
"""
import numpy as np, sys, json
AS = np.pi/180/3600
D = np.pi/180

def rotz(a):
    c,s=np.cos(a),np.sin(a); return np.array([[c,-s,0],[s,c,0],[0,0,1]])
def rotx(a):
    c,s=np.cos(a),np.sin(a); return np.array([[1,0,0],[0,c,-s],[0,s,c]])
def roty(a):
    c,s=np.cos(a),np.sin(a); return np.array([[c,0,s],[0,1,0],[-s,0,c]])

def vec(h,d):  # equatorial frame: x meridian-equator, y east, z pole ; h positive west
    return np.array([np.cos(d)*np.cos(h), -np.cos(d)*np.sin(h), np.sin(d)])
def unvec(v):
    return np.arctan2(-v[1],v[0]), np.arcsin(np.clip(v[2],-1,1))

def altaz_zen(lat):  # zenith vector in equatorial frame
    return vec(0.0, lat)

def forward(t1, t2, p, ctx):
    """encoder (t1,t2) rad -> pointed direction (unit vector), gimbal with errors p (arcsec)."""
    t1e = t1 + p['IH']*AS + ctx.get('dt1',0.0)
    t2e = t2 + p['ID']*AS + ctx.get('dt2',0.0)
    c = p['CH']*AS + ctx.get('dch',0.0)
    tube = np.array([np.cos(t2e)*np.cos(c), -np.sin(c), np.sin(t2e)*np.cos(c)])
    tube = rotx(p['NP']*AS) @ tube
    v = rotz(-t1e) @ tube
    # polar misalignment: ME tilt of polar axis in altitude (about east-west y axis), MA in azimuth (about zenith ~ use x)
    v = roty(-p['ME']*AS) @ v
    v = rotx(p['MA']*AS) @ v
    return v

def toward_zenith(v, zen, amt):
    """move unit vector v toward zenith by angle amt (rad)."""
    w = zen - np.dot(zen,v)*v; nw=np.linalg.norm(w)
    if nw<1e-12: return v
    w/=nw
    return np.cos(amt)*v + np.sin(amt)*w

def elev(v, zen): return np.arcsin(np.clip(np.dot(v,zen),-1,1))

def make_run(seed, n, cov, noise, mount, lat, effect, mult, G=144.0, phase=40.0, base=None, flipwin=15.0):
    rng = np.random.default_rng(seed)
    latr = lat*D; zen = altaz_zen(latr)
    p = dict(IH=1800.0+rng.normal(0,300), ID=-240+rng.normal(0,60), NP=rng.normal(0,40), CH=rng.normal(0,60),
             MA=rng.normal(0,120), ME=rng.normal(0,120), TF=rng.normal(0,15), FO=(rng.normal(0,10) if mount=='fork' else 0.0))
    if base: p.update(base)
    # targets
    pts=[]; tries=0
    hmin_el = 15*D
    while len(pts)<n and tries<200000:
        tries+=1
        if cov=='pole':
            d = np.arcsin(rng.uniform(np.sin(70*D),1.0)); h = rng.uniform(-np.pi,np.pi)
        elif cov=='decband':
            d = rng.uniform(20*D,30*D); h = rng.uniform(-np.pi,np.pi)
        else:
            d = np.arcsin(rng.uniform(-1,1)); h = rng.uniform(-np.pi,np.pi)
        v = vec(h,d); el = elev(v,zen)
        if cov=='lowalt':
            if not (5*D<el<25*D): continue
        else:
            if el<hmin_el: continue
        if mount=='gem':
            if cov=='oneside' and h<0.05: continue
            if abs(h)>110*D: continue  # counterweight limits
        else:
            if abs(h)>100*D: continue
        pts.append((h,d))
    pts=np.array(pts)
    n=len(pts)
    # observing order: sort by a raster (east to west through the night roughly, with dec zigzag)
    order = np.argsort(pts[:,0] + 0.3*rng.normal(size=n))[::-1]  # east first (most negative h last?) -> west
    order = order[::-1]
    pts = pts[order]
    time = 20.0 + np.linspace(0, 7.0, n) + rng.normal(0,0.01,n)
    temp = 12.0 - 6.0*(time-20)/7.0 + rng.normal(0,0.6,n)
    # pier side & encoder
    rows=[]; enc=[]
    for k,(h,d) in enumerate(pts):
        if mount=='gem':
            flip = (h < 0) if cov!='oneside' else False
            if abs(h)<flipwin*D and cov!='oneside': flip = rng.random()<0.5
        else: flip=False
        if flip:
            t1 = h + np.pi; t2 = np.pi - d
        else:
            t1 = h; t2 = d
        t1 = t1 - p['IH']*AS; t2 = t2 - (p['ID']*AS if not flip else -p['ID']*AS)
        enc.append((t1,t2,flip))
    enc=np.array(enc, dtype=float)
    t2seq = np.angle(np.exp(1j*enc[:,1]))
    # dec slew direction (mechanical, continuous through pole: use t2 in (-90,270))
    t2c = np.where(enc[:,1] < -np.pi/2, enc[:,1]+2*np.pi, enc[:,1]) if lat>=0 else np.where(enc[:,1] > np.pi/2, enc[:,1]-2*np.pi, enc[:,1])
    ddir = np.sign(np.diff(t2c, prepend=t2c[0]))
    ddir[0] = 1.0
    A = mult*noise
    truth = dict(effect=effect, amplitude=A if effect!='none' else 0.0)
    Tm = temp.mean(); tm = time.mean()
    out_idx = set()
    if effect=='outlier':
        out_idx = set(rng.choice(n, size=2, replace=False).tolist()); truth['lines_idx']=sorted(out_idx)
    if effect=='temperature':
        kT = A/np.std(temp); truth['per_unit']=kT
    if effect=='time_drift':
        kt = A/np.std(time); truth['per_unit']=kt
    recs=[]
    for k in range(n):
        t1,t2,flip = enc[k]; flip=bool(flip)
        ctx={}
        if effect=='ha_periodic': ctx['dt1'] = A*AS*np.sin(G*t1 + phase*D)
        if effect=='dec_periodic': ctx['dt2'] = A*AS*np.sin(G*t2 + phase*D)
        if effect=='pier_side' and flip: ctx['dt2'] = A*AS
        if effect=='pier_coll' and flip: ctx['dch'] = A*AS
        if effect=='temperature': ctx['dt1'] = kT*(temp[k]-Tm)*AS
        if effect=='time_drift': ctx['dt1'] = kt*(time[k]-tm)*AS
        if effect=='dec_backlash': ctx['dt2'] = A*AS*ddir[k]
        v = forward(t1,t2,p,ctx)
        el = elev(v,zen)
        # tube flexure (base TF): sag toward horizon TF*cos(el)
        v = toward_zenith(v, zen, -p['TF']*AS*np.cos(el))
        if mount=='fork':
            # FO: dec shift ~ cos h : apply along dec direction
            hh,dd = unvec(v); v = vec(hh, dd + p['FO']*AS*np.cos(hh))
        if effect=='tube_flexure': v = toward_zenith(v, zen, -A*AS*np.cos(el))
        if effect=='refraction': v = toward_zenith(v, zen, A*AS/np.tan(max(el,1*D)))
        hh,dd = unvec(v)
        hh += noise*AS*rng.normal()/np.cos(dd); dd += noise*AS*rng.normal()
        if k in out_idx:
            dd += 20*noise*AS*(1 if rng.random()<.5 else -1)
        recs.append((t1,t2,hh,dd,'W' if flip else 'E',temp[k],time[k]))
    return recs, truth, p

def write(path, recs, lat, comment, enc360=False):
    with open(path,'w') as f:
        f.write('# '+comment+'\n# latitude: %.4f\n# mount: equatorial\n# tau delta T D pier temp time\n'%lat)
        for t1,t2,hh,dd,ps,T,t in recs:
            a1=np.degrees(t1); a2=np.degrees(t2)
            a1 = (a1+180)%360-180
            a2 = a2 if a2<=270 else a2-360
            if lat<0 and a2>90: a2-=360
            if a2>180 and not enc360: pass  # keep >180 readings as real mounts (e.g. 194 deg)
            if enc360: a1 = a1%360
            f.write('%.8f %.8f %.8f %.8f %s %.2f %.5f\n'%(a1,a2,np.degrees(hh),np.degrees(dd),ps,T,t))

if __name__=='__main__':
    a=json.loads(sys.argv[1])
    recs,truth,p = make_run(a['seed'],a['n'],a['cov'],a['noise'],a['mount'],a['lat'],a['effect'],a['mult'],a.get('G',144.0),a.get('phase',40.0))
    write(a['out'],recs,a['lat'],json.dumps(a),a.get('enc360',False))
    print(json.dumps(dict(truth=truth,base=p,n=len(recs))))
