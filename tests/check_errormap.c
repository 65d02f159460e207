/*
**  check_errormap.c - the predicted error map (pm_fit_pointing_sigma):
**  the 1-sigma uncertainty of the fitted model's correction at a sky
**  position, from the fit's covariance, against the real error of fitted
**  models at held-out positions.
**
**  40 runs of one mount (order 1 truth: arcminute isotropic terms, 15"
**  anisotropic ones; 1" noise) observed on the EAST half of the sky only
**  (hour angle < 0, 60 points above 10 deg), each fitted at L = 1; at 300
**  held-out positions over the whole sky above 10 deg the error of the
**  fitted correction (fitted model minus the truth, per axis) is compared
**  with the predicted sigma: the ratio of the RMS of the one to the RMS of
**  the other within 20% on the sampled half and on the unsampled half
**  (where the model extrapolates and the predicted sigma is larger), and
**  with the model noise-free, on each position's own (the 2x2 covariance).
**  pmfit fit's map (--json "error_map", --error-map FILE.svg) agrees with
**  the C API at the run's own points.  pm_fit_point_gain (the allocation-
**  free I-optimal score of one more star) equals the fall of the mean
**  predicted variance of the refit with that star taken (1e-6).
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "runfile.h"
#include "testutil.h"
#include "tu_tool.h"

#define RUNS 40
#define NTRAIN 60
#define NHELD 300
#define LAT (47 * DEG)

static pm_fit fit; /* large: static */

/* The first `cap` points of a run file as four arrays; their number, and
** whether the run is alt-az. */
static size_t read_points(const char *path, double *eh, double *ed, double *ah, double *ad,
                          size_t cap, int *altaz)
{
    char err[512];
    pmrun_options ro;
    pmrun *run = NULL;
    size_t i, n;
    pmrun_options_default(&ro);
    ck_assert_msg(pmrun_read(path, &ro, &run, err, sizeof err) == 0, "%s", err);
    n = pmrun_count(run) < cap ? pmrun_count(run) : cap;
    for (i = 0; i < n; i++) {
        const pmrun_obs *o = pmrun_get(run, i);
        eh[i] = o->enc_ha;
        ed[i] = o->enc_dec;
        ah[i] = o->app_ha;
        ad[i] = o->app_dec;
    }
    if (altaz)
        *altaz = pmrun_mount(run) == PMRUN_MOUNT_ALTAZ;
    pmrun_free(run);
    return n;
}

/* The RMS of the fit's predicted sigma at n encoder positions (radians). */
static double sigma_at(const pm_fit_result *res, const pm_model *m, const double *eh,
                       const double *ed, size_t n)
{
    double ss = 0;
    size_t i;
    for (i = 0; i < n; i++) {
        double s;
        ck_assert_int_eq(pm_fit_pointing_sigma(&fit, res, m, NULL, eh[i], ed[i], &s, NULL), PM_OK);
        ss += s * s;
    }
    return sqrt(ss / (double)n);
}

