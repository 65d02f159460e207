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
} pmplan_target;

typedef struct pmplan_options {
    int order;            /* the model (harmonic order; no physical terms) */
    int altaz;            /* 1: alt-az mount */
    int gem;              /* equatorial: 1 German (flips west of the meridian), 0 fork */
    double latitude_deg;
    double min_el_deg;    /* the horizon */
    double grid_deg;      /* candidate spacing */
    double noise_arcsec;  /* per axis */
} pmplan_options;

/* order 1, equatorial German mount, latitude 47, horizon 15 deg, grid 6
** deg, noise 1". */
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
