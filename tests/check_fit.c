/*
**  check_fit.c - the least-squares fit: pm_fit_init/add/solve/run,
**  pm_fit_covariance and pm_fit_row.
**
**  TCases:
**    args        NULLs, non-finite input, calls out of order, bad indices
**    solver      one pass agrees with an independent LAPACK QR solve of the
**                design matrix built from pm_fit_row; errors and
**                correlations agree with an SVD of the same matrix
**    statistics  the unbiased sigma recovers the injected noise
**    offsets     degree-sized isotropic offsets: exact recovery, z-scores,
**                and the bias a single linear pass would leave
**    singular    rank deficiency, too few observations, pass kept on error
**
**  Set PM_TEST_VERBOSE=1 to print the measured numbers (stderr).
*/
#include <check.h>
#include <lapacke.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "testutil.h"

/* ---------------------------------------------------------------------- */
/* Tolerances and test constants.                                         */
/* ---------------------------------------------------------------------- */

/* Cholesky of the normal equations against Householder QR of the design
** matrix: the normal equations square the condition number; with column
** equilibration cond(A) is ~10-100 for the sampled skies here, so the
** expected disagreement is ~eps*cond^2 ~ 1e-12.  1e-9 is the requirement
** of the issue. */
#define TOL_QR_REL 1e-9
/* Coefficients smaller than this fraction of the largest one are compared
** only through the max-norm check (a relative error of a near-zero
** component says nothing). */
#define TINY_FRAC 1e-3
/* 1-sigma errors against sqrt(diag((A^T A)^-1)) * sigma from an SVD: same
** requirement as the coefficients. */
#define TOL_ERR_REL 1e-9
/* Correlations against the SVD reference (absolute; |rho| <= 1). */
#define TOL_CORR_ABS 1e-9
/* Rows against central differences with step FD_STEP (rad): truncation
** ~FD_STEP^2/6 * |r'''| ~ 2e-11 (rotations: derivatives of order 1),
** rounding ~eps*|r|/FD_STEP ~ 1e-12 for |r| ~ 0.2 rad; rows are O(1). */
#define FD_STEP 1e-5
#define TOL_FD 1e-8
/* Diagonal correlation c/sqrt(c*c): 1 up to a few rounding errors. */
#define TOL_CORR_DIAG 1e-14
/* chi^2 of a pass against sum r^2 of pm_fit_row at the same point: the
** same numbers summed in the same order, so only rounding differs. */
#define TOL_CHI2_REL 1e-12
/* chi^2 at the converged model against the sum of the squared angular
** distances model-to-observation (tu_angle): the transported-frame
** residual |log(q) - D| differs from the angle by a relative O(|D|^2)
** with |D| the anisotropic displacement (<= ~1e-3 rad here), and the
** last Gauss-Newton step (< 1e-6 sigma) changes chi^2 by far less. */
#define TOL_CHI2_SKY_REL 1e-5
/* Unbiased sigma against the injected noise: the requirement of the
** issue (the statistical scatter of sigma for 2N-P ~ 4000 degrees of
** freedom is 1/sqrt(2*4000) ~ 1.1%). */
#define TOL_SIGMA_REL 0.03
/* Noiseless data, exact model: coefficients recovered to this (rad).
** The requirement of the issue; double-precision rounding of the model
** and of the Gauss-Newton steps is ~1e-15. */
#define TOL_EXACT_RAD 1e-10
/* z = (fit - truth)/err is N(0,1) if the fit is unbiased and the errors
** right: over 20 seeds x P coefficients (>= 440 values) the RMS of z
** scatters by ~sqrt(1/(2*440)) ~ 3.4%, so [0.85, 1.15] is > 4 of those;
** P(|z| > 4.5) ~ 7e-6 per value. */
#define Z_RMS_LO 0.85
#define Z_RMS_HI 1.15
#define Z_MAX 4.5
/* Per seed, each of the six isotropic coefficients "within 3 sigma".
** Taken literally over 20 seeds x 6 = 120 z-values, a correct fit fails
** that with probability 1 - (1 - 0.0027)^120 = 28% (measured: seed index
** 16 at L = 1 has z(e') = -3.04, while over 500 seeds the fraction beyond
** 3 sigma is 0.20%, N(0,1) expects 0.27%).  So: no isotropic |z| beyond
** 4 (family-wise false alarm 120 * 6.3e-5 = 0.8%), and at most
** Z_ISO_N_BEYOND3 of the 120 beyond 3 (Poisson mean 0.32; P(> 2) = 0.4%). */
#define Z_ISO_MAX 4.0
#define Z_ISO_3SIGMA 3.0
#define Z_ISO_N_BEYOND3 2
/* A single linear pass from zero on degree-sized offsets is off by the
** neglected second order, (10 deg)^2/2 ~ 0.015 rad against errors of
** ~0.05 arcsec: anything below 100 sigma would mean no real bias. */
#define Z_BIASED_MIN 100.0
/* Gauss-Newton from zero to convergence on the degree-sized offsets
** (quadratic convergence: "a handful" of passes). */
#define MAX_GN_PASSES 8
#define MAX_ITER 20

#define LAT (47.9 * DEG)   /* observatory latitude of the simulated runs */
#define NOISE (1.0 * ARCSEC)
#define N_OBS 2000
#define N_SEEDS 20
#define ARCMIN (60.0 * ARCSEC)

/* The fit workspace is ~150 KB: static, not on the stack. */
static pm_fit g_fit, g_fit2, g_copy;

static void note(const char *fmt, ...)
{
    va_list ap;
    const char *v = getenv("PM_TEST_VERBOSE");
    if (!v || !*v || *v == '0')
        return;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
}

/* ---------------------------------------------------------------------- */
/* Helpers.                                                               */
/* ---------------------------------------------------------------------- */

/* Truth models.  "small": arcminute isotropic terms.  "big": the issue's
** offsets, c' = 10 deg, e' = 2 deg, a = b = d = i = 1 deg.  Harmonic terms
** 0.5..2.5 arcmin with alternating signs in both. */
static void make_truth(pm_model *m, int order, int big)
{
    static const double iso_small[6] = {3.0, -2.0, 5.0, 1.5, -4.0, 2.5};
    static const double iso_big[6] = {1.0, 1.0, 10.0, 1.0, 2.0, 1.0};
    int i;
    ck_assert_int_eq(pm_model_init(m, PM_MOUNT_EQUATORIAL, order), PM_OK);
    for (i = 0; i < 6; i++)
        m->coef[i] = big ? iso_big[i] * DEG : iso_small[i] * ARCMIN;
    for (i = 6; i < m->n_terms; i++)
        m->coef[i] = (i % 2 ? -1.0 : 1.0) * (0.5 + 0.5 * (double)((7 * i) % 5)) *
                     ARCMIN;
    ck_assert_int_eq(pm_model_prepare(m), PM_OK);
}

