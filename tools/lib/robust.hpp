// robust.hpp - a fit that ignores gross outliers (failed plate solves, wrong
// stars): iterative clipping of the 2-D tangent-plane residuals against a
// median-based scale, started from a least-trimmed-squares half fit
// (docs/robust.md describes the method and the threshold).
#ifndef PM_ROBUST_HPP
#define PM_ROBUST_HPP

#include "fitrun.hpp"

#include <string>
#include <vector>

namespace pmhost {

// Default clip K (in units of the robust sigma): the residual on the sky of a
// clean point with Gaussian noise of sigma per axis is Rayleigh distributed,
// P(|r| > K sigma) = exp(-K^2/2); K = sqrt(2 ln 10^4) = 4.29 rejects a clean
// point with probability 1e-4.
const double ROBUST_DEFAULT_CLIP = 4.29;

struct RobustFit {
    FitOut fit;                    // fit of the kept points (model, statistics, their residuals);
                                   // fit.status != PM_OK: that fit failed (error is empty)
    std::string error;             // non-empty: no robust model (too many rejected, too few kept)
    std::vector<int> use;          // the observations considered (indices into the run)
    std::vector<double> r0, r1;    // residual of every entry of use w.r.t. fit.model (rad)
    std::vector<double> dist;      // per entry of use: standardised distance (rad), the
                                   // residual weighed by its leverage (robust.cpp)
    std::vector<char> rejected;    // per entry of use
    std::vector<int> outliers;     // indices into the run of the rejected points, by line
    double clip = ROBUST_DEFAULT_CLIP;
    double sigma_robust = 0;       // rad: the scale the threshold multiplies (per axis)
    int rounds = 0;                // clipping rounds (refits) after the start
    bool stable = true;            // false: the rejected set still changed after max_rounds
    bool lts_start = true;         // false: the half fit was singular; started from all points
};

// Robust fit of `start` to the observations `use`:
//   1. least squares on all points;
//   2. start: concentration steps of least trimmed squares, refitting the
//      h = max(ceil(N/2), P) points of smallest residual until that set is
//      stable, so that any minority of gross errors has no leverage;
//   3. clipping: keep the points with d <= clip * sigma_robust, where d is
//      the residual standardised by its leverage (d^2 = r^T (I -+ H_ii)^-1 r,
//      minus for kept points, plus for rejected ones: chi^2(2) sigma^2 for
//      both) and sigma_robust = median(d of the kept points) / sqrt(2 ln 2)
//      (the Rayleigh median) until that set is stable, then the RMS of the
//      kept d corrected for the truncation at clip; refit the kept points
//      from the previous solution; recompute every residual (a rejected point
//      may come back) and repeat until the kept set is unchanged (at most
//      max_rounds).
// Errors (error set): fewer kept points than terms (N >= P is needed to judge a
// point against the others), or more than half of them rejected (no majority
// follows one model).
RobustFit robust_fit(const std::vector<Obs> &obs, const std::vector<int> &use,
                     const pm_model &start, double clip, int max_passes, int max_rounds = 50);

// The points a robust fit (started from f's model) rejects among those of
// the plain fit f (indices into the run, by line; empty if it fails): the
// hint to try --robust.
std::vector<int> robust_suspects(const FitOut &f, const std::vector<Obs> &obs, double clip,
                                 int max_passes);

} // namespace pmhost

#endif
