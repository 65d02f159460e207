// report.cpp - one self-contained HTML page of a pointing run (report.hpp).
//
// The page is built section by section into a string: tables in HTML, figures
// as inline SVG from pmplot (plots.hpp, rendered into strings), captions that
// say what is drawn and in which units.  No script, no external resource.
#include "report.hpp"
#include "compare.hpp"
#include "errormap.hpp"
#include "explain.hpp"
#include "explain_internal.hpp"
#include "modelfile.h"
#include "plan.hpp"
#include "plan_inputs.hpp"
#include "hostutil.hpp"
#include "plots.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace pmhost {

namespace {

const double DEG = PI / 180;

// HTML-escape text (hostutil's xml_escape; the page builds with a short name).
std::string (&h)(const std::string &) = xml_escape;

// A number for a table cell; an en dash where it is not finite.
std::string num(double v, int decimals)
{
    return std::isfinite(v) ? fmt("%.*f", decimals, v) : std::string("\xe2\x80\x93");
}

double wrap360(double deg)
{
    double x = std::fmod(deg, 360.0);
    return x < 0 ? x + 360 : x;
}

// Where an observation is on the sky, in both frames (apparent; degrees,
// hour angle in hours); NaN where the run gives no latitude to convert.
struct Where {
    double ha_h = NAN, dec = NAN, az = NAN, el = NAN;
};

// Between (ha, dec) and (az, el), azimuth from north through east: the same
// formula both ways.
void convert(double lat, double a, double b, double *a2, double *b2)
{
    *b2 = std::asin(std::sin(lat) * std::sin(b) + std::cos(lat) * std::cos(b) * std::cos(a));
    *a2 = std::atan2(-std::cos(b) * std::sin(a),
                     std::sin(b) * std::cos(lat) - std::cos(b) * std::cos(a) * std::sin(lat));
}

Where where_of(const Run &run, const Obs &o)
{
    Where w;
    double x, y;
    bool lat = std::isfinite(run.latitude);
    if (run.mount == PM_MOUNT_ALTAZ) {
        w.az = wrap360(o.ah / DEG);
        w.el = o.ad / DEG;
        if (lat)
            convert(run.latitude, o.ah, o.ad, &x, &y), w.ha_h = x / DEG / 15, w.dec = y / DEG;
    } else {
        w.ha_h = std::remainder(o.ah, 2 * PI) / DEG / 15;
        w.dec = o.ad / DEG;
        if (lat)
            convert(run.latitude, o.ah, o.ad, &x, &y), w.az = wrap360(x / DEG), w.el = y / DEG;
    }
    return w;
}

// The page under construction: the body, the figure and table counts, the
// sections for the contents list.
struct Page {
    std::string body;
    int figures = 0, tables = 0;
    std::vector<std::pair<std::string, std::string>> toc; // id, title
};

void section(Page &p, const std::string &id, const std::string &title)
{
    p.toc.push_back({id, title});
    p.body += "\n<section id=\"" + id + "\">\n<h2>" + h(title) + "</h2>\n";
}

void end_section(Page &p) { p.body += "</section>\n"; }

void para(Page &p, const std::string &html) { p.body += "<p>" + html + "</p>\n"; }

// An SVG document as an inline element: no XML declaration, no namespace
// attribute (the HTML parser puts <svg> in its namespace), ids made unique
// in the page (several figures have a "clip0"), role="img" for readers.
std::string inline_svg(std::string s, int fig)
{
    if (s.compare(0, 5, "<?xml") == 0)
        s.erase(0, s.find('\n') + 1);
    auto replace_all = [&](const std::string &a, const std::string &b) {
        for (size_t k = s.find(a); k != std::string::npos; k = s.find(a, k + b.size()))
            s.replace(k, a.size(), b);
    };
    replace_all(" xmlns=\"http://www.w3.org/2000/svg\"", "");
    replace_all("id=\"clip", fmt("id=\"f%d-clip", fig));
    replace_all("url(#clip", fmt("url(#f%d-clip", fig));
    replace_all("<svg ", "<svg role=\"img\" ");
    return s;
}

// A figure: the plot (rendered by `draw` into a string) and its caption.
void figure(Page &p, const std::string &caption_html,
            const std::function<int(const pmplot::Out &, std::string *)> &draw)
{
    std::string svg, err;
    p.figures++;
    if (draw(pmplot::Out(&svg, fmt("figure %d", p.figures)), &err) != 0)
        throw std::runtime_error("report: " + err);
    p.body += fmt("<figure id=\"fig%d\">\n", p.figures) + inline_svg(svg, p.figures) +
              fmt("<figcaption><b>Figure %d.</b> ", p.figures) + caption_html +
              "</figcaption>\n</figure>\n";
}

// A table: caption, header cells (units in them), rows of cells (HTML).
void table(Page &p, const std::string &caption, const std::vector<std::string> &head,
           const std::vector<std::vector<std::string>> &rows, const std::string &cls = "")
{
    p.tables++;
    p.body += "<table" + (cls.empty() ? std::string() : " class=\"" + cls + "\"") +
              fmt(">\n<caption><b>Table %d.</b> ", p.tables) + caption + "</caption>\n<thead><tr>";
    for (const std::string &c : head)
        p.body += "<th scope=\"col\">" + c + "</th>";
    p.body += "</tr></thead>\n<tbody>\n";
    auto is_number = [](const std::string &c) { // after any leading tags
        size_t k = 0;
        while (k < c.size() && c[k] == '<')
            k = c.find('>', k) == std::string::npos ? c.size() : c.find('>', k) + 1;
        return k < c.size() && (std::strchr("0123456789+-.", c[k]) || c.compare(k, 3, "\xe2\x80\x93") == 0);
    };
    for (const auto &r : rows) {
        p.body += "<tr>";
        for (const std::string &c : r)
            p.body += (is_number(c) ? "<td>" : "<td class=\"t\">") + c + "</td>";
        p.body += "</tr>\n";
    }
    p.body += "</tbody>\n</table>\n";
}

// Everything the sections show, computed stage by stage.
struct Data {
    const Run &run;
    const ReportOptions &o;
    bool altaz;
    std::vector<int> all;
    FitOut fit;
    ErrorMap emap;
    Explanation ex;
    std::string explain_note; // explained at order 0 instead, and why (stage_explain)
    Plan plan;
    PlanOptions plan_opt;
    std::string plan_error;
    bool have_cmp = false;
    Comparison cmp;
    std::string old_what; // "the model file X" or "the run X (fitted at order L)"
    Data(const Run &r, const ReportOptions &opt)
        : run(r), o(opt), altaz(r.mount == PM_MOUNT_ALTAZ) {}
    std::string xlabel() const { return altaz ? "azimuth (deg)" : "hour angle (deg)"; }
    std::string ylabel() const { return altaz ? "elevation (deg)" : "declination (deg)"; }
    std::vector<std::string> groups() const
    {
        return altaz ? std::vector<std::string>{"alt-az"}
                     : std::vector<std::string>{"pier east (normal)", "pier west (beyond the pole)"};
    }
};

// " --add 'E'" for each of the page's --add effects.
std::string plan_adds(const std::vector<std::string> &adds)
{
    std::string o;
    for (const std::string &a : adds)
        o += " --add " + add_word(a);
    return o;
}

// The fit's failure in the words pmfit fit uses.
[[noreturn]] void fit_failed(const FitOut &f, const std::string &what, int passes)
{
    throw std::runtime_error(what + ": " + pm_status_text(f.status) +
                             fit_failure_detail(f, passes, "--order"));
}


// ------------------------------------------------------------ the stages

// The map is the fitted model's own uncertainty: where explain finds physics
// the model leaves out, the pointing between the stars errs by about the
// misfit, not by the map (an outside probe: 5" of tube flexure fitted at
// order 0, 300 stars, the map 0.23" where the true error was 2.1", on the
// page that found the flexure).  Empty where explain found nothing.
std::string left_out_note(const Data &d)
{
    if (d.ex.findings.empty())
        return "";
    return fmt("the predicted error is the fitted model's own uncertainty: it assumes the model "
               "holds. This run's explanation finds %zu effect%s the model leaves out (sigma %.3f\" "
               "-> %.3f\"): until %s in the model (the explained model's command below), the "
               "pointing between the stars errs by about the fit's sigma, %.3f\" per axis",
               d.ex.findings.size(), d.ex.findings.size() == 1 ? "" : "s", d.ex.base_sigma_arcsec,
               d.ex.final_sigma_arcsec, d.ex.findings.size() == 1 ? "it is" : "they are",
               d.fit.res.sigma * RAD2AS);
}

// The fit the page is about, and its predicted error map.
void stage_fit(Data &d)
{
    d.all = all_of(d.run.obs.size());
    pm_model start = build_model(d.o.order, d.o.adds, d.run.obs, d.run.mount, d.run.latitude,
                                 d.run.aux_names);
    d.fit = do_fit(d.run.obs, d.all, start, d.o.max_passes);
    if (d.fit.status != PM_OK)
        fit_failed(d.fit, d.run.path, d.o.max_passes);
    d.emap = error_map(d.run, d.fit, 0);
}

// --compare OLD: a model file (its first line 'pm-model N') or a run,
// fitted with the page's terms (as pmfit compare).
void stage_compare(Data &d)
{
    const std::string &old = d.o.compare;
    OldSide os = load_old(old, d.o.order, d.o.adds, d.o.read, d.o.max_passes);
    if (os.is_run && os.fit.status != PM_OK)
        fit_failed(os.fit, old + " (the old run)", d.o.max_passes);
    d.old_what = os.is_run ? fmt("the run %s (fitted at order %d)", old.c_str(), d.o.order)
                           : "the model file " + old;
    try {
        d.cmp = compare_old(os, d.run, old);
    } catch (const std::exception &x) {
        throw std::runtime_error(old + " vs " + d.run.path + ": " + x.what());
    }
    d.have_cmp = true;
}

void stage_explain(Data &d)
{
    ExplainOptions eo;
    eo.order = d.o.order;
    eo.adds = d.o.adds;
    eo.alpha = d.o.alpha;
    eo.gears_ha = d.o.gears_ha;
    eo.gears_dec = d.o.gears_dec;
    // as pmfit explain without --order (explain.hpp, explain_default)
    if (d.o.order_given)
        d.ex = d.o.explained ? *d.o.explained : explain(d.run, eo);
    else
        d.ex = explain_default(d.run, eo, &d.explain_note, d.o.explained);
}

// The next targets for the page's model, the run's sigma as the noise.
void stage_plan(Data &d)
{
    PlanOptions &po = d.plan_opt;
    po.order = d.o.order;
    po.adds = d.o.adds;
    po.mount = d.run.mount;
    po.latitude = d.run.latitude;
    po.next = d.o.next;
    po.noise_arcsec = d.fit.res.sigma * RAD2AS;
    po.min_el_deg = d.o.min_el_deg;
    po.gem = !d.o.fork;
    try {
        d.plan = plan_targets(d.run, po);
    } catch (const std::exception &x) {
        d.plan_error = x.what();
    }
}


// ------------------------------------------------------------ the sections

std::string arcsec_text(double v) { return std::isfinite(v) ? fmt("%.3f\xe2\x80\xb3", v) : "\xe2\x80\x93"; }

void section_fit(Page &p, const Data &d)
{
    const FitOut &f = d.fit;
    const pm_model &m = f.model;
    section(p, "fit", "The fit");
    para(p, fmt("Order L = %d", m.order) + (d.o.adds.empty() ? std::string() : " with the added terms " +
                h([&] { std::string a; for (const std::string &x : d.o.adds) a += (a.empty() ? "" : ", ") + x; return a; }())) +
                fmt(": P = %d terms fitted to N = %ld observations in %d Gauss&ndash;Newton passes. "
                    "Unbiased &sigma; = <b>%s</b> per axis, RMS on the sky %s. Values are arcseconds "
                    "on the sky (radians &times; 206265); the terms are defined in docs/model.md.",
                    m.n_terms, f.res.n_obs, f.res.iterations, arcsec_text(f.res.sigma * RAD2AS).c_str(),
                    arcsec_text(f.rms * RAD2AS).c_str()));
    std::vector<std::vector<std::string>> rows;
    for (int i = 0; i < m.n_terms; i++) {
        double v = m.coef[i] * RAD2AS, e = f.res.err[i] * RAD2AS, z = e > 0 ? std::fabs(v) / e : 0;
        std::string sig = num(z, 1) + (z >= 3 ? " *" : "");
        rows.push_back({"<code>" + h(term_name(m, i)) + "</code>", h(meaning(m, i, &d.run.aux_names)), num(v, 2), num(e, 2),
                        z >= 3 ? "<b>" + sig + "</b>" : sig});
    }
    table(p, "The fitted terms. * = significant at 3&sigma; (|value| / 1&sigma; &ge; 3).",
          {"term", "meaning", "value (arcsec)", "1&sigma; (arcsec)", "|value| / 1&sigma;"}, rows, "num");
    if (std::fabs(f.corr) > 0.999)
        para(p, "<strong>Warning:</strong> " + h(term_name(m, f.corr_j)) + " and " + h(term_name(m, f.corr_i)) +
                    fmt(" are nearly degenerate for this sky coverage (correlation %+.5f): their values "
                        "are not meaningful one by one, only together; &sigma; is.", f.corr));
    std::vector<size_t> ord(f.idx.size());
    for (size_t j = 0; j < ord.size(); j++)
        ord[j] = j;
    auto mag = [&](size_t j) { return std::hypot(f.r0[j], f.r1[j]); };
    std::sort(ord.begin(), ord.end(), [&](size_t a, size_t b) { return mag(a) > mag(b); });
    rows.clear();
    for (size_t k = 0; k < ord.size() && k < 10; k++) {
        const Obs &o = d.run.obs[f.idx[ord[k]]];
        rows.push_back({"<code>" + h(d.run.path) + fmt(":%d</code>", o.line), num(f.r0[ord[k]] * RAD2AS, 2),
                        num(f.r1[ord[k]] * RAD2AS, 2), num(mag(ord[k]) * RAD2AS, 2), num(o.eh / DEG, 2),
                        num(o.ed / DEG, 2)});
    }
    table(p, "The worst points: the largest residuals on the sky, by line of the run file.",
          {"line", "axis 1 (arcsec)", "axis 2 (arcsec)", "|r| (arcsec)", "encoder axis 1 (deg)",
           "encoder axis 2 (deg)"}, rows, "num");
    end_section(p);
}

std::vector<pmplot::Vec> vectors_of(const Data &d, const FitOut &f)
{
    std::vector<pmplot::Vec> v;
    for (size_t j = 0; j < f.idx.size(); j++) {
        const Obs &o = d.run.obs[f.idx[j]];
        double x = std::remainder(o.ah, 2 * PI) / DEG;
        if (d.altaz && x < 0)
            x += 360;
        v.push_back({x, o.ad / DEG, f.r0[j] * RAD2AS, f.r1[j] * RAD2AS, o.pier < 0 ? 1 : 0});
    }
    return v;
}

std::string axis_names(const Data &d)
{
    return d.altaz ? "axis 1 along azimuth (times cos elevation, i.e. on the sky), axis 2 along elevation"
                   : "axis 1 along hour angle (times cos declination, i.e. on the sky), axis 2 along "
                     "declination";
}

// The residuals against one variable of the observations (NaN: absent).
struct Variable {
    std::string label, words;
    double (*get)(const Where &, const Obs &);
};

// One figure of the residuals against var; nothing drawn, and a note why
// in *why, when no observation has it or all have the same value.
bool residual_figure(Page &p, const Data &d, const Variable &var, std::string *why)
{
    const FitOut &f = d.fit;
    pmplot::Series s1{d.altaz ? "axis 1 (azimuth, on the sky)" : "axis 1 (hour angle, on the sky)", {}, {}, false};
    pmplot::Series s2{d.altaz ? "axis 2 (elevation)" : "axis 2 (declination)", {}, {}, false};
    size_t n = 0;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t j = 0; j < f.idx.size(); j++) {
        const Obs &o = d.run.obs[f.idx[j]];
        double x = var.get(where_of(d.run, o), o);
        if (std::isfinite(x))
            n++, lo = std::min(lo, x), hi = std::max(hi, x);
        s1.x.push_back(x), s1.y.push_back(f.r0[j] * RAD2AS);
        s2.x.push_back(x), s2.y.push_back(f.r1[j] * RAD2AS);
    }
    std::string unit = var.label.substr(var.label.find('(') + 1, var.label.size() - var.label.find('(') - 2);
    if (!n || hi == lo) {
        *why = var.words + (n ? fmt(": the run gives one value, %.6g %s, for every observation", lo, unit.c_str())
                              : std::string(": the run gives it for no observation") +
                                    (std::isfinite(d.run.latitude) ? "" : " (or no latitude to convert the axes)"));
        return false;
    }
    std::string what = var.label.substr(0, var.label.find(" ("));
    figure(p, "Residuals of the fit (observed minus model, arcsec on the sky) against " + h(var.words) +
                  " (" + h(unit) + "): " + h(axis_names(d)) + ". A trend is a term the model lacks" +
                  (n < f.idx.size() ? fmt("; %zu observations without it are not drawn", f.idx.size() - n) : "") + ".",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::xy(out, "Residuals against " + what, var.label, "residual (arcsec)", {s1, s2}, err);
           });
    return true;
}

