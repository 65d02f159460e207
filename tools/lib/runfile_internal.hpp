// runfile_internal.hpp - internals of the pointing-run reader (runfile.h).
// Shared by runfile.cpp (API, line reader, detection), runfile_columns.cpp
// (four-column and named formats), runfile_tpoint.cpp (TPOINT) and
// runfile_reduce.cpp (ERFA reduction).  Not installed, not a public API.
#ifndef PMRUN_RUNFILE_INTERNAL_HPP
#define PMRUN_RUNFILE_INTERNAL_HPP

#include "runfile.h"

#include <cstdarg>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

// The opaque run handed to C callers.
struct pmrun {
    std::vector<pmrun_obs> obs;
    int format = PMRUN_FORMAT_FOUR_COLUMN;
    int mount = PMRUN_MOUNT_EQUATORIAL;
    pmrun_site site{};
    std::vector<std::string> aux_names;
    std::vector<std::string> warnings;
    std::vector<std::string> skipped;
    int n_skipped = 0;
};

namespace pmrun_detail {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kHour = kPi / 12.0;

double nan();

// Encoder angles are modular (docs/formats.md, "Ranges"): an angle in
// degrees reduced into (-180, 180] exactly.  fmod is exact, and so is the
// one step of 360 after it (the operands are within a factor of two:
// Sterbenz), so two writings of one angle (194.16885990 and -165.83114010)
// give the same double to the rounding of their decimal text.
double reduce_deg(double v);
// The same into [0, 360) (azimuths).
double reduce_deg_positive(double v);

// Reading context: file name, options, messages and the run being built.
class Context {
public:
    Context(const char *path, const pmrun_options &opt, pmrun *run);

    const std::string &path() const { return path_; }
    const pmrun_options &opt() const { return opt_; }
    pmrun *run() { return run_; }

    // A fatal error at a line (line <= 0: no line).  Always returns false
    // so callers can write `return ctx.fail(...)`.
    bool fail(int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
    bool fail_with(int status, int line, const char *fmt, ...)
        __attribute__((format(printf, 4, 5)));
    // A note that does not stop the reading.
    void warn(int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
    // A bad record: with skip_bad, note it and return true (go on); else
    // fail and return false.
    bool bad_record(int line, const std::string &why);

    bool failed() const { return !error_.empty(); }
    const std::string &error() const { return error_; }
    int status() const { return status_; }
    void finish_messages();   // append the "N more not kept" notes

private:
    std::string where(int line) const;
    void add_warning(const std::string &msg);

    std::string path_;
    pmrun_options opt_;
    pmrun *run_;
    std::string error_;
    int status_ = PMRUN_OK;
    long warnings_dropped_ = 0;
};

std::string vformat(const char *fmt, va_list ap);
std::string format(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

// Whitespace tokens of a line (space, tab, CR, VT, FF).
std::vector<std::string> tokens(const std::string &s);
std::string trim(const std::string &s);
std::string lower(const std::string &s);
// The text with a trailing comment (from `c` preceded by whitespace or at
// the start) removed.
std::string strip_comment(const std::string &s, char c);
// Short printable excerpt of a token or line for messages.
std::string excerpt(const std::string &s, size_t max = 40);

// Strict decimal number: [+-]digits[.digits][e[+-]digits].  No NaN, Inf,
// hex or trailing garbage.  On failure `why` says what was wrong.
bool parse_number(const std::string &tok, double &v, std::string &why);
// Does the token look like a number (parse_number would accept it)?
bool is_number(const std::string &tok);

// A parser of one format: fed line by line, then finished.
class FormatParser {
public:
    virtual ~FormatParser() = default;
    // A line (without its line end).  Returns false after ctx.fail.
    virtual bool line(int number, const std::string &text) = 0;
    // A line that could not be read (too long, NUL bytes).  Returns false
    // after ctx.fail.
    virtual bool unreadable(int number, const std::string &why) = 0;
    // End of file (last line number).  Returns false after ctx.fail.
    virtual bool finish(int last_line) = 0;
};

std::unique_ptr<FormatParser> make_column_parser(Context &ctx);  // four-column, named
std::unique_ptr<FormatParser> make_tpoint_parser(Context &ctx);

// Weather for the refraction (eraRefco arguments).
struct Weather {
    double pressure_hpa, temp_c, humidity, wavelength_um;
};

// The ERFA reduction of one catalogue place (J2000 mean place, radians)
// to observed hour angle / declination at the given UTC instant (date at
// 0h + utc_h hours) and local sidereal time.  `weather` NULL: no
// refraction.  Returns false with `why` if ERFA rejects the date.
struct Reduction {
    bool setup(int year, int month, int day, double latitude_rad,
               const Weather *weather, std::string &why);
    bool observed(double ra, double dec, double lst, double utc_h, double &ha,
                  double &dec_obs, std::string &why) const;

    double utc1 = 0, utc2 = 0;        // UTC quasi-JD of the date at 0h
    double latitude = 0;
    bool refract = false;
    bool dubious = false;             // outside ERFA's leap-second table
    double refa = 0, refb = 0;
};

// Standard-atmosphere pressure (hPa) at height h (m).
double standard_pressure_hpa(double height_m);

}  // namespace pmrun_detail

#endif