static void truth_model(pm_model *m)
{
    tu_rng r;
    int i;
    static const double iso[6] = {60, -40, 600, 30, -300, 20};
    ck_assert_int_eq(pm_model_init(m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    for (i = 0; i < 6; i++)
        m->coef[i] = iso[i] * ARCSEC;
    tu_seed(&r, 4242);
    for (i = 6; i < m->n_terms; i++)
        m->coef[i] = (2 * tu_uniform(&r) - 1) * 15 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(m), PM_OK);
}

/* A position above 10 deg elevation; east: hour angle < 0. */
static void position(tu_rng *r, int east_only, double *t, double *d)
{
    double alt;
    do {
        *t = (2.0 * tu_uniform(r) - 1.0) * M_PI;
        *d = asin(2.0 * tu_uniform(r) - 1.0);
        alt = asin(sin(LAT) * sin(*d) + cos(LAT) * cos(*d) * cos(*t));
    } while (alt < 10 * DEG || (east_only && *t >= 0));
}

/* Tangent-plane error of model a against b at encoder (t, d), per axis
** (along the hour angle on the sky, along the declination). */
static void error_of(const pm_model *a, const pm_model *b, double t, double d, double e[2])
{
    double ta, da, tb, db;
    ck_assert_int_eq(pm_model_apply(a, NULL, t, d, &ta, &da), PM_OK);
    ck_assert_int_eq(pm_model_apply(b, NULL, t, d, &tb, &db), PM_OK);
    e[0] = remainder(ta - tb, 2 * M_PI) * cos(db);
    e[1] = da - db;
}

START_TEST(test_errormap_matches_heldout)
{
    static double eh[NTRAIN], ed[NTRAIN], ah[NTRAIN], ad[NTRAIN];
    pm_model truth, m;
    tu_rng r, h;
    int run, i, side;
    /* [side] sums: squared real error, predicted variance; chi^2 of the
    ** 2x2 form */
    double err2[2] = {0, 0}, pred2[2] = {0, 0}, chi2 = 0;
    long n[2] = {0, 0}, nchi = 0;
    truth_model(&truth);
    tu_seed(&r, 777);
    for (run = 0; run < RUNS; run++) {
        pm_fit_result res;
        for (i = 0; i < NTRAIN; i++) {
            position(&r, 1, &eh[i], &ed[i]);
            ck_assert_int_eq(pm_model_apply(&truth, NULL, eh[i], ed[i], &ah[i], &ad[i]), PM_OK);
            ad[i] += 1.0 * ARCSEC * tu_gauss(&r);
            ah[i] += 1.0 * ARCSEC * tu_gauss(&r) / cos(ad[i]);
        }
        ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
        ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, NTRAIN, eh, ed, ah, ad, 50, &res), PM_OK);
        tu_seed(&h, 991 + (unsigned long long)run);
        for (i = 0; i < NHELD; i++) {
            double t, d, e[2], s, c[3], det;
            position(&h, 0, &t, &d);
            side = t < 0 ? 0 : 1;
            ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, t, d, &s, c), PM_OK);
            error_of(&m, &truth, t, d, e);
            err2[side] += 0.5 * (e[0] * e[0] + e[1] * e[1]);
            pred2[side] += s * s;
            n[side]++;
            det = c[0] * c[2] - c[1] * c[1];
            if (det > 0) {
                chi2 += (c[2] * e[0] * e[0] - 2 * c[1] * e[0] * e[1] + c[0] * e[1] * e[1]) / det;
                nchi++;
            }
        }
    }
    for (side = 0; side < 2; side++) {
        double real = sqrt(err2[side] / (double)n[side]), pred = sqrt(pred2[side] / (double)n[side]);
        printf("check_errormap: %s half: predicted %.3f\", real %.3f\" (ratio %.3f, %ld positions)\n",
               side ? "unsampled (west)" : "sampled (east)", pred / ARCSEC, real / ARCSEC,
               real / pred, n[side]);
        ck_assert_msg(fabs(real / pred - 1) <= 0.2, "%s half: real/predicted %.3f",
                      side ? "west" : "east", real / pred);
    }
    printf("check_errormap: chi^2 per position with the 2x2 covariance %.3f (2 expected)\n",
           chi2 / (double)nchi);
    ck_assert(fabs(chi2 / (double)nchi / 2 - 1) <= 0.2);
    ck_assert(pred2[1] / (double)n[1] > 2 * pred2[0] / (double)n[0]); /* extrapolation shows */
}
END_TEST

