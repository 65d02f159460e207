/*
**  tpointterms.h - a fitted equatorial model as a TPOINT-style term list
**  (host side; pmfit fit --tpoint-terms FILE).
**
**  The six isotropic terms of the model map one to one onto TPOINT's
**  IH ID NP CH MA ME, an added tube flexure (cos el toward the zenith)
**  onto TF and an added refraction-like term (cot el) onto TX; every other
**  term (the harmonics of order >= 1, periodic, temperature, ... terms)
**  has no TPOINT name and is listed apart under its pm name.  The sign
**  conventions are those of the first-order formulas (docs/formats.md,
**  "TPOINT term export"): true = raw + (dh, dd),
**
**     dh = -IH - CH sec(d) - NP tan(d) + MA cos(h) tan(d) - ME sin(h) tan(d)
**          - TF cos(phi) sin(h) sec(d) - TX cos(phi) sin(h) sec(d) / sin(el)
**     dd = -ID - MA sin(h) - ME cos(h)
**          - TF (cos(phi) cos(h) sin(d) - sin(phi) cos(d))
**          - TX (cos(phi) cos(h) sin(d) - sin(phi) cos(d)) / sin(el)
**
**  with h, d the raw (encoder) hour angle and declination, phi the
**  latitude.  From pm's base vectors (docs/model.md): IH = -c', ID = e',
**  NP = d, CH = -i, MA = -a, ME = b, TF = the tube flexure coefficient, TX
**  = the cot(el) coefficient; tests/check_tpointterms.c checks the
**  formulas with these values against pm_model_apply at many places.
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

/* Most TPOINT-named terms (IH ID NP CH MA ME TF TX). */
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
**     m        const pm_model*  an equatorial model (pm_model_prepare'd or
**                               not: only term[] and coef[] are read)
**     err_rad  const double*    the coefficients' 1-sigma errors (radians,
**                               m->n_terms of them), or NULL
**  Returned:
**     named    pmtp_term[PMTP_MAX_NAMED]  IH ID NP CH MA ME, then TF, TX
**                               when the model has them (both pier sides)
**     n_named  int*             how many
**  Returned (function value):
**              int              0; -1 NULL argument or an alt-az model
**                               (TPOINT's alt-az terms are not exported)
**  Notes:
**  1) A term is "TPOINT-named" iff its index is one of the pm_index
**     values; every other term of m has no TPOINT name.
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
**     m        const pm_model*  the model (equatorial)
**     err_rad  const double*    errors (radians) or NULL
**     caption  const char*      the caption line (one line), or NULL
**     errlen   size_t           size of err
**  Returned:
**     err      char*            on error "path: what"
**  Returned (function value):
**              int              0; -1 (argument, alt-az model, I/O)
*/
int pmtp_write(const char *path, const pm_model *m, const double *err_rad, const char *caption,
               char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif /* PMTP_TPOINTTERMS_H */
