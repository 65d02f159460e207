/*
**  check_formats.c - the readers of the pointing files users already have
**  (RTS2 gpoint input, MountWizzard4 JSON model files, N.I.N.A./ASCOM-style
**  CSV logs, the MMT pointing log; tools/lib/runfile.h).  The TPOINT term
**  export (pmfit fit --tpoint-terms) is tested in check_tpointterms.c.
**
**  TCases: "detect" (detection by content, forcing a format, the names),
**  "samples" (every sample in tests/data, written by tests/ref/formats_gen.py
**  from two simulated runs, reads as the run it came from), "fit" (pmfit
**  fits every sample to the source run's fit and to the true terms),
**  "errors" (each bad_* sample's message, skipped records), "realdata" (the MMT log against its TPOINT conversion; skipped when
**  $PM_DATA_DIR has no mmt/).
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm.h"
#include "runfile.h"
#include "tu_runfile.h"
#include "tu_tool.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define AS (DEG / 3600.0)

/* A sample against its source run, record by record: the samples' decimal
** text (LST to 1e-7 deg, angles to 1e-9 deg or 1e-10 h) and nothing else. */
#define TOL_SAME_RAD 5e-9
/* The J2000 samples: sexagesimal text to 1e-4 s / 1e-3 arcsec and the
** reduction's round trip (eraAtoiq + eraAtic13 in Python, eraAtci13 and the
** one-step refraction inverse here): 10 mas. */
#define TOL_J2000_RAD 5e-8
/* Times: MW4's julianDate has whole seconds, the CSV milliseconds. */
#define TOL_TIME_H 3e-4
/* A fit of a sample against the fit of its source run (arcsec). */
#define TOL_FIT_SAME_AS 0.002
/* ... and against the true terms: 4 sigma of the fit plus this. */
#define TOL_FIT_TRUTH_AS 0.01
/* The MMT log and its TPOINT conversion (arcsec): the conversion's -5.9"
** elevation offset moves e' by 5.9" and, through the exact rotations, c', d
** and i by a second-order 0.1" (docs/formats.md); with the offset applied to
** the log too the fits agree to the conversion's 1e-7 deg rounding. */
#define TOL_MMT_EL_OFFSET_AS 0.01
#define TOL_MMT_SECOND_ORDER_AS 0.15
#define TOL_MMT_SAME_AS 0.001

/* ------------------------------------------------------------ helpers */

static void data_path(char *buf, size_t n, const char *name)
{
    const char *top = getenv("PM_TOP");
    snprintf(buf, n, "%s/tests/data/%s", top && *top ? top : ".", name);
}

static pmrun *read_opt(const char *name, const pmrun_options *opt)
{
    char path[4096], err[2048];
    pmrun *run = NULL;
    data_path(path, sizeof path, name);
    int st = pmrun_read(path, opt, &run, err, sizeof err);
    ck_assert_msg(st == PMRUN_OK, "%s: status %d: %s", name, st, err);
    return run;
}

static pmrun *read_ok(const char *name) { return read_opt(name, NULL); }

static void expect_error(const char *name, const pmrun_options *opt, int line, const char *needle)
{
    char path[4096];
    data_path(path, sizeof path, name);
    tu_read_fails(path, opt, PMRUN_ERR_FORMAT, line, needle);
}

static double wrap(double a) { return remainder(a, 2 * PI); }

static int count_west(const pmrun *run)
{
    size_t i;
    int n = 0;
    for (i = 0; i < pmrun_count(run); ++i) n += pmrun_get(run, i)->pier == PMRUN_PIER_WEST;
    return n;
}

/* Every record of `name` is the record of `source` at the same index. */
static void same_records(const char *name, const char *source, const pmrun_options *opt,
                         double tol, int check_time)
{
    pmrun *a = read_opt(name, opt), *b = read_ok(source);
    size_t i;
    ck_assert_uint_eq(pmrun_count(a), pmrun_count(b));
    ck_assert_int_eq(pmrun_mount(a), pmrun_mount(b));
    for (i = 0; i < pmrun_count(a); ++i) {
        const pmrun_obs *x = pmrun_get(a, i), *y = pmrun_get(b, i);
        ck_assert_msg(fabs(wrap(x->enc_ha - y->enc_ha)) < tol && fabs(x->enc_dec - y->enc_dec) < tol &&
                          fabs(wrap(x->app_ha - y->app_ha)) < tol && fabs(x->app_dec - y->app_dec) < tol,
                      "%s record %zu (line %d): enc %.12f %.12f app %.12f %.12f, source %.12f %.12f "
                      "%.12f %.12f",
                      name, i, x->line, x->enc_ha, x->enc_dec, x->app_ha, x->app_dec, y->enc_ha,
                      y->enc_dec, y->app_ha, y->app_dec);
        if (pmrun_mount(a) == PMRUN_MOUNT_EQUATORIAL)
            ck_assert_int_eq(x->pier, y->pier);
        if (check_time)
            ck_assert_msg(fabs(x->time_h - y->time_h) < TOL_TIME_H, "%s record %zu: time %.6f vs %.6f",
                          name, i, x->time_h, y->time_h);
    }
    pmrun_free(a);
    pmrun_free(b);
}

static double term_error(const char *json, const char *name)
{
    char pat[128];
    const char *p;
    snprintf(pat, sizeof pat, "{\"name\": \"%s\", \"value_arcsec\": ", name);
    p = strstr(json, pat);
    ck_assert_ptr_nonnull(p);
    p = strstr(p, "\"error_arcsec\": ");
    ck_assert_ptr_nonnull(p);
    return atof(p + strlen("\"error_arcsec\": "));
}

/* pmfit fit tests/data/<name> <args> --json into out; its exit code. */
static int pmfit_json(const char *name, const char *args, char *out, size_t len)
{
    char path[2048], cmd[4096];
    data_path(path, sizeof path, name);
    snprintf(cmd, sizeof cmd, "%s fit %s %s --json 2>/dev/null", tu_pmfit_path(), path, args);
    return tu_capture(cmd, out, len);
}

static const char *const kIso[6] = {"a", "b", "c'", "d", "e'", "i"};

/* ------------------------------------------------------------- detect */

START_TEST(test_pmrun_options_default_format_equinox)
{
    pmrun_options o;
    memset(&o, 0x5a, sizeof o);
    pmrun_options_default(&o);
    ck_assert_int_eq(o.format, PMRUN_FORMAT_AUTO);
    ck_assert_int_eq(o.equinox, PMRUN_EQUINOX_FILE);
}
END_TEST

