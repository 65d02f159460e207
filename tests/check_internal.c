/*
**  check_internal.c - the core's own sin/cos (lib/pm_detail.hpp sincos_d,
**  sincos_d2), which replace libm's on the per-tick path of the double
**  build, and the double model that uses them, against long double on
**  x86-64 (64-bit significand: a reference ~2000 times finer than a
**  double's ulp).  Skipped where long double is no wider than double.
**
**    sincos_d      within 1 ulp of the exact value (the header states it)
**                  on 10^6 angles: uniform in |x| <= 64 (every quadrant
**                  of ten turns), in |x| <= 3.3, tiny angles, and angles
**                  within 1e-9 of multiples of pi/2 (the reduction's hard
**                  cases); beyond 64, NaN and infinities: libm's answers
**    sincos_d2     the same bits as sincos_d for both angles, in and out
**                  of its fast range
**    the model     pm_model_apply within 1e-15 rad of the same model in long
**                  double (the templates instantiated again,
**                  tests/internal_shim.cpp); pm_model_invert's PM_OK round
**                  trips within PM_INVERT_TOL through that long double
**                  forward model
**    the Jacobian  the inverse's analytic dD/d(ha, dec) (aniso_jac: every
**                  term kind) against central differences of the long
**                  double displacement
*/
#include "tu_check.h"
#include "testutil.h"
#include "pm.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void pm_test_sincos_d(double x, double *s, double *c);
void pm_test_sincos_d2(double x0, double x1, double *s0, double *c0, double *s1, double *c1);
void pm_test_apply_ld(const pm_model *m, const pm_context *ctx, double t, double d,
                      long double *T, long double *D);
void pm_test_aniso_ld(const pm_model *m, const pm_context *ctx, long double t, long double d,
                      long double D[2]);
void pm_test_aniso_jac(const pm_model *m, const pm_context *ctx, double t, double d,
                       double D[2], double J[4]);

/* |a - ref| in units of the last place of the double nearest ref. */
static double ulp_err(double a, long double ref)
{
    double r = (double)ref;
    double ulp = nextafter(fabs(r), INFINITY) - fabs(r);
    if (r == 0)
        return a == 0 ? 0 : INFINITY;
    return (double)(fabsl((long double)a - ref) / ulp);
}

static double test_angle(tu_rng *r, int i)
{
    double u = tu_uniform(r) * 2 - 1;
    switch (i % 4) {
    case 0: return u * 64;
    case 1: return u * 3.3;
    case 2: return u * 1e-3;
    default: return floor(u * 40 + 0.5) * M_PI / 2 + tu_uniform(r) * 2e-9 - 1e-9;
    }
}

START_TEST(test_sincos_d_ulp)
{
    tu_rng r;
    double worst_s = 0, worst_c = 0, at_s = 0, at_c = 0;
    int i;
    if (LDBL_MANT_DIG < 64) {
        printf("check_internal: skipped, long double is no finer than double here\n");
        return;
    }
    tu_seed(&r, 20261121);
    for (i = 0; i < 1000000; i++) {
        double x = test_angle(&r, i), s, c, es, ec;
        pm_test_sincos_d(x, &s, &c);
        es = ulp_err(s, sinl((long double)x));
        ec = ulp_err(c, cosl((long double)x));
        if (es > worst_s) {
            worst_s = es;
            at_s = x;
        }
        if (ec > worst_c) {
            worst_c = ec;
            at_c = x;
        }
    }
    printf("check_internal: sincos_d on 10^6 angles: sin within %.3f ulp (at %.17g), "
           "cos within %.3f ulp (at %.17g)\n", worst_s, at_s, worst_c, at_c);
    ck_assert_msg(worst_s < 1.0, "sin off by %g ulp at %.17g", worst_s, at_s);
    ck_assert_msg(worst_c < 1.0, "cos off by %g ulp at %.17g", worst_c, at_c);
}
END_TEST

