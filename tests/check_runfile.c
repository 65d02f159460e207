/*
**  check_runfile.c - tests of the pointing-run reader (tools/lib/runfile.h).
**
**  TCases: "formats" (the three formats and their conventions), "reduction"
**  (the ERFA reduction against tests/ref/runfile_reduction_ref.h, made by
**  tests/ref/runfile_reduction_ref.py, and the weather checks), "errors"
**  (every kind of bad input), "realdata" (the runs in $PM_DATA_DIR, skipped
**  when absent).  Small inputs live in tests/data/ ($PM_TOP/tests/data).
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <erfa.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "runfile.h"
#include "tu_runfile.h"
#include "tu_tool.h"
#include "ref/runfile_reduction_ref.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define ARCSEC (DEG / 3600.0)

/* Values parsed from text: exact but for the degree-to-radian rounding. */
#define TOL_PARSE_RAD 1e-12
/* Reduction against the independent ERFA reference (Python). */
#define TOL_REF_RAD 1e-9
#define TOL_REF_H 1e-9
/* Latitude of the MMT: the file's 31 41 19.6 is 31.688778 deg, 0.44 arcsec
** from the 31.6889 deg quoted for it. */
#define TOL_LAT_DEG 2e-4

/* ------------------------------------------------------------ helpers */

static void data_path(char *buf, size_t n, const char *name)
{
    const char *top = getenv("PM_TOP");
    snprintf(buf, n, "%s/tests/data/%s", top && *top ? top : ".", name);
}

/* Reads tests/data/<name> with the given options (NULL: defaults). */
static pmrun *read_ok(const char *name, const pmrun_options *opt)
{
    char path[4096], err[1024];
    pmrun *run = NULL;
    data_path(path, sizeof path, name);
    int st = pmrun_read(path, opt, &run, err, sizeof err);
    ck_assert_msg(st == PMRUN_OK, "%s: status %d: %s", name, st, err);
    ck_assert_ptr_nonnull(run);
    return run;
}

static void expect_error(const char *name, int line, const char *needle)
{
    char path[4096];
    data_path(path, sizeof path, name);
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, line, needle);
}

/* Index of the first warning containing both strings, -1 if none. */
static int find_warning(const pmrun *run, const char *a, const char *b)
{
    int i;
    for (i = 0; i < pmrun_n_warnings(run); ++i) {
        const char *w = pmrun_warning(run, i);
        if (strstr(w, a) && (!b || strstr(w, b))) return i;
    }
    return -1;
}

static const pmrun_obs *obs_at_line(const pmrun *run, int line)
{
    size_t i;
    for (i = 0; i < pmrun_count(run); ++i)
        if (pmrun_get(run, i)->line == line) return pmrun_get(run, i);
    return NULL;
}

static double wrap(double a) { return remainder(a, 2 * PI); }

/* A temporary file holding `n` bytes of `text`; the name goes to buf. */
static void temp_file(char *buf, size_t bufn, const char *text, size_t n)
{
    snprintf(buf, bufn, "/tmp/check_runfile_XXXXXX");
    int fd = mkstemp(buf);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "wb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fwrite(text, 1, n, f), n);
    ck_assert_int_eq(fclose(f), 0);
}

/* A temporary file: `head`, a line of `len` copies of `c`, then `tail`. */
static void temp_file_long(char *buf, size_t bufn, const char *head, char c, size_t len,
                           const char *tail)
{
    size_t nh = strlen(head), nt = strlen(tail);
    char *text = malloc(nh + len + 1 + nt);
    ck_assert_ptr_nonnull(text);
    memcpy(text, head, nh);
    memset(text + nh, c, len);
    text[nh + len] = '\n';
    memcpy(text + nh + len + 1, tail, nt);
    temp_file(buf, bufn, text, nh + len + 1 + nt);
    free(text);
}

/* ------------------------------------------------------------ formats */

START_TEST(test_pmrun_options_default_values)
{
    pmrun_options o;
    memset(&o, 0x5a, sizeof o);
    pmrun_options_default(&o);
    ck_assert_int_eq(o.refraction, 1);
    ck_assert_int_eq(o.skip_bad, 0);
    ck_assert(isnan(o.pressure_hpa));
    ck_assert(isnan(o.temp_c));
    ck_assert(isnan(o.humidity));
    ck_assert(isnan(o.wavelength_um));
    pmrun_options_default(NULL); /* no crash */
}
END_TEST

