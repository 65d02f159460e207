// fitrun.cpp - fitting a pointing run with a chosen term set (host side).
#include "fitrun.hpp"
#include "hostutil.hpp"
#include "runfile.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace pmhost {

std::string ReadOptions::text() const
{
    std::string t = std::string(refraction ? "" : " --no-refraction") + (skip_bad ? " --skip-bad" : "");
    if (format != PMRUN_FORMAT_AUTO)
        t += std::string(" --format ") + pmrun_format_name(format);
    if (equinox == PMRUN_EQUINOX_J2000)
        t += " --equinox J2000";
    else if (equinox == PMRUN_EQUINOX_JNOW)
        t += " --equinox JNow";
    if (az_count)
        t += " --azimuth-count";
    const struct {
        const char *opt;
        double v;
    } w[] = {{"--pressure", pressure_hpa},
             {"--temperature", temp_c},
             {"--humidity", humidity},
             {"--wavelength", wavelength_um}};
    for (const auto &x : w)
        if (!std::isnan(x.v)) {
            char b[64];
            std::snprintf(b, sizeof b, " %s %.12g", x.opt, x.v); /* (as typed) */
            t += b;
        }
    return t;
}

Run load_run(const std::string &path, const ReadOptions &o)
{
    pmrun_options ro;
    pmrun_options_default(&ro);
    ro.refraction = o.refraction ? 1 : 0;
    ro.skip_bad = o.skip_bad ? 1 : 0;
    ro.format = o.format;
    ro.equinox = o.equinox;
    ro.pressure_hpa = o.pressure_hpa;
    ro.temp_c = o.temp_c;
    ro.humidity = o.humidity;
    ro.wavelength_um = o.wavelength_um;
    pmrun *run = nullptr;
    char err[1024];
    if (pmrun_read(path.c_str(), &ro, &run, err, sizeof err) != 0)
        throw std::runtime_error(err);
    std::unique_ptr<pmrun, void (*)(pmrun *)> guard(run, pmrun_free);
    Run r = run_from_pmrun(run, path, o.az_count);
    equinox_hint(r, run, path, ro);
    ReadOptions shown = o;
    shown.az_count = r.az_count; /* (asked for, and the run is alt-az with its raw axis) */
    r.read_options = shown.text();
    return r;
}

// A German mount's run whose records beyond the pole were written folded to
// the sky, without a pier column, reads every record as one side: the
// collimation and the declination index then change sign at the meridian
// unmodelled (an outside probe's 40 points: sigma 55", "19 points miss the
// fit of the others", and explain named higher_order).  Where no record is
// west and, leaving out the records within 15 deg of the meridian (a German
// mount tracks past it before it flips), both sides hold 5 or more, and on
// those records the model of the fit with e'@W and i@W read by the encoder
// hour angle's sign (west where it is positive) fits far better (F-test p <
// 1e-6, sigma below 2/3) and better than a step of c' there (below), the
// text that says so; else empty.
std::string folded_pier_hint(const Run &run, int order, const std::vector<std::string> &adds)
{
    if (run.mount != PM_MOUNT_EQUATORIAL)
        return "";
    long east = 0, west = 0;
    std::vector<int> use;
    for (size_t i = 0; i < run.obs.size(); i++) {
        if (run.obs[i].pier < 0)
            return "";
        const double ha = std::remainder(run.obs[i].eh, 2 * PI);
        if (std::fabs(ha) < 15 * PI / 180)
            continue;
        (ha < 0 ? east : west)++;
        use.push_back((int)i);
    }
    if (east < 5 || west < 5)
        return "";
    Run by_ha = run;
    for (Obs &o : by_ha.obs)
        o.pier = o.ctx.pier = std::remainder(o.eh, 2 * PI) < 0 ? 1 : -1;
    std::vector<std::string> sided = adds, stepped = adds;
    sided.push_back("e'@W");
    sided.push_back("i@W");
    stepped.push_back("c'@W");
    pm_model m[3];
    try { /* (a term the run cannot give throws: then nothing is said) */
        m[0] = build_model(order, adds, run.obs, run.mount, run.latitude, run.aux_names);
        m[1] = build_model(order, sided, by_ha.obs, run.mount, run.latitude, run.aux_names);
        m[2] = build_model(order, stepped, by_ha.obs, run.mount, run.latitude, run.aux_names);
    } catch (const std::exception &) {
        return "";
    }
    FitOut f[3];
    f[0] = do_fit(run.obs, use, m[0]);
    f[1] = do_fit(by_ha.obs, use, m[1]);
    if (f[0].status != PM_OK || f[1].status != PM_OK)
        return "";
    const FTest t = f_test(f[0].res.chi2, f[0].res.n_par, f[1].res.chi2, f[1].res.n_par,
                           (long)use.size(), "");
    if (!(t.done && t.p < 1e-6 && f[1].res.sigma < f[0].res.sigma * 2 / 3))
        return "";
    // Not where a step of the hour-angle index at the meridian does as well
    // (BIC, its one term against two): a German mount that never flips, its
    // worm changing flank as the balance reverses there, had been told its
    // records were folded (an outside probe's 10" step: 4 runs of 8).  (Its
    // fit only here, past the tests every fork and one-sided run stops at.)
    const double s2 = f[1].res.sigma * f[1].res.sigma,
                 ln2n = std::log(2.0 * (double)use.size());
    f[2] = do_fit(by_ha.obs, use, m[2]);
    if (f[2].status == PM_OK &&
        !(f[1].res.chi2 < f[2].res.chi2 - s2 * ln2n * (f[1].res.n_par - f[2].res.n_par)))
        return "";
    char b[700];
    std::snprintf(b, sizeof b,
                  "every record reads as one pier side, and the residuals change at the "
                  "meridian as a German mount's two sides do: with the collimation and the "
                  "declination index of each side (e'@W, i@W, the side from the sign of the "
                  "hour angle; the %zu records beyond 15 deg of it) sigma is %.3g\" against "
                  "%.3g\" (F-test p = %.2g). Records "
                  "beyond the pole written folded to the sky, with no pier column? Give each "
                  "record's pier side (a pier column, or the encoder declination beyond 90 deg "
                  "as the mount reads it: docs/formats.md) and fit again",
                  use.size(), f[1].res.sigma * RAD2AS, f[0].res.sigma * RAD2AS, t.p);
    return b;
}

