"""bench_lanes_insns.py - instructions per point of the Python package's
vectorised apply, by width (docs/python.md, "Speed"): repeatable where the
timings of bench_python.py are not (the machine is shared).

Run by `make bench-python-insns` (PYTHONPATH=build/python; needs valgrind).
Runs this file again under callgrind: Model._apply_lanes(ha, dec, path) on
N points (10^5) of examples/sim_gem.dat's fits at orders 1 and 2, for the
paths scalar (pm_model_apply per point), sse2, sse2x2, avx2 and avx2x2
(those the CPU has); valgrind does not run AVX-512, so those paths are timed
by bench_python.py only.  Reports the instructions of pm_apply_lanes
(inclusive: the scalar calls for the points the lanes hand back too) per
point.
"""
import os
import re
import subprocess
import sys
import tempfile

N = int(os.environ.get("PM_BENCH_INSNS_N", 100000))
TOP = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
PATHS = ["scalar", "sse2", "sse2x2", "avx2", "avx2x2"]


def child(order, path):
    import numpy as np
    import pm
    rng = np.random.default_rng(1)
    ha = rng.uniform(-np.pi, np.pi, N)
    dec = rng.uniform(-1.2, 1.5, N)
    m = pm.fit_run(os.path.join(TOP, "examples", "sim_gem.dat"), order=order).model
    if path in pm._pm._lanes_paths:
        m._apply_lanes(ha, dec, path)


def inclusive(out, func="pm_apply_lanes"):
    txt = subprocess.run(["callgrind_annotate", "--inclusive=yes", out], capture_output=True,
                         text=True, check=True).stdout
    for line in txt.splitlines():
        if re.search(r"[:\s]%s\(" % func, line) and "[" in line:
            return int(line.split()[0].replace(",", ""))
    return None  # not run (a path the CPU has not got)


def main():
    if len(sys.argv) == 3:
        child(int(sys.argv[1]), sys.argv[2])
        return 0
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for order in (1, 2):
            row = []
            for p in PATHS:
                out = os.path.join(tmp, "cg.%d.%s" % (order, p))
                subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out,
                                sys.executable, __file__, str(order), p], check=True,
                               capture_output=True)
                c = inclusive(out)
                row.append("%10.0f" % (c / N) if c else "%10s" % "-")
            rows.append((order, row))
    print("instructions per point (callgrind, %d points; inclusive of the scalar calls the "
          "lanes hand back)" % N)
    print("%-6s" % "order" + "".join(" %10s" % p for p in PATHS))
    for order, r in rows:
        print("%-6d" % order + "".join(" " + x for x in r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
