"""The package against the C programs on the same inputs, bit for bit: the
fit (coefficients against `pmfit fit --save`; errors, covariance, sigma and
the pointing sigma against the C API called from C, build/python/pm_ref),
apply and invert (against pm_ref), model files (both directions), explain
(against `pmfit explain --json`).  Simulated runs and, when present, the real
ones of $PM_DATA_DIR."""
import json
import os
import warnings

import numpy as np
import pytest

import pm
from conftest import (PMFIT, PM_REF, REAL_RUNS, TOP, parse_model_file, real_run, run_cmd,
                      sky_points)

SIM_RUNS = ["examples/sim_gem.dat", "sim:eq.dat", "sim:altaz.dat", "sim:fork.dat"]


def resolve(name, sim_dir):
    if name.startswith("sim:"):
        return str(sim_dir / name[4:])
    if name in REAL_RUNS:
        return real_run(name)
    return os.path.join(TOP, name)


def bits(a):
    """The doubles' bit patterns (so that -0.0 != 0.0 and NaN == NaN)."""
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64)).view(np.uint64)


def assert_bits(got, want, what):
    got, want = np.asarray(got, dtype=np.float64), np.asarray(want, dtype=np.float64)
    assert got.shape == want.shape, "%s: shape %s vs %s" % (what, got.shape, want.shape)
    diff = np.flatnonzero(bits(got).reshape(-1) != bits(want).reshape(-1))
    assert diff.size == 0, "%s: %d of %d differ, first at %d: %r vs %r" % (
        what, diff.size, got.size, diff[0], got.reshape(-1)[diff[0]], want.reshape(-1)[diff[0]])


def pmfit_save(run, tmp_path, *args):
    out = tmp_path / "c.pm"
    run_cmd(PMFIT, "fit", run, "--save", out, *args)
    return out


def ref_fit(run, order, grid, tmp_path):
    g = tmp_path / "grid.bin"
    np.column_stack(grid).astype(np.float64).tofile(g)
    out = tmp_path / "fit.bin"
    run_cmd(PM_REF, "fit", run, order, g, out)
    v = np.fromfile(out, dtype=np.float64)
    p = int(v[0])
    k = 4
    coef, err = v[k:k + p], v[k + p:k + 2 * p]
    cov = v[k + 2 * p:k + 2 * p + p * p].reshape(p, p)
    ps = v[k + 2 * p + p * p:].reshape(-1, 4)
    return {"P": p, "sigma": v[1], "chi2": v[2], "iterations": int(v[3]), "coef": coef,
            "err": err, "cov": cov, "psigma": ps[:, 0], "pcov": ps[:, 1:]}


def ref_apply(model_file, ha, dec, tmp_path, ctx=None):
    cols = [ha, dec] + ([] if ctx is None else ctx)
    src, out = tmp_path / "in.bin", tmp_path / "out.bin"
    np.column_stack(cols).astype(np.float64).tofile(src)
    run_cmd(PM_REF, "apply", model_file, 0 if ctx is None else 1, src, out)
    r = np.fromfile(out, dtype=np.float64).reshape(-1, 2)
    return r[:, 0], r[:, 1]


def ref_invert(model_file, ha, dec, side, tmp_path, start=None):
    cols = [ha, dec] + ([] if start is None else list(start))
    src, out = tmp_path / "in.bin", tmp_path / "out.bin"
    np.column_stack(cols).astype(np.float64).tofile(src)
    run_cmd(PM_REF, "invert", model_file, 0, -1 if start is not None else side, src, out)
    r = np.fromfile(out, dtype=np.float64).reshape(-1, 3)
    return r[:, 0], r[:, 1], r[:, 2].astype(int)