static void make_zero(pm_model *m, int order)
{
    ck_assert_int_eq(pm_model_init(m, PM_MOUNT_EQUATORIAL, order), PM_OK);
}

static void simulate(tu_run *run, const pm_model *truth, long n, double noise,
                     unsigned long long seed)
{
    ck_assert_int_eq(tu_simulate(run, truth, n, LAT, 0.3, noise, seed), 0);
}

static pm_status add_all(pm_fit *fit, const tu_run *run, long from, long to)
{
    long i;
    for (i = from; i < to; i++) {
        pm_status st = pm_fit_add(fit, NULL, run->eh[i], run->ed[i],
                                  run->ah[i], run->ad[i]);
        if (st != PM_OK)
            return st;
    }
    return PM_OK;
}

/* One Gauss-Newton pass from start over the whole run. */
static void one_pass(const pm_model *start, const tu_run *run, pm_model *out,
                     pm_fit_result *res)
{
    ck_assert_int_eq(pm_fit_init(&g_fit, start), PM_OK);
    ck_assert_int_eq(add_all(&g_fit, run, 0, run->n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, out, res), PM_OK);
}

/* Design matrix (row-major, 2N x P) and residuals at model m. */
static void design(const pm_model *m, const tu_run *run, double *A, double *r)
{
    long i;
    int P = m->n_terms;
    for (i = 0; i < run->n; i++) {
        double rr[2];
        ck_assert_int_eq(pm_fit_row(m, NULL, run->eh[i], run->ed[i],
                                    run->ah[i], run->ad[i], A + 2 * i * P,
                                    A + (2 * i + 1) * P, rr),
                         PM_OK);
        r[2 * i] = rr[0];
        r[2 * i + 1] = rr[1];
    }
}

/* Reference covariance (A^T A)^-1 (P x P, row-major) from the SVD of A
** (destroyed).  Returns the condition number of A with unit columns. */
static double svd_cov(double *A, long M, int P, double *cov)
{
    double *s = malloc((size_t)P * sizeof *s);
    double *vt = malloc((size_t)P * P * sizeof *vt);
    double *superb = malloc((size_t)P * sizeof *superb);
    double *colnorm = malloc((size_t)P * sizeof *colnorm);
    double cond;
    long i;
    int j, k;
    ck_assert_ptr_nonnull(s);
    ck_assert_ptr_nonnull(vt);
    ck_assert_ptr_nonnull(superb);
    ck_assert_ptr_nonnull(colnorm);
    /* equilibrate (as the library does) so that cond is meaningful; the
    ** covariance is scaled back below */
    for (j = 0; j < P; j++) {
        double ss = 0;
        for (i = 0; i < M; i++)
            ss += A[i * P + j] * A[i * P + j];
        colnorm[j] = sqrt(ss);
        for (i = 0; i < M; i++)
            A[i * P + j] /= colnorm[j];
    }
    ck_assert_int_eq(LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'A', (lapack_int)M,
                                    P, A, P, s, NULL, 1, vt, P, superb),
                     0);
    for (j = 0; j < P; j++)
        for (k = 0; k < P; k++) {
            double c = 0;
            int q;
            for (q = 0; q < P; q++)
                c += vt[q * P + j] * vt[q * P + k] / (s[q] * s[q]);
            cov[j * P + k] = c / (colnorm[j] * colnorm[k]);
        }
    cond = s[0] / s[P - 1];
    free(s);
    free(vt);
    free(superb);
    free(colnorm);
    return cond;
}

/* ---------------------------------------------------------------------- */
/* args                                                                   */
/* ---------------------------------------------------------------------- */

START_TEST(test_pm_fit_init_null)
{
    pm_model m;
    make_zero(&m, 1);
    ck_assert_int_eq(pm_fit_init(NULL, &m), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_init(&g_fit, NULL), PM_ERR_ARG);
}
END_TEST

START_TEST(test_pm_fit_init_stale_model)
{
    pm_model m;
    make_zero(&m, 1);
    m.coef[2] = 1e-3; /* changed, not re-prepared */
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_ERR_STATE);
    ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
}
END_TEST

START_TEST(test_pm_fit_add_null)
{
    ck_assert_int_eq(pm_fit_add(NULL, NULL, 0.1, 0.2, 0.1, 0.2), PM_ERR_ARG);
}
END_TEST

START_TEST(test_pm_fit_add_before_init_zeroed)
{
    memset(&g_fit, 0, sizeof g_fit);
    ck_assert_int_eq(pm_fit_add(&g_fit, NULL, 0.1, 0.2, 0.1, 0.2),
                     PM_ERR_STATE);
    ck_assert_int_eq(g_fit.n_obs, 0);
}
END_TEST

START_TEST(test_pm_fit_add_before_init_garbage)
{
    memset(&g_fit, 0xA5, sizeof g_fit);
    memcpy(&g_copy, &g_fit, sizeof g_fit);
    ck_assert_int_eq(pm_fit_add(&g_fit, NULL, 0.1, 0.2, 0.1, 0.2),
                     PM_ERR_STATE);
    ck_assert_int_eq(memcmp(&g_fit, &g_copy, sizeof g_fit), 0);
}
END_TEST

/* NaN or +-Inf in any of the four inputs: PM_ERR_NONFINITE, fit
** unchanged byte for byte (n_obs, normal equations, chi^2). */
START_TEST(test_pm_fit_add_nonfinite)
{
    pm_model m;
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    int b, arg;
    make_zero(&m, 1);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    ck_assert_int_eq(pm_fit_add(&g_fit, NULL, 0.3, 0.4, 0.31, 0.41), PM_OK);
    memcpy(&g_copy, &g_fit, sizeof g_fit);
    for (b = 0; b < 3; b++)
        for (arg = 0; arg < 4; arg++) {
            double x[4] = {0.3, 0.4, 0.31, 0.41};
            x[arg] = bad[b];
            ck_assert_int_eq(pm_fit_add(&g_fit, NULL, x[0], x[1], x[2], x[3]),
                             PM_ERR_NONFINITE);
            ck_assert_int_eq(g_fit.n_obs, 1);
            ck_assert_int_eq(memcmp(&g_fit, &g_copy, sizeof g_fit), 0);
        }
}
END_TEST

/* An apparent declination beyond the pole is not a position. */
START_TEST(test_pm_fit_add_dec_out_of_range)
{
    pm_model m;
    make_zero(&m, 0);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    memcpy(&g_copy, &g_fit, sizeof g_fit);
    ck_assert_int_eq(pm_fit_add(&g_fit, NULL, 0.3, 0.4, 0.3, 1.6),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_add(&g_fit, NULL, 0.3, 0.4, 0.3, -1.6),
                     PM_ERR_ARG);
    ck_assert_int_eq(memcmp(&g_fit, &g_copy, sizeof g_fit), 0);
}
END_TEST

