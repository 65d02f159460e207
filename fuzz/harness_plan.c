/*
**  harness_plan.c - fuzz target body: "which star next" (tools/lib/plan.h,
**  pmfit plan) on any run file, horizon file and star catalogue: the
**  readers of the last two (tools/lib/plan_inputs.cpp) are fuzzed here
**  only.  Then the predicted error of the targets found.
**
**  Input: two option bytes, then the files.
**     byte 0  bits 0-1  mount: German, fork, alt-az, German
**             bit 2     order 1 (else 0)
**             bit 3     D-optimal (else I-optimal)
**             bits 4-5  pier-side rule: as the run, the meridian, both, as the run
**             bit 6     slew-time weighting (1 deg/s)
**             bit 7     added terms "refraction,ha_periodic:144"
**     byte 1  bits 0-1  the rest is: the run file; a horizon file (nothing
**                       taken yet); a catalogue (LST 3.5 h, nothing taken);
**                       run, horizon and catalogue separated by lines "%%"
**                       (an empty part: none)
**             bits 2-4  k = 1..8 targets
**             bits 5-7  latitude: 47, -33, 0, 89.5, -89.9, 60, 20, -65
**  At most PMFZ_PLAN_MAX bytes (longer inputs are skipped): one input stays
**  well inside the 10 s limit.
**
**  Invariants: pmplan_next returns -1 with a message (non-empty,
**  terminated) or 0..k targets, each with finite angles, an elevation in
**  [-90, 90] and at or above the horizon given (min_el_deg), the side +1 or
**  -1 (0 for alt-az; with a run, the run's mount decides: plan.h), a
**  predicted error >= 0 or NaN, a terminated name and a slew time >= 0 or
**  NaN; the error before them >= 0 or NaN.  Then pmplan_predicted on them
**  returns 0 with a mean >= 0 (or NaN) or -1 with a message.
*/
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "plan.h"
#include "harness.h"
#include "fz_file.h"

#define PMFZ_PLAN_MAX 16384
#define PL_PARTS 3

static int pl_fail(const char *what)
{
    fprintf(stderr, "fuzz_plan: invariant broken: %s\n", what);
    return 1;
}

static int pl_msg_ok(const char *err, size_t n)
{
    size_t len = strnlen(err, n);
    return len > 0 && len < n;
}

static int pl_nonneg_or_nan(double x)
{
    return isnan(x) || (isfinite(x) && x >= 0);
}

/* Split p[0..n) at lines "%%" into up to three parts (start, length). */
static int pl_split(const unsigned char *p, size_t n, size_t start[PL_PARTS],
                    size_t len[PL_PARTS])
{
    size_t i = 0, s = 0;
    int k = 0;
    while (k < PL_PARTS - 1 && i + 3 <= n) {
        if ((i == 0 || p[i - 1] == '\n') && p[i] == '%' && p[i + 1] == '%' &&
            (i + 2 == n || p[i + 2] == '\n')) {
            start[k] = s;
            len[k] = i - s;
            k++;
            i += 3;
            s = i;
            continue;
        }
        i++;
    }
    start[k] = s;
    len[k] = n > s ? n - s : 0;
    return k + 1;
}

static int pl_targets_ok(const pmplan_options *o, int have_run, const pmplan_target *t, int n,
                         double before)
{
    int i;
    if (!pl_nonneg_or_nan(before))
        return pl_fail("the error before the targets neither >= 0 nor NaN");
    for (i = 0; i < n; i++) {
        const pmplan_target *x = &t[i];
        if (!isfinite(x->x_deg) || !isfinite(x->y_deg) || !isfinite(x->el_deg) ||
            x->el_deg < -90 || x->el_deg > 90)
            return pl_fail("a target's angles not finite, or its elevation beyond +-90");
        if (x->el_deg < o->min_el_deg - 1e-9)
            return pl_fail("a target below the horizon given");
        /* (with a run, the run's mount: plan.h) */
        if (have_run ? (x->side < -1 || x->side > 1)
                     : o->altaz ? x->side != 0 : (x->side != 1 && x->side != -1))
            return pl_fail("a target's side not +1/-1 (0 for alt-az)");
        if (!pl_nonneg_or_nan(x->after_arcsec) || !pl_nonneg_or_nan(x->slew_s))
            return pl_fail("a predicted error or slew time neither >= 0 nor NaN");
        if (strnlen(x->name, sizeof x->name) == sizeof x->name)
            return pl_fail("a target's name not terminated");
    }
    return 0;
}

