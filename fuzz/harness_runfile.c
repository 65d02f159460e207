/*
**  harness_runfile.c - fuzz target body: the bytes as a pointing-run file
**  read by pmrun_read (all seven formats: four-column, named columns,
**  TPOINT, RTS2 gpoint, MountWizzard4 JSON, CSV logs, the MMT log), then
**  every accessor walked.
**
**  Input: byte 0 picks the options, the rest is the file.
**     bit 0     skip_bad
**     bit 1     refraction off
**     bits 2-3  weather overrides: none, plausible, absurd, extreme
**     bits 4-5  error buffer: 512 bytes, NULL, 1 byte, 17 bytes
**     bits 6-7  1: every 0x01 byte of the file becomes 70000 '9's (lines
**               longer than PMRUN_MAX_LINE); 2: a file of at most 64 bytes
**               is repeated 1001 times (more than PMRUN_MAX_MESSAGES
**               warnings); 0: the file as it is; 3: byte 1 forces a
**               format and an equinox (format = (byte & 7) - 1, -1 the
**               detection; equinox = (byte >> 3) % 3) and the file starts
**               at byte 2
*/
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "runfile.h"
#include "harness.h"
#include "fz_input.h"
#include "fz_file.h"

#define RF_LONG 70000
#define RF_REPEAT 1001
#define RF_EPS 1e-12

static int rf_starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* The file the flags describe; NULL when out of memory. */
static char *rf_expand(unsigned flags, const unsigned char *p, size_t n, size_t *len)
{
    size_t i, total = 0, reps = 1, r;
    int expand = (flags >> 6) == 1u;
    char *buf, *o;
    if ((flags >> 6) == 2u && n <= 64)
        reps = RF_REPEAT;
    for (i = 0; i < n; i++)
        total += (expand && p[i] == 0x01) ? RF_LONG : 1;
    buf = malloc(total * reps + 1);
    if (!buf)
        return NULL;
    o = buf;
    for (r = 0; r < reps; r++)
        for (i = 0; i < n; i++) {
            if (expand && p[i] == 0x01) {
                memset(o, '9', RF_LONG);
                o += RF_LONG;
            } else {
                *o++ = (char)p[i];
            }
        }
    *len = (size_t)(o - buf);
    return buf;
}

