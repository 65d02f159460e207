/*
**  simulate.h - a mount simulator that writes pointing runs in the
**  named-column format (docs/formats.md), for testing the fit and for users
**  who want to compare a simulated mount with their recordings.
**
**  The run looks like a real one: targets spread over the sky above an
**  elevation limit, visited in a nearest-neighbour sequence (so the slew
**  direction and the time and temperature series are realistic), a German
**  equatorial mount flipping over the pole west of the meridian (encoder
**  dec beyond 90 deg), and Gaussian noise on the measured positions.
*/
#ifndef PM_SIMULATE_H
#define PM_SIMULATE_H

#include <stddef.h>
#include "pm.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pmsim_spec {
    long n;                 /* number of observations */
    unsigned long long seed;
    double latitude_deg;    /* site latitude */
    double el_limit_deg;    /* lowest elevation observed */
    double noise_arcsec;    /* per axis, on the sky */
    int gem;                /* equatorial: 1 = German mount (flip west of the
                               meridian), 0 = fork (never flipped) */
    double overlap_deg;     /* GEM: targets within this hour angle of the
                               meridian are observed on a random side (real
                               runs observe both sides there; default 15) */
    double start_time_h;    /* time of the first point (hours) */
    double minutes_per_point;
    double temp_start_c;    /* temperature at the start */
    double temp_rate_c_per_h; /* initial cooling rate; the night cools
                               exponentially (3 h time constant) with a
                               random walk of 0.08 C per point on top, so
                               temperature is not a linear function of time */
    int n_outliers;         /* gross errors added to random points */
    double outlier_arcsec;  /* their size (random direction) */
    pm_model truth;         /* the mount's true model (prepared) */
} pmsim_spec;

/* Defaults: 200 points, seed 1, latitude 47, elevation limit 15 deg,
** 1 arcsec noise, GEM with a 15 deg meridian overlap, 2 minutes a point,
** 12 C falling 0.5 C/h at first; the truth is an empty L=1 equatorial
** model. */
void pmsim_default(pmsim_spec *spec);

/* Add a physical effect to the truth: effect is any pmfit fit --add EFFECT
** (ha_periodic:G, refraction, temperature, i@W, ...) of size arcsec
** (periodic: amplitude with phase_deg; auxiliary inputs: arcsec per unit;
** others: the coefficient), or "outlier[:N]" (N points off by arcsec) or
** "higher_order" (every term of order L+1 random, RMS arcsec, seed).
** Returns 0, or -1 with err. */
int pmsim_add_effect(pmsim_spec *spec, const char *effect, double arcsec, double phase_deg,
                     unsigned long long seed, char *err, size_t errlen);

/* Simulate and write the run to path (atomically).  comment: optional
** '#' lines for the header (e.g. the command that made it).  Returns 0, or
** -1 with err. */
int pmsim_write(const pmsim_spec *spec, const char *path, const char *comment, char *err,
                size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
