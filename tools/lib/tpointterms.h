/*
**  tpointterms.h - a fitted model as a TPOINT-style term list
**  (host side; pmfit fit --tpoint-terms FILE).
**
**  The six isotropic terms of the model map one to one onto TPOINT's
**  geometric terms (equatorial: IH ID NP CH MA ME; alt-az: IA IE CA NPAE
**  AN AW), an added tube flexure (cos el toward the zenith) onto TF and an
**  added refraction-like term (cot el) onto TX; every other term (the
**  harmonics of order >= 1, periodic, temperature, ... terms) has no TPOINT
**  name and is listed apart under its pm name.
**
**  The convention (docs/formats.md, "TPOINT term export", with the sources):
**  TPOINT's terms are corrections from the raw (encoder) position to the
**  true one, true = raw + (dh, dd) or raw + (dA, dE), which is the direction
**  of pm_model_apply (encoder -> apparent):
**
**     dh =  IH + CH sec(d) + NP tan(d) - MA cos(h) tan(d) + ME sin(h) tan(d)
**           + (TF + TX / sin(el)) cos(phi) sin(h) sec(d)
**     dd =  ID + MA sin(h) + ME cos(h)
**           + (TF + TX / sin(el)) (cos(phi) cos(h) sin(d) - sin(phi) cos(d))
**
**     dA = -IA - CA sec(E) - NPAE tan(E) + AN sin(A) tan(E) - AW cos(A) tan(E)
**     dE =  IE + AN cos(A) + AW sin(A) - TF cos(E) - TX cot(E)
**
**  with h, d the raw hour angle and declination (h west positive), phi the
**  latitude, el the elevation; A, E the raw azimuth and elevation in
**  TPOINT's convention, A from south through east (A = 180 deg - az for
**  pmfit's azimuth az from north through east).  Positive TF and TX move
**  the true position away from the zenith (a drooping tube).  From pm's
**  coefficients (docs/model.md): IH = IA = c', ID = IE = -e', NP = NPAE = -d,
**  CH = CA = i, TF = -(tube flexure), TX = -(cot(el) coefficient), and the
**  polar-axis tilts turned by the index c' (pm's act at the index-shifted
**  angle, TPOINT's at the raw one): MA = AW = a cos c' + b sin c',
**  ME = -(b cos c' - a sin c'), AN = b cos c' - a sin c' (MA = a, ME = -b,
**  AW = a, AN = b at c' = 0); their errors turned without the a-b
**  covariance.  tests/check_tpointterms.c checks the formulas with these
**  values against pm_model_apply at many places and against direct fits of
**  the formulas to real runs.  An alt-az model is taken to use pmfit's
**  azimuth (north through east).
**
**  Plain C (C89), reentrant.
*/
#ifndef PMTP_TPOINTTERMS_H
#define PMTP_TPOINTTERMS_H

#include <stddef.h>

#include "pm.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most TPOINT-named terms of one model (six geometric terms, TF, TX). */
#define PMTP_MAX_NAMED 8

/* One TPOINT term: its name, value and 1-sigma error (arcsec; error NaN
** when not known), and the index of the pm term it comes from. */
typedef struct pmtp_term {
    char name[8];
    double value_arcsec;
    double error_arcsec;
    int pm_index;
} pmtp_term;

/*
**  pmtp_terms - the TPOINT-named terms of a model.
**
**  Given:
**     m        const pm_model*  an equatorial or alt-az model
**                               (pm_model_prepare'd or not: only mount,
**                               term[] and coef[] are read)
**     err_rad  const double*    the coefficients' 1-sigma errors (radians,
**                               m->n_terms of them), or NULL
**  Returned:
**     named    pmtp_term[PMTP_MAX_NAMED]  equatorial: IH ID NP CH MA ME;
**                               alt-az: IA IE CA NPAE AN AW; then TF, TX
**                               when the model has them (both pier sides)
**     n_named  int*             how many
**  Returned (function value):
**              int              0; -1 NULL argument or unknown mount type
**  Notes:
**  1) A term is "TPOINT-named" iff its index is one of the pm_index
**     values; every other term of m has no TPOINT name.
**  2) The values follow the convention above (first order; pm's isotropic
**     terms are exact rotations, TPOINT's first-order corrections).
*/
int pmtp_terms(const pm_model *m, const double *err_rad, pmtp_term *named, int *n_named);

/*
**  pmtp_write - write the term list to a file (through a temporary file and
**  a rename): '!' comment lines with the convention, a caption, one line
**  per TPOINT term "  NAME  value  error" (arcsec), END, then '!' lines
**  listing the terms with no TPOINT name (pm names, arcsec).
**
**  Given:
**     path     const char*      file to write
**     m        const pm_model*  the model (equatorial or alt-az)
**     err_rad  const double*    errors (radians) or NULL
**     caption  const char*      the caption line (one line), or NULL
**     errlen   size_t           size of err
**  Returned:
**     err      char*            on error "path: what"
**  Returned (function value):
**              int              0; -1 (argument, unknown mount type, I/O)
*/
int pmtp_write(const char *path, const pm_model *m, const double *err_rad, const char *caption,
               char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif /* PMTP_TPOINTTERMS_H */
