// bench_plan.cpp - how many points does pmfit plan save?  (issue 17 item
// 1, the proof; docs/model.md "Which star next", "How many points does it
// save").  Not a timing: it measures, for models of order 0, 1 and 2, the
// number of points each design needs for a given pointing error.
//
// Simulated (the project's mount model; a German mount at latitude 47):
//   designs: the greedy I-optimal plan (and D-optimal), a golden-spiral
//   lattice (the most uniform grid; MountWizzard4's "golden spiral"),
//   MountWizzard4's alt-az grid of R rings of C points (its genGrid: rings
//   equally spaced in altitude from the horizon to 85 deg, azimuths
//   180/C + k 360/C) and random stars (TPOINT-style runs);
//   error: each design's points observed on a simulated mount (1" noise),
//   the model fitted, and its correction compared with the truth at 1,000
//   held-out places over the usable sky (RMS per axis; mean over noise
//   draws) -- the held-out error against the truth, the cross-validated
//   error without the noise of the held-out measurement; and the predicted
//   error sigma sqrt(tr(W A^-1)/2).
//   settings: full sky; the truth beyond the model (order L+1 terms of RMS
//   3"); a partial sky (a horizon with buildings); points already taken (a
//   run's first part, east only); a model with physical terms.
// Real runs (../shared/data), sub-sampled: the candidates are the run's own
//   points; the plan (rows at the ideal mount: nothing measured is used to
//   choose), an evenly spread subset (farthest-point sampling) and random
//   subsets (mean of 20) choose N of them; the model is fitted to the N and
//   its RMS residual on the points not chosen is the cross-validated error.
//
// "Needed": the smallest N from which the design's error curve stays at or
// below the reference's error (curves sampled every ~5%; linear between
// samples).
//
// JSON lines (--out): one per reference; an error that could not be
// computed (a fit failed) is -1, a count not reached null.
//
//   build/bench/pmbench_plan [--quick] [--data DIR] [--out FILE.jsonl]
#include "fitrun.hpp"
#include "plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

using namespace pmhost;