void section_residuals(Page &p, const Data &d)
{
    section(p, "residuals", "Residuals");
    std::vector<pmplot::Vec> v = vectors_of(d, d.fit);
    figure(p, "Residuals of the fit on the sky (observed minus model): a dot at each observation, "
              "an arrow for its residual (arcsec on the sky, scale arrow in the legend; " + h(axis_names(d)) +
              "). Axes: " + h(d.xlabel()) + " and " + h(d.ylabel()) + ". Arrows that line up over a "
              "region are a pattern the model leaves out.",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::sky_vectors(out, "Residuals on the sky (" + fmt("sigma %.2f\"", d.fit.res.sigma * RAD2AS) + ")",
                                          d.xlabel(), d.ylabel(), v, 0, d.groups(), err);
           });
    static const Variable vars[] = {
        {"azimuth (deg)", "azimuth (north through east)", [](const Where &w, const Obs &) { return w.az; }},
        {"elevation (deg)", "elevation", [](const Where &w, const Obs &) { return w.el; }},
        {"hour angle (h)", "hour angle (apparent, west positive)", [](const Where &w, const Obs &) { return w.ha_h; }},
        {"declination (deg)", "declination", [](const Where &w, const Obs &) { return w.dec; }},
        {"time (h)", "time (hours, the run's own zero point)", [](const Where &, const Obs &o) { return o.ctx.time_h; }},
        {"temperature (\xc2\xb0" "C)", "air temperature", [](const Where &, const Obs &o) { return o.ctx.temp_c; }},
    };
    for (const Variable &var : vars) {
        std::string why;
        if (!residual_figure(p, d, var, &why))
            para(p, "Not drawn: the residuals against " + h(why) + ".");
    }
    end_section(p);
}


