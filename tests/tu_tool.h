/*
**  tu_tool.h - helpers for the suites that run build/pmfit: the program's
**  path, running a command with its output captured, a number from JSON
**  output, a temporary directory.  Include after defining
**  _POSIX_C_SOURCE 200809L (popen, mkdtemp).
*/
#ifndef PM_TU_TOOL_H
#define PM_TU_TOOL_H

#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

/* pmfit of the tree under test: $PM_TOP/$PM_BUILD/pmfit (both set by make
** test; PM_BUILD is the build directory, "build" unless make sanitize). */
static inline const char *tu_pmfit_path(void)
{
    static char path[512];
    const char *top = getenv("PM_TOP");
    const char *b = getenv("PM_BUILD");
    snprintf(path, sizeof path, "%s/%s/pmfit", top ? top : ".", b ? b : "build");
    return path;
}

/* Run a shell command with stdout and stderr captured into out (len bytes,
** NUL-terminated); the exit code, or -1 if it did not exit. */
static inline int tu_capture(const char *cmd, char *out, size_t len)
{
    char full[8192];
    FILE *p;
    size_t n;
    int st;
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    p = popen(full, "r");
    ck_assert_ptr_nonnull(p);
    n = fread(out, 1, len - 1, p);
    out[n] = 0;
    st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* The number right after the text pat in text (fails the test, naming
** `what`, if pat is absent). */
static inline double tu_number_after(const char *text, const char *pat, const char *what)
{
    const char *p = strstr(text, pat);
    ck_assert_msg(p != NULL, "no %s in: %.400s", what, text);
    return atof(p + strlen(pat));
}

/* The number after "key": in JSON text (fails the test if absent). */
static inline double tu_json_num(const char *json, const char *key)
{
    char pat[128];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    return tu_number_after(json, pat, key);
}

/* The value (arcsec) of term `name` in pmfit fit --json's "terms" (fails
** the test if absent). */
static inline double tu_term_value(const char *json, const char *name)
{
    char pat[128];
    snprintf(pat, sizeof pat, "{\"name\": \"%s\", \"value_arcsec\": ", name);
    return tu_number_after(json, pat, name);
}

/* A fresh directory /tmp/<prefix>XXXXXX into dir (at least 64 bytes). */
static inline void tu_tmpdir(char *dir, const char *prefix)
{
    snprintf(dir, 64, "/tmp/%sXXXXXX", prefix);
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

#endif
