/*
**  track_worst_cm.c - the dearest tracking ticks on a Cortex-M, under QEMU.
**
**  The 8,000 steady-state ticks of tests/check_bounded.c
**  (test_bounded_track_state_beyond_half_degree; tests/hard_cases.h:
**  hc_track_model, hc_track_case): realistic L = 1-2 models, half the
**  targets 0.5-5 deg from the mount's pole, ticks of 1 ms-0.1 s, state
**  three ticks in.  Each tick is measured twice, as pm_model_invert_near
**  from the state's position and as pm_model_track, between readings of
**  the instruction counter (firmware_demo/fw_platform.h: SysTick under
**  "qemu -icount shift=0", 40 instructions a count).  Prints every tick
**  above 5,000 instructions and the worst of each call ("BENCH {json}"),
**  the figures behind PM_BUDGET_M7_TRACK_INSNS in include/pm.h
**  (check_bounded counts the same ticks' evaluations on the host).
**
**    make bench-track-worst      (the Cortex-M7 build, ~2 s under QEMU)
**
**  Built with -DPROFILE_MODEL=I -DPROFILE_TICK=J it marks that tick's two
**  calls for bench/qemu_profile.py (instructions per function).
*/
#include <stdio.h>

#include "fw_platform.h"
#include "hard_cases.h"

#ifndef PROFILE_MODEL
#define PROFILE_MODEL (-1)
#define PROFILE_TICK (-1)
#endif

/* bench/qemu_profile.py's region markers (calls it can see) */
__attribute__((noinline)) void marker_begin(void) { __asm volatile(""); }
__attribute__((noinline)) void marker_end(void) { __asm volatile(""); }

int main(void)
{
    tu_rng r;
    unsigned long worst[2] = {0, 0}, cal;
    double rho_w[2] = {0, 0};
    int i, j, n = 0, bad = 0;
    fw_counter_init();
    cal = fw_counter_calibrate(100000UL);
    if (cal < 200000UL - 50 || cal > 200000UL + 100) {
        printf("the instruction counter is off: is QEMU running with -icount shift=0?\n");
        return 1;
    }
    tu_seed(&r, 1819);
    for (i = 0; i < 200; i++) {
        pm_model m;
        if (hc_track_model(&m, &r, i) != 0)
            return 1;
        for (j = 0; j < 40; j++) {
            hc_track_tick c;
            double x[2];
            unsigned long c0, c1, c2, ins[2];
            int k, mark;
            if (hc_track_case(&m, &r, j, &c) != 0)
                return 1;
            mark = i == PROFILE_MODEL && j == PROFILE_TICK;
            if (mark)
                marker_begin();
            c0 = fw_counter();
            bad += pm_model_invert_near(&m, NULL, c.ah, c.ad, c.tk.enc[0], c.tk.enc[1], &x[0],
                                        &x[1]) != PM_OK;
            c1 = fw_counter();
            if (mark) {
                marker_end();
                marker_begin();
            }
            bad += pm_model_track(&m, NULL, &c.tk, c.ah, c.ad, &x[0], &x[1]) != PM_OK;
            c2 = fw_counter();
            if (mark)
                marker_end();
            ins[0] = fw_counter_insns(c0, c1);
            ins[1] = fw_counter_insns(c1, c2);
            for (k = 0; k < 2; k++)
                if (ins[k] > worst[k]) {
                    worst[k] = ins[k];
                    rho_w[k] = c.rho / DEG;
                }
            if (ins[0] > 5000 || ins[1] > 5000)
                printf("BENCH {\"name\": \"%s_track_tick\", \"model\": %d, \"tick\": %d, "
                       "\"pole_deg\": %.3f, \"dt\": %g, \"invert_near\": %lu, \"track\": %lu}\n",
                       fw_target(), i, j, c.rho / DEG, c.dt, ins[0], ins[1]);
            n++;
        }
    }
    printf("BENCH {\"name\": \"%s_track_worst\", \"ticks\": %d, \"invert_near\": %lu, "
           "\"invert_near_pole_deg\": %.3f, \"track\": %lu, \"track_pole_deg\": %.3f, "
           "\"not_ok\": %d}\n", fw_target(), n, worst[0], rho_w[0], worst[1], rho_w[1], bad);
    return bad ? 1 : 0;
}
