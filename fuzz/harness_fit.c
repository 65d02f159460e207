/*
**  harness_fit.c - fuzz target body: random observation streams into the
**  fit (pm_fit_init, pm_fit_add, pm_fit_solve, pm_fit_run,
**  pm_fit_covariance, pm_fit_row, pm_fit_pointing_sigma, pm_fit_point_gain).
**
**  A model of random mount, order (0..2) and added terms is the truth;
**  observations are either made from it (apply plus noise, so that fits
**  can succeed) or any doubles (NaN, Inf, huge).  The bytes then choose a
**  sequence of adds, solves, covariance queries, whole runs and restarts.
**
**  Invariants (README.md): documented statuses only; pm_fit_add that fails
**  leaves the fit unchanged (memcmp of the whole struct); a failed solve
**  leaves *out and *res unchanged; after PM_OK the model is prepared
**  (evaluates) and its coefficients are finite; pm_fit_run leaves the
**  model unchanged unless PM_OK; the covariance is refused before a
**  successful solve, and finite with |corr| <= 1 after one.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "harness.h"
#include "fz_input.h"

#define FT_MAX_OBS 64
#define FT_MAX_OPS 24
/* |corr| may exceed 1 by rounding of the inverse only. */
#define FT_CORR_SLACK 1e-6

static const int ft_add_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_NONFINITE, PM_ERR_STATE, 99};
static const int ft_solve_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_TOO_FEW, PM_ERR_SINGULAR,
                                  PM_ERR_NONFINITE, PM_ERR_STATE, 99};
static const int ft_run_st[] = {PM_OK, PM_ERR_DIVERGED, PM_ERR_ARG, PM_ERR_NONFINITE,
                                PM_ERR_TOO_FEW, PM_ERR_SINGULAR, PM_ERR_STATE, 99};
static const int ft_cov_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_STATE, 99};
static const int ft_row_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_NONFINITE, PM_ERR_STATE, 99};

typedef struct ft_obs {
    double eh, ed, ah, ad;
    pm_context c;
    const pm_context *ctx;
} ft_obs;

/* Large, so static (one harness call at a time). */
static struct {
    pm_model truth, model, out, snap_model;
    pm_fit fit, snap_fit;
    pm_fit_result res, snap_res;
    ft_obs obs[FT_MAX_OBS];
    double eh[FT_MAX_OBS], ed[FT_MAX_OBS], ah[FT_MAX_OBS], ad[FT_MAX_OBS];
    pm_context ctxs[FT_MAX_OBS];
    double row0[PM_MAX_TERMS], row1[PM_MAX_TERMS];
} ft;

static void ft_add_terms(pmfz_in *in, pm_model *m)
{
    int n = pmfz_range(in, 0, 5), j;
    for (j = 0; j < n; j++) {
        pm_term t;
        memset(&t, 0, sizeof t);
        t.kind = (unsigned char)pmfz_range(in, 0, 4);
        t.k = (unsigned char)pmfz_range(in, 1, 6);
        t.side = (signed char)pmfz_range(in, -1, 1);
        switch (t.kind) {
        case PM_TERM_SH:
            t.l = (signed char)pmfz_range(in, 0, m->order);
            t.m = (signed char)pmfz_range(in, -t.l, t.l);
            break;
        case PM_TERM_FOURIER:
            t.l = (signed char)pmfz_range(in, 1, 2);
            t.m = (signed char)pmfz_range(in, 0, 1);
            t.param = pmfz_range(in, 1, 8) * (pmfz_u8(in) & 1u ? 1.0 : 0.5);
            break;
        case PM_TERM_SECTORAL:
            t.m = (signed char)pmfz_range(in, 0, 1);
            t.param = pmfz_range(in, 1, 6);
            break;
        case PM_TERM_ZENITH:
            t.l = (signed char)pmfz_range(in, 0, 1);
            break;
        default:
            t.aux = (unsigned char)pmfz_range(in, 0, PM_AUX_USER + PM_MAX_AUX - 1);
            t.param = pmfz_unit(in) * 10;
            break;
        }
        pm_model_add_term(m, &t, 0.0, NULL); /* invalid ones are refused */
    }
}

