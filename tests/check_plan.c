/*
**  check_plan.c - which star next (pmfit plan, issue 17 item 1): the greedy
**  I-optimal plan against a uniform grid and random points.
**
**  For a German mount at latitude 47 (horizon 15 deg) and models of order
**  0, 1 and 2: the plan from nothing, N points long, and for every N the
**  predicted mean error over the sky of the plan's first N points, of a
**  uniform grid of N points (a golden-spiral lattice over the sky above the
**  horizon) and of N random points (mean of 8 draws).  Printed: how many
**  points each needs to reach the grid's error at its reference size; the
**  plan needs fewer than the grid and than random points.
**
**  And the real error, not the predicted one: a mount of that order (the
**  truth: arcminute isotropic terms, 15" harmonic terms, 1" noise) observed
**  at the plan's points and at the grid's, fitted, and compared with the
**  truth over the sky (20 noise draws): the plan's real error is the lower,
**  and each is within 25% of what was predicted.
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "plan.h"
#include "testutil.h"

#define LAT 47.0
#define NMAX 160

static pm_fit fit; /* large: static */

static double elevation(double ha_deg, double dec_deg)
{
    return asin(sin(LAT * DEG) * sin(dec_deg * DEG) +
                cos(LAT * DEG) * cos(dec_deg * DEG) * cos(ha_deg * DEG)) / DEG;
}

static void make_point(double ha, double dec, pmplan_target *t)
{
    t->x_deg = ha;
    t->y_deg = dec;
    t->el_deg = elevation(ha, dec);
    t->side = ha > 0 ? -1 : 1;
    t->after_arcsec = 0;
}

/* n points of a golden-spiral lattice over the sky above the horizon. */
static void grid(int n, pmplan_target *out)
{
    int total = n, k, got;
    for (;;) {
        got = 0;
        for (k = 0; k < total && got < n + 1; k++) {
            double z = 1 - (2.0 * k + 1) / total, ha = fmod(k * 137.50776405, 360.0) - 180;
            double dec = asin(z) / DEG;
            if (elevation(ha, dec) >= 15)
                got++;
        }
        if (got >= n)
            break;
        total++;
    }
    got = 0;
    for (k = 0; k < total && got < n; k++) {
        double z = 1 - (2.0 * k + 1) / total, ha = fmod(k * 137.50776405, 360.0) - 180;
        double dec = asin(z) / DEG;
        if (elevation(ha, dec) >= 15)
            make_point(ha, dec, &out[got++]);
    }
}

static void random_points(int n, tu_rng *r, pmplan_target *out)
{
    int k = 0;
    while (k < n) {
        double ha = (2 * tu_uniform(r) - 1) * 180, dec = asin(2 * tu_uniform(r) - 1) / DEG;
        if (elevation(ha, dec) >= 15)
            make_point(ha, dec, &out[k++]);
    }
}

static double predicted(const pmplan_options *o, const pmplan_target *p, int n)
{
    double e;
    char err[256];
    ck_assert_msg(pmplan_predicted(o, p, n, &e, err, sizeof err) == 0, "%s", err);
    return e;
}

/* The smallest N (from 1) at which the curve reaches target, or NMAX + 1. */
static int needed(const double *curve, double target)
{
    int n;
    for (n = 1; n <= NMAX; n++)
        if (curve[n] <= target)
            return n;
    return NMAX + 1;
}