START_TEST(test_errormap_errors)
{
    static double eh[30], ed[30], ah[30], ad[30];
    pm_model truth, m, other;
    pm_fit_result res;
    tu_run run;
    double s, c[3];
    int i;
    truth_model(&truth);
    ck_assert_int_eq(tu_simulate(&run, &truth, 30, LAT, 0, 1 * ARCSEC, 5), 0);
    for (i = 0; i < 30; i++) {
        eh[i] = run.eh[i];
        ed[i] = run.ed[i];
        ah[i] = run.ah[i];
        ad[i] = run.ad[i];
    }
    tu_run_free(&run);
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 0), PM_OK);
    ck_assert_int_eq(pm_fit_init(&fit, &m), PM_OK);
    memset(&res, 0, sizeof res);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, 0.1, 0.2, &s, c), PM_ERR_STATE);
    ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, 30, eh, ed, ah, ad, 50, &res), PM_OK);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, 0.1, 0.2, &s, NULL), PM_OK);
    ck_assert(s > 0 && s < res.sigma); /* 30 points know an order-0 model better than one point */
    ck_assert_int_eq(pm_fit_pointing_sigma(NULL, &res, &m, NULL, 0.1, 0.2, &s, c), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, NULL, &m, NULL, 0.1, 0.2, &s, c), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, NULL, NULL, 0.1, 0.2, &s, c), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, 0.1, 0.2, NULL, c), PM_ERR_ARG);
    ck_assert_int_eq(pm_model_init(&other, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    ck_assert_int_eq(pm_model_prepare(&other), PM_OK);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &other, NULL, 0.1, 0.2, &s, c), PM_ERR_ARG);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, NAN, 0.2, &s, c), PM_ERR_NONFINITE);
    ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, 0.1, INFINITY, &s, c),
                     PM_ERR_NONFINITE);
    {
        double sky[4] = {0.1, 0.2, -0.3, 0.5}, g;
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, 0.1, 0.2, sky, 2, &g), PM_OK);
        ck_assert(g > 0);
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, 0.1, 0.2, sky, 0, &g), PM_ERR_ARG);
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, 0.1, 0.2, NULL, 2, &g), PM_ERR_ARG);
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, 0.1, 0.2, sky, 2, NULL), PM_ERR_ARG);
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &other, NULL, 0.1, 0.2, sky, 2, &g), PM_ERR_ARG);
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, NAN, 0.2, sky, 2, &g), PM_ERR_NONFINITE);
        sky[3] = NAN;
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, 0.1, 0.2, sky, 2, &g), PM_ERR_NONFINITE);
        sky[3] = 0.5;
        {
            /* no noise (sigma = 0, or one whose square underflows): S = 0,
            ** PM_ERR_SINGULAR (pm.h, pm_fit_point_gain Note 3), g untouched */
            pm_fit_result r0 = res;
            const double sig[2] = {0.0, 1e-160};
            int k;
            for (k = 0; k < 2; k++) {
                r0.sigma = sig[k];
                g = -7.0;
                ck_assert_int_eq(pm_fit_point_gain(&fit, &r0, &m, NULL, 0.1, 0.2, sky, 2, &g),
                                 PM_ERR_SINGULAR);
                ck_assert(g == -7.0);
            }
        }
    }
}
END_TEST

/* pmfit fit reports the map (its value at the stars is the C API's), and
** draws it. */
START_TEST(test_errormap_pmfit)
{
    static double eh[400], ed[400], ah[400], ad[400];
    static char out[1 << 16];
    const char *top = getenv("PM_TOP");
    char path[512], cmd[2048], dir[64], svg[128];
    pm_model m;
    pm_fit_result res;
    size_t n;
    double at_c, at;
    snprintf(path, sizeof path, "%s/tests/data/flip_gem_pm180.dat", top ? top : ".");
    n = read_points(path, eh, ed, ah, ad, 400, NULL);
    ck_assert(n < 400);
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, (long)n, eh, ed, ah, ad, 50, &res), PM_OK);
    at_c = sigma_at(&res, &m, eh, ed, n) / ARCSEC;
    tu_tmpdir(dir, "pm_errormap_");
    snprintf(svg, sizeof svg, "%s/map.svg", dir);
    snprintf(cmd, sizeof cmd, "%s fit '%s' --json --error-map %s", tu_pmfit_path(), path, svg);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    {
        const char *em = strstr(out, "\"error_map\"");
        ck_assert_ptr_nonnull(em);
        at = tu_json_num(em, "at_points_arcsec");
        printf("check_errormap: flip_gem at the stars: pmfit %.6f\", C API %.6f\"; over the sky "
               "%.3f\", max %.3f\"\n", at, at_c,
               tu_json_num(em, "rms_arcsec"), tu_json_num(em, "max_arcsec"));
        ck_assert(fabs(at - at_c) <= 1e-4 * at);
        ck_assert(tu_json_num(em, "max_arcsec") > tu_json_num(em, "rms_arcsec"));
        ck_assert(tu_json_num(em, "rms_arcsec") >= at);
    }
    {
        FILE *f = fopen(svg, "r");
        size_t k = 0;
        int c, rects = 0;
        char win[6] = {0};
        ck_assert_ptr_nonnull(f);
        while ((c = fgetc(f)) != EOF) {
            memmove(win, win + 1, 4);
            win[4] = (char)c;
            rects += !strncmp(win, "<rect", 5);
            k++;
        }
        fclose(f);
        ck_assert_int_gt(rects, 500); /* the cells of the map */
    }
    /* an unwritable map: an error, nothing computed is lost (the report is
    ** printed first) */
    snprintf(cmd, sizeof cmd, "%s fit '%s' --error-map /nonexistent/dir/map.svg", tu_pmfit_path(), path);
    ck_assert(tu_capture(cmd, out, sizeof out) != 0);
    ck_assert_ptr_nonnull(strstr(out, "/nonexistent/dir"));
}
END_TEST