START_TEST(test_sincos_d_outside)
{
    static const double xs[] = {64.000000000000014, -65.0, 1e3, -1e6, 1e300};
    size_t i;
    double s, c;
    for (i = 0; i < sizeof xs / sizeof xs[0]; i++) {
        pm_test_sincos_d(xs[i], &s, &c);
        ck_assert_msg(s == sin(xs[i]) && c == cos(xs[i]), "libm's answer at %g", xs[i]);
    }
    pm_test_sincos_d(NAN, &s, &c);
    ck_assert(isnan(s) && isnan(c));
    pm_test_sincos_d(INFINITY, &s, &c);
    ck_assert(isnan(s) && isnan(c));
    pm_test_sincos_d(64.0, &s, &c); /* the edge is inside */
    ck_assert(ulp_err(s, sinl(64.0L)) < 1.0 && ulp_err(c, cosl(64.0L)) < 1.0);
}
END_TEST

START_TEST(test_sincos_d2_same_bits)
{
    tu_rng r;
    int i, bad = 0;
    tu_seed(&r, 7);
    for (i = 0; i < 200000; i++) {
        double x0 = test_angle(&r, i), x1 = i % 97 == 0 ? 70.0 + i : test_angle(&r, i + 1);
        double s0, c0, s1, c1, a0, b0, a1, b1;
        pm_test_sincos_d2(x0, x1, &s0, &c0, &s1, &c1);
        pm_test_sincos_d(x0, &a0, &b0);
        pm_test_sincos_d(x1, &a1, &b1);
        bad += memcmp(&s0, &a0, sizeof s0) || memcmp(&c0, &b0, sizeof c0) ||
               memcmp(&s1, &a1, sizeof s1) || memcmp(&c1, &b1, sizeof c1);
    }
    ck_assert_int_eq(bad, 0);
}
END_TEST

/* A model of order L: isotropic terms of 0.01 rad (0.4 rad for every
** third), harmonic terms of 1e-4 rad. */
static void ld_model(pm_model *m, tu_rng *r, int mi)
{
    int i;
    double big = mi % 3 == 0 ? 0.4 : 0.01;
    ck_assert_int_eq(pm_model_init(m, PM_MOUNT_EQUATORIAL, mi % (PM_MAX_L + 1)), PM_OK);
    for (i = 0; i < m->n_terms; i++)
        m->coef[i] = (tu_uniform(r) * 2 - 1) * (i < 6 ? big : 1e-4);
    ck_assert_int_eq(pm_model_prepare(m), PM_OK);
}

/* Separation of (T1, D1) and (T2, D2), in long double (haversine). */
static long double ld_sep(long double T1, long double D1, long double T2, long double D2)
{
    long double a = sinl((D1 - D2) / 2), b = sinl((T1 - T2) / 2);
    long double h = a * a + cosl(D1) * cosl(D2) * b * b;
    return 2 * asinl(sqrtl(h));
}

/* The forward model (which takes its angles by series from the shifted
** position, and its sines and cosines from sincos_d2) against the same
** model evaluated in long double with libm's long double functions: on
** ordinary positions, hour angles to +-64 rad and declinations to +-4
** (the series' range), beyond it (the atan2 path), and within 0.05 rad of
** the mount's pole. */
START_TEST(test_apply_vs_long_double)
{
    static pm_model m;
    tu_rng r;
    double worst_t = 0, worst_d = 0, sum2 = 0;
    long n = 0;
    int mi, j;
    if (LDBL_MANT_DIG < 64)
        return;
    tu_seed(&r, 31);
    for (mi = 0; mi < 40; mi++) {
        ld_model(&m, &r, mi);
        for (j = 0; j < 4000; j++) {
            double u = tu_uniform(&r) * 2 - 1, v = tu_uniform(&r) * 2 - 1, t, d, T, D;
            long double Tr, Dr, eT, eD;
            switch (j % 4) {
            case 0: t = u * 3.2; d = v * 1.6; break;
            case 1: t = u * 64; d = v * 4; break;
            case 2: t = u * 100; d = v * 8; break;
            default:
                t = u * 3.2;
                d = m.coef[4] + (v < 0 ? -1 : 1) * (M_PI / 2 + v * 0.05);
                break;
            }
            ck_assert_int_eq(pm_model_apply(&m, NULL, t, d, &T, &D), PM_OK);
            pm_test_apply_ld(&m, NULL, t, d, &Tr, &Dr);
            eT = T - Tr;
            eT = fabsl(eT - 2 * (long double)M_PI * floorl(eT / (2 * (long double)M_PI) + 0.5L));
            eT *= cosl(Dr);
            eD = fabsl(D - Dr);
            if ((double)eT > worst_t)
                worst_t = (double)eT;
            if ((double)eD > worst_d)
                worst_d = (double)eD;
            sum2 += (double)(eT * eT + eD * eD);
            n++;
        }
    }
    printf("check_internal: pm_model_apply vs long double on %ld positions: ha (x cos dec) within "
           "%.2e rad, dec within %.2e rad, rms %.2e\n", n, worst_t, worst_d, sqrt(sum2 / n));
    ck_assert_msg(worst_t <= 1e-15 && worst_d <= 1e-15, "forward off by %g, %g", worst_t, worst_d);
}
END_TEST

