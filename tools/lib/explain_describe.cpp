// explain_describe.cpp - stage "describe" of pmfit explain: an accepted
// candidate in words, with its size and where on the sky it matters, in the
// vocabulary of the mount (equatorial or alt-az).  docs/explain.md.
#include "explain_internal.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace pmhost {
namespace xdetail {

double elevation_of(const Run &run, const Obs &o)
{
    if (run.mount == PM_MOUNT_ALTAZ)
        return o.ad;
    if (std::isnan(run.latitude))
        return NAN;
    double l = run.latitude;
    return std::asin(std::sin(l) * std::sin(o.ad) + std::cos(l) * std::cos(o.ad) * std::cos(o.ah));
}

bool has(const std::vector<std::string> &v, const std::string &s)
{
    return std::find(v.begin(), v.end(), s) != v.end();
}

std::vector<double> model_difference(const Run &run, const std::vector<int> &use,
                                     const pm_model &a, const pm_model &b)
{
    std::vector<double> d;
    for (int i : use) {
        const Obs &o = run.obs[i];
        double t1, d1, t2, d2;
        if (pm_model_apply(&a, &o.ctx, o.eh, o.ed, &t1, &d1) != PM_OK ||
            pm_model_apply(&b, &o.ctx, o.eh, o.ed, &t2, &d2) != PM_OK) {
            d.push_back(0);
            continue;
        }
        double c = std::sin(d1) * std::sin(d2) + std::cos(d1) * std::cos(d2) * std::cos(t1 - t2);
        double s = std::hypot(std::cos(d2) * std::sin(t2 - t1),
                              std::cos(d1) * std::sin(d2) -
                                  std::sin(d1) * std::cos(d2) * std::cos(t2 - t1));
        d.push_back(std::atan2(s, c));
    }
    return d;
}

const char *axis_word(const Run &run, int axis, bool raw)
{
    bool az = run.mount == PM_MOUNT_ALTAZ;
    if (axis == 1)
        return raw ? (az ? "raw azimuth" : "raw HA") : (az ? "azimuth" : "hour-angle");
    return raw ? (az ? "raw elevation" : "raw Dec") : (az ? "elevation" : "declination");
}

namespace {

struct Bin {
    double sum = 0;
    int n = 0;
};

// Sky bins of the observations: elevation bands, axis-1 quarters, pier sides.
std::map<std::string, Bin> bin_means(const Run &run, const std::vector<int> &use,
                                     const std::vector<double> &v)
{
    std::map<std::string, Bin> bins;
    for (size_t j = 0; j < use.size(); j++) {
        const Obs &o = run.obs[use[j]];
        double el = elevation_of(run, o);
        if (std::isfinite(el)) {
            double e = el * 180 / PI;
            const char *b = e < 20 ? "elevation below 20 deg"
                            : e < 35 ? "elevation 20-35 deg"
                            : e < 50 ? "elevation 35-50 deg"
                            : e < 65 ? "elevation 50-65 deg" : "elevation above 65 deg";
            bins[b].sum += v[j];
            bins[b].n++;
        }
        double h = std::remainder(o.ah, 2 * PI) * 180 / PI;
        const char *hb = run.mount == PM_MOUNT_ALTAZ
                             ? (h < -90 ? "azimuth 180-270" : h < 0 ? "azimuth 270-360"
                                : h < 90 ? "azimuth 0-90" : "azimuth 90-180")
                             : (h < -90 ? "hour angle -12h..-6h" : h < 0 ? "hour angle -6h..0h"
                                : h < 90 ? "hour angle 0h..6h" : "hour angle 6h..12h");
        bins[hb].sum += v[j];
        bins[hb].n++;
        if (o.pier) {
            const char *pb = o.pier > 0 ? "pier east (normal side)" : "pier west (beyond the pole)";
            bins[pb].sum += v[j];
            bins[pb].n++;
        }
    }
    return bins;
}

} // namespace

std::string largest_bin(const Run &run, const std::vector<int> &use, const std::vector<double> &v)
{
    std::string best;
    double bv = -1;
    for (const auto &b : bin_means(run, use, v))
        if (b.second.n >= 3 && b.second.sum / b.second.n > bv) {
            bv = b.second.sum / b.second.n;
            best = b.first;
        }
    return best;
}

std::string where_largest(const Run &run, const std::vector<int> &use,
                          const std::vector<double> &v, const char *unit)
{
    std::string best, low;
    double bv = -1, lv = 1e300, all = 0;
    for (double x : v)
        all += x;
    all /= v.empty() ? 1 : (double)v.size();
    for (const auto &b : bin_means(run, use, v)) {
        if (b.second.n < 3)
            continue;
        double m = b.second.sum / b.second.n;
        if (m > bv) {
            bv = m;
            best = b.first;
        }
        if (m < lv) {
            lv = m;
            low = b.first;
        }
    }
    char buf[256];
    std::snprintf(buf, sizeof buf, "largest at %s (mean %.2f%s), smallest at %s (mean %.2f%s); "
                                   "mean over the run %.2f%s",
                  best.c_str(), bv, unit, low.c_str(), lv, unit, all, unit);
    return buf;
}

namespace {

// A term's name with a user input shown by its column name.
std::string input_name(const Run &run, const pm_model &m, int i)
{
    std::string n = term_name(m, i);
    const pm_term &t = m.term[i];
    if (t.kind == PM_TERM_AUX && t.aux >= PM_AUX_USER &&
        (size_t)(t.aux - PM_AUX_USER) < run.aux_names.size()) {
        std::string tag = "aux" + std::to_string(t.aux - PM_AUX_USER);
        size_t p = n.find(tag);
        if (p != std::string::npos)
            n.replace(p, tag.size(), run.aux_names[(size_t)(t.aux - PM_AUX_USER)]);
    }
    return n;
}

std::string values_of(const Run &run, const pm_model &m, const pm_fit_result &res,
                      const std::vector<int> &newi)
{
    std::string vals;
    for (int i : newi) {
        // two decimals, or more where the error is below 0.1 (a column's
        // coefficient per unit of it: "0.06 +- 0.00" said nothing)
        // (and significant digits below 1e-5: a column of large values)
        int dp = 2;
        const double e = std::fabs(arcsec(res.err[i]));
        while (dp < 6 && e > 0 && e < std::pow(10.0, 1 - dp))
            dp++;
        char v[160];
        if (e > 0 && e < 1e-5)
            std::snprintf(v, sizeof v, "%s%s = %.3g +- %.2g", vals.empty() ? "" : ", ",
                          input_name(run, m, i).c_str(), arcsec(m.coef[i]), arcsec(res.err[i]));
        else
            std::snprintf(v, sizeof v, "%s%s = %.*f +- %.*f", vals.empty() ? "" : ", ",
                          input_name(run, m, i).c_str(), dp, arcsec(m.coef[i]), dp,
                          arcsec(res.err[i]));
        vals += v;
    }
    return vals;
}

// The terms newi of a finding's fit, as the finding's coefficients (the
// values its text gives, to JSON's precision).
void set_coefficients(const Run &run, const pm_model &m, const pm_fit_result &res,
                      const std::vector<int> &newi, Finding &fd)
{
    fd.coefficients.clear();
    for (int i : newi) {
        Finding::Coefficient c;
        c.name = term_name(m, i);
        const pm_term &t = m.term[i];
        if (t.kind == PM_TERM_AUX && t.aux >= PM_AUX_USER &&
            (size_t)(t.aux - PM_AUX_USER) < run.aux_names.size())
            c.column = run.aux_names[(size_t)(t.aux - PM_AUX_USER)];
        c.value_arcsec = arcsec(m.coef[i]);
        c.error_arcsec = arcsec(res.err[i]);
        fd.coefficients.push_back(c);
    }
}

double rms_of(const std::vector<double> &d)
{
    double ss = 0;
    for (double x : d)
        ss += x * x;
    return std::sqrt(ss / (double)std::max<size_t>(1, d.size()));
}

void describe_periodic(const Run &run, const Candidate &c, const std::vector<int> &newi,
                       const std::string &effect, double G, Finding &fd)
{
    const pm_model &m = c.fit.f.model;
    const pm_fit_result &res = c.fit.f.res;
    double cc = m.coef[newi[0]], ss = m.coef[newi[1]];
    double ec = res.err[newi[0]], es = res.err[newi[1]];
    double A = std::hypot(cc, ss);
    int axis = effect == "ha_periodic" ? 1 : 2;
    set_coefficients(run, m, res, newi, fd);
    fd.cycles_per_rev = G;
    fd.amplitude_arcsec = arcsec(A);
    fd.amplitude_err_arcsec = arcsec(A > 0 ? std::hypot(cc * ec, ss * es) / A : std::hypot(ec, es));
    fd.phase_deg = std::atan2(ss, cc) * 180 / PI;
    // an alt-az mount's azimuth error of a few cycles per turn is the track
    // or bearing, not a worm
    const char *what = "periodic error of the %s drive";
    if (run.mount == PM_MOUNT_ALTAZ && axis == 1 && G <= 4.5)
        what = "azimuth track or bearing runout (periodic in %s)";
    char head[96], buf[512];
    std::snprintf(head, sizeof head, what, axis_word(run, axis, false));
    std::snprintf(buf, sizeof buf,
                  "%s: %.6g cycles per revolution (period %.4g deg of the axis), amplitude "
                  "%.2f\" +- %.2f\", phase %.0f deg at %s = 0",
                  head, G, 360 / G, fd.amplitude_arcsec, fd.amplitude_err_arcsec,
                  fd.phase_deg, axis_word(run, axis, true));
    fd.text = buf;
    std::string others; // other peaks that fit as well (alias_peaks)
    for (double a : fd.aliases)
        others += fmt("%s%.6g", others.empty() ? "" : ", ", a);
    if (fd.cycles_lo < G || fd.cycles_hi > G || !others.empty()) {
        // the tooth count is not fixed by this run: say which counts fit
        std::string which = fd.cycles_lo < G || fd.cycles_hi > G
                                ? fmt("%.6g to %.6g cycles", fd.cycles_lo, fd.cycles_hi)
                                : std::string();
        if (!others.empty())
            which += (which.empty() ? "" : ", and ") + others + " cycles (other peaks)";
        std::snprintf(buf, sizeof buf,
                      "; %s fit as well (chi^2 within %.2f, 95%%): the run samples %.0f deg of "
                      "the axis, too little to fix the count (give a known tooth count with "
                      "--gear)",
                      which.c_str(), PERIOD_RANGE_CHI2, fd.sampled_deg);
        fd.text += buf;
    }
    // A period that is not a whole number of cycles per revolution jumps
    // where the raw angle wraps (+-180 deg, as the reader gives it).  Where
    // the axis turns through that place (its points on both sides of it:
    // no empty arc around it, as a German mount's flipped side near the
    // meridian, or an alt-az azimuth run through north) the term is not
    // continuous where the mount is, and the period read is biased (an
    // outside probe: 187.3 read as 187, phase off by 28 deg).
    if (std::fabs(G - std::round(G)) > 1e-6) {
        std::vector<double> ang;
        for (int i : c.fit.f.idx)
            ang.push_back(axis == 1 ? run.obs[(size_t)i].eh : run.obs[(size_t)i].ed);
        // where the axis never turns (derive_directions' cut): the widest
        // empty arc where it is over a quarter turn (a German mount's
        // counterweight-up half); else an equatorial axis does not pass
        // under the pole (a fork), and an alt-az one turns anywhere
        double middle = 0;
        const double gap = widest_gap(ang, &middle);
        const bool wrap_in_gap = std::fabs(std::remainder(PI - middle, 2 * PI)) < gap / 2;
        const bool turns_there = gap > 0.5 * PI ? !wrap_in_gap
                                                : run.mount == PM_MOUNT_ALTAZ && !wrap_in_gap;
        if (turns_there && gap < 2 * PI) {
            std::snprintf(buf, sizeof buf,
                          "; %.6g is not a whole number of cycles, so the term jumps where the "
                          "%s wraps at +-180 deg, which this run's %s axis turns through: the "
                          "period and phase read there are not to be trusted (a whole number, or "
                          "raw angles continuous where the axis turns, are)",
                          G, axis_word(run, axis, true), axis_word(run, axis, false));
            fd.text += buf;
        }
    }
}

void describe_outlier(const Run &run, const State &st, const Candidate &c, Finding &fd)
{
    const FitOut &cur = st.cur.f;
    double worst = 0;
    // the miss: each point's deleted residual (its own fit cannot pull it in)
    for (size_t k = 0; k < c.drop.size(); k++) {
        worst = std::max(worst, k < c.miss.size() ? c.miss[k] : 0.0);
        fd.lines.push_back(run.obs[c.drop[k]].line);
    }
    std::sort(fd.lines.begin(), fd.lines.end());
    fd.amplitude_arcsec = arcsec(worst);
    const std::string lines = joined(fd.lines);
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "%zu individual bad point%s (failed plate solve, wrong star?) at line%s %s; the "
                  "worst misses by %.1f\" (%.1f sigma)",
                  fd.lines.size(), fd.lines.size() > 1 ? "s" : "", fd.lines.size() > 1 ? "s" : "",
                  lines.c_str(), fd.amplitude_arcsec,
                  worst / (c.fit.ok ? c.fit.f.res.sigma : cur.res.sigma));
    fd.text = buf;
    // The run's first record, where the model has a backlash and the slew
    // directions came from the sequence: its own slew is not known (an
    // outside probe's high signal-to-noise backlash runs each named it a
    // failed plate solve).
    bool backlash = false;
    for (int i = cur.model.n_base; i < cur.model.n_terms; i++)
        backlash = backlash || (cur.model.term[i].kind == PM_TERM_AUX &&
                                cur.model.term[i].aux == PM_AUX_DIR);
    if (run.dir_derived && backlash && !run.obs.empty() &&
        std::find(c.drop.begin(), c.drop.end(), 0) != c.drop.end())
        fd.text += fmt("; line %d is the run's first record, the direction of whose slew "
                       "cannot be known from the sequence (0 in its backlash term): give the "
                       "run a direction column (dir) to keep it",
                       run.obs[0].line);
}

void describe_higher(const Run &run, const State &st, const Candidate &c, Finding &fd)
{
    std::vector<double> d = model_difference(run, st.use, st.cur.f.model, c.fit.f.model);
    fd.amplitude_arcsec = arcsec(rms_of(d));
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "anisotropy beyond order %d: the %d terms of order %d change the pointing by "
                  "%.2f\" RMS (flexure or gear errors with more structure than the model had)",
                  st.order, c.fit.P - st.cur.P, st.order + 1, fd.amplitude_arcsec);
    fd.text = buf;
}

