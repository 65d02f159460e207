/*
**  model.cpp - the pointing model: term set, forward and inverse evaluation.
**
**  Reference: Pal et al., Exp Astron (2016), Secs. 2, 3 and 5.
*/
#include "pm.h"
#include "pm_detail.hpp"

using namespace pm::detail;

namespace {

/* Is harmonic term (k, l, m) one of the linearly dependent ones dropped?
** (docs/model.md: p4 Y_lm = -sin(d) Y_lm p6 ties k=6 to k=4; the identity
** sum_i p_i (e_i x p) = 0 ties k=1,2,3.) */
bool dropped(int k, int l, int m)
{
    if (l == 0)
        return false;
    if (k == 6 && (m < 0 ? -m : m) <= l - 1)
        return true;
    if (k == 1 && m >= 1)
        return true;
    if (k == 2 && m >= 2)
        return true;
    return false;
}

/* Bound on how fast the anisotropic displacement of m changes with either
** axis angle (rad per rad), the AUX terms' inputs aside: the sum of
** |coef| times a bound for each term's displacement per unit coefficient
** (value and tangent-frame turning included):
**   harmonic Y_lm p_k: 8 + l (maxima measured on a 400 x 400 grid for
**     l <= 10: 4, 4, 8, 8.1, 8.8, 9.7, 10.6, 11.6, 12.7, 13.8, 14.8);
**   Fourier trig(G x) p_k: |G| + 2;  sectoral cos^G(d) trig(G t) p_k: 2G + 2;
**   zenith cot(el) (el clamped at 0.01 rad): 1/0.01^2 + 1/0.01 + 2;
**   zenith cos(el): 2;  AUX: 0 here (pm_model_invert adds them).
** pm_model_invert uses it to know when the rounding of its returned angles
** could matter (pm.h, pm_model_invert Note 4).  Infinite for geometries far
** from any mount, where every inverse is checked: |d|, |i| or the polar
** axis's offset beyond 0.5 rad (at d or i = 90 deg the closed form
** degenerates and loses digits), or an anisotropic displacement that can
** reach 0.5 rad (the sum of |coef| times each term's largest value per unit
** coefficient: harmonic 2 (N_lm Y_lm, l <= 10, measured), Fourier and
** sectoral 1, zenith cot(el) 100, cos(el) 1; towards 90 deg the closed
** form's branch is ill-conditioned: a 1.57 rad term missed by 5.6e-13). */
double lipschitz(const pm_model *m)
{
    const double far = 0.5;
    if (!(m_fabs(m->coef[3]) <= far && m_fabs(m->coef[5]) <= far &&
          m->coef[0] * m->coef[0] + m->coef[1] * m->coef[1] <= far * far))
        return __builtin_inf();
    double s = 0, amp = 0;
    for (int i = 6; i < m->n_terms; i++) {
        const pm_term &t = m->term[i];
        double b = 0, v = 0; /* rate and value bounds per unit coefficient */
        switch (t.kind) {
        case PM_TERM_SH: b = 8.0 + t.l; v = 2; break;
        case PM_TERM_FOURIER: b = m_fabs(t.param) + 2; v = 1; break;
        case PM_TERM_SECTORAL: b = 2 * m_fabs(t.param) + 2; v = 1; break;
        case PM_TERM_ZENITH:
            b = t.l == 0 ? 1e4 + 100 + 2 : 2;
            v = t.l == 0 ? 100 : 1;
            break;
        default: break;
        }
        s += m_fabs(m->coef[i]) * b;
        amp += m_fabs(m->coef[i]) * v;
    }
    return amp <= far ? s : __builtin_inf();
}

/* Bound on the second derivative of the anisotropic displacement (rad per
** rad^2, along any unit direction of the two axis angles), for the
** inverse's predicted stop (pm.h, pm_model_invert Note 1): the sum of
** |coef| times, for a harmonic term of degree l, 1.25 (l(l+1) + 2.5 l + 4),
** which is above 1.25 times the maxima of F2 B0 + 2 F1 B1 + F0 B2 measured
** by tests/ref/lip2_bounds.py for l <= 10 (4.1, 14.3, 22.6, 32.9, ...,
** 136.8: the product rule on N_lm Y_lm and the base vector's components,
** the i-th derivatives' suprema F_i and B_i).  The AUX terms' part depends
** on the context (pm_model_invert adds 1.45 |coef (input - param)|: 1.25
** B2); any other added term, a degree beyond 10 or an infinite lip make it
** infinite: the inverse then stops on measured changes only. */
double second_rate(const pm_model *m)
{
    const double inf = __builtin_inf();
    if (!(m->lip < inf))
        return inf;
    double s = 0;
    for (int i = 6; i < m->n_base; i++) {
        int l = m->term[i].l;
        if (l > 10)
            return inf;
        s += m_fabs(m->coef[i]) * 1.25 * (l * (l + 1) + 2.5 * l + 4);
    }
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind != PM_TERM_AUX || m->term[i].side != 0)
            return inf;
    return s;
}

/* Two 32-bit digests (FNV-1a with two offsets, and the second also
** rotated per word) of a sequence of 32-bit words: pm_model.ident and
** pm_track's inputs. */
struct Digest {
    unsigned long a, b;
};
inline void digest_word(Digest *h, unsigned long w)
{
    w &= 0xffffffffUL;
    h->a = ((h->a ^ w) * 16777619UL) & 0xffffffffUL;
    h->b = ((h->b ^ ((w << 7 | w >> 25) & 0xffffffffUL)) * 16777619UL) & 0xffffffffUL;
    h->b ^= h->b >> 15;
}
inline void digest_double(Digest *h, double x)
{
    unsigned char c[sizeof(double)];
    __builtin_memcpy(c, &x, sizeof c);
    for (unsigned i = 0; i < sizeof c; i += 4)
        digest_word(h, (unsigned long)c[i] | (unsigned long)c[i + 1] << 8 |
                           (unsigned long)c[i + 2] << 16 | (unsigned long)c[i + 3] << 24);
}
inline Digest digest_start()
{
    Digest h;
    h.a = 2166136261UL;
    h.b = 0x9e3779b9UL;
    return h;
}

/* The digest of a prepared model's content (pm_model.ident). */
void model_digest(pm_model *m)
{
    Digest h = digest_start();
    digest_word(&h, (unsigned long)m->mount);
    digest_word(&h, (unsigned long)m->order);
    digest_word(&h, (unsigned long)m->n_terms);
    digest_word(&h, (unsigned long)m->n_base);
    digest_double(&h, m->latitude);
    for (int i = 0; i < m->n_terms; i++) {
        const pm_term &t = m->term[i];
        digest_word(&h, (unsigned long)t.kind | (unsigned long)t.k << 8 |
                            (unsigned long)(unsigned char)t.l << 16 |
                            (unsigned long)(unsigned char)t.m << 24);
        digest_word(&h, (unsigned long)(unsigned char)t.side | (unsigned long)t.aux << 8);
        digest_double(&h, t.param);
        digest_double(&h, m->coef[i]);
    }
    m->ident[0] = h.a;
    m->ident[1] = h.b;
}

/* The digest of the inputs the model's AUX terms read at ctx (J's part
** from them depends on those). */
Digest inputs_digest(const pm_model *m, const pm_context *ctx)
{
    Digest h = digest_start();
    if (m->needs_ctx && ctx)
        for (int i = m->n_base; i < m->n_terms; i++)
            if (m->term[i].kind == PM_TERM_AUX)
                digest_double(&h, aux_input(ctx, m->term[i].aux));
    return h;
}

/* Which side of the mount's pole an encoder declination is on: the sign of
** cos(dec - e'). */
int side_of(const pm_model *m, double d)
{
    double x = d - m->coef[4];
    /* within pi: cos x >= 0 exactly where |x| <= pi/2 as a double (cos of
    ** that double is 6e-17, of the next one -1.6e-16) */
    if (!abs_beyond(x, PI))
        return abs_beyond(x, PI / 2) ? -1 : 1;
    return m_cos(x) >= 0 ? 1 : -1;
}

/* asin(r) for |r| <= 0.01 by its series (the terms left out are below
** 1e-23), by Estrin's scheme (the inverse's returned angles; the forward's
** atan and asin tails are atan_plus and asin_plus, lib/pm_detail.hpp). */
inline double asin_small(double r)
{
    double r2 = r * r, r4 = r2 * r2;
    return r * ((1 + r2 * (1.0 / 6)) + r4 * ((3.0 / 40 + r2 * (5.0 / 112)) + r4 * (35.0 / 1152)));
}

/* The angle x + s (+ pi if half) in (-pi, pi], for |x| <= 64 and |s| <= 1:
** the multiple of 2 pi taken off in the parts of pi/2 (x - q PIO2_1 is
** exact or rounded once), s added apart: within about an ulp (a result
** that rounds onto or beyond +-pi is pi). */
inline double turn_sum(double x, double s, bool half)
{
    /* the turn from x alone (ready before s: a shorter chain), from x + s
    ** where s carries the sum across +-pi */
    double n = (x * 0.15915494309189535 + (half ? 0.5 : 0.0) + RND_INT) - RND_INT;
    double q = 4 * n - (half ? 2 : 0); /* x + s + (pi) - 2 pi n = x + s - q pi/2 */
    double a = (x - q * PIO2_1) + ((s - q * PIO2_2) - q * PIO2_3);
    if (abs_beyond(a, PI)) {
        n = ((x + s) * 0.15915494309189535 + (half ? 0.5 : 0.0) + RND_INT) - RND_INT;
        q = 4 * n - (half ? 2 : 0);
        a = (x - q * PIO2_1) + ((s - q * PIO2_2) - q * PIO2_3);
    }
    return abs_beyond(a, PI) || same_as(a, -PI) ? PI : a;
}

/* turn_sum(x, c + atan(r), half) with the small parts summed otherwise:
** c and the parts of pi/2 that follow PIO2_1 first (from x alone: off the
** chain), then r and the series' tail (atan_plus): the forward model's
** hour angle, four operations shorter after r. */
inline double turn_sum_atan(double x, double c, double r, bool half)
{
    double n = (x * 0.15915494309189535 + (half ? 0.5 : 0.0) + RND_INT) - RND_INT;
    double q = 4 * n - (half ? 2 : 0);
    double a = (x - q * PIO2_1) + atan_plus((c - q * PIO2_2) - q * PIO2_3, r);
    if (abs_beyond(a, PI)) {
        const double s = atan_plus(c, r);
        n = ((x + s) * 0.15915494309189535 + (half ? 0.5 : 0.0) + RND_INT) - RND_INT;
        q = 4 * n - (half ? 2 : 0);
        a = (x - q * PIO2_1) + atan_plus((c - q * PIO2_2) - q * PIO2_3, r);
    }
    return abs_beyond(a, PI) || same_as(a, -PI) ? PI : a;
}

/* pi - x + s for a small s, pi in the parts of pi/2: 2 PIO2_1 - x is exact
** or rounded once, s added apart (the declination beyond the pole). */
inline double pi_minus(double x, double s)
{
    return (2 * PIO2_1 - x) + ((s + 2 * PIO2_2) + 2 * PIO2_3);
}

/*
** Apparent angles (T, D) of the forward model's unit vector p at encoder
** (t, d), without atan2, from pf = Pt(t')^T p (forward_framed; p turned
** back by the shifted hour angle t' = t + c'): measured from the shifted
** position (t + c', d - e') -- beyond the mount's pole from its
** equivalent (t + c' + pi, pi - (d - e')) -- whose trig sh is known, p's
** offsets (dT, dD) are small (the anisotropic displacement, a, b, d, i):
** two short series.  The sums are formed so that about one rounding falls on the
** result: multiples of pi/2 in three parts (turn_sum, pi_minus), the
** small parts added apart.  Returns false
** where this does not apply -- |t| > 64, |d| > 4, |c'| or |e'| > 0.5, an
** offset beyond 0.01 rad (near the pole) -- and the caller takes atan2.
*/
bool frame_angles(const pm_model *m, double t, double d, const double sh[4],
                  const V3<double> &pf, double *T, double *D)
{
    const double c = m->coef[2], e = m->coef[4];
    if (abs_beyond(t, 64) || abs_beyond(d, 4) || abs_beyond(c, 0.5) || abs_beyond(e, 0.5))
        return false;
    /* |d - e'| <= 4.5 < 3 pi/2: the normal side is d - e' in [-pi/2, pi/2] */
    const bool flip = sh[3] < 0;
    const double sD = sh[2], cD = flip ? -sh[3] : sh[3];
    /* p turned by -(t + c' (+ pi)): pf (forward_framed), negated beyond
    ** the pole */
    const double x1 = flip ? -pf.x : pf.x, y1 = flip ? -pf.y : pf.y;
    const V3<double> &p = pf;
    double rho = m_sqrt(x1 * x1 + y1 * y1);
    /* sin(D - D0) = p_z cos D0 - rho sin D0 (|p| = 1 to rounding: asin, no
    ** division after the square root) */
    double zn = p.z * cD - rho * sD, zd = rho * cD + p.z * sD;
    if (!(m_fabs(y1) <= 0.01 * x1) || !(m_fabs(zn) <= 0.01) || !(zd > 0))
        return false;
    /* T = t + c' + atan(y1/x1) (+ pi), in (-pi, pi] */
    *T = turn_sum_atan(t, c, y1 / x1, flip);
    /* D = d - e' + asin(zn), or beyond the pole +-pi - (d - e') +
    ** asin(zn) (pi_minus's sums, the small parts first) */
    double da;
    if (!flip)
        da = d + asin_plus(-e, zn);
    else if (d - e > 0)
        da = (2 * PIO2_1 - d) + asin_plus((e + 2 * PIO2_2) + 2 * PIO2_3, zn);
    else /* -pi - (d - e') + asin(zn) */
        da = -((2 * PIO2_1 + d) + asin_plus((2 * PIO2_2 - e) + 2 * PIO2_3, -zn));
    /* the exact angle is in [-pi/2, pi/2]: rounding only can leave it */
    *D = abs_beyond(da, PI / 2) ? (below0(da) ? -PI / 2 : PI / 2) : da;
    return true;
}

/* The inverse's target: apparent (ha, dec), their sines and cosines, the
** unit vector. */
struct Aim {
    double ha, dec;
    double sh, ch, sd, cd;
    V3<double> q;
};

/* The target as the Newton iteration sees it, in the frame before H (the
** outermost rotation, applied to the target once instead of to every
** trial point): q and its tangent frame, e1 along increasing axis 1, e2
** along axis 2. */
struct Frame {
    V3<double> q, e1, e2;
};