namespace {

const double DEG = PI / 180, AS = PI / 180 / 3600;
const double LAT = 47;

int g_draws = 8;           // noise draws per design (set per model size)
double g_draw_budget = 1200; // draws = max(8, budget / P): the held-out error's
                             // scatter ~ sqrt(2 / (P draws)) relative
int g_random_seqs = 5;     // random designs
int g_heldout = 1000;      // held-out places
FILE *g_json = nullptr;

// ---------------------------------------------------------------- geometry

double elevation(double ha, double dec) // degrees
{
    return std::asin(std::sin(LAT * DEG) * std::sin(dec * DEG) +
                     std::cos(LAT * DEG) * std::cos(dec * DEG) * std::cos(ha * DEG)) / DEG;
}

double azimuth(double ha, double dec) // degrees, north through east
{
    double h = ha * DEG, d = dec * DEG, f = LAT * DEG;
    double a = std::atan2(-std::sin(h) * std::cos(d),
                          std::sin(d) * std::cos(f) - std::cos(d) * std::cos(h) * std::sin(f)) / DEG;
    return a < 0 ? a + 360 : a;
}

void altaz_to_hadec(double alt, double az, double &ha, double &dec)
{
    double a = alt * DEG, z = az * DEG, f = LAT * DEG;
    double sd = std::sin(a) * std::sin(f) + std::cos(a) * std::cos(f) * std::cos(z);
    dec = std::asin(std::max(-1.0, std::min(1.0, sd))) / DEG;
    ha = std::atan2(-std::sin(z) * std::cos(a),
                    std::sin(a) * std::cos(f) - std::cos(a) * std::cos(z) * std::sin(f)) / DEG;
}

struct Sky {
    Horizon horizon;
    double min_el = 15;
    bool usable(double ha, double dec) const
    {
        double el = elevation(ha, dec);
        return el >= min_el && (horizon.empty() || el >= horizon.at(azimuth(ha, dec)));
    }
};

// A sky position on the GEM's side by the meridian rule, as a design place.
DesignPlace place(double ha, double dec)
{
    DesignPlace p;
    int side = ha > 0 ? -1 : 1;
    double t = ha * DEG, d = dec * DEG;
    if (side < 0)
        t += PI, d = PI - d;
    p.eh = t, p.ed = d;
    p.ctx.pier = side;
    return p;
}

// ---------------------------------------------------------------- designs

std::vector<DesignPlace> golden_spiral(const Sky &s, int n)
{
    for (int total = n;; total++) {
        std::vector<DesignPlace> out;
        for (int k = 0; k < total; k++) {
            double z = 1 - (2.0 * k + 1) / total, ha = std::fmod(k * 137.50776405, 360.0) - 180;
            double dec = std::asin(z) / DEG;
            if (s.usable(ha, dec))
                out.push_back(place(ha, dec));
        }
        if ((int)out.size() >= n) {
            out.resize((size_t)n);
            return out;
        }
    }
}

// MountWizzard4's genGrid: R rings from the lowest altitude to 85 deg, C
// azimuths 180/C + k 360/C; points below the horizon deleted.
std::vector<DesignPlace> mw4_grid(const Sky &s, int rows, int cols)
{
    std::vector<DesignPlace> out;
    double lo = s.min_el, hi = 85;
    for (int r = 0; r < rows; r++) {
        double alt = lo + (hi - lo) * r / (rows - 1);
        for (int c = 0; c < cols; c++) {
            double az = 180.0 / cols + c * 360.0 / cols, ha, dec;
            altaz_to_hadec(alt, az, ha, dec);
            if (s.usable(ha, dec))
                out.push_back(place(ha, dec));
        }
    }
    return out;
}

std::vector<DesignPlace> random_stars(const Sky &s, int n, std::mt19937_64 &rng)
{
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<DesignPlace> out;
    while ((int)out.size() < n) {
        double ha = 180 * u(rng), dec = std::asin(u(rng)) / DEG;
        if (s.usable(ha, dec))
            out.push_back(place(ha, dec));
    }
    return out;
}

// The sky of the criterion (4 deg cells, equal area) and the candidate grid.
std::vector<DesignPlace> sky_grid(const Sky &s, double step)
{
    std::vector<DesignPlace> out;
    for (double y = -90 + step / 2; y < 90; y += step) {
        int nx = std::max(1, (int)std::lround(360 / step * std::cos(y * DEG)));
        for (int k = 0; k < nx; k++) {
            double x = -180 + 360.0 / nx * (k + 0.5);
            if (s.usable(x, y))
                out.push_back(place(x, y));
        }
    }
    return out;
}

// ---------------------------------------------------------------- the truth

struct Setting {
    std::string name;
    Sky sky;
    std::vector<std::string> adds; // physical terms of the model (and the truth)
    double mismatch_arcsec = 0;    // the truth's order L+1 terms: RMS of their displacement
                                   // over the sky (per axis)
    int taken = 0;                 // points already taken (east of the meridian)
};

std::vector<DesignPlace> heldout_places(const Sky &s, int n);

pm_model truth_model(const Setting &st, int order)
{
    std::vector<Obs> none;
    pm_model t = build_model(order + 1, st.adds, none, PM_MOUNT_EQUATORIAL, LAT * DEG, {});
    std::mt19937_64 rng(99 + (unsigned)order);
    std::uniform_real_distribution<double> u(-1, 1);
    std::normal_distribution<double> g(0, 1);
    static const double iso[6] = {60, -40, 600, 30, -300, 20};
    for (int i = 0; i < t.n_terms; i++) {
        if (i < 6)
            t.coef[i] = iso[i] * AS;
        else if (i >= t.n_base)
            t.coef[i] = (t.term[i].l == 0 ? 20 : 10) * AS; // refraction 20", tube flexure 10"
        else if (t.term[i].l <= order)
            t.coef[i] = 15 * u(rng) * AS;
        else
            t.coef[i] = g(rng) * AS;
    }
    // scale the order L+1 terms to the requested RMS displacement over the sky
    pm_model lower = t;
    for (int i = 6; i < t.n_base; i++)
        if (t.term[i].l > order)
            lower.coef[i] = 0;
    pm_model_prepare(&t);
    pm_model_prepare(&lower);
    double ss = 0;
    std::vector<DesignPlace> pl = heldout_places(st.sky, 2000);
    for (const DesignPlace &p : pl) {
        pm_context c = p.ctx;
        double ta, da, tb, db;
        pm_model_apply(&t, &c, p.eh, p.ed, &ta, &da);
        pm_model_apply(&lower, &c, p.eh, p.ed, &tb, &db);
        double e0 = std::remainder(ta - tb, 2 * PI) * std::cos(db), e1 = da - db;
        ss += 0.5 * (e0 * e0 + e1 * e1);
    }
    double rms = std::sqrt(ss / (double)pl.size()) / AS;
    for (int i = 6; i < t.n_base; i++)
        if (t.term[i].l > order)
            t.coef[i] *= rms > 0 ? st.mismatch_arcsec / rms : 0;
    pm_model_prepare(&t);
    return t;
}

struct Truth {
    pm_model model;
    int order;
    const Setting *st;
    std::vector<DesignPlace> heldout;
};

std::vector<DesignPlace> heldout_places(const Sky &s, int n)
{
    std::mt19937_64 rng(7);
    return random_stars(s, n, rng);
}

// Observations of the truth at the places (1" noise per axis), draw k.
std::vector<Obs> observe(const Truth &tr, const std::vector<DesignPlace> &pts, unsigned seed)
{
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0, 1);
    std::vector<Obs> out;
    for (const DesignPlace &p : pts) {
        Obs o;
        o.eh = p.eh, o.ed = p.ed, o.ctx = p.ctx, o.pier = p.ctx.pier, o.line = 0;
        pm_model_apply(&tr.model, &o.ctx, o.eh, o.ed, &o.ah, &o.ad);
        o.ad += AS * g(rng);
        o.ah += AS * g(rng) / std::cos(o.ad);
        out.push_back(o);
    }
    return out;
}

