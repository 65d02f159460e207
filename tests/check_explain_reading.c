/*
**  check_explain_reading.c - explain, second generation (issue 15, items
**  2-4): what the baseline holds, confusable effects, weak effects in
**  company.
**
**  - The physical reading of the baseline (polar axis, non-perpendicularity,
**    collimation, indices, the tube-flexure part of the order-1 terms) read
**    back from a run of an independent numpy gimbal (tests/ref/flip_gem.py)
**    within 3 sigma of its truth, and a simulated sag read back within
**    3 sigma on German, fork and alt-az mounts.
**  - "Order 0 + one term predicts as well as order 1" is said where the
**    order-1 terms are that term, never where they are generic.
**  - Refraction and tube flexure over a sky above 35 deg are confusable:
**    the truth is named first or as an alternative (with Delta BIC < 6 and
**    the observation that would separate them); over a sky down to 10 deg
**    they are not, and no alternative is offered.
**  - Two weak effects: where neither alone passes, the pair does; the
**    detection rate against size, pairs on and off (a curve, printed).
**  - The backward pass: on independent gimbal runs (tests/ref/
**    prune_case.py) a time drift found first is withdrawn once the
**    temperature it followed is in, and the findings are re-described
**    without it (the sag within 25% of the truth); higher_order against an
**    order-0 baseline is withdrawn for the tube flexure it held.
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm.h"
#include "explain.h"
#include "simulate.h"
#include "testutil.h"
#include "tu_tool.h"

#define NSIG 3.0

static char g_dir[256];

static void make_dir(void)
{
    if (!g_dir[0])
        tu_tmpdir(g_dir, "pm_reading_");
}

static const pmx_reading *reading(const pmx_result *r, const char *what)
{
    int k;
    for (k = 0; k < r->n_readings; k++)
        if (!strcmp(r->readings[k].what, what))
            return &r->readings[k];
    return NULL;
}

/* The index of the (last) finding of this effect, -1 if none. */
static int finding_index(const pmx_result *r, const char *effect)
{
    int k, at = -1;
    for (k = 0; k < r->n_findings; k++)
        if (!strcmp(r->findings[k].effect, effect))
            at = k;
    return at;
}

/* How many of the withdrawn findings are of this effect. */
static int withdrawn_count(const pmx_result *r, const char *effect)
{
    int k, n = 0;
    for (k = 0; k < r->n_withdrawn; k++)
        n += !strcmp(r->withdrawn[k], effect);
    return n;
}

static void check_reading(const pmx_result *r, const char *what, double truth)
{
    const pmx_reading *x = reading(r, what);
    ck_assert_msg(x != NULL, "no reading %s", what);
    printf("check_explain_reading: flip_gem %-22s %10.3f +- %.3f %s (truth %.3f, %.1f sigma)\n",
           what, x->value, x->error, x->unit, truth, fabs(x->value - truth) / x->error);
    ck_assert_msg(fabs(x->value - truth) <= NSIG * x->error,
                  "%s: %.4f +- %.4f, truth %.4f", what, x->value, x->error, truth);
}

/* explain a run of tests/data with options o (pmx_options_default where
** NULL); a failure to explain it fails the test. */
static void explain_data(const char *name, const pmx_options *o, pmx_result *r)
{
    const char *top = getenv("PM_TOP");
    char path[512], err[512];
    pmx_options d;
    if (!o) {
        pmx_options_default(&d);
        o = &d;
    }
    snprintf(path, sizeof path, "%s/tests/data/%s", top ? top : ".", name);
    ck_assert_msg(pmx_explain_opts(path, o, r, err, sizeof err) == 0, "%s: %s", name, err);
}

/* The independent gimbal: IH 2.5 deg, ID -0.3 deg, CH 40", NP -25",
** MA 90" (axis east of the pole), ME -60" (below it), sag 15" toward the
** zenith.  Indices are read as true minus encoder: -IH, -ID. */
START_TEST(test_reading_flip_gem)
{
    const char *top = getenv("PM_TOP");
    char path[512], err[512];
    pmx_result r;
    snprintf(path, sizeof path, "%s/tests/data/flip_gem_pm180.dat", top ? top : ".");
    ck_assert_msg(pmx_explain(path, 1, 0.01, &r, err, sizeof err) == 0, "%s", err);
    check_reading(&r, "polar_altitude", -1.0);
    check_reading(&r, "polar_azimuth_west", -1.5);
    check_reading(&r, "non_perpendicularity", -25);
    check_reading(&r, "collimation", 40);
    check_reading(&r, "index_axis1", -9000);
    check_reading(&r, "index_axis2", 1080);
    check_reading(&r, "tube_flexure_in_order1", 15);
    /* its order-1 terms are the sag, and explain says so */
    ck_assert_int_eq(r.physical_reading, 1);
    ck_assert_int_eq(r.n_findings, 0);
}
END_TEST

static void spec_for(pmsim_spec *s, int mount, int gem, unsigned long long seed, double aniso)
{
    tu_rng g;
    int i;
    pmsim_default(s);
    s->n = 150 + (long)(seed % 4) * 50;
    s->seed = seed;
    s->latitude_deg = mount == PM_MOUNT_ALTAZ ? 31.7 : 20 + (double)(seed % 5) * 9;
    s->noise_arcsec = 0.5 + (double)(seed % 3) * 0.75;
    s->gem = gem;
    ck_assert_int_eq(pm_model_init(&s->truth, mount, 1), PM_OK);
    s->truth.latitude = s->latitude_deg * DEG;
    tu_seed(&g, seed * 17 + 3);
    for (i = 0; i < 6; i++)
        s->truth.coef[i] = (2 * tu_uniform(&g) - 1) * (i == 2 || i == 4 ? 3 * 3600 : 300) * ARCSEC;
    for (i = 6; i < s->truth.n_terms; i++)
        s->truth.coef[i] = (2 * tu_uniform(&g) - 1) * aniso * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&s->truth), PM_OK);
}

static void explain_spec(pmsim_spec *s, const pmx_options *o, pmx_result *r)
{
    char path[300], err[512];
    make_dir();
    snprintf(path, sizeof path, "%s/run.dat", g_dir);
    ck_assert_msg(pmsim_write(s, path, NULL, err, sizeof err) == 0, "%s", err);
    ck_assert_msg(pmx_explain_opts(path, o, r, err, sizeof err) == 0, "%s", err);
}

