#!/usr/bin/python3
"""Reference values for the TPOINT equatorial reduction of tools/lib/runfile.

Independent of the C++ reader: it parses the test runs itself, derives each
record's UTC instant itself and calls ERFA from Python (python3-erfa), then
writes tests/ref/runfile_reduction_ref.h for tests/check_runfile.c.

The reduction (docs/formats.md, "The reduction"):
  UTC (run date at 0h + hours) -> TAI -> TT          erfa.dtf2d/utctai/taitt
  J2000 catalogue place -> CIRS, eo                  erfa.atci13 (TT for TDB)
  apparent RA = CIRS RA - eo; HA = LST - RA          erfa.anp/anpm
  diurnal aberration toward the east point           diurab from erfa.pvtob
  refraction dZ = A tan Z + B tan^3 Z                erfa.refco, hd2ae/ae2hd
The refracted place is computed twice: with the formulae above, and with
erfa.atioq on a hand-built ASTROM context (local ERA = LST + eo, no polar
motion, diurab from erfa.pvtob), which applies ERFA's own diurnal
aberration and refraction code.
eraAtioq turns the vector by the refraction dz with cos dz ~ 1 - dz^2/2,
sin dz ~ dz, so the two may differ by up to dz^3/6 (2e-10 rad at 15 deg
elevation, 2e-8 rad at the 3 deg horizon guard); they must agree to that
(plus 1e-12 rad) or the script stops.  Below the guard (sin el < 0.05, where
the model is no longer meaningful) eraAtioq's vector update is no longer a
rotation and the two differ by up to ~1e-6 rad; such records are reduced
with the formula only and counted in the header comment.

Run: /usr/bin/python3 tests/ref/runfile_reduction_ref.py   (from the repo)
"""
import math
import os
import sys

import erfa
import erfa.version
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOP = os.path.dirname(os.path.dirname(HERE))
FILES = ["tests/data/tpoint_equat.dat", "tests/data/tpoint_south.dat"]
OUT = os.path.join(HERE, "runfile_reduction_ref.h")

SIDEREAL_PER_SOLAR = 1.00273790935
H2R = math.pi / 12.0
D2R = math.pi / 180.0


def isnum(s):
    try:
        float(s)
        return s.lower().lstrip("+-") not in ("nan", "inf", "infinity")
    except ValueError:
        return False


def sexa(parts):
    """Signed sexagesimal from 2 or 3 text parts (sign on the first)."""
    v = abs(float(parts[0]))
    for k, p in enumerate(parts[1:]):
        v += float(p) / 60.0 ** (k + 1)
    return -v if parts[0].startswith("-") else v


def read(path):
    run, recs = None, []
    with open(path) as f:
        for n, text in enumerate(f, 1):
            t = text.split("!", 1)[0].strip()
            if not t or t.startswith(":"):
                continue
            w = t.split()
            if run is None:
                if isnum(w[0]):
                    run = [float(x) for x in w]
                    run_parts = w
                continue
            if t.upper() == "END":
                break
            recs.append(dict(line=n,
                             ra=sexa(w[0:3]) * H2R, dec=sexa(w[3:6]) * D2R,
                             raw_ra=sexa(w[6:9]) * H2R, raw_dec=sexa(w[9:12]) * D2R,
                             lst=sexa(w[12:14]) * H2R))
    lat = sexa(run_parts[0:3]) * D2R
    y, m, d = (int(x) for x in run[3:6])
    tc, p = run[6], run[7]
    rh = run[9] if len(run) > 9 else 0.5
    if rh > 1:
        rh /= 100.0
    wl = run[10] if len(run) > 10 else 0.55
    height = run[8] if len(run) > 8 else 0.0
    return lat, height, (y, m, d), (p, tc, rh, wl), recs


def utc_hours(recs):
    s, acc = [], 0.0
    for i, r in enumerate(recs):
        if i:
            dh = (r["lst"] - recs[i - 1]["lst"]) / H2R
            dh -= 24.0 * math.floor((dh + 12.0) / 24.0)
            acc += dh
        s.append(acc)
    mid = 0.5 * (min(s) + max(s))
    return [12.0 + (x - mid) / SIDEREAL_PER_SOLAR for x in s]


def refract(ha, dec, lat, refa, refb):
    az, el = erfa.hd2ae(ha, dec, lat)
    guarded = math.sin(el) < 0.05
    r = max(math.cos(el), 1e-6)
    z = max(math.sin(el), 0.05)
    tz = r / z
    w = refb * tz * tz
    dz = (refa + w) * tz / (1.0 + (refa + 3.0 * w) / (z * z))
    ha, dec = erfa.ae2hd(az, el + dz, lat)
    return ha, dec, dz, guarded


