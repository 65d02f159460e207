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

typedef struct pmx_finding {
    char effect[24];                 /* ha_periodic, refraction, ... */
    double cycles_per_rev;           /* periodic effects, else 0 */
    double amplitude_arcsec, amplitude_err_arcsec, phase_deg;
    double false_alarm_probability;
    double sigma_after_arcsec, cv_rms_after_arcsec;
    int n_params_after;
    int n_lines;                     /* outliers: how many points */
    int lines[16];                   /* their file lines (the first 16) */
} pmx_finding;

typedef struct pmx_result {
    double base_sigma_arcsec, base_cv_rms_arcsec;
    int base_n_params;
    int n_findings;
    pmx_finding findings[PMX_MAX_FINDINGS];
    double final_sigma_arcsec, final_cv_rms_arcsec;
    int final_n_params;
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

#ifdef __cplusplus
}
#endif

#endif
