/*
**  inv_stress.c - the double inverse's outcomes on large samples (issue
**  18, round 3): statuses and model evaluations, deterministic (the core
**  with the evaluation counter of tests/probe.h).
**
**    pmbench_inv_stress real [N] [SEED] [RHO_MAX] [RHO_MIN]   N cold pm_model_invert calls
**        (default 20,000) on realistic models near the mount's pole: order
**        L = 0..2, isotropic terms uniform within +-10 deg, harmonic terms
**        within +-10', both pier sides, the true encoder position within
**        0.5 deg of the mount's pole (uniform in area, uniform in distance,
**        log-uniform down to 1e-10 rad, and exactly on the pole's edge);
**        every call must return PM_OK on the requested side, round trip
**        within PM_INVERT_TOL
**    pmbench_inv_stress hard              check_bounded's ordinary-scale
**        cases (tests/hard_cases.h, the same sequence as the test): PM_OK
**        counts of the double pm_model_invert and pm_model_invert_near
**
**    pmbench_inv_stress float ISO_DEG ANISO_ARCMIN RHO0_DEG RHO1_DEG   20,000
**        pm_model_invert_f calls, L = 2 models with every isotropic term
**        uniform within +-ISO_DEG and every harmonic term within
**        +-ANISO_ARCMIN, the true position RHO0..RHO1 deg from the mount's
**        pole (normal side): statuses, round trips through the float and
**        the double forward models, the float forward's own jitter
**    pmbench_inv_stress track DT [MODELS] [SEED]   tracking calls, the
**        figures behind PM_INVERT_TRACK_MAX_EVALS' "measured": 40 targets
**        per model (MODELS models, default 2,000, L = 1 and 2, isotropic
**        terms within +-10 deg, harmonic terms within +-10'), the true
**        position 0.5..1 deg from the mount's pole for half of them, 0.5..90
**        deg for the rest, either pole and side; pm_model_invert_near from
**        the solution of the target DT s of sidereal motion earlier:
**        evaluations per call (histogram) and the calls above 4
**
**  Prints one summary line per sample and the failures (up to 20).
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "testutil.h"
#include "probe.h"
#include "hard_cases.h"

static unsigned long probe_count;
void pm_probe_hit(void) { probe_count++; }
extern int pm_trace_on __attribute__((weak));

static void real_sample(long n, unsigned long long seed, double rho_max, double rho_min)
{
    tu_rng r;
    long i, ok = 0, bad = 0, hist[PM_INVERT_MAX_EVALS + 2];
    unsigned long worst = 0;
    double worst_rt = 0;
    pm_model m;
    memset(hist, 0, sizeof hist);
    tu_seed(&r, seed);
    for (i = 0; i < n; i++) {
        double rho, t, d, ah, ad, eh, ed, bh, bd, e, rt;
        int side, kind;
        unsigned long evals;
        pm_status st;
        if (i % 10 == 0 && hc_real_model(&m, &r) != 0)
            abort();
        e = m.coef[4];
        rho = hc_real_position(&m, &r, rho_max, rho_min, &side, &t, &d, &kind);
        if (pm_model_apply(&m, NULL, t, d, &ah, &ad) != PM_OK)
            abort();
        probe_count = 0;
        if (&pm_trace_on)
            pm_trace_on = getenv("STRESS_ONLY") && atol(getenv("STRESS_ONLY")) == i;
        st = pm_model_invert(&m, NULL, ah, ad, side, &eh, &ed);
        if (&pm_trace_on)
            pm_trace_on = 0;
        if (getenv("STRESS_DUMP") && getenv("STRESS_ONLY") && atol(getenv("STRESS_ONLY")) == i) {
            FILE *fp = fopen(getenv("STRESS_DUMP"), "wb");
            fwrite(&m, sizeof m, 1, fp);
            fwrite(&ah, sizeof ah, 1, fp);
            fwrite(&ad, sizeof ad, 1, fp);
            fwrite(&t, sizeof t, 1, fp);
            fwrite(&d, sizeof d, 1, fp);
            fwrite(&side, sizeof side, 1, fp);
            fclose(fp);
        }
        if (probe_count > worst)
            worst = probe_count;
        hist[probe_count]++;
        evals = probe_count;
        rt = 1;
        if (st >= 0 && pm_model_apply(&m, NULL, eh, ed, &bh, &bd) == PM_OK)
            rt = tu_angle(bh, bd, ah, ad);
        if (st == PM_OK && rt > worst_rt)
            worst_rt = rt;
        if (st == PM_OK && rt <= 1e-12 &&
            (cos(ed - e) >= 0) == (side == PM_SIDE_NORMAL)) {
            ok++;
        } else {
            if (bad < (getenv("STRESS_ALL") ? 1000000 : 20))
                printf("  fail %ld: status %d, %lu evals, order %d, rho %.3e rad (kind %d), "
                       "side %d, t %.6f; round trip %.3e; result (%.9f, %.9f) "
                       "cos(dec-e') %.3e; coef d %.3e i %.3e a %.3e b %.3e\n",
                       i, (int)st, evals, m.order, rho, kind, side, t, rt, eh, ed,
                       cos(ed - e), m.coef[3], m.coef[5], m.coef[0], m.coef[1]);
            bad++;
        }
    }
    {
        long med = 0, p99 = 0, acc = 0;
        unsigned long k;
        for (k = 0; k <= (unsigned long)PM_INVERT_MAX_EVALS; k++) {
            acc += hist[k];
            if (!med && acc * 2 >= n)
                med = (long)k;
            if (!p99 && acc * 100 >= 99 * n)
                p99 = (long)k;
        }
        printf("real, %g..%g rad from the pole: %ld cold calls (seed %llu): %ld PM_OK, %ld not; evaluations "
               "median %ld, p99 %ld, worst %lu (bound %d); worst PM_OK round trip %.2e rad\n",
               rho_min, rho_max, n, seed, ok, bad, med, p99, worst, PM_INVERT_MAX_EVALS, worst_rt);
    }
}

static void hard_sample(void)
{
    tu_rng r;
    long cold_ok = 0, near_ok = 0, calls = 0;
    unsigned long worst_cold = 0, worst_near = 0;
    int i, j;
    tu_seed(&r, 101);
    for (i = 0; i < 200; i++) {
        pm_model m;
        pm_model_f mf;
        pm_context c;
        const pm_context *ctx;
        if (hc_random_model(&m, &r, HC_SCALE_NORMAL) != 0)
            abort();
        (void)pm_model_f_prepare(&mf, &m);
        for (j = 0; j < 40; j++) {
            double ha, dec, eh, ed, sh, sd, sol[2];
            int side;
            pm_status st;
            hc_random_context(&c, &r);
            ctx = m.needs_ctx || tu_uniform(&r) < 0.5 ? &c : NULL;
            hc_hard_target(&m, &r, &ha, &dec);
            /* check_bounded's check_point: the same draws in the same order */
            side = tu_uniform(&r) < 0.5 ? PM_SIDE_NORMAL : PM_SIDE_FLIPPED;
            probe_count = 0;
            if (&pm_trace_on)
                pm_trace_on = getenv("STRESS_ONLY") && atol(getenv("STRESS_ONLY")) == i * 100 + j;
            if (&pm_trace_on && pm_trace_on) {
                int q;
                printf("model %d point %d: order %d, mount %d, target (%.17g, %.17g) side %d, ctx %d\n",
                       i, j, m.order, m.mount, ha, dec, side, ctx != NULL);
                for (q = m.n_base; q < m.n_terms; q++)
                    printf("  term kind %d k %d l %d m %d side %d aux %d param %g coef %g\n",
                           m.term[q].kind, m.term[q].k, m.term[q].l, m.term[q].m, m.term[q].side,
                           m.term[q].aux, m.term[q].param, m.coef[q]);
            }
            st = pm_model_invert(&m, ctx, ha, dec, side, &eh, &ed);
            if (&pm_trace_on)
                pm_trace_on = 0;
            cold_ok += st == PM_OK;
            if (getenv("STRESS_LIST"))
                printf("cold %d %d %d %lu order %d n_terms %d n_base %d ctx %d dec %.6f\n", i, j,
                       (int)st, probe_count, m.order, m.n_terms, m.n_base, ctx != NULL, dec);
            if (probe_count > worst_cold)
                worst_cold = probe_count;
            sol[0] = eh;
            sol[1] = ed;
            hc_hard_start(&r, st >= 0 ? sol : NULL, &sh, &sd);
            probe_count = 0;
            st = pm_model_invert_near(&m, ctx, ha, dec, sh, sd, &eh, &ed);
            near_ok += st == PM_OK;
            if (getenv("STRESS_LIST"))
                printf("near %d %d %d %lu\n", i, j, (int)st, probe_count);
            if (probe_count > worst_near)
                worst_near = probe_count;
            calls++;
            /* check_apply's draws */
            {
                double u = tu_uniform(&r);
                if (u < 0.5)
                    (void)tu_uniform(&r);
                else
                    (void)tu_gauss(&r);
                u = tu_uniform(&r);
                if (u < 0.5)
                    (void)tu_uniform(&r);
                else
                    (void)tu_gauss(&r);
            }
        }
    }
    printf("hard (check_bounded, ordinary): %ld targets: pm_model_invert PM_OK %ld (worst %lu "
           "evaluations, bound %d), pm_model_invert_near PM_OK %ld (worst %lu, bound %d)\n",
           calls, cold_ok, worst_cold, PM_INVERT_MAX_EVALS, near_ok, worst_near,
           PM_INVERT_NEAR_MAX_EVALS);
}

