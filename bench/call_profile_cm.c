/*
**  call_profile_cm.c - one cold pm_model_invert (or, with -DPROFILE_FWD,
**  one pm_model_apply) per position between marker_begin and marker_end,
**  for bench/qemu_profile.py: instructions per function of a Cortex-M7
**  call, the bench's L = 2 model (bench/bench_common.c's terms), 16 of its
**  positions.  docs/performance.md, "A series start, tried, and the floor
**  of this iteration (stop 36)".  Not part of make bench; by hand:
**
**    make build/bench/m7/platform_cm.o build/bench/m7/core/model.o \
**         build/bench/m7/core/fit.o build/bench/m7/core/model_f.o
**    F="-mthumb -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard"
**    arm-none-eabi-gcc -std=c89 -O2 -Iinclude $F [-DPROFILE_FWD] \
**        bench/call_profile_cm.c build/bench/m7/platform_cm.o \
**        build/bench/m7/core/model.o build/bench/m7/core/fit.o \
**        build/bench/m7/core/model_f.o -o /tmp/p.elf \
**        -T firmware_demo/cortex_m.ld -nostartfiles --specs=rdimon.specs \
**        -Wl,--gc-sections -lm
**    qemu-system-arm -M mps2-an500 -nographic -semihosting \
**        -icount shift=0,align=off,sleep=off -kernel /tmp/p.elf \
**        -singlestep -d exec,nochain,in_asm -D /tmp/q.log
**    python3 bench/qemu_profile.py /tmp/q.log --calls 1
*/
#include <math.h>
#include <stdio.h>

#include "pm.h"

#define PI 3.14159265358979323846
#define ARCSEC (PI / 648000.0)
#define DEG (PI / 180.0)

__attribute__((noinline)) void marker_begin(void) { __asm volatile(""); }
__attribute__((noinline)) void marker_end(void) { __asm volatile(""); }

/* bench_common.c's generator: the same terms and positions */
static double lcg_pm1(unsigned long *s)
{
    *s = (*s * 1664525UL + 1013904223UL) & 0xFFFFFFFFUL;
    return (double)(*s >> 8) / 8388608.0 - 1.0;
}

static pm_model m;

int main(void)
{
    static const double iso_arcsec[6] = {95, -140, 1200, 35, -420, -50};
    const double z0 = sin(-50 * DEG), z1 = sin(85 * DEG);
    unsigned long s = 2026UL + 2;
    double acc = 0, eh, ed, ah, ad, u, v;
    int i, bad = 0;
    if (pm_model_init(&m, PM_MOUNT_EQUATORIAL, 2) != PM_OK)
        return 1;
    for (i = 0; i < m.n_terms; i++)
        m.coef[i] = i < 6 ? iso_arcsec[i] * ARCSEC : 15.0 * ARCSEC * sqrt(3.0) * lcg_pm1(&s);
    if (pm_model_prepare(&m) != PM_OK)
        return 1;
    for (i = 0; i < 16; i++) {
        u = 0.5 * (lcg_pm1(&s) + 1);
        v = lcg_pm1(&s);
        eh = PI * v;
        ed = asin(z0 + (z1 - z0) * u);
        bad += pm_model_apply(&m, 0, eh, ed, &ah, &ad) != PM_OK;
        marker_begin();
#ifdef PROFILE_FWD
        bad += pm_model_apply(&m, 0, eh, ed, &ah, &ad) != PM_OK;
#else
        bad += pm_model_invert(&m, 0, ah, ad, PM_SIDE_NORMAL, &eh, &ed) != PM_OK;
#endif
        marker_end();
        acc += eh + ed;
    }
    printf("call_profile_cm: %d calls not PM_OK, checksum %.6f\n", bad, acc);
    return bad != 0;
}
