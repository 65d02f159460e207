// explain_report.cpp - stage "report" of pmfit explain: the explanation as
// one JSON object (keys in docs/formats.md, "pmfit explain --json") or as
// text.
#include "explain_internal.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pmhost {

namespace {

std::string num(double v)
{
    char b[40];
    std::snprintf(b, sizeof b, std::isfinite(v) ? "%.6g" : "null", v);
    return b;
}

std::string str(const std::string &s) { return "\"" + json_escape(s) + "\""; }

std::string alternatives_json(const std::vector<Alternative> &alts)
{
    std::string j = "[";
    for (size_t k = 0; k < alts.size(); k++) {
        const Alternative &a = alts[k];
        j += std::string(k ? ", " : "") + "{\"effect\": " + str(a.effect) +
             ", \"log10_false_alarm_probability\": " + num(a.log10_fap) +
             ", \"delta_bic\": " + num(a.delta_bic) + ", \"log10_likelihood_ratio\": " +
             num(a.log10_lr) + ", \"kind\": " +
             str(a.smooth ? "smooth" : a.final_model ? "final" : "close") +
             ", \"separate_by\": " + str(a.separate_by);
        j += "}";
    }
    return j + "]";
}

std::string finding_json(const Finding &f, int mount)
{
    // (label: the effect as the text names it, az_periodic and el_periodic
    // on an alt-az mount; effect: the name of either mount's axis 1 and 2)
    std::string j = "{\"effect\": " + str(f.effect) + ", \"label\": " +
                    str(mount_words(f.effect, mount));
    if (f.effect == "ha_periodic" || f.effect == "dec_periodic") {
        std::string aliases;
        for (double a : f.aliases)
            aliases += (aliases.empty() ? "" : ", ") + num(a);
        j += ", \"cycles_per_rev\": " + num(f.cycles_per_rev) + ", \"cycles_per_rev_range\": [" +
             num(f.cycles_lo) + ", " + num(f.cycles_hi) + "], \"cycles_per_rev_aliases\": [" +
             aliases + "], \"axis_sampled_deg\": " + num(f.sampled_deg) +
             ", \"phase_deg\": " + num(f.phase_deg);
    }
    j += ", \"amplitude_arcsec\": " + num(f.amplitude_arcsec) +
         ", \"amplitude_error_arcsec\": " +
         (f.amplitude_err_arcsec > 0 ? num(f.amplitude_err_arcsec) : std::string("null")) +
         ", \"false_alarm_probability\": " + num(f.false_alarm_probability) +
         ", \"log10_false_alarm_probability\": " + num(f.log10_p) +
         ", \"sigma_after_arcsec\": " + num(f.sigma_after_arcsec) +
         ", \"cv_rms_after_arcsec\": " + num(f.cv_rms_after_arcsec) +
         ", \"n_params_after\": " + std::to_string(f.n_params_after) + ", \"terms\": [";
    for (size_t k = 0; k < f.adds.size(); k++)
        j += std::string(k ? ", " : "") + str(f.adds[k]);
    j += "], \"coefficients\": [";
    for (size_t k = 0; k < f.coefficients.size(); k++)
        j += std::string(k ? ", " : "") + "{\"name\": " + str(f.coefficients[k].name) +
             (f.coefficients[k].column.empty() ? std::string()
                                               : ", \"column\": " + str(f.coefficients[k].column)) +
             ", \"value_arcsec\": " + num(f.coefficients[k].value_arcsec) +
             ", \"error_arcsec\": " + num(f.coefficients[k].error_arcsec) + "}";
    j += "]";
    if (!f.lines.empty()) {
        j += ", \"lines\": [" + joined(f.lines) + "]";
    }
    j += ", \"step\": " + std::to_string(f.step);
    if (!f.with.empty())
        j += ", \"with\": " + str(f.with);
    j += ", \"alternatives\": " + alternatives_json(f.alternatives);
    if (!f.beside.effect.empty())
        j += ", \"beside\": {\"effect\": " + str(f.beside.effect) + ", \"value_arcsec\": " +
             num(f.beside.value) + ", \"error_arcsec\": " + num(f.beside.error) +
             ", \"other_value_arcsec\": " + num(f.beside.other_value) +
             ", \"other_error_arcsec\": " + num(f.beside.other_error) + "}";
    return j + ", \"text\": " + str(f.text) + ", \"where\": " + str(f.where) + "}";
}

std::string interpretation_json(const Explanation &ex)
{
    std::string j = "[";
    for (size_t k = 0; k < ex.interpretation.size(); k++) {
        const Interpretation &it = ex.interpretation[k];
        j += std::string(k ? ", " : "") + "{\"what\": " + str(it.what) + ", \"value\": " +
             num(it.value) + ", \"error\": " + num(it.error) + ", \"unit\": " + str(it.unit) +
             ", \"text\": " + str(it.text) + "}";
    }
    return j + "]";
}

// The file lines of the points left out of the cross-validation, "1, 2".
std::string left_out_lines(const Run &run, const Explanation &ex)
{
    std::vector<int> lines;
    for (int i : ex.cv_left_out)
        lines.push_back(run.obs[i].line);
    return joined(lines);
}

} // namespace

