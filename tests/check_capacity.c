/*
**  check_capacity.c - the core built with capacities beyond the default
**  (PM_MAX_L = 10, PM_MAX_AUX = 12: build/big, Makefile), this suite
**  compiled with the same: term names with two-digit indices (pm_term_name
**  wrote each index's last digit only: "a*Y(0,-0)" for a*Y(10,-10)), and
**  PM_CHECK_CONFIG() of a consistent build.
*/
#include "tu_check.h"
#include "pm.h"
#include <string.h>

START_TEST(test_capacity_config)
{
    ck_assert_int_eq(PM_MAX_L, 10);
    ck_assert_int_eq(PM_MAX_AUX, 12);
    ck_assert_int_eq(PM_CHECK_CONFIG(), PM_OK);
}
END_TEST

START_TEST(test_pm_term_name_two_digit_indices)
{
    static pm_model m;
    static const struct {
        int k, l, mm;
        const char *name;
    } sh[] = {{1, 10, 0, "a*Y(10,0)"},  {1, 10, -10, "a*Y(10,-10)"}, {2, 10, 1, "b*Y(10,1)"},
              {3, 9, -9, "c'*Y(9,-9)"}, {4, 10, -3, "d*Y(10,-3)"},   {5, 1, -1, "e'*Y(1,-1)"}};
    char buf[32];
    pm_term t;
    int i, idx;
    ck_assert_int_eq(pm_model_init(&m, PM_MOUNT_EQUATORIAL, 10), PM_OK);
    for (i = 0; i < (int)(sizeof sh / sizeof sh[0]); i++) {
        ck_assert_int_eq(pm_model_find(&m, sh[i].k, sh[i].l, sh[i].mm, &idx), PM_OK);
        ck_assert_int_eq(pm_term_name(&m, idx, buf, sizeof buf), PM_OK);
        ck_assert_str_eq(buf, sh[i].name);
    }
    memset(&t, 0, sizeof t);
    t.kind = PM_TERM_AUX;
    t.k = PM_BASE_B;
    t.aux = PM_AUX_USER + 11;
    ck_assert_int_eq(pm_model_add_term(&m, &t, 0.0, &idx), PM_OK);
    ck_assert_int_eq(pm_term_name(&m, idx, buf, sizeof buf), PM_OK);
    ck_assert_str_eq(buf, "b*aux11");
    t.aux = PM_AUX_USER + 10;
    t.side = -1;
    ck_assert_int_eq(pm_model_add_term(&m, &t, 0.0, &idx), PM_OK);
    ck_assert_int_eq(pm_term_name(&m, idx, buf, sizeof buf), PM_OK);
    ck_assert_str_eq(buf, "b*aux10@W");
}
END_TEST

static Suite *capacity_suite(void)
{
    Suite *s = suite_create("capacity");
    TCase *tc = tcase_create("values");
    tcase_add_test(tc, test_capacity_config);
    tcase_add_test(tc, test_pm_term_name_two_digit_indices);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return tu_run_suite(capacity_suite());
}
