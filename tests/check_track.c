/*
**  check_track.c - pm_track_start / pm_model_track, the tracking loop's
**  inverse with a state carried from tick to tick (include/pm.h).
**
**  What must hold: every PM_OK result round-trips within PM_INVERT_TOL (the
**  predicted stop's bound with a carried J is what makes that so); the
**  result is pm_model_invert_near's from the same start to within the
**  tolerance; the evaluations stay within the bounds pm_model_invert_near
**  promises; J is really carried (taken afresh rarely at 1 kHz); a model
**  prepared with other coefficients, or AUX inputs that changed, make the
**  next call take J afresh; bad arguments get errors and leave the state.
**
**  Built, like check_bounded, against the core with the evaluation counter
**  of tests/probe.h (Makefile).
*/
#include "tu_check.h"
#include "testutil.h"
#include "probe.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static unsigned long probe_count;
void pm_probe_hit(void) { probe_count++; }

#define SIDEREAL 7.2921159e-5 /* rad/s */
/* apply(result) against the target: the tolerance and the rounding of the
** angles' sin/cos */
#define ROUND_TRIP_SLACK 1e-14
/* pm_model_track's result against pm_model_invert_near's from the same
** start, away from the mount's pole: both round-trip within
** PM_INVERT_TOL, so their encoder positions differ by about that over the
** local scale of the mapping */
#define SAME_AS_NEAR 1e-12

/* A realistic model: isotropic terms within +-10 deg, harmonic ones within
** +-10' (order 1 or 2), with an AUX temperature term where aux. */
static void real_model(pm_model *m, tu_rng *r, int order, int aux)
{
    int i;
    ck_assert_int_eq(pm_model_init(m, PM_MOUNT_EQUATORIAL, order), PM_OK);
    m->latitude = 0.6;
    for (i = 0; i < m->n_terms; i++)
        m->coef[i] = (2 * tu_uniform(r) - 1) * (i < 6 ? 10 * DEG : 10 * 60 * ARCSEC);
    ck_assert_int_eq(pm_model_prepare(m), PM_OK);
    if (aux) {
        pm_term t;
        memset(&t, 0, sizeof t);
        t.kind = PM_TERM_AUX;
        t.k = 4;
        t.aux = PM_AUX_TEMP;
        t.param = 10;
        ck_assert_int_eq(pm_model_add_term(m, &t, 2 * ARCSEC, NULL), PM_OK);
        ck_assert_int_eq(pm_model_prepare(m), PM_OK);
    }
}

typedef struct tally {
    long calls, ok, fresh, evals_track, evals_near, worst_far, worst_mid;
} tally;

/* Whether the state took J afresh in the last call: J's point moved. */
static int took_j(const pm_track *before, const pm_track *after)
{
    return !(before->flags & PM_TRACK_HAVE_J) ||
           memcmp(before->jac_at, after->jac_at, sizeof before->jac_at) != 0;
}

/* Track for n ticks of dt seconds the target that the encoder position
** (eh, ed) points at, moving at the sidereal rate, from that position;
** check every tick against pm_model_invert_near from the same start. */
static void track_run(const pm_model *m, pm_context *ctx, double eh, double ed, double dt,
                      int n, tally *s, int far)
{
    double ha0, dec;
    pm_track t;
    int k;
    if (ctx)
        ctx->temp_c = 5;
    ck_assert_int_eq(pm_model_apply(m, ctx, eh, ed, &ha0, &dec), PM_OK);
    ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
    for (k = 1; k <= n; k++) {
        double ah = ha0 + k * dt * SIDEREAL, th, td, nh, nd, bh, bd;
        pm_track before = t;
        unsigned long e0;
        pm_status st, sn;
        e0 = probe_count;
        st = pm_model_track(m, ctx, &t, ah, dec, &th, &td);
        s->evals_track += (long)(probe_count - e0);
        ck_assert_uint_le(probe_count - e0, PM_INVERT_NEAR_MAX_EVALS);
        if (far && (long)(probe_count - e0) > s->worst_far)
            s->worst_far = (long)(probe_count - e0);
        if (!far && (long)(probe_count - e0) > s->worst_mid)
            s->worst_mid = (long)(probe_count - e0);
        e0 = probe_count;
        sn = pm_model_invert_near(m, ctx, ah, dec, before.enc[0], before.enc[1], &nh, &nd);
        s->evals_near += (long)(probe_count - e0);
        s->calls++;
        s->fresh += took_j(&before, &t);
        ck_assert_msg(st == sn, "tick %d: track %d, invert_near %d", k, (int)st, (int)sn);
        if (st != PM_OK) {
            ck_assert_msg(memcmp(t.enc, before.enc, sizeof t.enc) == 0,
                          "a warning must leave the state's position");
            continue;
        }
        s->ok++;
        ck_assert_int_eq(pm_model_apply(m, ctx, th, td, &bh, &bd), PM_OK);
        ck_assert_msg(tu_angle(bh, bd, ah, dec) <= PM_INVERT_TOL + ROUND_TRIP_SLACK,
                      "tick %d (dt %g, encoders %.6f %.6f): round trip %.3g", k, dt, eh, ed,
                      tu_angle(bh, bd, ah, dec));
        if (far)
            ck_assert_msg(fabs(th - nh) <= SAME_AS_NEAR && fabs(td - nd) <= SAME_AS_NEAR,
                          "tick %d: track (%.17g, %.17g), invert_near (%.17g, %.17g)", k, th,
                          td, nh, nd);
        ck_assert(t.enc[0] == th && t.enc[1] == td);
    }
}

