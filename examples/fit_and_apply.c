/* Fit an L=1 model to observations held in arrays, then correct a target.
** Build and run, with the synthetic run of examples/fit_and_apply_main.c:
**   cc -std=c89 -Iinclude examples/fit_and_apply.c examples/fit_and_apply_main.c \
**      build/libpm.a -lm -o fit_and_apply && ./fit_and_apply */
#include <stdio.h>
#include "pm.h"

static pm_fit fit;                     /* ~150 KB at PM_MAX_L=4: static, not stack */

int fit_and_point(long n, const double *enc_ha, const double *enc_dec,
                  const double *app_ha, const double *app_dec)
{
    pm_model m;
    pm_fit_result res;
    double ha, dec;
    pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1);              /* the paper's L=1: 22 terms */
    if (pm_fit_run(&fit, &m, NULL, n, enc_ha, enc_dec, app_ha, app_dec, 20, &res) != PM_OK)
        return -1;                                           /* fit.bad_term names a bad term */
    printf("sigma = %.2f arcsec\n", res.sigma * 206264.8);
    if (pm_model_invert(&m, NULL, 0.3, 0.8, PM_SIDE_NORMAL, &ha, &dec) < 0)  /* slew target */
        return -1;
    printf("point the encoders at ha=%.6f dec=%.6f rad\n", ha, dec);
    return 0;
}
