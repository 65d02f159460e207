// modelfile.cpp - text model files and C-header emission (host side).
#include "modelfile.h"
#include "hostutil.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cctype>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using pmhost::set_err;
using pmhost::write_atomic;

std::string name_of(const pm_model *m, int i)
{
    char buf[32];
    pm_term_name(m, i, buf, sizeof buf);
    return buf;
}

void comment_lines(std::string &out, const char *comment, const char *lead)
{
    if (!comment)
        return;
    std::istringstream in(comment);
    std::string line;
    while (std::getline(in, line))
        out += std::string(lead) + line + "\n";
}

const char *kind_name(int kind)
{
    switch (kind) {
    case PM_TERM_SH: return "sh";
    case PM_TERM_FOURIER: return "fourier";
    case PM_TERM_SECTORAL: return "sectoral";
    case PM_TERM_ZENITH: return "zenith";
    case PM_TERM_AUX: return "aux";
    }
    return "?";
}

int kind_of(const std::string &s)
{
    for (int k = PM_TERM_SH; k <= PM_TERM_AUX; k++)
        if (s == kind_name(k))
            return k;
    return -1;
}

std::string fmt17(double v)
{
    char b[40];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

bool parse_double(const std::string &s, double *v)
{
    if (s.empty())
        return false;
    char *end = nullptr;
    errno = 0;
    double x = std::strtod(s.c_str(), &end);
    /* (ERANGE on underflow is a subnormal or zero, which %.17g writes and
    ** is a value: only an overflow is refused) */
    if (*end || (errno == ERANGE && std::fabs(x) == HUGE_VAL) || !std::isfinite(x))
        return false;
    *v = x;
    return true;
}

bool parse_int(const std::string &s, long lo, long hi, long *v)
{
    if (s.empty())
        return false;
    char *end = nullptr;
    long x = std::strtol(s.c_str(), &end, 10);
    if (*end || x < lo || x > hi)
        return false;
    *v = x;
    return true;
}

// One line of at most max bytes (without its '\n'): 1, 0 at the end of the
// file, -1 when longer (the rest is not read: bounded memory and time).
int read_line(std::istream &in, std::string &line, size_t max)
{
    line.clear();
    bool any = false;
    for (int c; (c = in.get()) != EOF;) {
        any = true;
        if (c == '\n')
            return 1;
        if (line.size() >= max)
            return -1;
        line.push_back((char)c);
    }
    return any ? 1 : 0;
}

} // namespace

// A model pmmodel_load would read back (and a compiler compile): one that
// pm_model_prepare accepts -- finite coefficients, a latitude, valid terms.
// A NaN coefficient was written as "nan", a term of l = 40 as it was, and
// the file then failed to load.
static bool preparable(const pm_model *m, const char *path, const char *who, char *err,
                       size_t errlen)
{
    pm_model c = *m;
    pm_status st = pm_model_prepare(&c);
    if (st == PM_OK)
        return true;
    set_err(err, errlen, std::string(path) + ": " + who + ": not written: pm_model_prepare " +
                             "refuses the model (status " + std::to_string((int)st) +
                             ": a coefficient or the latitude not finite or out of range, or a "
                             "term not valid)");
    return false;
}

// Does the model read its user input j (a term on PM_AUX_USER + j)?
static bool reads_input(const pm_model *m, int j)
{
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_AUX && m->term[i].aux == PM_AUX_USER + j)
            return true;
    return false;
}

// The info's lines of a version-4 file ("" when it says nothing of this
// model), or false with err when a name cannot be written.
static bool info_lines(const pm_model *m, const pmmodel_info *info, const char *path,
                       std::string *lines, char *err, size_t errlen)
{
    lines->clear();
    if (!info)
        return true;
    if (info->pier < -1 || info->pier > 1) {
        set_err(err, errlen, std::string(path) + ": pmmodel_save_info: pier " +
                                 std::to_string(info->pier) + " (expected 0, +1 or -1)");
        return false;
    }
    std::vector<std::string> used;
    for (int j = 0; j < PM_MAX_AUX; j++) {
        const char *nm = info->input[j];
        size_t len = strnlen(nm, PMMODEL_NAME_MAX);
        if (len == 0 || !reads_input(m, j))
            continue;
        std::string name(nm, len);
        if (len == PMMODEL_NAME_MAX || !pmhost::valid_column_name(name)) {
            set_err(err, errlen, std::string(path) + ": pmmodel_save_info: input " +
                                     std::to_string(j) + ": '" + name.substr(0, 80) +
                                     "' is not a column name (letters, digits, '_', '.', '-', "
                                     "a letter or '_' first, under " +
                                     std::to_string(PMMODEL_NAME_MAX) + " bytes)");
            return false;
        }
        for (const std::string &u : used)
            if (u == name) {
                set_err(err, errlen, std::string(path) + ": pmmodel_save_info: two inputs "
                                         "named '" + name + "'");
                return false;
            }
        used.push_back(name);
        *lines += "input " + std::to_string(j) + " " + name + "\n";
    }
    if (info->pier)
        *lines += std::string("pier ") + (info->pier > 0 ? "east" : "west") + "\n";
    if (info->has_err) {
        for (int i = 0; i < m->n_terms; i++)
            if (!(std::isfinite(info->err[i]) && info->err[i] >= 0)) {
                set_err(err, errlen, std::string(path) + ": pmmodel_save_info: the error of "
                                         "term " + name_of(m, i) + " is not a finite number "
                                         ">= 0");
                return false;
            }
        *lines += "errors\n"; /* (the term lines' last field) */
    }
    return true;
}