// Inputs for a map: the run's mean temperature, time and auxiliary columns.
pm_context mean_context(const Run &run)
{
    pm_context c = pm_context();
    double sum[2 + PM_MAX_AUX] = {0};
    long n[2 + PM_MAX_AUX] = {0};
    for (const Obs &o : run.obs)
        for (int k = 0; k < 2 + PM_MAX_AUX; k++) {
            double x = k == 0 ? o.ctx.temp_c : k == 1 ? o.ctx.time_h : o.ctx.aux[k - 2];
            if (std::isfinite(x))
                sum[k] += x, n[k]++;
        }
    c.temp_c = n[0] ? sum[0] / (double)n[0] : 0;
    c.time_h = n[1] ? sum[1] / (double)n[1] : 0;
    for (int k = 0; k < PM_MAX_AUX; k++)
        c.aux[k] = n[2 + k] ? sum[2 + k] / (double)n[2 + k] : 0;
    return c;
}

// The pier side of the run's star nearest to (ha, dec) (+1 when none says).
int nearest_side(const Run &run, double ha, double dec)
{
    double best = -2;
    int side = 1;
    for (const Obs &o : run.obs) {
        double c = std::sin(dec) * std::sin(o.ad) + std::cos(dec) * std::cos(o.ad) * std::cos(ha - o.ah);
        if (c > best)
            best = c, side = o.pier < 0 ? -1 : 1;
    }
    return side;
}

