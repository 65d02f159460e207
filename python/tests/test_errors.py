"""Bad input fails cleanly: a named pm.Error subclass carrying the library's
message (file:line for files), nothing crashes, nothing already computed or
held is changed."""
import glob
import os

import numpy as np
import pytest

import pm
from conftest import PMFIT, TOP, run_cmd

BAD_RUNS = sorted(glob.glob(os.path.join(TOP, "tests", "data", "bad_*.dat")) +
                  glob.glob(os.path.join(TOP, "tests", "data", "bad_*.csv")) +
                  glob.glob(os.path.join(TOP, "tests", "data", "bad_*.json")))


def test_exception_classes():
    assert issubclass(pm.FileError, pm.Error) and issubclass(pm.FileError, OSError)
    assert issubclass(pm.FormatError, pm.Error) and issubclass(pm.FormatError, ValueError)
    assert issubclass(pm.ArgumentError, ValueError)
    assert issubclass(pm.NonFiniteError, pm.ArgumentError)
    assert issubclass(pm.FitError, pm.Error)


@pytest.mark.parametrize("path", BAD_RUNS, ids=os.path.basename)
def test_bad_run_file_is_format_error_with_pmfit_message(path):
    """Every malformed run of tests/data: FormatError, the message pmfit
    prints for the same file ("path:LINE: what, expected what")."""
    with pytest.raises(pm.FormatError) as e:
        pm.read_run(path)
    p = run_cmd(PMFIT, "fit", path, check=False)
    assert p.returncode == 1
    assert p.stderr.strip() == "pmfit: " + str(e.value)
    assert str(e.value).startswith(path + ":")
    assert e.value.status == -3  # PMRUN_ERR_FORMAT


def test_forced_format_and_equinox():
    """format= and equinox= are pmfit's --format and --equinox: the same
    run, the same message when the forced reader fails, a clear error for
    an unknown name."""
    d = os.path.join(TOP, "tests", "data")
    mw4 = os.path.join(d, "mw4_model.json")
    auto, forced = pm.read_run(mw4), pm.read_run(mw4, format="mw4")
    assert auto.format == forced.format
    for col in ("enc_ha", "enc_dec", "app_ha", "app_dec"):
        assert np.array_equal(getattr(auto, col), getattr(forced, col))
    csv = os.path.join(d, "nina_j2000.csv")
    with pytest.raises(pm.FormatError) as e:
        pm.read_run(csv, format="mw4")
    p = run_cmd(PMFIT, "fit", csv, "--format", "mw4", check=False)
    assert p.returncode == 1 and p.stderr.strip().endswith(str(e.value))
    assert "read as a MountWizzard4 model file" in str(e.value)
    with pytest.raises(pm.ArgumentError):
        pm.read_run(mw4, format="lx200")
    with pytest.raises(pm.ArgumentError):
        pm.read_run(csv, equinox="B1950")
    assert len(pm.read_run(csv, equinox="J2000")) > 0


def test_weather_options(tmp_path):
    """pressure_hpa=, temp_c=, humidity=, wavelength_um= are pmfit's
    --pressure, --temperature, --humidity, --wavelength: given for a CSV log
    without its weather metadata, the places are the file's with it, bit
    for bit; a wrong weather moves them by the refraction's change; bad
    values are ArgumentErrors; unused ones are said so."""
    csv = os.path.join(TOP, "tests", "data", "nina_j2000.csv")
    bare = tmp_path / "bare.csv"
    with open(csv) as f:
        bare.write_text("".join(l for l in f
                                if not l.startswith(("# pressure", "# temperature"))))
    ref = pm.read_run(csv)
    given = pm.read_run(str(bare), pressure_hpa=950, temp_c=10.0)
    default = pm.read_run(str(bare))
    wrong = pm.read_run(csv, pressure_hpa=700, temp_c=-10)
    assert np.array_equal(ref.app_dec, given.app_dec) and np.array_equal(ref.app_ha, given.app_ha)
    assert given.site["pressure_hpa"] == 950
    assert not np.array_equal(ref.app_dec, default.app_dec)
    # the refraction at these elevations is tens of arcseconds: a quarter of
    # it less moves the observed places by arcseconds
    moved = np.degrees(np.abs(wrong.app_dec - ref.app_dec)).max() * 3600
    assert 1 < moved < 60, moved
    for kw in ({"pressure_hpa": "high"}, {"temp_c": float("nan")}, {"humidity": [1]},
               {"wavelength_um": float("inf")}, {"pressure_hpa": 29.9}, {"pressure_hpa": 5000},
               {"humidity": 50}, {"temp_c": 80}, {"wavelength_um": 0.1}):
        with pytest.raises(pm.ArgumentError):
            pm.read_run(csv, **kw)
    with pytest.raises(pm.ArgumentError) as e:
        pm.read_run(csv, humidity=1.5)
    assert "humidity: expected 0..1 (a fraction: 50% is 0.5)" in str(e.value)
    rts2 = os.path.join(TOP, "tests", "data", "rts2_gpoint.dat")
    assert [w for w in pm.read_run(rts2, pressure_hpa=900).warnings if "not used" in w]
    assert not [w for w in pm.read_run(rts2).warnings if "not used" in w]


