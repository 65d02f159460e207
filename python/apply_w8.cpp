// The vectorised pm_model_apply in 8 lanes (AVX-512F), compiled with
// -mavx512f -ffp-contract=off (python/python.mk): called only where
// pm_apply_lanes_max() is 8.  Its own namespace, as apply_w4.cpp.
#include "apply_lanes.h"
#if defined(__x86_64__) && defined(__AVX512F__)
#include <immintrin.h>
namespace pm_lanes8 {
#include "../lib/pm_detail.hpp"
namespace pm {
namespace detail {
#include "apply_simd.hpp"
} // namespace detail
} // namespace pm
} // namespace pm_lanes8

long pm_apply_lanes8(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    return pm_lanes8::pm::detail::apply_batch<8>(m, n, ha, dec, oa, ob, st);
}
#else
long pm_apply_lanes8(const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    return pm_apply_lanes4(m, n, ha, dec, oa, ob, st);
}
#endif
