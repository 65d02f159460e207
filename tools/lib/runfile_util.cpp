// runfile_util.cpp - helpers shared by the readers: a blank record (every
// reader but TPOINT's) and, for the RTS2, MW4, CSV and MMT readers,
// sexagesimal angles, ISO 8601 UTC times, the local sidereal time from UTC,
// the weather for refraction, a German mount's sky place to the encoder
// convention.  docs/formats.md, sections 4-7.
#include "runfile_internal.hpp"

#include <erfa.h>

#include <cmath>
#include <cstring>

namespace pmrun_detail {

pmrun_obs blank_obs(int line)
{
    pmrun_obs o;
    std::memset(&o, 0, sizeof o);
    o.enc_ha = o.enc_dec = o.app_ha = o.app_dec = 0;
    o.pier = PMRUN_PIER_UNKNOWN;
    o.temp_c = o.time_h = nan();
    o.dir = 0;
    o.line = line;
    for (double &a : o.aux) a = nan();
    return o;
}

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// One unsigned decimal number at s[i] (digits, optional fraction); false
// if none.  `frac` tells whether it had a fraction.
bool unsigned_number(const std::string &s, size_t &i, double &v, bool &frac)
{
    size_t b = i;
    while (i < s.size() && is_digit(s[i])) ++i;
    size_t int_end = i;
    frac = false;
    if (i < s.size() && s[i] == '.') {
        ++i;
        size_t fb = i;
        while (i < s.size() && is_digit(s[i])) ++i;
        frac = i > fb;
        if (!frac && int_end == b) return false;
    }
    if (i == b) return false;
    std::string why;
    return parse_number(s.substr(b, i - b), v, why);
}

}  // namespace

bool parse_sexagesimal(const std::string &text, double &value, std::string &why)
{
    std::string s = trim(text);
    if (s.empty()) {
        why = "empty, expected an angle (decimal, or sexagesimal h:m:s / d:m:s)";
        return false;
    }
    // A plain decimal number (with an exponent) first.
    double v;
    std::string w;
    if (parse_number(s, v, w)) {
        value = v;
        return angle_in_range(v, why);
    }
    std::string l = lower(s);
    if (l == "nan" || l == "+nan" || l == "-nan" || l.find("inf") != std::string::npos) {
        why = "NaN/Inf is not accepted, expected a finite angle";
        return false;
    }
    if (decimal_comma(s, why))
        return false;
    size_t i = 0;
    bool neg = false;
    if (s[i] == '+' || s[i] == '-') neg = s[i++] == '-';
    double part[3] = {0, 0, 0};
    int n = 0;
    bool last_frac = false;
    while (i < s.size()) {
        if (n == 3) {
            why = "more than three parts, expected hours/degrees, minutes, seconds";
            return false;
        }
        bool frac;
        if (!unsigned_number(s, i, part[n], frac)) {
            why = "not an angle, expected a decimal number or sexagesimal parts (12:34:56.7, "
                  "12h34m56.7s, -45 30 00)";
            return false;
        }
        if (last_frac) {
            why = "a fraction before the last part, expected it only on the last part";
            return false;
        }
        last_frac = frac;
        ++n;
        // separators: unit marks (h d m s ' " and the UTF-8 degree sign),
        // ':' or spaces; at most one mark, then spaces
        size_t b = i;
        if (i < s.size() && std::strchr("hHdDmMsS'\":", s[i]) != nullptr)
            ++i;
        else if (s.compare(i, 2, "\xC2\xB0") == 0)
            i += 2;
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
        if (i == b && i < s.size()) {
            why = "not an angle, expected a decimal number or sexagesimal parts (12:34:56.7, "
                  "12h34m56.7s, -45 30 00)";
            return false;
        }
    }
    if (n == 0) {
        why = "no number, expected an angle";
        return false;
    }
    for (int k = 1; k < n; ++k)
        if (!(part[k] < 60)) {
            why = k == 1 ? "minutes out of range, expected 0 <= minutes < 60"
                         : "seconds out of range, expected 0 <= seconds < 60";
            return false;
        }
    double mag = part[0] + part[1] / 60.0 + part[2] / 3600.0;
    value = neg ? -mag : mag;
    return angle_in_range(value, why);
}