def test_missing_and_unreadable_files(tmp_path):
    with pytest.raises(pm.FileError) as e:
        pm.read_run(tmp_path / "nothing.dat")
    assert isinstance(e.value, OSError)
    assert str(e.value) == "%s: cannot open: No such file or directory" % (tmp_path / "nothing.dat")
    with pytest.raises(pm.FileError):
        pm.read_run(tmp_path)  # a directory
    with pytest.raises(pm.FileError):
        pm.load_model(tmp_path / "nothing.pm")
    with pytest.raises(pm.FileError):
        pm.fit_run(tmp_path / "nothing.dat")
    with pytest.raises(pm.ArgumentError):
        pm.read_run(3.5)


BAD_MODELS = {
    "nan": ("pm-model 2\nmount equatorial\norder 0\nterms 6\nterm a 1 0 0 nan\n", 5),
    "version": ("pm-model 9\nmount equatorial\n", 1),
    "mount": ("pm-model 2\nmount fork\n", 2),
    "order": ("pm-model 2\nmount equatorial\norder 9\n", 3),
    "no_end": ("pm-model 2\nmount equatorial\norder 0\nterms 6\n" +
               "".join("term %s %d 0 0 0\n" % (n, k + 1)
                       for k, n in enumerate(["a", "b", "c'", "d", "e'", "i"])), 10),
    "binary": ("pm-model 2\n\x00\x01\x02\n", 2),
}


@pytest.mark.parametrize("kind", sorted(BAD_MODELS))
def test_bad_model_file_is_format_error_with_line(kind, tmp_path, sim_dir):
    text, line = BAD_MODELS[kind]
    f = tmp_path / ("bad_%s.pm" % kind)
    f.write_text(text)
    with pytest.raises(pm.FormatError) as e:
        pm.load_model(f)
    msg = str(e.value)
    assert msg.startswith("%s:" % f), msg
    # the same message pmfit eval gives (the library's)
    p = run_cmd(PMFIT, "eval", f, os.path.join(TOP, "examples", "sim_gem.dat"), check=False)
    assert p.returncode == 1 and p.stderr.strip() == "pmfit: " + msg
    if kind != "no_end":
        assert msg.startswith("%s:%d:" % (f, line)), msg


def test_save_failure_leaves_nothing(tmp_path):
    m = pm.Model(order=1)
    with pytest.raises(pm.FileError) as e:
        m.save(tmp_path / "no" / "such" / "dir.pm")
    assert "cannot write" in str(e.value)
    with pytest.raises(pm.FileError):
        m.save(tmp_path)  # a directory
    assert os.listdir(tmp_path) == []


