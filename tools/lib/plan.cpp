// plan.cpp - which star next (plan.hpp).
//
// The fitted model's covariance is sigma^2 A^-1 with A = sum J^T J over the
// points taken (two rows J per point, pm_fit_row at the model's own
// prediction); its predicted variance at a place g is sigma^2 tr(J_g A^-1
// J_g^T) / 2 per axis.  The I-optimal criterion is the mean of that over
// the usable sky, sigma^2 tr(W A^-1) / 2 with W the mean of J_g^T J_g.
// Taking a point x (rows J) changes A^-1 by -M S^-1 M^T (M = A^-1 J^T,
// S = I + J M: Woodbury), so the criterion falls by tr(S^-1 M^T W M) / 2:
// greedy, the best candidate, update, repeat.
#include "plan.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pmhost {

namespace {

const double DEG = PI / 180;

struct Place {
    double x, y, el; // degrees
    int side;
    double row[2][PM_MAX_TERMS];
};

double elevation_deg(const PlanOptions &o, double x, double y)
{
    if (o.mount == PM_MOUNT_ALTAZ)
        return y;
    return std::asin(std::sin(o.latitude) * std::sin(y * DEG) +
                     std::cos(o.latitude) * std::cos(y * DEG) * std::cos(x * DEG)) / DEG;
}

// The model's two rows at sky place (x, y) on `side`; false where it
// cannot be evaluated.
bool rows_at(const pm_model &m, const PlanOptions &o, Place &p)
{
    double t = p.x * DEG, d = p.y * DEG;
    if (o.mount != PM_MOUNT_ALTAZ && p.side < 0)
        t += PI, d = PI - d;
    pm_context ctx = pm_context();
    ctx.pier = p.side;
    double T, D, r[2];
    return pm_model_apply(&m, &ctx, t, d, &T, &D) == PM_OK &&
           pm_fit_row(&m, &ctx, t, d, T, D, p.row[0], p.row[1], r) == PM_OK;
}

// The pier side of the taken point nearest to (x, y) on the sky (a run's own
// convention of when to flip), or the German mount's usual one (beyond the
// pole west of the meridian) when nothing is taken.
int side_for(const PlanOptions &o, const std::vector<Place> &taken, double x, double y)
{
    if (o.mount == PM_MOUNT_ALTAZ)
        return 0;
    if (!o.gem)
        return 1;
    double best = -2;
    int side = x > 0 ? -1 : 1;
    for (const Place &p : taken) {
        double c = std::sin(y * DEG) * std::sin(p.y * DEG) +
                   std::cos(y * DEG) * std::cos(p.y * DEG) * std::cos((x - p.x) * DEG);
        if (c > best)
            best = c, side = p.side;
    }
    return side;
}

// Places over the usable sky on a grid of `step` degrees (equal area).
std::vector<Place> sky_places(const pm_model &m, const PlanOptions &o, double step,
                              const std::vector<Place> &taken)
{
    std::vector<Place> out;
    bool az = o.mount == PM_MOUNT_ALTAZ;
    for (double y = -90 + step / 2; y < 90; y += step) {
        int nx = std::max(1, (int)std::lround(360 / step * std::cos(y * DEG)));
        for (int k = 0; k < nx; k++) {
            Place p;
            p.x = (az ? 0 : -180) + 360.0 / nx * (k + 0.5);
            p.y = y;
            p.el = elevation_deg(o, p.x, p.y);
            if (p.el < o.min_el_deg)
                continue;
            p.side = side_for(o, taken, p.x, p.y);
            if (rows_at(m, o, p))
                out.push_back(p);
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

// A from the rows of `taken` places plus a ridge, W from the sky.
Design design(const std::vector<Place> &taken, const std::vector<Place> &sky, int P)
{
    Design d;
    d.P = P;
    std::vector<double> a((size_t)(P * P), 0.0);
    d.w.assign((size_t)(P * P), 0.0);
    auto add = [&](std::vector<double> &m, const Place &p, double wt) {
        for (int i = 0; i < P; i++)
            for (int j = 0; j < P; j++)
                m[(size_t)(i * P + j)] += wt * (p.row[0][i] * p.row[0][j] + p.row[1][i] * p.row[1][j]);
    };
    for (const Place &p : taken)
        add(a, p, 1.0);
    for (const Place &p : sky)
        add(d.w, p, 1.0 / (double)sky.size());
    for (int i = 0; i < P; i++)
        a[(size_t)(i * P + i)] += 1e-8; // a ridge: the first points of a run
    if (!spd_inverse(a, P))
        throw std::runtime_error("plan: the design is singular");
    d.ainv = a;
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++)
            d.f += d.w[(size_t)(i * P + j)] * d.ainv[(size_t)(j * P + i)] / 2;
    return d;
}

// The fall of the criterion by taking place p; M = A^-1 J^T, S^-1 returned.
double gain(const Design &d, const Place &p, std::vector<double> &M, double si[4])
{
    int P = d.P;
    M.assign((size_t)(2 * P), 0.0);
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++) {
            double a = d.ainv[(size_t)(i * P + j)];
            M[(size_t)(2 * i)] += a * p.row[0][j];
            M[(size_t)(2 * i + 1)] += a * p.row[1][j];
        }
    double s[4] = {1, 0, 0, 1};
    for (int i = 0; i < P; i++) {
        s[0] += p.row[0][i] * M[(size_t)(2 * i)];
        s[1] += p.row[0][i] * M[(size_t)(2 * i + 1)];
        s[2] += p.row[1][i] * M[(size_t)(2 * i)];
        s[3] += p.row[1][i] * M[(size_t)(2 * i + 1)];
    }
    double det = s[0] * s[3] - s[1] * s[2];
    si[0] = s[3] / det, si[1] = -s[1] / det, si[2] = -s[2] / det, si[3] = s[0] / det;
    double t[4] = {0, 0, 0, 0}; // M^T W M
    std::vector<double> wm((size_t)(2 * P), 0.0);
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++) {
            double w = d.w[(size_t)(i * P + j)];
            wm[(size_t)(2 * i)] += w * M[(size_t)(2 * j)];
            wm[(size_t)(2 * i + 1)] += w * M[(size_t)(2 * j + 1)];
        }
    for (int i = 0; i < P; i++) {
        t[0] += M[(size_t)(2 * i)] * wm[(size_t)(2 * i)];
        t[1] += M[(size_t)(2 * i)] * wm[(size_t)(2 * i + 1)];
        t[2] += M[(size_t)(2 * i + 1)] * wm[(size_t)(2 * i)];
        t[3] += M[(size_t)(2 * i + 1)] * wm[(size_t)(2 * i + 1)];
    }
    return (si[0] * t[0] + si[1] * t[2] + si[2] * t[1] + si[3] * t[3]) / 2;
}

void take(Design &d, const std::vector<double> &M, const double si[4], double g)
{
    int P = d.P;
    for (int i = 0; i < P; i++)
        for (int j = 0; j < P; j++) {
            double mi0 = M[(size_t)(2 * i)], mi1 = M[(size_t)(2 * i + 1)];
            double mj0 = M[(size_t)(2 * j)], mj1 = M[(size_t)(2 * j + 1)];
            d.ainv[(size_t)(i * P + j)] -= mi0 * (si[0] * mj0 + si[1] * mj1) + mi1 * (si[2] * mj0 + si[3] * mj1);
        }
    d.f -= g;
}

pm_model planning_model(const Run &taken, const PlanOptions &o)
{
    std::vector<Obs> none;
    pm_model m = build_model(o.order, o.adds, taken.obs.empty() ? none : taken.obs, o.mount,
                             o.latitude, taken.aux_names);
    std::vector<int> all(taken.obs.size());
    for (size_t i = 0; i < all.size(); i++)
        all[i] = (int)i;
    if (2 * (long)taken.obs.size() > (long)m.n_terms + 2) {
        FitOut f = do_fit(taken.obs, all, m);
        if (f.status == PM_OK)
            return f.model;
    }
    return m;
}

void check_options(const PlanOptions &o)
{
    if (o.mount != PM_MOUNT_ALTAZ && !std::isfinite(o.latitude))
        throw std::runtime_error("plan: an equatorial mount needs the site latitude (--lat, or a "
                                 "'# latitude:' line in the run)");
    if (!(o.next >= 1 && o.next <= 1000))
        throw std::runtime_error("plan: --next must be 1..1000");
    if (!(o.grid_deg >= 1 && o.grid_deg <= 30))
        throw std::runtime_error("plan: the candidate grid must be 1..30 deg");
}

} // namespace

