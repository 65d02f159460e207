#!/usr/bin/python3
"""model_ref.py - independent reference values for tests/check_model.c.

Run from the top of the repository:

    /usr/bin/python3 tests/ref/model_ref.py

It writes tests/ref/model_ref.h and prints the rank table.  Deterministic
(fixed seed); needs numpy and scipy only.

What it computes, from the formulas of Pal et al. (2016) and the
normalisation documented in include/pm.h, without reference to lib/:

1) The term functions Y_lm(t,d) p_k(t,d) (3-vectors) for L = 4 at a table of
   encoder positions (t, d), including d beyond +-90 deg, within 1e-6 rad of
   the pole and t near +-pi.
     p = (cos d cos t, cos d sin t, sin d)
     p_1..p_6 from Eq. (tdvectexpansion).
     Y_lm = N_lm * Pbar_l^|m|(sin d) * (cos m t  or  sin |m| t  for m < 0)
     Pbar_l^m(x) = P_l^m(x) without the Condon-Shortley phase and with the
       factor (1-x^2)^(m/2) replaced by cos(d)^m (signed, so that
       Y(t+pi, pi-d) = Y(t, d)).
     N_lm = 1/(2l-1)!! for m != 0; for m = 0: 1 if l <= 1 else 2.
   P_l^m comes from scipy.special.lpmv, which includes the Condon-Shortley
   phase (-1)^m and computes the factor as (1-x*x)^(m/2) from x = sin d.
   Near the pole that factor loses precision (1 - x*x has a relative error
   ~1e-16/cos^2 d), so it is divided out with the same expression and
   cos(d)^m is multiplied in.  The quotient P_l^m/(1-x^2)^(m/2) is the m-th
   derivative of the Legendre polynomial P_l; it is cross-checked below
   against numpy.polynomial.legendre (relative 1e-12), so the table does not
   depend on how scipy evaluates the factor.

2) Rank check of the term set that pm_model_init keeps (the dropping rule of
   include/pm.h, Note 2 of pm_model_init): for L = 0..5, the 2-component
   tangent design (projections of Y_lm p_k on e_t = (-st, ct, 0) and
   e_d = (-sd ct, -sd st, cd)) over random sky points, its numerical rank
   versus 4L^2 + 12L + 6, and the rank of all 6(L+1)^2 terms (which must be
   the same: every dropped term is a combination of kept ones).
"""

import math
import os
import sys

import numpy as np
from numpy.polynomial import legendre as npleg
from scipy.special import lpmv

L_TABLE = 4
L_RANK_MAX = 5
SEED = 20160101
RANK_POINTS = 3000
RANK_RTOL = 1e-10  # singular values below RANK_RTOL * s_max count as zero

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "model_ref.h")


def norm_lm(l, m):
    if m == 0:
        return 1.0 if l <= 1 else 2.0
    f = 1.0
    for k in range(2 * l - 1, 1, -2):
        f *= k
    return 1.0 / f


def pbar_over_cos(l, m, x):
    """P_l^m(x) / (1-x^2)^(m/2), no Condon-Shortley phase, via lpmv."""
    q = 1.0 - x * x
    if m == 0:
        return lpmv(0, l, x)
    if q <= 0.0:
        raise ValueError("point exactly at the pole: choose another")
    return (-1.0) ** m * lpmv(m, l, x) / q ** (m / 2.0)


def pbar_over_cos_poly(l, m, x):
    """The same quantity as the m-th derivative of Legendre P_l."""
    c = np.zeros(l + 1)
    c[l] = 1.0
    return npleg.legval(x, npleg.legder(c, m)) if m > 0 else npleg.legval(x, c)


def harmonics(L, t, d):
    """dict (l, m) -> Y_lm(t, d) in the paper's normalisation."""
    x, cd = math.sin(d), math.cos(d)
    Y = {}
    for l in range(L + 1):
        for m in range(-l, l + 1):
            am = abs(m)
            core = pbar_over_cos(l, am, x)
            poly = pbar_over_cos_poly(l, am, x)
            if abs(core - poly) > 1e-12 * max(1.0, abs(poly)):
                raise AssertionError("lpmv/polynomial mismatch l=%d m=%d d=%r: "
                                     "%r vs %r" % (l, am, d, core, poly))
            trig = math.cos(am * t) if m >= 0 else math.sin(am * t)
            Y[(l, m)] = norm_lm(l, m) * core * cd ** am * trig
    return Y


