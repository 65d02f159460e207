/*
**  naive.h - the pointing model evaluated straight from the paper's
**  formulas, for comparison (bench only; not part of the library).
*/
#ifndef PM_BENCH_NAIVE_H
#define PM_BENCH_NAIVE_H

#include "pm.h"

/*
**  naive_apply - p' = p + sign * sum_i a_i Y_{l_i m_i}(ha, dec) p_{k_i}(ha, dec)
**  over the model's harmonic terms (Pal et al. Eq. pyyexpansion, the 3-D
**  form, every term to first order, the isotropic ones included as the
**  l = 0 terms), then the angles of p'.  sign = -1 is the paper's inverse
**  (Sec. 5.2: the same series with the coefficients' signs flipped).
**  Every Y_lm and p_k is computed from libm sin/cos at each use, as the
**  formulas are written.  Differs from pm_model_apply at second order in
**  the coefficients (the library applies the isotropic part exactly).
*/
void naive_apply(const pm_model *m, double sign, double ha, double dec,
                 double *out_ha, double *out_dec);

/* The paper's Y_lm (Sec. 3; the library's normalisation beyond l = 2,
** docs/model.md) and base vector p_k (Eq. tdvectexpansion). */
double naive_Y(int l, int m, double ha, double dec);
void naive_p(int k, double ha, double dec, double v[3]);

#endif
