"""pm: telescope pointing models from Python.

The isotropic and anisotropic pointing models of Pal, Vida, Meszaros & Mezo
(Exp Astron, 2016), as the C library of this repository implements them
(include/pm.h, docs/model.md), for notebooks and observatory scripts:

    import numpy as np, pm
    run = pm.read_run("examples/sim_gem.dat")      # a pointing run file
    res = pm.fit_run(run, order=1)                 # what `pmfit fit RUN` fits
    res.names, res.coefficients, res.errors, res.covariance   # radians
    app_ha, app_dec = res.model.apply(enc_ha, enc_dec)        # numpy arrays
    enc_ha, enc_dec = res.model.invert(app_ha, app_dec)
    res.model.save("mount.pm"); m = pm.load_model("mount.pm")
    report = pm.explain(run)                       # a dict: `pmfit explain --json`

Angles are radians everywhere (pm.RAD2ARCSEC converts); arrays broadcast like
numpy's.  Failures raise pm.Error subclasses carrying the library's message
(file:line for files).  docs/python.md has the whole story.
"""

import json as _json
from math import isfinite as _isfinite
import os as _os
import warnings as _warnings

import numpy as _np

try:
    from . import _pm
except ImportError as _e:  # the source tree (python/pm) has no extension
    raise ImportError("pm: the compiled extension is missing (%s): build the package with "
                      "`make python` and put build/python on PYTHONPATH" % _e) from None

__all__ = [
    "Error", "FileError", "FormatError", "ArgumentError", "NonFiniteError", "FitError",
    "PointingWarning", "Model", "Run", "FitResult", "SplitFit", "read_run", "load_model",
    "fit", "fit_run", "explain", "plan", "compare", "inject", "simulate", "RAD2ARCSEC", "MAX_L", "MAX_TERMS", "MAX_AUX",
]

# ---------------------------------------------------------------------------
# Errors


class Error(Exception):
    """Any failure of the pm library.  ``status``: the library's status code
    (pm_status, or pmrun_read's) when there is one, else None."""
    status = None


class FileError(Error, OSError):
    """A file cannot be opened, read or written (the message names it)."""


class FormatError(Error, ValueError):
    """A run or model file is malformed: the message says where
    ("path:LINE: what was wrong, what was expected")."""


class ArgumentError(Error, ValueError):
    """A bad argument: arrays of mismatched shapes, an unknown option or
    effect, an input the model needs that was not given."""


class NonFiniteError(ArgumentError):
    """NaN or infinity in an input, or an evaluation that overflowed."""


class FitError(Error):
    """The fit failed (too few observations, a term the sky coverage cannot
    determine, no convergence).  ``bad_term``: the term's name after
    PM_ERR_SINGULAR, else None."""
    bad_term = None


class PointingWarning(UserWarning):
    """Some targets of an inverse were unreachable from the requested side
    (PM_WARN_UNREACHABLE), or the iteration bound was reached
    (PM_WARN_NOT_CONVERGED): the nearest positions found are returned."""


_pm._set_errors({"Error": Error, "FileError": FileError, "FormatError": FormatError,
                 "ArgumentError": ArgumentError, "NonFiniteError": NonFiniteError,
                 "FitError": FitError})

RAD2ARCSEC = _pm.RAD2AS
"""Arcseconds per radian."""
MAX_L = _pm.MAX_L
MAX_TERMS = _pm.MAX_TERMS
MAX_AUX = _pm.MAX_AUX
INVERT_TOL = _pm.INVERT_TOL
START_MAX = _pm.START_MAX
WARN_NOT_CONVERGED = 1
WARN_UNREACHABLE = 2

_MOUNTS = {"equatorial": 0, "altaz": 1, "alt-az": 1}
_AUX_INPUTS = ("temp_c", "time_h", "dir")  # PM_AUX_TEMP, _TIME, _DIR; then aux[j]

# ---------------------------------------------------------------------------
# Argument checks


def _mount_id(mount):
    if isinstance(mount, str) and mount.lower() in _MOUNTS:
        return _MOUNTS[mount.lower()]
    raise ArgumentError("mount: expected 'equatorial' or 'altaz', got %r" % (mount,))


def _path(path, what="path"):
    try:
        p = _os.fspath(path)
    except TypeError:
        raise ArgumentError("%s: expected a file name, got %r" % (what, path)) from None
    if ("\0" if isinstance(p, str) else b"\0") in p:  # the C call would cut it there
        raise ArgumentError("%s: %r holds a NUL character" % (what, p))
    return p


def _index(a, i):
    """"[i, j]" for the flat index i of array a ("" for a scalar)."""
    where = _np.unravel_index(i, a.shape) if a.ndim else ()
    return "[%s]" % ", ".join(str(int(j)) for j in where) if where else ""


def _as_float(name, value, what="numbers"):
    """value as a float64 array.  ArgumentError, naming the argument, for
    what numpy would turn silently into a wrong number: None (NaN), complex
    values (their real part, with only a ComplexWarning), and anything that
    is not a number."""
    if value is None:
        raise ArgumentError("%s is None: not a number" % name)
    mask = getattr(value, "mask", None)
    if isinstance(value, _np.ma.MaskedArray) or (
            mask is not None and not callable(mask) and hasattr(mask, "shape")):
        # np.asarray takes the data under the mask: masked points would be
        # fitted or evaluated as if they were good (astropy reads a CSV's
        # missing values as masked; an outside probe's five masked points
        # took sigma from 2.19" to 171").  numpy's masked arrays, and any
        # array with a mask of its own (astropy's Masked)
        m = (_np.ma.getmaskarray(value) if isinstance(value, _np.ma.MaskedArray)
             else _np.broadcast_to(_np.asarray(mask, dtype=bool), _np.shape(value)))
        if m.any():
            i = int(_np.argmax(m.reshape(-1)))
            raise ArgumentError(
                "%s%s is masked (%d of %d values): a masked array's data under the mask "
                "would be used; drop those points from every array, or fill them" % (
                    name, _index(m, i), int(m.sum()), m.size))
        value = (_np.ma.getdata(value) if isinstance(value, _np.ma.MaskedArray)
                 else getattr(value, "unmasked", value))
    try:
        a = _np.asarray(value)
    except (TypeError, ValueError) as e:
        raise ArgumentError("%s: expected %s (%s)" % (name, what, e)) from None
    if a.dtype.kind == "O":  # a Python loop, for object arrays only
        for i, x in enumerate(a.reshape(-1)):
            if x is None:
                raise ArgumentError("%s%s is None: not a number" % (name, _index(a, i)))
            if isinstance(x, (complex, _np.complexfloating)):
                raise ArgumentError("%s%s is %r: expected a real number (complex values; "
                                    "take .real to drop the imaginary part)" % (
                                        name, _index(a, i), x))
    elif a.dtype.kind in "USb":  # text and truth values are not numbers (numpy makes them so)
        raise ArgumentError("%s: expected %s, got %s values (%r%s)" % (
            name, what, {"U": "text", "S": "bytes", "b": "boolean"}[a.dtype.kind],
            a.reshape(-1)[0].item() if a.size else "", ", ..." if a.size > 1 else ""))
    elif a.dtype.kind == "c":
        if not a.size:
            raise ArgumentError("%s: expected real numbers, got %s" % (name, a.dtype))
        i = int(_np.argmax(a.reshape(-1).imag != 0))  # the first with an imaginary part
        raise ArgumentError("%s%s is %r: expected a real number (%s values; take .real to "
                            "drop the imaginary part)" % (name, _index(a, i),
                                                          a.reshape(-1)[i].item(), a.dtype))
    try:
        return a.astype(_np.float64, copy=False)
    except (TypeError, ValueError) as e:
        raise ArgumentError("%s: expected %s (%s)" % (name, what, e)) from None