/* One observation: from the truth plus noise, or any doubles. */
static void ft_make_obs(pmfz_in *in, ft_obs *o)
{
    unsigned sel = pmfz_u8(in);
    o->ctx = NULL;
    if (ft.truth.needs_ctx || (sel & 0x40u)) {
        memset(&o->c, 0, sizeof o->c);
        o->c.temp_c = (sel & 0x80u) ? pmfz_double(in) : pmfz_unit(in) * 30 - 5;
        o->c.time_h = pmfz_unit(in) * 10;
        o->c.dir = pmfz_range(in, -1, 1);
        o->c.pier = pmfz_range(in, -1, 1);
        o->c.aux[0] = pmfz_unit(in);
        o->c.aux[1] = pmfz_unit(in);
        o->ctx = &o->c;
    }
    if ((sel & 7u) == 0) { /* anything */
        o->eh = pmfz_angle(in);
        o->ed = pmfz_angle(in);
        o->ah = pmfz_angle(in);
        o->ad = pmfz_angle(in);
        return;
    }
    o->eh = (pmfz_unit(in) * 2 - 1) * M_PI;
    o->ed = (pmfz_unit(in) * 2 - 1) * (sel & 8u ? M_PI : 1.45);
    if (pm_model_apply(&ft.truth, o->ctx, o->eh, o->ed, &o->ah, &o->ad) != PM_OK) {
        o->ah = o->eh;
        o->ad = o->ed;
    }
    o->ah += (pmfz_unit(in) - 0.5) * 1e-5;
    o->ad += (pmfz_unit(in) - 0.5) * 1e-5;
    if (fabs(o->ad) > M_PI / 2)
        o->ad = o->ad > 0 ? M_PI / 2 : -M_PI / 2;
}

/* A model after PM_OK: finite and prepared (it evaluates: PM_OK, or
** PM_ERR_NONFINITE where huge coefficients overflow, never STATE). */
static int ft_model_ok(const pm_model *m, const char *what)
{
    int i;
    double t, d;
    pm_context c;
    pm_status st;
    for (i = 0; i < m->n_terms; i++)
        if (!pmfz_finite(m->coef[i]))
            return pmfz_fail("%s: PM_OK with coefficient %d = %g", what, i, m->coef[i]);
    memset(&c, 0, sizeof c);
    st = pm_model_apply(m, &c, 0.3, 0.4, &t, &d);
    if (st != PM_OK && (st != PM_ERR_NONFINITE || pmfz_plain_model(m)))
        return pmfz_fail("%s: PM_OK but the model does not evaluate (%d; max |coef| %g iso, %g "
                         "aniso)", what, st, pmfz_max_coef(m, 0), pmfz_max_coef(m, 1));
    return 0;
}

static int ft_add(const ft_obs *o)
{
    pm_status st;
    memcpy(&ft.snap_fit, &ft.fit, sizeof ft.fit);
    st = pm_fit_add(&ft.fit, o->ctx, o->eh, o->ed, o->ah, o->ad);
    if (!pmfz_status_in(st, ft_add_st))
        return pmfz_fail("fit_add: status %d", st);
    if (st == PM_OK && (!pmfz_finite(o->eh) || !pmfz_finite(o->ed) || !pmfz_finite(o->ah) ||
                        !pmfz_finite(o->ad)))
        return pmfz_fail("fit_add: PM_OK for non-finite input");
    if (st != PM_OK && memcmp(&ft.snap_fit, &ft.fit, sizeof ft.fit) != 0)
        return pmfz_fail("fit_add: error %d changed the fit", st);
    return 0;
}

