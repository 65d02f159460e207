"""The vectorised apply's lanes (python/apply_simd.hpp, apply_lanes.h: 2
points at a time with SSE2, 4 with AVX2, 8 with AVX-512, and twice that with
two vectors side by side) give pm_model_apply's doubles bit for bit, and its
errors at the same point: in every lane, in the tail (n not a multiple of
the lanes), near and beyond the pole, at hour angles to +-64 rad and past
them, for NaN and infinities, for orders 0..4, and for the points and models
the lanes hand back to the scalar call (displacements past expmap's series,
the pole's neighbourhood, added terms, |c'| > 0.5).

Model._apply_lanes(ha, dec, path) runs one path on one thread: "scalar" is
the C call per point (the reference), the others the vector code, each
path this machine runs (_pm._lanes_paths: SSE2 on any x86-64).  (Speed:
bench/bench_python.py, not here.)"""
import numpy as np
import pytest

import pm
from pm import _pm
from conftest import REAL_RUNS, TOP, real_run, sky_points

LANES = [p for p in _pm._lanes_paths if p != "scalar"]
WIDEST = 16  # points per step of the widest path (avx512x2)
if not LANES:
    pytestmark = pytest.mark.skip(reason="no vector lanes on this machine (not x86-64): "
                                         "apply runs the scalar call per point")
elif not pm.Model(order=1)._lanes_ok:
    pytestmark = pytest.mark.skip(reason="the lanes are off: the core was built with FMA "
                                         "(python/python.mk), apply runs the scalar call")


def outcome(model, ha, dec, lanes):
    """(results) or (the error's type and message) of one path."""
    try:
        a, b = model._apply_lanes(np.ascontiguousarray(ha, dtype=float),
                                  np.ascontiguousarray(dec, dtype=float), lanes)
        return ("ok", a, b)
    except pm.Error as e:
        return (type(e).__name__, str(e))


def assert_same(model, ha, dec):
    """Every lane width against the scalar call: the same doubles (bits), or
    the same error at the same point."""
    want = outcome(model, ha, dec, "scalar")
    for w in LANES:
        got = outcome(model, ha, dec, w)
        assert got[0] == want[0], (w, got[:2], want[:2])
        if want[0] == "ok":
            for x, y in zip(got[1:], want[1:]):
                # bit patterns: -0.0 against 0.0 and NaN payloads count
                assert np.array_equal(x.view(np.int64), y.view(np.int64)), (
                    w, np.flatnonzero(x.view(np.int64) != y.view(np.int64))[:10])
        else:
            assert got[1] == want[1], (w, got[1], want[1])
    return want


def random_model(order, scale, seed, mount="equatorial"):
    m = pm.Model(order=order, mount=mount, latitude=0.5)
    rng = np.random.default_rng(seed)
    m.coefficients = rng.normal(scale=scale, size=m.n_terms)
    return m


@pytest.fixture(scope="module")
def fitted():
    return {L: pm.fit_run(TOP + "/examples/sim_gem.dat", order=L).model for L in range(5)}


def test_reference_is_the_c_call(fitted):
    """lanes=1 is pm_model_apply itself (apply_point: the bare binding)."""
    ha, dec = sky_points(997, seed=21, flipped=True)
    a, b = fitted[2]._apply_lanes(ha, dec, "scalar")
    loop = np.array([fitted[2].apply_point(h, d) for h, d in zip(ha.tolist(), dec.tolist())])
    assert np.array_equal(a, loop[:, 0]) and np.array_equal(b, loop[:, 1])


@pytest.mark.parametrize("order", range(5))
def test_lanes_equal_c_call_fitted_orders(fitted, order):
    """Fitted models of order 0..4 over the sky, both sides of the pole; n
    = 16k + 3 (a tail in every width).  At order 4 the fit's displacement
    passes 0.01 rad over much of this sky: the lanes hand those points back."""
    m = fitted[order]
    assert m._lanes_ok
    ha, dec = sky_points(40003, seed=22 + order, flipped=True)
    assert_same(m, ha, dec)