/* The inverse's round trip through the long double forward model: a PM_OK
** inverse (either side, and from a start nearby) is within PM_INVERT_TOL of
** its target there too (plus the double forward's own 1e-15). */
START_TEST(test_invert_vs_long_double)
{
    static pm_model m;
    tu_rng r;
    double worst = 0;
    long ok = 0;
    int mi, j;
    if (LDBL_MANT_DIG < 64)
        return;
    tu_seed(&r, 37);
    for (mi = 0; mi < 40; mi++) {
        ld_model(&m, &r, mi);
        for (j = 0; j < 1500; j++) {
            double T = (tu_uniform(&r) * 2 - 1) * M_PI, D = asin(tu_uniform(&r) * 2 - 1) * 0.99;
            double t, d;
            long double Tr, Dr, e;
            pm_status st;
            if (j % 3 == 2)
                st = pm_model_invert_near(&m, NULL, T, D, T - m.coef[2] + 1e-3,
                                          D + m.coef[4] - 1e-3, &t, &d);
            else
                st = pm_model_invert(&m, NULL, T, D, j % 3 ? PM_SIDE_FLIPPED : PM_SIDE_NORMAL,
                                     &t, &d);
            if (st != PM_OK)
                continue;
            ok++;
            pm_test_apply_ld(&m, NULL, t, d, &Tr, &Dr);
            e = ld_sep(Tr, Dr, T, D);
            if ((double)e > worst)
                worst = (double)e;
        }
    }
    printf("check_internal: pm_model_invert round trips (%ld PM_OK) through the long double "
           "forward model: within %.2e rad\n", ok, worst);
    ck_assert(ok > 50000);
    ck_assert_msg(worst <= PM_INVERT_TOL + 1e-15, "round trip %g", worst);
}
END_TEST