static void float_sample(double iso, double an, double r0, double r1)
{
    int n = 20000, bad = 0, big = 0, i, j, k;
    tu_rng r;
    pm_model m;
    pm_model_f mf;
    double worst_ok = 0, worst_noise = 0, worst_warn = 0, worst_dbl = 0;
    tu_seed(&r, 7);
    for (i = 0; i < n; i++) {
        double rho, t, d, ah, ad, eh, ed, bh, bd, ch, cd, h0, d0, rt, e;
        pm_status st;
        if (i % 10 == 0) {
            if (pm_model_init(&m, PM_MOUNT_EQUATORIAL, 2) != PM_OK)
                abort();
            for (j = 0; j < m.n_terms; j++)
                m.coef[j] = (2 * tu_uniform(&r) - 1) * (j < 6 ? iso : an);
            if (pm_model_prepare(&m) != PM_OK || pm_model_f_prepare(&mf, &m) != PM_OK)
                abort();
        }
        rho = (r0 + (r1 - r0) * tu_uniform(&r)) * DEG;
        t = (2 * tu_uniform(&r) - 1) * M_PI;
        d = m.coef[4] + M_PI / 2 - rho;
        pm_model_apply(&m, NULL, t, d, &ah, &ad);
        st = pm_model_invert_f(&mf, NULL, ah, ad, PM_SIDE_NORMAL, &eh, &ed);
        /* the float forward's jitter near the true point (steps of 1e-12 rad) */
        pm_model_apply_f(&mf, NULL, t, d, &h0, &d0);
        for (k = 1; k < 8; k++) {
            double h1, d1;
            pm_model_apply_f(&mf, NULL, t + k * 1e-12, d + k * 1e-12, &h1, &d1);
            e = tu_angle(h1, d1, h0, d0);
            if (e > worst_noise)
                worst_noise = e;
        }
        pm_model_apply_f(&mf, NULL, eh, ed, &bh, &bd);
        rt = tu_angle(bh, bd, ah, ad);
        pm_model_apply(&m, NULL, eh, ed, &ch, &cd);
        e = tu_angle(ch, cd, ah, ad);
        if (e > worst_dbl)
            worst_dbl = e;
        if (st != PM_OK) {
            bad++;
            big += rt > 1e-7;
            if (rt > worst_warn)
                worst_warn = rt;
        } else if (rt > worst_ok)
            worst_ok = rt;
    }
    printf("float, isotropic %g deg, harmonic %g', %g..%g deg from the pole: %d of %d not PM_OK "
           "(%d beyond 1e-7 rad); round trip through the float forward: PM_OK worst %.2e, "
           "warnings worst %.2e; through the double forward %.2e; float forward jitter %.2e\n",
           iso / DEG, an / (ARCSEC * 60), r0, r1, bad, n, big, worst_ok, worst_warn, worst_dbl,
           worst_noise);
}

