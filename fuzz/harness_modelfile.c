/*
**  harness_modelfile.c - fuzz target body: the bytes as a model file read by
**  pmmodel_load_info; a model that loads is evaluated (apply, invert), saved,
**  emitted as C and loaded again, which must give the same model bit for
**  bit and the same information (pier side, the names of the inputs read).
*/
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "pm.h"
#include "modelfile.h"
#include "harness.h"
#include "fz_input.h"
#include "fz_file.h"

/* Round trip apply(invert(x)) promised by pm_model_invert with PM_OK, plus
** the rounding of going from vectors to angles and back (a few 1e-16). */
#define MF_TOL_ROUNDTRIP (PM_INVERT_TOL + 1e-14)

static int mf_same(const pm_model *a, const pm_model *b)
{
    int i;
    if (a->mount != b->mount || a->order != b->order || a->n_terms != b->n_terms ||
        a->n_base != b->n_base || a->latitude != b->latitude)
        return pmfz_fail("modelfile: reloaded header differs (mount %d/%d order %d/%d terms "
                         "%d/%d base %d/%d latitude %.17g/%.17g)", a->mount, b->mount, a->order,
                         b->order, a->n_terms, b->n_terms, a->n_base, b->n_base, a->latitude,
                         b->latitude);
    for (i = 0; i < a->n_terms; i++) {
        const pm_term *s = &a->term[i], *t = &b->term[i];
        if (memcmp(&a->coef[i], &b->coef[i], sizeof(double)) != 0)
            return pmfz_fail("modelfile: reloaded coefficient %d is %.17g, saved %.17g", i,
                             b->coef[i], a->coef[i]);
        if (s->kind != t->kind || s->k != t->k || s->l != t->l || s->m != t->m ||
            s->side != t->side || s->aux != t->aux ||
            (i >= a->n_base && memcmp(&s->param, &t->param, sizeof(double)) != 0))
            return pmfz_fail("modelfile: reloaded term %d differs", i);
    }
    return 0;
}

/* The information a reloaded file gives back: its pier side, and the name
** of every input a term reads (a name no term reads is not written). */
static int mf_same_info(const pm_model *m, const pmmodel_info *a, const pmmodel_info *b)
{
    int i;
    if (a->pier != b->pier)
        return pmfz_fail("modelfile: reloaded pier side %d, saved %d", b->pier, a->pier);
    if (a->has_err != b->has_err)
        return pmfz_fail("modelfile: reloaded has_err %d, saved %d", b->has_err, a->has_err);
    for (i = 0; a->has_err && i < m->n_terms; i++)
        if (memcmp(&a->err[i], &b->err[i], sizeof(double)) != 0)
            return pmfz_fail("modelfile: reloaded error %d is %.17g, saved %.17g", i, b->err[i],
                             a->err[i]);
    for (i = m->n_base; i < m->n_terms; i++) {
        int j = m->term[i].aux - PM_AUX_USER;
        if (m->term[i].kind == PM_TERM_AUX && j >= 0 && j < PM_MAX_AUX &&
            strcmp(a->input[j], b->input[j]) != 0)
            return pmfz_fail("modelfile: reloaded input %d is '%s', saved '%s'", j, b->input[j],
                             a->input[j]);
    }
    return 0;
}

