/*
**  check_pmfit.c - the pmfit program end to end: acceptance numbers on the
**  real recorded runs (skipped without ../shared/data), the simulate/fit
**  loop, model files, and command-line errors.
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pm.h"
#include "modelfile.h"
#include "testutil.h"
#include "tu_tool.h"

/* MMT k_and_e.dat: an independent reference fit gets 0.747" (L=1) and
** 0.560" (L=2); the issue's acceptance bounds are 0.76" and 0.57". */
#define MMT_SIGMA_MAX_L1 0.76
#define MMT_SIGMA_MAX_L2 0.57

static char tmpdir[256];
static char out[1 << 20];

static void make_tmpdir(void) { tu_tmpdir(tmpdir, "pm_pmfit_"); }

/* Run pmfit: fmt has three %s, the program and two arguments; stdout and
** stderr into out; the exit code. */
static int run(const char *fmt, const char *a, const char *b)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, fmt, tu_pmfit_path(), a ? a : "", b ? b : "");
    return tu_capture(cmd, out, sizeof out);
}

START_TEST(test_pmfit_mmt_sigma)
{
    char path[512];
    double s1, s2;
    if (!tu_real_run("mmt/k_and_e.dat", path, sizeof path))
        return;
    ck_assert_int_eq(run("%s fit %s --order 1 --json", path, NULL), 0);
    s1 = tu_json_num(out, "sigma_arcsec");
    ck_assert_int_eq((int)tu_json_num(out, "n_obs"), 80);
    ck_assert_int_eq((int)tu_json_num(out, "n_params"), 22);
    ck_assert_int_eq(run("%s fit %s --order 2 --json", path, NULL), 0);
    s2 = tu_json_num(out, "sigma_arcsec");
    ck_assert_int_eq((int)tu_json_num(out, "n_params"), 46);
    printf("MMT k_and_e: sigma L=1 %.4f\" (ref 0.747), L=2 %.4f\" (ref 0.560)\n", s1, s2);
    ck_assert_double_le(s1, MMT_SIGMA_MAX_L1);
    ck_assert_double_le(s2, MMT_SIGMA_MAX_L2);
}
END_TEST

/* The GEM runs converge from zero despite a ~5 deg raw HA offset; the fitted
** HA index must be of that size (the reader's median offset), at every order,
** joint and split by pier side (where the split fit can separate its terms). */
START_TEST(test_pmfit_gem_converges)
{
    const char *files[2] = {"celestial/gem-28.dat", "celestial/cgx-l-data.dat"};
    int f, L;
    for (f = 0; f < 2; f++) {
        char path[512];
        if (!tu_real_run(files[f], path, sizeof path))
            continue;
        for (L = 0; L <= 2; L++) {
            char opt[64];
            const char *p;
            double cp;
            snprintf(opt, sizeof opt, "--order %d --json", L);
            ck_assert_msg(run("%s fit %s %s", path, opt) == 0, "%s L=%d: %s", files[f], L, out);
            p = strstr(out, "\"name\": \"c'\", \"value_arcsec\": ");
            ck_assert_ptr_nonnull(p);
            cp = atof(p + strlen("\"name\": \"c'\", \"value_arcsec\": "));
            printf("%s L=%d joint: sigma %.2f\", c' = %.3f deg\n", files[f], L,
                   tu_json_num(out, "sigma_arcsec"), cp / 3600);
            ck_assert_double_gt(fabs(cp) / 3600, 2.0);  /* degrees, not arcseconds */
            ck_assert_double_lt(fabs(cp) / 3600, 10.0);
        }
        /* split at L=0 and L=1 converges on both runs */
        for (L = 0; L <= 1; L++) {
            char opt[64];
            snprintf(opt, sizeof opt, "--order %d --pier split --json", L);
            ck_assert_msg(run("%s fit %s %s", path, opt) == 0, "%s L=%d split: %s", files[f], L,
                          out);
            ck_assert_ptr_nonnull(strstr(out, "\"east\""));
            ck_assert_ptr_nonnull(strstr(out, "\"west\""));
        }
    }
}
END_TEST

/* simulate -> fit recovers the injected isotropic terms; --save writes a
** model file that reads back; --emit-c writes a header. */
START_TEST(test_pmfit_simulate_fit_roundtrip)
{
    char run_path[300], model_path[300], hdr_path[300], args[1024];
    double rms_fit;
    pm_model m;
    char err[512];
    int i;
    make_tmpdir();
    snprintf(run_path, sizeof run_path, "%s/sim.dat", tmpdir);
    snprintf(model_path, sizeof model_path, "%s/fit.pm", tmpdir);
    snprintf(hdr_path, sizeof hdr_path, "%s/fit.h", tmpdir);
    ck_assert_int_eq(run("%s simulate %s --n 600 --seed 9 --noise 0.5 --term \"c'=900\" "
                         "--term \"e'=-300\" --term a=60 --term i=40 %s",
                         run_path, ""), 0);
    snprintf(args, sizeof args, "%s --order 1 --save %s --emit-c %s --json", run_path,
             model_path, hdr_path);
    ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
    ck_assert_double_lt(fabs(tu_json_num(out, "sigma_arcsec") - 0.5), 0.05);
    rms_fit = tu_json_num(out, "rms_arcsec");
    /* pmfit reads its own model file back: eval on the same run gives the
    ** fit's sky RMS (same model, same residuals) */
    snprintf(args, sizeof args, "%s %s --json", model_path, run_path);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    ck_assert_double_eq_tol(tu_json_num(out, "rms_arcsec"), rms_fit, 1e-6);
    ck_assert_int_eq(pmmodel_load(model_path, &m, err, sizeof err), 0);
    ck_assert_int_eq(m.order, 1);
    /* c' within 1 arcsec (its error is ~0.05") */
    ck_assert_double_lt(fabs(m.coef[2] * 206264.806 - 900), 1.0);
    ck_assert_double_lt(fabs(m.coef[4] * 206264.806 + 300), 1.0);
    ck_assert_double_lt(fabs(m.coef[0] * 206264.806 - 60), 1.0);
    for (i = 6; i < m.n_terms; i++)
        ck_assert_double_lt(fabs(m.coef[i]) * 206264.806, 1.0);
    ck_assert_int_eq(access(hdr_path, R_OK), 0);
}
END_TEST

START_TEST(test_pmfit_cli_errors)
{
    char bad[300], res[300];
    FILE *f;
    make_tmpdir();
    ck_assert_int_eq(run("%s%s%s", "", ""), 2);
    ck_assert_int_eq(run("%s frobnicate%s%s", "", ""), 2);
    ck_assert_ptr_nonnull(strstr(out, "unknown command"));
    ck_assert_int_eq(run("%s fit%s%s", "", ""), 2);
    ck_assert_ptr_nonnull(strstr(out, "no run file"));
    ck_assert_int_eq(run("%s fit x.dat --order 99%s%s", "", ""), 2);
    ck_assert_ptr_nonnull(strstr(out, "--order"));
    ck_assert_int_eq(run("%s fit x.dat --pier sideways%s%s", "", ""), 2);
    ck_assert_int_eq(run("%s fit x.dat --bogus%s%s", "", ""), 2);
    ck_assert_ptr_nonnull(strstr(out, "unknown option"));
    ck_assert_int_eq(run("%s fit /nonexistent/run.dat%s%s", "", ""), 1);
    /* a periodic term's G out of range: the message gives the range */
    {
        char ex[600];
        const char *top = getenv("PM_TOP");
        snprintf(ex, sizeof ex, "%s/examples/sim_gem.dat", top ? top : ".");
        ck_assert_int_eq(run("%s fit %s --add ha_periodic:1e9%s", ex, ""), 1);
        ck_assert_msg(strstr(out, "G must be cycles per revolution, > 0 and <= 100000") != NULL,
                      "%s", out);
    }
    /* a malformed record: file:line in the message, no residual file left */
    snprintf(bad, sizeof bad, "%s/bad.dat", tmpdir);
    snprintf(res, sizeof res, "%s/res.txt", tmpdir);
    f = fopen(bad, "w");
    ck_assert_ptr_nonnull(f);
    fputs("# tau delta T D\n10 20 10.1 20.1\n11 21 eleven 21.1\n", f);
    fclose(f);
    ck_assert_int_eq(run("%s fit %s --residuals %s", bad, res), 1);
    ck_assert_msg(strstr(out, "bad.dat:3:") != NULL, "%s", out);
    ck_assert_int_ne(access(res, F_OK), 0);
    /* too few points for the order: a clear error, exit 1, nothing written */
    f = fopen(bad, "w");
    ck_assert_ptr_nonnull(f);
    fputs("# tau delta T D\n10 20 10.1 20.1\n11 21 11.1 21.1\n40 50 40.1 50.1\n", f);
    fclose(f);
    ck_assert_int_eq(run("%s fit %s --order 1 --residuals %s", bad, res), 1);
    ck_assert_msg(strstr(out, "too few") != NULL, "%s", out);
    ck_assert_int_ne(access(res, F_OK), 0);
}
END_TEST

static void put_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

/* No output may be an input or another output: refused before any work,
** the input unchanged (a night's run overwritten by its own residuals, the
** tester's report, was exit 0). */
START_TEST(test_pmfit_output_not_input)
{
    char runp[300], alias[300], model[300], args[1200], cmd[1400];
    char *before, *after;
    const char *top = getenv("PM_TOP");
    make_tmpdir();
    snprintf(runp, sizeof runp, "%s/run.dat", tmpdir);
    snprintf(cmd, sizeof cmd, "cp '%s/examples/sim_gem.dat' '%s'", top ? top : ".", runp);
    ck_assert_int_eq(system(cmd), 0);
    before = tu_slurp(runp);
    ck_assert_ptr_nonnull(before);
    ck_assert_int_eq(run("%s fit %s --residuals %s", runp, runp), 1);
    ck_assert_msg(strstr(out, "it is the input RUN (nothing was done)") != NULL, "%s", out);
    snprintf(args, sizeof args, "%s --save %s", runp, runp);
    ck_assert_int_eq(run("%s fit %s%s", args, ""), 1);
    ck_assert_int_eq(run("%s report %s -o %s", runp, runp), 1);
    ck_assert_msg(strstr(out, "--output") != NULL, "%s", out);
    /* under another name: a symbolic link to the run */
    snprintf(alias, sizeof alias, "%s/alias.dat", tmpdir);
    ck_assert_int_eq(symlink("run.dat", alias), 0);
    ck_assert_int_eq(run("%s fit %s --tpoint-terms %s", runp, alias), 1);
    ck_assert_msg(strstr(out, "the same file as the input RUN") != NULL, "%s", out);
    /* eval's MODEL is an input too */
    snprintf(model, sizeof model, "%s/m.pm", tmpdir);
    ck_assert_int_eq(run("%s fit %s --save %s", runp, model), 0);
    snprintf(args, sizeof args, "%s %s --residuals %s", model, runp, model);
    ck_assert_int_eq(run("%s eval %s%s", args, ""), 1);
    ck_assert_msg(strstr(out, "the input MODEL") != NULL, "%s", out);
    after = tu_slurp(runp);
    ck_assert_ptr_nonnull(after);
    ck_assert_str_eq(after, before);
    free(after);
    /* two outputs, one file: the second would replace the first */
    snprintf(args, sizeof args, "%s --residuals %s/two.txt --save %s/two.txt", runp, tmpdir,
             tmpdir);
    ck_assert_int_eq(run("%s fit %s%s", args, ""), 1);
    ck_assert_msg(strstr(out, "writes the same file (nothing was done)") != NULL, "%s", out);
    snprintf(cmd, sizeof cmd, "%s/two.txt", tmpdir);
    ck_assert_int_ne(access(cmd, F_OK), 0);
    free(before);
}
END_TEST

