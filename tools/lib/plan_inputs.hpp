// plan_inputs.hpp - the files pmfit plan reads besides a run: an
// azimuth-dependent horizon and a star catalogue of candidate targets, and
// placing catalogue stars on the sky at a given time.  Formats in
// docs/formats.md ("Horizon files", "Star catalogues for pmfit plan").
// Errors are std::runtime_error naming the file and line.
#ifndef PM_PLAN_INPUTS_HPP
#define PM_PLAN_INPUTS_HPP

#include <string>
#include <utility>
#include <vector>

namespace pmhost {

// A horizon: the lowest usable elevation as a function of azimuth (degrees,
// azimuth from north through east), linear between the given points and
// periodic in azimuth.  Empty: no horizon (elevation limit only).
struct Horizon {
    std::string path;
    std::vector<std::pair<double, double>> pts; // (azimuth, elevation), azimuth ascending
    bool empty() const { return pts.empty(); }
    double at(double az_deg) const;             // the horizon's elevation there
};

// Read a horizon file: text with one "azimuth elevation" pair a line
// (N.I.N.A. and Astro-Physics .hrz, Cartes du Ciel, comma-, tab- or
// space-separated; '#' comments; an optional header line naming the columns,
// "alt,az" for the reverse order of MountWizzard4's CSV), or MountWizzard4's
// .hpts (JSON [[elevation, azimuth], ...]).
Horizon read_horizon(const std::string &path);

// A catalogue star: right ascension (hours) and declination (degrees), as
// given (J2000 mean place, or of date), and its name.
struct CatalogueStar {
    std::string name;
    double ra_h = 0, dec_deg = 0;
    int line = 0;
};

// Read a star catalogue: one star a line, "RA Dec [name]" or "name RA Dec"
// (RA in hours, decimal or h:m:s; Dec in degrees, decimal or d:m:s;
// separated by spaces, tabs or commas; '#' comments).  An empty catalogue
// is an error.
std::vector<CatalogueStar> read_catalogue(const std::string &path);

// Where a catalogue star is at a given time: its hour angle and declination
// (degrees).  Either lst_h (local sidereal time, hours; the catalogue taken
// as coordinates of date) or utc ("YYYY-MM-DDTHH:MM[:SS]") with the site's
// east longitude and latitude (radians): then the J2000 place is reduced to
// the observed hour angle and declination with ERFA (precession, nutation,
// aberration; no refraction).
struct SkyTime {
    double lst_h = -1;     // >= 0: use it
    std::string utc;       // non-empty: use it (with lon, lat)
    double lon_rad = 0, lat_rad = 0;
};
void place_star(const CatalogueStar &s, const SkyTime &t, double &ha_deg, double &dec_deg);

// Check a SkyTime (a parsable UTC) before use; throws with the reason.
void check_sky_time(const SkyTime &t);

} // namespace pmhost

#endif