@pytest.mark.parametrize("order", range(5))
@pytest.mark.parametrize("mount", ["equatorial", "altaz"])
def test_lanes_equal_c_call_random_models(order, mount):
    """Random coefficients: small (the lanes' branch nearly everywhere) and
    large (many points past expmap's series and near the pole: the scalar
    call for those lanes, the lanes for their neighbours)."""
    for k, scale in enumerate((3e-4, 3e-3, 2e-2)):
        m = random_model(order, scale, seed=100 + 10 * order + k, mount=mount)
        assert m._lanes_ok
        ha, dec = sky_points(20001, seed=31 + k, flipped=True)
        assert_same(m, ha, dec)


@pytest.mark.parametrize("name", REAL_RUNS)
def test_lanes_equal_c_call_real_runs(name):
    """Models fitted to the real runs of $PM_DATA_DIR (orders 0..2), over
    the sky and the run's own positions (skipped when the data is absent)."""
    path = real_run(name)
    run = pm.read_run(path)
    fitted = 0
    for order in (0, 1, 2):
        try:
            m = pm.fit_run(run, order=order).model
        except pm.FitError:
            continue  # too few points for the order: nothing to apply
        fitted += 1
        assert m._lanes_ok
        ha, dec = sky_points(30001, seed=order, flipped=True)
        assert_same(m, ha, dec)
        assert_same(m, np.asarray(run.enc_ha, dtype=float), np.asarray(run.enc_dec, dtype=float))
    assert fitted >= 2, name


def test_lanes_random_models_and_points():
    """300 random models (orders 0..4, both mounts, coefficients of random
    scales 1e-7..3e-2 rad, c' and e' to +-0.5) on random point sets of
    random length: the sky, hour angles to +-70 and declinations to +-4.5,
    and points piled up near +-pi, +-64, the pole and their edges."""
    rng = np.random.default_rng(2024)
    for _ in range(300):
        m = pm.Model(order=int(rng.integers(0, 5)), mount=["equatorial", "altaz"][int(rng.integers(0, 2))],
                     latitude=float(rng.uniform(-1.5, 1.5)))
        c = rng.normal(size=m.n_terms) * 10 ** rng.uniform(-7, -1.5, size=m.n_terms)
        if rng.uniform() < 0.3:
            c[2] = rng.uniform(-0.5, 0.5)
        if rng.uniform() < 0.3:
            c[4] = rng.uniform(-0.5, 0.5)
        m.coefficients = c
        n = int(rng.integers(1, 3000))
        kind = int(rng.integers(0, 3))
        if kind == 0:
            ha, dec = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi / 2, np.pi / 2, n)
        elif kind == 1:
            ha, dec = rng.uniform(-70, 70, n), rng.uniform(-4.5, 4.5, n)
        else:
            ha = (rng.choice([-np.pi, np.pi, 0.0, -0.0, 64.0, -64.0, np.pi - c[2], -np.pi - c[2]], n) +
                  rng.normal(size=n) * 10 ** rng.uniform(-17, -2, n))
            dec = (rng.choice([np.pi / 2, -np.pi / 2, c[4] + np.pi / 2, c[4] - np.pi / 2, 0.0, 4.0],
                              n) + rng.normal(size=n) * 10 ** rng.uniform(-17, -2, n))
        assert_same(m, ha, dec)


def special_values():
    """Hour angles and declinations at the edges of the lanes' branches."""
    pi = np.pi
    ha = [0.0, -0.0, 1e-300, -1e-300, pi, -pi, np.nextafter(pi, 0), np.nextafter(-pi, 0),
          pi - 0.006, -pi + 0.006, pi / 2, 2 * pi, -2 * pi, 10.0, -33.3, 63.9, 64.0, -64.0,
          np.nextafter(64.0, 100), np.nextafter(-64.0, -100), 100.0, -1e6, 1e300, 5e-324]
    dec = [0.0, -0.0, pi / 2, -pi / 2, np.nextafter(pi / 2, 0), np.nextafter(pi / 2, 2),
           1.5707, 1.5709, -1.5707, -1.5709, pi / 2 + 0.002, pi / 2 - 0.002,
           pi - 1.2, pi + 0.3, 3.0, -3.0, 4.0, -4.0, np.nextafter(4.0, 5), 4.5, -10.0, 64.0,
           1e300, 5e-324]
    return np.array(ha), np.array(dec)