// The model's correction (apparent minus encoder position, arcsec on the
// sky) on a grid over the usable sky of the error map, without the index
// terms c' and e' (the encoder zero points).
std::vector<pmplot::Vec> correction_field(const Data &d)
{
    pm_model m = d.fit.model;
    m.coef[2] = m.coef[4] = 0;
    std::vector<pmplot::Vec> v;
    if (pm_model_prepare(&m) != PM_OK)
        return v;
    pm_context ctx = mean_context(d.run);
    const double step = 10;
    for (double y = -85; y < 90; y += step) {
        int nx = std::max(1, (int)std::lround(24 * std::cos(y * DEG)));
        for (int k = 0; k < nx; k++) {
            double x = (d.altaz ? 0 : -180) + 360.0 / nx * (k + 0.5), t = x * DEG, dd = y * DEG, el = y;
            if (!d.altaz && d.emap.elevation)
                el = std::asin(std::sin(d.run.latitude) * std::sin(dd) +
                               std::cos(d.run.latitude) * std::cos(dd) * std::cos(t)) / DEG;
            if (el < d.emap.limit_deg)
                continue;
            int side = d.altaz ? 0 : nearest_side(d.run, t, dd);
            ctx.pier = side;
            double et = side < 0 ? t + PI : t, ed = side < 0 ? PI - dd : dd, T, D;
            if (pm_model_apply(&m, &ctx, et, ed, &T, &D) != PM_OK)
                continue;
            v.push_back({x, y, std::remainder(T - t, 2 * PI) * std::cos(dd) * RAD2AS, (D - dd) * RAD2AS,
                         side < 0 ? 1 : 0});
        }
    }
    return v;
}

void section_model(Page &p, const Data &d)
{
    section(p, "model", "The model over the sky");
    std::vector<pmplot::Vec> v = correction_field(d);
    const pm_model &m = d.fit.model;
    std::string limit = fmt("%s %.0f&deg;", d.emap.elevation ? "elevation" : "declination", d.emap.limit_deg);
    figure(p, "The pointing correction the model predicts over the sky above " + limit +
                  " (the run's lowest star): each arrow goes from where the encoders say the telescope "
                  "points to where it points (apparent minus encoder position, arcsec on the sky; scale "
                  "arrow in the legend). Axes: " + h(d.xlabel()) + " and " + h(d.ylabel()) + ". " +
                  fmt("The encoder zero points c&prime; = %.1f&Prime; and e&prime; = %.1f&Prime; "
                      "(constant offsets of the two axes, often far larger than the rest) are left out "
                      "so the structure shows", m.coef[2] * RAD2AS, m.coef[4] * RAD2AS) +
                  (d.altaz ? "" : "; each place on the pier side of the run's nearest star") +
                  "; temperature and time at the run's mean.",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::sky_vectors(out, "Pointing correction of the model (without c', e')", d.xlabel(),
                                          d.ylabel(), v, 0, d.altaz ? std::vector<std::string>{} : d.groups(), err);
           });
    const ErrorMap &e = d.emap;
    if (!left_out_note(d).empty())
        para(p, "<b>Note:</b> " + h(left_out_note(d)));
    para(p, fmt("How well the fit knows its correction (1&sigma; per axis, from the fit's covariance): "
                "RMS over the sky above %s <b>%s</b>, largest %s at %s %.0f&deg;, %s %.0f&deg;; at the "
                "observed stars %s.", limit.c_str(), arcsec_text(e.mean_arcsec).c_str(),
                arcsec_text(e.max_arcsec).c_str(), d.altaz ? "azimuth" : "HA", e.max_x_deg,
                d.altaz ? "elevation" : "Dec", e.max_y_deg, arcsec_text(e.at_points_arcsec).c_str()));
    figure(p, "Predicted error map: the 1&sigma; uncertainty per axis of the model's correction "
              "(arcsec, colour bar) over the sky above " + limit + ", from the fit's covariance "
              "(docs/model.md, &ldquo;How well the model knows the sky&rdquo;); rings: the observed "
              "stars. Axes: " + h(d.xlabel()) + " and " + h(d.ylabel()) + ". Bright cells are where "
              "the model extrapolates: stars there teach it most (see the next targets).",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::sky_scalar(out, "Predicted pointing error of the model (1 sigma per axis)",
                                         d.xlabel(), d.ylabel(), e.cells, "1 sigma (arcsec)", e.marks,
                                         "observed stars", err);
           });
    end_section(p);
}


// The variable a finding shows against, at observation o (the j-th drawn),
// and its axis label with the unit.
double finding_x(const Data &d, const Finding &f, const Obs &o, size_t j, std::string *label)
{
    if (f.effect == "ha_periodic" || f.effect == "dec_periodic") {
        bool ha = f.effect == "ha_periodic";
        *label = fmt("phase of the period, %.4g x encoder ", f.cycles_per_rev) +
                 (ha ? (d.altaz ? "azimuth" : "HA") : (d.altaz ? "elevation" : "Dec")) + " (deg)";
        return wrap360(f.cycles_per_rev * (ha ? o.eh : o.ed) / DEG);
    }
    if (f.effect == "refraction" || f.effect == "tube_flexure") {
        *label = "elevation (deg)";
        return where_of(d.run, o).el;
    }
    if (f.effect == "temperature") {
        *label = "temperature (\xc2\xb0" "C)";
        return o.ctx.temp_c;
    }
    if (f.effect == "time_drift") {
        *label = "time (h)";
        return o.ctx.time_h;
    }
    if (f.effect.rfind("aux:", 0) == 0) {
        const std::vector<std::string> &names = d.run.aux_names;
        size_t col = (size_t)(std::find(names.begin(), names.end(), f.effect.substr(4)) -
                              names.begin());
        if (col < names.size() && col < (size_t)PM_MAX_AUX) {
            *label = "the run's column " + f.effect.substr(4) + " (its unit)";
            return o.ctx.aux[col];
        }
    }
    if (f.effect == "hysteresis") {
        *label = "direction of the last slew on axis 1 (+1 or -1, no unit; spread for visibility)";
        return o.ctx.dir + 0.1 * ((double)(j % 7) - 3) / 3;
    }
    if (f.effect == "pier_side") {
        *label = "hour angle (h)";
        return where_of(d.run, o).ha_h;
    }
    *label = "line in the run file (line number)";
    return (double)o.line;
}