def _as_int(name, value, allowed=None, allowed_words=None):
    f = _as_float(name, value, "integers")
    if f.size and not (_np.isfinite(f).all() and (f == _np.round(f)).all()):
        raise ArgumentError("%s: expected integers" % name)
    a = f.astype(_np.int64)
    if allowed is not None and a.size and not _np.isin(a, allowed).all():
        bad = a.reshape(-1)[~_np.isin(a.reshape(-1), allowed)][0]
        raise ArgumentError("%s: expected %s, got %d" % (
            name, allowed_words or "values in %s" % list(allowed), bad))
    return a.astype(_np.intc)


def _first_bad(name, a):
    """NonFiniteError naming the first non-finite element of a."""
    flat = a.reshape(-1)
    i = int(_np.flatnonzero(~_np.isfinite(flat))[0])
    return NonFiniteError("%s%s is %r: expected a finite number" % (name, _index(a, i),
                                                                   float(flat[i])))


def _broadcast(named):
    """Broadcast the (name, array) pairs to one shape: (shape, flat arrays)."""
    try:
        shape = _np.broadcast_shapes(*(a.shape for _, a in named))
    except ValueError:
        raise ArgumentError("the shapes do not match: " + ", ".join(
            "%s %s" % (n, a.shape) for n, a in named)) from None
    return shape, [_np.ascontiguousarray(_np.broadcast_to(a, shape)).reshape(-1) for _, a in named]


def _needed_inputs(model):
    """The context inputs a model's terms read: names in _AUX_INPUTS, and the
    indices j of aux[j]."""
    temp, time, dir_, aux = model._inputs_needed
    need = {n for n, f in zip(_AUX_INPUTS, (temp, time, dir_)) if f}
    return need, set(aux)


def _points(model, named, pier=None, temp_c=None, time_h=None, dir=None, aux=None):
    """Check, convert and broadcast the positions and the context inputs the
    model reads: (shape, flat position arrays, context keyword arguments)."""
    arrays = [(n, _as_float(n, v)) for n, v in named]
    for n, a in arrays:
        if not _np.isfinite(a).all():
            raise _first_bad(n, a)
    need, need_aux = _needed_inputs(model)
    given = {"temp_c": temp_c, "time_h": time_h, "dir": dir}
    extra = []
    for n in _AUX_INPUTS:
        if n in need:
            if given[n] is None:
                raise ArgumentError("the model has a term on %s (%s): pass %s=" % (
                    n, ", ".join(t["name"] for t in model.terms if t["kind"] == 4 and
                                 t["aux"] == _AUX_INPUTS.index(n)), n))
            v = _as_int(n, given[n], (-1, 0, 1)) if n == "dir" else _as_float(n, given[n])
            if n != "dir" and not _np.isfinite(v).all():
                raise _first_bad(n, v)
            extra.append((n, v))
    aux_cols = []
    if need_aux:
        if aux is None:
            raise ArgumentError("the model has terms on the auxiliary inputs %s: pass aux=[...] "
                                "(one column per input, in order)" % sorted(need_aux))
        if isinstance(aux, dict):
            # by the names of the columns the model reads (a fit's, or a
            # version-4 model file's Model.inputs), else by the dict's order
            # (its first MAX_AUX): a run whose columns come in another order
            # than the fit's is read right (by position it fed the humidity
            # in the pressure's place)
            names, keys = model.inputs, list(aux.keys())
            cols = []
            for j in range(max(need_aux) + 1):
                if j in names:
                    if names[j] not in aux:
                        raise ArgumentError(
                            "aux: the model reads the column %r as aux[%d]; the dict has no "
                            "such column (it has %s)" % (names[j], j, ", ".join(map(repr, keys))
                                                         or "none"))
                    cols.append(aux[names[j]])
                elif j < len(keys):
                    cols.append(aux[keys[j]])
                else:
                    cols.append(0.0 if j not in need_aux else None)
            aux = cols
        aux = list(aux)
        if len(aux) <= max(need_aux) or len(aux) > MAX_AUX:
            raise ArgumentError("aux: the model reads aux[%d]; give %d..%d columns" % (
                max(need_aux), max(need_aux) + 1, MAX_AUX))
        for j, col in enumerate(aux):
            c = _as_float("aux[%d]" % j, col)
            if j in need_aux and not _np.isfinite(c).all():
                raise _first_bad("aux[%d]" % j, c)
            aux_cols.append(("aux[%d]" % j, _np.nan_to_num(c) if j not in need_aux else c))
    if pier is not None:
        extra.append(("pier", _as_int("pier", pier, (-1, 0, 1))))
    shape, flat = _broadcast(arrays + extra + aux_cols)
    n_pos = len(arrays)
    kw = {}
    for (n, _), f in zip(extra, flat[n_pos:n_pos + len(extra)]):
        kw[n] = f.astype(_np.intc) if n in ("dir", "pier") else f
    if aux_cols:
        kw["aux"] = _np.ascontiguousarray(_np.stack(flat[n_pos + len(extra):], axis=1))
    return shape, flat[:n_pos], kw


def _ctx_args(kw, threads=None):
    if threads is None:
        threads = 0
    elif (isinstance(threads, bool) or not isinstance(threads, (int, _np.integer)) or
          not 1 <= threads <= 1 << 30):
        raise ArgumentError("threads: expected a positive integer, or None for all cores")
    return (kw.get("pier"), kw.get("temp_c"), kw.get("time_h"), kw.get("dir"), kw.get("aux"),
            int(threads))


