// runfile.cpp - the C API of the pointing-run reader (runfile.h): options,
// accessors, the bounded line reader, format detection and the shared
// helpers (messages, tokens, strict numbers).
#include "runfile_internal.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <new>
#include <unordered_map>

namespace pmrun_detail {

double nan() { return std::numeric_limits<double>::quiet_NaN(); }

double reduce_deg(double v)
{
    double r = std::fmod(v, 360.0);   // exact, |r| < 360, sign of v
    if (r > 180.0)
        r -= 360.0;                    // exact: r in (180, 360)
    else if (r <= -180.0)
        r += 360.0;                    // exact: r in (-360, -180]
    return r;
}

double reduce_deg_positive(double v)
{
    double r = std::fmod(v, 360.0);
    if (r < 0) r += 360.0;             // rounds for r in (-180, 0)
    return r < 360.0 ? r : 0.0;        // -1e-20 + 360 rounds to 360
}

// ---------------------------------------------------------------- messages

std::string vformat(const char *fmt, va_list ap)
{
    char small[512];
    va_list ap2;
    va_copy(ap2, ap);
    int n = std::vsnprintf(small, sizeof small, fmt, ap2);
    va_end(ap2);
    if (n < 0) return std::string(fmt);
    if (static_cast<size_t>(n) < sizeof small) return std::string(small, static_cast<size_t>(n));
    std::string big(static_cast<size_t>(n) + 1, '\0');
    std::vsnprintf(&big[0], big.size(), fmt, ap);
    big.resize(static_cast<size_t>(n));
    return big;
}

std::string format(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::string s = vformat(fmt, ap);
    va_end(ap);
    return s;
}

Context::Context(const char *path, const pmrun_options &opt, pmrun *run)
    : path_(path), opt_(opt), run_(run)
{
}

std::string Context::where(int line) const
{
    if (line > 0) return path_ + ":" + std::to_string(line) + ": ";
    return path_ + ": ";
}

// The notes made before an error, appended to it: the run and its notes
// are not returned on error, and a note can be the cause (a year of 9999
// noted, then refused for "mixed encoder conventions" without it).
static std::string with_notes(const std::vector<std::string> &notes)
{
    if (notes.empty())
        return "";
    std::string s = " (noted before it: " + notes[0];
    if (notes.size() > 1)
        s += "; and " + std::to_string(notes.size() - 1) + " more";
    return s + ")";
}

bool Context::fail(int line, const char *fmt, ...)
{
    if (!failed()) {
        va_list ap;
        va_start(ap, fmt);
        error_ = where(line) + (reading_as_.empty() ? "" : "read as " + reading_as_ + ": ") +
                 vformat(fmt, ap) + with_notes(run_->warnings);
        va_end(ap);
        status_ = PMRUN_ERR_FORMAT;
    }
    return false;
}

bool Context::fail_with(int status, int line, const char *fmt, ...)
{
    if (!failed()) {
        va_list ap;
        va_start(ap, fmt);
        error_ = where(line) + vformat(fmt, ap);
        va_end(ap);
        status_ = status;
    }
    return false;
}

void Context::add_warning(const std::string &msg)
{
    if (run_->warnings.size() < PMRUN_MAX_MESSAGES)
        run_->warnings.push_back(msg);
    else
        ++warnings_dropped_;
}

void Context::warn(int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::string msg = where(line) + vformat(fmt, ap);
    va_end(ap);
    add_warning(msg);
}

bool Context::bad_record(int line, const std::string &why)
{
    if (!opt_.skip_bad) return fail(line, "%s", why.c_str());
    // (skipped records: "path:LINE: skipped: why", without the format)
    std::string msg = where(line) + "skipped: " + why;
    if (run_->skipped.size() < PMRUN_MAX_MESSAGES) run_->skipped.push_back(msg);
    ++run_->n_skipped;
    add_warning(msg);
    return true;
}

void Context::finish_messages()
{
    if (warnings_dropped_ > 0)
        run_->warnings.push_back(where(0) + format("%ld more warnings not kept (at most %d are)",
                                                   warnings_dropped_, PMRUN_MAX_MESSAGES));
}

// ------------------------------------------------------------------ text

static bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

std::vector<std::string> tokens(const std::string &s)
{
    std::vector<std::string> out;
    size_t i = 0, n = s.size();
    while (i < n) {
        while (i < n && is_space(s[i])) ++i;
        size_t b = i;
        while (i < n && !is_space(s[i])) ++i;
        if (i > b) out.emplace_back(s, b, i - b);
    }
    return out;
}

std::string trim(const std::string &s)
{
    size_t b = 0, e = s.size();
    while (b < e && is_space(s[b])) ++b;
    while (e > b && is_space(s[e - 1])) --e;
    return s.substr(b, e - b);
}

std::string lower(const std::string &s)
{
    std::string r(s);
    for (char &c : r)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return r;
}

bool excel_sep_line(const std::string &t)
{
    return t.size() >= 4 && lower(t.substr(0, 4)) == "sep=";
}

std::string strip_comment(const std::string &s, char c)
{
    for (size_t i = 0; i < s.size(); ++i)
        if (s[i] == c && (i == 0 || is_space(s[i - 1]))) return trim(s.substr(0, i));
    return s;
}

std::string excerpt(const std::string &s, size_t max)
{
    std::string r;
    for (size_t i = 0; i < s.size() && r.size() < max; ++i) {
        unsigned char c = static_cast<unsigned char>(s[i]);
        if (c >= 0x20 && c < 0x7f)
            r += static_cast<char>(c);
        else
            r += format("\\x%02x", c);
    }
    if (r.size() >= max && s.size() > max) r += "...";
    return r;
}

// --------------------------------------------------------------- numbers

static bool digits(const std::string &s, size_t &i)
{
    size_t b = i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    return i > b;
}

static bool number_syntax(const std::string &s)
{
    size_t i = 0;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    bool intpart = digits(s, i);
    bool frac = false;
    if (i < s.size() && s[i] == '.') {
        ++i;
        frac = digits(s, i);
    }
    if (!intpart && !frac) return false;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        if (!digits(s, i)) return false;
    }
    return i == s.size();
}