Plan plan_targets(const Run &taken, const PlanOptions &o)
{
    check_options(o);
    pm_model m = planning_model(taken, o);
    std::vector<Place> done;
    for (const Obs &ob : taken.obs) {
        Place p;
        p.x = std::remainder(ob.ah, 2 * PI) / DEG;
        if (o.mount == PM_MOUNT_ALTAZ && p.x < 0)
            p.x += 360;
        p.y = ob.ad / DEG;
        p.el = elevation_deg(o, p.x, p.y);
        p.side = o.mount == PM_MOUNT_ALTAZ ? 0 : (ob.pier < 0 ? -1 : 1);
        pm_context ctx = ob.ctx;
        double T, D, r[2];
        if (pm_model_apply(&m, &ctx, ob.eh, ob.ed, &T, &D) == PM_OK &&
            pm_fit_row(&m, &ctx, ob.eh, ob.ed, T, D, p.row[0], p.row[1], r) == PM_OK)
            done.push_back(p);
    }
    std::vector<Place> sky = sky_places(m, o, 4, done), cand = sky_places(m, o, o.grid_deg, done);
    if (sky.empty() || cand.empty())
        throw std::runtime_error("plan: no usable sky above " + std::to_string(o.min_el_deg) +
                                 " deg elevation at this latitude");
    Design d = design(done, sky, m.n_terms);
    Plan plan;
    plan.n_candidates = (int)cand.size();
    plan.n_sky = (int)sky.size();
    bool determined = 2 * (long)done.size() >= m.n_terms;
    plan.before_arcsec = determined ? o.noise_arcsec * std::sqrt(std::max(0.0, d.f)) : NAN;
    std::vector<double> M, best_m;
    for (int k = 0; k < o.next; k++) {
        int best = -1;
        double bg = -1, si[4], best_si[4];
        for (size_t c = 0; c < cand.size(); c++) {
            double g = gain(d, cand[c], M, si);
            if (g > bg) {
                bg = g, best = (int)c, best_m = M;
                std::copy(si, si + 4, best_si);
            }
        }
        if (best < 0)
            break;
        take(d, best_m, best_si, bg);
        done.push_back(cand[(size_t)best]);
        const Place p = cand[(size_t)best];
        cand.erase(cand.begin() + best); // a star once: the next best is elsewhere
        bool det = 2 * (long)done.size() >= m.n_terms;
        plan.targets.push_back({p.x, p.y, p.el, p.side,
                                det ? o.noise_arcsec * std::sqrt(std::max(0.0, d.f)) : NAN});
    }
    return plan;
}