// The residuals of fit g against finding f's variable, as two series.
std::vector<pmplot::Series> finding_series(const Data &d, const Finding &f, const FitOut &g, std::string *label)
{
    bool along = f.effect == "ha_periodic";
    std::vector<pmplot::Series> s = {
        {along ? "axis 1 (along the axis)" : "axis 1 (on the sky)", {}, {}, false},
        {"axis 2", {}, {}, false}};
    for (size_t j = 0; j < g.idx.size(); j++) {
        const Obs &o = d.run.obs[g.idx[j]];
        double x = finding_x(d, f, o, j, label), y0 = g.r0[j] * RAD2AS;
        if (along && std::fabs(std::cos(o.ad)) > 0.2)
            y0 /= std::fabs(std::cos(o.ad)); // along the axis, not on the sky
        s[0].x.push_back(x), s[0].y.push_back(y0);
        s[1].x.push_back(x), s[1].y.push_back(g.r1[j] * RAD2AS);
    }
    return s;
}

// The explained model without finding f, refitted (its terms dropped; an
// outlier's points put back; higher_order: the order one lower).  False
// when it cannot be fitted.
bool without(const Data &d, const Finding &f, FitOut *out)
{
    const Explanation &ex = d.ex;
    int order = ex.final_order;
    std::vector<std::string> adds;
    std::vector<int> use = ex.kept;
    for (const std::string &a : ex.final_adds)
        if (std::find(f.adds.begin(), f.adds.end(), a) == f.adds.end())
            adds.push_back(a);
    if (f.effect == "higher_order")
        order--;
    if (f.effect == "outlier")
        use = d.all;
    if (order < 0 || (adds.size() == ex.final_adds.size() && order == ex.final_order && use.size() == ex.kept.size()))
        return false;
    xdetail::Fit w = xdetail::fit_spec(d.run, use, order, adds);
    if (w.ok)
        *out = w.f;
    return w.ok;
}

void finding_figure(Page &p, const Data &d, const Finding &f, size_t k)
{
    FitOut before;
    bool refit = without(d, f, &before);
    if (!refit)
        before = d.ex.baseline;
    std::string xlab;
    std::vector<pmplot::Series> b = finding_series(d, f, before, &xlab), a = finding_series(d, f, d.ex.final, &xlab);
    if (f.effect == "outlier") { // the points left out, on top
        pmplot::Series out{"left out (both axes)", {}, {}, false};
        for (size_t j = 0; j < before.idx.size(); j++) {
            const Obs &o = d.run.obs[before.idx[j]];
            if (std::find(f.lines.begin(), f.lines.end(), o.line) == f.lines.end())
                continue;
            out.x.insert(out.x.end(), {(double)o.line, (double)o.line});
            out.y.insert(out.y.end(), {before.r0[j] * RAD2AS, before.r1[j] * RAD2AS});
        }
        b.push_back(out);
    }
    std::string bt = fmt("without it: sigma %.2f\"", before.res.sigma * RAD2AS);
    std::string at = fmt("with it: sigma %.2f\"", d.ex.final.res.sigma * RAD2AS);
    figure(p, fmt("Finding %zu, <b>%s</b>, before and after: the residuals (arcsec; ", k + 1,
                  h(mount_words(f.effect, d.run.mount)).c_str()) +
                  // (a periodic error of axis 1 is read along the axis: the sky offset
                  // divided by cos of the second axis; axis_names gives the sky's)
                  h(f.effect == "ha_periodic"
                        ? std::string(d.altaz ? "axis 1 along azimuth (divided by cos elevation, i.e. "
                                                "along the axis), axis 2 along elevation"
                                              : "axis 1 along hour angle (divided by cos declination, "
                                                "i.e. along the axis), axis 2 along declination")
                        : axis_names(d)) +
                  ") against " + h(xlab) + ", " +
                  (refit ? "left: the explained model refitted without this finding; right: the explained model."
                         : "left: the baseline model; right: the explained model.") +
                  " The pattern on the left that is gone on the right is what the finding explains.",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::xy_pair(out, fmt("Finding %zu: %s", k + 1,
                                               mount_words(f.effect, d.run.mount).c_str()),
                                      xlab, "residual (arcsec)",
                                      b, a, bt, at, err);
           });
}


