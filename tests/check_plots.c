#define _POSIX_C_SOURCE 200809L
/*
**  check_plots.c - the SVG plots of pmfit explain (tools/lib/plots.cpp),
**  through the C wrappers of plots.h: every kind is written, is well-formed
**  XML carrying its (escaped) title, survives empty and NaN inputs, and a
**  path that cannot be written gives -1 with a message.
*/
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "plots.h"
#include "tu_tool.h"

static char tmpdir[256];

static void make_tmpdir(void)
{
    tu_tmpdir(tmpdir, "pm_plots_");
}

static void path_in(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/%s", tmpdir, name);
}

/* A small well-formedness check: declarations and comments skipped, every
** start tag closed by the matching end tag, one root, quoted attributes, no
** raw '<' or unescaped '&' in text.  Returns 1 if well-formed. */
static int balanced(const char *s)
{
    char stack[64][32];
    int depth = 0, roots = 0;
    const char *p = s;
    while (*p) {
        if (*p == '&') {
            const char *e = strchr(p, ';');
            if (!e || e - p > 8)
                return 0;
            p = e + 1;
        } else if (*p != '<') {
            p++;
        } else if (p[1] == '?' || p[1] == '!') {
            const char *e = strstr(p, p[1] == '?' ? "?>" : ">");
            if (!e)
                return 0;
            p = e + 1;
        } else {
            int close = p[1] == '/', selfclose = 0;
            char name[32];
            size_t n = 0;
            p += 1 + close;
            while (*p && !strchr(" \t\n/>", *p) && n < sizeof name - 1)
                name[n++] = *p++;
            name[n] = 0;
            if (!n)
                return 0;
            while (*p && *p != '>') {       /* attributes */
                if (*p == '"' || *p == '\'') {
                    const char *e = strchr(p + 1, *p);
                    if (!e || memchr(p, '<', (size_t)(e - p)))
                        return 0;
                    p = e;
                } else if (*p == '<') {
                    return 0;
                }
                selfclose = *p == '/';
                p++;
            }
            if (!*p)
                return 0;
            p++;
            if (close) {
                if (depth == 0 || strcmp(stack[depth - 1], name) != 0)
                    return 0;
                depth--;
            } else if (!selfclose) {
                if (depth == 64)
                    return 0;
                if (depth == 0)
                    roots++;
                strcpy(stack[depth++], name);
            } else if (depth == 0) {
                roots++;
            }
        }
    }
    return depth == 0 && roots == 1;
}

/* The file exists, is an SVG document, well-formed (and accepted by
** xmllint when installed), and contains want (NULL: anything).  Returns the
** text (caller frees). */
static char *check_svg(const char *name, const char *want)
{
    char path[400], cmd[600];
    char *s;
    path_in(path, sizeof path, name);
    s = tu_slurp(path);
    ck_assert_msg(s != NULL, "%s was not written", path);
    ck_assert_msg(strncmp(s, "<?xml", 5) == 0 || strncmp(s, "<svg", 4) == 0, "%s: not an SVG", path);
    ck_assert_msg(strstr(s, "<svg") != NULL && strstr(s, "</svg>") != NULL, "%s: no svg element", path);
    ck_assert_msg(balanced(s), "%s: not well-formed", path);
    if (access("/usr/bin/xmllint", X_OK) == 0) {
        snprintf(cmd, sizeof cmd, "/usr/bin/xmllint --noout '%s' 2>/dev/null", path);
        ck_assert_msg(system(cmd) == 0, "%s: xmllint rejects it", path);
    }
    if (want)
        ck_assert_msg(strstr(s, want) != NULL, "%s: no \"%s\"", path, want);
    return s;
}

/* No non-finite number reached an attribute. */
static void assert_no_nonfinite(const char *s, const char *name)
{
    ck_assert_msg(strstr(s, "nan") == NULL && strstr(s, "NaN") == NULL, "%s: a NaN was written", name);
    ck_assert_msg(strstr(s, "\"inf") == NULL && strstr(s, "\"-inf") == NULL && strstr(s, " inf") == NULL,
                  "%s: an infinity was written", name);
}