@pytest.mark.parametrize("order", [0, 1, 2])
@pytest.mark.parametrize("name", SIM_RUNS + REAL_RUNS)
def test_fit_matches_c(name, order, sim_dir, tmp_path):
    """pm.fit_run == pmfit fit --save (coefficients) == the C API from C
    (errors, covariance, sigma, pointing sigma), bit for bit."""
    run = resolve(name, sim_dir)
    saved = pmfit_save(run, tmp_path, "--order", order)
    mount, file_order, terms = parse_model_file(saved)
    res = pm.fit_run(run, order=order)
    assert res.model.mount == mount and res.model.order == file_order == order
    assert res.names == [n for n, _ in terms]
    assert_bits(res.coefficients, [v for _, v in terms], "coefficients vs pmfit --save")
    assert_bits(res.model.coefficients, res.coefficients, "model coefficients")

    grid = sky_points(50, seed=order)
    ref = ref_fit(run, order, grid, tmp_path)
    assert ref["P"] == res.n_params == len(terms)
    assert ref["iterations"] == res.iterations
    assert_bits(res.coefficients, ref["coef"], "coefficients vs pm_ref")
    assert_bits(res.errors, ref["err"], "errors")
    assert_bits(res.covariance, ref["cov"], "covariance")
    assert_bits(res.sigma, ref["sigma"], "sigma")
    assert_bits(res.chi2, ref["chi2"], "chi2")
    s, c = res.pointing_sigma(*grid, full=True)
    assert_bits(s, ref["psigma"], "pointing sigma")
    assert_bits(c, ref["pcov"], "pointing covariance")
    # the model file pm.load_model reads is the one fitted
    assert_bits(pm.load_model(saved).coefficients, res.coefficients, "load_model")


@pytest.mark.parametrize("name", SIM_RUNS + REAL_RUNS)
def test_apply_invert_match_c(name, sim_dir, tmp_path):
    """Vectorised apply, invert (both sides) and invert_near of a fitted
    model == the C calls from C, bit for bit, statuses included."""
    run = resolve(name, sim_dir)
    saved = pmfit_save(run, tmp_path, "--order", "2")
    m = pm.load_model(saved)
    ha, dec = sky_points(4000, seed=2, flipped=m.mount == "equatorial")
    a, b = m.apply(ha, dec)
    ra, rb = ref_apply(saved, ha, dec, tmp_path)
    assert_bits(a, ra, "apply ha")
    assert_bits(b, rb, "apply dec")
    app_ha, app_dec = sky_points(4000, seed=3)
    app_dec = np.clip(app_dec, -np.pi / 2, np.pi / 2)
    for side in (0, 1):
        h, d, st = m.invert(app_ha, app_dec, side, return_status=True)
        rh, rd, rst = ref_invert(saved, app_ha, app_dec, side, tmp_path)
        assert_bits(h, rh, "invert ha, side %d" % side)
        assert_bits(d, rd, "invert dec, side %d" % side)
        assert (st == rst).all()
    h, d, st = m.invert(a, b, start_ha=ha + 1e-3, start_dec=dec - 1e-3, return_status=True)
    rh, rd, rst = ref_invert(saved, a, b, 0, tmp_path, start=(ha + 1e-3, dec - 1e-3))
    assert_bits(h, rh, "invert_near ha")
    assert_bits(d, rd, "invert_near dec")
    assert (st == rst).all()
    # and the library's round trip holds through Python: apply(invert(x)) = x
    # to PM_INVERT_TOL on the sky wherever the status is PM_OK
    ok = st == 0
    assert ok.mean() > 0.99
    a2, b2 = m.apply(h[ok], d[ok])
    dha = np.remainder(a2 - a[ok] + np.pi, 2 * np.pi) - np.pi
    assert np.hypot(dha * np.cos(b[ok]), b2 - b[ok]).max() < 2 * pm.INVERT_TOL


def test_physical_terms_match_pmfit(sim_dir, tmp_path):
    """--add effects with run-time inputs (temperature, slew direction,
    periodic error, refraction): the same model as pmfit, and apply with
    contexts == the C call with the same pm_context."""
    run = str(sim_dir / "eq.dat")
    adds = ["temperature", "hysteresis", "ha_periodic:144", "refraction"]
    saved = pmfit_save(run, tmp_path, "--order", "2", *sum((["--add", a] for a in adds), []))
    _, _, terms = parse_model_file(saved)
    res = pm.fit_run(run, order=2, add=adds)
    assert res.names == [n for n, _ in terms]
    assert_bits(res.coefficients, [v for _, v in terms], "coefficients")
    m = res.model
    assert pm.load_model(saved) == m
    r = pm.read_run(run)
    inputs = r.inputs()
    a, b = m.apply(r.enc_ha, r.enc_dec, **inputs)
    ctx = [r.pier.astype(float), r.temp_c, r.time_h, r.dir.astype(float)]
    aux = list(inputs["aux"].values())[:4]   # (a dict by column name; this model reads none)
    ctx += [np.nan_to_num(c) for c in aux] + [np.zeros(len(r))] * (4 - len(aux))
    ra, rb = ref_apply(saved, r.enc_ha, r.enc_dec, tmp_path, ctx=ctx)
    assert_bits(a, ra, "apply ha with context")
    assert_bits(b, rb, "apply dec with context")
    # residuals of the model on its own run are the fit's residuals
    assert_bits(m.residual(r.enc_ha, r.enc_dec, r.app_ha, r.app_dec, **inputs), res.residuals,
                "residuals")


