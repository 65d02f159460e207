#define _POSIX_C_SOURCE 200809L
/*
**  check_modelfile.c - model files: save/load round trip, errors, and the
**  C header emitted for firmware.
*/
#include <check.h>
#include "tu_check.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm.h"
#include "modelfile.h"
#include "testutil.h"
#include "tu_tool.h"

static char tmpdir[256];

static void make_tmpdir(void)
{
    tu_tmpdir(tmpdir, "pm_modelfile_");
}

static void path_in(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/%s", tmpdir, name);
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

static void random_model(pm_model *m, int order, unsigned long long seed)
{
    tu_rng r;
    int i;
    tu_seed(&r, seed);
    ck_assert_int_eq(pm_model_init(m, PM_MOUNT_EQUATORIAL, order), PM_OK);
    for (i = 0; i < m->n_terms; i++)
        m->coef[i] = (tu_uniform(&r) - 0.5) * 1e-2 * (i < 6 ? 10.0 : 1.0);
    ck_assert_int_eq(pm_model_prepare(m), PM_OK);
}

START_TEST(test_pmmodel_save_load_roundtrip_bit_exact)
{
    pm_model a, b;
    char path[300], err[512];
    int i, order;
    make_tmpdir();
    for (order = 0; order <= (PM_MAX_L < 3 ? PM_MAX_L : 3); order++) {
        random_model(&a, order, 7 + (unsigned long long)order);
        a.mount = order == 1 ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
        ck_assert_int_eq(pm_model_prepare(&a), PM_OK);
        path_in(path, sizeof path, "m.pm");
        ck_assert_int_eq(pmmodel_save(path, &a, "a test\nsecond line", err, sizeof err), 0);
        ck_assert_int_eq(pmmodel_load(path, &b, err, sizeof err), 0);
        ck_assert_int_eq(b.mount, a.mount);
        ck_assert_int_eq(b.order, a.order);
        ck_assert_int_eq(b.n_terms, a.n_terms);
        for (i = 0; i < a.n_terms; i++) {
            ck_assert(memcmp(&a.coef[i], &b.coef[i], sizeof(double)) == 0);
            ck_assert_int_eq(a.term[i].k, b.term[i].k);
            ck_assert_int_eq(a.term[i].l, b.term[i].l);
            ck_assert_int_eq(a.term[i].m, b.term[i].m);
        }
        {   /* the loaded model evaluates identically */
            double t1, d1, t2, d2;
            ck_assert_int_eq(pm_model_apply(&a, NULL, 0.4, 0.7, &t1, &d1), PM_OK);
            ck_assert_int_eq(pm_model_apply(&b, NULL, 0.4, 0.7, &t2, &d2), PM_OK);
            ck_assert(t1 == t2 && d1 == d2);
        }
    }
}
END_TEST

/* Each bad file gives -1, a message naming file:line, and *m unchanged. */
static void expect_load_error(const char *text, const char *want_line, const char *want_word)
{
    pm_model m, before;
    char path[300], err[512], where[320];
    random_model(&m, 1, 3);
    before = m;
    path_in(path, sizeof path, "bad.pm");
    write_text(path, text);
    err[0] = 0;
    ck_assert_int_eq(pmmodel_load(path, &m, err, sizeof err), -1);
    snprintf(where, sizeof where, "%s:%s:", path, want_line);
    ck_assert_msg(strstr(err, where) != NULL, "message '%s' lacks '%s'", err, where);
    ck_assert_msg(strstr(err, want_word) != NULL, "message '%s' lacks '%s'", err, want_word);
    ck_assert(memcmp(&m, &before, sizeof m) == 0);
}

START_TEST(test_pmmodel_load_errors_name_line)
{
    char big[600];
    make_tmpdir();
    expect_load_error("", "1", "empty");
    expect_load_error("hello\n", "1", "pm-model");
    expect_load_error("pm-model 6\n", "1", "version");
    expect_load_error("pm-model 1\nmount dobsonian\n", "2", "mount");
    expect_load_error("pm-model 1\nmount altaz\norder x\n", "3", "order");
    snprintf(big, sizeof big, "pm-model 1\nmount altaz\norder %d\n", PM_MAX_L + 1);
    expect_load_error(big, "3", "PM_MAX_L");
    snprintf(big, sizeof big, "pm-model 1\nmount altaz\norder 0\nterms %d\n", PM_MAX_TERMS + 1);
    expect_load_error(big, "4", "capacity");
    expect_load_error("pm-model 1\nmount altaz\norder 0\nterms 6\nterm a 1 0 0 nan\n", "5",
                      "finite");
    expect_load_error("pm-model 1\nmount altaz\norder 0\nterms 6\nterm a 1 0 0 1e999\n", "5",
                      "finite");
    expect_load_error("pm-model 1\nmount altaz\norder 0\nterms 6\nterm a 7 0 0 0\n", "5",
                      "indices");
    expect_load_error("pm-model 1\nmount altaz\norder 0\nterms 6\nterm a 1 0 0 0\nend\n", "6",
                      "'end' after 1");
    expect_load_error("pm-model 1\nmount altaz\norder 0\nterms 6\nterm a 1 0 0 0\n", "6",
                      "truncated");
    expect_load_error("pm-model 1\nmount equatorial\norder 0\nterms 6\n"
                      "term a 1 0 0 0\nterm b 2 0 0 0\nterm c 3 0 0 0\nterm d 4 0 0 0\n"
                      "term e 5 0 0 0\nterm i 6 0 0 0\nend\nmore\n",
                      "12", "after 'end'");
}
END_TEST

/* Version 1 files (before the tilt terms were evaluated at the
** index-shifted position, docs/model.md): read where nothing evaluates
** differently, refused at the first anisotropic tilt term otherwise; files
** are written as version 2. */
/* An order-1 model file of version `version`: the isotropic terms
** iso(i), every anisotropic term aniso(i). */
static void write_old(const char *path, int version, double (*iso)(int), double (*aniso)(int))
{
    pm_model m;
    int i;
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1);
    fprintf(f, "pm-model %d\nmount equatorial\norder 1\nterms %d\n", version, m.n_terms);
    for (i = 0; i < m.n_terms; i++) {
        char name[32];
        pm_term_name(&m, i, name, sizeof name);
        fprintf(f, "term %s %d %d %d %.17g\n", name, m.term[i].k, m.term[i].l, m.term[i].m,
                m.term[i].l >= 1 ? aniso(i) : iso(i));
    }
    fprintf(f, "end\n");
    fclose(f);
}