static void track_sample(double dt, int models, unsigned long long seed)
{
    tu_rng r;
    unsigned long hist[PM_INVERT_NEAR_MAX_EVALS + 1], bad = 0, n = 0, shown = 0;
    int i, j, worst = 0;
    memset(hist, 0, sizeof hist);
    tu_seed(&r, seed);
    for (i = 0; i < models; i++) {
        pm_model m;
        if (hc_track_model(&m, &r, i) != 0)
            return;
        for (j = 0; j < 40; j++) {
            double rho = (0.5 + tu_uniform(&r) * (j % 2 ? 0.5 : 89.5)) * DEG;
            double hemi = tu_uniform(&r) < 0.5 ? 1 : -1;
            int flip = tu_uniform(&r) < 0.5;
            double t = (2 * tu_uniform(&r) - 1) * M_PI;
            double d = m.coef[4] + hemi * (flip ? M_PI / 2 + rho : M_PI / 2 - rho);
            double ah, ad, sh, sd, eh, ed;
            pm_status st;
            if (pm_model_apply(&m, NULL, t, d, &ah, &ad) != PM_OK ||
                pm_model_invert_near(&m, NULL, ah - 7.2921159e-5 * dt, ad, t, d, &sh, &sd) !=
                    PM_OK) {
                bad++; /* (the previous tick: beyond the pole's fold, say) */
                continue;
            }
            probe_count = 0;
            st = pm_model_invert_near(&m, NULL, ah, ad, sh, sd, &eh, &ed);
            n++;
            hist[probe_count <= PM_INVERT_NEAR_MAX_EVALS ? probe_count : 0]++;
            worst = (int)probe_count > worst ? (int)probe_count : worst;
            if (st != PM_OK)
                bad++;
            if ((probe_count > 4 || st != PM_OK) && shown++ < 20)
                printf("  model %d target %d: %.4f deg from the pole, status %d, %lu "
                       "evaluations\n", i, j, rho / DEG, (int)st, probe_count);
        }
    }
    printf("track dt %g s, %lu calls: evaluations", dt, n);
    for (j = 1; j <= PM_INVERT_NEAR_MAX_EVALS; j++)
        if (hist[j])
            printf(" %d: %lu", j, hist[j]);
    printf("; worst %d (bound %d); not PM_OK (or no previous tick) %lu\n", worst,
           PM_INVERT_TRACK_MAX_EVALS, bad);
}

