/*
**  check_plan.c - which star next (pmfit plan, issue 17 item 1): the greedy
**  I-optimal plan against a uniform grid and random points.
**
**  For a German mount at latitude 47 (horizon 15 deg) and models of order
**  0, 1 and 2: the plan from nothing, N points long, and for every N the
**  predicted mean error over the sky of the plan's first N points, of a
**  uniform grid of N points (a golden-spiral lattice over the sky above the
**  horizon) and of N random points (mean of 8 draws).  Printed: how many
**  points each needs to reach the grid's error at its reference size; the
**  plan needs fewer than the grid and than random points.
**
**  And the real error, not the predicted one: a mount of that order (the
**  truth: arcminute isotropic terms, 15" harmonic terms, 1" noise) observed
**  at the plan's points and at the grid's, fitted, and compared with the
**  truth over the sky (20 noise draws): the plan's real error is the lower,
**  and each is within 25% of what was predicted.  (The full comparison --
**  grids users shoot, partial skies, points taken, physical terms, real
**  runs sub-sampled -- is bench/bench_plan.cpp.)
**
**  The options: a horizon file (targets above it; the three accepted
**  formats give the same plan), a star catalogue (named targets above the
**  horizon at the given time; --utc against --lst), D-optimal (a larger
**  determinant, a larger mean error than I-optimal), the slew time (shorter
**  slews), the pier-side rules, physical terms.  A mount controller choosing
**  its next star with the C API (examples/next_star.c, compiled as C89):
**  its D score is the log det rise of a refit with the star, and the run it
**  drives ends better known than one of random stars.  Bad inputs: an
**  unknown horizon format, a malformed or empty catalogue, no candidate
**  above the horizon, a degenerate run.
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <erfa.h>

#include "pm.h"
#include "plan.h"
#include "testutil.h"
#include "tu_tool.h"

#define LAT 47.0
#define NMAX 160

static pm_fit fit; /* large: static */

static double elevation(double ha_deg, double dec_deg)
{
    return asin(sin(LAT * DEG) * sin(dec_deg * DEG) +
                cos(LAT * DEG) * cos(dec_deg * DEG) * cos(ha_deg * DEG)) / DEG;
}

static void make_point(double ha, double dec, pmplan_target *t)
{
    t->x_deg = ha;
    t->y_deg = dec;
    t->el_deg = elevation(ha, dec);
    t->side = ha > 0 ? 1 : -1; /* the normal pointing state looks west (ASCOM) */
    t->after_arcsec = 0;
}

/* n points of a golden-spiral lattice over the sky above the horizon. */
static void grid(int n, pmplan_target *out)
{
    int total = n, k, got;
    for (;;) {
        got = 0;
        for (k = 0; k < total && got < n + 1; k++) {
            double z = 1 - (2.0 * k + 1) / total, ha = fmod(k * 137.50776405, 360.0) - 180;
            double dec = asin(z) / DEG;
            if (elevation(ha, dec) >= 15)
                got++;
        }
        if (got >= n)
            break;
        total++;
    }
    got = 0;
    for (k = 0; k < total && got < n; k++) {
        double z = 1 - (2.0 * k + 1) / total, ha = fmod(k * 137.50776405, 360.0) - 180;
        double dec = asin(z) / DEG;
        if (elevation(ha, dec) >= 15)
            make_point(ha, dec, &out[got++]);
    }
}

static void random_points(int n, tu_rng *r, pmplan_target *out)
{
    int k = 0;
    while (k < n) {
        double ha = (2 * tu_uniform(r) - 1) * 180, dec = asin(2 * tu_uniform(r) - 1) / DEG;
        if (elevation(ha, dec) >= 15)
            make_point(ha, dec, &out[k++]);
    }
}

static double predicted(const pmplan_options *o, const pmplan_target *p, int n)
{
    double e;
    char err[256];
    ck_assert_msg(pmplan_predicted(o, p, n, &e, err, sizeof err) == 0, "%s", err);
    return e;
}

/* The smallest N (from 1) at which the curve reaches target, or NMAX + 1. */
static int needed(const double *curve, double target)
{
    int n;
    for (n = 1; n <= NMAX; n++)
        if (curve[n] <= target)
            return n;
    return NMAX + 1;
}

/* Real mean error over the sky (per axis) of a model of order L fitted to
** observations at pts, against the truth; mean over draws. */
static double real_error(int order, const pmplan_target *pts, int n, int draws)
{
    static double eh[NMAX], ed[NMAX], ah[NMAX], ad[NMAX];
    pm_model truth, m;
    tu_rng r, g;
    int i, k, cnt = 0;
    double ss = 0;
    static const double iso[6] = {60, -40, 600, 30, -300, 20};
    ck_assert_int_eq(pm_model_init(&truth, PM_MOUNT_EQUATORIAL, order), PM_OK);
    for (i = 0; i < 6; i++)
        truth.coef[i] = iso[i] * ARCSEC;
    tu_seed(&r, 99);
    for (i = 6; i < truth.n_terms; i++)
        truth.coef[i] = (2 * tu_uniform(&r) - 1) * 15 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&truth), PM_OK);
    for (k = 0; k < draws; k++) {
        pm_fit_result res;
        tu_seed(&r, 1000 + (unsigned long long)k);
        for (i = 0; i < n; i++) {
            double t = pts[i].x_deg * DEG, d = pts[i].y_deg * DEG;
            if (pts[i].side < 0)
                t += M_PI, d = M_PI - d;
            eh[i] = t;
            ed[i] = d;
            ck_assert_int_eq(pm_model_apply(&truth, NULL, t, d, &ah[i], &ad[i]), PM_OK);
            ad[i] += ARCSEC * tu_gauss(&r);
            ah[i] += ARCSEC * tu_gauss(&r) / cos(ad[i]);
        }
        ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, order), PM_OK);
        if (pm_fit_run(&fit, &m, NULL, n, eh, ed, ah, ad, 50, &res) != PM_OK)
            return INFINITY;
        /* over the sky: 400 random places above the horizon, on the plan's sides */
        tu_seed(&g, 7);
        for (i = 0; i < 400; i++) {
            pmplan_target p;
            double t, d, ta, da, tb, db, e0, e1;
            random_points(1, &g, &p);
            t = p.x_deg * DEG, d = p.y_deg * DEG;
            if (p.side < 0)
                t += M_PI, d = M_PI - d;
            ck_assert_int_eq(pm_model_apply(&m, NULL, t, d, &ta, &da), PM_OK);
            ck_assert_int_eq(pm_model_apply(&truth, NULL, t, d, &tb, &db), PM_OK);
            e0 = remainder(ta - tb, 2 * M_PI) * cos(db);
            e1 = da - db;
            ss += 0.5 * (e0 * e0 + e1 * e1);
            cnt++;
        }
    }
    return sqrt(ss / cnt) / ARCSEC;
}