bool is_number(const std::string &tok)
{
    double v;
    std::string why;
    return parse_number(tok, v, why);
}

bool decimal_comma(const std::string &s, std::string &why)
{
    const size_t k = !s.empty() && (s[0] == '+' || s[0] == '-') ? 1 : 0, comma = s.find(',');
    bool digits = comma != std::string::npos && comma > k && comma + 1 < s.size();
    for (size_t q = k; digits && q < s.size(); q++)
        digits = q == comma || (s[q] >= '0' && s[q] <= '9');
    if (digits)
        why = "a decimal comma? expected a decimal point ('" + s.substr(0, comma) + "." +
              s.substr(comma + 1) + "'); write the numbers with '.'";
    return digits;
}

bool parse_number(const std::string &tok, double &v, std::string &why)
{
    std::string l = lower(tok);
    std::string body = (!l.empty() && (l[0] == '+' || l[0] == '-')) ? l.substr(1) : l;
    if (body == "nan" || body.compare(0, 4, "nan(") == 0 || body == "inf" || body == "infinity") {
        why = "NaN/Inf is not accepted, expected a finite number";
        return false;
    }
    if (!number_syntax(tok)) {
        if (!decimal_comma(tok, why))
            why = "not a number, expected a decimal number";
        return false;
    }
    const char *b = tok.data();
    const char *e = b + tok.size();
    if (*b == '+') ++b;
    double x = 0;
    std::from_chars_result r = std::from_chars(b, e, x);
    if (r.ec == std::errc::result_out_of_range || !std::isfinite(x)) {
        why = "number out of range, expected a finite double";
        return false;
    }
    if (r.ec != std::errc() || r.ptr != e) {
        why = "not a number, expected a decimal number";
        return false;
    }
    v = x;
    return true;
}

bool angle_in_range(double v, std::string &why)
{
    if (std::fabs(v) <= kMaxAngle) return true;
    why = format("%.10g is beyond +-2^31 (%.0f): a corrupt value? expected an angle (in any "
                 "turn, within +-2^31)",
                 v, kMaxAngle);
    return false;
}

bool parse_angle(const std::string &tok, double &v, std::string &why)
{
    return parse_number(tok, v, why) && angle_in_range(v, why);
}

double standard_pressure_hpa(double height_m) { return 1013.25 * std::exp(-height_m / 8434.5); }

std::unique_ptr<FormatParser> make_parser(Context &ctx, int format)
{
    switch (format) {
    case PMRUN_FORMAT_FOUR_COLUMN:
    case PMRUN_FORMAT_NAMED: return make_column_parser(ctx);
    case PMRUN_FORMAT_TPOINT: return make_tpoint_parser(ctx);
    case PMRUN_FORMAT_RTS2: return make_rts2_parser(ctx);
    case PMRUN_FORMAT_MW4: return make_mw4_parser(ctx);
    case PMRUN_FORMAT_CSV: return make_csv_parser(ctx);
    case PMRUN_FORMAT_MMT: return make_mmt_parser(ctx);
    default: return nullptr;
    }
}

bool equinox_applies(Context &ctx, int format)
{
    if (ctx.opt().equinox == PMRUN_EQUINOX_FILE || format == PMRUN_FORMAT_CSV ||
        format == PMRUN_FORMAT_RTS2 || format == PMRUN_FORMAT_MW4)
        return true;
    // (PMRUN_ERR_FORMAT, as the MW4 reader's refusal of J2000: _ARG is for
    // NULL arguments, and the fuzzer's status invariant caught it)
    return ctx.fail(0,
                    "the equinox option (pmfit --equinox) applies to CSV logs, RTS2 gpoint and "
                    "MountWizzard4 files, and this is %s, whose places are what its format "
                    "defines (a TPOINT file's: mean places of its catalogue; a column file's: "
                    "apparent): refused rather than ignored",
                    format_description(format));
}

const char *format_description(int format)
{
    switch (format) {
    case PMRUN_FORMAT_FOUR_COLUMN: return "a four-column or named-column file";
    case PMRUN_FORMAT_NAMED: return "a named-column file";
    case PMRUN_FORMAT_TPOINT: return "a TPOINT data file";
    case PMRUN_FORMAT_RTS2: return "an RTS2 gpoint input file";
    case PMRUN_FORMAT_MW4: return "a MountWizzard4 model file (JSON)";
    case PMRUN_FORMAT_CSV: return "a N.I.N.A./ASCOM-style CSV log";
    case PMRUN_FORMAT_MMT: return "an MMT pointing log";
    default: return "an unknown format";
    }
}

// ----------------------------------------------------------- line reader

namespace {

// Reads lines of at most PMRUN_MAX_LINE bytes through a fixed buffer.  A
// longer line is reported as soon as the limit is passed, without reading
// its rest: the next call skips the rest (bounded time and memory when the
// caller stops at the error, e.g. a 1 GB or endless line).
class LineReader {
public:
    enum Result { kLine, kEof, kTooLong, kIoError };

    explicit LineReader(std::FILE *f) : f_(f), buf_(1 << 16) {}