static double some(int i) { return 1e-5 * (i + 1); }
static double zero(int i) { (void)i; return 0.0; }
static double no_index(int i) { return i == 2 || i == 4 ? 0.0 : 1e-5 * (i + 1); }

/* Older versions evaluated anisotropic terms at the encoder reading
** (version 1: the tilts too; version 2: the harmonics and the other base
** vectors); version 3 at the index-shifted position.  A file whose moved
** terms are zero, or whose index terms c' and e' are both zero (the two
** positions one), reads; any other is refused at the first moved term. */
START_TEST(test_pmmodel_version_1)
{
    pm_model m;
    char path[300], err[512], where[320];
    FILE *f;
    char head[32];
    int v;
    make_tmpdir();
    path_in(path, sizeof path, "old.pm");
    for (v = 1; v <= 2; v++) {
        write_old(path, v, some, zero);
        ck_assert_msg(pmmodel_load(path, &m, err, sizeof err) == 0, "%s", err);
        ck_assert(m.coef[0] == 1e-5 * 1 && m.coef[2] == 1e-5 * 3);
        write_old(path, v, no_index, some);
        ck_assert_msg(pmmodel_load(path, &m, err, sizeof err) == 0, "%s", err);
        ck_assert(m.coef[6] == 1e-5 * 7);
        write_old(path, v, some, some);
        ck_assert_int_eq(pmmodel_load(path, &m, err, sizeof err), -1);
        snprintf(where, sizeof where, "%s:%d:", path, 5 + 6); /* the first l = 1 term */
        ck_assert_msg(strstr(err, where) && strstr(err, "refit") &&
                      strstr(err, v == 1 ? "'pm-model 1'" : "'pm-model 2'"), "%s", err);
    }
    /* saved files are version 3 */
    ck_assert_int_eq(pmmodel_save(path, &m, NULL, err, sizeof err), 0);
    f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    ck_assert_ptr_nonnull(fgets(head, sizeof head, f));
    fclose(f);
    ck_assert_str_eq(head, "pm-model 3\n");
}
END_TEST