static void prove(int order, int nref)
{
    static pmplan_target plan[NMAX], g[NMAX], rnd[NMAX];
    static double cp[NMAX + 1], cg[NMAX + 1], cr[NMAX + 1];
    pmplan_options o;
    char err[256];
    double before, target, real_p, real_g, pred_p, pred_g;
    int n, d, np, ng, nr;
    tu_rng r;
    pmplan_options_default(&o);
    o.order = order;
    ck_assert_int_eq(pmplan_next(NULL, &o, NMAX, plan, &before, err, sizeof err), NMAX);
    tu_seed(&r, 5);
    for (n = 1; n <= NMAX; n++) {
        cp[n] = predicted(&o, plan, n);
        grid(n, g);
        cg[n] = predicted(&o, g, n);
        cr[n] = 0;
    }
    for (d = 0; d < 8; d++) {
        random_points(NMAX, &r, rnd);
        for (n = 1; n <= NMAX; n++)
            cr[n] += predicted(&o, rnd, n) / 8;
    }
    target = cg[nref];
    np = needed(cp, target);
    ng = needed(cg, target);
    nr = needed(cr, target);
    printf("check_plan: order %d: to reach the %d-point grid's predicted error %.3f\": plan %d "
           "points (%.0f%% fewer), grid %d, random %d\n", order, nref, target, np,
           100.0 * (1 - (double)np / nref), ng, nr);
    ck_assert_int_lt(np, nref);
    ck_assert_int_lt(np, nr);
    /* the real error of both designs at the reference size */
    grid(nref, g);
    real_p = real_error(order, plan, nref, 20);
    real_g = real_error(order, g, nref, 20);
    pred_p = cp[nref];
    pred_g = cg[nref];
    printf("check_plan: order %d, %d points: real error over the sky plan %.3f\" (predicted "
           "%.3f\"), grid %.3f\" (predicted %.3f\")\n", order, nref, real_p, pred_p, real_g, pred_g);
    ck_assert(real_p < real_g);
    ck_assert(fabs(real_p / pred_p - 1) < 0.25);
    ck_assert(fabs(real_g / pred_g - 1) < 0.25);
}

START_TEST(test_plan_beats_grid)
{
    static const int orders[3] = {0, 1, 2}, nref[3] = {20, 60, 140};
    prove(orders[_i], nref[_i]);
}
END_TEST

START_TEST(test_plan_errors)
{
    pmplan_options o;
    pmplan_target t[4];
    char err[256];
    double b;
    pmplan_options_default(&o);
    o.latitude_deg = NAN;
    ck_assert_int_eq(pmplan_next(NULL, &o, 4, t, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "latitude"));
    pmplan_options_default(&o);
    o.min_el_deg = 89.9;
    o.latitude_deg = -10; /* the pole below the horizon... and nothing above 89.9 on the grid */
    ck_assert_int_eq(pmplan_next(NULL, &o, 4, t, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "no usable sky"));
    pmplan_options_default(&o);
    ck_assert_int_eq(pmplan_next("/nonexistent.dat", &o, 4, t, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "/nonexistent.dat"));
}
END_TEST

/* ------------------------------------------------------------------ the CLI */

static char out[1 << 17];
static char dir[64];

static const char *tmpdir_once(void)
{
    if (!dir[0])
        tu_tmpdir(dir, "pm_plan_");
    return dir;
}