// The held-out error (arcsec, RMS per axis, mean square over draws) of the
// model fitted to observations at pts; NaN if it cannot be fitted.
double heldout_error(const Truth &tr, const std::vector<DesignPlace> &pts)
{
    double ss = 0;
    long n = 0;
    for (int k = 0; k < g_draws; k++) {
        std::vector<Obs> obs = observe(tr, pts, 1000 + (unsigned)k);
        std::vector<int> all(obs.size());
        for (size_t i = 0; i < all.size(); i++)
            all[i] = (int)i;
        pm_model start = build_model(tr.order, tr.st->adds, obs, PM_MOUNT_EQUATORIAL, LAT * DEG, {});
        if (2 * (long)obs.size() <= start.n_terms)
            return NAN;
        FitOut f = do_fit(obs, all, start, 50);
        if (f.status != PM_OK)
            return NAN;
        for (const DesignPlace &p : tr.heldout) {
            pm_context c = p.ctx;
            double ta, da, tb, db;
            if (pm_model_apply(&f.model, &c, p.eh, p.ed, &ta, &da) != PM_OK ||
                pm_model_apply(&tr.model, &c, p.eh, p.ed, &tb, &db) != PM_OK)
                continue;
            double e0 = std::remainder(ta - tb, 2 * PI) * std::cos(db), e1 = da - db;
            ss += 0.5 * (e0 * e0 + e1 * e1);
            n++;
        }
    }
    return n ? std::sqrt(ss / (double)n) / AS : NAN;
}

// ---------------------------------------------------------------- curves

std::vector<int> sample_sizes(int nmin, int nmax)
{
    std::vector<int> ns;
    for (int n = nmin; n <= nmax;) {
        ns.push_back(n);
        n += std::max(1, n / 20);
    }
    if (ns.back() != nmax)
        ns.push_back(nmax);
    return ns;
}

// The smallest N from which the curve stays at or below target (linear
// between samples); NaN if it never does within the samples.
double needed(const std::vector<int> &ns, const std::vector<double> &c, double target)
{
    int last_above = -1;
    for (size_t i = 0; i < ns.size(); i++)
        if (!(c[i] <= target))
            last_above = (int)i;
    if (last_above == (int)ns.size() - 1)
        return NAN;
    if (last_above < 0)
        return ns[0];
    size_t a = (size_t)last_above, b = a + 1;
    if (!std::isfinite(c[a]))
        return ns[b];
    double f = (c[a] - target) / (c[a] - c[b]);
    return std::ceil(ns[a] + f * (ns[b] - ns[a]) - 1e-9);
}

