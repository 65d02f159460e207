/*
**  apply_simd.hpp - the forward model (pm_model_apply) on W points at once,
**  one point per lane of a vector of W doubles (W = 2: SSE2, 4: AVX2, 8:
**  AVX-512F; twice the machine's width: two of its vectors side by side),
**  for the Python package's vectorised apply (docs/python.md, "Speed").
**
**  Not a second model: the same IEEE operations in the same order as the
**  core's scalar pm_model_apply (lib/model.cpp, lib/pm_detail.hpp), so that
**  every lane gives the scalar call's doubles bit for bit.  The templates of
**  lib/pm_detail.hpp that are written for any arithmetic type (sincos_core,
**  quadrant, harmonics_n, shifted, framed_rotations, framed_product,
**  atan_plus, asin_plus) are instantiated
**  on the vector type; the parts of the forward that branch per point
**  (expmap, frame_angles, turn_sum_atan) are written here once more with lane
**  masks, taking only their common branch.  A point whose lane leaves that
**  branch (|ha| > 64, |dec| > 4, a NaN or infinity, a displacement beyond
**  the series of expmap, the pole's neighbourhood where frame_angles gives
**  way to atan2, a sum that crosses +-pi twice) is evaluated again by
**  pm_model_apply itself, which also gives its error.  Models this path does
**  not cover (added terms, context inputs, |c'| or |e'| > 0.5, an order
**  beyond 4, an unprepared or stale model) go to pm_model_apply point by
**  point (apply_batch's caller decides: apply_simd_ok).
**
**  A change to the core's forward model must be made here too:
**  python/tests/test_lanes.py compares every path with the scalar call bit
**  for bit and fails otherwise.
**
**  Included inside a namespace of its own by apply_w2.cpp, apply_w4.cpp and
**  apply_w8.cpp (after lib/pm_detail.hpp, in the same namespace), so that
**  the copies built with -mavx2 or -mavx512f share no symbol with the
**  core's (which runs on any x86-64).  Host code: C++17, no heap.
*/

/* The vector types of W lanes: doubles, their comparisons' masks, bits. */
template <int W> struct RawOf {
    typedef double raw __attribute__((vector_size(8 * W)));
    typedef long long mask __attribute__((vector_size(8 * W)));
    typedef unsigned long long bits __attribute__((vector_size(8 * W)));
};

/* The widest vector of the machine the file is built for. */
#if defined(__AVX512F__)
const int NATIVE_W = 8;
#elif defined(__AVX__)
const int NATIVE_W = 4;
#else
const int NATIVE_W = 2;
#endif

/* W doubles in one vector, with the operators the core's templates use
** (a double converts to a vector of W copies of it). */
template <int W> struct VD {
    typedef typename RawOf<W>::raw raw;
    raw v;
    VD() = default;
    VD(double x)
    {
        for (int i = 0; i < W; i++)
            v[i] = x;
    }
    explicit VD(raw r) : v(r) {}
    friend VD operator+(VD a, VD b) { return VD(a.v + b.v); }
    friend VD operator-(VD a, VD b) { return VD(a.v - b.v); }
    friend VD operator*(VD a, VD b) { return VD(a.v * b.v); }
    friend VD operator/(VD a, VD b) { return VD(a.v / b.v); }
    friend VD operator-(VD a) { return VD(-a.v); }
    VD &operator+=(VD b)
    {
        v += b.v;
        return *this;
    }
};