START_TEST(test_pmrun_format_names_round_trip)
{
    int f;
    for (f = PMRUN_FORMAT_AUTO; f <= PMRUN_FORMAT_MMT; ++f) {
        const char *n = pmrun_format_name(f);
        ck_assert_ptr_nonnull(n);
        ck_assert_int_eq(pmrun_format_from_name(n), f);
    }
    ck_assert_int_eq(pmrun_format_from_name("MW4"), PMRUN_FORMAT_MW4);
    ck_assert_int_eq(pmrun_format_from_name("json"), -2);
    ck_assert_int_eq(pmrun_format_from_name(NULL), -2);
    ck_assert_ptr_null(pmrun_format_name(7));
    ck_assert_ptr_null(pmrun_format_name(-2));
}
END_TEST

START_TEST(test_pmrun_read_detects_each_format)
{
    static const struct {
        const char *name;
        int format, mount, n, west;
    } k[] = {{"rts2_gpoint.dat", PMRUN_FORMAT_RTS2, PMRUN_MOUNT_EQUATORIAL, 60, 31},
             {"rts2_altaz.dat", PMRUN_FORMAT_RTS2, PMRUN_MOUNT_ALTAZ, 50, 0},
             {"mw4_model.json", PMRUN_FORMAT_MW4, PMRUN_MOUNT_EQUATORIAL, 60, 31},
             {"nina_j2000.csv", PMRUN_FORMAT_CSV, PMRUN_MOUNT_EQUATORIAL, 60, 31},
             {"nina_jnow.csv", PMRUN_FORMAT_CSV, PMRUN_MOUNT_EQUATORIAL, 60, 31},
             {"mmt_log.dat", PMRUN_FORMAT_MMT, PMRUN_MOUNT_ALTAZ, 50, 0}};
    size_t i;
    for (i = 0; i < sizeof k / sizeof k[0]; ++i) {
        pmrun *run = read_ok(k[i].name);
        ck_assert_msg(pmrun_format(run) == k[i].format, "%s: format %d", k[i].name, pmrun_format(run));
        ck_assert_int_eq(pmrun_mount(run), k[i].mount);
        ck_assert_uint_eq(pmrun_count(run), (size_t)k[i].n);
        ck_assert_int_eq(count_west(run), k[i].west);
        pmrun_free(run);
    }
}
END_TEST

START_TEST(test_pmrun_read_forced_format_is_used)
{
    pmrun_options o;
    pmrun *run;
    pmrun_options_default(&o);
    o.format = PMRUN_FORMAT_CSV;
    run = read_opt("nina_jnow.csv", &o);
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_CSV);
    pmrun_free(run);
    o.format = PMRUN_FORMAT_TPOINT; /* forcing the old formats works too */
    run = read_opt("tpoint_equat.dat", &o);
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_TPOINT);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_forced_wrong_format_names_it)
{
    pmrun_options o;
    pmrun_options_default(&o);
    o.format = PMRUN_FORMAT_MMT;
    expect_error("nina_jnow.csv", &o, 6,
                 "read as an MMT pointing log (format forced: mmt): line "
                 "'LST;RA;Dec;SolvedRA;SolvedDec;SideOfPier' is not 'KEY: values'");
    o.format = PMRUN_FORMAT_CSV;
    expect_error("rts2_gpoint.dat", &o, 7,
                 "read as a N.I.N.A./ASCOM-style CSV log (format forced: csv): no mount RA column");
    o.format = PMRUN_FORMAT_MW4;
    expect_error("mmt_log.dat", &o, 1, "read as a MountWizzard4 model file (JSON) (format forced: "
                                       "mw4): '# MMT mount ' is not a JSON value");
    o.format = 9;
    {
        char path[4096];
        data_path(path, sizeof path, "mmt_log.dat");
        tu_read_fails(path, &o, PMRUN_ERR_ARG, 0, "options.format 9 is not a format");
    }
}
END_TEST

START_TEST(test_pmrun_read_wrong_guess_names_the_format)
{
    /* a delimited header without the CSV names: read as a column file,
    ** and the message says so and why */
    char tmp[] = "/tmp/pm_formats_XXXXXX";
    int fd = mkstemp(tmp);
    static const char text[] = "# equinox: JNow\nLST,Mount Alpha,Mount Delta,Sol Alpha,Sol Delta\n"
                               "1,2,3,4,5\n";
    ck_assert_int_ge(fd, 0);
    ck_assert_int_eq(write(fd, text, sizeof text - 1), (long)(sizeof text - 1));
    close(fd);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 2,
                  "read as a four-column or named-column file (line 2 has ',' or ';' but is not a "
                  "CSV header naming the mount's and the solved RA and Dec)");
    unlink(tmp);
}
END_TEST

/* An equatorial TPOINT file with its LST as h m s: the seconds are read as
** aux1 (TPOINT's LST is h and decimal minutes), and the note says so. */
static int edit_lst_hms(char *line, size_t size, void *arg)
{
    int *n = (int *)arg;
    char *last = strrchr(line, ' ');
    double m;
    if (++*n >= 9 && line[0] >= '0' && line[0] <= '9' && last && sscanf(last, "%lf", &m) == 1)
        snprintf(last, size - (size_t)(last - line), " %02d %05.2f\n", (int)m,
                 (m - (int)m) * 60.0);
    return 1;
}

START_TEST(test_pmrun_read_tpoint_lst_seconds_noted)
{
    char src[4096], path[64], err[1024];
    pmrun *run = NULL;
    int n = 0;
    data_path(src, sizeof src, "tpoint_equat.dat");
    strcpy(path, "/tmp/pm_lsthms_XXXXXX");
    tu_edited_copy(src, path, edit_lst_hms, &n);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_ptr_nonnull(strstr(pmrun_warning(run, 0), "if field 15 is the LST's seconds"));
    ck_assert(pmrun_get(run, 1)->aux[0] == 22.2);
    pmrun_free(run);
    unlink(path);
}
END_TEST

/* A TPOINT alt-az file without its ': ALTAZ' line: the four-field records are
** refused with a hint at the option (the error spoke only of 14 fields). */
static int edit_no_altaz(char *line, size_t size, void *arg)
{
    (void)size;
    (void)arg;
    return strncmp(line, ": ALTAZ", 7) != 0;
}

START_TEST(test_pmrun_read_tpoint_altaz_without_option)
{
    char src[4096], path[64];
    data_path(src, sizeof src, "tpoint_altaz.dat");
    strcpy(path, "/tmp/pm_noaltaz_XXXXXX");
    tu_edited_copy(src, path, edit_no_altaz, NULL);
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 6, "4 fields, expected 14");
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 6, "after the option line ': ALTAZ'");
    unlink(path);
}
END_TEST

/* Excel's first line 'sep=;' (or 'sep=,') names the delimiter; it was read as
** a TPOINT caption and the file refused for another cause (an outside probe).
** A delimiter other than ',' or ';' is refused on that line. */
typedef struct sep_edit {
    int first; /* the next line is the file's first */
    char sep;
} sep_edit;