inline Frame frame_of(const Iso<double> &k, const Aim &a)
{
    Frame f;
    f.q = mat_tmul<double>(k.h, a.q);
    f.e1 = mat_tmul<double>(k.h, v3(-a.sh, a.ch, 0.0));
    f.e2 = mat_tmul<double>(k.h, v3(-a.sd * a.ch, -a.sd * a.sh, a.cd));
    return f;
}

/* A trial point of the Newton iteration (newton): at (t, d), the forward
** model's unit vector p (the operations of forward_vec), its miss of the
** target (the angle between them), the residual F = (e1 . p, e2 . p) and
** its derivatives along the axes: M = dF/d(t, d) (rows e1, e2), analytic
** -- the rotations' and, through J = dD/dx (aniso_jac), the
** displacement's --, and the second derivatives of the rotations' part
** (H: tt, td, dd, each (e1, e2); the displacement's own second derivative,
** below lip2, left out), for the fold step (fold_step).  gt = dp/dt . q,
** gtt = d2p/dt2 . q: the search along the pole's edge.  One model
** evaluation. */
struct NPoint {
    double t, d, err;
    double F[2], M[4], H[6];
    double gt;
    double da, db; /* the displacement D at (t, d) */
};

__attribute__((noinline)) void newton_point(const pm_model *m, const Iso<double> &k,
                                            const pm_context *ctx, const Frame &f, double t,
                                            double d, NPoint *o, const double *pre = 0)
{
    const Trig<double> g = trig_of(t, d);
    double a, b, J[4], stp, ctp, sdp, cdp;
    if (!pre) {
        aniso_jac(m, k, g, ctx, &a, &b, J);
    } else { /* (J and D taken at (t, d) already: newton's pre) */
        for (int i = 0; i < 4; i++)
            J[i] = pre[i];
        a = pre[4];
        b = pre[5];
    }
    shifted<double>(k, g, &stp, &ctp, &sdp, &cdp);
    /* w = expmap(a, b) = (c, a s, b s), c and s functions of r^2 = a^2 +
    ** b^2; c1, s1 their derivatives by r^2 */
    const double r2 = a * a + b * b;
    double s, c1, s1;
    if (r2 < 1e-4) {
        s = 1 - r2 * (1.0 / 6) + r2 * r2 * (1.0 / 120);
        c1 = -0.5 + r2 * (1.0 / 12) - r2 * r2 * (1.0 / 240);
        s1 = -1.0 / 6 + r2 * (1.0 / 60) - r2 * r2 * (1.0 / 1680);
    } else {
        const double r = m_sqrt(r2), c = m_cos(r);
        s = m_sin(r) / r;
        c1 = -0.5 * s;
        s1 = (c - s) / (2 * r2);
    }
    const V3<double> wa = v3(2 * a * c1, s + 2 * a * a * s1, 2 * a * b * s1);
    const V3<double> wb = v3(2 * b * c1, 2 * a * b * s1, s + 2 * b * b * s1);
    /* W = Pt(t') X(d) Pd(d') T(i) w, and the same rotations of w's
    ** derivatives (Wt, Wd): p = H W */
    V3<double> v[3] = {expmap<double>(a, b),
                       v3(wa.x * J[0] + wb.x * J[2], wa.y * J[0] + wb.y * J[2],
                          wa.z * J[0] + wb.z * J[2]),
                       v3(wa.x * J[1] + wb.x * J[3], wa.y * J[1] + wb.y * J[3],
                          wa.z * J[1] + wb.z * J[3])};
    for (int i = 0; i < 3; i++)
        v[i] = rot_z<double>(stp, ctp, rot_x<double>(k.sd, k.cd, rot_d<double>(sdp, cdp,
                                                    rot_z<double>(k.si, k.ci, v[i]))));
    const V3<double> &W = v[0], &Wt = v[1], &Wd = v[2];
    /* The axes turn W themselves: d/dt' Pt(t') y = z x (Pt y), d/dd' Pd(d')
    ** y = -y^ x (Pd y), i.e. -ax x W with ax = Pt X y^ the declination
    ** axis.  So p_t = Wt + z x W, p_d = Wd - ax x W, and differentiating
    ** once more (ax turns with t only): p_tt = z x (p_t + Wt), p_dd = -ax x
    ** (p_d + Wd), p_td = z x p_d - ax x Wt, up to the rotated second
    ** derivatives of w (lip2 bounds them; they only slow the fold step). */
    const V3<double> ax = v3(-stp * k.cd, ctp * k.cd, k.sd);
    const V3<double> pt = v3(Wt.x - W.y, Wt.y + W.x, Wt.z);
    const V3<double> cw = cross<double>(ax, W);
    const V3<double> pd = v3(Wd.x - cw.x, Wd.y - cw.y, Wd.z - cw.z);
    const V3<double> ptt = v3(-(pt.y + Wt.y), pt.x + Wt.x, 0.0);
    const V3<double> cdd = cross<double>(ax, v3(pd.x + Wd.x, pd.y + Wd.y, pd.z + Wd.z));
    const V3<double> cwt = cross<double>(ax, Wt);
    const V3<double> ptd = v3(-pd.y - cwt.x, pd.x - cwt.y, -cwt.z);
    o->t = t;
    o->d = d;
    o->da = a;
    o->db = b;
    o->F[0] = dot(W, f.e1);
    o->F[1] = dot(W, f.e2);
    o->M[0] = dot(pt, f.e1);
    o->M[1] = dot(pd, f.e1);
    o->M[2] = dot(pt, f.e2);
    o->M[3] = dot(pd, f.e2);
    o->H[0] = dot(ptt, f.e1);
    o->H[1] = dot(ptt, f.e2);
    o->H[2] = dot(ptd, f.e1);
    o->H[3] = dot(ptd, f.e2);
    o->H[4] = -dot(cdd, f.e1);
    o->H[5] = -dot(cdd, f.e2);
    o->gt = dot(pt, f.q);
    const V3<double> x = cross<double>(W, f.q);
    o->err = m_atan2(m_sqrt(dot<double>(x, x)), dot<double>(W, f.q));
}

/* The second-order part of F left out of the analytic H (the
** displacement's own curvature), measured along the last step of the
** iteration: a secant, C (ux, uy) along dir (a unit step).  H + (dir .
** x)(dir . y) C then matches the change of F over that step to second
** order (a symmetric rank-one correction). */
struct Curv {
    double dir[2], C[2];
};

/* H(x, y) of point c with the correction cv: the second-order part of F
** along steps x and y (x_t y_t H_tt + (x_t y_d + x_d y_t) H_td + x_d y_d
** H_dd), projected on u. */
__attribute__((noinline)) double hess(const NPoint &c, const Curv &cv, const double *u, const double *x,
                   const double *y)
{
    const double tt = x[0] * y[0], td = x[0] * y[1] + x[1] * y[0], dd = x[1] * y[1];
    const double kk = (cv.dir[0] * x[0] + cv.dir[1] * x[1]) * (cv.dir[0] * y[0] + cv.dir[1] * y[1]);
    return u[0] * (tt * c.H[0] + td * c.H[2] + dd * c.H[4] + kk * cv.C[0]) +
           u[1] * (tt * c.H[1] + td * c.H[3] + dd * c.H[5] + kk * cv.C[1]);
}

/* The step h of the Newton iteration from point c: a root of the
** quadratic model F + M h + H(h, h)/2 = 0.  In M's singular directions
** (M v1 = s1 u1, M v2 = s2 u2, s1 >= |s2|) h = alpha v2 + beta v1: along
** u1 the model is solved for beta as a Newton step, along u2 as a
** quadratic in alpha.  Where M is regular that is Newton's step with a
** second-order correction; at the fold of the mount's pole, where M is
** singular (s2 -> 0: the edge of the cap the tube cannot reach, and the
** two solutions either side of it), plain Newton would halve its
** distance to the fold per step, while the quadratic gives both
** solutions at once: the one on side `want` is taken (+1/-1; 0: the
** nearer), and where the quadratic has no root (the target is beyond the
** fold: unreachable here) its vertex, the fold's point nearest the
** target.  0 where M is degenerate, else 1, or 2 for the vertex. */
__attribute__((noinline)) int fold_step(const pm_model *m, const NPoint &c, const Curv &cv,
                                        int want, double *ht, double *hd)
{
    const double A = c.M[0], B = c.M[1], C = c.M[2], D = c.M[3];
    const double j00 = A * A + C * C, j01 = A * B + C * D, j11 = B * B + D * D;
    const double dif = j00 - j11, tr = j00 + j11;
    if (!(tr > 0) || !(tr < 1e300))
        return 0;
    const double l1 = 0.5 * (tr + m_sqrt(dif * dif + 4 * j01 * j01));
    double v1[2] = {dif >= 0 ? l1 - j11 : j01, dif >= 0 ? j01 : l1 - j00};
    double n = m_sqrt(v1[0] * v1[0] + v1[1] * v1[1]);
    if (!(n > 0)) {
        v1[0] = 1;
        v1[1] = 0;
    } else {
        v1[0] /= n;
        v1[1] /= n;
    }
    const double v2[2] = {-v1[1], v1[0]};
    const double s1 = m_sqrt(l1);
    const double u1[2] = {(A * v1[0] + B * v1[1]) / s1, (C * v1[0] + D * v1[1]) / s1};
    const double u2[2] = {-u1[1], u1[0]};
    const double s2 = u2[0] * (A * v2[0] + B * v2[1]) + u2[1] * (C * v2[0] + D * v2[1]);
    const double f1 = u1[0] * c.F[0] + u1[1] * c.F[1], f2 = u2[0] * c.F[0] + u2[1] * c.F[1];
    const double b0 = -f1 / s1;
    const double h11 = hess(c, cv, u2, v1, v1), h12 = hess(c, cv, u2, v1, v2),
                 h22 = hess(c, cv, u2, v2, v2);
    const double a2 = 0.5 * h22, a1 = s2 + b0 * h12, a0 = f2 + 0.5 * b0 * b0 * h11;
    const double disc = a1 * a1 - 4 * a2 * a0;
    double al;
    if (disc < 0) {
        al = -a1 / (2 * a2); /* the vertex: the fold's nearest point */
    } else {
        const double qq = -0.5 * (a1 + (a1 >= 0 ? m_sqrt(disc) : -m_sqrt(disc)));
        al = qq != 0 ? a0 / qq : 0; /* the nearer root */
        if (want && a2 != 0 && qq != 0) {
            /* the other root where only it lies on the side wanted, and
            ** the nearer one lies beyond the pole's edge by more than a
            ** tenth of the way to it (else the nearer one, cut at the edge,
            ** is as good: a solution on the edge itself) */
            const double far = qq / a2, dn = c.d + al * v2[1] + b0 * v1[1];
            if (m_fabs(far) <= 0.2 && side_of(m, dn) != want &&
                side_of(m, c.d + far * v2[1] + b0 * v1[1]) == want &&
                m_fabs(m_cos(dn - m->coef[4])) > 0.01 * m_fabs((far - al) * v2[1]))
                al = far;
        }
    }
    /* beta with the second-order part at (alpha, b0) */
    const double hh[2] = {al * v2[0] + b0 * v1[0], al * v2[1] + b0 * v1[1]};
    const double be = -(f1 + 0.5 * hess(c, cv, u1, hh, hh)) / s1;
    *ht = al * v2[0] + be * v1[0];
    *hd = al * v2[1] + be * v1[1];
    return !(finite(*ht) && finite(*hd)) ? 0 : disc < 0 ? 2 : 1;
}

/* The encoder declination on the edge of the mount's pole (dec - e' =
** pole, +-pi/2) on the turn of ref (turn_of), the double nearest it on
** side `want`. */
inline double edge_of(const pm_model *m, const double *ref, double pole, int want)
{
    double t = ref[0], d = pole + m->coef[4];
    finish_angles(ref, &t, &d);
    const double step = (pole > 0 ? -want : want) * (m_fabs(d) * 2.3e-16 + 1e-300);
    for (int i = 0; i < 8 && side_of(m, d) != want; i++)
        d += step;
    return d;
}

/* Is trial point x better than c for an iteration that wants side `want`
** (0: any)?  A point on the side wanted beats one beyond it; then the
** smaller miss; where the misses agree to rounding (a target out of reach:
** the miss is stationary at the nearest point), the smaller gradient of
** the miss (along the edge only, for points on the pole's edge). */
inline bool better(const pm_model *m, const NPoint &x, const NPoint &c, int want)
{
    if (want) {
        const bool xs = side_of(m, x.d) == want, cs = side_of(m, c.d) == want;
        if (xs != cs)
            return xs;
    }
    if (x.err < c.err * (1 - 1e-12))
        return true;
    if (!(x.err <= c.err * (1 + 1e-12)))
        return false;
    const double gx0 = x.M[0] * x.F[0] + x.M[2] * x.F[1], gx1 = x.M[1] * x.F[0] + x.M[3] * x.F[1];
    const double gc0 = c.M[0] * c.F[0] + c.M[2] * c.F[1], gc1 = c.M[1] * c.F[0] + c.M[3] * c.F[1];
    return gx0 * gx0 + gx1 * gx1 < gc0 * gc0 + gc1 * gc1;
}

#ifndef NEWTON_MAX_STEP
#define NEWTON_MAX_STEP 1.0
#endif
/* A trust region for the fold step (ht, hd): the quadratic model holds
** over a fraction of a radian at most (near the mount's pole, where the
** hour angle is ill-determined, over much less). */
inline void trust_region(double *ht, double *hd)
{
    const double big = m_fabs(*ht) > 4 * m_fabs(*hd) ? m_fabs(*ht) : 4 * m_fabs(*hd);
    if (big > NEWTON_MAX_STEP) {
        *ht *= NEWTON_MAX_STEP / big;
        *hd *= NEWTON_MAX_STEP / big;
    }
}

/* The last point of the pole's edge the iteration stood on (along_edge). */
struct EdgeMemo {
    double t, g; /* its hour angle and p_t . q there */
    bool have;
};

