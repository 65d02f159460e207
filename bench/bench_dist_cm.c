/*
**  bench_dist_cm.c - the inverse's cost per call as a distribution over the
**  situations of dist.h, on Cortex-M under QEMU: instructions of each call
**  (SysTick under "qemu -icount shift=0", firmware_demo/fw_platform.h),
**  the call repeated DIST_REP times between two readings (the counter
**  moves 40 instructions at a time; the calls are deterministic), minus
**  the same loop around an empty call.  Prints "BENCH {json}" lines, one
**  per situation and precision (name, prec, measure "<target>_insn", n,
**  median, p99, worst), and exits 0.
**
**  Precisions: double and float on the M7 (FPv5-D16), float only on the
**  M4F (FPv4-SP: its double build is emulated, docs/performance.md).
*/
#include <stdio.h>
#include <string.h>

#include "dist.h"
#include "fw_platform.h"

#define DIST_REP 8

static pm_model models[DIST_MAX_MODELS];
static pm_model_f mf[DIST_MAX_MODELS];
static int have_f[DIST_MAX_MODELS];
static dist_call calls[DIST_N];
static double v[DIST_N];
static volatile double sink;

static pm_status empty_run(int prec, const pm_model *m, const pm_model_f *f,
                           const dist_call *c, double *eh, double *ed)
{
    (void)prec;
    (void)m;
    (void)f;
    *eh = c->ah;
    *ed = c->ad;
    return PM_OK;
}
static pm_status (*volatile run_ptr)(int, const pm_model *, const pm_model_f *,
                                     const dist_call *, double *, double *) = dist_run;
static pm_status (*volatile empty_ptr)(int, const pm_model *, const pm_model_f *,
                                       const dist_call *, double *, double *) = empty_run;

/* Instructions of DIST_REP calls of c through fn. */
static unsigned long measure(pm_status (*fn)(int, const pm_model *, const pm_model_f *,
                                             const dist_call *, double *, double *),
                             int prec, const dist_call *c, int *st)
{
    unsigned long c0, c1;
    double eh = 0, ed = 0;
    int k;
    c0 = fw_counter();
    for (k = 0; k < DIST_REP; k++)
        *st = fn(prec, models, mf, c, &eh, &ed);
    c1 = fw_counter();
    sink += eh + ed;
    return fw_counter_insns(c0, c1);
}

int main(void)
{
    int s, p, i, is_m7;
    unsigned long cal;
    fw_counter_init();
    cal = fw_counter_calibrate(100000UL);
    if (cal < 200000UL - 50 || cal > 200000UL + 100) {
        printf("the instruction counter is off: is QEMU running with -icount shift=0?\n");
        return 1;
    }
    if (PM_CHECK_CONFIG() != PM_OK)
        return 1;
    is_m7 = !strcmp(fw_target(), "m7");
    for (s = 0; s < dist_count(); s++) {
        dist_situation sit;
        if (dist_make(s, &sit, models, mf, have_f, calls) != 0) {
            printf("cannot build situation %d\n", s);
            return 1;
        }
        for (p = is_m7 ? 0 : 1; p < (is_m7 ? DIST_NPREC : 2); p++) {
            double loop, med, p99, worst;
            int n = 0, ok = 0, warn = 0, err = 0, st;
            loop = (double)measure(empty_ptr, p, &calls[0], &st) / DIST_REP;
            for (i = 0; i < sit.n; i++) {
                if (!dist_runnable(&calls[i], p, have_f))
                    continue;
                v[n++] = (double)measure(run_ptr, p, &calls[i], &st) / DIST_REP - loop;
                ok += st == PM_OK;
                warn += st > 0;
                err += st < 0;
            }
            if (!n)
                continue;
            dist_stats(v, n, &med, &p99, &worst);
            printf("BENCH {\"name\": \"dist_%s\", \"prec\": \"%s\", \"measure\": \"%s_insn\", "
                   "\"n\": %d, \"median\": %.1f, \"p99\": %.1f, \"worst\": %.1f, \"ok\": %d, "
                   "\"warn\": %d, \"err\": %d}\n",
                   sit.name, dist_prec_name[p], fw_target(), n, med, p99, worst, ok, warn,
                   err);
        }
    }
    return 0;
}
