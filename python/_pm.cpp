// _pm.cpp - the compiled half of the Python package `pm` (python/pm/):
// pybind11 bindings of the core (include/pm.h) and the host library
// (tools/lib: run files, model files, fits with physical terms, explain).
//
// The Python layer (python/pm/__init__.py) checks and broadcasts the arrays
// and documents the API; this file does the loops over the C calls with the
// GIL released, and turns every failure into a C++ exception (Failure) that
// the translator below raises as the pm.* exception named by its kind, with
// the library's message.  docs/python.md describes the package.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "pm.h"
#include "apply_lanes.h"
#include "compare.hpp"
#include "errormap.hpp"
#include "explain.hpp"
#include "fitrun.hpp"
#include "hostutil.hpp"
#include "inject.hpp"
#include "modelfile.h"
#include "plan.hpp"
#include "runfile.h"
#include "simulate.h"

#include <algorithm>
#include <cstdlib>
#include <unistd.h>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace py = pybind11;
using namespace pmhost;

namespace {

// ---------------------------------------------------------------------------
// Errors.

// Which pm.* exception a failure becomes (python/pm/_errors.py).
enum Kind { K_ERROR, K_FILE, K_FORMAT, K_ARGUMENT, K_NONFINITE, K_FIT };
const char *const KIND_NAMES[] = {"Error", "FileError", "FormatError", "ArgumentError",
                                  "NonFiniteError", "FitError"};

struct Failure {
    Kind kind;
    int status;          // pm_status, pmrun status, or 0
    std::string message;
    std::string bad_term; // FitError after PM_ERR_SINGULAR: the term's name
};

// The exception classes, handed over by python/pm/__init__.py (_set_errors).
py::object *g_errors[6];

const char *status_name(int s)
{
    switch (s) {
    case PM_OK: return "PM_OK";
    case PM_WARN_NOT_CONVERGED: return "PM_WARN_NOT_CONVERGED";
    case PM_WARN_UNREACHABLE: return "PM_WARN_UNREACHABLE";
    case PM_ERR_ARG: return "PM_ERR_ARG";
    case PM_ERR_NONFINITE: return "PM_ERR_NONFINITE";
    case PM_ERR_CAPACITY: return "PM_ERR_CAPACITY";
    case PM_ERR_TOO_FEW: return "PM_ERR_TOO_FEW";
    case PM_ERR_SINGULAR: return "PM_ERR_SINGULAR";
    case PM_ERR_STATE: return "PM_ERR_STATE";
    case PM_ERR_CONFIG: return "PM_ERR_CONFIG";
    case PM_ERR_DIVERGED: return "PM_ERR_DIVERGED";
    }
    return "unknown status";
}

// The words of pm.h's status enum (pm_status_text, as pmfit prints them).
const char *status_text(int s) { return pm_status_text((pm_status)s); }

// A failure of a core call: "what: PM_ERR_X (words)".
[[noreturn]] void fail_status(pm_status s, const std::string &what)
{
    Kind k = s == PM_ERR_NONFINITE ? K_NONFINITE : (s == PM_ERR_ARG ? K_ARGUMENT : K_ERROR);
    throw Failure{k, (int)s, what + ": " + status_name(s) + " (" + status_text(s) + ")", ""};
}

[[noreturn]] void fail(Kind k, const std::string &msg) { throw Failure{k, 0, msg, ""}; }

void translate(std::exception_ptr p)
{
    try {
        if (p)
            std::rethrow_exception(p);
    } catch (const Failure &f) {
        py::object cls = g_errors[f.kind] ? *g_errors[f.kind] : py::reinterpret_borrow<py::object>(PyExc_RuntimeError);
        py::object e = cls(f.message);
        if (g_errors[f.kind]) {
            e.attr("status") = f.status ? py::cast(f.status) : py::none();
            if (f.kind == K_FIT)
                e.attr("bad_term") = f.bad_term.empty() ? py::none() : py::cast(f.bad_term);
        }
        PyErr_SetObject(cls.ptr(), e.ptr());
    }
}

// ---------------------------------------------------------------------------
// Arrays.

using darr = py::array_t<double, py::array::c_style | py::array::forcecast>;
using iarr = py::array_t<int, py::array::c_style | py::array::forcecast>;

// The Python layer passes 1-D contiguous arrays of one length n; this checks
// it again (a caller of _pm itself gets an error, not a read past the end).
long length_of(const py::array &a, const char *name, long n = -1)
{
    if (a.ndim() != 1)
        fail(K_ARGUMENT, std::string(name) + ": expected a 1-D array");
    long len = (long)a.shape(0);
    if (n >= 0 && len != n)
        fail(K_ARGUMENT, std::string(name) + ": length " + std::to_string(len) + ", expected " +
                             std::to_string(n));
    return len;
}

// Per-observation inputs of the physical terms: optional columns.
struct Inputs {
    std::optional<iarr> pier, dir;
    std::optional<darr> temp_c, time_h;
    std::optional<darr> aux; // (n, k) with k <= PM_MAX_AUX
    const int *p_pier = nullptr, *p_dir = nullptr;
    const double *p_temp = nullptr, *p_time = nullptr, *p_aux = nullptr;
    long n_aux = 0;

    bool any() const { return p_pier || p_dir || p_temp || p_time || p_aux; }

    void check(long n)
    {
        if (pier)
            length_of(*pier, "pier", n), p_pier = pier->data();
        if (dir)
            length_of(*dir, "dir", n), p_dir = dir->data();
        if (temp_c)
            length_of(*temp_c, "temp_c", n), p_temp = temp_c->data();
        if (time_h)
            length_of(*time_h, "time_h", n), p_time = time_h->data();
        if (aux) {
            if (aux->ndim() != 2 || aux->shape(0) != n || aux->shape(1) > PM_MAX_AUX)
                fail(K_ARGUMENT, "aux: expected an array of shape (n, k), k <= " +
                                     std::to_string(PM_MAX_AUX));
            n_aux = (long)aux->shape(1);
            p_aux = aux->data();
        }
    }