/* Where an output goes: a symbolic link stays one (the file it names is
** written), a device is written, not replaced (--save /dev/null replaced
** the node as root), a file named like a temporary is not taken, and a
** failing --residuals loses neither the report nor the other outputs. */
START_TEST(test_pmfit_output_targets)
{
    char runp[300], path[300], args[1600];
    char *text;
    struct stat st;
    const char *top = getenv("PM_TOP");
    make_tmpdir();
    snprintf(runp, sizeof runp, "%s/examples/sim_gem.dat", top ? top : ".");
    snprintf(path, sizeof path, "%s/target.txt", tmpdir);
    put_file(path, "keep\n");
    snprintf(path, sizeof path, "%s/link.txt", tmpdir);
    ck_assert_int_eq(symlink("target.txt", path), 0);
    ck_assert_int_eq(run("%s fit %s --residuals %s", runp, path), 0);
    ck_assert_int_eq(lstat(path, &st), 0);
    ck_assert_msg(S_ISLNK(st.st_mode), "--residuals replaced the symbolic link");
    snprintf(path, sizeof path, "%s/target.txt", tmpdir);
    text = tu_slurp(path);
    ck_assert_ptr_nonnull(text);
    ck_assert_msg(strncmp(text, "# residuals of pmfit fit", 24) == 0, "%.200s", text);
    free(text);
    /* a user's file named as the old temporary was */
    snprintf(path, sizeof path, "%s/m.pm.tmp", tmpdir);
    put_file(path, "mine\n");
    snprintf(args, sizeof args, "%s --save %s/m.pm", runp, tmpdir);
    ck_assert_int_eq(run("%s fit %s%s", args, ""), 0);
    text = tu_slurp(path);
    ck_assert_ptr_nonnull(text);
    ck_assert_str_eq(text, "mine\n");
    free(text);
    /* devices */
    ck_assert_int_eq(run("%s fit %s --save /dev/null --residuals /dev/null%s", runp, ""), 0);
    ck_assert_int_eq(stat("/dev/null", &st), 0);
    ck_assert(S_ISCHR(st.st_mode));
    if (stat("/dev/full", &st) == 0 && S_ISCHR(st.st_mode)) {
        snprintf(args, sizeof args, "%s --residuals /dev/full --save %s/kept.pm", runp, tmpdir);
        ck_assert_int_eq(run("%s fit %s%s", args, ""), 1);
        ck_assert_msg(strstr(out, "unbiased sigma") != NULL, "no report: %s", out);
        ck_assert_msg(strstr(out, "/dev/full: cannot write: ") != NULL, "%s", out);
        ck_assert_msg(strstr(out, "(the fit is reported above)") != NULL, "%s", out);
        snprintf(path, sizeof path, "%s/kept.pm", tmpdir);
        ck_assert_msg(access(path, F_OK) == 0, "--save was lost with --residuals");
        ck_assert_int_eq(stat("/dev/full", &st), 0);
        ck_assert(S_ISCHR(st.st_mode));
    }
    /* a file made read-only is not replaced (root may write anything) */
    if (geteuid() != 0) {
        snprintf(path, sizeof path, "%s/ro.txt", tmpdir);
        put_file(path, "read-only\n");
        ck_assert_int_eq(chmod(path, 0444), 0);
        ck_assert_int_eq(run("%s fit %s --residuals %s", runp, path), 1);
        text = tu_slurp(path);
        ck_assert_ptr_nonnull(text);
        ck_assert_str_eq(text, "read-only\n");
        free(text);
    }
}
END_TEST

/* The first 15 records of the example (two patches of sky) cannot
** determine its order-1 model between them: exit 0 (the fit is what was
** asked), but a warning on the report, on stderr, in the JSON and in the
** saved model; the whole run: none. */
START_TEST(test_pmfit_undetermined)
{
    char part[300], model[300], cmd[1400];
    char *text;
    const char *top = getenv("PM_TOP");
    make_tmpdir();
    snprintf(part, sizeof part, "%s/part.dat", tmpdir);
    snprintf(cmd, sizeof cmd, "head -20 '%s/examples/sim_gem.dat' > '%s'", top ? top : ".", part);
    ck_assert_int_eq(system(cmd), 0);
    snprintf(model, sizeof model, "%s/part.pm", tmpdir);
    ck_assert_int_eq(run("%s fit %s --save %s", part, model), 0);
    ck_assert_msg(strstr(out, "warning: the stars do not determine this model between them") !=
                      NULL, "%s", out);
    ck_assert_msg(strstr(out, "pmfit: warning: the stars do not determine") != NULL, "%s", out);
    text = tu_slurp(model);
    ck_assert_ptr_nonnull(text);
    ck_assert_msg(strstr(text, "# warning: the stars do not determine") != NULL, "%.400s", text);
    free(text);
    ck_assert_int_eq(run("%s fit %s --json%s", part, ""), 0);
    ck_assert_msg(strstr(out, "\"undetermined\": true") != NULL, "%s", out);
    snprintf(cmd, sizeof cmd, "%s/examples/sim_gem.dat", top ? top : ".");
    ck_assert_int_eq(run("%s fit %s --json%s", cmd, ""), 0);
    ck_assert_msg(strstr(out, "\"undetermined\": false") != NULL, "%s", out);
    ck_assert_ptr_null(strstr(out, "warning: the stars"));
}
END_TEST

/* The sign of a refraction finding in words: the run's places below
** where the telescope points (c < 0) is refraction missing from the
** reduction -- as --no-refraction shows on a real run (docs/model.md: c
** moves by -A) -- and above (c > 0) too much of it.  The words had the two
** the other way round. */
START_TEST(test_pmfit_explain_refraction_words)
{
    static const double size[2] = {-20, 20};
    static const char *said[2] = {"refraction missing from the reduction",
                                  "refraction over-corrected"};
    char runp[300], cmd[2400];
    int k;
    make_tmpdir();
    snprintf(runp, sizeof runp, "%s/refr.dat", tmpdir);
    for (k = 0; k < 2; k++) {
        snprintf(cmd, sizeof cmd,
                 "%s simulate %s --lat 40 --seed 7 --noise 1 --effect refraction=%g > /dev/null "
                 "&& %s explain %s",
                 tu_pmfit_path(), runp, size[k], tu_pmfit_path(), runp);
        ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
        ck_assert_msg(strstr(out, said[k]) != NULL, "refraction %g: %s", size[k], out);
        ck_assert_msg(strstr(out, said[1 - k]) == NULL, "refraction %g: %s", size[k], out);
    }
}
END_TEST

/* 20 points of an alt-az mount (a 20" azimuth runout under 3" noise):
** order 1's 22 terms are more than they determine (cross-validated RMS
** 18-21" against order 0's 8-10"); explain with --order 1 says so and
** points to --order 0, where it said the harmonics were "that one term" of
** a refraction consistent with zero.  Without --order, explain explains it
** at order 0 and says why: the runout found, 21.5" (an outside probe's 15
** stars with two 18-sigma outliers had "nothing significant is left out"
** at order 1).  The example run of 300 points: no such note. */
START_TEST(test_pmfit_explain_few_points_order0)
{
    char runp[300], cmd[2400];
    const char *top = getenv("PM_TOP");
    double v = 0, e = 1;
    make_tmpdir();
    snprintf(runp, sizeof runp, "%s/az20.dat", tmpdir);
    snprintf(cmd, sizeof cmd,
             "%s simulate %s --mount altaz --n 20 --noise 3 --seed 2 --effect ha_periodic:2=20 "
             "> /dev/null && %s explain %s --json",
             tu_pmfit_path(), runp, tu_pmfit_path(), runp);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"order_note\": \"20 points are too few to pin down the order-1 "
                              "baseline's 22 terms, and order 0 predicts them better") != NULL,
                  "%.3000s", out);
    ck_assert_msg(strstr(out, "\"effect\": \"ha_periodic\", \"label\": \"az_periodic\", "
                              "\"cycles_per_rev\": 2,") != NULL,
                  "%.3000s", out);
    v = tu_json_num(strstr(out, "\"label\": \"az_periodic\""), "amplitude_arcsec");
    e = tu_json_num(strstr(out, "\"label\": \"az_periodic\""), "amplitude_error_arcsec");
    ck_assert_msg(fabs(v - 20) < 3 * e, "runout %.2f +- %.2f (20 injected)", v, e);
    /* the report page's explain section the same (its fit stays order 1) */
    {
        char page[400];
        char *html;
        snprintf(page, sizeof page, "%s/az20.html", tmpdir);
        snprintf(cmd, sizeof cmd, "%s report %s -o %s -q", tu_pmfit_path(), runp, page);
        ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
        html = tu_slurp(page);
        ck_assert_ptr_nonnull(html);
        ck_assert_msg(strstr(html, "20 points are too few to pin down the order-1 baseline&apos;s 22 "
                                   "terms, and order 0 predicts them better") != NULL &&
                          strstr(html, "The baseline (order 0, P = 6)") != NULL,
                      "%.3000s", strstr(html, "What the model left out") ? strstr(html, "What the model left out") : html);
        free(html);
    }
    snprintf(cmd, sizeof cmd, "%s explain %s --order 1", tu_pmfit_path(), runp);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    /* (read with the runout the search finds at order 1 on both sides) */
    ck_assert_msg(strstr(out, "order 0, with the findings' terms, predicts better than the order-1 "
                              "baseline with them") != NULL,
                  "%s", out);
    ck_assert_msg(strstr(out, "explain with --order 0") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "are that one term") == NULL, "%s", out);
    /* 8 points, too few for order 1 at all (it was refused) and 12, where
    ** order 1 cannot predict most points from the others (a probe's 12
    ** stayed at order 1 on the cross-validation of the few it could) */
    ck_assert_int_eq(run("%s simulate %s --n 8 --seed 3 > /dev/null%s", runp, ""), 0);
    snprintf(cmd, sizeof cmd, "%s explain %s; %s explain %s --order 1", tu_pmfit_path(), runp,
             tu_pmfit_path(), runp);
    ck_assert_int_ne(tu_capture(cmd, out, sizeof out), 0);
    ck_assert_msg(strstr(out, "8 points are too few for the order-1 baseline's 22 terms (they "
                              "need 12): explained at order 0") != NULL &&
                      strstr(out, "baseline: order 0, P = 6") != NULL &&
                      strstr(out, "P = 22 terms need at least 12") != NULL,
                  "%s", out);
    snprintf(cmd, sizeof cmd,
             "%s simulate %s --mount altaz --n 12 --seed 1 > /dev/null && %s explain %s",
             tu_pmfit_path(), runp, tu_pmfit_path(), runp);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    ck_assert_msg(strstr(out, "12 points are too few to pin down the order-1 baseline's 22 terms") !=
                          NULL &&
                      strstr(out, "baseline: order 0, P = 6") != NULL,
                  "%s", out);
    snprintf(cmd, sizeof cmd, "%s explain %s/examples/sim_gem.dat", tu_pmfit_path(),
             top ? top : ".");
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);
    ck_assert_msg(strstr(out, "order 0 alone predicts") == NULL &&
                      strstr(out, "order 0, with the findings' terms, predicts") == NULL,
                  "%s", out);
}
END_TEST

/* eval of a model whose terms read an input the run does not give (a
** temperature model on a run without temperatures): an error at the first
** such record, where it printed "sky RMS 0.000"" with exit 0.  And a model
** file whose first comment is longer than 255 bytes (pmfit's own
** undetermined-fit warning is ~290) is still a model file to compare. */
START_TEST(test_pmfit_eval_missing_input_and_long_comment)
{
    char model[300], longm[300], cmd[2400], args[1400];
    const char *top = getenv("PM_TOP");
    if (!top)
        top = ".";
    make_tmpdir();
    snprintf(model, sizeof model, "%s/t.pm", tmpdir);
    snprintf(args, sizeof args, "%s/tests/data/indep_temp_sag_gem.dat --order 0 --add temperature "
             "--save %s", top, model);
    ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
    snprintf(args, sizeof args, "%s %s/tests/data/four_column.dat", model, top);
    ck_assert_int_eq(run("%s eval %s%s", args, ""), 1);
    ck_assert_msg(strstr(out, "four_column.dat:5: ") != NULL &&
                      strstr(out, "cannot be evaluated here") != NULL &&
                      strstr(out, "c'*temp") != NULL, "%s", out);
    ck_assert_ptr_null(strstr(out, "sky RMS"));
    /* the long comment */
    snprintf(longm, sizeof longm, "%s/long.pm", tmpdir);
    snprintf(cmd, sizeof cmd, "{ printf '# %%0300d\\n' 0; cat '%s'; } > '%s'", model, longm);
    ck_assert_int_eq(system(cmd), 0);
    snprintf(args, sizeof args, "%s %s/tests/data/indep_temp_sag_gem.dat", longm, top);
    ck_assert_msg(run("%s compare %s%s", args, "") == 0, "%s", out);
}
END_TEST

/* A run's auxiliary columns are found by name, not by position.  A run
** "a" with columns "hum press" whose encoder Dec reads 3" per hPa of
** pressure off, and the same records as "b" with the two columns swapped
** and as "c" without "press": the model fitted on a (aux:press) must
** evaluate on b exactly as on a -- it read b's "hum" as the pressure and
** gave an RMS of thousands of arcseconds with exit 0 -- and refuse c, where
** it read the derived "dec_dir" in the pressure's place.  compare (a model
** file or a run as OLD) likewise.  A version-3 file, which does not name
** its columns, is read by position with a note saying which column.  A
** model fitted with --pier split says its side, and eval uses that side's
** records only (it used all of them). */
static void write_aux_run(const char *base, const char *path, int order)
{
    FILE *in = fopen(base, "r"), *f = fopen(path, "w");
    char line[512];
    unsigned long long x = 12345;
    ck_assert_ptr_nonnull(in);
    ck_assert_ptr_nonnull(f);
    while (fgets(line, sizeof line, in)) {
        double eh, ed, hum, press;
        int used;
        line[strcspn(line, "\n")] = 0;
        if (line[0] == '#') {
            fprintf(f, "%s%s\n", line,
                    strncmp(line, "# tau", 5) ? ""
                    : order == 0 ? " hum press"
                    : order == 1 ? " press hum"
                    : order == 2 ? " hum" : " w1 w2 w3 w4 hum press");
            continue;
        }
        ck_assert_int_eq(sscanf(line, "%lf %lf%n", &eh, &ed, &used), 2);
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        hum = 50 + 30 * (double)(x >> 11) / 9007199254740992.0;
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        press = 1000 + 20 * (double)(x >> 11) / 9007199254740992.0;
        ed += 3.0 * (press - 1010) / 3600;
        fprintf(f, "%.10f %.10f%s ", eh, ed, line + used);
        if (order == 0)
            fprintf(f, "%.6f %.6f\n", hum, press);
        else if (order == 1)
            fprintf(f, "%.6f %.6f\n", press, hum);
        else if (order == 2)
            fprintf(f, "%.6f\n", hum);
        else
            fprintf(f, "1 2 3 4 %.6f %.6f\n", hum, press);
    }
    fclose(in);
    fclose(f);
}