/* Evaluate a loaded (prepared) model at a few positions. */
static int mf_evaluate(const pm_model *m)
{
    static const double pos[][2] = {
        {0.3, 0.7}, {-2.5, -1.2}, {3.0, 1.5}, {1.0, 0.0}, {-0.5, 2.2}, {0.0, M_PI / 2}};
    static const int apply_ok[] = {PM_OK, 99};
    static const int inv_ok[] = {PM_OK, PM_WARN_NOT_CONVERGED, PM_WARN_UNREACHABLE, 99};
    pm_context ctx;
    size_t i;
    if (!pmfz_plain_model(m)) { /* fz_input.h: statuses only (overflow) */
        static const int apply_st[] = {PM_OK, PM_ERR_NONFINITE, 99}; /* overflow */
        double t, d;
        memset(&ctx, 0, sizeof ctx);
        if (!pmfz_status_in(pm_model_apply(m, &ctx, 0.3, 0.7, &t, &d), apply_st))
            return pmfz_fail("modelfile: apply of a loaded model failed");
        return 0;
    }
    memset(&ctx, 0, sizeof ctx);
    ctx.temp_c = 12.5;
    ctx.time_h = 3.25;
    ctx.dir = 1;
    for (i = 0; i < sizeof pos / sizeof pos[0]; i++) {
        double t = 9, d = 9, et = 9, ed = 9, rt, rd;
        int side;
        pm_status st = pm_model_apply(m, &ctx, pos[i][0], pos[i][1], &t, &d);
        if (!pmfz_status_in(st, apply_ok) || !pmfz_finite(t) || !pmfz_finite(d))
            return pmfz_fail("modelfile: apply of a loaded model at (%g, %g): status %d, "
                             "(%g, %g)", pos[i][0], pos[i][1], st, t, d);
        side = i & 1 ? PM_SIDE_FLIPPED : PM_SIDE_NORMAL;
        st = pm_model_invert(m, &ctx, t, d, side, &et, &ed);
        if (!pmfz_status_in(st, inv_ok))
            return pmfz_fail("modelfile: invert of a loaded model: status %d", st);
        if (st == PM_OK) {
            double miss;
            if (!pmfz_finite(et) || !pmfz_finite(ed))
                return pmfz_fail("modelfile: invert PM_OK with (%g, %g)", et, ed);
            if (pm_model_apply(m, &ctx, et, ed, &rt, &rd) != PM_OK)
                return pmfz_fail("modelfile: apply of the inverse failed");
            miss = pmfz_sep(rt, rd, t, d);
            if (!(miss <= MF_TOL_ROUNDTRIP))
                return pmfz_fail("modelfile: invert PM_OK but round trip misses by %g rad", miss);
        }
    }
    return 0;
}

/* Version 5: the file read again with its covariance (pmmodel_load_cov)
** loads as pmmodel_load_info did (r); where it keeps correlations the
** covariance is finite, symmetric, its diagonal the errors squared, and a
** save and a load give it back to 1e-9 (correlations keep 10 digits). */
static double mf_cov[PM_MAX_TERMS * PM_MAX_TERMS], mf_cov2[PM_MAX_TERMS * PM_MAX_TERMS];

static int mf_load_cov(const char *path, int r, const pm_model *m0)
{
    pm_model m, again;
    pmmodel_info info, info2;
    char err[512], out[128];
    const char *dir;
    int has = 7, has2 = 7, i, j, P, bad = 0;
    const size_t cap = sizeof mf_cov / sizeof mf_cov[0];
    int r2 = pmmodel_load_cov(path, &m, &info, mf_cov, cap, &has, err, sizeof err);
    if (r2 != r)
        return pmfz_fail("modelfile: pmmodel_load_cov returned %d, pmmodel_load_info %d", r2, r);
    if (r != 0)
        return has == 0 ? 0 : pmfz_fail("modelfile: failed load_cov set has_cov %d", has);
    if (memcmp(&m, m0, sizeof m) != 0)
        return pmfz_fail("modelfile: pmmodel_load_cov read another model");
    if (has != 0 && has != 1)
        return pmfz_fail("modelfile: has_cov %d", has);
    if (!has)
        return 0;
    P = m.n_terms;
    if (!info.has_err)
        return pmfz_fail("modelfile: a covariance without errors");
    for (i = 0; i < P; i++)
        for (j = 0; j < P; j++) {
            double c = mf_cov[i * P + j];
            if (!pmfz_finite(c) || c != mf_cov[j * P + i])
                return pmfz_fail("modelfile: covariance %d %d is %g, not finite or symmetric", i,
                                 j, c);
            if (i == j && c != info.err[i] * info.err[i])
                return pmfz_fail("modelfile: variance %d is %.17g, the error squared %.17g", i,
                                 c, info.err[i] * info.err[i]);
        }
    dir = pmfz_scratch();
    if (!dir)
        return 0;
    snprintf(out, sizeof out, "%s/cov.pm", dir);
    if (pmmodel_save_cov(out, &m, &info, mf_cov, NULL, err, sizeof err) != 0)
        bad = pmfz_fail("modelfile: saving a loaded covariance failed: %s", err);
    else if (pmmodel_load_cov(out, &again, &info2, mf_cov2, cap, &has2, err, sizeof err) != 0)
        bad = pmfz_fail("modelfile: reloading a saved covariance failed: %s", err);
    else if (has2 != 1)
        bad = pmfz_fail("modelfile: a saved covariance reloaded without it");
    else if (memcmp(&info2.stars_sigma, &info.stars_sigma, sizeof info.stars_sigma) != 0)
        bad = pmfz_fail("modelfile: stars_sigma reloaded as %.17g, saved %.17g",
                        info2.stars_sigma, info.stars_sigma);
    for (i = 0; !bad && i < P; i++)
        for (j = 0; !bad && j < P; j++) {
            double s = sqrt(mf_cov[i * P + i] * mf_cov[j * P + j]);
            if (!(fabs(mf_cov2[i * P + j] - mf_cov[i * P + j]) <= 1e-9 * s))
                bad = pmfz_fail("modelfile: covariance %d %d reloaded as %.17g, saved %.17g", i,
                                j, mf_cov2[i * P + j], mf_cov[i * P + j]);
        }
    unlink(out);
    return bad;
}

