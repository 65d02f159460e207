// simulate.cpp - simulated pointing runs (host side).
#include "simulate.h"
#include "hostutil.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <sstream>
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
    for (long i = 0; i < s->n; i++) {
        const Target &t = seq[(size_t)i];
        int side = 0; // pm side for the inverse
        if (!altaz && s->gem)
            side = t.ha > 0 ? PM_SIDE_FLIPPED : PM_SIDE_NORMAL; // west of the meridian: flipped
        double time_h = s->start_time_h + (double)i * s->minutes_per_point / 60.0;
        double temp = s->temp_start_c + s->temp_rate_c_per_h * (time_h - s->start_time_h);
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
        double D = t.dec + s->noise_arcsec * ARCSEC * gauss(rng);
        double T = t.ha + s->noise_arcsec * ARCSEC * gauss(rng) / std::cos(t.dec);
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
