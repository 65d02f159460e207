/*
**  check_report.c - pmfit report RUN -o PAGE.html: one self-contained HTML
**  page, checked as written and as a real browser renders it.
**
**  "page": the page of the bundled example (examples/sim_gem.dat), of a
**  simulated alt-az run and of a run compared with an earlier model and an
**  earlier run: every section is there; every figure is an inline <svg>
**  with an x and a y axis label that carry a unit, and a <figcaption>; no
**  script, no external resource (no http(s):// anywhere, no src=, no
**  <link>, no url() but to the page's own ids); its numbers are those of
**  pmfit fit / explain / plan / compare --json on the same run.
**  "errors": a malformed run or OLD gives pmfit fit's file:line message,
**  exit 1, and the output path as it was (no half-written page, no .tmp);
**  a missing directory, a missing -o: named errors.  "progress": stage
**  lines on stderr with --progress, none with --quiet.
**  "browser": Debian's chromium, headless, loads each page (file://):
**  --dump-dom gives the DOM the browser built, checked as above; the
**  console log (--enable-logging=stderr) must hold no CONSOLE line; a
**  screenshot is taken (build/tests/report_*.png, for a person to look at).
**  A control page with a console error and a figure without units proves
**  the checks can fail.  Skipped, with a message, without chromium.
**  "realdata": the runs in $PM_DATA_DIR, page and browser (skipped
**  without them).
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "testutil.h"
#include "tu_tool.h"

#define TOL_SIGMA 0.0006   /* arcsec: the page prints 3 decimals */
#define TOL_HA_H 0.0006    /* hours: the page prints 3 decimals */
#define MIN_SCREENSHOT 30000 /* bytes: a blank 1280x4000 page is about 10 kB */

static char tmp[64];
static char out[1 << 16];

static void setup(void) { tu_tmpdir(tmp, "pm_report_"); }

static void teardown(void)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    if (system(cmd) != 0)
        fprintf(stderr, "check_report: could not remove %s\n", tmp);
}

static const char *top(void)
{
    const char *t = getenv("PM_TOP");
    return t ? t : ".";
}

/* $PM_DATA_DIR when it is a directory, else NULL. */
static const char *data_dir(void)
{
    const char *d = tu_data_dir();
    struct stat st;
    return d && stat(d, &st) == 0 && S_ISDIR(st.st_mode) ? d : NULL;
}

/* pmfit report RUN ARGS -o tmp/NAME; the exit code, output in `out`. */
static int report(const char *run, const char *args, const char *name)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' report '%s' %s -o '%s/%s'", tu_pmfit_path(), run, args, tmp, name);
    return tu_capture(cmd, out, sizeof out);
}

/* ------------------------------------------------------------ the checks */

/* An axis label with a unit: (deg), (arcsec), (h), (°C), cycles per
** revolution, a line number, or said to have none. */
static int has_unit(const char *label)
{
    static const char *const units[] = {"(deg)", "(arcsec)", "(h)", "(\xc2\xb0" "C)", "(cycles per revolution)",
                                        "(line number)", "no unit"};
    size_t k;
    for (k = 0; k < sizeof units / sizeof units[0]; k++)
        if (strstr(label, units[k]))
            return 1;
    return 0;
}

/* The text of the first axis label of kind `kind` ("x", "y") within
** [s, end) into buf; 0 if none. */
static int axis_label(const char *s, const char *end, const char *kind, char *buf, size_t len)
{
    char pat[64];
    const char *p, *q, *e;
    snprintf(pat, sizeof pat, "class=\"axis-label %s\"", kind);
    p = strstr(s, pat);
    if (!p || p >= end || !(q = strchr(p, '>')) || !(e = strstr(q, "</text>")) || e > end)
        return 0;
    snprintf(buf, len, "%.*s", (int)(e - q - 1), q + 1);
    return 1;
}

