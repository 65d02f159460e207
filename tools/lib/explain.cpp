// explain.cpp - find the physics a pointing model left out (host side).
#include "explain.hpp"
#include "explain.h"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numeric>
#include <random>
#include <stdexcept>

namespace pmhost {

namespace {

const double LN10 = 2.302585092994046;

struct Fit {
    bool ok = false;
    FitOut f;
    double chi2 = 0;
    int P = 0;
    long N = 0;
};

// Fit (order, adds) to the observations `use`.  Not applicable (a needed
// input missing, a singular term) gives ok = false.
Fit fit_spec(const Run &run, const std::vector<int> &use, int order,
             const std::vector<std::string> &adds)
{
    Fit r;
    std::vector<Obs> sub;
    for (int i : use)
        sub.push_back(run.obs[i]);
    pm_model m;
    try {
        m = build_model(order, adds, sub, run.mount, run.latitude, run.aux_names);
    } catch (const std::exception &) {
        return r;
    }
    r.f = do_fit(run.obs, use, m);
    if (r.f.status != PM_OK)
        return r;
    r.ok = true;
    r.chi2 = r.f.res.chi2;
    r.P = r.f.res.n_par;
    r.N = r.f.res.n_obs;
    return r;
}

double arcsec(double rad) { return rad * RAD2AS; }

double elevation_of(const Run &run, const Obs &o)
{
    if (run.mount == PM_MOUNT_ALTAZ)
        return o.ad;
    if (std::isnan(run.latitude))
        return NAN;
    double l = run.latitude;
    return std::asin(std::sin(l) * std::sin(o.ad) + std::cos(l) * std::cos(o.ad) * std::cos(o.ah));
}

// Residuals (transported frame) of a fitted model at the observations.
void frame_residuals(const Run &run, const FitOut &f, std::vector<double> *r0,
                     std::vector<double> *r1)
{
    std::vector<double> row0(PM_MAX_TERMS), row1(PM_MAX_TERMS);
    r0->clear();
    r1->clear();
    for (int i : f.idx) {
        const Obs &o = run.obs[i];
        double r[2] = {0, 0};
        pm_fit_row(&f.model, &o.ctx, o.eh, o.ed, o.ah, o.ad, row0.data(), row1.data(), r);
        r0->push_back(r[0]);
        r1->push_back(r[1]);
    }
}

// Least-squares periodogram of residual component `comp` (0: along axis 1
// with the cos(dec) of an HA-axis error, 1: along axis 2) against the raw
// angle of axis `comp + 1`: chi^2 reduction in units of sigma^2.
double period_power(const Run &run, const std::vector<int> &idx, const std::vector<double> &r,
                    int comp, double G)
{
    double sxx = 0, sxy = 0, syy = 0, bx = 0, by = 0;
    for (size_t j = 0; j < idx.size(); j++) {
        const Obs &o = run.obs[idx[j]];
        double th = comp == 0 ? o.eh : o.ed;
        double w = comp == 0 ? std::cos(o.ed) : -1.0;
        double x = w * std::cos(G * th), y = w * std::sin(G * th);
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        bx += x * r[j];
        by += y * r[j];
    }
    double det = sxx * syy - sxy * sxy;
    if (!(det > 0))
        return 0;
    return (syy * bx * bx - 2 * sxy * bx * by + sxx * by * by) / det;
}

Periodogram periodogram(const Run &run, const FitOut &f, int comp, const ExplainOptions &opt,
                        double sigma2)
{
    double chi2 = f.res.chi2;
    long dof = 2 * f.res.n_obs - f.res.n_par;
    Periodogram pg;
    pg.axis = comp == 0 ? "ha" : "dec";
    std::vector<double> r0, r1;
    frame_residuals(run, f, &r0, &r1);
    const std::vector<double> &r = comp == 0 ? r0 : r1;
    for (double G = std::ceil(opt.g_min); G <= opt.g_max; G += 1) {
        pg.g.push_back(G);
        pg.power.push_back(period_power(run, f.idx, r, comp, G) / sigma2);
    }
    const std::vector<double> &gears = comp == 0 ? opt.gears_ha : opt.gears_dec;
    if (!gears.empty()) {
        // known gear periods: the best of them, corrected for them alone
        for (double G : gears) {
            double p = period_power(run, f.idx, r, comp, G) / sigma2;
            if (p > pg.peak_power || pg.peak_g == 0) {
                pg.peak_power = p;
                pg.peak_g = G;
            }
        }
        pg.trials = (double)gears.size();
        pg.threshold = -2 * std::log(opt.alpha / pg.trials);
        return pg;
    }
    // refine the three highest integer peaks to non-integer G
    std::vector<size_t> order(pg.g.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return pg.power[a] > pg.power[b]; });
    for (size_t k = 0; k < order.size() && k < 3; k++) {
        double g0 = pg.g[order[k]];
        for (double G = g0 - 1; G <= g0 + 1; G += 0.02) {
            double p = period_power(run, f.idx, r, comp, G) / sigma2;
            if (p > pg.peak_power) {
                pg.peak_power = p;
                pg.peak_g = G;
            }
        }
    }
    // An integer G (a worm with a whole number of teeth) unless the data
    // reject it: the chi^2 of the nearest integer exceeds the best G's by
    // more than 3.84 times the noise variance left once the sinusoid is
    // removed (chi^2 with one degree of freedom at 95%).
    double gi = std::round(pg.peak_g);
    double red_peak = pg.peak_power * sigma2;
    double red_int = period_power(run, f.idx, r, comp, gi);
    double s2_after = (chi2 - red_peak) / (double)std::max(1L, dof - 2);
    if (std::fabs(pg.peak_g - gi) < 0.5 && s2_after > 0 && (red_peak - red_int) / s2_after <= 3.84)
        pg.peak_g = gi;
    pg.trials = (double)pg.g.size();
    pg.threshold = -2 * std::log(opt.alpha / pg.trials); // chi^2(2) tail at alpha / M
    return pg;
}

// Observations on each pier side.
bool both_sides(const Run &run, const std::vector<int> &use)
{
    bool e = false, w = false;
    for (int i : use) {
        e = e || run.obs[i].pier > 0;
        w = w || run.obs[i].pier < 0;
    }
    return e && w;
}

// Does input `which` (0 temp, 1 time, 2 dir) vary, and is it known everywhere?
bool input_usable(const Run &run, const std::vector<int> &use, int which)
{
    double lo = 1e300, hi = -1e300;
    size_t zero = 0;
    for (int i : use) {
        const pm_context &c = run.obs[i].ctx;
        double x = which == 0 ? c.temp_c : which == 1 ? c.time_h : (double)c.dir;
        if (!std::isfinite(x))
            return false;
        zero += which == 2 && x == 0;
        lo = std::min(lo, x);
        hi = std::max(hi, x);
    }
    if (which == 2 && zero * 10 > use.size())
        return false;
    return hi - lo > (which == 0 ? 0.2 : which == 1 ? 0.05 : 1);
}

bool has(const std::vector<std::string> &v, const std::string &s)
{
    return std::find(v.begin(), v.end(), s) != v.end();
}

// Angular size (radians) of model b minus model a at each observation.
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

// Where a quantity (one value per observation in `use`) is largest: the sky
// bin (elevation band, hour-angle quarter, pier side) with the largest mean.
std::string where_largest(const Run &run, const std::vector<int> &use,
                          const std::vector<double> &v, const char *unit)
{
    struct Bin {
        double sum = 0;
        int n = 0;
    };
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
            bins[o.pier > 0 ? "pier east (normal side)" : "pier west (beyond the pole)"].sum += v[j];
            bins[o.pier > 0 ? "pier east (normal side)" : "pier west (beyond the pole)"].n++;
        }
    }
    std::string best, low;
    double bv = -1, lv = 1e300, all = 0;
    for (double x : v)
        all += x;
    all /= v.empty() ? 1 : (double)v.size();
    for (const auto &b : bins) {
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

std::vector<Located> locate(const Run &run, const FitOut &f, double sigma)
{
    std::vector<Located> out;
    size_t n = f.idx.size();
    if (n < 3)
        return out;
    double s2 = sigma * sigma;
    double all = 0;
    for (size_t j = 0; j < n; j++)
        all += f.r0[j] * f.r0[j] + f.r1[j] * f.r1[j];
    double rms = std::sqrt(all / (double)n);
    auto add_group = [&](const std::string &what, const std::vector<size_t> &members, int comps) {
        if (members.size() < 3)
            return;
        double ss = 0;
        for (size_t j : members)
            ss += (comps & 1 ? f.r0[j] * f.r0[j] : 0) + (comps & 2 ? f.r1[j] * f.r1[j] : 0);
        int per = (comps & 1 ? 1 : 0) + (comps & 2 ? 1 : 0);
        double grms = std::sqrt(ss / (double)(members.size() * per));
        double ref = rms / std::sqrt(2.0);
        // chi^2 excess of the group (sigma from the fit), Wilson-Hilferty tail
        double k = (double)(members.size() * per);
        double x = ss / s2;
        double z = (std::cbrt(x / k) - (1 - 2 / (9 * k))) / std::sqrt(2 / (9 * k));
        double p = 0.5 * std::erfc(z / std::sqrt(2.0));
        out.push_back({what, arcsec(grms), grms / ref, p});
    };
    std::vector<size_t> alli(n);
    std::iota(alli.begin(), alli.end(), 0);
    add_group("axis 1 (HA/azimuth direction)", alli, 1);
    add_group("axis 2 (Dec/elevation direction)", alli, 2);
    std::map<std::string, std::vector<size_t>> groups;
    for (size_t j = 0; j < n; j++) {
        const Obs &o = run.obs[f.idx[j]];
        double el = elevation_of(run, o);
        if (std::isfinite(el)) {
            double e = el * 180 / PI;
            groups[e < 20 ? "elevation below 20 deg" : e < 35 ? "elevation 20-35 deg"
                   : e < 65 ? "elevation 35-65 deg" : "elevation above 65 deg"].push_back(j);
        }
        double h = std::remainder(o.ah, 2 * PI) * 180 / PI;
        if (run.mount == PM_MOUNT_EQUATORIAL) {
            groups[h < -90 ? "hour angle -12h..-6h" : h < 0 ? "hour angle -6h..0h"
                   : h < 90 ? "hour angle 0h..6h" : "hour angle 6h..12h"].push_back(j);
            if (std::fabs(o.ad) > 75 * PI / 180)
                groups["near the pole (|dec| > 75 deg)"].push_back(j);
        }
        if (o.pier)
            groups[o.pier > 0 ? "pier east" : "pier west"].push_back(j);
    }
    for (const auto &g : groups)
        add_group(g.first, g.second, 3);
    // correlations with the inputs
    const char *names[3] = {"temperature", "time", "slew direction"};
    for (int w = 0; w < 3; w++) {
        std::vector<int> use(f.idx.begin(), f.idx.end());
        if (!input_usable(run, use, w))
            continue;
        for (int comp = 0; comp < 2; comp++) {
            double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
            for (size_t j = 0; j < n; j++) {
                const pm_context &c = run.obs[f.idx[j]].ctx;
                double x = w == 0 ? c.temp_c : w == 1 ? c.time_h : (double)c.dir;
                double y = comp == 0 ? f.r0[j] : f.r1[j];
                sx += x;
                sy += y;
                sxx += x * x;
                syy += y * y;
                sxy += x * y;
            }
            double dn = (double)n;
            double cov = sxy / dn - sx * sy / dn / dn;
            double vx = sxx / dn - sx * sx / dn / dn, vy = syy / dn - sy * sy / dn / dn;
            if (!(vx > 0 && vy > 0))
                continue;
            double r = cov / std::sqrt(vx * vy);
            double t = r * std::sqrt((dn - 2) / std::max(1e-12, 1 - r * r));
            double p = std::erfc(std::fabs(t) / std::sqrt(2.0));
            out.push_back({std::string(names[w]) + " vs axis " + (comp ? "2" : "1") + " residual", r,
                           std::fabs(t), p});
        }
    }
    std::sort(out.begin(), out.end(), [](const Located &a, const Located &b) { return a.p < b.p; });
    return out;
}

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

struct Candidate {
    std::string effect;
    int order;
    std::vector<std::string> adds;
    std::vector<std::string> new_adds; // what this candidate adds
    double trials = 1;                 // periods scanned
    double peak_g = 0;
    std::vector<int> drop;             // outliers: observations to drop
    Fit fit;
    double log_fap = 0;
};

} // namespace

