#define _GNU_SOURCE
/*
**  check_fuzz_regress.c - the fuzz targets' inputs as regression tests:
**  every file under fuzz/regress/<target>/ (inputs that once broke an
**  invariant) and fuzz/corpus/<target>/ (the seed corpora) goes through the
**  same harness as the libFuzzer target (fuzz/harness_<target>.c, compiled
**  in here), which checks the target's invariants (fuzz/README.md).  Also
**  checks that the run-file seeds reach each of the three parsers and that
**  the model-file seeds load.  Files are found from $PM_TOP (default ".").
*/
#include <check.h>
#include "tu_check.h"
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../fuzz/harness_runfile.c"
#include "../fuzz/harness_modelfile.c"
#include "../fuzz/harness_capi.c"
#include "../fuzz/harness_fit.c"
#include "../fuzz/harness_explain.c"
#include "../fuzz/harness_plan.c"

/* Largest input read (the corpora hold a few KB per file). */
#define FZ_MAX_INPUT (1 << 20)

typedef int (*harness_fn)(const unsigned char *, size_t);

static const char *top(void)
{
    const char *t = getenv("PM_TOP");
    return t && *t ? t : ".";
}

/* Read a whole file into a new buffer; NULL if it cannot be read. */
static unsigned char *read_all(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    unsigned char *buf;
    if (!f)
        return NULL;
    buf = malloc(FZ_MAX_INPUT);
    if (buf)
        *n = fread(buf, 1, FZ_MAX_INPUT, f);
    fclose(f);
    return buf;
}

/* Run every file of <top>/fuzz/<kind>/<target>/ through fn; returns the
** number of files run (-1 if the directory is missing) and appends the
** names of the failing ones to failed. */
static int run_dir(const char *kind, const char *target, harness_fn fn, char *failed,
                   size_t flen)
{
    char dir[1024], path[2048];
    DIR *d;
    struct dirent *e;
    int count = 0;
    snprintf(dir, sizeof dir, "%s/fuzz/%s/%s", top(), kind, target);
    d = opendir(dir);
    if (!d)
        return -1;
    while ((e = readdir(d)) != NULL) {
        size_t n = 0;
        unsigned char *buf;
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        buf = read_all(path, &n);
        if (!buf)
            continue;
        count++;
        if (fn(buf, n) != 0 && strlen(failed) + strlen(e->d_name) + 4 < flen) {
            strcat(failed, " ");
            strcat(failed, kind);
            strcat(failed, "/");
            strcat(failed, e->d_name);
        }
        free(buf);
    }
    closedir(d);
    return count;
}

/* The corpus must be there and every input must pass; regression inputs
** are optional per target. */
static void check_target(const char *target, harness_fn fn, int min_corpus)
{
    static char failed[4096];
    int nc, nr;
    failed[0] = '\0';
    nc = run_dir("corpus", target, fn, failed, sizeof failed);
    nr = run_dir("regress", target, fn, failed, sizeof failed);
    ck_assert_msg(nc >= min_corpus, "fuzz/corpus/%s under %s: %d inputs, expected at least %d",
                  target, top(), nc, min_corpus);
    ck_assert_msg(failed[0] == '\0', "%s: invariant broken by (%d corpus, %d regress inputs "
                  "run):%s", target, nc, nr < 0 ? 0 : nr, failed);
}

START_TEST(test_fuzz_runfile_inputs_keep_invariants)
{
    check_target("runfile", pmfz_runfile, 40);
}
END_TEST

START_TEST(test_fuzz_modelfile_inputs_keep_invariants)
{
    check_target("modelfile", pmfz_modelfile, 3);
}
END_TEST

START_TEST(test_fuzz_capi_inputs_keep_invariants)
{
    check_target("capi", pmfz_capi, 3);
}
END_TEST

START_TEST(test_fuzz_fit_inputs_keep_invariants)
{
    check_target("fit", pmfz_fit, 3);
}
END_TEST

