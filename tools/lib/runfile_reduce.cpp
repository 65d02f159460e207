// runfile_reduce.cpp - reduction of TPOINT catalogue places (J2000 mean
// places) to observed hour angle and declination with ERFA.
// docs/formats.md, "The reduction".
#include "runfile_internal.hpp"

#include <erfa.h>
#include <erfam.h>

#include <algorithm>
#include <cmath>

namespace pmrun_detail {

bool Reduction::setup(int year, int month, int day, double latitude_rad, double height_m,
                      const Weather *weather, std::string &why)
{
    if (eraDtf2d("UTC", year, month, day, 0, 0, 0.0, &utc1, &utc2) < 0) {
        why = format("date %d %d %d rejected by ERFA, expected a valid UTC date y m d", year, month,
                     day);
        return false;
    }
    double dat;
    dubious = eraDat(year, month, day, 0.5, &dat) == 1;
    // The observer's speed from the Earth's rotation over c (eraApco's
    // diurab, without polar motion): eraPvtob on the WGS84 ellipsoid.
    diurab = 0;
    if (std::isfinite(latitude_rad)) {
        double pv[2][3];
        eraPvtob(0.0, latitude_rad, std::isfinite(height_m) ? height_m : 0.0, 0.0, 0.0, 0.0, 0.0,
                 pv);
        diurab = std::hypot(pv[1][0], pv[1][1]) / ERFA_CMPS;
    }
    latitude = std::isfinite(latitude_rad) ? latitude_rad : 0.0;
    refract = weather != nullptr;
    refa = refb = 0;
    if (weather)
        eraRefco(weather->pressure_hpa, weather->temp_c, weather->humidity, weather->wavelength_um,
                 &refa, &refb);
    return true;
}

// Observed (refracted) place from the topocentric apparent one: the ERFA
// refraction model dZ = A tan Z + B tan^3 Z (Z observed zenith distance),
// inverted with one Newton step from the unrefracted zenith distance and
// guarded near the horizon exactly as eraAtioq does (sin el >= 0.05,
// cos el >= 1e-6).
static void refract_hd(double lat, double refa, double refb, double &ha, double &dec)
{
    double az, el;
    eraHd2ae(ha, dec, lat, &az, &el);
    double r = std::max(std::cos(el), 1e-6);    // sin of the zenith distance
    double z = std::max(std::sin(el), 0.05);    // cos of the zenith distance
    double tz = r / z;
    double w = refb * tz * tz;
    double del = (refa + w) * tz / (1.0 + (refa + 3.0 * w) / (z * z));
    eraAe2hd(az, el + del, lat, &ha, &dec);
}

bool Reduction::apparent(double ra, double dec, double lst, double utc_h, double &ha,
                         double &dec_app, std::string &why) const
{
    double tai1, tai2, tt1, tt2;
    int j = eraUtctai(utc1, utc2 + utc_h / 24.0, &tai1, &tai2);
    if (j < 0) {
        why = "UTC to TAI rejected by ERFA (bad date)";
        return false;
    }
    eraTaitt(tai1, tai2, &tt1, &tt2);
    // ICRS -> CIRS (precession-nutation, aberration, light deflection);
    // proper motion, parallax and radial velocity zero; TT stands for TDB.
    double ri, di, eo;
    eraAtci13(ra, dec, 0.0, 0.0, 0.0, 0.0, tt1, tt2, &ri, &di, &eo);
    // Equinox-based apparent RA through the equation of the origins.
    double ra_app = eraAnp(ri - eo);
    ha = eraAnpm(lst - ra_app);
    dec_app = di;
    return true;
}

void Reduction::topocentric(double &ha, double &dec) const
{
    if (diurab == 0) return;
    // (x toward the meridian's equator, y toward the east point, z the pole:
    // eraAtioq's first-order form)
    double cd = std::cos(dec);
    double x = cd * std::cos(ha), y = -cd * std::sin(ha), z = std::sin(dec);
    double f = 1.0 - diurab * y;
    x *= f;
    y = f * (y + diurab);
    z *= f;
    ha = std::atan2(-y, x);
    dec = std::atan2(z, std::hypot(x, y));
}

void Reduction::refract_place(double &ha, double &dec) const
{
    if (!refract) return;
    refract_hd(latitude, refa, refb, ha, dec);
    ha = eraAnpm(ha);
}

bool Reduction::observed(double ra, double dec, double lst, double utc_h, double &ha,
                         double &dec_obs, std::string &why) const
{
    double h, d;
    if (!apparent(ra, dec, lst, utc_h, h, d, why)) return false;
    topocentric(h, d);
    if (refract) refract_hd(latitude, refa, refb, h, d);
    ha = eraAnpm(h);
    dec_obs = d;
    return true;
}

}  // namespace pmrun_detail