int pmfz_plan(const unsigned char *data, size_t size)
{
    static const double lats[8] = {47, -33, 0, 89.5, -89.9, 60, 20, -65};
    static const int sides[4] = {PMPLAN_SIDES_RUN, PMPLAN_SIDES_MERIDIAN, PMPLAN_SIDES_BOTH,
                                 PMPLAN_SIDES_RUN};
    char paths[PL_PARTS][64], err[512];
    int fds[PL_PARTS] = {-1, -1, -1};
    size_t start[PL_PARTS] = {0, 0, 0}, len[PL_PARTS] = {0, 0, 0};
    pmplan_target t[8];
    pmplan_options o;
    double before = 0, mean = 0;
    const unsigned char *p;
    unsigned b0, b1;
    int k, n, i, bad = 0, layout;
    if (size < 2 || size - 2 > PMFZ_PLAN_MAX)
        return 0;
    b0 = data[0];
    b1 = data[1];
    p = data + 2;
    pmplan_options_default(&o);
    o.altaz = (b0 & 3u) == 2;
    o.gem = (b0 & 3u) != 1;
    o.order = (int)((b0 >> 2) & 1u);
    o.d_optimal = (int)((b0 >> 3) & 1u);
    o.sides = sides[(b0 >> 4) & 3u];
    if (b0 & 64u)
        o.slew_rate_deg_s = 1;
    if (b0 & 128u)
        o.adds = "refraction,ha_periodic:144";
    k = 1 + (int)((b1 >> 2) & 7u);
    o.latitude_deg = lats[(b1 >> 5) & 7u];
    layout = (int)(b1 & 3u);
    if (layout == 3) {
        pl_split(p, size - 2, start, len);
    } else {
        start[layout] = 0;
        len[layout] = size - 2;
    }
    if (layout == 2 || (layout == 3 && len[2] > 0))
        o.lst_h = 3.5;
    for (i = 0; i < PL_PARTS; i++) {
        if (len[i] == 0 && !(layout == i))
            continue;
        fds[i] = pmfz_memfile(p + start[i], len[i], paths[i], sizeof paths[i]);
        if (fds[i] < 0)
            goto done;
    }
    if (fds[1] >= 0)
        o.horizon_path = paths[1];
    if (fds[2] >= 0)
        o.catalogue_path = paths[2];
    memset(t, 0xa5, sizeof t); /* (nothing read before it is written) */
    err[0] = '\0';
    n = pmplan_next(fds[0] >= 0 ? paths[0] : NULL, &o, k, t, &before, err, sizeof err);
    if (getenv("PMFZ_VERBOSE")) /* (which path a seed takes) */
        fprintf(stderr, "fuzz_plan: %d of %d targets%s%s\n", n, k, n < 0 ? ": " : "",
                n < 0 ? err : "");
    if (n == -1) {
        if (!pl_msg_ok(err, sizeof err))
            bad = pl_fail("an error without a (terminated) message");
    } else if (n < 0 || n > k) {
        bad = pl_fail("pmplan_next returned neither -1 nor 0..k");
    } else {
        bad = pl_targets_ok(&o, fds[0] >= 0, t, n, before);
        if (!bad && n > 0) {
            err[0] = '\0';
            i = pmplan_predicted(&o, t, n, &mean, err, sizeof err);
            if (i == 0 ? !pl_nonneg_or_nan(mean) : (i != -1 || !pl_msg_ok(err, sizeof err)))
                bad = pl_fail("pmplan_predicted: neither a mean >= 0 (or NaN) nor -1 with a "
                              "message");
        }
    }
done:
    for (i = 0; i < PL_PARTS; i++)
        if (fds[i] >= 0)
            close(fds[i]);
    return bad;
}