std::vector<std::pair<std::string, std::string>> not_tried_why(const Run &run)
{
    std::vector<std::pair<std::string, std::string>> out;
    // (physical_candidates: the elevation of an equatorial run needs its
    // latitude)
    if (run.mount == PM_MOUNT_EQUATORIAL && std::isnan(run.latitude)) {
        out.push_back({"refraction", "the run gives no latitude"});
        out.push_back({"tube_flexure", "the run gives no latitude"});
    }
    const std::vector<int> all = all_of(run.obs.size());
    // temperature and time (physical_candidates' input_usable), said where
    // the run cannot give them (an outside probe: the MMT run's JSON listed
    // nothing not tried, and it has neither)
    static const char *const input[2][3] = {{"temperature", "temperature", "0.2 deg C"},
                                            {"time_drift", "time", "3 minutes"}};
    for (int w = 0; w < 2; w++) {
        if (xdetail::input_usable(run, all, w))
            continue;
        size_t known = 0;
        for (const Obs &o : run.obs)
            known += std::isfinite(w == 0 ? o.ctx.temp_c : o.ctx.time_h);
        const std::string what = input[w][1];
        out.push_back({input[w][0], known == 0 ? "the run gives no " + what + "s"
                                    : known < run.obs.size()
                                        ? "the run gives the " + what + " of only " +
                                              std::to_string(known) + " of its " +
                                              std::to_string(run.obs.size()) + " points"
                                        : "its " + what + "s span less than " + input[w][2]});
    }
    // the run's own columns that cannot be candidates (an outside probe: a
    // column's effect was not looked for, and nothing said so)
    for (size_t j = 0; j < run.aux_names.size(); j++) {
        const std::string &name = run.aux_names[j];
        if ((name == axis2_dir_name(run.mount) && run.dec_dir_derived) ||
            (name == "az_turn" && run.turn_derived) || (name == "az_wind" && run.wind_derived))
            continue;
        const std::string why = j >= (size_t)PM_MAX_AUX
                                    ? "beyond the first " + std::to_string(PM_MAX_AUX) +
                                          " columns, which are all a fit can read (put it "
                                          "among them)"
                                    : xdetail::column_unusable(run, all, j);
        if (!why.empty())
            out.push_back({"aux:" + name, why});
    }
    return out;
}

std::vector<std::string> not_tried(const Run &run)
{
    std::vector<std::string> names;
    for (const auto &w : not_tried_why(run))
        names.push_back(w.first);
    return names;
}

