// runfile_mmt.cpp - the MMT mount computer's pointing log (the raw file
// pytelpoint's read_raw_datfile reads): one block of 'KEY: values' lines
// per star, starting with CAT:.  RAA: is the raw (encoder) elevation and
// azimuth, TAA: the observed (target) elevation and azimuth, both degrees,
// azimuth from north through east; LST: the sidereal time.  An alt-az
// mount.  Blank lines and '#' comment lines (not in the MMT's own files)
// are skipped.  docs/formats.md, section 7.
#include "runfile_internal.hpp"

#include <cmath>
#include <cstring>

namespace pmrun_detail {
namespace {

// The keys of a block the reader knows but does not use.
const char *const kUnused[] = {"AA",   "ABS_AA", "TAPE_ALT_EW", "TAPE_ALT_EW_RAW",
                               "RRD",  "ARD",    "CRD",         "SVEL",
                               "SERR"};

constexpr double kSiderealPerSolar = 1.00273790935;

struct Block {
    int line = 0;                // of CAT:
    int raa = 0, taa = 0, lst = 0;   // lines (0: not seen)
    double raw_el = 0, raw_az = 0, obs_el = 0, obs_az = 0, lst_h = 0;
    bool bad = false;            // skipped (skip_bad): ignore the rest
};

class MmtParser : public FormatParser {
public:
    explicit MmtParser(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        std::string t = trim(text);
        if (t.empty() || t[0] == '#') return true;   // '#' comments: ours, not the MMT's
        size_t colon = t.find(':');
        std::string key = colon == std::string::npos ? std::string() : t.substr(0, colon);
        bool key_ok = !key.empty();
        for (char c : key)
            key_ok = key_ok && ((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
        if (!key_ok && open_ && cur_.bad) return true;
        if (!key_ok)
            return bad(n, format("line '%s' is not 'KEY: values', expected CAT:, RAA:, TAA:, "
                                 "LST: ... lines",
                                 excerpt(t).c_str()),
                       true);
        std::string rest = t.substr(colon + 1);
        if (key == "CAT") {
            if (!close_block()) return false;
            if (ctx_.run()->obs.size() + 1 > static_cast<size_t>(PMRUN_MAX_RECORDS))
                return ctx_.fail(n, "more than %d records, expected at most %d", PMRUN_MAX_RECORDS,
                                 PMRUN_MAX_RECORDS);
            cur_ = Block();
            cur_.line = n;
            open_ = true;
            return true;
        }
        if (!open_)
            return ctx_.fail(n, "'%s:' line before the first CAT: line, expected each star's block "
                                "to start with CAT:",
                             excerpt(key).c_str());
        if (cur_.bad) return true;
        if (key == "RAA" || key == "TAA") {
            int &seen = key == "RAA" ? cur_.raa : cur_.taa;
            if (seen)
                return bad(n, format("second %s: line in the star's block (the first at line %d), "
                                     "expected one per star",
                                     key.c_str(), seen));
            std::vector<std::string> tok = tokens(rest);
            if (tok.size() != 2)
                return bad(n, format("%s: has %zu values, expected 2: elevation and azimuth (degrees)",
                                     key.c_str(), tok.size()));
            double v[2];
            for (int k = 0; k < 2; ++k) {
                std::string why;
                if (!parse_angle(tok[k], v[k], why))
                    return bad(n, format("%s: %s '%s': %s (degrees)", key.c_str(),
                                         k == 0 ? "elevation" : "azimuth",
                                         excerpt(tok[k]).c_str(), why.c_str()));
            }
            if (key == "TAA" && std::fabs(v[0]) > 90)
                return bad(n, format("TAA: elevation '%s' beyond +-90 deg, expected the observed "
                                     "elevation within -90..+90",
                                     excerpt(tok[0]).c_str()));
            seen = n;
            (key == "RAA" ? cur_.raw_el : cur_.obs_el) = v[0];
            (key == "RAA" ? cur_.raw_az : cur_.obs_az) = v[1];
            return true;
        }
        if (key == "LST") {
            double h;
            std::string why;
            std::string v = trim(rest);
            if (!parse_sexagesimal(v, h, why))
                return bad(n, format("LST: '%s': %s", excerpt(v).c_str(), why.c_str()));
            if (!(h >= 0 && h < 24))
                return bad(n, format("LST: '%s' out of range, expected 0 <= hours < 24",
                                     excerpt(v).c_str()));
            cur_.lst = n;
            cur_.lst_h = h;
            return true;
        }
        for (const char *k : kUnused)
            if (key == k) return true;
        if (!unknown_warned_) {
            unknown_warned_ = true;
            ctx_.warn(n, "key '%s:' not known, ignored (noted once); the reader uses CAT:, RAA:, "
                         "TAA: and LST:",
                      excerpt(key).c_str());
        }
        return true;
    }

    bool unreadable(int n, const std::string &why) override
    {
        if (!open_) return ctx_.fail(n, "%s (before the first CAT: line)", why.c_str());
        if (cur_.bad) return true;
        return bad(n, why);
    }

    bool finish(int last_line) override
    {
        if (!close_block()) return false;
        pmrun *run = ctx_.run();
        if (run->obs.empty()) {
            if (run->n_skipped > 0)
                return ctx_.fail(last_line, "no records left: all %d records were bad and skipped",
                                 run->n_skipped);
            return ctx_.fail(last_line, "no star: the file ends at line %d without a CAT: block "
                                        "with RAA: and TAA:",
                             last_line);
        }
        run->format = PMRUN_FORMAT_MMT;
        run->mount = PMRUN_MOUNT_ALTAZ;
        // time: the sidereal time elapsed since the first star, unwrapped
        // from star to star, in solar hours (the log has no date)
        bool all_lst = true;
        for (double l : lst_) all_lst = all_lst && !std::isnan(l);
        if (all_lst) {
            double acc = 0;
            for (size_t i = 0; i < lst_.size(); ++i) {
                if (i > 0) {
                    double d = lst_[i] - lst_[i - 1];
                    d -= 24.0 * std::floor((d + 12.0) / 24.0);
                    acc += d;
                }
                run->obs[i].time_h = acc / kSiderealPerSolar;
            }
        } else {
            ctx_.warn(0, "not every star has an LST: line: no times (time_h NaN)");
        }
        return true;
    }

private:
    // A bad line of the current block: with skip_bad the whole star is
    // skipped; `anywhere` for lines that are bad whatever the block.
    bool bad(int n, const std::string &why, bool anywhere = false)
    {
        if (!open_ && anywhere) return ctx_.fail(n, "%s", why.c_str());
        if (!ctx_.bad_record(n, why + format(" (the star of line %d)", cur_.line))) return false;
        cur_.bad = true;
        return true;
    }

    bool close_block()
    {
        if (!open_ || cur_.bad) return true;
        open_ = false;
        if (!cur_.raa || !cur_.taa) {
            cur_.bad = true;
            return ctx_.bad_record(cur_.line,
                                   format("the star's block (CAT: at line %d) has no %s: line, "
                                          "expected RAA: (raw) and TAA: (observed) elevation and "
                                          "azimuth",
                                          cur_.line, cur_.raa ? "TAA" : "RAA"));
        }
        pmrun_obs o = blank_obs(cur_.line);
        // azimuth from north through east (ERFA's); the raw axes modular
        o.enc_ha = reduce_deg(cur_.raw_az) * kDeg;
        o.enc_dec = reduce_deg(cur_.raw_el) * kDeg;
        o.enc_raw[0] = cur_.raw_az * kDeg;
        o.enc_raw[1] = cur_.raw_el * kDeg;
        o.app_ha = reduce_deg_positive(cur_.obs_az) * kDeg;
        o.app_dec = cur_.obs_el * kDeg;
        ctx_.run()->obs.push_back(o);
        lst_.push_back(cur_.lst ? cur_.lst_h : nan());
        return true;
    }

    Context &ctx_;
    Block cur_;
    bool open_ = false;
    bool unknown_warned_ = false;
    std::vector<double> lst_;
};

}  // namespace

std::unique_ptr<FormatParser> make_mmt_parser(Context &ctx)
{
    return std::unique_ptr<FormatParser>(new MmtParser(ctx));
}

}  // namespace pmrun_detail
