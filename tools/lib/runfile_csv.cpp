// runfile_csv.cpp - N.I.N.A./ASCOM-style CSV logs: optional '# key: value'
// metadata lines, a header line of column names, one row per plate solve:
// the mount's RA/Dec (as its driver reports them), the solved RA/Dec, the
// side of pier (ASCOM's), the UTC time and/or the LST, the temperature.
// RA in hours and Dec in degrees, decimal or sexagesimal.  The equinox of
// the places (J2000 or JNow) must be stated: '# equinox:', an Equinox
// column, or pmrun_options.equinox.  docs/formats.md, section 6.
#include "runfile_internal.hpp"

#include <erfa.h>

#include <cmath>
#include <cstring>

namespace pmrun_detail {
namespace {

enum class Col { kMountRa, kMountDec, kSolvedRa, kSolvedDec, kPier, kTime, kLst, kTemp, kEquinox,
                 kUnused };

struct Known {
    Col kind;
    const char *names[10];
};

// Column names, normalised: lower case, letters and digits only ("Mount
// RA", "mount_ra", "MountRA" are all "mountra").
const Known kKnown[] = {
    {Col::kMountRa, {"mountra", "ramount", "telescopera", "scopera", "encoderra", "ra", nullptr}},
    {Col::kMountDec,
     {"mountdec", "decmount", "telescopedec", "scopedec", "encoderdec", "dec", nullptr}},
    {Col::kSolvedRa,
     {"solvedra", "rasolved", "platesolvedra", "platesolvera", "truera", "actualra",
      "measuredra", nullptr}},
    {Col::kSolvedDec,
     {"solveddec", "decsolved", "platesolveddec", "platesolvedec", "truedec", "actualdec",
      "measureddec", nullptr}},
    {Col::kPier, {"pier", "pierside", "sideofpier", "side", nullptr}},
    {Col::kTime,
     {"time", "utc", "timeutc", "utctime", "datetime", "datetimeutc", "date", "dateutc",
      "timestamp", nullptr}},
    {Col::kLst, {"lst", "siderealtime", "localsiderealtime", nullptr}},
    {Col::kTemp,
     {"temperature", "temp", "ambienttemperature", "tempc", "temperaturec", nullptr}},
    {Col::kEquinox, {"equinox", "epoch", nullptr}},
};

// Unit suffixes a name may carry ("Mount RA [h]" is "mountrah").
const char *const kSuffixes[] = {"hours", "hour", "degrees", "degree", "deg", "hms", "dms", "h"};

const char *kColumnsExpected =
    "columns MountRA, MountDec, SolvedRA, SolvedDec (RA hours, Dec degrees), PierSide, and "
    "Time (UTC, ISO 8601) or LST";

std::string normalise(const std::string &s)
{
    std::string out;
    for (char c : s)
        if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'))
            out += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    return out;
}

// The column a header name names; *unit: 'd' where a unit suffix of the
// name says degrees (deg, degree(s), dms), 'h' hours (h, hour(s), hms), 0
// none.
Col classify(const std::string &norm, char *unit = nullptr)
{
    if (unit) *unit = 0;
    for (int pass = 0; pass < 2; ++pass)
        for (const char *suf : kSuffixes) {
            std::string n = norm;
            if (pass == 1) {
                size_t ls = std::strlen(suf);
                if (n.size() <= ls || n.compare(n.size() - ls, ls, suf) != 0) continue;
                n.resize(n.size() - ls);
            }
            for (const Known &k : kKnown)
                for (int i = 0; k.names[i]; ++i)
                    if (n == k.names[i]) {
                        if (unit && pass == 1) *unit = suf[0] == 'd' ? 'd' : 'h';
                        return k.kind;
                    }
            if (pass == 0) break;
        }
    return Col::kUnused;
}

const char *col_title(Col c)
{
    switch (c) {
    case Col::kMountRa: return "mount RA";
    case Col::kMountDec: return "mount Dec";
    case Col::kSolvedRa: return "solved RA";
    case Col::kSolvedDec: return "solved Dec";
    case Col::kPier: return "pier side";
    case Col::kTime: return "time";
    case Col::kLst: return "LST";
    case Col::kTemp: return "temperature";
    case Col::kEquinox: return "equinox";
    default: return "unused";
    }
}

// Splits a row at `delim`; double quotes protect delimiters ("" is a
// quote).  False with `why` on a malformed quote.
bool split_row(const std::string &line, char delim, std::vector<std::string> &out, std::string &why)
{
    out.clear();
    std::string cur;
    size_t i = 0, n = line.size();
    for (;;) {
        cur.clear();
        while (i < n && (line[i] == ' ' || line[i] == '\t')) ++i;
        if (i < n && line[i] == '"') {
            ++i;
            for (;;) {
                if (i >= n) {
                    why = "a quoted field not closed by '\"', expected \"...\"";
                    return false;
                }
                if (line[i] == '"') {
                    if (i + 1 < n && line[i + 1] == '"') {
                        cur += '"';
                        i += 2;
                        continue;
                    }
                    ++i;
                    break;
                }
                cur += line[i++];
            }
            while (i < n && (line[i] == ' ' || line[i] == '\t')) ++i;
            if (i < n && line[i] != delim) {
                why = "text after a quoted field, expected the delimiter";
                return false;
            }
        } else {
            while (i < n && line[i] != delim) {
                if (line[i] == '"') {
                    why = "a '\"' inside an unquoted field, expected quotes around the whole field";
                    return false;
                }
                cur += line[i++];
            }
            cur = trim(cur);
        }
        out.push_back(cur);
        if (i >= n) return true;
        ++i;   // the delimiter
    }
}

int parse_equinox(const std::string &v)
{
    std::string l = lower(trim(v));
    if (l == "j2000" || l == "j2000.0" || l == "2000" || l == "2000.0" || l == "icrs" ||
        l == "fk5")
        return PMRUN_EQUINOX_J2000;
    if (l == "jnow" || l == "now" || l == "apparent" || l == "topocentric" || l == "of date" ||
        l == "date")
        return PMRUN_EQUINOX_JNOW;
    return -1;
}

struct Row {
    int line;
    double mra, mdec, sra, sdec;   // hours, degrees
    int pier;
    char pier_number;              // the side as a bare number: '0', '1', '-' (-1), '+' (+1)
    bool has_time;
    UtcTime t;
    double lst_h;                  // NaN: from the time
    double temp;
    int equinox;                   // PMRUN_EQUINOX_*, FILE: the file's
};

class CsvParser : public FormatParser {
public:
    explicit CsvParser(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        std::string t = trim(text);
        if (t.empty()) return true;
        if (t[0] == '#') return header_line_ ? true : metadata(n, t.substr(1));
        if (!header_line_ && !sep_ && excel_sep_line(t) && t.size() == 5 &&
            (t[4] == ',' || t[4] == ';')) {
            sep_ = t[4];   // Excel's delimiter line (the detector checked it)
            return true;
        }
        if (!header_line_) return header(n, t);
        return row(n, t);
    }