START_TEST(test_pmfit_columns_by_name)
{
    char base[300], a[300], b[300], c[300], m[300], m3[300], h[300], sp[300], cmd[2000],
        args[1400];
    double rms_fit;
    int n_east = 0;
    FILE *f;
    make_tmpdir();
    snprintf(base, sizeof base, "%s/base.dat", tmpdir);
    snprintf(a, sizeof a, "%s/a.dat", tmpdir);
    snprintf(b, sizeof b, "%s/b.dat", tmpdir);
    snprintf(c, sizeof c, "%s/c.dat", tmpdir);
    snprintf(m, sizeof m, "%s/m.pm", tmpdir);
    snprintf(m3, sizeof m3, "%s/m3.pm", tmpdir);
    snprintf(h, sizeof h, "%s/m.h", tmpdir);
    snprintf(sp, sizeof sp, "%s/s.pm", tmpdir);
    ck_assert_int_eq(run("%s simulate %s --n 150 --seed 3%s", base, ""), 0);
    write_aux_run(base, a, 0);
    write_aux_run(base, b, 1);
    write_aux_run(base, c, 2);

    snprintf(args, sizeof args, "%s --add \"aux:press:e'\" --save %s --emit-c %s --json", a, m, h);
    ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
    rms_fit = tu_json_num(out, "rms_arcsec");
    ck_assert_double_lt(rms_fit, 2.0);
    snprintf(cmd, sizeof cmd, "grep -c '^input 1 press$' %s && grep -c '^pm-model 5$' %s && "
             "grep -c \"aux\\[1\\]: the run's column 'press'\" %s", m, m, h);
    ck_assert_msg(tu_capture(cmd, out, sizeof out) == 0, "%s", out);

    /* the table names the term's column (it said "aux input") */
    snprintf(args, sizeof args, "%s --add \"aux:press:e'\"", a);
    ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "e'*aux1      column 'press' on axis-2 index") != NULL, "%s", out);
    /* b: the columns swapped */
    snprintf(args, sizeof args, "%s %s --json", m, b);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    ck_assert_double_eq_tol(tu_json_num(out, "rms_arcsec"), rms_fit, 1e-6);
    /* a built-in input asked for as a column: said so (it said the run had
    ** no column 'temp', which it has) */
    snprintf(args, sizeof args, "%s --add aux:temp", a);
    ck_assert_int_ne(run("%s fit %s%s", args, ""), 0);
    ck_assert_msg(strstr(out, "'temp' is a built-in input, not an auxiliary column: --add "
                              "temperature reads it") != NULL, "%s", out);
    /* six columns, "press" the sixth (beyond the contexts' four: it was
    ** "put it among them") */
    {
        char d6[300];
        snprintf(d6, sizeof d6, "%s/d6.dat", tmpdir);
        write_aux_run(base, d6, 3);
        snprintf(args, sizeof args, "%s %s --json", m, d6);
        ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
        ck_assert_double_eq_tol(tu_json_num(out, "rms_arcsec"), rms_fit, 1e-6);
    }
    /* c: no "press" */
    snprintf(args, sizeof args, "%s %s", m, c);
    ck_assert_int_eq(run("%s eval %s%s", args, ""), 1);
    ck_assert_msg(strstr(out, "reads the column 'press', which") != NULL &&
                      strstr(out, "hum, dec_dir (derived from the sequence)") != NULL, "%s", out);
    /* a version-3 file: by position, said */
    {   /* the same model written without its information */
        pm_model mm;
        char err[512];
        ck_assert_msg(pmmodel_load(m, &mm, err, sizeof err) == 0, "%s", err);
        ck_assert_msg(pmmodel_save(m3, &mm, NULL, err, sizeof err) == 0, "%s", err);
    }
    snprintf(args, sizeof args, "%s %s --json", m3, b);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "does not name the column its term e'*aux1 reads") != NULL &&
                      strstr(out, "column 2, 'hum', is taken") != NULL, "%s", out);
    /* compare, OLD a model file and a run */
    snprintf(args, sizeof args, "%s %s --json", m, b);
    ck_assert_msg(run("%s compare %s%s", args, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"moved\": []") != NULL, "%s", out);
    snprintf(args, sizeof args, "%s %s --add \"aux:press:e'\" --json", a, b);
    ck_assert_msg(run("%s compare %s%s", args, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"moved\": []") != NULL, "%s", out);
    ck_assert_double_lt(tu_json_num(out, "rms_as_is_arcsec"), 2.0);

    /* --pier split: each file its side */
    snprintf(args, sizeof args, "%s --pier split --save %s", a, sp);
    ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
    f = fopen(a, "r");
    ck_assert_ptr_nonnull(f);
    while (fgets(cmd, sizeof cmd, f))
        n_east += cmd[0] != '#' && strstr(cmd, " E ") != NULL;
    fclose(f);
    ck_assert_int_gt(n_east, 20);
    ck_assert_int_lt(n_east, 130);
    snprintf(args, sizeof args, "%s-east %s --json", sp, a);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    ck_assert_int_eq((int)tu_json_num(out, "n_obs"), n_east);
    ck_assert_msg(strstr(out, "pier side east (normal) only") != NULL, "%s", out);
    snprintf(args, sizeof args, "%s-west %s --json", sp, a);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    ck_assert_int_eq((int)tu_json_num(out, "n_obs"), 150 - n_east);
}
END_TEST

/* explain on an equatorial run without a latitude cannot try refraction
** and tube flexure (their elevation needs it): it says so, in the text and
** the JSON (it said nothing, and a 5" refraction was named higher_order). */
START_TEST(test_pmfit_explain_says_what_it_cannot_try)
{
    char path[300], cmd[1200];
    const char *top = getenv("PM_TOP");
    make_tmpdir();
    snprintf(path, sizeof path, "%s/nolat.dat", tmpdir);
    snprintf(cmd, sizeof cmd, "grep -v '^# latitude' %s/examples/sim_gem.dat > %s",
             top ? top : ".", path);
    ck_assert_int_eq(system(cmd), 0);
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "not tried: refraction and tube flexure") != NULL, "%s", out);
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"not_tried\": [{\"effect\": \"refraction\", \"why\": \"the run "
                              "gives no latitude\"}, {\"effect\": \"tube_flexure\"") != NULL,
                  "%.3000s", out);
    /* without temperature and time columns: temperature and time_drift
    ** (the MMT run's JSON had said nothing was left untried) */
    snprintf(path, sizeof path, "%s/notime.dat", tmpdir);
    snprintf(cmd, sizeof cmd,
             "awk '/^# latitude/ {print} /^[^#]/ {print $1, $2, $3, $4}' %s/examples/sim_gem.dat > %s",
             top ? top : ".", path);
    ck_assert_int_eq(system(cmd), 0);
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"not_tried\": [{\"effect\": \"temperature\", \"why\": \"the run gives no "
                              "temperatures\"}, {\"effect\": \"time_drift\", \"why\": \"the run gives "
                              "no times\"}]") != NULL,
                  "%.3000s", out);
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "not tried: temperature: the run gives no temperatures") != NULL,
                  "%s", out);
    snprintf(path, sizeof path, "%s/examples/sim_gem.dat", top ? top : ".");
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"not_tried\": []") != NULL, "%.3000s", out);
}
END_TEST

/* An alt-az run as a cable-wrapped controller writes it: the azimuth as a
** count from lo to lo + span degrees (not reduced), no direction column;
** index errors, a backlash h (arcsec, half of it per unit of the slew
** direction on azimuth) and an offset w (arcsec, on the azimuth index) on
** the turn beyond a count of 360 deg; 1" of noise.  A gimbal of its own
** (not pmfit simulate).  Returns the number of moves over 180 deg. */
/* A coefficient of pmfit's JSON: the value and error (arcsec) of the first
** coefficient named by key (e.g. "\"name\": \"c'*dir\"") after the first
** occurrence of `after` (NULL: anywhere in out).  0 where there is none. */
static int json_coef(const char *after, const char *key, double *v, double *e)
{
    const char *p = after ? strstr(out, after) : out;
    p = p ? strstr(p, key) : NULL;
    p = p ? strstr(p, "\"value_arcsec\"") : NULL;
    return p && sscanf(p, "\"value_arcsec\": %lf, \"error_arcsec\": %lf", v, e) == 2;
}

static long write_altaz_run(const char *path, unsigned long long seed, double lo, double span,
                            double h_as, double w_as, double el_lo, double el_hi, double flex_as,
                            double noise_as, int n);
static long write_counted_altaz(const char *path, unsigned long long seed, double lo, double span,
                                double h_as, double w_as)
{
    return write_altaz_run(path, seed, lo, span, h_as, w_as, 20, 80, 0, 1, 150);
}

/* The same with the elevations drawn from el_lo..el_hi deg, a tube sag of
** flex_as arcsec times cos(el) toward the horizon, noise_as arcsec of
** noise per axis and n points. */
static long write_altaz_run(const char *path, unsigned long long seed, double lo, double span,
                            double h_as, double w_as, double el_lo, double el_hi, double flex_as,
                            double noise_as, int n)
{
    FILE *f = fopen(path, "w");
    const double h = h_as / 3600, w = w_as / 3600, ia = 300.0 / 3600, ie = -120.0 / 3600;
    const double noise = noise_as / 3600, deg = 3.14159265358979323846 / 180;
    double prev = lo + 0.5 * span;
    unsigned long long x = seed;
    long long_moves = 0;
    ck_assert_ptr_nonnull(f);
    fprintf(f, "# mount: altaz\n# latitude: 32\n# tau delta T D\n");
    for (int i = 0; i < n; i++) {
        double u[4];
        for (int k = 0; k < 4; k++) { /* LCG, uniform in (0, 1) */
            x = x * 6364136223846793005ULL + 1442695040888963407ULL;
            u[k] = ((double)(x >> 11) + 0.5) / 9007199254740992.0;
        }
        const double raw = lo + span * u[0], el = el_lo + (el_hi - el_lo) * u[1];
        const int dir = i == 0 ? 0 : (raw > prev ? 1 : -1);
        long_moves += fabs(raw - prev) > 180;
        prev = raw;
        /* noise on the sky: uniform, sqrt 3 times the RMS */
        const double ns = noise * sqrt(3.0) * (2 * u[2] - 1), nd = noise * sqrt(3.0) * (2 * u[3] - 1);
        const double az = fmod(raw + ia + h * dir + (raw >= 360 ? w : 0) + ns / cos(el * deg), 360.0);
        fprintf(f, "%.7f %.7f %.7f %.7f\n", raw, el, az,
                el - ie - flex_as / 3600 * cos(el * deg) + nd);
    }
    fclose(f);
    return long_moves;
}