/* Realistic models, ticks of 1 ms, 0.1 s and 1 s, far from the mount's
** pole and within a few degrees of it, both sides. */
START_TEST(test_track_realistic)
{
    static const double dts[3] = {0.001, 0.1, 1.0};
    tu_rng r;
    tally s[3];
    int j, i;
    memset(s, 0, sizeof s);
    tu_seed(&r, 4242);
    for (j = 0; j < 12; j++) {
        pm_model m;
        pm_context ctx;
        const int aux = j % 3 == 2;
        memset(&ctx, 0, sizeof ctx);
        real_model(&m, &r, 1 + j % 2, aux);
        for (i = 0; i < 3; i++) {
            /* x: the encoder declination's distance from the equator of
            ** the mount, within 70 deg, or 0.5-5 deg from its pole */
            const double x_far = (2 * tu_uniform(&r) - 1) * 70 * DEG;
            const double x_pole = (tu_uniform(&r) < 0.5 ? 1 : -1) *
                                  (90 - 0.5 - 4.5 * tu_uniform(&r)) * DEG;
            const int flip = tu_uniform(&r) < 0.5;
            const double eh = (2 * tu_uniform(&r) - 1) * M_PI, e = m.coef[4];
            pm_context *c = aux ? &ctx : NULL;
            track_run(&m, c, eh, e + (flip ? M_PI - x_far : x_far), dts[i], 60, &s[i], 1);
            track_run(&m, c, eh, e + (flip ? M_PI - x_pole : x_pole), dts[i], 30, &s[i], 0);
        }
    }
    for (i = 0; i < 3; i++) {
        printf("track dt %g: %ld calls, %ld PM_OK, J taken %ld times, evaluations %ld "
               "(invert_near %ld), worst beyond 5 deg %ld, at 0.5-5 deg %ld\n",
               dts[i], s[i].calls, s[i].ok, s[i].fresh, s[i].evals_track, s[i].evals_near,
               s[i].worst_far, s[i].worst_mid);
        ck_assert_int_eq(s[i].ok, s[i].calls);
        ck_assert_int_le(s[i].worst_far, PM_INVERT_TRACK_MAX_EVALS);
    }
    /* J is carried and the start predicted (the last step again): about
    ** one evaluation per tick at 1 ms, J taken afresh at the start of each
    ** run and rarely after; at 0.1 s a second evaluation in one tick in
    ** five at most (the first ticks of a run, before there is a step, and
    ** near the mount's pole, where the path curves), J taken in one in
    ** five; at 1 s fewer evaluations than invert_near's */
    ck_assert_int_le(s[0].fresh, s[0].calls / 20);
    ck_assert_int_le(s[0].evals_track, s[0].calls * 105 / 100);
    ck_assert_int_le(s[1].fresh, s[1].calls / 5);
    ck_assert_int_le(s[1].evals_track, s[1].calls * 125 / 100);
    ck_assert_int_le(s[2].evals_track, s[2].evals_near);
}
END_TEST

