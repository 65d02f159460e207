// explain_interpret.cpp - stage "interpret" of pmfit explain: the physical
// reading of a fitted model (docs/explain.md, "What the baseline holds").
// The polar axis as an altitude and azimuth error (an alt-az mount: the
// tilt of its azimuth axis), non-perpendicularity, collimation, the two
// indices, and the part of the order-1 terms that is tube flexure: a sag
// cos(el) toward the zenith is an exact combination of order-1 terms, so an
// order-1 baseline holds it without naming it.
#include "explain_internal.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pmhost {

namespace xdetail {

bool solve(std::vector<double> A, std::vector<double> &b, int n, double rel_tol)
{
    double scale = 0;
    for (int k = 0; k < n; k++)
        scale = std::max(scale, std::fabs(A[(size_t)(k * n + k)]));
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (std::fabs(A[(size_t)(i * n + k)]) > std::fabs(A[(size_t)(p * n + k)]))
                p = i;
        if (!(std::fabs(A[(size_t)(p * n + k)]) > rel_tol * scale))
            return false;
        for (int j = 0; j < n; j++)
            std::swap(A[(size_t)(k * n + j)], A[(size_t)(p * n + j)]);
        std::swap(b[(size_t)k], b[(size_t)p]);
        for (int i = k + 1; i < n; i++) {
            double f = A[(size_t)(i * n + k)] / A[(size_t)(k * n + k)];
            for (int j = k; j < n; j++)
                A[(size_t)(i * n + j)] -= f * A[(size_t)(k * n + j)];
            b[(size_t)i] -= f * b[(size_t)k];
        }
    }
    for (int k = n - 1; k >= 0; k--) {
        for (int j = k + 1; j < n; j++)
            b[(size_t)k] -= A[(size_t)(k * n + j)] * b[(size_t)j];
        b[(size_t)k] /= A[(size_t)(k * n + k)];
    }
    return true;
}

} // namespace xdetail

using namespace xdetail;

