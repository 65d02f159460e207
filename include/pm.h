/*
**  pm.h - telescope pointing model: the public ANSI C (C89) interface.
**
**  A freestanding, allocation-free implementation of the isotropic and
**  anisotropic pointing models of Pal, Vida, Meszaros & Mezo,
**  "Isotropic and anisotropic pointing models", Exp Astron (2016).
**
**  Conventions
**  -----------
**  - Angles are radians.  The two mount axes are called (ha, dec) after the
**    equatorial case; for an alt-az mount pass azimuth as "ha" and elevation
**    as "dec" (see docs/model.md for the sign and zero-point conventions).
**  - "Encoder" positions are the raw axis readings; "apparent" positions are
**    where the telescope really points (the star's observed place).
**  - An encoder dec beyond +-pi/2 means the telescope is flipped over the
**    pole (German equatorial mount on the other pier side).
**  - Encoder angles are modular: every function takes any finite encoder
**    angle on either axis (a flipped mount's 194.17 deg as well as
**    -165.83 deg, a controller's 0..2pi), and angles a turn apart give the
**    same result to the rounding of 2pi, with one deliberate exception: a
**    periodic term of non-integer G reads the angle on the mount's own
**    turn (docs/model.md).  The host readers reduce the angles of a file
**    into (-pi, pi] exactly, in degrees (docs/formats.md).
**  - The caller owns every struct.  All structs are fully defined here so
**    that they can be allocated statically; their sizes depend on the
**    capacity macros PM_MAX_L, PM_MAX_EXTRA and PM_MAX_AUX, which must be
**    the same when the library and the caller are compiled
**    (PM_CHECK_CONFIG() verifies).
**  - Every function returns a pm_status.  PM_OK is 0, positive values are
**    warnings with a usable result, negative values are errors; on error the
**    outputs are left unchanged.
*/
#ifndef PM_H
#define PM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------- */
/* Capacities (compile-time).                                             */
/* ---------------------------------------------------------------------- */

/* Highest spherical-harmonic order L the structs can hold. */
#ifndef PM_MAX_L
#define PM_MAX_L 4
#endif

/* Room for terms beyond the spherical-harmonic set (reserved for the
** physical terms: periodic error, refraction, flexure, auxiliary inputs). */
#ifndef PM_MAX_EXTRA
#define PM_MAX_EXTRA 16
#endif

/* The model's definition (what a set of coefficients means): 3 since every
** anisotropic term (its harmonics and its base vector) is evaluated at the
** index-shifted, mechanical position (docs/model.md, "The anisotropic
** terms: at the mechanical position"; 2: only the tilts were); model files
** say "pm-model 3" and the headers of pmfit --emit-c refuse to compile
** against another. */
#define PM_MODEL_DEFINITION 3

/* Free parameters of the harmonic model of order L: 4L^2+12L+6
** (6, 22, 46, 78, 118 for L = 0..4; Pal et al. Sec. 3.1 and 5.1). */
#define PM_SH_TERMS(L) (4 * (L) * (L) + 12 * (L) + 6)

/* Number of (l,m) harmonics up to order L: (L+1)^2. */
#define PM_N_HARM(L) (((L) + 1) * ((L) + 1))

/* Most terms a model or fit can hold. */
#define PM_MAX_TERMS (PM_SH_TERMS(PM_MAX_L) + PM_MAX_EXTRA)

/* Packed symmetric matrix of n x n: n(n+1)/2 doubles. */
#define PM_PACKED(n) ((n) * ((n) + 1) / 2)

/* Hard iteration bounds of pm_model_invert (see its Notes 1 and 2), in
** model evaluations (each about one pm_model_apply, the Jacobian
** included): the closed form's fixed point on one branch, the Newton
** iteration that takes over where it does not converge (it also gets the
** evaluations the fixed point left), the points of the ring round the
** mount's pole the pole rescue samples, the Newton runs it makes from the
** best starts they give and their length. */
#define PM_INVERT_MAX_FIXED 4
#define PM_INVERT_MAX_NEWTON 9
#define PM_INVERT_POLE_STARTS 12
#define PM_INVERT_POLE_RUNS 3
#define PM_INVERT_POLE_NEWTON 12
/* Worst-case model evaluations per call, whatever the inputs:
** pm_model_invert_near one branch, fixed point then Newton (13);
** pm_model_invert two branches, then the pole rescue (2 x 13 + 12 +
** 3 x 12 = 74).  pm_model_apply makes exactly one.  tests/check_bounded.c
** counts them on adversarial inputs. */
#define PM_INVERT_NEAR_MAX_EVALS (PM_INVERT_MAX_FIXED + PM_INVERT_MAX_NEWTON)
#define PM_INVERT_MAX_EVALS \
    (2 * (PM_INVERT_MAX_FIXED + PM_INVERT_MAX_NEWTON) + PM_INVERT_POLE_STARTS + \
     PM_INVERT_POLE_RUNS * PM_INVERT_POLE_NEWTON)

/* Tracking bound: pm_model_invert_near for a target more than 0.5 deg from
** the mount's pole, started from the previous tick's solution (up to 0.1 s
** of sidereal motion before: ticks of 10 Hz or faster), with isotropic
** terms within 10 deg and harmonic terms of order L <= 2 within 10' each
** (AUX terms allowed): at most this many
** model evaluations (pm_model_invert Note 1 gives the reasons; measured
** worst 4 in tests/check_bounded.c's tracking calls, which asserts both:
** every call within 8, the worst within 4). */
#define PM_INVERT_TRACK_MAX_EVALS 8

/* Round-trip tolerance the inverse iterates to (radians). */
#define PM_INVERT_TOL 1e-13

/* Per-call budgets for firmware (worst cases; instructions as counted by
** QEMU, not cycles: docs/performance.md).  Measured by "make bench"
** (build/bench/results.txt, "per situation"; bench/dist.h), L = 2, gcc
** 12 -O2, the library at PM_MAX_L = 4:
**   tracking beyond 0.5 deg of the mount's pole, 10 Hz or faster, terms
**   within 10 deg / 10' (PM_INVERT_TRACK_MAX_EVALS): the Cortex-M7
**   double inverse took at most 4,085 instructions, at its worst measured
**   3 evaluations (stop 28; 4,020 at 4 at stop 25, 3,595 at 3 before the
**   anisotropic terms moved
**   to the mechanical position, 3,575 before the code moved with pm_model_track,
**   3,565 before solve_branch was split into functions,
**   3,640 before the typical iteration's lean loop, 3,870 before the
**   Jacobian's sums were fused).  The bench's situations hold no tick
**   that needs Newton; the dearest measured at all ("make
**   bench-track-worst": check_bounded's 8,000 steady-state ticks, half of
**   them 0.5-5 deg from the pole) are 7,360 (invert_near) and 7,640
**   instructions (pm_model_track) at 3 and 4 evaluations, 0.555 deg from
**   the pole, where the chord's matrix is singular and Newton on the
**   forward model starts at once (~1,800 instructions a trial point
**   there; 8,840 and 8,600 at 6 evaluations before stop 28, when plain
**   steps came first).  As such a tick may spend every evaluation up to
**   the bound of 8 on Newton's trial points, PM_BUDGET_M7_TRACK_INSNS is
**   2,000 + 8 x PM_BUDGET_M7_INSNS_PER_EVAL = 22,000 (until stop 28
**   16,095: the typical 3,595 and 5 evaluations more, which a tick with
**   Newton from its first evaluation could pass).
**   pm_model_track's ticks, under the bench's conditions: at most 3,370
**   instructions measured (2 evaluations; 6,890 at 6 before the next
**   evaluation took J afresh where a carried one converges slowly, Note 1
**   of pm_model_track; its typical tick ~1,900 against
**   invert_near's ~2,700); its bound is invert_near's, and so its budget.
**   PM_BUDGET_M7_INSNS_PER_EVAL: an evaluation of the Newton iteration
**   (the displacement with its Jacobian, sin/cos of the point, the
**   rotations and their first and second derivatives, the step's
**   singular directions) is the dearest kind: the worst measured call of
**   a harmonic L = 2 model near the pole (90,380 instructions, at most 41
**   evaluations; 90,525 and 98,400 before) is within 2,000 + 41 x 2,350; 2,500 leaves room for a
**   call that takes that count with fewer evaluations (the bench does not
**   pair them).  So a call of pm_model_invert_near stays within 2,000 +
**   13 x 2,500 instructions, one of pm_model_invert within 2,000 + 74 x
**   2,500 (harmonic and AUX terms at L = 2; added periodic or zenith
**   terms cost more).
**   The float build on the Cortex-M4F (pm_model_invert_near_f): at most
**   PM_INVERT_F_MAX_EVALS evaluations; PM_BUDGET_M4F_F_INSNS_PER_EVAL the
**   most one costs (2,926 measured near the pole).  It is no faster than
**   the double build's bound near the pole or with isotropic terms of
**   degrees (its inverse fails to converge there more often:
**   pm_model_invert_f Note 3). */
#define PM_BUDGET_M7_INSNS_PER_EVAL 2500
#define PM_BUDGET_M7_TRACK_INSNS (2000 + PM_INVERT_TRACK_MAX_EVALS * PM_BUDGET_M7_INSNS_PER_EVAL)
#define PM_BUDGET_M4F_F_INSNS_PER_EVAL 3000

