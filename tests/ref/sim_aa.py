# Own first-principles pointing-run generator (outside probe AA, stop 45; numpy only,
# written without the library's simulator). Angles in degrees in files.
import numpy as np
D2R=np.pi/180; AS=D2R/3600
def sky(n, rng, lat, elmin=15, elmax=89, decband=None, haband=None, azband=None):
    """uniform directions above elmin; return (h,d,az,el) degrees (az N through E, h west +)."""
    out=[]
    phi=lat*D2R
    while len(out)<n:
        z=rng.uniform(np.sin(elmin*D2R), np.sin(elmax*D2R)); el=np.arcsin(z); az=rng.uniform(0,2*np.pi)
        # az,el -> h,d
        sd=np.sin(phi)*np.sin(el)+np.cos(phi)*np.cos(el)*np.cos(az); d=np.arcsin(sd)
        h=np.arctan2(-np.sin(az)*np.cos(el), np.cos(phi)*np.sin(el)-np.sin(phi)*np.cos(el)*np.cos(az))
        H,Dd,A,E=h/D2R,d/D2R,az/D2R,el/D2R
        if decband and not (decband[0]<=Dd<=decband[1]): continue
        if haband and not (haband[0]<=H<=haband[1]): continue
        if azband and not (azband[0]<=A<=azband[1]): continue
        out.append((H,Dd,A,E))
    return np.array(out)
def hd2azel(h,d,lat):
    h,d,phi=h*D2R,d*D2R,lat*D2R
    se=np.sin(phi)*np.sin(d)+np.cos(phi)*np.cos(d)*np.cos(h); el=np.arcsin(se)
    az=np.arctan2(-np.cos(d)*np.sin(h), np.sin(d)*np.cos(phi)-np.cos(d)*np.cos(h)*np.sin(phi))
    return (az/D2R)%360, el/D2R
def equ_run(h,d,lat,rng,noise=1.0,pier=None,IH=0,ID=0,CH=0,NP=0,MA=0,ME=0,TF=0,
            aniso=None,worm_ha=None,worm_dec=None,extra=None):
    """h,d true apparent (deg). pier: array +1/-1 (German) or None (fork: all +1).
    Classic TPOINT-like terms (arcsec). enc = true + delta. Returns tau,delta,T,D,pier."""
    n=len(h); p=np.ones(n) if pier is None else np.asarray(pier,float)
    hr,dr=h*D2R,d*D2R
    az,el=hd2azel(h,d,lat); elr=el*D2R; phi=lat*D2R
    dh=IH + p*CH/np.cos(dr) + p*NP*np.tan(dr) - MA*np.cos(hr)*np.tan(dr) + ME*np.sin(hr)*np.tan(dr)
    dd=p*ID + MA*np.sin(hr) + ME*np.cos(hr)
    # tube flexure: toward zenith by TF cos(el): components along -d? parallactic
    q=np.arctan2(np.sin(hr), np.tan(phi)*np.cos(dr)-np.sin(dr)*np.cos(hr))  # parallactic angle
    # zenith direction on sky: along +dec by cos q, along -ha(i.e. east) ... displacement toward zenith
    sag=TF*np.cos(elr)
    dd=dd+ sag*np.cos(q)
    dh=dh- sag*np.sin(q)/np.cos(dr)
    if aniso is not None: # callable returning (dh_on_sky, dd) arcsec
        a,b=aniso(hr,dr); dh=dh+a/np.cos(dr); dd=dd+b
    if extra is not None:
        a,b=extra(hr,dr,p); dh=dh+a/np.cos(dr); dd=dd+b
    dh=dh+noise*rng.standard_normal(n)/np.cos(dr); dd=dd+noise*rng.standard_normal(n)
    tau=h+dh/3600; dl=d+dd/3600
    # pier west: beyond the pole
    w=p<0
    tau=np.where(w,tau+180,tau); dl=np.where(w,180-dl,dl)
    # worm: a function of the encoder (mechanical) angle
    if worm_ha: A,G,ph=worm_ha; tau=tau+A/3600*np.sin(G*tau*D2R+ph)
    if worm_dec: A,G,ph=worm_dec; dl=dl+A/3600*np.sin(G*dl*D2R+ph)
    tau=(tau+180)%360-180
    return tau,dl,h,d,p
def altaz_run(az,el,rng,noise=1.0,IA=0,IE=0,CA=0,NPAE=0,AN=0,AW=0,TF=0,aniso=None,worm_az=None,worm_el=None):
    azr,elr=az*D2R,el*D2R
    da=IA + CA/np.cos(elr) + NPAE*np.tan(elr) + (AN*np.sin(azr)+AW*np.cos(azr))*np.tan(elr)  # on axis
    de=IE + TF*np.cos(elr) + AN*np.cos(azr) - AW*np.sin(azr)
    if aniso is not None:
        a,b=aniso(azr,elr); da=da+a/np.cos(elr); de=de+b
    da=da+noise*rng.standard_normal(len(az))/np.cos(elr); de=de+noise*rng.standard_normal(len(az))
    A=az+da/3600; E=el+de/3600
    if worm_az: a,G,ph=worm_az; A=A+a/3600*np.sin(G*A*D2R+ph)
    if worm_el: a,G,ph=worm_el; E=E+a/3600*np.sin(G*E*D2R+ph)
    return A%360,E,az,el
def write_equ(path,lat,tau,dl,T,D,pier=None):
    with open(path,'w') as f:
        f.write(f"# probeAA own sim\n# latitude: {lat}\n# mount: equatorial\n")
        if pier is None:
            f.write("# tau delta T D\n")
            for r in zip(tau,dl,T,D): f.write("%.7f %.7f %.7f %.7f\n"%r)
        else:
            f.write("# tau delta T D pier\n")
            for a,b,c,e,p in zip(tau,dl,T,D,pier): f.write("%.7f %.7f %.7f %.7f %s\n"%(a,b,c,e,'E' if p>0 else 'W'))
def write_altaz(path,lat,A,E,az,el):
    with open(path,'w') as f:
        f.write(f"# probeAA own sim\n# latitude: {lat}\n# mount: altaz\n# tau delta T D\n")
        for r in zip(A,E,az,el): f.write("%.7f %.7f %.7f %.7f\n"%r)
def gem_pier(h):  # normal side looking west (h>0) : pier East(+1)? ASCOM: normal = pierEast, looking west
    return np.where(h>0,1,-1)
