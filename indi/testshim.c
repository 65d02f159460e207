/*
**  testshim.c - LD_PRELOAD fixture of the INDI end-to-end test (tests/check_indi.c,
**  indi/e2e_indi.py); never part of the plugin.
**
**  1) The sky stands still: libnova's ln_get_julian_from_sys(), from which the
**     driver, the alignment subsystem and the math plugins take the time,
**     returns PM_INDI_FROZEN_JD when that is set.  The event loop's timers and
**     the simulated mount's motion keep the real clocks (they do not call it).
**  2) The plugin directory: INDI 1.9.9 looks for math plugins in a directory
**     fixed when it was built (no environment variable on Linux).  When
**     PM_INDI_SYSTEM_PLUGIN_DIR and PM_INDI_PLUGIN_DIR are set, opendir() of
**     the first lists the second, and dlopen() of a file in the first that
**     exists only in the second loads it from there.  So the test finds the
**     plugin in the build directory without installing anything.
*/
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static size_t dir_len(const char *d)
{
    size_t n = strlen(d);
    while (n > 1 && d[n - 1] == '/')
        n--;
    return n;
}

/* Is path the system plugin directory (ignoring trailing slashes)? */
static int is_sysdir(const char *path)
{
    const char *sys = getenv("PM_INDI_SYSTEM_PLUGIN_DIR");
    size_t n;
    if (!sys || !*sys || !getenv("PM_INDI_PLUGIN_DIR") || !path)
        return 0;
    n = dir_len(sys);
    return strncmp(path, sys, n) == 0 && dir_len(path) == n;
}

double ln_get_julian_from_sys(void)
{
    typedef double fn_t(void);
    const char *s = getenv("PM_INDI_FROZEN_JD");
    fn_t *real;
    if (s && *s) {
        char *end;
        double jd = strtod(s, &end);
        if (end != s && *end == '\0')
            return jd;
        fprintf(stderr, "testshim: PM_INDI_FROZEN_JD '%s' is not a number\n", s);
        abort();
    }
    real = (fn_t *)dlsym(RTLD_NEXT, "ln_get_julian_from_sys");
    if (!real) {
        fprintf(stderr, "testshim: ln_get_julian_from_sys not found\n");
        abort();
    }
    return real();
}

DIR *opendir(const char *name)
{
    typedef DIR *fn_t(const char *);
    fn_t *real = (fn_t *)dlsym(RTLD_NEXT, "opendir");
    if (is_sysdir(name))
        name = getenv("PM_INDI_PLUGIN_DIR");
    return real(name);
}

void *dlopen(const char *file, int mode)
{
    typedef void *fn_t(const char *, int);
    fn_t *real = (fn_t *)dlsym(RTLD_NEXT, "dlopen");
    const char *sys = getenv("PM_INDI_SYSTEM_PLUGIN_DIR");
    const char *alt = getenv("PM_INDI_PLUGIN_DIR");
    if (file && sys && *sys && alt && *alt) {
        size_t n = dir_len(sys);
        if (strncmp(file, sys, n) == 0 && file[n] == '/' && access(file, F_OK) != 0) {
            char path[4096];
            if (snprintf(path, sizeof path, "%s/%s", alt, file + n + 1) < (int)sizeof path)
                return real(path, mode);
        }
    }
    return real(file, mode);
}
