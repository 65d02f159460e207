// runfile_columns.cpp - the four-column format ("tau delta T D", Pal et al.
// 2016) and the named-column format ("# tau delta T D pier temp ..." header
// plus "# key: value" metadata).  docs/formats.md, sections 1 and 2.
#include "runfile_internal.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pmrun_detail {
namespace {

enum class Col { kTau, kDelta, kT, kD, kPier, kTemp, kTime, kDir, kAux };

struct Column {
    Col kind;
    std::string name;   // as written in the header
    int aux = -1;       // index into aux[] for kAux
};

bool known_column(const std::string &lname, Col &kind)
{
    static const struct {
        const char *name;
        Col kind;
    } kNames[] = {{"tau", Col::kTau},   {"delta", Col::kDelta}, {"t", Col::kT},
                  {"d", Col::kD},       {"pier", Col::kPier},   {"temp", Col::kTemp},
                  {"time", Col::kTime}, {"dir", Col::kDir}};
    for (const auto &k : kNames)
        if (lname == k.name) {
            kind = k.kind;
            return true;
        }
    return false;
}

bool valid_aux_name(const std::string &s) { return pmhost::valid_column_name(s); }

// A time column of clock hours that passes midnight (23.9, then 0.1): the
// records after the step continued by 24 h where the times otherwise run
// forward as one night does (the drift and explain's time terms read the
// time as a number: a night from 20 h to 4 h written modulo 24 read a
// drift of +3"/h as -0.54"/h), with a note; likewise a run written newest
// first (the records before the leap forward).  Steps back of minutes (a
// clock set) are allowed; a note where the times step back by more, or
// leap half a day more than once.  Clock hours are 0..24 (a time of 23:59:53
// written to two decimals is 24.00).
void continue_past_midnight(Context &ctx, pmrun *run)
{
    std::vector<size_t> at;
    double lo = 1e300, hi = -1e300;
    for (size_t i = 0; i < run->obs.size(); i++)
        if (std::isfinite(run->obs[i].time_h)) {
            at.push_back(i);
            lo = std::min(lo, run->obs[i].time_h);
            hi = std::max(hi, run->obs[i].time_h);
        }
    if (at.size() < 2 || !(lo >= 0 && hi <= 24)) // not hours of a clock
        return;
    const double kClockSet = 0.5; // h: a step back this small is the clock, not the order
    size_t down = 0, up = 0, first_down = 0, first_up = 0, back = 0, fwd = 0, first_odd = 0;
    for (size_t k = 1; k < at.size(); k++) {
        double step = run->obs[at[k]].time_h - run->obs[at[k - 1]].time_h;
        if (step < -12) {
            if (!down++) first_down = k;
        } else if (step > 12) {
            if (!up++) first_up = k;
        } else if (step < -kClockSet) {
            if (!back++ && !fwd) first_odd = k;
        } else if (step > kClockSet) {
            if (!fwd++ && !back) first_odd = k;
        }
    }
    if (!down && !up)
        return;
    // one night in order: one leap, and the other steps all the other way
    const bool forward = down == 1 && !up && !back, reverse = up == 1 && !down && !fwd;
    const size_t k = forward ? first_down : first_up;
    const pmrun_obs &w = run->obs[at[k]], &b = run->obs[at[k - 1]];
    if (forward || reverse) {
        const size_t from = forward ? k : 0, to = forward ? at.size() : k;
        ctx.warn(w.line, "time: %.4g h after %.4g h (line %d): read as a clock passing midnight%s, "
                 "the %zu records %s it 24 h on; write the time continued (24.5 for 00:30) and "
                 "there is nothing to guess",
                 w.time_h, b.time_h, b.line, forward ? "" : " (the run written newest first)",
                 to - from, forward ? "from" : "before");
        for (size_t q = from; q < to; q++)
            run->obs[at[q]].time_h += 24;
        return;
    }
    const size_t odd = first_odd ? first_odd : (down ? first_down : first_up);
    const pmrun_obs &o = run->obs[at[odd]], &p = run->obs[at[odd - 1]];
    ctx.warn(o.line, "time: %.4g h after %.4g h (line %d): the times are not one night in order "
             "(%zu leaps of half a day, %zu steps of more than %g h against the rest): not read "
             "as a clock passing midnight, read as given (write a clock time that passes "
             "midnight continued, 24.5 for 00:30)",
             o.time_h, p.time_h, p.line, down + up, down ? back : fwd, kClockSet);
}

class ColumnParser : public FormatParser {
public:
    explicit ColumnParser(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        std::string t = trim(text);
        if (t.empty()) return true;
        if (t[0] == '#') {
            seen_hash_ = true;
            return comment(n, t.substr(1));
        }
        if (t[0] == '!' || t[0] == ':')
            return ctx_.fail(n,
                             "TPOINT %s line '%s' in a column file (%s): expected '#' comments "
                             "and records '%s'",
                             t[0] == '!' ? "comment" : "option", excerpt(t).c_str(),
                             seen_hash_ || first_data_ ? "mixed formats?"
                                        : "a TPOINT file? without --format it is detected, or "
                                          "--format tpoint",
                             column_list().c_str());
        if (first_data_ == 0) {
            first_data_ = n;
            if (cols_.empty()) {
                cols_ = {{Col::kTau, "tau"}, {Col::kDelta, "delta"}, {Col::kT, "T"}, {Col::kD, "D"}};
                has_[static_cast<int>(Col::kTau)] = has_[static_cast<int>(Col::kDelta)] = true;
            }
        }
        return record(n, tokens(strip_comment(t, '#')));
    }

