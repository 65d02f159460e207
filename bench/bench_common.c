/*
**  bench_common.c - models, positions and the operations the benches time.
*/
#include <math.h>
#include <stdio.h>

#include "bench_common.h"
#include "naive.h"

#define PI 3.14159265358979323846
#define ARCSEC (PI / 648000.0)
#define DEG (PI / 180.0)

const int bench_orders[BENCH_NORDERS] = {0, 1, 2, 4};

const char *const bench_op_name[BENCH_NOPS] = {
    "empty",     "fwd",     "inv",           "inv_near",     "naive_fwd",
    "naive_inv", "track10", "track1k",       "empty_track10", "empty_track1k"};

int bench_op_supported(const bench_api *api, int op)
{
    if (op == BENCH_NAIVE_FWD || op == BENCH_NAIVE_INV)
        return api == &bench_api_double;
    if (op == BENCH_TRACK10 || op == BENCH_TRACK1K || op == BENCH_EMPTY_TRACK10 ||
        op == BENCH_EMPTY_TRACK1K)
        return api->track != 0;
    return 1;
}

int bench_loop_op(int op)
{
    if (op == BENCH_TRACK10)
        return BENCH_EMPTY_TRACK10;
    if (op == BENCH_TRACK1K)
        return BENCH_EMPTY_TRACK1K;
    if (op == BENCH_EMPTY_TRACK10 || op == BENCH_EMPTY_TRACK1K)
        return op;
    return BENCH_EMPTY;
}

/* ---------------------------------------------------------------------- */
/* The double API.                                                        */

static const pm_model *d_model[BENCH_NORDERS];

static int d_load(int slot, const pm_model *m)
{
    if (slot < 0 || slot >= BENCH_NORDERS)
        return -1;
    d_model[slot] = m;
    return 0;
}

static int d_apply(int slot, double eh, double ed, double *ah, double *ad)
{
    return pm_model_apply(d_model[slot], 0, eh, ed, ah, ad);
}

static int d_invert(int slot, double ah, double ad, double *eh, double *ed)
{
    return pm_model_invert(d_model[slot], 0, ah, ad, PM_SIDE_NORMAL, eh, ed);
}

static int d_invert_near(int slot, double ah, double ad, double sh, double sd,
                         double *eh, double *ed)
{
    return pm_model_invert_near(d_model[slot], 0, ah, ad, sh, sd, eh, ed);
}

static int d_track_start(void *t, double eh, double ed)
{
    return pm_track_start((pm_track *)t, eh, ed);
}

static int d_track(int slot, void *t, double ah, double ad, double *eh, double *ed)
{
    return pm_model_track(d_model[slot], 0, (pm_track *)t, ah, ad, eh, ed);
}

const bench_api bench_api_double = {"double",      d_load,        d_apply, d_invert,
                                    d_invert_near, d_track_start, d_track};

/* ---------------------------------------------------------------------- */
/* The float build of the evaluation (pm_model_f: single precision inside,
** positions double at the interface).                                    */

static pm_model_f f_model[BENCH_NORDERS];

static int f_load(int slot, const pm_model *m)
{
    if (slot < 0 || slot >= BENCH_NORDERS)
        return -1;
    return pm_model_f_prepare(&f_model[slot], m) == PM_OK ? 0 : -1;
}

static int f_apply(int slot, double eh, double ed, double *ah, double *ad)
{
    return pm_model_apply_f(&f_model[slot], 0, eh, ed, ah, ad);
}

static int f_invert(int slot, double ah, double ad, double *eh, double *ed)
{
    return pm_model_invert_f(&f_model[slot], 0, ah, ad, PM_SIDE_NORMAL, eh, ed);
}

static int f_invert_near(int slot, double ah, double ad, double sh, double sd,
                         double *eh, double *ed)
{
    return pm_model_invert_near_f(&f_model[slot], 0, ah, ad, sh, sd, eh, ed);
}

static int f_track_start(void *t, double eh, double ed)
{
    return pm_track_f_start((pm_track_f *)t, eh, ed);
}

