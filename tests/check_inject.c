/*
**  check_inject.c - pmfit simulate --inject EFFECT[=SIZE] --into RUN OUT:
**  a known effect added to a recording, its noise and everything else kept.
**
**  - Nothing injected (size 0) gives the same run: positions to 1e-9",
**    the same explanation (the bundled flip_gem run of an independent numpy
**    gimbal, and the real runs of ../shared/data when present).
**  - Injecting +s and then -s gives the recording back to 0.1% of the
**    largest displacement (each injection works in the frame of its run's
**    own baseline fit, which the first one moves by the effect's share the
**    fit absorbs: a second-order difference).
**  - Injected effects are found by explain with their size (flip_gem:
**    refraction, hysteresis, an HA periodic error, an outlier at the line
**    the tool reports).
**  - Misuse is a clear error and writes nothing.
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
#include "explain.h"
#include "runfile.h"
#include "testutil.h"
#include "tu_tool.h"

static char tmpdir[256];
static char out[1 << 16];

static void setup(void)
{
    if (!tmpdir[0])
        tu_tmpdir(tmpdir, "pm_inject_");
}

static void flip_path(char *buf, size_t len)
{
    const char *top = getenv("PM_TOP");
    snprintf(buf, len, "%s/tests/data/flip_gem_pm180.dat", top ? top : ".");
}

static pmrun *read_run(const char *path)
{
    pmrun_options o;
    pmrun *r = NULL;
    char err[512];
    pmrun_options_default(&o);
    ck_assert_msg(pmrun_read(path, &o, &r, err, sizeof err) == 0, "%s", err);
    return r;
}

/* Largest difference of the apparent positions on the sky (arcsec). */
static double max_moved(const char *a, const char *b)
{
    pmrun *ra = read_run(a), *rb = read_run(b);
    size_t i;
    double worst = 0;
    ck_assert_uint_eq(pmrun_count(ra), pmrun_count(rb));
    for (i = 0; i < pmrun_count(ra); i++) {
        const pmrun_obs *p = pmrun_get(ra, i), *q = pmrun_get(rb, i);
        double d = tu_angle(p->app_ha, p->app_dec, q->app_ha, q->app_dec) / ARCSEC;
        ck_assert(fabs(remainder(p->enc_ha - q->enc_ha, 2 * M_PI)) < 1e-13);
        ck_assert(fabs(p->enc_dec - q->enc_dec) < 1e-13);
        if (d > worst)
            worst = d;
    }
    pmrun_free(ra);
    pmrun_free(rb);
    return worst;
}

static int inject(const char *into, const char *spec, const char *extra, const char *dst)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s simulate --inject '%s' %s --into '%s' '%s'", tu_pmfit_path(),
             spec, extra ? extra : "", into, dst);
    return tu_capture(cmd, out, sizeof out);
}

static void same_explanation(const char *a, const char *b)
{
    pmx_result x, y;
    char err[512];
    int k;
    ck_assert_msg(pmx_explain(a, 1, 0.01, &x, err, sizeof err) == 0, "%s", err);
    ck_assert_msg(pmx_explain(b, 1, 0.01, &y, err, sizeof err) == 0, "%s", err);
    ck_assert(fabs(x.base_sigma_arcsec - y.base_sigma_arcsec) < 1e-6 * x.base_sigma_arcsec);
    ck_assert_int_eq(x.n_findings, y.n_findings);
    for (k = 0; k < x.n_findings; k++) {
        ck_assert_str_eq(x.findings[k].effect, y.findings[k].effect);
        ck_assert(fabs(x.findings[k].amplitude_arcsec - y.findings[k].amplitude_arcsec) <
                  1e-6 * (1 + x.findings[k].amplitude_arcsec));
    }
}

START_TEST(test_inject_nothing_same_run)
{
    static const char *real[3] = {"mmt/k_and_e.dat", "celestial/gem-28.dat",
                                  "celestial/cgx-l-data.dat"};
    char src[512], dst[512];
    const char *d = tu_data_dir();
    int k;
    setup();
    flip_path(src, sizeof src);
    snprintf(dst, sizeof dst, "%s/zero.dat", tmpdir);
    ck_assert_msg(inject(src, "refraction=0", NULL, dst) == 0, "%s", out);
    ck_assert(max_moved(src, dst) < 1e-9);
    same_explanation(src, dst);
    if (!d) {
        printf("check_inject: ../shared/data absent: the real runs skipped\n");
        return;
    }
    for (k = 0; k < 3; k++) {
        snprintf(src, sizeof src, "%s/%s", d, real[k]);
        if (access(src, R_OK) != 0)
            continue;
        ck_assert_msg(inject(src, "hysteresis=0sigma", NULL, dst) == 0, "%s", out);
        /* TPOINT files are reduced (refraction, precession): the same
        ** apparent places, written to 1e-12 deg */
        ck_assert_msg(max_moved(src, dst) < 1e-6, "%s moved by %g\"", real[k], max_moved(src, dst));
        same_explanation(src, dst);
    }
}
END_TEST