static int rf_walk(const pmrun *run, const char *path, int skip_bad, int forced)
{
    size_t i, n = pmrun_count(run);
    int fmt = pmrun_format(run), mount = pmrun_mount(run);
    int naux = pmrun_n_aux(run), nw = pmrun_n_warnings(run), ns = pmrun_n_skipped(run);
    int kept, j, last_line = 0;
    char pre[80];
    pmrun_site site;
    double lat;

    snprintf(pre, sizeof pre, "%s:", path);
    if (fmt < PMRUN_FORMAT_FOUR_COLUMN || fmt > PMRUN_FORMAT_MMT)
        return pmfz_fail("runfile: format %d", fmt);
    if (forced != PMRUN_FORMAT_AUTO && fmt != forced &&
        !(forced <= PMRUN_FORMAT_NAMED && fmt <= PMRUN_FORMAT_NAMED))
        return pmfz_fail("runfile: forced format %d read as %d", forced, fmt);
    if ((fmt == PMRUN_FORMAT_MMT && mount != PMRUN_MOUNT_ALTAZ) ||
        ((fmt == PMRUN_FORMAT_MW4 || fmt == PMRUN_FORMAT_CSV) && mount != PMRUN_MOUNT_EQUATORIAL))
        return pmfz_fail("runfile: format %d with mount %d", fmt, mount);
    if (mount != PMRUN_MOUNT_EQUATORIAL && mount != PMRUN_MOUNT_ALTAZ)
        return pmfz_fail("runfile: mount %d", mount);
    if (n < 1)
        return pmfz_fail("runfile: PMRUN_OK with no records");
    if (naux < 0 || naux > PMRUN_MAX_AUX)
        return pmfz_fail("runfile: %d aux columns", naux);
    for (j = 0; j < naux; j++) {
        const char *s = pmrun_aux_name(run, j);
        if (!s || !*s)
            return pmfz_fail("runfile: aux name %d missing", j);
    }
    if (pmrun_aux_name(run, naux) || pmrun_aux_name(run, -1))
        return pmfz_fail("runfile: aux name out of range not NULL");
    if (nw < 0 || nw > PMRUN_MAX_MESSAGES + 1)
        return pmfz_fail("runfile: %d warnings", nw);
    for (j = 0; j < nw; j++) {
        const char *s = pmrun_warning(run, j);
        if (!s || !rf_starts(s, pre))
            return pmfz_fail("runfile: warning %d '%s' does not start with the path", j,
                             s ? s : "(null)");
    }
    if (pmrun_warning(run, nw) || pmrun_warning(run, -1))
        return pmfz_fail("runfile: warning out of range not NULL");
    if (ns < 0 || (!skip_bad && ns != 0))
        return pmfz_fail("runfile: %d skipped records (skip_bad %d)", ns, skip_bad);
    kept = ns < PMRUN_MAX_MESSAGES ? ns : PMRUN_MAX_MESSAGES;
    for (j = 0; j < kept; j++) {
        const char *s = pmrun_skipped(run, j);
        if (!s || !rf_starts(s, pre) || !strstr(s, "skipped: "))
            return pmfz_fail("runfile: skipped message %d '%s'", j, s ? s : "(null)");
    }
    if (pmrun_skipped(run, kept) || pmrun_skipped(run, -1))
        return pmfz_fail("runfile: skipped message out of range not NULL");
    if (pmrun_get_site(run, &site) != PMRUN_OK || pmrun_get_site(run, NULL) != PMRUN_ERR_ARG)
        return pmfz_fail("runfile: pmrun_get_site");
    lat = pmrun_latitude_rad(run);
    if (!(isnan(lat) && isnan(site.latitude_rad)) && lat != site.latitude_rad)
        return pmfz_fail("runfile: latitude %g vs site %g", lat, site.latitude_rad);
    if (!isnan(lat) && !(fabs(lat) <= M_PI / 2 + RF_EPS))
        return pmfz_fail("runfile: latitude %g", lat);

    for (i = 0; i < n; i++) {
        const pmrun_obs *o = pmrun_get(run, i);
        if (!o)
            return pmfz_fail("runfile: record %zu of %zu is NULL", i, n);
        if (!pmfz_finite(o->enc_ha) || !pmfz_finite(o->enc_dec) || !pmfz_finite(o->app_ha) ||
            !pmfz_finite(o->app_dec))
            return pmfz_fail("runfile: record %zu not finite: %g %g %g %g", i, o->enc_ha,
                             o->enc_dec, o->app_ha, o->app_dec);
        if (!(fabs(o->app_dec) <= M_PI / 2 + RF_EPS) || !(fabs(o->enc_dec) <= M_PI + RF_EPS))
            return pmfz_fail("runfile: record %zu axis 2 out of range: enc %.17g app %.17g", i,
                             o->enc_dec, o->app_dec);
        /* encoder angles are modular: every reader reduces them into
        ** (-pi, pi] (the file's value in enc_raw); apparent axis 1 is an HA
        ** in (-pi, pi] or an azimuth in [0, 2pi) */
        if (!(o->enc_ha > -M_PI - RF_EPS && o->enc_ha <= M_PI + RF_EPS) ||
            !(o->enc_dec > -M_PI - RF_EPS && o->enc_dec <= M_PI + RF_EPS))
            return pmfz_fail("runfile: record %zu encoder not in (-pi, pi]: %.17g %.17g", i,
                             o->enc_ha, o->enc_dec);
        if (mount == PMRUN_MOUNT_ALTAZ ? !(o->app_ha >= 0 && o->app_ha < 2 * M_PI + RF_EPS)
                                       : !(o->app_ha > -M_PI - RF_EPS && o->app_ha <= M_PI + RF_EPS))
            return pmfz_fail("runfile: record %zu apparent axis 1 %.17g out of range", i,
                             o->app_ha);
        if (!pmfz_finite(o->enc_raw[0]) || !pmfz_finite(o->enc_raw[1]))
            return pmfz_fail("runfile: record %zu enc_raw not finite", i);
        if (fmt == PMRUN_FORMAT_TPOINT && mount == PMRUN_MOUNT_ALTAZ &&
            !(o->app_ha >= 0 && o->app_ha < 2 * M_PI))
            return pmfz_fail("runfile: record %zu TPOINT azimuth %.17g not in [0, 2pi)", i,
                             o->app_ha);
        if (o->pier < -1 || o->pier > 1 || o->dir < -1 || o->dir > 1)
            return pmfz_fail("runfile: record %zu pier %d dir %d", i, o->pier, o->dir);
        if (fmt != PMRUN_FORMAT_NAMED && fmt != PMRUN_FORMAT_MW4 && fmt != PMRUN_FORMAT_CSV) {
            int want = mount == PMRUN_MOUNT_ALTAZ ? 0 : (fabs(o->enc_dec) > M_PI / 2 ? -1 : 1);
            if (o->pier != want || o->dir != 0)
                return pmfz_fail("runfile: record %zu pier %d (expected %d), dir %d", i, o->pier,
                                 want, o->dir);
        }
        /* MW4, CSV: the side of pier from the file, the encoder beyond the
        ** pole exactly for the west side (the sky place unfolded) */
        if ((fmt == PMRUN_FORMAT_MW4 || fmt == PMRUN_FORMAT_CSV) &&
            (o->dir != 0 || (o->pier != 1 && o->pier != -1) ||
             (o->pier == -1) != (fabs(o->enc_dec) > M_PI / 2 - RF_EPS) ||
             (o->pier == 1 && fabs(o->enc_dec) > M_PI / 2 + RF_EPS)))
            return pmfz_fail("runfile: %s record %zu pier %d with encoder dec %.17g, dir %d",
                             fmt == PMRUN_FORMAT_MW4 ? "MW4" : "CSV", i, o->pier, o->enc_dec,
                             o->dir);
        if (fmt == PMRUN_FORMAT_FOUR_COLUMN && (!isnan(o->temp_c) || !isnan(o->time_h)))
            return pmfz_fail("runfile: four-column record %zu has temp/time", i);
        if ((!isnan(o->temp_c) && !pmfz_finite(o->temp_c)) ||
            (!isnan(o->time_h) && !pmfz_finite(o->time_h)))
            return pmfz_fail("runfile: record %zu temp/time infinite", i);
        for (j = 0; j < naux; j++)
            if (!isnan(o->aux[j]) && !pmfz_finite(o->aux[j]))
                return pmfz_fail("runfile: record %zu aux %d infinite", i, j);
        if (o->line <= last_line)
            return pmfz_fail("runfile: record %zu line %d after line %d", i, o->line, last_line);
        last_line = o->line;
    }
    if (pmrun_get(run, n))
        return pmfz_fail("runfile: pmrun_get past the end not NULL");
    return 0;
}

