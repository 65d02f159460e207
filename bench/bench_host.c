/*
**  bench_host.c - per-call cost of the model on the host.
**
**    pmbench [--batches K] [--out FILE]   TSC ticks per call (median of K
**                                         batches, default 31, taken in K
**                                         rounds over all cases), JSON lines
**    pmbench --callgrind                  run each case once between
**                                         callgrind client requests (under
**                                         valgrind --tool=callgrind: one
**                                         dump per case, instructions)
**
**  Every case runs over the same BENCH_NPOS positions per batch
**  (bench_common.h); the loop's own cost (an empty function called the
**  same way: for the tracking ops a loop that also computes each tick's
**  target, bench_loop_op) is measured the same way and subtracted.  Before timing, the
**  naive evaluation is checked against the library (same terms, agreement
**  to second order in the coefficients), and every call must return PM_OK.
*/
#define _GNU_SOURCE
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_common.h"
#include "naive.h"

#include "host_timer.h"

#define ARCSEC (3.14159265358979323846 / 648000.0)

static bench_input inputs[BENCH_NORDERS];
static volatile double sink;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Ticks per call of one batch of one case. */
static double time_batch(const bench_api *api, int slot, int op, int *bad)
{
    unsigned long long t0 = ticks();
    *bad += bench_run(api, slot, op, &inputs[slot], BENCH_NPOS, &sink);
    unsigned long long t1 = ticks();
    return (double)(t1 - t0) / BENCH_NPOS;
}

static double median(double *v, int k)
{
    qsort(v, (size_t)k, sizeof(double), cmp_double);
    return v[k / 2];
}

/* The naive evaluation must be the same model to first order: the terms
** against pm_terms_eval, the result against pm_model_apply (differences
** of second order in the coefficients: arcseconds for these models). */
static int check_naive(FILE *log)
{
    int s, i, bad = 0;
    for (s = 0; s < BENCH_NORDERS; s++) {
        const bench_input *in = &inputs[s];
        int L = bench_orders[s];
        double terms[6 * PM_N_HARM(PM_MAX_L) * 3], worst_t = 0, worst_a = 0;
        for (i = 0; i < 16; i++) {
            int l, mm, k;
            double ah, ad;
            if (pm_terms_eval(L, in->eh[i], in->ed[i], terms) != PM_OK)
                return 1;
            for (l = 0; l <= L; l++)
                for (mm = -l; mm <= l; mm++)
                    for (k = 1; k <= 6; k++) {
                        double v[3], y = naive_Y(l, mm, in->eh[i], in->ed[i]);
                        const double *o = terms + 3 * (6 * (l * l + l + mm) + k - 1);
                        int c;
                        naive_p(k, in->eh[i], in->ed[i], v);
                        for (c = 0; c < 3; c++)
                            if (fabs(y * v[c] - o[c]) > worst_t)
                                worst_t = fabs(y * v[c] - o[c]);
                    }
            naive_apply(&in->m, 1.0, in->eh[i], in->ed[i], &ah, &ad);
            ah = fabs(ah - in->ah[i]) * cos(ad) + fabs(ad - in->ad[i]);
            if (ah > worst_a)
                worst_a = ah;
        }
        fprintf(log, "naive check L=%d: terms vs pm_terms_eval %.1e, result vs "
                     "pm_model_apply %.2f arcsec (second order)\n", L, worst_t,
                worst_a / ARCSEC);
        if (worst_t > 1e-14 || worst_a > 60 * ARCSEC)
            bad = 1;
    }
    return bad;
}

