/*
**  model_f.cpp - the pointing model evaluated in single precision, for
**  FPUs without double precision (Cortex-M4F).
**
**  A float holds an absolute angle only to ~6e-8 rad (0.012"), so the float
**  build never forms absolute directions.  The index terms c' and e' (the
**  only large ones: degrees on real mounts) are exact shifts of the frame
**  angles, done in double; everything else is a small correction computed
**  in the frame local to the shifted position, as an offset from (1,0,0),
**  where float's relative precision is enough; the result is the frame angle
**  plus the correction, added in double.  The harmonics, base vectors and
**  added terms are the same templates as the double build.
**
**  Reference: Pal et al., Exp Astron (2016), Secs. 2-3; docs/model.md.
*/
#include "pm.h"
#include "pm_detail.hpp"

using namespace pm::detail;

namespace {

/* The added terms' view of a position, in float (cf. site_of). */
Site<float> site_f(const pm_model_f *m, const Trig<float> &ge, int side,
                   float ia, float ib, float ic) /* omega' = (ia, ib, ic) */
{
    Site<float> s;
    s.gs = ge;
    s.side = side;
    s.have_zenith = false;
    s.zx = s.zy = s.zz = 0;
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_ZENITH) {
            /* Z in the frame of the shifted position, then through H_loc^T,
            ** X_loc^T, T(i)^T (directions only: float is enough) */
            V3<float> z = m->mount == PM_MOUNT_ALTAZ ? v3<float>(0, 0, 1)
                                                      : v3<float>(m->lat_c, 0, m->lat_s);
            z = rot_dt<float>(ge.sd, ge.cd, rot_zt<float>(ge.st, ge.ct, z));
            V3<float> w = v3<float>(ia, ib, ic);
            V3<float> wz = cross<float>(w, z);
            V3<float> wwz = cross<float>(w, wz);
            z = v3<float>(z.x - m->ra * wz.x + m->rb * wwz.x, z.y - m->ra * wz.y + m->rb * wwz.y,
                          z.z - m->ra * wz.z + m->rb * wwz.z);
            V3<float> n = v3<float>(ge.cd, 0, -ge.sd);
            V3<float> nz = cross<float>(n, z);
            V3<float> nnz = cross<float>(n, nz);
            z = v3<float>(z.x - m->sd * nz.x + m->vd * nnz.x, z.y - m->sd * nz.y + m->vd * nnz.y,
                          z.z - m->sd * nz.z + m->vd * nnz.z);
            z = rot_zt<float>(m->si, 1 - m->vi, z);
            s.zx = z.x;
            s.zy = z.y;
            s.zz = z.z;
            s.have_zenith = true;
            break;
        }
    return s;
}

/* v + s1 (n x v) + s2 (n x (n x v)) for v = (1,0,0) + o, returned as the new
** offset from (1,0,0): a rotation written as identity plus a small part. */
V3<float> rotate_offset(const V3<float> &n, float s1, float s2, const V3<float> &o)
{
    V3<float> v = v3<float>(1 + o.x, o.y, o.z); /* rounding of 1 + o.x only
                                                    enters the cross products */
    V3<float> nv = cross<float>(n, v);
    V3<float> nnv = cross<float>(n, nv);
    return v3<float>(o.x + s1 * nv.x + s2 * nnv.x, o.y + s1 * nv.y + s2 * nnv.y,
                     o.z + s1 * nv.z + s2 * nnv.z);
}

/* An encoder position as the float correction sees it: the trig of its
** frame position (t_r, d_r) (|d_r| <= pi/2: beyond the pole the equivalent
** position (t_c + pi, pi - d_e)), of the shifted position (t_c, d_e) and of
** the encoder position itself, with its float angles for the terms that
** read them (periodic terms). */
struct FrameF {
    bool flip;        /* beyond the pole */
    float sd, cd;     /* sin, cos of d_r (cd >= 0) */
    Trig<float> ge;   /* shifted position */
    Trig<float> g;    /* encoder position */
};

