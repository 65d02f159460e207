// tpointterms.cpp - a fitted model as a TPOINT-style term list
// (tpointterms.h; docs/formats.md, "TPOINT term export").
#include "tpointterms.h"

#include "fitrun.hpp"
#include "hostutil.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace {

const double kAs = 206264.80624709636;   // arcsec per radian

struct Map {
    const char *name;
    int k;          // base vector of an isotropic term (0: a zenith term)
    int zenith_l;   // for zenith terms: 1 cos(el) (TF), 0 cot(el) (TX)
    double sign;    // TPOINT value = sign * pm coefficient
};

// From the first-order forms (tpointterms.h): true = raw + correction.
// Equatorial: IH = c', ID = -e', NP = -d, CH = i, MA = a, ME = -b.
const Map kEquatorial[PMTP_MAX_NAMED] = {
    {"IH", PM_BASE_C, -1, 1.0}, {"ID", PM_BASE_E, -1, -1.0}, {"NP", PM_BASE_D, -1, -1.0},
    {"CH", PM_BASE_I, -1, 1.0}, {"MA", PM_BASE_A, -1, 1.0},  {"ME", PM_BASE_B, -1, -1.0},
    {"TF", 0, 1, -1.0},         {"TX", 0, 0, -1.0}};

// Alt-az, TPOINT's azimuth from south through east: IA = c', IE = -e',
// CA = i, NPAE = -d, AN = b, AW = a.
const Map kAltaz[PMTP_MAX_NAMED] = {
    {"IA", PM_BASE_C, -1, 1.0}, {"IE", PM_BASE_E, -1, -1.0},  {"CA", PM_BASE_I, -1, 1.0},
    {"NPAE", PM_BASE_D, -1, -1.0}, {"AN", PM_BASE_B, -1, 1.0}, {"AW", PM_BASE_A, -1, 1.0},
    {"TF", 0, 1, -1.0},         {"TX", 0, 0, -1.0}};

const Map *map_of(const pm_model *m)
{
    if (m->mount == PM_MOUNT_EQUATORIAL) return kEquatorial;
    if (m->mount == PM_MOUNT_ALTAZ) return kAltaz;
    return nullptr;
}

// Index of the term a map entry names, -1 if the model has none.
int find(const pm_model *m, const Map &e)
{
    for (int i = 0; i < m->n_terms; ++i) {
        const pm_term &t = m->term[i];
        if (e.k && i < m->n_base && t.kind == PM_TERM_SH && t.k == e.k && t.l == 0 && t.m == 0)
            return i;
        if (!e.k && t.kind == PM_TERM_ZENITH && t.l == e.zenith_l && t.side == 0) return i;
    }
    return -1;
}

// The '!' lines at the top of the file: the convention of the values.
const char *convention(const pm_model *m)
{
    if (m->mount == PM_MOUNT_ALTAZ)
        return "! Values in arcsec; TPOINT corrections from the raw to the true position,\n"
               "! true = raw + (dA, dE), A, E the raw azimuth and elevation, A from SOUTH\n"
               "! through east (TPOINT's convention; A = 180 deg - pmfit's azimuth):\n"
               "!   dA = -IA - CA sec E - NPAE tan E + AN sin A tan E - AW cos A tan E\n"
               "!   dE =  IE + AN cos A + AW sin A - TF cos E - TX cot E\n"
               "! Positive TF, TX: the telescope points below where the encoders say (droop).\n";
    return "! Values in arcsec; TPOINT corrections from the raw to the true position,\n"
           "! true = raw + (dh, dd), h, d the raw hour angle (west positive) and dec:\n"
           "!   dh = IH + CH sec d + NP tan d - MA cos h tan d + ME sin h tan d\n"
           "!        + (TF + TX / sin el) cos phi sin h sec d\n"
           "!   dd = ID + MA sin h + ME cos h + (TF + TX / sin el) (cos phi cos h sin d - sin phi cos d)\n"
           "! Positive TF, TX: the telescope points below where the encoders say (droop).\n";
}

}  // namespace

