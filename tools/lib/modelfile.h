/*
**  modelfile.h - save and load pointing models as text, and emit them as C
**  constant data for firmware.
**
**  The model file format (docs/formats.md, "Model files"):
**
**     # any comment
**     pm-model 2                  (version 1 read as docs/formats.md says)
**     mount equatorial            (or altaz)
**     order 2
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