static int edit_sep(char *line, size_t size, void *arg)
{
    sep_edit *a = (sep_edit *)arg;
    size_t n = strlen(line);
    if (a->first && n + 7 < size) {
        memmove(line + 6, line, n + 1);
        memcpy(line, "sep=", 4);
        line[4] = a->sep;
        line[5] = '\n';
    }
    a->first = 0;
    return 1;
}

START_TEST(test_pmrun_read_csv_excel_sep)
{
    static const char seps[2] = {';', '\t'};
    char src[4096], path[64], err[1024];
    pmrun *words = read_ok("nina_jnow.csv"), *run;
    size_t i;
    int k;
    data_path(src, sizeof src, "nina_jnow.csv");
    for (k = 0; k < 2; ++k) {
        sep_edit a;
        a.first = 1;
        a.sep = seps[k];
        strcpy(path, "/tmp/pm_sep_XXXXXX");
        tu_edited_copy(src, path, edit_sep, &a);
        if (k == 0) {
            run = NULL;
            ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
            ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_CSV);
            ck_assert_uint_eq(pmrun_count(run), pmrun_count(words));
            for (i = 0; i < pmrun_count(run); ++i) {
                ck_assert(pmrun_get(run, i)->enc_ha == pmrun_get(words, i)->enc_ha);
                ck_assert(pmrun_get(run, i)->app_dec == pmrun_get(words, i)->app_dec);
                ck_assert_int_eq(pmrun_get(run, i)->line, pmrun_get(words, i)->line + 1);
            }
            pmrun_free(run);
        } else {
            tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 1, "'sep=<tab>': expected 'sep=,' or 'sep=;'");
        }
        unlink(path);
    }
    pmrun_free(words);
}
END_TEST

/* nina_jnow.csv with its sides East/West written as `e` and `w` into a
** temporary file (path out); rows of only East when `w` is NULL.  The line
** of the first East and the first West row written: line_e, line_w. */
static int line_e, line_w;
typedef struct sides_edit {
    const char *e, *w;
    int n; /* lines written */
} sides_edit;

static int edit_sides(char *line, size_t size, void *arg)
{
    sides_edit *a = (sides_edit *)arg;
    char *p = strstr(line, ";East"), *q = strstr(line, ";West");
    if (p) {
        snprintf(p, size - (size_t)(p - line), ";%s\n", a->e);
        if (!line_e) line_e = a->n + 1;
    } else if (q) {
        if (!a->w) return 0;
        snprintf(q, size - (size_t)(q - line), ";%s\n", a->w);
        if (!line_w) line_w = a->n + 1;
    }
    a->n++;
    return 1;
}

static void csv_sides(char *out, const char *e, const char *w)
{
    char src[4096];
    sides_edit a = {e, w, 0};
    line_e = line_w = 0;
    data_path(src, sizeof src, "nina_jnow.csv");
    strcpy(out, "/tmp/pm_sides_XXXXXX");
    tu_edited_copy(src, out, edit_sides, &a);
}

/* Sides as numbers: ASCOM's SideOfPier numbers (0 pierEast, 1 pierWest) where
** a 0 is among them, pm's (+1, -1) otherwise; the words' records either way.
** Read as pm's, an ASCOM log's 1 (pierWest) was the normal side: d, e' and i
** of opposite sign, nothing to show it (an outside probe). */
START_TEST(test_pmrun_read_csv_sides_as_numbers)
{
    static const char *const pairs[3][2] = {{"0", "1"}, {"+1", "-1"}, {"1", "-1"}};
    char path[64], err[1024];
    pmrun *words = read_ok("nina_jnow.csv"), *run;
    size_t i;
    int k;
    ck_assert_int_gt(count_west(words), 0);
    for (k = 0; k < 3; k++) {
        csv_sides(path, pairs[k][0], pairs[k][1]);
        run = NULL;
        ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
        ck_assert_uint_eq(pmrun_count(run), pmrun_count(words));
        for (i = 0; i < pmrun_count(run); ++i) {
            ck_assert_int_eq(pmrun_get(run, i)->pier, pmrun_get(words, i)->pier);
            ck_assert(pmrun_get(run, i)->enc_dec == pmrun_get(words, i)->enc_dec);
        }
        if (k == 0)
            ck_assert_ptr_nonnull(strstr(pmrun_warning(run, pmrun_n_warnings(run) - 1),
                                         "ASCOM's SideOfPier"));
        pmrun_free(run);
        unlink(path);
    }
    /* ASCOM's -1 is pierUnknown; mixed numbers are refused */
    csv_sides(path, "0", "-1");
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, line_w, "-1 is pierUnknown");
    unlink(path);
    csv_sides(path, "+1", "0");
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, line_e, "mixed");
    unlink(path);
    /* -1 alone: pm's beyond the pole, with a note that ASCOM's -1 is pierUnknown
    ** (it was read so silently) */
    csv_sides(path, "-1", NULL);
    run = NULL;
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_int_eq(count_west(run), (int)pmrun_count(run));
    ck_assert_ptr_nonnull(strstr(pmrun_warning(run, pmrun_n_warnings(run) - 1), "-1 pierUnknown"));
    pmrun_free(run);
    unlink(path);
    /* 1 alone: read as pm's +1, with a note that ASCOM's 1 is pierWest */
    csv_sides(path, "1", NULL);
    run = NULL;
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_int_eq(count_west(run), 0);
    ck_assert_ptr_nonnull(strstr(pmrun_warning(run, pmrun_n_warnings(run) - 1), "1 is pierWest"));
    pmrun_free(run);
    unlink(path);
    pmrun_free(words);
}
END_TEST

/* nina_jnow.csv's RA and LST in degrees, the header saying so (k = 0), or
** its declination named in hours (k = 1; the header's line: header). */
typedef struct units_edit {
    int k, n, header;
} units_edit;

static int edit_units(char *line, size_t size, void *arg)
{
    units_edit *a = (units_edit *)arg;
    double f[5];
    char side[32];
    a->n++;
    if (!strncmp(line, "LST;", 4)) {
        snprintf(line, size, "%s",
                 a->k ? "LST;RA;Dec (h);SolvedRA;SolvedDec;SideOfPier\n"
                      : "LST (deg);RA (deg);Dec;SolvedRA (degrees);SolvedDec (deg);SideOfPier\n");
        a->header = a->n;
    } else if (line[0] != '#' && sscanf(line, "%lf;%lf;%lf;%lf;%lf;%31s", &f[0], &f[1], &f[2],
                                        &f[3], &f[4], side) == 6) {
        snprintf(line, size, "%.10f;%.10f;%.9f;%.10f;%.9f;%s\n", 15 * f[0], 15 * f[1], f[2],
                 15 * f[3], f[4], side);
    }
    return 1;
}