template <int W> struct Lanes {
    typedef typename RawOf<W>::raw raw;
    typedef typename RawOf<W>::mask mask;
    typedef typename RawOf<W>::bits bits;

    static raw load(const double *p)
    {
        raw r;
        __builtin_memcpy(&r, p, sizeof r);
        return r;
    }
    static void store(double *p, raw r) { __builtin_memcpy(p, &r, sizeof r); }
    static raw sel(mask m, raw a, raw b) { return (raw)(((bits)a & (bits)m) | ((bits)b & ~(bits)m)); }
    static raw fabs(raw x) { return (raw)((bits)x & 0x7fffffffffffffffULL); }
    /* Comparisons (all ones where true).  Twice the machine's width is two
    ** of its vectors (two chains side by side): compared half by half (gcc
    ** would compare them lane by lane in scalar code). */
    static constexpr bool halves = W > NATIVE_W;
    template <class F> static mask cmp(raw a, raw b, F f)
    {
        if constexpr (halves) {
            typedef RawOf<W / 2> H;
            typename H::raw x[2], y[2];
            typename H::mask z[2];
            __builtin_memcpy(x, &a, sizeof a);
            __builtin_memcpy(y, &b, sizeof b);
            z[0] = Lanes<W / 2>::cmp(x[0], y[0], f);
            z[1] = Lanes<W / 2>::cmp(x[1], y[1], f);
            mask r;
            __builtin_memcpy(&r, z, sizeof r);
            return r;
        } else
            return (mask)f(a, b);
    }
    static mask le(raw a, raw b) { return cmp(a, b, [](auto x, auto y) { return x <= y; }); }
    static mask lt(raw a, raw b) { return cmp(a, b, [](auto x, auto y) { return x < y; }); }
    static mask eq(raw a, raw b) { return cmp(a, b, [](auto x, auto y) { return x == y; }); }
    static raw all(double x) { return VD<W>(x).v; }
    static raw sqrt(raw x)
    {
        if constexpr (halves) {
            typename RawOf<W / 2>::raw h[2];
            __builtin_memcpy(h, &x, sizeof x);
            h[0] = Lanes<W / 2>::sqrt(h[0]);
            h[1] = Lanes<W / 2>::sqrt(h[1]);
            __builtin_memcpy(&x, h, sizeof x);
            return x;
        } else if constexpr (W == 2)
            return _mm_sqrt_pd(x);
        else if constexpr (W == 4)
            return _mm256_sqrt_pd(x);
        else {
#if defined(__AVX512F__)
            return _mm512_mask_sqrt_pd(x, 0xff, x); /* (_mm512_sqrt_pd: a warning in gcc 12) */
#endif
        }
    }
    /* sincos_d for |x| <= 64 (the caller's mask): sincos_core and quadrant,
    ** as sincos_d2 runs them on SSE2 pairs */
    __attribute__((always_inline)) static void sincos(raw x, raw *s, raw *c)
    {
        raw sr, cr, kr;
        bits us, uc;
        sincos_core(x, &sr, &cr, &kr);
        quadrant((bits)kr, (bits)sr, (bits)cr, &us, &uc);
        *s = (raw)us;
        *c = (raw)uc;
    }
};

/* The model's constants in W lanes (once per batch). */
template <int W, int LC> struct Consts {
    Iso<VD<W>> k;
    VD<W> dense[PM_N_HARM(LC)][6];
    double c, e; /* c', e' (coef[2], coef[4]) */
};

template <int W, int LC> inline void consts_of(const pm_model *m, Consts<W, LC> *o)
{
    iso_from_model<VD<W>>(m, &o->k);
    for (int j = 0; j < PM_N_HARM(LC); j++)
        for (int kk = 0; kk < 6; kk++)
            o->dense[j][kk] = VD<W>(m->dense[j][kk]);
    o->c = m->coef[2];
    o->e = m->coef[4];
}

/* The harmonic sums S[k] = sum over j >= 1 of dense[j][k] Y[j] in the order
** of the core's: HarmSums<double, double, LC> on SSE2 (the odd harmonics
** with j = 1 in one sum, the even ones in another from zero, added at the
** end), else the generic HarmSums (in the order of j). */
template <int W, int LC>
inline void harm_sums(const Consts<W, LC> &K, const VD<W> *Y, VD<W> *S)
{
    const int N = PM_N_HARM(LC);
    if constexpr (LC == 0) {
        for (int kk = 0; kk < 6; kk++)
            S[kk] = VD<W>(0.0);
        (void)K;
        (void)Y;
        (void)N;
    } else {
#if defined(__SSE2__) && !defined(PM_SCALAR_SUMS)
        VD<W> s[6], t[6];
#pragma GCC unroll 6
        for (int kk = 0; kk < 6; kk++) {
            s[kk] = K.dense[1][kk] * Y[1];
            t[kk] = VD<W>(0.0);
        }
#pragma GCC unroll 32
        for (int j = 2; j < N; j++) {
#pragma GCC unroll 6
            for (int kk = 0; kk < 6; kk++) {
                if (j & 1)
                    s[kk] += K.dense[j][kk] * Y[j];
                else
                    t[kk] += K.dense[j][kk] * Y[j];
            }
        }
#pragma GCC unroll 6
        for (int kk = 0; kk < 6; kk++)
            S[kk] = s[kk] + t[kk];
#else
#pragma GCC unroll 6
        for (int kk = 0; kk < 6; kk++)
            S[kk] = K.dense[1][kk] * Y[1];
#pragma GCC unroll 32
        for (int j = 2; j < N; j++)
#pragma GCC unroll 6
            for (int kk = 0; kk < 6; kk++)
                S[kk] += K.dense[j][kk] * Y[j];
#endif
    }
}

