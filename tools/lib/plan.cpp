// plan.cpp - which star next (plan.hpp).
//
// The fitted model's covariance is sigma^2 A^-1 with A = sum J^T J over the
// points taken (two rows J per point, pm_fit_row at the model's own
// prediction); its predicted variance at a place g is sigma^2 tr(J_g A^-1
// J_g^T) / 2 per axis.  The I-optimal criterion is the mean of that over
// the usable sky, sigma^2 tr(W A^-1) / 2 with W the (weighted) mean of
// J_g^T J_g.  Taking a point x (rows J) changes A^-1 by -M S^-1 M^T
// (M = A^-1 J^T, S = I + J M: Woodbury), so the criterion falls by
// tr(S^-1 M^T W M) / 2, and log det A rises by log det S (the D-optimal
// criterion): greedy, the best candidate (per second of slewing and
// observing when the slew time is weighed), update, repeat.
#include "plan.hpp"
#include "hostutil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace pmhost {

namespace {

const double DEG = PI / 180;

// A design place with its two rows.
struct Rowed {
    DesignPlace p;
    double row[2][PM_MAX_TERMS];
};

bool eval_rows(const pm_model &m, Rowed &r)
{
    double T, D, res[2];
    return pm_model_apply(&m, &r.p.ctx, r.p.eh, r.p.ed, &T, &D) == PM_OK &&
           pm_fit_row(&m, &r.p.ctx, r.p.eh, r.p.ed, T, D, r.row[0], r.row[1], res) == PM_OK;
}

std::vector<Rowed> with_rows(const pm_model &m, const std::vector<DesignPlace> &v,
                             std::vector<int> *kept = nullptr)
{
    std::vector<Rowed> out;
    out.reserve(v.size());
    for (size_t i = 0; i < v.size(); i++) {
        Rowed r;
        r.p = v[i];
        if (eval_rows(m, r)) {
            out.push_back(r);
            if (kept)
                kept->push_back((int)i);
        }
    }
    return out;
}

// Inverse of the symmetric positive definite n x n matrix a (Cholesky).
bool spd_inverse(std::vector<double> &a, int n)
{
    std::vector<double> l((size_t)(n * n), 0.0);
    for (int j = 0; j < n; j++) {
        double s = a[(size_t)(j * n + j)];
        for (int k = 0; k < j; k++)
            s -= l[(size_t)(j * n + k)] * l[(size_t)(j * n + k)];
        if (!(s > 0))
            return false;
        l[(size_t)(j * n + j)] = std::sqrt(s);
        for (int i = j + 1; i < n; i++) {
            double t = a[(size_t)(i * n + j)];
            for (int k = 0; k < j; k++)
                t -= l[(size_t)(i * n + k)] * l[(size_t)(j * n + k)];
            l[(size_t)(i * n + j)] = t / l[(size_t)(j * n + j)];
        }
    }
    // inverse of L, then L^-T L^-1
    std::vector<double> li((size_t)(n * n), 0.0);
    for (int i = 0; i < n; i++) {
        li[(size_t)(i * n + i)] = 1 / l[(size_t)(i * n + i)];
        for (int j = 0; j < i; j++) {
            double s = 0;
            for (int k = j; k < i; k++)
                s -= l[(size_t)(i * n + k)] * li[(size_t)(k * n + j)];
            li[(size_t)(i * n + j)] = s / l[(size_t)(i * n + i)];
        }
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) {
            double s = 0;
            for (int k = i; k < n; k++)
                s += li[(size_t)(k * n + i)] * li[(size_t)(k * n + j)];
            a[(size_t)(i * n + j)] = a[(size_t)(j * n + i)] = s;
        }
    return true;
}

struct Design {
    int P = 0;
    std::vector<double> ainv, w; // A^-1 and W (P x P)
    double f = 0;                // tr(W A^-1) / 2
};

// A from the rows of `taken` plus a ridge, W from the sky (weighted mean).
// The ridge keeps A invertible before the points determine the model: a
// direction they leave free gets a variance of 1/ridge.
void add_rows(std::vector<double> &m, const Rowed &p, double wt, int P)
{
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++)
            m[(size_t)(i * P + j)] += wt * (p.row[0][i] * p.row[0][j] + p.row[1][i] * p.row[1][j]);
}

const double RIDGE = 1e-8;

// A^-1 and the criterion for the places `taken`, with W of d (kept).
void design_taken(Design &d, const std::vector<const Rowed *> &taken, double ridge = RIDGE)
{
    const int P = d.P;
    std::vector<double> a((size_t)(P * P), 0.0);
    for (const Rowed *p : taken)
        add_rows(a, *p, 1.0, P);
    for (int i = 0; i < P; i++)
        a[(size_t)(i * P + i)] += ridge;
    if (!spd_inverse(a, P))
        throw std::runtime_error("plan: the design is singular");
    d.ainv = a;
    d.f = 0;
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++)
            d.f += d.w[(size_t)(i * P + j)] * d.ainv[(size_t)(j * P + i)] / 2;
}

Design design(const std::vector<Rowed> &taken, const std::vector<Rowed> &sky, int P,
              double ridge = RIDGE)
{
    Design d;
    d.P = P;
    std::vector<double> a((size_t)(P * P), 0.0);
    d.w.assign((size_t)(P * P), 0.0);
    auto add = [&](std::vector<double> &m, const Rowed &p, double wt) { add_rows(m, p, wt, P); };
    double wsum = 0;
    for (const Rowed &p : sky)
        wsum += p.p.weight;
    for (const Rowed &p : taken)
        add(a, p, 1.0);
    for (const Rowed &p : sky)
        add(d.w, p, p.p.weight / wsum);
    for (int i = 0; i < P; i++)
        a[(size_t)(i * P + i)] += ridge;
    if (!spd_inverse(a, P))
        throw std::runtime_error("plan: the design is singular");
    d.ainv = a;
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++)
            d.f += d.w[(size_t)(i * P + j)] * d.ainv[(size_t)(j * P + i)] / 2;
    return d;
}

