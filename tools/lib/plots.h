/*
**  plots.h - C access to the SVG plots of plots.hpp, for tests and C callers.
*/
#ifndef PM_PLOTS_H
#define PM_PLOTS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/*
**  pmplot_xy_c - one series (scatter, or a line if line != 0) as an xy plot
**  (pmplot::xy).  x and y hold n values each (may be NULL when n == 0);
**  name is the legend entry (NULL or "" for none).
**  Returns 0, or -1 with err = "path: what went wrong".
*/
int pmplot_xy_c(const char *path, const char *title, const char *xlabel, const char *ylabel,
                const char *name, const double *x, const double *y, long n, int line,
                char *err, size_t errlen);

/*
**  pmplot_demo - write one plot of each kind from synthetic data into the
**  directory dir (which must exist):
**     sky_vectors.svg, sky_vectors_pair.svg, xy.svg, periodogram.svg (log x),
**     periodogram_lin.svg, steps.svg
**  Titles contain "&" to exercise escaping ("... before &amp; after" etc.).
**  Returns 0, or -1 with err.
*/
int pmplot_demo(const char *dir, char *err, size_t errlen);

/*
**  pmplot_demo_degenerate - the same kinds from empty and NaN-laden inputs
**  (must not crash; empty ones say "no data"):
**     empty_sky.svg, empty_pair.svg, empty_xy.svg, empty_periodogram.svg,
**     empty_steps.svg (all empty), nan_sky.svg, nan_xy.svg,
**     nan_periodogram.svg, nan_steps.svg (NaN mixed with finite values)
**  Returns 0, or -1 with err.
*/
int pmplot_demo_degenerate(const char *dir, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