    Result next(std::string &line, bool &nul)
    {
        line.clear();
        nul = false;
        if (!skip_rest()) return kIoError;
        bool any = false;
        for (;;) {
            if (pos_ == len_ && !fill()) {
                if (err_) return kIoError;
                if (!any) return kEof;
                unterminated_ = true;
                break;
            }
            any = true;
            const char *start = buf_.data() + pos_;
            size_t avail = len_ - pos_;
            const char *nl = static_cast<const char *>(std::memchr(start, '\n', avail));
            size_t n = nl ? static_cast<size_t>(nl - start) : avail;
            // +1: room for the CR of a CRLF line end.
            if (line.size() + n > static_cast<size_t>(PMRUN_MAX_LINE) + 1) {
                std::string().swap(line);
                pos_ += nl ? n + 1 : n;
                rest_ = nl == nullptr;
                if (number_ == INT_MAX) return kIoError;
                ++number_;
                return kTooLong;
            }
            line.append(start, n);
            pos_ += n;
            if (nl) {
                ++pos_;
                break;
            }
        }
        if (number_ == INT_MAX) return kIoError;
        ++number_;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.size() > static_cast<size_t>(PMRUN_MAX_LINE)) return kTooLong;
        nul = std::memchr(line.data(), '\0', line.size()) != nullptr;
        return kLine;
    }

    int number() const { return number_; }
    bool io_error() const { return err_; }
    // The last line read ended at the end of the file, without a line end.
    bool unterminated() const { return unterminated_; }

private:
    // Skips what is left of a too-long line; false on a read error.
    bool skip_rest()
    {
        while (rest_) {
            if (pos_ == len_ && !fill()) {
                rest_ = false;
                return !err_;
            }
            const char *start = buf_.data() + pos_;
            size_t avail = len_ - pos_;
            const char *nl = static_cast<const char *>(std::memchr(start, '\n', avail));
            pos_ += nl ? static_cast<size_t>(nl - start) + 1 : avail;
            rest_ = nl == nullptr;
        }
        return true;
    }

    bool fill()
    {
        if (eof_) return false;
        len_ = std::fread(buf_.data(), 1, buf_.size(), f_);
        pos_ = 0;
        if (len_ == 0) {
            eof_ = true;
            err_ = std::ferror(f_) != 0;
            return false;
        }
        return true;
    }

    std::FILE *f_;
    std::vector<char> buf_;
    size_t pos_ = 0, len_ = 0;
    bool eof_ = false, err_ = false;
    bool rest_ = false;   // the rest of a too-long line is still unread
    bool unterminated_ = false;
    int number_ = 0;
};

struct FileCloser {
    void operator()(std::FILE *f) const { std::fclose(f); }
};

const char *kExpectedAny =
    "expected a pointing run: four numbers 'tau delta T D' per line, '#' comments and a "
    "'# tau delta T D ...' column header, or a TPOINT file (caption, '!' comments, ':' "
    "options, run line, records), an RTS2 gpoint file, a MountWizzard4 JSON model file, a "
    "CSV log with a header of named columns or an MMT pointing log";

// The fields of a CSV header line: split at the delimiter (',' or ';'),
// quotes removed, names normalised (letters and digits, lower case).
std::vector<std::string> csv_header_names(const std::string &line)
{
    char delim = line.find(',') != std::string::npos ? ',' : ';';
    std::vector<std::string> out;
    std::string cur;
    for (size_t i = 0; i <= line.size(); ++i) {
        if (i == line.size() || line[i] == delim) {
            out.push_back(cur);
            cur.clear();
            continue;
        }
        char c = line[i];
        if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'))
            cur += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    }
    return out;
}

// Does a line look like a CSV log's header: delimited, and naming a mount
// RA and Dec (docs/formats.md, "CSV logs")?  A TPOINT caption with a comma
// ("Test mount, latitude +49") does not.
bool csv_header(const std::string &line)
{
    if (line.find(',') == std::string::npos && line.find(';') == std::string::npos) return false;
    int ra = 0, dec = 0;
    for (const std::string &n : csv_header_names(line)) {
        ra += n.find("ra") != std::string::npos ? 1 : 0;
        dec += n.find("dec") != std::string::npos ? 1 : 0;
    }
    return ra >= 2 && dec >= 2;   // the mount's and the solved position
}

// A delimited line of four or more names, none a number, one naming an RA
// and one a Dec: a CSV log's header that lacks a column (an
// outside probe's "Mount Dec" written twice, no "Mount RA", had been read as
// a four-column file: "7 fields, expected 4"); read as one, its reader
// names what is missing.
//
// RA and Dec as words of a name ("Mount RA", "MountRA", "RA_mount", "Solved
// Dec", "Declination"), not inside one: a TPOINT caption "Camera test,
// Temperature 10C, Konkoly site, observer J Smith" (camera, temperature) is
// not a header (an outside probe's, read as a CSV log when any name holding
// "ra" counted).  Words: split at what is not a letter or digit and where a
// lower-case letter is followed by a capital.
bool csv_header_like(const std::string &line)
{
    if (line.find(',') == std::string::npos && line.find(';') == std::string::npos) return false;
    const char delim = line.find(',') != std::string::npos ? ',' : ';';
    int fields = 0, ra = 0, dec = 0;
    size_t b = 0;
    for (;;) {
        size_t e = line.find(delim, b);
        const std::string f = trim(line.substr(b, e == std::string::npos ? std::string::npos : e - b));
        std::string bare;
        for (char c : f)
            if (c != '"' && c != '\'') bare += c;
        if (bare.empty() || is_number(bare)) return false;
        ++fields;
        std::string w;
        bool has_ra = false, has_dec = false;
        auto word = [&]() {
            has_ra = has_ra || w == "ra";
            has_dec = has_dec || w == "dec" || w == "declination";
            w.clear();
        };
        for (size_t i = 0; i < bare.size(); ++i) {
            const char c = bare[i];
            const bool alnum = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
            if (!alnum) {
                word();
                continue;
            }
            if (c >= 'A' && c <= 'Z' && i > 0 && bare[i - 1] >= 'a' && bare[i - 1] <= 'z') word();
            w += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
        }
        word();
        ra += has_ra;
        dec += has_dec;
        if (e == std::string::npos) break;
        b = e + 1;
    }
    return fields >= 4 && ra >= 1 && dec >= 1;
}

