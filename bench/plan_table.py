#!/usr/bin/python3
"""plan_table.py - the tables of docs/model.md ("How many points does the
plan save?") from build/bench/plan.jsonl (make bench-plan).

    /usr/bin/python3 bench/plan_table.py build/bench/plan.jsonl

Simulated: per setting and order, the change in points the plan needs to
reach each reference design's held-out error (its size in parentheses);
">" where the plan does not reach it within the benchmark's range.  Real
runs: the same against the evenly spread subset and random subsets, on the
cross-validated error of the points not chosen.
"""
import json
import sys


def pct(need, n):
    if need is None:
        return "not reached"
    return "%+.0f%%" % (100.0 * (need / n - 1))


def main(path):
    rows = [json.loads(line) for line in open(path) if line.strip()]
    sim = [r for r in rows if r["kind"] == "simulated"]
    real = [r for r in rows if r["kind"] == "real"]
    print("| setting | order | vs golden spiral | vs MountWizzard4 alt-az grids | vs random stars |")
    print("|---|---|---|---|---|")
    seen = []
    for r in sim:
        key = (r["setting"], r["order"])
        if key not in seen:
            seen.append(key)
    for setting, order in seen:
        group = [r for r in sim if r["setting"] == setting and r["order"] == order]

        def cells(prefix):
            out = []
            for r in group:
                if r["reference"].startswith(prefix):
                    label = r["reference"][len("MW4 grid "):] + ": " if prefix == "MW4" else ""
                    out.append("%s%s (%d)" % (label, pct(r["plan_needs"], r["n"]), r["n"]))
            return ", ".join(out)

        taken = group[0]["taken"]
        name = setting + (" (%d taken)" % taken if taken else "")
        print("| %s | %d | %s | %s | %s |" % (name, order, cells("golden"), cells("MW4"),
                                              cells("random")))
    print()
    print("| run | order | N | CV error: spread / random / plan | plan needs (vs spread) | random needs |")
    print("|---|---|---|---|---|---|")
    for r in real:
        print("| %s | %d | %d | %.3f\" / %.3f\" / %.3f\" | %s | %s |" % (
            r["run"], r["order"], r["n"], r["spread_cv_arcsec"], r["random_cv_arcsec"],
            r["plan_cv_arcsec"], pct(r["plan_needs"], r["n"]), pct(r["random_needs"], r["n"])))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "build/bench/plan.jsonl")