// An RTS2 file read with its true places as they are (the default) whose
// places fit far better reduced from J2000: a note that says so.  Image
// astrometry gives J2000, and read as of date an outside probe's run came
// out with sigma 90.7" and a, b, c' hundreds of arcseconds off, without a
// word (6.2" and every term within 0.3" read with --equinox J2000).  Both
// readings are fitted at order 0, the one as read with a refraction term
// (the J2000 reduction adds refraction: over a short run of places of date
// order 0 holds the precession, and the comparison had rewarded the
// refraction, not the equinox; an outside probe's JNow runs of 6-15
// minutes got the note 10 times in 10); the note where J2000's sigma is
// below a third of the other's and 5" less.
void equinox_hint(Run &r, const pmrun *raw, const std::string &path, const pmrun_options &ro)
{
    if (pmrun_format(raw) != PMRUN_FORMAT_RTS2 || ro.equinox != PMRUN_EQUINOX_FILE ||
        !std::isfinite(r.latitude) || r.obs.size() < 6)
        return;
    pmrun_options o2 = ro;
    o2.equinox = PMRUN_EQUINOX_J2000;
    o2.skip_bad = 1;
    pmrun *other = nullptr;
    char err[1024];
    if (pmrun_read(path.c_str(), &o2, &other, err, sizeof err) != 0)
        return;
    std::unique_ptr<pmrun, void (*)(pmrun *)> guard(other, pmrun_free);
    Run j = run_from_pmrun(other, path);
    double sigma[2];
    const Run *runs[2] = {&r, &j};
    for (int k = 0; k < 2; k++) {
        const pm_model m =
            build_model(0, k == 0 ? std::vector<std::string>{"refraction"} : std::vector<std::string>{},
                        runs[k]->obs, runs[k]->mount, runs[k]->latitude, runs[k]->aux_names);
        FitOut f = do_fit(runs[k]->obs, all_of(runs[k]->obs.size()), m, FIT_MAX_PASSES);
        if (f.status != PM_OK)
            return;
        sigma[k] = f.res.sigma * RAD2AS;
    }
    if (sigma[1] < sigma[0] / 3 && sigma[0] - sigma[1] > 5) {
        char b[400];
        std::snprintf(b, sizeof b,
                      "%s: its true places fit far better as J2000 places (order 0 sigma %.3g\" "
                      "reduced from J2000, %.3g\" as they are with a refraction term; they were "
                      "read as they are): image "
                      "astrometry gives J2000; read it with --equinox J2000 (in Python, "
                      "read_run(..., equinox=\"J2000\"))",
                      path.c_str(), sigma[1], sigma[0]);
        r.notes.push_back(b);
    }
}

Run run_from_pmrun(const pmrun *run, const std::string &path, bool az_count)
{
    Run r;
    r.path = path;
    r.mount = pmrun_mount(run) == PMRUN_MOUNT_ALTAZ ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
    r.latitude = pmrun_latitude_rad(run);
    for (int i = 0; i < pmrun_n_warnings(run); i++)
        r.notes.push_back(pmrun_warning(run, i));
    for (size_t i = 0; i < pmrun_count(run); i++) {
        const pmrun_obs *p = pmrun_get(run, i);
        Obs ob{p->enc_ha, p->enc_dec, p->app_ha, p->app_dec, p->pier, p->line, pm_context()};
        std::memset(&ob.ctx, 0, sizeof ob.ctx);
        ob.raw1 = p->enc_raw[0];
        ob.ctx.temp_c = p->temp_c;
        ob.ctx.time_h = p->time_h;
        ob.ctx.pier = p->pier;
        ob.ctx.dir = p->dir;
        for (int j = 0; j < PM_MAX_AUX && j < PMRUN_MAX_AUX; j++)
            ob.ctx.aux[j] = p->aux[j];
        r.obs.push_back(ob);
    }
    for (int j = 0; j < pmrun_n_aux(run); j++) {
        r.aux_names.push_back(pmrun_aux_name(run, j));
        std::vector<double> col;
        for (size_t i = 0; i < pmrun_count(run) && j < PMRUN_MAX_AUX; i++)
            col.push_back(pmrun_get(run, i)->aux[j]);
        r.aux_values.push_back(col);
    }
    derive_directions(r, az_count);
    return r;
}

// The sign of the move from angle a to angle b (radians) of an axis whose
// path never crosses `cut` (cut_ok), else the short way round.
static int move_sign(double a, double b, double cut, bool cut_ok)
{
    /* (remainder(x - cut - pi) jumps at x = cut only) */
    double d = cut_ok ? std::remainder(b - cut - PI, 2 * PI) - std::remainder(a - cut - PI, 2 * PI)
                      : std::remainder(b - a, 2 * PI);
    return d > 0 ? 1 : (d < 0 ? -1 : 0);
}

double widest_gap(const std::vector<double> &ang, double *middle)
{
    std::vector<double> a;
    for (double x : ang)
        if (std::isfinite(x))
            a.push_back(x - 2 * PI * std::floor(x / (2 * PI)));
    if (middle)
        *middle = 0;
    if (a.size() < 2)
        return 2 * PI;
    std::sort(a.begin(), a.end());
    double gap = a.front() + 2 * PI - a.back(), at = a.back() + 0.5 * gap;
    for (size_t k = 1; k < a.size(); k++)
        if (a[k] - a[k - 1] > gap) {
            gap = a[k] - a[k - 1];
            at = a[k - 1] + 0.5 * gap;
        }
    if (middle)
        *middle = std::remainder(at, 2 * PI);
    return gap;
}

// Where an axis's path never goes: the middle of the widest empty arc of
// its angles over the run, when that arc is wider than a quarter turn.  A
// mount does not turn its axis through a zone it never points into (a
// German mount's counterweight-up half, a fork's HA beyond +-180 deg under
// the pole, the ends of a cable wrap), so a move between the arc's two
// sides goes the long way round, not across it.  A narrower empty arc is a
// gap of the sampling.  False (and *cut untouched) without such an arc.
static bool axis_cut(const std::vector<double> &ang, double *cut)
{
    double middle;
    if (ang.size() < 2 || !(widest_gap(ang, &middle) > 0.5 * PI))
        return false;
    *cut = middle;
    return true;
}

const char *axis2_dir_name(int mount)
{
    return mount == PM_MOUNT_ALTAZ ? "el_dir" : "dec_dir";
}

std::string mount_words(const std::string &s, int mount)
{
    if (mount != PM_MOUNT_ALTAZ)
        return s;
    std::string r = s;
    static const char *const from[2] = {"ha_periodic", "dec_periodic"};
    static const char *const to[2] = {"az_periodic", "el_periodic"};
    for (int k = 0; k < 2; k++) {
        const std::string f = from[k], t = to[k];
        for (size_t p = r.find(f); p != std::string::npos; p = r.find(f, p + t.size())) {
            const bool word_start =
                p == 0 || !(std::isalnum((unsigned char)r[p - 1]) || r[p - 1] == '_');
            const size_t e = p + f.size();
            const bool paper = r.compare(e, 6, "_paper") == 0; // (the paper's form keeps its name)
            if (word_start && !paper)
                r.replace(p, f.size(), t);
        }
    }
    return r;
}