def test_arrays_shape_and_type_errors():
    m = pm.Model(order=1)
    with pytest.raises(pm.ArgumentError, match="shapes do not match"):
        m.apply([0.1, 0.2], [0.1, 0.2, 0.3])
    with pytest.raises(pm.ArgumentError, match="expected numbers"):
        m.apply("north", 0.1)
    with pytest.raises(pm.ArgumentError):
        m.apply([1j], [0.1])
    with pytest.raises(pm.ArgumentError, match="side"):
        m.invert(0.1, 0.2, side=2)
    with pytest.raises(pm.ArgumentError, match="side"):
        m.invert([0.1, 0.2], [0.2, 0.3], side=[0, 1, 1])
    with pytest.raises(pm.ArgumentError, match="both start_ha and start_dec"):
        m.invert(0.1, 0.2, start_ha=0.1)
    with pytest.raises(pm.ArgumentError, match="beyond"):
        m.invert([0.1, 0.2], [0.2, 1.6])
    with pytest.raises(pm.ArgumentError, match="mount"):
        pm.Model(mount="fork")
    with pytest.raises(pm.ArgumentError, match="PM_MAX_L"):
        pm.Model(order=pm.MAX_L + 1)
    with pytest.raises(pm.ArgumentError):
        pm.Model(order=1.5)
    with pytest.raises(pm.ArgumentError, match="like enc_ha"):
        pm.fit(np.zeros(10), np.zeros(9), np.zeros(10), np.zeros(10))
    with pytest.raises(pm.ArgumentError, match="1-D"):
        pm.fit(np.zeros((5, 2)), np.zeros((5, 2)), np.zeros((5, 2)), np.zeros((5, 2)))
    with pytest.raises(pm.ArgumentError, match="pier"):
        pm.fit(np.zeros(10), np.zeros(10), np.zeros(10), np.zeros(10), pier=np.full(10, 2))


def test_non_finite_inputs_are_named():
    m = pm.Model(order=1)
    ha = np.linspace(-1, 1, 12).reshape(3, 4)
    dec = np.full((3, 4), 0.3)
    dec[1, 2] = np.nan
    with pytest.raises(pm.NonFiniteError, match=r"enc_dec\[1, 2\] is nan"):
        m.apply(ha, dec)
    with pytest.raises(pm.NonFiniteError, match=r"app_ha\[0\] is inf"):
        m.invert([np.inf], [0.1])
    with pytest.raises(pm.NonFiniteError, match=r"app_dec\[3\] is nan"):
        pm.fit(np.zeros(5), np.zeros(5), np.zeros(5), [0, 0, 0, np.nan, 0])
    with pytest.raises(pm.NonFiniteError):
        m.residual(0.1, 0.2, 0.1, -np.inf)


def test_angles_beyond_their_range_are_named():
    """Arrays are radians.  An apparent hour angle beyond +-2pi is a unit
    slip, named with its point.  Encoder angles are modular, as a file's
    (another probe's round trip of tests/data through enc_raw, 0..360 deg and
    counts past a turn), and with ``pier`` given they follow one convention
    as pmfit checks a file's: an outside probe's encoder dec of 10 rad among
    200 points of the normal side had been fitted as a 50 deg outlier, sigma
    18089", where pmfit refused the same file."""
    ha = np.linspace(-1.2, 1.2, 40)
    dec = np.linspace(-0.3, 1.3, 40)
    bad = dec.copy()
    bad[7] = 10.0
    with pytest.raises(pm.ArgumentError, match=r"enc_dec: point 7, pier 1 \(normal side\), has its "
                                               r"encoder dec beyond the pole"):
        pm.fit(ha, bad, ha, dec, order=0, pier=np.ones(40, int))
    with pytest.raises(pm.ArgumentError, match=r"both sides have their encoder dec beyond"):
        pm.fit(ha, np.pi - dec, ha, dec, order=0, pier=np.where(ha < 0, 1, -1))
    hours = np.linspace(-7.5, 7.5, 40)
    with pytest.raises(pm.ArgumentError, match=r"app_ha: point 0 is -7.5, beyond \+-2pi"):
        pm.fit(ha, dec, hours, dec, order=0)
    # modular: beyond the pole (pi - dec, its 0..2pi form), counts past a turn
    pm.Run.from_arrays(ha, np.pi - dec, ha + np.pi, dec, pier=-np.ones(40, int))
    pm.Run.from_arrays(ha + 2 * np.pi, 2 * np.pi + dec, ha, dec, pier=np.ones(40, int))
    pm.Run.from_arrays(ha + 4 * np.pi, dec + 2 * np.pi, ha, dec, mount="altaz")
    # every run of tests/data as its file wrote the encoder angles, pier as read
    d = os.path.join(TOP, "tests", "data")
    n = 0
    for name in sorted(os.listdir(d)):
        if name.startswith("bad_") or not name.endswith((".dat", ".csv", ".json")):
            continue
        try:
            r = pm.read_run(os.path.join(d, name))
        except pm.Error:
            continue
        pm.Run.from_arrays(r.enc_raw[:, 0], r.enc_raw[:, 1], r.app_ha, r.app_dec,
                           mount=r.mount, pier=r.pier)
        n += 1
    assert n > 50, n


