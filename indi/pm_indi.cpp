/*
**  pm_indi.cpp - the INDI math plugin's fitting logic (pm_indi.h): the rule
**  for the order, the fit and its fallbacks.  Plain pm C API, no INDI.
*/
#include "pm_indi.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace
{

const double kPi = 3.14159265358979323846;
const int kMaxIter = 30;

double wrap_pi(double a)
{
    a = std::fmod(a, 2 * kPi);
    if (a > kPi)
        a -= 2 * kPi;
    else if (a <= -kPi)
        a += 2 * kPi;
    return a;
}

/* Index offsets: c' the circular mean of app1 - enc1, weighted by
** cos^2 of the star's axis-2 angle, e' the mean of enc2 - app2 (pm:
** apparent = (enc1 + c', enc2 - e') for a model of the index terms alone,
** exactly).  The weight: an axis-1 offset of the sky's error x reads
** x / cos(axis 2), so a sync near the pole (the zenith) carries its
** pointing error, and any polar (tilt) error, magnified by sec; unweighted,
** one such sync beside one at Dec 20 moved every GOTO by up to 11 deg (an
** outside probe; pm_fit_run's own start from the offsets weights so). */
void offsets(long n, const double *e1, const double *e2, const double *a1, const double *a2, double *c,
             double *e)
{
    double s = 0, co = 0, d = 0;
    for (long i = 0; i < n; i++) {
        const double t = a1[i] - e1[i], w = std::cos(a2[i]) * std::cos(a2[i]);
        s += w * std::sin(t);
        co += w * std::cos(t);
        d += e2[i] - a2[i];
    }
    *c = (s == 0 && co == 0) ? 0.0 : std::atan2(s, co);
    *e = n > 0 ? d / (double)n : 0.0;
}

/* A model of the given order whose isotropic terms are copied from src
** (or the offsets when src is NULL). */
pm_status start_model(pm_model *m, int mount, int order, const pm_model *src, double c, double e)
{
    pm_status st = pm_model_init(m, mount, order);
    if (st != PM_OK)
        return st;
    if (src) {
        for (int k = 0; k < 6; k++)
            m->coef[k] = src->coef[k];
    } else {
        int ic, ie;
        if (pm_model_find(m, PM_BASE_C, 0, 0, &ic) != PM_OK || pm_model_find(m, PM_BASE_E, 0, 0, &ie) != PM_OK)
            return PM_ERR_STATE;
        m->coef[ic] = c;
        m->coef[ie] = e;
    }
    return pm_model_prepare(m);
}

/* Near the pole: the tilt of the polar (azimuth) axis, a and b, that puts
** the n points where they belong (least squares; Gauss-Newton with the
** derivatives by differences, from the model m, which holds the rest).
** There a sky error is what a tilt gives, the same shift everywhere near the
** pole, where an index offset gives none (Note 3).  False where a step is
** not finite or the 2 x 2 system is singular (m then unchanged). */
bool fit_tilt(pm_model *m, long n, const double *e1, const double *e2, const double *a1,
              const double *a2)
{
    int ia, ib;
    if (pm_model_find(m, PM_BASE_A, 0, 0, &ia) != PM_OK || pm_model_find(m, PM_BASE_B, 0, 0, &ib) != PM_OK)
        return false;
    const pm_model start = *m;
    const int idx[2] = {ia, ib};
    const double h = 1e-7;
    /* the sum of squared residuals, and (J) its Gauss-Newton system */
    auto ssr = [&](pm_model *q, double A[3], double g[2]) -> double {
        double s = 0;
        if (A) {
            A[0] = A[1] = A[2] = g[0] = g[1] = 0;
        }
        for (long i = 0; i < n; i++) {
            double r0[2], rk[2][2];
            if (pm_model_residual(q, nullptr, e1[i], e2[i], a1[i], a2[i], r0) != PM_OK)
                return NAN;
            s += r0[0] * r0[0] + r0[1] * r0[1];
            if (!A)
                continue;
            for (int k = 0; k < 2; k++) {
                q->coef[idx[k]] += h;
                pm_status st = pm_model_prepare(q);
                if (st == PM_OK)
                    st = pm_model_residual(q, nullptr, e1[i], e2[i], a1[i], a2[i], rk[k]);
                q->coef[idx[k]] -= h;
                if (st != PM_OK || pm_model_prepare(q) != PM_OK)
                    return NAN;
            }
            for (int c = 0; c < 2; c++) {
                const double j0 = (rk[0][c] - r0[c]) / h, j1 = (rk[1][c] - r0[c]) / h;
                A[0] += j0 * j0;
                A[1] += j0 * j1;
                A[2] += j1 * j1;
                g[0] += j0 * r0[c];
                g[1] += j1 * r0[c];
            }
        }
        return s;
    };
    /* damped: a step that does not lower the sum is halved (near the pole
    ** the residual's frame turns with the position) */
    for (int it = 0; it < 30; it++) {
        double A[3], g[2];
        const double s0 = ssr(m, A, g);
        const double det = A[0] * A[2] - A[1] * A[1];
        if (!std::isfinite(s0) || !(A[0] > 0) || !(det > 1e-12 * (A[0] * A[2]))) {
            *m = start;
            pm_model_prepare(m);
            return false;
        }
        if (s0 < 1e-26 * (double)n) /* (1e-13 rad per point) */
            break;
        double d0 = (A[2] * g[0] - A[1] * g[1]) / det, d1 = (A[0] * g[1] - A[1] * g[0]) / det;
        const pm_model before = *m;
        bool lower = false;
        for (int half = 0; half < 30; half++) {
            *m = before;
            m->coef[ia] -= d0;
            m->coef[ib] -= d1;
            lower = pm_model_prepare(m) == PM_OK && ssr(m, nullptr, nullptr) < s0;
            if (lower)
                break;
            d0 /= 2;
            d1 /= 2;
        }
        if (!lower) {
            *m = before;
            pm_model_prepare(m);
            break;
        }
        if (std::fabs(d0) + std::fabs(d1) < 1e-14)
            break;
    }
    return true;
}

/* The most correlated pair of the fit's terms (after a solve): the signed
** correlation, their names into pair; 0 where none is available. */
double worst_corr(const pm_fit *fit, const pm_fit_result *fr, const pm_model *m, char *pair, size_t len)
{
    double best = 0;
    int bi = -1, bj = -1;
    for (int i = 0; i < fr->n_par; i++)
        for (int j = 0; j < i; j++) {
            double cov, corr;
            if (pm_fit_covariance(fit, fr, i, j, &cov, &corr) == PM_OK && std::fabs(corr) > std::fabs(best)) {
                best = corr;
                bi = i;
                bj = j;
            }
        }
    pair[0] = 0;
    if (bi >= 0) {
        char a[28], b[28]; /* (pm term names are short: "e'*Y(2,-2)") */
        pm_term_name(m, bj, a, sizeof a);
        pm_term_name(m, bi, b, sizeof b);
        std::snprintf(pair, len, "%s and %s", a, b);
    }
    return best;
}

/* The RMS over the sky of the fit's own pointing error per unit residual
** sigma (pm_fit_pointing_sigma at sigma 1; Note 2 of pm_indi_fit): every
** axis-1 angle, axis 2 from the lowest sync point's to 90 deg, weighted by
** area.  HUGE_VAL where it cannot be had. */
double sky_gain(const pm_fit *fit, const pm_fit_result *fr, const pm_model *m, long n, const double *e2)
{
    pm_fit_result unit = *fr;
    unit.sigma = 1.0;
    double lo = kPi / 2, sum = 0, area = 0;
    for (long i = 0; i < n; i++)
        lo = std::min(lo, e2[i]);
    for (int j = 0; j < 12; j++) {
        const double y = lo + (kPi / 2 - lo) * (j + 0.5) / 12, w = std::cos(y);
        for (int i = 0; i < 24; i++) {
            double sg, cov[3];
            if (pm_fit_pointing_sigma(fit, &unit, m, nullptr, (i - 11.5) * kPi / 12, y, &sg, cov) != PM_OK)
                return HUGE_VAL;
            sum += w * sg * sg;
            area += w;
        }
    }
    return area > 0 ? std::sqrt(sum / area) : HUGE_VAL;
}

/* Leave-one-out rms per axis (Note 1 of pm_indi_fit). */
double loo_rms(const pm_fit *fit, const pm_fit_result *fr, const pm_model *m, long n, const double *e1,
               const double *e2, const double *a1, const double *a2, long *worst, double *worst_loo)
{
    pm_fit_result unit = *fr;
    double sum = 0;
    unit.sigma = 1.0;
    *worst = -1;
    *worst_loo = 0;
    for (long i = 0; i < n; i++) {
        double s, cov[3], r[2];
        if (pm_fit_pointing_sigma(fit, &unit, m, nullptr, e1[i], e2[i], &s, cov) != PM_OK ||
                pm_model_residual(m, nullptr, e1[i], e2[i], a1[i], a2[i], r) != PM_OK)
            return HUGE_VAL;
        double h = 0.5 * (cov[0] + cov[2]);
        if (!(h < 0.999))
            return HUGE_VAL;
        const double e = (r[0] * r[0] + r[1] * r[1]) / ((1 - h) * (1 - h));
        sum += e;
        if (std::sqrt(e) > *worst_loo) { /* (the whole miss, both axes) */
            *worst_loo = std::sqrt(e);
            *worst = i;
        }
    }
    return n > 0 ? std::sqrt(sum / (2.0 * (double)n)) : 0.0;
}

} // namespace

