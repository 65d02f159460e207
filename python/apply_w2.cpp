// The vectorised pm_model_apply in 2 lanes (SSE2: every x86-64), and which
// width this machine runs (apply_lanes.h).  Elsewhere: the scalar call per point.
#include "apply_lanes.h"
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

bool pm_apply_lanes_ok(const pm_model *m) { return pm_lanes2::pm::detail::apply_simd_ok(m); }

long pm_apply_lanes2(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    return pm_lanes2::pm::detail::apply_batch<2>(m, n, ha, dec, oa, ob, st);
}

// AVX-512F (8 lanes) where the CPU and the OS have it, else AVX2 (4), else
// SSE2 (2; every x86-64).  (__builtin_cpu_supports checks the OS's saving of
// the registers too.)
int pm_apply_lanes_max(void)
{
    const bool avx2 = __builtin_cpu_supports("avx2");
    return avx2 && __builtin_cpu_supports("avx512f") ? 8 : avx2 ? 4 : 2;
}
#else
bool pm_apply_lanes_ok(const pm_model *) { return false; }
long pm_apply_lanes2(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
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
int pm_apply_lanes_max(void) { return 1; }
#endif