static const char *write_file(const char *name, const char *text)
{
    static char path[4][256];
    static int k;
    FILE *f;
    char *p = path[k++ % 4];
    snprintf(p, 256, "%s/%s", tmpdir_once(), name);
    f = fopen(p, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
    return p;
}

static int plan_cli(const char *args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s plan %s", tu_pmfit_path(), args);
    return tu_capture(cmd, out, sizeof out);
}

typedef struct cli_target {
    double x, y, el;
    int side;
    double after, time_s;
    char name[40];
} cli_target;

/* The targets of pmfit plan --json output (equatorial keys). */
static int parse_targets(const char *json, cli_target *t, int max)
{
    const char *p = strstr(json, "\"targets\": [");
    int n = 0;
    ck_assert_ptr_nonnull(p);
    while (n < max && (p = strstr(p, "{\"ha_deg\": ")) != NULL) {
        const char *end = strchr(p, '}'), *nm;
        cli_target *q = &t[n++];
        ck_assert_ptr_nonnull(end);
        q->x = tu_json_num(p, "ha_deg");
        q->y = tu_json_num(p, "dec_deg");
        q->el = tu_json_num(p, "elevation_deg");
        q->side = (int)tu_json_num(p, "side");
        nm = strstr(p, "\"after_arcsec\": ");
        ck_assert_ptr_nonnull(nm);
        q->after = strncmp(nm + 16, "null", 4) ? atof(nm + 16) : NAN;
        q->time_s = NAN;
        if ((nm = strstr(p, "\"time_s\": ")) != NULL && nm < end)
            q->time_s = tu_json_num(p, "time_s");
        q->name[0] = 0;
        if ((nm = strstr(p, "\"name\": \"")) != NULL && nm < end) {
            const char *e = strchr(nm + 9, '"');
            snprintf(q->name, sizeof q->name, "%.*s", (int)(e - nm - 9), nm + 9);
        }
        p = end;
    }
    return n;
}

static double azimuth(double ha, double dec)
{
    double h = ha * DEG, d = dec * DEG, f = LAT * DEG;
    double a = atan2(-sin(h) * cos(d), sin(d) * cos(f) - cos(d) * cos(h) * sin(f)) / DEG;
    return a < 0 ? a + 360 : a;
}

/* The test's own horizon: 0 20, 90 50, 180 10, 270 25, linear, periodic. */
static double test_horizon(double az)
{
    static const double a[5] = {0, 90, 180, 270, 360}, e[5] = {20, 50, 10, 25, 20};
    int k = 0;
    while (k < 3 && az > a[k + 1])
        k++;
    return e[k] + (e[k + 1] - e[k]) * (az - a[k]) / (a[k + 1] - a[k]);
}

/* A horizon file: every target above it; the three formats (azimuth
** elevation text, MountWizzard4's .hpts, a CSV with an "alt,az" header)
** give the same plan; candidates below it are gone. */
START_TEST(test_plan_horizon)
{
    static char first[1 << 17];
    static cli_target t[60];
    const char *files[3];
    char args[512];
    int k, i, n, below15 = 0;
    double cand_all, cand_h;
    files[0] = write_file("h.hrz", "# Astro-Physics GTO Horizon File v1.0\n# Az Alt\n0 20\n90 50\n"
                                   "180 10\n270 25\n");
    files[1] = write_file("h.hpts", "[\n  [20, 0],\n  [50, 90],\n  [10.0, 180],\n  [25, 270]\n]\n");
    files[2] = write_file("h.csv", "alt,az\n20,0\n50,90\n10,180\n25,270\n");
    ck_assert_int_eq(plan_cli("--next 1 --json"), 0);
    cand_all = tu_json_num(out, "candidates");
    for (k = 0; k < 3; k++) {
        snprintf(args, sizeof args, "--next 60 --json --horizon '%s'", files[k]);
        ck_assert_msg(plan_cli(args) == 0, "%s", out);
        if (k == 0)
            memcpy(first, out, sizeof first);
        else
            ck_assert_str_eq(out, first);
    }
    cand_h = tu_json_num(first, "candidates");
    n = parse_targets(first, t, 60);
    ck_assert_int_eq(n, 60);
    for (i = 0; i < n; i++) {
        double az = azimuth(t[i].x, t[i].y), h = test_horizon(az);
        ck_assert_msg(t[i].el >= 15 - 1e-9 && t[i].el >= h - 1e-6,
                      "target %d at az %.2f el %.2f below the horizon %.2f", i, az, t[i].el, h);
        below15 += t[i].el < 25; /* low targets exist only where the horizon is low */
    }
    printf("check_plan: horizon file: %.0f of %.0f grid candidates above it; 60 targets above it "
           "(%d below 25 deg elevation)\n", cand_h, cand_all, below15);
    ck_assert(cand_h < 0.9 * cand_all);
    ck_assert_int_gt(below15, 0);
}
END_TEST

/* A star catalogue: named targets, each once, above the horizon at the
** given sidereal time; --utc with --lon places them at the ERFA sidereal
** time (to the precession since J2000). */
START_TEST(test_plan_catalogue)
{
    static char text[1 << 14];
    static cli_target t[20], u[20];
    double ra[60], dec[60];
    char args[512], line[128];
    const char *cat;
    int i, j, n, above = 0;
    tu_rng r;
    tu_seed(&r, 31);
    text[0] = 0;
    for (i = 0; i < 60; i++) {
        ra[i] = 24 * tu_uniform(&r);
        dec[i] = asin(2 * tu_uniform(&r) - 1) / DEG;
        if (i % 3 == 0)
            snprintf(line, sizeof line, "%.6f %+.6f Star %02d\n", ra[i], dec[i], i);
        else if (i % 3 == 1) /* name first, sexagesimal */
            snprintf(line, sizeof line, "S%02d %02d:%02d:%06.3f %c%02d:%02d:%05.2f\n", i,
                     (int)ra[i], (int)(fmod(ra[i] * 60, 60)), fmod(ra[i] * 3600, 60),
                     dec[i] < 0 ? '-' : '+', (int)fabs(dec[i]), (int)fmod(fabs(dec[i]) * 60, 60),
                     fmod(fabs(dec[i]) * 3600, 60));
        else
            snprintf(line, sizeof line, "%.6f,%.6f\n", ra[i], dec[i]); /* no name */
        strcat(text, line);
        {
            double ha = remainder((6.0 - ra[i]) * 15, 360.0);
            above += elevation(ha, dec[i]) >= 15;
        }
    }
    cat = write_file("stars.txt", text);
    snprintf(args, sizeof args, "--next 20 --json --catalog '%s' --lst 6", cat);
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    ck_assert_int_eq((int)tu_json_num(out, "catalogue_stars"), 60);
    ck_assert_int_eq((int)tu_json_num(out, "candidates"), above); /* one side each (GEM, run rule) */
    n = parse_targets(out, t, 20);
    ck_assert_int_eq(n, 20);
    ck_assert_ptr_null(strstr(out, "targets asked for"));
    /* more asked for than there are stars above the horizon: all of them,
    ** and the note says so */
    snprintf(args, sizeof args, "--next %d --json --catalog '%s' --lst 6", above + 5, cat);
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    snprintf(line, sizeof line, "only %d of the %d targets asked for: the catalogue has no more",
             above, above + 5);
    ck_assert_msg(strstr(out, line) != NULL, "%s", out);
    snprintf(args, sizeof args, "--next 20 --json --catalog '%s' --lst 6", cat);
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    for (i = 0; i < n; i++) {
        int k = -1;
        ck_assert(t[i].name[0]);
        if (t[i].name[0] == 'S' && t[i].name[1] == 't')
            k = atoi(t[i].name + 5);
        else if (t[i].name[0] == 'S')
            k = atoi(t[i].name + 1);
        else
            k = atoi(t[i].name + 5) - 1; /* "line N" */
        ck_assert_msg(k >= 0 && k < 60, "%s", t[i].name);
        ck_assert(fabs(remainder(t[i].x - (6.0 - ra[k]) * 15, 360.0)) < 2e-3);
        ck_assert(fabs(t[i].y - dec[k]) < 2e-3);
        ck_assert(t[i].el >= 15);
        for (j = 0; j < i; j++)
            ck_assert_str_ne(t[i].name, t[j].name);
    }
    /* --utc: 2024-03-20T04:00 at 20 deg east; the ERFA sidereal time */
    {
        double u1, u2, lst;
        int same = 0;
        eraDtf2d("UTC", 2024, 3, 20, 4, 0, 0, &u1, &u2);
        lst = eraAnp(eraGmst06(u1, u2, u1, u2) + 20 * DEG) / DEG / 15;
        snprintf(args, sizeof args, "--next 20 --json --catalog '%s' --lst %.9f", cat, lst);
        ck_assert_msg(plan_cli(args) == 0, "%s", out);
        ck_assert_int_eq(parse_targets(out, t, 20), 20);
        snprintf(args, sizeof args,
                 "--next 20 --json --catalog '%s' --utc 2024-03-20T04:00 --lon 20", cat);
        ck_assert_msg(plan_cli(args) == 0, "%s", out);
        ck_assert_int_eq(parse_targets(out, u, 20), 20);
        for (i = 0; i < 20; i++) /* the same stars nearly everywhere; places within 0.5 deg */
            for (j = 0; j < 20; j++)
                if (!strcmp(t[i].name, u[j].name)) {
                    /* 24 years of precession (0.33 deg) and aberration */
                    double sep = tu_angle(t[i].x * DEG, t[i].y * DEG, u[j].x * DEG, u[j].y * DEG);
                    ck_assert_msg(sep < 0.5 * DEG, "%s: %.3f deg", t[i].name, sep / DEG);
                    ck_assert(sep > 0.05 * DEG); /* the J2000 places were precessed */
                    same++;
                }
        ck_assert_int_ge(same, 15);
    }
}
END_TEST

/* A star listed twice (under another name, or the same) is a candidate
** once, and the note says so: it was proposed twice (an outside probe). */
START_TEST(test_plan_catalogue_star_twice)
{
    static char text[1 << 13];
    static cli_target t[40];
    char args[512], line[128];
    const char *cat;
    int i, j, n;
    tu_rng r;
    tu_seed(&r, 77);
    text[0] = 0;
    for (i = 0; i < 30; i++) {
        double ra = 24 * tu_uniform(&r), dec = asin(2 * tu_uniform(&r) - 1) / DEG;
        snprintf(line, sizeof line, "%.6f %+.6f Star %02d\n", ra, dec, i);
        strcat(text, line);
        if (i % 6 == 0) { /* again, under another name, to 0.1" */
            snprintf(line, sizeof line, "Again%02d %.8f %+.8f\n", i, ra + 0.1 / 15 / 3600, dec);
            strcat(text, line);
        }
    }
    cat = write_file("twice.txt", text);
    snprintf(args, sizeof args, "--next 40 --json --catalog '%s' --lst 6", cat);
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    ck_assert_msg(strstr(out, "the catalogue lists 5 stars twice, taken once") != NULL, "%s", out);
    n = parse_targets(out, t, 40);
    ck_assert_int_gt(n, 5);
    for (i = 0; i < n; i++)
        for (j = 0; j < i; j++)
            ck_assert_msg(tu_angle(t[i].x * DEG, t[i].y * DEG, t[j].x * DEG, t[j].y * DEG) >
                              1e-3 * DEG,
                          "%s and %s: one place", t[i].name, t[j].name);
}
END_TEST

/* The highest elevation of the targets in plan_cli's JSON output. */
static double highest_target(void)
{
    const char *p = strstr(out, "\"targets\": [");
    double hi = -90;
    ck_assert_ptr_nonnull(p);
    while ((p = strstr(p, "\"elevation_deg\": ")) != NULL) {
        double el = atof(p + strlen("\"elevation_deg\": "));
        if (el > hi)
            hi = el;
        p++;
    }
    return hi;
}

/* An alt-az mount is planned below 85 deg by default (the zenith keyhole:
** targets at 87-89 deg were proposed, an outside probe), --max-el sets it
** for any mount; above --min-el and at most 90, else an error. */
START_TEST(test_plan_max_el)
{
    ck_assert_msg(plan_cli("--lat 47 --mount altaz --next 30 --grid 2 --json") == 0, "%s", out);
    printf("check_plan: alt-az, 30 targets on a 2 deg grid: highest %.2f deg\n", highest_target());
    ck_assert(highest_target() <= 85 + 1e-9);
    ck_assert_msg(plan_cli("--lat 47 --mount altaz --next 30 --grid 2 --max-el 90 --json") == 0,
                  "%s", out);
    ck_assert(highest_target() > 85); /* the keyhole's places are the plan's best there */
    ck_assert_msg(plan_cli("--lat 47 --next 20 --max-el 60 --json") == 0, "%s", out);
    ck_assert(highest_target() <= 60 + 1e-9);
    ck_assert_int_ne(plan_cli("--lat 47 --next 5 --min-el 30 --max-el 20"), 0);
    ck_assert_msg(strstr(out, "--max-el must be above --min-el") != NULL, "%s", out);
    /* --fork is of an equatorial mount (an alt-az plan ignored it; a probe) */
    ck_assert_int_ne(plan_cli("--lat 47 --mount altaz --next 5 --fork"), 0);
    ck_assert_msg(strstr(out, "--fork is for an equatorial mount") != NULL, "%s", out);
}
END_TEST

/* D-optimal: another plan; the I-optimal one has the lower mean predicted
** error (its criterion).  Physical terms: the plan determines them. */
/* Few stars for the model (an outside probe): from nothing, 12 targets at
** order 1 (22 terms) and 26 at order 2 (46) are better than a golden
** spiral's as many points, predicted and in truth (the I criterion's greedy
** picks had predicted 17.5" where the spiral's gave 3.0": while the points
** did not determine the model it chose by the ridge's variances); and a
** fork's closed loop, one target at a time from 3 stars, ends at 12 better
** than the spiral too. */
START_TEST(test_plan_few_stars)
{
    static pmplan_target plan[40], g[40];
    static const int orders[2] = {1, 2}, sizes[2] = {12, 26};
    pmplan_options o;
    char err[512];
    double b;
    int k;
    for (k = 0; k < 2; k++) {
        const int n = sizes[k];
        double pp, pg, rp, rg;
        pmplan_options_default(&o);
        o.order = orders[k];
        ck_assert_msg(pmplan_next(NULL, &o, n, plan, &b, err, sizeof err) == n, "%s", err);
        grid(n, g);
        pp = predicted(&o, plan, n);
        pg = predicted(&o, g, n);
        rp = real_error(o.order, plan, n, 20);
        rg = real_error(o.order, g, n, 20);
        printf("check_plan: order %d, %d points from nothing: plan predicted %.3f\" real %.3f\", "
               "golden spiral predicted %.3f\" real %.3f\"\n", o.order, n, pp, rp, pg, rg);
        ck_assert(pp < pg);
        ck_assert(rp < rg);
    }
    {
        /* the loop: a fork at order 1, each star observed with 1" noise */
        static const double iso[6] = {60, -40, 600, 30, -300, 20};
        static char text[1 << 14];
        pm_model truth;
        tu_rng r;
        int i, n = 3;
        double pp, pg;
        const char *path = NULL;
        ck_assert_int_eq(pm_model_init(&truth, PM_MOUNT_EQUATORIAL, 1), PM_OK);
        for (i = 0; i < 6; i++)
            truth.coef[i] = iso[i] * ARCSEC;
        ck_assert_int_eq(pm_model_prepare(&truth), PM_OK);
        tu_seed(&r, 31);
        random_points(3, &r, plan);
        pmplan_options_default(&o);
        o.gem = 0;
        for (;;) {
            snprintf(text, sizeof text, "# latitude: %g\n# tau delta T D\n", LAT);
            for (i = 0; i < n; i++) {
                double t = plan[i].x_deg * DEG, d = plan[i].y_deg * DEG, ah, ad;
                char line[160];
                ck_assert_int_eq(pm_model_apply(&truth, NULL, t, d, &ah, &ad), PM_OK);
                ad += ARCSEC * tu_gauss(&r);
                ah += ARCSEC * tu_gauss(&r) / cos(ad);
                snprintf(line, sizeof line, "%.9f %.9f %.9f %.9f\n", t / DEG, d / DEG, ah / DEG,
                         ad / DEG);
                strcat(text, line);
            }
            if (n == 12)
                break;
            path = write_file("loop.dat", text);
            ck_assert_msg(pmplan_next(path, &o, 1, &plan[n], &b, err, sizeof err) == 1, "%s", err);
            n++;
        }
        for (i = 0; i < 12; i++)
            plan[i].side = 1;
        grid(12, g);
        for (i = 0; i < 12; i++)
            g[i].side = 1;
        pp = predicted(&o, plan, 12);
        pg = predicted(&o, g, 12);
        printf("check_plan: a fork's closed loop at order 1, 3 stars + 9 one at a time: predicted "
               "%.3f\", golden spiral %.3f\"\n", pp, pg);
        ck_assert(pp < pg);
    }
}
END_TEST

START_TEST(test_plan_criteria_and_terms)
{
    static pmplan_target pi[40], pd[40], pt[40];
    pmplan_options o;
    char err[512];
    double b, ei, ed;
    int i, same = 0;
    pmplan_options_default(&o);
    ck_assert_int_eq(pmplan_next(NULL, &o, 40, pi, &b, err, sizeof err), 40);
    o.d_optimal = 1;
    ck_assert_int_eq(pmplan_next(NULL, &o, 40, pd, &b, err, sizeof err), 40);
    for (i = 0; i < 40; i++)
        same += pi[i].x_deg == pd[i].x_deg && pi[i].y_deg == pd[i].y_deg;
    o.d_optimal = 0;
    ei = predicted(&o, pi, 40);
    ed = predicted(&o, pd, 40);
    printf("check_plan: order 1, 40 points: predicted mean error I-optimal %.4f\", D-optimal "
           "%.4f\" (%d of 40 targets the same)\n", ei, ed, same);
    ck_assert_int_lt(same, 40);
    ck_assert(ei < ed);
    /* refraction and tube flexure at order 0: determined within 20 points */
    o.order = 0;
    o.adds = "refraction,tube_flexure";
    ck_assert_msg(pmplan_next(NULL, &o, 20, pt, &b, err, sizeof err) == 20, "%s", err);
    ck_assert(isfinite(pt[19].after_arcsec));
    ck_assert(pt[19].after_arcsec < pt[7].after_arcsec || !isfinite(pt[7].after_arcsec));
    /* tube flexure at order 1 is part of the order-1 terms: no plan can
    ** determine it, and the plan says so */
    o.order = 1;
    o.adds = "tube_flexure";
    ck_assert_int_eq(pmplan_next(NULL, &o, 5, pt, &b, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "no set of points on this sky can determine"));
}
END_TEST

/* Slew-time weighting: much shorter slews, each target's time at least the
** settle and point time. */
START_TEST(test_plan_slew)
{
    static cli_target a[15], w[15];
    double da = 0, dw = 0;
    int i;
    ck_assert_int_eq(plan_cli("--next 15 --json --sides meridian"), 0);
    ck_assert_int_eq(parse_targets(out, a, 15), 15);
    ck_assert_int_eq(plan_cli("--next 15 --json --sides meridian --slew 2 --settle 4 "
                              "--point-time 20 --flip-time 90"), 0);
    ck_assert_int_eq(parse_targets(out, w, 15), 15);
    for (i = 1; i < 15; i++) {
        /* encoder axis moves: beyond the pole HA + 180, Dec 180 - dec */
        double t0 = a[i - 1].x + (a[i - 1].side < 0 ? 180 : 0), t1 = a[i].x + (a[i].side < 0 ? 180 : 0);
        double d0 = a[i - 1].side < 0 ? 180 - a[i - 1].y : a[i - 1].y;
        double d1 = a[i].side < 0 ? 180 - a[i].y : a[i].y;
        da += fmax(fabs(remainder(t1 - t0, 360.0)), fabs(d1 - d0));
        t0 = w[i - 1].x + (w[i - 1].side < 0 ? 180 : 0), t1 = w[i].x + (w[i].side < 0 ? 180 : 0);
        d0 = w[i - 1].side < 0 ? 180 - w[i - 1].y : w[i - 1].y;
        d1 = w[i].side < 0 ? 180 - w[i].y : w[i].y;
        dw += fmax(fabs(remainder(t1 - t0, 360.0)), fabs(d1 - d0));
        ck_assert(w[i].time_s >= 24 - 1e-9);
        ck_assert(fabs(w[i].time_s - (24 + fmax(fabs(remainder(t1 - t0, 360.0)), fabs(d1 - d0)) / 2 +
                                      (w[i].side != w[i - 1].side ? 90 : 0))) < 0.01);
    }
    printf("check_plan: 15 targets: slews of %.0f deg in all, with --slew %.0f deg\n", da, dw);
    ck_assert(dw < 0.5 * da);
    /* While the points do not determine the model the quickest of the
    ** nearly best is taken, not the best per second: an order-2 plan of 40
    ** (an outside probe's) had stayed on one side of the meridian, 2,000"
    ** off, and order 1 printed "predicted 0.000"" from the 19th target on
    ** (the criterion updated step by step had drifted below 0) */
    {
        static pmplan_target ps[40], pn[40];
        pmplan_options o;
        char err[512];
        double b, es, en;
        int k, east = 0, west = 0;
        pmplan_options_default(&o);
        o.order = 2;
        ck_assert_msg(pmplan_next(NULL, &o, 40, pn, &b, err, sizeof err) == 40, "%s", err);
        o.slew_rate_deg_s = 2;
        ck_assert_msg(pmplan_next(NULL, &o, 40, ps, &b, err, sizeof err) == 40, "%s", err);
        for (k = 0; k < 40; k++) {
            ck_assert_msg(isnan(ps[k].after_arcsec) || ps[k].after_arcsec > 0.1, "target %d: %g", k,
                          ps[k].after_arcsec);
            east += ps[k].x_deg < -15;
            west += ps[k].x_deg > 15;
        }
        o.slew_rate_deg_s = 0;
        es = predicted(&o, ps, 40);
        en = predicted(&o, pn, 40);
        printf("check_plan: order 2, 40 targets: predicted %.3f\" with --slew 2, %.3f\" without; "
               "%d east and %d west of the meridian\n", es, en, east, west);
        ck_assert(es < 2 * en);
        ck_assert(east >= 8 && west >= 8);
        o.order = 1;
        o.slew_rate_deg_s = 2;
        ck_assert_msg(pmplan_next(NULL, &o, 25, ps, &b, err, sizeof err) == 25, "%s", err);
        for (k = 0; k < 25; k++)
            ck_assert_msg(isnan(ps[k].after_arcsec) || ps[k].after_arcsec > 0.1, "order 1, target %d: %g",
                          k, ps[k].after_arcsec);
    }
}
END_TEST

/* Pier sides: meridian -- beyond the pole exactly west of the meridian;
** both -- either side within the limit, and the plan uses both there. */
/* The meridian rule: without a run ASCOM's normal pointing state (pier +1,
** pierEast) takes the sky west of the meridian, beyond the pole the east;
** with a run, the run's own (it was hard-coded the other way round, so on
** the real German runs every target away from the meridian was proposed on
** a side the mount never used there, and the predicted error was of that
** mirrored sky: 235" where the fit's map said 47"). */
static void sides_follow(const char *run, int normal_west, int n_want)
{
    static cli_target t[120];
    char args[1024];
    int i, n, far = 0;
    snprintf(args, sizeof args, "%s --next %d --json --grid 4", run, n_want);
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    n = parse_targets(out, t, 120);
    ck_assert_int_eq(n, n_want);
    for (i = 0; i < n; i++)
        if (fabs(t[i].x) > 15 + 1e-9) {
            far++;
            ck_assert_msg(t[i].side == (t[i].x > 0 ? normal_west : -normal_west),
                          "%s: target %d at HA %+.2f deg on side %+d", run, i, t[i].x,
                          t[i].side);
        }
    printf("check_plan: sides %s: %d of %d targets beyond 15 deg of the meridian, each on the "
           "side the %s takes there\n", run[0] ? run : "(no run)", far, n,
           run[0] ? "run" : "normal pointing state");
    ck_assert_int_gt(far, n / 3);
}

START_TEST(test_plan_sides)
{
    static cli_target t[120];
    int i, n, crossed = 0;
    char path[512], sim[512];
    const char *top = getenv("PM_TOP");
    ck_assert_int_eq(plan_cli("--next 80 --json --sides meridian"), 0);
    n = parse_targets(out, t, 120);
    for (i = 0; i < n; i++)
        ck_assert_int_eq(t[i].side, t[i].x > 0 ? 1 : -1);
    ck_assert_int_eq(plan_cli("--next 120 --json --sides both --meridian-limit 20 --grid 4"), 0);
    n = parse_targets(out, t, 120);
    ck_assert_int_eq(n, 120);
    for (i = 0; i < n; i++) {
        ck_assert(t[i].side > 0 ? t[i].x >= -20 - 1e-9 : t[i].x <= 20 + 1e-9);
        crossed += t[i].side != (t[i].x > 0 ? 1 : -1);
    }
    printf("check_plan: --sides both: %d of 120 targets past the meridian on the other side\n",
           crossed);
    ck_assert_int_gt(crossed, 0);
    /* a run's own convention: pmsim flips west of the meridian (the other
    ** way round from ASCOM's), the real German runs east */
    sides_follow("", 1, 40);
    snprintf(sim, sizeof sim, "%s/examples/sim_gem.dat", top ? top : ".");
    sides_follow(sim, -1, 40);
    if (tu_real_run("celestial/gem-28.dat", path, sizeof path))
        sides_follow(path, 1, 40);
    {   /* a fork's run planned without --fork: normal-side points on both
        ** sides of the meridian; every target was put beyond the pole */
        char cmd[1024];
        int k, n2;
        snprintf(cmd, sizeof cmd, "%s simulate %s/fork.dat --fork --seed 5 >/dev/null 2>&1",
                 tu_pmfit_path(), tmpdir_once());
        ck_assert_int_eq(system(cmd), 0);
        snprintf(cmd, sizeof cmd, "%s/fork.dat --next 12 --json", tmpdir_once());
        ck_assert_msg(plan_cli(cmd) == 0, "%s", out);
        ck_assert_msg(strstr(out, "a mount that does not flip, planned as one (--fork)"), "%s", out);
        n2 = parse_targets(out, t, 120);
        ck_assert_int_eq(n2, 12);
        for (k = 0; k < n2; k++)
            ck_assert_int_eq(t[k].side, 1);
    }
    if (tu_real_run("celestial/cgx-l-data.dat", path, sizeof path))
        sides_follow(path, 1, 40);
}
END_TEST

/* ---------------------------------------------- a controller (C API only) */

pm_status next_star(const pm_fit *fit, const pm_fit_result *res, const pm_model *m,
                    const pm_context *ctx, const double *cand, int n_cand,
                    const unsigned char *taken, const double *sky, int n_sky, int d_optimal,
                    int *best, double *score);

#define NCAND 300
#define NSKYC 400

/* Encoder positions of random places above 15 deg (meridian rule). */
static void encoder_places(tu_rng *r, int n, double *out)
{
    pmplan_target p;
    int i;
    for (i = 0; i < n; i++) {
        random_points(1, r, &p);
        out[2 * i] = p.x_deg * DEG + (p.side < 0 ? M_PI : 0);
        out[2 * i + 1] = p.side < 0 ? M_PI - p.y_deg * DEG : p.y_deg * DEG;
    }
}

/* The mean predicted variance over the sky of the fit (rad^2). */
static double mean_var(const pm_fit_result *res, const pm_model *m, const double *sky)
{
    double s, ss = 0;
    int g;
    for (g = 0; g < NSKYC; g++) {
        ck_assert_int_eq(pm_fit_pointing_sigma(&fit, res, m, NULL, sky[2 * g], sky[2 * g + 1], &s,
                                               NULL), PM_OK);
        ss += s * s;
    }
    return ss / NSKYC;
}

/* A simulated night driven by the controller (mode 0 I-optimal, 1
** D-optimal, 2 random candidates): 12 start points, then 28 chosen; the
** final mean predicted variance over the sky. */
static double drive(int mode)
{
    static double cand[2 * NCAND], sky[2 * NSKYC], eh[64], ed[64], ah[64], ad[64];
    static unsigned char taken[NCAND];
    pm_model truth, m;
    pm_fit_result res;
    tu_rng r, noise;
    int i, n = 0;
    static const double iso[6] = {60, -40, 600, 30, -300, 20};
    ck_assert_int_eq(pm_model_init(&truth, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    for (i = 0; i < 6; i++)
        truth.coef[i] = iso[i] * ARCSEC;
    tu_seed(&r, 77);
    for (i = 6; i < truth.n_terms; i++)
        truth.coef[i] = (2 * tu_uniform(&r) - 1) * 15 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&truth), PM_OK);
    tu_seed(&r, 5);
    encoder_places(&r, NCAND, cand);
    encoder_places(&r, NSKYC, sky);
    memset(taken, 0, sizeof taken);
    tu_seed(&noise, 9);
    for (i = 0; i < 40; i++) {
        int k = i;
        if (i >= 12) {
            double score;
            ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
            ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, n, eh, ed, ah, ad, 50, &res), PM_OK);
            if (mode < 2)
                ck_assert_int_eq(next_star(&fit, &res, &m, NULL, cand, NCAND, taken, sky, NSKYC,
                                           mode, &k, &score), PM_OK);
            ck_assert_int_ge(k, 0);
        }
        taken[k] = 1;
        eh[n] = cand[2 * k];
        ed[n] = cand[2 * k + 1];
        ck_assert_int_eq(pm_model_apply(&truth, NULL, eh[n], ed[n], &ah[n], &ad[n]), PM_OK);
        ad[n] += ARCSEC * tu_gauss(&noise);
        ah[n] += ARCSEC * tu_gauss(&noise) / cos(ad[n]);
        n++;
    }
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, n, eh, ed, ah, ad, 50, &res), PM_OK);
    return mean_var(&res, &m, sky);
}