int main(int argc, char **argv)
{
    int k = 31, callgrind = 0, s, a, op, i, bad = 0;
    const char *out_path = 0;
    FILE *out = stdout;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--batches") && i + 1 < argc)
            k = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out_path = argv[++i];
        else if (!strcmp(argv[i], "--callgrind"))
            callgrind = 1;
        else {
            fprintf(stderr, "usage: pmbench [--batches K] [--out FILE] | --callgrind\n");
            return 2;
        }
    }
    if (k < 1)
        k = 1;
    if (PM_CHECK_CONFIG() != PM_OK || PM_MAX_L < 4) {
        fprintf(stderr, "pmbench: needs the library built with PM_MAX_L >= 4\n");
        return 1;
    }
    for (s = 0; s < BENCH_NORDERS; s++) {
        if (bench_input_make(&inputs[s], bench_orders[s]) != 0) {
            fprintf(stderr, "pmbench: cannot build the model of order %d\n", bench_orders[s]);
            return 1;
        }
        for (a = 0; a < bench_n_apis; a++)
            if (bench_apis[a]->load(s, &inputs[s].m) != 0) {
                fprintf(stderr, "pmbench: %s API refuses the model\n", bench_apis[a]->prec);
                return 1;
            }
    }
    if (check_naive(stderr)) {
        fprintf(stderr, "pmbench: the naive evaluation does not match the library\n");
        return 1;
    }

    if (callgrind) {
        /* one dump per case: "<name>/<calls>" */
        for (a = 0; a < bench_n_apis; a++)
            for (s = 0; s < BENCH_NORDERS; s++)
                for (op = 0; op < BENCH_NOPS; op++) {
                    char name[96], dump[128];
                    if (!bench_op_supported(bench_apis[a], op))
                        continue;
                    bench_case_name(name, sizeof name, "host", op, bench_orders[s],
                                    bench_apis[a]->prec);
                    snprintf(dump, sizeof dump, "%s/%d", name, BENCH_NPOS);
                    bench_run(bench_apis[a], s, op, &inputs[s], BENCH_NPOS, &sink); /* warm */
                    CALLGRIND_ZERO_STATS;
                    bad += bench_run(bench_apis[a], s, op, &inputs[s], BENCH_NPOS, &sink);
                    CALLGRIND_DUMP_STATS_AT(dump);
                }
        if (bad)
            fprintf(stderr, "pmbench: %d calls did not return PM_OK\n", bad);
        return bad ? 1 : 0;
    }

    pin_one_cpu();
    if (out_path && !(out = fopen(out_path, "w"))) {
        perror(out_path);
        return 1;
    }
    {
        /* k rounds; each round runs one batch of every case, so that a
        ** disturbance (another process, a frequency change) spreads over
        ** all cases instead of shifting the median of one */
        enum { MAXC = 128, MAXA = 8 };
        const bench_api *c_api[MAXC];
        int c_ai[MAXC], c_slot[MAXC], c_op[MAXC], nc = 0, c, r;
        double *t = malloc(sizeof(double) * MAXC * (size_t)k);
        double loop[MAXA * BENCH_NORDERS * BENCH_NOPS]; /* by api, order, loop op */
        for (a = 0; a < bench_n_apis; a++)
            for (s = 0; s < BENCH_NORDERS; s++)
                for (op = 0; op < BENCH_NOPS; op++) {
                    if (!bench_op_supported(bench_apis[a], op))
                        continue;
                    if (nc < MAXC && a < MAXA) {
                        c_api[nc] = bench_apis[a];
                        c_ai[nc] = a;
                        c_slot[nc] = s;
                        c_op[nc] = op;
                        nc++;
                    }
                }
        for (c = 0; c < nc; c++) /* warm-up */
            for (r = 0; r < 3; r++)
                time_batch(c_api[c], c_slot[c], c_op[c], &bad);
        for (r = 0; r < k; r++)
            for (c = 0; c < nc; c++) {
                /* an untimed batch first: the timed one runs hot, as in a
                ** loop of calls, not after the other cases' code */
                time_batch(c_api[c], c_slot[c], c_op[c], &bad);
                t[c * k + r] = time_batch(c_api[c], c_slot[c], c_op[c], &bad);
            }
        if (bad) {
            fprintf(stderr, "pmbench: %d calls did not return PM_OK\n", bad);
            return 1;
        }
        for (c = 0; c < nc; c++) { /* the loops' costs, per api, order and loop op */
            double m = median(t + c * k, k);
            if (bench_loop_op(c_op[c]) == c_op[c])
                loop[(c_ai[c] * BENCH_NORDERS + c_slot[c]) * BENCH_NOPS + c_op[c]] = m;
            t[c * k] = m;
        }
        for (c = 0; c < nc; c++) {
            char name[96];
            const int lo = bench_loop_op(c_op[c]);
            double l = loop[(c_ai[c] * BENCH_NORDERS + c_slot[c]) * BENCH_NOPS + lo];
            bench_case_name(name, sizeof name, "host", c_op[c], bench_orders[c_slot[c]],
                            c_api[c]->prec);
            fprintf(out, "{\"name\": \"%s\", \"ticks_median\": %.1f, \"batches\": %d, "
                         "\"calls_per_batch\": %d, \"unit\": \"%s\"}\n",
                    name, lo == c_op[c] ? t[c * k] : t[c * k] - l, k, BENCH_NPOS, TICK_UNIT);
        }
        free(t);
    }
    if (out != stdout && fclose(out) != 0)
        return 1;
    return 0;
}
