// pmfit - fit a pointing model to a recorded pointing run and report it.
//
//   pmfit fit RUN [--order L] [--pier joint|split] [--json] [--residuals FILE]
//                 [--save MODEL] [--emit-c HEADER] [--no-refraction] [--skip-bad]
//                 [--robust [--clip K]] [--tpoint-terms FILE] [--format NAME]
//                 [--equinox J2000|JNow]
//   pmfit explain RUN [--order L] [--add EFFECT ...] [--json] [--plots DIR] [--alpha P]
//                 [--robust [--clip K]]
//   pmfit eval MODEL RUN [--json] [--residuals FILE] [--no-refraction] [--skip-bad]
//   pmfit report RUN -o PAGE.html [--order L] [--add EFFECT ...] [--compare OLD] [--next K]
//                 [--alpha P] [--gear [ha:|dec:|az:|el:]G ...] [--quiet | --progress]
//   pmfit simulate OUT [--n N] [--seed S] [--lat DEG] [--mount equatorial|altaz]
//                 [--fork] [--el-limit DEG] [--noise ARCSEC] [--order L]
//                 [--term NAME=ARCSEC ...] [--random-aniso ARCSEC]
//
// Host-side program: uses the freestanding core (include/pm.h) and the run
// reader (tools/lib/runfile.h).  Angles in the reports are arcseconds.
#include "pm.h"
#include "runfile.h"
#include "modelfile.h"
#include "simulate.h"
#include "inject.hpp"
#include "errormap.hpp"
#include "compare.hpp"
#include "plan.hpp"
#include "hostutil.hpp"
#include "fitrun.hpp"
#include "explain.hpp"
#include "plots.hpp"
#include "robust.hpp"
#include "report.hpp"
#include "tpointterms.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <optional>
#include <string>
#include <vector>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sys/stat.h>
#include <unistd.h>
#include <stdexcept>