/* ---------------------------------------------------------------------- */
/* Status.                                                                */
/* ---------------------------------------------------------------------- */

typedef enum pm_status {
    PM_OK = 0,
    PM_WARN_NOT_CONVERGED = 1, /* iteration bound reached; best result returned */
    PM_WARN_UNREACHABLE = 2,   /* target outside what the mount can point to;
                                  the nearest reachable position is returned */
    PM_ERR_ARG = -1,           /* NULL pointer, bad enum or index */
    PM_ERR_NONFINITE = -2,     /* NaN or infinity in an input, or an
                                  evaluation overflowed (huge coefficients
                                  or context values; the float build at
                                  3e38): nothing is written */
    PM_ERR_CAPACITY = -3,      /* order or term count beyond PM_MAX_L/PM_MAX_TERMS */
    PM_ERR_TOO_FEW = -4,       /* not enough observations: need 2N > P */
    PM_ERR_SINGULAR = -5,      /* a term cannot be determined from the data;
                                  pm_fit.bad_term names it */
    PM_ERR_STATE = -6,         /* call out of order (e.g. model changed and
                                  not re-prepared, fit not initialised) */
    PM_ERR_CONFIG = -7,        /* caller and library built with different
                                  capacity macros */
    PM_ERR_DIVERGED = -8       /* the fit did not converge */
} pm_status;

/* ---------------------------------------------------------------------- */
/* Model.                                                                 */
/* ---------------------------------------------------------------------- */

/* Mount kinds. */
#define PM_MOUNT_EQUATORIAL 0
#define PM_MOUNT_ALTAZ 1

/* Term kinds (docs/model.md, "Physical terms").  All but the six
** isotropic ones are tangent-plane displacements, linear in their
** coefficient. */
#define PM_TERM_SH 0       /* a_klm Y_lm p_k (Pal et al. Eq. pyyexpansion) */
#define PM_TERM_FOURIER 1  /* coef * trig(param * theta) * p_k: theta the raw
                              angle of axis l (1 or 2), trig = cos (m = 0) or
                              sin (m = 1), param = cycles per revolution
                              (periodic gear error; non-integer allowed) */
#define PM_TERM_SECTORAL 2 /* the paper's Y_{G,G} p_k (m = 0) or Y_{G,-G} p_k
                              (m = 1) with G = param: cos^G(dec) * trig(G ha),
                              kept to compare with PM_TERM_FOURIER */
#define PM_TERM_ZENITH 3   /* displacement toward the zenith: l = 0:
                              coef * cot(el) (refraction-like), l = 1:
                              coef * cos(el) (tube flexure) */
#define PM_TERM_AUX 4      /* coef * (input - param) * p_k, input chosen by
                              aux (PM_AUX_*) from the pm_context */

/* Inputs of PM_TERM_AUX (pm_term.aux). */
#define PM_AUX_TEMP 0  /* pm_context.temp_c */
#define PM_AUX_TIME 1  /* pm_context.time_h */
#define PM_AUX_DIR 2   /* pm_context.dir (+1/-1) */
#define PM_AUX_USER 3  /* PM_AUX_USER + j: pm_context.aux[j] */

/* User inputs in a pm_context (its size: the same in the library and the
** caller, PM_CHECK_CONFIG()). */
#ifndef PM_MAX_AUX
#define PM_MAX_AUX 4
#endif

/* Base vectors k = 1..6 of Pal et al. Eq. (tdvectexpansion). */
#define PM_BASE_A 1 /* polar axis misalignment, a (TPOINT: MA-like)  */
#define PM_BASE_B 2 /* polar axis misalignment, b (TPOINT: ME-like)  */
#define PM_BASE_C 3 /* hour-angle encoder index, c' (TPOINT: IH)     */
#define PM_BASE_D 4 /* axis non-perpendicularity, d (TPOINT: NP)     */
#define PM_BASE_E 5 /* declination encoder index, e' (TPOINT: ID)    */
#define PM_BASE_I 6 /* collimation, i (TPOINT: CH)                   */

/* Pier sides / which solution the inverse returns: on which side of the
** mount's pole the encoder declination lies (the pole is at encoder
** dec - e' = +-pi/2). */
#define PM_SIDE_NORMAL 0  /* cos(enc_dec - e') >= 0 */
#define PM_SIDE_FLIPPED 1 /* cos(enc_dec - e') < 0: beyond the pole */

/* One term of the model. */
typedef struct pm_term {
    unsigned char kind; /* PM_TERM_* */
    unsigned char k;    /* base vector 1..6 (PM_BASE_*); unused by ZENITH */
    signed char l;      /* SH: degree 0..PM_MAX_L; FOURIER: axis 1 or 2;
                           ZENITH: 0 cot(el), 1 cos(el) */
    signed char m;      /* SH: order -l..l (m<0: sin|m|tau); FOURIER,
                           SECTORAL: 0 cos, 1 sin */
    signed char side;   /* 0 both pier sides; +1 normal side only; -1 only
                           beyond the pole (PM_SIDE_* of the observation) */
    unsigned char aux;  /* AUX: PM_AUX_* input */
    double param;       /* FOURIER: cycles per revolution; SECTORAL: G;
                           AUX: reference value of the input */
} pm_term;

/* Per-evaluation inputs that some terms use (temperature, time, pier side,
** slew direction, user columns).  Pass NULL where no term needs them: the
** harmonic, periodic and zenith terms need none; PM_TERM_AUX terms make a
** NULL context an error (PM_ERR_ARG). */
typedef struct pm_context {
    double temp_c;          /* ambient temperature (deg C) */
    double time_h;          /* time (hours, any zero point) */
    int pier;               /* +1 normal side (east), -1 beyond the pole
                               (west), 0: from the encoder dec (other
                               values: by their sign) */
    int dir;                /* last slew direction on axis 1: +1, -1, 0
                               (another value is PM_ERR_ARG where a term
                               reads it: not a velocity or a step count) */
    double aux[PM_MAX_AUX]; /* user inputs (PM_AUX_USER + j) */
} pm_context;

/* A pointing model: the term list, the coefficients (radians) and derived
** constants filled in by pm_model_prepare.  The first six terms are always
** the isotropic ones (a, b, c', d, e', i), applied exactly as rotations;
** the others are tangent-plane displacements (docs/model.md). */
typedef struct pm_model {
    int mount;                     /* PM_MOUNT_* */
    int order;                     /* spherical-harmonic order L */
    int n_terms;                   /* P */
    int n_base;                    /* the first n_base terms are the
                                      harmonic set of pm_model_init; the
                                      rest were added (pm_model_add_term) */
    double latitude;               /* site latitude (radians), needed by
                                      ZENITH terms on equatorial mounts */
    int needs_ctx;                 /* derived: some term reads pm_context */
    pm_term term[PM_MAX_TERMS];    /* set by pm_model_init and
                                      pm_model_add_term; after changing it
                                      (or n_terms, n_base, order, mount)
                                      by hand, call pm_model_prepare before
                                      any other use: otherwise undefined
                                      (pm_model_prepare Note 2) */
    double coef[PM_MAX_TERMS];     /* radians */
    /* Derived by pm_model_prepare; do not set by hand. */
    int prepared;
    double prep_coef[PM_MAX_TERMS]; /* coef[] when prepared (staleness check) */
    double h[9];                   /* polar-axis rotation H, row-major */
    double sc, cc, se, ce;         /* sin/cos of c' and e' */
    double sd, cd, si, ci;         /* sin/cos of d and i */
    double lip;                    /* bound on the change of the
                                      anisotropic displacement per radian
                                      of either axis angle, AUX inputs
                                      aside; infinite if |d|, |i| or the
                                      polar offset exceed 0.5 rad
                                      (pm_model_invert, Note 4) */
    double lip2;                   /* bound on the second derivative of
                                      the harmonic displacement per
                                      radian^2 (pm_model_invert, Note 1);
                                      infinite where the inverse does not
                                      predict its stop */
    double dense[PM_N_HARM(PM_MAX_L)][6]; /* per harmonic, per base vector k */
    unsigned long ident[2];        /* two 32-bit digests of the prepared
                                      model (mount, order, latitude,
                                      terms, coefficients): pm_model_track
                                      keeps a Jacobian only for the model
                                      it was taken with */
} pm_model;