def _shaped(shape, *arrays):
    if shape == ():
        return tuple(a.reshape(-1)[0].item() for a in arrays)
    return tuple(a.reshape(shape) for a in arrays)


def _adds(add):
    if add is None:
        return []
    if isinstance(add, str):
        return [add]
    try:
        adds = list(add)
    except TypeError:
        raise ArgumentError("add: expected an effect name or a list of them") from None
    for a in adds:
        if not isinstance(a, str):
            raise ArgumentError("add: expected effect names (pmfit --add syntax), got %r" % (a,))
    return adds


def _order(order):
    if isinstance(order, bool) or not isinstance(order, (int, _np.integer)):
        raise ArgumentError("order: expected an integer 0..%d, got %r" % (MAX_L, order))
    return int(order)

# ---------------------------------------------------------------------------
# Model


class Model(_pm.Model):
    """A pointing model: its terms and coefficients (radians).

    ``Model(order=1, mount="equatorial", latitude=0.0)`` is the harmonic set
    of order L (4L^2+12L+6 terms, all zero); models also come from fits
    (``FitResult.model``) and model files (``load_model``).

    Attributes: ``names``, ``coefficients`` (read-only arrays; settable as a
    whole: the model is prepared again, and left unchanged if that fails),
    ``terms`` (dicts), ``order``,
    ``n_terms``, ``mount``, ``latitude`` (radians, used by refraction and
    tube-flexure terms), ``inputs`` ({j: column name}: the run column each
    ``aux[:, j]`` the model reads is, where a fit or a version-4 model file
    says so; ``save`` writes it and ``compare`` finds the columns by it) and
    ``pier_side`` (0; +1 or -1 for a model of one pier side, ``split=True``).
    """

    def __init__(self, order=1, mount="equatorial", latitude=0.0):
        lat = _as_float("latitude", latitude)
        if lat.shape != () or not abs(float(lat)) <= _np.pi / 2:
            raise ArgumentError("latitude: expected radians within +-pi/2, got %r" % (latitude,))
        super().__init__(_mount_id(mount), _order(order), float(lat))

    @classmethod
    def _wrap(cls, c):
        m = cls.__new__(cls)
        _pm.Model.__init__(m, c)
        return m

    @property
    def mount(self):
        return "altaz" if self._mount == 1 else "equatorial"

    @property
    def coefficients(self):
        """The coefficients (radians, one per term): a read-only copy, so that
        an in-place edit raises instead of being lost.  To change them assign
        a whole array (``c = m.coefficients.copy(); c[2] += 1e-5;
        m.coefficients = c``): the model is prepared again, and left
        unchanged if that fails."""
        c = _pm.Model.coefficients.__get__(self)
        c.setflags(write=False)
        return c

    @coefficients.setter
    def coefficients(self, value):
        c = _as_float("coefficients", value)
        if c.shape != (self.n_terms,):
            raise ArgumentError("coefficients: expected %d numbers (one per term), got shape %s"
                                % (self.n_terms, c.shape))
        _pm.Model.coefficients.__set__(self, c)

    def copy(self):
        """An independent copy (also ``copy.copy`` and ``copy.deepcopy``)."""
        return Model._wrap(self)

    def __copy__(self):
        return self.copy()

    def __deepcopy__(self, memo):
        return self.copy()

    def __repr__(self):
        return "<pm.Model %s, order %d, %d terms>" % (self.mount, self.order, self.n_terms)

    def __eq__(self, other):
        return (isinstance(other, Model) and self.mount == other.mount and
                self.order == other.order and self.terms == other.terms and
                _np.array_equal(self.coefficients, other.coefficients) and
                (self.latitude == other.latitude))

    __hash__ = None

    def add_term(self, kind, k=0, l=0, m=0, side=0, aux=0, param=0.0, value=0.0):
        """Append a term (pm_model_add_term; fields as pm_term in include/pm.h,
        kind 0 SH, 1 FOURIER, 2 SECTORAL, 3 ZENITH, 4 AUX); its index."""
        def one(name, v, conv):
            a = conv(name, v)
            if a.shape != ():
                raise ArgumentError("%s: expected one number, got shape %s" % (name, a.shape))
            return a.item()
        ints = [one(n, v, _as_int) for n, v in (("kind", kind), ("k", k), ("l", l), ("m", m),
                                                ("side", side), ("aux", aux))]
        param, value = one("param", param, _as_float), one("value", value, _as_float)
        for name, v in (("param", param), ("value", value)):
            if not _np.isfinite(v):
                raise NonFiniteError("%s is %r: expected a finite number" % (name, v))
        return self._add_term(*ints, param, value)

    def apply(self, enc_ha, enc_dec, *, pier=None, temp_c=None, time_h=None, dir=None, aux=None,
              threads=None):
        """Apparent (ha, dec) of encoder positions (pm_model_apply, vectorised).

        Radians; arrays (or scalars) broadcast together.  The context inputs
        (pier side, temperature, time, slew direction, auxiliary columns) are
        needed only by models with such terms.  Raises NonFiniteError for a
        NaN or infinity, naming the element."""
        if threads is not None:
            _ctx_args({}, threads)  # checked on every way, the one-point way too
        if (isinstance(enc_ha, float) and isinstance(enc_dec, float) and _isfinite(enc_ha) and
                _isfinite(enc_dec) and pier is None and not self.needs_context):
            return self.apply_point(enc_ha, enc_dec)  # one point: the C call itself
        if (type(enc_ha) is _np.ndarray and type(enc_dec) is _np.ndarray and
                enc_ha.dtype == _np.float64 and enc_dec.dtype == _np.float64 and
                enc_ha.ndim >= 1 and enc_ha.shape == enc_dec.shape and pier is None and
                temp_c is None and time_h is None and dir is None and aux is None and
                not self.needs_context):
            # float arrays of one shape, no context: straight to the loop,
            # which checks every point (the pass of _points over the arrays
            # would cost a fifth of the time); a NaN or infinity there
            # takes the checked way below for its message naming the element
            args = _ctx_args({}, threads)
            try:
                a, b = self._apply(enc_ha.reshape(-1), enc_dec.reshape(-1), *args)
                return _shaped(enc_ha.shape, a, b)
            except NonFiniteError:
                pass
        shape, (h, d), kw = _points(self, [("enc_ha", enc_ha), ("enc_dec", enc_dec)],
                                    pier, temp_c, time_h, dir, aux)
        a, b = self._apply(h, d, *_ctx_args(kw, threads))
        return _shaped(shape, a, b)

    def invert(self, app_ha, app_dec, side=0, *, start_ha=None, start_dec=None,
               return_status=False, pier=None, temp_c=None, time_h=None, dir=None, aux=None,
               threads=None):
        """Encoder (ha, dec) that point at apparent positions (pm_model_invert,
        vectorised).

        ``side``: 0 / "normal" or 1 / "flipped" (beyond the pole), per point
        or for all.  With ``start_ha``, ``start_dec`` (e.g. the previous
        tracking tick) the solution continuous with them
        (pm_model_invert_near).  Targets the mount cannot reach from that side
        give the nearest position and a PointingWarning;
        ``return_status=True`` returns the per-point status as a third array
        (0 ok, 1 PM_WARN_NOT_CONVERGED, 2 PM_WARN_UNREACHABLE)."""
        if isinstance(side, str):
            if side not in ("normal", "flipped"):
                raise ArgumentError("side: expected 'normal' or 'flipped', got %r" % side)
            side = 0 if side == "normal" else 1
        named = [("app_ha", app_ha), ("app_dec", app_dec)]
        if (start_ha is None) != (start_dec is None):
            raise ArgumentError("invert: give both start_ha and start_dec, or neither")
        if start_ha is not None:
            named += [("start_ha", start_ha), ("start_dec", start_dec)]
        shape, pos, kw = _points(self, named, pier, temp_c, time_h, dir, aux)
        if (_np.abs(pos[1]) > _np.pi / 2).any():
            i = int(_np.flatnonzero(_np.abs(pos[1]) > _np.pi / 2)[0])
            raise ArgumentError("app_dec: point %d is %r, beyond +-pi/2 (an apparent "
                                "declination or elevation)" % (i, float(pos[1][i])))
        if start_ha is not None:
            for n, a in (("start_ha", pos[2]), ("start_dec", pos[3])):
                if (_np.abs(a) > START_MAX).any():
                    raise ArgumentError("%s: |angle| beyond %g rad (PM_START_MAX)" % (n, START_MAX))
        s = _as_int("side", side, (0, 1),
                    "0 / 'normal' or 1 / 'flipped' (per point or for all)")
        try:
            s = _np.ascontiguousarray(_np.broadcast_to(s, shape)).reshape(-1)
        except ValueError:
            raise ArgumentError("side: shape %s does not match %s" % (s.shape, shape)) from None
        if start_ha is not None:
            a, b, st = self._invert(pos[0], pos[1], None, pos[2], pos[3], *_ctx_args(kw, threads))
        else:
            a, b, st = self._invert(pos[0], pos[1], s, None, None, *_ctx_args(kw, threads))
        n_warn = int(_np.count_nonzero(st))
        if n_warn and not return_status:
            first = int(_np.flatnonzero(st)[0])
            _warnings.warn(PointingWarning(
                "%d of %d targets: %s (first: point %d); the nearest positions are returned "
                "(return_status=True gives each point's status)" % (
                    n_warn, st.size, _pm.status_text(int(st[first])), first)), stacklevel=2)
        if return_status:
            return _shaped(shape, a, b) + (st.reshape(shape) if shape != () else int(st[0]),)
        return _shaped(shape, a, b)

    def residual(self, enc_ha, enc_dec, app_ha, app_dec, *, pier=None, temp_c=None,
                 time_h=None, dir=None, aux=None, threads=None):
        """Observed minus model in the tangent plane (pm_model_residual):
        an array of shape (..., 2), radians (axis 1 on the sky, axis 2)."""
        shape, (a, b, c, d), kw = _points(
            self, [("enc_ha", enc_ha), ("enc_dec", enc_dec), ("app_ha", app_ha),
                   ("app_dec", app_dec)], pier, temp_c, time_h, dir, aux)
        r = self._residual(a, b, c, d, *_ctx_args(kw, threads))
        return r.reshape(shape + (2,))

    def save(self, path, comment=None):
        """Write a model file (docs/formats.md; atomically, bit-exact)."""
        self._save(_path(path), comment)

    def emit_c(self, path, prefix="pm_fitted", comment=None):
        """Write the model as C89 constant data with a loader (pmfit --emit-c)."""
        self._emit_c(_path(path), prefix, comment)