// Every observation has axis 1 as its file wrote it (runs from arrays
// have none), and there is one.
static bool raw_known(const std::vector<Obs> &obs)
{
    return !obs.empty() && std::all_of(obs.begin(), obs.end(),
                                       [](const Obs &ob) { return std::isfinite(ob.raw1); });
}

// The derived input `name` appended to the run's columns (a context slot
// of each observation, and the run's columns as read where they are kept
// alongside: run_for_model takes an input from there by its name).
static void add_derived_input(Run &r, const std::string &name, const std::vector<double> &v)
{
    const int j = (int)r.aux_names.size();
    r.aux_names.push_back(name);
    for (size_t i = 0; i < r.obs.size(); i++)
        r.obs[i].ctx.aux[j] = v[i];
    if (r.aux_values.size() == (size_t)j)
        r.aux_values.push_back(v);
}

// True where the file wrote axis 1 as a count that runs on past a turn
// (every value finite, and not all within one of the two ranges a modular
// writer uses, 0..360 and -180..180 deg, both ends and a micro-degree
// beyond them included: atan2 gives -180 as well as 180, and 359.9999997
// printed to six decimals is 360.000000, and one such record had read a
// whole run as a count, every move across the cut the long way round; an
// outside probe): an alt-az controller's cable wrap, e.g. -270..270 or
// 90..450 deg.  The count then says which way the axis went between two
// points, however far; an outside probe's runs with the azimuth written
// 90..450 deg had their backlash read at half its size from the short way
// round, and false gear periods beside it.
static bool raw_counted(const std::vector<Obs> &obs)
{
    const double eps = 1e-6 * PI / 180, turn = 2 * PI;
    bool in_0_360 = true, in_pm180 = true;
    for (const Obs &ob : obs) {
        in_0_360 = in_0_360 && ob.raw1 >= -eps && ob.raw1 <= turn + eps;
        in_pm180 = in_pm180 && ob.raw1 >= -PI - eps && ob.raw1 <= PI + eps;
    }
    return raw_known(obs) && !in_0_360 && !in_pm180;
}

void derive_directions(Run &r, bool az_count)
{
    std::vector<double> e1, e2;
    for (const Obs &ob : r.obs) {
        e1.push_back(ob.eh);
        e2.push_back(ob.ed);
    }
    // Without such an arc: an equatorial mount's axis 1 does not pass under
    // the pole (encoder HA +-180 deg: a fork's limit; a German mount always
    // leaves its counterweight-up arc empty), an alt-az azimuth is taken the
    // short way round (a cable wrap's ends are not in the file).
    double cut1 = PI, cut2 = PI; /* axis 2 without: the encoder angle's own ends */
    const bool ok1 = axis_cut(e1, &cut1) || r.mount == PM_MOUNT_EQUATORIAL;
    axis_cut(e2, &cut2);
    bool have_dir = false;
    for (const Obs &ob : r.obs)
        have_dir = have_dir || ob.ctx.dir != 0;
    const bool counted =
        r.mount == PM_MOUNT_ALTAZ && (raw_counted(r.obs) || (az_count && raw_known(r.obs)));
    r.az_count = counted && az_count;
    if (!have_dir) {
        r.dir_derived = true;
        // (the count's sense against the encoder angle's: a reader may
        // count the file's azimuth from the south, or the other way round)
        double sense = 0;
        for (size_t i = 1; counted && i < r.obs.size(); i++)
            sense += std::remainder(r.obs[i].eh - r.obs[i - 1].eh, 2 * PI) *
                     std::remainder(r.obs[i].raw1 - r.obs[i - 1].raw1, 2 * PI);
        for (size_t i = 1; i < r.obs.size(); i++) {
            const double d = (r.obs[i].raw1 - r.obs[i - 1].raw1) * (sense < 0 ? -1 : 1);
            r.obs[i].ctx.dir = counted ? (d > 0 ? 1 : (d < 0 ? -1 : 0))
                                       : move_sign(r.obs[i - 1].eh, r.obs[i].eh, cut1, ok1);
        }
    }
    // The slew direction on axis 2, likewise from the sequence, as the input
    // "dec_dir" ("el_dir" on an alt-az mount; backlash of the declination or
    // elevation drive), when the run has no such column and a context slot
    // is free.  (An alt-az run's had been called dec_dir: "e'*dec_dir" for
    // the elevation index.)
    const std::string dir2 = axis2_dir_name(r.mount);
    bool have_dec_dir = false;
    for (const std::string &n : r.aux_names)
        have_dec_dir = have_dec_dir || n == dir2;
    if (!have_dec_dir && (int)r.aux_names.size() < PM_MAX_AUX && r.obs.size() > 1) {
        std::vector<double> v(r.obs.size(), 0.0);
        for (size_t i = 1; i < r.obs.size(); i++)
            v[i] = move_sign(r.obs[i - 1].ed, r.obs[i].ed, cut2, true);
        add_derived_input(r, dir2, v);
        r.dec_dir_derived = true;
    }
    // The turn of an alt-az cable wrap, as the input "az_turn": where the
    // file counts its azimuth past a turn (raw_counted) and the run's count
    // crosses a multiple of 360 deg, the count's own turn (floor(count / 360
    // deg)) less the least one's: 0 and 1, or 2 where the count crosses two
    // (the pointing may differ on the next turn: the cables' drag, a
    // wrap-dependent offset; an outside probe's 30" on the turn beyond 360
    // deg was called bad points or false gears, over -270..270 deg and over
    // 90..450, where each azimuth has one count and the turn is a step at
    // north).  When a context slot is free and the run has no such column.
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const Obs &ob : r.obs) {
        lo = std::min(lo, ob.raw1);
        hi = std::max(hi, ob.raw1);
    }
    if (counted && std::floor(hi / (2 * PI)) != std::floor(lo / (2 * PI)) &&
        std::find(r.aux_names.begin(), r.aux_names.end(), "az_turn") == r.aux_names.end() &&
        (int)r.aux_names.size() < PM_MAX_AUX) {
        std::vector<double> v;
        for (const Obs &ob : r.obs)
            v.push_back(std::floor(ob.raw1 / (2 * PI)) - std::floor(lo / (2 * PI)));
        add_derived_input(r, "az_turn", v);
        r.turn_derived = true;
    }
    // And how far the wrap is wound, "az_wind": the count in turns (count /
    // 360 deg, zero at the count's zero, the middle of a -270..270 wrap), for
    // a drag that grows with the wind, a line and not a step at a turn (an
    // outside probe's drag of 100" over -270..270 deg was named a step "on
    // the next turn", sigma 12.9" left for 10" of noise, a false gear beside
    // it in another run).  Where az_turn is, and a slot is free.
    if (r.turn_derived &&
        std::find(r.aux_names.begin(), r.aux_names.end(), "az_wind") == r.aux_names.end() &&
        (int)r.aux_names.size() < PM_MAX_AUX) {
        std::vector<double> v;
        for (const Obs &ob : r.obs)
            v.push_back(ob.raw1 / (2 * PI));
        add_derived_input(r, "az_wind", v);
        r.wind_derived = true;
    }
}

