/*
**  pm_math_plugin.cpp - an INDI alignment-subsystem math plugin (INDI 1.9.9
**  interface, alignment/MathPlugin.h) that corrects pointing with the pm
**  pointing model (include/pm.h): a joint least-squares fit of all the sync
**  points, its order chosen from their number and sky coverage, the exact
**  inverse for GOTOs.  docs/indi.md describes it, the rule for the order, and
**  how it is tested (tests/check_indi.c).
**
**  Frames.  Each sync point of the alignment database holds the catalogue
**  place (RA in hours, Dec in degrees), the Julian date of the sync, and the
**  mount's own direction as a unit vector (TelescopeDirection).  For an
**  equatorial mount (ApproximateMountAlignment NORTH/SOUTH_CELESTIAL_POLE)
**  the vector is in RA/Dec, as AstroTrac and the other 1.9.9 drivers store
**  it, so both are turned into hour angles with the local sidereal time at
**  the sync's date: pm's "encoder" position is the mount's (HA, Dec), its
**  "apparent" position the star's.  For an alt-az mount (ZENITH) the vector
**  is in azimuth (from north through east) and altitude, and the star's
**  place is turned into the same at the sync's date.  The sidereal time is
**  libnova's apparent one (ln_get_apparent_sidereal_time), as the drivers'
**  get_local_sidereal_time.
**
**  Logging: IDLog (the server's log) and an INDI message to the clients, both
**  prefixed "pm Math Plugin:".
*/
#include "alignment/AlignmentSubsystemForMathPlugins.h"
#include "indidevapi.h"

#include <libnova/julian_day.h>
#include <libnova/sidereal_time.h>

#include "pm.h"
#include "pm_indi.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <new>
#include <vector>

