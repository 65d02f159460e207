/*
**  probe.h - the evaluation counter of tests/check_bounded.c: the core is
**  compiled for that suite with -include tests/probe.h and
**  PM_EVAL_PROBE()=pm_probe_hit() (Makefile), so each model evaluation
**  calls the suite's pm_probe_hit.
*/
#ifndef PM_PROBE_H
#define PM_PROBE_H
#ifdef __cplusplus
extern "C" {
#endif
void pm_probe_hit(void);
#ifdef __cplusplus
}
#endif
#endif