int pmfz_modelfile(const unsigned char *data, size_t size)
{
    pm_model m, before, again;
    pmmodel_info info, info_before, info_again;
    char path[64], err[512], out[128], hdr[128];
    const char *dir;
    int fd, r, bad = 0;

    if (pmmodel_load(NULL, &m, err, sizeof err) != -1)
        return pmfz_fail("modelfile: pmmodel_load(NULL) accepted");
    fd = pmfz_memfile(data, size, path, sizeof path);
    if (fd < 0)
        return 0;
    if (pmmodel_load(path, NULL, err, sizeof err) != -1) {
        close(fd);
        return pmfz_fail("modelfile: pmmodel_load(path, NULL) accepted");
    }
    memset(&m, 0xA5, sizeof m);
    before = m;
    memset(&info, 0x5A, sizeof info);
    info_before = info;
    memset(err, 'x', sizeof err);
    r = pmmodel_load_info(path, &m, &info, err, sizeof err);
    bad = mf_load_cov(path, r, &m);
    close(fd);
    if (bad)
        return bad;
    if (r != 0) {
        if (r != -1)
            return pmfz_fail("modelfile: pmmodel_load returned %d", r);
        if (memcmp(&m, &before, sizeof m) != 0)
            return pmfz_fail("modelfile: failed load changed the model");
        if (memcmp(&info, &info_before, sizeof info) != 0)
            return pmfz_fail("modelfile: failed load changed the information");
        if (!memchr(err, '\0', sizeof err) || strncmp(err, path, strlen(path)) != 0)
            return pmfz_fail("modelfile: error message '%.80s' does not name the file", err);
        return 0;
    }
    bad = mf_evaluate(&m);
    if (bad)
        return bad;

    dir = pmfz_scratch();
    if (!dir)
        return 0;
    snprintf(out, sizeof out, "%s/model.pm", dir);
    snprintf(hdr, sizeof hdr, "%s/model.h", dir);
    if (pmmodel_save_info(out, &m, &info, "fuzz\nround trip", err, sizeof err) != 0)
        bad = pmfz_fail("modelfile: saving a loaded model failed: %s", err);
    else if (pmmodel_load_info(out, &again, &info_again, err, sizeof err) != 0)
        bad = pmfz_fail("modelfile: reloading a saved model failed: %s", err);
    else
        bad = mf_same(&m, &again) || mf_same_info(&m, &info, &info_again);
    if (!bad && pmmodel_emit_c(hdr, &m, "pm_fz", "fuzz", err, sizeof err) != 0)
        bad = pmfz_fail("modelfile: emitting C for a loaded model failed: %s", err);
    unlink(out);
    unlink(hdr);
    return bad;
}