namespace {

using namespace pmhost;

// Gauss-Newton passes pmfit fit allows: nearly degenerate term sets (one
// pier side at L=2) creep along a flat valley for a thousand passes; each
// pass is cheap, and a warning names the pair (print_table).
const int MAX_PASSES = FIT_MAX_PASSES;

struct Options {
    std::string cmd, run, model; // model: eval's MODEL
    int order = 1;
    bool split = false;
    bool json = false;
    bool refraction = true;
    bool skip_bad = false;
    std::string residuals, save, emit_c;
    std::vector<std::string> adds; // fit, explain: --add EFFECT
    std::string plots;             // explain: --plots DIR
    double alpha = 0.01;           // explain: --alpha
    std::vector<double> gears_ha, gears_dec; // explain: --gear [ha:|dec:]G
    bool gears_altaz_names = false;          // az:G or el:G given (an alt-az mount's)
    bool compose = true;           // explain: the baseline composed as a gimbal (--no-compose: not)
    bool robust = false;           // fit, explain: --robust (docs/robust.md)
    double clip = ROBUST_DEFAULT_CLIP; // --clip K
    bool clip_given = false;
    // simulate
    long n = 200;
    unsigned long long seed = 1;
    double lat = 47, el_limit = 15, noise = 1, random_aniso = 0;
    bool altaz = false, fork = false;
    std::vector<std::pair<std::string, double>> terms;
    std::vector<std::pair<std::string, double>> effects; // simulate --effect SPEC=ARCSEC
    double phase_deg = 0;
    std::string error_map;           // fit --error-map FILE.svg
    int next = 5;                    // plan --next K
    double min_el = 15, grid = 6;    // plan --min-el, --grid
    double max_el = NAN;             // plan --max-el (NaN: the mount's)
    std::string horizon, catalogue;  // plan --horizon FILE, --catalog FILE
    double lst = -1, lon = NAN;      // plan --lst HOURS, --lon DEG (with --utc)
    std::string utc;                 // plan --utc YYYY-MM-DDTHH:MM[:SS]
    bool d_optimal = false;          // plan --criterion D
    double slew_rate = 0, settle = 5, point_time = 30, flip_time = 60; // plan --slew ...
    std::string sides = "run";       // plan --sides run|meridian|both
    double meridian_limit = 15;      // plan --meridian-limit DEG
    bool min_el_given = false, lat_given = false, noise_given = false, mount_given = false;
    std::vector<std::string> inject; // simulate --inject EFFECT[=SIZE] --into RUN
    std::string into;
    std::string shape_opt;           // a simulate option that shapes a simulated run
    std::string output, compare;     // report: -o PAGE.html, --compare OLD
    bool quiet = false;              // report: no progress on stderr
    bool report_fork = false;        // report: plan a mount that does not flip (--fork)
    bool progress = false;           // report: a line per stage on stderr, always
    // --no-refraction, --skip-bad, --format NAME (docs/formats.md),
    // --equinox J2000|JNow, --azimuth-count, --pressure HPA, ...
    ReadOptions read;
    std::string tpoint_terms;        // fit --tpoint-terms FILE
    bool order_given = false;        // --order on the command line
};

void usage(FILE *f)
{
    std::fprintf(f,
        "usage: pmfit fit RUN [--order L] [--pier joint|split] [--add EFFECT ...] [--json]\n"
        "                     [--residuals FILE] [--save MODEL] [--emit-c HEADER]\n"
        "                     [--error-map F] [--tpoint-terms FILE] [--no-refraction]\n"
        "                     [--skip-bad] [--robust [--clip K]] [--format NAME]\n"
        "                     [--equinox J2000|JNow] [--azimuth-count] [--pressure HPA]\n"
        "                     [--temperature C] [--humidity H] [--wavelength UM]\n"
        "\n"
        "  RUN              pointing run: four-column, named-column, TPOINT, RTS2 gpoint,\n"
        "                   MountWizzard4 JSON, CSV log or MMT log (docs/formats.md)\n"
        "  --order L        spherical-harmonic order, 0..%d (default 1, the paper's L=1)\n"
        "  --pier split     fit each pier side separately (default: joint)\n"
        "  --json           one JSON object on standard output\n"
        "  --residuals F    write per-observation residuals (arcsec) to F\n"
        "  --add EFFECT     add physical terms (repeatable; docs/model.md):\n"
        "                     ha_periodic:G[:H]   periodic error of G cycles/rev on the HA\n"
        "                                         axis, harmonics 1..H (default 1)\n"
        "                     dec_periodic:G[:H]  the same on the Dec axis\n"
        "                     az_periodic:G[:H], el_periodic:G[:H]   the same on an alt-az\n"
        "                                         mount's azimuth and elevation axes\n"
        "                     ha_periodic_paper:G the paper's Y(G,+-G) form, for comparison\n"
        "                     refraction          cot(elevation) toward the zenith\n"
        "                     tube_flexure        cos(elevation) toward the zenith\n"
        "                     temperature[:B,..]  (temp - mean) on base vectors B (default c',e')\n"
        "                     time_drift[:B,..]   (time - mean), default c',e'\n"
        "                     hysteresis[:B,..]   last slew direction (+-1), default c'\n"
        "                     aux:NAME[:B,..]     any named column, default c',e'\n"
        "                     TERM@E or TERM@W    a term for one pier side only, e.g. i@W,\n"
        "                                         c'*Y(1,0)@E, refraction@W (joint fit +\n"
        "                                         F-test: do the sides really differ?)\n"
        "  --save MODEL     write the fitted model as a text model file (docs/formats.md);\n"
        "                   with --pier split: MODEL-east and MODEL-west\n"
        "  --emit-c HEADER  write the model as C constant data with a loader, for firmware\n"
        "  --error-map F    write the predicted pointing error of the model over the sky\n"
        "                   (1 sigma, from the fit's covariance) as an SVG map; with\n"
        "                   --pier split: F-east and F-west (docs/model.md)\n"
"  --tpoint-terms F write the fitted model as a TPOINT-style term list (IH ID NP CH\n"
        "                   MA ME, alt-az IA IE CA NPAE AN AW; TF TX when added; the\n"
        "                   other terms listed apart) to F;\n"
        "                   with --pier split: F-east and F-west (docs/formats.md)\n"
        "  --no-refraction  leave refraction out of the reductions (TPOINT, CSV, RTS2)\n"
        "  --skip-bad       skip malformed records (each is reported) instead of failing\n"
        "  --format NAME    read RUN as this format, not the detected one: four-column,\n"
        "                   named, tpoint, rts2, mw4, csv, mmt (every command reading a run)\n"
        "  --equinox E      J2000 or JNow: the equinox of a CSV log's or an RTS2 file's\n"
        "                   RA/Dec places, over what the file says (docs/formats.md);\n"
        "                   an error for formats it does not apply to (TPOINT, columns, MMT)\n"
        "  --azimuth-count  an alt-az file's azimuth is the mount's count, even within\n"
        "                   0..360 deg: the slew direction is its change (the mount never\n"
        "                   turns through the file's seam; explain offers it where it fits\n"
        "                   far better; docs/explain.md)\n"
        "  --pressure HPA (400..1100), --temperature C (-60..50), --humidity H (0..1),\n"
        "  --wavelength UM (0.3..25)\n"
        "                   the weather of the refraction where a reduction refracts\n"
        "                   (TPOINT equatorial, J2000 places of CSV and RTS2 files), over\n"
        "                   the file's or the defaults (an RTS2 file has none; every command\n"
        "                   reading a run)\n"
        "  --robust         ignore gross outliers (failed plate solves): clip points whose\n"
        "                   residual on the sky exceeds K robust sigmas, refit, repeat until\n"
        "                   stable; the report lists them by line (docs/robust.md)\n"
        "  --clip K         the threshold K (default %.2f: a clean point is rejected with\n"
        "                   probability 1e-4)\n"
        "\n"
        "usage: pmfit explain RUN [--order L] [--add EFFECT ...] [--json] [--plots DIR]\n"
        "                     [--alpha P] [--gear [ha:|dec:|az:|el:]G ...] [--no-refraction]\n"
        "                     [--skip-bad] [--robust [--clip K]] [--no-compose]\n"
        "\n"
        "  fits the baseline model (order L, default 1, plus --add terms), locates where the\n"
        "  residuals are too large, names the physics left out (ha_periodic, dec_periodic,\n"
        "  pier_side, refraction, tube_flexure, temperature, time_drift, hysteresis,\n"
        "  higher_order, outlier), adds it and repeats while the false-alarm probability is\n"
        "  below P (default 0.01) and the leave-one-out RMS improves (docs/explain.md);\n"
        "  --plots DIR writes SVG pictures: residuals on the sky before/after, residual vs the\n"
        "  located variable, periodograms, sigma per step; --robust: explain the points a\n"
        "  robust fit of the baseline keeps (the rejected ones are listed); --gear G: a known\n"
        "  gear period (cycles per revolution, e.g. the worm's tooth count; ha:G or dec:G for\n"
        "  one axis, az:G or el:G on an alt-az mount; repeatable): the periodic search looks\n"
        "  at the given periods only, so a smaller periodic error is significant\n"
        "  (docs/explain.md); the baseline's anisotropic terms are read as the mount's gimbal\n"
        "  composes them, their second-order part taken out before the search where that fits\n"
        "  better (--no-compose: to first order), and read again with the terms the search\n"
        "  found; its fits run on as many threads as the machine has (at most 8; environment\n"
        "  PMFIT_THREADS=N for N, the results the same)\n"
        "\n"
        "usage: pmfit eval MODEL RUN [--json] [--residuals FILE] [--no-refraction] [--skip-bad]\n"
        "\n"
        "  applies a saved model (pmfit fit --save) to a run without refitting: how well\n"
        "  does last night's model point tonight?\n"
        "\n"
        "usage: pmfit plan [RUN] [--next K] [--order L] [--add EFFECT ...] [--lat DEG]\n"
        "                  [--mount equatorial|altaz] [--fork] [--min-el DEG] [--max-el DEG]\n"
        "                  [--grid DEG]\n"
        "                  [--noise ARCSEC] [--json] [--horizon FILE] [--criterion I|D]\n"
        "                  [--catalog FILE (--lst HOURS | --utc YYYY-MM-DDTHH:MM --lon DEG)]\n"
        "                  [--sides run|meridian|both] [--meridian-limit DEG]\n"
        "                  [--slew DEG_PER_S [--settle S] [--point-time S] [--flip-time S]]\n"
        "\n"
        "  which star next: the K targets (default 5) that most reduce the model's predicted\n"
        "  pointing error averaged over the sky above --min-el (default 15 deg), given the\n"
        "  points of RUN taken so far (none: the first points of a run); candidates on a grid\n"
        "  of --grid deg (6); a German mount takes each on the side the run used nearby;\n"
        "  --max-el: the highest place (default: alt-az 85 deg, the zenith keyhole; 90)\n"
        "  --horizon F      azimuth-dependent horizon: 'azimuth elevation' lines (N.I.N.A.,\n"
        "                   APCC .hrz, Cartes du Ciel) or MountWizzard4 .hpts (docs/formats.md)\n"
        "  --catalog F      candidates are the stars of F ('RA Dec [name]' lines), placed on\n"
        "                   the sky at --lst (local sidereal time, hours) or --utc with --lon\n"
        "                   (east longitude; J2000 places reduced with ERFA)\n"
        "  --criterion D    D-optimal (maximise the information's determinant) instead of the\n"
        "                   default I-optimal (minimise the mean predicted error over the sky)\n"
        "  --sides S        German mount, within --meridian-limit DEG (15) of the meridian:\n"
        "                   run (default: the side the run used nearby), meridian (flip at\n"
        "                   the meridian), both (either side: the plan chooses); beyond the\n"
        "                   limit always the side that reaches the place: the run's normal\n"
        "                   side on its side of the meridian (without a run ASCOM's: normal\n"
        "                   looking west, beyond the pole east)\n"
        "  --slew R         weigh the time: the gain per second, a slew at R deg/s per axis\n"
        "                   plus --settle S (5) and --point-time S (30, exposure and solve) per\n"
        "                   point and --flip-time S (60) for a change of pier side\n"
        "\n"
        "usage: pmfit compare OLD RUN [--order L] [--add EFFECT ...] [--json] [--no-refraction]\n"
        "                     [--skip-bad]\n"
        "\n"
        "  has the model changed since last night? OLD is a saved model, or a run (fitted at\n"
        "  --order with --add; a model file brings its own terms, and --order or --add with\n"
        "  it is an error); RUN is refitted with the same terms: the pointing error the\n"
        "  old model leaves, the terms that moved beyond 3 sigma, and whether re-zeroing the\n"
        "  index terms (c', e') suffices or a full refit is needed (cross-validated)\n"
        "\n"
        "usage: pmfit report RUN -o PAGE.html [--order L] [--add EFFECT ...] [--compare OLD]\n"
        "                    [--next K] [--min-el DEG] [--horizon FILE] [--fork] [--alpha P]\n"
        "                    [--gear [ha:|dec:|az:|el:]G ...] [--no-refraction] [--skip-bad]\n"
        "                    [--format NAME] [--equinox J2000|JNow] [--azimuth-count]\n"
        "                    [--quiet | --progress]\n"
        "\n"
        "  one self-contained HTML page (inline SVG, no script, no network): the fit and its\n"
        "  table, the residuals on the sky and against azimuth, elevation, hour angle,\n"
        "  declination, time and temperature, the model's correction and predicted error\n"
        "  over the sky, the explain findings with before/after plots, the next K targets\n"
        "  (default 5; --fork: an equatorial mount that does not flip, as pmfit plan) and,\n"
        "  with --compare OLD (a saved model or a run), what changed since;\n"
        "  progress on stderr (on a terminal, or once it has taken a second; --progress:\n"
        "  always, a line per stage; --quiet: never) (docs/report.md)\n"
        "\n"
        "usage: pmfit simulate OUT [--n N] [--seed S] [--lat DEG] [--mount equatorial|altaz]\n"
        "                      [--fork] [--el-limit DEG] [--noise ARCSEC] [--order L]\n"
        "                      [--term NAME=ARCSEC ...] [--random-aniso ARCSEC]\n"
        "                      [--effect EFFECT=SIZE ...] [--phase DEG]\n"
        "\n"
        "  writes a simulated run in the named-column format (docs/formats.md):\n"
        "  --n N            points (default 200)      --seed S        random seed (default 1)\n"
        "  --lat DEG        site latitude (47)         --el-limit DEG  lowest elevation (15)\n"
        "  --mount M        equatorial (default) or altaz; --fork: equatorial without flip\n"
        "  --noise ARCSEC   measurement noise per axis on the sky (default 1)\n"
        "  --order L        order of the true model (default 1)\n"
        "  --term N=V       set true term N (as pmfit fit names it: a b c' d e' i d*Y(1,-1) ...)\n"
        "                   to V arcsec; repeatable\n"
        "  --random-aniso S give every anisotropic term a random value of RMS S arcsec\n"
        "  --effect E=V     inject a physical effect E (any fit --add EFFECT) of size V\n"
        "                   arcsec (periodic: amplitude, phase --phase DEG; temperature,\n"
        "                   time_drift: arcsec per deg C / per hour; hysteresis: arcsec per\n"
        "                   unit of direction, i.e. half the backlash), or outlier[:N] (N\n"
        "                   points off by V) or higher_order (order L+1 terms of RMS V);\n"
        "                   repeatable\n"
        "\n"
        "usage: pmfit simulate --inject EFFECT[=SIZE] [--inject ...] --into RUN OUT\n"
        "                      [--phase DEG] [--seed S] [--no-refraction] [--skip-bad]\n"
        "\n"
        "  the real run RUN with a known effect added to its observed positions (its noise\n"
        "  and everything it holds unchanged), written to OUT in the named-column format:\n"
        "  EFFECT as for --effect; SIZE in arcsec (EFFECT=2.5), or in units of the run's\n"
        "  baseline sigma (EFFECT=1.5sigma, also EFFECT:1.5sigma); default 1sigma\n",
        PM_MAX_L, ROBUST_DEFAULT_CLIP);
}

[[noreturn]] void die(const std::string &msg, int code = 2)
{
    std::fprintf(stderr, "pmfit: %s\n", msg.c_str());
    std::exit(code);
}

bool parse_int(const char *s, int *v)
{
    char *end = nullptr;
    long x = std::strtol(s, &end, 10);
    if (!*s || *end || x < -1000000 || x > 1000000)
        return false;
    *v = (int)x;
    return true;
}

// pmfit report's options (its own list: a page, not a table on stdout).
// An option's number, in lo..hi, or a clear error naming the option.
double number(const std::string &opt, const char *v, double lo, double hi)
{
    char *end = nullptr;
    double x = std::strtod(v, &end);
    if (!*v || *end || !(x >= lo && x <= hi)) {
        char range[64];
        std::snprintf(range, sizeof range, "%g..%g", lo, hi);
        die(opt + ": expected a number in " + range + ", got '" + v + "'");
    }
    return x;
}

// --gear [ha:|dec:]G: the axes a gear period is for (*ha, *dec) and G's
// text.  az: and el: name an alt-az mount's axis 1 and 2 as ha: and dec:
// do (the text of an alt-az run speaks of az_periodic and el_periodic).
std::string gear_axes(const std::string &v, bool *ha, bool *dec, bool *altaz_name)
{
    static const char *const one[2] = {"ha:", "az:"}, *const two[2] = {"dec:", "el:"};
    *ha = *dec = true;
    for (int k = 0; k < 2; k++) {
        if (v.rfind(one[k], 0) == 0) {
            *dec = false;
            *altaz_name = *altaz_name || k == 1;
            return v.substr(3);
        }
        if (v.rfind(two[k], 0) == 0) {
            *ha = false;
            *altaz_name = *altaz_name || k == 1;
            return v.substr(std::string(two[k]).size());
        }
    }
    return v;
}

// az:G and el:G name an alt-az mount's axes: an error on an equatorial run.
void check_gear_names(const Options &o, const Run &run)
{
    if (o.gears_altaz_names && run.mount != PM_MOUNT_ALTAZ)
        die("--gear az:G and el:G name an alt-az mount's axes; " + run.path +
            " is of an equatorial mount: ha:G or dec:G");
}

struct Args {
    int argc;
    char **argv;
    int i;
    std::string a;
    /* The next argument, the value of option a (what it should be). */
    const char *need(const char *what)
    {
        if (i + 1 >= argc)
            die(a + " needs " + what);
        return argv[++i];
    }
};

// The options of reading a run (every command that reads one; ReadOptions);
// true where g.a was one.
bool read_option(Options &o, Args &g)
{
    const std::string &a = g.a;
    ReadOptions &r = o.read;
    if (a == "--format") {
        const std::string v = g.need("a format name");
        r.format = pmrun_format_from_name(v.c_str());
        if (r.format == -2)
            die("--format: expected auto, four-column, named, tpoint, rts2, mw4, csv or mmt, "
                "got '" + v + "'");
    } else if (a == "--equinox") {
        const std::string v = g.need("J2000 or JNow");
        std::string l = v;
        for (char &c : l)
            c = (char)std::tolower((unsigned char)c);
        if (l == "j2000")
            r.equinox = PMRUN_EQUINOX_J2000;
        else if (l == "jnow")
            r.equinox = PMRUN_EQUINOX_JNOW;
        else
            die("--equinox: expected J2000 or JNow, got '" + v + "'");
    } else if (a == "--azimuth-count") {
        r.az_count = true;
    } else if (a == "--no-refraction") {
        r.refraction = false;
    } else if (a == "--skip-bad") {
        r.skip_bad = true;
    } else if (a == "--pressure") {
        // (the weather as typed: in the ranges of sites and light, so that a
        // unit slip is refused, not reduced with; an outside probe's 29.9,
        // inches of mercury, had been taken as hPa)
        const char *v = g.need("hPa (mbar)");
        const double p = std::strtod(v, nullptr);
        if (p >= 20 && p <= 35)
            die(std::string("--pressure: expected hPa (mbar) in 400..1100, got '") + v +
                "' (in inches of mercury that is " + fmt("%.0f", p * 33.8639) + " hPa)");
        r.pressure_hpa = number(a, v, 400, 1100);
    } else if (a == "--temperature") {
        r.temp_c = number(a, g.need("degrees Celsius"), -60, 50);
    } else if (a == "--humidity") {
        const char *v = g.need("a relative humidity, 0..1");
        if (std::strtod(v, nullptr) > 1)
            die(std::string("--humidity: expected a fraction in 0..1, got '") + v + "' (50% is 0.5)");
        r.humidity = number(a, v, 0, 1);
    } else if (a == "--wavelength") {
        r.wavelength_um = number(a, g.need("micrometres"), 0.3, 25);
    } else {
        return false;
    }
    return true;
}

Options parse_report(Options o, int argc, char **argv)
{
    Args g{argc, argv, 2, ""};
    for (; g.i < argc; g.i++) {
        g.a = argv[g.i];
        const std::string &a = g.a;
        auto need = [&](const char *what) { return g.need(what); };
        if (a == "--order") {
            const char *v = need("an order");
            o.order_given = true;
            if (!parse_int(v, &o.order) || o.order < 0 || o.order > PM_MAX_L)
                die(std::string("--order: expected an integer 0..") + std::to_string(PM_MAX_L) +
                    ", got '" + v + "'");
        } else if (a == "--add") {
            o.adds.push_back(need("an effect (see pmfit --help)"));
        } else if (a == "-o" || a == "--output") {
            o.output = need("a file name (the HTML page)");
        } else if (a == "--compare") {
            o.compare = need("OLD: a saved model or a run");
        } else if (a == "--next") {
            o.next = (int)number(a, need("a count"), 1, 1000);
        } else if (a == "--min-el") {
            o.min_el = number(a, need("degrees"), -10, 80);
        } else if (a == "--horizon") {
            o.horizon = need("a horizon file");
        } else if (a == "--fork") {
            o.report_fork = true;
        } else if (a == "--alpha") {
            o.alpha = number(a, need("a probability"), 1e-12, 0.5);
        } else if (a == "--gear") {
            std::string v = need("a gear period in cycles per revolution ([ha:|dec:]G)");
            bool ha, dec;
            v = gear_axes(v, &ha, &dec, &o.gears_altaz_names);
            double gear = number(a, v.c_str(), 1e-6, 1e6);
            if (ha)
                o.gears_ha.push_back(gear);
            if (dec)
                o.gears_dec.push_back(gear);
        } else if (read_option(o, g)) {
        } else if (a == "--quiet" || a == "-q") {
            o.quiet = true;
        } else if (a == "--progress") {
            o.progress = true;
        } else if (!a.empty() && a[0] == '-') {
            die("report: unknown option '" + a + "'; see pmfit --help");
        } else if (o.run.empty()) {
            o.run = a;
        } else {
            die("more than one run file given ('" + o.run + "', '" + a + "')");
        }
    }
    if (o.run.empty())
        die("report: no run file given; usage: pmfit report RUN -o PAGE.html");
    if (o.output.empty())
        die("report: no output given; usage: pmfit report RUN -o PAGE.html");
    if (o.quiet && o.progress)
        die("report: --quiet and --progress contradict each other");
    return o;
}

/* Which command parse_args reads the options of. */
struct Cmd {
    bool sim, eval, expl, cmp, pln;
};

/* Options of fitting and explaining (fit, explain, compare, plan); true
** where a was one. */
bool fit_option(Options &o, const Cmd &c, Args &g)
{
    const std::string &a = g.a;
    if (!c.eval && a == "--order") {
        if (c.sim)
            o.shape_opt = a;
        const char *v = g.need("an order");
        if (!parse_int(v, &o.order) || o.order < 0 || o.order > PM_MAX_L)
            die(std::string("--order: expected an integer 0..") + std::to_string(PM_MAX_L) +
                ", got '" + v + "'");
        o.order_given = true;
    } else if (!c.sim && !c.eval && !c.expl && a == "--pier") {
        std::string v = g.need("joint or split");
        if (v == "split")
            o.split = true;
        else if (v == "joint")
            o.split = false;
        else
            die("--pier: expected joint or split, got '" + v + "'");
    } else if (!c.sim && a == "--json") {
        o.json = true;
    } else if (!c.sim && a == "--residuals") {
        o.residuals = g.need("a file name");
    } else if (!c.sim && !c.eval && a == "--add") {
        o.adds.push_back(g.need("an effect (see pmfit --help)"));
    } else if (!c.sim && !c.eval && !c.expl && a == "--save") {
        o.save = g.need("a file name");
    } else if (!c.sim && !c.eval && !c.expl && a == "--error-map") {
        o.error_map = g.need("a file name (SVG)");
    } else if (!c.sim && !c.eval && !c.expl && a == "--emit-c") {
        o.emit_c = g.need("a file name");
    } else if (!c.sim && !c.eval && !c.expl && a == "--tpoint-terms") {
        o.tpoint_terms = g.need("a file name");
    } else if (!c.sim && !c.eval && a == "--robust") {
        o.robust = true;
    } else if (!c.sim && !c.eval && a == "--clip") {
        o.clip = number(a, g.need("a threshold in robust sigmas"), 2, 1000);
        o.clip_given = true;
    } else {
        return false;
    }
    return true;
}

/* Options of explain alone. */
bool explain_option(Options &o, const Cmd &c, Args &g)
{
    const std::string &a = g.a;
    if (!c.expl)
        return false;
    if (a == "--plots") {
        o.plots = g.need("a directory");
    } else if (a == "--alpha") {
        o.alpha = number(a, g.need("a probability"), 1e-12, 0.5);
    } else if (a == "--no-compose") {
        o.compose = false;
    } else if (a == "--gear") {
        std::string v = g.need("a gear period in cycles per revolution ([ha:|dec:]G)");
        bool ha, dec;
        v = gear_axes(v, &ha, &dec, &o.gears_altaz_names);
        double gp = number(a, v.c_str(), 1e-6, 1e6);
        if (ha)
            o.gears_ha.push_back(gp);
        if (dec)
            o.gears_dec.push_back(gp);
    } else {
        return false;
    }
    return true;
}

/* Options of plan alone (the catalogue, the slew model). */
bool plan_option(Options &o, const Cmd &c, Args &g)
{
    const std::string &a = g.a;
    if (!c.pln)
        return false;
    if (a == "--next") {
        o.next = (int)number(a, g.need("a count"), 1, 1000);
    } else if (a == "--min-el") {
        o.min_el = number(a, g.need("degrees"), -10, 80);
        o.min_el_given = true;
    } else if (a == "--max-el") {
        o.max_el = number(a, g.need("degrees"), 10, 90);
    } else if (a == "--grid") {
        o.grid = number(a, g.need("degrees"), 1, 30);
    } else if (a == "--horizon") {
        o.horizon = g.need("a horizon file");
    } else if (a == "--catalog" || a == "--catalogue") {
        o.catalogue = g.need("a star catalogue file");
    } else if (a == "--lst") {
        o.lst = number(a, g.need("hours"), 0, 23.999999999);
    } else if (a == "--utc") {
        o.utc = g.need("a UTC time YYYY-MM-DDTHH:MM[:SS]");
    } else if (a == "--lon") {
        o.lon = number(a, g.need("degrees (east)"), -180, 360);
    } else if (a == "--criterion") {
        std::string v = g.need("I or D");
        if (v != "I" && v != "D" && v != "i" && v != "d")
            die("--criterion: expected I (mean predicted error) or D (determinant), got '" + v +
                "'");
        o.d_optimal = v == "D" || v == "d";
    } else if (a == "--slew") {
        o.slew_rate = number(a, g.need("the slew rate in deg/s"), 0.01, 100);
    } else if (a == "--settle") {
        o.settle = number(a, g.need("seconds"), 0, 3600);
    } else if (a == "--point-time") {
        o.point_time = number(a, g.need("seconds"), 0, 36000);
    } else if (a == "--flip-time") {
        o.flip_time = number(a, g.need("seconds"), 0, 3600);
    } else if (a == "--sides") {
        o.sides = g.need("run, meridian or both");
        if (o.sides != "run" && o.sides != "meridian" && o.sides != "both")
            die("--sides: expected run, meridian or both, got '" + o.sides + "'");
    } else if (a == "--meridian-limit") {
        o.meridian_limit = number(a, g.need("degrees"), 0, 90);
    } else {
        return false;
    }
    return true;
}

/* Options that shape a simulated run (simulate; --lat, --noise, --fork and
** --mount also plan's sky); each noted in shape_opt. */
bool shape_option(Options &o, const Cmd &c, Args &g)
{
    const std::string &a = g.a;
    bool both = c.sim || c.pln;
    if (c.sim && a == "--n") {
        o.n = (long)number(a, g.need("a count"), 1, 1e7);
    } else if (both && a == "--lat") {
        o.lat = number(a, g.need("degrees"), -90, 90);
    } else if (c.sim && a == "--el-limit") {
        o.el_limit = number(a, g.need("degrees"), -10, 80);
    } else if (both && a == "--noise") {
        o.noise = number(a, g.need("arcseconds"), 0, 1e5);
    } else if (c.sim && a == "--random-aniso") {
        o.random_aniso = number(a, g.need("arcseconds"), 0, 1e5);
    } else if (both && a == "--fork") {
        o.fork = true;
    } else if (both && a == "--mount") {
        std::string v = g.need("equatorial or altaz");
        if (v != "equatorial" && v != "altaz")
            die("--mount: expected equatorial or altaz, got '" + v + "'");
        o.altaz = v == "altaz";
    } else if (c.sim && a == "--effect") {
        std::string v = g.need("SPEC=ARCSEC");
        size_t eq = v.rfind('=');
        if (eq == std::string::npos || eq == 0)
            die("--effect: expected SPEC=ARCSEC (SPEC as for fit --add), got '" + v + "'");
        o.effects.push_back({v.substr(0, eq), number(a, v.c_str() + eq + 1, -1e6, 1e6)});
    } else if (c.sim && a == "--term") {
        std::string v = g.need("NAME=ARCSEC");
        size_t eq = v.rfind('=');
        if (eq == std::string::npos || eq == 0)
            die("--term: expected NAME=ARCSEC, got '" + v + "'");
        o.terms.push_back({v.substr(0, eq), number(a, v.c_str() + eq + 1, -1e6, 1e6)});
    } else {
        return false;
    }
    o.shape_opt = a;
    return true;
}

/* Options of simulate that do not shape the run, and of reading a run. */
bool run_option(Options &o, const Cmd &c, Args &g)
{
    const std::string &a = g.a;
    if (c.sim && a == "--inject") {
        o.inject.push_back(g.need("EFFECT[=SIZE]"));
    } else if (c.sim && a == "--into") {
        o.into = g.need("a run file");
    } else if (c.sim && a == "--seed") {
        o.seed = (unsigned long long)number(a, g.need("a seed"), 0, 1e15);
    } else if (c.sim && a == "--phase") {
        o.phase_deg = number(a, g.need("degrees"), -360, 360);
    } else {
        return read_option(o, g);
    }
    return true;
}

/* The file arguments (RUN, and eval's and compare's MODEL or OLD first). */
void positional(Options &o, const Cmd &c, const std::string &a)
{
    if (!a.empty() && a[0] == '-')
        die("unknown option '" + a + "'; see pmfit --help");
    if ((c.eval || c.cmp) && o.model.empty())
        o.model = a;
    else if (o.run.empty())
        o.run = a;
    else
        die("more than one run file given ('" + o.run + "', '" + a + "')");
}

/* The combinations of options a command refuses. */
void check_combinations(const Options &o, const Cmd &c, int argc, char **argv)
{
    const bool sim = c.sim, eval = c.eval, cmp = c.cmp, pln = c.pln;
    if (sim && !o.into.empty() && !o.shape_opt.empty())
        die(o.shape_opt + " shapes a simulated run; with --into the run is the recording (only "
                          "--inject, --phase, --seed, --no-refraction and --skip-bad apply)");
    if (sim && o.into.empty() && !o.inject.empty())
        die("--inject needs --into RUN (the recording to inject into); to simulate a run with "
            "an effect use --effect");
    if (sim && !o.into.empty() && o.inject.empty())
        die("--into RUN needs at least one --inject EFFECT[=SIZE]");
    if (sim && o.into.empty() && !o.read.text().empty())
        die("--no-refraction, --skip-bad, --format, --equinox, --azimuth-count, --pressure, "
            "--temperature, --humidity and --wavelength apply to reading a run: with --into only");
    if ((cmp || pln) && !o.tpoint_terms.empty())
        die("--tpoint-terms writes the model of pmfit fit; see pmfit --help");
    if (o.clip_given && !o.robust)
        die("--clip K sets the threshold of --robust; add --robust");
    if (eval && o.model.empty())
        die("no model file given; see pmfit --help");
    if (cmp && (o.model.empty() || o.run.empty()))
        die("compare needs OLD (a model file, or a run) and RUN; see pmfit --help");
    if (cmp && (o.split || !o.save.empty() || !o.emit_c.empty() || !o.error_map.empty() ||
                o.robust || !o.residuals.empty()))
        die("compare takes OLD RUN [--order L] [--add EFFECT ...] [--json] [--no-refraction] "
            "[--skip-bad]; see pmfit --help");
    if (o.run.empty() && !pln)
        die(sim ? "no output file given; see pmfit --help" : "no run file given; see pmfit --help");
    if (pln && (o.split || !o.save.empty() || !o.emit_c.empty() || !o.error_map.empty() ||
                o.robust || !o.residuals.empty()))
        die("plan takes [RUN] [--next K] [--order L] [--add EFFECT ...] [--lat DEG] [--mount M] "
            "[--fork] [--min-el DEG] [--grid DEG] [--noise ARCSEC] [--json] and the options of "
            "pmfit --help; see there");
    if (pln && o.catalogue.empty() && (o.lst >= 0 || !o.utc.empty() || std::isfinite(o.lon)))
        die("--lst, --utc and --lon place the stars of a catalogue; add --catalog FILE");
    if (pln && !o.catalogue.empty() && (o.lst >= 0) == !o.utc.empty())
        die("--catalog needs the time: --lst HOURS (local sidereal time) or --utc "
            "YYYY-MM-DDTHH:MM with --lon DEG (one of them)");
    if (pln && !o.utc.empty() && !std::isfinite(o.lon))
        die("--utc needs the site's east longitude: --lon DEG");
    if (pln && o.slew_rate <= 0) {
        for (int i = 2; i < argc; i++) {
            std::string a = argv[i];
            if (a == "--settle" || a == "--point-time" || a == "--flip-time")
                die(a + " belongs to the slew model; add --slew DEG_PER_S");
        }
    }
}

/* pmfit CMD --help: the usage of CMD (its "usage: pmfit CMD" sections),
** or all of it. */
void usage_of(const std::string &cmd)
{
    char *buf = nullptr;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    if (!m) {
        usage(stdout);
        return;
    }
    usage(m);
    std::fclose(m);
    std::string all(buf, len), out;
    std::free(buf);
    const std::string head = "usage: pmfit " + cmd + " ";
    for (size_t at = all.find(head); at != std::string::npos; at = all.find(head, at + 1)) {
        size_t end = all.find("\nusage: ", at);
        out += all.substr(at, end == std::string::npos ? std::string::npos : end + 1 - at);
        if (end != std::string::npos && all.compare(end + 1, head.size(), head) != 0)
            out += "\n";
    }
    std::fputs(out.empty() ? all.c_str() : out.c_str(), stdout);
}

Options parse_args(int argc, char **argv)
{
    Options o;
    if (argc < 2) {
        usage(stderr);
        std::exit(2);
    }
    o.cmd = argv[1];
    auto known = [](const std::string &c) {
        return c == "fit" || c == "simulate" || c == "eval" || c == "explain" || c == "compare" ||
               c == "plan" || c == "report";
    };
    if (o.cmd == "-h" || o.cmd == "--help" || o.cmd == "help") {
        if (argc > 2 && known(argv[2])) // pmfit help CMD
            usage_of(argv[2]);
        else
            usage(stdout);
        std::exit(0);
    }
    if (!known(o.cmd))
        die("unknown command '" + o.cmd +
            "' (expected: fit, explain, eval, compare, plan, report or simulate); see pmfit --help");
    for (int i = 2; i < argc; i++)
        if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
            usage_of(o.cmd);
            std::exit(0);
        }
    if (o.cmd == "report")
        return parse_report(o, argc, argv);
    const Cmd c = {o.cmd == "simulate", o.cmd == "eval", o.cmd == "explain", o.cmd == "compare",
                   o.cmd == "plan"};
    Args g = {argc, argv, 2, std::string()};
    for (; g.i < argc; g.i++) {
        g.a = argv[g.i];
        if (!fit_option(o, c, g) && !explain_option(o, c, g) && !plan_option(o, c, g) &&
            !shape_option(o, c, g) && !run_option(o, c, g))
            positional(o, c, g.a);
    }
    check_combinations(o, c, argc, argv);
    for (int i = 2; i < argc; i++) {
        std::string a = argv[i];
        o.lat_given = o.lat_given || a == "--lat";
        o.noise_given = o.noise_given || a == "--noise";
        o.mount_given = o.mount_given || a == "--mount";
    }
    return o;
}