std::string explain_json(const Run &run, const Explanation &ex, int order)
{
    std::string j = "\"baseline\": {\"order\": " + std::to_string(order) +
                    ", \"sigma_arcsec\": " + num(ex.base_sigma_arcsec) +
                    ", \"cv_rms_arcsec\": " + num(ex.base_cv_rms_arcsec) +
                    ", \"n_params\": " + std::to_string(ex.base_n_params) +
                    ", \"composition_rms_arcsec\": " + num(ex.compose_rms_arcsec) +
                    ", \"cv_left_out_lines\": [" + left_out_lines(run, ex) + "]}, \"mount\": " +
                    str(run.mount == PM_MOUNT_ALTAZ ? "altaz" : "equatorial") +
                    ", \"interpretation\": " + interpretation_json(ex) + ", \"physical_reading\": " +
                    (ex.physical_reading.empty() ? "null" : str(ex.physical_reading)) +
                    ", \"folded_pier\": " + (ex.folded_pier.empty() ? "null" : str(ex.folded_pier)) +
                    ", \"located\": [";
    for (size_t i = 0; i < ex.located.size() && i < 8; i++)
        j += std::string(i ? ", " : "") + "{\"what\": " + str(ex.located[i].what) + ", \"value\": " +
             num(ex.located[i].rms_arcsec) + ", \"ratio\": " + num(ex.located[i].ratio) +
             ", \"p\": " + num(ex.located[i].p) + "}";
    j += "], \"periodograms\": [";
    for (size_t i = 0; i < ex.periodograms.size(); i++)
        j += std::string(i ? ", " : "") + "{\"axis\": " + str(ex.periodograms[i].axis) +
             ", \"peak_cycles_per_rev\": " + num(ex.periodograms[i].peak_g) +
             ", \"peak_power\": " + num(ex.periodograms[i].peak_power) +
             ", \"threshold\": " + num(ex.periodograms[i].threshold) + "}";
    j += "], \"findings\": [";
    for (size_t i = 0; i < ex.findings.size(); i++)
        j += std::string(i ? ", " : "") + finding_json(ex.findings[i], run.mount);
    j += "], \"withdrawn\": [";
    for (size_t i = 0; i < ex.withdrawn.size(); i++)
        j += std::string(i ? ", " : "") + "{\"effect\": " + str(ex.withdrawn[i].effect) +
             ", \"step\": " + std::to_string(ex.withdrawn[i].step) + ", \"why\": " +
             str(ex.withdrawn_why[i]) + "}";
    j += "], \"unmodelled\": [";
    for (size_t i = 0; i < ex.unmodelled.size(); i++) {
        const Unmodelled &u = ex.unmodelled[i];
        j += std::string(i ? ", " : "") + "{\"effect\": " + str(u.effect) +
             ", \"cycles_per_rev\": " + num(u.cycles_per_rev) + ", \"log10_fap\": " +
             num(u.log10_fap) + ", \"sigma_arcsec\": " + num(u.sigma_arcsec) +
             ", \"cv_rms_arcsec\": " + num(u.cv_rms_arcsec) + ", \"n_params\": " +
             std::to_string(u.n_params) + ", \"sigma_before_arcsec\": " +
             num(u.sigma_before_arcsec) + ", \"cv_before_arcsec\": " +
             num(u.cv_before_arcsec) + "}";
    }
    j += "], \"not_converged\": [";
    for (size_t i = 0; i < ex.unfitted.size(); i++)
        j += std::string(i ? ", " : "") + "{\"effect\": " + str(ex.unfitted[i].effect) +
             ", \"step\": " + std::to_string(ex.unfitted[i].step) + ", \"order\": " +
             std::to_string(ex.unfitted[i].order) + "}";
    j += "], \"not_separable\": [";
    for (size_t i = 0; i < ex.blurred.size(); i++) {
        const Explanation::Blurred &b = ex.blurred[i];
        j += std::string(i ? ", " : "") + "{\"effect\": " + str(b.effect) + ", \"step\": " +
             std::to_string(b.step) + ", \"order\": " + std::to_string(b.order) +
             ", \"error_arcsec\": " + num(b.error_arcsec) + ", \"error_order1_arcsec\": " +
             num(b.error_order1_arcsec) + "}";
    }
    j += "], \"not_tried\": [";
    const auto nt = not_tried_why(run);
    for (size_t i = 0; i < nt.size(); i++)
        j += std::string(i ? ", " : "") + "{\"effect\": " + str(nt[i].first) +
             ", \"why\": " + str(nt[i].second) + "}";
    return j + "], \"final\": {\"sigma_arcsec\": " + num(ex.final_sigma_arcsec) +
           ", \"cv_rms_arcsec\": " + num(ex.final_cv_rms_arcsec) +
           ", \"n_params\": " + std::to_string(ex.final_n_params) + "}";
}

