// runfile_rts2.cpp - RTS2 gpoint input files (rts2's python gpoint,
// GPoint.process_files): a '#' header line, optional '#observatory LON LAT
// ALT' (German equatorial, also '#gem') or '#altaz LON LAT ALT' lines, and
// one line per observation:
//
//   Observation  MJD  LST-MNT  RA-MNT  DEC-MNT  AXRA  AXDEC  RA-TRUE  DEC-TRUE
//   (alt-az:     MJD  LST-MNT  AZ-MNT  ALT-MNT  AXAZ  AXALT  AZ-TRUE  ALT-TRUE)
//
// in degrees (LST too); the mount's Dec beyond +-90 when the telescope is
// beyond the pole; RTS2 (libnova) azimuths from south through west.
// docs/formats.md, section 4.
#include "runfile_internal.hpp"

#include <erfa.h>

#include <cmath>
#include <cstring>

namespace pmrun_detail {
namespace {

const char *const kEqFields[9] = {"observation", "MJD",     "LST-MNT", "RA-MNT",  "DEC-MNT",
                                  "AXRA",        "AXDEC",   "RA-TRUE", "DEC-TRUE"};
const char *const kAzFields[9] = {"observation", "MJD",    "LST-MNT", "AZ-MNT",  "ALT-MNT",
                                  "AXAZ",        "AXALT",  "AZ-TRUE", "ALT-TRUE"};
const char *kEqExpected =
    "observation id, MJD, LST, mount RA, Dec, axis counts RA, Dec, true RA, Dec (degrees)";
const char *kAzExpected =
    "observation id, MJD, LST, mount az, alt, axis counts az, alt, true az, alt (degrees, "
    "azimuth from south through west)";

struct Record {
    int line;
    double mjd, lst, m1, m2, ax1, ax2, t1, t2;   // degrees as written
};

class Rts2Parser : public FormatParser {
public:
    explicit Rts2Parser(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        std::string t = trim(text);
        if (t.empty()) return true;
        if (t[0] == '#') return comment(n, t);
        if (recs_.size() >= static_cast<size_t>(PMRUN_MAX_RECORDS))
            return ctx_.fail(n, "more than %d records, expected at most %d", PMRUN_MAX_RECORDS,
                             PMRUN_MAX_RECORDS);
        if (!first_data_) first_data_ = n;
        std::vector<std::string> tok = tokens(strip_comment(t, '#'));
        const char *expected = altaz_ ? kAzExpected : kEqExpected;
        if (tok.size() < 9)
            return ctx_.bad_record(n, format("%zu fields, expected 9: %s", tok.size(), expected));
        if (tok.size() > 9 && !extra_warned_) {
            extra_warned_ = true;
            ctx_.warn(n, "%zu fields beyond the 9 of gpoint, ignored as gpoint does (noted once)",
                      tok.size() - 9);
        }
        const char *const *names = altaz_ ? kAzFields : kEqFields;
        double v[9];
        for (size_t i = 1; i < 9; ++i) {
            std::string why;
            // (fields 2, 6 and 7 are the MJD and axis counts, the rest angles)
            const bool angle = i != 1 && i != 5 && i != 6;
            if (!(angle ? parse_angle(tok[i], v[i], why) : parse_number(tok[i], v[i], why)))
                return ctx_.bad_record(n, format("field %zu (%s) '%s': %s (%s)", i + 1, names[i],
                                                 excerpt(tok[i]).c_str(), why.c_str(),
                                                 i == 1 ? "a modified Julian date"
                                                 : angle ? "degrees"
                                                         : "an axis count"));
        }
        if (v[1] > 2415000.5 && v[1] < 2500000.5) {
            // a Julian date where gpoint writes the modified one (the ranges
            // are disjoint: JD 2415000.5 is MJD 15000)
            v[1] -= 2400000.5;
            if (!jd_warned_) {
                jd_warned_ = true;
                ctx_.warn(n, "field 2 (MJD) '%s' is a Julian date: read as MJD = JD - 2400000.5 "
                             "(noted once)",
                          excerpt(tok[1]).c_str());
            }
        }
        if (!(v[1] > 15000 && v[1] < 100000))
            return ctx_.bad_record(n, format("field 2 (MJD) '%s': out of range, expected a modified "
                                             "Julian date between 15000 and 100000 (years "
                                             "1900..2132) or a Julian date between 2415000.5 "
                                             "and 2500000.5",
                                             excerpt(tok[1]).c_str()));
        if (std::fabs(v[8]) > 90)
            return ctx_.bad_record(n, format("field 9 (%s) '%s': beyond +-90 deg, expected the "
                                             "star's %s within -90..+90",
                                             names[8], excerpt(tok[8]).c_str(),
                                             altaz_ ? "elevation" : "declination"));
        recs_.push_back(Record{n, v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]});
        return true;
    }

