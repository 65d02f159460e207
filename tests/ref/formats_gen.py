#!/usr/bin/python3
"""formats_gen.py - write the samples of the RTS2, MW4, CSV and MMT readers
from two simulated runs with known models (pmfit simulate output, committed):

  tests/data/formats_source_eq.dat     equatorial GEM, both pier sides
  tests/data/formats_source_altaz.dat  alt-az

(their first line is the pmfit simulate command that made them: order 0,
a b c' d e' i set, 0.5 arcsec noise).  Each sample holds the same
observations in another format, written from the format's public
description (cited in each sample's header), with an independent
computation of whatever the format needs (LST, MJD, J2000 places, azimuth
conventions) through python3-erfa.  tests/check_formats.c fits every sample
and checks the fit against the source file's fit and the true terms.

Run from the top of the repository:   python3 tests/ref/formats_gen.py
"""
import json
import math
import os
import sys

import erfa
import numpy as np

TOP = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DATA = os.path.join(TOP, "tests", "data")
D2R = math.pi / 180.0

# The site and night the samples claim (the source runs are site-free
# except for the latitude; the date and longitude are ours).
DATE = (2024, 3, 15)
LON_DEG = 19.0
HEIGHT_M = 500.0
WEATHER = (950.0, 10.0, 0.5, 0.55)   # hPa, C, 0-1, um (CSV J2000 sample)


def read_source(name):
    rows, lat, cols = [], None, None
    for line in open(os.path.join(DATA, name)):
        t = line.strip()
        if t.startswith("# latitude:"):
            lat = float(t.split(":")[1])
        elif t.startswith("# tau"):
            cols = t[1:].split()
        elif t and not t.startswith("#"):
            f = t.split()
            r = dict(zip(cols, f))
            for k in ("tau", "delta", "T", "D", "temp", "time"):
                if k in r:
                    r[k] = float(r[k])
            rows.append(r)
    return lat, rows


def utc_tt(hours):
    """UTC quasi-JD and TT of DATE 0h + hours (as the readers compute)."""
    u1, u2 = erfa.dtf2d("UTC", DATE[0], DATE[1], DATE[2], 0, 0, 0.0)
    u2 = u2 + hours / 24.0
    a1, a2 = erfa.utctai(u1, u2)
    t1, t2 = erfa.taitt(a1, a2)
    return u1, u2, t1, t2


def lst_rad(hours):
    """Local apparent sidereal time, UT1 = UTC (docs/formats.md)."""
    u1, u2, t1, t2 = utc_tt(hours)
    return float(erfa.anp(erfa.gst06a(u1, u2, t1, t2) + LON_DEG * D2R))


def iso(hours, frac=True):
    u1, u2, _, _ = utc_tt(hours)
    iy, im, iday, ihmsf = erfa.d2dtf("UTC", 3 if frac else 0, u1, u2)
    h, m, s, f = (int(x) for x in ihmsf)
    sec = "%02d.%03d" % (s, f) if frac else "%02d" % s
    return "%04d-%02d-%02dT%02d:%02d:%sZ" % (iy, im, iday, h, m, sec)


def sky_of_encoder(tau, delta):
    """The sky place (HA, Dec, degrees) of an encoder reading and its side:
    beyond the pole (|delta| > 90) is (tau + 180, 180 - delta)."""
    d = math.remainder(delta, 360.0)
    if abs(d) > 90:
        return math.remainder(tau + 180.0, 360.0), math.remainder(180.0 - d, 360.0), "W"
    return math.remainder(tau, 360.0), d, "E"


def hms(hours, places=4):
    hours %= 24.0
    h = int(hours)
    m = int((hours - h) * 60)
    s = (hours - h - m / 60.0) * 3600.0
    if round(s, places) >= 60:
        s, m = 0.0, m + 1
    if m >= 60:
        m, h = 0, (h + 1) % 24
    return "%02d:%02d:%0*.*f" % (h, m, places + 3, places, s)


def dms(deg, places=3):
    sign = "-" if deg < 0 else "+"
    a = abs(deg)
    d = int(a)
    m = int((a - d) * 60)
    s = (a - d - m / 60.0) * 3600.0
    if round(s, places) >= 60:
        s, m = 0.0, m + 1
    if m >= 60:
        m, d = 0, d + 1
    return "%s%02d:%02d:%0*.*f" % (sign, d, m, places + 3, places, s)