extern "C" int pmmodel_save(const char *path, const pm_model *m, const char *comment,
                            char *err, size_t errlen)
{
    return pmmodel_save_info(path, m, nullptr, comment, err, errlen);
}

// The correlation rows of a version-5 file from the covariance (row-major,
// P x P): 'corr I J r...' lines, I = 2..P, at most 8 values a line, the
// lower triangle in order; false with err where cov is not a covariance.
static bool corr_lines(const pm_model *m, const double *cov, const char *path,
                       std::string *lines, char *err, size_t errlen)
{
    const int P = m->n_terms;
    for (int i = 0; i < P; i++)
        for (int j = 0; j <= i; j++) {
            const double c = cov[(size_t)i * P + j];
            if (!std::isfinite(c) || c != cov[(size_t)j * P + i] || (i == j && c < 0)) {
                set_err(err, errlen, std::string(path) + ": pmmodel_save_cov: the covariance of " +
                                         name_of(m, i) + " and " + name_of(m, j) +
                                         (i == j ? " is not a finite number >= 0"
                                                 : " is not finite or not symmetric"));
                return false;
            }
        }
    for (int i = 1; i < P; i++)
        for (int j0 = 0; j0 < i; j0 += 8) {
            char b[64];
            std::snprintf(b, sizeof b, "corr %d %d", i + 1, j0 + 1);
            *lines += b;
            for (int j = j0; j < i && j < j0 + 8; j++) {
                const double vi = cov[(size_t)i * P + i], vj = cov[(size_t)j * P + j];
                double r = vi > 0 && vj > 0 ? cov[(size_t)i * P + j] / std::sqrt(vi * vj) : 0;
                r = r > 1 ? 1 : r < -1 ? -1 : r;
                std::snprintf(b, sizeof b, " %.10g", r);
                *lines += b;
            }
            *lines += "\n";
        }
    return true;
}

static int save_model(const char *path, const pm_model *m, const pmmodel_info *info,
                      const double *cov, const char *comment, char *err, size_t errlen)
{
    if (!path || !m || m->n_terms < 6 || m->n_terms > PM_MAX_TERMS) {
        set_err(err, errlen, "pmmodel_save: invalid arguments");
        return -1;
    }
    if (!preparable(m, path, "pmmodel_save", err, errlen))
        return -1;
    std::string extra, corr;
    if (!info_lines(m, info, path, &extra, err, errlen))
        return -1;
    if (cov) {
        if (!info || !info->has_err) {
            set_err(err, errlen, std::string(path) + ": pmmodel_save_cov: the covariance needs "
                                     "the errors (info->has_err): the file keeps correlations "
                                     "beside them");
            return -1;
        }
        if (!corr_lines(m, cov, path, &corr, err, errlen))
            return -1;
        extra += "correlations\n"; /* (the 'corr' lines after the terms) */
        if (std::isfinite(info->stars_sigma) && info->stars_sigma > 0)
            extra += "stars_sigma " + fmt17(info->stars_sigma) + "\n";
    }
    std::string out;
    comment_lines(out, comment, "# ");
    /* (version 3 where there is nothing more to say: a reader of before
    ** version 4 reads it as before; 5 only with correlations) */
    out += cov ? "pm-model 5\n" : extra.empty() ? "pm-model 3\n" : "pm-model 4\n";
    out += std::string("mount ") + (m->mount == PM_MOUNT_ALTAZ ? "altaz" : "equatorial") + "\n";
    out += "order " + std::to_string(m->order) + "\n";
    if (m->latitude != 0)
        out += "latitude " + fmt17(m->latitude) + "\n";
    out += extra;
    out += "terms " + std::to_string(m->n_terms) + "\n";
    const bool errs = info && info->has_err;
    out += errs ? "# name k l m value_rad error_rad\n" : "# name k l m value_rad\n";
    for (int i = 0; i < m->n_terms; i++) {
        char buf[320];
        const pm_term &t = m->term[i];
        if (i < m->n_base)
            std::snprintf(buf, sizeof buf, "term %s %d %d %d %.17g", name_of(m, i).c_str(),
                          t.k, t.l, t.m, m->coef[i]);
        else
            std::snprintf(buf, sizeof buf, "xterm %s %s %d %d %d %d %d %.17g %.17g",
                          name_of(m, i).c_str(), kind_name(t.kind), t.k, t.l, t.m, t.side, t.aux,
                          t.param, m->coef[i]);
        out += buf;
        out += errs ? " " + fmt17(info->err[i]) + "\n" : std::string("\n");
    }
    if (cov)
        out += "# correlations of term I with terms J, J+1, ... (the lower triangle)\n" + corr;
    out += "end\n";
    return write_atomic(path, out, err, errlen);
}