def test_fit_from_arrays_equals_fit_of_file(sim_dir, tmp_path):
    """pm.fit on the arrays of a run == pm.fit_run of the file (same
    contexts, the same derived slew directions)."""
    r = pm.read_run(sim_dir / "eq.dat")
    adds = ["temperature", "hysteresis"]
    a = pm.fit(r.enc_ha, r.enc_dec, r.app_ha, r.app_dec, order=1, add=adds,
               latitude=r.latitude, temp_c=r.temp_c, time_h=r.time_h, dir=r.dir, pier=r.pier)
    b = pm.fit_run(r, order=1, add=adds)
    assert a.names == b.names
    assert_bits(a.coefficients, b.coefficients, "coefficients")
    assert_bits(a.covariance, b.covariance, "covariance")
    # without dir, it is derived from the sequence as the reader does for a
    # file without a dir column (here: a four-column file)
    f = tmp_path / "four.dat"
    np.savetxt(f, np.degrees(np.column_stack([r.enc_ha, r.enc_dec, r.app_ha, r.app_dec])),
               fmt="%.17g")
    g = pm.read_run(f)
    assert g.dir_derived and g.format == "four-column"
    c = pm.fit(g.enc_ha, g.enc_dec, g.app_ha, g.app_dec, add="hysteresis")
    d = pm.fit_run(g, add="hysteresis")
    assert_bits(c.coefficients, d.coefficients, "hysteresis, derived directions")
    assert (pm.Run.from_arrays(g.enc_ha, g.enc_dec, g.app_ha, g.app_dec).dir == g.dir).all()


@pytest.mark.parametrize("name", ["examples/sim_gem.dat", "celestial/gem-28.dat"])
def test_pier_split_matches_pmfit(name, sim_dir, tmp_path):
    run = resolve(name, sim_dir)
    pmfit_save(run, tmp_path, "--pier", "split")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = pm.fit_run(run, split=True)
    out = json.loads(run_cmd(PMFIT, "fit", run, "--pier", "split", "--json").stdout)
    # (gem-28's west side is undetermined between its stars: pmfit warns, so does pm)
    assert len(caught) == sum(out["sides"][k]["error_map"]["undetermined"] for k in ("east", "west"))
    for side, res in (("east", s.east), ("west", s.west)):
        _, _, terms = parse_model_file(str(tmp_path / "c.pm") + "-" + side)
        assert_bits(res.coefficients, [v for _, v in terms], side)
    out = json.loads(run_cmd(PMFIT, "fit", run, "--pier", "split", "--json").stdout)
    assert s.f_test["dof1"] == out["pier_f_test"]["dof1"]
    assert s.f_test["f"] == pytest.approx(out["pier_f_test"]["f"], rel=1e-5)
    assert s.east.n_obs == out["sides"]["east"]["n_obs"]


def test_side_terms_f_test_matches_pmfit():
    run = os.path.join(TOP, "examples", "sim_gem.dat")
    res = pm.fit_run(run, add=["i@W", "c'@W"])
    out = json.loads(run_cmd(PMFIT, "fit", run, "--add", "i@W", "--add", "c'@W", "--json").stdout)
    assert res.names[-2:] == ["i@W", "c'@W"]
    assert res.f_test["test"] == out["pier_f_test"]["test"]
    assert res.f_test["f"] == pytest.approx(out["pier_f_test"]["f"], rel=1e-5)
    d = res.to_dict()
    assert [t["name"] for t in d["terms"]] == [t["name"] for t in out["terms"]]
    for t, u in zip(d["terms"], out["terms"]):
        assert round(t["value_arcsec"], 6) == pytest.approx(u["value_arcsec"], abs=1.5e-6)