extern "C" {

double pm_indi_spread(long n, const double *a1, const double *a2)
{
    double mx = 0, my = 0, mz = 0, worst = 0, len;
    if (n < 1 || !a1 || !a2)
        return 0.0;
    for (long i = 0; i < n; i++) {
        mx += std::cos(a2[i]) * std::cos(a1[i]);
        my += std::cos(a2[i]) * std::sin(a1[i]);
        mz += std::sin(a2[i]);
    }
    len = std::sqrt(mx * mx + my * my + mz * mz);
    if (!(len > 1e-9 * (double)n))
        return kPi;
    mx /= len;
    my /= len;
    mz /= len;
    for (long i = 0; i < n; i++) {
        double x = std::cos(a2[i]) * std::cos(a1[i]), y = std::cos(a2[i]) * std::sin(a1[i]), z = std::sin(a2[i]);
        double cx = y * mz - z * my, cy = z * mx - x * mz, cz = x * my - y * mx;
        double ang = std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), x * mx + y * my + z * mz);
        if (ang > worst)
            worst = ang;
    }
    return worst;
}

int pm_indi_choose_order(long n, double spread)
{
    static const double need[PM_INDI_MAX_ORDER + 1] = {PM_INDI_SPREAD_L0, PM_INDI_SPREAD_L1, PM_INDI_SPREAD_L2};
    for (int L = PM_INDI_MAX_ORDER; L >= 0; L--)
        if (n >= PM_SH_TERMS(L) && spread >= need[L])
            return L;
    return -1;
}

