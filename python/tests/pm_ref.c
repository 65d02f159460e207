/*
**  pm_ref.c - the C API called from C, for the Python tests to compare
**  with bit for bit (python/tests/test_roundtrip.py).  Binary files of
**  native doubles in and out (numpy tofile/fromfile).
**
**  pm_ref apply  MODEL CTX IN OUT        IN rows: enc_ha enc_dec [ctx]
**                                        OUT rows: app_ha app_dec
**  pm_ref invert MODEL CTX SIDE IN OUT   IN rows: app_ha app_dec [ctx]
**                                        (SIDE -1: app_ha app_dec start_ha
**                                        start_dec [ctx], pm_model_invert_near)
**                                        OUT rows: enc_ha enc_dec status
**  pm_ref fit    RUN ORDER GRID OUT      pmrun_read (defaults), pm_model_init,
**                                        pm_fit_run (2000 passes, as pmfit);
**                                        OUT: P sigma chi2 iterations, coef[P],
**                                        err[P], cov[P*P], then per GRID row
**                                        (enc_ha enc_dec; "-" for none):
**                                        sigma v11 v12 v22
**  [ctx] (CTX 1): pier temp_c time_h dir aux0 aux1 aux2 aux3.
**  Exit 0, or 1 with a message on stderr at the first failure.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modelfile.h"
#include "pm.h"
#include "runfile.h"

static pm_fit work; /* large: static */

static void die(const char *what)
{
    fprintf(stderr, "pm_ref: %s\n", what);
    exit(1);
}

/* The whole file as doubles; *n their count. */
static double *read_doubles(const char *path, long *n)
{
    FILE *f = fopen(path, "rb");
    double *d;
    long size;
    if (!f)
        die(path);
    fseek(f, 0, SEEK_END);
    size = ftell(f);
    fseek(f, 0, SEEK_SET);
    *n = size / (long)sizeof(double);
    d = malloc((size_t)(*n > 0 ? *n : 1) * sizeof(double));
    if (!d || fread(d, sizeof(double), (size_t)*n, f) != (size_t)*n)
        die("read");
    fclose(f);
    return d;
}

static void write_doubles(const char *path, const double *d, long n)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(d, sizeof(double), (size_t)n, f) != (size_t)n || fclose(f) != 0)
        die("write");
}

static void load(const char *path, pm_model *m)
{
    char err[1024];
    if (pmmodel_load(path, m, err, sizeof err) != 0)
        die(err);
}

static void context(const double *r, pm_context *c)
{
    int j;
    memset(c, 0, sizeof *c);
    c->pier = (int)r[0];
    c->temp_c = r[1];
    c->time_h = r[2];
    c->dir = (int)r[3];
    for (j = 0; j < 4 && j < PM_MAX_AUX; j++)
        c->aux[j] = r[4 + j];
}

static int cmd_apply(int argc, char **argv)
{
    static pm_model m;
    long n, i, w;
    double *in, *out;
    int ctx;
    if (argc != 6)
        die("usage: pm_ref apply MODEL CTX IN OUT");
    load(argv[2], &m);
    ctx = atoi(argv[3]);
    w = ctx ? 10 : 2;
    in = read_doubles(argv[4], &n);
    n /= w;
    out = malloc((size_t)(2 * n + 1) * sizeof(double));
    for (i = 0; i < n; i++) {
        pm_context c;
        const double *r = in + i * w;
        if (ctx)
            context(r + 2, &c);
        if (pm_model_apply(&m, ctx ? &c : NULL, r[0], r[1], &out[2 * i], &out[2 * i + 1]) != PM_OK)
            die("pm_model_apply failed");
    }
    write_doubles(argv[5], out, 2 * n);
    return 0;
}

