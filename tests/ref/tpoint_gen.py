#!/usr/bin/python3
"""tpoint_gen.py -- an independent generator of pointing runs as mount software writes them.

Written without reference to pm's own simulators (tools/lib/simulate.cpp, tools/lib/inject.cpp,
tests/ref/indep_gen.py, tests/ref/flip_gem.py) or its library sources; only the public file
formats (docs/formats.md) and TPOINT's published term definitions are used.

What it does, per run:

1. A site (latitude, longitude, height, weather), a UTC date and a start time; targets spread over
   the chosen part of the sky above an elevation limit, visited in a realistic slew order (a
   German mount does one pier side, then the other), one UTC time per point (slew + settle +
   exposure/solve).  Each target is a "catalogue star": the J2000 (ICRS) place that is at the
   target's place at its time, rounded as a catalogue/TheSky export rounds it.
2. The OBSERVED (refracted, topocentric) place of that star with **astropy**
   (ICRS -> AltAz with pressure, temperature, humidity, wavelength; IERS-B, no download), and
   the observed HA/Dec from the observed alt/az by a rotation through the site latitude.
3. The mount: an EXACT gimbal (rotations, not first-order formulas) whose first-order expansion
   is TPOINT's published model with "true = raw + Delta" (docs/formats.md, "TPOINT term
   export"; the self-test `--selftest` checks the expansion term by term):
       equatorial: IH ID CH NP MA ME (+ TF sag toward/away from the zenith)
       alt-az:     IA IE CA NPAE AN AW (+ TF)
   plus smooth anisotropy of our own design (perturbations of the gimbal's axis angles,
   non-perpendicularity, collimation and polar-axis tilt as sin/cos of the mechanical axis
   angles), and the hidden effects, all in the mount's frame.  The raw (encoder) angles are
   found by Newton iteration so that the exact forward model points at the observed place plus
   Gaussian noise (on the sky, per axis).
4. Written as mount software writes it: TPOINT .dat (equatorial 14-field records, or `: ALTAZ`
   4-field records, azimuth from the south through east), a N.I.N.A./ASCOM-style CSV log
   (J2000 or JNow; mount RA/Dec as the driver reports them, pier side, temperature, time), or
   (for alt-az runs that need temperature or time) pm's named-column format.

The truth (configuration, seed, every term, hidden effects and their sizes, the lines of any
outliers) is written into the file's comment header and, with --truth FILE (default
OUT.truth.json), as JSON.

Run with /usr/bin/python3 (numpy, astropy, pyerfa).  Deterministic for a seed.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

AS = math.pi / 180.0 / 3600.0        # one arcsecond in radians
DEG = math.pi / 180.0
TWOPI = 2.0 * math.pi

_astropy = None


def _ap():
    """Import astropy lazily, configured for no network (IERS-B, no auto download)."""
    global _astropy
    if _astropy is None:
        import warnings
        from astropy.utils import iers
        iers.conf.auto_download = False
        iers.conf.auto_max_age = None
        try:
            iers.conf.iers_degraded_accuracy = 'warn'
        except Exception:
            pass
        from astropy.utils.exceptions import AstropyWarning
        warnings.simplefilter('ignore', AstropyWarning)
        warnings.filterwarnings('ignore', module='erfa')
        import astropy.units as u
        from astropy.time import Time
        from astropy.coordinates import SkyCoord, EarthLocation, AltAz, TETE, ICRS
        _astropy = dict(u=u, Time=Time, SkyCoord=SkyCoord, EarthLocation=EarthLocation,
                        AltAz=AltAz, TETE=TETE, ICRS=ICRS)
    return _astropy


# ----------------------------------------------------------------------------------------------
# vectors and rotations (right-handed frames)
#   equatorial frame E: x = (HA 0, Dec 0), y = east point, z = celestial pole
#       v(h, d) = (cos d cos h, -cos d sin h, sin d), h positive west
#   horizon frame H:    x = north, y = west, z = zenith
#       v(az, el) = (cos el cos az, -cos el sin az, sin el), az from north through east
# The same formula in both, so one gimbal serves both mounts.

def vec(a, b):
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    return np.stack([cb * ca, -cb * sa, sb], axis=-1)


def angles(v):
    a = np.arctan2(-v[..., 1], v[..., 0])
    b = np.arctan2(v[..., 2], np.hypot(v[..., 0], v[..., 1]))
    return a, b


def rodrigues(v, k, theta):
    """Rotate vectors v (N,3) about unit axes k (N,3) by theta (N)."""
    c = np.cos(theta)[..., None]
    s = np.sin(theta)[..., None]
    kv = np.sum(k * v, axis=-1)[..., None]
    return v * c + np.cross(k, v) * s + k * kv * (1.0 - c)


def rotvec(v, w):
    """Rotate v by the rotation vector w (N,3) or (3,)."""
    w = np.broadcast_to(w, v.shape)
    th = np.linalg.norm(w, axis=-1)
    k = np.where(th[..., None] > 0, w / np.where(th > 0, th, 1.0)[..., None], 0.0)
    return rodrigues(v, k, th)


def toward(v, z, ang):
    """Move v along the great circle toward the (unit) direction z by the angle ang (N)."""
    ax = np.cross(v, np.broadcast_to(z, v.shape))
    n = np.linalg.norm(ax, axis=-1)
    ax = ax / np.where(n > 1e-15, n, 1.0)[..., None]
    return rodrigues(v, ax, ang)


def wrap180(x):
    """degrees into (-180, 180]"""
    y = np.mod(np.asarray(x, float) + 180.0, 360.0) - 180.0
    return np.where(y == -180.0, 180.0, y)


def wrap_pi(x):
    y = np.mod(np.asarray(x, float) + math.pi, TWOPI) - math.pi
    return np.where(y == -math.pi, math.pi, y)


def gimbal(H, D, NP, CH, wx, wy):
    """Exact gimbal: tube (cos CH, -sin CH, 0) turned by the declination (elevation) angle D about
    y, the axis tilted by NP about x (non-perpendicularity), turned by the hour angle (azimuth) H
    about the mount's pole z, and the whole mount tilted by the rotation vector (wx, wy, 0).
    With wx = -MA, wy = -ME (alt-az: wx = -AW, wy = AN) its first-order expansion is TPOINT's
    formulas (docs/formats.md, "TPOINT term export"); `--selftest` checks it."""
    cC, sC = np.cos(CH), np.sin(CH)
    cD, sD = np.cos(D), np.sin(D)
    x1 = cC * cD
    y1 = -sC
    z1 = cC * sD
    cN, sN = np.cos(NP), np.sin(NP)
    y2 = y1 * cN - z1 * sN
    z2 = y1 * sN + z1 * cN
    cH, sH = np.cos(H), np.sin(H)
    x3 = x1 * cH + y2 * sH
    y3 = -x1 * sH + y2 * cH
    v = np.stack([x3, y3, z2], axis=-1)
    w = np.stack([wx * np.ones_like(H), wy * np.ones_like(H), np.zeros_like(H)], axis=-1)
    return rotvec(v, w)


def tangent_basis(v):
    """Unit vectors along increasing axis 1 (h or az; westward / eastward per frame) and axis 2."""
    a, b = angles(v)
    ea = np.stack([-np.sin(a), -np.cos(a), np.zeros_like(a)], axis=-1)       # d v / d a / cos b
    eb = np.stack([-np.sin(b) * np.cos(a), np.sin(b) * np.sin(a), np.cos(b)], axis=-1)
    return ea, eb


# ----------------------------------------------------------------------------------------------
# configuration

EFFECTS_EQ = ['ha_pe', 'dec_pe', 'pier_flex', 'refraction', 'pressure', 'sag', 'temperature',
              'drift', 'backlash', 'outlier']
EFFECTS_AZ = ['az_pe', 'el_pe', 'az_runout', 'refraction', 'pressure', 'sag', 'temperature',
              'drift', 'cable_wrap', 'outlier', 'el_flex_cot']


def parse_effect(s):
    """NAME:SIZE[:key=val,...]  e.g. ha_pe:2.5  ha_pe:2.5:G=144,phase=40  temperature:0.5:psi=30"""
    parts = s.split(':')
    name = parts[0]
    size = float(parts[1]) if len(parts) > 1 and parts[1] != '' else None
    opts = {}
    if len(parts) > 2:
        for kv in ':'.join(parts[2:]).split(','):
            if not kv:
                continue
            k, v = kv.split('=')
            try:
                opts[k] = float(v)
            except ValueError:
                opts[k] = v
    return dict(name=name, size=size, **opts)


def std_pressure(h):
    return 1013.25 * math.exp(-h / 8434.5)


def draw_config(seed, mount='gem', n=None, noise=None, sky=None, lat=None, aniso=None,
                aniso_beyond=None, fmt=None, flip_writing=None, flip_side=None, ra_writing=None,
                order=None, el_limit=None, hours=None, index_deg=None, tilt_arcmin=None,
                outlier_frac=None, csv_equinox=None, az_writing=None, date=None, terms=None,
                aniso_frame=None):
    """All random choices of a run, from the seed; then the overrides.  Every value is drawn
    whether overridden or not, so overriding one (e.g. --noise 1e-6) leaves the others as they
    were: the same run with another noise."""
    rng = np.random.default_rng([seed, 7919])
    D = {}
    D['n'] = int(rng.integers(50, 301))
    D['noise'] = float(rng.uniform(0.3, 3.0))
    D['sky'] = str(rng.choice(['full', 'full', 'half', 'band', 'oneside']))
    lat_d = float(rng.uniform(15.0, 65.0) * (1 if rng.random() < 0.7 else -1))
    D['lon'] = float(rng.uniform(-180.0, 180.0))
    D['height'] = float(np.round(rng.uniform(0.0, 3000.0), 1))
    D['temp_c'] = float(np.round(rng.uniform(-5.0, 25.0), 2))
    pfac = float(rng.uniform(0.97, 1.02))
    D['humidity'] = float(np.round(rng.uniform(0.2, 0.9), 2))
    D['wavelength'] = float(rng.choice([0.55, 0.55, 0.65, 0.7]))
    D['mjd_start'] = float(57023.0 + rng.integers(0, 59850 - 57023) + rng.uniform(0.0, 1.0))
    D['el_limit'] = float(rng.uniform(15.0, 20.0))
    D['hours'] = float(rng.uniform(1.0, 6.0))
    D['order'] = str(rng.choice(['zigzag', 'ha', 'nearest']))
    idx_d = float(rng.choice([0.05, 0.5, 2.0, 5.0]))
    tilt_d = float(rng.choice([1.0, 5.0, 20.0]))
    u = rng.uniform(-1, 1, 7)
    D['aniso'] = float(rng.choice([0.0, 3.0, 30.0, 120.0]))
    D['aniso_coef'] = [float(x) for x in rng.normal(0.0, 1.0, 12)]
    D['aniso_beyond_coef'] = [float(x) for x in rng.normal(0.0, 1.0, 6)]
    D['aniso_beyond_phase'] = [float(x) for x in rng.uniform(0, 360, 6)]
    D['flip_side'] = str(rng.choice(['west', 'east']))
    D['meridian_overlap'] = float(rng.uniform(0.0, 12.0))
    D['flip_writing'] = str(rng.choice(['pm180', '0360']))
    D['ra_writing'] = str(rng.choice(['std', 'std', 'cont', 'neg']))
    D['az_writing'] = str(rng.choice(['0360', 'pm180', 'wrap']))
    D['csv_equinox'] = str(rng.choice(['J2000', 'J2000', 'JNow']))
    D['csv_style'] = int(rng.integers(0, 4))
    D['side_first'] = int(rng.integers(0, 2))
    D['temp_drop'] = float(rng.uniform(1.5, 8.0))
    D['temp_tau_h'] = float(rng.uniform(0.7, 4.0))
    D['wrap_center'] = float(rng.choice([0.0, 180.0]))
    D['sky_param'] = float(rng.uniform(0.0, 360.0))
    c = dict(seed=int(seed), mount=mount)
    c.update(D)
    for k, v in (('n', n), ('noise', noise), ('sky', sky), ('el_limit', el_limit), ('hours', hours),
                 ('order', order), ('aniso', aniso), ('flip_side', flip_side), ('flip_writing', flip_writing),
                 ('ra_writing', ra_writing), ('az_writing', az_writing), ('csv_equinox', csv_equinox)):
        if v is not None:
            c[k] = type(D[k])(v)
    c['n'] = int(c['n'])
    lat = lat_d if lat is None else float(lat)
    c['lat'] = round(lat * 36000.0) / 36000.0       # the run line writes 0.1"
    c['pressure'] = float(np.round(std_pressure(c['height']) * pfac, 2))
    if date is not None:
        c['mjd_start'] = float(date)
    idx = idx_d if index_deg is None else float(index_deg)
    tilt = tilt_d if tilt_arcmin is None else float(tilt_arcmin)
    if mount == 'altaz':
        t = dict(IA=u[0] * idx * 3600.0, IE=u[1] * min(idx, 1.0) * 3600.0, CA=3 * u[2] * 60.0,
                 NPAE=2 * u[3] * 60.0, AN=u[4] * tilt * 60.0, AW=u[5] * tilt * 60.0, TF=20 * u[6])
    else:
        t = dict(IH=u[0] * idx * 3600.0, ID=u[1] * idx * 3600.0, CH=3 * u[2] * 60.0, NP=2 * u[3] * 60.0,
                 MA=u[4] * tilt * 60.0, ME=u[5] * tilt * 60.0, TF=20 * u[6])
    c['terms'] = {k: float(np.round(v, 3)) for k, v in t.items()}
    for k, v in (terms or {}).items():
        if k not in c['terms']:
            raise ValueError('unknown term %s for a %s mount (known: %s)' % (k, mount, ' '.join(c['terms'])))
        c['terms'][k] = float(v)
    c['aniso_beyond'] = float(aniso_beyond if aniso_beyond is not None else 0.0)
    c['aniso_frame'] = str(aniso_frame if aniso_frame is not None else 'mech')
    c['outlier_frac'] = float(outlier_frac if outlier_frac is not None else 0.0)
    c['format'] = fmt if fmt is not None else 'tpoint'
    return c


# ----------------------------------------------------------------------------------------------
# the sky: targets, order, times, catalogue stars, observed places

def hd_to_azel(h, d, phi):
    """geometric HA/Dec -> az (N through E), el; radians"""
    v = vec(h, d)
    Z = np.array([math.cos(phi), 0.0, math.sin(phi)])
    N = np.array([-math.sin(phi), 0.0, math.cos(phi)])
    E = np.array([0.0, 1.0, 0.0])
    el = np.arcsin(np.clip(v @ Z, -1, 1))
    az = np.mod(np.arctan2(v @ E, v @ N), TWOPI)
    return az, el


def azel_to_hd(az, el, phi):
    Z = np.array([math.cos(phi), 0.0, math.sin(phi)])
    N = np.array([-math.sin(phi), 0.0, math.cos(phi)])
    E = np.array([0.0, 1.0, 0.0])
    ce = np.cos(el)
    v = (ce * np.cos(az))[:, None] * N + (ce * np.sin(az))[:, None] * E + np.sin(el)[:, None] * Z
    return angles(v)


def sample_targets(c, rng):
    """Targets (az, el, ha, dec) over the chosen sky, radians."""
    phi = c['lat'] * DEG
    n = c['n']
    el_lo = c['el_limit'] * DEG
    el_hi = (84.0 if c['mount'] == 'altaz' else 87.0) * DEG
    out_az, out_el = [], []
    a0 = c['sky_param'] * DEG
    dec_lo = None
    if c['sky'] == 'band':
        # a declination band (equatorial) or an elevation band (alt-az)
        if c['mount'] == 'altaz':
            b_lo = rng.uniform(el_lo, 45 * DEG)
            b_hi = b_lo + rng.uniform(25, 40) * DEG
        else:
            dmin = max(-90.0, -(90.0 - abs(c['lat'])) + c['el_limit']) if c['lat'] > 0 else -89.0
            dmax = 89.0 if c['lat'] > 0 else min(90.0, (90.0 - abs(c['lat'])) - c['el_limit'])
            width = rng.uniform(35, 60)
            dec_lo = rng.uniform(dmin, max(dmin, dmax - width))
            dec_hi = dec_lo + width
    tries = 0
    while len(out_az) < n and tries < 200:
        tries += 1
        m = 4 * n
        az = rng.uniform(0, TWOPI, m)
        sl = rng.uniform(math.sin(el_lo), math.sin(el_hi), m)
        el = np.arcsin(sl)
        ok = np.ones(m, bool)
        if c['sky'] == 'half':
            ok &= np.mod(az - a0, TWOPI) < math.pi
        elif c['sky'] == 'band':
            if c['mount'] == 'altaz':
                ok &= (el >= b_lo) & (el <= b_hi)
            else:
                h, d = azel_to_hd(az, el, phi)
                ok &= (d >= dec_lo * DEG) & (d <= dec_hi * DEG)
        elif c['sky'] == 'oneside':
            if c['mount'] == 'altaz':
                ok &= np.abs(wrap_pi(az - a0)) < 60 * DEG
            else:
                h, d = azel_to_hd(az, el, phi)
                want_west = (c['sky_param'] < 180.0)
                ok &= (h > 2 * DEG) if want_west else (h < -2 * DEG)
        if c['mount'] != 'altaz':
            # keep the raw declination on its own side of the pole: a Dec index of degrees would
            # otherwise put a normal-side raw reading beyond 90 deg (and the TPOINT reader's pier
            # side, derived from |raw Dec| > 90, would then be the other one)
            h, d = azel_to_hd(az, el, phi)
            ok &= np.abs(d) < (87.5 - abs(c['terms']['ID']) / 3600.0) * DEG
        out_az.extend(az[ok].tolist())
        out_el.extend(el[ok].tolist())
    az = np.array(out_az[:n])
    el = np.array(out_el[:n])
    if len(az) < n:
        raise RuntimeError('could not place %d targets on the requested sky' % n)
    h, d = azel_to_hd(az, el, phi)
    return az, el, h, d


def assign_sides(c, h, rng):
    """+1 normal, -1 beyond the pole (German mounts); fork and alt-az: all +1 (0 for alt-az)."""
    n = len(h)
    if c['mount'] != 'gem':
        return np.ones(n, int)
    m = c['meridian_overlap'] * DEG
    hd = wrap_pi(h)
    flip_west = c['flip_side'] == 'west'
    side = np.where(hd > 0, -1, 1) if flip_west else np.where(hd < 0, -1, 1)
    near = np.abs(hd) < m
    # within the overlap the mount keeps tracking on the side it came from: random here, then
    # the slew order groups the sides
    side = np.where(near, np.where(rng.random(n) < 0.5, side, -side), side)
    return side


def slew_order(c, az, el, h, d, side, rng):
    n = len(az)
    idx = np.arange(n)
    groups = [idx]
    if c['mount'] == 'gem':
        first = 1 if c['side_first'] == 0 else -1
        groups = [idx[side == first], idx[side == -first]]
    order = []
    for g in groups:
        if len(g) == 0:
            continue
        if c['order'] == 'zigzag':
            # sectors in azimuth, elevation up and down alternately
            k = max(1, int(round(math.sqrt(len(g) / 4.0))))
            a_ = np.mod(az[g] - c['sky_param'] * DEG, TWOPI)
            sec = np.minimum((a_ / TWOPI * k).astype(int), k - 1)
            seq = []
            for s in range(k):
                gg = g[sec == s]
                oo = np.argsort(el[gg])
                if s % 2:
                    oo = oo[::-1]
                seq.extend(gg[oo].tolist())
            order.extend(seq)
        elif c['order'] == 'ha':
            # by hour angle (east to west), declination alternating within HA bins
            k = max(1, int(round(math.sqrt(len(g) / 4.0))))
            hh = wrap_pi(h[g])
            oo = np.argsort(hh)
            bins = np.array_split(oo, k)
            seq = []
            for j, b in enumerate(bins):
                bb = b[np.argsort(d[g][b])]
                if j % 2:
                    bb = bb[::-1]
                seq.extend(g[bb].tolist())
            order.extend(seq)
        else:
            # nearest neighbour from the lowest point
            vv = vec(az[g], el[g])
            left = list(range(len(g)))
            cur = int(np.argmin(el[g]))
            seq = [cur]
            left.remove(cur)
            while left:
                dots = vv[left] @ vv[cur]
                j = left[int(np.argmax(dots))]
                seq.append(j)
                left.remove(j)
                cur = j
            order.extend(g[seq].tolist())
    return np.array(order, int)


def observe(c):
    """Plan the run and compute the observed places with astropy.  Returns a dict of arrays."""
    A = _ap()
    u = A['u']
    rng = np.random.default_rng([c['seed'], 104729])
    az, el, h, d = sample_targets(c, rng)
    side = assign_sides(c, h, rng)
    order = slew_order(c, az, el, h, d, side, rng)
    az, el, h, d, side = az[order], el[order], h[order], d[order], side[order]
    n = len(az)
    # times: slew (axis angles, 2.5 deg/s) + settle + exposure and solve, scaled to the run length
    if c['mount'] == 'altaz':
        a1, a2 = az, el
    else:
        a1 = np.where(side > 0, h, h + math.pi)
        a2 = np.where(side > 0, d, math.pi - d)
    step = np.zeros(n)
    step[1:] = np.maximum(np.abs(wrap_pi(np.diff(a1))), np.abs(np.diff(a2))) / DEG / 2.5
    flips = np.zeros(n)
    flips[1:] = (side[1:] != side[:-1]) * 60.0
    base = rng.uniform(20.0, 60.0, n)
    dt = step + flips + base
    dt[0] = 0.0
    total = c['hours'] * 3600.0
    scale = total / max(dt.sum(), 1.0)
    tsec = np.cumsum(dt * scale)
    mjd = c['mjd_start'] + tsec / 86400.0
    Time = A['Time']
    loc = A['EarthLocation'].from_geodetic(c['lon'] * u.deg, c['lat'] * u.deg, c['height'] * u.m)
    t = Time(mjd, format='mjd', scale='utc')
    # the catalogue star at the target's place at its time (geometric, no refraction)
    fr0 = A['AltAz'](obstime=t, location=loc, pressure=0 * u.hPa)
    sc = A['SkyCoord'](az=az * u.rad, alt=el * u.rad, frame=fr0).transform_to(A['ICRS']())
    ra = sc.ra.rad
    dec = sc.dec.rad
    # catalogue rounding: RA to 0.0001 s, Dec to 0.001" (what a TheSky export writes)
    ra = np.round(ra / (15 * AS) * 1e4) / 1e4 * 15 * AS
    dec = np.round(dec / AS * 1e3) / 1e3 * AS
    obs = dict(ra=ra, dec=dec, mjd=mjd, tsec=tsec, side=side, n=n)
    obs.update(observed_places(c, obs, c['pressure']))
    # LST (apparent sidereal time, UT1 from IERS-B)
    obs['lst'] = t.sidereal_time('apparent', longitude=c['lon'] * u.deg).rad
    obs['lst_mean'] = t.sidereal_time('mean', longitude=c['lon'] * u.deg).rad
    # apparent place of date (TETE) of the star, for JNow logs
    te = A['SkyCoord'](ra=ra * u.rad, dec=dec * u.rad, frame='icrs').transform_to(A['TETE'](obstime=t))
    obs['ra_app'] = te.ra.rad
    obs['dec_app'] = te.dec.rad
    # temperature series: a night that cools (exponential) with a random walk and read noise
    th = tsec / 3600.0
    walk = np.cumsum(rng.normal(0, 0.08, n))
    T = (c['temp_c'] + c['temp_drop'] / 2 - c['temp_drop'] * (1 - np.exp(-th / c['temp_tau_h']))
         + walk + rng.normal(0, 0.05, n))
    # refraction (astropy and the file's weather) uses one temperature for the run, c['temp_c'];
    # the series is centred on it, so that a reader taking the column's mean for refraction
    # (docs/formats.md, CSV) uses the same value
    T = T - np.mean(T) + c['temp_c']
    obs['temp'] = np.round(T, 2)
    return obs


def observed_places(c, obs, pressure):
    """astropy observed az/el (refracted at `pressure`) and observed HA/Dec of the stars."""
    A = _ap()
    u = A['u']
    loc = A['EarthLocation'].from_geodetic(c['lon'] * u.deg, c['lat'] * u.deg, c['height'] * u.m)
    t = A['Time'](obs['mjd'], format='mjd', scale='utc')
    fr = A['AltAz'](obstime=t, location=loc, pressure=pressure * u.hPa,
                    temperature=c['temp_c'] * u.deg_C, relative_humidity=c['humidity'],
                    obswl=c['wavelength'] * u.micron)
    aa = A['SkyCoord'](ra=obs['ra'] * u.rad, dec=obs['dec'] * u.rad, frame='icrs').transform_to(fr)
    az = aa.az.rad
    el = aa.alt.rad
    h, d = azel_to_hd(az, el, c['lat'] * DEG)
    return dict(az_obs=az, el_obs=el, ha_obs=h, dec_obs=d)


# ----------------------------------------------------------------------------------------------
# the mount

def zenith_vec(c):
    if c['mount'] == 'altaz':
        return np.array([0.0, 0.0, 1.0])
    phi = c['lat'] * DEG
    return np.array([math.cos(phi), 0.0, math.sin(phi)])


def mech_continuous(c, a1):
    """Raw axis-1 angle on the mount's continuous turn (what a mount's axis really travels)."""
    if c['mount'] == 'gem':
        centre = -90.0 * DEG if c['flip_side'] == 'west' else 90.0 * DEG
        return centre + wrap_pi(a1 - centre)
    if c['mount'] == 'fork':
        return wrap_pi(a1)
    return a1   # alt-az: already unwrapped by the cable wrap


def cable_wrap(c, az):
    """Continuous azimuth along the cable wrap: +-270 deg about the wrap centre, shortest legal move."""
    cen = c['wrap_center'] * DEG
    lo, hi = cen - 270 * DEG, cen + 270 * DEG
    out = np.empty_like(az)
    cur = cen + wrap_pi(az[0] - cen)
    out[0] = cur
    for i in range(1, len(az)):
        best = None
        for k in (-2, -1, 0, 1, 2):
            cand = az[i] + k * TWOPI
            if lo <= cand <= hi:
                if best is None or abs(cand - cur) < abs(best - cur):
                    best = cand
        cur = best
        out[i] = cur
    return out


class Mount:
    """The exact forward model raw -> true direction, with anisotropy and hidden effects."""

    def __init__(self, c, obs, effects):
        self.c = c
        self.obs = obs
        self.eff = effects
        t = c['terms']
        if c['mount'] == 'altaz':
            self.I1, self.I2 = t['IA'] * AS, t['IE'] * AS
            self.C, self.N = t['CA'] * AS, t['NPAE'] * AS
            self.wx, self.wy = -t['AW'] * AS, t['AN'] * AS
        else:
            self.I1, self.I2 = t['IH'] * AS, t['ID'] * AS
            self.C, self.N = t['CH'] * AS, t['NP'] * AS
            self.wx, self.wy = -t['MA'] * AS, -t['ME'] * AS
        self.TF = t['TF'] * AS
        self.Z = zenith_vec(c)
        n = obs['n']
        self.side = obs['side']
        self.temp = obs['temp']
        self.th = obs['tsec'] / 3600.0
        self.extra_cot = np.zeros(n)   # refraction-like coefficient per point (rad)
        self.sag = np.zeros(n)         # TF-like coefficient added (rad, TPOINT sign: away from zenith)
        self.dir1 = np.zeros(n)
        self.dir2 = np.zeros(n)

    def perturb(self, r1, r2):
        """Axis-angle and gimbal-parameter perturbations (radians) at raw angles r1, r2."""
        c = self.c
        n = len(r1)
        H = r1 + self.I1
        D = r2 + self.I2
        # the anisotropy is a function of the mechanical (true) axis angles, as gravity sees the
        # mount ('mech'), or of the raw encoder angles ('encoder', as pm's harmonics are)
        Ha, Da = (H, D) if c.get('aniso_frame', 'mech') == 'mech' else (r1, r2)
        dH = np.zeros(n)
        dD = np.zeros(n)
        dN = np.zeros(n)
        dC = np.zeros(n)
        dwx = np.zeros(n)
        dwy = np.zeros(n)
        # anisotropy, in-span-like smooth terms (RMS ~ aniso)
        A = c['aniso'] * AS
        if A:
            k = np.array(c['aniso_coef']) * A / math.sqrt(2.0)
            sD, cD, sH, cH = np.sin(Da), np.cos(Da), np.sin(Ha), np.cos(Ha)
            dH += k[0] * sD + k[1] * cD * sH          # HA (az) index with Dec, flexure along the axis
            dD += k[2] * cD * cH + k[3] * sD + k[4] * cD * sH
            dC += k[5] * cD * cH + k[6] * cD * sH
            dN += k[7] * sD + k[8] * cD * cH
            dwx += k[9] * sD
            dwy += k[10] * sD + k[11] * cD * cH
        B = c['aniso_beyond'] * AS
        if B:
            k = np.array(c['aniso_beyond_coef']) * B / math.sqrt(2.0)
            p = np.array(c['aniso_beyond_phase']) * DEG
            dH += k[0] * np.sin(Ha + p[0])              # axis-1 encoder eccentricity (1 cycle)
            dD += k[1] * np.sin(Da + p[1])              # axis-2 encoder eccentricity
            dH += k[2] * np.sin(2 * Ha + p[2]) * np.cos(Da)   # two-cycle distortion
            dN += k[3] * np.sin(Ha + p[3])              # axis-2 axis flexure with axis-1 angle
            dwx += k[4] * np.cos(Ha + p[4])             # bearing wobble
            dwy += k[5] * np.sin(Ha + p[5])
        # hidden effects
        for e in self.eff:
            nm = e['name']
            s = e['size'] * AS
            if nm in ('ha_pe', 'az_pe'):
                dH += s * np.cos(e['G'] * r1 + e['phase'] * DEG)
            elif nm in ('dec_pe', 'el_pe'):
                dD += s * np.cos(e['G'] * r2 + e['phase'] * DEG)
            elif nm == 'az_runout':
                dH += s * np.cos(e['G'] * r1 + e['phase'] * DEG)
            elif nm == 'pier_flex':
                on = (self.side == (-1 if e['on'] == 'beyond' else 1))
                dC += np.where(on, s * math.cos(e['psi'] * DEG), 0.0)
                dD += np.where(on, s * math.sin(e['psi'] * DEG), 0.0)
            elif nm == 'temperature':
                x = self.temp - np.mean(self.temp)
                dH += s * math.cos(e['psi'] * DEG) * x
                dD += s * math.sin(e['psi'] * DEG) * x
            elif nm == 'drift':
                x = self.th - np.mean(self.th)
                dH += s * math.cos(e['psi'] * DEG) * x
                dD += s * math.sin(e['psi'] * DEG) * x
            elif nm in ('backlash', 'cable_wrap'):
                dH += s * math.cos(e['psi'] * DEG) * self.dir1
                dD += s * math.sin(e['psi'] * DEG) * self.dir2
        return H + dH, D + dD, self.N + dN, self.C + dC, self.wx + dwx, self.wy + dwy

    def forward(self, r1, r2, idx=None):
        H, D, N, C, wx, wy = self.perturb(r1, r2)
        v = gimbal(H, D, N, C, wx, wy)
        el = np.arcsin(np.clip(v @ self.Z, -1, 1))
        sag = self.TF + (self.sag if idx is None else self.sag[idx])
        cot = self.extra_cot if idx is None else self.extra_cot[idx]
        ang = -sag * np.cos(el) + cot / np.tan(np.maximum(el, 0.01))
        return toward(v, self.Z, ang)

    def solve(self, v_tgt, r1, r2):
        """Newton: raw angles whose forward direction is v_tgt (N,3); r1, r2 starting values."""
        ea, eb = tangent_basis(v_tgt)
        eps = 1e-7
        for it in range(40):
            f = self.forward(r1, r2)
            res = np.stack([np.sum((f - v_tgt) * ea, -1), np.sum((f - v_tgt) * eb, -1)], -1)
            f1 = self.forward(r1 + eps, r2)
            f2 = self.forward(r1, r2 + eps)
            J = np.empty(res.shape + (2,))
            J[:, 0, 0] = np.sum((f1 - f) * ea, -1) / eps
            J[:, 1, 0] = np.sum((f1 - f) * eb, -1) / eps
            J[:, 0, 1] = np.sum((f2 - f) * ea, -1) / eps
            J[:, 1, 1] = np.sum((f2 - f) * eb, -1) / eps
            step = np.linalg.solve(J, -res[..., None])[..., 0]
            r1 = r1 + step[:, 0]
            r2 = r2 + step[:, 1]
            if np.max(np.abs(step)) < 1e-14:
                break
        f = self.forward(r1, r2)
        err = np.max(np.linalg.norm(f - v_tgt, axis=-1))
        if err > 1e-10:
            raise RuntimeError('encoder solve did not converge (%.3g rad)' % err)
        return r1, r2


def effect_defaults(e, c, rng):
    """Fill in an effect's random parameters (G, phase, shape angle, side) from rng."""
    e = dict(e)
    nm = e['name']
    if nm in ('ha_pe', 'dec_pe', 'az_pe', 'el_pe'):
        e.setdefault('G', float(rng.integers(50, 401)))
        e.setdefault('phase', float(rng.uniform(0, 360)))
    elif nm == 'az_runout':
        e.setdefault('G', float(rng.integers(2, 4)))
        e.setdefault('phase', float(rng.uniform(0, 360)))
    elif nm == 'pier_flex':
        e.setdefault('on', 'beyond' if rng.random() < 0.5 else 'normal')
        e.setdefault('psi', float(rng.choice([0.0, rng.uniform(-40, 40)])))
    elif nm in ('temperature', 'drift'):
        if c['mount'] == 'altaz' and nm == 'temperature':
            e.setdefault('psi', float(90.0 * rng.choice([1, -1])))   # on the elevation index
        else:
            e.setdefault('psi', float(rng.uniform(0, 360)))
    elif nm == 'backlash':
        e.setdefault('psi', float(rng.choice([0.0, 180.0, rng.uniform(0, 360)])))
    elif nm == 'cable_wrap':
        e.setdefault('psi', float(rng.choice([0.0, 180.0])))        # azimuth only
    elif nm == 'outlier':
        e.setdefault('count', 1.0)
    for k in ('phase', 'psi'):
        if k in e:
            e[k] = round(float(e[k]), 3)     # printed exactly in the header and the commands
    return e