def test_lanes_special_points_in_every_lane(fitted):
    """Each special (ha, dec) pair at every position of a block of 16 (so of
    8, 4 and 2) and in the tail, between ordinary points (so one lane leaves
    the branch while its neighbours stay)."""
    sha, sdec = special_values()
    pairs = [(h, d) for h in sha for d in sdec]
    base_h, base_d = sky_points(WIDEST * len(pairs) + 3, seed=41)
    for m in (fitted[1], fitted[2], random_model(3, 3e-3, seed=42)):
        for pos in range(WIDEST):
            ha, dec = base_h.copy(), base_d.copy()
            idx = WIDEST * np.arange(len(pairs)) + pos
            ha[idx] = [p[0] for p in pairs]
            dec[idx] = [p[1] for p in pairs]
            assert_same(m, ha, dec)
        # the tail: n = 16k + r, the special pair last
        for r in range(1, WIDEST):
            for h, d in pairs[::7]:
                ha = np.append(base_h[:2 * WIDEST + r - 1], h)
                dec = np.append(base_d[:2 * WIDEST + r - 1], d)
                assert_same(m, ha, dec)


def test_lanes_near_and_beyond_the_pole(fitted):
    """A dense grid across the pole (dec - e' = +-pi/2) and beyond it, and
    hour angles near +-pi where turn_sum crosses: the lanes' frame_angles and
    the atan2 fallback meet here."""
    m = fitted[2]
    e = m.coefficients[4]
    dd = np.concatenate([np.linspace(-0.02, 0.02, 401), np.geomspace(1e-12, 1e-2, 60),
                         -np.geomspace(1e-12, 1e-2, 60)])
    for pole in (np.pi / 2 + e, -np.pi / 2 + e):
        dec = np.repeat(pole + dd, 9)
        ha = np.tile(np.array([-3.14, -np.pi, -1.0, 0.0, 0.5, np.pi, 3.1, 63.0, -63.9]),
                     len(dd))
        assert_same(m, ha, dec)
    c = m.coefficients[2]
    ha = np.concatenate([np.pi - c + np.linspace(-0.02, 0.02, 2001),
                         -np.pi - c + np.linspace(-0.02, 0.02, 2001)])
    for dec0 in (0.3, np.pi - 0.3, -1.0):
        assert_same(m, ha, np.full(ha.shape, dec0))


def test_lanes_large_hour_angles(fitted):
    """Hour angles over +-64 rad (the lanes' sincos range) and past it."""
    m = fitted[2]
    rng = np.random.default_rng(51)
    ha = rng.uniform(-66, 66, 30001)
    dec = rng.uniform(-3.5, 3.5, 30001)
    assert_same(m, ha, dec)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_lanes_nonfinite_same_error_same_point(fitted, bad):
    """A NaN or infinity in either input, at each lane and in the tail:
    NonFiniteError naming the same point as the scalar call's loop."""
    m = fitted[2]
    n = WIDEST * 13 + 15
    for which in (0, 1):
        for i in list(range(2 * WIDEST)) + list(range(n - 15, n)):
            ha, dec = sky_points(n, seed=61)
            (ha if which == 0 else dec)[i] = bad
            want = assert_same(m, ha, dec)
            assert want[0] == "NonFiniteError" and "point %d" % i in want[1], want
    # two bad points: the first one is named
    ha, dec = sky_points(n, seed=62)
    ha[9] = bad
    dec[6] = bad
    want = assert_same(m, ha, dec)
    assert "point 6" in want[1]


