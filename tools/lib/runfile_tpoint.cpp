// runfile_tpoint.cpp - TPOINT data files: caption, '!' comments, ':'
// options, the run line, equatorial or alt-az records, optional END.
// docs/formats.md, section 3.
#include "runfile_internal.hpp"

#include <erfa.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pmrun_detail {
namespace {

// Largest |azimuth| accepted (degrees): room for cable wraps, not garbage.
// Mean solar day in sidereal days' units: sidereal hours per solar hour.
constexpr double kSiderealPerSolar = 1.00273790935;

const char *const kRunFields[12] = {
    "latitude degrees", "latitude minutes", "latitude seconds", "year",
    "month",            "day",              "temperature (C)",  "pressure (mbar)",
    "height (m)",       "humidity (0-1)",   "wavelength (um)",  "lapse rate (K/m)"};
const char *kRunExpected =
    "latitude (d m s), UTC date (y m d), temperature (C), pressure (mbar), height (m), "
    "humidity (0-1), wavelength (um), lapse rate (K/m); the fields after the latitude may be "
    "left off from the end";

const char *const kEqFields[14] = {
    "RA hours",        "RA minutes",      "RA seconds",      "Dec degrees",     "Dec minutes",
    "Dec seconds",     "raw RA hours",    "raw RA minutes",  "raw RA seconds",  "raw Dec degrees",
    "raw Dec minutes", "raw Dec seconds", "LST hours",       "LST minutes"};
const char *kEqExpected =
    "catalogue RA (h m s), Dec (d m s), raw RA (h m s), raw Dec (d m s), LST (h m)";
const char *const kAzFields[4] = {"observed azimuth", "observed elevation", "raw azimuth",
                                  "raw elevation"};
const char *kAzExpected =
    "observed azimuth, elevation, raw azimuth, raw elevation (degrees, azimuth from south "
    "through east)";

bool whole(double v) { return v == std::floor(v); }

// A record of an equatorial file before the reduction.
struct EqRecord {
    int line;
    double ra, dec, raw_ra, raw_dec, lst;   // radians (raw: reduced)
    double raw_ra_file, raw_dec_file;       // raw, as written (radians)
    double aux[PMRUN_MAX_AUX];
};

class TpointParser : public FormatParser {
public:
    explicit TpointParser(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        std::string t = trim(text);
        if (t.empty() || t[0] == '!') return true;
        if (stage_ == kAfterEnd) {
            if (!after_end_warned_) ctx_.warn(n, "text after END ignored");
            after_end_warned_ = true;
            return true;
        }
        if (t[0] == '#')
            return ctx_.fail(n,
                             "'#' line in a TPOINT file (TPOINT comments start with '!'): mixed "
                             "formats? expected %s",
                             stage_ == kHead ? "a caption, '!' comment, ':' option or the run line"
                                             : "a record or END");
        t = strip_comment(t, '!');
        if (t[0] == ':') {
            if (stage_ != kHead)
                return ctx_.fail(n,
                                 "option line '%s' after the run line (line %d), expected options "
                                 "before the run line",
                                 excerpt(t).c_str(), run_line_);
            return option(n, t);
        }
        std::vector<std::string> tok = tokens(t);
        if (stage_ == kHead) {
            if (is_number(tok[0]) || tok[0][0] == '+' || tok[0][0] == '-') return run_line(n, tok);
            if (caption_line_ == 0) {
                caption_line_ = n;
                caption_ = t;
            }
            return true;   // caption
        }
        if (tok.size() == 1 && lower(tok[0]) == "end") {
            stage_ = kAfterEnd;
            return true;
        }
        return record(n, tok);
    }

    bool unreadable(int n, const std::string &why) override
    {
        if (stage_ == kHead) return ctx_.fail(n, "%s (before the run line)", why.c_str());
        if (stage_ == kAfterEnd) return true;
        return ctx_.bad_record(n, why);
    }

