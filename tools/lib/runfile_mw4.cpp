// runfile_mw4.cpp - MountWizzard4 model files: the JSON list of points MW4
// saves after a model build (its generateSaveData: json.dump of one object
// per point).  The reader uses the mount's JNow place (raJNowM hours,
// decJNowM degrees), the plate-solved JNow place (raJNowS, decJNowS), the
// mount's sidereal time (siderealTime, hours) and side of pier (pierside
// "E"/"W"); julianDate (UTC, ISO 8601), latitude, angularPosRA/DEC and a
// "temperature" key are read when present.  docs/formats.md, section 5.
#include "runfile_internal.hpp"

#include <erfa.h>

#include <charconv>
#include <cmath>
#include <cstring>

namespace pmrun_detail {
namespace {

// Largest file the reader holds in memory (the JSON is parsed whole).
constexpr size_t kMaxBytes = 64u << 20;
// Deepest nesting of JSON arrays/objects accepted.
constexpr int kMaxDepth = 64;

struct JValue {
    enum Type { kNull, kBool, kNumber, kString, kArray, kObject } type = kNull;
    bool b = false;
    double num = 0;
    std::string str;
    std::vector<JValue> arr;
    std::vector<std::pair<std::string, JValue>> obj;
    int line = 0;
};

// A strict JSON parser (RFC 8259, plus Python's NaN, Infinity, -Infinity
// numbers, which json.dump writes for non-finite floats) over the whole
// text, keeping line numbers.
class Json {
public:
    Json(const std::string &text, int first_line) : s_(text), line_(first_line) {}

    bool parse(JValue &out)
    {
        ws();
        if (!value(out, 0)) return false;
        ws();
        if (i_ != s_.size()) return error("text after the JSON value");
        return true;
    }

    int line() const { return line_; }
    const std::string &why() const { return why_; }

private:
    bool error(const std::string &what)
    {
        if (why_.empty()) why_ = what;
        return false;
    }

    void ws()
    {
        while (i_ < s_.size()) {
            char c = s_[i_];
            if (c == '\n')
                ++line_;
            else if (c != ' ' && c != '\t' && c != '\r')
                break;
            ++i_;
        }
    }

    bool literal(const char *word)
    {
        size_t n = std::strlen(word);
        if (s_.compare(i_, n, word) != 0) return false;
        i_ += n;
        return true;
    }

    bool value(JValue &v, int depth)
    {
        if (depth > kMaxDepth) return error(format("nesting deeper than %d, expected MW4's list of "
                                                   "point objects", kMaxDepth));
        v.line = line_;
        if (i_ >= s_.size()) return error("unexpected end of the file, expected a JSON value");
        char c = s_[i_];
        if (c == '{') return object(v, depth);
        if (c == '[') return array(v, depth);
        if (c == '"') {
            v.type = JValue::kString;
            return string(v.str);
        }
        if (literal("true")) {
            v.type = JValue::kBool;
            v.b = true;
            return true;
        }
        if (literal("false")) {
            v.type = JValue::kBool;
            return true;
        }
        if (literal("null")) return true;
        v.type = JValue::kNumber;
        if (literal("NaN")) {
            v.num = nan();
            return true;
        }
        if (literal("Infinity")) {
            v.num = HUGE_VAL;
            return true;
        }
        if (literal("-Infinity")) {
            v.num = -HUGE_VAL;
            return true;
        }
        return number(v.num);
    }

