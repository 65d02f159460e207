/*
**  check_robust.c - pmfit fit --robust (docs/robust.md): 1% gross outliers
**  (arcminutes, in random directions and concentrated in one part of the
**  sky) move no coefficient by more than 1 sigma of the clean fit, every one
**  of them is reported by its line, a clean run loses (almost) nothing, the
**  real runs, and the edge cases that must be errors.
**
**  Each simulated run is written once clean (pmsim, Gaussian noise 1" per
**  axis) and once with 1% of its points' measured positions moved by 2'-5';
**  the clean fit of the first is the reference, with its 1-sigma errors.
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm.h"
#include "simulate.h"
#include "testutil.h"
#include "tu_tool.h"

#define N_SEEDS 10
#define N_POINTS 300
#define N_OUT 3               /* 1% of N_POINTS */
#define OUT_MIN_ARCSEC 120.0  /* outlier sizes: uniform 2'..5' */
#define OUT_MAX_ARCSEC 300.0
#define MAX_TERMS 128
#define MAX_LINES 20000

/* The default clip K = 4.29 rejects a clean point with probability
** exp(-K^2/2) = 1.0e-4 (Rayleigh tail of the 2-D residual).  Over the 4
** configurations x 10 seeds x 300 points = 12,000 clean points of one pass the
** expected number of false rejections is 1.2 (Poisson: P(more than 6) =
** 1.5e-4); over the two outlier patterns 24,000 points, 2.4 expected
** (P(more than 8) = 1.1e-3).  The bounds are those Poisson quantiles. */
#define FALSE_MAX_CLEAN 6
#define FALSE_MAX_OUTLIERS 8

static char tmpdir[64];
static char out[1 << 20];

/* pmfit with the arguments args; output into out; the exit code. */
static int pmfit(const char *args)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s %s", tu_pmfit_path(), args);
    return tu_capture(cmd, out, sizeof out);
}

typedef struct config {
    const char *name;
    int altaz, order;
} config;

static const config CONFIGS[4] = {
    {"GEM (both pier sides) L=1", 0, 1},
    {"GEM (both pier sides) L=2", 0, 2},
    {"alt-az L=1", 1, 1},
    {"alt-az L=2", 1, 2},
};

/* A clean simulated run: random isotropic terms of 60" RMS, anisotropic of
** 10" RMS, 1" noise per axis. */
static void simulate(const char *path, const config *c, long n, unsigned long long seed)
{
    pmsim_spec s;
    tu_rng r;
    char err[512];
    int i;
    pmsim_default(&s);
    s.n = n;
    s.seed = seed;
    s.noise_arcsec = 1.0;
    pm_model_init(&s.truth, c->altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL, c->order);
    s.truth.latitude = s.latitude_deg * DEG;
    tu_seed(&r, seed * 31 + 7);
    for (i = 0; i < s.truth.n_terms; i++)
        s.truth.coef[i] = (i < 6 ? 60.0 : 10.0) * ARCSEC * tu_gauss(&r);
    ck_assert_int_eq(pm_model_prepare(&s.truth), PM_OK);
    ck_assert_msg(pmsim_write(&s, path, NULL, err, sizeof err) == 0, "%s", err);
}

/* The run file as lines. */
typedef struct lines {
    int n;
    char *l[MAX_LINES];
} lines;

static void read_lines(const char *path, lines *f)
{
    FILE *fp = fopen(path, "r");
    char buf[1024];
    ck_assert_ptr_nonnull(fp);
    f->n = 0;
    while (fgets(buf, sizeof buf, fp) && f->n < MAX_LINES)
        f->l[f->n++] = strdup(buf);
    fclose(fp);
}

static void write_lines(const char *path, const lines *f)
{
    FILE *fp = fopen(path, "w");
    int i;
    ck_assert_ptr_nonnull(fp);
    for (i = 0; i < f->n; i++)
        fputs(f->l[i], fp);
    fclose(fp);
}

static void free_lines(lines *f)
{
    int i;
    for (i = 0; i < f->n; i++)
        free(f->l[i]);
    f->n = 0;
}

