/*
**  bench_dist_host.c - the inverse's cost per call as a distribution over
**  the situations of dist.h, on the host.
**
**    pmbench_dist [--rounds R] [--out FILE]   TSC ticks of each call (the
**        median of R rounds, default 15, each round over every call of
**        every situation in turn), minus the timer's own cost
**    pmbench_dist --callgrind [--every K]     each call (every K-th, default
**        1) between callgrind client requests: under valgrind
**        --tool=callgrind, one dump per call, "dist/<prec>/<situation>/<i>"
**    pmbench_dist_probe [--out FILE]          (this source built with
**        -DDIST_PROBE against the core with the evaluation counter of
**        tests/probe.h) model evaluations of each call
**
**  Output: JSON lines, one per situation and precision: name, prec,
**  measure ("evals", "host_ticks"), n, median, p99, worst, bound (evals),
**  statuses (ok, warn, err).
*/
#define _GNU_SOURCE
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dist.h"

#include "host_timer.h"

#ifdef DIST_PROBE
static unsigned long probe_count;
void pm_probe_hit(void) { probe_count++; }
#endif


typedef struct sit_data {
    dist_situation sit;
    pm_model models[DIST_MAX_MODELS];
    pm_model_f mf[DIST_MAX_MODELS];
    int have_f[DIST_MAX_MODELS];
    dist_call calls[DIST_N];
    int status[DIST_NPREC][DIST_N];
} sit_data;

static sit_data *all;
static int n_sit;
static volatile double sink;

static int runnable(const sit_data *d, int prec, int i)
{
    return dist_runnable(&d->calls[i], prec, d->have_f);
}

static void emit(FILE *out, const sit_data *d, int prec, const char *measure, double *v,
                 int n)
{
    double med, p99, worst;
    int i, ok = 0, warn = 0, err = 0;
    if (n == 0)
        return;
    for (i = 0; i < d->sit.n; i++) {
        if (!runnable(d, prec, i))
            continue;
        int st = d->status[prec][i];
        ok += st == PM_OK;
        warn += st > 0;
        err += st < 0;
    }
    dist_stats(v, n, &med, &p99, &worst);
    fprintf(out, "{\"name\": \"dist_%s\", \"prec\": \"%s\", \"measure\": \"%s\", \"n\": %d, "
                 "\"median\": %.1f, \"p99\": %.1f, \"worst\": %.1f, \"bound\": %d, "
                 "\"ok\": %d, \"warn\": %d, \"err\": %d}\n",
            d->sit.name, dist_prec_name[prec], measure, n, med, p99, worst,
            prec == 1 ? PM_INVERT_F_MAX_EVALS : d->sit.bound, ok, warn, err);
}