// Scratch of the gain computation (no allocation per candidate).
struct Scratch {
    std::vector<double> M, wm;
    double si[4];
    double logdet;
};

// The fall of the I criterion by taking place p; M = A^-1 J^T and S^-1 in
// sc, and log det S (the rise of log det A).
double gain(const Design &d, const Rowed &p, Scratch &sc)
{
    int P = d.P;
    std::vector<double> &M = sc.M, &wm = sc.wm;
    M.assign((size_t)(2 * P), 0.0);
    for (int i = 0; i < P; i++) {
        const double *ar = &d.ainv[(size_t)(i * P)];
        double m0 = 0, m1 = 0;
        for (int j = 0; j < P; j++) {
            m0 += ar[j] * p.row[0][j];
            m1 += ar[j] * p.row[1][j];
        }
        M[(size_t)(2 * i)] = m0;
        M[(size_t)(2 * i + 1)] = m1;
    }
    double s[4] = {1, 0, 0, 1};
    for (int i = 0; i < P; i++) {
        s[0] += p.row[0][i] * M[(size_t)(2 * i)];
        s[1] += p.row[0][i] * M[(size_t)(2 * i + 1)];
        s[2] += p.row[1][i] * M[(size_t)(2 * i)];
        s[3] += p.row[1][i] * M[(size_t)(2 * i + 1)];
    }
    double det = s[0] * s[3] - s[1] * s[2];
    double *si = sc.si;
    si[0] = s[3] / det, si[1] = -s[1] / det, si[2] = -s[2] / det, si[3] = s[0] / det;
    sc.logdet = det > 0 ? std::log(det) : -INFINITY;
    double t[4] = {0, 0, 0, 0}; // M^T W M
    wm.assign((size_t)(2 * P), 0.0);
    for (int i = 0; i < P; i++) {
        const double *wr = &d.w[(size_t)(i * P)];
        double a0 = 0, a1 = 0;
        for (int j = 0; j < P; j++) {
            a0 += wr[j] * M[(size_t)(2 * j)];
            a1 += wr[j] * M[(size_t)(2 * j + 1)];
        }
        wm[(size_t)(2 * i)] = a0;
        wm[(size_t)(2 * i + 1)] = a1;
    }
    for (int i = 0; i < P; i++) {
        t[0] += M[(size_t)(2 * i)] * wm[(size_t)(2 * i)];
        t[1] += M[(size_t)(2 * i)] * wm[(size_t)(2 * i + 1)];
        t[2] += M[(size_t)(2 * i + 1)] * wm[(size_t)(2 * i)];
        t[3] += M[(size_t)(2 * i + 1)] * wm[(size_t)(2 * i + 1)];
    }
    return (si[0] * t[0] + si[1] * t[2] + si[2] * t[1] + si[3] * t[3]) / 2;
}

} // namespace

double slew_time(const SlewModel &s, int mount, const DesignPlace &a, const DesignPlace &b)
{
    double d1 = std::fabs(std::remainder(a.eh - b.eh, 2 * PI)) / DEG;
    double d2 = std::fabs(a.ed - b.ed) / DEG;
    double t = (s.rate_deg_s > 0 ? std::max(d1, d2) / s.rate_deg_s : 0) + s.settle_s + s.point_s;
    if (mount != PM_MOUNT_ALTAZ && a.ctx.pier != 0 && b.ctx.pier != 0 && a.ctx.pier != b.ctx.pier)
        t += s.flip_s;
    return t;
}

double design_criterion(const pm_model &m, const std::vector<DesignPlace> &pts,
                        const std::vector<DesignPlace> &sky)
{
    std::vector<Rowed> t = with_rows(m, pts), s = with_rows(m, sky);
    if (s.empty())
        throw std::runtime_error("plan: no place of the sky can be evaluated");
    return design(t, s, m.n_terms).f;
}

namespace {

// Do the places determine the model over the sky?  The criterion with the
// ridge a hundred times larger: unchanged where they do, a hundred times
// smaller where a direction the sky needs is left free.
bool determines(const pm_model &m, const std::vector<DesignPlace> &pts,
                const std::vector<DesignPlace> &sky)
{
    if (2 * (long)pts.size() < m.n_terms)
        return false;
    std::vector<Rowed> t = with_rows(m, pts), s = with_rows(m, sky);
    double f1 = design(t, s, m.n_terms, 1e-8).f, f2 = design(t, s, m.n_terms, 1e-6).f;
    return std::isfinite(f1) && f1 < 1.5 * f2;
}

} // namespace