def refco(c, pressure):
    import erfa
    return erfa.refco(pressure, c['temp_c'], c['humidity'], c['wavelength'])


def pressure_for(c, k_arcsec):
    """The wrong pressure whose refraction constant A differs from the true one by k (arcsec);
    bisection on (1, 3000) hPa (the caller keeps it legal, <= 1100)."""
    A0, _ = refco(c, c['pressure'])
    lo, hi = 1.0, 3000.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if (refco(c, mid)[0] - A0) / AS < k_arcsec:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def make_run(c, obs, effects, noise_seed=None, outlier_seed=None):
    """Encoders for the run with the effects.  Returns (run dict, truth list of effects)."""
    n = obs['n']
    eff_rng = np.random.default_rng([c['seed'], 31337])
    effs = [effect_defaults(e, c, eff_rng) for e in effects]
    m = Mount(c, obs, [e for e in effs if e['name'] not in ('refraction', 'pressure', 'sag', 'outlier',
                                                             'el_flex_cot')])
    pressure_file = c['pressure']
    az_written, el_written = obs['az_obs'], obs['el_obs']
    for e in effs:
        if e['name'] in ('refraction', 'el_flex_cot'):
            m.extra_cot = m.extra_cot + e['size'] * AS
        elif e['name'] == 'sag':
            m.sag = m.sag + e['size'] * AS
        elif e['name'] == 'pressure':
            pressure_file = pressure_for(c, e['size'])
            e['pressure_true'] = c['pressure']
            e['pressure_written'] = round(pressure_file, 2)
            pressure_file = round(pressure_file, 2)
            A0, B0 = refco(c, c['pressure'])
            A1, B1 = refco(c, pressure_file)
            e['dA_arcsec'] = (A1 - A0) / AS
            e['dB_arcsec'] = (B1 - B0) / AS
            if c['mount'] == 'altaz':
                wr = observed_places(c, obs, pressure_file)
                az_written, el_written = wr['az_obs'], wr['el_obs']
    # the observed direction plus the measurement noise
    if c['mount'] == 'altaz':
        v = vec(obs['az_obs'], obs['el_obs'])
    else:
        v = vec(obs['ha_obs'], obs['dec_obs'])
    nrng = np.random.default_rng([c['seed'], 2718] if noise_seed is None else [noise_seed, 2718])
    ea, eb = tangent_basis(v)
    g = nrng.normal(0.0, c['noise'] * AS, (n, 2))
    # outliers: a failed plate solve / wrong identification -> far off
    out_idx = []
    orng = np.random.default_rng([c['seed'], 4242] if outlier_seed is None else [outlier_seed, 4242])
    oo = [e for e in effs if e['name'] == 'outlier']
    n_frac = max(1, int(round(c['outlier_frac'] * n))) if c['outlier_frac'] > 0 else 0
    sizes = []
    for e in oo:
        cnt = int(e.get('count', 1))
        for _ in range(cnt):
            sizes.append(e['size'])
    for _ in range(n_frac):
        sizes.append(float(orng.uniform(10, 100)) * c['noise'])
    if sizes:
        cand = orng.permutation(np.arange(2, n - 2))[:len(sizes)]
        for j, sz in zip(cand, sizes):
            ang = orng.uniform(0, TWOPI)
            g[j] += sz * AS * np.array([math.cos(ang), math.sin(ang)])
            out_idx.append((int(j), float(sz)))
    off = g[:, 0:1] * ea + g[:, 1:2] * eb
    vt = v + off
    vt /= np.linalg.norm(vt, axis=-1)[:, None]
    # starting raw angles on each point's branch
    if c['mount'] == 'altaz':
        a1 = cable_wrap(c, obs['az_obs'])
        r1 = a1 - m.I1
        r2 = obs['el_obs'] - m.I2
    else:
        side = obs['side']
        a1 = np.where(side > 0, obs['ha_obs'], obs['ha_obs'] + math.pi)
        a1 = mech_continuous(c, a1)
        a2 = np.where(side > 0, obs['dec_obs'], math.pi - obs['dec_obs'])
        r1 = a1 - m.I1
        r2 = a2 - m.I2
    # slew directions from the mechanical angles (sign of the move from the previous point)
    m.dir1[1:] = np.sign(np.diff(r1))
    m.dir2[1:] = np.sign(np.diff(r2))
    m.dir1[0] = 1.0
    m.dir2[0] = 1.0
    r1, r2 = m.solve(vt, r1, r2)
    run = dict(r1=r1, r2=r2, dir1=m.dir1.copy(), dir2=m.dir2.copy(), outliers=out_idx,
               pressure_file=pressure_file, az_written=az_written, el_written=el_written,
               effects=effs)
    return run