START_TEST(test_plan_controller)
{
    double vi = drive(0), vd = drive(1), vr = drive(2);
    printf("check_plan: controller (examples/next_star.c), 40 stars: predicted mean error over "
           "the sky I-optimal %.3f\", D-optimal %.3f\", the next candidates in turn %.3f\"\n",
           sqrt(vi) / ARCSEC, sqrt(vd) / ARCSEC, sqrt(vr) / ARCSEC);
    ck_assert(vi < 0.8 * vr);
    ck_assert(vd < 0.8 * vr);
}
END_TEST

/* The D score of next_star is the rise of log det of the information by
** the star: against the unit covariances of the fit with and without it
** (the star observed at the model's prediction, so the refit does not
** move). */
static double log_det_cov(const pm_fit_result *res, int P)
{
    static double a[PM_MAX_TERMS * PM_MAX_TERMS];
    pm_fit_result unit = *res;
    double ld = 0;
    int i, j, k;
    unit.sigma = 1;
    for (i = 0; i < P; i++)
        for (j = 0; j < P; j++)
            ck_assert_int_eq(pm_fit_covariance(&fit, &unit, i, j, &a[i * P + j], NULL), PM_OK);
    for (j = 0; j < P; j++) { /* Cholesky in place */
        double s = a[j * P + j];
        for (k = 0; k < j; k++)
            s -= a[j * P + k] * a[j * P + k];
        ck_assert(s > 0);
        a[j * P + j] = sqrt(s);
        ld += 2 * log(a[j * P + j]);
        for (i = j + 1; i < P; i++) {
            double t = a[i * P + j];
            for (k = 0; k < j; k++)
                t -= a[i * P + k] * a[j * P + k];
            a[i * P + j] = t / a[j * P + j];
        }
    }
    return ld;
}

