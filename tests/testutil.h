/*
**  testutil.h - helpers shared by the Check suites: a seeded random
**  generator, angular distance, and a simulated pointing run.
*/
#ifndef PM_TESTUTIL_H
#define PM_TESTUTIL_H

#include <math.h>
#include <stdlib.h>
#include "pm.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define ARCSEC (M_PI / 648000.0)
#define DEG (M_PI / 180.0)

/* xorshift64*: deterministic across platforms, unlike rand(). */
typedef struct tu_rng {
    unsigned long long s;
} tu_rng;

static inline void tu_seed(tu_rng *r, unsigned long long seed)
{
    r->s = seed * 2685821657736338717ULL + 0x9E3779B97F4A7C15ULL;
    if (!r->s)
        r->s = 1;
}

/* uniform in [0, 1) */
static inline double tu_uniform(tu_rng *r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return (double)((r->s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

static inline double tu_gauss(tu_rng *r)
{
    double u = tu_uniform(r), v = tu_uniform(r);
    if (u < 1e-300)
        u = 1e-300;
    return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

/* Angle between two (ha, dec) directions (radians), accurate when small. */
static inline double tu_angle(double t1, double d1, double t2, double d2)
{
    double a[3], b[3], c[3], s, cs;
    a[0] = cos(d1) * cos(t1); a[1] = cos(d1) * sin(t1); a[2] = sin(d1);
    b[0] = cos(d2) * cos(t2); b[1] = cos(d2) * sin(t2); b[2] = sin(d2);
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
    s = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    cs = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return atan2(s, cs);
}

/* A simulated run: n encoder positions spread over the sky above an
** elevation limit (equatorial mount at latitude lat; a fraction of the
** points flipped over the pole), apparent positions from the true model
** plus isotropic Gaussian noise of noise_rad per axis on the sky. */
typedef struct tu_run {
    long n;
    double *eh, *ed, *ah, *ad;
} tu_run;

static inline void tu_run_free(tu_run *r)
{
    free(r->eh);
    free(r->ed);
    free(r->ah);
    free(r->ad);
    r->eh = r->ed = r->ah = r->ad = 0;
    r->n = 0;
}

/* Whole-sphere sampling when lat is NaN, else above 10 deg elevation. */
static inline int tu_simulate(tu_run *run, const pm_model *truth, long n, double lat,
                       double flip_fraction, double noise_rad,
                       unsigned long long seed)
{
    tu_rng r;
    long i;
    tu_seed(&r, seed);
    run->n = n;
    run->eh = (double *)malloc((size_t)n * sizeof(double));
    run->ed = (double *)malloc((size_t)n * sizeof(double));
    run->ah = (double *)malloc((size_t)n * sizeof(double));
    run->ad = (double *)malloc((size_t)n * sizeof(double));
    if (!run->eh || !run->ed || !run->ah || !run->ad)
        return -1;
    for (i = 0; i < n; i++) {
        double t, d, T, D, alt;
        do {
            t = (2.0 * tu_uniform(&r) - 1.0) * M_PI;
            d = asin(2.0 * tu_uniform(&r) - 1.0);
            alt = lat == lat
                      ? asin(sin(lat) * sin(d) + cos(lat) * cos(d) * cos(t))
                      : 1.0;
        } while (alt < 10.0 * DEG);
        if (tu_uniform(&r) < flip_fraction) {
            t = t + M_PI;
            d = M_PI - d;
        }
        if (pm_model_apply(truth, NULL, t, d, &T, &D) != PM_OK)
            return -1;
        D += noise_rad * tu_gauss(&r);
        T += noise_rad * tu_gauss(&r) / cos(D);
        if (D > M_PI / 2) D = M_PI - D, T += M_PI;
        if (D < -M_PI / 2) D = -M_PI - D, T += M_PI;
        run->eh[i] = t;
        run->ed[i] = d;
        run->ah[i] = T;
        run->ad[i] = D;
    }
    return 0;
}

/* Data directory for the real runs (../shared/data), or NULL if absent. */
static inline const char *tu_data_dir(void)
{
    const char *d = getenv("PM_DATA_DIR");
    return d && *d ? d : 0;
}

#endif