# ----------------------------------------------------------------------------------------------
# writing

def sexa(x, nfrac, signed, width0=2):
    """x in units (hours or degrees) -> 'DD MM SS.fff' with rounding carried; sign on the first."""
    neg = x < 0
    tot = round(abs(x) * 3600.0 * 10 ** nfrac)
    q = 10 ** nfrac
    sec_i, frac = divmod(tot, q)
    mm, ss = divmod(sec_i, 60)
    dd, mm = divmod(mm, 60)
    s = '%0*d %02d %02d' % (width0, dd, mm, ss)
    if nfrac:
        s += '.%0*d' % (nfrac, frac)
    if signed:
        s = ('-' if neg else '+') + s
    elif neg:
        s = '-' + s
    return s


def lst_field(lst_rad):
    hrs = (lst_rad / TWOPI * 24.0) % 24.0
    tot = round(hrs * 60.0 * 1000.0)
    hh, mmm = divmod(tot, 60000)
    hh %= 24
    return '%02d %6.3f' % (hh, mmm / 1000.0)


def truth_record(c, run, path):
    effs = []
    for e in run['effects']:
        d = {k: v for k, v in e.items()}
        effs.append(d)
    t = dict(generator='tests/ref/tpoint_gen.py', config=c, effects=effs,
             outliers=[dict(index=i, size_arcsec=s) for i, s in run['outliers']],
             pressure_file=run['pressure_file'])
    return t