def test_context_inputs_the_model_needs(sim_dir):
    r = pm.read_run(sim_dir / "eq.dat")
    m = pm.fit_run(r, add=["temperature", "hysteresis"]).model
    with pytest.raises(pm.ArgumentError, match="pass temp_c="):
        m.apply(r.enc_ha, r.enc_dec)
    with pytest.raises(pm.ArgumentError, match="pass dir="):
        m.apply(r.enc_ha, r.enc_dec, temp_c=r.temp_c)
    with pytest.raises(pm.ArgumentError, match="dir"):
        m.apply(0.1, 0.2, temp_c=3.0, dir=0.5)
    t = np.array(r.temp_c)
    t[7] = np.nan
    with pytest.raises(pm.NonFiniteError, match=r"temp_c\[7\]"):
        m.apply(r.enc_ha, r.enc_dec, temp_c=t, dir=r.dir)
    a = m.apply(r.enc_ha, r.enc_dec, temp_c=r.temp_c, dir=r.dir)  # and with them it works
    assert np.isfinite(a).all()


def test_fit_failures_name_the_reason():
    with pytest.raises(pm.FitError) as e:
        pm.fit([], [], [], [])
    assert e.value.status == -4 and "no observations" in str(e.value)
    z = np.linspace(0, 1, 5)
    with pytest.raises(pm.FitError) as e:
        pm.fit(z, z, z, z, order=1)
    assert e.value.status == -4  # PM_ERR_TOO_FEW
    assert "P = 22 terms need at least 12 observations" in str(e.value)
    one = np.full(40, 0.2)
    with pytest.raises(pm.FitError) as e:
        pm.fit(one, one, one + 1e-5, one)
    assert e.value.status == -5 and e.value.bad_term is not None  # PM_ERR_SINGULAR
    assert "term %s" % e.value.bad_term in str(e.value)
    rng = np.random.default_rng(1)
    ha, dec = rng.uniform(-3, 3, 80), rng.uniform(-1, 1.4, 80)
    with pytest.raises(pm.ArgumentError, match="unknown effect"):
        pm.fit(ha, dec, ha, dec, add="wobble")
    with pytest.raises(pm.ArgumentError, match="latitude"):
        pm.fit(ha, dec, ha, dec, add="refraction")
    with pytest.raises(pm.ArgumentError, match="degrees"):
        pm.fit(ha, dec, ha, dec, latitude=47.0)
    with pytest.raises(pm.ArgumentError, match="latitude"):
        pm.Model(latitude=np.nan)
    with pytest.raises(pm.ArgumentError, match="no value for the observation at line 1"):
        pm.fit(ha, dec, ha, dec, add="temperature")
    with pytest.raises(pm.ArgumentError, match="order"):
        pm.fit(ha, dec, ha, dec, order=-1)
    with pytest.raises(pm.ArgumentError, match="add"):
        pm.fit(ha, dec, ha, dec, add=[3])
    with pytest.raises(pm.FitError, match="no observations on the pier side west"):
        pm.fit(ha, np.clip(dec, -1, 1), ha, np.clip(dec, -1, 1), split=True)
    with pytest.raises(pm.ArgumentError, match="joint fit"):
        pm.fit(ha, dec, ha, dec, split=True, add="i@W")