/* A version-2 file's side-specific c' or d term (an added SH term of
** l = 0): its base vector, cos d or -sin d, moved to the index-shifted
** position with every other; such files were read without a word and
** pointed up to 5.75" differently.  Refused as the moved harmonics are;
** e'@W and i@W (constant base vectors) still read. */
START_TEST(test_pmmodel_version_2_side_terms)
{
    static const char *xterm[4] = {"xterm c'@W sh 3 0 0 -1 0 0 -0.0007",
                                   "xterm d@W sh 4 0 0 -1 0 0 -0.0005",
                                   "xterm e'@W sh 5 0 0 -1 0 0 0.0003",
                                   "xterm i@W sh 6 0 0 -1 0 0 0.0002"};
    pm_model m;
    char path[300], err[512], where[320];
    int k;
    make_tmpdir();
    path_in(path, sizeof path, "v2.pm");
    for (k = 0; k < 4; k++) {
        FILE *f = fopen(path, "w");
        ck_assert_ptr_nonnull(f);
        fprintf(f, "pm-model 2\nmount equatorial\norder 0\nlatitude -0.8\nterms 7\n"
                   "term a 1 0 0 -0.0008\nterm b 2 0 0 0.00085\nterm c' 3 0 0 -0.013\n"
                   "term d 4 0 0 -0.00045\nterm e' 5 0 0 0.0287\nterm i 6 0 0 -0.00036\n"
                   "%s\nend\n", xterm[k]);
        fclose(f);
        if (k < 2) {
            ck_assert_int_eq(pmmodel_load(path, &m, err, sizeof err), -1);
            snprintf(where, sizeof where, "%s:12:", path);
            ck_assert_msg(strstr(err, where) && strstr(err, "'pm-model 2'") && strstr(err, "refit"),
                          "%s", err);
        } else {
            ck_assert_msg(pmmodel_load(path, &m, err, sizeof err) == 0, "%s: %s", xterm[k], err);
        }
    }
}
END_TEST

/* Save writes only what load reads back: a subnormal coefficient round
** trips (strtod's ERANGE on underflow was taken for an error); a NaN
** coefficient or a latitude beyond the pole is refused before anything is
** written (it was written, and the file failed to load); emit-c refuses a
** prefix that is not a C identifier. */
START_TEST(test_pmmodel_save_only_what_loads)
{
    pm_model m, back;
    char path[300], err[512];
    make_tmpdir();
    random_model(&m, 1, 7);
    m.coef[7] = 1e-310;
    m.coef[8] = -4.9e-324;
    ck_assert_int_eq(pm_model_prepare(&m), PM_OK);
    path_in(path, sizeof path, "sub.pm");
    ck_assert_msg(pmmodel_save(path, &m, NULL, err, sizeof err) == 0, "%s", err);
    ck_assert_msg(pmmodel_load(path, &back, err, sizeof err) == 0, "%s", err);
    ck_assert(memcmp(&back.coef[7], &m.coef[7], sizeof(double)) == 0);
    ck_assert(memcmp(&back.coef[8], &m.coef[8], sizeof(double)) == 0);
    path_in(path, sizeof path, "nan.pm");
    m.coef[3] = NAN;
    ck_assert_int_eq(pmmodel_save(path, &m, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "not written") != NULL, "%s", err);
    ck_assert_int_ne(access(path, F_OK), 0);
    ck_assert_int_eq(pmmodel_emit_c(path, &m, "pm_x", NULL, err, sizeof err), -1);
    ck_assert_int_ne(access(path, F_OK), 0);
    m.coef[3] = 0;
    m.latitude = 5;
    ck_assert_int_eq(pmmodel_save(path, &m, NULL, err, sizeof err), -1);
    ck_assert_int_ne(access(path, F_OK), 0);
    m.latitude = 0.7;
    ck_assert_int_eq(pmmodel_emit_c(path, &m, "my-model 1", NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "not a C identifier") != NULL, "%s", err);
    ck_assert_int_ne(access(path, F_OK), 0);
    ck_assert_msg(pmmodel_emit_c(path, &m, "_my_model1", NULL, err, sizeof err) == 0, "%s", err);
}
END_TEST