def load_model(path):
    """Read a model file (pmmodel_load): a Model, bit-identical to the one saved.
    FormatError with file:line for a malformed file, FileError if unreadable."""
    return Model._wrap(_pm.Model._load(_path(path)))

# ---------------------------------------------------------------------------
# Runs


class Run:
    """A pointing run: observations with encoder and apparent positions and
    the inputs of the physical terms, as pmfit reads and fits them.

    Columns (numpy arrays, radians unless the name says otherwise):
    ``enc_ha, enc_dec, app_ha, app_dec`` (axis 1/2: hour angle/declination,
    or azimuth (north through east)/elevation), ``pier`` (+1 east/normal, -1
    west/beyond the pole, 0 unknown), ``dir`` (slew direction on axis 1;
    derived from the sequence when the file has none), ``line`` (file line),
    ``temp_c``, ``time_h`` (NaN when absent), ``aux`` (dict of the auxiliary
    columns, with the derived "dec_dir"), ``enc_raw`` (the encoder angles as
    written, shape (n, 2)).  Metadata: ``path, mount, latitude, format,
    warnings, skipped, aux_names, site, dir_derived``."""

    def __init__(self, data):
        self._data = data
        info = data.info()
        cols = data.columns()
        for k, v in cols.items():
            if isinstance(v, _np.ndarray):
                v.setflags(write=False)
            setattr(self, k, v)
        for v in cols["aux"].values():
            v.setflags(write=False)
        for k, v in info.items():
            setattr(self, k, v)

    def __len__(self):
        return len(self.enc_ha)

    def __repr__(self):
        return "<pm.Run %s: %s mount, %d observations>" % (self.path, self.mount, len(self))

    @classmethod
    def from_arrays(cls, enc_ha, enc_dec, app_ha, app_dec, *, mount="equatorial", latitude=None,
                    pier=None, temp_c=None, time_h=None, dir=None, aux=None):
        """A run from arrays (radians), as if read from a file: without
        ``pier`` an equatorial mount's side comes from the encoder dec;
        without ``dir`` the slew directions are derived from the sequence.
        ``aux``: a dict {name: column} (names for ``add=["aux:NAME"]``);
        ``latitude`` (radians) is needed by refraction/tube_flexure terms of
        equatorial mounts; ``temp_c``, ``time_h`` may hold NaN (absent).
        Messages call observation i (0-based) "line i+1"."""
        m = _mount_id(mount)
        named = [("enc_ha", enc_ha), ("enc_dec", enc_dec), ("app_ha", app_ha), ("app_dec", app_dec)]
        given = [(n, _as_float(n, v)) for n, v in named]
        shapes = {n: a.shape for n, a in given}
        arrays = [(n, _np.atleast_1d(a)) for n, a in given]
        for n, a in arrays:
            if a.ndim != 1:
                raise ArgumentError("%s: expected a 1-D array, got shape %s" % (n, a.shape))
            if not _np.isfinite(a).all():
                raise _first_bad(n, a)
        bad = _np.flatnonzero(_np.abs(arrays[3][1]) > _np.pi / 2)
        if bad.size:  # (as invert; the fit refused it later as a bare PM_ERR_ARG)
            raise ArgumentError("app_dec: point %d is %r, beyond +-pi/2 (an apparent "
                                "declination or elevation)" % (bad[0], float(arrays[3][1][bad[0]])))
        # an apparent hour angle beyond a turn is a unit slip (hours, degrees);
        # the encoder angles are modular, as a file's (docs/formats.md:
        # controllers write 0..360 deg or count past a turn), and checked
        # against the pier side where it is given, below
        bad = _np.flatnonzero(_np.abs(arrays[2][1]) > 2 * _np.pi * (1 + 1e-12))
        if bad.size:
            raise ArgumentError("app_ha: point %d is %r, beyond +-2pi (an apparent hour angle or "
                                "azimuth, in radians: hours or degrees? np.radians converts "
                                "degrees)" % (bad[0], float(arrays[2][1][bad[0]])))
        extra = []
        if pier is not None:
            extra.append(("pier", _as_int("pier", pier, (-1, 0, 1))))
        if dir is not None:
            extra.append(("dir", _as_int("dir", dir, (-1, 0, 1))))
        for n, v in (("temp_c", temp_c), ("time_h", time_h)):
            if v is not None:
                a = _as_float(n, v)
                if _np.isinf(a).any():
                    raise _first_bad(n, _np.where(_np.isnan(a), 0.0, a))
                extra.append((n, a))
        names = []
        if aux is not None:
            if not isinstance(aux, dict):
                raise ArgumentError("aux: expected a dict {name: column}")
            if len(aux) > MAX_AUX:
                raise ArgumentError("aux: at most %d columns (PM_MAX_AUX)" % MAX_AUX)
            for k, v in aux.items():
                if not isinstance(k, str) or not k:
                    raise ArgumentError("aux: column names must be non-empty strings")
                a = _as_float("aux[%r]" % k, v)
                if _np.isinf(a).any():
                    raise _first_bad("aux[%r]" % k, _np.where(_np.isnan(a), 0.0, a))
                names.append(k)
                extra.append(("aux[%r]" % k, a))
        for n, a in arrays[1:]:  # (one per observation, not broadcast: a probe's 0-d
            if a.shape != arrays[0][1].shape:  # enc_dec was called shape (1,))
                raise ArgumentError("%s: shape %s, expected %s like enc_ha (the four positions "
                                    "are one per observation, not broadcast)" % (
                                        n, shapes[n], arrays[0][1].shape))
        for n, a in extra:
            if a.ndim > 1 or (a.ndim == 1 and a.shape != arrays[0][1].shape):
                raise ArgumentError("%s: shape %s, expected %s like enc_ha" % (
                    n, a.shape, arrays[0][1].shape))
        shape, flat = _broadcast(arrays + extra)
        cols = dict(zip([n for n, _ in arrays + extra], flat))
        if pier is not None and m == _MOUNTS["equatorial"]:
            _check_pier_convention(cols["enc_dec"], cols["pier"])
        aux_arr = (_np.ascontiguousarray(_np.stack([cols["aux[%r]" % k] for k in names], axis=1))
                   if names else None)
        lat = float("nan")
        if latitude is not None:
            la = _as_float("latitude", latitude)
            if la.shape != () or not abs(float(la)) <= _np.pi / 2:
                raise ArgumentError("latitude: expected radians within +-pi/2, got %r "
                                    "(degrees? np.radians converts)" % (latitude,))
            lat = float(la)
        data = _pm.run_from_arrays(
            cols["enc_ha"], cols["enc_dec"], cols["app_ha"], cols["app_dec"], m, lat,
            cols.get("pier"), cols.get("temp_c"), cols.get("time_h"), cols.get("dir"),
            aux_arr, names)
        return cls(data)

    def inputs(self):
        """The context inputs of the observations, as keyword arguments of
        Model.apply/invert/residual and FitResult.pointing_sigma; ``aux`` is
        a dict {column name: values}, which a model reads by the names of
        its inputs (Model.inputs), so a run whose columns come in another
        order than the fit's run is read right."""
        aux = {n: self.aux[n] for n in self.aux_names}
        return {"pier": self.pier, "temp_c": self.temp_c, "time_h": self.time_h,
                "dir": self.dir, "aux": aux}

    def fit(self, **kw):
        """fit_run(self, **kw)."""
        return fit_run(self, **kw)

    def explain(self, **kw):
        """explain(self, **kw)."""
        return explain(self, **kw)


