#!/usr/bin/env python3
"""prune_case.py - the run behind tests/check_explain_reading.c's backward-pass
test: a fork mount of tests/ref/indep_gen.py (an independent numpy gimbal)
with a temperature drift of 3.06"/degC and a tube sag of -10.0" hidden under
2.7" noise, half the sky.  The night cools steadily, so a drift through the
night reads much of the temperature term: against an order-0 baseline the
forward search names time_drift first, then the sag and the temperature,
and the backward pass withdraws the time drift.  (Found by
tests/ref/explain_campaign.py, case combo2_temperature+tube_flexure_fork_06.)

Usage: /usr/bin/python3 tests/ref/prune_case.py [OUT]
       (default tests/data/indep_temp_sag_fork.dat)
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import indep_gen  # noqa: E402

CFG = {"aniso": 0.0, "aniso_order": 1, "coverage": "half",
       "effects": [{"name": "temperature", "size": 3.0596948365512304},
                   {"name": "tube_flexure", "size": -10.00128420854293}],
       "el_limit": 22.398220107480462, "geom": 363.2888343654769,
       "index_deg": 0.2990620980499969, "lat": 37.62854890444147, "mount": "fork",
       "n": 135, "noise": 2.7032556962819596, "seed": 548598278}


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "data", "indep_temp_sag_fork.dat")
    rows, truth = indep_gen.gen(CFG)
    indep_gen.write_run(out, rows, truth)
    return 0


if __name__ == "__main__":
    sys.exit(main())