    bool unreadable(int n, const std::string &why) override
    {
        if (first_data_ == 0) first_data_ = n;
        return ctx_.bad_record(n, why);
    }

    bool finish(int last_line) override
    {
        pmrun *run = ctx_.run();
        if (run->obs.empty()) {
            if (run->n_skipped > 0)
                return ctx_.fail(last_line, "no records left: all %d records were bad and skipped",
                                 run->n_skipped);
            return ctx_.fail(last_line,
                             "no records: the file ends at line %d without one, expected lines "
                             "of '%s' (degrees)",
                             last_line, column_list().c_str());
        }
        run->format = header_line_ ? PMRUN_FORMAT_NAMED : PMRUN_FORMAT_FOUR_COLUMN;
        run->mount = mount_;
        run->site.latitude_rad = latitude_deg_ * kDeg;
        for (const Column &c : cols_)
            if (c.kind == Col::kAux) run->aux_names.push_back(c.name);
        continue_past_midnight(ctx_, run);
        return true;
    }

private:
    std::string column_list() const
    {
        if (cols_.empty()) return "tau delta T D";
        std::string s;
        for (const Column &c : cols_) s += (s.empty() ? "" : " ") + c.name;
        return s;
    }

    bool comment(int n, const std::string &body)
    {
        // A header: starts with a known column name, names tau delta T D,
        // and every word is a column name (docs/formats.md, "Detection").
        std::vector<std::string> tok = tokens(body);
        int found = 0;
        bool names = true;
        for (const std::string &s : tok) {
            std::string l = lower(s);
            found |= (l == "tau" ? 1 : 0) | (l == "delta" ? 2 : 0) | (l == "t" ? 4 : 0) |
                     (l == "d" ? 8 : 0);
            names = names && valid_aux_name(s);
        }
        Col first;
        if (found == 15 && names && known_column(lower(tok[0]), first)) return header(n, tok);
        std::string b = trim(body);
        size_t colon = b.find(':');
        if (colon != std::string::npos && colon > 0) {
            std::string key = trim(b.substr(0, colon));
            if (valid_aux_name(key)) return metadata(n, lower(key), trim(b.substr(colon + 1)));
        }
        return true;   // a plain comment
    }

    bool header(int n, const std::vector<std::string> &tok)
    {
        if (header_line_)
            return ctx_.fail(n, "second column header (the first is at line %d), expected one header",
                             header_line_);
        if (first_data_)
            return ctx_.fail(n,
                             "column header after the first record (line %d): mixed formats? "
                             "expected the header before the records",
                             first_data_);
        header_line_ = n;
        int naux = 0;
        for (const std::string &name : tok) {
            Column c{Col::kAux, name};
            std::string l = lower(name);
            if (known_column(l, c.kind)) {
                if (has_[static_cast<int>(c.kind)])
                    return ctx_.fail(n, "column '%s' named twice, expected each column once",
                                     excerpt(name).c_str());
                has_[static_cast<int>(c.kind)] = true;
            } else {
                for (const Column &o : cols_)
                    if (o.kind == Col::kAux && lower(o.name) == l)
                        return ctx_.fail(n, "column '%s' named twice, expected each column once",
                                         excerpt(name).c_str());
                if (naux == PMRUN_MAX_AUX)
                    return ctx_.fail(n,
                                     "more than %d auxiliary columns ('%s'), expected at most %d "
                                     "besides tau delta T D pier temp time dir",
                                     PMRUN_MAX_AUX, excerpt(name).c_str(), PMRUN_MAX_AUX);
                c.aux = naux++;
            }
            cols_.push_back(c);
        }
        return true;
    }

    bool metadata(int n, const std::string &key, const std::string &value)
    {
        if (key == "latitude") {
            double v;
            std::string why;
            if (!parse_number(value, v, why))
                return ctx_.fail(n, "latitude '%s': %s (degrees)", excerpt(value).c_str(), why.c_str());
            if (std::fabs(v) > 90)
                return ctx_.fail(n, "latitude %s deg is beyond +-90, expected degrees within -90..+90",
                                 excerpt(value).c_str());
            if (latitude_line_)
                return ctx_.fail(n, "latitude given twice (first at line %d), expected it once",
                                 latitude_line_);
            latitude_deg_ = v;
            latitude_line_ = n;
            return true;
        }
        if (key == "mount") {
            std::string v = lower(value);
            int m;
            if (v == "altaz" || v == "alt-az" || v == "azel" || v == "alt-azimuth")
                m = PMRUN_MOUNT_ALTAZ;
            else if (v == "equatorial" || v == "equat" || v == "eq")
                m = PMRUN_MOUNT_EQUATORIAL;
            else
                return ctx_.fail(n, "mount '%s', expected 'altaz' or 'equatorial'",
                                 excerpt(value).c_str());
            if (first_data_)
                return ctx_.fail(n, "mount given after the first record (line %d), expected it before",
                                 first_data_);
            if (mount_line_ && m != mount_)
                return ctx_.fail(n, "mount '%s' conflicts with line %d, expected one mount type",
                                 excerpt(value).c_str(), mount_line_);
            mount_ = m;
            mount_line_ = n;
            return true;
        }
        ctx_.warn(n, "metadata '%s' accepted, not used", excerpt(key).c_str());
        return true;
    }