/* An RA (and LST) column whose name says degrees is read in degrees (an
** 'RA (deg)' column was read as hours, silently: sigma 20" for 0.4"); a
** declination named in hours is refused (an outside probe). */
START_TEST(test_pmrun_read_csv_units_in_names)
{
    char src[4096], path[64], err[1024];
    int fd, k;
    pmrun *words = read_ok("nina_jnow.csv"), *run = NULL;
    size_t i;
    for (k = 0; k < 2; k++) {
        units_edit a = {k, 0, 0};
        data_path(src, sizeof src, "nina_jnow.csv");
        strcpy(path, "/tmp/pm_units_XXXXXX");
        tu_edited_copy(src, path, edit_units, &a);
        if (k == 1) {
            tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, a.header, "a declination in hours?");
        } else {
            ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
            ck_assert_uint_eq(pmrun_count(run), pmrun_count(words));
            for (i = 0; i < pmrun_count(run); ++i) {
                const pmrun_obs *x = pmrun_get(run, i), *y = pmrun_get(words, i);
                ck_assert(fabs(wrap(x->enc_ha - y->enc_ha)) < 1e-9);
                ck_assert(fabs(wrap(x->app_ha - y->app_ha)) < 1e-9);
                ck_assert(fabs(x->app_dec - y->app_dec) < 1e-9);
            }
            pmrun_free(run);
        }
        unlink(path);
    }
    pmrun_free(words);
    /* hours written with their letters under a header in degrees: refused
    ** (read as degrees: sigma 14" for 0.5", an outside probe) */
    {
        static const char text[] = "# equinox: JNow\n# refraction: no\n"
                                   "LST;RA (deg);Dec;SolvedRA (deg);SolvedDec;SideOfPier\n"
                                   "8.86;2h45m30.357s;63.97;2h45m19.878s;63.98;West\n";
        strcpy(path, "/tmp/pm_units_XXXXXX");
        fd = mkstemp(path);
        ck_assert_int_ge(fd, 0);
        ck_assert_int_eq(write(fd, text, sizeof text - 1), (long)(sizeof text - 1));
        close(fd);
        tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 4, "written in hours, but the header names");
        unlink(path);
    }
}
END_TEST

/* a row's time without its zone (its Z taken out) */
static int edit_no_zone(char *line, size_t size, void *arg)
{
    char *z = strstr(line, "Z,");
    (void)size;
    (void)arg;
    if (z && line[0] != '#')
        memmove(z, z + 1, strlen(z + 1) + 1);
    return 1;
}

/* Times without their zone are UTC, said where they place the stars (a log
** of local times read as UTC turns every hour angle by the zone, and the
** fit blamed the plate solves: an outside probe). */
START_TEST(test_pmrun_read_csv_time_without_zone)
{
    char src[4096], path[64], err[1024];
    int k, found = -1;
    pmrun *run = NULL;
    data_path(src, sizeof src, "nina_j2000.csv");
    strcpy(path, "/tmp/pm_zone_XXXXXX");
    tu_edited_copy(src, path, edit_no_zone, NULL);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    for (k = 0; k < pmrun_n_warnings(run); k++)
        if (strstr(pmrun_warning(run, k), "the time has no zone"))
            found = k;
    ck_assert_int_ge(found, 0);
    pmrun_free(run);
    unlink(path);
    run = read_ok("nina_j2000.csv"); /* with its Z: nothing said */
    for (k = 0; k < pmrun_n_warnings(run); k++)
        ck_assert_ptr_null(strstr(pmrun_warning(run, k), "no zone"));
    pmrun_free(run);
}
END_TEST

/* ------------------------------------------------------------ samples */

START_TEST(test_pmrun_read_rts2_same_as_source)
{
    same_records("rts2_gpoint.dat", "formats_source_eq.dat", NULL, TOL_SAME_RAD, 1);
    same_records("rts2_altaz.dat", "formats_source_altaz.dat", NULL, TOL_SAME_RAD, 1);
}
END_TEST

/* A gpoint file with Julian dates in field 2 (where gpoint writes MJD) is
** read as JD - 2400000.5, with a note; it was refused. */
static int edit_jd(char *line, size_t size, void *arg)
{
    char name[64], rest[1024];
    double mjd;
    (void)arg;
    if (line[0] != '#' && sscanf(line, "%63s %lf %1023[^\n]", name, &mjd, rest) == 3)
        snprintf(line, size, "%s %.8f %s\n", name, mjd + 2400000.5, rest);
    return 1;
}

START_TEST(test_pmrun_read_rts2_julian_dates)
{
    char src[4096], path[64], err[1024];
    pmrun *mjd = read_ok("rts2_gpoint.dat"), *run = NULL;
    size_t i;
    data_path(src, sizeof src, "rts2_gpoint.dat");
    strcpy(path, "/tmp/pm_jd_XXXXXX");
    tu_edited_copy(src, path, edit_jd, NULL);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_uint_eq(pmrun_count(run), pmrun_count(mjd));
    for (i = 0; i < pmrun_count(run); ++i) {
        const pmrun_obs *x = pmrun_get(run, i), *y = pmrun_get(mjd, i);
        ck_assert(fabs(wrap(x->app_ha - y->app_ha)) < TOL_SAME_RAD);
        ck_assert(fabs(x->app_dec - y->app_dec) < TOL_SAME_RAD);
        ck_assert(x->enc_ha == y->enc_ha && x->enc_dec == y->enc_dec);
        ck_assert(fabs(x->time_h - y->time_h) < 1e-6);
    }
    ck_assert_ptr_nonnull(strstr(pmrun_warning(run, 0), "is a Julian date"));
    pmrun_free(run);
    unlink(path);
    pmrun_free(mjd);
}
END_TEST

