/*
** bench/inv_floor.c - the numbers behind the stateless inverse's floor
** (docs/performance.md, "Where the stateless inverse's time goes"): for the
** bench's model of order 2 (bench_input_make) the rigorous bounds the
** inverse certifies with (pm_model.lip, .lip2), the anisotropic
** displacement |D| at the bench's 256 positions (the full model against its
** isotropic part), the real |J| = |dD/d(t, d)| there by finite differences
** (Frobenius norm; D as the offset in hour angle times cos dec and in dec),
** and lip2 |D|^2 / 2, what a Newton step from D^ = 0 is certified to miss.
**
**   make build/bench/pminv_floor && build/bench/pminv_floor
*/
#include <math.h>
#include <stdio.h>

#include "bench_common.h"
#include "pm.h"

/* The offset (hour angle times cos dec, dec) of model m from model iso at
** encoder (eh, ed). */
static void offset(const pm_model *m, const pm_model *iso, double eh, double ed, double D[2])
{
    double a1, d1, a0, d0;
    pm_model_apply(m, 0, eh, ed, &a1, &d1);
    pm_model_apply(iso, 0, eh, ed, &a0, &d0);
    D[0] = remainder(a1 - a0, 2 * M_PI) * cos(d0);
    D[1] = d1 - d0;
}

int main(void)
{
    static bench_input in;
    static pm_model iso;
    const double h = 1e-6;
    double s2 = 0, dmax = 0, jsum = 0, jmax = 0, rms;
    int i, k;
    if (bench_input_make(&in, 2) != 0)
        return 1;
    iso = in.m;
    for (k = 6; k < iso.n_terms; k++)
        iso.coef[k] = 0;
    if (pm_model_prepare(&iso) != PM_OK)
        return 1;
    for (i = 0; i < BENCH_NPOS; i++) {
        double D0[2], Dt[2], Dd[2], J[4], r, jn;
        offset(&in.m, &iso, in.eh[i], in.ed[i], D0);
        offset(&in.m, &iso, in.eh[i] + h, in.ed[i], Dt);
        offset(&in.m, &iso, in.eh[i], in.ed[i] + h, Dd);
        r = sqrt(D0[0] * D0[0] + D0[1] * D0[1]);
        s2 += r * r;
        dmax = r > dmax ? r : dmax;
        J[0] = (Dt[0] - D0[0]) / h;
        J[1] = (Dd[0] - D0[0]) / h;
        J[2] = (Dt[1] - D0[1]) / h;
        J[3] = (Dd[1] - D0[1]) / h;
        jn = sqrt(J[0] * J[0] + J[1] * J[1] + J[2] * J[2] + J[3] * J[3]);
        jsum += jn;
        jmax = jn > jmax ? jn : jmax;
    }
    rms = sqrt(s2 / BENCH_NPOS);
    printf("lip %.4g, lip2 %.4g (pm_model, the bounds the inverse certifies with)\n", in.m.lip,
           in.m.lip2);
    printf("|J| real (finite differences): mean %.3g, max %.3g\n", jsum / BENCH_NPOS, jmax);
    printf("|D|: rms %.3g rad (%.1f arcsec), max %.3g rad\n", rms, rms * 206264.806, dmax);
    printf("lip2 |D|^2 / 2 at the rms |D|: %.3g rad (PM_INVERT_TOL / 2 = %.3g)\n",
           in.m.lip2 * rms * rms / 2, PM_INVERT_TOL / 2);
    return 0;
}