/* Fill f.ge and f.g from the frame trig (st, ct of t_r; f.sd, f.cd) and the
** encoder angles (t, d). */
void frame_finish(const pm_model_f *m, float st, float ct, float t, float d, FrameF *f)
{
    f->ge.st = f->flip ? -st : st;
    f->ge.ct = f->flip ? -ct : ct;
    f->ge.sd = f->sd;
    f->ge.cd = f->flip ? -f->cd : f->cd;
    f->ge.have_angles = false;
    /* the encoder position's trig: only the added terms' periodic and
    ** sectoral factors read it (the harmonics and base vectors are at ge) */
    if (m->n_terms > m->n_base) {
        f->g.st = f->ge.st * m->cc - f->ge.ct * m->sc;
        f->g.ct = f->ge.ct * m->cc + f->ge.st * m->sc;
        f->g.sd = f->ge.sd * m->ce + f->ge.cd * m->se;
        f->g.cd = f->ge.cd * m->ce - f->ge.sd * m->se;
    } else {
        f->g.st = f->g.ct = f->g.sd = f->g.cd = 0;
    }
    f->g.t = t;
    f->g.d = d;
    f->g.have_angles = true;
}

/* atan2(y, x), by its series where the angle is small (|y| <= 0.01 x: the
** terms left out are below 2e-15 rad), else by libm. */
inline float atan2_small(float y, float x)
{
    if (x > 0 && m_fabs(y) <= 0.01f * x) {
        float r = y / x, r2 = r * r;
        return r * (1 - r2 * (1.0f / 3 - r2 * 0.2f));
    }
    return m_atan2(y, x);
}

/* The correction at a frame: the apparent position is (t_r + dT, d_r + dD).
** One model evaluation (everything of the forward model but the frame
** angles). */
void correction_f(const pm_model_f *m, const pm_context *ctx, const FrameF &f, float *dTo,
                  float *dDo)
{
    PM_EVAL_PROBE();
    const Trig<float> &ge = f.ge, &g = f.g;
    const float cd = f.cd, sd = f.sd;
    /* the polar-axis rotation in the local frame: omega' = Q^T (a, b, 0) */
    V3<float> om = rot_dt<float>(ge.sd, ge.cd, rot_zt<float>(ge.st, ge.ct, v3<float>(m->a, m->b, 0)));

    /* anisotropic displacement (same templates as the double build): the
    ** harmonics and base vectors at the shifted position ge */
    float S[6];
    sh_sums<float, float>(m->order, ge, m->dense, S);
    float dt = -ge.sd * (S[0] * ge.ct + S[1] * ge.st) - ge.sd * S[3] + ge.cd * S[2] + S[5];
    float dd = S[0] * ge.st - S[1] * ge.ct - S[4];
    if (m->n_terms > m->n_base) {
        int side = ctx && ctx->pier ? (ctx->pier > 0 ? 1 : -1) : (f.flip ? -1 : 1);
        Site<float> s = site_f(m, ge, side, om.x, om.y, om.z);
        for (int i = m->n_base; i < m->n_terms; i++) {
            float u, v;
            term_uv<float>(m->term[i], g, s, ctx, &u, &v);
            dt += m->coef[i] * u;
            dd += m->coef[i] * v;
        }
    }

    /* w = expmap(dt, dd) as an offset from (1,0,0) */
    float r2 = dt * dt + dd * dd;
    float sinc = 1 - r2 * (1.0f / 6 - r2 * (1.0f / 120));
    V3<float> o = v3<float>(-r2 * (0.5f - r2 * (1.0f / 24)), dt * sinc, dd * sinc);
    if (r2 >= 1e-4f) {
        float r = m_sqrt(r2);
        o = v3<float>(-2 * m_sin(r / 2) * m_sin(r / 2), dt * m_sin(r) / r, dd * m_sin(r) / r);
    }
    /* T(i): (1 + ox, oy, oz) -> offset */
    float ci = 1 - m->vi;
    o = v3<float>(o.x * ci - o.y * m->si - m->vi, o.x * m->si + o.y * ci + m->si, o.z);
    /* X(d) about n = Pd(d_e)^T x = (cos d_e, 0, -sin d_e) */
    o = rotate_offset(v3<float>(ge.cd, 0, -ge.sd), m->sd, m->vd, o);
    /* H about omega' (Rodrigues with the prepared factors, unit scaling in
    ** the factors: ra = sin(th)/th, rb = (1 - cos th)/th^2) */
    o = rotate_offset(om, m->ra, m->rb, o);
    /* beyond the pole the frame of (t_r, d_r) is (x, -y, -z) */
    if (f.flip) {
        o.y = -o.y;
        o.z = -o.z;
    }
    /* angles of (1 + ox, oy, oz) in the frame at (t_r, d_r), written so that
    ** only small quantities are differenced */
    float eta = cd * o.x - sd * o.z; /* q = cd + eta */
    float zeta = sd * o.x + cd * o.z;
    float q = cd + eta;
    float rho = m_sqrt(o.y * o.y + q * q);
    float rmc = rho + cd > 0 ? (2 * cd * eta + eta * eta + o.y * o.y) / (rho + cd) : rho - cd;
    *dTo = atan2_small(o.y, q);
    *dDo = atan2_small(zeta * cd - rmc * sd, rho * cd + (sd + zeta) * sd);
}

