#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs the whole test suite (what CI runs):
#   0. the format: every tracked *.cc and *.h as .clang-format says (scripts/check_format.sh,
#      once setup.sh has installed clang-format and built; `scripts/check_format.sh --fix`
#      formats them), else it stops there, before any test;
#   1. the build, with any compiler warning in bifilar's own code an error (BIFILAR_WERROR);
#   2. every test (ctest), the real-data ones on ../shared/data when it is beside the checkout
#      (or on $BIFILAR_DATA_DIR), and a line saying how many real-data tests did not run and why;
#   3. the tests that compare with committed outputs or real-data reference numbers (labels
#      committed, realdata) again, under another numeric environment: glibc's AVX2, FMA and
#      AVX-512 code paths turned off (libm and the string functions take their SSE2 paths), as
#      on an older or different CPU. Their tolerances must hold there too;
#   4. scripts/sanitize.sh: the suite again in a second build with AddressSanitizer and
#      UndefinedBehaviorSanitizer (BIFILAR_TEST_SANITIZE=0 skips it, for a quick local run).
# Beyond the build's packages (scripts/setup.sh), the tests need Chromium (the report is loaded
# in headless Chromium and checked for console errors), so it is installed here when missing.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
if ! dpkg-query -W -f='${Status}' chromium 2>/dev/null | grep -q "install ok installed"; then
  echo "test: installing chromium (for the report test)"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
cmake_args="-DBIFILAR_WERROR=ON"
data="${BIFILAR_DATA_DIR:-}"
if [ -z "$data" ] && [ -d "$here/../shared/data" ]; then data="$(cd "$here/../shared/data" && pwd)"; fi
if [ -n "$data" ]; then cmake_args="$cmake_args -DBIFILAR_DATA_DIR=$data"; fi
BIFILAR_CMAKE_ARGS="$cmake_args" "$here/scripts/setup.sh" "$here/build"
"$here/scripts/check_format.sh"

cd "$here/build"
log="$here/build/Testing/test_sh_ctest.log"
mkdir -p "$(dirname "$log")"
status=0
ctest --output-on-failure -j"$(nproc)" 2>&1 | tee "$log" || status=$?
# Real-data tests that did not run: CTest's line "Test #N: NAME ....***Skipped".
labelled=$(ctest -N -L realdata | sed -n 's/^ *Test *#[0-9]*: //p')
skipped=0
while read -r name; do
  [ -n "$name" ] && grep -qE "Test +#[0-9]+: ${name//./\\.} \.*\*+Skipped" "$log" &&
    skipped=$((skipped + 1))
done <<< "$labelled"
total=$(printf '%s\n' "$labelled" | grep -c . || true)
folder=$(sed -n 's/^BIFILAR_DATA_DIR:PATH=//p' CMakeCache.txt)
if [ "$skipped" -gt 0 ]; then
  echo "test: $skipped of $total real-data tests (label realdata) did not run: no data folder named"\
       "(set BIFILAR_DATA_DIR to a folder of the real logs: crazyflie/, px4/)"
else
  echo "test: all $total real-data tests (label realdata) ran, on ${folder:-?}"
fi
[ "$status" -eq 0 ] || exit "$status"

# Another machine's numbers: glibc's x86 code paths without AVX2, FMA, AVX-512 (glibc >= 2.33
# spells the features without the old "_Usable"; `ld.so --list-diagnostics` shows the change).
echo "test: the tests of committed outputs and real data again, with GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F"
GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F \
  ctest --output-on-failure -j"$(nproc)" -L 'committed|realdata'

if [ "${BIFILAR_TEST_SANITIZE:-1}" != "0" ]; then
  "$here/scripts/sanitize.sh"
fi