def truth_lines(c, run):
    """Human-readable truth for the header; no ':' (CSV/named readers take '# key: value')."""
    L = []
    L.append('truth generator tests/ref/tpoint_gen.py seed=%d mount=%s n=%d noise_arcsec=%.3f sky=%s'
             % (c['seed'], c['mount'], c['n'], c['noise'], c['sky']))
    L.append('truth site lat=%.6f lon=%.4f height_m=%.1f T_C=%.2f P_hPa=%.2f RH=%.2f wl_um=%.2f'
             % (c['lat'], c['lon'], c['height'], c['temp_c'], c['pressure'], c['humidity'],
                c['wavelength']))
    L.append('truth run mjd_start=%.6f hours=%.3f order=%s el_limit=%.2f flip_side=%s overlap_deg=%.2f'
             % (c['mjd_start'], c['hours'], c['order'], c['el_limit'], c['flip_side'],
                c['meridian_overlap']))
    L.append('truth terms_arcsec (TPOINT convention, true = raw + Delta, exact gimbal) '
             + ' '.join('%s=%.3f' % (k, v) for k, v in c['terms'].items()))
    L.append('truth anisotropy in_span_rms_arcsec=%.3f beyond_rms_arcsec=%.3f frame=%s'
             % (c['aniso'], c['aniso_beyond'], c.get('aniso_frame', 'mech')))
    if not run['effects']:
        L.append('truth hidden effects none')
    for e in run['effects']:
        L.append('truth hidden ' + ' '.join('%s=%s' % (k, ('%.6g' % v) if isinstance(v, float) else v)
                                            for k, v in e.items()))
    for i, s in run['outliers']:
        L.append('truth outlier point=%d (0-based) off_arcsec=%.3f' % (i, s))
    L.append('truth writing format=%s flip_writing=%s ra_writing=%s az_writing=%s csv_equinox=%s'
             % (c['format'], c['flip_writing'], c['ra_writing'], c['az_writing'], c['csv_equinox']))
    return L


