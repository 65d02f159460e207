/*
**  demo.c - a mount controller's use of the pointing model (ANSI C, C89).
**
**  The model is compiled in as constant data: build/fw/gen/fw_model.h is
**  written during the build by "pmfit fit examples/sim_gem.dat --order 2
**  --emit-c" and gives pm_fitted_load().  Then, as a controller would:
**
**  0) The model's own guard.  Every evaluation first checks that no
**     coefficient changed since pm_model_prepare, bit for bit (on
**     Armv7-M in Thumb-2 assembly of its own, lib/pm_detail.hpp): the
**     lowest bit and the sign of each coefficient in turn, changed in a
**     copy of the model, must make pm_model_apply, pm_model_invert and
**     pm_model_invert_near refuse it (PM_ERR_STATE), and putting it back
**     must make them work again; with an even and an odd number of terms
**     (the check reads the coefficients in pairs).
**  1) Tracking.  Every tick the controller reads the encoders, reports
**     where the telescope points (forward model, pm_model_apply), and
**     converts the target's apparent (ha, dec) for this tick into encoder
**     targets for the servo (inverse model, pm_model_invert_near from the
**     encoders).  The servo here is ideal: at the next tick the encoders
**     are where they were sent, so the reported position must be the
**     previous tick's target (checked to 1e-12 rad; 0.01" for float).  Three targets, one
**     of them close to the pole, one crossing the meridian; one tick is
**     FW_TICK_S seconds of sidereal motion (compressed time: a real loop
**     runs at 10-100 Hz, the arithmetic per tick is the same).  Beside it
**     the loop a controller that keeps its own setpoints would run:
**     pm_model_track (pm_model_track_f) with its state carried from tick
**     to tick, checked against pm_model_invert_near's result (1e-12 rad;
**     the float build 2 PM_INVERT_F_TOL) and its cost printed beside it.
**  2) Refit on the controller.  A pointing run: slew to FW_NOBS stars with
**     the current model, "measure" where the telescope really points (a
**     simulated true mount: the model with every coefficient changed by up
**     to 5 arcsec), keep the observations in static memory, and refit with
**     pm_fit_run into a static pm_fit.  The measurements carry 0.5 arcsec
**     of (deterministic, pseudo-random) noise per axis: the refit must
**     recover the true mount within 5 sigma of every coefficient, with a
**     residual sigma near 0.5 arcsec.
**
**  Every result is compared with the host build of this same program
**  (build/fw/gen/fw_ref.h, written by "demo --emit-ref"): within 1e-9 rad
**  for the double evaluation, 0.01" on the sky for the float build
**  (FW_FLOAT).  The exit code is 0 for pass, 1 for fail; under QEMU it is
**  passed out through semihosting.
**
**  On Cortex-M it also counts instructions per call (SysTick under
**  "qemu -icount shift=0", see fw_platform.h) and the stack used.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "fw_model.h"
#include "fw_platform.h"
#if defined(FW_REF)
#include "fw_ref.h"
#endif

/* FW_FLOAT: track with the float build of the evaluation (pm_model_f,
** for single-precision FPUs).  Tolerances of the tracking against the
** host's double results and of the reported position against the last
** target (radians): 1e-9 and 1e-12 for double, 0.01" = 4.8e-8 for float
** (its inverse iterates to PM_INVERT_F_TOL).  The pointing run slews with
** the double inverse in both (slews are rare; it is exact everywhere) and
** the refit is double, so it compares with the host to 1e-9 rad. */
#if defined(FW_FLOAT)
#define FW_TOL_RAD 4.8e-8
#define FW_TRACK_TOL 4.8e-8
#define FW_PREC "float"
#else
#define FW_TOL_RAD 1e-9
#define FW_TRACK_TOL 1e-12
#define FW_PREC "double"
#endif
#define FW_FIT_TOL_RAD 1e-9

#define FW_TARGETS 3
#define FW_TICKS 120
#define FW_TICK_S 60.0
#define FW_REF_EVERY 5 /* keep every 5th tick for the host comparison */
#define FW_NCHECK (FW_TARGETS * FW_TICKS / FW_REF_EVERY)
#define FW_NOBS 96
#define FW_NOISE (0.5 * ARCSEC) /* measurement noise per axis, rms */

