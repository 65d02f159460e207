/* Drives examples/fit_and_apply.c with a synthetic run (used by `make test`). */
#include <math.h>
#include <stdio.h>
#include "pm.h"
int fit_and_point(long n, const double *, const double *, const double *, const double *);
int main(void)
{
    static double eh[400], ed[400], ah[400], ad[400];
    pm_model truth;
    long i;
    pm_model_init(&truth, PM_MOUNT_EQUATORIAL, 1);
    truth.coef[2] = 0.08; truth.coef[4] = -0.01; truth.coef[5] = 3e-4; truth.coef[8] = 1e-4;
    pm_model_prepare(&truth);
    for (i = 0; i < 400; i++) {
        eh[i] = -1.5 + 3.0 * (double)(i % 20) / 19.0;
        ed[i] = -0.5 + 1.9 * (double)(i / 20) / 19.0;
        pm_model_apply(&truth, NULL, eh[i], ed[i], &ah[i], &ad[i]);
    }
    return fit_and_point(400, eh, ed, ah, ad) == 0 ? 0 : 1;
}