/*
**  pm_model_init - an empty model of the given mount and harmonic order.
**
**  Given:
**     m        pm_model*   model to fill
**     mount    int         PM_MOUNT_EQUATORIAL or PM_MOUNT_ALTAZ
**     order    int         spherical-harmonic order L, 0..PM_MAX_L
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_CAPACITY (order)
**  Notes:
**  1) The term list holds the 4L^2+12L+6 linearly independent terms
**     a_klm Y_lm p_k, k = 1..6, l = 0..L, |m| <= l, in the order l, m, k,
**     with the dependent ones removed (Note 2).  All coefficients are 0.
**  2) Dropped for every L (docs/model.md derives the rule):
**     k=6 (i) with l >= 1 and |m| <= l-1     (relations like Eq. l1lin1)
**     k=1 (a) with l >= 1 and m >= 1         (relations like Eq. l1lin2)
**     k=2 (b) with l >= 2 and m >= 2
**     For L = 1 and 2 these are the paper's choices (Sec. 3.1).
**  Reference: Pal et al., Sec. 3, Eq. (pyyexpansion).
*/
pm_status pm_model_init(pm_model *m, int mount, int order);

/*
**  pm_model_prepare - derive the constants used by apply/invert.
**
**  Given/Returned:
**     m        pm_model*   model whose coef[] were set or changed
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_NONFINITE (a coefficient
**                          not finite, or |a|, |b| beyond ~1e154 rad, where
**                          the polar-axis rotation overflows); PM_ERR_CAPACITY
**  Notes:
**  1) pm_model_init and pm_fit_solve leave the model prepared.  After
**     changing coef[] directly, call this again: apply, invert and the
**     fit return PM_ERR_STATE if any coefficient differs from the ones
**     last prepared, bit for bit (never a silently stale model).
**  2) After changing term[] (or n_terms, n_base, order or mount) directly,
**     call this again before any other use of the model.  Changing them
**     and then calling anything else without preparing again is
**     undefined: the evaluations (pm_model_apply, pm_model_invert,
**     pm_model_invert_near, pm_model_track, pm_model_residual) do not look
**     at the terms (it would cost every tick), and a term this function
**     would refuse (l beyond the order, an AUX input beyond PM_MAX_AUX) is
**     read out of bounds there.  The calls outside that path never read
**     such a term: pm_model_f_prepare, pm_fit_init (so pm_fit_run),
**     pm_fit_row, pm_fit_pointing_sigma and pm_fit_point_gain return
**     PM_ERR_STATE for a prepared model whose shape or terms this function
**     would now refuse (a term changed into another valid one goes
**     unnoticed there too), pm_term_name PM_ERR_ARG for such a term.
**  3) On error the model is left unprepared: every evaluation returns
**     PM_ERR_STATE until a pm_model_prepare succeeds.
*/
pm_status pm_model_prepare(pm_model *m);

/*
**  pm_model_add_term - append a term (a physical term, or a harmonic term
**  restricted to one pier side) to a model.
**
**  Given/Returned:
**     m        pm_model*       model (from pm_model_init)
**  Given:
**     t        const pm_term*  the term (kind and fields as in pm_term)
**     value    double          its coefficient (radians; for AUX radians
**                              per unit of the input)
**  Returned:
**     index    int*            its index (may be NULL)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG (invalid term: bad kind, base
**                          vector, axis, side or input; ZENITH on an
**                          equatorial mount whose latitude is not set is
**                          accepted, m->latitude is used as it is);
**                          PM_ERR_CAPACITY (PM_MAX_TERMS reached);
**                          PM_ERR_NONFINITE
**  Notes:
**  1) The model is prepared again.  Harmonic terms (PM_TERM_SH) added here
**     may have any l <= m->order, including 0, and apply as tangent-plane
**     displacements; with side != 0 they give the "joint fit with
**     side-specific terms" of docs/model.md.
*/
pm_status pm_model_add_term(pm_model *m, const pm_term *t, double value,
                            int *index);

/*
**  pm_model_find - index of a harmonic term in the model.
**
**  Given:
**     m        const pm_model*  model
**     k,l,mm   int              base vector, degree, order
**  Returned:
**     index    int*             index into term[]/coef[]
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG (not in the model)
*/
pm_status pm_model_find(const pm_model *m, int k, int l, int mm, int *index);

/*
**  pm_term_name - a short name for a term, e.g. "c'", "d*Y(1,-1)".
**
**  Given:
**     m        const pm_model*  model
**     index    int              term index
**     buf      char*            output buffer
**     len      size_t           its size (>= 2)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG (also a term pm_model_prepare
**                          would refuse: m need not be prepared, but the
**                          term must be valid; buf is then untouched)
**  Notes:
**  1) Isotropic terms are named a, b, c', d, e', i; harmonic terms
**     "<base>*Y(l,m)"; periodic terms "<base>*cos(<G>*ha)" or "*sin(..dec)";
**     paper-form periodic "<base>*Ycos(G)"/"Ysin(G)"; zenith terms
**     "cot(el)", "cos(el)"; auxiliary terms "<base>*temp", "*time",
**     "*dir", "*aux<j>"; a side restriction appends "@E" or "@W".  The name
**     is truncated to fit buf (always NUL-terminated).
*/
pm_status pm_term_name(const pm_model *m, int index, char *buf, size_t len);

/*
**  pm_model_apply - encoder position to apparent position (forward model).
**
**  Given:
**     m        const pm_model*   prepared model
**     ctx      const pm_context* per-evaluation inputs, or NULL
**     enc_ha   double            encoder axis 1 (radians)
**     enc_dec  double            encoder axis 2 (radians; beyond +-pi/2
**                                when flipped over the pole)
**  Returned:
**     app_ha   double*           apparent axis 1, in (-pi, pi]
**     app_dec  double*           apparent axis 2, in [-pi/2, pi/2]
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_NONFINITE; PM_ERR_STATE
**  Notes:
**  1) p' = H Pt(ha+c') X(d) Pd(dec-e') T(i) w, where the rotations carry
**     the isotropic terms exactly and w is the unit vector displaced from
**     (1,0,0) by the anisotropic terms' tangent-plane offset (docs/model.md).
**     To first order in the coefficients this is the paper's Eq.
**     (pyyexpansion).
**  2) Cost: one sin/cos pair per axis (the library's own, within 1 ulp,
**     for angles within 64 rad; libm beyond), recurrences for the
**     harmonics, and the angles of p' measured from (ha+c', dec-e') by
**     short series (atan2 where they differ by more than 0.01 rad).  No
**     iteration, no libm call in the common case.
**  Reference: Pal et al., Sec. 2, Eq. (tdmatrices); Sec. 3, Eq. (pyyexpansion).
*/
pm_status pm_model_apply(const pm_model *m, const pm_context *ctx,
                         double enc_ha, double enc_dec,
                         double *app_ha, double *app_dec);