START_TEST(test_pmrun_read_rts2_j2000_reduced_with_equinox_option)
{
    pmrun_options o;
    pmrun *run;
    pmrun_options_default(&o);
    o.equinox = PMRUN_EQUINOX_J2000;
    same_records("rts2_gpoint_j2000.dat", "formats_source_eq.dat", &o, TOL_J2000_RAD, 1);
    /* without the option the places are taken as they are (gpoint's way):
    ** 24 years of precession and the refraction away from the source */
    run = read_ok("rts2_gpoint_j2000.dat");
    ck_assert(fabs(pmrun_get(run, 0)->app_dec - 63.975098125 * DEG) > 60 * AS);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_mw4_same_as_source)
{
    pmrun *run;
    same_records("mw4_model.json", "formats_source_eq.dat", NULL, TOL_SAME_RAD, 1);
    run = read_ok("mw4_model.json");
    ck_assert_int_eq(pmrun_n_aux(run), 2);
    ck_assert_str_eq(pmrun_aux_name(run, 0), "angularPosRA");
    ck_assert(fabs(pmrun_latitude_rad(run) - 47 * DEG) < 1e-12);
    ck_assert_int_eq(pmrun_get(run, 0)->line, 2);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_csv_same_as_source)
{
    pmrun *run;
    same_records("nina_jnow.csv", "formats_source_eq.dat", NULL, TOL_SAME_RAD, 0);
    same_records("nina_j2000.csv", "formats_source_eq.dat", NULL, TOL_J2000_RAD, 1);
    run = read_ok("nina_j2000.csv");
    ck_assert(fabs(pmrun_get(run, 0)->temp_c - 12.01) < 1e-12);
    /* the unused 'Target' column is named in a warning, not dropped silently */
    ck_assert_int_ge(pmrun_n_warnings(run), 1);
    ck_assert_ptr_nonnull(strstr(pmrun_warning(run, 0), "column 'Target' not used"));
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_csv_equinox_option_overrides)
{
    pmrun_options o;
    pmrun *a, *b;
    pmrun_options_default(&o);
    o.equinox = PMRUN_EQUINOX_J2000; /* the JNow file (LST, no times) as J2000 */
    expect_error("nina_jnow.csv", &o, 7, "J2000 places need the UTC time of the row");
    a = read_opt("nina_j2000.csv", NULL);
    /* the J2000 file's places taken as JNow: 24 years of precession, far
    ** more than the samples' agreement */
    o.equinox = PMRUN_EQUINOX_JNOW; /* the J2000 file's places taken as JNow */
    o.refraction = 1;
    b = read_opt("nina_j2000.csv", &o);
    ck_assert(fabs(pmrun_get(a, 0)->app_dec - pmrun_get(b, 0)->app_dec) > 60 * AS);
    pmrun_free(a);
    pmrun_free(b);
}
END_TEST

/* An equinox asked of a format whose places it does not apply to (a TPOINT
** file's are its catalogue's mean places; a column file's and an MMT
** log's are apparent): refused, where it was ignored without a word --
** detected or forced, with either equinox. */
START_TEST(test_pmrun_read_equinox_refused_where_it_does_not_apply)
{
    static const char *names[] = {"tpoint_equat.dat", "four_column.dat", "named.dat", "mmt_log.dat"};
    static const int forced[] = {PMRUN_FORMAT_TPOINT, PMRUN_FORMAT_FOUR_COLUMN,
                                 PMRUN_FORMAT_NAMED, PMRUN_FORMAT_MMT};
    pmrun_options o;
    char path[4096];
    size_t k;
    int e;
    for (k = 0; k < sizeof names / sizeof names[0]; k++)
        for (e = 0; e < 4; e++) {
            pmrun_options_default(&o);
            o.equinox = e & 1 ? PMRUN_EQUINOX_JNOW : PMRUN_EQUINOX_J2000;
            if (e & 2)
                o.format = forced[k];
            data_path(path, sizeof path, names[k]);
            tu_read_fails(path, &o, PMRUN_ERR_FORMAT, 0, "refused rather than ignored");
        }
    /* and read as before without it */
    pmrun_free(read_ok("four_column.dat"));
}
END_TEST

START_TEST(test_pmrun_read_mmt_same_as_source)
{
    same_records("mmt_log.dat", "formats_source_altaz.dat", NULL, TOL_SAME_RAD, 0);
}
END_TEST

/* ---------------------------------------------------------------- fit */

static void fit_matches(const char *name, const char *source, const double truth[6],
                        const char *args)
{
    char a[16384], b[16384];
    int k;
    ck_assert_int_eq(pmfit_json(name, args, a, sizeof a), 0);
    ck_assert_int_eq(pmfit_json(source, "--order 0", b, sizeof b), 0);
    for (k = 0; k < 6; ++k) {
        double v = tu_term_value(a, kIso[k]), s = tu_term_value(b, kIso[k]), e = term_error(a, kIso[k]);
        ck_assert_msg(fabs(v - s) < TOL_FIT_SAME_AS, "%s: %s = %.5f\", source %.5f\"", name, kIso[k],
                      v, s);
        ck_assert_msg(fabs(v - truth[k]) < 4 * e + TOL_FIT_TRUTH_AS,
                      "%s: %s = %.4f +- %.4f\", true %.4f\"", name, kIso[k], v, e, truth[k]);
    }
}

/* The terms of the pmfit simulate commands in the sources' first lines. */
static const double kTruthEq[6] = {40, -25, 120, 18, -35, 22};
static const double kTruthAz[6] = {30, 15, -200, 12, 25, -18};

START_TEST(test_sources_are_the_simulations_named)
{
    char path[4096], line[1024];
    FILE *f;
    data_path(path, sizeof path, "formats_source_eq.dat");
    f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
    fclose(f);
    ck_assert_ptr_nonnull(strstr(line, "--order 0 --term a=40 --term b=-25 --term c'=120 --term d=18 "
                                       "--term e'=-35 --term i=22 --noise 0.5"));
    data_path(path, sizeof path, "formats_source_altaz.dat");
    f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
    fclose(f);
    ck_assert_ptr_nonnull(strstr(line, "--mount altaz --order 0 --term a=30 --term b=15 --term "
                                       "c'=-200 --term d=12 --term e'=25 --term i=-18 --noise 0.5"));
}
END_TEST

START_TEST(test_pmfit_fits_rts2) { fit_matches("rts2_gpoint.dat", "formats_source_eq.dat", kTruthEq, "--order 0"); }
END_TEST

START_TEST(test_pmfit_fits_rts2_j2000)
{
    fit_matches("rts2_gpoint_j2000.dat", "formats_source_eq.dat", kTruthEq,
                "--order 0 --equinox J2000");
}
END_TEST

START_TEST(test_pmfit_fits_rts2_altaz)
{
    fit_matches("rts2_altaz.dat", "formats_source_altaz.dat", kTruthAz, "--order 0");
}
END_TEST

START_TEST(test_pmfit_fits_mw4) { fit_matches("mw4_model.json", "formats_source_eq.dat", kTruthEq, "--order 0"); }
END_TEST

START_TEST(test_pmfit_fits_csv_j2000)
{
    fit_matches("nina_j2000.csv", "formats_source_eq.dat", kTruthEq, "--order 0");
}
END_TEST

START_TEST(test_pmfit_fits_csv_jnow)
{
    fit_matches("nina_jnow.csv", "formats_source_eq.dat", kTruthEq, "--order 0 --format csv");
}
END_TEST

START_TEST(test_pmfit_fits_mmt) { fit_matches("mmt_log.dat", "formats_source_altaz.dat", kTruthAz, "--order 0"); }
END_TEST