def test_bad_coefficients_leave_the_model_unchanged():
    m = pm.Model(order=1)
    c = np.arange(m.n_terms) * 1e-6
    m.coefficients = c
    before = m.apply(0.3, 0.4)
    for bad, what in ((np.full(m.n_terms, np.nan), "PM_ERR_NONFINITE"),
                      (np.full(m.n_terms, 1e200), "coefficients"),
                      (np.ones(3), r"expected 22 numbers \(one per term\), got shape \(3,\)"),
                      ("x", "coefficients: expected numbers"), (None, "coefficients is None"),
                      (np.zeros(m.n_terms) + 1j, r"coefficients\[0\] is 1j: expected a real")):
        with pytest.raises(pm.ArgumentError, match=what):
            m.coefficients = bad
        assert (m.coefficients == c).all()
        assert m.apply(0.3, 0.4) == before


def test_model_coefficients_are_read_only():
    """Model.coefficients is a read-only copy, as FitResult.coefficients: an
    edit in place raises instead of being lost; a whole array assigned
    through the setter is taken (the model prepared again)."""
    m = pm.fit_run(os.path.join(TOP, "examples", "sim_gem.dat")).model
    before = m.apply(0.3, 0.4)
    with pytest.raises(ValueError, match="read-only"):
        m.coefficients[2] += 0.01
    assert not m.coefficients.flags.writeable
    assert m.apply(0.3, 0.4) == before
    c = m.coefficients.copy()
    c[2] += 0.01
    m.coefficients = c
    assert np.array_equal(m.coefficients, c)
    assert m.apply(0.3, 0.4) != before
    m.coefficients = list(c - 0.01 * (np.arange(m.n_terms) == 2))  # any sequence of numbers
    assert m.apply(0.3, 0.4) == before


def _real_inputs_cases(m, fit, run):
    """(label, call, name): call(x) passes x to one argument of each function
    that converts arrays; name is how the message names that argument."""
    ha, dec = np.linspace(-1, 1, 8), np.full(8, 0.4)
    return [
        ("apply", lambda x: m.apply(x, dec), "enc_ha"),
        ("apply, dec", lambda x: m.apply(ha, x), "enc_dec"),
        ("apply, pier", lambda x: m.apply(ha, dec, pier=x), "pier"),
        ("invert", lambda x: m.invert(x, dec), "app_ha"),
        ("invert, side", lambda x: m.invert(ha, dec, side=x), "side"),
        ("invert, start", lambda x: m.invert(ha, dec, start_ha=x, start_dec=dec), "start_ha"),
        ("residual", lambda x: m.residual(ha, dec, ha, x), "app_dec"),
        ("pointing_sigma", lambda x: fit.pointing_sigma(ha, x), "enc_dec"),
        ("Model", lambda x: pm.Model(latitude=x), "latitude"),
        ("coefficients", lambda x: setattr(m, "coefficients", x), "coefficients"),
        ("fit", lambda x: pm.fit(ha, dec, x, dec), "app_ha"),
        ("from_arrays, temp_c", lambda x: pm.Run.from_arrays(ha, dec, ha, dec, temp_c=x),
         "temp_c"),
        ("explain, gears", lambda x: pm.explain(run, gears=x), "gears"),
        ("plan, lst", lambda x: pm.plan(run, lst=x), "lst"),
    ]


@pytest.mark.filterwarnings("error")  # numpy's ComplexWarning would be one
def test_complex_inputs_are_argument_errors():
    """Complex numbers are never cut to their real part (numpy's cast, with
    only a ComplexWarning): ArgumentError naming the argument and the first
    element with an imaginary part, from every function that converts
    arrays."""
    m = pm.Model(order=1)
    run = pm.read_run(os.path.join(TOP, "examples", "sim_gem.dat"))
    fit = pm.fit_run(run)
    before = m.coefficients
    for label, call, name in _real_inputs_cases(m, fit, run):
        for x, where in ((np.array([0.3, 0.3 + 0.5j] + [0.3] * 6), r"\[1\] is \(0\.3\+0\.5j\)"),
                         (np.complex128(1j), r" is 1j"),
                         (np.array([0.1, 2j] + [0.1] * 6, dtype=object), r"\[1\] is 2j")):
            with pytest.raises(pm.ArgumentError, match=r"^%s%s: expected a real number" % (
                    name, where)):
                call(x)
    assert np.array_equal(m.coefficients, before)
    m.coefficients = np.zeros(m.n_terms, dtype=np.complex64).real  # .real: taken


