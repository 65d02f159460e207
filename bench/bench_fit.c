/*
**  bench_fit.c - how the fit scales: our normal-equation Cholesky against
**  LAPACK's QR least squares (dgels) on the same data, in the same run.
**
**    pmbench_fit [--max-n N] [--out FILE]
**
**  For L = 0, 1, 2, 4 and N = 1e2 .. 1e6 (up to --max-n) simulated
**  observations (a model of order L with the example run's isotropic terms
**  and 15" rms harmonic terms, 1" noise per axis), one Gauss-Newton pass
**  from the zero model, i.e. one linear least-squares solve of the same
**  2N x P system, both ways:
**    ours:  pm_fit_init, N x pm_fit_add, pm_fit_solve (normal equations
**           accumulated in the fixed-size pm_fit, equilibrated Cholesky);
**    dgels: N x pm_fit_row into a 2N x P column-major matrix (the same
**           rows), then LAPACKE_dgels (Householder QR); the matrix is
**           allocated and filled inside the timed region (it is the
**           method's memory).
**  And at L = 2 and 4, the whole Gauss-Newton fit both ways (pm_fit_run to
**  convergence; dgels for the same number of passes), whose coefficients
**  are the ones to compare (one pass from zero amplifies the normal
**  equations' rounding by the condition number squared; the following
**  passes remove it).
**
**  Each (L, N, method) runs in its own child process, so its peak resident
**  memory (VmHWM) is its own; "extra" is the peak at the end minus the peak
**  once the data were made and the method had run once on 100 of them (so
**  the code is resident: what remains is what the method needs for N; the
**  data, 4N doubles, are the same for both).  Ours also has the fixed
**  sizeof(pm_fit), statically allocated (reported as fixed_kb).  Time:
**  median over repeats (enough to fill ~0.2 s, at most 200; one at the
**  largest sizes), CLOCK_MONOTONIC.
**  Output: one JSON object per line (bench/report.py reads them).
*/
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <lapacke.h>

#include "pm.h"

#define PI 3.14159265358979323846
#define ARCSEC (PI / 648000.0)
#define DEG (PI / 180.0)

enum { OURS, DGELS };
static const char *const method_name[2] = {"ours", "dgels"};

typedef struct result {
    int status;       /* 0 ok, else the failing pm_status or LAPACK info */
    int passes;       /* Gauss-Newton passes (whole fit) */
    int repeats;
    double seconds;   /* median */
    long base_kb, peak_kb;
    int n_par;
    double coef[PM_MAX_TERMS];
    double err[PM_MAX_TERMS]; /* 1-sigma errors (ours) */
} result;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Peak resident memory so far (VmHWM, KB). */
static long peak_kb(void)
{
    char line[256];
    long kb = 0;
    FILE *f = fopen("/proc/self/status", "r");
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld kB", &kb) == 1)
            break;
    fclose(f);
    return kb;
}

