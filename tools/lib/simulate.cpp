// simulate.cpp - simulated pointing runs (host side).
#include "simulate.h"
#include "hostutil.hpp"
#include "fitrun.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const double PI = 3.14159265358979323846;
const double DEG = PI / 180.0;
const double ARCSEC = PI / 648000.0;

using pmhost::set_err;

struct Target {
    double ha, dec; // true apparent position (radians), dec in [-pi/2, pi/2]
};

double elevation(double ha, double dec, double lat)
{
    return std::asin(std::sin(lat) * std::sin(dec) + std::cos(lat) * std::cos(dec) * std::cos(ha));
}

// Distance between two sky directions (radians).
double separation(const Target &a, const Target &b)
{
    double c = std::sin(a.dec) * std::sin(b.dec) +
               std::cos(a.dec) * std::cos(b.dec) * std::cos(a.ha - b.ha);
    return std::acos(std::max(-1.0, std::min(1.0, c)));
}

} // namespace

extern "C" void pmsim_default(pmsim_spec *s)
{
    std::memset(s, 0, sizeof *s);
    s->n = 200;
    s->seed = 1;
    s->latitude_deg = 47.0;
    s->el_limit_deg = 15.0;
    s->noise_arcsec = 1.0;
    s->gem = 1;
    s->overlap_deg = 15.0;
    s->start_time_h = 20.0;
    s->minutes_per_point = 2.0;
    s->temp_start_c = 12.0;
    s->temp_rate_c_per_h = -0.5;
    pm_model_init(&s->truth, PM_MOUNT_EQUATORIAL, 1);
}