/* The first problem of the figures of an HTML text (the file or the DOM),
** NULL if none; *n: the number of figures. */
static const char *figure_problem(const char *html, int *n, char *msg, size_t len)
{
    const char *p = html, *end;
    char lab[512];
    *n = 0;
    while ((p = strstr(p, "<figure")) != NULL) {
        const char *kinds[2] = {"x", "y"};
        int k;
        end = strstr(p, "</figure>");
        if (!end)
            return snprintf(msg, len, "figure %d is not closed", *n + 1), msg;
        (*n)++;
        if (!strstr(p, "<svg") || strstr(p, "<svg") > end)
            return snprintf(msg, len, "figure %d has no <svg>", *n), msg;
        if (!strstr(p, "<figcaption>") || strstr(p, "<figcaption>") > end)
            return snprintf(msg, len, "figure %d has no <figcaption>", *n), msg;
        for (k = 0; k < 2; k++) {
            if (!axis_label(p, end, kinds[k], lab, sizeof lab))
                return snprintf(msg, len, "figure %d has no %s axis label", *n, kinds[k]), msg;
            if (!has_unit(lab))
                return snprintf(msg, len, "figure %d: %s axis label without a unit: '%s'", *n, kinds[k], lab), msg;
        }
        p = end;
    }
    return NULL;
}

/* What must not be in a self-contained page (NULL if clean). */
static const char *external_problem(const char *html)
{
    static const char *const bad[] = {"http://", "https://", "<script", " src=", "<link", "@import", "<iframe",
                                      "<object", "<embed"};
    const char *p;
    size_t k;
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++)
        if (strstr(html, bad[k]))
            return bad[k];
    for (p = strstr(html, "url("); p; p = strstr(p + 4, "url("))
        if (p[4] != '#')
            return "url( to something but an id of the page";
    return NULL;
}

/* The page (file or DOM) has its title, headings and every section, and
** at least min_figures good figures. */
static void check_page(const char *html, const char *what, int min_figures, int compare)
{
    static const char *const sections[] = {"id=\"fit\"", "id=\"residuals\"", "id=\"model\"", "id=\"explain\"",
                                           "id=\"plan\""};
    char msg[1024];
    const char *prob;
    size_t k;
    int n;
    ck_assert_msg(strstr(html, "<title>Pointing report: ") != NULL, "%s: no <title>", what);
    ck_assert_msg(strstr(html, "<h1>") != NULL && strstr(html, "<h2>") != NULL, "%s: no headings", what);
    for (k = 0; k < sizeof sections / sizeof sections[0]; k++)
        ck_assert_msg(strstr(html, sections[k]) != NULL, "%s: no section %s", what, sections[k]);
    ck_assert_msg((strstr(html, "id=\"compare\"") != NULL) == compare, "%s: compare section %s", what,
                  compare ? "missing" : "without --compare");
    prob = figure_problem(html, &n, msg, sizeof msg);
    ck_assert_msg(prob == NULL, "%s: %s", what, prob);
    ck_assert_msg(n >= min_figures, "%s: %d figures, expected at least %d", what, n, min_figures);
    prob = external_problem(html);
    ck_assert_msg(prob == NULL, "%s: not self-contained: it has '%s'", what, prob);
    /* every table's header names its unit where it holds numbers: no bare "value" */
    ck_assert_msg(strstr(html, "<th scope=\"col\">value</th>") == NULL, "%s: a column without its unit", what);
}

/* pmfit report RUN ARGS -o tmp/NAME, which must succeed, and its page,
** checked by check_page (what, min_figures, compare); the caller frees it. */
static char *checked_report(const char *run, const char *args, const char *name, const char *what,
                            int min_figures, int compare)
{
    char path[512];
    char *html;
    ck_assert_msg(report(run, args, name) == 0, "pmfit report %s failed: %s", args, out);
    snprintf(path, sizeof path, "%s/%s", tmp, name);
    html = tu_slurp(path);
    ck_assert_ptr_nonnull(html);
    check_page(html, what, min_figures, compare);
    return html;
}

/* The number after `key` in text (fails if absent). */
static double after(const char *text, const char *key, const char *what)
{
    const char *p = strstr(text, key);
    ck_assert_msg(p != NULL, "%s: no '%s'", what, key);
    return atof(p + strlen(key));
}

/* ------------------------------------------------------------ page */

