/*
**  hard_cases.h - the adversarial models, contexts and targets of
**  tests/check_bounded.c, shared with the bench (bench/bench_dist.c
**  measures the inverse's cost on the same cases the test bounds).
**  Header-only C99 (static functions), deterministic: tu_rng.
*/
#ifndef PM_HARD_CASES_H
#define PM_HARD_CASES_H

#include <math.h>
#include <string.h>
#include "pm.h"
#include "testutil.h"

/* (static: each includer uses some of them) */
#if defined(__GNUC__)
#define HC_FN static __attribute__((unused))
#else
#define HC_FN static
#endif

/* Coefficient scales: ordinary mounts, badly built ones, and absurd. */
enum { HC_SCALE_NORMAL, HC_SCALE_LARGE, HC_SCALE_HUGE, HC_N_SCALES };

/* A random model of every term kind at the given scale (any order up to
** PM_MAX_L, equatorial or alt-az, up to five added terms of the kinds
** FOURIER..AUX).  Returns 0, or -1 if the library refused it. */
HC_FN int hc_random_model(pm_model *m, tu_rng *r, int scale)
{
    static const double iso_scale[HC_N_SCALES] = {1e-2, 0.3, 1e3};
    static const double an_scale[HC_N_SCALES] = {1e-3, 3e-2, 10.0};
    int mount = tu_uniform(r) < 0.5 ? PM_MOUNT_EQUATORIAL : PM_MOUNT_ALTAZ;
    int order = (int)(tu_uniform(r) * (PM_MAX_L + 1));
    int i, n_extra;
    if (pm_model_init(m, mount, order) != PM_OK)
        return -1;
    m->latitude = (tu_uniform(r) * 2 - 1) * M_PI / 2;
    for (i = 0; i < m->n_terms; i++)
        m->coef[i] = tu_gauss(r) * (i < 6 ? iso_scale[scale] : an_scale[scale]);
    if (pm_model_prepare(m) != PM_OK)
        return -1;
    n_extra = (int)(tu_uniform(r) * 6);
    for (i = 0; i < n_extra; i++) {
        pm_term t;
        memset(&t, 0, sizeof t);
        t.kind = (unsigned char)(1 + (int)(tu_uniform(r) * 4)); /* FOURIER..AUX */
        t.k = (unsigned char)(1 + (int)(tu_uniform(r) * 6));
        t.side = (signed char)((int)(tu_uniform(r) * 3) - 1);
        t.m = (signed char)(tu_uniform(r) < 0.5);
        switch (t.kind) {
        case PM_TERM_FOURIER:
            t.l = (signed char)(1 + (tu_uniform(r) < 0.5));
            t.param = tu_uniform(r) < 0.3 ? 1e6 : 1 + tu_uniform(r) * 720;
            break;
        case PM_TERM_SECTORAL:
            t.param = (double)(1 + (int)(tu_uniform(r) * 300));
            break;
        case PM_TERM_ZENITH:
            t.l = (signed char)(tu_uniform(r) < 0.5);
            t.m = 0;
            break;
        default:
            t.aux = (unsigned char)(tu_uniform(r) * (PM_AUX_USER + PM_MAX_AUX));
            t.param = tu_gauss(r) * 10;
            break;
        }
        if (pm_model_add_term(m, &t, tu_gauss(r) * an_scale[scale], NULL) != PM_OK)
            return -1;
    }
    return 0;
}

/* A context with ordinary, huge or denormal values. */
HC_FN void hc_random_context(pm_context *c, tu_rng *r)
{
    static const double vals[] = {0.0, 1e300, -1e300, 4.9e-324, 1e6, -40.0};
    int j;
    double u = tu_uniform(r);
    c->temp_c = u < 0.7 ? tu_gauss(r) * 10 : vals[(int)(tu_uniform(r) * 6)];
    c->time_h = u < 0.7 ? tu_gauss(r) * 5 : vals[(int)(tu_uniform(r) * 6)];
    c->pier = (int)(tu_uniform(r) * 3) - 1;
    c->dir = (int)(tu_uniform(r) * 3) - 1;
    for (j = 0; j < PM_MAX_AUX; j++)
        c->aux[j] = u < 0.7 ? tu_gauss(r) : vals[(int)(tu_uniform(r) * 6)];
}