int main(int argc, char **argv)
{
    if (argc >= 3 && !strcmp(argv[1], "track")) {
        track_sample(atof(argv[2]), argc >= 4 ? atoi(argv[3]) : 2000,
                     argc >= 5 ? strtoull(argv[4], 0, 10) : 1818);
        return 0;
    }
    if (argc >= 6 && !strcmp(argv[1], "float")) {
        float_sample(atof(argv[2]) * DEG, atof(argv[3]) * ARCSEC * 60, atof(argv[4]),
                     atof(argv[5]));
        return 0;
    }
    if (argc >= 2 && !strcmp(argv[1], "real")) {
        long n = argc >= 3 ? atol(argv[2]) : 20000;
        unsigned long long seed = argc >= 4 ? strtoull(argv[3], 0, 10) : 1;
        double rmax = argc >= 5 ? atof(argv[4]) : 0.5 * DEG, rmin = argc >= 6 ? atof(argv[5]) : 0;
        real_sample(n, seed, rmax, rmin);
        return 0;
    }
    if (argc >= 2 && !strcmp(argv[1], "hard")) {
        hard_sample();
        return 0;
    }
    fprintf(stderr, "usage: pmbench_inv_stress real [N] [SEED] [RHO_MAX] [RHO_MIN] | hard | "
                    "float ISO_DEG ANISO_ARCMIN RHO0_DEG RHO1_DEG | track DT [MODELS] [SEED]\n");
    return 2;
}