void print_table(const char *title, const FitOut &f, const std::vector<Obs> &obs,
                 const std::string &path, const std::vector<std::string> &aux_names)
{
    const pm_model &m = f.model;
    std::printf("\n%s\n", title);
    std::printf("  N = %ld observations, P = %d terms, order L = %d, %d Gauss-Newton passes\n",
                f.res.n_obs, f.res.n_par, m.order, f.res.iterations);
    std::printf("  unbiased sigma = %.3f\"   sky RMS = %.3f\"\n\n", f.res.sigma * RAD2AS,
                f.rms * RAD2AS);
    std::printf("  %-12s %-38s %13s %10s %7s\n", "term", "meaning", "value(\")", "1sigma(\")",
                "signif");
    for (int i = 0; i < m.n_terms; i++) {
        double v = m.coef[i] * RAD2AS, e = f.res.err[i] * RAD2AS;
        double z = e > 0 ? std::fabs(v) / e : 0;
        // (a term per unit of a column of large values has an error below
        // 0.005: significant digits, not "0.00 0.00" with signif 11.5)
        const bool tiny = e > 0 && e < 0.005;
        std::printf(tiny ? "  %-12s %-38s %13.4g %10.3g %6.1f%s\n"
                         : "  %-12s %-38s %13.2f %10.2f %6.1f%s\n",
                    term_name(m, i).c_str(), meaning(m, i, &aux_names).c_str(), v, e, z,
                    z >= 3 ? " *" : "");
    }
    if (std::fabs(f.corr) > 0.999)
        std::printf("\n  warning: %s and %s are nearly degenerate for this sky coverage "
                    "(correlation %+.5f):\n  their values are not meaningful one by one, only "
                    "together; sigma is.\n",
                    term_name(m, f.corr_j).c_str(), term_name(m, f.corr_i).c_str(), f.corr);
    // worst points
    std::vector<size_t> order(f.idx.size());
    for (size_t j = 0; j < order.size(); j++)
        order[j] = j;
    auto mag = [&](size_t j) { return std::hypot(f.r0[j], f.r1[j]); };
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return mag(a) > mag(b); });
    std::printf("\n  worst points (residual on the sky, arcsec):\n");
    for (size_t k = 0; k < order.size() && k < 5; k++) {
        size_t j = order[k];
        const Obs &o = obs[f.idx[j]];
        std::printf("    %s:%d  axis1 %+8.2f  axis2 %+8.2f  |r| %7.2f  (enc %7.2f, %7.2f deg)\n",
                    path.c_str(), o.line, f.r0[j] * RAD2AS, f.r1[j] * RAD2AS, mag(j) * RAD2AS,
                    o.eh * 180 / PI, o.ed * 180 / PI);
    }
}