/*
**  pm_model_invert - apparent position to the encoder position that points
**  there (inverse model).
**
**  Given:
**     m        const pm_model*   prepared model
**     ctx      const pm_context* per-evaluation inputs, or NULL
**     app_ha   double            apparent axis 1 (radians)
**     app_dec  double            apparent axis 2 (radians, |.| <= pi/2)
**     side     int               PM_SIDE_NORMAL or PM_SIDE_FLIPPED
**  Returned:
**     enc_ha   double*           encoder axis 1, in (-pi, pi]
**     enc_dec  double*           encoder axis 2, on the requested side:
**                                enc_dec - e' in [-pi/2, pi/2] for
**                                PM_SIDE_NORMAL, in (pi/2, 3pi/2) for
**                                PM_SIDE_FLIPPED; with
**                                PM_WARN_UNREACHABLE the nearest
**                                position, which may be on the pole
**                                itself (enc_dec - e' = +-pi/2, the
**                                boundary of both sides)
**  Returned (function value):
**              pm_status   PM_OK; PM_WARN_NOT_CONVERGED; PM_WARN_UNREACHABLE;
**                          PM_ERR_ARG; PM_ERR_NONFINITE; PM_ERR_STATE
**  Notes:
**  1) The isotropic part is inverted in closed form (x = F(D): the encoder
**     position that points at the target for a given anisotropic
**     displacement D); D is iterated to the model's own, D = D(F(D)).  A
**     point x = F(D^) misses the target by |D(x) - D^| (to first order):
**     the measured stop.  The first evaluation also gives the Jacobian
**     J = dD/dx (analytic), and the steps are Newton steps on D with the
**     closed form's derivative F_D: (I - J F_D) (D^' - D^) = D(x) - D^, J
**     kept for the call (a chord).  Where the model's second-derivative
**     bound m->lip2 is known (harmonic and AUX terms) the next point's
**     miss is bounded before it is evaluated,
**       |D(x') - D^'| <= |D(x) + J h - D^'| + lip2 (|x - x_J| + |h|/2) |h|,
**     h = x' - x (Taylor's theorem), and the iteration stops when that is
**     below PM_INVERT_TOL/2: the predicted stop.  So a tracking call
**     started within 0.1 s of sidereal motion of the solution needs: one
**     evaluation (with J) at the start, whose miss the start's own
**     displacement measures; one closed form to x1, whose miss is
**     quadratic in the start's (the chord's error); one evaluation at x1
**     (its miss measured), or none where the bound above already holds
**     (1 kHz ticks); a third or fourth only where the step is long and
**     the contraction weak (within a few degrees of the mount's pole,
**     |F_D| ~ 1/cos of the distance, with 10' terms): hence
**     PM_INVERT_TRACK_MAX_EVALS = 8 (measured worst 4 in
**     tests/check_bounded.c's 16,000 tracking calls, 1 ms to 0.1 s ticks;
**     5 once in 80,000 more at 0.1 s, 0.500 deg from the pole, and 8 with
**     1 s ticks within a degree of it: bench/inv_stress.c).  Where a step
**     contracts the miss by less than 1e-3 and the next point would still
**     miss the tolerance at that rate, the next evaluation takes J afresh
**     (within a few degrees of the mount's pole J goes stale within a
**     step: |F_D| magnifies its change).  At most PM_INVERT_MAX_FIXED (4)
**     such steps (where Newton's steps on D do not contract -- a term that
**     varies fast makes the first evaluation's J a poor guide -- plain
**     fixed-point steps D^' = D(x) from the best point, within the same
**     4): where they have not converged by then (within about the
**     anisotropic amplitude of the mount's pole, where the closed form's
**     branch is ill-conditioned, or for displacements of degrees) Newton
**     steps on the full forward model take over from the best point, with
**     the evaluations the fixed point left; in a call from a start
**     (pm_model_invert_near, pm_model_track) at once where I - J F_D is
**     ill-conditioned (|det| < 0.2), from the point just evaluated (its
**     evaluation reused where J was taken there; plain steps do not
**     contract there either, and cost a tracking call one or two
**     evaluations before): the residual
**     is the tangent offset F of the model's position from the target, its
**     Jacobian M analytic (the rotations' derivatives and J, every term
**     kind differentiated), so each trial point costs one evaluation.  The
**     step solves the quadratic model F + M h + H(h,h)/2 = 0 (H: the
**     rotations' second derivatives, analytic, plus the displacement's,
**     measured along the last step by the secant): in M's singular
**     directions a Newton step along the regular one and a quadratic along
**     the near-null one.  At the fold of the mount's pole (the edge of the
**     cap the tube cannot reach, where M is singular and the two
**     solutions either side of the edge merge) plain Newton halves its
**     distance to the fold per step; the quadratic gives both solutions,
**     and the one on the side asked for is taken (the other root where
**     only it lies on that side), its vertex where the target is beyond
**     the fold (the nearest point).  A trial that is not better (on the
**     side asked for, then a smaller miss) shortens the step to a quarter;
**     steps are capped at 1 rad (a trust region: near the pole the hour
**     angle is ill-determined); a step beyond the pole's edge from the
**     side asked for stops at the edge, and from the edge the step is
**     along it (Gauss-Newton, then the secant of dp/dt . q: the nearest
**     point of the edge where the target is out of reach).  At most
**     PM_INVERT_MAX_FIXED + PM_INVERT_MAX_NEWTON evaluations in all: so
**     pm_model_invert_near needs at most PM_INVERT_NEAR_MAX_EVALS = 13
**     evaluations, whatever the inputs (the misses of the points it
**     returns are those measured on the way: no evaluation to check them).
**     The round-trip error |apply(invert(x)) - x| is below PM_INVERT_TOL
**     on return with PM_OK.
**  2) Within a few arcminutes of the mount's pole the closed form's two
**     branches need not match the two sides of the pole (the anisotropic
**     terms fold the sky there), so pm_model_invert tries the other
**     branch (fixed point and Newton again, for the side asked for: 13
**     more), then the pole rescue, a pole-aware parametrisation: for an
**     hour angle t the declination d(t) that turns the pointing into the
**     plane of the target and the polar axis is exact (one rotation about
**     the declination axis), which leaves one equation E(t) = 0 (the miss
**     along that axis) on the circle of hour angles.  E is sampled at
**     PM_INVERT_POLE_STARTS (12) hour angles round the pole (one
**     evaluation each, for the displacement there), its changes of sign
**     bracket the solutions (roots by the parabolas through the
**     neighbours), and Newton, locked to the side asked for, runs from the
**     brackets on that side, then from the samples with the least miss:
**     PM_INVERT_POLE_RUNS (3) runs of PM_INVERT_POLE_NEWTON (12) trial
**     points (36).  Hard bound, whatever the inputs: PM_INVERT_MAX_EVALS =
**     2 x 13 + 12 + 3 x 12 = 74 model evaluations; elsewhere a few.
**     Realistic models (L <= 2, isotropic terms within 10 deg, harmonic
**     terms within 10') get PM_OK for the targets a mount can reach: 2 of
**     1,200,000 cold calls within 0.5 deg of the mount's pole, down to its
**     very edge, did not (both where d and i nearly cancel at that pole;
**     bench/inv_stress.c; tests/check_bounded.c asserts 48,000 calls, all
**     PM_OK).  An outside probe's 2,400,000 such calls (its own random
**     models, isotropic terms within 1 deg) found 4 more, 0.017-0.028 deg
**     from the pole where d and i do not cancel: PM_WARN_UNREACHABLE with
**     the position returned 1.8-7" off, for targets pm_model_invert_near
**     reaches from a start 1e-3 rad away (the rescue's 12 samples missed
**     the pair of close roots; not fixed).  For tracking use
**     pm_model_invert_near, which never needs the rescue (at most 13).
**  3) PM_WARN_NOT_CONVERGED: a bound was reached; the best position found
**     is returned.  PM_WARN_UNREACHABLE: no position on the requested side
**     points at the target: it lies in the cap around the mount's pole
**     that collimation, non-perpendicularity and the anisotropic terms
**     make unreachable from that side (for pm_model_invert_near, the side
**     of the start: the closed form's reach says so, or, where Newton
**     started at once, its last step to the fold's vertex); the nearest
**     position found on that side is returned (where the miss is
**     stationary: the fold's vertex or
**     the edge's nearest point, within 1e-9 rad of a brute-force scan in
**     tests/check_model.c).
**  4) The round trip holds at the angles returned, as rounded to doubles.
**     The fixed point is judged before that rounding, with PM_INVERT_TOL/2
**     to spare; where the rounding times how fast the anisotropic
**     displacement can change (m->lip, plus |coef (input - param)| of the
**     AUX terms) could use that margin (coefficients of ~10 rad and more,
**     or angles beyond ~100 rad), and for geometries no mount has (|d|,
**     |i| or the polar axis's offset beyond 0.5 rad, or an anisotropic
**     displacement that can reach 0.5 rad, where the closed form
**     degenerates towards 90 deg), one more evaluation checks the round
**     trip at the returned angles (Newton, within the bounds of Notes 1
**     and 2).
**     So it does where a term restricted to one pier side (no pier side
**     in ctx) sees the rounded angles on the other side of the pole's
**     edge than the fixed point's last position: such a term jumps there,
**     and a target whose only solutions sit on the edge itself gets
**     PM_WARN_UNREACHABLE (or _NOT_CONVERGED) with the nearest position.
**  5) The paper (Sec. 5.2) inverts by flipping the sign of the
**     coefficients, with an error O(a^2); docs/model.md gives the measured
**     size of that error.
**  Reference: Pal et al., Sec. 5.2.
*/
pm_status pm_model_invert(const pm_model *m, const pm_context *ctx,
                          double app_ha, double app_dec, int side,
                          double *enc_ha, double *enc_dec);

/*
**  pm_model_invert_near - as pm_model_invert, starting from a known encoder
**  position (e.g. the previous tracking tick).
**
**  Given:
**     start_ha, start_dec  double  encoder position to start from (the
**                                  previous tick); the solution is the one
**                                  continuous with it, and enc_ha, enc_dec
**                                  are returned within pi of start_ha,
**                                  start_dec (no jump at +-pi when
**                                  tracking).  |start_ha|, |start_dec|
**                                  at most PM_START_MAX, else
**                                  PM_ERR_ARG.  At most
**                                  PM_INVERT_NEAR_MAX_EVALS (13) model
**                                  evaluations, whatever the inputs.
**  Other arguments, return values and notes as pm_model_invert.
*/
/* Largest start angle pm_model_invert_near(_f) accepts (radians; about
** 160,000 turns): the result is returned within pi of the start, and
** beyond this a double no longer holds an angle to 1e-10 rad.  PM_OK needs
** the result held to PM_INVERT_TOL, which a double near the start cannot
** beyond about 1e3 rad (its spacing there is 1.1e-13): with larger starts
** most calls end PM_WARN_NOT_CONVERGED with the answer within the
** spacing (an outside probe: 87% at 1e4 rad, misses up to 9e-13 rad).  A
** controller that keeps its axis angles within a few turns of zero gets
** PM_OK. */
#define PM_START_MAX 1e6
pm_status pm_model_invert_near(const pm_model *m, const pm_context *ctx,
                               double app_ha, double app_dec,
                               double start_ha, double start_dec,
                               double *enc_ha, double *enc_dec);

