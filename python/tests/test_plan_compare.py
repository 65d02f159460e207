"""pm.plan and pm.compare give what `pmfit plan --json` and `pmfit compare
--json` give (the same JSON, parsed), for runs, no run, alt-az mounts, a
horizon and a catalogue, OLD as a Model, a Run or a file; bad keywords and
bad files raise the package's exceptions with the reason."""
import json
import os

import numpy as np
import pytest

import pm
from conftest import PMFIT, TOP, real_run, run_cmd

SIM = os.path.join(TOP, "examples", "sim_gem.dat")


def cli(*args):
    return json.loads(run_cmd(PMFIT, *args).stdout)


@pytest.mark.parametrize("kw,args", [
    (dict(next=4), ["--next", "4"]),
    (dict(next=3, order=2, criterion="D"), ["--next", "3", "--order", "2", "--criterion", "D"]),
    (dict(next=3, sides="both", meridian_limit=20, min_el=25, grid=9),
     ["--next", "3", "--sides", "both", "--meridian-limit", "20", "--min-el", "25", "--grid", "9"]),
    (dict(next=3, slew=2.5, settle=3, point_time=20, flip_time=90, noise=1.5),
     ["--next", "3", "--slew", "2.5", "--settle", "3", "--point-time", "20", "--flip-time", "90",
      "--noise", "1.5"]),
])
def test_plan_equals_pmfit_with_a_run(kw, args):
    assert pm.plan(SIM, **kw) == cli("plan", SIM, "--json", *args)
    assert pm.plan(pm.read_run(SIM), **kw) == cli("plan", SIM, "--json", *args)


def test_plan_without_a_run_and_alt_az(tmp_path):
    assert pm.plan(latitude=-33.5, next=5, fork=True) == \
        cli("plan", "--lat", "-33.5", "--fork", "--next", "5", "--json")
    assert pm.plan(mount="altaz", next=5) == cli("plan", "--mount", "altaz", "--next", "5", "--json")
    mmt = real_run("mmt/k_and_e.dat")
    p = pm.plan(mmt, next=3)
    assert p == cli("plan", mmt, "--next", "3", "--json")
    assert "azimuth_deg" in p["targets"][0] and p["taken"] == 80


def test_plan_horizon_and_catalogue(tmp_path):
    hrz = tmp_path / "h.hrz"
    hrz.write_text("0 20\n90 50\n180 10\n270 25\n")
    assert pm.plan(latitude=47, next=6, horizon=hrz) == \
        cli("plan", "--lat", "47", "--next", "6", "--horizon", hrz, "--json")
    cat = tmp_path / "stars.txt"
    cat.write_text("".join("%02d:%02d:00 %+03d:30:00 star%d\n" % (h, (7 * h) % 60, d, 10 * h + k)
                           for k, d in enumerate((-20, 10, 40, 70)) for h in range(0, 24, 2)))
    p = pm.plan(SIM, next=5, catalogue=cat, lst=6)
    assert p == cli("plan", SIM, "--next", "5", "--catalog", cat, "--lst", "6", "--json")
    assert p["catalogue_stars"] == 48 and all(t["name"].startswith("star") for t in p["targets"])
    assert pm.plan(SIM, next=3, catalogue=cat, utc="2024-03-20T04:00", lon=20) == \
        cli("plan", SIM, "--next", "3", "--catalog", cat, "--utc", "2024-03-20T04:00", "--lon", "20",
            "--json")


def test_plan_errors(tmp_path):
    for kw, what in [(dict(next=0), "next:"), (dict(min_el=95), "min_el:"),
                     (dict(criterion="X"), "criterion:"), (dict(sides="east"), "sides:"),
                     (dict(mount="fork"), "mount:"), (dict(add="nonsense"), "--add nonsense"),
                     (dict(lst=3), "catalogue"), (dict(order=9), "order"),
                     (dict(noise=float("nan")), "noise:")]:
        with pytest.raises(pm.ArgumentError, match=what):
            pm.plan(SIM, **kw)
    with pytest.raises(pm.ArgumentError, match="latitude"):
        pm.plan(next=2)                                  # equatorial, no run, no latitude
    with pytest.raises(pm.ArgumentError, match="mount: 'altaz', but the run is of an equatorial"):
        pm.plan(SIM, mount="altaz")                      # the run's own mount decides
    assert pm.plan(SIM, mount="equatorial", next=1) == pm.plan(SIM, next=1)
    # fork is of an equatorial mount (an alt-az plan had ignored it, as pmfit plan)
    with pytest.raises(pm.ArgumentError, match="fork: an equatorial mount"):
        pm.plan(mount="altaz", latitude=40, next=2, fork=True)
    with pytest.raises(pm.FileError, match="nowhere.hrz"):
        pm.plan(SIM, horizon=tmp_path / "nowhere.hrz")
    bad = tmp_path / "bad.hrz"
    bad.write_text("0 20\n90 fifty\n")
    with pytest.raises(pm.FormatError, match="bad.hrz:2"):
        pm.plan(SIM, horizon=bad)
    cat = tmp_path / "c.txt"
    cat.write_text("1 2 x\n")
    with pytest.raises(pm.ArgumentError, match="needs the time"):
        pm.plan(SIM, catalogue=cat)
    # a bad date is worded with the keyword utc, not pmfit's flag --utc
    for utc in ("2024-13-01T20:00", "tonight"):
        with pytest.raises(pm.ArgumentError) as e:
            pm.plan(SIM, catalogue=cat, utc=utc, lon=20)
        assert str(e.value) == ("utc: expected YYYY-MM-DDTHH:MM[:SS] (UTC), got '%s'" % utc)


