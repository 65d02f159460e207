/*
**  plan.h - C access to pmfit plan (tools/lib/plan.hpp) for tests and C
**  callers: the next targets of a pointing run, and the predicted mean
**  error over the sky of a given set of targets.
*/
#ifndef PM_PLAN_H
#define PM_PLAN_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pmplan_target {
    double x_deg, y_deg;  /* HA and Dec, or azimuth and elevation */
    double el_deg;
    int side;             /* +1 normal, -1 beyond the pole, 0 alt-az */
    double after_arcsec;  /* predicted mean error once taken (NaN: not determined yet) */
    char name[40];        /* the catalogue star ("" on the grid; truncated) */
    double slew_s;        /* slew-time weighting: time to reach and take it (else NaN) */
} pmplan_target;

/* Pier-side rules of a German mount (pmplan_options.sides). */
#define PMPLAN_SIDES_RUN 0      /* as the run used it nearby (else the meridian rule) */
#define PMPLAN_SIDES_MERIDIAN 1 /* the meridian rule: the normal side west of the meridian
                                   (ASCOM's normal pointing state; the run's own side of it
                                   where the run shows one), beyond the pole east */
#define PMPLAN_SIDES_BOTH 2     /* within meridian_limit_deg of it on either side */

typedef struct pmplan_options {
    int order;            /* the model's harmonic order */
    int altaz;            /* 1: alt-az mount (with a run: the run's mount, whatever this says) */
    int gem;              /* equatorial: 1 German (flips at the meridian), 0 fork */
    double latitude_deg;
    double min_el_deg;    /* the horizon */
    double grid_deg;      /* candidate spacing */
    double noise_arcsec;  /* per axis */
    /* since the horizon file, catalogue and criterion options: */
    const char *adds;     /* physical terms, comma-separated pmfit --add EFFECTs (NULL: none) */
    const char *horizon_path;   /* horizon file (NULL: none; docs/formats.md) */
    const char *catalogue_path; /* candidate stars (NULL: the grid) */
    double lst_h;         /* local sidereal time placing the catalogue (hours; < 0: unset) */
    int d_optimal;        /* 1: D-optimal instead of I-optimal */
    int sides;            /* PMPLAN_SIDES_* */
    double meridian_limit_deg;
    double slew_rate_deg_s; /* > 0: weigh the slew time (per axis rate) */
    double settle_s, point_s, flip_s;
    /* since the zenith keyhole: */
    double max_el_deg;    /* the highest place planned; 0: the mount's (alt-az 85 deg, the
                             zenith keyhole; equatorial 90) */
} pmplan_options;

/* order 1, equatorial German mount, latitude 47, horizon 15 deg, grid 6
** deg, noise 1"; no horizon file, catalogue or slew weighting; I-optimal;
** sides as the run used them, meridian limit 15 deg; settle 5 s, 30 s a
** point, 60 s a flip. */
void pmplan_options_default(pmplan_options *o);

/* The next k targets after the run in file run_path (NULL: nothing taken
** yet) into out[k]; *before: the predicted mean error now (NaN when not
** determined).  Returns the number of targets, or -1 with err. */
int pmplan_next(const char *run_path, const pmplan_options *o, int k, pmplan_target *out,
                double *before, char *err, size_t errlen);

/* The predicted mean error over the sky (1 sigma per axis, arcsec) after
** the n targets pts.  Returns 0, or -1 with err. */
int pmplan_predicted(const pmplan_options *o, const pmplan_target *pts, int n, double *mean_arcsec,
                     char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