/*
**  pm_track_start, pm_model_track - a tracking loop's inverse, with a state
**  carried from tick to tick.
**
**  Given (pm_track_start):
**     enc_ha, enc_dec  double  encoder position the loop starts from (as
**                              pm_model_invert_near's start; |.| at most
**                              PM_START_MAX)
**  Given (pm_model_track):
**     m        const pm_model*   prepared model
**     ctx      const pm_context* per-evaluation inputs, or NULL
**     app_ha, app_dec  double    this tick's target, as pm_model_invert
**  Given and returned:
**     t        pm_track*         the loop's state (pm_track_start first)
**  Returned:
**     enc_ha, enc_dec  double*   encoder position, as pm_model_invert_near
**                                from the state's last position
**  Returned (function value):
**              pm_status   as pm_model_invert_near; PM_ERR_ARG also for a
**                          state pm_track_start did not fill
**  Notes:
**  1) pm_model_track(m, ctx, t, ...) is pm_model_invert_near from the
**     state's position t->enc, with two differences.  The iteration
**     starts at that position moved on by the state's last step (a target
**     moving uniformly is then met within the step's second-order change,
**     ~1e-11 rad at 10 Hz); not where that would cross the mount's pole
**     or where the last call gave no PM_OK.  The Jacobian J = dD/dx that
**     the iteration needs (pm_model_invert Note 1) is carried in the
**     state from the tick where it was taken, and reused while the start
**     is within PM_TRACK_J_REACH of that point (the model and the inputs
**     of its AUX terms unchanged: pm_model.ident and a digest of those
**     inputs say so).  Where a step h shows the carried J too far off to
**     converge fast (lip2 |x - x_J| |h| above 100 PM_INVERT_TOL: the
**     next point's bound could not certify it, and the chord contracts
**     slowly), the next evaluation takes J afresh (a tick within a few
**     degrees of the mount's pole took 6 evaluations without it,
**     where pm_model_invert_near took 4).  With J carried, a tick of a
**     uniformly moving target costs one
**     plain evaluation where pm_model_invert_near makes one with the
**     Jacobian (about three evaluations' worth of arithmetic) and, at
**     10 Hz, a second one.  Where the state's J is used
**     the predicted stop's bound holds as written there, with |x - x_J|
**     the distance from the point J was taken at (Taylor's theorem does
**     not care where J came from), so PM_OK still promises the round trip
**     within PM_INVERT_TOL, and the bound of PM_INVERT_NEAR_MAX_EVALS
**     evaluations holds as for pm_model_invert_near.  The results differ
**     from pm_model_invert_near's in the last bits (other iterates):
**     tests/check_track.c finds them within 1e-12 rad of it beyond 5 deg
**     of the mount's pole.  A model without anisotropic terms needs no
**     evaluation: the closed form, on the branch of the start.
**  2) On PM_OK the state's position becomes the result; on a warning or
**     an error it stays (the next tick starts from the last good one),
**     and a J taken in the call is kept (it is right wherever it was
**     taken).  Every call is independent of the earlier ones otherwise:
**     a new target far away is solved from the state's position as
**     pm_model_invert_near would, J taken afresh.
**  3) The state is plain data of the caller's (no pointers): copy it,
**     keep one per axis pair, or start again with pm_track_start at any
**     time (e.g. after a slew).  Use it with one model at a time: another
**     model, or this one prepared with other coefficients, makes the next
**     call take J afresh (a 64-bit digest: two models that share it are
**     treated as one, with probability 2^-64 for a change of
**     coefficients).
*/
/* How far (radians, along the encoder axes) from the point it was taken
** at pm_model_track reuses a Jacobian (pm_model_track, Note 1). */
#define PM_TRACK_J_REACH 1e-3
typedef struct pm_track {
    double enc[2];          /* the last position (encoder axes 1 and 2) */
    /* Set by pm_track_start and pm_model_track; do not set by hand. */
    int magic;              /* PM_TRACK_MAGIC once started */
    int flags;              /* PM_TRACK_HAVE_*, PM_TRACK_REFRESH */
    double jac[4];          /* J = dD/dx, row-major */
    double jac_at[4];       /* sin, cos of both axes where J was taken */
    double ni[4];           /* the chord's matrix (I - J F_D)^-1 with it */
    double trig[4];         /* sin, cos of both axes at enc */
    double step[2];         /* the last step of enc (radians) */
    double step_trig[4];    /* sin, cos of it on both axes */
    unsigned long ident[2]; /* the model's digest (pm_model.ident) */
    unsigned long inputs[2]; /* digest of the AUX terms' inputs then */
} pm_track;
#define PM_TRACK_HAVE_J 1
#define PM_TRACK_HAVE_NI 2
#define PM_TRACK_HAVE_TRIG 4
#define PM_TRACK_REFRESH 8
#define PM_TRACK_HAVE_STEP 16
#define PM_TRACK_MAGIC 0x7472616b
pm_status pm_track_start(pm_track *t, double enc_ha, double enc_dec);
pm_status pm_model_track(const pm_model *m, const pm_context *ctx, pm_track *t,
                         double app_ha, double app_dec, double *enc_ha,
                         double *enc_dec);

/*
**  pm_model_residual - observed minus model in the tangent plane.
**
**  Given:
**     m        const pm_model*   prepared model
**     ctx      const pm_context* per-evaluation inputs, or NULL
**     enc_ha, enc_dec  double    encoder position of an observation
**     app_ha, app_dec  double    the observed apparent position (app_dec
**                                within +-pi/2: PM_ERR_ARG beyond, as
**                                pm_fit_add)
**  Returned:
**     res      double[2]         residual (radians): [0] along axis 1 on
**                                the sky (i.e. d(ha)*cos(dec)), [1] along
**                                axis 2, both at the model's position
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_NONFINITE; PM_ERR_STATE
*/
pm_status pm_model_residual(const pm_model *m, const pm_context *ctx,
                            double enc_ha, double enc_dec,
                            double app_ha, double app_dec, double res[2]);

/*
**  pm_terms_eval - the term functions Y_lm(ha,dec) p_k(ha,dec) themselves.
**
**  Given:
**     order    int         L, 0..PM_MAX_L
**     ha, dec  double      the position (radians) the terms are evaluated
**                          at: in a model, the index-shifted (mechanical)
**                          position (ha + c', dec - e')
**  Returned:
**     out      double*     6*(L+1)^2 x 3 values: for harmonic index
**                          j = l*l + l + m and base vector k = 1..6, the
**                          3-D vector Y_lm p_k at out[3*(6*j + k-1) + 0..2]
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_NONFINITE; PM_ERR_CAPACITY
**  Notes:
**  1) All 6(L+1)^2 products, including the linearly dependent ones the
**     model drops, in the paper's normalisation (Y_00 = 1, Y_1,-1 =
**     cos(dec) sin(ha), ..., Y_20 = 3 sin^2(dec) - 1; docs/model.md gives
**     the general rule), so the paper's relations can be checked.
**  Reference: Pal et al., Sec. 3, Table 1, Eqs. (l1lin1)-(yl2r6).
*/
pm_status pm_terms_eval(int order, double ha, double dec, double *out);

/* ---------------------------------------------------------------------- */
/* Float build of the evaluation (single-precision FPUs: Cortex-M4F).     */
/* ---------------------------------------------------------------------- */

/* A model prepared for single-precision evaluation.  Positions stay double
** at the interface (a float holds an angle only to ~6e-8 rad = 0.012");
** the correction is computed in float in a frame local to the position,
** where it is small, and added in double (docs/model.md, "Float build"). */
typedef struct pm_model_f {
    int mount, order, n_terms, n_base, needs_ctx;
    int prepared;
    double c, e;                   /* index terms c', e' (radians), exact */
    float a, b, ra, rb;            /* polar axis (a, b) and Rodrigues factors */
    float sd, vd, si, vi;          /* sin d, 1 - cos d, sin i, 1 - cos i */
    float sc, cc, se, ce;          /* sin, cos of c' and e' */
    float lat_s, lat_c;            /* site latitude */
    float dense[PM_N_HARM(PM_MAX_L)][6];
    pm_term term[PM_MAX_TERMS];    /* the added terms (index >= n_base) */
    float coef[PM_MAX_TERMS];
} pm_model_f;