double predicted_mean_error(const std::vector<Target> &points, const PlanOptions &o)
{
    check_options(o);
    Run none;
    none.mount = o.mount;
    none.latitude = o.latitude;
    pm_model m = planning_model(none, o);
    std::vector<Place> sky = sky_places(m, o, 4, {}), pts;
    for (const Target &t : points) {
        Place p;
        p.x = t.x_deg, p.y = t.y_deg, p.el = t.el_deg, p.side = t.side;
        if (rows_at(m, o, p))
            pts.push_back(p);
    }
    Design d = design(pts, sky, m.n_terms);
    return o.noise_arcsec * std::sqrt(std::max(0.0, d.f));
}

} // namespace pmhost

// ---------------------------------------------------------------- C access

#include "hostutil.hpp"
#include "plan.h"

namespace {

pmhost::PlanOptions from_c(const pmplan_options *c)
{
    pmhost::PlanOptions o;
    o.order = c->order;
    o.mount = c->altaz ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
    o.gem = c->gem != 0;
    o.latitude = c->latitude_deg * pmhost::PI / 180;
    o.min_el_deg = c->min_el_deg;
    o.grid_deg = c->grid_deg;
    o.noise_arcsec = c->noise_arcsec;
    return o;
}

} // namespace

extern "C" void pmplan_options_default(pmplan_options *o)
{
    o->order = 1;
    o->altaz = 0;
    o->gem = 1;
    o->latitude_deg = 47;
    o->min_el_deg = 15;
    o->grid_deg = 6;
    o->noise_arcsec = 1;
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
            run = load_run(run_path, true, false);
            o.mount = run.mount;
            if (std::isfinite(run.latitude))
                o.latitude = run.latitude;
        }
        Plan p = plan_targets(run, o);
        if (before)
            *before = p.before_arcsec;
        for (size_t i = 0; i < p.targets.size(); i++) {
            const Target &t = p.targets[i];
            out[i] = {t.x_deg, t.y_deg, t.el_deg, t.side, t.after_arcsec};
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
        for (int i = 0; i < n; i++)
            v.push_back({pts[i].x_deg, pts[i].y_deg, pts[i].el_deg, pts[i].side, 0});
        *mean_arcsec = predicted_mean_error(v, from_c(c));
        return 0;
    } catch (const std::exception &x) {
        set_err(err, errlen, x.what());
        return -1;
    }
}