namespace {

// While the points do not determine the model, A^-1 holds the ridge's
// variance 1/ridge in every direction no point fixes, and the I
// criterion's fall is that of those variances: among the places that fix
// some, it picks by how much W weighs them, not by how well they are then
// fixed.  From an empty run, order 1, its 12 targets predicted 17.5" (and
// gave 17.1") where a golden spiral's 12 stars gave 3.0" and D-optimal
// picks 1.4" (an outside probe).  So until the design determines the model
// (f above 1e-2 / ridge: a free direction of weight 1e-2 or more) a pick
// maximises the information's log det (D-optimal), then the I criterion.
const double UNDETERMINED_F = 1e-2 / RIDGE;

// Greedy: k picks from pool (indices into c; each once), from the design d.
// t: the places taken before (d is theirs).  A^-1 is made afresh after
// each pick: Woodbury's update, step after step from a design that does
// not determine the model (its ridge's variances of 1e8 and their
// cancellation), had drifted to a criterion of 0 or below and printed
// "predicted 0.000"" (an outside probe's --slew plans).
std::vector<int> greedy_pass(Design d, const std::vector<Rowed> &t, const std::vector<Rowed> &c,
                             const std::vector<int> &pool, int k, bool d_optimal,
                             const SlewModel &slew, int mount, const DesignPlace *start,
                             std::vector<double> *crit, std::vector<double> *slew_s)
{
    std::vector<const Rowed *> rows;
    for (const Rowed &r : t)
        rows.push_back(&r);
    std::vector<char> used(pool.size(), 0);
    std::vector<int> order;
    if (crit)
        crit->clear();
    if (slew_s)
        slew_s->clear();
    Scratch sc;
    DesignPlace here = start ? *start : DesignPlace();
    bool have_here = start != nullptr;
    for (int step = 0; step < k; step++) {
        int best = -1;
        double best_score = -INFINITY, best_time = NAN;
        const bool undetermined = d.f > UNDETERMINED_F, d_pick = d_optimal || undetermined;
        // While the points do not determine the model, the slew time does
        // not divide the score: among the places within 80% of the best
        // log det gain the quickest is taken.  (Per second, the nearest
        // places won, and an order-2 plan of 40 targets stayed on one side
        // of the meridian, 2,000" off its truth; an outside probe.)
        double top_logdet = -INFINITY;
        if (slew.on() && undetermined)
            for (size_t u = 0; u < pool.size(); u++)
                if (!used[u]) {
                    gain(d, c[(size_t)pool[u]], sc);
                    top_logdet = std::max(top_logdet, sc.logdet);
                }
        for (size_t u = 0; u < pool.size(); u++) {
            if (used[u])
                continue;
            const Rowed &q = c[(size_t)pool[u]];
            double g = gain(d, q, sc);
            double score = d_pick ? sc.logdet : g;
            double time = NAN;
            if (slew.on()) {
                time = have_here ? slew_time(slew, mount, here, q.p) : slew.settle_s + slew.point_s;
                if (!undetermined)
                    score /= time;
                else
                    score = sc.logdet >= 0.8 * top_logdet ? -time : -INFINITY;
            }
            if (std::isfinite(score) && score > best_score)
                best_score = score, best = (int)u, best_time = time;
        }
        if (best < 0)
            break;
        used[(size_t)best] = 1;
        rows.push_back(&c[(size_t)pool[(size_t)best]]);
        design_taken(d, rows);
        order.push_back(pool[(size_t)best]);
        if (crit)
            crit->push_back(d.f);
        if (slew_s)
            slew_s->push_back(best_time);
        here = c[(size_t)pool[(size_t)best]].p;
        have_here = true;
    }
    return order;
}

// Exchange (Fedorov): each pick in turn is put back and the best candidate
// for its place taken instead where that lowers the I criterion, until no
// exchange does (at most 20 rounds).  Greedy is myopic: its first picks
// were best alone, not together with the later ones.
void exchange(const Design &base, const std::vector<Rowed> &t, const std::vector<Rowed> &c,
              std::vector<int> &chosen)
{
    if (chosen.size() < 2)
        return;
    std::vector<char> in(c.size(), 0);
    for (int q : chosen)
        in[(size_t)q] = 1;
    auto criterion_without = [&](size_t j, Design &d) {
        std::vector<const Rowed *> rows;
        for (const Rowed &r : t)
            rows.push_back(&r);
        for (size_t i = 0; i < chosen.size(); i++)
            if (i != j)
                rows.push_back(&c[(size_t)chosen[i]]);
        design_taken(d, rows);
    };
    Design d = base;
    criterion_without(chosen.size(), d); // (all of them)
    double f = d.f;
    Scratch sc;
    for (int round = 0; round < 20; round++) {
        bool changed = false;
        for (size_t j = 0; j < chosen.size(); j++) {
            criterion_without(j, d);
            int best = chosen[j];
            double best_f = d.f - gain(d, c[(size_t)best], sc);
            for (size_t q = 0; q < c.size(); q++) {
                if (in[q])
                    continue;
                double fq = d.f - gain(d, c[q], sc);
                if (fq < best_f)
                    best_f = fq, best = (int)q;
            }
            if (best != chosen[j] && best_f < f * (1 - 1e-9)) {
                in[(size_t)chosen[j]] = 0;
                in[(size_t)best] = 1;
                chosen[j] = best;
                f = best_f;
                changed = true;
            }
        }
        if (!changed)
            break;
    }
}

} // namespace