static int f_track(int slot, void *t, double ah, double ad, double *eh, double *ed)
{
    return pm_model_track_f(&f_model[slot], 0, (pm_track_f *)t, ah, ad, eh, ed);
}

const bench_api bench_api_float = {"float",       f_load,        f_apply, f_invert,
                                   f_invert_near, f_track_start, f_track};

const bench_api *const bench_apis[] = {&bench_api_double, &bench_api_float};
const int bench_n_apis = (int)(sizeof bench_apis / sizeof bench_apis[0]);

/* ---------------------------------------------------------------------- */
/* Inputs.                                                                */

/* 32-bit LCG: the same numbers on every target. */
static double lcg_pm1(unsigned long *s) /* uniform in [-1, 1) */
{
    *s = (*s * 1664525UL + 1013904223UL) & 0xFFFFFFFFUL;
    return (double)(*s >> 8) / 8388608.0 - 1.0;
}

int bench_input_make(bench_input *in, int order)
{
    static const double iso_arcsec[6] = {95, -140, 1200, 35, -420, -50};
    unsigned long s = 2026UL + (unsigned long)order;
    int i;
    if (pm_model_init(&in->m, PM_MOUNT_EQUATORIAL, order) != PM_OK)
        return -1;
    for (i = 0; i < in->m.n_terms; i++)
        in->m.coef[i] = i < 6 ? iso_arcsec[i] * ARCSEC
                              : 15.0 * ARCSEC * sqrt(3.0) * lcg_pm1(&s);
    if (pm_model_prepare(&in->m) != PM_OK)
        return -1;
    for (i = 0; i < BENCH_NPOS; i++) {
        double z0 = sin(-50 * DEG), z1 = sin(85 * DEG);
        double u = 0.5 * (lcg_pm1(&s) + 1), v = lcg_pm1(&s);
        in->eh[i] = PI * v;
        in->ed[i] = asin(z0 + (z1 - z0) * u);
        if (pm_model_apply(&in->m, 0, in->eh[i], in->ed[i], &in->ah[i], &in->ad[i]) != PM_OK)
            return -1;
        /* the last tick: 0.1 s of sidereal motion earlier */
        in->sh[i] = in->eh[i] - 0.1 * 7.2921159e-5;
        in->sd[i] = in->ed[i];
    }
    return 0;
}

/* ---------------------------------------------------------------------- */
/* Operations.                                                            */

/* The loop's own cost: a call through the same kind of pointer to a
** function that does nothing but return its arguments. */
static int empty_eval(int slot, double x, double y, double *a, double *b)
{
    (void)slot;
    *a = x;
    *b = y;
    return 0;
}
static int (*volatile empty_ptr)(int, double, double, double *, double *) = empty_eval;

/* The tracking loops' empty calls: a state set up by nothing, a tick that
** returns its target (through a volatile pointer, as empty_eval: not
** inlined into the loop). */
static int empty_track_start(void *t, double eh, double ed)
{
    (void)t;
    (void)eh;
    (void)ed;
    return 0;
}

static int empty_track(int slot, void *t, double ah, double ad, double *eh, double *ed)
{
    (void)slot;
    (void)t;
    *eh = ah;
    *ed = ad;
    return 0;
}

static const bench_api empty_track_api = {"empty", 0, 0, 0, 0, empty_track_start, empty_track};
static const bench_api *volatile empty_track_ptr = &empty_track_api;

/* pm_model_track's states, one per position, for the tracking ops: each
** call is the next tick of that position's loop (the target a tick on),
** so every timed call is a tick of a loop in its steady state, the calls
** that take J afresh included (J's reach, PM_TRACK_J_REACH, is ~14 s of
** sidereal motion: about once in 140 calls at 0.1 s ticks, and not at all
** within a 1 ms run of the bench's length); the first two ticks (J taken,
** no step to predict from yet) are made when the states are set up. */
static struct {
    const bench_input *in;
    const bench_api *api;
    int slot;
    union {
        pm_track d;
        pm_track_f f;
    } t[BENCH_NPOS];
    long k[BENCH_NPOS]; /* the tick the state is at */
} track_state[4];