// The run with its slew directions read from the azimuth as the mount's
// count, and how many of them differ from the run's (0 where the reading
// does not apply: not alt-az, directions given or already counted, no raw
// azimuth, fewer than 10 points).
static long count_directions(const Run &run, Run *rc)
{
    if (run.mount != PM_MOUNT_ALTAZ || !run.dir_derived || run.az_count || run.obs.size() < 10 ||
        !raw_known(run.obs) || raw_counted(run.obs))
        return 0;
    *rc = run;
    for (Obs &o : rc->obs)
        o.ctx.dir = 0;
    derive_directions(*rc, true);
    long differ = 0;
    for (size_t i = 0; i < run.obs.size(); i++)
        differ += rc->obs[i].ctx.dir != run.obs[i].ctx.dir;
    return differ;
}

bool count_reading_possible(const Run &run)
{
    Run rc;
    return count_directions(run, &rc) >= 3;
}

std::string count_reading_hint(const Run &run, int order, const std::vector<std::string> &adds)
{
    Run rc;
    const long differ = count_directions(run, &rc);
    if (differ < 3)
        return "";
    std::vector<std::string> h = adds;
    if (std::find(h.begin(), h.end(), "hysteresis") == h.end())
        h.push_back("hysteresis");
    const std::vector<int> use = all_of(run.obs.size());
    FitOut f[3];
    try {
        f[0] = do_fit(run.obs, use, build_model(order, h, run.obs, run.mount, run.latitude,
                                                run.aux_names));
        f[1] = do_fit(rc.obs, use, build_model(order, h, rc.obs, rc.mount, rc.latitude,
                                               rc.aux_names));
        f[2] = do_fit(run.obs, use, build_model(order, adds, run.obs, run.mount, run.latitude,
                                                run.aux_names));
    } catch (const std::exception &) {
        return "";
    }
    // The short way's reference: the better of its fit with the backlash
    // and without (a sky that hardly determines the terms can stop the
    // larger fit above the smaller), and the count's fit must beat it by
    // 100 sigma^2: a clean run in a 10 deg band of elevation, whose fits
    // creep for hundreds of passes, came out 28 sigma^2 apart (a backlash
    // of 1" in 1" of noise over 30 moves read otherwise is about 120).
    if (f[0].status != PM_OK || f[1].status != PM_OK || f[2].status != PM_OK)
        return "";
    const double ref = std::min(f[0].res.chi2, f[2].res.chi2);
    if (!(ref - f[1].res.chi2 > 100 * f[1].res.sigma * f[1].res.sigma))
        return "";
    char b[600];
    std::snprintf(b, sizeof b,
                  "the slew directions fit far better with the file's azimuth read as the "
                  "mount's count, never through its 0/360 deg seam (%ld of %zu moves then go the "
                  "other way; with a backlash term sigma %.3g\" against %.3g\" the short way "
                  "round): a cable wrap that does not let the mount turn through the seam? "
                  "Read so with --azimuth-count",
                  differ, run.obs.size() - 1, f[1].res.sigma * RAD2AS, f[0].res.sigma * RAD2AS);
    return b;
}

std::string term_name(const pm_model &m, int i)
{
    char buf[32];
    pm_term_name(&m, i, buf, sizeof buf);
    return buf;
}

int term_index(const pm_model &m, const std::string &name, int n)
{
    int found = -1;
    for (int i = 0; i < (n < 0 ? m.n_terms : n); i++)
        if (term_name(m, i) == name)
            found = i;
    return found;
}

// Physical meaning of a term, for the table.
std::string meaning(const pm_model &m, int i, const std::vector<std::string> *aux_names)
{
    const pm_term &t = m.term[i];
    bool altaz = m.mount == PM_MOUNT_ALTAZ;
    if (t.kind == PM_TERM_SH && t.l == 0 && t.side == 0) {
        switch (t.k) {
        case 1: return altaz ? "azimuth axis tilt (x)" : "polar axis misalignment (x)";
        case 2: return altaz ? "azimuth axis tilt (y)" : "polar axis misalignment (y)";
        case 3: return altaz ? "azimuth index [IA]" : "HA index [IH]";
        case 4: return "axis non-perpendicularity [NP]";
        case 5: return altaz ? "elevation index [IE]" : "Dec index [ID]";
        case 6: return "collimation [CH/CA]";
        }
    }
    static const char *base[] = {"", "tilt x", "tilt y", "axis-1 index", "non-perp.",
                                 "axis-2 index", "collimation"};
    std::string side = t.side > 0 ? ", east side" : (t.side < 0 ? ", west side" : "");
    char g[32];
    std::snprintf(g, sizeof g, "%g", t.param);
    switch (t.kind) {
    case PM_TERM_FOURIER:
        return std::string("periodic error, ") + g + " cyc/rev of axis " +
               (t.l == 1 ? "1" : "2") + (t.m ? " (sin)" : " (cos)") + side;
    case PM_TERM_SECTORAL:
        return std::string("paper-form periodic Y(") + g + ",+-" + g + ")" + side;
    case PM_TERM_ZENITH:
        return std::string(t.l == 0 ? "refraction-like cot(el)" : "tube flexure cos(el)") + side;
    case PM_TERM_AUX: {
        const size_t j = (size_t)(t.aux - PM_AUX_USER);
        const std::string in =
            t.aux == PM_AUX_TEMP ? "temperature"
            : t.aux == PM_AUX_TIME ? "time drift"
            : t.aux == PM_AUX_DIR ? "hysteresis (slew dir)"
            : aux_names && t.aux >= PM_AUX_USER && j < aux_names->size()
                ? "column '" + (*aux_names)[j] + "'"
                : "aux input";
        return in + " on " + base[t.k] + " [per unit]" + side;
    }
    }
    if (t.l == 0)
        return std::string(base[t.k]) + side;
    return std::string(base[t.k]) + " varying as Y(" + std::to_string(t.l) + "," +
           std::to_string(t.m) + ")" + side;
}

std::string json_escape(const std::string &s)
{
    std::string o;
    for (char c : s) {
        if (c == '"' || c == '\\')
            o += '\\', o += c;
        else if ((unsigned char)c < 0x20) {
            char b[8];
            std::snprintf(b, sizeof b, "\\u%04x", c);
            o += b;
        } else
            o += c;
    }
    return o;
}