START_TEST(test_pmrun_read_four_column)
{
    pmrun *run = read_ok("four_column.dat", NULL);
    const pmrun_obs *o;
    pmrun_site site;
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_FOUR_COLUMN);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_EQUATORIAL);
    ck_assert_uint_eq(pmrun_count(run), 3);
    ck_assert_double_eq_tol(pmrun_latitude_rad(run), 47.9 * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(pmrun_n_aux(run), 0);
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    ck_assert_int_eq(pmrun_get_site(run, &site), PMRUN_OK);
    ck_assert_double_eq_tol(site.latitude_rad, 47.9 * DEG, TOL_PARSE_RAD);
    ck_assert(isnan(site.pressure_hpa) && isnan(site.temp_c) && isnan(site.height_m));
    ck_assert(isnan(site.humidity) && isnan(site.wavelength_um) && isnan(site.lapse_k_per_m));
    ck_assert_int_eq(site.year, 0);
    o = pmrun_get(run, 0);
    ck_assert_int_eq(o->line, 5);
    ck_assert_double_eq_tol(o->enc_ha, -30.5 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_dec, 45.25 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->app_ha, -30.4 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->app_dec, 45.2 * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(o->pier, PMRUN_PIER_EAST);
    ck_assert(isnan(o->temp_c) && isnan(o->time_h));
    ck_assert_int_eq(o->dir, 0);
    ck_assert(isnan(o->aux[0]));
    o = pmrun_get(run, 1); /* inline comment */
    ck_assert_int_eq(o->line, 6);
    ck_assert_double_eq_tol(o->app_dec, -10.05 * DEG, TOL_PARSE_RAD);
    o = pmrun_get(run, 2); /* encoder Dec 100: beyond the pole, kept as given */
    ck_assert_double_eq_tol(o->enc_dec, 100.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_ha, 170.0 * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(o->pier, PMRUN_PIER_WEST);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_named_columns)
{
    pmrun *run = read_ok("named.dat", NULL);
    const pmrun_obs *o;
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_NAMED);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_EQUATORIAL);
    ck_assert_uint_eq(pmrun_count(run), 3);
    ck_assert_double_eq_tol(pmrun_latitude_rad(run), -24.6 * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(pmrun_n_aux(run), 2);
    ck_assert_str_eq(pmrun_aux_name(run, 0), "focus");
    ck_assert_str_eq(pmrun_aux_name(run, 1), "rot_angle");
    ck_assert_ptr_null(pmrun_aux_name(run, 2));
    ck_assert_ptr_null(pmrun_aux_name(run, -1));
    /* "# site: test bench" is metadata the reader does not use */
    ck_assert_int_ge(find_warning(run, "named.dat:4:", "metadata 'site' accepted, not used"), 0);
    o = pmrun_get(run, 0);
    ck_assert_int_eq(o->line, 6);
    ck_assert_int_eq(o->pier, PMRUN_PIER_EAST);
    ck_assert_double_eq_tol(o->temp_c, 10.5, 1e-12);
    ck_assert_double_eq_tol(o->time_h, 20.25, 1e-12);
    ck_assert_int_eq(o->dir, 1);
    ck_assert_double_eq_tol(o->aux[0], 1.25, 1e-12);
    ck_assert_double_eq_tol(o->aux[1], 30.0, 1e-12);
    ck_assert(isnan(o->aux[2]));
    o = pmrun_get(run, 1); /* W, '-' for missing values */
    ck_assert_int_eq(o->pier, PMRUN_PIER_WEST);
    ck_assert(isnan(o->temp_c));
    ck_assert_int_eq(o->dir, -1);
    ck_assert(isnan(o->aux[0]) && isnan(o->aux[1]));
    o = pmrun_get(run, 2); /* pier -1, dir 0, trailing comment */
    ck_assert_int_eq(o->pier, PMRUN_PIER_WEST);
    ck_assert_int_eq(o->dir, 0);
    ck_assert_double_eq_tol(o->aux[1], -12.5, 1e-12);
    /* both sides, no encoder dec beyond 90: the W records are the sky
    ** position folded back, read as the mount's axes (HA + 180, -180 -
    ** dec), the file's values in enc_raw, and a note */
    ck_assert_double_eq_tol(o->enc_dec, -160.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_ha, -160.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_raw[1], -20.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_raw[0], 20.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(pmrun_get(run, 0)->enc_dec, 45.25 * DEG, TOL_PARSE_RAD);
    ck_assert_int_ge(find_warning(run, "named.dat:7:", "the W records are the sky position"), 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_named_altaz)
{
    pmrun *run = read_ok("named_altaz.dat", NULL);
    const pmrun_obs *o;
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_NAMED);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_ALTAZ);
    ck_assert(isnan(pmrun_latitude_rad(run)));
    ck_assert_uint_eq(pmrun_count(run), 2);
    o = pmrun_get(run, 1);
    /* encoder azimuth reduced into (-180, 180], the file's 270.5 kept */
    ck_assert_double_eq_tol(o->enc_ha, -89.5 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_raw[0], 270.5 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->app_ha, 270.48 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->app_dec, 30.01 * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(o->pier, PMRUN_PIER_UNKNOWN);
    ck_assert_double_eq_tol(o->temp_c, 11.5, 1e-12);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_tpoint_equatorial_fields)
{
    pmrun *run = read_ok("tpoint_equat.dat", NULL);
    const pmrun_obs *o;
    pmrun_site site;
    double lst, raw_ra;
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_TPOINT);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_EQUATORIAL);
    ck_assert_uint_eq(pmrun_count(run), 10);
    ck_assert_int_eq(pmrun_n_warnings(run), 0); /* :NODA and :EQUAT are known */
    ck_assert_double_eq_tol(pmrun_latitude_rad(run), (49 + 12 / 60.0 + 30 / 3600.0) * DEG,
                            TOL_PARSE_RAD);
    ck_assert_int_eq(pmrun_get_site(run, &site), PMRUN_OK);
    ck_assert_int_eq(site.year, 2024);
    ck_assert_int_eq(site.month, 3);
    ck_assert_int_eq(site.day, 15);
    ck_assert_double_eq_tol(site.temp_c, 5.5, 1e-12);
    ck_assert_double_eq_tol(site.pressure_hpa, 950.0, 1e-12);
    ck_assert_double_eq_tol(site.height_m, 500.0, 1e-12);
    ck_assert_double_eq_tol(site.humidity, 0.6, 1e-12);
    ck_assert_double_eq_tol(site.wavelength_um, 0.55, 1e-12);
    ck_assert_double_eq_tol(site.lapse_k_per_m, 0.0065, 1e-12);
    /* line 11: catalogue Dec "-00 24 00": the sign on "-00" counts */
    o = obs_at_line(run, 11);
    ck_assert_ptr_nonnull(o);
    ck_assert_double_eq_tol(o->enc_dec, -(21 / 60.0 + 30 / 3600.0) * DEG, TOL_PARSE_RAD);
    ck_assert_msg(o->app_dec < 0, "apparent Dec of a -00 24 star is %g", o->app_dec);
    ck_assert_int_eq(o->pier, PMRUN_PIER_EAST);
    ck_assert_double_eq_tol(o->temp_c, 5.5, 1e-12);
    /* encoder HA = LST - raw RA */
    lst = (23 + 59.740 / 60.0) * 15 * DEG;
    raw_ra = (23 + 29 / 60.0 + 29.4 / 3600.0) * 15 * DEG;
    ck_assert_double_eq_tol(o->enc_ha, wrap(lst - raw_ra), TOL_PARSE_RAD);
    /* line 17: raw Dec -155 02 30 is beyond the pole */
    o = obs_at_line(run, 17);
    ck_assert_double_eq_tol(o->enc_dec, -(155 + 2 / 60.0 + 30 / 3600.0) * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(o->pier, PMRUN_PIER_WEST);
    ck_assert_int_eq(pmrun_get(run, 0)->dir, 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_tpoint_altaz)
{
    pmrun *run = read_ok("tpoint_altaz.dat", NULL);
    const pmrun_obs *o;
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_TPOINT);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_ALTAZ); /* ": ALTAZ" with a space */
    ck_assert_uint_eq(pmrun_count(run), 3);
    ck_assert_double_eq_tol(pmrun_latitude_rad(run), (31 + 41 / 60.0 + 19.6 / 3600.0) * DEG,
                            TOL_PARSE_RAD);
    /* unknown option and text after END: warnings with file:line */
    ck_assert_int_ge(find_warning(run, "tpoint_altaz.dat:5:", "option :ALLSKY accepted, not used"),
                     0);
    ck_assert_int_ge(find_warning(run, "tpoint_altaz.dat:11:", "text after END ignored"), 0);
    ck_assert_int_ge(find_warning(run, "tpoint_altaz.dat:9:", "kept as auxiliary columns aux1..aux2"),
                     0);
    ck_assert_int_eq(pmrun_n_warnings(run), 3);
    /* azimuth from south through east -> from north through east */
    o = pmrun_get(run, 0);
    ck_assert_double_eq_tol(o->app_ha, (180.0 - 192.3860283 + 360.0) * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_ha, (180.0 + 167.2778909 - 360.0) * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_raw[0], (180.0 + 167.2778909) * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->app_dec, 77.3468410 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_dec, 77.3475476 * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(o->pier, PMRUN_PIER_UNKNOWN);
    ck_assert(isnan(o->time_h));
    ck_assert_double_eq_tol(o->temp_c, 13.0, 1e-12);
    o = pmrun_get(run, 1); /* east stays east */
    ck_assert_double_eq_tol(o->app_ha, 90.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_ha, 89.9 * DEG, TOL_PARSE_RAD);
    o = pmrun_get(run, 2); /* south: apparent in [0, 2pi), encoder in (-pi, pi] */
    ck_assert_double_eq_tol(o->app_ha, 180.0 * DEG, TOL_PARSE_RAD);
    ck_assert_double_eq_tol(o->enc_ha, -179.9 * DEG, TOL_PARSE_RAD);
    /* two extra readings: aux1, aux2 */
    ck_assert_int_eq(pmrun_n_aux(run), 2);
    ck_assert_str_eq(pmrun_aux_name(run, 0), "aux1");
    ck_assert_str_eq(pmrun_aux_name(run, 1), "aux2");
    ck_assert_double_eq_tol(o->aux[0], 1.5, 1e-12);
    ck_assert_double_eq_tol(o->aux[1], -2.25, 1e-12);
    ck_assert(isnan(pmrun_get(run, 0)->aux[0]));
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_crlf_same_as_lf)
{
    char path[4096], tmp[64], err[512];
    FILE *f;
    char *text, *crlf;
    long n, i, k = 0;
    pmrun *a, *b;
    size_t j;
    data_path(path, sizeof path, "tpoint_equat.dat");
    f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    text = malloc((size_t)n);
    crlf = malloc(2 * (size_t)n);
    ck_assert_uint_eq(fread(text, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    for (i = 0; i < n; ++i) {
        if (text[i] == '\n') crlf[k++] = '\r';
        crlf[k++] = text[i];
    }
    temp_file(tmp, sizeof tmp, crlf, (size_t)k);
    ck_assert_int_eq(pmrun_read(path, NULL, &a, err, sizeof err), PMRUN_OK);
    ck_assert_int_eq(pmrun_read(tmp, NULL, &b, err, sizeof err), PMRUN_OK);
    unlink(tmp);
    ck_assert_uint_eq(pmrun_count(a), pmrun_count(b));
    for (j = 0; j < pmrun_count(a); ++j) {
        const pmrun_obs *p = pmrun_get(a, j), *q = pmrun_get(b, j);
        ck_assert(p->enc_ha == q->enc_ha && p->enc_dec == q->enc_dec);
        ck_assert(p->app_ha == q->app_ha && p->app_dec == q->app_dec);
        ck_assert(p->time_h == q->time_h && p->temp_c == q->temp_c);
        ck_assert(p->pier == q->pier && p->dir == q->dir && p->line == q->line);
    }
    pmrun_free(a);
    pmrun_free(b);
    free(text);
    free(crlf);
}
END_TEST

START_TEST(test_pmrun_get_out_of_range)
{
    pmrun *run = read_ok("four_column.dat", NULL);
    pmrun_site site;
    ck_assert_ptr_null(pmrun_get(run, 3));
    ck_assert_ptr_null(pmrun_warning(run, 0));
    ck_assert_ptr_null(pmrun_skipped(run, 0));
    ck_assert_int_eq(pmrun_n_skipped(run), 0);
    /* NULL runs are safe */
    ck_assert_uint_eq(pmrun_count(NULL), 0);
    ck_assert_ptr_null(pmrun_get(NULL, 0));
    ck_assert_int_eq(pmrun_mount(NULL), -1);
    ck_assert_int_eq(pmrun_format(NULL), -1);
    ck_assert(isnan(pmrun_latitude_rad(NULL)));
    ck_assert_int_eq(pmrun_n_aux(NULL), 0);
    ck_assert_int_eq(pmrun_n_warnings(NULL), 0);
    ck_assert_int_eq(pmrun_get_site(NULL, &site), PMRUN_ERR_ARG);
    ck_assert_int_eq(pmrun_get_site(run, NULL), PMRUN_ERR_ARG);
    pmrun_free(NULL);
    pmrun_free(run);
}
END_TEST

/* ---------------------------------------------------------- reduction */

START_TEST(test_pmrun_read_reduction_matches_erfa)
{
    char path[4096];
    size_t i;
    pmrun_options norefr;
    pmrun_options_default(&norefr);
    norefr.refraction = 0;
    for (i = 0; i < RUNFILE_REF_N; ++i) {
        const runfile_ref_row *r = &RUNFILE_REF[i];
        pmrun *a, *b;
        const pmrun_obs *o, *u;
        const char *name = strrchr(r->file, '/') + 1;
        a = read_ok(name, NULL);
        b = read_ok(name, &norefr);
        o = obs_at_line(a, r->line);
        u = obs_at_line(b, r->line);
        data_path(path, sizeof path, name);
        ck_assert_msg(o && u, "%s:%d: no record", path, r->line);
        ck_assert_double_eq_tol(o->time_h, r->time_h, TOL_REF_H);
        ck_assert_double_eq_tol(wrap(o->enc_ha - r->enc_ha), 0.0, TOL_REF_RAD);
        ck_assert_double_eq_tol(o->enc_dec, r->enc_dec, TOL_REF_RAD);
        ck_assert_double_eq_tol(wrap(o->app_ha - r->app_ha), 0.0, TOL_REF_RAD);
        ck_assert_double_eq_tol(o->app_dec, r->app_dec, TOL_REF_RAD);
        ck_assert_double_eq_tol(wrap(u->app_ha - r->app_ha_norefr), 0.0, TOL_REF_RAD);
        ck_assert_double_eq_tol(u->app_dec, r->app_dec_norefr, TOL_REF_RAD);
        ck_assert_double_eq_tol(u->time_h, r->time_h, TOL_REF_H);
        pmrun_free(a);
        pmrun_free(b);
    }
}
END_TEST

/* Refraction lifts the star: at 15.8 deg elevation by about 3.3 arcmin
** (950 hPa, 5.5 C), along the vertical only. */
START_TEST(test_pmrun_read_refraction_lifts_star)
{
    pmrun_options o;
    pmrun *a, *b;
    double lat, az1, el1, az0, el0;
    const pmrun_obs *p, *q;
    pmrun_options_default(&o);
    a = read_ok("tpoint_equat.dat", &o);
    o.refraction = 0;
    b = read_ok("tpoint_equat.dat", &o);
    lat = pmrun_latitude_rad(a);
    p = obs_at_line(a, 12);
    q = obs_at_line(b, 12);
    eraHd2ae(p->app_ha, p->app_dec, lat, &az1, &el1);
    eraHd2ae(q->app_ha, q->app_dec, lat, &az0, &el0);
    ck_assert_msg(el0 > 15.0 * DEG && el0 < 16.5 * DEG, "elevation %g deg", el0 / DEG);
    ck_assert_msg(el1 - el0 > 170 * ARCSEC && el1 - el0 < 230 * ARCSEC, "refraction %g arcsec",
                  (el1 - el0) / ARCSEC);
    ck_assert_double_eq_tol(wrap(az1 - az0), 0.0, 1e-9);
    /* the encoder side is untouched */
    ck_assert(p->enc_ha == q->enc_ha);
    ck_assert(p->enc_dec == q->enc_dec);
    pmrun_free(a);
    pmrun_free(b);
}
END_TEST

/* Refraction scales with pressure: half the pressure, half the lift. */
START_TEST(test_pmrun_read_pressure_override)
{
    pmrun_options o;
    pmrun *full, *half, *none;
    double lat, az, e_full, e_half, e_none;
    pmrun_site site;
    pmrun_options_default(&o);
    full = read_ok("tpoint_equat.dat", &o);
    o.pressure_hpa = 475.0;
    half = read_ok("tpoint_equat.dat", &o);
    o.refraction = 0;
    none = read_ok("tpoint_equat.dat", &o);
    ck_assert_int_eq(pmrun_get_site(half, &site), PMRUN_OK);
    ck_assert(site.pressure_hpa == 475.0);
    /* 475 hPa at 500 m is implausible: warned about, not refused */
    ck_assert_int_ge(find_warning(half, "tpoint_equat.dat:8:", "pressure_hpa option"), 0);
    lat = pmrun_latitude_rad(full);
    eraHd2ae(obs_at_line(full, 13)->app_ha, obs_at_line(full, 13)->app_dec, lat, &az, &e_full);
    eraHd2ae(obs_at_line(half, 13)->app_ha, obs_at_line(half, 13)->app_dec, lat, &az, &e_half);
    eraHd2ae(obs_at_line(none, 13)->app_ha, obs_at_line(none, 13)->app_dec, lat, &az, &e_none);
    ck_assert_double_eq_tol((e_half - e_none) / (e_full - e_none), 0.5, 0.01);
    pmrun_free(full);
    pmrun_free(half);
    pmrun_free(none);
}
END_TEST

START_TEST(test_pmrun_read_humidity_percent_converted)
{
    pmrun *run = read_ok("tpoint_south.dat", NULL);
    pmrun_site site;
    ck_assert_int_ge(find_warning(run, "tpoint_south.dat:7:", "humidity 45 taken as percent: 0.45"),
                     0);
    ck_assert_int_ge(find_warning(run, "tpoint_south.dat:7:", "no wavelength"), 0);
    ck_assert_int_eq(pmrun_get_site(run, &site), PMRUN_OK);
    ck_assert_double_eq_tol(site.humidity, 0.45, 1e-15);
    ck_assert(isnan(site.wavelength_um));
    ck_assert(isnan(site.lapse_k_per_m));
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_pressure_mmhg_warns)
{
    pmrun *run = read_ok("tpoint_mmhg.dat", NULL);
    ck_assert_int_ge(find_warning(run, "tpoint_mmhg.dat:3:", "looks like mmHg"), 0);
    ck_assert_int_ge(find_warning(run, "tpoint_mmhg.dat:3:", "-25%"), 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_pressure_absurd)
{
    char path[4096];
    pmrun_options o;
    pmrun *run;
    data_path(path, sizeof path, "tpoint_pressure_absurd.dat");
    /* refraction requested: an error */
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 3, "pressure 5000 mbar is absurd");
    /* no refraction: only a warning */
    pmrun_options_default(&o);
    o.refraction = 0;
    run = read_ok("tpoint_pressure_absurd.dat", &o);
    ck_assert_int_ge(find_warning(run, "tpoint_pressure_absurd.dat:3:", "absurd"), 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_weather_implausible_warns)
{
    pmrun *run = read_ok("tpoint_weather.dat", NULL);
    ck_assert_int_ge(find_warning(run, "tpoint_weather.dat:3:", "temperature 80 C is implausible"),
                     0);
    ck_assert_int_ge(find_warning(run, "tpoint_weather.dat:3:", "wavelength 40 um is outside"), 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_missing_weather_defaults)
{
    pmrun *run = read_ok("tpoint_nomet.dat", NULL);
    pmrun_options o;
    ck_assert_int_eq(pmrun_n_warnings(run), 4);
    ck_assert_int_ge(find_warning(run, "tpoint_nomet.dat:3:", "no pressure"), 0);
    ck_assert_int_ge(find_warning(run, "tpoint_nomet.dat:3:", "no temperature"), 0);
    ck_assert_int_ge(find_warning(run, "tpoint_nomet.dat:3:", "no humidity"), 0);
    ck_assert_int_ge(find_warning(run, "tpoint_nomet.dat:3:", "no wavelength"), 0);
    ck_assert(isnan(pmrun_get(run, 0)->temp_c));
    pmrun_free(run);
    /* without refraction nothing is missing */
    pmrun_options_default(&o);
    o.refraction = 0;
    run = read_ok("tpoint_nomet.dat", &o);
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_below_horizon_warns)
{
    pmrun *run = read_ok("tpoint_horizon.dat", NULL);
    ck_assert_uint_eq(pmrun_count(run), 1);
    ck_assert_int_ge(find_warning(run, "tpoint_horizon.dat:6:", "star below the horizon"), 0);
    ck_assert_int_ge(find_warning(run, "tpoint_horizon.dat:5:", "outside ERFA's leap-second table"),
                     0);
    pmrun_free(run);
}
END_TEST

/* ------------------------------------------------------------- errors */

START_TEST(test_pmrun_read_null_args)
{
    char err[256];
    pmrun *run = (pmrun *)err;
    ck_assert_int_eq(pmrun_read(NULL, NULL, &run, err, sizeof err), PMRUN_ERR_ARG);
    ck_assert_ptr_null(run);
    ck_assert(strstr(err, "NULL") != NULL);
    ck_assert_int_eq(pmrun_read("x.dat", NULL, NULL, err, sizeof err), PMRUN_ERR_ARG);
    /* err may be NULL */
    ck_assert_int_eq(pmrun_read("/nonexistent/x.dat", NULL, &run, NULL, 0), PMRUN_ERR_IO);
}
END_TEST

START_TEST(test_pmrun_read_missing_file)
{
    tu_read_fails("/nonexistent/run.dat", NULL, PMRUN_ERR_IO, 0, "cannot open");
}
END_TEST

START_TEST(test_pmrun_read_directory)
{
    char path[4096];
    data_path(path, sizeof path, "");
    tu_read_fails(path, NULL, PMRUN_ERR_IO, 1, "read error");
}
END_TEST

/* A decimal comma (a European locale's writing) is named as such, with
** the number as it should read, in a four-column file and in a ';' CSV
** (an outside probe's CSV was told "not an angle"). */
START_TEST(test_pmrun_read_decimal_comma)
{
    static const char four[] = "# latitude: 40\n10.0 20.0 10.1 20.1\n10,5 20 10.6 20.1\n";
    static const char csv[] = "# longitude: 19.0\n# latitude: 47.0\n# equinox: JNow\n"
                              "MountRA;MountDec;SolvedRA;SolvedDec;PierSide;Time\n"
                              "10,1650125;20,5;10,166;20,51;pierEast;2024-03-01T20:00:00Z\n";
    char tmp[64];
    temp_file(tmp, sizeof tmp, four, sizeof four - 1);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 3, "'10,5': a decimal comma? expected a decimal point ('10.5')");
    unlink(tmp);
    temp_file(tmp, sizeof tmp, csv, sizeof csv - 1);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 5, "a decimal comma? expected a decimal point ('10.1650125')");
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_too_many_records)
{
    static const char rec[] = "0 0 0 0\n";
    size_t n = (size_t)PMRUN_MAX_RECORDS + 1, i, k = sizeof rec - 1;
    char *text = malloc(n * k), tmp[64];
    ck_assert_ptr_nonnull(text);
    for (i = 0; i < n; ++i) memcpy(text + i * k, rec, k);
    temp_file(tmp, sizeof tmp, text, n * k);
    free(text);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, PMRUN_MAX_RECORDS + 1, "more than");
    unlink(tmp);
}
END_TEST

/* Out of memory: the address space of this (forked) test is limited to a
** few MiB more than it uses, then 200000 records do not fit. */
START_TEST(test_pmrun_read_out_of_memory)
{
    static const char rec[] = "0 0 0 0\n";
    size_t n = 200000, i, k = sizeof rec - 1;
    char *text, tmp[64];
    unsigned long pages = 0;
    struct rlimit rl;
    FILE *f;
    const char *fork_env = getenv("CK_FORK");
    if (fork_env && strcmp(fork_env, "no") == 0) {
        printf("skipped: out-of-memory test needs Check's fork mode\n");
        return;
    }
#ifdef __SANITIZE_ADDRESS__
    /* AddressSanitizer maps terabytes of shadow memory and dies when an
    ** allocation fails, so an address-space limit cannot be tested under it. */
    printf("skipped: out-of-memory test under AddressSanitizer (make sanitize)\n");
    return;
#endif
    text = malloc(n * k);
    ck_assert_ptr_nonnull(text);
    for (i = 0; i < n; ++i) memcpy(text + i * k, rec, k);
    temp_file(tmp, sizeof tmp, text, n * k);
    free(text);
    f = fopen("/proc/self/statm", "r");
    if (!f || fscanf(f, "%lu", &pages) != 1) {
        printf("skipped: /proc/self/statm absent\n");
        if (f) fclose(f);
        unlink(tmp);
        return;
    }
    fclose(f);
    ck_assert_int_eq(getrlimit(RLIMIT_AS, &rl), 0);
    rl.rlim_cur = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + ((rlim_t)8 << 20);
    ck_assert_int_eq(setrlimit(RLIMIT_AS, &rl), 0);
    tu_read_fails(tmp, NULL, PMRUN_ERR_NOMEM, 0, "out of memory");
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_error_truncated)
{
    char path[4096], err[16];
    pmrun *run;
    data_path(path, sizeof path, "bad_nan.dat");
    ck_assert_int_eq(pmrun_read(path, NULL, &run, err, sizeof err), PMRUN_ERR_FORMAT);
    ck_assert_uint_eq(strlen(err), sizeof err - 1);
}
END_TEST

START_TEST(test_pmrun_read_empty_file) { expect_error("bad_empty.dat", 0, "empty file"); }
END_TEST

START_TEST(test_pmrun_read_blank_file) { expect_error("bad_blank.dat", 3, "only blank lines"); }
END_TEST

START_TEST(test_pmrun_read_comments_only) { expect_error("bad_comments_only.dat", 3, "no records"); }
END_TEST

START_TEST(test_pmrun_read_tpoint_no_records)
{
    expect_error("bad_tpoint_no_records.dat", 4, "no records after the run line (line 3)");
}
END_TEST

START_TEST(test_pmrun_read_tpoint_no_run_line)
{
    expect_error("bad_tpoint_no_runline.dat", 3, "no run line");
}
END_TEST

START_TEST(test_pmrun_read_too_few_fields_tpoint)
{
    expect_error("bad_eq_few_fields.dat", 4, "13 fields, expected 14");
}
END_TEST

START_TEST(test_pmrun_read_too_few_fields_four_column)
{
    expect_error("bad_four_few_fields.dat", 2, "3 fields, expected 4: tau delta T D");
}
END_TEST

START_TEST(test_pmrun_read_too_few_fields_named)
{
    expect_error("bad_named_fields.dat", 3, "4 fields, expected 5: tau delta T D temp");
}
END_TEST

START_TEST(test_pmrun_read_non_numeric_field)
{
    expect_error("bad_non_numeric.dat", 4, "field 2 (RA minutes) '3O': not a number");
}
END_TEST

START_TEST(test_pmrun_read_nan_text) { expect_error("bad_nan.dat", 2, "'nan': NaN/Inf is not accepted"); }
END_TEST

START_TEST(test_pmrun_read_inf_text)
{
    expect_error("bad_inf.dat", 4, "field 9 (raw RA seconds) '-Inf': NaN/Inf is not accepted");
}
END_TEST

START_TEST(test_pmrun_read_number_overflow)
{
    expect_error("bad_overflow.dat", 2, "'1e999': number out of range");
}
END_TEST

START_TEST(test_pmrun_read_minutes_ge_60)
{
    expect_error("bad_minutes.dat", 4, "'60': out of range, expected 0 <= minutes < 60");
}
END_TEST

START_TEST(test_pmrun_read_seconds_ge_60)
{
    expect_error("bad_seconds.dat", 4, "'60.5': out of range, expected 0 <= seconds < 60");
}
END_TEST

START_TEST(test_pmrun_read_signed_minutes)
{
    expect_error("bad_sign_minutes.dat", 4, "'-36': expected an unsigned number");
}
END_TEST

START_TEST(test_pmrun_read_ra_hours_ge_24)
{
    expect_error("bad_ra_hours.dat", 4, "field 1 (RA hours) '24': out of range");
}
END_TEST

START_TEST(test_pmrun_read_catalogue_dec_beyond_90)
{
    expect_error("bad_cat_dec.dat", 4, "catalogue Dec +90 30 00.000 is beyond +-90 deg");
}
END_TEST

/* A raw Dec beyond 180 deg (a controller writing 0..360) is the same
** reading as 360 deg less: +180 30 00 is -179 30 00, beyond the pole. */
START_TEST(test_pmrun_read_raw_dec_beyond_180)
{
    pmrun *run = read_ok("tpoint_raw_dec_360.dat", NULL);
    const pmrun_obs *o = pmrun_get(run, 0);
    ck_assert_uint_eq(pmrun_count(run), 2);
    ck_assert(o->enc_dec == -(179 + 30 / 60.0) * DEG);
    ck_assert_double_eq_tol(o->enc_raw[1], (180 + 30 / 60.0) * DEG, TOL_PARSE_RAD);
    ck_assert_int_eq(o->pier, PMRUN_PIER_WEST);
    /* raw RA 25 h (line 5) is 1 h (line 6): the same encoder HA */
    ck_assert(pmrun_get(run, 1)->enc_ha == o->enc_ha);
    ck_assert(pmrun_get(run, 1)->enc_dec == o->enc_dec);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_latitude_beyond_90_tpoint)
{
    expect_error("bad_latitude.dat", 3, "latitude +95 00 00 is beyond +-90 deg");
}
END_TEST

START_TEST(test_pmrun_read_latitude_beyond_90_named)
{
    expect_error("bad_named_latitude.dat", 1, "latitude 95 deg is beyond +-90");
}
END_TEST

START_TEST(test_pmrun_read_altaz_elevation_beyond_90_tpoint)
{
    expect_error("bad_altaz_el.dat", 4, "field 2 (observed elevation) '91.5': elevation beyond");
}
END_TEST

/* An alt-az encoder elevation is modular too: 95 deg is over the zenith
** (the core's far side), 370 deg is 10 deg; the observed one is not. */
START_TEST(test_pmrun_read_altaz_elevation_beyond_90_named)
{
    pmrun *run = read_ok("named_altaz_el_modular.dat", NULL);
    ck_assert_uint_eq(pmrun_count(run), 2);
    ck_assert_double_eq_tol(pmrun_get(run, 0)->enc_dec, 95.0 * DEG, TOL_PARSE_RAD);
    ck_assert(pmrun_get(run, 1)->enc_dec == 10.0 * DEG);
    ck_assert(pmrun_get(run, 1)->enc_ha == -170.0 * DEG);
    ck_assert_int_eq(pmrun_get(run, 0)->pier, PMRUN_PIER_UNKNOWN);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_run_line_without_date)
{
    expect_error("bad_no_date.dat", 3, "run line has no date");
}
END_TEST

START_TEST(test_pmrun_read_run_line_incomplete_date)
{
    expect_error("bad_incomplete_date.dat", 3, "incomplete date");
}
END_TEST

START_TEST(test_pmrun_read_run_line_without_latitude)
{
    expect_error("bad_short_runline.dat", 3, "run line has 2 fields, expected at least 3");
}
END_TEST

START_TEST(test_pmrun_read_invalid_date) { expect_error("bad_date.dat", 3, "2023 13 1 is not a valid date"); }
END_TEST

/* the run line's date 2021 8 21 written 21 8 21 */
static int edit_two_digit_year(char *line, size_t size, void *arg)
{
    char *y = strstr(line, " 2021 8 21 ");
    (void)size;
    (void)arg;
    if (y)
        memmove(y + 1, y + 3, strlen(y + 3) + 1); /* 2021 -> 21 */
    return 1;
}

/* 23 for 2023 was read as 23 AD: 2,000 years of precession (an outside probe);
** an alt-az file's records are not reduced: its year is not checked */
START_TEST(test_pmrun_read_two_digit_year)
{
    char src[4096], path[64], err[512];
    pmrun *run = NULL;
    expect_error("bad_year_two_digits.dat", 3, "expected the year in full (2023, not 23)");
    data_path(src, sizeof src, "tpoint_altaz.dat");
    strcpy(path, "/tmp/check_runfile_XXXXXX");
    tu_edited_copy(src, path, edit_two_digit_year, NULL);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    pmrun_free(run);
    remove(path);
}
END_TEST

/* A time column of clock hours that passes midnight is continued past 24 h
** with a note naming the line (a drift was read with the wrong sign and a
** sixth of its size: an outside probe); times that step back otherwise
** are read as given, with a note. */
START_TEST(test_pmrun_read_time_past_midnight)
{
    static const char wrapped[] = "# tau delta T D time\n"
                                  "10 20 10.1 20.1 23.50\n"
                                  "20 30 20.1 30.1 23.90\n"
                                  "30 40 30.1 40.1 0.25\n"
                                  "40 50 40.1 50.1 0.25\n"
                                  "50 60 50.1 60.1 1.75\n";
    static const char unordered[] = "# tau delta T D time\n"
                                    "10 20 10.1 20.1 23.50\n"
                                    "20 30 20.1 30.1 0.10\n"
                                    "30 40 30.1 40.1 23.70\n";
    static const char continued[] = "# tau delta T D time\n"
                                    "10 20 10.1 20.1 23.50\n"
                                    "20 30 20.1 30.1 24.10\n";
    char path[64], err[512];
    pmrun *run = NULL;
    temp_file(path, sizeof path, wrapped, sizeof wrapped - 1);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_double_eq(pmrun_get(run, 1)->time_h, 23.90);
    ck_assert_double_eq(pmrun_get(run, 2)->time_h, 24.25);
    ck_assert_double_eq(pmrun_get(run, 3)->time_h, 24.25);
    ck_assert_double_eq(pmrun_get(run, 4)->time_h, 25.75);
    ck_assert_int_ge(find_warning(run, ":4:", "passing midnight"), 0);
    pmrun_free(run);
    remove(path);
    temp_file(path, sizeof path, unordered, sizeof unordered - 1);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_double_eq(pmrun_get(run, 1)->time_h, 0.10);
    ck_assert_double_eq(pmrun_get(run, 2)->time_h, 23.70);
    ck_assert_int_ge(find_warning(run, ":3:", "read as given"), 0);
    pmrun_free(run);
    remove(path);
    /* a time of 23:59:53 written 24.00; a clock set back a minute; newest first */
    {
        static const char edge[] = "# tau delta T D time\n"
                                   "10 20 10.1 20.1 23.50\n"
                                   "20 30 20.1 30.1 24.00\n"
                                   "30 40 30.1 40.1 23.98\n"
                                   "40 50 40.1 50.1 0.25\n";
        static const char newest[] = "# tau delta T D time\n"
                                     "10 20 10.1 20.1 1.50\n"
                                     "20 30 20.1 30.1 0.25\n"
                                     "30 40 30.1 40.1 23.75\n"
                                     "40 50 40.1 50.1 22.00\n";
        temp_file(path, sizeof path, edge, sizeof edge - 1);
        ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
        ck_assert_double_eq(pmrun_get(run, 1)->time_h, 24.00);
        ck_assert_double_eq(pmrun_get(run, 3)->time_h, 24.25);
        ck_assert_int_ge(find_warning(run, ":5:", "passing midnight"), 0);
        pmrun_free(run);
        remove(path);
        temp_file(path, sizeof path, newest, sizeof newest - 1);
        ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
        ck_assert_double_eq(pmrun_get(run, 0)->time_h, 25.50);
        ck_assert_double_eq(pmrun_get(run, 1)->time_h, 24.25);
        ck_assert_double_eq(pmrun_get(run, 2)->time_h, 23.75);
        ck_assert_int_ge(find_warning(run, ":4:", "newest first"), 0);
        pmrun_free(run);
        remove(path);
    }
    temp_file(path, sizeof path, continued, sizeof continued - 1); /* beyond 24: as given */
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_double_eq(pmrun_get(run, 1)->time_h, 24.10);
    ck_assert_int_lt(find_warning(run, "time:", NULL), 0);
    pmrun_free(run);
    remove(path);
}
END_TEST

/* A pier column that names the sides the other way round from the encoder
** (E records beyond the pole, W within) is read by the encoder, with a
** note; E and W both beyond the pole is refused (an outside probe: --pier
** split's "east" model was the beyond-the-pole records'). */
START_TEST(test_pmrun_read_pier_other_way_round)
{
    static const char swapped[] = "# tau delta T D pier\n"
                                  "190 110 10.1 70.1 E\n"
                                  "20 30 20.1 30.1 W\n"
                                  "200 120 20.1 60.1 E\n";
    static const char both[] = "# tau delta T D pier\n"
                               "190 110 10.1 70.1 E\n"
                               "200 120 20.1 60.1 W\n";
    char path[64], err[512];
    pmrun *run = NULL;
    temp_file(path, sizeof path, swapped, sizeof swapped - 1);
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_int_eq(pmrun_get(run, 0)->pier, PMRUN_PIER_WEST);
    ck_assert_int_eq(pmrun_get(run, 1)->pier, PMRUN_PIER_EAST);
    ck_assert_int_eq(pmrun_get(run, 2)->pier, PMRUN_PIER_WEST);
    ck_assert_int_ge(find_warning(run, ":2:", "other way round"), 0);
    pmrun_free(run);
    remove(path);
    temp_file(path, sizeof path, both, sizeof both - 1);
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 3, "does not follow the encoder");
    remove(path);
    {   /* W only, within +-90: the run cannot say which is right; said */
        static const char w_only[] = "# tau delta T D pier\n"
                                     "20 30 20.1 30.1 W\n"
                                     "40 10 40.1 10.1 W\n";
        temp_file(path, sizeof path, w_only, sizeof w_only - 1);
        ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
        ck_assert_int_eq(pmrun_get(run, 0)->pier, PMRUN_PIER_WEST);
        ck_assert_int_ge(find_warning(run, ":2:", "every record is pier W"), 0);
        pmrun_free(run);
        remove(path);
    }
}
END_TEST

/* Four numbers under a line of words are read as TPOINT (the words its
** caption): the error says so and how to mark a column header (it spoke of
** a latitude's whole degrees only: an outside probe). */
START_TEST(test_pmrun_read_header_without_hash)
{
    static const char text[] = "tau delta T D\n"
                               "-147.540642059 -162.103582003 32.487047222 -17.894317317\n";
    char path[64];
    temp_file(path, sizeof path, text, sizeof text - 1);
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 2, "start its header with '#' ('# tau delta T D'");
    remove(path);
}
END_TEST