def write_tpoint_eq(c, obs, run, path):
    lines = []
    for L in truth_lines(c, run):
        lines.append('! ' + L)
    lines.append('! raw RA/Dec as the mount reports its axes; beyond the pole: raw Dec = 180 - dec')
    lines.append('Simulated %s mount (tpoint_gen seed %d)' % ('German equatorial' if c['mount'] == 'gem'
                                                              else 'fork equatorial', c['seed']))
    lines.append(':NODA')
    lines.append(':EQUAT')
    t0 = _ap()['Time'](c['mjd_start'], format='mjd', scale='utc').datetime
    lines.append('%s %d %d %d %.2f %.2f %.2f %5.2f %.4f 0.0065'
                 % (sexa(c['lat'], 1, True), t0.year, t0.month, t0.day, c['temp_c'], run['pressure_file'],
                    c['height'], c['humidity'], c['wavelength']))
    rec_line = {}
    lst = obs['lst']
    for i in range(obs['n']):
        ra_h = obs['ra'][i] / TWOPI * 24.0
        dec_d = obs['dec'][i] / DEG
        raw_ha = run['r1'][i]                    # continuous mechanical turn
        raw_ra = (lst[i] - raw_ha) / TWOPI * 24.0
        if c['ra_writing'] == 'std':
            raw_ra = raw_ra % 24.0
        elif c['ra_writing'] == 'neg':
            raw_ra = ((raw_ra + 12.0) % 24.0) - 12.0
        else:  # 'cont': LST in [0,24) minus the continuous axis angle: may be < 0 or >= 24
            raw_ra = (lst[i] % TWOPI - raw_ha) / TWOPI * 24.0
        rd = run['r2'][i] / DEG
        if c['flip_writing'] == 'pm180':
            rd = float(wrap180(rd))
        else:
            rd = rd % 360.0
        lines.append('%s %s %s %s  %s ' % (sexa(ra_h % 24.0, 4, False), sexa(dec_d, 3, True),
                                            sexa(raw_ra, 4, False), sexa(rd, 3, True, 2),
                                            lst_field(lst[i])))
        rec_line[i] = len(lines)
    lines.append('END')
    nl = '\r\n' if c['csv_style'] == 3 else '\n'
    with open(path, 'w', newline='') as f:
        f.write(nl.join(lines) + nl)
    return rec_line