static int is_data(const char *s) { return s[0] != '#' && s[0] != '\n' && s[0] != 0; }

/* Measured position (T, D in degrees) of a data line. */
static void measured(const char *s, double *t, double *d)
{
    double e1, e2;
    ck_assert_int_eq(sscanf(s, "%lf %lf %lf %lf", &e1, &e2, t, d), 4);
}

/* Move the measured position of line i by size arcsec toward angle a (on the
** sky: a = 0 along axis 2, pi/2 along axis 1). */
static void displace(lines *f, int i, double size, double a, int altaz)
{
    double e1, e2, t, d;
    int used = 0;
    char buf[1024];
    ck_assert_int_eq(sscanf(f->l[i], "%lf %lf %lf %lf%n", &e1, &e2, &t, &d, &used), 4);
    d += size * cos(a) / 3600.0;
    t += size * sin(a) / 3600.0 / cos(d * DEG);
    if (altaz)
        t = fmod(t + 720.0, 360.0);
    else if (t > 180)
        t -= 360;
    else if (t <= -180)
        t += 360;
    snprintf(buf, sizeof buf, "%.9f %.9f %.9f %.9f%s", e1, e2, t, d, f->l[i] + used);
    free(f->l[i]);
    f->l[i] = strdup(buf);
}

enum { RANDOM, CLUSTER };

/* Replace n_out data points of the run by gross outliers (2'-5'); their
** file lines (1-based) into out_lines.  RANDOM: random points, random
** directions; CLUSTER: the n_out points nearest to a random one, all moved
** the same way (the worst case for a start from all points). */
static void inject_sized(const char *clean, const char *dirty, int pattern, int n_out, int altaz,
                         unsigned long long seed, int *out_lines, double out_min, double out_max)
{
    lines f;
    tu_rng r;
    int cand[MAX_LINES], nc = 0, i, k;
    double a0;
    read_lines(clean, &f);
    tu_seed(&r, seed * 977 + 5);
    for (i = 0; i < f.n; i++)
        if (is_data(f.l[i])) {
            double t, d;
            measured(f.l[i], &t, &d);
            if (fabs(d) < 75) /* away from the pole: the displacement is well defined */
                cand[nc++] = i;
        }
    ck_assert_int_ge(nc, n_out);
    a0 = 2 * M_PI * tu_uniform(&r);
    if (pattern == RANDOM) {
        for (k = 0; k < n_out; k++) {
            int j = k + (int)(tu_uniform(&r) * (nc - k)), tmp = cand[k];
            cand[k] = cand[j];
            cand[j] = tmp;
        }
    } else {
        /* sort the candidates by distance from a random centre */
        double tc, dc, dist[MAX_LINES];
        int c = cand[(int)(tu_uniform(&r) * nc)];
        measured(f.l[c], &tc, &dc);
        for (k = 0; k < nc; k++) {
            double t, d;
            measured(f.l[cand[k]], &t, &d);
            dist[k] = tu_angle(t * DEG, d * DEG, tc * DEG, dc * DEG);
        }
        for (k = 0; k < n_out; k++) {
            int j, best = k;
            for (j = k + 1; j < nc; j++)
                if (dist[j] < dist[best])
                    best = j;
            {
                int ti = cand[k];
                double td = dist[k];
                cand[k] = cand[best];
                dist[k] = dist[best];
                cand[best] = ti;
                dist[best] = td;
            }
        }
    }
    for (k = 0; k < n_out; k++) {
        double size = out_min + (out_max - out_min) * tu_uniform(&r);
        double a = pattern == RANDOM ? 2 * M_PI * tu_uniform(&r) : a0;
        displace(&f, cand[k], size, a, altaz);
        out_lines[k] = cand[k] + 1;
    }
    write_lines(dirty, &f);
    free_lines(&f);
}

static void inject(const char *clean, const char *dirty, int pattern, int n_out, int altaz,
                   unsigned long long seed, int *out_lines)
{
    inject_sized(clean, dirty, pattern, n_out, altaz, seed, out_lines, OUT_MIN_ARCSEC,
                 OUT_MAX_ARCSEC);
}