    // The context of observation i (absent inputs are 0: they are read only
    // by terms that need them, which the Python layer checks).
    void fill(long i, pm_context &c) const
    {
        std::memset(&c, 0, sizeof c);
        if (p_pier)
            c.pier = p_pier[i];
        if (p_dir)
            c.dir = p_dir[i];
        if (p_temp)
            c.temp_c = p_temp[i];
        if (p_time)
            c.time_h = p_time[i];
        for (long j = 0; j < n_aux; j++)
            c.aux[j] = p_aux[i * n_aux + j];
    }
};

Inputs make_inputs(std::optional<iarr> pier, std::optional<darr> temp_c,
                   std::optional<darr> time_h, std::optional<iarr> dir, std::optional<darr> aux,
                   long n)
{
    Inputs in;
    in.pier = std::move(pier);
    in.temp_c = std::move(temp_c);
    in.time_h = std::move(time_h);
    in.dir = std::move(dir);
    in.aux = std::move(aux);
    in.check(n);
    return in;
}

template <class T> py::array_t<T> copy_out(const std::vector<T> &v)
{
    py::array_t<T> a((py::ssize_t)v.size());
    if (!v.empty())
        std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
    return a;
}

// Points per thread below which more threads do not pay for their start.
const long MIN_POINTS_PER_THREAD = 1L << 15;

// range(lo, hi) for contiguous chunks covering [0, n), without the GIL, on
// up to `threads` threads (0: as many as the machine has); range returns
// the first failing index of its chunk and its status, or (-1, PM_OK), and
// stops there.  Returns the first failing index of all (the lowest) and its
// status, or (-1, PM_OK).  The points are independent, so the results do not
// depend on the number of threads.
template <class F> std::pair<long, pm_status> for_ranges(long n, int threads, const F &range)
{
    py::gil_scoped_release nogil;
    long t = threads > 0 ? threads : (long)std::thread::hardware_concurrency();
    t = std::max(1L, std::min({t, n / MIN_POINTS_PER_THREAD, 64L}));
    std::vector<long> bad((size_t)t, -1);
    std::vector<pm_status> st((size_t)t, PM_OK);
    auto chunk = [&](long k) {
        std::pair<long, pm_status> r = range(n * k / t, n * (k + 1) / t);
        bad[(size_t)k] = r.first, st[(size_t)k] = r.second;
    };
    std::vector<std::thread> pool;
    std::vector<long> here; // chunks no thread could be started for
    for (long k = 1; k < t; k++) {
        try {
            pool.emplace_back(chunk, k);
        } catch (const std::system_error &) {
            here.push_back(k);
        }
    }
    chunk(0);
    for (long k : here)
        chunk(k);
    for (std::thread &th : pool)
        th.join();
    for (long k = 0; k < t; k++)
        if (bad[(size_t)k] >= 0)
            return {bad[(size_t)k], st[(size_t)k]};
    return {-1, PM_OK};
}

// body(i) for every point i in [0, n), as for_ranges; each chunk stops at
// its first error (a negative status).
template <class F> std::pair<long, pm_status> for_points(long n, int threads, const F &body)
{
    return for_ranges(n, threads, [&](long lo, long hi) -> std::pair<long, pm_status> {
        for (long i = lo; i < hi; i++) {
            pm_status s = body(i);
            if (s < 0)
                return {i, s};
        }
        return {-1, PM_OK};
    });
}

// pm_model_apply without context on the points, several at a time on the
// given path (apply_lanes.h; the same doubles as the scalar call), on up to
// `threads` threads: as for_ranges.
std::pair<long, pm_status> apply_lanes_on(const pm_model &m, int path, long n, int threads,
                                          const double *h, const double *d, double *a,
                                          double *b)
{
    return for_ranges(n, threads, [&](long lo, long hi) -> std::pair<long, pm_status> {
        pm_status s = PM_OK;
        long i = pm_apply_lanes(path, &m, hi - lo, h + lo, d + lo, a + lo, b + lo, &s);
        return {i < 0 ? -1 : lo + i, s};
    });
}

// ---------------------------------------------------------------------------
// Model.

struct Model {
    pm_model m;
    pmmodel_info info; // a model file's column names and pier side (modelfile.h)
    std::vector<double> cov; // the fit's covariance (P x P) where info.has_err; else empty

    Model()
    {
        std::memset(&m, 0, sizeof m);
        std::memset(&info, 0, sizeof info);
    }

    // {j: name}: the run column each aux[j] the model reads is
    py::dict inputs() const
    {
        py::dict d;
        for (int j = 0; j < PM_MAX_AUX; j++)
            if (info.input[j][0])
                d[py::int_(j)] = std::string(info.input[j]);
        return d;
    }

    static Model make(int mount, int order, double latitude)
    {
        Model r;
        pm_status s = pm_model_init(&r.m, mount, order);
        if (s == PM_ERR_CAPACITY)
            fail(K_ARGUMENT, "order " + std::to_string(order) + " is beyond this build's PM_MAX_L = " +
                                 std::to_string(PM_MAX_L));
        if (s != PM_OK)
            fail_status(s, "pm_model_init");
        r.m.latitude = latitude;
        s = pm_model_prepare(&r.m);
        if (s != PM_OK)
            fail_status(s, "pm_model_prepare");
        return r;
    }

    std::string name(int i) const
    {
        char buf[64];
        pm_term_name(&m, i, buf, sizeof buf);
        return buf;
    }

    std::vector<std::string> names() const
    {
        std::vector<std::string> v;
        for (int i = 0; i < m.n_terms; i++)
            v.push_back(name(i));
        return v;
    }

    py::array_t<double> coefficients() const
    {
        return copy_out(std::vector<double>(m.coef, m.coef + m.n_terms));
    }

    // New coefficients (radians), prepared; on error the model is unchanged.
    void set_coefficients(darr c)
    {
        length_of(c, "coefficients", m.n_terms);
        pm_model t = m;
        std::memcpy(t.coef, c.data(), sizeof(double) * (size_t)m.n_terms);
        pm_status s = pm_model_prepare(&t);
        if (s != PM_OK)
            fail_status(s, "coefficients");
        m = t;
        info.has_err = 0; /* a fit's errors are not these coefficients' */
        cov.clear();
    }

    void set_latitude(double lat)
    {
        pm_model t = m;
        t.latitude = lat;
        pm_status s = pm_model_prepare(&t);
        if (s != PM_OK)
            fail_status(s, "latitude");
        m = t;
    }

    // Which context inputs the terms read: (temp_c, time_h, dir, [aux j]).
    py::tuple inputs_needed() const
    {
        bool temp = false, time = false, dir = false;
        std::vector<int> aux;
        for (int i = 0; i < m.n_terms; i++) {
            const pm_term &t = m.term[i];
            if (t.kind != PM_TERM_AUX)
                continue;
            if (t.aux == PM_AUX_TEMP)
                temp = true;
            else if (t.aux == PM_AUX_TIME)
                time = true;
            else if (t.aux == PM_AUX_DIR)
                dir = true;
            else if (std::find(aux.begin(), aux.end(), t.aux - PM_AUX_USER) == aux.end())
                aux.push_back(t.aux - PM_AUX_USER);
        }
        return py::make_tuple(temp, time, dir, aux);
    }

    py::list terms() const
    {
        py::list l;
        for (int i = 0; i < m.n_terms; i++) {
            const pm_term &t = m.term[i];
            py::dict d;
            d["name"] = name(i);
            d["kind"] = (int)t.kind;
            d["k"] = (int)t.k;
            d["l"] = (int)t.l;
            d["m"] = (int)t.m;
            d["side"] = (int)t.side;
            d["aux"] = (int)t.aux;
            d["param"] = t.param;
            d["meaning"] = meaning(m, i);
            l.append(d);
        }
        return l;
    }

    int add_term(int kind, int k, int l, int mm, int side, int aux, double param, double value)
    {
        if (kind < 0 || kind > 255 || k < 0 || k > 255 || l < -128 || l > 127 || mm < -128 ||
            mm > 127 || side < -1 || side > 1 || aux < 0 || aux > 255)
            fail(K_ARGUMENT, "add_term: a field is out of its range (docs/model.md, pm_term)");
        pm_term t;
        std::memset(&t, 0, sizeof t);
        t.kind = (unsigned char)kind;
        t.k = (unsigned char)k;
        t.l = (signed char)l;
        t.m = (signed char)mm;
        t.side = (signed char)side;
        t.aux = (unsigned char)aux;
        t.param = param;
        pm_model c = m;
        int index = -1;
        pm_status s = pm_model_add_term(&c, &t, value, &index);
        if (s != PM_OK)
            fail_status(s, "add_term");
        m = c;
        info.has_err = 0; /* a fit's errors are not this model's */
        cov.clear();
        return index;
    }

    // Forward model over arrays; the first failing point raises.
    py::tuple apply(darr ha, darr dec, std::optional<iarr> pier, std::optional<darr> temp_c,
                    std::optional<darr> time_h, std::optional<iarr> dir,
                    std::optional<darr> aux, int threads) const
    {
        long n = length_of(ha, "enc_ha");
        length_of(dec, "enc_dec", n);
        Inputs in = make_inputs(pier, temp_c, time_h, dir, aux, n);
        py::array_t<double> oa(n), od(n);
        const double *h = ha.data(), *d = dec.data();
        double *a = oa.mutable_data(), *b = od.mutable_data();
        const bool use_ctx = in.any();
        std::pair<long, pm_status> bad;
        if (!use_ctx && pm_apply_lanes_ok(&m)) // several points at a time
            bad = apply_lanes_on(m, pm_lanes_best(), n, threads, h, d, a, b);
        else
            bad = for_points(n, threads, [&](long i) {
                pm_context c;
                if (use_ctx)
                    in.fill(i, c);
                return pm_model_apply(&m, use_ctx ? &c : nullptr, h[i], d[i], &a[i], &b[i]);
            });
        if (bad.first >= 0)
            fail_status(bad.second, "apply, point " + std::to_string(bad.first));
        return py::make_tuple(oa, od);
    }

