/*
**  fw_platform.h - what the mount-controller demo and the bench need from
**  the board: its name, an instruction counter and a stack gauge.
**
**  Two implementations: platform_cm.c (Cortex-M under QEMU: vector table,
**  reset handler, SysTick as an instruction counter, stack painting) and
**  platform_host.c (a hosted build, where neither is available).
**
**  The instruction counter.  QEMU has no DWT cycle counter.  Run with
**  "-icount shift=0" its virtual clock advances exactly 1 ns per executed
**  instruction, and the MPS2 SysTick, clocked from the 25 MHz SYSCLK,
**  counts one tick per 40 ns: so SysTick counts instructions, 40 at a time,
**  deterministically.  fw_counter_calibrate() checks the factor against a
**  loop of a known number of instructions.
*/
#ifndef FW_PLATFORM_H
#define FW_PLATFORM_H

/* Short target name ("host", "m4f", "m7"). */
const char *fw_target(void);

/* 1 if fw_counter() counts instructions, 0 if it is not available. */
int fw_counter_available(void);

/* Start the counter (once, before the first fw_counter()). */
void fw_counter_init(void);

/* Raw counter value; increases, wraps (use fw_counter_insns for deltas). */
unsigned long fw_counter(void);

/* Instructions executed between two fw_counter() readings (at most about
** 6.7e8 apart: the 24-bit SysTick wraps after that). */
unsigned long fw_counter_insns(unsigned long start, unsigned long end);

/* Measure a loop of exactly n_iter * 2 instructions; returns what the
** counter saw (0 where unavailable).  A correct counter returns
** 2 * n_iter to within 40 plus the few instructions around the loop. */
unsigned long fw_counter_calibrate(unsigned long n_iter);

/* Stack gauge: fw_stack_paint() fills the unused stack below the caller
** with a pattern; fw_stack_depth() returns how many bytes below the top of
** the stack have been written since (the deepest point reached, counted
** from the reset stack pointer).  0 where unavailable. */
int fw_stack_available(void);
void fw_stack_paint(void);
unsigned long fw_stack_depth(void);

#endif