def test_compare_equals_pmfit(tmp_path):
    gem = real_run("celestial/gem-28.dat")
    want = cli("compare", SIM, SIM, "--json")
    assert pm.compare(SIM, SIM) == want                       # OLD a run file
    assert pm.compare(pm.read_run(SIM), pm.read_run(SIM)) == want   # OLD a Run
    model = tmp_path / "m.pm"
    run_cmd(PMFIT, "fit", SIM, "--save", model)
    want = cli("compare", model, SIM, "--json")
    assert pm.compare(model, SIM) == want                     # OLD a model file
    assert pm.compare(pm.load_model(str(model)), SIM) == want  # OLD a Model
    # the model file keeps the fit's covariance (version 5), and so does a
    # fit's Model: the joint test uses it as the old run's; a Model whose
    # coefficients were set keeps no errors
    assert open(model).read().count("pm-model 5") == 1
    assert want["old_covariance"] == "model_file"
    fitted = pm.fit_run(SIM).model
    assert pm.compare(fitted, SIM)["old_covariance"] == "model_file"
    fitted.save(str(tmp_path / "f.pm"))
    assert "correlations" in open(tmp_path / "f.pm").read()
    fitted.coefficients = fitted.coefficients
    assert pm.compare(fitted, SIM)["old_covariance"] == "none"
    assert pm.compare(SIM, SIM)["old_covariance"] == "run"
    assert pm.compare(SIM, SIM, order=2)["n_terms"] == pm.fit_run(SIM, order=2).n_params
    # a model's own terms are compared: order or add with it is refused (an
    # order-1 model compared as order 1 under order=2, without a word)
    for old in (model, pm.load_model(str(model))):
        with pytest.raises(pm.ArgumentError, match="its own terms"):
            pm.compare(old, SIM, order=2)
        with pytest.raises(pm.ArgumentError, match="its own terms"):
            pm.compare(old, SIM, add="refraction")
    with pytest.raises(pm.ArgumentError, match="order"):
        pm.compare(SIM, SIM, order=-1)
    with pytest.raises(pm.Error, match="mount|equatorial|alt"):
        pm.compare(real_run("mmt/k_and_e.dat"), gem)
    with pytest.raises(pm.FileError, match="nothing.dat"):
        pm.compare(tmp_path / "nothing.dat", SIM)
    bad = tmp_path / "bad.pm"
    bad.write_text("pm-model 2\nmount equatorial\norder one\n")
    with pytest.raises(pm.FormatError, match="bad.pm:3"):
        pm.compare(bad, SIM)
    with pytest.raises(pm.ArgumentError, match="--add"):
        pm.compare(SIM, SIM, add="nonsense")


def _with_columns(src, dst, names):
    """src's records with the columns hum and press added in the order of
    names (press absent when not named), the encoder Dec off by 3" per hPa."""
    rng = __import__("numpy").random.default_rng(5)
    out = []
    for line in open(src):
        line = line.rstrip("\n")
        if line.startswith("# tau"):
            out.append(line + " " + " ".join(names))
            continue
        if line.startswith("#") or not line.strip():
            out.append(line)
            continue
        f = line.split()
        hum, press = 50 + 30 * rng.random(), 1000 + 20 * rng.random()
        f[1] = "%.10f" % (float(f[1]) + 3.0 * (press - 1010) / 3600)
        val = {"hum": "%.6f" % hum, "press": "%.6f" % press}
        out.append(" ".join(f + [val[n] for n in names]))
    dst.write_text("\n".join(out) + "\n")
    return str(dst)


def test_model_columns_by_name(tmp_path):
    """A fit's model knows the names of the columns it reads; a saved and
    loaded model keeps them; compare on a run with the columns in another
    order is the compare on the same columns (pmfit's, too); a split fit's
    models know their pier side."""
    a = _with_columns(SIM, tmp_path / "a.dat", ["hum", "press"])
    b = _with_columns(SIM, tmp_path / "b.dat", ["press", "hum"])
    c = _with_columns(SIM, tmp_path / "c.dat", ["hum"])
    f = pm.fit_run(a, add=["aux:press:e'"])
    assert f.model.inputs == {1: "press"} and f.model.pier_side == 0
    path = tmp_path / "m.pm"
    f.model.save(str(path))
    m = pm.load_model(str(path))
    assert m.inputs == {1: "press"} and m.copy().inputs == {1: "press"}
    got = pm.compare(m, b)
    assert got["moved"] == []
    assert got["rms_as_is_arcsec"] == pytest.approx(pm.compare(m, a)["rms_as_is_arcsec"], rel=1e-9)
    assert got == cli("compare", path, b, "--json")
    assert pm.compare(a, b, add=["aux:press:e'"])["moved"] == []
    with pytest.raises(pm.Error, match="reads the column 'press'"):
        pm.compare(m, c)
    east, west = pm.fit_run(a, split=True)
    assert (east.model.pier_side, west.model.pier_side) == (1, -1)
    # Model.residual with run.inputs(): the aux dict is read by the model's
    # input names (by position it fed b's "press" in "hum"'s place, silently)
    ra, rb = pm.read_run(a), pm.read_run(b)
    res_a = m.residual(ra.enc_ha, ra.enc_dec, ra.app_ha, ra.app_dec, **ra.inputs())
    res_b = m.residual(rb.enc_ha, rb.enc_dec, rb.app_ha, rb.app_dec, **rb.inputs())
    assert np.array_equal(res_a, res_b)
    rc = pm.read_run(c)
    with pytest.raises(pm.ArgumentError, match="reads the column 'press' as aux\\[1\\]"):
        m.residual(rc.enc_ha, rc.enc_dec, rc.app_ha, rc.app_dec, **rc.inputs())