START_TEST(test_pmmodel_load_binary_and_missing)
{
    pm_model m;
    char path[300], err[512];
    FILE *f;
    make_tmpdir();
    path_in(path, sizeof path, "bin.pm");
    f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    fwrite("pm-model 1\n\0\x01\x02garbage\n", 1, 22, f);
    fclose(f);
    ck_assert_int_eq(pmmodel_load(path, &m, err, sizeof err), -1);
    ck_assert_msg(strstr(err, ":2:") && strstr(err, "binary"), "%s", err);
    path_in(path, sizeof path, "absent.pm");
    ck_assert_int_eq(pmmodel_load(path, &m, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "cannot open") != NULL, "%s", err);
    ck_assert_int_eq(pmmodel_load(NULL, &m, err, sizeof err), -1);
}
END_TEST

/* A failed save leaves no file behind. */
START_TEST(test_pmmodel_save_unwritable)
{
    pm_model m;
    char err[512];
    random_model(&m, 1, 5);
    ck_assert_int_eq(pmmodel_save("/nonexistent-dir/x.pm", &m, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "cannot write") != NULL, "%s", err);
    ck_assert_int_ne(access("/nonexistent-dir/x.pm", F_OK), 0);
}
END_TEST

/* The emitted header compiles as strict C89 and its loader reproduces the
** model bit for bit (checked by a program that prints the coefficients with
** 17 significant digits and compares them with ours). */
START_TEST(test_pmmodel_emit_c_compiles_and_loads)
{
    pm_model m;
    char hdr[300], src[300], exe[300], out[300], cmd[2048], err[512];
    const char *top = getenv("PM_TOP");
    FILE *f;
    int i;
    if (!top)
        top = ".";
    make_tmpdir();
    random_model(&m, 2 <= PM_MAX_L ? 2 : PM_MAX_L, 11);
    path_in(hdr, sizeof hdr, "fitted_model.h");
    /* a comment with the end of a C comment in it (a run in a folder "x*"): it
    ** must not end the header's comment */
    ck_assert_int_eq(pmmodel_emit_c(hdr, &m, "pm_fitted", "test model of x*/run.dat", err,
                                    sizeof err), 0);
    path_in(src, sizeof src, "use.c");
    path_in(exe, sizeof exe, "use");
    path_in(out, sizeof out, "use.out");
    write_text(src, "#include <stdio.h>\n#include \"fitted_model.h\"\n"
                    "int main(void) { pm_model m; int i;\n"
                    "  if (pm_fitted_load(&m) != PM_OK) return 1;\n"
                    "  for (i = 0; i < m.n_terms; i++) printf(\"%.17g\\n\", m.coef[i]);\n"
                    "  return 0; }\n");
    snprintf(cmd, sizeof cmd,
             "cc -std=c89 -pedantic -Werror -Wall -Wno-unused-function -I%s/include -I%s %s "
             "%s/build/libpm.a -lm -o %s && %s > %s",
             top, tmpdir, src, top, exe, exe, out);
    ck_assert_msg(system(cmd) == 0, "failed: %s", cmd);
    f = fopen(out, "r");
    ck_assert_ptr_nonnull(f);
    for (i = 0; i < m.n_terms; i++) {
        double v;
        ck_assert_int_eq(fscanf(f, "%lf", &v), 1);
        ck_assert(memcmp(&v, &m.coef[i], sizeof v) == 0);
    }
    fclose(f);
}
END_TEST