// log of the regularised incomplete beta I_x(a, b) by its continued fraction
// (modified Lentz), in logarithms so that tiny tails do not underflow; the
// direct branch, valid for x < (a+1)/(a+b+2).
static double log_inc_beta_cf(double a, double b, double x)
{
    double lbeta = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b);
    double logfront = lbeta + a * std::log(x) + b * std::log1p(-x) - std::log(a);
    const double tiny = 1e-300;
    double f = 1, c = 1, d = 0;
    for (int i = 0; i <= 600; i++) {
        int mm = i / 2;
        double num;
        if (i == 0)
            num = 1;
        else if (i % 2 == 0)
            num = mm * (b - mm) * x / ((a + 2 * mm - 1) * (a + 2 * mm));
        else
            num = -(a + mm) * (a + b + mm) * x / ((a + 2 * mm) * (a + 2 * mm + 1));
        d = 1 + num * d;
        d = std::fabs(d) < tiny ? tiny : d;
        d = 1 / d;
        c = 1 + num / c;
        c = std::fabs(c) < tiny ? tiny : c;
        f *= c * d;
        if (std::fabs(1 - c * d) < 1e-15)
            break;
    }
    return logfront + std::log(f - 1);
}

double inc_beta(double a, double b, double x)
{
    if (x <= 0)
        return 0;
    if (x >= 1)
        return 1;
    if (x > (a + 1) / (a + b + 2))
        return 1 - std::exp(log_inc_beta_cf(b, a, 1 - x));
    return std::exp(log_inc_beta_cf(a, b, x));
}

double log_f_tail(double f, double d1, double d2)
{
    if (!(f > 0))
        return 0;
    double a = d2 / 2, b = d1 / 2, x = d2 / (d2 + d1 * f);
    if (x < (a + 1) / (a + b + 2))
        return log_inc_beta_cf(a, b, x);
    double q = std::exp(log_inc_beta_cf(b, a, 1 - x));
    return std::log1p(-std::min(q, 1.0));
}

double f_tail(double f, double d1, double d2) { return std::exp(log_f_tail(f, d1, d2)); }

FTest f_test(double chi2_small, int p_small, double chi2_big, int p_big, long n_obs,
             const std::string &what)
{
    FTest t;
    t.done = true;
    t.what = what;
    t.d1 = p_big - p_small;
    t.d2 = 2 * n_obs - p_big;
    if (t.d1 <= 0 || t.d2 <= 0 || !(chi2_big > 0)) {
        t.done = false;
        return t;
    }
    t.f = ((chi2_small - chi2_big) / t.d1) / (chi2_big / (double)t.d2);
    t.p = f_tail(t.f, t.d1, (double)t.d2);
    return t;
}

// Residuals of f.model on the observations `use`, and their RMS on the sky
// (fitrun.hpp).  A residual the model cannot give is NaN, not the 0 that
// pm_model_residual leaves: pmfit eval of a temperature model on a run
// without temperatures printed "sky RMS 0.000"".
pm_status residuals(FitOut &f, const std::vector<Obs> &obs, const std::vector<int> &use,
                    size_t *bad)
{
    double ss = 0;
    size_t n = 0;
    pm_status first = PM_OK;
    for (size_t j = 0; j < use.size(); j++) {
        const int i = use[j];
        double r[2] = {NAN, NAN};
        pm_status st = pm_model_residual(&f.model, &obs[i].ctx, obs[i].eh, obs[i].ed, obs[i].ah,
                                         obs[i].ad, r);
        if (st != PM_OK) {
            r[0] = r[1] = NAN;
            if (first == PM_OK) {
                first = st;
                if (bad)
                    *bad = j;
            }
        } else {
            ss += r[0] * r[0] + r[1] * r[1];
            n++;
        }
        f.r0.push_back(r[0]);
        f.r1.push_back(r[1]);
        f.idx.push_back(i);
    }
    f.rms = n ? std::sqrt(ss / (double)n) : 0;
    return first;
}

FitOut do_fit(const std::vector<Obs> &obs, const std::vector<int> &use, const pm_model &start,
              int max_passes)
{
    thread_local static pm_fit fit; // large; not on the stack (one per thread: parallel_for)
    return do_fit(fit, obs, use, start, max_passes);
}

FitOut do_fit(pm_fit &fit, const std::vector<Obs> &obs, const std::vector<int> &use,
              const pm_model &start, int max_passes)
{
    FitOut f;
    f.model = start;
    std::vector<double> eh, ed, ah, ad;
    std::vector<pm_context> ctx;
    bool east = false, west = false;
    for (int i : use) {
        east = east || obs[i].pier > 0;
        west = west || obs[i].pier < 0;
        eh.push_back(obs[i].eh);
        ed.push_back(obs[i].ed);
        ah.push_back(obs[i].ah);
        ad.push_back(obs[i].ad);
        ctx.push_back(obs[i].ctx);
    }
    f.both_sides = east && west;
    f.status = pm_fit_run(&fit, &f.model, ctx.data(), (long)use.size(), eh.data(), ed.data(),
                          ah.data(), ad.data(), max_passes, &f.res);
    f.bad_term = f.status == PM_OK ? -1 : fit.bad_term;
    if (f.status != PM_OK) { // res is not filled in on error: N and P for the message
        f.res.n_obs = (long)use.size();
        f.res.n_par = start.n_terms;
    }
    if (f.status == PM_OK || (f.status == PM_ERR_DIVERGED && fit.iterations > 0)) {
        // the most nearly degenerate pair of the last accepted pass
        pm_fit_result unit;
        std::memset(&unit, 0, sizeof unit);
        unit.sigma = 1;
        for (int i = 0; i < fit.n_par; i++)
            for (int j = 0; j < i; j++) {
                double c, r;
                if (pm_fit_covariance(&fit, &unit, i, j, &c, &r) == PM_OK &&
                    std::fabs(r) > std::fabs(f.corr)) {
                    f.corr = r;
                    f.corr_i = i;
                    f.corr_j = j;
                }
            }
    }
    if (f.status != PM_OK)
        return f;
    int P = f.model.n_terms;
    f.cov.assign((size_t)P * (size_t)P, 0.0);
    for (int i = 0; i < P; i++)
        for (int j = 0; j <= i; j++) {
            double c = 0;
            pm_fit_covariance(&fit, &f.res, i, j, &c, nullptr);
            f.cov[(size_t)i * P + j] = f.cov[(size_t)j * P + i] = c;
        }
    residuals(f, obs, use);
    return f;
}

