/*
**  harness_capi.c - fuzz target body: the C API of include/pm.h driven by
**  the bytes.  A model of a random mount and order (invalid ones included)
**  goes through a random sequence of operations: coefficients set to any
**  double (NaN, Inf, 1e300, subnormals), terms added (valid and invalid),
**  fields of the struct overwritten, prepare, apply, invert, invert_near,
**  pm_model_track (a state carried across the operations, the model
**  changing under it), residual, the float build (pm_model_track_f too),
**  pm_terms_eval,
**  pm_term_name, pm_model_find.
**
**  Invariants (README.md): every call returns one of its documented
**  statuses; what the header makes certain is checked exactly (a stale
**  model gives PM_ERR_STATE, a ready model and finite input give no error,
**  non-finite input never gives PM_OK); outputs are unchanged on error and
**  finite otherwise; apply gives (-pi, pi] x [-pi/2, pi/2]; invert with PM_OK
**  round-trips to PM_INVERT_TOL, on the requested side of the pole; the float
**  inverse round-trips to PM_INVERT_F_TOL.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "harness.h"
#include "fz_input.h"

/* apply(invert(x)) with PM_OK: the promise plus the rounding of going from
** vectors to angles and back. */
#define CA_TOL_ROUNDTRIP (PM_INVERT_TOL + 1e-14)
/* The float inverse: PM_INVERT_F_TOL, measured by pm_model_apply_f in
** double here, in float inside (float rounding of the offset, 1e-7 of it,
** and the float forward's noise, ~1e-9 rad). */
#define CA_TOL_ROUNDTRIP_F (PM_INVERT_F_TOL * 1.01 + 2e-9)
/* Slack on range checks of returned angles. */
#define CA_EPS 1e-9

#define CA_SENTINEL 12345.0
#define CA_MAX_OPS 64

static const int ca_prepare_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_NONFINITE, PM_ERR_CAPACITY, 99};
static const int ca_add_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_CAPACITY, PM_ERR_NONFINITE,
                                PM_ERR_STATE, 99};
static const int ca_apply_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_NONFINITE, PM_ERR_STATE, 99};
static const int ca_invert_st[] = {PM_OK, PM_WARN_NOT_CONVERGED, PM_WARN_UNREACHABLE,
                                   PM_ERR_ARG, PM_ERR_NONFINITE, PM_ERR_STATE, 99};
static const int ca_eval_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_NONFINITE, PM_ERR_CAPACITY, 99};
static const int ca_fprep_st[] = {PM_OK, PM_ERR_ARG, PM_ERR_STATE, 99};
static const int ca_argonly_st[] = {PM_OK, PM_ERR_ARG, 99};

typedef struct ca_state {
    pm_model m;
    int prepared;                /* a prepare (init, add_term) succeeded */
    double pcoef[PM_MAX_TERMS];  /* the coefficients it prepared */
    pm_track tk;                 /* pm_model_track's state (zero: not started) */
    pm_track_f tkf;              /* pm_model_track_f's */
} ca_state;

static void ca_mark(ca_state *s)
{
    memcpy(s->pcoef, s->m.coef, sizeof s->pcoef);
    s->prepared = 1;
}

/* Ready for evaluation by the header's rule: prepared, and no coefficient
** differs from the ones last prepared (bit for bit: -0.0 over 0.0 is a
** change). */
static int ca_ready(const ca_state *s)
{
    int i;
    if (!s->prepared || s->m.n_terms < 6 || s->m.n_terms > PM_MAX_TERMS)
        return 0;
    for (i = 0; i < s->m.n_terms; i++)
        if (memcmp(&s->m.coef[i], &s->pcoef[i], sizeof(double)) != 0)
            return 0;
    return 1;
}

/* The part of a model its functions promise to leave alone on error. */
static int ca_same_model(const pm_model *a, const pm_model *b)
{
    int i;
    if (a->mount != b->mount || a->order != b->order || a->n_terms != b->n_terms ||
        a->n_base != b->n_base || memcmp(&a->latitude, &b->latitude, sizeof(double)) != 0 ||
        a->prepared != b->prepared)
        return 0;
    for (i = 0; i < a->n_terms && i < PM_MAX_TERMS; i++)
        if (memcmp(&a->term[i], &b->term[i], sizeof(pm_term)) != 0 ||
            memcmp(&a->coef[i], &b->coef[i], sizeof(double)) != 0)
            return 0;
    return 1;
}

/* Does the context carry what the model's AUX terms read (finite)? */
static int ca_ctx_ok(const pm_model *m, const pm_context *ctx)
{
    int i;
    for (i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_AUX) {
            int a = m->term[i].aux;
            double x;
            if (!ctx)
                return 0;
            x = a == PM_AUX_TEMP ? ctx->temp_c
              : a == PM_AUX_TIME ? ctx->time_h
              : a == PM_AUX_DIR ? (double)ctx->dir : ctx->aux[a - PM_AUX_USER];
            if (!pmfz_finite(x) || (a == PM_AUX_DIR && (ctx->dir < -1 || ctx->dir > 1)))
                return 0;
        }
    return 1;
}