/* Version 4: the names of the columns a model reads (pm_context.aux[j]),
** its pier side and its coefficients' errors, written where the model reads a named input or is of
** one side (version 3 otherwise), read back; bad lines are errors at
** their line; a name that is not a column name is not written. */
START_TEST(test_pmmodel_info)
{
    static const char head4[] = "pm-model 4\nmount equatorial\norder 0\n";
    static const char body[] = "terms 6\nterm a 1 0 0 0\nterm b 2 0 0 0\nterm c 3 0 0 0\n"
                               "term d 4 0 0 0\nterm e 5 0 0 0\nterm i 6 0 0 0\nend\n";
    static const struct { const char *lines, *line, *word; } bad[] = {
        {"input 0 hum\ninput 0 press\n", "5", "second name for input 0"},
        {"input 0 hum\ninput 1 hum\n", "5", "named 'hum' as input 0"},
        {"input 9 hum\n", "4", "PM_MAX_AUX"},
        {"input 0 9hum\n", "4", "not a column name"},
        {"input 0\n", "4", "expected 'input J NAME'"},
        {"input -1 hum\n", "4", "expected 'input J NAME'"},
        {"pier north\n", "4", "'pier east' or 'pier west'"},
        {"pier east\npier west\n", "5", "second 'pier'"},
    };
    pm_model a, b;
    pmmodel_info in, got;
    pm_term t;
    char path[300], err[512], text[1024];
    FILE *f;
    size_t k;
    make_tmpdir();
    path_in(path, sizeof path, "i.pm");
    random_model(&a, 1, 11);
    memset(&t, 0, sizeof t);
    t.kind = PM_TERM_AUX;
    t.k = PM_BASE_E;
    t.aux = PM_AUX_USER + 2;
    t.param = 1010;
    ck_assert_int_eq(pm_model_add_term(&a, &t, 1e-6, NULL), PM_OK);
    t.aux = PM_AUX_TEMP;
    ck_assert_int_eq(pm_model_add_term(&a, &t, 2e-6, NULL), PM_OK);
    memset(&in, 0, sizeof in);
    strcpy(in.input[2], "press");
    strcpy(in.input[0], "hum"); /* read by no term: not written */
    in.pier = -1;
    ck_assert_msg(pmmodel_save_info(path, &a, &in, "c", err, sizeof err) == 0, "%s", err);
    memset(&got, 0x55, sizeof got);
    ck_assert_msg(pmmodel_load_info(path, &b, &got, err, sizeof err) == 0, "%s", err);
    ck_assert_str_eq(got.input[2], "press");
    ck_assert_str_eq(got.input[0], "");
    ck_assert_str_eq(got.input[1], "");
    ck_assert_int_eq(got.pier, -1);
    ck_assert_int_eq(b.n_terms, a.n_terms);
    ck_assert_int_eq(b.term[a.n_terms - 2].aux, PM_AUX_USER + 2);
    ck_assert(memcmp(b.coef, a.coef, sizeof(double) * (size_t)a.n_terms) == 0);
    /* pmmodel_load reads it too (without the information) */
    ck_assert_int_eq(pmmodel_load(path, &b, err, sizeof err), 0);
    /* nothing more to say: version 3 */
    memset(&in, 0, sizeof in);
    strcpy(in.input[0], "hum");
    ck_assert_int_eq(pmmodel_save_info(path, &a, &in, NULL, err, sizeof err), 0);
    f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    ck_assert_ptr_nonnull(fgets(text, sizeof text, f));
    fclose(f);
    ck_assert_str_eq(text, "pm-model 3\n");
    ck_assert_int_eq(pmmodel_load_info(path, &b, &got, err, sizeof err), 0);
    ck_assert_str_eq(got.input[2], "");
    ck_assert_int_eq(got.pier, 0);
    /* what cannot be written */
    strcpy(in.input[2], "two words");
    ck_assert_int_eq(pmmodel_save_info(path, &a, &in, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "not a column name") != NULL, "%s", err);
    memset(&in, 0, sizeof in);
    in.pier = 2;
    ck_assert_int_eq(pmmodel_save_info(path, &a, &in, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "pier 2") != NULL, "%s", err);
    /* the lines: an error at their line; not in version 3 */
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        snprintf(text, sizeof text, "%s%s%s", head4, bad[k].lines, body);
        expect_load_error(text, bad[k].line, bad[k].word);
    }
    snprintf(text, sizeof text, "pm-model 3\nmount equatorial\norder 0\ninput 0 hum\n%s", body);
    expect_load_error(text, "4", "version 4 has them");
    /* errors: each term line's last field, written and read bit for bit */
    memset(&in, 0, sizeof in);
    in.has_err = 1;
    for (k = 0; k < (size_t)a.n_terms; k++)
        in.err[k] = 1e-7 * (double)(k + 1) / 3.0;
    ck_assert_msg(pmmodel_save_info(path, &a, &in, NULL, err, sizeof err) == 0, "%s", err);
    ck_assert_msg(pmmodel_load_info(path, &b, &got, err, sizeof err) == 0, "%s", err);
    ck_assert_int_eq(got.has_err, 1);
    ck_assert(memcmp(got.err, in.err, sizeof(double) * (size_t)a.n_terms) == 0);
    ck_assert(memcmp(b.coef, a.coef, sizeof(double) * (size_t)a.n_terms) == 0);
    in.err[3] = -1;
    ck_assert_int_eq(pmmodel_save_info(path, &a, &in, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "not a finite number >= 0") != NULL, "%s", err);
    snprintf(text, sizeof text, "%serrors\nterms 6\nterm a 1 0 0 0 1e-6\nterm b 2 0 0 0\n", head4);
    expect_load_error(text, "7", "'errors' line");
    snprintf(text, sizeof text, "%serrors\nterms 6\nterm a 1 0 0 0 -1e-6\n", head4);
    expect_load_error(text, "6", "bad error");
    snprintf(text, sizeof text, "%serrors\nerrors\n", head4);
    expect_load_error(text, "5", "second 'errors'");
    snprintf(text, sizeof text, "pm-model 3\nmount equatorial\norder 0\nerrors\n%s", body);
    expect_load_error(text, "4", "version 4 has them");
    snprintf(text, sizeof text, "%sinput 3 x.y-z_\npier east\n%s", head4, body);
    write_text(path, text);
    ck_assert_msg(pmmodel_load_info(path, &b, &got, err, sizeof err) == 0, "%s", err);
    ck_assert_str_eq(got.input[3], "x.y-z_");
    ck_assert_int_eq(got.pier, 1);
}
END_TEST