    bool number(double &x)
    {
        size_t b = i_;
        auto digit = [&](size_t k) { return k < s_.size() && s_[k] >= '0' && s_[k] <= '9'; };
        if (i_ < s_.size() && s_[i_] == '-') ++i_;
        if (!digit(i_)) return error(format("'%s' is not a JSON value, expected a number, string, "
                                            "list, object, true, false or null",
                                            excerpt(s_.substr(b, 12)).c_str()));
        if (s_[i_] == '0')
            ++i_;
        else
            while (digit(i_)) ++i_;
        if (i_ < s_.size() && s_[i_] == '.') {
            ++i_;
            if (!digit(i_)) return error("a number with no digits after '.'");
            while (digit(i_)) ++i_;
        }
        if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
            ++i_;
            if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
            if (!digit(i_)) return error("a number with no digits in its exponent");
            while (digit(i_)) ++i_;
        }
        std::from_chars_result r = std::from_chars(s_.data() + b, s_.data() + i_, x);
        if (r.ec != std::errc() || r.ptr != s_.data() + i_ || !std::isfinite(x))
            return error(format("number '%s' out of range, expected a finite double",
                                excerpt(s_.substr(b, i_ - b)).c_str()));
        return true;
    }

    static void utf8(unsigned cp, std::string &out)
    {
        if (cp < 0x80) {
            out += static_cast<char>(cp);
        } else if (cp < 0x800) {
            out += static_cast<char>(0xC0 | (cp >> 6));
            out += static_cast<char>(0x80 | (cp & 0x3F));
        } else if (cp < 0x10000) {
            out += static_cast<char>(0xE0 | (cp >> 12));
            out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (cp & 0x3F));
        } else {
            out += static_cast<char>(0xF0 | (cp >> 18));
            out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
            out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (cp & 0x3F));
        }
    }

    bool hex4(unsigned &cp)
    {
        cp = 0;
        for (int k = 0; k < 4; ++k, ++i_) {
            if (i_ >= s_.size()) return error("a \\u escape with fewer than 4 hex digits");
            char c = s_[i_];
            unsigned d = (c >= '0' && c <= '9')   ? static_cast<unsigned>(c - '0')
                         : (c >= 'a' && c <= 'f') ? static_cast<unsigned>(c - 'a' + 10)
                         : (c >= 'A' && c <= 'F') ? static_cast<unsigned>(c - 'A' + 10)
                                                  : 16u;
            if (d == 16) return error("a \\u escape with fewer than 4 hex digits");
            cp = cp * 16 + d;
        }
        return true;
    }

    bool string(std::string &out)
    {
        ++i_;   // the opening quote
        for (;;) {
            if (i_ >= s_.size()) return error("a string not closed by '\"' before the end of the file");
            unsigned char c = static_cast<unsigned char>(s_[i_]);
            if (c == '"') {
                ++i_;
                return true;
            }
            if (c < 0x20) return error("a control character (a line end?) inside a string, "
                                       "expected it escaped");
            if (c != '\\') {
                out += static_cast<char>(c);
                ++i_;
                continue;
            }
            ++i_;
            if (i_ >= s_.size()) return error("a string not closed by '\"' before the end of the file");
            char e = s_[i_++];
            switch (e) {
            case '"': out += '"'; break;
            case '\\': out += '\\'; break;
            case '/': out += '/'; break;
            case 'b': out += '\b'; break;
            case 'f': out += '\f'; break;
            case 'n': out += '\n'; break;
            case 'r': out += '\r'; break;
            case 't': out += '\t'; break;
            case 'u': {
                unsigned cp;
                if (!hex4(cp)) return false;
                if (cp >= 0xD800 && cp < 0xDC00) {
                    unsigned lo;
                    if (s_.compare(i_, 2, "\\u") != 0) return error("a lone UTF-16 surrogate in a \\u escape");
                    i_ += 2;
                    if (!hex4(lo)) return false;
                    if (lo < 0xDC00 || lo >= 0xE000) return error("a lone UTF-16 surrogate in a \\u escape");
                    cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
                } else if (cp >= 0xDC00 && cp < 0xE000) {
                    return error("a lone UTF-16 surrogate in a \\u escape");
                }
                utf8(cp, out);
                break;
            }
            default:
                return error(format("an unknown escape '\\%s' in a string",
                                    excerpt(std::string(1, e)).c_str()));
            }
        }
    }

    bool array(JValue &v, int depth)
    {
        v.type = JValue::kArray;
        ++i_;
        ws();
        if (i_ < s_.size() && s_[i_] == ']') {
            ++i_;
            return true;
        }
        for (;;) {
            if (v.arr.size() >= static_cast<size_t>(PMRUN_MAX_RECORDS))
                return error(format("more than %d list entries, expected at most %d",
                                    PMRUN_MAX_RECORDS, PMRUN_MAX_RECORDS));
            v.arr.emplace_back();
            ws();
            if (!value(v.arr.back(), depth + 1)) return false;
            ws();
            if (i_ < s_.size() && s_[i_] == ',') {
                ++i_;
                continue;
            }
            if (i_ < s_.size() && s_[i_] == ']') {
                ++i_;
                return true;
            }
            return error("expected ',' or ']' after a list entry");
        }
    }

    bool object(JValue &v, int depth)
    {
        v.type = JValue::kObject;
        ++i_;
        ws();
        if (i_ < s_.size() && s_[i_] == '}') {
            ++i_;
            return true;
        }
        for (;;) {
            ws();
            if (i_ >= s_.size() || s_[i_] != '"') return error("expected a key in '\"' in an object");
            std::string key;
            int key_line = line_;
            if (!string(key)) return false;
            for (const auto &kv : v.obj)
                if (kv.first == key) {
                    line_ = key_line;
                    return error(format("key '%s' twice in one object, expected each key once",
                                        excerpt(key).c_str()));
                }
            ws();
            if (i_ >= s_.size() || s_[i_] != ':') return error("expected ':' after a key");
            ++i_;
            ws();
            v.obj.emplace_back(key, JValue());
            if (!value(v.obj.back().second, depth + 1)) return false;
            ws();
            if (i_ < s_.size() && s_[i_] == ',') {
                ++i_;
                continue;
            }
            if (i_ < s_.size() && s_[i_] == '}') {
                ++i_;
                return true;
            }
            return error("expected ',' or '}' after a value in an object");
        }
    }

    const std::string &s_;
    size_t i_ = 0;
    int line_;
    std::string why_;
};