std::string fmt_needed(double n)
{
    char b[32];
    if (std::isnan(n))
        std::snprintf(b, sizeof b, ">max");
    else
        std::snprintf(b, sizeof b, "%.0f", n);
    return b;
}

// ---------------------------------------------------------------- simulated

void simulated(const Setting &st, int order, const std::vector<int> &refs,
               const std::vector<std::pair<int, int>> &grids)
{
    Truth tr;
    tr.order = order;
    tr.st = &st;
    tr.model = truth_model(st, order);
    tr.heldout = heldout_places(st.sky, g_heldout);
    std::vector<Obs> none;
    pm_model ideal = build_model(order, st.adds, none, PM_MOUNT_EQUATORIAL, LAT * DEG, {});
    int P = ideal.n_terms;
    g_draws = std::max(8, (int)(g_draw_budget / P));
    std::vector<DesignPlace> sky = sky_grid(st.sky, 4), cand = sky_grid(st.sky, 6);
    // points already taken: a run's first part, east of the meridian
    std::vector<DesignPlace> taken;
    if (st.taken > 0) {
        std::mt19937_64 rng(3);
        Sky east = st.sky;
        while ((int)taken.size() < st.taken) {
            std::vector<DesignPlace> r = random_stars(east, 1, rng);
            if (r[0].ctx.pier > 0)
                taken.push_back(r[0]);
        }
    }
    int nmax = 0;
    for (int r : refs)
        nmax = std::max(nmax, r);
    for (auto &g : grids)
        nmax = std::max(nmax, g.first * g.second);
    nmax = (int)(nmax * 1.1) + 2;
    int nmin = std::max(1, P / 2 + 1 - (int)taken.size());
    std::vector<int> ns = sample_sizes(nmin, nmax);
    auto with_taken = [&](const std::vector<DesignPlace> &add) {
        std::vector<DesignPlace> v = taken;
        v.insert(v.end(), add.begin(), add.end());
        return v;
    };
    // nested designs: plan (I and D), random sequences
    SlewModel noslew;
    std::vector<double> crit;
    std::vector<int> order_i = greedy_design(ideal, taken, cand, sky, nmax, false, noslew, nullptr, &crit);
    std::vector<int> order_d = greedy_design(ideal, taken, cand, sky, nmax, true, noslew, nullptr, nullptr);
    auto prefix = [&](const std::vector<int> &ord, int n) {
        std::vector<DesignPlace> v;
        for (int i = 0; i < n && i < (int)ord.size(); i++)
            v.push_back(cand[(size_t)ord[(size_t)i]]);
        return with_taken(v);
    };
    std::vector<double> cp, cd, cr, pp, pr;
    std::vector<std::vector<DesignPlace>> rnd;
    for (int k = 0; k < g_random_seqs; k++) {
        std::mt19937_64 rng(500 + (unsigned)k);
        rnd.push_back(random_stars(st.sky, nmax, rng));
    }
    for (int n : ns) {
        cp.push_back(heldout_error(tr, prefix(order_i, n)));
        cd.push_back(heldout_error(tr, prefix(order_d, n)));
        pp.push_back(std::sqrt(design_criterion(ideal, prefix(order_i, n), sky)));
        double s = 0, sp = 0;
        int cnt = 0;
        for (auto &r : rnd) {
            std::vector<DesignPlace> v = with_taken(std::vector<DesignPlace>(r.begin(), r.begin() + n));
            double e = heldout_error(tr, v);
            if (std::isfinite(e)) {
                s += e * e;
                sp += design_criterion(ideal, v, sky);
                cnt++;
            }
        }
        cr.push_back(cnt == (int)rnd.size() ? std::sqrt(s / cnt) : NAN);
        pr.push_back(cnt == (int)rnd.size() ? std::sqrt(sp / cnt) : NAN);
    }
    std::printf("\n%s, order %d (%d terms)%s; %d noise draws:\n", st.name.c_str(), order, P,
                taken.empty() ? "" : (", " + std::to_string(taken.size()) + " points taken").c_str(),
                g_draws);
    std::printf("  %-26s %5s %9s %9s | %-14s %-14s %-14s | %s\n", "reference design", "N",
                "held-out", "predicted", "plan needs", "D-plan needs", "random needs",
                "plan's predicted needs");
    auto report = [&](const std::string &name, const std::vector<DesignPlace> &add) {
        int n = (int)add.size();
        std::vector<DesignPlace> v = with_taken(add);
        double e = heldout_error(tr, v), pe = std::sqrt(design_criterion(ideal, v, sky));
        double np = needed(ns, cp, e), nd = needed(ns, cd, e), nr = needed(ns, cr, e);
        double npp = needed(ns, pp, pe);
        auto pct = [&](double x) {
            char b[48];
            if (std::isnan(x))
                std::snprintf(b, sizeof b, ">%d", ns.back());
            else
                std::snprintf(b, sizeof b, "%.0f (%+.0f%%)", x, 100 * (x / n - 1));
            return std::string(b);
        };
        std::printf("  %-26s %5d %8.3f\" %8.3f\" | %-14s %-14s %-14s | %s\n", name.c_str(), n, e, pe,
                    pct(np).c_str(), pct(nd).c_str(), pct(nr).c_str(), pct(npp).c_str());
        if (g_json)
            std::fprintf(g_json,
                         "{\"kind\": \"simulated\", \"setting\": \"%s\", \"order\": %d, \"taken\": %zu, "
                         "\"reference\": \"%s\", \"n\": %d, \"heldout_arcsec\": %.4f, "
                         "\"predicted_arcsec\": %.4f, \"plan_needs\": %s, \"dplan_needs\": %s, "
                         "\"random_needs\": %s, \"plan_needs_predicted\": %s}\n",
                         json_escape(st.name).c_str(), order, taken.size(), name.c_str(), n,
                         std::isfinite(e) ? e : -1.0, pe,
                         fmt_needed(np) == ">max" ? "null" : fmt_needed(np).c_str(),
                         fmt_needed(nd) == ">max" ? "null" : fmt_needed(nd).c_str(),
                         fmt_needed(nr) == ">max" ? "null" : fmt_needed(nr).c_str(),
                         fmt_needed(npp) == ">max" ? "null" : fmt_needed(npp).c_str());
    };
    for (int r : refs)
        report("golden spiral", golden_spiral(st.sky, r));
    for (auto &g : grids) {
        std::vector<DesignPlace> v = mw4_grid(st.sky, g.first, g.second);
        if (2 * ((int)v.size() + (int)taken.size()) <= P + 2)
            continue;
        report("MW4 grid " + std::to_string(g.first) + "x" + std::to_string(g.second), v);
    }
    for (int r : refs) {
        std::mt19937_64 rng(900 + (unsigned)r);
        report("random stars", random_stars(st.sky, r, rng));
    }
}

