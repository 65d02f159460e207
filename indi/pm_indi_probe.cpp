/*
**  pm_indi_probe.cpp - loads the math plugin the way INDI 1.9.9 does (dlopen,
**  Create, GetDisplayName, Destroy), gives it an alignment database of the
**  library's own type (InMemoryDatabase), and checks its transforms against
**  a known mount, for an equatorial and an alt-az mount, with sync points
**  taken over three hours (so the time conversions matter).  Run by
**  tests/check_indi.c with indi/testshim.c preloaded (a frozen clock).
**
**  Usage: pm_indi_probe PLUGIN.so eq|altaz
**  Prints "probe: ..." lines; exits 0 when it ran, 1 on a usage or load error.
**
**  The reference is independent of the plugin: the known mount is a rotation
**  plus index offsets written here, and alt-az positions come from libnova's
**  ln_get_hrz_from_equ_sidereal_time (azimuth from the south there; from the
**  north in INDI's direction vectors).
*/
#include "alignment/AlignmentSubsystemForMathPlugins.h"
#include "alignment/InMemoryDatabase.h"

#include <libnova/julian_day.h>
#include <libnova/sidereal_time.h>
#include <libnova/transform.h>

#include <dlfcn.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

using namespace INDI::AlignmentSubsystem;

namespace
{

const double kPi = 3.14159265358979323846;
const double D2R = kPi / 180.0;
const double ARCSEC = 180.0 / kPi * 3600.0;
const double LAT = -33.9, LON = 151.2; /* a southern site, east longitude */

struct Vec
{
    double x, y, z;
};

Vec vec(double a, double b)
{
    return {std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b)};
}

void angles(Vec v, double *a, double *b)
{
    double n = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    *a = std::atan2(v.y, v.x);
    *b = std::asin(v.z / n);
}

double sep(double a1, double b1, double a2, double b2)
{
    Vec p = vec(a1, b1), q = vec(a2, b2);
    double cx = p.y * q.z - p.z * q.y, cy = p.z * q.x - p.x * q.z, cz = p.x * q.y - p.y * q.x;
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), p.x * q.x + p.y * q.y + p.z * q.z);
}

/* The known mount: index offsets o1, o2 on the axes, then a fixed rotation
** (small rotations about x and y) of the whole mount; the probe needs only
** its inverse, sky to mount (truth_inv). */
const double O1 = 0.40 * D2R, O2 = -0.25 * D2R, RX = 0.20 * D2R, RY = -0.12 * D2R;

void truth_inv(double s1, double s2, double *m1, double *m2)
{
    Vec v = vec(s1, s2);
    /* inverse rotation: about y by -RY, then about x by -RX */
    Vec a = {std::cos(-RY) * v.x + std::sin(-RY) * v.z, v.y, -std::sin(-RY) * v.x + std::cos(-RY) * v.z};
    Vec b = {a.x, std::cos(-RX) * a.y - std::sin(-RX) * a.z, std::sin(-RX) * a.y + std::cos(-RX) * a.z};
    angles(b, m1, m2);
    *m1 -= O1;
    *m2 -= O2;
}

double wrap(double a)
{
    return std::remainder(a, 2 * kPi);
}

double lst(double jd)
{
    return wrap(ln_get_apparent_sidereal_time(jd) * 15 * D2R + LON * D2R);
}

/* star (ra, dec; radians) -> azimuth from north, altitude (radians) */
void azalt(double ra, double dec, double jd, double *az, double *alt)
{
    ln_equ_posn eq = {ra / D2R, dec / D2R};
    ln_lnlat_posn obs = {LON, LAT};
    ln_hrz_posn h;
    ln_get_hrz_from_equ_sidereal_time(&eq, &obs, ln_get_apparent_sidereal_time(jd), &h);
    *az = wrap((h.az + 180.0) * D2R);
    *alt = h.alt * D2R;
}

struct Helper : TelescopeDirectionVectorSupportFunctions
{
};

} // namespace

