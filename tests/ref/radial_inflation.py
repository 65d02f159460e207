#!/usr/bin/env python3
"""radial_inflation.py - how much the paper's 3-D regression inflates sigma.

Independent of the C library (numpy only).  Simulates pointing runs with the
first-order model of Pal et al. (2016), Eq. (pyyexpansion), taken as the
truth:

    p' = normalize(p + sum_k a_k Y_lm(t, d) p_k(t, d))

(isotropic terms + the L = 1 anisotropic ones, 22 independent terms), adds
1 arcsec of Gaussian noise per axis on the sky, and fits the coefficients
linearly in two ways:

  (i)  the paper's (Sec. 2 and 5.1): the 3-D difference vectors
       p(T,D) - p(t,d) regressed on the 3-vectors Y_lm p_k (3N rows), with
       the "unbiased" sigma = sqrt(chi2 / (2N - P)) as the paper counts the
       degrees of freedom;
  (ii) tangent-plane residuals: the same difference projected on e_t, e_d
       at the encoder position (2N rows), same regression.

Every Y_lm p_k is perpendicular to p(t,d) (the paper notes p . p_k = 0), so
both regressions have the same normal equations and give identical
coefficients; (i) only adds the radial component of the difference,
p(T,D).p(t,d) - 1 = cos(theta) - 1 ~ -theta^2/2 (theta = total pointing
offset), which no term can fit and which goes straight into chi2:

    sigma_3d^2 = sigma_tan^2 + sum (1 - cos theta)^2 / (2N - P).

The script prints both sigmas, the ratio, that prediction, and the rms
offset for several term sizes, as a Markdown table.

Usage: python3 tests/ref/radial_inflation.py [--seeds S] [--n N]
"""
import argparse

import numpy as np

ARCSEC = np.pi / 648000.0
ARCMIN = 60.0 * ARCSEC
DEG = np.pi / 180.0
LAT = 47.9 * DEG  # latitude of the simulated site
ELEV_MIN = 10.0 * DEG
NOISE = 1.0 * ARCSEC


def sample_sky(rng, n):
    """n encoder positions uniform on the sphere above ELEV_MIN at LAT."""
    t = np.empty(0)
    d = np.empty(0)
    while t.size < n:
        tt = rng.uniform(-np.pi, np.pi, 4 * n)
        dd = np.arcsin(rng.uniform(-1.0, 1.0, 4 * n))
        alt = np.arcsin(np.sin(LAT) * np.sin(dd)
                        + np.cos(LAT) * np.cos(dd) * np.cos(tt))
        keep = alt >= ELEV_MIN
        t = np.concatenate([t, tt[keep]])
        d = np.concatenate([d, dd[keep]])
    return t[:n], d[:n]


def unit(t, d):
    return np.stack([np.cos(d) * np.cos(t), np.cos(d) * np.sin(t), np.sin(d)],
                    axis=-1)


def base_vectors(t, d):
    """p_1..p_6 of Pal et al. Eq. (tdvectexpansion): (n, 6, 3)."""
    st, ct, sd, cd = np.sin(t), np.cos(t), np.sin(d), np.cos(d)
    z = np.zeros_like(t)
    return np.stack([
        np.stack([z, -sd, cd * st], -1),          # a
        np.stack([sd, z, -cd * ct], -1),          # b
        np.stack([-cd * st, cd * ct, z], -1),     # c'
        np.stack([sd * st, -sd * ct, z], -1),     # d
        np.stack([sd * ct, sd * st, -cd], -1),    # e'
        np.stack([-st, ct, z], -1),               # i
    ], axis=1)


def harmonics_l1(t, d):
    """Y_00, Y_1,-1, Y_10, Y_11 in the paper's normalisation: dict (l,m)."""
    return {(0, 0): np.ones_like(t), (1, -1): np.cos(d) * np.sin(t),
            (1, 0): np.sin(d), (1, 1): np.cos(d) * np.cos(t)}


def term_list():
    """The 22 independent (k, l, m) for L = 1: all but i*Y(1,0) and a*Y(1,1)
    (the paper's Table 1 dependencies; the same choice as docs/model.md)."""
    terms = []
    for (l, m) in [(0, 0), (1, -1), (1, 0), (1, 1)]:
        for k in range(1, 7):
            if l == 1 and k == 6 and abs(m) <= 0:
                continue
            if l == 1 and k == 1 and m >= 1:
                continue
            terms.append((k, l, m))
    return terms


def design_vectors(t, d, terms):
    """(n, P, 3): the 3-vectors Y_lm p_k of every term at every point."""
    pk = base_vectors(t, d)
    y = harmonics_l1(t, d)
    return np.stack([y[(l, m)][:, None] * pk[:, k - 1, :]
                     for (k, l, m) in terms], axis=1)