pm_status pm_indi_fit(int mount, long n, const double *enc1, const double *enc2, const double *app1,
                      const double *app2, pm_fit *fit, pm_model *out, pm_indi_result *res)
{
    if (!fit || !out || !res || n < 0 || (mount != PM_MOUNT_EQUATORIAL && mount != PM_MOUNT_ALTAZ))
        return PM_ERR_ARG;
    if (n > 0 && (!enc1 || !enc2 || !app1 || !app2))
        return PM_ERR_ARG;
    for (long i = 0; i < n; i++)
        if (!std::isfinite(enc1[i]) || !std::isfinite(enc2[i]) || !std::isfinite(app1[i]) ||
                !std::isfinite(app2[i]))
            return PM_ERR_NONFINITE;

    pm_indi_result r;
    std::memset(&r, 0, sizeof r);
    for (int L = 0; L <= PM_INDI_MAX_ORDER; L++)
        r.cv[L] = -1;
    r.order = -1;
    r.chosen_order = -1;
    r.spread = pm_indi_spread(n, app1, app2);

    pm_model best;
    double c = 0, e = 0, sec_min = HUGE_VAL;
    offsets(n, enc1, enc2, app1, app2, &c, &e);
    /* every point within PM_INDI_POLE_CAP of the pole: no axis-1 index
    ** from them (Note 3; the fits below still start from c) */
    bool near_pole = n > 0;
    for (long i = 0; i < n; i++) {
        const double ca = std::fabs(std::cos(app2[i]));
        near_pole = near_pole && ca < std::sin(PM_INDI_POLE_CAP);
        sec_min = std::min(sec_min, ca > 0 ? 1.0 / ca : HUGE_VAL);
    }
    pm_status st = start_model(&best, mount, 0, nullptr, near_pole ? 0.0 : wrap_pi(c), near_pole ? 0.0 : e);
    if (st != PM_OK)
        return st;
    if (near_pole && !fit_tilt(&best, n, enc1, enc2, app1, app2)) { /* (the offsets then) */
        near_pole = false;
        st = start_model(&best, mount, 0, nullptr, wrap_pi(c), e);
        if (st != PM_OK)
            return st;
    }
    r.kind = n > 0 ? PM_INDI_OFFSET : PM_INDI_NONE;
    r.n_par = n > 0 ? 2 : 0;
    r.altaz = mount == PM_MOUNT_ALTAZ;
    for (long i = 0; i < n && !r.altaz; i++) {
        const double h = wrap_pi(enc1[i]);
        r.east += h < -PM_INDI_MERIDIAN_GAP;
        r.west += h > PM_INDI_MERIDIAN_GAP;
    }
    if (near_pole) {
        r.axis1_unset = 1;
        r.axis1_read = wrap_pi(c);
        r.axis1_sec = sec_min;
        int ia, ib;
        if (pm_model_find(&best, PM_BASE_A, 0, 0, &ia) == PM_OK &&
                pm_model_find(&best, PM_BASE_B, 0, 0, &ib) == PM_OK)
            r.tilt = std::hypot(best.coef[ia], best.coef[ib]);
    }

    r.chosen_order = n > 0 ? pm_indi_choose_order(n, r.spread) : -1;
    /* Fit up the ladder 0 .. chosen (each start from the one below); a
    ** singular or diverging fit ends the climb at the last good one. */
    std::vector<pm_model> fitted(PM_INDI_MAX_ORDER + 1);
    double sig[PM_INDI_MAX_ORDER + 1] = {0};
    int npar[PM_INDI_MAX_ORDER + 1] = {0};
    long worst[PM_INDI_MAX_ORDER + 1] = {-1, -1, -1};
    double worst_loo[PM_INDI_MAX_ORDER + 1] = {0};
    int top = -1;
    double corr[PM_INDI_MAX_ORDER + 1] = {0}, gain[PM_INDI_MAX_ORDER + 1] = {0};
    char pair[PM_INDI_MAX_ORDER + 1][sizeof r.corr_pair] = {{0}};
    r.worst = -1;
    for (int L = 0; L <= r.chosen_order; L++) {
        pm_model &m = fitted[L];
        const pm_model *lower = L > 0 ? &fitted[L - 1] : nullptr;
        pm_fit_result fr;
        st = start_model(&m, mount, L, lower, wrap_pi(c), e);
        if (st == PM_OK)
            st = pm_fit_run(fit, &m, nullptr, n, enc1, enc2, app1, app2, kMaxIter, &fr);
        if (st != PM_OK) {
            r.fallbacks = r.chosen_order - L + 1;
            r.failed = (int)st;
            r.bad_term[0] = 0;
            if (st == PM_ERR_SINGULAR && fit->bad_term >= 0 && fit->bad_term < m.n_terms)
                pm_term_name(&m, fit->bad_term, r.bad_term, sizeof r.bad_term);
            else
                std::snprintf(r.bad_term, sizeof r.bad_term, "%s", pm_status_text(st));
            break;
        }
        corr[L] = worst_corr(fit, &fr, &m, pair[L], sizeof pair[L]);
        gain[L] = sky_gain(fit, &fr, &m, n, enc2);
        r.cv[L] = loo_rms(fit, &fr, &m, n, enc1, enc2, app1, app2, &worst[L], &worst_loo[L]);
        sig[L] = fr.sigma;
        npar[L] = fr.n_par;
        top = L;
    }
    /* the fitted order that predicts best (a higher one must earn it) */
    for (int L = 0; L <= top; L++)
        if (r.kind != PM_INDI_FIT || r.cv[L] + PM_INDI_CV_FLOOR < PM_INDI_CV_GAIN * r.cv[r.order]) {
            best = fitted[L];
            r.kind = PM_INDI_FIT;
            r.axis1_unset = 0;
            r.order = L;
            r.sigma = sig[L];
            r.n_par = npar[L];
            r.worst = worst[L];
            r.worst_loo = worst_loo[L];
            r.corr = corr[L];
            r.gain = gain[L];
            std::memcpy(r.corr_pair, pair[L], sizeof r.corr_pair);
        }
    *out = best;
    *res = r;
    return PM_OK;
}

