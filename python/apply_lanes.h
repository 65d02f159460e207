/*
**  apply_lanes.h - the Python package's vectorised pm_model_apply
**  (apply_simd.hpp), built three times: 2 lanes (SSE2, any x86-64:
**  apply_w2.cpp), 4 lanes (AVX2, apply_w4.cpp, compiled with -mavx2) and 8
**  lanes (AVX-512F, apply_w8.cpp, compiled with -mavx512f); call a width
**  only up to pm_apply_lanes_max().  On other machines each runs the scalar
**  call per point.
*/
#ifndef PM_APPLY_LANES_H
#define PM_APPLY_LANES_H
#include "pm.h"

/* Can the lanes take this model (else call pm_model_apply per point):
** prepared and not stale, no context inputs, only the base terms, |c'| and
** |e'| <= 0.5, order 0..4. */
bool pm_apply_lanes_ok(const pm_model *m);

/* pm_model_apply(m, NULL, ha[i], dec[i], &oa[i], &ob[i]) for i = 0..n-1,
** 2 or 4 points at a time, bit for bit the same doubles; returns the index
** of the first point whose call fails (its status in *st; later points may
** have been written), else -1.  m must pass pm_apply_lanes_ok. */
long pm_apply_lanes2(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st);
long pm_apply_lanes4(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st);
long pm_apply_lanes8(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st);

/* The widest this machine runs: 8 with AVX-512F, 4 with AVX2, 2 with SSE2,
** 1 elsewhere (the scalar call). */
int pm_apply_lanes_max(void);
#endif