START_TEST(test_pmfit_format_option_errors)
{
    char out[4096], cmd[4096], path[2048];
    data_path(path, sizeof path, "mmt_log.dat");
    snprintf(cmd, sizeof cmd, "%s fit %s --format tpont", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 2);
    ck_assert_ptr_nonnull(strstr(out, "--format: expected auto, four-column, named, tpoint, rts2, "
                                      "mw4, csv or mmt, got 'tpont'"));
    snprintf(cmd, sizeof cmd, "%s fit %s --equinox B1950", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 2);
    ck_assert_ptr_nonnull(strstr(out, "--equinox: expected J2000 or JNow, got 'B1950'"));
    snprintf(cmd, sizeof cmd, "%s fit %s --format rts2", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 1);
    ck_assert_ptr_nonnull(strstr(out, "read as an RTS2 gpoint input file (format forced: rts2)"));
    /* a TPOINT file forced as another format: what the field is (an MJD,
    ** not degrees), and a TPOINT file, not "mixed formats" in a '#' file
    ** that has no '#' line (an outside probe's) */
    data_path(path, sizeof path, "outside_altaz_el309.dat");
    snprintf(cmd, sizeof cmd, "%s fit %s --format rts2", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 1);
    ck_assert_msg(strstr(out, "field 2 (MJD) 'truth': not a number, expected a decimal number "
                              "(a modified Julian date)") != NULL,
                  "%s", out);
    snprintf(cmd, sizeof cmd, "%s fit %s --format four-column", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, sizeof out), 1);
    ck_assert_msg(strstr(out, "in a column file (a TPOINT file? without --format it is detected, "
                              "or --format tpoint)") != NULL,
                  "%s", out);
}
END_TEST

/* ------------------------------------------------------------- errors */

START_TEST(test_pmrun_read_bad_rts2)
{
    expect_error("bad_rts2_fields.dat", NULL, 4,
                 "read as an RTS2 gpoint input file (its '#' line 1 is an RTS2 gpoint header): 8 "
                 "fields, expected 9: observation id, MJD, LST, mount RA, Dec");
    expect_error("bad_rts2_latitude.dat", NULL, 2,
                 "'#observatory' latitude 95.0 is beyond +-90 deg, expected -90..+90");
    expect_error("bad_rts2_true_dec.dat", NULL, 3,
                 "field 9 (DEC-TRUE) '95.5': beyond +-90 deg, expected the star's declination");
}
END_TEST

START_TEST(test_pmrun_read_bad_mw4)
{
    pmrun_options o;
    expect_error("bad_mw4_syntax.json", NULL, 5,
                 "read as a MountWizzard4 model file (JSON) (line 1 starts with '['): expected ',' "
                 "or '}' after a value in an object");
    expect_error("bad_mw4_missing_key.json", NULL, 2, "point has no 'raJNowS', expected raJNowM");
    expect_error("bad_mw4_pierside.json", NULL, 2, "'pierside' missing or not \"E\"/\"W\"");
    expect_error("bad_mw4_not_list.json", NULL, 1,
                 "the JSON value is not a list, expected a list of points");
    pmrun_options_default(&o);
    o.equinox = PMRUN_EQUINOX_J2000;
    expect_error("mw4_model.json", &o, 0, "MW4 files are read through their JNow places");
}
END_TEST

START_TEST(test_pmrun_read_bad_csv)
{
    expect_error("bad_csv_no_equinox.csv", NULL, 2,
                 "read as a N.I.N.A./ASCOM-style CSV log (line 2 is a header of delimited names "
                 "with RA and Dec): the equinox of the RA/Dec columns is not stated");
    expect_error("bad_csv_missing_column.csv", NULL, 3, "no solved Dec column in the header");
    expect_error("bad_csv_ra_range.csv", NULL, 5,
                 "field 2 (mount RA) '25:00:00': out of range, expected 0 <= hours < 24");
    expect_error("bad_csv_time.csv", NULL, 5,
                 "field 1 (time) '2024-02-30T20:00:00Z': not a valid date and time");
    expect_error("bad_csv_pier.csv", NULL, 4, "field 6 (pier side) 'pierUnknown': unknown side");
    expect_error("bad_csv_quote.csv", NULL, 4, "a quoted field not closed by '\"'");
    expect_error("bad_csv_no_lst.csv", NULL, 3,
                 "no LST column and no '# longitude:': the hour angles need the sidereal time");
}
END_TEST

/* A temporary file for one case k of a test (its name from tag and the
** process), open for writing; the caller closes and removes it. */
static FILE *tmp_case(char *path, size_t len, const char *tag, const char *ext, int k)
{
    const char *dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    FILE *f;
    snprintf(path, len, "%s/pm_%s_%d_%d.%s", dir, tag, (int)getpid(), k, ext);
    f = fopen(path, "w");
    ck_assert_msg(f != NULL, "%s", path);
    return f;
}

/* Second 60 of a CSV log's time: the leap second only, 23:59:60 UTC at the
** end of a day that has one (2016-12-31; the same instant written with a
** zone, +01:00); on an ordinary day (2023-12-31 22:46:60, an outside probe's,
** read as 22:47:00 without a word) or at 23:59:60 of a day without one, the
** line is refused. */
START_TEST(test_pmrun_read_csv_second_60)
{
    static const struct {
        const char *time;
        int ok;
    } c[5] = {{"2016-12-31T23:59:60.500Z", 1},
              {"2017-01-01T00:59:60.500+01:00", 1},
              {"2016-12-31T23:59:59.500Z", 1},
              {"2023-12-31T22:46:60.000Z", 0},
              {"2023-12-31T23:59:60Z", 0}};
    char path[4096], err[2048];
    int k;
    double t[3] = {0, 0, 0};
    for (k = 0; k < 5; k++) {
        pmrun *run = NULL;
        FILE *f;
        int st;
        f = tmp_case(path, sizeof path, "sec60", "csv", k);
        fprintf(f, "# equinox: J2000\n# latitude: 47.0\n# longitude: 19.0\n"
                   "Time,Mount RA,Mount Dec,Solved RA,Solved Dec,Pier Side\n"
                   "%s,02:43:35.8170,+63:52:06.753,02:43:16.7290,+63:51:42.749,pierWest\n",
                c[k].time);
        fclose(f);
        st = pmrun_read(path, NULL, &run, err, sizeof err);
        if (c[k].ok) {
            ck_assert_msg(st == PMRUN_OK, "%s: %s", c[k].time, err);
            t[k] = pmrun_get(run, 0)->time_h;
            pmrun_free(run);
        } else {
            ck_assert_msg(st == PMRUN_ERR_FORMAT && strstr(err, ":5: ") &&
                              strstr(err, "second 60 is not a leap second here"),
                          "%s: status %d: %s", c[k].time, st, err);
        }
        remove(path);
    }
    /* the leap second is the second after 23:59:59.5 (UTC hours since 0h
    ** of the run's first date, one second on); the same written with its
    ** zone, whose run starts on the next date (24 h less) */
    ck_assert_double_eq_tol((t[0] - t[2]) * 3600, 1.0, 1e-6);
    ck_assert_double_eq_tol((t[1] + 24 - t[0]) * 3600, 0.0, 1e-6);
}
END_TEST

