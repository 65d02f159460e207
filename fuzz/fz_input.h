/*
**  fz_input.h - what the fuzz harnesses share: a reader that turns the
**  fuzzer's bytes into choices (integers, doubles that include NaN, Inf,
**  huge and subnormal values), the failure report, and checks on statuses.
**
**  C99, header-only (static functions), so that the libFuzzer entry points
**  (fuzz/fuzz_*.c) and the regression test (tests/check_fuzz_regress.c,
**  which includes the harness sources) compile the same code.
*/
#ifndef PMFZ_INPUT_H
#define PMFZ_INPUT_H

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "pm.h"
#include "../tests/testutil.h"

/* The bytes still to be read.  Past the end every read gives 0. */
typedef struct pmfz_in {
    const unsigned char *p;
    size_t n;
} pmfz_in;

static inline void pmfz_init(pmfz_in *in, const unsigned char *data, size_t size)
{
    in->p = data;
    in->n = data ? size : 0;
}

static inline int pmfz_left(const pmfz_in *in) { return in->n > 0; }

static inline unsigned pmfz_u8(pmfz_in *in)
{
    if (!in->n)
        return 0;
    in->n--;
    return *in->p++;
}

static inline unsigned long long pmfz_u64(pmfz_in *in)
{
    unsigned long long v = 0;
    int i;
    for (i = 0; i < 8; i++)
        v = (v << 8) | pmfz_u8(in);
    return v;
}

/* An integer in lo..hi (inclusive; hi - lo < 65536). */
static inline int pmfz_range(pmfz_in *in, int lo, int hi)
{
    unsigned span = (unsigned)(hi - lo) + 1u;
    unsigned v = pmfz_u8(in);
    if (span > 256u)
        v = (v << 8) | pmfz_u8(in);
    return lo + (int)(v % span);
}

/* A uniform fraction in [0, 1) from two bytes. */
static inline double pmfz_unit(pmfz_in *in)
{
    unsigned v = pmfz_u8(in);
    v = (v << 8) | pmfz_u8(in);
    return (double)v / 65536.0;
}

/* Values that break numerical code. */
static inline double pmfz_special(unsigned i)
{
    static const double tab[] = {
        0.0, -0.0, 1.0, -1.0, 0.5, M_PI / 2, -M_PI / 2, M_PI, -M_PI, 2 * M_PI,
        M_PI / 2 + 1e-12, M_PI / 2 - 1e-12, 1e-300, 1e300, -1e300, 1e20,
        DBL_MAX, -DBL_MAX, DBL_MIN, 4.9406564584124654e-324, 1e-8, 1e-3, 0.1,
        3 * M_PI / 2
    };
    double inf = HUGE_VAL;
    switch (i % 27u) {
    case 24: return inf;
    case 25: return -inf;
    case 26: return nan("");
    default: return tab[i % 27u];
    }
}

/* Any double: a special value, the raw bits of 8 bytes (NaN payloads,
** subnormals, anything), or a plain number of either sign over 21 decades. */
static inline double pmfz_double(pmfz_in *in)
{
    unsigned sel = pmfz_u8(in);
    if (sel < 64)
        return pmfz_special(sel);
    if (sel < 96) {
        unsigned long long b = pmfz_u64(in);
        double d;
        memcpy(&d, &b, sizeof d);
        return d;
    }
    {
        double u = pmfz_unit(in) * 2 - 1;
        int e = (int)(sel % 21u) - 12; /* 1e-12 .. 1e8 */
        return u * pow(10.0, e);
    }
}

/* Mostly an ordinary angle in [-2pi, 2pi], sometimes any double. */
static inline double pmfz_angle(pmfz_in *in)
{
    unsigned sel = pmfz_u8(in);
    if (sel < 24)
        return pmfz_double(in);
    return (pmfz_unit(in) * 2 - 1) * 2 * M_PI + (double)(sel & 7u) * 1e-9;
}

/* Mostly a small coefficient (up to 0.05 rad), sometimes any double. */
static inline double pmfz_coef(pmfz_in *in)
{
    unsigned sel = pmfz_u8(in);
    if (sel < 24)
        return pmfz_double(in);
    if (sel < 40)
        return 0.0;
    return (pmfz_unit(in) * 2 - 1) * 0.05 * pow(10.0, -(double)(sel % 5u));
}

