// fitrun.hpp - fitting a pointing run with a chosen term set (host side):
// the observations with their contexts, models built from effect names, the
// Gauss-Newton fit with diagnostics, residuals, and the F-test.  Shared by
// pmfit fit/eval/simulate and pmfit explain.  Errors are exceptions
// (std::runtime_error) carrying the message for the user.
#ifndef PM_FITRUN_HPP
#define PM_FITRUN_HPP

#include "pm.h"
#include "modelfile.h"
#include "runfile.h"

#include <limits>
#include <string>
#include <vector>

namespace pmhost {

const double RAD2AS = 206264.80624709636;
const double PI = 3.14159265358979323846;

struct Obs {
    double eh, ed, ah, ad;
    int pier, line;
    pm_context ctx; // inputs of the physical terms
    // axis 1 as the file wrote it (radians; pmrun_obs.enc_raw[0]): a cable
    // wrap's turn; NaN where the observation did not come from a file
    double raw1 = std::numeric_limits<double>::quiet_NaN();
};

struct FitOut {
    pm_status status = PM_OK;
    pm_model model;
    pm_fit_result res;
    int bad_term = -1;
    int corr_i = -1, corr_j = -1; // most correlated pair when not converged
    double corr = 0;
    bool both_sides = false;    // the observations fitted hold both pier sides
    std::vector<double> r0, r1; // residuals (rad), sky frame
    std::vector<int> idx;       // indices into the run
    double rms = 0;
    std::vector<double> cov;    // P x P coefficient covariance (rad^2), row-major
};

// A pointing run read from a file, with per-observation contexts.
struct Run {
    std::string path;
    int mount = PM_MOUNT_EQUATORIAL;
    double latitude = 0; // radians; NaN when the file gives none
    std::vector<Obs> obs;
    std::vector<std::string> aux_names;
    std::vector<std::string> notes; // reader warnings, skipped records
    bool dir_derived = false;       // slew directions from the sequence
    bool dec_dir_derived = false;   // the input "dec_dir" too (derive_directions)
    bool turn_derived = false;      // the input "az_turn" (derive_directions)
    bool wind_derived = false;      // the input "az_wind" (derive_directions)
    bool az_count = false;          // axis 1 read as the mount's count (load_run)
    // the reading options a command that refits the run repeats
    // (" --equinox J2000 --no-refraction ..."; explain's closing command)
    std::string read_options;
    // every auxiliary column as read, [column][observation] (the contexts
    // hold the first PM_MAX_AUX): run_for_model takes a model's input from
    // beyond them by its name.  Only for the run as read (a run whose obs
    // were filtered since has columns of another length: not used then).
    std::vector<std::vector<double>> aux_values;
};

// How a run file is read: pmfit's reading options (pmrun_options, with
// az_count).  format: a PMRUN_FORMAT_* id or -1 (PMRUN_FORMAT_AUTO,
// detect); equinox: a PMRUN_EQUINOX_* id (0: as the file says)
// (tools/lib/runfile.h).  az_count: an alt-az file's azimuth is the mount's
// count, read so even within 0..360 deg (the mount never turns through the
// file's seam; pmfit --azimuth-count; derive_directions).  The weather of
// the refraction in the reductions: NaN takes the file's (pmfit
// --pressure, --temperature, --humidity, --wavelength).
struct ReadOptions {
    bool refraction = true;
    bool skip_bad = false;
    int format = -1;
    int equinox = 0;
    bool az_count = false;
    double pressure_hpa = std::numeric_limits<double>::quiet_NaN();
    double temp_c = std::numeric_limits<double>::quiet_NaN();
    double humidity = std::numeric_limits<double>::quiet_NaN();
    double wavelength_um = std::numeric_limits<double>::quiet_NaN();
    // the options as pmfit's arguments, each after a space (" --equinox
    // J2000 --pressure 780"; "" for the defaults): what a command that
    // reads the run again repeats (Run::read_options)
    std::string text() const;
};

// Read a run (pmrun_read); without a direction column the slew direction on
// axis 1 is the sign of the encoder's change from the previous observation.
// r.read_options is ro.text().
Run load_run(const std::string &path, const ReadOptions &ro = ReadOptions());
// Where an equatorial run's records are all one pier side but its residuals
// change at the meridian as a German mount's sides do (records folded to the
// sky, no pier column): the text that says so (fit order, adds); else "".
std::string folded_pier_hint(const Run &run, int order, const std::vector<std::string> &adds);
// A note in r.notes where an RTS2 file read with its true places as they
// are (ro.equinox PMRUN_EQUINOX_FILE) fits far better with them reduced
// from J2000 (both fitted at order 0); raw is the run as read.
void equinox_hint(Run &r, const pmrun *raw, const std::string &path, const pmrun_options &ro);
// The same from a run already read (pmrun_read), named path in messages.
Run run_from_pmrun(const pmrun *run, const std::string &path, bool az_count = false);
// What load_run derives from the sequence of the observations: the slew
// direction on axis 1 where no observation has one, and the input "dec_dir"
// ("el_dir" on an alt-az mount: axis2_dir_name) where the run has no such
// column and a context slot is free.
// az_count: axis 1 of an alt-az run as written is the mount's count (the
// slew direction its change), whatever its range (load_run).
void derive_directions(Run &r, bool az_count = false);
// Where an alt-az run's slew directions were taken the short way round
// but the file's azimuth read as the mount's count (never through the
// file's 0/360 seam) gives other ones, and with a backlash term they fit
// far better so (order, adds as the fit's): the text that says so; else "".
std::string count_reading_hint(const Run &run, int order, const std::vector<std::string> &adds);
// Whether count_reading_hint can apply at all (its reading gives 3 or more
// other directions; no fit).
bool count_reading_possible(const Run &run);
// The name of the derived slew direction on axis 2: "el_dir" on an alt-az
// mount, "dec_dir" on an equatorial one.
const char *axis2_dir_name(int mount);
// The names of an alt-az mount's periodic effects where the text speaks of
// its axes: "ha_periodic" and "dec_periodic" (axis 1 and 2 of either
// mount, the names in JSON and model files) read "az_periodic" and
// "el_periodic" in s on an alt-az mount; s unchanged on an equatorial one.
// --add takes both names on an alt-az mount (build_model).
std::string mount_words(const std::string &s, int mount);
// The widest empty arc of the angles (radians) on the circle: its width
// (2 pi for fewer than two angles), and where middle is given its middle,
// in (-pi, pi].  (explain's sampled extent of an axis is the circle less
// it; derive_directions' cut where an axis never turns.)
double widest_gap(const std::vector<double> &ang, double *middle = nullptr);

// Name and physical meaning of a model term.
std::string term_name(const pm_model &m, int i);
// The index of the term named `name` (term_name) among the first n terms
// of m (all of them where n < 0), -1 if none.
int term_index(const pm_model &m, const std::string &name, int n = -1);
// With aux_names (the run's columns, aux_names[j] for pm_context.aux[j]) a
// term on a user input is named by its column ("column 'press' on ..."),
// else "aux input".
std::string meaning(const pm_model &m, int i,
                    const std::vector<std::string> *aux_names = nullptr);
std::string json_escape(const std::string &s);

// The harmonic set of `order` plus the effects `adds` (pmfit fit --add
// syntax, documented in its usage).
pm_model build_model(int order, const std::vector<std::string> &adds,
                     const std::vector<Obs> &obs, int mount, double lat,
                     const std::vector<std::string> &aux_names);
// The model without its side-specific added terms.
pm_model without_side_terms(const pm_model &m);

// The run as model m (of model_name) reads it, for evaluating a model
// fitted on another run.  inputs[j]: the name of the column m reads as
// ctx.aux[j] ("" where not known: a version-3 model file); each such
// column is looked up in run by its name and moved to slot j, so a run
// whose columns come in another order (or lack one a fit derived, as
// "dec_dir" from the sequence) is read right.  pier: 0, or the one pier
// side (+1 east, -1 west) m was fitted to: the records of that side only.
// What was done by position or left out is said in *notes.  Throws
// std::runtime_error ("model_name: ...") when the run lacks a named
// column or has no record of the side.
Run run_for_model(const Run &run, const pm_model &m, const std::vector<std::string> &inputs,
                  int pier, const std::string &model_name, std::vector<std::string> *notes);
// What a model file of m fitted on a run with auxiliary columns aux_names
// (pier: 0, or the one side it was fitted to) says beyond the model
// (pmmodel_info): the names of the columns its terms read, and where err is
// given the fit's 1-sigma errors of its coefficients.
pmmodel_info model_info(const pm_model &m, const std::vector<std::string> &aux_names, int pier,
                        const double *err = nullptr);
// The other way: a model file's input names, one per pm_context.aux[j]
// ("" where it names none), as run_for_model takes them.
std::vector<std::string> model_inputs(const pmmodel_info &info);

// The Gauss-Newton passes a fit may take: pmfit fit's, and every host
// tool's by default (explain's candidate fits too, so that explain fits
// whatever fit fits: a sky that nearly confounds terms -- an alt-az run in a
// narrow band of elevation -- can take hundreds of damped passes).
const int FIT_MAX_PASSES = 2000;

// The title of the fit of all points, as the report and model files give
// it: an alt-az mount has no pier sides to fit jointly.
inline const char *all_points_title(const pm_model &m)
{
    return m.mount == PM_MOUNT_ALTAZ ? "all points (alt-az mount)" : "joint fit, both pier sides";
}

// Fit `start` to the observations `use` (Gauss-Newton, at most max_passes);
// on success the residuals are filled in.  corr, corr_i, corr_j: the most
// correlated pair of terms (also after PM_ERR_DIVERGED).
FitOut do_fit(const std::vector<Obs> &obs, const std::vector<int> &use, const pm_model &start,
              int max_passes = FIT_MAX_PASSES);
// The same in a caller-owned workspace, which holds the last solve afterwards
// (for pm_fit_pointing_sigma and pm_fit_covariance); do_fit above uses one
// static workspace, so it is not reentrant.
FitOut do_fit(pm_fit &work, const std::vector<Obs> &obs, const std::vector<int> &use,
              const pm_model &start, int max_passes);
// Residuals of f.model on the observations `use` into f (r0, r1, idx, rms).
// Returns PM_OK, or the status of the first observation the model cannot
// be evaluated at (a term reads an input the record does not give:
// temperature, time, an aux column), its position in `use` in *bad; the
// residuals there are NaN, and rms is of the others.
pm_status residuals(FitOut &f, const std::vector<Obs> &obs, const std::vector<int> &use,
                    size_t *bad = nullptr);
// J C J^T at one position: J its two design rows at the fitted model
// (pm_fit_row with the observed place ah, ad; the model's own prediction
// for a place not observed), C the fit's coefficient covariance (rad^2):
// v = (v00, v01, v11) in rad^2, and r observed minus model (pm_fit_row's
// frame, so |r| is the sky's).  False where the rows cannot be made or the
// fit has no covariance.
bool row_covariance(const FitOut &f, const pm_context &ctx, double eh, double ed, double ah,
                    double ad, double v[3], double r[2]);

// What more than its status (pm_status_text) is known of why fit f failed,
// in the words every host tool uses: the term that is a combination of the
// terms before it, the pair the sky coverage hardly separates (after
// `passes` passes), the observations P terms need.  order: how the caller's
// user lowers the order ("--order", "the order").  "" where nothing more
// is known; else text to append to "WHAT: STATUS TEXT".
std::string fit_failure_detail(const FitOut &f, int passes, const std::string &order);

// The F distribution's upper tail (and its natural log, which does not
// underflow for huge F), and the nested-model F-test.
double inc_beta(double a, double b, double x);
double f_tail(double f, double d1, double d2);
double log_f_tail(double f, double d1, double d2);
struct FTest {
    bool done = false;
    double f = 0, p = 1;
    int d1 = 0;
    long d2 = 0;
    std::string what;
};
FTest f_test(double chi2_small, int p_small, double chi2_big, int p_big, long n_obs,
             const std::string &what);

} // namespace pmhost

#endif
