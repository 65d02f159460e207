// compare.cpp - night-to-night drift (compare.hpp).
#include "compare.hpp"
#include "errormap.hpp"
#include "hostutil.hpp"
#include "modelfile.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

namespace pmhost {

namespace {

// Per-axis RMS of a model's residuals on observations `use` (no fit).
double rms_of(const pm_model &m, const Run &run, const std::vector<int> &use)
{
    double ss = 0;
    long n = 0;
    for (int i : use) {
        const Obs &o = run.obs[i];
        double r[2];
        if (pm_model_residual(&m, &o.ctx, o.eh, o.ed, o.ah, o.ad, r) != PM_OK)
            continue;
        ss += r[0] * r[0] + r[1] * r[1];
        n++;
    }
    return n ? std::sqrt(ss / (double)(2 * n)) : NAN;
}

// Re-zero: the model m with only its two index terms (c', e': terms 2 and
// 4) refitted to `use` (Gauss-Newton on the 2x2 normal equations; the
// other terms held).  err: their 1-sigma errors.  False if singular.
bool rezero(pm_model &m, const Run &run, const std::vector<int> &use, double err[2])
{
    std::vector<double> a(PM_MAX_TERMS), b(PM_MAX_TERMS);
    for (int pass = 0; pass < 8; pass++) {
        double n00 = 0, n01 = 0, n11 = 0, g0 = 0, g1 = 0, chi2 = 0;
        long n = 0;
        for (int i : use) {
            const Obs &o = run.obs[i];
            double r[2];
            if (pm_fit_row(&m, &o.ctx, o.eh, o.ed, o.ah, o.ad, a.data(), b.data(), r) != PM_OK)
                continue;
            n00 += a[2] * a[2] + b[2] * b[2];
            n01 += a[2] * a[4] + b[2] * b[4];
            n11 += a[4] * a[4] + b[4] * b[4];
            g0 += a[2] * r[0] + b[2] * r[1];
            g1 += a[4] * r[0] + b[4] * r[1];
            chi2 += r[0] * r[0] + r[1] * r[1];
            n++;
        }
        double det = n00 * n11 - n01 * n01;
        if (!(det > 0) || n < 2)
            return false;
        double d0 = (n11 * g0 - n01 * g1) / det, d1 = (n00 * g1 - n01 * g0) / det;
        m.coef[2] += d0;
        m.coef[4] += d1;
        if (pm_model_prepare(&m) != PM_OK)
            return false;
        double s2 = chi2 / (double)std::max(1L, 2 * n - 2);
        err[0] = std::sqrt(s2 * n11 / det);
        err[1] = std::sqrt(s2 * n00 / det);
        if (std::fabs(d0) < 1e-15 && std::fabs(d1) < 1e-15)
            break;
    }
    return true;
}

// 5-fold cross-validated per-axis RMS of: 0 the old model as is, 1 its
// re-zero, 2 a full refit (from the old model's terms and values).
void cross_validate(const pm_model &old_model, const Run &run, double cv[3])
{
    std::vector<int> perm(run.obs.size());
    for (size_t i = 0; i < perm.size(); i++)
        perm[i] = (int)i;
    std::mt19937 rng(1);
    std::shuffle(perm.begin(), perm.end(), rng);
    double ss[3] = {0, 0, 0};
    long n[3] = {0, 0, 0};
    const int folds = 5;
    for (int k = 0; k < folds; k++) {
        std::vector<int> train, test;
        for (size_t j = 0; j < perm.size(); j++)
            ((int)(j % folds) == k ? test : train).push_back(perm[j]);
        pm_model m[3] = {old_model, old_model, old_model};
        double e[2];
        bool ok[3] = {true, rezero(m[1], run, train, e), false};
        FitOut f = do_fit(run.obs, train, old_model);
        if (f.status == PM_OK)
            m[2] = f.model, ok[2] = true;
        for (int w = 0; w < 3; w++) {
            if (!ok[w])
                continue;
            double r = rms_of(m[w], run, test);
            ss[w] += r * r * (double)test.size();
            n[w] += (long)test.size();
        }
    }
    for (int w = 0; w < 3; w++)
        cv[w] = n[w] ? std::sqrt(ss[w] / (double)n[w]) : NAN;
}

// The changes of all terms together, and of all but c' and e' (what a
// re-zero leaves): T = d^T (C_old + C_new)^-1 d, with C from the fits'
// estimated sigma, so T / k against F(k, nu) (Hotelling's T^2 read as F),
// nu the residual degrees of freedom of the refit (and of the old fit,
// the fewer).  (Against chi^2(k), as if sigma were known, unchanged alt-az
// mounts of 30 stars, nu = 38, got "refit" in 3 of 30 pairs.)  One term at
// a time, 22 terms at 3 sigma flag one on 6% of unchanged nights, while
// terms this sky confounds (an alt-az run's
// c', d and i, correlated -0.9998) can move together by many sigma with
// none beyond 3 alone (an outside probe: the old model left 14" where a
// refit leaves 0.89", and the report said "everything else stable").
// C_old: the old fit's covariance (OLD a run, or a version-5 model file,
// which keeps it); for a model file that keeps each coefficient's error
// but not their correlations (version 4), its errors
// with the refit's correlations shrunk by a tenth toward none (the same
// terms on a sky like it are correlated alike, but not exactly: with the
// refit's own, an unchanged alt-az mount's pair of nights of 40 stars read
// p = 10^-4.8, the old night's nearly degenerate combination of c', d and
// i lying a little elsewhere; each term's own error says how well the old
// sky held it); none without errors.
void joint_tests(const pm_model &old_model, const std::vector<double> &old_err,
                 const FitOut &f, const FitOut *old_fit, const std::vector<double> *old_cov,
                 Comparison &c)
{
    const int P = old_model.n_terms;
    if (f.cov.size() != (size_t)(P * P) || P < 6)
        return;
    std::vector<double> C = f.cov, d((size_t)P);
    for (int i = 0; i < P; i++)
        d[(size_t)i] = f.model.coef[i] - old_model.coef[i];
    if (old_fit && old_fit->cov.size() == (size_t)(P * P)) {
        for (size_t k = 0; k < C.size(); k++)
            C[k] += old_fit->cov[k];
        c.old_cov = "the old fit's";
        c.old_cov_kind = "run";
    } else if (old_cov && old_cov->size() == (size_t)(P * P)) {
        for (size_t k = 0; k < C.size(); k++)
            C[k] += (*old_cov)[k];
        c.old_cov = "the model file's";
        c.old_cov_kind = "model_file";
    } else if (old_err.size() >= (size_t)P) {
        for (int i = 0; i < P; i++)
            if (!(f.cov[(size_t)(i * P + i)] > 0))
                return;
        const double shrink = 0.1; // (toward independent errors: another sky's correlations)
        for (int i = 0; i < P; i++)
            for (int j = 0; j < P; j++)
                C[(size_t)(i * P + j)] +=
                    old_err[(size_t)i] * old_err[(size_t)j] *
                    (i == j ? 1.0
                            : (1 - shrink) * f.cov[(size_t)(i * P + j)] /
                                  std::sqrt(f.cov[(size_t)(i * P + i)] * f.cov[(size_t)(j * P + j)]));
        c.old_cov = "the model file's errors, correlated as the refit's terms";
        c.old_cov_kind = "errors_only";
        c.old_cov_borrowed = true;
    } else {
        c.old_cov = "none (the model file keeps no errors)";
        return; // (the refit's errors alone: a version-3 file's unchanged mount read as moved)
    }
    std::vector<int> all, rest;
    for (int i = 0; i < P; i++) {
        all.push_back(i);
        if (i != 2 && i != 4) // (c', e')
            rest.push_back(i);
    }
    double nu = (double)(2 * f.res.n_obs - P);
    if (old_fit && old_fit->cov.size() == (size_t)(P * P))
        nu = std::min(nu, (double)(2 * old_fit->res.n_obs - P));
    if (!(nu > 0))
        return;
    const double qa = quad_form(d, C, P, all), qr = quad_form(d, C, P, rest), ln10 = std::log(10.0);
    if (std::isfinite(qa))
        c.joint_log10p = log_f_tail(qa / P, P, nu) / ln10;
    if (std::isfinite(qr))
        c.rest_log10p = log_f_tail(qr / (P - 2), P - 2, nu) / ln10;
}

std::string p_text(double log10p)
{
    return log10p > -3 ? fmt("p = %.2g", std::pow(10.0, log10p)) : fmt("p = 10^%.1f", log10p);
}

// Tonight's refit leaves far more than the old run's fit did: sigma twice
// and beyond chance (F-test, p < 0.1%).  (Beyond the model the two skies
// hold different parts of what it leaves out: an unchanged mount's 20
// stars for 22 terms left 1.14" against 0.61", p = 0.005.)
bool grew(const Comparison &c)
{
    return c.sigma_refit > 2 * c.old_sigma && c.sigma_log10p < -3;
}

std::string advice_of(const Comparison &c)
{
    char b[700];
    const double alpha_log10 = -2; // 1%
    // Guards from the cross-validation, whatever the terms' errors say: the
    // old model predicting the night more than twice worse than a re-zero
    // or a refit does not "still hold" (a model file's borrowed
    // correlations cannot show terms this sky confounds moving as one; an
    // alt-az index moved 10" with a next night of 20 stars, whose refit
    // cross-validates poorly, held in 19 of 60 pairs against the refit
    // alone), and a re-zero more than twice worse than a refit is not
    // advised (it was, 2-5 times worse, in 9 of an outside probe's 4,500
    // comparisons).
    // A refit that cannot be cross-validated (a fold's 4/5 of a small
    // night's points too few for the terms: 13 stars for 22) is not
    // compared: the advice had said "a full refit predicts nan"", and the
    // guard could not act (an outside probe).
    const bool refit_cv = std::isfinite(c.cv_refit);
    const double best_cv = refit_cv ? std::min(c.cv_refit, c.cv_rezero) : c.cv_rezero;
    const std::string refit_s =
        refit_cv ? fmt("%.3g\"", c.cv_refit)
                 : fmt("not available (%ld points, too few in 4/5 of them for %d terms)",
                       c.n_obs, c.n_terms);
    const bool far_worse = c.cv_as_is > 2 * best_cv;
    const bool rezero_far_worse = refit_cv && c.cv_rezero > 2 * c.cv_refit;
    const char *moved = c.old_cov_borrowed ? "differ from the model file's" : "moved";
    if (std::isfinite(c.joint_log10p) && std::isfinite(c.rest_log10p) &&
        !(c.joint_log10p >= alpha_log10 && far_worse)) {
        if (c.joint_log10p >= alpha_log10) {
            std::string single;
            if (!c.moved.empty())
                single = fmt("; %s alone moved %.1f sigma, within what testing %d terms gives by "
                             "chance",
                             c.moved[0].name.c_str(), std::fabs(c.moved[0].z), c.n_terms);
            std::snprintf(b, sizeof b, "the model still holds: its %d terms together have not "
                                       "moved beyond both fits' errors (joint test, %s)%s; "
                                       "cross-validated %.3g\" as is, refitted %s",
                          c.n_terms, p_text(c.joint_log10p).c_str(), single.c_str(), c.cv_as_is,
                          refit_s.c_str());
        } else if (refit_cv && c.cv_refit >= c.cv_as_is) {
            // The terms moved, yet this night's own refit cross-validates no
            // better than the model as is: undecided, and said so.  An
            // outside probe's unchanged alt-az mount (20 stars a night) got
            // "refit" at 8.49" refitted against 1.49" as is, the refit 3
            // times worse against its truth; a second probe's real changes
            // on 20-star nights, told "keep the model" for that, were 3-8
            // times better refitted: 20 stars for 22 terms cannot decide it.
            const std::string meanwhile =
                1.05 * c.cv_rezero < c.cv_as_is
                    ? fmt("; meanwhile a re-zero of the index terms (c' %+.2f\", e' %+.2f\") "
                          "predicts it best",
                          c.rezero_c, c.rezero_e)
                    : std::string();
            // (where the night's sigma grew, the refit does not predict
            // better because what changed is not in the terms, not for
            // want of stars: 30 stars for 7 terms had been told to take
            // more, an outside probe)
            const std::string why =
                grew(c) ? std::string("what changed is not in these terms (below)")
                        : fmt("%ld stars for %d terms do not determine a refit; take more stars "
                              "and compare again",
                              c.n_obs, c.n_terms);
            std::snprintf(b, sizeof b, "undecided: the terms %s (joint test, %s), yet this "
                                       "night's own refit cross-validates no better (%.3g\" "
                                       "refitted, %.3g\" as is, %.3g\" re-zeroed): %s%s",
                          moved, p_text(c.joint_log10p).c_str(), c.cv_refit, c.cv_as_is,
                          c.cv_rezero, why.c_str(), meanwhile.c_str());
        } else if (c.rest_log10p >= alpha_log10 && !rezero_far_worse) {
            std::snprintf(b, sizeof b, "re-zero the index terms (c' %+.2f\", e' %+.2f\"): the "
                                       "terms %s together (joint test, %s), but beyond the "
                                       "indices not (%s); cross-validated %.3g\" re-zeroed, "
                                       "%.3g\" as is, refitted %s",
                          c.rezero_c, c.rezero_e, moved, p_text(c.joint_log10p).c_str(),
                          p_text(c.rest_log10p).c_str(), c.cv_rezero, c.cv_as_is,
                          refit_s.c_str());
        } else if (c.rest_log10p >= alpha_log10) {
            std::snprintf(b, sizeof b, "refit: the terms %s together (joint test, %s), beyond the "
                                       "indices within their errors (%s), but a re-zero of the "
                                       "index terms leaves %.3g\" where a full refit predicts "
                                       "%.3g\" (cross-validated; as is %.3g\")",
                          moved, p_text(c.joint_log10p).c_str(), p_text(c.rest_log10p).c_str(),
                          c.cv_rezero, c.cv_refit, c.cv_as_is);
        } else if (refit_cv) {
            std::snprintf(b, sizeof b, "refit: terms beyond the indices %s (joint test, %s); "
                                       "a re-zero of the index terms leaves %.3g\" where a full "
                                       "refit predicts %.3g\" (cross-validated; as is %.3g\")",
                          moved, p_text(c.rest_log10p).c_str(), c.cv_rezero, c.cv_refit,
                          c.cv_as_is);
        } else {
            std::snprintf(b, sizeof b, "refit: terms beyond the indices %s (joint test, %s); "
                                       "a re-zero of the index terms leaves %.3g\" "
                                       "(cross-validated; as is %.3g\"), a full refit is %s: "
                                       "take more stars before refitting",
                          moved, p_text(c.rest_log10p).c_str(), c.cv_rezero, c.cv_as_is,
                          refit_s.c_str());
        }
        std::string a = b;
        if (c.old_cov_borrowed && c.joint_log10p < alpha_log10)
            a += "; the model file (version 4) keeps its terms' errors but not their "
                 "correlations, taken here from the refit: where the two nights saw different "
                 "parts of the sky that is no change (compare with the old run itself, pmfit "
                 "compare OLD_RUN RUN, whose covariance is known; pmfit fit --save now keeps it "
                 "in the model file)";
        return a;
    }
    std::string pre;
    if (std::isfinite(c.joint_log10p) && far_worse)
        pre = fmt("the terms are within their errors (joint test, %s), yet the old model predicts "
                  "this night far worse than %s (cross-validated %.3g\" against %.3g\")%s: ",
                  p_text(c.joint_log10p).c_str(),
                  !refit_cv || c.cv_rezero < c.cv_refit ? "a re-zero" : "a refit", c.cv_as_is,
                  best_cv,
                  c.old_cov_borrowed ? "; terms this sky confounds can move as one, which a "
                                       "version-4 model file's errors without their "
                                       "correlations cannot show (compare with the old run "
                                       "itself, whose covariance is known)"
                                     : "");
    if (c.moved.empty() && (refit_cv ? c.cv_as_is <= 1.05 * c.cv_refit
                                     : c.cv_as_is <= 1.05 * c.cv_rezero)) {
        std::snprintf(b, sizeof b, "the model still holds: no term moved beyond 3 sigma and it "
                                   "predicts this night as well as %s would (%.3g\" vs %.3g\")",
                      refit_cv ? "a refit" : "a re-zero", c.cv_as_is, best_cv);
    } else if (!refit_cv) {
        std::snprintf(b, sizeof b, "re-zero the index terms (c' %+.2f\", e' %+.2f\"): "
                                   "cross-validated %.3g\" (as is %.3g\"); a full refit is %s",
                      c.rezero_c, c.rezero_e, c.cv_rezero, c.cv_as_is, refit_s.c_str());
    } else if (c.cv_rezero <= 1.05 * c.cv_refit) {
        std::snprintf(b, sizeof b, "re-zero the index terms (c' %+.2f\", e' %+.2f\"): that predicts "
                                   "as well as a full refit (cross-validated %.3g\" vs %.3g\"; as "
                                   "is %.3g\")",
                      c.rezero_c, c.rezero_e, c.cv_rezero, c.cv_refit, c.cv_as_is);
    } else {
        std::snprintf(b, sizeof b, "refit: a re-zero of the index terms leaves %.3g\" where a full "
                                   "refit predicts %.3g\" (cross-validated; as is %.3g\")",
                      c.cv_rezero, c.cv_refit, c.cv_as_is);
    }
    return pre + b;
}

} // namespace

// RMS of the old fit's predicted sigma over a run's points (arcsec).
double predicted_over(const FitOut &f, const Run &run)
{
    double ss = 0;
    long n = 0;
    for (const Obs &o : run.obs) {
        double s = predicted_sigma(f, o.ctx, o.eh, o.ed);
        if (std::isfinite(s))
            ss += s * s, n++;
    }
    return n ? std::sqrt(ss / (double)n) * RAD2AS : NAN;
}

Comparison compare_models(const pm_model &old_in, const std::vector<double> &old_err,
                          const Run &run, const FitOut *old_fit, const Run *old_run,
                          const std::vector<double> *old_cov, double old_stars_sigma)
{
    // The site is the run's: where the run gives a latitude other than the
    // model's (a portable mount moved, or another mount's model), the model
    // is evaluated and refitted there -- its elevation-dependent terms
    // (refraction, flexure) belong to the sky it points at -- and the advice
    // says so.  (An alt-az model reads its elevation from its own axis: no
    // latitude in it.  An old run without a latitude was fitted at 0.)
    pm_model lat_model = old_in;
    std::string site_note;
    const double dlat = run.latitude - old_in.latitude;
    if (old_in.mount != PM_MOUNT_ALTAZ && std::isfinite(run.latitude) &&
        std::fabs(dlat) > 1e-6) { // 0.2"
        lat_model.latitude = run.latitude;
        if (pm_model_prepare(&lat_model) != PM_OK)
            throw std::runtime_error("the model cannot be prepared at the run's latitude");
        char b[400];
        if (old_run && !std::isfinite(old_run->latitude))
            std::snprintf(b, sizeof b,
                          "The old run gives no latitude: compared at the new run's, %+.4f deg. ",
                          run.latitude * 180 / M_PI);
        else
            std::snprintf(b, sizeof b,
                          "The model was fitted at latitude %+.4f deg, the run is at %+.4f deg: "
                          "compared at the run's (a mount moved changes its polar alignment, a "
                          "and b; another site's model is another mount's). ",
                          old_in.latitude * 180 / M_PI, run.latitude * 180 / M_PI);
        site_note = b;
    }
    const pm_model &old_model = lat_model;
    if (old_model.mount != run.mount)
        throw std::runtime_error("the model is of an " +
                                 std::string(old_model.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial") +
                                 " mount, the run of an " +
                                 (run.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial") + " one");
    Comparison c;
    std::vector<int> all(run.obs.size());
    for (size_t i = 0; i < all.size(); i++)
        all[i] = (int)i;
    c.n_obs = (long)all.size();
    c.n_terms = old_model.n_terms;
    c.old_has_errors = !old_err.empty();
    c.rms_as_is = rms_of(old_model, run, all) * RAD2AS;
    FitOut f = do_fit(run.obs, all, old_model);
    if (f.status != PM_OK)
        throw std::runtime_error(
            "the new run cannot be refitted with the model's terms: " +
            (f.status == PM_ERR_SINGULAR && f.bad_term >= 0
                 ? "term " + term_name(old_model, f.bad_term) + " (" +
                       meaning(old_model, f.bad_term) +
                       ") cannot be determined from its points (too little sky for it)"
             : f.status == PM_ERR_TOO_FEW
                 ? std::to_string(all.size()) + " points are too few for " +
                       std::to_string(old_model.n_terms) + " terms"
             : f.status == PM_ERR_NONFINITE
                 ? std::string("the run does not give an input the model's terms read "
                               "(temperature, time, slew direction or a column)")
                 : "the fit does not converge (status " + std::to_string((int)f.status) + ")") +
            "; compare needs a run that determines the model (or a lower --order)");
    // the refit's rotation terms (c', d, e', i) in the old model's turn (the
    // same model): a c' of -179.99 deg against 179.99 deg is a change of
    // 0.02 deg, not of a turn (the fit reduces them into (-pi, pi]; an
    // outside probe read "moved -1295971" (68335 sigma)")
    for (int k = 2; k <= 5; k++)
        f.model.coef[k] = old_model.coef[k] +
                          std::remainder(f.model.coef[k] - old_model.coef[k], 2 * PI);
    if (pm_model_prepare(&f.model) != PM_OK)
        throw std::runtime_error("the refit's model cannot be prepared");
    c.refit = f.model;
    c.sigma_refit = f.res.sigma * RAD2AS;
    for (int i = 0; i < old_model.n_terms; i++) {
        TermChange t;
        t.name = term_name(old_model, i);
        t.meaning = meaning(old_model, i);
        t.old_arcsec = old_model.coef[i] * RAD2AS;
        t.new_arcsec = f.model.coef[i] * RAD2AS;
        double e0 = c.old_has_errors && (size_t)i < old_err.size() ? old_err[(size_t)i] : 0;
        t.err_arcsec = std::sqrt(f.res.err[i] * f.res.err[i] + e0 * e0) * RAD2AS;
        t.z = t.err_arcsec > 0 ? (t.new_arcsec - t.old_arcsec) / t.err_arcsec : 0;
        if (std::fabs(t.z) >= 3)
            c.moved.push_back(t);
        else
            c.n_stable++;
    }
    std::sort(c.moved.begin(), c.moved.end(),
              [](const TermChange &a, const TermChange &b) { return std::fabs(a.z) > std::fabs(b.z); });
    c.rezeroed = old_model;
    double e[2] = {0, 0};
    if (rezero(c.rezeroed, run, all, e)) {
        c.rezero_c = (c.rezeroed.coef[2] - old_model.coef[2]) * RAD2AS;
        c.rezero_e = (c.rezeroed.coef[4] - old_model.coef[4]) * RAD2AS;
        c.rezero_c_err = e[0] * RAD2AS;
        c.rezero_e_err = e[1] * RAD2AS;
        c.rms_rezero = rms_of(c.rezeroed, run, all) * RAD2AS;
    }
    double cv[3];
    cross_validate(old_model, run, cv);
    c.cv_as_is = cv[0] * RAD2AS;
    c.cv_rezero = cv[1] * RAD2AS;
    c.cv_refit = cv[2] * RAD2AS;
    if (old_fit && old_run && old_fit->cov.size() == (size_t)(old_model.n_terms * old_model.n_terms)) {
        c.old_pred_new = predicted_over(*old_fit, run);
        c.old_pred_old = predicted_over(*old_fit, *old_run);
    } else if (old_cov && old_cov->size() == (size_t)(old_model.n_terms * old_model.n_terms) &&
               old_stars_sigma > 0) {
        // a version-5 model file: its covariance at the new stars, and what
        // its fit predicted at its own (it keeps that), as for a run
        FitOut of;
        of.model = old_in; // (at its own latitude, as the run's fit)
        of.cov = *old_cov;
        c.old_pred_new = predicted_over(of, run);
        c.old_pred_old = old_stars_sigma * RAD2AS;
    }
    // Tonight's own refit leaving far more than the old run's fit: what
    // grew is not in these terms, whatever they did (an outside probe's
    // periodic error tripled, the model without it: "the model still
    // holds", sigma 1.80" then, 5.35" now); advice_of says so
    if (old_fit && old_fit->status == PM_OK && old_fit->res.sigma > 0) {
        c.old_sigma = old_fit->res.sigma * RAD2AS;
        const double d1 = 2.0 * (double)f.res.n_obs - f.res.n_par,
                     d2 = 2.0 * (double)old_fit->res.n_obs - old_fit->res.n_par;
        if (d1 > 0 && d2 > 0) {
            const double F = (c.sigma_refit / c.old_sigma) * (c.sigma_refit / c.old_sigma);
            c.sigma_log10p = log_f_tail(F, d1, d2) / std::log(10.0);
        }
    }
    joint_tests(old_model, old_err, f, old_fit, old_cov, c);
    c.advice = advice_of(c);
    if (std::isfinite(c.old_pred_new) && c.old_pred_new > 2 * c.old_pred_old &&
        c.old_pred_new > c.sigma_refit) {
        char b[300];
        std::snprintf(b, sizeof b, "; but the new run is largely where the old model extrapolates "
                                   "(its predicted 1 sigma there %.3g\", at its own stars %.3g\"): "
                                   "much of the difference is the old model's ignorance, not drift",
                      c.old_pred_new, c.old_pred_old);
        c.advice += b;
    }
    if (grew(c))
        c.advice += fmt("; but tonight's own refit leaves sigma %.3g\" where the old run's left "
                        "%.3g\" (F-test, %s): something these %d terms do not hold has grown or "
                        "appeared since (pmfit explain the new run)",
                        c.sigma_refit, c.old_sigma, p_text(c.sigma_log10p).c_str(), c.n_terms);
    if (!site_note.empty() && !c.advice.empty())
        c.advice = site_note + (char)std::toupper((unsigned char)c.advice[0]) + c.advice.substr(1);
    return c;
}

std::string comparison_json(const Comparison &c)
{
    auto num = [](double v) {
        char b[40];
        std::snprintf(b, sizeof b, std::isfinite(v) ? "%.6g" : "null", v);
        return std::string(b);
    };
    std::string j = "{\"n_obs\": " + std::to_string(c.n_obs) + ", \"n_terms\": " +
                    std::to_string(c.n_terms) + ", \"old_errors_counted\": " +
                    (c.old_has_errors ? "true" : "false") + ", \"rms_as_is_arcsec\": " +
                    num(c.rms_as_is) + ", \"sigma_refit_arcsec\": " + num(c.sigma_refit) +
                    ", \"old_sigma_arcsec\": " + num(c.old_sigma) +
                    ", \"sigma_change_log10p\": " + num(c.sigma_log10p) +
                    ", \"moved\": [";
    for (size_t k = 0; k < c.moved.size(); k++) {
        const TermChange &t = c.moved[k];
        j += std::string(k ? ", " : "") + "{\"term\": \"" + json_escape(t.name) +
             "\", \"old_arcsec\": " + num(t.old_arcsec) + ", \"new_arcsec\": " + num(t.new_arcsec) +
             ", \"error_arcsec\": " + num(t.err_arcsec) + ", \"z\": " + num(t.z) + "}";
    }
    j += "], \"n_stable\": " + std::to_string(c.n_stable) + ", \"rezero\": {\"c_arcsec\": " +
         num(c.rezero_c) + ", \"c_error_arcsec\": " + num(c.rezero_c_err) + ", \"e_arcsec\": " +
         num(c.rezero_e) + ", \"e_error_arcsec\": " + num(c.rezero_e_err) +
         ", \"rms_arcsec\": " + num(c.rms_rezero) + "}, \"cv_rms_arcsec\": {\"as_is\": " +
         num(c.cv_as_is) + ", \"rezero\": " +
         num(c.cv_rezero) + ", \"refit\": " + num(c.cv_refit) +
         "}, \"old_covariance\": \"" + c.old_cov_kind + "\", \"joint_log10_p\": " +
         num(c.joint_log10p) + ", \"rest_log10_p\": " +
         num(c.rest_log10p) + ", \"old_predicted_sigma_arcsec\": {\"at_new_points\": " + num(c.old_pred_new) +
         ", \"at_old_points\": " + num(c.old_pred_old) + "}, \"advice\": \"" +
         json_escape(c.advice) + "\", \"notes\": [";
    for (size_t k = 0; k < c.notes.size(); k++)
        j += std::string(k ? ", " : "") + "\"" + json_escape(c.notes[k]) + "\"";
    j += "]}";
    return j;
}

void print_comparison(const Comparison &c, const std::string &old_name, const std::string &run_name)
{
    std::printf("pmfit compare %s %s: %ld observations, %d terms\n\n", old_name.c_str(),
                run_name.c_str(), c.n_obs, c.n_terms);
    for (const std::string &n : c.notes)
        std::printf("  note: %s\n\n", n.c_str());
    std::printf("  the old model on the new run, no refit: RMS %.3f\" per axis (a refit: sigma "
                "%.3f\")\n", c.rms_as_is, c.sigma_refit);
    std::printf("\n  terms that moved (beyond 3 sigma of the %s):\n",
                c.old_has_errors ? "two fits' errors" : "refit's errors; the model file has none");
    if (c.moved.empty())
        std::printf("    none\n");
    for (const TermChange &t : c.moved)
        std::printf("    %-14s %-36s %+10.2f\" -> %+10.2f\": moved %+8.2f\" +- %.2f\" (%.1f sigma)\n",
                    t.name.c_str(), t.meaning.c_str(), t.old_arcsec, t.new_arcsec,
                    t.new_arcsec - t.old_arcsec, t.err_arcsec, std::fabs(t.z));
    const bool together = std::isfinite(c.joint_log10p) && c.joint_log10p < -2;
    if (together)
        std::printf("    the other %d terms each within 3 sigma\n", c.n_stable);
    else
        std::printf("    everything else stable (%d terms)\n", c.n_stable);
    if (std::isfinite(c.joint_log10p))
        std::printf("  all terms together: %s (joint test of their changes, %s; the old "
                    "covariance: %s)%s\n",
                    !together               ? "not moved"
                    : c.old_cov_borrowed ? "differ from the model file's beyond its errors"
                                         : "moved",
                    p_text(c.joint_log10p).c_str(), c.old_cov.c_str(),
                    together && c.moved.empty()
                        ? ": no one term beyond 3 sigma, but together they are; terms this "
                          "sky confounds changed as one"
                        : "");
    std::printf("\n  re-zero (only c' and e' refitted): c' %+.2f\" +- %.2f\", e' %+.2f\" +- "
                "%.2f\"%s\n",
                c.rezero_c, c.rezero_c_err, c.rezero_e, c.rezero_e_err,
                std::isfinite(c.rms_rezero) ? fmt(", RMS per axis %.3f\"", c.rms_rezero).c_str()
                                            : "");
    std::printf("  cross-validated RMS per axis (5-fold): as is %.3f\", re-zero %.3f\", full refit "
                "%s\n",
                c.cv_as_is, c.cv_rezero,
                std::isfinite(c.cv_refit)
                    ? fmt("%.3f\"", c.cv_refit).c_str()
                    : fmt("not available (%ld points, too few in 4/5 of them for %d terms)",
                          c.n_obs, c.n_terms)
                          .c_str());
    if (std::isfinite(c.old_pred_new))
        std::printf("  the old fit's predicted error (1 sigma per axis): %.3f\" at the new run's "
                    "points, %.3f\" at its own\n", c.old_pred_new, c.old_pred_old);
    std::printf("\n  %s\n", c.advice.c_str());
}

OldSide old_from_run(const Run &run, int order, const std::vector<std::string> &adds,
                     int max_passes)
{
    OldSide o;
    o.is_run = true;
    o.run = run;
    std::vector<int> all(o.run.obs.size());
    for (size_t i = 0; i < all.size(); i++)
        all[i] = (int)i;
    o.fit = do_fit(o.run.obs, all,
                   build_model(order, adds, o.run.obs, o.run.mount, o.run.latitude,
                               o.run.aux_names),
                   max_passes);
    if (o.fit.status == PM_OK) {
        o.model = o.fit.model;
        o.err.assign(o.fit.res.err, o.fit.res.err + o.fit.model.n_terms);
    }
    o.inputs = o.run.aux_names;
    return o;
}

OldSide old_from_model(const pm_model &m, const pmmodel_info &info, const std::vector<double> &cov)
{
    OldSide o;
    o.model = m;
    o.inputs = model_inputs(info);
    o.pier = info.pier;
    if (info.has_err) { /* the fit's errors the file keeps count as a run's do */
        o.err.assign(info.err, info.err + m.n_terms);
        if (cov.size() == (size_t)m.n_terms * (size_t)m.n_terms) {
            o.cov = cov; /* and its covariance (version 5) */
            o.stars_sigma = info.stars_sigma;
        }
    }
    return o;
}

OldSide load_old(const std::string &path, int order, const std::vector<std::string> &adds,
                 const ReadOptions &ro, int max_passes)
{
    OldSide o;
    char err[1024];
    int kind = is_model_file(path, err, sizeof err);
    if (kind < 0)
        throw std::runtime_error(err);
    if (kind == 1) {
        pmmodel_info info;
        std::vector<double> cov((size_t)PM_MAX_TERMS * PM_MAX_TERMS);
        int has_cov = 0;
        if (pmmodel_load_cov(path.c_str(), &o.model, &info, cov.data(), cov.size(), &has_cov, err,
                             sizeof err) != 0)
            throw std::runtime_error(err);
        cov.resize(has_cov ? (size_t)o.model.n_terms * (size_t)o.model.n_terms : 0);
        return old_from_model(o.model, info, cov);
    }
    return old_from_run(load_run(path, ro), order, adds,
                        max_passes);
}

Comparison compare_old(const OldSide &os, const Run &run, const std::string &old_name)
{
    std::vector<std::string> notes;
    Run r = run_for_model(run, os.model, os.inputs, os.pier, old_name, &notes);
    Comparison c = compare_models(os.model, os.err, r, os.is_run ? &os.fit : nullptr,
                                  os.is_run ? &os.run : nullptr, os.cov.empty() ? nullptr : &os.cov,
                                  os.stars_sigma);
    c.notes = notes;
    return c;
}

} // namespace pmhost