namespace
{

using namespace INDI::AlignmentSubsystem;

const char *const kDisplayName = "pm Math Plugin";
const double kPi = 3.14159265358979323846;
const double kDeg = kPi / 180.0;
const double kHour = kPi / 12.0;

void note(const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    IDLog("pm Math Plugin: %s\n", buf);
    IDMessage(nullptr, "pm Math Plugin: %s", buf);
}

double wrap_pi(double a)
{
    a = std::fmod(a, 2 * kPi);
    if (a > kPi)
        a -= 2 * kPi;
    else if (a <= -kPi)
        a += 2 * kPi;
    return a;
}

/* Local apparent sidereal time (radians) at a Julian date and east longitude
** (degrees), as INDI's get_local_sidereal_time computes it. */
double lst_rad(double jd, double lon_deg)
{
    return wrap_pi(ln_get_apparent_sidereal_time(jd) * kHour + lon_deg * kDeg);
}

/* Hour angle, declination -> azimuth (from north through east), altitude
** at latitude phi (all radians). */
void hadec_to_azalt(double ha, double dec, double phi, double *az, double *alt)
{
    double x = -std::cos(phi) * std::sin(dec) + std::sin(phi) * std::cos(dec) * std::cos(ha);
    double y = std::cos(dec) * std::sin(ha);
    double z = std::sin(phi) * std::sin(dec) + std::cos(phi) * std::cos(dec) * std::cos(ha);
    /* x toward south, y toward west: azimuth from north = atan2(-y, -x) */
    *az = std::atan2(-y, -x);
    *alt = std::atan2(z, std::sqrt(x * x + y * y));
}

void azalt_to_hadec(double az, double alt, double phi, double *ha, double *dec)
{
    double x = -std::cos(alt) * std::cos(az); /* south */
    double y = -std::cos(alt) * std::sin(az); /* west */
    double z = std::sin(alt);
    double xe = std::sin(phi) * x + std::cos(phi) * z; /* toward (ha 0, dec 0) */
    double ze = -std::cos(phi) * x + std::sin(phi) * z; /* toward the pole */
    *ha = std::atan2(y, xe);
    *dec = std::atan2(ze, std::sqrt(xe * xe + y * y));
}

bool finite3(const TelescopeDirectionVector &v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

class PmMathPlugin : public AlignmentSubsystemForMathPlugins
{
  public:
    PmMathPlugin() : fit_(new (std::nothrow) pm_fit), kind_(PM_INDI_NONE)
    {
        pm_model_init(&model_, PM_MOUNT_EQUATORIAL, 0);
        summary_[0] = 0;
    }
    ~PmMathPlugin() override { delete fit_; }

    bool Initialise(InMemoryDatabase *db) override;
    /* INDI 1.9.9 sets the mount's kind after Initialise (the driver's
    ** updateLocation); the fit is in the mount's frame, so refit. */
    void SetApproximateMountAlignment(MountAlignment_t a) override
    {
        bool changed = a != ApproximateMountAlignment;
        MathPlugin::SetApproximateMountAlignment(a);
        if (changed && pInMemoryDatabase)
            Initialise(pInMemoryDatabase);
    }
    bool TransformCelestialToTelescope(const double RightAscension, const double Declination,
                                       double JulianOffset,
                                       TelescopeDirectionVector &ApparentTelescopeDirectionVector) override;
    bool TransformTelescopeToCelestial(const TelescopeDirectionVector &ApparentTelescopeDirectionVector,
                                       double &RightAscension, double &Declination) override;

  private:
    bool altaz() const { return ApproximateMountAlignment == ZENITH; }
    bool site(double *lat, double *lon);
    /* mount direction vector -> (axis 1, axis 2) of the fit frame at local
    ** sidereal time lst; false for a vector that is not a direction */
    bool mount_axes(const TelescopeDirectionVector &v, double lst, double *a1, double *a2);
    TelescopeDirectionVector mount_vector(double a1, double a2, double lst);
    void sky_axes(double ra_h, double dec_deg, double lst, double lat, double *a1, double *a2);
    void sky_radec(double a1, double a2, double lst, double lat, double *ra_h, double *dec_deg);

    pm_model model_;
    pm_fit *fit_;
    int kind_; /* PM_INDI_*: what model_ is */
    char summary_[512];
};

bool PmMathPlugin::site(double *lat, double *lon)
{
    INDI::IGeographicCoordinates pos;
    if (!pInMemoryDatabase || !pInMemoryDatabase->GetDatabaseReferencePosition(pos))
        return false;
    if (!std::isfinite(pos.latitude) || !std::isfinite(pos.longitude) || std::fabs(pos.latitude) > 90)
        return false;
    *lat = pos.latitude * kDeg;
    *lon = pos.longitude;
    return true;
}

/* v / |v|, false where v is not finite or shorter than 1e-6.  Scaled
** first: the length of (1e300, 1e300, 0) overflows, and x / inf had read
** it as (1, 0, 0) (an outside probe). */
static bool unit_vector(const TelescopeDirectionVector &v, TelescopeDirectionVector *u)
{
    if (!finite3(v))
        return false;
    const double big = std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z)));
    if (!(big > 0))
        return false;
    const double sx = v.x / big, sy = v.y / big, sz = v.z / big;
    const double ln = std::sqrt(sx * sx + sy * sy + sz * sz); /* 1 .. sqrt 3 */
    if (!(ln * big > 1e-6))
        return false;
    *u = TelescopeDirectionVector(sx / ln, sy / ln, sz / ln);
    return true;
}

bool PmMathPlugin::mount_axes(const TelescopeDirectionVector &v, double lst, double *a1, double *a2)
{
    TelescopeDirectionVector u;
    if (!unit_vector(v, &u))
        return false;
    double az, pol;
    if (altaz()) {
        /* TelescopeDirectionVectorFromAltitudeAzimuth: clockwise azimuth */
        SphericalCoordinateFromTelescopeDirectionVector(u, az, CLOCKWISE, pol, FROM_AZIMUTHAL_PLANE);
        *a1 = wrap_pi(az);
        *a2 = pol;
    } else {
        /* TelescopeDirectionVectorFromEquatorialCoordinates: RA anticlockwise */
        SphericalCoordinateFromTelescopeDirectionVector(u, az, ANTI_CLOCKWISE, pol, FROM_AZIMUTHAL_PLANE);
        *a1 = wrap_pi(lst - az);
        *a2 = pol;
    }
    return std::isfinite(*a1) && std::isfinite(*a2);
}

TelescopeDirectionVector PmMathPlugin::mount_vector(double a1, double a2, double lst)
{
    if (altaz())
        return TelescopeDirectionVectorFromSphericalCoordinate(a1, CLOCKWISE, a2, FROM_AZIMUTHAL_PLANE);
    return TelescopeDirectionVectorFromSphericalCoordinate(wrap_pi(lst - a1), ANTI_CLOCKWISE, a2,
                                                           FROM_AZIMUTHAL_PLANE);
}