    bool unreadable(int n, const std::string &why) override
    {
        if (!header_line_) return ctx_.fail(n, "%s (before the header line)", why.c_str());
        return ctx_.bad_record(n, why);
    }

    bool finish(int last_line) override
    {
        pmrun *run = ctx_.run();
        if (!header_line_)
            return ctx_.fail(last_line, "no header line: the file ends at line %d, expected a line "
                                        "naming the %s",
                             last_line, kColumnsExpected);
        if (rows_.empty()) {
            if (run->n_skipped > 0)
                return ctx_.fail(last_line, "no records left: all %d records were bad and skipped",
                                 run->n_skipped);
            return ctx_.fail(last_line, "no rows after the header (line %d), expected one row per "
                                        "plate solve",
                             header_line_);
        }
        return build();
    }

private:
    bool metadata(int n, const std::string &body)
    {
        std::string b = trim(body);
        size_t colon = b.find(':');
        if (colon == std::string::npos || colon == 0) return true;   // a comment
        std::string key = lower(trim(b.substr(0, colon)));
        std::string value = trim(b.substr(colon + 1));
        for (char c : key)
            if (!((c >= 'a' && c <= 'z') || c == '_' || c == ' ')) return true;   // a comment
        pmrun_site &site = ctx_.run()->site;
        if (key == "equinox") {
            int e = parse_equinox(value);
            if (e < 0)
                return ctx_.fail(n, "equinox '%s', expected J2000 or JNow", excerpt(value).c_str());
            meta_equinox_ = e;
            return true;
        }
        if (key == "refraction") {
            std::string l = lower(value);
            if (l == "yes" || l == "on" || l == "true" || l == "1")
                meta_refraction_ = true;
            else if (l == "no" || l == "off" || l == "false" || l == "0")
                meta_refraction_ = false;
            else
                return ctx_.fail(n, "refraction '%s', expected yes or no", excerpt(value).c_str());
            return true;
        }
        double *slot = nullptr;
        double lo = -1e300, hi = 1e300;
        const char *unit = "";
        if (key == "latitude") {
            slot = &lat_deg_;
            lo = -90, hi = 90, unit = "degrees";
        } else if (key == "longitude") {
            slot = &lon_deg_;
            lo = -360, hi = 360, unit = "degrees, east positive";
        } else if (key == "height" || key == "elevation" || key == "altitude") {
            slot = &site.height_m;
            lo = -1000, hi = 10000, unit = "metres";
        } else if (key == "pressure") {
            slot = &site.pressure_hpa, unit = "hPa";
        } else if (key == "temperature") {
            slot = &site.temp_c, unit = "C";
        } else if (key == "humidity") {
            slot = &site.humidity, unit = "0-1";
        } else if (key == "wavelength") {
            slot = &site.wavelength_um, unit = "micrometres";
        } else {
            ctx_.warn(n, "metadata '%s' accepted, not used", excerpt(key).c_str());
            return true;
        }
        double v;
        std::string why;
        if (!parse_number(value, v, why))
            return ctx_.fail(n, "%s '%s': %s (%s)", key.c_str(), excerpt(value).c_str(), why.c_str(),
                             unit);
        if (v < lo || v > hi)
            return ctx_.fail(n, "%s %s is out of range, expected %g..%g (%s)", key.c_str(),
                             excerpt(value).c_str(), lo, hi, unit);
        *slot = v;
        return true;
    }

