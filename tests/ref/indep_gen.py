#!/usr/bin/env python3
"""indep_gen.py - an independent simulator of pointing runs (numpy only).

Nothing here uses the C library or its formulas (no spherical harmonics, no
base vectors, no exponential map).  The mount is a physical gimbal of small
rotations, in the style of tests/ref/flip_gem.py:

    p = R_tilt  Rz(th1)  Rx(NP)  Ry(-th2)  (cos CH, sin CH, 0)

    th1 = enc1 - I1 + (errors of the axis-1 angle)     axis 1 (HA / azimuth), about z
    th2 = enc2 - I2 + (errors of the axis-2 angle)     axis 2 (Dec / elevation), along y at th1 = 0
    R_tilt = Rx(TX) Ry(TY)                             polar / azimuth axis tilt (two components)
    NP, CH                                             axis non-perpendicularity, collimation

in the frame where (th1, th2) = (tau, delta) give (cos d cos t, cos d sin t, sin d):
for an equatorial mount x = meridian on the equator, z = the pole; for an
alt-az mount x = north, y = east, z = the zenith (azimuth north through east).
The encoders read enc = true axis angle + index (I1, I2 up to degrees).

A German equatorial mount (gem) points west of the meridian from the other
pier side (pier 'W'), beyond the pole: the encoders read (H + 180 + I1,
180 - dec + I2); within 15 deg of the meridian either side is used.  A fork
(fork) never flips (pier 'E' always).  Alt-az (altaz): no pier column.

Anisotropic distortions ("--aniso S"): each of the six gimbal parameters
(both axis angles, NP, CH, both tilts) varies over the sky as a random
combination of smooth functions of the mechanical direction u = (cos a2 cos
a1, cos a2 sin a1, sin a2), a = the true axis angles (enc - index: where the
mount's parts are; --aniso-frame encoder: of the encoder reading e instead,
as this generator did before pm evaluated its harmonics at the mechanical
position): degree 1 (x, y, z) by default, degree 2 (xy, xz, yz, x^2 - y^2,
3z^2 - 1) with --aniso-order 2; scaled so that the distortion moves the
run's points by S arcsec RMS (--aniso-params: only some of the six
parameters vary).

Hidden effects ("--effect NAME=SIZE[:G]", SIZE in arcsec; what pmfit explain
reports as amplitude_arcsec):

  ha_periodic (az_periodic)  th1 += A cos(G*enc1 + phase)     enc1 = the encoder reading
  dec_periodic (el_periodic) th2 += A cos(G*enc2 + phase)     as written in the file
                             (either more than once: gears on one axis, each its own G)
  refraction                 the observed place is R*cot(el) nearer the zenith than
                             where the gimbal points (times --zenith-sign, default +1:
                             positive = toward the zenith, docs/model.md)
  tube_flexure               likewise F*cos(el) (a real sag is F < 0)
  temperature                th1 += s1*K*(T - mean T), th2 += s2*K*(T - mean T), K arcsec/degC,
                             s1, s2 = +-1 drawn per run (truth gives them)
  time_drift                 the same with (t - mean t), K arcsec per hour
  hysteresis                 th1 += B*dir, dir = sign of the last slew on axis 1 (column dir)
  pier_side                  (gem only) extra collimation C on pier side 'W' only
  outlier                    a fraction (--outliers, default 1%) of the points moved by
                             U(SIZE/2, 3 SIZE/2) arcsec in a random direction (SIZE 40: 20-60")
  higher_order               an extra degree-2 distortion (as --aniso-order 2) of SIZE RMS

The observation: targets uniform on the sky above --el-limit (or part of it,
--coverage), visited in nearest-neighbour order of the slew (the longer axis
move), 2 minutes per point, a temperature that falls through the night
exponentially with a random walk on top, Gaussian noise on the sky (axis 1
scaled by sec(axis 2), as flip_gem.py).  Independent random streams per part
(targets, geometry, noise, each effect), so adding an effect changes nothing
else of the run.

Writes the named-column format (docs/formats.md, "2. Named-column format"):
  # latitude: LAT
  # mount: equatorial | altaz
  # tau delta T D pier temp time dir     (equatorial)
  # tau delta T D temp time dir          (alt-az)
with 8 decimals on angles; encoder angles and apparent HA in (-180, 180],
apparent azimuth in [0, 360).

Usage:
  python3 tests/ref/indep_gen.py OUT [--mount gem|fork|altaz] [--n N] [--seed S]
      [--lat DEG] [--el-limit DEG] [--noise AS] [--coverage full|half|band|pier_east]
      [--index-deg X | --index I1,I2] [--geom AS] [--aniso AS] [--aniso-order 1|2]
      [--aniso-params all|axis1,axis2,np,coll,tilt_x,tilt_y]
      [--effect NAME=SIZE[:G]] ... [--outliers FRAC] [--zenith-sign +1|-1]
      [--truth-json FILE]

As a module: rows, truth = indep_gen.gen({'mount': 'gem', 'n': 200, ...});
indep_gen.write_run(path, rows, truth).
"""
import argparse
import json
import sys
import zlib