namespace {

double cov_of(const FitOut &f, int i, int j)
{
    int P = f.model.n_terms;
    return f.cov.empty() ? 0 : f.cov[(size_t)(i * P + j)];
}

// Where the mount's pole (encoder axis 2 at +-90 deg) points for polar
// offsets (a, b) alone: its offset from the true pole toward axis-1 angle 0
// (x) and toward +90 deg (y), radians.
void pole_offset(int mount, double a, double b, double pole, double *x, double *y)
{
    pm_model m;
    pm_model_init(&m, mount, 0);
    m.coef[0] = a;
    m.coef[1] = b;
    *x = *y = 0;
    if (pm_model_prepare(&m) != PM_OK)
        return;
    double t, d;
    if (pm_model_apply(&m, nullptr, 0.0, pole, &t, &d) != PM_OK)
        return;
    double rho = PI / 2 - std::fabs(d);
    *x = rho * std::cos(t);
    *y = rho * std::sin(t);
}

// A linear function of (a, b), by differences, and its 1-sigma error.
void polar(const FitOut &f, int mount, double pole, double out[2], double err[2])
{
    const double h = 1e-7;
    double a = f.model.coef[0], b = f.model.coef[1], x0, y0, xa, ya, xb, yb;
    pole_offset(mount, a, b, pole, &x0, &y0);
    pole_offset(mount, a + h, b, pole, &xa, &ya);
    pole_offset(mount, a, b + h, pole, &xb, &yb);
    double J[2][2] = {{(xa - x0) / h, (xb - x0) / h}, {(ya - y0) / h, (yb - y0) / h}};
    double caa = cov_of(f, 0, 0), cab = cov_of(f, 0, 1), cbb = cov_of(f, 1, 1);
    out[0] = x0;
    out[1] = y0;
    for (int k = 0; k < 2; k++)
        err[k] = std::sqrt(std::fabs(J[k][0] * J[k][0] * caa + 2 * J[k][0] * J[k][1] * cab +
                                     J[k][1] * J[k][1] * cbb));
}

Interpretation item(const char *what, double v, double e, const char *unit, const std::string &text)
{
    Interpretation it;
    it.what = what;
    it.value = v;
    it.error = e;
    it.unit = unit;
    it.text = text;
    return it;
}

// An angle and its error (radians) as text: arcminutes from 1', else
// arcseconds (0.01' would hide a well-measured 0.7").
// An error that would print as 0.00 in the value's unit goes down a unit,
// or to two significant figures: "3.00' +- 0.00'" had hidden a 0.15" error
// (an outside probe).
std::string angle_text(double v, double e)
{
    char b[80], err[40];
    const bool arcmin = std::fabs(v) * RAD2AS >= 60;
    if (arcmin && e * RAD2AS / 60 >= 0.005)
        std::snprintf(err, sizeof err, "%.2f'", e * RAD2AS / 60);
    else if (e * RAD2AS >= 0.005 || !(e > 0))
        std::snprintf(err, sizeof err, "%.2f\"", e * RAD2AS);
    else
        std::snprintf(err, sizeof err, "%.2g\"", e * RAD2AS);
    if (arcmin)
        std::snprintf(b, sizeof b, "%.2f' +- %s", v * RAD2AS / 60, err);
    else
        std::snprintf(b, sizeof b, "%.2f\" +- %s", v * RAD2AS, err);
    return b;
}

void polar_items(const Run &run, const FitOut &f, std::vector<Interpretation> &out)
{
    bool az = run.mount == PM_MOUNT_ALTAZ;
    bool south = !az && std::isfinite(run.latitude) && run.latitude < 0;
    double v[2], e[2];
    polar(f, run.mount, south ? -PI / 2 : PI / 2, v, e);
    const double am = RAD2AS / 60;
    char buf[400];
    if (az) {
        // the azimuth axis's tilt: toward azimuth 0 (north) and 90 (east)
        std::snprintf(buf, sizeof buf, "azimuth axis tilted %s toward the %s",
                      angle_text(std::fabs(v[0]), e[0]).c_str(), v[0] >= 0 ? "north" : "south");
        out.push_back(item("axis_tilt_north", v[0] * am, e[0] * am, "arcmin", buf));
        std::snprintf(buf, sizeof buf, "azimuth axis tilted %s toward the %s",
                      angle_text(std::fabs(v[1]), e[1]).c_str(), v[1] >= 0 ? "east" : "west");
        out.push_back(item("axis_tilt_east", v[1] * am, e[1] * am, "arcmin", buf));
        return;
    }
    // from the pole, hour angle 0 is toward the zenith, +6h toward the west
    double cl = std::isfinite(run.latitude) ? std::cos(run.latitude) : NAN;
    std::snprintf(buf, sizeof buf, "polar axis %s %s the pole in altitude%s",
                  angle_text(std::fabs(v[0]), e[0]).c_str(), v[0] >= 0 ? "above" : "below",
                  std::isfinite(run.latitude) ? "" : " (latitude not given: the north pole taken)");
    out.push_back(item("polar_altitude", v[0] * am, e[0] * am, "arcmin", buf));
    std::string az_deg;
    if (std::isfinite(cl) && cl > 0.05)
        az_deg = "; " + angle_text(std::fabs(v[1]) / cl, e[1] / cl) + " in azimuth at this latitude";
    std::snprintf(buf, sizeof buf, "polar axis %s %s of the pole on the sky%s",
                  angle_text(std::fabs(v[1]), e[1]).c_str(), v[1] >= 0 ? "west" : "east", az_deg.c_str());
    out.push_back(item("polar_azimuth_west", v[1] * am, e[1] * am, "arcmin", buf));
}

void axis_items(const Run &run, const FitOut &f, std::vector<Interpretation> &out)
{
    bool az = run.mount == PM_MOUNT_ALTAZ;
    const double as = RAD2AS;
    char buf[300];
    // the indices as "apparent minus encoder": c' shifts tau by +c', e'
    // shifts delta by -e' (docs/model.md, the base vectors)
    struct {
        int k;
        double sign;
        const char *key, *words;
    } t[4] = {{3, 1, "non_perpendicularity", az ? "elevation axis not perpendicular to the azimuth axis by"
                                                : "declination axis not perpendicular to the polar axis by"},
              {5, 1, "collimation", az ? "optical axis not perpendicular to the elevation axis (collimation) by"
                                       : "optical axis not perpendicular to the declination axis (collimation) by"},
              {2, 1, "index_axis1", az ? "azimuth index (true minus encoder azimuth)"
                                       : "hour-angle index (true minus encoder hour angle)"},
              {4, -1, "index_axis2", az ? "elevation index (true minus encoder elevation)"
                                        : "declination index (true minus encoder declination, pier east)"}};
    for (const auto &x : t) {
        double v = x.sign * f.model.coef[x.k] * as, e = f.res.err[x.k] * as;
        if (std::fabs(v) < 600)
            std::snprintf(buf, sizeof buf, "%s %.2f\" +- %.2f\"", x.words, v, e);
        else // an index of degrees reads better in degrees; the error stays in arcsec
            std::snprintf(buf, sizeof buf, "%s %.4f deg (%.1f\") +- %.2f\"", x.words, v / 3600, v, e);
        out.push_back(item(x.key, v, e, "arcsec", buf));
    }
}

// The tube-flexure field as an exact combination x of the model's terms
// (least squares over the run's points; exact to rounding or not at all).
// The combination is sparse (alt-az: a*Y(1,-1) and b*Y(1,1) alone), but on a
// sky that nearly confounds the terms (an elevation band) the normal
// equations' solution carries rounding of 1e-9 on the others; read as part
// of the sag, those terms' coefficients of degrees made the reading 3026" +-
// 86" of a sag of -6" (an outside probe's control run, el 10-35 deg).  So
// the components above 1e-6 of the largest are solved for again alone and
// kept where that is exact.
bool sag_combination(const Run &run, const FitOut &f, std::vector<double> &x)
{
    std::vector<std::string> tf = {"tube_flexure"};
    // both at zero isotropic terms: the combination of the ideal mount (the
    // frame of a mount with index terms of degrees differs in the second
    // order only)
    pm_model s = build_model(0, tf, run.obs, run.mount, run.latitude, run.aux_names), m = f.model;
    for (int k = 0; k < m.n_terms; k++)
        m.coef[k] = 0;
    if (pm_model_prepare(&s) != PM_OK || pm_model_prepare(&m) != PM_OK)
        return false;
    int P = f.model.n_terms;
    std::vector<double> A((size_t)(P * P), 0.0), r0(PM_MAX_TERMS), r1(PM_MAX_TERMS), t0(PM_MAX_TERMS),
        t1(PM_MAX_TERMS), rows, b((size_t)P, 0.0);
    double ss = 0;
    for (int i : f.idx) {
        const Obs &o = run.obs[i];
        double r[2];
        if (pm_fit_row(&m, &o.ctx, o.eh, o.ed, o.ah, o.ad, r0.data(), r1.data(), r) != PM_OK ||
            pm_fit_row(&s, &o.ctx, o.eh, o.ed, o.ah, o.ad, t0.data(), t1.data(), r) != PM_OK)
            return false;
        for (int a = 0; a < P; a++) {
            b[(size_t)a] += r0[(size_t)a] * t0[6] + r1[(size_t)a] * t1[6];
            for (int c = 0; c < P; c++)
                A[(size_t)(a * P + c)] += r0[(size_t)a] * r0[(size_t)c] + r1[(size_t)a] * r1[(size_t)c];
        }
        ss += t0[6] * t0[6] + t1[6] * t1[6];
        rows.insert(rows.end(), r0.begin(), r0.begin() + P);
        rows.insert(rows.end(), r1.begin(), r1.begin() + P);
        rows.push_back(t0[6]);
        rows.push_back(t1[6]);
    }
    if (!(ss > 0))
        return false;
    // the least squares on the terms `on` alone: x (zero elsewhere), exact?
    auto combination = [&](const std::vector<int> &on, std::vector<double> &out) {
        const int n = (int)on.size();
        std::vector<double> As((size_t)(n * n)), bs((size_t)n);
        for (int a = 0; a < n; a++) {
            bs[(size_t)a] = b[(size_t)on[(size_t)a]];
            for (int c = 0; c < n; c++)
                As[(size_t)(a * n + c)] = A[(size_t)(on[(size_t)a] * P + on[(size_t)c])];
        }
        if (n == 0 || !solve(As, bs, n))
            return false;
        out.assign((size_t)P, 0.0);
        for (int a = 0; a < n; a++)
            out[(size_t)on[(size_t)a]] = bs[(size_t)a];
        double miss = 0;
        size_t stride = (size_t)(2 * P + 2);
        for (size_t j = 0; j + stride <= rows.size(); j += stride)
            for (int c = 0; c < 2; c++) {
                double v = -rows[j + (size_t)(2 * P + c)];
                for (int a = 0; a < P; a++)
                    v += rows[j + (size_t)(c * P + a)] * out[(size_t)a];
                miss += v * v;
            }
        return miss <= 1e-16 * ss;
    };
    std::vector<int> all, big;
    for (int a = 0; a < P; a++)
        all.push_back(a);
    if (!combination(all, x))
        return false;
    double top = 0;
    for (double v : x)
        top = std::max(top, std::fabs(v));
    for (int a = 0; a < P; a++)
        if (std::fabs(x[(size_t)a]) > 1e-6 * top)
            big.push_back(a);
    std::vector<double> sparse;
    if (big.size() < all.size() && combination(big, sparse))
        x = sparse;
    return true;
}

// The sag that the order-1 terms hold: generalised least squares of their
// fitted values c_S on the sag's combination x_S, with their covariance.
void sag_item(const Run &run, const FitOut &f, std::vector<Interpretation> &out)
{
    // (order 1 only: beside harmonics of order 2 and more, which share the
    // order-1 terms' shapes on a run's sky, the sag's combination read
    // thousands of arcseconds +- hundreds on runs with none, an outside
    // probe: 5276" +- 292" at order 3, -2.7" +- 1.9" at order 1)
    std::vector<double> x;
    if (f.model.order != 1 || f.cov.empty() || !sag_combination(run, f, x))
        return;
    double big = 0;
    for (double v : x)
        big = std::max(big, std::fabs(v));
    std::vector<int> S;
    for (int i = 0; i < (int)x.size(); i++)
        if (std::fabs(x[(size_t)i]) > 1e-9 * big)
            S.push_back(i);
    int n = (int)S.size();
    if (n == 0)
        return;
    // W x_S and W c_S with W = Cov_SS^-1
    std::vector<double> C((size_t)(n * n)), wx((size_t)n), wc((size_t)n);
    for (int a = 0; a < n; a++) {
        wx[(size_t)a] = x[(size_t)S[(size_t)a]];
        wc[(size_t)a] = f.model.coef[S[(size_t)a]];
        for (int b = 0; b < n; b++)
            C[(size_t)(a * n + b)] = cov_of(f, S[(size_t)a], S[(size_t)b]);
    }
    if (!solve(C, wx, n) || !solve(C, wc, n))
        return;
    double xwx = 0, xwc = 0, cwc = 0;
    for (int a = 0; a < n; a++) {
        xwx += x[(size_t)S[(size_t)a]] * wx[(size_t)a];
        xwc += x[(size_t)S[(size_t)a]] * wc[(size_t)a];
        cwc += f.model.coef[S[(size_t)a]] * wc[(size_t)a];
    }
    if (!(xwx > 0))
        return;
    double t = xwc / xwx, et = 1 / std::sqrt(xwx), chi2 = cwc - t * xwc;
    // Where the terms hold more than a sag, the error is scaled by
    // sqrt(chi^2 / dof) (the Birge ratio): the sag's share of terms that
    // are not in its proportions is known only that well.  Unscaled, an
    // alt-az run in a band of elevation 20-40 deg, where cos(el) is nearly
    // the elevation index, read 372.77" +- 1.69" of sag that was not there
    // (chi^2 3.1e7 for 7 degrees of freedom; an outside probe).
    const bool consistent = chi2 <= n - 1 + 3 * std::sqrt(2.0 * (n - 1));
    const double birge = n > 1 && chi2 > n - 1 ? std::sqrt(chi2 / (n - 1)) : 1.0;
    if (!consistent)
        et *= birge;
    char buf[700];
    // The direct fit of order 0 + tube flexure on the same points: where the
    // two disagree beyond 3 sigma and the order-1 reading is the far less
    // precise, other terms share the sag's shape on this sky, and the
    // order-1 reading is not given as a measurement (an outside probe's forks at declinations
    // 75-88 deg read 224.66" +- 32.12" of a 15" sag, "consistent with a pure
    // sag", where the direct fit said 11.69" +- 3.20")
    {
        pm_model m0 = build_model(0, {"tube_flexure"}, run.obs, run.mount, run.latitude,
                                  run.aux_names);
        FitOut f0 = do_fit(run.obs, f.idx, m0);
        if (f0.status == PM_OK && m0.n_terms == 7) {
            const double t0 = f0.model.coef[6], e0 = f0.res.err[6];
            // (and only where the order-1 terms fix the sag far less well
            // than the direct fit: on a real mount with more than a sag,
            // the MMT's, the two differ, -23.9" +- 1.1" and -13.74" +-
            // 0.43", and the order-1 reading is the one to trust)
            if (std::fabs(t - t0) > 3 * std::sqrt(et * et + e0 * e0) && et > 3 * e0) {
                std::snprintf(buf, sizeof buf,
                              "tube flexure held by the order-1 terms: not read on this sky "
                              "(%.1f\" +- %.1f\" from the %zu terms that would hold it, %.2f\" "
                              "+- %.2f\" fitted directly with order 0 + tube_flexure: other "
                              "terms share its shape here, or the mount holds more than a sag)",
                              t * RAD2AS, et * RAD2AS, S.size(), t0 * RAD2AS, e0 * RAD2AS);
                out.push_back(item("tube_flexure_in_order1", t * RAD2AS, et * RAD2AS, "arcsec", buf));
                return;
            }
        }
    }
    // An error of more than 100" (a tube's sag is tens of arcseconds at
    // most) reads nothing: said so, not a value of thousands of arcseconds
    // (an outside probe's control runs in a band of elevation: -2065" +-
    // 2870" of a sag of -6")
    if (et * RAD2AS > 100) {
        std::snprintf(buf, sizeof buf,
                      "tube flexure held by the order-1 terms: not determined on this sky (%.0f\" "
                      "+- %.0f\"; a sag is tens of arcseconds): the %zu terms that would hold it are "
                      "too loosely fixed by these points",
                      t * RAD2AS, et * RAD2AS, S.size());
        out.push_back(item("tube_flexure_in_order1", t * RAD2AS, et * RAD2AS, "arcsec", buf));
        return;
    }
    std::snprintf(buf, sizeof buf,
                  "tube flexure held by the order-1 terms: %.2f\" +- %.2f\" of cos(el) toward the "
                  "zenith (a sag toward the horizon is negative); it is %zu of them in fixed "
                  "proportion, and they %s a pure sag (chi^2 %.1f for %d degree%s of freedom%s)",
                  t * RAD2AS, et * RAD2AS, S.size(), consistent ? "are consistent with" : "hold more than",
                  chi2, n - 1, n - 1 == 1 ? "" : "s",
                  consistent ? "" : pmhost::fmt("; the error scaled by sqrt(chi^2/dof), %.3g", birge).c_str());
    out.push_back(item("tube_flexure_in_order1", t * RAD2AS, et * RAD2AS, "arcsec", buf));
}

} // namespace

std::vector<Interpretation> interpret(const Run &run, const FitOut &f)
{
    std::vector<Interpretation> out;
    if (f.status != PM_OK)
        return out;
    polar_items(run, f, out);
    axis_items(run, f, out);
    if (run.mount == PM_MOUNT_ALTAZ || std::isfinite(run.latitude))
        sag_item(run, f, out);
    return out;
}

} // namespace pmhost
