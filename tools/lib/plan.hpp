// plan.hpp - which star next (pmfit plan): the targets that most reduce the
// model's predicted pointing error averaged over the usable sky (I-optimal
// design, greedy; D-optimal as an option), given the points taken so far,
// a horizon, candidates on a grid or from a star catalogue, the pier-side
// rules of a German mount and, optionally, the slew time.  docs/model.md,
// "Which star next".
#ifndef PM_PLAN_HPP
#define PM_PLAN_HPP

#include "fitrun.hpp"
#include "plan_inputs.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace pmhost {

// Which pier side a German mount takes a place on.
enum PlanSides {
    SIDES_RUN,      // within meridian_limit_deg of the meridian the side the run used
                    // nearby (the meridian rule when nothing is taken); beyond, the meridian rule
    SIDES_MERIDIAN, // the meridian rule: the normal side on its side of the meridian, the
                    // other side beyond the pole (normal_west below)
    SIDES_BOTH      // within meridian_limit_deg of the meridian either side (the plan chooses)
};

// The slew model of the slew-time weighting: both axes move at once at
// rate_deg_s (the slower axis decides), then settle_s; each point costs
// point_s more (exposure, plate solve); a German mount changing pier sides
// costs flip_s more.  rate_deg_s <= 0: no weighting.
struct SlewModel {
    double rate_deg_s = 0, settle_s = 5, point_s = 30, flip_s = 60;
    bool on() const { return rate_deg_s > 0; }
};

struct PlanOptions {
    int order = 1;                 // the model to plan for
    std::vector<std::string> adds; // its physical terms
    int mount = PM_MOUNT_EQUATORIAL;
    double latitude = NAN;         // radians (equatorial: required)
    double min_el_deg = 15;        // the horizon (with `horizon`: the higher of the two)
    double max_el_deg = NAN;       // the highest place (NaN: the mount's, max_el_of)
    Horizon horizon;               // azimuth-dependent horizon (empty: none)
    int next = 5;                  // how many targets
    double noise_arcsec = 1;       // per axis, to scale the predicted error (a run's sigma)
    double grid_deg = 6;           // candidate grid spacing (no catalogue)
    std::vector<CatalogueStar> stars; // candidates from a catalogue (empty: the grid)
    SkyTime when;                  // where the catalogue's stars are
    bool gem = true;               // equatorial: a German mount (flips at the meridian)
    // The side of the meridian a German mount takes on its normal pier side
    // (+1, encoder declination within +-90 deg): +1 west (HA > 0: the tube
    // east of the pier looking west, ASCOM's pierEast "normal pointing
    // state", as the real runs of ../shared/data do), -1 east (a mount that
    // counts its declination the other way round; pmsim's runs).  With a run
    // plan_targets takes the run's own (the sides of its places beyond
    // meridian_limit_deg), this where the run does not show one.
    int normal_west = 1;
    PlanSides sides = SIDES_RUN;
    double meridian_limit_deg = 15; // how far past the meridian either side reaches
    bool d_optimal = false;        // maximise det(A) instead of minimising the mean variance
    SlewModel slew;
};

struct Target {
    double x_deg, y_deg;  // HA and Dec, or azimuth and elevation (the sky position)
    double el_deg;        // its elevation
    int side;             // pier side to take it on (+1 normal, -1 beyond the pole, 0 alt-az)
    double after_arcsec;  // the predicted mean error over the sky once it is taken
    std::string name;     // the catalogue star (empty on the grid)
    double ra_h = NAN, dec_deg = NAN; // its catalogue place
    double slew_s = NAN;  // slew-time weighting: the time to reach it and take it
};

struct Plan {
    double before_arcsec = 0;     // predicted mean error over the sky now (1 sigma per axis)
    std::vector<Target> targets;  // in the order to take them
    int n_candidates = 0, n_sky = 0;
    int n_catalogue = 0;          // stars read (n_candidates of them usable)
    std::string note;             // e.g. the run does not determine the model yet
    bool note_says_undetermined = false; // the note says why the model is not determined
    int sides = 0;                // the sky planned: 2 a German mount's (both pier
                                  // sides), 1 a mount that does not flip, 0 alt-az
};

// The highest elevation planned: o.max_el_deg, else the mount's: an
// alt-az mount 85 deg (the zenith keyhole, where azimuth turns faster than
// it can follow: most cannot slew or track there), an equatorial one 90.
double max_el_of(const PlanOptions &o);

// Plan the next targets after the observations of `taken` (may be empty:
// the first points of a run).  The model's rows are evaluated at the run's
// fitted model when taken has enough points, else at the ideal mount.
// Throws std::runtime_error (no latitude for an equatorial mount, no
// usable sky, no candidate above the horizon, a catalogue without a time).
Plan plan_targets(const Run &taken, const PlanOptions &o);

// The same criterion for a given set of sky positions (x, y in degrees,
// pier side): the predicted mean error over the sky (arcsec) -- for
// comparing a plan with a grid or random points.
double predicted_mean_error(const std::vector<Target> &points, const PlanOptions &o);

// The noise a plan scales its predictions by when none is given: the
// run's own sigma (arcsec) fitted at the plan's order and terms, or
// `fallback` when the run cannot be fitted (too few points, no solution).
double run_noise_arcsec(const Run &run, int order, const std::vector<std::string> &adds,
                        double fallback);

// pmfit plan --json: the plan as one JSON object (docs/formats.md).
std::string plan_json(const Plan &p, const PlanOptions &o, size_t taken);

// ---- the design machinery, for benchmarks choosing among given places

// A place of a design: an encoder position and the inputs of the terms.
struct DesignPlace {
    double eh = 0, ed = 0; // encoder (radians; beyond the pole as the mount reads it)
    pm_context ctx = pm_context();
    double weight = 1;     // its weight in the sky average
};

// The greedy order: from the places `taken`, k of `cand` (each at most
// once), each the one that most lowers the criterion (the mean over `sky`
// of the predicted variance, or with d_optimal the log det of the
// information), per unit time with slew.on() (from start, when given).
// Rows of model m at its own prediction.  crit: the I criterion
// tr(W A^-1)/2 (for unit noise) after each pick.  Returns indices into
// cand (fewer than k when the candidates run out).
std::vector<int> greedy_design(const pm_model &m, const std::vector<DesignPlace> &taken,
                               const std::vector<DesignPlace> &cand,
                               const std::vector<DesignPlace> &sky, int k, bool d_optimal,
                               const SlewModel &slew, const DesignPlace *start,
                               std::vector<double> *crit, std::vector<double> *slew_s = nullptr);

// The I criterion tr(W A^-1)/2 (unit noise) of the places `pts` over `sky`
// (a tiny ridge keeps it finite when pts do not determine the model).
double design_criterion(const pm_model &m, const std::vector<DesignPlace> &pts,
                        const std::vector<DesignPlace> &sky);

// The slew model's time from place a to place b (seconds, point_s
// included), for a mount of type `mount`.
double slew_time(const SlewModel &s, int mount, const DesignPlace &a, const DesignPlace &b);

} // namespace pmhost

#endif