/* An alt-az controller that writes its azimuth as a count past a turn (a
** cable wrap's 90..450 deg here), without a direction column: the slew
** direction is the count's, however far the move; the short way round had
** read every move over 180 deg backwards, the backlash at half its size and
** false gear periods beside it (an outside probe). */
START_TEST(test_pmfit_altaz_counted_azimuth_direction)
{
    char path[300];
    double h_fit = 0, h_err = 1;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/counted.dat", tmpdir);
    ck_assert(write_counted_altaz(path, 12345, 90, 360, 4, 0) > 30);
    ck_assert_msg(run("%s fit %s --order 0 --add hysteresis --json%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(json_coef(NULL, "\"name\": \"c'*dir\"", &h_fit, &h_err), "%.2000s", out);
    ck_assert_msg(fabs(h_fit - 4.0) < 4 * h_err && h_err < 0.3, "c'*dir %.3f +- %.3f (4 injected)",
                  h_fit, h_err);
    /* A file in 0..360 deg with one record written 360.000000 (359.9999997
    ** to six decimals), or -180 in -180..180 (atan2), is not a count: read
    ** as its sister file with 0 (or 180) there (one such record had turned
    ** every move across the cut the long way round; an outside probe). */
    {
        static const char *const ends[2][2] = {{"0.0000000", "360.0000000"},
                                               {"180.0000000", "-180.0000000"}};
        for (int k = 0; k < 2; k++) {
            double v[2];
            write_counted_altaz(path, 999, k ? -180 : 0, 360, 4, 0);
            for (int e = 0; e < 2; e++) {
                char cmd[1600];
                /* the first record's encoder azimuth at the range's end, its
                ** star's azimuth moved with it (their difference kept) */
                snprintf(cmd, sizeof cmd,
                         "awk 'BEGIN {done = 0} /^#/ {print; next} !done {o = $3 - $1; "
                         "o -= 360 * int(o / 360 + (o < 0 ? -0.5 : 0.5)); $3 = sprintf(\"%%.7f\", "
                         "%s + o); $1 = \"%s\"; done = 1} {print}' %.300s > %.300s.end && "
                         "mv %.300s.end %.300s",
                         ends[k][e], ends[k][e], path, path, path, path);
                ck_assert_int_eq(system(cmd), 0);
                ck_assert_msg(run("%s fit %s --order 0 --add hysteresis --json%s", path, "") == 0,
                              "%.2000s", out);
                double err;
                ck_assert_msg(json_coef(NULL, "\"name\": \"c'*dir\"", &v[e], &err), "%.2000s",
                              out);
            }
            /* (this gimbal never crosses the file's cut, which a 0..360
            ** file cannot show: both read the short way round, alike) */
            ck_assert_msg(v[0] == v[1], "%s: c'*dir %.4f, %s: %.4f", ends[k][0], v[0], ends[k][1],
                          v[1]);
        }
    }
}
END_TEST

/* A file in 0..360 deg of a mount that never turns through north (its
** directions are the count's; the generator's mount so): explain finds the
** slew directions fit far better read so, says it, explains so, and its
** closing command carries --azimuth-count, which fit takes (the short way
** round had read the backlash at a third and stacked false gears on it; an
** outside probe's 6 of 6).  Reading options repeat in the closing command
** (--equinox J2000 had been dropped from it). */
START_TEST(test_pmfit_explain_azimuth_count_reading)
{
    char path[300];
    double h_fit = 0, h_err = 1;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/count360.dat", tmpdir);
    ck_assert(write_counted_altaz(path, 4242, 0, 360, 4, 0) > 30);
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "fit far better with the file's azimuth read as the mount's count") &&
                      strstr(out, "--add 'hysteresis'") && strstr(out, " --azimuth-count   #") &&
                      !strstr(out, "az_periodic"),
                  "%.3000s", out);
    ck_assert_msg(run("%s fit %s --order 0 --add hysteresis --azimuth-count --json%s", path, "") ==
                      0,
                  "%.2000s", out);
    ck_assert_msg(json_coef(NULL, "\"name\": \"c'*dir\"", &h_fit, &h_err), "%.2000s", out);
    ck_assert_msg(fabs(h_fit - 4.0) < 4 * h_err && h_err < 0.3, "c'*dir %.3f +- %.3f (4 injected)",
                  h_fit, h_err);
    /* with a periodic azimuth error beside the backlash, which the first
    ** check leaves out (an outside probe's generator, tests/ref/altaz_gen_y.py:
    ** the backlash had been read at half its size, 2.65" for 5") */
    snprintf(path, sizeof path, "%s/tests/data/altaz_count_pe.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(json_coef("\"effect\": \"hysteresis\"", "\"name\": \"c'*dir\"", &h_fit, &h_err),
                  "%.2000s", out);
    ck_assert_msg(fabs(h_fit - 5.0) < 4 * h_err && h_err < 0.3, "c'*dir %.3f +- %.3f (5 injected)",
                  h_fit, h_err);
    /* a short-way mount's backlash of 10 sigma: the run's first record, whose
    ** slew direction cannot be known, misses by it, and is said to be so, not
    ** only "a failed plate solve" (an outside probe's, each such run) */
    snprintf(path, sizeof path, "%s/tests/data/altaz_short_backlash.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "line 5 is the run's first record, the direction of whose slew "
                              "cannot be known") != NULL &&
                      strstr(out, "azimuth-count") == NULL,
                  "%.3000s", out);
    /* a mount that does take the short way (pmfit simulate's) is not read so */
    snprintf(path, sizeof path, "%s/short.dat", tmpdir);
    ck_assert_int_eq(run("%s simulate %s --mount altaz --n 150 --seed 3 --effect hysteresis=3%s",
                         path, ""),
                     0);
    {
        char cmd[1600];
        snprintf(cmd, sizeof cmd,
                 "awk '/^# tau/ {print \"# tau delta T D temp time\"; next} /^#/ {print; next} "
                 "{a = $1; t = $3; if (a < 0) a += 360; if (t < 0) t += 360; "
                 "print a, $2, t, $4, $5, $6}' %.300s > %.300s.n && mv %.300s.n %.300s",
                 path, path, path, path);
        ck_assert_int_eq(system(cmd), 0);
    }
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(!strstr(out, "azimuth-count") && strstr(out, "1. hysteresis"), "%.3000s", out);
    /* the reading options in the closing command */
    snprintf(path, sizeof path, "%s/tests/data/rts2_gpoint_j2000.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s --order 0 --equinox J2000 --no-refraction%s", path, "") == 0,
                  "%.2000s", out);
    ck_assert_msg(strstr(out, " --no-refraction --equinox J2000   # fits") != NULL, "%.3000s", out);
}
END_TEST

/* The sag held by the order-1 terms on skies that nearly confound them
** (outside probe Z2's control run, tests/ref/altaz_gen_z2.py: 40 stars at
** elevations 10-35 deg, a sag of -6"; a fork near the pole with no sag;
** probe AA's fork at declinations 75-88 deg with a 15" sag,
** tests/ref/sim_aa_fork_pole.py): a reading given is within 3 sigma of the
** truth, and where its error is above 100", or it disagrees with the direct
** fit of order 0 + tube_flexure that fixes it ten times better, it says it
** is not determined / not read.  (Rounding of 1e-9 on the other terms of
** the combination had read 3026" +- 86" and -727533" +- 80332"; the pole
** fork 224.66" +- 32.12", "consistent with a pure sag".) */
START_TEST(test_pmfit_explain_sag_reading_on_a_band)
{
    static const struct {
        const char *file;
        double truth;
        int determined;
    } c[3] = {{"altaz_lowband_sag.dat", -6, 0}, {"outside_fork_pole_dec_index.dat", 0, 1},
              {"fork_pole_sag.dat", 15, 0}};
    char path[300];
    int k;
    for (k = 0; k < 3; k++) {
        const char *p;
        double v, e;
        snprintf(path, sizeof path, "%s/tests/data/%s", getenv("PM_TOP") ? getenv("PM_TOP") : ".",
                 c[k].file);
        ck_assert_msg(run("%s explain %s --json 2>/dev/null%s", path, "") == 0, "%.2000s", out);
        p = strstr(out, "\"what\": \"tube_flexure_in_order1\"");
        ck_assert_msg(p != NULL, "%s: %.2000s", c[k].file, out);
        v = tu_json_num(p, "value");
        e = tu_json_num(p, "error");
        if (c[k].determined)
            ck_assert_msg(fabs(v - c[k].truth) <= 3 * e, "%s: sag %.2f +- %.2f, truth %.0f",
                          c[k].file, v, e, c[k].truth);
        {
            const char *nd = strstr(p, "not determined on this sky"), *nr = strstr(p, "not read on this sky");
            const char *end = strchr(p, '}');
            ck_assert_msg(((nd && nd < end) || (nr && nr < end)) == !c[k].determined, "%s: %.600s",
                          c[k].file, p);
        }
        ck_assert_msg(!c[k].determined || e < 20, "%s: +- %.2f", c[k].file, e);
    }
}
END_TEST

/* A model saved from a fit of hardly more stars than terms reads back: an
** outside probe's closed loop of 26 stars, order 2 (46 terms, two of them
** correlated -0.99999), had been refused by eval reading its own --save
** ("the correlations are not those of a covariance"). */
START_TEST(test_pmfit_save_nearly_singular_reads_back)
{
    char path[300], model[300];
    make_tmpdir();
    snprintf(path, sizeof path, "%s/tests/data/plan_loop_altaz26.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    snprintf(model, sizeof model, "%s/m26.pm", tmpdir);
    ck_assert_msg(run("%s fit %s --order 2 --save %s", path, model) == 0, "%.2000s", out);
    ck_assert_msg(run("%s eval %s %s", model, path) == 0, "%.2000s", out);
    ck_assert_msg(run("%s compare %s %s", model, path) == 0, "%.2000s", out);
}
END_TEST

/* A baseline the sky cannot fit: a fork's 200 stars in a band of
** declination (outside probe Z1's generator, tests/ref/equ_gen_z1.py) fail at
** order 1 with advice that fits a one-sided run's mount (it had said "use
** both pier sides" to a fork), and --order 0 explains it. */
START_TEST(test_pmfit_explain_baseline_advice)
{
    char path[300];
    snprintf(path, sizeof path, "%s/tests/data/fork_decband.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_int_eq(run("%s explain %s%s", path, ""), 1);
    ck_assert_msg(strstr(out, "the baseline fit failed") &&
                      strstr(out, "lower --order or add stars over more of the sky (a German "
                                  "mount: on both pier sides)") &&
                      !strstr(out, "lower --order or use both pier sides"),
                  "%.2000s", out);
    ck_assert_msg(run("%s explain %s --order 0%s", path, "") == 0, "%.2000s", out);
}
END_TEST

/* A declination worm in a band of 20-30 deg (outside probe Z1's generator,
** tests/ref/equ_gen_z1.py; the commands in the files' first lines): the
** true count, where an alias had been named (141.36 for 144, "141.28 to
** 141.44 fit as well"; 177 for 180), and an alias that fits as well listed
** (the 180's 177). */
START_TEST(test_pmfit_explain_period_aliases)
{
    static const struct {
        const char *file;
        double G;
    } c[2] = {{"dec_alias_band80.dat", 144}, {"dec_alias_band40c.dat", 180}};
    char path[300];
    int k;
    for (k = 0; k < 2; k++) {
        const char *p;
        snprintf(path, sizeof path, "%s/tests/data/%s", getenv("PM_TOP") ? getenv("PM_TOP") : ".",
                 c[k].file);
        ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
        p = strstr(out, "\"effect\": \"dec_periodic\"");
        ck_assert_msg(p != NULL, "%s: %.2000s", c[k].file, out);
        ck_assert_msg(tu_json_num(p, "cycles_per_rev") == c[k].G, "%s: %.600s", c[k].file, p);
    }
    ck_assert_msg(strstr(out, "\"cycles_per_rev_aliases\": [177]") != NULL, "%.2000s", out);
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "; 177 cycles (other peaks) fit as well (chi^2 within 3.84, 95%)") !=
                      NULL,
                  "%.3000s", out);
}
END_TEST

/* What the order-1 baseline holds, read with the findings' terms (outside
** probe Z1's generator, tests/ref/equ_gen_z1.py, the command in each file's
** first line):
** - a 15" declination step on the west side of a German mount whose flip
**   zone is +-15 deg: the sides are two hemispheres of the mechanical
**   sphere and the order-1 terms held most of it, with no finding and no
**   word (sigma 3.6" on 3" of noise); the reading names the pier side, e'@W
**   within 3 sigma of the -15" the generator put there (the generator
**   moves the west side's encoder declination by +15", read as true minus
**   encoder), and its 8.05" sag;
** - the same mount and sky without the step: no pier side read;
** - a dec backlash of 9" on a southern German mount, found by the search:
**   read before the search, the sag held by order 1 had been -14.09" +-
**   1.58" of the generator's -8.55" (3.5 sigma), since the backlash's
**   slews differed between the sides; with the findings' terms it is
**   within 3 sigma, and no pier side. */
static double reading_value(const char *s, const char *key, double *err)
{
    const char *p = strstr(s, key), *q;
    char *end;
    double v = NAN;
    *err = NAN;
    if (!p)
        return NAN;
    v = strtod(p + strlen(key), &end); /* the value, then (JSON-escaped) "\" +- error" */
    q = strstr(end, "+- ");
    if (end == p + strlen(key) || !q || q - end > 4)
        return NAN;
    *err = strtod(q + 3, NULL);
    return v;
}