def test_model_file_round_trip(sim_dir, tmp_path):
    """pm's save == pmfit's file (comments aside); load(save(m)) == m bit for
    bit; pmfit eval reads what pm saved."""
    run = str(sim_dir / "eq.dat")
    adds = ["ha_periodic:144:2", "refraction", "temperature"]
    saved = pmfit_save(run, tmp_path, "--order", "2", *sum((["--add", a] for a in adds), []))
    res = pm.fit_run(run, order=2, add=adds)
    mine = tmp_path / "py.pm"
    res.model.save(mine, comment="from python")

    def body(p):
        return [l for l in open(p).read().splitlines() if not l.startswith("#")]
    assert body(mine) == body(saved)
    assert open(mine).read().startswith("# from python\n")
    back = pm.load_model(mine)
    assert back == res.model
    assert_bits(back.coefficients, res.coefficients, "reloaded")
    ev = json.loads(run_cmd(PMFIT, "eval", mine, run, "--json").stdout)
    assert ev["rms_arcsec"] == pytest.approx(res.rms * pm.RAD2ARCSEC, abs=1e-6)
    # emit-c output is the same as pmfit's for the same model and prefix
    res.model.emit_c(tmp_path / "py.h", prefix="pm_fitted", comment="x")
    run_cmd(PMFIT, "fit", run, "--order", "2", *sum((["--add", a] for a in adds), []),
            "--emit-c", tmp_path / "c.h")
    strip = lambda p: [l for l in open(p).read().splitlines() if not l.startswith(("/*", "**", " *", "*/"))]
    assert "pm_fitted_load" in open(tmp_path / "py.h").read()
    assert strip(tmp_path / "py.h") == strip(tmp_path / "c.h")


def test_coefficients_set_and_round_trip(tmp_path):
    m = pm.Model(order=2, mount="altaz")
    rng = np.random.default_rng(4)
    c = rng.normal(0, 1e-4, m.n_terms)
    m.coefficients = c
    assert_bits(m.coefficients, c, "set")
    m.save(tmp_path / "m.pm")
    assert_bits(pm.load_model(tmp_path / "m.pm").coefficients, c, "saved")
    ha, dec = sky_points(1000, seed=9)
    a, b = m.apply(ha, dec)
    ra, rb = ref_apply(tmp_path / "m.pm", ha, dec, tmp_path)
    assert_bits(a, ra, "apply")
    assert_bits(b, rb, "apply")


@pytest.mark.parametrize("name", ["examples/sim_gem.dat", "sim:eq.dat"] + REAL_RUNS)
def test_explain_matches_pmfit(name, sim_dir):
    """pm.explain(run) is the dict of pmfit explain --json: the same content."""
    run = resolve(name, sim_dir)
    want = json.loads(run_cmd(PMFIT, "explain", run, "--json").stdout)
    assert pm.explain(run) == want


def test_explain_options_match_pmfit(sim_dir):
    run = str(sim_dir / "eq.dat")
    want = json.loads(run_cmd(PMFIT, "explain", run, "--json", "--order", "2", "--add",
                              "temperature", "--gear", "ha:144", "--alpha", "0.001").stdout)
    got = pm.explain(pm.read_run(run), order=2, add=["temperature"], gears_ha=[144], alpha=0.001)
    assert got == want
    assert got["baseline"]["order"] == 2


def test_explain_default_order_matches_pmfit(tmp_path):
    """order=None is pmfit explain without --order: 20 points of an alt-az
    mount are explained at order 0, which predicts them better than the
    order-1 baseline's 22 terms, and order_note says so; order=1 is --order 1."""
    run = str(tmp_path / "az20.dat")
    run_cmd(PMFIT, "simulate", run, "--mount", "altaz", "--n", "20", "--noise", "3", "--seed", "2",
            "--effect", "ha_periodic:2=20")
    got = pm.explain(run)
    assert got == json.loads(run_cmd(PMFIT, "explain", run, "--json").stdout)
    assert got["baseline"]["order"] == 0
    assert got["order_note"].startswith("20 points are too few to pin down the order-1 baseline's "
                                        "22 terms")
    one = pm.explain(run, order=1)
    assert one == json.loads(run_cmd(PMFIT, "explain", run, "--json", "--order", "1").stdout)
    assert one["baseline"]["order"] == 1 and one["order_note"] is None
    with pytest.raises(pm.ArgumentError):
        pm.explain(run, order=-1)