import numpy as np

DEG = np.pi / 180.0
AS = DEG / 3600.0

MOUNTS = ("gem", "fork", "altaz")
COVERAGES = ("full", "half", "band", "pier_east")
EFFECTS = ("ha_periodic", "dec_periodic", "refraction", "tube_flexure", "temperature",
           "time_drift", "hysteresis", "pier_side", "outlier", "higher_order")
ANISO_PARAMS = ("axis1", "axis2", "np", "coll", "tilt_x", "tilt_y")  # order of dq columns
ALIASES = {"az_periodic": "ha_periodic", "el_periodic": "dec_periodic", "outliers": "outlier",
           "pier": "pier_side", "flexure": "tube_flexure"}

DEFAULTS = {
    "mount": "gem",
    "n": 200,
    "seed": 1,
    "lat": 47.0,            # deg
    "el_limit": 15.0,       # deg
    "el_max": 88.0,         # deg, highest target elevation
    "noise": 1.0,           # arcsec per axis on the sky
    "coverage": "full",
    "index_deg": 2.0,       # index errors uniform in +-index_deg on both axes
    "index": None,          # or [I1, I2] deg: the index errors exactly
    "geom": 120.0,          # tilts, NP, CH uniform in +-geom arcsec
    "aniso": 0.0,           # RMS arcsec of the smooth distortion
    "aniso_order": 1,
    "aniso_params": "all",  # or a list of: axis1 axis2 np coll tilt_x tilt_y
    # "mechanical" (the command line's default) or "encoder": gen() takes
    # "encoder" when not given, so that the "made by" parameters of runs
    # written before the choice existed make the same run again
    "aniso_frame": "encoder",
    "effects": [],          # list of 'NAME=SIZE[:G]' or dicts {name, size, G, phase_deg}
    "outliers": None,       # fraction of points (None: 0, or 0.01 with an 'outlier' effect)
    "outlier_size": 40.0,   # middle of the outlier range: U(S/2, 3S/2)
    "zenith_sign": 1,       # +1: refraction / tube_flexure sizes positive toward the zenith
    "minutes_per_point": 2.0,
    "made_by": None,
}


# ---------------------------------------------------------------- rotations
# rot_*(a, v) = R_*(a) @ v for arrays: a (N,), v (N, 3); R_x, R_y, R_z as in flip_gem.py

def rot_x(a, v):
    c, s = np.cos(a), np.sin(a)
    return np.stack([v[:, 0], c * v[:, 1] - s * v[:, 2], s * v[:, 1] + c * v[:, 2]], axis=1)


def rot_y(a, v):
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[:, 0] + s * v[:, 2], v[:, 1], -s * v[:, 0] + c * v[:, 2]], axis=1)


def rot_z(a, v):
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1], v[:, 2]], axis=1)


def unit(t, d):
    t, d = np.asarray(t, float), np.asarray(d, float)
    return np.stack([np.cos(d) * np.cos(t), np.cos(d) * np.sin(t), np.sin(d)], axis=-1)


def angles(p):
    return np.arctan2(p[:, 1], p[:, 0]), np.arcsin(np.clip(p[:, 2], -1, 1))


def wrap180(x):
    """degrees into (-180, 180]"""
    r = np.fmod(np.asarray(x, float), 360.0)
    r = np.where(r > 180, r - 360, r)
    return np.where(r <= -180, r + 360, r)