/* Version 5: the fit's covariance, kept as correlations beside the term
** lines' errors (pmfit compare then tests a model file's changes with it,
** as with the old run). */
START_TEST(test_pmmodel_covariance)
{
    static const char head5[] = "pm-model 5\nmount equatorial\norder 0\nerrors\ncorrelations\n"
                                "terms 6\nterm a 1 0 0 0 1e-6\nterm b 2 0 0 0 1e-6\n"
                                "term c 3 0 0 0 1e-6\nterm d 4 0 0 0 1e-6\n"
                                "term e 5 0 0 0 1e-6\nterm i 6 0 0 0 1e-6\n";
    static const struct { const char *lines, *line, *word; } bad[] = {
        {"corr 2 1 0\ncorr 3 1 0 0\nend\n", "15", "'end' before the correlations of term 4"},
        {"corr 2 1 0\ncorr 3 2 0\n", "14", "out of order"},
        {"corr 2 1 0\ncorr 3 1 0 0 0\n", "14", "has 2 left"},
        {"corr 2 1 1.5\n", "13", "bad correlation"},
        {"corr 2 1 nan\n", "13", "bad correlation"},
        {"corr 2\n", "13", "expected 'corr 2 1 r...'"},
        /* r21 = r31 = 0.9, r32 = -0.9: no covariance has these */
        {"corr 2 1 0.9\ncorr 3 1 0.9 -0.9\ncorr 4 1 0 0 0\ncorr 5 1 0 0 0 0\n"
         "corr 6 1 0 0 0 0 0\nend\n",
         "14", "not those of a covariance"},
        {"corr 2 1 0\ncorr 3 1 0 0\ncorr 4 1 0 0 0\ncorr 5 1 0 0 0 0\ncorr 6 1 0 0 0 0 0\n"
         "corr 7 1 0\n",
         "18", "more correlations"},
        /* r21 = 1 (a zero pivot), r31 = 1, r32 = -1: eigenvalues -1, 2, 2; it
        ** was taken (an outside probe) */
        {"corr 2 1 1\ncorr 3 1 1 -1\ncorr 4 1 0 0 0\ncorr 5 1 0 0 0 0\n"
         "corr 6 1 0 0 0 0 0\nend\n",
         "14", "not positive semi-definite at term 3, c'"},
    };
    pm_model a, b;
    pmmodel_info in, got;
    double *A, *cov, *back;
    char path[300], err[512], text[2048];
    tu_rng r;
    int P, i, j, k, has = 7;
    FILE *f;
    make_tmpdir();
    path_in(path, sizeof path, "c.pm");
    random_model(&a, 2, 21);
    P = a.n_terms;
    A = malloc(sizeof(double) * (size_t)(P * P));
    cov = malloc(sizeof(double) * (size_t)(P * P));
    back = malloc(sizeof(double) * (size_t)(PM_MAX_TERMS * PM_MAX_TERMS));
    ck_assert(A && cov && back);
    tu_seed(&r, 5);
    for (i = 0; i < P * P; i++)
        A[i] = tu_uniform(&r) - 0.5;
    memset(&in, 0, sizeof in);
    in.has_err = 1;
    for (i = 0; i < P; i++)
        for (j = 0; j < P; j++) {
            double c = 0;
            for (k = 0; k < P; k++)
                c += A[i * P + k] * A[j * P + k];
            cov[i * P + j] = 1e-12 * c; /* (A A^T: a covariance, radians^2) */
        }
    for (i = 0; i < P; i++)
        in.err[i] = sqrt(cov[i * P + i]);
    in.stars_sigma = 1.5e-6; /* (the fit's predicted 1 sigma at its stars) */
    ck_assert_msg(pmmodel_save_cov(path, &a, &in, cov, "c", err, sizeof err) == 0, "%s", err);
    f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    ck_assert_ptr_nonnull(fgets(text, sizeof text, f)); /* the comment */
    ck_assert_ptr_nonnull(fgets(text, sizeof text, f));
    fclose(f);
    ck_assert_str_eq(text, "pm-model 5\n");
    for (i = 0; i < P * P; i++)
        back[i] = -7;
    ck_assert_msg(pmmodel_load_cov(path, &b, &got, back, (size_t)(PM_MAX_TERMS * PM_MAX_TERMS),
                                   &has, err, sizeof err) == 0, "%s", err);
    ck_assert_int_eq(has, 1);
    ck_assert(memcmp(b.coef, a.coef, sizeof(double) * (size_t)P) == 0);
    ck_assert(memcmp(got.err, in.err, sizeof(double) * (size_t)P) == 0);
    ck_assert(got.stars_sigma == in.stars_sigma);
    for (i = 0; i < P; i++)
        for (j = 0; j < P; j++)
            ck_assert_msg(fabs(back[i * P + j] - cov[i * P + j]) <=
                              1e-9 * sqrt(cov[i * P + i] * cov[j * P + j]),
                          "cov[%d][%d] %.17g read back %.17g", i, j, cov[i * P + j], back[i * P + j]);
    /* a nearly singular covariance, as a fit of hardly more stars than
    ** terms has, reads back (an outside probe's order-2 fit of 26 stars had
    ** been refused reading its own file: the 10 digits of a pivot of 1e-12) */
    for (k = 0; k < 16; k++) {
        tu_seed(&r, 40 + (unsigned long long)k);
        for (j = 0; j < P; j++) /* row 2 of A nearly rows 0 + 1: a pivot of 1e-4 .. 1e-19 */
            A[2 * P + j] = A[j] + A[P + j] + pow(10.0, -2 - 0.5 * k) * (tu_uniform(&r) - 0.5);
        for (i = 0; i < P; i++)
            for (j = 0; j < P; j++) {
                double c = 0;
                for (int m = 0; m < P; m++)
                    c += A[i * P + m] * A[j * P + m];
                cov[i * P + j] = 1e-12 * c;
            }
        for (i = 0; i < P; i++)
            in.err[i] = sqrt(cov[i * P + i]);
        ck_assert_msg(pmmodel_save_cov(path, &a, &in, cov, "c", err, sizeof err) == 0, "%s", err);
        ck_assert_msg(pmmodel_load_cov(path, &b, &got, back, (size_t)(PM_MAX_TERMS * PM_MAX_TERMS),
                                       &has, err, sizeof err) == 0,
                      "near-singular, noise 1e-%g: %s", 2 + 0.5 * k, err);
        ck_assert_int_eq(has, 1);
    }
    /* the older calls read it, without the covariance */
    ck_assert_msg(pmmodel_load_info(path, &b, &got, err, sizeof err) == 0, "%s", err);
    ck_assert_int_eq(got.has_err, 1);
    ck_assert_msg(pmmodel_load(path, &b, err, sizeof err) == 0, "%s", err);
    /* too little room: an error, nothing changed */
    ck_assert_int_eq(pmmodel_load_cov(path, &b, &got, back, (size_t)(P * P - 1), &has, err,
                                      sizeof err), -1);
    ck_assert_msg(strstr(err, "needs") != NULL, "%s", err);
    ck_assert_int_eq(has, 0);
    /* a version-4 file: no covariance, the buffer untouched */
    ck_assert_int_eq(pmmodel_save_info(path, &a, &in, NULL, err, sizeof err), 0);
    back[0] = -7;
    ck_assert_int_eq(pmmodel_load_cov(path, &b, &got, back, (size_t)(P * P), &has, err, sizeof err),
                     0);
    ck_assert_int_eq(has, 0);
    ck_assert(back[0] == -7);
    /* what cannot be written */
    cov[1] += 1e-15; /* (not symmetric) */
    ck_assert_int_eq(pmmodel_save_cov(path, &a, &in, cov, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "not symmetric") != NULL, "%s", err);
    cov[1] -= 1e-15;
    in.has_err = 0;
    ck_assert_int_eq(pmmodel_save_cov(path, &a, &in, cov, NULL, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "needs the errors") != NULL, "%s", err);
    /* the file's faults, at their line */
    for (k = 0; k < (int)(sizeof bad / sizeof bad[0]); k++) {
        snprintf(text, sizeof text, "%s%s", head5, bad[k].lines);
        expect_load_error(text, bad[k].line, bad[k].word);
    }
    expect_load_error("pm-model 5\nmount equatorial\norder 0\ncorrelations\n", "4",
                      "without the 'errors' line");
    expect_load_error("pm-model 4\nmount equatorial\norder 0\nerrors\ncorrelations\n", "5",
                      "version 5 has it");
    expect_load_error("pm-model 4\nmount equatorial\norder 0\nstars_sigma 1e-6\n", "4",
                      "version 5 has it");
    expect_load_error("pm-model 5\nmount equatorial\norder 0\nstars_sigma -1e-6\n", "4",
                      "expected 'stars_sigma S'");
    expect_load_error("pm-model 5\nmount equatorial\norder 0\nstars_sigma 1e-6\nstars_sigma 1e-6\n",
                      "5", "second 'stars_sigma'");
    expect_load_error("pm-model 5\nmount equatorial\norder 0\nerrors\nterms 6\n"
                      "term a 1 0 0 0 1e-6\ncorr 2 1 0\n",
                      "7", "without the 'correlations' line");
    expect_load_error("pm-model 5\nmount equatorial\norder 0\nerrors\ncorrelations\nterms 6\n"
                      "term a 1 0 0 0 1e-6\ncorr 2 1 0\n",
                      "8", "before the last term line");
    free(A);
    free(cov);
    free(back);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("modelfile");
    TCase *tc = tcase_create("roundtrip");
    tcase_add_test(tc, test_pmmodel_save_load_roundtrip_bit_exact);
    tcase_add_test(tc, test_pmmodel_emit_c_compiles_and_loads);
    tcase_add_test(tc, test_pmmodel_version_2_side_terms);
    tcase_add_test(tc, test_pmmodel_save_only_what_loads);
    tcase_set_timeout(tc, 60);
    suite_add_tcase(s, tc);
    tc = tcase_create("errors");
    tcase_add_test(tc, test_pmmodel_load_errors_name_line);
    tcase_add_test(tc, test_pmmodel_version_1);
    tcase_add_test(tc, test_pmmodel_load_binary_and_missing);
    tcase_add_test(tc, test_pmmodel_save_unwritable);
    tcase_add_test(tc, test_pmmodel_info);
    tcase_add_test(tc, test_pmmodel_covariance);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