def astrom(lst, eo, lat, refa, refb, diurab):
    a = np.zeros((), dtype=erfa.dt_eraASTROM)
    a["eral"] = lst + eo
    a["sphi"], a["cphi"] = math.sin(lat), math.cos(lat)
    a["refa"], a["refb"] = refa, refb
    a["diurab"] = diurab
    return a


def diurab_at(lat):
    """The diurnal aberration (radians) at latitude lat, HEIGHT_M: the
    observer's speed over c, from erfa.pvtob (no polar motion)."""
    pv = erfa.pvtob(0.0, lat, HEIGHT_M, 0.0, 0.0, 0.0, 0.0)
    return math.hypot(pv[1][0], pv[1][1]) / erfa.CMPS


def j2000_of(ha, dec, hours, lat, refa, refb, observed=True):
    """The ICRS (J2000) place whose place at DATE + hours is (ha, dec),
    radians: observed (the diurnal aberration, and refraction with refa,
    refb) or, observed False, the apparent place of date (what a mount's
    driver converts: neither).  eraAtoiq on a hand-built context (local
    ERA = LST + eo, no polar motion), then eraAtic13."""
    _, _, t1, t2 = utc_tt(hours)
    lst = lst_rad(hours)
    eo = float(erfa.eo06a(t1, t2))
    ctx = astrom(lst, eo, lat, refa, refb, diurab_at(lat) if observed else 0.0)
    ri, di = erfa.atoiq("H", ha, dec, ctx)
    rc, dc, _ = erfa.atic13(ri, di, t1, t2)
    return float(rc), float(dc)


def write(name, text):
    with open(os.path.join(DATA, name), "w") as f:
        f.write(text)
    print("wrote tests/data/%s" % name)


def rts2_eq(lat, rows):
    out = ["#  Observation\t  MJD\t   LST-MNT RA-MNT   DEC-MNT   AXRA\t  AXDEC   RA-TRUE  DEC-TRUE\n",
           "# RTS2 gpoint input (rts2 python/rts2/gpoint.py, GPoint.process_files): MJD,\n",
           "# LST, mount RA/Dec (Dec beyond +-90 beyond the pole), axis counts, true\n",
           "# RA/Dec, degrees.  Written by tests/ref/formats_gen.py from\n",
           "# tests/data/formats_source_eq.dat (true places: apparent, as gpoint uses them).\n",
           "#observatory %.1f %.1f %.0f\n" % (LON_DEG, lat, HEIGHT_M)]
    mjd0 = erfa.cal2jd(*DATE)[1]
    for k, r in enumerate(rows):
        lst = lst_rad(r["time"]) / D2R
        mjd = mjd0 + r["time"] / 24.0
        ra_m = (lst - r["tau"]) % 360.0
        ra_t = (lst - r["T"]) % 360.0
        out.append("02a60384e%04do %.8f %.7f %.9f %.9f %d %d %.9f %.9f\n" % (
            k + 1, mjd, lst, ra_m, r["delta"], round(r["tau"] * 11930.46), round(r["delta"] * 11930.46),
            ra_t, r["D"]))
    write("rts2_gpoint.dat", "".join(out))


def rts2_j2000(lat, rows):
    """The same with J2000 true places (pmfit --equinox J2000): reduced with
    refraction under the defaults the reader uses when the file gives no
    weather (standard atmosphere at the height, humidity 0.5, 0.55 um)."""
    p0 = 1013.25 * math.exp(-HEIGHT_M / 8434.5)
    refa, refb = erfa.refco(p0, 15.0 - 0.0065 * HEIGHT_M, 0.5, 0.55)
    out = ["#  Observation\t  MJD\t   LST-MNT RA-MNT   DEC-MNT   AXRA\t  AXDEC   RA-TRUE  DEC-TRUE\n",
           "# RTS2 gpoint input with J2000 true places (astrometry of the images): read\n",
           "# with --equinox J2000.  Written by tests/ref/formats_gen.py from\n",
           "# tests/data/formats_source_eq.dat (eraAtoiq + eraAtic13: diurnal aberration,\n",
           "# refraction in the standard atmosphere).\n",
           "#observatory %.1f %.1f %.0f\n" % (LON_DEG, lat, HEIGHT_M)]
    mjd0 = erfa.cal2jd(*DATE)[1]
    for k, r in enumerate(rows):
        lst = lst_rad(r["time"]) / D2R
        mjd = mjd0 + r["time"] / 24.0
        ra_m = (lst - r["tau"]) % 360.0
        rc, dc = j2000_of(r["T"] * D2R, r["D"] * D2R, r["time"], lat * D2R, refa, refb)
        out.append("02a60384e%04do %.8f %.7f %.9f %.9f %d %d %.9f %.9f\n" % (
            k + 1, mjd, lst, ra_m, r["delta"], round(r["tau"] * 11930.46), round(r["delta"] * 11930.46),
            rc / D2R, dc / D2R))
    write("rts2_gpoint_j2000.dat", "".join(out))