    bool header(int n, const std::string &t)
    {
        header_line_ = n;
        delim_ = sep_ ? sep_ : t.find(',') != std::string::npos ? ',' : ';';
        std::vector<std::string> names;
        std::string why;
        if (!split_row(t, delim_, names, why)) return ctx_.fail(n, "header: %s", why.c_str());
        std::string unused;
        for (const std::string &name : names) {
            char unit;
            Col c = classify(normalise(name), &unit);
            // a unit the column's name gives: RA and LST in degrees are read
            // so (an 'RA (deg)' column was read as hours, silently), a
            // declination in hours is refused
            const bool ra = c == Col::kMountRa || c == Col::kSolvedRa || c == Col::kLst;
            const bool dec = c == Col::kMountDec || c == Col::kSolvedDec;
            if (dec && unit == 'h')
                return ctx_.fail(n, "column '%s': a declination in hours? expected degrees",
                                 excerpt(name).c_str());
            deg_.push_back(ra && unit == 'd');
            for (size_t k = 0; k < cols_.size(); ++k)
                if (c != Col::kUnused && cols_[k] == c)
                    return ctx_.fail(n, "column '%s' is a second %s column (the first is '%s'), "
                                        "expected each once",
                                     excerpt(name).c_str(), col_title(c),
                                     excerpt(names[k]).c_str());
            cols_.push_back(c);
            if (c == Col::kUnused) unused += (unused.empty() ? "'" : ", '") + excerpt(name) + "'";
            has_[static_cast<int>(c)] = true;
        }
        for (Col c : {Col::kMountRa, Col::kMountDec, Col::kSolvedRa, Col::kSolvedDec})
            if (!has_[static_cast<int>(c)])
                return ctx_.fail(n, "no %s column in the header, expected %s", col_title(c),
                                 kColumnsExpected);
        if (!has_[static_cast<int>(Col::kLst)] &&
            !(has_[static_cast<int>(Col::kTime)] && !std::isnan(lon_deg_)))
            return ctx_.fail(n, "no LST column and %s: the hour angles need the sidereal time, "
                                "expected an LST column, or a Time column (UTC) and '# longitude: "
                                "DEG' before the header",
                             has_[static_cast<int>(Col::kTime)] ? "no '# longitude:'"
                                                                : "no Time column");
        int eq = ctx_.opt().equinox;
        if (eq == PMRUN_EQUINOX_FILE && meta_equinox_ < 0 && !has_[static_cast<int>(Col::kEquinox)])
            return ctx_.fail(n, "the equinox of the RA/Dec columns is not stated, expected '# "
                                "equinox: J2000' or '# equinox: JNow' before the header, an "
                                "Equinox column, or the equinox option (pmfit --equinox)");
        if (!unused.empty())
            ctx_.warn(n, "column%s %s not used (the reader uses the %s, Temperature, Equinox)",
                      unused.find(',') != std::string::npos ? "s" : "", unused.c_str(),
                      kColumnsExpected);
        if (!has_[static_cast<int>(Col::kPier)])
            ctx_.warn(n, "no pier side column: every row taken as the normal side (a German "
                         "mount's flipped rows need PierSide to be read right)");
        return true;
    }