def _check_pier_convention(enc_dec, pier):
    """One encoder convention per run, as pmfit's readers check it (docs/
    formats.md, "Beyond the pole"): the records of a side (pier 1: normal,
    -1: beyond the pole) all have their encoder dec, reduced into one turn,
    within +-pi/2 or all beyond, and not both sides beyond (an outside
    probe's encoder dec of 10 rad among 200 points of pier 1 was fitted as a
    50 deg outlier, sigma 18089", where pmfit refused the same file)."""
    ed = _np.remainder(_np.asarray(enc_dec, dtype=float) + _np.pi, 2 * _np.pi) - _np.pi
    beyond = _np.abs(ed) > _np.pi / 2
    # within 2 deg of the pole the encoder cannot show the side (an index
    # error moves a record across pi/2), as pmfit's readers
    clear = (_np.abs(_np.abs(ed) - _np.pi / 2) >= _np.radians(2.0)).reshape(-1)
    first_beyond = {}
    for side, word in ((1, "1 (normal side)"), (-1, "-1 (beyond the pole)")):
        idx = _np.flatnonzero((_np.asarray(pier).reshape(-1) == side) & clear)
        if not idx.size:
            continue
        b = beyond.reshape(-1)[idx]
        odd = _np.flatnonzero(b != b[0])
        if odd.size:
            i0, j = int(idx[0]), int(idx[odd[0]])
            raise ArgumentError(
                "enc_dec: point %d, pier %s, has its encoder dec %s (%r rad) but point %d of "
                "the same side %s (%r rad): mixed encoder conventions, or a value in degrees? "
                "expected one convention (beyond the pole: an encoder dec beyond +-pi/2 in one "
                "turn)" % (j, word, "beyond the pole" if b[odd[0]] else "within +-pi/2",
                           float(_np.asarray(enc_dec).reshape(-1)[j]), i0,
                           "beyond" if b[0] else "within +-pi/2",
                           float(_np.asarray(enc_dec).reshape(-1)[i0])))
        first_beyond[side] = bool(b[0])
    if first_beyond.get(1) and first_beyond.get(-1):
        raise ArgumentError("pier: the points of both sides have their encoder dec beyond the "
                            "pole: the pier does not follow the encoder (1: the normal side, "
                            "-1: beyond the pole)")


