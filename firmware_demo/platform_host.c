/*
**  platform_host.c - the hosted build of the demo: no instruction counter
**  and no stack gauge (the bench measures the host; see bench/).
*/
#include "fw_platform.h"

const char *fw_target(void) { return "host"; }
int fw_counter_available(void) { return 0; }
void fw_counter_init(void) {}
unsigned long fw_counter(void) { return 0; }
unsigned long fw_counter_insns(unsigned long start, unsigned long end)
{
    (void)start;
    (void)end;
    return 0;
}
unsigned long fw_counter_calibrate(unsigned long n_iter)
{
    (void)n_iter;
    return 0;
}
int fw_stack_available(void) { return 0; }
void fw_stack_paint(void) {}
unsigned long fw_stack_depth(void) { return 0; }