/* An angle beyond +-2^31 (degrees or hours) is refused where it is read:
** fmod had reduced 1e300 exactly to a direction the file never gave, and
** the run was read without a word (an outside probe).  2^31 itself is an
** angle in some turn; gpoint's axis counts are not angles. */
static void read_text_fails(const char *text, int line, const char *needle)
{
    char path[64];
    temp_file(path, sizeof path, text, strlen(text));
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, line, needle);
    remove(path);
}

static pmrun *read_text(const char *text)
{
    char path[64], err[512];
    pmrun *run = NULL;
    temp_file(path, sizeof path, text, strlen(text));
    int st = pmrun_read(path, NULL, &run, err, sizeof err);
    ck_assert_msg(st == PMRUN_OK, "%s", err);
    remove(path);
    return run;
}

START_TEST(test_pmrun_read_angle_beyond_turns)
{
    static const char *const big[] = {"1e300", "-1e10", "2147483648.5"};
    char text[512];
    int k;
    for (k = 0; k < 3; ++k) {
        snprintf(text, sizeof text, "# tau delta T D\n10 20 10 20\n%s 20 10 20\n", big[k]);
        read_text_fails(text, 3, "field 1 (tau)");
        read_text_fails(text, 3, "is beyond +-2^31 (2147483648): a corrupt value?");
        snprintf(text, sizeof text, "# tau delta T D\n10 20 10 20\n10 20 %s 20\n", big[k]);
        read_text_fails(text, 3, "field 3 (T)");
        snprintf(text, sizeof text, "# tau delta T D\n10 20 10 20\n10 %s 10 20\n", big[k]);
        read_text_fails(text, 3, "field 2 (delta)");
    }
    /* CSV (a sexagesimal field): the mount declination */
    read_text_fails("# equinox: JNow\n# refraction: no\n"
                    "LST,Mount RA,Mount Dec,Solved RA,Solved Dec,Pier Side\n"
                    "8.8607141587,2.7584324228,-1e300,2.7555217120,63.975098125,pierWest\n",
                    4, "field 3 (mount Dec)");
    read_text_fails("# equinox: JNow\n# refraction: no\n"
                    "LST,Mount RA,Mount Dec,Solved RA,Solved Dec,Pier Side\n"
                    "8.8607141587,2.7584324228,-2147483649:00:00,2.7555217120,63.975098125,pierWest\n",
                    4, "is beyond +-2^31");
    /* TPOINT equatorial: the raw RA's hours, the raw Dec's degrees */
    read_text_fails("Bad input test run\n:EQUAT\n+39 00 25 2023 9 1 21.70 992.00 228.00 0.96 0.5500 "
                    "0.0065\n12 00 00.0000 +77 47 53.139 1e300 04 46.8191 +77 36 25.053  22 41.127\n",
                    4, "field 7");
    read_text_fails("Bad input test run\n:EQUAT\n+39 00 25 2023 9 1 21.70 992.00 228.00 0.96 0.5500 "
                    "0.0065\n12 00 00.0000 +77 47 53.139 18 04 46.8191 -1e300 36 25.053  22 41.127\n",
                    4, "field 10");
    /* MMT: the raw (RAA) and observed (TAA) azimuths */
    read_text_fails("CAT: FK5-0711        18:55:20.111 +43:56:45.99 +00.214 +008.25  3.9  M3  J2000.0\n"
                    "RAA:   77.3475476  1e300\nTAA:   77.3484799  -12.3860283\nLST: 19:11:22.950\n",
                    2, "RAA: azimuth '1e300'");
    read_text_fails("CAT: FK5-0711        18:55:20.111 +43:56:45.99 +00.214 +008.25  3.9  M3  J2000.0\n"
                    "RAA:   77.3475476  347.2778909\nTAA:   77.3484799  -3e9\nLST: 19:11:22.950\n",
                    3, "TAA: azimuth '-3e9'");
    /* TPOINT alt-az: the raw azimuth */
    read_text_fails("Alt-az\n: ALTAZ\n+31 41 19.6 2021 8 21 13.0 741 2608.0 0.75\n"
                    "90.0 45.0 1e300 45.02\nEND\n",
                    4, "field 3");
    /* RTS2: the mount RA, but not the axis counts */
    static const char rts2_head[] =
        "#  Observation\t  MJD\t   LST-MNT RA-MNT   DEC-MNT   AXRA\t  AXDEC   RA-TRUE  DEC-TRUE\n"
        "#observatory 19.0 47.0 500\n";
    snprintf(text, sizeof text,
             "%s02a60384e0001o 60384.83333333 132.9107124 1e300 116.026230884 -1055437 1384246 "
             "41.332825681 63.975098125\n",
             rts2_head);
    read_text_fails(text, 3, "field 4 (RA-MNT)");
    snprintf(text, sizeof text,
             "%s02a60384e0001o 60384.83333333 132.9107124 221.376486342 116.026230884 "
             "-1055437000000 1384246 41.332825681 63.975098125\n",
             rts2_head);
    pmrun *run = read_text(text);
    ck_assert_uint_eq(pmrun_count(run), 1);
    pmrun_free(run);
    /* 2^31 deg is 5965232 turns and 128 deg: read as that angle */
    run = read_text("# tau delta T D\n2147483648 20 -2147483648 20\n");
    const pmrun_obs *o = pmrun_get(run, 0);
    ck_assert_double_eq_tol(o->enc_ha / DEG, 128.0, 1e-9);
    ck_assert_double_eq_tol(o->app_ha / DEG, -128.0, 1e-9);
    pmrun_free(run);
}
END_TEST