/* A simulated sag on the three kinds of mount, sizes from -25" to 25",
** isotropic terms of degrees: read back within 3 sigma in every run. */
START_TEST(test_reading_simulated_sag)
{
    static const double sizes[] = {-25, -9, 4, 12, 25};
    static const int kinds[3][2] = {{PM_MOUNT_EQUATORIAL, 1}, {PM_MOUNT_EQUATORIAL, 0},
                                    {PM_MOUNT_ALTAZ, 0}};
    int k, j, runs = 0;
    double worst = 0;
    pmx_options o;
    pmx_options_default(&o);
    for (k = 0; k < 3; k++)
        for (j = 0; j < 5; j++) {
            pmsim_spec s;
            pmx_result r;
            char err[256];
            const pmx_reading *x;
            unsigned long long seed = 300 + 11 * (unsigned long long)(5 * k + j);
            spec_for(&s, kinds[k][0], kinds[k][1], seed, 0);
            ck_assert_msg(pmsim_add_effect(&s, "tube_flexure", sizes[j], 0, seed, err, sizeof err) == 0,
                          "%s", err);
            explain_spec(&s, &o, &r);
            x = reading(&r, "tube_flexure_in_order1");
            ck_assert_msg(x != NULL, "kind %d: no sag reading", k);
            if (fabs(x->value - sizes[j]) / x->error > worst)
                worst = fabs(x->value - sizes[j]) / x->error;
            ck_assert_msg(fabs(x->value - sizes[j]) <= NSIG * x->error,
                          "kind %d seed %llu: sag %.3f +- %.3f, truth %.1f", k, seed, x->value,
                          x->error, sizes[j]);
            runs++;
        }
    printf("check_explain_reading: simulated sag read back in %d runs (GEM, fork, alt-az), "
           "worst %.2f sigma\n", runs, worst);
}
END_TEST

/* "the order-1 terms are that one term" only where it is so: a pure sag
** (order-0 truth + tube flexure) vs generic order-1 terms of 15". */
START_TEST(test_physical_reading_only_when_true)
{
    int k, said_sag = 0, said_generic = 0;
    pmx_options o;
    pmx_options_default(&o);
    for (k = 0; k < 10; k++) {
        pmsim_spec s;
        pmx_result r;
        char err[256];
        spec_for(&s, PM_MOUNT_EQUATORIAL, 1, 500 + (unsigned long long)k, 0);
        ck_assert(pmsim_add_effect(&s, "tube_flexure", 10, 0, 1, err, sizeof err) == 0);
        explain_spec(&s, &o, &r);
        said_sag += r.physical_reading;
        spec_for(&s, PM_MOUNT_EQUATORIAL, 1, 600 + (unsigned long long)k, 15);
        explain_spec(&s, &o, &r);
        said_generic += r.physical_reading;
    }
    printf("check_explain_reading: 'order 0 + one term' said for %d/10 pure sags, %d/10 generic "
           "order-1 mounts\n", said_sag, said_generic);
    ck_assert_int_ge(said_sag, 8);
    ck_assert_int_eq(said_generic, 0);
}
END_TEST

/* Refraction or tube flexure hidden from an order-0 baseline.  Over a sky
** above el_limit: how often the truth is named first, named only as an
** alternative, or missed; alternatives are well formed. */
static void confusable(const char *truth, double el_limit, int *first, int *as_alt, int *alts,
                       int *runs)
{
    const char *other = !strcmp(truth, "refraction") ? "tube_flexure" : "refraction";
    int k, j;
    pmx_options o;
    pmx_options_default(&o);
    o.order = 0;
    *first = *as_alt = *alts = *runs = 0;
    for (k = 0; k < 20; k++) {
        pmsim_spec s;
        pmx_result r;
        char err[256];
        const pmx_finding *f;
        int has_other = 0;
        pmsim_default(&s);
        s.n = 80 + 20 * (k % 5);
        s.seed = 700 + (unsigned long long)k;
        s.el_limit_deg = el_limit;
        s.noise_arcsec = 1;
        ck_assert_int_eq(pm_model_init(&s.truth, PM_MOUNT_EQUATORIAL, 0), PM_OK);
        s.truth.latitude = s.latitude_deg * DEG;
        s.truth.coef[2] = 600 * ARCSEC;
        s.truth.coef[4] = -300 * ARCSEC;
        s.truth.coef[5] = 30 * ARCSEC;
        ck_assert_int_eq(pm_model_prepare(&s.truth), PM_OK);
        ck_assert(pmsim_add_effect(&s, truth, 2.5, 0, 1, err, sizeof err) == 0);
        explain_spec(&s, &o, &r);
        (*runs)++;
        if (r.n_findings == 0)
            continue;
        f = &r.findings[0];
        for (j = 0; j < f->n_alternatives; j++) {
            ck_assert_str_ne(f->alternatives[j].effect, f->effect);
            ck_assert(f->alternatives[j].delta_bic >= 0 &&
                      (f->alternatives[j].smooth || f->alternatives[j].delta_bic < 6));
            ck_assert(strlen(f->alternatives[j].separate_by) > 10);
            if (!strcmp(f->alternatives[j].effect, other) || !strcmp(f->alternatives[j].effect, truth))
                has_other = 1;
        }
        if (!strcmp(f->effect, truth))
            (*first)++;
        else if (has_other)
            (*as_alt)++;
        *alts += has_other;
    }
}

START_TEST(test_alternatives_confusable)
{
    static const char *names[2] = {"refraction", "tube_flexure"};
    int k;
    for (k = 0; k < 2; k++) {
        int first, as_alt, alts, runs;
        confusable(names[k], 35, &first, &as_alt, &alts, &runs);
        printf("check_explain_reading: %s hidden, sky above 35 deg: named first %d/%d, only as "
               "the alternative %d, an alternative offered in %d\n",
               names[k], first, runs, as_alt, alts);
        /* the truth is never dropped silently */
        ck_assert_int_ge(first + as_alt, 19);
        /* and the tool does not always hedge: the evidence decides often */
        ck_assert_int_lt(alts, runs);
        confusable(names[k], 10, &first, &as_alt, &alts, &runs);
        printf("check_explain_reading: %s hidden, sky down to 10 deg: named first %d/%d, an "
               "alternative offered in %d\n", names[k], first, runs, alts);
        ck_assert_int_ge(first, 19);
        ck_assert_int_le(alts, 2);
    }
}
END_TEST

/* Two weak effects hidden together from an order-1 baseline, each of a
** size that alone adds q sigma0^2 of variance (calibrated per run as in
** check_explain.c).  Returns how many runs named both, pairs on and off,
** and how many named anything else. */
typedef struct pair_case {
    const char *a, *b;     /* pmsim effects */
    const char *na, *nb;   /* the names explain gives them */
} pair_case;