/* W points from index i: the results into a[i..], b[i..]; returns the lanes
** (bit j for point i + j) whose point left the common branch (to be
** evaluated by pm_model_apply). */
template <int W, int LC>
inline unsigned apply_block(const Consts<W, LC> &K, const double *ha, const double *dec,
                            double *oa, double *ob)
{
    typedef Lanes<W> Ln;
    typedef typename Ln::raw raw;
    typedef typename Ln::mask mask;
    typedef VD<W> V;
    const Iso<V> &k = K.k;
    const raw t = Ln::load(ha), d = Ln::load(dec);
    /* sincos_d2's and frame_angles' ranges (false for NaN) */
    mask ok = Ln::le(Ln::fabs(t), Ln::all(64.0)) & Ln::le(Ln::fabs(d), Ln::all(4.0));
    /* trig_of */
    Trig<V> g;
    Ln::sincos(t, &g.st.v, &g.ct.v);
    Ln::sincos(d, &g.sd.v, &g.cd.v);
    g.t = V(t);
    g.d = V(d);
    g.have_angles = true;
    /* forward_framed: the shifted position, aniso (sh_sums, aniso_of_sums
    ** without added terms), expmap, the composed rotations */
    V stp, ctp, sdp, cdp;
    shifted<V>(k, g, &stp, &ctp, &sdp, &cdp);
    V S[6];
    {
        /* the harmonics at the shifted position (shifted_trig) */
        Trig<V> gs;
        gs.st = stp;
        gs.ct = ctp;
        gs.sd = sdp;
        gs.cd = cdp;
        gs.t = gs.d = V(0.0);
        gs.have_angles = false;
        V Y[PM_N_HARM(LC)];
        if constexpr (LC > 0)
            harmonics_n<V, LC>(LC, gs, Y);
        harm_sums<W, LC>(K, Y, S);
    }
    const V sc = sdp * ctp, ss = sdp * stp;
    const V dt = ((cdp * S[2] + S[5]) - sc * S[0]) - (ss * S[1] + sdp * S[3]);
    const V dd = (S[0] * stp - S[4]) - S[1] * ctp;
    const V r2 = dt * dt + dd * dd;
    ok &= Ln::lt(r2.v, Ln::all(1e-4)); /* expmap's series */
    const V r4 = r2 * r2;
    const V c = (1 - 0.5 * r2) + r4 * ((1.0 / 24) - r2 * (1.0 / 720));
    const V s = (1 - (1.0 / 6) * r2) + r4 * ((1.0 / 120) - r2 * (1.0 / 5040));
#if PM_COMPOSED_FORWARD
    /* framed_rotations and framed_product: for AVX2 and AVX-512 row by
    ** row (the same operations, fewer values live at once: avx2x2 spilled
    ** at order 2, ~25 ns a point against ~20), for SSE2 as the core writes
    ** them (row by row, sse2x2 took ~83 ns a point at order 2) */
    V3<V> p;
    if constexpr (NATIVE_W < 4) {
        V F[9];
        framed_rotations<V>(k, stp, ctp, sdp, cdp, F);
        p = framed_product<V>(F, dt, dd, c, s);
    } else {
        const V a0 = sdp * k.ci, a1 = sdp * k.si;
        const V b0 = cdp * k.ci, nb1 = cdp * k.si;
        const V b3 = k.cd * k.si - k.sd * a0, b4 = k.cd * k.ci + k.sd * a1, nb5 = k.sd * cdp;
        const V b6 = k.sd * k.si + k.cd * a0, b7 = k.sd * k.ci - k.cd * a1, b8 = k.cd * cdp;
        const V *h = k.h;
        const V d04 = h[0] - h[4], s13 = h[1] + h[3];
        const V e0 = stp * (stp * d04 - ctp * s13), e1 = stp * (stp * s13 + ctp * d04);
        {
            const V g0 = h[0] - e0, g1 = h[1] - e1, g2 = ctp * h[2] + stp * h[5];
            const V F0 = (g0 * b0 + g1 * b3) + g2 * b6, F1 = (g1 * b4 - g0 * nb1) + g2 * b7,
                    F2 = g2 * b8 - (g0 * sdp + g1 * nb5);
            p.x = c * F0 + s * (F1 * dt + F2 * dd);
        }
        {
            const V g3 = h[3] - e1, g4 = h[4] + e0, g5 = ctp * h[5] - stp * h[2];
            const V F3 = (g3 * b0 + g4 * b3) + g5 * b6, F4 = (g4 * b4 - g3 * nb1) + g5 * b7,
                    F5 = g5 * b8 - (g3 * sdp + g4 * nb5);
            p.y = c * F3 + s * (F4 * dt + F5 * dd);
        }
        {
            const V g6 = ctp * h[6] + stp * h[7], g7 = ctp * h[7] - stp * h[6], g8 = h[8];
            const V F6 = (g6 * b0 + g7 * b3) + g8 * b6, F7 = (g7 * b4 - g6 * nb1) + g8 * b7,
                    F8 = g8 * b8 - (g6 * sdp + g7 * nb5);
            p.z = c * F6 + s * (F7 * dt + F8 * dd);
        }
    }
#else
    V3<V> w = v3<V>(c, dt * s, dd * s);
    w = rot_z<V>(k.si, k.ci, w);
    w = rot_d<V>(sdp, cdp, w);
    w = rot_x<V>(k.sd, k.cd, w);
    w = rot_z<V>(stp, ctp, w);
    const V3<V> p = rot_zt<V>(stp, ctp, mat_mul<V>(k.h, w));
#endif
    /* frame_angles (the model's |c'|, |e'| <= 0.5: apply_simd_ok) */
    const mask flip = Ln::lt(cdp.v, Ln::all(0.0));
    const V sD = sdp, cD(Ln::sel(flip, -cdp.v, cdp.v));
    const V x1(Ln::sel(flip, -p.x.v, p.x.v)), y1(Ln::sel(flip, -p.y.v, p.y.v));
    const V rho(Ln::sqrt((x1 * x1 + y1 * y1).v));
    const V zn = p.z * cD - rho * sD, zd = rho * cD + p.z * sD;
    ok &= Ln::le(Ln::fabs(y1.v), (0.01 * x1).v) & Ln::le(Ln::fabs(zn.v), Ln::all(0.01)) &
          Ln::lt(Ln::all(0.0), zd.v);
    /* turn_sum_atan(t, c', y1 / x1, flip), its first try (the second: the
    ** scalar call) */
    const V half(Ln::sel(flip, Ln::all(0.5), Ln::all(0.0)));
    const V two(Ln::sel(flip, Ln::all(2.0), Ln::all(0.0)));
    const V tv(t), r = y1 / x1;
    const V n = ((tv * 0.15915494309189535 + half) + RND_INT) - RND_INT;
    const V q = 4 * n - two;
    const V a = (tv - q * PIO2_1) + atan_plus<V>((K.c - q * PIO2_2) - q * PIO2_3, r);
    ok &= Ln::le(Ln::fabs(a.v), Ln::all(PI));
    raw T = Ln::sel(Ln::eq(a.v, Ln::all(-PI)), Ln::all(PI), a.v);
    /* the declination: d + asin_plus(-e', zn), or beyond the pole (the
    ** sums of frame_angles) */
    const V dv(d), ev(K.e);
    const V d0 = dv + asin_plus<V>(-ev, zn);
    const V dp = (2 * PIO2_1 - dv) + asin_plus<V>((ev + 2 * PIO2_2) + 2 * PIO2_3, zn);
    const V dm = -((2 * PIO2_1 + dv) + asin_plus<V>((2 * PIO2_2 - ev) + 2 * PIO2_3, -zn));
    const raw da = Ln::sel(flip, Ln::sel(Ln::lt(Ln::all(0.0), (dv - ev).v), dp.v, dm.v), d0.v);
    const mask out = ~Ln::le(Ln::fabs(da), Ln::all(PI / 2));
    const raw D = Ln::sel(out, Ln::sel(Ln::lt(da, Ln::all(0.0)), Ln::all(-PI / 2), Ln::all(PI / 2)), da);
    /* pm_model_apply's ending: finite, -pi as pi */
    ok &= Ln::eq(T - T, Ln::all(0.0)) & Ln::eq(D - D, Ln::all(0.0));
    T = Ln::sel(Ln::le(T, Ln::all(-PI)), Ln::all(PI), T);
    Ln::store(oa, T);
    Ln::store(ob, D);
    unsigned redo = 0;
    for (int j = 0; j < W; j++)
        if (!ok[j])
            redo |= 1u << j;
    return redo;
}

