/*
**  fwd_latency.c - pm_model_apply's time per call two ways, for the
**  forward model's dependency chain (docs/performance.md, "Round 7: the
**  forward's chain"): "throughput" as in pmbench (256 independent calls,
**  the core overlapping one call with the next as far as its window
**  allows) and "latency" (each call's input depends on the previous
**  call's output: the call's whole chain, nothing overlapped).  The bench's
**  model and positions (bench/bench_common.c), TSC ticks per call, the
**  median of 41 rounds; the loop's own cost printed beside, not taken
**  off.  A timing, never a test.
**
**    build/bench/pmbench_fwd_latency [L ...]     (default: 0 2 4)
*/
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>

#include "pm.h"
#include "bench_common.h"
#include "host_timer.h"

#define ROUNDS 41

static bench_input in;

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v)
{
    qsort(v, ROUNDS, sizeof *v, by_value);
    return v[ROUNDS / 2];
}

int main(int argc, char **argv)
{
    static const int def[3] = {0, 2, 4};
    int n = argc > 1 ? argc - 1 : 3, a;
    volatile double sink = 0;
    pin_one_cpu();
    for (a = 0; a < n; a++) {
        double thr[ROUNDS], lat[ROUNDS], loop[ROUNDS];
        int L = argc > 1 ? atoi(argv[a + 1]) : def[a], r, i;
        if (L < 0 || L > PM_MAX_L || bench_input_make(&in, L) != 0) {
            fprintf(stderr, "pmbench_fwd_latency: no bench model of order %s\n",
                    argc > 1 ? argv[a + 1] : "?");
            return 2;
        }
        for (r = 0; r < ROUNDS; r++) {
            unsigned long long t0, t1;
            double x = 0, y = 0, acc = 0;
            int bad = 0;
            for (i = 0; i < BENCH_NPOS; i++) { /* untimed: caches, predictors */
                bad += pm_model_apply(&in.m, 0, in.eh[i], in.ed[i], &x, &y) != PM_OK;
                acc += x + y;
            }
            t0 = ticks();
            for (i = 0; i < BENCH_NPOS; i++) {
                bad += pm_model_apply(&in.m, 0, in.eh[i], in.ed[i], &x, &y) != PM_OK;
                acc += x + y;
            }
            t1 = ticks();
            thr[r] = (double)(t1 - t0) / BENCH_NPOS;
            x = y = 0;
            t0 = ticks();
            for (i = 0; i < BENCH_NPOS; i++) /* x * 0.0: the next input waits */
                bad += pm_model_apply(&in.m, 0, in.eh[i] + x * 0.0, in.ed[i] + y * 0.0, &x,
                                      &y) != PM_OK;
            t1 = ticks();
            lat[r] = (double)(t1 - t0) / BENCH_NPOS;
            t0 = ticks();
            for (i = 0; i < BENCH_NPOS; i++) { /* the latency loop without the call */
                acc += in.eh[i] + x * 0.0 + in.ed[i];
                x = acc;
            }
            t1 = ticks();
            loop[r] = (double)(t1 - t0) / BENCH_NPOS;
            if (bad) {
                fprintf(stderr, "pmbench_fwd_latency: pm_model_apply failed (L = %d)\n", L);
                return 1;
            }
            sink = sink + acc;
        }
        printf("L=%d double: throughput %.1f, latency %.1f ticks per call (loop %.1f)\n", L,
               median(thr), median(lat), median(loop));
    }
    (void)sink;
    return 0;
}