/* The trial point (nt, nd) of newton beyond the pole from side `want`,
** moved back onto the edge: dec - e' = +-90 deg on the side wanted, and
** along the edge the hour angle's Newton step on p . q (its maximum: the
** nearest point of the edge where the target is out of reach), the plain
** step where p . q is not concave.  ht is the step's hour angle from cur, lam
** its damping. */
inline void onto_edge(const pm_model *m, const NPoint &cur, const double *turn, int want,
                      double lam, double ht, EdgeMemo *e, double *nt, double *nd)
{
    const double pole = m_sin(*nd - m->coef[4]) >= 0 ? PI / 2 : -PI / 2;
    const double step_d = *nd - cur.d;
    *nd = edge_of(m, turn, pole, want);
    if (!(m_fabs(*nd - cur.d) <= 1e-15 * m_fabs(*nd))) {
        /* the step as far as the edge */
        double frac = (*nd - cur.d) / step_d;
        frac = frac > 0 ? (frac < 1 ? frac : 1) : 0;
        *nt = cur.t + lam * ht * frac;
        return;
    }
    /* from the edge along it: where the target is out of reach, the
    ** nearest point is where p . q peaks; the secant step on its
    ** derivative p_t . q once two points of the edge are known, the
    ** Gauss-Newton step before */
    double he = -(cur.M[0] * cur.F[0] + cur.M[2] * cur.F[1]) /
                (cur.M[0] * cur.M[0] + cur.M[2] * cur.M[2]);
    if (e->have && cur.t != e->t && cur.gt != e->g)
        he = -cur.gt * (cur.t - e->t) / (cur.gt - e->g);
    e->t = cur.t;
    e->g = cur.gt;
    e->have = true;
    if (!finite(he))
        he = 0;
    if (m_fabs(he) > NEWTON_MAX_STEP)
        he = he > 0 ? NEWTON_MAX_STEP : -NEWTON_MAX_STEP;
    *nt = cur.t + lam * he;
}

/* The secant of the curvature along the step from cur to trial at (nt,
** nd), into cv (fold_step's second-order part), where the step is long
** enough for F's change to show it above rounding. */
inline void secant_curvature(const NPoint &cur, const NPoint &trial, double nt, double nd,
                             Curv *cv)
{
    const double h[2] = {wrap_pi(nt - cur.t), nd - cur.d};
    const double hn2 = h[0] * h[0] + h[1] * h[1];
    if (!(hn2 > 1e-12 && hn2 < 1))
        return;
    const double hn = m_sqrt(hn2);
    const Curv zero = {{0, 0}, {0, 0}};
    cv->dir[0] = h[0] / hn;
    cv->dir[1] = h[1] / hn;
    for (int i = 0; i < 2; i++) {
        const double u[2] = {i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0};
        const double s = trial.F[i] - cur.F[i] - (cur.M[2 * i] * h[0] + cur.M[2 * i + 1] * h[1]);
        cv->C[i] = 2 * s / hn2 - hess(cur, zero, u, cv->dir, cv->dir);
    }
    if (!finite(cv->C[0]) || !finite(cv->C[1]))
        *cv = zero;
}

/* Damped Newton iteration on the forward model, in a frame fixed at the
** target, with the analytic Jacobian and the fold step (newton_point,
** fold_step: one evaluation per trial point).  Used where the closed
** form's fixed point does not contract (close to the mount's pole) and to
** check returned angles.  x = (t, d) encoder angles, updated in place.  At
** most `budget` evaluations (trial points), the first at x (or `first`,
** already evaluated; or made from pre, J (pre[0..3]) and D (pre[4],
** pre[5]) evaluated at x already, no evaluation); a trial point that is
** not better shortens the step to a quarter.  want = +1/-1: the side of
** the pole wanted (a trial point beyond the pole from that side is moved
** back onto the pole's edge: onto_edge); 0: any side, the nearer
** solution; 2: as 0, started at once where the fixed point had no chord
** (no_chord), and then PM_WARN_UNREACHABLE where it ends without
** converging after a step to the fold's vertex (the target beyond the
** fold: what the closed form's reach said where the fixed point's steps
** came first).  Trial points are kept on the turn the result is returned
** on (turn, from turn_of), since periodic terms of non-integer G read the
** raw angles and jump between turns. */
__attribute__((noinline)) pm_status newton(const pm_model *m, const Iso<double> &k,
                                           const pm_context *ctx, const Aim &a,
                                           const double *turn, double *t, double *d,
                                           double *err, int want, int budget,
                                           const NPoint *first = 0, const double *pre = 0)
{
    const bool at_once = want == 2; /* (finish_branch: Newton at once, no_chord) */
    if (at_once)
        want = 0;
    const Frame f = frame_of(k, a);
    NPoint cur, trial;
    int evals = 0;
    if (first) {
        cur = *first;
    } else {
        newton_point(m, k, ctx, f, *t, *d, &cur, pre);
        evals = !pre;
    }
    double lam = 1;
    EdgeMemo edge = {0, 0, false};
    bool beyond = false; /* the last step the fold's vertex: the target beyond it */
    Curv cv = {{0, 0}, {0, 0}};
    while (!(cur.err <= PM_INVERT_TOL && (!want || side_of(m, cur.d) == want)) &&
           evals < budget) {
        double ht, hd;
        const int fs = fold_step(m, cur, cv, want, &ht, &hd);
        if (!fs)
            break;
        beyond = fs == 2;
        trust_region(&ht, &hd);
        double nt = cur.t + lam * ht, nd = cur.d + lam * hd;
        if (want && side_of(m, nd) != want)
            onto_edge(m, cur, turn, want, lam, ht, &edge, &nt, &nd);
        finish_angles(turn, &nt, &nd);
        if (want && m_fabs(nt - cur.t) <= 1e-15 * m_fabs(cur.t) &&
            m_fabs(nd - cur.d) <= 1e-15 * m_fabs(cur.d))
            break; /* no step left (a few ulp): the nearest point */
        newton_point(m, k, ctx, f, nt, nd, &trial);
        evals++;
        secant_curvature(cur, trial, nt, nd, &cv);
        if (better(m, trial, cur, want)) {
            cur = trial;
            lam = 1;
        } else {
            lam *= 0.25;
        }
    }
    *t = cur.t;
    *d = cur.d;
    *err = cur.err;
    if (cur.err <= PM_INVERT_TOL)
        return PM_OK;
    return at_once && beyond ? PM_WARN_UNREACHABLE : PM_WARN_NOT_CONVERGED;
}

/* Does an evaluation of m read the raw axis angles, not only their sines
** and cosines?  Periodic terms of non-integer G do (the angle's turn
** matters); nothing else. */
bool reads_raw_angles(const pm_model *m)
{
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_FOURIER &&
            m->term[i].param != (double)(long)m->term[i].param)
            return true;
    return false;
}

/* The side of the pole the added terms see at g without a pier side in
** the context (site_of). */
int side_at(const Iso<double> &k, const Trig<double> &g)
{
    double stp, ctp, sdp, cdp;
    shifted<double>(k, g, &stp, &ctp, &sdp, &cdp);
    return cdp >= 0 ? 1 : -1;
}

/* Angle of the unit pair (s, c) near the angle a0 whose sine and cosine
** are (s0, c0): a - a0 = asin(sin(a - a0)) with cos(a - a0) > 0, by its
** series, in *small; false if it is not small (beyond 0.01 rad). */
inline bool near_angle(double s, double c, double s0, double c0, double *small)
{
    double y = s * c0 - c * s0, x = c * c0 + s * s0;
    if (!(m_fabs(y) <= 0.01) || !(x > 0))
        return false;
    *small = asin_small(y);
    return true;
}

/* Give trig g (an inverse's trial point for target a) its angles, the ones
** nearest the reference angles.  The encoder position is near the target
** after the index shifts, (ha - c', dec + e') -- beyond the pole (ha - c'
** + pi, pi - dec + e') --, off by the displacement: its angles from there
** by series where that is below 0.01 rad (the sums formed as in
** frame_angles), else by atan2. */
void on_turn(const pm_model *m, const Iso<double> &k, const Aim &a, Trig<double> *g,
             double ref_t, double ref_d)
{
    const double c = m->coef[2], e = m->coef[4];
    /* beyond the pole: cos(d - e') < 0 */
    const bool flip = g->cd * k.ce + g->sd * k.se < 0;
    double small, t, d;
    /* t0 = ha - c' (+ pi) */
    double s0 = a.sh * k.cc - a.ch * k.sc, c0 = a.ch * k.cc + a.sh * k.sc;
    if (flip) {
        s0 = -s0;
        c0 = -c0;
    }
    if (!abs_beyond(a.ha, 64) && !abs_beyond(c, 0.5) &&
        near_angle(g->st, g->ct, s0, c0, &small))
        t = turn_sum(a.ha, small - c, flip);
    else
        t = m_atan2(g->st, g->ct);
    /* d0 = dec + e', or pi - dec + e' */
    double sd0 = a.sd * k.ce + a.cd * k.se, cd0 = a.cd * k.ce - a.sd * k.se;
    if (flip) {
        sd0 = a.sd * k.ce - a.cd * k.se;
        cd0 = -(a.cd * k.ce + a.sd * k.se);
    }
    if (!abs_beyond(e, 0.5) && near_angle(g->sd, g->cd, sd0, cd0, &small))
        d = flip ? pi_minus(a.dec, e + small) : a.dec + (small + e);
    else
        d = m_atan2(g->sd, g->cd);
    g->t = ref_t + wrap_pi(t - ref_t);
    g->d = ref_d + wrap_pi(d - ref_d);
    g->have_angles = true;
}

/* The step from trig b to trig a, when both angles are within 0.01 rad:
** their sines (ht, hd); the angles are larger by at most |h|^3 / 5. */
inline bool small_step(const Trig<double> &a, const Trig<double> &b, double *ht, double *hd)
{
    double s1 = a.st * b.ct - a.ct * b.st, c1 = a.ct * b.ct + a.st * b.st;
    double s2 = a.sd * b.cd - a.cd * b.sd, c2 = a.cd * b.cd + a.sd * b.sd;
    if (!(m_fabs(s1) <= 0.01 && c1 > 0 && m_fabs(s2) <= 0.01 && c2 > 0))
        return false;
    *ht = s1;
    *hd = s2;
    return true;
}

/* The predicted bound on |D(x') - D^'| (solve_branch): the linear model's
** miss at the step h (sines of the angles: the angles' excess over them,
** |h|^3 / 5 per axis, times |J| added), J's own change since it was taken
** (lip2 times the distance dist_j) and the second-order remainder; hn
** bounds the step's length in angle. */
inline double step_bound(double dt, double dd, const double J[4], double ht, double hd,
                         double nt, double nd, double lip2, double dist_j, double hn)
{
    double et = dt + (J[0] * ht + J[1] * hd) - nt;
    double ed = dd + (J[2] * ht + J[3] * hd) - nd;
    double jn = m_fabs(J[0]) + m_fabs(J[1]) + m_fabs(J[2]) + m_fabs(J[3]);
    return m_sqrt(et * et + ed * ed) + jn * hn * hn * hn * 0.4 +
           lip2 * (dist_j + 0.5 * hn) * hn;
}

/* The Newton step on the displacement: with F the closed form (D to the
** encoder position it needs) and J = dD/dx, y = (I - J F_D)^-1 r; this
** prepares the matrix Ni = (I - J F_D)^-1 (once per call: a chord).  F_D
** at g = F(D^), D^ = (a, b): the closed form solves M'(x) v = H^T q with
** M' = Pt(t') X(d) Pd(d'), v = T(i) w, w = expmap(a, b); differentiated,
** in the frame of w, dt (A x w) - dd (y x w) = -w_D dD with A = (T(i)
** M')^T z the polar axis, y = T(i)^T (0, 1, 0) the declination axis there
** (every vector tangent at w: the y and z components are the system).
** w_D to O(|D|^3) by the series; an approximation only changes how fast
** the iteration converges, never when it stops (the stop is measured, or
** bounded with J itself).  False where the step is ill-conditioned (the
** mount's pole). */
/* Ni = (I - K)^-1, K = J F_D; false where I - K is ill-conditioned. */
inline bool chord_matrix(double K00, double K01, double K10, double K11, double Ni[4])
{
    double A = 1 - K00, B = -K01, C = -K10, D = 1 - K11;
    double det = A * D - B * C;
    if (!(m_fabs(det) >= 0.2))
        return false;
    double id = 1 / det;
    /* (I - K)^-1 */
    Ni[0] = D * id;
    Ni[1] = -B * id;
    Ni[2] = -C * id;
    Ni[3] = A * id;
    return true;
}

inline bool newton_prep(const Iso<double> &k, const Trig<double> &g, double a, double b,
                        const double J[4], double Ni[4])
{
    double sdp = g.sd * k.ce - g.cd * k.se, cdp = g.cd * k.ce + g.sd * k.se;
    /* A in the frame of v, then of w */
    double ax = sdp * k.cd, ay = k.sd, az = cdp * k.cd;
    double bx = k.ci * ax + k.si * ay, by = k.ci * ay - k.si * ax;
    double r2 = a * a + b * b, sc = 1 - r2 * (1.0 / 6);
    double wx = 1 - 0.5 * r2, wy = a * sc, wz = b * sc;
    /* columns (A x w), -(y x w) restricted to y, z; y = (si, ci, 0) */
    double m00 = az * wx - bx * wz, m10 = bx * wy - by * wx;
    double m01 = k.si * wz, m11 = k.ci * wx - k.si * wy;
    double dm = m00 * m11 - m01 * m10;
    if (!(m_fabs(dm) >= 1e-3 * k.ci))
        return false;
    double idm = 1 / dm;
    /* w_D (y, z rows): [[sc - a^2/3, -ab/3], [-ab/3, sc - b^2/3]] */
    double w00 = sc - a * a * (1.0 / 3), w01 = -a * b * (1.0 / 3), w11 = sc - b * b * (1.0 / 3);
    /* F_D = -M^-1 W */
    double i00 = m11 * idm, i01 = -m01 * idm, i10 = -m10 * idm, i11 = m00 * idm;
    double f00 = -(i00 * w00 + i01 * w01), f01 = -(i00 * w01 + i01 * w11);
    double f10 = -(i10 * w00 + i11 * w01), f11 = -(i10 * w01 + i11 * w11);
    return chord_matrix(J[0] * f00 + J[1] * f10, J[0] * f01 + J[1] * f11,
                        J[2] * f00 + J[3] * f10, J[2] * f01 + J[3] * f11, Ni);
}

/* newton_prep at D^ = 0 (a cold call's first point): w = (1, 0, 0) and w_D
** = I, the same values without the products by zero. */
inline bool newton_prep0(const Iso<double> &k, const Trig<double> &g, const double J[4],
                         double Ni[4])
{
    double sdp = g.sd * k.ce - g.cd * k.se, cdp = g.cd * k.ce + g.sd * k.se;
    double ax = sdp * k.cd, ay = k.sd, az = cdp * k.cd;
    double by = k.ci * ay - k.si * ax;
    double dm = az * k.ci;
    if (!(m_fabs(dm) >= 1e-3 * k.ci))
        return false;
    double idm = 1 / dm;
    double f00 = -(k.ci * idm), f10 = -(by * idm), f11 = -(az * idm);
    return chord_matrix(J[0] * f00 + J[1] * f10, J[1] * f11, J[2] * f00 + J[3] * f10,
                        J[3] * f11, Ni);
}