/* The inverse's Newton steps use the Jacobian J = dD/d(ha, dec) of the
** anisotropic displacement, analytic (lib/pm_detail.hpp aniso_jac): against
** central differences (steps 1e-4 and 5e-5 rad, Richardson-extrapolated)
** of the displacement in long double,
** for models of every order with every added term kind (periodic of
** non-integer G, sectoral, both zenith terms, AUX, a harmonic term of one
** pier side; the pier side given, as a jump is not differentiable).  The
** differences' truncation is ~1e-17 of the fifth derivative; J agrees to
** TOL_JAC_REL of its size plus TOL_JAC_ABS (rad/rad). */
#define TOL_JAC_REL 1e-9
#define TOL_JAC_ABS 1e-14
START_TEST(test_aniso_jacobian)
{
    static pm_model m;
    static const int kinds[6] = {PM_TERM_FOURIER, PM_TERM_SECTORAL, PM_TERM_ZENITH,
                                 PM_TERM_ZENITH, PM_TERM_AUX, PM_TERM_SH};
    tu_rng r;
    pm_context c;
    double worst = 0;
    long n = 0;
    int mi, j, i;
    if (LDBL_MANT_DIG < 64)
        return;
    tu_seed(&r, 41);
    memset(&c, 0, sizeof c);
    c.temp_c = 12;
    c.pier = 1;
    for (mi = 0; mi < 40; mi++) {
        ck_assert_int_eq(pm_model_init(&m, mi % 2 ? PM_MOUNT_EQUATORIAL : PM_MOUNT_ALTAZ,
                                       1 + mi % PM_MAX_L), PM_OK);
        m.latitude = 0.7;
        for (i = 0; i < m.n_terms; i++)
            m.coef[i] = (tu_uniform(&r) * 2 - 1) * (i < 6 ? 0.1 : 3e-3);
        ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
        for (i = 0; i < 6; i++) {
            pm_term t;
            memset(&t, 0, sizeof t);
            t.kind = (unsigned char)kinds[i];
            t.k = (unsigned char)(1 + (i + mi) % 6);
            t.m = (signed char)(mi % 2);
            switch (t.kind) {
            case PM_TERM_FOURIER:
                t.l = (signed char)(1 + mi % 2);
                t.param = 1.5 + 3 * tu_uniform(&r);
                break;
            case PM_TERM_SECTORAL: t.param = 1 + mi % 4; break;
            case PM_TERM_ZENITH: t.l = (signed char)(i == 3); t.m = 0; break;
            case PM_TERM_AUX: t.aux = PM_AUX_TEMP; t.param = 3; break;
            default:
                t.l = 1;
                t.m = (signed char)(mi % 3 - 1);
                t.side = 1;
                break;
            }
            ck_assert_int_eq(pm_model_add_term(&m, &t, (tu_uniform(&r) * 2 - 1) * 2e-3, NULL),
                             PM_OK);
        }
        for (j = 0; j < 200; j++) {
            const long double h = 1e-4L;
            double t = (tu_uniform(&r) * 2 - 1) * M_PI, d = (tu_uniform(&r) * 2 - 1) * 1.5;
            double D[2], J[4];
            long double P[2], M[2];
            int ax, k;
            /* the zenith terms' cot(el) grows fast toward the horizon:
            ** positions 0.3 rad or more above it (at the encoder angles,
            ** within the isotropic terms' 0.1 rad of the model's) */
            double sel = m.mount == PM_MOUNT_ALTAZ
                             ? sin(d)
                             : sin(m.latitude) * sin(d) + cos(m.latitude) * cos(d) * cos(t);
            if (sel < sin(0.3))
                continue;
            pm_test_aniso_jac(&m, &c, t, d, D, J);
            for (ax = 0; ax < 2; ax++) {
                long double P2[2], M2[2];
                pm_test_aniso_ld(&m, &c, t + (ax == 0 ? h : 0), d + (ax == 1 ? h : 0), P);
                pm_test_aniso_ld(&m, &c, t - (ax == 0 ? h : 0), d - (ax == 1 ? h : 0), M);
                pm_test_aniso_ld(&m, &c, t + (ax == 0 ? h / 2 : 0), d + (ax == 1 ? h / 2 : 0),
                                 P2);
                pm_test_aniso_ld(&m, &c, t - (ax == 0 ? h / 2 : 0), d - (ax == 1 ? h / 2 : 0),
                                 M2);
                for (k = 0; k < 2; k++) {
                    /* Richardson: the h^2 term of the central difference
                    ** cancels */
                    long double d1 = (P[k] - M[k]) / (2 * h), d2 = (P2[k] - M2[k]) / h;
                    double fd = (double)((4 * d2 - d1) / 3), an = J[2 * k + ax];
                    double e = fabs(fd - an) / (TOL_JAC_REL * fabs(an) + TOL_JAC_ABS);
                    if (e > worst)
                        worst = e;
                    ck_assert_msg(e <= 1, "model %d at (%.17g, %.17g): J[%d] %.17g, differences "
                                  "%.17g", mi, t, d, 2 * k + ax, an, fd);
                }
            }
            n++;
        }
    }
    printf("check_internal: the analytic Jacobian of the displacement at %ld positions: within "
           "%.2g of its tolerance (%.0e relative + %.0e) of central differences\n", n, worst,
           TOL_JAC_REL, TOL_JAC_ABS);
}
END_TEST

static Suite *internal_suite(void)
{
    Suite *s = suite_create("internal");
    TCase *tc = tcase_create("sincos");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_sincos_d_ulp);
    tcase_add_test(tc, test_sincos_d_outside);
    tcase_add_test(tc, test_sincos_d2_same_bits);
    tcase_add_test(tc, test_apply_vs_long_double);
    tcase_add_test(tc, test_invert_vs_long_double);
    tcase_add_test(tc, test_aniso_jacobian);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(internal_suite()); }
