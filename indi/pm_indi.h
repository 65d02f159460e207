/*
**  pm_indi.h - the INDI math plugin's fitting logic, without INDI: which
**  model a set of sync points supports (order from their number and sky
**  coverage), the fit with its fallbacks, and a one-line description.
**  Used by indi/pm_math_plugin.cpp and tested by tests/check_indi.c.
**  docs/indi.md states the rule.
*/
#ifndef PM_INDI_H
#define PM_INDI_H

#include <stddef.h>
#include "pm.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What the plugin's model is. */
#define PM_INDI_NONE 0   /* no sync points: the identity */
#define PM_INDI_OFFSET 1 /* index offsets only (c', e'): too few points or
                            too small a patch of sky for a fit */
#define PM_INDI_FIT 2    /* a fitted pm model of order pm_indi_result.order */

/* A higher order is kept only if its leave-one-out rms is below
** PM_INDI_CV_GAIN times the lower one's minus PM_INDI_CV_FLOOR (radians;
** 1e-9 rad = 0.0002": noise-free data tie at rounding). */
#define PM_INDI_CV_GAIN 0.8
#define PM_INDI_CV_FLOOR 1e-9

/* Highest order the rule chooses. */
#define PM_INDI_MAX_ORDER 2

/* Sky coverage (radians): the largest distance of a sync point from the
** points' mean direction needed for order 0, 1, 2. */
#define PM_INDI_SPREAD_L0 (10.0 * 3.14159265358979323846 / 180.0)
#define PM_INDI_SPREAD_L1 (30.0 * 3.14159265358979323846 / 180.0)
#define PM_INDI_SPREAD_L2 (60.0 * 3.14159265358979323846 / 180.0)

typedef struct pm_indi_result {
    int kind;          /* PM_INDI_* */
    int order;         /* fitted order (PM_INDI_FIT), else -1 */
    int chosen_order;  /* what the rule asked for (-1: offsets) */
    double spread;     /* coverage (radians) */
    double sigma;      /* fit residual (radians; 0 for NONE/OFFSET) */
    int n_par;         /* parameters of the model used */
    int fallbacks;     /* orders given up (singular or diverged fits) */
    double cv[PM_INDI_MAX_ORDER + 1]; /* leave-one-out rms per axis of each
                          order fitted (radians; -1 not fitted, HUGE_VAL
                          when a point alone determines terms) */
    char bad_term[64]; /* why the last given-up fit failed: the term that
                          made it singular, else pm's status in words
                          ("the fit did not converge") */
    long worst;        /* the point (0-based, of those given; the plugin
                          turns it into the database entry's) the others'
                          fit misses most, by its leave-one-out residual
                          (PM_INDI_FIT), else -1; pm_indi_describe names
                          it as "sync point worst + 1" */
    double worst_loo;  /* that residual, the whole miss (both axes, radians) */
    int failed;        /* pm's status of the last given-up fit (0: none) */
    double corr;       /* the used fit's largest |correlation| of two terms
                          (PM_INDI_FIT; 0 otherwise), signed */
    char corr_pair[64]; /* their names, "c' and i" */
    double gain;       /* the used fit's own pointing error over the sky per
                          unit residual sigma (RMS; Note 2); 0 if none */
    int axis1_unset;   /* PM_INDI_OFFSET with every sync point within
                          PM_INDI_POLE_CAP of the pole (an alt-az mount's
                          zenith): the index offsets are left at 0 and
                          the tilt fitted instead (Note 3) */
    double axis1_read; /* then the axis-1 offset the points read (radians) */
    double axis1_sec;  /* and the least 1 / cos(axis 2) of them */
    double tilt;       /* then the tilt of the polar (azimuth) axis fitted instead
                          (radians; Note 3) */
    int altaz;         /* the mount is alt-az (the words of the description) */
    long east, west;   /* equatorial: sync points more than PM_INDI_MERIDIAN_GAP
                          east and west of the meridian (a German mount's two
                          pier sides, which INDI does not record) */
} pm_indi_result;

/* A fit of a German mount's sync points on both sides of the meridian
** (two or more more than this hour angle from it on each) with sigma above
** PM_INDI_SIDES_SIGMA (radians) is told that INDI does not record the pier
** side (docs/indi.md, quirk 7): an outside probe's 2' collimation and 1'
** non-perpendicularity, synced on both sides, gave GOTOs 150-470" off and a
** sigma of 126" with no word of why. */
#define PM_INDI_MERIDIAN_GAP (0.5 * 3.14159265358979323846 / 180.0)
#define PM_INDI_SIDES_SIGMA (10.0 / 206264.80624709636)

/* Index offsets only, every sync point within this of the pole (zenith):
** the axis-1 (hour-angle, azimuth) index is not read from them (Note 3). */
#define PM_INDI_POLE_CAP (10.0 * 3.14159265358979323846 / 180.0)