static void ca_random_term(pmfz_in *in, pm_term *t)
{
    unsigned sel = pmfz_u8(in);
    memset(t, 0, sizeof *t);
    t->kind = (unsigned char)(sel % 7u); /* 5, 6: invalid */
    t->k = (unsigned char)pmfz_range(in, 0, 7);
    t->l = (signed char)pmfz_range(in, -2, PM_MAX_L + 2);
    t->m = (signed char)pmfz_range(in, -3, 3);
    t->side = (signed char)((sel & 0x80u) ? pmfz_range(in, -3, 3) : 0);
    t->aux = (unsigned char)pmfz_range(in, 0, 9);
    switch (pmfz_u8(in) % 4u) {
    case 0: t->param = pmfz_double(in); break;
    case 1: t->param = pmfz_range(in, 1, 12); break;
    case 2: t->param = pmfz_unit(in) * 10; break;
    default: t->param = 0; break;
    }
}

/* For triage: the model's terms and coefficients on stderr. */
static void ca_dump(const ca_state *s, const pm_context *ctx, const double *start)
{
    int i;
    fprintf(stderr, "pmfz: model mount %d order %d n_terms %d n_base %d latitude %.17g\n",
            s->m.mount, s->m.order, s->m.n_terms, s->m.n_base, s->m.latitude);
    for (i = 0; i < s->m.n_terms && i < PM_MAX_TERMS; i++)
        if (s->m.coef[i] != 0)
            fprintf(stderr, "pmfz:   term %d kind %d k %d l %d m %d side %d param %.17g coef %.17g\n",
                    i, s->m.term[i].kind, s->m.term[i].k, s->m.term[i].l, s->m.term[i].m,
                    s->m.term[i].side, s->m.term[i].param, s->m.coef[i]);
    if (ctx)
        fprintf(stderr, "pmfz: ctx temp %.17g time %.17g pier %d dir %d\n", ctx->temp_c,
                ctx->time_h, ctx->pier, ctx->dir);
    if (start)
        fprintf(stderr, "pmfz: start %.17g %.17g\n", start[0], start[1]);
}

/* Plain: no overflow possible, so PM_ERR_NONFINITE is not allowed. */
static int ca_plain(const ca_state *s, const pm_context *ctx, double x, double y)
{
    return pmfz_plain_model(&s->m) && pmfz_plain_ctx(ctx) && pmfz_plain_x(x) && pmfz_plain_x(y);
}

/* Apply with checks; returns 0 or 1 (and the result in t, d). */
static int ca_apply(ca_state *s, const pm_context *ctx, double eh, double ed, double *t,
                    double *d, pm_status *stp)
{
    pm_status st;
    *t = *d = CA_SENTINEL;
    st = pm_model_apply(&s->m, ctx, eh, ed, t, d);
    *stp = st;
    if (!pmfz_status_in(st, ca_apply_st))
        return pmfz_fail("apply: status %d", st);
    if (!ca_ready(s) && st != PM_ERR_STATE)
        return pmfz_fail("apply: stale model gave %d, expected PM_ERR_STATE", st);
    if ((!pmfz_finite(eh) || !pmfz_finite(ed)) && st == PM_OK)
        return pmfz_fail("apply: PM_OK for non-finite input");
    /* PM_ERR_NONFINITE: also when the terms overflow (huge coefficients) */
    if (ca_ready(s) && ca_ctx_ok(&s->m, ctx) && pmfz_finite(eh) && pmfz_finite(ed) && st != PM_OK &&
        (st != PM_ERR_NONFINITE || ca_plain(s, ctx, eh, ed)))
        return pmfz_fail("apply: ready model, finite input (%.17g, %.17g) gave %d", eh, ed, st);
    if (st != PM_OK) {
        if (*t != CA_SENTINEL || *d != CA_SENTINEL)
            return pmfz_fail("apply: outputs changed on error %d", st);
        return 0;
    }
    if (!pmfz_finite(*t) || !pmfz_finite(*d))
        return pmfz_fail("apply: PM_OK with non-finite output (%g, %g) for input (%.17g, %.17g)",
                         *t, *d, eh, ed);
    if (!(*t > -M_PI && *t <= M_PI) || !(fabs(*d) <= M_PI / 2))
        return pmfz_fail("apply: output (%.17g, %.17g) out of range", *t, *d);
    return 0;
}

static int ca_op_apply(pmfz_in *in, ca_state *s)
{
    pm_context c;
    const pm_context *ctx = pmfz_context(in, &c);
    double eh = pmfz_angle(in), ed = pmfz_angle(in), t, d;
    pm_status st;
    if ((pmfz_u8(in) & 15u) == 0) { /* NULL outputs */
        double x = CA_SENTINEL;
        st = pm_model_apply(&s->m, ctx, eh, ed, NULL, &x);
        if (st == PM_OK || !pmfz_status_in(st, ca_apply_st) || x != CA_SENTINEL)
            return pmfz_fail("apply: NULL output gave %d", st);
        st = pm_model_apply(NULL, ctx, eh, ed, &x, &x);
        if (st != PM_ERR_ARG)
            return pmfz_fail("apply: NULL model gave %d", st);
        return 0;
    }
    return ca_apply(s, ctx, eh, ed, &t, &d, &st);
}