_WEATHER_RANGE = {"pressure_hpa": (400, 1100, "hPa"), "temp_c": (-60, 50, "deg C"),
                  "humidity": (0, 1, "(a fraction: 50% is 0.5)"),
                  "wavelength_um": (0.3, 25, "micrometres")}


def _weather(name, v):
    """A weather value of read_run: NaN for None (the file's), else a float
    in pmfit's range for it (--pressure 400..1100 hPa, --temperature -60..50
    C, --humidity 0..1, --wavelength 0.3..25 um), or ArgumentError naming the
    argument."""
    if v is None:
        return float("nan")
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise ArgumentError("%s: expected a number or None, got %r" % (name, v)) from None
    lo, hi, unit = _WEATHER_RANGE[name]
    if not (lo <= x <= hi):
        raise ArgumentError("%s: expected %g..%g %s or None, got %r" % (name, lo, hi, unit, v))
    return x


def read_run(path, refraction=True, skip_bad=False, format="auto", equinox=None,
             azimuth_count=False, pressure_hpa=None, temp_c=None, humidity=None,
             wavelength_um=None):
    """Read a pointing run file: four-column, named-column, TPOINT, RTS2
    gpoint, MountWizzard4 JSON, N.I.N.A./ASCOM CSV or MMT log
    (docs/formats.md), detected from its content.

    ``format``: "auto" (detect), or one of "four-column", "named", "tpoint",
    "rts2", "mw4", "csv", "mmt" (pmfit --format).  ``equinox``: None (as the
    file says), "J2000" or "JNow" (pmfit --equinox; CSV logs and RTS2 files).

    ``refraction``: apply refraction in the TPOINT equatorial reduction
    (pmfit's default; False is --no-refraction).  ``skip_bad``: skip
    malformed records, each listed in ``run.skipped`` (--skip-bad); otherwise
    the first one raises FormatError("path:LINE: ...").  ``azimuth_count``:
    an alt-az file's azimuth is the mount's count even within 0..360 deg, the
    slew direction its change (pmfit --azimuth-count).

    ``pressure_hpa``, ``temp_c``, ``humidity`` (0..1, or percent),
    ``wavelength_um``: the weather of the refraction where a reduction
    refracts (TPOINT equatorial files, J2000 places of RTS2 and CSV files),
    in place of the file's or the defaults (pmfit --pressure, --temperature,
    --humidity, --wavelength); None takes the file's.  Given for a run that
    no reduction refracts, a warning in ``run.warnings`` says they were not
    used."""
    weather = [_weather("pressure_hpa", pressure_hpa), _weather("temp_c", temp_c),
               _weather("humidity", humidity), _weather("wavelength_um", wavelength_um)]
    return Run(_pm.read_run(_path(path), bool(refraction), bool(skip_bad), str(format),
                            "" if equinox is None else str(equinox), bool(azimuth_count),
                            weather))


def _run(run):
    if isinstance(run, Run):
        return run
    return read_run(run)

# ---------------------------------------------------------------------------
# Fits


class FitResult:
    """A fitted model and its statistics (one Gauss-Newton fit, as pmfit fit).

    ``model`` (Model), ``names``, ``coefficients`` and ``errors`` (1-sigma;
    radians), ``covariance`` (P x P, rad^2), ``correlation``, ``sigma`` (the
    unbiased residual per axis, sqrt(chi2/(2N-P)), radians), ``chi2``,
    ``rms`` (on the sky), ``n_obs``, ``n_params``, ``iterations``,
    ``residuals`` (observed minus model, shape (N, 2), radians), ``index``
    (the observations fitted, into the run), ``lines`` (their file lines),
    ``max_correlation`` (the most correlated pair of terms), ``f_test`` (the
    pier-side F-test of a joint fit with side-specific terms, or None),
    ``error_map`` (pmfit fit --json's: the predicted error over the sky) and
    ``undetermined`` (pmfit's warning where the stars do not determine the
    model between them, else ""; fit_run also issues it as a
    PointingWarning)."""

    def __init__(self, c, f_test=None):
        self._c = c
        self.model = Model._wrap(c.model)
        for k in ("names", "coefficients", "errors", "covariance", "residuals", "index",
                  "lines", "sigma", "chi2", "rms", "n_obs", "n_params", "iterations",
                  "converged", "title", "max_correlation", "undetermined"):
            v = getattr(c, k)
            if isinstance(v, _np.ndarray):
                v.setflags(write=False)
            setattr(self, k, v)
        self.f_test = f_test
        self.error_map = _json.loads("{%s}" % c._error_map)["error_map"] if c._error_map else None

    @property
    def correlation(self):
        d = _np.sqrt(_np.diag(self.covariance))
        return self.covariance / _np.outer(d, d)

    def __repr__(self):
        return "<pm.FitResult %s: N = %d, P = %d, sigma = %.3f arcsec>" % (
            self.title, self.n_obs, self.n_params, self.sigma * RAD2ARCSEC)

    def pointing_sigma(self, enc_ha, enc_dec, *, full=False, pier=None, temp_c=None,
                       time_h=None, dir=None, aux=None, threads=None):
        """How well the model knows the pointing at encoder positions
        (pm_fit_pointing_sigma): 1-sigma per axis, radians; with ``full=True``
        also (v11, v12, v22) in rad^2, shape (..., 3)."""
        shape, (h, d), kw = _points(self.model, [("enc_ha", enc_ha), ("enc_dec", enc_dec)],
                                    pier, temp_c, time_h, dir, aux)
        s, c = self._c._pointing_sigma(h, d, *_ctx_args(kw, threads))
        if shape == ():
            return (float(s[0]), tuple(c[0])) if full else float(s[0])
        return (s.reshape(shape), c.reshape(shape + (3,))) if full else s.reshape(shape)

    def to_dict(self):
        """The fit as plain Python values (the keys of pmfit fit --json, in
        full precision)."""
        d = {"n_obs": self.n_obs, "n_params": self.n_params, "order": self.model.order,
             "sigma_arcsec": self.sigma * RAD2ARCSEC, "rms_arcsec": self.rms * RAD2ARCSEC,
             "iterations": self.iterations,
             "terms": [{"name": n, "value_arcsec": v * RAD2ARCSEC, "error_arcsec": e * RAD2ARCSEC}
                       for n, v, e in zip(self.names, self.coefficients, self.errors)]}
        if self.max_correlation is not None:
            a, b, r = self.max_correlation
            d["max_correlation"] = {"terms": [a, b], "value": r}
        if self.f_test is not None:
            d["pier_f_test"] = dict(self.f_test)
        if self.error_map is not None:
            d["error_map"] = dict(self.error_map)
        return d