namespace {

void print_located(const Explanation &ex, double alpha, bool gears_ha, bool gears_dec, bool altaz)
{
    std::printf("\nwhere the baseline residuals are too large (p: chance of so much, uncorrected):\n");
    int shown = 0;
    for (const Located &l : ex.located) {
        if (shown >= 6 || l.p > 0.05)
            break;
        if (l.what.find(" vs ") != std::string::npos)
            std::printf("  %-44s correlation %+.2f (|t| = %.1f), p = %.2g\n", l.what.c_str(),
                        l.rms_arcsec, l.ratio, l.p);
        else
            std::printf("  %-44s RMS %.2f\" (%.2f x typical), p = %.2g\n", l.what.c_str(),
                        l.rms_arcsec, l.ratio, l.p);
        shown++;
    }
    if (!shown)
        std::printf("  nowhere in particular (no group or variable at p < 0.05)\n");
    for (const Periodogram &pg : ex.periodograms)
        std::printf("  periodogram of the %s axis: highest peak at G = %.6g cycles/rev%s, power "
                    "%.1f (false-alarm %g level: %.1f)\n",
                    pg.axis == "ha" ? (altaz ? "azimuth" : "hour-angle") : (altaz ? "elevation" : "declination"),
                    pg.peak_g,
                    (pg.axis == "ha" ? gears_ha : gears_dec) ? " of the --gear periods" : "",
                    pg.peak_power, alpha, pg.threshold);
}

// A cross-validated RMS for the text: NaN where the model cannot be
// fitted without some point (loo_rms, cv_rms; null in the JSON).
std::string cv_text(double x)
{
    return std::isfinite(x) ? fmt("%.3f\"", x)
                            : std::string("not available (the model cannot be fitted without "
                                          "some point: alone it fixes a term)");
}

std::string cv_cell(double x)
{
    return std::isfinite(x) ? fmt("%10.3f", x) : fmt("%10s", "n/a");
}

void print_findings(const Explanation &ex, double alpha, int mount)
{
    // an alt-az mount's periodic effects by its axes' names (mount_words)
    auto W = [mount](const std::string &x) { return mount_words(x, mount); };
    std::printf("\nfindings:\n");
    if (ex.findings.empty() && ex.unmodelled.empty() && ex.blurred.empty() && ex.unfitted.empty())
        std::printf("  none: nothing significant is left out (false-alarm probability below %g "
                    "and a better cross-validated RMS were required)\n",
                    alpha);
    else if (ex.findings.empty())
        std::printf("  none named (false-alarm probability below %g and a "
                    "better cross-validated RMS were required); but see below\n",
                    alpha);
    for (size_t i = 0; i < ex.findings.size(); i++) {
        const Finding &f = ex.findings[i];
        std::printf("  %zu. %s: %s\n", i + 1, W(f.effect).c_str(), W(f.text).c_str());
        if (!f.with.empty())
            std::printf("     found together with %s: neither alone passed, the pair does\n",
                        W(f.with).c_str());
        // the sizes above are the final model's, these the step's (docs/explain.md step 5)
        std::printf("     where: %s\n     step %d: false-alarm probability %.2g (10^%.1f); with "
                    "it sigma %.3f\", CV RMS %s, P = %d\n",
                    W(f.where).c_str(), f.step, f.false_alarm_probability, f.log10_p,
                    f.sigma_after_arcsec, cv_text(f.cv_rms_after_arcsec).c_str(), f.n_params_after);
        for (const Alternative &a : f.alternatives) {
            if (a.smooth)
                std::printf("     or a smooth shape: %s (false-alarm 10^%.1f) holds all that the "
                            "periodic term explains, so this run cannot tell a periodic error "
                            "from a smooth distortion (Delta BIC %+.1f prefers %s for its fewer "
                            "terms); to separate them: %s\n",
                            W(a.effect).c_str(), a.log10_fap, a.delta_bic, W(f.effect).c_str(),
                            W(a.separate_by).c_str());
            else if (a.final_model) // (a better one where the evidence is clear for it)
                std::printf("     %s reading in the final model: %s (false-alarm 10^%.1f "
                            "there, Delta BIC %+.1f with as many terms, likelihood ratio 10^%.2f "
                            "in favour of %s; the step that found %s had the later findings "
                            "still in its residuals); to separate them: %s\n",
                            a.delta_bic <= -6 ? "a better" : "as good a", W(a.effect).c_str(),
                            a.log10_fap, a.delta_bic, std::fabs(a.log10_lr),
                            a.log10_lr >= 0 ? W(f.effect).c_str() : W(a.effect).c_str(),
                            W(f.effect).c_str(), W(a.separate_by).c_str());
            else // (the finding won by its false-alarm probability, which counts the
                 // periods and candidates tried; where BIC clearly prefers the other,
                 // "as good" overstated it: an outside probe's 10^3.53 in its favour)
                std::printf("     %s reading: %s (false-alarm 10^%.1f, Delta BIC %+.1f%s, "
                            "likelihood ratio 10^%.2f in favour of %s); to separate them: %s\n",
                            a.delta_bic <= -6 ? "a better-fitting" : "as good a",
                            W(a.effect).c_str(), a.log10_fap, a.delta_bic,
                            a.delta_bic < 0 ? ": BIC, which does not count the periods or "
                                              "candidates tried, prefers it" : "",
                            std::fabs(a.log10_lr),
                            a.log10_lr >= 0 ? W(f.effect).c_str() : W(a.effect).c_str(),
                            W(a.separate_by).c_str());
        }
        if (!f.beside.effect.empty())
            std::printf("     %s\n", W(beside_text(f)).c_str());
    }
    for (size_t i = 0; i < ex.withdrawn.size(); i++)
        std::printf("  withdrawn: %s; the findings above are those of the search without it\n",
                    W(ex.withdrawn_why[i]).c_str());
    for (const Unmodelled &u : ex.unmodelled)
        std::printf("  significant, not modelled: %s\n", W(unmodelled_text(u)).c_str());
    for (const Explanation::Blurred &b : ex.blurred)
        std::printf("  significant, not named: %s\n", W(blurred_text(b)).c_str());
    for (const Explanation::Unfitted &u : ex.unfitted)
        std::printf("  not judged: %s\n", W(unfitted_text(u)).c_str());
}

} // namespace