std::vector<int> greedy_design(const pm_model &m, const std::vector<DesignPlace> &taken,
                               const std::vector<DesignPlace> &cand,
                               const std::vector<DesignPlace> &sky, int k, bool d_optimal,
                               const SlewModel &slew, const DesignPlace *start,
                               std::vector<double> *crit, std::vector<double> *slew_s)
{
    std::vector<int> kept;
    std::vector<Rowed> t = with_rows(m, taken), s = with_rows(m, sky),
                       c = with_rows(m, cand, &kept);
    if (s.empty())
        throw std::runtime_error("plan: no place of the sky can be evaluated");
    Design d = design(t, s, m.n_terms);
    std::vector<int> all(c.size());
    for (size_t q = 0; q < c.size(); q++)
        all[q] = (int)q;
    std::vector<int> order =
        greedy_pass(d, t, c, all, k, d_optimal, slew, m.mount, start, crit, slew_s);
    // The I criterion's set improved by exchanges, then taken in the
    // greedy order within it (the first targets the most useful alone):
    // where the points, taken and planned, are no more than the model's
    // terms (the fewest stars, where greedy is most myopic: from nothing,
    // 26 targets at order 2 gave 1.00" against greedy's 2.00" and a golden
    // spiral's 2.25", an outside probe's mount).  With more, it was a wash
    // in make bench-plan (better on the full sky, worse with points taken
    // or the truth beyond the model), and greedy's is kept.  Not where the
    // slew time is weighed: the order is the path.
    if (!d_optimal && !slew.on() && order.size() >= 2 &&
        (long)(taken.size() + order.size()) <= (long)m.n_terms) {
        exchange(d, t, c, order);
        order = greedy_pass(d, t, c, std::vector<int>(order), (int)order.size(), false, slew,
                            m.mount, start, crit, slew_s);
    }
    for (int &q : order)
        q = kept[(size_t)q];
    return order;
}

double max_el_of(const PlanOptions &o)
{
    if (std::isfinite(o.max_el_deg))
        return o.max_el_deg;
    return o.mount == PM_MOUNT_ALTAZ ? 85.0 : 90.0;
}