/* solved: 1 after an accepted solve (covariance available), 0 when there
** is none, 2 unknown (after pm_fit_run). */
static int ft_solve(int *solved)
{
    pm_status st;
    int i;
    pm_fit_result res = ft.res; /* a rejected step leaves most fields */
    memset(&ft.out, 0x5A, sizeof ft.out);
    memcpy(&ft.snap_model, &ft.out, sizeof ft.out);
    memcpy(&ft.snap_res, &res, sizeof res);
    memcpy(&ft.snap_fit, &ft.fit, sizeof ft.fit);
    st = pm_fit_solve(&ft.fit, &ft.out, &res);
    if (!pmfz_status_in(st, ft_solve_st))
        return pmfz_fail("fit_solve: status %d", st);
    if (st != PM_OK) {
        const pm_fit *a = &ft.snap_fit, *b = &ft.fit;
        if (memcmp(&ft.snap_model, &ft.out, sizeof ft.out) != 0 ||
            memcmp(&ft.snap_res, &res, sizeof res) != 0)
            return pmfz_fail("fit_solve: error %d changed *out or *res", st);
        /* the accumulated pass and the damping state are kept */
        if (a->n_obs != b->n_obs || memcmp(&a->chi2, &b->chi2, sizeof a->chi2) != 0 ||
            memcmp(a->ata, b->ata, sizeof a->ata) != 0 ||
            memcmp(a->atb, b->atb, sizeof a->atb) != 0 ||
            memcmp(&a->lin, &b->lin, sizeof a->lin) != 0 ||
            memcmp(a->base_coef, b->base_coef, sizeof a->base_coef) != 0 ||
            memcmp(a->step, b->step, sizeof a->step) != 0 || a->halvings != b->halvings ||
            a->iterations != b->iterations)
            return pmfz_fail("fit_solve: error %d changed the pass or the damping state", st);
        if (st == PM_ERR_SINGULAR && (ft.fit.bad_term < 0 || ft.fit.bad_term >= ft.fit.n_par))
            return pmfz_fail("fit_solve: PM_ERR_SINGULAR with bad_term %d", ft.fit.bad_term);
        if (st == PM_ERR_SINGULAR)
            *solved = 0; /* the factorisation overwrote the covariance */
        return 0;
    }
    if (ft_model_ok(&ft.out, "fit_solve"))
        return 1;
    ft.res = res;
    if (ft.res.accepted)
        *solved = 1;
    if (ft.res.accepted) {
        if (!pmfz_finite(ft.res.chi2) || ft.res.chi2 < 0 || !pmfz_finite(ft.res.sigma) ||
            ft.res.sigma < 0 || ft.res.n_par != ft.fit.n_par)
            return pmfz_fail("fit_solve: result chi2 %g sigma %g", ft.res.chi2, ft.res.sigma);
        for (i = 0; i < ft.res.n_par; i++)
            if (!pmfz_finite(ft.res.err[i]) || ft.res.err[i] < 0)
                return pmfz_fail("fit_solve: err[%d] = %g", i, ft.res.err[i]);
    }
    return 0;
}

static int ft_cov(pmfz_in *in, int solved)
{
    int n = ft.fit.n_par, i = pmfz_range(in, -1, n), j = pmfz_range(in, -1, n);
    double cov = 777, corr = 777;
    pm_status st = pm_fit_covariance(&ft.fit, &ft.res, i, j, &cov, &corr);
    if (!pmfz_status_in(st, ft_cov_st))
        return pmfz_fail("covariance: status %d", st);
    if (st == PM_OK && solved == 0)
        return pmfz_fail("covariance: PM_OK without a successful solve");
    if (st != PM_OK) {
        if (cov != 777 || corr != 777)
            return pmfz_fail("covariance: output changed on error %d", st);
        return 0;
    }
    if (i < 0 || j < 0 || i >= n || j >= n)
        return pmfz_fail("covariance: PM_OK for (%d, %d) of %d", i, j, n);
    if (!pmfz_finite(cov) || !pmfz_finite(corr) ||
        !(fabs(corr) <= 1 + FT_CORR_SLACK) || (i == j && cov < 0))
        return pmfz_fail("covariance: (%d, %d) cov %g corr %g", i, j, cov, corr);
    return 0;
}

