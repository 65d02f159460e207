// explain.hpp - find the physics a pointing model left out (host side).
//
// Fit a baseline model, locate where the residuals are systematically too
// large, name the left-out effect from a catalogue of candidates (each a set
// of core terms), add it, refit, and repeat while something significant is
// left; significance controls false alarms (F-test p-value times the number
// of periods scanned and of candidates tried) and is confirmed by the
// leave-one-out cross-validated prediction error.  docs/explain.md describes the method.
#ifndef PM_EXPLAIN_HPP
#define PM_EXPLAIN_HPP

#include "fitrun.hpp"

#include <string>
#include <vector>

namespace pmhost {

struct ExplainOptions {
    int order = 1;                 // baseline harmonic order
    std::vector<std::string> adds; // baseline added terms (--add)
    double alpha = 0.01;           // false-alarm probability to accept a finding
    int folds = 0;                 // cross-validation: 0 leave-one-out (PRESS, from the
                                   // fit itself), k >= 2 k-fold (k more fits)
    int max_findings = 8;
    double g_min = 2, g_max = 720; // periodogram range (cycles per revolution)
    // Known gear periods (cycles per revolution, e.g. the worm's tooth
    // count): when an axis has any, its periodic candidates are only these,
    // and the false-alarm correction counts only them (--gear).
    std::vector<double> gears_ha, gears_dec;
    unsigned seed = 1;             // fold assignment (k-fold)
    bool pairs = true;             // where no single family passes, try pairs
    double close_delta_bic = 6;    // alternatives: Delta BIC below this (for readings of
                                   // as many terms: a likelihood ratio below 20)
    std::vector<std::string> exclude; // families not to try (the ones a backward pass withdrew)
    bool compose = true;           // take out the baseline's second-order
                                   // composition (docs/explain.md, step 1; --no-compose)
};

// One located statistic: a part of the data whose residuals are too large.
struct Located {
    std::string what;   // "axis 2", "elevation 10-25 deg", "pier west", "temperature" ...
    double rms_arcsec;  // RMS there (or correlation coefficient for variables)
    double ratio;       // RMS there / overall RMS (or |t| statistic)
    double p;           // probability of so much excess by chance (not corrected)
};

struct Periodogram {
    std::string axis;              // "ha" or "dec"
    std::vector<double> g, power;  // power: chi^2 reduction / sigma^2 (arcsec^2 / sigma^2)
    double peak_g = 0, peak_power = 0, threshold = 0; // threshold: false alarm alpha
    double trials = 0;             // periods the peak was chosen among (known gears or the scan)
};

// Another reading of the same residuals whose evidence is close to the
// chosen one's (docs/explain.md, "Confusable effects").
struct Alternative {
    std::string effect;
    double log10_fap = 0;      // its own false-alarm probability (log10)
    double delta_bic = 0;      // BIC(alternative) - BIC(chosen), >= 0
    double log10_lr = 0;       // log10 of the likelihood ratio chosen : alternative
    std::string separate_by;   // the observation that would tell them apart
    bool smooth = false;       // kind "smooth": offered because the run cannot show the
                               // chosen periodic shape repeats (explain.cpp, smooth_alternative),
                               // not for a Delta BIC below close_delta_bic (kind "close")
    bool final_model = false;  // kind "final": the rival family (temperature, time_drift)
                               // as good in the final model, where the step that chose the
                               // finding had the later findings still in its residuals
                               // (explain.cpp, final_rival)
};

// One physical reading of the fitted baseline (docs/explain.md,
// "What the baseline holds").
struct Interpretation {
    std::string what;          // key: polar_altitude, polar_azimuth, ...
    double value = 0, error = 0;
    std::string unit;          // "arcmin", "arcsec", "deg"
    std::string text;          // in plain words, with the size
};

struct Finding {
    // A refraction or tube-flexure finding fitted at its step with the
    // other of the two beside it (they share their shape over a run's
    // elevations): the finding's value and error then, the other's
    // (arcsec); beside empty where not fitted (explain.cpp, record)
    struct Beside {
        std::string effect;
        double value = 0, error = 0, other_value = 0, other_error = 0;
        double alone = 0, alone_error = 0; // the finding's own at its step, without the other
        bool close = false;   // the other is an as-good alternative of the finding
    } beside;
    std::string effect;       // vocabulary: ha_periodic, dec_periodic, pier_side, refraction,
                              // tube_flexure, temperature, time_drift, hysteresis,
                              // higher_order, outlier
    std::string text;         // what it is, in plain words, with its size
    std::string where;        // where on the sky (or when) it matters
    std::vector<std::string> adds; // the terms added (pmfit --add syntax)
    std::vector<std::string> term_names; // those terms' names in the model (term_name)
    // those terms' values and 1-sigma errors, arcsec, in the final model
    // (as pmfit fit --json lists its terms); none for outliers, higher_order
    struct Coefficient {
        std::string name;
        std::string column; // the run's column of a term on one (name says aux0), else empty
        double value_arcsec = 0, error_arcsec = 0;
    };
    std::vector<Coefficient> coefficients;
    double cycles_per_rev = 0, amplitude_arcsec = 0, amplitude_err_arcsec = 0, phase_deg = 0;
    double cycles_lo = 0, cycles_hi = 0; // periodic: the periods that fit as well (lo..hi)
    std::vector<double> aliases;          // periodic: periods of other peaks that fit as well
    double sampled_deg = 0;               // periodic: the extent of the axis the run samples
    double f_stat = 0, log10_p = 0, false_alarm_probability = 1;
    double sigma_after_arcsec = 0, cv_rms_after_arcsec = 0;
    int n_params_after = 0;
    std::vector<int> lines;   // outliers: their file lines
    double trials = 1;        // periods its search chose among (periodic), else 1
    int step = 0;             // the step of the search that found it (1, 2, ...)
    std::string with;         // found together with this effect (a pair), else ""
    std::vector<Alternative> alternatives; // readings with close evidence
};

// A family significant at alpha where the search ended that does not
// predict better (its cross-validated RMS no smaller than the model's): the
// residuals hold it, but the run's points cannot fit it usefully
// (docs/explain.md, "Significant, not modelled").
struct Unmodelled {
    std::string effect;        // as Finding::effect ("a+b" for a pair)
    double log10_fap = 0;      // its false-alarm probability (log10), as a finding's
    double sigma_arcsec = 0, cv_rms_arcsec = 0; // with it
    double sigma_before_arcsec = 0, cv_before_arcsec = 0; // the model it was tried on
    int n_params = 0;          // the model's terms with it
    int n_obs = 0;             // the points it was fitted to
    double cycles_per_rev = 0; // periodic: its period, else 0
};

struct Explanation {
    double base_sigma_arcsec = 0, base_cv_rms_arcsec = 0;
    int base_n_params = 0;
    double final_sigma_arcsec = 0, final_cv_rms_arcsec = 0;
    int final_n_params = 0;
    std::vector<Located> located;        // before any finding
    std::vector<Periodogram> periodograms; // of the baseline residuals
    std::vector<Finding> findings;
    std::vector<std::string> candidates_tried; // per step, for the report
    std::vector<Finding> withdrawn;      // found, then not needed once later ones were in
    std::vector<std::string> withdrawn_why;
    std::vector<Interpretation> interpretation; // the physical reading of the baseline
    std::string physical_reading;        // order 0 + one term predicts as well as order 1
    // fewer points than the order-1 baseline has terms (N < P; its own
    // options order 1, no --add): order 0's cross-validated RMS, else NaN
    double order0_cv_rms_arcsec = std::numeric_limits<double>::quiet_NaN();
    std::string order0_with; // the physical term that order 0 did so with ("" for none)
    std::string folded_pier;             // folded_pier_hint (fitrun.hpp): sides not in the file
    FitOut baseline, final;              // the two fits (residuals for plots)
    std::vector<int> kept;               // observations used by the final fit
    std::vector<std::string> final_adds;
    int final_order = 1;
    double compose_rms_arcsec = 0;       // the composition taken out (RMS per axis), 0 if none
    std::vector<int> cv_left_out;        // points the baseline cannot predict from the others,
                                         // left out of every cross-validated RMS (sorted)
    std::vector<Unmodelled> unmodelled;  // where the search ended: the most significant
                                         // family that does not predict better (0 or 1)
    struct Blurred {                     // significant, but not separable from the model's
        std::string effect;              // harmonics (explain.cpp, separable)
        int step = 0, order = 0;
        double error_arcsec = 0, error_order1_arcsec = 0;
    };
    std::vector<Blurred> blurred;
    struct Unfitted {                    // a candidate whose fit did not converge: not
        std::string effect;              // judged at that step (its first)
        int step = 0, order = 0;
    };
    std::vector<Unfitted> unfitted;
};

// The pipeline: baseline -> locate -> candidates -> select (singles, then
// pairs) -> describe, repeated while something is found; then interpret.
Explanation explain(const Run &run, const ExplainOptions &opt);

// Where the caller left the order to explain (pmfit explain without
// --order, pm.explain without order=) and ex is the order-1 explanation
// (opt.order 1, no adds): the note that says why the run is better
// explained at order 0 -- fewer points than the baseline's terms, which
// order 0 predicts better (Explanation::order0_cv_rms_arcsec) -- else "".
std::string order0_instead(const Run &run, const Explanation &ex, const ExplainOptions &opt);
// The explanation where the caller left the order (opt.order 1, no adds;
// else explain(run, opt) as asked): at order 1, or at order 0 where the run
// is too few points for order 1 or order0_instead says so, *note then saying
// why ("" else).  first: the order-1 explanation where made already.
Explanation explain_default(const Run &run, const ExplainOptions &opt, std::string *note,
                            const Explanation *first = nullptr);

// The physical reading of a fitted model (stage "interpret"): polar axis,
// non-perpendicularity, collimation, indices, the tube-flexure-like part of
// the order-1 terms; explain_interpret.cpp.
std::vector<Interpretation> interpret(const Run &run, const FitOut &f);

// The report (explain_report.cpp): one JSON object (docs/formats.md), or
// text on stdout.
std::string explain_json(const Run &run, const Explanation &ex, int order);
// The candidate effects the run cannot have tried, and so not found: an
// equatorial run without a latitude cannot try refraction and tube flexure,
// nor the run's own column beyond the first PM_MAX_AUX, one with a point
// without a value, or one the same everywhere (the JSON's "not_tried", a
// line each of the text, with the reason).
std::vector<std::string> not_tried(const Run &run);
std::vector<std::pair<std::string, std::string>> not_tried_why(const Run &run);
// "significant, not modelled" in words: its sizes and what would fit it.
std::string unmodelled_text(const Unmodelled &u);
// A refraction or tube-flexure finding with the other fitted beside it
// (Finding::beside): "with E beside it: ..."; "" where not fitted.
std::string beside_text(const Finding &f);
// A candidate whose fit did not converge, in words.
std::string unfitted_text(const Explanation::Unfitted &u);
// A family significant at a step but not separable from its harmonics, in words.
std::string blurred_text(const Explanation::Blurred &b);
void print_explain_text(const Run &run, const Explanation &ex, int order, bool added,
                        double alpha, bool gears_ha, bool gears_dec);

// k-fold cross-validated RMS per axis (radians) of a model spec on the
// observations `use`; train_also are added to every training fold, never
// predicted (to measure what outliers do to the others); warm: the spec's
// fit on all of `use`, which starts each fold's (fit_spec); skip: sorted
// indices trained on but never predicted (explain's unpredictable points).
double cv_rms(const Run &run, const std::vector<int> &use, int order,
              const std::vector<std::string> &adds, int folds, unsigned seed,
              const std::vector<int> &train_also = {}, const pm_model *warm = nullptr,
              const std::vector<int> *skip = nullptr);

} // namespace pmhost

#endif
