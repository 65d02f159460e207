/*
**  check_firmware.c - the mount-controller demo (firmware_demo/) passes on
**  the host and, under QEMU, on Cortex-M4F and Cortex-M7: every target
**  tracks to 1e-12 rad, refits from its observations, and agrees with the
**  host build within 1e-9 rad ("make firmware-run" exits 0).  Skipped,
**  passing, when the ARM toolchain or QEMU is not installed.
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

static Suite *suite(void)
{
    Suite *s = suite_create("firmware");
    TCase *tc = tcase_create("qemu");
    tcase_add_test(tc, test_firmware_all_targets_pass);
    tcase_set_timeout(tc, 300); /* a first build compiles the core for three targets */
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
