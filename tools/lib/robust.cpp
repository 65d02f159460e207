// robust.cpp - iterative clipping with a median-based scale, started from a
// least-trimmed-squares half fit (docs/robust.md).
#include "robust.hpp"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <numeric>

namespace pmhost {

namespace {

// Median of |r| / sqrt(2 ln 2) is sigma for Rayleigh-distributed |r|.
const double RAYLEIGH_MEDIAN = 1.1774100225154747; // sqrt(2 ln 2)

double median(std::vector<double> v)
{
    if (v.empty())
        return 0;
    size_t h = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + (long)h, v.end());
    double m = v[h];
    if (v.size() % 2 == 0) {
        std::nth_element(v.begin(), v.begin() + (long)h - 1, v.end());
        m = 0.5 * (m + v[h - 1]);
    }
    return m;
}

// Residuals of model at the observations use (rad); false if one fails.
bool all_residuals(const pm_model &m, const std::vector<Obs> &obs, const std::vector<int> &use,
                   std::vector<double> &r0, std::vector<double> &r1, std::vector<double> &rho)
{
    r0.assign(use.size(), 0);
    r1.assign(use.size(), 0);
    rho.assign(use.size(), 0);
    for (size_t j = 0; j < use.size(); j++) {
        const Obs &o = obs[use[j]];
        double r[2];
        if (pm_model_residual(&m, &o.ctx, o.eh, o.ed, o.ah, o.ad, r) != PM_OK)
            return false;
        r0[j] = r[0];
        r1[j] = r[1];
        rho[j] = std::hypot(r[0], r[1]);
    }
    return true;
}

// sqrt(2M/(2M-P)): a fit's residuals are smaller than the noise by this on average.
double shrinkage(size_t m, int p)
{
    double e = 2.0 * (double)m;
    return e > p ? std::sqrt(e / (e - p)) : 1.0;
}

// Standardised residual distances of every observation of use about the fit
// of the kept ones, d^2 = r^T C^-1 r with C = I - H_ii for a kept point (its
// residual is shrunk by its own weight in the fit) and C = I + H_ii for a
// rejected one (the uncertainty of the prediction), H_ii = J_i (J^T J)^-1 J_i^T
// over the kept points: under Gaussian noise every d^2/sigma^2 is chi^2 with 2
// degrees of freedom, so one threshold serves kept and rejected points alike
// and a rejected point with high leverage is not kept out by its own absence.
// False if the normal matrix cannot be factorised.
bool standardised(const pm_model &m, const std::vector<Obs> &obs, const std::vector<int> &use,
                  const std::vector<char> &keep, std::vector<double> &d)
{
    const size_t n = use.size();
    const int p = m.n_terms;
    std::vector<double> J(n * 2 * (size_t)p), R(2 * n);
    for (size_t j = 0; j < n; j++) {
        const Obs &o = obs[use[j]];
        double *row0 = &J[(2 * j) * (size_t)p], *row1 = row0 + p;
        if (pm_fit_row(&m, &o.ctx, o.eh, o.ed, o.ah, o.ad, row0, row1, &R[2 * j]) != PM_OK)
            return false;
    }
    // normal matrix of the kept points, equilibrated, Cholesky (lower)
    std::vector<double> A((size_t)p * p, 0.0), sc(p, 1.0);
    for (size_t j = 0; j < n; j++)
        if (keep[j])
            for (int q = 0; q < 2; q++) {
                const double *row = &J[(2 * j + q) * (size_t)p];
                for (int a = 0; a < p; a++)
                    for (int b = 0; b <= a; b++)
                        A[(size_t)a * p + b] += row[a] * row[b];
            }
    for (int a = 0; a < p; a++) {
        if (!(A[(size_t)a * p + a] > 0))
            return false;
        sc[a] = 1 / std::sqrt(A[(size_t)a * p + a]);
    }
    for (int a = 0; a < p; a++)
        for (int b = 0; b <= a; b++)
            A[(size_t)a * p + b] *= sc[a] * sc[b];
    for (int a = 0; a < p; a++) {
        for (int b = 0; b <= a; b++) {
            double v = A[(size_t)a * p + b];
            for (int c = 0; c < b; c++)
                v -= A[(size_t)a * p + c] * A[(size_t)b * p + c];
            if (a == b) {
                if (!(v > 1e-13))
                    return false;
                A[(size_t)a * p + a] = std::sqrt(v);
            } else {
                A[(size_t)a * p + b] = v / A[(size_t)b * p + b];
            }
        }
    }
    d.assign(n, 0);
    std::vector<double> u0(p), u1(p);
    for (size_t j = 0; j < n; j++) {
        // u = L^-1 (scaled row): H_ii = [u0.u0 u0.u1; u1.u0 u1.u1]
        for (int q = 0; q < 2; q++) {
            const double *row = &J[(2 * j + q) * (size_t)p];
            std::vector<double> &u = q ? u1 : u0;
            for (int a = 0; a < p; a++) {
                double v = row[a] * sc[a];
                for (int c = 0; c < a; c++)
                    v -= A[(size_t)a * p + c] * u[c];
                u[a] = v / A[(size_t)a * p + a];
            }
        }
        double h00 = 0, h01 = 0, h11 = 0;
        for (int a = 0; a < p; a++) {
            h00 += u0[a] * u0[a];
            h01 += u0[a] * u1[a];
            h11 += u1[a] * u1[a];
        }
        double sgn = keep[j] ? -1 : 1;
        double c00 = 1 + sgn * h00, c01 = sgn * h01, c11 = 1 + sgn * h11;
        double det = c00 * c11 - c01 * c01;
        double r0 = R[2 * j], r1 = R[2 * j + 1];
        if (!(det > 1e-9)) { // a kept point that alone determines a term: cannot be judged
            d[j] = 0;
            continue;
        }
        d[j] = std::sqrt(std::max(0.0, (c11 * r0 * r0 - 2 * c01 * r0 * r1 + c00 * r1 * r1) / det));
    }
    return true;
}

// A least-trimmed-squares solution: the model fitted to the h points of
// smallest residual, its objective q (the sum of those h squared residuals).
struct Lts {
    bool ok = false;
    pm_model model = pm_model();
    double q = 0;
    std::vector<int> hs; // the h points (indices into the run), sorted
};

// The h points of use with the smallest residual under m, and their sum of
// squared residuals; false if a residual fails.
bool smallest(const pm_model &m, const std::vector<Obs> &obs, const std::vector<int> &use,
              size_t h, std::vector<int> &hs, double &q)
{
    std::vector<double> r0, r1, rho;
    if (!all_residuals(m, obs, use, r0, r1, rho))
        return false;
    std::vector<size_t> ord(use.size());
    std::iota(ord.begin(), ord.end(), 0);
    std::stable_sort(ord.begin(), ord.end(), [&](size_t a, size_t b) { return rho[a] < rho[b]; });
    hs.clear();
    q = 0;
    for (size_t j = 0; j < h; j++) {
        hs.push_back(use[ord[j]]);
        q += rho[ord[j]] * rho[ord[j]];
    }
    std::sort(hs.begin(), hs.end());
    return true;
}

// Concentration steps (Rousseeuw & Van Driessen's C-step) from model m: fit
// the h points of smallest residual, repeat until that set is unchanged or
// after `steps` fits.  Not ok if a fit of a half fails.
Lts concentrate(const std::vector<Obs> &obs, const std::vector<int> &use, size_t h,
                const pm_model &m, int max_passes, int steps)
{
    Lts l;
    l.model = m;
    std::vector<int> hs;
    double q;
    for (int step = 0; step < steps; step++) {
        if (!smallest(l.model, obs, use, h, hs, q))
            return l;
        if (step > 0 && hs == l.hs)
            break;
        FitOut g = do_fit(obs, hs, l.model, max_passes);
        if (g.status != PM_OK)
            return l;
        l.model = g.model;
        l.hs = hs;
    }
    l.ok = smallest(l.model, obs, use, h, hs, l.q);
    return l;
}

// The scale of the first kept set: from the best hh points' median, i.e.
// the quantile q = (hh/2 + 1/2)/N of |r| over all (Rayleigh: sigma
// sqrt(-2 ln(1-q))), for the hh points' fit of p terms.
double first_scale(std::vector<double> rho, size_t hh, int p)
{
    std::sort(rho.begin(), rho.end());
    const size_t j = hh / 2;
    const double q = ((double)j + 0.5) / (double)rho.size();
    return rho[j] / std::sqrt(-2 * std::log(1 - q)) * shrinkage(hh, p);
}

// Does m leave a point of use beyond clip times the first scale of its h
// best?  (True where a residual fails.)
bool beyond_first_threshold(const pm_model &m, const std::vector<Obs> &obs,
                            const std::vector<int> &use, size_t h, int p, double clip)
{
    std::vector<double> r0, r1, rho;
    if (!all_residuals(m, obs, use, r0, r1, rho))
        return true;
    const double lim = clip * first_scale(rho, h, p);
    return std::any_of(rho.begin(), rho.end(), [lim](double x) { return x > lim; });
}

// The start that a cluster of gross errors cannot bend: order-0 fits (the
// six isotropic terms, which carry nearly all of a mount's pointing) of
// random four-point subsets, the ten of least trimmed objective followed by
// two concentration steps at order 0; the best of them, its h points
// fitted with the full model and concentrated to the end.  A least-squares fit of
// all points leans towards a cluster of failed solves all off the same way
// (20% of a run in one part of the sky: clipping from it kept part of the
// cluster and rejected 32 good points, an outside probe), while one of
// these subsets is clean with probability (1 - f)^4 for a fraction f of
// gross errors: 0.13 at f = 0.4, so that 60 subsets miss with probability
// 2e-4.  The subsets come from a fixed generator seeded by the run's size:
// the same run gives the same fit.
Lts order0_start(const std::vector<Obs> &obs, const std::vector<int> &use, size_t h,
                 const pm_model &start, int max_passes)
{
    Lts best;
    const size_t n = use.size();
    pm_model m0;
    if (n < 8 || pm_model_init(&m0, start.mount, 0) != PM_OK)
        return best;
    m0.latitude = start.latitude;
    if (pm_model_prepare(&m0) != PM_OK)
        return best;
    uint64_t state = 0x9e3779b97f4a7c15ull ^ (uint64_t)n;
    auto next = [&]() { // splitmix64
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    };
    // each subset's fit judged by its trimmed objective; the best ten of
    // them concentrated two steps (Rousseeuw & Van Driessen's selection)
    std::vector<std::pair<double, pm_model>> cand;
    for (int s = 0; s < 60; s++) {
        std::vector<int> sub, hs;
        while (sub.size() < 4) {
            int k = use[(size_t)(next() % n)];
            if (std::find(sub.begin(), sub.end(), k) == sub.end())
                sub.push_back(k);
        }
        FitOut g = do_fit(obs, sub, m0, max_passes);
        double q;
        if (g.status == PM_OK && smallest(g.model, obs, use, h, hs, q))
            cand.emplace_back(q, g.model);
    }
    std::stable_sort(cand.begin(), cand.end(),
                     [](const std::pair<double, pm_model> &x,
                        const std::pair<double, pm_model> &y) { return x.first < y.first; });
    Lts b0;
    for (size_t k = 0; k < cand.size() && k < 10; k++) {
        Lts l = concentrate(obs, use, h, cand[k].second, max_passes, 2);
        if (l.ok && (!b0.ok || l.q < b0.q))
            b0 = l;
    }
    if (!b0.ok)
        return best;
    FitOut g = do_fit(obs, b0.hs, start, max_passes);
    if (g.status != PM_OK)
        return best;
    return concentrate(obs, use, h, g.model, max_passes, 30);
}

// The threshold K' on d / s for a scale s estimated with nu degrees of
// freedom that rejects a clean point as often as K does for the true sigma:
// d^2 / (2 s^2) is F(2, nu), P(d > K' s) = (1 + K'^2/nu)^(-nu/2), set equal
// to exp(-K^2/2).  K itself for nu <= 0 or large nu.
double studentised_clip(double clip, double nu)
{
    if (!(nu > 0))
        return clip;
    const double x = clip * clip / nu; // K'^2 = nu (exp(K^2/nu) - 1)
    return x < 1e-12 ? clip : std::sqrt(nu * std::expm1(x));
}

std::vector<int> pick(const std::vector<int> &use, const std::vector<char> &keep)
{
    std::vector<int> k;
    for (size_t j = 0; j < use.size(); j++)
        if (keep[j])
            k.push_back(use[j]);
    return k;
}

} // namespace