/* solve_branch in parts, every one inlined into it (the hot path gains no
** calls): the first point (first_point), the lean loop of the typical
** iteration (lean_loop, lean_stop, lean_advance), the hand-over to the
** general loop (hand_over), the general loop (general_loop, keep_best,
** fall_back, general_next) and the check of the returned angles
** (rounding_safe, finish_branch).  Their state is a Branch, passed by
** pointer; the points themselves live in three slots of solve_branch's
** frame, J and Ni beside them, and D is evaluated into locals (addresses
** that reach a call keep the Branch out of memory: its scalars stay in
** registers).  Each loop's iterations stay one loop: as a function per
** iteration returning how it ended, gcc spilled more across the closed
** form's call (+31 host instructions per cold call, bench/typical.sh); the
** general loop is marked unlikely, so that the typical path gets the
** registers. */
#define PM_HOT __attribute__((always_inline)) inline

/* pm_model_track's state (pm_track) in a call: J, the point it was taken
** at and the chord's matrix Ni made with it are read where have_j (and
** have_ni); the start's sines and cosines from strig where given; J, its
** point and Ni are written where J is taken afresh (fresh, out_ni), the
** result's sines and cosines where it converged without Newton (out_trig,
** rtrig). */
struct Carry {
    pm_track *t;
    bool have_j, have_ni;         /* in */
    const double *strig;          /* in: the start's sines and cosines, or 0 */
    bool fresh, out_ni, out_trig; /* out */
    double rtrig[4];              /* out: the result's sines and cosines */
    int used;                     /* out: evaluations made */
};

/* The state of solve_branch's iteration.
**
** Iteration: g = F(D^), the closed form for the displacement D^; the
** model's displacement D at g misses D^ by |D - D^|, which is g's
** round-trip error (to first order): the measured stop.  The next D^ is
** the Newton step on D^ = D(F(D^)) with J = dD/dx from the first
** evaluation (a chord: J is not evaluated again), and where lip2 is known
** the next point's error is bounded before it is evaluated,
**   |D(x') - D^'| <= |D + J h - D^'| + lip2 (|x - x_J| + |h| / 2) |h|,
** h = x' - x: the predicted stop. */
struct Branch {
    /* the call */
    const pm_model *m;
    const Iso<double> *k;
    const pm_context *ctx;
    const Aim *a;
    const Target<double> *tg;
    const double *start;
    Carry *carry;        /* pm_model_track's J, or 0 */
    double ref_t, ref_d; /* the turn the angles are kept on (turn_of) */
    double lip2;         /* the second-derivative bound; -1: no predicted stop */
    bool raw;            /* a term reads the raw angles (on_turn at every point) */
    int side;            /* the closed form's branch */
    /* the points (three slots, passed round by pointer: no copies), J, Ni */
    Trig<double> *slot;
    double *J, *Ni;
    Trig<double> *gp, *bp; /* the current point, the best */
    double dh_t, dh_d;     /* D^ of *gp */
    double d0t, d0d;       /* D at *gp, where have_d */
    double dist_j;         /* the distance from J's point (1e300: no bound) */
    int used;              /* evaluations made */
    bool have_j, have_n, tried_n, have_d, reachable;
    /* the general loop: the misses, the best point's D, D^ and distance */
    double change, last_change, best_change;
    double b_dt, b_dd, b_ht, b_hd, b_dist;
    bool converged, best_reachable;
    bool chord; /* Newton steps on D (else plain fixed-point steps) */
    int it0;    /* the iteration the general loop starts at; ~it0 (< 0):
                ** none, Newton at once (no_chord) */
};

/* The predicted stop (Note 1 of pm_model_invert in pm.h) needs the
** second-derivative bound: finite only where J is complete (harmonic and
** AUX terms) and no term reads the raw angles; the AUX terms' part at
** this context.  -1: no prediction. */
PM_HOT double lip2_at(const pm_model *m, const pm_context *ctx, bool raw)
{
    double lip2 = raw ? __builtin_inf() : m->lip2;
    if (lip2 < 1e300)
        for (int i = m->n_base; i < m->n_terms; i++)
            lip2 += 1.45 * m_fabs(m->coef[i] * (aux_input(ctx, m->term[i].aux) -
                                                m->term[i].param));
    if (!(lip2 < 1e300))
        lip2 = -1; /* no prediction */
    return lip2;
}

/* No anisotropic term: D = 0 everywhere. */
PM_HOT bool iso_only(const pm_model *m)
{
    return m->order == 0 && m->n_terms == m->n_base;
}

/* A bound on the length in angle of the step whose sines are (ht, hd). */
PM_HOT double step_len(double ht, double hd)
{
    const double h2 = ht * ht + hd * hd;
    return m_sqrt(h2) * (1 + h2 * 0.2);
}

/* pm_model_track's J at the start g, where the state's applies (its point
** within reach of g): then it is s->J, with its distance from g in
** dist_j (the predicted stop's bound holds for J taken anywhere, Note 1
** of pm_model_invert), and the state's chord matrix Ni where it has one
** (F_D moves with the point: only the speed depends on it). */
PM_HOT bool carried_j(Branch *s, const Trig<double> &g)
{
    const Carry *c = s->carry;
    if (!c->have_j)
        return false;
    const pm_track *t = c->t;
    Trig<double> gj = g;
    gj.st = t->jac_at[0];
    gj.ct = t->jac_at[1];
    gj.sd = t->jac_at[2];
    gj.cd = t->jac_at[3];
    double ht, hd;
    if (!small_step(g, gj, &ht, &hd))
        return false;
    const double hn = step_len(ht, hd);
    if (!(hn <= PM_TRACK_J_REACH))
        return false;
    for (int i = 0; i < 4; i++)
        s->J[i] = t->jac[i];
    s->dist_j = hn;
    if (c->have_ni) {
        for (int i = 0; i < 4; i++)
            s->Ni[i] = t->ni[i];
        s->tried_n = s->have_n = true;
    }
    return true;
}

/* pm_model_track's J taken afresh at g in this call: the state gets it
** and its point (Carry). */
PM_HOT void fresh_j(Branch *s, const Trig<double> &g)
{
    double *at = s->carry->t->jac_at;
    s->carry->fresh = true;
    at[0] = g.st;
    at[1] = g.ct;
    at[2] = g.sd;
    at[3] = g.cd;
}

/* The next evaluation takes J afresh, and the chord's matrix with it
** (stale_j, slow_chord).  True. */
PM_HOT bool retake_j(Branch *s)
{
    s->have_j = s->have_n = s->tried_n = false;
    return true;
}

/* After a step h of length hn that the predicted stop did not certify:
** where J is pm_model_track's, carried from another tick, and its
** distance alone keeps the next point's bound above 100 PM_INVERT_TOL
** (the bound is ~100 times the real curvature: the next point would still
** miss by more than the tolerance), the next evaluation takes J afresh and
** the chord's matrix with it.  With J carried that far the chord
** contracts by about its error times |F_D|, slowly within a few degrees of
** the mount's pole (|F_D| ~ 1/cos of the distance): 6 evaluations were
** seen where pm_model_invert_near, with J taken at its start, needed 4; a
** fresh J converges quadratically from the next point on. */
PM_HOT bool stale_j(Branch *s, double hn)
{
    if (!(s->carry && !s->carry->fresh && s->lip2 * s->dist_j * hn > 100 * PM_INVERT_TOL))
        return false;
    return retake_j(s);
}

/* After a step the predicted stop did not certify: where the chord
** contracted the miss by less than 1e-3 at the last evaluation (change,
** from last) and the next point will miss by more than the tolerance all
** the same (at that rate), the next evaluation takes J afresh and the
** chord's matrix with it.  Within a few degrees of the mount's pole J goes
** stale within a step (|F_D| ~ 1/cos of the distance magnifies its
** change): a fresh J converges quadratically from the next point on. */
__attribute__((noinline, cold)) bool slow_rate(double change, double last)
{
    return change > 1e-3 * last && change * change > 0.5 * PM_INVERT_TOL * last;
}
PM_HOT bool slow_chord(Branch *s, int it, double last)
{
    return it > 0 && slow_rate(s->change, last) && retake_j(s);
}

/* The first point, in slot 0: the closed form at D^ = 0 (a cold call), or
** the start (one evaluation, with J); the branch (side) and whether the
** closed form reaches the target. */
PM_HOT void first_point(Branch *s)
{
    const pm_model *m = s->m;
    const Iso<double> &k = *s->k;
    Trig<double> &g = s->slot[0];
    if (iso_only(m)) {
        /* No anisotropic term: the closed form is the solution (no
        ** evaluation); from a start, on its branch. */
        if (s->start) { /* (the branch needs the start's declination alone) */
            double sd0, cd0;
            if (s->carry && s->carry->strig) {
                sd0 = s->carry->strig[2];
                cd0 = s->carry->strig[3];
            } else {
                sincos_d(s->start[1], &sd0, &cd0);
            }
            double cdp = cd0 * k.ce + sd0 * k.se;
            s->side = cdp * k.ci >= 0 ? 1 : -1;
        }
        s->reachable = iso_inverse0<double>(k, *s->tg, s->side, &g);
        if (s->raw)
            on_turn(m, k, *s->a, &g, s->ref_t, s->ref_d);
        s->have_d = true; /* (the iteration stops at once: D = D^ = 0) */
    } else if (s->start) {
        /* The branch of the start: the sign of the x-component of
        ** Pd(d - e') T(i) w there, the quantity iso_inverse chooses by
        ** (near the mount's pole it differs from the sign of cos(dec)). */
        if (s->carry && s->carry->strig) {
            const double *tr = s->carry->strig;
            g.st = tr[0];
            g.ct = tr[1];
            g.sd = tr[2];
            g.cd = tr[3];
            g.t = s->start[0];
            g.d = s->start[1];
            g.have_angles = true;
        } else {
            g = trig_of(s->start[0], s->start[1]);
        }
        double dt, dd; /* (locals: the Branch's address stays in here) */
        const bool carried = s->carry && carried_j(s, g);
        if (!carried)
            aniso_jac(m, k, g, s->ctx, &dt, &dd, s->J);
        else
            aniso<double>(m, k, g, s->ctx, &dt, &dd);
        if (s->carry && !carried)
            fresh_j(s, g);
        s->d0t = dt;
        s->d0d = dd;
        s->used = 1;
        s->have_j = s->have_d = true;
        double stp, ctp, sdp, cdp;
        shifted<double>(k, g, &stp, &ctp, &sdp, &cdp);
        V3<double> v = rot_z<double>(k.si, k.ci, expmap<double>(s->d0t, s->d0d));
        s->side = cdp * v.x - sdp * v.z >= 0 ? 1 : -1;
        /* The start is the closed form's exact point for the displacement
        ** at which the target is seen from it: D^ = log((H Pt X Pd T)^T q),
        ** so it is the first iterate (its miss |D - D^| is measured like
        ** the others', and a start that already points there is returned
        ** after one evaluation). */
        V3<double> w = rot_zt<double>(
            k.si, k.ci,
            rot_dt<double>(sdp, cdp,
                           rot_xt<double>(k.sd, k.cd, rot_zt<double>(stp, ctp, s->tg->q0))));
        double ht, hd;
        logmap<double>(w, &ht, &hd);
        s->dh_t = ht;
        s->dh_d = hd;
        s->reachable = true;
    } else {
        s->reachable = iso_inverse0<double>(k, *s->tg, s->side, &g);
    }
    if (s->raw)
        on_turn(m, k, *s->a, &g, s->ref_t, s->ref_d);
}

/* One evaluation of D at g (counted in used); J with the first.  (D
** through locals: the evaluations are calls, and a Branch or Lean whose
** address reached one would live in memory, not in registers.) */
PM_HOT void evaluate(Branch *s, const Trig<double> &g, double *dt_out, double *dd_out)
{
    double dt, dd;
    s->used++;
    if (s->have_j) {
        aniso<double>(s->m, *s->k, g, s->ctx, &dt, &dd);
    } else {
        aniso_jac(s->m, *s->k, g, s->ctx, &dt, &dd, s->J);
        s->have_j = true;
        s->dist_j = 0;
        if (s->carry)
            fresh_j(s, g); /* (stale_j) */
    }
    *dt_out = dt;
    *dd_out = dd;
}

/* The Newton step on D from D = (dt, dd) at D^: the next D^ (chord). */
PM_HOT void chord_step(const Branch *s, double dt, double dd, double *nt, double *nd)
{
    const double *Ni = s->Ni;
    *nt = s->dh_t + (Ni[0] * (dt - s->dh_t) + Ni[1] * (dd - s->dh_d));
    *nd = s->dh_d + (Ni[2] * (dt - s->dh_t) + Ni[3] * (dd - s->dh_d));
}

/* The predicted stop for the step (ht, hd) of length hn to D^ = (nt, nd)
** from D = (dt, dd): the second-order part alone first (it fails most
** steps), then the whole bound (step_bound). */
PM_HOT bool predicted_stop(const Branch *s, double dt, double dd, double ht, double hd,
                           double nt, double nd, double hn)
{
    return !(s->lip2 * (s->dist_j + 0.5 * hn) * hn > PM_INVERT_TOL * 0.5) &&
           step_bound(dt, dd, s->J, ht, hd, nt, nd, s->lip2, s->dist_j, hn) <=
               PM_INVERT_TOL * 0.5;
}

/* How the lean loop hands over where it is not done: the general loop
** takes over at the start of this iteration (bail) or of the next
** (bail_next). */
enum LeanEnd { LEAN_BAIL, LEAN_BAIL_NEXT };

/* The lean loop's own state: the current point, the previous one (the
** best so far: while the steps contract the best point is the current
** one's predecessor or itself), the next; D at the current point; the
** previous point's miss, D, D^ and distance; the step's D^ (bail_next). */
struct Lean {
    Trig<double> *cur, *prv, *nxt;
    double dt, dd, last;
    double p_dt, p_dd, p_ht, p_hd, p_dist;
    double s_nt, s_nd;
    int it;
};

/* The loop below (hand_over) in the state bail_next leaves: the general
** loop at the start of iteration it + 1, as it leaves a step the bound
** cannot follow (dist_j = 1e300): the point at cur the best, the next
** point at nxt. */
PM_HOT void hand_over_next(Branch *s, const Lean *L)
{
    s->it0 = L->it + 1;
    s->bp = L->cur;
    s->best_change = s->last_change = s->change;
    s->b_dt = L->dt;
    s->b_dd = L->dd;
    s->b_ht = s->dh_t;
    s->b_hd = s->dh_d;
    s->b_dist = s->dist_j;
    s->best_reachable = true;
    s->dist_j = 1e300;
    s->gp = L->nxt;
    s->dh_t = L->s_nt;
    s->dh_d = L->s_nd;
}

