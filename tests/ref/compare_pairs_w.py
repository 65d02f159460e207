"""Pairs of nights of one unchanged alt-az mount, 20 stars each, from
gimbal_w.py (an outside probe's generator): the pair of seed 70 is the one
tests/check_compare.c holds (tests/data/cmp_w70_old.dat, cmp_w70_new.dat),
where the joint test fires by chance and the new night's own refit
cross-validates 5.7 times worse than the old model as is.

    /usr/bin/python3 tests/ref/compare_pairs_w.py tests/data 70
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gimbal_w import Mount, random_sky, write_run  # noqa: E402


def pair(seed):
    r = np.random.RandomState(seed + 300)
    par = dict(IH=r.uniform(-900, 900), ID=r.uniform(-600, 600), MA=r.uniform(-300, 300),
               ME=r.uniform(-300, 300), NP=r.uniform(-60, 60), CH=r.uniform(-100, 100),
               TF=r.uniform(0, 30))
    m = Mount('altaz', lat=r.uniform(25, 55), noise=1.0, HO=0.0, hoseed=seed, **par)
    rng = np.random.RandomState(seed + 900)
    s1, s2 = random_sky(m, 20, rng)
    o1 = m.observe(s1, s2, m.side_for(s1), rng)
    s1, s2 = random_sky(m, 20, rng)
    o2 = m.observe(s1, s2, m.side_for(s1), rng)
    return m, o1, o2


if __name__ == "__main__":
    out, seed = sys.argv[1], int(sys.argv[2])
    m, o1, o2 = pair(seed)
    cmd = "(tests/ref/compare_pairs_w.py %d)" % seed
    write_run(os.path.join(out, "cmp_w%d_old.dat" % seed), m, *o1, comment=cmd)
    write_run(os.path.join(out, "cmp_w%d_new.dat" % seed), m, *o2, comment=cmd)