START_TEST(test_plan_d_score)
{
    static double eh[41], ed[41], ah[41], ad[41], cand[2], pairs[80];
    unsigned char taken[1] = {0};
    pm_model truth, m, m2;
    pm_fit_result res, res2;
    tu_rng r;
    int i, best;
    double score, before, after;
    ck_assert_int_eq(pm_model_init(&truth, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    truth.coef[2] = 600 * ARCSEC;
    ck_assert_int_eq(pm_model_prepare(&truth), PM_OK);
    tu_seed(&r, 12);
    encoder_places(&r, 40, pairs);
    for (i = 0; i < 40; i++) {
        eh[i] = pairs[2 * i];
        ed[i] = pairs[2 * i + 1];
    }
    for (i = 0; i < 40; i++) {
        ck_assert_int_eq(pm_model_apply(&truth, NULL, eh[i], ed[i], &ah[i], &ad[i]), PM_OK);
        ad[i] += ARCSEC * tu_gauss(&r);
        ah[i] += ARCSEC * tu_gauss(&r) / cos(ad[i]);
    }
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 1), PM_OK);
    ck_assert_int_eq(pm_fit_run(&fit, &m, NULL, 40, eh, ed, ah, ad, 50, &res), PM_OK);
    before = log_det_cov(&res, m.n_terms);
    encoder_places(&r, 1, cand);
    ck_assert_int_eq(next_star(&fit, &res, &m, NULL, cand, 1, taken, NULL, 0, 1, &best, &score),
                     PM_OK);
    ck_assert_int_eq(best, 0);
    /* the star at the model's prediction, with the noise of the fit */
    eh[40] = cand[0];
    ed[40] = cand[1];
    ck_assert_int_eq(pm_model_apply(&m, NULL, eh[40], ed[40], &ah[40], &ad[40]), PM_OK);
    m2 = m;
    ck_assert_int_eq(pm_fit_run(&fit, &m2, NULL, 41, eh, ed, ah, ad, 50, &res2), PM_OK);
    after = log_det_cov(&res2, m.n_terms);
    printf("check_plan: D score %.9f, log det of the unit covariance fell by %.9f\n", score,
           before - after);
    ck_assert(fabs(score - (before - after)) < 1e-6 * fabs(score) + 1e-9);
    taken[0] = 1;
    ck_assert_int_eq(next_star(&fit, &res2, &m2, NULL, cand, 1, taken, NULL, 0, 1, &best, &score),
                     PM_OK);
    ck_assert_int_eq(best, -1);
}
END_TEST

