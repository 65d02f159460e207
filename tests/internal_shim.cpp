/*
**  internal_shim.cpp - the core's internal helpers (lib/pm_detail.hpp)
**  behind C entry points for tests/check_internal.c, compiled with the
**  core's flags (Makefile).  Test-only: the library exports none of this.
**
**  Also the forward model evaluated in long double: the same templates
**  instantiated with long double and libm's long double functions, the
**  model's constants (H, the sines and cosines of c', d, e', i) computed
**  again from its coefficients in long double.
*/
namespace pm {
namespace detail {
/* long double math for the templates (declared before they are) */
inline long double m_sin(long double x) { return __builtin_sinl(x); }
inline long double m_cos(long double x) { return __builtin_cosl(x); }
inline long double m_atan2(long double y, long double x) { return __builtin_atan2l(y, x); }
inline long double m_sqrt(long double x) { return __builtin_sqrtl(x); }
inline long double m_fabs(long double x) { return __builtin_fabsl(x); }
inline void sin_cos(long double x, long double *s, long double *c)
{
    *s = __builtin_sinl(x);
    *c = __builtin_cosl(x);
}
inline void sin_cos2(long double t, long double d, long double *st, long double *ct,
                     long double *sd, long double *cd)
{
    sin_cos(t, st, ct);
    sin_cos(d, sd, cd);
}
} /* namespace detail */
} /* namespace pm */

#include "../lib/pm_detail.hpp"

using namespace pm::detail;
typedef long double LD;

extern "C" {
void pm_test_sincos_d(double x, double *s, double *c) { sincos_d(x, s, c); }
void pm_test_sincos_d2(double x0, double x1, double *s0, double *c0, double *s1, double *c1)
{
    sincos_d2(x0, x1, s0, c0, s1, c1);
}

/* The forward model of a prepared model at encoder (t, d), in long double:
** the apparent angles (T in (-pi, pi], D). */
static void iso_ld(const pm_model *m, Iso<LD> *ko)
{
    Iso<LD> &k = *ko;
    LD a = m->coef[0], b = m->coef[1], th2 = a * a + b * b, th = m_sqrt(th2);
    LD A = th > 0 ? m_sin(th) / th : 1, B = th > 0 ? (1 - m_cos(th)) / th2 : 0.5L;
    LD K[9] = {0, 0, b, 0, 0, -a, -b, a, 0}, W[3] = {a, b, 0};
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            k.h[3 * r + c] =
                (r == c ? 1 : 0) + A * K[3 * r + c] + B * (W[r] * W[c] - (r == c ? th2 : 0));
    sin_cos((LD)m->coef[2], &k.sc, &k.cc);
    sin_cos((LD)m->coef[3], &k.sd, &k.cd);
    sin_cos((LD)m->coef[4], &k.se, &k.ce);
    sin_cos((LD)m->coef[5], &k.si, &k.ci);
}

void pm_test_apply_ld(const pm_model *m, const pm_context *ctx, double t, double d,
                      long double *T, long double *D)
{
    Iso<LD> k;
    iso_ld(m, &k);
    Trig<LD> g = trig_of<LD>(t, d);
    V3<LD> p = forward_vec<LD>(m, k, g, ctx);
    *T = m_atan2(p.y, p.x);
    *D = m_atan2(p.z, m_sqrt(p.x * p.x + p.y * p.y));
}

/* The anisotropic displacement D at encoder (t, d) in long double (the
** model's constants recomputed, as pm_test_apply_ld). */
void pm_test_aniso_ld(const pm_model *m, const pm_context *ctx, long double t, long double d,
                      long double D[2])
{
    Iso<LD> k;
    iso_ld(m, &k);
    aniso<LD>(m, k, trig_of<LD>(t, d), ctx, &D[0], &D[1]);
}

/* The inverse's analytic Jacobian (aniso_jac, double): D and J = dD/d(t, d)
** (J[0] = d Dt/dt, J[1] = d Dt/dd, J[2] = d Dd/dt, J[3] = d Dd/dd). */
void pm_test_aniso_jac(const pm_model *m, const pm_context *ctx, double t, double d,
                       double D[2], double J[4])
{
    aniso_jac(m, iso_of(m), trig_of<double>(t, d), ctx, &D[0], &D[1], J);
}
}
