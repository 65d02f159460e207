// The vectorised pm_model_apply on SSE2 (every x86-64), and the choice of
// path (apply_lanes.h).  Elsewhere: only the scalar call per point.
#include "apply_lanes.h"

namespace {
long scalar_loop(const pm_model *m, long n, const double *ha, const double *dec, double *oa,
                 double *ob, pm_status *st)
{
    for (long i = 0; i < n; i++) {
        pm_status s = pm_model_apply(m, nullptr, ha[i], dec[i], oa + i, ob + i);
        if (s < 0) {
            *st = s;
            return i;
        }
    }
    return -1;
}
} // namespace

#if defined(__x86_64__) && defined(__SSE2__)
#include <immintrin.h>
namespace pm_lanes2 {
#include "../lib/pm_detail.hpp"
namespace pm {
namespace detail {
#include "apply_simd.hpp"
} // namespace detail
} // namespace pm
} // namespace pm_lanes2

#if defined(PM_LANES_OFF) /* the core rounds with FMA (python/python.mk) */
bool pm_apply_lanes_ok(const pm_model *) { return false; }
#else
bool pm_apply_lanes_ok(const pm_model *m) { return pm_lanes2::pm::detail::apply_simd_ok(m); }
#endif

// (__builtin_cpu_supports checks that the OS saves the registers, too)
bool pm_lanes_runs(int path)
{
    switch (path) {
    case PM_LANES_SCALAR:
    case PM_LANES_SSE2:
    case PM_LANES_SSE2X2: return true;
    case PM_LANES_AVX2:
    case PM_LANES_AVX2X2: return __builtin_cpu_supports("avx2");
    case PM_LANES_AVX512:
    case PM_LANES_AVX512X2:
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f");
    default: return false;
    }
}

int pm_lanes_best(void)
{
    return pm_lanes_runs(PM_LANES_AVX512X2) ? PM_LANES_AVX512X2
           : pm_lanes_runs(PM_LANES_AVX2X2) ? PM_LANES_AVX2X2
                                            : PM_LANES_SSE2X2;
}

long pm_apply_lanes(int path, const pm_model *m, long n, const double *ha, const double *dec,
                    double *oa, double *ob, pm_status *st)
{
    using pm_lanes2::pm::detail::apply_batch;
    switch (path) {
    case PM_LANES_SSE2: return apply_batch<2>(m, n, ha, dec, oa, ob, st);
    case PM_LANES_SSE2X2: return apply_batch<4>(m, n, ha, dec, oa, ob, st);
    case PM_LANES_AVX2: return pm_apply_avx2(0, m, n, ha, dec, oa, ob, st);
    case PM_LANES_AVX2X2: return pm_apply_avx2(1, m, n, ha, dec, oa, ob, st);
    case PM_LANES_AVX512: return pm_apply_avx512(0, m, n, ha, dec, oa, ob, st);
    case PM_LANES_AVX512X2: return pm_apply_avx512(1, m, n, ha, dec, oa, ob, st);
    default: return scalar_loop(m, n, ha, dec, oa, ob, st);
    }
}
#else
bool pm_apply_lanes_ok(const pm_model *) { return false; }
bool pm_lanes_runs(int path) { return path == PM_LANES_SCALAR; }
int pm_lanes_best(void) { return PM_LANES_SCALAR; }
long pm_apply_lanes(int, const pm_model *m, long n, const double *ha, const double *dec,
                    double *oa, double *ob, pm_status *st)
{
    return scalar_loop(m, n, ha, dec, oa, ob, st);
}
#endif

const char *pm_lanes_name(int path)
{
    static const char *const names[PM_LANES_N_PATHS] = {
        "scalar", "sse2", "sse2x2", "avx2", "avx2x2", "avx512", "avx512x2"};
    return path >= 0 && path < PM_LANES_N_PATHS ? names[path] : nullptr;
}