START_TEST(test_pm_fit_solve_null)
{
    pm_model m, out;
    pm_fit_result res;
    make_zero(&m, 0);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    ck_assert_int_eq(pm_fit_solve(NULL, &out, &res), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_solve(&g_fit, NULL, &res), PM_ERR_ARG);
}
END_TEST

START_TEST(test_pm_fit_solve_before_init)
{
    pm_model out;
    pm_fit_result res;
    memset(&g_fit, 0, sizeof g_fit);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_STATE);
    memset(&g_fit, 0xA5, sizeof g_fit);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_STATE);
}
END_TEST

START_TEST(test_pm_fit_run_null)
{
    pm_model m;
    pm_fit_result res;
    double x[1] = {0.1};
    make_zero(&m, 0);
    ck_assert_int_eq(pm_fit_run(NULL, &m, NULL, 1, x, x, x, x, 5, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, NULL, NULL, 1, x, x, x, x, 5, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 1, NULL, x, x, x, 5, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 1, x, NULL, x, x, 5, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 1, x, x, NULL, x, 5, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 1, x, x, x, NULL, 5, &res),
                     PM_ERR_ARG);
}
END_TEST

START_TEST(test_pm_fit_run_bad_counts)
{
    pm_model m;
    pm_fit_result res;
    double x[1] = {0.1};
    make_zero(&m, 0);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, -1, x, x, x, x, 5, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 1, x, x, x, x, 0, &res),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 0, x, x, x, x, 5, &res),
                     PM_ERR_TOO_FEW);
}
END_TEST

START_TEST(test_pm_fit_run_stale_model)
{
    pm_model m, copy;
    pm_fit_result res;
    double x[1] = {0.1};
    make_zero(&m, 0);
    m.coef[4] = 1e-3;
    copy = m;
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 1, x, x, x, x, 5, &res),
                     PM_ERR_STATE);
    ck_assert_int_eq(memcmp(&m, &copy, sizeof m), 0);
}
END_TEST

/* One pass cannot converge from zero on degree-sized offsets:
** PM_ERR_DIVERGED, the model and the result untouched. */
START_TEST(test_pm_fit_run_max_iter_one_diverged)
{
    static pm_model truth, m, copy;
    pm_fit_result res, res_copy;
    tu_run run;
    make_truth(&truth, 1, 1);
    simulate(&run, &truth, N_OBS, NOISE, 11);
    make_zero(&m, 1);
    copy = m;
    memset(&res, 0x5A, sizeof res);
    res_copy = res;
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed,
                                run.ah, run.ad, 1, &res),
                     PM_ERR_DIVERGED);
    ck_assert_int_eq(memcmp(&m, &copy, sizeof m), 0);
    ck_assert_int_eq(memcmp(&res, &res_copy, sizeof res), 0);
    /* and with enough passes the same call succeeds */
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed,
                                run.ah, run.ad, MAX_ITER, &res),
                     PM_OK);
    tu_run_free(&run);
}
END_TEST

START_TEST(test_pm_fit_run_nonfinite)
{
    pm_model m, copy;
    pm_fit_result res;
    double eh[8], ed[8], ah[8], ad[8];
    int i;
    make_zero(&m, 0);
    for (i = 0; i < 8; i++) {
        eh[i] = ah[i] = -1.0 + 0.3 * i;
        ed[i] = ad[i] = -0.5 + 0.15 * i;
    }
    ad[5] = NAN;
    copy = m;
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 8, eh, ed, ah, ad, 5, &res),
                     PM_ERR_NONFINITE);
    ck_assert_int_eq(memcmp(&m, &copy, sizeof m), 0);
}
END_TEST

START_TEST(test_pm_fit_covariance_before_solve)
{
    pm_model m;
    pm_fit_result res;
    double c = 123.0, rho = 456.0;
    make_zero(&m, 0);
    memset(&res, 0, sizeof res);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 0, 0, &c, &rho),
                     PM_ERR_STATE);
    memset(&g_fit, 0, sizeof g_fit);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 0, 0, &c, &rho),
                     PM_ERR_STATE);
    ck_assert(c == 123.0 && rho == 456.0);
}
END_TEST

START_TEST(test_pm_fit_covariance_null)
{
    pm_model m, out;
    pm_fit_result res;
    double c;
    tu_run run;
    make_zero(&m, 0);
    simulate(&run, &m, 100, NOISE, 3);
    one_pass(&m, &run, &out, &res);
    ck_assert_int_eq(pm_fit_covariance(NULL, &res, 0, 0, &c, NULL),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, NULL, 0, 0, &c, NULL),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 0, 0, NULL, NULL),
                     PM_ERR_ARG);
    /* corr may be NULL */
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 0, 0, &c, NULL), PM_OK);
    tu_run_free(&run);
}
END_TEST

START_TEST(test_pm_fit_covariance_bad_index)
{
    pm_model m, out;
    pm_fit_result res;
    double c = 123.0, rho = 456.0;
    int P;
    tu_run run;
    make_zero(&m, 1);
    P = m.n_terms;
    simulate(&run, &m, 200, NOISE, 4);
    one_pass(&m, &run, &out, &res);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, -1, 0, &c, &rho),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 0, -1, &c, &rho),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, P, 0, &c, &rho),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 0, P, &c, &rho),
                     PM_ERR_ARG);
    ck_assert(c == 123.0 && rho == 456.0);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, P - 1, 0, &c, &rho),
                     PM_OK);
    tu_run_free(&run);
}
END_TEST

START_TEST(test_pm_fit_row_args)
{
    pm_model m;
    double r0[PM_MAX_TERMS], r1[PM_MAX_TERMS], r[2];
    make_zero(&m, 1);
    ck_assert_int_eq(pm_fit_row(NULL, NULL, 0.1, 0.2, 0.1, 0.2, r0, r1, r),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_row(&m, NULL, 0.1, 0.2, 0.1, 0.2, NULL, r1, r),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_row(&m, NULL, 0.1, 0.2, 0.1, 0.2, r0, NULL, r),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_row(&m, NULL, 0.1, 0.2, 0.1, 0.2, r0, r1, NULL),
                     PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_row(&m, NULL, 0.1, NAN, 0.1, 0.2, r0, r1, r),
                     PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_fit_row(&m, NULL, 0.1, 0.2, INFINITY, 0.2, r0, r1, r),
                     PM_ERR_NONFINITE);
    m.coef[7] = 1e-4;
    ck_assert_int_eq(pm_fit_row(&m, NULL, 0.1, 0.2, 0.1, 0.2, r0, r1, r),
                     PM_ERR_STATE);
}
END_TEST

/* ---------------------------------------------------------------------- */
/* solver                                                                 */
/* ---------------------------------------------------------------------- */

