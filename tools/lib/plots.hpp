// plots.hpp - dependency-free SVG plots for `pmfit explain` (host side, C++).
//
// Each function writes one standalone SVG 1.1 file (through pmhost::write_atomic, so a
// failure never leaves a half-written file), or the same document into a string (Out),
// and returns 0, or -1 with a message in *err (err may be NULL).  Non-finite values are
// skipped; with nothing left to draw the figure still gets its title and axes and says
// "no data".  Text is escaped for XML; control characters become spaces and invalid UTF-8
// bytes '?'.  Fonts: DejaVu Sans, Helvetica, Arial, sans-serif; sizes 18 (title), 14 (axis
// labels), 12-13 (ticks, legend).
//
// Labels are drawn as given: put the units in them ("hour angle (deg)").
// Colours (Okabe-Ito, colour-blind safe) are assigned in order: blue, vermillion, green,
// orange, purple, sky blue, yellow-brown, black; group/series i always gets colour i.
#ifndef PM_PLOTS_HPP
#define PM_PLOTS_HPP

#include <string>
#include <vector>

namespace pmplot {

// Where a plot goes: a file (a path converts to an Out), or, with `text` set, a string
// that receives the SVG document (pmfit report inlines it in a page).  `path` names the
// plot in error messages.
struct Out {
    std::string path;
    std::string *text = nullptr;
    Out(const std::string &p) : path(p) {}
    Out(const char *p) : path(p ? p : "") {}
    Out(std::string *t, const std::string &name) : path(name), text(t) {}
};

// Axis labels carry class="axis-label x" (below the frame), "axis-label y" (beside it)
// or "axis-label bar" (a colour bar's unit), so a test or a style sheet can find them.

// A point on the sky and its residual vector.
struct Vec {
    double x, y;    // position, degrees (hour angle or azimuth, declination or elevation)
    double dx, dy;  // residual, arcsec: dx along +x (drawn rightwards), dy along +y (upwards)
    int group;      // colour/legend group, 0..7 (e.g. 0 = east pier, 1 = west pier)
};

// Residual vectors on the sky: a dot at each (x, y) and an arrow from it, scaled so that
// scale_arcsec is as long as the reference arrow in the legend (40 px).  scale_arcsec <= 0
// or non-finite: chosen automatically (a 1-2-5 value near twice the median length).
// group_names[g] names group g in the legend (with its count); a group without a name is
// called "group g"; with no names and a single group no group entry is shown.  The panel
// header shows n and the RMS length sqrt(mean(dx^2 + dy^2)).  Ticks are at angular steps
// (1, 2, 5, 10, 15, 30, 45, 90 deg).  Arrows are clipped at the frame.
int sky_vectors(const Out &path, const std::string &title, const std::string &xlabel,
                const std::string &ylabel, const std::vector<Vec> &v, double scale_arcsec,
                const std::vector<std::string> &group_names, std::string *err);

// Before and after side by side in one figure: the same axes, the same arrow scale (auto:
// from `before`) and one legend, so the improvement is visible at a glance.
int sky_vectors_pair(const Out &path, const std::string &title, const std::string &xlabel,
                     const std::string &ylabel, const std::vector<Vec> &before,
                     const std::vector<Vec> &after, const std::string &before_title,
                     const std::string &after_title, double scale_arcsec,
                     const std::vector<std::string> &group_names, std::string *err);

// A value on the sky (a cell of a map), degrees and the value's unit.
struct Cell {
    double x, y;        // cell centre, degrees
    double w, h;        // cell size, degrees
    double v;           // the value (non-finite: not drawn)
};

// A map of a scalar over the sky: each cell filled by its value on a sequential colour
// scale from 0 to the largest value (a colour bar with ticks and `unit` beside the frame),
// and the points `marks` (x, y in degrees, e.g. the observed stars) drawn as small black
// rings on top, named `marks_name` in the legend.  With mark_labels (one per mark, e.g.
// "1", "2", ...) the marks are bold rings with their label beside them (targets).
int sky_scalar(const Out &path, const std::string &title, const std::string &xlabel,
               const std::string &ylabel, const std::vector<Cell> &cells, const std::string &unit,
               const std::vector<std::pair<double, double>> &marks, const std::string &marks_name,
               std::string *err, const std::vector<std::string> &mark_labels = {});

// A series of an xy plot.  line = true: a polyline in the given order (a non-finite point
// breaks it), e.g. a model curve; line = false: scatter points.  x and y must have the
// same length.  An empty name leaves the series out of the legend.
struct Series {
    std::string name;
    std::vector<double> x, y;
    bool line;
};

// Scatter/line plot of several series with a legend above the frame.  A darker line
// marks y = 0 whenever 0 is within the y range.  Error: x and y of a series differ in length.
int xy(const Out &path, const std::string &title, const std::string &xlabel,
       const std::string &ylabel, const std::vector<Series> &s, std::string *err);

// Before and after side by side: two xy panels on the same axes with one legend (the
// names of `before`), e.g. residuals against a variable without and with a term.
int xy_pair(const Out &path, const std::string &title, const std::string &xlabel,
            const std::string &ylabel, const std::vector<Series> &before,
            const std::vector<Series> &after, const std::string &before_title,
            const std::string &after_title, std::string *err);

// Periodogram: power against frequency in cycles per revolution, on a log (log_x; values
// <= 0 skipped) or linear x axis, y from 0.  A dashed line at `threshold` labelled
// threshold_label (skipped if threshold is not finite), and the point nearest peak_freq
// marked and labelled "G = 240.0" (skipped if peak_freq is not finite).
// The first form labels the y axis "power"; the second takes the y label (e.g.
// "amplitude (arcsec)").  freq and power must have the same length.
int periodogram(const Out &path, const std::string &title, const std::vector<double> &freq,
                const std::vector<double> &power, double threshold,
                const std::string &threshold_label, double peak_freq, bool log_x, std::string *err);
int periodogram(const Out &path, const std::string &title, const std::string &ylabel,
                const std::vector<double> &freq, const std::vector<double> &power, double threshold,
                const std::string &threshold_label, double peak_freq, bool log_x, std::string *err);

// Bar chart of the greedy model search: for each step (labels: "baseline", "+refraction",
// ...) a bar for sigma and one for the cross-validated RMS, in arcsec, values printed on
// the bars when there is room; the step with the lowest CV RMS is marked "best".
// sigma or cv_rms may be empty (that series is left out), otherwise each must have one
// value per label; non-finite values leave a gap.  Long labels are drawn slanted.
int steps(const Out &path, const std::string &title, const std::vector<std::string> &labels,
          const std::vector<double> &sigma, const std::vector<double> &cv_rms, std::string *err);

} // namespace pmplot

#endif