def test_masked_arrays_are_argument_errors():
    """A numpy masked array with masked values is refused, naming the first
    masked element: np.asarray would pass the data under the mask on, and
    the points would be fitted as good (an outside probe: five masked points
    2000" off took sigma from 2.19" to 171").  With nothing masked it is
    its data, the same result as the plain array."""
    m = pm.Model(order=1)
    run = pm.read_run(os.path.join(TOP, "examples", "sim_gem.dat"))
    fit = pm.fit_run(run)
    before = m.coefficients
    for label, call, name in _real_inputs_cases(m, fit, run):
        x = np.ma.array([0.3] * 8, mask=[0, 0, 1, 0, 1, 0, 0, 0])
        with pytest.raises(pm.ArgumentError, match=r"^%s\[2\] is masked \(2 of 8 values\)" % name):
            call(x)
    assert np.array_equal(m.coefficients, before)
    a = run.app_ha.copy()
    a[:5] += 0.01
    ma = np.ma.array(a, mask=np.r_[np.ones(5, bool), np.zeros(a.size - 5, bool)])
    with pytest.raises(pm.ArgumentError, match=r"^app_ha\[0\] is masked \(5 of 300 values\)"):
        pm.fit(run.enc_ha, run.enc_dec, ma, run.app_dec, order=1, latitude=run.latitude)
    plain = pm.fit(run.enc_ha, run.enc_dec, run.app_ha, run.app_dec, order=1,
                   latitude=run.latitude)
    unmasked = pm.fit(run.enc_ha, run.enc_dec, np.ma.array(run.app_ha), run.app_dec, order=1,
                      latitude=run.latitude)
    assert np.array_equal(plain.model.coefficients, unmasked.model.coefficients)
    ha = np.ma.array([0.1, 0.2], mask=[0, 1])
    with pytest.raises(pm.ArgumentError, match=r"^enc_ha\[1\] is masked"):
        m.apply(ha, 0.2)
    # astropy's Masked (its own mask; np.asarray takes the data under it)
    masked = pytest.importorskip("astropy.utils.masked")
    x = masked.Masked(run.app_ha.copy(), mask=np.r_[np.ones(5, bool), np.zeros(a.size - 5, bool)])
    with pytest.raises(pm.ArgumentError, match=r"^app_ha\[0\] is masked \(5 of 300 values\)"):
        pm.fit(run.enc_ha, run.enc_dec, x, run.app_dec, order=1, latitude=run.latitude)
    clean = pm.fit(run.enc_ha, run.enc_dec, masked.Masked(run.app_ha), run.app_dec, order=1,
                   latitude=run.latitude)
    assert np.array_equal(plain.model.coefficients, clean.model.coefficients)


def test_threads_checked_on_every_way():
    """threads=0 or -1 is refused for one point as for many (the one-point
    way had taken it)."""
    m = pm.Model(order=1)
    for t in (0, -1, True, 1.5, 10**12):
        for h in (0.1, np.array([0.1, 0.2])):
            with pytest.raises(pm.ArgumentError, match=r"^threads: expected a positive integer"):
                m.apply(h, 0.2, threads=t)
    assert m.apply(0.1, 0.2, threads=1) == m.apply(0.1, 0.2)