double cv_rms(const Run &run, const std::vector<int> &use, int order,
              const std::vector<std::string> &adds, int folds, unsigned seed,
              const std::vector<int> &train_also)
{
    std::vector<int> perm(use);
    std::mt19937 rng(seed);
    std::shuffle(perm.begin(), perm.end(), rng);
    double ss = 0;
    long n = 0;
    for (int k = 0; k < folds; k++) {
        std::vector<int> train, test;
        for (size_t j = 0; j < perm.size(); j++)
            ((int)(j % (size_t)folds) == k ? test : train).push_back(perm[j]);
        train.insert(train.end(), train_also.begin(), train_also.end());
        Fit f = fit_spec(run, train, order, adds);
        if (!f.ok)
            return NAN;
        for (int i : test) {
            const Obs &o = run.obs[i];
            double r[2];
            if (pm_model_residual(&f.f.model, &o.ctx, o.eh, o.ed, o.ah, o.ad, r) != PM_OK)
                return NAN;
            ss += r[0] * r[0] + r[1] * r[1];
            n++;
        }
    }
    return n ? std::sqrt(ss / (double)(2 * n)) : NAN; /* per axis, like sigma */
}

Explanation explain(const Run &run, const ExplainOptions &opt)
{
    Explanation ex;
    std::vector<int> use(run.obs.size());
    std::iota(use.begin(), use.end(), 0);
    int order = opt.order;
    std::vector<std::string> adds = opt.adds;
    Fit cur = fit_spec(run, use, order, adds);
    if (!cur.ok) {
        // let the user see why (singular, too few, diverged): the plain fit
        FitOut f = do_fit(run.obs, use,
                          build_model(order, adds, run.obs, run.mount, run.latitude, run.aux_names));
        std::string why = "status " + std::to_string((int)f.status);
        if (f.status == PM_ERR_TOO_FEW)
            why = "too few observations (P = " + std::to_string(f.model.n_terms) +
                  " terms need at least " + std::to_string(f.model.n_terms / 2 + 1) +
                  ", there are " + std::to_string(use.size()) + ")";
        else if (f.status == PM_ERR_SINGULAR && f.bad_term >= 0)
            why = "term " + term_name(f.model, f.bad_term) +
                  " cannot be determined from these observations";
        else if (f.status == PM_ERR_DIVERGED)
            why = "the fit did not converge";
        throw std::runtime_error(run.path + ": the baseline fit failed: " + why +
                                 "; try pmfit fit for details");
    }
    ex.baseline = cur.f;
    double cur_cv = cv_rms(run, use, order, adds, opt.folds, opt.seed);
    ex.base_sigma_arcsec = arcsec(cur.f.res.sigma);
    ex.base_cv_rms_arcsec = arcsec(cur_cv);
    ex.base_n_params = cur.P;
    ex.located = locate(run, cur.f, cur.f.res.sigma);
    double s2 = cur.f.res.sigma * cur.f.res.sigma;
    ex.periodograms.push_back(periodogram(run, cur.f, 0, opt, s2));
    ex.periodograms.push_back(periodogram(run, cur.f, 1, opt, s2));

    for (int step = 0; step < opt.max_findings; step++) {
        std::vector<Candidate> cands;
        auto with = [&](const std::string &effect, const std::vector<std::string> &more) {
            Candidate c;
            c.effect = effect;
            c.order = order;
            c.adds = adds;
            for (const std::string &a : more) {
                if (has(adds, a))
                    return;
                c.adds.push_back(a);
                c.new_adds.push_back(a);
            }
            cands.push_back(c);
        };
        double sg2 = cur.f.res.sigma * cur.f.res.sigma;
        for (int comp = 0; comp < 2; comp++) {
            Periodogram pg = periodogram(run, cur.f, comp, opt, sg2);
            char spec[64];
            std::snprintf(spec, sizeof spec, "%s_periodic:%.6g", comp ? "dec" : "ha", pg.peak_g);
            bool already = false;
            for (const std::string &a : adds)
                already = already || a.rfind(comp ? "dec_periodic:" : "ha_periodic:", 0) == 0;
            if (!already && pg.peak_g > 0) {
                with(comp ? "dec_periodic" : "ha_periodic", {spec});
                cands.back().trials = pg.trials;
                cands.back().peak_g = pg.peak_g;
            }
        }
        if (order < PM_MAX_L) {
            Candidate c;
            c.effect = "higher_order";
            c.order = order + 1;
            c.adds = adds;
            cands.push_back(c);
        }
        if (run.mount == PM_MOUNT_ALTAZ || !std::isnan(run.latitude)) {
            with("refraction", {"refraction"});
            if (order == 0) // cos(el) toward the zenith is an L=1 combination
                with("tube_flexure", {"tube_flexure"});
        }
        if (run.mount == PM_MOUNT_EQUATORIAL && both_sides(run, use))
            with("pier_side", {"e'@W", "i@W"});
        if (input_usable(run, use, 0))
            with("temperature", {"temperature"});
        if (input_usable(run, use, 1))
            with("time_drift", {"time_drift"});
        {
            // backlash: the last slew direction on axis 1 (HA index) and, when
            // known, on axis 2 (the derived "dec_dir" input, Dec index)
            std::vector<std::string> h;
            if (input_usable(run, use, 2))
                h.push_back("hysteresis");
            if (has(run.aux_names, "dec_dir"))
                h.push_back("aux:dec_dir:e'");
            if (!h.empty())
                with("hysteresis", h);
        }
        // outliers: points beyond the Bonferroni-corrected chi^2(2) tail
        {
            Candidate c;
            c.effect = "outlier";
            c.order = order;
            c.adds = adds;
            double worst = 0;
            for (size_t j = 0; j < cur.f.idx.size(); j++) {
                double z2 = (cur.f.r0[j] * cur.f.r0[j] + cur.f.r1[j] * cur.f.r1[j]) / sg2;
                double lp = -z2 / 2 + std::log((double)cur.f.idx.size());
                if (lp < std::log(opt.alpha))
                    c.drop.push_back(cur.f.idx[j]);
                worst = std::max(worst, z2);
            }
            c.log_fap = -worst / 2 + std::log((double)cur.f.idx.size());
            if (!c.drop.empty())
                cands.push_back(c);
        }
        double K = (double)cands.size();
        ex.candidates_tried.clear();
        for (Candidate &c : cands) {
            ex.candidates_tried.push_back(c.effect);
            if (c.effect == "outlier") {
                std::vector<int> keep;
                for (int i : use)
                    if (std::find(c.drop.begin(), c.drop.end(), i) == c.drop.end())
                        keep.push_back(i);
                c.fit = fit_spec(run, keep, order, adds);
                c.log_fap += std::log(K);
                continue;
            }
            c.fit = fit_spec(run, use, c.order, c.adds);
            if (!c.fit.ok || c.fit.P <= cur.P) {
                c.log_fap = 0;
                continue;
            }
            double d1 = c.fit.P - cur.P, d2 = (double)(2 * c.fit.N - c.fit.P);
            double F = ((cur.chi2 - c.fit.chi2) / d1) / (c.fit.chi2 / d2);
            c.log_fap = log_f_tail(F, d1, d2) + std::log(c.trials) + std::log(K);
        }
        std::sort(cands.begin(), cands.end(),
                  [](const Candidate &a, const Candidate &b) { return a.log_fap < b.log_fap; });
        bool accepted = false;
        for (Candidate &c : cands) {
            if (!(c.log_fap < std::log(opt.alpha)) || !c.fit.ok)
                break;
            std::vector<int> nuse = use;
            if (c.effect == "outlier") {
                nuse.clear();
                for (int i : use)
                    if (std::find(c.drop.begin(), c.drop.end(), i) == c.drop.end())
                        nuse.push_back(i);
            }
            // confirm out of sample: the cross-validated RMS must improve
            double cv_new = cv_rms(run, nuse, c.order, c.adds, opt.folds, opt.seed);
            // outliers: the same points predicted by models trained with them
            double cv_old = c.effect == "outlier"
                                ? cv_rms(run, nuse, order, adds, opt.folds, opt.seed, c.drop)
                                : cur_cv;
            if (!(cv_new < cv_old))
                continue;
            // the finding
            Finding fd;
            fd.effect = c.effect;
            fd.adds = c.new_adds;
            fd.false_alarm_probability = std::exp(c.log_fap);
            fd.log10_p = c.log_fap / LN10;
            fd.sigma_after_arcsec = arcsec(c.fit.f.res.sigma);
            fd.cv_rms_after_arcsec = arcsec(cv_new);
            fd.n_params_after = c.fit.P;
            const pm_model &m = c.fit.f.model;
            const pm_fit_result &res = c.fit.f.res;
            // the new terms and their values
            std::vector<int> newi;
            for (int i = cur.f.model.n_terms; i < m.n_terms; i++)
                newi.push_back(i);
            char buf[512];
            if (c.effect == "ha_periodic" || c.effect == "dec_periodic") {
                double cc = m.coef[newi[0]], ss = m.coef[newi[1]];
                double ec = res.err[newi[0]], es = res.err[newi[1]];
                double A = std::hypot(cc, ss);
                fd.cycles_per_rev = c.peak_g;
                fd.amplitude_arcsec = arcsec(A);
                fd.amplitude_err_arcsec =
                    arcsec(A > 0 ? std::hypot(cc * ec, ss * es) / A : std::hypot(ec, es));
                fd.phase_deg = std::atan2(ss, cc) * 180 / PI;
                std::snprintf(buf, sizeof buf,
                              "periodic error of the %s drive: %.6g cycles per revolution "
                              "(period %.4g deg of the axis), amplitude %.2f\" +- %.2f\", phase "
                              "%.0f deg at %s = 0",
                              c.effect == "ha_periodic"
                                  ? (run.mount == PM_MOUNT_ALTAZ ? "azimuth" : "hour-angle")
                                  : (run.mount == PM_MOUNT_ALTAZ ? "elevation" : "declination"),
                              c.peak_g, 360 / c.peak_g, fd.amplitude_arcsec,
                              fd.amplitude_err_arcsec, fd.phase_deg,
                              c.effect == "ha_periodic"
                                  ? (run.mount == PM_MOUNT_ALTAZ ? "raw azimuth" : "raw HA")
                                  : (run.mount == PM_MOUNT_ALTAZ ? "raw elevation" : "raw Dec"));
                fd.text = buf;
            } else if (c.effect == "outlier") {
                double worst = 0;
                for (size_t j = 0; j < cur.f.idx.size(); j++)
                    if (std::find(c.drop.begin(), c.drop.end(), cur.f.idx[j]) != c.drop.end()) {
                        worst = std::max(worst, std::hypot(cur.f.r0[j], cur.f.r1[j]));
                        fd.lines.push_back(run.obs[cur.f.idx[j]].line);
                    }
                fd.amplitude_arcsec = arcsec(worst);
                std::string lines;
                for (int l : fd.lines)
                    lines += (lines.empty() ? "" : ", ") + std::to_string(l);
                std::snprintf(buf, sizeof buf,
                              "%zu individual bad point%s (failed plate solve, wrong star?) at "
                              "line%s %s; the worst misses by %.1f\" (%.1f sigma)",
                              fd.lines.size(), fd.lines.size() > 1 ? "s" : "",
                              fd.lines.size() > 1 ? "s" : "", lines.c_str(), fd.amplitude_arcsec,
                              worst / cur.f.res.sigma);
                fd.text = buf;
            } else if (c.effect == "higher_order") {
                std::vector<double> d = model_difference(run, use, cur.f.model, m);
                double ss2 = 0;
                for (double x : d)
                    ss2 += x * x;
                fd.amplitude_arcsec = arcsec(std::sqrt(ss2 / (double)std::max<size_t>(1, d.size())));
                std::snprintf(buf, sizeof buf,
                              "anisotropy beyond order %d: the %d terms of order %d change the "
                              "pointing by %.2f\" RMS (flexure or gear errors with more structure "
                              "than the model had)",
                              order, c.fit.P - cur.P, order + 1, fd.amplitude_arcsec);
                fd.text = buf;
            } else if (c.effect == "pier_side") {
                // the side-specific displacement, RMS over the west-pier points
                pm_model z = m;
                for (int i : newi)
                    z.coef[i] = 0;
                pm_model_prepare(&z);
                std::vector<int> west;
                for (int i : use)
                    if (run.obs[i].pier < 0)
                        west.push_back(i);
                std::vector<double> d = model_difference(run, west, z, m);
                double ss2 = 0;
                for (double x : d)
                    ss2 += x * x;
                fd.amplitude_arcsec = arcsec(std::sqrt(ss2 / (double)std::max<size_t>(1, d.size())));
                std::string vals;
                for (int i : newi) {
                    char v[96];
                    std::snprintf(v, sizeof v, "%s%s = %.2f +- %.2f", vals.empty() ? "" : ", ",
                                  term_name(m, i).c_str(), arcsec(m.coef[i]), arcsec(res.err[i]));
                    vals += v;
                }
                std::snprintf(buf, sizeof buf,
                              "the pointing differs across the meridian flip (pier side) by "
                              "%.2f\" RMS on the west side: collimation/index offsets change "
                              "with the side, as flexure or a side-dependent cone error does; %s "
                              "arcsec",
                              fd.amplitude_arcsec, vals.c_str());
                fd.text = buf;
            } else {
                // one coefficient family: report the largest and its error
                int big = newi.empty() ? -1 : newi[0];
                for (int i : newi)
                    if (std::fabs(m.coef[i]) > std::fabs(m.coef[big]))
                        big = i;
                fd.amplitude_arcsec = big >= 0 ? arcsec(std::fabs(m.coef[big])) : 0;
                fd.amplitude_err_arcsec = big >= 0 ? arcsec(res.err[big]) : 0;
                std::string vals;
                for (int i : newi) {
                    char v[160];
                    std::snprintf(v, sizeof v, "%s%s = %.2f +- %.2f", vals.empty() ? "" : ", ",
                                  input_name(run, m, i).c_str(), arcsec(m.coef[i]),
                                  arcsec(res.err[i]));
                    vals += v;
                }
                const char *what =
                    c.effect == "refraction"
                        ? "an elevation-dependent shift toward the zenith growing as cot(el): "
                          "refraction missing or wrong in the reduction"
                    : c.effect == "tube_flexure"
                        ? "tube flexure: a sag toward the horizon growing as cos(el)"
                    : c.effect == "pier_side"
                        ? "the pointing differs across the meridian flip (pier side): "
                          "collimation/index offsets change with the side, as flexure or a "
                          "cone error that depends on the side does"
                    : c.effect == "temperature"
                        ? "the pointing drifts with temperature (arcsec per deg C): thermal "
                          "expansion of the tube or mount"
                    : c.effect == "time_drift"
                        ? "the pointing drifts through the night (arcsec per hour): settling, "
                          "slipping encoders or a clock error"
                        : "the pointing depends on the direction of the last slew: backlash or "
                          "hysteresis in the drive (half the backlash per unit of direction)";
                std::snprintf(buf, sizeof buf, "%s; %s arcsec", what, vals.c_str());
                fd.text = buf;
            }
            {
                std::vector<double> d = model_difference(run, c.effect == "outlier" ? nuse : use,
                                                         cur.f.model, m);
                for (double &x : d)
                    x = arcsec(x);
                fd.where = c.effect == "outlier" ? "individual points (see lines)"
                                                 : where_largest(run, use, d, "\"");
            }
            ex.findings.push_back(fd);
            order = c.order;
            adds = c.adds;
            use = nuse;
            cur = c.fit;
            cur_cv = cv_new;
            accepted = true;
            break;
        }
        if (!accepted)
            break;
    }
    ex.final = cur.f;
    ex.kept = use;
    ex.final_sigma_arcsec = arcsec(cur.f.res.sigma);
    ex.final_cv_rms_arcsec = arcsec(cur_cv);
    ex.final_n_params = cur.P;
    ex.final_adds = adds;
    ex.final_order = order;
    return ex;
}

} // namespace pmhost