def write_tpoint_altaz(c, obs, run, path):
    lines = []
    for L in truth_lines(c, run):
        lines.append('! ' + L)
    lines.append('! observed AZ/EL then raw AZ/EL, degrees, azimuth from south through east')
    lines.append('Simulated alt-az mount (tpoint_gen seed %d)' % c['seed'])
    lines.append(': ALTAZ')
    t0 = _ap()['Time'](c['mjd_start'], format='mjd', scale='utc').datetime
    lines.append('%s %d %d %d %.1f %.1f %.1f %.2f'
                 % (sexa(c['lat'], 1, True), t0.year, t0.month, t0.day, c['temp_c'], run['pressure_file'],
                    c['height'], c['humidity']))
    rec_line = {}
    for i in range(obs['n']):
        A_obs = (180.0 - run['az_written'][i] / DEG) % 360.0
        E_obs = run['el_written'][i] / DEG
        az_raw = run['r1'][i] / DEG               # continuous (cable wrap), N through E
        A_raw = 180.0 - az_raw                    # S through E
        if c['az_writing'] == '0360':
            A_raw = A_raw % 360.0
        elif c['az_writing'] == 'pm180':
            A_raw = float(wrap180(A_raw))
        E_raw = run['r2'][i] / DEG
        lines.append('%.7f %.7f %.7f %.7f' % (A_obs, E_obs, A_raw, E_raw))
        rec_line[i] = len(lines)
    lines.append('END')
    with open(path, 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return rec_line


def write_named_altaz(c, obs, run, path):
    lines = []
    for L in truth_lines(c, run):
        lines.append('# ' + L)
    lines.append('# latitude: %.6f' % c['lat'])
    lines.append('# mount: altaz')
    lines.append('# tau delta T D temp time')
    rec_line = {}
    for i in range(obs['n']):
        lines.append('%.7f %.7f %.7f %.7f %.2f %.6f' % (
            run['r1'][i] / DEG, run['r2'][i] / DEG, run['az_written'][i] / DEG,
            run['el_written'][i] / DEG, obs['temp'][i], obs['tsec'][i] / 3600.0))
        rec_line[i] = len(lines)
    with open(path, 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return rec_line


def _fmt_ra(h, style):
    if style in (0, 3):
        return sexa(h % 24.0, 4, False).replace(' ', ':')
    if style == 1:
        return '%.7f' % (h % 24.0)
    s = sexa(h % 24.0, 3, False).split()
    return '%sh%sm%ss' % (s[0], s[1], s[2])


def _fmt_dec(d, style):
    if style in (0, 3):
        return sexa(d, 3, True).replace(' ', ':')
    if style == 1:
        return '%+.7f' % d
    s = sexa(d, 2, True).split()
    return '%sd%sm%ss' % (s[0], s[1], s[2])


def write_csv(c, obs, run, path):
    """N.I.N.A./ASCOM-style log: the mount's RA/Dec as its driver reports them (sky place, J2000
    through the driver's conversion, or JNow), the solved place, ASCOM side of pier, temperature."""
    A = _ap()
    u = A['u']
    n = obs['n']
    side = obs['side'] if c['mount'] == 'gem' else np.ones(n, int)
    # the driver: raw axes -> sky HA/Dec (folding beyond the pole) -> RA = LST - HA
    h_enc = run['r1']
    d_enc = run['r2']
    h_sky, d_sky = angles(vec(h_enc, d_enc))      # the sky place of the raw reading
    side = np.where(np.cos(d_enc) < 0, -1, 1) if c['mount'] == 'gem' else side
    ra_m_app = np.mod(obs['lst'] - h_sky, TWOPI)
    t = A['Time'](obs['mjd'], format='mjd', scale='utc')
    if c['csv_equinox'] == 'J2000':
        sc = A['SkyCoord'](ra=ra_m_app * u.rad, dec=d_sky * u.rad,
                           frame=A['TETE'](obstime=t)).transform_to(A['ICRS']())
        ra_m, dec_m = sc.ra.rad, sc.dec.rad
        ra_s, dec_s = obs['ra'], obs['dec']
    else:
        ra_m, dec_m = ra_m_app, d_sky
        ra_s, dec_s = obs['ra_app'], obs['dec_app']
    st = c['csv_style']
    sep = ';' if st == 2 else ','
    pier_words = [('pierEast', 'pierWest'), ('East', 'West'), ('E', 'W'), ('+1', '-1')][st]
    lines = []
    for L in truth_lines(c, run):
        lines.append('# ' + L)
    lines.append('# equinox: %s' % c['csv_equinox'])
    lines.append('# latitude: %.6f' % c['lat'])
    lines.append('# longitude: %.6f' % c['lon'])
    lines.append('# height: %.1f' % c['height'])
    lines.append('# pressure: %.2f' % run['pressure_file'])
    if st != 1:
        lines.append('# temperature: %.2f' % c['temp_c'])
    lines.append('# humidity: %.2f' % c['humidity'])
    lines.append('# wavelength: %.2f' % c['wavelength'])
    has_pier = not (c['mount'] == 'fork' and st == 2)
    hdr = ['Time (UTC)', 'Target', 'Mount RA', 'Mount Dec', 'Solved RA', 'Solved Dec']
    if has_pier:
        hdr.append('Pier Side')
    hdr.append('Temperature')
    lines.append(sep.join(hdr))
    rec_line = {}
    for i in range(n):
        tt = t[i].datetime
        if st == 3:
            ts = tt.strftime('%Y-%m-%dT%H:%M:%S.') + '%03d+00:00' % (tt.microsecond // 1000)
        else:
            ts = tt.strftime('%Y-%m-%dT%H:%M:%S.') + '%03dZ' % (tt.microsecond // 1000)
        row = [ts, '"Star %d, field"' % (i + 1) if sep == ',' else 'Star %d' % (i + 1),
               _fmt_ra(ra_m[i] / TWOPI * 24, st), _fmt_dec(dec_m[i] / DEG, st),
               _fmt_ra(ra_s[i] / TWOPI * 24, st), _fmt_dec(dec_s[i] / DEG, st)]
        if has_pier:
            row.append(pier_words[0] if side[i] > 0 else pier_words[1])
        row.append('%.2f' % obs['temp'][i])
        lines.append(sep.join(row))
        rec_line[i] = len(lines)
    with open(path, 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return rec_line


def write_four_column(c, obs, run, path):
    """The same run with astropy's observed places as the apparent places (no reduction in pmfit):
    for measuring the reduction mismatch."""
    lines = ['# four-column copy of a tpoint_gen run: encoder axes, astropy observed places (deg)',
             '# latitude: %.6f' % c['lat']]
    if c['mount'] == 'altaz':
        lines.append('# mount: altaz')
        T, D = run['az_written'] / DEG, run['el_written'] / DEG
    else:
        T, D = obs['ha_obs'] / DEG, obs['dec_obs'] / DEG
    lines.append('# tau delta T D')
    for i in range(obs['n']):
        lines.append('%.9f %.9f %.9f %.9f' % (run['r1'][i] / DEG, run['r2'][i] / DEG, T[i], D[i]))
    with open(path, 'w') as f:
        f.write('\n'.join(lines) + '\n')


def write(c, obs, run, path, truth_path=None):
    fmt = c['format']
    if fmt == 'tpoint':
        rl = write_tpoint_altaz(c, obs, run, path) if c['mount'] == 'altaz' else write_tpoint_eq(c, obs, run, path)
    elif fmt == 'csv':
        if c['mount'] == 'altaz':
            raise ValueError('CSV logs are equatorial (RA/Dec); use --format tpoint or named for alt-az')
        rl = write_csv(c, obs, run, path)
    elif fmt == 'named':
        if c['mount'] != 'altaz':
            raise ValueError('--format named is written for alt-az runs only')
        rl = write_named_altaz(c, obs, run, path)
    else:
        raise ValueError('unknown format ' + fmt)
    truth = truth_record(c, run, path)
    truth['record_lines'] = [rl[i] for i in range(obs['n'])]
    truth['outlier_lines'] = sorted(rl[i] for i, s in run['outliers'])
    truth['run'] = path
    if truth_path is None:
        truth_path = path + '.truth.json'
    if truth_path:
        with open(truth_path, 'w') as f:
            json.dump(truth, f, indent=1, default=float)
    return truth


def generate(c, effects, path, truth_path=None, obs=None, noise_seed=None):
    if obs is None:
        obs = observe(c)
    run = make_run(c, obs, effects, noise_seed=noise_seed)
    return write(c, obs, run, path, truth_path), obs, run


# ----------------------------------------------------------------------------------------------
# self-test: the exact gimbal against TPOINT's first-order formulas (docs/formats.md)

def selftest():
    rng = np.random.default_rng(1)
    n = 4000
    ok = True
    for mount in ('eq', 'altaz'):
        for scale in (10.0, 1.0):
            phi = 47.0 * DEG
            r1 = rng.uniform(-math.pi, math.pi, n)
            r2 = rng.uniform(-75, 75, n) * DEG
            if mount == 'eq':
                flip = rng.random(n) < 0.5
                r2 = np.where(flip, math.pi - r2, r2)
            t = {k: rng.uniform(-2, 2) * scale * AS for k in ('I1', 'I2', 'C', 'N', 'T1', 'T2', 'TF')}
            if mount == 'eq':
                MA, ME = t['T1'], t['T2']
                v = gimbal(r1 + t['I1'], r2 + t['I2'], t['N'], t['C'], -MA, -ME)
                Z = np.array([math.cos(phi), 0, math.sin(phi)])
            else:
                AN, AW = t['T1'], t['T2']
                v = gimbal(r1 + t['I1'], r2 + t['I2'], t['N'], t['C'], -AW, AN)
                Z = np.array([0, 0, 1.0])
            el = np.arcsin(v @ Z)
            v = toward(v, Z, -t['TF'] * np.cos(el))
            a, b = angles(v)
            # the same point, read on the raw branch (beyond the pole: (a+180, 180-b))
            if mount == 'eq':
                far = np.cos(r2) < 0
                a = np.where(far, a + math.pi, a)
                b = np.where(far, math.pi - b, b)
            da = wrap_pi(a - r1)
            db = wrap_pi(b - r2)
            h, d = r1, r2
            if mount == 'eq':
                cphi, sphi = math.cos(phi), math.sin(phi)
                sel = np.arcsin(np.sin(phi) * np.sin(d) + cphi * np.cos(d) * np.cos(h))
                fh = (t['I1'] + t['C'] / np.cos(d) + t['N'] * np.tan(d) - MA * np.cos(h) * np.tan(d)
                      + ME * np.sin(h) * np.tan(d) + t['TF'] * cphi * np.sin(h) / np.cos(d))
                fd = (t['I2'] + MA * np.sin(h) + ME * np.cos(h)
                      + t['TF'] * (cphi * np.cos(h) * np.sin(d) - sphi * np.cos(d)))
                e1 = (da - fh) * np.cos(d)
                e2 = db - fd
            else:
                A = math.pi - h          # TPOINT azimuth, S through E
                E = d
                fA = (-t['I1'] - t['C'] / np.cos(E) - t['N'] * np.tan(E) + AN * np.sin(A) * np.tan(E)
                      - AW * np.cos(A) * np.tan(E))
                fE = t['I2'] + AN * np.cos(A) + AW * np.sin(A) - t['TF'] * np.cos(E)
                e1 = (-da - fA) * np.cos(E)
                e2 = db - fE
            err = np.max(np.hypot(e1, e2)) / AS
            print('selftest %-5s terms ~%4.1f": max |exact - first order| = %.6f"' % (mount, 2 * scale, err))
            lim = 0.05 if scale == 10.0 else 0.0005
            if not err < lim:
                ok = False
    # Newton round trip
    c = draw_config(3, mount='gem', n=60, sky='full', aniso=30.0, aniso_beyond=2.0, index_deg=5.0)
    obs = observe(c)
    run = make_run(c, obs, [dict(name='ha_pe', size=3.0), dict(name='backlash', size=2.0)])
    print('selftest newton: %d points solved' % len(run['r1']))
    print('selftest', 'PASSED' if ok else 'FAILED')
    return ok


# ----------------------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('out', nargs='?', help='output run file')
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--mount', choices=['gem', 'fork', 'altaz'], default='gem')
    ap.add_argument('--n', type=int)
    ap.add_argument('--noise', type=float, help='arcsec per axis on the sky')
    ap.add_argument('--format', choices=['tpoint', 'csv', 'named'], default=None)
    ap.add_argument('--effect', action='append', default=[],
                    help='NAME:SIZE[:k=v,...]; NAME one of ' + ', '.join(sorted(set(EFFECTS_EQ + EFFECTS_AZ)))
                    + '. Sizes in arcsec (temperature: per deg C; drift: per hour; pe: axis-angle'
                    ' amplitude; backlash: half the backlash; outlier: the miss)')
    ap.add_argument('--sky', choices=['full', 'half', 'band', 'oneside'])
    ap.add_argument('--lat', type=float)
    ap.add_argument('--aniso', type=float, help='RMS (arcsec) of the smooth in-span anisotropy')
    ap.add_argument('--aniso-beyond', type=float, help='RMS (arcsec) of the anisotropy beyond order 1')
    ap.add_argument('--aniso-frame', choices=['mech', 'encoder'],
                    help='anisotropy as a function of the mechanical (true) axis angles (default) or of the raw encoder angles')
    ap.add_argument('--flip-writing', choices=['pm180', '0360'])
    ap.add_argument('--flip-side', choices=['west', 'east'])
    ap.add_argument('--ra-writing', choices=['std', 'cont', 'neg'])
    ap.add_argument('--az-writing', choices=['0360', 'pm180', 'wrap'])
    ap.add_argument('--csv-equinox', choices=['J2000', 'JNow'])
    ap.add_argument('--order', choices=['zigzag', 'ha', 'nearest'])
    ap.add_argument('--el-limit', type=float)
    ap.add_argument('--hours', type=float)
    ap.add_argument('--index-deg', type=float)
    ap.add_argument('--tilt-arcmin', type=float)
    ap.add_argument('--term', action='append', default=[],
                    help='NAME=ARCSEC: set a mount term (IH ID CH NP MA ME TF; alt-az IA IE CA NPAE AN AW TF)')
    ap.add_argument('--outlier-frac', type=float, help='fraction of gross outliers (10-100 sigma)')
    ap.add_argument('--noise-seed', type=int)
    ap.add_argument('--truth', help='truth JSON path (default OUT.truth.json; "" for none)')
    ap.add_argument('--four-column', help='also write the run with astropy places as a four-column file')
    ap.add_argument('--selftest', action='store_true')
    a = ap.parse_args(argv)
    if a.selftest:
        return 0 if selftest() else 1
    if not a.out:
        ap.error('OUT is required')
    fmt = a.format or ('tpoint')
    c = draw_config(a.seed, mount=a.mount, n=a.n, noise=a.noise, sky=a.sky, lat=a.lat, aniso=a.aniso,
                    aniso_beyond=a.aniso_beyond, fmt=fmt, flip_writing=a.flip_writing,
                    flip_side=a.flip_side, ra_writing=a.ra_writing, order=a.order, el_limit=a.el_limit,
                    hours=a.hours, index_deg=a.index_deg, tilt_arcmin=a.tilt_arcmin,
                    outlier_frac=a.outlier_frac, csv_equinox=a.csv_equinox, az_writing=a.az_writing,
                    terms={t.split('=')[0]: float(t.split('=')[1]) for t in a.term}, aniso_frame=a.aniso_frame)
    effects = [parse_effect(s) for s in a.effect]
    for e in effects:
        if e['size'] is None:
            ap.error('effect %s needs a size' % e['name'])
        if e['name'] == 'temperature' and fmt == 'tpoint':
            sys.stderr.write('warning: TPOINT records carry no temperature: the effect is in the run, '
                             'but no reader can see it (use --format csv, or named for alt-az)\n')
        if e['name'] == 'drift' and fmt == 'tpoint' and a.mount == 'altaz':
            sys.stderr.write('warning: TPOINT alt-az records carry no time (use --format named)\n')
    truth, obs, run = generate(c, effects, a.out, truth_path=a.truth, noise_seed=a.noise_seed)
    if a.four_column:
        write_four_column(c, obs, run, a.four_column)
    sys.stderr.write('wrote %s: %s mount, %d points, %s\n' % (a.out, c['mount'], c['n'],
                     ', '.join('%s=%g' % (e['name'], e['size']) for e in run['effects']) or 'nothing hidden'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
