// inject.cpp - a known effect added to a real recording (inject.hpp).
//
// The displacement of an effect at an observation is the difference of two
// forward evaluations at its encoder angles and inputs: the run's own
// baseline model M, and M with the effect's terms (pmsim_add_effect, the
// same sizes as pmfit simulate --effect).  Adding that difference to the
// observed position leaves the run's noise and every effect it already holds
// in place.
#include "inject.hpp"
#include "hostutil.hpp"
#include "simulate.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <stdexcept>

namespace pmhost {

namespace {

const double DEG = PI / 180;

// "2.5sigma" / "2.5as" / "2.5arcsec" -> size and unit; false if not so.
bool sized(const std::string &s, double &v, bool &in_sigma)
{
    const char *units[3] = {"sigma", "arcsec", "as"};
    for (const char *u : units) {
        size_t n = std::strlen(u);
        if (s.size() > n && s.compare(s.size() - n, n, u) == 0) {
            std::string num = s.substr(0, s.size() - n);
            char *end = nullptr;
            v = std::strtod(num.c_str(), &end);
            if (num.empty() || *end || !std::isfinite(v))
                return false;
            in_sigma = u[0] == 's';
            return true;
        }
    }
    return false;
}

double mean_of(const std::vector<Obs> &obs, double pm_context::*field)
{
    double s = 0;
    long n = 0;
    for (const Obs &o : obs)
        if (std::isfinite(o.ctx.*field)) {
            s += o.ctx.*field;
            n++;
        }
    return n ? s / (double)n : 0;
}

// The run's baseline: order 1 (0 when too few points), all observations.
FitOut baseline_fit(const Run &run, int &order)
{
    std::vector<int> use(run.obs.size());
    for (size_t i = 0; i < use.size(); i++)
        use[i] = (int)i;
    for (order = 1; order >= 0; order--) {
        pm_model m = build_model(order, {}, run.obs, run.mount, run.latitude, run.aux_names);
        if (2 * (long)run.obs.size() <= (long)m.n_terms + 2)
            continue;
        FitOut f = do_fit(run.obs, use, m);
        if (f.status == PM_OK)
            return f;
    }
    throw std::runtime_error(run.path + ": inject: the run cannot be fitted even at order 0 (too "
                                        "few or degenerate points)");
}

// Outliers: n points (seeded) moved by `arcsec` in a random direction.
std::vector<int> move_outliers(std::vector<Obs> &obs, int n, double arcsec, unsigned long long seed)
{
    if (n < 1 || n > (int)obs.size())
        throw std::runtime_error("inject outlier:N: N must be 1.." + std::to_string(obs.size()));
    std::mt19937_64 rng(seed * 104729 + 11);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::vector<char> hit(obs.size(), 0);
    std::vector<int> moved;
    for (int k = 0; k < n; k++) {
        size_t j;
        do
            j = (size_t)(rng() % obs.size());
        while (hit[j]);
        hit[j] = 1;
        double a = 2 * PI * uni(rng), s = arcsec / RAD2AS;
        Obs &o = obs[j];
        o.ad += s * std::sin(a);
        o.ah += s * std::cos(a) / std::cos(o.ad);
        moved.push_back((int)j);
    }
    return moved;
}

// aux:NAME[:BASES]: the run's own column NAME times the base vectors, arcsec
// per unit of it, about the column's mean (as pmfit fit --add aux:NAME fits
// it).  pmsim_add_effect cannot: its truth knows no column names.
void add_column_effect(pm_model &truth, const std::string &effect, double arcsec, const Run &run,
                       const std::vector<Obs> &obs)
{
    pm_model with;
    try {
        with = build_model(truth.order, {effect}, obs, run.mount, run.latitude, run.aux_names);
    } catch (const std::exception &e) {
        throw std::runtime_error(std::string("--inject: effect ") + effect + ": " + e.what());
    }
    for (int i = with.n_base; i < with.n_terms; i++)
        if (pm_model_add_term(&truth, &with.term[i], arcsec / RAD2AS, nullptr) != PM_OK)
            throw std::runtime_error("--inject: effect " + effect +
                                     ": cannot add its terms to the baseline model");
    if (pm_model_prepare(&truth) != PM_OK)
        throw std::runtime_error("--inject: effect " + effect + ": the model with it is invalid");
}

} // namespace

Injection parse_injection(const std::string &spec)
{
    Injection in;
    size_t eq = spec.rfind('=');
    if (eq != std::string::npos) {
        std::string v = spec.substr(eq + 1);
        char *end = nullptr;
        in.size = std::strtod(v.c_str(), &end);
        in.in_sigma = false;
        if (v.empty() || *end || !std::isfinite(in.size)) {
            if (!sized(v, in.size, in.in_sigma))
                throw std::runtime_error("--inject " + spec + ": expected EFFECT=SIZE (arcsec) or "
                                         "EFFECT=SIZEsigma, got size '" + v + "'");
        }
        in.effect = spec.substr(0, eq);
    } else {
        size_t c = spec.rfind(':');
        if (c != std::string::npos && sized(spec.substr(c + 1), in.size, in.in_sigma))
            in.effect = spec.substr(0, c);
        else
            in.effect = spec; // default: 1 sigma
    }
    if (in.effect.empty())
        throw std::runtime_error("--inject " + spec + ": no effect named");
    if (!(std::fabs(in.size) <= 1e6))
        throw std::runtime_error("--inject " + spec + ": size beyond 1e6");
    return in;
}

InjectReport inject(Run &run, const std::vector<Injection> &list)
{
    InjectReport rep;
    FitOut base = baseline_fit(run, rep.order);
    rep.sigma_arcsec = base.res.sigma * RAD2AS;
    std::vector<Obs> obs = run.obs; // the run is changed only on success
    for (const Injection &in : list) {
        double arcsec = in.in_sigma ? in.size * rep.sigma_arcsec : in.size;
        rep.size_arcsec.push_back(arcsec);
        std::vector<double> before(obs.size() * 2);
        for (size_t i = 0; i < obs.size(); i++) {
            before[2 * i] = obs[i].ah;
            before[2 * i + 1] = obs[i].ad;
        }
        if (in.effect == "outlier" || in.effect.rfind("outlier:", 0) == 0) {
            int n = in.effect == "outlier" ? 1 : std::atoi(in.effect.c_str() + 8);
            rep.moved.push_back(move_outliers(obs, n, arcsec, in.seed));
        } else {
            pmsim_spec s;
            pmsim_default(&s);
            s.truth = base.model;
            s.truth.latitude = std::isfinite(run.latitude) ? run.latitude : 0;
            s.temp_start_c = mean_of(obs, &pm_context::temp_c);
            s.start_time_h = mean_of(obs, &pm_context::time_h);
            char err[512];
            if (in.effect.rfind("aux:", 0) == 0)
                add_column_effect(s.truth, in.effect, arcsec, run, obs);
            else if (pmsim_add_effect(&s, in.effect.c_str(), arcsec, in.phase_deg, in.seed, err,
                                      sizeof err) != 0)
                throw std::runtime_error(std::string("--inject: ") + err);
            for (Obs &o : obs) {
                double a0[2], a1[2];
                pm_status s0 = pm_model_apply(&base.model, &o.ctx, o.eh, o.ed, &a0[0], &a0[1]);
                pm_status s1 = pm_model_apply(&s.truth, &o.ctx, o.eh, o.ed, &a1[0], &a1[1]);
                if (s0 != PM_OK || s1 != PM_OK)
                    throw std::runtime_error(run.path + ":" + std::to_string(o.line) + ": --inject " +
                                             in.effect + ": cannot evaluate it here (" +
                                             ((s1 != PM_OK ? s1 : s0) == PM_ERR_NONFINITE
                                                  ? std::string("an input it needs is missing")
                                                  : "status " + std::to_string((int)(s1 != PM_OK ? s1 : s0))) +
                                             "; does the run give the temperature, time or "
                                             "column it reads?)");
                o.ah += std::remainder(a1[0] - a0[0], 2 * PI);
                o.ad += a1[1] - a0[1];
            }
            rep.moved.push_back({});
        }
        double ss = 0;
        for (size_t i = 0; i < obs.size(); i++) {
            double dh = std::remainder(obs[i].ah - before[2 * i], 2 * PI) * std::cos(obs[i].ad);
            double dd = obs[i].ad - before[2 * i + 1];
            ss += dh * dh + dd * dd;
            if (!(std::fabs(obs[i].ad) <= PI / 2))
                throw std::runtime_error(run.path + ":" + std::to_string(obs[i].line) +
                                         ": --inject " + in.effect +
                                         " moves the point over the pole; inject less");
        }
        rep.rms_arcsec.push_back(std::sqrt(ss / (double)(2 * obs.size())) * RAD2AS);
    }
    run.obs = obs;
    return rep;
}

void write_named_run(const Run &run, const std::string &path,
                     const std::vector<std::string> &comments)
{
    bool altaz = run.mount == PM_MOUNT_ALTAZ;
    std::string out;
    for (const std::string &c : comments)
        out += "# " + c + "\n";
    char buf[512];
    if (std::isfinite(run.latitude)) {
        std::snprintf(buf, sizeof buf, "# latitude: %.12f\n", run.latitude / DEG);
        out += buf;
    }
    out += std::string("# mount: ") + (altaz ? "altaz" : "equatorial") + "\n";
    out += "# tau delta T D pier temp time dir";
    for (const std::string &n : run.aux_names)
        out += " " + n;
    out += "\n";
    auto val = [](double v, const char *fmt) {
        char b[64];
        if (!std::isfinite(v))
            return std::string("-");
        std::snprintf(b, sizeof b, fmt, v);
        return std::string(b);
    };
    for (size_t i = 0; i < run.obs.size(); i++) {
        const Obs &o = run.obs[i];
        double T = o.ah / DEG;
        if (altaz)
            T = std::fmod(std::fmod(T, 360.0) + 360.0, 360.0);
        std::snprintf(buf, sizeof buf, "%.12f %.12f %.12f %.12f %s %s %s %s", o.eh / DEG, o.ed / DEG,
                      T, o.ad / DEG, o.pier > 0 ? "E" : (o.pier < 0 ? "W" : "0"),
                      val(o.ctx.temp_c, "%.4f").c_str(), val(o.ctx.time_h, "%.8f").c_str(),
                      o.ctx.dir > 0 ? "+1" : (o.ctx.dir < 0 ? "-1" : "0"));
        out += buf;
        // every column the header names (beyond the contexts' first
        // PM_MAX_AUX from the run's columns as read: a run of six had its
        // header name six and its records hold four, unreadable)
        for (size_t j = 0; j < run.aux_names.size(); j++)
            out += " " + val(j < (size_t)PM_MAX_AUX ? o.ctx.aux[j]
                             : j < run.aux_values.size() && i < run.aux_values[j].size()
                                 ? run.aux_values[j][i]
                                 : std::nan(""),
                             "%.10g");
        out += "\n";
    }
    char err[1024];
    if (write_atomic(path, out, err, sizeof err) != 0)
        throw std::runtime_error(err);
}

} // namespace pmhost