// The first '#' line of an RTS2 gpoint file names its columns
// ("#  Observation  MJD  LST-MNT  RA-MNT ..."), or a '#observatory',
// '#gem' or '#altaz' line gives the site.
bool rts2_comment(const std::string &t)
{
    std::vector<std::string> tok = tokens(t.substr(1));
    if (tok.empty()) return false;
    bool mjd = false, mnt = false;
    for (const std::string &w : tok) {
        std::string l = lower(w);
        mjd = mjd || l == "mjd";
        mnt = mnt || l == "lst-mnt" || l == "ra-mnt" || l == "az-mnt";
    }
    if (mjd && mnt) return true;
    std::string f = lower(tok[0]);
    if ((f == "observatory" || f == "gem" || f == "altaz" || f == "altaz-manual") && tok.size() >= 4) {
        for (size_t i = 1; i < 4; ++i)
            if (!is_number(tok[i])) return false;
        return true;
    }
    return false;
}

// Picks the format from the first lines (docs/formats.md, "Detection"):
// '#' and blank lines are held until the first other line, which decides
// with them; then all are handed to the chosen parser.
class Detector : public FormatParser {
public:
    explicit Detector(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        if (parser_) return parser_->line(n, text);
        std::string t = trim(text);
        if (t.empty() || t[0] == '#') {
            if (!t.empty() && !rts2_ && rts2_comment(t)) {
                rts2_ = true;
                first_hash_ = n;
            }
            held_.emplace_back(n, text);
            held_bytes_ += text.size();
            // a long comment block: the column formats (they read '#' lines)
            if (held_.size() > 1000 || held_bytes_ > (1u << 20)) return choose(n, nullptr);
            return true;
        }
        // Excel's first line 'sep=;' names the delimiter of the CSV that follows
        if (!sep_line_ && excel_sep_line(t)) {
            if (t.size() != 5 || (t[4] != ',' && t[4] != ';')) {
                // (a tab or a blank is trimmed from t: named from the line)
                const size_t at = text.find_first_not_of(" \t") + 4;
                const char c = at < text.size() ? text[at] : '\0';
                return ctx_.fail(n, "Excel's delimiter line 'sep=%s': expected 'sep=,' or "
                                    "'sep=;' (a CSV log's fields are separated by ',' or ';')",
                                 c == '\t'  ? "<tab>"
                                 : c == ' ' ? "<blank>"
                                            : excerpt(t.substr(4)).c_str());
            }
            sep_line_ = n;
            held_.emplace_back(n, text);
            return true;
        }
        return choose(n, &t) && parser_->line(n, text);
    }

    bool unreadable(int n, const std::string &why) override
    {
        if (!parser_) {
            if (held_.empty()) return ctx_.fail(n, "%s; cannot tell the format", why.c_str());
            if (!choose(n, nullptr)) return false;
        }
        return parser_->unreadable(n, why);
    }

    bool finish(int last_line) override
    {
        if (!parser_ && !choose(last_line, nullptr)) return false;
        return parser_->finish(last_line);
    }

    bool empty() const { return held_.empty() && !parser_; }

private:
    // Chooses with the first non-comment line `t` (nullptr: none yet).
    bool choose(int n, const std::string *t)
    {
        int format = -1;
        std::string why;
        if (rts2_) {
            format = PMRUN_FORMAT_RTS2;
            why = format_str("its '#' line %d is an RTS2 gpoint header", first_hash_);
        } else if (sep_line_) {
            if (t && !csv_header(*t))
                return ctx_.fail(n, "line %d follows Excel's delimiter line (line %d) but is not a "
                                    "CSV header naming the mount's and the solved RA and Dec; %s",
                                 n, sep_line_, kExpectedAny);
            format = PMRUN_FORMAT_CSV;
        } else if (!held_.empty() || !t) {
            if (t && t->compare(0, 4, "CAT:") == 0) {
                format = PMRUN_FORMAT_MMT;
                why = format_str("line %d starts with 'CAT:'", n);
            } else if (t && csv_header(*t)) {
                format = PMRUN_FORMAT_CSV;
                why = format_str("line %d is a header of delimited names with RA and Dec", n);
            } else if (t && csv_header_like(*t)) {
                format = PMRUN_FORMAT_CSV;
                why = format_str("line %d is a header of delimited names, some of RA or Dec", n);
            } else {
                format = PMRUN_FORMAT_FOUR_COLUMN;   // four-column or named
                if (t && (t->find(',') != std::string::npos || t->find(';') != std::string::npos))
                    why = format_str("line %d has ',' or ';' but is not a CSV header naming the "
                                     "mount's and the solved RA and Dec",
                                     n);
            }
        } else if ((*t)[0] == '!' || (*t)[0] == ':') {
            format = PMRUN_FORMAT_TPOINT;
        } else if ((*t)[0] == '[' || (*t)[0] == '{') {
            format = PMRUN_FORMAT_MW4;
            why = format_str("line %d starts with '%c'", n, (*t)[0]);
        } else if (t->compare(0, 4, "CAT:") == 0) {
            format = PMRUN_FORMAT_MMT;
            why = format_str("line %d starts with 'CAT:'", n);
        } else if (csv_header(*t)) {
            format = PMRUN_FORMAT_CSV;
            why = format_str("line %d is a header of delimited names with RA and Dec", n);
        } else if (csv_header_like(*t)) {
            format = PMRUN_FORMAT_CSV;
            why = format_str("line %d is a header of delimited names, some of RA or Dec", n);
        } else {
            std::vector<std::string> tok = tokens(strip_comment(*t, '#'));
            if (!tok.empty() && is_number(tok[0])) {
                size_t nums = 0;
                for (const std::string &x : tok) nums += is_number(x) ? 1 : 0;
                if (nums != tok.size() || tok.size() != 4)
                    return ctx_.fail(n,
                                     "cannot tell the format: the first line '%s' starts with a "
                                     "number but is not four numbers 'tau delta T D' (a TPOINT "
                                     "caption must not start with a number); %s",
                                     excerpt(*t).c_str(), kExpectedAny);
                format = PMRUN_FORMAT_FOUR_COLUMN;
            } else {
                format = PMRUN_FORMAT_TPOINT;
                if (t->find(',') != std::string::npos || t->find(';') != std::string::npos)
                    why = format_str("line %d is taken as its caption: it has ',' or ';' but is "
                                     "not a CSV header naming the mount's and the solved RA and "
                                     "Dec",
                                     n);
            }
        }
        if (!equinox_applies(ctx_, format))
            return false;
        parser_ = make_parser(ctx_, format);
        if (!why.empty())
            ctx_.set_reading_as(std::string(format_description(format)) + " (" + why + ")");
        for (const auto &h : held_)
            if (!parser_->line(h.first, h.second)) return false;
        held_.clear();
        return true;
    }

