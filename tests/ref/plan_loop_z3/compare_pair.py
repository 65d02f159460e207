"""A pair of nights of probe Z3's German mount (mount.py; its cmp.py, stop 45):
the old night unchanged, the new one with its periodic error tripled and
turned (PE 5" -> 15", phase 30 -> 120 deg), N stars each, 1" noise.  The
model without the periodic term held "the model still holds" for it.

    /usr/bin/python3 tests/ref/plan_loop_z3/compare_pair.py 30 104 OLD NEW

writes tests/data/cmp_pe_grew_old.dat and _new.dat (tests/check_compare.c)
as OLD and NEW."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import mount as M

BASE = dict(IH=300, ID=-120, CH=40, NP=25, MA=60, ME=-45, TF=10, PE=5.0, PEG=2, PEph=30)
CHANGE = {'none': {}, 'pe': dict(PE=15, PEph=120)}


def night(lat, n, seed, change, path, noise=1.0):
    rng = np.random.default_rng(seed)
    kw = dict(BASE)
    kw.update(CHANGE[change])
    mt = M.GEM(lat, **kw)
    A, E = M.sky_points(n, lat, rng=rng)
    M.write_run(path, mt, *M.design_obs(mt, A, E, noise, rng))


if __name__ == '__main__':
    n, s, old, new = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
    night(35.0, n, 1000 + s, 'none', old)
    night(35.0, n, 2000 + s, 'pe', new)