START_TEST(test_inject_and_back)
{
    static const char *specs[4][2] = {{"refraction=2.5", "refraction=-2.5"},
                                      {"ha_periodic:120=3", "ha_periodic:120=-3"},
                                      {"i@W=4", "i@W=-4"},
                                      {"higher_order=2", "higher_order=-2"}};
    char src[512], a[512], b[512];
    int k;
    setup();
    flip_path(src, sizeof src);
    snprintf(a, sizeof a, "%s/plus.dat", tmpdir);
    snprintf(b, sizeof b, "%s/back.dat", tmpdir);
    for (k = 0; k < 4; k++) {
        ck_assert_msg(inject(src, specs[k][0], "--phase 30", a) == 0, "%s", out);
        ck_assert_msg(max_moved(src, a) > 1, "%s moved nothing", specs[k][0]);
        ck_assert_msg(inject(a, specs[k][1], "--phase 30", b) == 0, "%s", out);
        printf("check_inject: %s then back: %.2g\" from the recording\n", specs[k][0],
               max_moved(src, b));
        ck_assert(max_moved(src, b) < 1e-3 * max_moved(src, a));
    }
}
END_TEST

/* explain names what was injected into the independent gimbal's run, with
** its size (25%); an outlier at the line the tool reports */
START_TEST(test_inject_found)
{
    static const struct {
        const char *spec, *name;
        double G;
    } cases[] = {{"refraction:4sigma", "refraction", 0},
                 {"hysteresis:3sigma", "hysteresis", 0},
                 {"ha_periodic:150:4sigma", "ha_periodic", 150},
                 {"dec_periodic:97:4sigma", "dec_periodic", 97}};
    char src[512], dst[512], err[512];
    size_t k;
    int j, found;
    pmx_result r;
    setup();
    flip_path(src, sizeof src);
    snprintf(dst, sizeof dst, "%s/found.dat", tmpdir);
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double size;
        const char *p;
        ck_assert_msg(inject(src, cases[k].spec, "--phase 70", dst) == 0, "%s", out);
        p = strstr(out, "of size ");
        ck_assert_ptr_nonnull(p);
        size = atof(p + 8);
        ck_assert_msg(pmx_explain(dst, 1, 0.01, &r, err, sizeof err) == 0, "%s", err);
        found = 0;
        for (j = 0; j < r.n_findings; j++)
            if (!strcmp(r.findings[j].effect, cases[k].name) &&
                (cases[k].G == 0 || r.findings[j].cycles_per_rev == cases[k].G)) {
                found = 1;
                printf("check_inject: flip_gem + %s (%.2f\"): found %s, %.2f\" +- %.2f\"\n",
                       cases[k].spec, size, r.findings[j].effect, r.findings[j].amplitude_arcsec,
                       r.findings[j].amplitude_err_arcsec);
                ck_assert(fabs(r.findings[j].amplitude_arcsec - size) <= 0.25 * size);
            }
        ck_assert_msg(found, "%s not found", cases[k].spec);
    }
    ck_assert_msg(inject(src, "outlier=12sigma", "--seed 5", dst) == 0, "%s", out);
    {
        const char *p = strstr(out, "; in ");
        int line;
        ck_assert_ptr_nonnull(p);
        p = strchr(p + 5, ':');
        line = atoi(p + 1);
        ck_assert_msg(pmx_explain(dst, 1, 0.01, &r, err, sizeof err) == 0, "%s", err);
        ck_assert_int_ge(r.n_findings, 1);
        ck_assert_str_eq(r.findings[0].effect, "outlier");
        ck_assert_int_eq(r.findings[0].n_lines, 1);
        ck_assert_int_eq(r.findings[0].lines[0], line);
    }
}
END_TEST