/* Keep the runs of a failing case beside the temporary directory's files. */
static void keep_failure(const char *clean, const char *dirty)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "cp %s %s.clean; cp %s %s.dirty 2>/dev/null", clean, tmpdir,
             dirty ? dirty : "/dev/null", tmpdir);
    if (system(cmd) != 0)
        printf("could not keep %s\n", clean);
}

/* The coefficients and 1-sigma errors of pmfit --json output; their count. */
static int json_terms(const char *json, double *val, double *err)
{
    const char *p = strstr(json, "\"terms\": [");
    const char *end = p ? strchr(p, ']') : NULL;
    int n = 0;
    ck_assert_msg(p && end, "no terms in: %.400s", json);
    while ((p = strstr(p, "\"value_arcsec\": ")) != NULL && p < end && n < MAX_TERMS) {
        const char *q = strstr(p, "\"error_arcsec\": ");
        ck_assert_ptr_nonnull(q);
        val[n] = atof(p + strlen("\"value_arcsec\": "));
        err[n] = atof(q + strlen("\"error_arcsec\": "));
        n++;
        p = q;
    }
    return n;
}

/* The lines of "robust": {"outliers": [...]} (after the first occurrence
** at or after from); their count. */
static int json_outliers(const char *json, int *ln, double *res, int max)
{
    const char *p = strstr(json, "\"outliers\": [");
    const char *end = p ? strchr(p, ']') : NULL;
    int n = 0;
    ck_assert_msg(p && end, "no robust outliers in: %.400s", json);
    while ((p = strstr(p, "\"line\": ")) != NULL && p < end && n < max) {
        ln[n] = atoi(p + strlen("\"line\": "));
        if (res)
            res[n] = atof(strstr(p, "\"residual_arcsec\": ") + strlen("\"residual_arcsec\": "));
        n++;
        p++;
    }
    return n;
}

static int contains(const int *a, int n, int x)
{
    int i;
    for (i = 0; i < n; i++)
        if (a[i] == x)
            return 1;
    return 0;
}

/* max over the coefficients of |a - ref| / err */
static double max_shift(const double *a, const double *ref, const double *err, int n)
{
    double m = 0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i] - ref[i]) / err[i]);
    return m;
}