void describe_pier(const Run &run, const State &st, const Candidate &c,
                   const std::vector<int> &newi, Finding &fd)
{
    const pm_model &m = c.fit.f.model;
    pm_model z = m;  // the side-specific displacement, RMS over the west points
    for (int i : newi)
        z.coef[i] = 0;
    pm_model_prepare(&z);
    std::vector<int> west;
    for (int i : st.use)
        if (run.obs[i].pier < 0)
            west.push_back(i);
    fd.amplitude_arcsec = arcsec(rms_of(model_difference(run, west, z, m)));
    set_coefficients(run, m, c.fit.f.res, newi, fd);
    char buf[700];
    std::snprintf(buf, sizeof buf,
                  "the pointing differs across the meridian flip (pier side) by %.2f\" RMS on the "
                  "west side: collimation/index offsets change with the side, as flexure or a "
                  "side-dependent cone error does; %s arcsec",
                  fd.amplitude_arcsec, values_of(run, m, c.fit.f.res, newi).c_str());
    fd.text = buf;
}

// What a one-family effect is, in the mount's vocabulary; sign: of the
// (single) coefficient of refraction and tube flexure, + toward the zenith:
// the place the run gives is the encoder's moved that way.  Refraction
// raises a star, so a reduction without it gives places below where the
// telescope points: c < 0 (c = -A, docs/model.md; --no-refraction on
// gem-28 moves c by -55"); c > 0 is more lift than the air gave.  (The
// words had the two the other way round until stop 38.)
const char *family_words(const Run &run, const std::string &e, double sign)
{
    bool az = run.mount == PM_MOUNT_ALTAZ;
    if (e == "refraction")
        return sign < 0 ? "an elevation-dependent shift toward the horizon growing as cot(el): "
                          "refraction missing from the reduction or under-corrected (the "
                          "stars are higher than the run's places say)"
                        : "an elevation-dependent shift toward the zenith growing as cot(el): "
                          "refraction over-corrected (applied twice, or a wrong pressure or "
                          "temperature)";
    if (e == "tube_flexure")
        return sign < 0 ? (az ? "elevation-dependent flexure: the tube sags toward the horizon as cos(el)"
                              : "tube flexure: a sag toward the horizon growing as cos(el)")
                        : (az ? "elevation-dependent flexure toward the zenith as cos(el) (the "
                                "opposite sense of a tube sag: a flexure of the structure that "
                                "lifts the optics)"
                              : "flexure toward the zenith growing as cos(el) (the opposite sense "
                                "of a tube sag: a flexure of the structure that lifts the optics)");
    if (e == "temperature")
        return az ? "the pointing follows temperature (arcsec per deg C): on the elevation and "
                    "azimuth index, as thermal expansion of the tube or the structure moves them"
                  : "the pointing drifts with temperature (arcsec per deg C): thermal expansion "
                    "of the tube or mount";
    if (e == "time_drift")
        return "the pointing drifts through the night (arcsec per hour): settling, slipping "
               "encoders or a clock error";
    if (e == "cable_wrap")
        return "the pointing differs on the cable wrap's next turn (the file's azimuth count "
               "past the next multiple of 360 deg): an offset that depends on the wrap, on the "
               "azimuth and elevation index (arcsec on the next turn)";
    if (e == "cable_drag")
        return "the pointing changes as the cable wrap winds (in proportion to the file's "
               "azimuth count): the cables' drag, on the azimuth and elevation index (arcsec "
               "per turn of the wrap)";
    if (e.rfind("aux:", 0) == 0)
        return az ? "the pointing follows the run's own column (arcsec per unit of it, about its "
                    "mean), on the azimuth and elevation index: a cause the run recorded (a "
                    "focus position, a second temperature ...)"
                  : "the pointing follows the run's own column (arcsec per unit of it, about its "
                    "mean), on the hour-angle and declination index: a cause the run recorded (a "
                    "focus position, a second temperature ...)";
    return az ? "the pointing depends on the direction of the last slew: cable-wrap or bearing "
                "hysteresis, or backlash in the drive (half the offset per unit of direction)"
              : "the pointing depends on the direction of the last slew: backlash or hysteresis "
                "in the drive (half the backlash per unit of direction)";
}