/* The predicted error and the point gain at fuzzed positions: documented
** statuses; after PM_OK finite and non-negative (the gain to rounding);
** never PM_OK without a successful solve. */
static const int ft_pred_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_STATE, PM_ERR_NONFINITE,
                                 PM_ERR_SINGULAR, PM_ERR_CAPACITY, 99};

static int ft_predict(pmfz_in *in, int solved)
{
    double t = pmfz_angle(in), d = pmfz_angle(in), sky[4], s = 777, c[3], g = 777;
    pm_status st;
    sky[0] = pmfz_angle(in);
    sky[1] = pmfz_angle(in);
    sky[2] = pmfz_double(in);
    sky[3] = pmfz_angle(in);
    st = pm_fit_pointing_sigma(&ft.fit, &ft.res, &ft.fit.lin, NULL, t, d, &s, c);
    if (!pmfz_status_in(st, ft_pred_st))
        return pmfz_fail("pointing_sigma: status %d", st);
    if (st == PM_OK && (solved == 0 || !pmfz_finite(s) || s < 0 || !pmfz_finite(c[0]) ||
                        !pmfz_finite(c[1]) || !pmfz_finite(c[2])))
        return pmfz_fail("pointing_sigma: PM_OK with sigma %g (solved %d)", s, solved);
    st = pm_fit_point_gain(&ft.fit, &ft.res, &ft.fit.lin, NULL, t, d, sky,
                           1 + (int)(pmfz_u8(in) & 1u), &g);
    if (!pmfz_status_in(st, ft_pred_st))
        return pmfz_fail("point_gain: status %d", st);
    if (st == PM_OK && (solved == 0 || !pmfz_finite(g)))
        return pmfz_fail("point_gain: PM_OK with gain %g (solved %d)", g, solved);
    return 0;
}

static int ft_run(pmfz_in *in, int nobs)
{
    int n = pmfz_range(in, 0, nobs), it = pmfz_range(in, 0, 12), k, use_ctx = 0;
    pm_fit_result r;
    pm_status st;
    for (k = 0; k < n; k++) {
        ft.eh[k] = ft.obs[k].eh;
        ft.ed[k] = ft.obs[k].ed;
        ft.ah[k] = ft.obs[k].ah;
        ft.ad[k] = ft.obs[k].ad;
        memset(&ft.ctxs[k], 0, sizeof ft.ctxs[k]);
        if (ft.obs[k].ctx) {
            ft.ctxs[k] = ft.obs[k].c;
            use_ctx = 1;
        }
    }
    memcpy(&ft.snap_model, &ft.model, sizeof ft.model);
    st = pm_fit_run(&ft.fit, &ft.model, use_ctx ? ft.ctxs : NULL, n, ft.eh, ft.ed, ft.ah,
                    ft.ad, it, &r);
    if (!pmfz_status_in(st, ft_run_st))
        return pmfz_fail("fit_run: status %d", st);
    if ((it < 1) && st != PM_ERR_ARG)
        return pmfz_fail("fit_run: max_iter %d gave %d", it, st);
    if (st != PM_OK) {
        if (memcmp(&ft.snap_model, &ft.model, sizeof ft.model) != 0)
            return pmfz_fail("fit_run: error %d changed the model", st);
        return 0;
    }
    return ft_model_ok(&ft.model, "fit_run");
}