/* Checks common to invert, invert_near and track; start NULL for invert;
** reach: how far from start the result may be (pi; pm_model_track starts
** at most 0.01 rad on from its state's position on each axis). */
static int ca_check_inverse(ca_state *s, const pm_context *ctx, double ah, double ad,
                            int side, const double *start, double reach, const char *fn,
                            double et, double ed, pm_status st)
{
    int args_ok = pmfz_finite(ah) && pmfz_finite(ad) && fabs(ad) <= M_PI / 2 &&
                  (start ? fabs(start[0]) <= PM_START_MAX && fabs(start[1]) <= PM_START_MAX
                         : side == PM_SIDE_NORMAL || side == PM_SIDE_FLIPPED);
    int plain = ca_plain(s, ctx, ah, ad) && (!start || ca_plain(s, ctx, start[0], start[1]));
    /* (pm_model_invert checks the side before the model) */
    int args_side_ok = start || side == PM_SIDE_NORMAL || side == PM_SIDE_FLIPPED;
    double rt, rd, miss;
    pm_status ast;
    if (!pmfz_status_in(st, ca_invert_st))
        return pmfz_fail("%s: status %d", fn, st);
    if (!ca_ready(s) && (st >= 0 || (args_side_ok && st != PM_ERR_STATE)))
        return pmfz_fail("%s: stale model gave %d, expected PM_ERR_STATE", fn, st);
    if (st >= 0 && (!pmfz_finite(ah) || !pmfz_finite(ad) ||
                    (start && (!pmfz_finite(start[0]) || !pmfz_finite(start[1])))))
        return pmfz_fail("%s: status %d for non-finite input", fn, st);
    if (st >= 0 && fabs(ad) > M_PI / 2 + 1e-12)
        return pmfz_fail("%s: status %d for |app_dec| = %.17g > pi/2", fn, st, fabs(ad));
    if (ca_ready(s) && args_ok && ca_ctx_ok(&s->m, ctx) && st < 0 &&
        (st != PM_ERR_NONFINITE || plain))
        return pmfz_fail("%s: ready model, valid input (%.17g, %.17g) gave %d", fn, ah, ad, st);
    if (st < 0) {
        if (et != CA_SENTINEL || ed != CA_SENTINEL)
            return pmfz_fail("%s: outputs changed on error %d", fn, st);
        return 0;
    }
    if (!pmfz_finite(et) || !pmfz_finite(ed))
        return pmfz_fail("%s: status %d with non-finite result (%g, %g)", fn, st, et, ed);
    if (st != PM_OK)
        return 0;
    if (start) {
        double tol_t = reach + CA_EPS * (1 + fabs(start[0]));
        double tol_d = reach + CA_EPS * (1 + fabs(start[1]));
        if (!(fabs(et - start[0]) <= tol_t) || !(fabs(ed - start[1]) <= tol_d))
            return pmfz_fail("%s: (%.17g, %.17g) not within %g of the start (%.17g, %.17g)",
                             fn, et, ed, reach, start[0], start[1]);
    } else {
        double de = ed - s->m.coef[4];
        int off;
        if (!(et > -M_PI && et <= M_PI))
            return pmfz_fail("invert: enc_ha %.17g not in (-pi, pi]", et);
        off = side == PM_SIDE_NORMAL ? !(fabs(de) <= M_PI / 2 + CA_EPS)
                                     : !(de > M_PI / 2 - CA_EPS && de < 3 * M_PI / 2 + CA_EPS);
        if (off)
            return pmfz_fail("invert: enc_dec - e' = %.17g not on side %d (target %.17g %.17g, "
                             "max |coef| %g iso, %g aniso)", de, side, ah, ad,
                             pmfz_max_coef(&s->m, 0), pmfz_max_coef(&s->m, 1));
    }
    if (ca_apply(s, ctx, et, ed, &rt, &rd, &ast))
        return 1;
    if (ast != PM_OK) {
        ca_dump(s, ctx, start);
        return pmfz_fail("%s: status %d, apply of the result (%.17g, %.17g) gave %d (target "
                         "%.17g %.17g, max |coef| %g iso, %g aniso)", fn, st, et, ed, ast, ah,
                         ad, pmfz_max_coef(&s->m, 0), pmfz_max_coef(&s->m, 1));
    }
    miss = pmfz_sep(rt, rd, ah, ad);
    /* at the returned angles as they are, however far out (pm.h,
    ** pm_model_invert Note 4) */
    if (!(miss <= CA_TOL_ROUNDTRIP)) {
        ca_dump(s, ctx, start);
        return pmfz_fail("%s: PM_OK but apply(invert(%.17g, %.17g)) misses by %g rad (max "
                         "|coef| %g iso, %g aniso)", fn, ah, ad, miss, pmfz_max_coef(&s->m, 0),
                         pmfz_max_coef(&s->m, 1));
    }
    return 0;
}