/* A record on a last line without a line end whose last number has fewer
** decimals than the line before's is read, with a note: a file cut short
** reads its last number short (an outside probe's truncated run was read
** silently).  One as long as the line before's, a last line that is not a
** record, a terminated one and MW4's JSON (which ends without a line end as
** a rule) get no note. */
START_TEST(test_pmrun_read_unterminated_last_record)
{
    pmrun *run = read_text("# tau delta T D\n10 20 10.001 20.002\n30 40 30.001 40");
    ck_assert_uint_eq(pmrun_count(run), 2);
    ck_assert_int_eq(pmrun_n_warnings(run), 1);
    ck_assert_int_ge(find_warning(run, ":3: ", "the last line has no line end"), 0);
    pmrun_free(run);
    run = read_text("# tau delta T D\n10 20 10.001 20.002\n30 40 30.001 40\n");
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    pmrun_free(run);
    /* its last number as long as the line before's: complete, no note */
    run = read_text("# tau delta T D\n10 20 10.001 20.002\n30 40 30.001 40.000");
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    pmrun_free(run);
    run = read_text("# tau delta T D\n10 20 10.001 20.002\n30 40 30.001 40\n# end");
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    pmrun_free(run);
    /* MW4 without its last line end */
    char path[4096], text[200000];
    data_path(path, sizeof path, "mw4_model.json");
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    ck_assert_uint_lt(n, sizeof text - 1);
    while (n > 0 && text[n - 1] == '\n') --n;
    text[n] = '\0';
    run = read_text(text);
    ck_assert_int_eq(find_warning(run, "no line end", NULL), -1);
    pmrun_free(run);
}
END_TEST

