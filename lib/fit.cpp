/*
**  fit.cpp - least-squares fit of the pointing model: Gauss-Newton passes
**  over observations accumulated into fixed-size normal equations, solved
**  by an equilibrated Cholesky factorisation written out here.
**
**  Reference: Pal et al., Exp Astron (2016), Sec. 5.1 (linear least
**  squares); the exact isotropic part makes the problem mildly nonlinear.
*/
#include "pm.h"
#include "pm_detail.hpp"

using namespace pm::detail;

namespace {

const int FIT_READY = 0x5046; /* fit->state after init / solve */

/* Pivots below this fraction of the equilibrated diagonal mean the term is
** (numerically) a combination of the ones before it. */
const double PIVOT_MIN = 1e-11;

inline int pidx(int i, int j) { return i * (i + 1) / 2 + j; } /* i >= j */

/* chi^2 changes below this (rad^2, i.e. (1e-15 rad)^2) are rounding: with
** exactly consistent data chi^2 itself is zero and the statistical tests
** scaled by it could never be met. */
const double CHI2_FLOOR = 1e-30;

/* Bound on the sums of squares (chi^2 and the diagonal of J^T J) and on
** what the solve derives from them.  Since |(J^T J)_ij| <=
** sqrt((J^T J)_ii (J^T J)_jj) and |(J^T r)_i| <= sqrt((J^T J)_ii chi^2),
** no accumulated sum can overflow below it; residuals and derivatives up
** to ~1e150 (rad) are accepted, far beyond any real mount. */
const double SUM_MAX = 1e300;

/* Derivative of the log map at unit vector q (2 x 3). */
void dlog(const V3<double> &q, double D[2][3], double *ly, double *lz)
{
    double s2 = q.y * q.y + q.z * q.z;
    double s = m_sqrt(s2);
    double th = m_atan2(s, q.x);
    double f, g; /* f = th/sin th, g = f'(th)/sin th */
    if (s2 < 1e-4 && q.x > 0) {
        f = 1 + s2 / 6 + 3 * s2 * s2 / 40;
        g = 1.0 / 3 + 2.0 / 15 * th * th;
    } else {
        f = th / s;
        g = (s - th * q.x) / (s2 * s);
    }
    *ly = q.y * f;
    *lz = q.z * f;
    /* d(log) = f dq_yz + q_yz g (qx (qy dqy + qz dqz) - s^2 dqx) */
    D[0][0] = -q.y * g * s2;
    D[0][1] = f + q.y * g * q.x * q.y;
    D[0][2] = q.y * g * q.x * q.z;
    D[1][0] = -q.z * g * s2;
    D[1][1] = q.z * g * q.x * q.y;
    D[1][2] = f + q.z * g * q.x * q.z;
}

/* M^T x for the model's isotropic rotation M = H Pt(t') X(d) Pd(d') T(i)
** at one position, and its derivatives with respect to the six isotropic
** coefficients (a, b, c', d, e', i). */
struct Chain {
    const pm_model *m;
    Iso<double> k;
    double stp, ctp, sdp, cdp;
};

V3<double> mt_and_derivs(const Chain &c, const V3<double> &x, V3<double> dq[6])
{
    const Iso<double> &k = c.k;
    const V3<double> ex = v3(1.0, 0.0, 0.0), ey = v3(0.0, 1.0, 0.0),
                     ez = v3(0.0, 0.0, 1.0);
    V3<double> s0 = mat_tmul<double>(k.h, x);
    V3<double> s1 = rot_zt<double>(c.stp, c.ctp, s0);
    V3<double> s2 = rot_xt<double>(k.sd, k.cd, s1);
    V3<double> s3 = rot_dt<double>(c.sdp, c.cdp, s2);
    V3<double> q = rot_zt<double>(k.si, k.ci, s3);
    {
        /* right Jacobian of exp at w = (a, b, 0) */
        double a = c.m->coef[0], b = c.m->coef[1], th2 = a * a + b * b, Bc, Cc;
        if (th2 < 1e-8) {
            Bc = 0.5 - th2 / 24;
            Cc = 1.0 / 6 - th2 / 120;
        } else {
            double th = m_sqrt(th2);
            Bc = (1 - m_cos(th)) / th2;
            Cc = (th - m_sin(th)) / (th2 * th);
        }
        V3<double> w = v3(a, b, 0.0);
        for (int j = 0; j < 2; j++) {
            V3<double> e = j == 0 ? ex : ey;
            V3<double> we = cross(w, e);
            V3<double> wwe = cross(w, we);
            V3<double> jr = v3(e.x - Bc * we.x + Cc * wwe.x,
                               e.y - Bc * we.y + Cc * wwe.y,
                               e.z - Bc * we.z + Cc * wwe.z);
            V3<double> v = cross(s0, jr); /* -(jr x s0) */
            v = rot_zt<double>(c.stp, c.ctp, v);
            v = rot_xt<double>(k.sd, k.cd, v);
            v = rot_dt<double>(c.sdp, c.cdp, v);
            dq[j] = rot_zt<double>(k.si, k.ci, v);
        }
    }
    {
        V3<double> v = cross(s1, ez); /* -(ez x s1) */
        v = rot_xt<double>(k.sd, k.cd, v);
        v = rot_dt<double>(c.sdp, c.cdp, v);
        dq[2] = rot_zt<double>(k.si, k.ci, v);
    }
    {
        V3<double> v = cross(s2, ex);
        v = rot_dt<double>(c.sdp, c.cdp, v);
        dq[3] = rot_zt<double>(k.si, k.ci, v);
    }
    dq[4] = rot_zt<double>(k.si, k.ci, cross(s3, ey));
    dq[5] = cross(q, ez);
    return q;
}

/* Two design rows (model derivatives) and the residual of one observation
** at model m.  Residual: r = log(M^T t) - D(x), in the frame transported
** by the isotropic rotation M (docs/model.md). */
void rows(const pm_model *m, const pm_context *ctx, double enc_ha,
          double enc_dec, double app_ha, double app_dec, double *row0,
          double *row1, double r[2])
{
    Chain c;
    c.m = m;
    iso_from_model<double>(m, &c.k);
    Trig<double> g = trig_of(enc_ha, enc_dec);
    shifted<double>(c.k, g, &c.stp, &c.ctp, &c.sdp, &c.cdp);
    V3<double> dq[6];
    V3<double> q = mt_and_derivs(c, unit_of(app_ha, app_dec), dq);
    double D[2][3], ly, lz;
    dlog(q, D, &ly, &lz);
    /* The anisotropic displacement D, a function of the shifted position
    ** (t' = t + c', d' = d - e': its harmonics and base vectors,
    ** docs/model.md), and with it, in the same evaluation, how D moves
    ** with c' and e' (Js: d/dt', d/dd'; its part of the index columns,
    ** below); D bit for bit as aniso computes it. */
    double dt, dd, Js[4] = {0, 0, 0, 0};
    if (m->n_terms > 6) {
        aniso_jac_at(m, c.k, g, ctx, true, &dt, &dd, Js);
    } else {
        const double sg[4] = {c.stp, c.ctp, c.sdp, c.cdp};
        aniso<double>(m, c.k, g, ctx, &dt, &dd, sg);
    }
    r[0] = ly - dt;
    r[1] = lz - dd;

    /* isotropic terms: row = -dlog * dq/dtheta */
    for (int j = 0; j < 6; j++) {
        row0[j] = -(D[0][0] * dq[j].x + D[0][1] * dq[j].y + D[0][2] * dq[j].z);
        row1[j] = -(D[1][0] * dq[j].x + D[1][1] * dq[j].y + D[1][2] * dq[j].z);
    }

    /* harmonic terms: linear, row = Y_lm N_lm (u_k, v_k), harmonics and
    ** base vectors at the shifted position */
    Trig<double> gs = g;
    gs.st = c.stp;
    gs.ct = c.ctp;
    gs.sd = c.sdp;
    gs.cd = c.cdp;
    double Y[PM_N_HARM(PM_MAX_L)];
    harmonics<double>(m->order, gs, Y);
    for (int i = 6; i < m->n_base; i++) {
        const pm_term *tm = &m->term[i];
        int j = tm->l * tm->l + tm->l + tm->m;
        double y = Y[j] * norm_lm(tm->l, tm->m);
        double u, v;
        base_uv<double>(tm->k, gs, &u, &v);
        row0[i] = y * u;
        row1[i] = y * v;
    }
    Site<double> st;
    if (m->n_terms > m->n_base) {
        /* added terms: linear, row = their displacement per unit coefficient */
        st = site_of<double>(m, c.k, g, ctx);
        for (int i = m->n_base; i < m->n_terms; i++)
            term_uv<double>(m->term[i], g, st, ctx, &row0[i], &row1[i]);
    }
    /* D's part of the index columns (exact Jacobian; rows are +dD/dtheta):
    ** d/dc' = d/dt', d/de' = -d/dd' */
    row0[2] += Js[0];
    row1[2] += Js[2];
    row0[4] -= Js[1];
    row1[4] -= Js[3];
    if (m->n_terms == m->n_base)
        return;
    /* The zenith terms' direction, M^T Z, turns with the isotropic terms:
    ** their part of the isotropic columns (exact Jacobian). */
    if (!st.have_zenith)
        return;
    V3<double> Z = m->mount == PM_MOUNT_ALTAZ
                       ? v3(0.0, 0.0, 1.0)
                       : v3(m_cos(m->latitude), 0.0, m_sin(m->latitude));
    V3<double> dz[6];
    V3<double> z = mt_and_derivs(c, Z, dz);
    for (int i = m->n_base; i < m->n_terms; i++) {
        const pm_term &t = m->term[i];
        if (t.kind != PM_TERM_ZENITH || (t.side && t.side != st.side))
            continue;
        for (int j = 0; j < 6; j++) {
            double du, dv;
            if (t.l == 0 && z.x > 0.01) { /* (zy, zz) / zx */
                du = (dz[j].y * z.x - z.y * dz[j].x) / (z.x * z.x);
                dv = (dz[j].z * z.x - z.z * dz[j].x) / (z.x * z.x);
            } else if (t.l == 0) { /* clamped: (zy, zz) / 0.01 */
                du = dz[j].y / 0.01;
                dv = dz[j].z / 0.01;
            } else {
                du = dz[j].y;
                dv = dz[j].z;
            }
            row0[j] += m->coef[i] * du;
            row1[j] += m->coef[i] * dv;
        }
    }
}

void reset_pass(pm_fit *fit)
{
    int P = fit->n_par;
    for (int i = 0; i < PM_PACKED(P); i++)
        fit->ata[i] = 0;
    for (int i = 0; i < P; i++)
        fit->atb[i] = 0;
    fit->chi2 = 0;
    fit->n_obs = 0;
}

/* Cholesky factorisation of packed lower A (n x n) in place: A = L L^T.
** Returns -1 on success, else the index of the first pivot below PIVOT_MIN
** (A equilibrated: unit diagonal). */
int cholesky(double *a, int n)
{
    for (int j = 0; j < n; j++) {
        double *rj = a + pidx(j, 0);
        double d = rj[j];
        for (int k = 0; k < j; k++)
            d -= rj[k] * rj[k];
        if (!(d > PIVOT_MIN))
            return j;
        d = m_sqrt(d);
        rj[j] = d;
        for (int i = j + 1; i < n; i++) {
            double *ri = a + pidx(i, 0);
            double s = ri[j];
            for (int k = 0; k < j; k++)
                s -= ri[k] * rj[k];
            ri[j] = s / d;
        }
    }
    return -1;
}

/* Solve L L^T x = b in place (L packed lower). */
void chol_solve(const double *l, int n, double *b)
{
    for (int i = 0; i < n; i++) {
        const double *ri = l + pidx(i, 0);
        double s = b[i];
        for (int k = 0; k < i; k++)
            s -= ri[k] * b[k];
        b[i] = s / ri[i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = b[i];
        for (int k = i + 1; k < n; k++)
            s -= l[pidx(k, i)] * b[k];
        b[i] = s / l[pidx(i, i)];
    }
}

/* Replace L (packed lower) by (L L^T)^-1 (packed lower), in place. */
void chol_inverse(double *a, int n)
{
    /* L^-1 in place (lower triangular) */
    for (int j = 0; j < n; j++) {
        a[pidx(j, j)] = 1.0 / a[pidx(j, j)];
        for (int i = j + 1; i < n; i++) {
            double s = 0;
            for (int k = j; k < i; k++)
                s -= a[pidx(i, k)] * a[pidx(k, j)];
            a[pidx(i, j)] = s / a[pidx(i, i)];
        }
    }
    /* C = L^-T L^-1: C_ij = sum_{k >= i} Linv_ki Linv_kj (i >= j) */
    for (int j = 0; j < n; j++)
        for (int i = j; i < n; i++) {
            double s = 0;
            for (int k = i; k < n; k++)
                s += a[pidx(k, i)] * a[pidx(k, j)];
            a[pidx(i, j)] = s;
        }
}

} /* namespace */

extern "C" {

pm_status pm_fit_init(pm_fit *fit, const pm_model *start)
{
    if (!fit || !start)
        return PM_ERR_ARG;
    pm_status st = model_ready(start);
    if (st != PM_OK)
        return st;
    if (!terms_intact(start))
        return PM_ERR_STATE; /* a term changed since pm_model_prepare */
    fit->lin = *start;
    fit->n_par = start->n_terms;
    fit->bad_term = -1;
    fit->iterations = 0;
    fit->cov_valid = 0;
    fit->base_chi2 = 0;
    fit->base_pred = 0;
    fit->halvings = 0;
    for (int i = 0; i < PM_MAX_TERMS; i++)
        fit->base_coef[i] = fit->step[i] = 0;
    reset_pass(fit);
    for (int i = 0; i < PM_MAX_TERMS; i++)
        fit->scale[i] = 0;
    fit->state = FIT_READY;
    return PM_OK;
}

pm_status pm_fit_add(pm_fit *fit, const pm_context *ctx, double enc_ha,
                     double enc_dec, double app_ha, double app_dec)
{
    if (!fit)
        return PM_ERR_ARG;
    if (fit->state != FIT_READY || fit->n_par != fit->lin.n_terms)
        return PM_ERR_STATE;
    pm_status cs = context_ok(&fit->lin, ctx);
    if (cs != PM_OK)
        return cs;
    if (!finite(enc_ha) || !finite(enc_dec) || !finite(app_ha) ||
        !finite(app_dec))
        return PM_ERR_NONFINITE;
    if (m_fabs(app_dec) > PI / 2 + 1e-9)
        return PM_ERR_ARG;
    double r0[PM_MAX_TERMS], r1[PM_MAX_TERMS], r[2];
    rows(&fit->lin, ctx, enc_ha, enc_dec, app_ha, app_dec, r0, r1, r);
    int P = fit->n_par;
    /* Refused before anything is added: non-finite rows (the terms
    ** overflow here) and rows that would take a sum beyond SUM_MAX (then
    ** chi^2, sigma and the covariance could not be finite). */
    if (!(fit->chi2 + (r[0] * r[0] + r[1] * r[1]) <= SUM_MAX))
        return PM_ERR_NONFINITE;
    for (int i = 0; i < P; i++)
        if (!(fit->ata[pidx(i, i)] + (r0[i] * r0[i] + r1[i] * r1[i]) <= SUM_MAX))
            return PM_ERR_NONFINITE;
    /* the row's outer product, two columns at a time (independent sums:
    ** GCC's vectoriser makes the loop two-wide SIMD on the host; the normal
    ** equations are most of a large run's fitting time) */
    for (int i = 0; i < P; i++) {
        double *ai = fit->ata + pidx(i, 0);
        double x0 = r0[i], x1 = r1[i];
        int j = 0;
        for (; j < i; j += 2) {
            double s0 = x0 * r0[j] + x1 * r1[j];
            double s1 = x0 * r0[j + 1] + x1 * r1[j + 1];
            ai[j] += s0;
            ai[j + 1] += s1;
        }
        if (j == i)
            ai[j] += x0 * r0[j] + x1 * r1[j];
        fit->atb[i] += x0 * r[0] + x1 * r[1];
    }
    fit->chi2 += r[0] * r[0] + r[1] * r[1];
    fit->n_obs++;
    return PM_OK;
}

/* The four terms applied exactly as rotations, c', d, e' and i, reduced
** into (-pi, pi]: the model is the same to rounding, and a Gauss-Newton
** step that went a turn or a hundred away (c' -36179 deg, i 360.06 deg;
** outside probes) no longer comes back as the fit.  A non-finite step is
** left to pm_model_prepare's PM_ERR_NONFINITE. */
static void wrap_index(pm_model *m)
{
    for (int k = 2; k <= 5; k++)
        if (finite(m->coef[k]))
            m->coef[k] = wrap_pi(m->coef[k]);
}

/* The isotropic terms a[6] (reduced into (-pi, pi]) at their alias with
** |d| and |i| within pi/2: (e' + pi, pi - i) and (c' + pi, pi - d, e' +
** pi) point exactly alike where these six are all the model (pm.h,
** pm_fit_run Note 3).  True if it changed them. */
static bool canonical_alias(double *a)
{
    bool changed = false;
    if (m_fabs(a[5]) > PI / 2) {
        a[4] = wrap_pi(a[4] + PI);
        a[5] = wrap_pi(PI - a[5]);
        changed = true;
    }
    if (m_fabs(a[3]) > PI / 2) {
        a[2] = wrap_pi(a[2] + PI);
        a[3] = wrap_pi(PI - a[3]);
        a[4] = wrap_pi(a[4] + PI);
        changed = true;
    }
    return changed;
}

/* pm_fit_solve but for the covariance's state after an error (there).
** keep: the statistics and covariance at the pass's own point, which is
** returned unmoved (pm_fit_run's last pass, Note 2 there); no damping, and
** a pass after it is taken as from an accepted point with no step. */
static pm_status solve(pm_fit *fit, pm_model *out, pm_fit_result *res, bool keep = false)
{
    if (!fit || !out)
        return PM_ERR_ARG;
    if (fit->state != FIT_READY || fit->n_par != fit->lin.n_terms)
        return PM_ERR_STATE;
    int P = fit->n_par;
    if (2 * fit->n_obs <= P)
        return PM_ERR_TOO_FEW;

    /* Damping (Armijo): the step s from the accepted point predicted a
    ** decrease s^T J^T r of chi^2; a pass that did not realise at least 1e-4
    ** of it (for the current step fraction) is rejected and s halved. */
    double frac = 1.0;
    for (int h = 0; h < fit->halvings; h++)
        frac *= 0.5;
    if (!keep && fit->iterations > 0 &&
        fit->chi2 > fit->base_chi2 - 1e-4 * frac * fit->base_pred) {
        pm_model next = fit->lin;
        /* give up on the step (the accepted point is the answer) when what
        ** is left of it could not matter statistically, or after 40 cuts */
        long dof_r = 2 * fit->n_obs - P;
        bool give_up = fit->halvings >= 40 ||
                       0.5 * frac * fit->base_pred <=
                           1e-6 * fit->base_chi2 / (double)dof_r + CHI2_FLOOR;
        for (int i = 0; i < P; i++) {
            if (!give_up)
                fit->step[i] *= 0.5;
            next.coef[i] = fit->base_coef[i] + (give_up ? 0.0 : fit->step[i]);
        }
        wrap_index(&next);
        pm_status st = pm_model_prepare(&next);
        if (st != PM_OK)
            return st;
        fit->halvings++;
        fit->iterations++;
        if (res) {
            res->accepted = 0;
            res->converged = give_up ? 1 : 0;
            res->iterations = fit->iterations;
        }
        *out = next;
        fit->lin = next;
        reset_pass(fit);
        return PM_OK;
    }

    /* From here fit->cov is overwritten: it is valid again only when this
    ** solve succeeds (pm_fit_covariance checks; pm_fit_solve also clears
    ** cov_valid after an error returned before this point). */
    fit->cov_valid = 0;

    /* column equilibration: unit diagonal */
    for (int j = 0; j < P; j++) {
        double d = fit->ata[pidx(j, j)];
        if (!(d > 0)) {
            fit->bad_term = j;
            return PM_ERR_SINGULAR;
        }
        fit->scale[j] = 1.0 / m_sqrt(d);
    }
    for (int i = 0; i < P; i++)
        for (int j = 0; j <= i; j++)
            fit->cov[pidx(i, j)] =
                fit->ata[pidx(i, j)] * fit->scale[i] * fit->scale[j];
    int bad = cholesky(fit->cov, P);
    if (bad >= 0) {
        fit->bad_term = bad;
        return PM_ERR_SINGULAR;
    }
    double step[PM_MAX_TERMS];
    for (int i = 0; i < P; i++)
        step[i] = fit->atb[i] * fit->scale[i];
    chol_solve(fit->cov, P, step);
    for (int i = 0; i < P; i++)
        step[i] *= fit->scale[i];
    chol_inverse(fit->cov, P);
    for (int i = 0; i < P; i++)
        for (int j = 0; j <= i; j++)
            fit->cov[pidx(i, j)] *= fit->scale[i] * fit->scale[j];

    pm_model next = fit->lin;
    for (int i = 0; i < P && !keep; i++)
        next.coef[i] += step[i];
    wrap_index(&next);
    /* a step that overflows: PM_ERR_NONFINITE from the prepare */
    pm_status st = pm_model_prepare(&next);
    if (st != PM_OK)
        return st;

    long dof = 2 * fit->n_obs - P;
    double sigma = m_sqrt(fit->chi2 / (double)dof);
    double max_step = 0, pred = 0;
    for (int i = 0; i < P; i++)
        pred += step[i] * fit->atb[i]; /* predicted chi^2 decrease */
    /* The statistics must be finite: every variance sigma^2 (J^T J)^-1_ii
    ** (so every covariance, |cov_ij| <= sqrt(cov_ii cov_jj)) and the
    ** predicted decrease.  They overflow only for steps or residuals near
    ** 1e150 rad. */
    if (!(m_fabs(pred) <= SUM_MAX))
        return PM_ERR_NONFINITE;
    for (int i = 0; i < P; i++)
        if (!(fit->cov[pidx(i, i)] * (sigma * sigma) <= SUM_MAX))
            return PM_ERR_NONFINITE;
    /* Converged: every step negligible against its error, or a predicted
    ** decrease of chi^2 below 1e-4 sigma^2 (the step then moves every
    ** coefficient by less than 1% of its 1-sigma error). */
    long dof_c = 2 * fit->n_obs - P;
    int converged = pred <= 1e-4 * fit->chi2 / (double)dof_c + CHI2_FLOOR ? 1 : 0;
    int small = 1;
    double err[PM_MAX_TERMS];
    for (int i = 0; i < P; i++) {
        err[i] = sigma * m_sqrt(fit->cov[pidx(i, i)]);
        double a = m_fabs(step[i]);
        if (err[i] > 0 && a / err[i] > max_step)
            max_step = a / err[i];
        if (a > 1e-6 * err[i] + 1e-15)
            small = 0;
    }
    converged = converged || small || keep;
    for (int i = 0; i < P; i++) {
        fit->base_coef[i] = fit->lin.coef[i];
        fit->step[i] = keep ? 0.0 : step[i];
    }
    fit->iterations++;
    fit->cov_valid = 1;
    fit->base_chi2 = fit->chi2;
    fit->base_pred = keep ? 0.0 : pred;
    fit->halvings = 0;
    if (res) {
        res->accepted = 1;
        res->n_obs = fit->n_obs;
        res->n_par = P;
        res->chi2 = fit->chi2;
        res->sigma = sigma;
        for (int i = 0; i < PM_MAX_TERMS; i++)
            res->err[i] = i < P ? err[i] : 0.0;
        res->max_step = max_step;
        res->converged = converged;
        res->iterations = fit->iterations;
    }
    *out = next;
    fit->lin = next;
    fit->bad_term = -1;
    reset_pass(fit);
    return PM_OK;
}

pm_status pm_fit_solve(pm_fit *fit, pm_model *out, pm_fit_result *res)
{
    pm_status st = solve(fit, out, res);
    /* Every error ends the previous solve's covariance (Note 6 of pm.h):
    ** pm_fit_covariance, pm_fit_pointing_sigma and pm_fit_point_gain
    ** then return PM_ERR_STATE, whether or not the factorisation got to
    ** overwrite fit->cov. */
    if (st < 0 && fit)
        fit->cov_valid = 0;
    return st;
}

/* The circular sums of index_start for one reading of the sides: fold < 0
** none, else readings whose declination minus fold_e lies beyond +-90 deg
** folded to the sky (there e' enters with the other sign).  Returns the
** squared resultant of the declination offsets (how well they agree). */
static double index_sums(const pm_model *m, long n, const double *enc_ha,
                         const double *enc_dec, const double *app_ha,
                         const double *app_dec, int fold, double fold_e, double *sums)
{
    for (int j = 0; j < 4; j++)
        sums[j] = 0;
    for (long i = 0; i < n; i++) {
        if (!finite(enc_ha[i]) || !finite(enc_dec[i]) || !finite(app_ha[i]) ||
            !finite(app_dec[i]) || m_fabs(enc_dec[i]) > 1e6 || m_fabs(enc_ha[i]) > 1e6)
            continue;
        const double cd = m_cos(app_dec[i]), w = cd * cd;
        double h = enc_ha[i], d = wrap_pi(enc_dec[i]), s = 1;
        if (fold >= 0 && m->mount != PM_MOUNT_ALTAZ && m_fabs(wrap_pi(d - fold_e)) > PI / 2) {
            h += PI;
            d = (d > 0 ? PI : -PI) - d;
            s = -1;
        }
        const double dc = app_ha[i] - h, de = s * (d - app_dec[i]);
        sums[0] += w * m_sin(dc);
        sums[1] += w * m_cos(dc);
        sums[2] += m_sin(de);
        sums[3] += m_cos(de);
    }
    return sums[2] * sums[2] + sums[3] * sums[3];
}

/* A start for the two index terms c' and e' (pm_fit_run's Note 1): the
** circular means of the encoder-minus-true offsets (c' = true - encoder
** on axis 1, e' = encoder - true on axis 2: pm.h's P_d(delta - e')), the
** hour-angle offsets weighted by cos^2 of the declination (near the pole
** they grow as sec), for the reading of the sides under which the
** declination offsets agree best: unfolded (a fork whose declination index
** takes its readings past 90 deg does not flip), readings beyond +-90 deg
** folded to the sky (a German mount's two sides differ by twice the
** declination unfolded), or readings beyond +-90 deg of the unfolded or
** the folded mean e' folded, that mean refined once (a German mount whose
** declination encoder reads 180 deg off reads its normal side beyond
** +-90: folded at 0 its offsets were spread, unfolded half of them, and
** the hour-angle mean of two halves 180 deg apart fell anywhere; an
** outside probe's runs stopped at sigma 1.3e5" in 6 of 32).  A later
** reading is taken only where its offsets agree better beyond rounding.
** False where no offset is usable. */
static bool index_start(const pm_model *m, long n, const double *enc_ha,
                        const double *enc_dec, const double *app_ha,
                        const double *app_dec, double *c, double *e)
{
    double best[4], sums[4];
    double best_r = index_sums(m, n, enc_ha, enc_dec, app_ha, app_dec, -1, 0, best);
    double r = index_sums(m, n, enc_ha, enc_dec, app_ha, app_dec, 1, 0, sums);
    const double unfolded_e = m_atan2(best[2], best[3]), folded_e = m_atan2(sums[2], sums[3]);
    if (r >= best_r) { /* (ties folded, as before) */
        best_r = r;
        __builtin_memcpy(best, sums, sizeof best);
    }
    if (m->mount != PM_MOUNT_ALTAZ) {
        for (int j = 0; j < 2; j++) {
            double fe = j ? folded_e : unfolded_e;
            for (int it = 0; it < 2; it++) {
                r = index_sums(m, n, enc_ha, enc_dec, app_ha, app_dec, 1, fe, sums);
                if (r > best_r * (1 + 1e-9)) {
                    best_r = r;
                    __builtin_memcpy(best, sums, sizeof best);
                }
                fe = m_atan2(sums[2], sums[3]);
            }
        }
    }
    if (!(best[0] * best[0] + best[1] * best[1] > 0) || !(best_r > 0))
        return false;
    *c = m_atan2(best[0], best[1]);
    *e = m_atan2(best[2], best[3]);
    return true;
}

/* One pass's observations into the workspace (pm_fit_add each). */
static pm_status add_pass(pm_fit *fit, const pm_context *ctx, long n, const double *enc_ha,
                          const double *enc_dec, const double *app_ha, const double *app_dec)
{
    for (long i = 0; i < n; i++) {
        pm_status st = pm_fit_add(fit, ctx ? ctx + i : 0, enc_ha[i], enc_dec[i], app_ha[i],
                                  app_dec[i]);
        if (st != PM_OK)
            return st;
    }
    return PM_OK;
}

/* Gauss-Newton from *m (the loop of pm_fit_run), m updated in place: PM_OK
** with *m the converged model and *r its statistics. */
static pm_status run_from(pm_fit *fit, pm_model *m, const pm_context *ctx, long n,
                          const double *enc_ha, const double *enc_dec, const double *app_ha,
                          const double *app_dec, int max_iter, pm_fit_result *r)
{
    pm_status st = pm_fit_init(fit, m);
    if (st != PM_OK)
        return st;
    __builtin_memset(r, 0, sizeof *r);
    for (int it = 0; it < max_iter; it++) {
        st = add_pass(fit, ctx, n, enc_ha, enc_dec, app_ha, app_dec);
        if (st != PM_OK)
            return st;
        st = pm_fit_solve(fit, m, r);
        if (st != PM_OK)
            return st;
        if (r->converged) {
            /* The last accepted pass solved at the point before its step:
            ** its covariance, chi^2 and sigma are that point's, not the
            ** returned model's.  Where it took a step, one more pass takes
            ** them at the returned model, which it does not move (pm.h,
            ** pm_fit_run Note 2: an ill-conditioned fit's predicted error
            ** at its stars was 6.2" for sigma 1.39", 1.19" at its own
            ** point). */
            bool stepped = false;
            for (int i = 0; i < fit->n_par; i++)
                stepped = stepped || fit->step[i] != 0;
            if (!r->accepted || !stepped)
                return PM_OK;
            st = add_pass(fit, ctx, n, enc_ha, enc_dec, app_ha, app_dec);
            if (st != PM_OK)
                return st;
            st = solve(fit, m, r, true);
            if (st != PM_OK)
                fit->cov_valid = 0;
            return st;
        }
    }
    return PM_ERR_DIVERGED;
}

/* The order-0 fit (the six isotropic terms alone) of the observations from
** the six of start, in the scratch model *s: its six into out, at their
** alias with d and i within 90 deg (an order-0 fit's two are the same fit;
** the order-L fit from either is not, and rounding had chosen between
** them: an outside probe's fits from the other came back with i -180 deg
** and a worse chi^2), its statistics into *r.  The seeds of pm_fit_run's
** starts (in the caller's scratch model and result: the stack of one run). */
static pm_status order0_fit(pm_fit *fit, const pm_model *model, const double *start,
                            const pm_context *ctx, long n, const double *enc_ha,
                            const double *enc_dec, const double *app_ha, const double *app_dec,
                            int max_iter, pm_model *s, double *out, pm_fit_result *r)
{
    pm_status st = pm_model_init(s, model->mount, 0);
    if (st != PM_OK)
        return st;
    s->latitude = model->latitude;
    for (int i = 0; i < 6; i++)
        s->coef[i] = start[i];
    if ((st = pm_model_prepare(s)) != PM_OK ||
        (st = run_from(fit, s, ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter, r)) != PM_OK)
        return st;
    for (int i = 0; i < 6; i++)
        out[i] = s->coef[i];
    canonical_alias(out);
    return PM_OK;
}

/* *s: the caller's model with the six isotropic terms of start k (k = 0:
** the caller's own), prepared. */
static pm_status start_model(const pm_model *model, const double (*iso)[6], int k,
                             pm_model *s)
{
    *s = *model;
    if (k == 0)
        return PM_OK;
    for (int i = 0; i < 6; i++)
        s->coef[i] = iso[k][i];
    return pm_model_prepare(s);
}

pm_status pm_fit_run(pm_fit *fit, pm_model *model, const pm_context *ctx,
                     long n, const double *enc_ha, const double *enc_dec,
                     const double *app_ha, const double *app_dec,
                     int max_iter, pm_fit_result *res)
{
    if (!fit || !model || !enc_ha || !enc_dec || !app_ha || !app_dec ||
        n < 0 || max_iter < 1)
        return PM_ERR_ARG;
    pm_status st = pm_fit_init(fit, model);
    if (st != PM_OK)
        return st;
    /* The starts (pm.h, Note 1): the caller's model; where it has no index
    ** terms and the offsets put one beyond PM_FIT_INDEX_START, the
    ** offsets' (index_start), and for a model beyond the six isotropic
    ** terms the six of the better order-0 fit from these two (a few runs
    ** of 12-20 stars near the pole with index errors of tens of degrees
    ** still stopped short at order 1 from the offsets alone).  The fit of
    ** least chi^2 is returned.  (Six coefficients a start and one model on
    ** the stack: firmware refits.) */
    double iso[4][6];
    int n_start = 1;
    for (int i = 0; i < 6; i++)
        iso[0][i] = model->coef[i];
    double c0, e0;
    if (model->coef[2] == 0 && model->coef[4] == 0 &&
        index_start(model, n, enc_ha, enc_dec, app_ha, app_dec, &c0, &e0) &&
        (m_fabs(c0) > PM_FIT_INDEX_START || m_fabs(e0) > PM_FIT_INDEX_START)) {
        for (int i = 0; i < 6; i++)
            iso[1][i] = model->coef[i];
        iso[1][2] = c0;
        iso[1][4] = e0;
        n_start = 2;
    }
    pm_model s;
    pm_fit_result r;
    const int n_index = n_start;
    double iso_chi2 = 0;
    for (int k = 0; k < n_index && n_index > 1 && model->n_terms > 6; k++) {
        double six[6];
        if (order0_fit(fit, model, iso[k], ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter,
                       &s, six, &r) != PM_OK ||
            (n_start > n_index && !(r.chi2 < iso_chi2)))
            continue;
        for (int i = 0; i < 6; i++)
            iso[n_index][i] = six[i];
        iso_chi2 = r.chi2;
        n_start = n_index + 1;
    }
    /* A cold start with no index start: the order-0 fit from it, whose six
    ** are a start of their own where the model's fit ends above its chi^2
    ** (the model holds order 0, so at its least-squares fit chi^2 is no
    ** larger: above it, the fit stopped in a false minimum; an outside
    ** probe's German runs beyond the pole with c' near 180 deg ended at
    ** 8,142" with PM_OK at order 1, 2.77" at order 0).  (An order-0 fit
    ** costs a fraction of the model's; a refit from a model pays nothing.) */
    bool seed0 = false;
    double chi2_0 = 0;
    int n_cold = 0;
    for (int i = 0; i < 6; i++)
        n_cold += iso[0][i] == 0;
    if (n_index == 1 && model->n_terms > 6 && n_cold == 6 &&
        order0_fit(fit, model, iso[0], ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter, &s,
                   iso[n_start], &r) == PM_OK) {
        chi2_0 = r.chi2;
        seed0 = true;
    }
    pm_status first = PM_ERR_DIVERGED;
    double best_chi2 = 0;
    int best = -1, last = -1;
    for (int k = 0; k < n_start + (seed0 ? 1 : 0); k++) {
        if (k == n_start && best >= 0 && !(best_chi2 > chi2_0 * (1 + 1e-9)))
            break; /* (the seed of order 0, only where the fit ended above it) */
        if (start_model(model, iso, k, &s) != PM_OK)
            continue;
        st = run_from(fit, &s, ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter, &r);
        last = k;
        if (k == 0)
            first = st;
        /* (a later start must be better beyond rounding: two starts that
        ** reach the same fit, or its alias a turn away, keep the first) */
        if (st == PM_OK && (best < 0 || r.chi2 < best_chi2 * (1 - 1e-9))) {
            best = k;
            best_chi2 = r.chi2;
        }
    }
    if (seed0 && last == n_start)
        n_start++; /* (the seed ran: the alias's slot is after it) */
    /* the workspace, *model and *res as the chosen start's fit leaves them
    ** (its passes again where another start ran after it); on no success,
    ** the caller's start's status (fit->bad_term its) */
    const int k = best < 0 ? 0 : best;
    if (k != last) {
        start_model(model, iso, k, &s); /* (prepared before, so PM_OK) */
        st = run_from(fit, &s, ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter, &r);
    }
    if (best < 0)
        return first;
    /* The alias (pm.h, Note 3): where the fit came to a collimation or a
    ** non-perpendicularity beyond 90 deg from a start within it (a fork
    ** whose HA encoder read 180 deg off: e' 180 deg and i -180 deg, which
    ** TPOINT's CH cannot mean; an alt-az azimuth 180 deg off: d -180 deg;
    ** outside probes), once more from the alias of its six isotropic terms
    ** with both within 90 deg, whose sides are the encoders' (the other
    ** put a fork's every star beyond the pole, and the inverse's normal
    ** side there).  Kept where that fit converges, its d and i within 90
    ** deg, and at order 0 where its chi^2 is no larger beyond rounding (the
    ** same pointing); at higher orders the aliases are different models and
    ** the other's chi^2 may be a little lower (a fork's 1.10" against
    ** 1.12").  A caller's start beyond 90 deg keeps its alias (a refit
    ** from an old model: compare). */
    double a0[6];
    for (int i = 0; i < 6; i++)
        a0[i] = wrap_pi(model->coef[i]);
    double *a = iso[n_start];
    for (int i = 0; i < 6; i++)
        a[i] = s.coef[i];
    if (!canonical_alias(a0) && canonical_alias(a)) {
        const double chi2 = r.chi2;
        pm_fit_result ra;
        if (start_model(model, iso, n_start, &s) == PM_OK &&
            run_from(fit, &s, ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter, &ra) == PM_OK &&
            m_fabs(s.coef[3]) <= PI / 2 && m_fabs(s.coef[5]) <= PI / 2 &&
            (model->n_terms > 6 || ra.chi2 <= chi2 * (1 + 1e-9))) {
            r = ra;
        } else {
            start_model(model, iso, k, &s);
            run_from(fit, &s, ctx, n, enc_ha, enc_dec, app_ha, app_dec, max_iter, &r);
        }
    }
    *model = s;
    if (res)
        *res = r;
    return PM_OK;
}

/* The checks of pm_fit_pointing_sigma and pm_fit_point_gain: a solved fit
** of m's terms, a finite position. */
static pm_status prediction_ready(const pm_fit *fit, const pm_model *m, double enc_ha,
                                  double enc_dec)
{
    if (fit->state != FIT_READY || fit->iterations < 1 || !fit->cov_valid)
        return PM_ERR_STATE;
    if (m->n_terms != fit->n_par)
        return PM_ERR_ARG;
    if (model_ready(m) != PM_OK || !terms_intact(m))
        return PM_ERR_STATE; /* before pm_model_apply, which does not look at the terms */
    if (!finite(enc_ha) || !finite(enc_dec))
        return PM_ERR_NONFINITE;
    return PM_OK;
}

/* The two rows of m at an encoder position, at the model's own prediction. */
static pm_status rows_at(const pm_model *m, const pm_context *ctx, double enc_ha, double enc_dec,
                         double *row0, double *row1)
{
    double app_ha, app_dec, r[2];
    pm_status st = pm_model_apply(m, ctx, enc_ha, enc_dec, &app_ha, &app_dec);
    return st != PM_OK ? st : pm_fit_row(m, ctx, enc_ha, enc_dec, app_ha, app_dec, row0, row1, r);
}

pm_status pm_fit_pointing_sigma(const pm_fit *fit, const pm_fit_result *res,
                                const pm_model *m, const pm_context *ctx, double enc_ha,
                                double enc_dec, double *sigma, double cov[3])
{
    if (!fit || !res || !m || !sigma)
        return PM_ERR_ARG;
    double row0[PM_MAX_TERMS], row1[PM_MAX_TERMS];
    pm_status st = prediction_ready(fit, m, enc_ha, enc_dec);
    if (st == PM_OK)
        st = rows_at(m, ctx, enc_ha, enc_dec, row0, row1);
    if (st != PM_OK)
        return st;
    /* J C J^T over the packed lower triangle: each off-diagonal element
    ** twice */
    const int P = fit->n_par;
    double v00 = 0, v01 = 0, v11 = 0;
    for (int i = 0; i < P; i++) {
        for (int j = 0; j < i; j++) {
            double c = fit->cov[pidx(i, j)];
            v00 += 2 * row0[i] * c * row0[j];
            v01 += c * (row0[i] * row1[j] + row1[i] * row0[j]);
            v11 += 2 * row1[i] * c * row1[j];
        }
        double c = fit->cov[pidx(i, i)];
        v00 += row0[i] * c * row0[i];
        v01 += row0[i] * c * row1[i];
        v11 += row1[i] * c * row1[i];
    }
    double s2 = res->sigma * res->sigma;
    v00 *= s2;
    v01 *= s2;
    v11 *= s2;
    /* rows or a covariance of 1e150 and more overflow the product */
    if (!finite(v00) || !finite(v01) || !finite(v11))
        return PM_ERR_NONFINITE;
    double v = 0.5 * (v00 + v11);
    *sigma = v > 0 ? m_sqrt(v) : 0.0;
    if (cov) {
        cov[0] = v00;
        cov[1] = v01;
        cov[2] = v11;
    }
    return PM_OK;
}

pm_status pm_fit_point_gain(const pm_fit *fit, const pm_fit_result *res, const pm_model *m,
                            const pm_context *ctx, double enc_ha, double enc_dec,
                            const double *sky, int n_sky, double *gain)
{
    if (!fit || !res || !m || !sky || n_sky < 1 || !gain)
        return PM_ERR_ARG;
    double j0[PM_MAX_TERMS], j1[PM_MAX_TERMS];
    pm_status st = prediction_ready(fit, m, enc_ha, enc_dec);
    if (st == PM_OK)
        st = rows_at(m, ctx, enc_ha, enc_dec, j0, j1);
    if (st != PM_OK)
        return st;
    const int P = fit->n_par;
    const double s2 = res->sigma * res->sigma;
    /* M = C J^T (P x 2), C = sigma^2 (J^T J)^-1 from the packed triangle */
    double m0[PM_MAX_TERMS], m1[PM_MAX_TERMS];
    for (int i = 0; i < P; i++) {
        double a = 0, b = 0;
        for (int j = 0; j < P; j++) {
            double c = fit->cov[i >= j ? pidx(i, j) : pidx(j, i)] * s2;
            a += c * j0[j];
            b += c * j1[j];
        }
        m0[i] = a;
        m1[i] = b;
    }
    /* S = sigma^2 I + J M, and its inverse */
    double s00 = s2, s01 = 0, s10 = 0, s11 = s2;
    for (int i = 0; i < P; i++) {
        s00 += j0[i] * m0[i];
        s01 += j0[i] * m1[i];
        s10 += j1[i] * m0[i];
        s11 += j1[i] * m1[i];
    }
    double det = s00 * s11 - s01 * s10;
    if (!finite(det))
        return PM_ERR_NONFINITE;
    if (!(det > 0))
        return PM_ERR_SINGULAR;
    double i00 = s11 / det, i01 = -s01 / det, i10 = -s10 / det, i11 = s00 / det;
    double sum = 0;
    for (int g = 0; g < n_sky; g++) {
        double th = sky[2 * g], dh = sky[2 * g + 1], g0[PM_MAX_TERMS], g1[PM_MAX_TERMS];
        if (!finite(th) || !finite(dh))
            return PM_ERR_NONFINITE;
        st = rows_at(m, ctx, th, dh, g0, g1);
        if (st != PM_OK)
            return st;
        /* U = J_g M (2 x 2); the fall tr(U S^-1 U^T) / 2 */
        double u00 = 0, u01 = 0, u10 = 0, u11 = 0;
        for (int i = 0; i < P; i++) {
            u00 += g0[i] * m0[i];
            u01 += g0[i] * m1[i];
            u10 += g1[i] * m0[i];
            u11 += g1[i] * m1[i];
        }
        sum += 0.5 * (u00 * (i00 * u00 + i01 * u01) + u01 * (i10 * u00 + i11 * u01) +
                      u10 * (i00 * u10 + i01 * u11) + u11 * (i10 * u10 + i11 * u11));
    }
    if (!finite(sum))
        return PM_ERR_NONFINITE; /* an overflow of the products (huge rows or covariance) */
    *gain = sum / n_sky;
    return PM_OK;
}

pm_status pm_fit_covariance(const pm_fit *fit, const pm_fit_result *res,
                            int i, int j, double *cov, double *corr)
{
    if (!fit || !res || !cov)
        return PM_ERR_ARG;
    if (fit->state != FIT_READY || fit->iterations < 1 || !fit->cov_valid)
        return PM_ERR_STATE;
    if (i < 0 || j < 0 || i >= fit->n_par || j >= fit->n_par)
        return PM_ERR_ARG;
    int a = i > j ? i : j, b = i > j ? j : i;
    double c = fit->cov[pidx(a, b)];
    *cov = c * res->sigma * res->sigma;
    if (corr) {
        double d = fit->cov[pidx(a, a)] * fit->cov[pidx(b, b)];
        *corr = d > 0 ? c / m_sqrt(d) : 0.0;
    }
    return PM_OK;
}

pm_status pm_fit_row(const pm_model *m, const pm_context *ctx, double enc_ha,
                     double enc_dec, double app_ha, double app_dec,
                     double *row0, double *row1, double r[2])
{
    pm_status st = model_ready(m);
    if (st == PM_OK && !terms_intact(m))
        st = PM_ERR_STATE; /* a term changed since pm_model_prepare */
    if (st == PM_OK)
        st = context_ok(m, ctx);
    if (st != PM_OK)
        return st;
    if (!row0 || !row1 || !r)
        return PM_ERR_ARG;
    if (!finite(enc_ha) || !finite(enc_dec) || !finite(app_ha) ||
        !finite(app_dec))
        return PM_ERR_NONFINITE;
    rows(m, ctx, enc_ha, enc_dec, app_ha, app_dec, row0, row1, r);
    if (!finite(r[0]) || !finite(r[1]))
        return PM_ERR_NONFINITE; /* the terms overflow here */
    return PM_OK;
}

} /* extern "C" */