def base_vectors(t, d):
    st, ct, sd, cd = math.sin(t), math.cos(t), math.sin(d), math.cos(d)
    return [
        np.array([0.0, -sd, cd * st]),
        np.array([sd, 0.0, -cd * ct]),
        np.array([-cd * st, cd * ct, 0.0]),
        np.array([sd * st, -sd * ct, 0.0]),
        np.array([sd * ct, sd * st, -cd]),
        np.array([-st, ct, 0.0]),
    ]


def terms(L, t, d):
    """array [(L+1)^2][6][3] in the layout of pm_terms_eval:
    j = l*l + l + m, k = 1..6."""
    Y = harmonics(L, t, d)
    P = base_vectors(t, d)
    out = np.zeros(((L + 1) ** 2, 6, 3))
    for l in range(L + 1):
        for m in range(-l, l + 1):
            for k in range(6):
                out[l * l + l + m, k] = Y[(l, m)] * P[k]
    return out


def dropped(k, l, m):
    """pm_model_init's rule (include/pm.h, pm_model_init Note 2)."""
    if l == 0:
        return False
    if k == 6 and abs(m) <= l - 1:
        return True
    if k == 1 and m >= 1:
        return True
    if k == 2 and m >= 2:
        return True
    return False


def table_points(rng):
    hp = math.pi / 2
    pts = [
        (0.0, 0.0),
        (math.pi, 0.3),                 # t = pi
        (-math.pi + 1e-12, 0.5),        # t just above -pi
        (math.pi - 1e-9, -0.7),         # t just below pi
        (1.0, hp - 1e-6),               # 1e-6 rad below the north pole
        (2.0, hp + 1e-6),               # 1e-6 rad beyond the north pole
        (-2.5, -hp + 1e-7),             # near the south pole
        (0.4, -hp - 1e-5),              # beyond the south pole
        (-0.3, hp - 4.8e-6),            # ~1 arcsec from the pole
        (0.7, math.pi - 0.2),           # flipped
        (-1.2, -2.0),                   # flipped, below -90 deg
        (3.0, 3 * hp - 0.1),            # flipped, near 270 deg
        (7.0, 0.9),                     # t outside (-pi, pi]
        (-4.0, -0.4),
        (0.25, 1.2),
        (-0.8, -1.1),
    ]
    for _ in range(24):
        t = rng.uniform(-math.pi, math.pi)
        d = rng.uniform(-math.pi / 2, 3 * math.pi / 2)
        pts.append((t, d))
    return pts


def rank_table(rng):
    rows = []
    pts_t = rng.uniform(-math.pi, math.pi, RANK_POINTS)
    pts_d = np.arcsin(rng.uniform(-1.0, 1.0, RANK_POINTS))
    flip = rng.uniform(0.0, 1.0, RANK_POINTS) < 0.3
    pts_t = np.where(flip, pts_t + math.pi, pts_t)
    pts_d = np.where(flip, math.pi - pts_d, pts_d)
    for L in range(L_RANK_MAX + 1):
        cols_all = [(k, l, m) for l in range(L + 1) for m in range(-l, l + 1)
                    for k in range(1, 7)]
        kept = [c for c in cols_all if not dropped(*c)]
        A = np.zeros((2 * RANK_POINTS, len(cols_all)))
        for n, (t, d) in enumerate(zip(pts_t, pts_d)):
            st, ct, sd, cd = math.sin(t), math.cos(t), math.sin(d), math.cos(d)
            et = np.array([-st, ct, 0.0])
            ed = np.array([-sd * ct, -sd * st, cd])
            T = terms(L, t, d)
            for c, (k, l, m) in enumerate(cols_all):
                v = T[l * l + l + m, k - 1]
                A[2 * n, c] = v @ et
                A[2 * n + 1, c] = v @ ed
        A /= np.linalg.norm(A, axis=0)
        idx = [cols_all.index(c) for c in kept]
        s_kept = np.linalg.svd(A[:, idx], compute_uv=False)
        s_all = np.linalg.svd(A, compute_uv=False)
        r_kept = int(np.sum(s_kept > RANK_RTOL * s_kept[0]))
        r_all = int(np.sum(s_all > RANK_RTOL * s_all[0]))
        want = 4 * L * L + 12 * L + 6
        gap_hi = s_all[want - 1] / s_all[0]
        gap_lo = s_all[want] / s_all[0] if want < len(s_all) else 0.0
        rows.append((L, want, len(kept), r_kept, len(cols_all), r_all,
                     s_kept[-1] / s_kept[0], gap_lo))
    return rows