START_TEST(test_report_example)
{
    char path[512], cmd[4096], run[512];
    char *html, *js;
    const char *p;
    int n = 0;
    snprintf(run, sizeof run, "%s/examples/sim_gem.dat", top());
    html = checked_report(run, "", "sim.html", "sim_gem page", 14, 0);
    /* the numbers are pmfit's own: sigma of the fit */
    snprintf(cmd, sizeof cmd, "'%s' fit '%s' --json", tu_pmfit_path(), run);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    ck_assert_double_eq_tol(after(html, "terms: &sigma; = ", "page"), tu_json_num(out, "sigma_arcsec"), TOL_SIGMA);
    /* the findings of pmfit explain, in its order (refraction, then the worm) */
    snprintf(cmd, sizeof cmd, "'%s' explain '%s' --json", tu_pmfit_path(), run);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    js = strstr(out, "\"findings\"");
    ck_assert_ptr_nonnull(js);
    for (p = strstr(js, "\"effect\": \""); p && p < strstr(js, "\"withdrawn\""); p = strstr(p + 1, "\"effect\": \"")) {
        char head[128], eff[64];
        const char *q = strchr(p + 11, '"');
        if (strncmp(q, "\", \"log10_false", 14) == 0)
            continue; /* an alternative reading, not a finding */
        snprintf(eff, sizeof eff, "%.*s", (int)(q - (p + 11)), p + 11);
        n++;
        snprintf(head, sizeof head, "id=\"finding%d\">Finding %d: %s</h3>", n, n, eff);
        ck_assert_msg(strstr(html, head) != NULL, "page: no '%s'", head);
    }
    ck_assert_int_ge(n, 2);
    ck_assert_msg(strstr(html, "Finding 1: refraction") && strstr(html, "Finding 2: ha_periodic"),
                  "the example's two findings");
    /* the next targets of pmfit plan --json, in its order */
    snprintf(cmd, sizeof cmd, "'%s' plan '%s' --next 5 --json", tu_pmfit_path(), run);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    p = strstr(html, "class=\"num targets\"");
    ck_assert_ptr_nonnull(p);
    ck_assert_double_eq_tol(after(p, "<tr><td>1</td><td>", "targets"), tu_json_num(out, "ha_deg") / 15, TOL_HA_H);
    free(html);
    /* with a horizon file and a higher --min-el: pmfit plan's first target
    ** with the same options (they move it) */
    snprintf(cmd, sizeof cmd, "--horizon '%s/examples/horizon.hrz' --min-el 25", top());
    ck_assert_msg(report(run, cmd, "sim_hz.html") == 0, "pmfit report failed: %s", out);
    snprintf(path, sizeof path, "%s/sim_hz.html", tmp);
    html = tu_slurp(path);
    ck_assert_ptr_nonnull(html);
    ck_assert_msg(strstr(html, "above elevation 25&deg; and the horizon of ") != NULL, "horizon not said");
    snprintf(cmd, sizeof cmd, "'%s' plan '%s' --next 5 --json --horizon '%s/examples/horizon.hrz' --min-el 25",
             tu_pmfit_path(), run, top());
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    p = strstr(html, "class=\"num targets\"");
    ck_assert_ptr_nonnull(p);
    ck_assert_double_eq_tol(after(p, "<tr><td>1</td><td>", "targets"), tu_json_num(out, "ha_deg") / 15, TOL_HA_H);
    free(html);
}
END_TEST

/* A simulated alt-az run: azimuth and elevation axes, no pier sides. */
START_TEST(test_report_altaz)
{
    char path[512], cmd[4096];
    char *html;
    snprintf(path, sizeof path, "%s/altaz.dat", tmp);
    snprintf(cmd, sizeof cmd, "'%s' simulate '%s' --mount altaz --n 150 --seed 7 --lat 31.7 --noise 0.8",
             tu_pmfit_path(), path);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "simulate: %s", out);
    html = checked_report(path, "--next 3", "altaz.html", "alt-az page", 10, 0);
    ck_assert_msg(strstr(html, "alt-az, site latitude +31.7000&deg;") != NULL, "alt-az summary");
    ck_assert_msg(strstr(html, "class=\"axis-label x\">azimuth (deg)</text>") != NULL, "azimuth axis");
    ck_assert_msg(strstr(html, "<th scope=\"col\">azimuth (deg)</th>") != NULL, "targets in azimuth");
    ck_assert_msg(strstr(html, "pier west") == NULL, "no pier sides on an alt-az mount");
    free(html);
}
END_TEST

