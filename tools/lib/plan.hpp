// plan.hpp - which star next (pmfit plan): the targets that most reduce the
// model's predicted pointing error averaged over the usable sky (I-optimal
// design, greedy), given the points taken so far.  docs/model.md, "Which
// star next".
#ifndef PM_PLAN_HPP
#define PM_PLAN_HPP

#include "fitrun.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace pmhost {

struct PlanOptions {
    int order = 1;                 // the model to plan for
    std::vector<std::string> adds; // its physical terms
    int mount = PM_MOUNT_EQUATORIAL;
    double latitude = NAN;         // radians (equatorial: required)
    double min_el_deg = 15;        // the horizon
    int next = 5;                  // how many targets
    double noise_arcsec = 1;       // per axis, to scale the predicted error (a run's sigma)
    double grid_deg = 6;           // candidate grid spacing
    bool gem = true;               // equatorial: a German mount (flips west of the meridian)
};

struct Target {
    double x_deg, y_deg;  // HA and Dec, or azimuth and elevation (the sky position)
    double el_deg;        // its elevation
    int side;             // pier side to take it on (+1 normal, -1 beyond the pole, 0 alt-az)
    double after_arcsec;  // the predicted mean error over the sky once it is taken
};

struct Plan {
    double before_arcsec = 0;     // predicted mean error over the sky now (1 sigma per axis)
    std::vector<Target> targets;  // in the order to take them
    int n_candidates = 0, n_sky = 0;
};

// Plan the next targets after the observations of `taken` (may be empty:
// the first points of a run).  The model's rows are evaluated at the run's
// fitted model when taken has enough points, else at the ideal mount.
// Throws std::runtime_error (no latitude for an equatorial mount, no
// usable sky).
Plan plan_targets(const Run &taken, const PlanOptions &o);

// The same criterion for a given set of sky positions (x, y in degrees,
// pier side): the predicted mean error over the sky (arcsec) -- for
// comparing a plan with a grid or random points.
double predicted_mean_error(const std::vector<Target> &points, const PlanOptions &o);

} // namespace pmhost

#endif