class SplitFit:
    """A fit of each pier side on its own (pmfit fit --pier split): ``east``
    and ``west`` (FitResult), ``f_test`` (split vs joint, or None)."""

    def __init__(self, east, west, f_test):
        self.east, self.west, self.f_test = east, west, f_test

    def __iter__(self):
        return iter((self.east, self.west))

    def __repr__(self):
        return "<pm.SplitFit east %r, west %r>" % (self.east, self.west)


def fit_run(run, *, order=1, add=(), split=False, max_iter=2000):
    """Fit a run (a Run, or a file name read with the defaults) as
    ``pmfit fit RUN --order L [--add EFFECT ...] [--pier split]`` does:
    the same model, the same coefficients to the last bit.

    ``add``: physical terms in pmfit's --add syntax (a string or a list):
    "ha_periodic:G[:H]", "dec_periodic:G[:H]", "ha_periodic_paper:G",
    "refraction", "tube_flexure", "temperature[:B,..]", "time_drift[:B,..]",
    "hysteresis[:B,..]", "aux:NAME[:B,..]", and "TERM@E"/"TERM@W" for one
    pier side (docs/model.md).  ``split=True``: each pier side on its own
    (a SplitFit).  Returns a FitResult; raises FitError with the library's
    reason when the fit fails."""
    r = _run(run)
    if not isinstance(max_iter, (int, _np.integer)) or isinstance(max_iter, bool):
        raise ArgumentError("max_iter: expected an integer")
    fits, f_test = _pm.fit_run(r._data, _order(order), _adds(add), bool(split), int(max_iter))
    for c in fits:
        if c.undetermined:
            _warnings.warn("%s: %s" % (c.title, c.undetermined), PointingWarning, stacklevel=2)
    if split:
        return SplitFit(FitResult(fits[0]), FitResult(fits[1]), f_test)
    return FitResult(fits[0], f_test)


def fit(enc_ha, enc_dec, app_ha, app_dec, *, order=1, add=(), split=False, mount="equatorial",
        latitude=None, pier=None, temp_c=None, time_h=None, dir=None, aux=None, max_iter=2000):
    """Fit a model to observations held in arrays (radians): encoder and
    observed (apparent) positions, with optional inputs of the physical
    terms (see Run.from_arrays).  The same as fit_run(Run.from_arrays(...))."""
    r = Run.from_arrays(enc_ha, enc_dec, app_ha, app_dec, mount=mount, latitude=latitude,
                        pier=pier, temp_c=temp_c, time_h=time_h, dir=dir, aux=aux)
    return fit_run(r, order=order, add=add, split=split, max_iter=max_iter)

# ---------------------------------------------------------------------------
# Explain


def explain(run, *, order=None, add=(), alpha=0.01, gears=(), gears_ha=(), gears_dec=(),
            pairs=True, folds=0, compose=True):
    """What did the model leave out? ``pmfit explain RUN --json`` as a dict
    (keys in docs/formats.md, "pmfit explain --json"; docs/explain.md for
    the method): the baseline, its physical reading, where the residuals are
    too large, the findings with their sizes and false-alarm probabilities,
    and the final model.  ``gears``: known gear periods (cycles per
    revolution) of both axes (--gear G), ``gears_ha``/``gears_dec`` of one;
    ``compose=False``: the baseline read to first order (--no-compose);
    ``folds``: 0 cross-validates leave-one-out (from each fit itself), k >= 2
    k-fold (k more fits each).  ``order``: None (pmfit's default) explains at
    order 1, or at order 0 where the run has fewer points than the order-1
    baseline's terms and order 0 predicts them better; ``order_note`` says
    so (None otherwise)."""
    r = _run(run)

    def g(name, v):
        a = _np.atleast_1d(_as_float(name, v)).reshape(-1)
        return [float(x) for x in a]
    gh = g("gears", gears) + g("gears_ha", gears_ha)
    gd = g("gears", gears) + g("gears_dec", gears_dec)
    if not isinstance(folds, (int, _np.integer)) or isinstance(folds, bool):
        raise ArgumentError("folds: expected an integer")
    if order is not None and _order(order) < 0:
        raise ArgumentError("order: expected an integer 0..%d or None, got %r" % (MAX_L, order))
    text = _pm.explain_run(r._data, -1 if order is None else _order(order), _adds(add),
                           float(alpha), gh, gd,
                           bool(pairs), int(folds), bool(compose))
    return _json.loads(text)


def _opt_float(name, v):
    """None -> NaN (the C++ side's 'not given'), else a finite float."""
    if v is None:
        return float("nan")
    f = _as_float(name, v)
    if f.shape != () or not _np.isfinite(f):
        raise ArgumentError("%s: expected a finite number, got %r" % (name, v))
    return float(f)


def _opt_path(name, v):
    return "" if v is None else _path(v, name)