// ---------------------------------------------------------------- real runs

double sky_dist(const Obs &a, const Obs &b)
{
    double c = std::sin(a.ad) * std::sin(b.ad) + std::cos(a.ad) * std::cos(b.ad) * std::cos(a.ah - b.ah);
    return std::acos(std::max(-1.0, std::min(1.0, c)));
}

// Per-axis RMS residual of the model fitted (order, no added terms) to the
// points `use` on the others; NaN if the fit fails.
double cv_error(const Run &run, int order, const std::vector<int> &use)
{
    pm_model start = build_model(order, {}, run.obs, run.mount, run.latitude, run.aux_names);
    if (2 * (long)use.size() <= start.n_terms + 2)
        return NAN;
    FitOut f = do_fit(run.obs, use, start, 50);
    if (f.status != PM_OK)
        return NAN;
    std::vector<char> in(run.obs.size(), 0);
    for (int i : use)
        in[(size_t)i] = 1;
    double ss = 0;
    long n = 0;
    for (size_t i = 0; i < run.obs.size(); i++) {
        if (in[i])
            continue;
        const Obs &o = run.obs[i];
        double r[2];
        if (pm_model_residual(&f.model, &o.ctx, o.eh, o.ed, o.ah, o.ad, r) != PM_OK)
            continue;
        ss += r[0] * r[0] + r[1] * r[1];
        n++;
    }
    return n ? std::sqrt(ss / (double)(2 * n)) / AS : NAN;
}

