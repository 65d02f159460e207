"""A fork's run near the pole, from outside probe AA's own simulator
(sim_aa.py; its exp5.py, stop 45): 60 stars at declinations 75-88 deg,
latitude 40, random classical terms (IH, ID up to degrees, CH, NP, MA, ME),
a sag TF = -15" (the simulator's sign: explain reads +15"), 1" noise.
Explain had read the sag held by its order-1 terms as 224.66" +- 32.12",
"consistent with a pure sag".

    /usr/bin/python3 tests/ref/sim_aa_fork_pole.py tests/data/fork_pole_sag.dat
"""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
from sim_aa import sky, equ_run, write_equ

LAT = 40
kind, sk, TF, seed = 'fork', 'pole75_88', -15, 0
rng = np.random.default_rng(seed * 1000 + TF + len(sk) * 7 + len(kind))
n, noise = 60, 1.0
s = sky(n, rng, LAT, elmin=15, decband=(75, 88))
h, d = s[:, 0], s[:, 1]
cls = dict(IH=rng.uniform(-3600, 3600), ID=rng.uniform(-1800, 1800), CH=rng.uniform(-60, 60),
           NP=rng.uniform(-40, 40), MA=rng.uniform(-120, 120), ME=rng.uniform(-120, 120))
t = equ_run(h, d, LAT, rng, noise=noise, pier=None, TF=TF, **cls)
write_equ(sys.argv[1], LAT, *t[:4], None)
