#!/usr/bin/env python3
"""qemu_profile.py - instructions per function of a marked region of a
Cortex-M program under QEMU (no DWT there, no perf: QEMU's own log).

The program calls marker_begin() and marker_end() (noinline functions,
e.g. bench/track_worst_cm.c built with -DPROFILE_MODEL=I -DPROFILE_TICK=J)
around what is to be profiled; run it one instruction per block with the
execution log on:

  qemu-system-arm -M mps2-an500 -nographic -semihosting \\
      -icount shift=0,align=off,sleep=off -kernel PROG.elf \\
      -singlestep -d exec,nochain,in_asm -D q.log
  python3 bench/qemu_profile.py q.log [--calls N]

Prints, per marked region, the instructions executed in each function
(divided by N: the calls the region makes).  The total agrees with the
SysTick counter of firmware_demo/fw_platform.h to the instruction (both
count what QEMU executes)."""
import argparse
import collections
import re

TRACE = re.compile(r"^Trace \d+: 0x[0-9a-f]+ \[[0-9a-f]+/([0-9a-f]+)/")


def profile(path):
    """[(Counter function -> instructions)] per marked region."""
    blocks, runs = {}, []
    fn, start, n, active = None, None, 0, None
    with open(path) as f:
        for line in f:
            if line.startswith("IN: "):
                fn, start, n = line[4:].strip(), None, 0
            elif line.startswith("0x") and fn is not None:
                if start is None:
                    start = int(line.split(":")[0], 16)
                n += 1
            elif line.startswith("Trace"):
                if start is not None:
                    blocks[start] = (fn, n)
                    start = None
                pc = int(TRACE.match(line).group(1), 16)
                name, k = blocks.get(pc, ("?", 0))
                if name == "marker_begin":
                    active = collections.Counter()
                elif name == "marker_end":
                    runs.append(active)
                    active = None
                elif active is not None:
                    active[name] += k
    return runs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log")
    ap.add_argument("--calls", type=int, default=1, help="calls per marked region")
    ap.add_argument("--top", type=int, default=25)
    a = ap.parse_args()
    for i, c in enumerate(profile(a.log)):
        tot = sum(c.values())
        print("== region %d: %d instructions, %.1f per call" % (i, tot, tot / a.calls))
        for name, k in c.most_common(a.top):
            print("  %9.1f  %s" % (k / a.calls, name))


if __name__ == "__main__":
    main()