void real_run(const std::string &path, const std::string &label)
{
    Run run;
    try {
        run = load_run(path);
    } catch (const std::exception &x) {
        std::printf("\n%s: skipped (%s)\n", label.c_str(), x.what());
        return;
    }
    int total = (int)run.obs.size();
    std::vector<DesignPlace> cand;
    for (const Obs &o : run.obs) {
        DesignPlace p;
        p.eh = o.eh, p.ed = o.ed, p.ctx = o.ctx;
        cand.push_back(p);
    }
    // evenly spread: farthest-point sampling from the highest point
    std::vector<int> spread;
    {
        std::vector<double> dmin((size_t)total, 1e9);
        int first = 0;
        for (int i = 0; i < total; i++)
            if (run.obs[(size_t)i].ad > run.obs[(size_t)first].ad && run.mount == PM_MOUNT_ALTAZ)
                first = i;
        if (run.mount != PM_MOUNT_ALTAZ) { // the highest: nearest the zenith
            double best = -2;
            for (int i = 0; i < total; i++) {
                const Obs &o = run.obs[(size_t)i];
                double el = std::sin(run.latitude) * std::sin(o.ad) +
                            std::cos(run.latitude) * std::cos(o.ad) * std::cos(o.ah);
                if (el > best)
                    best = el, first = i;
            }
        }
        int cur = first;
        for (int k = 0; k < total; k++) {
            spread.push_back(cur);
            int next = -1;
            double far = -1;
            for (int i = 0; i < total; i++) {
                dmin[(size_t)i] = std::min(dmin[(size_t)i], sky_dist(run.obs[(size_t)i], run.obs[(size_t)cur]));
                if (dmin[(size_t)i] > far)
                    far = dmin[(size_t)i], next = i;
            }
            if (k + 1 < total)
                cur = next;
        }
    }
    std::printf("\n%s (%d points, %s): cross-validated RMS per axis on the points not chosen\n",
                label.c_str(), total, run.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial");
    std::printf("  %-6s %5s %10s %10s %10s | %-14s %-14s\n", "order", "N", "spread", "random",
                "plan", "plan needs", "random needs");
    for (int order = 0; order <= 2; order++) {
        pm_model ideal = build_model(order, {}, run.obs, run.mount, run.latitude, run.aux_names);
        int P = ideal.n_terms;
        int nmax = std::min(total * 2 / 3, std::max(4 * P, P / 2 + 10));
        int nmin = P / 2 + 2;
        if (nmin + 4 > nmax)
            continue;
        SlewModel noslew;
        std::vector<int> plan = greedy_design(ideal, {}, cand, cand, nmax, false, noslew, nullptr, nullptr);
        std::vector<int> ns = sample_sizes(nmin, nmax);
        std::vector<double> cp, cs, cr;
        std::vector<std::vector<int>> perms;
        for (int k = 0; k < 20; k++) {
            std::vector<int> p((size_t)total);
            for (int i = 0; i < total; i++)
                p[(size_t)i] = i;
            std::mt19937_64 rng(700 + (unsigned)k);
            std::shuffle(p.begin(), p.end(), rng);
            perms.push_back(p);
        }
        for (int n : ns) {
            cp.push_back(cv_error(run, order, std::vector<int>(plan.begin(), plan.begin() + n)));
            cs.push_back(cv_error(run, order, std::vector<int>(spread.begin(), spread.begin() + n)));
            double s = 0;
            int cnt = 0;
            for (auto &p : perms) {
                double e = cv_error(run, order, std::vector<int>(p.begin(), p.begin() + n));
                if (std::isfinite(e))
                    s += e * e, cnt++;
            }
            cr.push_back(cnt >= 15 ? std::sqrt(s / cnt) : NAN);
        }
        // references: the evenly spread subset at 2P/2 .. 4P/2 points
        for (int mult : {2, 3, 4}) {
            int nref = std::min(nmax, mult * P / 2 + 2);
            size_t i = 0;
            while (i + 1 < ns.size() && ns[i] < nref)
                i++;
            nref = ns[i];
            double e = cs[i];
            double np = needed(ns, cp, e), nr = needed(ns, cr, e);
            auto pct = [&](double x) {
                char b[48];
                if (std::isnan(x))
                    std::snprintf(b, sizeof b, ">%d", ns.back());
                else
                    std::snprintf(b, sizeof b, "%.0f (%+.0f%%)", x, 100 * (x / nref - 1));
                return std::string(b);
            };
            std::printf("  %-6d %5d %9.3f\" %9.3f\" %9.3f\" | %-14s %-14s\n", order, nref, e, cr[i],
                        cp[i], pct(np).c_str(), pct(nr).c_str());
            if (g_json)
                std::fprintf(g_json,
                             "{\"kind\": \"real\", \"run\": \"%s\", \"order\": %d, \"n\": %d, "
                             "\"spread_cv_arcsec\": %.4f, \"random_cv_arcsec\": %.4f, "
                             "\"plan_cv_arcsec\": %.4f, \"plan_needs\": %s, \"random_needs\": %s}\n",
                             label.c_str(), order, nref, std::isfinite(e) ? e : -1.0,
                             std::isfinite(cr[i]) ? cr[i] : -1.0, std::isfinite(cp[i]) ? cp[i] : -1.0,
                             std::isnan(np) ? "null" : fmt_needed(np).c_str(),
                             std::isnan(nr) ? "null" : fmt_needed(nr).c_str());
            if (nref == ns.back())
                break;
        }
    }
}

} // namespace

