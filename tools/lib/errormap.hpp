// errormap.hpp - the predicted error map of a fitted model (host side):
// the 1-sigma uncertainty of its correction over the usable sky, from the
// fit's covariance (the same J C J^T as pm_fit_pointing_sigma), its mean and
// maximum, and the cells of a sky plot.  docs/model.md, "How well the model
// knows the sky".
#ifndef PM_ERRORMAP_HPP
#define PM_ERRORMAP_HPP

#include "fitrun.hpp"
#include "plots.hpp"

#include <string>
#include <utility>
#include <vector>

namespace pmhost {

struct ErrorMap {
    bool elevation = true;        // the sky's lower limit is an elevation (else a declination)
    double limit_deg = 0;         // the usable sky: above the run's lowest star (deg)
    double mean_arcsec = 0, max_arcsec = 0; // over the usable sky, per axis
    double max_x_deg = 0, max_y_deg = 0;    // where the maximum is (HA, Dec or az, el)
    double at_points_arcsec = 0;  // RMS at the run's own points
    long dof = 0;                 // 2N - P of the fit: what its sigma, and the map, rest on
    std::vector<pmplot::Cell> cells;             // the map (x, y in degrees)
    std::vector<std::pair<double, double>> marks; // the run's points, same axes
};

// The predicted per-axis 1-sigma of fit f's correction at encoder (t, d)
// with inputs ctx (radians; NaN where the model cannot be evaluated).
double predicted_sigma(const FitOut &f, const pm_context &ctx, double t, double d);

// The map of fit f of run over the usable sky, for the pier side `side`
// (+1 normal, -1 beyond the pole; 0: alt-az, or an equatorial mount used
// as the run used it -- each place on the side of the run's nearest star):
// cells of about 3 deg.
// Throws std::runtime_error if the fit has no covariance.
ErrorMap error_map(const Run &run, const FitOut &f, int side);

// A line for the text report and a JSON object (keys in docs/formats.md).
std::string error_map_text(const Run &run, const ErrorMap &e);
std::string error_map_json(const ErrorMap &e, double sigma_arcsec);

// A model its stars do not determine between them: its predicted error over
// the usable sky (RMS) is more than UNDETERMINED_RATIO times the residual
// sigma, so pointing between the stars is worse than at them by more than
// the noise -- the terms are extrapolated, not measured.  (Fits of the real
// runs of ../shared/data and the examples at orders 0-2 reach 1.05; the
// first 12-80 stars of a run, with order 1-2: 4-20,000.)  "" or the warning
// (one sentence, no leading spaces).
//
// And a sigma that rests on few degrees of freedom: the map is sigma times
// the covariance's shape, and with 2N - P = k the true sigma is within
// sigma_factor_95's factors of it (chi^2 with k degrees of freedom, 95%);
// where the upper factor is above 2 (k <= 7) the warning says so too (an
// outside probe's 5 stars for 9 terms: sigma 0.154" for 1" of noise, the
// map 0.283" where the model was 1.53" off, and no word).
const double UNDETERMINED_RATIO = 3;
std::string undetermined_warning(const ErrorMap &e, double sigma_arcsec);
// The factors (lo, hi) within which the true sigma is, 95%, of one
// estimated on dof degrees of freedom; (1, 1) for dof <= 0.
std::pair<double, double> sigma_factor_95(long dof);
// The sky plot (an SVG file); throws with the reason on failure.
void error_map_plot(const std::string &path, const Run &run, const ErrorMap &e,
                    const std::string &title);

} // namespace pmhost

#endif