/* An adversarial apparent position (ha, dec) for model m: the celestial
** poles, the mount's pole (within the anisotropic amplitude of it), hour
** angles at and next to +-180 deg and far outside (-pi, pi]. */
HC_FN void hc_hard_target(const pm_model *m, tu_rng *r, double *ha, double *dec)
{
    static const double has[] = {M_PI, -M_PI, 3.141592653589793, -3.1415926535897927,
                                 0.0, -0.0, 1e6, -1e300, 7 * M_PI};
    double e = m->coef[4];
    double u = tu_uniform(r);
    *ha = tu_uniform(r) < 0.5 ? has[(int)(tu_uniform(r) * 9)]
                              : (tu_uniform(r) * 2 - 1) * M_PI;
    if (u < 0.2)
        *dec = tu_uniform(r) < 0.5 ? M_PI / 2 : -M_PI / 2; /* celestial poles */
    else if (u < 0.5) {
        /* at the mount's pole, within the anisotropic amplitude of it */
        double p = (tu_uniform(r) < 0.5 ? M_PI / 2 : -M_PI / 2) + e;
        p += tu_gauss(r) * 1e-3 * (tu_uniform(r) < 0.5 ? 1.0 : 1e-6);
        *dec = p;
    } else
        *dec = asin(tu_uniform(r) * 2 - 1);
    if (*dec > M_PI / 2)
        *dec = M_PI - *dec; /* keep it on the sphere */
    if (*dec < -M_PI / 2)
        *dec = -M_PI - *dec;
}

/* The start of pm_model_invert_near for a hard case: near the solution
** just found (sol != 0: within ~1e-3 rad of it), or absurd. */
HC_FN void hc_hard_start(tu_rng *r, const double *sol, double *sh, double *sd)
{
    static const double starts[] = {1e300, -1e300, 1e7, M_PI, -M_PI, 0.0};
    if (sol && tu_uniform(r) < 0.5) {
        *sh = sol[0] + tu_gauss(r) * 1e-3;
        *sd = sol[1] + tu_gauss(r) * 1e-3;
    } else {
        *sh = starts[(int)(tu_uniform(r) * 6)];
        *sd = tu_uniform(r) < 0.5 ? starts[(int)(tu_uniform(r) * 6)] : tu_gauss(r);
    }
}

/* A realistic model near the mount's pole (issue 18): equatorial, order
** L = 0..2, every isotropic term uniform within +-10 deg, every harmonic
** term within +-10'.  Returns 0, or -1 if the library refused it. */
HC_FN int hc_real_model(pm_model *m, tu_rng *r)
{
    int order = (int)(tu_uniform(r) * 3), j;
    if (pm_model_init(m, PM_MOUNT_EQUATORIAL, order) != PM_OK)
        return -1;
    for (j = 0; j < m->n_terms; j++)
        m->coef[j] = (2 * tu_uniform(r) - 1) * (j < 6 ? 10 * DEG : 10 * ARCSEC * 60);
    return pm_model_prepare(m) == PM_OK ? 0 : -1;
}

/* A true encoder position of realistic model m within rho_max rad of the
** mount's pole (either pole, side PM_SIDE_*, hour angle all round): the
** distance uniform in area (40%), uniform (30%), log-uniform from 1e-10
** rad (20%), or exactly on the pole's edge (10%: rho = 0).  Returns the
** distance (*kind: which of the four). */
HC_FN double hc_real_position(const pm_model *m, tu_rng *r, double rho_max, double rho_min,
                               int *side, double *t, double *d, int *kind)
{
    double u = tu_uniform(r), rho;
    int hemi;
    *kind = u < 0.4 ? 0 : u < 0.7 ? 1 : u < 0.9 ? 2 : 3;
    if (*kind == 0)
        rho = sqrt(rho_min * rho_min + tu_uniform(r) * (rho_max * rho_max - rho_min * rho_min));
    else if (*kind == 1)
        rho = rho_min + tu_uniform(r) * (rho_max - rho_min);
    else if (*kind == 2)
        rho = rho_min > 0 ? rho_min : pow(10, -10 + 7 * tu_uniform(r));
    else
        rho = rho_min;
    hemi = tu_uniform(r) < 0.5 ? 1 : -1;
    *side = tu_uniform(r) < 0.5 ? PM_SIDE_NORMAL : PM_SIDE_FLIPPED;
    *t = (2 * tu_uniform(r) - 1) * M_PI;
    *d = m->coef[4] + hemi * (*side == PM_SIDE_NORMAL ? M_PI / 2 - rho : M_PI / 2 + rho);
    return rho;
}