int main(int argc, char **argv)
{
    std::string data = "../shared/data", out;
    bool quick = false;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--quick")
            quick = true;
        else if (a == "--data" && i + 1 < argc)
            data = argv[++i];
        else if (a == "--out" && i + 1 < argc)
            out = argv[++i];
        else {
            std::fprintf(stderr, "usage: pmbench_plan [--quick] [--data DIR] [--out FILE.jsonl]\n");
            return 2;
        }
    }
    if (quick)
        g_draw_budget = 150, g_random_seqs = 3, g_heldout = 400;
    if (!out.empty() && !(g_json = std::fopen(out.c_str(), "w"))) {
        std::perror(out.c_str());
        return 1;
    }
    std::printf("pmbench_plan: points needed for the reference design's error (held-out against "
                "the truth at %d places, 1\" noise; random: %d sequences)\n", g_heldout,
                g_random_seqs);
    // the reference sizes per order, and MountWizzard4 grids (rows x cols)
    const std::vector<int> refs[3] = {{12, 24}, {30, 60}, {70, 140}};
    const std::vector<std::pair<int, int>> grids[3] = {
        {{3, 4}, {4, 6}, {5, 6}},
        {{4, 8}, {5, 8}, {6, 10}, {7, 12}},
        {{6, 12}, {7, 12}, {8, 14}}};
    Setting full{"full sky (horizon 15 deg)", Sky(), {}, 0, 0};
    Setting beyond{"full sky, truth beyond the model (order L+1 terms, 1\" RMS)", Sky(), {}, 1, 0};
    Setting strong{"full sky, truth far beyond the model (order L+1 terms, 3\" RMS)", Sky(), {}, 3, 0};
    Setting partial = beyond;
    partial.name = "partial sky (buildings east and north to 40-50 deg), truth beyond the model";
    partial.sky.horizon.path = "(built in)";
    partial.sky.horizon.pts = {{0, 45}, {60, 45}, {100, 50}, {130, 15}, {300, 15}, {330, 40}};
    // physical terms: refraction and, at order 0, tube flexure (at order >= 1
    // tube flexure is a combination of the order-1 terms: docs/explain.md)
    Setting physical = beyond;
    for (int order = 0; order <= 2; order++) {
        simulated(full, order, refs[order], grids[order]);
        simulated(beyond, order, refs[order], grids[order]);
        simulated(strong, order, refs[order], grids[order]);
        simulated(partial, order, refs[order], grids[order]);
        Setting taken = beyond;
        taken.name = "points already taken (east only), truth beyond the model";
        taken.taken = order == 0 ? 6 : order == 1 ? 15 : 30;
        simulated(taken, order, refs[order], grids[order]);
        physical.name = order == 0 ? "order 0 + refraction + tube flexure, truth beyond the model"
                                   : "order L + refraction, truth beyond the model";
        physical.adds = order == 0 ? std::vector<std::string>{"refraction", "tube_flexure"}
                                   : std::vector<std::string>{"refraction"};
        if (!quick)
            simulated(physical, order, refs[order], grids[order]);
    }
    real_run(data + "/mmt/k_and_e.dat", "MMT k_and_e");
    real_run(data + "/celestial/cgx-l-data.dat", "cgx-l");
    real_run(data + "/celestial/gem-28.dat", "gem-28");
    if (g_json)
        std::fclose(g_json);
    return 0;
}