extern "C" int pmmodel_save_info(const char *path, const pm_model *m, const pmmodel_info *info,
                                 const char *comment, char *err, size_t errlen)
{
    return save_model(path, m, info, nullptr, comment, err, errlen);
}

extern "C" int pmmodel_save_cov(const char *path, const pm_model *m, const pmmodel_info *info,
                                const double *cov, const char *comment, char *err, size_t errlen)
{
    return save_model(path, m, info, cov, comment, err, errlen);
}

namespace {

// A model file being read (pmmodel_load): where it is, what it said so far.
struct Loader {
    enum State { HEADER, MOUNT, ORDER, TERMS, BODY, DONE } state = HEADER;
    int lineno = 0, end_line = 0;
    int mount = 0, version = 3;
    long order = 0, nterms = 0;
    int base = -1; // index of the first added term
    int got = 0;   // terms read
    double latitude = 0;
    pm_model m;
    pmmodel_info info;          // version 4's input and pier lines
    std::vector<int> term_line; // line of each term, for the term-list check
    bool has_corr = false;      // version 5's 'correlations' line
    int corr_row = 1, corr_col = 0; // the next correlation (0-based: row > col)
    std::vector<double> corr;   // P x P, unit diagonal
    std::vector<int> corr_line; // line of each row's first 'corr' line
    Loader()
    {
        std::memset(&m, 0, sizeof m);
        std::memset(&info, 0, sizeof info);
    }
};

// A term that an older file's version evaluated elsewhere: version 1 the
// anisotropic tilt terms (k = 1, 2) at the encoder reading, version 2 the
// harmonics and the other base vectors there; version 3 all at the
// index-shifted (mechanical) position.  Where the file's index terms c'
// and e' are both zero the two positions are one.
std::string old_term(const Loader &L, const std::string &name)
{
    return "term " + name + " of a 'pm-model " + std::to_string(L.version) +
           "' file: versions before 3 evaluated " +
           (L.version == 1 ? "the anisotropic terms" : "the harmonics and the base vectors of "
                                                       "the axes, the axes' angle and the tube") +
           " at the encoder reading, this one at the index-shifted (mechanical) position "
           "(docs/model.md, \"The anisotropic terms: at the mechanical position\"); the model "
           "would point differently: refit the run and save it again";
}

// Does this term of an older file evaluate differently now (old_term)?
// added: an added term (xterm; a side-specific isotropic term is an added
// SH term of l = 0, whose base vector moved as every other did).
bool moved_term(const Loader &L, int kind, long k, long l, double v, bool added)
{
    if (L.version >= 3 || v == 0 || (L.m.coef[2] == 0 && L.m.coef[4] == 0))
        return false;
    if (L.version == 1 && (k == 1 || k == 2) && (kind != PM_TERM_SH || l >= 1))
        return true; /* (version 1: the tilts at the encoder reading) */
    if (kind == PM_TERM_SH && (l >= 1 || !added))
        return l >= 1;
    /* base vectors cos d, -sin d (c'@W, d@W of a version-2 file were read
    ** without a word and pointed up to 5.75" differently) */
    return k == 3 || k == 4;
}

// Version 4's "input J NAME" (the run column read as pm_context.aux[J])
// and "pier east|west" (a one-side model) lines: "" or why not.
std::string info_line(Loader &L, const std::vector<std::string> &tok)
{
    if (L.version < 4)
        return "an '" + tok[0] + "' line in a 'pm-model " + std::to_string(L.version) +
               "' file (version 4 has them)";
    if (tok[0] == "correlations") {
        if (L.version < 5)
            return "a 'correlations' line in a 'pm-model " + std::to_string(L.version) +
                   "' file (version 5 has it)";
        if (tok.size() != 1)
            return "expected 'correlations' alone ('corr' lines after the terms then give them)";
        if (!L.info.has_err)
            return "a 'correlations' line without the 'errors' line before it";
        if (L.has_corr)
            return "a second 'correlations' line";
        L.has_corr = true;
        return "";
    }
    if (tok[0] == "stars_sigma") {
        if (L.version < 5)
            return "a 'stars_sigma' line in a 'pm-model " + std::to_string(L.version) +
                   "' file (version 5 has it)";
        double v;
        if (tok.size() != 2 || !parse_double(tok[1], &v) || !(v > 0))
            return "expected 'stars_sigma S': the fit's predicted 1-sigma at its stars, radians "
                   "> 0";
        if (L.info.stars_sigma > 0)
            return "a second 'stars_sigma' line";
        L.info.stars_sigma = v;
        return "";
    }
    if (tok[0] == "errors") {
        if (tok.size() != 1)
            return "expected 'errors' alone (each term line then ends in its 1-sigma error)";
        if (L.info.has_err)
            return "a second 'errors' line";
        L.info.has_err = 1;
        return "";
    }
    if (tok[0] == "pier") {
        if (tok.size() != 2 || (tok[1] != "east" && tok[1] != "west"))
            return "expected 'pier east' or 'pier west' (a model of one pier side)";
        if (L.info.pier)
            return "a second 'pier' line";
        L.info.pier = tok[1] == "east" ? 1 : -1;
        return "";
    }
    long j;
    if (tok.size() != 3 || !parse_int(tok[1], 0, 1000, &j))
        return "expected 'input J NAME': the run column NAME read as the context's aux[J]";
    if (j >= PM_MAX_AUX)
        return "input " + tok[1] + " is beyond this build's PM_MAX_AUX = " +
               std::to_string(PM_MAX_AUX) + " inputs (0.." + std::to_string(PM_MAX_AUX - 1) +
               ")";
    if (tok[2].size() >= PMMODEL_NAME_MAX || !pmhost::valid_column_name(tok[2]))
        return "input name '" + tok[2].substr(0, 80) + "' is not a column name (letters, "
               "digits, '_', '.', '-', a letter or '_' first, under " +
               std::to_string(PMMODEL_NAME_MAX) + " bytes)";
    if (L.info.input[j][0])
        return "a second name for input " + tok[1];
    for (int q = 0; q < PM_MAX_AUX; q++)
        if (tok[2] == L.info.input[q])
            return "input " + tok[1] + " is named '" + tok[2] + "' as input " +
                   std::to_string(q) + " is";
    std::memcpy(L.info.input[j], tok[2].c_str(), tok[2].size() + 1);
    return "";
}

// The header's lines, one state each: "" when the line is right, else why.
std::string header_line(Loader &L, const std::vector<std::string> &tok)
{
    switch (L.state) {
    case Loader::HEADER:
        if (tok.size() != 2 || tok[0] != "pm-model")
            return "expected 'pm-model N' first, N = 1..5 (is this a pm model file?)";
        if (tok[1] != "1" && tok[1] != "2" && tok[1] != "3" && tok[1] != "4" && tok[1] != "5")
            return "model file version '" + tok[1] + "' not supported (expected 5, 4 or 3, or 2 "
                   "or 1)";
        L.version = tok[1][0] - '0';
        L.state = Loader::MOUNT;
        return "";
    case Loader::MOUNT:
        if (tok.size() != 2 || tok[0] != "mount" || (tok[1] != "equatorial" && tok[1] != "altaz"))
            return "expected 'mount equatorial' or 'mount altaz'";
        L.mount = tok[1] == "altaz" ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
        L.state = Loader::ORDER;
        return "";
    case Loader::ORDER:
        if (tok.size() != 2 || tok[0] != "order" || !parse_int(tok[1], 0, 1000, &L.order))
            return "expected 'order L' with an integer L >= 0";
        if (L.order > PM_MAX_L)
            return "model order " + std::to_string(L.order) + " exceeds this build's PM_MAX_L = " +
                   std::to_string(PM_MAX_L) + " (rebuild with -DPM_MAX_L=" +
                   std::to_string(L.order) + ")";
        L.state = Loader::TERMS;
        return "";
    default: // TERMS
        if (tok.size() == 2 && tok[0] == "latitude") {
            if (!parse_double(tok[1], &L.latitude) || std::fabs(L.latitude) > 1.5707963267948966)
                return "bad latitude '" + tok[1] + "' (expected radians, |lat| <= pi/2)";
            return "";
        }
        if (tok[0] == "input" || tok[0] == "pier" || tok[0] == "errors" ||
            tok[0] == "correlations" || tok[0] == "stars_sigma")
            return info_line(L, tok);
        if (tok.size() != 2 || tok[0] != "terms" || !parse_int(tok[1], 6, 100000, &L.nterms))
            return "expected 'terms P' with an integer P >= 6";
        if (L.nterms > PM_MAX_TERMS)
            return std::to_string(L.nterms) + " terms exceed this build's capacity of " +
                   std::to_string(PM_MAX_TERMS) + " (rebuild with -DPM_MAX_EXTRA=" +
                   std::to_string(L.nterms - PM_SH_TERMS(PM_MAX_L)) + ")";
        L.m.mount = L.mount;
        L.m.order = (int)L.order;
        L.m.n_terms = (int)L.nterms;
        L.m.latitude = L.latitude;
        if (L.has_corr) {
            L.corr.assign((size_t)(L.nterms * L.nterms), 0.0);
            for (long i = 0; i < L.nterms; i++)
                L.corr[(size_t)(i * L.nterms + i)] = 1;
        }
        L.state = Loader::BODY;
        return "";
    }
}

// xterm NAME KIND k l m side aux param value: an added term.
std::string added_term(Loader &L, const std::vector<std::string> &tok)
{
    long k, l, mm, side, aux;
    double v, param;
    if (L.got >= L.nterms)
        return "more terms than the header's " + std::to_string(L.nterms);
    if (L.got < 6)
        return "an added term (xterm) before the six isotropic terms";
    int kind = kind_of(tok[2]);
    if (kind < 0)
        return "unknown term kind '" + tok[2] + "' (expected sh, fourier, sectoral, zenith or aux)";
    if (!parse_int(tok[3], 0, 6, &k) || !parse_int(tok[4], -100, 100, &l) ||
        !parse_int(tok[5], -100, 100, &mm) || !parse_int(tok[6], -1, 1, &side) ||
        !parse_int(tok[7], 0, 255, &aux))
        return "bad fields of an added term (expected xterm NAME KIND k l m side aux param value)";
    if (!parse_double(tok[8], &param) || !parse_double(tok[9], &v))
        return "bad parameter or value (expected finite numbers)";
    if (moved_term(L, kind, k, l, v, true))
        return old_term(L, tok[1]);
    if (L.base < 0)
        L.base = L.got;
    pm_term &nt = L.m.term[L.got];
    nt.kind = (unsigned char)kind;
    nt.k = (unsigned char)k;
    nt.l = (signed char)l;
    nt.m = (signed char)mm;
    nt.side = (signed char)side;
    nt.aux = (unsigned char)aux;
    nt.param = param;
    L.m.coef[L.got] = v;
    L.term_line.push_back(L.lineno);
    L.got++;
    return "";
}

// term NAME k l m value: a harmonic term (before any added term).
std::string harmonic_term(Loader &L, const std::vector<std::string> &tok)
{
    long k, l, mm;
    double v;
    if (L.got >= L.nterms)
        return "more terms than the header's " + std::to_string(L.nterms);
    if (L.base >= 0)
        return "a harmonic term after an added term (xterm lines come last)";
    if (!parse_int(tok[2], 1, 6, &k) || !parse_int(tok[3], 0, L.order, &l) ||
        !parse_int(tok[4], -l, l, &mm))
        return "bad term indices '" + tok[2] + " " + tok[3] + " " + tok[4] +
               "' (expected k in 1..6, l in 0..order, |m| <= l)";
    if (!parse_double(tok[5], &v))
        return "bad value '" + tok[5] + "' (expected a finite number, radians)";
    if (moved_term(L, PM_TERM_SH, k, l, v, false))
        return old_term(L, tok[1]);
    L.m.term[L.got].kind = PM_TERM_SH;
    L.m.term[L.got].k = (unsigned char)k;
    L.m.term[L.got].l = (signed char)l;
    L.m.term[L.got].m = (signed char)mm;
    L.m.coef[L.got] = v;
    L.term_line.push_back(L.lineno);
    L.got++;
    return "";
}

// corr I J r...: term I's correlations with terms J, J+1, ... (1-based),
// the lower triangle's next values in order: "" or why not.
std::string corr_line(Loader &L, const std::vector<std::string> &tok)
{
    if (!L.has_corr)
        return "a 'corr' line without the 'correlations' line in the header";
    if (L.got != L.nterms)
        return "a 'corr' line before the last term line (correlations come after every term)";
    if (L.corr_row >= L.nterms)
        return "more correlations than the " + std::to_string(L.nterms) + " terms have";
    long I, J;
    const std::string want = "'corr " + std::to_string(L.corr_row + 1) + " " +
                             std::to_string(L.corr_col + 1) + " r...'";
    if (tok.size() < 4 || !parse_int(tok[1], 1, 100000, &I) || !parse_int(tok[2], 1, 100000, &J))
        return "expected " + want + " (term I's correlations with terms J, J+1, ...)";
    if (I != L.corr_row + 1 || J != L.corr_col + 1)
        return "'corr " + tok[1] + " " + tok[2] + "' out of order, expected " + want +
               " (the lower triangle, row by row)";
    if ((long)tok.size() - 3 > I - J)
        return std::to_string(tok.size() - 3) + " correlations from term " + tok[2] +
               " on, term " + tok[1] + " has " + std::to_string(I - J) + " left before itself";
    if (L.corr_col == 0)
        L.corr_line.push_back(L.lineno);
    const size_t P = (size_t)L.nterms;
    for (size_t q = 3; q < tok.size(); q++) {
        double r;
        if (!parse_double(tok[q], &r) || std::fabs(r) > 1)
            return "bad correlation '" + tok[q] + "' of terms " + tok[1] + " and " +
                   std::to_string(L.corr_col + 1) + " (expected a number within -1..1)";
        L.corr[(size_t)L.corr_row * P + (size_t)L.corr_col] =
            L.corr[(size_t)L.corr_col * P + (size_t)L.corr_row] = r;
        if (++L.corr_col == L.corr_row) {
            L.corr_row++;
            L.corr_col = 0;
        }
    }
    return "";
}

// The correlations must be those of a covariance: positive semi-definite
// to 1e-6 (the Cholesky factorisation of C + 1e-6 I exists), "" or why not,
// L.lineno the row to blame.  Their 10 digits move an eigenvalue by at most
// P * 5e-11, so a fitted covariance always passes, however nearly singular
// (an outside probe's order-2 fit of 26 stars, two terms correlated
// -0.99999, had been refused on reading back its own file: a pivot of 1e-12
// was taken for zero and the next row's 1e-6 for a contradiction); a table
// no covariance has is refused where it fails (r21 = r31 = 1, r32 = -1:
// eigenvalues -1, 2, 2).
std::string check_correlations(Loader &L)
{
    const size_t P = (size_t)L.nterms;
    std::vector<double> c = L.corr; // Cholesky in place, lower triangle
    for (size_t j = 0; j < P; j++) {
        double d = c[j * P + j] + 1e-6;
        for (size_t k = 0; k < j; k++)
            d -= c[j * P + k] * c[j * P + k];
        if (!(d > 0)) {
            L.lineno = j > 0 ? L.corr_line[j - 1] : L.end_line;
            return "the correlations are not those of a covariance (not positive semi-definite "
                   "at term " + std::to_string(j + 1) + ", " + name_of(&L.m, (int)j) +
                   ": its correlations with the terms before it are not possible together)";
        }
        const double s = std::sqrt(d);
        c[j * P + j] = s;
        for (size_t i = j + 1; i < P; i++) {
            double v = c[i * P + j];
            for (size_t k = 0; k < j; k++)
                v -= c[i * P + k] * c[j * P + k];
            c[i * P + j] = v / s;
        }
    }
    return "";
}

// One line of the file (not blank, not a comment): "" or why it is wrong.
std::string file_line(Loader &L, const std::vector<std::string> &tok)
{
    if (L.state == Loader::DONE)
        return "text after 'end'";
    if (L.state != Loader::BODY)
        return header_line(L, tok);
    if (tok.size() == 1 && tok[0] == "end") {
        if (L.got != L.nterms)
            return "'end' after " + std::to_string(L.got) + " terms; the header says " +
                   std::to_string(L.nterms);
        if (L.has_corr && L.corr_row < L.nterms)
            return "'end' before the correlations of term " + std::to_string(L.corr_row + 1) +
                   " (expected 'corr " + std::to_string(L.corr_row + 1) + " " +
                   std::to_string(L.corr_col + 1) + " ...': the file's 'correlations' line)";
        L.end_line = L.lineno;
        L.state = Loader::DONE;
        return "";
    }
    if (tok[0] == "corr")
        return corr_line(L, tok);
    if (L.has_corr && L.corr_row > 1)
        return "a term line after the 'corr' lines (they come after every term)";
    const size_t e = L.info.has_err ? 1 : 0; /* the error field after the value */
    std::string why;
    if (tok.size() == 10 + e && tok[0] == "xterm")
        why = added_term(L, tok);
    else if (tok.size() != 6 + e || tok[0] != "term")
        return L.info.has_err ? "expected 'term NAME k l m value error', 'xterm ... value error' "
                                "or 'end' (the file's 'errors' line: each term ends in its error)"
                              : "expected 'term NAME k l m value', 'xterm ...' or 'end'";
    else
        why = harmonic_term(L, tok);
    if (why.empty() && e) {
        double v;
        if (!parse_double(tok.back(), &v) || v < 0)
            return "bad error '" + tok.back() + "' (expected a finite number >= 0, radians)";
        L.info.err[L.got - 1] = v;
    }
    return why;
}

// The harmonic terms must be the set pm_model_init makes for the order, in
// its order (pm.h: the first n_base terms are that set): "" or why not,
// with L.lineno set to the line to blame (0: none).
std::string check_term_list(Loader &L)
{
    const pm_model &m = L.m;
    const long order = L.order;
    pm_model ref;
    if (pm_model_init(&ref, L.mount, (int)order) != PM_OK) {
        L.lineno = 0;
        return "cannot build the order-" + std::to_string(order) + " term list";
    }
    for (int i = 0; i < ref.n_terms || i < m.n_base; i++) {
        if (i >= m.n_base || i >= ref.n_terms) {
            L.lineno = i < m.n_base ? L.term_line[i] : (i < m.n_terms ? L.term_line[i] : L.end_line);
            return "the term list does not match 'order " + std::to_string(order) +
                   "': the order-" + std::to_string(order) + " model has " +
                   std::to_string(ref.n_terms) + " harmonic terms, the file " +
                   std::to_string(m.n_base) + " (expected the term lines pmfit writes)";
        }
        const pm_term &a = m.term[i], &b = ref.term[i];
        if (a.k != b.k || a.l != b.l || a.m != b.m) {
            L.lineno = L.term_line[i];
            return "term " + std::to_string(i + 1) + " is k l m = " + std::to_string(a.k) + " " +
                   std::to_string(a.l) + " " + std::to_string(a.m) + ", expected " +
                   name_of(&ref, i) + " = " + std::to_string(b.k) + " " + std::to_string(b.l) +
                   " " + std::to_string(b.m) + ": the term list does not match 'order " +
                   std::to_string(order) + "' (expected the term lines pmfit writes)";
        }
    }
    return "";
}

} // namespace