    bool finish(int last_line) override
    {
        pmrun *run = ctx_.run();
        if (!run_line_)
            return ctx_.fail(last_line,
                             "no run line: the file ends at line %d without one, expected after the "
                             "caption and options a line of %s",
                             last_line, kRunExpected);
        size_t count = mount_ == PMRUN_MOUNT_ALTAZ ? run->obs.size() : eq_.size();
        if (count == 0) {
            if (run->n_skipped > 0)
                return ctx_.fail(last_line, "no records left: all %d records were bad and skipped",
                                 run->n_skipped);
            return ctx_.fail(last_line, "no records after the run line (line %d), expected lines of %s",
                             run_line_, mount_ == PMRUN_MOUNT_ALTAZ ? kAzExpected : kEqExpected);
        }
        run->format = PMRUN_FORMAT_TPOINT;
        run->mount = mount_;
        for (int i = 0; i < n_aux_; ++i) run->aux_names.push_back(format("aux%d", i + 1));
        if (mount_ == PMRUN_MOUNT_EQUATORIAL) return reduce_all();
        return true;
    }

private:
    enum Stage { kHead, kRecords, kAfterEnd };

    bool option(int n, const std::string &t)
    {
        std::vector<std::string> tok = tokens(t.substr(1));
        if (tok.empty()) return ctx_.fail(n, "empty option line ':', expected ':NAME'");
        std::string name = tok[0];
        for (char &c : name)
            if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
        int m = -1;
        if (name == "EQUAT")
            m = PMRUN_MOUNT_EQUATORIAL;
        else if (name == "ALTAZ")
            m = PMRUN_MOUNT_ALTAZ;
        else if (name == "NODA")
            return true;
        else if (name == "GIMBAL")
            return ctx_.fail(n, "option :GIMBAL (generalised gimbal mount) not supported, expected "
                                ":EQUAT or :ALTAZ mounts");
        else {
            ctx_.warn(n, "option :%s accepted, not used", excerpt(name).c_str());
            return true;
        }
        if (mount_line_ && m != mount_)
            return ctx_.fail(n, "option :%s conflicts with the mount option at line %d, expected one "
                                "of :EQUAT or :ALTAZ",
                             name.c_str(), mount_line_);
        mount_ = m;
        mount_line_ = n;
        return true;
    }

    // Sexagesimal value of `parts` tokens from t[i]: the lead (sign allowed
    // if `sign`) must be whole when parts follow, minutes whole when
    // seconds follow, minutes and seconds unsigned and below 60.
    bool sexa(const std::vector<std::string> &t, size_t i, int parts, bool sign,
              const char *const names[], double &value, std::string &why)
    {
        double v[3] = {0, 0, 0};
        for (int k = 0; k < parts; ++k) {
            const std::string &s = t[i + static_cast<size_t>(k)];
            std::string w;
            if (!parse_angle(s, v[k], w)) {
                why = format("field %zu (%s) '%s': %s", i + static_cast<size_t>(k) + 1,
                             names[i + static_cast<size_t>(k)], excerpt(s).c_str(), w.c_str());
                return false;
            }
            const char *problem = nullptr;
            if (k == 0 && !sign && (s[0] == '-' || s[0] == '+'))
                problem = "expected an unsigned number";
            else if (k > 0 && (s[0] == '-' || s[0] == '+'))
                problem = "expected an unsigned number (the sign goes on the first part)";
            else if (k < parts - 1 && !whole(v[k]))
                problem = "expected a whole number (a fraction only on the last part)";
            else if (k > 0 && !(v[k] >= 0 && v[k] < 60))
                problem = k == 1 ? "out of range, expected 0 <= minutes < 60"
                                 : "out of range, expected 0 <= seconds < 60";
            if (problem) {
                why = format("field %zu (%s) '%s': %s", i + static_cast<size_t>(k) + 1,
                             names[i + static_cast<size_t>(k)], excerpt(s).c_str(), problem);
                return false;
            }
        }
        double mag = std::fabs(v[0]) + v[1] / 60.0 + v[2] / 3600.0;
        value = t[i][0] == '-' ? -mag : mag;
        return true;
    }