/* Bad inputs: each a clear error, files with their line. */
START_TEST(test_plan_bad_inputs)
{
    static const char *const bad[][3] = {
        /* name, contents, expected message */
        {"bad.hrz", "0 20\n90 fifty\n", "bad.hrz:2: expected 'azimuth elevation'"},
        {"bad3.hrz", "0 20 30\n", "bad3.hrz:1: expected 'azimuth elevation'"},
        {"badaz.hrz", "0 20\n400 10\n", "badaz.hrz:2: azimuth 400"},
        {"bad.hpts", "[[20, 0], [30 90]]\n", "bad.hpts:1: malformed .hpts"},
        {"empty.hrz", "# nothing\n", "empty.hrz: no horizon points"},
    };
    static const char *const badcat[][3] = {
        {"c1.txt", "18:36:56 +38:47:01 Vega\nAltair 19:50:47\n", "c1.txt:2: expected 'RA Dec"},
        {"c2.txt", "279.23 38.78 Vega\n", "c2.txt:1: RA 279.23 is outside 0..24 h"},
        {"c3.txt", "# no stars\n\n", "c3.txt: the catalogue has no stars"},
        {"c4.txt", "12:61:00 +10:00:00 x\n", "c4.txt:1: expected 'RA Dec"},
        {"c5.txt", "12:00:00 +95:00:00 x\n", "c5.txt:1: Dec +95:00:00 is outside"},
    };
    char args[512];
    size_t k;
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        const char *p = write_file(bad[k][0], bad[k][1]);
        snprintf(args, sizeof args, "--horizon '%s'", p);
        ck_assert_int_eq(plan_cli(args), 1);
        ck_assert_msg(strstr(out, bad[k][2]) != NULL, "%s: %s", bad[k][0], out);
    }
    for (k = 0; k < sizeof badcat / sizeof badcat[0]; k++) {
        const char *p = write_file(badcat[k][0], badcat[k][1]);
        snprintf(args, sizeof args, "--catalog '%s' --lst 3", p);
        ck_assert_int_eq(plan_cli(args), 1);
        ck_assert_msg(strstr(out, badcat[k][2]) != NULL, "%s: %s", badcat[k][0], out);
    }
    /* no candidate above the horizon: a southern star from latitude 47 */
    snprintf(args, sizeof args, "--catalog '%s' --lst 12",
             write_file("south.txt", "12:00:00 -80:00:00 Octans region\n"));
    ck_assert_int_eq(plan_cli(args), 1);
    ck_assert_ptr_nonnull(strstr(out, "none of the 1 catalogue stars is above 15 deg"));
    snprintf(args, sizeof args, "--horizon '%s'", write_file("wall.hrz", "0 90\n180 90\n"));
    ck_assert_int_eq(plan_cli(args), 1);
    ck_assert_ptr_nonnull(strstr(out, "no usable sky above 15 deg elevation and the horizon"));
    /* a catalogue without its time; the time without a catalogue; a slew
    ** option without the slew model; an unknown criterion or side rule */
    snprintf(args, sizeof args, "--catalog '%s'", write_file("one.txt", "1 2 x\n"));
    ck_assert_int_eq(plan_cli(args), 2);
    ck_assert_ptr_nonnull(strstr(out, "--catalog needs the time"));
    ck_assert_int_eq(plan_cli("--lst 3"), 2);
    ck_assert_ptr_nonnull(strstr(out, "add --catalog FILE"));
    ck_assert_int_eq(plan_cli("--flip-time 30"), 2);
    ck_assert_ptr_nonnull(strstr(out, "add --slew"));
    ck_assert_int_eq(plan_cli("--criterion A"), 2);
    ck_assert_ptr_nonnull(strstr(out, "--criterion: expected I"));
    ck_assert_int_eq(plan_cli("--sides east"), 2);
    ck_assert_ptr_nonnull(strstr(out, "--sides: expected run, meridian or both"));
    ck_assert_int_eq(plan_cli("--utc 2024-13-01T00:00 --lon 10 --catalog x"), 1);
    /* a time with anything after its minutes or seconds: refused (04:00x
    ** was taken as 04:00) */
    {
        static const char *utc[4] = {"2024-03-20T04:00x", "2024-03-20T04:00:30x",
                                     "2024-03-20T04:00:", "2024-03-20T04:00:30"};
        const char *top = getenv("PM_TOP");
        int k;
        for (k = 0; k < 4; k++) {
            snprintf(args, sizeof args, "--utc %s --lon 20 --catalog '%s/examples/bright_stars.txt'",
                     utc[k], top && *top ? top : ".");
            if (k < 3) {
                ck_assert_msg(plan_cli(args) == 1, "%s: %s", utc[k], out);
                ck_assert_msg(strstr(out, "--utc: expected YYYY-MM-DDTHH:MM[:SS]") != NULL, "%s",
                              out);
            } else {
                ck_assert_msg(plan_cli(args) == 0, "%s: %s", utc[k], out);
            }
        }
    }
    /* --mount against the run's own mount: its observations would be read
    ** as the other mount's axes (it planned an alt-az sky from a German run
    ** before); the same mount is accepted */
    {
        const char *top = getenv("PM_TOP");
        snprintf(args, sizeof args, "'%s/examples/sim_gem.dat' --mount altaz --next 1",
                 top && *top ? top : ".");
        ck_assert_int_eq(plan_cli(args), 2);
        ck_assert_msg(strstr(out, "plan: --mount altaz, but ") != NULL &&
                          strstr(out, "is a run of an equatorial mount; its mount is the "
                                      "plan's: drop --mount") != NULL,
                      "%s", out);
        snprintf(args, sizeof args, "'%s/examples/sim_gem.dat' --mount equatorial --next 1",
                 top && *top ? top : ".");
        ck_assert_int_eq(plan_cli(args), 0);
    }
    /* the C access reports file errors too */
    {
        pmplan_options o;
        pmplan_target t[2];
        char err[512];
        double b;
        pmplan_options_default(&o);
        o.horizon_path = write_file("bad.hrz", "0 20\n90 fifty\n");
        ck_assert_int_eq(pmplan_next(NULL, &o, 2, t, &b, err, sizeof err), -1);
        ck_assert_ptr_nonnull(strstr(err, "bad.hrz:2:"));
    }
}
END_TEST