def turn_toward(p, target, s):
    """Rotate unit vectors p by angles s (rad) along the great circle toward target (3,)."""
    z = np.broadcast_to(target, p.shape)
    zt = z - np.sum(p * z, axis=1)[:, None] * p
    nz = np.linalg.norm(zt, axis=1)
    e = zt / np.where(nz > 0, nz, 1.0)[:, None]
    return np.cos(s)[:, None] * p + np.sin(s)[:, None] * e, nz


def tangent_basis(p):
    t, d = angles(p)
    e1 = np.stack([-np.sin(t), np.cos(t), np.zeros_like(t)], axis=1)
    e2 = np.stack([-np.sin(d) * np.cos(t), -np.sin(d) * np.sin(t), np.cos(d)], axis=1)
    return e1, e2


def stream(seed, tag):
    """An independent random stream per part of the simulation."""
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, zlib.crc32(tag.encode())])


# ---------------------------------------------------------------- effects

def parse_effect(e):
    """'NAME=SIZE[:G]' or 'NAME:G=SIZE' or a dict -> {name, size, G, phase_deg}."""
    if isinstance(e, dict):
        d = dict(e)
        d["name"] = ALIASES.get(d["name"], d["name"])
        d.setdefault("G", None)
        d.setdefault("phase_deg", None)
        d["size"] = float(d["size"])
    else:
        if "=" not in e:
            raise ValueError("effect '%s': expected NAME=SIZE[:G]" % e)
        left, right = e.split("=", 1)
        name, g = (left.split(":", 1) + [None])[:2]
        parts = right.split(":")
        size = float(parts[0])
        if len(parts) > 1:
            g = parts[1]
        d = {"name": ALIASES.get(name, name), "size": size,
             "G": float(g) if g is not None else None, "phase_deg": None}
    if d["name"] not in EFFECTS:
        raise ValueError("unknown effect '%s' (known: %s)" % (d["name"], ", ".join(EFFECTS)))
    return d


def basis(u, order):
    x, y, z = u[:, 0], u[:, 1], u[:, 2]
    if order == 1:
        return np.stack([x, y, z], axis=1)
    return np.stack([x * y, x * z, y * z, x * x - y * y, 3 * z * z - 1], axis=1)


# ---------------------------------------------------------------- the run

def _targets(P, rng_t, rng_c):
    """Targets (axis-1, axis-2 of the sky, rad) and pier sides for the coverage."""
    lat = P["lat"] * DEG
    altaz = P["mount"] == "altaz"
    cov = P["coverage"]
    centre = rng_c.choice([0.0, 90.0, 180.0, 270.0]) * DEG   # for 'half'
    idx2 = abs(P["_I2"])
    t_all, d_all, side_all = [], [], []
    n = P["n"]
    s_lo, s_hi = np.sin(P["el_limit"] * DEG), np.sin(P["el_max"] * DEG)
    north = np.array([-np.sin(lat), 0.0, np.cos(lat)])
    west = np.array([0.0, 1.0, 0.0])
    zen = np.array([np.cos(lat), 0.0, np.sin(lat)])
    tries = 0
    while sum(len(x) for x in t_all) < n:
        tries += 1
        if tries > 2000:
            raise ValueError("cannot place %d targets with this coverage/latitude/limits" % n)
        m = 4 * n
        az = rng_t.uniform(0, 2 * np.pi, m)
        el = np.arcsin(rng_t.uniform(s_lo, s_hi, m))
        sidepick = rng_t.uniform(size=m) < 0.5
        keep = np.ones(m, bool)
        if cov == "half":
            keep &= np.abs(np.remainder(az - centre + np.pi, 2 * np.pi) - np.pi) <= np.pi / 2
        if altaz:
            if cov == "band":
                mer = np.pi if P["lat"] >= 0 else 0.0
                keep &= np.abs(np.remainder(az - mer + np.pi, 2 * np.pi) - np.pi) <= 60 * DEG
            elif cov == "pier_east":
                keep &= az <= np.pi
            t_all.append(az[keep])
            d_all.append(el[keep])
            side_all.append(np.zeros(keep.sum(), int))
            continue
        # horizon (north through east) -> (HA, Dec): x = meridian/equator, y = west, z = pole
        p = (np.cos(el) * np.cos(az))[:, None] * north - (np.cos(el) * np.sin(az))[:, None] * west \
            + np.sin(el)[:, None] * zen
        h, d = angles(p)
        keep &= np.abs(d) / DEG + idx2 < 89.0   # encoders stay on their side of +-90
        if cov == "band":
            keep &= np.abs(h) <= 45 * DEG
        elif cov == "pier_east":
            keep &= h <= (15 * DEG if P["mount"] == "gem" else 0.0)
        if P["mount"] == "gem" and cov != "pier_east":
            flip = np.where(np.abs(h) < 15 * DEG, sidepick, h > 0)
        else:
            flip = np.zeros(m, bool)
        t_all.append(h[keep])
        d_all.append(d[keep])
        side_all.append(np.where(flip[keep], -1, 1))
    t = np.concatenate(t_all)[:n]
    d = np.concatenate(d_all)[:n]
    side = np.concatenate(side_all)[:n]
    return t, d, side


