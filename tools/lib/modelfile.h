/*
**  modelfile.h - save and load pointing models as text, and emit them as C
**  constant data for firmware.
**
**  The model file format (docs/formats.md, "Model files"):
**
**     # any comment
**     pm-model 3                  (4: the lines below; 5: correlations;
**                                  versions 1, 2 read as docs/formats.md says)
**     mount equatorial            (or altaz)
**     order 2
**     input 0 humidity            (version 4 only: pmmodel_info below)
**     pier east                   (version 4 only)
**     terms 46
**     term c' 3 0 0 1.2345678901234567e-03
**     ...                         (name k l m value-in-radians, %.17g)
**     end
**
**  Values are radians written with 17 significant digits, so a model read
**  back is bit-identical.  The term list is explicit; the reader checks it
**  against what this build can hold (PM_MAX_L, PM_MAX_TERMS).
*/
#ifndef PM_MODELFILE_H
#define PM_MODELFILE_H

#include <stddef.h>
#include "pm.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
**  pmmodel_save - write a model file (atomically: a temporary file renamed
**  into place, so a failure leaves no half-written file).
**  Returns 0, or -1 with err = "path: what went wrong".
**  comment: optional text written as '#' lines at the top (NULL for none).
*/
int pmmodel_save(const char *path, const pm_model *m, const char *comment,
                 char *err, size_t errlen);

/*
**  pmmodel_load - read a model file into *m (prepared).
**  Returns 0, or -1 with err = "path:LINE: what was wrong, what was
**  expected"; *m is unchanged on error.
*/
int pmmodel_load(const char *path, pm_model *m, char *err, size_t errlen);

/* Longest name of an input column, with its NUL. */
#define PMMODEL_NAME_MAX 64

/*
**  pmmodel_info - what a model file says beyond the model (version 4):
**     input[j]  the name of the run's column the model reads as
**               pm_context.aux[j] (its terms' PM_AUX_USER + j); "" where
**               the file does not say (a version-3 file, or a column
**               not used).  A host evaluating the model on another run
**               finds the column by this name, not by its position:
**               a run whose columns come in another order has the
**               same column at another index.
**     pier      0: a model of both pier sides; +1 (east, normal) or -1
**               (west, beyond the pole): a model fitted to that side's
**               records only (pmfit fit --pier split), which points
**               only there.
**     has_err, err  the fit's 1-sigma error of each coefficient, written
**               as a seventh field of each term line (xterm: an
**               eleventh), so that a later run compared with the model
**               (pmfit compare) counts the model's own uncertainty, not
**               the new fit's alone.
**  Zero it (memset) for "nothing more to say".
*/
typedef struct pmmodel_info {
    char input[PM_MAX_AUX][PMMODEL_NAME_MAX];
    int pier;
    int has_err;             /* err below holds the fit's 1-sigma errors */
    double err[PM_MAX_TERMS]; /* of each coefficient (radians, the model's
                               term order): a term line's last field */
    double stars_sigma;      /* the RMS of the fit's predicted 1-sigma at its
                               own stars (radians; 0: not known); written
                               with the covariance (version 5), so that a
                               comparison can tell a new night where the
                               model extrapolates */
} pmmodel_info;

/*
**  pmmodel_save_info / pmmodel_load_info - pmmodel_save and pmmodel_load
**  with the information above (info NULL: none; the file is then version
**  3, as is one whose info names nothing the model uses and gives no pier
**  side).  A name must be a column name of the named-column format
**  (letters, digits, '_', '.', '-', not a digit first) shorter than
**  PMMODEL_NAME_MAX; two inputs may not share one.  pmmodel_load_info
**  clears *info, then fills what the file says (*info unchanged on error).
*/
int pmmodel_save_info(const char *path, const pm_model *m, const pmmodel_info *info,
                      const char *comment, char *err, size_t errlen);
int pmmodel_load_info(const char *path, pm_model *m, pmmodel_info *info, char *err,
                      size_t errlen);

/*
**  pmmodel_save_cov / pmmodel_load_cov - pmmodel_save_info and
**  pmmodel_load_info with the fit's covariance of the coefficients
**  (version 5): cov is n_terms x n_terms, row-major, radians^2.  The file
**  keeps the correlations, to 10 significant digits, after the term lines
**  ('corr I J r...'), beside the errors of the term lines; a later
**  comparison (pmfit compare MODEL RUN) then tests the changes of all terms
**  together with the old fit's covariance, as it does with the old run.
**  save: cov NULL is pmmodel_save_info; with cov, info->has_err must be set
**  (the errors the file gives are info->err, the correlations cov's);
**  cov must be finite and symmetric with a diagonal >= 0.
**  load: cov has room for cov_len doubles (NULL: not read); *has_cov (may
**  be NULL) is 1 where the file keeps correlations and cov was filled,
**  cov[i*P + j] = r_ij err_i err_j, else 0 and cov untouched.  A file whose
**  correlations are out of order, incomplete, beyond -1..1 or not those of
**  a covariance (not positive semi-definite) is refused at its line; a
**  cov_len below P*P for a file that keeps them is an error.
*/
int pmmodel_save_cov(const char *path, const pm_model *m, const pmmodel_info *info,
                     const double *cov, const char *comment, char *err, size_t errlen);
int pmmodel_load_cov(const char *path, pm_model *m, pmmodel_info *info, double *cov,
                     size_t cov_len, int *has_cov, char *err, size_t errlen);

/*
**  pmmodel_emit_c - write a C89 header holding the model as constant data
**  and a loader:
**     static const double <prefix>_coef[P];     radians
**     static const signed char <prefix>_terms[P][3];   k, l, m
**     static pm_status <prefix>_load(pm_model *m);
**  The loader rebuilds the term list with pm_model_init, checks that it is
**  the same, copies the coefficients and prepares the model.
**  Returns 0, or -1 with err.
*/
int pmmodel_emit_c(const char *path, const pm_model *m, const char *prefix,
                   const char *comment, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