    bool run_line(int n, const std::vector<std::string> &tok)
    {
        pmrun_site &site = ctx_.run()->site;
        if (tok.size() < 3)
            return ctx_.fail(n, "run line has %zu fields, expected at least 3: %s", tok.size(),
                             kRunExpected);
        if (tok.size() > 12)
            return ctx_.fail(n, "run line has %zu fields, expected at most 12: %s", tok.size(),
                             kRunExpected);
        double v[12];
        for (size_t i = 0; i < 12; ++i) v[i] = nan();
        // four numbers under a line of words: a four-column or named-column
        // file whose header lost its '#' (read as TPOINT, the words its
        // caption: the message was about a latitude's whole degrees)
        std::string hint;
        if (tok.size() == 4 && caption_line_ > 0)
            hint = format("; read as a TPOINT file, line %d ('%s') its caption and this line its "
                          "run line: if the file holds four-column or named-column records, "
                          "start its header with '#' ('# %s', docs/formats.md, sections 1 and 2)",
                          caption_line_, excerpt(caption_).c_str(), excerpt(caption_).c_str());
        for (size_t i = 0; i < tok.size(); ++i) {
            std::string why;
            if (!parse_number(tok[i], v[i], why))
                return ctx_.fail(n, "run line field %zu (%s) '%s': %s; the run line is %s%s", i + 1,
                                 kRunFields[i], excerpt(tok[i]).c_str(), why.c_str(), kRunExpected,
                                 hint.c_str());
        }
        std::string why;
        double lat;
        if (!sexa(tok, 0, 3, true, kRunFields, lat, why))
            return ctx_.fail(n, "run line %s%s", why.c_str(), hint.c_str());
        if (std::fabs(lat) > 90)
            return ctx_.fail(n, "run line latitude %s %s %s is beyond +-90 deg, expected -90..+90",
                             tok[0].c_str(), tok[1].c_str(), tok[2].c_str());
        site.latitude_rad = lat * kDeg;
        if (tok.size() >= 4 && tok.size() < 6)
            return ctx_.fail(n, "run line has an incomplete date, expected year month day after the "
                                "latitude%s",
                             hint.c_str());
        if (tok.size() >= 6) {
            for (size_t i = 3; i < 6; ++i)
                if (!whole(v[i]))
                    return ctx_.fail(n, "run line field %zu (%s) '%s': expected a whole number", i + 1,
                                     kRunFields[i], tok[i].c_str());
            double d1, d2;
            if (std::fabs(v[3]) > 100000 || std::fabs(v[4]) > 100000 || std::fabs(v[5]) > 100000 ||
                eraCal2jd(static_cast<int>(v[3]), static_cast<int>(v[4]), static_cast<int>(v[5]),
                          &d1, &d2) != 0)
                return ctx_.fail(n, "run line date %s %s %s is not a valid date, expected year month "
                                    "day (UTC)",
                                 tok[3].c_str(), tok[4].c_str(), tok[5].c_str());
            // (a year of two digits, 23 for 2023, was read as 23 AD: 2,000
            // years of precession on every catalogue place, under a note that
            // only TAI-UTC was a guess)
            // (alt-az records are not reduced: the date is not used there)
            if (v[3] < 1000 && mount_ == PMRUN_MOUNT_EQUATORIAL)
                return ctx_.fail(n, "run line field 4 (year) '%s': expected the year in full "
                                    "(2023, not 23): the catalogue places are reduced to the date",
                                 tok[3].c_str());
            if ((v[3] < 1900 || v[3] > 2200) && mount_ == PMRUN_MOUNT_EQUATORIAL)
                ctx_.warn(n, "run line year %s: the catalogue places are reduced to that date; "
                             "is it the year of the observations?",
                          tok[3].c_str());
            site.year = static_cast<int>(v[3]);
            site.month = static_cast<int>(v[4]);
            site.day = static_cast<int>(v[5]);
        } else if (mount_ == PMRUN_MOUNT_EQUATORIAL) {
            return ctx_.fail(n, "run line has no date: the equatorial reduction needs the UTC date "
                                "(y m d) after the latitude");
        }
        site.temp_c = v[6];
        site.pressure_hpa = v[7];
        site.height_m = v[8];
        site.humidity = v[9];
        site.wavelength_um = v[10];
        site.lapse_k_per_m = v[11];
        run_line_ = n;
        stage_ = kRecords;
        return weather(n);
    }