START_TEST(test_inject_misuse)
{
    static const struct {
        const char *args, *says;
    } bad[] = {
        {"--inject refraction OUT", "--inject needs --into"},
        {"--into RUN OUT", "needs at least one --inject"},
        {"--inject refraction --into RUN --n 50 OUT", "--n shapes a simulated run"},
        {"--inject refraction --into RUN --order 2 OUT", "--order shapes a simulated run"},
        {"--inject nonsense --into RUN OUT", "nonsense"},
        {"--inject refraction=2furlongs --into RUN OUT", "2furlongs"},
        {"--inject time_drift --into RUN OUT", "flip_gem_pm180.dat:"},
        {"--inject temperature --into RUN OUT", "flip_gem_pm180.dat:"},
        {"--inject outlier:1000 --into RUN OUT", "outlier:N"},
        {"--inject refraction --into /nonexistent.dat OUT", "/nonexistent.dat"},
    };
    char src[512], dst[512], cmd[4096], args[1024];
    size_t k;
    setup();
    flip_path(src, sizeof src);
    snprintf(dst, sizeof dst, "%s/never.dat", tmpdir);
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        /* RUN and OUT replaced by the paths */
        const char *s = bad[k].args;
        char *w = args;
        while (*s) {
            if (!strncmp(s, "RUN", 3)) {
                w += sprintf(w, "'%s'", src);
                s += 3;
            } else if (!strncmp(s, "OUT", 3)) {
                w += sprintf(w, "'%s'", dst);
                s += 3;
            } else {
                *w++ = *s++;
            }
        }
        *w = 0;
        snprintf(cmd, sizeof cmd, "%s simulate %s", tu_pmfit_path(), args);
        ck_assert_msg(tu_capture(cmd, out, sizeof out) != 0, "accepted: %s", args);
        ck_assert_msg(strstr(out, bad[k].says) != NULL, "%s: says '%s', not '%s'", args, out,
                      bad[k].says);
        ck_assert_msg(access(dst, F_OK) != 0, "%s: wrote the output", args);
    }
}
END_TEST

/* flip_gem with an auxiliary column 'hum' (deterministic values 10..70;
** arg: the records so far) */
static int edit_with_column(char *line, size_t size, void *arg)
{
    int *i = (int *)arg;
    size_t n = strcspn(line, "\r\n");
    line[n] = 0;
    if (!strncmp(line, "# tau", 5))
        snprintf(line + n, size - n, " hum\n");
    else if (line[0] == '#' || !line[0])
        snprintf(line + n, size - n, "\n");
    else
        snprintf(line + n, size - n, " %.3f\n", 40 + 30 * sin(1.7 * (*i)++));
    return 1;
}

static void with_column(const char *src, char *dst)
{
    int i = 0;
    tu_edited_copy(src, dst, edit_with_column, &i);
}

/* An effect on the run's own column (aux:NAME) is injected as pmfit fit
** --add aux:NAME reads it (the simulator's truth knows no column names: it
** said the run has no column 'hum'), and fit's JSON names the column of
** the terms it calls c'*aux0 and e'*aux0. */
START_TEST(test_inject_own_column)
{
    char src[512], col[512], dst[512], cmd[2048];
    const char *p;
    int found = 0;
    setup();
    flip_path(src, sizeof src);
    snprintf(col, sizeof col, "%s/hum.dat", tmpdir);
    snprintf(dst, sizeof dst, "%s/hum_in.dat", tmpdir);
    with_column(src, col);
    ck_assert_msg(inject(col, "aux:hum=0.25", NULL, dst) == 0, "%s", out);
    ck_assert(max_moved(col, dst) > 5);
    snprintf(cmd, sizeof cmd, "%s fit --add aux:hum --json '%s'", tu_pmfit_path(), dst);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    for (p = out; (p = strstr(p, "\"column\": \"hum\", \"value_arcsec\": ")) != NULL; p++) {
        double v = atof(p + strlen("\"column\": \"hum\", \"value_arcsec\": "));
        ck_assert_msg(fabs(v - 0.25) < 0.01, "%s", out);
        found++;
    }
    ck_assert_msg(found == 2, "%s", out);
    /* a column the run lacks is named */
    ck_assert(inject(src, "aux:hum=0.25", NULL, dst) != 0);
    ck_assert_msg(strstr(out, "no column 'hum'") != NULL, "%s", out);
}
END_TEST