/* A run whose residuals hold order 2 that its 90 points cannot fit
** (tests/data/indep_ho_altaz_n90_unmodelled.dat, check_explain_reading's
** test_unmodelled): the explain section says nothing it can model is left
** out, and names what is there. */
START_TEST(test_report_unmodelled)
{
    char path[512];
    char *html;
    snprintf(path, sizeof path, "%s/tests/data/indep_ho_altaz_n90_unmodelled.dat", top());
    html = checked_report(path, "--next 3", "unmodelled.html", "unmodelled page", 8, 0);
    ck_assert_msg(strstr(html, "nothing that this run can model is left out") != NULL, "summary");
    ck_assert_msg(strstr(html, "<b>Significant, not modelled:</b> higher_order (false-alarm 10^") != NULL,
                  "the unmodelled family not named");
    free(html);
}
END_TEST

/* The sky of the targets' predicted error: 8 stars of the normal side of a
** German mount (every 15th of the example's normal side) give it
** over both sides, the other side unobserved, said with the map's figure
** beside it (an outside probe's 5 stars: 0.450" in the map, 1.510" in the
** plan, nothing to tell them apart); --fork plans the normal side only,
** smaller, and says so; --fork on an alt-az run is refused. */
/* 8 stars of one pier side of the example run (every 15th of side E or W)
** in tmp/onesideE.dat or onesideW.dat; its path in path. */
static void one_side(char *path, size_t len, char side)
{
    char cmd[4096];
    snprintf(path, len, "%s/oneside%c.dat", tmp, side);
    snprintf(cmd, sizeof cmd,
             "awk '/^#/ {print; next} $5 == \"%c\" && c++ %% 15 == 0 && n < 8 {print; n++}' "
             "'%s/examples/sim_gem.dat' > '%s'", side, top(), path);
    ck_assert_int_eq(system(cmd), 0);
}

START_TEST(test_report_plan_sky)
{
    char path[512];
    char *html, *fork;
    double both, one, map;
    one_side(path, sizeof path, 'E');
    html = checked_report(path, "--order 0 --next 3", "oneside.html", "one-side page", 8, 0);
    ck_assert_msg(strstr(html, "The sky of this prediction is both pier sides") &&
                      strstr(html, "this run's stars are all on the normal side"),
                  "%.400s", strstr(html, "Predicted mean error now") ? strstr(html, "Predicted mean error now") : html);
    both = after(html, "Predicted mean error now: <b>", "both sides");
    map = after(html, "star) says ", "the map");
    fork = checked_report(path, "--order 0 --next 3 --fork", "oneside_fork.html", "one-side page, --fork",
                          8, 0);
    ck_assert_msg(strstr(fork, "The sky of this prediction is that of a mount that does not flip") &&
                      !strstr(fork, "this run's stars are all"),
                  "--fork");
    one = after(fork, "Predicted mean error now: <b>", "--fork");
    ck_assert_msg(one < both && map < both, "both sides %g, normal side %g, map %g", both, one, map);
    free(html);
    free(fork);
    /* all beyond the pole (a German mount seen on one side): the other
    ** side's sky said, no --fork offered; with --fork, the normal side's
    ** sky, unobserved, said (a second probe's: no word) */
    one_side(path, sizeof path, 'W');
    html = checked_report(path, "--order 0 --next 3", "onesideW.html", "beyond-the-pole page", 8, 0);
    ck_assert_msg(strstr(html, "this run's stars are all beyond the pole, so it counts the sky of the "
                               "other side") && !strstr(html, "For a mount that does not flip"),
                  "beyond the pole");
    free(html);
    html = checked_report(path, "--order 0 --next 3 --fork", "onesideW_fork.html",
                          "beyond-the-pole page, --fork", 8, 0);
    ck_assert_msg(strstr(html, "this run's stars are all beyond the pole, so it counts the sky of the "
                               "normal side, which the run has not observed") != NULL,
                  "beyond the pole, --fork");
    free(html);
    snprintf(path, sizeof path, "%s/tests/data/indep_ho_altaz_n90_unmodelled.dat", top());
    ck_assert_int_eq(report(path, "--fork", "altaz_fork.html"), 1);
    ck_assert_msg(strstr(out, "--fork is for an equatorial mount") != NULL, "%s", out);
}
END_TEST

