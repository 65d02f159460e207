/*
**  apply_lanes.h - the Python package's vectorised pm_model_apply: the
**  forward model on several points at once, one per lane of a vector
**  (apply_simd.hpp), bit for bit the scalar call's doubles.  Built for
**  x86-64 three times: SSE2 (apply_w2.cpp, any x86-64), AVX2 (apply_w4.cpp,
**  compiled with -mavx2) and AVX-512F (apply_w8.cpp, -mavx512f), each as
**  one vector and as two side by side ("x2": two independent chains, which
**  the core's long dependency chain rewards: docs/python.md, "Speed").
**  A path runs only where pm_lanes_runs says so (the CPU and the OS have
**  its instructions); elsewhere (other machines) only the scalar path.
*/
#ifndef PM_APPLY_LANES_H
#define PM_APPLY_LANES_H
#include "pm.h"

enum pm_lanes_path {
    PM_LANES_SCALAR,   /* pm_model_apply per point */
    PM_LANES_SSE2,     /* 2 points per step */
    PM_LANES_SSE2X2,   /* 4: two SSE2 vectors */
    PM_LANES_AVX2,     /* 4 */
    PM_LANES_AVX2X2,   /* 8: two AVX2 vectors */
    PM_LANES_AVX512,   /* 8 */
    PM_LANES_AVX512X2, /* 16: two AVX-512 vectors */
    PM_LANES_N_PATHS
};

/* The path's name ("scalar", "sse2", "sse2x2", "avx2", ...), or 0. */
const char *pm_lanes_name(int path);

/* Does this machine run the path (its CPU and OS; the build has it). */
bool pm_lanes_runs(int path);

/* The fastest path this machine runs: the widest, two vectors side by side
** (bench/bench_python.py measures each). */
int pm_lanes_best(void);

/* Can the lanes take this model (else call pm_model_apply per point):
** prepared and not stale, no context inputs, only the base terms, |c'| and
** |e'| <= 0.5, order 0..4. */
bool pm_apply_lanes_ok(const pm_model *m);

/* pm_model_apply(m, NULL, ha[i], dec[i], &oa[i], &ob[i]) for i = 0..n-1 on
** the path (one pm_lanes_runs allows; m passing pm_apply_lanes_ok, else
** only PM_LANES_SCALAR), the same doubles bit for bit.  Returns the index
** of the first point whose call fails (its status in *st; later points may
** have been written), else -1. */
long pm_apply_lanes(int path, const pm_model *m, long n, const double *ha, const double *dec,
                    double *oa, double *ob, pm_status *st);

/* The paths of apply_w4.cpp and apply_w8.cpp (two: x2 != 0). */
long pm_apply_avx2(int x2, const pm_model *m, long n, const double *ha, const double *dec,
                   double *oa, double *ob, pm_status *st);
long pm_apply_avx512(int x2, const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st);
#endif
