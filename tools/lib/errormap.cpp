// errormap.cpp - the predicted error map of a fitted model (errormap.hpp).
#include "errormap.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace pmhost {

namespace {

const double DEG = PI / 180;

} // namespace

// Per-axis 1-sigma of the correction at encoder (t, d) with inputs ctx:
// sqrt((J0 C J0 + J1 C J1) / 2), C the fit's covariance (rad^2).
double predicted_sigma(const FitOut &f, const pm_context &ctx, double t, double d)
{
    double T, D, v[3], r[2];
    if (pm_model_apply(&f.model, &ctx, t, d, &T, &D) != PM_OK ||
        !row_covariance(f, ctx, t, d, T, D, v, r))
        return NAN;
    const double tr = v[0] + v[2];
    return tr > 0 ? std::sqrt(tr / 2) : 0.0;
}

namespace {

// Inputs for the map: the run's mean temperature and time, no slew
// direction, the mean of every auxiliary column; the pier side given.
pm_context mean_context(const Run &run, int side)
{
    pm_context c = pm_context();
    double s[3 + PM_MAX_AUX] = {0};
    long n[3 + PM_MAX_AUX] = {0};
    for (const Obs &o : run.obs) {
        double x[3 + PM_MAX_AUX] = {o.ctx.temp_c, o.ctx.time_h, 0};
        for (int k = 0; k < PM_MAX_AUX; k++)
            x[3 + k] = o.ctx.aux[k];
        for (int k = 0; k < 3 + PM_MAX_AUX; k++)
            if (std::isfinite(x[k]))
                s[k] += x[k], n[k]++;
    }
    c.temp_c = n[0] ? s[0] / (double)n[0] : 0;
    c.time_h = n[1] ? s[1] / (double)n[1] : 0;
    c.dir = 0;
    c.pier = side;
    for (int k = 0; k < PM_MAX_AUX; k++)
        c.aux[k] = n[3 + k] ? s[3 + k] / (double)n[3 + k] : 0;
    return c;
}

// The pier side of the run's star nearest to (ha, dec) on the sky (+1 when
// it gives none).
int nearest_side(const Run &run, const FitOut &f, double ha, double dec)
{
    double best = -2;
    int side = 1;
    for (int i : f.idx) {
        const Obs &o = run.obs[i];
        double c = std::sin(dec) * std::sin(o.ad) + std::cos(dec) * std::cos(o.ad) * std::cos(ha - o.ah);
        if (c > best)
            best = c, side = o.pier < 0 ? -1 : 1;
    }
    return side;
}

// How the run's German mount chooses its pier side, as pmfit plan plans it
// (its default --meridian-limit of 15 deg): beyond the limit the side the
// run's own points there vote for (ASCOM's, the normal side looking west,
// without any), within it the side of the nearest star.  A run all on the
// normal side, or without pier sides, is taken as a mount that does not
// flip (nearest star everywhere: a fork, or a German mount whose run never
// flipped, for which the map may then be too kind where it would).
// Before, every place took the side of its nearest star: a
// run all east of the meridian, beyond the pole, mapped the west sky on
// the side the mount cannot use there (1.8" RMS over the sky where that
// side's own covariance gives 24").
struct SideRule {
    bool flips = false;
    int normal_west = 1; // +1: the normal side looks west (ASCOM)
};

const double MERIDIAN_LIMIT_DEG = 15;

SideRule side_rule(const Run &run, const std::vector<int> &idx)
{
    SideRule r;
    long vote = 0, flipped = 0;
    for (int i : idx) {
        const Obs &o = run.obs[i];
        double x = std::remainder(o.ah, 2 * PI) / DEG;
        int side = o.pier < 0 ? -1 : 1;
        flipped += side < 0;
        if (std::fabs(x) > MERIDIAN_LIMIT_DEG)
            vote += (x > 0 ? 1 : -1) * side;
    }
    // A run with no point beyond the pole may be of a fork (or a German
    // mount that never flipped): each place then takes its nearest star's
    // side, as before (the side rule put a fork's unsampled west on the
    // side it never uses: 32" predicted where the fit errs by 4.2", an
    // outside probe); a point beyond the pole says the mount flips.
    r.flips = flipped > 0;
    r.normal_west = vote < 0 ? -1 : 1;
    return r;
}

double elevation(const Run &run, double ha, double dec)
{
    return std::asin(std::sin(run.latitude) * std::sin(dec) +
                     std::cos(run.latitude) * std::cos(dec) * std::cos(ha));
}

} // namespace