void describe_family(const Run &run, const Candidate &c, const std::vector<int> &newi,
                     const std::string &effect, Finding &fd)
{
    const pm_model &m = c.fit.f.model;
    int big = newi.empty() ? -1 : newi[0];
    for (int i : newi)
        if (std::fabs(m.coef[i]) > std::fabs(m.coef[big]))
            big = i;
    set_coefficients(run, m, c.fit.f.res, newi, fd);
    fd.amplitude_arcsec = big >= 0 ? arcsec(std::fabs(m.coef[big])) : 0;
    fd.amplitude_err_arcsec = big >= 0 ? arcsec(c.fit.f.res.err[big]) : 0;
    char buf[700];
    std::snprintf(buf, sizeof buf, "%s; %s arcsec",
                  family_words(run, effect, big >= 0 ? m.coef[big] : 0.0),
                  values_of(run, m, c.fit.f.res, newi).c_str());
    fd.text = buf;
}

} // namespace

std::vector<Finding> describe(const Run &run, const State &st, const Candidate &c,
                              const ExplainOptions &opt)
{
    std::vector<Finding> out;
    int first = st.cur.f.model.n_terms;
    for (size_t k = 0; k < c.members.size(); k++) {
        const std::string &e = c.members[k];
        std::vector<int> newi;
        int n = k < c.member_terms.size() ? c.member_terms[k] : c.fit.f.model.n_terms - first;
        for (int i = first; i < first + n && i < c.fit.f.model.n_terms; i++)
            newi.push_back(i);
        first += n;
        Finding fd;
        fd.effect = e;
        for (int i : newi)
            fd.term_names.push_back(term_name(c.fit.f.model, i));
        if (c.members.size() == 2)
            fd.with = c.members[1 - k];
        if (e == "ha_periodic" || e == "dec_periodic") {
            double G = k < c.member_g.size() ? c.member_g[k] : c.peak_g;
            period_range(run, st, opt, c.fit, c.adds, e == "ha_periodic" ? 0 : 1, G,
                         &fd.cycles_lo, &fd.cycles_hi, &fd.sampled_deg);
            if (c.members.size() == 1)
                fd.aliases = c.aliases;
            describe_periodic(run, c, newi, e, G, fd);
        }
        else if (e == "outlier")
            describe_outlier(run, st, c, fd);
        else if (e == "higher_order")
            describe_higher(run, st, c, fd);
        else if (e == "pier_side")
            describe_pier(run, st, c, newi, fd);
        else
            describe_family(run, c, newi, e, fd);
        out.push_back(fd);
    }
    return out;
}