/* Real mean error over the sky (per axis) of a model of order L fitted to
** observations at pts, against the truth; mean over draws. */
static double real_error(int order, const pmplan_target *pts, int n, int draws)
{
    static double eh[NMAX], ed[NMAX], ah[NMAX], ad[NMAX];
    pm_model truth, m;
    tu_rng r, g;
    int i, k, cnt = 0;
    double ss = 0;
    static const double iso[6] = {60, -40, 600, 30, -300, 20};
    ck_assert_int_eq(pm_model_init(&truth, PM_MOUNT_EQUATORIAL, order), PM_OK);
    for (i = 0; i < 6; i++)
        truth.coef[i] = iso[i] * ARCSEC;
    tu_seed(&r, 99);
    for (i = 6; i < truth.n_terms; i++)
        truth.coef[i] = (2 * tu_uniform(&r) - 1) * 15 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&truth), PM_OK);
    for (k = 0; k < draws; k++) {
        pm_fit_result res;
        tu_seed(&r, 1000 + (unsigned long long)k);
        for (i = 0; i < n; i++) {
            double t = pts[i].x_deg * DEG, d = pts[i].y_deg * DEG;
            if (pts[i].side < 0)
                t += M_PI, d = M_PI - d;
            eh[i] = t;
            ed[i] = d;
            ck_assert_int_eq(pm_model_apply(&truth, NULL, t, d, &ah[i], &ad[i]), PM_OK);
            ad[i] += ARCSEC * tu_gauss(&r);
            ah[i] += ARCSEC * tu_gauss(&r) / cos(ad[i]);
        }
        ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, order), PM_OK);
        if (pm_fit_run(&fit, &m, NULL, n, eh, ed, ah, ad, 50, &res) != PM_OK)
            return INFINITY;
        /* over the sky: 400 random places above the horizon, on the plan's sides */
        tu_seed(&g, 7);
        for (i = 0; i < 400; i++) {
            pmplan_target p;
            double t, d, ta, da, tb, db, e0, e1;
            random_points(1, &g, &p);
            t = p.x_deg * DEG, d = p.y_deg * DEG;
            if (p.side < 0)
                t += M_PI, d = M_PI - d;
            ck_assert_int_eq(pm_model_apply(&m, NULL, t, d, &ta, &da), PM_OK);
            ck_assert_int_eq(pm_model_apply(&truth, NULL, t, d, &tb, &db), PM_OK);
            e0 = remainder(ta - tb, 2 * M_PI) * cos(db);
            e1 = da - db;
            ss += 0.5 * (e0 * e0 + e1 * e1);
            cnt++;
        }
    }
    return sqrt(ss / cnt) / ARCSEC;
}

static void prove(int order, int nref)
{
    static pmplan_target plan[NMAX], g[NMAX], rnd[NMAX];
    static double cp[NMAX + 1], cg[NMAX + 1], cr[NMAX + 1];
    pmplan_options o;
    char err[256];
    double before, target, real_p, real_g, pred_p, pred_g;
    int n, d, np, ng, nr;
    tu_rng r;
    pmplan_options_default(&o);
    o.order = order;
    ck_assert_int_eq(pmplan_next(NULL, &o, NMAX, plan, &before, err, sizeof err), NMAX);
    tu_seed(&r, 5);
    for (n = 1; n <= NMAX; n++) {
        cp[n] = predicted(&o, plan, n);
        grid(n, g);
        cg[n] = predicted(&o, g, n);
        cr[n] = 0;
    }
    for (d = 0; d < 8; d++) {
        random_points(NMAX, &r, rnd);
        for (n = 1; n <= NMAX; n++)
            cr[n] += predicted(&o, rnd, n) / 8;
    }
    target = cg[nref];
    np = needed(cp, target);
    ng = needed(cg, target);
    nr = needed(cr, target);
    printf("check_plan: order %d: to reach the %d-point grid's predicted error %.3f\": plan %d "
           "points (%.0f%% fewer), grid %d, random %d\n", order, nref, target, np,
           100.0 * (1 - (double)np / nref), ng, nr);
    ck_assert_int_lt(np, nref);
    ck_assert_int_lt(np, nr);
    /* the real error of both designs at the reference size */
    grid(nref, g);
    real_p = real_error(order, plan, nref, 20);
    real_g = real_error(order, g, nref, 20);
    pred_p = cp[nref];
    pred_g = cg[nref];
    printf("check_plan: order %d, %d points: real error over the sky plan %.3f\" (predicted "
           "%.3f\"), grid %.3f\" (predicted %.3f\")\n", order, nref, real_p, pred_p, real_g, pred_g);
    ck_assert(real_p < real_g);
    ck_assert(fabs(real_p / pred_p - 1) < 0.25);
    ck_assert(fabs(real_g / pred_g - 1) < 0.25);
}

START_TEST(test_plan_beats_grid)
{
    static const int orders[3] = {0, 1, 2}, nref[3] = {20, 60, 140};
    prove(orders[_i], nref[_i]);
}
END_TEST

START_TEST(test_plan_errors)
{
    pmplan_options o;
    pmplan_target t[4];
    char err[256];
    double b;
    pmplan_options_default(&o);
    o.latitude_deg = NAN;
    ck_assert_int_eq(pmplan_next(NULL, &o, 4, t, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "latitude"));
    pmplan_options_default(&o);
    o.min_el_deg = 89.9;
    o.latitude_deg = -10; /* the pole below the horizon... and nothing above 89.9 on the grid */
    ck_assert_int_eq(pmplan_next(NULL, &o, 4, t, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "no usable sky"));
    pmplan_options_default(&o);
    ck_assert_int_eq(pmplan_next("/nonexistent.dat", &o, 4, t, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "/nonexistent.dat"));
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("plan");
    TCase *t = tcase_create("plan");
    tcase_set_timeout(t, 600);
    tcase_add_loop_test(t, test_plan_beats_grid, 0, 3);
    tcase_add_test(t, test_plan_errors);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