static int ca_op_invert(pmfz_in *in, ca_state *s, int near)
{
    pm_context c;
    const pm_context *ctx = pmfz_context(in, &c);
    double ah = pmfz_angle(in), ad = pmfz_angle(in), start[2];
    double et = CA_SENTINEL, ed = CA_SENTINEL;
    int side = 0;
    unsigned sel = pmfz_u8(in);
    pm_status st;
    if (sel & 1u)
        ad = fmod(ad, M_PI / 2); /* mostly a valid declination */
    if (near) {
        start[0] = pmfz_angle(in);
        start[1] = pmfz_angle(in);
        st = pm_model_invert_near(&s->m, ctx, ah, ad, start[0], start[1], &et, &ed);
    } else {
        side = (sel & 0x30u) == 0x30u ? pmfz_range(in, -3, 3) : (int)((sel >> 1) & 1u);
        st = pm_model_invert(&s->m, ctx, ah, ad, side, &et, &ed);
    }
    if ((sel & 0xC0u) == 0xC0u) { /* NULL output */
        double x = CA_SENTINEL;
        pm_status s2 = near ? pm_model_invert_near(&s->m, ctx, ah, ad, 0, 0, &x, NULL)
                            : pm_model_invert(&s->m, ctx, ah, ad, side, NULL, &x);
        if (s2 >= 0 || !pmfz_status_in(s2, ca_invert_st) || x != CA_SENTINEL)
            return pmfz_fail("invert: NULL output gave %d", s2);
    }
    return ca_check_inverse(s, ctx, ah, ad, side, near ? start : NULL, M_PI,
                            near ? "invert_near" : "invert", et, ed, st);
}

/* pm_model_track: start the state anew (any angles), or a tick with any
** target from wherever the state is, the model as the operations left
** it; an unstarted state and NULL outputs are refused. */
static int ca_op_track(pmfz_in *in, ca_state *s)
{
    pm_context c;
    const pm_context *ctx;
    double ah, ad, et = CA_SENTINEL, ed = CA_SENTINEL, before[2];
    unsigned sel = pmfz_u8(in);
    pm_status st;
    if ((sel & 3u) == 0) {
        double h = pmfz_angle(in), d = pmfz_angle(in);
        int want = !pmfz_finite(h) || !pmfz_finite(d) ? PM_ERR_NONFINITE
                   : fabs(h) > PM_START_MAX || fabs(d) > PM_START_MAX ? PM_ERR_ARG
                                                                       : PM_OK;
        st = pm_track_start(&s->tk, h, d);
        if (st != want)
            return pmfz_fail("track_start(%.17g, %.17g) gave %d, expected %d", h, d, st, want);
        return 0;
    }
    ctx = pmfz_context(in, &c);
    ah = pmfz_angle(in);
    ad = pmfz_angle(in);
    if (sel & 4u)
        ad = fmod(ad, M_PI / 2);
    if (s->tk.magic != PM_TRACK_MAGIC) {
        st = pm_model_track(&s->m, ctx, &s->tk, ah, ad, &et, &ed);
        if (st != PM_ERR_ARG || et != CA_SENTINEL || ed != CA_SENTINEL)
            return pmfz_fail("track: an unstarted state gave %d", st);
        return 0;
    }
    if ((sel & 0xC0u) == 0xC0u) {
        double x = CA_SENTINEL;
        st = pm_model_track(&s->m, ctx, &s->tk, ah, ad, NULL, &x);
        if (st != PM_ERR_ARG || x != CA_SENTINEL)
            return pmfz_fail("track: NULL output gave %d", st);
    }
    before[0] = s->tk.enc[0];
    before[1] = s->tk.enc[1];
    st = pm_model_track(&s->m, ctx, &s->tk, ah, ad, &et, &ed);
    if (st == PM_OK && (s->tk.enc[0] != et || s->tk.enc[1] != ed))
        return pmfz_fail("track: PM_OK without the state's position moved to the result");
    if (st != PM_OK && (s->tk.enc[0] != before[0] || s->tk.enc[1] != before[1]))
        return pmfz_fail("track: status %d moved the state's position", st);
    return ca_check_inverse(s, ctx, ah, ad, 0, before, M_PI + 0.0101, "track", et, ed, st);
}

static int ca_op_residual(pmfz_in *in, ca_state *s)
{
    pm_context c;
    const pm_context *ctx = pmfz_context(in, &c);
    double v[4], res[2] = {CA_SENTINEL, CA_SENTINEL};
    int i, fin = 1;
    pm_status st;
    for (i = 0; i < 4; i++) {
        v[i] = pmfz_angle(in);
        fin = fin && pmfz_finite(v[i]);
    }
    st = pm_model_residual(&s->m, ctx, v[0], v[1], v[2], v[3], res);
    if (!pmfz_status_in(st, ca_apply_st))
        return pmfz_fail("residual: status %d", st);
    if (!ca_ready(s) && st != PM_ERR_STATE)
        return pmfz_fail("residual: stale model gave %d", st);
    if (st == PM_OK && !fin)
        return pmfz_fail("residual: PM_OK for non-finite input");
    if (st == PM_OK && fabs(v[3]) > M_PI / 2 + 1e-9)
        return pmfz_fail("residual: PM_OK for an observed dec of %.17g", v[3]);
    if (ca_ready(s) && fin && ca_ctx_ok(&s->m, ctx) && fabs(v[3]) <= M_PI / 2 &&
        st != PM_OK && (st != PM_ERR_NONFINITE || ca_plain(s, ctx, v[0], v[1])))
        return pmfz_fail("residual: ready model, finite input gave %d", st);
    if (st != PM_OK && (res[0] != CA_SENTINEL || res[1] != CA_SENTINEL))
        return pmfz_fail("residual: output changed on error %d", st);
    if (st == PM_OK && (!pmfz_finite(res[0]) || !pmfz_finite(res[1])))
        return pmfz_fail("residual: PM_OK with (%g, %g) for (%.17g %.17g %.17g %.17g)", res[0],
                         res[1], v[0], v[1], v[2], v[3]);
    return 0;
}