/* A context with random inputs, or NULL (one choice in four). */
static inline const pm_context *pmfz_context(pmfz_in *in, pm_context *c)
{
    int j;
    unsigned sel = pmfz_u8(in);
    if ((sel & 3u) == 0)
        return NULL;
    c->temp_c = (sel & 4u) ? pmfz_double(in) : pmfz_unit(in) * 40 - 10;
    c->time_h = (sel & 8u) ? pmfz_double(in) : pmfz_unit(in) * 24;
    c->pier = pmfz_range(in, -2, 2);
    c->dir = pmfz_range(in, -2, 2);
    for (j = 0; j < PM_MAX_AUX; j++)
        c->aux[j] = (sel & 16u) ? pmfz_double(in) : pmfz_unit(in);
    return c;
}

static inline int pmfz_finite(double x) { return x - x == 0.0; }

/* Report a broken invariant on stderr; returns 1 (the harness's result). */
static inline int pmfz_fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("pmfz: invariant violated: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return 1;
}

/* Is st one of the statuses in the list ("allowed" holds PM_* values,
** terminated by 99)? */
static inline int pmfz_status_in(pm_status st, const int *allowed)
{
    for (; *allowed != 99; allowed++)
        if ((int)st == *allowed)
            return 1;
    return 0;
}

/* Angle between two (axis 1, axis 2) directions, accurate when small: the
** test suites' tu_angle. */
#define pmfz_sep tu_angle


/* Plain evaluations: coefficients, displacements, angles and context
** inputs within the bounds below.  Everywhere the harnesses require
** documented statuses, no crash, hang, leak or undefined behaviour and
** every result property (round trips, sides, finite statistics); for
** plain evaluations they also refuse PM_ERR_NONFINITE, which the core may
** answer only where the terms overflow. */
#define PMFZ_SANE_COEF 0.5   /* radians, isotropic terms (real: < 0.1) */
#define PMFZ_SANE_ANISO 2e-3 /* radians, displacement of the others
                                (real: < 1e-3); cot(el) counts 100 times */
#define PMFZ_SANE_ANGLE 1e3  /* radians, and units of the AUX inputs */

/* Plain values: within the bounds above.  Outside them the core may
** answer PM_ERR_NONFINITE (the terms overflow), as documented. */
static inline int pmfz_plain_x(double x) { return fabs(x) <= PMFZ_SANE_ANGLE; }

/* Largest |coefficient| of the model: the first six (isotropic) or the
** others (anisotropic; cot(el) terms count 100 times). */
static inline double pmfz_max_coef(const pm_model *m, int aniso)
{
    int i;
    double mx = 0;
    for (i = aniso ? 6 : 0; i < (aniso ? m->n_terms : 6) && i < PM_MAX_TERMS; i++) {
        double c = fabs(m->coef[i]);
        if (i >= m->n_base && m->term[i].kind == PM_TERM_ZENITH && m->term[i].l == 0)
            c *= 100; /* cot(el), capped at el = 0.01 rad */
        if (!(c <= mx))
            mx = c;
    }
    return mx;
}

/* Are the model's coefficients and AUX displacements (for inputs up to
** PMFZ_SANE_ANGLE) plain? */
static inline int pmfz_plain_model(const pm_model *m)
{
    int i;
    if (!(pmfz_max_coef(m, 0) <= PMFZ_SANE_COEF) || !(pmfz_max_coef(m, 1) <= PMFZ_SANE_ANISO))
        return 0;
    for (i = 0; i < m->n_terms && i < PM_MAX_TERMS; i++)
        /* an AUX term displaces by coef * (input - param); the float build
        ** forms input - param in float, so a huge param overflows there
        ** even with a zero coefficient */
        if (i >= m->n_base && m->term[i].kind == PM_TERM_AUX &&
            (!(fabs(m->coef[i]) * (fabs(m->term[i].param) + PMFZ_SANE_ANGLE) <= PMFZ_SANE_ANISO) ||
             !(fabs(m->term[i].param) <= PMFZ_SANE_ANGLE)))
            return 0;
    return 1;
}

/* Are the context inputs plain (NULL: yes)? */
static inline int pmfz_plain_ctx(const pm_context *c)
{
    int j;
    if (!c)
        return 1;
    if (!pmfz_plain_x(c->temp_c) || !pmfz_plain_x(c->time_h))
        return 0;
    for (j = 0; j < PM_MAX_AUX; j++)
        if (!pmfz_plain_x(c->aux[j]))
            return 0;
    return 1;
}

#endif
