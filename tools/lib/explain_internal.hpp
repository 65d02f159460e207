// explain_internal.hpp - the parts the stages of pmfit explain share
// (explain.cpp: locate, candidates, select; explain_describe.cpp: the
// findings in words; explain_interpret.cpp: the baseline in physical terms).
// Not installed, not a public API.
#ifndef PM_EXPLAIN_INTERNAL_HPP
#define PM_EXPLAIN_INTERNAL_HPP

#include "explain.hpp"

#include <string>
#include <vector>

namespace pmhost {
namespace xdetail {

const double LN10 = 2.302585092994046;

inline double arcsec(double rad) { return rad * RAD2AS; }

// A fit of one model spec (order, adds) to a set of observations.
struct Fit {
    bool ok = false;
    FitOut f;
    double chi2 = 0;
    int P = 0;
    long N = 0;
};

// Fit (order, adds) to the observations `use`.  Not applicable (a needed
// input missing, a singular term) gives ok = false.  warm: a fitted model
// whose coefficients start the terms it has too (the current model for a
// candidate, the whole run's fit for a cross-validation fold): a few
// passes from near the answer where a sky that nearly confounds terms
// makes the damped iteration creep from the default start.
Fit fit_spec(const Run &run, const std::vector<int> &use, int order,
             const std::vector<std::string> &adds, const pm_model *warm = nullptr);
// A fit's model as a warm start (fit_spec), or none where it did not fit.
inline const pm_model *warm_of(const Fit &f) { return f.ok ? &f.f.model : nullptr; }
// The leave-one-out RMS per axis (radians) of a fit (PRESS) over its
// points but `skip`; the points it cannot predict (H_ii's larger eigenvalue
// above LEVERAGE_MAX); the cross-validated RMS explain decides by
// (explain.cpp).
const double LEVERAGE_MAX = 0.99;
double loo_rms(const Run &run, const Fit &fit, const std::vector<int> &skip = {});
std::vector<int> unpredictable(const Run &run, const Fit &fit);
double cv_of(const Run &run, const std::vector<int> &use, int order,
             const std::vector<std::string> &adds, const ExplainOptions &opt, const Fit &fit,
             const std::vector<int> &skip);

// Where the search stands: the observations used and the current model.
struct State {
    std::vector<int> use;
    int order = 1;
    std::vector<std::string> adds;
    Fit cur;
    double cur_cv = 0;
    std::vector<int> cv_skip; // the baseline's unpredictable points (sorted), left out of
                              // every cross-validated RMS of the search
};

// One candidate explanation: a family of terms (or a pair of families, or
// outliers to drop) and its fit.
struct Candidate {
    std::string effect;                // "refraction", or "a+b" for a pair
    std::vector<std::string> members;  // the families of a pair (else {effect})
    std::vector<int> member_terms;     // per member, how many terms it adds
    int order = 1;
    std::vector<std::string> adds;
    std::vector<std::string> new_adds; // what this candidate adds
    double trials = 1;                 // periods scanned
    double peak_g = 0;
    std::vector<double> aliases;       // periodic: other periods (other peaks) that fit as well
    std::vector<double> member_g;      // per member of a pair: its G (periodic), else 0
    std::vector<int> drop;             // outliers: observations to drop
    std::vector<double> miss;          // outliers: each one's deleted residual (rad)
    Fit fit;
    bool fitted = false;               // fit made already (the chosen period's, prefer_integer)
    double log_fap = 0;                // natural log of the false-alarm probability
    double cv = 0;                     // cross-validated RMS once checked
    double blur = 0;                   // > 0: its terms' error beside the harmonics over their
                                       // error at order 1, where that passed kMaxBlur
    double err_arcsec = 0, err1_arcsec = 0; // (that largest error, here and at order 1)
};

double elevation_of(const Run &run, const Obs &o);
bool has(const std::vector<std::string> &v, const std::string &s);
// Why the run's column j (j < PM_MAX_AUX) cannot be a candidate over the
// observations `use`: "no value at line N (...)", "the same at every
// point"; empty where it can (physical_candidates, not_tried_why).
std::string column_unusable(const Run &run, const std::vector<int> &use, size_t j);
// Does input `which` (0 temp, 1 time, 2 dir) vary, and is it known everywhere?
bool input_usable(const Run &run, const std::vector<int> &use, int which);
// Angular size (radians) of model b minus model a at each observation.
std::vector<double> model_difference(const Run &run, const std::vector<int> &use,
                                     const pm_model &a, const pm_model &b);
// Where a quantity (one value per observation in `use`) is largest and
// smallest, over elevation bands, axis-1 quarters and pier sides.
std::string where_largest(const Run &run, const std::vector<int> &use,
                          const std::vector<double> &v, const char *unit);
// The bin name where a quantity is largest (for "separate by" advice).
std::string largest_bin(const Run &run, const std::vector<int> &use,
                        const std::vector<double> &v);

// Words for an axis of this mount: "hour-angle"/"azimuth", ...
const char *axis_word(const Run &run, int axis, bool raw);

// The periods of axis comp (0, 1) that fit as well as G: the full fit of
// adds (which holds G's term; own_fit, their fit on st.use at st.order,
// the candidate's) with the period g in G's place within
// PERIOD_RANGE_CHI2 noise variances of own_fit's, from *lo to *hi (G itself where
// the data fix it).  Whole numbers of cycles beside an integer G (up to 5
// either way); beside another G, the half-width of the chi^2 parabola.  An
// axis sampled over part of its circle (*sampled_deg) resolves G only to
// about a turn's worth of phase over that extent: 80 deg of an axis cannot
// always tell 309 teeth from 310.  Within the periods the full fit may
// settle on (from refine_floor, one cycle over the sampled range, to
// opt.g_max).
const double PERIOD_RANGE_CHI2 = 3.84; // chi^2(1) at 5%
void period_range(const Run &run, const State &st, const ExplainOptions &opt, const Fit &own_fit,
                  const std::vector<std::string> &adds, int comp, double G, double *lo,
                  double *hi, double *sampled_deg);

// Step 1's composition (explain_compose.cpp): the run with the
// second-order composition of its baseline's anisotropic terms (read as
// gimbal parameters) taken out of the observed positions; *rms its RMS per
// axis (radians).  The run as it is (*rms = 0) where the baseline does not
// fit, has no anisotropic terms or does not determine them, or where the
// composed reading does not fit better.
Run composed_run(const Run &run, const ExplainOptions &opt, const std::vector<int> &use,
                 double *rms);
// The sum over the observations use of the squared shift (radians^2, both
// axes, on the sky) between the observed positions of a and b.
double shift_ss(const Run &a, const Run &b, const std::vector<int> &use);

// Solve the small dense system A x = b (n x n, row-major; x returned in b)
// by Gaussian elimination with partial pivoting; false where a pivot is not
// above rel_tol times the largest |A_ii| (0: exactly singular)
// (explain_interpret.cpp).
bool solve(std::vector<double> A, std::vector<double> &b, int n, double rel_tol = 0);

// Whether a candidate's family may pair with another (step 4's pairs: not
// higher_order, not outliers).
inline bool pairable(const Candidate &c)
{
    return c.effect != "higher_order" && c.effect != "outlier";
}

// The finding(s) one accepted candidate makes: one per member family.
std::vector<Finding> describe(const Run &run, const State &st, const Candidate &c,
                              const ExplainOptions &opt);
// A finding's size, error, phase and text from the final model (st.cur:
// every finding in, the outliers left out) instead of its step's; outliers
// and higher_order keep their step's.
void describe_final(const Run &run, const State &st, Finding &fd);

} // namespace xdetail
} // namespace pmhost

#endif