bool row_covariance(const FitOut &f, const pm_context &ctx, double eh, double ed, double ah,
                    double ad, double v[3], double r[2])
{
    const int P = f.model.n_terms;
    double j0[PM_MAX_TERMS], j1[PM_MAX_TERMS];
    if (f.cov.size() != (size_t)P * (size_t)P ||
        pm_fit_row(&f.model, &ctx, eh, ed, ah, ad, j0, j1, r) != PM_OK)
        return false;
    v[0] = v[1] = v[2] = 0;
    for (int a = 0; a < P; a++) {
        const double *c = &f.cov[(size_t)a * P];
        double x0 = 0, x1 = 0;
        for (int b = 0; b < P; b++) {
            x0 += c[b] * j0[b];
            x1 += c[b] * j1[b];
        }
        v[0] += j0[a] * x0;
        v[1] += j0[a] * x1;
        v[2] += j1[a] * x1;
    }
    return true;
}

// Base vectors named in a list like "c',e',i" (default: def).
std::vector<int> parse_bases(const std::string &spec, const std::string &list,
                             const std::vector<int> &def)
{
    if (list.empty())
        return def;
    std::vector<int> ks;
    size_t pos = 0;
    while (pos <= list.size()) {
        size_t c = list.find(',', pos);
        std::string b = list.substr(pos, c == std::string::npos ? std::string::npos : c - pos);
        static const char *names[] = {"a", "b", "c'", "d", "e'", "i"};
        int k = 0;
        for (int j = 0; j < 6; j++)
            if (b == names[j])
                k = j + 1;
        if (!k)
            throw std::runtime_error("--add " + spec + ": unknown base vector '" + b + "' (expected a, b, c', d, e', i)");
        ks.push_back(k);
        if (c == std::string::npos)
            break;
        pos = c + 1;
    }
    return ks;
}

// One --add specification taken apart: its ':' fields and the pier side of
// an '@E' / '@W' suffix (0: both sides).
struct AddSpec {
    std::string spec, body;
    std::vector<std::string> f;
    int side = 0;
};

static AddSpec split_add(const std::string &spec)
{
    AddSpec a;
    a.spec = spec;
    a.body = spec;
    if (a.body.size() > 2 && a.body[a.body.size() - 2] == '@') {
        char c = a.body.back();
        a.side = c == 'E' || c == 'e' ? 1 : (c == 'W' || c == 'w' ? -1 : 0);
        if (!a.side)
            throw std::runtime_error("--add " + spec + ": expected @E or @W for a pier side");
        a.body = a.body.substr(0, a.body.size() - 2);
    }
    size_t pos = 0, c;
    while ((c = a.body.find(':', pos)) != std::string::npos) {
        a.f.push_back(a.body.substr(pos, c - pos));
        pos = c + 1;
    }
    a.f.push_back(a.body.substr(pos));
    return a;
}

// The model being built, and how a term joins it.
struct ModelBuilder {
    pm_model m;
    int mount;
    double lat;
    void add(const std::string &spec, pm_term t)
    {
        int st = pm_model_add_term(&m, &t, 0.0, nullptr);
        if (st == PM_ERR_CAPACITY)
            throw std::runtime_error("--add " + spec + ": more than " + std::to_string(PM_MAX_TERMS) +
                " terms (this build's PM_MAX_TERMS)");
        if (st != PM_OK)
            throw std::runtime_error("--add " + spec + ": not a valid term for this model");
    }
};

// ha_periodic:G[:H], dec_periodic:G[:H]: G cycles per revolution of the
// axis, harmonics 1..H, a sine and a cosine each.
static void add_periodic(ModelBuilder &b, const AddSpec &a, pm_term t)
{
    const std::string &name = a.f[0];
    if (a.f.size() < 2 || a.f.size() > 3)
        throw std::runtime_error("--add " + a.spec + ": expected " + // (the user's name)
                                 a.body.substr(0, a.body.find(':')) + ":G[:H]");
    char *end;
    double G = std::strtod(a.f[1].c_str(), &end);
    if (*end || !(G > 0 && G <= 100000))
        throw std::runtime_error("--add " + a.spec + ": G must be cycles per revolution, "
                                 "> 0 and <= 100000");
    long H = a.f.size() == 3 ? std::strtol(a.f[2].c_str(), &end, 10) : 1;
    if (a.f.size() == 3 && (*end || H < 1 || H > 8))
        throw std::runtime_error("--add " + a.spec + ": H must be 1..8 harmonics");
    t.kind = PM_TERM_FOURIER;
    t.l = (signed char)(name == "ha_periodic" ? 1 : 2);
    t.k = (unsigned char)(name == "ha_periodic" ? PM_BASE_C : PM_BASE_E);
    for (long h = 1; h <= H; h++)
        for (int sc = 0; sc < 2; sc++) {
            t.param = G * (double)h;
            t.m = (signed char)sc;
            b.add(a.spec, t);
        }
}

// ha_periodic_paper:G: the paper's Y(G, +-G) form, integer G.
static void add_periodic_paper(ModelBuilder &b, const AddSpec &a, pm_term t)
{
    char *end;
    long G = a.f.size() == 2 ? std::strtol(a.f[1].c_str(), &end, 10) : 0;
    if (a.f.size() != 2 || *end || G < 1 || G > 100000)
        throw std::runtime_error("--add " + a.spec + ": expected ha_periodic_paper:G with an integer G");
    t.kind = PM_TERM_SECTORAL;
    t.k = PM_BASE_C;
    t.param = (double)G;
    for (int sc = 0; sc < 2; sc++) {
        t.m = (signed char)sc;
        b.add(a.spec, t);
    }
}

// refraction, tube_flexure: cot(el) or cos(el) toward the zenith.
static void add_zenith(ModelBuilder &b, const AddSpec &a, pm_term t)
{
    if (a.f.size() != 1)
        throw std::runtime_error("--add " + a.spec + ": takes no arguments");
    if (b.mount == PM_MOUNT_EQUATORIAL && std::isnan(b.lat))
        throw std::runtime_error("--add " + a.spec + ": needs the site latitude, which the run file does not "
            "give (a '# latitude: DEG' line or a TPOINT run line)");
    t.kind = PM_TERM_ZENITH;
    t.l = (signed char)(a.f[0] == "refraction" ? 0 : 1);
    b.add(a.spec, t);
}

