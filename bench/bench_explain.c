/*
**  bench_explain.c - how long pmfit explain takes on a large run (issue 15:
**  10,000 points in under 5 s).
**
**    pmbench_explain [--max-n N] [--out FILE]
**
**  For N = 1,000, 3,000, 10,000 and 30,000 (up to --max-n, default 10,000) simulated
**  points (pmsim: a German mount at latitude 47, 1" noise, arcminute
**  isotropic terms, every L = 1 term random within 10", and two hidden
**  effects: refraction 1" and an HA periodic error of 1.5" at G = 240),
**  the whole explain (baseline, locate, both periodograms, every
**  candidate, cross-validation, pairs when needed, interpretation) through
**  pmx_explain, which also reads the run file: wall time (CLOCK_MONOTONIC),
**  the best of three runs (one at N > 10,000), and what it found.
**  Output: one JSON object per line (bench/report.py reads them).
**
**    pmbench_explain --file PATH NAME [--out FILE]
**
**  times pmx_explain on the run file PATH instead (best of three), the line
**  named NAME: `make bench` gives it a 10,000-point run of the independent
**  gimbal (tests/ref/indep_gen.py) with 10' of anisotropy, where explain
**  composes its baseline as a gimbal and reads the composition again with
**  what it found (docs/explain.md), two searches where the simulated run
**  above needs one.
*/
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pm.h"
#include "explain.h"
#include "simulate.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int make_run(long n, const char *path)
{
    pmsim_spec s;
    char err[512];
    int i;
    unsigned long long x = 12345;
    const double as = M_PI / 180 / 3600;
    pmsim_default(&s);
    s.n = n;
    s.seed = 7;
    s.minutes_per_point = 600.0 / (double)n; /* one ten-hour night */
    pm_model_init(&s.truth, PM_MOUNT_EQUATORIAL, 1);
    s.truth.latitude = 47 * M_PI / 180;
    s.truth.coef[0] = 60 * as;
    s.truth.coef[1] = -40 * as;
    s.truth.coef[2] = 600 * as;
    s.truth.coef[4] = -300 * as;
    for (i = 6; i < s.truth.n_terms; i++) {
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        s.truth.coef[i] = ((double)(x >> 11) / 9007199254740992.0 * 2 - 1) * 10 * as;
    }
    pm_model_prepare(&s.truth);
    if (pmsim_add_effect(&s, "refraction", 1.0, 0, 1, err, sizeof err) != 0 ||
        pmsim_add_effect(&s, "ha_periodic:240", 1.5, 30, 1, err, sizeof err) != 0 ||
        pmsim_write(&s, path, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "pmbench_explain: %s\n", err);
        return -1;
    }
    return 0;
}

/* The best of three pmx_explain calls on path: one JSON line named name. */
static int time_file(const char *path, const char *name, long n, FILE *out)
{
    static pmx_result r;
    char err[512], found[256] = "";
    double best = 1e30;
    int rep, reps = n > 10000 ? 1 : 3, f;
    for (rep = 0; rep < reps; rep++) {
        double t0 = now(), t;
        if (pmx_explain(path, 1, 0.01, &r, err, sizeof err) != 0) {
            fprintf(stderr, "pmbench_explain: %s\n", err);
            return -1;
        }
        t = now() - t0;
        if (t < best)
            best = t;
    }
    for (f = 0; f < r.n_findings; f++)
        snprintf(found + strlen(found), sizeof found - strlen(found), "%s\"%s\"", f ? ", " : "",
                 r.findings[f].effect);
    fprintf(out,
            "{\"name\": \"%s\", \"n_obs\": %ld, \"seconds\": %.4f, \"base_sigma_arcsec\": "
            "%.4f, \"final_sigma_arcsec\": %.4f, \"composition_rms_arcsec\": %.4f, "
            "\"findings\": [%s]}\n",
            name, n, best, r.base_sigma_arcsec, r.final_sigma_arcsec, r.compose_rms_arcsec, found);
    fflush(out);
    fprintf(stderr, "pmbench_explain: %s (N = %ld): %.3f s, composition %.3f\", found %s\n", name,
            n, best, r.compose_rms_arcsec, found);
    return 0;
}

/* The observations of a run file: its lines that are not comments. */
static long count_points(const char *path)
{
    FILE *f = fopen(path, "r");
    char line[1024];
    long n = 0;
    if (!f)
        return -1;
    while (fgets(line, sizeof line, f))
        if (line[0] != '#' && line[0] != '\n')
            n++;
    fclose(f);
    return n;
}

int main(int argc, char **argv)
{
    static const long sizes[] = {1000, 3000, 10000, 30000};
    long max_n = 10000;
    const char *outpath = NULL;
    char dir[64] = "/tmp/pm_bench_explain_XXXXXX", path[128];
    FILE *out = stdout;
    size_t k;
    int i;
    const char *file = NULL, *file_name = NULL;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--max-n") && i + 1 < argc)
            max_n = atol(argv[++i]);
        else if (!strcmp(argv[i], "--file") && i + 2 < argc) {
            file = argv[++i];
            file_name = argv[++i];
        }
        else if (!strcmp(argv[i], "--out") && i + 1 < argc)
            outpath = argv[++i];
        else {
            fprintf(stderr, "usage: pmbench_explain [--max-n N] [--out FILE]\n"
                            "       pmbench_explain --file PATH NAME [--out FILE]\n");
            return 2;
        }
    }
    if (file) {
        long n = count_points(file);
        if (n < 0) {
            perror(file);
            return 1;
        }
        if (outpath && !(out = fopen(outpath, "a"))) {
            perror(outpath);
            return 1;
        }
        i = time_file(file, file_name, n, out);
        if (outpath)
            fclose(out);
        return i ? 1 : 0;
    }
    if (!mkdtemp(dir)) {
        perror("pmbench_explain: mkdtemp");
        return 1;
    }
    if (outpath && !(out = fopen(outpath, "w"))) {
        perror(outpath);
        return 1;
    }
    snprintf(path, sizeof path, "%s/run.dat", dir);
    for (k = 0; k < sizeof sizes / sizeof sizes[0] && sizes[k] <= max_n; k++) {
        char name[32];
        snprintf(name, sizeof name, "explain_N%ld", sizes[k]);
        if (make_run(sizes[k], path) != 0 || time_file(path, name, sizes[k], out) != 0)
            return 1;
    }
    unlink(path);
    rmdir(dir);
    if (outpath)
        fclose(out);
    return 0;
}