// The step's values of a finding are those of the model it was found in:
// with effects found later still in the residuals, and a term confounded
// with a later one (a drift and a temperature both hidden) takes part of
// it, with an error that does not know the later term.  The values the
// user fits (the last line's pmfit fit) are the final model's: a fork run
// with a drift of 1.50"/h and a temperature of 4.96"/C hidden read the
// drift at step 1 as e'*time = 3.60 +- 0.11, in the final model 2.00 +-
// 0.36.  The terms are found in the final model by name (the order may
// have been raised since, moving their indices); where one is not there,
// the step's values stay.
void describe_final(const Run &run, const State &st, Finding &fd)
{
    if (fd.term_names.empty() || fd.effect == "outlier" || fd.effect == "higher_order")
        return;
    const pm_model &m = st.cur.f.model;
    std::vector<int> newi;
    for (const std::string &n : fd.term_names) {
        int i = term_index(m, n);
        if (i < 0)
            return;
        newi.push_back(i);
    }
    Candidate c;
    c.fit = st.cur;
    if (fd.effect == "ha_periodic" || fd.effect == "dec_periodic")
        describe_periodic(run, c, newi, fd.effect, fd.cycles_per_rev, fd);
    else if (fd.effect == "pier_side")
        describe_pier(run, st, c, newi, fd);
    else
        describe_family(run, c, newi, fd.effect, fd);
}

} // namespace xdetail
} // namespace pmhost