/* An equatorial run without a latitude: no azimuth, elevation or targets,
** each said on the page; the rest drawn. */
START_TEST(test_report_no_latitude)
{
    char path[512], cmd[4096];
    char *html;
    snprintf(path, sizeof path, "%s/nolat.dat", tmp);
    snprintf(cmd, sizeof cmd, "grep -v '^# latitude:' '%s/examples/sim_gem.dat' > '%s'", top(), path);
    ck_assert_int_eq(system(cmd), 0);
    html = checked_report(path, "", "nolat.html", "page without a latitude", 12, 0);
    ck_assert_msg(strstr(html, "site latitude not given") != NULL, "summary");
    ck_assert_msg(strstr(html, "Not drawn: the residuals against elevation") != NULL, "no elevation");
    ck_assert_msg(strstr(html, "Not available for this run: plan: an equatorial mount needs the site latitude"),
                  "no targets");
    free(html);
}
END_TEST

/* --compare OLD: a saved model, and a run; the numbers of pmfit compare. */
START_TEST(test_report_compare)
{
    char run[512], old[512], cmd[4096], args[1024];
    char *html;
    int k;
    snprintf(run, sizeof run, "%s/examples/sim_gem.dat", top());
    snprintf(old, sizeof old, "%s/half.dat", tmp);
    /* the earlier night: the first 150 points of the run, as a run and as a model */
    snprintf(cmd, sizeof cmd, "head -155 '%s' > '%s' && '%s' fit '%s' --save '%s/old.pm' > /dev/null", run, old,
             tu_pmfit_path(), old, tmp);
    ck_assert_int_eq(system(cmd), 0);
    for (k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "--compare '%s%s'", k ? old : tmp, k ? "" : "/old.pm");
        html = checked_report(run, args, "cmp.html", k ? "compare with a run" : "compare with a model", 14, 1);
        snprintf(cmd, sizeof cmd, "'%s' compare %s '%s' --json", tu_pmfit_path(), args + 10, run);
        ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
        ck_assert_double_eq_tol(after(html, "the old model as it is</td><td>", "compare table"),
                                tu_json_num(out, "rms_as_is_arcsec"), 0.0006);
        ck_assert_msg(strstr(html, k ? "from the run " : "from the model file ") != NULL, "what OLD was");
        free(html);
    }
}
END_TEST

/* ------------------------------------------------------------ errors */

/* The output path as it was, and no temporary file beside it. */
static void unchanged(const char *name, const char *content)
{
    char path[512];
    char *s;
    snprintf(path, sizeof path, "%s/%s", tmp, name);
    s = tu_slurp(path);
    ck_assert_ptr_nonnull(s);
    ck_assert_str_eq(s, content);
    free(s);
    /* (the temporary is NAME.tmpPID.N) */
    snprintf(path, sizeof path, "%s.tmp", name);
    {
        DIR *d = opendir(tmp);
        struct dirent *e;
        ck_assert_ptr_nonnull(d);
        while ((e = readdir(d)) != NULL)
            ck_assert_msg(strncmp(e->d_name, path, strlen(path)) != 0, "%s/%s left behind", tmp,
                          e->d_name);
        closedir(d);
    }
}