/* The general loop's state where the lean loop ends with `end` (bail or
** bail_next).  Bail: the general loop at the start of iteration it, the
** evaluation at cur made, the previous point the best (none at it = 0). */
PM_HOT void hand_over(Branch *s, const Lean *L, LeanEnd end)
{
    if (end == LEAN_BAIL_NEXT) {
        hand_over_next(s, L);
        return;
    }
    s->it0 = L->it;
    s->gp = L->cur;
    s->d0t = L->dt;
    s->d0d = L->dd;
    s->have_d = true;
    if (L->it == 0) {
        s->bp = L->cur;
        s->best_change = s->last_change = 1e300;
        s->b_dt = s->b_dd = s->b_ht = s->b_hd = s->b_dist = 0;
    } else {
        s->bp = L->prv;
        s->best_change = s->last_change = L->last;
        s->b_dt = L->p_dt;
        s->b_dd = L->p_dd;
        s->b_ht = L->p_ht;
        s->b_hd = L->p_hd;
        s->b_dist = L->p_dist;
    }
    s->best_reachable = true;
}

/* The lean loop certifies point p (converged, the best point). */
PM_HOT void lean_stop(Branch *s, Trig<double> *p)
{
    s->bp = p;
    s->best_reachable = true;
    s->converged = true;
}

/* The lean loop's step taken: the current point (D = (dt, dd)) becomes
** the previous one, the best so far; the next point, at D^ = (nt, nd) a
** step hn from it, the current one. */
PM_HOT void lean_advance(Branch *s, Lean *L, double dt, double dd, double nt, double nd,
                         double hn)
{
    L->p_dt = dt;
    L->p_dd = dd;
    L->p_ht = s->dh_t;
    L->p_hd = s->dh_d;
    L->p_dist = s->dist_j;
    L->last = s->change;
    s->dist_j += hn;
    s->dh_t = nt;
    s->dh_d = nd;
    Trig<double> *x = L->prv;
    L->prv = L->cur;
    L->cur = L->nxt;
    L->nxt = x;
}

/* The typical call (far from the mount's pole, a small anisotropic
** displacement): every Newton step on D contracts, and the predicted stop
** certifies a point within PM_INVERT_MAX_FIXED evaluations.  The same
** operations and decisions as the general loop, without its bookkeeping
** for the other cases: while the steps contract the best point is the
** current one.  At the first event of another kind (no contraction, no
** Newton step, a step beyond the closed form's reach, an overflow) the
** general loop takes over at the start of that iteration, with the
** evaluation made (have_d) and the state it would have had; after a step
** beyond 0.01 rad (small_step), at the start of the next one.  Where
** there is no Newton step (the chord's matrix ill-conditioned) it0 says so
** (~it: no_chord decides).  Where a step contracted slowly the next
** evaluation takes J afresh (slow_chord).  True where the lean loop is
** done (the general loop is not needed). */
PM_HOT bool lean_loop(Branch *s)
{
    Lean L;
    L.cur = &s->slot[0];
    L.prv = &s->slot[1];
    L.nxt = &s->slot[2];
    L.dt = s->d0t;
    L.dd = s->d0d;
    L.last = 1e300;
    L.p_dt = L.p_dd = L.p_ht = L.p_hd = L.p_dist = 0;
    L.s_nt = L.s_nd = 0;
    LeanEnd end = LEAN_BAIL;
    for (L.it = 0;; L.it++) {
        if (!s->have_d) {
            if (s->used >= PM_INVERT_MAX_FIXED) {
                /* (the general loop would stop here, with the best point) */
                s->bp = L.prv;
                s->best_reachable = true;
                return true;
            }
            evaluate(s, *L.cur, &L.dt, &L.dd);
        }
        s->have_d = false;
        const double dt = L.dt, dd = L.dd;
        if (!finite(dt * dt + dd * dd)) {
            end = LEAN_BAIL;
            break;
        }
        s->change = m_sqrt((dt - s->dh_t) * (dt - s->dh_t) + (dd - s->dh_d) * (dd - s->dh_d));
        if (s->change <= PM_INVERT_TOL * 0.5) {
            lean_stop(s, L.cur);
            return true;
        }
        if (L.it > 0 && s->change > 0.5 * L.last) {
            end = LEAN_BAIL;
            break;
        }
        if (!s->tried_n) {
            s->tried_n = true;
            /* (a cold call's first point: D^ = 0; J afresh later: D^ as found) */
            s->have_n = s->start || L.it ? newton_prep(*s->k, *L.cur, s->dh_t, s->dh_d, s->J, s->Ni)
                                         : newton_prep0(*s->k, *L.cur, s->J, s->Ni);
        }
        if (!(s->have_n && s->change <= 0.01)) {
            if (!s->have_n) { /* (no_chord) */
                hand_over(s, &L, LEAN_BAIL);
                s->it0 = ~s->it0;
                s->J[4] = dt;
                s->J[5] = dd;
                return false;
            }
            end = LEAN_BAIL;
            break;
        }
        double nt, nd, ht, hd;
        chord_step(s, dt, dd, &nt, &nd);
        if (!iso_inverse<double>(*s->k, *s->tg, nt, nd, s->side, L.nxt)) {
            end = LEAN_BAIL;
            break;
        }
        if (!small_step(*L.nxt, *L.cur, &ht, &hd)) {
            /* a step beyond 0.01 rad: no bound from here on, the general
            ** loop takes over after it */
            L.s_nt = nt;
            L.s_nd = nd;
            end = LEAN_BAIL_NEXT;
            break;
        }
        const double hn = step_len(ht, hd);
        if (predicted_stop(s, dt, dd, ht, hd, nt, nd, hn)) {
            lean_stop(s, L.nxt);
            return true;
        }
        const bool rejac = stale_j(s, hn) || slow_chord(s, L.it, L.last);
        lean_advance(s, &L, dt, dd, nt, nd, hn);
        if (rejac) /* (the best point's distance from where J will be taken) */
            L.p_dist = hn;
    }
    hand_over(s, &L, end);
    return false;
}

/* Not contracting (general_loop): where the steps were Newton's on D
** (with J from the first evaluation: a term that varies fast makes J a
** poor guide), plain fixed-point steps from the best point, its D in
** (dt, dd); false where they were plain already or had no Newton step
** (Newton on the forward model takes over). */
PM_HOT bool fall_back(Branch *s, double *dt, double *dd)
{
    if (!(s->chord && s->have_n))
        return false;
    s->chord = false;
    s->gp = s->bp;
    s->reachable = s->best_reachable;
    *dt = s->b_dt;
    *dd = s->b_dd;
    s->dh_t = s->b_ht;
    s->dh_d = s->b_hd;
    s->dist_j = s->b_dist;
    s->change = s->best_change;
    return true;
}

/* The general loop's step from *gp, where D = (dt, dd): the next D^ (the
** chord step, or the plain fixed-point step D^' = D), its point in a free
** slot, the predicted stop.  True where that stops the iteration
** (converged). */
PM_HOT bool general_next(Branch *s, double dt, double dd)
{
    double nt = dt, nd = dd, ht, hd;
    if (!s->tried_n) { /* (F_D once, where the first step needs it) */
        s->tried_n = true;
        s->have_n = newton_prep(*s->k, *s->gp, s->dh_t, s->dh_d, s->J, s->Ni);
    }
    if (s->chord && s->have_n && s->change <= 0.01)
        chord_step(s, dt, dd, &nt, &nd);
    Trig<double> *g2p = &s->slot[0];
    while (g2p == s->gp || g2p == s->bp)
        g2p++;
    s->reachable = iso_inverse<double>(*s->k, *s->tg, nt, nd, s->side, g2p);
    if (s->raw)
        on_turn(s->m, *s->k, *s->a, g2p, s->ref_t, s->ref_d);
    if (s->lip2 >= 0 && small_step(*g2p, *s->gp, &ht, &hd)) {
        const double hn = step_len(ht, hd);
        if (predicted_stop(s, dt, dd, ht, hd, nt, nd, hn)) {
            s->bp = g2p;
            s->best_reachable = s->reachable;
            s->converged = true;
            return true;
        }
        s->dist_j += hn;
    } else {
        s->dist_j = 1e300; /* (a bound fails from here on: J is not evaluated again) */
    }
    s->gp = g2p;
    s->dh_t = nt;
    s->dh_d = nd;
    return false;
}

/* The point *gp, where D = (dt, dd), the best so far (general_loop). */
PM_HOT void keep_best(Branch *s, double dt, double dd)
{
    s->best_change = s->change;
    s->bp = s->gp;
    s->best_reachable = s->reachable;
    s->b_dt = dt;
    s->b_dd = dd;
    s->b_ht = s->dh_t;
    s->b_hd = s->dh_d;
    s->b_dist = s->dist_j;
}

/* The general loop, from iteration it0: the fixed point with its best
** point kept, plain steps where the chord does not contract.  Each
** iteration: D at *gp (evaluated, or the lean loop's), the best point so
** far, the measured stop, the contraction (else fall_back), the step
** (general_next).  It stops converged, out of evaluations, at an overflow
** or with no contraction left.  (One loop, as the lean one: see above.) */
PM_HOT void general_loop(Branch *s)
{
    for (int it = s->it0; !s->converged; it++) {
        double dt, dd;
        if (s->have_d) {
            dt = s->d0t;
            dd = s->d0d;
            s->have_d = false;
        } else {
            if (s->used >= PM_INVERT_MAX_FIXED)
                break;
            evaluate(s, *s->gp, &dt, &dd);
        }
        if (!finite(dt * dt + dd * dd))
            break; /* the forward model overflows here: not converged */
        s->change = m_sqrt((dt - s->dh_t) * (dt - s->dh_t) + (dd - s->dh_d) * (dd - s->dh_d));
        if (s->change < s->best_change)
            keep_best(s, dt, dd);
        if (s->change <= PM_INVERT_TOL * 0.5) {
            s->converged = true;
            break;
        }
        if (it > 0 && s->change > 0.5 * s->last_change && !fall_back(s, &dt, &dd))
            break;
        s->last_change = s->change;
        if (general_next(s, dt, dd))
            break;
    }
}

/* Where the lean loop stopped at a point (*gp, D in J[4], J[5]) whose
** chord's matrix I - J F_D is ill-conditioned (no Newton step on D: within
** about the anisotropic amplitude of the mount's pole), it0 = ~it (the
** general loop's state made, hand_over).  In a call from a start (want =
** 0: invert_near, pm_model_track) Newton on the forward model starts there
** at once, not after the general loop's plain fixed-point steps, which do
** not contract there either (K = J F_D has an eigenvalue near 1) and spent
** one or two evaluations first; the point is the best so far (the steps
** before it contracted), and where J was taken there its evaluation is
** Newton's first point (finish_branch).  A cold call (want = +-1) keeps
** the general loop (it0 = it): its plain steps cost fewer instructions
** than Newton's trial points near the pole.  True where Newton takes over. */
PM_HOT bool no_chord(Branch *s, int want)
{
    if (want) {
        s->it0 = ~s->it0;
        return false;
    }
    s->bp = s->gp;
    s->best_reachable = true;
    return true;
}

/* Are the angles (t, d), the best point's rounded to doubles, safe to
** return without a check?  The fixed point judged the position before
** its angles were rounded (atan2, the turn), with PM_INVERT_TOL / 2 to
** spare.  The rounding (a few ulp of the larger angle) moves the model's
** position by up to 1 + lip times as much; where that could use the
** margin, Newton checks the round trip at the returned angles themselves
** (pm.h, pm_model_invert Note 4). */
PM_HOT bool rounding_safe(const Branch *s, const Trig<double> &gb, double t, double d)
{
    const pm_model *m = s->m;
    double big = m_fabs(t) > m_fabs(d) ? m_fabs(t) : m_fabs(d);
    double lip = m->lip;
    bool sided = false;
    for (int i = m->n_base; i < m->n_terms; i++) {
        if (m->term[i].kind == PM_TERM_AUX) /* (ctx checked by eval_ready) */
            lip += m_fabs(m->coef[i] * (aux_input(s->ctx, m->term[i].aux) - m->term[i].param)) *
                   2;
        sided = sided || m->term[i].side != 0;
    }
    /* (the AUX terms' part of lip is twice their largest displacement:
    ** beyond 0.5 rad, as for lipschitz(), every inverse is checked) */
    if (!((1 + lip) * 8 * DBL_EPS * (big > 1 ? big : 1) <= 0.5 * PM_INVERT_TOL) ||
        !(lip - m->lip <= 1))
        return false;
    /* A term restricted to one side of the pole jumps at the pole's edge;
    ** where rounding the angles moved the point across it, the returned
    ** angles evaluate a different model: Newton checks them. */
    return !(sided && !(s->ctx && s->ctx->pier) &&
             side_at(*s->k, gb) != side_at(*s->k, trig_of(t, d)));
}

/* The result from the best point: its angles, checked by Newton (newton)
** where the iteration did not converge, the closed form did not reach
** the target, the point is not on the side wanted or rounding could
** matter (rounding_safe).  *err_out: Newton's measured miss, or -1 where
** the point is returned without Newton (PM_OK, and on the side wanted
** where want is given: invert need not ask side_of again). */
PM_HOT pm_status finish_branch(Branch *s, int want, const double *turn, double *t_out,
                               double *d_out, double *err_out)
{
    Trig<double> &gb = *s->bp;
    const bool reachable = s->best_reachable;
    if (!s->raw)
        on_turn(s->m, *s->k, *s->a, &gb, s->ref_t, s->ref_d);
    double t = gb.t; /* on the turn of ref_t, ref_d (on_turn) */
    double d = gb.d;
    bool converged = s->converged && rounding_safe(s, gb, t, d);
    pm_status result = PM_OK;
    double err = -1; /* (no Newton: see above) */
    if (s->carry)
        s->carry->out_trig = false;
    if (!converged || !reachable || (want && side_of(s->m, d) != want)) {
        result = newton(s->m, *s->k, s->ctx, *s->a, turn, &t, &d, &err, s->it0 < 0 ? 2 : want,
                        PM_INVERT_MAX_FIXED + PM_INVERT_MAX_NEWTON - s->used, 0,
                        s->it0 < 0 && s->dist_j == 0 ? s->J : 0);
        if (result != PM_OK && !reachable)
            result = PM_WARN_UNREACHABLE;
    } else if (s->carry) {
        double *tr = s->carry->rtrig;
        tr[0] = gb.st;
        tr[1] = gb.ct;
        tr[2] = gb.sd;
        tr[3] = gb.cd;
        s->carry->out_trig = true;
    }
    if (s->carry) {
        Carry *c = s->carry;
        c->used = s->used;
        if (c->fresh) { /* J, and Ni where the iteration made one with it */
            c->out_ni = s->have_n;
            for (int i = 0; i < 4; i++) {
                c->t->jac[i] = s->J[i];
                c->t->ni[i] = s->Ni[i];
            }
        }
    }
    *t_out = t;
    *d_out = d;
    *err_out = err;
    return result;
}