namespace {

// A place of the sky in the plan: sky position (degrees), elevation,
// azimuth, side, and the design place.
struct SkyPlace {
    double x, y, el, az;
    int side;
    DesignPlace d;
    int star = -1; // the catalogue star
};

void el_az(const PlanOptions &o, double x, double y, double &el, double &az)
{
    if (o.mount == PM_MOUNT_ALTAZ) {
        el = y, az = x;
        return;
    }
    double h = x * DEG, dd = y * DEG, f = o.latitude;
    el = std::asin(std::sin(f) * std::sin(dd) + std::cos(f) * std::cos(dd) * std::cos(h)) / DEG;
    az = std::atan2(-std::sin(h) * std::cos(dd),
                    std::sin(dd) * std::cos(f) - std::cos(dd) * std::cos(h) * std::sin(f)) / DEG;
    if (az < 0)
        az += 360;
}

bool usable(const PlanOptions &o, double el, double az)
{
    return el >= o.min_el_deg && el <= max_el_of(o) && (o.horizon.empty() || el >= o.horizon.at(az));
}

// The encoder position of sky place (x, y) on `side`.
void encoder_of(const PlanOptions &o, SkyPlace &p, const pm_context &ctx)
{
    double t = p.x * DEG, d = p.y * DEG;
    if (o.mount != PM_MOUNT_ALTAZ && p.side < 0)
        t += PI, d = PI - d;
    p.d.eh = t;
    p.d.ed = d;
    p.d.ctx = ctx;
    p.d.ctx.pier = p.side;
}

// The pier side of the taken point nearest to (x, y) on the sky (a run's own
// convention of when to flip).
int nearest_side(const std::vector<SkyPlace> &taken, double x, double y, int dflt)
{
    double best = -2;
    int side = dflt;
    for (const SkyPlace &p : taken) {
        double c = std::sin(y * DEG) * std::sin(p.y * DEG) +
                   std::cos(y * DEG) * std::cos(p.y * DEG) * std::cos((x - p.x) * DEG);
        if (c > best)
            best = c, side = p.side;
    }
    return side;
}

// The side of the meridian the run takes on its normal pier side (+1 west,
// -1 east; PlanOptions::normal_west): a vote of its places beyond the
// meridian limit, where a German mount has no choice; dflt without any.
int run_normal_west(const std::vector<SkyPlace> &taken, double limit_deg, int dflt)
{
    long vote = 0;
    for (const SkyPlace &p : taken)
        if (std::fabs(p.x) > limit_deg && p.side != 0)
            vote += (p.x > 0 ? 1 : -1) * p.side;
    return vote > 0 ? 1 : vote < 0 ? -1 : dflt;
}

// The sides a place is taken on under the options' rules (one or two).
std::vector<int> sides_for(const PlanOptions &o, const std::vector<SkyPlace> &taken, double x,
                           double y)
{
    if (o.mount == PM_MOUNT_ALTAZ)
        return {0};
    if (!o.gem)
        return {1};
    int meridian = (x > 0 ? 1 : -1) * (o.normal_west < 0 ? -1 : 1);
    switch (o.sides) {
    case SIDES_MERIDIAN:
        return {meridian};
    case SIDES_BOTH:
        if (std::fabs(x) <= o.meridian_limit_deg)
            return {1, -1};
        return {meridian};
    case SIDES_RUN:
    default:
        // beyond the meridian limit only one side reaches the place
        if (std::fabs(x) > o.meridian_limit_deg)
            return {meridian};
        return {nearest_side(taken, x, y, meridian)};
    }
}

// Places over the usable sky on a grid of `step` degrees (equal area); a
// place taken on two sides counts half on each.
std::vector<SkyPlace> sky_places(const PlanOptions &o, double step,
                                 const std::vector<SkyPlace> &taken, const pm_context &ctx)
{
    std::vector<SkyPlace> out;
    bool az = o.mount == PM_MOUNT_ALTAZ;
    for (double y = -90 + step / 2; y < 90; y += step) {
        int nx = std::max(1, (int)std::lround(360 / step * std::cos(y * DEG)));
        for (int k = 0; k < nx; k++) {
            SkyPlace p;
            p.x = (az ? 0 : -180) + 360.0 / nx * (k + 0.5);
            p.y = y;
            el_az(o, p.x, p.y, p.el, p.az);
            if (!usable(o, p.el, p.az))
                continue;
            std::vector<int> sides = sides_for(o, taken, p.x, p.y);
            for (int s : sides) {
                p.side = s;
                encoder_of(o, p, ctx);
                p.d.weight = 1.0 / (double)sides.size();
                out.push_back(p);
            }
        }
    }
    return out;
}

// The catalogue's stars above the horizon now, on their sides.
std::vector<SkyPlace> star_places(const PlanOptions &o, const std::vector<SkyPlace> &taken,
                                  const pm_context &ctx)
{
    std::vector<SkyPlace> out;
    for (size_t i = 0; i < o.stars.size(); i++) {
        double ha, dec;
        place_star(o.stars[i], o.when, ha, dec);
        SkyPlace p;
        p.star = (int)i;
        if (o.mount == PM_MOUNT_ALTAZ) {
            PlanOptions eq = o;
            eq.mount = PM_MOUNT_EQUATORIAL;
            el_az(eq, ha, dec, p.el, p.az);
            p.x = p.az, p.y = p.el;
        } else {
            p.x = ha, p.y = dec;
            el_az(o, p.x, p.y, p.el, p.az);
        }
        if (!usable(o, p.el, p.az))
            continue;
        for (int s : sides_for(o, taken, p.x, p.y)) {
            p.side = s;
            encoder_of(o, p, ctx);
            out.push_back(p);
        }
    }
    return out;
}

// The planning model and whether the run's points determine it.
pm_model planning_model(const Run &taken, const PlanOptions &o, std::string &note)
{
    std::vector<Obs> none;
    pm_model m = build_model(o.order, o.adds, taken.obs.empty() ? none : taken.obs, o.mount,
                             o.latitude, taken.aux_names);
    if (taken.obs.empty())
        return m;
    std::vector<int> all(taken.obs.size());
    for (size_t i = 0; i < all.size(); i++)
        all[i] = (int)i;
    if (2 * (long)taken.obs.size() > (long)m.n_terms) { /* (pmfit fit's rule, 2N > P) */
        FitOut f = do_fit(taken.obs, all, m);
        if (f.status == PM_OK)
            return f.model;
        note = "the run's " + std::to_string(taken.obs.size()) + " points do not determine the model (" +
               (f.status == PM_ERR_SINGULAR && f.bad_term >= 0
                    ? "term " + term_name(m, f.bad_term) + " cannot be determined"
                    : std::string("the fit fails")) +
               "): planned at the ideal mount";
    } else {
        note = "the run's " + std::to_string(taken.obs.size()) + " points are too few for the " +
               std::to_string(m.n_terms) + "-term model: planned at the ideal mount";
    }
    return m;
}

void check_options(const PlanOptions &o)
{
    if (o.mount != PM_MOUNT_ALTAZ && !std::isfinite(o.latitude))
        throw std::runtime_error("plan: an equatorial mount needs the site latitude (--lat, or a "
                                 "'# latitude:' line in the run)");
    if (o.mount == PM_MOUNT_ALTAZ && !o.stars.empty() && !std::isfinite(o.latitude))
        throw std::runtime_error("plan: placing catalogue stars on an alt-az mount's sky needs the "
                                 "site latitude (--lat)");
    if (!(o.next >= 1 && o.next <= 1000))
        throw std::runtime_error("plan: --next must be 1..1000");
    if (!(o.grid_deg >= 1 && o.grid_deg <= 30))
        throw std::runtime_error("plan: the candidate grid must be 1..30 deg");
    if (std::isfinite(o.max_el_deg) && !(o.max_el_deg > o.min_el_deg && o.max_el_deg <= 90))
        throw std::runtime_error("plan: --max-el must be above --min-el and at most 90 deg");
    if (!(o.meridian_limit_deg >= 0 && o.meridian_limit_deg <= 90))
        throw std::runtime_error("plan: --meridian-limit must be 0..90 deg");
    if (o.slew.on() && !(o.slew.settle_s >= 0 && o.slew.point_s >= 0 && o.slew.flip_s >= 0 &&
                         o.slew.settle_s + o.slew.point_s > 0))
        throw std::runtime_error("plan: the slew model's settle, point and flip times must be >= 0 "
                                 "and settle + point > 0");
    if (!o.stars.empty())
        check_sky_time(o.when);
}

// The mean inputs of the run's physical terms (their planned places use
// them: temperature, time and the like cannot be chosen by slewing).
pm_context mean_context(const Run &run)
{
    pm_context c = pm_context();
    if (run.obs.empty())
        return c;
    double n = (double)run.obs.size();
    for (const Obs &ob : run.obs) {
        c.temp_c += ob.ctx.temp_c / n;
        c.time_h += ob.ctx.time_h / n;
        for (int j = 0; j < PM_MAX_AUX; j++)
            c.aux[j] += ob.ctx.aux[j] / n;
    }
    c.dir = 0;
    return c;
}

// Can any set of points on this sky determine the model?  A noise-free fit
// at every place of the sky names the first term that cannot be.
void check_determinable(const pm_model &m, const std::vector<SkyPlace> &sky)
{
    std::vector<Obs> obs;
    for (const SkyPlace &p : sky) {
        Obs o;
        o.eh = p.d.eh, o.ed = p.d.ed, o.ctx = p.d.ctx, o.pier = p.side, o.line = 0;
        if (pm_model_apply(&m, &o.ctx, o.eh, o.ed, &o.ah, &o.ad) == PM_OK)
            obs.push_back(o);
    }
    std::vector<int> all(obs.size());
    for (size_t i = 0; i < all.size(); i++)
        all[i] = (int)i;
    FitOut f = do_fit(obs, all, m, 3);
    if (f.status == PM_ERR_SINGULAR && f.bad_term >= 0)
        throw std::runtime_error("plan: no set of points on this sky can determine the model: term " +
                                 term_name(m, f.bad_term) +
                                 " is a combination of the terms before it (tube_flexure, for "
                                 "one, is part of the order-1 terms; docs/explain.md)");
}

std::string horizon_text(const PlanOptions &o)
{
    std::string s = "above " + std::to_string((int)std::lround(o.min_el_deg)) + " deg elevation";
    if (max_el_of(o) < 90)
        s += " and below " + fmt("%g", max_el_of(o));
    if (!o.horizon.empty())
        s += " and the horizon of " + o.horizon.path;
    return s;
}

} // namespace