static int ca_op_terms_eval(pmfz_in *in)
{
    int order = pmfz_range(in, -2, PM_MAX_L + 2), i, n;
    double ha = pmfz_angle(in), dec = pmfz_angle(in), *out;
    int valid = order >= 0 && order <= PM_MAX_L;
    pm_status st;
    n = valid ? 18 * PM_N_HARM(order) : 1;
    out = (double *)malloc(sizeof(double) * (size_t)n); /* exact size: ASan sees overruns */
    if (!out)
        return 0;
    for (i = 0; i < n; i++)
        out[i] = CA_SENTINEL;
    st = pm_terms_eval(order, ha, dec, out);
    if (!pmfz_status_in(st, ca_eval_st) || (!valid && st == PM_OK) ||
        ((!pmfz_finite(ha) || !pmfz_finite(dec)) && st == PM_OK) ||
        (valid && pmfz_finite(ha) && pmfz_finite(dec) && st != PM_OK)) {
        free(out);
        return pmfz_fail("terms_eval: order %d (%.17g, %.17g) gave %d", order, ha, dec, st);
    }
    for (i = 0; i < n; i++)
        if (st == PM_OK ? !pmfz_finite(out[i]) : out[i] != CA_SENTINEL) {
            double v = out[i];
            free(out);
            return pmfz_fail("terms_eval: order %d (%.17g, %.17g) status %d, out[%d] = %g",
                             order, ha, dec, st, i, v);
        }
    free(out);
    if (pm_terms_eval(0, 0, 0, NULL) != PM_ERR_ARG)
        return pmfz_fail("terms_eval: NULL out accepted");
    return 0;
}

/* The float build's tracking loop on the target (t, d) that (eh, ed)
** points at: its state started there first (start), else carried from
** the calls before, whatever model they had; PM_OK round-trips. */
static int ca_op_track_f(const pm_model_f *mf, const pm_context *ctx, pm_track_f *tk,
                         double t, double d, double eh, double ed, int start)
{
    double et = CA_SENTINEL, edc = CA_SENTINEL;
    pm_status st;
    if ((start || tk->magic != PM_TRACK_F_MAGIC) && pm_track_f_start(tk, eh, ed) != PM_OK)
        return 0; /* (a start beyond PM_START_MAX: refused) */
    st = pm_model_track_f(mf, ctx, tk, t, d, &et, &edc);
    if (!pmfz_status_in(st, ca_invert_st))
        return pmfz_fail("track_f: status %d", st);
    if (st < 0) {
        if (et != CA_SENTINEL || edc != CA_SENTINEL)
            return pmfz_fail("track_f: outputs changed on error %d", st);
        return 0;
    }
    if (!pmfz_finite(et) || !pmfz_finite(edc))
        return pmfz_fail("track_f: status %d with (%g, %g)", st, et, edc);
    if (st == PM_OK) {
        double rt, rd, miss;
        if (pm_model_apply_f(mf, ctx, et, edc, &rt, &rd) != PM_OK)
            return pmfz_fail("track_f: apply_f of the result failed");
        miss = pmfz_sep(rt, rd, t, d);
        if (!(miss <= CA_TOL_ROUNDTRIP_F))
            return pmfz_fail("track_f: PM_OK but the round trip misses by %g rad", miss);
        if (tk->enc[0] != et || tk->enc[1] != edc)
            return pmfz_fail("track_f: PM_OK without the state's position moved");
    }
    return 0;
}