/*
**  pm_model_f_prepare - single-precision copy of a prepared model.
**
**  Given:
**     m        const pm_model*  prepared model
**  Returned:
**     mf       pm_model_f*      float model
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_STATE (m not
**                          prepared, or changed since: pm_model_prepare
**                          Notes 1 and 2)
**  Notes:
**  1) mf is a snapshot of m: a later change of m (new coefficients,
**     pm_model_prepare, a refit by pm_fit_solve) does not reach it, and
**     the float calls cannot see that it happened (mf keeps no link to m,
**     and no copy to check as pm_model_prepare's Note 1 does).  Call
**     pm_model_f_prepare again after every change of m; do not write
**     mf's fields directly.
*/
pm_status pm_model_f_prepare(pm_model_f *mf, const pm_model *m);

/*
**  pm_model_apply_f, pm_model_invert_f, pm_model_invert_near_f - as
**  pm_model_apply, pm_model_invert, pm_model_invert_near, evaluated in
**  single precision.
**
**  Notes:
**  1) The correction (apparent - encoder, after the exact index shifts)
**     agrees with the double build to 0.01" over the sky (tested at L=2
**     with index terms c', e' of degrees, which are applied in double, and
**     the other terms within arcminutes).  The other isotropic rotations
**     (a, b, d, i) are applied in float, which rounds at up to 6e-7 of
**     their angle (check_float: a or b alone 4-5e-7, d or i 2-3e-7): of 1
**     deg, 1e-8 rad (0.002"); of 10 deg, up to 9e-8 rad (0.018").
**  2) The inverse is a fixed point on the float correction (the frame
**     position is the target minus the correction there; at most
**     PM_INVERT_F_FIXED steps of one evaluation each, usually 2, no libm
**     call per step while the correction is below 0.01 rad), stopped when
**     the change it predicts for the next step is below PM_INVERT_F_TOL/4,
**     and the point checked with the forward model.  Where it does not
**     contract or the check fails (near the mount's pole; corrections
**     beyond 0.01 rad) a Newton iteration on sky offsets at the target
**     takes over (Jacobian by differences, kept while steps gain a factor
**     10, steps cut back when they do not help).  At most
**     PM_INVERT_F_MAX_EVALS = PM_INVERT_F_FIXED + 3 + 6 * PM_INVERT_F_MAX
**     model evaluations whatever the inputs.  It iterates to
**     PM_INVERT_F_TOL (0.002", above the float forward's own noise of
**     ~0.0002"), not 1e-13.
**     PM_WARN_NOT_CONVERGED if the bound is reached or the solution found
**     is on the other side of the mount's pole.
**  3) What to expect (bench/inv_stress.c "float", L = 2, harmonic terms
**     within 10', 20,000 targets per row, docs/performance.md): the float
**     forward's own jitter (its change between neighbouring inputs) grows
**     with the correction it carries, about 1e-7 of it (isotropic terms
**     of 1 deg: 3e-9 rad; of 10 deg: up to 4e-8 rad, above
**     PM_INVERT_F_TOL); its offset from the double forward is larger
**     (Note 1), so an inverse that is PM_OK against the float forward can
**     miss by that offset against the double one (terms of 1 deg: up to
**     1.7e-8 rad).  With isotropic terms within 1
**     deg every inverse 5 to 90 deg from the mount's pole returns PM_OK.
**     With terms of several degrees some end PM_WARN_NOT_CONVERGED at
**     that noise floor (the position returned within 5e-8 rad of the
**     target: 10 deg terms, 3% of targets beyond 20 deg from the pole,
**     15% at 10-20 deg), and within about |d| + |i| of the mount's pole
**     the float inverse (it has no pole rescue) can miss altogether (10
**     deg terms, 5-10 deg from the pole: 2% of targets beyond 1e-7 rad).
**     A float firmware with large isotropic terms should judge a warning
**     by the round trip it needs and, near the mount's pole, use the
**     double pm_model_invert (about 90,000 instructions on the M4F).
*/
#define PM_INVERT_F_FIXED 6
#define PM_INVERT_F_MAX 12
#define PM_INVERT_F_TOL 1e-8
/* Worst-case model evaluations of the float inverse (81). */
#define PM_INVERT_F_MAX_EVALS (PM_INVERT_F_FIXED + 3 + 6 * PM_INVERT_F_MAX)
pm_status pm_model_apply_f(const pm_model_f *m, const pm_context *ctx,
                           double enc_ha, double enc_dec,
                           double *app_ha, double *app_dec);
pm_status pm_model_invert_f(const pm_model_f *m, const pm_context *ctx,
                            double app_ha, double app_dec, int side,
                            double *enc_ha, double *enc_dec);
pm_status pm_model_invert_near_f(const pm_model_f *m, const pm_context *ctx,
                                 double app_ha, double app_dec,
                                 double start_ha, double start_dec,
                                 double *enc_ha, double *enc_dec);

/*
**  pm_track_f_start, pm_model_track_f - the float build's tracking loop:
**  as pm_model_invert_near_f from the state's last position, the fixed
**  point started from the correction the last ticks converged to, moved
**  on by its last change.
**
**  Notes:
**  1) The correction changes by |dC/dx| times a tick's motion (1e-9 rad
**     at 10 Hz with arcminute terms), and that change by far less, so the
**     point the predicted correction gives is within PM_INVERT_F_TOL
**     already: it is checked with the forward model (Note 2 above, the
**     check that certifies every float result) and returned, one
**     evaluation a tick; where the check fails the fixed point goes on
**     from there, as pm_model_invert_near_f's.  The check is what makes
**     the result right, whatever the state holds (a state from another
**     model only costs steps).
**  2) Arguments, statuses and the state's updates as pm_model_track
**     (PM_ERR_ARG for a state pm_track_f_start did not fill); the state
**     is plain data of the caller's.
*/
typedef struct pm_track_f {
    double enc[2];  /* the last position (encoder axes 1 and 2) */
    /* Set by pm_track_f_start and pm_model_track_f; do not set by hand. */
    int magic;      /* PM_TRACK_F_MAGIC once started */
    int have_corr;  /* corr holds the last tick's correction (1), and
                       corr_prev the one before (2) */
    float corr[2];  /* the correction (frame, radians) it converged to */
    float corr_prev[2];
} pm_track_f;
#define PM_TRACK_F_MAGIC 0x7472616c
pm_status pm_track_f_start(pm_track_f *t, double enc_ha, double enc_dec);
pm_status pm_model_track_f(const pm_model_f *m, const pm_context *ctx, pm_track_f *t,
                           double app_ha, double app_dec, double *enc_ha,
                           double *enc_dec);

/* ---------------------------------------------------------------------- */
/* Fit.                                                                   */
/* ---------------------------------------------------------------------- */

/* Normal equations of a Gauss-Newton pass, in caller-owned fixed memory.
** Size does not depend on the number of observations: about
** 8 * (PM_MAX_TERMS^2 + ...) bytes plus one pm_model (sizeof(pm_fit) for
** the build's PM_MAX_L; docs/model.md lists it for L = 1, 2, 4). */
typedef struct pm_fit {
    int state;                           /* internal */
    int n_par;                           /* P */
    long n_obs;                          /* N in the current pass */
    double chi2;                         /* sum of squared residuals (rad^2) */
    double ata[PM_PACKED(PM_MAX_TERMS)]; /* normal matrix J^T J of the
                                            current pass, packed lower */
    double atb[PM_MAX_TERMS];            /* J^T r */
    double cov[PM_PACKED(PM_MAX_TERMS)]; /* after a solve: (J^T J)^-1 */
    int cov_valid;                       /* cov belongs to the last solve */
    double scale[PM_MAX_TERMS];          /* column equilibration */
    pm_model lin;                        /* linearisation point */
    double base_coef[PM_MAX_TERMS];      /* last accepted point */
    double step[PM_MAX_TERMS];           /* step taken from it */
    double base_chi2;                    /* chi^2 at the accepted point */
    double base_pred;                    /* chi^2 decrease its step predicted */
    int halvings;                        /* step halvings since then */
    int bad_term;                        /* term index after PM_ERR_SINGULAR */
    int iterations;                      /* passes solved so far */
} pm_fit;

/* What a solved pass gives besides the model. */
typedef struct pm_fit_result {
    long n_obs;                    /* N */
    int n_par;                     /* P */
    double chi2;                   /* chi^2 at the linearisation point (rad^2) */
    double sigma;                  /* unbiased residual sqrt(chi2/(2N-P)) (rad) */
    double err[PM_MAX_TERMS];      /* 1-sigma error of each coefficient (rad) */
    double max_step;               /* largest |step| / error of this pass */
    int accepted;                  /* 0: chi^2 rose, the step was halved */
    int converged;                 /* 1 when the step was negligible */
    int iterations;                /* passes so far */
} pm_fit_result;