    // apply without context on one path of apply_lanes.h by name ("scalar",
    // "sse2", "avx2x2", ...: _pm._lanes_paths), one thread, for the tests
    // (each path must give the scalar call's doubles) and the bench; raises
    // as apply, or ArgumentError if the path is not this machine's or the
    // model not the lanes'.
    py::tuple apply_lanes(darr ha, darr dec, const std::string &name) const
    {
        long n = length_of(ha, "enc_ha");
        length_of(dec, "enc_dec", n);
        int path = 0;
        while (path < PM_LANES_N_PATHS && name != pm_lanes_name(path))
            path++;
        if (path == PM_LANES_N_PATHS || !pm_lanes_runs(path))
            fail(K_ARGUMENT, "lanes: no path '" + name + "' on this machine");
        if (path != PM_LANES_SCALAR && !pm_apply_lanes_ok(&m))
            fail(K_ARGUMENT, "lanes: the model has terms the lanes do not take");
        py::array_t<double> oa(n), od(n);
        const double *h = ha.data(), *d = dec.data();
        double *a = oa.mutable_data(), *b = od.mutable_data();
        auto bad = apply_lanes_on(m, path, n, 1, h, d, a, b);
        if (bad.first >= 0)
            fail_status(bad.second, "apply, point " + std::to_string(bad.first));
        return py::make_tuple(oa, od);
    }

    // The per-point C call itself (no arrays): what a Python loop would call.
    py::tuple apply_point(double ha, double dec) const
    {
        double a, b;
        pm_status s = pm_model_apply(&m, nullptr, ha, dec, &a, &b);
        if (s != PM_OK)
            fail_status(s, "apply");
        return py::make_tuple(a, b);
    }

    py::tuple invert_point(double ha, double dec, int side) const
    {
        double a, b;
        pm_status s = pm_model_invert(&m, nullptr, ha, dec, side, &a, &b);
        if (s < 0)
            fail_status(s, "invert");
        return py::make_tuple(a, b, (int)s);
    }

    // Inverse over arrays: side per point (0/1), or start positions
    // (pm_model_invert_near).  Warnings come back in the status array.
    py::tuple invert(darr ha, darr dec, std::optional<iarr> side, std::optional<darr> start_ha,
                     std::optional<darr> start_dec, std::optional<iarr> pier,
                     std::optional<darr> temp_c, std::optional<darr> time_h,
                     std::optional<iarr> dir, std::optional<darr> aux, int threads) const
    {
        long n = length_of(ha, "app_ha");
        length_of(dec, "app_dec", n);
        if (side)
            length_of(*side, "side", n);
        if (start_ha.has_value() != start_dec.has_value())
            fail(K_ARGUMENT, "invert: give both start_ha and start_dec, or neither");
        if (start_ha) {
            length_of(*start_ha, "start_ha", n);
            length_of(*start_dec, "start_dec", n);
        }
        Inputs in = make_inputs(pier, temp_c, time_h, dir, aux, n);
        py::array_t<double> oa(n), od(n);
        py::array_t<signed char> os(n);
        const double *h = ha.data(), *d = dec.data();
        const int *sd = side ? side->data() : nullptr;
        const double *s0 = start_ha ? start_ha->data() : nullptr;
        const double *s1 = start_dec ? start_dec->data() : nullptr;
        double *a = oa.mutable_data(), *b = od.mutable_data();
        signed char *st = os.mutable_data();
        const bool use_ctx = in.any();
        auto bad = for_points(n, threads, [&](long i) {
            pm_context c;
            if (use_ctx)
                in.fill(i, c);
            const pm_context *cp = use_ctx ? &c : nullptr;
            pm_status s = s0 ? pm_model_invert_near(&m, cp, h[i], d[i], s0[i], s1[i], &a[i], &b[i])
                             : pm_model_invert(&m, cp, h[i], d[i], sd ? sd[i] : 0, &a[i], &b[i]);
            st[i] = (signed char)s;
            return s;
        });
        if (bad.first >= 0)
            fail_status(bad.second, "invert, point " + std::to_string(bad.first));
        return py::make_tuple(oa, od, os);
    }

    py::array_t<double> residual(darr eh, darr ed, darr ah, darr ad, std::optional<iarr> pier,
                                 std::optional<darr> temp_c, std::optional<darr> time_h,
                                 std::optional<iarr> dir, std::optional<darr> aux,
                                 int threads) const
    {
        long n = length_of(eh, "enc_ha");
        length_of(ed, "enc_dec", n);
        length_of(ah, "app_ha", n);
        length_of(ad, "app_dec", n);
        Inputs in = make_inputs(pier, temp_c, time_h, dir, aux, n);
        py::array_t<double> out({(py::ssize_t)n, (py::ssize_t)2});
        double *o = out.mutable_data();
        const double *p0 = eh.data(), *p1 = ed.data(), *p2 = ah.data(), *p3 = ad.data();
        const bool use_ctx = in.any();
        auto bad = for_points(n, threads, [&](long i) {
            pm_context c;
            if (use_ctx)
                in.fill(i, c);
            return pm_model_residual(&m, use_ctx ? &c : nullptr, p0[i], p1[i], p2[i], p3[i],
                                     o + 2 * i);
        });
        if (bad.first >= 0)
            fail_status(bad.second, "residual, point " + std::to_string(bad.first));
        return out;
    }

    // A string the C call would cut at its first NUL: refused, named.
    static void no_nul(const char *what, const std::optional<std::string> &s)
    {
        if (s && s->find('\0') != std::string::npos)
            fail(K_ARGUMENT, std::string(what) + ": holds a NUL character at " +
                                 std::to_string(s->find('\0')) + " (the file would end it there)");
    }

    void save(const std::string &path, std::optional<std::string> comment) const
    {
        no_nul("comment", comment);
        char err[1024];
        const bool c = info.has_err && cov.size() == (size_t)m.n_terms * (size_t)m.n_terms;
        if (pmmodel_save_cov(path.c_str(), &m, &info, c ? cov.data() : nullptr,
                             comment ? comment->c_str() : nullptr, err, sizeof err) != 0)
            fail(K_FILE, err);
    }

    void emit_c(const std::string &path, const std::string &prefix,
                std::optional<std::string> comment) const
    {
        no_nul("comment", comment);
        no_nul("prefix", prefix);
        char err[1024];
        if (pmmodel_emit_c(path.c_str(), &m, prefix.c_str(), comment ? comment->c_str() : nullptr,
                           err, sizeof err) != 0)
            fail(K_FILE, err);
    }