/* At the stars the predicted variance sums to the trace of the hat matrix:
** P sigma^2 over the 2N components, so its RMS per axis is exactly
** sigma sqrt(P / 2N) when the covariance is taken at the returned model.
** pm_fit_run's converging pass takes it at the point before its step; in an
** ill-conditioned fit the step moves the Jacobian (an outside probe's 15
** stars for 22 terms, ~400 passes: 6.2" at the stars for sigma 1.39", which
** a linear fit cannot exceed; the first 12 stars of gem-28: 633" for 29.7",
** where 27.9" is at the returned model).
** pm_fit_run now takes it there (pm.h, pm_fit_run Note 2). */
START_TEST(test_errormap_at_stars_is_trace)
{
    static double eh[400], ed[400], ah[400], ad[400];
    const char *top = getenv("PM_TOP");
    char path[512];
    int k;
    for (k = 0; k < 3; k++) {
        pm_model m;
        pm_fit_result res;
        size_t n;
        int altaz;
        double at, want;
        if (k == 0)
            snprintf(path, sizeof path, "%s/tests/data/outside_altaz_patch15.dat", top ? top : ".");
        else if (k == 1)
            snprintf(path, sizeof path, "%s/tests/data/flip_gem_pm180.dat", top ? top : ".");
        else if (!tu_real_run("celestial/gem-28.dat", path, sizeof path))
            break;
        /* (gem-28: its first 12 stars, in one patch) */
        n = read_points(path, eh, ed, ah, ad, k == 2 ? 12 : 400, &altaz);
        ck_assert(n < 400);
        ck_assert_int_eq(pm_model_init(&m, altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL, 1), PM_OK);
        ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, (long)n, eh, ed, ah, ad, 2000, &res), PM_OK);
        at = sigma_at(&res, &m, eh, ed, n);
        want = res.sigma * sqrt((double)m.n_terms / (2.0 * (double)n));
        printf("check_errormap: %s (%zu stars, %d passes): at the stars %.4f\", sigma "
               "sqrt(P/2N) %.4f\"\n",
               k == 0 ? "outside_altaz_patch15" : k == 1 ? "flip_gem" : "gem-28's first 12", n,
               res.iterations, at / ARCSEC, want / ARCSEC);
        /* (pm_fit_pointing_sigma takes the rows at the model's own
        ** prediction, not at the observed place: gem-28's residuals of 30"
        ** in a fit this ill-conditioned move them by 2%) */
        ck_assert(fabs(at / want - 1) < (k == 2 ? 0.05 : 1e-3));
    }
}
END_TEST

/* Keep the records of a named-column run below 40 deg (the 4th field). */
static int below_40(char *line, size_t size, void *arg)
{
    double v[4];
    (void)size;
    (void)arg;
    if (line[0] == '#' || sscanf(line, "%lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3]) != 4)
        return 1;
    return v[3] < 40;
}

/* The map's RMS is the average over the sky's area: pmfit fit's rms_arcsec
** against the C API's predicted sigma at 40,000 places drawn uniformly on
** the sphere above the map's limit (2%), for an alt-az run whose stars lie
** below 40 deg.  The cells had been weighted by cos(el) on top of their
** equal areas, so by cos^2: 27.7" for this run's 52.1" (the zenith, which
** its stars do not reach, counted for little; an outside probe: actual/
** predicted 1.78 on such runs, 0.94 weighted by area). */
START_TEST(test_errormap_rms_is_area_average)
{
    static double eh[400], ed[400], ah[400], ad[400];
    static char out[1 << 16];
    char dir[64], all[128], low[128], cmd[1024];
    pm_model m;
    pm_fit_result res;
    tu_rng r;
    size_t n;
    long nk = 0;
    double ss = 0, lim, rms, mc, at;
    const char *em;
    tu_tmpdir(dir, "pm_errormap_");
    snprintf(all, sizeof all, "%s/all.dat", dir);
    snprintf(low, sizeof low, "%s/low.dat", dir);
    snprintf(cmd, sizeof cmd, "%s simulate '%s' --mount altaz --n 300 --seed 11 --el-limit 15",
             tu_pmfit_path(), all);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    tu_edited_copy(all, low, below_40, NULL);
    snprintf(cmd, sizeof cmd, "%s fit '%s' --json", tu_pmfit_path(), low);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    em = strstr(out, "\"error_map\"");
    ck_assert_ptr_nonnull(em);
    lim = tu_json_num(em, "limit_deg");
    rms = tu_json_num(em, "rms_arcsec");
    n = read_points(low, eh, ed, ah, ad, 400, NULL);
    ck_assert(n > 40 && n < 400);
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_ALTAZ, 1), PM_OK);
    ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, (long)n, eh, ed, ah, ad, 50, &res), PM_OK);
    tu_seed(&r, 2024);
    while (nk < 40000) {
        double az = 2 * M_PI * tu_uniform(&r), el = asin(2 * tu_uniform(&r) - 1), s;
        if (el < lim * DEG)
            continue;
        ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, az, el, &s, NULL), PM_OK);
        ss += s * s;
        nk++;
    }
    mc = sqrt(ss / (double)nk) / ARCSEC;
    at = sigma_at(&res, &m, eh, ed, n) / ARCSEC;
    printf("check_errormap: %zu alt-az stars below 40 deg: the map's RMS above %.0f deg %.3f\", "
           "the area average %.3f\" (at the stars %.3f\", C API %.3f\")\n",
           n, lim, rms, mc, tu_json_num(em, "at_points_arcsec"), at);
    ck_assert(fabs(tu_json_num(em, "at_points_arcsec") - at) <=
              1e-4 * tu_json_num(em, "at_points_arcsec")); /* the same fit */
    ck_assert_msg(fabs(rms / mc - 1) <= 0.02, "map %.3f\", area average %.3f\"", rms, mc);
}
END_TEST

