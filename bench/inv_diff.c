/*
**  inv_diff.c - the double inverse's outcomes, one line per call, for a
**  differential check of two builds of the core (bench/inv_diff.sh): a
**  refactor of the inverse must give every call the same status, the same
**  number of model evaluations (the core built with the probe of
**  tests/probe.h) and the same bits of both returned angles.
**
**    pmbench_inv_diff [SCALE [save|load FILE]]
**                                 SCALE (default 1) multiplies every
**                                 sample's size; save writes the
**                                 realistic samples' targets (the forward
**                                 model's apparent positions) to FILE,
**                                 load inverts FILE's targets instead of
**                                 this core's, so that two cores whose
**                                 forward models round differently are
**                                 compared on the same calls
**
**  Samples (deterministic: tu_rng with fixed seeds; at SCALE 1 96,000 hard
**  calls and 291,840 realistic ones, 387,840 in all):
**    hard S     check_bounded's adversarial models, contexts, targets and
**               starts (tests/hard_cases.h) at scale S = normal, large,
**               huge: 400 models x 40 targets, pm_model_invert on the
**               side drawn, then pm_model_invert_near from hc_hard_start
**    real       realistic equatorial models (hc_real_model: isotropic
**               terms within 10 deg, harmonic within 10'), plus 0-3 AUX
**               terms (temperature, time, direction, user input; within
**               1') with a random context; true encoder positions 0-90
**               deg from the mount's pole (hc_real_position's four
**               kinds), both pier sides; the cold call, then tracking
**               calls (pm_model_invert_near) from 1e-5 rad, 1e-3 rad and
**               0.5 deg away from the true position
**    small      the same with the bench's kind of model: isotropic terms
**               within 10', harmonic within 15" (the typical, lean path)
**
**  Each line: sample, index, call (c cold, n near), status, evaluations,
**  the bits of both returned angles (hex; outputs preset to a fixed NaN,
**  so an error's unchanged outputs compare too).  The last line counts
**  the calls.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm.h"
#include "testutil.h"
#include "probe.h"
#include "hard_cases.h"

static unsigned long probe_count;
void pm_probe_hit(void) { probe_count++; }

static long n_calls;

/* The targets' file (save, load) or none. */
static FILE *targets;
static int loading;

/* The target (ah, ad) of a realistic call: this core's forward model's,
** saved to the targets' file, or the file's instead. */
static void target(double *ah, double *ad)
{
    if (!targets)
        return;
    if (!loading ? fwrite(ah, sizeof *ah, 1, targets) != 1 ||
                       fwrite(ad, sizeof *ad, 1, targets) != 1
                 : fread(ah, sizeof *ah, 1, targets) != 1 ||
                       fread(ad, sizeof *ad, 1, targets) != 1) {
        fprintf(stderr, "pmbench_inv_diff: targets' file: %s failed after %ld calls\n",
                loading ? "read" : "write", n_calls);
        exit(2);
    }
}

static unsigned long long bits_of(double x)
{
    unsigned long long u;
    memcpy(&u, &x, sizeof u);
    return u;
}

static void put(const char *sample, long idx, char call, pm_status st, double t, double d)
{
    printf("%s %ld %c %d %lu %016llx %016llx\n", sample, idx, call, (int)st, probe_count,
           bits_of(t), bits_of(d));
    n_calls++;
}

static const double PRESET = -1.2345678901234567e300; /* (outputs before a call) */

static pm_status cold(const pm_model *m, const pm_context *c, double ha, double dec, int side,
                      double *t, double *d)
{
    *t = *d = PRESET;
    probe_count = 0;
    return pm_model_invert(m, c, ha, dec, side, t, d);
}

static pm_status near(const pm_model *m, const pm_context *c, double ha, double dec, double sh,
                      double sd, double *t, double *d)
{
    *t = *d = PRESET;
    probe_count = 0;
    return pm_model_invert_near(m, c, ha, dec, sh, sd, t, d);
}

static void hard_sample(int scale, const char *name, int n_models)
{
    tu_rng r;
    int i, j;
    tu_seed(&r, 1000 + (unsigned long long)scale);
    for (i = 0; i < n_models; i++) {
        pm_model m;
        pm_context c;
        const pm_context *ctx;
        if (hc_random_model(&m, &r, scale) != 0)
            continue; /* (refused by the library: the same in both builds) */
        for (j = 0; j < 40; j++) {
            double ha, dec, eh, ed, sh, sd, sol[2];
            int side;
            pm_status st;
            hc_random_context(&c, &r);
            ctx = m.needs_ctx || tu_uniform(&r) < 0.5 ? &c : NULL;
            hc_hard_target(&m, &r, &ha, &dec);
            side = tu_uniform(&r) < 0.5 ? PM_SIDE_NORMAL : PM_SIDE_FLIPPED;
            st = cold(&m, ctx, ha, dec, side, &eh, &ed);
            put(name, i * 40L + j, 'c', st, eh, ed);
            sol[0] = eh;
            sol[1] = ed;
            /* (the start from the result itself: its bits are compared) */
            hc_hard_start(&r, st >= 0 ? sol : NULL, &sh, &sd);
            st = near(&m, ctx, ha, dec, sh, sd, &eh, &ed);
            put(name, i * 40L + j, 'n', st, eh, ed);
        }
    }
}