// (aux_names: the run's auxiliary columns; a term on one of them gets
// "column": its name, which the term's name, c'*aux0, does not say)
void print_json_fit(const FitOut &f, const std::string &extra,
                    const std::vector<std::string> &aux_names)
{
    const pm_model &m = f.model;
    std::printf("{\"n_obs\": %ld, \"n_params\": %d, \"order\": %d, \"sigma_arcsec\": %.6f, "
                "\"rms_arcsec\": %.6f, \"iterations\": %d, \"terms\": [",
                f.res.n_obs, f.res.n_par, m.order, f.res.sigma * RAD2AS, f.rms * RAD2AS,
                f.res.iterations);
    for (int i = 0; i < m.n_terms; i++) {
        const pm_term &t = m.term[i];
        std::string col;
        if (t.kind == PM_TERM_AUX && t.aux >= PM_AUX_USER &&
            (size_t)(t.aux - PM_AUX_USER) < aux_names.size())
            col = ", \"column\": \"" + json_escape(aux_names[t.aux - PM_AUX_USER]) + "\"";
        std::printf("%s{\"name\": \"%s\"%s, \"value_arcsec\": %.6f, \"error_arcsec\": %.6f}",
                    i ? ", " : "", json_escape(term_name(m, i)).c_str(), col.c_str(),
                    m.coef[i] * RAD2AS, f.res.err[i] * RAD2AS);
    }
    std::printf("]");
    if (f.corr_i >= 0)
        std::printf(", \"max_correlation\": {\"terms\": [\"%s\", \"%s\"], \"value\": %.6f}",
                    json_escape(term_name(m, f.corr_j)).c_str(),
                    json_escape(term_name(m, f.corr_i)).c_str(), f.corr);
    std::printf("%s%s}", extra.empty() ? "" : ", ", extra.c_str());
}

void fail_fit(const FitOut &f, const std::string &what)
{
    die(what + ": " + pm_status_text(f.status) + fit_failure_detail(f, MAX_PASSES, "--order"), 1);
}

} // namespace




// Write per-observation residuals (arcsec) atomically; "" or the error (the
// caller reports its results first).
std::string write_residuals(const std::string &path, const std::string &title,
                     const std::vector<FitOut> &fits, const std::vector<Obs> &obs)
{
    std::string text = "# " + title + ", arcsec on the sky\n"
                       "# line enc1_deg enc2_deg pier res1_arcsec res2_arcsec\n";
    char buf[160];
    for (const FitOut &f : fits)
        for (size_t j = 0; j < f.idx.size(); j++) {
            const Obs &ob = obs[f.idx[j]];
            std::snprintf(buf, sizeof buf, "%d %.6f %.6f %d %.4f %.4f\n", ob.line,
                          ob.eh * 180 / PI, ob.ed * 180 / PI, ob.pier, f.r0[j] * RAD2AS,
                          f.r1[j] * RAD2AS);
            text += buf;
        }
    char err[1024];
    if (pmhost::write_atomic(path, text, err, sizeof err) != 0)
        return err;
    return "";
}

// --robust: the residual file lists every observation, rejected ones flagged.
std::string write_residuals_robust(const std::string &path, const std::string &title,
                            const std::vector<RobustFit> &rfs, const std::vector<Obs> &obs)
{
    std::string text = "# " + title + ", arcsec on the sky; rejected = 1: left out by --robust "
                       "(its residual is from the fit of the others)\n"
                       "# line enc1_deg enc2_deg pier res1_arcsec res2_arcsec rejected\n";
    char buf[160];
    for (const RobustFit &rf : rfs)
        for (size_t j = 0; j < rf.use.size(); j++) {
            const Obs &ob = obs[rf.use[j]];
            std::snprintf(buf, sizeof buf, "%d %.6f %.6f %d %.4f %.4f %d\n", ob.line,
                          ob.eh * 180 / PI, ob.ed * 180 / PI, ob.pier, rf.r0[j] * RAD2AS,
                          rf.r1[j] * RAD2AS, rf.rejected[j] ? 1 : 0);
            text += buf;
        }
    char err[1024];
    if (pmhost::write_atomic(path, text, err, sizeof err) != 0)
        return err;
    return "";
}

// The "robust" member of the JSON output.
std::string robust_json(const RobustFit &rf, const std::vector<Obs> &obs)
{
    char b[256];
    std::snprintf(b, sizeof b,
                  "\"robust\": {\"clip\": %.6g, \"sigma_robust_arcsec\": %.6f, \"n_considered\": "
                  "%zu, \"n_rejected\": %zu, \"rounds\": %d, \"stable\": %s, \"lts_start\": %s, "
                  "\"outliers\": [",
                  rf.clip, rf.sigma_robust * RAD2AS, rf.use.size(), rf.outliers.size(), rf.rounds,
                  rf.stable ? "true" : "false", rf.lts_start ? "true" : "false");
    std::string out = b;
    for (size_t k = 0; k < rf.outliers.size(); k++) {
        size_t j = 0;
        while (rf.use[j] != rf.outliers[k])
            j++;
        std::snprintf(b, sizeof b,
                      "%s{\"line\": %d, \"residual_arcsec\": %.4f, \"robust_sigmas\": %.3f}",
                      k ? ", " : "", obs[rf.outliers[k]].line,
                      std::hypot(rf.r0[j], rf.r1[j]) * RAD2AS, rf.dist[j] / rf.sigma_robust);
        out += b;
    }
    return out + "]}";
}

// The table report's list of rejected observations.
void print_robust(const RobustFit &rf, const std::vector<Obs> &obs, const std::string &path)
{
    std::printf("\n  robust fit (--robust, clip K = %.2f): robust sigma %.3f\", threshold %.2f\"\n"
                "  (on the residual weighed by its leverage, docs/robust.md);\n"
                "  %zu of %zu observations rejected, so N, sigma, the terms and the worst points\n"
                "  above are of the %zu kept (%d clipping round%s%s)%s\n",
                rf.clip, rf.sigma_robust * RAD2AS, rf.clip * rf.sigma_robust * RAD2AS,
                rf.outliers.size(), rf.use.size(), rf.use.size() - rf.outliers.size(), rf.rounds,
                rf.rounds == 1 ? "" : "s", rf.lts_start ? "" : ", started from all points",
                rf.outliers.empty() ? "" : ":");
    for (int i : rf.outliers) {
        size_t j = 0;
        while (rf.use[j] != i)
            j++;
        const Obs &o = obs[i];
        std::printf("    %s:%d  rejected  axis1 %+9.2f  axis2 %+9.2f  |r| %8.2f  (%.1f robust "
                    "sigma)\n",
                    path.c_str(), o.line, rf.r0[j] * RAD2AS, rf.r1[j] * RAD2AS,
                    std::hypot(rf.r0[j], rf.r1[j]) * RAD2AS, rf.dist[j] / rf.sigma_robust);
    }
    if (rf.outliers.size() > std::max<size_t>(3, rf.use.size() / 20))
        std::printf("  warning: %.0f%% rejected, far more than failed plate solves explain: the "
                    "residuals are not\n  noise plus a few gross errors; the model leaves "
                    "something out (pmfit explain)\n",
                    100.0 * (double)rf.outliers.size() / (double)rf.use.size());
    if (!rf.stable)
        std::printf("  warning: the rejected set still changed after %d rounds (points on the "
                    "threshold);\n  the list is that of the last round\n",
                    rf.rounds);
}