static int ca_op_float(pmfz_in *in, ca_state *s)
{
    static pm_model_f mf;
    int k, rounds = pmfz_range(in, 1, 4);
    pm_status st;
    memset(&mf, 0, sizeof mf);
    st = pm_model_apply_f(&mf, NULL, 0, 0, NULL, NULL);
    if (st != PM_ERR_STATE && st != PM_ERR_ARG)
        return pmfz_fail("float: unprepared model gave %d", st);
    st = pm_model_f_prepare(&mf, &s->m);
    if (!pmfz_status_in(st, ca_fprep_st))
        return pmfz_fail("float: f_prepare status %d", st);
    if (!ca_ready(s) && st == PM_OK)
        return pmfz_fail("float: f_prepare of a stale model gave PM_OK");
    if (ca_ready(s) && st != PM_OK)
        return pmfz_fail("float: f_prepare of a ready model gave %d", st);
    if (st != PM_OK)
        return 0;
    for (k = 0; k < rounds; k++) {
        pm_context c;
        const pm_context *ctx = pmfz_context(in, &c);
        double eh = pmfz_angle(in), ed = pmfz_angle(in);
        int plain = ca_plain(s, ctx, eh, ed);
        double t = CA_SENTINEL, d = CA_SENTINEL, et = CA_SENTINEL, edc = CA_SENTINEL;
        int fin = pmfz_finite(eh) && pmfz_finite(ed), cok = ca_ctx_ok(&s->m, ctx);
        int side = pmfz_range(in, -1, 2), near = pmfz_u8(in) & 1u;
        st = pm_model_apply_f(&mf, ctx, eh, ed, &t, &d);
        if (!pmfz_status_in(st, ca_apply_st) || (st == PM_OK && !fin) ||
            (fin && cok && st != PM_OK && (st != PM_ERR_NONFINITE || plain))) {
            ca_dump(s, ctx, NULL);
            return pmfz_fail("apply_f: (%.17g, %.17g) gave %d", eh, ed, st);
        }
        if (st != PM_OK) {
            if (t != CA_SENTINEL || d != CA_SENTINEL)
                return pmfz_fail("apply_f: outputs changed on error %d", st);
            continue;
        }
        if (!pmfz_finite(t) || !pmfz_finite(d))
            return pmfz_fail("apply_f: PM_OK with non-finite output (%g, %g) for (%.17g, %.17g)",
                             t, d, eh, ed);
        if (!(fabs(d) <= M_PI / 2))
            return pmfz_fail("apply_f: app_dec %.17g", d);
        st = near ? pm_model_invert_near_f(&mf, ctx, t, d, eh, ed, &et, &edc)
                  : pm_model_invert_f(&mf, ctx, t, d, side, &et, &edc);
        if (!pmfz_status_in(st, ca_invert_st))
            return pmfz_fail("invert_f: status %d", st);
        if (!near && side != PM_SIDE_NORMAL && side != PM_SIDE_FLIPPED && st != PM_ERR_ARG)
            return pmfz_fail("invert_f: side %d gave %d", side, st);
        if (st < 0) {
            int far = near && (fabs(eh) > PM_START_MAX || fabs(ed) > PM_START_MAX);
            if ((near || side == PM_SIDE_NORMAL || side == PM_SIDE_FLIPPED) &&
                !(far && st == PM_ERR_ARG) && !(st == PM_ERR_NONFINITE && !plain))
                return pmfz_fail("invert_f: valid input (%.17g, %.17g) gave %d", t, d, st);
            if (et != CA_SENTINEL || edc != CA_SENTINEL)
                return pmfz_fail("invert_f: outputs changed on error %d", st);
            continue;
        }
        if (!pmfz_finite(et) || !pmfz_finite(edc))
            return pmfz_fail("invert_f: status %d with (%g, %g)", st, et, edc);
        if (st == PM_OK && !near) { /* the turn of pm_model_invert */
            double de = edc - mf.e;
            if (!(et > -M_PI && et <= M_PI) ||
                (side == PM_SIDE_NORMAL ? !(fabs(de) <= M_PI / 2 + CA_EPS)
                                        : !(de > M_PI / 2 - CA_EPS && de < 3 * M_PI / 2 + CA_EPS)))
                return pmfz_fail("invert_f: (%.17g, enc_dec - e' = %.17g) not on side %d", et,
                                 de, side);
        }
        if (st == PM_OK) {
            double rt, rd, miss;
            if (pm_model_apply_f(&mf, ctx, et, edc, &rt, &rd) != PM_OK)
                return pmfz_fail("invert_f: apply_f of the result failed");
            miss = pmfz_sep(rt, rd, t, d);
            if (!(miss <= CA_TOL_ROUNDTRIP_F))
                return pmfz_fail("invert_f: PM_OK but the round trip misses by %g rad "
                                 "(target %.17g %.17g)", miss, t, d);
        }
        if (near && ca_op_track_f(&mf, ctx, &s->tkf, t, d, eh, ed, k == 0))
            return 1;
    }
    return 0;
}

static int ca_op_name(pmfz_in *in, ca_state *s)
{
    int idx = pmfz_range(in, -2, s->m.n_terms + 1);
    size_t len = (size_t)pmfz_range(in, 0, 48);
    char *buf = (char *)malloc(len ? len : 1); /* exact size */
    pm_status st;
    if (!buf)
        return 0;
    st = pm_term_name(&s->m, idx, buf, len);
    if (!pmfz_status_in(st, ca_argonly_st) || (st == PM_OK && (len < 2 || idx < 0 ||
                                                                idx >= s->m.n_terms))) {
        free(buf);
        return pmfz_fail("term_name: index %d len %zu gave %d", idx, len, st);
    }
    if (st == PM_OK && !memchr(buf, '\0', len)) {
        free(buf);
        return pmfz_fail("term_name: not NUL-terminated");
    }
    free(buf);
    return 0;
}