    // Overrides, plausibility checks and defaults of the run line's
    // weather (docs/formats.md, "Weather").
    bool weather(int n)
    {
        const pmrun_options &opt = ctx_.opt();
        pmrun_site &site = ctx_.run()->site;
        bool refr = opt.refraction && mount_ == PMRUN_MOUNT_EQUATORIAL;
        const char *src;
        ctx_.run()->weather_used = refr;

        if (std::isfinite(site.height_m) && (site.height_m < -500 || site.height_m > 9000))
            ctx_.warn(n, "height %g m is implausible, expected -500..9000 m", site.height_m);
        double h = std::isfinite(site.height_m) ? site.height_m : 0.0;
        double p0 = standard_pressure_hpa(h);

        // Pressure.
        src = "pressure";
        if (!std::isnan(opt.pressure_hpa)) {
            site.pressure_hpa = opt.pressure_hpa;
            src = "pressure (pressure_hpa option)";
        }
        double p = site.pressure_hpa;
        if (std::isnan(p)) {
            if (refr) {
                ctx_.warn(n, "no pressure on the run line: refraction uses %.1f hPa, the standard "
                             "atmosphere at %g m",
                          p0, h);
                p = p0;
            }
        } else {
            std::string hint;
            if (std::fabs(p * 1.33322 / p0 - 1) < 0.1)
                hint = format("; looks like mmHg (%.1f mmHg = %.1f hPa)", p, p * 1.33322);
            else if (std::fabs(p * 33.8639 / p0 - 1) < 0.1)
                hint = format("; looks like inHg (%.2f inHg = %.1f hPa)", p, p * 33.8639);
            if (!(p > 0 && p <= 1100)) {
                if (refr || !std::isfinite(p))
                    return ctx_.fail(n, "%s %g mbar is absurd, expected 0 < p <= 1100 hPa (standard "
                                        "atmosphere at %g m: %.1f hPa)%s",
                                     src, p, h, p0, hint.c_str());
                ctx_.warn(n, "%s %g mbar is absurd, expected 0 < p <= 1100 hPa (standard atmosphere "
                             "at %g m: %.1f hPa)%s; not used",
                          src, p, h, p0, hint.c_str());
            } else if (std::fabs(p / p0 - 1) > 0.2) {
                ctx_.warn(n, "%s %g mbar differs by %+.0f%% from the standard atmosphere at %g m "
                             "(%.1f hPa)%s",
                          src, p, 100 * (p / p0 - 1), h, p0, hint.c_str());
            }
        }

        // Temperature.
        src = "temperature";
        if (!std::isnan(opt.temp_c)) {
            site.temp_c = opt.temp_c;
            src = "temperature (temp_c option)";
        }
        double tc = site.temp_c;
        if (std::isnan(tc)) {
            if (refr) {
                tc = 15.0 - 0.0065 * h;
                ctx_.warn(n, "no temperature on the run line: refraction uses %.1f C, the standard "
                             "atmosphere at %g m",
                          tc, h);
            }
        } else if (tc <= -273.15) {
            if (refr)
                return ctx_.fail(n, "%s %g C is below absolute zero, expected -60..+50 C", src, tc);
            ctx_.warn(n, "%s %g C is below absolute zero, expected -60..+50 C", src, tc);
        } else if (tc < -60 || tc > 50) {
            ctx_.warn(n, "%s %g C is implausible, expected -60..+50 C", src, tc);
        }

        // Humidity.
        src = "humidity";
        if (!std::isnan(opt.humidity)) {
            site.humidity = opt.humidity;
            src = "humidity (humidity option)";
        }
        double rh = site.humidity;
        if (std::isnan(rh)) {
            if (refr) {
                rh = 0.5;
                ctx_.warn(n, "no humidity on the run line: refraction uses 0.5");
            }
        } else if (rh > 1 && rh <= 100) {
            ctx_.warn(n, "%s %g taken as percent: %g", src, rh, rh / 100);
            rh /= 100;
            site.humidity = rh;
        } else if (rh < 0 || rh > 100) {
            if (refr)
                return ctx_.fail(n, "%s %g is out of range, expected 0-1 (or percent 0-100)", src, rh);
            ctx_.warn(n, "%s %g is out of range, expected 0-1 (or percent 0-100)", src, rh);
        }

        // Wavelength.
        src = "wavelength";
        if (!std::isnan(opt.wavelength_um)) {
            site.wavelength_um = opt.wavelength_um;
            src = "wavelength (wavelength_um option)";
        }
        double wl = site.wavelength_um;
        if (std::isnan(wl)) {
            if (refr) {
                wl = 0.55;
                ctx_.warn(n, "no wavelength on the run line: refraction uses 0.55 um");
            }
        } else if (wl <= 0) {
            if (refr)
                return ctx_.fail(n, "%s %g um is not positive, expected 0.3..25 um (optical/IR)", src,
                                 wl);
            ctx_.warn(n, "%s %g um is not positive, expected 0.3..25 um (optical/IR)", src, wl);
        } else if (wl < 0.3 || wl > 25) {
            ctx_.warn(n, "%s %g um is outside 0.3..25 um%s", src, wl,
                      wl > 100 ? " (ERFA takes it as radio)" : "");
        }
        weather_ = Weather{p, tc, rh, wl};
        return true;
    }