def test_lanes_overflow_in_the_terms():
    """Coefficients so large that the terms overflow: the scalar call's
    error (outputs non-finite) at the same point."""
    m = random_model(2, 1e-3, seed=71)
    c = m.coefficients.copy()
    c[10] = 1e300
    m.coefficients = c
    ha, dec = sky_points(1003, seed=72, flipped=True)
    want = assert_same(m, ha, dec)
    assert want[0] == "NonFiniteError", want
    # Model.apply (its way straight to the loop, then the checked way):
    # the loop's error, the inputs being finite
    with pytest.raises(pm.NonFiniteError, match=r"apply, point \d+"):
        m.apply(ha, dec)


def test_apply_nonfinite_input_named_on_the_fast_way(fitted):
    """Float arrays of one shape go to the loop unchecked; a NaN there is
    still reported by name and element (the checked way's message)."""
    ha, dec = sky_points(4000, seed=73)
    ha, dec = ha.reshape(40, 100), dec.reshape(40, 100)
    dec[7, 3] = np.nan
    ha[30, 1] = np.inf
    with pytest.raises(pm.NonFiniteError, match=r"enc_ha\[30, 1\] is inf"):
        fitted[2].apply(ha, dec)
    ha[30, 1] = 0.5
    with pytest.raises(pm.NonFiniteError, match=r"enc_dec\[7, 3\] is nan"):
        fitted[2].apply(ha, dec, threads=2)


def test_lanes_decline_other_models(fitted):
    """Models with added terms, context inputs or |c'|, |e'| > 0.5 are not
    the lanes' (apply runs pm_model_apply per point): _apply_lanes says so,
    and apply still equals the loop over the C call.  |c'| = |e'| = 0.5 is
    theirs."""
    ha, dec = sky_points(2003, seed=81, flipped=True)
    m = fitted[2].copy()
    m.add_term(1, k=3, l=1, m=1, param=2.0, value=1e-4)  # a periodic term
    assert not m._lanes_ok
    with pytest.raises(pm.ArgumentError, match="lanes"):
        m._apply_lanes(ha, dec, LANES[0])
    a, b = m.apply(ha, dec)
    loop = np.array([m.apply_point(h, d) for h, d in zip(ha.tolist(), dec.tolist())])
    assert np.array_equal(a, loop[:, 0]) and np.array_equal(b, loop[:, 1])
    for k in (2, 4):
        for v, ok in ((0.5, True), (-0.5, True), (np.nextafter(0.5, 1), False), (0.7, False)):
            m = fitted[2].copy()
            c = m.coefficients.copy()
            c[k] = v
            m.coefficients = c
            assert m._lanes_ok == ok, (k, v)
            if ok:
                assert_same(m, ha, dec)
            else:
                a, b = m.apply(ha, dec, threads=1)
                w = m._apply_lanes(ha, dec, "scalar")
                assert np.array_equal(a, w[0]) and np.array_equal(b, w[1])


def test_apply_uses_the_widest_lanes(fitted):
    """Model.apply (threads 1, 2, None) takes the fastest path, and gives
    the scalar call's doubles."""
    assert _pm._lanes_best in LANES
    ha, dec = sky_points(100001, seed=91, flipped=True)
    m = fitted[2]
    want = m._apply_lanes(ha, dec, "scalar")
    for t in (1, 2, None):
        a, b = m.apply(ha, dec, threads=t)
        assert np.array_equal(a, want[0]) and np.array_equal(b, want[1])
    with pytest.raises(pm.ArgumentError, match="no path 'avx3'"):
        m._apply_lanes(ha, dec, "avx3")
    for p in ("sse2", "sse2x2", "avx2", "avx2x2", "avx512", "avx512x2"):
        if p not in _pm._lanes_paths:  # a machine without it
            with pytest.raises(pm.ArgumentError, match="no path"):
                m._apply_lanes(ha, dec, p)
