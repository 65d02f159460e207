/*
**  pm_indi.cpp - the INDI math plugin's fitting logic (pm_indi.h): the rule
**  for the order, the fit and its fallbacks.  Plain pm C API, no INDI.
*/
#include "pm_indi.h"

#include <cmath>
#include <cstdio>
#include <cstring>

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

/* Index offsets: c' the circular mean of app1 - enc1, e' the mean of
** enc2 - app2 (pm: apparent = (enc1 + c', enc2 - e') for a model of the
** index terms alone, exactly). */
void offsets(long n, const double *e1, const double *e2, const double *a1, const double *a2, double *c,
             double *e)
{
    double s = 0, co = 0, d = 0;
    for (long i = 0; i < n; i++) {
        double t = a1[i] - e1[i];
        s += std::sin(t);
        co += std::cos(t);
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
    r.order = -1;
    r.chosen_order = -1;
    r.spread = pm_indi_spread(n, app1, app2);

    pm_model best;
    double c = 0, e = 0;
    offsets(n, enc1, enc2, app1, app2, &c, &e);
    pm_status st = start_model(&best, mount, 0, nullptr, wrap_pi(c), e);
    if (st != PM_OK)
        return st;
    r.kind = n > 0 ? PM_INDI_OFFSET : PM_INDI_NONE;
    r.n_par = n > 0 ? 2 : 0;

    r.chosen_order = n > 0 ? pm_indi_choose_order(n, r.spread) : -1;
    /* Fit up the ladder 0 .. chosen (each start from the one below); a
    ** singular or diverging fit ends the climb at the last good one. */
    pm_model lower = best;
    bool have_lower = false;
    for (int L = 0; L <= r.chosen_order; L++) {
        pm_model m;
        pm_fit_result fr;
        st = start_model(&m, mount, L, have_lower ? &lower : nullptr, wrap_pi(c), e);
        if (st == PM_OK)
            st = pm_fit_run(fit, &m, nullptr, n, enc1, enc2, app1, app2, kMaxIter, &fr);
        if (st != PM_OK) {
            r.fallbacks = r.chosen_order - L + 1;
            r.bad_term[0] = 0;
            if (st == PM_ERR_SINGULAR && fit->bad_term >= 0 && fit->bad_term < m.n_terms)
                pm_term_name(&m, fit->bad_term, r.bad_term, sizeof r.bad_term);
            else
                std::snprintf(r.bad_term, sizeof r.bad_term, "status %d", (int)st);
            break;
        }
        lower = m;
        have_lower = true;
        best = m;
        r.kind = PM_INDI_FIT;
        r.order = L;
        r.sigma = fr.sigma;
        r.n_par = fr.n_par;
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
        std::snprintf(buf, len,
                      "%ld sync point(s) over %.1f deg: index offsets only (order 0 needs %d points "
                      "over %.0f deg)%s",
                      n, r->spread * 180.0 / kPi, PM_SH_TERMS(0), PM_INDI_SPREAD_L0 * 180.0 / kPi, extra);
        break;
    default:
        std::snprintf(buf, len, "%ld sync points over %.1f deg: order %d fit, %d terms, sigma %.3f arcsec%s%s", n,
                      r->spread * 180.0 / kPi, r->order, r->n_par, r->sigma * arcsec, extra,
                      r->sigma * arcsec > 1800.0 ? " (the sync points disagree by degrees: check the "
                      "site, the time and the sync targets)" : "");
        break;
    }
}

}