void pm_indi_describe(const pm_indi_result *r, long n, long skipped, char *buf, size_t len)
{
    char extra[160] = "";
    const double arcsec = 180.0 / kPi * 3600.0;
    if (!buf || len == 0)
        return;
    if (!r) {
        buf[0] = 0;
        return;
    }
    if (r->fallbacks > 0)
        std::snprintf(extra, sizeof extra, "; order lowered %d time(s) (%s)", r->fallbacks, r->bad_term);
    if (skipped > 0) {
        size_t k = std::strlen(extra);
        std::snprintf(extra + k, sizeof extra - k, "; %ld sync point(s) skipped", skipped);
    }
    switch (r->kind) {
    case PM_INDI_NONE:
        std::snprintf(buf, len, "no sync points: no correction%s", extra);
        break;
    case PM_INDI_OFFSET:
        if (r->chosen_order < 0) /* too few points, or too little sky, for order 0 */
            std::snprintf(buf, len,
                          "%ld sync point(s) over %.1f deg: index offsets only (order 0 needs %d "
                          "points over %.0f deg)%s",
                          n, r->spread * 180.0 / kPi, PM_SH_TERMS(0), PM_INDI_SPREAD_L0 * 180.0 / kPi,
                          extra);
        else if (r->failed == PM_ERR_SINGULAR) /* the order 0 fit itself failed (extra says why) */
            std::snprintf(buf, len,
                          "%ld sync point(s) over %.1f deg: index offsets only, the order 0 fit "
                          "failed: these points do not determine it (all on one declination or "
                          "hour-angle circle, or one altitude? add sync points spread over both "
                          "axes)%s",
                          n, r->spread * 180.0 / kPi, extra);
        else /* (a 3 x 2 grid whose fit did not converge had been told it was all on one circle) */
            std::snprintf(buf, len,
                          "%ld sync point(s) over %.1f deg: index offsets only, the order 0 fit "
                          "failed: these points hardly determine it (add sync points spread over "
                          "more of the sky)%s",
                          n, r->spread * 180.0 / kPi, extra);
        if (r->axis1_unset) {
            size_t k = std::strlen(buf);
            std::snprintf(buf + k, len - k,
                          "; every sync point is within %.0f deg of the %s, where 1 arcmin on the "
                          "sky reads as %.1f arcmin or more of the %s index (these would read "
                          "%.2f deg): read instead as a tilt of the %s axis, %.2f arcmin, the "
                          "indices left at 0; sync on a star farther from the %s to set them",
                          PM_INDI_POLE_CAP * 180.0 / kPi, r->altaz ? "zenith" : "pole",
                          r->axis1_sec < 1e6 ? r->axis1_sec : 1e6, r->altaz ? "azimuth" : "hour-angle",
                          r->axis1_read * 180.0 / kPi, r->altaz ? "azimuth" : "polar",
                          r->tilt * 180.0 / kPi * 60.0, r->altaz ? "zenith" : "pole");
        }
        break;
    default: {
        char cv[160] = "";
        for (int L = 0, k = 0; L <= PM_INDI_MAX_ORDER; L++) {
            if (r->cv[L] < 0)
                continue;
            if (r->cv[L] < 1e6)
                k += std::snprintf(cv + k, sizeof cv - (size_t)k, "%s%d: %.3f", k ? ", " : "", L, r->cv[L] * arcsec);
            else
                k += std::snprintf(cv + k, sizeof cv - (size_t)k, "%s%d: undetermined", k ? ", " : "", L);
            if (k >= (int)sizeof cv)
                break;
        }
        std::snprintf(buf, len,
                      "%ld sync points over %.1f deg: order %d fit, %d terms, sigma %.3f arcsec "
                      "(leave-one-out arcsec, order %s)%s%s", n,
                      r->spread * 180.0 / kPi, r->order, r->n_par, r->sigma * arcsec, cv, extra,
                      r->sigma * arcsec > 1800.0 ? " (the sync points disagree by degrees: check the "
                      "site, the time and the sync targets)" : "");
        /* the others' leave-one-out miss (rms, both axes), without the
        ** worst point's own: with it in, the ratio could not pass sqrt(n) */
        double others = -1;
        if (r->worst >= 0 && r->order >= 0 && n > 1 && r->cv[r->order] >= 0 &&
                r->cv[r->order] < 1e6) {
            const double all2 = 2.0 * (double)n * r->cv[r->order] * r->cv[r->order];
            others = std::sqrt(std::max(0.0, all2 - r->worst_loo * r->worst_loo) / (double)(n - 1));
        }
        if (r->gain > PM_INDI_GAIN_WARN) {
            size_t k = std::strlen(buf);
            std::snprintf(buf + k, len - k,
                          "; these points do not determine the model between them: an error of 1 "
                          "arcsec at them moves GOTOs elsewhere by %.1f arcsec (RMS over the sky above "
                          "the lowest one; %s correlated %.4f): add sync points over more of the sky",
                          r->gain, r->corr_pair, r->corr);
        }
        const bool wrong_sync = others >= 0 && r->worst_loo > PM_INDI_WORST_RATIO * others &&
                                r->worst_loo * arcsec > 10.0;
        if (!wrong_sync && !r->altaz && r->east >= 2 && r->west >= 2 &&
                r->sigma > PM_INDI_SIDES_SIGMA) { /* (a wrong sync is said below instead) */
            size_t k = std::strlen(buf);
            std::snprintf(buf + k, len - k,
                          "; the sync points are on both sides of the meridian (%ld east, %ld "
                          "west): on a German mount INDI does not record the pier side, so "
                          "errors that change sign across the flip (collimation, "
                          "non-perpendicularity) cannot be fitted and are averaged: sync on "
                          "the side you observe",
                          r->east, r->west);
        }
        if (wrong_sync) {
            size_t k = std::strlen(buf);
            std::snprintf(buf + k, len - k,
                          "; the others' fit misses sync point %ld by %.1f arcsec, %.1f times "
                          "their own leave-one-out miss (rms): a wrong sync? (it moves every GOTO; "
                          "delete it and re-initialise)",
                          r->worst + 1, r->worst_loo * arcsec,
                          others > 0 ? r->worst_loo / others : HUGE_VAL);
        }
        break;
    }
    }
}

}