/* sin and cos of a float angle |x| <= 3.2 (frame angles: within pi), without
** libm: the nearest multiple k pi/2 taken off in two parts (k pi/2 as a float
** is exact for |k| <= 2, and x - k pi/2 then too, by Sterbenz's lemma), the
** Taylor series to r^9 and r^10 on |r| <= pi/4 (truncation below 3e-9
** relative), the quadrant's swap: within 1.5 ulp of 1 of the exact values
** (libm: 0.5 ulp).  Beyond 3.2 (k = 3 and more), libm. */
inline void sincos_f(float x, float *s, float *c)
{
    if (!(m_fabs(x) <= 3.2f)) {
        *s = m_sin(x);
        *c = m_cos(x);
        return;
    }
    const float P1 = 1.57079625129699707031f, P2 = 7.54978995489188216e-08f;
    int k = (int)(x * 0.636619772f + (x >= 0 ? 0.5f : -0.5f));
    float r = (x - (float)k * P1) - (float)k * P2, r2 = r * r;
    float sr = r + r * r2 * (-1.0f / 6 + r2 * (1.0f / 120 + r2 * (-1.0f / 5040 + r2 * (1.0f / 362880))));
    float cr = 1 - 0.5f * r2 +
               r2 * r2 * (1.0f / 24 + r2 * (-1.0f / 720 + r2 * (1.0f / 40320 - r2 * (1.0f / 3628800))));
    switch (k & 3) {
    case 0: *s = sr; *c = cr; break;
    case 1: *s = cr; *c = -sr; break;
    case 2: *s = -sr; *c = -cr; break;
    default: *s = -cr; *c = sr; break;
    }
}

/* sin and cos of a declination-like angle |x| <= pi/2.  Beyond 1 rad the
** cosine comes from the complement pi/2 - |x| formed in double: near the
** pole cos((float)x) would carry the angle's own rounding (up to 6e-8 rad,
** a relative error of 6e-8 tan x in the cosine), which the HA correction
** (~ offset / cos d) magnifies; within 1 rad that is below 1e-7. */
inline void dec_trig_f(double x, float *s, float *c)
{
    if (!abs_beyond(x, 1.0)) {
        sincos_f((float)x, s, c);
        return;
    }
    float cu = (float)(PI / 2 - m_fabs(x));
    float sc;
    sincos_f(cu, c, &sc);
    *s = below0(x) ? -sc : sc;
}

/* Forward model: encoder (t, d) -> apparent (T, D) = (wrap_pi(t_r + dT),
** d_r + dD), in float except for the frame angles (t_r, d_r), returned
** apart with the correction (dT, dD). */
void forward_parts_f(const pm_model_f *m, const pm_context *ctx, double t, double d,
                     double *tr_out, double *dr_out, float *dT, float *dD)
{
    /* frame angles: exact index shifts; beyond the pole, the equivalent
    ** position (t_r, d_r) = (t_c + pi, pi - d_e) with |d_r| <= pi/2 */
    double tc = t + m->c, de = wrap_pi(d - m->e);
    FrameF f;
    f.flip = abs_beyond(de, PI / 2);
    double tr = f.flip ? tc + PI : tc;
    double dr = f.flip ? (above0(de) ? PI - de : -PI - de) : de;
    float st, ct;
    sincos_f((float)wrap_pi(tr), &st, &ct);
    dec_trig_f(dr, &f.sd, &f.cd);
    frame_finish(m, st, ct, (float)t, (float)d, &f);
    correction_f(m, ctx, f, dT, dD);
    *tr_out = tr;
    *dr_out = dr;
}