extern "C" int pmx_explain(const char *path, int order, double alpha, pmx_result *out,
                           char *err, size_t errlen)
{
    return pmx_explain_gears(path, order, alpha, NULL, 0, out, err, errlen);
}

extern "C" int pmx_explain_gears(const char *path, int order, double alpha, const double *gears,
                                 int n_gears, pmx_result *out, char *err, size_t errlen)
{
    using namespace pmhost;
    if (!path || !out || n_gears < 0 || (n_gears > 0 && !gears)) {
        set_err(err, errlen, "pmx_explain: invalid arguments");
        return -1;
    }
    try {
        Run run = load_run(path, true, false);
        ExplainOptions o;
        o.order = order;
        o.alpha = alpha;
        for (int i = 0; i < n_gears; i++) {
            if (!(gears[i] > 0 && gears[i] <= 1e6)) {
                set_err(err, errlen, "pmx_explain: a gear period must be in (0, 1e6]");
                return -1;
            }
            o.gears_ha.push_back(gears[i]);
            o.gears_dec.push_back(gears[i]);
        }
        Explanation ex = explain(run, o);
        pmx_result r;
        std::memset(&r, 0, sizeof r);
        r.base_sigma_arcsec = ex.base_sigma_arcsec;
        r.base_cv_rms_arcsec = ex.base_cv_rms_arcsec;
        r.base_n_params = ex.base_n_params;
        r.final_sigma_arcsec = ex.final_sigma_arcsec;
        r.final_cv_rms_arcsec = ex.final_cv_rms_arcsec;
        r.final_n_params = ex.final_n_params;
        for (const Finding &f : ex.findings) {
            if (r.n_findings >= PMX_MAX_FINDINGS)
                break;
            pmx_finding &g = r.findings[r.n_findings++];
            std::snprintf(g.effect, sizeof g.effect, "%s", f.effect.c_str());
            g.cycles_per_rev = f.cycles_per_rev;
            g.amplitude_arcsec = f.amplitude_arcsec;
            g.amplitude_err_arcsec = f.amplitude_err_arcsec;
            g.phase_deg = f.phase_deg;
            g.false_alarm_probability = f.false_alarm_probability;
            g.sigma_after_arcsec = f.sigma_after_arcsec;
            g.cv_rms_after_arcsec = f.cv_rms_after_arcsec;
            g.n_params_after = f.n_params_after;
            g.n_lines = (int)f.lines.size();
            for (size_t k = 0; k < f.lines.size() && k < 16; k++)
                g.lines[k] = f.lines[k];
        }
        *out = r;
    } catch (const std::exception &x) {
        set_err(err, errlen, x.what());
        return -1;
    }
    return 0;
}
