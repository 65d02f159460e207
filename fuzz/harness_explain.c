/*
**  harness_explain.c - fuzz target body: the bytes as a pointing-run file
**  explained by pmx_explain_opts (tools/lib/explain.h: pmfit explain's whole
**  pipeline -- the run read, the baseline fit, locate, the candidates with
**  their fits and cross-validation, the pairs, the backward pass, the
**  reading of the baseline), then every result checked.
**
**  Input: byte 0 picks the options, the rest is the file (at most
**  PMFZ_EXPLAIN_MAX bytes: a few hundred points, so that one input stays
**  well inside the 10 s limit; longer inputs are skipped).
**     bit 0     baseline order 0 or 1
**     bit 1     pairs off
**     bits 2-3  folds: 5, 2, 3, 10
**     bits 4-5  alpha: 0.01, 0.05, 1e-6, 0.5
**     bit 6     known gear periods (144 and 2.5 cycles a revolution)
**     bit 7     (unused)
**
**  Invariants: pmx_explain_opts returns 0 or -1; -1 with a message (non-
**  empty, terminated); 0 with counts inside their arrays, finite sigmas at
**  or above zero, cross-validated RMS the same or NaN (a fold that did not
**  fit: documented), at least the six base terms in
**  the baseline and no fewer in the final model, every finding named (a
**  terminated, non-empty name) with a false-alarm probability in [0, 1],
**  finite amplitudes and errors at or above zero, its lines inside the file,
**  its alternatives' counts in range and each alternative named, with
**  finite evidence, and (a close one, not smooth) Delta BIC below 6.
*/
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "explain.h"
#include "harness.h"
#include "fz_file.h"

#define PMFZ_EXPLAIN_MAX 24576

static int ex_fail(const char *what)
{
    fprintf(stderr, "fuzz_explain: invariant broken: %s\n", what);
    return 1;
}

/* A name: terminated within n bytes, non-empty, printable. */
static int ex_name_ok(const char *s, size_t n)
{
    size_t i, len = strnlen(s, n);
    if (len == 0 || len == n)
        return 0;
    for (i = 0; i < len; i++)
        if (s[i] < 0x21 || s[i] > 0x7e)
            return 0;
    return 1;
}

static int ex_nonneg(double x)
{
    return isfinite(x) && x >= 0;
}

/* A cross-validated RMS: finite and >= 0, or NaN (a fold did not fit:
** documented, null in the JSON). */
static int ex_cv_ok(double x)
{
    return ex_nonneg(x) || isnan(x);
}

static int ex_finding_ok(const pmx_finding *f, int n_lines_file)
{
    int j;
    if (!ex_name_ok(f->effect, sizeof f->effect))
        return ex_fail("a finding without a name");
    if (!(f->false_alarm_probability >= 0 && f->false_alarm_probability <= 1))
        return ex_fail("false-alarm probability outside [0, 1]");
    if (!isfinite(f->amplitude_arcsec) || !ex_nonneg(f->amplitude_err_arcsec))
        return ex_fail("amplitude not finite, or its error not finite and >= 0");
    if (!ex_nonneg(f->sigma_after_arcsec) || !ex_cv_ok(f->cv_rms_after_arcsec))
        return ex_fail("a finding's sigma or CV RMS not finite and >= 0");
    if (!(f->cycles_per_rev >= 0) || !isfinite(f->cycles_per_rev))
        return ex_fail("cycles per revolution negative or not finite");
    if (f->n_lines < 0 || f->n_alternatives < 0 || f->n_alternatives > PMX_MAX_ALTERNATIVES)
        return ex_fail("a finding's counts out of range");
    for (j = 0; j < f->n_lines && j < 16; j++)
        if (f->lines[j] < 1 || f->lines[j] > n_lines_file)
            return ex_fail("an outlier's line outside the file");
    for (j = 0; j < f->n_alternatives; j++) {
        const pmx_alternative *a = &f->alternatives[j];
        if (!ex_name_ok(a->effect, sizeof a->effect))
            return ex_fail("an alternative without a name");
        if (strnlen(a->separate_by, sizeof a->separate_by) == sizeof a->separate_by)
            return ex_fail("an alternative's advice not terminated");
        if (!isfinite(a->delta_bic) || !isfinite(a->log10_lr) || !(a->log10_fap <= 0) ||
            (a->smooth != 0 && a->smooth != 1) || (!a->smooth && !(a->delta_bic < 6)))
            return ex_fail("an alternative's evidence not finite, or a close one at Delta BIC "
                           ">= 6");
    }
    return 0;
}