void explain_findings(Page &p, const Data &d)
{
    const Explanation &ex = d.ex;
    // an alt-az mount's periodic effects by its axes' names (mount_words)
    auto W = [&d](const std::string &x) { return mount_words(x, d.run.mount); };
    std::vector<std::vector<std::string>> rows = {
        {"0", "baseline", "", num(ex.base_sigma_arcsec, 3), num(ex.base_cv_rms_arcsec, 3), fmt("%d", ex.base_n_params)}};
    for (size_t k = 0; k < ex.findings.size(); k++) {
        const Finding &f = ex.findings[k];
        rows.push_back({fmt("%zu", k + 1), fmt("<a href=\"#finding%zu\">", k + 1) + h(W(f.effect)) + "</a>",
                        fmt("%.2g", f.false_alarm_probability), num(f.sigma_after_arcsec, 3),
                        num(f.cv_rms_after_arcsec, 3), fmt("%d", f.n_params_after)});
    }
    table(p, "What the model left out, step by step: each finding, its false-alarm probability (the "
             "chance that noise alone makes so large an improvement, corrected for the periods and "
             "candidates tried) and the fit once it is added.",
          {"step", "added", "false-alarm probability", "&sigma; after (arcsec)", "cross-validated RMS (arcsec)",
           "terms P"}, rows, "num");
    for (size_t k = 0; k < ex.findings.size(); k++) {
        const Finding &f = ex.findings[k];
        std::string extra;
        if (!f.with.empty())
            extra += "<li>Found together with " + h(W(f.with)) + ": neither alone passed, the pair does.</li>";
        for (const Alternative &a : f.alternatives)
            extra += std::string(a.smooth        ? "<li>Or a smooth shape: <b>"
                                 : a.final_model ? (a.delta_bic <= -6
                                                        ? "<li>A better reading in the final model: <b>"
                                                        : "<li>As good a reading in the final model: <b>")
                                                 : a.delta_bic <= -6 ? "<li>A better-fitting reading: <b>"
                                                                    : "<li>As good a reading: <b>") +
                     h(W(a.effect)) +
                     fmt("</b> (false-alarm 10<sup>%.1f</sup>, &Delta;BIC %+.1f%s); to separate them: ",
                         a.log10_fap, a.delta_bic,
                         a.smooth ? ": it holds all that the periodic term explains, so this run cannot "
                                    "tell a periodic error from a smooth distortion" : "") +
                     h(W(a.separate_by)) + "</li>";
        if (!f.beside.effect.empty())
            extra += "<li>" + h(W(beside_text(f))) + ".</li>";
        p.body += fmt("<h3 id=\"finding%zu\">Finding %zu: ", k + 1, k + 1) + h(W(f.effect)) + "</h3>\n";
        para(p, h(W(f.text)) + ". <i>Where:</i> " + h(W(f.where)) + ".");
        if (!extra.empty())
            p.body += "<ul>" + extra + "</ul>\n";
        finding_figure(p, d, f, k);
    }
    for (const std::string &w : ex.withdrawn_why)
        para(p, "Withdrawn: " + h(W(w)) + "; the findings above are those of the search without it.");
    for (const Unmodelled &u : ex.unmodelled)
        para(p, "<b>Significant, not modelled:</b> " + h(W(unmodelled_text(u))) + ".");
    for (const Explanation::Blurred &b : ex.blurred)
        para(p, "<b>Significant, not named:</b> " + h(W(blurred_text(b))) + ".");
    for (const Explanation::Unfitted &u : ex.unfitted)
        para(p, "<b>Not judged:</b> " + h(W(unfitted_text(u))) + ".");
}

void section_explain(Page &p, const Data &d)
{
    const Explanation &ex = d.ex;
    section(p, "explain", "What the model left out (pmfit explain)");
    if (!d.explain_note.empty())
        para(p, h(d.explain_note) + ".");
    para(p, fmt("The baseline (order %d%s, P = %d) leaves &sigma; = %s, cross-validated RMS %s; ",
                d.explain_note.empty() ? d.o.order : 0,
                d.o.adds.empty() ? "" : " with the added terms", ex.base_n_params,
                arcsec_text(ex.base_sigma_arcsec).c_str(), arcsec_text(ex.base_cv_rms_arcsec).c_str()) +
                (ex.findings.empty()
                     ? fmt("nothing %s is left out (false-alarm probability below %g and a better "
                           "cross-validated RMS were required).",
                           ex.unmodelled.empty() ? "significant" : "that this run can model", d.o.alpha)
                     : fmt("after %zu finding%s &sigma; = <b>%s</b>, cross-validated RMS %s with P = %d terms "
                           "(docs/explain.md).", ex.findings.size(), ex.findings.size() == 1 ? "" : "s",
                           arcsec_text(ex.final_sigma_arcsec).c_str(),
                           arcsec_text(ex.final_cv_rms_arcsec).c_str(), ex.final_n_params)));
    if (!ex.interpretation.empty()) {
        p.body += "<h3>What the baseline holds</h3>\n<ul>\n";
        for (const Interpretation &it : ex.interpretation)
            p.body += "<li>" + h(it.text) + "</li>\n";
        if (!ex.physical_reading.empty())
            p.body += "<li>" + h(ex.physical_reading) + "</li>\n";
        p.body += "</ul>\n";
    }
    if (!ex.folded_pier.empty())
        para(p, "<strong>Warning:</strong> " + h(ex.folded_pier) + ".");
    p.body += "<h3>Findings</h3>\n";
    explain_findings(p, d);
    std::string cmd = fmt("pmfit fit %s --order %d", shell_word(d.run.path).c_str(), ex.final_order);
    for (const std::string &a : ex.final_adds)
        cmd += " --add " + add_word(mount_words(a, d.run.mount));
    cmd += d.run.read_options; /* (as it was read: --equinox, ...) */
    para(p, "The explained model: <code>" + h(cmd) + "</code>");
    figure(p, "Residuals on the sky (arcsec, scale arrow in the legend) of the baseline (left) and of the "
              "explained model (right), on the same axes and arrow scale: " + h(d.xlabel()) + " and " +
              h(d.ylabel()) + ".",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::sky_vectors_pair(out, fmt("Baseline (sigma %.2f\") and explained model (sigma %.2f\")",
                                                        ex.base_sigma_arcsec, ex.final_sigma_arcsec),
                                               d.xlabel(), d.ylabel(), vectors_of(d, ex.baseline),
                                               vectors_of(d, ex.final), "baseline", "explained model", 0,
                                               d.groups(), err);
           });
    for (const Periodogram &pg : ex.periodograms) {
        std::string axis = pg.axis == "ha" ? (d.altaz ? "azimuth" : "hour-angle") : (d.altaz ? "elevation" : "declination");
        figure(p, "Periodogram of the baseline residuals along the " + h(axis) + fmt(" axis: the power (the "
                  "reduction of &chi;&sup2; by a sinusoid of that period, in units of &sigma;&sup2;, no unit) "
                  "against the frequency in cycles per revolution of the axis (log scale); dashed: the "
                  "false-alarm level %g over the %.0f periods tried; the triangle marks the highest peak.",
                  d.o.alpha, pg.trials),
               [&](const pmplot::Out &out, std::string *err) {
                   return pmplot::periodogram(out, "Periodogram of the baseline residuals, " + axis + " axis",
                                              "power (\xcf\x87\xc2\xb2 reduction / \xcf\x83\xc2\xb2, no unit)", pg.g, pg.power,
                                              pg.threshold, fmt("false-alarm %g", d.o.alpha), pg.peak_g, true, err);
               });
    }
    end_section(p);
}


