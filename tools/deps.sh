#!/bin/sh
# Install the Debian packages the build and the tests need (idempotent).
# Usage: sh tools/deps.sh      (as root, or with sudo available)
set -e
PKGS="build-essential pkg-config check liberfa-dev liblapacke-dev python3-numpy python3-scipy python3-erfa gnuplot-nox gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm valgrind clang-14 libclang-rt-14-dev"
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