def rts2_altaz(lat, rows):
    out = ["#  Observation\t  MJD\t   LST-MNT   AZ-MNT   ALT-MNT   AXAZ\t  AXALT   AZ-TRUE  ALT-TRUE\n",
           "# RTS2 gpoint alt-az input (rts2 python/rts2/gpoint.py): azimuths of libnova,\n",
           "# from south through west.  Written by tests/ref/formats_gen.py from\n",
           "# tests/data/formats_source_altaz.dat.\n",
           "# altaz %.1f %.1f %.0f\n" % (LON_DEG, lat, HEIGHT_M)]
    mjd0 = erfa.cal2jd(*DATE)[1]
    for k, r in enumerate(rows):
        lst = lst_rad(r["time"]) / D2R
        mjd = mjd0 + r["time"] / 24.0
        az_m = (r["tau"] - 180.0) % 360.0     # A_SW = A_NE - 180
        az_t = (r["T"] - 180.0) % 360.0
        out.append("02a60384e%04do %.8f %.7f %.9f %.9f %d %d %.9f %.9f\n" % (
            k + 1, mjd, lst, az_m, r["delta"], round(r["tau"] * 11930.46), round(r["delta"] * 11930.46),
            az_t, r["D"]))
    write("rts2_altaz.dat", "".join(out))


def mw4(lat, rows):
    pts = []
    for k, r in enumerate(rows):
        lst_h = lst_rad(r["time"]) / D2R / 15.0
        ha_m, dec_m, side = sky_of_encoder(r["tau"], r["delta"])
        pts.append({
            "altitude": 45.0, "azimuth": 180.0, "angularPosRA": round(r["tau"] + 90.0, 6),
            "angularPosDEC": round(90.0 - r["delta"], 6), "binning": 1, "countSequence": k + 1,
            "decJ2000M": 0.0, "decJ2000S": 0.0,
            "decJNowM": round(dec_m, 9), "decJNowS": round(r["D"], 9),
            "errorRA": 0.0, "errorDEC": 0.0, "errorRMS": 0.0, "exposureTime": 3.0,
            "firmware": "3.1.2", "haMountModel": 0.0, "decMountModel": 0.0,
            "imagePath": "/model/image-%03d.fits" % (k + 1), "julianDate": iso(r["time"], False),
            "latitude": lat, "lenSequence": len(rows), "message": "Solved",
            "pierside": side, "profile": "config", "raJ2000M": 0.0, "raJ2000S": 0.0,
            "raJNowM": round(((lst_h - ha_m / 15.0) % 24.0), 10),
            "raJNowS": round(((lst_h - r["T"] / 15.0) % 24.0), 10),
            "siderealTime": round(lst_h, 10), "success": True, "version": "3.2.0",
        })
    text = json.dumps(pts, sort_keys=True, indent=4)
    write("mw4_model.json", text + "\n")