/* A fit whose own pointing error over the sky is more than this many
** times its residual sigma (pm_indi_result.gain) does not determine the
** model between its points: pm_indi_describe says so (pmfit's threshold
** for its "the stars do not determine this model" warning). */
#define PM_INDI_GAIN_WARN 3.0

/* A point whose leave-one-out miss is this many times the other points'
** (rms, both axes; and over 10") is named in the description: one wrong
** sync spreads its error over every GOTO. */
#define PM_INDI_WORST_RATIO 4.0

/*
**  pm_indi_spread - sky coverage of n positions (axis 1, axis 2, radians):
**  the largest angle between one of them and their normalised mean
**  direction (pi when the mean vanishes).  0 for n < 1.
*/
double pm_indi_spread(long n, const double *a1, const double *a2);

/*
**  pm_indi_choose_order - the order the rule allows for n sync points of a
**  given spread: the highest L <= PM_INDI_MAX_ORDER with n >= PM_SH_TERMS(L)
**  (twice as many equations as parameters) and spread >= PM_INDI_SPREAD_L<L>;
**  -1 (offsets only) when even L = 0 is not allowed.
*/
int pm_indi_choose_order(long n, double spread);

/*
**  pm_indi_fit - the model for n sync points.
**
**  Given:
**     mount    int          PM_MOUNT_EQUATORIAL or PM_MOUNT_ALTAZ
**     n        long         number of points (0 allowed)
**     enc1, enc2  const double*  the mount's positions (radians)
**     app1, app2  const double*  the stars' positions (radians)
**     fit      pm_fit*      workspace
**  Returned:
**     out      pm_model*    the model (prepared): identity for n = 0,
**                           index offsets when no fit is allowed, else of
**                           the orders up to the rule's that fit (singular
**                           or diverging fits end the climb), the one whose
**                           leave-one-out error is smallest; a higher order
**                           must beat a lower one by PM_INDI_CV_GAIN and
**                           PM_INDI_CV_FLOOR (Note 1)
**     res      pm_indi_result*  what was done
**  Returned (function value):
**              pm_status    PM_OK; PM_ERR_ARG (NULL, n < 0, bad mount);
**                           PM_ERR_NONFINITE (a non-finite position).
**                           On error *out and *res are unchanged.
**  Notes:
**  1) The leave-one-out error of a point is its residual / (1 - h), h the
**     mean of its two rows' leverages (the diagonal block of
**     J (J^T J)^-1 J^T, from pm_fit_pointing_sigma at sigma 1): exact for a
**     linear fit, and what the model would miss there without the point.
**     It catches an order the coverage nearly cannot determine (a pivot
**     just above pm's singular threshold), which fits the sync points and
**     errs between them.
**  2) The leave-one-out error cannot catch terms the points hardly tell
**     apart when the data hold no noise to show it: six noise-free syncs
**     on a 40 x 20 deg patch fitted order 0 to sigma 0.000" and missed by
**     107" elsewhere (an outside probe).  res->gain is what a unit error of
**     the sync points becomes over the sky (the RMS of the fit's own
**     pointing error at sigma 1, every axis-1 angle, axis 2 from the lowest
**     point's to 90 deg, by area); pm_indi_describe warns beyond
**     PM_INDI_GAIN_WARN, naming the most correlated pair of terms
**     (res->corr, res->corr_pair).  A 3 x 3 grid of 16 x 16 deg: 9.2; 45
**     points over a hemisphere at order 1: 1.6.
**  3) An axis-1 offset read at axis-2 angle b is the sky's error there
**     times 1 / cos b: within 10 deg of the pole a polar axis 5' off, read
**     at Polaris (b = 89.4 deg), is an hour-angle index of 7.6 deg, and
**     every GOTO away from the pole moved by that made GOTOs 8-14 times
**     worse than no correction (an outside probe; INDI's own plugins did
**     the same).  There a sky error is what a tilt of the polar (azimuth)
**     axis gives, the same shift everywhere near the pole, where an index
**     offset gives none.  So where only offsets are allowed and every
**     point is within PM_INDI_POLE_CAP of the pole (zenith), the model is
**     that tilt (a, b; least squares, exact for one point), not index
**     offsets; res->axis1_unset says so, with the axis-1 offset the points
**     would have read (res->axis1_read, res->axis1_sec) and the tilt
**     (res->tilt), and pm_indi_describe asks for a sync farther from the
**     pole for the indices.  A mount whose index is off by degrees keeps
**     that error until then (the offsets had set it from one sync there).
*/
pm_status pm_indi_fit(int mount, long n, const double *enc1, const double *enc2,
                      const double *app1, const double *app2, pm_fit *fit,
                      pm_model *out, pm_indi_result *res);

/* One line for the log: what model, from how many points, its sigma. */
void pm_indi_describe(const pm_indi_result *res, long n, long skipped, char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif
