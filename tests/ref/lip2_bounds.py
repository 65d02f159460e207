#!/usr/bin/python3
"""lip2_bounds.py - bounds on the second derivative of the anisotropic
displacement per unit coefficient, for lib/model.cpp (second_rate): the
inverse's predicted stop (pm.h, pm_model_invert Note 1) needs
|D(x + h) - D(x) - D'(x) h| <= (M / 2) |h|^2, M = sup over positions and unit
directions u of |d^2/ds^2 D(x + s u)|, x = (ha, dec) in radians.

A harmonic term is f(t, d) b_k(t', d'): f = N_lm Y_lm (the library's
normalisation), b_k the tangent components of base vector k (at the
index-shifted position for k = 1, 2; a shift does not change a supremum).
Product rule: M <= F2 B0 + 2 F1 B1 + F0 B2 with F_i, B_i the suprema of the
i-th directional derivative's magnitude of f and b over positions and unit
directions.  Measured here on a grid (720 declinations x 144 phases of m t
x 72 directions); lib/model.cpp takes 1.25 times these.

Pure Python (no numpy needed).  Prints the table lib/model.cpp holds.
"""
import math

ND, NP, NU = 720, 144, 72


def norm_lm(l, m):
    if m == 0:
        return 2.0 if l >= 2 else 1.0
    f = 1.0
    k = 2 * l - 1
    while k > 1:
        f *= k
        k -= 2
    return 1.0 / f


def legendre(L, d):
    """Q[l][m] and its first and second derivatives in d: P_l^m(sin d) with
    cos^m d for (1 - x^2)^(m/2), no Condon-Shortley phase (harmonics_n)."""
    s, c = math.sin(d), math.cos(d)
    Q = [[0.0] * (L + 1) for _ in range(L + 1)]
    Q1 = [[0.0] * (L + 1) for _ in range(L + 1)]
    Q2 = [[0.0] * (L + 1) for _ in range(L + 1)]
    pmm, d1, d2 = 1.0, 0.0, 0.0
    for m in range(L + 1):
        if m >= 1:
            # pmm_m = (2m-1) c pmm_{m-1}
            pmm, d1, d2 = ((2 * m - 1) * c * pmm,
                           (2 * m - 1) * (c * d1 - s * pmm),
                           (2 * m - 1) * (c * d2 - 2 * s * d1 - c * pmm))
        p2 = (0.0, 0.0, 0.0)
        p1 = (pmm, d1, d2)
        Q[m][m], Q1[m][m], Q2[m][m] = p1
        for l in range(m + 1, L + 1):
            a, b = (2 * l - 1), (l + m - 1)
            v = (a * s * p1[0] - b * p2[0]) / (l - m)
            v1 = (a * (c * p1[0] + s * p1[1]) - b * p2[1]) / (l - m)
            v2 = (a * (-s * p1[0] + 2 * c * p1[1] + s * p1[2]) - b * p2[2]) / (l - m)
            p2, p1 = p1, (v, v1, v2)
            Q[l][m], Q1[l][m], Q2[l][m] = p1
    return Q, Q1, Q2


def harmonic_bounds(L):
    """F0, F1, F2 per (l, m), m >= 0 (sin and cos have the same suprema)."""
    F = {}
    dirs = [(math.cos(2 * math.pi * i / NU), math.sin(2 * math.pi * i / NU)) for i in range(NU)]
    for i in range(ND + 1):
        d = -math.pi / 2 + math.pi * i / ND
        Q, Q1, Q2 = legendre(L, d)
        for l in range(L + 1):
            for m in range(l + 1):
                n = norm_lm(l, m)
                q, q1, q2 = Q[l][m] * n, Q1[l][m] * n, Q2[l][m] * n
                f0, f1, f2 = F.get((l, m), (0.0, 0.0, 0.0))
                for j in range(NP if m else 1):
                    ph = 2 * math.pi * j / NP
                    C, S = math.cos(ph), math.sin(ph)
                    # f = q C(m t); f_t = -m q S, f_d = q1 C; f_tt = -m^2 q C,
                    # f_td = -m q1 S, f_dd = q2 C
                    ft, fd = -m * q * S, q1 * C
                    ftt, ftd, fdd = -m * m * q * C, -m * q1 * S, q2 * C
                    f0 = max(f0, abs(q * C))
                    f1 = max(f1, math.hypot(ft, fd))
                    for (u, w) in dirs:
                        f2 = max(f2, abs(ftt * u * u + 2 * ftd * u * w + fdd * w * w))
                F[(l, m)] = (f0, f1, f2)
    return F


def base_bounds():
    """B0, B1, B2: the base vectors' tangent components (base_uv), suprema
    over positions and unit directions of |b|, |db/ds|, |d^2 b/ds^2|."""
    h = 1e-4
    dirs = [(math.cos(2 * math.pi * i / NU), math.sin(2 * math.pi * i / NU)) for i in range(NU)]

    def b(k, t, d):
        st, ct, sd, cd = math.sin(t), math.cos(t), math.sin(d), math.cos(d)
        return {1: (-sd * ct, st), 2: (-sd * st, -ct), 3: (cd, 0.0), 4: (-sd, 0.0),
                5: (0.0, -1.0), 6: (1.0, 0.0)}[k]
    B = [0.0, 0.0, 0.0]
    n = 90
    for k in range(1, 7):
        for i in range(n + 1):
            for j in range(n):
                t, d = 2 * math.pi * j / n, -math.pi / 2 + math.pi * i / n
                v = b(k, t, d)
                B[0] = max(B[0], math.hypot(*v))
                for (u, w) in dirs[::4]:
                    vp = b(k, t + h * u, d + h * w)
                    vm = b(k, t - h * u, d - h * w)
                    B[1] = max(B[1], math.hypot((vp[0] - vm[0]) / (2 * h), (vp[1] - vm[1]) / (2 * h)))
                    B[2] = max(B[2], math.hypot((vp[0] - 2 * v[0] + vm[0]) / h ** 2,
                                                (vp[1] - 2 * v[1] + vm[1]) / h ** 2))
    return B


def main():
    L = 10
    F = harmonic_bounds(L)
    B = base_bounds()
    print("base vectors: B0 %.4f B1 %.4f B2 %.4f" % tuple(B))
    print("l: max over m of F2 B0 + 2 F1 B1 + F0 B2 (F0, F1, F2 of the worst m)")
    for l in range(1, L + 1):
        best = max(((F[(l, m)][2] * B[0] + 2 * F[(l, m)][1] * B[1] + F[(l, m)][0] * B[2]), m)
                   for m in range(l + 1))
        f = F[(l, best[1])]
        print("%2d %8.3f   (m %d: %.3f %.3f %.3f)" % (l, best[0], best[1], f[0], f[1], f[2]))


if __name__ == "__main__":
    main()
