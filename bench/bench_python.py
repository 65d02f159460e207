"""bench_python.py - the Python package's vectorised apply against a Python
loop over the per-point C call (docs/python.md, "Speed").

Run by `make bench-python` (PYTHONPATH=build/python).  For 10^6 encoder
positions and a fitted model (examples/sim_gem.dat at orders 1 and 2):

  vectorised   Model.apply(ha, dec, threads=1): one call, the loop in C++
               without the GIL, on one core, several points at a time
               (python/apply_simd.hpp: the fastest path the machine has)
  C loop       Model._apply_lanes(ha, dec, "scalar"): the same loop calling
               pm_model_apply per point (the vectorised apply before the
               lanes; what a C program's loop over the call costs)
  paths        Model._apply_lanes(ha, dec, p): each path p the machine has
               (sse2, sse2x2, avx2, avx2x2, avx512, avx512x2), one core
  all cores    Model.apply(ha, dec): the same loop split over the cores
               (os.cpu_count())
  loop, C call [m.apply_point(h, d) for h, d in zip(...)]: a Python loop over
               the bare binding of pm_model_apply (the thinnest per-point call)
  loop, apply  for i in range(n): m.apply(ha[i], dec[i]): the vectorised
               function called per point on numpy scalars

Each time is the best of R repetitions (the machine is shared).  Prints a
table and writes build/bench/python.json.  Checks that all three give the same
doubles; never fails on a timing.
"""
import json
import os
import platform
import sys
import time

import numpy as np

import pm

TOP = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
N = int(os.environ.get("PM_BENCH_N", 1000000))
REPS = int(os.environ.get("PM_BENCH_REPS", 5))


def best(f, reps):
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        r = f()
        t.append(time.perf_counter() - t0)
    return min(t), r


def main():
    rng = np.random.default_rng(1)
    ha = rng.uniform(-np.pi, np.pi, N)
    dec = rng.uniform(-1.2, 1.5, N)
    hl, dl = ha.tolist(), dec.tolist()
    rows = []
    for order in (1, 2):
        m = pm.fit_run(os.path.join(TOP, "examples", "sim_gem.dat"), order=order).model
        t_vec, (a, b) = best(lambda: m.apply(ha, dec, threads=1), REPS)
        t_one, (oa, ob) = best(lambda: m._apply_lanes(ha, dec, "scalar"), REPS)
        paths = {}  # each path this machine has, one core
        for p in pm._pm._lanes_paths[1:]:
            t_p, (wa, wb) = best(lambda: m._apply_lanes(ha, dec, p), REPS)
            paths[p] = (t_p, np.array_equal(wa, oa) and np.array_equal(wb, ob))
        t_par, (pa, pb) = best(lambda: m.apply(ha, dec), REPS)
        ap = m.apply_point
        t_loop, lp = best(lambda: [ap(h, d) for h, d in zip(hl, dl)], max(1, REPS // 2))
        n_slow = N // 10  # the per-point public call is slow: a tenth, scaled
        t_slow, sl = best(lambda: [m.apply(ha[i], dec[i]) for i in range(n_slow)], 1)
        t_slow *= N / n_slow
        lp = np.array(lp)
        same = (all(ok for _, ok in paths.values()) and np.array_equal(a, lp[:, 0]) and np.array_equal(oa, a) and np.array_equal(ob, b) and np.array_equal(pa, a) and np.array_equal(pb, b) and np.array_equal(b, lp[:, 1]) and
                np.array_equal(np.array(sl), lp[:n_slow]))
        rows.append({"order": order, "n_terms": m.n_terms, "n": N,
                     "vectorised_s": t_vec, "all_cores_s": t_par, "cores": os.cpu_count(),
                     "path": pm._pm._lanes_best, "c_loop_s": t_one,
                     "ns_per_point_c_loop": t_one / N * 1e9,
                     "ns_per_point_paths": {p: t / N * 1e9 for p, (t, _) in paths.items()},
                     "loop_c_call_s": t_loop, "loop_apply_s": t_slow,
                     "ns_per_point_vectorised": t_vec / N * 1e9,
                     "ns_per_point_loop_c_call": t_loop / N * 1e9,
                     "ratio_loop_c_call": t_loop / t_vec, "ratio_loop_apply": t_slow / t_vec,
                     "ratio_loop_c_call_all_cores": t_loop / t_par,
                     "identical": bool(same)})
    print("pm Python package: %d-point apply, best of %d (python %s, numpy %s, %s, path %s, "
          "load average %.2f)" % (N, REPS, platform.python_version(), np.__version__,
                                  platform.machine(), pm._pm._lanes_best, os.getloadavg()[0]))
    print("%-6s %-6s %12s %12s %10s %13s %14s %10s %10s %10s %s" % (
        "order", "terms", "vectorised", "all cores", "C loop", "loop C call", "loop apply()",
        "x C call", "x (cores)", "x apply()", "same doubles"))
    for r in rows:
        print("%-6d %-6d %10.3f s %10.3f s %8.3f s %11.3f s %12.3f s %9.1fx %9.1fx %9.1fx %s" % (
            r["order"], r["n_terms"], r["vectorised_s"], r["all_cores_s"], r["c_loop_s"],
            r["loop_c_call_s"], r["loop_apply_s"], r["ratio_loop_c_call"],
            r["ratio_loop_c_call_all_cores"], r["ratio_loop_apply"],
            "yes" if r["identical"] else "NO"))
    print("(%d cores; per point, one core: %.1f ns at order 1, %.1f ns at order 2; the C loop "
          "%.1f ns, %.1f ns; the Python loop over the C call %.0f ns, %.0f ns)" % (
              os.cpu_count(), rows[0]["ns_per_point_vectorised"], rows[1]["ns_per_point_vectorised"],
              rows[0]["ns_per_point_c_loop"], rows[1]["ns_per_point_c_loop"],
              rows[0]["ns_per_point_loop_c_call"], rows[1]["ns_per_point_loop_c_call"]))
    for r in rows:
        print("order %d, one core, per point (x the loop over the C call): %s" % (
            r["order"], ", ".join("%s %.1f ns (%.0fx)" % (p, t, r["ns_per_point_loop_c_call"] / t)
                                  for p, t in r["ns_per_point_paths"].items())))
    out = os.path.join(TOP, "build", "bench")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "python.json"), "w") as f:
        json.dump({"python": platform.python_version(), "numpy": np.__version__,
               "loadavg": os.getloadavg(), "rows": rows}, f,
                  indent=1)
    print("wrote build/bench/python.json")
    return 0 if all(r["identical"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