int main(int argc, char **argv)
{
    if (argc != 3 || (strcmp(argv[2], "eq") != 0 && strcmp(argv[2], "altaz") != 0)) {
        fprintf(stderr, "usage: pm_indi_probe PLUGIN.so eq|altaz\n");
        return 1;
    }
    bool altaz = strcmp(argv[2], "altaz") == 0;
    void *h = dlopen(argv[1], RTLD_NOW);
    if (!h) {
        fprintf(stderr, "pm_indi_probe: cannot load %s: %s\n", argv[1], dlerror());
        return 1;
    }
    typedef MathPlugin *Create_t();
    typedef void Destroy_t(MathPlugin *);
    typedef const char *Name_t();
    Create_t *create = (Create_t *)dlsym(h, "Create");
    Destroy_t *destroy = (Destroy_t *)dlsym(h, "Destroy");
    Name_t *name = (Name_t *)dlsym(h, "GetDisplayName");
    if (!create || !destroy || !name) {
        fprintf(stderr, "pm_indi_probe: %s lacks Create/Destroy/GetDisplayName\n", argv[1]);
        return 1;
    }
    printf("probe: plugin '%s'\n", name());
    const double jd_now = ln_get_julian_from_sys(); /* frozen by the shim */
    Helper hf;
    InMemoryDatabase db;
    db.SetDatabaseReferencePosition(LAT, LON);
    int n = 0;
    /* sync points over the three hours before now, over the sky above 20 deg */
    for (int i = 0; i < 12; i++)
        for (int j = 0; j < 6; j++) {
            double jd = jd_now - 0.125 + 0.125 * (i * 6 + j) / 72.0;
            double ha = (-75.0 + 150.0 * i / 11.0) * D2R, dec = (-80.0 + 18.0 * j) * D2R;
            double ra = wrap(lst(jd) - ha), az, alt;
            azalt(ra, dec, jd, &az, &alt);
            if (alt < 20 * D2R)
                continue;
            AlignmentDatabaseEntry e;
            e.ObservationJulianDate = jd;
            e.RightAscension = std::fmod(ra / D2R / 15.0 + 24.0, 24.0);
            e.Declination = dec / D2R;
            double m1, m2;
            if (altaz) {
                truth_inv(az, alt, &m1, &m2);
                INDI::IHorizontalCoordinates hc {std::fmod(m1 / D2R + 360.0, 360.0), m2 / D2R};
                e.TelescopeDirection = hf.TelescopeDirectionVectorFromAltitudeAzimuth(hc);
            } else {
                truth_inv(ha, dec, &m1, &m2);
                INDI::IEquatorialCoordinates ec {std::fmod((lst(jd) - m1) / D2R / 15.0 + 48.0, 24.0), m2 / D2R};
                e.TelescopeDirection = hf.TelescopeDirectionVectorFromEquatorialCoordinates(ec);
            }
            db.GetAlignmentDatabase().push_back(e);
            n++;
        }
    /* malformed entries the plugin must skip, naming them */
    AlignmentDatabaseEntry bad;
    bad.ObservationJulianDate = jd_now;
    bad.RightAscension = NAN;
    bad.Declination = 10;
    bad.TelescopeDirection = TelescopeDirectionVector(1, 0, 0);
    db.GetAlignmentDatabase().push_back(bad);
    bad.RightAscension = 3;
    bad.Declination = 95;
    db.GetAlignmentDatabase().push_back(bad);
    bad.Declination = 10;
    bad.TelescopeDirection = TelescopeDirectionVector(0, 0, 0);
    db.GetAlignmentDatabase().push_back(bad);
    bad.TelescopeDirection = TelescopeDirectionVector(1, 0, 0);
    bad.ObservationJulianDate = 0;
    db.GetAlignmentDatabase().push_back(bad);

    MathPlugin *p = create();
    p->SetApproximateMountAlignment(altaz ? ZENITH : (LAT >= 0 ? NORTH_CELESTIAL_POLE : SOUTH_CELESTIAL_POLE));
    fflush(stdout);
    bool init = p->Initialise(&db);
    fflush(stdout);
    printf("\nprobe: %s sync points %d (+4 malformed) initialise %d\n", argv[2], n, (int)init);

    double worst_goto = 0, worst_back = 0;
    int fails = 0, q = 0;
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 5; j++) {
            double ha = (-70.0 + 140.0 * i / 8.0 + 3.0) * D2R, dec = (-70.0 + 20.0 * j + 5.0) * D2R;
            double ra = wrap(lst(jd_now) - ha), az, alt, m1, m2;
            azalt(ra, dec, jd_now, &az, &alt);
            if (alt < 25 * D2R)
                continue;
            if (altaz)
                truth_inv(az, alt, &m1, &m2);
            else
                truth_inv(ha, dec, &m1, &m2);
            TelescopeDirectionVector tdv;
            double ra_h = std::fmod(ra / D2R / 15.0 + 24.0, 24.0);
            q++;
            if (!p->TransformCelestialToTelescope(ra_h, dec / D2R, 0.0, tdv)) {
                fails++;
                continue;
            }
            double g1, g2;
            if (altaz) {
                INDI::IHorizontalCoordinates hc;
                hf.AltitudeAzimuthFromTelescopeDirectionVector(tdv, hc);
                g1 = hc.azimuth * D2R;
                g2 = hc.altitude * D2R;
            } else {
                INDI::IEquatorialCoordinates ec;
                hf.EquatorialCoordinatesFromTelescopeDirectionVector(tdv, ec);
                g1 = wrap(lst(jd_now) - ec.rightascension * 15 * D2R);
                g2 = ec.declination * D2R;
            }
            worst_goto = std::fmax(worst_goto, sep(g1, g2, m1, m2) * ARCSEC);
            /* the reverse, from the true mount position */
            TelescopeDirectionVector mv;
            if (altaz) {
                INDI::IHorizontalCoordinates hc {std::fmod(m1 / D2R + 360.0, 360.0), m2 / D2R};
                mv = hf.TelescopeDirectionVectorFromAltitudeAzimuth(hc);
            } else {
                INDI::IEquatorialCoordinates ec {std::fmod((lst(jd_now) - m1) / D2R / 15.0 + 48.0, 24.0), m2 / D2R};
                mv = hf.TelescopeDirectionVectorFromEquatorialCoordinates(ec);
            }
            double bra, bdec;
            if (!p->TransformTelescopeToCelestial(mv, bra, bdec)) {
                fails++;
                continue;
            }
            worst_back = std::fmax(worst_back, sep(bra * 15 * D2R, bdec * D2R, ra, dec) * ARCSEC);
        }
    /* bad input to the transforms */
    TelescopeDirectionVector tdv;
    double r1, r2;
    int refused = (int)!p->TransformCelestialToTelescope(NAN, 10, 0, tdv) +
                  (int)!p->TransformCelestialToTelescope(5, 91, 0, tdv) +
                  (int)!p->TransformCelestialToTelescope(5, 10, NAN, tdv) +
                  (int)!p->TransformTelescopeToCelestial(TelescopeDirectionVector(0, 0, 0), r1, r2) +
                  (int)!p->TransformTelescopeToCelestial(TelescopeDirectionVector(NAN, 0, 1), r1, r2) +
                  (int)!p->TransformCelestialToTelescope(1e300, 10, 0, tdv);
    /* a vector whose length overflows is still a direction: (1e300, 1e300,
    ** 0) read as (1, 0, 0) before */
    double u1 = 0, u2 = 0, b1 = 1, b2 = 1;
    int big_ok = (int)(p->TransformTelescopeToCelestial(TelescopeDirectionVector(0.6, 0.6, 0.1), u1, u2) &&
                       p->TransformTelescopeToCelestial(TelescopeDirectionVector(6e299, 6e299, 1e299), b1, b2) &&
                       std::fabs(u1 - b1) < 1e-12 && std::fabs(u2 - b2) < 1e-12);
    /* The known mount's axis-2 encoder reads 0.25 deg high (O2), so within
    ** about that of the north pole (eq) or the zenith (altaz) it reads
    ** beyond 90 deg, which a direction vector cannot carry: refused.  A
    ** degree away it is not. */
    double zra = std::fmod(lst(jd_now) / D2R / 15.0 + 24.0, 24.0);
    int near_refused = (int)!p->TransformCelestialToTelescope(altaz ? zra : 7.5, altaz ? LAT - 0.02 : 89.98,
                                                              0, tdv);
    int near_ok = (int)p->TransformCelestialToTelescope(altaz ? zra : 7.5, altaz ? LAT - 1.5 : 88.5, 0, tdv);
    fflush(stdout);
    printf("\nprobe: %s targets %d failed %d worst_goto_arcsec %.3e worst_back_arcsec %.3e bad_refused %d/6 "
           "near_refused %d near_ok %d big_ok %d\n",
           argv[2], q, fails, worst_goto, worst_back, refused, near_refused, near_ok, big_ok);
    destroy(p);
    dlclose(h);
    return 0;
}
