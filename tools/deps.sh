#!/bin/sh
# Install the Debian packages the build and the tests need (idempotent).
# Usage: sh tools/deps.sh      (as root, or with sudo available)
# One package per line below (with what needs it), so additions merge cleanly.
set -e
PKGS=$(sed -n 's/^#pkg \([^ ]*\).*/\1/p' "$0")
missing=""
for p in $PKGS; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "installing:$missing" >&2
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >&2
exit 0
# The packages (the list the script reads above):
#pkg build-essential          compilers, make
#pkg pkg-config               Check's flags
#pkg check                    the test framework
#pkg liberfa-dev              catalogue reduction (tools/lib/runfile_reduce.cpp)
#pkg liblapacke-dev           reference solutions in the tests, bench_fit
#pkg python3-numpy            reference scripts (tests/ref)
#pkg python3-scipy            reference scripts
#pkg python3-erfa             reference scripts
#pkg python3-astropy          the independent generator tests/ref/tpoint_gen.py (its own reduction)
#pkg gnuplot-nox              plots in docs
#pkg gcc-arm-none-eabi        make firmware, make bench (Cortex-M)
#pkg libnewlib-arm-none-eabi  make firmware, make bench
#pkg qemu-system-arm          make firmware, make bench
#pkg valgrind                 instruction counts (bench)
#pkg clang-14                 make sanitize, make fuzz
#pkg libclang-rt-14-dev       make sanitize, make fuzz
#pkg chromium                 pmfit report's browser test (tests/check_report.c)
#pkg python3-dev              the Python package's extension (make python): Python.h
#pkg python3-pybind11         the Python package's extension (pulls in pybind11-dev)
#pkg python3-pytest           the Python package's tests (tests/check_python.c)
#pkg libindi-dev              the INDI math plugin (make indi; tests/check_indi.c)
#pkg libnova-dev              the INDI math plugin: sidereal time as INDI's drivers compute it
#pkg indi-bin                 indiserver and the AstroTrac simulator (tests/check_indi.c end to end)
#pkg libindi-plugins          INDI's Nearest and SVD math plugins (make indi-e2e compares them)
