#!/usr/bin/env python3
"""flip_gem.py - a German equatorial mount run that flips over the pole,
written the two ways controllers write encoder angles.

Independent of the C library (numpy only).  The mount is a gimbal with its
own small rotations, not the library's model:

    p_app = R_polar  Rz(h_e - IH)  Rx(NP)  Ry(-(d_e - ID))  (cos CH, sin CH, 0)

(HA axis = z, the declination axis along y at h = 0, the tube at CH from
perpendicular to it), plus a tube sag toward the zenith (TF cos el) and
Gaussian noise on the sky.  The encoder angles go beyond the pole exactly as
a flipped German mount reads them: east of the meridian the telescope is on
the other pier side, at (H + 180, 180 - dec) -- a southern target there
reads 180 - (-14) = 194 deg.

Writes, from one set of readings (tests/data):

  flip_gem_pm180.dat  encoder and apparent angles in (-180, 180] deg
  flip_gem_0360.dat   the same readings with every angle in [0, 360) deg,
                      as many controllers write them (194.17 for -165.83)

Both are printed with 8 decimals: x and x - 360 print the same digits, so
the two files hold exactly the same decimal readings modulo 360.

Usage: python3 tests/ref/flip_gem.py [OUTDIR]   (default tests/data)
"""
import os
import sys

import numpy as np

DEG = np.pi / 180.0
AS = DEG / 3600.0
LAT = 39.0 * DEG
N = 160
# the truth (radians)
IH, ID = 2.5 * DEG, -0.3 * DEG
CH, NP = 40 * AS, -25 * AS
MA, ME = 90 * AS, -60 * AS
TF = 15 * AS
NOISE = 0.8 * AS


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def unit(ha, dec):
    return np.array([np.cos(dec) * np.cos(ha), np.cos(dec) * np.sin(ha), np.sin(dec)])


def angles(p):
    return np.arctan2(p[1], p[0]), np.arcsin(np.clip(p[2], -1, 1))


def sky(eh, ed, rng):
    """Apparent (HA, Dec) the mount points at with encoder (eh, ed)."""
    tube = np.array([np.cos(CH), np.sin(CH), 0.0])
    p = rx(MA) @ ry(ME) @ rz(eh - IH) @ rx(NP) @ ry(-(ed - ID)) @ tube
    # sag toward the zenith: zenith in (HA, Dec) frame is (cos lat, 0, sin lat)
    z = np.array([np.cos(LAT), 0.0, np.sin(LAT)])
    cos_el = np.sqrt(max(0.0, 1 - np.dot(p, z) ** 2))
    toward = z - np.dot(p, z) * p
    nt = np.linalg.norm(toward)
    if nt > 0:
        p = p + TF * cos_el * toward / nt
    p = p / np.linalg.norm(p)
    ha, dec = angles(p)
    # noise on the sky: dec, and HA scaled by sec(dec)
    dec += rng.normal(0, NOISE)
    ha += rng.normal(0, NOISE) / np.cos(dec)
    return ha, dec


def targets(rng):
    out = []
    while len(out) < N:
        h = rng.uniform(-6.5, 6.5) * 15 * DEG
        d = np.arcsin(rng.uniform(np.sin(-35 * DEG), np.sin(87 * DEG)))
        el = np.arcsin(np.sin(LAT) * np.sin(d) + np.cos(LAT) * np.cos(d) * np.cos(h))
        if el > 15 * DEG:
            out.append((h, d))
    return out


def wrap180(x):
    r = np.fmod(x, 360.0)
    if r > 180:
        r -= 360
    elif r <= -180:
        r += 360
    return r


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "data")
    rng = np.random.default_rng(20261125)
    rows = []
    for h, d in targets(rng):
        flipped = h < 0  # east of the meridian: the other pier side
        if flipped:
            eh, ed = h + np.pi + IH, np.pi - d + ID
        else:
            eh, ed = h + IH, d + ID
        ah, ad = sky(eh, ed, rng)
        rows.append((eh / DEG, ed / DEG, ah / DEG, ad / DEG, "W" if flipped else "E"))
    head = ("# A German equatorial mount flipping over the pole (tests/ref/flip_gem.py;\n"
            "# numpy gimbal IH 2.5 deg, ID -0.3 deg, CH 40\", NP -25\", MA 90\", ME -60\",\n"
            "# tube sag 15\", noise 0.8\"), encoder and apparent angles %s.\n"
            "# latitude: 39\n# tau delta T D pier\n")
    with open(os.path.join(outdir, "flip_gem_pm180.dat"), "w") as f:
        f.write(head % "in (-180, 180] deg")
        for eh, ed, ah, ad, p in rows:
            f.write("%.8f %.8f %.8f %.8f %s\n" % (wrap180(eh), wrap180(ed), wrap180(ah), ad, p))
    with open(os.path.join(outdir, "flip_gem_0360.dat"), "w") as f:
        f.write(head % "in [0, 360) deg, as many controllers write them")
        for eh, ed, ah, ad, p in rows:
            f.write("%.8f %.8f %.8f %.8f %s\n" % (eh % 360, ed % 360, ah % 360, ad, p))


if __name__ == "__main__":
    main()
