/*
**  next_star.c - a mount controller choosing its own next calibration star
**  with the allocation-free scores of include/pm.h (docs/model.md, "Which
**  star next"): strict C89, no heap, nothing but the library.
**
**  After each star the controller refits (pm_fit_run), scores every
**  candidate it has not taken and slews to the best.  I-optimal: the fall
**  of the mean predicted variance over the caller's sky (pm_fit_point_gain).
**  D-optimal: the rise of log det of the information,
**  log det(I + V / s^2) with V the 2x2 covariance of the correction at the
**  candidate (pm_fit_pointing_sigma) and s the measurement noise
**  (res->sigma) -- the information a star adds is largest where the model
**  is least known relative to the noise.
**
**  tests/check_plan.c compiles this file with -std=c89 -pedantic -Werror
**  and drives a simulated mount with it.
*/
#include <math.h>

#include "pm.h"

/*
**  next_star - the best candidate to observe next.
**
**  Given:
**     fit, res, m   the last successful fit (pm_fit_run) and its model
**     ctx           inputs of the model's physical terms (or NULL)
**     cand          n_cand encoder positions (ha, dec pairs, radians)
**     taken         n_cand flags: nonzero for a candidate already observed
**     sky           n_sky encoder positions the error is averaged over
**                   (I-optimal only; may be NULL for D-optimal)
**     d_optimal     0: I-optimal, 1: D-optimal
**  Returned:
**     best          index of the best candidate (-1: none left)
**     score         its score (I: rad^2 of mean variance; D: log det rise)
**  Returned (function value):
**                   PM_OK, or the first error of a scoring call
*/
pm_status next_star(const pm_fit *fit, const pm_fit_result *res, const pm_model *m,
                    const pm_context *ctx, const double *cand, int n_cand,
                    const unsigned char *taken, const double *sky, int n_sky, int d_optimal,
                    int *best, double *score)
{
    int i;
    double s2 = res->sigma * res->sigma;
    *best = -1;
    *score = 0;
    for (i = 0; i < n_cand; i++) {
        double g, sigma, v[3];
        pm_status st;
        if (taken[i])
            continue;
        if (d_optimal) {
            st = pm_fit_pointing_sigma(fit, res, m, ctx, cand[2 * i], cand[2 * i + 1], &sigma, v);
            if (st != PM_OK)
                return st;
            /* det(I + V / s^2) of the 2x2 symmetric V */
            g = log((1 + v[0] / s2) * (1 + v[2] / s2) - v[1] * v[1] / (s2 * s2));
        } else {
            st = pm_fit_point_gain(fit, res, m, ctx, cand[2 * i], cand[2 * i + 1], sky, n_sky, &g);
            if (st != PM_OK)
                return st;
        }
        if (*best < 0 || g > *score) {
            *best = i;
            *score = g;
        }
    }
    return PM_OK;
}
