// The vectorised pm_model_apply in 4 lanes (AVX2), compiled with -mavx2
// -mno-fma -ffp-contract=off (python/python.mk): called only where
// pm_apply_lanes_max() is 4.  Its own namespace: none of the core's inline
// functions built here for AVX2 can stand in for the core's own.
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

long pm_apply_lanes4(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    return pm_lanes4::pm::detail::apply_batch<4>(m, n, ha, dec, oa, ob, st);
}
#else
long pm_apply_lanes4(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    return pm_apply_lanes2(m, n, ha, dec, oa, ob, st);
}
#endif