static int ca_op_find(pmfz_in *in, ca_state *s)
{
    int k = pmfz_range(in, -1, 7), l = pmfz_range(in, -1, PM_MAX_L + 1);
    int mm = pmfz_range(in, -PM_MAX_L - 1, PM_MAX_L + 1), idx = -77;
    pm_status st = pm_model_find(&s->m, k, l, mm, &idx);
    if (!pmfz_status_in(st, ca_argonly_st))
        return pmfz_fail("find: status %d", st);
    if (st == PM_OK) {
        const pm_term *t;
        if (idx < 0 || idx >= s->m.n_terms)
            return pmfz_fail("find: index %d of %d terms", idx, s->m.n_terms);
        t = &s->m.term[idx];
        if (t->kind != PM_TERM_SH || t->k != k || t->l != l || t->m != mm)
            return pmfz_fail("find: (%d,%d,%d) gave term %d", k, l, mm, idx);
    } else if (idx != -77) {
        return pmfz_fail("find: index written on error");
    }
    return 0;
}

static int ca_op_add(pmfz_in *in, ca_state *s)
{
    static pm_model before;
    pm_term t;
    double v;
    int idx = -77, n = s->m.n_terms, use_idx;
    pm_status st;
    ca_random_term(in, &t);
    v = pmfz_coef(in);
    use_idx = (int)(pmfz_u8(in) & 1u);
    before = s->m;
    st = pm_model_add_term(&s->m, &t, v, use_idx ? &idx : NULL);
    if (!pmfz_status_in(st, ca_add_st))
        return pmfz_fail("add_term: status %d", st);
    if (st != PM_OK) {
        /* a model that was not ready may be left unprepared (its
        ** pm_model_prepare failed: Note 2 there) */
        if (!ca_ready(s) && !s->m.prepared)
            before.prepared = 0;
        if (!ca_same_model(&s->m, &before) || idx != -77)
            return pmfz_fail("add_term: error %d changed the model", st);
        if (!s->m.prepared)
            s->prepared = 0;
        if (!pmfz_finite(v) || st == PM_ERR_NONFINITE || st == PM_ERR_STATE)
            return 0;
        if (st == PM_ERR_CAPACITY && n < PM_MAX_TERMS)
            return pmfz_fail("add_term: PM_ERR_CAPACITY with %d terms", n);
        return 0;
    }
    if (!pmfz_finite(v))
        return pmfz_fail("add_term: PM_OK for a non-finite value");
    if (s->m.n_terms != n + 1 || (use_idx && idx != n))
        return pmfz_fail("add_term: PM_OK, n_terms %d -> %d, index %d", n, s->m.n_terms, idx);
    ca_mark(s);
    return 0;
}

/* Add valid terms until the model is full: exactly PM_MAX_TERMS fit. */
static int ca_op_fill(ca_state *s)
{
    pm_term t;
    pm_status st = PM_OK;
    int guard = 0;
    if (!ca_ready(s))
        return 0;
    memset(&t, 0, sizeof t);
    t.kind = PM_TERM_SH;
    t.k = PM_BASE_C;
    t.side = 1;
    while (st == PM_OK && guard++ <= PM_MAX_TERMS)
        st = pm_model_add_term(&s->m, &t, 1e-5, NULL);
    if (st != PM_ERR_CAPACITY || s->m.n_terms != PM_MAX_TERMS)
        return pmfz_fail("fill: stopped at %d terms with %d", s->m.n_terms, st);
    ca_mark(s);
    return 0;
}

static int ca_op_setcoef(pmfz_in *in, ca_state *s)
{
    int hi = s->m.n_terms > 0 && s->m.n_terms <= PM_MAX_TERMS ? s->m.n_terms - 1 : 5;
    int i = pmfz_range(in, 0, hi);
    s->m.coef[i] = pmfz_coef(in);
    return 0;
}

static int ca_op_prepare(ca_state *s)
{
    int i, fin = 1;
    pm_status st = pm_model_prepare(&s->m);
    if (!pmfz_status_in(st, ca_prepare_st))
        return pmfz_fail("prepare: status %d", st);
    for (i = 0; i < s->m.n_terms && i < PM_MAX_TERMS; i++)
        fin = fin && pmfz_finite(s->m.coef[i]);
    if (!fin && st == PM_OK)
        return pmfz_fail("prepare: PM_OK with a non-finite coefficient");
    if (st == PM_OK)
        ca_mark(s);
    else
        s->prepared = 0; /* pm_model_prepare, Note 2 */
    return 0;
}