static int cmd_invert(int argc, char **argv)
{
    static pm_model m;
    long n, i, w;
    double *in, *out;
    int ctx, side;
    if (argc != 7)
        die("usage: pm_ref invert MODEL CTX SIDE IN OUT");
    load(argv[2], &m);
    ctx = atoi(argv[3]);
    side = atoi(argv[4]);
    w = (side < 0 ? 4 : 2) + (ctx ? 8 : 0);
    in = read_doubles(argv[5], &n);
    n /= w;
    out = malloc((size_t)(3 * n + 1) * sizeof(double));
    for (i = 0; i < n; i++) {
        pm_context c;
        const double *r = in + i * w;
        pm_status s;
        if (ctx)
            context(r + (side < 0 ? 4 : 2), &c);
        if (side < 0)
            s = pm_model_invert_near(&m, ctx ? &c : NULL, r[0], r[1], r[2], r[3], &out[3 * i],
                                     &out[3 * i + 1]);
        else
            s = pm_model_invert(&m, ctx ? &c : NULL, r[0], r[1], side, &out[3 * i],
                                &out[3 * i + 1]);
        if (s < 0)
            die("pm_model_invert failed");
        out[3 * i + 2] = (double)s;
    }
    write_doubles(argv[6], out, 3 * n);
    return 0;
}

static int cmd_fit(int argc, char **argv)
{
    static pm_model m;
    pm_fit_result res;
    pmrun *run = NULL;
    char err[1024];
    long n, i, ng = 0, k = 0;
    int p, a, b;
    double *eh, *ed, *ah, *ad, *grid = NULL, *out, lat;
    if (argc != 6)
        die("usage: pm_ref fit RUN ORDER GRID OUT");
    if (pmrun_read(argv[2], NULL, &run, err, sizeof err) != PMRUN_OK)
        die(err);
    n = (long)pmrun_count(run);
    eh = malloc((size_t)n * sizeof(double));
    ed = malloc((size_t)n * sizeof(double));
    ah = malloc((size_t)n * sizeof(double));
    ad = malloc((size_t)n * sizeof(double));
    for (i = 0; i < n; i++) {
        const pmrun_obs *o = pmrun_get(run, (size_t)i);
        eh[i] = o->enc_ha;
        ed[i] = o->enc_dec;
        ah[i] = o->app_ha;
        ad[i] = o->app_dec;
    }
    if (pm_model_init(&m, pmrun_mount(run) == PMRUN_MOUNT_ALTAZ ? PM_MOUNT_ALTAZ
                                                                 : PM_MOUNT_EQUATORIAL,
                      atoi(argv[3])) != PM_OK)
        die("pm_model_init");
    lat = pmrun_latitude_rad(run);
    m.latitude = isnan(lat) ? 0.0 : lat;
    if (pm_model_prepare(&m) != PM_OK)
        die("pm_model_prepare");
    if (pm_fit_run(&work, &m, NULL, n, eh, ed, ah, ad, 2000, &res) != PM_OK)
        die("pm_fit_run failed");
    if (strcmp(argv[4], "-") != 0) {
        grid = read_doubles(argv[4], &ng);
        ng /= 2;
    }
    p = m.n_terms;
    out = malloc((size_t)(4 + 2 * p + p * p + 4 * ng) * sizeof(double));
    out[k++] = p;
    out[k++] = res.sigma;
    out[k++] = res.chi2;
    out[k++] = res.iterations;
    for (a = 0; a < p; a++)
        out[k++] = m.coef[a];
    for (a = 0; a < p; a++)
        out[k++] = res.err[a];
    for (a = 0; a < p; a++)
        for (b = 0; b < p; b++) {
            double c;
            if (pm_fit_covariance(&work, &res, a, b, &c, NULL) != PM_OK)
                die("pm_fit_covariance");
            out[k++] = c;
        }
    for (i = 0; i < ng; i++) {
        double s, v[3];
        if (pm_fit_pointing_sigma(&work, &res, &m, NULL, grid[2 * i], grid[2 * i + 1], &s, v) != PM_OK)
            die("pm_fit_pointing_sigma");
        out[k++] = s;
        out[k++] = v[0];
        out[k++] = v[1];
        out[k++] = v[2];
    }
    write_doubles(argv[5], out, k);
    pmrun_free(run);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "apply") == 0)
        return cmd_apply(argc, argv);
    if (argc > 1 && strcmp(argv[1], "invert") == 0)
        return cmd_invert(argc, argv);
    if (argc > 1 && strcmp(argv[1], "fit") == 0)
        return cmd_fit(argc, argv);
    die("usage: pm_ref apply|invert|fit ...");
    return 1;
}
