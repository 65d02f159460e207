/*
**  tu_check.h - the main() every Check suite shares: run the suite (fork
**  mode, so a crash is a failure), exit status failure if any test failed.
*/
#ifndef PM_TU_CHECK_H
#define PM_TU_CHECK_H

#include <check.h>
#include <stdlib.h>

static inline int tu_run_suite(Suite *s)
{
    SRunner *sr = srunner_create(s);
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}

#endif