START_TEST(test_report_bad_input)
{
    char bad[512], cmd[2048], fitmsg[1024], args[4096];
    FILE *f;
    snprintf(bad, sizeof bad, "%s/bad.dat", tmp);
    /* the example with line 40 broken */
    snprintf(cmd, sizeof cmd, "sed '40s/.*/12.5 abc 3 4/' '%s/examples/sim_gem.dat' > '%s'", top(), bad);
    ck_assert_int_eq(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "%s/page.html", tmp);
    f = fopen(cmd, "w");
    ck_assert_ptr_nonnull(f);
    fputs("an earlier page\n", f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "'%s' fit '%s'", tu_pmfit_path(), bad);
    ck_assert_int_eq(tu_capture(cmd, fitmsg, sizeof fitmsg), 1);
    ck_assert_msg(strstr(fitmsg, "bad.dat:40: ") != NULL, "fit: %s", fitmsg);
    fitmsg[strcspn(fitmsg, "\n")] = 0;
    ck_assert_int_eq(report(bad, "", "page.html"), 1);
    ck_assert_msg(strstr(out, fitmsg) == out, "report says '%s', fit '%s'", out, fitmsg);
    ck_assert_msg(strstr(out, "(no page written)") != NULL, "%s", out); /* (as docs/report.md) */
    unchanged("page.html", "an earlier page\n");
    /* a malformed OLD: its file:line, nothing written */
    snprintf(cmd, sizeof cmd, "%s/examples/sim_gem.dat", top());
    snprintf(args, sizeof args, "--compare '%s'", bad);
    ck_assert_int_eq(report(cmd, args, "page.html"), 1);
    ck_assert_msg(strstr(out, "bad.dat:40: ") && strstr(out, "(no page written)"), "%s", out);
    unchanged("page.html", "an earlier page\n");
    /* an OLD that is not there */
    ck_assert_int_eq(report(cmd, "--compare /nonexistent/old.pm", "page.html"), 1);
    ck_assert_msg(strstr(out, "/nonexistent/old.pm: cannot open") != NULL, "%s", out);
    unchanged("page.html", "an earlier page\n");
    /* a model the run cannot fit: pmfit fit's words */
    snprintf(cmd, sizeof cmd, "head -25 '%s/examples/sim_gem.dat' > '%s/short.dat'", top(), tmp);
    ck_assert_int_eq(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "%s/short.dat", tmp);
    ck_assert_int_eq(report(cmd, "--order 3", "page.html"), 1);
    ck_assert_msg(strstr(out, "too few observations for the number of terms") != NULL, "%s", out);
    unchanged("page.html", "an earlier page\n");
    /* a horizon file that is not there: the user's error, no page */
    snprintf(cmd, sizeof cmd, "%s/examples/sim_gem.dat", top());
    ck_assert_int_eq(report(cmd, "--horizon /nonexistent/h.hrz", "page.html"), 1);
    ck_assert_msg(strstr(out, "/nonexistent/h.hrz: cannot open the horizon file") != NULL, "%s", out);
    unchanged("page.html", "an earlier page\n");
    /* an unknown effect, a missing directory, a missing -o */
    snprintf(cmd, sizeof cmd, "%s/examples/sim_gem.dat", top());
    ck_assert_int_eq(report(cmd, "--add nonsense", "page.html"), 1);
    ck_assert_msg(strstr(out, "--add nonsense") != NULL, "%s", out);
    unchanged("page.html", "an earlier page\n");
    ck_assert_int_eq(report(cmd, "", "no/such/dir/page.html"), 1);
    ck_assert_msg(strstr(out, "does not exist (nothing was done)") != NULL, "%s", out);
    snprintf(args, sizeof args, "'%s' report '%s'", tu_pmfit_path(), cmd);
    ck_assert_int_eq(tu_capture(args, out, sizeof out), 2);
    ck_assert_msg(strstr(out, "no output given") != NULL, "%s", out);
}
END_TEST

START_TEST(test_report_progress)
{
    char run[512];
    snprintf(run, sizeof run, "%s/examples/sim_gem.dat", top());
    ck_assert_int_eq(report(run, "--progress", "p.html"), 0);
    ck_assert_msg(strstr(out, "pmfit report: [  5%] fit") && strstr(out, "] explain") &&
                      strstr(out, "] plan") && strstr(out, "pmfit report: [100%] done"),
                  "stages: %s", out);
    ck_assert_int_eq(report(run, "--quiet", "q.html"), 0);
    ck_assert_str_eq(out, "");
}
END_TEST

/* ------------------------------------------------------------ browser */

/* Debian's chromium, or NULL (with the reason printed once). */
static const char *chromium(void)
{
    static const char *const paths[] = {"/usr/bin/chromium", "/usr/bin/chromium-browser"};
    size_t k;
    for (k = 0; k < sizeof paths / sizeof paths[0]; k++)
        if (access(paths[k], X_OK) == 0)
            return paths[k];
    printf("check_report: chromium not found: the browser checks are skipped (tools/deps.sh installs it)\n");
    return NULL;
}