/* Forward model: encoder (t, d) -> apparent (T, D). */
void forward_f(const pm_model_f *m, const pm_context *ctx, double t, double d, double *T,
               double *D)
{
    double tr, dr;
    float dT, dD;
    forward_parts_f(m, ctx, t, d, &tr, &dr, &dT, &dD);
    /* the frame angle reduced first: t + c' can be far beyond pi (a huge
    ** index term), where adding the correction would round at its ulp
    ** (fuzz finding: c' = 7.8e7 rad, 7.5e-9 rad) */
    *T = wrap_pi(wrap_pi(tr) + (double)dT);
    *D = dr + (double)dD;
}

/* Offset of apparent (T1, D1) from (T2, D2), in the frame at (T2, D2):
** the tangent components (x, y) of the direction (T1, D1) and, returned,
** a size that grows with the angle between them: |(x, y)| = sin(angle)
** in the near hemisphere, 2 - sin(angle) in the far one (the tangent
** components alone vanish at the antipode too).  The cosines of the
** declinations by dec_trig_f: near a celestial pole cos((float)D) would
** carry the angle's own rounding (6e-8 rad, a quarter of the cosine
** 2.5e-7 rad from the pole) into the HA part of the offset (fuzz finding:
** a 1.29e-8 rad miss judged within 1e-8). */
float sky_offset(double T1, double D1, double T2, double D2, float *x, float *y)
{
    float dT = (float)wrap_pi(T1 - T2), dD = (float)(D1 - D2);
    float s1, c1, s2, c2;
    dec_trig_f(D1, &s1, &c1);
    dec_trig_f(D2, &s2, &c2);
    float h = m_sin(dT / 2);
    *x = c1 * m_sin(dT);
    *y = m_sin(dD) + c1 * s2 * 2 * h * h;
    /* cos(angle) = cos(dD) - 2 cos(D1) cos(D2) sin^2(dT/2) */
    float z = m_cos(dD) - 2 * c1 * c2 * h * h;
    float n = m_sqrt(*x * *x + *y * *y);
    return z >= 0 ? n : 2 - n;
}

pm_status check_f(const pm_model_f *m, const pm_context *ctx)
{
    if (!m)
        return PM_ERR_ARG;
    if (m->prepared != 1 || m->n_terms < 6 || m->n_terms > PM_MAX_TERMS)
        return PM_ERR_STATE;
    return context_ok(m, ctx);
}

/* Does an evaluation read the float angles g.t, g.d, not only their trig
** (periodic and sectoral terms)? */
bool reads_angles_f(const pm_model_f *m)
{
    for (int i = m->n_base; i < m->n_terms; i++)
        if (m->term[i].kind == PM_TERM_FOURIER || m->term[i].kind == PM_TERM_SECTORAL)
            return true;
    return false;
}

/* sin and cos of a float angle, by series where it is small (the fixed
** point's corrections: arcminutes), else by libm. */
inline void sincos_small(float x, float *s, float *c)
{
    float x2 = x * x;
    if (x2 < 1e-4f) { /* |x| < 0.01: the next terms are below 1e-12 */
        *s = x * (1 - x2 / 6 * (1 - x2 / 20));
        *c = 1 - x2 / 2 * (1 - x2 / 12);
    } else {
        *s = m_sin(x);
        *c = m_cos(x);
    }
}

/* Encoder angles of the frame position (T0 - dT, D - dD) on the side given
** by flip (the forward model's frame, undone), on the turn of ref. */
void encoder_of(const pm_model_f *m, double T0, double D, float dT, float dD, bool flip,
                const double ref[2], double *t, double *d)
{
    double tr = T0 - (double)dT, dr = D - (double)dD;
    double tt = (flip ? tr - PI : tr) - m->c;
    double dd = (flip ? (above0(dr) ? PI - dr : -PI - dr) : dr) + m->e;
    finish_angles(ref, &tt, &dd);
    *t = tt;
    *d = dd;
}

