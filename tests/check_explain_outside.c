/*
**  check_explain_outside.c - explain on runs of the independent generator
**  tests/ref/tpoint_gen.py (astropy places, an exact TPOINT-convention
**  gimbal, files written as mount software writes them), the cases its
**  campaign (tests/ref/tpoint_campaign.py) found wrong, each made with the
**  command in its file's first lines:
**
**  - A fork mount that never turns its HA axis under the pole: a slew from
**    one side of HA 180 deg to the other goes the long way round, and the
**    backlash it leaves must be read with that direction (before, the
**    short way was assumed and 7 points after such slews were named a
**    gross error).
**  - An alt-az run in a narrow band of elevation, where the azimuth index,
**    non-perpendicularity and collimation nearly confound: the baseline
**    fit takes 176 damped passes; explain must fit what pmfit fit fits
**    (before: "the baseline fit failed: the fit did not converge").
**  - Gear periods on axes sampled over part of their circle: the reported
**    range of periods that fit as well holds the true tooth count, and a
**    whole circle fixes it.
**  - Azimuth runout of 2 and 3 cycles on alt-az runs that sample half and
**    a third of the azimuth circle: one cycle of it over the sampled
**    range, below the periodogram's one and a half.  The periodogram's
**    peak sat at 3 and 5 cycles, and the full fit could not move below
**    the search's floor to the period that fits best: a runout of the
**    wrong period was named (5 of 15 such runs of the campaign, seed 7;
**    3 more named higher_order).  Made by
**      tests/ref/tpoint_gen.py OUT --seed 700292 --mount altaz --format
**        tpoint --sky half --aniso 30.0 --aniso-beyond 0.0 --aniso-frame
**        mech --effect az_runout:6.2046:G=2.0,phase=306.395
**      tests/ref/tpoint_gen.py OUT --seed 700290 --mount altaz --format
**        tpoint --sky oneside --aniso 3.0 --aniso-beyond 0.0 --aniso-frame
**        mech --effect az_runout:16.8079:G=3.0,phase=168.486
**    A three-cycle runout on half the circle (1.45 cycles sampled): the
**    periodogram, from 1.5 cycles up, peaked at 4.2, and the full fits
**    tried only 4 and 5 beside it, while 3 fits better than 4.2 (sigma
**    1.035" against 1.077"): 4.2 was named, with a range of 4.12-4.28
**    (campaign seed 13).  The whole numbers are now walked from the better
**    of the two.  Made by
**      tests/ref/tpoint_gen.py OUT --seed 1300291 --mount altaz --format
**        tpoint --sky half --aniso 0.0 --aniso-beyond 0.3 --aniso-frame
**        mech --effect az_runout:4.22915:G=3.0,phase=25.687
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "explain.h"

/* explain on tests/data/name; compose 0: the baseline read to first order
** (--no-compose). */
static void explain_file_c(const char *name, int compose, pmx_result *r)
{
    const char *top = getenv("PM_TOP");
    char path[512], err[512];
    pmx_options o;
    snprintf(path, sizeof path, "%s/tests/data/%s", top ? top : ".", name);
    pmx_options_default(&o);
    o.compose = compose;
    ck_assert_msg(pmx_explain_opts(path, &o, r, err, sizeof err) == 0, "%s: %s", name, err);
}

static void explain_file(const char *name, pmx_result *r)
{
    explain_file_c(name, 1, r);
}

static int find(const pmx_result *r, const char *effect)
{
    int k;
    for (k = 0; k < r->n_findings; k++)
        if (!strcmp(r->findings[k].effect, effect))
            return k;
    return -1;
}

/* backlash 3.08" on the HA axis (psi 0), a drift, a 135-cycle HA error */
START_TEST(test_long_way_round)
{
    pmx_result r;
    int k, h;
    explain_file("outside_fork_pole_backlash.dat", &r);
    for (k = 0; k < r.n_findings; k++)
        printf("check_explain_outside: fork under the pole: finding %d %s %.2f\"\n", k + 1,
               r.findings[k].effect, r.findings[k].amplitude_arcsec);
    ck_assert_int_eq(find(&r, "outlier"), -1);
    h = find(&r, "hysteresis");
    ck_assert_int_ge(h, 0);
    ck_assert(fabs(r.findings[h].amplitude_arcsec - 3.07735) <= 0.25 * 3.07735);
    ck_assert_int_ge(find(&r, "ha_periodic"), 0);
    ck_assert_int_ge(find(&r, "time_drift"), 0);
}
END_TEST

/* a temperature term on the elevation index, 5.18"/deg C */
START_TEST(test_narrow_band_fits)
{
    pmx_result r;
    explain_file("outside_altaz_band_temp.dat", &r);
    ck_assert_int_ge(r.n_findings, 1);
    ck_assert_str_eq(r.findings[0].effect, "temperature");
    printf("check_explain_outside: alt-az band: baseline %.3f\", %s\n", r.base_sigma_arcsec,
           r.findings[0].effect);
}
END_TEST

