/*
**  dist.h - the inverse's cost as a distribution over situations (issue
**  18): which cases bench/bench_dist_host.c and bench/bench_dist_cm.c
**  measure, built the same way on every target (deterministic).
**
**  A situation is a set of coefficients, a mode and, for the realistic
**  sets, a band of distance from the mount's pole and a pier side:
**    set   bench   the model of bench_common.c (L = 2, the example run's
**                  isotropic terms, harmonic terms of 15" rms)
**          real    8 models of L = 2: every isotropic term uniform within
**                  +-10 deg, every harmonic term uniform within +-10'
**          hard    the adversarial cases of tests/check_bounded.c
**                  ("ordinary" scale: any order, every term kind, the
**                  celestial and the mount's poles, absurd starts)
**    mode  cold     pm_model_invert, the side of the true position
**          track10  pm_model_invert_near from the previous tick's
**                   solution, the target 0.1 s of sidereal motion on
**          track1k  the same, 1 ms on
**          near     (hard) pm_model_invert_near from check_bounded's starts
**    band  far (> 5 deg from the mount's pole), mid (0.5..5 deg), pole
**          (< 0.5 deg): the true encoder position's distance
**    side  normal, flipped (beyond the pole: a German mount after the
**          meridian flip); hour angles all round, across the meridian.
*/
#ifndef PM_BENCH_DIST_H
#define PM_BENCH_DIST_H

#include "pm.h"

/* Calls per situation. */
#ifndef DIST_N
#define DIST_N 256
#endif

enum { DIST_COLD, DIST_NEAR };

typedef struct dist_call {
    int model;      /* index into the situation's models */
    int op;         /* DIST_COLD or DIST_NEAR */
    int side;       /* PM_SIDE_* (cold) */
    int use_ctx;    /* pass ctx (else NULL) */
    pm_context ctx;
    double ah, ad;  /* target */
    double sh, sd;  /* start (near) */
    int have_tk;    /* tk: tracking situations (pm_model_track) */
    pm_track tk;    /* the loop's state at the tick before (a copy is used) */
} dist_call;

/* The builds a call can be run in: the double inverses, the float ones,
** and pm_model_track (double, from the loop's state: tracking situations
** of the bench and real sets only). */
#define DIST_NPREC 3
extern const char *const dist_prec_name[DIST_NPREC];

/* May call c run in precision prec?  (The float build refuses some of the
** hard models; only tracking calls have a state.) */
int dist_runnable(const dist_call *c, int prec, const int *have_f);

typedef struct dist_situation {
    char name[48];  /* "<set>_<mode>[_<band>_<side>]" */
    int set;        /* DIST_SET_* */
    int n_models;
    int bound;      /* evaluations the header promises for this mode */
    int n;          /* calls */
} dist_situation;

enum { DIST_SET_BENCH, DIST_SET_REAL, DIST_SET_HARD, DIST_NSETS };

/* Number of situations. */
int dist_count(void);

/* Describe situation s (0 <= s < dist_count()) and build its models and
** calls: models[] (room for DIST_MAX_MODELS), mf[] their float builds
** (have_f[j] = 0 where pm_model_f_prepare refused), calls[] (room for
** DIST_N).  Returns 0, or -1 if a model or a call could not be built. */
#define DIST_MAX_MODELS 64
int dist_make(int s, dist_situation *sit, pm_model *models, pm_model_f *mf, int *have_f,
              dist_call *calls);

/* Run one call in double (prec 0), float (prec 1) or by pm_model_track
** from a copy of its state (prec 2); returns the status. */
pm_status dist_run(int prec, const pm_model *models, const pm_model_f *mf,
                   const dist_call *c, double *eh, double *ed);

/* Order statistics of n values (sorted in place): median, p99, max. */
void dist_stats(double *v, int n, double *med, double *p99, double *worst);

#endif