/* Solve on one branch of the closed form (side = +1/-1), or from the start
** position's branch, with the angles on the turn the result is returned
** on (turn_of).  Returns the status, (t, d) and the miss at (t, d) (0 for
** PM_OK: below PM_INVERT_TOL).  The fixed point (Branch) by the lean loop
** where the typical iteration applies, the general loop where it does not
** or from where it ends; Newton on the forward model where neither
** certifies a point (finish_branch). */
template <bool TRACK>
pm_status solve_branch(const pm_model *m, const Iso<double> &k,
                       const pm_context *ctx, const Aim &a, int side, int want,
                       const double *start, Carry *carry,
                       const double *turn, double *t_out, double *d_out, double *err_out)
{
    const Target<double> tg = target_of(k, a.q);
    Trig<double> slot[3];
    double J[6], Ni[4]; /* (J[4], J[5]: D where no_chord starts Newton) */
    Branch s;
    s.m = m;
    s.k = &k;
    s.ctx = ctx;
    s.a = &a;
    s.tg = &tg;
    s.start = start;
    s.carry = TRACK ? carry : 0; /* (the other calls compile without it) */
    /* Periodic terms of non-integer G read the raw angle itself, not only
    ** its sine and cosine: iterate with the angles on the returned turn
    ** (on_turn at every point), else once, at the end. */
    s.ref_t = turn[0];
    s.ref_d = turn[1];
    s.raw = reads_raw_angles(m);
    s.lip2 = lip2_at(m, ctx, s.raw);
    s.side = side;
    s.slot = slot;
    s.J = J;
    s.Ni = Ni;
    s.dh_t = s.dh_d = s.d0t = s.d0d = s.dist_j = 0;
    s.used = 0;
    s.have_j = s.have_n = s.tried_n = s.have_d = false;
    first_point(&s);
    s.change = 0;
    s.converged = false;
    s.chord = true;
    s.it0 = 0;
    s.gp = s.bp = &slot[0];
    bool lean_done = false;
    if (s.reachable && s.lip2 >= 0 && !iso_only(m)) {
        lean_done = lean_loop(&s);
    } else {
        s.last_change = s.best_change = 1e300;
        s.best_reachable = s.reachable;
        s.b_dt = s.b_dd = s.b_ht = s.b_hd = s.b_dist = 0;
    }
    if (__builtin_expect(!lean_done, 0)) { /* (the typical call is done) */
        if (s.it0 >= 0 || !no_chord(&s, want))
            general_loop(&s);
    }
    return finish_branch(&s, want, turn, t_out, d_out, err_out);
}

/* The pole rescue's parametrisation: at encoder hour angle t (st, ct its
** sine and cosine) and displacement (a, b), the rotation Pd(d') about the
** declination axis that brings the pointing into the plane of the target
** and that axis is (sdp, cdp) = (sin d', cos d') times |v_xz| |u_xz|
** (u = (Pt(t') X)^T H^T q the target, v = T(i) expmap(a, b) the pointing,
** both in the frame of the declination axis, y): exact.  Returns the miss
** left along the axis, v_y - u_y: zero at a solution. */
__attribute__((noinline)) double ring_point(const Iso<double> &k, const V3<double> &q0, double st, double ct,
                         double a, double b, double *sdp, double *cdp)
{
    const double stp = st * k.cc + ct * k.sc, ctp = ct * k.cc - st * k.sc;
    const V3<double> u = rot_xt<double>(k.sd, k.cd, rot_zt<double>(stp, ctp, q0));
    const V3<double> v = expmap_z<double>(k.si, k.ci, a, b);
    *cdp = u.x * v.x + u.z * v.z;
    *sdp = u.z * v.x - u.x * v.z;
    return v.y - u.y;
}

/* The root in [0, 1] of the parabola through (x0 - 1, y0), (x0, y1),
** (x0 + 1, y2), with x0 = 0 or 1, where the root is bracketed in [0, 1]
** (the middle one of y0, y1 and y1, y2 of opposite signs). */
__attribute__((noinline)) double bracket_root(double y0, double y1, double y2, int x0)
{
    /* y = c0 + c1 u + c2 u^2, u = x - x0 */
    const double c0 = y1, c1 = 0.5 * (y2 - y0), c2 = 0.5 * (y2 + y0) - y1;
    const double ya = x0 ? y0 : y1, yb = x0 ? y1 : y2; /* at x = 0, 1 */
    double r = ya != yb ? ya / (ya - yb) : 0; /* the straight line's */
    const double disc = c1 * c1 - 4 * c2 * c0;
    if (c2 != 0 && disc >= 0) {
        const double sq = m_sqrt(disc);
        const double u1 = (-c1 + sq) / (2 * c2) + x0, u2 = (-c1 - sq) / (2 * c2) + x0;
        if (u1 >= 0 && u1 <= 1)
            r = u1;
        else if (u2 >= 0 && u2 <= 1)
            r = u2;
    }
    return r;
}

/* What pole_rescue learns from the ring of hour angles round the mount's
** pole: the edge points (Newton's starts, by miss), each ring point's
** displacement and miss E, and the brackets of E's sign changes on the
** requested side (their start, by the smaller |E| of their ends). */
struct PoleScan {
    NPoint edge[PM_INVERT_POLE_RUNS + 1];
    int n_edge;
    double sa[PM_INVERT_POLE_STARTS], sb[PM_INVERT_POLE_STARTS], se[PM_INVERT_POLE_STARTS];
    double bt[PM_INVERT_POLE_RUNS], bd[PM_INVERT_POLE_RUNS], bs[PM_INVERT_POLE_RUNS];
    int n_b;
};

/* The ring: PM_INVERT_POLE_STARTS hour angles, d(t_j) for no displacement
** (ring_point), one evaluation there (the displacement D_j and the miss,
** kept sorted by miss in ps->edge), E(t_j) again with D_j. */
inline void pole_ring(const pm_model *m, const Iso<double> &k, const pm_context *ctx,
                      const Frame &f, const V3<double> &q0, const double *turn, PoleScan *ps)
{
    const double step = 2 * PI / PM_INVERT_POLE_STARTS;
    ps->n_edge = 0;
    for (int j = 0; j < PM_INVERT_POLE_STARTS; j++) {
        double tj = -PI + step * (j + 0.5), st, ct, sdp, cdp;
        sincos_d(tj, &st, &ct);
        ring_point(k, q0, st, ct, 0.0, 0.0, &sdp, &cdp);
        double dj = m_atan2(sdp, cdp) + m->coef[4];
        finish_angles(turn, &tj, &dj);
        int i = ps->n_edge < PM_INVERT_POLE_RUNS ? ps->n_edge++ : PM_INVERT_POLE_RUNS;
        NPoint *edge = ps->edge;
        newton_point(m, k, ctx, f, tj, dj, &edge[i]);
        ps->sa[j] = edge[i].da;
        ps->sb[j] = edge[i].db;
        ps->se[j] = ring_point(k, q0, st, ct, ps->sa[j], ps->sb[j], &sdp, &cdp);
        if (!finite(ps->se[j]))
            ps->se[j] = 0;
        for (; i > 0 && (edge[i].err < edge[i - 1].err || !(edge[i - 1].err >= 0)); i--) {
            NPoint x = edge[i];
            edge[i] = edge[i - 1];
            edge[i - 1] = x;
        }
    }
}

/* The brackets on the side requested, by the smaller |E| of their ends (a
** solution near a point where the displacement was evaluated). */
inline void pole_brackets(const pm_model *m, const Iso<double> &k, const V3<double> &q0,
                          const double *turn, int side, PoleScan *ps)
{
    const double step = 2 * PI / PM_INVERT_POLE_STARTS;
    const double *se = ps->se, *sa = ps->sa, *sb = ps->sb;
    ps->n_b = 0;
    for (int j = 0; j < PM_INVERT_POLE_STARTS; j++) {
        const int jn = (j + 1) % PM_INVERT_POLE_STARTS;
        const double e0 = se[j], e1 = se[jn];
        if (e0 * e1 > 0)
            continue;
        /* the root in [0, 1] of the parabolas through the bracket and
        ** either neighbour (E varies with the displacement, by the
        ** harmonics of t: a straight line misses roots near a turning
        ** point), averaged */
        const double em = se[(j + PM_INVERT_POLE_STARTS - 1) % PM_INVERT_POLE_STARTS],
                     ep = se[(jn + 1) % PM_INVERT_POLE_STARTS];
        const double w = 0.5 * (bracket_root(em, e0, e1, 0) + bracket_root(e0, e1, ep, 1));
        double tj = -PI + step * (j + 0.5 + w), st, ct, sdp, cdp;
        sincos_d(tj, &st, &ct);
        ring_point(k, q0, st, ct, sa[j] + w * (sa[jn] - sa[j]), sb[j] + w * (sb[jn] - sb[j]),
                   &sdp, &cdp);
        double dj = m_atan2(sdp, cdp) + m->coef[4];
        finish_angles(turn, &tj, &dj);
        if (side_of(m, dj) != side)
            continue;
        const double sc = m_fabs(e0) < m_fabs(e1) ? m_fabs(e0) : m_fabs(e1);
        int i;
        if (ps->n_b < PM_INVERT_POLE_RUNS)
            i = ps->n_b++;
        else if (sc < ps->bs[PM_INVERT_POLE_RUNS - 1])
            i = PM_INVERT_POLE_RUNS - 1; /* (replaces the last) */
        else
            continue;
        for (; i > 0 && sc < ps->bs[i - 1]; i--) {
            ps->bt[i] = ps->bt[i - 1];
            ps->bd[i] = ps->bd[i - 1];
            ps->bs[i] = ps->bs[i - 1];
        }
        ps->bt[i] = tj;
        ps->bd[i] = dj;
        ps->bs[i] = sc;
    }
}

/* The pole rescue of pm_model_invert (pm.h, Note 2), after both branches
** failed to give a PM_OK point on the requested side: (t, d, err) the
** first branch's point and status `result`, (t2, d2, err2) the second's
** and its status r2; returns the status and the point in (t, d, err).
** Kept out of line: its table of edge points would otherwise sit in every
** inverse's stack frame. */
__attribute__((noinline)) pm_status pole_rescue(const pm_model *m, const Iso<double> &k,
                                                const pm_context *ctx, const Aim &a, int side,
                                                const double *turn, pm_status result,
                                                pm_status r2, double t2, double d2,
                                                double err2, double *tp, double *dp,
                                                double *errp)
{
    double t = *tp, d = *dp, err = *errp;
    /* Close to the mount's pole a solution on the requested side
    ** can lie between the pole and the fold, out of both branches'
    ** reach: Newton from PM_INVERT_POLE_STARTS points on the edge
    ** of the pole nearer the target (the sign of the target's
    ** component along the polar axis, H^T q), on the requested
    ** side.  (The other pole is at least 90 deg less the
    ** isotropic and anisotropic amplitudes away.) */
    bool found = false;
    /* unreachable: the nearest point on the requested side seen
    ** (the branches' misses: a point not PM_OK came from Newton,
    ** which measured it) */
    double best_err = 1e300, best_t = t, best_d = d;
    if (side_of(m, d) == side && result != PM_OK)
        best_err = err;
    if (side_of(m, d2) == side && r2 != PM_OK && err2 < best_err) {
        best_err = err2;
        best_t = t2;
        best_d = d2;
    }
    const Frame f = frame_of(k, a);
    const V3<double> q0 = mat_tmul<double>(k.h, a.q);
    /* A pole-aware parametrisation: for an hour angle t, the declination
    ** d(t) that turns the pointing into the plane of the target and the
    ** polar axis (exact, ring_point) leaves one equation, E(t) = 0 (the
    ** pointing's miss along the declination axis), on the circle of hour
    ** angles (pole_ring).  A change of sign of E between neighbours
    ** brackets a solution (the displacement changes little between them):
    ** the interpolated hour angle and displacement give a start close to
    ** it, on the side requested (pole_brackets).  Newton runs from the best
    ** bracket and then from the points with the smallest miss,
    ** PM_INVERT_POLE_RUNS runs in all. */
    PoleScan ps;
    pole_ring(m, k, ctx, f, q0, turn, &ps);
    pole_brackets(m, k, q0, turn, side, &ps);
    for (int r = 0; r < PM_INVERT_POLE_RUNS && !found; r++) {
        double tj, dj, ej;
        pm_status sj;
        if (r < ps.n_b) {
            tj = ps.bt[r];
            dj = ps.bd[r];
            sj = newton(m, k, ctx, a, turn, &tj, &dj, &ej, side, PM_INVERT_POLE_NEWTON);
        } else {
            const int e = r - ps.n_b;
            if (e >= ps.n_edge || !(ps.edge[e].err >= 0))
                break;
            tj = ps.edge[e].t;
            dj = ps.edge[e].d;
            sj = newton(m, k, ctx, a, turn, &tj, &dj, &ej, side, PM_INVERT_POLE_NEWTON,
                        &ps.edge[e]);
        }
        if (side_of(m, dj) != side)
            continue;
        if (sj == PM_OK) {
            t = tj;
            d = dj;
            result = PM_OK;
            found = true;
        } else if (ej < best_err) {
            best_err = ej;
            best_t = tj;
            best_d = dj;
        }
    }
    if (!found) {
        /* nothing on the requested side reaches the target */
        result = PM_WARN_UNREACHABLE;
        if (best_err < 1e300) {
            t = best_t;
            d = best_d;
            err = best_err;
        }
    }
    *tp = t;
    *dp = d;
    *errp = err;
    return result;
}