Plan plan_targets(const Run &taken, const PlanOptions &opt)
{
    check_options(opt);
    PlanOptions o = opt;
    Plan plan;
    pm_model m = planning_model(taken, o, plan.note);
    const bool fit_note = !plan.note.empty(); /* the run's fit said why already */
    pm_context ctx = mean_context(taken);
    std::vector<SkyPlace> done;
    for (const Obs &ob : taken.obs) {
        SkyPlace p;
        p.x = std::remainder(ob.ah, 2 * PI) / DEG;
        if (o.mount == PM_MOUNT_ALTAZ && p.x < 0)
            p.x += 360;
        p.y = ob.ad / DEG;
        el_az(o, p.x, p.y, p.el, p.az);
        p.side = o.mount == PM_MOUNT_ALTAZ ? 0 : (ob.pier < 0 ? -1 : 1);
        p.d.eh = ob.eh;
        p.d.ed = ob.ed;
        p.d.ctx = ob.ctx;
        p.d.ctx.pier = p.side;
        done.push_back(p);
    }
    // A run all on the normal side with points on both sides of the
    // meridian, beyond where a German mount must flip, is of a mount that
    // does not flip (a fork, or a German mount run without --fork): planned
    // as one, said (every target was put beyond the pole on the side the
    // run never used, the predicted error 20 times the fork's).
    if (o.mount != PM_MOUNT_ALTAZ && o.gem) {
        long east = 0, west = 0, flipped = 0;
        for (const SkyPlace &p : done) {
            flipped += p.side < 0;
            if (p.side > 0 && std::fabs(p.x) > o.meridian_limit_deg)
                (p.x > 0 ? west : east)++;
        }
        const long far = east + west;
        if (flipped == 0 && east >= 3 && west >= 3 && 10 * std::min(east, west) >= far) {
            o.gem = false;
            plan.note += std::string(plan.note.empty() ? "" : "; ") + "the run's " +
                         std::to_string(done.size()) + " points are all on the normal side, " +
                         std::to_string(east) + " east and " + std::to_string(west) +
                         " west of the meridian beyond " + fmt("%g", o.meridian_limit_deg) +
                         " deg: a mount that does not flip, planned as one (--fork)";
        }
    }
    if (o.mount != PM_MOUNT_ALTAZ && o.gem)
        o.normal_west = run_normal_west(done, o.meridian_limit_deg, o.normal_west);
    plan.sides = o.mount == PM_MOUNT_ALTAZ ? 0 : (o.gem ? 2 : 1);
    std::vector<SkyPlace> sky = sky_places(o, 4, done, ctx);
    if (sky.empty())
        throw std::runtime_error("plan: no usable sky " + horizon_text(o) + " at this latitude");
    check_determinable(m, sky);
    // a star listed twice (within 1") is a candidate once: it was proposed
    // twice, the second time with a "predicted" gain of its own
    plan.n_catalogue = (int)o.stars.size(); // (the stars read)
    {
        std::vector<CatalogueStar> once;
        std::string same;
        int n_same = 0;
        for (const CatalogueStar &s : o.stars) {
            const CatalogueStar *first = nullptr;
            for (const CatalogueStar &t : once)
                if (std::fabs(s.dec_deg - t.dec_deg) * 3600 < 1 &&
                    std::fabs(std::remainder(s.ra_h - t.ra_h, 24.0)) * 15 * 3600 *
                            std::cos(s.dec_deg * DEG) < 1)
                    first = &t;
            if (!first) {
                once.push_back(s);
                continue;
            }
            if (!n_same++)
                same = "line " + std::to_string(s.line) + " (" + s.name + ") is line " +
                       std::to_string(first->line) + "'s place (" + first->name + ")";
        }
        if (n_same) {
            plan.note += std::string(plan.note.empty() ? "" : "; ") + "the catalogue lists " +
                         std::to_string(n_same) + (n_same == 1 ? " star" : " stars") +
                         " twice, taken once: " + same + (n_same > 1 ? ", ..." : "");
            o.stars = once;
        }
    }
    std::vector<SkyPlace> cand = o.stars.empty() ? sky_places(o, o.grid_deg, done, ctx)
                                                 : star_places(o, done, ctx);
    if (cand.empty())
        throw std::runtime_error(
            o.stars.empty() ? "plan: no candidate on the " + std::to_string(o.grid_deg) +
                                  " deg grid is " + horizon_text(o)
                            : "plan: none of the " + std::to_string(o.stars.size()) +
                                  " catalogue stars is " + horizon_text(o) +
                                  " at this time (--lst/--utc) and latitude");
    std::vector<DesignPlace> dt, ds, dc;
    for (const SkyPlace &p : done)
        dt.push_back(p.d);
    for (const SkyPlace &p : sky)
        ds.push_back(p.d);
    for (const SkyPlace &p : cand)
        dc.push_back(p.d);
    plan.n_candidates = (int)cand.size();
    plan.n_sky = (int)sky.size();
    double f0 = design_criterion(m, dt, ds);
    plan.before_arcsec =
        determines(m, dt, ds) ? o.noise_arcsec * std::sqrt(std::max(0.0, f0)) : NAN;
    plan.note_says_undetermined = fit_note;
    if (!std::isfinite(plan.before_arcsec) && !dt.empty() && !fit_note) {
        // (the points fit, but some combination of the terms is fixed by no
        // point: the error over the sky is unbounded, not "too few points")
        plan.note += std::string(plan.note.empty() ? "" : "; ") + "the run's " +
                     std::to_string(dt.size()) + " points fit the " +
                    std::to_string(m.n_terms) + "-term model but do not determine it over the " +
                    "sky (a combination of its terms that no point fixes)";
        plan.note_says_undetermined = true;
    }
    std::vector<double> crit, secs;
    const DesignPlace *start = dt.empty() ? nullptr : &dt.back();
    std::vector<int> order =
        greedy_design(m, dt, dc, ds, o.next, o.d_optimal, o.slew, start, &crit, &secs);
    // the first step from which the points determine the model (taking more
    // points keeps it determined): bisection
    auto with_first = [&](size_t k) {
        std::vector<DesignPlace> v = dt;
        for (size_t i = 0; i < k; i++)
            v.push_back(dc[(size_t)order[i]]);
        return v;
    };
    size_t lo = 0, hi = order.size() + 1; // determined from step hi on (hi > size: never)
    if (std::isfinite(plan.before_arcsec))
        hi = 0;
    else if (!order.empty() && determines(m, with_first(order.size()), ds)) {
        hi = order.size();
        while (hi - lo > 1) {
            size_t mid = (lo + hi) / 2;
            if (determines(m, with_first(mid), ds))
                hi = mid;
            else
                lo = mid;
        }
    }
    for (size_t k = 0; k < order.size(); k++) {
        const SkyPlace &p = cand[(size_t)order[k]];
        Target t;
        t.x_deg = p.x, t.y_deg = p.y, t.el_deg = p.el, t.side = p.side;
        t.after_arcsec = k + 1 >= hi ? o.noise_arcsec * std::sqrt(std::max(0.0, crit[k])) : NAN;
        if (p.star >= 0) {
            const CatalogueStar &s = o.stars[(size_t)p.star];
            t.name = s.name, t.ra_h = s.ra_h, t.dec_deg = s.dec_deg;
        }
        t.slew_s = secs[k];
        plan.targets.push_back(t);
    }
    if ((int)plan.targets.size() < o.next) { // (each candidate is taken once)
        std::string fewer =
            "only " + std::to_string(plan.targets.size()) + " of the " + std::to_string(o.next) +
            " targets asked for: " +
            (o.stars.empty() ? "the grid has no more usable places (a finer --grid has more)"
                             : "the catalogue has no more usable stars " + horizon_text(o));
        plan.note = plan.note.empty() ? fewer : plan.note + "; " + fewer;
    }
    return plan;
}

