/*
**  dist.c - the situations of the inverse's cost distribution (dist.h).
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dist.h"
#include "bench_common.h"
#include "hard_cases.h"

#define SIDEREAL 7.2921159e-5 /* rad/s */

static const char *const set_names[DIST_NSETS] = {"bench", "real", "hard"};
static const char *const modes[3] = {"cold", "track10", "track1k"};
static const double mode_dt[3] = {0, 0.1, 0.001};
static const char *const bands[3] = {"far", "mid", "pole"};
static const char *const sides[2] = {"normal", "flipped"};

/* bench and real: 3 modes x 3 bands x 2 sides each; hard: cold, near */
#define N_REAL (3 * 3 * 2)
int dist_count(void) { return 2 * N_REAL + 2; }

/* The evaluations the header promises for a call of this kind. */
static int bound_of(int near, int band_far_tracking)
{
#ifdef PM_INVERT_TRACK_MAX_EVALS
    if (band_far_tracking)
        return PM_INVERT_TRACK_MAX_EVALS;
#else
    (void)band_far_tracking;
#endif
    return near ? PM_INVERT_NEAR_MAX_EVALS : PM_INVERT_MAX_EVALS;
}

/* The realistic models: isotropic terms within +-10 deg, harmonic terms
** within +-10', order 2. */
static int real_model(pm_model *m, tu_rng *r)
{
    const double deg = M_PI / 180, amin = M_PI / 10800;
    int i;
    if (pm_model_init(m, PM_MOUNT_EQUATORIAL, 2) != PM_OK)
        return -1;
    for (i = 0; i < m->n_terms; i++)
        m->coef[i] = (2 * tu_uniform(r) - 1) * (i < 6 ? 10 * deg : 10 * amin);
    return pm_model_prepare(m) == PM_OK ? 0 : -1;
}

const char *const dist_prec_name[DIST_NPREC] = {"double", "float", "track"};

int dist_runnable(const dist_call *c, int prec, const int *have_f)
{
    return prec == 0 || (prec == 1 && have_f[c->model]) || (prec == 2 && c->have_tk);
}

/* pm_model_track's state at the tick before c's, three ticks into its
** loop (hc_track_state: warnings on the way allowed, the state then as
** those calls left it). */
static int track_state(const pm_model *m, dist_call *c, double t, double d, double dh)
{
    if (hc_track_state(m, c->ah, c->ad, t, d, dh, &c->tk) < 0)
        return -1;
    c->have_tk = 1;
    return 0;
}

