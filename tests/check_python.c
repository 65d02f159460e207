/*
**  check_python.c - the Python package (python/, docs/python.md): runs its
**  pytest suite (python/tests) on the package that make built in
**  $PM_BUILD/python, and fails if pytest fails.  It builds nothing itself:
**  python/python.mk makes the extension a prerequisite of this program.
**  Skipped, passing, with a message when python3-numpy or python3-pytest is
**  not installed.  The log of the run is $PM_BUILD/python/pytest.log.
*/
#define _XOPEN_SOURCE 700 /* realpath */
#include <check.h>
#include "tu_check.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define PYTHON "/usr/bin/python3"

static const char *env_or(const char *name, const char *def)
{
    const char *v = getenv(name);
    return v && *v ? v : def;
}

/* The last non-blank line of a file into line (len bytes); 0 if none. */
static int last_line(const char *path, char *line, size_t len)
{
    char buf[4096];
    int found = 0;
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    while (fgets(buf, sizeof buf, f)) {
        size_t n = strlen(buf);
        while (n && (buf[n - 1] == '\n' || buf[n - 1] == '\r' || buf[n - 1] == ' '))
            buf[--n] = 0;
        if (n) {
            snprintf(line, len, "%s", buf);
            found = 1;
        }
    }
    fclose(f);
    return found;
}

START_TEST(test_python_pytest_suite_passes)
{
    char top[4096], pkg[4200], cmd[16384], log[4300], line[512], path[4300];
    const char *t = env_or("PM_TOP", ".");
    const char *b = env_or("PM_BUILD", "build");
    int st;
    if (access(PYTHON, X_OK) != 0 ||
        system(PYTHON " -c 'import numpy, pytest' > /dev/null 2>&1") != 0) {
        printf("skipped: Python package tests (" PYTHON " with numpy and pytest not found; "
               "sh tools/deps.sh installs python3-numpy and python3-pytest)\n");
        return;
    }
    ck_assert_msg(realpath(t, top) != NULL, "PM_TOP=%s: no such directory", t);
    ck_assert(snprintf(pkg, sizeof pkg, "%s/%s/python", top, b) < (int)sizeof pkg);
    ck_assert(snprintf(path, sizeof path, "%s/pm/__init__.py", pkg) < (int)sizeof path);
    ck_assert_msg(access(path, R_OK) == 0, "%s missing: make python builds the package", path);
    ck_assert(snprintf(log, sizeof log, "%s/pytest.log", pkg) < (int)sizeof log);
    ck_assert(snprintf(cmd, sizeof cmd,
                       "cd '%s' && PYTHONPATH='%s' PM_TOP='%s' PM_BUILD='%s' "
                       "PYTHONDONTWRITEBYTECODE=1 " PYTHON
                       " -m pytest -q -p no:cacheprovider python/tests > '%s' 2>&1",
                       top, pkg, top, b, log) < (int)sizeof cmd);
    st = system(cmd);
    if (!last_line(log, line, sizeof line))
        snprintf(line, sizeof line, "(no output)");
    printf("python: pytest: %s\n", line);
    fflush(stdout); /* a failed assertion below ends the process */
    ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 0,
                  "pytest failed (exit %d): %s; see %s", WIFEXITED(st) ? WEXITSTATUS(st) : -1,
                  line, log);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("python");
    TCase *tc = tcase_create("pytest");
    tcase_add_test(tc, test_python_pytest_suite_passes);
    tcase_set_timeout(tc, 900); /* a few seconds alone; minutes on a loaded machine */
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return tu_run_suite(suite());
}