/* explain takes the run's own columns as candidates (aux:NAME, on c' and
** e' as pmfit fit --add aux:NAME fits them): a column 'hum' added to the
** bundled run and to the three real ones (as injection writes them, a
** named-column run) is not a finding when nothing follows it, and is
** found, with its size (25%), when an effect of about 1.5 sigma per axis
** follows it (its coefficient sigma/14 per unit; hum spreads by 21).
** Before, a column the run recorded was never looked at. */
START_TEST(test_inject_own_column_explained)
{
    static const char *real[3] = {"mmt/k_and_e.dat", "celestial/gem-28.dat",
                                  "celestial/cgx-l-data.dat"};
    const char *d = tu_data_dir();
    char src[512], named[512], col[512], dst[512], err[512], spec[64];
    int k, j;
    pmx_result r;
    setup();
    snprintf(named, sizeof named, "%s/named.dat", tmpdir);
    snprintf(col, sizeof col, "%s/hum.dat", tmpdir);
    snprintf(dst, sizeof dst, "%s/hum_in.dat", tmpdir);
    for (k = -1; k < 3; k++) {
        double p;
        int found = 0;
        if (k < 0) {
            flip_path(src, sizeof src);
        } else {
            if (!d)
                break;
            snprintf(src, sizeof src, "%s/%s", d, real[k]);
            if (access(src, R_OK) != 0)
                continue;
        }
        ck_assert_msg(inject(src, "refraction=0", NULL, named) == 0, "%s", out);
        with_column(named, col);
        ck_assert_msg(pmx_explain(col, 1, 0.01, &r, err, sizeof err) == 0, "%s", err);
        for (j = 0; j < r.n_findings; j++)
            ck_assert_msg(strcmp(r.findings[j].effect, "aux:hum") != 0,
                          "%s: aux:hum found in nothing", src);
        p = r.base_sigma_arcsec / 14;
        snprintf(spec, sizeof spec, "aux:hum=%.6g", p);
        ck_assert_msg(inject(col, spec, NULL, dst) == 0, "%s", out);
        ck_assert_msg(pmx_explain(dst, 1, 0.01, &r, err, sizeof err) == 0, "%s", err);
        for (j = 0; j < r.n_findings; j++)
            if (!strcmp(r.findings[j].effect, "aux:hum")) {
                found = 1;
                printf("check_inject: %s + aux:hum %.4g\"/unit: found %.4g\" +- %.4g\" "
                       "(finding %d of %d)\n",
                       k < 0 ? "flip_gem" : real[k], p, r.findings[j].amplitude_arcsec,
                       r.findings[j].amplitude_err_arcsec, j + 1, r.n_findings);
                ck_assert(fabs(r.findings[j].amplitude_arcsec - p) <= 0.25 * p);
            }
        ck_assert_msg(found, "%s: aux:hum of %g\"/unit not found", src, p);
    }
    if (!d)
        printf("check_inject: ../shared/data absent: the real runs skipped\n");
}
END_TEST

/* flip_gem with six columns c1..c6 (deterministic values) */
static int edit_six_columns(char *line, size_t size, void *arg)
{
    int *i = (int *)arg, k;
    size_t n = strcspn(line, "\r\n");
    line[n] = 0;
    if (!strncmp(line, "# tau", 5)) {
        snprintf(line + n, size - n, " c1 c2 c3 c4 c5 c6\n");
        return 1;
    }
    if (line[0] == '#' || !line[0]) {
        snprintf(line + n, size - n, "\n");
        return 1;
    }
    for (k = 1; k <= 6; k++) {
        n = strlen(line);
        snprintf(line + n, size - n, " %.4f", 10 * sin(0.7 * k + 1.3 * (*i)));
    }
    n = strlen(line);
    snprintf(line + n, size - n, "\n");
    (*i)++;
    return 1;
}

/* The tenth record's last field made '-' (unknown); arg: the counts so far,
** and that record's line. */
typedef struct { int lines, records, at; } tenth_state;
static int edit_tenth_unknown(char *line, size_t size, void *arg)
{
    tenth_state *t = (tenth_state *)arg;
    char *sp;
    (void)size;
    t->lines++;
    if (line[0] == '#' || line[0] == '\n' || ++t->records != 10)
        return 1;
    sp = strrchr(line, ' ');
    ck_assert_ptr_nonnull(sp);
    strcpy(sp, " -\n");
    t->at = t->lines;
    return 1;
}