    static Model load(const std::string &path)
    {
        Model r;
        char err[1024];
        int has_cov = 0;
        r.cov.assign((size_t)PM_MAX_TERMS * PM_MAX_TERMS, 0.0);
        if (pmmodel_load_cov(path.c_str(), &r.m, &r.info, r.cov.data(), r.cov.size(), &has_cov, err,
                             sizeof err) != 0) {
            // a file that cannot be opened is an OSError, its content a ValueError
            FILE *f = std::fopen(path.c_str(), "rb");
            if (!f)
                fail(K_FILE, err);
            std::fclose(f);
            fail(K_FORMAT, err);
        }
        r.cov.resize(has_cov ? (size_t)r.m.n_terms * (size_t)r.m.n_terms : 0);
        return r;
    }
};

// ---------------------------------------------------------------------------
// Runs.

struct RunData {
    Run run;          // as pmfit fits it: contexts, derived slew directions
    int format = -1;  // PMRUN_FORMAT_*, -1 for a run made from arrays
    pmrun_site site;
    std::vector<std::string> skipped;
    std::vector<std::string> file_aux_names; // the file's own auxiliary columns
    std::vector<double> file_aux;            // n x file_aux_names.size()
    std::vector<double> enc_raw;             // n x 2
};

std::shared_ptr<RunData> read_run(const std::string &path, bool refraction, bool skip_bad,
                                  const std::string &format, const std::string &equinox,
                                  bool azimuth_count, const std::vector<double> &weather)
{
    pmrun_options ro;
    pmrun_options_default(&ro);
    if (weather.size() != 4)
        throw Failure{K_ARGUMENT, PMRUN_ERR_ARG, "weather: expected 4 values", ""};
    ro.pressure_hpa = weather[0]; /* (NaN: the file's) */
    ro.temp_c = weather[1];
    ro.humidity = weather[2];
    ro.wavelength_um = weather[3];
    ro.refraction = refraction ? 1 : 0;
    ro.skip_bad = skip_bad ? 1 : 0;
    ro.format = pmrun_format_from_name(format.c_str());
    if (ro.format == -2)
        throw Failure{K_ARGUMENT, PMRUN_ERR_ARG,
                      "format: expected auto, four-column, named, tpoint, rts2, mw4, csv or mmt, "
                      "got '" + format + "'", ""};
    if (equinox == "J2000" || equinox == "j2000")
        ro.equinox = PMRUN_EQUINOX_J2000;
    else if (equinox == "JNow" || equinox == "jnow" || equinox == "JNOW")
        ro.equinox = PMRUN_EQUINOX_JNOW;
    else if (!equinox.empty())
        throw Failure{K_ARGUMENT, PMRUN_ERR_ARG,
                      "equinox: expected 'J2000' or 'JNow', got '" + equinox + "'", ""};
    pmrun *raw = nullptr;
    char err[1024];
    int st;
    {
        py::gil_scoped_release nogil;
        st = pmrun_read(path.c_str(), &ro, &raw, err, sizeof err);
    }
    if (st != PMRUN_OK) {
        Kind k = st == PMRUN_ERR_IO ? K_FILE : (st == PMRUN_ERR_FORMAT ? K_FORMAT : K_ERROR);
        throw Failure{k, st, err, ""};
    }
    std::unique_ptr<pmrun, void (*)(pmrun *)> guard(raw, pmrun_free);
    auto r = std::make_shared<RunData>();
    r->run = run_from_pmrun(raw, path, azimuth_count);
    equinox_hint(r->run, raw, path, ro);
    r->format = pmrun_format(raw);
    pmrun_get_site(raw, &r->site);
    for (int i = 0; i < pmrun_n_skipped(raw); i++) {
        const char *s = pmrun_skipped(raw, i);
        if (s)
            r->skipped.push_back(s);
    }
    int na = pmrun_n_aux(raw);
    for (int j = 0; j < na; j++)
        r->file_aux_names.push_back(pmrun_aux_name(raw, j));
    for (size_t i = 0; i < pmrun_count(raw); i++) {
        const pmrun_obs *p = pmrun_get(raw, i);
        for (int j = 0; j < na; j++)
            r->file_aux.push_back(p->aux[j]);
        r->enc_raw.push_back(p->enc_raw[0]);
        r->enc_raw.push_back(p->enc_raw[1]);
    }
    return r;
}

// A run from arrays (the Python layer checked finiteness and lengths).
std::shared_ptr<RunData> run_from_arrays(darr eh, darr ed, darr ah, darr ad, int mount,
                                         double latitude, std::optional<iarr> pier,
                                         std::optional<darr> temp_c, std::optional<darr> time_h,
                                         std::optional<iarr> dir, std::optional<darr> aux,
                                         std::vector<std::string> aux_names)
{
    long n = length_of(eh, "enc_ha");
    length_of(ed, "enc_dec", n);
    length_of(ah, "app_ha", n);
    length_of(ad, "app_dec", n);
    if (mount != PM_MOUNT_EQUATORIAL && mount != PM_MOUNT_ALTAZ)
        fail(K_ARGUMENT, "mount: expected equatorial or altaz");
    Inputs in = make_inputs(pier, temp_c, time_h, dir, aux, n);
    if ((long)aux_names.size() != in.n_aux)
        fail(K_ARGUMENT, "aux: as many names as columns");
    auto r = std::make_shared<RunData>();
    std::memset(&r->site, 0, sizeof r->site);
    r->run.path = "<arrays>";
    r->run.mount = mount;
    r->run.latitude = latitude;
    r->run.aux_names = aux_names;
    r->file_aux_names = aux_names;
    for (long i = 0; i < n; i++) {
        Obs ob{eh.data()[i], ed.data()[i], ah.data()[i], ad.data()[i], 0, (int)(i + 1), pm_context()};
        in.fill(i, ob.ctx);
        if (!in.p_temp)
            ob.ctx.temp_c = NAN;
        if (!in.p_time)
            ob.ctx.time_h = NAN;
        if (!in.p_pier) // as the readers do for a file without a pier column
            ob.ctx.pier = mount == PM_MOUNT_EQUATORIAL ? (std::cos(ob.ed) < 0 ? -1 : 1) : 0;
        ob.pier = ob.ctx.pier;
        r->run.obs.push_back(ob);
        for (long j = 0; j < in.n_aux; j++)
            r->file_aux.push_back(ob.ctx.aux[j]);
        r->enc_raw.push_back(ob.eh);
        r->enc_raw.push_back(ob.ed);
    }
    derive_directions(r->run);
    return r;
}

py::dict run_columns(const RunData &d)
{
    const std::vector<Obs> &o = d.run.obs;
    size_t n = o.size();
    std::vector<double> eh(n), ed(n), ah(n), ad(n), tc(n), th(n);
    std::vector<int> pier(n), dir(n), line(n);
    for (size_t i = 0; i < n; i++) {
        eh[i] = o[i].eh, ed[i] = o[i].ed, ah[i] = o[i].ah, ad[i] = o[i].ad;
        tc[i] = o[i].ctx.temp_c, th[i] = o[i].ctx.time_h;
        pier[i] = o[i].pier, dir[i] = o[i].ctx.dir, line[i] = o[i].line;
    }
    py::dict c;
    c["enc_ha"] = copy_out(eh);
    c["enc_dec"] = copy_out(ed);
    c["app_ha"] = copy_out(ah);
    c["app_dec"] = copy_out(ad);
    c["pier"] = copy_out(pier);
    c["dir"] = copy_out(dir);
    c["line"] = copy_out(line);
    c["temp_c"] = copy_out(tc);
    c["time_h"] = copy_out(th);
    py::dict aux;
    size_t nf = d.file_aux_names.size();
    for (size_t j = 0; j < nf; j++) {
        std::vector<double> col(n);
        for (size_t i = 0; i < n; i++)
            col[i] = d.file_aux[i * nf + j];
        aux[py::str(d.file_aux_names[j])] = copy_out(col);
    }
    // inputs derived from the sequence (dec_dir), as pmfit uses them
    for (size_t j = 0; j < d.run.aux_names.size() && j < (size_t)PM_MAX_AUX; j++) {
        const std::string &nm = d.run.aux_names[j];
        if (aux.contains(py::str(nm)))
            continue;
        std::vector<double> col(n);
        for (size_t i = 0; i < n; i++)
            col[i] = o[i].ctx.aux[j];
        aux[py::str(nm)] = copy_out(col);
    }
    c["aux"] = aux;
    py::array_t<double> raw({(py::ssize_t)n, (py::ssize_t)2});
    if (n)
        std::memcpy(raw.mutable_data(), d.enc_raw.data(), sizeof(double) * 2 * n);
    c["enc_raw"] = raw;
    return c;
}

py::dict run_info(const RunData &d)
{
    py::dict i;
    i["path"] = d.run.path;
    i["mount"] = d.run.mount == PM_MOUNT_ALTAZ ? "altaz" : "equatorial";
    i["latitude"] = d.run.latitude;
    // pmfit --format's name of every format (it named three, None for the
    // CSV, MW4, RTS2 and MMT files: an outside probe)
    const char *fname = d.format == PMRUN_FORMAT_AUTO ? nullptr : pmrun_format_name(d.format);
    i["format"] = fname ? py::object(py::str(fname)) : py::object(py::none());
    i["warnings"] = d.run.notes;
    i["skipped"] = d.skipped;
    i["aux_names"] = d.run.aux_names;
    i["dir_derived"] = d.run.dir_derived;
    py::dict s;
    if (d.format >= 0) {
        s["latitude_rad"] = d.site.latitude_rad;
        s["height_m"] = d.site.height_m;
        s["pressure_hpa"] = d.site.pressure_hpa;
        s["temp_c"] = d.site.temp_c;
        s["humidity"] = d.site.humidity;
        s["wavelength_um"] = d.site.wavelength_um;
        s["lapse_k_per_m"] = d.site.lapse_k_per_m;
        s["date"] = d.site.year ? py::object(py::make_tuple(d.site.year, d.site.month, d.site.day))
                                : py::object(py::none());
    }
    i["site"] = s;
    return i;
}

// ---------------------------------------------------------------------------
// Fits.

struct Fit {
    std::unique_ptr<pm_fit> work; // the last solve (covariance, pointing sigma)
    FitOut out;
    std::string title;
    std::vector<int> lines;       // file line of each fitted observation
    pmmodel_info info{};          // the run's columns the model reads, its side
    std::string error_map;        // pmfit fit --json's "error_map" object
    std::string undetermined;     // its warning where the stars do not determine the model