    bool angle(const std::string &tok, size_t i, bool hours, double &v, std::string &why)
    {
        std::string w;
        if (!parse_sexagesimal(tok, v, w)) {
            why = format("field %zu (%s) '%s': %s", i + 1, col_title(cols_[i]), excerpt(tok).c_str(),
                         w.c_str());
            return false;
        }
        if (hours && !(v >= 0 && v < 24)) {
            why = format("field %zu (%s) '%s': out of range, expected 0 <= hours < 24", i + 1,
                         col_title(cols_[i]), excerpt(tok).c_str());
            return false;
        }
        if (!hours && std::fabs(v) > 90) {
            why = format("field %zu (%s) '%s': beyond +-90 deg, expected a declination within "
                         "-90..+90 (the sky place; the side of pier is its own column)",
                         i + 1, col_title(cols_[i]), excerpt(tok).c_str());
            return false;
        }
        return true;
    }

    bool row(int n, const std::string &t)
    {
        if (rows_.size() >= static_cast<size_t>(PMRUN_MAX_RECORDS))
            return ctx_.fail(n, "more than %d records, expected at most %d", PMRUN_MAX_RECORDS,
                             PMRUN_MAX_RECORDS);
        std::vector<std::string> f;
        std::string why;
        if (!split_row(t, delim_, f, why)) return ctx_.bad_record(n, why);
        if (f.size() != cols_.size())
            return ctx_.bad_record(n, format("%zu fields, expected %zu as the header (line %d) names",
                                             f.size(), cols_.size(), header_line_));
        Row r;
        r.line = n;
        r.pier = PMRUN_PIER_EAST;
        r.pier_number = 0;
        r.has_time = false;
        r.lst_h = r.temp = nan();
        r.equinox = PMRUN_EQUINOX_FILE;
        for (size_t i = 0; i < f.size(); ++i) {
            const std::string &v = f[i];
            bool missing = v.empty() || v == "-";
            switch (cols_[i]) {
            case Col::kMountRa:
            case Col::kSolvedRa:
            case Col::kMountDec:
            case Col::kSolvedDec: {
                bool hours = cols_[i] == Col::kMountRa || cols_[i] == Col::kSolvedRa;
                double a;
                if (hours && deg_[i]) { // (the header says degrees)
                    std::string w;
                    if (v.find_first_of("hH") != std::string::npos)
                        return ctx_.bad_record(n, format("field %zu (%s) '%s': written in hours, "
                                                         "but the header names the column in "
                                                         "degrees",
                                                         i + 1, col_title(cols_[i]),
                                                         excerpt(v).c_str()));
                    if (!parse_sexagesimal(v, a, w))
                        return ctx_.bad_record(n, format("field %zu (%s) '%s': %s", i + 1,
                                                         col_title(cols_[i]), excerpt(v).c_str(),
                                                         w.c_str()));
                    if (!(a >= 0 && a < 360))
                        return ctx_.bad_record(n, format("field %zu (%s) '%s': out of range, "
                                                         "expected 0 <= degrees < 360 (the header "
                                                         "says degrees)",
                                                         i + 1, col_title(cols_[i]),
                                                         excerpt(v).c_str()));
                    a /= 15;
                } else if (!angle(v, i, hours, a, why)) {
                    return ctx_.bad_record(n, why);
                }
                (cols_[i] == Col::kMountRa    ? r.mra
                 : cols_[i] == Col::kMountDec ? r.mdec
                 : cols_[i] == Col::kSolvedRa ? r.sra
                                              : r.sdec) = a;
                break;
            }
            case Col::kPier: {
                std::string l = lower(v);
                r.pier_number = l == "0" ? '0' : l == "1" ? '1' : l == "-1" ? '-' : l == "+1" ? '+' : 0;
                if (r.pier_number) // (numbers: resolved for the whole file, sides_by_number)
                    r.pier = l == "-1" ? PMRUN_PIER_WEST : PMRUN_PIER_EAST;
                else if (l == "piereast" || l == "east" || l == "e" || l == "normal")
                    r.pier = PMRUN_PIER_EAST;
                else if (l == "pierwest" || l == "west" || l == "w" || l == "beyondpole" ||
                         l == "flipped")
                    r.pier = PMRUN_PIER_WEST;
                else if (l == "pierunknown" || l == "unknown" || l == "?" || missing)
                    return ctx_.bad_record(n, format("field %zu (pier side) '%s': unknown side, "
                                                     "expected pierEast or pierWest (a German "
                                                     "mount's side decides its encoder angles)",
                                                     i + 1, excerpt(v).c_str()));
                else
                    return ctx_.bad_record(n, format("field %zu (pier side) '%s': expected "
                                                     "pierEast, pierWest, East, West, E, W, or "
                                                     "ASCOM's numbers 0 (pierEast), 1 (pierWest)",
                                                     i + 1, excerpt(v).c_str()));
                break;
            }
            case Col::kTime: {
                if (missing) break;
                std::string w;
                if (!parse_iso_utc(v, r.t, w))
                    return ctx_.bad_record(n, format("field %zu (time) '%s': %s", i + 1,
                                                     excerpt(v).c_str(), w.c_str()));
                r.has_time = true;
                break;
            }
            case Col::kLst: {
                if (missing) break;
                std::string w;
                if (!parse_sexagesimal(v, r.lst_h, w))
                    return ctx_.bad_record(n, format("field %zu (LST) '%s': %s", i + 1,
                                                     excerpt(v).c_str(), w.c_str()));
                if (deg_[i] && v.find_first_of("hH") != std::string::npos)
                    return ctx_.bad_record(n, format("field %zu (LST) '%s': written in hours, but "
                                                     "the header names the column in degrees",
                                                     i + 1, excerpt(v).c_str()));
                if (deg_[i]) {
                    if (!(r.lst_h >= 0 && r.lst_h < 360))
                        return ctx_.bad_record(n, format("field %zu (LST) '%s': out of range, "
                                                         "expected 0 <= degrees < 360 (the header "
                                                         "says degrees)",
                                                         i + 1, excerpt(v).c_str()));
                    r.lst_h /= 15;
                }
                if (!(r.lst_h >= 0 && r.lst_h < 24))
                    return ctx_.bad_record(n, format("field %zu (LST) '%s': out of range, expected "
                                                     "0 <= hours < 24",
                                                     i + 1, excerpt(v).c_str()));
                break;
            }
            case Col::kTemp: {
                if (missing) break;
                std::string w;
                if (!parse_number(v, r.temp, w))
                    return ctx_.bad_record(n, format("field %zu (temperature) '%s': %s (C)", i + 1,
                                                     excerpt(v).c_str(), w.c_str()));
                break;
            }
            case Col::kEquinox: {
                int e = parse_equinox(v);
                if (e < 0)
                    return ctx_.bad_record(n, format("field %zu (equinox) '%s': expected J2000 or "
                                                     "JNow",
                                                     i + 1, excerpt(v).c_str()));
                r.equinox = e;
                break;
            }
            default:
                break;
            }
        }
        if (std::isnan(r.lst_h) && !r.has_time)
            return ctx_.bad_record(n, "no LST and no time in the row, expected one of them");
        rows_.push_back(r);
        return true;
    }