START_TEST(test_period_range)
{
    static const struct {
        const char *file, *effect;
        double G;
        int partial; /* the axis is sampled over part of its circle */
    } C[] = {{"outside_altaz_el309.dat", "dec_periodic", 309, 1},
             {"outside_gem_dec260.dat", "dec_periodic", 260, 1},
             {"outside_fork_dec88.dat", "dec_periodic", 88, 1},
             {"outside_gem_ha144_full.dat", "ha_periodic", 144, 0}};
    pmx_result r;
    const pmx_finding *f;
    explain_file(C[_i].file, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    printf("check_explain_outside: %s: %s G %g (range %g..%g), true %g\n", C[_i].file,
           f->effect, f->cycles_per_rev, f->cycles_lo, f->cycles_hi, C[_i].G);
    ck_assert_str_eq(f->effect, C[_i].effect);
    ck_assert(f->cycles_lo <= f->cycles_per_rev && f->cycles_per_rev <= f->cycles_hi);
    ck_assert_msg(f->cycles_lo <= C[_i].G && C[_i].G <= f->cycles_hi,
                  "true G %g outside the range %g..%g", C[_i].G, f->cycles_lo, f->cycles_hi);
    ck_assert(f->cycles_hi - f->cycles_lo <= 2);
    if (!C[_i].partial) /* a whole circle fixes the count */
        ck_assert(f->cycles_lo == C[_i].G && f->cycles_hi == C[_i].G);
}
END_TEST

/* runout of G cycles, amplitude A, on an azimuth range holding one cycle
** (one and a half in the third) */
START_TEST(test_runout_one_cycle)
{
    static const struct {
        const char *file;
        double G, amp;
    } C[] = {{"outside_altaz_runout2_half.dat", 2, 6.2046},
             {"outside_altaz_runout3_oneside.dat", 3, 16.8079},
             {"outside_altaz_runout3_half.dat", 3, 4.22915}};
    pmx_result r;
    const pmx_finding *f;
    explain_file(C[_i].file, &r);
    ck_assert_int_ge(r.n_findings, 1);
    f = &r.findings[0];
    printf("check_explain_outside: %s: %s G %g (range %g..%g), %.2f\" (true G %g, %.2f\")\n",
           C[_i].file, f->effect, f->cycles_per_rev, f->cycles_lo, f->cycles_hi,
           f->amplitude_arcsec, C[_i].G, C[_i].amp);
    ck_assert_str_eq(f->effect, "ha_periodic");
    ck_assert(f->cycles_per_rev == C[_i].G);
    ck_assert(fabs(f->amplitude_arcsec - C[_i].amp) <= 0.25 * C[_i].amp);
    ck_assert(f->cycles_lo <= C[_i].G && C[_i].G <= f->cycles_hi);
    /* one cycle seen: the smooth reading is offered beside it */
    ck_assert_int_ge(f->n_alternatives, 1);
    ck_assert_str_eq(f->alternatives[0].effect, "higher_order");
    ck_assert_int_eq(f->alternatives[0].smooth, 1);
}
END_TEST

/* Two periodic errors on one axis (tests/ref/indep_gen.py, the command in
** each file's first line): a German mount's worm (144 cycles, 3") and a
** second gear (36, 2") in hour angle; an alt-az mount's azimuth worm (144,
** 3") and its second harmonic (288, 1.5") at a southern site.  Until stop
** 39 an axis with a periodic term was not looked at again: the first was
** named, sigma stayed 1.2-1.4" against the 1" noise, and explain said
** nothing more was left out.  Both are named now, each within 25% of its
** size, and nothing else. */
/* Two gears one cycle apart (100 and 101 cycles, 3" and 2"; German,
** indep_gen.py): the run cannot tell 101 from the 100 it holds, and what
** the periodogram shows elsewhere is its leakage and aliases.  The first
** answer to an axis searched again named a second period of 688 cycles
** (0.70") here (514 on another seed, 104 next to it on others): now the
** one period, and nothing invented beside it. */
START_TEST(test_unresolved_pair_invents_nothing)
{
    pmx_result r;
    int k;
    explain_file("indep_gem_gears_100_101.dat", &r);
    for (k = 0; k < r.n_findings; k++)
        printf("check_explain_outside: indep_gem_gears_100_101.dat: %s G %g, %.2f\"\n",
               r.findings[k].effect, r.findings[k].cycles_per_rev,
               r.findings[k].amplitude_arcsec);
    ck_assert_int_eq(r.n_findings, 1);
    ck_assert_str_eq(r.findings[0].effect, "ha_periodic");
    ck_assert(fabs(r.findings[0].cycles_per_rev - 100) < 1);
}
END_TEST

START_TEST(test_two_periods_one_axis)
{
    static const struct {
        const char *file;
        double G[2], amp[2];
    } C[] = {{"indep_gem_two_gears.dat", {144, 36}, {3.0, 2.0}},
             {"indep_altaz_worm_harmonic.dat", {144, 288}, {3.0, 1.5}}};
    pmx_result r;
    int k, j, seen[2] = {0, 0};
    explain_file(C[_i].file, &r);
    for (k = 0; k < r.n_findings; k++)
        printf("check_explain_outside: %s: %s G %g, %.2f\" +- %.2f\"\n", C[_i].file,
               r.findings[k].effect, r.findings[k].cycles_per_rev, r.findings[k].amplitude_arcsec,
               r.findings[k].amplitude_err_arcsec);
    ck_assert_int_eq(r.n_findings, 2);
    for (k = 0; k < 2; k++) {
        const pmx_finding *f = &r.findings[k];
        ck_assert_str_eq(f->effect, "ha_periodic");
        for (j = 0; j < 2; j++)
            if (f->cycles_per_rev == C[_i].G[j]) {
                seen[j]++;
                ck_assert(fabs(f->amplitude_arcsec - C[_i].amp[j]) <= 0.25 * C[_i].amp[j]);
            }
    }
    ck_assert_int_eq(seen[0], 1);
    ck_assert_int_eq(seen[1], 1);
}
END_TEST

/* Nothing hidden, the generator's own gimbal parameters varying by 10'
** over the sky (tpoint_gen's anisotropy, its TPOINT-convention gimbal;
** /usr/bin/python3 tests/ref/tpoint_gen.py tests/data/outside_M_aniso600.dat
** --seed 2 --mount M --aniso 600 --noise 0.3 --outlier-frac 0 --truth "",
** M = gem, altaz).  Read to first order, the second-order composition is
** named (gem: refraction and higher_order; alt-az: higher_order); composed
** as a gimbal (docs/explain.md, step 1), nothing, and sigma back to the
** noise.  Over seeds 1-10 of each mount, 19 of 30 such runs found
** something to first order, none composed (docs/explain.md). */
START_TEST(test_composed_outside)
{
    static const char *const F[] = {"outside_gem_aniso600.dat", "outside_altaz_aniso600.dat"};
    pmx_result on, off;
    explain_file_c(F[_i], 1, &on);
    explain_file_c(F[_i], 0, &off);
    printf("check_explain_outside: %s: composed sigma %.3f\" (composition %.3f\" RMS), %d "
           "finding(s); first order sigma %.3f\", %d finding(s)%s%s\n", F[_i],
           on.base_sigma_arcsec, on.compose_rms_arcsec, on.n_findings, off.base_sigma_arcsec,
           off.n_findings, off.n_findings ? ", first " : "",
           off.n_findings ? off.findings[0].effect : "");
    ck_assert_int_eq(on.n_findings, 0);
    ck_assert_int_ge(off.n_findings, 1);
    ck_assert(on.base_sigma_arcsec < 0.32 && off.base_sigma_arcsec > 0.36);
}
END_TEST

/* An order-3 baseline on the 129 alt-az points does not determine its
** anisotropic terms (coefficients of 7,500" +- 28,000"): composed, they
** would move the points by a meaningless 94" RMS, so the baseline is
** read to first order (docs/explain.md, step 1). */
START_TEST(test_composed_undetermined)
{
    const char *top = getenv("PM_TOP");
    char path[512], err[512];
    pmx_options o;
    pmx_result r;
    snprintf(path, sizeof path, "%s/tests/data/outside_altaz_aniso600.dat", top ? top : ".");
    pmx_options_default(&o);
    o.order = 3;
    ck_assert_msg(pmx_explain_opts(path, &o, &r, err, sizeof err) == 0, "%s", err);
    printf("check_explain_outside: outside_altaz_aniso600.dat at order 3: composition %.3f\" "
           "RMS, sigma %.3f\"\n", r.compose_rms_arcsec, r.base_sigma_arcsec);
    ck_assert(r.compose_rms_arcsec == 0);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("explain_outside");
    TCase *t = tcase_create("outside");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, test_long_way_round);
    tcase_add_test(t, test_narrow_band_fits);
    tcase_add_loop_test(t, test_period_range, 0, 4);
    tcase_add_loop_test(t, test_runout_one_cycle, 0, 3);
    tcase_add_loop_test(t, test_two_periods_one_axis, 0, 2);
    tcase_add_test(t, test_unresolved_pair_invents_nothing);
    tcase_add_loop_test(t, test_composed_outside, 0, 2);
    tcase_add_test(t, test_composed_undetermined);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
