#!/usr/bin/env python3
"""inv_series_start.py - issue 18, stop 36: a start for pm_model_invert
from a series in the target's coordinates, tried and left out
(docs/performance.md, "A series start, tried").

One Newton step from a start within r of the solution is certified (the
predicted stop, pm_model_invert Note 1) where lip2 r^2 / 2 <= PM_INVERT_TOL
/ 2, r <= sqrt(1e-13 / lip2): ~1.5e-6 rad for the bench's model.  The cold
call starts from the closed form at D^ = 0, 2.8e-4 rad away, and so needs a
second evaluation.  A series fitted once (at pm_model_prepare) that put the
start within r would save it.  This fits, by least squares on 4,000
solved targets and checks on 2,000 others, (a) D^'s two components at the
solution, (b) the solution's unit vector, as polynomials in the target's
unit vector of degree Ls, and prints how far the predicted start is from
the solution.

  make build/libpm.a
  /usr/bin/python3 bench/tried/inv_series_start.py      (~10 s)
"""
import os
import subprocess
import sys

import numpy as np

TOP = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(TOP, "build", "inv_series_start")
KINDS = {0: "the bench's L = 2 model", 2: "terms within 1 deg / 1'", 1: "terms within 10 deg / 10'"}


def samples(kind, n, pos_seed):
    out = subprocess.run([BIN, str(kind), "11", str(n), "2", str(pos_seed)], check=True,
                         capture_output=True, text=True).stdout
    return np.array([[float(v) for v in line.split()] for line in out.splitlines()])


def unit(a, d):
    return np.array([np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)])


def monomials(a, d, degree):
    x, y, z = unit(a, d)
    cols = [x**i * y**j * z**k for i in range(degree + 1) for j in range(degree + 1 - i)
            for k in range(min(2, degree + 1 - i - j))]  # (z^2 = 1 - x^2 - y^2)
    return np.array(cols).T


def main():
    subprocess.run(["g++", "-O2", "-std=c++17", "-I" + os.path.join(TOP, "include"),
                    "-I" + os.path.join(TOP, "lib"),
                    os.path.join(TOP, "bench", "tried", "inv_series_start.cpp"),
                    os.path.join(TOP, "build", "libpm.a"), "-o", BIN], check=True)
    for kind, name in KINDS.items():
        tr, te = samples(kind, 4000, 1), samples(kind, 2000, 2)
        lip2 = tr[0, 6]
        print("%s: lip2 %.3g, |D^| rms %.2e rad; one Newton step certified from within %.1e rad"
              % (name, lip2, np.sqrt(np.mean(tr[:, 2]**2 + tr[:, 3]**2)), np.sqrt(1e-13 / lip2)))
        print("   Ls  terms   (a) D^ error rms / max      (b) solution error rms / max")
        xtr, xte = unit(tr[:, 4], tr[:, 5]).T, unit(te[:, 4], te[:, 5]).T
        for degree in (2, 4, 6, 8, 10):
            A, B = monomials(tr[:, 0], tr[:, 1], degree), monomials(te[:, 0], te[:, 1], degree)
            cd, *_ = np.linalg.lstsq(A, tr[:, 2:4], rcond=None)
            rd = np.linalg.norm(B @ cd - te[:, 2:4], axis=1)
            cx, *_ = np.linalg.lstsq(A, xtr, rcond=None)
            p = B @ cx
            rx = np.linalg.norm(p / np.linalg.norm(p, axis=1)[:, None] - xte, axis=1)
            print("   %2d  %5d   %.1e / %.1e            %.1e / %.1e"
                  % (degree, A.shape[1], np.sqrt(np.mean(rd**2)), rd.max(),
                     np.sqrt(np.mean(rx**2)), rx.max()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