/* Long loops: 3,000 ticks of 1 ms and of 0.1 s from each of three
** positions.  Where the start is the solution already it is returned as
** it is, with the sines and cosines the state predicted: their lengths
** must stay 1 (they would drift tick by tick, and the measured stop at
** such a point miss by as much), every tick round-tripping. */
START_TEST(test_track_long)
{
    static const double dts[2] = {0.001, 0.1};
    tu_rng r;
    pm_model m;
    int i, j, k;
    double worst = 0, worst_len = 0;
    tu_seed(&r, 83);
    real_model(&m, &r, 2, 0);
    for (j = 0; j < 2; j++)
        for (i = 0; i < 3; i++) {
            const double eh = (2 * tu_uniform(&r) - 1) * M_PI;
            const double ed = m.coef[4] + (2 * tu_uniform(&r) - 1) * 60 * DEG;
            double ha0, dec, th, td, bh, bd;
            pm_track t;
            ck_assert_int_eq(pm_model_apply(&m, NULL, eh, ed, &ha0, &dec), PM_OK);
            ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
            for (k = 1; k <= 3000; k++) {
                double ah = ha0 + k * dts[j] * SIDEREAL, rt;
                ck_assert_int_eq(pm_model_track(&m, NULL, &t, ah, dec, &th, &td), PM_OK);
                ck_assert_int_eq(pm_model_apply(&m, NULL, th, td, &bh, &bd), PM_OK);
                rt = tu_angle(bh, bd, ah, dec);
                if (rt > worst)
                    worst = rt;
                ck_assert_msg(rt <= PM_INVERT_TOL + ROUND_TRIP_SLACK,
                              "tick %d of %g s: round trip %.3g", k, dts[j], rt);
                if (t.flags & PM_TRACK_HAVE_TRIG) {
                    double l1 = fabs(t.trig[0] * t.trig[0] + t.trig[1] * t.trig[1] - 1);
                    double l2 = fabs(t.trig[2] * t.trig[2] + t.trig[3] * t.trig[3] - 1);
                    if (l1 > worst_len)
                        worst_len = l1;
                    if (l2 > worst_len)
                        worst_len = l2;
                }
            }
        }
    printf("track, 18,000 ticks: worst round trip %.3g rad, sin^2 + cos^2 - 1 at most %.3g\n",
           worst, worst_len);
    /* (the renormalisation's own roundings: a few units of 2.2e-16) */
    ck_assert_double_le(worst_len, 2e-15);
}
END_TEST

/* A loop whose target does not move uniformly: ticks of random length, a
** pause (the same target again: the predicted start overshoots), a
** reversal, a jump of a degree; every result the solution
** pm_model_invert_near finds from the state's position. */
START_TEST(test_track_irregular)
{
    tu_rng r;
    pm_model m;
    pm_track t;
    double eh = 0.7, ed, ah, ad, th, td, nh, nd, bh, bd;
    int k;
    tu_seed(&r, 80);
    real_model(&m, &r, 2, 0);
    ed = m.coef[4] + 40 * DEG;
    ck_assert_int_eq(pm_model_apply(&m, NULL, eh, ed, &ah, &ad), PM_OK);
    ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
    for (k = 1; k <= 80; k++) {
        pm_track before = t;
        if (k % 20 == 5)
            ; /* a pause */
        else if (k % 20 == 12)
            ah -= 3 * SIDEREAL; /* back 3 s */
        else if (k == 40)
            ad += 1 * DEG; /* a new target */
        else
            ah += SIDEREAL * (0.001 + 0.999 * tu_uniform(&r));
        ck_assert_int_eq(pm_model_track(&m, NULL, &t, ah, ad, &th, &td), PM_OK);
        ck_assert_int_eq(pm_model_invert_near(&m, NULL, ah, ad, before.enc[0], before.enc[1],
                                              &nh, &nd),
                         PM_OK);
        ck_assert_msg(fabs(th - nh) <= SAME_AS_NEAR && fabs(td - nd) <= SAME_AS_NEAR,
                      "tick %d: track (%.17g, %.17g), invert_near (%.17g, %.17g)", k, th, td,
                      nh, nd);
        ck_assert_int_eq(pm_model_apply(&m, NULL, th, td, &bh, &bd), PM_OK);
        ck_assert_double_le(tu_angle(bh, bd, ah, ad), PM_INVERT_TOL + ROUND_TRIP_SLACK);
    }
}
END_TEST

