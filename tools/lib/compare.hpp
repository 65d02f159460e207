// compare.hpp - night-to-night drift (pmfit compare OLD RUN): apply an
// earlier model to a new run, say what it leaves, which terms moved
// significantly, and whether re-zeroing the two index terms suffices or the
// model must be refitted (cross-validated).  docs/model.md, "Has the model
// changed since last night?".
#ifndef PM_COMPARE_HPP
#define PM_COMPARE_HPP

#include "fitrun.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace pmhost {

struct TermChange {
    std::string name, meaning;
    double old_arcsec = 0, new_arcsec = 0, err_arcsec = 0; // err: of the difference
    double z = 0;                                          // difference / err
};

struct Comparison {
    long n_obs = 0;
    int n_terms = 0;
    bool old_has_errors = false;   // OLD was a run (its errors count), not a model file
    double rms_as_is = 0;          // per axis, the new run under the old model, no refit
    double rms_rezero = NAN;       // per axis, under the old model re-zeroed on it (NaN: the
                                   // re-zero failed)
    double sigma_refit = 0;        // unbiased sigma of the refit
    std::vector<TermChange> moved; // |z| >= 3, largest first
    int n_stable = 0;              // terms that did not move (|z| < 3)
    double rezero_c = 0, rezero_c_err = 0, rezero_e = 0, rezero_e_err = 0; // arcsec
    double cv_as_is = 0, cv_rezero = 0, cv_refit = 0; // per axis, 5-fold
    // OLD a run: the old fit's predicted error (pm_fit_pointing_sigma) at
    // the new run's points and at its own; NaN for a model file
    double old_pred_new = NAN, old_pred_old = NAN;
    // OLD a run: its fit's sigma (arcsec), and log10 of the chance that
    // tonight's refit leaves so much more by chance (F-test); NaN else
    double old_sigma = NAN, sigma_log10p = NAN;
    // The joint test of the changes (NaN where not made): log10 of the
    // chance of so large a change of all terms together, and of all but
    // c' and e' (what a re-zero leaves), with both fits' errors
    // (compare.cpp, joint_tests); old_cov: how the old covariance was had
    double joint_log10p = NAN, rest_log10p = NAN;
    std::string old_cov;
    bool old_cov_borrowed = false; // a model file's errors with the refit's correlations
    // JSON's "old_covariance": "run", "model_file" (version 5), "errors_only"
    // (version 4: the refit's correlations borrowed) or "none"
    std::string old_cov_kind = "none";
    std::string advice;
    std::vector<std::string> notes; // how the run was read for the old model (run_for_model)
    pm_model refit, rezeroed;
};

// old_model: the earlier model; old_err: its coefficients' 1-sigma errors
// (empty when it came from a model file); run: the new night.  Throws
// std::runtime_error with the reason (mount mismatch, the refit failing).
// old_fit, old_run: the fit OLD came from (a run), or null (a model file);
// old_cov: a model file's covariance (P x P, version 5), or null;
// old_stars_sigma: its fit's predicted 1 sigma at its own stars (rad), 0
// where not known.
Comparison compare_models(const pm_model &old_model, const std::vector<double> &old_err,
                          const Run &run, const FitOut *old_fit = nullptr,
                          const Run *old_run = nullptr,
                          const std::vector<double> *old_cov = nullptr,
                          double old_stars_sigma = 0);

// OLD of pmfit compare and pmfit report --compare: a model file, or a run
// fitted at order + adds (do_fit with max_passes).
struct OldSide {
    bool is_run = false;
    pm_model model;            // the model file's, or the run's fit (on success)
    std::vector<double> err;   // the fit's 1-sigma errors (a model file's where it keeps them)
    std::vector<double> cov;   // a model file's covariance (version 5), P x P; else empty
    double stars_sigma = 0;    // and its fit's predicted 1 sigma at its stars (rad; 0: none)
    FitOut fit;                // a run: its fit; check fit.status (the caller words a failure)
    Run run;                   // a run: the run
    // the columns the model reads as ctx.aux[j] (a run's names; a model
    // file's input lines, "" where it has none) and its pier side (0: both)
    std::vector<std::string> inputs;
    int pier = 0;
};
// Throws std::runtime_error with the file's message when OLD cannot be
// opened or read (its file:line).
OldSide load_old(const std::string &path, int order, const std::vector<std::string> &adds,
                 const ReadOptions &ro, int max_passes);

// OLD as a model (prepared) and what its file says: its inputs' names, its
// pier side, its coefficients' errors where it keeps them.
OldSide old_from_model(const pm_model &m, const pmmodel_info &info,
                       const std::vector<double> &cov = std::vector<double>());
// OLD as a run already read: fitted at order + adds (do_fit with max_passes).
OldSide old_from_run(const Run &run, int order, const std::vector<std::string> &adds,
                     int max_passes);

// compare_models of OLD on the new run, read as OLD's model reads a run
// (run_for_model: its columns by name, its pier side); old_name for the
// messages.  Throws std::runtime_error as compare_models and run_for_model.
Comparison compare_old(const OldSide &os, const Run &run, const std::string &old_name);
std::string comparison_json(const Comparison &c);
void print_comparison(const Comparison &c, const std::string &old_name, const std::string &run_name);

} // namespace pmhost

#endif