void section_plan(Page &p, const Data &d)
{
    section(p, "plan", "The next targets (pmfit plan)");
    if (!d.plan_error.empty()) {
        para(p, "Not available for this run: " + h(d.plan_error) + ".");
        end_section(p);
        return;
    }
    const Plan &pl = d.plan;
    para(p, fmt("The %zu stars to take next, in this order, that most reduce the model's predicted error "
                "averaged over the sky above elevation %.0f&deg;%s (I-optimal design, docs/model.md, &ldquo;Which "
                "star next&rdquo;), for this model (P = %d) and this run's &sigma; = %.3f&Prime;; candidates on a "
                "%.0f&deg; grid. Predicted mean error now: <b>%s</b>. The same list: <code>",
                pl.targets.size(), d.plan_opt.min_el_deg,
                d.o.horizon.empty() ? "" : (" and the horizon of " + h(d.o.horizon)).c_str(),
                d.fit.model.n_terms, d.plan_opt.noise_arcsec, d.plan_opt.grid_deg,
                arcsec_text(pl.before_arcsec).c_str()) +
                h(fmt("pmfit plan %s --next %d --order %d --min-el %g%s%s", shell_word(d.run.path).c_str(),
                      d.o.next, d.o.order, d.o.min_el_deg, d.o.horizon.empty() ? "" : " --horizon ",
                      d.o.horizon.empty() ? "" : shell_word(d.o.horizon).c_str()) +
                  plan_adds(d.o.adds) + (d.o.fork ? " --fork" : "")) +
                "</code>.");
    if (pl.sides > 0) {
        // the sky the predicted error is over: a German mount's both pier
        // sides (where a run of one side has not been, the model is not
        // known: an outside probe's 5 stars said 0.450" over the sky in the
        // map and 1.510" here, with nothing to tell the two apart)
        long beyond = 0, normal = 0;
        for (const Obs &ob : d.run.obs)
            (ob.pier < 0 ? beyond : normal)++;
        std::string s = pl.sides == 2 ? "The sky of this prediction is both pier sides, as a German mount reaches "
                                        "it (beyond the pole on the one side of the meridian, normal on the other)"
                                      : "The sky of this prediction is that of a mount that does not flip (all "
                                        "on the normal side)";
        // (a run all beyond the pole is of a German mount: planned as one
        // that does not flip (--fork), its sky is the normal side it has not
        // observed, and --fork is not offered to it; a second probe)
        if ((pl.sides == 2 && (beyond == 0 || normal == 0)) || (pl.sides == 1 && normal == 0 && beyond > 0))
            s += fmt(": this run's stars are all %s, so it counts the sky of %s side, which the run has "
                     "not observed; the map of the model above (each place on the side of the run's nearest "
                     "star) says %s over the sky above %s %.0f&deg;%s",
                     beyond ? "beyond the pole" : "on the normal side", pl.sides == 2 ? "the other" : "the normal",
                     arcsec_text(d.emap.mean_arcsec).c_str(), d.emap.elevation ? "elevation" : "declination",
                     d.emap.limit_deg,
                     pl.sides == 2 && beyond == 0 ? ". For a mount that does not flip: <code>--fork</code>" : "");
        para(p, s + ".");
    }
    if (!pl.note.empty())
        para(p, "Note: " + h(pl.note) + ".");
    std::vector<std::vector<std::string>> rows;
    std::vector<std::pair<double, double>> marks;
    std::vector<std::string> labels;
    for (size_t k = 0; k < pl.targets.size(); k++) {
        const Target &t = pl.targets[k];
        marks.push_back({t.x_deg, t.y_deg});
        labels.push_back(fmt("%zu", k + 1));
        if (d.altaz)
            rows.push_back({fmt("%zu", k + 1), num(t.x_deg, 2), num(t.y_deg, 2), arcsec_text(t.after_arcsec)});
        else
            rows.push_back({fmt("%zu", k + 1), num(t.x_deg / 15, 3), num(t.y_deg, 2), num(t.el_deg, 1),
                            t.side < 0 ? "beyond the pole (west)" : "normal (east)", arcsec_text(t.after_arcsec)});
    }
    if (d.altaz)
        table(p, "The next targets.", {"#", "azimuth (deg)", "elevation (deg)", "predicted mean error after (arcsec)"},
              rows, "num targets");
    else
        table(p, "The next targets.", {"#", "hour angle (h)", "declination (deg)", "elevation (deg)", "pier side",
                                       "predicted mean error after (arcsec)"}, rows, "num targets");
    figure(p, "Where the next targets are (numbered rings, in the order of the table) on the predicted error map of the current fit (1&sigma; "
              "per axis, arcsec, colour bar). Axes: " + h(d.xlabel()) + " and " + h(d.ylabel()) + ".",
           [&](const pmplot::Out &out, std::string *err) {
               return pmplot::sky_scalar(out, "Next targets on the predicted error map", d.xlabel(), d.ylabel(),
                                         d.emap.cells, "1 sigma (arcsec)", marks, "next targets, in order", err,
                                         labels);
           });
    end_section(p);
}

void section_compare(Page &p, const Data &d)
{
    const Comparison &c = d.cmp;
    section(p, "compare", "What changed since (pmfit compare)");
    para(p, "The earlier model, from " + h(d.old_what) + fmt(", applied to this run (%ld observations, %d terms): ",
                                                                c.n_obs, c.n_terms) + "<b>" + h(c.advice) + "</b>");
    std::vector<std::vector<std::string>> rows = {
        {"the old model as it is", num(c.rms_as_is, 3), num(c.cv_as_is, 3)},
        {fmt("the old model re-zeroed (c&prime; %+.2f &plusmn; %.2f&Prime;, e&prime; %+.2f &plusmn; %.2f&Prime;)",
             c.rezero_c, c.rezero_c_err, c.rezero_e, c.rezero_e_err),
         std::isfinite(c.rms_rezero) ? num(c.rms_rezero, 3) : std::string("&mdash;"),
         num(c.cv_rezero, 3)},
        {"refitted to this run", num(c.sigma_refit, 3), num(c.cv_refit, 3)}};
    table(p, "The pointing error on this run (per axis): residual RMS (for the refit: its unbiased &sigma;) and the "
             "5-fold cross-validated RMS, which says how each would point at new stars.",
          {"model", "RMS or &sigma; (arcsec)", "cross-validated RMS (arcsec)"}, rows, "num");
    if (std::isfinite(c.old_pred_new))
        para(p, fmt("The old fit's own predicted error (1&sigma; per axis) at this run's stars: %s; at its own: %s.",
                    arcsec_text(c.old_pred_new).c_str(), arcsec_text(c.old_pred_old).c_str()));
    rows.clear();
    for (const TermChange &t : c.moved)
        rows.push_back({"<code>" + h(t.name) + "</code>", h(t.meaning), num(t.old_arcsec, 2), num(t.new_arcsec, 2),
                        num(t.err_arcsec, 2), num(t.z, 1)});
    if (rows.empty())
        para(p, fmt("No term moved beyond 3&sigma; (%d stable).", c.n_stable));
    else
        table(p, fmt("The terms that moved beyond 3&sigma;, largest first (%d others did not).", c.n_stable),
              {"term", "meaning", "old (arcsec)", "new (arcsec)", "1&sigma; of the difference (arcsec)",
               "difference / 1&sigma;"}, rows, "num");
    end_section(p);
}