    bool aux_fields(const std::vector<std::string> &tok, size_t first, double *aux, std::string &why)
    {
        for (size_t i = first; i < tok.size(); ++i) {
            std::string w;
            if (!parse_number(tok[i], aux[i - first], w)) {
                why = format("field %zu (aux%zu) '%s': %s", i + 1, i - first + 1,
                             excerpt(tok[i]).c_str(), w.c_str());
                return false;
            }
        }
        int extra = static_cast<int>(tok.size() - first);
        n_aux_ = std::max(n_aux_, extra);
        return true;
    }

    // Notes once that records carry fields beyond the standard ones.
    void note_extra(int n, const std::vector<std::string> &tok, size_t need)
    {
        size_t extra = tok.size() - need;
        if (extra == 0 || extra_warned_) return;
        extra_warned_ = true;
        // whole LST minutes and a first extra field below 60: the LST's
        // seconds, written where TPOINT has decimal minutes?
        double m = 0, x = -1;
        std::string w;
        const bool lst_seconds = need == 14 && parse_number(tok[13], m, w) && whole(m) &&
                                 parse_number(tok[14], x, w) && x >= 0 && x < 60;
        ctx_.warn(n, "record has %zu field(s) beyond the standard %zu: kept as auxiliary columns "
                     "aux1..aux%zu (noted once)%s",
                  extra, need, extra,
                  lst_seconds ? "; if field 15 is the LST's seconds, write the LST as hours and "
                                "decimal minutes (TPOINT's h m): its seconds are not read"
                              : "");
    }

    bool record(int n, const std::vector<std::string> &tok)
    {
        pmrun *run = ctx_.run();
        if (run->obs.size() + eq_.size() >= static_cast<size_t>(PMRUN_MAX_RECORDS))
            return ctx_.fail(n, "more than %d records, expected at most %d", PMRUN_MAX_RECORDS,
                             PMRUN_MAX_RECORDS);
        bool altaz = mount_ == PMRUN_MOUNT_ALTAZ;
        size_t need = altaz ? 4 : 14;
        if (tok.size() < need || tok.size() > need + PMRUN_MAX_AUX) {
            // four to eight fields and no mount option: an alt-az run without its ': ALTAZ'?
            const bool az_hint = !altaz && !mount_line_ && tok.size() >= 4 && tok.size() <= 8;
            return ctx_.bad_record(n, format("%zu fields, expected %zu%s: %s%s", tok.size(), need,
                                             tok.size() > need ? format(" (+ at most %d auxiliary)",
                                                                        PMRUN_MAX_AUX)
                                                                     .c_str()
                                                               : "",
                                             altaz ? kAzExpected : kEqExpected,
                                             az_hint ? " (an alt-az run? TPOINT reads its records "
                                                       "as alt-az only after the option line "
                                                       "': ALTAZ' before the run line)"
                                                     : ""));
        }
        double aux[PMRUN_MAX_AUX];
        for (double &a : aux) a = nan();
        std::string why;
        if (!aux_fields(tok, need, aux, why)) return ctx_.bad_record(n, why);
        note_extra(n, tok, need);
        return altaz ? altaz_record(n, tok, aux) : eq_record(n, tok, aux);
    }