ErrorMap error_map(const Run &run, const FitOut &f, int side)
{
    ErrorMap e;
    int P = f.model.n_terms;
    if (f.cov.size() != (size_t)(P * P))
        throw std::runtime_error("error map: the fit has no covariance");
    e.dof = 2 * f.res.n_obs - f.res.n_par;
    bool altaz = run.mount == PM_MOUNT_ALTAZ;
    e.elevation = altaz || std::isfinite(run.latitude);
    // the usable sky: above the run's lowest star (whole degrees, >= 0 in elevation)
    double lo = 90, ss = 0;
    long np = 0;
    for (int i : f.idx) {
        const Obs &o = run.obs[i];
        double y = altaz ? o.ad : e.elevation ? elevation(run, o.ah, o.ad) : o.ad;
        lo = std::min(lo, y / DEG);
        double x = std::remainder(o.ah, 2 * PI) / DEG;
        e.marks.push_back({altaz && x < 0 ? x + 360 : x, o.ad / DEG});
        double s = predicted_sigma(f, o.ctx, o.eh, o.ed);
        if (std::isfinite(s))
            ss += s * s, np++;
    }
    e.limit_deg = e.elevation ? std::max(0.0, std::floor(lo)) : std::floor(lo);
    e.at_points_arcsec = np ? std::sqrt(ss / (double)np) * RAD2AS : NAN;
    pm_context ctx = mean_context(run, side);
    // the side rule of the fitted points, or for a model of one pier side
    // (pmfit fit --pier split) of the whole run: such a model is mapped
    // where the mount uses that side only (both sides' models had been
    // mapped over the whole sky, where each is used on half of it: gem-28's
    // west model warned of 3.35 times its sigma)
    std::vector<int> every;
    if (side)
        for (size_t i = 0; i < run.obs.size(); i++)
            every.push_back((int)i);
    const SideRule rule = altaz ? SideRule() : side_rule(run, side ? every : f.idx);
    double sum = 0, area = 0;
    const double step = 3;
    for (double y = -90 + step / 2; y < 90; y += step) {
        int nx = std::max(1, (int)std::lround(360 / step * std::cos(y * DEG)));
        double w = 360.0 / nx;
        for (int k = 0; k < nx; k++) {
            double x = (altaz ? 0 : -180) + w * (k + 0.5);
            double above = altaz ? y : e.elevation ? elevation(run, x * DEG, y * DEG) / DEG : y;
            if (above < e.limit_deg)
                continue;
            // the encoder position of that place on this pier side (side 0
            // of an equatorial mount: the side the mount takes there, as
            // side_rule says)
            double t = x * DEG, d = y * DEG;
            const int ruled = rule.flips && std::fabs(x) > MERIDIAN_LIMIT_DEG
                                  ? (x > 0 ? 1 : -1) * rule.normal_west
                                  : 0;
            if (side && ruled && ruled != side)
                continue; // (the mount takes the other side there)
            int sd = altaz ? 0 : side ? side : ruled ? ruled : nearest_side(run, f, t, d);
            ctx.pier = sd;
            if (sd < 0)
                t += PI, d = PI - d;
            double s = predicted_sigma(f, ctx, t, d) * RAD2AS;
            if (!std::isfinite(s))
                continue;
            e.cells.push_back({x, y, w, step, s});
            // the cell's area, w cos(y) by step (about step^2 everywhere:
            // nx follows cos y).  It had been cos(y) alone, which with the
            // cells' equal areas weighted the RMS by cos^2 and told a map
            // of stars below 40 deg elevation 1.8 times too good (an
            // outside probe: actual/predicted 1.78, 0.94 with the area).
            double a = w * std::cos(y * DEG);
            sum += s * s * a;
            area += a;
            if (s > e.max_arcsec)
                e.max_arcsec = s, e.max_x_deg = x, e.max_y_deg = y;
        }
    }
    e.mean_arcsec = area > 0 ? std::sqrt(sum / area) : NAN;
    return e;
}

std::string error_map_text(const Run &run, const ErrorMap &e)
{
    bool altaz = run.mount == PM_MOUNT_ALTAZ;
    char b[600];
    std::snprintf(b, sizeof b,
                  "  predicted pointing error of this model (1 sigma per axis, from the fit's "
                  "covariance; not what the model leaves out, which sigma holds with the "
                  "noise):\n    over the sky above %s %.0f deg (the lowest star): RMS %.3g\", "
                  "max %.3g\" at %s %.0f deg, %s %.0f deg; at the stars %.3g\"",
                  e.elevation ? "elevation" : "declination", e.limit_deg, e.mean_arcsec,
                  e.max_arcsec, altaz ? "azimuth" : "HA", e.max_x_deg,
                  altaz ? "elevation" : "Dec", e.max_y_deg, e.at_points_arcsec);
    return b;
}