START_TEST(test_pmplot_demo_writes_every_kind)
{
    static const char *const name[] = {"sky_vectors.svg", "sky_vectors_pair.svg", "xy.svg",
                                       "periodogram.svg", "periodogram_lin.svg", "steps.svg"};
    /* the titles, with '&' and '<', '>' escaped */
    static const char *const title[] = {"Pointing residuals: baseline model (IH &amp; ID only)",
                                        "Residuals before &amp; after adding flexure",
                                        "Elevation residual vs elevation: refraction &amp; sag",
                                        "Periodogram of HA residuals vs raw HA axis angle",
                                        "(linear) &lt;worm &amp; gear&gt;",
                                        "Greedy model search: sigma &amp; cross-validated RMS"};
    char err[512] = "";
    size_t i;
    make_tmpdir();
    ck_assert_msg(pmplot_demo(tmpdir, err, sizeof err) == 0, "%s", err);
    for (i = 0; i < sizeof name / sizeof name[0]; i++) {
        char *s = check_svg(name[i], title[i]);
        assert_no_nonfinite(s, name[i]);
        ck_assert_ptr_null(strstr(s, "no data"));
        free(s);
    }
}
END_TEST

START_TEST(test_pmplot_demo_content)
{
    char err[512] = "", *s;
    make_tmpdir();
    ck_assert_msg(pmplot_demo(tmpdir, err, sizeof err) == 0, "%s", err);
    s = check_svg("sky_vectors_pair.svg", "before: baseline");  /* panel titles, legend, scale */
    ck_assert_ptr_nonnull(strstr(s, "after: +flexure +polar axis"));
    ck_assert_ptr_nonnull(strstr(s, "pier east (77)"));
    ck_assert_ptr_nonnull(strstr(s, "pier west (83)"));
    ck_assert_ptr_nonnull(strstr(s, "50 arcsec"));
    ck_assert_ptr_nonnull(strstr(s, "declination (deg)"));
    free(s);
    s = check_svg("periodogram.svg", "G = 240.0");              /* peak and threshold labels */
    ck_assert_ptr_nonnull(strstr(s, "false-alarm 1%"));
    ck_assert_ptr_nonnull(strstr(s, "cycles per revolution"));
    free(s);
    s = check_svg("steps.svg", "+worm 240/rev");
    ck_assert_ptr_nonnull(strstr(s, ">best<"));
    free(s);
}
END_TEST

START_TEST(test_pmplot_degenerate_inputs)
{
    static const char *const empty[] = {"empty_sky.svg", "empty_pair.svg", "empty_xy.svg",
                                        "empty_periodogram.svg", "empty_steps.svg"};
    static const char *const nan[] = {"nan_sky.svg", "nan_xy.svg", "nan_periodogram.svg", "nan_steps.svg"};
    char err[512] = "", *s;
    size_t i;
    make_tmpdir();
    ck_assert_msg(pmplot_demo_degenerate(tmpdir, err, sizeof err) == 0, "%s", err);
    for (i = 0; i < sizeof empty / sizeof empty[0]; i++) {
        s = check_svg(empty[i], "no data");
        free(s);
    }
    for (i = 0; i < sizeof nan / sizeof nan[0]; i++) {
        s = check_svg(nan[i], NULL);
        assert_no_nonfinite(s, nan[i]);
        ck_assert_ptr_null(strstr(s, "no data"));
        free(s);
    }
}
END_TEST

START_TEST(test_pmplot_xy_c_nan_and_empty)
{
    double x[6], y[6];
    char path[400], err[512] = "", *s;
    x[0] = 1; x[1] = NAN; x[2] = 3; x[3] = 4; x[4] = INFINITY; x[5] = 6;
    y[0] = 2; y[1] = 1; y[2] = NAN; y[3] = 5; y[4] = 3; y[5] = -1;
    make_tmpdir();
    path_in(path, sizeof path, "xy_nan.svg");
    ck_assert_msg(pmplot_xy_c(path, "with gaps", "time (h)", "dx (arcsec)", "obs", x, y, 6, 0, err, sizeof err) == 0,
                  "%s", err);
    s = check_svg("xy_nan.svg", "with gaps");
    assert_no_nonfinite(s, "xy_nan.svg");
    ck_assert_int_eq((int)(strstr(s, "no data") == NULL), 1);
    free(s);
    path_in(path, sizeof path, "xy_allnan.svg");
    ck_assert_int_eq(pmplot_xy_c(path, "all NaN", "x", "y", "obs", x + 1, y + 2, 1, 1, err, sizeof err), 0);
    free(check_svg("xy_allnan.svg", "no data"));
    path_in(path, sizeof path, "xy_empty.svg");
    ck_assert_int_eq(pmplot_xy_c(path, "nothing", "x", "y", NULL, NULL, NULL, 0, 0, err, sizeof err), 0);
    free(check_svg("xy_empty.svg", "no data"));
}
END_TEST

