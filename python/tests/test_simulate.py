"""pm.simulate gives the run `pmfit simulate OUT` writes (the same truth,
effects, seed and shape): every column bit for bit as read from pmfit's
file; German, fork and alt-az mounts; explain finds the effect; bad
arguments raise ArgumentError."""
import numpy as np
import pytest

import pm
from conftest import PMFIT, run_cmd

COLS = ["enc_ha", "enc_dec", "app_ha", "app_dec", "pier", "temp_c", "time_h", "dir"]


def truth(order=1, mount="equatorial", **terms):
    m = pm.Model(order=order, mount=mount)
    c = m.coefficients.copy()
    for name, v in terms.items():
        c[m.names.index(name.replace("_p", "'"))] = v / pm.RAD2ARCSEC
    m.coefficients = c
    return m


@pytest.mark.parametrize("kw,args", [
    (dict(n=120, seed=5, latitude=30, effects=["refraction=2.5"]),
     ["--n", "120", "--seed", "5", "--lat", "30", "--effect", "refraction=2.5"]),
    (dict(n=80, seed=9, latitude=-35, fork=True, noise=0.5, el_limit=25,
          effects=[("ha_periodic:144", 3.0)], phase=40),
     ["--n", "80", "--seed", "9", "--lat", "-35", "--fork", "--noise", "0.5", "--el-limit", "25",
      "--effect", "ha_periodic:144=3", "--phase", "40"]),
])
def test_simulate_equals_pmfit(tmp_path, kw, args):
    out = tmp_path / "s.dat"
    run_cmd(PMFIT, "simulate", out, "--order", "1", "--term", "c'=600", "--term", "e'=-300", *args)
    want = pm.read_run(out)
    got = pm.simulate(truth(c_p=600, e_p=-300), **kw)
    assert len(got) == len(want)
    for k in COLS:
        assert np.array_equal(getattr(got, k), getattr(want, k), equal_nan=True), k
    assert got.path == "<pm.simulate>"


def test_simulate_alt_az_and_explain():
    r = pm.simulate(truth(mount="altaz", c_p=200), n=150, seed=3, latitude=20,
                    effects="tube_flexure=-4")
    assert r.mount == "altaz" and len(r) == 150
    found = pm.explain(r, order=0)["findings"]
    assert found and found[0]["effect"] == "tube_flexure"


def test_simulate_errors():
    m = truth()
    for kw, what in [(dict(n=0), "n:"), (dict(latitude=91), "latitude"),
                     (dict(noise=-1), "noise"), (dict(effects=["nonsense=1"]), "nonsense"),
                     (dict(effects=["refraction"]), "EFFECT=SIZE"), (dict(seed=-2), "seed")]:
        with pytest.raises(pm.ArgumentError, match=what):
            pm.simulate(m, **kw)
    with pytest.raises(pm.ArgumentError, match="truth"):
        pm.simulate("model.pm")
