# Independent mount simulator (first principles, small-angle TPOINT-like terms).
# Written by an outside probe (Z3, stop 45) without the library's simulator; table.py runs it.
import numpy as np
AS = np.pi/180/3600
D = np.pi/180

class GEM:
    """Equatorial German mount. Truth terms in arcsec. Encoder->sky mapping.
    ASCOM convention: normal side (enc dec within +-90) looking west (HA>0)."""
    mount = 'equatorial'
    def __init__(s, lat, IH=0, ID=0, CH=0, NP=0, MA=0, ME=0, TF=0, PE=0, PEG=2, PEph=0.0, DPE=0, DPEG=2):
        s.lat = lat; s.t = dict(IH=IH, ID=ID, CH=CH, NP=NP, MA=MA, ME=ME, TF=TF, PE=PE, DPE=DPE)
        s.PEG = PEG; s.PEph = PEph; s.DPEG = DPEG
    def delta(s, tau, dec):
        # tau, dec: encoder (degrees).  returns sky (h, d) nominal + errors (deg)
        t = s.t
        side = np.where(np.cos(dec*D) >= 0, 1.0, -1.0)
        h0 = np.where(side > 0, tau, tau-180.0); d0 = np.where(side > 0, dec, 180.0-dec)
        h0r, d0r, dr = h0*D, d0*D, dec*D
        phi = s.lat*D
        dh = (t['IH'] + t['CH']/np.cos(dr) + t['NP']*np.tan(dr)
              - t['MA']*np.cos(h0r)*np.tan(d0r) + t['ME']*np.sin(h0r)*np.tan(d0r)
              + t['TF']*np.cos(phi)*np.sin(h0r)/np.cos(d0r)
              + t['PE']*np.sin(s.PEG*tau*D + s.PEph*D))
        dd = (side*t['ID'] + t['MA']*np.sin(h0r) + t['ME']*np.cos(h0r)
              + t['TF']*(np.cos(phi)*np.cos(h0r)*np.sin(d0r) - np.sin(phi)*np.cos(d0r))
              + side*t['DPE']*np.sin(s.DPEG*dec*D))
        return h0 + dh/3600.0, d0 + dd/3600.0, side
    def observe(s, h, d, side, noise, rng):
        """star at apparent (h,d), on pier side; returns encoder tau, dec, and measured apparent."""
        h = np.asarray(h, float); d = np.asarray(d, float); side = np.asarray(side, float)
        tau = np.where(side > 0, h, h+180.0); dec = np.where(side > 0, d, 180.0-d)
        for _ in range(8):
            hh, dd, _ = s.delta(tau, dec)
            eh = ((h - hh + 180) % 360) - 180; ed = d - dd
            tau = tau + eh; dec = dec + np.where(side > 0, ed, -ed)
        n = h.shape
        T = h + rng.normal(0, noise, n)/3600/np.cos(d*D); Dd = d + rng.normal(0, noise, n)/3600
        return tau, dec, T, Dd

class AltAz:
    mount = 'altaz'
    def __init__(s, lat, IA=0, IE=0, CA=0, NPAE=0, AN=0, AW=0, TF=0, PE=0, PEG=2, PEph=0.0):
        s.lat = lat; s.t = dict(IA=IA, IE=IE, CA=CA, NPAE=NPAE, AN=AN, AW=AW, TF=TF, PE=PE); s.PEG = PEG; s.PEph = PEph
    def delta(s, A, E):
        t = s.t; Ar, Er = A*D, E*D
        dA = (t['IA'] + t['CA']/np.cos(Er) + t['NPAE']*np.tan(Er)
              - (t['AN']*np.cos(Ar) + t['AW']*np.sin(Ar))*np.tan(Er)
              + t['PE']*np.sin(s.PEG*Ar + s.PEph*D))
        dE = t['IE'] + t['AN']*np.sin(Ar) - t['AW']*np.cos(Ar) + t['TF']*np.cos(Er)
        return A + dA/3600, E + dE/3600, np.zeros_like(A)
    def observe(s, A, E, side, noise, rng):
        A = np.asarray(A, float); E = np.asarray(E, float)
        a, e = A.copy(), E.copy()
        for _ in range(8):
            aa, ee, _ = s.delta(a, e)
            a = a + (((A-aa+180) % 360) - 180); e = e + (E-ee)
        n = A.shape
        return a, e, A + rng.normal(0, noise, n)/3600/np.cos(E*D), E + rng.normal(0, noise, n)/3600

def hadec_to_altaz(h, d, lat):
    h, d, p = h*D, d*D, lat*D
    se = np.sin(p)*np.sin(d) + np.cos(p)*np.cos(d)*np.cos(h)
    E = np.arcsin(np.clip(se, -1, 1))
    # azimuth north through east
    y = -np.cos(d)*np.sin(h); x = np.sin(d)*np.cos(p) - np.cos(d)*np.cos(h)*np.sin(p)
    A = np.arctan2(y, x) % (2*np.pi)
    return A/D, E/D

def altaz_to_hadec(A, E, lat):
    A, E, p = A*D, E*D, lat*D
    sd = np.sin(p)*np.sin(E) + np.cos(p)*np.cos(E)*np.cos(A)
    d = np.arcsin(np.clip(sd, -1, 1))
    y = -np.cos(E)*np.sin(A); x = np.sin(E)*np.cos(p) - np.cos(E)*np.cos(A)*np.sin(p)
    h = np.arctan2(y, x)
    return h/D, d/D

def sky_points(n, lat, minel=15, maxel=90, rng=None, horizon=None):
    """uniform on the sphere above minel (and horizon function of az)."""
    out = []
    while sum(len(o) for o in out) < n:
        m = 4*n
        z = rng.uniform(np.sin(minel*D), np.sin(maxel*D), m); A = rng.uniform(0, 360, m)
        E = np.arcsin(z)/D
        ok = np.ones(m, bool) if horizon is None else E > horizon(A)
        out.append(np.c_[A[ok], E[ok]])
    P = np.vstack(out)[:n]
    return P[:, 0], P[:, 1]

def meridian_side(h):
    h = ((np.asarray(h) + 180) % 360) - 180
    return np.where(h >= 0, 1.0, -1.0)

def write_run(path, mount, tau, dec, T, Dd, header=''):
    with open(path, 'w') as f:
        if header: f.write(header)
        f.write('# latitude: %.6f\n# mount: %s\n# tau delta T D\n' % (mount.lat, mount.mount))
        for a, b, c, e in zip(tau, dec, T, Dd):
            f.write('%.9f %.9f %.9f %.9f\n' % (a, b, c, e))

def design_obs(mount, A, E, noise, rng, sides=None):
    """observe stars given at alt-az (A,E). returns tau,dec,T,D."""
    if mount.mount == 'altaz':
        return mount.observe(A, E, None, noise, rng)
    h, d = altaz_to_hadec(A, E, mount.lat)
    side = meridian_side(h) if sides is None else sides
    return mount.observe(h, d, side, noise, rng)
