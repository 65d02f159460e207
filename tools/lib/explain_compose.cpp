// explain_compose.cpp - pmfit explain's baseline composed as a gimbal
// (docs/explain.md, step 1, "Composed as a gimbal"): the second-order part
// of the baseline's anisotropic terms, taken out of the observations
// before the search.
//
// The library's model (docs/model.md) applies the six isotropic terms as
// exact rotations and the anisotropic ones (harmonics of degree >= 1 times
// the base vectors) as one small first-order displacement.  A real mount
// whose gimbal parameters vary over the sky (an axis angle, the
// non-perpendicularity, the collimation, the polar-axis tilt: what flexure
// and bearings do) composes those variations with each other and with the
// rotations: at 10' of anisotropy that leaves 0.2-0.3" of second-order
// structure an order-1 fit cannot hold, which the search would report as
// higher order or a two-cycle term, though nothing physical was left out.
// Read as a gimbal, the same fitted coefficients say the mount's six
// parameters are at each point the isotropic value plus the sum S_k of its
// harmonics (the base vectors are the parameters' first derivatives), so
// the exact prediction is the isotropic rotations with those parameters.
// What that adds to the fitted model is the correction taken out here.

#include "explain_internal.hpp"
#include "errormap.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <stdexcept>
#include <cmath>
#include <vector>

namespace pmhost {
namespace xdetail {

namespace {

// The isotropic coefficients (l = 0) of a model's harmonic set, by base
// vector, and the highest degree of its anisotropic harmonics (0: none).
int iso_and_degree(const pm_model &m, double iso[6])
{
    int deg = 0;
    for (int k = 0; k < 6; k++)
        iso[k] = 0;
    for (int i = 0; i < m.n_base; i++) {
        const pm_term &t = m.term[i];
        if (t.kind != PM_TERM_SH || t.k < 1 || t.k > 6)
            continue;
        if (t.l == 0)
            iso[t.k - 1] = m.coef[i];
        else if (t.l > deg)
            deg = t.l;
    }
    return deg;
}

// The readings a first-order fit cannot tell apart, which differ as
// gimbals (fitted to second order: a run of 10' of anisotropy can tell).
// g, h: the first-order null directions of degree 1, the model's two
// dropped terms of that degree (include/pm.h, pm_model_init Note 2): the
// identity sum_i p_i (e_i x p) = 0 makes a Y11 + b Y1,-1 + c' Y10 vanish,
// and p4 = -sin(dec) p6 makes i Y10 + d vanish; they move no point to
// first order, but a polar-axis tilt that follows the tube's x component
// is not an hour-angle index that follows its z one.  k: the order of the
// two polar-axis tilts (A about x, B about y).  The library's H is one
// rotation, exp([(A, B, 0)]x); turning about x, then y is exp of (A, B,
// AB/2) to second order (the Baker-Campbell-Hausdorff term), about y, then
// x (A, B, -AB/2): a turn about the pole of k AB/2, k in [-1, 1], which
// is an hour-angle index (c').
struct Null {
    double v[3] = {0, 0, 0}; // g, h, k
};
const int N_NULL = 3;

// The gimbal parameters at encoder position (t, d): per base vector k, the
// isotropic coefficient plus the harmonic sum S_k at the mechanical
// position (t + c', d - e'), where the model evaluates its harmonics, plus
// the null directions.  Y_lm comes from pm_terms_eval's Y_lm p_6, p_6 =
// (-sin t, cos t, 0) being a unit vector.
bool gimbal_params(const pm_model &m, int deg, const double iso[6], const Null &nu, double t,
                   double d, std::vector<double> &buf, double par[6])
{
    const double tm = t + iso[2], dm = d - iso[4];
    if (pm_terms_eval(deg, tm, dm, buf.data()) != PM_OK)
        return false;
    const double e0 = -std::sin(tm), e1 = std::cos(tm);
    auto Y = [&](int j) {
        const double *y = &buf[3 * (6 * j + 5)];
        return y[0] * e0 + y[1] * e1;
    };
    for (int k = 0; k < 6; k++)
        par[k] = iso[k];
    for (int i = 0; i < m.n_base; i++) {
        const pm_term &t6 = m.term[i];
        if (t6.kind != PM_TERM_SH || t6.l < 1 || t6.k < 1 || t6.k > 6)
            continue;
        par[t6.k - 1] += m.coef[i] * Y(t6.l * t6.l + t6.l + t6.m);
    }
    const double y1m = Y(1), y10 = Y(2), y11 = Y(3), g = nu.v[0], h = nu.v[1];
    par[0] += g * y11;
    par[1] += g * y1m;
    par[2] += g * y10;
    par[5] += h * y10;
    par[3] += h;
    par[2] += nu.v[2] * par[0] * par[1] / 2;
    return true;
}

// What the gimbal reading of a fitted model predicts, point by point.
struct Gimbal {
    const pm_model &fitted;
    double iso[6];
    int deg = 0;
    pm_model first, exact;
    std::vector<double> buf;
    bool ok = false;