def _order(e1c, e2c, start):
    """Nearest-neighbour sequence by slew length max(|d axis1|, |d axis2|)."""
    n = len(e1c)
    left = np.ones(n, bool)
    seq = [start]
    left[start] = False
    cur = start
    for _ in range(n - 1):
        cost = np.maximum(np.abs(e1c - e1c[cur]), np.abs(e2c - e2c[cur]))
        cost[~left] = np.inf
        cur = int(np.argmin(cost))
        seq.append(cur)
        left[cur] = False
    return np.array(seq)


def header_lines(P):
    altaz = P["mount"] == "altaz"
    made = P.get("made_by") or ("indep_gen.gen(%s)" % json.dumps(
        {k: P[k] for k in DEFAULTS if k not in ("made_by",)}, default=str, sort_keys=True))
    made = made.replace("\n", " ")
    what = {"gem": "German equatorial, flipped west of the meridian",
            "fork": "fork equatorial, never flipped", "altaz": "alt-azimuth"}[P["mount"]]
    return ["# made by: %s" % made,
            "# independent numpy gimbal (tests/ref/indep_gen.py): %s" % what,
            "# latitude: %.10g" % P["lat"],
            "# mount: %s" % ("altaz" if altaz else "equatorial"),
            "# tau delta T D temp time dir" if altaz else "# tau delta T D pier temp time dir"]