/* Can apply_batch take this model: prepared and not stale, no context
** inputs, only the base terms, |c'|, |e'| <= 0.5, order 0..4. */
inline bool apply_simd_ok(const pm_model *m)
{
    return model_ready(m) == PM_OK && !m->needs_ctx && m->n_terms == m->n_base &&
           !abs_beyond(m->coef[2], 0.5) && !abs_beyond(m->coef[4], 0.5) && m->order >= 0 &&
           m->order <= 4 && m->order <= PM_MAX_L;
}

template <int W, int LC>
long apply_run(const pm_model *m, long n, const double *ha, const double *dec, double *oa,
               double *ob, pm_status *st)
{
    Consts<W, LC> K;
    consts_of<W, LC>(m, &K);
    long i = 0;
    for (; i + W <= n; i += W) {
        unsigned redo = apply_block<W, LC>(K, ha + i, dec + i, oa + i, ob + i);
        for (int j = 0; redo; j++, redo >>= 1)
            if (redo & 1) {
                pm_status s = pm_model_apply(m, nullptr, ha[i + j], dec[i + j], oa + i + j,
                                             ob + i + j);
                if (s < 0) {
                    *st = s;
                    return i + j;
                }
            }
    }
    for (; i < n; i++) { /* the tail: the scalar call */
        pm_status s = pm_model_apply(m, nullptr, ha[i], dec[i], oa + i, ob + i);
        if (s < 0) {
            *st = s;
            return i;
        }
    }
    return -1;
}

