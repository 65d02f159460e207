/*
**  check_firmware.c - the mount-controller demo (firmware_demo/) passes on
**  the host and, under QEMU, on Cortex-M4F and Cortex-M7: every target
**  tracks to 1e-12 rad, refits from its observations, and agrees with the
**  host build within 1e-9 rad ("make firmware-run" exits 0); and the core
**  compiles for Cortex-M7 and M3 at -O0, -Og and -Os, also with r9
**  reserved, which it then leaves alone, and with clang for Armv8.1-M.
**  Skipped, passing, when the ARM toolchain or QEMU is not installed.
*/
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include "tu_check.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

static const char *top(void)
{
    const char *t = getenv("PM_TOP");
    return t ? t : ".";
}

static int have(const char *tool)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "command -v %s > /dev/null 2>&1", tool);
    return system(cmd) == 0;
}

/* Does the file contain the string? */
static int file_has(const char *path, const char *s)
{
    static char buf[1 << 16];
    size_t n;
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    return strstr(buf, s) != NULL;
}

START_TEST(test_firmware_all_targets_pass)
{
    static const char *const targets[] = {"m4f", "m7"};
    char cmd[2048], path[1024], want[64];
    int st, i;
    if (!have("arm-none-eabi-gcc") || !have("qemu-system-arm")) {
        printf("skipped: firmware demo (arm-none-eabi-gcc or qemu-system-arm not installed; "
               "sh tools/deps.sh installs them)\n");
        return;
    }
    /* a make of its own, not a child of the one running the tests */
    unsetenv("MAKEFLAGS");
    unsetenv("MFLAGS");
    unsetenv("MAKELEVEL");
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/build/fw' && make -s -C '%s' firmware-run "
             "> '%s/build/fw/check.log' 2>&1", top(), top(), top());
    st = system(cmd);
    ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 0,
                  "make firmware-run failed (exit %d); see build/fw/check.log",
                  WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    snprintf(path, sizeof path, "%s/build/fw/host/demo.out", top());
    ck_assert_msg(file_has(path, "RESULT: PASS (host)"), "host run: see %s", path);
    for (i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/build/fw/%s/demo.out", top(), targets[i]);
        snprintf(want, sizeof want, "RESULT: PASS (%s)", targets[i]);
        ck_assert_msg(file_has(path, want), "%s run: see %s", targets[i], path);
        ck_assert_msg(file_has(path, "vs. host: tracking worst"),
                      "%s run did not compare with the host: see %s", targets[i], path);
    }
}
END_TEST

/* Does the disassembly of obj have a line that grep, given args, finds? */
static int objdump_has(const char *obj, const char *args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "arm-none-eabi-objdump -d '%s' | grep -q %s", obj, args);
    return system(cmd) == 0;
}

/* The coefficient check's ldm of the prepared copy, as objdump writes it */
#define CHECK_LDM "'ldmia.*{sl, fp, ip, lr}'"

/* The core compiles for Cortex-M at the optimisation levels firmware is
** built with, debug builds included: the coefficient check's Thumb-2
** assembly (lib/pm_detail.hpp, PM_LDM_COMPARE) needs registers that -O0
** (r7 the frame pointer) leaves few of, and was once refused there.  And
** where firmware reserves r9, the AAPCS platform register, the core
** compiles and leaves it alone: the assembly once clobbered r9, which gcc
** refused where r9 is the PIC base (-msingle-pic-base) and, with
** -ffixed-r9, let it overwrite unannounced.  (With -ffixed-r9 gcc itself
** never names r9, so any r9 in the object is the assembly's; the PIC base
** gcc may name itself, and there compiling is the check.) */
START_TEST(test_core_compiles_at_every_level)
{
    static const char *const cpus[] = {"-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard",
                                       "-mcpu=cortex-m3",
                                       "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard "
                                       "-ffixed-r9",
                                       "-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard "
                                       "-fpic -msingle-pic-base -mpic-register=r9"};
    static const char *const levels[] = {"-O0", "-Og", "-Os"};
    static const char *const files[] = {"model", "model_f"};
    char cmd[8192], obj[1024];
    int c, l, f, st;
    if (!have("arm-none-eabi-g++")) {
        printf("skipped: Cortex-M builds of the core (arm-none-eabi-g++ not installed; "
               "sh tools/deps.sh installs it)\n");
        return;
    }
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/build/fw/levels'", top());
    ck_assert_int_eq(system(cmd), 0);
    for (c = 0; c < 4; c++)
        for (l = 0; l < 3; l++)
            for (f = 0; f < 2; f++) {
                snprintf(obj, sizeof obj, "%s/build/fw/levels/%s_%d%s.o", top(), files[f], c,
                         levels[l]);
                snprintf(cmd, sizeof cmd,
                         "arm-none-eabi-g++ -std=c++11 -mthumb %s %s -ffreestanding "
                         "-fno-exceptions -fno-rtti -fno-threadsafe-statics -I'%s/include' "
                         "-c '%s/lib/%s.cpp' -o '%s' > '%s.log' 2>&1",
                         cpus[c], levels[l], top(), top(), files[f], obj, obj);
                st = system(cmd);
                ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 0,
                              "lib/%s.cpp for %s at %s does not compile: see %s.log", files[f],
                              cpus[c], levels[l], obj);
                /* the check's assembly is there */
                ck_assert_msg(objdump_has(obj, CHECK_LDM), "%s: no ldm of the coefficient check",
                              obj);
                /* -ffixed-r9: no instruction of the core names r9 */
                ck_assert_msg(c != 2 || !objdump_has(obj, "-w -e r9 -e sb"),
                              "%s: r9 is reserved (%s) and the core's code uses it", obj, cpus[c]);
            }
    /* clang names Armv8.1-M mainline's architecture macro apart
    ** (__ARM_ARCH_8_1M_MAIN__): the check's assembly is chosen by ACLE's
    ** profile 'M' and __thumb2__ instead, and is there for it too */
    if (!have("clang++")) {
        printf("skipped: clang's Armv8.1-M build of the core (clang++ not installed)\n");
        return;
    }
    snprintf(obj, sizeof obj, "%s/build/fw/levels/model_clang_v81m.o", top());
    snprintf(cmd, sizeof cmd,
             "clang++ --target=thumbv8.1m.main-none-eabi -std=c++11 -O2 -ffreestanding "
             "-fno-exceptions -fno-rtti -nostdinc++ -I'%s/include' -c '%s/lib/model.cpp' "
             "-o '%s' > '%s.log' 2>&1",
             top(), top(), obj, obj);
    st = system(cmd);
    ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 0,
                  "lib/model.cpp for thumbv8.1m.main (clang) does not compile: see %s.log", obj);
    ck_assert_msg(objdump_has(obj, CHECK_LDM),
                  "%s: no ldm of the coefficient check (clang, Armv8.1-M)", obj);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("firmware");
    TCase *tc = tcase_create("qemu");
    tcase_add_test(tc, test_firmware_all_targets_pass);
    tcase_add_test(tc, test_core_compiles_at_every_level);
    tcase_set_timeout(tc, 300); /* a first build compiles the core for three targets */
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