/* A German run all on its flipped side (the independent gimbal's W records,
** beyond the pole and west of the meridian: tests/ref/indep_gen.py, the
** file's first lines): the map takes the east sky on the side the mount
** must use there, the normal side, which the run never sampled, as pmfit
** plan does.  It took every place on the side of its nearest star: 1.8" RMS
** and "undetermined": false where that side's own covariance gives 24" (an
** outside probe).  A run with no point beyond the pole may be of a fork and
** keeps its nearest star's side everywhere (the rule put a fork's unsampled
** west on the side it never uses: 32" predicted where it erred by 4.2"). */
START_TEST(test_errormap_side_never_used)
{
    static char out[1 << 16];
    const char *top = getenv("PM_TOP");
    char path[512], cmd[2048];
    const char *em;
    snprintf(path, sizeof path, "%s/tests/data/indep_gem_flipped_side.dat", top ? top : ".");
    snprintf(cmd, sizeof cmd, "%s fit '%s' --json 2>/dev/null", tu_pmfit_path(), path);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    em = strstr(out, "\"error_map\"");
    ck_assert_ptr_nonnull(em);
    printf("check_errormap: flipped side only: over the sky %.2f\", at the stars %.3f\"\n",
           tu_json_num(em, "rms_arcsec"), tu_json_num(em, "at_points_arcsec"));
    ck_assert(tu_json_num(em, "rms_arcsec") > 10 * tu_json_num(em, "at_points_arcsec"));
    ck_assert_ptr_nonnull(strstr(em, "\"max_at_deg\": ["));
    ck_assert(atof(strstr(em, "\"max_at_deg\": [") + 15) < -15); /* HA: in the east */
    ck_assert_ptr_nonnull(strstr(em, "\"undetermined\": true"));
}
END_TEST

/* A model of one pier side (pmfit fit --pier split) is mapped where the
** mount uses that side: beyond the meridian limit on its own half of the
** sky, and within it.  Each side's model had been mapped over the whole sky,
** half of it where the mount never takes that side: flip_gem's 4.2" and
** 3.8" for 0.32" at the stars, and gem-28's west model "undetermined"
** (393", 3.35 times its sigma; an outside probe).  Those RMS were weighted
** by cos^2 of the declination; weighted by area (stop 42), flip_gem's sides
** read 0.87" and 1.01", 2.7 and 3.1 times their value at the stars, so the
** bound is 5 times (the whole sky had been 13 times). */
START_TEST(test_errormap_split_sides)
{
    static char out[1 << 16];
    static const char *const sides[2] = {"\"east\"", "\"west\""};
    const char *top = getenv("PM_TOP");
    char path[512], cmd[2048];
    int k, real;
    for (real = 0; real < 2; real++) {
        if (!real)
            snprintf(path, sizeof path, "%s/tests/data/flip_gem_pm180.dat", top ? top : ".");
        else if (!tu_real_run("celestial/gem-28.dat", path, sizeof path))
            break;
        snprintf(cmd, sizeof cmd, "%s fit '%s' --pier split --json 2>/dev/null", tu_pmfit_path(),
                 path);
        ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
        for (k = 0; k < 2; k++) {
            const char *sd = strstr(out, sides[k]), *em;
            ck_assert_ptr_nonnull(sd);
            em = strstr(sd, "\"error_map\"");
            ck_assert_ptr_nonnull(em);
            printf("check_errormap: %s, the %s model: over its side's sky %.3f\", at the stars "
                   "%.3f\"\n", real ? "gem-28" : "flip_gem", sides[k], tu_json_num(em, "rms_arcsec"),
                   tu_json_num(em, "at_points_arcsec"));
            ck_assert(tu_json_num(em, "rms_arcsec") < 5 * tu_json_num(em, "at_points_arcsec"));
            ck_assert_ptr_nonnull(strstr(em, "\"undetermined\": false"));
        }
    }
}
END_TEST