static void pair_spec(pmsim_spec *s, const pair_case *c, unsigned long long seed, double sa,
                      double sb)
{
    char err[256];
    spec_for(s, PM_MOUNT_EQUATORIAL, 1, seed, 10);
    s->n = 250;
    s->noise_arcsec = 1;
    if (sa > 0)
        ck_assert_msg(pmsim_add_effect(s, c->a, sa, 40, seed, err, sizeof err) == 0, "%s", err);
    if (sb > 0)
        ck_assert_msg(pmsim_add_effect(s, c->b, sb, 110, seed, err, sizeof err) == 0, "%s", err);
}

static int named(const pmx_result *r, const char *name)
{
    int k;
    for (k = 0; k < r->n_findings; k++)
        if (!strcmp(r->findings[k].effect, name) || !strcmp(r->findings[k].with, name))
            return 1;
    return 0;
}

static int named_other(const pmx_result *r, const pair_case *c)
{
    int k;
    for (k = 0; k < r->n_findings; k++)
        if (strcmp(r->findings[k].effect, c->na) && strcmp(r->findings[k].effect, c->nb))
            return 1;
    return 0;
}

static void print_findings(const pair_case *c, unsigned long long seed, double q,
                           const pmx_result *r)
{
    int k;
    printf("check_explain_reading: %s + %s seed %llu q %.2f: named", c->na, c->nb, seed, q);
    for (k = 0; k < r->n_findings; k++)
        printf(" %s%s%s (fap %.2g)", r->findings[k].effect, r->findings[k].with[0] ? " with " : "",
               r->findings[k].with, r->findings[k].false_alarm_probability);
    printf("\n");
}

#define PAIR_SEEDS 20
#define PAIR_QS 5

static void pair_curve(const pair_case *c)
{
    static const double qs[PAIR_QS] = {0.02, 0.04, 0.06, 0.09, 0.14};
    int both[2][PAIR_QS] = {{0}}, other[PAIR_QS] = {0}, via_pair[PAIR_QS] = {0};
    int k, j, p;
    pmx_options o;
    pmx_options_default(&o);
    for (k = 0; k < PAIR_SEEDS; k++) {
        unsigned long long seed = 900 + 7 * (unsigned long long)k;
        pmsim_spec s;
        pmx_result r0, ra, rb;
        double s0, ka, kb;
        pair_spec(&s, c, seed, 0, 0);
        explain_spec(&s, &o, &r0);
        s0 = r0.base_sigma_arcsec;
        pair_spec(&s, c, seed, 3, 0);
        explain_spec(&s, &o, &ra);
        pair_spec(&s, c, seed, 0, 3);
        explain_spec(&s, &o, &rb);
        ka = (ra.base_sigma_arcsec * ra.base_sigma_arcsec - s0 * s0) / 9;
        kb = (rb.base_sigma_arcsec * rb.base_sigma_arcsec - s0 * s0) / 9;
        ck_assert(ka > 0 && kb > 0);
        for (j = 0; j < PAIR_QS; j++) {
            pair_spec(&s, c, seed, sqrt(qs[j] * s0 * s0 / ka), sqrt(qs[j] * s0 * s0 / kb));
            for (p = 0; p < 2; p++) {
                pmx_result r;
                o.pairs = p;
                explain_spec(&s, &o, &r);
                both[p][j] += named(&r, c->na) && named(&r, c->nb);
                if (p && named_other(&r, c))
                    print_findings(c, seed, qs[j], &r);
                if (p) {
                    other[j] += named_other(&r, c);
                    via_pair[j] += r.n_findings > 0 && r.findings[0].with[0] != 0;
                }
            }
            o.pairs = 1;
        }
    }
    for (j = 0; j < PAIR_QS; j++) {
        printf("check_explain_reading: %s + %s, each alone +%2.0f%% variance (together sigma x "
               "%.3f): both named %2d/%d with pairs (%d as a pair), %2d/%d singles only; "
               "another effect named in %d\n",
               c->na, c->nb, 100 * qs[j], sqrt(1 + 2 * qs[j]), both[1][j], PAIR_SEEDS,
               via_pair[j], both[0][j], PAIR_SEEDS, other[j]);
    }
    fflush(stdout);
    /* Where both sit below the single threshold (q = 2%) the pair search
    ** finds more.  Above it the two modes need not compare so: with pairs
    ** on, each single's false-alarm probability counts the pairs the step
    ** may try (the step's K, docs/explain.md step 4), so singles-only,
    ** which tries fewer tests, has the lower threshold per test (before
    ** the shared K, pairs on took alpha twice over and found at least as
    ** many at every q). */
    ck_assert_int_ge(both[1][0], both[0][0]);
    for (j = 0; j < PAIR_QS; j++)
        ck_assert_int_le(other[j], 1);
    /* where the two together inflate sigma by 13% (q = 0.14), >= 90% */
    ck_assert_int_ge(both[1][PAIR_QS - 1], (9 * PAIR_SEEDS + 9) / 10);
}

static const pair_case PAIRS[] = {{"refraction", "temperature", "refraction", "temperature"},
                                  {"hysteresis", "i@W", "hysteresis", "pier_side"}};

START_TEST(test_pairs_curve)
{
    pair_curve(&PAIRS[_i]);
}
END_TEST

START_TEST(test_backward_pass)
{
    pmx_options o;
    pmx_result r;
    int sag, temp;
    pmx_options_default(&o);
    o.order = 0;
    explain_data("indep_temp_sag_fork.dat", &o, &r);
    ck_assert_int_eq(r.n_withdrawn, 1);
    ck_assert_str_eq(r.withdrawn[0], "time_drift");
    ck_assert_int_eq(finding_index(&r, "time_drift"), -1);
    sag = finding_index(&r, "tube_flexure");
    temp = finding_index(&r, "temperature");
    ck_assert_int_eq(r.n_findings, 2);
    ck_assert(sag >= 0 && temp >= 0);
    printf("check_explain_reading: backward pass: time_drift withdrawn; sag %.2f\" (truth 10.00\"), "
           "temperature %.2f\"/C (truth 3.06)\n", r.findings[sag].amplitude_arcsec,
           r.findings[temp].amplitude_arcsec);
    ck_assert(fabs(r.findings[sag].amplitude_arcsec - 10.0) <= 2.5);
    /* without the backward pass's rerun the drift stays and the
    ** temperature reads -6.1 on axis 1: the rerun is what this checks */
    ck_assert(fabs(r.findings[temp].amplitude_arcsec - 3.06) <= 0.25 * 3.06);

    /* a German mount's sag and temperature drift against an order-0
    ** baseline: higher_order (which holds the sag exactly) is found first
    ** and withdrawn for tube flexure */
    explain_data("indep_temp_sag_gem.dat", &o, &r);
    ck_assert_int_eq(r.n_withdrawn, 1);
    ck_assert_str_eq(r.withdrawn[0], "higher_order");
    ck_assert_int_eq(finding_index(&r, "higher_order"), -1);
    sag = finding_index(&r, "tube_flexure");
    temp = finding_index(&r, "temperature");
    ck_assert(sag >= 0 && temp >= 0);
    printf("check_explain_reading: backward pass: higher_order withdrawn for tube flexure; sag "
           "%.2f\" (truth 2.80\")\n", r.findings[sag].amplitude_arcsec);
    ck_assert(fabs(r.findings[sag].amplitude_arcsec - 2.80) <= 0.25 * 2.80);
}
END_TEST