    bool altaz_record(int n, const std::vector<std::string> &tok, const double *aux)
    {
        double v[4];
        for (size_t i = 0; i < 4; ++i) {
            std::string w;
            if (!parse_angle(tok[i], v[i], w))
                return ctx_.bad_record(n, format("field %zu (%s) '%s': %s (degrees)", i + 1,
                                                 kAzFields[i], excerpt(tok[i]).c_str(), w.c_str()));
            // the observed elevation is a place on the sky; the other three
            // are angles on a circle (the raw ones modular encoder readings)
            if (i == 1 && std::fabs(v[i]) > 90)
                return ctx_.bad_record(n, format("field 2 (%s) '%s': elevation beyond +-90 deg, "
                                                 "expected -90..+90",
                                                 kAzFields[i], excerpt(tok[i]).c_str()));
        }
        pmrun_obs o = blank(n, aux);
        // TPOINT azimuth is from south through east: A_NE = 180 deg - A_SE
        // (of the exactly reduced raw azimuth, so both writings agree).
        o.app_ha = reduce_deg_positive(180.0 - reduce_deg(v[0])) * kDeg;
        o.app_dec = v[1] * kDeg;
        o.enc_ha = reduce_deg(180.0 - reduce_deg(v[2])) * kDeg;
        o.enc_dec = reduce_deg(v[3]) * kDeg;
        o.enc_raw[0] = (180.0 - v[2]) * kDeg;
        o.enc_raw[1] = v[3] * kDeg;
        ctx_.run()->obs.push_back(o);
        return true;
    }

    bool eq_record(int n, const std::vector<std::string> &tok, const double *aux)
    {
        EqRecord r;
        r.line = n;
        std::copy(aux, aux + PMRUN_MAX_AUX, r.aux);
        std::string why;
        double ra, dec, raw_ra, raw_dec, lst;
        if (!sexa(tok, 0, 3, false, kEqFields, ra, why) || !sexa(tok, 3, 3, true, kEqFields, dec, why) ||
            !sexa(tok, 6, 3, true, kEqFields, raw_ra, why) ||
            !sexa(tok, 9, 3, true, kEqFields, raw_dec, why) ||
            !sexa(tok, 12, 2, false, kEqFields, lst, why))
            return ctx_.bad_record(n, why);
        if (ra >= 24 || lst >= 24) {
            int f = ra >= 24 ? 1 : 13;
            return ctx_.bad_record(n, format("field %d (%s) '%s': out of range, expected 0 <= hours < 24",
                                             f, kEqFields[f - 1], tok[static_cast<size_t>(f - 1)].c_str()));
        }
        if (std::fabs(dec) > 90)
            return ctx_.bad_record(n, format("catalogue Dec %s %s %s is beyond +-90 deg, expected a J2000 "
                                             "declination within -90..+90",
                                             tok[3].c_str(), tok[4].c_str(), tok[5].c_str()));
        // The raw (encoder) RA and Dec are modular: any finite value, the
        // file's own kept, reduced exactly (hours into [0, 24) by fmod and
        // one exact step; degrees into (-180, 180]).
        r.raw_ra_file = raw_ra * kHour;
        r.raw_dec_file = raw_dec * kDeg;
        raw_ra = std::fmod(raw_ra, 24.0);
        if (raw_ra < 0) raw_ra += 24.0;
        if (raw_ra >= 24.0) raw_ra = 0.0;
        raw_dec = reduce_deg(raw_dec);
        r.ra = ra * kHour;
        r.dec = dec * kDeg;
        r.raw_ra = raw_ra * kHour;
        r.raw_dec = raw_dec * kDeg;
        r.lst = lst * kHour;
        eq_.push_back(r);
        return true;
    }