def diurnal(ha, dec, diurab):
    """Diurnal aberration toward the east point, to first order in diurab
    (the form eraAtioq uses), on (HA, Dec) radians."""
    v = erfa.s2c(-ha, dec)                       # y toward the east point
    f = 1.0 - diurab * v[1]
    w = np.array([f * v[0], f * (v[1] + diurab), f * v[2]])
    lon, lat = erfa.c2s(w)
    return -float(lon), float(lat)


def atioq_path(ri, di, eo, lst, lat, refa, refb, diurab):
    a = np.zeros((), dtype=erfa.dt_eraASTROM)
    a["eral"] = lst + eo
    a["sphi"], a["cphi"] = math.sin(lat), math.cos(lat)
    a["diurab"] = diurab
    a["refa"], a["refb"] = refa, refb
    _, _, hob, dob, _ = erfa.atioq(ri, di, a)
    return float(erfa.anpm(hob)), float(dob)


def rows_for(rel):
    lat, height, (y, m, d), (p, tc, rh, wl), recs = read(os.path.join(TOP, rel))
    refa, refb = erfa.refco(p, tc, rh, wl)
    pv = erfa.pvtob(0.0, lat, height, 0.0, 0.0, 0.0, 0.0)
    diurab = math.hypot(pv[1][0], pv[1][1]) / erfa.CMPS
    u1, u2 = erfa.dtf2d("UTC", y, m, d, 0, 0, 0.0)
    rows, worst, nguard = [], 0.0, 0
    for r, h in zip(recs, utc_hours(recs)):
        tai1, tai2 = erfa.utctai(u1, u2 + h / 24.0)
        tt1, tt2 = erfa.taitt(tai1, tai2)
        ri, di, eo = erfa.atci13(r["ra"], r["dec"], 0.0, 0.0, 0.0, 0.0, tt1, tt2)
        ha0 = float(erfa.anpm(r["lst"] - erfa.anp(ri - eo)))
        ha0, dec0 = diurnal(ha0, float(di), diurab)
        ha0 = float(erfa.anpm(ha0))
        ha1, dec1, dz, guarded = refract(ha0, dec0, lat, refa, refb)
        ha1 = float(erfa.anpm(ha1))
        dec1 = float(dec1)
        ha2, dec2 = atioq_path(ri, di, eo, r["lst"], lat, refa, refb, diurab)
        ha3, dec3 = atioq_path(ri, di, eo, r["lst"], lat, 0.0, 0.0, diurab)
        diff = float(erfa.seps(ha1, dec1, ha2, dec2))     # on the sky (rad)
        diff0 = float(erfa.seps(ha0, dec0, ha3, dec3))
        bound = abs(dz) ** 3 / 6.0 * 1.05 + 1e-12
        if guarded:
            nguard += 1
        elif diff > bound or diff0 > 1e-12:
            sys.exit("%s:%d: formula and eraAtioq differ by %.3g rad (%.3g unrefracted), "
                     "allowed %.3g" % (rel, r["line"], diff, diff0, bound))
        else:
            worst = max(worst, diff / bound)
        rows.append((rel, r["line"], h,
                     float(erfa.anpm(r["lst"] - r["raw_ra"])), r["raw_dec"],
                     ha1, dec1, ha0, dec0))
    return rows, worst, nguard


def main():
    rows, worst, nguard = [], 0.0, 0
    for rel in FILES:
        r, w, g = rows_for(rel)
        rows += r
        worst = max(worst, w)
        nguard += g
    with open(OUT, "w") as f:
        f.write("/* Generated by tests/ref/runfile_reduction_ref.py; do not edit.\n"
                "** python3-erfa %s (ERFA %s), numpy %s.  Observed (refracted) and\n"
                "** unrefracted apparent HA/Dec (radians) of the records of\n%s"
                "** computed independently of tools/lib with ERFA called from Python; the\n"
                "** refracted places agree with eraAtioq within %.2f of its dz^3/6\n"
                "** second-order bound (%d record(s) below the 3 deg horizon guard: formula\n"
                "** only). */\n"
                % (erfa.__version__, erfa.version.erfa_version, np.__version__,
                   "".join("**    %s\n" % rel for rel in FILES), worst, nguard))
        f.write("typedef struct runfile_ref_row {\n"
                "    const char *file;\n    int line;\n    double time_h;\n"
                "    double enc_ha, enc_dec;\n    double app_ha, app_dec;\n"
                "    double app_ha_norefr, app_dec_norefr;\n} runfile_ref_row;\n\n")
        f.write("static const runfile_ref_row RUNFILE_REF[] = {\n")
        for row in rows:
            f.write('    {"%s", %d, %s},\n' % (row[0], row[1],
                                              ", ".join("%.17g" % x for x in row[2:])))
        f.write("};\n#define RUNFILE_REF_N (sizeof RUNFILE_REF / sizeof RUNFILE_REF[0])\n")
    print("wrote %s: %d rows; formula vs eraAtioq: worst %.2f of the dz^3/6 bound, "
          "%d below the horizon guard" % (OUT, len(rows), worst, nguard))


if __name__ == "__main__":
    main()