def gen(params):
    """Simulate one run.  params: dict (keys of DEFAULTS).  Returns (rows, truth):
    rows a list of dicts (tau, delta, T, D in degrees as written, pier 'E'/'W' or None,
    temp degC, time h, dir +-1), truth a JSON-able dict of the true mount and effects."""
    P = dict(DEFAULTS)
    unknown = set(params) - set(DEFAULTS)
    if unknown:
        raise ValueError("unknown parameters: %s" % ", ".join(sorted(unknown)))
    P.update(params)
    if P["mount"] not in MOUNTS:
        raise ValueError("mount must be one of %s" % (MOUNTS,))
    if P["coverage"] not in COVERAGES:
        raise ValueError("coverage must be one of %s" % (COVERAGES,))
    P["n"] = int(P["n"])
    if P["n"] < 3:
        raise ValueError("n must be >= 3")
    if not -90 <= P["lat"] <= 90:
        raise ValueError("latitude must be within -90..90")
    if P["aniso_params"] != "all":
        bad = [x for x in P["aniso_params"] if x not in ANISO_PARAMS]
        if bad:
            raise ValueError("aniso_params: unknown %s (known: %s)" % (bad, ", ".join(ANISO_PARAMS)))
    effects = [parse_effect(e) for e in P["effects"]]
    names = [e["name"] for e in effects]
    once = [x for x in names if x not in ("ha_periodic", "dec_periodic")]
    if len(set(once)) != len(once):
        raise ValueError("each effect at most once (a periodic one on an axis as often as "
                         "it has gears, each with its own :G)")
    if "pier_side" in names and P["mount"] != "gem":
        raise ValueError("pier_side needs --mount gem")
    if "pier_side" in names and P["coverage"] == "pier_east":
        raise ValueError("pier_side needs both pier sides (not --coverage pier_east)")
    seed = int(P["seed"])
    altaz = P["mount"] == "altaz"
    n = P["n"]

    # geometry
    rg = stream(seed, "geometry")
    I1, I2 = rg.uniform(-1, 1, 2) * P["index_deg"]
    if P["index"] is not None:
        I1, I2 = float(P["index"][0]), float(P["index"][1])
    TX, TY, NP, CH = rg.uniform(-1, 1, 4) * P["geom"]
    P["_I2"] = I2

    # targets, encoder readings, order of the visits
    t, d, side = _targets(P, stream(seed, "targets"), stream(seed, "coverage"))
    flip = side < 0
    e1 = np.where(flip, t / DEG + 180.0, t / DEG) + I1      # continuous (no wrap) in degrees
    if altaz:
        e1 = np.remainder(t / DEG, 360.0) + I1
    e2 = np.where(flip, 180.0 - d / DEG, d / DEG) + I2
    ro = stream(seed, "order")
    seq = _order(e1, e2, int(ro.integers(n)))
    t, d, side, flip, e1, e2 = t[seq], d[seq], side[seq], flip[seq], e1[seq], e2[seq]
    park = 180.0 + I1 if altaz else 0.0
    prev = np.concatenate([[park], e1[:-1]])
    sdir = np.where(e1 - prev >= 0, 1, -1)

    # the written encoder readings (these are what the encoders say)
    tau_w = np.round(wrap180(e1), 8)
    delta_w = np.round(wrap180(e2), 8)
    enc1, enc2 = tau_w * DEG, delta_w * DEG

    # time and temperature
    rw = stream(seed, "weather")
    t0 = rw.uniform(19.0, 22.0)
    time_h = np.round(t0 + np.arange(n) * P["minutes_per_point"] / 60.0, 5)
    T0, dT, tau_c = rw.uniform(5, 20), rw.uniform(3, 8), rw.uniform(1.5, 4.0)
    temp = T0 - dT * (1 - np.exp(-(time_h - t0) / tau_c)) + np.cumsum(rw.normal(0, 0.04, n))
    temp = np.round(temp, 2)

    # effects: parameters (own streams)
    eff = {}
    truth_eff = []
    for k, e in enumerate(effects):
        # (a second periodic effect on one axis draws from its own stream;
        # the first keeps the stream it always had)
        again = sum(1 for f in effects[:k] if f["name"] == e["name"])
        r = stream(seed, "effect:" + e["name"] + ("#%d" % again if again else ""))
        name, A = e["name"], e["size"]
        x = {"name": name, "size_arcsec": A, "explain_effect": name}
        if name in ("ha_periodic", "dec_periodic"):
            G = e["G"] if e["G"] is not None else float(r.integers(100, 400))
            ph = e["phase_deg"] if e["phase_deg"] is not None else r.uniform(0, 360)
            x.update(G=G, phase_deg=ph, explain_amplitude_arcsec=abs(A))
            # the phase pmfit reports (atan2(s, c) of c cos(G enc) + s sin(G enc) on c' / e')
            exp_ph = -ph if name == "ha_periodic" else 180.0 - ph
            if A < 0:
                exp_ph += 180.0
            x["explain_phase_deg"] = float(wrap180(exp_ph))
            e.update(G=G, phase_deg=ph)
        elif name in ("refraction", "tube_flexure"):
            c = P["zenith_sign"] * A
            x.update(coefficient_arcsec=c, explain_amplitude_arcsec=abs(c),
                     convention="positive toward the zenith")
        elif name in ("temperature", "time_drift"):
            s1, s2 = r.choice([-1, 1], 2)
            e.update(s1=int(s1), s2=int(s2))
            x.update(axis1_per_unit=s1 * A, axis2_per_unit=s2 * A,
                     explain_c_prime=s1 * A, explain_e_prime=-s2 * A,
                     explain_amplitude_arcsec=abs(A),
                     unit="arcsec per degC" if name == "temperature" else "arcsec per hour")
        elif name == "hysteresis":
            x.update(explain_c_prime=A, explain_amplitude_arcsec=abs(A))
        elif name == "pier_side":
            x.update(extra_collimation_west_arcsec=A, explain_amplitude_arcsec=abs(A))
        elif name == "higher_order":
            x.update(explain_amplitude_arcsec=None,
                     note="degree-2 distortion; pmfit's amplitude is the RMS its order-2 terms "
                          "add beyond order 1, only part of this")
        if name in ("ha_periodic", "dec_periodic"):
            eff.setdefault(name, []).append(e)
        else:
            eff[name] = e
        truth_eff.append(x)

    # anisotropic distortion coefficients (unit scale, normalised below),
    # functions of the mechanical (true) axis angles, or of the encoders
    if P["aniso_frame"] == "encoder":
        u_enc = unit(enc1, enc2)
    else:
        u_enc = unit(enc1 - I1 * DEG, enc2 - I2 * DEG)
    ra = stream(seed, "aniso")
    B1 = basis(u_enc, int(P["aniso_order"]))
    Ca = ra.normal(size=(6, B1.shape[1]))
    if P["aniso_params"] != "all":
        for j, nm in enumerate(ANISO_PARAMS):
            if nm not in P["aniso_params"]:
                Ca[j] = 0.0
    dq_aniso = (B1 @ Ca.T)                      # (n, 6), in units to be scaled
    if "higher_order" in eff:
        rh = stream(seed, "effect:higher_order:coef")
        B2 = basis(u_enc, 2)
        dq_ho = B2 @ rh.normal(size=(6, B2.shape[1])).T
    else:
        dq_ho = np.zeros((n, 6))

    lat = P["lat"] * DEG
    zen = np.array([0.0, 0.0, 1.0]) if altaz else np.array([np.cos(lat), 0.0, np.sin(lat)])

    def gimbal(dq, with_effects):
        x1 = np.zeros(n)
        x2 = np.zeros(n)
        coll = np.zeros(n)
        if with_effects:
            for e in eff.get("ha_periodic", []):
                x1 += e["size"] * AS * np.cos(e["G"] * enc1 + e["phase_deg"] * DEG)
            for e in eff.get("dec_periodic", []):
                x2 += e["size"] * AS * np.cos(e["G"] * enc2 + e["phase_deg"] * DEG)
            for nm, xv in (("temperature", temp), ("time_drift", time_h)):
                if nm in eff:
                    e = eff[nm]
                    x1 += e["s1"] * e["size"] * AS * (xv - xv.mean())
                    x2 += e["s2"] * e["size"] * AS * (xv - xv.mean())
            if "hysteresis" in eff:
                x1 += eff["hysteresis"]["size"] * AS * sdir
            if "pier_side" in eff:
                coll += np.where(flip, eff["pier_side"]["size"] * AS, 0.0)
        th1 = enc1 - I1 * DEG + x1 + dq[:, 0]
        th2 = enc2 - I2 * DEG + x2 + dq[:, 1]
        ch = CH * AS + coll + dq[:, 3]
        v = np.stack([np.cos(ch), np.sin(ch), np.zeros(n)], axis=1)
        v = rot_y(-th2, v)
        v = rot_x(NP * AS + dq[:, 2], v)
        v = rot_z(th1, v)
        v = rot_y(TY * AS + dq[:, 5], v)
        v = rot_x(TX * AS + dq[:, 4], v)
        if with_effects:
            for nm, f in (("refraction", "cot"), ("tube_flexure", "cos")):
                if nm in eff:
                    c = P["zenith_sign"] * eff[nm]["size"] * AS
                    sin_el = v @ zen
                    cos_el = np.sqrt(np.maximum(0.0, 1 - sin_el ** 2))
                    amt = c * (cos_el / np.maximum(sin_el, 0.01) if f == "cot" else cos_el)
                    v, _ = turn_toward(v, zen, amt)
        return v / np.linalg.norm(v, axis=1)[:, None]

    def rms_sep(a, b):
        return float(np.sqrt(np.mean(np.arccos(np.clip(np.sum(a * b, axis=1), -1, 1)) ** 2)))

    p_plain = gimbal(np.zeros((n, 6)), False)
    scale_a = 0.0
    if P["aniso"] > 0:
        r1 = rms_sep(gimbal(dq_aniso * AS, False), p_plain) / AS
        scale_a = P["aniso"] / r1 if r1 > 0 else 0.0
    scale_h = 0.0
    if "higher_order" in eff:
        r2 = rms_sep(gimbal(dq_ho * AS, False), p_plain) / AS
        scale_h = eff["higher_order"]["size"] / r2 if r2 > 0 else 0.0
    dq = (dq_aniso * scale_a + dq_ho * scale_h) * AS
    p = gimbal(dq, True)
    aniso_rms = rms_sep(gimbal(dq_aniso * scale_a * AS, False), p_plain) / AS if scale_a else 0.0

    # outliers (own stream)
    frac = P["outliers"]
    if frac is None:
        frac = 0.01 if "outlier" in eff else 0.0
    out_list = []
    if frac > 0:
        ro = stream(seed, "effect:outlier")
        k = max(1, int(round(frac * n)))
        which = np.sort(ro.choice(n, size=k, replace=False))
        S = eff["outlier"]["size"] if "outlier" in eff else P["outlier_size"]
        sizes = ro.uniform(0.5, 1.5, k) * S
        psi = ro.uniform(0, 2 * np.pi, k)
        e1v, e2v = tangent_basis(p[which])
        dirv = np.cos(psi)[:, None] * e1v + np.sin(psi)[:, None] * e2v
        s = sizes * AS
        p[which] = np.cos(s)[:, None] * p[which] + np.sin(s)[:, None] * dirv
        nh = len(header_lines(P))
        for j, i in enumerate(which):
            out_list.append({"index": int(i), "line": int(nh + 1 + i), "size_arcsec": float(sizes[j]),
                             "direction_deg": float(psi[j] / DEG)})
        if "outlier" not in eff:
            truth_eff.append({"name": "outlier", "explain_effect": "outlier", "size_arcsec": S})
        for x in truth_eff:
            if x["name"] == "outlier":
                x.update(fraction=frac, count=k,
                         explain_amplitude_arcsec=float(sizes.max()),
                         lines=[o["line"] for o in out_list])

    # noise on the sky: axis 2, and axis 1 scaled by sec(axis 2)
    a1, a2 = angles(p)
    rn = stream(seed, "noise")
    nz = rn.normal(0, P["noise"] * AS, (n, 2))
    a1 = a1 + nz[:, 0] / np.cos(a2)
    a2 = a2 + nz[:, 1]

    T = np.round(np.remainder(a1 / DEG, 360.0) if altaz else wrap180(a1 / DEG), 8)
    T = np.where(T >= 360.0, T - 360.0, T)
    D = np.round(a2 / DEG, 8)
    rows = []
    for i in range(n):
        rows.append({"tau": float(tau_w[i]), "delta": float(delta_w[i]), "T": float(T[i]),
                     "D": float(D[i]), "pier": None if altaz else ("W" if flip[i] else "E"),
                     "temp": float(temp[i]), "time": float(time_h[i]), "dir": int(sdir[i])})

    el = np.arcsin(np.clip(p @ zen, -1, 1)) / DEG
    truth = {
        "generator": "tests/ref/indep_gen.py",
        "params": {k: P[k] for k in DEFAULTS if k != "effects"},
        "mount": P["mount"], "n": n, "seed": seed, "latitude_deg": P["lat"],
        "noise_arcsec": P["noise"],
        "geometry": {"index1_deg": float(I1), "index2_deg": float(I2),
                     "tilt_x_arcsec": float(TX), "tilt_y_arcsec": float(TY),
                     "np_arcsec": float(NP), "collimation_arcsec": float(CH),
                     "note": "encoder = true axis angle + index; p = Rx(TX) Ry(TY) Rz(th1) Rx(NP) "
                             "Ry(-th2) (cos CH, sin CH, 0)"},
        "aniso": {"level_arcsec": P["aniso"], "order": int(P["aniso_order"]),
                  "rms_arcsec": aniso_rms,
                  "coefficients_arcsec": (Ca * scale_a).tolist()},
        "effects": truth_eff,
        "outliers": out_list,
        "n_west": int(flip.sum()), "n_east": int((~flip).sum()) if not altaz else 0,
        "elevation_range_deg": [float(el.min()), float(el.max())],
        "hours": float(time_h[-1] - time_h[0]),
        "temp_range_c": [float(temp.min()), float(temp.max())],
        "header": header_lines(P),
    }
    return rows, _jsonable(truth)


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.floating):
        return float(x)
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    return x