/* One pass of the library against LAPACK on the same design matrix.
** start_kind 0: from zero towards an arcminute truth; 1: from the
** degree-offset truth perturbed by 1..3 arcmin in every coefficient (rows
** linearised at large isotropic rotations; every step component sizable,
** so the per-coefficient comparison means something). */
static void check_against_lapack(int L, int start_kind)
{
    static pm_model truth, start, out;
    pm_fit_result res;
    tu_run run;
    long M;
    int P, i, j;
    double *A, *A2, *r, *cov, chi2 = 0, sig, maxd = 0, maxx = 0, worst = 0,
                              worst_err = 0, worst_rho = 0, cond;

    make_truth(&truth, L, start_kind);
    if (start_kind == 0) {
        make_zero(&start, L);
    } else {
        start = truth;
        for (i = 0; i < start.n_terms; i++)
            start.coef[i] += (i % 2 ? -1.0 : 1.0) * (1.0 + i % 3) * ARCMIN;
        ck_assert_int_eq(pm_model_prepare(&start), PM_OK);
    }
    simulate(&run, &truth, N_OBS, NOISE, 100 + (unsigned)L);
    P = start.n_terms;
    M = 2 * run.n;
    A = malloc((size_t)M * P * sizeof *A);
    A2 = malloc((size_t)M * P * sizeof *A2);
    r = malloc((size_t)M * sizeof *r);
    cov = malloc((size_t)P * P * sizeof *cov);
    ck_assert(A && A2 && r && cov);
    design(&start, &run, A, r);
    memcpy(A2, A, (size_t)M * P * sizeof *A);
    for (i = 0; i < M; i++)
        chi2 += r[i] * r[i];

    one_pass(&start, &run, &out, &res);

    /* coefficients: least squares by Householder QR */
    ck_assert_int_eq(LAPACKE_dgels(LAPACK_ROW_MAJOR, 'N', (lapack_int)M, P, 1,
                                   A, P, r, 1),
                     0);
    for (i = 0; i < P; i++) {
        double step = out.coef[i] - start.coef[i];
        double d = fabs(step - r[i]);
        if (d > maxd)
            maxd = d;
        if (fabs(r[i]) > maxx)
            maxx = fabs(r[i]);
    }
    ck_assert_double_le(maxd / maxx, TOL_QR_REL);
    for (i = 0; i < P; i++) {
        double step = out.coef[i] - start.coef[i], rel;
        if (fabs(r[i]) < TINY_FRAC * maxx)
            continue;
        rel = fabs(step - r[i]) / fabs(r[i]);
        if (rel > worst)
            worst = rel;
        ck_assert_double_le(rel, TOL_QR_REL);
    }

    /* statistics and errors: sigma and (A^T A)^-1 from an SVD */
    ck_assert_int_eq(res.n_obs, run.n);
    ck_assert_int_eq(res.n_par, P);
    ck_assert_double_eq_tol(res.chi2, chi2, TOL_CHI2_REL * chi2);
    sig = sqrt(chi2 / (double)(M - P));
    cond = svd_cov(A2, M, P, cov);
    for (i = 0; i < P; i++) {
        double want = sig * sqrt(cov[i * P + i]);
        double rel = fabs(res.err[i] - want) / want;
        if (rel > worst_err)
            worst_err = rel;
        ck_assert_double_le(rel, TOL_ERR_REL);
    }
    /* covariance and correlation */
    for (i = 0; i < P; i++)
        for (j = 0; j < P; j++) {
            double c, rho, c2, rho2;
            double want = cov[i * P + j] / sqrt(cov[i * P + i] * cov[j * P + j]);
            ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, i, j, &c, &rho),
                             PM_OK);
            ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, j, i, &c2, &rho2),
                             PM_OK);
            ck_assert(c == c2 && rho == rho2); /* symmetric */
            ck_assert_double_le(fabs(rho), 1.0);
            if (i == j) {
                ck_assert_double_eq_tol(rho, 1.0, TOL_CORR_DIAG);
                ck_assert_double_eq_tol(sqrt(c), res.err[i],
                                        TOL_ERR_REL * res.err[i]);
            }
            if (fabs(rho - want) > worst_rho)
                worst_rho = fabs(rho - want);
            ck_assert_double_eq_tol(rho, want, TOL_CORR_ABS);
        }
    note("solver L=%d start=%s: P=%d cond(A, unit columns)=%.1f  "
         "max|dx|/max|x|=%.2e  worst per-coef rel=%.2e  err rel=%.2e  "
         "rho abs=%.2e\n",
         L, start_kind ? "offset truth+1..3'" : "zero", P, cond, maxd / maxx,
         worst, worst_err, worst_rho);
    free(A);
    free(A2);
    free(r);
    free(cov);
    tu_run_free(&run);
}

/* The rows are the derivatives the solver assumes: -d r / d coef, checked
** by central differences of pm_fit_row's own residual r at re-prepared
** models, at the degree-offset L = 2 truth (where the isotropic part is far
** from linear), on both pier sides and close to the pole. */
START_TEST(test_pm_fit_row_matches_finite_difference)
{
    static pm_model m, mp, mm;
    static const double pts[6][4] = {
        /* enc_ha, enc_dec, app_ha, app_dec */
        {0.3, 0.4, 0.5, 0.45},          {-2.0, -0.7, -1.8, -0.72},
        {2.9, 1.2, 3.05, 1.18},         {0.1, 1.5, 0.4, 1.52},
        {-1.0, 2.5, 2.2, 0.6},          {1.9, M_PI - 0.2, -1.2, 0.25}};
    double row0[PM_MAX_TERMS], row1[PM_MAX_TERMS], r[2], rp[2], rm[2],
        d0[PM_MAX_TERMS], d1[PM_MAX_TERMS], worst = 0;
    int p, j;
    make_truth(&m, 2, 1);
    for (p = 0; p < 6; p++) {
        const double *x = pts[p];
        ck_assert_int_eq(pm_fit_row(&m, NULL, x[0], x[1], x[2], x[3], row0,
                                    row1, r),
                         PM_OK);
        for (j = 0; j < m.n_terms; j++) {
            mp = m;
            mm = m;
            mp.coef[j] += FD_STEP;
            mm.coef[j] -= FD_STEP;
            ck_assert_int_eq(pm_model_prepare(&mp), PM_OK);
            ck_assert_int_eq(pm_model_prepare(&mm), PM_OK);
            ck_assert_int_eq(pm_fit_row(&mp, NULL, x[0], x[1], x[2], x[3], d0,
                                        d1, rp),
                             PM_OK);
            ck_assert_int_eq(pm_fit_row(&mm, NULL, x[0], x[1], x[2], x[3], d0,
                                        d1, rm),
                             PM_OK);
            ck_assert_double_eq_tol(row0[j], -(rp[0] - rm[0]) / (2 * FD_STEP),
                                    TOL_FD);
            ck_assert_double_eq_tol(row1[j], -(rp[1] - rm[1]) / (2 * FD_STEP),
                                    TOL_FD);
            if (fabs(row0[j] + (rp[0] - rm[0]) / (2 * FD_STEP)) > worst)
                worst = fabs(row0[j] + (rp[0] - rm[0]) / (2 * FD_STEP));
            if (fabs(row1[j] + (rp[1] - rm[1]) / (2 * FD_STEP)) > worst)
                worst = fabs(row1[j] + (rp[1] - rm[1]) / (2 * FD_STEP));
        }
    }
    note("solver: rows vs central differences, max abs diff %.2e\n", worst);
}
END_TEST