// The mean of an auxiliary input over the run (the term's reference, so that
// it is decorrelated from the index); every observation must give a value,
// and the slew direction must be known for nine in ten.
static double aux_mean(const AddSpec &a, int input, const std::vector<Obs> &obs)
{
    double sum = 0;
    size_t no_dir = 0;
    for (const Obs &ob : obs) {
        const pm_context &c = ob.ctx;
        double x = input == PM_AUX_TEMP ? c.temp_c
                   : input == PM_AUX_TIME ? c.time_h
                   : input == PM_AUX_DIR ? (double)c.dir : c.aux[input - PM_AUX_USER];
        if (!std::isfinite(x))
            throw std::runtime_error("--add " + a.spec + ": the run gives no value for the observation at "
                "line " + std::to_string(ob.line));
        no_dir += input == PM_AUX_DIR && x == 0;
        sum += x;
    }
    if (no_dir * 10 > obs.size()) // 0 = unknown; the first point always is
        throw std::runtime_error("--add " + a.spec + ": the slew direction is unknown for " +
            std::to_string(no_dir) + " of " + std::to_string(obs.size()) + " observations");
    return obs.empty() ? 0 : sum / (double)obs.size();
}

// temperature, time_drift, hysteresis, aux:NAME, each [:BASES]: the input
// (minus its mean) times the chosen base vectors.
static void add_aux(ModelBuilder &b, const AddSpec &a, pm_term t, const std::vector<Obs> &obs,
                    const std::vector<std::string> &aux_names)
{
    const std::string &name = a.f[0];
    int input;
    std::vector<int> def = {PM_BASE_C, PM_BASE_E};
    size_t bases_at = 1;
    if (name == "temperature")
        input = PM_AUX_TEMP;
    else if (name == "time_drift")
        input = PM_AUX_TIME;
    else if (name == "hysteresis") {
        input = PM_AUX_DIR;
        def = {PM_BASE_C};
    } else {
        if (a.f.size() < 2)
            throw std::runtime_error("--add " + a.spec + ": expected aux:NAME[:BASES]");
        int j = -1;
        for (size_t q = 0; q < aux_names.size(); q++)
            if (aux_names[q] == a.f[1])
                j = (int)q;
        if (j < 0) {
            static const char *const builtin[][2] = {{"temp", "temperature"},
                                                     {"time", "time_drift"},
                                                     {"dir", "hysteresis"},
                                                     {"pier", "TERM@E or TERM@W"}};
            for (const auto &bi : builtin)
                if (a.f[1] == bi[0])
                    throw std::runtime_error("--add " + a.spec + ": '" + a.f[1] +
                                             "' is a built-in input, not an auxiliary column: "
                                             "--add " + bi[1] + " reads it");
            throw std::runtime_error("--add " + a.spec + ": the run has no column '" + a.f[1] + "'");
        }
        if (j >= PM_MAX_AUX)
            throw std::runtime_error("--add " + a.spec + ": column '" + a.f[1] + "' is beyond the first " +
                std::to_string(PM_MAX_AUX) + " auxiliary columns the core takes");
        input = PM_AUX_USER + j;
        bases_at = 2;
    }
    if (a.f.size() > bases_at + 1)
        throw std::runtime_error("--add " + a.spec + ": too many ':' fields");
    std::vector<int> ks = parse_bases(a.spec, a.f.size() > bases_at ? a.f[bases_at] : std::string(), def);
    t.kind = PM_TERM_AUX;
    t.aux = (unsigned char)input;
    t.param = aux_mean(a, input, obs);
    for (int k : ks) {
        t.k = (unsigned char)k;
        b.add(a.spec, t);
    }
}

// A harmonic term of the model by name (c'*Y(1,0)@E ...), for one pier side.
static void add_side_harmonic(ModelBuilder &b, const AddSpec &a)
{
    int found = term_index(b.m, a.body, b.m.n_base);
    if (found < 0)
        throw std::runtime_error("--add " + a.spec + ": unknown effect or term (see pmfit --help)");
    if (!a.side)
        throw std::runtime_error("--add " + a.spec + ": " + a.body + " is already in the model; add it for one "
            "pier side with " + a.body + "@E or " + a.body + "@W");
    pm_term t = b.m.term[found];
    t.side = (signed char)a.side;
    b.add(a.spec, t);
}

// The model to fit: the harmonic set of the order plus the --add effects.
pm_model build_model(int order, const std::vector<std::string> &adds,
                     const std::vector<Obs> &obs, int mount, double lat,
                     const std::vector<std::string> &aux_names)
{
    ModelBuilder b;
    b.mount = mount;
    b.lat = lat;
    if (pm_model_init(&b.m, mount, order) != PM_OK)
        throw std::runtime_error("order " + std::to_string(order) + ": not a valid order for this build (0.." +
            std::to_string(PM_MAX_L) + ")");
    b.m.latitude = std::isnan(lat) ? 0.0 : lat;
    pm_model_prepare(&b.m);
    for (const std::string &spec : adds) {
        AddSpec a = split_add(spec);
        pm_term t;
        std::memset(&t, 0, sizeof t);
        t.side = (signed char)a.side;
        if (a.f[0] == "az_periodic" || a.f[0] == "el_periodic") {
            // (an alt-az mount's names of axis 1 and 2's periodic errors)
            if (mount != PM_MOUNT_ALTAZ)
                throw std::runtime_error("--add " + spec + ": " + a.f[0] + " is an alt-az mount's; "
                                         "on an equatorial mount the axes' periodic errors are "
                                         "ha_periodic and dec_periodic");
            a.f[0] = a.f[0] == "az_periodic" ? "ha_periodic" : "dec_periodic";
        }
        const std::string &name = a.f[0];
        if (name == "ha_periodic" || name == "dec_periodic")
            add_periodic(b, a, t);
        else if (name == "ha_periodic_paper")
            add_periodic_paper(b, a, t);
        else if (name == "refraction" || name == "tube_flexure")
            add_zenith(b, a, t);
        else if (name == "temperature" || name == "time_drift" || name == "hysteresis" || name == "aux")
            add_aux(b, a, t, obs, aux_names);
        else
            add_side_harmonic(b, a);
    }
    return b.m;
}