/* pm_model_track in a loop's steady state (tests/check_bounded.c,
** test_bounded_track_state_beyond_half_degree; bench/track_worst_cm.c
** measures the same ticks on the Cortex-M7).  The models: order 1 + i % 2,
** isotropic terms uniform within +-10 deg, every harmonic term within
** +-10'.  Returns 0, or -1 if the library refused it. */
HC_FN int hc_track_model(pm_model *m, tu_rng *r, int i)
{
    int j;
    if (pm_model_init(m, PM_MOUNT_EQUATORIAL, 1 + i % 2) != PM_OK)
        return -1;
    for (j = 0; j < m->n_terms; j++)
        m->coef[j] = (2 * tu_uniform(r) - 1) * (j < 6 ? 10 * DEG : 10 * ARCSEC * 60);
    return pm_model_prepare(m) == PM_OK ? 0 : -1;
}

/* pm_model_track's state tk in a loop that has tracked the target (ah, ad)
** for three ticks of dh radians of hour angle, its solution (t, d) known:
** started at the solution three ticks before (J taken there), the two
** ticks before (ah, ad) made.  Returns the first error, else the largest
** status on the way (PM_OK, or a warning: within the anisotropic
** amplitude of the mount's pole a tick may end in one, and the state is
** then as it left it).  (bench/dist.c, hc_track_case) */
HC_FN pm_status hc_track_state(const pm_model *m, double ah, double ad, double t, double d,
                               double dh, pm_track *tk)
{
    double x[2], y[2];
    pm_status st, worst;
    int k;
    worst = pm_model_invert_near(m, NULL, ah - 3 * dh, ad, t, d, &x[0], &x[1]);
    if (worst < 0)
        return worst;
    st = pm_track_start(tk, x[0], x[1]);
    if (st != PM_OK)
        return st;
    for (k = 2; k >= 1; k--) {
        st = pm_model_track(m, NULL, tk, ah - k * dh, ad, &y[0], &y[1]);
        if (st < 0)
            return st;
        worst = st > worst ? st : worst;
    }
    return worst;
}

/* Tick j of model m: the target (ah, ad) rho rad from the mount's pole
** (0.5..5 deg for odd j, 5..90 for even), either pole and side, dt s of
** sidereal motion per tick (1 ms, 10 ms, 0.1 s, 50 ms by j); tk tracking
** it three ticks in (started at the solution three ticks before, J taken
** there, two ticks made), ready for the tick at (ah, ad).  Returns 0, or
** -1 if a call on the way did not give PM_OK. */
typedef struct hc_track_tick {
    double rho, dt, ah, ad;
    pm_track tk;
} hc_track_tick;

HC_FN int hc_track_case(const pm_model *m, tu_rng *r, int j, hc_track_tick *c)
{
    static const double dts[4] = {0.001, 0.01, 0.1, 0.05};
    double hemi, t, d;
    int flip;
    c->rho = (j % 2 ? 0.5 + tu_uniform(r) * 4.5 : 5 + tu_uniform(r) * 85) * DEG;
    hemi = tu_uniform(r) < 0.5 ? 1 : -1;
    flip = tu_uniform(r) < 0.5;
    t = (2 * tu_uniform(r) - 1) * M_PI;
    d = m->coef[4] + hemi * (flip ? M_PI / 2 + c->rho : M_PI / 2 - c->rho);
    c->dt = dts[j % 4];
    if (pm_model_apply(m, NULL, t, d, &c->ah, &c->ad) != PM_OK ||
        hc_track_state(m, c->ah, c->ad, t, d, 7.2921159e-5 * c->dt, &c->tk) != PM_OK)
        return -1;
    return 0;
}

#endif