/* The model prepared again with other coefficients: the state's J is the
** old model's, and the next call must not use it (pm_model.ident).  With
** the anisotropic terms ten times larger the old J is far off; used with
** the predicted stop it would certify points that miss. */
START_TEST(test_track_model_change)
{
    tu_rng r;
    pm_model m;
    pm_track t;
    double eh, ed, th, td, bh, bd, dec = 30 * DEG;
    int k, i;
    tu_seed(&r, 77);
    real_model(&m, &r, 2, 0);
    ck_assert_int_eq(pm_model_invert(&m, NULL, 0.2, dec, PM_SIDE_NORMAL, &eh, &ed), PM_OK);
    ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
    for (k = 1; k <= 5; k++)
        ck_assert_int_eq(pm_model_track(&m, NULL, &t, 0.2 + k * 0.001 * SIDEREAL, dec, &th, &td),
                         PM_OK);
    for (i = 6; i < m.n_terms; i++)
        m.coef[i] *= 10;
    ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
    for (; k <= 10; k++) {
        pm_track before = t;
        double ah = 0.2 + k * 0.001 * SIDEREAL;
        ck_assert_int_eq(pm_model_track(&m, NULL, &t, ah, dec, &th, &td), PM_OK);
        if (k == 6)
            ck_assert_msg(took_j(&before, &t), "J of the old model kept");
        ck_assert_int_eq(pm_model_apply(&m, NULL, th, td, &bh, &bd), PM_OK);
        ck_assert_msg(tu_angle(bh, bd, ah, dec) <= PM_INVERT_TOL + ROUND_TRIP_SLACK,
                      "tick %d after the change: round trip %.3g", k,
                      tu_angle(bh, bd, ah, dec));
    }
}
END_TEST

/* An AUX input that changes between ticks changes J (its AUX part): the
** state takes J afresh when it does, and keeps it while it does not. */
START_TEST(test_track_aux_inputs)
{
    tu_rng r;
    pm_model m;
    pm_context ctx;
    pm_track t;
    double eh, ed, th, td, bh, bd, dec = -20 * DEG;
    int k, fresh = 0;
    tu_seed(&r, 78);
    real_model(&m, &r, 2, 1);
    memset(&ctx, 0, sizeof ctx);
    ctx.temp_c = 4;
    ck_assert_int_eq(pm_model_invert(&m, &ctx, 1.0, dec, PM_SIDE_NORMAL, &eh, &ed), PM_OK);
    ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
    for (k = 1; k <= 20; k++) {
        pm_track before = t;
        double ah = 1.0 + k * 0.001 * SIDEREAL;
        if (k > 10)
            ctx.temp_c -= 0.01; /* from tick 11 on, every tick */
        ck_assert_int_eq(pm_model_track(&m, &ctx, &t, ah, dec, &th, &td), PM_OK);
        if (k > 1)
            fresh += took_j(&before, &t) << (k > 10 ? 8 : 0);
        ck_assert_int_eq(pm_model_apply(&m, &ctx, th, td, &bh, &bd), PM_OK);
        ck_assert_double_le(tu_angle(bh, bd, ah, dec), PM_INVERT_TOL + ROUND_TRIP_SLACK);
    }
    ck_assert_int_eq(fresh & 0xff, 0);    /* ticks 2-10: J carried */
    ck_assert_int_eq(fresh >> 8, 10);     /* ticks 11-20: taken every tick */
}
END_TEST