void PmMathPlugin::sky_axes(double ra_h, double dec_deg, double lst, double lat, double *a1, double *a2)
{
    double ha = wrap_pi(lst - ra_h * kHour), dec = dec_deg * kDeg;
    if (altaz())
        hadec_to_azalt(ha, dec, lat, a1, a2);
    else {
        *a1 = ha;
        *a2 = dec;
    }
}

void PmMathPlugin::sky_radec(double a1, double a2, double lst, double lat, double *ra_h, double *dec_deg)
{
    double ha = a1, dec = a2;
    if (altaz())
        azalt_to_hadec(a1, a2, lat, &ha, &dec);
    double ra = std::fmod(lst - ha, 2 * kPi);
    if (ra < 0)
        ra += 2 * kPi;
    *ra_h = ra / kHour;
    if (*ra_h >= 24.0)
        *ra_h -= 24.0;
    *dec_deg = dec / kDeg;
}

bool PmMathPlugin::Initialise(InMemoryDatabase *db)
{
    MathPlugin::Initialise(db);
    if (!fit_) {
        note("out of memory for the fit; nothing changed");
        return false;
    }
    if (!db) {
        note("no alignment database; nothing changed");
        return false;
    }
    InMemoryDatabase::AlignmentDatabaseType &points = db->GetAlignmentDatabase();
    std::vector<double> e1, e2, s1v, s2v;

    double lat = 0, lon = 0;
    bool have_site = site(&lat, &lon);
    if (!points.empty() && !have_site) {
        note("the alignment database has %zu sync points but no site position (set the "
             "telescope's location): the previous model is kept", points.size());
        return false;
    }
    long skipped = 0;
    std::vector<long> db_index; /* the database entry of each point fitted */
    for (size_t i = 0; i < points.size(); i++) {
        const AlignmentDatabaseEntry &e = points[i];
        const char *why = nullptr;
        double a1 = 0, a2 = 0, s1 = 0, s2 = 0;
        if (!std::isfinite(e.RightAscension) || !std::isfinite(e.Declination))
            why = "RA or Dec not finite";
        else if (std::fabs(e.Declination) > 90.0)
            why = "|Dec| > 90 deg";
        else if (!std::isfinite(e.ObservationJulianDate) || e.ObservationJulianDate < 1.0e6)
            why = "no usable Julian date";
        else {
            double lst = lst_rad(e.ObservationJulianDate, lon);
            if (!mount_axes(e.TelescopeDirection, lst, &a1, &a2))
                why = "telescope direction vector is not a direction (zero or not finite)";
            else
                sky_axes(e.RightAscension, e.Declination, lst, lat, &s1, &s2);
        }
        if (why) {
            note("sync point %zu skipped: %s", i + 1, why);
            skipped++;
            continue;
        }
        db_index.push_back((long)i);
        e1.push_back(a1);
        e2.push_back(a2);
        s1v.push_back(s1);
        s2v.push_back(s2);
    }

    pm_indi_result r;
    long n = (long)e1.size();
    pm_status st = pm_indi_fit(altaz() ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL, n, e1.data(), e2.data(),
                               s1v.data(), s2v.data(), fit_, &model_, &r);
    if (st < 0) {
        /* never happens for the statuses pm_indi_fit documents; keep what we had */
        note("fit failed (%s); the previous model is kept", pm_status_text(st));
        return false;
    }
    kind_ = r.kind;
    if (r.worst >= 0 && r.worst < n) /* named by its place in the database */
        r.worst = db_index[(size_t)r.worst];
    pm_indi_describe(&r, n, skipped, summary_, sizeof summary_);
    note("%s mount: %s", altaz() ? "alt-az" : "equatorial", summary_);
    return true;
}

