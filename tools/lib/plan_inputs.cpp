// plan_inputs.cpp - horizon files and star catalogues for pmfit plan
// (plan_inputs.hpp).
#include "plan_inputs.hpp"

#include <erfa.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pmhost {

namespace {

const double D2R = 3.14159265358979323846 / 180;

[[noreturn]] void fail(const std::string &path, int line, const std::string &what)
{
    throw std::runtime_error(path + (line > 0 ? ":" + std::to_string(line) : std::string()) +
                             ": " + what);
}

std::string excerpt(const std::string &s)
{
    std::string t = s.size() > 60 ? s.substr(0, 57) + "..." : s;
    return "'" + t + "'";
}

std::vector<std::string> lines_of(const std::string &path, const char *what)
{
    std::ifstream in(path);
    if (!in)
        throw std::runtime_error(path + ": cannot open the " + what);
    std::vector<std::string> out;
    std::string s;
    while (std::getline(in, s)) {
        if (!s.empty() && s.back() == '\r')
            s.pop_back();
        if (out.empty() && s.size() >= 3 && (unsigned char)s[0] == 0xEF &&
            (unsigned char)s[1] == 0xBB && (unsigned char)s[2] == 0xBF)
            s = s.substr(3); // a UTF-8 byte-order mark (spreadsheet exports)
        out.push_back(s);
    }
    return out;
}

// Fields separated by spaces, tabs, commas or semicolons; a '#' starts a
// comment.
std::vector<std::string> fields(std::string s)
{
    size_t h = s.find('#');
    if (h != std::string::npos)
        s.erase(h);
    for (char &c : s)
        if (c == ',' || c == ';' || c == '\t')
            c = ' ';
    std::istringstream is(s);
    std::vector<std::string> out;
    std::string t;
    while (is >> t)
        out.push_back(t);
    return out;
}

bool decimal(const std::string &t, double &v)
{
    if (t.empty())
        return false;
    char *end = nullptr;
    v = std::strtod(t.c_str(), &end);
    return *end == '\0' && std::isfinite(v);
}

// A decimal or sexagesimal value: "12.5", "12:30:00", "12h30m00s",
// "-05d30m", "-05:30" (the sign applies to the whole).  units: the letters
// that may separate the parts ("hms" or "dms").
bool sexagesimal(const std::string &tok, const char *units, double &v)
{
    if (decimal(tok, v))
        return true;
    std::string t = tok;
    double sign = 1;
    if (!t.empty() && (t[0] == '-' || t[0] == '+')) {
        sign = t[0] == '-' ? -1 : 1;
        t = t.substr(1);
    }
    // the separators: ':' or the unit letters (and degree/minute/second marks)
    std::string norm;
    for (size_t i = 0; i < t.size(); i++) {
        char c = (char)std::tolower((unsigned char)t[i]);
        if (c == ':' || c == units[0] || c == units[1] || c == units[2] || c == '\'' || c == '"')
            norm += ' ';
        else if ((unsigned char)t[i] == 0xC2 && i + 1 < t.size() && (unsigned char)t[i + 1] == 0xB0)
            norm += ' ', i++; // the degree sign in UTF-8
        else if (std::isdigit((unsigned char)c) || c == '.')
            norm += c;
        else
            return false;
    }
    std::istringstream is(norm);
    std::vector<std::string> parts;
    std::string p;
    while (is >> p)
        parts.push_back(p);
    if (parts.size() < 2 || parts.size() > 3)
        return false;
    double a[3] = {0, 0, 0};
    for (size_t i = 0; i < parts.size(); i++)
        if (!decimal(parts[i], a[i]) || a[i] < 0)
            return false;
    if (a[1] >= 60 || a[2] >= 60 || (parts.size() == 3 && a[1] != std::floor(a[1])))
        return false;
    v = sign * (a[0] + a[1] / 60 + a[2] / 3600);
    return true;
}

const char *kHorizonFormats =
    "expected 'azimuth elevation' in degrees (azimuth from north through east; separated by "
    "spaces, tabs or commas; '#' comments) as in N.I.N.A./Astro-Physics .hrz and Cartes du Ciel "
    "files, or MountWizzard4's .hpts JSON [[elevation, azimuth], ...]";

void add_point(Horizon &h, int line, double az, double el)
{
    if (!(az >= 0 && az <= 360))
        fail(h.path, line, "azimuth " + std::to_string(az) + " is outside 0..360 deg");
    if (!(el >= -10 && el <= 90))
        fail(h.path, line, "horizon elevation " + std::to_string(el) +
                               " is outside -10..90 deg");
    h.pts.push_back({az == 360 ? 0.0 : az, el});
}

// MountWizzard4's .hpts: a JSON list of [elevation, azimuth] pairs.
void read_hpts(Horizon &h, const std::vector<std::string> &lines)
{
    std::string all;
    std::vector<int> line_at; // the line of each character
    for (size_t i = 0; i < lines.size(); i++) {
        all += lines[i] + "\n";
        line_at.insert(line_at.end(), lines[i].size() + 1, (int)i + 1);
    }
    size_t i = 0;
    auto skip = [&]() {
        while (i < all.size() && std::isspace((unsigned char)all[i]))
            i++;
    };
    auto line = [&]() { return i < line_at.size() ? line_at[i] : (int)lines.size(); };
    auto expect = [&](char c) {
        skip();
        if (i >= all.size() || all[i] != c)
            fail(h.path, line(), std::string("malformed .hpts (JSON list of [elevation, "
                                             "azimuth] pairs): expected '") + c + "'");
        i++;
    };
    auto number = [&]() {
        skip();
        const char *s = all.c_str() + i;
        char *end = nullptr;
        double v = std::strtod(s, &end);
        if (end == s || !std::isfinite(v))
            fail(h.path, line(), "malformed .hpts (JSON list of [elevation, azimuth] pairs): "
                                 "expected a number");
        i += (size_t)(end - s);
        return v;
    };
    expect('[');
    skip();
    if (i < all.size() && all[i] == ']') {
        i++;
    } else {
        for (;;) {
            int at = (skip(), line());
            expect('[');
            double el = number();
            expect(',');
            double az = number();
            expect(']');
            add_point(h, at, az, el);
            skip();
            if (i < all.size() && all[i] == ',') {
                i++;
                continue;
            }
            expect(']');
            break;
        }
    }
    skip();
    if (i < all.size())
        fail(h.path, line(), "unexpected text after the .hpts list");
}

} // namespace