/* A degree-2 distortion of an independent gimbal (tests/ref/generic_case.py)
** that a periodic term of a few cycles half holds: order 2 holds all of it
** and the periodic term nothing beyond, so higher_order is the reading and
** the periodic term at most its alternative. */
START_TEST(test_generic_reading)
{
    static const struct { const char *file; double noise; } C[] = {
        {"indep_ho_altaz.dat", 1.6181809022483622}, {"indep_ho_gem.dat", 2.872469262742089}};
    pmx_result r;
    const pmx_finding *f;
    int k;
    explain_data(C[_i].file, NULL, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    printf("check_explain_reading: %s: first finding %s, sigma %.3f\" -> %.3f\" (noise %.3f\"), "
           "%d alternative(s)%s%s\n", C[_i].file, f->effect, r.base_sigma_arcsec,
           f->sigma_after_arcsec, C[_i].noise, f->n_alternatives,
           f->n_alternatives ? ": " : "", f->n_alternatives ? f->alternatives[0].effect : "");
    ck_assert_str_eq(f->effect, "higher_order");
    /* the distortion is degree 2: order 2 leaves the noise (5%: about
    ** 2.5 / sqrt(2 dof) for these runs' degrees of freedom) */
    ck_assert(fabs(f->sigma_after_arcsec / C[_i].noise - 1) <= 0.05);
    for (k = 1; k < r.n_findings; k++)
        ck_assert_msg(strcmp(r.findings[k].effect, "ha_periodic") &&
                      strcmp(r.findings[k].effect, "dec_periodic"),
                      "the periodic term came back as finding %d", k + 1);
}
END_TEST

/* The generic reading where the periodic family is partly inside order 2
** (explain_campaign.py --seed 9's single_higher_order_gem_01; the command in
** the file's first line): a degree-2 distortion of 2.1" on 97 points of a
** German mount, 0.30" of noise.  A two-cycle declination term takes part of
** it first (false-alarm 1e-10); its e' cos 2dec is a combination of the
** degree-2 terms on this sky, so the joint fit with order 2 was singular
** and the periodic reading was kept, with a pier-side flexure after it
** (sigma 0.386").  Dropping what order 2 holds exactly, the periodic term
** adds nothing to order 2, which fits to 0.323": higher_order, first and
** alone. */
START_TEST(test_generic_reading_inside)
{
    const double noise = 0.30394888917754725;
    pmx_result r;
    const pmx_finding *f;
    int k;
    explain_data("indep_ho_gem_dec2.dat", NULL, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    printf("check_explain_reading: indep_ho_gem_dec2.dat: first finding %s, sigma %.3f\" -> "
           "%.3f\" (noise %.3f\"), %d finding(s)\n", f->effect, r.base_sigma_arcsec,
           f->sigma_after_arcsec, noise, r.n_findings);
    ck_assert_str_eq(f->effect, "higher_order");
    /* order 2 leaves the noise: within 2.5 / sqrt(2 dof), 148 degrees of
    ** freedom */
    ck_assert(fabs(f->sigma_after_arcsec / noise - 1) <= 2.5 / sqrt(2.0 * 148));
    for (k = 1; k < r.n_findings; k++)
        ck_assert_msg(strcmp(r.findings[k].effect, "dec_periodic") &&
                      strcmp(r.findings[k].effect, "pier_side"),
                      "%s came back as finding %d", r.findings[k].effect, k + 1);
}
END_TEST

/* The case the generic reading does not take (tests/ref/generic_case.py):
** a degree-2 distortion whose declination part looks like 1.5 cycles of a
** 4-cycle term over the declinations sampled (the periodogram's peak; the
** full fit settles on 3, 1.1 cycles).  The periodic term passes
** far beyond alpha and order 2 adds nothing significant beside it, so the
** two-term reading is kept -- but order 2 holds all it explains and the
** run cannot show the shape repeats: higher_order must be offered beside
** it as the smooth alternative (any Delta BIC), with the axis range as the
** observation that separates them. */
START_TEST(test_smooth_alternative)
{
    pmx_result r;
    const pmx_finding *f;
    int j, smooth = -1;
    explain_data("indep_ho_fork_dec.dat", NULL, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    for (j = 0; j < f->n_alternatives; j++)
        if (f->alternatives[j].smooth)
            smooth = j;
    printf("check_explain_reading: indep_ho_fork_dec.dat: first finding %s (G %.0f), smooth "
           "alternative %s (Delta BIC %.1f)\n", f->effect, f->cycles_per_rev,
           smooth >= 0 ? f->alternatives[smooth].effect : "none",
           smooth >= 0 ? f->alternatives[smooth].delta_bic : 0.0);
    if (!strcmp(f->effect, "higher_order"))
        return; /* the generic reading named it outright: as good */
    ck_assert_str_eq(f->effect, "dec_periodic");
    ck_assert_msg(smooth >= 0, "no smooth alternative beside dec_periodic:%g", f->cycles_per_rev);
    ck_assert_str_eq(f->alternatives[smooth].effect, "higher_order");
    ck_assert(f->alternatives[smooth].delta_bic >= 6); /* not offered as a close one */
    ck_assert(f->alternatives[smooth].log10_fap < -2);  /* significant on its own */
    ck_assert_ptr_nonnull(strstr(f->alternatives[smooth].separate_by, "cycles of the period"));
}
END_TEST

/* A degree-2 distortion (explain_campaign.py's single_higher_order_gem_07,
** seed 1; the command in the file's first line) on a German mount's one
** pier side, declinations sampled over 102 deg: half a cycle of a two-cycle
** declination term fits it as a bump.  The full fit may settle a
** periodogram peak on a lower period than the search's floor, but not
** below one cycle over the range sampled (refine_floor): else the bump was
** named a periodic error of 2 cycles, 20" +- 5", without the smooth
** reading beside it. */
START_TEST(test_subcycle_not_periodic)
{
    pmx_result r;
    const pmx_finding *f;
    explain_data("indep_ho_gem_subcycle.dat", NULL, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    printf("check_explain_reading: indep_ho_gem_subcycle.dat: first finding %s (G %g), "
           "%d alternative(s)\n", f->effect, f->cycles_per_rev, f->n_alternatives);
    ck_assert_str_eq(f->effect, "higher_order");
}
END_TEST

/* Step 1 (docs/explain.md, "Composed as a gimbal"): the baseline's anisotropic terms composed as
** the mount's gimbal composes them.  Runs of the independent gimbal
** (tests/ref/indep_gen.py, commands in each file's first line) whose six
** gimbal parameters vary by 10' over the sky, nothing hidden: read to
** first order, 0.2-0.3" of second-order structure is left, which the
** search named (higher_order, a two-cycle azimuth term); composed, nothing.
** The noise-free run (0.001" of noise) measures the composition itself: it
** leaves 0.300" to first order, 0.185" composed without the three amounts
** a first-order fit cannot see (two null directions of the order-1 set and
** the order of the two tilts), 0.015" without the tilts' order, 0.0009"
** with all three: the independent gimbal, to its noise. */
START_TEST(test_composed_baseline)
{
    static const char *const noisy[] = {"indep_aniso600_gem.dat", "indep_aniso600_altaz.dat"};
    pmx_options o;
    pmx_result on, off;
    int j;
    pmx_options_default(&o);
    for (j = 0; j < 2; j++) {
        o.compose = 1;
        explain_data(noisy[j], &o, &on);
        o.compose = 0;
        explain_data(noisy[j], &o, &off);
        printf("check_explain_reading: %s: composed sigma %.3f\" (composition %.3f\" RMS), %d "
               "finding(s); first order sigma %.3f\", %d finding(s)%s%s\n", noisy[j],
               on.base_sigma_arcsec, on.compose_rms_arcsec, on.n_findings,
               off.base_sigma_arcsec, off.n_findings, off.n_findings ? ", first " : "",
               off.n_findings ? off.findings[0].effect : "");
        ck_assert_int_eq(on.n_findings, 0);
        ck_assert_int_ge(off.n_findings, 1);
        ck_assert(on.compose_rms_arcsec > 0.3 && on.compose_rms_arcsec < 3);
        ck_assert(off.compose_rms_arcsec == 0);
        ck_assert(on.base_sigma_arcsec < 0.33 && off.base_sigma_arcsec > 0.36);
    }
    o.compose = 1;
    explain_data("indep_aniso600_exact.dat", &o, &on);
    o.compose = 0;
    explain_data("indep_aniso600_exact.dat", &o, &off);
    printf("check_explain_reading: indep_aniso600_exact.dat (noise 0.001\"): sigma %.4f\" "
           "composed, %.4f\" to first order\n", on.base_sigma_arcsec, off.base_sigma_arcsec);
    ck_assert(on.base_sigma_arcsec < 0.003);
    ck_assert(off.base_sigma_arcsec > 0.25);
}
END_TEST

/* The composition read without what a hidden effect does to the baseline
** (docs/explain.md, "Composed as a gimbal"): a refraction hidden in a
** German mount of the independent gimbal with 10' of anisotropy and
** indices of 7-9 deg, at -65 deg latitude (a run of tests/ref/
** explain_campaign.py --seed 9 at its -10.44" and at -3"; the commands in
** the files' first lines).  The baseline's first-order terms take part of
** the refraction, and composed as a gimbal they gave 7.5" (at -10.44") and
** 2.94" (at -3") of "second order" where the run without the refraction
** composes to 1.02": that took half of the larger refraction, found at
** -5.41 +- 0.40" beside an invented higher order, and all of the smaller
** one, not found at all (read to first order it is found, -2.63").  Read
** from a baseline with a refraction term beside it (a nuisance term the
** correction leaves out), and again with what the search found, the
** composition is 1.02" in both and the refractions are found alone:
** -10.06 +- 0.37" and -2.61 +- 0.37". */
START_TEST(test_composed_with_findings)
{
    static const struct { const char *file; double truth; } C[] = {
        {"indep_refr_aniso600_gem.dat", -10.436707051601744},
        {"indep_refr3_aniso600_gem.dat", -3.0}};
    pmx_result r;
    int j;
    explain_data(C[_i].file, NULL, &r);
    printf("check_explain_reading: %s: composition %.3f\" RMS, %d finding(s)%s%s, %.2f +- %.2f\" "
           "(true %.2f\")\n", C[_i].file, r.compose_rms_arcsec, r.n_findings,
           r.n_findings ? ", first " : "", r.n_findings ? r.findings[0].effect : "",
           r.n_findings ? r.findings[0].amplitude_arcsec : 0.0,
           r.n_findings ? r.findings[0].amplitude_err_arcsec : 0.0, C[_i].truth);
    ck_assert_int_ge(r.n_findings, 1);
    ck_assert_str_eq(r.findings[0].effect, "refraction");
    ck_assert(fabs(fabs(r.findings[0].amplitude_arcsec) - fabs(C[_i].truth)) <
              3 * r.findings[0].amplitude_err_arcsec);
    for (j = 1; j < r.n_findings; j++)
        ck_assert_msg(strcmp(r.findings[j].effect, "higher_order") != 0,
                      "finding %d: higher_order invented", j + 1);
    ck_assert(r.compose_rms_arcsec > 0.3 && r.compose_rms_arcsec < 2);
}
END_TEST

/* The refraction beside the composition's baseline only where the run
** finds it (3 sigma; docs/explain.md, "Composed as a gimbal"): an alt-az
** run of the independent gimbal (tests/ref/explain_campaign.py --seed 2;
** the command in the file's first line) with 10' of anisotropy, indices of
** 4 deg and a worm error of the elevation drive, 124 cycles of 1.14", and
** no refraction.  Its baseline fits a refraction of 0.07 +- 0.45"; with that
** noise beside it the composition fitted worse (0.776" after the worm term
** against 0.750") and a two-cycle azimuth term was invented after the
** worm.  Without it: the worm alone. */
START_TEST(test_nuisance_only_when_found)
{
    pmx_result r;
    const pmx_finding *f;
    explain_data("indep_worm_altaz_el124.dat", NULL, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    printf("check_explain_reading: indep_worm_altaz_el124.dat: %d finding(s), first %s %.6g "
           "cycles, %.2f +- %.2f\" (true 1.14\"), sigma after %.3f\"\n", r.n_findings, f->effect,
           f->cycles_per_rev, f->amplitude_arcsec, f->amplitude_err_arcsec,
           f->sigma_after_arcsec);
    ck_assert_str_eq(f->effect, "dec_periodic");
    ck_assert(f->cycles_lo <= 124 && f->cycles_hi >= 124);
    ck_assert(fabs(f->amplitude_arcsec - 1.1391250886566169) < 3 * f->amplitude_err_arcsec);
    ck_assert_msg(r.n_findings == 1, "finding 2 invented: %s", r.findings[1].effect);
}
END_TEST

/* Cross-validation by leave-one-out from the fit itself (PRESS; docs/
** explain.md, step 4): a degree-2 distortion of 6.6" on a fork mount seen
** at 55 points, 0.71" of noise (tests/ref/explain_campaign.py --seed 2; the
** command in the file's first line).  Order 2's 24 more terms pass the
** F-test (false alarm 5e-4), but fitted on the 44 points of a 5-fold
** training set they predicted worse than order 1 (1.29" against 1.17"),
** and nothing was found.  Left out one at a time, as the fit on all 55
** sees them, they predict better (1.145" against 1.228"): higher_order.
** PRESS must also be the leave-one-out it stands for: the baseline's,
** against 55 refits each without one point (folds = N), to 1e-3. */
START_TEST(test_loo_cross_validation)
{
    pmx_options o;
    pmx_result loo, refits, k5;
    double rel;
    explain_data("indep_ho_fork_n55.dat", NULL, &loo);
    pmx_options_default(&o);
    ck_assert_int_eq(o.folds, 0);
    o.folds = 55;
    explain_data("indep_ho_fork_n55.dat", &o, &refits);
    o.folds = 5;
    explain_data("indep_ho_fork_n55.dat", &o, &k5);
    rel = fabs(loo.base_cv_rms_arcsec / refits.base_cv_rms_arcsec - 1);
    printf("check_explain_reading: indep_ho_fork_n55.dat: baseline CV %.4f\" (PRESS), %.4f\" "
           "(55 refits), %.4f\" (5-fold); findings %d (first %s) with PRESS, %d with 5-fold\n",
           loo.base_cv_rms_arcsec, refits.base_cv_rms_arcsec, k5.base_cv_rms_arcsec,
           loo.n_findings, loo.n_findings ? loo.findings[0].effect : "-", k5.n_findings);
    ck_assert(rel < 1e-3);
    ck_assert_int_ge(loo.n_findings, 1);
    ck_assert_str_eq(loo.findings[0].effect, "higher_order");
    ck_assert(loo.findings[0].cv_rms_after_arcsec < loo.base_cv_rms_arcsec);
}
END_TEST

/* A point the others cannot predict, left out of the cross-validation
** (docs/explain.md, step 4): the TPOINT generator's German run from one
** pier side with one point from the other (line 147), 135 points, 1.72" of
** noise and a declination worm error of 3.6", 201 cycles (python3
** tests/ref/tpoint_gen.py OUT --seed 100020 --mount gem --format tpoint
** --sky oneside --aniso 3.0 --aniso-beyond 0.0 --aniso-frame encoder
** --effect dec_pe:3.59332:G=201.0,phase=120.974).  Line 147 nearly alone
** fixes some combination of the terms (H_ii's eigenvalue 0.9994): its
** leave-one-out miss was 25% of the baseline's sum and 65% of the worm
** term's, and the worm, sigma 2.53" -> 1.81", did not "predict better"
** (3.036" against 3.046"): nothing was found. */
START_TEST(test_cv_without_unpredictable)
{
    pmx_result r;
    const pmx_finding *f;
    explain_data("tpoint_gem_oneside_dec201.dat", NULL, &r);
    printf("check_explain_reading: tpoint_gem_oneside_dec201.dat: CV left out %d point(s), "
           "line %d; baseline CV %.3f\", %d finding(s)%s%s\n", r.n_cv_left_out,
           r.n_cv_left_out ? r.cv_left_out_lines[0] : 0, r.base_cv_rms_arcsec, r.n_findings,
           r.n_findings ? ", first " : "", r.n_findings ? r.findings[0].effect : "");
    ck_assert_int_eq(r.n_cv_left_out, 1);
    ck_assert_int_eq(r.cv_left_out_lines[0], 147);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    ck_assert_str_eq(f->effect, "dec_periodic");
    ck_assert(f->cycles_lo <= 201 && f->cycles_hi >= 201);
    ck_assert(fabs(f->amplitude_arcsec - 3.59332) < 3 * f->amplitude_err_arcsec);
    ck_assert(f->cv_rms_after_arcsec < r.base_cv_rms_arcsec);
}
END_TEST

/* The reading without higher_order where it predicts as well with fewer
** terms (docs/explain.md, step 4): the TPOINT generator's German run, half
** the sky, a pier-side flexure of 105" and a refraction of -9.64" (python3
** tests/ref/tpoint_gen.py OUT --seed 1300524 --mount gem --format tpoint
** --sky half --aniso 120.0 --aniso-beyond 0.0 --aniso-frame encoder
** --effect pier_flex:104.934:on=normal,psi=0.0 --effect pressure:-9.63887).
** Order 2 won the first step on false-alarm probability, then the pier
** side: 48 terms, sigma 1.933", CV 2.112".  Pier side and refraction: 25
** terms, 1.922", 2.041" -- taken, higher_order withdrawn. */
START_TEST(test_physical_instead_of_higher)
{
    pmx_result r;
    int pier, refr, withdrawn;
    explain_data("tpoint_gem_half_pier_refr.dat", NULL, &r);
    pier = finding_index(&r, "pier_side");
    refr = finding_index(&r, "refraction");
    withdrawn = withdrawn_count(&r, "higher_order");
    printf("check_explain_reading: tpoint_gem_half_pier_refr.dat: %d finding(s) (first %s), "
           "refraction %.2f +- %.2f\" (true -9.64\"), P = %d, higher_order withdrawn %d\n",
           r.n_findings, r.n_findings ? r.findings[0].effect : "-",
           refr >= 0 ? r.findings[refr].amplitude_arcsec : 0.0,
           refr >= 0 ? r.findings[refr].amplitude_err_arcsec : 0.0, r.final_n_params, withdrawn);
    ck_assert_int_eq(r.n_findings, 2);
    ck_assert(pier >= 0 && refr >= 0);
    ck_assert(fabs(r.findings[refr].amplitude_arcsec - 9.63887) <
              3 * r.findings[refr].amplitude_err_arcsec);
    ck_assert_int_eq(withdrawn, 1);
    ck_assert_int_eq(r.final_n_params, 25);
}
END_TEST

/* The rival in the final model (docs/explain.md, "Confusable effects"):
** a fork run of 72 points from one side of the sky (campaign seed 2,
** tests/ref/indep_gen.py) hides a drift of 7.36"/h and one gross error
** (line 15).  The search found temperature first, with the bad point
** still in; with it left out, the drift fits better (sigma 2.016" against
** 2.101").  The reading is now the drift and the outlier, temperature
** withdrawn.  Before: temperature 5.58" +- 0.71" and the outlier. */
START_TEST(test_rival_in_final_model)
{
    pmx_result r;
    int drift, outlier, temp, withdrawn;
    explain_data("indep_fork_drift_outlier.dat", NULL, &r);
    drift = finding_index(&r, "time_drift");
    outlier = finding_index(&r, "outlier");
    temp = finding_index(&r, "temperature") >= 0;
    withdrawn = withdrawn_count(&r, "temperature");
    printf("check_explain_reading: indep_fork_drift_outlier.dat: %d finding(s), drift %.2f +- "
           "%.2f\"/h (true 7.36), temperature found %d, withdrawn %d\n", r.n_findings,
           drift >= 0 ? r.findings[drift].amplitude_arcsec : 0.0,
           drift >= 0 ? r.findings[drift].amplitude_err_arcsec : 0.0, temp, withdrawn);
    ck_assert_int_eq(r.n_findings, 2);
    ck_assert(drift >= 0 && outlier >= 0 && temp == 0);
    ck_assert_int_eq(r.findings[outlier].n_lines, 1);
    ck_assert_int_eq(r.findings[outlier].lines[0], 15);
    ck_assert(fabs(r.findings[drift].amplitude_arcsec - 7.35689) <
              3 * r.findings[drift].amplitude_err_arcsec);
    ck_assert_int_eq(withdrawn, 1);
}
END_TEST

/* The rival offered in the final model (docs/explain.md, "Confusable
** effects"): a German run of 117 points (campaign seed 11, tests/ref/
** indep_gen.py, the parameters in its first line) hides a pier-side
** flexure of 36" and a drift of 5.1"/h.  Step 1, with the pier side still
** in the residuals, takes temperature (the night cools, and the west side
** was observed later); in the final model, beside the pier side, the drift
** fits as well (sigma 2.551" against 2.560", likelihood ratio 2 for it),
** but the search without temperature did not end with the same families,
** so temperature stays.  It was named with no alternative; the drift is now
** offered beside it (kind "final", Delta BIC below 6).  A drift named
** outright would pass too. */
START_TEST(test_rival_offered_in_final_model)
{
    pmx_result r;
    int drift, temp, pier, k, offered = 0;
    explain_data("indep_gem_pier_drift.dat", NULL, &r);
    drift = finding_index(&r, "time_drift");
    temp = finding_index(&r, "temperature");
    pier = finding_index(&r, "pier_side");
    ck_assert(pier >= 0);
    ck_assert(drift >= 0 || temp >= 0);
    if (temp >= 0) {
        for (k = 0; k < r.findings[temp].n_alternatives; k++) {
            const pmx_alternative *a = &r.findings[temp].alternatives[k];
            if (strcmp(a->effect, "time_drift") == 0) {
                printf("check_explain_reading: indep_gem_pier_drift.dat: temperature, with "
                       "time_drift beside it (final %d, Delta BIC %+.2f, false alarm 10^%.1f): "
                       "%s\n", a->final_model, a->delta_bic, a->log10_fap, a->separate_by);
                ck_assert_int_eq(a->final_model, 1);
                ck_assert(a->delta_bic < 6);
                ck_assert(a->log10_fap < -2);
                offered = 1;
            }
        }
        ck_assert_msg(offered || drift >= 0, "temperature named, the drift neither named nor "
                                             "offered");
    }
}
END_TEST

/* The reading withdrawn for its rival is offered beside it where it is as
** good (docs/explain.md, "Confusable effects"): a German run of 54 points
** on a band of sky (campaign seed 14, tests/ref/indep_gen.py, the
** parameters in its first line) hides a refraction of 5.6" and a drift of
** 7.4"/h.  The search names the drift first; with the refraction in, the
** temperature fits the final model a little better (sigma 0.977" against
** 0.978") and the search without the drift agrees, so the temperature
** replaces it.  That search had the drift excluded and could not offer it:
** the temperature was named alone, though the two readings are as good
** (Delta BIC 0.2).  The drift is now offered beside it (kind "final"). */
START_TEST(test_rival_withdrawn_offered)
{
    pmx_result r;
    int temp, refr, k, offered = 0;
    explain_data("indep_gem_refr_drift_swap.dat", NULL, &r);
    temp = finding_index(&r, "temperature");
    refr = finding_index(&r, "refraction");
    ck_assert(refr >= 0);
    ck_assert_int_eq(withdrawn_count(&r, "time_drift"), 1);
    ck_assert(temp >= 0);
    for (k = 0; k < r.findings[temp].n_alternatives; k++) {
        const pmx_alternative *a = &r.findings[temp].alternatives[k];
        if (strcmp(a->effect, "time_drift") == 0) {
            printf("check_explain_reading: indep_gem_refr_drift_swap.dat: temperature, "
                   "time_drift withdrawn and offered beside it (final %d, Delta BIC %+.2f, "
                   "false alarm 10^%.1f)\n", a->final_model, a->delta_bic, a->log10_fap);
            ck_assert_int_eq(a->final_model, 1);
            ck_assert(a->delta_bic >= 0 && a->delta_bic < 6);
            ck_assert(a->log10_fap < -2);
            offered = 1;
        }
    }
    ck_assert_msg(offered, "the drift withdrawn, not offered beside the temperature");
}
END_TEST

/* A gross error's neighbours (docs/explain.md step 3, outliers): an
** alt-az run of 113 points (campaign seed 11, tests/ref/indep_gen.py, the
** parameters in its first line) with one gross error of 41" at elevation
** 87 deg (line 113).  Each point's deleted residual was taken with the
** others in, and the error pulled the fit near the zenith: lines 106 and
** 112, 5 and 7 deg from it, were flagged beside it, though without line
** 113 explain finds nothing at all.  Each point is now tested without the
** points flagged before it: line 113 alone. */
START_TEST(test_outlier_neighbours)
{
    pmx_result r;
    int out;
    explain_data("indep_altaz_outlier_zenith.dat", NULL, &r);
    out = finding_index(&r, "outlier");
    ck_assert(out >= 0);
    printf("check_explain_reading: indep_altaz_outlier_zenith.dat: %d finding(s), outlier lines "
           "%d (first %d)\n", r.n_findings, r.findings[out].n_lines, r.findings[out].lines[0]);
    ck_assert_int_eq(r.n_findings, 1);
    ck_assert_int_eq(r.findings[out].n_lines, 1);
    ck_assert_int_eq(r.findings[out].lines[0], 113);
}
END_TEST

/* Significant, not modelled: an alt-az run of 90 points (campaign seed
** 11, tests/ref/indep_gen.py, noise 0.30") hides a degree-2 distortion of
** 2.0" RMS.  Order 2 fits it (sigma 0.426" -> 0.318", false-alarm
** 10^-10.5 with the step's candidates counted), but its 24 more terms
** predict worse (leave-one-out RMS 0.530" against 0.454"), so it is no
** finding; before, explain said only "nothing significant is left out".
** It is now named as the effect the residuals hold and the run cannot fit
** usefully.  With the order-2 terms in the baseline nothing is left, and
** nothing is named so. */
START_TEST(test_unmodelled)
{
    pmx_options o;
    pmx_result r, r2;
    explain_data("indep_ho_altaz_n90_unmodelled.dat", NULL, &r);
    printf("check_explain_reading: indep_ho_altaz_n90_unmodelled.dat: %d finding(s); "
           "unmodelled '%s' (10^%.1f): sigma %.3f\" (baseline %.3f\"), CV RMS %.3f\" "
           "(baseline %.3f\")\n",
           r.n_findings, r.unmodelled, r.unmodelled_log10_fap, r.unmodelled_sigma_arcsec,
           r.base_sigma_arcsec, r.unmodelled_cv_rms_arcsec, r.base_cv_rms_arcsec);
    ck_assert_int_eq(r.n_findings, 0);
    ck_assert_str_eq(r.unmodelled, "higher_order");
    ck_assert(r.unmodelled_log10_fap < -2);
    ck_assert(r.unmodelled_sigma_arcsec < 0.8 * r.base_sigma_arcsec);
    ck_assert(r.unmodelled_cv_rms_arcsec >= r.base_cv_rms_arcsec);
    ck_assert(r.unmodelled_cv_before_arcsec == r.base_cv_rms_arcsec);
    pmx_options_default(&o);
    o.order = 2;
    explain_data("indep_ho_altaz_n90_unmodelled.dat", &o, &r2);
    ck_assert_int_eq(r2.n_findings, 0);
    ck_assert_str_eq(r2.unmodelled, "");
}
END_TEST

/* The sizes are the final model's (docs/explain.md step 5): a fork run of
** 259 points (campaign seed 1, tests/ref/indep_gen.py, an order-0
** baseline) hides a temperature of 4.96"/C, a drift of 1.50"/h (c' +1.50,
** e' +1.50) and a sag of 10.7".  The drift is found at step 1, where it
** takes part of the temperature: e'*time 3.60 +- 0.11, 19 of its sigmas
** from the truth.  In the final model, with the temperature in, it is 2.00
** +- 0.36 (the larger of its two coefficients, the amplitude). */
START_TEST(test_sizes_of_final_model)
{
    pmx_options o;
    pmx_result r;
    int drift, temp;
    pmx_options_default(&o);
    o.order = 0;
    explain_data("indep_fork_temp_drift_sag.dat", &o, &r);
    drift = finding_index(&r, "time_drift");
    temp = finding_index(&r, "temperature");
    ck_assert(drift >= 0 && temp >= 0);
    printf("check_explain_reading: indep_fork_temp_drift_sag.dat: drift %.2f +- %.2f\"/h "
           "(true 1.50), temperature %.2f +- %.2f\"/C (true 4.96)\n",
           r.findings[drift].amplitude_arcsec, r.findings[drift].amplitude_err_arcsec,
           r.findings[temp].amplitude_arcsec, r.findings[temp].amplitude_err_arcsec);
    ck_assert(fabs(r.findings[drift].amplitude_arcsec - 1.49954) <
              3 * r.findings[drift].amplitude_err_arcsec);
    ck_assert(fabs(r.findings[temp].amplitude_arcsec - 4.95928) <
              3 * r.findings[temp].amplitude_err_arcsec);
}
END_TEST

/* The step's K counts the pairs it may try (docs/explain.md step 4): a
** single found with pairs on reports a false-alarm probability larger by
** K(singles + pairs) / K(singles) than with pairs off (before, the same:
** the pairs had an alpha of their own, and a run with nothing in it could
** find something with probability up to about 2 alpha). */
START_TEST(test_step_k_counts_pairs)
{
    static const pair_case c = {"refraction", "temperature", "refraction", "temperature"};
    pmsim_spec s;
    pmx_options o;
    pmx_result on, off;
    double ratio;
    pmx_options_default(&o);
    pair_spec(&s, &c, 901, 3, 0);
    explain_spec(&s, &o, &on);
    o.pairs = 0;
    explain_spec(&s, &o, &off);
    ck_assert_int_ge(on.n_findings, 1);
    ck_assert_int_ge(off.n_findings, 1);
    ck_assert_str_eq(on.findings[0].effect, "refraction");
    ck_assert_str_eq(off.findings[0].effect, "refraction");
    ratio = on.findings[0].false_alarm_probability / off.findings[0].false_alarm_probability;
    printf("check_explain_reading: refraction's false-alarm probability %.3g with pairs, %.3g "
           "without (x %.2f)\n", on.findings[0].false_alarm_probability,
           off.findings[0].false_alarm_probability, ratio);
    /* at least 3 families that pair: K grows by at least 3 pairs over at
    ** most 10 singles */
    ck_assert(ratio >= 1.3);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("explain_reading");
    TCase *t = tcase_create("reading");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, test_reading_flip_gem);
    tcase_add_test(t, test_reading_simulated_sag);
    tcase_add_test(t, test_physical_reading_only_when_true);
    tcase_add_test(t, test_alternatives_confusable);
    tcase_add_test(t, test_backward_pass);
    tcase_add_loop_test(t, test_generic_reading, 0, 2);
    tcase_add_test(t, test_generic_reading_inside);
    tcase_add_test(t, test_smooth_alternative);
    tcase_add_test(t, test_subcycle_not_periodic);
    tcase_add_test(t, test_step_k_counts_pairs);
    tcase_add_test(t, test_composed_baseline);
    tcase_add_loop_test(t, test_composed_with_findings, 0, 2);
    tcase_add_test(t, test_nuisance_only_when_found);
    tcase_add_test(t, test_loo_cross_validation);
    tcase_add_test(t, test_cv_without_unpredictable);
    tcase_add_test(t, test_physical_instead_of_higher);
    tcase_add_test(t, test_rival_in_final_model);
    tcase_add_test(t, test_rival_offered_in_final_model);
    tcase_add_test(t, test_rival_withdrawn_offered);
    tcase_add_test(t, test_outlier_neighbours);
    tcase_add_test(t, test_unmodelled);
    tcase_add_test(t, test_sizes_of_final_model);
    tcase_add_loop_test(t, test_pairs_curve, 0, (int)(sizeof PAIRS / sizeof PAIRS[0]));
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