static double median3(double *v, int n)
{
    int i, j;
    for (i = 1; i < n; i++)
        for (j = i; j > 0 && v[j - 1] > v[j]; j--) {
            double t = v[j];
            v[j] = v[j - 1];
            v[j - 1] = t;
        }
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The requirement of issue 7: 1% gross outliers move no coefficient by more
** than 1 sigma of the clean fit under --robust; without --robust they do. */
START_TEST(test_robust_one_percent_outliers)
{
    int c, pattern, seed, total_false = 0, plain_ok = 0, runs = 0;
    tu_tmpdir(tmpdir, "pm_robust_");
    printf("robust fit, 1%% outliers of %.0f-%.0f\" (N = %d, %d seeds, noise 1\"): the largest "
           "coefficient shift in units of the clean fit's 1 sigma\n",
           OUT_MIN_ARCSEC, OUT_MAX_ARCSEC, N_POINTS, N_SEEDS);
    printf("  %-28s %-8s %12s %12s %12s %6s %6s\n", "run", "outliers", "robust max", "plain min",
           "plain median", "found", "false");
    for (c = 0; c < 4; c++) {
        const config *cf = &CONFIGS[c];
        double ref[N_SEEDS][MAX_TERMS], err[N_SEEDS][MAX_TERMS];
        int nt[N_SEEDS];
        char clean[128], dirty[128], args[512];
        snprintf(clean, sizeof clean, "%s/clean.dat", tmpdir);
        snprintf(dirty, sizeof dirty, "%s/dirty.dat", tmpdir);
        for (pattern = RANDOM; pattern <= CLUSTER; pattern++) {
            double rob_max = 0, plain[N_SEEDS];
            int found = 0, fals = 0;
            for (seed = 1; seed <= N_SEEDS; seed++) {
                double val[MAX_TERMS], e[MAX_TERMS];
                int inj[N_OUT], rep[64], nrep, k, s = seed - 1;
                simulate(clean, cf, N_POINTS, (unsigned long long)(100 * c + seed));
                if (pattern == RANDOM) {
                    snprintf(args, sizeof args, "fit %s --order %d --json", clean, cf->order);
                    ck_assert_msg(pmfit(args) == 0, "%s", out);
                    nt[s] = json_terms(out, ref[s], err[s]);
                }
                inject(clean, dirty, pattern, N_OUT, cf->altaz, (unsigned long long)seed, inj);
                /* robust */
                snprintf(args, sizeof args, "fit %s --order %d --json --robust", dirty, cf->order);
                ck_assert_msg(pmfit(args) == 0, "%s", out);
                ck_assert_int_eq(json_terms(out, val, e), nt[s]);
                rob_max = fmax(rob_max, max_shift(val, ref[s], err[s], nt[s]));
                if (max_shift(val, ref[s], err[s], nt[s]) > 1.0)
                    keep_failure(clean, dirty);
                ck_assert_msg(max_shift(val, ref[s], err[s], nt[s]) <= 1.0,
                              "%s seed %d pattern %d: a coefficient moved by %.2f sigma (runs "
                              "kept: %s.clean, %s.dirty)",
                              cf->name, seed, pattern, max_shift(val, ref[s], err[s], nt[s]),
                              tmpdir, tmpdir);
                nrep = json_outliers(out, rep, NULL, 64);
                for (k = 0; k < N_OUT; k++) {
                    ck_assert_msg(contains(rep, nrep, inj[k]),
                                  "%s seed %d pattern %d: outlier at line %d not reported",
                                  cf->name, seed, pattern, inj[k]);
                    found++;
                }
                for (k = 0; k < nrep; k++)
                    fals += !contains(inj, N_OUT, rep[k]);
                ck_assert_int_eq((int)tu_json_num(out, "n_obs"), N_POINTS - nrep);
                /* plain least squares on the same data */
                snprintf(args, sizeof args, "fit %s --order %d --json", dirty, cf->order);
                ck_assert_msg(pmfit(args) == 0, "%s", out);
                ck_assert_int_eq(json_terms(out, val, e), nt[s]);
                plain[s] = max_shift(val, ref[s], err[s], nt[s]);
                plain_ok += plain[s] <= 1.0;
                runs++;
            }
            total_false += fals;
            {
                double m = plain[0];
                int k;
                for (k = 1; k < N_SEEDS; k++)
                    m = fmin(m, plain[k]);
                printf("  %-28s %-8s %12.3f %12.2f %12.2f %3d/%-2d %6d\n", cf->name,
                       pattern == RANDOM ? "random" : "cluster", rob_max, m,
                       median3(plain, N_SEEDS), found, N_SEEDS * N_OUT, fals);
            }
        }
    }
    printf("  false rejections: %d of %d clean points (bound %d; expected 2.4 at 1e-4 each)\n",
           total_false, runs * (N_POINTS - N_OUT), FALSE_MAX_OUTLIERS);
    printf("  plain least squares within 1 sigma in %d of %d runs\n", plain_ok, runs);
    ck_assert_int_le(total_false, FALSE_MAX_OUTLIERS);
    /* the requirement is not met without --robust: the test can fail */
    ck_assert_int_eq(plain_ok, 0);
}
END_TEST

/* A fifth of a run's points in one part of the sky, all off the same way
** by 0.5-5 deg (failed solves of one region): the fit of all points leans
** towards them, and clipping from its concentration steps alone kept part
** of the cluster and rejected good points (an outside probe's 120-point
** runs: 8 of 20 wrong German models at sigma 193", or "more than half"
** rejected of a 300-point run that 240 points fit at 1").  The starts of
** order-0 fits of four-point subsets find the majority: every cluster
** point is rejected, at most the expected few clean ones, sigma the
** noise's. */
START_TEST(test_robust_cluster_fifth)
{
    int c, seed, fals = 0, runs = 0;
    tu_tmpdir(tmpdir, "pm_robust_");
    for (c = 0; c < 4; c += 2) {
        const config *cf = &CONFIGS[c];
        char clean[128], dirty[128], args[512];
        snprintf(clean, sizeof clean, "%s/clean.dat", tmpdir);
        snprintf(dirty, sizeof dirty, "%s/dirty.dat", tmpdir);
        for (seed = 1; seed <= N_SEEDS; seed++) {
            enum { N = 120, K = 24 };
            int inj[K], rep[64], nrep, k;
            double sigma;
            simulate(clean, cf, N, (unsigned long long)(700 + 100 * c + seed));
            inject_sized(clean, dirty, CLUSTER, K, cf->altaz, (unsigned long long)(50 + seed),
                         inj, 1800.0, 18000.0);
            snprintf(args, sizeof args, "fit %s --order %d --json --robust", dirty, cf->order);
            ck_assert_msg(pmfit(args) == 0, "%s seed %d: %s", cf->name, seed, out);
            nrep = json_outliers(out, rep, NULL, 64);
            sigma = tu_json_num(out, "sigma_arcsec");
            if (sigma > 1.3)
                keep_failure(clean, dirty);
            ck_assert_msg(sigma <= 1.3, "%s seed %d: sigma %.2f\" for 1\" of noise (runs kept: "
                          "%s.clean, %s.dirty)", cf->name, seed, sigma, tmpdir, tmpdir);
            for (k = 0; k < K; k++)
                ck_assert_msg(contains(rep, nrep, inj[k]), "%s seed %d: line %d not rejected",
                              cf->name, seed, inj[k]);
            fals += nrep - K;
            runs++;
        }
    }
    printf("robust fit, a 20%% cluster of 0.5-5 deg (N = 120, %d runs): every cluster point "
           "rejected, %d clean points rejected\n", runs, fals);
    ck_assert_int_le(fals, FALSE_MAX_CLEAN);
}
END_TEST

/* Small runs: the robust scale comes from 2N - P degrees of freedom (18
** for 12 points at L = 0, 38 for 30 at L = 1), and the threshold K on
** d / sigma_robust rejected a clean point as often as F(2, nu)'s tail says,
** not as the docs promise (K = 4.29: 1e-4; at nu = 18 it is 1.8e-3): an
** outside probe counted 12 of 18,000 clean points of 30-point runs at
** L = 1.  The final threshold is now studentised (docs/robust.md, step 4).
** 200 runs of 30 points at L = 1, German and alt-az, expected 0.6
** rejections at 1e-4 each; the bound is the Poisson 99.9% quantile.  Not
** met, and printed only (docs/robust.md, "What it cannot do"): 12-point runs
** at L = 0 (9 of 3600 where 0.36 are expected; 31 before) and a lower K
** (--clip 3.5: about twice the nominal 2.2e-3; 3.3 times before). */
START_TEST(test_robust_small_runs_false_rate)
{
    static const config small[4] = {
        {"GEM L=0", 0, 0}, {"alt-az L=0", 1, 0}, {"GEM L=1", 0, 1}, {"alt-az L=1", 1, 1}};
    int c, seed, rej[2] = {0, 0}, rej35 = 0, refused = 0;
    tu_tmpdir(tmpdir, "pm_robust_");
    for (c = 0; c < 4; c++) {
        const config *cf = &small[c];
        const int n = cf->order ? 30 : 12, runs = cf->order ? 100 : 150;
        char clean[128], args[512];
        snprintf(clean, sizeof clean, "%s/small.dat", tmpdir);
        for (seed = 1; seed <= runs; seed++) {
            int rep[64];
            simulate(clean, cf, n, (unsigned long long)(5000 + 1000 * c + seed));
            snprintf(args, sizeof args, "fit %s --order %d --json --robust", clean, cf->order);
            ck_assert_msg(pmfit(args) == 0, "%s seed %d: %s", cf->name, seed, out);
            rej[cf->order] += json_outliers(out, rep, NULL, 64);
            if (cf->order) {
                snprintf(args, sizeof args, "fit %s --order 1 --json --robust --clip 3.5", clean);
                if (pmfit(args) == 0)
                    rej35 += json_outliers(out, rep, NULL, 64);
                else
                    refused++;
            }
        }
    }
    printf("robust fit of clean small runs: 12 points at L = 0, %d of 3600 rejected (expected "
           "0.36); 30 points at L = 1, %d of 6000 (expected 0.6), at --clip 3.5 %d (expected 13 "
           "at 2.2e-3 each; %d runs refused)\n", rej[0], rej[1], rej35, refused);
    ck_assert_int_le(rej[1], 4);
}
END_TEST

/* A clean run: --robust rejects at most the expected few, and what it keeps
** fits to the plain fit's coefficients (identical when nothing is rejected,
** to the fit's convergence: 1% of sigma). */
START_TEST(test_robust_clean_run)
{
    int c, seed, total = 0;
    tu_tmpdir(tmpdir, "pm_robust_");
    for (c = 0; c < 4; c++) {
        const config *cf = &CONFIGS[c];
        char clean[128], args[512];
        double worst = 0;
        int rej = 0;
        snprintf(clean, sizeof clean, "%s/clean.dat", tmpdir);
        for (seed = 1; seed <= N_SEEDS; seed++) {
            double ref[MAX_TERMS], err[MAX_TERMS], val[MAX_TERMS], e[MAX_TERMS];
            int n, nrep, rep[64];
            simulate(clean, cf, N_POINTS, (unsigned long long)(100 * c + seed));
            snprintf(args, sizeof args, "fit %s --order %d --json", clean, cf->order);
            ck_assert_msg(pmfit(args) == 0, "%s", out);
            n = json_terms(out, ref, err);
            snprintf(args, sizeof args, "fit %s --order %d --json --robust", clean, cf->order);
            ck_assert_msg(pmfit(args) == 0, "%s", out);
            ck_assert_int_eq(json_terms(out, val, e), n);
            nrep = json_outliers(out, rep, NULL, 64);
            rej += nrep;
            if (nrep == 0) {
                ck_assert_double_le(max_shift(val, ref, err, n), 0.02);
                ck_assert_double_le(fabs(tu_json_num(out, "sigma_arcsec") - 1.0), 0.15);
                worst = fmax(worst, max_shift(val, ref, err, n));
            } else {
                /* a false rejection: a genuine 4.3-sigma point; where its leverage h is
                ** high, leaving it out moves a coefficient by up to about
                ** 4.3 sqrt(h)/(1-h) sigma, so no bound is asserted here */
                printf("clean %s seed %d: %d rejected (%.2f robust sigmas), largest "
                       "coefficient shift %.2f sigma\n",
                       cf->name, seed, nrep, tu_json_num(out, "robust_sigmas"),
                       max_shift(val, ref, err, n));
            }
        }
        printf("clean %-28s: %d of %d points rejected; with none rejected the coefficients "
               "agree to %.4f sigma\n",
               cf->name, rej, N_SEEDS * N_POINTS, worst);
        total += rej;
    }
    ck_assert_int_le(total, FALSE_MAX_CLEAN);
}
END_TEST

/* The report: rejected lines in the table, flagged in --residuals, the
** hint without --robust; --pier split; explain --robust. */
START_TEST(test_robust_report)
{
    char clean[128], dirty[128], res[128], args[1024], line[512];
    int inj[N_OUT], k, flagged = 0, rows = 0, rep[64], nrep;
    FILE *f;
    const config gem = {"GEM L=1", 0, 1};
    tu_tmpdir(tmpdir, "pm_robust_");
    snprintf(clean, sizeof clean, "%s/clean.dat", tmpdir);
    snprintf(dirty, sizeof dirty, "%s/dirty.dat", tmpdir);
    snprintf(res, sizeof res, "%s/res.txt", tmpdir);
    simulate(clean, &gem, N_POINTS, 7);
    inject(clean, dirty, RANDOM, N_OUT, 0, 7, inj);
    /* table: every rejected line as FILE:LINE */
    snprintf(args, sizeof args, "fit %s --robust --residuals %s", dirty, res);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    ck_assert_ptr_nonnull(strstr(out, "robust fit (--robust, clip K = 4.29)"));
    for (k = 0; k < N_OUT; k++) {
        snprintf(line, sizeof line, "dirty.dat:%d  rejected", inj[k]);
        ck_assert_msg(strstr(out, line) != NULL, "%s not in: %s", line, out);
    }
    /* residual file: every point, the rejected ones flagged */
    f = fopen(res, "r");
    ck_assert_ptr_nonnull(f);
    while (fgets(line, sizeof line, f)) {
        int ln, pier, flag;
        double a, b, c, d;
        if (line[0] == '#')
            continue;
        ck_assert_int_eq(sscanf(line, "%d %lf %lf %d %lf %lf %d", &ln, &a, &b, &pier, &c, &d,
                                &flag), 7);
        rows++;
        flagged += flag;
        ck_assert_int_eq(flag, contains(inj, N_OUT, ln));
    }
    fclose(f);
    ck_assert_int_eq(rows, N_POINTS);
    ck_assert_int_eq(flagged, N_OUT);
    /* without --robust: the hint names the lines and the option */
    snprintf(args, sizeof args, "fit %s", dirty);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    ck_assert_msg(strstr(out, "hint: 3 points miss") != NULL && strstr(out, "--robust"), "%s",
                  out);
    for (k = 0; k < N_OUT; k++) {
        snprintf(line, sizeof line, "%d", inj[k]);
        ck_assert_ptr_nonnull(strstr(strstr(out, "hint:"), line));
    }
    /* no hint on the clean run */
    snprintf(args, sizeof args, "fit %s", clean);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    ck_assert_ptr_null(strstr(out, "hint:"));
    /* split by pier side: the two sides together report the outliers */
    snprintf(args, sizeof args, "fit %s --pier split --robust --json", dirty);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    nrep = json_outliers(out, rep, NULL, 64);
    nrep += json_outliers(strstr(out, "\"west\""), rep + nrep, NULL, 64 - nrep);
    ck_assert_int_eq(nrep, N_OUT);
    for (k = 0; k < N_OUT; k++)
        ck_assert(contains(rep, nrep, inj[k]));
    /* explain --robust explains the kept points */
    snprintf(args, sizeof args, "explain %s --robust --json", dirty);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    ck_assert_int_eq((int)tu_json_num(out, "n_obs"), N_POINTS - N_OUT);
    ck_assert_int_eq(json_outliers(out, rep, NULL, 64), N_OUT);
}
END_TEST

/* Edge cases: no majority, too few points, options. */
START_TEST(test_robust_errors)
{
    char clean[128], dirty[128], args[1024];
    int inj[200];
    const config gem = {"GEM L=1", 0, 1};
    tu_tmpdir(tmpdir, "pm_robust_");
    snprintf(clean, sizeof clean, "%s/clean.dat", tmpdir);
    snprintf(dirty, sizeof dirty, "%s/dirty.dat", tmpdir);
    /* 60% of the points gross outliers: no majority, an error (exit 1) */
    simulate(clean, &gem, 200, 3);
    inject(clean, dirty, RANDOM, 120, 0, 3, inj);
    snprintf(args, sizeof args, "fit %s --robust", dirty);
    ck_assert_int_eq(pmfit(args), 1);
    ck_assert_msg(strstr(out, "more than half") != NULL, "%s", out);
    /* (40% is still a majority: the 80 are found) */
    inject(clean, dirty, RANDOM, 80, 0, 3, inj);
    snprintf(args, sizeof args, "fit %s --robust --json", dirty);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    ck_assert_int_eq((int)tu_json_num(out, "n_rejected"), 80);
    /* fewer points than terms (P = 22 at L=1): the plain fit can (2N > P), a
    ** robust fit cannot judge a point */
    simulate(clean, &gem, 20, 4);
    snprintf(args, sizeof args, "fit %s", clean);
    ck_assert_msg(pmfit(args) == 0, "%s", out);
    snprintf(args, sizeof args, "fit %s --robust", clean);
    ck_assert_int_eq(pmfit(args), 1);
    ck_assert_msg(strstr(out, "at least as many observations as terms") != NULL, "%s", out);
    /* clipping would leave fewer points than terms */
    simulate(clean, &gem, 24, 5);
    inject(clean, dirty, RANDOM, 4, 0, 5, inj);
    snprintf(args, sizeof args, "fit %s --robust", dirty);
    ck_assert_int_eq(pmfit(args), 1);
    ck_assert_msg(strstr(out, "would leave") != NULL, "%s", out);
    /* options */
    snprintf(args, sizeof args, "fit %s --clip 3", clean);
    ck_assert_int_eq(pmfit(args), 2);
    ck_assert_ptr_nonnull(strstr(out, "add --robust"));
    snprintf(args, sizeof args, "fit %s --robust --clip 1", clean);
    ck_assert_int_eq(pmfit(args), 2);
    snprintf(args, sizeof args, "eval %s %s --robust", clean, clean);
    ck_assert_int_eq(pmfit(args), 2);
}
END_TEST

/* The real runs at L=1: what --robust rejects (printed); it runs, and every
** reported line is a data line of the file. */
START_TEST(test_robust_realdata)
{
    const char *files[3] = {"mmt/k_and_e.dat", "celestial/gem-28.dat",
                            "celestial/cgx-l-data.dat"};
    char dir[512];
    const char *d = getenv("PM_DATA_DIR");
    int i;
    if (d && *d)
        snprintf(dir, sizeof dir, "%s", d);
    else
        snprintf(dir, sizeof dir, "%s/../shared/data", getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    for (i = 0; i < 3; i++) {
        char path[1024], args[1200];
        int ln[2000], n, k;
        double res[2000];
        lines f;
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        if (access(path, R_OK) != 0) {
            printf("skipped: %s absent\n", path);
            continue;
        }
        snprintf(args, sizeof args, "fit %s --order 1 --json", path);
        ck_assert_msg(pmfit(args) == 0, "%s", out);
        {
            double s_plain = tu_json_num(out, "sigma_arcsec"), s_rob, s_r;
            int n_obs;
            snprintf(args, sizeof args, "fit %s --order 1 --json --robust", path);
            ck_assert_msg(pmfit(args) == 0, "%s", out);
            s_rob = tu_json_num(out, "sigma_arcsec");
            s_r = tu_json_num(out, "sigma_robust_arcsec");
            n_obs = (int)tu_json_num(out, "n_considered");
            n = json_outliers(out, ln, res, 2000);
            printf("%s L=1 --robust: %d of %d rejected, sigma %.3f\" -> %.3f\" (robust sigma "
                   "%.3f\"), lines",
                   files[i], n, n_obs, s_plain, s_rob, s_r);
            for (k = 0; k < n && k < 12; k++)
                printf(" %d (%.0f\")", ln[k], res[k]);
            printf("%s\n", n > 12 ? " ..." : "");
            ck_assert_int_lt(2 * n, n_obs);
            {
                /* every rejected point is beyond the clip in robust sigmas */
                const char *p = out;
                while ((p = strstr(p, "\"robust_sigmas\": ")) != NULL) {
                    ck_assert_double_gt(atof(p + strlen("\"robust_sigmas\": ")), 4.29);
                    p++;
                }
            }
            ck_assert_double_le(s_rob, s_plain);
        }
        read_lines(path, &f);
        for (k = 0; k < n; k++) {
            ck_assert_int_ge(ln[k], 1);
            ck_assert_int_le(ln[k], f.n);
            ck_assert_msg(is_data(f.l[ln[k] - 1]), "%s:%d is not a data line", files[i], ln[k]);
        }
        free_lines(&f);
    }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("robust");
    TCase *tc = tcase_create("requirement");
    tcase_add_test(tc, test_robust_one_percent_outliers);
    tcase_add_test(tc, test_robust_clean_run);
    tcase_add_test(tc, test_robust_cluster_fifth);
    tcase_add_test(tc, test_robust_small_runs_false_rate);
    tcase_set_timeout(tc, 600);
    suite_add_tcase(s, tc);
    tc = tcase_create("report");
    tcase_add_test(tc, test_robust_report);
    tcase_add_test(tc, test_robust_errors);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);
    tc = tcase_create("realdata");
    tcase_add_test(tc, test_robust_realdata);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
