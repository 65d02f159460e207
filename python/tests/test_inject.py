"""pm.inject gives what `pmfit simulate --inject ... --into RUN OUT` writes:
the same observed positions (to the file's 12 decimals of a degree), the
encoder readings untouched, the same sizes and moved lines; explain finds
the injected effect; bad specs raise ArgumentError."""
import numpy as np
import pytest

import pm
from conftest import PMFIT, TOP, real_run, run_cmd

SIM = TOP + "/examples/sim_gem.dat"
DEG = np.pi / 180


@pytest.mark.parametrize("name,specs", [
    ("examples/sim_gem.dat", ["refraction=3"]),
    ("examples/sim_gem.dat", ["ha_periodic:120:2sigma", "temperature:1.5sigma"]),
    ("examples/sim_gem.dat", ["outlier:3:20as"]),
    ("mmt", ["tube_flexure=-2", "higher_order=1.5"]),
])
def test_inject_equals_pmfit(tmp_path, name, specs):
    path = SIM if name != "mmt" else real_run("mmt/k_and_e.dat")
    out = tmp_path / "inj.dat"
    args = sum((["--inject", s] for s in specs), [])
    p = run_cmd(PMFIT, "simulate", *args, "--phase", "30", "--seed", "7", "--into", path, out)
    want = pm.read_run(out)
    run = pm.read_run(path)
    got, info = pm.inject(run, specs, phase=30, seed=7)
    assert len(got) == len(run) == len(want)
    assert np.array_equal(got.enc_ha, run.enc_ha) and np.array_equal(got.enc_dec, run.enc_dec)
    # the file has 12 decimals of a degree: 5e-13 deg, under 1e-14 rad
    dh = np.remainder(got.app_ha - want.app_ha + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(dh)) < 2e-14 and np.max(np.abs(got.app_dec - want.app_dec)) < 2e-14
    assert not np.array_equal(got.app_ha, run.app_ha)       # something was injected
    for it in info["injected"]:
        assert ("%.6g arcsec" % it["size_arcsec"]) in p.stderr
        if it["moved_lines"]:
            assert "moved lines %s: %s;" % (path, " ".join(map(str, it["moved_lines"]))) in p.stderr
    assert ("sigma %.4f arcsec" % info["sigma_arcsec"]) in p.stderr


def test_inject_is_found_and_the_run_is_kept():
    run = pm.read_run(SIM)
    before = run.app_ha.copy()
    inj, info = pm.inject(SIM, "dec_periodic:90:3sigma", phase=45)
    assert np.array_equal(run.app_ha, before)                # the input run is unchanged
    found = pm.explain(inj)["findings"]
    assert any(f["effect"] == "dec_periodic" and f["cycles_per_rev"] == 90 for f in found)
    assert info["injected"][0]["size_arcsec"] == pytest.approx(3 * info["sigma_arcsec"])


def test_inject_errors():
    for bad, what in [("nonsense=3", "nonsense"), ("refraction=abc", "refraction"),
                      ([], "at least one")]:
        with pytest.raises(pm.ArgumentError, match=what):
            pm.inject(SIM, bad)
    with pytest.raises(pm.ArgumentError, match="seed"):
        pm.inject(SIM, "refraction", seed=-1)
    with pytest.raises(pm.ArgumentError, match="phase"):
        pm.inject(SIM, "refraction", phase=float("inf"))