/* A CSV log's header that lacks a column is read as a CSV log, whose reader
** names what is missing (an outside probe's "Mount Dec" twice and no
** "Mount RA" had been read as a four-column file: "7 fields, expected 4"). */
START_TEST(test_pmrun_read_csv_header_lacking_column)
{
    static const struct {
        const char *header, *needle;
    } c[2] = {{"Time (UTC),Target,Mount Dec,Mount Dec,Solved RA,Solved Dec,Pier Side",
               "column 'Mount Dec' is a second mount Dec column"},
              {"Time (UTC),Target,Mount Dec,Solved RA,Solved Dec,Pier Side",
               "no mount RA column"}};
    char path[4096], err[2048];
    int k;
    for (k = 0; k < 2; k++) {
        pmrun *run = NULL;
        FILE *f;
        int st;
        f = tmp_case(path, sizeof path, "csvhdr", "csv", k);
        fprintf(f, "# equinox: J2000\n# latitude: 39.5\n# longitude: -105.2\n%s\n"
                   "2023-12-31T22:30:00.000Z,\"Star 1, field\",+24.9244310,+24.9,22.08027576,"
                   "+24.8652908,pierEast\n",
                c[k].header);
        fclose(f);
        st = pmrun_read(path, NULL, &run, err, sizeof err);
        ck_assert_msg(st == PMRUN_ERR_FORMAT && strstr(err, ":4: read as a N.I.N.A./ASCOM-style CSV log") &&
                          strstr(err, c[k].needle),
                      "%s: status %d: %s", c[k].header, st, err);
        remove(path);
    }
}
END_TEST

/* A TPOINT file whose first line is a caption with commas, naming words
** that hold "ra" or "dec" (camera, temperature, decker), is a TPOINT file,
** not a CSV header lacking a column (an outside probe's, misread so for one
** commit); a header naming RA and Dec as words still is a CSV log's. */
START_TEST(test_pmrun_read_tpoint_comma_caption)
{
    static const char *const caption[2] = {
        "Camera test, Temperature 10C, Konkoly site, observer J Smith",
        "RC8 Astrograph, Fornax mount, Decker slit, night 2"};
    char src[4096], path[4096], err[2048], line[1024];
    int k;
    data_path(src, sizeof src, "tpoint_equat.dat");
    for (k = 0; k < 2; k++) {
        pmrun *run = NULL;
        FILE *in = fopen(src, "r"), *out;
        int first = 1;
        ck_assert(in != NULL);
        out = tmp_case(path, sizeof path, "tpcap", "dat", k);
        while (fgets(line, sizeof line, in)) {
            if (line[0] == '!')
                continue;
            fputs(first ? caption[k] : line, out);
            if (first)
                fputc('\n', out);
            first = 0;
        }
        fclose(in);
        fclose(out);
        ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s: %s",
                      caption[k], err);
        ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_TPOINT);
        pmrun_free(run);
        remove(path);
    }
}
END_TEST

/* Within 2 deg of the pole the encoder cannot show the pier side: a star at
** Dec 89.37 on the flipped side with a 0.69 deg Dec index reads 89.94 deg,
** pier W, beside W records beyond 90 (an outside probe's run was refused as
** "mixed encoder conventions?"); 5 deg from it still is refused. */
START_TEST(test_pmrun_read_pier_near_pole)
{
    static const char *const rec[2] = {"150 89.94 150.01 89.93 W", "150 85.00 150.01 85.01 W"};
    char path[4096], err[2048];
    int k;
    for (k = 0; k < 2; k++) {
        pmrun *run = NULL;
        FILE *f;
        int st;
        f = tmp_case(path, sizeof path, "pole", "dat", k);
        fprintf(f, "# latitude: 47\n# tau delta T D pier\n-30 40 -29.99 40.01 E\n"
                   "150 120 -29.99 60.01 W\n%s\n-40 20 -39.99 20.01 E\n", rec[k]);
        fclose(f);
        st = pmrun_read(path, NULL, &run, err, sizeof err);
        if (k == 0) {
            ck_assert_msg(st == PMRUN_OK, "%s: %s", rec[k], err);
            ck_assert_uint_eq(pmrun_count(run), 4);
            pmrun_free(run);
        } else {
            ck_assert_msg(st == PMRUN_ERR_FORMAT && strstr(err, ":5: ") &&
                              strstr(err, "mixed encoder conventions?"),
                          "%s: status %d: %s", rec[k], st, err);
        }
        remove(path);
    }
}
END_TEST

/* A dir column's "+0" and "-0" are 0, as "0" (an outside probe's "+0" was
** refused); "+2" still is not a direction. */
START_TEST(test_pmrun_read_dir_signed_zero)
{
    static const char *const tok[3] = {"+0", "-0", "+2"};
    char path[4096], err[2048];
    int k;
    for (k = 0; k < 3; k++) {
        pmrun *run = NULL;
        FILE *f;
        int st;
        f = tmp_case(path, sizeof path, "dir0", "dat", k);
        fprintf(f, "# latitude: 47\n# tau delta T D dir\n10 20 10.01 20.01 %s\n"
                   "20 30 20.01 30.01 -1\n", tok[k]);
        fclose(f);
        st = pmrun_read(path, NULL, &run, err, sizeof err);
        if (k < 2) {
            ck_assert_msg(st == PMRUN_OK, "%s: %s", tok[k], err);
            ck_assert_int_eq(pmrun_get(run, 0)->dir, 0);
            ck_assert_int_eq(pmrun_get(run, 1)->dir, -1);
            pmrun_free(run);
        } else {
            ck_assert_msg(st == PMRUN_ERR_FORMAT && strstr(err, "expected +1, -1, 0 or '-'"),
                          "%s: %s", tok[k], err);
        }
        remove(path);
    }
}
END_TEST

START_TEST(test_pmrun_read_bad_mmt)
{
    expect_error("bad_mmt_no_taa.dat", NULL, 5,
                 "read as an MMT pointing log (line 1 starts with 'CAT:'): the star's block (CAT: "
                 "at line 5) has no TAA: line");
    expect_error("bad_mmt_elevation.dat", NULL, 3,
                 "TAA: elevation '97.3484799' beyond +-90 deg, expected the observed elevation");
    expect_error("bad_mmt_twice.dat", NULL, 3,
                 "second RAA: line in the star's block (the first at line 2), expected one per star");
}
END_TEST

START_TEST(test_pmrun_read_skip_bad_lists_skipped)
{
    pmrun_options o;
    pmrun *run;
    pmrun_options_default(&o);
    o.skip_bad = 1;
    run = read_opt("bad_mmt_no_taa.dat", &o);
    ck_assert_uint_eq(pmrun_count(run), 1);
    ck_assert_int_eq(pmrun_n_skipped(run), 1);
    ck_assert_ptr_nonnull(strstr(pmrun_skipped(run, 0), "bad_mmt_no_taa.dat:5: skipped: the star's "
                                                        "block (CAT: at line 5) has no TAA: line"));
    pmrun_free(run);
    run = read_opt("bad_csv_ra_range.csv", &o);
    ck_assert_uint_eq(pmrun_count(run), 1);
    ck_assert_int_eq(pmrun_n_skipped(run), 1);
    ck_assert_ptr_nonnull(strstr(pmrun_skipped(run, 0), ":5: skipped: field 2 (mount RA)"));
    pmrun_free(run);
}
END_TEST