    static std::string format_str(const char *fmt, ...) __attribute__((format(printf, 1, 2)))
    {
        va_list ap;
        va_start(ap, fmt);
        std::string s = vformat(fmt, ap);
        va_end(ap);
        return s;
    }

    Context &ctx_;
    std::unique_ptr<FormatParser> parser_;
    std::vector<std::pair<int, std::string>> held_;
    size_t held_bytes_ = 0;
    int first_hash_ = 0;
    int sep_line_ = 0;   // Excel's 'sep=' line, 0: none
    bool rts2_ = false;
};

// Records that repeat an earlier one exactly (same encoder and apparent
// readings and time): one warning, the fit goes on (docs/reliability.md).
void check_duplicates(Context &ctx)
{
    struct Key {
        double v[5];
        bool operator==(const Key &o) const { return std::memcmp(v, o.v, sizeof v) == 0; }
    };
    struct Hash {
        size_t operator()(const Key &k) const
        {
            size_t h = 1469598103934665603ULL;
            const unsigned char *p = reinterpret_cast<const unsigned char *>(k.v);
            for (size_t i = 0; i < sizeof k.v; ++i) h = (h ^ p[i]) * 1099511628211ULL;
            return h;
        }
    };
    const std::vector<pmrun_obs> &obs = ctx.run()->obs;
    std::unordered_map<Key, int, Hash> seen;
    seen.reserve(obs.size());
    long repeats = 0;
    int first = 0, first_of = 0;
    // The values as the file gives them, to well below any file's
    // precision: angles on a grid of 1e-11 rad (2 uas), the hour angles
    // turned into one turn first (a record copied after the night's end
    // reads its LST a day later, and its hour angles differ in the last
    // bits: 24 of a copied run's 454 repeats were found), times on 1e-9 h.
    auto grid = [](double v, double step) {
        if (!std::isfinite(v)) return v;   // (NaN, inf: as read)
        double q = std::nearbyint(v / step);
        return q == 0 ? 0.0 : q;           // (-0 and 0 alike)
    };
    for (const pmrun_obs &o : obs) {
        Key k;
        std::memset(&k, 0, sizeof k);   // NaN payloads: as read
        k.v[0] = grid(std::remainder(o.enc_ha, 2 * M_PI), 1e-11);
        k.v[1] = grid(o.enc_dec, 1e-11);
        k.v[2] = grid(std::remainder(o.app_ha, 2 * M_PI), 1e-11);
        k.v[3] = grid(o.app_dec, 1e-11);
        k.v[4] = std::isnan(o.time_h) ? 0.0 : grid(o.time_h, 1e-9);
        auto ins = seen.emplace(k, o.line);
        if (ins.second) continue;
        if (repeats++ == 0) {
            first = o.line;
            first_of = ins.first->second;
        }
    }
    if (repeats > 0)
        ctx.warn(first,
                 "record repeats line %d exactly (%ld record%s repeat an earlier one): each counts "
                 "as an independent measurement in the fit; if they are copies, remove them (the "
                 "fit's errors assume independent points)",
                 first_of, repeats, repeats == 1 ? "" : "s");
}

// A named-column run of a German mount with both pier sides and no
// encoder declination beyond +-90 deg writes its W records folded back
// into the sky position (the convention of ASCOM logs, whose pierWest is
// "through the pole"): mechanically one side must be beyond the pole.
// Its W records are read as the mount's axes are, (HA + 180, +-180 - dec):
// as they were, d, e', i and the order-1 terms of those base vectors
// changed sign across the flip by the file's convention, and explain read
// that as physics (a pier-side flexure of 310" and order 3 on a run of
// 2" noise).  enc_raw keeps the file's values; a note says so.
void unfold_sky_convention(Context &ctx)
{
    pmrun *run = ctx.run();
    if (run->format != PMRUN_FORMAT_NAMED || run->mount != PMRUN_MOUNT_EQUATORIAL)
        return;
    int first_w = 0;
    bool east = false;
    for (const pmrun_obs &o : run->obs) {
        if (std::fabs(o.enc_dec) > kPi / 2)
            return; // beyond the pole: the mount's own convention
        east = east || o.pier == PMRUN_PIER_EAST;
        if (o.pier == PMRUN_PIER_WEST && !first_w)
            first_w = o.line;
    }
    if (!east || !first_w)
        return;
    for (pmrun_obs &o : run->obs)
        if (o.pier == PMRUN_PIER_WEST) {
            o.enc_ha = std::remainder(o.enc_ha + kPi, 2 * kPi);
            o.enc_dec = (o.enc_dec >= 0 ? kPi : -kPi) - o.enc_dec;
        }
    ctx.warn(first_w,
             "both pier sides and no encoder declination beyond +-90 deg: the W records are "
             "the sky position folded back (as ASCOM's pierWest, through the pole); read as the "
             "mount's axes, (HA + 180, 180 - dec) (docs/formats.md, \"Beyond the pole\")");
}