    // One field; false with `why` on error.
    bool field(const Column &c, const std::string &tok, pmrun_obs &o, std::string &why)
    {
        bool missing = tok == "-";
        switch (c.kind) {
        case Col::kPier: {
            std::string l = lower(tok);
            if (l == "e" || l == "east" || l == "+1" || l == "1")
                o.pier = PMRUN_PIER_EAST;
            else if (l == "w" || l == "west" || l == "-1")
                o.pier = PMRUN_PIER_WEST;
            else if (l == "0" || l == "?" || missing)
                o.pier = PMRUN_PIER_UNKNOWN;
            else {
                why = "expected E, W, +1, -1, 0 or '-'";
                return false;
            }
            return true;
        }
        case Col::kDir:
            if (tok == "+1" || tok == "1")
                o.dir = 1;
            else if (tok == "-1")
                o.dir = -1;
            else if (tok == "0" || tok == "+0" || tok == "-0" || missing)
                o.dir = 0;
            else {
                why = "expected +1, -1, 0 or '-'";
                return false;
            }
            return true;
        case Col::kTemp:
        case Col::kTime:
        case Col::kAux: {
            double v = nan();
            if (!missing && !parse_number(tok, v, why)) return false;
            if (c.kind == Col::kTemp) o.temp_c = v;
            if (c.kind == Col::kTime) o.time_h = v;
            if (c.kind == Col::kAux) o.aux[c.aux] = v;
            return true;
        }
        default:
            break;
        }
        double v;
        if (!parse_angle(tok, v, why)) {
            why += " (degrees)";
            return false;
        }
        bool altaz = mount_ == PMRUN_MOUNT_ALTAZ;
        switch (c.kind) {
        case Col::kTau:
            // Encoder angles are modular: any finite value, reduced exactly
            // (the file's own value kept in enc_raw).
            o.enc_raw[0] = v * kDeg;
            o.enc_ha = reduce_deg(v) * kDeg;
            return true;
        case Col::kT:
            o.app_ha = (altaz ? reduce_deg_positive(v) : reduce_deg(v)) * kDeg;
            return true;
        case Col::kDelta:
            o.enc_raw[1] = v * kDeg;
            o.enc_dec = reduce_deg(v) * kDeg;
            return true;
        case Col::kD:
            if (std::fabs(v) > 90) {
                why = altaz ? "elevation beyond +-90 deg, expected -90..+90"
                            : "apparent declination beyond +-90 deg, expected -90..+90";
                return false;
            }
            o.app_dec = v * kDeg;
            return true;
        default:
            return true;
        }
    }

    bool record(int n, const std::vector<std::string> &tok)
    {
        pmrun *run = ctx_.run();
        if (tok.size() != cols_.size())
            return ctx_.bad_record(n, format("%zu fields, expected %zu: %s", tok.size(), cols_.size(),
                                             column_list().c_str()));
        pmrun_obs o = blank_obs(n);
        for (size_t i = 0; i < tok.size(); ++i) {
            std::string why;
            if (!field(cols_[i], tok[i], o, why))
                return ctx_.bad_record(n, format("field %zu (%s) '%s': %s", i + 1,
                                                 cols_[i].name.c_str(), excerpt(tok[i]).c_str(),
                                                 why.c_str()));
        }
        if (!has_[static_cast<int>(Col::kPier)] && mount_ == PMRUN_MOUNT_EQUATORIAL)
            o.pier = std::fabs(o.enc_dec) > kPi / 2 ? PMRUN_PIER_WEST : PMRUN_PIER_EAST;
        if (run->obs.size() >= static_cast<size_t>(PMRUN_MAX_RECORDS))
            return ctx_.fail(n, "more than %d records, expected at most %d", PMRUN_MAX_RECORDS,
                             PMRUN_MAX_RECORDS);
        run->obs.push_back(o);
        return true;
    }

    Context &ctx_;
    std::vector<Column> cols_;
    bool has_[9] = {};
    int header_line_ = 0;
    int first_data_ = 0;
    bool seen_hash_ = false; // a '#' line read (a TPOINT line after one or a record: mixed formats)
    int mount_ = PMRUN_MOUNT_EQUATORIAL;
    int mount_line_ = 0;
    double latitude_deg_ = nan();
    int latitude_line_ = 0;
};

}  // namespace

std::unique_ptr<FormatParser> make_column_parser(Context &ctx)
{
    return std::unique_ptr<FormatParser>(new ColumnParser(ctx));
}

}  // namespace pmrun_detail