/* ----------------------------------------------------------- realdata */

static int mmt_paths(char *log, char *tp, size_t n)
{
    const char *d = getenv("PM_DATA_DIR");
    snprintf(log, n, "%s/mmt/point_20210821.dat", d && *d ? d : "../shared/data");
    snprintf(tp, n, "%s/mmt/k_and_e.dat", d && *d ? d : "../shared/data");
    return access(log, R_OK) == 0 && access(tp, R_OK) == 0;
}

static void fit_file(const char *path, char *out, size_t len)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s fit %s --order 1 --json 2>/dev/null", tu_pmfit_path(), path);
    ck_assert_int_eq(tu_capture(cmd, out, len), 0);
}

START_TEST(test_mmt_log_fits_as_its_tpoint_conversion)
{
    char log[4096], tp[4096], shifted[64], a[16384], b[16384], c[16384];
    FILE *in, *out;
    char line[512];
    int k;
    if (!mmt_paths(log, tp, sizeof log)) {
        fprintf(stderr, "check_formats: skipped the MMT log test (no %s)\n", log);
        return;
    }
    fit_file(log, a, sizeof a);
    fit_file(tp, b, sizeof b);
    /* the log with the conversion's -5.9" on the observed elevation */
    snprintf(shifted, sizeof shifted, "/tmp/pm_formats_mmt_%d.dat", (int)getpid());
    in = fopen(log, "r");
    out = fopen(shifted, "w");
    ck_assert(in && out);
    while (fgets(line, sizeof line, in)) {
        double el, az;
        if (strncmp(line, "TAA:", 4) == 0 && sscanf(line + 4, "%lf %lf", &el, &az) == 2)
            fprintf(out, "TAA: %.10f %.7f\n", el - 5.9 / 3600.0, az);
        else
            fputs(line, out);
    }
    fclose(in);
    fclose(out);
    fit_file(shifted, c, sizeof c);
    unlink(shifted);
    ck_assert_int_eq((int)tu_json_num(a, "n_obs"), 80);
    for (k = 0; k < 6; ++k) {
        double va = tu_term_value(a, kIso[k]), vb = tu_term_value(b, kIso[k]), vc = tu_term_value(c, kIso[k]);
        if (k == 4)
            ck_assert_msg(fabs((va - vb) + 5.9) < TOL_MMT_EL_OFFSET_AS, "e': log %.4f, TPOINT %.4f", va,
                          vb);
        else
            ck_assert_msg(fabs(va - vb) < TOL_MMT_SECOND_ORDER_AS, "%s: log %.4f, TPOINT %.4f",
                          kIso[k], va, vb);
        ck_assert_msg(fabs(vc - vb) < TOL_MMT_SAME_AS, "%s: shifted log %.5f, TPOINT %.5f", kIso[k],
                      vc, vb);
    }
    ck_assert(fabs(tu_json_num(c, "sigma_arcsec") - tu_json_num(b, "sigma_arcsec")) < TOL_MMT_SAME_AS);
}
END_TEST

static Suite *formats_suite(void)
{
    Suite *s = suite_create("formats");
    TCase *tc = tcase_create("detect");
    tcase_add_test(tc, test_pmrun_options_default_format_equinox);
    tcase_add_test(tc, test_pmrun_format_names_round_trip);
    tcase_add_test(tc, test_pmrun_read_detects_each_format);
    tcase_add_test(tc, test_pmrun_read_forced_format_is_used);
    tcase_add_test(tc, test_pmrun_read_forced_wrong_format_names_it);
    tcase_add_test(tc, test_pmrun_read_wrong_guess_names_the_format);
    suite_add_tcase(s, tc);
    tc = tcase_create("samples");
    tcase_add_test(tc, test_pmrun_read_rts2_same_as_source);
    tcase_add_test(tc, test_pmrun_read_rts2_j2000_reduced_with_equinox_option);
    tcase_add_test(tc, test_pmrun_read_mw4_same_as_source);
    tcase_add_test(tc, test_pmrun_read_csv_same_as_source);
    tcase_add_test(tc, test_pmrun_read_csv_sides_as_numbers);
    tcase_add_test(tc, test_pmrun_read_csv_excel_sep);
    tcase_add_test(tc, test_pmrun_read_tpoint_lst_seconds_noted);
    tcase_add_test(tc, test_pmrun_read_rts2_julian_dates);
    tcase_add_test(tc, test_pmrun_read_tpoint_altaz_without_option);
    tcase_add_test(tc, test_pmrun_read_csv_units_in_names);
    tcase_add_test(tc, test_pmrun_read_csv_time_without_zone);
    tcase_add_test(tc, test_pmrun_read_csv_equinox_option_overrides);
    tcase_add_test(tc, test_pmrun_read_equinox_refused_where_it_does_not_apply);
    tcase_add_test(tc, test_pmrun_read_mmt_same_as_source);
    suite_add_tcase(s, tc);
    tc = tcase_create("fit");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_sources_are_the_simulations_named);
    tcase_add_test(tc, test_pmfit_fits_rts2);
    tcase_add_test(tc, test_pmfit_fits_rts2_j2000);
    tcase_add_test(tc, test_pmfit_fits_rts2_altaz);
    tcase_add_test(tc, test_pmfit_fits_mw4);
    tcase_add_test(tc, test_pmfit_fits_csv_j2000);
    tcase_add_test(tc, test_pmfit_fits_csv_jnow);
    tcase_add_test(tc, test_pmfit_fits_mmt);
    tcase_add_test(tc, test_pmfit_format_option_errors);
    suite_add_tcase(s, tc);
    tc = tcase_create("errors");
    tcase_add_test(tc, test_pmrun_read_bad_rts2);
    tcase_add_test(tc, test_pmrun_read_bad_mw4);
    tcase_add_test(tc, test_pmrun_read_bad_csv);
    tcase_add_test(tc, test_pmrun_read_bad_mmt);
    tcase_add_test(tc, test_pmrun_read_csv_second_60);
    tcase_add_test(tc, test_pmrun_read_csv_header_lacking_column);
    tcase_add_test(tc, test_pmrun_read_dir_signed_zero);
    tcase_add_test(tc, test_pmrun_read_tpoint_comma_caption);
    tcase_add_test(tc, test_pmrun_read_pier_near_pole);
    tcase_add_test(tc, test_pmrun_read_skip_bad_lists_skipped);
    suite_add_tcase(s, tc);
    tc = tcase_create("realdata");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_mmt_log_fits_as_its_tpoint_conversion);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(formats_suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