/* Shared inverse: side = +1/-1, or use the start position. */
template <bool TRACK>
pm_status invert(const pm_model *m, const pm_context *ctx, double app_ha,
                 double app_dec, int side, const double *start, Carry *carry,
                 double *enc_ha, double *enc_dec)
{
    /* (pm_model_track checked the model and the context itself, before it
    ** read them) */
    pm_status st = TRACK ? PM_OK : eval_ready(m, ctx);
    if (st != PM_OK)
        return st;
    if (!enc_ha || !enc_dec)
        return PM_ERR_ARG;
    if (!finite(app_ha) || !finite(app_dec) ||
        (start && (!finite(start[0]) || !finite(start[1]))))
        return PM_ERR_NONFINITE;
    if (m_fabs(app_dec) > PI / 2 + 1e-12)
        return PM_ERR_ARG;
    if (start && (m_fabs(start[0]) > PM_START_MAX || m_fabs(start[1]) > PM_START_MAX))
        return PM_ERR_ARG;

    const Iso<double> &k = iso_of(m);
    Aim a;
    a.ha = app_ha;
    a.dec = app_dec;
    sincos_d2(app_ha, app_dec, &a.sh, &a.ch, &a.sd, &a.cd);
    a.q = v3(a.cd * a.ch, a.cd * a.sh, a.sd);
    double turn[2], t, d, err;
    turn_of(start, side, m->coef[4], turn);
    pm_status result =
        TRACK ? solve_branch<true>(m, k, ctx, a, side, 0, start, carry, turn, &t, &d, &err)
              : solve_branch<false>(m, k, ctx, a, side, start ? 0 : side, start, 0, turn, &t,
                                    &d, &err);
    /* (err < 0: PM_OK on the side asked for, finish_branch checked it) */
    if (!TRACK && !start && (result != PM_OK || (err >= 0 && side_of(m, d) != side))) {
        /* Within the anisotropic amplitude of the mount's pole the closed
        ** form's branches (sign of cos(dec - e' + displacement angle)) and
        ** the sides of the pole (sign of cos(dec - e')) differ: the other
        ** branch may hold the solution on the requested side. */
        double t2, d2, err2;
        pm_status r2 = solve_branch<false>(m, k, ctx, a, -side, side, 0, 0, turn, &t2, &d2, &err2);
        if (r2 == PM_OK && side_of(m, d2) == side) {
            result = r2;
            t = t2;
            d = d2;
            err = err2;
        } else {
            result = pole_rescue(m, k, ctx, a, side, turn, result, r2, t2, d2, err2, &t,
                                 &d, &err);
        }
    }
    /* A warning returns the best position found: the model must still be
    ** finite there (coefficients or context values can overflow it, and
    ** then no position is any good): its miss, measured where it was
    ** found, is finite.  PM_OK already passed the round trip. */
    if (!finite(t) || !finite(d) || (result != PM_OK && !finite(err)))
        return PM_ERR_NONFINITE; /* outputs untouched */
    finish_angles(turn, &t, &d);
    *enc_ha = t;
    *enc_dec = d;
    return result;
}

} /* namespace */

/* Is an added term well formed for model m? */
static bool term_valid(const pm_model *m, const pm_term *t)
{
    if (t->side < -1 || t->side > 1)
        return false;
    if (t->kind != PM_TERM_ZENITH && (t->k < 1 || t->k > 6))
        return false;
    switch (t->kind) {
    case PM_TERM_SH:
        return t->l >= 0 && t->l <= m->order && t->m >= -t->l && t->m <= t->l;
    case PM_TERM_FOURIER:
        return (t->l == 1 || t->l == 2) && (t->m == 0 || t->m == 1) &&
               finite(t->param) && t->param > 0 && t->param <= 1e6;
    case PM_TERM_SECTORAL:
        return (t->m == 0 || t->m == 1) && t->param >= 1 && t->param <= 100000 &&
               t->param == (double)(long)t->param;
    case PM_TERM_ZENITH:
        return t->l == 0 || t->l == 1;
    case PM_TERM_AUX:
        return t->aux <= PM_AUX_USER + PM_MAX_AUX - 1 && finite(t->param);
    default:
        return false;
    }
}

/* Is term i of m one pm_model_prepare accepts?  (m->order within
** 0..PM_MAX_L and m->n_base within 6..m->n_terms checked before.) */
static bool term_ok(const pm_model *m, int i)
{
    const pm_term *t = &m->term[i];
    if (i >= m->n_base)
        return term_valid(m, t);
    /* the harmonic set: plain SH, both sides */
    if (t->kind != PM_TERM_SH || t->k < 1 || t->k > 6 || t->side != 0)
        return false;
    if (i < 6)
        return t->l == 0 && t->k == i + 1; /* the six isotropic terms come first */
    return t->l >= 1 && t->l <= m->order && t->m >= -t->l && t->m <= t->l;
}

namespace pm {
namespace detail {

bool terms_intact(const pm_model *m)
{
    if (m->mount != PM_MOUNT_EQUATORIAL && m->mount != PM_MOUNT_ALTAZ)
        return false;
    if (m->order < 0 || m->order > PM_MAX_L || m->n_terms < 6 || m->n_terms > PM_MAX_TERMS ||
        m->n_base < 6 || m->n_base > m->n_terms)
        return false;
    int aux = 0;
    for (int i = 0; i < m->n_terms; i++) {
        if (!term_ok(m, i))
            return false;
        aux |= m->term[i].kind == PM_TERM_AUX;
    }
    return m->needs_ctx == aux;
}

} /* namespace detail */
} /* namespace pm */

extern "C" {

pm_status pm_model_init(pm_model *m, int mount, int order)
{
    if (!m)
        return PM_ERR_ARG;
    if (mount != PM_MOUNT_EQUATORIAL && mount != PM_MOUNT_ALTAZ)
        return PM_ERR_ARG;
    if (order < 0 || order > PM_MAX_L)
        return PM_ERR_CAPACITY;
    __builtin_memset(m, 0, sizeof *m);
    m->mount = mount;
    m->order = order;
    int n = 0;
    for (int l = 0; l <= order; l++)
        for (int mm = -l; mm <= l; mm++)
            for (int k = 1; k <= 6; k++) {
                if (dropped(k, l, mm))
                    continue;
                m->term[n].kind = PM_TERM_SH;
                m->term[n].k = (unsigned char)k;
                m->term[n].l = (signed char)l;
                m->term[n].m = (signed char)mm;
                n++;
            }
    m->n_terms = n;
    m->n_base = n;
    return pm_model_prepare(m);
}

pm_status pm_model_add_term(pm_model *m, const pm_term *t, double value, int *index)
{
    if (!m || !t)
        return PM_ERR_ARG;
    if (m->prepared != 1)
        return PM_ERR_STATE;
    if (!term_valid(m, t))
        return PM_ERR_ARG;
    if (!finite(value))
        return PM_ERR_NONFINITE;
    if (m->n_terms >= PM_MAX_TERMS)
        return PM_ERR_CAPACITY;
    int n = m->n_terms;
    m->term[n] = *t;
    m->coef[n] = value;
    m->n_terms = n + 1;
    pm_status st = pm_model_prepare(m);
    if (st != PM_OK) {
        m->n_terms = n; /* leave the model as it was */
        pm_model_prepare(m);
        return st;
    }
    if (index)
        *index = n;
    return PM_OK;
}

pm_status pm_model_prepare(pm_model *m)
{
    if (!m)
        return PM_ERR_ARG;
    m->prepared = 0; /* a refused model cannot be evaluated (PM_ERR_STATE) */
    if (m->mount != PM_MOUNT_EQUATORIAL && m->mount != PM_MOUNT_ALTAZ)
        return PM_ERR_ARG;
    if (m->order < 0 || m->order > PM_MAX_L)
        return PM_ERR_CAPACITY;
    if (m->n_terms < 6 || m->n_terms > PM_MAX_TERMS)
        return PM_ERR_CAPACITY;
    if (m->n_base < 6 || m->n_base > m->n_terms)
        return PM_ERR_ARG;
    if (!finite(m->latitude) || m_fabs(m->latitude) > PI / 2)
        return PM_ERR_ARG;
    m->needs_ctx = 0;
    for (int i = 0; i < m->n_terms; i++) {
        if (!term_ok(m, i))
            return PM_ERR_ARG;
        if (m->term[i].kind == PM_TERM_AUX)
            m->needs_ctx = 1;
        if (!finite(m->coef[i]))
            return PM_ERR_NONFINITE;
    }
    /* polar-axis rotation H = exp([w]x), w = (a, b, 0) (Rodrigues) */
    double a = m->coef[0], b = m->coef[1];
    double th2 = a * a + b * b, A, B;
    if (th2 < 1e-8) {
        A = 1 - th2 / 6 + th2 * th2 / 120;
        B = 0.5 - th2 / 24 + th2 * th2 / 720;
    } else {
        double th = m_sqrt(th2);
        A = m_sin(th) / th;
        B = (1 - m_cos(th)) / th2;
    }
    /* [w]x = [[0,0,b],[0,0,-a],[-b,a,0]]; [w]x^2 = w w^T - th2 I */
    double K[9] = {0, 0, b, 0, 0, -a, -b, a, 0};
    double W[3] = {a, b, 0};
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double k2 = W[r] * W[c] - (r == c ? th2 : 0.0);
            m->h[3 * r + c] = (r == c ? 1.0 : 0.0) + A * K[3 * r + c] + B * k2;
            /* a or b beyond ~1e154 rad: a^2 + b^2 overflows and the
            ** rotation is NaN (the inverse's closed form would then give
            ** finite garbage) */
            if (!finite(m->h[3 * r + c]))
                return PM_ERR_NONFINITE;
        }
    m->sc = m_sin(m->coef[2]);
    m->cc = m_cos(m->coef[2]);
    m->sd = m_sin(m->coef[3]);
    m->cd = m_cos(m->coef[3]);
    m->se = m_sin(m->coef[4]);
    m->ce = m_cos(m->coef[4]);
    m->si = m_sin(m->coef[5]);
    m->ci = m_cos(m->coef[5]);
    /* harmonic coefficients per base vector, normalisation folded in */
    __builtin_memset(m->dense, 0, sizeof m->dense);
    for (int i = 6; i < m->n_base; i++) {
        const pm_term *t = &m->term[i];
        int j = t->l * t->l + t->l + t->m;
        m->dense[j][t->k - 1] += m->coef[i] * norm_lm(t->l, t->m);
    }
    m->lip = lipschitz(m);
    m->lip2 = second_rate(m);
    model_digest(m);
    for (int i = 0; i < PM_MAX_TERMS; i++)
        m->prep_coef[i] = i < m->n_terms ? m->coef[i] : 0.0;
    m->prepared = 1;
    return PM_OK;
}

pm_status pm_model_find(const pm_model *m, int k, int l, int mm, int *index)
{
    if (!m || !index || m->n_terms > PM_MAX_TERMS)
        return PM_ERR_ARG;
    for (int i = 0; i < m->n_terms; i++) {
        const pm_term *t = &m->term[i];
        if (t->kind == PM_TERM_SH && t->side == 0 && t->k == k && t->l == l &&
            t->m == mm) {
            *index = i;
            return PM_OK;
        }
    }
    return PM_ERR_ARG;
}

pm_status pm_term_name(const pm_model *m, int index, char *buf, size_t len)
{
    if (!m || !buf || len < 2 || index < 0 || index >= m->n_terms ||
        index >= PM_MAX_TERMS)
        return PM_ERR_ARG;
    /* the term as pm_model_prepare would accept it (a prepared model's term
    ** changed since, or one of a model never prepared, may hold anything:
    ** G = 1e300 has no long) */
    if (m->order < 0 || m->order > PM_MAX_L || m->n_base < 6 || m->n_base > m->n_terms ||
        !term_ok(m, index))
        return PM_ERR_ARG;
    const pm_term *t = &m->term[index];
    char tmp[48];
    size_t n = 0;
    if (t->kind == PM_TERM_ZENITH) {
        const char *z = t->l == 0 ? "cot(el)" : "cos(el)";
        while (*z)
            tmp[n++] = *z++;
    } else switch (t->k) {
    case 1: tmp[n++] = 'a'; break;
    case 2: tmp[n++] = 'b'; break;
    case 3: tmp[n++] = 'c'; tmp[n++] = '\''; break;
    case 4: tmp[n++] = 'd'; break;
    case 5: tmp[n++] = 'e'; tmp[n++] = '\''; break;
    default: tmp[n++] = 'i'; break;
    }
    if (t->kind == PM_TERM_FOURIER || t->kind == PM_TERM_SECTORAL) {
        const char *s = t->kind == PM_TERM_FOURIER ? (t->m ? "*sin(" : "*cos(")
                                                   : (t->m ? "*Ysin(" : "*Ycos(");
        while (*s)
            tmp[n++] = *s++;
        /* G with up to 3 decimals, no printf in the core (G within
        ** 0..1e6, term_ok) */
        double g = t->param;
        long ip = (long)g;
        long fr = (long)((g - (double)ip) * 1000.0 + 0.5);
        if (fr >= 1000) {
            ip++;
            fr -= 1000;
        }
        n += format_long(ip, tmp + n);
        if (fr > 0) {
            tmp[n++] = '.';
            tmp[n++] = (char)('0' + fr / 100);
            if (fr % 100) {
                tmp[n++] = (char)('0' + fr / 10 % 10);
                if (fr % 10)
                    tmp[n++] = (char)('0' + fr % 10);
            }
        }
        if (t->kind == PM_TERM_FOURIER) {
            const char *ax = t->l == 1 ? "*ha" : "*dec";
            while (*ax)
                tmp[n++] = *ax++;
        }
        tmp[n++] = ')';
    } else if (t->kind == PM_TERM_AUX) {
        const char *s = t->aux == PM_AUX_TEMP ? "*temp"
                        : t->aux == PM_AUX_TIME ? "*time"
                        : t->aux == PM_AUX_DIR ? "*dir" : "*aux";
        while (*s)
            tmp[n++] = *s++;
        if (t->aux >= PM_AUX_USER)
            n += format_long(t->aux - PM_AUX_USER, tmp + n);
    } else if (t->kind == PM_TERM_SH && t->l > 0) {
        const char *s = "*Y(";
        while (*s)
            tmp[n++] = *s++;
        n += format_long(t->l, tmp + n);
        tmp[n++] = ',';
        n += format_long(t->m, tmp + n);
        tmp[n++] = ')';
    }
    if (t->side) {
        tmp[n++] = '@';
        tmp[n++] = t->side > 0 ? 'E' : 'W';
    }
    size_t i;
    for (i = 0; i < n && i + 1 < len; i++)
        buf[i] = tmp[i];
    buf[i] = '\0';
    return PM_OK;
}

