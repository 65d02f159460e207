/*
**  naive.c - the paper's formulas as written (see naive.h).
**
**  Compiled with the compiler's default floating-point flags (errno-setting
**  libm calls), so each sin/cos written here is a call: nothing is shared
**  between terms, which is what "as written" costs.
*/
#include <math.h>

#include "naive.h"

double naive_Y(int l, int m, double ha, double dec)
{
    /* Pal et al. Sec. 3, the series for the first three orders */
    if (l == 0)
        return 1.0;
    if (l == 1) {
        if (m == -1)
            return cos(dec) * sin(ha);
        if (m == 0)
            return sin(dec);
        return cos(dec) * cos(ha);
    }
    if (l == 2) {
        switch (m) {
        case -2: return cos(dec) * cos(dec) * sin(2 * ha);
        case -1: return cos(dec) * sin(dec) * sin(ha);
        case 0: return 3 * sin(dec) * sin(dec) - 1;
        case 1: return cos(dec) * sin(dec) * cos(ha);
        default: return cos(dec) * cos(dec) * cos(2 * ha);
        }
    }
    {
        /* K_lm P_l^|m|(sin dec) cos(m ha) or sin(|m| ha): the associated
        ** Legendre function by its recurrence in l, (1-x^2)^(m/2) taken as
        ** cos(dec)^m; K_lm = 1/(2l-1)!! (m != 0), 2 (m = 0) (docs/model.md) */
        int am = m < 0 ? -m : m, j;
        double x = sin(dec), pmm = 1, p1, p2, p = 0, k = 1;
        for (j = 1; j <= am; j++)
            pmm *= (2 * j - 1) * cos(dec);
        p2 = pmm;
        p1 = (2 * am + 1) * x * pmm;
        if (l == am)
            p = pmm;
        else if (l == am + 1)
            p = p1;
        for (j = am + 2; j <= l; j++) {
            p = ((2 * j - 1) * x * p1 - (j + am - 1) * p2) / (j - am);
            p2 = p1;
            p1 = p;
        }
        if (m == 0)
            k = 2;
        else
            for (j = 2 * l - 1; j > 1; j -= 2)
                k /= j;
        return k * p * (m < 0 ? sin(am * ha) : cos(am * ha));
    }
}

void naive_p(int k, double ha, double dec, double v[3])
{
    /* Pal et al. Eq. (tdvectexpansion) */
    switch (k) {
    case 1: /* a */
        v[0] = 0;
        v[1] = -sin(dec);
        v[2] = cos(dec) * sin(ha);
        break;
    case 2: /* b */
        v[0] = sin(dec);
        v[1] = 0;
        v[2] = -cos(dec) * cos(ha);
        break;
    case 3: /* c' */
        v[0] = -cos(dec) * sin(ha);
        v[1] = cos(dec) * cos(ha);
        v[2] = 0;
        break;
    case 4: /* d */
        v[0] = sin(dec) * sin(ha);
        v[1] = -sin(dec) * cos(ha);
        v[2] = 0;
        break;
    case 5: /* e' */
        v[0] = sin(dec) * cos(ha);
        v[1] = sin(dec) * sin(ha);
        v[2] = -cos(dec);
        break;
    default: /* i */
        v[0] = -sin(ha);
        v[1] = cos(ha);
        v[2] = 0;
        break;
    }
}

void naive_apply(const pm_model *m, double sign, double ha, double dec,
                 double *out_ha, double *out_dec)
{
    /* Eq. (pdef), then Eq. (pyyexpansion) */
    double p[3];
    int i;
    p[0] = cos(dec) * cos(ha);
    p[1] = cos(dec) * sin(ha);
    p[2] = sin(dec);
    for (i = 0; i < m->n_terms; i++) {
        const pm_term *t = &m->term[i];
        double v[3], a;
        if (t->kind != PM_TERM_SH)
            continue;
        a = sign * m->coef[i] * naive_Y(t->l, t->m, ha, dec);
        naive_p(t->k, ha, dec, v);
        p[0] += a * v[0];
        p[1] += a * v[1];
        p[2] += a * v[2];
    }
    *out_ha = atan2(p[1], p[0]);
    *out_dec = atan2(p[2], sqrt(p[0] * p[0] + p[1] * p[1]));
}