/* The fixed point's check: the encoder position of the frame position
** (T0 - dT, D - dD) evaluated with the forward model itself; true where
** it points within PM_INVERT_F_TOL of the target (T0, D), the position in
** (t_out, d_out) and the correction the forward model found there in
** corr (where given: the next tick's start, pm_model_track_f). */
__attribute__((always_inline)) inline bool
point_ok_f(const pm_model_f *m, const pm_context *ctx, double T0, double D, float sD, float cD,
           float dT, float dD, bool flip, const double ref[2], float *corr, double *t_out,
           double *d_out)
{
    const float tol = (float)PM_INVERT_F_TOL;
    double t, d, tr, dr;
    float kT, kD; /* the correction there */
    encoder_of(m, T0, D, dT, dD, flip, ref, &t, &d);
    forward_parts_f(m, ctx, t, d, &tr, &dr, &kT, &kD);
    /* The forward model gives (T1, D1) = (t_r + kT, d_r + kD), to the
    ** rounding of those sums (1e-16), so its offset from the target is
    ** (eT, eD) below.  The separation (haversine):
    ** chord^2 = (2 sin(eD/2))^2 + cos D1 cos D (2 sin(eT/2))^2
    **         <= eD^2 + cos D1 cos D eT^2,
    ** with cos D1 <= cos D - sin D eD + eD^2 (|eD| < 1); the angle exceeds
    ** the chord by a part in chord^2 / 24, and the float sums by a few
    ** parts in 1e7: 1% of tol^2 covers both. */
    float eT = (float)wrap_pi(wrap_pi(tr) - T0) + kT, eD = (float)(dr - D) + kD;
    float cD1 = cD - sD * eD + eD * eD;
    float cc = cD1 > 0 ? cD1 * cD : 0.0f;
    if (!(m_fabs(eD) < 1 && eD * eD + cc * eT * eT <= 0.99f * tol * tol))
        return false;
    *t_out = t;
    *d_out = d;
    if (corr) {
        corr[0] = kT;
        corr[1] = kD;
    }
    return true;
}

/* The fixed point of the float inverse: the frame position is the target
** minus the correction there, x_{n+1} = target - C(x_n), iterated from
** the target itself.  The frame trig comes from the target's, turned by
** the correction (no libm call per step while it is below 0.01 rad), so a
** step costs one correction.  x_{n+1} misses by about the contraction
** times the last change |C(x_n) - C(x_{n-1})|; it stops when that
** prediction (or the change itself) is well below PM_INVERT_F_TOL.
** PM_WARN_NOT_CONVERGED where it does not contract (close to the mount's
** pole, or beyond its edge): the Newton iteration then takes over. */
pm_status fixed_f(const pm_model_f *m, const pm_context *ctx, double T, double D, bool flip,
                  const double ref[2], const float *warm, float *corr, double *t_out,
                  double *d_out)
{
    const double T0 = wrap_pi(T);
    float sD, cD;
    dec_trig_f(D, &sD, &cD);
    /* (from the correction of the tick before where pm_model_track_f has
    ** one: it then changes by far less than the tolerance per step) */
    float dT = warm ? warm[0] : 0.0f, dD = warm ? warm[1] : 0.0f, last = 0;
    /* A tracking loop's start (pm_model_track_f) is the correction of the
    ** ticks before, moved on by its last change: checked as it is first,
    ** one evaluation where it is within the tolerance already */
    if (warm && m_fabs(dT) <= 0.01f && m_fabs(dD) <= 0.01f &&
        point_ok_f(m, ctx, T0, D, sD, cD, dT, dD, flip, ref, corr, t_out, d_out))
        return PM_OK;
    float sT, cT;
    sincos_f((float)T0, &sT, &cT);
    const bool raw = reads_angles_f(m);
    const float tol = (float)PM_INVERT_F_TOL;
    for (int it = 0; it < PM_INVERT_F_FIXED; it++) {
        float s1, c1, s2, c2;
        sincos_small(dT, &s1, &c1);
        sincos_small(dD, &s2, &c2);
        FrameF f;
        f.flip = flip;
        f.sd = sD * c2 - cD * s2; /* sin(D - dD) */
        f.cd = cD * c2 + sD * s2;
        if (!(f.cd > 0))
            return PM_WARN_NOT_CONVERGED; /* past the pole's edge */
        float ft = 0, fd = 0;
        if (raw) { /* the angles as forward_f would see them */
            double t, d;
            encoder_of(m, T0, D, dT, dD, flip, ref, &t, &d);
            ft = (float)t;
            fd = (float)d;
        }
        frame_finish(m, sT * c1 - cT * s1, cT * c1 + sT * s1, ft, fd, &f);
        float nT, nD;
        correction_f(m, ctx, f, &nT, &nD);
        float ex = (nT - dT) * f.cd, ey = nD - dD; /* on the sky */
        float change = m_sqrt(ex * ex + ey * ey);
        dT = nT;
        dD = nD;
        if (!finite(change) || (it > 0 && change > 0.5f * last))
            return PM_WARN_NOT_CONVERGED;
        /* corrections beyond 0.01 rad (no real mount's, after the exact
        ** index shifts) carry float noise of 1e-9 and more: Newton, on
        ** forward_f itself, is consistent with the forward model there */
        if (!(m_fabs(dT) <= 0.01f && m_fabs(dD) <= 0.01f))
            return PM_WARN_NOT_CONVERGED;
        /* From the second step on, the contraction rho = change / last
        ** predicts the next change, which is about how far the new point
        ** misses.  One direction's rate need not be another's, and this
        ** iteration turns the target's trig where the forward model rounds
        ** its own frame angle to float: so the point is checked with the
        ** forward model itself, as the Newton iteration judges its points
        ** (one more evaluation); Newton takes over if it misses. */
        float rho = last > 0 ? change / last : change == 0 ? 0.0f : 1.0f;
        if ((it > 0 || warm) && change * rho <= 0.25f * tol) {
            return point_ok_f(m, ctx, T0, D, sD, cD, dT, dD, flip, ref, corr, t_out, d_out)
                       ? PM_OK
                       : PM_WARN_NOT_CONVERGED;
        }
        last = change;
    }
    return PM_WARN_NOT_CONVERGED;
}

