/*
**  tu_runfile.h - the check every run-reader error test makes: pmrun_read
**  fails with the expected status, the message starts "path:LINE: " (line
**  0: "path: ") and holds a key phrase, and no run comes back.
*/
#ifndef PM_TU_RUNFILE_H
#define PM_TU_RUNFILE_H

#include <check.h>
#include <stdio.h>
#include <string.h>
#include "runfile.h"

static inline void tu_read_fails(const char *path, const pmrun_options *opt, int status,
                                 int line, const char *needle)
{
    char err[2048], where[4200];
    pmrun *run = (pmrun *)err; /* anything but NULL: must come back NULL */
    int st = pmrun_read(path, opt, &run, err, sizeof err);
    ck_assert_msg(st == status, "%s: status %d, expected %d (%s)", path, st, status, err);
    ck_assert_ptr_null(run);
    if (line > 0)
        snprintf(where, sizeof where, "%s:%d: ", path, line);
    else
        snprintf(where, sizeof where, "%s: ", path);
    ck_assert_msg(strncmp(err, where, strlen(where)) == 0, "error '%s' does not start with '%s'",
                  err, where);
    ck_assert_msg(strstr(err, needle) != NULL, "error '%s' lacks '%s'", err, needle);
}

#endif