START_TEST(test_pmfit_explain_reading_pier_step)
{
    static const struct {
        const char *file;
        int pier;       /* the reading names the pier side */
        double pier_e;  /* its e'@W (arcsec) */
        double sag;     /* the sag, read toward the zenith (arcsec) */
    } c[3] = {{"gem_flipzone_pier.dat", 1, -15.0, 8.054},
              {"gem_flipzone_none.dat", 0, 0, 8.054},
              {"gem_dec_backlash_s.dat", 0, 0, -8.546}};
    char path[300];
    int k;
    for (k = 0; k < 3; k++) {
        const char *p;
        double v, e;
        snprintf(path, sizeof path, "%s/tests/data/%s", getenv("PM_TOP") ? getenv("PM_TOP") : ".",
                 c[k].file);
        ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
        p = strstr(out, "\"physical_reading\": \"");
        ck_assert_msg(p != NULL, "%s: no reading: %.3000s", c[k].file, out);
        ck_assert_msg((strstr(p, "pier_side (e'@W") != NULL) == c[k].pier, "%s: %.600s",
                      c[k].file, p);
        if (c[k].pier) {
            v = reading_value(p, "e'@W", &e);
            ck_assert_msg(fabs(v - c[k].pier_e) <= 3 * e, "%s: e'@W %g +- %g: %.600s", c[k].file,
                          v, e, p);
        }
        v = reading_value(p, "tube_flexure (", &e);
        ck_assert_msg(fabs(v - c[k].sag) <= 3 * e, "%s: sag %g +- %g: %.600s", c[k].file, v, e,
                      p);
    }
}
END_TEST

/* Refraction and tube flexure share their shape over a run's elevations:
** 20 stars of a German mount (probe Z1's generator, the command in the
** file's first line) with a 24" over-corrected refraction (cot el toward the
** zenith) and a 15.65" sag (toward the horizon, read -15.65): explain names
** the refraction at order 0, 17.01" +- 0.68", 10 sigma from its truth, as
** the sag is left in it.  The finding now carries the two fitted together,
** each within 3 sigma of its truth, and says so in words. */
START_TEST(test_pmfit_explain_refraction_beside_sag)
{
    char path[300];
    const char *p;
    double v, e, ov, oe;
    snprintf(path, sizeof path, "%s/tests/data/gem20_refr_sag.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    p = strstr(out, "\"effect\": \"refraction\"");
    ck_assert_msg(p != NULL, "%.2000s", out);
    p = strstr(p, "\"beside\": {\"effect\": \"tube_flexure\"");
    ck_assert_msg(p != NULL, "%.3000s", out);
    v = tu_json_num(p, "value_arcsec");
    e = tu_json_num(p, "error_arcsec");
    ov = tu_json_num(p, "other_value_arcsec");
    oe = tu_json_num(p, "other_error_arcsec");
    ck_assert_msg(fabs(v - 24.0) <= 3 * e && fabs(ov + 15.65) <= 3 * oe,
                  "refraction %g +- %g (24), sag %g +- %g (-15.65)", v, e, ov, oe);
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "with tube_flexure beside it (at its step): refraction ") != NULL &&
                      strstr(out, "both are measured, and the size above holds part of the other"),
                  "%.3000s", out);
    /* What the order-1 baseline holds, with the two tried together: another
    ** seed's 24" refraction beside a 14.16" sag (read -14.16") had been read
    ** "order 0 + refraction (17.98" +- 0.89")", 6.8 sigma off; now both,
    ** each within 3 sigma. */
    snprintf(path, sizeof path, "%s/tests/data/gem20_refr_sag22.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s --order 1 --json%s", path, "") == 0, "%.2000s", out);
    p = strstr(out, "\"physical_reading\": \"");
    ck_assert_msg(p != NULL, "%.2000s", out);
    v = reading_value(p, "tube_flexure (", &e);
    ov = reading_value(p, "refraction (", &oe);
    ck_assert_msg(fabs(v + 14.16) <= 3 * e && fabs(ov - 24.0) <= 3 * oe,
                  "sag %g +- %g (-14.16), refraction %g +- %g (24): %.600s", v, e, ov, oe, p);
}
END_TEST

/* A sigma on few degrees of freedom: the error map's JSON gives 2N - P and
** the 95% range of the true sigma over it, and where the range's top is
** above 2 (2N - P <= 7) the fit warns (an outside probe's 5 stars for 9
** terms: sigma 0.154" for 1" of noise, the map 0.283" where the model was
** 1.53" off, without a word).  The ranges are scipy's (beyond 100 degrees
** of freedom Wilson and Hilferty's form; the series had overflowed at 2000):
**   python3 -c "from scipy.stats import chi2; import math; k = 7;
**               print(math.sqrt(k / chi2.ppf(0.975, k)), math.sqrt(k / chi2.ppf(0.025, k)))" */
START_TEST(test_pmfit_few_dof_warning)
{
    static const struct {
        int n, tf;
        long dof;
        double lo, hi;
    } c[7] = {{4, 1, 1, 0.4461491849, 31.910159350}, {4, 0, 2, 0.5206582667, 6.2847346965},
              {7, 1, 7, 0.6611741488, 2.0352720908}, {7, 0, 8, 0.6754570344, 1.9157708829},
              {13, 0, 20, 0.7650591375, 1.4440694900}, {56, 0, 106, 0.8816052035, 1.1554181825},
              {1003, 0, 2000, 0.9699502859, 1.0319851395}};
    char path[300], n[16];
    int k;
    make_tmpdir();
    for (k = 0; k < 7; k++) {
        const char *p;
        snprintf(path, sizeof path, "%s/s%d.dat", tmpdir, c[k].n);
        snprintf(n, sizeof n, "%d", c[k].n);
        ck_assert_int_eq(run("%s simulate %s --seed 3 --n %s > /dev/null", path, n), 0);
        ck_assert_msg(run(c[k].tf ? "%s fit %s --order 0 --add tube_flexure --json%s"
                                  : "%s fit %s --order 0 --json%s",
                          path, "") == 0,
                      "%.2000s", out);
        p = strstr(out, "\"sigma_dof\": ");
        ck_assert_msg(p != NULL, "%.2000s", out);
        ck_assert_int_eq((long)tu_json_num(p, "sigma_dof"), c[k].dof);
        p = strstr(p, "\"sigma_factor_95\": [");
        ck_assert_ptr_nonnull(p);
        {
            double lo = 0, hi = 0;
            ck_assert_int_eq(sscanf(p, "\"sigma_factor_95\": [%lf, %lf]", &lo, &hi), 2);
            ck_assert_msg(fabs(lo / c[k].lo - 1) < 2e-4 && fabs(hi / c[k].hi - 1) < 2e-4,
                          "dof %ld: %g..%g, scipy %g..%g", c[k].dof, lo, hi, c[k].lo, c[k].hi);
        }
        ck_assert_msg((strstr(out, "rest on only") != NULL) == (c[k].hi > 2), "dof %ld: %.2000s",
                      c[k].dof, out);
    }
    ck_assert_msg(strstr(out, "rest on only") == NULL, "%.2000s", out);
    ck_assert_int_eq(run("%s fit %s/s4.dat --order 0 --add tube_flexure%s", tmpdir, ""), 0);
    ck_assert_msg(strstr(out, "its sigma, and the map scaled by it, rest on only 1 degree of "
                              "freedom (2N - P): the true sigma may be 0.45 to 31.9 times it") != NULL,
                  "%.2000s", out);
}
END_TEST

/* Where a pier-side offset is: between the sides, not the bin where the
** refit moved the model most (outside probe Z1's generator: a west-side
** offset on 80 stars was "largest at hour angle 6h..12h", 3 stars of the
** normal side). */
START_TEST(test_pmfit_explain_pier_side_where)
{
    char path[300];
    snprintf(path, sizeof path, "%s/tests/data/gem_pier_side_west.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "1. pier_side:") != NULL &&
                      strstr(out, "where: between the pier sides: the 36 points beyond the pole "
                                  "(pier west) against the 44 of the normal side") != NULL &&
                      strstr(out, "where: largest at hour angle 6h..12h") == NULL,
                  "%.3000s", out);
}
END_TEST

/* A cable's drag that grows as the wrap winds (66.7" a turn of the
** count, over -270..270 deg) against a step past count 0 (25"), outside
** probe Z2's generator (tests/ref/altaz_gen_z2.py): the drag is named
** cable_drag at its size, the step cable_wrap (a drag had been named a
** step "on the next turn", with false gears beside it). */
START_TEST(test_pmfit_explain_cable_drag)
{
    char path[300];
    double v = 0, e = 1;
    snprintf(path, sizeof path, "%s/tests/data/altaz_cable_drag.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "\"findings\": [{\"effect\": \"cable_drag\"") != NULL, "%.3000s",
                  out);
    ck_assert_msg(json_coef("\"effect\": \"cable_drag\"", "\"column\": \"az_wind\"", &v, &e),
                  "%.2000s", out);
    ck_assert_msg(fabs(v + 66.67) < 3 * e && e < 4, "drag %.2f +- %.2f a turn (-66.7)", v, e);
    /* its order-2 candidate judged: pmfit fit's passes from the cold start
    ** (it had been "not judged: its fit did not converge") */
    ck_assert_msg(strstr(out, "\"not_converged\": []") != NULL, "%.3000s", out);
    snprintf(path, sizeof path, "%s/tests/data/altaz_cable_step.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "\"findings\": [{\"effect\": \"cable_wrap\"") != NULL &&
                      strstr(out, "\"effect\": \"cable_drag\"") == NULL,
                  "%.3000s", out);
}
END_TEST

/* The weather of the refraction from the command line (--pressure,
** --temperature, --humidity, --wavelength), for files that lack it (an
** RTS2 gpoint file never has it): the CSV log's weather given as options
** for a copy without its metadata fits to the same JSON byte for byte as
** the file with it; options override the file's (a wrong weather fits
** worse); explain's closing command repeats them; bad values are refused
** naming the option; where no reduction refracts, a note says they were
** not used. */
START_TEST(test_pmfit_weather_options)
{
    char path[300], bare[300], cmd[1200];
    static char with_meta[sizeof out];
    const char *top = getenv("PM_TOP") ? getenv("PM_TOP") : ".";
    double s_file, s_wrong;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/tests/data/nina_j2000.csv", top);
    snprintf(bare, sizeof bare, "%s/bare.csv", tmpdir);
    snprintf(cmd, sizeof cmd, "grep -v '^# pressure\\|^# temperature' %s > %s", path, bare);
    ck_assert_int_eq(system(cmd), 0);
    ck_assert_msg(run("%s fit %s --order 0 --json%s", path, "") == 0, "%.2000s", out);
    ck_assert(strstr(out, "{\"n_obs\"") != NULL);
    snprintf(with_meta, sizeof with_meta, "%s", strstr(out, "{\"n_obs\"")); /* (the JSON) */
    s_file = tu_json_num(out, "sigma_arcsec");
    ck_assert_msg(run("%s fit %s --order 0 --json --pressure 950 --temperature 10%s",
                      bare, "") == 0,
                  "%.2000s", out);
    ck_assert_msg(strstr(out, "{\"n_obs\"") && strcmp(strstr(out, "{\"n_obs\""), with_meta) == 0,
                  "options:\n%.1500s\nmetadata:\n%.1500s", out, with_meta);
    /* without them: the standard atmosphere and the temperature column */
    ck_assert_msg(run("%s fit %s --order 0 --json%s", bare, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "{\"n_obs\"") && strcmp(strstr(out, "{\"n_obs\""), with_meta) != 0,
                  "%.2000s", out);
    ck_assert_msg(run("%s fit %s --order 0 --json --pressure 700 --temperature -10%s",
                      path, "") == 0,
                  "%.2000s", out);
    s_wrong = tu_json_num(out, "sigma_arcsec");
    ck_assert_msg(s_wrong > 5 * s_file, "sigma %.3f with the wrong weather, %.3f", s_wrong, s_file);
    /* explain repeats them */
    ck_assert_msg(run("%s explain %s --order 0 --pressure 950 --temperature 10 --humidity 0.5 "
                      "--wavelength 0.55%s",
                      bare, "") == 0,
                  "%.2000s", out);
    ck_assert_msg(strstr(out, " --pressure 950 --temperature 10 --humidity 0.5 --wavelength 0.55   "
                              "# fits") != NULL,
                  "%.3000s", out);
    /* bad values, named */
    ck_assert_int_ne(run("%s fit %s --pressure 2000%s", bare, ""), 0);
    ck_assert_msg(strstr(out, "--pressure: expected a number in") != NULL, "%.2000s", out);
    ck_assert_int_ne(run("%s fit %s --temperature warm%s", bare, ""), 0);
    ck_assert_msg(strstr(out, "--temperature: expected a number") != NULL, "%.2000s", out);
    /* unit slips refused (inches of mercury, percent), as an outside probe's
    ** 29.9 and 1.5 had been read as hPa and as 1.5% */
    ck_assert_int_ne(run("%s fit %s --pressure 29.9%s", bare, ""), 0);
    ck_assert_msg(strstr(out, "(in inches of mercury that is 1013 hPa)") != NULL, "%.2000s", out);
    ck_assert_int_ne(run("%s fit %s --humidity 50%s", bare, ""), 0);
    ck_assert_msg(strstr(out, "--humidity: expected a fraction in 0..1, got '50' (50% is 0.5)") !=
                      NULL,
                  "%.2000s", out);
    ck_assert_int_ne(run("%s fit %s --humidity 1.5%s", bare, ""), 0);
    ck_assert_int_ne(run("%s simulate %s/sim.dat --pressure 900%s", tmpdir, ""), 0);
    ck_assert_msg(strstr(out, "apply to reading a run") != NULL, "%.2000s", out);
    /* not used where nothing is refracted (observed places) */
    snprintf(path, sizeof path, "%s/tests/data/rts2_gpoint.dat", top);
    ck_assert_msg(run("%s fit %s --order 0 --pressure 900%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "the weather options (pressure, temperature, humidity, wavelength) "
                              "are not used") != NULL,
                  "%.2000s", out);
    ck_assert_msg(run("%s fit %s --order 0%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "weather options") == NULL, "%.2000s", out);
}
END_TEST

/* A cable wrap's second turn: where the azimuth count spans more than a
** turn (0..540 deg), explain tries the input az_turn (0, or 1 past 360)
** and names an offset there as cable_wrap (an outside probe's 10" and 30"
** had been called bad points, or false gears); on the same sky without it,
** not. */
START_TEST(test_pmfit_explain_cable_wrap)
{
    char path[300];
    double v = 0, e = 1;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/wrap.dat", tmpdir);
    write_counted_altaz(path, 777, 0, 540, 0, 10);
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    static const char turn[] = "\"name\": \"c'*aux1\", \"column\": \"az_turn\"";
    ck_assert_msg(json_coef("\"effect\": \"cable_wrap\"", turn, &v, &e), "%.2000s", out);
    ck_assert_msg(fabs(v - 10.0) < 4 * e && e < 1, "c'*az_turn %.3f +- %.3f (10 injected)", v, e);
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "--add 'aux:az_turn'") != NULL, "%.2000s", out);
    write_counted_altaz(path, 777, 0, 540, 0, 0);
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "\"effect\": \"cable_wrap\"") == NULL, "%.2000s", out);
    /* a count over 90..450 deg, each azimuth once: the turn is a step at
    ** north (it had not been tried there, and 30" were read as gears) */
    write_counted_altaz(path, 778, 90, 360, 0, 30);
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(json_coef("\"effect\": \"cable_wrap\"", turn, &v, &e), "%.2000s", out);
    ck_assert_msg(fabs(v - 30.0) < 4 * e && e < 1.5, "c'*az_turn %.3f +- %.3f (30 injected)", v, e);
}
END_TEST