#define PI 3.14159265358979323846
#define ARCSEC (PI / 648000.0)
#define SIDEREAL_RATE (2.0 * PI / 86164.0905) /* rad/s */

/* The model, the fit state and the observations live in static memory:
** the fit is ~35 KB at PM_MAX_L=2, never on a controller's stack. */
static pm_model model, truth, refit;
#if defined(FW_FLOAT)
static pm_model_f model_f;
#endif
static pm_fit fit;
static double obs_eh[FW_NOBS], obs_ed[FW_NOBS], obs_ah[FW_NOBS], obs_ad[FW_NOBS];
static double track[FW_NCHECK][4]; /* cmd_ha, cmd_dec, rep_ha, rep_dec */

static int failures;

static void fail(const char *what, double got, double limit)
{
    printf("FAIL: %s: %.3g (limit %.3g)\n", what, got, limit);
    failures++;
}

/* Angle between two (ha, dec) directions, accurate when small. */
static double angle(double t1, double d1, double t2, double d2)
{
    double a[3], b[3], c[3];
    a[0] = cos(d1) * cos(t1); a[1] = cos(d1) * sin(t1); a[2] = sin(d1);
    b[0] = cos(d2) * cos(t2); b[1] = cos(d2) * sin(t2); b[2] = sin(d2);
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                 a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

/* A 32-bit linear congruential generator: the same sequence wherever
** unsigned long is 32 or 64 bits. */
static unsigned long rng_state = 12345UL;
static double rng_pm1(void) /* uniform in [-1, 1) */
{
    rng_state = (rng_state * 1664525UL + 1013904223UL) & 0xFFFFFFFFUL;
    return (double)(rng_state >> 8) / 8388608.0 - 1.0;
}

/* Instruction statistics of one kind of call. */
typedef struct cost {
    unsigned long n, sum, max;
} cost;

static void cost_add(cost *c, unsigned long a, unsigned long b)
{
    unsigned long d = fw_counter_insns(a, b);
    c->n++;
    c->sum += d;
    if (d > c->max)
        c->max = d;
}

static void cost_print(const char *name, const cost *c)
{
    if (!fw_counter_available() || c->n == 0)
        return;
    printf("  %-22s %8lu instructions mean, %8lu max  (%lu calls)\n", name,
           c->sum / c->n, c->max, c->n);
}

/* ---------------------------------------------------------------------- */
/* The controller's evaluation: double, or the float build.               */

static pm_status ctl_apply(double eh, double ed, double *ah, double *ad)
{
#if defined(FW_FLOAT)
    return pm_model_apply_f(&model_f, NULL, eh, ed, ah, ad);
#else
    return pm_model_apply(&model, NULL, eh, ed, ah, ad);
#endif
}

static pm_status ctl_invert(double ah, double ad, double *eh, double *ed)
{
#if defined(FW_FLOAT)
    return pm_model_invert_f(&model_f, NULL, ah, ad, PM_SIDE_NORMAL, eh, ed);
#else
    return pm_model_invert(&model, NULL, ah, ad, PM_SIDE_NORMAL, eh, ed);
#endif
}

static pm_status ctl_invert_near(double ah, double ad, double sh, double sd, double *eh,
                                 double *ed)
{
#if defined(FW_FLOAT)
    return pm_model_invert_near_f(&model_f, NULL, ah, ad, sh, sd, eh, ed);
#else
    return pm_model_invert_near(&model, NULL, ah, ad, sh, sd, eh, ed);
#endif
}

/* The tracking loop's state (pm_model_track): one per axis pair. */
#if defined(FW_FLOAT)
static pm_track_f trk;
#define FW_TRACK_SAME (2 * PM_INVERT_F_TOL)
#else
static pm_track trk;
#define FW_TRACK_SAME 1e-12
#endif

static pm_status ctl_track_start(double eh, double ed)
{
#if defined(FW_FLOAT)
    return pm_track_f_start(&trk, eh, ed);
#else
    return pm_track_start(&trk, eh, ed);
#endif
}

static pm_status ctl_track(double ah, double ad, double *eh, double *ed)
{
#if defined(FW_FLOAT)
    return pm_model_track_f(&model_f, NULL, &trk, ah, ad, eh, ed);
#else
    return pm_model_track(&model, NULL, &trk, ah, ad, eh, ed);
#endif
}

/* ---------------------------------------------------------------------- */
/* Phase 0: the model's guard against a changed coefficient.             */
/* ---------------------------------------------------------------------- */

/* Flip one bit of x in place: bit 0 of its first byte (kind 0) or bit 7
** of its last (kind 1): the lowest mantissa bit and the sign on a
** little-endian machine, one in each 32-bit half of the double either way. */
static void flip_bit(double *x, int kind)
{
    unsigned char b[sizeof(double)];
    memcpy(b, x, sizeof b);
    if (kind == 0)
        b[0] ^= 1;
    else
        b[sizeof b - 1] ^= 0x80;
    memcpy(x, b, sizeof b);
}

static void staleness(void)
{
    pm_term x;
    double t, d, keep;
    int pass, i, kind, refused = 0, n = 0;
    truth = model; /* (a copy: pointing_run sets truth afresh) */
    for (pass = 0; pass < 2; pass++) {
        if (pass == 1) { /* one term more: the other parity */
            memset(&x, 0, sizeof x);
            x.kind = PM_TERM_FOURIER;
            x.k = PM_BASE_C;
            x.l = 1;
            x.param = 2.0;
            if (pm_model_add_term(&truth, &x, 1e-6, NULL) != PM_OK ||
                pm_model_prepare(&truth) != PM_OK) {
                fail("staleness: adding a term", 1, 0);
                return;
            }
        }
        for (i = 0; i < truth.n_terms; i++)
            for (kind = 0; kind < 2; kind++) {
                keep = truth.coef[i];
                flip_bit(&truth.coef[i], kind);
                n++;
                refused += pm_model_apply(&truth, NULL, 0.1, 0.2, &t, &d) == PM_ERR_STATE &&
                           pm_model_invert(&truth, NULL, 0.1, 0.2, PM_SIDE_NORMAL, &t, &d) ==
                               PM_ERR_STATE &&
                           pm_model_invert_near(&truth, NULL, 0.1, 0.2, 0.1, 0.2, &t, &d) ==
                               PM_ERR_STATE;
                truth.coef[i] = keep;
                if (pm_model_apply(&truth, NULL, 0.1, 0.2, &t, &d) != PM_OK ||
                    pm_model_invert(&truth, NULL, 0.1, 0.2, PM_SIDE_NORMAL, &t, &d) != PM_OK)
                    fail("staleness: the model restored", (double)i, 0);
            }
    }
    printf("staleness: %d of %d one-bit changes of a coefficient refused "
           "(%d and %d terms)\n", refused, n, model.n_terms, model.n_terms + 1);
    if (refused != n)
        fail("staleness: changes not refused", (double)(n - refused), 0);
}

/* ---------------------------------------------------------------------- */
/* Phase 1: tracking.                                                     */

static void tracking(void)
{
    static const double start[FW_TARGETS][2] = {
        {-1.60, 0.35},  /* east, mid declination */
        {-0.25, 1.45},  /* 83 deg, crosses the meridian */
        {-2.00, -0.45}  /* low in the south-east */
    };
    cost c_apply = {0, 0, 0}, c_inv = {0, 0, 0}, c_trk = {0, 0, 0};
    double worst = 0, worst_trk = 0;
    int t, k, n = 0;
    for (t = 0; t < FW_TARGETS; t++) {
        double ha = start[t][0], dec = start[t][1];
        double enc_ha, enc_dec, prev_ha = ha, prev_dec = dec;
        /* slew: the full inverse picks the normal pier side */
        pm_status st = ctl_invert(ha, dec, &enc_ha, &enc_dec);
        if (st != PM_OK)
            fail("pm_model_invert status", (double)st, 0);
        if (ctl_track_start(enc_ha, enc_dec) != PM_OK)
            fail("pm_track_start status", 0, 0);
        for (k = 1; k <= FW_TICKS; k++) {
            double rep_ha, rep_dec, cmd_ha, cmd_dec, trk_ha, trk_dec, err;
            unsigned long c0, c1, c2, c3;
            ha = start[t][0] + SIDEREAL_RATE * FW_TICK_S * k;
            c0 = fw_counter();
            st = ctl_apply(enc_ha, enc_dec, &rep_ha, &rep_dec);
            c1 = fw_counter();
            if (st == PM_OK)
                st = ctl_invert_near(ha, dec, enc_ha, enc_dec, &cmd_ha, &cmd_dec);
            c2 = fw_counter();
            if (st == PM_OK)
                st = ctl_track(ha, dec, &trk_ha, &trk_dec);
            c3 = fw_counter();
            cost_add(&c_apply, c0, c1);
            cost_add(&c_inv, c1, c2);
            cost_add(&c_trk, c2, c3);
            if (st != PM_OK) {
                fail("tracking status", (double)st, 0);
                return;
            }
            err = fabs(trk_ha - cmd_ha) > fabs(trk_dec - cmd_dec) ? fabs(trk_ha - cmd_ha)
                                                                  : fabs(trk_dec - cmd_dec);
            if (!(err <= worst_trk))
                worst_trk = err;
            err = angle(rep_ha, rep_dec, prev_ha, prev_dec);
            if (err > worst)
                worst = err;
            if (k % FW_REF_EVERY == 0) {
                track[n][0] = cmd_ha;
                track[n][1] = cmd_dec;
                track[n][2] = rep_ha;
                track[n][3] = rep_dec;
                n++;
            }
            enc_ha = cmd_ha; /* the servo gets there by the next tick */
            enc_dec = cmd_dec;
            prev_ha = ha;
            prev_dec = dec;
        }
    }
    printf("tracking: %d targets x %d ticks, reported position vs. last "
           "target: worst %.2e rad\n", FW_TARGETS, FW_TICKS, worst);
    if (worst > FW_TRACK_TOL)
        fail("tracking: report vs. target (rad)", worst, FW_TRACK_TOL);
    printf("tracking with a state: vs. invert_near worst %.2e rad\n", worst_trk);
    if (!(worst_trk <= FW_TRACK_SAME))
        fail("tracking: pm_model_track vs. invert_near (rad)", worst_trk, FW_TRACK_SAME);
#if defined(FW_FLOAT)
    cost_print("pm_model_apply_f", &c_apply);
    cost_print("pm_model_invert_near_f", &c_inv);
    cost_print("pm_model_track_f", &c_trk);
#else
    cost_print("pm_model_apply", &c_apply);
    cost_print("pm_model_invert_near", &c_inv);
    cost_print("pm_model_track", &c_trk);
#endif
}

/* ---------------------------------------------------------------------- */
/* Phase 2: pointing run and refit.                                       */

static void pointing_run(void)
{
    const double golden = PI * (3.0 - sqrt(5.0));
    const double z0 = sin(-35.0 * PI / 180), z1 = sin(85.0 * PI / 180);
    int i;
    truth = model;
    for (i = 0; i < truth.n_terms; i++)
        truth.coef[i] += 5.0 * ARCSEC * rng_pm1();
    if (pm_model_prepare(&truth) != PM_OK)
        fail("pm_model_prepare(truth)", 1, 0);
    for (i = 0; i < FW_NOBS; i++) {
        /* a Fibonacci spiral over dec -35..85 deg, |ha| <= 105 deg */
        double z = z0 + (z1 - z0) * (i + 0.5) / FW_NOBS;
        double dec = asin(z);
        double ha = fmod(golden * i, 2 * PI) / (2 * PI); /* 0..1 */
        double eh, ed, ah, ad;
        ha = (ha * 2 - 1) * 105.0 * PI / 180;
        if (pm_model_invert(&model, NULL, ha, dec, PM_SIDE_NORMAL, &eh, &ed) != PM_OK ||
            pm_model_apply(&truth, NULL, eh, ed, &ah, &ad) != PM_OK) {
            fail("pointing run status", 1, 0);
            return;
        }
        /* uniform noise of rms FW_NOISE along each axis on the sky */
        obs_eh[i] = eh;
        obs_ed[i] = ed;
        obs_ah[i] = ah + sqrt(3.0) * FW_NOISE * rng_pm1() / cos(ad);
        obs_ad[i] = ad + sqrt(3.0) * FW_NOISE * rng_pm1();
    }
}

static void refit_model(void)
{
    pm_fit_result res;
    cost c_add = {0, 0, 0}, c_solve = {0, 0, 0}, c_run = {0, 0, 0};
    unsigned long c0, c1;
    double worst = 0;
    pm_status st;
    int i;

    /* one pass by hand, to count its parts */
    refit = model;
    st = pm_fit_init(&fit, &refit);
    for (i = 0; i < FW_NOBS && st == PM_OK; i++) {
        c0 = fw_counter();
        st = pm_fit_add(&fit, NULL, obs_eh[i], obs_ed[i], obs_ah[i], obs_ad[i]);
        c1 = fw_counter();
        cost_add(&c_add, c0, c1);
    }
    if (st == PM_OK) {
        c0 = fw_counter();
        st = pm_fit_solve(&fit, &refit, &res);
        c1 = fw_counter();
        cost_add(&c_solve, c0, c1);
    }
    if (st != PM_OK)
        fail("fit pass status", (double)st, 0);

    /* the refit itself: Gauss-Newton to convergence from the current model */
    refit = model;
    c0 = fw_counter();
    st = pm_fit_run(&fit, &refit, NULL, FW_NOBS, obs_eh, obs_ed, obs_ah, obs_ad,
                    20, &res);
    c1 = fw_counter();
    cost_add(&c_run, c0, c1);
    if (st != PM_OK) {
        fail("pm_fit_run status", (double)st, 0);
        return;
    }
    for (i = 0; i < refit.n_terms; i++) {
        double d = fabs(refit.coef[i] - truth.coef[i]) / res.err[i];
        if (!(d <= worst))
            worst = d;
    }
    printf("refit: %d observations, %d terms, %d passes, sigma %.3f arcsec, "
           "worst |coef - true| = %.2f sigma\n", FW_NOBS, refit.n_terms,
           res.iterations, res.sigma / ARCSEC, worst);
    if (!(worst <= 5.0))
        fail("refit: coefficient vs. true mount (sigma)", worst, 5.0);
    if (!(res.sigma > 0.6 * FW_NOISE && res.sigma < 1.4 * FW_NOISE))
        fail("refit: residual sigma (arcsec)", res.sigma / ARCSEC, FW_NOISE / ARCSEC);
    cost_print("pm_fit_add", &c_add);
    cost_print("pm_fit_solve", &c_solve);
    cost_print("pm_fit_run (whole)", &c_run);
}

/* ---------------------------------------------------------------------- */

#if defined(FW_REF)
static void compare_with_host(void)
{
    double worst_t = 0, worst_c = 0;
    int i, j;
    if (FW_REF_NTRACK != FW_NCHECK || FW_REF_NCOEF != refit.n_terms) {
        fail("reference shape", 1, 0);
        return;
    }
    /* on the sphere: the angle between the two encoder positions and
    ** between the two reported positions */
    for (i = 0; i < FW_NCHECK; i++)
        for (j = 0; j < 4; j += 2) {
            double d = angle(track[i][j], track[i][j + 1], fw_ref_track[i][j],
                             fw_ref_track[i][j + 1]);
            if (!(d <= worst_t))
                worst_t = d; /* a NaN sticks */
        }
    for (i = 0; i < refit.n_terms; i++) {
        double d = fabs(refit.coef[i] - fw_ref_coef[i]);
        if (!(d <= worst_c))
            worst_c = d;
    }
    printf("vs. host: tracking worst %.2e rad (tolerance %.1e), refit worst %.2e rad "
           "(tolerance %.1e)\n", worst_t, FW_TOL_RAD, worst_c, FW_FIT_TOL_RAD);
    if (!(worst_t <= FW_TOL_RAD))
        fail("tracking vs. host (rad)", worst_t, FW_TOL_RAD);
    if (!(worst_c <= FW_FIT_TOL_RAD))
        fail("refit vs. host (rad)", worst_c, FW_FIT_TOL_RAD);
}
#endif

#if defined(FW_HOSTED)
static int emit_ref(const char *path)
{
    FILE *f = fopen(path, "w");
    int i;
    if (!f) {
        printf("cannot write %s\n", path);
        return 1;
    }
    fprintf(f, "/* Reference values from the host build of firmware_demo/demo.c\n"
               "** (demo --emit-ref); generated, do not edit. */\n");
    fprintf(f, "#define FW_REF_NTRACK %d\n#define FW_REF_NCOEF %d\n", FW_NCHECK,
            refit.n_terms);
    fprintf(f, "static const double fw_ref_track[%d][4] = {\n", FW_NCHECK);
    for (i = 0; i < FW_NCHECK; i++)
        fprintf(f, "    {%.17g, %.17g, %.17g, %.17g}%s\n", track[i][0], track[i][1],
                track[i][2], track[i][3], i + 1 < FW_NCHECK ? "," : "");
    fprintf(f, "};\nstatic const double fw_ref_coef[%d] = {\n", refit.n_terms);
    for (i = 0; i < refit.n_terms; i++)
        fprintf(f, "    %.17g%s\n", refit.coef[i], i + 1 < refit.n_terms ? "," : "");
    fprintf(f, "};\n");
    return fclose(f) == 0 ? 0 : 1;
}
#endif

#if defined(FW_HOSTED)
int main(int argc, char **argv)
#else
int main(void)
#endif
{
    unsigned long d_track = 0, d_fit = 0;
    pm_status st;

    fw_counter_init();
    printf("pm firmware demo: target %s, PM_MAX_L %d\n", fw_target(), PM_MAX_L);
    printf("sizeof: pm_term %lu, pm_context %lu, pm_model %lu, pm_model_f %lu, "
           "pm_fit %lu, pm_fit_result %lu\n", (unsigned long)sizeof(pm_term),
           (unsigned long)sizeof(pm_context), (unsigned long)sizeof(pm_model),
           (unsigned long)sizeof(pm_model_f), (unsigned long)sizeof(pm_fit),
           (unsigned long)sizeof(pm_fit_result));
    if (fw_counter_available()) {
        unsigned long got = fw_counter_calibrate(100000UL);
        printf("counter: a loop of 200000 instructions counted as %lu\n", got);
        if (got < 200000UL - 50 || got > 200000UL + 100)
            fail("instruction counter calibration", (double)got, 200000.0);
    }

    st = PM_CHECK_CONFIG();
    if (st != PM_OK) {
        printf("FAIL: library and demo built with different PM_MAX_L\n");
        return 1;
    }
    st = pm_fitted_load(&model);
    if (st != PM_OK) {
        printf("FAIL: loading the compiled-in model: status %d\n", (int)st);
        return 1;
    }
#if defined(FW_FLOAT)
    st = pm_model_f_prepare(&model_f, &model);
    if (st != PM_OK) {
        printf("FAIL: preparing the float model: status %d\n", (int)st);
        return 1;
    }
#endif
    printf("model: order %d, %d terms (compiled in), tracking in %s\n", model.order,
           model.n_terms, FW_PREC);

    staleness();
    fw_stack_paint();
    tracking();
    d_track = fw_stack_depth();
    pointing_run();
    fw_stack_paint();
    refit_model();
    d_fit = fw_stack_depth();
    if (fw_stack_available())
        printf("stack: tracking %lu bytes, refit %lu bytes (deepest point below "
               "the reset stack pointer)\n", d_track, d_fit);

#if defined(FW_REF)
    compare_with_host();
#endif
#if defined(FW_HOSTED)
    if (argc == 3 && strcmp(argv[1], "--emit-ref") == 0) {
        if (emit_ref(argv[2]) != 0)
            failures++;
    }
#endif
    printf("RESULT: %s (%s)\n", failures ? "FAIL" : "PASS", fw_target());
    return failures ? 1 : 0;
}