def write_run(path, rows, truth):
    altaz = truth["mount"] == "altaz"
    with open(path, "w") as f:
        for h in truth["header"]:
            f.write(h + "\n")
        for r in rows:
            if altaz:
                f.write("%.8f %.8f %.8f %.8f %.2f %.5f %+d\n" % (
                    r["tau"], r["delta"], r["T"], r["D"], r["temp"], r["time"], r["dir"]))
            else:
                f.write("%.8f %.8f %.8f %.8f %s %.2f %.5f %+d\n" % (
                    r["tau"], r["delta"], r["T"], r["D"], r["pier"], r["temp"], r["time"],
                    r["dir"]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--mount", choices=MOUNTS, default=DEFAULTS["mount"])
    ap.add_argument("--n", type=int, default=DEFAULTS["n"])
    ap.add_argument("--seed", type=int, default=DEFAULTS["seed"])
    ap.add_argument("--lat", type=float, default=DEFAULTS["lat"])
    ap.add_argument("--el-limit", type=float, default=DEFAULTS["el_limit"])
    ap.add_argument("--noise", type=float, default=DEFAULTS["noise"], help="arcsec per axis")
    ap.add_argument("--coverage", choices=COVERAGES, default=DEFAULTS["coverage"])
    ap.add_argument("--index-deg", type=float, default=DEFAULTS["index_deg"])
    ap.add_argument("--index", default=None, metavar="I1,I2",
                    help="the two index errors exactly (deg), instead of --index-deg")
    ap.add_argument("--geom", type=float, default=DEFAULTS["geom"],
                    help="tilts, NP, collimation uniform in +-GEOM arcsec")
    ap.add_argument("--aniso", type=float, default=DEFAULTS["aniso"], help="RMS arcsec")
    ap.add_argument("--aniso-order", type=int, choices=(1, 2), default=DEFAULTS["aniso_order"])
    ap.add_argument("--aniso-params", default="all",
                    help="which gimbal parameters vary: all, or a comma list of %s" % (
                        ",".join(ANISO_PARAMS)))
    ap.add_argument("--aniso-frame", choices=("mechanical", "encoder"), default="mechanical",
                    help="the anisotropy a function of the true axis angles (default) or of the "
                         "encoder readings")
    ap.add_argument("--effect", action="append", default=[], metavar="NAME=SIZE[:G]")
    ap.add_argument("--outliers", type=float, default=None, metavar="FRAC")
    ap.add_argument("--outlier-size", type=float, default=DEFAULTS["outlier_size"])
    ap.add_argument("--zenith-sign", type=int, choices=(-1, 1), default=1)
    ap.add_argument("--truth-json", default=None)
    a = ap.parse_args(argv)
    params = {"mount": a.mount, "n": a.n, "seed": a.seed, "lat": a.lat, "el_limit": a.el_limit,
              "noise": a.noise, "coverage": a.coverage, "index_deg": a.index_deg,
              "geom": a.geom, "aniso": a.aniso, "aniso_order": a.aniso_order,
              "aniso_params": a.aniso_params if a.aniso_params == "all" else
              a.aniso_params.split(","), "aniso_frame": a.aniso_frame,
              "index": [float(x) for x in a.index.split(",")] if a.index else None,
              "effects": a.effect, "outliers": a.outliers, "outlier_size": a.outlier_size,
              "zenith_sign": a.zenith_sign,
              "made_by": "python3 tests/ref/indep_gen.py " + " ".join(
                  sys.argv[1:] if argv is None else argv)}
    try:
        rows, truth = gen(params)
    except ValueError as e:
        sys.exit("indep_gen.py: %s" % e)
    write_run(a.out, rows, truth)
    if a.truth_json:
        with open(a.truth_json, "w") as f:
            json.dump(truth, f, indent=1)
    print("indep_gen.py: wrote %s (%d points, %s)" % (a.out, len(rows), a.mount), file=sys.stderr)


if __name__ == "__main__":
    main()