    Model model() const
    {
        Model r;
        r.m = out.model;
        r.info = info;
        if (info.has_err && out.cov.size() == (size_t)out.model.n_terms * (size_t)out.model.n_terms)
            r.cov = out.cov; /* (saved with the model: a later compare's joint test) */
        return r;
    }
    py::array_t<double> coefficients() const
    {
        return copy_out(std::vector<double>(out.model.coef, out.model.coef + out.model.n_terms));
    }
    py::array_t<double> errors() const
    {
        return copy_out(std::vector<double>(out.res.err, out.res.err + out.model.n_terms));
    }
    py::array_t<double> covariance() const
    {
        py::ssize_t p = out.model.n_terms;
        py::array_t<double> c({p, p});
        if (p)
            std::memcpy(c.mutable_data(), out.cov.data(), sizeof(double) * (size_t)(p * p));
        return c;
    }
    py::array_t<double> residuals() const
    {
        size_t n = out.r0.size();
        py::array_t<double> r({(py::ssize_t)n, (py::ssize_t)2});
        double *p = r.mutable_data();
        for (size_t i = 0; i < n; i++)
            p[2 * i] = out.r0[i], p[2 * i + 1] = out.r1[i];
        return r;
    }

    // Predicted 1-sigma pointing error per axis, and (v11, v12, v22), over arrays.
    py::tuple pointing_sigma(darr ha, darr dec, std::optional<iarr> pier, std::optional<darr> temp_c,
                             std::optional<darr> time_h, std::optional<iarr> dir,
                             std::optional<darr> aux, int threads) const
    {
        long n = length_of(ha, "enc_ha");
        length_of(dec, "enc_dec", n);
        Inputs in = make_inputs(pier, temp_c, time_h, dir, aux, n);
        py::array_t<double> sig(n);
        py::array_t<double> cov({(py::ssize_t)n, (py::ssize_t)3});
        const double *h = ha.data(), *d = dec.data();
        double *s = sig.mutable_data(), *c3 = cov.mutable_data();
        const bool use_ctx = in.any();
        auto bad = for_points(n, threads, [&](long i) {
            pm_context c;
            if (use_ctx)
                in.fill(i, c);
            return pm_fit_pointing_sigma(work.get(), &out.res, &out.model, use_ctx ? &c : nullptr,
                                         h[i], d[i], &s[i], c3 + 3 * i);
        });
        if (bad.first >= 0)
            fail_status(bad.second, "pointing_sigma, point " + std::to_string(bad.first));
        return py::make_tuple(sig, cov);
    }

