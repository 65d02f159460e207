/*
**  internal_shim.cpp - the core's internal math helpers (lib/pm_detail.hpp)
**  behind C entry points for tests/check_internal.c, compiled with the
**  core's flags (Makefile).  Test-only: the library exports none of this.
*/
#include "../lib/pm_detail.hpp"

extern "C" {
void pm_test_sincos_d(double x, double *s, double *c) { pm::detail::sincos_d(x, s, c); }
void pm_test_sincos_d2(double x0, double x1, double *s0, double *c0, double *s1, double *c1)
{
    pm::detail::sincos_d2(x0, x1, s0, c0, s1, c1);
}
}