/* The notes made before an error come with it (the run and its notes are
** not returned on error; a TPOINT year of 9999 was noted, then the file
** refused for "mixed encoder conventions" without the note: an outside
** probe). */
START_TEST(test_pmrun_read_error_keeps_notes)
{
    static const char text[] = "# flavour: sweet\n# tau delta T D\n10 20 x 30\n";
    char path[64];
    temp_file(path, sizeof path, text, sizeof text - 1);
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 3, "(noted before it: ");
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 3, "'flavour' accepted, not used");
    remove(path);
}
END_TEST

/* Weather that makes refraction meaningless is an error when refraction is
** requested, a warning otherwise. */
static void expect_weather_error(const char *name, const char *needle)
{
    char path[4096];
    pmrun_options o;
    pmrun *run;
    data_path(path, sizeof path, name);
    tu_read_fails(path, NULL, PMRUN_ERR_FORMAT, 3, needle);
    pmrun_options_default(&o);
    o.refraction = 0;
    run = read_ok(name, &o);
    ck_assert_int_ge(find_warning(run, ":3:", needle), 0);
    pmrun_free(run);
}

START_TEST(test_pmrun_read_humidity_out_of_range)
{
    expect_weather_error("bad_humidity.dat", "humidity 150 is out of range");
}
END_TEST