def main():
    rng = np.random.default_rng(SEED)
    pts = table_points(rng)
    tabs = [terms(L_TABLE, t, d) for (t, d) in pts]
    rows = rank_table(rng)

    print("L  4L^2+12L+6  kept  rank(kept)  all  rank(all)  "
          "smin/smax(kept)  s[P]/smax(all)")
    ok = True
    for r in rows:
        print("%d  %10d  %4d  %10d  %3d  %9d  %15.3e  %14.3e" % r)
        if not (r[1] == r[2] == r[3] == r[5]):
            ok = False
    print("rank check:", "OK" if ok else "FAILED")

    nh = (L_TABLE + 1) ** 2
    with open(OUT, "w") as f:
        f.write("/*\n**  model_ref.h - reference values for tests/check_model.c.\n"
                "**  GENERATED, do not edit: /usr/bin/python3 tests/ref/model_ref.py\n"
                "**  (numpy %s, scipy %s; scipy.special.lpmv with the Condon-Shortley\n"
                "**  phase removed, cross-checked against numpy.polynomial.legendre).\n"
                "**\n"
                "**  model_ref_pt[n] = (t, d) encoder position (radians);\n"
                "**  model_ref_terms[n][j][k-1][c] = component c of Y_lm p_k at it,\n"
                "**  j = l*l + l + m (the layout of pm_terms_eval), L = %d.\n"
                "**  model_ref_rank[L] = {4L^2+12L+6, kept terms, rank of kept,\n"
                "**  all 6(L+1)^2 terms, rank of all} of the 2-component tangent design\n"
                "**  over %d random points (numpy SVD, columns normalised, rank =\n"
                "**  singular values above %g of the largest).\n*/\n"
                % (np.__version__, __import__("scipy").__version__, L_TABLE,
                   RANK_POINTS, RANK_RTOL))
        f.write("#ifndef MODEL_REF_H\n#define MODEL_REF_H\n\n")
        f.write("#define MODEL_REF_L %d\n#define MODEL_REF_NPT %d\n"
                "#define MODEL_REF_RANK_LMAX %d\n\n"
                % (L_TABLE, len(pts), L_RANK_MAX))
        f.write("static const double model_ref_pt[MODEL_REF_NPT][2] = {\n")
        for (t, d) in pts:
            f.write("    {%r, %r},\n" % (float(t), float(d)))
        f.write("};\n\n")
        f.write("static const double model_ref_terms[MODEL_REF_NPT][%d][6][3] = {\n"
                % nh)
        for n, T in enumerate(tabs):
            f.write("  { /* point %d */\n" % n)
            for j in range(nh):
                f.write("    {")
                f.write(", ".join("{%r, %r, %r}" % tuple(float(v) for v in T[j, k])
                                  for k in range(6)))
                f.write("},\n")
            f.write("  },\n")
        f.write("};\n\n")
        f.write("static const int model_ref_rank[MODEL_REF_RANK_LMAX + 1][5] = {\n")
        for r in rows:
            f.write("    {%d, %d, %d, %d, %d},\n" % (r[1], r[2], r[3], r[4], r[5]))
        f.write("};\n\n#endif\n")
    print("wrote", os.path.relpath(OUT))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