    explicit Gimbal(const pm_model &f) : fitted(f)
    {
        deg = iso_and_degree(f, iso);
        // the fitted model's harmonic part alone (its added terms at zero)
        // and an order-0 model that takes each point's gimbal parameters
        first = f;
        for (int i = f.n_base; i < f.n_terms; i++)
            first.coef[i] = 0;
        ok = deg > 0 && pm_model_prepare(&first) == PM_OK &&
             pm_model_init(&exact, f.mount, 0) == PM_OK;
        exact.latitude = f.latitude;
        buf.resize(3 * 6 * (size_t)((deg + 1) * (deg + 1)));
    }
    // The exact prediction at o with the null amounts nu.
    bool predict(const Obs &o, const Null &nu, double *a, double *d)
    {
        double par[6];
        if (!gimbal_params(fitted, deg, iso, nu, o.eh, o.ed, buf, par))
            return false;
        for (int i = 0; i < exact.n_terms; i++)
            exact.coef[i] = par[exact.term[i].k - 1];
        return pm_model_prepare(&exact) == PM_OK &&
               pm_model_apply(&exact, &o.ctx, o.eh, o.ed, a, d) == PM_OK;
    }
    // Its difference from the fitted (first-order) model at o.
    bool offset(const Obs &o, const Null &nu, double *d1, double *d2)
    {
        double ea, ed, fa, fd;
        if (!predict(o, nu, &ea, &ed) ||
            pm_model_apply(&first, &o.ctx, o.eh, o.ed, &fa, &fd) != PM_OK)
            return false;
        *d1 = std::remainder(ea - fa, 2 * M_PI);
        *d2 = ed - fd;
        return true;
    }
};

// The run with gm's offsets at the null amounts nu taken out of its
// observed positions; false where an evaluation failed.
bool corrected(const Run &run, Gimbal &gm, const Null &nu, Run *out)
{
    for (size_t i = 0; i < run.obs.size(); i++) {
        double d1, d2;
        if (!gm.offset(run.obs[i], nu, &d1, &d2))
            return false;
        out->obs[i].ah = run.obs[i].ah - d1;
        out->obs[i].ad = run.obs[i].ad - d2;
    }
    return true;
}

// The residuals (2 per point) of the baseline refitted to the run
// corrected at nu: the null amounts' effect after the first-order terms
// have taken what they can of it (most of it: their second-order pattern
// is largely first-order itself).  Empty where it did not fit.
std::vector<double> refit_residuals(const Run &run, Gimbal &gm, const Null &nu,
                                    const std::vector<int> &all, const ExplainOptions &opt)
{
    Run c = run;
    std::vector<double> r;
    if (!corrected(run, gm, nu, &c))
        return r;
    Fit f = fit_spec(c, all, opt.order, opt.adds);
    if (!f.ok)
        return r;
    for (size_t i = 0; i < f.f.r0.size(); i++) {
        r.push_back(f.f.r0[i]);
        r.push_back(f.f.r1[i]);
    }
    return r;
}

double sum_sq(const std::vector<double> &r)
{
    double s = 0;
    for (double x : r)
        s += x * x;
    return s;
}

// One Gauss-Newton step for the null amounts on the refitted residuals
// (derivatives by central differences), kept within their bounds and only
// where it lowers chi^2 (halved up to four times).
Null null_step(const Run &run, Gimbal &gm, const Null &nu, const double bound[N_NULL],
               const std::vector<int> &all, const ExplainOptions &opt)
{
    const double eps[N_NULL] = {1e-5, 1e-5, 1e-3};
    const std::vector<double> r0 = refit_residuals(run, gm, nu, all, opt);
    if (r0.empty())
        return nu;
    // the 2 N_NULL refits side by side (parallel_for; each its own Gimbal:
    // predict() writes the Gimbal's scratch model)
    std::vector<double> side[2 * N_NULL];
    parallel_for(2 * N_NULL, [&](size_t w) {
        const int q = (int)(w / 2);
        Null a = nu;
        a.v[q] += (w % 2 ? -eps[q] : eps[q]);
        Gimbal own(gm.fitted);
        side[w] = refit_residuals(run, own, a, all, opt);
    });
    std::vector<double> jac[N_NULL];
    for (int q = 0; q < N_NULL; q++) {
        const std::vector<double> &rp = side[2 * q], &rm = side[2 * q + 1];
        if (rp.size() != r0.size() || rm.size() != r0.size())
            return nu;
        for (size_t i = 0; i < r0.size(); i++)
            jac[q].push_back((rm[i] - rp[i]) / (2 * eps[q])); // -d(residual)/d(amount)
    }
    std::vector<double> A(N_NULL * N_NULL, 0.0), d(N_NULL, 0.0);
    for (int q = 0; q < N_NULL; q++) {
        for (int w = 0; w < N_NULL; w++)
            for (size_t i = 0; i < r0.size(); i++)
                A[(size_t)(q * N_NULL + w)] += jac[q][i] * jac[w][i];
        for (size_t i = 0; i < r0.size(); i++)
            d[(size_t)q] += jac[q][i] * r0[i];
    }
    if (!solve(A, d, N_NULL, 1e-12))
        return nu;
    const double chi0 = sum_sq(r0);
    for (int half = 0; half < 5; half++) {
        Null t = nu;
        for (int q = 0; q < N_NULL; q++)
            t.v[q] = std::max(-bound[q], std::min(bound[q], nu.v[q] + d[q]));
        const std::vector<double> rt = refit_residuals(run, gm, t, all, opt);
        if (rt.size() == r0.size() && sum_sq(rt) < chi0)
            return t;
        for (int q = 0; q < N_NULL; q++)
            d[q] *= 0.5;
    }
    return nu;
}

// The null amounts' bounds: g and h twice the largest anisotropic
// coefficient (on noise-free runs of the independent gimbal with 10' of
// anisotropy the amounts the data choose are 0.5-0.8 of it), k 1 (the
// two orders of the tilts).
void null_bounds(const pm_model &m, double bound[N_NULL])
{
    double b = 0;
    for (int i = 0; i < m.n_base; i++)
        if (m.term[i].kind == PM_TERM_SH && m.term[i].l >= 1)
            b = std::max(b, std::fabs(m.coef[i]));
    bound[0] = bound[1] = 2 * b;
    bound[2] = 1;
}

// Passes of the composition from the run corrected as in *out: the
// baseline fitted, the null amounts stepped where `nulls`, the offsets
// taken out again (with the null amounts, until a pass lowers chi^2 by
// less than 0.1%: the amounts and the coefficients settle together, and
// where the tilts' order sits at its bound that takes up to eight).  *chi2: the baseline's chi^2 on the result (its first
// fit's in *chi2_first where given); false where a fit or an evaluation
// failed (*out is then the last good correction).
bool compose_passes(const Run &run, const ExplainOptions &opt, const std::vector<int> &all,
                    int passes, bool nulls, Null *nu, Run *out, double *chi2, int *P,
                    double *chi2_first, Fit *first_fit = nullptr)
{
    double before = 0;
    for (int pass = 0; pass <= passes; pass++) {
        Fit f = fit_spec(*out, all, opt.order, opt.adds);
        if (!f.ok)
            return false;
        *chi2 = f.chi2;
        *P = f.P;
        if (pass == 0 && chi2_first)
            *chi2_first = f.chi2;
        if (pass == 0 && first_fit)
            *first_fit = f;
        if (pass == passes || (nulls && pass >= 2 && !(f.chi2 < 0.999 * before)))
            return true;
        before = f.chi2;
        Gimbal gm(f.f.model);
        if (!gm.ok)
            return false;
        if (nulls) {
            double bound[N_NULL];
            null_bounds(f.f.model, bound);
            *nu = null_step(run, gm, *nu, bound, all, opt);
        }
        Run next = run;
        if (!corrected(run, gm, *nu, &next))
            return false;
        *out = next;
    }
    return true;
}

// Whether a fitted baseline determines its anisotropic terms: every
// harmonic coefficient of degree >= 1 known to better than the largest of
// them.  A gimbal's second-order terms are products of its parameters'
// variations; where some combination of them is not determined at the
// scale of the distortion itself (an order-3 baseline on 129 alt-az
// points: coefficients of 7,500" +- 28,000"), its products are arbitrary,
// and a "composition" of 94" came out of one.  Nor where the stars do not
// determine the model between them (the predicted error over the sky
// beyond UNDETERMINED_RATIO times sigma: pmfit fit's warning): the first
// 13 points of the MMT run, 22 terms, "composed" 0.41" out of a 0.39"
// sigma, and the page's explained sigma (0.313") was not what the fit it
// printed gives.
bool determined(const Run &run, const Fit &f)
{
    try {
        const ErrorMap em = error_map(run, f.f, 0);
        if (!undetermined_warning(em, f.f.res.sigma * RAD2AS).empty())
            return false;
    } catch (const std::runtime_error &) {
        return false; /* no covariance */
    }
    double big = 0, err = 0;
    for (int i = 0; i < f.f.model.n_base; i++) {
        const pm_term &t = f.f.model.term[i];
        if (t.kind == PM_TERM_SH && t.l >= 1) {
            big = std::max(big, std::fabs(f.f.model.coef[i]));
            err = std::max(err, f.f.res.err[i]);
        }
    }
    return err < big;
}

// The observations use of run, every k-th of them, k the smallest that
// leaves at most `most`.
Run thinned(const Run &run, const std::vector<int> &use, size_t most)
{
    const size_t k = (use.size() + most - 1) / most;
    Run t = run;
    t.obs.clear();
    for (size_t i = 0; i < use.size(); i += k)
        t.obs.push_back(run.obs[(size_t)use[i]]);
    return t;
}

} // namespace

// The composition (step 1): run with the baseline's composition taken out
// of its observed positions; *rms: its size (radians, RMS on the sky per
// axis, as sigma).  First without the null amounts (two passes: each
// pass's correction moves the coefficients at second order only); then
// the null amounts are fitted (up to eight Gauss-Newton passes; on at
// most 2,000 of the observations, every k-th: three numbers do not need
// more, and it keeps a 10,000-point run's explain within its budget) and
// the composition with them made on the whole run, kept only where it
// lowers chi^2 by more than chi^2(3) at 1% in noise variances (three
// amounts fitted to a run without them would pass once in a hundred); the
// composed reading is kept only where it fits better than the
// first-order one (chi^2; the same terms, the reading the data prefer).
// Else, and where the baseline does not fit, has no anisotropic terms or
// does not determine them, the run as it is and *rms = 0.  The baseline is
// opt's (order, adds) fitted to the observations use; every observation is
// corrected.
double shift_ss(const Run &a, const Run &b, const std::vector<int> &use)
{
    double ss = 0;
    for (int i : use) {
        const Obs &p = a.obs[(size_t)i], &q = b.obs[(size_t)i];
        const double d1 = std::remainder(p.ah - q.ah, 2 * M_PI) * std::cos(p.ad),
                     d2 = p.ad - q.ad;
        ss += d1 * d1 + d2 * d2;
    }
    return ss;
}

Run composed_run(const Run &run, const ExplainOptions &opt, const std::vector<int> &use,
                 double *rms)
{
    const double CHI2_3_AT_1PC = 11.34;
    const size_t NULL_FIT_MOST = 2000;
    *rms = 0;
    const std::vector<int> &all = use;
    Null none, nu;
    Run plain = run;
    double chi2_first = 0, chi2_plain = 0, chi2_null = 0;
    int P = 0;
    Fit first;
    if (!compose_passes(run, opt, all, 2, false, &none, &plain, &chi2_plain, &P, &chi2_first,
                        &first) ||
        !determined(run, first))
        return run;
    const Run *best = &plain;
    double chi2_best = chi2_plain;
    const Run est = thinned(run, all, NULL_FIT_MOST);
    Run est_out = thinned(plain, all, NULL_FIT_MOST);
    double chi2_est = 0;
    int P_est = 0;
    Run with = plain;
    if (compose_passes(est, opt, all_of(est.obs.size()), 8, true, &nu, &est_out, &chi2_est,
                       &P_est, nullptr) &&
        compose_passes(run, opt, all, 2, false, &nu, &with, &chi2_null, &P, nullptr)) {
        const double dof = 2.0 * (double)all.size() - P - N_NULL;
        if (dof > 0 && chi2_plain - chi2_null > CHI2_3_AT_1PC * chi2_null / dof) {
            best = &with;
            chi2_best = chi2_null;
        }
    }
    if (!(chi2_best < chi2_first))
        return run;
    *rms = all.empty() ? 0 : std::sqrt(shift_ss(run, *best, all) / (2.0 * (double)all.size()));
    return *best;
}

} // namespace xdetail
} // namespace pmhost