pm_status invert_f(const pm_model_f *m, const pm_context *ctx, double T, double D, int side,
                   const double *start, const float *warm, float *corr, bool *have_corr,
                   double *enc_ha, double *enc_dec)
{
    pm_status st = check_f(m, ctx);
    if (st != PM_OK)
        return st;
    if (!enc_ha || !enc_dec)
        return PM_ERR_ARG;
    if (!finite(T) || !finite(D) || (start && (!finite(start[0]) || !finite(start[1]))))
        return PM_ERR_NONFINITE;
    if (abs_beyond(D, PI / 2 + 1e-12))
        return PM_ERR_ARG;
    if (start && (abs_beyond(start[0], PM_START_MAX) || abs_beyond(start[1], PM_START_MAX)))
        return PM_ERR_ARG;
    double turn[2];
    turn_of(start, side, m->e, turn);
    double t, d;
    {
        /* the fixed point first; Newton where it does not contract */
        bool flip = side < 0;
        if (start)
            flip = abs_beyond(wrap_pi(start[1] - m->e), PI / 2);
        /* (within float noise of the pole's edge the frame can put the
        ** point a hair beyond it: the side is checked in double) */
        if (fixed_f(m, ctx, T, D, flip, turn, warm, corr, &t, &d) == PM_OK &&
            (start || !abs_beyond(wrap_pi(d - m->e), PI / 2) == !flip)) {
            *enc_ha = t;
            *enc_dec = d;
            if (have_corr)
                *have_corr = true;
            return PM_OK;
        }
    }
    if (start) {
        t = start[0];
        d = start[1];
    } else if (side > 0) {
        t = T - m->c;
        d = D + m->e;
    } else {
        t = T + PI - m->c;
        d = PI - D + m->e;
    }
    /* Newton on sky offsets at the target, the Jacobian by differences:
    ** kept while each step gains a factor 10 (chord steps, one evaluation
    ** each), refreshed otherwise; a step that does not reduce the offset is
    ** cut back (at most 3 times). */
    /* iterate on the turn the result is returned on: periodic terms of
    ** non-integer G read the raw angle and jump between turns */
    finish_angles(turn, &t, &d);
    const double h = 1e-5;
    double T0, D0, T1, D1;
    float fx, fy, ax, ay, j00 = 0, j01 = 0, j10 = 0, j11 = 0, det = 0;
    forward_f(m, ctx, t, d, &T0, &D0);
    float fn = sky_offset(T0, D0, T, D, &fx, &fy);
    bool refresh = true;
    pm_status result = PM_WARN_NOT_CONVERGED;
    for (int it = 0; it <= PM_INVERT_F_MAX; it++) {
        if (fn <= (float)PM_INVERT_F_TOL) {
            result = PM_OK;
            break;
        }
        if (it == PM_INVERT_F_MAX)
            break;
        if (refresh) {
            forward_f(m, ctx, t + h, d, &T1, &D1);
            sky_offset(T1, D1, T, D, &ax, &ay);
            j00 = (ax - fx) / (float)h;
            j10 = (ay - fy) / (float)h;
            forward_f(m, ctx, t, d + h, &T1, &D1);
            sky_offset(T1, D1, T, D, &ax, &ay);
            j01 = (ax - fx) / (float)h;
            j11 = (ay - fy) / (float)h;
            det = j00 * j11 - j01 * j10;
            if (!(m_fabs(det) > 1e-12f))
                break;
        }
        double ds_t = (double)((j11 * fx - j01 * fy) / det);
        double ds_d = (double)((j00 * fy - j10 * fx) / det);
        float lam = 1, nfx = 0, nfy = 0, nfn = 0;
        double nt = t, nd = d;
        for (int cut = 0; cut < 4; cut++, lam *= 0.25f) {
            nt = t - lam * ds_t;
            nd = d - lam * ds_d;
            finish_angles(turn, &nt, &nd);
            forward_f(m, ctx, nt, nd, &T0, &D0);
            nfn = sky_offset(T0, D0, T, D, &nfx, &nfy);
            if (nfn < fn)
                break;
        }
        if (!(nfn < fn)) {
            if (refresh)
                break; /* no progress even with a fresh Jacobian */
            refresh = true;
            continue;
        }
        refresh = nfn > 0.1f * fn;
        t = nt;
        d = nd;
        fx = nfx;
        fy = nfy;
        fn = nfn;
    }
    /* the solution must be on the requested side of the mount's pole */
    /* (in double, without trig: a float cosine misjudges the side within
    ** ~1e-8 rad of the pole's edge) */
    if (result == PM_OK && !start) {
        double de = wrap_pi(d - m->e);
        if ((de >= -PI / 2 && de <= PI / 2 ? 1 : -1) != side)
            result = PM_WARN_NOT_CONVERGED;
    }
    if (result != PM_OK && finite(t) && finite(d)) {
        /* the best position of a warning: is the model finite there? */
        forward_f(m, ctx, t, d, &T0, &D0);
        if (!finite(T0) || !finite(D0))
            t = T0;
    }
    if (!finite(t) || !finite(d))
        return PM_ERR_NONFINITE; /* float overflow in the terms: outputs untouched */
    finish_angles(turn, &t, &d);
    *enc_ha = t;
    *enc_dec = d;
    return result;
}

} /* namespace */