// Without --robust: name the points a robust fit would reject, if any.
void print_robust_hint(const FitOut &f, const std::vector<Obs> &obs, const std::string &path)
{
    std::vector<int> s = robust_suspects(f, obs, ROBUST_DEFAULT_CLIP, MAX_PASSES);
    if (s.empty())
        return;
    std::string lines;
    for (size_t k = 0; k < s.size() && k < 20; k++)
        lines += (k ? ", " : "") + std::to_string(obs[s[k]].line);
    if (s.size() > 20)
        lines += " and " + std::to_string(s.size() - 20) + " more";
    std::printf("\n  hint: %zu point%s miss%s the fit of the others by more than %.2f robust "
                "sigmas, line%s\n    %s\n  failed plate solves or wrong stars? pmfit fit %s "
                "--robust fits without them\n  (docs/robust.md)\n",
                s.size(), s.size() == 1 ? "" : "s", s.size() == 1 ? "es" : "",
                ROBUST_DEFAULT_CLIP, s.size() == 1 ? "" : "s", lines.c_str(), shell_word(path).c_str());
}

int cmd_eval(const Options &o, const Run &run_in)
{
    FitOut f;
    char err[1024];
    pmmodel_info info;
    if (pmmodel_load_info(o.model.c_str(), &f.model, &info, err, sizeof err) != 0)
        die(err, 1);
    const int mount = run_in.mount;
    if (f.model.mount != mount)
        die(o.model + " is a model of an " +
                (f.model.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial") + " mount, " +
                o.run + " a run of an " + (mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial") +
                " one", 1);
    // the run as the model reads it: its columns by name, its pier side
    std::vector<std::string> notes;
    Run run;
    try {
        run = run_for_model(run_in, f.model, model_inputs(info), info.pier, o.model, &notes);
    } catch (const std::exception &x) {
        die(x.what(), 1);
    }
    // the model's elevation-dependent terms (refraction, tube flexure) read
    // the elevation at the model's latitude: at another site's run they
    // point for the wrong sky (as the model would in that mount's firmware)
    bool zenith = false;
    for (int i = f.model.n_base; i < f.model.n_terms; i++)
        zenith = zenith || f.model.term[i].kind == PM_TERM_ZENITH;
    if (zenith && mount != PM_MOUNT_ALTAZ && std::isfinite(run.latitude) &&
        std::fabs(run.latitude - f.model.latitude) > 1e-6)
        notes.push_back(fmt("%s was fitted at latitude %+.4f deg, %s is at %+.4f deg: evaluated "
                            "as the model is, its elevation-dependent terms (refraction, tube "
                            "flexure) at its own latitude; pmfit compare refits at the run's",
                            o.model.c_str(), f.model.latitude * 180 / PI, o.run.c_str(),
                            run.latitude * 180 / PI));
    for (const std::string &n : notes)
        std::fprintf(stderr, "pmfit: note: %s\n", n.c_str());
    const std::vector<Obs> &obs = run.obs;
    std::vector<int> all(obs.size());
    for (size_t i = 0; i < obs.size(); i++)
        all[i] = (int)i;
    size_t bad = 0;
    pm_status rst = residuals(f, obs, all, &bad);
    if (rst != PM_OK) {
        std::string inputs;
        for (int i = 0; i < f.model.n_terms; i++)
            if (f.model.term[i].kind == PM_TERM_AUX)
                inputs += (inputs.empty() ? "" : ", ") + term_name(f.model, i);
        die(o.run + ":" + std::to_string(obs[(size_t)all[bad]].line) + ": " + o.model +
                " cannot be evaluated here (" + pm_status_text(rst) + (inputs.empty()
                    ? std::string(")")
                    : "): its terms " + inputs + " read an input (temperature, time, slew "
                      "direction or a column) this record does not give") +
                "; nothing evaluated",
            1);
    }
    std::string werr;
    if (!o.residuals.empty())
        werr = write_residuals(o.residuals, "residuals of pmfit eval " + o.model + " " + o.run,
                               {f}, obs);
    if (o.json) {
        std::printf("{\"n_obs\": %zu, \"n_params\": %d, \"order\": %d, \"rms_arcsec\": %.6f}\n",
                    obs.size(), f.model.n_terms, f.model.order, f.rms * RAD2AS);
    } else {
        std::printf("pmfit eval %s on %s: %zu observations, model of order %d (%d terms)\n",
                    o.model.c_str(), o.run.c_str(), obs.size(), f.model.order, f.model.n_terms);
        std::printf("  sky RMS of the residuals, no refit: %.3f\"\n", f.rms * RAD2AS);
    }
    if (!werr.empty()) {
        std::fflush(stdout);
        die(werr + " (the evaluation is reported above)", 1);
    }
    return 0;
}

// pmfit plan [RUN]: the next targets that most reduce the predicted error
// over the sky (plan.hpp).
int cmd_plan(const Options &o)
{
    Run run;
    PlanOptions po;
    if (!o.run.empty()) {
        run = load_run(o.run, o.read);
        po.mount = run.mount;
        po.latitude = run.latitude;
        /* the run's observations are of its mount: planning another one's
        ** sky from them would mix the axes */
        if (o.mount_given && (o.altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL) != run.mount)
            die("plan: --mount " + std::string(o.altaz ? "altaz" : "equatorial") + ", but " +
                o.run + " is a run of an " +
                (run.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial") +
                " mount; its mount is the plan's: drop --mount");
    }
    if (o.mount_given || o.run.empty())
        po.mount = o.altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
    if (o.lat_given || (o.run.empty() && po.mount != PM_MOUNT_ALTAZ))
        po.latitude = o.lat * PI / 180;
    po.order = o.order;
    po.adds = o.adds;
    po.next = o.next;
    po.min_el_deg = o.min_el;
    po.max_el_deg = o.max_el;
    po.grid_deg = o.grid;
    po.gem = !o.fork;
    if (o.fork && po.mount == PM_MOUNT_ALTAZ) /* (as pmfit report; it had been ignored) */
        die("plan: --fork is for an equatorial mount that does not flip; the plan is of an alt-az "
            "mount");
    po.noise_arcsec = o.noise;
    if (!o.noise_given) // the run's own sigma, when it can be fitted
        po.noise_arcsec = run_noise_arcsec(run, o.order, o.adds, o.noise);
    po.d_optimal = o.d_optimal;
    po.sides = o.sides == "both" ? SIDES_BOTH : o.sides == "meridian" ? SIDES_MERIDIAN : SIDES_RUN;
    po.meridian_limit_deg = o.meridian_limit;
    po.slew.rate_deg_s = o.slew_rate;
    po.slew.settle_s = o.settle;
    po.slew.point_s = o.point_time;
    po.slew.flip_s = o.flip_time;
    Plan p;
    try {
        if (!o.horizon.empty())
            po.horizon = read_horizon(o.horizon);
        if (!o.catalogue.empty()) {
            po.stars = read_catalogue(o.catalogue);
            po.when.lst_h = o.lst;
            po.when.utc = o.utc;
            po.when.lon_rad = o.lon * PI / 180;
            po.when.lat_rad = po.latitude;
            if (!o.utc.empty() && !std::isfinite(po.latitude))
                throw std::runtime_error("--utc needs the site latitude (--lat, or the run's)");
        }
        p = plan_targets(run, po);
    } catch (const std::exception &x) {
        die(x.what(), 1);
    }
    if (o.json) {
        std::printf("%s\n", plan_json(p, po, run.obs.size()).c_str());
        return 0;
    }
    bool az = po.mount == PM_MOUNT_ALTAZ;
    char below[48] = "";
    if (max_el_of(po) < 90)
        std::snprintf(below, sizeof below, " and below %g", max_el_of(po));
    std::printf("pmfit plan: %zu points taken, order %d%s, noise %.3g\" per axis; %d candidates "
                "above %.0f%s deg elevation%s%s%s\n", run.obs.size(), o.order,
                o.adds.empty() ? "" : " + terms", po.noise_arcsec, p.n_candidates, po.min_el_deg,
                below, o.horizon.empty() ? "" : (" and the horizon of " + o.horizon).c_str(),
                o.catalogue.empty() ? "" : (" (stars of " + o.catalogue + ": " +
                                            std::to_string(p.n_catalogue) + ")").c_str(),
                po.d_optimal ? "; D-optimal" : "");
    if (!p.note.empty())
        std::printf("  note: %s\n", p.note.c_str());
    if (std::isfinite(p.before_arcsec))
        std::printf("  predicted error over the sky now: %.3f\" (1 sigma per axis, mean)\n",
                    p.before_arcsec);
    else
        std::printf("  the model is not determined yet%s\n",
                    p.note_says_undetermined ? " (the note above)" : " (fewer points than half its terms)");
    std::printf("  next targets (in this order):\n");
    for (size_t k = 0; k < p.targets.size(); k++) {
        const Target &t = p.targets[k];
        char after[96] = "not yet determined";
        if (std::isfinite(t.after_arcsec))
            std::snprintf(after, sizeof after, "%.3f\"", t.after_arcsec);
        if (po.slew.on())
            std::snprintf(after + std::strlen(after), sizeof after - std::strlen(after),
                          "  (%.0f s)", t.slew_s);
        char num_s[32];
        std::snprintf(num_s, sizeof num_s, "%2zu.", k + 1);
        if (!t.name.empty()) {
            std::printf("    %s %s (RA %.4f h, Dec %+.3f deg)\n", num_s, t.name.c_str(), t.ra_h,
                        t.dec_deg);
            std::snprintf(num_s, sizeof num_s, "   ");
        }
        if (az)
            std::printf("    %s az %7.2f deg  el %6.2f deg  -> predicted %s\n", num_s, t.x_deg,
                        t.y_deg, after);
        else
            std::printf("    %s HA %+6.2f h  Dec %+7.2f deg  (el %5.1f, %s)  -> predicted %s\n",
                        num_s, t.x_deg / 15, t.y_deg, t.el_deg,
                        t.side < 0 ? "beyond the pole" : "normal side", after);
    }
    return 0;
}

// pmfit compare OLD RUN: OLD a model file (its first line 'pm-model N') or
// a run (fitted at --order with --add, and its errors count).
int cmd_compare(const Options &o, const Run &run)
{
    // (an unreadable OLD throws its file:line message: main prints it, exit 1)
    {
        char err[1024];
        // the terms of a model file are its own: --order 2 with an order-1
        // OLD compared order 1 without a word
        if ((o.order_given || !o.adds.empty()) && is_model_file(o.model, err, sizeof err) == 1)
            die(o.model + " is a model file: the comparison is of its own terms; --order and "
                          "--add choose the model fitted to an OLD run");
    }
    OldSide os = load_old(o.model, o.order, o.adds, o.read, 100);
    if (os.is_run && os.fit.status != PM_OK)
        fail_fit(os.fit, o.model + " (the old run)");
    Comparison c;
    try {
        c = compare_old(os, run, o.model);
    } catch (const std::exception &x) {
        die(o.model + " vs " + o.run + ": " + x.what(), 1);
    }
    if (o.json)
        std::printf("%s\n", comparison_json(c).c_str());
    else
        print_comparison(c, o.model, o.run);
    return 0;
}

// The pictures of pmfit explain --plots DIR (SVG).
// The variable a finding was located by, at observation o (the j-th of the
// baseline fit), and its axis label: the x of its residual plot.
double finding_variable(const Run &run, const Finding &f, const Obs &o, size_t j, std::string *xlab)
{
    bool altaz = run.mount == PM_MOUNT_ALTAZ;
    if (f.effect == "ha_periodic" || f.effect == "dec_periodic") {
        double th = f.effect == "ha_periodic" ? o.eh : o.ed;
        *xlab = "phase of the period, G * raw " +
                std::string(f.effect == "ha_periodic" ? (altaz ? "azimuth" : "HA")
                                                      : (altaz ? "elevation" : "Dec")) + " (deg)";
        return std::fmod(std::fmod(f.cycles_per_rev * th * 180 / PI, 360) + 360, 360);
    }
    if (f.effect == "refraction" || f.effect == "tube_flexure") {
        double el = altaz ? o.ad
                          : std::asin(std::sin(run.latitude) * std::sin(o.ad) +
                                      std::cos(run.latitude) * std::cos(o.ad) * std::cos(o.ah));
        *xlab = "elevation (deg)";
        return el * 180 / PI;
    }
    if (f.effect == "temperature") {
        *xlab = "temperature (deg C)";
        return o.ctx.temp_c;
    }
    if (f.effect == "time_drift") {
        *xlab = "time (h)";
        return o.ctx.time_h;
    }
    if (f.effect.rfind("aux:", 0) == 0) {
        auto it = std::find(run.aux_names.begin(), run.aux_names.end(), f.effect.substr(4));
        size_t col = (size_t)(it - run.aux_names.begin());
        if (col < run.aux_names.size() && col < (size_t)PM_MAX_AUX) {
            *xlab = "the run's column " + f.effect.substr(4);
            return o.ctx.aux[col];
        }
    }
    if (f.effect == "hysteresis") {
        *xlab = "direction of the last slew on axis 1 (-1, +1; jittered)";
        return o.ctx.dir + 0.1 * ((double)(j % 7) - 3) / 3; // jitter to see the spread
    }
    if (f.effect == "pier_side") {
        *xlab = "apparent hour angle (h); west pier = beyond the pole";
        return std::remainder(o.ah, 2 * PI) * 12 / PI;
    }
    *xlab = "line in the run file";
    return (double)o.line;
}

void write_explain_plots(const std::string &dir, const Run &run, const Explanation &ex)
{
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec)
        die("--plots: cannot create " + dir + ": " + ec.message(), 1);
    std::string err;
    auto check = [&](int rc) {
        if (rc != 0)
            die("--plots: " + err, 1);
    };
    bool altaz = run.mount == PM_MOUNT_ALTAZ;
    std::string xl = altaz ? "azimuth (deg)" : "hour angle (deg)";
    std::string yl = altaz ? "elevation (deg)" : "declination (deg)";
    auto vecs = [&](const FitOut &f) {
        std::vector<pmplot::Vec> v;
        for (size_t j = 0; j < f.idx.size(); j++) {
            const Obs &o = run.obs[f.idx[j]];
            double x = std::remainder(o.ah, 2 * PI) * 180 / PI;
            if (altaz && x < 0)
                x += 360;
            v.push_back({x, o.ad * 180 / PI, f.r0[j] * RAD2AS, f.r1[j] * RAD2AS,
                         o.pier < 0 ? 1 : 0});
        }
        return v;
    };
    std::vector<std::string> groups = altaz ? std::vector<std::string>{"alt-az"}
                                            : std::vector<std::string>{"pier east", "pier west"};
    char t[256];
    std::snprintf(t, sizeof t, "Residuals on the sky: baseline (sigma %.2f\") and after %zu "
                               "finding%s (sigma %.2f\")",
                  ex.base_sigma_arcsec, ex.findings.size(), ex.findings.size() == 1 ? "" : "s",
                  ex.final_sigma_arcsec);
    check(pmplot::sky_vectors_pair(dir + "/sky_before_after.svg", t, xl, yl, vecs(ex.baseline),
                                   vecs(ex.final), "baseline", "explained model", 0, groups, &err));
    for (const Periodogram &pg : ex.periodograms) {
        std::snprintf(t, sizeof t, "Periodogram of the baseline residuals, %s axis",
                      pg.axis == "ha" ? (altaz ? "azimuth" : "hour-angle")
                                      : (altaz ? "elevation" : "declination"));
        char lab[64];
        std::snprintf(lab, sizeof lab, "false-alarm 1%% over %zu periods", pg.g.size());
        // (on an alt-az mount periodogram_az.svg and _el.svg)
        const std::string axis = !altaz ? pg.axis : pg.axis == "ha" ? "az" : "el";
        check(pmplot::periodogram(dir + "/periodogram_" + axis + ".svg", t,
                                  "chi^2 reduction / sigma^2", pg.g, pg.power, pg.threshold, lab,
                                  pg.peak_g, true, &err));
    }
    std::vector<std::string> labels = {"baseline"};
    std::vector<double> sig = {ex.base_sigma_arcsec}, cv = {ex.base_cv_rms_arcsec};
    for (const Finding &f : ex.findings) {
        labels.push_back("+ " + mount_words(f.effect, run.mount));
        sig.push_back(f.sigma_after_arcsec);
        cv.push_back(f.cv_rms_after_arcsec);
    }
    check(pmplot::steps(dir + "/steps.svg", "Unbiased sigma and cross-validated RMS per step",
                        labels, sig, cv, &err));
    // each finding: the baseline residual against its variable
    const FitOut &b = ex.baseline;
    for (size_t k = 0; k < ex.findings.size(); k++) {
        const Finding &f = ex.findings[k];
        pmplot::Series s1{altaz ? "along azimuth" : "along hour angle", {}, {}, false};
        pmplot::Series s2{altaz ? "along elevation" : "along declination", {}, {}, false};
        std::string xlab;
        for (size_t j = 0; j < b.idx.size(); j++) {
            const Obs &o = run.obs[b.idx[j]];
            double x = finding_variable(run, f, o, j, &xlab);
            double y0 = b.r0[j] * RAD2AS, y1 = b.r1[j] * RAD2AS;
            if (f.effect == "ha_periodic" && std::fabs(std::cos(o.ad)) > 0.2)
                y0 /= std::fabs(std::cos(o.ad)); // along the axis, not on the sky
            s1.x.push_back(x);
            s1.y.push_back(y0);
            s2.x.push_back(x);
            s2.y.push_back(y1);
        }
        // (an alt-az mount's periodic effects by its axes' names: mount_words)
        const std::string name = mount_words(f.effect, run.mount);
        std::snprintf(t, sizeof t, "Finding %zu, %s: baseline residuals", k + 1, name.c_str());
        check(pmplot::xy(dir + "/finding" + std::to_string(k + 1) + "_" + name + ".svg", t, xlab,
                         "residual (arcsec)", {s1, s2}, &err));
    }
}

// The --robust preface of explain's text report.
void print_robust_explained(const RobustFit &rf, const Run &full, const Run &run)
{
    std::string lines;
    for (int i : rf.outliers)
        lines += (lines.empty() ? " (line" + std::string(rf.outliers.size() > 1 ? "s " : " ")
                                : std::string(", ")) +
                 std::to_string(full.obs[i].line);
    std::printf("robust: %zu of %zu observations rejected by a robust fit of the baseline%s%s;\n"
                "  explained below: the %zu kept (robust sigma %.3f\", clip K = %.2f)\n\n",
                rf.outliers.size(), full.obs.size(), lines.c_str(), lines.empty() ? "" : ")",
                run.obs.size(), rf.sigma_robust * RAD2AS, rf.clip);
}

// The explanation's options from pmfit's.
ExplainOptions explain_options(const Options &o)
{
    ExplainOptions eo;
    eo.order = o.order;
    eo.adds = o.adds;
    eo.alpha = o.alpha;
    eo.gears_ha = o.gears_ha;
    eo.gears_dec = o.gears_dec;
    eo.compose = o.compose;
    return eo;
}

// After an explanation of an alt-az run whose slew directions were taken
// the short way round: count_reading_hint again with its terms (a periodic
// error it found, left out, had hidden the difference: an outside probe's
// mounts that never turn through north with a 20" two-cycle error were
// missed in 28 of 37 runs, the backlash read at half its size).  The text
// of the hint, or "".
std::string count_hint_after(const Run &run, const Explanation &ex)
{
    if (ex.findings.empty())
        return "";
    std::vector<std::string> adds; /* (count_reading_hint adds the backlash) */
    for (const std::string &a : ex.final_adds)
        if (a != "hysteresis" && a.rfind("aux:" + std::string(axis2_dir_name(run.mount)), 0) != 0)
            adds.push_back(a);
    return count_reading_hint(run, ex.final_order, adds);
}

// The run read again with its azimuth as the mount's count, with the note
// that says why, where count_reading_hint (with the user's terms, or with
// those of a first explanation) finds that far better; else the run
// itself, and in *pre the first explanation where one was made (of that
// run, with explain_options(o): the caller's to use, not to make again).
Run count_reading(const Options &o, const Run &run, std::optional<Explanation> *pre)
{
    pre->reset();
    if (o.read.az_count || run.az_count || !count_reading_possible(run))
        return run;
    std::string hint = count_reading_hint(run, o.order, o.adds);
    if (hint.empty()) {
        *pre = explain(run, explain_options(o));
        hint = count_hint_after(run, **pre);
    }
    if (hint.empty())
        return run;
    pre->reset();
    ReadOptions counted = o.read;
    counted.az_count = true;
    Run r = load_run(o.run, counted);
    r.notes.push_back(o.run + ": " + hint + " (read so here)");
    std::fprintf(stderr, "pmfit: note: %s\n", r.notes.back().c_str());
    return r;
}

// pmfit explain: report, JSON, plots.
int cmd_explain(const Options &o, const Run &full_in)
{
    check_gear_names(o, full_in);
    std::optional<Explanation> pre;
    const Run full = count_reading(o, full_in, &pre);
    ExplainOptions eo = explain_options(o);
    // --robust: explain the observations a robust fit of the baseline keeps
    Run clean;
    RobustFit rf;
    if (o.robust) {
        rf = robust_fit(full.obs, all_of(full.obs.size()),
                        build_model(o.order, o.adds, full.obs, full.mount, full.latitude,
                                    full.aux_names),
                        o.clip, MAX_PASSES);
        if (!rf.error.empty())
            die(full.path + ": --robust: " + rf.error, 1);
        if (rf.fit.status != PM_OK)
            fail_fit(rf.fit, full.path + " (robust fit of the baseline)");
        clean = full;
        clean.obs.clear();
        for (size_t j = 0; j < rf.use.size(); j++)
            if (!rf.rejected[j])
                clean.obs.push_back(full.obs[rf.use[j]]);
    }
    const Run &run = o.robust ? clean : full;
    // Without --order: order 0 where the run is too few points for order 1
    // (explain.hpp, explain_default)
    std::string order_note;
    Explanation ex;
    try {
        const Explanation *first = pre && !o.robust ? &*pre : nullptr;
        ex = o.order_given ? (first ? *first : explain(run, eo))
                           : explain_default(run, eo, &order_note, first);
    } catch (const std::exception &x) {
        die(x.what(), 1);
    }
    const int order = order_note.empty() ? o.order : 0;
    if (!order_note.empty())
        std::fprintf(stderr, "pmfit: note: %s: %s\n", run.path.c_str(), order_note.c_str());
    if (o.json) {
        std::printf("{\"n_obs\": %zu%s, \"order_note\": %s, %s}\n", run.obs.size(),
                    o.robust ? (", " + robust_json(rf, full.obs)).c_str() : "",
                    order_note.empty() ? "null" : ("\"" + json_escape(order_note) + "\"").c_str(),
                    explain_json(run, ex, order).c_str());
    } else {
        std::printf("pmfit explain %s: %s mount, %zu observations\n\n", run.path.c_str(),
                    run.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial", run.obs.size());
        if (!order_note.empty())
            std::printf("%s\n\n", order_note.c_str());
        if (o.robust)
            print_robust_explained(rf, full, run);
        print_explain_text(run, ex, order, !o.adds.empty(), o.alpha, !o.gears_ha.empty(),
                           !o.gears_dec.empty());
    }
    if (!o.plots.empty())
        write_explain_plots(o.plots, run, ex);
    return 0;
}

// pmfit simulate --inject EFFECT[=SIZE] --into RUN OUT
int cmd_inject(const Options &o, int argc, char **argv)
{
    std::vector<Injection> list;
    for (const std::string &spec : o.inject) {
        Injection in;
        try {
            in = parse_injection(spec);
        } catch (const std::exception &e) {
            die(e.what());
        }
        in.phase_deg = o.phase_deg;
        in.seed = o.seed;
        list.push_back(in);
    }
    Run run = load_run(o.into, o.read);
    for (const std::string &n : run.notes)
        std::fprintf(stderr, "pmfit: note: %s\n", n.c_str());
    InjectReport rep = inject(run, list);
    std::vector<std::string> head;
    std::string cmd = "made by:";
    for (int i = 0; i < argc; i++)
        cmd += std::string(" ") + argv[i];
    head.push_back(cmd);
    char b[512];
    std::snprintf(b, sizeof b, "the recording %s (%zu points, baseline order %d, sigma %.4f arcsec)",
                  o.into.c_str(), run.obs.size(), rep.order, rep.sigma_arcsec);
    head.push_back(b);
    std::vector<size_t> slot(list.size(), 0);
    for (size_t k = 0; k < list.size(); k++) {
        std::snprintf(b, sizeof b, "injected %s of size %.6g arcsec (%.4g sigma), phase %g deg, seed "
                      "%llu: RMS displacement %.4f arcsec per axis (%.4g sigma)",
                      list[k].effect.c_str(), rep.size_arcsec[k], rep.size_arcsec[k] / rep.sigma_arcsec,
                      list[k].phase_deg, list[k].seed, rep.rms_arcsec[k],
                      rep.rms_arcsec[k] / rep.sigma_arcsec);
        head.push_back(b);
        if (!rep.moved[k].empty()) {
            slot[k] = head.size();
            head.push_back(""); // the moved lines, below
        }
    }
    // the moved points' lines in RUN and in OUT (after the comments, the
    // latitude, mount and column lines)
    size_t first = head.size() + (std::isfinite(run.latitude) ? 1 : 0) + 2 + 1;
    for (size_t k = 0; k < list.size(); k++) {
        if (rep.moved[k].empty())
            continue;
        std::string in_run = "moved lines " + o.into + ":", in_out = "; in " + o.run + ":";
        for (int j : rep.moved[k]) {
            in_run += " " + std::to_string(run.obs[(size_t)j].line);
            in_out += " " + std::to_string(first + (size_t)j);
        }
        head[slot[k]] = in_run + in_out;
    }
    write_named_run(run, o.run, head);
    for (size_t k = 1; k < head.size(); k++)
        std::fprintf(stderr, "pmfit: %s\n", head[k].c_str());
    std::fprintf(stderr, "pmfit: wrote %s\n", o.run.c_str());
    return 0;
}

int cmd_simulate(const Options &o, int argc, char **argv)
{
    if (!o.into.empty())
        return cmd_inject(o, argc, argv);
    pmsim_spec spec;
    pmsim_default(&spec);
    spec.n = o.n;
    spec.seed = o.seed;
    spec.latitude_deg = o.lat;
    spec.el_limit_deg = o.el_limit;
    spec.noise_arcsec = o.noise;
    spec.gem = o.fork ? 0 : 1;
    pm_model &m = spec.truth;
    pm_model_init(&m, o.altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL, o.order);
    if (o.random_aniso > 0) {
        std::mt19937_64 rng(o.seed ^ 0x5eedULL);
        std::normal_distribution<double> g(0.0, 1.0);
        for (int i = 6; i < m.n_terms; i++)
            m.coef[i] = o.random_aniso / RAD2AS * g(rng);
    }
    for (const auto &t : o.terms) {
        int found = term_index(m, t.first);
        if (found < 0)
            die("--term: no term '" + t.first + "' in an order-" + std::to_string(o.order) +
                " model (names as pmfit fit prints them, e.g. c' or d*Y(1,-1))");
        m.coef[found] = t.second / RAD2AS;
    }
    m.latitude = o.lat * PI / 180;
    if (pm_model_prepare(&m) != PM_OK)
        die("simulate: the true model is invalid", 1);
    // physical effects (pmsim_add_effect)
    for (const auto &e : o.effects) {
        char err[512];
        if (pmsim_add_effect(&spec, e.first.c_str(), e.second, o.phase_deg, o.seed, err,
                             sizeof err) != 0)
            die(std::string("simulate: ") + err, 1);
    }
    std::string cmd = "made by:";
    for (int i = 0; i < argc; i++)
        cmd += std::string(" ") + argv[i];
    char err[1024];
    if (pmsim_write(&spec, o.run.c_str(), cmd.c_str(), err, sizeof err) != 0)
        die(err, 1);
    std::fprintf(stderr, "pmfit: wrote %s (%ld points)\n", o.run.c_str(), o.n);
    return 0;
}

// Output files must be writable before any work is done (a fit is not
// computed and then lost): the directory exists and is writable, the path
// is not a directory.
void check_output(const std::string &opt, const std::string &path)
{
    if (path.empty())
        return;
    std::error_code ec;
    std::filesystem::path p(path);
    std::string dir = p.has_parent_path() ? p.parent_path().string() : std::string(".");
    if (!std::filesystem::is_directory(dir, ec))
        die(opt + " " + path + ": cannot write: the directory '" + dir +
            "' does not exist (nothing was done)", 1);
    if (std::filesystem::is_directory(p, ec))
        die(opt + " " + path + ": cannot write: it is a directory (nothing was done)", 1);
    if (access(dir.c_str(), W_OK) != 0)
        die(opt + " " + path + ": cannot write into '" + dir + "': " + std::strerror(errno) +
            " (nothing was done)", 1);
}

// One file under two names?  Both exist and are one node (links followed),
// or neither exists yet and both name one place.
bool same_file(const std::string &a, const std::string &b)
{
    struct stat sa, sb;
    bool ea = stat(a.c_str(), &sa) == 0, eb = stat(b.c_str(), &sb) == 0;
    if (ea && eb)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (ea || eb)
        return false;
    std::error_code e1, e2;
    std::filesystem::path ca = std::filesystem::weakly_canonical(a, e1);
    std::filesystem::path cb = std::filesystem::weakly_canonical(b, e2);
    return !e1 && !e2 && ca == cb;
}

// No output may be one of the inputs (a run overwritten by its own
// residuals is a night's data lost), nor may two outputs be one file (the
// second would replace the first): refused before any work.  A device or a
// FIFO (/dev/null, /dev/stdout) may take several outputs.
void check_distinct(const std::vector<std::pair<std::string, std::string>> &outs,
                    const std::vector<std::pair<std::string, std::string>> &ins)
{
    for (size_t i = 0; i < outs.size(); i++) {
        struct stat st;
        if (stat(outs[i].second.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
            continue;
        for (const auto &in : ins)
            if (same_file(outs[i].second, in.second))
                die(outs[i].first + " " + outs[i].second + ": cannot write: it is " +
                    (outs[i].second == in.second ? "" : "the same file as ") + "the input " +
                    in.first + (outs[i].second == in.second ? "" : " " + in.second) +
                    " (nothing was done)", 1);
        for (size_t j = 0; j < i; j++)
            if (same_file(outs[i].second, outs[j].second))
                die(outs[i].first + " " + outs[i].second + ": cannot write: " + outs[j].first +
                    " writes the same file (nothing was done)", 1);
    }
}

// pmfit report RUN -o PAGE.html: the page, written through a temporary file
// and a rename, so a failure leaves the output path as it was.  Progress on
// stderr: on a terminal one line updated per stage; otherwise a line per
// stage once the page has taken a second (a short run stays quiet but for
// the closing 'wrote'); --progress: a line per stage always; --quiet: none.
int cmd_report(const Options &o, const Run &run_in, int argc, char **argv)
{
    check_gear_names(o, run_in);
    // (an alt-az run read as the mount's count where that fits far better,
    // as explain reads it)
    std::optional<Explanation> pre;
    Run run;
    try {
        run = count_reading(o, run_in, &pre);
    } catch (const std::exception &x) {
        die(std::string(x.what()) + " (no page written)", 1);
    }
    if (o.report_fork && run.mount == PM_MOUNT_ALTAZ)
        die("report: --fork is for an equatorial mount that does not flip; " + run.path +
            " is of an alt-az mount", 1);
    ReportOptions ro;
    ro.order = o.order;
    ro.order_given = o.order_given;
    ro.adds = o.adds;
    ro.alpha = o.alpha;
    ro.gears_ha = o.gears_ha;
    ro.gears_dec = o.gears_dec;
    ro.next = o.next;
    ro.min_el_deg = o.min_el;
    ro.horizon = o.horizon;
    ro.fork = o.report_fork;
    ro.compare = o.compare;
    ro.read = o.read;
    ro.max_passes = MAX_PASSES;
    ro.explained = pre ? &*pre : nullptr; /* (count_reading's, with the page's options) */
    ro.command = "pmfit";
    for (int i = 1; i < argc; i++)
        ro.command += std::string(" ") + argv[i];
    bool tty = isatty(fileno(stderr)) != 0;
    auto t0 = std::chrono::steady_clock::now();
    ReportProgress progress = [&](const std::string &stage, double done) {
        double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (o.quiet || (!tty && !o.progress && sec < 1))
            return;
        bool line = !tty || o.progress;
        std::fprintf(stderr, line ? "pmfit report: [%3.0f%%] %s (%.1f s)\n" : "\rpmfit report: [%3.0f%%] %-20s %6.1f s",
                     done * 100, stage.c_str(), sec);
        if (!line && stage == "done")
            std::fprintf(stderr, "\n");
    };
    std::string html;
    try {
        html = report_html(run, ro, progress);
    } catch (const std::exception &x) {
        if (tty && !o.quiet && !o.progress)
            std::fprintf(stderr, "\n");
        die(std::string(x.what()) + " (no page written)", 1);
    }
    char err[1024];
    if (pmhost::write_atomic(o.output, html, err, sizeof err) != 0)
        die(err, 1);
    if (!o.quiet)
        std::fprintf(stderr, "pmfit report: wrote %s (%zu kB)\n", o.output.c_str(), (html.size() + 500) / 1000);
    return 0;
}

int run_main(int argc, char **argv)
{
    Options o = parse_args(argc, argv);
    for (const char *sfx : {"", "-east", "-west"}) {
        if (!o.split && *sfx)
            continue;
        if (o.split && !*sfx)
            continue;
        check_output("--save", o.save.empty() ? o.save : o.save + sfx);
        check_output("--emit-c", o.emit_c.empty() ? o.emit_c : o.emit_c + sfx);
        check_output("--error-map", o.error_map.empty() ? o.error_map : o.error_map + sfx);
        check_output("--tpoint-terms", o.tpoint_terms.empty() ? o.tpoint_terms : o.tpoint_terms + sfx);
    }
    check_output("--residuals", o.residuals);
    check_output("--output", o.output);
    if (o.cmd == "simulate")
        check_output("simulate", o.run);
    {
        std::vector<std::pair<std::string, std::string>> outs, ins;
        auto out = [&](const char *opt, const std::string &p) {
            if (!p.empty())
                outs.emplace_back(opt, p);
        };
        auto in = [&](const char *what, const std::string &p) {
            if (!p.empty())
                ins.emplace_back(what, p);
        };
        for (const char *sfx : {"", "-east", "-west"}) {
            if (o.split != (*sfx != 0))
                continue;
            if (!o.save.empty())
                out("--save", o.save + sfx);
            if (!o.emit_c.empty())
                out("--emit-c", o.emit_c + sfx);
            if (!o.error_map.empty())
                out("--error-map", o.error_map + sfx);
            if (!o.tpoint_terms.empty())
                out("--tpoint-terms", o.tpoint_terms + sfx);
        }
        out("--residuals", o.residuals);
        out("--output", o.output);
        if (o.cmd == "simulate") {
            out("simulate", o.run);
            in("--into", o.into);
        } else {
            in("RUN", o.run);
        }
        in("MODEL", o.model);
        in("--compare", o.compare);
        in("--horizon", o.horizon);
        in("--catalog", o.catalogue);
        check_distinct(outs, ins);
    }
    if (PM_CHECK_CONFIG() != PM_OK)
        die("library and program were built with different PM_MAX_L/PM_MAX_EXTRA", 1);
    if (o.cmd == "simulate")
        return cmd_simulate(o, argc, argv);
    if (o.cmd == "plan")
        return cmd_plan(o);

    Run run;
    try {
        run = load_run(o.run, o.read);
    } catch (const std::exception &x) {
        // (report says so of every failure; its run's had lacked it)
        die(std::string(x.what()) + (o.cmd == "report" ? " (no page written)" : ""), 1);
    }
    for (const std::string &n : run.notes)
        std::fprintf(stderr, "pmfit: note: %s\n", n.c_str());
    std::vector<Obs> &obs = run.obs;
    const std::vector<std::string> &aux_names = run.aux_names;
    int mount = run.mount;
    if (o.cmd == "eval")
        return cmd_eval(o, run);
    if (o.cmd == "compare")
        return cmd_compare(o, run);
    if (o.cmd == "explain")
        return cmd_explain(o, run);
    if (o.cmd == "report")
        return cmd_report(o, run, argc, argv);

    pm_model start = build_model(o.order, o.adds, obs, mount, run.latitude, aux_names);
    bool side_terms = false;
    for (int i = start.n_base; i < start.n_terms; i++)
        side_terms = side_terms || start.term[i].side != 0;
    if (o.split && side_terms)
        die("--pier split fits the sides independently; side-specific terms (@E, @W) belong "
            "to a joint fit");
    std::vector<int> all(obs.size());
    for (size_t i = 0; i < obs.size(); i++)
        all[i] = (int)i;

    // residual file is written only after every fit succeeded
    std::vector<FitOut> fits;
    std::vector<std::string> titles;
    FTest ftest;
    // --robust: each fit is of the points its robust fit keeps (robs), and the
    // F-tests compare models of the kept points only
    std::vector<RobustFit> robs;
    std::vector<int> kept;
    auto fit_points = [&](const std::vector<int> &use, const std::string &what) {
        if (!o.robust) {
            FitOut f = do_fit(obs, use, start, MAX_PASSES);
            if (f.status != PM_OK)
                fail_fit(f, what);
            kept.insert(kept.end(), use.begin(), use.end());
            return f;
        }
        RobustFit rf = robust_fit(obs, use, start, o.clip, MAX_PASSES);
        if (!rf.error.empty())
            die(what + ": --robust: " + rf.error, 1);
        if (rf.fit.status != PM_OK)
            fail_fit(rf.fit, what + " (robust fit)");
        kept.insert(kept.end(), rf.fit.idx.begin(), rf.fit.idx.end());
        robs.push_back(rf);
        return rf.fit;
    };
    if (!o.split) {
        FitOut f = fit_points(all, o.run);
        fits.push_back(f);
        titles.push_back(all_points_title(start));
        if (side_terms) {
            FitOut g = do_fit(obs, kept, without_side_terms(start));
            if (g.status == PM_OK)
                ftest = f_test(g.res.chi2, g.res.n_par, f.res.chi2, f.res.n_par, f.res.n_obs,
                               "side-specific terms vs shared only");
        }
    } else {
        for (int side : {1, -1}) {
            std::vector<int> use;
            for (size_t i = 0; i < obs.size(); i++)
                if (obs[i].pier == side)
                    use.push_back((int)i);
            std::string t = side > 0 ? "pier side east (normal)" : "pier side west (beyond the pole)";
            if (use.empty())
                die(o.run + ": --pier split: no observations on the " + t, 1);
            FitOut f = fit_points(use, o.run + " (" + t + ")");
            fits.push_back(f);
            titles.push_back(t);
        }
        std::sort(kept.begin(), kept.end());
        FitOut g = do_fit(obs, kept, start);
        if (g.status == PM_OK)
            ftest = f_test(g.res.chi2, g.res.n_par, fits[0].res.chi2 + fits[1].res.chi2,
                           fits[0].res.n_par + fits[1].res.n_par, g.res.n_obs,
                           "split (independent sides) vs joint");
    }

    std::vector<std::string> write_errors;
    if (!o.residuals.empty()) {
        std::string title = "residuals of pmfit fit " + o.run + " (order " +
                            std::to_string(o.order) + ", pier " + (o.split ? "split" : "joint") +
                            (o.robust ? ", robust" : "") + ")";
        std::string e = o.robust ? write_residuals_robust(o.residuals, title, robs, obs)
                                 : write_residuals(o.residuals, title, fits, obs);
        if (!e.empty())
            write_errors.push_back(e);
    }

    // the predicted error map of each fit (pier side of a split fit: its
    // own), and whether the stars determine the model between them
    std::vector<ErrorMap> maps;
    std::vector<std::string> undetermined;
    for (size_t k = 0; k < fits.size(); k++) {
        int side = fits.size() == 1 ? 0 : (k == 0 ? 1 : -1);
        maps.push_back(error_map(run, fits[k], side));
        undetermined.push_back(undetermined_warning(maps[k], fits[k].res.sigma * RAD2AS));
        std::string suffix = fits.size() == 1 ? "" : (k == 0 ? "-east" : "-west");
        if (!o.error_map.empty()) {
            try {
                error_map_plot(o.error_map + suffix, run, maps[k],
                               "Predicted pointing error of the model (1 sigma per axis), " +
                                   titles[k]);
            } catch (const std::exception &x) {
                write_errors.push_back(x.what());
            }
        }
    }

    for (size_t k = 0; k < fits.size(); k++) {
        std::string suffix = fits.size() == 1 ? "" : (k == 0 ? "-east" : "-west");
        std::string note = "fitted by pmfit from " + o.run + " (" + titles[k] + ")\n" +
                           "N = " + std::to_string(fits[k].res.n_obs) + ", sigma = " +
                           std::to_string(fits[k].res.sigma * RAD2AS) + " arcsec" +
                           (o.robust ? ", --robust: " + std::to_string(robs[k].outliers.size()) +
                                           " outliers left out"
                                     : std::string()) +
                           (undetermined[k].empty() ? "" : "\nwarning: " + undetermined[k]);
        char e[1024];
        // what the model file says beyond the model: the names of the
        // columns its terms read (another run may have them in another
        // order) and, split, its pier side
        pmmodel_info info = model_info(fits[k].model, aux_names,
                                       fits.size() == 1 ? 0 : (k == 0 ? 1 : -1), fits[k].res.err);
        if (std::isfinite(maps[k].at_points_arcsec))
            info.stars_sigma = maps[k].at_points_arcsec / RAD2AS;
        std::string inputs_note;
        for (int j = 0; j < PM_MAX_AUX; j++)
            if (info.input[j][0])
                inputs_note += "\npm_context.aux[" + std::to_string(j) + "]: the run's column '" +
                               info.input[j] + "'" +
                               (std::string(info.input[j]) == axis2_dir_name(run.mount) &&
                                        run.dec_dir_derived
                                    ? " (the sign of the axis-2 move from the previous "
                                      "position, derived)"
                                : std::string(info.input[j]) == "az_turn" && run.turn_derived
                                    ? " (the turn of the file's azimuth count past 360 deg "
                                      "multiples, less the run's least: 0, 1 or 2, derived)"
                                : std::string(info.input[j]) == "az_wind" && run.wind_derived
                                    ? " (the file's azimuth count in turns, count / 360 deg, "
                                      "derived)"
                                    : "");
        // a write that fails now still lets the report below be printed
        if (!o.save.empty() &&
            pmmodel_save_cov((o.save + suffix).c_str(), &fits[k].model, &info,
                             fits[k].cov.size() == (size_t)fits[k].model.n_terms *
                                                       (size_t)fits[k].model.n_terms
                                 ? fits[k].cov.data()
                                 : nullptr,
                             note.c_str(), e, sizeof e) != 0)
            write_errors.push_back(e);
        if (!o.tpoint_terms.empty()) {
            if (pmtp_write((o.tpoint_terms + suffix).c_str(), &fits[k].model, fits[k].res.err,
                           ("pmfit fit " + o.run + " (" + titles[k] + ")").c_str(), e,
                           sizeof e) != 0)
                write_errors.push_back(e);
        }
        if (!o.emit_c.empty()) {
            std::string prefix = fits.size() == 1 ? "pm_fitted" : (k == 0 ? "pm_east" : "pm_west");
            if (pmmodel_emit_c((o.emit_c + suffix).c_str(), &fits[k].model, prefix.c_str(),
                               (note + inputs_note).c_str(), e, sizeof e) != 0)
                write_errors.push_back(e);
        }
    }


    std::string fjson;
    if (ftest.done) {
        char b[256];
        std::snprintf(b, sizeof b,
                      "\"pier_f_test\": {\"test\": \"%s\", \"f\": %.6g, \"dof1\": %d, "
                      "\"dof2\": %ld, \"p\": %.6g}",
                      ftest.what.c_str(), ftest.f, ftest.d1, ftest.d2, ftest.p);
        fjson = b;
    }
    if (o.json) {
        auto rj = [&](size_t k) { return o.robust ? robust_json(robs[k], obs) : std::string(); };
        if (fits.size() == 1) {
            std::string r = rj(0), em = error_map_json(maps[0], fits[0].res.sigma * RAD2AS);
            r = r.empty() ? em : r + ", " + em;
            print_json_fit(fits[0], fjson + (fjson.empty() ? "" : ", ") + r, aux_names);
        } else {
            std::printf("{\"pier\": \"split\", %s%s\"sides\": {\"east\": ", fjson.c_str(),
                        fjson.empty() ? "" : ", ");
            auto with_map = [&](size_t k) {
                std::string r = rj(k);
                return (r.empty() ? "" : r + ", ") +
                       error_map_json(maps[k], fits[k].res.sigma * RAD2AS);
            };
            print_json_fit(fits[0], with_map(0), aux_names);
            std::printf(", \"west\": ");
            print_json_fit(fits[1], with_map(1), aux_names);
            std::printf("}}");
        }
        std::printf("\n");
    } else {
        std::printf("pmfit fit %s: %s mount, %zu observations\n", o.run.c_str(),
                    mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial", obs.size());
        for (size_t k = 0; k < fits.size(); k++) {
            print_table(titles[k].c_str(), fits[k], obs, o.run, aux_names);
            std::printf("\n%s\n", error_map_text(run, maps[k]).c_str());
            if (!undetermined[k].empty())
                std::printf("\n  warning: %s.\n", undetermined[k].c_str());
            // (records folded to the sky: the robust hint's "failed plate
            // solves" would be the wrong cause, 19 of 40 points)
            const std::string folded =
                fits.size() == 1 && !o.robust ? folded_pier_hint(run, o.order, o.adds) : "";
            if (!folded.empty())
                std::printf("\n  warning: %s.\n", folded.c_str());
            else if (o.robust)
                print_robust(robs[k], obs, o.run);
            else
                print_robust_hint(fits[k], obs, o.run);
        }
        if (ftest.done)
            std::printf("\n  pier sides, %s: F = %.3g (%d, %ld dof), p = %.3g: %s\n",
                        ftest.what.c_str(), ftest.f, ftest.d1, ftest.d2, ftest.p,
                        ftest.p < 0.01 ? "the sides differ significantly"
                                       : "no significant difference between the sides");
        std::printf("\n  * = significant at 3 sigma. Values are radians x 206265 (arcsec);\n"
                    "    the model is defined in docs/model.md.\n");
    }
    std::fflush(stdout);
    for (size_t k = 0; k < fits.size(); k++)
        if (!undetermined[k].empty())
            std::fprintf(stderr, "pmfit: warning: %s%s.\n",
                         fits.size() == 1 ? "" : (k == 0 ? "east: " : "west: "),
                         undetermined[k].c_str());
    if (!write_errors.empty()) {
        for (size_t k = 0; k + 1 < write_errors.size(); k++)
            std::fprintf(stderr, "pmfit: %s\n", write_errors[k].c_str());
        die(write_errors.back() + " (the fit is reported above)", 1);
    }
    return 0;
}

int main(int argc, char **argv)
{
    try {
        return run_main(argc, argv);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "pmfit: %s\n", e.what());
        return 1;
    }
}