bool PmMathPlugin::TransformCelestialToTelescope(const double RightAscension, const double Declination,
                                                 double JulianOffset, TelescopeDirectionVector &out)
{
    /* (an RA beyond 2^31 h is no hour angle a caller meant: fmod reduces
    ** 1e300 exactly, to a direction nobody gave; pmfit's readers refuse
    ** such angles alike) */
    if (!std::isfinite(RightAscension) || std::fabs(RightAscension) > 2147483648.0 ||
            !std::isfinite(Declination) || std::fabs(Declination) > 90.0 || !std::isfinite(JulianOffset)) {
        note("TransformCelestialToTelescope: bad target (RA %g h, Dec %g deg, offset %g d)", RightAscension,
             Declination, JulianOffset);
        return false;
    }
    double lat = 0, lon = 0;
    if (!site(&lat, &lon)) {
        if (!altaz() && kind_ == PM_INDI_NONE) {
            INDI::IEquatorialCoordinates rd {RightAscension, Declination};
            out = TelescopeDirectionVectorFromEquatorialCoordinates(rd);
            return true;
        }
        note("TransformCelestialToTelescope: no site position");
        return false;
    }
    double lst = lst_rad(ln_get_julian_from_sys() + JulianOffset, lon);
    double s1, s2, e1, e2;
    sky_axes(RightAscension, Declination, lst, lat, &s1, &s2);
    pm_status st = pm_model_invert(&model_, nullptr, s1, s2, PM_SIDE_NORMAL, &e1, &e2);
    if (st < 0 || st == PM_WARN_UNREACHABLE) {
        note("TransformCelestialToTelescope: RA %.6f h Dec %.6f deg %s%s", RightAscension, Declination,
             st == PM_WARN_UNREACHABLE ? "is not reachable by the model's mount" : "failed: ",
             st == PM_WARN_UNREACHABLE ? "" : pm_status_text(st));
        return false;
    }
    if (std::fabs(e2) > kPi / 2) {
        /* Within the model's axis-2 index of the pole (the zenith), where
        ** the encoder reads beyond +-90 deg: a direction vector folds that
        ** to the position across the pole, which the model's mount points
        ** elsewhere (twice the excess away). */
        note("TransformCelestialToTelescope: RA %.6f h Dec %.6f deg: the mount's %s encoder would "
             "read %.4f deg there, beyond %s90, which an INDI direction vector cannot carry (it "
             "would be read as the position across the %s, %.1f arcmin from the target): refused",
             RightAscension, Declination, altaz() ? "altitude" : "declination", e2 / kDeg,
             e2 > 0 ? "+" : "-", altaz() ? "zenith" : "pole", 2 * (std::fabs(e2) - kPi / 2) / kDeg * 60);
        return false;
    }
    if (st == PM_WARN_NOT_CONVERGED)
        note("TransformCelestialToTelescope: inverse not converged to 1e-13 rad at RA %.6f h Dec %.6f deg "
             "(best position used)", RightAscension, Declination);
    out = mount_vector(e1, e2, lst);
    return true;
}

bool PmMathPlugin::TransformTelescopeToCelestial(const TelescopeDirectionVector &v, double &RightAscension,
                                                 double &Declination)
{
    double lat = 0, lon = 0;
    if (!site(&lat, &lon)) {
        TelescopeDirectionVector u;
        if (!altaz() && kind_ == PM_INDI_NONE && unit_vector(v, &u)) {
            INDI::IEquatorialCoordinates rd;
            EquatorialCoordinatesFromTelescopeDirectionVector(u, rd);
            RightAscension = rd.rightascension;
            Declination = rd.declination;
            return true;
        }
        note("TransformTelescopeToCelestial: no site position");
        return false;
    }
    double lst = lst_rad(ln_get_julian_from_sys(), lon);
    double e1, e2, s1, s2;
    if (!mount_axes(v, lst, &e1, &e2)) {
        note("TransformTelescopeToCelestial: the direction vector is not a direction");
        return false;
    }
    pm_status st = pm_model_apply(&model_, nullptr, e1, e2, &s1, &s2);
    if (st < 0) {
        note("TransformTelescopeToCelestial: model evaluation failed (%s)", pm_status_text(st));
        return false;
    }
    sky_radec(s1, s2, lst, lat, &RightAscension, &Declination);
    return true;
}

} // namespace

extern "C" {

MathPlugin *Create()
{
    return new (std::nothrow) PmMathPlugin;
}

void Destroy(MathPlugin *plugin)
{
    delete plugin;
}

const char *GetDisplayName()
{
    return kDisplayName;
}

}
