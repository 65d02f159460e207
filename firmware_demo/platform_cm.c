/*
**  platform_cm.c - bare-metal Cortex-M start-up for the MPS2 boards under
**  QEMU (mps2-an386: Cortex-M4F, mps2-an500: Cortex-M7), with semihosting
**  for standard output and the exit code.
**
**  Reset: copy .data, zero .bss, enable the FPU, open the semihosting
**  handles, exit(main()).  Any fault ends the run with exit code 99, so a
**  crash is a failure, never a hang.
*/
#include <stdlib.h>
#include <unistd.h>

#include "fw_platform.h"

extern int main(void);
extern void initialise_monitor_handles(void);

/* Linker script symbols (cortex_m.ld). */
extern unsigned long _sidata, _sdata, _edata, _sbss, _ebss;
extern unsigned long _sstack, _estack;

void fw_reset(void);
void fw_fault(void);

/* The sixteen system vectors; no device interrupts are used. */
typedef void (*fw_vector)(void);
__attribute__((section(".vectors"), used)) const fw_vector fw_vectors[16] = {
    (fw_vector)&_estack, /* initial stack pointer */
    fw_reset,            /* reset */
    fw_fault,            /* NMI */
    fw_fault,            /* HardFault */
    fw_fault,            /* MemManage */
    fw_fault,            /* BusFault */
    fw_fault,            /* UsageFault */
    0, 0, 0, 0,
    fw_fault,            /* SVCall */
    fw_fault,            /* DebugMonitor */
    0,
    fw_fault,            /* PendSV */
    fw_fault             /* SysTick (its interrupt stays disabled) */
};

/* crti/crtn are left out (-nostartfiles): newlib's exit() still calls these. */
void _init(void);
void _fini(void);
void _init(void) {}
void _fini(void) {}

void fw_fault(void)
{
    _exit(99);
}

void fw_reset(void)
{
    unsigned long *s = &_sidata, *d = &_sdata;
    while (d < &_edata)
        *d++ = *s++;
    for (d = &_sbss; d < &_ebss;)
        *d++ = 0;
#if defined(__ARM_FP)
    /* CPACR: full access to CP10 and CP11 (the FPU) */
    *(volatile unsigned long *)0xE000ED88UL |= 0xFUL << 20;
    __asm volatile("dsb\n\tisb" ::: "memory");
#endif
    initialise_monitor_handles();
    exit(main());
}

/* ---------------------------------------------------------------------- */

#define SYST_CSR (*(volatile unsigned long *)0xE000E010UL)
#define SYST_RVR (*(volatile unsigned long *)0xE000E014UL)
#define SYST_CVR (*(volatile unsigned long *)0xE000E018UL)
#define SYST_MASK 0xFFFFFFUL
/* Instructions per SysTick count: 1 ns per instruction (-icount shift=0)
** and a 25 MHz SysTick clock (the MPS2 SYSCLK). */
#define INSN_PER_COUNT 40UL

const char *fw_target(void)
{
#if defined(FW_TARGET_NAME)
    return FW_TARGET_NAME;
#else
    return "cortex-m";
#endif
}

int fw_counter_available(void) { return 1; }

void fw_counter_init(void)
{
    SYST_CSR = 0;
    SYST_RVR = SYST_MASK;
    SYST_CVR = 0;
    SYST_CSR = 5; /* enable, processor clock, no interrupt */
}

unsigned long fw_counter(void)
{
    return SYST_MASK - (SYST_CVR & SYST_MASK); /* SysTick counts down */
}

unsigned long fw_counter_insns(unsigned long start, unsigned long end)
{
    return ((end - start) & SYST_MASK) * INSN_PER_COUNT;
}

unsigned long fw_counter_calibrate(unsigned long n_iter)
{
    unsigned long a, b, n = n_iter;
    a = fw_counter();
    __asm volatile("1:\n\tsubs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
    b = fw_counter();
    return fw_counter_insns(a, b);
}

/* ---------------------------------------------------------------------- */

#define PAINT 0xA5C3E187UL

int fw_stack_available(void) { return 1; }

__attribute__((noinline)) void fw_stack_paint(void)
{
    unsigned long *sp, *p;
    __asm volatile("mov %0, sp" : "=r"(sp));
    /* leave this function's own frame (and some margin) alone */
    for (p = sp - 16; p >= &_sstack; p--)
        *p = PAINT;
}

unsigned long fw_stack_depth(void)
{
    const unsigned long *p = &_sstack;
    while (p < &_estack && *p == PAINT)
        p++;
    return (unsigned long)((const char *)&_estack - (const char *)p);
}
