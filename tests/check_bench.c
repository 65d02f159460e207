/*
**  check_bench.c - a smoke run of the bench: pmbench runs every case once
**  (one batch: no timing is judged here, timings belong in bench/), every
**  call returns PM_OK, the naive evaluation matches the library's terms,
**  and bench/report.py turns the output into a valid results.json with an
**  entry per case.
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

static int sh(const char *cmd)
{
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* body run by sh in a fresh scratch directory d (under the top, made anew),
** with $T the top: the fixtures' files by their own names */
static int sh_scratch(const char *d, const char *body)
{
    char cmd[8192];
    snprintf(cmd, sizeof cmd,
             "T=$(cd '%s' && pwd) && cd \"$T\" && rm -rf %s && mkdir -p %s && cd %s && %s",
             top(), d, d, d, body);
    return sh(cmd);
}

START_TEST(test_bench_smoke_json)
{
    char cmd[4096];
    const char *d = "build/bench/smoke";
    unsetenv("MAKEFLAGS");
    unsetenv("MFLAGS");
    unsetenv("MAKELEVEL");
    snprintf(cmd, sizeof cmd, "cd '%s' && make -s build/bench/pmbench > /dev/null 2>&1", top());
    ck_assert_int_eq(sh(cmd), 0);
    snprintf(cmd, sizeof cmd, "cd '%s' && rm -rf %s && mkdir -p %s && "
             "build/bench/pmbench --batches 1 --out %s/host.jsonl 2> %s/log.txt && "
             "/usr/bin/python3 bench/report.py --dir %s --targets '' > %s/report.txt",
             top(), d, d, d, d, d, d);
    ck_assert_int_eq(sh(cmd), 0);
    /* a JSON list with the ticks of every op and order of the double API */
    snprintf(cmd, sizeof cmd, "cd '%s' && /usr/bin/python3 -c '"
             "import json, sys\n"
             "r = json.load(open(\"%s/results.json\"))\n"
             "n = {e[\"name\"]: e for e in r}\n"
             "for op in (\"fwd\", \"inv\", \"inv_near\", \"naive_fwd\", \"naive_inv\"):\n"
             "  for L in (0, 1, 2, 4):\n"
             "    e = n[\"host_%%s_L%%d_double\" %% (op, L)]\n"
             "    assert isinstance(e[\"ticks_median\"], float)\n"
             "    assert (\"ratio\" in e) == (not op.startswith(\"naive\"))\n"
             "for op in (\"track10\", \"track1k\"):\n"
             "  for p in (\"double\", \"float\"):\n"
             "    assert isinstance(n[\"host_%%s_L2_%%s\" %% (op, p)][\"ticks_median\"], float)\n"
             "    assert \"ratio\" not in n[\"host_empty_%%s_L2_%%s\" %% (op, p)]\n"
             "' > %s/check.txt 2>&1", top(), d, d);
    ck_assert_msg(sh(cmd) == 0, "results.json malformed: see %s/check.txt", d);
}
END_TEST

/* the Cortex-M rows: bench_cm.c prints each case with its loop's cost
** already subtracted, so report.py takes them as they are (599a586 to the
** fix subtracted the "empty" case a second time) */
START_TEST(test_bench_report_cm_rows)
{
    const char *d = "build/bench/smoke_cm";
    ck_assert_msg(
        sh_scratch(d, "printf '%s\\n' "
                      "'BENCH {\"name\": \"mx_empty_L2_double\", \"instructions\": 21.0}' "
                      "'BENCH {\"name\": \"mx_fwd_L2_double\", \"instructions\": 1000.0}' "
                      "'BENCH {\"name\": \"mx_inv_L2_double\", \"instructions\": 2300.0}' "
                      "> mx.out && /usr/bin/python3 \"$T/bench/report.py\" --dir . --targets mx "
                      "> report.txt 2>&1 && /usr/bin/python3 -c '"
                      "import json, sys\n"
                      "n = {e[\"name\"]: e for e in json.load(open(\"results.json\"))}\n"
                      "assert n[\"mx_fwd_L2_double\"][\"instructions\"] == 1000.0, n\n"
                      "assert n[\"mx_inv_L2_double\"][\"instructions\"] == 2300.0, n\n"
                      "sys.path.insert(0, sys.argv[1]); import report\n"
                      "assert report.loop_name(\"host_track10_L2_double\") == "
                      "\"host_empty_track10_L2_double\"\n"
                      "assert report.loop_name(\"host_track1k_L4_float\") == "
                      "\"host_empty_track1k_L4_float\"\n"
                      "assert report.loop_name(\"host_inv_near_L2_double\") == "
                      "\"host_empty_L2_double\"\n"
                      "' \"$T/bench\" > check.txt 2>&1") == 0,
        "report.py's Cortex-M rows: see %s/check.txt, report.txt", d);
}
END_TEST

