// The vectorised pm_model_apply on AVX2 (apply_lanes.h), compiled with
// -mavx2 -mno-fma -ffp-contract=off (python/python.mk): run only where
// pm_lanes_runs(PM_LANES_AVX2).  Its own namespace: none of the core's
// inline functions built here for AVX2 can stand in for the core's own.
#include "apply_lanes.h"
#if defined(__x86_64__) && defined(__AVX2__)
#include <immintrin.h>
namespace pm_lanes4 {
#include "../lib/pm_detail.hpp"
namespace pm {
namespace detail {
#include "apply_simd.hpp"
} // namespace detail
} // namespace pm
} // namespace pm_lanes4

long pm_apply_avx2(int x2, const pm_model *m, long n, const double *ha, const double *dec,
                   double *oa, double *ob, pm_status *st)
{
    using pm_lanes4::pm::detail::apply_batch;
    return x2 ? apply_batch<8>(m, n, ha, dec, oa, ob, st)
              : apply_batch<4>(m, n, ha, dec, oa, ob, st);
}
#else
long pm_apply_avx2(int, const pm_model *m, long n, const double *ha, const double *dec,
                   double *oa, double *ob, pm_status *st)
{
    return pm_apply_lanes(PM_LANES_SCALAR, m, n, ha, dec, oa, ob, st);
}
#endif