int main(int argc, char **argv)
{
    int rounds = 15, callgrind = 0, every = 1, s, i, p;
    const char *out_path = 0;
    FILE *out = stdout;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--rounds") && i + 1 < argc)
            rounds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--every") && i + 1 < argc)
            every = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out_path = argv[++i];
        else if (!strcmp(argv[i], "--callgrind"))
            callgrind = 1;
        else {
            fprintf(stderr, "usage: pmbench_dist [--rounds R] [--out FILE] | --callgrind "
                            "[--every K]\n");
            return 2;
        }
    }
    if (rounds < 1)
        rounds = 1;
    if (every < 1)
        every = 1;
    n_sit = dist_count();
    all = calloc((size_t)n_sit, sizeof *all);
    if (!all)
        return 1;
    for (s = 0; s < n_sit; s++)
        if (dist_make(s, &all[s].sit, all[s].models, all[s].mf, all[s].have_f,
                      all[s].calls) != 0) {
            fprintf(stderr, "pmbench_dist: cannot build situation %d\n", s);
            return 1;
        }
    if (out_path && !(out = fopen(out_path, "w"))) {
        perror(out_path);
        return 1;
    }
    /* statuses (and, with the probe, evaluations) of every call, once */
    {
#ifdef DIST_PROBE
        double *v = malloc(sizeof(double) * DIST_N);
#endif
        for (s = 0; s < n_sit; s++)
            for (p = 0; p < DIST_NPREC; p++) {
                int n = 0;
                for (i = 0; i < all[s].sit.n; i++) {
                    double eh, ed;
                    if (!runnable(&all[s], p, i))
                        continue;
#ifdef DIST_PROBE
                    probe_count = 0;
#endif
                    all[s].status[p][i] =
                        dist_run(p, all[s].models, all[s].mf, &all[s].calls[i], &eh, &ed);
#ifdef DIST_PROBE
                    v[n] = (double)probe_count;
#endif
                    n++;
                }
#ifdef DIST_PROBE
                emit(out, &all[s], p, "evals", v, n);
#else
                (void)n;
#endif
            }
#ifdef DIST_PROBE
        free(v);
        if (out != stdout)
            fclose(out);
        return 0;
#endif
    }
    if (callgrind) {
        for (p = 0; p < DIST_NPREC; p++)
            for (s = 0; s < n_sit; s++)
                for (i = 0; i < all[s].sit.n; i += every) {
                    char dump[96];
                    double eh, ed;
                    if (!runnable(&all[s], p, i))
                        continue;
                    dist_run(p, all[s].models, all[s].mf, &all[s].calls[i], &eh, &ed);
                    snprintf(dump, sizeof dump, "dist/%s/%s/%d", dist_prec_name[p],
                             all[s].sit.name, i);
                    CALLGRIND_ZERO_STATS;
                    dist_run(p, all[s].models, all[s].mf, &all[s].calls[i], &eh, &ed);
                    CALLGRIND_DUMP_STATS_AT(dump);
                }
        return 0;
    }
    pin_one_cpu();
    {
        /* t[((s * DIST_NPREC + p) * DIST_N + i) * rounds + r] */
        size_t per = (size_t)DIST_N * (size_t)rounds;
        double *t = malloc(sizeof(double) * per * DIST_NPREC * (size_t)n_sit), *v, timer[64];
        double tmed, x1, x2;
        int r;
        if (!t)
            return 1;
        /* the timer's own cost: an empty interval, the median of many */
        for (r = 0; r < 64; r++) {
            unsigned long long a = ticks(), b = ticks();
            timer[r] = (double)(b - a);
        }
        dist_stats(timer, 64, &tmed, &x1, &x2);
        for (r = 0; r < rounds; r++)
            for (s = 0; s < n_sit; s++)
                for (p = 0; p < DIST_NPREC; p++)
                    for (i = 0; i < all[s].sit.n; i++) {
                        double eh, ed;
                        unsigned long long a, b;
                        if (!runnable(&all[s], p, i))
                            continue;
                        a = ticks();
                        dist_run(p, all[s].models, all[s].mf, &all[s].calls[i], &eh, &ed);
                        b = ticks();
                        sink += eh;
                        t[((size_t)(s * DIST_NPREC + p) * DIST_N + (size_t)i) * (size_t)rounds +
                          (size_t)r] = (double)(b - a) - tmed;
                    }
        v = malloc(sizeof(double) * DIST_N);
        for (s = 0; s < n_sit; s++)
            for (p = 0; p < DIST_NPREC; p++) {
                int n = 0;
                for (i = 0; i < all[s].sit.n; i++) {
                    double med;
                    if (!runnable(&all[s], p, i))
                        continue;
                    dist_stats(t + ((size_t)(s * DIST_NPREC + p) * DIST_N + (size_t)i) * (size_t)rounds,
                               rounds, &med, &x1, &x2);
                    v[n++] = med;
                }
                emit(out, &all[s], p, "host_ticks", v, n);
            }
        fprintf(stderr, "pmbench_dist: timer cost %.0f ticks (subtracted)\n", tmed);
        free(v);
        free(t);
    }
    if (out != stdout && fclose(out) != 0)
        return 1;
    return 0;
}