/* A run of more columns than the core takes (PM_MAX_AUX, 4): the injected
** run keeps all of them, readable (its header named six and its records
** held four: "12 fields, expected 14"; an outside probe), and the fifth and
** sixth as read. */
START_TEST(test_inject_keeps_every_column)
{
    char src[512], six[512], dst[512];
    pmrun *a, *b;
    size_t i;
    int k = 0, j;
    setup();
    flip_path(src, sizeof src);
    snprintf(six, sizeof six, "%s/six.dat", tmpdir);
    snprintf(dst, sizeof dst, "%s/six_in.dat", tmpdir);
    tu_edited_copy(src, six, edit_six_columns, &k);
    ck_assert_msg(inject(six, "aux:c2=0.5", NULL, dst) == 0, "%s", out);
    a = read_run(six);
    b = read_run(dst);
    ck_assert_int_eq(pmrun_n_aux(b), 6);
    ck_assert_uint_eq(pmrun_count(a), pmrun_count(b));
    for (i = 0; i < pmrun_count(a); i++)
        for (j = 0; j < 6; j++)
            ck_assert(fabs(pmrun_get(a, i)->aux[j] - pmrun_get(b, i)->aux[j]) < 1e-9);
    pmrun_free(a);
    pmrun_free(b);
    /* explain says which columns it could not try, and why (it had passed
    ** them over without a word: an outside probe) */
    {
        char cmd[1200];
        snprintf(cmd, sizeof cmd, "%s explain '%s'", tu_pmfit_path(), six);
        ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
        ck_assert_msg(strstr(out, "not tried: aux:c5: beyond the first 4 columns") != NULL &&
                          strstr(out, "not tried: aux:c6: beyond the first 4 columns") != NULL &&
                          strstr(out, "not tried: aux:c1") == NULL,
                      "%s", out);
    }
    {   /* a column without a value at one point */
        char col[512], gap[512], cmd[1200];
        tenth_state t = {0, 0, 0};
        snprintf(col, sizeof col, "%s/hum6.dat", tmpdir);
        snprintf(gap, sizeof gap, "%s/hum_gap.dat", tmpdir);
        with_column(src, col);
        tu_edited_copy(col, gap, edit_tenth_unknown, &t);
        snprintf(cmd, sizeof cmd, "%s explain '%s'", tu_pmfit_path(), gap);
        ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
        snprintf(cmd, sizeof cmd, "not tried: aux:hum: no value at line %d", t.at);
        ck_assert_msg(strstr(out, cmd) != NULL, "%s: %s", cmd, out);
    }
}
END_TEST

static double sag_reading(const char *path)
{
    pmx_result r;
    char err[512];
    int k;
    ck_assert_msg(pmx_explain(path, 1, 0.01, &r, err, sizeof err) == 0, "%s", err);
    for (k = 0; k < r.n_readings; k++)
        if (!strcmp(r.readings[k].what, "tube_flexure_in_order1"))
            return r.readings[k].value;
    ck_abort_msg("%s: no sag reading", path);
    return 0;
}

/* A sag injected into a real recording is read back by the physical
** reading of the order-1 baseline ("what the baseline holds"): the reading
** moves by the injected size (1%), whatever sag the run holds itself. */
START_TEST(test_inject_sag_read_back)
{
    static const char *real[3] = {"mmt/k_and_e.dat", "celestial/gem-28.dat",
                                  "celestial/cgx-l-data.dat"};
    static const double sizes[3] = {2.0, -1.5, 3.0};
    char src[512], dst[512];
    const char *d = tu_data_dir();
    int k;
    setup();
    snprintf(dst, sizeof dst, "%s/sag.dat", tmpdir);
    for (k = 0; k < 3; k++) {
        double r0, r1, size;
        const char *p;
        char spec[64];
        if (!d) {
            printf("check_inject: ../shared/data absent: skipped\n");
            return;
        }
        snprintf(src, sizeof src, "%s/%s", d, real[k]);
        if (access(src, R_OK) != 0)
            continue;
        snprintf(spec, sizeof spec, "tube_flexure=%gsigma", sizes[k]);
        ck_assert_msg(inject(src, spec, NULL, dst) == 0, "%s", out);
        p = strstr(out, "of size ");
        ck_assert_ptr_nonnull(p);
        size = atof(p + 8);
        r0 = sag_reading(src);
        r1 = sag_reading(dst);
        printf("check_inject: %s: its order-1 terms hold a sag of %.2f\"; with %.2f\" injected "
               "%.2f\" (moved by %.2f\")\n", real[k], r0, size, r1, r1 - r0);
        ck_assert(fabs((r1 - r0) - size) <= 0.01 * fabs(size));
    }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("inject");
    TCase *t = tcase_create("inject");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, test_inject_nothing_same_run);
    tcase_add_test(t, test_inject_and_back);
    tcase_add_test(t, test_inject_found);
    tcase_add_test(t, test_inject_misuse);
    tcase_add_test(t, test_inject_own_column);
    tcase_add_test(t, test_inject_own_column_explained);
    tcase_add_test(t, test_inject_keeps_every_column);
    tcase_add_test(t, test_inject_sag_read_back);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