double predicted_mean_error(const std::vector<Target> &points, const PlanOptions &o)
{
    check_options(o);
    Run none;
    none.mount = o.mount;
    none.latitude = o.latitude;
    std::string note;
    pm_model m = planning_model(none, o, note);
    pm_context ctx = pm_context();
    std::vector<SkyPlace> sky = sky_places(o, 4, {}, ctx);
    if (sky.empty())
        throw std::runtime_error("plan: no usable sky " + horizon_text(o) + " at this latitude");
    std::vector<DesignPlace> pts, ds;
    for (const Target &t : points) {
        SkyPlace p;
        p.x = t.x_deg, p.y = t.y_deg, p.side = t.side;
        encoder_of(o, p, ctx);
        pts.push_back(p.d);
    }
    for (const SkyPlace &p : sky)
        ds.push_back(p.d);
    return o.noise_arcsec * std::sqrt(std::max(0.0, design_criterion(m, pts, ds)));
}

double run_noise_arcsec(const Run &run, int order, const std::vector<std::string> &adds,
                        double fallback)
{
    if (run.obs.empty())
        return fallback;
    std::vector<int> all(run.obs.size());
    for (size_t i = 0; i < all.size(); i++)
        all[i] = (int)i;
    pm_model m = build_model(order, adds, run.obs, run.mount, run.latitude, run.aux_names);
    if (2 * (long)run.obs.size() <= (long)m.n_terms + 2)
        return fallback;
    FitOut f = do_fit(run.obs, all, m);
    return f.status == PM_OK ? f.res.sigma * RAD2AS : fallback;
}