    pmrun_obs blank(int n, const double *aux) const
    {
        pmrun_obs o;
        std::memset(&o, 0, sizeof o);
        o.enc_ha = o.enc_dec = o.app_ha = o.app_dec = 0;
        o.pier = PMRUN_PIER_UNKNOWN;
        o.temp_c = ctx_.run()->site.temp_c;
        o.time_h = nan();
        o.dir = 0;
        o.line = n;
        std::copy(aux, aux + PMRUN_MAX_AUX, o.aux);
        return o;
    }

    // Times of the records (docs/formats.md, "Time of each record"): the
    // sidereal time elapsed since the first record, unwrapped from record
    // to record, converted to solar time; the middle of the run is put at
    // 12h UTC on the run date.
    std::vector<double> utc_hours() const
    {
        std::vector<double> s(eq_.size());
        double acc = 0;
        for (size_t i = 0; i < eq_.size(); ++i) {
            if (i > 0) {
                double d = (eq_[i].lst - eq_[i - 1].lst) / kHour;   // hours
                d -= 24.0 * std::floor((d + 12.0) / 24.0);        // [-12, 12)
                acc += d;
            }
            s[i] = acc;
        }
        double lo = *std::min_element(s.begin(), s.end());
        double hi = *std::max_element(s.begin(), s.end());
        double mid = 0.5 * (lo + hi);
        for (double &x : s) x = 12.0 + (x - mid) / kSiderealPerSolar;
        return s;
    }

    bool reduce_all()
    {
        pmrun *run = ctx_.run();
        const pmrun_site &site = run->site;
        bool refr = ctx_.opt().refraction != 0;
        Reduction red;
        std::string why;
        if (!red.setup(site.year, site.month, site.day, site.latitude_rad, site.height_m,
                       refr ? &weather_ : nullptr, why))
            return ctx_.fail(run_line_, "%s", why.c_str());
        if (red.dubious)
            ctx_.warn(run_line_, "date %d %d %d is outside ERFA's leap-second table: TAI-UTC is a "
                                 "guess (effect far below 0.1 arcsec)",
                      site.year, site.month, site.day);
        std::vector<double> utc = utc_hours();
        run->obs.reserve(eq_.size());
        for (size_t i = 0; i < eq_.size(); ++i) {
            const EqRecord &r = eq_[i];
            pmrun_obs o = blank(r.line, r.aux);
            if (!red.observed(r.ra, r.dec, r.lst, utc[i], o.app_ha, o.app_dec, why))
                return ctx_.fail(r.line, "%s", why.c_str());
            o.enc_ha = eraAnpm(r.lst - r.raw_ra);
            o.enc_dec = r.raw_dec;
            o.enc_raw[0] = r.lst - r.raw_ra_file;
            o.enc_raw[1] = r.raw_dec_file;
            o.pier = std::fabs(r.raw_dec) > kPi / 2 ? PMRUN_PIER_WEST : PMRUN_PIER_EAST;
            o.time_h = utc[i];
            double az, el;
            eraHd2ae(o.app_ha, o.app_dec, site.latitude_rad, &az, &el);
            if (el < 0)
                ctx_.warn(r.line, "star below the horizon (elevation %.2f deg), expected a visible "
                                  "star: check the latitude, LST and catalogue place",
                          el / kDeg);
            run->obs.push_back(o);
        }
        return true;
    }

    Context &ctx_;
    Stage stage_ = kHead;
    int caption_line_ = 0;
    std::string caption_;   // its text (a hint where a column header lost its '#')
    int run_line_ = 0;
    int mount_ = PMRUN_MOUNT_EQUATORIAL;
    int mount_line_ = 0;
    int n_aux_ = 0;
    bool after_end_warned_ = false;
    bool extra_warned_ = false;
    Weather weather_{nan(), nan(), nan(), nan()};
    std::vector<EqRecord> eq_;
};

}  // namespace

std::unique_ptr<FormatParser> make_tpoint_parser(Context &ctx)
{
    return std::unique_ptr<FormatParser>(new TpointParser(ctx));
}

}  // namespace pmrun_detail