const JValue *member(const JValue &o, const char *key)
{
    for (const auto &kv : o.obj)
        if (kv.first == key) return &kv.second;
    return nullptr;
}

class Mw4Parser : public FormatParser {
public:
    explicit Mw4Parser(Context &ctx) : ctx_(ctx) {}

    bool line(int n, const std::string &text) override
    {
        if (!first_line_) first_line_ = n;
        // blank lines before the first one were skipped by the caller: the
        // held text starts at first_line_ and every line after is kept
        while (last_line_ + 1 < n && last_line_ > 0) {
            text_ += '\n';
            ++last_line_;
        }
        if (text_.size() + text.size() + 1 > kMaxBytes)
            return ctx_.fail(n, "file larger than %zu MiB, expected a MountWizzard4 model file "
                                "(a JSON list of points)",
                             kMaxBytes >> 20);
        if (last_line_ > 0) text_ += '\n';
        text_ += text;
        last_line_ = n;
        return true;
    }

    bool unreadable(int n, const std::string &why) override { return ctx_.fail(n, "%s", why.c_str()); }

    bool finish(int last_line) override
    {
        if (ctx_.opt().equinox == PMRUN_EQUINOX_J2000)
            return ctx_.fail(0, "the J2000 equinox was asked for, but MW4 files are read through "
                                "their JNow places (raJNowM, raJNowS: the mount's own frame), "
                                "expected the file's equinox (or JNow)");
        JValue root;
        Json js(text_, first_line_ ? first_line_ : 1);
        if (!js.parse(root)) return ctx_.fail(js.line(), "%s", js.why().c_str());
        if (root.type != JValue::kArray)
            return ctx_.fail(root.line, "the JSON value is not a list, expected a list of points "
                                        "('[' {...}, ... ']') as MountWizzard4 saves its model");
        pmrun *run = ctx_.run();
        double lat = nan();
        int lat_line = 0;
        bool any_time = false;
        UtcTime t0;
        for (const JValue &p : root.arr)
            if (!point(p, lat, lat_line, any_time, t0)) return false;
        if (run->obs.empty()) {
            if (run->n_skipped > 0)
                return ctx_.fail(last_line, "no records left: all %d records were bad and skipped",
                                 run->n_skipped);
            return ctx_.fail(last_line, "no points: the list holds no usable point, expected "
                                        "objects with raJNowM, decJNowM, raJNowS, decJNowS, "
                                        "siderealTime, pierside");
        }
        run->format = PMRUN_FORMAT_MW4;
        run->mount = PMRUN_MOUNT_EQUATORIAL;
        run->site.latitude_rad = lat;
        if (any_time) {
            run->site.year = t0.year;
            run->site.month = t0.month;
            run->site.day = t0.day;
        }
        if (n_aux_ > 0) run->aux_names = {"angularPosRA", "angularPosDEC"};
        return true;
    }

private:
    // A required number (or, for the times, a sexagesimal string).
    bool num(const JValue &p, const char *key, double &v, std::string &why, bool sexa = false)
    {
        const JValue *m = member(p, key);
        if (!m) {
            why = format("point has no '%s'", key);
            return false;
        }
        if (m->type == JValue::kString && sexa) {
            std::string w;
            if (!parse_sexagesimal(m->str, v, w)) {
                why = format("'%s' \"%s\": %s", key, excerpt(m->str).c_str(), w.c_str());
                return false;
            }
            return true;
        }
        if (m->type != JValue::kNumber) {
            why = format("'%s' is not a number", key);
            return false;
        }
        if (!std::isfinite(m->num)) {
            why = format("'%s' is NaN/Infinity, expected a finite number", key);
            return false;
        }
        v = m->num;
        return true;
    }