static int track_run(const bench_api *api, int slot, int op, const bench_input *in, int n,
                     double *acc)
{
    const int ten = op == BENCH_TRACK10 || op == BENCH_EMPTY_TRACK10;
    const double tick = (ten ? 0.1 : 0.001) * 7.2921159e-5;
    /* (the empty loops keep states of their own: measuring them does not
    ** set up the library's again) */
    int w = (ten ? 0 : 1) + (op == BENCH_EMPTY_TRACK10 || op == BENCH_EMPTY_TRACK1K ? 2 : 0);
    int i, bad = 0;
    double a, b;
    if (track_state[w].in != in || track_state[w].api != api || track_state[w].slot != slot) {
        for (i = 0; i < BENCH_NPOS; i++) {
            void *t = &track_state[w].t[i];
            bad += api->track_start(t, in->eh[i], in->ed[i]) != PM_OK;
            bad += api->track(slot, t, in->ah[i] + tick, in->ad[i], &a, &b) != PM_OK;
            bad += api->track(slot, t, in->ah[i] + 2 * tick, in->ad[i], &a, &b) != PM_OK;
            track_state[w].k[i] = 2;
        }
        track_state[w].in = in;
        track_state[w].api = api;
        track_state[w].slot = slot;
    }
    for (i = 0; i < n; i++) {
        long k = ++track_state[w].k[i];
        bad += api->track(slot, &track_state[w].t[i], in->ah[i] + (double)k * tick, in->ad[i],
                          &a, &b) != PM_OK;
        *acc += a + b;
    }
    return bad;
}

int bench_run(const bench_api *api, int slot, int op, const bench_input *in, int n,
              volatile double *sink)
{
    int i, bad = 0;
    double a, b, acc = 0;
    int (*empty)(int, double, double, double *, double *) = empty_ptr;
    switch (op) {
    case BENCH_EMPTY:
        for (i = 0; i < n; i++) {
            bad += empty(slot, in->eh[i], in->ed[i], &a, &b) != 0;
            acc += a + b;
        }
        break;
    case BENCH_FWD:
        for (i = 0; i < n; i++) {
            bad += api->apply(slot, in->eh[i], in->ed[i], &a, &b) != PM_OK;
            acc += a + b;
        }
        break;
    case BENCH_INV:
        for (i = 0; i < n; i++) {
            bad += api->invert(slot, in->ah[i], in->ad[i], &a, &b) != PM_OK;
            acc += a + b;
        }
        break;
    case BENCH_INV_NEAR:
        for (i = 0; i < n; i++) {
            bad += api->invert_near(slot, in->ah[i], in->ad[i], in->sh[i], in->sd[i], &a,
                                    &b) != PM_OK;
            acc += a + b;
        }
        break;
    case BENCH_TRACK10:
    case BENCH_TRACK1K:
        if (!api->track)
            return n;
        bad += track_run(api, slot, op, in, n, &acc);
        break;
    case BENCH_EMPTY_TRACK10:
    case BENCH_EMPTY_TRACK1K:
        bad += track_run(empty_track_ptr, slot, op, in, n, &acc);
        break;
    case BENCH_NAIVE_FWD:
        for (i = 0; i < n; i++) {
            naive_apply(&in->m, 1.0, in->eh[i], in->ed[i], &a, &b);
            acc += a + b;
        }
        break;
    case BENCH_NAIVE_INV:
        for (i = 0; i < n; i++) {
            naive_apply(&in->m, -1.0, in->ah[i], in->ad[i], &a, &b);
            acc += a + b;
        }
        break;
    default:
        return n;
    }
    *sink += acc;
    return bad;
}

void bench_case_name(char *buf, int len, const char *target, int op, int order,
                     const char *prec)
{
    snprintf(buf, (size_t)len, "%s_%s_L%d_%s", target, bench_op_name[op], order, prec);
}