/* Load tmp/NAME.html in headless chromium, with a fresh profile and no
** network: the DOM into tmp/NAME.dom, the console log into tmp/NAME.log,
** and (png != NULL) a 1280x4000 screenshot into png.  The exit code. */
static int browse(const char *browser, const char *name, const char *png)
{
    char cmd[4096], flags[1024];
    int rc;
    snprintf(flags, sizeof flags,
             "--headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
             "--disable-background-networking --disable-component-update --disable-sync "
             "--disable-extensions --hide-scrollbars --user-data-dir='%s/profile-%s'", tmp, name);
    snprintf(cmd, sizeof cmd,
             "timeout 120 '%s' %s --enable-logging=stderr --v=0 --dump-dom 'file://%s/%s.html' "
             "> '%s/%s.dom' 2> '%s/%s.log'", browser, flags, tmp, name, tmp, name, tmp, name);
    rc = system(cmd);
    if (rc != 0 || !png)
        return rc;
    snprintf(cmd, sizeof cmd,
             "timeout 120 '%s' %s --window-size=1280,4000 --screenshot='%s' 'file://%s/%s.html' "
             "> /dev/null 2>&1", browser, flags, png, tmp, name);
    return system(cmd);
}

/* The console messages chromium logged (lines with ":CONSOLE" or
** "Uncaught"): their count, the first into first. */
static int console_messages(const char *name, char *first, size_t len)
{
    char path[512], line[4096];
    FILE *f;
    int n = 0;
    snprintf(path, sizeof path, "%s/%s.log", tmp, name);
    f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    first[0] = 0;
    while (fgets(line, sizeof line, f))
        if (strstr(line, ":CONSOLE") || strstr(line, "Uncaught")) {
            if (!n++)
                snprintf(first, len, "%s", line);
        }
    fclose(f);
    return n;
}

/* The page tmp/NAME.html as the browser builds it: the checks of
** check_page on the DOM, no console message, a screenshot that is not
** blank (kept as $PM_BUILD/tests/report_NAME.png). */
static void check_in_browser(const char *browser, const char *name, int min_figures, int compare)
{
    char path[512], png[512], first[4096];
    char *dom;
    struct stat st;
    const char *b = getenv("PM_BUILD");
    snprintf(png, sizeof png, "%s/%s/tests/report_%s.png", top(), b ? b : "build", name);
    ck_assert_int_eq(browse(browser, name, png), 0);
    snprintf(path, sizeof path, "%s/%s.dom", tmp, name);
    dom = tu_slurp(path);
    ck_assert_ptr_nonnull(dom);
    ck_assert_msg(strlen(dom) > 1000, "%s: the browser gave no DOM: %.300s", name, dom);
    check_page(dom, name, min_figures, compare);
    ck_assert_msg(console_messages(name, first, sizeof first) == 0, "%s: console: %s", name, first);
    ck_assert_int_eq(stat(png, &st), 0);
    ck_assert_msg(st.st_size > MIN_SCREENSHOT, "%s: screenshot of %ld bytes: blank?", name, (long)st.st_size);
    free(dom);
}

/* The checks can fail: a console error is seen; a figure without units
** or caption is named; an external resource is found. */
START_TEST(test_browser_control)
{
    const char *browser = chromium();
    char path[512], first[4096], msg[256];
    FILE *f;
    int n;
    ck_assert_ptr_nonnull(figure_problem("<figure><svg><text class=\"axis-label x\">x (deg)</text>"
                                         "<text class=\"axis-label y\">y</text></svg><figcaption>c</figcaption></figure>",
                                         &n, msg, sizeof msg));
    ck_assert_msg(strstr(msg, "y axis label without a unit") != NULL, "%s", msg);
    ck_assert_ptr_nonnull(figure_problem("<figure><svg><text class=\"axis-label x\">x (deg)</text>"
                                         "<text class=\"axis-label y\">y (arcsec)</text></svg></figure>",
                                         &n, msg, sizeof msg));
    ck_assert_ptr_null(figure_problem("<figure><svg><text class=\"axis-label x\">x (deg)</text>"
                                      "<text class=\"axis-label y\">y (arcsec)</text></svg><figcaption>c"
                                      "</figcaption></figure>", &n, msg, sizeof msg));
    ck_assert_int_eq(n, 1);
    ck_assert_ptr_nonnull(external_problem("<img src=\"a.png\">"));
    ck_assert_ptr_nonnull(external_problem("<style>b{background:url(x.png)}</style>"));
    if (!browser)
        return;
    snprintf(path, sizeof path, "%s/control.html", tmp);
    f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs("<!DOCTYPE html><html><head><title>control</title></head><body><h1>control</h1>"
          "<script>console.error('control error'); no_such_function();</script></body></html>\n", f);
    fclose(f);
    ck_assert_int_eq(browse(browser, "control", NULL), 0);
    ck_assert_int_eq(console_messages("control", first, sizeof first), 2);
    ck_assert_msg(strstr(first, "control error") != NULL, "%s", first);
}
END_TEST