START_TEST(test_pm_fit_solve_matches_qr)
{
    check_against_lapack(_i, 0);
}
END_TEST

START_TEST(test_pm_fit_solve_matches_qr_offsets)
{
    check_against_lapack(_i, 1);
}
END_TEST

/* ---------------------------------------------------------------------- */
/* statistics                                                             */
/* ---------------------------------------------------------------------- */

START_TEST(test_pm_fit_run_sigma_unbiased)
{
    static pm_model truth, m;
    pm_fit_result res;
    tu_run run;
    int L = _i;
    long i;
    double sky = 0;
    make_truth(&truth, L, 0);
    simulate(&run, &truth, N_OBS, NOISE, 200 + (unsigned)L);
    make_zero(&m, L);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed,
                                run.ah, run.ad, MAX_ITER, &res),
                     PM_OK);
    ck_assert_int_eq(res.n_obs, N_OBS);
    ck_assert_int_eq(res.n_par, PM_SH_TERMS(L));
    ck_assert_int_eq(res.converged, 1);
    ck_assert_double_eq_tol(res.sigma / NOISE, 1.0, TOL_SIGMA_REL);
    ck_assert_double_eq_tol(res.sigma * res.sigma,
                            res.chi2 / (double)(2 * N_OBS - PM_SH_TERMS(L)),
                            TOL_CHI2_REL * res.sigma * res.sigma);
    /* chi^2 is the sum of squared angular distances on the sky */
    for (i = 0; i < run.n; i++) {
        double T, D, a;
        ck_assert_int_eq(pm_model_apply(&m, NULL, run.eh[i], run.ed[i], &T, &D),
                         PM_OK);
        a = tu_angle(T, D, run.ah[i], run.ad[i]);
        sky += a * a;
    }
    ck_assert_double_eq_tol(res.chi2, sky, TOL_CHI2_SKY_REL * sky);
    note("statistics L=%d: P=%d sigma/n=%.4f chi2/sum(angle^2)-1=%.2e "
         "passes=%d\n",
         L, res.n_par, res.sigma / NOISE, res.chi2 / sky - 1, res.iterations);
    tu_run_free(&run);
}
END_TEST

/* ---------------------------------------------------------------------- */
/* offsets                                                                */
/* ---------------------------------------------------------------------- */

/* Noiseless data from a model with degree-sized isotropic offsets: the
** converged fit returns every coefficient exactly (no first-order bias). */
START_TEST(test_pm_fit_run_offsets_noiseless_exact)
{
    static pm_model truth, m;
    pm_fit_result res;
    tu_run run;
    int L = _i, i;
    double worst = 0;
    make_truth(&truth, L, 1);
    simulate(&run, &truth, N_OBS, 0.0, 300 + (unsigned)L);
    make_zero(&m, L);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed,
                                run.ah, run.ad, MAX_ITER, &res),
                     PM_OK);
    ck_assert_int_le(res.iterations, MAX_GN_PASSES);
    for (i = 0; i < m.n_terms; i++) {
        double d = fabs(m.coef[i] - truth.coef[i]);
        if (d > worst)
            worst = d;
        ck_assert_double_eq_tol(m.coef[i], truth.coef[i], TOL_EXACT_RAD);
    }
    note("offsets noiseless L=%d: max|fit-truth|=%.2e rad, passes=%d, "
         "sigma=%.2e rad\n",
         L, worst, res.iterations, res.sigma);
    tu_run_free(&run);
}
END_TEST

/* With 1 arcsec noise, "the fitted coefficients agree with the truth
** within their 1-sigma errors" means statistically: z = (fit - truth)/err
** is distributed N(0,1), so about 68% of the |z| are below 1, the RMS of z
** over many coefficients and seeds is 1, and |z| beyond ~4.5 does not
** occur.  (Requiring every |z| < 1 would fail a correct fit a third of
** the time.) */
START_TEST(test_pm_fit_run_offsets_zscores)
{
    static pm_model truth, m;
    pm_fit_result res;
    tu_run run;
    int L = _i, i, seed, n = 0, maxit = 0, below1 = 0, iso_beyond3 = 0;
    double s2 = 0, zmax = 0, zisomax = 0;
    make_truth(&truth, L, 1);
    for (seed = 0; seed < N_SEEDS; seed++) {
        simulate(&run, &truth, N_OBS, NOISE, 1000 + 37 * (unsigned)seed);
        make_zero(&m, L);
        ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed,
                                    run.ah, run.ad, MAX_ITER, &res),
                         PM_OK);
        ck_assert_int_le(res.iterations, MAX_GN_PASSES);
        if (res.iterations > maxit)
            maxit = res.iterations;
        for (i = 0; i < m.n_terms; i++) {
            double z = (m.coef[i] - truth.coef[i]) / res.err[i];
            s2 += z * z;
            n++;
            below1 += fabs(z) < 1.0;
            if (fabs(z) > zmax)
                zmax = fabs(z);
            if (i < 6) {
                if (fabs(z) > zisomax)
                    zisomax = fabs(z);
                iso_beyond3 += fabs(z) > Z_ISO_3SIGMA;
                ck_assert_double_lt(fabs(z), Z_ISO_MAX);
            }
        }
        tu_run_free(&run);
    }
    ck_assert_double_ge(sqrt(s2 / n), Z_RMS_LO);
    ck_assert_double_le(sqrt(s2 / n), Z_RMS_HI);
    ck_assert_double_lt(zmax, Z_MAX);
    ck_assert_int_le(iso_beyond3, Z_ISO_N_BEYOND3);
    note("offsets z-scores L=%d: %d values, RMS z=%.3f, max|z|=%.2f, "
         "max|z| isotropic=%.2f (%d of %d beyond 3), frac |z|<1=%.3f, "
         "max passes=%d\n",
         L, n, sqrt(s2 / n), zmax, zisomax, iso_beyond3, 6 * N_SEEDS,
         (double)below1 / n, maxit);
}
END_TEST