def test_explain_compose_matches_pmfit():
    """compose=False is pmfit explain --no-compose (docs/explain.md, step 1): on a run of
    10' of gimbal anisotropy, the composition taken out is reported, and off it is 0."""
    run = os.path.join(TOP, "tests", "data", "indep_aniso600_gem.dat")
    on = pm.explain(run)
    off = pm.explain(run, compose=False)
    assert off == json.loads(run_cmd(PMFIT, "explain", run, "--json", "--no-compose").stdout)
    assert on["baseline"]["composition_rms_arcsec"] > 0.3
    assert off["baseline"]["composition_rms_arcsec"] == 0


def test_read_run_columns(tmp_path):
    """The reader's columns: what the file says, in radians (a folded W
    record as the mount's axes), pier from the column, skipped records
    listed with file:line."""
    f = tmp_path / "r.dat"
    f.write_text("# tau delta T D pier temp\n"
                 "10 20 10.01 20.02 E 5.5\n"
                 "-30 45 -29.98 45.01 W 6.0\n"
                 "bad line here x y\n"
                 "100 -10 100.02 -10.03 E 7\n")
    with pytest.raises(pm.FormatError) as e:
        pm.read_run(f)
    assert str(e.value).startswith(str(f) + ":4:")
    r = pm.read_run(f, skip_bad=True)
    assert len(r) == 3 and list(r.line) == [2, 3, 5]
    assert list(r.pier) == [1, -1, 1]
    assert list(r.temp_c) == [5.5, 6.0, 7.0]
    assert r.format == "named" and r.mount == "equatorial"
    assert len(r.skipped) == 1 and r.skipped[0].startswith(str(f) + ":4:")
    # both pier sides, no encoder dec beyond 90: the W record is the sky
    # position folded back (ASCOM's pierWest), read as the mount's axes,
    # (HA + 180, 180 - dec) (docs/formats.md, "Beyond the pole")
    assert np.allclose(np.degrees(r.enc_ha), [10, 150, 100], atol=1e-12)
    assert np.allclose(np.degrees(r.enc_dec), [20, 135, -10], atol=1e-12)
    assert np.allclose(np.degrees(r.app_dec), [20.02, 45.01, -10.03], atol=1e-12)
    with pytest.raises(ValueError):
        r.enc_ha[0] = 1.0  # read-only: the run stays what was read


def test_error_map_and_undetermined_match_pmfit(tmp_path):
    """FitResult.error_map and to_dict()["error_map"] are pmfit fit --json's
    (to_dict lacked it), and where the stars do not determine the model
    between them fit_run warns as pmfit does (the warning was lost)."""
    run = os.path.join(TOP, "examples", "sim_gem.dat")
    out = json.loads(run_cmd(PMFIT, "fit", run, "--json").stdout)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = pm.fit_run(run)
    assert res.undetermined == ""
    assert res.to_dict()["error_map"] == out["error_map"]
    few = tmp_path / "few.dat"
    few.write_text("".join(open(run).readlines()[:18]))   # 13 points, 22 terms
    out = json.loads(run_cmd(PMFIT, "fit", few, "--json").stdout)
    assert out["error_map"]["undetermined"] is True
    with pytest.warns(pm.PointingWarning, match="do not determine this model"):
        res = pm.fit_run(str(few))
    assert res.to_dict()["error_map"] == out["error_map"]
    assert res.error_map["undetermined"] is True and "do not determine" in res.undetermined


def test_run_format_names_every_format():
    """Run.format is pmfit --format's name for every reader (it was None for
    the CSV, MW4, RTS2 and MMT files: an outside probe), None for arrays."""
    data = os.path.join(TOP, "tests", "data")
    for name, want in (("formats_source_eq.dat", "named"), ("tpoint_equat.dat", "tpoint"),
                       ("rts2_gpoint.dat", "rts2"), ("mw4_model.json", "mw4"),
                       ("nina_jnow.csv", "csv"), ("mmt_log.dat", "mmt")):
        assert pm.read_run(os.path.join(data, name)).format == want, name