START_TEST(test_fuzz_explain_inputs_keep_invariants)
{
    check_target("explain", pmfz_explain, 8);
}
END_TEST

START_TEST(test_fuzz_plan_inputs_keep_invariants)
{
    check_target("plan", pmfz_plan, 6);
}
END_TEST

/* A run-file seed (option byte, then the file) read with the default
** options: its format, or -1 if it does not read. */
static int seed_format(const char *name)
{
    char path[2048], mpath[64];
    unsigned char *buf;
    size_t n = 0;
    pmrun *run = NULL;
    int fd, fmt = -1;
    snprintf(path, sizeof path, "%s/fuzz/corpus/runfile/%s", top(), name);
    buf = read_all(path, &n);
    ck_assert_msg(buf != NULL && n > 1, "cannot read %s", path);
    fd = pmfz_memfile(buf + 1, n - 1, mpath, sizeof mpath);
    free(buf);
    ck_assert_int_ge(fd, 0);
    if (pmrun_read(mpath, NULL, &run, NULL, 0) == PMRUN_OK)
        fmt = pmrun_format(run);
    pmrun_free(run);
    close(fd);
    return fmt;
}

START_TEST(test_fuzz_runfile_seeds_reach_every_parser)
{
    ck_assert_int_eq(seed_format("four_column"), PMRUN_FORMAT_FOUR_COLUMN);
    ck_assert_int_eq(seed_format("named"), PMRUN_FORMAT_NAMED);
    ck_assert_int_eq(seed_format("named_altaz"), PMRUN_FORMAT_NAMED);
    ck_assert_int_eq(seed_format("tpoint_equat"), PMRUN_FORMAT_TPOINT);
    ck_assert_int_eq(seed_format("tpoint_altaz"), PMRUN_FORMAT_TPOINT);
    ck_assert_int_eq(seed_format("rts2_gpoint"), PMRUN_FORMAT_RTS2);
    ck_assert_int_eq(seed_format("rts2_altaz"), PMRUN_FORMAT_RTS2);
    ck_assert_int_eq(seed_format("mw4_model"), PMRUN_FORMAT_MW4);
    ck_assert_int_eq(seed_format("nina_j2000"), PMRUN_FORMAT_CSV);
    ck_assert_int_eq(seed_format("nina_jnow"), PMRUN_FORMAT_CSV);
    ck_assert_int_eq(seed_format("mmt_log"), PMRUN_FORMAT_MMT);
    ck_assert_int_eq(seed_format("bad_nan"), -1);
}
END_TEST

START_TEST(test_fuzz_modelfile_seeds_load)
{
    static const char *names[] = {"order0.pm", "order1_physical.pm", "altaz_latitude.pm",
                                  "crlf_zero.pm"};
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; i++) {
        char path[2048], err[512];
        pm_model m;
        snprintf(path, sizeof path, "%s/fuzz/corpus/modelfile/%s", top(), names[i]);
        ck_assert_msg(pmmodel_load(path, &m, err, sizeof err) == 0, "%s", err);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("fuzz_regress");
    TCase *tc = tcase_create("inputs");
    tcase_add_test(tc, test_fuzz_runfile_inputs_keep_invariants);
    tcase_add_test(tc, test_fuzz_modelfile_inputs_keep_invariants);
    tcase_add_test(tc, test_fuzz_capi_inputs_keep_invariants);
    tcase_add_test(tc, test_fuzz_fit_inputs_keep_invariants);
    tcase_add_test(tc, test_fuzz_explain_inputs_keep_invariants);
    tcase_add_test(tc, test_fuzz_plan_inputs_keep_invariants);
    tcase_set_timeout(tc, 300);
    suite_add_tcase(s, tc);
    tc = tcase_create("seeds");
    tcase_add_test(tc, test_fuzz_runfile_seeds_reach_every_parser);
    tcase_add_test(tc, test_fuzz_modelfile_seeds_load);
    tcase_set_timeout(tc, 60);
    suite_add_tcase(s, tc);
    return tu_run_suite(s);
}
