/*
**  bench_cm.c - instructions per call on Cortex-M, under QEMU.
**
**  The same cases as the host bench (bench_common.h), each run once over
**  the BENCH_NPOS positions between two readings of the instruction
**  counter (SysTick under "qemu -icount shift=0"; firmware_demo/
**  fw_platform.h), minus the loop's own cost (its empty case: "empty",
**  or for the tracking ops "empty_track10" / "empty_track1k", whose loops
**  also compute each tick's target).  The empty cases are printed as
**  measured.  Deterministic: the same
**  binary gives the same counts on every run.  Prints one line per case,
**  "BENCH {json}", and exits 0 when every call returned PM_OK.
*/
#include <math.h>
#include <stdio.h>

#include "bench_common.h"
#include "fw_platform.h"

static bench_input inputs[BENCH_NORDERS];
static volatile double sink;

/* The libm calls and arithmetic the evaluation is made of, for scale:
** instructions per call with the loop's own cost included (the "loop_"
** cases measure that alone), over the positions of order 0. */
#define LIBM_CASE(label, T, expr)                                              \
    do {                                                                       \
        unsigned long c0, c1;                                                  \
        int i;                                                                 \
        T acc = 0;                                                             \
        c0 = fw_counter();                                                     \
        for (i = 0; i < BENCH_NPOS; i++)                                       \
            acc += (expr);                                                     \
        c1 = fw_counter();                                                     \
        sink += acc;                                                           \
        printf("BENCH {\"name\": \"%s_libm_%s\", \"instructions\": %.1f}\n", \
               fw_target(), label, (double)fw_counter_insns(c0, c1) / BENCH_NPOS); \
    } while (0)

static void libm_costs(void)
{
    static float fh[BENCH_NPOS], fd[BENCH_NPOS];
    const bench_input *in = &inputs[0];
    int i;
    for (i = 0; i < BENCH_NPOS; i++) {
        fh[i] = (float)in->eh[i];
        fd[i] = (float)in->ed[i];
    }
    LIBM_CASE("loop_double", double, in->eh[i]);
    LIBM_CASE("sin_double", double, sin(in->eh[i]));
    LIBM_CASE("atan2_double", double, atan2(in->ed[i], in->eh[i]));
    LIBM_CASE("sqrt_double", double, sqrt(in->ed[i] + 2));
    LIBM_CASE("mul_add_double", double, in->eh[i] * in->ed[i] + in->eh[i]);
    LIBM_CASE("loop_float", float, fh[i]);
    LIBM_CASE("sin_float", float, sinf(fh[i]));
    LIBM_CASE("atan2_float", float, atan2f(fd[i], fh[i]));
    LIBM_CASE("sqrt_float", float, sqrtf(fd[i] + 2));
    LIBM_CASE("mul_add_float", float, fh[i] * fd[i] + fh[i]);
}

static double insns_per_call(const bench_api *api, int slot, int op, int *bad)
{
    unsigned long c0, c1;
    *bad += bench_run(api, slot, op, &inputs[slot], 8, &sink); /* warm */
    c0 = fw_counter();
    *bad += bench_run(api, slot, op, &inputs[slot], BENCH_NPOS, &sink);
    c1 = fw_counter();
    return (double)fw_counter_insns(c0, c1) / BENCH_NPOS;
}

int main(void)
{
    int s, a, op, bad = 0;
    unsigned long cal;
    fw_counter_init();
    cal = fw_counter_calibrate(100000UL);
    printf("BENCH {\"name\": \"%s_counter_calibration\", \"instructions\": %lu, "
           "\"expected\": 200000}\n", fw_target(), cal);
    if (cal < 200000UL - 50 || cal > 200000UL + 100) {
        printf("the instruction counter is off: is QEMU running with -icount shift=0?\n");
        return 1;
    }
    if (PM_CHECK_CONFIG() != PM_OK)
        return 1;
    for (s = 0; s < BENCH_NORDERS; s++) {
        if (bench_input_make(&inputs[s], bench_orders[s]) != 0)
            return 1;
        for (a = 0; a < bench_n_apis; a++)
            if (bench_apis[a]->load(s, &inputs[s].m) != 0)
                return 1;
    }
    libm_costs();
    for (a = 0; a < bench_n_apis; a++)
        for (s = 0; s < BENCH_NORDERS; s++) {
            /* the loops' own costs first (an op's is bench_loop_op's) */
            double loop[BENCH_NOPS];
            for (op = 0; op < BENCH_NOPS; op++)
                if (bench_loop_op(op) == op && bench_op_supported(bench_apis[a], op))
                    loop[op] = insns_per_call(bench_apis[a], s, op, &bad);
            for (op = 0; op < BENCH_NOPS; op++) {
                char name[96];
                double n;
                if (!bench_op_supported(bench_apis[a], op))
                    continue;
                n = bench_loop_op(op) == op
                        ? loop[op]
                        : insns_per_call(bench_apis[a], s, op, &bad) - loop[bench_loop_op(op)];
                bench_case_name(name, sizeof name, fw_target(), op, bench_orders[s],
                                bench_apis[a]->prec);
                printf("BENCH {\"name\": \"%s\", \"instructions\": %.1f}\n", name, n);
            }
        }
    if (bad)
        printf("%d calls did not return PM_OK\n", bad);
    return bad ? 1 : 0;
}