std::string unfitted_text(const Explanation::Unfitted &u)
{
    return fmt("%s%s at step %d: its fit did not converge, so the step chose without it (a "
               "reading of this run may change where it does)",
               u.effect.c_str(),
               u.effect == "higher_order" ? fmt(" (order %d)", u.order).c_str() : "", u.step);
}

std::string blurred_text(const Explanation::Blurred &b)
{
    return fmt("%s at step %d: its value is not determined beside the order-%d terms (1 sigma "
               "%.4g\" there, %.4g\" beside order 1's): on this sky those terms hold nearly its "
               "shape, so its fitted size is a balance between them, not a measurement",
               b.effect.c_str(), b.step, b.order, b.error_arcsec, b.error_order1_arcsec);
}

std::string beside_text(const Finding &f)
{
    const Finding::Beside &b = f.beside;
    if (b.effect.empty())
        return "";
    const bool one = std::fabs(b.value) >= 3 * b.error, other = std::fabs(b.other_value) >= 3 * b.other_error;
    // how far the size moves with the other beside it, in the step's own
    // error of it: "the other is not measured" had been said where the size
    // moved by 3-6 of its sigmas (an outside probe's 15 stars: refraction
    // -8.21" +- 1.19" alone, -15.09" +- 3.01" beside the sag; truth -18.3")
    const double moved = b.alone_error > 0 ? std::fabs(b.value - b.alone) / b.alone_error : 0;
    std::string what;
    if (!one && !other)
        what = "each within 3 sigma of zero beside the other, so this run cannot tell the two "
               "apart, and the size above is one reading's";
    else if (other)
        what = "both are measured, and the size above holds part of the other";
    else if (moved > 3)
        what = fmt("the other is not measured, but beside it the size moves by %.1f of its own "
                   "sigmas: the size above holds whatever of the other the run has",
                   moved);
    else if (b.close)
        what = "this run hardly tells the two apart, and the size above is one reading's";
    else
        what = "the other is not measured, and the size holds beside it";
    return fmt("with %s beside it (at its step): %s %.2f\" +- %.2f\", %s %.2f\" +- %.2f\": %s",
               b.effect.c_str(), f.effect.c_str(), b.value, b.error, b.effect.c_str(), b.other_value,
               b.other_error, what.c_str());
}

std::string unmodelled_text(const Unmodelled &u)
{
    const std::string g = u.cycles_per_rev > 0 ? fmt(" (%g cycles/rev)", u.cycles_per_rev) : "";
    return fmt("%s%s (false-alarm 10^%.1f): with it sigma %.3f\" against %.3f\", but its model "
               "of %d terms predicts no better (CV RMS %.3f\" against %.3f\"): the residuals "
               "hold it, the run's %d points cannot fit it usefully; more points, spread over "
               "the sky, would",
               u.effect.c_str(), g.c_str(), u.log10_fap, u.sigma_arcsec, u.sigma_before_arcsec,
               u.n_params, u.cv_rms_arcsec, u.cv_before_arcsec, u.n_obs);
}

