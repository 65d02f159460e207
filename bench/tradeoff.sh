#!/bin/sh
# bench/tradeoff.sh - the inverse's budgets against what they reach (issue
# 18): for each setting of the bounds' macros (include/pm.h), the library is
# built in a scratch copy with the evaluation counter (tests/probe.h) and
# bench/inv_stress.c run on check_bounded's hard cases and on 200,000
# realistic cold calls within 0.5 deg of the mount's pole (seeds 1-10).
# Prints one table row per setting.  Usage: sh bench/tradeoff.sh [settings...]
# where a setting is "FIXED NEWTON STARTS RUNS POLE_NEWTON".
set -e
top=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ $# -gt 0 ] || set -- "4 9 8 2 16" "4 9 8 3 16" "4 9 12 2 16" "4 9 12 3 12" "4 9 12 3 16" \
                       "4 9 16 2 16" "4 9 16 3 16" "6 7 12 3 12" "8 5 12 3 12"
printf '| fixed | Newton | ring points | runs | run length | bound cold | bound near | hard invert PM_OK | hard invert_near PM_OK | realistic < 0.5 deg not PM_OK (of 200,000) |\n'
printf '|---|---|---|---|---|---|---|---|---|---|\n'
for s in "$@"; do
    set -- $s
    rm -rf "$tmp/src" && mkdir -p "$tmp/src" && cp -r "$top/lib" "$top/include" "$top/tests" "$top/bench" "$tmp/src/"
    sed -i "s/^#define PM_INVERT_MAX_FIXED .*/#define PM_INVERT_MAX_FIXED $1/;
            s/^#define PM_INVERT_MAX_NEWTON .*/#define PM_INVERT_MAX_NEWTON $2/;
            s/^#define PM_INVERT_POLE_STARTS .*/#define PM_INVERT_POLE_STARTS $3/;
            s/^#define PM_INVERT_POLE_RUNS .*/#define PM_INVERT_POLE_RUNS $4/;
            s/^#define PM_INVERT_POLE_NEWTON .*/#define PM_INVERT_POLE_NEWTON $5/" "$tmp/src/include/pm.h"
    for f in model fit model_f; do
        ${CXX:-g++} -std=c++11 -O2 -ffreestanding -fno-exceptions -fno-rtti -fno-threadsafe-statics \
            -fbuiltin -fno-math-errno -I"$tmp/src/include" -include "$tmp/src/tests/probe.h" \
            '-DPM_EVAL_PROBE()=pm_probe_hit()' -c "$tmp/src/lib/$f.cpp" -o "$tmp/$f.o"
    done
    ${CC:-gcc} -std=gnu99 -O2 -I"$tmp/src/include" -I"$tmp/src/tests" "$tmp/src/bench/inv_stress.c" \
        "$tmp/model.o" "$tmp/fit.o" "$tmp/model_f.o" -lstdc++ -lm -o "$tmp/stress"
    hard=$("$tmp/stress" hard)
    bc=$(echo "$hard" | sed 's/.*worst [0-9]* evaluations, bound \([0-9]*\)).*/\1/')
    hi=$(echo "$hard" | sed 's/.*pm_model_invert PM_OK \([0-9]*\).*/\1/')
    hn=$(echo "$hard" | sed 's/.*pm_model_invert_near PM_OK \([0-9]*\).*/\1/')
    bn=$(echo "$hard" | sed 's/.*worst [0-9]*, bound \([0-9]*\)).*/\1/')
    bad=0
    for seed in 1 2 3 4 5 6 7 8 9 10; do
        n=$("$tmp/stress" real 20000 $seed | tail -1 | sed 's/.*PM_OK, \([0-9]*\) not.*/\1/')
        bad=$((bad + n))
    done
    printf '| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$1" "$2" "$3" "$4" "$5" "$bc" "$bn" "$hi" "$hn" "$bad"
done
