#!/usr/bin/env python3
"""generic_case.py - the runs behind tests/check_explain_reading.c's test of
the generic reading (both found by tests/ref/explain_campaign.py).

A degree-2 distortion of tests/ref/indep_gen.py's gimbal parameters (an
independent numpy gimbal) hidden under noise.  A periodic term of a few
cycles holds part of it (the azimuth angle's cos^2(el) cos 2az is half a
two-cycle azimuth term) and wins the false-alarm ranking; order 2 holds all
of it and the periodic term adds nothing beyond.  explain must name
higher_order, not the periodic term.

tests/data/indep_ho_altaz.dat: alt-az, 133 points, full sky, 1.62" noise,
6.68" RMS of distortion (campaign case single_higher_order_altaz_08; read
as 'ha_periodic:2' before the generic reading).
tests/data/indep_ho_gem.dat: German mount, 269 points, half the sky, 2.87"
noise, 23.8" RMS (single_higher_order_gem_16; read as 'ha_periodic:4').

And the case the generic reading does not take, for the smooth alternative:
tests/data/indep_ho_fork_dec.dat: fork mount, 159 points, one pier side,
1.94" noise, 19.8" RMS (single_higher_order_fork_09).  Its declination
residuals rise and fall like 4 cycles per revolution over the 133 deg of
declination sampled (1.5 cycles): dec_periodic:4 passes at 10^-25.5, order 2
given it does not pass, and it adds nothing given order 2.  explain keeps
the two-term reading and must offer higher_order beside it as the smooth
alternative (the run cannot show the shape repeats).

Usage: /usr/bin/python3 tests/ref/generic_case.py   (writes all three into tests/data)
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import indep_gen  # noqa: E402

CASES = [
    ("indep_ho_altaz.dat",
     {"mount": "altaz", "n": 133, "seed": 770497789, "lat": -57.90359532412855,
      "el_limit": 17.76498929572574, "noise": 1.6181809022483622, "coverage": "full",
      "index_deg": 1.1319721315877493, "geom": 110.0006343955418, "aniso": 30.0,
      "aniso_order": 1, "effects": [{"name": "higher_order", "size": 6.68285027310978}]}),
    ("indep_ho_gem.dat",
     {"mount": "gem", "n": 269, "seed": 1757057395, "lat": 60.43679238956101,
      "el_limit": 18.962834742723373, "noise": 2.872469262742089, "coverage": "half",
      "index_deg": 2.960893268692846, "geom": 78.89402608894969, "aniso": 3.0,
      "aniso_order": 1, "effects": [{"name": "higher_order", "size": 23.84407409037782}]}),
    ("indep_ho_fork_dec.dat",
     {"mount": "fork", "n": 159, "seed": 20947471, "lat": -23.07974608650787,
      "el_limit": 17.427736790530368, "noise": 1.942084413611793, "coverage": "pier_east",
      "index_deg": 1.1761715087936342, "geom": 198.47588213298764, "aniso": 30.0,
      "aniso_order": 1, "effects": [{"name": "higher_order", "size": 19.776128383348553}]}),
]


def main():
    data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
    for name, cfg in CASES:
        rows, truth = indep_gen.gen(cfg)
        indep_gen.write_run(os.path.join(data, name), rows, truth)
    return 0


if __name__ == "__main__":
    sys.exit(main())
