// report.hpp - one self-contained HTML page of a pointing run (pmfit report):
// the fit and its table, the residuals on the sky and against azimuth,
// elevation, hour angle, declination, time and temperature, the model's
// pointing correction over the sky, its predicted error map, what pmfit
// explain finds (each finding with a before/after plot), the next targets
// (pmfit plan) and, given an earlier model or run, what changed since
// (pmfit compare).  Inline SVG and CSS only: no script, no external
// resource, no date (the same run gives the same page).  docs/report.md.
#ifndef PM_REPORT_HPP
#define PM_REPORT_HPP

#include "explain.hpp"
#include "fitrun.hpp"
#include "runfile.h"

#include <functional>
#include <string>
#include <vector>

namespace pmhost {

struct ReportOptions {
    int order = 1;                     // the model of the fit (pmfit fit --order)
    std::vector<std::string> adds;     // and its added terms (--add)
    double alpha = 0.01;               // explain: false-alarm probability
    std::vector<double> gears_ha, gears_dec; // explain: known gear periods (--gear)
    int next = 5;                      // plan: how many targets
    double min_el_deg = 15;            // plan: the lowest elevation (pmfit plan --min-el)
    bool fork = false;                 // plan: an equatorial mount that does not flip (--fork)
    std::string horizon;               // plan: a horizon file (--horizon; empty: none)
    std::string compare;               // OLD: a model file or a run; empty: no comparison
    ReadOptions read;                  // reading OLD when it is a run (as the run)
    std::string command;               // the command line, quoted at the end of the page
    int max_passes = 2000;             // Gauss-Newton passes of the fit (as pmfit fit)
    // the run's explanation with these options, where the caller has made
    // it already (pmfit's check of the azimuth reading); NULL: made here
    const Explanation *explained = nullptr;
    // false: the order was left to the page (pmfit report without --order),
    // and explain's section takes order 0 where order0_instead says so
    bool order_given = true;
};

// Progress: the stage starting ("fit", "explain", ...) and the fraction of the
// whole page done before it (0..1); called once more with "done", 1.
typedef std::function<void(const std::string &stage, double done)> ReportProgress;

// The page for a run read by load_run.  Throws std::runtime_error with the
// reason when the page cannot be made: the fit fails (the status and the
// term, as pmfit fit says it), OLD cannot be read (its file:line) or is of
// another mount.  A section that does not apply to the run (no latitude for
// the targets, no temperature column) says so on the page instead.
std::string report_html(const Run &run, const ReportOptions &o,
                        const ReportProgress &progress = nullptr);

} // namespace pmhost

#endif
