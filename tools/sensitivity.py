#!/usr/bin/env python3
"""sensitivity.py - how large must an effect hidden in a real recording be
before pmfit explain names it?  (docs/explain.md, "Real recordings with
injected effects".)

For every run and every effect of explain's vocabulary, inject the effect
into the real run with `pmfit simulate --inject EFFECT=SIZEsigma --into RUN
OUT` (the recording's observed positions displaced, its noise and everything
it holds unchanged) at sizes growing on a grid (in units of the run's
baseline sigma), several trials per size (periodic: 8 phases; outliers and
higher order: 8 seeds; the others: both signs, as nothing else varies on a
fixed recording), and report the smallest size from which explain names the
injected effect in >= 90% of trials (and at every larger size of the grid),
with the recovered size against the injected one there.  Effects the run
cannot carry (constant temperature, no time, one pier side) are reported as
not applicable; effects explain already finds in the untouched run are
reported as held by the run.

Usage: python3 tools/sensitivity.py [--data DIR] [--pmfit PATH] [--runs NAME ...]
                                    [--json OUT] [--quick]
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

GRID = [0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0]
OUTLIER_GRID = [3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0]

RUNS = {
    "mmt/k_and_e.dat": {"mount": "altaz", "G1": 60, "G2": 60, "G_low": 3},
    "celestial/gem-28.dat": {"mount": "equatorial", "G1": 144, "G2": 144},
    "celestial/cgx-l-data.dat": {"mount": "equatorial", "G1": 144, "G2": 144},
}


def effects(info):
    """(label, inject spec, explain name, baseline order, trials kind)."""
    out = [
        ("ha_periodic:%d" % info["G1"], "ha_periodic:%d" % info["G1"], "ha_periodic", 1, "phase"),
        ("dec_periodic:%d" % info["G2"], "dec_periodic:%d" % info["G2"], "dec_periodic", 1, "phase"),
    ]
    if "G_low" in info:
        out.append(("ha_periodic:%d (runout)" % info["G_low"], "ha_periodic:%d" % info["G_low"],
                    "ha_periodic", 1, "phase"))
    if info["mount"] == "equatorial":
        out.append(("pier_side (i@W)", "i@W", "pier_side", 1, "sign"))
    out += [
        ("refraction", "refraction", "refraction", 1, "sign"),
        ("tube_flexure (order-0 baseline)", "tube_flexure", "tube_flexure", 0, "sign"),
        ("temperature", "temperature", "temperature", 1, "sign"),
        ("time_drift", "time_drift", "time_drift", 1, "sign"),
        ("hysteresis", "hysteresis", "hysteresis", 1, "sign"),
        ("higher_order", "higher_order", "higher_order", 1, "seed"),
        ("outlier", "outlier", "outlier", 1, "seed"),
    ]
    return out


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd), p.returncode, p.stderr.strip()))
    return p


def explain(pmfit, path, order):
    return json.loads(run([pmfit, "explain", path, "--order", str(order), "--json"]).stdout)


def read_header(path):
    """The injection's sigma, the parameter in arcsec and the moved lines of OUT."""
    size = sigma = None
    moved = []
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            if "sigma " in line and "the recording" in line:
                sigma = float(line.split("sigma ")[1].split()[0])
            if line.startswith("# injected"):
                size = float(line.split("of size ")[1].split()[0])
            if line.startswith("# moved lines"):
                moved = [int(x) for x in line.split(": ")[-1].split()]
    return sigma, size, moved


def matches(finding, name, G, moved):
    if finding["effect"] != name and finding.get("with") != name:
        return False
    if name.endswith("_periodic"):
        return abs(finding.get("cycles_per_rev", 0) - G) < 0.5
    if name == "outlier":
        return all(m in finding.get("lines", []) for m in moved)
    return finding["effect"] == name


def trials(kind, n):
    if kind == "phase":
        return [("--phase", str(45 * k), "--seed", "1", 1) for k in range(n)]
    if kind == "seed":
        return [("--phase", "0", "--seed", str(k + 1), 1) for k in range(n)]
    return [("--phase", "0", "--seed", "1", s) for s in (1, -1)]


def applicable(path, spec, tmp, pmfit):
    """False with a reason when injecting moves nothing (constant temperature ...)."""
    out = os.path.join(tmp, "probe.dat")
    try:
        p = run([pmfit, "simulate", "--inject", spec + "=1sigma", "--into", path, out])
    except RuntimeError as e:
        if "input it needs is missing" in str(e):
            return False, "the run does not give the input it reads (time or temperature)"
        return False, str(e).split(": ", 1)[-1][:160]
    rms = float(p.stderr.split("RMS displacement ")[1].split()[0])
    if rms <= 0:
        return False, "moves nothing on this run (the input it reads is constant)"
    return True, ""