const char *const CSS =
    "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;color:#222;background:#fff;max-width:1120px;"
    "margin:0 auto;padding:0 18px 40px;line-height:1.45}\n"
    "h1{font-size:1.6em;margin:.8em 0 .3em}h2{font-size:1.3em;border-bottom:2px solid #0072B2;"
    "padding-bottom:.15em;margin-top:1.8em}h3{font-size:1.1em;margin-top:1.4em}\n"
    "nav ol{columns:2;margin:.3em 0}nav a{color:#0072B2}\n"
    "table{border-collapse:collapse;margin:.8em 0;font-size:.92em}caption{text-align:left;padding:.3em 0;"
    "caption-side:top}\n"
    "th,td{border:1px solid #ccc;padding:.25em .55em;vertical-align:top}th{background:#f0f4f8;text-align:left}\n"
        "table.num td{text-align:right}table.num td.t{text-align:left}\n"
    "dl.summary{display:grid;grid-template-columns:max-content auto;gap:.2em 1em}dl.summary dt{font-weight:bold}"
    "dl.summary dd{margin:0}\n"
    "figure{margin:1.2em 0;padding:.5em;border:1px solid #ddd;background:#fff}figure svg{display:block;"
    "max-width:100%;height:auto;margin:0 auto}\n"
    "figcaption{font-size:.9em;color:#333;margin-top:.4em}code{background:#f4f4f4;padding:0 .2em}\n"
    "footer{margin-top:2em;font-size:.85em;color:#555;border-top:1px solid #ccc;padding-top:.5em}\n"
    "@media print{figure{break-inside:avoid}}\n";

void summary(Page &p, const Data &d)
{
    const FitOut &f = d.fit;
    std::string lat = std::isfinite(d.run.latitude) ? fmt("%+.4f&deg;", d.run.latitude / DEG) : "not given";
    p.body += "<dl class=\"summary\">\n<dt>run</dt><dd><code>" + h(d.run.path) + "</code></dd>\n" +
              fmt("<dt>mount</dt><dd>%s, site latitude %s</dd>\n", d.altaz ? "alt-az" : "equatorial", lat.c_str()) +
              fmt("<dt>observations</dt><dd>%zu</dd>\n", d.run.obs.size()) +
              fmt("<dt>model</dt><dd>order %d, %d terms: &sigma; = %s per axis</dd>\n", f.model.order,
                  f.model.n_terms, arcsec_text(f.res.sigma * RAD2AS).c_str()) +
              fmt("<dt>explained</dt><dd>%zu finding%s: &sigma; = %s with %d terms</dd>\n", d.ex.findings.size(),
                  d.ex.findings.size() == 1 ? "" : "s", arcsec_text(d.ex.final_sigma_arcsec).c_str(),
                  d.ex.final_n_params) +
              fmt("<dt>predicted error</dt><dd>%s over the sky above %s %.0f&deg; (the lowest star; "
                  "1&sigma; per axis), largest %s",
                  arcsec_text(d.emap.mean_arcsec).c_str(), d.emap.elevation ? "elevation" : "declination",
                  d.emap.limit_deg, arcsec_text(d.emap.max_arcsec).c_str());
    const std::string undetermined = undetermined_warning(d.emap, f.res.sigma * RAD2AS);
    if (!undetermined.empty())
        p.body += "<br><b>warning</b>: " + h(undetermined);
    if (!left_out_note(d).empty())
        p.body += "<br>" + h(left_out_note(d));
    p.body += "</dd>\n";
    if (d.have_cmp) {
        p.body += "<dt>since before</dt><dd>" + h(d.cmp.advice);
        for (const std::string &n : d.cmp.notes)
            p.body += "<br>note: " + h(n);
        p.body += "</dd>\n";
    }
    p.body += "</dl>\n";
    if (!d.run.notes.empty()) {
        p.body += "<p>Notes from reading the run:</p>\n<ul>\n";
        for (size_t k = 0; k < d.run.notes.size() && k < 20; k++)
            p.body += "<li>" + h(d.run.notes[k]) + "</li>\n";
        if (d.run.notes.size() > 20)
            p.body += fmt("<li>and %zu more</li>\n", d.run.notes.size() - 20);
        p.body += "</ul>\n";
    }
}

std::string assemble(const Page &p, const Page &head, const Data &d)
{
    std::string title = "Pointing report: " + d.run.path;
    std::string s = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                    "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                    "<title>" + h(title) + "</title>\n<style>\n" + CSS + "</style>\n</head>\n<body>\n"
                    "<header>\n<h1>" + h(title) + "</h1>\n" + head.body + "</header>\n"
                    "<nav aria-label=\"Contents\">\n<h2>Contents</h2>\n<ol>\n";
    for (const auto &t : p.toc)
        s += "<li><a href=\"#" + t.first + "\">" + h(t.second) + "</a></li>\n";
    s += "</ol>\n</nav>\n<main>\n" + p.body + "</main>\n<footer>\n<p>Made by <code>" + h(d.o.command) +
         "</code> with pm, the open pointing-model library (docs/report.md). Angles on the sky are "
         "arcseconds (&Prime;), positions degrees, hour angle and time hours. The page is one file: no "
         "script, no external resource.</p>\n</footer>\n</body>\n</html>\n";
    return s;
}

} // namespace

std::string report_html(const Run &run, const ReportOptions &o, const ReportProgress &progress)
{
    auto stage = [&](const char *name, double done) {
        if (progress)
            progress(name, done);
    };
    Data d(run, o);
    if (!o.horizon.empty()) // a bad horizon file is the user's error, not the run's
        d.plan_opt.horizon = read_horizon(o.horizon);
    if (!o.compare.empty()) {
        stage("compare", 0.0);
        stage_compare(d);
    }
    stage("fit", 0.05);
    stage_fit(d);
    stage("explain", 0.15);
    stage_explain(d);
    stage("plan", 0.65);
    stage_plan(d);
    Page p, head;
    stage("figures", 0.75);
    section_fit(p, d);
    section_residuals(p, d);
    section_model(p, d);
    stage("figures: explain", 0.85);
    section_explain(p, d);
    section_plan(p, d);
    if (d.have_cmp)
        section_compare(p, d);
    summary(head, d);
    std::string html = assemble(p, head, d);
    stage("done", 1.0);
    return html;
}

} // namespace pmhost