// Does the last field of `last` (a record on the last line, which has no
// line end) look cut short against `prev` (the record before it): fewer
// fields, or a last number with fewer decimals?
bool cut_short(const std::string &last, const std::string &prev)
{
    auto fields = [](const std::string &t) {
        std::vector<std::string> f;
        std::string cur;
        for (char c : t) {
            if (c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r') {
                if (!cur.empty()) f.push_back(cur);
                cur.clear();
            } else {
                cur += c;
            }
        }
        if (!cur.empty()) f.push_back(cur);
        return f;
    };
    auto decimals = [](const std::string &t) {
        size_t dot = t.find('.');
        if (dot == std::string::npos) return 0;
        size_t k = dot + 1;
        while (k < t.size() && t[k] >= '0' && t[k] <= '9') ++k;
        return (int)(k - dot - 1);
    };
    std::vector<std::string> a = fields(last), b = fields(prev);
    if (a.size() < b.size()) return true;
    if (a.empty() || b.empty() || !is_number(a.back()) || !is_number(b.back())) return false;
    return decimals(a.back()) < decimals(b.back());
}

// One encoder convention per run (docs/formats.md, "Beyond the pole"): a
// pier column must relate to the encoder declination the same way for all
// records of a side, and the encoder axis 1 (beyond the pole turned back by
// 180 deg) must be near the apparent one for every record as for the run.
const double kNearPoleSide = 2.0 * kPi / 180.0;

bool check_conventions(Context &ctx)
{
    const pmrun *run = ctx.run();
    const std::vector<pmrun_obs> &obs = run->obs;
    bool altaz = run->mount == PMRUN_MOUNT_ALTAZ;
    const double half = kPi / 2;
    if (!altaz) {
        const pmrun_obs *side[2] = {nullptr, nullptr};   // first E, first W record
        for (const pmrun_obs &o : obs) {
            if (o.pier == PMRUN_PIER_UNKNOWN) continue;
            // within 2 deg of the pole the encoder cannot show the side: an
            // index error moves a record across 90 deg (an outside probe's
            // star at Dec 89.37 on the flipped side with a 0.69 deg Dec index
            // reads 89.94 deg, pier W; the run had been refused)
            if (std::fabs(std::fabs(o.enc_dec) - half) < kNearPoleSide) continue;
            const pmrun_obs *&f = side[o.pier == PMRUN_PIER_WEST ? 1 : 0];
            if (!f) {
                f = &o;
                continue;
            }
            bool b0 = std::fabs(f->enc_dec) > half, b1 = std::fabs(o.enc_dec) > half;
            if (b0 != b1) {
                const char *p = o.pier == PMRUN_PIER_WEST ? "W" : "E";
                return ctx.fail(o.line,
                                "pier %s with encoder dec %.4g deg (%s) but line %d has pier %s with "
                                "encoder dec %.4g deg (%s): mixed encoder conventions? expected one "
                                "convention for the run (this reader's: beyond the pole, an encoder "
                                "dec beyond +-90 deg)",
                                p, o.enc_dec / kDeg, b1 ? "beyond the pole" : "within +-90", f->line,
                                p, f->enc_dec / kDeg, b0 ? "beyond the pole" : "within +-90");
            }
        }
        // E is the normal side, W beyond the pole (docs/formats.md, "Pier
        // side"): a run whose E records are beyond the pole and whose W
        // records (if any) are within names the sides the other way round
        // (the side the tube is on, say).  Its labels are read by its
        // encoders, with a note: as written, --pier split's "east" model was
        // the beyond-the-pole records', and a term@W was fitted on the normal
        // side (an outside probe).  E and W both beyond the pole: refused.
        const bool e_beyond = side[0] && std::fabs(side[0]->enc_dec) > half;
        const bool w_beyond = side[1] && std::fabs(side[1]->enc_dec) > half;
        if (e_beyond && w_beyond)
            return ctx.fail(side[1]->line,
                            "pier W with encoder dec %.4g deg (beyond the pole), and line %d has "
                            "pier E with encoder dec %.4g deg (beyond the pole too): the pier "
                            "column does not follow the encoder (E: the normal side, W: beyond "
                            "the pole)",
                            side[1]->enc_dec / kDeg, side[0]->line, side[0]->enc_dec / kDeg);
        // W only, every encoder dec within +-90: the label and the encoder
        // disagree, and the run cannot say which is right (a sky position
        // folded back, or the sides named the other way round): said
        if (!side[0] && side[1] && !w_beyond)
            ctx.warn(side[1]->line,
                     "every record is pier W (beyond the pole) with its encoder declination "
                     "within +-90 deg: the sky position folded back (ASCOM's pierWest: give the "
                     "mount's axes, dec beyond +-90), or the pier column names the sides the "
                     "other way round; read as written, which the fit cannot check (the signs "
                     "of d, e' and i follow the side)");
        if (e_beyond) {
            for (pmrun_obs &o : ctx.run()->obs)
                if (o.pier != PMRUN_PIER_UNKNOWN)
                    o.pier = o.pier == PMRUN_PIER_WEST ? PMRUN_PIER_EAST : PMRUN_PIER_WEST;
            ctx.warn(side[0]->line,
                     "pier E with encoder dec %.4g deg, beyond the pole%s: the pier column names "
                     "the sides the other way round from this reader (E: the normal side, W: "
                     "beyond the pole); read by the encoder, E as W and W as E",
                     side[0]->enc_dec / kDeg,
                     side[1] ? (", and every W record within +-90 (line " +
                                std::to_string(side[1]->line) + ")").c_str()
                             : "");
        }
    }
    // Axis-1 offsets of the records away from the pole / zenith, where the
    // axis-1 angle is well defined.
    const double kMaxLat = 75 * kDeg, kMaxOffset = 60 * kDeg;
    std::vector<double> off(obs.size(), nan());
    double s = 0, c = 0;
    for (size_t i = 0; i < obs.size(); ++i) {
        const pmrun_obs &o = obs[i];
        double a1 = o.enc_ha, a2 = o.enc_dec;
        if (std::fabs(a2) > half) {   // beyond the pole / over the zenith
            a1 += kPi;
            a2 = (a2 > 0 ? kPi : -kPi) - a2;
        }
        if (std::fabs(a2) > kMaxLat || std::fabs(o.app_dec) > kMaxLat) continue;
        off[i] = std::remainder(a1 - o.app_ha, 2 * kPi);
        s += std::sin(off[i]);
        c += std::cos(off[i]);
    }
    double mean = std::atan2(s, c);
    for (size_t i = 0; i < obs.size(); ++i) {
        if (std::isnan(off[i]) || std::fabs(std::remainder(off[i] - mean, 2 * kPi)) <= kMaxOffset)
            continue;
        const pmrun_obs &o = obs[i];
        if (altaz)
            return ctx.fail(o.line,
                            "encoder azimuth is %.1f deg from the star's azimuth here but %.1f deg "
                            "on average over the run: mixed azimuth conventions? expected azimuths "
                            "of one convention (north through east in column files) for the run",
                            off[i] / kDeg, mean / kDeg);
        return ctx.fail(o.line,
                        "encoder hour angle is %.1f deg from the star's here but %.1f deg on average "
                        "over the run (an encoder dec beyond +-90 taken as beyond the pole, HA turned "
                        "by 180 deg): mixed encoder conventions? expected one convention for the run "
                        "(beyond the pole: encoder dec beyond +-90 and encoder HA 180 deg from the "
                        "star's)",
                        off[i] / kDeg, mean / kDeg);
    }
    return true;
}