START_TEST(test_pmplot_xy_c_escapes_text)
{
    double x[2] = {0, 1}, y[2] = {1, 0};
    char path[400], err[512] = "", *s;
    make_tmpdir();
    path_in(path, sizeof path, "esc.svg");
    ck_assert_int_eq(pmplot_xy_c(path, "a<b & \"c\" 'd'>\x01", "x<1>", "y&", "s\xff", x, y, 2, 1, err, sizeof err), 0);
    s = check_svg("esc.svg", "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
    ck_assert_ptr_nonnull(strstr(s, "x&lt;1&gt;"));
    ck_assert_ptr_nonnull(strstr(s, ">s?<"));   /* invalid UTF-8 byte replaced */
    free(s);
}
END_TEST

START_TEST(test_pmplot_xy_c_unwritable_path)
{
    double x[2] = {0, 1}, y[2] = {1, 0};
    char err[512] = "";
    const char *path = "/nonexistent_pm_dir/plot.svg";
    ck_assert_int_eq(pmplot_xy_c(path, "t", "x", "y", "s", x, y, 2, 0, err, sizeof err), -1);
    ck_assert_msg(strstr(err, path) != NULL && strstr(err, "cannot write") != NULL, "message: %s", err);
    ck_assert_int_eq(access(path, F_OK), -1);
}
END_TEST

START_TEST(test_pmplot_xy_c_bad_args)
{
    char err[512] = "";
    ck_assert_int_eq(pmplot_xy_c(NULL, "t", "x", "y", "s", NULL, NULL, 0, 0, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "bad arguments"));
    err[0] = 0;
    ck_assert_int_eq(pmplot_xy_c("/tmp/pm_plots_never.svg", "t", "x", "y", "s", NULL, NULL, 3, 0, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "bad arguments"));
    ck_assert_int_eq(access("/tmp/pm_plots_never.svg", F_OK), -1);
    ck_assert_int_eq(pmplot_xy_c("", "t", "x", "y", "s", NULL, NULL, 0, 0, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "empty output path"));
}
END_TEST

START_TEST(test_pmplot_demo_unwritable_dir)
{
    char err[512] = "";
    ck_assert_int_eq(pmplot_demo("/nonexistent_pm_dir", err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "/nonexistent_pm_dir/sky_vectors.svg: cannot write"));
    ck_assert_int_eq(pmplot_demo(NULL, err, sizeof err), -1);
}
END_TEST

static Suite *plots_suite(void)
{
    Suite *s = suite_create("plots");
    TCase *files = tcase_create("files"), *numerics = tcase_create("numerics"), *args = tcase_create("args");
    tcase_add_test(files, test_pmplot_demo_writes_every_kind);
    tcase_add_test(files, test_pmplot_demo_content);
    tcase_add_test(files, test_pmplot_xy_c_escapes_text);
    tcase_add_test(numerics, test_pmplot_degenerate_inputs);
    tcase_add_test(numerics, test_pmplot_xy_c_nan_and_empty);
    tcase_add_test(args, test_pmplot_xy_c_unwritable_path);
    tcase_add_test(args, test_pmplot_xy_c_bad_args);
    tcase_add_test(args, test_pmplot_demo_unwritable_dir);
    tcase_set_timeout(files, 30);
    suite_add_tcase(s, files);
    suite_add_tcase(s, numerics);
    suite_add_tcase(s, args);
    return s;
}

int main(void)
{
    SRunner *r = srunner_create(plots_suite());
    int failed;
    srunner_run_all(r, CK_NORMAL);
    failed = srunner_ntests_failed(r);
    srunner_free(r);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