START_TEST(test_pmrun_read_wavelength_not_positive)
{
    expect_weather_error("bad_wavelength.dat", "wavelength 0 um is not positive");
}
END_TEST

START_TEST(test_pmrun_read_temperature_below_absolute_zero)
{
    expect_weather_error("bad_temperature.dat", "temperature -300 C is below absolute zero");
}
END_TEST

START_TEST(test_pmrun_read_unsupported_option)
{
    expect_error("bad_gimbal.dat", 2, "option :GIMBAL (generalised gimbal mount) not supported");
}
END_TEST

START_TEST(test_pmrun_read_conflicting_mount_options)
{
    expect_error("bad_conflicting_mount.dat", 3, "option :ALTAZ conflicts");
}
END_TEST

START_TEST(test_pmrun_read_option_after_run_line)
{
    expect_error("bad_option_after_run.dat", 4, "after the run line (line 3)");
}
END_TEST

START_TEST(test_pmrun_read_mixed_bang_in_column_file)
{
    expect_error("bad_mixed_bang.dat", 2, "mixed formats");
}
END_TEST

START_TEST(test_pmrun_read_mixed_hash_in_tpoint)
{
    expect_error("bad_mixed_hash.dat", 5, "'#' line in a TPOINT file");
}
END_TEST

START_TEST(test_pmrun_read_header_after_data)
{
    expect_error("bad_header_after_data.dat", 2, "column header after the first record (line 1)");
}
END_TEST