    bool point(const JValue &p, double &lat, int &lat_line, bool &any_time, UtcTime &t0)
    {
        int n = p.line;
        if (p.type != JValue::kObject)
            return ctx_.bad_record(n, "list entry is not an object, expected one object per point");
        const JValue *ok = member(p, "success");
        if (ok && ok->type == JValue::kBool && !ok->b) {
            ctx_.warn(n, "point with \"success\": false (not solved) left out");
            return true;
        }
        double ra_m, dec_m, ra_s, dec_s, st;
        std::string why;
        if (!num(p, "raJNowM", ra_m, why) || !num(p, "decJNowM", dec_m, why) ||
            !num(p, "raJNowS", ra_s, why) || !num(p, "decJNowS", dec_s, why) ||
            !num(p, "siderealTime", st, why, true))
            return ctx_.bad_record(n, why + ", expected raJNowM, decJNowM, raJNowS, decJNowS "
                                            "(hours, degrees), siderealTime (hours)");
        const char *range = nullptr;
        if (!(ra_m >= 0 && ra_m < 24))
            range = "raJNowM";
        else if (!(ra_s >= 0 && ra_s < 24))
            range = "raJNowS";
        else if (!(st >= 0 && st < 24))
            range = "siderealTime";
        if (range)
            return ctx_.bad_record(n, format("'%s' out of range, expected 0 <= hours < 24", range));
        if (std::fabs(dec_m) > 90 || std::fabs(dec_s) > 90)
            return ctx_.bad_record(n, format("'%s' beyond +-90 deg, expected a declination within "
                                             "-90..+90 (the sky place; the side is pierside)",
                                             std::fabs(dec_m) > 90 ? "decJNowM" : "decJNowS"));
        const JValue *ps = member(p, "pierside");
        int pier = 0;
        if (ps && ps->type == JValue::kString) {
            std::string l = lower(ps->str);
            if (l == "e" || l == "east" || l == "piereast")
                pier = PMRUN_PIER_EAST;
            else if (l == "w" || l == "west" || l == "pierwest")
                pier = PMRUN_PIER_WEST;
        }
        if (!pier)
            return ctx_.bad_record(n, "'pierside' missing or not \"E\"/\"W\", expected the "
                                      "mount's side of pier");
        pmrun_obs o = blank_obs(n);
        o.pier = pier;
        double ha_m = (st - ra_m) * 15.0, ha_s = (st - ra_s) * 15.0;
        double eh, ed;
        sky_to_encoder_deg(ha_m, dec_m, pier, eh, ed);
        o.enc_ha = eh * kDeg;
        o.enc_dec = ed * kDeg;
        o.enc_raw[0] = (pier == PMRUN_PIER_WEST ? ha_m + 180.0 : ha_m) * kDeg;
        o.enc_raw[1] = (pier == PMRUN_PIER_WEST ? 180.0 - dec_m : dec_m) * kDeg;
        // the mount's JNow places are corrected for refraction by the mount
        // (MW4 programs it with the JNowM/JNowS pairs): no refraction here
        o.app_ha = reduce_deg(ha_s) * kDeg;
        o.app_dec = dec_s * kDeg;
        const JValue *jd = member(p, "julianDate");
        if (jd && jd->type == JValue::kString) {
            UtcTime t;
            std::string w;
            if (!parse_iso_utc(jd->str, t, w))
                return ctx_.bad_record(n, format("'julianDate' \"%s\": %s", excerpt(jd->str).c_str(),
                                                 w.c_str()));
            if (!any_time) t0 = t;
            any_time = true;
            o.time_h = hours_since(t0, t);
        } else if (jd && jd->type == JValue::kNumber && std::isfinite(jd->num) && jd->num > 2400000.5 &&
                   jd->num < 2500000.5) {
            UtcTime t;
            double fd;
            eraJd2cal(jd->num, 0.0, &t.year, &t.month, &t.day, &fd);
            t.hours = fd * 24.0;
            if (!any_time) t0 = t;
            any_time = true;
            o.time_h = hours_since(t0, t);
        } else if (jd && jd->type != JValue::kNull) {
            return ctx_.bad_record(n, "'julianDate' is neither an ISO 8601 UTC string nor a "
                                      "Julian date");
        }
        const JValue *tc = member(p, "temperature");
        if (tc && tc->type == JValue::kNumber && std::isfinite(tc->num)) o.temp_c = tc->num;
        const JValue *la = member(p, "latitude");
        if (la && la->type == JValue::kNumber) {
            if (!(std::fabs(la->num) <= 90))
                return ctx_.fail(la->line, "'latitude' %g is beyond +-90 deg, expected -90..+90",
                                 la->num);
            if (lat_line && std::fabs(la->num * kDeg - lat) > 1e-9)
                return ctx_.fail(la->line, "'latitude' %.9g differs from the %.9g of line %d, "
                                           "expected one site",
                                 la->num, lat / kDeg, lat_line);
            if (!lat_line) {
                lat = la->num * kDeg;
                lat_line = la->line;
            }
        }
        const JValue *a1 = member(p, "angularPosRA"), *a2 = member(p, "angularPosDEC");
        if (a1 && a2 && a1->type == JValue::kNumber && a2->type == JValue::kNumber &&
            std::isfinite(a1->num) && std::isfinite(a2->num)) {
            o.aux[0] = a1->num;
            o.aux[1] = a2->num;
            n_aux_ = 2;
        }
        if (ctx_.run()->obs.size() >= static_cast<size_t>(PMRUN_MAX_RECORDS))
            return ctx_.fail(n, "more than %d records, expected at most %d", PMRUN_MAX_RECORDS,
                             PMRUN_MAX_RECORDS);
        ctx_.run()->obs.push_back(o);
        return true;
    }

    Context &ctx_;
    std::string text_;
    int first_line_ = 0, last_line_ = 0;
    int n_aux_ = 0;
};

}  // namespace

std::unique_ptr<FormatParser> make_mw4_parser(Context &ctx)
{
    return std::unique_ptr<FormatParser>(new Mw4Parser(ctx));
}

}  // namespace pmrun_detail