def held(base, name, G):
    return any(matches(f, name, G, []) and name != "outlier" for f in base["findings"])


def measure(pmfit, path, eff, tmp, n_trials):
    label, spec, name, order, kind = eff
    G = float(spec.split(":")[1]) if name.endswith("_periodic") else 0
    ok, why = applicable(path, spec, tmp, pmfit)
    if not ok:
        return {"effect": label, "status": "n/a", "why": why}
    base = explain(pmfit, path, order)
    if held(base, name, G):
        return {"effect": label, "status": "held", "why": "explain finds it in the untouched run"}
    if name == "tube_flexure":  # the order-1 terms of the untouched run may hold a sag
        for it in explain(pmfit, path, 1)["interpretation"]:
            if it["what"] == "tube_flexure_in_order1" and abs(it["value"]) > 3 * it["error"]:
                return {"effect": label, "status": "held",
                        "why": "the run's order-1 terms hold a sag of %.2f\" +- %.2f\"" %
                               (it["value"], it["error"])}
    grid = OUTLIER_GRID if name == "outlier" else GRID
    rows = []
    for size in grid:
        hits, ratios, ts = 0, [], trials(kind, n_trials)
        for (po, pv, so, sv, sign) in ts:
            out = os.path.join(tmp, "inj.dat")
            run([pmfit, "simulate", "--inject", "%s=%gsigma" % (spec, sign * size), "--into", path,
                 po, pv, so, sv, out])
            sigma, size_as, moved = read_header(out)
            ex = explain(pmfit, out, order)
            hit = [f for f in ex["findings"] if matches(f, name, G, moved)]
            if hit:
                hits += 1
                if name not in ("higher_order", "outlier") and size_as:
                    ratios.append(abs(hit[0]["amplitude_arcsec"]) / abs(size_as))
        ratios.sort()
        rows.append({"size_sigma": size, "rate": hits / len(ts),
                     "recovered_over_injected": ratios[len(ratios) // 2] if ratios else None})
        # stop once two consecutive sizes reach 90%
        if len(rows) >= 2 and rows[-1]["rate"] >= 0.9 and rows[-2]["rate"] >= 0.9:
            break
    thr = None
    for k in range(len(rows)):
        if all(r["rate"] >= 0.9 for r in rows[k:]):
            thr = rows[k]
            break
    return {"effect": label, "status": "measured", "rows": rows,
            "threshold_sigma": thr["size_sigma"] if thr else None,
            "recovered_over_injected": thr["recovered_over_injected"] if thr else None}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data"))
    ap.add_argument("--pmfit", default=os.path.join(here, "..", "build", "pmfit"))
    ap.add_argument("--runs", nargs="*", default=list(RUNS))
    ap.add_argument("--json")
    ap.add_argument("--quick", action="store_true", help="4 trials, fewer effects")
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print("sensitivity.py: no data directory %s (../shared/data); nothing to do" % a.data)
        return 0
    n_trials = 4 if a.quick else 8
    result = {}
    with tempfile.TemporaryDirectory(prefix="pm_sens_") as tmp:
        # a copy: a rebuild during the hour this takes must not pull the program away
        exe = os.path.join(tmp, "pmfit")
        shutil.copy(a.pmfit, exe)
        a.pmfit = exe
        for name in a.runs:
            path = os.path.join(a.data, name)
            if not os.path.exists(path):
                print("sensitivity.py: %s absent, skipped" % path)
                continue
            base = explain(a.pmfit, path, 1)
            print("\n%s: baseline sigma %.3f\", untouched run's findings: %s" % (
                name, base["baseline"]["sigma_arcsec"],
                ", ".join(f["effect"] for f in base["findings"]) or "none"))
            print("  %-34s %-14s %s" % ("effect", "90% named at", "recovered / injected there"))
            res = []
            for eff in effects(RUNS[name]):
                r = measure(a.pmfit, path, eff, tmp, n_trials)
                res.append(r)
                if r["status"] != "measured":
                    print("  %-34s %s: %s" % (r["effect"], r["status"], r["why"]))
                elif r["threshold_sigma"] is None:
                    print("  %-34s not reached up to %g sigma" % (r["effect"], r["rows"][-1]["size_sigma"]))
                else:
                    rr = r["recovered_over_injected"]
                    print("  %-34s %-14s %s" % (r["effect"], "%g sigma" % r["threshold_sigma"],
                                                "%.2f" % rr if rr is not None else "-"))
                sys.stdout.flush()
            result[name] = {"sigma_arcsec": base["baseline"]["sigma_arcsec"],
                            "findings": [f["effect"] for f in base["findings"]], "effects": res}
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
