#!/bin/sh
# bench/typical.sh - the typical call's instruction counts of several
# commits side by side (issue 18, round 5): for each REV, a clean copy
# (git archive) built in a scratch directory, its host bench under
# callgrind and its Cortex-M7 bench under QEMU -icount (the commands of
# `make bench`, bench/bench.mk's bench-run), the loop's own cost subtracted
# once (callgrind: here, as bench/report.py does; M7: by bench_cm.c).
# Deterministic: instructions, not time.
#
#   sh bench/typical.sh 0f7bbbd HEAD      (~3 min per revision)
#
# Prints per revision: L = 0, 2, 4, double, forward / invert / invert_near,
# host and M7 instructions per call (the bench's model and 256 positions).
# Needs valgrind, arm-none-eabi-gcc, qemu-system-arm (tools/deps.sh).
set -e
[ $# -ge 1 ] || { echo "usage: sh bench/typical.sh REV..." >&2; exit 2; }
top=$(git rev-parse --show-toplevel)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
for rev in "$@"; do
    d="$tmp/$(git -C "$top" rev-parse --short "$rev")"
    mkdir -p "$d"
    git -C "$top" archive "$rev" | tar -x -C "$d"
    make -C "$d" -j2 build/bench/pmbench build/bench/m7/bench.elf > "$d.log" 2>&1 ||
        { tail -20 "$d.log"; exit 1; }
    mkdir -p "$d/build/bench/cg"
    valgrind --tool=callgrind --callgrind-out-file="$d/build/bench/cg/cg.out" \
        "$d/build/bench/pmbench" --callgrind > "$d/build/bench/cg/log.txt" 2>&1
    timeout 600 qemu-system-arm -M mps2-an500 -nographic -semihosting \
        -icount shift=0,align=off,sleep=off -kernel "$d/build/bench/m7/bench.elf" \
        > "$d/build/bench/m7.out" 2>&1
    echo "== $rev ($(git -C "$top" rev-parse --short "$rev")): instructions per call, double"
    /usr/bin/python3 - "$d" <<'EOF'
import os, re, sys
sys.path.insert(0, os.path.join(sys.argv[1], "bench"))
import report
D = os.path.join(sys.argv[1], "build", "bench")
host = report.callgrind(os.path.join(D, "cg"))
raw = {r["name"]: r["instructions"] for r in report.read_jsonl(os.path.join(D, "m7.out"))}
def m7(n):  # bench_cm.c's figures have the loop subtracted already
    return raw[n]
print("   %-9s %2s %10s %10s" % ("op", "L", "host", "M7"))
for L in (0, 2, 4):
    for op in ("fwd", "inv", "inv_near"):
        n = "%s_L%d_double" % (op, L)
        print("   %-9s %2d %10.1f %10.1f" % (op, L, host["host_" + n], m7("m7_" + n)))
EOF
done