std::string plan_json(const Plan &p, const PlanOptions &o, size_t taken)
{
    bool az = o.mount == PM_MOUNT_ALTAZ;
    auto num = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string("null"); };
    std::string s = fmt("{\"taken\": %zu, \"order\": %d, \"noise_arcsec\": %.6g, \"before_arcsec\": %s, "
                        "\"criterion\": \"%s\", \"candidates\": %d, \"catalogue_stars\": %d, "
                        "\"note\": \"%s\", \"targets\": [", taken, o.order, o.noise_arcsec,
                        num(p.before_arcsec).c_str(), o.d_optimal ? "D" : "I", p.n_candidates,
                        p.n_catalogue, json_escape(p.note).c_str());
    for (size_t k = 0; k < p.targets.size(); k++) {
        const Target &t = p.targets[k];
        s += fmt("%s{\"%s\": %.4f, \"%s\": %.4f, \"elevation_deg\": %.4f, \"side\": %d, "
                 "\"after_arcsec\": %s", k ? ", " : "", az ? "azimuth_deg" : "ha_deg", t.x_deg,
                 az ? "el_deg" : "dec_deg", t.y_deg, t.el_deg, t.side, num(t.after_arcsec).c_str());
        if (!t.name.empty())
            s += fmt(", \"name\": \"%s\", \"ra_h\": %.6f, \"catalogue_dec_deg\": %.5f",
                     json_escape(t.name).c_str(), t.ra_h, t.dec_deg);
        if (o.slew.on())
            s += fmt(", \"time_s\": %s", num(t.slew_s).c_str());
        s += "}";
    }
    return s + "]}";
}

} // namespace pmhost

// ---------------------------------------------------------------- C access

#include "hostutil.hpp"
#include "plan.h"

#include <cstring>

namespace {

pmhost::PlanOptions from_c(const pmplan_options *c)
{
    pmhost::PlanOptions o;
    o.order = c->order;
    o.mount = c->altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
    o.gem = c->gem != 0;
    o.latitude = c->latitude_deg * pmhost::PI / 180;
    o.min_el_deg = c->min_el_deg;
    if (c->max_el_deg > 0)
        o.max_el_deg = c->max_el_deg;
    o.grid_deg = c->grid_deg;
    o.noise_arcsec = c->noise_arcsec;
    if (c->adds) {
        std::string s = c->adds;
        size_t pos = 0, comma;
        while ((comma = s.find(',', pos)) != std::string::npos) {
            o.adds.push_back(s.substr(pos, comma - pos));
            pos = comma + 1;
        }
        if (pos < s.size())
            o.adds.push_back(s.substr(pos));
    }
    if (c->horizon_path)
        o.horizon = pmhost::read_horizon(c->horizon_path);
    if (c->catalogue_path)
        o.stars = pmhost::read_catalogue(c->catalogue_path);
    o.when.lst_h = c->lst_h;
    o.d_optimal = c->d_optimal != 0;
    if (c->sides < PMPLAN_SIDES_RUN || c->sides > PMPLAN_SIDES_BOTH)
        throw std::runtime_error("plan: sides must be PMPLAN_SIDES_RUN, _MERIDIAN or _BOTH");
    o.sides = (pmhost::PlanSides)c->sides;
    o.meridian_limit_deg = c->meridian_limit_deg;
    o.slew.rate_deg_s = c->slew_rate_deg_s;
    o.slew.settle_s = c->settle_s;
    o.slew.point_s = c->point_s;
    o.slew.flip_s = c->flip_s;
    return o;
}

} // namespace

extern "C" void pmplan_options_default(pmplan_options *o)
{
    std::memset(o, 0, sizeof *o);
    o->order = 1;
    o->altaz = 0;
    o->gem = 1;
    o->latitude_deg = 47;
    o->min_el_deg = 15;
    o->grid_deg = 6;
    o->noise_arcsec = 1;
    o->lst_h = -1;
    o->sides = PMPLAN_SIDES_RUN;
    o->meridian_limit_deg = 15;
    o->slew_rate_deg_s = 0;
    o->settle_s = 5;
    o->point_s = 30;
    o->flip_s = 60;
}

extern "C" int pmplan_next(const char *run_path, const pmplan_options *c, int k, pmplan_target *out,
                           double *before, char *err, size_t errlen)
{
    using namespace pmhost;
    if (!c || !out || k < 1) {
        set_err(err, errlen, "pmplan_next: invalid arguments");
        return -1;
    }
    try {
        PlanOptions o = from_c(c);
        o.next = k;
        Run run;
        if (run_path) {
            run = load_run(run_path);
            o.mount = run.mount;
            if (std::isfinite(run.latitude))
                o.latitude = run.latitude;
        }
        Plan p = plan_targets(run, o);
        if (before)
            *before = p.before_arcsec;
        for (size_t i = 0; i < p.targets.size(); i++) {
            const Target &t = p.targets[i];
            pmplan_target &q = out[i];
            std::memset(&q, 0, sizeof q);
            q.x_deg = t.x_deg, q.y_deg = t.y_deg, q.el_deg = t.el_deg, q.side = t.side;
            q.after_arcsec = t.after_arcsec;
            std::snprintf(q.name, sizeof q.name, "%s", t.name.c_str());
            q.slew_s = t.slew_s;
        }
        return (int)p.targets.size();
    } catch (const std::exception &x) {
        set_err(err, errlen, x.what());
        return -1;
    }
}

extern "C" int pmplan_predicted(const pmplan_options *c, const pmplan_target *pts, int n,
                                double *mean_arcsec, char *err, size_t errlen)
{
    using namespace pmhost;
    if (!c || (n > 0 && !pts) || n < 0 || !mean_arcsec) {
        set_err(err, errlen, "pmplan_predicted: invalid arguments");
        return -1;
    }
    try {
        std::vector<Target> v;
        for (int i = 0; i < n; i++) {
            Target t;
            t.x_deg = pts[i].x_deg, t.y_deg = pts[i].y_deg, t.el_deg = pts[i].el_deg;
            t.side = pts[i].side, t.after_arcsec = 0;
            v.push_back(t);
        }
        *mean_arcsec = predicted_mean_error(v, from_c(c));
        return 0;
    } catch (const std::exception &x) {
        set_err(err, errlen, x.what());
        return -1;
    }
}