int dist_make(int s, dist_situation *sit, pm_model *models, pm_model_f *mf, int *have_f,
              dist_call *calls)
{
    tu_rng r;
    int i, j;
    memset(sit, 0, sizeof *sit);
    tu_seed(&r, 1800 + (unsigned long long)s);
    sit->n = DIST_N;
    if (s >= 2 * N_REAL) {
        /* the hard cases of check_bounded ("ordinary" coefficients) */
        int near = s - 2 * N_REAL;
        sit->set = DIST_SET_HARD;
        sit->n_models = DIST_MAX_MODELS;
        sit->bound = bound_of(near, 0);
        snprintf(sit->name, sizeof sit->name, "hard_%s", near ? "near" : "cold");
        for (j = 0; j < sit->n_models; j++) {
            if (hc_random_model(&models[j], &r, HC_SCALE_NORMAL) != 0)
                return -1;
            have_f[j] = pm_model_f_prepare(&mf[j], &models[j]) == PM_OK;
        }
        for (i = 0; i < sit->n; i++) {
            dist_call *c = &calls[i];
            const pm_model *m = &models[i % sit->n_models];
            double sol[2];
            memset(c, 0, sizeof *c);
            c->model = i % sit->n_models;
            c->op = near ? DIST_NEAR : DIST_COLD;
            hc_random_context(&c->ctx, &r);
            c->use_ctx = m->needs_ctx || tu_uniform(&r) < 0.5;
            hc_hard_target(m, &r, &c->ah, &c->ad);
            c->side = tu_uniform(&r) < 0.5 ? PM_SIDE_NORMAL : PM_SIDE_FLIPPED;
            if (near) {
                pm_status st = pm_model_invert(m, c->use_ctx ? &c->ctx : NULL, c->ah, c->ad,
                                               c->side, &sol[0], &sol[1]);
                hc_hard_start(&r, st >= 0 ? sol : NULL, &c->sh, &c->sd);
            }
        }
        return 0;
    }
    {
        int set = s / N_REAL, k = s % N_REAL;
        int mode = k / 6, band = (k / 2) % 3, side = k % 2;
        const double deg = M_PI / 180;
        sit->set = set;
        sit->n_models = set == DIST_SET_BENCH ? 1 : 8;
        sit->bound = bound_of(mode > 0, mode > 0 && band < 2);
        snprintf(sit->name, sizeof sit->name, "%s_%s_%s_%s", set_names[set], modes[mode],
                 bands[band], sides[side]);
        for (j = 0; j < sit->n_models; j++) {
            if (set == DIST_SET_BENCH) {
                static bench_input in; /* (large: not on the stack) */
                if (bench_input_make(&in, 2) != 0)
                    return -1;
                models[j] = in.m;
            } else if (real_model(&models[j], &r) != 0)
                return -1;
            have_f[j] = pm_model_f_prepare(&mf[j], &models[j]) == PM_OK;
        }
        for (i = 0; i < sit->n; i++) {
            dist_call *c = &calls[i];
            const pm_model *m = &models[i % sit->n_models];
            double rho, dp, t, d, e = m->coef[4];
            int hemi = tu_uniform(&r) < 0.5 ? 1 : -1;
            memset(c, 0, sizeof *c);
            c->model = i % sit->n_models;
            /* distance from the mount's pole: uniform on the sphere beyond
            ** 5 deg; uniform in area within the bands near it */
            if (band == 0)
                rho = M_PI / 2 - asin(tu_uniform(&r) * sin(85 * deg));
            else if (band == 1)
                rho = sqrt(0.5 * 0.5 + tu_uniform(&r) * (5 * 5 - 0.5 * 0.5)) * deg;
            else
                rho = sqrt(tu_uniform(&r)) * 0.5 * deg;
            dp = side == 0 ? hemi * (M_PI / 2 - rho) : hemi * (M_PI / 2 + rho);
            t = (2 * tu_uniform(&r) - 1) * M_PI;
            d = dp + e;
            if (pm_model_apply(m, NULL, t, d, &c->ah, &c->ad) != PM_OK)
                return -1;
            c->side = side == 0 ? PM_SIDE_NORMAL : PM_SIDE_FLIPPED;
            if (mode == 0) {
                c->op = DIST_COLD;
            } else {
                /* the previous tick: the target mode_dt earlier, solved */
                double ph = c->ah - SIDEREAL * mode_dt[mode];
                c->op = DIST_NEAR;
                if (pm_model_invert_near(m, NULL, ph, c->ad, t, d, &c->sh, &c->sd) < 0)
                    return -1;
                if (track_state(m, c, t, d, SIDEREAL * mode_dt[mode]) != 0)
                    return -1;
            }
        }
    }
    return 0;
}

pm_status dist_run(int prec, const pm_model *models, const pm_model_f *mf,
                   const dist_call *c, double *eh, double *ed)
{
    const pm_context *ctx = c->use_ctx ? &c->ctx : NULL;
    if (prec == 2) {
        pm_track t = c->tk;
        return pm_model_track(&models[c->model], ctx, &t, c->ah, c->ad, eh, ed);
    }
    if (prec == 0)
        return c->op == DIST_COLD
                   ? pm_model_invert(&models[c->model], ctx, c->ah, c->ad, c->side, eh, ed)
                   : pm_model_invert_near(&models[c->model], ctx, c->ah, c->ad, c->sh, c->sd,
                                          eh, ed);
    return c->op == DIST_COLD
               ? pm_model_invert_f(&mf[c->model], ctx, c->ah, c->ad, c->side, eh, ed)
               : pm_model_invert_near_f(&mf[c->model], ctx, c->ah, c->ad, c->sh, c->sd, eh,
                                        ed);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void dist_stats(double *v, int n, double *med, double *p99, double *worst)
{
    int k;
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    *med = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    /* the smallest value at least 99% of the calls do not exceed */
    k = (int)ceil(0.99 * n) - 1;
    *p99 = v[k < 0 ? 0 : k];
    *worst = v[n - 1];
}
