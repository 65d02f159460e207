/*
**  explain.h - C access to pmfit explain (tools/lib/explain.hpp) for tests
**  and C callers: explain a run file, get the findings as plain structs.
*/
#ifndef PM_EXPLAIN_H
#define PM_EXPLAIN_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PMX_MAX_FINDINGS 8
#define PMX_MAX_ALTERNATIVES 4
#define PMX_MAX_READINGS 12
/* an effect's name with its NUL: ha_periodic ..., or aux:NAME for the
** run's own column NAME (a longer name is cut) */
#define PMX_EFFECT_LEN 64

/* Another reading of the same residuals with close evidence. */
typedef struct pmx_alternative {
    char effect[PMX_EFFECT_LEN];
    double delta_bic;                /* BIC(alternative) - BIC(chosen); negative where BIC
                                        (which does not count the periods or candidates
                                        tried) prefers the alternative */
    double log10_lr;                 /* log10 likelihood ratio chosen : alternative */
    double log10_fap;                /* its own false-alarm probability, log10 */
    char separate_by[160];           /* the observation that would tell them apart */
    int smooth;                      /* 1: offered because the run cannot show the chosen
                                        periodic shape repeats (any Delta BIC); 0: Delta BIC
                                        below 6 (docs/explain.md, "Confusable effects") */
    int final_model;                 /* 1: a temperature's or drift's rival, Delta BIC below 6
                                        in the final model (JSON kind "final") */
} pmx_alternative;

/* One item of the physical reading of the baseline. */
typedef struct pmx_reading {
    char what[32];                   /* polar_altitude, collimation, ... */
    double value, error;
    char unit[8];                    /* "arcmin" or "arcsec" */
} pmx_reading;

typedef struct pmx_finding {
    char effect[PMX_EFFECT_LEN];     /* ha_periodic, refraction, aux:NAME ... */
    double cycles_per_rev;           /* periodic effects, else 0 */
    double cycles_lo, cycles_hi;     /* periodic: the periods that fit as well (95%),
                                        cycles_per_rev itself where the run fixes it */
    double amplitude_arcsec, amplitude_err_arcsec, phase_deg; /* in the final model (every
                                        finding in); higher_order, outliers: at their step */
    double false_alarm_probability;  /* these four: at the step that found it */
    double sigma_after_arcsec, cv_rms_after_arcsec;
    int n_params_after;
    int n_lines;                     /* outliers: how many points */
    int lines[16];                   /* their file lines (the first 16) */
    char with[PMX_EFFECT_LEN];       /* found as a pair with this effect, else "" */
    int n_alternatives;
    pmx_alternative alternatives[PMX_MAX_ALTERNATIVES];
} pmx_finding;

typedef struct pmx_result {
    /* (a cross-validated RMS is NaN where the model cannot be fitted
    ** without some point -- alone it fixes a term -- or, k-fold, where a
    ** fold did not fit; the finding that removes such a point is an
    ** outlier, which needs none) */
    double base_sigma_arcsec, base_cv_rms_arcsec;
    int base_n_params;
    int n_findings;
    pmx_finding findings[PMX_MAX_FINDINGS];
    double final_sigma_arcsec, final_cv_rms_arcsec;
    int final_n_params;
    int n_readings;                  /* the physical reading of the baseline */
    pmx_reading readings[PMX_MAX_READINGS];
    int physical_reading;            /* 1: order 0 + one term predicts as well as order 1 */
    int n_withdrawn;                 /* found, then not needed once later findings were in */
    char withdrawn[PMX_MAX_FINDINGS][PMX_EFFECT_LEN];
    double compose_rms_arcsec;       /* the composition taken out, RMS per axis (0: none) */
    int n_cv_left_out;               /* points the baseline cannot predict from the others, */
    int cv_left_out_lines[16];       /* left out of every CV RMS: their file lines (first 16) */
    /* where the search ended, the most significant family that does not
    ** predict better ("significant, not modelled": the residuals hold it,
    ** the run's points cannot fit it usefully); "" if none */
    char unmodelled[PMX_EFFECT_LEN];
    double unmodelled_log10_fap;     /* its false-alarm probability (log10) */
    double unmodelled_sigma_arcsec, unmodelled_cv_rms_arcsec; /* with it */
    double unmodelled_cv_before_arcsec; /* the CV RMS of the model it was tried on */
} pmx_result;

/* Explain the run in file path from a baseline of the given order; alpha is
** the false-alarm probability a finding must beat (0.01 is pmfit's
** default).  Returns 0, or -1 with err. */
int pmx_explain(const char *path, int order, double alpha, pmx_result *out, char *err,
                size_t errlen);

/* As pmx_explain, with known gear periods (cycles per revolution, both
** axes; pmfit explain --gear): the periodic search looks at these only. */
int pmx_explain_gears(const char *path, int order, double alpha, const double *gears,
                      int n_gears, pmx_result *out, char *err, size_t errlen);

/* Every option (pmx_options_default: order 1, alpha 0.01, no gears,
** pairs on, folds 0: leave-one-out). */
typedef struct pmx_options {
    int order;                       /* baseline harmonic order */
    double alpha;                    /* false-alarm probability to beat */
    const double *gears;             /* known gear periods, both axes (may be NULL) */
    int n_gears;
    int pairs;                       /* 1: where no single family passes, try pairs */
    int folds;                       /* cross-validation: 0 leave-one-out (PRESS),
                                        k >= 2 k-fold */
    int compose;                     /* 1: the baseline composed as a gimbal
                                        (docs/explain.md, step 1); 0: --no-compose */
} pmx_options;

void pmx_options_default(pmx_options *o);

int pmx_explain_opts(const char *path, const pmx_options *o, pmx_result *out, char *err,
                     size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
