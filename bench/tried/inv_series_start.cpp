/*
**  inv_series_start.cpp - samples for bench/tried/inv_series_start.py: can
**  a series in the target's coordinates start pm_model_invert close enough
**  to its solution that one Newton step (one evaluation with J) is
**  certified?  (Issue 18, stop 36: tried, no; docs/performance.md, "A
**  series start, tried".)
**
**  inv_series_start KIND MODEL_SEED N L POS_SEED
**  prints N lines "app_ha app_dec dt dd enc_ha enc_dec lip2" for targets
**  spread as the bench's (hour angle all round, declination -50..85 deg
**  uniform in its sine), each solved by pm_model_invert (normal side), with
**  the anisotropic displacement D^ = (dt, dd) at the solution.  KIND 0:
**  the bench's L = 2 model (bench/bench_common.c's terms); 1: isotropic
**  terms within +-10 deg, harmonic terms within +-10'; 2: within +-1 deg
**  and +-1'.  Built by the .py (it includes the core's private header).
*/
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "pm.h"
#include "pm_detail.hpp"

using namespace pm::detail;

static double lcg(unsigned long *s) /* uniform in [-1, 1), as the bench's */
{
    *s = (*s * 1664525UL + 1013904223UL) & 0xFFFFFFFFUL;
    return (double)(*s >> 8) / 8388608.0 - 1.0;
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: inv_series_start KIND MODEL_SEED N L POS_SEED\n");
        return 2;
    }
    const double as = M_PI / 648000.0;
    const int kind = atoi(argv[1]), n = atoi(argv[3]), order = atoi(argv[4]);
    unsigned long s = strtoul(argv[2], 0, 10);
    static const double iso[6] = {95, -140, 1200, 35, -420, -50};
    pm_model m;
    if (pm_model_init(&m, PM_MOUNT_EQUATORIAL, order) != PM_OK)
        return 1;
    for (int i = 0; i < m.n_terms; i++) {
        if (kind == 0)
            m.coef[i] = i < 6 ? iso[i] * as : 15.0 * as * sqrt(3.0) * lcg(&s);
        else if (kind == 1)
            m.coef[i] = (i < 6 ? 36000 : 600) * as * lcg(&s);
        else
            m.coef[i] = (i < 6 ? 3600 : 60) * as * lcg(&s);
    }
    if (pm_model_prepare(&m) != PM_OK)
        return 1;
    const Iso<double> &k = iso_of(&m);
    s = strtoul(argv[5], 0, 10);
    const double z0 = sin(-50 * M_PI / 180), z1 = sin(85 * M_PI / 180);
    for (int j = 0; j < n; j++) {
        const double u = 0.5 * (lcg(&s) + 1), v = lcg(&s);
        const double ah = M_PI * v, ad = asin(z0 + (z1 - z0) * u);
        double eh, ed, dt, dd;
        if (pm_model_invert(&m, 0, ah, ad, PM_SIDE_NORMAL, &eh, &ed) != PM_OK)
            continue;
        aniso<double>(&m, k, trig_of(eh, ed), 0, &dt, &dd);
        printf("%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", ah, ad, dt, dd, eh, ed, m.lip2);
    }
    return 0;
}