Run run_for_model(const Run &run, const pm_model &m, const std::vector<std::string> &inputs,
                  int pier, const std::string &model_name, std::vector<std::string> *notes)
{
    Run r = run;
    r.aux_names.assign(PM_MAX_AUX, std::string());
    std::vector<bool> used(PM_MAX_AUX, false);
    std::vector<std::string> readers(PM_MAX_AUX);
    for (int i = m.n_base; i < m.n_terms; i++) {
        const int j = m.term[i].aux - PM_AUX_USER;
        if (m.term[i].kind == PM_TERM_AUX && j >= 0 && j < PM_MAX_AUX) {
            readers[(size_t)j] += (used[(size_t)j] ? ", " : "") + term_name(m, i);
            used[(size_t)j] = true;
        }
    }
    auto columns = [&run]() {
        std::string c;
        for (const std::string &n : run.aux_names)
            c += (c.empty() ? "" : ", ") + n +
                 (n == axis2_dir_name(run.mount) && run.dec_dir_derived
                      ? " (derived from the sequence)"
                  : (n == "az_turn" && run.turn_derived) || (n == "az_wind" && run.wind_derived)
                      ? " (derived from the azimuth count)"
                      : "");
        return c.empty() ? std::string("none") : c;
    };
    for (size_t j = 0; j < (size_t)PM_MAX_AUX; j++) {
        const std::string name = j < inputs.size() ? inputs[j] : std::string();
        // "its term X reads" / "its terms X, Y read"
        const bool several = readers[j].find(',') != std::string::npos;
        const std::string terms_read = std::string(several ? "terms " : "term ") + readers[j] +
                                       (several ? " read" : " reads");
        long from = -1;
        if (used[j] && name.empty()) {
            /* a model file that does not name its inputs: by position, said */
            from = (long)j;
            if (j < run.aux_names.size() && notes)
                notes->push_back(model_name + " does not name the column its " + terms_read +
                                 " (a version-3 file, or its 'input' line left out): " +
                                 run.path + "'s auxiliary column " + std::to_string(j + 1) +
                                 ", '" + run.aux_names[j] + "', is taken for it");
        } else if (used[j]) {
            for (size_t q = 0; q < run.aux_names.size() && from < 0; q++)
                if (run.aux_names[q] == name)
                    from = (long)q;
            // a model file of an alt-az run from before stop 42 names the
            // derived elevation direction dec_dir
            for (size_t q = 0; q < run.aux_names.size() && from < 0; q++)
                if (run.dec_dir_derived && run.mount == PM_MOUNT_ALTAZ && name == "dec_dir" &&
                    run.aux_names[q] == "el_dir")
                    from = (long)q;
            if (from < 0)
                throw std::runtime_error(model_name + ": its " + terms_read +
                                         " the column '" + name + "', which " +
                                         run.path + " does not have (its auxiliary columns: " +
                                         columns() + ")");
            // a column beyond the contexts' first PM_MAX_AUX: from the run's
            // columns as read (it was an error: "put it among them")
            if (from >= PM_MAX_AUX && !((size_t)from < run.aux_values.size() &&
                                        run.aux_values[(size_t)from].size() == run.obs.size()))
                throw std::runtime_error(model_name + ": " + run.path + "'s column '" + name +
                                         "' is beyond the first " + std::to_string(PM_MAX_AUX) +
                                         " auxiliary columns, and this run's values of it are "
                                         "not at hand");
        }
        if (from >= 0 && (size_t)from < run.aux_names.size())
            r.aux_names[j] = run.aux_names[(size_t)from];
        for (size_t i = 0; i < r.obs.size(); i++)
            r.obs[i].ctx.aux[j] = from < 0 ? NAN
                                  : from < PM_MAX_AUX ? run.obs[i].ctx.aux[from]
                                                      : run.aux_values[(size_t)from][i];
    }
    while (!r.aux_names.empty() && r.aux_names.back().empty())
        r.aux_names.pop_back();
    r.aux_values.clear(); /* (the run's own layout, not this one's) */
    if (pier) {
        const char *side = pier > 0 ? "east (normal)" : "west (beyond the pole)";
        std::vector<Obs> keep;
        for (const Obs &ob : r.obs)
            if (ob.pier == pier)
                keep.push_back(ob);
        if (keep.empty())
            throw std::runtime_error(model_name + " is a model of the pier side " + side +
                                     " only (pmfit fit --pier split), and " + run.path +
                                     " has no record of that side");
        if (notes && keep.size() < r.obs.size())
            notes->push_back(model_name + " is a model of the pier side " + side +
                             " only (pmfit fit --pier split): the " +
                             std::to_string(keep.size()) + " records of that side are used, " +
                             std::to_string(r.obs.size() - keep.size()) + " others not");
        r.obs = keep;
    }
    return r;
}

pmmodel_info model_info(const pm_model &m, const std::vector<std::string> &aux_names, int pier,
                        const double *err)
{
    pmmodel_info info;
    std::memset(&info, 0, sizeof info);
    info.pier = pier;
    if (err) {
        info.has_err = 1;
        for (int i = 0; i < m.n_terms; i++)
            info.err[i] = err[i];
    }
    for (int i = m.n_base; i < m.n_terms; i++) {
        const size_t j = (size_t)(m.term[i].aux - PM_AUX_USER);
        if (m.term[i].kind == PM_TERM_AUX && m.term[i].aux >= PM_AUX_USER &&
            j < (size_t)PM_MAX_AUX && j < aux_names.size() &&
            aux_names[j].size() < PMMODEL_NAME_MAX)
            std::memcpy(info.input[j], aux_names[j].c_str(), aux_names[j].size() + 1);
    }
    return info;
}

std::vector<std::string> model_inputs(const pmmodel_info &info)
{
    std::vector<std::string> in;
    for (int j = 0; j < PM_MAX_AUX; j++)
        in.push_back(info.input[j]);
    return in;
}

std::string fit_failure_detail(const FitOut &f, int passes, const std::string &order)
{
    const pm_model &m = f.model; // the model that was fitted (unchanged on error)
    char buf[64];
    switch (f.status) {
    case PM_ERR_SINGULAR:
        if (f.bad_term < 0)
            return "";
        return " (term " + term_name(m, f.bad_term) + ", " + meaning(m, f.bad_term) +
               ": a combination of the terms before it for this sky coverage" +
               (f.bad_term >= m.n_base ? " and model" : "") + "; lower " + order +
               ", drop the term or add points)";
    case PM_ERR_DIVERGED:
        if (f.corr_i < 0)
            return "";
        std::snprintf(buf, sizeof buf, "%.6f", f.corr);
        return " in " + std::to_string(passes) + " passes: the sky coverage hardly separates " +
               term_name(m, f.corr_j) + " from " + term_name(m, f.corr_i) + " (correlation " +
               buf + "); lower " + order + " or add stars over more of the sky" +
               // (a fork has one side: "use both pier sides" had been its advice)
               (m.mount == PM_MOUNT_ALTAZ || f.both_sides ? ""
                                                          : " (a German mount: on both pier sides)");
    case PM_ERR_TOO_FEW:
        return " (P = " + std::to_string(m.n_terms) + " terms need at least " +
               std::to_string(m.n_terms / 2 + 1) + " observations, 2N > P; there are " +
               std::to_string(f.res.n_obs) + "; lower " + order + ")";
    default:
        return "";
    }
}

// The model without its side-specific added terms (for the pier F-test).
pm_model without_side_terms(const pm_model &m)
{
    pm_model r;
    pm_model_init(&r, m.mount, m.order);
    r.latitude = m.latitude;
    pm_model_prepare(&r);
    for (int i = m.n_base; i < m.n_terms; i++)
        if (m.term[i].side == 0)
            pm_model_add_term(&r, &m.term[i], 0.0, nullptr);
    return r;
}

} // namespace pmhost
