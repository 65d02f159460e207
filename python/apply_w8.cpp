// The vectorised pm_model_apply on AVX-512F (apply_lanes.h), compiled with
// -mavx512f -ffp-contract=off (python/python.mk; no FMA instruction is
// emitted without contraction: the build checks): run only where
// pm_lanes_runs(PM_LANES_AVX512).  Its own namespace, as apply_w4.cpp.
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

long pm_apply_avx512(int x2, const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    using pm_lanes8::pm::detail::apply_batch;
    return x2 ? apply_batch<16>(m, n, ha, dec, oa, ob, st)
              : apply_batch<8>(m, n, ha, dec, oa, ob, st);
}
#else
long pm_apply_avx512(int, const pm_model *m, long n, const double *ha, const double *dec,
                     double *oa, double *ob, pm_status *st)
{
    return pm_apply_lanes(PM_LANES_SCALAR, m, n, ha, dec, oa, ob, st);
}
#endif