/* A linear (first-order) fit, i.e. a single pass from zero as the paper's
** Sec. 5.1 regression would do, is biased by many sigma on these offsets;
** the converged fit is not. */
START_TEST(test_pm_fit_solve_single_pass_biased)
{
    static pm_model truth, zero, one, m;
    pm_fit_result res1, res;
    tu_run run;
    int L = _i, i;
    double z1max = 0, zmax = 0;
    make_truth(&truth, L, 1);
    simulate(&run, &truth, N_OBS, NOISE, 400 + (unsigned)L);
    make_zero(&zero, L);
    one_pass(&zero, &run, &one, &res1);
    ck_assert_int_eq(res1.converged, 0);
    m = zero;
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed,
                                run.ah, run.ad, MAX_ITER, &res),
                     PM_OK);
    for (i = 0; i < m.n_terms; i++) {
        double z1 = fabs(one.coef[i] - truth.coef[i]) / res.err[i];
        double z = fabs(m.coef[i] - truth.coef[i]) / res.err[i];
        if (z1 > z1max)
            z1max = z1;
        if (z > zmax)
            zmax = z;
    }
    ck_assert_double_gt(z1max, Z_BIASED_MIN);
    ck_assert_double_lt(zmax, Z_MAX);
    note("offsets single pass L=%d: max|z| one pass=%.3g (c' off by %.3g "
         "arcsec), converged max|z|=%.2f after %d passes\n",
         L, z1max, (one.coef[2] - truth.coef[2]) / ARCSEC, zmax,
         res.iterations);
    tu_run_free(&run);
}
END_TEST

/* ---------------------------------------------------------------------- */
/* singular                                                               */
/* ---------------------------------------------------------------------- */

static void sentinels(pm_model *out, pm_fit_result *res)
{
    memset(out, 0x5A, sizeof *out);
    memset(res, 0x5A, sizeof *res);
}

static void assert_sentinels(const pm_model *out, const pm_fit_result *res)
{
    pm_model o;
    pm_fit_result r;
    sentinels(&o, &r);
    ck_assert_int_eq(memcmp(out, &o, sizeof o), 0);
    ck_assert_int_eq(memcmp(res, &r, sizeof r), 0);
}

/* Observations (noiseless, zero model) at given encoder positions. */
static void add_points(pm_fit *fit, const double *t, const double *d, int n)
{
    int i;
    for (i = 0; i < n; i++)
        ck_assert_int_eq(pm_fit_add(fit, NULL, t[i], d[i], t[i], d[i]), PM_OK);
}

/* All points at one declination (30 deg): c', d and i all move the
** pointing along the hour-angle direction by cos(dec), -sin(dec) and 1,
** the same at every point, so d (the first of them that is a combination
** of earlier terms) is named. */
START_TEST(test_pm_fit_solve_single_dec_singular)
{
    static pm_model m, out;
    pm_fit_result res;
    double t[200], d[200];
    char name[16];
    int i;
    make_zero(&m, 0);
    for (i = 0; i < 200; i++) {
        t[i] = -M_PI + 2 * M_PI * (i + 0.5) / 200;
        d[i] = 30 * DEG;
    }
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    add_points(&g_fit, t, d, 200);
    sentinels(&out, &res);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_SINGULAR);
    assert_sentinels(&out, &res);
    ck_assert_int_ge(g_fit.bad_term, 0);
    ck_assert_int_lt(g_fit.bad_term, m.n_terms);
    ck_assert_int_eq(pm_term_name(&m, g_fit.bad_term, name, sizeof name),
                     PM_OK);
    ck_assert_str_eq(name, "d");
    note("singular: one declination -> bad_term %d \"%s\"\n", g_fit.bad_term,
         name);
}
END_TEST

/* All points on the meridian strip |ha| <= 1e-7 rad (0.02 arcsec): a and
** d both displace along hour angle by -sin(dec) (and b, e' along dec by
** -1), so d is named. */
START_TEST(test_pm_fit_solve_ha_strip_singular)
{
    static pm_model m, out;
    pm_fit_result res;
    double t[200], d[200];
    char name[16];
    int i;
    make_zero(&m, 0);
    for (i = 0; i < 200; i++) {
        t[i] = 1e-7 * sin(3.0 * i);
        d[i] = -60 * DEG + 140 * DEG * (i + 0.5) / 200;
    }
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    add_points(&g_fit, t, d, 200);
    sentinels(&out, &res);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_SINGULAR);
    assert_sentinels(&out, &res);
    ck_assert_int_eq(pm_term_name(&m, g_fit.bad_term, name, sizeof name),
                     PM_OK);
    ck_assert_str_eq(name, "d");
    note("singular: HA strip |ha|<=1e-7 -> bad_term %d \"%s\"\n",
         g_fit.bad_term, name);
}
END_TEST

/* L = 1 with every point on the equator: Y(1,0) = sin(dec) = 0, and the
** isotropic d moves by -sin(dec) = 0 too, a column of zeros: named by the
** zero diagonal before any factorisation. */
START_TEST(test_pm_fit_solve_equator_zero_column)
{
    static pm_model m, out;
    pm_fit_result res;
    double t[300], d[300];
    char name[16];
    int i;
    make_zero(&m, 1);
    for (i = 0; i < 300; i++) {
        t[i] = -M_PI + 2 * M_PI * (i + 0.5) / 300;
        d[i] = 0.0;
    }
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    add_points(&g_fit, t, d, 300);
    sentinels(&out, &res);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_SINGULAR);
    assert_sentinels(&out, &res);
    ck_assert_int_eq(pm_term_name(&m, g_fit.bad_term, name, sizeof name),
                     PM_OK);
    ck_assert_str_eq(name, "d");
}
END_TEST

/* 2N <= P: PM_ERR_TOO_FEW (L = 0: 3 points give 6 rows for 6 terms);
** one more point and the same pass solves. */
START_TEST(test_pm_fit_solve_too_few)
{
    static pm_model m, out;
    pm_fit_result res;
    const double t[4] = {-2.0, -0.5, 0.7, 2.2}, d[4] = {-0.6, 0.1, 0.9, 0.4};
    make_zero(&m, 0);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    add_points(&g_fit, t, d, 3);
    sentinels(&out, &res);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_TOO_FEW);
    assert_sentinels(&out, &res);
    add_points(&g_fit, t + 3, d + 3, 1);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_OK);
    ck_assert_int_eq(res.n_obs, 4);
}
END_TEST

START_TEST(test_pm_fit_solve_zero_obs)
{
    static pm_model m, out;
    pm_fit_result res;
    make_zero(&m, 0);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    sentinels(&out, &res);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_TOO_FEW);
    assert_sentinels(&out, &res);
}
END_TEST

/* After PM_ERR_SINGULAR the pass is kept: adding the rest of the run and
** solving again gives exactly the pass of a fit fed everything at once. */
START_TEST(test_pm_fit_solve_singular_keeps_pass)
{
    static pm_model truth, m, out, ref;
    pm_fit_result res, rref;
    tu_run run;
    double t[100], d[100];
    int i;
    make_truth(&truth, 1, 0);
    simulate(&run, &truth, 1000, NOISE, 500);
    make_zero(&m, 1);
    for (i = 0; i < 100; i++) {
        t[i] = -M_PI + 2 * M_PI * (i + 0.5) / 100;
        d[i] = 30 * DEG;
    }
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    add_points(&g_fit, t, d, 100);
    sentinels(&out, &res);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_SINGULAR);
    assert_sentinels(&out, &res);
    ck_assert_int_eq(add_all(&g_fit, &run, 0, run.n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_OK);
    ck_assert_int_eq(res.n_obs, 1100);
    ck_assert_int_eq(g_fit.bad_term, -1);

    ck_assert_int_eq(pm_fit_init(&g_fit2, &m), PM_OK);
    add_points(&g_fit2, t, d, 100);
    ck_assert_int_eq(add_all(&g_fit2, &run, 0, run.n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit2, &ref, &rref), PM_OK);
    /* the same sums in the same order: identical */
    ck_assert_int_eq(memcmp(out.coef, ref.coef, sizeof out.coef), 0);
    ck_assert(res.chi2 == rref.chi2);
    tu_run_free(&run);
}
END_TEST