def plan(run=None, *, latitude=None, mount=None, order=1, add=(), next=5, min_el=15.0,
         grid=6.0, fork=False, noise=None, criterion="I", sides="run", meridian_limit=15.0,
         slew=None, settle=5.0, point_time=30.0, flip_time=60.0, horizon=None, catalogue=None,
         lst=None, utc=None, lon=None, max_el=None):
    """Which star next? ``pmfit plan [RUN] --json`` as a dict (keys in
    docs/formats.md, "pmfit plan --json"; the method in docs/model.md,
    "Which star next"): the ``next`` targets that most reduce the model's
    predicted pointing error averaged over the sky above ``min_el``
    (degrees) and the ``horizon`` file and below ``max_el`` (default: alt-az
    85, the zenith keyhole; equatorial 90), given the points of ``run`` taken so
    far (a Run or a path; None: the first points of a run).

    ``latitude`` (degrees; default the run's), ``mount`` ("equatorial" or
    "altaz"; default the run's, else equatorial), ``order``/``add`` the model
    planned for, ``noise`` (arcsec per axis; default the run's own sigma, 1
    without a run), ``grid`` (candidate spacing, degrees) or ``catalogue`` (a
    star file, placed at ``lst`` hours or at ``utc`` "YYYY-MM-DDTHH:MM" with
    ``lon`` degrees east), ``fork`` (an equatorial mount that does not flip),
    ``sides``/``meridian_limit`` (German mounts: "run", "meridian" or
    "both"), ``criterion`` ("I": mean predicted error, "D": determinant),
    ``slew`` (deg/s: weight by slew time, with ``settle``, ``point_time``
    and ``flip_time`` in seconds).  Errors: ArgumentError for a bad keyword,
    FileError/FormatError for the files (with their file:line)."""
    r = None if run is None else _run(run)
    if mount is not None and mount not in ("equatorial", "altaz"):
        raise ArgumentError("mount: expected 'equatorial' or 'altaz', got %r" % (mount,))
    if isinstance(next, bool) or not isinstance(next, (int, _np.integer)):
        raise ArgumentError("next: expected an integer count, got %r" % (next,))
    for name, v in (("criterion", criterion), ("sides", sides)):
        if not isinstance(v, str):
            raise ArgumentError("%s: expected a string, got %r" % (name, v))
    if utc is not None and not isinstance(utc, str):
        raise ArgumentError("utc: expected 'YYYY-MM-DDTHH:MM[:SS]', got %r" % (utc,))
    text = _pm.plan_run(None if r is None else r._data, "" if mount is None else mount,
                        _opt_float("latitude", latitude), _order(order), _adds(add), int(next),
                        _opt_float("min_el", min_el), _opt_float("grid", grid), bool(fork),
                        _opt_float("noise", noise), criterion, sides,
                        _opt_float("meridian_limit", meridian_limit), _opt_float("slew", slew),
                        _opt_float("settle", settle), _opt_float("point_time", point_time),
                        _opt_float("flip_time", flip_time), _opt_path("horizon", horizon),
                        _opt_path("catalogue", catalogue), _opt_float("lst", lst),
                        "" if utc is None else utc, _opt_float("lon", lon),
                        _opt_float("max_el", max_el))
    return _json.loads(text)


def compare(old, run, *, order=None, add=()):
    """What changed since last night?  ``pmfit compare OLD RUN --json`` as a
    dict (keys in docs/formats.md, "pmfit compare --json"; docs/model.md,
    "What changed"): ``old`` is a Model, a Run (fitted at ``order``, default
    1, with ``add``, so that its errors count), or a path to a model file or
    a run file; ``run`` (a Run or a path) is the new night.  ``order`` and
    ``add`` with a model (its own terms are compared) raise ArgumentError."""
    r = _run(run)
    o = -1 if order is None else _order(order)
    if order is not None and not 0 <= o <= MAX_L:
        raise ArgumentError("order: expected an integer 0..%d, got %r" % (MAX_L, order))
    if isinstance(old, Model):
        text = _pm.compare_run(old, None, "", r._data, o, _adds(add))
    elif isinstance(old, Run):
        text = _pm.compare_run(None, old._data, "", r._data, o, _adds(add))
    else:
        text = _pm.compare_run(None, None, _path(old, "old"), r._data, o, _adds(add))
    return _json.loads(text)


def inject(run, effects, *, phase=0.0, seed=1):
    """A known effect added to a real recording (``pmfit simulate --inject
    EFFECT --into RUN``, docs/explain.md "Real recordings with injected
    effects"): returns ``(new_run, info)``, the run (a Run or a path) with
    the effects added to its observed positions in the frame of its own
    baseline fit (noise and everything else unchanged), and a dict:
    ``order`` and ``sigma_arcsec`` of that baseline, ``injected`` (per
    effect: ``effect``, ``size_arcsec``, ``rms_arcsec`` per axis on the sky,
    ``moved_lines`` for outliers).

    ``effects``: one or a list of pmfit's --inject specs: ``"EFFECT"`` (one
    sigma), ``"EFFECT=SIZE"`` (arcsec) or ``"EFFECT:SIZEsigma"`` /
    ``"EFFECT:SIZEas"``; EFFECT is any --add effect, ``outlier[:N]`` or
    ``higher_order``.  ``phase`` (degrees) for periodic effects, ``seed`` for
    outliers and higher_order."""
    r = _run(run)
    specs = [effects] if isinstance(effects, str) else list(effects)
    for e in specs:
        if not isinstance(e, str):
            raise ArgumentError("effects: expected --inject specs (strings), got %r" % (e,))
    if isinstance(seed, bool) or not isinstance(seed, (int, _np.integer)) or seed < 0:
        raise ArgumentError("seed: expected an integer >= 0, got %r" % (seed,))
    data, info = _pm.inject_run(r._data, specs, _opt_float("phase", phase), int(seed))
    return Run(data), info


def simulate(truth, *, n=200, seed=1, latitude=47.0, el_limit=15.0, noise=1.0, fork=False,
             effects=(), phase=0.0):
    """A simulated pointing run (``pmfit simulate OUT``): ``truth`` (a Model:
    its mount, order and coefficients; its latitude is set to ``latitude``)
    observed at ``n`` targets above ``el_limit`` degrees in a nearest-
    neighbour sequence, a German mount flipping west of the meridian (or a
    fork, ``fork=True``), Gaussian ``noise`` (arcsec per axis).  ``effects``:
    physical effects added to the truth, each ``"EFFECT=SIZE"`` or
    ``(EFFECT, SIZE)`` with EFFECT any --add effect, ``outlier[:N]`` or
    ``higher_order`` and SIZE in arcsec (pmfit simulate --effect); ``phase``
    (degrees) for periodic ones.  Returns a Run, as read from the file pmfit
    would write."""
    if not isinstance(truth, Model):
        raise ArgumentError("truth: expected a pm.Model, got %r" % (truth,))
    for name, v, lo in (("n", n, 1), ("seed", seed, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, _np.integer)) or v < lo:
            raise ArgumentError("%s: expected an integer >= %d, got %r" % (name, lo, v))
    effs = []
    for e in ([effects] if isinstance(effects, str) else effects):
        if isinstance(e, str):
            name, sep, size = e.rpartition("=")
            try:
                effs.append((name, float(size)) if sep else None)
            except ValueError:
                effs.append(None)
            if effs[-1] is None:
                raise ArgumentError("effects: expected EFFECT=SIZE (arcsec), got %r" % (e,))
        else:
            try:
                name, size = e
                effs.append((str(name), _opt_float("effects", size)))
            except (TypeError, ValueError):
                raise ArgumentError("effects: expected EFFECT=SIZE or (EFFECT, SIZE), got %r"
                                    % (e,)) from None
    data = _pm.simulate_run(truth, int(n), int(seed), _opt_float("latitude", latitude),
                            _opt_float("el_limit", el_limit), _opt_float("noise", noise),
                            bool(fork), effs, _opt_float("phase", phase))
    return Run(data)