double Horizon::at(double az_deg) const
{
    if (pts.empty())
        return -90;
    if (pts.size() == 1)
        return pts[0].second;
    double a = std::fmod(az_deg, 360.0);
    if (a < 0)
        a += 360;
    // the bracketing points, periodic in azimuth
    size_t n = pts.size(), k = 0;
    while (k < n && pts[k].first <= a)
        k++;
    const std::pair<double, double> &hi = k < n ? pts[k] : pts[0];
    const std::pair<double, double> &lo = k > 0 ? pts[k - 1] : pts[n - 1];
    double x0 = lo.first, x1 = hi.first;
    if (k == 0)
        x0 -= 360;
    if (k == n)
        x1 += 360;
    if (!(x1 > x0))
        return std::max(lo.second, hi.second);
    double f = (a - x0) / (x1 - x0);
    return lo.second + f * (hi.second - lo.second);
}

Horizon read_horizon(const std::string &path)
{
    Horizon h;
    h.path = path;
    std::vector<std::string> lines = lines_of(path, "horizon file");
    size_t first = 0;
    while (first < lines.size() && fields(lines[first]).empty() &&
           lines[first].find('[') == std::string::npos)
        first++;
    if (first < lines.size() && lines[first].find_first_not_of(" \t") != std::string::npos &&
        lines[first][lines[first].find_first_not_of(" \t")] == '[') {
        read_hpts(h, lines);
    } else {
        bool el_first = false, header_seen = false, data_seen = false;
        for (size_t i = 0; i < lines.size(); i++) {
            std::vector<std::string> f = fields(lines[i]);
            if (f.empty())
                continue;
            double a, b;
            bool num = f.size() == 2 && decimal(f[0], a) && decimal(f[1], b);
            if (!num && !header_seen && !data_seen && f.size() == 2) {
                // a header line naming the columns
                std::string c0 = f[0], c1 = f[1];
                for (char &c : c0)
                    c = (char)std::tolower((unsigned char)c);
                for (char &c : c1)
                    c = (char)std::tolower((unsigned char)c);
                bool az0 = c0.rfind("az", 0) == 0, az1 = c1.rfind("az", 0) == 0;
                bool el0 = c0.rfind("alt", 0) == 0 || c0.rfind("el", 0) == 0;
                bool el1 = c1.rfind("alt", 0) == 0 || c1.rfind("el", 0) == 0;
                if ((az0 && el1) || (el0 && az1)) {
                    el_first = el0;
                    header_seen = true;
                    continue;
                }
            }
            if (!num)
                fail(path, (int)i + 1, std::string(kHorizonFormats) + "; got " +
                                           excerpt(lines[i]));
            data_seen = true;
            add_point(h, (int)i + 1, el_first ? b : a, el_first ? a : b);
        }
    }
    if (h.pts.empty())
        fail(path, 0, std::string("no horizon points: ") + kHorizonFormats);
    std::stable_sort(h.pts.begin(), h.pts.end(),
                     [](const std::pair<double, double> &x, const std::pair<double, double> &y) {
                         return x.first < y.first;
                     });
    return h;
}