extern "C" int pmtp_terms(const pm_model *m, const double *err_rad, pmtp_term *named, int *n_named)
{
    if (!m || !named || !n_named) return -1;
    if (m->n_terms < 6 || m->n_terms > PM_MAX_TERMS || m->n_base < 6 || m->n_base > m->n_terms)
        return -1; /* (the model need not be prepared: its counts are checked) */
    const Map *map = map_of(m);
    if (!map) return -1;
    // pm's polar-axis tilts a, b are the outermost rotation, at the index-
    // shifted axis-1 angle tau + c' (docs/model.md, "The isotropic part is
    // exact"); TPOINT's MA, ME (AW, AN) act at the raw angle.  So the tilt
    // is turned by c': a sin(h + c') - b cos(h + c') = X sin h - Y cos h with
    // X = a cos c' + b sin c', Y = b cos c' - a sin c' (and likewise in dh),
    // in place of X = a, Y = b, which left a c' x tilt error: 345" of ME at
    // IH = 5.5 deg and MA = 1 deg (cgx-l-data.dat).  Their errors are
    // turned without the a-b covariance, which pm_fit_result does not hold
    // (it mixes them by sin c').
    const double cc = std::cos(m->coef[PM_BASE_C - 1]), sc = std::sin(m->coef[PM_BASE_C - 1]);
    const double a = m->coef[PM_BASE_A - 1], b = m->coef[PM_BASE_B - 1];
    int n = 0;
    for (int j = 0; j < PMTP_MAX_NAMED; ++j) {
        const Map &e = map[j];
        int i = find(m, e);
        if (i < 0) continue;
        pmtp_term &t = named[n++];
        std::memset(&t, 0, sizeof t);
        std::snprintf(t.name, sizeof t.name, "%s", e.name);
        double v = m->coef[i], ev = err_rad ? err_rad[i] : std::nan("");
        if (e.k == PM_BASE_A || e.k == PM_BASE_B) {
            const double ea = err_rad ? err_rad[PM_BASE_A - 1] : std::nan("");
            const double eb = err_rad ? err_rad[PM_BASE_B - 1] : std::nan("");
            v = e.k == PM_BASE_A ? a * cc + b * sc : b * cc - a * sc;
            ev = e.k == PM_BASE_A ? std::hypot(ea * cc, eb * sc) : std::hypot(eb * cc, ea * sc);
        }
        t.value_arcsec = e.sign * v * kAs;
        t.error_arcsec = ev * kAs;
        t.pm_index = i;
    }
    *n_named = n;
    return 0;
}

extern "C" int pmtp_write(const char *path, const pm_model *m, const double *err_rad,
                          const char *caption, char *err, size_t errlen)
{
    if (!path || !m) {
        if (err && errlen) std::snprintf(err, errlen, "pmtp_write: NULL argument");
        return -1;
    }
    pmtp_term named[PMTP_MAX_NAMED];
    int n = 0;
    if (pmtp_terms(m, err_rad, named, &n) != 0) {
        if (err && errlen)
            std::snprintf(err, errlen, "%s: TPOINT terms are written for equatorial and alt-az "
                                       "models only (mount type %d; docs/formats.md)",
                          path, m->mount);
        return -1;
    }
    std::string text =
        "! TPOINT-style term list written by pmfit (docs/formats.md, \"TPOINT term export\").\n";
    text += convention(m);
    std::string cap = caption ? caption : "pmfit model";
    for (char &c : cap)
        if (c == '\n' || c == '\r') c = ' ';
    text += cap + "\n";
    char buf[160];
    for (int k = 0; k < n; ++k) {
        if (std::isnan(named[k].error_arcsec))
            std::snprintf(buf, sizeof buf, "     %-4.7s %14.4f\n", named[k].name, named[k].value_arcsec);
        else
            std::snprintf(buf, sizeof buf, "     %-4.7s %14.4f %10.4f\n", named[k].name,
                          named[k].value_arcsec, named[k].error_arcsec);
        text += buf;
    }
    text += "END\n";
    std::string rest;
    for (int i = 0; i < m->n_terms; ++i) {
        bool is_named = false;
        for (int k = 0; k < n; ++k) is_named = is_named || named[k].pm_index == i;
        if (is_named) continue;
        double e = err_rad ? err_rad[i] * kAs : std::nan("");
        if (std::isnan(e))
            std::snprintf(buf, sizeof buf, "!   %-22s %14.4f\n", pmhost::term_name(*m, i).c_str(),
                          m->coef[i] * kAs);
        else
            std::snprintf(buf, sizeof buf, "!   %-22s %14.4f %10.4f\n",
                          pmhost::term_name(*m, i).c_str(), m->coef[i] * kAs, e);
        rest += buf;
    }
    if (!rest.empty())
        text += "! Terms of the model with no TPOINT name (pm names, arcsec; docs/model.md). They\n"
                "! are part of the fitted model: the TPOINT terms above alone are not the model.\n" +
                rest;
    return pmhost::write_atomic(path, text, err, errlen);
}
