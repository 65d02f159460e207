/*
**  bench_common.h - what the host bench (bench_host.c) and the Cortex-M
**  bench (bench_cm.c) share: the models and positions they evaluate, the
**  evaluations behind one interface (so a float build slots in as one more
**  bench_api), and the list of cases.
*/
#ifndef PM_BENCH_COMMON_H
#define PM_BENCH_COMMON_H

#include "pm.h"

/* Positions per batch: every case runs over the same BENCH_NPOS encoder
** positions (and the apparent positions they point at). */
#define BENCH_NPOS 256

/* Orders measured. */
#define BENCH_NORDERS 4
extern const int bench_orders[BENCH_NORDERS]; /* 0, 1, 2, 4 */

/* One evaluation of the model, in some precision.  The adapters take and
** return doubles; a float build converts at the boundary (which is what a
** controller holding its targets in double would do). */
typedef struct bench_api {
    const char *prec; /* "double", "float" */
    /* build the evaluation's model from a prepared pm_model; 0 on success */
    int (*load)(int slot, const pm_model *m);
    int (*apply)(int slot, double eh, double ed, double *ah, double *ad);
    int (*invert)(int slot, double ah, double ad, double *eh, double *ed);
    int (*invert_near)(int slot, double ah, double ad, double sh, double sd,
                       double *eh, double *ed);
    /* pm_track_start and pm_model_track, or their float build's, on the
    ** state at t (a pm_track or a pm_track_f) */
    int (*track_start)(void *t, double eh, double ed);
    int (*track)(int slot, void *t, double ah, double ad, double *eh, double *ed);
} bench_api;

/* The double API of include/pm.h and its float build (pm_model_f); a
** further build is one more bench_api and its entry in bench_apis[]. */
extern const bench_api bench_api_double;
extern const bench_api bench_api_float;
extern const bench_api *const bench_apis[];
extern const int bench_n_apis;

/* Inputs of one order: the model and the positions. */
typedef struct bench_input {
    pm_model m;
    double eh[BENCH_NPOS], ed[BENCH_NPOS]; /* encoder positions */
    double ah[BENCH_NPOS], ad[BENCH_NPOS]; /* where they point (apply) */
    double sh[BENCH_NPOS], sd[BENCH_NPOS]; /* previous tick's encoders */
} bench_input;

/* A realistic model of order L: the isotropic terms of the bundled
** example run (c' = 1200", e' = -420", a = 95", b = -140", d = 35",
** i = -50"), every harmonic term random with an rms of 15"; encoder
** positions over the sky (hour angle all round, declination -50..85 deg,
** normal pier side), deterministic (the same on every machine).
** Returns 0, or -1 if the library refuses the model. */
int bench_input_make(bench_input *in, int order);

/* Operations. */
enum {
    BENCH_EMPTY,     /* an empty function of the same shape: the loop's cost */
    BENCH_FWD,       /* pm_model_apply */
    BENCH_INV,       /* pm_model_invert (side given) */
    BENCH_INV_NEAR,  /* pm_model_invert_near (tracking: from the last tick) */
    BENCH_NAIVE_FWD, /* the paper's formulas as written (naive.h) */
    BENCH_NAIVE_INV, /* the paper's inverse: the same with -coefficients */
    BENCH_TRACK10,   /* pm_model_track, ticks of 0.1 s (bench_run) */
    BENCH_TRACK1K,   /* pm_model_track, ticks of 1 ms */
    /* the tracking ops' loops with an empty call of the same shape: the
    ** loop's cost, which there includes the target's arithmetic (each
    ** tick's hour angle, in double: emulated on an FPU without double) */
    BENCH_EMPTY_TRACK10,
    BENCH_EMPTY_TRACK1K,
    BENCH_NOPS
};
extern const char *const bench_op_name[BENCH_NOPS];

/* The op whose cost is op's loop (BENCH_EMPTY, or the tracking ops'
** empty loops); op itself for those. */
int bench_loop_op(int op);

/* Whether api has operation op (the naive ones: the double API only). */
int bench_op_supported(const bench_api *api, int op);

/* Run operation op of api over the n first positions of in (slot: the
** api's model slot loaded from in->m); returns the number of calls that
** did not return PM_OK (0 expected).  The results go to *sink. */
int bench_run(const bench_api *api, int slot, int op, const bench_input *in,
              int n, volatile double *sink);

/* "<target>_<op>_L<order>_<prec>" into buf. */
void bench_case_name(char *buf, int len, const char *target, int op, int order,
                     const char *prec);

#endif