/* pm_fit_point_gain against the refit with the star taken: the fall of the
** mean predicted variance over the places (each fit's variance scaled by
** its own sigma^2, since one more star changes sigma a little). */
START_TEST(test_point_gain_matches_refit)
{
    static double eh[NTRAIN + 1], ed[NTRAIN + 1], ah[NTRAIN + 1], ad[NTRAIN + 1];
    static double sky[2 * 200];
    pm_model truth, m;
    pm_fit_result res, res2;
    tu_rng r;
    int i, c;
    truth_model(&truth);
    tu_seed(&r, 31);
    for (i = 0; i < NTRAIN; i++) {
        position(&r, 1, &eh[i], &ed[i]);
        ck_assert_int_eq(pm_model_apply(&truth, NULL, eh[i], ed[i], &ah[i], &ad[i]), PM_OK);
        ad[i] += 1.0 * ARCSEC * tu_gauss(&r);
        ah[i] += 1.0 * ARCSEC * tu_gauss(&r) / cos(ad[i]);
    }
    for (i = 0; i < 200; i++)
        position(&r, 0, &sky[2 * i], &sky[2 * i + 1]);
    for (c = 0; c < 3; c++) {
        double t, d, gain, before = 0, after = 0, s;
        ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
        ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, NTRAIN, eh, ed, ah, ad, 50, &res), PM_OK);
        position(&r, c != 1, &t, &d); /* sampled half, unsampled half, sampled half */
        ck_assert_int_eq(pm_fit_point_gain(&fit, &res, &m, NULL, t, d, sky, 200, &gain), PM_OK);
        for (i = 0; i < 200; i++) {
            ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res, &m, NULL, sky[2 * i], sky[2 * i + 1],
                                                   &s, NULL), PM_OK);
            before += s * s / 200;
        }
        /* the star taken where the model predicts it (no residual): the
        ** refit's covariance is the update's */
        eh[NTRAIN] = t;
        ed[NTRAIN] = d;
        ck_assert_int_eq(pm_model_apply(&m, NULL, t, d, &ah[NTRAIN], &ad[NTRAIN]), PM_OK);
        ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, NTRAIN + 1, eh, ed, ah, ad, 50, &res2), PM_OK);
        for (i = 0; i < 200; i++) {
            ck_assert_int_eq(pm_fit_pointing_sigma(&fit, &res2, &m, NULL, sky[2 * i], sky[2 * i + 1],
                                                   &s, NULL), PM_OK);
            after += s * s / 200;
        }
        {
            double s1 = res.sigma * res.sigma, s2 = res2.sigma * res2.sigma;
            double brute = before / s1 - after / s2;
            printf("check_errormap: point gain at (%.2f, %.2f): %.6g sigma^2, refit %.6g "
                   "sigma^2 (mean predicted %.3f\" -> %.3f\")\n", t, d, gain / s1, brute,
                   sqrt(before) / ARCSEC, sqrt(after * s1 / s2) / ARCSEC);
            ck_assert(fabs(gain / s1 - brute) <= 1e-6 * brute);
        }
    }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("errormap");
    TCase *t = tcase_create("errormap");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, test_errormap_matches_heldout);
    tcase_add_test(t, test_errormap_errors);
    tcase_add_test(t, test_errormap_pmfit);
    tcase_add_test(t, test_errormap_side_never_used);
    tcase_add_test(t, test_errormap_split_sides);
    tcase_add_test(t, test_errormap_rms_is_area_average);
    tcase_add_test(t, test_errormap_at_stars_is_trace);
    tcase_add_test(t, test_point_gain_matches_refit);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
