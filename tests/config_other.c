/*
**  config_other.c - PM_CHECK_CONFIG() as a program built with another
**  PM_MAX_AUX sees it: compiled (Makefile) with -DPM_MAX_AUX=1 and with
**  -DPM_MAX_AUX=8, each under its own name (CONFIG_FN), and linked into
**  tests/check_model.c against the library of the default capacities.
*/
#include "pm.h"

int CONFIG_FN(void);
int CONFIG_FN(void) { return (int)PM_CHECK_CONFIG(); }
