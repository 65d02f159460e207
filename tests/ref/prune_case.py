#!/usr/bin/env python3
"""prune_case.py - the runs behind tests/check_explain_reading.c's backward-pass
tests (both found by tests/ref/explain_campaign.py).

tests/data/indep_temp_sag_fork.dat: a fork mount of tests/ref/indep_gen.py (an independent numpy gimbal)
with a temperature drift of 3.06"/degC and a tube sag of -10.0" hidden under
2.7" noise, half the sky.  The night cools steadily, so a drift through the
night reads much of the temperature term: against an order-0 baseline the
forward search names time_drift first, then the sag and the temperature,
and the backward pass withdraws the time drift (campaign case
combo2_temperature+tube_flexure_fork_06).

tests/data/indep_temp_sag_gem.dat: a German mount, 290 points, a
temperature drift of 1.59"/degC and a sag of -2.80" under 1.32" noise:
against an order-0 baseline higher_order (the 16 order-1 terms, which hold
the sag exactly and part of the drift) is found first; the backward pass
withdraws it for tube flexure (campaign case
combo2_temperature+tube_flexure_gem_19).

Usage: /usr/bin/python3 tests/ref/prune_case.py   (writes both into tests/data)
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


CFG_GEM = {"aniso": 0.0, "aniso_order": 1, "coverage": "full",
           "effects": [{"name": "temperature", "size": 1.5876700849058052},
                       {"name": "tube_flexure", "size": -2.7985932206355963}],
           "el_limit": 17.862492141230014, "geom": 242.0777119541632,
           "index_deg": 1.6890539313029012, "lat": 35.18921400442932, "mount": "gem",
           "n": 290, "noise": 1.3212596409099555, "seed": 587951636}


def main():
    data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
    for cfg, name in ((CFG, "indep_temp_sag_fork.dat"), (CFG_GEM, "indep_temp_sag_gem.dat")):
        rows, truth = indep_gen.gen(cfg)
        indep_gen.write_run(os.path.join(data, name), rows, truth)
    return 0


if __name__ == "__main__":
    sys.exit(main())
