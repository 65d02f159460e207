/*
**  check_internal.c - the core's own sin/cos (lib/pm_detail.hpp sincos_d,
**  sincos_d2), which replace libm's on the per-tick path of the double
**  build, against long double libm on x86-64 (64-bit significand: a
**  reference ~2000 times finer than a double's ulp).
**
**    sincos_d      within 1 ulp of the exact value (the header states it)
**                  on 10^6 angles: uniform in |x| <= 64 (every quadrant
**                  of ten turns), in |x| <= 3.3, tiny angles, and angles
**                  within 1e-9 of multiples of pi/2 (the reduction's hard
**                  cases); beyond 64, NaN and infinities: libm's answers
**    sincos_d2     the same bits as sincos_d for both angles, in and out
**                  of its fast range
*/
#include "tu_check.h"
#include "testutil.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void pm_test_sincos_d(double x, double *s, double *c);
void pm_test_sincos_d2(double x0, double x1, double *s0, double *c0, double *s1, double *c1);

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

static Suite *internal_suite(void)
{
    Suite *s = suite_create("internal");
    TCase *tc = tcase_create("sincos");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_sincos_d_ulp);
    tcase_add_test(tc, test_sincos_d_outside);
    tcase_add_test(tc, test_sincos_d2_same_bits);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(internal_suite()); }