int read_file(Context &ctx)
{
    std::FILE *raw = std::fopen(ctx.path().c_str(), "rb");
    if (!raw) {
        int e = errno;
        ctx.fail_with(PMRUN_ERR_IO, 0, "cannot open: %s", std::strerror(e));
        return ctx.status();
    }
    std::unique_ptr<std::FILE, FileCloser> f(raw);
    LineReader rd(raw);
    int forced = ctx.opt().format;
    std::unique_ptr<FormatParser> parser;
    Detector *detector = nullptr;
    if (forced == PMRUN_FORMAT_AUTO) {
        detector = new Detector(ctx);
        parser.reset(detector);
    } else {
        parser = make_parser(ctx, forced);
        if (!parser) {
            ctx.fail_with(PMRUN_ERR_ARG, 0, "options.format %d is not a format, expected "
                                            "PMRUN_FORMAT_AUTO or a PMRUN_FORMAT_* id",
                          forced);
            return ctx.status();
        }
        ctx.set_reading_as(std::string(format_description(forced)) + " (format forced: " +
                           pmrun_format_name(forced) + ")");
        if (!equinox_applies(ctx, forced))
            return ctx.status();
    }
    std::string line, last_text, prev_text; // the last two lines (cut_short)
    bool nul = false;
    bool any_text = false, any_line = false;
    for (;;) {
        LineReader::Result r = rd.next(line, nul);
        if (r == LineReader::kEof) break;
        if (r == LineReader::kLine) {
            prev_text.swap(last_text);
            last_text = line;
        }
        if (r == LineReader::kIoError) {
            if (rd.io_error())
                ctx.fail_with(PMRUN_ERR_IO, rd.number() + 1, "read error: %s", std::strerror(errno));
            else
                ctx.fail(rd.number(), "too many lines: expected fewer than %d", INT_MAX);
            return ctx.status();
        }
        int n = rd.number();
        if (n == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 BOM
        std::string why;
        if (r == LineReader::kTooLong)
            why = format("line too long (more than %d bytes), expected at most %d bytes per line",
                         PMRUN_MAX_LINE, PMRUN_MAX_LINE);
        else if (nul)
            why = "NUL byte in the line (binary data?), expected text";
        else if (std::count(line.begin(), line.end(), '\r') >= 2)
            // (one line holding the whole file: it said "no records")
            why = "carriage returns inside the line: a file with classic Mac (CR-only) line "
                  "ends? expected lines ending in LF or CR LF (convert it: tr '\\r' '\\n' < "
                  "FILE > NEW)";
        any_text = true;
        if (!any_line) {
            if (!why.empty() && forced == PMRUN_FORMAT_AUTO) {
                ctx.fail(n, "%s; cannot tell the format", why.c_str());
                return ctx.status();
            }
            if (why.empty() && trim(line).empty()) continue;
            any_line = true;
        }
        bool ok = why.empty() ? parser->line(n, line) : parser->unreadable(n, why);
        if (!ok) return ctx.status();
    }
    if (!any_line) {
        if (!any_text)
            ctx.fail(0, "empty file: %s", kExpectedAny);
        else
            ctx.fail(rd.number(), "no records: the file holds only blank lines; %s", kExpectedAny);
        return ctx.status();
    }
    if (!parser->finish(rd.number())) return ctx.status();
    // A record on a last line without a line end: a file cut short reads
    // its last number short (12.3 of 12.3456), and that record is wrong
    // without an error.  Noted where its last number has fewer decimals
    // than the record before it has there (or there is no record before it
    // to tell); JSON (MW4) ends without a line end as a rule.
    const std::vector<pmrun_obs> &obs = ctx.run()->obs;
    if (rd.unterminated() && ctx.run()->format != PMRUN_FORMAT_MW4 && !obs.empty() &&
        obs.back().line == rd.number()) {
        const bool prev_record = obs.size() > 1 && obs[obs.size() - 2].line == rd.number() - 1;
        if (!prev_record || cut_short(last_text, prev_text))
            ctx.warn(rd.number(), "the last line has no line end%s: if the file was cut short, "
                                  "this record is incomplete (read as written)",
                     prev_record ? " and fewer fields or decimals at its end than the line before"
                                 : "");
    }
    unfold_sky_convention(ctx);
    if (!check_conventions(ctx)) return ctx.status();
    check_duplicates(ctx);
    ctx.finish_messages();
    return PMRUN_OK;
}

void set_error(char *err, size_t errlen, const std::string &msg)
{
    if (!err || errlen == 0) return;
    size_t n = msg.size() < errlen - 1 ? msg.size() : errlen - 1;
    std::memcpy(err, msg.data(), n);
    err[n] = '\0';
}

}  // namespace
}  // namespace pmrun_detail

