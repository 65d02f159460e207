#!/bin/sh
# bench/inv_diff.sh - the differential check of a change to the inverse:
# every pm_model_invert and pm_model_invert_near call of bench/inv_diff.c
# (387,840 at SCALE 1: hard cases at three scales, realistic models 0-90 deg
# from the mount's pole, cold and tracking, both pier sides, AUX terms) must
# give the same status, evaluation count and bits of both angles in the core
# of REV as in the core of NEW (a revision, or . for the working tree,
# the default).  Each core is built with its own Makefile's probe rule
# (build/probe/*.o: the evaluation counter of tests/probe.h); both link the
# same test program, this checkout's bench/inv_diff.c.  The realistic
# samples' targets come from REV's forward model in both runs (NEW inverts
# the targets REV's pm_model_apply gave: bench/inv_diff.c's save/load), so
# that a change to the forward model's rounding does not move them.
#
#   sh bench/inv_diff.sh REV [NEW] [SCALE]     e.g. sh bench/inv_diff.sh main
#
# Prints the number of calls compared and "identical", or the first
# differing lines; exit status 0 only when identical.
set -e
[ $# -ge 1 ] || { echo "usage: sh bench/inv_diff.sh REV [NEW|.] [SCALE]" >&2; exit 2; }
top=$(git rev-parse --show-toplevel)
new=${2:-.}
scale=${3:-1}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
build() { # build(rev, dir, save|load): the program against rev's core, output in dir/out.txt
    if [ "$1" = . ]; then
        src=$top
    else
        src=$2/src
        mkdir -p "$src"
        git -C "$top" archive "$1" | tar -x -C "$src"
    fi
    objs=$(cd "$src" && ls lib/*.cpp | sed 's|^lib/\(.*\)\.cpp$|build/probe/\1.o|')
    make -C "$src" -j2 $objs > "$2/make.log" 2>&1 || { tail -20 "$2/make.log"; exit 1; }
    gcc -std=c99 -O2 -I"$src/include" -I"$top/tests" "$top/bench/inv_diff.c" \
        $(for o in $objs; do echo "$src/$o"; done) -lstdc++ -lm -o "$2/inv_diff"
    "$2/inv_diff" "$scale" "$3" "$tmp/targets.bin" > "$2/out.txt"
}
mkdir -p "$tmp/a" "$tmp/b"
build "$1" "$tmp/a" save
build "$new" "$tmp/b" load
echo "$1: $(tail -1 "$tmp/a/out.txt"); $new: $(tail -1 "$tmp/b/out.txt")"
if cmp -s "$tmp/a/out.txt" "$tmp/b/out.txt"; then
    echo "identical: status, evaluations and both angles' bits of every call"
else
    echo "DIFFERENT: $(diff "$tmp/a/out.txt" "$tmp/b/out.txt" | grep -c '^<') lines; the first:"
    diff "$tmp/a/out.txt" "$tmp/b/out.txt" | head -20
    exit 1
fi