START_TEST(test_pmrun_read_second_header)
{
    expect_error("bad_second_header.dat", 2, "second column header");
}
END_TEST

START_TEST(test_pmrun_read_duplicate_column)
{
    expect_error("bad_duplicate_column.dat", 1, "column 'Temp' named twice");
}
END_TEST

START_TEST(test_pmrun_read_too_many_aux_columns)
{
    expect_error("bad_too_many_aux.dat", 1, "more than 8 auxiliary columns");
}
END_TEST

START_TEST(test_pmrun_read_bad_pier) { expect_error("bad_pier.dat", 2, "field 5 (pier) 'X'"); }
END_TEST

START_TEST(test_pmrun_read_bad_dir) { expect_error("bad_dir.dat", 2, "field 5 (dir) '2'"); }
END_TEST

START_TEST(test_pmrun_read_bad_mount) { expect_error("bad_mount.dat", 1, "mount 'fork'"); }
END_TEST

START_TEST(test_pmrun_read_unknown_first_line)
{
    expect_error("bad_first_line.dat", 1, "cannot tell the format");
}
END_TEST

START_TEST(test_pmrun_read_nul_bytes)
{
    static const char text[] = "1.0 2.0 3.0 4.0\n1.0 2\0.0 3.0 4.0\n";
    char tmp[64];
    temp_file(tmp, sizeof tmp, text, sizeof text - 1);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 2, "NUL byte");
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_binary_garbage)
{
    static const char text[] = "\x7f" "ELF\x02\x01\x01\0\0\0\0\0\0\0\0\0\x03\0>\0\x01\0\0\0";
    char tmp[64];
    temp_file(tmp, sizeof tmp, text, sizeof text - 1);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 1, "NUL byte");
    unlink(tmp);
}
END_TEST

/* A file with classic Mac line ends (CR only) was one line and "no
** records"; now it is named as such at line 1.  CR LF is read (the CRs
** dropped), and a single CR inside a CSV-like field is left to the format. */
START_TEST(test_pmrun_read_cr_only)
{
    static const char text[] = "# latitude: 47\r# tau delta T D\r10 20 10.1 20.1\r"
                               "11 21 11.1 21.1\r12 22 12.1 22.1\r";
    static const char crlf[] = "# latitude: 47\r\n# tau delta T D\r\n10 20 10.1 20.1\r\n";
    char tmp[64];
    pmrun *run = NULL;
    char err[512];
    temp_file(tmp, sizeof tmp, text, sizeof text - 1);
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 1, "classic Mac (CR-only) line ends");
    unlink(tmp);
    temp_file(tmp, sizeof tmp, crlf, sizeof crlf - 1);
    ck_assert_msg(pmrun_read(tmp, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_int_eq((int)pmrun_count(run), 1);
    pmrun_free(run);
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_line_too_long)
{
    char tmp[64];
    /* a 1 MiB record line after a good one */
    temp_file_long(tmp, sizeof tmp, "1.0 2.0 3.0 4.0\n", '1', (size_t)1 << 20, "1.0 2.0 3.0 4.0\n");
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 2, "line too long");
    unlink(tmp);
    /* as the first line */
    temp_file_long(tmp, sizeof tmp, "", '#', (size_t)PMRUN_MAX_LINE + 1, "1.0 2.0 3.0 4.0\n");
    tu_read_fails(tmp, NULL, PMRUN_ERR_FORMAT, 1, "line too long");
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_line_at_limit)
{
    char tmp[64];
    pmrun *run;
    char err[512];
    /* a comment of exactly PMRUN_MAX_LINE bytes is fine, also with CRLF */
    temp_file_long(tmp, sizeof tmp, "", '#', (size_t)PMRUN_MAX_LINE, "1.0 2.0 3.0 4.0\r\n");
    ck_assert_int_eq(pmrun_read(tmp, NULL, &run, err, sizeof err), PMRUN_OK);
    ck_assert_uint_eq(pmrun_count(run), 1);
    ck_assert_int_eq(pmrun_get(run, 0)->line, 2);
    pmrun_free(run);
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_skip_bad_records)
{
    pmrun_options o;
    pmrun *run;
    pmrun_options_default(&o);
    /* without skip_bad: the first bad record is the error */
    expect_error("bad_records_skip.dat", 5, "12 fields, expected 14");
    o.skip_bad = 1;
    run = read_ok("bad_records_skip.dat", &o);
    ck_assert_uint_eq(pmrun_count(run), 3);
    ck_assert_int_eq(pmrun_get(run, 0)->line, 4);
    ck_assert_int_eq(pmrun_get(run, 1)->line, 6);
    ck_assert_int_eq(pmrun_get(run, 2)->line, 8);
    ck_assert_int_eq(pmrun_n_skipped(run), 2);
    ck_assert_ptr_nonnull(strstr(pmrun_skipped(run, 0), "bad_records_skip.dat:5: skipped: 12 fields"));
    ck_assert_ptr_nonnull(strstr(pmrun_skipped(run, 1), "bad_records_skip.dat:7: skipped: field 11"));
    ck_assert_ptr_null(pmrun_skipped(run, 2));
    ck_assert_int_ge(find_warning(run, "bad_records_skip.dat:5: skipped", NULL), 0);
    ck_assert_int_ge(find_warning(run, "bad_records_skip.dat:7: skipped", NULL), 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_skip_bad_long_line)
{
    char tmp[64], err[512];
    pmrun_options o;
    pmrun *run;
    pmrun_options_default(&o);
    o.skip_bad = 1;
    temp_file_long(tmp, sizeof tmp, "1.0 2.0 3.0 4.0\n", '1', (size_t)1 << 20, "1.5 2.0 3.0 4.0\n");
    ck_assert_int_eq(pmrun_read(tmp, &o, &run, err, sizeof err), PMRUN_OK);
    ck_assert_uint_eq(pmrun_count(run), 2);
    ck_assert_int_eq(pmrun_get(run, 1)->line, 3);
    ck_assert_int_eq(pmrun_n_skipped(run), 1);
    ck_assert_ptr_nonnull(strstr(pmrun_skipped(run, 0), ":2: skipped: line too long"));
    pmrun_free(run);
    unlink(tmp);
}
END_TEST

START_TEST(test_pmrun_read_skip_bad_all_records)
{
    char path[4096];
    pmrun_options o;
    pmrun_options_default(&o);
    o.skip_bad = 1;
    data_path(path, sizeof path, "bad_all_skipped.dat");
    tu_read_fails(path, &o, PMRUN_ERR_FORMAT, 5, "no records left: all 2 records were bad");
}
END_TEST

/* ----------------------------------------------------------- realdata */

static int real_path(char *buf, size_t n, const char *rel)
{
    const char *dir = getenv("PM_DATA_DIR");
    snprintf(buf, n, "%s/%s", dir && *dir ? dir : "../shared/data", rel);
    if (access(buf, R_OK) != 0) {
        printf("skipped: %s absent\n", buf);
        return 0;
    }
    return 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Median of encoder minus apparent HA, beyond-the-pole records turned
** back (HA - 180 deg), in degrees; counts the pier sides. */
static double median_ha_offset_deg(const pmrun *run, int *east, int *west)
{
    size_t i, n = pmrun_count(run);
    double *d = malloc(n * sizeof *d), m;
    *east = *west = 0;
    for (i = 0; i < n; ++i) {
        const pmrun_obs *o = pmrun_get(run, i);
        double enc = o->enc_ha;
        if (o->pier == PMRUN_PIER_WEST) {
            enc -= PI;
            ++*west;
        } else if (o->pier == PMRUN_PIER_EAST) {
            ++*east;
        }
        d[i] = wrap(enc - o->app_ha) / DEG;
    }
    qsort(d, n, sizeof *d, cmp_double);
    m = n % 2 ? d[n / 2] : 0.5 * (d[n / 2 - 1] + d[n / 2]);
    free(d);
    return m;
}

START_TEST(test_pmrun_read_real_gem28)
{
    char path[4096], err[1024];
    pmrun *run;
    int east, west;
    double med;
    if (!real_path(path, sizeof path, "celestial/gem-28.dat")) return;
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_uint_eq(pmrun_count(run), 454);
    ck_assert_int_eq(pmrun_format(run), PMRUN_FORMAT_TPOINT);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_EQUATORIAL);
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    ck_assert_double_eq_tol(pmrun_latitude_rad(run) / DEG, 39 + 25 / 3600.0, 1e-12);
    med = median_ha_offset_deg(run, &east, &west);
    ck_assert_msg(med > 4.0 && med < 7.0, "median HA offset %g deg, expected about 5", med);
    ck_assert_int_gt(east, 0);
    ck_assert_int_gt(west, 0);
    ck_assert_int_eq(east + west, 454);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_real_cgxl)
{
    char path[4096], err[1024];
    pmrun *run;
    int east, west;
    double med;
    if (!real_path(path, sizeof path, "celestial/cgx-l-data.dat")) return; /* CRLF lines */
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_uint_eq(pmrun_count(run), 148);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_EQUATORIAL);
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    med = median_ha_offset_deg(run, &east, &west);
    ck_assert_msg(med > 4.0 && med < 7.0, "median HA offset %g deg, expected about 5", med);
    ck_assert_int_gt(east, 0);
    ck_assert_int_gt(west, 0);
    pmrun_free(run);
}
END_TEST