void print_explain_text(const Run &run, const Explanation &ex, int order, bool added,
                        double alpha, bool gears_ha, bool gears_dec)
{
    std::printf("baseline: order %d%s, P = %d, unbiased sigma %.3f\", cross-validated RMS %s\n",
                order, added ? " + added terms" : "", ex.base_n_params, ex.base_sigma_arcsec,
                cv_text(ex.base_cv_rms_arcsec).c_str());
    if (!ex.cv_left_out.empty()) {
        const std::string lines = left_out_lines(run, ex);
        std::printf("  cross-validated without line%s %s: the others cannot predict %s (%s "
                    "alone or nearly alone fixes a combination of the terms)\n",
                    ex.cv_left_out.size() > 1 ? "s" : "", lines.c_str(),
                    ex.cv_left_out.size() > 1 ? "them" : "it",
                    ex.cv_left_out.size() > 1 ? "each" : "it");
    }
    if (ex.compose_rms_arcsec >= 0.01)
        std::printf("  its anisotropic terms composed as the mount's gimbal composes them: "
                    "%.3f\" RMS of second order, taken out of the observed positions\n",
                    ex.compose_rms_arcsec);
    if (!ex.interpretation.empty()) {
        std::printf("\nwhat the baseline holds (its physical reading):\n");
        for (const Interpretation &it : ex.interpretation)
            std::printf("  %s\n", it.text.c_str());
        if (!ex.physical_reading.empty())
            std::printf("  %s\n", ex.physical_reading.c_str());
    }
    if (!ex.folded_pier.empty())
        std::printf("\n  warning: %s\n", ex.folded_pier.c_str());
    print_located(ex, alpha, gears_ha, gears_dec, run.mount == PM_MOUNT_ALTAZ);
    print_findings(ex, alpha, run.mount);
    std::printf("\n  %-22s %5s %10s %10s\n", "step", "P", "sigma(\")", "CV RMS(\")");
    std::printf("  %-22s %5d %10.3f %s\n", "baseline", ex.base_n_params, ex.base_sigma_arcsec,
                cv_cell(ex.base_cv_rms_arcsec).c_str());
    for (const Finding &f : ex.findings)
        std::printf("  %-22s %5d %10.3f %s\n", ("+ " + mount_words(f.effect, run.mount)).c_str(),
                    f.n_params_after,
                    f.sigma_after_arcsec, cv_cell(f.cv_rms_after_arcsec).c_str());
    const auto nt = not_tried_why(run);
    for (size_t k = 0; k < nt.size(); k++) {
        if (nt[k].first == "tube_flexure")
            continue; // (said with refraction)
        if (nt[k].first == "refraction")
            std::printf("%s  not tried: refraction and tube flexure, which depend on the "
                        "elevation: the run gives no\n  latitude (add a line '# latitude: DEG' "
                        "to a column file)\n",
                        k ? "" : "\n");
        else
            std::printf("%s  not tried: %s: %s\n", k ? "" : "\n", nt[k].first.c_str(),
                        nt[k].second.c_str());
    }
    std::printf("\n  pmfit fit %s --order %d", shell_word(run.path).c_str(), ex.final_order);
    for (const std::string &a : ex.final_adds)
        std::printf(" --add %s", add_word(mount_words(a, run.mount)).c_str());
    std::printf("%s", run.read_options.c_str()); /* (as it was read: --equinox, ...) */
    std::vector<int> bad;
    for (const Finding &f : ex.findings)
        if (f.effect == "outlier")
            bad.insert(bad.end(), f.lines.begin(), f.lines.end());
    if (bad.empty()) {
        std::printf("   # fits the explained model\n");
    } else {
        std::string l;
        for (int x : bad)
            l += (l.empty() ? "" : ", ") + std::to_string(x);
        std::printf("   # fits the explained model once line%s %s %s left out (or add --robust)\n",
                    bad.size() > 1 ? "s" : "", l.c_str(), bad.size() > 1 ? "are" : "is");
    }
}

} // namespace pmhost