    py::object max_correlation() const
    {
        if (out.corr_i < 0)
            return py::none();
        return py::make_tuple(term_name(out.model, out.corr_j), term_name(out.model, out.corr_i),
                              out.corr);
    }
};

// Why a fit failed, in the words pmfit fit uses.
[[noreturn]] void fail_fit(const FitOut &f, const std::string &what, int max_iter)
{
    const std::string bad = f.status == PM_ERR_SINGULAR && f.bad_term >= 0
                                ? term_name(f.model, f.bad_term) : std::string();
    const std::string msg = what + ": " + status_name(f.status) + " (" + status_text(f.status) +
                            ")" + fit_failure_detail(f, max_iter, "the order");
    throw Failure{f.status == PM_ERR_NONFINITE ? K_NONFINITE : K_FIT, (int)f.status, msg, bad};
}

std::unique_ptr<Fit> fit_points(const Run &run, const std::vector<int> &use, const pm_model &start,
                                int max_iter, const std::string &what, const std::string &title,
                                int pier = 0)
{
    auto f = std::make_unique<Fit>();
    f->work.reset(new pm_fit);
    f->out = do_fit(*f->work, run.obs, use, start, max_iter);
    if (f->out.status != PM_OK)
        fail_fit(f->out, what, max_iter);
    f->title = title;
    f->info = model_info(f->out.model, run.aux_names, pier, f->out.res.err);
    // the predicted error map and the undetermined-fit warning, as pmfit fit
    // (its JSON's "error_map", its warning)
    try {
        ErrorMap em = error_map(run, f->out, pier);
        if (std::isfinite(em.at_points_arcsec)) /* (a saved model keeps it: pm.compare) */
            f->info.stars_sigma = em.at_points_arcsec / RAD2AS;
        f->error_map = error_map_json(em, f->out.res.sigma * RAD2AS);
        f->undetermined = undetermined_warning(em, f->out.res.sigma * RAD2AS);
    } catch (const std::runtime_error &) {
        /* no covariance: no map (pmfit fit has none then either) */
    }
    for (int i : f->out.idx)
        f->lines.push_back(run.obs[i].line);
    return f;
}

py::object f_test_dict(const FTest &t)
{
    if (!t.done)
        return py::none();
    py::dict d;
    d["test"] = t.what;
    d["f"] = t.f;
    d["dof1"] = t.d1;
    d["dof2"] = t.d2;
    d["p"] = t.p;
    return d;
}

// pmfit fit RUN [--order L] [--add ...] [--pier split]: one fit (joint) or
// two (east, west), and the pier F-test where pmfit makes one.
py::tuple fit_run(const RunData &d, int order, std::vector<std::string> adds, bool split,
                  int max_iter)
{
    const Run &run = d.run;
    if (order < 0 || order > PM_MAX_L)
        fail(K_ARGUMENT, "order " + std::to_string(order) + ": expected 0.." + std::to_string(PM_MAX_L) +
                             " (this build's PM_MAX_L)");
    if (max_iter < 1)
        fail(K_ARGUMENT, "max_iter: expected at least 1");
    if (run.obs.empty())
        throw Failure{K_FIT, PM_ERR_TOO_FEW, run.path + ": no observations to fit", ""};
    std::vector<std::unique_ptr<Fit>> fits;
    FTest ftest;
    {
        py::gil_scoped_release nogil;
        pm_model start;
        try {
            start = build_model(order, adds, run.obs, run.mount, run.latitude, run.aux_names);
        } catch (const std::runtime_error &e) {
            fail(K_ARGUMENT, e.what());
        }
        bool side_terms = false;
        for (int i = start.n_base; i < start.n_terms; i++)
            side_terms = side_terms || start.term[i].side != 0;
        if (split && side_terms)
            fail(K_ARGUMENT, "split: the pier sides are fitted independently; side-specific terms "
                             "(@E, @W) belong to a joint fit");
        std::vector<int> all(run.obs.size());
        for (size_t i = 0; i < all.size(); i++)
            all[i] = (int)i;
        if (!split) {
            fits.push_back(
                fit_points(run, all, start, max_iter, run.path, all_points_title(start)));
            if (side_terms) {
                std::unique_ptr<pm_fit> w(new pm_fit);
                FitOut g = do_fit(*w, run.obs, all, without_side_terms(start), 100);
                const FitOut &f = fits[0]->out;
                if (g.status == PM_OK)
                    ftest = f_test(g.res.chi2, g.res.n_par, f.res.chi2, f.res.n_par, f.res.n_obs,
                                   "side-specific terms vs shared only");
            }
        } else {
            std::vector<int> kept; // the observations of either side, in order
            for (int side : {1, -1}) {
                std::vector<int> use;
                for (size_t i = 0; i < run.obs.size(); i++)
                    if (run.obs[i].pier == side)
                        use.push_back((int)i);
                std::string t = side > 0 ? "pier side east (normal)" : "pier side west (beyond the pole)";
                if (use.empty())
                    throw Failure{K_FIT, 0, run.path + ": split: no observations on the " + t, ""};
                fits.push_back(fit_points(run, use, start, max_iter, run.path + " (" + t + ")", t, side));
                kept.insert(kept.end(), use.begin(), use.end());
            }
            std::sort(kept.begin(), kept.end());
            std::unique_ptr<pm_fit> w(new pm_fit);
            FitOut g = do_fit(*w, run.obs, kept, start, 100);
            if (g.status == PM_OK)
                ftest = f_test(g.res.chi2, g.res.n_par, fits[0]->out.res.chi2 + fits[1]->out.res.chi2,
                               fits[0]->out.res.n_par + fits[1]->out.res.n_par, g.res.n_obs,
                               "split (independent sides) vs joint");
        }
    }
    py::list l;
    for (auto &f : fits)
        l.append(py::cast(std::move(f)));
    return py::make_tuple(l, f_test_dict(ftest));
}

// pmfit explain RUN --json, as the same JSON text (json.loads in Python).
std::string explain_run(const RunData &d, int order, std::vector<std::string> adds, double alpha,
                        std::vector<double> gears_ha, std::vector<double> gears_dec, bool pairs,
                        int folds, bool compose)
{
    // order -1: the default (1, or 0 where order0_instead says so)
    const bool chosen = order >= 0;
    if (!chosen)
        order = 1;
    if (order < 0 || order > PM_MAX_L)
        fail(K_ARGUMENT, "order " + std::to_string(order) + ": expected 0.." + std::to_string(PM_MAX_L));
    if (!(alpha > 0 && alpha < 1))
        fail(K_ARGUMENT, "alpha: expected a false-alarm probability in (0, 1)");
    if (folds < 0 || folds == 1 || folds > (int)d.run.obs.size())
        fail(K_ARGUMENT, "folds: expected 0 (leave-one-out) or 2 .. the number of observations");
    for (double g : gears_ha)
        if (!(g > 0 && g <= 1e6))
            fail(K_ARGUMENT, "gears_ha: a gear period must be in (0, 1e6] cycles per revolution");
    for (double g : gears_dec)
        if (!(g > 0 && g <= 1e6))
            fail(K_ARGUMENT, "gears_dec: a gear period must be in (0, 1e6] cycles per revolution");
    ExplainOptions eo;
    eo.order = order;
    eo.adds = adds;
    eo.alpha = alpha;
    eo.gears_ha = gears_ha;
    eo.gears_dec = gears_dec;
    eo.pairs = pairs;
    eo.folds = folds;
    eo.compose = compose;
    // explain() fits through pmhost::do_fit's one static workspace: the GIL
    // is kept, so that two Python threads never explain at once.
    Explanation ex;
    std::string note;
    try {
        ex = chosen ? explain(d.run, eo) : explain_default(d.run, eo, &note);
        if (!note.empty())
            order = 0;
    } catch (const std::runtime_error &e) {
        std::string w = e.what();
        fail(w.rfind("--add", 0) == 0 ? K_ARGUMENT : K_ERROR, w);
    }
    return "{\"n_obs\": " + std::to_string(d.run.obs.size()) + ", \"order_note\": " +
           (note.empty() ? std::string("null") : "\"" + json_escape(note) + "\"") + ", " +
           explain_json(d.run, ex, order) + "}";
}

// A number keyword of plan(): finite and within [lo, hi], else ArgumentError.
double in_range(const char *name, double v, double lo, double hi, const char *unit)
{
    if (!(v >= lo && v <= hi))
        fail(K_ARGUMENT, std::string(name) + ": expected " + unit + " in [" + fmt("%g", lo) + ", " +
                             fmt("%g", hi) + "], got " + fmt("%g", v));
    return v;
}

// An input file of plan() read by `read`: FileError when it cannot be
// opened, FormatError (with its file:line) when it cannot be read.
template <class F> auto input_file(const std::string &path, const F &read) -> decltype(read())
{
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f)
        fail(K_FILE, path + ": cannot open: " + std::strerror(errno));
    std::fclose(f);
    try {
        return read();
    } catch (const std::runtime_error &e) {
        fail(K_FORMAT, e.what());
    }
}

