/*
**  pm_detail.hpp - internals of the pointing-model core (freestanding C++).
**
**  Templates over the scalar type so that one source serves double and
**  (later) float builds.  No heap, no exceptions, no globals.
*/
#ifndef PM_DETAIL_HPP
#define PM_DETAIL_HPP

#include "pm.h"

namespace pm {
namespace detail {

/* Math through the compiler builtins: the library stays freestanding and
** the calls resolve to libm (or to instructions). */
/* A hook called once per model evaluation (aniso): nothing in the library;
** tests/check_bounded.c builds the core again with a counter here to check
** the evaluation bounds documented in include/pm.h. */
#ifndef PM_EVAL_PROBE
#define PM_EVAL_PROBE() ((void)0)
#endif

inline double m_sin(double x) { return __builtin_sin(x); }
inline double m_cos(double x) { return __builtin_cos(x); }
inline double m_atan2(double y, double x) { return __builtin_atan2(y, x); }
inline double m_sqrt(double x) { return __builtin_sqrt(x); }
inline double m_fabs(double x) { return __builtin_fabs(x); }
inline float m_sin(float x) { return __builtin_sinf(x); }
inline float m_cos(float x) { return __builtin_cosf(x); }
inline float m_atan2(float y, float x) { return __builtin_atan2f(y, x); }
inline float m_sqrt(float x) { return __builtin_sqrtf(x); }
inline float m_fabs(float x) { return __builtin_fabsf(x); }

/* The bit pattern of a double. */
inline unsigned long long bits_of(double x)
{
    unsigned long long u;
    __builtin_memcpy(&u, &x, sizeof u);
    return u;
}

/* Double-precision tests written on the bit pattern where double arithmetic
** is emulated (a Cortex-M4F: a libgcc compare costs ~100 instructions, the
** integer test a few); plain comparisons elsewhere.  Same answers. */
#if defined(__arm__) && !(defined(__ARM_FP) && (__ARM_FP & 8))
#define PM_SOFT_DOUBLE 1
#else
#define PM_SOFT_DOUBLE 0
#endif

/* v in decimal at out ('-' first where negative; at most 20 characters
** for any 64-bit long, no NUL): the count written.  (No printf in the
** core: pm_term_name.) */
inline int format_long(long v, char *out)
{
    unsigned long u = v < 0 ? 0UL - (unsigned long)v : (unsigned long)v;
    char d[24];
    int nd = 0, n = 0;
    do {
        d[nd++] = (char)('0' + u % 10);
        u /= 10;
    } while (u > 0);
    if (v < 0)
        out[n++] = '-';
    while (nd > 0)
        out[n++] = d[--nd];
    return n;
}

/* A model's shape and terms as pm_model_prepare accepts them (needs_ctx
** as it sets it): what the entries outside the evaluation's hot path
** (pm_model_f_prepare, the fit's) check, so that a term changed after
** pm_model_prepare is never read out of bounds there (model.cpp). */
bool terms_intact(const pm_model *m);

/* x finite (not NaN, not +-inf). */
inline bool finite(double x)
{
#if PM_SOFT_DOUBLE
    return (bits_of(x) & 0x7ff0000000000000ULL) != 0x7ff0000000000000ULL;
#else
    return x - x == 0.0;
#endif
}

/* !(|a| <= b): |a| beyond b, or a NaN; for b >= 0, not NaN.  (Non-negative
** doubles are ordered as their bit patterns.) */
inline bool abs_beyond(double a, double b)
{
#if PM_SOFT_DOUBLE
    return (bits_of(a) & 0x7fffffffffffffffULL) > bits_of(b);
#else
    return !(m_fabs(a) <= b);
#endif
}

/* A tracking state (pm_track, pm_track_f) started at (h, d) with its
** magic number: PM_OK, PM_ERR_ARG (no state, or beyond PM_START_MAX) or
** PM_ERR_NONFINITE; the state untouched on error. */
template <typename S> inline pm_status start_state(S *t, double h, double d, int magic)
{
    if (!t)
        return PM_ERR_ARG;
    if (!finite(h) || !finite(d))
        return PM_ERR_NONFINITE;
    if (abs_beyond(h, PM_START_MAX) || abs_beyond(d, PM_START_MAX))
        return PM_ERR_ARG;
    __builtin_memset(t, 0, sizeof *t);
    t->enc[0] = h;
    t->enc[1] = d;
    t->magic = magic;
    return PM_OK;
}

/* a == b for b not NaN and not zero (one bit pattern each). */
inline bool same_as(double a, double b)
{
#if PM_SOFT_DOUBLE
    return bits_of(a) == bits_of(b);
#else
    return a == b;
#endif
}

/* x < 0, for x not NaN. */
inline bool below0(double x)
{
#if PM_SOFT_DOUBLE
    return bits_of(x) > 0x8000000000000000ULL;
#else
    return x < 0;
#endif
}

/* x > 0, for x not NaN. */
inline bool above0(double x)
{
#if PM_SOFT_DOUBLE
    return (long long)bits_of(x) > 0;
#else
    return x > 0;
#endif
}

const double PI = 3.14159265358979323846;
const double DBL_EPS = 2.220446049250313e-16; /* 2^-52 */
/* pi/2 in three parts (Cody & Waite): PIO2_1 and PIO2_2 have 33
** significant bits (k times them is exact for |k| < 2^20), PIO2_1 + PIO2_2 +
** PIO2_3 is pi/2 to 1e-37 (tests/ref/sincos_split.py) */
const double PIO2_1 = 1.5707963267341256, PIO2_2 = 6.077100506303966e-11,
             PIO2_3 = 2.0222662487959506e-21;
/* (x + RND_INT) - RND_INT is x rounded to an integer, |x| < 2^51 (1.5 2^52) */
const double RND_INT = 6755399441055744.0;

/* x0 + atan(r) and x0 + asin(r) for |r| <= 0.01 by their series to r^9
** (the terms left out are below 1e-23): (x0 + r) and the series' tail,
** whose terms are formed side by side, six operations deep from r (the
** forward model's frame_angles, where the small x0 is added beside r
** instead of after the series).  Any arithmetic type (the Python lanes). */
template <typename T> inline T atan_plus(T x0, T r)
{
    const T r2 = r * r, r3 = r * r2, r4 = r2 * r2, r7 = r3 * r4;
    return (x0 + r) + (r3 * (-1.0 / 3 + r2 * (1.0 / 5)) + r7 * (-1.0 / 7 + r2 * (1.0 / 9)));
}
template <typename T> inline T asin_plus(T x0, T r)
{
    const T r2 = r * r, r3 = r * r2, r4 = r2 * r2, r7 = r3 * r4;
    return (x0 + r) +
           (r3 * (1.0 / 6 + r2 * (3.0 / 40)) + r7 * (5.0 / 112 + r2 * (35.0 / 1152)));
}

/* A double from its bit pattern. */
inline double of_bits(unsigned long long u)
{
    double x;
    __builtin_memcpy(&x, &u, sizeof x);
    return x;
}

/*
** sin and cos of a double |x| <= 64 (axis angles and targets; beyond, and
** where double arithmetic is emulated, libm), without libm.  The nearest
** multiple k pi/2 is taken off in three parts (PIO2_1..3; x - k PIO2_1 is
** exact by Sterbenz's lemma), keeping the rounding of the reduced angle
** r = rh + rl; the Taylor series to r^17 and r^18 on |r| <= pi/4
** (truncation below 1.2e-19 relative), the leading terms added last and
** the cosine's 1 - r^2/2 compensated; the quadrant chosen on the bit
** patterns (no branch to mispredict).  Within 1 ulp of the exact values
** (0.92 measured against long double on 4e6 angles; libm's 0.52;
** tests/check_internal.c checks).
*/
/* The core of sincos_d on doubles or (V) on SSE2 pairs of them, |x| <= 64:
** the sine sr and cosine cr of the reduced angle, and kr, whose low bits
** hold k (its ulp is 1). */
template <typename V> inline void sincos_core(V x, V *sr, V *cr, V *kr)
{
    *kr = x * 0.6366197723675814 + RND_INT;
    const V kd = *kr - RND_INT;
    const V a = x - kd * PIO2_1, b = kd * PIO2_2; /* exact */
    const V rh = a - b;
    const V rl = ((a - rh) - b) - kd * PIO2_3; /* a - b - rh exactly, as |a| >= |b| or a ~ b */
    const V r2 = rh * rh;
    /* the series by Estrin's scheme (pairs, then powers r^4, r^8): a third
    ** of Horner's dependency chain, which is the forward model's longest */
    const V r4 = r2 * r2, r8 = r4 * r4;
    const V ps = r2 * (((-1.0 / 6 + r2 * (1.0 / 120)) +
                        r4 * (-1.0 / 5040 + r2 * (1.0 / 362880))) +
                       r8 * ((-1.0 / 39916800 + r2 * (1.0 / 6227020800.0)) +
                             r4 * (-1.0 / 1307674368000.0 + r2 * (1.0 / 355687428096000.0))));
    const V pc = r4 * (((1.0 / 24 + r2 * (-1.0 / 720)) +
                        r4 * (1.0 / 40320 + r2 * (-1.0 / 3628800))) +
                       r8 * ((1.0 / 479001600 + r2 * (-1.0 / 87178291200.0)) +
                             r4 * (1.0 / 20922789888000.0 + r2 * (-1.0 / 6402373705728000.0))));
    *sr = rh + (rh * ps + rl); /* sin(rh + rl) = sin rh + rl cos rh */
    const V hz = 0.5 * r2, w = 1.0 - hz;
    *cr = w + (((1.0 - w) - hz) + (pc - rh * rl));
}

/* The quadrant, k mod 4 in the low bits of q: (sin, cos) = (sr, cr), (cr,
** -sr), (-sr, -cr), (-cr, sr), chosen on the bit patterns bs, bc of sr and
** cr (U: a 64-bit integer or an SSE2 pair of them). */
template <typename U> inline void quadrant(U q, U bs, U bc, U *us, U *uc)
{
    const U sw = (q ^ q) - (q & 1); /* all ones where k is odd */
    *us = ((bs & ~sw) | (bc & sw)) ^ ((q & 2) << 62);
    *uc = ((bc & ~sw) | (bs & sw)) ^ (((q + 1) & 2) << 62);
}

inline void sincos_d(double x, double *s, double *c)
{
#if !PM_SOFT_DOUBLE
    if (m_fabs(x) <= 64.0) {
        double sr, cr, kr;
        unsigned long long us, uc;
        sincos_core(x, &sr, &cr, &kr);
        quadrant(bits_of(kr), bits_of(sr), bits_of(cr), &us, &uc);
        *s = of_bits(us);
        *c = of_bits(uc);
        return;
    }
#endif
    *s = m_sin(x);
    *c = m_cos(x);
}

/* sincos_d of two angles, one after the other (kept out of line: the
** rare path of sincos_d2 on x86-64). */
__attribute__((noinline, cold)) inline void sincos_d_each(double x0, double x1, double *s0,
                                                          double *c0, double *s1, double *c1)
{
    sincos_d(x0, s0, c0);
    sincos_d(x1, s1, c1);
}

/* sincos_d of two angles at once: the same operations in the two lanes of
** a vector where the machine has them (x86-64's SSE2: half the
** instructions), else one after the other.  Same results. */
inline void sincos_d2(double x0, double x1, double *s0, double *c0, double *s1, double *c1)
{
#if defined(__SSE2__) && !PM_SOFT_DOUBLE
    if (m_fabs(x0) <= 64.0 && m_fabs(x1) <= 64.0) {
        typedef double v2d __attribute__((vector_size(16)));
        typedef unsigned long long v2u __attribute__((vector_size(16)));
        const v2d x = {x0, x1};
        v2d sr, cr, kr;
        v2u us, uc;
        sincos_core(x, &sr, &cr, &kr);
        quadrant((v2u)kr, (v2u)sr, (v2u)cr, &us, &uc);
        const v2d vs = (v2d)us, vc = (v2d)uc;
        *s0 = vs[0];
        *s1 = vs[1];
        *c0 = vc[0];
        *c1 = vc[1];
        return;
    }
    sincos_d_each(x0, x1, s0, c0, s1, c1);
#else
    sincos_d(x0, s0, c0);
    sincos_d(x1, s1, c1);
#endif
}

template <typename T> struct V3 {
    T x, y, z;
};

template <typename T> inline V3<T> v3(T x, T y, T z)
{
    V3<T> r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}

template <typename T> inline T dot(const V3<T> &a, const V3<T> &b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <typename T> inline V3<T> cross(const V3<T> &a, const V3<T> &b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
              a.x * b.y - a.y * b.x);
}

/* Rotations of the model, written out (Pal et al. Sec. 2):
**   Pt(t) = Rz(t), Pd(d) = Ry(-d), X(d) = Rx(d), T(i) = Rz(i).
** s, c are the sine and cosine of the angle. */
template <typename T> inline V3<T> rot_z(T s, T c, const V3<T> &v)
{
    return v3(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
}
template <typename T> inline V3<T> rot_zt(T s, T c, const V3<T> &v)
{
    return v3(c * v.x + s * v.y, -s * v.x + c * v.y, v.z);
}
template <typename T> inline V3<T> rot_x(T s, T c, const V3<T> &v)
{
    return v3(v.x, c * v.y - s * v.z, s * v.y + c * v.z);
}
template <typename T> inline V3<T> rot_xt(T s, T c, const V3<T> &v)
{
    return v3(v.x, c * v.y + s * v.z, -s * v.y + c * v.z);
}
/* Pd(d) = Ry(-d): (x,y,z) -> (c x - s z, y, s x + c z). */
template <typename T> inline V3<T> rot_d(T s, T c, const V3<T> &v)
{
    return v3(c * v.x - s * v.z, v.y, s * v.x + c * v.z);
}
template <typename T> inline V3<T> rot_dt(T s, T c, const V3<T> &v)
{
    return v3(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}
template <typename T> inline V3<T> mat_mul(const T *h, const V3<T> &v)
{
    return v3(h[0] * v.x + h[1] * v.y + h[2] * v.z,
              h[3] * v.x + h[4] * v.y + h[5] * v.z,
              h[6] * v.x + h[7] * v.y + h[8] * v.z);
}
template <typename T> inline V3<T> mat_tmul(const T *h, const V3<T> &v)
{
    return v3(h[0] * v.x + h[3] * v.y + h[6] * v.z,
              h[1] * v.x + h[4] * v.y + h[7] * v.z,
              h[2] * v.x + h[5] * v.y + h[8] * v.z);
}

/* Sine and cosine of one encoder position, and the angles themselves when
** known (have_angles; the periodic terms need them). */
template <typename T> struct Trig {
    T st, ct; /* axis 1 */
    T sd, cd; /* axis 2 (cd signed: negative beyond the pole) */
    T t, d;   /* the angles, valid when have_angles */
    bool have_angles;
};

/* g with its angles (from its sines and cosines where g does not have them). */
template <typename T> inline Trig<T> with_angles(const Trig<T> &g)
{
    Trig<T> r = g;
    if (!r.have_angles) {
        r.t = m_atan2(r.st, r.ct);
        r.d = m_atan2(r.sd, r.cd);
        r.have_angles = true;
    }
    return r;
}

/*
** Raw harmonics: for j = l*l + l + m,
**   Y[j] = P_l^|m|(sin d) * (cos m t  if m >= 0,  sin |m| t  if m < 0)
** with P_l^m the associated Legendre function without the Condon-Shortley
** phase and with (1-x^2)^(m/2) taken as cos(d)^m (signed), so that
** Y(t+pi, pi-d) = Y(t, d) (Pal et al. Sec. 5.4).  The paper's normalisation
** multiplies by norm_lm() (folded into the coefficients).  Recurrences
** only: no trigonometric call.
**
** harmonics_n is the recurrence for order LC > 0 known at compile time
** (unrolled: no loop counters, the divisions by constants folded), or for
** the order Lrt (LC = 0).
*/
template <typename T, int LC> inline void harmonics_n(int Lrt, const Trig<T> &g, T *Y)
{
    const int L = LC > 0 ? LC : Lrt;
    T cm = 1, sm = 0;  /* cos(m t), sin(m t) */
    T pmm = 1;         /* P_m^m */
#pragma GCC unroll 16
    for (int m = 0; m <= L; m++) {
        if (m == 1) { /* (cos t, sin t) themselves: 1 * ct - 0 * st is two
                         ** operations on the chain the compiler may not fold */
            cm = g.ct;
            sm = g.st;
            pmm = g.cd;
        } else if (m > 1) {
            T c2 = cm * g.ct - sm * g.st;
            sm = sm * g.ct + cm * g.st;
            cm = c2;
            pmm = pmm * (T)(2 * m - 1) * g.cd;
        }
        T p2 = 0, p1 = pmm; /* P_{l-2}^m, P_{l-1}^m */
#pragma GCC unroll 16
        for (int l = m; l <= L; l++) {
            T p;
            if (l == m)
                p = pmm;
            else if (l == m + 1)
                p = (T)(2 * m + 1) * g.sd * pmm;
            else
                p = ((T)(2 * l - 1) * g.sd * p1 - (T)(l + m - 1) * p2) /
                    (T)(l - m);
            if (l > m) {
                p2 = p1;
                p1 = p;
            }
            int j = l * l + l;
            Y[j + m] = p * cm;
            if (m > 0)
                Y[j - m] = p * sm;
        }
    }
}


/* The raw harmonics up to order L (0..PM_MAX_L): orders 1..4 unrolled (the
** orders a mount model uses), beyond that the loops. */
template <typename T> inline void harmonics(int L, const Trig<T> &g, T *Y)
{
    switch (L) {
    case 0: Y[0] = 1; return;
    case 1: harmonics_n<T, 1>(1, g, Y); return;
#if PM_MAX_L >= 2
    case 2: harmonics_n<T, 2>(2, g, Y); return;
#endif
#if PM_MAX_L >= 3
    case 3: harmonics_n<T, 3>(3, g, Y); return;
#endif
#if PM_MAX_L >= 4
    case 4: harmonics_n<T, 4>(4, g, Y); return;
#endif
    default:
#if PM_MAX_L > 4
        harmonics_n<T, 0>(L, g, Y);
#endif
        return;
    }
}

/* The raw harmonics Y (the same operations as harmonics_n: the same bits)
** and their derivatives along the axes, Yt = dY/dt and Yd = dY/dd, for
** the inverse's Newton step (analytic Jacobian).  With Q_l^m the Legendre
** part, Y_{l,m} = Q cos(m t), Y_{l,-m} = Q sin(m t): Yt_{l,+-m} = -+m
** Y_{l,-+m}, and dQ/dd by the derivative of each recurrence step
** (d cos d = -sin d, d sin d = cos d). */
template <typename T, int LC>
inline void harmonics_jac_n(int Lrt, const Trig<T> &g, T *Y, T *Yt, T *Yd)
{
    const int L = LC > 0 ? LC : Lrt;
    T cm = 1, sm = 0;
    T pmm = 1, dpmm = 0; /* P_m^m and its derivative */
#pragma GCC unroll 16
    for (int m = 0; m <= L; m++) {
        if (m == 1) {
            cm = g.ct;
            sm = g.st;
            pmm = g.cd;
            dpmm = -g.sd;
        } else if (m > 1) {
            T c2 = cm * g.ct - sm * g.st;
            sm = sm * g.ct + cm * g.st;
            cm = c2;
            dpmm = (T)(2 * m - 1) * (dpmm * g.cd - pmm * g.sd);
            pmm = pmm * (T)(2 * m - 1) * g.cd;
        }
        T p2 = 0, p1 = pmm, d2 = 0, d1 = dpmm;
#pragma GCC unroll 16
        for (int l = m; l <= L; l++) {
            T p, dp;
            if (l == m) {
                p = pmm;
                dp = dpmm;
            } else if (l == m + 1) {
                p = (T)(2 * m + 1) * g.sd * pmm;
                dp = (T)(2 * m + 1) * (g.cd * pmm + g.sd * dpmm);
            } else {
                p = ((T)(2 * l - 1) * g.sd * p1 - (T)(l + m - 1) * p2) / (T)(l - m);
                dp = ((T)(2 * l - 1) * (g.cd * p1 + g.sd * d1) - (T)(l + m - 1) * d2) /
                     (T)(l - m);
            }
            if (l > m) {
                p2 = p1;
                p1 = p;
                d2 = d1;
                d1 = dp;
            }
            int j = l * l + l;
            Y[j + m] = p * cm;
            Yd[j + m] = dp * cm;
            Yt[j + m] = -(T)m * p * sm;
            if (m > 0) {
                Y[j - m] = p * sm;
                Yd[j - m] = dp * sm;
                Yt[j - m] = (T)m * p * cm;
            }
        }
    }
}

/* Normalisation N_lm reproducing the paper's Y_lm for l <= 2:
** 1/(2l-1)!! for m != 0 (so Y_ll = cos^l d cos l t), and for m = 0:
** 1 for l <= 1, 2 for l >= 2 (Y_20 = 3 sin^2 d - 1). */
inline double norm_lm(int l, int m)
{
    if (m == 0)
        return l >= 2 ? 2.0 : 1.0;
    double f = 1.0;
    for (int k = 2 * l - 1; k > 1; k -= 2)
        f *= (double)k;
    return 1.0 / f;
}

/* Tangent-plane components (along increasing axis 1 on the sky, along
** increasing axis 2) of the paper's base vectors p_k at (t, d):
**   p1 = x^p = (-sd ct, st)    p2 = y^p = (-sd st, -ct)    p3 = z^p = (cd, 0)
**   p4 = (-sd, 0)              p5 = (0, -1)                p6 = (1, 0)
** (Pal et al. Eq. tdvectexpansion, projected on e_t = (-st, ct, 0) and
** e_d = (-sd ct, -sd st, cd)).  A model evaluates them at the index-shifted
** position (t + c', d - e'), the mechanical axis angles (docs/model.md,
** "The anisotropic terms: at the mechanical position"). */
template <typename T>
inline void base_uv(int k, const Trig<T> &g, T *u, T *v)
{
    switch (k) {
    case 1: *u = -g.sd * g.ct; *v = g.st; break;
    case 2: *u = -g.sd * g.st; *v = -g.ct; break;
    case 3: *u = g.cd; *v = 0; break;
    case 4: *u = -g.sd; *v = 0; break;
    case 5: *u = 0; *v = -1; break;
    default: *u = 1; *v = 0; break;
    }
}

/* Unit vector displaced from (1,0,0) by the tangent offset (a, b) along y
** and z: the exponential map.  Series below 1e-2 (error < 1e-15). */
/* expmap(a, b) = (c, a s, b s): c = cos r and s = sin(r)/r, r^2 = a^2 +
** b^2. */
template <typename T> __attribute__((always_inline)) inline void expmap_cs(T a, T b, T *c, T *s)
{
    T r2 = a * a + b * b;
    if (r2 < (T)1e-4) {
        /* (by the reciprocals: no division; the r^4 part beside the
        ** leading terms, so that the chain is short: it is on the
        ** inverse's iteration path) */
        T r4 = r2 * r2;
        *c = (1 - (T)0.5 * r2) + r4 * ((T)(1.0 / 24) - r2 * (T)(1.0 / 720));
        *s = (1 - (T)(1.0 / 6) * r2) + r4 * ((T)(1.0 / 120) - r2 * (T)(1.0 / 5040));
    } else {
        T r = m_sqrt(r2);
        *c = m_cos(r);
        *s = m_sin(r) / r;
    }
}
template <typename T> inline V3<T> expmap(T a, T b)
{
    T c, s;
    expmap_cs<T>(a, b, &c, &s);
    return v3(c, a * s, b * s);
}

/* rot_z(si, ci, expmap(a, b)) for the inverse's iteration, whose chain
** runs through the y-component: in the series case y = si c + ci a s
** summed by powers of r^2 (c, s as in expmap), two operations shorter. */
template <typename T> inline V3<T> expmap_z(T si, T ci, T a, T b)
{
    V3<T> v = rot_z<T>(si, ci, expmap<T>(a, b));
    T r2 = a * a + b * b;
    if (r2 < (T)1e-4) {
        T A = ci * a, r4 = r2 * r2;
        v.y = ((si + A) - r2 * (si * (T)0.5 + A * (T)(1.0 / 6))) +
              (r4 * (si * (T)(1.0 / 24) + A * (T)(1.0 / 120)) -
               (r2 * r4) * (si * (T)(1.0 / 720) + A * (T)(1.0 / 5040)));
    }
    return v;
}

/* Inverse of expmap: tangent offset of unit vector q as seen from (1,0,0). */
template <typename T> inline void logmap(const V3<T> &q, T *a, T *b)
{
    T s2 = q.y * q.y + q.z * q.z;
    T f;
    if (s2 < (T)1e-4 && q.x > 0) {
        /* theta/sin(theta) as a series in sin^2 */
        f = 1 + s2 * ((T)(1.0 / 6) + s2 * ((T)(3.0 / 40) + s2 * (T)(5.0 / 112)));
    } else {
        T s = m_sqrt(s2);
        f = s > 0 ? m_atan2(s, q.x) / s : (T)1;
    }
    *a = q.y * f;
    *b = q.z * f;
}

/* Wrap an angle into (-pi, pi]. */
inline double wrap_pi(double a)
{
    if (!abs_beyond(a, PI)) /* |a| <= pi: the common case */
        return same_as(a, -PI) ? PI : a;
    if (a > 1e6 || a < -1e6) {
        /* far out, the remainder by the double 2 pi (off by 2.4e-16 per
        ** turn) would not be the angle libm's sin and cos see (the double
        ** build's targets go through them): reduce as they do */
        a = m_atan2(m_sin(a), m_cos(a));
        return a == -PI ? PI : a;
    }
    if (a > PI || a <= -PI) {
        /* one remainder, not a loop: bounded time for any finite a */
        a = __builtin_fmod(a, 2 * PI); /* |a| < 2 pi, the sign of a */
        if (a > PI)
            a -= 2 * PI;
        else if (a <= -PI)
            a += 2 * PI;
    }
    return a;
}

/* The turn an inverse returns its angles on: within pi of the start
** position when there is one; else the hour angle in (-pi, pi] and the
** declination within pi of e' (side +1) or e' + pi (side -1), so that
** enc_dec - e' is in [-pi/2, pi/2] on the normal side and in
** (pi/2, 3pi/2) beyond the pole (pm.h).  Iterations keep their trial
** points on this turn too: periodic terms of non-integer G read the raw
** angles, so a point and its copy a turn away are different positions. */
inline void turn_of(const double *start, int side, double e, double ref[2])
{
    if (start) {
        ref[0] = start[0];
        ref[1] = start[1];
    } else {
        ref[0] = 0;
        ref[1] = side > 0 ? e : e + PI;
    }
}

/* Angles (t, d) on the turn of ref (turn_of): each within pi of it.
** Angles already there are left as they are (bit for bit: the inverse
** checks its round trip at the angles it returns). */
inline void finish_angles(const double ref[2], double *t, double *d)
{
    double a = *t - ref[0], b = *d - ref[1];
    if (abs_beyond(a, PI) || same_as(a, -PI)) /* not in (-pi, pi] */
        *t = ref[0] + wrap_pi(a);
    if (abs_beyond(b, PI) || same_as(b, -PI))
        *d = ref[1] + wrap_pi(b);
}


/* The coefficient check in Thumb-2 assembly (coef_changed): on the
** M-profile cores with Thumb-2 (Armv7-M, Armv7E-M, Armv8-M and Armv8.1-M
** mainline; ACLE's profile 'M' with __thumb2__: not Armv6-M or Armv8-M
** baseline, whose ldm takes low registers only), unless PM_LDM_COMPARE is
** defined 0.  (By ACLE's macros: clang names Armv8.1-M's architecture
** macro apart, __ARM_ARCH_8_1M_MAIN__, where gcc 12 says 8M_MAIN.) */
#ifndef PM_LDM_COMPARE
#if defined(__thumb2__) && defined(__GNUC__) && defined(__ARM_ARCH_PROFILE) && \
    __ARM_ARCH_PROFILE == 'M'
#define PM_LDM_COMPARE 1
#else
#define PM_LDM_COMPARE 0
#endif
#endif

/* Is the model prepared, with a term count it can evaluate (model_ready's
** first part: what makes an evaluation safe to run). */
__attribute__((always_inline)) inline pm_status model_shape(const pm_model *m)
{
    if (!m)
        return PM_ERR_ARG;
    if (m->prepared != 1 || m->n_terms < 6 || m->n_terms > PM_MAX_TERMS)
        return PM_ERR_STATE;
    return PM_OK;
}

/* Has a coefficient of a model that passed model_shape changed since
** pm_model_prepare (model_ready's second part)? */
__attribute__((always_inline)) inline bool coef_changed(const pm_model *m)
{
#if PM_LDM_COMPARE
    /* M-profile Thumb-2 (Armv7-M, Armv8-M and 8.1-M mainline): gcc loads
    ** the words one by one (ldr, 19 instructions per two coefficients);
    ** here two coefficients of each array per ldm, 12 instructions per
    ** two (docs/performance.md, "The coefficient check on Armv7-M").
    ** Registers named so that ldm's lists ascend.  Left out: r7 (Thumb's
    ** frame pointer) and r9, the AAPCS platform register, which firmware
    ** may reserve (-ffixed-r9: gcc would let the assembly overwrite it
    ** unannounced) or make the PIC base (-msingle-pic-base: gcc refuses
    ** the assembly); lr is clobbered instead.  The arrays are read
    ** through a "memory" clobber, not "m" operands, whose addresses would
    ** take two more registers: at -O0 only r0-r3 (and r9 where it is
    ** free) are left for the four operands. */
    typedef unsigned long __attribute__((may_alias)) word; /* 32 bits */
    const word *a = (const word *)m->coef;
    const word *b = (const word *)m->prep_coef;
    const word *end = a + 4 * (m->n_terms / 2); /* n_terms >= 6: one pair at least */
    unsigned long acc = 0;
    __asm__("1:\n\t"
            "ldmia %[a]!, {r4, r5, r6, r8}\n\t"
            "ldmia %[b]!, {r10, r11, r12, lr}\n\t"
            "eor r4, r4, r10\n\t"
            "eor r5, r5, r11\n\t"
            "eor r6, r6, r12\n\t"
            "eor r8, r8, lr\n\t"
            "orr r4, r4, r5\n\t"
            "orr r6, r6, r8\n\t"
            "orr %[acc], %[acc], r4\n\t"
            "orr %[acc], %[acc], r6\n\t"
            "cmp %[a], %[end]\n\t"
            "bne 1b"
            : [a] "+&r"(a), [b] "+&r"(b), [acc] "+&r"(acc)
            : [end] "r"(end)
            : "r4", "r5", "r6", "r8", "r10", "r11", "r12", "lr", "cc", "memory");
    if (m->n_terms & 1) /* the last coefficient, after the pairs */
        acc |= (a[0] ^ b[0]) | (a[1] ^ b[1]);
    return acc != 0;
#else
    /* Bit patterns XOR-ed and OR-ed together in the machine's words (two
    ** per double on a 32-bit core; two doubles per SSE2 register), four at
    ** a time, no early exit.  (Bitwise, so writing -0.0 over 0.0 also asks
    ** for pm_model_prepare.) */
#if defined(__SSE2__)
    typedef unsigned long long __attribute__((vector_size(16), aligned(8), may_alias)) word;
#else
    typedef unsigned long __attribute__((may_alias)) word; /* 32 bits on ARM EABI, 64 on LP64 */
#endif
    const word *a = (const word *)m->coef;
    const word *b = (const word *)m->prep_coef;
    const int n = m->n_terms * (int)sizeof(double) / (int)sizeof(word); /* whole words */
    word acc0 = a[0] ^ b[0], acc1 = acc0, acc2 = acc0, acc3 = acc0; /* n_terms >= 6 */
    int i = 1;
    for (; i + 4 <= n; i += 4) {
        acc0 |= a[i] ^ b[i];
        acc1 |= a[i + 1] ^ b[i + 1];
        acc2 |= a[i + 2] ^ b[i + 2];
        acc3 |= a[i + 3] ^ b[i + 3];
    }
    for (; i < n; i++)
        acc0 |= a[i] ^ b[i];
    acc0 |= acc1 | acc2 | acc3;
#if defined(__SSE2__)
    unsigned long long any = acc0[0] | acc0[1];
    if (m->n_terms & 1) /* the last double, outside the whole words */
        any |= bits_of(m->coef[m->n_terms - 1]) ^ bits_of(m->prep_coef[m->n_terms - 1]);
#else
    word any = acc0;
#endif
    return any != 0;
#endif /* PM_LDM_COMPARE */
}

/* Is the model ready for evaluation: prepared, and no coefficient changed
** since (a stale model would be silently wrong). */
inline pm_status model_ready(const pm_model *m)
{
    const pm_status st = model_shape(m);
    if (st != PM_OK)
        return st;
    return coef_changed(m) ? PM_ERR_STATE : PM_OK;
}

/* Model constants in working precision. */
template <typename T> struct __attribute__((may_alias)) Iso {
    T h[9];
    T sc, cc, se, ce, sd, cd, si, ci;
};

/* The double constants in place: pm_model holds them in Iso<double>'s
** layout (checked here), so the double build reads them without a copy. */
inline const Iso<double> &iso_of(const pm_model *m)
{
    static_assert(__builtin_offsetof(pm_model, ci) - __builtin_offsetof(pm_model, h) ==
                      __builtin_offsetof(Iso<double>, ci),
                  "pm_model's h..ci must match Iso<double>");
    return *reinterpret_cast<const Iso<double> *>(m->h);
}

template <typename T> inline void iso_from_model(const pm_model *m, Iso<T> *o)
{
    for (int i = 0; i < 9; i++)
        o->h[i] = (T)m->h[i];
    o->sc = (T)m->sc;
    o->cc = (T)m->cc;
    o->se = (T)m->se;
    o->ce = (T)m->ce;
    o->sd = (T)m->sd;
    o->cd = (T)m->cd;
    o->si = (T)m->si;
    o->ci = (T)m->ci;
}

/* sin/cos of axis angles shifted by the index terms. */
template <typename T>
inline void shifted(const Iso<T> &k, const Trig<T> &g, T *stp, T *ctp, T *sdp,
                    T *cdp)
{
    *stp = g.st * k.cc + g.ct * k.sc; /* t' = t + c' */
    *ctp = g.ct * k.cc - g.st * k.sc;
    *sdp = g.sd * k.ce - g.cd * k.se; /* d' = d - e' */
    *cdp = g.cd * k.ce + g.sd * k.se;
}

/* x^n for integer n >= 0 by squaring. */
template <typename T> inline T ipow(T x, long n)
{
    T r = 1;
    while (n > 0) {
        if (n & 1)
            r *= x;
        x *= x;
        n >>= 1;
    }
    return r;
}

/* What the added (non-base) terms need at one position: the pier side, the
** zenith in the transported frame, the angles. */
template <typename T> struct Site {
    int side;        /* +1 normal side, -1 beyond the pole */
    bool have_zenith;
    T zx, zy, zz;    /* M^T Z: zx = sin(el), (zy, zz) toward the zenith */
    Trig<T> gs;      /* the shifted position (t + c', d - e'), where the
                        harmonics and base vectors are */
};

template <typename T>
inline Site<T> site_of(const pm_model *m, const Iso<T> &k, const Trig<T> &g,
                       const pm_context *ctx)
{
    Site<T> s;
    T stp, ctp, sdp, cdp;
    shifted<T>(k, g, &stp, &ctp, &sdp, &cdp);
    s.gs.st = stp;
    s.gs.ct = ctp;
    s.gs.sd = sdp;
    s.gs.cd = cdp;
    s.gs.t = s.gs.d = 0;
    s.gs.have_angles = false;
    s.side = ctx && ctx->pier ? (ctx->pier > 0 ? 1 : -1) : (cdp >= 0 ? 1 : -1);
    s.have_zenith = false;
    s.zx = s.zy = s.zz = 0;
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_ZENITH) {
            V3<T> z = m->mount == PM_MOUNT_ALTAZ
                          ? v3<T>(0, 0, 1)
                          : v3<T>((T)m_cos(m->latitude), 0,
                                  (T)m_sin(m->latitude));
            z = mat_tmul<T>(k.h, z);
            z = rot_zt<T>(stp, ctp, z);
            z = rot_xt<T>(k.sd, k.cd, z);
            z = rot_dt<T>(sdp, cdp, z);
            z = rot_zt<T>(k.si, k.ci, z);
            s.zx = z.x;
            s.zy = z.y;
            s.zz = z.z;
            s.have_zenith = true;
            break;
        }
    return s;
}

/* Value of the input of an AUX term (finite inputs are checked by the
** callers). */
inline double aux_input(const pm_context *ctx, int aux)
{
    switch (aux) {
    case PM_AUX_TEMP: return ctx->temp_c;
    case PM_AUX_TIME: return ctx->time_h;
    case PM_AUX_DIR: return (double)ctx->dir;
    default: return ctx->aux[aux - PM_AUX_USER];
    }
}

/* Does the context carry what the model's AUX terms read, finite, and a
** slew direction of +1, -1 or 0 where one is read (a raw velocity or step
** count there had scaled the hysteresis term silently: dir 3, three times
** the term; an outside probe)?  (For pm_model and pm_model_f alike.) */
template <typename M> inline pm_status context_ok(const M *m, const pm_context *ctx)
{
    if (!m->needs_ctx)
        return PM_OK;
    if (!ctx)
        return PM_ERR_ARG;
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_AUX) {
            double x = aux_input(ctx, m->term[i].aux);
            if (!finite(x))
                return PM_ERR_NONFINITE;
            if (m->term[i].aux == PM_AUX_DIR && (ctx->dir < -1 || ctx->dir > 1))
                return PM_ERR_ARG;
        }
    return PM_OK;
}

/* Ready for an evaluation with this context: model_ready, then context_ok. */
inline pm_status eval_ready(const pm_model *m, const pm_context *ctx)
{
    pm_status st = model_ready(m);
    return st != PM_OK ? st : context_ok(m, ctx);
}

/* The factor f of an added term t at position g (its displacement is f
** times its base vector), or false for the zenith terms (whose direction
** is their own) and a term of the other pier side (f = 0). */
template <typename T>
inline bool term_factor(const pm_term &t, const Trig<T> &g, const Site<T> &s,
                        const pm_context *ctx, T *fo)
{
    *fo = 0;
    if ((t.side && t.side != s.side) || t.kind == PM_TERM_ZENITH)
        return false;
    T f = 0;
    switch (t.kind) {
    case PM_TERM_SH: { /* at the mechanical position, as the base terms */
        T Y[PM_N_HARM(PM_MAX_L)] = {};
        harmonics<T>(t.l, s.gs, Y);
        f = Y[t.l * t.l + t.l + t.m] * (T)norm_lm(t.l, t.m);
        break;
    }
    case PM_TERM_FOURIER: {
        T a = (T)t.param * (t.l == 1 ? g.t : g.d);
        f = t.m ? m_sin(a) : m_cos(a);
        break;
    }
    case PM_TERM_SECTORAL: {
        long G = (long)t.param;
        T a = (T)G * g.t;
        f = ipow<T>(g.cd, G) * (t.m ? m_sin(a) : m_cos(a));
        break;
    }
    case PM_TERM_AUX:
        f = (T)(aux_input(ctx, t.aux) - t.param);
        break;
    default:
        return false;
    }
    *fo = f;
    return true;
}

/* Displacement per unit coefficient of an added term t at position g; its
** base vector and a harmonic factor at the shifted position s.gs (the
** mechanical axis angles, docs/model.md), a periodic or sectoral factor of the encoder angles (a
** gear turns with its encoder). */
template <typename T>
inline void term_uv(const pm_term &t, const Trig<T> &g, const Site<T> &s,
                    const pm_context *ctx, T *u, T *v)
{
    *u = 0;
    *v = 0;
    if (t.side && t.side != s.side)
        return;
    if (t.kind == PM_TERM_ZENITH) {
        if (t.l == 0) { /* cot(el) along the unit vector to the zenith */
            T sel = s.zx > (T)0.01 ? s.zx : (T)0.01;
            *u = s.zy / sel;
            *v = s.zz / sel;
        } else { /* cos(el) along it */
            *u = s.zy;
            *v = s.zz;
        }
        return;
    }
    T f, bu, bv;
    if (!term_factor<T>(t, g, s, ctx, &f))
        return;
    base_uv<T>(t.k, s.gs, &bu, &bv);
    *u = f * bu;
    *v = f * bv;
}

/* S[k] = sum over the harmonics j = 1..N-1 of dense[j][k] Y[j], in the
** order of j (N = (L+1)^2; LC > 0: unrolled). */
template <typename T, typename W, int LC> struct HarmSums {
    static void sum(int N, const W (*dense)[6], const T *Y, T *S)
    {
        /* (assigned, not zeroed and added: the same sums, and no memset
        ** call from the compiler on some cores; summed in locals and
        ** stored once: S may alias dense as far as the compiler knows, and
        ** would otherwise be stored after every product) */
        T acc[6];
#pragma GCC unroll 6
        for (int kk = 0; kk < 6; kk++)
            acc[kk] = (T)dense[1][kk] * Y[1];
#pragma GCC unroll 32
        for (int j = 2; j < N; j++) {
            const T y = Y[j];
#pragma GCC unroll 6
            for (int kk = 0; kk < 6; kk++)
                acc[kk] += (T)dense[j][kk] * y;
        }
#pragma GCC unroll 6
        for (int kk = 0; kk < 6; kk++)
            S[kk] = acc[kk];
    }
};

#if defined(__SSE2__) && !PM_SOFT_DOUBLE && !defined(PM_SCALAR_SUMS)
/* Doubles on x86-64: the six sums as three pairs in SSE2 registers (half
** the instructions), the odd and even harmonics summed apart (so the
** sums round differently from the scalar version's, by an ulp). */
template <int LC> struct HarmSums<double, double, LC> {
    static void sum(int N, const double (*dense)[6], const double *Y, double *S)
    {
        typedef double v2d __attribute__((vector_size(16)));
        typedef double __attribute__((vector_size(16), aligned(8), may_alias)) v2u;
        const v2u *r = (const v2u *)dense[1];
        v2d y = {Y[1], Y[1]};
        v2d s0 = r[0] * y, s1 = r[1] * y, s2 = r[2] * y;
        /* the odd and the even harmonics apart, added at the end: half the
        ** dependency chain (the inverse iterates on it) */
        v2d t0 = {0, 0}, t1 = {0, 0}, t2 = {0, 0};
#pragma GCC unroll 32
        for (int j = 2; j < N; j++) {
            r = (const v2u *)dense[j];
            y = (v2d){Y[j], Y[j]};
            if (j & 1) {
                s0 += r[0] * y;
                s1 += r[1] * y;
                s2 += r[2] * y;
            } else {
                t0 += r[0] * y;
                t1 += r[1] * y;
                t2 += r[2] * y;
            }
        }
        s0 += t0;
        s1 += t1;
        s2 += t2;
        S[0] = s0[0];
        S[1] = s0[1];
        S[2] = s1[0];
        S[3] = s1[1];
        S[4] = s2[0];
        S[5] = s2[1];
    }
};
#endif

/* The harmonic sums of the base vectors at g: S[k] = sum over the harmonics
** j >= 1 of dense[j][k] Y_j (base vector k + 1), for order LC >= 1 (compile
** time, unrolled) or Lrt >= 1 (LC = 0).  W is the table's type (pm_model's
** double, pm_model_f's float). */
template <typename T, typename W, int LC>
inline void sh_sums_n(int Lrt, const Trig<T> &g, const W (*dense)[6], T *S)
{
    const int L = LC > 0 ? LC : Lrt;
    T Y[PM_N_HARM(LC > 0 ? LC : PM_MAX_L)];
    harmonics_n<T, LC>(L, g, Y);
    HarmSums<T, W, LC>::sum((L + 1) * (L + 1), dense, Y, S);
}

/* The harmonic sums for order L (0..PM_MAX_L), dispatched as harmonics(). */
template <typename T, typename W>
inline void sh_sums(int L, const Trig<T> &g, const W (*dense)[6], T S[6])
{
    switch (L) {
    case 0:
        S[0] = S[1] = S[2] = S[3] = S[4] = S[5] = 0;
        return;
    case 1: sh_sums_n<T, W, 1>(1, g, dense, S); return;
#if PM_MAX_L >= 2
    case 2: sh_sums_n<T, W, 2>(2, g, dense, S); return;
#endif
#if PM_MAX_L >= 3
    case 3: sh_sums_n<T, W, 3>(3, g, dense, S); return;
#endif
#if PM_MAX_L >= 4
    case 4: sh_sums_n<T, W, 4>(4, g, dense, S); return;
#endif
    default:
#if PM_MAX_L > 4
        sh_sums_n<T, W, 0>(L, g, dense, S);
#else
        S[0] = S[1] = S[2] = S[3] = S[4] = S[5] = 0; /* (L is checked) */
#endif
        return;
    }
}

/* The harmonic sums (as sh_sums_n: the same bits) and their derivatives
** along the axes, St and Sd, for order LC >= 1 (compile time) or Lrt. */
template <typename T, int LC>
inline void sh_sums_jac_n(int Lrt, const Trig<T> &g, const double (*dense)[6], T *S, T *St,
                          T *Sd)
{
    const int L = LC > 0 ? LC : Lrt;
    T Y[PM_N_HARM(LC > 0 ? LC : PM_MAX_L)], Yt[PM_N_HARM(LC > 0 ? LC : PM_MAX_L)],
        Yd[PM_N_HARM(LC > 0 ? LC : PM_MAX_L)];
    harmonics_jac_n<T, LC>(L, g, Y, Yt, Yd);
#if defined(__SSE2__) && !PM_SOFT_DOUBLE && !defined(PM_SCALAR_SUMS)
    /* (SSE2: three sums of three register pairs each) */
    HarmSums<T, double, LC>::sum((L + 1) * (L + 1), dense, Y, S);
    HarmSums<T, double, LC>::sum((L + 1) * (L + 1), dense, Yt, St);
    HarmSums<T, double, LC>::sum((L + 1) * (L + 1), dense, Yd, Sd);
#else
    /* The three sums together, three base vectors at a time (each table
    ** entry loaded once; 9 sums, 3 harmonics and the entry fit the 16
    ** double registers of a Cortex-M7), S in the order of HarmSums::sum
    ** (the same bits).  St leaves out the harmonics of m = 0, whose Yt is
    ** zero. */
#pragma GCC unroll 2
    for (int h = 0; h < 6; h += 3) {
        T a[3], b[3], c[3];
#pragma GCC unroll 3
        for (int kk = 0; kk < 3; kk++) {
            const T w = (T)dense[1][h + kk];
            a[kk] = w * Y[1];
            b[kk] = w * Yt[1];
            c[kk] = w * Yd[1];
        }
#pragma GCC unroll 16
        for (int l = 1; l <= L; l++) {
#pragma GCC unroll 33
            for (int mm = -l; mm <= l; mm++) {
                const int j = l * l + l + mm;
                if (j < 2)
                    continue;
#pragma GCC unroll 3
                for (int kk = 0; kk < 3; kk++) {
                    const T w = (T)dense[j][h + kk];
                    a[kk] += w * Y[j];
                    if (mm != 0)
                        b[kk] += w * Yt[j];
                    c[kk] += w * Yd[j];
                }
            }
        }
#pragma GCC unroll 3
        for (int kk = 0; kk < 3; kk++) {
            S[h + kk] = a[kk];
            St[h + kk] = b[kk];
            Sd[h + kk] = c[kk];
        }
    }
#endif
}

/* sh_sums_jac_n for order L (0..PM_MAX_L), dispatched as sh_sums. */
template <typename T>
inline void sh_sums_jac(int L, const Trig<T> &g, const double (*dense)[6], T S[6], T St[6],
                        T Sd[6])
{
    switch (L) {
    case 0:
        for (int i = 0; i < 6; i++)
            S[i] = St[i] = Sd[i] = 0;
        return;
    case 1: sh_sums_jac_n<T, 1>(1, g, dense, S, St, Sd); return;
#if PM_MAX_L >= 2
    case 2: sh_sums_jac_n<T, 2>(2, g, dense, S, St, Sd); return;
#endif
#if PM_MAX_L >= 3
    case 3: sh_sums_jac_n<T, 3>(3, g, dense, S, St, Sd); return;
#endif
#if PM_MAX_L >= 4
    case 4: sh_sums_jac_n<T, 4>(4, g, dense, S, St, Sd); return;
#endif
    default:
#if PM_MAX_L > 4
        sh_sums_jac_n<T, 0>(L, g, dense, S, St, Sd);
#else
        for (int i = 0; i < 6; i++)
            S[i] = St[i] = Sd[i] = 0; /* (L is checked) */
#endif
        return;
    }
}

/* The index-shifted position (t + c', d - e') of encoder trig g0 as a Trig
** (sines and cosines only): from sh (sin t', cos t', sin d', cos d') when
** the caller has them, else computed. */
template <typename T>
__attribute__((always_inline)) inline Trig<T> shifted_trig(const Iso<T> &k, const Trig<T> &g0,
                                                           const T *sh)
{
    Trig<T> gs;
    if (sh) {
        gs.st = sh[0];
        gs.ct = sh[1];
        gs.sd = sh[2];
        gs.cd = sh[3];
    } else {
        shifted<T>(k, g0, &gs.st, &gs.ct, &gs.sd, &gs.cd);
    }
    gs.t = gs.d = 0;
    gs.have_angles = false;
    return gs;
}

/* Anisotropic displacement (tangent components in the transported frame)
** at encoder trig g0: the base harmonic terms with l >= 1 through the
** dense table, then the added terms; harmonics and base vectors at the
** index-shifted position gs (the mechanical axis angles). */
template <typename T>
__attribute__((always_inline)) inline void
aniso_of_sums(const pm_model *m, const Iso<T> &k, const Trig<T> &g0, const Trig<T> &gs,
              const pm_context *ctx, const T *S, T *dt, T *dd);

template <typename T>
inline void aniso(const pm_model *m, const Iso<T> &k, const Trig<T> &g0,
                  const pm_context *ctx, T *dt, T *dd, const T *sh = 0)
{
    PM_EVAL_PROBE();
    const Trig<T> gs = shifted_trig<T>(k, g0, sh);
    T S[6];
    sh_sums<T, double>(m->order, gs, m->dense, S);
    aniso_of_sums<T>(m, k, g0, gs, ctx, S, dt, dd);
}

/* The displacement from the harmonic sums S at gs: the projection on the
** base vectors (at gs), then the added terms (aniso and the inverse's
** aniso_jac: the same operations). */
template <typename T>
__attribute__((always_inline)) inline void
aniso_of_sums(const pm_model *m, const Iso<T> &k, const Trig<T> &g0, const Trig<T> &gs,
              const pm_context *ctx, const T *S, T *dt, T *dd)
{
    /* sum_k S_k (u_k, v_k), written out (the products of the position's
    ** trig formed beside the sums: a short chain after them) */
    const T sc = gs.sd * gs.ct, ss = gs.sd * gs.st;
    *dt = ((gs.cd * S[2] + S[5]) - sc * S[0]) - (ss * S[1] + gs.sd * S[3]);
    *dd = (S[0] * gs.st - S[4]) - S[1] * gs.ct;
    if (m->n_terms > m->n_base) {
        const Trig<T> g = with_angles(g0);
        Site<T> s = site_of<T>(m, k, g, ctx);
        for (int i = m->n_base; i < m->n_terms; i++) {
            T u, v;
            term_uv<T>(m->term[i], g, s, ctx, &u, &v);
            *dt += (T)m->coef[i] * u;
            *dd += (T)m->coef[i] * v;
        }
    }
}

/* Forward model as a unit vector: p' = H Pt(t') X(d) Pd(d') T(i) w; sh, if
** not null, receives the trig of the shifted position (t', d'): sin t',
** cos t', sin d', cos d'. */
template <typename T>
inline V3<T> forward_vec(const pm_model *m, const Iso<T> &k, const Trig<T> &g,
                         const pm_context *ctx, T *sh = 0)
{
    T dt, dd, stp, ctp, sdp, cdp;
    shifted<T>(k, g, &stp, &ctp, &sdp, &cdp);
    const T sg[4] = {stp, ctp, sdp, cdp};
    aniso<T>(m, k, g, ctx, &dt, &dd, sg);
    if (sh) {
        sh[0] = stp;
        sh[1] = ctp;
        sh[2] = sdp;
        sh[3] = cdp;
    }
    V3<T> w = expmap<T>(dt, dd);
    w = rot_z<T>(k.si, k.ci, w);
    w = rot_d<T>(sdp, cdp, w);
    w = rot_x<T>(k.sd, k.cd, w);
    w = rot_z<T>(stp, ctp, w);
    return mat_mul<T>(k.h, w);
}

/* pm_model_apply's rotations: composed beside the displacement
** (framed_rotations) where the core runs several instructions per cycle
** out of order and a shorter chain pays for ~80 more instructions; one
** after the other (forward_vec's five, as before) on 32-bit ARM (Cortex-M:
** in order, and counted in instructions).  Either way within about an ulp
** of each other.  With the composed rotations pm_model_apply also
** compares the coefficients with pm_model_prepare's copy after the sines
** and cosines instead of first (lib/model.cpp). */
#ifndef PM_COMPOSED_FORWARD
#if defined(__arm__)
#define PM_COMPOSED_FORWARD 0
#else
#define PM_COMPOSED_FORWARD 1
#endif
#endif
/* For pm_model_apply with the composed rotations: gcc's pairing of their
** scalar products into SSE2 registers costs more shuffles than it saves
** (1,021 host instructions per call at L = 2 with it, 981 without; the
** same operations, the same results). */
#if PM_COMPOSED_FORWARD && defined(__GNUC__) && !defined(__clang__)
#define PM_NO_SLP __attribute__((optimize("no-tree-slp-vectorize")))
#else
#define PM_NO_SLP
#endif

/* The forward model's rotations composed, seen from the shifted hour angle
** t' = t + c': F = Pt(t')^T H Pt(t') X(d) Pd(d') T(i) (row-major), so that
** Pt(t')^T p = F expmap(D).  F depends only on the shifted position's trig
** (stp, ctp, sdp, cdp) and the model's constants: it is formed beside the
** displacement, and one product with expmap(D) follows it (a short chain)
** instead of five rotations in a row. */
template <typename T>
__attribute__((always_inline)) inline void framed_rotations(const Iso<T> &k, T stp, T ctp,
                                                            T sdp, T cdp, T *F)
{
    /* B = X(d) Pd(d') T(i), written out (its columns: the three axes
    ** through T(i), Pd(d'), X(d)); nb1, nb2 = sdp, nb5: the negated
    ** entries, whose signs the sums below take */
    const T a0 = sdp * k.ci, a1 = sdp * k.si;
    const T b0 = cdp * k.ci, nb1 = cdp * k.si;
    const T b3 = k.cd * k.si - k.sd * a0, b4 = k.cd * k.ci + k.sd * a1, nb5 = k.sd * cdp;
    const T b6 = k.sd * k.si + k.cd * a0, b7 = k.sd * k.ci - k.cd * a1, b8 = k.cd * cdp;
    /* G = Pt(t')^T H Pt(t'): H's upper 2 x 2 block P turned, Q^T P Q =
    ** P + s E with c^2 = 1 - s^2 (E from P's difference and sum across),
    ** its third column and row turned once */
    const T *h = k.h;
    const T d04 = h[0] - h[4], s13 = h[1] + h[3];
    const T e0 = stp * (stp * d04 - ctp * s13), e1 = stp * (stp * s13 + ctp * d04);
    const T g0 = h[0] - e0, g4 = h[4] + e0, g1 = h[1] - e1, g3 = h[3] - e1;
    const T g2 = ctp * h[2] + stp * h[5], g5 = ctp * h[5] - stp * h[2];
    const T g6 = ctp * h[6] + stp * h[7], g7 = ctp * h[7] - stp * h[6], g8 = h[8];
    /* F = G B (row r: (g_r0 b_0c + g_r1 b_1c) + g_r2 b_2c) */
    F[0] = (g0 * b0 + g1 * b3) + g2 * b6;
    F[1] = (g1 * b4 - g0 * nb1) + g2 * b7;
    F[2] = g2 * b8 - (g0 * sdp + g1 * nb5);
    F[3] = (g3 * b0 + g4 * b3) + g5 * b6;
    F[4] = (g4 * b4 - g3 * nb1) + g5 * b7;
    F[5] = g5 * b8 - (g3 * sdp + g4 * nb5);
    F[6] = (g6 * b0 + g7 * b3) + g8 * b6;
    F[7] = (g7 * b4 - g6 * nb1) + g8 * b7;
    F[8] = g8 * b8 - (g6 * sdp + g7 * nb5);
}

/* F expmap(a, b) = c F0 + s (a F1 + b F2) (Fj: F's columns): a F1 + b F2
** is formed beside expmap's series, two operations follow it. */
template <typename T>
__attribute__((always_inline)) inline V3<T> framed_product(const T *F, T a, T b, T c, T s)
{
    const T u0 = F[1] * a + F[2] * b, u1 = F[4] * a + F[5] * b, u2 = F[7] * a + F[8] * b;
    return v3(c * F[0] + s * u0, c * F[3] + s * u1, c * F[6] + s * u2);
}
template <typename T>
__attribute__((always_inline)) inline V3<T> framed_apply(const T *F, T a, T b)
{
    T c, s;
    expmap_cs<T>(a, b, &c, &s);
    return framed_product<T>(F, a, b, c, s);
}

/* The forward model's unit vector seen from the shifted hour angle:
** Pt(t')^T p (p of forward_vec, the same model; the rotations composed by
** framed_rotations); sh receives the shifted position's trig as in
** forward_vec.  pm_model_apply's path (frame_angles), inlined there. */
template <typename T>
__attribute__((always_inline)) inline V3<T> forward_framed(const pm_model *m, const Iso<T> &k,
                                                           const Trig<T> &g,
                                                           const pm_context *ctx, T *sh)
{
    T dt, dd, stp, ctp, sdp, cdp, F[9];
    shifted<T>(k, g, &stp, &ctp, &sdp, &cdp);
    const T sg[4] = {stp, ctp, sdp, cdp};
    aniso<T>(m, k, g, ctx, &dt, &dd, sg);
    /* (after the call in the code, beside its chain in the core) */
    framed_rotations<T>(k, stp, ctp, sdp, cdp, F);
    sh[0] = stp;
    sh[1] = ctp;
    sh[2] = sdp;
    sh[3] = cdp;
    return framed_apply<T>(F, dt, dd);
}

/* The derivatives (ft, fd) along the axes of an added term's factor f at g
** (term_factor; f itself in *f): harmonic (at the shifted position gs, as
** term_factor), periodic, sectoral and AUX terms (AUX: constant). */
__attribute__((noinline)) inline void factor_jac(const pm_term &t, const Trig<double> &g,
                                                 const Trig<double> &gs, const pm_context *ctx,
                                                 double *f, double *ft, double *fd)
{
    *f = *ft = *fd = 0;
    switch (t.kind) {
    case PM_TERM_SH: {
        double Y[PM_N_HARM(PM_MAX_L)], Yt[PM_N_HARM(PM_MAX_L)], Yd[PM_N_HARM(PM_MAX_L)];
        const int j = t.l * t.l + t.l + t.m;
        const double nl = norm_lm(t.l, t.m);
        if (t.l == 0) {
            *f = nl;
            return;
        }
        harmonics_jac_n<double, 0>(t.l, gs, Y, Yt, Yd);
        *f = Y[j] * nl;
        *ft = Yt[j] * nl;
        *fd = Yd[j] * nl;
        return;
    }
    case PM_TERM_FOURIER: {
        const double G = t.param, a = G * (t.l == 1 ? g.t : g.d);
        const double sa = m_sin(a), ca = m_cos(a);
        *f = t.m ? sa : ca;
        const double df = G * (t.m ? ca : -sa);
        if (t.l == 1)
            *ft = df;
        else
            *fd = df;
        return;
    }
    case PM_TERM_SECTORAL: {
        const long G = (long)t.param;
        const double a = (double)G * g.t, sa = m_sin(a), ca = m_cos(a);
        const double p1 = ipow<double>(g.cd, G - 1), p = p1 * g.cd;
        const double tr = t.m ? sa : ca;
        *f = p * tr;
        *ft = p * (double)G * (t.m ? ca : -sa);
        *fd = (double)G * p1 * -g.sd * tr;
        return;
    }
    case PM_TERM_AUX:
        *f = aux_input(ctx, t.aux) - t.param;
        return;
    default:
        return;
    }
}

/* The zenith in the transported frame at g (site_of's (zx, zy, zz)) and
** its derivatives along the axes: M^T Z with M = H Pt(t') X Pd(d') T(i);
** d/dt' of Pt^T y is (y'_y, -y'_x, 0) and d/dd' of Pd^T y is (y'_z, 0,
** -y'_x), y' the rotated vector. */
__attribute__((noinline)) inline void zenith_jac(const pm_model *m, const Iso<double> &k, const Trig<double> &g, V3<double> *z,
                V3<double> *zt, V3<double> *zd)
{
    double stp, ctp, sdp, cdp;
    shifted<double>(k, g, &stp, &ctp, &sdp, &cdp);
    V3<double> y = m->mount == PM_MOUNT_ALTAZ
                       ? v3(0.0, 0.0, 1.0)
                       : v3(m_cos(m->latitude), 0.0, m_sin(m->latitude));
    y = rot_zt<double>(stp, ctp, mat_tmul<double>(k.h, y));
    V3<double> yt = v3(y.y, -y.x, 0.0);
    y = rot_dt<double>(sdp, cdp, rot_xt<double>(k.sd, k.cd, y));
    yt = rot_dt<double>(sdp, cdp, rot_xt<double>(k.sd, k.cd, yt));
    V3<double> yd = v3(y.z, 0.0, -y.x);
    *z = rot_zt<double>(k.si, k.ci, y);
    *zt = rot_zt<double>(k.si, k.ci, yt);
    *zd = rot_zt<double>(k.si, k.ci, yd);
}

/* The displacement D at g, bit for bit as aniso computes it, and its
** Jacobian: with shift_only false, J = dD/d(t, d) along the encoder angles
** (J[0] = d dt/dt, J[1] = d dt/dd, J[2] = d dd/dt, J[3] = d dd/dd),
** analytic for every term kind (a term of one pier side counts on the side
** g is on, its jump at the pole's edge aside); with shift_only true, the
** derivatives along the shifted position (t', d') alone, as the index terms
** c' and e' move it: what depends on the encoder angles themselves (the
** periodic and sectoral factors, the zenith terms, whose direction turns
** with the isotropic rotation and is the isotropic columns' business)
** held.  The harmonics and base vectors are functions of (t', d') = (t +
** c', d - e'), so they differentiate alike either way.  One model
** evaluation. */
inline void aniso_jac_at(const pm_model *m, const Iso<double> &k, const Trig<double> &g0,
                         const pm_context *ctx, bool shift_only, double *dt, double *dd,
                         double J[4])
{
    PM_EVAL_PROBE();
    const Trig<double> gs = shifted_trig<double>(k, g0, 0);
    double S[6], St[6], Sd[6];
    sh_sums_jac<double>(m->order, gs, m->dense, S, St, Sd);
    aniso_of_sums<double>(m, k, g0, gs, ctx, S, dt, dd);
    double zj[4] = {0, 0, 0, 0}; /* the zenith terms' part of J */
    if (m->n_terms > m->n_base) {
        /* the added terms: factor f times base vector k, so (f, ft, fd)
        ** join the harmonic sums of k (the J below differentiates the base
        ** vectors); the zenith terms apart */
        const Trig<double> g = with_angles(g0);
        Site<double> s = site_of<double>(m, k, g, ctx);
        V3<double> z, zt, zd;
        bool have_z = false;
        for (int i = m->n_base; i < m->n_terms; i++) {
            const pm_term &t = m->term[i];
            if (t.side && t.side != s.side)
                continue;
            if (t.kind == PM_TERM_ZENITH) {
                if (shift_only)
                    continue;
                if (!have_z) {
                    zenith_jac(m, k, g, &z, &zt, &zd);
                    have_z = true;
                }
                double ut, ud, vt, vd;
                if (t.l == 0) { /* (zy, zz) / max(zx, 0.01) */
                    const bool lo = !(z.x > 0.01);
                    const double sel = lo ? 0.01 : z.x;
                    const double u = z.y / sel, v = z.z / sel;
                    const double st_ = lo ? 0.0 : zt.x, sd_ = lo ? 0.0 : zd.x;
                    ut = (zt.y - u * st_) / sel;
                    ud = (zd.y - u * sd_) / sel;
                    vt = (zt.z - v * st_) / sel;
                    vd = (zd.z - v * sd_) / sel;
                } else {
                    ut = zt.y;
                    ud = zd.y;
                    vt = zt.z;
                    vd = zd.z;
                }
                zj[0] += m->coef[i] * ut;
                zj[1] += m->coef[i] * ud;
                zj[2] += m->coef[i] * vt;
                zj[3] += m->coef[i] * vd;
                continue;
            }
            double f, ft, fd;
            factor_jac(t, g, gs, ctx, &f, &ft, &fd);
            if (shift_only && t.kind != PM_TERM_SH)
                ft = fd = 0;
            S[t.k - 1] += m->coef[i] * f;
            St[t.k - 1] += m->coef[i] * ft;
            Sd[t.k - 1] += m->coef[i] * fd;
        }
    }
    const double stp = gs.st, ctp = gs.ct, sdp = gs.sd, cdp = gs.cd;
    /* dt = cdp S2 + S5 - sdp ctp S0 - sdp stp S1 - sdp S3, dd = stp S0 -
    ** S4 - ctp S1 (aniso_of_sums); d/dt turns (stp, ctp), d/dd (sdp,
    ** cdp) */
    J[0] = cdp * St[2] + St[5] - sdp * (ctp * St[0] - stp * S[0]) -
           sdp * (stp * St[1] + ctp * S[1]) - sdp * St[3] + zj[0];
    J[1] = -sdp * S[2] + cdp * Sd[2] + Sd[5] - cdp * (ctp * S[0] + stp * S[1]) -
           sdp * (ctp * Sd[0] + stp * Sd[1]) - cdp * S[3] - sdp * Sd[3] + zj[1];
    J[2] = ctp * S[0] + stp * St[0] - St[4] + stp * S[1] - ctp * St[1] + zj[2];
    J[3] = stp * Sd[0] - Sd[4] - ctp * Sd[1] + zj[3];
}

/* D and J = dD/d(t, d) (aniso_jac_at along the encoder angles): the
** inverse's Jacobian. */
inline void aniso_jac(const pm_model *m, const Iso<double> &k, const Trig<double> &g0,
                      const pm_context *ctx, double *dt, double *dd, double J[4])
{
    aniso_jac_at(m, k, g0, ctx, false, dt, dd, J);
}

/* sin and cos of one angle: sincos_d for doubles, libm for floats. */
inline void sin_cos(double x, double *s, double *c) { sincos_d(x, s, c); }
inline void sin_cos(float x, float *s, float *c)
{
    *s = m_sin(x);
    *c = m_cos(x);
}

/* sin and cos of two angles: sincos_d2 for doubles, libm for floats. */
inline void sin_cos2(double t, double d, double *st, double *ct, double *sd, double *cd)
{
    sincos_d2(t, d, st, ct, sd, cd);
}
inline void sin_cos2(float t, float d, float *st, float *ct, float *sd, float *cd)
{
    sin_cos(t, st, ct);
    sin_cos(d, sd, cd);
}

template <typename T> inline Trig<T> trig_of(T t, T d)
{
    Trig<T> g;
    sin_cos2(t, d, &g.st, &g.ct, &g.sd, &g.cd);
    g.t = t;
    g.d = d;
    g.have_angles = true;
    return g;
}

template <typename T> inline V3<T> unit_of(T t, T d)
{
    T st, ct, sd, cd;
    sin_cos2(t, d, &st, &ct, &sd, &cd);
    return v3(cd * ct, cd * st, sd);
}

/* Normalise (s, c) in place to a unit pair; returns false for (0,0). */
template <typename T> inline bool unit_pair(T *s, T *c)
{
    T r = m_sqrt(*s * *s + *c * *c);
    if (!(r > 0))
        return false;
    *s /= r;
    *c /= r;
    return true;
}

/* A target as the closed-form inverse reads it: q0 = H^T q, |q0_xy|^2 and
** its inverse, 1 / cos d (loop constants of the fixed point). */
template <typename T> struct Target {
    V3<T> q0;
    T rho2, irho2, icd;
    T sdq;  /* sin d q0_z */
    T P, Q; /* (q0_y cos c' - q0_x sin c', q0_x cos c' + q0_y sin c') / rho2 */
};

template <typename T> inline Target<T> target_of(const Iso<T> &k, const V3<T> &q)
{
    Target<T> o;
    o.q0 = mat_tmul<T>(k.h, q);
    o.rho2 = o.q0.x * o.q0.x + o.q0.y * o.q0.y;
    o.irho2 = o.rho2 > (T)1e-12 ? 1 / o.rho2 : 0; /* 0: normalise by unit_pair */
    o.icd = 1 / k.cd;
    o.sdq = k.sd * o.q0.z;
    o.P = (o.q0.y * k.cc - o.q0.x * k.sc) * o.irho2;
    o.Q = (o.q0.x * k.cc + o.q0.y * k.sc) * o.irho2;
    return o;
}

/*
** Closed-form inverse of the isotropic part for a fixed anisotropic
** displacement (dt, dd): the encoder trig g with
**   H Pt(t+c') X(d) Pd(d-e') T(i) expmap(dt, dd) = q.
** side: +1 normal branch, -1 beyond the pole.  Returns true if reachable;
** if not, the nearest reachable point (branch boundary) is returned.
*/
template <typename T>
inline bool iso_inverse_v(const Iso<T> &k, const Target<T> &tg, const V3<T> &v, int side,
                          Trig<T> *g);
template <typename T>
inline bool iso_inverse(const Iso<T> &k, const Target<T> &tg, T dt, T dd, int side,
                        Trig<T> *g)
{
    return iso_inverse_v<T>(k, tg, expmap_z<T>(k.si, k.ci, dt, dd), side, g);
}

/* The same for no displacement: expmap_z(si, ci, 0, 0) is (ci, si, 0)
** exactly (si + 0: the sign of its zero as there), without the series. */
template <typename T>
inline bool iso_inverse0(const Iso<T> &k, const Target<T> &tg, int side, Trig<T> *g)
{
    return iso_inverse_v<T>(k, tg, v3<T>(k.ci, k.si + (T)0, (T)0), side, g);
}

/* iso_inverse for the pointing v = T(i) expmap(dt, dd) (expmap_z). */
template <typename T>
inline bool iso_inverse_v(const Iso<T> &k, const Target<T> &tg, const V3<T> &v, int side,
                          Trig<T> *g)
{
    const V3<T> &q0 = tg.q0;
    /* With g = Pd(d') v and u = X(d) g: u_z = q0_z fixes g3, then u_y,
    ** and |u_xy| = |q0_xy| fixes g1 up to the side. */
    T g3 = (q0.z - k.sd * v.y) * tg.icd;
    /* uy = cd vy - sd g3 = (vy - sd q0_z) / cd: two operations after v.y
    ** (this is the iteration's critical path) */
    T uy = (v.y - tg.sdq) * tg.icd;
    T rho2 = tg.rho2;
    T disc = rho2 - uy * uy;
    bool ok = true, on_edge = false;
    if (disc < 0) {
        /* The target lies outside this branch's reach by about
        ** -disc / (2 |q0_xy|) radians; within rounding of the edge (the
        ** fold, where both branches meet) it is reached there. */
        T rho = m_sqrt(rho2) + (T)1e-300;
        if (-disc / (2 * rho) > (T)(PM_INVERT_TOL * 0.25))
            ok = false;
        disc = 0;
        on_edge = true;
    }
    T g1 = (T)side * m_sqrt(disc);
    T vxz = v.x * v.x + v.z * v.z;
    if (!on_edge && tg.irho2 > 0 && vxz > (T)1e-12) {
        /* The pairs below have known lengths: |g| = |u| = |q| = |v| = 1
        ** gives |(g1, g3)| = |(vx, vz)|, so |(sdp, cdp)| = vx^2 + vz^2, and
        ** g1^2 + uy^2 = rho2, so |(stp, ctp)| = rho2.  Normalised by them
        ** and turned back by the index shifts, written out: every factor
        ** but g1 is ready before the square root, so the iteration's
        ** chain ends two operations after it (no square root or division
        ** of its own; the pairs come out unit to rounding). */
        T f = 1 / vxz;
        T fU = f * (v.x * k.ce + v.z * k.se), fW = f * (v.x * k.se - v.z * k.ce);
        g->sd = g3 * fU + g1 * fW;
        g->cd = g1 * fU - g3 * fW;
        g->st = g1 * tg.P - uy * tg.Q;
        g->ct = g1 * tg.Q + uy * tg.P;
    } else {
        /* (g1 + i g3) = (vx + i vz) exp(i d'): d' = arg(g1 + i g3) - arg(v) */
        T sdp = g3 * v.x - g1 * v.z;
        T cdp = g1 * v.x + g3 * v.z;
        /* t' = arg(q0_xy) - arg(u_xy), u_x = g1 */
        T stp = q0.y * g1 - q0.x * uy;
        T ctp = q0.x * g1 + q0.y * uy;
        if (!unit_pair<T>(&sdp, &cdp)) {
            sdp = 0;
            cdp = 1;
        }
        if (!unit_pair<T>(&stp, &ctp)) {
            stp = 0;
            ctp = 1;
        }
        /* undo the index shifts: t = t' - c', d = d' + e' */
        g->st = stp * k.cc - ctp * k.sc;
        g->ct = ctp * k.cc + stp * k.sc;
        g->sd = sdp * k.ce + cdp * k.se;
        g->cd = cdp * k.ce - sdp * k.se;
    }
    g->t = g->d = 0;
    g->have_angles = false;
    return ok;
}

} /* namespace detail */
} /* namespace pm */

#endif