extern "C" int pmmodel_load(const char *path, pm_model *out, char *err, size_t errlen)
{
    return pmmodel_load_info(path, out, nullptr, err, errlen);
}

static int load_model(const char *path, pm_model *out, pmmodel_info *info, double *cov,
                      size_t cov_len, int *has_cov, char *err, size_t errlen)
{
    if (!path || !out) {
        set_err(err, errlen, "pmmodel_load: invalid arguments");
        return -1;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        set_err(err, errlen, std::string(path) + ": cannot open: " + std::strerror(errno));
        return -1;
    }
    const size_t MAX_LINE = 4096;
    std::string line;
    Loader L;
    auto fail = [&](const std::string &msg) {
        set_err(err, errlen, std::string(path) + ":" + std::to_string(L.lineno) + ": " + msg);
        return -1;
    };
    for (int r; (r = read_line(in, line, MAX_LINE)) != 0;) {
        L.lineno++;
        if (r < 0)
            return fail("line longer than " + std::to_string(MAX_LINE) + " bytes");
        if (line.find('\0') != std::string::npos)
            return fail("binary data (NUL byte); expected a text model file");
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        std::istringstream ls(line);
        std::vector<std::string> tok;
        std::string t;
        while (ls >> t)
            tok.push_back(t);
        if (tok.empty() || tok[0][0] == '#')
            continue;
        std::string why = file_line(L, tok);
        if (!why.empty())
            return fail(why);
    }
    if (in.bad()) {
        set_err(err, errlen, std::string(path) + ": cannot read: " + std::strerror(errno));
        return -1;
    }
    if (L.state != Loader::DONE) {
        L.lineno++;
        return fail(L.state == Loader::HEADER ? "empty file; expected a pm model file"
                                              : "file ends before 'end' (truncated?)");
    }
    L.m.n_base = L.base < 0 ? (int)L.nterms : L.base;
    std::string why = check_term_list(L);
    if (why.empty() && L.has_corr)
        why = check_correlations(L);
    for (long i = 0; why.empty() && L.has_corr && i < L.nterms; i++)
        if (!std::isfinite(L.info.err[i] * L.info.err[i])) {
            L.lineno = L.term_line[(size_t)i];
            why = "the error of term " + std::to_string(i + 1) + " is too large for a covariance "
                  "(its square overflows)";
        }
    if (!why.empty())
        return fail(why);
    const size_t P = (size_t)L.nterms;
    if (L.has_corr && cov && cov_len < P * P) {
        set_err(err, errlen, std::string(path) + ": pmmodel_load_cov: the covariance of " +
                                 std::to_string(P) + " terms needs " + std::to_string(P * P) +
                                 " doubles, cov_len is " + std::to_string(cov_len));
        return -1;
    }
    pm_model &m = L.m;
    pm_status st = pm_model_prepare(&m);
    if (st == PM_ERR_NONFINITE) {
        set_err(err, errlen, std::string(path) + ": the polar-axis coefficients a, b are too "
                             "large to evaluate (beyond ~1e154 rad)");
        return -1;
    }
    if (st != PM_OK) {
        set_err(err, errlen, std::string(path) + ": the terms do not form a valid model "
                             "(the six isotropic terms a b c' d e' i must come first, in order; "
                             "added terms must be valid for the mount and order)");
        return -1;
    }
    /* (a name of an input no term reads is kept: harmless, as in the file) */
    *out = m;
    if (info)
        *info = L.info;
    if (has_cov)
        *has_cov = L.has_corr && cov ? 1 : 0;
    if (L.has_corr && cov) /* (symmetric to the bit: each pair computed once) */
        for (size_t i = 0; i < P; i++)
            for (size_t j = 0; j <= i; j++)
                cov[i * P + j] = cov[j * P + i] = L.corr[i * P + j] * L.info.err[i] * L.info.err[j];
    return 0;
}