extern "C" int pmsim_write(const pmsim_spec *s, const char *path, const char *comment,
                           char *err, size_t errlen)
{
    if (!s || !path) {
        set_err(err, errlen, "pmsim_write: invalid arguments");
        return -1;
    }
    if (s->n < 1 || s->n > 10000000) {
        set_err(err, errlen, "simulate: number of points must be 1..10000000");
        return -1;
    }
    if (!(std::fabs(s->latitude_deg) <= 90) || !(s->el_limit_deg > -90 && s->el_limit_deg < 85) ||
        !(s->noise_arcsec >= 0) || !std::isfinite(s->minutes_per_point) ||
        !(s->overlap_deg >= 0 && s->overlap_deg <= 90) ||
        s->n_outliers < 0 || !std::isfinite(s->outlier_arcsec) ||
        !std::isfinite(s->temp_start_c) || !std::isfinite(s->temp_rate_c_per_h)) {
        set_err(err, errlen, "simulate: latitude, elevation limit, noise, cadence or "
                             "temperature out of range");
        return -1;
    }
    bool altaz = s->truth.mount == PM_MOUNT_ALTAZ;
    double lat = s->latitude_deg * DEG, elmin = s->el_limit_deg * DEG;
    std::mt19937_64 rng(s->seed);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::normal_distribution<double> gauss(0.0, 1.0);

    // Targets uniform on the visible sky (for alt-az: above the limit).
    std::vector<Target> pool;
    while ((long)pool.size() < s->n) {
        double ha = (2 * uni(rng) - 1) * PI, dec = std::asin(2 * uni(rng) - 1);
        double el = altaz ? dec : elevation(ha, dec, lat);
        if (el < elmin || (altaz && el > 89 * DEG))
            continue;
        pool.push_back({ha, dec});
    }
    // Visit them in a nearest-neighbour sequence from the first.
    std::vector<Target> seq;
    seq.reserve(pool.size());
    std::vector<char> used(pool.size(), 0);
    size_t cur = 0;
    used[0] = 1;
    seq.push_back(pool[0]);
    for (size_t k = 1; k < pool.size(); k++) {
        size_t best = 0;
        double bd = 1e9;
        for (size_t j = 0; j < pool.size(); j++)
            if (!used[j]) {
                double d = separation(pool[cur], pool[j]);
                if (d < bd) {
                    bd = d;
                    best = j;
                }
            }
        used[best] = 1;
        cur = best;
        seq.push_back(pool[best]);
    }

    std::ostringstream out;
    if (comment) {
        std::istringstream c(comment);
        std::string line;
        while (std::getline(c, line))
            out << "# " << line << "\n";
    }
    out << "# simulated by pmsim: seed " << s->seed << ", " << s->n << " points, noise "
        << s->noise_arcsec << " arcsec per axis\n";
    out << "# latitude: " << s->latitude_deg << "\n";
    out << "# mount: " << (altaz ? "altaz" : "equatorial") << "\n";
    out << (altaz ? "# tau delta T D temp time dir\n" : "# tau delta T D pier temp time dir\n");
    char buf[256];
    std::mt19937_64 rng_t(s->seed * 7919 + 17); // temperature walk, separate stream
    std::normal_distribution<double> gauss_t(0.0, 1.0);
    double temp_walk = 0;
    std::vector<char> is_outlier((size_t)s->n, 0);
    {
        std::mt19937_64 rng_o(s->seed * 104729 + 3);
        for (int k = 0; k < s->n_outliers && k < s->n; k++) {
            size_t j;
            do
                j = (size_t)(rng_o() % (unsigned long long)s->n);
            while (is_outlier[j]);
            is_outlier[j] = 1;
        }
    }
    for (long i = 0; i < s->n; i++) {
        const Target &t = seq[(size_t)i];
        int side = 0; // pm side for the inverse
        if (!altaz && s->gem) { // west of the meridian: flipped; both sides near it
            if (std::fabs(t.ha) < s->overlap_deg * DEG)
                side = uni(rng) < 0.5 ? PM_SIDE_FLIPPED : PM_SIDE_NORMAL;
            else
                side = t.ha > 0 ? PM_SIDE_FLIPPED : PM_SIDE_NORMAL;
        }
        double time_h = s->start_time_h + (double)i * s->minutes_per_point / 60.0;
        double el_h = time_h - s->start_time_h;
        temp_walk += 0.08 * gauss_t(rng_t);
        double temp = s->temp_start_c + s->temp_rate_c_per_h * 3.0 * (1 - std::exp(-el_h / 3.0)) +
                      temp_walk;
        // the slew direction on axis 1 is the commanded one: toward the new target
        int dir = 0;
        if (i > 0) {
            double dh = std::remainder(t.ha - seq[(size_t)i - 1].ha, 2 * PI);
            dir = dh > 0 ? 1 : (dh < 0 ? -1 : 0);
        }
        pm_context ctx;
        std::memset(&ctx, 0, sizeof ctx);
        ctx.temp_c = temp;
        ctx.time_h = time_h;
        ctx.dir = dir;
        ctx.pier = altaz ? 0 : (side == PM_SIDE_FLIPPED ? -1 : 1);
        double eh, ed;
        pm_status st = pm_model_invert(&s->truth, &ctx, t.ha, t.dec,
                                       side ? PM_SIDE_FLIPPED : PM_SIDE_NORMAL, &eh, &ed);
        if (st < 0 || st == PM_WARN_NOT_CONVERGED) {
            set_err(err, errlen, "simulate: the true model could not be inverted (status " +
                                     std::to_string((int)st) + "); is it prepared and sane?");
            return -1;
        }
        if (st == PM_WARN_UNREACHABLE)
            continue; // the mount cannot point there; a real run would skip it too
        // measured (apparent) position: the target plus noise on the sky
        double nd = s->noise_arcsec * ARCSEC * gauss(rng), nt = s->noise_arcsec * ARCSEC * gauss(rng);
        if (is_outlier[(size_t)i]) { // a gross error: failed plate solve, wrong star
            double a = 2 * PI * uni(rng);
            nd += s->outlier_arcsec * ARCSEC * std::sin(a);
            nt += s->outlier_arcsec * ARCSEC * std::cos(a);
        }
        double D = t.dec + nd;
        double T = t.ha + nt / std::cos(t.dec);
        if (D > PI / 2)
            D = PI - D, T += PI;
        if (D < -PI / 2)
            D = -PI - D, T += PI;
        T = std::remainder(T, 2 * PI);
        double enc1 = eh / DEG, app1 = T / DEG;
        double enc2 = std::remainder(ed, 2 * PI) / DEG; // flipped: beyond +-90, within +-180
        if (altaz) { // azimuth in [0, 360)
            enc1 = std::fmod(enc1 + 720.0, 360.0);
            app1 = std::fmod(app1 + 720.0, 360.0);
        }
        std::snprintf(buf, sizeof buf, "%.9f %.9f %.9f %.9f %s%.2f %.5f %s\n", enc1, enc2,
                      app1, D / DEG, altaz ? "" : (std::fabs(enc2) > 90 ? "W " : "E "), temp,
                      time_h, dir > 0 ? "+1" : (dir < 0 ? "-1" : "0"));
        out << buf;
    }
    return pmhost::write_atomic(path, out.str(), err, errlen);
}

