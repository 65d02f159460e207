"""The vectorised calls give exactly what a Python loop over the per-point C
call gives, keep the shapes of their inputs, and broadcast like numpy.
(How much faster they are is measured in bench/bench_python.py, not here.)"""
import threading

import numpy as np
import pytest

import pm
from conftest import TOP, sky_points


@pytest.fixture(scope="module")
def model():
    res = pm.fit_run(TOP + "/examples/sim_gem.dat", order=2)
    return res.model


def test_apply_equals_loop_over_c_call(model):
    ha, dec = sky_points(200000, seed=11, flipped=True)
    a, b = model.apply(ha, dec)
    loop = np.array([model.apply_point(h, d) for h, d in zip(ha.tolist(), dec.tolist())])
    assert np.array_equal(a, loop[:, 0]) and np.array_equal(b, loop[:, 1])


def test_invert_equals_loop_over_c_call(model):
    app_ha, app_dec = sky_points(20000, seed=12)
    app_dec = np.clip(app_dec, -np.pi / 2, np.pi / 2)
    for side in (0, 1):
        h, d, st = model.invert(app_ha, app_dec, side, return_status=True)
        loop = np.array([model.invert_point(x, y, side) for x, y in zip(app_ha, app_dec)])
        assert np.array_equal(h, loop[:, 0]) and np.array_equal(d, loop[:, 1])
        assert np.array_equal(st, loop[:, 2].astype(int))


def test_shapes_scalars_and_broadcasting(model):
    ha = np.linspace(-3, 3, 12).reshape(3, 4)
    a, b = model.apply(ha, 0.4)
    assert a.shape == b.shape == (3, 4)
    assert np.array_equal(a, model.apply(ha.ravel(), np.full(12, 0.4))[0].reshape(3, 4))
    s = model.apply(0.1, 0.2)
    assert isinstance(s[0], float) and s == model.apply_point(0.1, 0.2)
    assert model.apply([0.1], [0.2])[0].shape == (1,)
    h, d = model.invert(a, b, side=np.zeros((3, 4), dtype=int))
    assert h.shape == (3, 4)
    h2, d2 = model.invert(a, b, side="normal")
    assert np.array_equal(h, h2) and np.array_equal(d, d2)
    h1, d1, st = model.invert(0.3, 0.5, return_status=True)
    assert isinstance(h1, float) and st == 0
    r = model.residual(ha, 0.4, a, b)
    assert r.shape == (3, 4, 2) and np.abs(r).max() < 1e-14
    # float32 and integer inputs are converted
    assert model.apply(np.float32(0.5), 1)[0] == model.apply(float(np.float32(0.5)), 1.0)[0]


def test_pointing_sigma_vectorised_equals_scalar_calls():
    res = pm.fit_run(TOP + "/examples/sim_gem.dat", order=1)
    ha, dec = sky_points(50, seed=13)
    s, c = res.pointing_sigma(ha, dec, full=True)
    for i in range(0, 50, 7):
        si, ci = res.pointing_sigma(ha[i], dec[i], full=True)
        assert si == s[i] and ci == tuple(c[i])
    assert res.pointing_sigma(ha.reshape(5, 10), dec.reshape(5, 10)).shape == (5, 10)


def test_threads_give_the_same_results(model):
    """The loops run without the GIL: two threads at once get what one gets."""
    ha, dec = sky_points(100000, seed=14)
    want = model.apply(ha, dec)
    out = [None, None]

    def work(k):
        out[k] = model.apply(ha, dec)
    ts = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    for o in out:
        assert np.array_equal(o[0], want[0]) and np.array_equal(o[1], want[1])


def test_fit_result_contents():
    res = pm.fit_run(TOP + "/examples/sim_gem.dat", order=1)
    p = res.n_params
    assert len(res.names) == p == res.coefficients.shape[0] == res.errors.shape[0]
    assert res.covariance.shape == (p, p)
    assert np.array_equal(res.covariance, res.covariance.T)
    assert np.allclose(np.sqrt(np.diag(res.covariance)), res.errors, rtol=1e-12)
    assert np.allclose(np.diag(res.correlation), 1)
    assert res.residuals.shape == (res.n_obs, 2)
    assert res.sigma == pytest.approx(np.sqrt(res.chi2 / (2 * res.n_obs - p)), rel=1e-14)
    assert len(res.lines) == res.n_obs and res.converged
    d = res.to_dict()
    assert d["n_params"] == p and len(d["terms"]) == p
    for arr in (res.coefficients, res.covariance, res.residuals):
        with pytest.raises(ValueError):
            arr[0] = 1  # read-only: the result stays what was fitted
    m = res.model
    m2 = m.copy()
    m2.coefficients = np.zeros(p)
    assert not np.array_equal(m.coefficients, m2.coefficients)  # a copy, not a view
    assert [t["name"] for t in m.terms] == res.names


def test_threads_do_not_change_results(model):
    """The loops split the points over threads (threads=None: all cores):
    the same doubles for any number, and the first failing point is still
    the lowest index."""
    ha, dec = sky_points(1 << 17, seed=15, flipped=True)
    one = model.apply(ha, dec, threads=1)
    for t in (2, 3, None):
        got = model.apply(ha, dec, threads=t)
        assert np.array_equal(got[0], one[0]) and np.array_equal(got[1], one[1])
    a, b = one
    i1 = model.invert(a, np.clip(b, -1.5, 1.5), 1, threads=1, return_status=True)
    i4 = model.invert(a, np.clip(b, -1.5, 1.5), 1, threads=4, return_status=True)
    for x, y in zip(i1, i4):
        assert np.array_equal(x, y)
    with pytest.raises(pm.ArgumentError, match="threads"):
        model.apply(ha, dec, threads=0)
    # the extension's own loop, past the Python checks: NaN at two places
    h = ha.copy()
    h[[100000, 70000]] = np.nan
    with pytest.raises(pm.NonFiniteError, match="point 70000"):
        model._apply(h, dec, None, None, None, None, None, 4)