static unsigned long long rng_s;
static double uniform(void) /* [0, 1), xorshift64* */
{
    rng_s ^= rng_s >> 12;
    rng_s ^= rng_s << 25;
    rng_s ^= rng_s >> 27;
    return (double)((rng_s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}
static double gauss(void)
{
    double u = uniform(), v = uniform();
    if (u < 1e-300)
        u = 1e-300;
    return sqrt(-2 * log(u)) * cos(2 * PI * v);
}

typedef struct data {
    long n;
    double *eh, *ed, *ah, *ad;
} data;

static int make_data(int order, long n, data *d)
{
    static const double iso[6] = {95, -140, 1200, 35, -420, -50};
    pm_model truth;
    long i;
    int j;
    rng_s = 0x9E3779B97F4A7C15ULL ^ (unsigned long long)(order * 1000003L + n);
    if (pm_model_init(&truth, PM_MOUNT_EQUATORIAL, order) != PM_OK)
        return -1;
    for (j = 0; j < truth.n_terms; j++)
        truth.coef[j] = j < 6 ? iso[j] * ARCSEC : 15 * ARCSEC * gauss();
    if (pm_model_prepare(&truth) != PM_OK)
        return -1;
    d->n = n;
    d->eh = malloc(sizeof(double) * (size_t)n * 4);
    if (!d->eh)
        return -1;
    d->ed = d->eh + n;
    d->ah = d->ed + n;
    d->ad = d->ah + n;
    for (i = 0; i < n; i++) {
        double z0 = sin(-50 * DEG), z1 = sin(85 * DEG), ah, ad;
        d->eh[i] = PI * (2 * uniform() - 1);
        d->ed[i] = asin(z0 + (z1 - z0) * uniform());
        if (pm_model_apply(&truth, NULL, d->eh[i], d->ed[i], &ah, &ad) != PM_OK)
            return -1;
        d->ad[i] = ad + ARCSEC * gauss();
        d->ah[i] = ah + ARCSEC * gauss() / cos(ad);
    }
    return 0;
}

/* One pass from model m, ours: the new coefficients in out. */
static pm_fit fit; /* static: ~150 KB at PM_MAX_L = 4 */
static int pass_ours(const data *d, const pm_model *m, pm_model *out, pm_fit_result *res)
{
    long i;
    pm_status st = pm_fit_init(&fit, m);
    for (i = 0; i < d->n && st == PM_OK; i++)
        st = pm_fit_add(&fit, NULL, d->eh[i], d->ed[i], d->ah[i], d->ad[i]);
    if (st == PM_OK)
        st = pm_fit_solve(&fit, out, res);
    return (int)st;
}

/* One pass from model m with dgels: the new coefficients in out. */
static int pass_dgels(const data *d, const pm_model *m, pm_model *out)
{
    int P = m->n_terms, j;
    lapack_int rows = (lapack_int)(2 * d->n), info;
    double *A = malloc(sizeof(double) * (size_t)rows * (size_t)P);
    double *b = malloc(sizeof(double) * (size_t)rows);
    double r0[PM_MAX_TERMS], r1[PM_MAX_TERMS], r[2];
    long i;
    if (!A || !b) {
        free(A);
        free(b);
        return -100;
    }
    for (i = 0; i < d->n; i++) {
        pm_status st = pm_fit_row(m, NULL, d->eh[i], d->ed[i], d->ah[i], d->ad[i], r0, r1, r);
        if (st != PM_OK) {
            free(A);
            free(b);
            return (int)st;
        }
        for (j = 0; j < P; j++) {
            A[(size_t)j * (size_t)rows + (size_t)(2 * i)] = r0[j];
            A[(size_t)j * (size_t)rows + (size_t)(2 * i + 1)] = r1[j];
        }
        b[2 * i] = r[0];
        b[2 * i + 1] = r[1];
    }
    info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', rows, P, 1, A, rows, b, rows);
    if (info == 0) {
        *out = *m;
        for (j = 0; j < P; j++)
            out->coef[j] += b[j];
        if (pm_model_prepare(out) != PM_OK)
            info = -101;
    }
    free(A);
    free(b);
    return (int)info;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The child's work: make the data, run the method, fill *r. */
static void run_case(int order, long n, int method, int whole, int passes, result *r)
{
    data d;
    pm_model m0, out;
    pm_fit_result res;
    double t[200];
    int k, reps;
    memset(r, 0, sizeof *r);
    if (make_data(order, n, &d) != 0 || pm_model_init(&m0, PM_MOUNT_EQUATORIAL, order) != PM_OK) {
        r->status = -200;
        return;
    }
    r->n_par = m0.n_terms;
    {
        /* warm up on the first 100 observations: the code's pages (LAPACK's
        ** are 2 MB) and the static pm_fit are then resident before the
        ** baseline, so "extra" is what grows with the problem */
        data small = d;
        small.n = n < 100 ? n : 100;
        double t2[2] = {now(), now()};
        if (method == OURS)
            pass_ours(&small, &m0, &out, &res);
        else
            pass_dgels(&small, &m0, &out);
        qsort(t2, 2, sizeof(double), cmp_double); /* the C library's first use */
    }
    r->base_kb = peak_kb();
    /* repeats: ~0.2 s worth, from the cost of one (N P^2 multiply-adds) */
    reps = (int)(2e7 / ((double)n * m0.n_terms * m0.n_terms + 1e4) / (whole ? 4 : 1));
    reps = reps < 1 ? 1 : reps > 200 ? 200 : reps;
    for (k = 0; k < reps && r->status == 0; k++) {
        double t0 = now();
        if (!whole) {
            r->status = method == OURS ? pass_ours(&d, &m0, &out, &res)
                                       : pass_dgels(&d, &m0, &out);
            r->passes = 1;
        } else if (method == OURS) {
            out = m0;
            r->status = (int)pm_fit_run(&fit, &out, NULL, d.n, d.eh, d.ed, d.ah, d.ad, 30, &res);
            r->passes = res.iterations;
        } else {
            pm_model cur = m0;
            int p;
            for (p = 0; p < passes && r->status == 0; p++) {
                r->status = pass_dgels(&d, &cur, &out);
                cur = out;
            }
            r->passes = passes;
        }
        t[k] = now() - t0;
    }
    qsort(t, (size_t)k, sizeof(double), cmp_double);
    r->repeats = k;
    r->seconds = t[k / 2];
    if (r->status == 0) {
        memcpy(r->coef, out.coef, sizeof(double) * (size_t)out.n_terms);
        if (method == OURS)
            memcpy(r->err, res.err, sizeof(double) * (size_t)out.n_terms);
    }
    r->peak_kb = peak_kb();
    free(d.eh);
}

/* Run one case in a child process. */
static int forked(int order, long n, int method, int whole, int passes, result *r)
{
    int fd[2];
    pid_t pid;
    ssize_t got = 0;
    if (pipe(fd) != 0)
        return -1;
    fflush(NULL);
    pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        result mine;
        ssize_t put = 0;
        close(fd[0]);
        run_case(order, n, method, whole, passes, &mine);
        while (put < (ssize_t)sizeof mine) {
            ssize_t w = write(fd[1], (char *)&mine + put, sizeof mine - (size_t)put);
            if (w <= 0)
                _exit(1);
            put += w;
        }
        _exit(0);
    }
    close(fd[1]);
    while (got < (ssize_t)sizeof *r) {
        ssize_t g = read(fd[0], (char *)r + got, sizeof *r - (size_t)got);
        if (g <= 0)
            break;
        got += g;
    }
    close(fd[0]);
    waitpid(pid, NULL, 0);
    return got == (ssize_t)sizeof *r ? 0 : -1;
}

static void emit(FILE *out, const char *kind, int order, long n, int method,
                 const result *r, const result *other)
{
    char name[96], vs[96];
    snprintf(name, sizeof name, "fit_%s_%s_L%d_N%ld", kind, method_name[method], order, n);
    fprintf(out, "{\"name\": \"%s\", \"order\": %d, \"n_obs\": %ld, \"n_par\": %d, "
                 "\"method\": \"%s\", \"status\": %d, \"passes\": %d, \"repeats\": %d, "
                 "\"seconds\": %.6g, \"peak_rss_kb\": %ld, \"extra_rss_kb\": %ld",
            name, order, n, r->n_par, method_name[method], r->status, r->passes, r->repeats,
            r->seconds, r->peak_kb, r->peak_kb - r->base_kb);
    if (method == OURS)
        fprintf(out, ", \"fixed_kb\": %.1f", (double)sizeof(pm_fit) / 1024);
    if (method == OURS && other) {
        double dmax = 0, cmax = 0, smax = 0;
        int j;
        for (j = 0; j < r->n_par; j++) {
            double dd = fabs(r->coef[j] - other->coef[j]);
            if (dd > dmax)
                dmax = dd;
            if (fabs(other->coef[j]) > cmax)
                cmax = fabs(other->coef[j]);
            if (r->err[j] > 0 && dd / r->err[j] > smax)
                smax = dd / r->err[j];
        }
        snprintf(vs, sizeof vs, "fit_%s_dgels_L%d_N%ld", kind, order, n);
        if (r->status == 0 && other->status == 0)
            fprintf(out, ", \"ratio_vs\": \"%s\", \"ratio\": %.4g, \"coef_rel_diff\": %.3g, "
                         "\"coef_max_diff_sigma\": %.3g",
                    vs, r->seconds / other->seconds, cmax > 0 ? dmax / cmax : dmax, smax);
    }
    fprintf(out, "}\n");
    fflush(out);
}

int main(int argc, char **argv)
{
    static const int orders[] = {0, 1, 2, 4};
    long max_n = 1000000, n;
    FILE *out = stdout;
    int i, o;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--max-n") && i + 1 < argc)
            max_n = atol(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) {
            if (!(out = fopen(argv[++i], "w"))) {
                perror(argv[i]);
                return 1;
            }
        } else {
            fprintf(stderr, "usage: pmbench_fit [--max-n N] [--out FILE]\n");
            return 2;
        }
    }
    if (PM_MAX_L < 4) {
        fprintf(stderr, "pmbench_fit: needs the library built with PM_MAX_L >= 4\n");
        return 1;
    }
    for (o = 0; o < 4; o++)
        for (n = 100; n <= max_n; n *= 10) {
            result r[2];
            if (forked(orders[o], n, OURS, 0, 0, &r[0]) ||
                forked(orders[o], n, DGELS, 0, 0, &r[1])) {
                fprintf(stderr, "pmbench_fit: a child failed (L=%d, N=%ld)\n", orders[o], n);
                return 1;
            }
            emit(out, "pass", orders[o], n, DGELS, &r[1], 0);
            emit(out, "pass", orders[o], n, OURS, &r[0], &r[1]);
            fprintf(stderr, "fit pass L=%d N=%-8ld ours %.4g s  dgels %.4g s\n", orders[o], n,
                    r[0].seconds, r[1].seconds);
        }
    /* whole Gauss-Newton fits at L = 2 (and L = 4 to a tenth of the largest
    ** N: its dgels fit of 1e6 observations alone would take over a minute) */
    for (o = 2; o <= 4; o += 2)
        for (n = 100; n <= (o == 2 ? max_n : max_n / 10); n *= 10) {
            result r[2];
            if (forked(o, n, OURS, 1, 0, &r[0]) || forked(o, n, DGELS, 1, r[0].passes, &r[1])) {
                fprintf(stderr, "pmbench_fit: a child failed (whole fit, N=%ld)\n", n);
                return 1;
            }
            emit(out, "whole", o, n, DGELS, &r[1], 0);
            emit(out, "whole", o, n, OURS, &r[0], &r[1]);
            fprintf(stderr, "whole fit L=%d N=%-8ld ours %.4g s (%d passes)  dgels %.4g s\n", o,
                    n, r[0].seconds, r[0].passes, r[1].seconds);
        }
    return out != stdout && fclose(out) != 0;
}