/* bench/qemu_profile.py on a hand-made QEMU log: translation blocks ("IN:"
** and their instructions) and executions ("Trace"), two marked regions;
** a block executed twice counts twice, the markers' own blocks not at all,
** blocks outside the regions not at all */
START_TEST(test_bench_qemu_profile)
{
    const char *d = "build/bench/smoke_qprof";
    ck_assert_msg(
        sh_scratch(d, "printf '%s\\n' "
                      "'IN: marker_begin' '0x00000100:  bx lr' '' "
                      "'Trace 0: 0x7f00 [00000000/00000100/00000000/00000000] marker_begin' "
                      "'IN: f' '0x00000200:  movs r0, #1' '0x00000202:  movs r1, #2' '' "
                      "'Trace 0: 0x7f01 [00000000/00000200/00000000/00000000] f' "
                      "'Trace 0: 0x7f01 [00000000/00000200/00000000/00000000] f' "
                      "'IN: g' '0x00000300:  bx lr' '' "
                      "'Trace 0: 0x7f02 [00000000/00000300/00000000/00000000] g' "
                      "'IN: marker_end' '0x00000400:  bx lr' '' "
                      "'Trace 0: 0x7f03 [00000000/00000400/00000000/00000000] marker_end' "
                      "'Trace 0: 0x7f01 [00000000/00000200/00000000/00000000] f' "
                      "'Trace 0: 0x7f00 [00000000/00000100/00000000/00000000] marker_begin' "
                      "'Trace 0: 0x7f02 [00000000/00000300/00000000/00000000] g' "
                      "'Trace 0: 0x7f03 [00000000/00000400/00000000/00000000] marker_end' "
                      "> q.log && /usr/bin/python3 \"$T/bench/qemu_profile.py\" q.log > out.txt "
                      "&& /usr/bin/python3 -c '"
                      "t = open(\"out.txt\").read().split(\"== \")[1:]\n"
                      "assert len(t) == 2, t\n"
                      "assert t[0].startswith(\"region 0: 5 instructions\"), t\n"
                      "assert \"4.0  f\" in t[0] and \"1.0  g\" in t[0], t\n"
                      "assert t[1].startswith(\"region 1: 1 instructions\"), t\n"
                      "' > check.txt 2>&1") == 0,
        "qemu_profile.py: see %s/check.txt, out.txt", d);
}
END_TEST

/* the explain bench at its smallest size: a JSON line with the time and
** the two hidden effects found (timing is judged in bench/, not here) */
START_TEST(test_bench_explain_smoke)
{
    char cmd[4096];
    const char *d = "build/bench/smoke_explain";
    unsetenv("MAKEFLAGS");
    unsetenv("MFLAGS");
    unsetenv("MAKELEVEL");
    snprintf(cmd, sizeof cmd, "cd '%s' && make -s build/bench/pmbench_explain > /dev/null 2>&1", top());
    ck_assert_int_eq(sh(cmd), 0);
    snprintf(cmd, sizeof cmd, "cd '%s' && rm -rf %s && mkdir -p %s && "
             "build/bench/pmbench_explain --max-n 1000 --out %s/explain.jsonl 2> %s/log.txt && "
             "/usr/bin/python3 -c '"
             "import json\n"
             "r = [json.loads(l) for l in open(\"%s/explain.jsonl\")]\n"
             "assert [e[\"n_obs\"] for e in r] == [1000]\n"
             "assert r[0][\"seconds\"] > 0\n"
             "assert sorted(r[0][\"findings\"]) == [\"ha_periodic\", \"refraction\"], r\n"
             "' > %s/check.txt 2>&1", top(), d, d, d, d, d, d);
    ck_assert_msg(sh(cmd) == 0, "pmbench_explain: see %s/check.txt", d);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("bench");
    TCase *tc = tcase_create("smoke");
    tcase_add_test(tc, test_bench_smoke_json);
    tcase_add_test(tc, test_bench_report_cm_rows);
    tcase_add_test(tc, test_bench_qemu_profile);
    tcase_add_test(tc, test_bench_explain_smoke);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return tu_run_suite(suite()); }