    // The equinox of a row: the option, the row's column, the metadata.
    int equinox_of(const Row &r) const
    {
        int eq = ctx_.opt().equinox;
        if (eq != PMRUN_EQUINOX_FILE) return eq;
        if (r.equinox != PMRUN_EQUINOX_FILE) return r.equinox;
        return meta_equinox_;
    }

    bool build()
    {
        pmrun *run = ctx_.run();
        pmrun_site &site = run->site;
        site.latitude_rad = std::isnan(lat_deg_) ? nan() : lat_deg_ * kDeg;
        // the date: the first row with a time
        const Row *first_t = nullptr;
        bool need_time = false;
        for (const Row &r : rows_) {
            if (!first_t && r.has_time) first_t = &r;
            need_time = need_time || equinox_of(r) == PMRUN_EQUINOX_J2000;
        }
        for (const Row &r : rows_)
            if (!r.has_time && (need_time && equinox_of(r) == PMRUN_EQUINOX_J2000))
                return ctx_.fail(r.line, "J2000 places need the UTC time of the row for the "
                                         "reduction, expected a time in the Time column");
        // a time without its zone is UTC (docs/formats.md); where the
        // times place the stars (no LST, or J2000 places) a local time would
        // turn every hour angle by the zone, 15 deg an hour, and the fit
        // would blame the plate solves: said
        for (const Row &r : rows_)
            if (r.has_time && !r.t.zoned &&
                (std::isnan(r.lst_h) || equinox_of(r) == PMRUN_EQUINOX_J2000)) {
                ctx_.warn(r.line, "the time has no zone (Z or +-hh:mm): read as UTC; if the log "
                                  "writes local time, every hour angle is off by the zone (15 "
                                  "deg an hour): give the zone, or convert the times to UTC");
                break;
            }
        UtcTime t0;
        if (first_t) {
            t0 = first_t->t;
            site.year = t0.year;
            site.month = t0.month;
            site.day = t0.day;
        } else {
            t0.year = 2000, t0.month = 1, t0.day = 1;   // only for the refraction constants
        }
        bool refr = ctx_.opt().refraction != 0 && meta_refraction_;
        if (refr && std::isnan(lat_deg_))
            return ctx_.fail(header_line_, "refraction needs the latitude, expected '# latitude: "
                                           "DEG' before the header (or '# refraction: no' when "
                                           "the mount's coordinates are corrected for refraction, "
                                           "or pmfit --no-refraction)");
        Weather w{};
        if (refr) {
            if (std::isnan(site.temp_c)) {   // the temperature column's mean
                double s = 0;
                int k = 0;
                for (const Row &r : rows_)
                    if (!std::isnan(r.temp)) s += r.temp, ++k;
                if (k) site.temp_c = s / k;
            }
            if (!refraction_weather(ctx_, header_line_, "the metadata", w)) return false;
        }
        Reduction red;
        std::string why;
        if (!red.setup(t0.year, t0.month, t0.day, lat_deg_ * kDeg, site.height_m,
                       refr ? &w : nullptr, why))
            return ctx_.fail(first_t ? first_t->line : header_line_, "%s", why.c_str());
        if (red.dubious && need_time)
            ctx_.warn(first_t->line, "date %d %d %d is outside ERFA's leap-second table: TAI-UTC "
                                     "is a guess (effect far below 0.1 arcsec)",
                      t0.year, t0.month, t0.day);
        if (!sides_by_number()) return false;
        run->obs.reserve(rows_.size());
        for (const Row &r : rows_) {
            pmrun_obs o = blank_obs(r.line);
            o.temp_c = r.temp;
            double th = r.has_time ? hours_since(t0, r.t) : nan();
            o.time_h = th;
            double lst;
            if (!std::isnan(r.lst_h)) {
                lst = r.lst_h * kHour;
            } else if (!lst_from_utc(t0.year, t0.month, t0.day, th, lon_deg_ * kDeg, lst, why)) {
                return ctx_.fail(r.line, "%s", why.c_str());
            }
            double mha, mdec, sha, sdec;
            if (equinox_of(r) == PMRUN_EQUINOX_J2000) {
                // the mount's place back to the apparent place of date (the
                // driver's J2000 conversion undone), no refraction; the
                // solved place to the observed one (refraction if used)
                if (!red.apparent(r.mra * kHour, r.mdec * kDeg, lst, th, mha, mdec, why) ||
                    !red.observed(r.sra * kHour, r.sdec * kDeg, lst, th, sha, sdec, why))
                    return ctx_.fail(r.line, "%s", why.c_str());
            } else {
                mha = eraAnpm(lst - r.mra * kHour);
                mdec = r.mdec * kDeg;
                sha = eraAnpm(lst - r.sra * kHour);
                sdec = r.sdec * kDeg;
                red.topocentric(sha, sdec);
                red.refract_place(sha, sdec);
            }
            o.pier = has_[static_cast<int>(Col::kPier)] ? r.pier : PMRUN_PIER_EAST;
            double eh, ed;
            sky_to_encoder_deg(mha / kDeg, mdec / kDeg, o.pier, eh, ed);
            o.enc_ha = eh * kDeg;
            o.enc_dec = ed * kDeg;
            o.enc_raw[0] = o.pier == PMRUN_PIER_WEST ? mha + kPi : mha;
            o.enc_raw[1] = o.pier == PMRUN_PIER_WEST ? kPi - mdec : mdec;
            o.app_ha = eraAnpm(sha);
            o.app_dec = sdec;
            run->obs.push_back(o);
        }
        run->format = PMRUN_FORMAT_CSV;
        run->mount = PMRUN_MOUNT_EQUATORIAL;
        return true;
    }