@pytest.mark.filterwarnings("error")
def test_none_inputs_are_not_numbers():
    """None, or None in an object array, is not a number (numpy would read
    it as NaN): ArgumentError saying so, not NonFiniteError "is nan"."""
    m = pm.Model(order=1)
    run = pm.read_run(os.path.join(TOP, "examples", "sim_gem.dat"))
    fit = pm.fit_run(run)
    for label, call, name in _real_inputs_cases(m, fit, run):
        for x, where in ((np.array([0.1, None] + [0.1] * 6, dtype=object), r"\[1\]"),
                         ([0.1, None] + [0.1] * 6, r"\[1\]")):
            with pytest.raises(pm.ArgumentError, match=r"^%s%s is None: not a number$" % (
                    name, where)) as e:
                call(x)
            assert type(e.value) is pm.ArgumentError, label
    with pytest.raises(pm.ArgumentError, match=r"^enc_ha is None: not a number$") as e:
        m.apply(None, 0.2)
    assert type(e.value) is pm.ArgumentError
    with pytest.raises(pm.ArgumentError, match=r"^coefficients is None: not a number$"):
        m.coefficients = None


def test_explain_errors(tmp_path):
    run = os.path.join(TOP, "examples", "sim_gem.dat")
    with pytest.raises(pm.FileError):
        pm.explain(tmp_path / "none.dat")
    with pytest.raises(pm.ArgumentError, match="alpha"):
        pm.explain(run, alpha=2)
    with pytest.raises(pm.ArgumentError, match="gear"):
        pm.explain(run, gears=[-1])
    with pytest.raises(pm.ArgumentError, match="folds"):
        pm.explain(run, folds=1)
    with pytest.raises(pm.ArgumentError, match="unknown effect"):
        pm.explain(run, add="wobble")


@pytest.mark.filterwarnings("ignore::pm.PointingWarning")
def test_nasty_values_do_not_crash():
    """Extreme but finite inputs: a result or a pm.Error, never a crash."""
    m = pm.Model(order=2)
    m.coefficients = np.full(m.n_terms, 1e-3)
    for ha, dec in ((1e300, 0.1), (0.1, 1e300), (-1e308, 1e-320), (5e-324, -5e-324),
                    (np.pi / 2, np.pi / 2), (0.0, -np.pi / 2)):
        try:
            a, b = m.apply(ha, dec)
            assert np.isfinite(a) and np.isfinite(b)
        except pm.Error:
            pass
        try:
            m.invert(0.1, np.clip(dec, -np.pi / 2, np.pi / 2), start_ha=ha % 7, start_dec=0.0)
        except pm.Error:
            pass
    with pytest.raises(pm.ArgumentError, match="PM_START_MAX"):
        m.invert(0.1, 0.2, start_ha=1e300, start_dec=0.0)
    big = pm.Model(order=1)
    big.coefficients = np.full(big.n_terms, 1e150)
    try:
        assert np.isfinite(big.apply(0.3, 0.4)).all()
    except pm.Error:
        pass
    m.apply(np.zeros(0), np.zeros(0))
    assert m.apply(np.zeros((0, 3)), 0.1)[0].shape == (0, 3)


def test_add_term_fields_are_checked():
    """Model.add_term took int(k) and float(param): k=1.5 added a term on
    base vector 1 without a word, param=1j raised a bare TypeError.  Each
    field is now one real number of its kind, named when it is not; the model
    is unchanged."""
    m = pm.Model()
    n = m.n_terms
    for kw, exc, words in [
            (dict(k=1.5), pm.ArgumentError, "k: expected integers"),
            (dict(k=None), pm.ArgumentError, "k is None"),
            (dict(k=[1, 2]), pm.ArgumentError, "k: expected one number"),
            (dict(param=1j), pm.ArgumentError, "param is 1j"),
            (dict(value="x"), pm.ArgumentError, "value: expected numbers"),
            (dict(param=float("nan")), pm.NonFiniteError, "param is nan"),
            (dict(value=float("inf")), pm.NonFiniteError, "value is inf")]:
        with pytest.raises(exc, match=words):
            m.add_term(4, **dict(dict(k=3, aux=3), **kw))
        assert m.n_terms == n
    assert m.add_term(4, k=np.int64(3), aux=3, param=np.float32(2.0), value=1e-6) == n
    assert m.terms[n]["k"] == 3 and m.terms[n]["param"] == 2.0