std::vector<int> robust_suspects(const FitOut &f, const std::vector<Obs> &obs, double clip,
                                 int max_passes)
{
    if (f.status != PM_OK || f.idx.empty())
        return {};
    RobustFit rf = robust_fit(obs, f.idx, f.model, clip, max_passes);
    if (!rf.error.empty() || rf.fit.status != PM_OK)
        return {};
    return rf.outliers;
}

RobustFit robust_fit(const std::vector<Obs> &obs, const std::vector<int> &use,
                     const pm_model &start, double clip, int max_passes, int max_rounds)
{
    RobustFit rf;
    rf.use = use;
    rf.clip = clip;
    const size_t n = use.size();
    const int p = start.n_terms;
    auto too_few = [&](size_t kept) {
        rf.error = "a robust fit needs at least as many observations as terms (P = " +
                   std::to_string(p) + ", so that every point is judged against a model the " +
                   "others over-determine); " +
                   (kept == n ? std::string("the run has ") + std::to_string(n)
                              : "clipping at " + std::to_string(clip).substr(0, 4) +
                                    " sigma would leave " + std::to_string(kept) + " of " +
                                    std::to_string(n)) +
                   " (lower --order, or add points)";
    };
    if ((long)n < p) {
        too_few(n);
        return rf;
    }
    // 1. least squares on all points
    rf.fit = do_fit(obs, use, start, max_passes);
    if (rf.fit.status != PM_OK)
        return rf;
    pm_model model = rf.fit.model;
    std::vector<double> r0, r1, rho, dist;

    // 2. the start: concentration steps of least trimmed squares on h points,
    //    from the fit of all points and from the best of order-0 fits of
    //    random four-point subsets (docs/robust.md)
    size_t h = std::max((n + 1) / 2, (size_t)p);
    rf.lts_start = h < n;
    if (rf.lts_start) {
        Lts a = concentrate(obs, use, h, rf.fit.model, max_passes, 30);
        // the subsets' start where the first leaves a point beyond the
        // threshold (a run it leaves none in has nothing to clip, and the
        // subsets cost more than the rest of the robust fit: 60 fits and
        // their concentration steps), and taken only where its half fits
        // far better (a tenth of the objective): behind a cluster of gross
        // errors the fit of all points leaves one of 1e-4 or less (an
        // outside probe's runs), while a run of broad, heavy-tailed
        // residuals has halves of either start within a factor of a few
        // (gem-28 0.86 at L=1, cgx-l 0.40), and what it keeps is for the
        // fit's model terms and explain to read, not gross errors to clip
        // (docs/robust.md)
        if (!a.ok || beyond_first_threshold(a.model, obs, use, h, p, clip)) {
            Lts b = order0_start(obs, use, h, start, max_passes);
            if (b.ok && (!a.ok || b.q < 0.1 * a.q))
                a = b;
        }
        if (a.ok)
            model = a.model;
        else // singular on every half: start from all points
            rf.lts_start = false;
    }

    // the first kept set: within the first threshold (first_scale)
    if (!all_residuals(model, obs, use, r0, r1, rho)) {
        rf.fit.status = PM_ERR_NONFINITE;
        return rf;
    }
    std::vector<char> keep(n, 1);
    {
        const double sig = first_scale(rho, rf.lts_start ? h : n, p);
        for (size_t i = 0; i < n; i++)
            keep[i] = rho[i] <= clip * sig;
    }

    // 3. clipping rounds until the kept set is stable
    rf.stable = false;
    bool phase2 = false;
    for (rf.rounds = 1; rf.rounds <= max_rounds; rf.rounds++) {
        size_t kept = (size_t)std::count(keep.begin(), keep.end(), (char)1);
        if ((long)kept < p) {
            too_few(kept);
            break;
        }
        if (2 * kept < n) {
            rf.error = "clipping at " + std::to_string(clip).substr(0, 4) + " sigma rejects " +
                       std::to_string(n - kept) + " of " + std::to_string(n) +
                       " observations, more than half: no majority of the run follows one model, "
                       "so no model can be trusted (mixed runs, a wrong site or mount type, a "
                       "slipping axis?); check the run, or use a larger --clip";
            break;
        }
        std::vector<int> k = pick(use, keep);
        FitOut g = do_fit(obs, k, model, max_passes);
        if (g.status != PM_OK) // nearly degenerate terms: from the previous solution the
            g = do_fit(obs, k, start, max_passes); // valley may be longer than from the start
        if (g.status != PM_OK) {
            rf.fit = g;
            return rf;
        }
        model = g.model;
        rf.fit = g;
        if (!all_residuals(model, obs, use, r0, r1, rho)) {
            rf.fit.status = PM_ERR_NONFINITE;
            return rf;
        }
        // standardised distances (without the normal matrix: |r| and the
        // average shrinkage sqrt(2M/(2M-P)) instead)
        bool std_ok = standardised(model, obs, use, keep, dist);
        if (!std_ok)
            dist = rho;
        std::vector<double> kr;
        double ss = 0;
        for (size_t i = 0; i < n; i++)
            if (keep[i]) {
                kr.push_back(dist[i]);
                ss += dist[i] * dist[i];
            }
        double shrink = std_ok ? 1.0 : shrinkage(kept, p);
        // phase 1: the median (robust while gross errors may still be kept);
        // phase 2, once that set is stable: the RMS of the kept distances,
        // corrected for the truncation at clip (twice as precise: sigma of
        // the median is 0.72 sigma/sqrt(N), of the RMS 0.35 sigma/sqrt(N)).
        // The final threshold on d / sigma_robust: the scale is estimated
        // from 2M - P degrees of freedom, so a rejected point's ratio has
        // the tail of F(2, nu), not of chi^2(2): at nu = 38 (30 points,
        // L = 1) K = 4.29 rejected a clean point with probability 5.5e-4,
        // not 1e-4 (an outside probe: 7 of 9000).  (The median's rounds
        // only find the set the RMS rounds start from.)
        const double k_rms = studentised_clip(clip, 2.0 * (double)kept - p), k_med = clip;
        // E[d^2 | d < K sigma] / E[d^2] for d^2/sigma^2 ~ chi^2(2)
        const double e = std::exp(-k_rms * k_rms / 2);
        const double trunc = 1 - (k_rms * k_rms / 2) * e / (1 - e);
        double s_med = median(kr) / RAYLEIGH_MEDIAN * shrink;
        double s_rms = std::sqrt(ss / (2.0 * (double)kept) / trunc) * shrink;
        auto decide = [&](double threshold) {
            std::vector<char> v(n);
            for (size_t i = 0; i < n; i++)
                v[i] = dist[i] <= threshold;
            return v;
        };
        rf.sigma_robust = phase2 ? s_rms : s_med;
        std::vector<char> nk = decide(phase2 ? k_rms * s_rms : k_med * s_med);
        if (nk == keep && !phase2) {
            phase2 = true;
            rf.sigma_robust = s_rms;
            nk = decide(k_rms * s_rms);
        }
        if (nk == keep) {
            rf.stable = true;
            break;
        }
        keep = nk;
    }
    if (rf.rounds > max_rounds) {
        // still changing (a point on the threshold flipping): fit the last set,
        // so that the model, sigma and the rejected list belong together
        rf.rounds = max_rounds;
        FitOut g = do_fit(obs, pick(use, keep), model, max_passes);
        if (g.status != PM_OK)
            g = do_fit(obs, pick(use, keep), start, max_passes);
        if (g.status != PM_OK) {
            rf.fit = g;
            return rf;
        }
        rf.fit = g;
        if (!all_residuals(g.model, obs, use, r0, r1, rho)) {
            rf.fit.status = PM_ERR_NONFINITE;
            return rf;
        }
        if (!standardised(g.model, obs, use, keep, dist))
            dist = rho;
    }
    rf.r0 = r0;
    rf.r1 = r1;
    rf.dist = dist;
    rf.rejected.assign(n, 0);
    for (size_t i = 0; i < n; i++)
        if (!keep[i]) {
            rf.rejected[i] = 1;
            rf.outliers.push_back(use[i]);
        }
    std::sort(rf.outliers.begin(), rf.outliers.end(),
              [&](int a, int b) { return obs[a].line < obs[b].line; });
    return rf;
}

} // namespace pmhost
