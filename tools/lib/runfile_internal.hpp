// runfile_internal.hpp - internals of the pointing-run reader (runfile.h).
// Shared by runfile.cpp (API, line reader, detection), runfile_columns.cpp
// (four-column and named formats), runfile_tpoint.cpp (TPOINT),
// runfile_reduce.cpp (ERFA reduction), runfile_rts2.cpp, runfile_mw4.cpp,
// runfile_csv.cpp, runfile_mmt.cpp (the other formats) and runfile_util.cpp
// (their shared helpers).  Not installed, not a public API.
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
    bool weather_used = false; // a reduction refracted with the weather
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

    // The format a reader tries, named in its errors: "path:LINE: read as
    // <what>: ..." (empty: no prefix, the original three formats' messages).
    void set_reading_as(const std::string &what) { reading_as_ = what; }
    const std::string &reading_as() const { return reading_as_; }

    bool failed() const { return !error_.empty(); }
    const std::string &error() const { return error_; }
    int status() const { return status_; }
    void finish_messages();   // append the "N more not kept" notes

private:
    std::string where(int line) const;
    void add_warning(const std::string &msg);

    std::string path_;
    std::string reading_as_;
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
// Excel's optional first line of a CSV file, 'sep=;' (trimmed): 'sep=' and
// whatever follows.
bool excel_sep_line(const std::string &t);
// The text with a trailing comment (from `c` preceded by whitespace or at
// the start) removed.
std::string strip_comment(const std::string &s, char c);
// Short printable excerpt of a token or line for messages.
std::string excerpt(const std::string &s, size_t max = 40);

// Strict decimal number: [+-]digits[.digits][e[+-]digits].  No NaN, Inf,
// hex or trailing garbage.  On failure `why` says what was wrong.
bool parse_number(const std::string &tok, double &v, std::string &why);
// A token of digits with one decimal comma ('10,165', a European locale's
// writing): true, with why saying so.
bool decimal_comma(const std::string &s, std::string &why);
// An angle in a file (degrees or hours) may be written in any turn, but not
// beyond +-kMaxAngle = 2^31: fmod reduces 1e300 exactly, to a direction the
// file never gave (an outside probe's run read it silently).  Below 2^31 a
// double's spacing is at most 2.4e-7 (0.001" in degrees), and no mount
// counts millions of turns.  On failure `why` says so.  parse_angle:
// parse_number and this.
const double kMaxAngle = 2147483648.0;
bool angle_in_range(double v, std::string &why);
bool parse_angle(const std::string &tok, double &v, std::string &why);
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
std::unique_ptr<FormatParser> make_rts2_parser(Context &ctx);
std::unique_ptr<FormatParser> make_mw4_parser(Context &ctx);
std::unique_ptr<FormatParser> make_csv_parser(Context &ctx);
std::unique_ptr<FormatParser> make_mmt_parser(Context &ctx);
// The parser of a format id (PMRUN_FORMAT_*), nullptr for another value.
std::unique_ptr<FormatParser> make_parser(Context &ctx, int format);
// A description of each format for messages ("an RTS2 gpoint input file").
const char *format_description(int format);
// false (the error set in ctx) where an equinox is asked for (pmrun_options.equinox)
// and the format has no places it applies to: refused, not ignored.
bool equinox_applies(Context &ctx, int format);

// Weather for the refraction (eraRefco arguments).
struct Weather {
    double pressure_hpa, temp_c, humidity, wavelength_um;
};