/* Errors: a state pm_track_start did not fill, NULL pointers, non-finite
** or out-of-range inputs, a stale model: an error, and the state as it
** was. */
START_TEST(test_track_errors)
{
    tu_rng r;
    pm_model m;
    pm_track t, z, before;
    double eh, ed, th, td;
    tu_seed(&r, 79);
    real_model(&m, &r, 2, 0);
    ck_assert_int_eq(pm_model_invert(&m, NULL, 0.5, 0.3, PM_SIDE_NORMAL, &eh, &ed), PM_OK);
    ck_assert_int_eq(pm_track_start(NULL, eh, ed), PM_ERR_ARG);
    ck_assert_int_eq(pm_track_start(&t, NAN, ed), PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_track_start(&t, eh, INFINITY), PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_track_start(&t, 2 * PM_START_MAX, ed), PM_ERR_ARG);
    memset(&z, 0, sizeof z);
    ck_assert_int_eq(pm_model_track(&m, NULL, &z, 0.5, 0.3, &th, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
    ck_assert_int_eq(pm_model_track(&m, NULL, &t, 0.5, 0.3, &th, &td), PM_OK);
    before = t;
    ck_assert_int_eq(pm_model_track(NULL, NULL, &t, 0.5, 0.3, &th, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_model_track(&m, NULL, NULL, 0.5, 0.3, &th, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_model_track(&m, NULL, &t, 0.5, 0.3, NULL, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_model_track(&m, NULL, &t, NAN, 0.3, &th, &td), PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_model_track(&m, NULL, &t, 0.5, 2.0, &th, &td), PM_ERR_ARG);
    ck_assert(memcmp(&t, &before, sizeof t) == 0);
    m.coef[7] += 1e-6; /* changed without pm_model_prepare */
    ck_assert_int_eq(pm_model_track(&m, NULL, &t, 0.5, 0.3, &th, &td), PM_ERR_STATE);
    ck_assert(memcmp(&t, &before, sizeof t) == 0);
}
END_TEST

/* A model without anisotropic terms: the closed form, no evaluation. */
START_TEST(test_track_isotropic)
{
    pm_model m;
    pm_track t;
    double eh, ed, th, td, bh, bd;
    int k;
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 0), PM_OK);
    m.coef[0] = 100 * ARCSEC;
    m.coef[2] = 2 * DEG;
    m.coef[3] = 30 * ARCSEC;
    m.coef[5] = -50 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
    ck_assert_int_eq(pm_model_invert(&m, NULL, 0.1, 0.9, PM_SIDE_FLIPPED, &eh, &ed), PM_OK);
    ck_assert_int_eq(pm_track_start(&t, eh, ed), PM_OK);
    for (k = 1; k <= 5; k++) {
        unsigned long e0 = probe_count;
        double ah = 0.1 + k * 0.1 * SIDEREAL;
        ck_assert_int_eq(pm_model_track(&m, NULL, &t, ah, 0.9, &th, &td), PM_OK);
        ck_assert_uint_eq(probe_count - e0, 0);
        ck_assert_int_eq(pm_model_apply(&m, NULL, th, td, &bh, &bd), PM_OK);
        ck_assert_double_le(tu_angle(bh, bd, ah, 0.9), PM_INVERT_TOL + ROUND_TRIP_SLACK);
        ck_assert_msg(cos(td - m.coef[4]) < 0, "the flipped side kept");
    }
}
END_TEST

/* The float build's loop: models whose correction its fixed point takes
** (pm.h, pm_model_invert_f Note 2: below 0.01 rad after the index shifts;
** index terms within 1 deg, the polar axis, d and i within 0.1 deg,
** harmonic terms within 10'), ticks of 1 ms, 0.1 s and 1 s, up to 70 deg
** from the mount's equator, both sides: the same status as
** pm_model_invert_near_f from the same start, every PM_OK result
** round-tripping through the float forward model within
** 2 PM_INVERT_F_TOL, and one evaluation a tick (the forward model's
** check of the predicted point) where pm_model_invert_near_f makes more. */
START_TEST(test_track_float)
{
    static const double dts[3] = {0.001, 0.1, 1.0};
    tu_rng r;
    long calls = 0, ok = 0, ev_t[3] = {0, 0, 0}, ev_n[3] = {0, 0, 0};
    int j, i, k;
    tu_seed(&r, 81);
    for (j = 0; j < 8; j++) {
        pm_model m;
        pm_model_f mf;
        ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 2), PM_OK);
        for (i = 0; i < m.n_terms; i++)
            m.coef[i] = (2 * tu_uniform(&r) - 1) *
                        (i == 2 || i == 4 ? 1 * DEG : i < 6 ? 0.1 * DEG : 10 * 60 * ARCSEC);
        ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
        ck_assert_int_eq(pm_model_f_prepare(&mf, &m), PM_OK);
        for (i = 0; i < 3; i++) {
            const double x = (2 * tu_uniform(&r) - 1) * 70 * DEG, e = m.coef[4];
            const int flip = tu_uniform(&r) < 0.5;
            double eh = (2 * tu_uniform(&r) - 1) * M_PI, ed = e + (flip ? M_PI - x : x);
            double ha0, dec;
            pm_track_f t;
            ck_assert_int_eq(pm_model_apply_f(&mf, NULL, eh, ed, &ha0, &dec), PM_OK);
            ck_assert_int_eq(pm_track_f_start(&t, eh, ed), PM_OK);
            for (k = 1; k <= 40; k++) {
                double ah = ha0 + k * dts[i] * SIDEREAL, th, td, nh, nd, bh, bd;
                pm_track_f before = t;
                unsigned long e0 = probe_count;
                pm_status st = pm_model_track_f(&mf, NULL, &t, ah, dec, &th, &td), sn;
                if (k > 2)
                    ev_t[i] += (long)(probe_count - e0);
                ck_assert_uint_le(probe_count - e0, PM_INVERT_F_MAX_EVALS);
                e0 = probe_count;
                sn = pm_model_invert_near_f(&mf, NULL, ah, dec, before.enc[0], before.enc[1], &nh,
                                            &nd);
                if (k > 2)
                    ev_n[i] += (long)(probe_count - e0);
                calls++;
                ck_assert_msg(st == sn, "tick %d: track_f %d, invert_near_f %d", k, (int)st,
                              (int)sn);
                if (st != PM_OK)
                    continue;
                ok++;
                ck_assert_int_eq(pm_model_apply_f(&mf, NULL, th, td, &bh, &bd), PM_OK);
                ck_assert_msg(tu_angle(bh, bd, ah, dec) <= 2 * PM_INVERT_F_TOL,
                              "tick %d: float round trip %.3g", k, tu_angle(bh, bd, ah, dec));
                ck_assert(t.enc[0] == th && t.enc[1] == td);
            }
        }
    }
    printf("track_f: %ld calls, %ld PM_OK; evaluations from the third tick on: 1 ms %ld "
           "(invert_near_f %ld), 0.1 s %ld (%ld), 1 s %ld (%ld)\n",
           calls, ok, ev_t[0], ev_n[0], ev_t[1], ev_n[1], ev_t[2], ev_n[2]);
    ck_assert_int_eq(ok, calls);
    /* one evaluation a tick (the check of the predicted point) where
    ** pm_model_invert_near_f makes four to five */
    ck_assert_int_le(ev_t[0], ev_n[0] / 3);
    ck_assert_int_le(ev_t[1], ev_n[1] / 3);
    ck_assert_int_le(ev_t[2], ev_n[2] / 2);
}
END_TEST

/* The float state's errors: as pm_model_track's. */
START_TEST(test_track_float_errors)
{
    pm_model m;
    pm_model_f mf;
    pm_track_f t, z;
    double th, td;
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    m.coef[7] = 30 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
    ck_assert_int_eq(pm_model_f_prepare(&mf, &m), PM_OK);
    ck_assert_int_eq(pm_track_f_start(NULL, 0, 0), PM_ERR_ARG);
    ck_assert_int_eq(pm_track_f_start(&t, NAN, 0), PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_track_f_start(&t, 0, 2 * PM_START_MAX), PM_ERR_ARG);
    memset(&z, 0, sizeof z);
    ck_assert_int_eq(pm_model_track_f(&mf, NULL, &z, 0.1, 0.2, &th, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_track_f_start(&t, 0.1, 0.2), PM_OK);
    ck_assert_int_eq(pm_model_track_f(&mf, NULL, &t, 0.1, 0.2, NULL, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_model_track_f(NULL, NULL, &t, 0.1, 0.2, &th, &td), PM_ERR_ARG);
    ck_assert_int_eq(pm_model_track_f(&mf, NULL, &t, INFINITY, 0.2, &th, &td),
                     PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_model_track_f(&mf, NULL, &t, 0.1, 0.2, &th, &td), PM_OK);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("track");
    TCase *tc = tcase_create("track");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_track_realistic);
    tcase_add_test(tc, test_track_long);
    tcase_add_test(tc, test_track_irregular);
    tcase_add_test(tc, test_track_model_change);
    tcase_add_test(tc, test_track_aux_inputs);
    tcase_add_test(tc, test_track_errors);
    tcase_add_test(tc, test_track_isotropic);
    tcase_add_test(tc, test_track_float);
    tcase_add_test(tc, test_track_float_errors);
    suite_add_tcase(s, tc);
    return tu_run_suite(s);
}