std::vector<CatalogueStar> read_catalogue(const std::string &path)
{
    std::vector<std::string> lines = lines_of(path, "star catalogue");
    std::vector<CatalogueStar> out;
    for (size_t i = 0; i < lines.size(); i++) {
        std::vector<std::string> f = fields(lines[i]);
        if (f.empty())
            continue;
        CatalogueStar s;
        s.line = (int)i + 1;
        double ra, dec;
        size_t n = f.size();
        bool front = n >= 2 && sexagesimal(f[0], "hms", ra) && sexagesimal(f[1], "dms", dec);
        bool back = !front && n >= 3 && sexagesimal(f[n - 2], "hms", ra) &&
                    sexagesimal(f[n - 1], "dms", dec);
        if (!front && !back)
            fail(path, s.line, "expected 'RA Dec [name]' or 'name RA Dec' (RA in hours, decimal "
                               "or h:m:s; Dec in degrees, decimal or d:m:s); got " +
                                   excerpt(lines[i]));
        if (!(ra >= 0 && ra < 24))
            fail(path, s.line, "RA " + f[front ? 0 : n - 2] +
                                   " is outside 0..24 h (RA is in hours, not degrees)");
        if (!(dec >= -90 && dec <= 90))
            fail(path, s.line, "Dec " + f[front ? 1 : n - 1] + " is outside -90..90 deg");
        for (size_t k = front ? 2 : 0; k < (front ? n : n - 2); k++)
            s.name += (s.name.empty() ? "" : " ") + f[k];
        if (s.name.empty())
            s.name = "line " + std::to_string(s.line);
        s.ra_h = ra;
        s.dec_deg = dec;
        out.push_back(s);
    }
    if (out.empty())
        fail(path, 0, "the catalogue has no stars (one a line: 'RA Dec [name]')");
    return out;
}

namespace {

// The UTC of a SkyTime as an ERFA two-part quasi-JD; false if unparsable.
bool utc_jd(const std::string &s, double &u1, double &u2)
{
    int y, mo, d, h = 0, mi = 0, used = -1;
    double sec = 0;
    if (std::sscanf(s.c_str(), "%d-%d-%d%*[T ]%d:%d%n", &y, &mo, &d, &h, &mi, &used) != 5 ||
        used < 0)
        return false;
    const char *rest = s.c_str() + used;
    if (*rest == ':') { // seconds, then nothing ("04:00x" was taken as 04:00)
        int more = -1;
        if (std::sscanf(rest + 1, "%lf%n", &sec, &more) != 1 || more < 0 || rest[1 + more])
            return false;
    } else if (*rest) {
        return false;
    }
    if (h < 0 || h > 23 || mi < 0 || mi > 59 || !(sec >= 0 && sec < 61))
        return false;
    return eraDtf2d("UTC", y, mo, d, h, mi, sec, &u1, &u2) >= 0;
}

} // namespace

void check_sky_time(const SkyTime &t)
{
    double u1, u2;
    if (!t.utc.empty() && !utc_jd(t.utc, u1, u2))
        throw std::runtime_error("--utc: expected YYYY-MM-DDTHH:MM[:SS] (UTC), got '" + t.utc +
                                 "'");
    if (t.utc.empty() && !(t.lst_h >= 0 && t.lst_h < 24))
        throw std::runtime_error("a star catalogue needs the time: --lst HOURS (local sidereal "
                                 "time) or --utc YYYY-MM-DDTHH:MM with --lon DEG");
}

void place_star(const CatalogueStar &s, const SkyTime &t, double &ha_deg, double &dec_deg)
{
    check_sky_time(t);
    if (t.utc.empty()) {
        double h = std::remainder((t.lst_h - s.ra_h) * 15, 360.0);
        ha_deg = h;
        dec_deg = s.dec_deg;
        return;
    }
    double u1, u2, aob, zob, hob, dob, rob, eo;
    utc_jd(t.utc, u1, u2);
    // ICRS to observed: no proper motion, parallax; UT1 = UTC, no polar
    // motion; pressure 0 (no refraction: the model's own terms hold it)
    if (eraAtco13(s.ra_h * 15 * D2R, s.dec_deg * D2R, 0, 0, 0, 0, u1, u2, 0, t.lon_rad, t.lat_rad,
                  0, 0, 0, 0, 10, 0.5, 0.55, &aob, &zob, &hob, &dob, &rob, &eo) < 0)
        throw std::runtime_error("--utc: ERFA rejected the date '" + t.utc + "'");
    ha_deg = std::remainder(hob / D2R, 360.0);
    dec_deg = dob / D2R;
}

} // namespace pmhost