// The ERFA reduction of one catalogue place (J2000 mean place, radians)
// to observed hour angle / declination at the given UTC instant (date at
// 0h + utc_h hours) and local sidereal time.  `weather` NULL: no
// refraction.  latitude_rad NaN: unknown (no refraction then, and no
// diurnal aberration); height_m NaN: 0.  Returns false with `why` if ERFA
// rejects the date.
struct Reduction {
    bool setup(int year, int month, int day, double latitude_rad, double height_m,
               const Weather *weather, std::string &why);
    // The observed place: apparent, diurnal aberration (topocentric), then
    // refraction if used.
    bool observed(double ra, double dec, double lst, double utc_h, double &ha,
                  double &dec_obs, std::string &why) const;
    // Diurnal aberration of an apparent (geocentric) HA/Dec, in place:
    // toward the east point by diurab (0.32" cos(latitude) at sea level),
    // as eraAtioq applies it; nothing where the latitude is unknown.
    void topocentric(double &ha, double &dec) const;
    // The same without refraction (the apparent place of date), whatever
    // `refract` says.
    bool apparent(double ra, double dec, double lst, double utc_h, double &ha,
                  double &dec_app, std::string &why) const;
    // Refraction of an apparent (unrefracted) HA/Dec, in place (the same
    // model and guards as observed()); nothing if !refract.
    void refract_place(double &ha, double &dec) const;

    double utc1 = 0, utc2 = 0;        // UTC quasi-JD of the date at 0h
    double latitude = 0;
    bool refract = false;
    bool dubious = false;             // outside ERFA's leap-second table
    double refa = 0, refb = 0;
    double diurab = 0;                // diurnal aberration (radians)
};

// Standard-atmosphere pressure (hPa) at height h (m).
double standard_pressure_hpa(double height_m);

// ---- helpers of the RTS2, MW4, CSV and MMT readers (runfile_util.cpp)

// A sexagesimal or decimal angle: "12.5", "-0:30:00", "12 34 56.7",
// "12h34m56.7s", "+45d30m00s", "+45°30'00\"" (the unit letters and marks
// optional, ':' or spaces between parts).  Only the first part has a sign,
// only the last a fraction, minutes and seconds below 60.  `value` is in
// the first part's unit (hours or degrees).  On failure `why` says what.
bool parse_sexagesimal(const std::string &text, double &value, std::string &why);

// A UTC time in ISO 8601: "YYYY-MM-DD[T| ]hh:mm[:ss[.fff]][Z|+hh:mm|-hh:mm]"
// (no zone: UTC).  Returns the calendar date of the UTC day and the hours
// since its 0h (the zone offset applied).
struct UtcTime {
    int year = 0, month = 0, day = 0;
    double hours = 0;
    bool zoned = false; // the text gave its zone (Z or an offset)
};
bool parse_iso_utc(const std::string &text, UtcTime &t, std::string &why);
// Hours from 0h UTC of `ref`'s date to `t` (whole days counted).
double hours_since(const UtcTime &ref, const UtcTime &t);
// Local apparent sidereal time (radians, [0, 2pi)) at UTC `date` + `hours`
// and east longitude `lon` (radians), UT1 taken as UTC (docs/formats.md:
// a DUT1 below 0.9 s is a constant HA offset, the index term's).
bool lst_from_utc(int year, int month, int day, double hours, double lon, double &lst,
                  std::string &why);

// The weather for refraction from the site (NaN: absent) and the options'
// overrides, with defaults from the standard atmosphere at the height (one
// warning naming what was defaulted) and errors for absurd values, as the
// TPOINT run line's (docs/formats.md, "Weather").  `what` names the source
// in messages ("metadata", "the MW4 points").  False after ctx.fail.
bool refraction_weather(Context &ctx, int line, const char *what, Weather &out);

// A sky place of a German mount's pointing (HA, Dec within +-90, degrees)
// and its pier side to the encoder convention of this reader (docs/
// formats.md, "Beyond the pole"): pier -1 (beyond the pole) gives
// (HA + 180, 180 - Dec); both reduced into (-180, 180].
void sky_to_encoder_deg(double ha_deg, double dec_deg, int pier, double &enc_ha_deg,
                        double &enc_dec_deg);

// A blank observation: angles 0, pier unknown, temp/time NaN, aux NaN.
pmrun_obs blank_obs(int line);

}  // namespace pmrun_detail

#endif