def csv_j2000(lat, rows):
    refa, refb = erfa.refco(*WEATHER)
    out = ["# N.I.N.A./ASCOM-style CSV pointing log (docs/formats.md, section 6): the\n",
           "# mount's RA/Dec as the driver reports them, the plate-solved RA/Dec, ASCOM's\n",
           "# SideOfPier, the UTC time.  Written by tests/ref/formats_gen.py from\n",
           "# tests/data/formats_source_eq.dat: J2000 places by eraAtoiq + eraAtic13\n",
           "# (the solved place observed: diurnal aberration and refraction).\n",
           "# equinox: J2000\n", "# latitude: %.1f\n" % lat, "# longitude: %.1f\n" % LON_DEG,
           "# height: %.0f\n" % HEIGHT_M, "# pressure: %.1f\n" % WEATHER[0],
           "# temperature: %.1f\n" % WEATHER[1], "# humidity: %.2f\n" % WEATHER[2],
           "# wavelength: %.2f\n" % WEATHER[3],
           "Time (UTC),Target,Mount RA,Mount Dec,Solved RA,Solved Dec,Pier Side,Temperature\n"]
    for k, r in enumerate(rows):
        ha_m, dec_m, side = sky_of_encoder(r["tau"], r["delta"])
        # the mount's place: the driver's J2000 conversion of its apparent
        # place (no refraction); the solved place: the J2000 place observed
        # (refracted) at the star's (T, D)
        rm, dm = j2000_of(ha_m * D2R, dec_m * D2R, r["time"], lat * D2R, 0.0, 0.0, False)
        rs, ds = j2000_of(r["T"] * D2R, r["D"] * D2R, r["time"], lat * D2R, refa, refb)
        out.append('%s,"Star %d, field",%s,%s,%s,%s,%s,%.2f\n' % (
            iso(r["time"]), k + 1, hms(rm / D2R / 15.0), dms(dm / D2R), hms(rs / D2R / 15.0),
            dms(ds / D2R), "pierEast" if side == "E" else "pierWest", r["temp"]))
    write("nina_j2000.csv", "".join(out))


def csv_jnow(lat, rows):
    out = ["# N.I.N.A./ASCOM-style CSV pointing log, JNow places, decimal hours and\n",
           "# degrees, an LST column, ';' delimited; the mount corrects refraction itself.\n",
           "# Written by tests/ref/formats_gen.py from tests/data/formats_source_eq.dat.\n",
           "# equinox: JNow\n", "# refraction: no\n",
           "LST;RA;Dec;SolvedRA;SolvedDec;SideOfPier\n"]
    for r in rows:
        lst_h = lst_rad(r["time"]) / D2R / 15.0
        ha_m, dec_m, side = sky_of_encoder(r["tau"], r["delta"])
        out.append("%.10f;%.10f;%.9f;%.10f;%.9f;%s\n" % (
            lst_h, (lst_h - ha_m / 15.0) % 24.0, dec_m, (lst_h - r["T"] / 15.0) % 24.0, r["D"],
            "East" if side == "E" else "West"))
    write("nina_jnow.csv", "".join(out))


def mmt(rows):
    out = ["# MMT mount computer pointing log (the raw file of pytelpoint's\n",
           "# read_raw_datfile, MMTObservatory/pytelpoint pytelpoint/io.py): 13 'KEY: values'\n",
           "# lines per star; RAA: raw and TAA: observed elevation, azimuth (north through\n",
           "# east), LST:.  Written by tests/ref/formats_gen.py from\n",
           "# tests/data/formats_source_altaz.dat ('#' lines: ours, not the MMT's).\n"]
    for k, r in enumerate(rows):
        lst_h = lst_rad(r["time"]) / D2R / 15.0
        az_t = math.remainder(r["T"], 360.0)       # the log writes -180..180 here
        out += ["CAT: SIM-%04d        %s %s +00.000 +000.00  5.0  A0  J2000.0\n" % (
                    k + 1, hms(r["T"] / 15.0, 3), dms(r["D"], 2)),
                "RAA: %14.7f %12.7f\n" % (r["delta"], r["tau"] % 360.0),
                "AA: %14.7f %12.7f\n" % (r["delta"], r["tau"] % 360.0),
                "TAA: %14.7f %12.7f\n" % (r["D"], az_t),
                "ABS_AA: %14.7f %12.7f\n" % (r["D"], az_t),
                "TAPE_ALT_EW:   89.9664100 %12.7f\n" % r["delta"],
                "TAPE_ALT_EW_RAW:   89.9664100 %12.7f\n" % r["delta"],
                "LST: %s\n" % hms(lst_h, 3),
                "RRD:   18.9330670   43.9741152\n", "ARD:   18.9334263   43.9779932\n",
                "CRD: 18:55:18.284  43:56:28.290\n", "SVEL: -0.0008 -0.0133\n",
                "SERR: 1601733632 1076516358\n"]
    write("mmt_log.dat", "".join(out))


def main():
    lat_eq, eq = read_source("formats_source_eq.dat")
    lat_az, az = read_source("formats_source_altaz.dat")
    rts2_eq(lat_eq, eq)
    rts2_j2000(lat_eq, eq)
    rts2_altaz(lat_az, az)
    mw4(lat_eq, eq)
    csv_j2000(lat_eq, eq)
    csv_jnow(lat_eq, eq)
    mmt(az)
    return 0


if __name__ == "__main__":
    sys.exit(main())