extern "C" int pmmodel_load_info(const char *path, pm_model *out, pmmodel_info *info, char *err,
                                 size_t errlen)
{
    return load_model(path, out, info, nullptr, 0, nullptr, err, errlen);
}

extern "C" int pmmodel_load_cov(const char *path, pm_model *out, pmmodel_info *info, double *cov,
                                size_t cov_len, int *has_cov, char *err, size_t errlen)
{
    if (has_cov)
        *has_cov = 0;
    return load_model(path, out, info, cov, cov_len, has_cov, err, errlen);
}

extern "C" int pmmodel_emit_c(const char *path, const pm_model *m, const char *prefix,
                              const char *comment, char *err, size_t errlen)
{
    if (!path || !m || !prefix || m->n_terms < 6 || m->n_terms > PM_MAX_TERMS) {
        set_err(err, errlen, "pmmodel_emit_c: invalid arguments");
        return -1;
    }
    bool ident = (std::isalpha((unsigned char)prefix[0]) || prefix[0] == '_');
    for (const char *q = prefix; *q && ident; q++)
        ident = std::isalnum((unsigned char)*q) || *q == '_';
    if (!ident) {
        set_err(err, errlen, std::string(path) + ": pmmodel_emit_c: the prefix '" + prefix +
                                 "' is not a C identifier (letters, digits, '_', not a digit "
                                 "first)");
        return -1;
    }
    if (!preparable(m, path, "pmmodel_emit_c", err, errlen))
        return -1;
    std::string p = prefix;
    std::string guard;
    for (char c : p)
        guard += (char)std::toupper((unsigned char)c);
    guard += "_MODEL_H";
    std::string o = "/*\n** Pointing model as constant data, written by pmfit --emit-c.\n";
    // the comment (a run's path, a caption) must not end the C comment: "*/"
    // written "* /"
    std::string safe = comment ? comment : "";
    for (size_t at = 0; (at = safe.find("*/", at)) != std::string::npos; at += 3)
        safe.replace(at, 2, "* /");
    comment_lines(o, comment ? safe.c_str() : nullptr, "** ");
    o += "**\n** Use:  pm_model m;  if (" + p + "_load(&m) != PM_OK) ...\n*/\n";
    o += "#ifndef " + guard + "\n#define " + guard + "\n\n#include \"pm.h\"\n\n";
    o += "#if PM_MAX_L < " + std::to_string(m->order) + "\n#error \"this model needs PM_MAX_L >= " +
         std::to_string(m->order) + "\"\n#endif\n";
    const std::string def = std::to_string(PM_MODEL_DEFINITION);
    o += "#if !defined(PM_MODEL_DEFINITION) || PM_MODEL_DEFINITION != " + def +
         "\n#error \"this model was fitted with the model definition " + def +
         " (include/pm.h, docs/model.md); rebuild it with this pm.h's pmfit\"\n#endif\n\n";
    o += "#define " + guard.substr(0, guard.size() - 2) + "_MOUNT " +
         (m->mount == PM_MOUNT_ALTAZ ? "PM_MOUNT_ALTAZ" : "PM_MOUNT_EQUATORIAL") + "\n";
    o += "#define " + guard.substr(0, guard.size() - 2) + "_ORDER " + std::to_string(m->order) + "\n";
    o += "#define " + guard.substr(0, guard.size() - 2) + "_NTERMS " + std::to_string(m->n_terms) +
         "\n";
    o += "#define " + guard.substr(0, guard.size() - 2) + "_NBASE " + std::to_string(m->n_base) +
         "\n\n";
    o += "/* coefficients (radians) */\nstatic const double " + p + "_coef[" +
         std::to_string(m->n_terms) + "] = {\n";
    for (int i = 0; i < m->n_terms; i++) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "    %.17g%s /* %s */\n", m->coef[i],
                      i + 1 < m->n_terms ? "," : "", name_of(m, i).c_str());
        o += buf;
    }
    o += "};\n\n/* harmonic terms: base vector k, degree l, order m */\nstatic const signed char " +
         p + "_terms[" + std::to_string(m->n_base) + "][3] = {\n";
    for (int i = 0; i < m->n_base; i++) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "    {%d, %d, %d}%s\n", m->term[i].k, m->term[i].l,
                      m->term[i].m, i + 1 < m->n_base ? "," : "");
        o += buf;
    }
    int n_added = m->n_terms - m->n_base;
    if (n_added > 0) {
        o += "};\n\n/* added terms: kind, k, l, m, side, aux, param (pm_term) */\n"
             "static const pm_term " + p + "_added[" + std::to_string(n_added) + "] = {\n";
        for (int i = m->n_base; i < m->n_terms; i++) {
            const pm_term &t = m->term[i];
            char buf[160];
            std::snprintf(buf, sizeof buf, "    {%d, %d, %d, %d, %d, %d, %.17g}%s /* %s */\n", t.kind,
                          t.k, t.l, t.m, t.side, t.aux, t.param, i + 1 < m->n_terms ? "," : "",
                          name_of(m, i).c_str());
            o += buf;
        }
    }
    std::string G = guard.substr(0, guard.size() - 2);
    o += "};\n\n"
         "/* Fill *m with this model (term list checked against the library's). */\n"
         "static pm_status " + p + "_load(pm_model *m)\n{\n"
         "    int i;\n"
         "    pm_status s = pm_model_init(m, " + G + "_MOUNT, " + G + "_ORDER);\n"
         "    if (s != PM_OK)\n        return s;\n"
         "    if (m->n_terms != " + G + "_NBASE)\n        return PM_ERR_CONFIG;\n"
         "    m->latitude = " + fmt17(m->latitude) + ";\n"
         "    for (i = 0; i < " + G + "_NBASE; i++) {\n"
         "        if (m->term[i].k != " + p + "_terms[i][0] || m->term[i].l != " + p + "_terms[i][1] ||\n"
         "            m->term[i].m != " + p + "_terms[i][2])\n"
         "            return PM_ERR_CONFIG;\n"
         "        m->coef[i] = " + p + "_coef[i];\n"
         "    }\n" +
         (n_added > 0 ? "    for (i = " + G + "_NBASE; i < " + G + "_NTERMS; i++) {\n"
                        "        s = pm_model_add_term(m, &" + p + "_added[i - " + G + "_NBASE], " + p +
                        "_coef[i], 0);\n"
                        "        if (s != PM_OK)\n            return s;\n"
                        "    }\n"
                      : std::string()) +
         "    return pm_model_prepare(m);\n}\n\n#endif\n";
    return write_atomic(path, o, err, errlen);
}