static int ex_result_ok(const pmx_result *r, int n_lines_file)
{
    int i;
    if (r->n_findings < 0 || r->n_findings > PMX_MAX_FINDINGS || r->n_readings < 0 ||
        r->n_readings > PMX_MAX_READINGS || r->n_withdrawn < 0 ||
        r->n_withdrawn > PMX_MAX_FINDINGS)
        return ex_fail("a count outside its array");
    if (!ex_nonneg(r->base_sigma_arcsec) || !ex_cv_ok(r->base_cv_rms_arcsec) ||
        !ex_nonneg(r->final_sigma_arcsec) || !ex_cv_ok(r->final_cv_rms_arcsec))
        return ex_fail("a sigma or CV RMS not finite and >= 0");
    if (r->base_n_params < 6 || r->final_n_params < r->base_n_params)
        return ex_fail("the baseline below the six base terms, or the final model smaller");
    for (i = 0; i < r->n_findings; i++)
        if (ex_finding_ok(&r->findings[i], n_lines_file))
            return 1;
    for (i = 0; i < r->n_readings; i++)
        if (!ex_name_ok(r->readings[i].what, sizeof r->readings[i].what) ||
            !isfinite(r->readings[i].value) || !(r->readings[i].error >= 0))
            return ex_fail("a reading of the baseline unnamed or not finite");
    for (i = 0; i < r->n_withdrawn; i++)
        if (!ex_name_ok(r->withdrawn[i], sizeof r->withdrawn[i]))
            return ex_fail("a withdrawn finding without a name");
    /* significant, not modelled: significant (below alpha) and predicting
    ** no better than the model it was tried on */
    if (r->unmodelled[0] &&
        (!ex_name_ok(r->unmodelled, sizeof r->unmodelled) ||
         !(r->unmodelled_log10_fap < 0) || !ex_nonneg(r->unmodelled_sigma_arcsec) ||
         !ex_nonneg(r->unmodelled_cv_rms_arcsec) || !ex_nonneg(r->unmodelled_cv_before_arcsec) ||
         !(r->unmodelled_cv_rms_arcsec >= r->unmodelled_cv_before_arcsec)))
        return ex_fail("an unmodelled family unnamed, not significant or predicting better");
    return 0;
}

int pmfz_explain(const unsigned char *data, size_t size)
{
    static const int folds[4] = {5, 2, 3, 10};
    static const double alphas[4] = {0.01, 0.05, 1e-6, 0.5};
    static const double gears[2] = {144, 2.5};
    static pmx_result res; /* (large: not on the stack) */
    char path[64], err[512];
    pmx_options o;
    unsigned flags;
    int fd, rc, bad = 0, n_lines = 1;
    size_t i;
    if (size < 1 || size - 1 > PMFZ_EXPLAIN_MAX)
        return 0;
    flags = data[0];
    for (i = 1; i < size; i++)
        n_lines += data[i] == '\n';
    pmx_options_default(&o);
    o.order = (int)(flags & 1u);
    o.pairs = !(flags & 2u);
    o.folds = folds[(flags >> 2) & 3u];
    o.alpha = alphas[(flags >> 4) & 3u];
    if (flags & 64u) {
        o.gears = gears;
        o.n_gears = 2;
    }
    fd = pmfz_memfile(data + 1, size - 1, path, sizeof path);
    if (fd < 0)
        return 0;
    memset(&res, 0xa5, sizeof res); /* (nothing read before it is written) */
    err[0] = '\0';
    rc = pmx_explain_opts(path, &o, &res, err, sizeof err);
    close(fd);
    if (rc == -1)
        bad = strnlen(err, sizeof err) == 0 || strnlen(err, sizeof err) == sizeof err
                  ? ex_fail("an error without a (terminated) message")
                  : 0;
    else if (rc == 0)
        bad = ex_result_ok(&res, n_lines);
    else
        bad = ex_fail("pmx_explain_opts returned neither 0 nor -1");
    return bad;
}