    bool unreadable(int n, const std::string &why) override
    {
        if (!first_data_) first_data_ = n;
        return ctx_.bad_record(n, why);
    }

    bool finish(int last_line) override
    {
        pmrun *run = ctx_.run();
        if (recs_.empty()) {
            if (run->n_skipped > 0)
                return ctx_.fail(last_line, "no records left: all %d records were bad and skipped",
                                 run->n_skipped);
            return ctx_.fail(last_line, "no records: the file ends at line %d without one, "
                                        "expected lines of %s",
                             last_line, altaz_ ? kAzExpected : kEqExpected);
        }
        run->format = PMRUN_FORMAT_RTS2;
        run->mount = altaz_ ? PMRUN_MOUNT_ALTAZ : PMRUN_MOUNT_EQUATORIAL;
        run->aux_names = {altaz_ ? "axaz" : "axra", altaz_ ? "axalt" : "axdec"};
        // the date of the first record: time_h counts from its 0h UTC
        double day0 = std::floor(recs_[0].mjd);
        int iy, im, id;
        double fd;
        if (eraJd2cal(2400000.5, day0, &iy, &im, &id, &fd) != 0)
            return ctx_.fail(recs_[0].line, "MJD %.6f rejected by ERFA", recs_[0].mjd);
        run->site.year = iy;
        run->site.month = im;
        run->site.day = id;
        int eq = ctx_.opt().equinox;
        bool j2000 = eq == PMRUN_EQUINOX_J2000;
        if (j2000 && altaz_)
            return ctx_.fail(directive_line_, "the J2000 equinox was asked for an alt-az gpoint "
                                              "file: its true places are azimuth and altitude, "
                                              "expected no equinox (or an equatorial file)");
        Reduction red;
        if (j2000) {
            if (std::isnan(run->site.latitude_rad))
                return ctx_.fail(recs_[0].line, "J2000 true places need the latitude for the "
                                                "reduction (refraction), expected an '#observatory "
                                                "LON LAT ALT' line before the records");
            Weather w{};
            bool refr = ctx_.opt().refraction != 0;
            if (refr && !refraction_weather(ctx_, recs_[0].line, "the gpoint file", w))
                return false;
            std::string why;
            if (!red.setup(iy, im, id, run->site.latitude_rad, run->site.height_m,
                           refr ? &w : nullptr, why))
                return ctx_.fail(recs_[0].line, "%s", why.c_str());
        }
        for (const Record &r : recs_) {
            pmrun_obs o = blank_obs(r.line);
            o.time_h = (r.mjd - day0) * 24.0;
            o.aux[0] = r.ax1;
            o.aux[1] = r.ax2;
            if (altaz_) {
                // libnova azimuth from south through west: A_NE = A_SW + 180
                o.enc_raw[0] = (r.m1 + 180.0) * kDeg;
                o.enc_raw[1] = r.m2 * kDeg;
                o.enc_ha = reduce_deg(reduce_deg(r.m1) + 180.0) * kDeg;
                o.enc_dec = reduce_deg(r.m2) * kDeg;
                o.app_ha = reduce_deg_positive(reduce_deg(r.t1) + 180.0) * kDeg;
                o.app_dec = r.t2 * kDeg;
            } else {
                o.enc_raw[0] = (r.lst - r.m1) * kDeg;
                o.enc_raw[1] = r.m2 * kDeg;
                o.enc_ha = reduce_deg(reduce_deg(r.lst) - reduce_deg(r.m1)) * kDeg;
                o.enc_dec = reduce_deg(r.m2) * kDeg;
                o.pier = std::fabs(o.enc_dec) > kPi / 2 ? PMRUN_PIER_WEST : PMRUN_PIER_EAST;
                if (j2000) {
                    std::string why;
                    if (!red.observed(reduce_deg_positive(r.t1) * kDeg, r.t2 * kDeg,
                                      reduce_deg_positive(r.lst) * kDeg, o.time_h, o.app_ha,
                                      o.app_dec, why))
                        return ctx_.fail(r.line, "%s", why.c_str());
                } else {
                    o.app_ha = reduce_deg(reduce_deg(r.lst) - reduce_deg(r.t1)) * kDeg;
                    o.app_dec = r.t2 * kDeg;
                }
            }
            run->obs.push_back(o);
        }
        return true;
    }

private:
    bool comment(int n, const std::string &t)
    {
        std::vector<std::string> tok = tokens(t.substr(1));
        if (tok.empty()) return true;
        std::string f = lower(tok[0]);
        bool eq = f == "observatory" || f == "gem";
        bool az = f == "altaz";
        if (f == "altaz-manual")
            return ctx_.fail(n, "'#altaz-manual' files (offsets typed by hand) are not supported, "
                                "expected '#observatory' or '#altaz' files");
        if (!eq && !az) return true;   // a comment (the column header)
        if (tok.size() != 4) {
            ctx_.warn(n, "'#%s' line with %zu values taken as a comment (gpoint's is '#%s "
                         "LONGITUDE LATITUDE ALTITUDE')",
                      tok[0].c_str(), tok.size() - 1, tok[0].c_str());
            return true;
        }
        double v[3];
        for (int i = 0; i < 3; ++i) {
            std::string why;
            if (!parse_number(tok[static_cast<size_t>(i) + 1], v[i], why))
                return ctx_.fail(n, "'#%s' %s '%s': %s", tok[0].c_str(),
                                 i == 0 ? "longitude" : i == 1 ? "latitude" : "altitude",
                                 excerpt(tok[static_cast<size_t>(i) + 1]).c_str(), why.c_str());
        }
        if (std::fabs(v[1]) > 90)
            return ctx_.fail(n, "'#%s' latitude %s is beyond +-90 deg, expected -90..+90",
                             tok[0].c_str(), excerpt(tok[2]).c_str());
        if (first_data_)
            return ctx_.fail(n, "'#%s' line after the first record (line %d), expected the site "
                                "before the records",
                             tok[0].c_str(), first_data_);
        if (directive_line_ && az != altaz_)
            return ctx_.fail(n, "'#%s' conflicts with line %d, expected one mount type",
                             tok[0].c_str(), directive_line_);
        altaz_ = az;
        directive_line_ = n;
        pmrun_site &site = ctx_.run()->site;
        site.latitude_rad = v[1] * kDeg;
        site.height_m = v[2];
        return true;
    }

    Context &ctx_;
    std::vector<Record> recs_;
    bool altaz_ = false;
    int directive_line_ = 0;
    int first_data_ = 0;
    bool extra_warned_ = false;
    bool jd_warned_ = false;
};

}  // namespace

std::unique_ptr<FormatParser> make_rts2_parser(Context &ctx)
{
    return std::unique_ptr<FormatParser>(new Rts2Parser(ctx));
}

}  // namespace pmrun_detail
