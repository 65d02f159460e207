/*
**  host_timer.h - what the host benchmarks share (bench_host.c,
**  bench_dist_host.c): the TSC read between fences (monotonic nanoseconds
**  where there is no TSC), the callgrind client requests (no-ops without
**  valgrind's header), and pinning to one core so the TSC and the caches
**  are one CPU's.  Include after _GNU_SOURCE is defined.
*/
#ifndef PM_BENCH_HOST_TIMER_H
#define PM_BENCH_HOST_TIMER_H

#include <sched.h>
#include <time.h>

#if defined(__has_include)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define HAVE_CALLGRIND 1
#endif
#endif
#ifndef HAVE_CALLGRIND
#define CALLGRIND_ZERO_STATS
#define CALLGRIND_DUMP_STATS_AT(s) ((void)(s))
#endif

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
static inline unsigned long long ticks(void)
{
    unsigned long long t;
    _mm_lfence();
    t = __rdtsc();
    _mm_lfence();
    return t;
}
#define TICK_UNIT "TSC ticks"
#else
static inline unsigned long long ticks(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (unsigned long long)ts.tv_sec * 1000000000ULL + (unsigned long long)ts.tv_nsec;
}
#define TICK_UNIT "ns (no TSC on this architecture)"
#endif

/* Run on CPU 1 (CPU 0 where there is no second), so that every tick comes
** from one TSC and one set of caches. */
static inline void pin_one_cpu(void)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(1, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0) {
        CPU_ZERO(&set);
        CPU_SET(0, &set);
        sched_setaffinity(0, sizeof set, &set);
    }
}

#endif