/* pm_model_apply (no context) on points 0..n-1, W at a time: returns the
** index of the first point whose call failed (its status in *st; the
** points before it are evaluated, the ones after it may be), else -1.  The
** model must pass apply_simd_ok. */
template <int W>
long apply_batch(const pm_model *m, long n, const double *ha, const double *dec, double *oa,
                 double *ob, pm_status *st)
{
    switch (m->order) {
    case 0: return apply_run<W, 0>(m, n, ha, dec, oa, ob, st);
    case 1: return apply_run<W, 1>(m, n, ha, dec, oa, ob, st);
#if PM_MAX_L >= 2
    case 2: return apply_run<W, 2>(m, n, ha, dec, oa, ob, st);
#endif
#if PM_MAX_L >= 3
    case 3: return apply_run<W, 3>(m, n, ha, dec, oa, ob, st);
#endif
#if PM_MAX_L >= 4
    case 4: return apply_run<W, 4>(m, n, ha, dec, oa, ob, st);
#endif
    default: break;
    }
    for (long i = 0; i < n; i++) { /* (apply_simd_ok keeps this out) */
        pm_status s = pm_model_apply(m, nullptr, ha[i], dec[i], oa + i, ob + i);
        if (s < 0) {
            *st = s;
            return i;
        }
    }
    return -1;
}