/* Overwrite one field of the struct, then prepare; a model it rejects is
** put back as it was. */
static int ca_op_corrupt(pmfz_in *in, ca_state *s)
{
    static pm_model saved;
    static const int counts[] = {-1, 0, 5, 6, 7, 21, 22, PM_MAX_TERMS - 1, PM_MAX_TERMS,
                                 PM_MAX_TERMS + 1, 100000};
    unsigned what = pmfz_u8(in) % 9u;
    int i = pmfz_range(in, 0, PM_MAX_TERMS - 1);
    pm_status st;
    saved = s->m;
    switch (what) {
    case 0: s->m.n_terms = counts[pmfz_u8(in) % 11u]; break;
    case 1: s->m.n_base = counts[pmfz_u8(in) % 11u]; break;
    case 2: s->m.order = pmfz_range(in, -2, PM_MAX_L + 2); break;
    case 3: s->m.mount = pmfz_range(in, -1, 2); break;
    case 4: s->m.latitude = pmfz_double(in); break;
    case 5: ca_random_term(in, &s->m.term[i]); break;
    case 6: s->m.term[i].k = (unsigned char)pmfz_range(in, 0, 7); break;
    case 7: s->m.term[i].l = (signed char)pmfz_range(in, -2, PM_MAX_L + 2); break;
    default: s->m.term[i].side = (signed char)pmfz_range(in, -2, 2); break;
    }
    st = pm_model_prepare(&s->m);
    if (!pmfz_status_in(st, ca_prepare_st))
        return pmfz_fail("prepare after overwriting field %u: status %d", what, st);
    if (st != PM_OK) { /* Note 2: left unprepared, no evaluation */
        double t = CA_SENTINEL, d = CA_SENTINEL;
        pm_context c;
        memset(&c, 0, sizeof c);
        st = pm_model_apply(&s->m, &c, 0.3, 0.4, &t, &d);
        if (st != PM_ERR_STATE || t != CA_SENTINEL)
            return pmfz_fail("apply after a refused model (field %u) gave %d", what, st);
        s->m = saved; /* put the model back */
        return 0;
    }
    {
        if (s->m.n_terms < 6 || s->m.n_terms > PM_MAX_TERMS || s->m.order < 0 ||
            s->m.order > PM_MAX_L || s->m.n_base < 6 || s->m.n_base > s->m.n_terms ||
            !(fabs(s->m.latitude) <= M_PI / 2))
            return pmfz_fail("prepare accepted n_terms %d n_base %d order %d latitude %g",
                             s->m.n_terms, s->m.n_base, s->m.order, s->m.latitude);
        ca_mark(s);
    }
    return 0;
}

int pmfz_capi(const unsigned char *data, size_t size)
{
    static ca_state s;
    pmfz_in in;
    unsigned sel;
    int mount, order, ops, r = 0;
    pm_status st;

    pmfz_init(&in, data, size);
    memset(&s, 0, sizeof s);
    if (PM_CHECK_CONFIG() != PM_OK ||
        pm_check_config(sizeof(pm_model) + 8, sizeof(pm_fit), PM_MAX_L, PM_MAX_EXTRA) !=
            PM_ERR_CONFIG)
        return pmfz_fail("pm_check_config");
    if (pm_model_init(NULL, 0, 0) != PM_ERR_ARG || pm_model_prepare(NULL) != PM_ERR_ARG)
        return pmfz_fail("NULL model accepted");

    sel = pmfz_u8(&in);
    mount = (sel & 7u) < 3 ? PM_MOUNT_EQUATORIAL : (sel & 7u) < 6 ? PM_MOUNT_ALTAZ
          : (sel & 7u) == 6 ? 2 : -1;
    sel = pmfz_u8(&in);
    order = sel >= 250 ? (sel == 255 ? -2147483647 - 1 : 1000) : (int)(sel % (PM_MAX_L + 4)) - 2;
    st = pm_model_init(&s.m, mount, order);
    if (mount != PM_MOUNT_EQUATORIAL && mount != PM_MOUNT_ALTAZ) {
        if (st != PM_ERR_ARG)
            return pmfz_fail("init: mount %d gave %d", mount, st);
    } else if (order < 0 || order > PM_MAX_L) {
        if (st != PM_ERR_CAPACITY)
            return pmfz_fail("init: order %d gave %d", order, st);
    } else if (st != PM_OK || s.m.n_terms != PM_SH_TERMS(order) || s.m.n_base != s.m.n_terms) {
        return pmfz_fail("init: mount %d order %d gave %d, %d terms", mount, order, st,
                         s.m.n_terms);
    }
    if (st == PM_OK)
        ca_mark(&s);
    /* After a failed init the (zeroed) struct is not a model: every call
    ** must refuse it. */
    for (ops = 0; ops < CA_MAX_OPS && pmfz_left(&in) && !r; ops++) {
        unsigned op = pmfz_u8(&in) % 16u;
        switch (op) {
        case 0: case 1: r = ca_op_setcoef(&in, &s); break;
        case 2: r = ca_op_prepare(&s); break;
        case 3: r = ca_op_add(&in, &s); break;
        case 4: case 5: r = ca_op_apply(&in, &s); break;
        case 6: case 7: r = ca_op_invert(&in, &s, 0); break;
        case 8: r = (pmfz_u8(&in) & 1u) ? ca_op_track(&in, &s) : ca_op_invert(&in, &s, 1); break;
        case 9: r = ca_op_residual(&in, &s); break;
        case 10: r = ca_op_terms_eval(&in); break;
        case 11: r = ca_op_float(&in, &s); break;
        case 12: r = ca_op_name(&in, &s); break;
        case 13: r = ca_op_find(&in, &s); break;
        case 14: r = ca_op_corrupt(&in, &s); break;
        default: r = (pmfz_u8(&in) & 7u) == 0 ? ca_op_fill(&s) : ca_op_setcoef(&in, &s); break;
        }
    }
    return r;
}
