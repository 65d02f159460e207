/*
**  tu_tool.h - helpers for the suites that run build/pmfit: the program's
**  path, running a command with its output captured, a number from JSON
**  output, a file's whole text, a temporary directory removed at exit.  Include after defining
**  _POSIX_C_SOURCE 200809L (popen, mkdtemp).
*/
#ifndef PM_TU_TOOL_H
#define PM_TU_TOOL_H

#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

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

/* A copy of the file src written to dst, each line passed through
** edit(line, size, arg) first: it may change the line in place (line holds
** size bytes) and returns 0 to leave the line out.  dst ending in "XXXXXX"
** is a mkstemp template (the file's name written into it). */
typedef int (*tu_line_edit)(char *line, size_t size, void *arg);
static inline void tu_edited_copy(const char *src, char *dst, tu_line_edit edit, void *arg)
{
    char line[4096];
    size_t n = strlen(dst);
    FILE *in = fopen(src, "r"), *o;
    ck_assert_msg(in != NULL, "%s: cannot open", src);
    if (n >= 6 && !strcmp(dst + n - 6, "XXXXXX")) {
        int fd = mkstemp(dst);
        ck_assert_int_ge(fd, 0);
        o = fdopen(fd, "w");
    } else {
        o = fopen(dst, "w");
    }
    ck_assert_msg(o != NULL, "%s: cannot write", dst);
    while (fgets(line, sizeof line, in))
        if (edit(line, sizeof line, arg))
            fputs(line, o);
    fclose(in);
    ck_assert_int_eq(fclose(o), 0);
}

/* The whole of a file, NUL-terminated (the caller frees it); NULL if it
** cannot be opened.  A file that opens but cannot be read fails the test. */
static inline char *tu_slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *s;
    long n;
    if (!f)
        return NULL;
    ck_assert_int_eq(fseek(f, 0, SEEK_END), 0);
    n = ftell(f);
    ck_assert_int_ge(n, 0);
    ck_assert_int_eq(fseek(f, 0, SEEK_SET), 0);
    s = (char *)malloc((size_t)n + 1);
    ck_assert_ptr_nonnull(s);
    ck_assert_uint_eq(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = 0;
    fclose(f);
    return s;
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

/* The real run rel under ../shared/data ($PM_DATA_DIR) into path (len
** bytes): 1 if it is there, else 0 with "skipped: ..." printed (the tests
** that need the real runs skip cleanly without them; PM_DATA_DIR unset or
** empty is absent, as for testutil.h's tu_data_dir). */
static inline int tu_real_run(const char *rel, char *path, size_t len)
{
    const char *d = getenv("PM_DATA_DIR");
    if (!d || !*d) {
        printf("skipped: ../shared/data absent\n");
        return 0;
    }
    snprintf(path, len, "%s/%s", d, rel);
    if (access(path, R_OK) != 0) {
        printf("skipped: %s absent\n", path);
        return 0;
    }
    return 1;
}

/* The directories tu_tmpdir made, and the process that made each: removed
** with their contents when that process exits (Check runs each test in a
** child that exits, also on a failed assertion; a child never removes the
** directory of the parent it was forked from).  A test killed by a signal
** (a timeout) leaves its directory behind. */
#define TU_MAX_TMPDIRS 64
static char tu_tmpdirs[TU_MAX_TMPDIRS][64];
static pid_t tu_tmpdir_pid[TU_MAX_TMPDIRS];
static int tu_n_tmpdirs;

static inline void tu_remove_tmpdirs(void)
{
    char cmd[128];
    int i;
    for (i = 0; i < tu_n_tmpdirs; i++) {
        if (tu_tmpdir_pid[i] != getpid())
            continue;
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tu_tmpdirs[i]);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", tu_tmpdirs[i]);
    }
}

/* A fresh directory /tmp/<prefix>XXXXXX into dir (at least 64 bytes),
** removed with its contents when this process exits. */
static inline void tu_tmpdir(char *dir, const char *prefix)
{
    static int registered;
    snprintf(dir, 64, "/tmp/%sXXXXXX", prefix);
    ck_assert_ptr_nonnull(mkdtemp(dir));
    if (tu_n_tmpdirs < TU_MAX_TMPDIRS) {
        snprintf(tu_tmpdirs[tu_n_tmpdirs], 64, "%.63s", dir);
        tu_tmpdir_pid[tu_n_tmpdirs++] = getpid();
    }
    if (!registered && atexit(tu_remove_tmpdirs) == 0)
        registered = 1;
}

#endif