/* A degenerate run (every point at one place): the plan says the run does
** not determine the model and plans from the ideal mount; its first target
** is elsewhere; the run's side is used only near the meridian. */
START_TEST(test_plan_degenerate_run)
{
    static char text[1 << 13];
    static cli_target t[5];
    char args[512], line[128];
    int i;
    snprintf(text, sizeof text, "# latitude: 47\n# tau delta T D pier\n");
    for (i = 0; i < 30; i++) {
        snprintf(line, sizeof line, "-30.0 40.0 -30.01 40.0%d E\n", i % 3);
        strcat(text, line);
    }
    snprintf(args, sizeof args, "'%s' --next 5 --json", write_file("degenerate.dat", text));
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    ck_assert_ptr_nonnull(strstr(out, "do not determine the model"));
    ck_assert_ptr_nonnull(strstr(out, "\"before_arcsec\": null"));
    ck_assert_int_eq(parse_targets(out, t, 5), 5);
    ck_assert(fabs(t[0].x + 30) > 10 || fabs(t[0].y - 40) > 10);
    /* the run used the normal side only; beyond the meridian limit (15 deg)
    ** west of the meridian the targets are beyond the pole all the same */
    {
        static cli_target u[40];
        int n, west = 0;
        snprintf(args, sizeof args, "'%s' --next 40 --json", write_file("degenerate.dat", text));
        ck_assert_msg(plan_cli(args) == 0, "%s", out);
        n = parse_targets(out, u, 40);
        for (i = 0; i < n; i++) {
            if (fabs(u[i].x) > 15)
                ck_assert_int_eq(u[i].side, u[i].x > 0 ? -1 : 1);
            west += u[i].x > 15;
        }
        ck_assert_int_gt(west, 0);
    }
}
END_TEST