namespace {

bool fixed_int(const std::string &s, size_t &i, int digits, int &v)
{
    v = 0;
    for (int k = 0; k < digits; ++k, ++i) {
        if (i >= s.size() || !is_digit(s[i])) return false;
        v = 10 * v + (s[i] - '0');
    }
    return true;
}

}  // namespace

bool parse_iso_utc(const std::string &text, UtcTime &t, std::string &why)
{
    const char *expect = "expected an ISO 8601 UTC time YYYY-MM-DDThh:mm:ss[.fff][Z|+hh:mm]";
    std::string s = trim(text);
    size_t i = 0;
    int y, mo, d, h, mi, zh = 0, zm = 0;
    double sec = 0;
    if (!fixed_int(s, i, 4, y) || i >= s.size() || s[i++] != '-' || !fixed_int(s, i, 2, mo) ||
        i >= s.size() || s[i++] != '-' || !fixed_int(s, i, 2, d) || i >= s.size() ||
        (s[i] != 'T' && s[i] != 't' && s[i] != ' ') || !fixed_int(s, ++i, 2, h) ||
        i >= s.size() || s[i++] != ':' || !fixed_int(s, i, 2, mi)) {
        why = expect;
        return false;
    }
    if (i < s.size() && s[i] == ':') {
        ++i;
        size_t b = i;
        bool frac;
        if (!unsigned_number(s, i, sec, frac) || i - b < 2) {
            why = expect;
            return false;
        }
    }
    int zsign = 0;
    bool zoned = false;
    if (i < s.size() && (s[i] == 'Z' || s[i] == 'z')) {
        ++i;
        zoned = true;
    } else if (i < s.size() && (s[i] == '+' || s[i] == '-')) {
        zsign = s[i++] == '-' ? -1 : 1;
        zoned = true;
        if (!fixed_int(s, i, 2, zh)) {
            why = expect;
            return false;
        }
        if (i < s.size() && s[i] == ':') ++i;
        if (!fixed_int(s, i, 2, zm) || zh > 14 || zm > 59) {
            why = expect;
            return false;
        }
    }
    if (i != s.size()) {
        why = expect;
        return false;
    }
    double d1, d2;
    if (mo < 1 || mo > 12 || h > 23 || mi > 59 || !(sec < 61) ||
        eraCal2jd(y, mo, d, &d1, &d2) != 0) {
        why = "not a valid date and time, " + std::string(expect);
        return false;
    }
    if (sec >= 60) {
        // second 60: only the leap second, 23:59:60 UTC at the end of a
        // day ERFA's table (eraDat) ends with one (an outside probe's
        // 22:46:60 on an ordinary day was read as 22:47:00 without a word)
        const long umin = (long)h * 60 + mi - (long)zsign * (zh * 60 + zm);
        const long day = (long)std::floor((double)umin / 1440.0);
        int uy, um, ud, ny, nm, nd;
        double fd, a0 = 0, a1 = 0;
        const bool leap =
            umin - day * 1440 == 23 * 60 + 59 &&
            eraJd2cal(d1, d2 + (double)day, &uy, &um, &ud, &fd) == 0 &&
            eraJd2cal(d1, d2 + (double)day + 1, &ny, &nm, &nd, &fd) == 0 &&
            eraDat(uy, um, ud, 0.0, &a0) >= 0 && eraDat(ny, nm, nd, 0.0, &a1) >= 0 &&
            std::fabs(a1 - a0 - 1.0) < 1e-9;
        if (!leap) {
            why = "second 60 is not a leap second here (only 23:59:60 UTC at the end of a day "
                  "that has one), " + std::string(expect);
            return false;
        }
    }
    t.year = y;
    t.month = mo;
    t.day = d;
    t.hours = h + mi / 60.0 + sec / 3600.0 - zsign * (zh + zm / 60.0);
    t.zoned = zoned;
    return true;
}

double hours_since(const UtcTime &ref, const UtcTime &t)
{
    double a1, a2, b1, b2;
    eraCal2jd(ref.year, ref.month, ref.day, &a1, &a2);
    eraCal2jd(t.year, t.month, t.day, &b1, &b2);
    return ((b1 - a1) + (b2 - a2)) * 24.0 + t.hours;
}