/* A realistic model with isotropic terms within iso, harmonic within an,
** and 0-3 AUX terms within 1'. */
static int aux_model(pm_model *m, tu_rng *r, double iso, double an)
{
    int order = (int)(tu_uniform(r) * 3), j, n_aux;
    if (pm_model_init(m, PM_MOUNT_EQUATORIAL, order) != PM_OK)
        return -1;
    for (j = 0; j < m->n_terms; j++)
        m->coef[j] = (2 * tu_uniform(r) - 1) * (j < 6 ? iso : an);
    if (pm_model_prepare(m) != PM_OK)
        return -1;
    n_aux = (int)(tu_uniform(r) * 4);
    for (j = 0; j < n_aux; j++) {
        pm_term t;
        memset(&t, 0, sizeof t);
        t.kind = PM_TERM_AUX;
        t.k = (unsigned char)(1 + (int)(tu_uniform(r) * 6));
        t.aux = (unsigned char)(tu_uniform(r) * (PM_AUX_USER + PM_MAX_AUX));
        t.param = tu_gauss(r);
        if (pm_model_add_term(m, &t, (2 * tu_uniform(r) - 1) * 60 * ARCSEC / 10, NULL) != PM_OK)
            return -1;
    }
    return 0;
}

static void real_sample(const char *name, unsigned long long seed, double iso, double an,
                        long n)
{
    static const double offs[3] = {1e-5, 1e-3, 0.5 * DEG};
    tu_rng r;
    long i;
    pm_model m;
    pm_context c;
    tu_seed(&r, seed);
    for (i = 0; i < n; i++) {
        double t, d, ah, ad, eh, ed;
        int side, kind, k;
        pm_status st;
        if (i % 8 == 0 && aux_model(&m, &r, iso, an) != 0)
            abort();
        c.temp_c = tu_gauss(&r) * 10;
        c.time_h = tu_gauss(&r) * 5;
        c.pier = 0;
        c.dir = tu_uniform(&r) < 0.5 ? 1 : -1;
        for (k = 0; k < PM_MAX_AUX; k++)
            c.aux[k] = tu_gauss(&r);
        (void)hc_real_position(&m, &r, 90 * DEG, 0, &side, &t, &d, &kind);
        if (pm_model_apply(&m, &c, t, d, &ah, &ad) != PM_OK)
            abort();
        target(&ah, &ad);
        st = cold(&m, &c, ah, ad, side, &eh, &ed);
        put(name, i, 'c', st, eh, ed);
        for (k = 0; k < 3; k++) {
            double a = tu_uniform(&r) * 2 * M_PI;
            st = near(&m, &c, ah, ad, t + offs[k] * cos(a), d + offs[k] * sin(a), &eh, &ed);
            put(name, i, 'n', st, eh, ed);
        }
    }
}

int main(int argc, char **argv)
{
    long scale = argc >= 2 ? atol(argv[1]) : 1;
    if (scale < 1 || argc == 3 || argc > 4 ||
        (argc == 4 && strcmp(argv[2], "save") != 0 && strcmp(argv[2], "load") != 0)) {
        fprintf(stderr, "usage: pmbench_inv_diff [SCALE [save|load FILE]]\n");
        return 2;
    }
    if (argc == 4) {
        loading = argv[2][0] == 'l';
        targets = fopen(argv[3], loading ? "rb" : "wb");
        if (!targets) {
            fprintf(stderr, "pmbench_inv_diff: cannot open %s\n", argv[3]);
            return 2;
        }
    }
    hard_sample(HC_SCALE_NORMAL, "hard_normal", (int)(400 * scale));
    hard_sample(HC_SCALE_LARGE, "hard_large", (int)(400 * scale));
    hard_sample(HC_SCALE_HUGE, "hard_huge", (int)(400 * scale));
    real_sample("real", 11, 10 * DEG, 10 * ARCSEC * 60, 36480 * scale);
    real_sample("small", 12, 10 * ARCSEC * 60, 15 * ARCSEC, 36480 * scale);
    printf("calls %ld\n", n_calls);
    if (targets) {
        char extra;
        if (loading && fread(&extra, 1, 1, targets) != 0) {
            fprintf(stderr, "pmbench_inv_diff: targets' file longer than the samples\n");
            return 2;
        }
        if (fclose(targets) != 0) {
            fprintf(stderr, "pmbench_inv_diff: targets' file: close failed\n");
            return 2;
        }
    }
    return 0;
}