int pmfz_runfile(const unsigned char *data, size_t size)
{
    static const double ovr[4][4] = {
        {0, 0, 0, 0},
        {800.0, 5.0, 0.3, 0.6},
        {-5.0, -300.0, 150.0, -1.0},
        {1e300, -1e300, 0.0, 1e-300}};
    unsigned flags = size ? data[0] : 0;
    size_t len = 0;
    char *text, path[64], err[512], *errp = err;
    size_t errlen = sizeof err;
    pmrun_options opt;
    const pmrun_options *optp = &opt;
    pmrun *run = (pmrun *)&opt; /* must be overwritten */
    int fd, st, bad = 0, set = (int)((flags >> 2) & 3u);
    int forced = PMRUN_FORMAT_AUTO, equinox = PMRUN_EQUINOX_FILE;
    const unsigned char *body = size ? data + 1 : data;
    size_t body_len = size ? size - 1 : 0;

    if (pmrun_count(NULL) != 0 || pmrun_get(NULL, 0) || pmrun_format(NULL) != -1 ||
        pmrun_mount(NULL) != -1 || !isnan(pmrun_latitude_rad(NULL)) || pmrun_n_aux(NULL) != 0 ||
        pmrun_n_warnings(NULL) != 0 || pmrun_n_skipped(NULL) != 0 || pmrun_warning(NULL, 0) ||
        pmrun_skipped(NULL, 0) || pmrun_aux_name(NULL, 0))
        return pmfz_fail("runfile: an accessor mishandles NULL");

    if ((flags >> 6) == 3u && body_len > 0) {
        forced = (int)(body[0] & 7u) - 1;
        equinox = (int)((body[0] >> 3) % 3u);
        body++;
        body_len--;
    }
    text = rf_expand(flags, body, body_len, &len);
    if (!text)
        return 0;
    fd = pmfz_memfile(text, len, path, sizeof path);
    free(text);
    if (fd < 0)
        return 0;

    pmrun_options_default(&opt);
    opt.skip_bad = (int)(flags & 1u);
    opt.refraction = (flags & 2u) ? 0 : 1;
    if (set) {
        opt.pressure_hpa = ovr[set][0];
        opt.temp_c = ovr[set][1];
        opt.humidity = ovr[set][2];
        opt.wavelength_um = ovr[set][3];
    } else if (flags == 0) {
        optp = NULL; /* the defaults */
    }
    opt.format = forced;
    opt.equinox = equinox;
    switch ((flags >> 4) & 3u) {
    case 1: errp = NULL; errlen = 0; break;
    case 2: errlen = 1; break;
    case 3: errlen = 17; break;
    default: break;
    }
    memset(err, 'x', sizeof err);

    st = pmrun_read(path, optp, &run, errp, errlen);
    if (st != PMRUN_OK && st != PMRUN_ERR_IO && st != PMRUN_ERR_FORMAT && st != PMRUN_ERR_NOMEM) {
        bad = pmfz_fail("runfile: status %d", st);
    } else if (st != PMRUN_OK) {
        if (run)
            bad = pmfz_fail("runfile: *out not NULL after error %d", st);
        else if (errp && !memchr(err, '\0', errlen))
            bad = pmfz_fail("runfile: error message not NUL-terminated within %zu", errlen);
        else if (errp && errlen == sizeof err && (strncmp(err, path, strlen(path)) != 0 ||
                                                 err[strlen(path)] != ':'))
            bad = pmfz_fail("runfile: error message '%s' does not start with the path", err);
    } else if (!run) {
        bad = pmfz_fail("runfile: PMRUN_OK and *out NULL");
    } else {
        bad = rf_walk(run, path, opt.skip_bad, forced);
        pmrun_free(run);
    }
    close(fd);
    return bad;
}