/* Two readings that fit nearly as well are both given, where the rival
** only just misses alpha alone: a tube sag on a low sky (15-35 deg) read
** as refraction at false-alarm 0.008, tube_flexure 0.7 in Delta BIC behind
** at 0.013, had been named without it (an outside probe's 1 of 8 runs; this
** run is of write_altaz_run's own gimbal, seed 34 of 40, the one of them
** where the reading went to refraction with the rival above alpha). */
START_TEST(test_pmfit_explain_close_rival_above_alpha)
{
    char path[300];
    make_tmpdir();
    snprintf(path, sizeof path, "%s/lowflex.dat", tmpdir);
    write_altaz_run(path, 34, 0, 360, 0, 0, 15, 35, 10, 2, 100);
    ck_assert_msg(run("%s explain %s --order 0%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "1. refraction") != NULL &&
                      strstr(out, "as good a reading: tube_flexure (false-alarm 10^-1.9") != NULL,
                  "%s", out);
}
END_TEST

/* An RTS2 file of J2000 true places read as they are (the default): a note
** says they fit far better as J2000 (an outside probe's run had come out
** with sigma 90.7" and a, b, c' hundreds of arcseconds off, and nothing
** said); not where the places are of date, nor with --equinox given. */
START_TEST(test_pmfit_rts2_equinox_hint)
{
    char path[600];
    const char *top = getenv("PM_TOP");
    snprintf(path, sizeof path, "%s/tests/data/rts2_gpoint_j2000.dat", top ? top : ".");
    ck_assert_msg(run("%s fit %s --order 0%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "its true places fit far better as J2000 places") != NULL &&
                      strstr(out, "read it with --equinox J2000") != NULL,
                  "%s", out);
    ck_assert_msg(run("%s fit %s --order 0 --equinox J2000%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "fit far better") == NULL, "%s", out);
    ck_assert_msg(run("%s fit %s --order 0 --equinox JNow%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "fit far better") == NULL, "%s", out);
    snprintf(path, sizeof path, "%s/tests/data/rts2_gpoint.dat", top ? top : ".");
    ck_assert_msg(run("%s fit %s --order 0%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "fit far better") == NULL, "%s", out);
    /* a 6-minute run of places of date (tests/ref/rts2_gen_v.py, an outside
    ** probe's ERFA generator): order 0 holds the precession there, and
    ** without the refraction term beside the reading as read the note had
    ** rewarded the J2000 reduction's refraction (10 of 10 such runs) */
    snprintf(path, sizeof path, "%s/tests/data/rts2_jnow_short.dat", top ? top : ".");
    ck_assert_msg(run("%s fit %s --order 0%s", path, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "fit far better") == NULL, "%.2000s", out);
}
END_TEST

/* A German mount's run whose records beyond the pole are written folded to
** the sky, without a pier column: every record reads as one side, and the
** fit and explain say that the residuals change at the meridian as the two
** sides do (an outside probe's run: sigma 55", "19 points ... failed plate
** solves?", explain named higher_order).  Not for the run as simulated,
** with its pier column. */
START_TEST(test_pmfit_folded_records_without_pier)
{
    char src[300], path[300], cmd[1400];
    make_tmpdir();
    snprintf(src, sizeof src, "%s/fold_src.dat", tmpdir);
    snprintf(path, sizeof path, "%s/folded.dat", tmpdir);
    ck_assert_int_eq(run("%s simulate %s --n 80 --seed 5 --noise 2 --term i=60 --term \"e'=-40\" "
                         "--term d=20%s",
                         src, ""),
                     0);
    snprintf(cmd, sizeof cmd,
             "awk '/^# tau/ {print \"# tau delta T D temp time dir\"; next} /^#/ {print; next} "
             "{t = $1; d = $2; if ($5 == \"W\") {t += 180; if (t > 180) t -= 360; d = 180 - d} "
             "print t, d, $3, $4, $6, $7, $8}' %s > %s",
             src, path);
    ck_assert_int_eq(system(cmd), 0);
    ck_assert_msg(run("%s fit %s%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "warning: every record reads as one pier side, and the residuals "
                              "change at the meridian") != NULL &&
                      strstr(out, "failed plate solves") == NULL,
                  "%s", out);
    ck_assert_msg(run("%s explain %s --json%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"folded_pier\": \"every record reads as one pier side") != NULL,
                  "%.2000s", out);
    ck_assert_msg(run("%s fit %s%s", src, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "every record reads as one pier side") == NULL, "%s", out);
    ck_assert_msg(run("%s explain %s --json%s", src, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"folded_pier\": null") != NULL, "%.2000s", out);
    /* Nor a German mount that never flips, its hour-angle index stepping
    ** 10" at the meridian as the balance reverses (an outside probe's
    ** gimbal, tests/ref/equ_gen_v.py: 4 runs of 8 had been told their
    ** records were folded) */
    snprintf(src, sizeof src, "%s/tests/data/gem_oneside_balstep.dat",
             getenv("PM_TOP") ? getenv("PM_TOP") : ".");
    ck_assert_msg(run("%s fit %s%s", src, "") == 0, "%.2000s", out);
    ck_assert_msg(strstr(out, "every record reads as one pier side") == NULL, "%.2000s", out);
}
END_TEST

/* An error that rounds to 0.00 in the value's unit is given in the next
** unit down: a 3' polar error measured to 0.01" read "3.00' +- 0.00'" (an
** outside probe). */
START_TEST(test_pmfit_explain_small_error_shown)
{
    char path[300];
    make_tmpdir();
    snprintf(path, sizeof path, "%s/lown.dat", tmpdir);
    ck_assert_int_eq(run("%s simulate %s --n 200 --seed 4 --noise 0.05 --term a=180 --term b=20%s",
                         path, ""),
                     0);
    ck_assert_msg(run("%s explain %s --order 0%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "polar axis 3.00' +- 0.01\" east of the pole") != NULL &&
                      strstr(out, "+- 0.00'") == NULL,
                  "%s", out);
}
END_TEST

/* The commands the tools print are runnable as printed: a run's path with a
** space is quoted (explain's "pmfit fit ..." line, the report page's fit
** and plan commands; the page listed "--add ..." for the effects). */
START_TEST(test_pmfit_printed_commands_quote)
{
    char path[300], page[300], cmd[1400];
    const char *top = getenv("PM_TOP");
    char *html;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/my run.dat", tmpdir);
    snprintf(page, sizeof page, "%s/page.html", tmpdir);
    snprintf(cmd, sizeof cmd, "cp %s/examples/sim_gem.dat '%s'", top ? top : ".", path);
    ck_assert_int_eq(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "%s explain '%s'", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd, "pmfit fit '%s' --order", path);
    ck_assert_msg(strstr(out, cmd) != NULL, "%s", out);
    snprintf(cmd, sizeof cmd, "%s report '%s' --add \"aux:dec_dir:e'\" -o '%s'", tu_pmfit_path(),
             path, page);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 0);
    html = tu_slurp(page);
    ck_assert_ptr_nonnull(html);
    snprintf(cmd, sizeof cmd, "pmfit plan &apos;%s&apos; --next 5 --order 1 --min-el 15 --add "
             "&quot;aux:dec_dir:e&apos;&quot;</code>", path);
    ck_assert_msg(strstr(html, cmd) != NULL, "no '%s' in the page", cmd);
    snprintf(cmd, sizeof cmd, "pmfit fit &apos;%s&apos; --order 1 --add &quot;aux:dec_dir:e&apos;"
             "&quot;", path);
    ck_assert_msg(strstr(html, cmd) != NULL, "no '%s' in the page", cmd);
    free(html);
}
END_TEST

/* A period that is not a whole number of cycles jumps where the raw angle
** wraps at +-180 deg: explain says so where the run's axis turns through
** there (a German mount's flipped side near the meridian), not where an
** empty arc holds the wrap (a fork).  Runs of tests/ref/indep_gen.py, a
** 187.3-cycle, 3" HA error (the commands in their first lines). */
START_TEST(test_pmfit_explain_period_seam)
{
    char path[512];
    const char *top = getenv("PM_TOP");
    snprintf(path, sizeof path, "%s/tests/data/indep_gem_g187_seam.dat", top ? top : ".");
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "is not a whole number of cycles, so the term jumps where the raw "
                              "HA wraps at +-180 deg, which this run's hour-angle axis turns "
                              "through") != NULL, "%s", out);
    snprintf(path, sizeof path, "%s/tests/data/indep_fork_g187.dat", top ? top : ".");
    ck_assert_msg(run("%s explain %s%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "ha_periodic") != NULL && strstr(out, "not a whole number") == NULL,
                  "%s", out);
}
END_TEST

/* The MMT run with a 144-cycle azimuth error of 2 sigma injected (phase
** 180 deg): explain names refraction first (by its false-alarm
** probability, which counts the periods tried), and offers the periodic
** error, which BIC prefers by 11 (likelihood ratio 10^3.5), as "a
** better-fitting reading"; it had said "as good a reading" (an outside
** probe).  A reading within Delta BIC 6 is still "as good".  The fit of an
** alt-az run is of "all points", not a "joint fit, both pier sides", and
** its periodic effects are az_periodic and el_periodic. */
START_TEST(test_pmfit_explain_better_reading_altaz)
{
    char path[512], inj[600], args[1400];
    const char *p;
    if (!tu_real_run("mmt/k_and_e.dat", path, sizeof path))
        return;
    make_tmpdir();
    snprintf(inj, sizeof inj, "%s/kae_p144.dat", tmpdir);
    snprintf(args, sizeof args, "--inject ha_periodic:144=2sigma --phase 180 --into '%s' %s",
             path, inj);
    ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
    ck_assert_msg(run("%s explain %s%s", inj, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "a better-fitting reading: az_periodic") != NULL, "%s", out);
    /* an alt-az mount's periodic effects by its axes' names, in the text and
    ** the closing command, which fit takes (ha_periodic had been said
    ** beside "periodic error of the azimuth drive") */
    ck_assert_msg(strstr(out, "ha_periodic") == NULL && strstr(out, "dec_periodic") == NULL &&
                      strstr(out, ". az_periodic: periodic error of the azimuth drive") != NULL &&
                      strstr(out, "--add 'az_periodic:144'") != NULL,
                  "%s", out);
    for (p = strstr(out, "as good a reading: "); p; p = strstr(p + 1, "as good a reading: ")) {
        const char *b = strstr(p, "Delta BIC ");
        ck_assert_ptr_nonnull(b);
        ck_assert_msg(atof(b + strlen("Delta BIC ")) > -6, "%.200s", p);
    }
    ck_assert_msg(run("%s explain %s --json%s", inj, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "\"effect\": \"ha_periodic\", \"label\": \"az_periodic\"") != NULL,
                  "%s", out);
    ck_assert_msg(run("%s fit %s%s", path, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "all points (alt-az mount)") != NULL &&
                      strstr(out, "both pier sides") == NULL, "%s", out);
    /* --add takes the alt-az names there, the same terms; not on an
    ** equatorial mount */
    {
        double s1, s2;
        snprintf(args, sizeof args, "%s --add az_periodic:144:2 --add el_periodic:7 --json", path);
        ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
        s1 = tu_json_num(out, "sigma_arcsec");
        snprintf(args, sizeof args, "%s --add ha_periodic:144:2 --add dec_periodic:7 --json", path);
        ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
        s2 = tu_json_num(out, "sigma_arcsec");
        ck_assert(s1 == s2);
        snprintf(args, sizeof args, "%s/examples/sim_gem.dat --add az_periodic:144",
                 getenv("PM_TOP") ? getenv("PM_TOP") : ".");
        ck_assert_int_ne(run("%s fit %s%s", args, ""), 0);
        ck_assert_msg(strstr(out, "az_periodic is an alt-az mount's") != NULL, "%s", out);
        snprintf(args, sizeof args, "%s/examples/sim_gem.dat --gear az:144",
                 getenv("PM_TOP") ? getenv("PM_TOP") : ".");
        ck_assert_int_ne(run("%s explain %s%s", args, ""), 0);
        ck_assert_msg(strstr(out, "--gear az:G and el:G name an alt-az mount's axes") != NULL, "%s",
                      out);
    }
    /* the plots (file names, titles) and the report's captions in its axes'
    ** words too (an outside probe: "Finding 1, ha_periodic", "divided by cos
    ** declination" on an alt-az run) */
    {
        char dir[600], page[700], *text;
        snprintf(dir, sizeof dir, "%s/kae_plots", tmpdir);
        snprintf(args, sizeof args, "%s --plots %s", inj, dir);
        ck_assert_msg(run("%s explain %s%s", args, "") == 0, "%s", out);
        snprintf(page, sizeof page, "%s/finding2_az_periodic.svg", dir);
        text = tu_slurp(page);
        ck_assert_msg(text != NULL, "no %s", page);
        ck_assert(strstr(text, "Finding 2, az_periodic") != NULL);
        free(text);
        snprintf(page, sizeof page, "%s/periodogram_az.svg", dir);
        text = tu_slurp(page);
        ck_assert_msg(text != NULL, "no %s", page);
        free(text);
        snprintf(page, sizeof page, "%s/steps.svg", dir);
        text = tu_slurp(page);
        ck_assert_ptr_nonnull(text);
        ck_assert(strstr(text, "ha_periodic") == NULL && strstr(text, "az_periodic") != NULL);
        free(text);
        snprintf(page, sizeof page, "%s/kae.html", tmpdir);
        snprintf(args, sizeof args, "%s -o %s", inj, page);
        ck_assert_msg(run("%s report %s%s", args, "") == 0, "%s", out);
        text = tu_slurp(page);
        ck_assert_ptr_nonnull(text);
        ck_assert(strstr(text, "axis 1 along azimuth (divided by cos elevation") != NULL &&
                  strstr(text, "cos declination") == NULL && strstr(text, "ha_periodic") == NULL);
        free(text);
    }
}
END_TEST

/* explain composes its baseline as a gimbal only where the stars determine
** it between them: the first 13 points of the MMT run (22 terms, pmfit
** fit's undetermined warning) "composed" 0.41" out of a 0.39" sigma, and
** the baseline sigma explain and the report gave (0.313") was not the fit
** its closing command makes (0.385"). */
START_TEST(test_pmfit_explain_no_composition_undetermined)
{
    char path[512], few[600], cmd[1400];
    double fit_sigma;
    if (!tu_real_run("mmt/k_and_e.dat", path, sizeof path))
        return;
    make_tmpdir();
    snprintf(few, sizeof few, "%s/kae13.dat", tmpdir);
    snprintf(cmd, sizeof cmd, "head -n 33 '%s' > '%s'", path, few);
    ck_assert_int_eq(system(cmd), 0);
    ck_assert_msg(run("%s fit %s --json%s", few, "") == 0, "%s", out);
    ck_assert_int_eq((int)tu_json_num(out, "n_obs"), 13);
    ck_assert_msg(strstr(out, "\"undetermined\": true") != NULL, "%s", out);
    fit_sigma = tu_json_num(out, "sigma_arcsec");
    /* (--order 1: without it 13 points for 22 terms are explained at order 0) */
    ck_assert_msg(run("%s explain %s --order 1 --json%s", few, "") == 0, "%s", out);
    ck_assert_double_eq_tol(tu_json_num(out, "composition_rms_arcsec"), 0.0, 1e-12);
    ck_assert_double_eq_tol(tu_json_num(out, "sigma_arcsec"), fit_sigma, 1e-4);
}
END_TEST

/* Index errors of an unsynchronised encoder, tens of degrees to 170 (the
** independent gimbal, tests/ref/indep_gen.py, order-2 anisotropy of 10",
** 1" noise): the fit starts c' and e' from the run's own offsets and
** reaches the noise.  From zero Gauss-Newton stopped in a local minimum and
** said nothing: sigma 23-98" (an outside probe's alt-az azimuth zero 60 deg
** off: 14", and explain then invented two gear errors). */
START_TEST(test_pmfit_large_index_errors)
{
    static const struct { const char *mount, *index; double c; } k[] = {
        {"altaz", "120,-20", 120}, {"altaz", "170,-10", 170}, {"fork", "120,-20", 120}};
    const char *top = getenv("PM_TOP");
    char cmd[2048], path[400];
    size_t i;
    int seed;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/ix.dat", tmpdir);
    for (i = 0; i < sizeof k / sizeof k[0]; i++)
        for (seed = 1; seed <= 2; seed++) {
            double sigma, c;
            const char *t;
            snprintf(cmd, sizeof cmd,
                     "/usr/bin/python3 %s/tests/ref/indep_gen.py %s --mount %s --n 150 --seed %d "
                     "--noise 1 --index %s --aniso 10 --aniso-order 2 > /dev/null 2>&1",
                     top ? top : ".", path, k[i].mount, seed, k[i].index);
            ck_assert_int_eq(system(cmd), 0);
            ck_assert_msg(run("%s fit %s --order 2 --json%s", path, "") == 0, "%s", out);
            sigma = tu_json_num(out, "sigma_arcsec");
            t = strstr(out, "{\"name\": \"c'\"");
            ck_assert_ptr_nonnull(t);
            c = tu_json_num(t, "value_arcsec") / 3600;
            printf("check_pmfit: %s, index %s deg, seed %d: sigma %.3f\", c' %.3f deg\n",
                   k[i].mount, k[i].index, seed, sigma, c);
            ck_assert(sigma < 1.3);
            ck_assert(fabs(fabs(c) - k[i].c) < 1);
        }
    /* Outside probes' runs (tests/data/outside_*: their own generators):
    ** order L + 1 holds order L, so its chi^2 is no larger at the
    ** least-squares fit.  The first version of the start (e' with the wrong
    ** sign; readings past 90 deg always folded, on a fork that does not
    ** flip) left 28.6" and 33.8" for 1" of noise at order 1.  The last two
    ** (German runs, index offsets below PM_FIT_INDEX_START, so a cold start
    ** from zero alone) had stopped at order 1 at 8,142" and 6,022" (order 2:
    ** 552" and 419"), 2.77" and 1.72" at order 0: the order-0 fit's six are
    ** now a start where the model's fit ends above its chi^2 (pm.h,
    ** pm_fit_run Note 1). */
    for (i = 0; i < 4; i++) {
        static const char *const runs[4] = {
            "outside_altaz_index_sign.dat", "outside_fork_pole_dec_index.dat",
            "outside_gem_beyond_pole.dat", "outside_gem_order1_false_minimum.dat"};
        static const int top_order[4] = {1, 1, 2, 2}; /* (the first two: 12 points) */
        double chi2[3] = {0, 0, 0};
        int order;
        snprintf(path, sizeof path, "%s/tests/data/%s", top ? top : ".", runs[i]);
        for (order = 0; order <= top_order[i]; order++) {
            double s;
            snprintf(cmd, sizeof cmd, "%s --order %d --json 2>/dev/null", path, order);
            ck_assert_msg(run("%s fit %s%s", cmd, "") == 0, "%s", out);
            s = tu_json_num(out, "sigma_arcsec");
            chi2[order] = s * s * (2 * tu_json_num(out, "n_obs") - tu_json_num(out, "n_params"));
        }
        printf("check_pmfit: %s: chi^2 order 0 %.3f, order 1 %.3f", runs[i], chi2[0], chi2[1]);
        if (top_order[i] >= 2)
            printf(", order 2 %.3f", chi2[2]);
        printf(" (arcsec^2)\n");
        ck_assert(chi2[1] <= chi2[0] * (1 + 1e-6));
        ck_assert(top_order[i] < 2 || chi2[2] <= chi2[1] * (1 + 1e-6));
    }
}
END_TEST

/* On an alt-az mount the slew direction derived for axis 2 is the
** elevation drive's, el_dir: explain and the model file had called it
** dec_dir ("e'*dec_dir" for the elevation index).  A model file of such a
** run written before (its input "dec_dir") still reads the derived one. */
START_TEST(test_pmfit_altaz_elevation_direction)
{
    char sim[300], m[300], mold[300], args[1200];
    double rms;
    make_tmpdir();
    snprintf(sim, sizeof sim, "%s/azh.dat", tmpdir);
    snprintf(m, sizeof m, "%s/azh.pm", tmpdir);
    snprintf(mold, sizeof mold, "%s/azh_old.pm", tmpdir);
    snprintf(args, sizeof args, "%s --mount altaz --n 200 --seed 4 --effect hysteresis=3", sim);
    ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
    ck_assert_msg(run("%s explain %s%s", sim, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "1. hysteresis:") != NULL && strstr(out, "e'*el_dir = ") != NULL &&
                      strstr(out, "--add \"aux:el_dir:e'\"") != NULL &&
                      strstr(out, "dec_dir") == NULL,
                  "%s", out);
    snprintf(args, sizeof args, "%s --add hysteresis --add \"aux:el_dir:e'\" --save %s", sim, m);
    ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
    {
        char *text = tu_slurp(m), *p;
        FILE *f;
        ck_assert_ptr_nonnull(text);
        p = strstr(text, "input 0 el_dir\n");
        ck_assert_msg(p != NULL, "%s", text);
        f = fopen(mold, "w");
        ck_assert_ptr_nonnull(f);
        fprintf(f, "%.*sinput 0 dec_dir%s", (int)(p - text), text, p + strlen("input 0 el_dir"));
        fclose(f);
        free(text);
    }
    snprintf(args, sizeof args, "%s %s --json", m, sim);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    rms = tu_json_num(out, "rms_arcsec");
    snprintf(args, sizeof args, "%s %s --json", mold, sim);
    ck_assert_msg(run("%s eval %s%s", args, "") == 0, "%s", out);
    ck_assert_double_eq_tol(tu_json_num(out, "rms_arcsec"), rms, 1e-9);
}
END_TEST

/* A copy of a simulated run with a column "tube": its temperature (field 6)
** + 0.5 and a small deterministic jitter (arg: the records so far). */
static int edit_tube(char *line, size_t size, void *arg)
{
    int *i = (int *)arg;
    size_t n = strcspn(line, "\r\n");
    char f[8][40];
    line[n] = 0;
    if (!strncmp(line, "# tau", 5))
        snprintf(line + n, size - n, " tube\n");
    else if (line[0] == '#' || sscanf(line, "%39s %39s %39s %39s %39s %39s", f[0], f[1], f[2], f[3],
                                      f[4], f[5]) != 6)
        snprintf(line + n, size - n, "\n");
    else
        snprintf(line + n, size - n, " %.3f\n", atof(f[5]) + 0.5 + 0.02 * sin(1.3 * (*i)++));
    return 1;
}

/* The run's own column that follows the temperature is as good a reading
** as the temperature, and explain says which observation tells them apart
** (it had said "more points where the two readings differ most"). */
START_TEST(test_pmfit_explain_column_follows_temperature)
{
    char sim[300], tube[300], args[600];
    int k = 0;
    make_tmpdir();
    snprintf(sim, sizeof sim, "%s/tt.dat", tmpdir);
    snprintf(tube, sizeof tube, "%s/tt_tube.dat", tmpdir);
    snprintf(args, sizeof args, "%s --n 200 --seed 8 --effect temperature=2", sim);
    ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
    tu_edited_copy(sim, tube, edit_tube, &k);
    ck_assert_msg(run("%s explain %s%s", tube, "") == 0, "%s", out);
    ck_assert_msg(strstr(out, "1. temperature:") != NULL || strstr(out, "1. aux:tube:") != NULL,
                  "%s", out);
    ck_assert_msg(strstr(out, "to separate them: points where the column tube does not follow "
                              "the temperature, or a second night") != NULL,
                  "%s", out);
}
END_TEST

/* A copy of a column run with its first field (the encoder's axis 1)
** moved by *(double *)arg degrees. */
static int edit_shift_tau(char *line, size_t size, void *arg)
{
    double t;
    int k;
    if (line[0] == '#' || sscanf(line, "%lf%n", &t, &k) != 1)
        return 1;
    {
        char rest[4096];
        snprintf(rest, sizeof rest, "%s", line + k);
        snprintf(line, size, "%.9f%s", t + *(const double *)arg, rest);
    }
    return 1;
}

/* The value (degrees) of term `name` in pmfit fit --json's output. */
static double term_deg(const char *name)
{
    char key[64];
    const char *t;
    snprintf(key, sizeof key, "{\"name\": \"%s\"", name);
    t = strstr(out, key);
    ck_assert_msg(t != NULL, "%s: %s", key, out);
    return tu_json_num(t, "value_arcsec") / 3600;
}

/* A copy of a column run with both encoder fields (1 and 2) moved by 180
** deg, wrapped into (-180, 180]: both index errors half a turn more. */
static int edit_half_turn_both(char *line, size_t size, void *arg)
{
    double t, d;
    int k;
    (void)arg;
    if (line[0] == '#' || sscanf(line, "%lf %lf%n", &t, &d, &k) != 2)
        return 1;
    {
        char head[64];
        int m = snprintf(head, sizeof head, "%.9f %.9f", fmod(t + 360, 360) - 180,
                         fmod(d + 360, 360) - 180);
        ck_assert(m > 0 && (size_t)m < sizeof head && (size_t)m + strlen(line + k) < size);
        memmove(line + m, line + k, strlen(line + k) + 1);
        memcpy(line, head, (size_t)m);
    }
    return 1;
}

/* A German mount whose two encoders both read half a turn off (c' and e'
** of 180.3 deg): its normal side reads declinations beyond +-90 and its
** flipped side within.  The start from the offsets folded the readings
** beyond +-90 (the wrong half) and, unfolded, averaged hour-angle offsets
** 180 deg apart: the fit stopped in a false minimum at sigma 1.2e5-1.3e5"
** with PM_OK in 5 of these 16 runs of the independent generator (an
** outside probe: 6 of 32 of its own).  It now folds about the offsets' own
** declination index (lib/fit.cpp, index_start). */
START_TEST(test_pmfit_gem_both_encoders_half_turn)
{
    const char *top = getenv("PM_TOP");
    char cmd[2048], path[400], shifted[400];
    int seed, lat, order;
    make_tmpdir();
    snprintf(path, sizeof path, "%s/hb.dat", tmpdir);
    snprintf(shifted, sizeof shifted, "%s/hb_shifted.dat", tmpdir);
    for (seed = 1; seed <= 8; seed++)
        for (lat = 40; lat >= -35; lat -= 75) {
            snprintf(cmd, sizeof cmd,
                     "/usr/bin/python3 %s/tests/ref/indep_gen.py %s --mount gem --n 100 --seed %d "
                     "--lat %d --noise 1 --index 0.3,0.3 > /dev/null 2>&1",
                     top ? top : ".", path, seed, lat);
            ck_assert_int_eq(system(cmd), 0);
            tu_edited_copy(path, shifted, edit_half_turn_both, NULL);
            for (order = 0; order <= 1; order++) {
                double sigma;
                snprintf(cmd, sizeof cmd, "%s --order %d --json", shifted, order);
                ck_assert_msg(run("%s fit %s%s", cmd, "") == 0, "%s", out);
                sigma = tu_json_num(out, "sigma_arcsec");
                if (sigma > 1.3)
                    printf("check_pmfit: seed %d, lat %d, order %d: sigma %.1f\"\n", seed, lat,
                           order, sigma);
                ck_assert(sigma < 1.3);
                ck_assert(fabs(fabs(term_deg("c'")) - 179.7) < 0.01);
                ck_assert(fabs(fabs(term_deg("e'")) - 179.7) < 0.01);
            }
        }
}
END_TEST

/* Encoders read 180 deg off on axis 1 (a fork synchronised 12 h wrong, an
** alt-az azimuth from the other side): the fit has two exact aliases of
** the isotropic terms (pm.h, pm_fit_run Note 3) and comes back with the one
** whose collimation and non-perpendicularity are within 90 deg, with c'
** near 180 deg and the sigma of the unshifted run.  It had come back with
** e' 180 deg and i -180 deg (a fork), or d -180 deg (alt-az; an outside
** probe).  compare of two nights on either side of c' = 180 deg reads no
** change: the refit's c' had been a turn away (-1295971", 68335 sigma). */
START_TEST(test_pmfit_index_half_turn)
{
    static const struct { const char *mount; double shift; } k[] = {
        {"--fork", -180.0005}, {"--fork", 179.9995}, {"--mount altaz", 179.9},
        {"--mount altaz", -180.0}};
    char base[300], sh[300], sh2[300], pmf[300], args[1200];
    size_t i;
    int order;
    make_tmpdir();
    snprintf(base, sizeof base, "%s/h0.dat", tmpdir);
    snprintf(sh, sizeof sh, "%s/h1.dat", tmpdir);
    snprintf(sh2, sizeof sh2, "%s/h2.dat", tmpdir);
    snprintf(pmf, sizeof pmf, "%s/h1.pm", tmpdir);
    for (i = 0; i < sizeof k / sizeof k[0]; i++) {
        double shift = k[i].shift;
        snprintf(args, sizeof args, "%s %s --n 80 --seed 4", base, k[i].mount);
        ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
        tu_edited_copy(base, sh, edit_shift_tau, &shift);
        for (order = 0; order <= 1; order++) {
            double s0, s1, c, d, e, ci;
            snprintf(args, sizeof args, "%s --order %d --json", base, order);
            ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
            s0 = tu_json_num(out, "sigma_arcsec");
            snprintf(args, sizeof args, "%s --order %d --json", sh, order);
            ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
            s1 = tu_json_num(out, "sigma_arcsec");
            c = term_deg("c'");
            d = term_deg("d");
            e = term_deg("e'");
            ci = term_deg("i");
            printf("check_pmfit: %s, axis 1 moved %+.4f deg, order %d: sigma %.4f\" (%.4f\" "
                   "unmoved), c' %.4f, d %.4f, e' %.4f, i %.4f deg\n",
                   k[i].mount, shift, order, s1, s0, c, d, e, ci);
            ck_assert(fabs(s1 - s0) < 1e-3 * s0);
            ck_assert(fabs(d) < 1 && fabs(e) < 1 && fabs(ci) < 1);
            ck_assert(fabs(fabs(c) - 180) < 1);
        }
    }
    /* compare: two fork nights either side of c' = 180 deg */
    {
        double a = -179.999, b = -180.001;
        snprintf(args, sizeof args, "%s --fork --n 80 --seed 4", base);
        ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
        tu_edited_copy(base, sh, edit_shift_tau, &a);
        snprintf(args, sizeof args, "%s --fork --n 80 --seed 5", base);
        ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
        tu_edited_copy(base, sh2, edit_shift_tau, &b);
        snprintf(args, sizeof args, "%s --save %s", sh, pmf);
        ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
        snprintf(args, sizeof args, "%s %s --json", pmf, sh2);
        ck_assert_msg(run("%s compare %s%s", args, "") == 0, "%s", out);
        ck_assert_msg(strstr(out, "\"moved\": []") != NULL, "%s", out);
        ck_assert_ptr_nonnull(strstr(out, "\"rezero\": {"));
        printf("check_pmfit: fork nights at c' -179.999 and -180.001 deg: re-zero c' %+.2f\"\n",
               tu_json_num(strstr(out, "\"rezero\": {"), "c_arcsec"));
        ck_assert_msg(fabs(tu_json_num(strstr(out, "\"rezero\": {"), "c_arcsec") - 7.2) < 1,
                      "%s", out);
    }
    /* compare from a model file in the other alias (e' + pi, pi - i; an
    ** order-0 model written so by the build before): the refit keeps the
    ** old model's alias, and an unchanged mount still holds (the refit had
    ** been turned to the canonical alias: e' moved 1,641,614 sigma, "refit";
    ** an outside probe) */
    {
        char alias[300];
        FILE *in, *o;
        char line[1024];
        snprintf(args, sizeof args, "%s --fork --n 80 --seed 4", base);
        ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
        snprintf(args, sizeof args, "%s --order 0 --save %s", base, pmf);
        ck_assert_msg(run("%s fit %s%s", args, "") == 0, "%s", out);
        snprintf(alias, sizeof alias, "%s/alias.pm", tmpdir);
        in = fopen(pmf, "r");
        o = fopen(alias, "w");
        ck_assert(in && o);
        while (fgets(line, sizeof line, in)) {
            double v, e, r[5];
            int nr;
            if (sscanf(line, "term e' 5 0 0 %lf %lf", &v, &e) == 2)
                fprintf(o, "term e' 5 0 0 %.17g %.17g\n", v + M_PI, e);
            else if (sscanf(line, "term i 6 0 0 %lf %lf", &v, &e) == 2)
                fprintf(o, "term i 6 0 0 %.17g %.17g\n", M_PI - v, e);
            else if ((nr = sscanf(line, "corr 6 1 %lf %lf %lf %lf %lf", &r[0], &r[1], &r[2], &r[3],
                                  &r[4])) == 5)
                fprintf(o, "corr 6 1 %.10g %.10g %.10g %.10g %.10g\n", -r[0], -r[1], -r[2], -r[3],
                        -r[4]);
            else
                fputs(line, o);
        }
        fclose(in);
        fclose(o);
        snprintf(args, sizeof args, "%s --fork --n 80 --seed 5", base);
        ck_assert_msg(run("%s simulate %s%s", args, "") == 0, "%s", out);
        snprintf(args, sizeof args, "%s %s --json", alias, base);
        ck_assert_msg(run("%s compare %s%s", args, "") == 0, "%s", out);
        ck_assert_msg(strstr(out, "\"moved\": []") != NULL &&
                          strstr(out, "\"advice\": \"the model still holds") != NULL,
                      "%s", out);
    }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("pmfit");
    TCase *tc = tcase_create("realdata");
    tcase_add_test(tc, test_pmfit_mmt_sigma);
    tcase_add_test(tc, test_pmfit_gem_converges);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);
    tc = tcase_create("tool");
    tcase_add_test(tc, test_pmfit_simulate_fit_roundtrip);
    tcase_add_test(tc, test_pmfit_cli_errors);
    tcase_add_test(tc, test_pmfit_output_not_input);
    tcase_add_test(tc, test_pmfit_output_targets);
    tcase_add_test(tc, test_pmfit_undetermined);
    tcase_add_test(tc, test_pmfit_large_index_errors);
    tcase_add_test(tc, test_pmfit_explain_refraction_words);
    tcase_add_test(tc, test_pmfit_explain_few_points_order0);
    tcase_add_test(tc, test_pmfit_eval_missing_input_and_long_comment);
    tcase_add_test(tc, test_pmfit_columns_by_name);
    tcase_add_test(tc, test_pmfit_explain_says_what_it_cannot_try);
    tcase_add_test(tc, test_pmfit_explain_small_error_shown);
    tcase_add_test(tc, test_pmfit_altaz_counted_azimuth_direction);
    tcase_add_test(tc, test_pmfit_explain_cable_wrap);
    tcase_add_test(tc, test_pmfit_explain_azimuth_count_reading);
    tcase_add_test(tc, test_pmfit_weather_options);
    tcase_add_test(tc, test_pmfit_explain_cable_drag);
    tcase_add_test(tc, test_pmfit_explain_pier_side_where);
    tcase_add_test(tc, test_pmfit_few_dof_warning);
    tcase_add_test(tc, test_pmfit_explain_period_aliases);
    tcase_add_test(tc, test_pmfit_explain_reading_pier_step);
    tcase_add_test(tc, test_pmfit_explain_refraction_beside_sag);
    tcase_add_test(tc, test_pmfit_explain_baseline_advice);
    tcase_add_test(tc, test_pmfit_save_nearly_singular_reads_back);
    tcase_add_test(tc, test_pmfit_explain_sag_reading_on_a_band);
    tcase_add_test(tc, test_pmfit_rts2_equinox_hint);
    tcase_add_test(tc, test_pmfit_folded_records_without_pier);
    tcase_add_test(tc, test_pmfit_explain_close_rival_above_alpha);
    tcase_add_test(tc, test_pmfit_printed_commands_quote);
    tcase_add_test(tc, test_pmfit_explain_period_seam);
    tcase_add_test(tc, test_pmfit_explain_no_composition_undetermined);
    tcase_add_test(tc, test_pmfit_altaz_elevation_direction);
    tcase_add_test(tc, test_pmfit_explain_column_follows_temperature);
    tcase_add_test(tc, test_pmfit_index_half_turn);
    tcase_add_test(tc, test_pmfit_gem_both_encoders_half_turn);
    tcase_add_test(tc, test_pmfit_explain_better_reading_altaz);
    tcase_set_timeout(tc, 60);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