START_TEST(test_pmrun_read_real_mmt_altaz)
{
    char path[4096], err[1024];
    pmrun *run;
    size_t i;
    if (!real_path(path, sizeof path, "mmt/k_and_e.dat")) return;
    ck_assert_msg(pmrun_read(path, NULL, &run, err, sizeof err) == PMRUN_OK, "%s", err);
    ck_assert_uint_eq(pmrun_count(run), 80);
    ck_assert_int_eq(pmrun_mount(run), PMRUN_MOUNT_ALTAZ);
    ck_assert_int_eq(pmrun_n_warnings(run), 0);
    ck_assert_double_eq_tol(pmrun_latitude_rad(run) / DEG, 31 + 41 / 60.0 + 19.6 / 3600.0, 1e-12);
    ck_assert_double_eq_tol(pmrun_latitude_rad(run) / DEG, 31.6889, TOL_LAT_DEG);
    /* encoder and observed azimuths agree within a degree once wrapped */
    for (i = 0; i < pmrun_count(run); ++i) {
        const pmrun_obs *o = pmrun_get(run, i);
        ck_assert_msg(fabs(wrap(o->enc_ha - o->app_ha)) < 1.0 * DEG, "line %d", o->line);
        ck_assert_msg(fabs(o->enc_dec - o->app_dec) < 0.1 * DEG, "line %d", o->line);
        ck_assert(o->app_ha >= 0 && o->app_ha < 2 * PI);
    }
    pmrun_free(run);
}
END_TEST

static Suite *runfile_suite(void)
{
    Suite *s = suite_create("runfile");
    TCase *tc;

    tc = tcase_create("formats");
    tcase_add_test(tc, test_pmrun_options_default_values);
    tcase_add_test(tc, test_pmrun_read_four_column);
    tcase_add_test(tc, test_pmrun_read_named_columns);
    tcase_add_test(tc, test_pmrun_read_named_altaz);
    tcase_add_test(tc, test_pmrun_read_tpoint_equatorial_fields);
    tcase_add_test(tc, test_pmrun_read_tpoint_altaz);
    tcase_add_test(tc, test_pmrun_read_crlf_same_as_lf);
    tcase_add_test(tc, test_pmrun_get_out_of_range);
    suite_add_tcase(s, tc);

    tc = tcase_create("reduction");
    tcase_add_test(tc, test_pmrun_read_reduction_matches_erfa);
    tcase_add_test(tc, test_pmrun_read_refraction_lifts_star);
    tcase_add_test(tc, test_pmrun_read_pressure_override);
    tcase_add_test(tc, test_pmrun_read_humidity_percent_converted);
    tcase_add_test(tc, test_pmrun_read_pressure_mmhg_warns);
    tcase_add_test(tc, test_pmrun_read_pressure_absurd);
    tcase_add_test(tc, test_pmrun_read_weather_implausible_warns);
    tcase_add_test(tc, test_pmrun_read_missing_weather_defaults);
    tcase_add_test(tc, test_pmrun_read_below_horizon_warns);
    suite_add_tcase(s, tc);

    tc = tcase_create("errors");
    /* a file of a million records (too_many_records) takes 2-3 s under
    ** AddressSanitizer on an idle machine: Check's default 4 s is too close */
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_pmrun_read_null_args);
    tcase_add_test(tc, test_pmrun_read_missing_file);
    tcase_add_test(tc, test_pmrun_read_directory);
    tcase_add_test(tc, test_pmrun_read_too_many_records);
    tcase_add_test(tc, test_pmrun_read_decimal_comma);
    tcase_add_test(tc, test_pmrun_read_out_of_memory);
    tcase_add_test(tc, test_pmrun_read_error_truncated);
    tcase_add_test(tc, test_pmrun_read_empty_file);
    tcase_add_test(tc, test_pmrun_read_blank_file);
    tcase_add_test(tc, test_pmrun_read_comments_only);
    tcase_add_test(tc, test_pmrun_read_tpoint_no_records);
    tcase_add_test(tc, test_pmrun_read_tpoint_no_run_line);
    tcase_add_test(tc, test_pmrun_read_too_few_fields_tpoint);
    tcase_add_test(tc, test_pmrun_read_too_few_fields_four_column);
    tcase_add_test(tc, test_pmrun_read_too_few_fields_named);
    tcase_add_test(tc, test_pmrun_read_non_numeric_field);
    tcase_add_test(tc, test_pmrun_read_nan_text);
    tcase_add_test(tc, test_pmrun_read_inf_text);
    tcase_add_test(tc, test_pmrun_read_number_overflow);
    tcase_add_test(tc, test_pmrun_read_minutes_ge_60);
    tcase_add_test(tc, test_pmrun_read_seconds_ge_60);
    tcase_add_test(tc, test_pmrun_read_signed_minutes);
    tcase_add_test(tc, test_pmrun_read_ra_hours_ge_24);
    tcase_add_test(tc, test_pmrun_read_catalogue_dec_beyond_90);
    tcase_add_test(tc, test_pmrun_read_raw_dec_beyond_180);
    tcase_add_test(tc, test_pmrun_read_latitude_beyond_90_tpoint);
    tcase_add_test(tc, test_pmrun_read_latitude_beyond_90_named);
    tcase_add_test(tc, test_pmrun_read_altaz_elevation_beyond_90_tpoint);
    tcase_add_test(tc, test_pmrun_read_altaz_elevation_beyond_90_named);
    tcase_add_test(tc, test_pmrun_read_run_line_without_date);
    tcase_add_test(tc, test_pmrun_read_run_line_incomplete_date);
    tcase_add_test(tc, test_pmrun_read_run_line_without_latitude);
    tcase_add_test(tc, test_pmrun_read_invalid_date);
    tcase_add_test(tc, test_pmrun_read_two_digit_year);
    tcase_add_test(tc, test_pmrun_read_time_past_midnight);
    tcase_add_test(tc, test_pmrun_read_pier_other_way_round);
    tcase_add_test(tc, test_pmrun_read_header_without_hash);
    tcase_add_test(tc, test_pmrun_read_error_keeps_notes);
    tcase_add_test(tc, test_pmrun_read_angle_beyond_turns);
    tcase_add_test(tc, test_pmrun_read_unterminated_last_record);
    tcase_add_test(tc, test_pmrun_read_humidity_out_of_range);
    tcase_add_test(tc, test_pmrun_read_wavelength_not_positive);
    tcase_add_test(tc, test_pmrun_read_temperature_below_absolute_zero);
    tcase_add_test(tc, test_pmrun_read_unsupported_option);
    tcase_add_test(tc, test_pmrun_read_conflicting_mount_options);
    tcase_add_test(tc, test_pmrun_read_option_after_run_line);
    tcase_add_test(tc, test_pmrun_read_mixed_bang_in_column_file);
    tcase_add_test(tc, test_pmrun_read_mixed_hash_in_tpoint);
    tcase_add_test(tc, test_pmrun_read_header_after_data);
    tcase_add_test(tc, test_pmrun_read_second_header);
    tcase_add_test(tc, test_pmrun_read_duplicate_column);
    tcase_add_test(tc, test_pmrun_read_too_many_aux_columns);
    tcase_add_test(tc, test_pmrun_read_bad_pier);
    tcase_add_test(tc, test_pmrun_read_bad_dir);
    tcase_add_test(tc, test_pmrun_read_bad_mount);
    tcase_add_test(tc, test_pmrun_read_unknown_first_line);
    tcase_add_test(tc, test_pmrun_read_nul_bytes);
    tcase_add_test(tc, test_pmrun_read_binary_garbage);
    tcase_add_test(tc, test_pmrun_read_cr_only);
    tcase_add_test(tc, test_pmrun_read_line_too_long);
    tcase_add_test(tc, test_pmrun_read_line_at_limit);
    tcase_add_test(tc, test_pmrun_read_skip_bad_records);
    tcase_add_test(tc, test_pmrun_read_skip_bad_long_line);
    tcase_add_test(tc, test_pmrun_read_skip_bad_all_records);
    suite_add_tcase(s, tc);

    tc = tcase_create("realdata");
    tcase_add_test(tc, test_pmrun_read_real_gem28);
    tcase_add_test(tc, test_pmrun_read_real_cgxl);
    tcase_add_test(tc, test_pmrun_read_real_mmt_altaz);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(runfile_suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