/* A failed solve overwrites the covariance workspace: the covariance of the
** previous solve must then be refused, never returned as garbage. */
START_TEST(test_pm_fit_covariance_after_failed_solve)
{
    static pm_model truth, m, out;
    pm_fit_result res;
    tu_run run;
    double t[100], d[100], c, rho;
    int i;
    make_truth(&truth, 1, 0);
    simulate(&run, &truth, 500, NOISE, 501);
    make_zero(&m, 1);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    ck_assert_int_eq(add_all(&g_fit, &run, 0, run.n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_OK);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_OK);
    for (i = 0; i < 100; i++) {
        t[i] = -M_PI + 2 * M_PI * (i + 0.5) / 100;
        d[i] = 30 * DEG;
    }
    add_points(&g_fit, t, d, 100);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_SINGULAR);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_ERR_STATE);
    tu_run_free(&run);
}
END_TEST

/* Every failing status of a solve ends the previous covariance (pm.h,
** pm_fit_solve Note 6), also those returned before the factorisation
** touches it: PM_ERR_TOO_FEW (a solve again at once: the new pass is
** empty) and PM_ERR_ARG (no output model). */
START_TEST(test_pm_fit_covariance_after_early_failed_solve)
{
    static pm_model truth, m, out;
    pm_fit_result res;
    tu_run run;
    double c, rho, s;
    make_truth(&truth, 1, 0);
    simulate(&run, &truth, 500, NOISE, 502);
    make_zero(&m, 1);

    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    ck_assert_int_eq(add_all(&g_fit, &run, 0, run.n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_OK);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_OK);
    ck_assert_int_eq(pm_fit_pointing_sigma(&g_fit, &res, &out, NULL, 0.1, 0.2, &s, NULL), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_ERR_TOO_FEW);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_ERR_STATE);
    ck_assert_int_eq(pm_fit_pointing_sigma(&g_fit, &res, &out, NULL, 0.1, 0.2, &s, NULL),
                     PM_ERR_STATE);

    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    ck_assert_int_eq(add_all(&g_fit, &run, 0, run.n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_OK);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, NULL, &res), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_ERR_STATE);
    /* a successful solve brings it back */
    ck_assert_int_eq(add_all(&g_fit, &run, 0, run.n), PM_OK);
    ck_assert_int_eq(pm_fit_solve(&g_fit, &out, &res), PM_OK);
    ck_assert_int_eq(pm_fit_covariance(&g_fit, &res, 2, 3, &c, &rho), PM_OK);
    tu_run_free(&run);
}
END_TEST

/* term[] changed after pm_model_prepare into a term it refuses (pm.h,
** pm_model_prepare Note 1): the entries outside the evaluation's hot path
** return PM_ERR_STATE instead of reading it (out of bounds: l = 40 in the
** harmonics, aux = 250 in pm_context.aux). */
START_TEST(test_terms_changed_after_prepare)
{
    static pm_model truth, m, fitted, bad;
    static pm_model_f mf;
    pm_fit_result res;
    pm_context ctx;
    tu_run run;
    pm_term t;
    double r0[PM_MAX_TERMS], r1[PM_MAX_TERMS], r[2], s, g, sky[2] = {0.3, 0.4};
    int idx, k;
    make_truth(&truth, 1, 0);
    simulate(&run, &truth, 300, NOISE, 503);
    make_zero(&m, 1);
    memset(&t, 0, sizeof t);
    t.kind = PM_TERM_AUX;
    t.k = PM_BASE_C;
    t.aux = PM_AUX_USER;
    ck_assert_int_eq(pm_model_add_term(&m, &t, 0.0, &idx), PM_OK);
    memset(&ctx, 0, sizeof ctx);
    ck_assert_int_eq(pm_fit_init(&g_fit, &m), PM_OK);
    for (k = 0; k < run.n; k++) {
        ctx.aux[0] = k % 7 - 3.0;
        ck_assert_int_eq(pm_fit_add(&g_fit, &ctx, run.eh[k], run.ed[k], run.ah[k], run.ad[k]),
                         PM_OK);
    }
    ck_assert_int_eq(pm_fit_solve(&g_fit, &fitted, &res), PM_OK);
    ck_assert_int_eq(pm_fit_pointing_sigma(&g_fit, &res, &fitted, &ctx, 0.1, 0.2, &s, NULL), PM_OK);
    ck_assert_int_eq(pm_fit_row(&fitted, &ctx, 0.1, 0.2, 0.1, 0.2, r0, r1, r), PM_OK);
    for (k = 0; k < 2; k++) {
        int j;
        bad = fitted;
        if (k == 0) {
            ck_assert_int_eq(pm_model_find(&bad, PM_BASE_D, 1, 0, &j), PM_OK);
            bad.term[j].l = 40;
        } else {
            bad.term[idx].aux = 250;
        }
        ck_assert_int_eq(pm_fit_init(&g_fit2, &bad), PM_ERR_STATE);
        ck_assert_int_eq(pm_model_f_prepare(&mf, &bad), PM_ERR_STATE);
        ck_assert_int_eq(pm_fit_row(&bad, &ctx, 0.1, 0.2, 0.1, 0.2, r0, r1, r), PM_ERR_STATE);
        ck_assert_int_eq(pm_fit_pointing_sigma(&g_fit, &res, &bad, &ctx, 0.1, 0.2, &s, NULL),
                         PM_ERR_STATE);
        ck_assert_int_eq(pm_fit_point_gain(&g_fit, &res, &bad, &ctx, 0.1, 0.2, sky, 1, &g),
                         PM_ERR_STATE);
        ck_assert_int_eq(pm_fit_run(&g_fit2, &bad, &ctx, 1, run.eh, run.ed, run.ah, run.ad, 5,
                                    &res), PM_ERR_STATE);
        /* preparing again refuses it too */
        ck_assert_int_eq(pm_model_prepare(&bad), PM_ERR_ARG);
    }
    /* a term made AUX after the prepare: needs_ctx says no term reads the
    ** context (a NULL one would be read) */
    bad = fitted;
    bad.needs_ctx = 0;
    ck_assert_int_eq(pm_fit_init(&g_fit2, &bad), PM_ERR_STATE);
    ck_assert_int_eq(pm_fit_row(&bad, NULL, 0.1, 0.2, 0.1, 0.2, r0, r1, r), PM_ERR_STATE);
    tu_run_free(&run);
}
END_TEST