def test_inputs_the_c_calls_would_misread(tmp_path):
    """What the C side would read as something else is refused, named:
    a NUL in a path, a comment or a prefix (the C string ends there: the
    comment was cut, the path another file); an apparent declination beyond
    +-pi/2 in Run.from_arrays (the fit refused it later as a bare
    PM_ERR_ARG); text and booleans as numbers (numpy turns them into
    numbers).  And the messages say what is wrong: n=0 is below 1 like
    n=-1; lst and utc together are two times, not none."""
    m = pm.Model()
    with pytest.raises(pm.ArgumentError, match="comment: holds a NUL character at 1"):
        m.save(str(tmp_path / "a.pm"), comment="a\x00b")
    with pytest.raises(pm.ArgumentError, match="NUL"):
        m.save(str(tmp_path / "a.pm") + "\x00.txt")
    with pytest.raises(pm.ArgumentError, match="prefix: holds a NUL"):
        m.emit_c(str(tmp_path / "a.h"), prefix="pm\x00x")
    assert not list(tmp_path.iterdir())
    with pytest.raises(pm.ArgumentError, match=r"app_dec: point 1 is 2.0, beyond \+-pi/2"):
        pm.Run.from_arrays([0.1, 0.2], [0.3, 0.4], [0.1, 0.2], [0.3, 2.0])
    with pytest.raises(pm.ArgumentError, match="enc_ha: expected numbers, got text"):
        m.apply("0.1", 0.2)
    with pytest.raises(pm.ArgumentError, match="enc_ha: expected numbers, got boolean"):
        m.apply(np.array([True, False]), 0.2)
    for n in (0, -1):
        with pytest.raises(pm.ArgumentError, match="n: expected an integer >= 1"):
            pm.simulate(m, n=n)
    with pytest.raises(pm.ArgumentError, match="lst and utc both given"):
        pm.plan(latitude=0.8, lst=3, utc="2026-01-01T00:00", lon=5,
                catalogue=os.path.join(TOP, "examples", "bright_stars.txt"))


def test_rts2_j2000_places_read_as_of_date_noted():
    # An RTS2 file of J2000 true places read as they are (the default): the
    # run's warnings say they fit far better as J2000 (an outside probe's run
    # came out 90.7" with nothing said); not with the equinox given.
    path = os.path.join(TOP, "tests", "data", "rts2_gpoint_j2000.dat")
    notes = [w for w in pm.read_run(path).warnings if "fit far better as J2000" in w]
    assert len(notes) == 1 and 'equinox="J2000"' in notes[0], notes
    assert not [w for w in pm.read_run(path, equinox="J2000").warnings if "far better" in w]


def test_model_copy_and_deepcopy_are_independent():
    import copy
    m = pm.Model(order=0)
    for c in (copy.copy(m), copy.deepcopy(m), m.copy()):
        v = c.coefficients.copy()
        v[2] += 1e-5
        c.coefficients = v
        assert m.coefficients[2] == 0 and c.coefficients[2] == 1e-5


def test_invert_side_message_and_fit_shapes_named():
    m = pm.Model(order=0)
    with pytest.raises(pm.ArgumentError, match=r"side: expected 0 / 'normal' or 1 / 'flipped'"):
        m.invert(0.1, 0.2, side=2)
    h = np.linspace(-1, 1, 20)
    with pytest.raises(pm.ArgumentError, match=r"enc_dec: shape \(\), expected \(20,\) like enc_ha"):
        pm.fit(h, 0.3, h, h * 0 + 0.3)


def test_read_run_azimuth_count(tmp_path):
    # azimuth_count: an alt-az file in 0..360 deg read as the mount's count:
    # the slew direction is the change of the written azimuth, however far
    # (350 -> 10 is a move of -340, not +20)
    p = tmp_path / "count.dat"
    p.write_text("# mount: altaz\n# latitude: 40\n# tau delta T D\n"
                 "350 40 350.01 40\n10 41 10.01 41\n200 42 200.01 42\n340 43 340.01 43\n")
    short = pm.read_run(str(p))
    count = pm.read_run(str(p), azimuth_count=True)
    assert list(short.dir[1:]) == [1, -1, 1]
    assert list(count.dir[1:]) == [-1, 1, 1]
