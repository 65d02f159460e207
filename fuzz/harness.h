/*
**  harness.h - the fuzz harnesses: one function per target, called by the
**  libFuzzer entry point (fuzz/fuzz_<target>.c, which aborts on a nonzero
**  result) and by the regression test tests/check_fuzz_regress.c (which
**  fails the test).  Each returns 0, or 1 after printing the invariant that
**  broke to stderr.  README.md lists the invariants.
*/
#ifndef PMFZ_HARNESS_H
#define PMFZ_HARNESS_H

#include <stddef.h>

int pmfz_runfile(const unsigned char *data, size_t size);
int pmfz_modelfile(const unsigned char *data, size_t size);
int pmfz_capi(const unsigned char *data, size_t size);
int pmfz_fit(const unsigned char *data, size_t size);
int pmfz_explain(const unsigned char *data, size_t size);
int pmfz_plan(const unsigned char *data, size_t size);

#endif