// pmfit plan [RUN] --json, as the same JSON text.  d: the run taken so far
// (null: none).  NaN stands for an option not given (latitude, noise, lst,
// lon, slew); mount "" for the run's.
std::string plan_run(const std::shared_ptr<RunData> &d, const std::string &mount, double lat_deg,
                     int order, std::vector<std::string> adds, int next, double min_el,
                     double grid, bool fork, double noise, const std::string &criterion,
                     const std::string &sides, double meridian_limit, double slew, double settle,
                     double point_time, double flip_time, const std::string &horizon,
                     const std::string &catalogue, double lst, const std::string &utc, double lon,
                     double max_el)
{
    Run none;
    const Run &run = d ? d->run : none;
    PlanOptions po;
    if (order < 0 || order > PM_MAX_L)
        fail(K_ARGUMENT, "order " + std::to_string(order) + ": expected 0.." + std::to_string(PM_MAX_L));
    if (mount != "" && mount != "equatorial" && mount != "altaz")
        fail(K_ARGUMENT, "mount: expected 'equatorial' or 'altaz', got '" + mount + "'");
    if (d) {
        po.mount = run.mount;
        po.latitude = run.latitude;
    }
    if (mount != "") {
        const int want = mount == "altaz" ? PM_MOUNT_ALTAZ : PM_MOUNT_EQUATORIAL;
        if (d && want != run.mount) /* (its observations are of its mount) */
            fail(K_ARGUMENT, "mount: '" + mount + "', but the run is of an " +
                                 (run.mount == PM_MOUNT_ALTAZ ? "alt-az" : "equatorial") +
                                 " mount; its mount is the plan's: leave mount= out");
        po.mount = want;
    }
    if (!std::isnan(lat_deg))
        po.latitude = in_range("latitude", lat_deg, -90, 90, "degrees") * PI / 180;
    if (po.mount == PM_MOUNT_EQUATORIAL && std::isnan(po.latitude))
        fail(K_ARGUMENT, "latitude: an equatorial mount needs the site latitude (degrees), which " +
                             std::string(d ? "the run does not give" : "is not given"));
    if (next < 1 || next > 1000)
        fail(K_ARGUMENT, "next: expected a count 1..1000, got " + std::to_string(next));
    if (criterion != "I" && criterion != "D" && criterion != "i" && criterion != "d")
        fail(K_ARGUMENT, "criterion: expected 'I' (mean predicted error) or 'D' (determinant), got '" +
                             criterion + "'");
    if (sides != "run" && sides != "meridian" && sides != "both")
        fail(K_ARGUMENT, "sides: expected 'run', 'meridian' or 'both', got '" + sides + "'");
    bool timed = !std::isnan(lst) || !utc.empty();
    if (catalogue.empty() && (timed || !std::isnan(lon)))
        fail(K_ARGUMENT, "lst, utc and lon place the stars of a catalogue; give catalogue= too");
    if (!catalogue.empty() && !std::isnan(lst) && !utc.empty())
        fail(K_ARGUMENT, "catalogue: lst and utc both given: the time is one of them (lst, or "
                         "utc with lon)");
    if (!catalogue.empty() && std::isnan(lst) && utc.empty())
        fail(K_ARGUMENT, "catalogue: needs the time: lst (local sidereal time, hours) or utc "
                         "('YYYY-MM-DDTHH:MM') with lon (degrees east), one of them");
    po.order = order;
    po.adds = adds;
    po.next = next;
    po.min_el_deg = in_range("min_el", min_el, -10, 80, "degrees");
    if (!std::isnan(max_el))
        po.max_el_deg = in_range("max_el", max_el, 10, 90, "degrees");
    po.grid_deg = in_range("grid", grid, 1, 30, "degrees");
    po.gem = !fork;
    if (fork && po.mount == PM_MOUNT_ALTAZ) // (as pmfit plan --fork)
        fail(K_ARGUMENT, "fork: an equatorial mount that does not flip; the plan is of an alt-az "
                         "mount");
    po.d_optimal = criterion == "D" || criterion == "d";
    po.sides = sides == "both" ? SIDES_BOTH : sides == "meridian" ? SIDES_MERIDIAN : SIDES_RUN;
    po.meridian_limit_deg = in_range("meridian_limit", meridian_limit, 0, 90, "degrees");
    if (!std::isnan(slew))
        po.slew.rate_deg_s = in_range("slew", slew, 0.01, 100, "deg/s");
    po.slew.settle_s = in_range("settle", settle, 0, 3600, "seconds");
    po.slew.point_s = in_range("point_time", point_time, 0, 36000, "seconds");
    po.slew.flip_s = in_range("flip_time", flip_time, 0, 3600, "seconds");
    Plan p;
    try {
        po.noise_arcsec = std::isnan(noise) ? run_noise_arcsec(run, order, adds, 1.0)
                                            : in_range("noise", noise, 0, 1e5, "arcseconds");
        if (!horizon.empty())
            po.horizon = input_file(horizon, [&] { return read_horizon(horizon); });
        if (!catalogue.empty()) {
            po.stars = input_file(catalogue, [&] { return read_catalogue(catalogue); });
            if (!std::isnan(lst))
                po.when.lst_h = in_range("lst", lst, 0, 23.999999999, "hours");
            po.when.utc = utc;
            if (!utc.empty() && std::isnan(lon))
                fail(K_ARGUMENT, "utc: needs lon, the site's east longitude (degrees)");
            if (!utc.empty() && std::isnan(po.latitude))
                fail(K_ARGUMENT, "utc: needs the site latitude (latitude=, or the run's)");
            po.when.lon_rad = std::isnan(lon) ? 0 : in_range("lon", lon, -180, 360, "degrees") * PI / 180;
            po.when.lat_rad = po.latitude;
        }
        p = plan_targets(run, po);
    } catch (const std::runtime_error &e) {
        std::string w = e.what();
        // the host library words a bad date after pmfit's flag: here it is
        // the keyword utc=
        if (w.rfind("--utc: ", 0) == 0)
            fail(K_ARGUMENT, w.substr(2));
        fail(w.rfind("--add", 0) == 0 ? K_ARGUMENT : K_ERROR, w);
    }
    return plan_json(p, po, run.obs.size());
}

// pmfit compare OLD RUN --json, as the same JSON text.  OLD: a model
// (old_model), a run already read (old_run, fitted at order + adds) or a
// file (old_path: a model file or a run file, as pmfit compare reads it).
std::string compare_run(const Model *old_model, const std::shared_ptr<RunData> &old_run,
                        const std::string &old_path, const RunData &d, int order,
                        std::vector<std::string> adds)
{
    const bool order_given = order != -1; /* (-1: not given, the default 1) */
    if (!order_given)
        order = 1;
    if (order < 0 || order > PM_MAX_L)
        fail(K_ARGUMENT, "order " + std::to_string(order) + ": expected 0.." + std::to_string(PM_MAX_L));
    const int passes = 2000;
    OldSide os;
    try {
        if (old_model) {
            pm_model m = old_model->m;
            if (pm_model_prepare(&m) != PM_OK)
                fail(K_ARGUMENT, "old: the model cannot be prepared (non-finite coefficients?)");
            os = old_from_model(m, old_model->info, old_model->cov);
        } else if (old_run) {
            os = old_from_run(old_run->run, order, adds, passes);
        } else {
            os = load_old(old_path, order, adds, ReadOptions(), passes);
        }
    } catch (const std::runtime_error &e) {
        std::string w = e.what();
        // an effect pmfit does not know, a file that cannot be opened, or
        // one that cannot be read (its file:line)
        fail(w.rfind("--add", 0) == 0 ? K_ARGUMENT
             : w.find("cannot open") != std::string::npos ? K_FILE : K_FORMAT, w);
    }
    if (!os.is_run && (order_given || !adds.empty())) // (pmfit compare's rule)
        fail(K_ARGUMENT, "old is a model: the comparison is of its own terms; order and add "
                         "choose the model fitted to an old run");
    if (os.is_run && os.fit.status != PM_OK)
        fail_fit(os.fit, (old_path.empty() ? std::string("old run") : old_path) + " (the old run)", passes);
    Comparison c;
    try {
        c = compare_old(os, d.run, old_model ? std::string("old") : old_path.empty() ? "old run" : old_path);
    } catch (const std::runtime_error &e) {
        fail(K_ERROR, e.what());
    }
    return comparison_json(c);
}

// pmfit simulate --inject SPEC ... --into RUN, without the file: a copy of
// the run with the effects added to its observed positions, and what was
// injected (sizes, RMS displacements, the lines of moved points).
py::tuple inject_run(const RunData &d, const std::vector<std::string> &specs, double phase_deg,
                     unsigned long long seed)
{
    if (specs.empty())
        fail(K_ARGUMENT, "effects: expected at least one EFFECT[=SIZE] (pmfit --inject syntax)");
    if (!std::isfinite(phase_deg))
        fail(K_ARGUMENT, "phase: expected a finite angle in degrees");
    std::vector<Injection> list;
    for (const std::string &spec : specs) {
        Injection in;
        try {
            in = parse_injection(spec);
        } catch (const std::runtime_error &e) {
            fail(K_ARGUMENT, e.what());
        }
        in.phase_deg = phase_deg;
        in.seed = seed;
        list.push_back(in);
    }
    auto out = std::make_shared<RunData>(d);
    InjectReport rep;
    try {
        rep = inject(out->run, list);
    } catch (const std::runtime_error &e) {
        std::string w = e.what(); // an effect it cannot make, or the baseline fit failing
        fail(w.find("--add") != std::string::npos || w.rfind("--inject", 0) == 0 ? K_ARGUMENT : K_ERROR, w);
    }
    py::list items;
    for (size_t k = 0; k < list.size(); k++) {
        py::dict it;
        it["effect"] = list[k].effect;
        it["size_arcsec"] = rep.size_arcsec[k];
        it["rms_arcsec"] = rep.rms_arcsec[k];
        py::list lines;
        for (int j : rep.moved[k])
            lines.append(out->run.obs[(size_t)j].line);
        it["moved_lines"] = lines;
        items.append(it);
    }
    py::dict info;
    info["order"] = rep.order;
    info["sigma_arcsec"] = rep.sigma_arcsec;
    info["injected"] = items;
    return py::make_tuple(out, info);
}