extern "C" {

pm_status pm_model_f_prepare(pm_model_f *mf, const pm_model *m)
{
    if (!mf)
        return PM_ERR_ARG;
    pm_status st = model_ready(m);
    if (st != PM_OK)
        return st;
    if (!terms_intact(m))
        return PM_ERR_STATE; /* a term changed since pm_model_prepare */
    __builtin_memset(mf, 0, sizeof *mf);
    mf->mount = m->mount;
    mf->order = m->order;
    mf->n_terms = m->n_terms;
    mf->n_base = m->n_base;
    mf->needs_ctx = m->needs_ctx;
    mf->c = m->coef[2];
    mf->e = m->coef[4];
    mf->sc = (float)m->sc;
    mf->cc = (float)m->cc;
    mf->se = (float)m->se;
    mf->ce = (float)m->ce;
    double a = m->coef[0], b = m->coef[1], th2 = a * a + b * b;
    mf->a = (float)a;
    mf->b = (float)b;
    if (th2 < 1e-8) {
        mf->ra = (float)(1 - th2 / 6);
        mf->rb = (float)(0.5 - th2 / 24);
    } else {
        double th = m_sqrt(th2);
        mf->ra = (float)(m_sin(th) / th);
        mf->rb = (float)((1 - m_cos(th)) / th2);
    }
    double dh = m->coef[3], ih = m->coef[5];
    mf->sd = (float)m_sin(dh);
    mf->vd = (float)(2 * m_sin(dh / 2) * m_sin(dh / 2));
    mf->si = (float)m_sin(ih);
    mf->vi = (float)(2 * m_sin(ih / 2) * m_sin(ih / 2));
    mf->lat_s = (float)m_sin(m->latitude);
    mf->lat_c = (float)m_cos(m->latitude);
    for (int j = 0; j < PM_N_HARM(PM_MAX_L); j++)
        for (int k = 0; k < 6; k++)
            mf->dense[j][k] = (float)m->dense[j][k];
    for (int i = 0; i < m->n_terms; i++) {
        mf->term[i] = m->term[i];
        mf->coef[i] = (float)m->coef[i];
    }
    mf->prepared = 1;
    return PM_OK;
}

pm_status pm_model_apply_f(const pm_model_f *m, const pm_context *ctx, double enc_ha,
                           double enc_dec, double *app_ha, double *app_dec)
{
    pm_status st = check_f(m, ctx);
    if (st != PM_OK)
        return st;
    if (!app_ha || !app_dec)
        return PM_ERR_ARG;
    if (!finite(enc_ha) || !finite(enc_dec))
        return PM_ERR_NONFINITE;
    double t, d;
    forward_f(m, ctx, enc_ha, enc_dec, &t, &d);
    if (!finite(t) || !finite(d))
        return PM_ERR_NONFINITE; /* float overflow in the terms: outputs untouched */
    *app_ha = t;
    /* float rounding can step past the pole by an ulp of float (the test
    ** on the bits first: two double comparisons are calls on an FPU
    ** without double) */
    *app_dec = !abs_beyond(d, PI / 2) ? d : below0(d) ? -PI / 2 : PI / 2;
    return PM_OK;
}

pm_status pm_model_invert_f(const pm_model_f *m, const pm_context *ctx, double app_ha,
                            double app_dec, int side, double *enc_ha, double *enc_dec)
{
    if (side != PM_SIDE_NORMAL && side != PM_SIDE_FLIPPED)
        return PM_ERR_ARG;
    return invert_f(m, ctx, app_ha, app_dec, side == PM_SIDE_NORMAL ? 1 : -1, 0, 0, 0, 0,
                    enc_ha, enc_dec);
}

pm_status pm_model_invert_near_f(const pm_model_f *m, const pm_context *ctx, double app_ha,
                                 double app_dec, double start_ha, double start_dec,
                                 double *enc_ha, double *enc_dec)
{
    double start[2] = {start_ha, start_dec};
    return invert_f(m, ctx, app_ha, app_dec, 1, start, 0, 0, 0, enc_ha, enc_dec);
}

pm_status pm_track_f_start(pm_track_f *t, double enc_ha, double enc_dec)
{
    return start_state(t, enc_ha, enc_dec, PM_TRACK_F_MAGIC);
}

pm_status pm_model_track_f(const pm_model_f *m, const pm_context *ctx, pm_track_f *t,
                           double app_ha, double app_dec, double *enc_ha, double *enc_dec)
{
    if (!t || t->magic != PM_TRACK_F_MAGIC || !enc_ha || !enc_dec)
        return PM_ERR_ARG;
    float corr[2] = {0, 0}, warm[2];
    bool have = false;
    double eh = 0, ed = 0;
    /* the correction moved on by its last change (a target moving
    ** uniformly: second order), or as it was */
    for (int i = 0; i < 2; i++)
        warm[i] = t->have_corr > 1 ? t->corr[i] + (t->corr[i] - t->corr_prev[i]) : t->corr[i];
    pm_status st = invert_f(m, ctx, app_ha, app_dec, 1, t->enc, t->have_corr ? warm : 0, corr,
                            &have, &eh, &ed);
    if (st < 0)
        return st;
    if (st == PM_OK) {
        t->enc[0] = eh;
        t->enc[1] = ed;
        t->have_corr = have ? (t->have_corr ? 2 : 1) : 0;
        t->corr_prev[0] = t->corr[0];
        t->corr_prev[1] = t->corr[1];
        t->corr[0] = corr[0];
        t->corr[1] = corr[1];
    } else {
        t->have_corr = 0;
    }
    *enc_ha = eh;
    *enc_dec = ed;
    return st;
}

} /* extern "C" */