bool lst_from_utc(int year, int month, int day, double hours, double lon, double &lst,
                  std::string &why)
{
    double u1, u2, tai1, tai2, tt1, tt2;
    if (eraDtf2d("UTC", year, month, day, 0, 0, 0.0, &u1, &u2) < 0) {
        why = format("date %d %d %d rejected by ERFA", year, month, day);
        return false;
    }
    u2 += hours / 24.0;
    if (eraUtctai(u1, u2, &tai1, &tai2) < 0) {
        why = "UTC to TAI rejected by ERFA (bad date)";
        return false;
    }
    eraTaitt(tai1, tai2, &tt1, &tt2);
    // UT1 taken as UTC: |DUT1| < 0.9 s, a constant HA offset for a night.
    lst = eraAnp(eraGst06a(u1, u2, tt1, tt2) + lon);
    return true;
}

bool refraction_weather(Context &ctx, int line, const char *what, Weather &out)
{
    const pmrun_options &opt = ctx.opt();
    pmrun_site &site = ctx.run()->site;
    ctx.run()->weather_used = true;
    double h = std::isfinite(site.height_m) ? site.height_m : 0.0;
    double p0 = standard_pressure_hpa(h);
    if (!std::isnan(opt.pressure_hpa)) site.pressure_hpa = opt.pressure_hpa;
    if (!std::isnan(opt.temp_c)) site.temp_c = opt.temp_c;
    if (!std::isnan(opt.humidity)) site.humidity = opt.humidity;
    if (!std::isnan(opt.wavelength_um)) site.wavelength_um = opt.wavelength_um;
    std::string defaulted;
    auto note = [&](const char *s) { defaulted += (defaulted.empty() ? "" : ", ") + std::string(s); };
    double p = site.pressure_hpa, tc = site.temp_c, rh = site.humidity, wl = site.wavelength_um;
    if (std::isnan(p)) {
        p = p0;
        note("pressure (standard atmosphere)");
    }
    if (std::isnan(tc)) {
        tc = 15.0 - 0.0065 * h;
        note("temperature (standard atmosphere)");
    }
    if (std::isnan(rh)) {
        rh = 0.5;
        note("humidity 0.5");
    }
    if (std::isnan(wl)) {
        wl = 0.55;
        note("wavelength 0.55 um");
    }
    // (where a value came from: the file, or the options)
    auto src = [&](double given) { return std::isnan(given) ? what : "given as an option"; };
    if (!(p > 0 && p <= 1100))
        return ctx.fail(line, "pressure %g hPa (%s) is absurd, expected 0 < p <= 1100 hPa", p,
                        src(opt.pressure_hpa));
    if (!(tc > -273.15) || !std::isfinite(tc))
        return ctx.fail(line, "temperature %g C (%s) is below absolute zero, expected -60..+50 C",
                        tc, src(opt.temp_c));
    if (rh > 1 && rh <= 100) {
        ctx.warn(line, "humidity %g (%s) taken as percent: %g", rh, src(opt.humidity), rh / 100);
        rh /= 100;
        site.humidity = rh;
    } else if (!(rh >= 0 && rh <= 1)) {
        return ctx.fail(line, "humidity %g (%s) is out of range, expected 0-1 (or percent 0-100)",
                        rh, src(opt.humidity));
    }
    if (!(wl > 0) || !std::isfinite(wl))
        return ctx.fail(line, "wavelength %g um (%s) is not positive, expected 0.3..25 um", wl,
                        src(opt.wavelength_um));
    if (!defaulted.empty())
        ctx.warn(line, "refraction uses defaults for what %s does not give: %s (height %g m)", what,
                 defaulted.c_str(), h);
    out = Weather{p, tc, rh, wl};
    return true;
}

void sky_to_encoder_deg(double ha_deg, double dec_deg, int pier, double &enc_ha_deg,
                        double &enc_dec_deg)
{
    if (pier == PMRUN_PIER_WEST) {
        enc_ha_deg = reduce_deg(reduce_deg(ha_deg) + 180.0);
        enc_dec_deg = reduce_deg(180.0 - dec_deg);
    } else {
        enc_ha_deg = reduce_deg(ha_deg);
        enc_dec_deg = reduce_deg(dec_deg);
    }
}

}  // namespace pmrun_detail