/* Exactly consistent data (chi^2 = 0 at the solution): pm_fit_run must
** converge, not report PM_ERR_DIVERGED because statistical tests scaled by
** chi^2 can never be met (regression: the firmware demo's noiseless refit). */
START_TEST(test_pm_fit_run_noiseless_converges)
{
    static pm_model truth, m;
    pm_fit_result res;
    double eh[400], ed[400], ah[400], ad[400];
    int i;
    ck_assert_int_eq(pm_model_init(&truth, PM_MOUNT_EQUATORIAL, 2), PM_OK);
    for (i = 0; i < truth.n_terms; i++)
        truth.coef[i] = 1e-4 * (double)((i * 37) % 11 - 5);
    truth.coef[2] = 0.1;
    ck_assert_int_eq(pm_model_prepare(&truth), PM_OK);
    for (i = 0; i < 400; i++) {
        eh[i] = -3 + 6.0 * (i % 40) / 40;
        ed[i] = -1 + 2.4 * (double)(i / 40) / 10.0;
        ck_assert_int_eq(pm_model_apply(&truth, NULL, eh[i], ed[i], &ah[i], &ad[i]), PM_OK);
    }
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 2), PM_OK);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, 400, eh, ed, ah, ad, 20, &res), PM_OK);
    for (i = 0; i < m.n_terms; i++)
        ck_assert_double_le(fabs(m.coef[i] - truth.coef[i]), 1e-12);
}
END_TEST

/* The index terms come back in (-pi, pi]: a start turns away (or a
** Gauss-Newton step that went there: -36179 deg from a start of 0, an
** outside probe) gave the same model with c' and e' turns away, and the
** TPOINT export and model files passed them on. */
START_TEST(test_pm_fit_run_index_turns_reduced)
{
    static pm_model truth, m;
    pm_fit_result res;
    tu_run run;
    int i;
    make_truth(&truth, 1, 1);
    simulate(&run, &truth, N_OBS, 0.0, 77);
    make_zero(&m, 1);
    m.coef[2] = truth.coef[2] + 7 * 2 * M_PI;
    m.coef[4] = truth.coef[4] - 3 * 2 * M_PI;
    m.coef[5] = truth.coef[5] + 2 * M_PI; /* i of 361 deg (an outside probe's fit: 360.06) */
    ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
    ck_assert_int_eq(pm_fit_run(&g_fit, &m, NULL, run.n, run.eh, run.ed, run.ah, run.ad,
                                MAX_ITER, &res),
                     PM_OK);
    ck_assert_double_le(fabs(m.coef[2]), M_PI);
    ck_assert_double_le(fabs(m.coef[4]), M_PI);
    ck_assert_double_le(fabs(m.coef[5]), M_PI);
    for (i = 0; i < m.n_terms; i++)
        ck_assert_double_eq_tol(m.coef[i], truth.coef[i], TOL_EXACT_RAD);
    tu_run_free(&run);
}
END_TEST

/* ---------------------------------------------------------------------- */

static Suite *fit_suite(void)
{
    Suite *s = suite_create("fit");
    TCase *tc;

    tc = tcase_create("args");
    tcase_add_test(tc, test_pm_fit_init_null);
    tcase_add_test(tc, test_pm_fit_init_stale_model);
    tcase_add_test(tc, test_pm_fit_add_null);
    tcase_add_test(tc, test_pm_fit_add_before_init_zeroed);
    tcase_add_test(tc, test_pm_fit_add_before_init_garbage);
    tcase_add_test(tc, test_pm_fit_add_nonfinite);
    tcase_add_test(tc, test_pm_fit_add_dec_out_of_range);
    tcase_add_test(tc, test_pm_fit_solve_null);
    tcase_add_test(tc, test_pm_fit_solve_before_init);
    tcase_add_test(tc, test_pm_fit_run_null);
    tcase_add_test(tc, test_pm_fit_run_bad_counts);
    tcase_add_test(tc, test_pm_fit_run_stale_model);
    tcase_add_test(tc, test_pm_fit_run_max_iter_one_diverged);
    tcase_add_test(tc, test_pm_fit_run_nonfinite);
    tcase_add_test(tc, test_pm_fit_covariance_before_solve);
    tcase_add_test(tc, test_pm_fit_covariance_null);
    tcase_add_test(tc, test_pm_fit_covariance_bad_index);
    tcase_add_test(tc, test_pm_fit_row_args);
    suite_add_tcase(s, tc);

    tc = tcase_create("solver");
    tcase_set_timeout(tc, 30);
    tcase_add_test(tc, test_pm_fit_row_matches_finite_difference);
    tcase_add_loop_test(tc, test_pm_fit_solve_matches_qr, 0, 3);
    tcase_add_loop_test(tc, test_pm_fit_solve_matches_qr_offsets, 0, 3);
    suite_add_tcase(s, tc);

    tc = tcase_create("statistics");
    tcase_set_timeout(tc, 30);
    tcase_add_loop_test(tc, test_pm_fit_run_sigma_unbiased, 0, 3);
    suite_add_tcase(s, tc);

    tc = tcase_create("offsets");
    tcase_set_timeout(tc, 60);
    tcase_add_loop_test(tc, test_pm_fit_run_offsets_noiseless_exact, 0, 3);
    tcase_add_test(tc, test_pm_fit_run_index_turns_reduced);
    tcase_add_loop_test(tc, test_pm_fit_run_offsets_zscores, 1, 3);
    tcase_add_loop_test(tc, test_pm_fit_solve_single_pass_biased, 1, 3);
    suite_add_tcase(s, tc);

    tc = tcase_create("singular");
    tcase_add_test(tc, test_pm_fit_solve_single_dec_singular);
    tcase_add_test(tc, test_pm_fit_solve_ha_strip_singular);
    tcase_add_test(tc, test_pm_fit_solve_equator_zero_column);
    tcase_add_test(tc, test_pm_fit_solve_too_few);
    tcase_add_test(tc, test_pm_fit_solve_zero_obs);
    tcase_add_test(tc, test_pm_fit_solve_singular_keeps_pass);
    tcase_add_test(tc, test_pm_fit_covariance_after_failed_solve);
    tcase_add_test(tc, test_pm_fit_covariance_after_early_failed_solve);
    tcase_add_test(tc, test_terms_changed_after_prepare);
    tcase_add_test(tc, test_pm_fit_run_noiseless_converges);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    int failed;
    SRunner *sr;
    (void)tu_data_dir;
    if (PM_CHECK_CONFIG() != PM_OK) {
        fprintf(stderr, "check_fit: library built with other capacities\n");
        return EXIT_FAILURE;
    }
    sr = srunner_create(fit_suite());
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