// pmfit simulate OUT (the true model given): the run pmsim_write writes,
// read back as pmfit would read the file (through a temporary file, removed).
std::shared_ptr<RunData> simulate_run(const Model &truth, long n, unsigned long long seed,
                                      double lat_deg, double el_limit, double noise, bool fork,
                                      const std::vector<std::pair<std::string, double>> &effects,
                                      double phase_deg)
{
    if (n < 1 || n > 10000000)
        fail(K_ARGUMENT, "n: expected 1..10000000 observations, got " + std::to_string(n));
    pmsim_spec spec;
    pmsim_default(&spec);
    spec.n = n;
    spec.seed = seed;
    spec.latitude_deg = in_range("latitude", lat_deg, -90, 90, "degrees");
    spec.el_limit_deg = in_range("el_limit", el_limit, -10, 80, "degrees");
    spec.noise_arcsec = in_range("noise", noise, 0, 1e5, "arcseconds");
    spec.gem = fork ? 0 : 1;
    spec.truth = truth.m;
    spec.truth.latitude = lat_deg * PI / 180;
    if (pm_model_prepare(&spec.truth) != PM_OK)
        fail(K_ARGUMENT, "truth: the model cannot be prepared (non-finite coefficients?)");
    char err[1024];
    for (const auto &e : effects)
        if (pmsim_add_effect(&spec, e.first.c_str(), e.second, phase_deg, seed, err, sizeof err) != 0)
            fail(K_ARGUMENT, std::string("effects: ") + err);
    const char *dir = std::getenv("TMPDIR");
    std::string path = std::string(dir && *dir ? dir : "/tmp") + "/pm-simulate-XXXXXX";
    int fd = mkstemp(&path[0]);
    if (fd < 0)
        fail(K_FILE, path + ": cannot create a temporary file: " + std::strerror(errno));
    close(fd);
    int st;
    {
        py::gil_scoped_release nogil;
        st = pmsim_write(&spec, path.c_str(), "made by: pm.simulate", err, sizeof err);
    }
    if (st != 0) {
        std::remove(path.c_str());
        fail(K_ERROR, err);
    }
    std::shared_ptr<RunData> r;
    try {
        r = read_run(path, true, false, "named", "", false, std::vector<double>(4, NAN));
    } catch (...) {
        std::remove(path.c_str());
        throw;
    }
    std::remove(path.c_str());
    r->run.path = "<pm.simulate>"; // (the temporary file is gone)
    return r;
}

} // namespace

PYBIND11_MODULE(_pm, mod)
{
    mod.doc() = "compiled core of the pm package (use `import pm`)";
    if (PM_CHECK_CONFIG() != PM_OK)
        throw std::runtime_error("pm: library and extension built with different PM_MAX_L/PM_MAX_EXTRA");
    py::register_exception_translator(translate);
    // apply's paths on this machine (apply_lanes.h), and the one apply takes
    py::list paths;
    for (int p = 0; p < PM_LANES_N_PATHS; p++)
        if (pm_lanes_runs(p))
            paths.append(pm_lanes_name(p));
    mod.attr("_lanes_paths") = paths;
    mod.attr("_lanes_best") = pm_lanes_name(pm_lanes_best());

    mod.def("_set_errors", [](py::dict d) {
        for (int k = 0; k < 6; k++) {
            delete g_errors[k];
            g_errors[k] = new py::object(d[KIND_NAMES[k]]);
        }
    });
    mod.attr("MAX_L") = PM_MAX_L;
    mod.attr("MAX_TERMS") = PM_MAX_TERMS;
    mod.attr("MAX_AUX") = PM_MAX_AUX;
    mod.attr("MODEL_DEFINITION") = PM_MODEL_DEFINITION;
    mod.attr("INVERT_TOL") = PM_INVERT_TOL;
    mod.attr("START_MAX") = PM_START_MAX;
    mod.attr("RAD2AS") = RAD2AS;
    mod.def("status_name", &status_name);
    mod.def("status_text", &status_text);

    py::class_<Model>(mod, "Model")
        .def(py::init([](int mount, int order, double lat) { return Model::make(mount, order, lat); }),
             py::arg("mount"), py::arg("order"), py::arg("latitude") = 0.0)
        .def(py::init([](const Model &o) { return Model(o); }))
        .def_static("_load", &Model::load)
        .def_property_readonly("_mount", [](const Model &m) { return m.m.mount; })
        .def_property_readonly("order", [](const Model &m) { return m.m.order; })
        .def_property_readonly("n_terms", [](const Model &m) { return m.m.n_terms; })
        .def_property_readonly("n_base", [](const Model &m) { return m.m.n_base; })
        .def_property_readonly("needs_context", [](const Model &m) { return m.m.needs_ctx != 0; })
        .def_property("latitude", [](const Model &m) { return m.m.latitude; }, &Model::set_latitude)
        .def_property("coefficients", &Model::coefficients, &Model::set_coefficients)
        .def_property_readonly("names", &Model::names)
        .def_property_readonly("terms", &Model::terms)
        .def_property_readonly("inputs", &Model::inputs)
        .def_property_readonly("pier_side", [](const Model &m) { return m.info.pier; })
        .def_property_readonly("_inputs_needed", &Model::inputs_needed)
        .def("_add_term", &Model::add_term)
        .def("_apply", &Model::apply)
        .def("_apply_lanes", &Model::apply_lanes)
        .def_property_readonly("_lanes_ok", [](const Model &m) { return pm_apply_lanes_ok(&m.m); })
        .def("_invert", &Model::invert)
        .def("_residual", &Model::residual)
        .def("apply_point", &Model::apply_point, py::arg("enc_ha"), py::arg("enc_dec"),
             "apparent (ha, dec) of one encoder position: the per-point C call "
             "pm_model_apply (radians; models without context inputs)")
        .def("invert_point", &Model::invert_point, py::arg("app_ha"), py::arg("app_dec"),
             py::arg("side") = 0,
             "encoder (ha, dec, status) pointing at one apparent position: the per-point C "
             "call pm_model_invert (status 0, or a warning 1/2)")
        .def("_save", &Model::save)
        .def("_emit_c", &Model::emit_c);

    py::class_<RunData, std::shared_ptr<RunData>>(mod, "RunData")
        .def("columns", &run_columns)
        .def("info", &run_info);
    mod.def("read_run", &read_run, py::arg("path"), py::arg("refraction"), py::arg("skip_bad"),
            py::arg("format"), py::arg("equinox"), py::arg("azimuth_count"), py::arg("weather"));
    mod.def("run_from_arrays", &run_from_arrays);

    py::class_<Fit>(mod, "Fit")
        .def_property_readonly("model", &Fit::model)
        .def_property_readonly("coefficients", &Fit::coefficients)
        .def_property_readonly("errors", &Fit::errors)
        .def_property_readonly("covariance", &Fit::covariance)
        .def_property_readonly("names", [](const Fit &f) { return f.model().names(); })
        .def_property_readonly("residuals", &Fit::residuals)
        .def_property_readonly("index", [](const Fit &f) { return copy_out(f.out.idx); })
        .def_property_readonly("lines", [](const Fit &f) { return copy_out(f.lines); })
        .def_property_readonly("sigma", [](const Fit &f) { return f.out.res.sigma; })
        .def_property_readonly("chi2", [](const Fit &f) { return f.out.res.chi2; })
        .def_property_readonly("rms", [](const Fit &f) { return f.out.rms; })
        .def_property_readonly("n_obs", [](const Fit &f) { return f.out.res.n_obs; })
        .def_property_readonly("n_params", [](const Fit &f) { return f.out.res.n_par; })
        .def_property_readonly("iterations", [](const Fit &f) { return f.out.res.iterations; })
        .def_property_readonly("converged", [](const Fit &f) { return f.out.res.converged != 0; })
        .def_property_readonly("title", [](const Fit &f) { return f.title; })
        .def_property_readonly("_error_map", [](const Fit &f) { return f.error_map; })
        .def_property_readonly("undetermined", [](const Fit &f) { return f.undetermined; })
        .def_property_readonly("max_correlation", &Fit::max_correlation)
        .def("_pointing_sigma", &Fit::pointing_sigma);
    mod.def("fit_run", &fit_run);
    mod.def("explain_run", &explain_run);
    mod.def("plan_run", &plan_run);
    mod.def("compare_run", &compare_run);
    mod.def("inject_run", &inject_run);
    mod.def("simulate_run", &simulate_run);
}