START_TEST(test_browser_example)
{
    const char *browser = chromium();
    char run[512];
    if (!browser)
        return;
    snprintf(run, sizeof run, "%s/examples/sim_gem.dat", top());
    ck_assert_msg(report(run, "", "sim_gem.html") == 0, "pmfit report failed: %s", out);
    check_in_browser(browser, "sim_gem", 14, 0);
}
END_TEST

START_TEST(test_browser_altaz_compare)
{
    const char *browser = chromium();
    char path[512], cmd[4096];
    if (!browser)
        return;
    snprintf(path, sizeof path, "%s/altaz.dat", tmp);
    snprintf(cmd, sizeof cmd, "'%s' simulate '%s' --mount altaz --n 150 --seed 7 --lat 31.7 --noise 0.8 "
             "--effect refraction=3 2>&1 && '%s' fit '%s' --save '%s/old.pm' > /dev/null", tu_pmfit_path(), path,
             tu_pmfit_path(), path, tmp);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd, "--compare '%s/old.pm'", tmp);
    ck_assert_msg(report(path, cmd, "altaz.html") == 0, "pmfit report failed: %s", out);
    check_in_browser(browser, "altaz", 10, 1);
}
END_TEST

/* ------------------------------------------------------------ realdata */

START_TEST(test_report_realdata)
{
    static const char *const runs[] = {"mmt/k_and_e.dat", "celestial/gem-28.dat", "celestial/cgx-l-data.dat"};
    const char *d = data_dir(), *browser;
    char run[512], name[64], path[512];
    size_t k;
    if (!d) {
        printf("check_report: ../shared/data absent: the real runs skipped\n");
        return;
    }
    browser = chromium();
    for (k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        char *html;
        snprintf(run, sizeof run, "%s/%s", d, runs[k]);
        snprintf(name, sizeof name, "real%zu", k);
        snprintf(path, sizeof path, "%s.html", name);
        ck_assert_msg(report(run, "--order 2", path) == 0, "pmfit report %s failed: %s", runs[k], out);
        snprintf(path, sizeof path, "%s/%s.html", tmp, name);
        html = tu_slurp(path);
        ck_assert_ptr_nonnull(html);
        check_page(html, runs[k], 9, 0);
        free(html);
        if (browser)
            check_in_browser(browser, name, 9, 0);
        printf("check_report: %s: page and browser checks passed\n", runs[k]);
    }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("report");
    TCase *t = tcase_create("page");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_set_timeout(t, 600);
    tcase_add_test(t, test_report_example);
    tcase_add_test(t, test_report_altaz);
    tcase_add_test(t, test_report_no_latitude);
    tcase_add_test(t, test_report_plan_sky);
    tcase_add_test(t, test_report_unmodelled);
    tcase_add_test(t, test_report_compare);
    suite_add_tcase(s, t);
    t = tcase_create("errors");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_set_timeout(t, 600);
    tcase_add_test(t, test_report_bad_input);
    tcase_add_test(t, test_report_progress);
    suite_add_tcase(s, t);
    t = tcase_create("browser");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_set_timeout(t, 900);
    tcase_add_test(t, test_browser_control);
    tcase_add_test(t, test_browser_example);
    tcase_add_test(t, test_browser_altaz_compare);
    suite_add_tcase(s, t);
    t = tcase_create("realdata");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_set_timeout(t, 900);
    tcase_add_test(t, test_report_realdata);
    suite_add_tcase(s, t);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