using namespace pmrun_detail;

extern "C" {

void pmrun_options_default(pmrun_options *opt)
{
    if (!opt) return;
    opt->refraction = 1;
    opt->skip_bad = 0;
    opt->pressure_hpa = nan();
    opt->temp_c = nan();
    opt->humidity = nan();
    opt->wavelength_um = nan();
    opt->format = PMRUN_FORMAT_AUTO;
    opt->equinox = PMRUN_EQUINOX_FILE;
}

int pmrun_read(const char *path, const pmrun_options *opt, pmrun **out, char *err, size_t errlen)
{
    if (out) *out = nullptr;
    set_error(err, errlen, "");
    if (!path || !out) {
        set_error(err, errlen, "pmrun_read: NULL path or out pointer, expected both");
        return PMRUN_ERR_ARG;
    }
    try {
        pmrun_options o;
        if (opt)
            o = *opt;
        else
            pmrun_options_default(&o);
        std::unique_ptr<pmrun> run(new pmrun);
        pmrun_site &site = run->site;
        site.latitude_rad = site.height_m = site.pressure_hpa = site.temp_c = nan();
        site.humidity = site.wavelength_um = site.lapse_k_per_m = nan();
        site.year = site.month = site.day = 0;
        Context ctx(path, o, run.get());
        int st = read_file(ctx);
        if (st != PMRUN_OK) {
            set_error(err, errlen, ctx.error());
            return st;
        }
        // Weather given for a run no reduction refracted: said, not dropped
        // in silence (the places are observed ones already, alt-az, or
        // refraction is off).
        if (!run->weather_used && !(std::isnan(o.pressure_hpa) && std::isnan(o.temp_c) &&
                                    std::isnan(o.humidity) && std::isnan(o.wavelength_um)))
            ctx.warn(0, "the weather options (pressure, temperature, humidity, wavelength) are not "
                        "used: no place of this run is reduced with refraction (its places are "
                        "observed ones, or refraction is off)");
        *out = run.release();
        return PMRUN_OK;
    } catch (const std::bad_alloc &) {
        set_error(err, errlen, std::string(path) + ": out of memory");
        return PMRUN_ERR_NOMEM;
    } catch (...) {
        set_error(err, errlen, std::string(path) + ": out of memory (container limit)");
        return PMRUN_ERR_NOMEM;
    }
}

void pmrun_free(pmrun *run) { delete run; }

size_t pmrun_count(const pmrun *run) { return run ? run->obs.size() : 0; }

const pmrun_obs *pmrun_get(const pmrun *run, size_t i)
{
    if (!run || i >= run->obs.size()) return nullptr;
    return &run->obs[i];
}

int pmrun_mount(const pmrun *run) { return run ? run->mount : -1; }

int pmrun_format(const pmrun *run) { return run ? run->format : -1; }

static const char *const kFormatNames[] = {"four-column", "named", "tpoint", "rts2",
                                           "mw4",         "csv",   "mmt"};

const char *pmrun_format_name(int format)
{
    if (format == PMRUN_FORMAT_AUTO) return "auto";
    if (format < 0 || format > PMRUN_FORMAT_MMT) return nullptr;
    return kFormatNames[format];
}

int pmrun_format_from_name(const char *name)
{
    if (!name) return -2;
    std::string l = lower(name);
    if (l == "auto") return PMRUN_FORMAT_AUTO;
    for (int i = 0; i <= PMRUN_FORMAT_MMT; ++i)
        if (l == kFormatNames[i]) return i;
    return -2;
}

double pmrun_latitude_rad(const pmrun *run) { return run ? run->site.latitude_rad : nan(); }

int pmrun_get_site(const pmrun *run, pmrun_site *site)
{
    if (!run || !site) return PMRUN_ERR_ARG;
    *site = run->site;
    return PMRUN_OK;
}

int pmrun_n_aux(const pmrun *run) { return run ? static_cast<int>(run->aux_names.size()) : 0; }

const char *pmrun_aux_name(const pmrun *run, int i)
{
    if (!run || i < 0 || static_cast<size_t>(i) >= run->aux_names.size()) return nullptr;
    return run->aux_names[static_cast<size_t>(i)].c_str();
}

int pmrun_n_warnings(const pmrun *run) { return run ? static_cast<int>(run->warnings.size()) : 0; }

const char *pmrun_warning(const pmrun *run, int i)
{
    if (!run || i < 0 || static_cast<size_t>(i) >= run->warnings.size()) return nullptr;
    return run->warnings[static_cast<size_t>(i)].c_str();
}

int pmrun_n_skipped(const pmrun *run) { return run ? run->n_skipped : 0; }

const char *pmrun_skipped(const pmrun *run, int i)
{
    if (!run || i < 0 || static_cast<size_t>(i) >= run->skipped.size()) return nullptr;
    return run->skipped[static_cast<size_t>(i)].c_str();
}

}  // extern "C"
