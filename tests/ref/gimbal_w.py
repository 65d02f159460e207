"""Independent mount generator, written by an outside probe (W, stop 44) without
pmfit simulate or the other tests/ref scripts; numpy only.  compare_pairs_w.py
writes the pairs of nights tests/check_compare.c reads with it.

Gimbal forward model: encoder (axis1, axis2) in degrees -> true sky (axis1, axis2) degrees.
Frame: p(h,d) = (cos d cos h, cos d sin h, sin d) (same parametrisation as the library docs).
"""
import numpy as np

AS = np.pi / 180 / 3600
D2R = np.pi / 180


def rotx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def roty(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def vec(h, d):
    return np.stack([np.cos(d) * np.cos(h), np.cos(d) * np.sin(h), np.sin(d)], -1)


def ang(v):
    return np.arctan2(v[..., 1], v[..., 0]), np.arcsin(np.clip(v[..., 2], -1, 1))


class Mount:
    """kind: 'gem', 'fork', 'altaz'. Parameters in arcsec."""

    def __init__(self, kind, lat=40.0, IH=0, ID=0, MA=0, ME=0, NP=0, CH=0, TF=0,
                 HO=0, hoseed=0, noise=1.0):
        self.kind, self.lat = kind, lat
        self.IH, self.ID, self.MA, self.ME, self.NP, self.CH, self.TF = IH, ID, MA, ME, NP, CH, TF
        self.noise = noise
        # higher-order structure: random smooth distortion of mechanical angles (order 2-3 terms)
        r = np.random.RandomState(hoseed)
        self.ho = HO * r.randn(8) / np.sqrt(8 / 2.0)  # rms per axis ~ HO

    def copy(self, **kw):
        import copy
        m = copy.deepcopy(self)
        for k, v in kw.items():
            setattr(m, k, v)
        return m

    def forward(self, e1, e2):
        """encoder deg -> true sky deg (axis1, axis2)."""
        e1 = np.asarray(e1, float) * D2R
        e2 = np.asarray(e2, float) * D2R
        h = e1 + self.IH * AS
        d = e2 + self.ID * AS
        k = self.ho
        # higher-order mechanical distortions (functions of mechanical angles)
        h = h + AS * (k[0] * np.sin(2 * h) * np.cos(d) + k[1] * np.cos(2 * h) * np.sin(d) + k[2] * np.sin(3 * h) + k[3] * np.cos(d) ** 2 * np.sin(d))
        d = d + AS * (k[4] * np.cos(2 * h) + k[5] * np.sin(2 * h) * np.sin(d) + k[6] * np.cos(3 * h) * np.cos(d) + k[7] * np.sin(2 * d))
        np_ = self.NP * AS
        c = self.CH * AS
        # tube vector in frame of HA axis (rotating with h): dec axis a tilted by NP
        a = np.array([0.0, np.cos(np_), np.sin(np_)])
        xp = np.array([1.0, 0.0, 0.0])
        zp = np.cross(xp, a)  # perpendicular to a and x -> (0,-sin np, cos np)
        cd, sd = np.cos(d)[..., None], np.sin(d)[..., None]
        t = np.cos(c) * (cd * xp + sd * zp) + np.sin(c) * a
        # rotate about polar axis by h (p(h,d) convention: rotation +h about z)
        ch, sh = np.cos(h), np.sin(h)
        v = np.stack([ch * t[..., 0] - sh * t[..., 1], sh * t[..., 0] + ch * t[..., 1], t[..., 2]], -1)
        # polar axis misalignment: small rotations about x and y
        R = rotx(self.MA * AS) @ roty(self.ME * AS)
        v = v @ R.T
        s1, s2 = ang(v)
        # tube flexure: displacement toward zenith TF*cos(el)
        if self.TF:
            if self.kind == 'altaz':
                s2 = s2 + self.TF * AS * np.cos(s2)
            else:
                zen = vec(0.0, self.lat * D2R)
                el = np.arcsin(np.clip(v @ zen, -1, 1))
                # direction toward zenith in tangent plane
                tz = zen - (v @ zen)[..., None] * v
                nz = np.linalg.norm(tz, axis=-1, keepdims=True)
                tz = tz / np.where(nz > 0, nz, 1)
                amt = (self.TF * AS * np.cos(el))[..., None]
                v2 = v * np.cos(amt) + tz * np.sin(amt)
                s1, s2 = ang(v2)
        return np.degrees(s1), np.degrees(s2)

    def elev(self, s1, s2):
        if self.kind == 'altaz':
            return np.asarray(s2)
        v = vec(np.radians(s1), np.radians(s2))
        return np.degrees(np.arcsin(v @ vec(0.0, self.lat * D2R)))

    def side_for(self, ha):
        """German: normal side looking west (HA>0), beyond the pole east."""
        if self.kind != 'gem':
            return np.ones_like(np.asarray(ha, float))
        return np.where(np.asarray(ha) >= 0, 1, -1)

    def encoder_for(self, s1, s2, side):
        """nominal encoder for a target (no model; the mount is unsynchronised only by its errors)."""
        s1 = np.asarray(s1, float)
        s2 = np.asarray(s2, float)
        side = np.asarray(side)
        e1 = np.where(side < 0, s1 + 180, s1)
        e2 = np.where(side < 0, 180 - s2, s2)
        e1 = (e1 + 180) % 360 - 180
        return e1, e2

    def observe(self, s1, s2, side, rng, noise=True):
        e1, e2 = self.encoder_for(s1, s2, side)
        t1, t2 = self.forward(e1, e2)
        if noise and self.noise > 0:
            # noise on the sky, tangent plane
            n1 = rng.randn(*np.shape(t1)) * self.noise / 3600 / np.cos(np.radians(t2))
            n2 = rng.randn(*np.shape(t2)) * self.noise / 3600
            t1 = t1 + n1
            t2 = t2 + n2
        t1 = (t1 + 180) % 360 - 180
        if self.kind == 'altaz':
            t1 = t1 % 360
        return e1, e2, t1, t2


def random_sky(m, n, rng, min_el=15.0, max_el=None, hamask=None):
    """uniform over sky area above min_el (and below max_el)."""
    if max_el is None:
        max_el = 85.0 if m.kind == 'altaz' else 90.0
    out1, out2 = [], []
    while len(out1) < n:
        # uniform on sphere
        z = rng.uniform(-1, 1, 4 * n)
        lon = rng.uniform(-180, 180, 4 * n)
        if m.kind == 'altaz':
            el = np.degrees(np.arcsin(z))
            ok = (el > min_el) & (el < max_el)
            s1, s2 = lon % 360, el
        else:
            dec = np.degrees(np.arcsin(z))
            s1, s2 = lon, dec
            el = m.elev(s1, s2)
            ok = (el > min_el) & (el < max_el)
            if m.kind == 'fork':
                ok &= True
        if hamask is not None:
            ok &= hamask(s1, s2)
        out1 += list(s1[ok])
        out2 += list(s2[ok])
    return np.array(out1[:n]), np.array(out2[:n])


def grid_sky(m, n, min_el=15.0, max_el=None):
    """golden-spiral (equal area) over the sky above min_el, exactly n points in local alt-az."""
    if max_el is None:
        max_el = 85.0 if m.kind == 'altaz' else 90.0
    z0, z1 = np.sin(np.radians(min_el)), np.sin(np.radians(max_el))
    i = np.arange(n) + 0.5
    z = z0 + (z1 - z0) * i / n
    az = (i * 137.50776405) % 360
    el = np.degrees(np.arcsin(z))
    if m.kind == 'altaz':
        return az, el
    return altaz_to_hadec(az, el, m.lat)


def altaz_to_hadec(az, el, lat):
    az, el, ph = np.radians(az), np.radians(el), np.radians(lat)
    sd = np.sin(el) * np.sin(ph) + np.cos(el) * np.cos(ph) * np.cos(az)
    d = np.arcsin(sd)
    # hour angle: az north through east, HA positive west
    y = -np.sin(az) * np.cos(el)
    x = np.sin(el) * np.cos(ph) - np.cos(el) * np.sin(ph) * np.cos(az)
    h = np.arctan2(y, x)
    return np.degrees(h), np.degrees(d)


def write_run(path, m, e1, e2, t1, t2, comment=""):
    with open(path, "w") as f:
        f.write("# probeW independent generator %s\n" % comment)
        f.write("# latitude: %.6f\n" % m.lat)
        f.write("# mount: %s\n" % ("altaz" if m.kind == 'altaz' else "equatorial"))
        f.write("# tau delta T D\n")
        for a, b, c, d in zip(e1, e2, t1, t2):
            f.write("%.9f %.9f %.9f %.9f\n" % (a, b, c, d))
