#!/usr/bin/python3
"""The constants of lib/pm_detail.hpp's sincos_d: pi/2 split in three doubles
P1 + P2 + P3 (P1, P2 with 33 significant bits, so that k*P1 and k*P2 are exact
for |k| <= 2^20), from 110 digits of pi in exact rational arithmetic, and 2/pi.

    /usr/bin/python3 tests/ref/sincos_split.py
"""
import math
from decimal import Decimal, getcontext
from fractions import Fraction

getcontext().prec = 120
PI = Decimal("3.14159265358979323846264338327950288419716939937510"
             "58209749445923078164062862089986280348253421170679821480865")


def keep_bits(x, bits):
    """x > 0 truncated to its first `bits` significant bits (exact)."""
    e = math.floor(math.log2(x))
    scale = Fraction(2) ** (bits - 1 - e)
    return Fraction(math.floor(x * scale)) / scale


half_pi = Fraction(PI) / 2
p1 = keep_bits(half_pi, 33)
p2 = keep_bits(half_pi - p1, 33)
p3 = float(half_pi - p1 - p2)
assert float(p1) == p1 and float(p2) == p2
print("P1 = %r, P2 = %r, P3 = %r" % (float(p1), float(p2), p3))
print("2/pi = %r" % float(1 / half_pi))
print("left after P1 + P2 + P3: %.3g" % float(half_pi - p1 - p2 - Fraction(p3)))