def one_run(rng, n, size):
    terms = term_list()
    P = len(terms)
    t, d = sample_sky(rng, n)
    p = unit(t, d)
    V = design_vectors(t, d, terms)                 # (n, P, 3)
    a_true = size * rng.choice([-1.0, 1.0], P)
    pt = p + np.einsum('npj,p->nj', V, a_true)      # first-order truth
    pt /= np.linalg.norm(pt, axis=1, keepdims=True)
    # 1 arcsec per axis on the sky around the true position
    rho = np.hypot(pt[:, 0], pt[:, 1])
    et = np.stack([-pt[:, 1] / rho, pt[:, 0] / rho, np.zeros(n)], -1)
    ed = np.stack([-pt[:, 2] * pt[:, 0] / rho, -pt[:, 2] * pt[:, 1] / rho,
                   rho], -1)
    q = (pt + NOISE * rng.standard_normal((n, 1)) * et
         + NOISE * rng.standard_normal((n, 1)) * ed)
    q /= np.linalg.norm(q, axis=1, keepdims=True)   # p(T, D)
    diff = q - p

    # (i) the paper's 3-D regression: 3N rows
    A3 = V.transpose(0, 2, 1).reshape(3 * n, P)
    b3 = diff.reshape(3 * n)
    x3, *_ = np.linalg.lstsq(A3, b3, rcond=None)
    chi2_3 = float(np.sum((b3 - A3 @ x3) ** 2))

    # (ii) tangent plane at the encoder position: 2N rows
    st, ct, sd, cd = np.sin(t), np.cos(t), np.sin(d), np.cos(d)
    e1 = np.stack([-st, ct, np.zeros(n)], -1)
    e2 = np.stack([-sd * ct, -sd * st, cd], -1)
    A2 = np.concatenate([np.einsum('npj,nj->np', V, e1),
                         np.einsum('npj,nj->np', V, e2)])
    b2 = np.concatenate([np.sum(diff * e1, 1), np.sum(diff * e2, 1)])
    x2, *_ = np.linalg.lstsq(A2, b2, rcond=None)
    chi2_2 = float(np.sum((b2 - A2 @ x2) ** 2))

    dof = 2 * n - P
    radial = np.sum(diff * p, 1)                    # cos(theta) - 1
    theta = np.arctan2(np.linalg.norm(np.cross(p, q), axis=1),
                       np.sum(p * q, 1))
    return dict(
        P=P,
        sigma3=np.sqrt(chi2_3 / dof),
        sigma2=np.sqrt(chi2_2 / dof),
        pred=np.sqrt((chi2_2 + float(np.sum(radial ** 2))) / dof),
        theta_rms=float(np.sqrt(np.mean(theta ** 2))),
        coef_diff=float(np.max(np.abs(x3 - x2))),
        bias2=float(np.max(np.abs(x2 - a_true))),
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--seeds', type=int, default=20)
    ap.add_argument('--n', type=int, default=2000)
    args = ap.parse_args()
    sizes = [0.3, 1.0, 2.0, 3.0, 5.0, 10.0]
    print(f'N = {args.n} points above {ELEV_MIN / DEG:.0f} deg elevation at '
          f'latitude {LAT / DEG:.1f} deg, noise {NOISE / ARCSEC:.0f} arcsec '
          f'per axis, L = 1 (P = {len(term_list())}), every coefficient '
          f'+-size, mean over {args.seeds} seeds')
    print()
    print('| term size | rms offset | sigma 3-D (paper) | sigma tangent '
          '| ratio | predicted from radial part |')
    print('|---|---|---|---|---|---|')
    worst_coef_diff = 0.0
    for size in sizes:
        runs = [one_run(np.random.default_rng(1000 + s), args.n,
                        size * ARCMIN) for s in range(args.seeds)]
        m = {k: float(np.mean([r[k] for r in runs]))
             for k in ('sigma3', 'sigma2', 'pred', 'theta_rms')}
        ratio = float(np.mean([r['sigma3'] / r['sigma2'] for r in runs]))
        pred = float(np.mean([r['pred'] / r['sigma2'] for r in runs]))
        worst_coef_diff = max(worst_coef_diff,
                              max(r['coef_diff'] for r in runs) / ARCSEC)
        print(f"| {size:g}' | {m['theta_rms'] / ARCMIN:.2f}' "
              f"| {m['sigma3'] / ARCSEC:.3f}\" | {m['sigma2'] / ARCSEC:.3f}\" "
              f"| {ratio:.3f} | {pred:.3f} |")
    print()
    print(f'Coefficients of (i) and (ii) agree to {worst_coef_diff:.1e} '
          'arcsec (same normal equations: every Y_lm p_k is perpendicular '
          'to p).')
    print('The excess is the radial component cos(theta) - 1 ~ -theta^2/2 '
          'of the 3-D difference: ratio^2 ~ 1 + <theta^4>/(8 sigma^2).')


if __name__ == '__main__':
    main()