int pmfz_fit(const unsigned char *data, size_t size)
{
    pmfz_in in;
    int mount, order, nobs, k, ops, r = 0, solved = 0;
    unsigned sel;
    pm_status st;

    pmfz_init(&in, data, size);
    memset(&ft.fit, 0, sizeof ft.fit);
    if (pm_fit_add(&ft.fit, NULL, 0, 0, 0, 0) != PM_ERR_STATE ||
        pm_fit_solve(&ft.fit, &ft.out, NULL) != PM_ERR_STATE || pm_fit_init(NULL, NULL) !=
        PM_ERR_ARG)
        return pmfz_fail("fit: uninitialised fit accepted");
    sel = pmfz_u8(&in);
    mount = (sel & 1u) ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
    order = (int)((sel >> 1) % 3u);
    if (pm_model_init(&ft.truth, mount, order) != PM_OK)
        return pmfz_fail("fit: init mount %d order %d", mount, order);
    ft.truth.latitude = (pmfz_unit(&in) - 0.5) * M_PI;
    pm_model_prepare(&ft.truth);
    ft_add_terms(&in, &ft.truth);
    ft.model = ft.truth; /* the terms to fit, from zero */
    for (k = 0; k < ft.truth.n_terms; k++)
        ft.truth.coef[k] = (sel & 0x80u) ? pmfz_coef(&in) : (pmfz_unit(&in) - 0.5) * 2e-3;
    if (pm_model_prepare(&ft.truth) != PM_OK) { /* a NaN among them: a plain truth */
        for (k = 0; k < ft.truth.n_terms; k++)
            ft.truth.coef[k] = 1e-4;
        pm_model_prepare(&ft.truth);
    }

    nobs = pmfz_range(&in, 0, FT_MAX_OBS);
    for (k = 0; k < nobs; k++)
        ft_make_obs(&in, &ft.obs[k]);

    st = pm_fit_init(&ft.fit, &ft.model);
    if (st != PM_OK)
        return pmfz_fail("fit_init of a prepared model gave %d", st);
    memset(&ft.res, 0, sizeof ft.res);
    for (ops = 0; ops < FT_MAX_OPS && !r; ops++) {
        unsigned op = pmfz_u8(&in) % 8u;
        if (!pmfz_left(&in))
            op = ops < 3 ? 0 : 8; /* a pass and a solve, then stop */
        switch (op) {
        case 0: case 1: /* a pass over a range of the observations */
        {
            int a = pmfz_range(&in, 0, nobs), b = pmfz_range(&in, 0, nobs);
            if (!pmfz_left(&in)) {
                a = 0;
                b = nobs;
            }
            for (k = a; k < b && !r; k++)
                r = ft_add(&ft.obs[k]);
            break;
        }
        case 2: /* one observation, any doubles */
        {
            ft_obs o;
            o.ctx = pmfz_context(&in, &o.c);
            o.eh = pmfz_double(&in);
            o.ed = pmfz_angle(&in);
            o.ah = pmfz_angle(&in);
            o.ad = pmfz_double(&in);
            r = ft_add(&o);
            break;
        }
        case 3: case 4:
            r = ft_solve(&solved);
            break;
        case 5:
            r = ft_cov(&in, solved);
            if (!r)
                r = ft_predict(&in, solved);
            break;
        case 6: /* a whole run from the current model */
            r = ft_run(&in, nobs);
            solved = 2; /* pm_fit_run re-initialised the fit and solved */
            break;
        case 7: /* restart from a model: the fitted one or the start */
        {
            int k2 = pmfz_range(&in, 0, nobs > 0 ? nobs - 1 : 0);
            if (pmfz_u8(&in) & 1u)
                st = pm_fit_init(&ft.fit, &ft.model);
            else
                st = pm_fit_init(&ft.fit, &ft.truth);
            if (st != PM_OK)
                return pmfz_fail("fit_init of a prepared model gave %d", st);
            solved = 0;
            if (nobs > 0) {
                double rr[2] = {777, 777};
                st = pm_fit_row(&ft.fit.lin, ft.obs[k2].ctx, ft.obs[k2].eh, ft.obs[k2].ed,
                                ft.obs[k2].ah, ft.obs[k2].ad, ft.row0, ft.row1, rr);
                if (!pmfz_status_in(st, ft_row_st) ||
                    (st == PM_OK && (!pmfz_finite(rr[0]) || !pmfz_finite(rr[1]))))
                    return pmfz_fail("fit_row: status %d r (%g, %g) for (%.17g %.17g %.17g "
                                     "%.17g)", st, rr[0], rr[1], ft.obs[k2].eh, ft.obs[k2].ed,
                                     ft.obs[k2].ah, ft.obs[k2].ad);
            }
            break;
        }
        default:
            ops = FT_MAX_OPS;
            break;
        }
    }
    return r;
}