    // Sides written as numbers: ASCOM's SideOfPier numbers (0 pierEast, 1
    // pierWest, -1 pierUnknown, as Alpaca returns them) where a 0 is among
    // them; else pm's (+1 normal, -1 beyond the pole).  Read as pm's, an
    // ASCOM log's 1 (pierWest) was the normal side: d, e' and i with the
    // opposite sign and nothing to show it.  A file of 1 only is read as
    // pm's, with a note.
    bool sides_by_number()
    {
        const Row *zero = nullptr, *plus = nullptr, *one = nullptr, *minus = nullptr;
        for (const Row &r : rows_) {
            const Row **f = r.pier_number == '0' ? &zero : r.pier_number == '+' ? &plus
                            : r.pier_number == '1' ? &one : r.pier_number == '-' ? &minus : nullptr;
            if (f && !*f) *f = &r;
        }
        if (zero) {
            if (plus)
                return ctx_.fail(plus->line, "pier side '+1' with '0' at line %d: ASCOM's "
                                             "SideOfPier numbers (0 pierEast, 1 pierWest) and "
                                             "pm's (+1 normal, -1 beyond the pole) mixed; write "
                                             "East and West",
                                 zero->line);
            if (minus)
                return ctx_.fail(minus->line, "pier side '-1' with '0' at line %d: with ASCOM's "
                                              "SideOfPier numbers, -1 is pierUnknown (a German "
                                              "mount's side decides its encoder angles)",
                                 zero->line);
            for (Row &r : rows_)
                if (r.pier_number) r.pier = r.pier_number == '1' ? PMRUN_PIER_WEST : PMRUN_PIER_EAST;
            ctx_.warn(zero->line, "pier sides as numbers with a 0: read as ASCOM's SideOfPier "
                                  "(0 pierEast, the normal side; 1 pierWest, beyond the pole)");
        } else if (one || minus) {
            // (pm's numbers, which ASCOM's read otherwise: 1 is pierWest, -1
            // pierUnknown; a log of -1 alone was read beyond the pole silently)
            const Row *first = one && (!minus || one->line < minus->line) ? one : minus;
            ctx_.warn(first->line, "pier sides as the numbers 1 and -1 without a 0: read as pm's "
                                   "(+1 the normal side, -1 beyond the pole); in ASCOM's "
                                   "SideOfPier numbers 1 is pierWest and -1 pierUnknown: if the "
                                   "log writes those, write East/West");
        }
        return true;
    }

    Context &ctx_;
    std::vector<bool> deg_;         // per column: an RA or LST in degrees (its name says so)
    int header_line_ = 0;
    char delim_ = ',';
    char sep_ = 0;   // from Excel's 'sep=' line, 0: none
    std::vector<Col> cols_;
    bool has_[10] = {};
    std::vector<Row> rows_;
    int meta_equinox_ = -1;
    bool meta_refraction_ = true;
    double lat_deg_ = nan(), lon_deg_ = nan();
};

}  // namespace

std::unique_ptr<FormatParser> make_csv_parser(Context &ctx)
{
    return std::unique_ptr<FormatParser>(new CsvParser(ctx));
}

}  // namespace pmrun_detail