PM_NO_SLP pm_status pm_model_apply(const pm_model *m, const pm_context *ctx,
                         double enc_ha, double enc_dec, double *app_ha,
                         double *app_dec)
{
#if PM_COMPOSED_FORWARD
    /* eval_ready's checks and the arguments', the same statuses in the same
    ** order, but the comparison of the coefficients with pm_model_prepare's
    ** copy inside the evaluation (forward_framed's stale), unless an
    ** argument is refused */
    pm_status st = model_shape(m);
    if (st != PM_OK)
        return st;
    st = context_ok(m, ctx);
    if (st == PM_OK && (!app_ha || !app_dec))
        st = PM_ERR_ARG;
    if (st == PM_OK && (!finite(enc_ha) || !finite(enc_dec)))
        st = PM_ERR_NONFINITE;
    if (st != PM_OK)
        return coef_changed(m) ? PM_ERR_STATE : st;
#else
    pm_status st = eval_ready(m, ctx);
    if (st != PM_OK)
        return st;
    if (!app_ha || !app_dec)
        return PM_ERR_ARG;
    if (!finite(enc_ha) || !finite(enc_dec))
        return PM_ERR_NONFINITE;
#endif
    const Iso<double> &k = iso_of(m);
    double sh[4], t, d;
#if PM_COMPOSED_FORWARD
    const Trig<double> g = trig_of(enc_ha, enc_dec);
    /* the comparison after the sines and cosines in the code (the barrier
    ** keeps the compiler from hoisting it to the top): the evaluation is
    ** safe to run once model_shape passed, and its ~150 instructions (L =
    ** 2) then enter the core while the sines and cosines are computed, not
    ** before them, where they took the place of the next call's start in
    ** the core's window */
    const pm_model *mc = m;
#if defined(__GNUC__)
    __asm__ volatile("" : "+r"(mc) : "m"(g));
#endif
    if (coef_changed(mc))
        return PM_ERR_STATE;
    const V3<double> pf = forward_framed<double>(m, k, g, ctx, sh);
#else
    const V3<double> p0 = forward_vec<double>(m, k, trig_of(enc_ha, enc_dec), ctx, sh);
    const V3<double> pf = rot_zt<double>(sh[0], sh[1], p0);
#endif
    if (!frame_angles(m, enc_ha, enc_dec, sh, pf, &t, &d)) {
#if PM_COMPOSED_FORWARD
        const V3<double> p = rot_z<double>(sh[0], sh[1], pf);
#else
        const V3<double> &p = p0;
#endif
        t = m_atan2(p.y, p.x);
        d = m_atan2(p.z, m_sqrt(p.x * p.x + p.y * p.y));
    }
    if (!finite(t) || !finite(d))
        return PM_ERR_NONFINITE; /* overflow in the terms: outputs untouched */
    *app_ha = t <= -PI ? PI : t; /* atan2(-0, -1) = -pi */
    *app_dec = d;
    return PM_OK;
}

pm_status pm_model_invert(const pm_model *m, const pm_context *ctx,
                          double app_ha, double app_dec, int side,
                          double *enc_ha, double *enc_dec)
{
    if (side != PM_SIDE_NORMAL && side != PM_SIDE_FLIPPED)
        return PM_ERR_ARG;
    return invert<false>(m, ctx, app_ha, app_dec, side == PM_SIDE_NORMAL ? 1 : -1, 0, 0,
                  enc_ha, enc_dec);
}

pm_status pm_model_invert_near(const pm_model *m, const pm_context *ctx,
                               double app_ha, double app_dec, double start_ha,
                               double start_dec, double *enc_ha,
                               double *enc_dec)
{
    double start[2] = {start_ha, start_dec};
    return invert<false>(m, ctx, app_ha, app_dec, 1, start, 0, enc_ha, enc_dec);
}

pm_status pm_track_start(pm_track *t, double enc_ha, double enc_dec)
{
    return start_state(t, enc_ha, enc_dec, PM_TRACK_MAGIC);
}

/* The sines and cosines of a + b (each axis) from a's and b's. */
static inline void trig_sum(const double a[4], const double b[4], double out[4])
{
    out[0] = a[0] * b[1] + a[1] * b[0];
    out[1] = a[1] * b[1] - a[0] * b[0];
    out[2] = a[2] * b[3] + a[3] * b[2];
    out[3] = a[3] * b[3] - a[2] * b[2];
}

/* The start of pm_model_track's call (Note 1 of pm_model_track): the
** state's position moved on by its last step where it has one, as angles
** (start) and as sines and cosines (trig, by the angle-sum formulas);
** where that would take it to the other side of the mount's pole, the
** position itself.  (Moving it on by the step's change too, a quadratic
** prediction, was tried: the positions it starts from are right only to
** PM_INVERT_TOL, so at 1 ms and 0.1 s ticks its error stays ~1e-13 rad,
** as the linear one's, and it costs ~70 instructions a call; only with
** ticks of 0.1 s and longer on models with 10' terms did it save
** evaluations: 1.05 a tick against 1.12 at 0.1 s, 1.07 against 1.37 at
** 1 s in tests/check_track.c.) */
static void track_start(const pm_model *m, const pm_track *t, double start[2], double trig[4])
{
    const double *p = t->trig, *qt = t->step_trig;
    start[0] = t->enc[0];
    start[1] = t->enc[1];
    for (int i = 0; i < 4; i++)
        trig[i] = p[i];
    if (!(t->flags & PM_TRACK_HAVE_STEP))
        return;
    double nt[4];
    trig_sum(p, qt, nt);
    /* Back onto the unit circle (one Newton step of 1/sqrt from 1: the
    ** error left is 3/8 of its square): the products' lengths multiply,
    ** and a start that is the solution already is returned as it is, its
    ** sines and cosines those of the next tick's position -- unchecked,
    ** their lengths would drift from 1 tick by tick (1.9e-12 after 3,000
    ** ticks in tests/check_track.c, test_track_long) and the measured
    ** stop at such a point miss by as much. */
    for (int i = 0; i < 4; i += 2) {
        const double n = 1.5 - 0.5 * (nt[i] * nt[i] + nt[i + 1] * nt[i + 1]);
        nt[i] *= n;
        nt[i + 1] *= n;
    }
    if ((nt[3] * m->ce + nt[2] * m->se >= 0) != (p[3] * m->ce + p[2] * m->se >= 0))
        return;
    start[0] = t->enc[0] + t->step[0];
    start[1] = t->enc[1] + t->step[1];
    for (int i = 0; i < 4; i++)
        trig[i] = nt[i];
}

/* The step from the state's position to the new one (eh, ed; sines and
** cosines r): kept where both axes moved by less than 0.01 rad. */
static int track_step(pm_track *t, double eh, double ed, const double r[4])
{
    const double *p = t->trig;
    double *h = t->step_trig;
    h[0] = r[0] * p[1] - r[1] * p[0];
    h[1] = r[1] * p[1] + r[0] * p[0];
    h[2] = r[2] * p[3] - r[3] * p[2];
    h[3] = r[3] * p[3] + r[2] * p[2];
    t->step[0] = eh - t->enc[0];
    t->step[1] = ed - t->enc[1];
    return m_fabs(h[0]) <= 0.01 && h[1] > 0 && m_fabs(h[2]) <= 0.01 && h[3] > 0 &&
           m_fabs(t->step[0]) <= 0.01 && m_fabs(t->step[1]) <= 0.01;
}

pm_status pm_model_track(const pm_model *m, const pm_context *ctx, pm_track *t,
                         double app_ha, double app_dec, double *enc_ha, double *enc_dec)
{
    if (!t || t->magic != PM_TRACK_MAGIC || !enc_ha || !enc_dec)
        return PM_ERR_ARG;
    pm_status st = eval_ready(m, ctx); /* (before the digest reads them) */
    if (st != PM_OK)
        return st;
    const Digest in = inputs_digest(m, ctx);
    Carry c;
    c.t = t;
    c.have_j = (t->flags & PM_TRACK_HAVE_J) && !(t->flags & PM_TRACK_REFRESH) &&
               t->ident[0] == m->ident[0] && t->ident[1] == m->ident[1] &&
               t->inputs[0] == in.a && t->inputs[1] == in.b;
    c.have_ni = c.have_j && (t->flags & PM_TRACK_HAVE_NI);
    double start[2], strig[4];
    if (t->flags & PM_TRACK_HAVE_TRIG) {
        track_start(m, t, start, strig);
        c.strig = strig;
    } else {
        start[0] = t->enc[0];
        start[1] = t->enc[1];
        c.strig = 0;
    }
    c.fresh = c.out_ni = c.out_trig = false;
    c.rtrig[0] = c.rtrig[1] = c.rtrig[2] = c.rtrig[3] = 0; /* (written where out_trig) */
    c.used = 0;
    double eh = 0, ed = 0;
    st = invert<true>(m, ctx, app_ha, app_dec, 1, start, &c, &eh, &ed);
    if (st < 0 && !c.fresh)
        return st; /* (the state as it was) */
    int f = t->flags & ~PM_TRACK_REFRESH;
    if (c.fresh) { /* J is right wherever it was taken: kept whatever st */
        f = (f & ~PM_TRACK_HAVE_NI) | PM_TRACK_HAVE_J | (c.out_ni ? PM_TRACK_HAVE_NI : 0);
        t->ident[0] = m->ident[0];
        t->ident[1] = m->ident[1];
        t->inputs[0] = in.a;
        t->inputs[1] = in.b;
    } else if (c.used >= 2 && st == PM_OK) {
        /* J carried so far that its distance kept the predicted stop from
        ** certifying a step that a J taken at the start would have (ticks
        ** of 1 kHz, J carried for many): take it afresh next time */
        const double ht = eh - start[0], hd = ed - start[1];
        if (m->lip2 * 0.5 * (ht * ht + hd * hd) <= 0.25 * PM_INVERT_TOL)
            f |= PM_TRACK_REFRESH;
    }
    if (st == PM_OK) {
        f &= ~(PM_TRACK_HAVE_TRIG | PM_TRACK_HAVE_STEP);
        if (c.out_trig) {
            if ((t->flags & PM_TRACK_HAVE_TRIG) && track_step(t, eh, ed, c.rtrig))
                f |= PM_TRACK_HAVE_STEP;
            f |= PM_TRACK_HAVE_TRIG;
            for (int i = 0; i < 4; i++)
                t->trig[i] = c.rtrig[i];
        }
        t->enc[0] = eh;
        t->enc[1] = ed;
    }
    t->flags = f;
    if (st < 0)
        return st;
    *enc_ha = eh;
    *enc_dec = ed;
    return st;
}

pm_status pm_model_residual(const pm_model *m, const pm_context *ctx,
                            double enc_ha, double enc_dec, double app_ha,
                            double app_dec, double res[2])
{
    pm_status st = eval_ready(m, ctx);
    if (st != PM_OK)
        return st;
    if (!res)
        return PM_ERR_ARG;
    if (!finite(enc_ha) || !finite(enc_dec) || !finite(app_ha) ||
        !finite(app_dec))
        return PM_ERR_NONFINITE;
    if (m_fabs(app_dec) > PI / 2 + 1e-9) /* (as pm_fit_add: no place on the sky) */
        return PM_ERR_ARG;
    const Iso<double> &k = iso_of(m);
    V3<double> p = forward_vec<double>(m, k, trig_of(enc_ha, enc_dec), ctx);
    V3<double> q = unit_of(app_ha, app_dec);
    /* sky frame at the model position */
    double rho = m_sqrt(p.x * p.x + p.y * p.y);
    V3<double> e1, e2;
    if (rho > 1e-15) {
        e1 = v3(-p.y / rho, p.x / rho, 0.0);
        e2 = v3(-p.z * p.x / rho, -p.z * p.y / rho, rho);
    } else {
        e1 = v3(0.0, 1.0, 0.0);
        e2 = v3(-1.0, 0.0, 0.0);
    }
    /* log map at p: angle times direction */
    double a = dot(q, e1), b = dot(q, e2);
    double s = m_sqrt(a * a + b * b);
    double f = s > 0 ? m_atan2(s, dot(p, q)) / s : 1.0;
    if (!finite(a * f) || !finite(b * f))
        return PM_ERR_NONFINITE; /* overflow in the terms: res untouched */
    res[0] = a * f;
    res[1] = b * f;
    return PM_OK;
}

pm_status pm_terms_eval(int order, double ha, double dec, double *out)
{
    if (!out)
        return PM_ERR_ARG;
    if (order < 0 || order > PM_MAX_L)
        return PM_ERR_CAPACITY;
    if (!finite(ha) || !finite(dec))
        return PM_ERR_NONFINITE;
    Trig<double> g = trig_of(ha, dec);
    double Y[PM_N_HARM(PM_MAX_L)];
    harmonics<double>(order, g, Y);
    V3<double> et = v3(-g.st, g.ct, 0.0);
    V3<double> ed = v3(-g.sd * g.ct, -g.sd * g.st, g.cd);
    for (int l = 0; l <= order; l++)
        for (int mm = -l; mm <= l; mm++) {
            int j = l * l + l + mm;
            double y = Y[j] * norm_lm(l, mm);
            for (int k = 1; k <= 6; k++) {
                double u, v;
                base_uv<double>(k, g, &u, &v);
                double *o = out + 3 * (6 * j + k - 1);
                o[0] = y * (u * et.x + v * ed.x);
                o[1] = y * (u * et.y + v * ed.y);
                o[2] = y * (u * et.z + v * ed.z);
            }
        }
    return PM_OK;
}

pm_status pm_check_config(size_t model_size, size_t fit_size, int max_l,
                          int max_extra)
{
    if (model_size != sizeof(pm_model) || fit_size != sizeof(pm_fit) ||
        max_l != PM_MAX_L || max_extra != PM_MAX_EXTRA)
        return PM_ERR_CONFIG;
    return PM_OK;
}

const char *pm_status_text(pm_status s)
{
    switch (s) {
    case PM_OK: return "ok";
    case PM_WARN_NOT_CONVERGED: return "iteration bound reached";
    case PM_WARN_UNREACHABLE: return "target unreachable";
    case PM_ERR_ARG: return "invalid argument";
    case PM_ERR_NONFINITE: return "non-finite input, or an evaluation overflowed";
    case PM_ERR_CAPACITY: return "beyond the compiled capacity";
    case PM_ERR_TOO_FEW: return "too few observations for the number of terms";
    case PM_ERR_SINGULAR: return "a term cannot be determined from these observations";
    case PM_ERR_STATE: return "call out of order (model not prepared, or changed since)";
    case PM_ERR_CONFIG: return "library built with other capacities";
    case PM_ERR_DIVERGED: return "the fit did not converge";
    }
    return "unknown status";
}

pm_status pm_check_config_all(size_t model_size, size_t fit_size, size_t context_size,
                              int max_l, int max_extra, int max_aux)
{
    if (pm_check_config(model_size, fit_size, max_l, max_extra) != PM_OK ||
        context_size != sizeof(pm_context) || max_aux != PM_MAX_AUX)
        return PM_ERR_CONFIG;
    return PM_OK;
}

} /* extern "C" */