/* A run that fits but does not determine the model over the sky (the first
** 13 points of the bundled run, 22 terms): the note says so, and the text
** does not say there are fewer points than half the terms (it did, and of
** 12 points "too few for the 22-term model", while pmfit fit fitted them). */
START_TEST(test_plan_undetermined_words)
{
    char args[1024], cmd[1024];
    const char *top = getenv("PM_TOP");
    snprintf(cmd, sizeof cmd, "head -n 18 %s/examples/sim_gem.dat > %s/s13.dat",
             top ? top : ".", tmpdir_once());
    ck_assert_int_eq(system(cmd), 0);
    snprintf(args, sizeof args, "%s/s13.dat --next 2", tmpdir_once());
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    ck_assert_msg(strstr(out, "the run's 13 points fit the 22-term model but do not determine it "
                              "over the sky") != NULL && !strstr(out, "fewer points than half"),
                  "%s", out);
    snprintf(cmd, sizeof cmd, "head -n 11 %s/examples/sim_gem.dat > %s/s6.dat", top ? top : ".",
             tmpdir_once());
    ck_assert_int_eq(system(cmd), 0);
    snprintf(args, sizeof args, "%s/s6.dat --next 2", tmpdir_once());
    ck_assert_msg(plan_cli(args) == 0, "%s", out);
    ck_assert_msg(strstr(out, "the run's 6 points are too few for the 22-term model") != NULL,
                  "%s", out);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("plan");
    TCase *t = tcase_create("plan");
    tcase_set_timeout(t, 600);
    tcase_add_loop_test(t, test_plan_beats_grid, 0, 3);
    tcase_add_test(t, test_plan_errors);
    tcase_add_test(t, test_plan_horizon);
    tcase_add_test(t, test_plan_catalogue);
    tcase_add_test(t, test_plan_catalogue_star_twice);
    tcase_add_test(t, test_plan_max_el);
    tcase_add_test(t, test_plan_few_stars);
    tcase_add_test(t, test_plan_criteria_and_terms);
    tcase_add_test(t, test_plan_slew);
    tcase_add_test(t, test_plan_sides);
    tcase_add_test(t, test_plan_controller);
    tcase_add_test(t, test_plan_d_score);
    tcase_add_test(t, test_plan_bad_inputs);
    tcase_add_test(t, test_plan_degenerate_run);
    tcase_add_test(t, test_plan_undetermined_words);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