/*
**  pm_fit_init - start a fit of the terms of a model.
**
**  Given:
**     fit      pm_fit*          fit state to initialise
**     start    const pm_model*  terms to fit and their starting values
**                               (e.g. from pm_model_init: all zero)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_STATE (start is not
**                          prepared, or changed since: pm_model_prepare
**                          reports what is wrong with it)
*/
pm_status pm_fit_init(pm_fit *fit, const pm_model *start);

/*
**  pm_fit_add - accumulate one observation into the normal equations.
**
**  Given:
**     fit      pm_fit*           initialised fit
**     ctx      const pm_context* inputs for this observation, or NULL
**     enc_ha, enc_dec  double    encoder position (radians)
**     app_ha, app_dec  double    observed apparent position (radians)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_NONFINITE (a
**                          non-finite input or row, or one that would take
**                          chi^2 or a diagonal element of J^T J beyond
**                          1e300; the fit is unchanged); PM_ERR_STATE
**  Notes:
**  1) Each observation gives two rows (the tangent-plane residual along both
**     axes), linearised at fit->lin.  O(P^2) work, no memory growth.
**  2) The 1e300 bound keeps every accumulated sum finite (residuals and
**     derivatives up to ~1e150 rad pass), so a solve never reports an
**     infinite chi^2.
*/
pm_status pm_fit_add(pm_fit *fit, const pm_context *ctx,
                     double enc_ha, double enc_dec,
                     double app_ha, double app_dec);

/*
**  pm_fit_solve - solve the accumulated pass and start the next one.
**
**  Given/Returned:
**     fit      pm_fit*          fit with the observations of one pass
**  Returned:
**     out      pm_model*        the updated model (prepared)
**     res      pm_fit_result*   statistics (may be NULL)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_TOO_FEW;
**                          PM_ERR_SINGULAR (fit->bad_term names the term);
**                          PM_ERR_NONFINITE (the step, a variance or the
**                          predicted decrease would overflow: coefficients
**                          or residuals near 1e150 rad); PM_ERR_STATE
**  Notes:
**  1) Column equilibration, then a Cholesky factorisation that stops on a
**     pivot below 1e-11 of the equilibrated diagonal (the term is a linear
**     combination of earlier ones for this sky coverage).
**  2) On success fit->cov holds (J^T J)^-1 for the covariance; the next
**     pm_fit_add starts a new pass linearised at *out.  Feed the same
**     observations again until res->converged (Gauss-Newton); pm_fit_run
**     does the loop for observations held in arrays.
**  3) Convergence: every step below 1e-6 of its 1-sigma error (or 1e-15
**     rad), or a predicted chi^2 decrease s^T J^T r below 1e-4 sigma^2,
**     so that the step moves every coefficient by less than 1% of its
**     1-sigma error (noise-free data still converge to rounding, since
**     sigma is then at rounding level).
**  4) Damping (Armijo): a pass whose chi^2 did not fall by at least 1e-4 of
**     what the step predicted is rejected: the step is halved, *out is the
**     new trial point and res->accepted is 0 (the other fields of *res are
**     left as they were).  When what is left of the step could not matter
**     (predicted decrease below 1e-6 sigma^2), or after 40 halvings, the
**     accepted point is returned as converged.  So chi^2 never increases, which matters when terms are
**     nearly degenerate (one pier side only, narrow sky) and residuals
**     large, where undamped Gauss-Newton can oscillate.
**  5) After PM_OK, chi^2, sigma, every error and every covariance
**     (pm_fit_covariance) are finite.
**  6) On error *out and *res are unchanged and the accumulated pass is kept
**     (more observations can be added and the solve retried); the
**     covariance of the previous solve is no longer available.
**  7) The four terms applied exactly as rotations, c', d, e' and i
**     (coef[2] to coef[5]), come back reduced into (-pi, pi]: the same
**     model to rounding, where a start or a step turns away had given
**     c' = -36179 deg or i = 360.06 deg (outside probes).  The polar axis's
**     a and b and the anisotropic terms are not reduced.
*/
pm_status pm_fit_solve(pm_fit *fit, pm_model *out, pm_fit_result *res);

/*
**  pm_fit_run - Gauss-Newton fit of observations held in arrays.
**
**  Given:
**     fit      pm_fit*           workspace
**     model    pm_model*         terms and starting values; on success the
**                                fitted model
**     ctx      const pm_context* n contexts, or NULL
**     n        long              number of observations
**     enc_ha, enc_dec, app_ha, app_dec  const double*  n values each
**     max_iter int               bound on passes (e.g. 20)
**  Returned:
**     res      pm_fit_result*    statistics of the final pass (may be NULL)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_DIVERGED (bound reached, model
**                          unchanged); errors of pm_fit_init/add/solve
**  Notes:
**  1) The starts: the fit runs from *model as given; where *model holds no
**     index terms (c' and e' both 0) and the observations' own offsets put
**     one beyond PM_FIT_INDEX_START, it runs again from the offsets (the
**     circular means of the hour-angle and declination offsets, the first
**     weighted by cos^2 of the declination; readings beyond the pole folded
**     to the sky, where "beyond" is measured from the declination offsets'
**     own mean where that makes them agree better (a German mount whose
**     declination encoder reads half a turn off reads its normal side
**     beyond 90 deg), or unfolded where that does (a fork whose declination
**     index takes readings past 90 deg) and,
**     for a model beyond the six isotropic terms, from the six of the
**     better order-0 fit from these two starts, and returns the fit of
**     least chi^2, a later start only where it is lower beyond rounding
**     (the workspace as that fit left it).  A cold start (the six
**     isotropic terms all 0) that takes no start from the offsets runs
**     the order-0 fit from zero as well, and where the model's fit ends
**     above that fit's chi^2 (which it holds, so at its least-squares fit
**     it is no larger: a false minimum) it runs again from its six (an
**     outside probe's German runs beyond the pole with index offsets under
**     PM_FIT_INDEX_START stopped at order 1 at 8,142" with PM_OK, 2.77" at
**     order 0).  A refit from a model does not pay for it.
**     Gauss-Newton from zero converges for index errors of a few degrees;
**     an unsynchronised encoder's tens stopped in a local minimum that
**     PM_OK reported (an alt-az azimuth zero 60 deg off: sigma 14" for 1"
**     of noise, c' -12.5 deg; an outside probe).  Give a non-zero c' or e'
**     to start from your own values only.  Stack: one pm_model, as for
**     one run.
**  2) The statistics and the covariance are the returned model's: where
**     the converging pass took a step, one more pass (beyond max_iter)
**     takes them at the model it returns, and does not move it.  The pass
**     solves at its point before the step, and in an ill-conditioned fit
**     the step moves the Jacobian: 15 stars for 22 terms, 394 passes, had
**     a predicted error at the stars of 6.2" for sigma 1.39" (a linear
**     fit's cannot exceed sigma), 1.19" at the returned model (an outside
**     probe).  pm_fit_solve's passes are the caller's to repeat.
**  3) Two aliases of the six isotropic terms point exactly alike where
**     they are the whole model (order 0): (e' + pi, pi - i), the tube
**     through the pole and turned round, and (c' + pi, pi - d, e' + pi),
**     the axes turned round.  The fit returns the one with the collimation
**     i and the non-perpendicularity d within 90 deg, whose sides are the
**     encoders' (in the other a fork's every star is beyond the pole, and
**     pm_model_invert's normal side with it).  The order-0 fits that seed
**     higher orders are taken there; where the fit still comes to |d| or
**     |i| beyond 90 deg from a start within it, it runs once more from that
**     alias of its six and keeps it where it converges there (at order 0:
**     where its chi^2 is no larger beyond rounding).  At higher orders the
**     anisotropic terms, which live in the mechanical frame, make the two
**     different models, and the other's chi^2 may be a little lower (a
**     fork's sigma 1.10" against 1.12"; outside probes).  A fork whose HA
**     encoder read 180 deg off had come back with e' 180 deg and i -180
**     deg, an alt-az run with its azimuth 180 deg off with d -180 deg.  A
**     start with |d| or |i| beyond 90 deg (a refit from such a model) keeps
**     its alias.  Stack: the same pm_model.
*/
#define PM_FIT_INDEX_START 0.17453292519943295 /* 10 deg, radians */
pm_status pm_fit_run(pm_fit *fit, pm_model *model, const pm_context *ctx,
                     long n, const double *enc_ha, const double *enc_dec,
                     const double *app_ha, const double *app_dec,
                     int max_iter, pm_fit_result *res);

/*
**  pm_fit_covariance - element of the coefficient covariance (rad^2).
**
**  Given:
**     fit      const pm_fit*   fit after a successful pm_fit_solve
**     res      const pm_fit_result* its result (for sigma)
**     i, j     int             term indices
**  Returned:
**     cov      double*         covariance sigma^2 (J^T J)^-1_ij
**     corr     double*         correlation coefficient (may be NULL)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_STATE (no successful
**                          solve yet, or the last solve failed: its
**                          factorisation overwrote the covariance)
*/
pm_status pm_fit_covariance(const pm_fit *fit, const pm_fit_result *res,
                            int i, int j, double *cov, double *corr);