extern "C" int pmsim_add_effect(pmsim_spec *spec, const char *effect, double arcsec,
                                double phase_deg, unsigned long long seed, char *err,
                                size_t errlen)
{
    if (!spec || !effect) {
        set_err(err, errlen, "pmsim_add_effect: invalid arguments");
        return -1;
    }
    std::string e = effect;
    pm_model &m = spec->truth;
    if (!std::isfinite(arcsec) || !std::isfinite(phase_deg)) {
        set_err(err, errlen, std::string("effect ") + e + ": size and phase must be finite");
        return -1;
    }
    const double as = ARCSEC;
    try {
        if (e == "outlier" || e.rfind("outlier:", 0) == 0) {
            int n = e == "outlier" ? 1 : std::atoi(e.c_str() + 8);
            if (n < 1)
                throw std::runtime_error("outlier:N needs N >= 1");
            spec->n_outliers += n;
            spec->outlier_arcsec = arcsec;
            return 0;
        }
        if (e == "higher_order") {
            if (m.order + 1 > PM_MAX_L)
                throw std::runtime_error("higher_order: the truth is already at PM_MAX_L");
            pm_model h;
            pm_model_init(&h, m.mount, m.order + 1);
            h.latitude = m.latitude;
            for (int i = 0; i < m.n_base; i++) {
                int idx;
                if (pm_model_find(&h, m.term[i].k, m.term[i].l, m.term[i].m, &idx) == PM_OK)
                    h.coef[idx] = m.coef[i];
            }
            std::mt19937_64 rng(seed ^ 0x4849ULL);
            std::normal_distribution<double> g(0.0, 1.0);
            for (int i = 0; i < h.n_base; i++)
                if (h.term[i].l == h.order)
                    h.coef[i] = arcsec * as * g(rng);
            pm_model_prepare(&h);
            for (int i = m.n_base; i < m.n_terms; i++)
                if (pm_model_add_term(&h, &m.term[i], m.coef[i], nullptr) != PM_OK)
                    throw std::runtime_error("higher_order: cannot carry over the added terms");
            m = h;
            return 0;
        }
        // the terms pmfit fit --add would add, with the given size
        pmhost::Obs ref{0, 0, 0, 0, 1, 0, pm_context()};
        std::memset(&ref.ctx, 0, sizeof ref.ctx);
        ref.ctx.temp_c = spec->temp_start_c;
        ref.ctx.time_h = spec->start_time_h;
        ref.ctx.dir = 1;
        pm_model with = pmhost::build_model(m.order, {e}, {ref}, m.mount, m.latitude, {});
        int first = m.n_terms;
        for (int i = with.n_base; i < with.n_terms; i++) {
            pm_term t = with.term[i];
            if (t.kind == PM_TERM_AUX) // references: the run's start, no direction
                t.param = t.aux == PM_AUX_TEMP ? spec->temp_start_c
                          : t.aux == PM_AUX_TIME ? spec->start_time_h : 0.0;
            if (pm_model_add_term(&m, &t, 0.0, nullptr) != PM_OK)
                throw std::runtime_error("cannot add the effect's terms to the truth");
        }
        double v = arcsec * as;
        bool periodic = m.n_terms > first && (m.term[first].kind == PM_TERM_FOURIER ||
                                              m.term[first].kind == PM_TERM_SECTORAL);
        if (periodic) { // first harmonic: amplitude and phase
            double ph = phase_deg * PI / 180;
            m.coef[first] = v * std::cos(ph);
            m.coef[first + 1] = v * std::sin(ph);
        } else {
            for (int i = first; i < m.n_terms; i++)
                m.coef[i] = v;
        }
        if (pm_model_prepare(&m) != PM_OK)
            throw std::runtime_error("the true model is invalid");
    } catch (const std::exception &x) {
        set_err(err, errlen, std::string("effect ") + e + ": " + x.what());
        return -1;
    }
    return 0;
}