namespace {

// The regularised lower incomplete gamma P(a, x) (the chi^2 CDF with 2a
// degrees of freedom at 2x), by its series: sum over n of the Poisson-like
// terms e^-x x^(a+n) / Gamma(a+n+1), each at most 1 (no overflow), the
// first in logarithms.  For a <= 50 and x <= 550 (chi2_quantile's range)
// that first term is above 1e-170 (no underflow).
double gamma_p(double a, double x)
{
    if (!(x > 0))
        return 0;
    double term = std::exp(-x + a * std::log(x) - std::lgamma(a + 1)), sum = term;
    for (int n = 1; n < 2000 && term > 1e-17 * sum; n++) {
        term *= x / (a + n);
        sum += term;
    }
    return std::min(1.0, sum);
}

// The chi^2 quantile with k degrees of freedom at probability p: bisection
// on gamma_p to k = 100; beyond, Wilson and Hilferty's cube-root normal
// form, within 1e-4 of it there (p 0.025 or 0.975 only: z = -+1.959964).
// (The series had overflowed at 2,000 degrees of freedom: a factor range of
// [0.576, 0.576].)
double chi2_quantile(long k, double p)
{
    if (k > 100) {
        const double z = p < 0.5 ? -1.959963985 : 1.959963985, c = 2.0 / (9.0 * (double)k);
        const double w = 1 - c + z * std::sqrt(c);
        return (double)k * w * w * w;
    }
    double lo = 0, hi = 10.0 * (double)k + 100;
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi);
        (gamma_p(0.5 * (double)k, 0.5 * mid) < p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

std::string few_dof_text(const ErrorMap &e)
{
    const std::pair<double, double> f = sigma_factor_95(e.dof);
    if (e.dof <= 0 || !(f.second > 2))
        return "";
    return fmt("its sigma, and the map scaled by it, rest on only %ld degree%s of freedom "
               "(2N - P): the true sigma may be %.2g to %.3g times it (95%%); take more stars "
               "or lower --order",
               e.dof, e.dof == 1 ? "" : "s", f.first, f.second);
}

} // namespace

std::pair<double, double> sigma_factor_95(long dof)
{
    if (dof <= 0)
        return {1, 1};
    const double k = (double)dof;
    return {std::sqrt(k / chi2_quantile(dof, 0.975)), std::sqrt(k / chi2_quantile(dof, 0.025))};
}

std::string undetermined_warning(const ErrorMap &e, double sigma_arcsec)
{
    const std::string few = few_dof_text(e);
    if (!(e.mean_arcsec > UNDETERMINED_RATIO * sigma_arcsec) || !(sigma_arcsec > 0))
        return few;
    char b[600];
    std::snprintf(b, sizeof b,
                  "the stars do not determine this model between them: its predicted error over "
                  "the sky above %s %.0f deg, %.3g\" RMS, is %.3g times the residual sigma "
                  "(%.3g\"), so its terms are extrapolated, not measured; lower --order, or take "
                  "stars where the error is largest (pmfit plan RUN)",
                  e.elevation ? "elevation" : "declination", e.limit_deg, e.mean_arcsec,
                  e.mean_arcsec / sigma_arcsec, sigma_arcsec);
    return few.empty() ? std::string(b) : std::string(b) + "; and " + few;
}

std::string error_map_json(const ErrorMap &e, double sigma_arcsec)
{
    const std::pair<double, double> f95 = sigma_factor_95(e.dof);
    char b[400];
    std::snprintf(b, sizeof b,
                  "\"error_map\": {\"limit\": \"%s\", \"limit_deg\": %.6g, \"rms_arcsec\": %.6g, "
                  "\"max_arcsec\": %.6g, \"max_at_deg\": [%.6g, %.6g], \"at_points_arcsec\": %.6g, "
                  "\"undetermined\": %s, \"sigma_dof\": %ld, \"sigma_factor_95\": [%.6g, %.6g]}",
                  e.elevation ? "elevation" : "declination", e.limit_deg, e.mean_arcsec,
                  e.max_arcsec, e.max_x_deg, e.max_y_deg, e.at_points_arcsec,
                  e.mean_arcsec > UNDETERMINED_RATIO * sigma_arcsec && sigma_arcsec > 0 ? "true"
                                                                                      : "false",
                  e.dof, f95.first, f95.second);
    return b;
}

void error_map_plot(const std::string &path, const Run &run, const ErrorMap &e,
                    const std::string &title)
{
    bool altaz = run.mount == PM_MOUNT_ALTAZ;
    std::string err;
    if (pmplot::sky_scalar(path, title, altaz ? "azimuth (deg)" : "hour angle (deg)",
                           altaz ? "elevation (deg)" : "declination (deg)", e.cells,
                           "1 sigma (arcsec)", e.marks, "observed stars", &err) != 0)
        throw std::runtime_error(err);
}

} // namespace pmhost