/*
**  pm_fit_pointing_sigma - how well the fitted model knows the pointing at
**  one encoder position: the 1-sigma uncertainty of its correction there,
**  from the coefficients' covariance (the model's own error, not the
**  measurement noise).  Where the run sampled densely it is small; where
**  the model extrapolates (below the lowest star, in a gap of the sky) it
**  grows.  The predicted error map of docs/model.md ("How well the model
**  knows the sky").
**
**  Given:
**     fit      const pm_fit*           after a successful pm_fit_solve or
**                                      pm_fit_run
**     res      const pm_fit_result*    its result (for sigma)
**     m        const pm_model*         the fitted model (its terms the fit's)
**     ctx      const pm_context*       inputs of its physical terms (or NULL)
**     enc_ha, enc_dec  double          the encoder position (rad)
**  Returned:
**     sigma    double*     per axis: sqrt((v11 + v22) / 2) (rad), on the
**                          scale of res->sigma
**     cov      double[3]   (may be NULL) v11, v12, v22 (rad^2): the
**                          covariance of the correction along axis 1 (on
**                          the sky) and axis 2
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG (NULL, or m has another number
**                          of terms than the fit); PM_ERR_STATE (no
**                          successful solve, or the last solve failed:
**                          pm_fit_solve Note 6); PM_ERR_NONFINITE (a
**                          non-finite angle, or a variance beyond the
**                          double range); the model's statuses of
**                          pm_fit_row.  Nothing is written on error.
**  Notes:
**  1) J C J^T with J the position's two rows (pm_fit_row at the model's own
**     prediction) and C = sigma^2 (J^T J)^-1 of the last solve: about P^2
**     multiply-adds (2,100 at L = 2), allocation-free, for a controller
**     choosing where to look next.
**  2) The scatter of a corrected telescope at a new star is about
**     sqrt(res->sigma^2 + sigma^2) per axis: the noise of one measurement
**     plus this (tests/check_errormap.c compares it with held-out points).
**  3) The D-optimal score of a candidate star (the rise of log det of the
**     information if it were taken, noise s = res->sigma) follows from cov:
**     log((1 + v11/s^2)(1 + v22/s^2) - v12^2/s^4) (examples/next_star.c;
**     tests/check_plan.c checks it against the refit).
*/
pm_status pm_fit_pointing_sigma(const pm_fit *fit, const pm_fit_result *res,
                                const pm_model *m, const pm_context *ctx, double enc_ha,
                                double enc_dec, double *sigma, double cov[3]);

/*
**  pm_fit_point_gain - how much one more star at an encoder position would
**  lower the fitted model's predicted error, averaged over given places of
**  the sky (the I-optimal criterion of pmfit plan): allocation-free, so a
**  mount controller can choose its own next star by calling it for each
**  candidate and taking the largest.
**
**  Given:
**     fit      const pm_fit*           after a successful pm_fit_solve or
**                                      pm_fit_run
**     res      const pm_fit_result*    its result (sigma: the noise of the
**                                      new star too)
**     m        const pm_model*         the fitted model
**     ctx      const pm_context*       inputs of its physical terms (or NULL),
**                                      for the candidate and the places alike
**     enc_ha, enc_dec  double          the candidate's encoder position (rad)
**     sky      const double*           n_sky encoder positions (ha, dec pairs,
**                                      rad): the places the error is averaged
**                                      over (e.g. a grid of the usable sky)
**     n_sky    int                     >= 1
**  Returned:
**     gain     double*     the mean over the places of the fall of the
**                          predicted variance per axis (rad^2): the mean of
**                          sigma^2 before minus after (pm_fit_pointing_sigma)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_STATE (no successful
**                          solve, or the last solve failed: pm_fit_solve
**                          Note 6); PM_ERR_NONFINITE (a non-finite angle, or
**                          products beyond the double range);
**                          PM_ERR_SINGULAR (Note 3); the model's statuses.
**                          Nothing is written on error.
**  Notes:
**  1) With C the covariance, J the candidate's two rows and J_g a place's:
**     C' = C - C J^T S^-1 J C, S = sigma^2 I + J C J^T (one more star of
**     noise sigma), so the fall at g is tr(U_g S^-1 U_g^T) / 2 with
**     U_g = J_g C J^T.  Cost: P^2 + n_sky (one evaluation + 4P).
**  2) The sum over the places is the caller's choice of "the sky": above
**     its horizon, on the pier side it will use there.
**  3) PM_ERR_SINGULAR: S is not positive definite as computed (det S <= 0),
**     so S^-1 does not exist.  Mathematically S >= sigma^2 I, so this
**     happens where sigma^2 vanishes: res->sigma = 0 (a fit of exactly
**     consistent data, chi^2 = 0), or so small (below ~1e-77 rad) that
**     det S underflows to 0; and where rounding in det S cancels (J C J^T
**     beyond ~1e16 sigma^2 and of rank one).  The fall is then 0 (no
**     variance to lower) or not known to any digit.
*/
pm_status pm_fit_point_gain(const pm_fit *fit, const pm_fit_result *res, const pm_model *m,
                            const pm_context *ctx, double enc_ha, double enc_dec,
                            const double *sky, int n_sky, double *gain);

/*
**  pm_fit_row - the two design-matrix rows of one observation.
**
**  Given:
**     m        const pm_model*   prepared model (linearisation point)
**     ctx      const pm_context* inputs, or NULL
**     enc_ha, enc_dec, app_ha, app_dec  double  the observation
**  Returned:
**     row0, row1  double*        m->n_terms derivatives each of the model
**                                position w.r.t. the coefficients
**     r        double[2]         observed minus model (radians)
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_ARG; PM_ERR_NONFINITE; PM_ERR_STATE
**  Notes:
**  1) The least-squares step solves (J^T J) d = J^T r with these rows;
**     exposed so that a caller can check the solver against another one.
**     Both components are in the frame transported by the isotropic
**     rotation (docs/model.md), so chi^2 is the same as in the sky frame.
**  2) PM_ERR_NONFINITE also when the terms overflow at this observation
**     (row0, row1 and r are then overwritten with meaningless values).
*/
pm_status pm_fit_row(const pm_model *m, const pm_context *ctx,
                     double enc_ha, double enc_dec,
                     double app_ha, double app_dec,
                     double *row0, double *row1, double r[2]);

/* ---------------------------------------------------------------------- */
/* Status words.                                                          */
/* ---------------------------------------------------------------------- */

/*
**  pm_status_text - a status in words, for messages and logs
**
**  Given:
**     s        pm_status   any value
**  Returned (function value):
**              const char* a static string, never NULL ("unknown status"
**                          for a value not in the enum); at most 63 bytes
**  Notes:
**  1) The one table of them: pmfit, the Python package and the INDI
**     plugin print these words.
*/
const char *pm_status_text(pm_status s);

/* ---------------------------------------------------------------------- */
/* Configuration check.                                                   */
/* ---------------------------------------------------------------------- */

/*
**  pm_check_config_all - do the caller's struct layouts match the library's?
**
**  Given:
**     model_size, fit_size, context_size  size_t  sizeof(pm_model),
**                          sizeof(pm_fit), sizeof(pm_context) as the
**                          caller was compiled
**     max_l, max_extra, max_aux  int  its PM_MAX_L, PM_MAX_EXTRA,
**                          PM_MAX_AUX
**  Returned (function value):
**              pm_status   PM_OK; PM_ERR_CONFIG
**  Notes:
**  1) Call as PM_CHECK_CONFIG().  Different PM_MAX_L or PM_MAX_EXTRA in
**     the caller and the library change pm_model's and pm_fit's layouts; a
**     different PM_MAX_AUX pm_context's (the library would read a
**     context's aux[] where the caller has none, or the term indices
**     PM_AUX_USER + j it accepts would not be the caller's).
**  2) pm_check_config is the check earlier headers' PM_CHECK_CONFIG()
**     called: the same without pm_context and PM_MAX_AUX.  It is kept
**     unchanged, so that programs built against them still link and
**     check what they checked; new code should use PM_CHECK_CONFIG().
*/
pm_status pm_check_config_all(size_t model_size, size_t fit_size, size_t context_size,
                              int max_l, int max_extra, int max_aux);
pm_status pm_check_config(size_t model_size, size_t fit_size, int max_l,
                          int max_extra);
#define PM_CHECK_CONFIG() \
    pm_check_config_all(sizeof(pm_model), sizeof(pm_fit), sizeof(pm_context), \
                        PM_MAX_L, PM_MAX_EXTRA, PM_MAX_AUX)

#ifdef __cplusplus
}
#endif

#endif /* PM_H */
