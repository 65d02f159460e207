"""Fixtures of the pm package's tests: where the tree, the build and the real
runs are, the C programs to compare with, and simulated runs.

Run by `make test` (tests/check_python.c) with PYTHONPATH=build/python,
PM_TOP, PM_BUILD and PM_DATA_DIR set; by hand:
    make python && PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests
"""
import os
import subprocess

import numpy as np
import pytest

TOP = os.environ.get("PM_TOP") or os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.path.join(TOP, os.environ.get("PM_BUILD", "build"))
PMFIT = os.path.join(BUILD, "pmfit")
PM_REF = os.path.join(BUILD, "python", "pm_ref")
DATA = os.environ.get("PM_DATA_DIR") or os.path.join(TOP, "..", "shared", "data")
REAL_RUNS = ["mmt/k_and_e.dat", "celestial/gem-28.dat", "celestial/cgx-l-data.dat"]


def run_cmd(*args, check=True):
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError("%s failed (%d): %s" % (" ".join(map(str, args)), p.returncode,
                                                     p.stderr))
    return p


def real_run(name):
    path = os.path.join(DATA, name)
    if not os.path.exists(path):
        pytest.skip("real run %s not found (PM_DATA_DIR=%s; ../shared/data)" % (name, DATA))
    return path


def parse_model_file(path):
    """The coefficients of a model file, parsed here (float() rounds
    correctly, as strtod does): (mount, order, [(name, value)])."""
    mount = order = None
    terms = []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if t[0] == "mount":
                mount = t[1]
            elif t[0] == "order":
                order = int(t[1])
            elif t[0] in ("term", "xterm"):
                # the value: term NAME k l m VALUE, xterm NAME KIND k l m side aux param
                # VALUE; a version-4 file's 'errors' adds each one's error after it
                terms.append((t[1], float(t[5] if t[0] == "term" else t[9])))
    return mount, order, terms


@pytest.fixture(scope="session")
def sim_dir(tmp_path_factory):
    """Simulated runs made by pmfit simulate: an equatorial mount with order-2
    anisotropy and physical effects, an alt-az mount, and a fork mount."""
    d = tmp_path_factory.mktemp("sim")
    run_cmd(PMFIT, "simulate", d / "eq.dat", "--n", "300", "--order", "2", "--random-aniso", "3",
            "--effect", "temperature=0.5", "--effect", "hysteresis=1", "--effect",
            "ha_periodic:144=2", "--effect", "refraction=3", "--seed", "5")
    run_cmd(PMFIT, "simulate", d / "altaz.dat", "--mount", "altaz", "--n", "150", "--order", "1",
            "--random-aniso", "2", "--seed", "3")
    run_cmd(PMFIT, "simulate", d / "fork.dat", "--fork", "--n", "120", "--order", "1",
            "--random-aniso", "2", "--seed", "7", "--lat", "-30")
    return d


def sky_points(n, seed=1, flipped=False):
    """Encoder positions over the sky (radians), with some near the pole and
    beyond it for a German mount."""
    rng = np.random.default_rng(seed)
    ha = rng.uniform(-np.pi, np.pi, n)
    dec = rng.uniform(-1.2, 1.55, n)
    if flipped:
        dec = np.where(rng.uniform(size=n) < 0.5, np.pi - dec, dec)
    return ha, dec
